//! The run logs: MCAP contents and schemas, the Foxglove layout, the controller's topics (one
//! test binary; each module a topic).

#[path = "../common.rs"]
mod common;

mod controller_log;
mod foxglove_layout;
mod mcap_log;
