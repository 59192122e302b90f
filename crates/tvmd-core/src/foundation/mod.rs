//! The foundations every stage stands on, none of them a stage: the scalar ([`real`]), the
//! rotations ([`rotation`]), the small dense solvers, the positive-definite check and the typed
//! errors ([`error`]). Nothing here imports another room.

pub(crate) mod definite;
pub mod error;
pub(crate) mod linalg;
pub mod real;
pub mod rotation;
pub mod stored;
