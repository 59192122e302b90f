//! Progress bars on a terminal (hidden otherwise).

use std::io::IsTerminal;

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use tvmd_scenario::Scenario;

/// A bar of `ticks` steps labelled `message`.
pub fn progress_bar(ticks: u64, message: &str) -> ProgressBar {
    let target = if std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(ticks), target);
    if let Ok(style) = ProgressStyle::with_template(
        "{msg} [{elapsed_precise}] {wide_bar} {pos}/{len} ticks (eta {eta})",
    ) {
        bar.set_style(style);
    }
    bar.set_message(message.to_string());
    bar
}

/// Controller ticks of a scenario.
pub fn ticks_of(s: &Scenario) -> u64 {
    (s.duration / s.controller_period).ceil().max(1.0) as u64
}
