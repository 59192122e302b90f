//! The `tvmd-sim` command line: commands, hostile arguments, the live view and the allocation
//! benchmark (one test binary; each module a topic).

mod allocation_set;
#[allow(clippy::module_inception)]
mod cli;
mod hostile;
mod live;
mod outputs;
