//! Team presets: the authors' catalogue ([`Preset`](crate::team::presets::Preset): A3 to A10 and T10, Con and Inc, with the
//! paper's A4 square), the paper's A4 teams, grid layouts and ring layouts for tests and the
//! simulator.

use super::*;

mod catalogue;
mod certified;
mod relaxation;

/// One row of the certified-relaxation table: `(preset, s* nominal, s* without agent i)`.
type CertifiedEntry = (Preset, Option<f64>, &'static [Option<f64>]);
pub use catalogue::{Cell, Preset};

/// Half side of the paper's square: `a = 0.5 sqrt(2)/2` m.
pub const PAPER_HALF_SIDE: f64 = 0.353_553_390_593_273_8;
/// Agent mass of the paper's simulation (kg).
pub const PAPER_AGENT_MASS: f64 = 0.7;
/// Gravity used throughout the paper (m/s^2).
pub const GRAVITY: f64 = 9.81;

/// The paper's agent limits: `sigma_x = pi/6`, `sigma_y = pi/4`, `sigma_Tf = 2 m_i g`.
pub fn paper_limits<T: Real>() -> AgentLimits<T> {
    AgentLimits::trusted(
        T::pi() / lit(6.0),
        T::frac_pi_4(),
        lit(2.0 * PAPER_AGENT_MASS * GRAVITY),
    )
}

/// A square of four agents at `(+a,+a), (+a,-a), (-a,-a), (-a,+a)` with the given quarter turns.
pub fn square<T: Real, const N: usize>(
    quarter_turns: [i32; 4],
    limits: AgentLimits<T>,
) -> Result<TeamConfig<T, N>, ConfigError> {
    let a: T = lit(PAPER_HALF_SIDE);
    let corners = [(a, a), (a, -a), (-a, -a), (-a, a)];
    let mut agents = [AgentSpec::placeholder(); 4];
    for ((agent, (x, y)), m) in agents.iter_mut().zip(corners).zip(quarter_turns) {
        *agent = AgentSpec::new(Vector3::new(x, y, T::zero()), m, lit(PAPER_AGENT_MASS));
    }
    TeamConfig::new(&agents, limits, Navigator::default())
}

/// The paper's simulated team "A4 inc, 1 navigator": `psi = [pi/2, pi/2, 0, 0]`,
/// `m_i = 0.7` kg, navigator mass 0, [`paper_limits`].
///
/// ```
/// use tvmd_core::team::presets;
/// use tvmd_core::{Arrangement, FailureMask, TeamConfig};
/// let team: TeamConfig<f64, 4> = presets::a4_inc()?;
/// assert_eq!((team.len(), team.n_x(&FailureMask::none())), (4, 2));
/// assert_eq!(team.arrangement(), Arrangement::Inc);
/// assert!((team.mass() - 2.8).abs() < 1e-12);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
pub fn a4_inc<T: Real, const N: usize>() -> Result<TeamConfig<T, N>, ConfigError> {
    square([1, 1, 0, 0], paper_limits())
}

/// As [`a4_inc`] with every agent aligned (`psi = 0`): the consistent A4 team.
pub fn a4_con<T: Real, const N: usize>() -> Result<TeamConfig<T, N>, ConfigError> {
    square([0, 0, 0, 0], paper_limits())
}

/// `n` agents of the paper's mass on a circle of `radius` in the `x-y` plane; every second
/// agent turned a quarter turn when `inconsistent` (A3..A10-like layouts).
pub fn ring<T: Real, const N: usize>(
    n: usize,
    radius: T,
    inconsistent: bool,
    limits: AgentLimits<T>,
) -> Result<TeamConfig<T, N>, ConfigError> {
    if n > N {
        return Err(ConfigError::TooManyAgents {
            count: n,
            capacity: N,
        });
    }
    let mut agents = [AgentSpec::placeholder(); N];
    for (i, agent) in agents.iter_mut().take(n).enumerate() {
        let phase = T::two_pi() * crate::foundation::real::count::<T>(i)
            / crate::foundation::real::count::<T>(n);
        let m = if inconsistent { (i % 2) as i32 } else { 0 };
        *agent = AgentSpec::new(
            Vector3::new(radius * phase.cos(), radius * phase.sin(), T::zero()),
            m,
            lit(PAPER_AGENT_MASS),
        );
    }
    TeamConfig::new(agents.get(..n).unwrap_or(&[]), limits, Navigator::default())
}

/// One agent of an authors' grid layout: cell `(x, y)` in grid units and the yaw `m` in quarter
/// turns (`psi = m pi/2`).
pub type GridCell = (i32, i32, i32);

/// The authors' layout A6-Inc (TVMD-Simulations, `simulation/system_model/team_conf/
/// model_A6_inc.m`): cells `(1,0) (0,-1) (0,1) (-1,-2) (-1,0) (-1,2)`, `psi = [pi/2 0 0 pi/2 0
/// pi/2]`.
pub const A6_INC_CELLS: [GridCell; 6] = [
    (1, 0, 1),
    (0, -1, 0),
    (0, 1, 0),
    (-1, -2, 1),
    (-1, 0, 0),
    (-1, 2, 1),
];

/// The authors' layout A8-Inc (`team_conf/model_A8_inc.m`): cells `(2,0) (1,-1) (1,1) (0,-2)
/// (0,0) (0,2) (-1,-1) (-1,1)`, `psi = [0 pi/2 pi/2 0 0 0 pi/2 pi/2]`.
pub const A8_INC_CELLS: [GridCell; 8] = [
    (2, 0, 0),
    (1, -1, 1),
    (1, 1, 1),
    (0, -2, 0),
    (0, 0, 0),
    (0, 2, 0),
    (-1, -1, 1),
    (-1, 1, 1),
];

/// Agents of the paper's mass on the authors' grid (TVMD-Simulations `team_conf/model_*.m`):
/// cell `(x, y)` at `(x, y) GRID_SIZE` with their `GRID_SIZE = 0.5 sqrt(2)/2` m
/// ([`PAPER_HALF_SIDE`]: the A4 square is the cells `(+-1, +-1)`), shifted so the cells'
/// centroid is the origin (their `pos - mean(pos, 2)`), yaw `m pi/2`.
pub fn grid<T: Real, const N: usize>(
    cells: &[GridCell],
    limits: AgentLimits<T>,
) -> Result<TeamConfig<T, N>, ConfigError> {
    if cells.len() > N {
        return Err(ConfigError::TooManyAgents {
            count: cells.len(),
            capacity: N,
        });
    }
    let mut layout = [Cell {
        x: 0,
        y: 0,
        z: 0,
        quarter_turns: 0,
    }; N];
    for (slot, &(x, y, m)) in layout.iter_mut().zip(cells) {
        *slot = Cell {
            x,
            y,
            z: 0,
            quarter_turns: m,
        };
    }
    let team: TeamConfig<T, N> = catalogue::layout_team(
        layout.get(..cells.len()).unwrap_or(&[]),
        false,
        lit(PAPER_HALF_SIDE),
        lit(PAPER_AGENT_MASS),
    )?;
    TeamConfig::new(team.agents(), limits, Navigator::default())
}

/// The authors' six-agent inconsistent team A6-Inc ([`A6_INC_CELLS`] on [`grid`]), the paper's
/// agents and [`paper_limits`].
///
/// ```
/// use tvmd_core::team::presets;
/// use tvmd_core::{Arrangement, FailureMask, TeamConfig};
/// let team: TeamConfig<f64, 6> = presets::a6_inc()?;
/// assert_eq!((team.len(), team.n_x(&FailureMask::none())), (6, 3));
/// assert_eq!(team.arrangement(), Arrangement::Inc);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
pub fn a6_inc<T: Real, const N: usize>() -> Result<TeamConfig<T, N>, ConfigError> {
    grid(&A6_INC_CELLS, paper_limits())
}

/// The authors' eight-agent inconsistent team A8-Inc ([`A8_INC_CELLS`] on [`grid`]), the
/// paper's agents and [`paper_limits`].
pub fn a8_inc<T: Real, const N: usize>() -> Result<TeamConfig<T, N>, ConfigError> {
    grid(&A8_INC_CELLS, paper_limits())
}

/// The authors' consistent A8-Con (`team_conf/model_A8_con.m`): the cells of [`a8_inc`], every
/// `psi = 0`.
pub fn a8_con<T: Real, const N: usize>() -> Result<TeamConfig<T, N>, ConfigError> {
    grid(&A8_INC_CELLS.map(|(x, y, _)| (x, y, 0)), paper_limits())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::agent::failure::FailureMask;

    fn check_layout<const N: usize>(team: &TeamConfig<f64, N>, n: usize, n_x: usize) {
        let none = FailureMask::none();
        assert_eq!((team.len(), team.n_x(&none)), (n, n_x));
        assert!((team.mass() - 0.7 * n as f64).abs() < 1e-12);
        // Centred: the CoM of equal point masses is the centroid.
        let centroid = team
            .agents()
            .iter()
            .fold(Vector3::zeros(), |c, a| c + a.position);
        assert!(centroid.norm() < 1e-12, "{centroid}");
        // Mirror symmetry y -> -y, with the yaw parity kept: J_C has no x-y product.
        for a in team.agents() {
            let mirrored = Vector3::new(a.position.x, -a.position.y, 0.0);
            assert!(team
                .agents()
                .iter()
                .any(|b| (b.position - mirrored).norm() < 1e-12
                    && b.is_x_aligned() == a.is_x_aligned()));
        }
        assert!(team.inertia()[(0, 1)].abs() < 1e-12);
        let hover = team.hover_capability(&none, GRAVITY).unwrap();
        assert!(hover.capable && hover.margin > 0.1, "{hover:?}");
    }

    #[test]
    fn authors_grid_teams() {
        let a6: TeamConfig<f64, 6> = a6_inc().unwrap();
        check_layout(&a6, 6, 3);
        assert_eq!(a6.arrangement(), Arrangement::Inc);
        // Cell (1, 0) after the centroid shift (-1/3, 0).
        let p = a6.agents()[0].position;
        assert!((p - Vector3::new(4.0 / 3.0 * PAPER_HALF_SIDE, 0.0, 0.0)).norm() < 1e-12);
        let a8: TeamConfig<f64, 8> = a8_inc().unwrap();
        check_layout(&a8, 8, 4);
        assert_eq!(a8.arrangement(), Arrangement::Inc);
        let con: TeamConfig<f64, 8> = a8_con().unwrap();
        check_layout(&con, 8, 8);
        assert_eq!(con.arrangement(), Arrangement::Con);
        // The A4 square is the cells (+-1, +-1) of the same grid.
        let a4: TeamConfig<f64, 4> = grid(
            &[(1, 1, 1), (1, -1, 1), (-1, -1, 0), (-1, 1, 0)],
            paper_limits(),
        )
        .unwrap();
        assert_eq!(a4, a4_inc().unwrap());
        // f32 builds the same layouts; too small a capacity is a typed error.
        assert!(a8_inc::<f32, 8>().is_ok());
        assert!(matches!(
            a8_inc::<f64, 6>(),
            Err(ConfigError::TooManyAgents {
                count: 8,
                capacity: 6
            })
        ));
    }
}
