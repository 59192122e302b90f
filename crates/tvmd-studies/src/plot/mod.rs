//! PNG figures reproducing the paper's simulation figures, drawn with plotters.
//!
//! - [`state_profile`]: position `x, y, z` against `x_r`; roll, pitch, yaw against the reference
//!   and the planned roll (paper, "state profile in the simulation");
//! - [`lyapunov`]: `V_x` and `V_R` on a log scale (paper, "Lyapunov candidates profile");
//! - [`relaxation_study`]: planned roll, actual roll, `e_f` and position error for several
//!   relaxations `s` (paper, "tracking performance with different attitude planner relaxation").
//!
//! The data come either from a run's samples ([`PlotSeries::from_samples`]) or from an MCAP log
//! written by the simulator ([`PlotSeries::from_mcap`]), so a log can be re-plotted without
//! re-running it.
//!
//! Text is drawn with plotters' `ab_glyph` backend and a font embedded in the binary
//! (`assets/TvmdPlotSans.ttf`, a renamed subset of DejaVu Sans, see `assets/FONT-LICENSE.txt`):
//! no system fontconfig or freetype is needed.

mod draw;
mod figures;
mod series;

pub use figures::{lyapunov, relaxation_study, state_profile, write_run_figures};
pub use series::{PlotPoint, PlotSeries};

pub(crate) use draw::{draw_lines, ensure_parent, plot_err, register_font, Line, COLORS};

/// The most samples a run's figures are drawn from: a run keeps this many evenly spaced
/// controller ticks for its figures (a 1500 px wide figure shows no more), whatever its length.
pub const PLOT_SAMPLES: usize = 20_000;
