"""Type stubs of ``tvmd.sim`` (the submodule ``tvmd._tvmd.sim``: PyO3 bindings of ``tvmd-sim``).

Time series are fresh NumPy arrays with ``K`` samples (one per controller tick) and ``n``
agents; SI units, z up, angles in rad. Values the controller did not report are NaN.

Scenarios are loaded (the CLI's name-or-file rule), overridden and run by ``tvmd-sim`` on its
one worker pool; runs release the GIL and come back in input order.

Errors: a scenario, TOML text or override that cannot be used raises ``ValueError`` (the message
is tvmd-sim's, naming the field), as does an integer argument outside its valid range (the
message names the argument and the range), wrong argument types ``TypeError``, I/O errors ``OSError`` (its
errno subclass, e.g. ``FileNotFoundError``, with the file name), a run that fails while flying
(divergence, controller error) ``RuntimeError``. A panic inside tvmd-sim is raised as
``RuntimeError`` too, never as ``PanicException``.

Ctrl-C (or any signal whose handler raises) while a run or batch flies raises that exception
within about 20 ms: the flights stop at their next controller tick, every log is finalised
with what was simulated, and the workers stop before the exception reaches the caller.
Log paths are checked before anything runs: two runs of a batch on one file raise
``ValueError`` (``output path clash``).
"""

import os
from typing import Any, ClassVar, Iterable, Literal, Mapping, Optional, Tuple, TypedDict, Union, final, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._tvmd import AllocatorName, Reference, State, Team

_F64 = NDArray[np.float64]
_ScenarioArg = Union[str, "os.PathLike[str]"]
_PathArg = Union[str, "os.PathLike[str]"]
_RunItem = Union[str, "os.PathLike[str]", Mapping[str, Any]]
# A control law: a name, or a dict with the keys of a scenario's TOML ``[law]`` table.
_LawArg = Union[Literal["paper", "offset-free"], Mapping[str, Any]]
# The controller's float type: "f32" flies ``tvmd_core::Controller<f32, ..>`` (the flight
# configuration), "f64" the default; the physics is f64 either way.
_Precision = Literal["f32", "f64"]
# Processor in the loop: the f32 controller runs on an emulated target (QEMU mps2-an386 for
# "cortex-m4", mps2-an500 for "cortex-m7"), the physics here.
_PilTarget = Literal["cortex-m4", "cortex-m7"]

@final
class SimResult:
    """The result of one simulated run (read-only; every array access returns a fresh float64
    copy, so bind it to a name before indexing in a loop).

    ``K`` samples, one per controller tick (``t_k = k controller_period``, true state before the
    tick's commands act), or one per ``sample_stride`` ticks when ``run(max_samples=...)`` bounds
    them (``summary`` and ``paper_metrics`` cover every tick either way); ``n`` agents. SI units, z up, angles in rad. Values a controller did
    not report at a tick (a skipped cycle) are NaN.

    Attributes:
        scenario_name, law (the control law that flew: ``"paper"``, ``"offset-free"`` or
        ``"custom"``; None when your own controller flew, a ``Simulation`` stepped with commands
        or wrenches), relaxation (``s``; None likewise), allocator, null_space (the null-space
        stage or None),
        precision (``"f64"`` or ``"f32"``, the
        controller's float type), controller_target (``"host"`` or the PIL target), mcap_path
        (str or None), n_agents,
        mass (``m_C``, kg), gravity (``g``, m/s^2), hover_roll_limit (``atan(c_y(1, s))``, rad: the
        planned roll at which the planner saturates in hover).
        t: (K,) time (s).
        position, velocity_world, reference_position: (K, 3) ``x`` (m), ``x_dot`` (m/s, world
            frame; ``velocity`` is its old name), ``x_r`` (m). velocity_body: (K, 3) ``R^T x_dot``.
        angular_velocity: (K, 3) body rates ``Omega``. rotation: (K, 3, 3) ``R``.
        attitude_rpy, reference_rpy, planned_rpy: (K, 3) roll, pitch, yaw (ZYX) of ``R``, ``R_r``
            and the planned ``R_d``.
        reference_roll: (K,) ``phi_r``. planned_roll: (K,) ``phi_d = atan2(R_d[2,1], R_d[2,2])``.
        attitude_error: (K,) angle between ``R`` and ``R_d``. reference_attitude_error: (K,)
            angle between ``R`` and ``R_r``. theta: (K,) planner angle ``theta*``.
        e_f: (K,) allocation error ``||u_fd - u_f||`` (N). e_tau: (K,) moment error
            ``||u_taud - u_tau||`` (N m). thrust_efficiency: (K,) ``||u_f|| / sum_i ||f_i||``.
            saturated_agents: (K,) int64, agents the allocator saturated (-1 if not reported).
        V_x, V_R: (K,) the Lyapunov candidates. cycle_error: (K,) bool, cycle skipped.
        commands, actual: (K, n, 3) commanded and actual actuator values, columns
            ``eta_x, eta_y`` (rad), ``thrust`` (N): ``commands[k]`` is what tick ``k`` commanded,
            ``actual[k]`` what the actuators output at ``t_k``, before tick ``k``'s commands act
            (the previous period's commands, through the actuator models and the plant's
            saturation). failed: (K, n) bool, true failure flags.
        forces: (K, n, 3) body-frame forces of the actual outputs (N), at ``t_k`` as ``actual``.
            rotor_speeds: (K, n) normalized commanded rotor speeds.
        summary: dict, every field of tvmd-sim's ``RunSummary`` (``max_planned_roll``, ``max_e_f``,
            ``max_e_f_over_weight`` = ``max e_f / (m_C g)``, ``max_position_error_after_4s``, ...),
            with ``metrics`` (settling time, steady-state, peak and integral errors, force and
            moment errors, thrust efficiency, time saturated; docs/method.md, "Flight metrics")
            and ``verdict`` (``{"success": bool, "failures": [str]}`` against the scenario's
            ``[success]`` bounds).
        paper_metrics: dict, tvmd-sim's ``PaperMetrics`` (horizontal errors at 4 and 12 s,
            stage-B attitude settling, ``e_f`` onset, ``V_x`` rise, ...).
        scenario_toml: the scenario that ran, as TOML.
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def scenario_name(self) -> str:
        """Name of the scenario that ran."""
    @property
    def law(self) -> Optional[Literal["paper", "offset-free", "custom"]]:
        """The control law that flew (the scenario's ``law``, or ``run``'s override):
        ``"paper"``, ``"offset-free"`` or ``"custom"`` (any other ``[law]`` table); None for the
        flight of a ``Simulation`` that your own controller stepped (commands not from a
        ``ScenarioController``, or ``step_wrench``)."""
    @property
    def relaxation(self) -> Optional[float]:
        """Planner relaxation ``s`` of the run; None when your own controller flew (as
        ``law``)."""
    @property
    def allocator(self) -> AllocatorName:
        """Allocator of the run."""
    @property
    def null_space(self) -> Optional[str]:
        """The null-space stage of the run ("margin", "inward-tilt=<rad>"), or None."""
    @property
    def precision(self) -> _Precision:
        """The float type the controller flew in, "f64" or "f32"."""
    @property
    def controller_target(self) -> str:
        """Where the controller ran: "host", or the emulated target of a processor-in-the-loop
        run (e.g. "cortex-m4 (qemu mps2-an386)")."""
    @property
    def mcap_path(self) -> Optional[str]:
        """Path of the MCAP log written, or None."""
    @property
    def n_agents(self) -> int:
        """Number of agents ``n``."""
    @property
    def mass(self) -> Optional[float]:
        """Team mass ``m_C`` (kg)."""
    @property
    def gravity(self) -> float:
        """Gravity ``g`` (m/s^2)."""
    @property
    def hover_roll_limit(self) -> Optional[float]:
        """``atan(c_y(1, s))`` (rad): the planned roll at which the planner saturates in hover for
        this team, limits and ``s``.
        """
    @property
    def sample_stride(self) -> int:
        """Controller ticks between the kept samples: 1 keeps every tick; ``k`` keeps ticks
        0, k, 2k, ... (a power of two, from ``max_samples``)."""
    @property
    def t(self) -> _F64:
        """(K,) time (s)."""
    @property
    def position(self) -> _F64:
        """(K, 3) ``x`` (m)."""
    @property
    def velocity(self) -> _F64:
        """(K, 3) ``x_dot`` (m/s), world frame: ``velocity_world`` under its old name (kept for
        compatibility; not a column of ``to_columns``)."""
    @property
    def velocity_world(self) -> _F64:
        """(K, 3) ``x_dot`` (m/s), world frame."""
    @property
    def velocity_body(self) -> _F64:
        """(K, 3) ``v = R^T x_dot`` (m/s), body frame (the frame of ``tvmd.State.velocity``)."""
    @property
    def angular_velocity(self) -> _F64:
        """(K, 3) body rates ``Omega`` (rad/s), body frame."""
    @property
    def rotation(self) -> _F64:
        """(K, 3, 3) attitude ``R`` (body to world)."""
    @property
    def reference_position(self) -> _F64:
        """(K, 3) ``x_r`` (m)."""
    @property
    def attitude_rpy(self) -> _F64:
        """(K, 3) roll, pitch, yaw of ``R`` (rad, ZYX)."""
    @property
    def reference_rpy(self) -> _F64:
        """(K, 3) roll, pitch, yaw of ``R_r`` (rad)."""
    @property
    def reference_roll(self) -> _F64:
        """(K,) ``phi_r`` (rad)."""
    @property
    def planned_roll(self) -> _F64:
        """(K,) ``phi_d`` of the planned ``R_d`` (rad)."""
    @property
    def planned_rpy(self) -> _F64:
        """(K, 3) roll, pitch, yaw of ``R_d`` (rad)."""
    @property
    def attitude_error(self) -> _F64:
        """(K,) angle between ``R`` and ``R_d`` (rad)."""
    @property
    def reference_attitude_error(self) -> _F64:
        """(K,) angle between ``R`` and ``R_r`` (rad)."""
    @property
    def theta(self) -> _F64:
        """(K,) planner angle ``theta*`` (rad)."""
    @property
    def e_f(self) -> _F64:
        """(K,) allocation error ``||u_fd - u_f||`` (N)."""
    @property
    def e_tau(self) -> _F64:
        """(K,) moment error ``||u_taud - u_tau||`` (N m)."""
    @property
    def thrust_efficiency(self) -> _F64:
        """(K,) thrust efficiency ``||u_f|| / sum_i ||f_i||`` (NaN: no thrust)."""
    @property
    def saturated_agents(self) -> NDArray[np.int64]:
        """(K,) agents the allocator saturated (-1: not reported)."""
    @property
    def V_x(self) -> _F64:
        """(K,) Lyapunov candidate ``V_x``."""
    @property
    def V_R(self) -> _F64:
        """(K,) Lyapunov candidate ``V_R = Psi(R, R_d) + ||e_Omega||_{K_Omega}``; NaN if not
        reported.
        """
    @property
    def cycle_error(self) -> NDArray[np.bool_]:
        """(K,) the controller skipped the cycle."""
    @property
    def commands(self) -> _F64:
        """(K, n, 3) commanded ``eta_x``, ``eta_y`` (rad), ``thrust`` (N)."""
    @property
    def actual(self) -> _F64:
        """(K, n, 3) actual actuator outputs, same columns."""
    @property
    def forces(self) -> _F64:
        """(K, n, 3) the agents' body-frame forces (N) of the actual outputs, with the plant's
        actuation error (gimbal offsets, rotor efficiency): what the plant applied."""
    @property
    def rotor_speeds(self) -> _F64:
        """(K, n) commanded rotor speeds, normalized (1 at the largest thrust ``sigma_Tf``):
        ``sqrt(thrust / sigma_Tf)``."""
    @property
    def failed(self) -> NDArray[np.bool_]:
        """(K, n) true failure flags."""
    @property
    def summary(self) -> dict[str, Any]:
        """Every field of tvmd-sim's ``RunSummary``."""
    @property
    def paper_metrics(self) -> dict[str, Any]:
        """tvmd-sim's ``PaperMetrics``."""
    @property
    def scenario_toml(self) -> str:
        """The scenario that ran, as TOML."""
    def to_dict(self) -> dict[str, Any]:
        """Every field as a dict (arrays as they are: (K, ...))."""
    def to_columns(self) -> dict[str, _F64]:
        """Every time series as flat (K,) columns, in field order, for ``pandas.DataFrame``:
        vectors as ``<name>_x/_y/_z`` (``attitude_rpy_roll/_pitch/_yaw``, ...), matrices as
        ``rotation_<row><col>``, per-agent values as ``<name>_<i>`` and
        ``commands_<i>_eta_x/_eta_y/_thrust``, ``forces_<i>_x/_y/_z``; ``velocity`` appears once,
        as ``velocity_world``."""
    def to_pandas(self) -> Any:
        """``pandas.DataFrame(to_columns())``: one row per sample.

        Raises:
            ImportError: pandas is not installed.
        """
    def __len__(self) -> int:
        """The number of samples ``K``."""

@final
class Observation:
    """One controller tick as a controller sees it (read-only): what ``Simulation.reset``,
    ``observe``, ``step`` and ``step_wrench`` return.

    Attributes:
        t: simulation time ``t_k`` (s).
        state: the fed-back state (the scenario's state noise and feedback latency applied), a
            ``tvmd.State``: position ``x``, attitude ``R``, body rates ``Omega`` and the
            body-frame velocity ``v`` (``x_dot = R v``); what ``tvmd.Controller.step`` takes.
        true_state: the true state, a ``tvmd.State``.
        velocity_world: (3,) the fed-back world-frame velocity ``x_dot`` (m/s).
        reference: the scenario's reference at ``t_k``, a ``tvmd.Reference``.
        failed: (n,) bool, the failures the controller is told of.
        done: the scenario's duration is reached (the last state; no step follows).
        saturation: (n, 3) by how much the plant clamped the last step's commands to the
            hardware's range: each command minus what the plant held (``eta_x``, ``eta_y`` rad,
            thrust N); zero inside the range and after a reset.
        reports: (n, 4) each agent's newest report (``[reports]``): rotor speed as thrust (N),
            ``eta_x``, ``eta_y`` (rad), age (s); NaN rows before the first; None without it.
    """

    FIELDS: ClassVar[Tuple[str, ...]]
    @property
    def t(self) -> float:
        """Simulation time ``t_k`` (s)."""
    @property
    def state(self) -> State:
        """The fed-back state (noise and latency applied)."""
    @property
    def true_state(self) -> State:
        """The true state."""
    @property
    def velocity_world(self) -> _F64:
        """(3,) world-frame velocity ``x_dot`` of the fed-back state (m/s)."""
    @property
    def reference(self) -> Reference:
        """The reference at ``t_k``."""
    @property
    def failed(self) -> NDArray[np.bool_]:
        """(n,) the failures the controller is told of."""
    @property
    def done(self) -> bool:
        """The scenario's duration is reached (no step follows)."""
    @property
    def saturation(self) -> _F64:
        """(n, 3) by how much the plant clamped the last step's commands (the command minus
        what it held)."""
    @property
    def reports(self) -> Optional[_F64]:
        """(n, 4) each agent's newest report arrived: rotor speed as thrust (N), ``eta_x``,
        ``eta_y`` (rad), age (s); NaN before its first; None without the scenario's
        ``[reports]``."""
    def to_dict(self) -> dict[str, Any]:
        """Every field as a dict (the states and the reference as dicts)."""

@final
class ControllerOutput:
    """What ``ScenarioController.step`` returns for one tick: the commands and the diagnostics;
    ``Simulation.step`` takes it as it is (the diagnostics then reach ``Simulation.result()``).
    """

    @property
    def commands(self) -> _F64:
        """(n, 3) commands ``eta_x``, ``eta_y`` (rad), ``thrust`` (N)."""
    @property
    def diagnostics(self) -> dict[str, Any]:
        """The controller's diagnostics of the tick (planner, law, allocation, Lyapunov values)."""

@final
class Simulation:
    """The simulator stepped one controller period at a time, with your own controller.

    The plant is ``run``'s (rapier3d rigid body at ``physics.dt``; the scenario's actuators,
    failures, payloads, wind, gusts, external wrench, state noise and feedback latency apply), and
    so is the loop: ``run`` is one client of these steps, so ``ScenarioController`` flown through
    ``step`` reproduces ``run``'s flight exactly. Each step holds its commands for
    ``controller_period`` (zero-order hold) and returns the next tick's ``Observation``.

    Two action modes:

    * ``step(commands)``: per-agent gimbal angles and thrusts (or normalized rotor speeds);
    * ``step_wrench(wrench)``: a body wrench ``[u_tau; u_f]`` (N m, N; body frame, about the
      centre of mass) that the scenario controller's planner-free allocation stage
      (``tvmd_core::Controller::allocate``: its allocator, limits, rate limits; in f64) turns into
      admissible commands, the failed agents the controller is told of idle.

    The plant flies what the hardware can: it holds each agent's command saturated to the gimbal
    limits (``|eta_x| <= sigma_x``, ``|eta_y| <= sigma_y``) and to thrusts in ``[0, max_thrust]``
    (a rotor never pushes down its axis, nor beyond its largest speed), as in ``run`` and
    ``SimulationBatch``; ``Observation.saturation`` says by how much it clamped each agent's
    command. tvmd's own commands are inside that range. Non-finite commands are refused.

    Copies: ``copy.copy``, ``copy.deepcopy`` and ``pickle`` replay the simulation's reset and
    steps since its last reset on a simulation of the same scenario (``scenario_toml``), so the
    copy is in the same state, noise generator included, and every later step gives exactly the
    original's observation (only ``result().summary``'s wall time differs). A copy costs the
    replay of those steps.

    Example::

        sim = tvmd.sim.Simulation("hover")
        obs = sim.reset()
        while not obs.done:
            s, r = obs.state, obs.reference
            f = sim.mass * (9.81 * e3 - kp * (s.position - r.position) - kd * (obs.velocity_world - r.velocity))
            obs = sim.step_wrench(np.r_[tau, s.attitude.T @ f])

    Args:
        scenario: a built-in name or a TOML scenario file, as ``run``'s; default ``"hover"``
            (A4-Inc holding a hover at 1.5 m for 12 s; with ``team`` another team).
        toml: inline TOML scenario text instead of ``scenario``.
        team: a catalogue team (``"a6-inc"``, ...) or a ``tvmd.Team`` instead of the scenario's
            (as ``run``'s ``team``).
        relaxation, allocator, precision, null_space, law: ``run``'s overrides (the allocator and
            the null-space stage are ``step_wrench``'s; ``precision`` and ``law`` concern
            ``ScenarioController`` built with the same arguments).
        max_samples: the samples ``result()`` keeps, as ``run``'s.
        fault_detection, max_rounds: as ``run``'s (the round cap is ``step_wrench``'s
            allocator's; fault detection concerns ``ScenarioController`` built from
            ``scenario_toml``).

    Raises:
        ValueError: a scenario or override that cannot be used; a step with commands of the
            wrong shape or with NaN or infinite values, a negative rotor speed, a wrench that is
            not (6,) finite values, or a step after the duration (``done``: ``reset`` first).
        RuntimeError: the state diverged.
    """

    def __new__(
        cls,
        scenario: Optional[_ScenarioArg] = None,
        *,
        toml: Optional[str] = None,
        team: Optional[Union[str, Team]] = None,
        relaxation: Optional[float] = None,
        allocator: Optional[AllocatorName] = None,
        precision: Optional[_Precision] = None,
        null_space: Optional[str] = None,
        law: Optional[_LawArg] = None,
        max_samples: Optional[int] = None,
        fault_detection: Optional[Union[Literal["report", "mask"], Mapping[str, Any]]] = None,
        max_rounds: Optional[Union[int, Literal["uncapped"]]] = None,
    ) -> "Simulation": ...
    def reset(
        self,
        seed: Optional[int] = None,
        *,
        position: Optional[ArrayLike] = None,
        attitude_rpy: Optional[ArrayLike] = None,
    ) -> Observation:
        """Starts over (initial state, actuators at rest, no failure applied, time 0, nothing
        recorded) and returns the first observation.

        Args:
            seed: 0 to 2**64 - 1, reseeds the state noise and the draws of the agents' links
                and reports; without it the scenario's seeds are used, so every reset replays
                the same noise. No effect without any of them.
            position: (3,) another initial position of the centre of mass (m).
            attitude_rpy: (3,) another initial attitude, roll, pitch, yaw (rad, ZYX).
                ``position`` and ``attitude_rpy`` replace the scenario's initial pose (later
                resets start there too); the team starts at rest.

        Raises:
            ValueError: a seed out of range, a pose that is not 3 finite values or that the
                scenario's validation refuses (the simulation is then unchanged).
        """
    def observe(self) -> Observation:
        """The current tick's observation (the noise is drawn once per tick: calling it again
        returns the same values)."""
    def step(self, commands: Union[ArrayLike, ControllerOutput], *, rotor_speeds: bool = False) -> Observation:
        """Holds per-agent commands for one controller period; returns the next observation.

        Args:
            commands: (n, 3) rows ``eta_x, eta_y`` (rad), ``thrust`` (N); or (n, 4), the layout of
                ``tvmd.Controller``'s commands (``eta_x, eta_y, thrust, omega``); or a
                ``ControllerOutput`` (its diagnostics are recorded too). Failed agents' commands
                are overridden as their failure dictates.
            rotor_speeds: the last column is the normalized rotor speed ``omega`` (1 at
                ``max_thrust``; thrust ``max_thrust * omega**2``) instead of the thrust.

        The plant holds each command saturated to the hardware's range (the returned
        observation's ``saturation`` says by how much).

        Raises:
            ValueError: a wrong shape or count (also a ``ControllerOutput`` of another team), a
                non-finite value, a negative rotor speed; nothing changes.
        """
    def step_wrench(self, wrench: ArrayLike) -> Observation:
        """Holds the admissible commands of the (6,) body wrench ``[u_tau; u_f]`` (N m, N; body
        frame) for one controller period; returns the next observation. A wrench the
        allocation cannot serve (zero thrust for a non-zero force) holds the previous commands."""
    def result(self) -> SimResult:
        """The flight so far as a ``SimResult`` (the samples copied; the simulation goes on)."""
    def link_stats(self) -> Optional[dict[str, NDArray[np.int64]]]:
        """The command links' counts per agent since the last reset (scenario ``[links]``).

        Returns:
            A dict of (n,) int64 arrays in the agents' order: ``sent`` (commands sent),
            ``lost`` (on their own, in bursts, or to a silent link), ``stale`` (arrived after a
            newer one and dropped), ``failsafes`` (times the agent failed safe after ``hold``
            seconds without a command); None when the scenario has no ``[links]``.
        """
    @property
    def state(self) -> State:
        """The true state now."""
    @property
    def time(self) -> float:
        """Simulation time (s)."""
    @property
    def done(self) -> bool:
        """The scenario's duration is reached: ``reset`` before the next step."""
    @property
    def n_agents(self) -> int:
        """Number of agents ``n``."""
    @property
    def mass(self) -> float:
        """Team mass ``m_C`` (kg)."""
    @property
    def max_thrust(self) -> float:
        """Largest thrust of one agent ``sigma_Tf`` (N)."""
    @property
    def agent_positions(self) -> _F64:
        """(n, 3) the agents' positions ``p_i`` relative to the centre of mass (m, body frame)."""
    @property
    def gimbal_limits(self) -> Tuple[float, float]:
        """``(sigma_x, sigma_y)``: the gimbal limits ``|eta_x| <= sigma_x``, ``|eta_y| <= sigma_y``
        (rad)."""
    @property
    def controller_period(self) -> float:
        """The time one step holds its commands (s)."""
    @property
    def duration(self) -> float:
        """The scenario's duration (s)."""
    @property
    def scenario_toml(self) -> str:
        """The scenario (overrides applied) as TOML."""

@final
class ScenarioController:
    """The tvmd controller of a scenario exactly as ``run`` flies it (its precision, law,
    allocator, failure handling, landing), to fly through ``Simulation.step``: with the same
    arguments, ``sim.step(ctrl.step(obs))`` from ``sim.reset()`` to ``done`` reproduces
    ``run``'s flight.

    Args: as ``Simulation``'s (default scenario ``"hover"``).
    """

    def __new__(
        cls,
        scenario: Optional[_ScenarioArg] = None,
        *,
        toml: Optional[str] = None,
        team: Optional[Union[str, Team]] = None,
        relaxation: Optional[float] = None,
        allocator: Optional[AllocatorName] = None,
        precision: Optional[_Precision] = None,
        null_space: Optional[str] = None,
        law: Optional[_LawArg] = None,
    ) -> "ScenarioController": ...
    def step(self, observation: Observation) -> ControllerOutput:
        """The commands and diagnostics for one tick's observation (advances the controller's
        state: call it once per tick).

        Raises:
            ValueError: the observation is of a team with another number of agents.
            RuntimeError: the controller failed.
        """

@final
class SimulationBatch:
    """Many teams of one scenario stepped together inside Rust: one call steps every team one
    controller period on a worker pool (``jobs`` threads, the GIL released), each team with its
    own action, and returns every team's observation as ``(B, ...)`` arrays. Each team is a
    ``Simulation`` of its own (its noise, failures and errors); a team whose step fails (a
    divergence) reports it in ``errors`` and NaN in the arrays, the others go on. The batch keeps
    no samples.

    Every call returns a dict of the teams' observations (the fed-back state):
    ``t`` (B,), ``position``, ``velocity_world``, ``angular_velocity`` (B, 3), ``rotation``
    (B, 3, 3), ``true_position`` (B, 3), ``reference_position``, ``reference_velocity`` (B, 3),
    ``reference_rotation`` (B, 3, 3), ``reference_angular_velocity`` (B, 3) (the reference's
    body rates ``Omega_r``),
    ``done`` (B,) bool (the duration is reached: reset that team), ``saturation`` (B, n, 3): by how
    much the plant clamped each team's last commands to the hardware's range, as
    ``Observation.saturation`` (NaN for a failed team), and ``errors`` (a list of B messages or
    None).

    Args:
        scenario, toml, team, relaxation, allocator, precision, null_space, law: as
            ``Simulation``'s (default scenario ``"hover"``).
        count: the number of teams ``B`` (1 to 2**20).
        jobs: worker threads (default: the available cores).
    """

    def __new__(
        cls,
        scenario: Optional[_ScenarioArg] = None,
        *,
        count: int,
        jobs: Optional[int] = None,
        toml: Optional[str] = None,
        team: Optional[Union[str, Team]] = None,
        relaxation: Optional[float] = None,
        allocator: Optional[AllocatorName] = None,
        precision: Optional[_Precision] = None,
        null_space: Optional[str] = None,
        law: Optional[_LawArg] = None,
    ) -> "SimulationBatch": ...
    def reset(
        self,
        indices: Optional[list[int]] = None,
        *,
        seeds: Optional[list[int]] = None,
        positions: Optional[ArrayLike] = None,
        attitudes_rpy: Optional[ArrayLike] = None,
    ) -> dict[str, Any]:
        """Resets the teams ``indices`` (default all, each named at most once: a repeat is a
        ``ValueError``) as ``Simulation.reset`` does, with one seed and optional (m, 3) initial
        positions and attitudes per reset team; every team's observation."""
    def step_wrench(self, wrenches: ArrayLike, *, active: Optional[list[bool]] = None) -> dict[str, Any]:
        """Holds each team's (B, 6) body wrench ``[u_tau; u_f]`` (N m, N) for one controller
        period (only the ``active`` teams step, all by default); every team's observation.

        A team whose wrench is not finite (NaN, inf) fails alone: its ``errors`` entry says
        which component, its arrays are NaN, its simulation is unchanged, and the other teams
        step (as the Rust batch does).

        Raises:
            ValueError: not (B, 6) values, ``active`` not B flags.
        """
    def step(
        self, commands: ArrayLike, *, active: Optional[list[bool]] = None, rotor_speeds: bool = False
    ) -> dict[str, Any]:
        """Holds each team's (B, n, 3) or (B, n, 4) per-agent commands (as ``Simulation.step``)
        for one controller period; every team's observation. A team whose commands are not
        finite fails alone (its ``errors`` entry), as with ``step_wrench``."""
    @property
    def n_teams(self) -> int:
        """The number of teams ``B``."""
    @property
    def n_agents(self) -> int:
        """Number of agents ``n`` per team."""
    @property
    def mass(self) -> float:
        """Team mass ``m_C`` (kg)."""
    @property
    def max_thrust(self) -> float:
        """Largest thrust of one agent ``sigma_Tf`` (N)."""
    @property
    def controller_period(self) -> float:
        """The time one step holds its commands (s)."""

def builtin_scenarios() -> list[str]:
    """The names of the built-in scenarios (``"paper-tilt"`` is the paper's simulation, see
    docs/method.md; ``"relaxation-<s>"`` the relaxation study; failures, A4-Con, ...).
    """

def scenario_toml(name: str) -> str:
    """A built-in scenario as TOML text: every field, a starting point for a scenario file (or for
    ``run(toml=...)``).

    Raises:
        ValueError: unknown name.
    """

def run(
    scenario: Optional[_ScenarioArg] = None,
    *,
    toml: Optional[str] = None,
    mcap: Optional[_PathArg] = None,
    relaxation: Optional[float] = None,
    allocator: Optional[AllocatorName] = None,
    precision: Optional[_Precision] = None,
    pil: Optional[_PilTarget] = None,
    null_space: Optional[str] = None,
    max_samples: Optional[int] = None,
    team: Optional[Union[str, Team]] = None,
    law: Optional[_LawArg] = None,
    fault_detection: Optional[Union[Literal["report", "mask"], Mapping[str, Any]]] = None,
    max_rounds: Optional[Union[int, Literal["uncapped"]]] = None,
) -> SimResult:
    """Runs one scenario with the tvmd controller in the loop (tvmd-sim: rapier3d rigid body at
    ``physics.dt``, controller every ``controller_period`` with zero-order hold) and returns its
    time series. The GIL is released during the run.

    Args:
        scenario: a built-in name (see ``builtin_scenarios()``), or a TOML scenario file (a path
            ending in ``.toml`` or naming an existing file, or any ``os.PathLike``). Default
            ``"paper-tilt"``: the paper's simulation (A4-Inc, ascent, roll tilt towards the
            infeasible ``pi/3``, descent; ``s = 0.5``).
        toml: inline TOML scenario text instead of ``scenario`` (fields left out take the
            paper-tilt defaults, except ``law``: the offset-free law unless the text or ``law``
            names one; see ``scenario_toml("paper-tilt")``).
        mcap: write an MCAP log there (parent directories are created; open it in Foxglove).
            Every channel is protobuf with its schema in the file; read it with ``mcap`` and
            ``mcap-protobuf-support``: ``make_reader(f, decoder_factories=[DecoderFactory()])``.
        relaxation: override the planner's AFS relaxation ``s``, in (0, 1].
        allocator: override the allocator ("exact-boundary-redistribution", the default;
            "redistributed-pseudo-inverse", the paper's; "pseudo-inverse",
            "weighted-pseudo-inverse"; "capped-redistribution"; "clarabel" and "clarabel-sequential" with the cargo
            feature).
        precision: override the controller's float type (scenario field
            ``controller_precision``): "f32" flies ``tvmd_core::Controller<f32, ..>``, the type a
            flight controller runs; "f64" (the default). The physics stays f64; the summary's
            ``controller_precision`` says which flew.
        pil: processor in the loop: "cortex-m4" or "cortex-m7" runs the f32 controller in QEMU
            (``qemu-system-arm``, machine mps2-an386 or mps2-an500; the PIL firmware built by
            ``bash scripts/pil.sh build``, or the ELF ``TVMD_PIL_FIRMWARE`` names) while the
            physics stays here; the precision becomes "f32" (asking for "f64" too is a
            ``ValueError``). The summary's and the result's ``controller_target`` say
            which target flew ("host" otherwise).
        null_space: run a null-space stage after the allocator (scenario field ``null_space``):
            ``"margin"`` or ``"inward-tilt=<rad>"`` (docs/method.md "Null-space stage"; the
            wrench is unchanged to round-off). The summary's ``null_space`` gives its margins
            before and after; not with ``pil``.
        max_samples: keep at most this many samples, evenly spaced (every ``sample_stride``-th
            tick, the smallest power of two that fits; ``0`` keeps none), so a long run's memory
            stays flat; ``summary`` and ``paper_metrics`` still cover every tick. Default None:
            every tick, which a run longer than 2,000,000 controller ticks (about 2 GB) refuses
            with a ``ValueError`` naming ``duration``.
        team: fly the scenario with a catalogue team instead of its own (``team.preset``:
            ``"a3-con"`` ... ``"a10-inc"``, ``"a4-diamond-inc"``, ``"t10-con"``, ``"t10-inc"``);
            the scenario families (``"hover"``, ``"wind"``, ``"payload"``, ``"model-error"``,
            ``"reference-jump"``, ``"sine"``, ``"figure-eight"``, ``"initial-attitude-<rad>"``)
            are built for any of them (docs/method.md "Scenario families"). Or a ``tvmd.Team``
            (a preset or one built in Python): its agents (positions, quarter turns, masses),
            navigator, gimbal limits and largest thrust replace the scenario's ``[team]`` and
            ``[limits]``; a team with agent inertias or a ``min_thrust`` raises ``ValueError``
            (the simulator's agents are point masses that idle at zero thrust). In ``run_many``
            dicts too (on a process pool's ``executor``, a name only: a ``tvmd.Team`` does not
            pickle).
        law: override the scenario's control law (scenario field ``law``): ``"paper"`` (the
            paper's eq. 12), ``"offset-free"`` (natural gains, disturbance observer, planned
            rates), or a dict with the keys of the TOML ``[law]`` table (as
            ``tvmd.Controller``'s ``law``). Default None: the scenario's own (the built-in
            paper scenarios fly ``"paper"``; the families and any TOML that names no ``law``,
            ``toml=`` text included, ``"offset-free"``).
            ``SimResult.law`` says which flew. Not with ``pil`` unless ``"paper"``.
        fault_detection: turn on agent fault detection in the controller (scenario table
            ``[fault_detection]``), as ``tvmd.Controller``'s ``fault_detection``: ``"report"``,
            ``"mask"`` or a dict of the table's keys (``report_check`` a dict of the
            ``[fault_detection.report_check]`` keys); it needs the offset-free law's observer.
            ``summary["fault"]`` reports what it found. Default None: the scenario's own.
        max_rounds: the "exact-boundary-redistribution" allocator's round cap per period
            (scenario field ``allocator_max_rounds``; bounds its worst-case cost): an int >= 0
            or "uncapped". Default None: the scenario's own (a scenario that names none flies
            the library's default, 2 rounds).

    Raises:
        ValueError: unknown scenario, TOML that does not parse or a field that is not valid (the
            message names the field, e.g. ``physics.dt``), a bad override, both ``scenario`` and
            ``toml``, an unknown ``pil`` target or ``pil`` with ``precision="f64"``, an unknown
            ``null_space`` objective or a bad tilt (``null_space.tilt``), ``null_space`` with ``pil``,
            ``max_samples < 0``, a run that would keep more than 2,000,000 samples, an unknown
            ``law`` name or key or a law setting out of range (the message names the field, e.g.
            ``law.attitude_rate.bandwidth``).
        TypeError: an argument of the wrong type (also a ``law`` neither a str nor a dict, or a
            value of the wrong type in it).
        OSError: the scenario file cannot be read (also: not a regular file, over 1 MiB) or the
            log cannot be written; the message names the path.
        KeyboardInterrupt: Ctrl-C while flying; the log holds what was simulated.
        RuntimeError: the run failed while flying (the state diverged, the controller failed,
            the PIL link broke); with ``pil``, also ``qemu-system-arm`` or the PIL firmware not
            found (the message says how to install or build it).
    """

def load(path: _PathArg) -> SimResult:
    """A run read back from the MCAP log it wrote (``run(..., mcap=path)``), as the
    :class:`SimResult` that run returned.

    The log stores every value as a float64 (protobuf ``double``), so the arrays equal the
    in-memory result's exactly (NaN where it has NaN; a ``-0.0`` may read back as ``0.0``,
    which compares equal) for a run that kept every tick
    (``max_samples=None``): one sample per controller tick (``sample_stride`` 1). ``summary``
    and ``paper_metrics`` are the ones the run computed (stored in the log's ``tvmd.result``
    metadata); ``scenario_toml`` is the scenario that ran (``tvmd.scenario`` metadata);
    ``mcap_path`` is ``path``. On ticks a scenario's ``[log] decimation > 1`` thinned, the
    heavy topics are absent: those samples' commands, actual outputs, forces, rotor speeds,
    planner and allocation values are NaN.

    Args:
        path: the ``.mcap`` file (a str or ``os.PathLike``).

    A log damaged after its first tick (a run cut short, a copy truncated) loads the ticks
    before the damage, its summary folded over them when the stored one is lost, with a
    ``UserWarning`` naming ``path`` and the damage.

    Raises:
        FileNotFoundError: the file is missing (``OSError`` when it cannot be read, or is not a
            regular file: a FIFO or device is refused before it is opened).
        ValueError: not MCAP (checked on its first bytes, so a large foreign file is not read
            whole), damaged before its first tick, or not a tvmd-sim run's log (no ``/state``
            messages or no scenario metadata); the message names ``path``.
    """

@overload
def run_many(
    runs: Iterable[_RunItem],
    *,
    jobs: Optional[int] = None,
    executor: Optional[Any] = None,
    errors: Literal["keep"],
) -> list[Union[SimResult, Exception]]:
    """``run_many`` with ``errors="keep"``: each failed run's exception in its place (see the
    other overload for every argument)."""
@overload
def run_many(
    runs: Iterable[_RunItem],
    *,
    jobs: Optional[int] = None,
    executor: Optional[Any] = None,
    errors: Literal["raise"] = "raise",
) -> list[SimResult]:
    """Runs many scenarios in parallel threads (GIL released) and returns their results in input
    order.

    Args:
        runs: a sequence whose items are each a scenario (a built-in name or a TOML file, as
            ``run``'s ``scenario``) or a dict of ``run``'s keyword arguments, e.g.
            ``{"scenario": "a4-con", "relaxation": 1.0}``, ``{"toml": text, "mcap": "x.mcap"}`` or
            ``{"scenario": "paper-tilt", "precision": "f32"}`` (``"pil"``, ``"null_space"`` and
            ``"law"`` too, as ``run``; ``"max_samples"`` bounds that run's samples); errors name
            the item's key, e.g. ``runs[1]['law'].offset_free``.
        jobs: worker threads (default: the available cores), at most ``len(runs)``.
        executor: fly on any ``concurrent.futures.Executor`` instead of this process's
            threads (``ProcessPoolExecutor``, a Dask ``Client.get_executor()``): one task per
            run, each ``SimResult`` pickled back; logs are written where the task runs. The
            batch is checked here first (items, no two runs on one log); not with ``jobs``.

        errors: ``"raise"`` (default): if runs fail, the first failure in input order is
            raised. ``"keep"``: every successful run's ``SimResult`` is returned, and each failed
            run's exception (the one ``"raise"`` would raise: ``ValueError`` for a bad item or
            log, ``RuntimeError`` for a failure while flying, ...) stands in its place, so
            ``[r for r in out if isinstance(r, Exception)]`` lists the failures by index. What
            concerns the whole batch still raises (``runs`` not a sequence, two runs on one log,
            ``jobs``, an interrupt).

    Every item is loaded and validated before any run starts. A failure's message is prefixed
    with ``runs[k]``.

    Raises:
        ValueError, TypeError, OSError, KeyboardInterrupt, RuntimeError: as ``run``;
            ``ValueError`` also for an unknown dict key, ``jobs < 1`` or two runs with one log.
    """

def relaxation_sweep(
    relaxations: Optional[ArrayLike] = None,
    scenario: Optional[_ScenarioArg] = None,
    *,
    toml: Optional[str] = None,
    allocator: Optional[AllocatorName] = None,
    precision: Optional[_Precision] = None,
    mcap_dir: Optional[_PathArg] = None,
    jobs: Optional[int] = None,
    pil: Optional[_PilTarget] = None,
    max_samples: Optional[int] = None,
    executor: Optional[Any] = None,
) -> list[SimResult]:
    """The paper's relaxation study: one scenario flown once per relaxation ``s`` (in parallel
    threads, GIL released), results in the order of ``relaxations``. The planner's roll limit in
    hover is ``atan(c_y(1, s))``, so the largest planned roll grows with ``s``.

    Each run's ``scenario_name`` is ``"<name>-s<s>"`` (as ``tvmd-sim sweep``).

    Args:
        relaxations: the values of ``s``, each in (0, 1].
        scenario: as ``run`` (default ``"paper-tilt"``).
        toml: inline TOML text instead of ``scenario``.
        allocator: override the scenario's allocator.
        precision: override the controller's float type, as ``run``.
        mcap_dir: write one MCAP log per run there, ``<name>-s<s>.mcap``.
        jobs: worker threads (default: the available cores).
        executor: fly on any ``concurrent.futures.Executor`` instead of this process's
            threads (``ProcessPoolExecutor``, a Dask ``Client.get_executor()``): one task per
            run, each ``SimResult`` pickled back; logs are written where the task runs. The
            batch is checked here first (items, no two runs on one log); not with ``jobs``.
        pil: fly every run with the controller on this emulated target, as ``run``.
        max_samples: bound every run's samples, as ``run``.

    Raises:
        ValueError: as ``run``; an ``s`` outside (0, 1] or not finite, ``relaxations`` not 1-D,
            an ``s`` given twice with ``mcap_dir`` (one log written twice).
        TypeError, OSError, KeyboardInterrupt, RuntimeError: as ``run``.
    """

class Distributions(TypedDict, total=False):
    """The uniform distributions of a Monte Carlo study (docs/method.md "Monte Carlo"); a key
    left out keeps its default. Model-error half-widths are multiplied by ``model_error``."""

    model_error: float
    """Multiplier of every model-error half-width (default 1)."""
    mass: float
    """Plant mass over the model's in ``[1 - e, 1 + e]`` (default 0.02)."""
    inertia: float
    """Plant inertia over the model's in ``[1 - e, 1 + e]`` (default 0.1)."""
    com_offset: float
    """Centre-of-mass offset per axis in ``[-e, e]`` m (default 0.01)."""
    thrust_efficiency: float
    """Each agent's thrust efficiency in ``[1 - e, 1]`` (default 0.02)."""
    gimbal_offset: float
    """Each agent's gimbal offsets per axis in ``[-e, e]`` rad (default 0.01)."""
    initial_position: float
    """Initial horizontal offset per axis in ``[-e, e]`` m (default 0.1; not scaled)."""
    initial_tilt: float
    """Initial tilt in ``[0, e]`` rad about a random horizontal axis (default 0, at most 2.5;
    the scenario must start in the air)."""
    conditions: dict[str, Any]
    """Flight conditions every flight meets where the scenario sets none: ``servo`` (a servo
    model table), ``state_noise`` (a noise table; its seed is drawn per flight),
    ``feedback_latency`` (periods); default 40 rad/s servos, 1 mm / 1 cm/s / 2 mrad / 0.01 rad/s
    noise and one period. ``{"servo": None, "state_noise": None, "feedback_latency": 0}``: none.
    Off by default: ``turbulence`` (``{"wind_speed_20ft": W20, "altitude": m, "scale": 1.0,
    "seed": 0}``, Dryden, MIL-F-8785C; phases drawn per flight, on the standard's mean wind
    where the scenario has no air) and ``gust`` (``{"speed": m/s, "duration": s}``, heading
    and start drawn per flight)."""

def monte_carlo(
    scenario: Optional[_ScenarioArg] = None,
    *,
    toml: Optional[str] = None,
    runs: int = 100,
    seed: int = 0,
    teams: Optional[Iterable[str]] = None,
    allocators: Optional[Iterable[AllocatorName]] = None,
    model_errors: Optional[Iterable[float]] = None,
    distributions: Optional[Distributions] = None,
    law: Optional[_LawArg] = None,
    out: Optional[_PathArg] = None,
    jobs: Optional[int] = None,
    executor: Optional[Any] = None,
) -> dict[str, Any]:
    """A Monte Carlo study: ``runs`` flights of the scenario for every team, allocator and
    model-error level, each with a plant error and initial conditions drawn from
    ``distributions`` (flight ``k`` of a group draws from the stream ``(seed, k)``, so teams
    and allocators meet the same errors and the results do not depend on where they fly).

    Args:
        scenario, toml: as ``run`` (default ``"hover"``: the hover family, which flies the
            default law; ``"paper-tilt"`` names the paper's law, which has no integral action
            and fails every flight under model error).
        runs: flights per group.
        seed: the study's seed.
        teams: catalogue teams (``team.preset`` names); default the scenario's own.
        allocators: allocators; default the scenario's.
        model_errors: model-error multipliers, one group each; default
            ``distributions["model_error"]``.
        distributions: the half-widths (``Distributions``).
        law: the control law of every flight, as ``run``'s ``law``; default the scenario's.
        out: write ``flights.csv``, ``groups.csv`` and the box plots (PNG) into this directory.
        jobs: threads of this process (default: every core); not with ``executor``.
        executor: any ``concurrent.futures.Executor`` (``ProcessPoolExecutor``, a Dask
            ``Client.get_executor()``): each flight is one task, its spec and row JSON text.

    Returns:
        ``{"flights": [row, ...], "groups": [group, ...], "success_rate": float,
        "files": {"flights": path, "groups": path, "plots": [path, ...]} or None}``: one row
        dict per flight (what it drew and its metrics: ``success``, ``feasibility``
        (``"feasible"``, ``"infeasible"``: no admissible command of the plant as built holds
        the reference, or ``"undecided"``), ``position_steady_state``, ...; ``None`` where the
        run has no value), one dict per group (``success_rate``, ``infeasible``,
        ``feasible_success_rate``, medians); ``pandas.DataFrame(result["flights"])`` or
        ``polars.DataFrame(result["flights"])`` loads them.

    Raises:
        ValueError: as ``run``; ``runs < 1``, an unknown team, allocator or distributions key,
            a half-width out of range, a draw that makes an invalid scenario (a tilted start on
            the ground), ``jobs`` with ``executor``.
        OSError: ``out`` cannot be a report directory (an existing file, not writable),
            checked before any flight, the path named.
        KeyboardInterrupt: Ctrl-C while flying on threads: the flights stop at their next
            controller tick; the exception's ``partial`` is the report of the flights that
            finished (``"interrupted": True``, ``"flights_asked"``), no file written.
    """

def monte_carlo_specs(
    scenario: Optional[_ScenarioArg] = None,
    *,
    toml: Optional[str] = None,
    runs: int = 100,
    seed: int = 0,
    teams: Optional[Iterable[str]] = None,
    allocators: Optional[Iterable[str]] = None,
    model_errors: Optional[Iterable[float]] = None,
    distributions: Optional[Distributions] = None,
    law: Optional[_LawArg] = None,
) -> list[str]:
    """The study's flights as JSON specs, group by group (as ``monte_carlo``, nothing flown)."""

def monte_carlo_flight(spec: str) -> str:
    """Flies one JSON spec (GIL released); its row as JSON. What an executor's task runs."""

def monte_carlo_fly(specs: list[str], *, jobs: Optional[int] = None) -> list[str]:
    """Flies JSON specs on this process's threads (GIL released); rows as JSON, input order."""

def monte_carlo_report(rows: list[str], *, out: Optional[_PathArg] = None) -> dict[str, Any]:
    """The report of JSON rows, as ``monte_carlo`` returns it (with ``out``, the files too)."""


__all__ = [
    "ControllerOutput",
    "Observation",
    "ScenarioController",
    "SimResult",
    "Simulation",
    "SimulationBatch",
    "builtin_scenarios",
    "load",
    "monte_carlo",
    "monte_carlo_flight",
    "monte_carlo_fly",
    "monte_carlo_report",
    "monte_carlo_specs",
    "relaxation_sweep",
    "run",
    "run_many",
    "scenario_toml",
]
