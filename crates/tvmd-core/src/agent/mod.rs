//! One agent, and the team's wrench from its agents: the gimbal's thrust direction
//! ([`gimbal`], eq. 1), the limits ([`limits`], eqs. 5-6), the admissible set `E_f`
//! ([`admissible`], eq. 6), the inversion to gimbal angles and rotor speeds ([`command`]), the
//! effectiveness `M(Xi)` ([`effectiveness`], eq. 4) and the failure mask ([`failure`]).
//! Imports only the foundations.

pub mod admissible;
pub mod command;
pub mod effectiveness;
pub mod failure;
pub mod gimbal;
pub mod limits;
