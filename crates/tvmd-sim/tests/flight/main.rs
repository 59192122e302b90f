//! Flights of the loop: the paper's scenario, the plant and actuators, failures, the samples and
//! the summary (one test binary; each module a topic).

#[path = "../common/mod.rs"]
mod common;

mod closed_loop;
mod coarse_step;
mod fault_detection;
mod fault_reports;
mod flight_metrics;
mod hover_failure;
mod links;
mod null_space;
mod offset_free;
mod precision;
mod recording;
mod reports;
mod sample_retention;
mod scenario_families;
mod sim_loop;
mod stepping;
