//! Which agents of a team have failed.

use crate::foundation::error::ConfigError;

/// Which agents have failed. A failed agent leaves `n`, `n_x` / `n_y` and `M` (paper's degraded
/// team); it is commanded to zero thrust.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(transparent)]
pub struct FailureMask<const N: usize> {
    pub(crate) failed: [bool; N],
}

impl<const N: usize> Default for FailureMask<N> {
    fn default() -> Self {
        Self::none()
    }
}

impl<const N: usize> FailureMask<N> {
    /// No agent failed.
    pub const fn none() -> Self {
        Self { failed: [false; N] }
    }

    /// Marks agent `i` failed (or working again with `failed = false`).
    pub fn set(&mut self, agent: usize, failed: bool) -> Result<(), ConfigError> {
        let slot = self
            .failed
            .get_mut(agent)
            .ok_or(ConfigError::FailureIndex { agent })?;
        *slot = failed;
        Ok(())
    }

    /// A mask with the given agents failed.
    pub fn with_failed(agents: &[usize]) -> Result<Self, ConfigError> {
        let mut mask = Self::none();
        for &i in agents {
            mask.set(i, true)?;
        }
        Ok(mask)
    }

    /// Whether agent `i` is marked failed (`false` beyond the capacity).
    pub fn is_failed(&self, agent: usize) -> bool {
        self.failed.get(agent).copied().unwrap_or(false)
    }

    /// The flags, one per slot of the capacity.
    pub fn as_array(&self) -> &[bool; N] {
        &self.failed
    }
}
