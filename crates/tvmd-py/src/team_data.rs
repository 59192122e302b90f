//! The data `tvmd.Team` pickles (`Team.__reduce__`, `Team._restore`): enough to build the same
//! team again, bit for bit.

use nalgebra::{Matrix3, Vector3};

use tvmd_core::{AgentLimits, AgentSpec, Navigator, TeamConfig};

use crate::convert::CAPACITY;

/// A team's constructing data, as `Team.__reduce__` pickles it: per agent its position,
/// quarter turns, mass and row-major inertia; the limits `(sigma_x, sigma_y, max_thrust,
/// min_thrust, thrust_coefficient)`; the navigator's mass and row-major inertia.
pub(crate) struct TeamData {
    pub(crate) positions: Vec<[f64; 3]>,
    pub(crate) quarter_turns: Vec<i32>,
    pub(crate) masses: Vec<f64>,
    pub(crate) agent_inertias: Vec<[f64; 9]>,
    pub(crate) limits: (f64, f64, f64, f64, f64),
    pub(crate) navigator_mass: f64,
    pub(crate) navigator_inertia: [f64; 9],
}

/// A row-major 3x3 matrix.
fn rows(m: &Matrix3<f64>) -> [f64; 9] {
    let mut out = [0.0; 9];
    out.iter_mut()
        .zip(m.transpose().iter())
        .for_each(|(o, v)| *o = *v);
    out
}

/// `TeamData` as the arguments of `Team._restore`.
pub(crate) type TeamArgs = (
    Vec<[f64; 3]>,
    Vec<i32>,
    Vec<f64>,
    Vec<[f64; 9]>,
    (f64, f64, f64, f64, f64),
    f64,
    [f64; 9],
);

impl TeamData {
    /// The data of `team`.
    pub(crate) fn of(team: &TeamConfig<f64, CAPACITY>) -> Self {
        let agents = team.agents();
        let l = team.limits();
        Self {
            positions: agents.iter().map(|a| a.position.into()).collect(),
            quarter_turns: agents.iter().map(|a| a.quarter_turns).collect(),
            masses: agents.iter().map(|a| a.mass).collect(),
            agent_inertias: agents.iter().map(|a| rows(&a.inertia)).collect(),
            limits: (
                l.sigma_x(),
                l.sigma_y(),
                l.max_thrust(),
                l.min_thrust(),
                l.thrust_coefficient(),
            ),
            navigator_mass: team.navigator().mass,
            navigator_inertia: rows(&team.navigator().inertia),
        }
    }

    /// The fields in `Team._restore`'s order.
    pub(crate) fn args(self) -> TeamArgs {
        (
            self.positions,
            self.quarter_turns,
            self.masses,
            self.agent_inertias,
            self.limits,
            self.navigator_mass,
            self.navigator_inertia,
        )
    }

    /// The team again. Limits whose thrust coefficient is not `max_thrust` (`Team.from_rotor`)
    /// come from eq. (5) with `rho d^4 c_l` the coefficient and the rotor speed whose thrust is
    /// `max_thrust` exactly (the speed's neighbours within a few units in the last place).
    pub(crate) fn team(&self) -> Result<TeamConfig<f64, CAPACITY>, tvmd_core::ConfigError> {
        let (sigma_x, sigma_y, max_thrust, min_thrust, coefficient) = self.limits;
        let limits = if coefficient == max_thrust {
            AgentLimits::new(sigma_x, sigma_y, max_thrust)?
        } else {
            let speed = (max_thrust / coefficient).sqrt();
            let rotor =
                |s: f64| AgentLimits::from_rotor(sigma_x, sigma_y, coefficient, 1.0, 1.0, s);
            let mut candidates = (0..8u64).flat_map(|k| {
                [
                    f64::from_bits(speed.to_bits().wrapping_add(k)),
                    f64::from_bits(speed.to_bits().wrapping_sub(k)),
                ]
            });
            match candidates.find_map(|s| rotor(s).ok().filter(|l| l.max_thrust() == max_thrust)) {
                Some(l) => l,
                None => rotor(speed)?,
            }
        };
        let agents: Vec<AgentSpec<f64>> = self
            .positions
            .iter()
            .zip(&self.quarter_turns)
            .zip(&self.masses)
            .zip(&self.agent_inertias)
            .map(|(((p, m), mass), inertia)| {
                let mut agent = AgentSpec::new(Vector3::from(*p), *m, *mass);
                agent.inertia = Matrix3::from_row_slice(inertia);
                agent
            })
            .collect();
        let navigator = Navigator {
            mass: self.navigator_mass,
            inertia: Matrix3::from_row_slice(&self.navigator_inertia),
        };
        TeamConfig::new(&agents, limits.with_min_thrust(min_thrust)?, navigator)
    }
}
