//! The AFS atlas: the exact attainable force set of a team, bracketed, against the paper's
//! elliptic cone (eqs. 7-8). Std only: this is analysis, not part of the control cycle.
//!
//! For a team, a failure mask, a vertical force `u_z` and a required torque `tau` (zero by
//! default), the attainable lateral forces are
//! `{ (u_x, u_y) : sum_i M_i T_i a_hat(eta_i) = [tau; u_x; u_y; u_z], every agent in its box }`
//! (eqs. 1, 4, 6: the exact gimbal map and thrust range, no approximation). Along each
//! direction the farthest attainable force is bracketed:
//! - **inner** (`lower`): a command inside every box that attains the force to `1e-10 n sigma_Tf`
//!   (projected Gauss-Newton, bisection along the ray, [`inner`]); the commands are returned as
//!   the certificate;
//! - **outer** (`upper`): `D(y) = h(y) - y . w0` for a multiplier `y`, where `h` is the sum of the
//!   agents' support functions in closed form ([`support`]); weak duality makes every `D(y)` an
//!   upper bound of the exact radius, whatever `y` ([`outer`]).
//!
//! The true radius lies in `[lower, upper]`; the width is the method's stated error, reported
//! with every number. The outer bound is the radius of the convex hull when the multiplier is
//! optimal, so a wide bracket means either a non-convex boundary (the gimbal box's curved
//! faces) or an inexact minimizer; the docs (`docs/afs-atlas.md`) give the widths measured
//! over the catalogue.

pub mod bracket;
pub mod certify;
pub mod compare;
pub mod inner;
pub mod model;
pub mod outer;
pub mod plot;
pub mod ray;
pub mod report;
mod run;
pub mod section;
pub mod support;

pub use bracket::{bound_ray, RESTARTS};
pub use certify::{
    certified_relaxation, certified_relaxation_until, CertifiedRelaxation, HeightRange,
};
pub use compare::{compare, cone_radius, ConeComparison};
pub use model::AtlasModel;
pub use ray::{Bracket, Ray, RayBound};
pub use report::{
    atlas_entry, atlas_entry_until, markdown_table, AtlasEntry, AtlasRow, AtlasSettings, HeightRow,
};
pub use run::{run, run_until, AtlasRequest};
pub use section::{
    cross_section, cross_section_until, hover_ceiling, ray_radius, CrossSection, SectionQuery,
};

#[cfg(test)]
mod tests;
