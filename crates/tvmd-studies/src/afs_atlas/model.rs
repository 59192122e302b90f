//! The exact wrench map of a (degraded) team: `w(x) = sum_i M_i T_i a_hat(eta_x,i, eta_y,i)`
//! (eqs. 1 and 4), its Jacobian, and the support function of the attainable wrench set's
//! convex hull.

use nalgebra::{DMatrix, Matrix6x3, Vector3, Vector6};
use tvmd_core::effectiveness::agent_block;
use tvmd_core::{ConfigError, FailureMask, GimbalCommand, TeamConfig};

use super::support::{support, AgentBox};

/// The working agents of a team: their blocks `M_i` and admissible boxes, with the data of the
/// cone they are compared with.
#[derive(Clone, Debug)]
pub struct AtlasModel {
    /// Indices (in the team) of the working agents.
    pub agents: Vec<usize>,
    blocks: Vec<Matrix6x3<f64>>,
    /// The admissible box shared by every agent.
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
            .zip(commands)
            .fold(Vector6::zeros(), |w, (b, c)| w + b * c.force())
    }

    /// `dw/dx` (6 x 3n), columns per agent `[dT / T_hi, d eta_x, d eta_y]` (thrust in units of
    /// `T_hi` so that the columns are of one scale).
    pub fn jacobian(&self, commands: &[GimbalCommand<f64>]) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(6, 3 * self.len());
        let t_hi = self.agent_box.max_thrust;
        for (i, (b, c)) in self.blocks.iter().zip(commands).enumerate() {
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
            .map(|b| {
                let (h, cmd) = support(&(b.transpose() * y), &self.agent_box);
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
