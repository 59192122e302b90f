//! The run logs: MCAP contents and schemas, the Foxglove layout, the controller's topics (one
//! test binary; each module a topic).

#[path = "../common/mod.rs"]
mod common;

mod foxglove_layout;
mod load;
mod mcap_log;
