//! The exact wrench map of a (degraded) team: `w(x) = sum_i M_i T_i a_hat(eta_x,i, eta_y,i)`
//! (eqs. 1 and 4), its Jacobian, and the support function of the attainable wrench set's
//! convex hull; with an actuation error ([`AgentActuation`]) the map of the plant as built,
//! `w(x) = sum_i M_i e_i T_i a_hat(eta_x,i + d_x,i, eta_y,i + d_y,i)`.

use nalgebra::{DMatrix, Matrix6x3, Vector3, Vector6};
use tvmd_core::effectiveness::agent_block;
use tvmd_core::{ConfigError, FailureMask, GimbalCommand, TeamConfig};

use super::support::{support, support_shifted, AgentBox};

/// One agent's actuation as built: the plant makes `efficiency T a_hat(eta_x + d_x,
/// eta_y + d_y)` for the command `(T, eta_x, eta_y)` (the simulator's rotor efficiency and
/// gimbal offsets, `tvmd_scenario::PlantError`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AgentActuation {
    /// Share of the commanded thrust the rotor makes, in `[0, 2]`.
    pub efficiency: f64,
    /// `(d_x, d_y)`: how far off each gimbal axis turns from its command (rad).
    pub gimbal_offset: [f64; 2],
}

impl AgentActuation {
    /// No error: efficiency 1, no offsets.
    pub const NOMINAL: Self = Self {
        efficiency: 1.0,
        gimbal_offset: [0.0; 2],
    };

    fn is_nominal(&self) -> bool {
        *self == Self::NOMINAL
    }

    /// The force the plant makes for `cmd` (agent frame).
    fn force(&self, cmd: &GimbalCommand<f64>) -> Vector3<f64> {
        if self.is_nominal() {
            return cmd.force();
        }
        self.true_command(cmd).force() * self.efficiency
    }

    /// `cmd` with the gimbal offsets added: the angles the gimbal really turns to.
    fn true_command(&self, cmd: &GimbalCommand<f64>) -> GimbalCommand<f64> {
        GimbalCommand {
            thrust: cmd.thrust,
            eta_x: cmd.eta_x + self.gimbal_offset[0],
            eta_y: cmd.eta_y + self.gimbal_offset[1],
        }
    }
}

/// The working agents of a team: their blocks `M_i` and admissible boxes, with the data of the
/// cone they are compared with.
#[derive(Clone, Debug)]
pub struct AtlasModel {
    /// Indices (in the team) of the working agents.
    pub agents: Vec<usize>,
    blocks: Vec<Matrix6x3<f64>>,
    /// Per working agent, its actuation as built (nominal unless
    /// [`AtlasModel::with_actuation`] says otherwise).
    actuation: Vec<AgentActuation>,
    /// The admissible box of the commands, shared by every agent.
    pub agent_box: AgentBox,
    /// `m_C` (kg) of the whole team (failed agents still carry mass).
    pub mass: f64,
    /// The cone's approximation of the working agents (eqs. 7-8).
    pub afs: tvmd_core::AttainableForceSpace<f64>,
}

impl AtlasModel {
    /// The working agents of `team` under `failures`.
    pub fn new<const N: usize>(
        team: &TeamConfig<f64, N>,
        failures: &FailureMask<N>,
    ) -> Result<Self, ConfigError> {
        team.validate_failures(failures)?;
        let limits = team.limits();
        let working: Vec<(usize, Matrix6x3<f64>)> = team
            .working(failures)
            .map(|(i, a)| (i, agent_block(&a.position, a.quarter_turns)))
            .collect();
        Ok(Self {
            actuation: vec![AgentActuation::NOMINAL; working.len()],
            agents: working.iter().map(|(i, _)| *i).collect(),
            blocks: working.into_iter().map(|(_, b)| b).collect(),
            agent_box: AgentBox {
                min_thrust: limits.min_thrust(),
                max_thrust: limits.max_thrust(),
                sigma_x: limits.sigma_x(),
                sigma_y: limits.sigma_y(),
            },
            mass: team.mass(),
            afs: team.afs(failures)?,
        })
    }

    /// The model of the plant as built: `actuation[k]` for the `k`-th working agent. `Err`
    /// (naming the agent) for a count other than [`AtlasModel::len`], an efficiency outside
    /// `[0, 2]` or an offset that turns a gimbal past `pi/2` (where the closed-form support
    /// function no longer holds).
    pub fn with_actuation(mut self, actuation: &[AgentActuation]) -> Result<Self, String> {
        if actuation.len() != self.len() {
            return Err(format!(
                "{} actuation errors for {} working agents",
                actuation.len(),
                self.len()
            ));
        }
        let b = &self.agent_box;
        for (k, a) in actuation.iter().enumerate() {
            let [dx, dy] = a.gimbal_offset;
            let ok = (0.0..=2.0).contains(&a.efficiency)
                && dx.is_finite()
                && dy.is_finite()
                && b.sigma_x + dx.abs() <= std::f64::consts::FRAC_PI_2
                && b.sigma_y + dy.abs() <= std::f64::consts::FRAC_PI_2;
            if !ok {
                return Err(format!(
                    "agent {}: efficiency {} and gimbal offsets {:?} outside [0, 2] and \
                     sigma + |offset| <= pi/2",
                    self.agents[k], a.efficiency, a.gimbal_offset
                ));
            }
        }
        self.actuation = actuation.to_vec();
        Ok(self)
    }

    /// Per working agent, its actuation as built.
    pub fn actuation(&self) -> &[AgentActuation] {
        &self.actuation
    }

    /// Working agents.
    pub fn len(&self) -> usize {
        self.blocks.len()
    }

    /// Always `false` (a model has a working agent).
    pub fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    /// A force scale: `n sigma_Tf` (N).
    pub fn scale(&self) -> f64 {
        self.len() as f64 * self.agent_box.max_thrust
    }

    /// `w(x)`, rows `[torque; force]` in the team frame.
    pub fn wrench(&self, commands: &[GimbalCommand<f64>]) -> Vector6<f64> {
        self.blocks
            .iter()
            .zip(&self.actuation)
            .zip(commands)
            .fold(Vector6::zeros(), |w, ((b, a), c)| w + b * a.force(c))
    }

    /// `dw/dx` (6 x 3n), columns per agent `[dT / T_hi, d eta_x, d eta_y]` (thrust in units of
    /// `T_hi` so that the columns are of one scale).
    pub fn jacobian(&self, commands: &[GimbalCommand<f64>]) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(6, 3 * self.len());
        let t_hi = self.agent_box.max_thrust;
        for (i, ((b, act), c)) in self
            .blocks
            .iter()
            .zip(&self.actuation)
            .zip(commands)
            .enumerate()
        {
            let (b, c) = if act.is_nominal() {
                (*b, *c)
            } else {
                (b * act.efficiency, act.true_command(c))
            };
            let (sx, cx) = c.eta_x.sin_cos();
            let (sy, cy) = c.eta_y.sin_cos();
            let a = Vector3::new(cx * sy, -sx, cx * cy);
            let da_x = Vector3::new(-sx * sy, -cx, -sx * cy) * c.thrust;
            let da_y = Vector3::new(cx * cy, 0.0, -cx * sy) * c.thrust;
            for (k, col) in [a * t_hi, da_x, da_y].iter().enumerate() {
                j.column_mut(3 * i + k).copy_from(&(b * col));
            }
        }
        j
    }

    /// `h(y) = sum_i h_i(M_i^T y)`, the support function of the attainable wrench set (and of
    /// its convex hull) in the direction `y`, and the maximizing commands.
    pub fn support(&self, y: &Vector6<f64>) -> (f64, Vec<GimbalCommand<f64>>) {
        let mut total = 0.0;
        let commands = self
            .blocks
            .iter()
            .zip(&self.actuation)
            .map(|(b, a)| {
                let c = b.transpose() * y;
                let (h, cmd) = if a.is_nominal() {
                    support(&c, &self.agent_box)
                } else {
                    let (h, cmd) = support_shifted(&c, &self.agent_box, a.gimbal_offset);
                    (h * a.efficiency, cmd)
                };
                total += h;
                cmd
            })
            .collect();
        (total, commands)
    }

    /// Every agent straight up at `thrust` (clamped into the box).
    pub fn level(&self, thrust: f64) -> Vec<GimbalCommand<f64>> {
        let cmd = self.agent_box.clamp(GimbalCommand {
            thrust,
            eta_x: 0.0,
            eta_y: 0.0,
        });
        vec![cmd; self.len()]
    }
}
