//! The authors' team catalogue (TVMD-Simulations, `simulation/system_model/team_conf/model_*.m`):
//! A3 to A10 and the three-dimensional T10, each consistent (Con, every `psi_i = 0`) and
//! inconsistent (Inc, the authors' yaws), plus the authors' diamond A4 beside the paper's square.
//!
//! Every layout is a set of cells of the authors' diagonal grid: cell `(x, y, z)` sits at
//! `(x, y, z) GRID_SIZE` with `GRID_SIZE = 0.5 sqrt(2)/2` m ([`PAPER_HALF_SIDE`]), shifted so the
//! cells' centroid is the origin; neighbouring agents (cells one step apart in both `x` and `y`)
//! are 0.5 m apart. Agents carry the paper's mass and limits ([`paper_limits`]); the authors'
//! own files use 0.674 kg agents, `sigma_y = pi/2` and `sigma_Tf = 1.5 m_i g`, which we do not
//! copy so that every preset flies with the paper's agent. The navigator is massless (the
//! paper's simulation).

use super::{paper_limits, ConfigError, Real, TeamConfig, PAPER_AGENT_MASS, PAPER_HALF_SIDE};
use crate::foundation::real::{count, lit};
use crate::team::{AgentSpec, Navigator};
use nalgebra::Vector3;

/// One agent of a catalogue layout: its grid cell and yaw `psi = quarter_turns pi/2` (the
/// inconsistent variant's; the consistent variant sets every yaw to zero).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cell {
    /// Grid column (along the team's `x`).
    pub x: i32,
    /// Grid row (along the team's `y`).
    pub y: i32,
    /// Grid layer (along the team's `z`; nonzero only in T10).
    pub z: i32,
    /// `m_i` of the inconsistent variant.
    pub quarter_turns: i32,
}

const fn c(x: i32, y: i32, quarter_turns: i32) -> Cell {
    Cell {
        x,
        y,
        z: 0,
        quarter_turns,
    }
}

const fn c3(x: i32, y: i32, z: i32, quarter_turns: i32) -> Cell {
    Cell {
        x,
        y,
        z,
        quarter_turns,
    }
}

/// The cells of a planar layout given as `(x, y, m)`.
// Only evaluated for `const` items: an index out of range fails the build, it cannot panic
// at run time.
#[allow(clippy::indexing_slicing)]
const fn planar<const K: usize>(cells: &[super::GridCell; K]) -> [Cell; K] {
    let mut out = [c(0, 0, 0); K];
    let mut i = 0;
    while i < K {
        let (x, y, m) = cells[i];
        out[i] = c(x, y, m);
        i += 1;
    }
    out
}

/// A3 (`model_A3_inc.m`): a triangle, the front agent turned.
const A3: [Cell; 3] = [c(4, 0, 1), c(3, -1, 0), c(3, 1, 0)];
/// The paper's A4 square (`model_A4_inc_1_nav.m`, the paper's "A4 inc, 1 navigator"): the
/// cells `(+-1, +-1)`, the front pair turned; agent order as [`super::square`].
const A4_SQUARE: [Cell; 4] = [c(1, 1, 1), c(1, -1, 1), c(-1, -1, 0), c(-1, 1, 0)];
/// The authors' A4 (`model_A4_inc.m`): a diamond, front and back agents turned.
const A4_DIAMOND: [Cell; 4] = [c(1, 0, 1), c(0, -1, 0), c(0, 1, 0), c(-1, 0, 1)];
/// A5 (`model_A5_inc.m`): the square with a centre agent, the front pair and the centre turned.
const A5: [Cell; 5] = [
    c(1, 1, 1),
    c(1, -1, 1),
    c(0, 0, 1),
    c(-1, 1, 0),
    c(-1, -1, 0),
];
/// A6 (`model_A6_inc.m`), as [`super::A6_INC_CELLS`].
const A6: [Cell; 6] = planar(&super::A6_INC_CELLS);
/// A7 (`model_A7_inc.m`): a hexagon with a centre agent, the four corners turned.
const A7: [Cell; 7] = [
    c(1, -1, 1),
    c(1, 1, 1),
    c(0, -2, 0),
    c(0, 0, 0),
    c(0, 2, 0),
    c(-1, -1, 1),
    c(-1, 1, 1),
];
/// A8 (`model_A8_inc.m`), as [`super::A8_INC_CELLS`].
const A8: [Cell; 8] = planar(&super::A8_INC_CELLS);
/// A9 (`model_A9_inc.m`): a diamond of nine agents.
const A9: [Cell; 9] = [
    c(2, 0, 0),
    c(1, -1, 1),
    c(1, 1, 1),
    c(0, -2, 0),
    c(0, 0, 1),
    c(0, 2, 0),
    c(-1, -1, 1),
    c(-1, 1, 1),
    c(-2, 0, 0),
];
/// A10 (`model_A10_inc.m`): a triangle of ten agents, rows of 1, 2, 3 and 4.
const A10: [Cell; 10] = [
    c(4, 0, 1),
    c(3, -1, 1),
    c(3, 1, 1),
    c(2, -2, 0),
    c(2, 0, 0),
    c(2, 2, 0),
    c(1, -3, 1),
    c(1, -1, 0),
    c(1, 1, 0),
    c(1, 3, 1),
];
/// T10 (`model_T10_inc.m`): nine agents in a plane and one a layer above (cell `(0, -2, 1)`).
const T10: [Cell; 10] = [
    c3(-1, 3, 0, 1),
    c3(1, 3, 0, 1),
    c3(0, 2, 0, 0),
    c3(-1, 1, 0, 0),
    c3(1, 1, 0, 0),
    c3(-1, -1, 0, 1),
    c3(1, -1, 0, 1),
    c3(-2, -2, 0, 0),
    c3(0, -2, 1, 0),
    c3(2, -2, 0, 0),
];

/// A team of the catalogue (see the module docs). `Preset::ALL` lists them; [`Preset::name`]
/// is the spelling of the simulator's `team.preset` and of Python's `Team.preset`.
///
/// ```
/// use tvmd_core::team::presets::Preset;
/// use tvmd_core::{Arrangement, FailureMask, TeamConfig};
/// let preset = Preset::from_name("a6-inc").unwrap();
/// let team: TeamConfig<f64, 16> = preset.team()?;
/// assert_eq!((team.len(), team.n_x(&FailureMask::none())), (6, 3));
/// assert_eq!(team.arrangement(), Arrangement::Inc);
/// assert_eq!(Preset::ALL.len(), 20);
/// # Ok::<(), tvmd_core::ConfigError>(())
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[allow(missing_docs)]
pub enum Preset {
    A3Con,
    A3Inc,
    A4Con,
    A4Inc,
    A4DiamondCon,
    A4DiamondInc,
    A5Con,
    A5Inc,
    A6Con,
    A6Inc,
    A7Con,
    A7Inc,
    A8Con,
    A8Inc,
    A9Con,
    A9Inc,
    A10Con,
    A10Inc,
    T10Con,
    T10Inc,
}

impl Preset {
    /// Every catalogue team, Con before Inc, by size.
    pub const ALL: [Preset; 20] = [
        Self::A3Con,
        Self::A3Inc,
        Self::A4Con,
        Self::A4Inc,
        Self::A4DiamondCon,
        Self::A4DiamondInc,
        Self::A5Con,
        Self::A5Inc,
        Self::A6Con,
        Self::A6Inc,
        Self::A7Con,
        Self::A7Inc,
        Self::A8Con,
        Self::A8Inc,
        Self::A9Con,
        Self::A9Inc,
        Self::A10Con,
        Self::A10Inc,
        Self::T10Con,
        Self::T10Inc,
    ];

    /// The preset's name: `"a3-con"`, `"a4-inc"`, `"a4-diamond-inc"`, `"t10-con"`, ...
    pub const fn name(self) -> &'static str {
        match self {
            Self::A3Con => "a3-con",
            Self::A3Inc => "a3-inc",
            Self::A4Con => "a4-con",
            Self::A4Inc => "a4-inc",
            Self::A4DiamondCon => "a4-diamond-con",
            Self::A4DiamondInc => "a4-diamond-inc",
            Self::A5Con => "a5-con",
            Self::A5Inc => "a5-inc",
            Self::A6Con => "a6-con",
            Self::A6Inc => "a6-inc",
            Self::A7Con => "a7-con",
            Self::A7Inc => "a7-inc",
            Self::A8Con => "a8-con",
            Self::A8Inc => "a8-inc",
            Self::A9Con => "a9-con",
            Self::A9Inc => "a9-inc",
            Self::A10Con => "a10-con",
            Self::A10Inc => "a10-inc",
            Self::T10Con => "t10-con",
            Self::T10Inc => "t10-inc",
        }
    }

    /// The preset named `name` ([`Preset::name`]; `_` may stand for `-`, case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        let same = |known: &str| {
            known.len() == name.len()
                && known.bytes().zip(name.bytes()).all(|(k, b)| {
                    let b = b.to_ascii_lowercase();
                    k == b || (k == b'-' && b == b'_')
                })
        };
        Self::ALL.into_iter().find(|p| same(p.name()))
    }

    /// Whether this is the consistent variant (every `psi_i = 0`).
    pub const fn is_consistent(self) -> bool {
        matches!(
            self,
            Self::A3Con
                | Self::A4Con
                | Self::A4DiamondCon
                | Self::A5Con
                | Self::A6Con
                | Self::A7Con
                | Self::A8Con
                | Self::A9Con
                | Self::A10Con
                | Self::T10Con
        )
    }

    /// The layout's cells with the inconsistent variant's yaws.
    pub const fn cells(self) -> &'static [Cell] {
        match self {
            Self::A3Con | Self::A3Inc => &A3,
            Self::A4Con | Self::A4Inc => &A4_SQUARE,
            Self::A4DiamondCon | Self::A4DiamondInc => &A4_DIAMOND,
            Self::A5Con | Self::A5Inc => &A5,
            Self::A6Con | Self::A6Inc => &A6,
            Self::A7Con | Self::A7Inc => &A7,
            Self::A8Con | Self::A8Inc => &A8,
            Self::A9Con | Self::A9Inc => &A9,
            Self::A10Con | Self::A10Inc => &A10,
            Self::T10Con | Self::T10Inc => &T10,
        }
    }

    /// `n`, the number of agents.
    pub const fn len(self) -> usize {
        self.cells().len()
    }

    /// Always `false`: every layout has agents.
    pub const fn is_empty(self) -> bool {
        self.cells().is_empty()
    }

    /// The authors' file the layout comes from (in TVMD-Simulations).
    pub const fn source(self) -> &'static str {
        match self {
            Self::A3Con | Self::A3Inc => "team_conf/model_A3_inc.m",
            Self::A4Con | Self::A4Inc => "team_conf/model_A4_inc_1_nav.m",
            Self::A4DiamondCon | Self::A4DiamondInc => "team_conf/model_A4_inc.m",
            Self::A5Con | Self::A5Inc => "team_conf/model_A5_inc.m",
            Self::A6Con | Self::A6Inc => "team_conf/model_A6_inc.m",
            Self::A7Con | Self::A7Inc => "team_conf/model_A7_inc.m",
            Self::A8Con | Self::A8Inc => "team_conf/model_A8_inc.m",
            Self::A9Con | Self::A9Inc => "team_conf/model_A9_inc.m",
            Self::A10Con | Self::A10Inc => "team_conf/model_A10_inc.m",
            Self::T10Con | Self::T10Inc => "team_conf/model_T10_inc.m",
        }
    }

    /// The team with the paper's agents ([`paper_limits`], 0.7 kg, massless navigator).
    /// Errors: [`ConfigError::TooManyAgents`] when `N < self.len()`.
    pub fn team<T: Real, const N: usize>(self) -> Result<TeamConfig<T, N>, ConfigError> {
        self.team_with(lit(PAPER_HALF_SIDE), lit(PAPER_AGENT_MASS))
    }

    /// The team on a grid of `unit` metres (the paper's is [`PAPER_HALF_SIDE`]) with agents of
    /// `mass` kg and [`paper_limits`].
    pub fn team_with<T: Real, const N: usize>(
        self,
        unit: T,
        mass: T,
    ) -> Result<TeamConfig<T, N>, ConfigError> {
        let consistent = self.is_consistent();
        layout_team(self.cells(), consistent, unit, mass)
    }
}

/// The team of `cells` on a grid of `unit`, centred on the cells' centroid.
pub(super) fn layout_team<T: Real, const N: usize>(
    cells: &[Cell],
    consistent: bool,
    unit: T,
    mass: T,
) -> Result<TeamConfig<T, N>, ConfigError> {
    if cells.len() > N {
        return Err(ConfigError::TooManyAgents {
            count: cells.len(),
            capacity: N,
        });
    }
    let n = count::<T>(cells.len().max(1));
    let sum = cells.iter().fold([0_i32; 3], |s, c| {
        [
            s[0].saturating_add(c.x),
            s[1].saturating_add(c.y),
            s[2].saturating_add(c.z),
        ]
    });
    let centroid = sum.map(|s| lit::<T>(f64::from(s)) / n);
    let mut agents = [AgentSpec::placeholder(); N];
    for (agent, cell) in agents.iter_mut().zip(cells) {
        let at = |k: i32, centre: T| (lit::<T>(f64::from(k)) - centre) * unit;
        let position = Vector3::new(
            at(cell.x, centroid[0]),
            at(cell.y, centroid[1]),
            at(cell.z, centroid[2]),
        );
        let m = if consistent { 0 } else { cell.quarter_turns };
        *agent = AgentSpec::new(position, m, mass);
    }
    TeamConfig::new(
        agents.get(..cells.len()).unwrap_or(&[]),
        paper_limits(),
        Navigator::default(),
    )
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::agent::failure::FailureMask;
    use crate::team::Arrangement;

    #[test]
    fn every_preset_builds_centred_and_hover_capable() {
        for preset in Preset::ALL {
            let team: TeamConfig<f64, 16> = preset.team().unwrap();
            assert_eq!(team.len(), preset.len(), "{}", preset.name());
            let centroid = team
                .agents()
                .iter()
                .fold(Vector3::zeros(), |c, a| c + a.position);
            assert!(centroid.norm() < 1e-12, "{}: {centroid}", preset.name());
            let expected = if preset.is_consistent() {
                Arrangement::Con
            } else {
                Arrangement::Inc
            };
            assert_eq!(team.arrangement(), expected, "{}", preset.name());
            let hover = team
                .hover_capability(&FailureMask::none(), super::super::GRAVITY)
                .unwrap();
            assert!(hover.capable, "{}: {hover:?}", preset.name());
            // Names round-trip, with `_` for `-` and any case.
            assert_eq!(Preset::from_name(preset.name()), Some(preset));
            let mut alias = [0_u8; 16];
            let name = preset.name().as_bytes();
            for (a, b) in alias.iter_mut().zip(name) {
                *a = if *b == b'-' {
                    b'_'
                } else {
                    b.to_ascii_uppercase()
                };
            }
            let alias = core::str::from_utf8(&alias[..name.len()]).unwrap();
            assert_eq!(Preset::from_name(alias), Some(preset));
            // Neighbours are 0.5 m apart: no two agents closer.
            let agents = team.agents();
            for (i, a) in agents.iter().enumerate() {
                for b in &agents[i + 1..] {
                    assert!((a.position - b.position).norm() > 0.5 - 1e-12);
                }
            }
            assert!(preset.team::<f32, 16>().is_ok());
        }
        assert_eq!(Preset::from_name("a11-inc"), None);
        assert_eq!(Preset::from_name(""), None);
    }

    #[test]
    fn presets_match_the_older_constructors() {
        assert_eq!(
            Preset::A4Inc.team::<f64, 4>().unwrap(),
            super::super::a4_inc().unwrap()
        );
        assert_eq!(
            Preset::A4Con.team::<f64, 4>().unwrap(),
            super::super::a4_con().unwrap()
        );
        assert_eq!(
            Preset::A6Inc.team::<f64, 6>().unwrap(),
            super::super::a6_inc().unwrap()
        );
        assert_eq!(
            Preset::A8Con.team::<f64, 8>().unwrap(),
            super::super::a8_con().unwrap()
        );
        // T10 is three-dimensional: its raised agent sits above the others.
        let t10: TeamConfig<f64, 10> = Preset::T10Inc.team().unwrap();
        let z = |i: usize| t10.agents()[i].position.z;
        assert!((z(8) - 0.9 * PAPER_HALF_SIDE).abs() < 1e-12, "{}", z(8));
        assert!((z(0) + 0.1 * PAPER_HALF_SIDE).abs() < 1e-12, "{}", z(0));
        // Too small a capacity is a typed error.
        assert!(matches!(
            Preset::A10Inc.team::<f64, 8>(),
            Err(ConfigError::TooManyAgents {
                count: 10,
                capacity: 8
            })
        ));
    }
}
