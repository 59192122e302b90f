//! The team configuration `Xi` (paper, "Modeling"): agents, limits, navigator, and the derived
//! team mass `m_C`, inertia `J_C`, `n_x` / `n_y` and the Con/Inc arrangement.

use nalgebra::{Matrix3, Matrix6, Vector3};

use crate::afs::hover::{hover_capability, HoverCapability};
use crate::afs::AttainableForceSpace;
use crate::agent::admissible::AdmissibleSet;
use crate::agent::effectiveness::{agent_block, check_gram_rank, Effectiveness};
/// The failure mask, at its old path (now in [`crate::agent::failure`]).
pub use crate::agent::failure::FailureMask;
/// The agent limits, at their old path (now in [`crate::agent::limits`]).
pub use crate::agent::limits::AgentLimits;
use crate::foundation::definite::{is_symmetric_pd, is_symmetric_psd};
use crate::foundation::error::{ConfigError, ConfigField, MassOf};
use crate::foundation::linalg::weighted_gram;
use crate::foundation::real::{count, lit, Real};
use crate::law::Plant;

/// One agent of the team: its frame in the team CoM frame `{C}`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgentSpec<T: Real> {
    /// `p_i`: the agent's gimbal centre in `{C}` (m).
    pub position: Vector3<T>,
    /// `m_i`: the agent's yaw as a whole number of quarter turns, `psi_i = m_i pi/2`.
    /// Stored as an integer so `R_z(psi_i)` is exact.
    pub quarter_turns: i32,
    /// `m_i` of the dynamics (kg), treated as a point mass at `p_i`.
    pub mass: T,
    /// Optional inertia of the agent about its own centre, in `{C}` axes (extension of the
    /// paper's point-mass model; zero by default).
    pub inertia: Matrix3<T>,
}

impl<T: Real> AgentSpec<T> {
    /// A point-mass agent at `position` with yaw `quarter_turns * pi/2`.
    pub fn new(position: Vector3<T>, quarter_turns: i32, mass: T) -> Self {
        Self {
            position,
            quarter_turns,
            mass,
            inertia: Matrix3::zeros(),
        }
    }

    /// Whether the agent's `x` gimbal axis is aligned with the team's `x` axis (`m_i` even).
    pub fn is_x_aligned(&self) -> bool {
        self.quarter_turns.rem_euclid(2) == 0
    }

    fn placeholder() -> Self {
        Self::new(Vector3::zeros(), 0, T::zero())
    }
}

/// The navigator module at the team CoM (the paper's "1 navigator").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Navigator<T: Real> {
    /// `m_0` (kg), `>= 0`.
    pub mass: T,
    /// `J_0`, inertia about the team CoM (kg m^2), symmetric positive semi-definite.
    pub inertia: Matrix3<T>,
}

impl<T: Real> Default for Navigator<T> {
    /// No navigator mass (the paper's simulation).
    fn default() -> Self {
        Self {
            mass: T::zero(),
            inertia: Matrix3::zeros(),
        }
    }
}

/// Whether every agent's gimbal axes are aligned with the team's (paper's "Con") or not ("Inc").
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Arrangement {
    /// Consistent: every `m_i` even (`n_y = 0`).
    Con,
    /// Inconsistent: some `m_i` odd.
    Inc,
}

/// The team configuration `Xi = {(p_i, psi_i)}` with limits, masses and navigator, validated.
///
/// Fixed-capacity storage: up to `N` agents, no allocation. Mass `m_C = m_0 + sum m_i` and
/// inertia `J_C = J_0 + sum (J_i - m_i [p_i]x [p_i]x)` are derived once.
///
/// ```
/// use tvmd_core::nalgebra::Vector3;
/// use tvmd_core::{AgentLimits, AgentSpec, ConfigError, Navigator, TeamConfig};
/// let limits = AgentLimits::new(0.5, 0.7, 14.0)?;
/// let agents = [(1.0, 0.0, 0), (0.0, 1.0, 1), (-1.0, 0.0, 0), (0.0, -1.0, 1)]
///     .map(|(x, y, m)| AgentSpec::new(Vector3::new(x, y, 0.0), m, 0.7));
/// let team = TeamConfig::<f64, 8>::new(&agents, limits, Navigator::default())?;
/// assert_eq!(team.len(), 4);
/// // Two agents on a line cannot produce every wrench.
/// let e = TeamConfig::<f64, 8>::new(&agents[..2], limits, Navigator::default()).unwrap_err();
/// assert!(matches!(e, ConfigError::RankDeficient { .. }));
/// # Ok::<(), ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TeamConfig<T: Real, const N: usize> {
    agents: [AgentSpec<T>; N],
    pub(crate) len: usize,
    pub(crate) limits: AgentLimits<T>,
    navigator: Navigator<T>,
    mass: T,
    inertia: Matrix3<T>,
}

impl<T: Real, const N: usize> TeamConfig<T, N> {
    /// Validates and builds a team.
    ///
    /// Errors: [`ConfigError::NoAgents`], [`ConfigError::TooManyAgents`],
    /// [`ConfigError::NonFinite`], [`ConfigError::GimbalLimit`], [`ConfigError::NonPositiveMass`],
    /// [`ConfigError::NonPositiveThrust`], [`ConfigError::IdleThrust`],
    /// [`ConfigError::NavigatorInertia`], [`ConfigError::AgentInertia`] (not symmetric positive
    /// semi-definite), [`ConfigError::Overflow`] (finite values whose team mass, weight
    /// `m_C g` at standard gravity, `J_C`, `M M^T` or `n sigma_Tf` is not finite),
    /// [`ConfigError::RankDeficient`], [`ConfigError::NotSymmetricPositiveDefinite`] (`J_C`).
    pub fn new(
        agents: &[AgentSpec<T>],
        limits: AgentLimits<T>,
        navigator: Navigator<T>,
    ) -> Result<Self, ConfigError> {
        if agents.is_empty() {
            return Err(ConfigError::NoAgents);
        }
        if agents.len() > N {
            return Err(ConfigError::TooManyAgents {
                count: agents.len(),
                capacity: N,
            });
        }
        limits.validate()?;
        validate_navigator(&navigator)?;
        let mut storage = [AgentSpec::placeholder(); N];
        let mut mass = navigator.mass;
        let mut inertia = navigator.inertia;
        for (i, (slot, agent)) in storage.iter_mut().zip(agents).enumerate() {
            if !agent.position.iter().all(|x| x.is_finite()) {
                return Err(ConfigError::NonFinite {
                    field: ConfigField::AgentPosition,
                });
            }
            if !agent.mass.is_finite() {
                return Err(ConfigError::NonFinite {
                    field: ConfigField::AgentMass,
                });
            }
            if !agent.inertia.iter().all(|x| x.is_finite()) {
                return Err(ConfigError::NonFinite {
                    field: ConfigField::AgentInertia,
                });
            }
            if agent.mass <= T::zero() {
                return Err(ConfigError::NonPositiveMass {
                    of: MassOf::Agent(i),
                    value: crate::foundation::real::to_f64(agent.mass),
                });
            }
            if !is_symmetric_psd(&agent.inertia) {
                return Err(ConfigError::AgentInertia { agent: i });
            }
            let p = agent.position.cross_matrix();
            mass += agent.mass;
            inertia += agent.inertia - p * p * agent.mass;
            *slot = *agent;
        }
        // Finite inputs can still overflow in the sums and products the cycle uses.
        finite_derived([mass].iter(), "team mass m_C", ConfigField::AgentMass)?;
        let weight = mass * lit(presets::GRAVITY);
        finite_derived([weight].iter(), "weight m_C g", ConfigField::AgentMass)?;
        finite_derived(
            inertia.iter(),
            "team inertia J_C",
            ConfigField::AgentPosition,
        )?;
        let total_thrust = limits.max_thrust() * count::<T>(agents.len());
        finite_derived(
            [total_thrust].iter(),
            "total thrust n sigma_Tf",
            ConfigField::MaxThrust,
        )?;
        let team = Self {
            agents: storage,
            len: agents.len(),
            limits,
            navigator,
            mass,
            inertia,
        };
        let gram = team.gram(&FailureMask::none());
        finite_derived(gram.iter(), "Gram matrix M M^T", ConfigField::AgentPosition)?;
        check_gram_rank(&gram)?;
        // Rank 6 rules out collinear teams, the only ones whose point masses alone give a
        // singular J_C; this catches what rounding or a navigator inertia could still leave.
        if !is_symmetric_pd(&inertia) {
            return Err(ConfigError::NotSymmetricPositiveDefinite {
                field: ConfigField::TeamInertia,
            });
        }
        Ok(team)
    }

    /// The agents (length `n`).
    pub fn agents(&self) -> &[AgentSpec<T>] {
        self.agents.get(..self.len).unwrap_or(&[])
    }

    /// `n`, the number of agents.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always `false`: a validated team has at least one agent.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Agent limits.
    pub fn limits(&self) -> &AgentLimits<T> {
        &self.limits
    }

    /// Navigator.
    pub fn navigator(&self) -> &Navigator<T> {
        &self.navigator
    }

    /// `m_C`, the team mass (kg).
    pub fn mass(&self) -> T {
        self.mass
    }

    /// `J_C`, the team inertia about its CoM (kg m^2).
    pub fn inertia(&self) -> Matrix3<T> {
        self.inertia
    }

    /// `n_x`: working agents with even `m_i`.
    pub fn n_x(&self, failures: &FailureMask<N>) -> usize {
        self.working(failures)
            .filter(|(_, a)| a.is_x_aligned())
            .count()
    }

    /// `n_y = n - n_x` over working agents.
    pub fn n_y(&self, failures: &FailureMask<N>) -> usize {
        self.working(failures)
            .filter(|(_, a)| !a.is_x_aligned())
            .count()
    }

    /// Con if every agent's axes align with the team's, else Inc.
    pub fn arrangement(&self) -> Arrangement {
        if self.agents().iter().all(AgentSpec::is_x_aligned) {
            Arrangement::Con
        } else {
            Arrangement::Inc
        }
    }

    /// Indices and specs of the agents not marked failed.
    pub fn working<'a>(
        &'a self,
        failures: &'a FailureMask<N>,
    ) -> impl Iterator<Item = (usize, &'a AgentSpec<T>)> + 'a {
        self.agents()
            .iter()
            .enumerate()
            .filter(move |(i, _)| !failures.is_failed(*i))
    }

    /// The effectiveness model `M(Xi)` of the working agents (eq. 4).
    pub fn effectiveness(&self, failures: &FailureMask<N>) -> Effectiveness<T, N> {
        Effectiveness::new(
            self.working(failures)
                .map(|(i, a)| (i, &a.position, a.quarter_turns)),
        )
    }

    /// [`Self::effectiveness`] written into `model` in place ([`Effectiveness::assign`]).
    pub fn effectiveness_into(&self, failures: &FailureMask<N>, model: &mut Effectiveness<T, N>) {
        model.assign(
            self.working(failures)
                .map(|(i, a)| (i, &a.position, a.quarter_turns)),
        );
    }

    /// [`Self::effectiveness`] written at `model`, without a model on the stack.
    ///
    /// # Safety
    /// `model` is valid for writes and aligned; what it held is overwritten, not dropped.
    pub(crate) unsafe fn write_effectiveness(
        &self,
        failures: &FailureMask<N>,
        model: *mut Effectiveness<T, N>,
    ) {
        Effectiveness::write_new(
            model,
            self.working(failures)
                .map(|(i, a)| (i, &a.position, a.quarter_turns)),
        );
    }

    /// `M M^T` of the working agents, the same sum as [`Effectiveness::gram`], one block at a
    /// time (the checks need no whole model on the stack).
    fn gram(&self, failures: &FailureMask<N>) -> Matrix6<T> {
        self.working(failures)
            .fold(Matrix6::zeros(), |gram, (_, a)| {
                let block = agent_block(&a.position, a.quarter_turns);
                weighted_gram(gram, [(&block, T::one())])
            })
    }

    /// The attainable-force-space approximation of the working agents (eqs. 7-8).
    /// Errors with [`ConfigError::NoAgents`] when every agent failed.
    pub fn afs(&self, failures: &FailureMask<N>) -> Result<AttainableForceSpace<T>, ConfigError> {
        let n = self.working(failures).count();
        AttainableForceSpace::new(
            n,
            self.n_x(failures),
            self.limits.sigma_x(),
            self.limits.sigma_y(),
            self.limits.max_thrust(),
        )
    }

    /// Whether the working agents can hold hover at gravity `gravity` with a margin (see
    /// [`crate::afs::hover`]): the hover wrench `[0, 0, 0, 0, 0, m_C g]` strictly inside their
    /// attainable wrench set. A rank-deficient degraded team is reported not capable.
    ///
    /// Errors: [`ConfigError::FailureIndex`] or [`ConfigError::NoAgents`] for the mask;
    /// [`ConfigError::NonFinite`], [`ConfigError::Parameter`] or [`ConfigError::Overflow`]
    /// (the weight) for `gravity`.
    ///
    /// ```
    /// use tvmd_core::{team::presets, FailureMask, TeamConfig};
    /// let team: TeamConfig<f64, 4> = presets::a4_inc()?;
    /// let lost = team.hover_capability(&FailureMask::with_failed(&[1])?, 9.81)?;
    /// assert!(!lost.capable);
    /// # Ok::<(), tvmd_core::ConfigError>(())
    /// ```
    pub fn hover_capability(
        &self,
        failures: &FailureMask<N>,
        gravity: T,
    ) -> Result<HoverCapability<T>, ConfigError> {
        self.check_mask(failures)?;
        let weight = Plant::new(self.mass, self.inertia, gravity)?.weight();
        Ok(hover_capability(
            &self.effectiveness(failures),
            &AdmissibleSet::from_limits(&self.limits),
            weight,
        ))
    }

    /// Checks that a degraded team can still produce every wrench (rank-6 `M`).
    pub fn validate_failures(&self, failures: &FailureMask<N>) -> Result<(), ConfigError> {
        self.check_mask(failures)?;
        check_gram_rank(&self.gram(failures))
    }

    fn check_mask(&self, failures: &FailureMask<N>) -> Result<(), ConfigError> {
        if let Some(agent) = (self.len..N).find(|&i| failures.is_failed(i)) {
            return Err(ConfigError::FailureIndex { agent });
        }
        if self.working(failures).next().is_none() {
            return Err(ConfigError::NoAgents);
        }
        Ok(())
    }
}

fn validate_navigator<T: Real>(navigator: &Navigator<T>) -> Result<(), ConfigError> {
    if !navigator.mass.is_finite() {
        return Err(ConfigError::NonFinite {
            field: ConfigField::NavigatorMass,
        });
    }
    if !navigator.inertia.iter().all(|x| x.is_finite()) {
        return Err(ConfigError::NonFinite {
            field: ConfigField::NavigatorInertia,
        });
    }
    if navigator.mass < T::zero() {
        return Err(ConfigError::NonPositiveMass {
            of: MassOf::Navigator,
            value: crate::foundation::real::to_f64(navigator.mass),
        });
    }
    if !is_symmetric_psd(&navigator.inertia) {
        return Err(ConfigError::NavigatorInertia);
    }
    Ok(())
}

/// `Err(Overflow)` unless every entry of `values` is finite.
fn finite_derived<'a, T: Real + 'a>(
    values: impl IntoIterator<Item = &'a T>,
    quantity: &'static str,
    field: ConfigField,
) -> Result<(), ConfigError> {
    if values.into_iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(ConfigError::Overflow { quantity, field })
    }
}

/// Team presets: the authors' catalogue ([`presets::Preset`], A3 to A10 and T10), the paper's A4
/// teams, grid layouts and ring layouts for tests and the simulator.
pub mod presets;
