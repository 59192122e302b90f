//! The certified relaxation of a preset, read from the generated table ([`super::certified`]).

use super::certified::CERTIFIED;
use super::Preset;
use crate::afs::Relaxation;
use crate::foundation::real::{lit, Real};

impl Preset {
    /// The certified relaxation `s*` of the AFS atlas (`docs/afs-atlas.md`) for this team with
    /// the paper's agents, nominal (`failed = None`) or without one agent: the largest `s`
    /// (rounded down to 0.001) whose elliptic cone (eqs. 7-8) lies inside the attained lateral
    /// forces at zero torque on the atlas's grid (36 directions, nine heights from 0.1 to 0.9 of
    /// the hover ceiling). `None` for an agent index out of range or a degraded team without a
    /// value (rank-deficient `M`, or no attained ceiling).
    ///
    /// Certified on that grid, for the paper's limits and zero torque; the values do not depend
    /// on the grid unit or the agent mass (with `sigma_Tf = 2 m_i g`), and are invalid for other
    /// gimbal or thrust limits (compute them with `tvmd-sim afs`).
    ///
    /// ```
    /// use tvmd_core::team::presets::Preset;
    /// let s = Preset::A4Inc.certified_relaxation::<f64>(None).unwrap();
    /// assert!(s.get() > 0.5 && s.get() < 1.0);
    /// assert!(Preset::A4Inc.certified_relaxation::<f32>(Some(9)).is_none());
    /// ```
    pub fn certified_relaxation<T: Real>(self, failed: Option<usize>) -> Option<Relaxation<T>> {
        let (_, nominal, degraded) = CERTIFIED.iter().find(|(p, _, _)| *p == self)?;
        let value = match failed {
            None => *nominal,
            Some(i) => *degraded.get(i)?,
        }?;
        Relaxation::new(lit::<T>(value)).ok()
    }
}
