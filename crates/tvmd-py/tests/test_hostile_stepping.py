"""The hostile suite of the steppable surfaces (issue 57): property-based tests of
``tvmd.sim.Simulation``, ``SimulationBatch``, the Gymnasium environments and ``tvmd.sim.load``.

Random shapes, dtypes and values (NaN, infinities, extreme magnitudes) as actions; random
environment arguments and actions; files of every kind given to ``load`` (random bytes, MCAP's
magic then random bytes, a real log cut at a random point or with random bytes overwritten, a
directory, a device). Each call must end in a typed error (``ValueError``, ``TypeError``,
``OSError``; ``RuntimeError`` only for a diverged flight) or a valid result, under a watchdog
(``KeyboardInterrupt`` in the main thread after ``HANG`` seconds). A valid step holds what the
hardware can do: the plant's gimbal angles within their limits, thrusts in ``[0, sigma_Tf]``,
and ``saturation`` the commands minus what was held. Derandomized, as the rest of the suite.
"""

from __future__ import annotations

import _thread
import math
import os
import threading
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tvmd import sim

TYPED = (ValueError, TypeError, OSError)
HANG = 20.0
SETTINGS = settings(
    max_examples=40,
    deadline=None,
    derandomize=True,
    database=None,
    suppress_health_check=list(HealthCheck),
)
FLOATS = st.one_of(
    st.sampled_from([math.nan, math.inf, -math.inf, 0.0, -0.0, 1e308, -1e308, 5e-324, 2.0, -2.0, 30.0]),
    st.floats(-100, 100),
    st.floats(allow_nan=True, allow_infinity=True),
)
DTYPES = st.sampled_from([np.float64, np.float32, np.int64, np.bool_])


class Watchdog:
    """Interrupts the main thread if the body takes longer than `HANG` seconds."""

    def __enter__(self):
        self.timer = threading.Timer(HANG, _thread.interrupt_main)
        self.timer.start()

    def __exit__(self, *exc):
        self.timer.cancel()
        return False


def actions(n):
    """Commands of random shape and dtype, mostly (n, 3) or (n, 4) of hostile values."""
    right = hnp.arrays(np.float64, st.sampled_from([(n, 3), (n, 4)]), elements=FLOATS)
    other = hnp.arrays(DTYPES, hnp.array_shapes(min_dims=0, max_dims=3, max_side=6), elements=None)
    return st.one_of(right, right, other, st.lists(FLOATS, max_size=6), st.none(), st.text(max_size=3))


def assert_inside_the_hardware(simulation, held):
    sx, sy = simulation.gimbal_limits
    top = simulation.max_thrust
    assert np.isfinite(held).all()
    assert (np.abs(held[:, 0]) <= sx * (1 + 1e-7)).all() and (np.abs(held[:, 1]) <= sy * (1 + 1e-7)).all()
    assert (held[:, 2] >= 0.0).all() and (held[:, 2] <= top * (1 + 1e-7)).all()


@SETTINGS
@given(data=st.data())
def test_random_actions_are_refused_or_held_inside_the_hardware(data):
    s = sim.Simulation("hover")
    s.reset(seed=0)
    for _ in range(3):
        action = data.draw(actions(s.n_agents))
        rotor_speeds = data.draw(st.booleans())
        before = s.time
        with Watchdog():
            try:
                obs = s.step(action, rotor_speeds=rotor_speeds)
            except TYPED:
                assert s.time == before, "a refused action changes nothing"
                continue
            except RuntimeError as e:
                assert "diverg" in str(e).lower() or "exceeds" in str(e), e
                return
        a = np.asarray(action, dtype=np.float64)
        commanded = a[:, :3].copy()
        if rotor_speeds:
            commanded[:, 2] = s.max_thrust * a[:, -1] ** 2
        held = commanded - obs.saturation
        assert_inside_the_hardware(s, held)
        # Inside the range nothing is clamped.
        inside = (np.abs(commanded[:, 0]) <= s.gimbal_limits[0]) & (np.abs(commanded[:, 1]) <= s.gimbal_limits[1])
        inside &= (commanded[:, 2] >= 0) & (commanded[:, 2] <= s.max_thrust)
        assert (obs.saturation[inside] == 0.0).all()
    r = s.result()
    if len(r):
        actual = r.actual[~np.isnan(r.actual).any(axis=(1, 2))]
        for held in actual:
            assert_inside_the_hardware(s, held)


@SETTINGS
@given(data=st.data())
def test_random_batch_actions_are_refused_or_held_inside_the_hardware(data):
    b = sim.SimulationBatch("hover", count=2, jobs=1)
    b.reset()
    n = b.n_agents
    right = hnp.arrays(np.float64, st.sampled_from([(2, n, 3), (2, n, 4)]), elements=FLOATS)
    other = hnp.arrays(DTYPES, hnp.array_shapes(min_dims=0, max_dims=4, max_side=5), elements=None)
    action = data.draw(st.one_of(right, right, other))
    with Watchdog():
        try:
            d = b.step(action)
        except TYPED:
            return
    assert d["saturation"].shape == (2, n, 3)
    for k in range(2):
        if d["errors"][k] is None:
            assert np.isfinite(d["saturation"][k]).all()
            assert np.isfinite(d["position"][k]).all()


gym = pytest.importorskip("gymnasium")
import tvmd.gym as tgym  # noqa: E402

ENV_ARGS = st.fixed_dictionaries(
    {},
    optional={
        "initial_offset": st.one_of(FLOATS, st.text(max_size=2)),
        "initial_tilt": FLOATS,
        "max_position_error": FLOATS,
        "max_tilt": FLOATS,
        "weights": st.dictionaries(
            st.sampled_from(["alive", "position", "velocity", "attitude", "rate", "action", "x"]),
            st.one_of(FLOATS, st.text(max_size=2)),
            max_size=3,
        ),
        "action": st.sampled_from(["wrench", "commands", "thrust"]),
    },
)


@settings(SETTINGS, max_examples=30)
@given(kwargs=ENV_ARGS, data=st.data())
def test_environments_refuse_bad_arguments_or_step_finite(kwargs, data):
    with Watchdog():
        try:
            env = gym.make(tgym.HOVER_ID, **kwargs)
        except TYPED:
            return
        obs, _ = env.reset(seed=data.draw(st.integers(0, 2**32)))
        assert obs.shape == (18,) and np.isfinite(obs).all()
        shape = env.action_space.shape
        for _ in range(3):
            action = data.draw(hnp.arrays(np.float64, shape, elements=FLOATS))
            try:
                obs, reward, terminated, truncated, info = env.step(action)
            except ValueError:
                assert not np.isfinite(action).all(), "a finite action is clipped, never refused"
                continue
            assert np.isfinite(obs).all() and math.isfinite(reward)
            if terminated or truncated:
                break


@pytest.fixture(scope="module")
def log_bytes(tmp_path_factory):
    path = tmp_path_factory.mktemp("log") / "short.mcap"
    flown = sim.run(toml='name = "short"\nduration = 0.3\n', mcap=path)
    return path.read_bytes(), len(flown)


def files(whole):
    cut = st.integers(0, len(whole)).map(lambda k: whole[:k])
    flipped = st.tuples(st.integers(0, len(whole) - 1), st.binary(min_size=1, max_size=16)).map(
        lambda p: whole[: p[0]] + p[1] + whole[p[0] + len(p[1]) :]
    )
    return st.one_of(
        st.binary(max_size=64),
        st.binary(max_size=256).map(lambda b: b"\x89MCAP0\r\n" + b),
        cut,
        flipped,
    )


@settings(SETTINGS, max_examples=60)
@given(data=st.data())
def test_load_reads_any_file_or_fails_typed(log_bytes, tmp_path_factory, data):
    whole, ticks = log_bytes
    path = tmp_path_factory.mktemp("f") / "x.mcap"
    content = data.draw(files(whole))
    path.write_bytes(content)
    with Watchdog(), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            r = sim.load(path)
        except TYPED:
            return
    assert 0 < len(r) <= ticks
    assert r.position.shape == (len(r), 3)


def test_load_refuses_what_is_not_a_regular_file(tmp_path):
    with pytest.raises(OSError, match="not a regular file"):
        sim.load(tmp_path)
    if os.path.exists("/dev/null"):
        with pytest.raises(OSError, match="not a regular file"):
            sim.load("/dev/null")
