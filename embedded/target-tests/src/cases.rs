//! The computation of one reference-vector case, shared verbatim by the firmware (target `libm`)
//! and its build script (host `std`), so that both run exactly the same f32 code on the same
//! f32 inputs. Inputs are the f64 numbers of `core_vectors.json`, flattened per family (see
//! `build.rs`); outputs are f32, written into `out`.

use tvmd_core::controller::roll;
use tvmd_core::effectiveness::agent_block;
use tvmd_core::nalgebra::{Matrix3, Vector3};
use tvmd_core::team::presets;
use tvmd_core::{
    project_force, AttainableForceSpace, AttitudePlanner, Controller, ControllerSettings,
    GimbalCommand, PlannerStatus, RedistributedPseudoInverse, Reference, Relaxation, RigidState,
};

/// Longest output of any case: the effectiveness case of 12 agents (6 wrench + 18 per agent).
/// (A control cycle writes 4 x 4 commands, `theta` and the status.)
pub const MAX_OUTPUTS: usize = 6 + 18 * 12;

/// The five families of `core_vectors.json`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    /// eq. (1) and its inversion.
    Gimbal,
    /// eq. (4).
    Effectiveness,
    /// eqs. (7)-(8).
    AfsSemiAxes,
    /// eqs. (12)-(13).
    ForceProjection,
    /// eqs. (9)-(11).
    AttitudePlanner,
    /// One whole control cycle of the paper's four-agent team (`Controller::step`), from a
    /// fresh controller; no f64 reference, compared with the host only.
    ControlCycle,
}

fn v3(x: &[f64], at: usize) -> Option<Vector3<f32>> {
    Some(Vector3::new(
        *x.get(at)? as f32,
        *x.get(at + 1)? as f32,
        *x.get(at + 2)? as f32,
    ))
}

fn m3(x: &[f64], at: usize) -> Option<Matrix3<f32>> {
    let r = x.get(at..at + 9)?;
    Some(Matrix3::from_fn(|i, j| {
        r.get(3 * i + j).map_or(f32::NAN, |v| *v as f32)
    }))
}

fn count(x: &[f64], at: usize) -> Option<usize> {
    x.get(at).map(|v| *v as usize)
}

/// Runs one case in f32; returns the number of outputs written, or why it could not run.
pub fn run(family: Family, x: &[f64], out: &mut [f32; MAX_OUTPUTS]) -> Result<usize, &'static str> {
    const BAD: &str = "malformed case inputs";
    let mut put = |values: &mut dyn Iterator<Item = f32>| -> Result<usize, &'static str> {
        let mut k = 0;
        for v in values {
            *out.get_mut(k).ok_or("too many outputs")? = v;
            k += 1;
        }
        Ok(k)
    };
    match family {
        // x = [eta_x, eta_y, thrust, force(3)]
        Family::Gimbal => {
            let cmd = GimbalCommand {
                eta_x: *x.first().ok_or(BAD)? as f32,
                eta_y: *x.get(1).ok_or(BAD)? as f32,
                thrust: *x.get(2).ok_or(BAD)? as f32,
            };
            let f = cmd.force();
            let inv = GimbalCommand::from_force(&v3(x, 3).ok_or(BAD)?);
            put(&mut [f.x, f.y, f.z, inv.thrust, inv.eta_x, inv.eta_y].into_iter())
        }
        // x = [n, positions(3n), quarter_turns(n), f(3n)]; out = [wrench(6), blocks(18n)]
        Family::Effectiveness => {
            let n = count(x, 0).ok_or(BAD)?;
            let mut wrench = tvmd_core::nalgebra::Vector6::<f32>::zeros();
            let mut blocks = [0.0f32; 18 * 12];
            for k in 0..n {
                let p = v3(x, 1 + 3 * k).ok_or(BAD)?;
                let turns = *x.get(1 + 3 * n + k).ok_or(BAD)? as i32;
                let f = v3(x, 1 + 4 * n + 3 * k).ok_or(BAD)?;
                let block = agent_block::<f32>(&p, turns);
                wrench += block * f;
                for r in 0..6 {
                    for c in 0..3 {
                        *blocks.get_mut(18 * k + 3 * r + c).ok_or(BAD)? =
                            block.get((r, c)).copied().ok_or(BAD)?;
                    }
                }
            }
            let tail = blocks.get(..18 * n).ok_or(BAD)?;
            put(&mut wrench.iter().copied().chain(tail.iter().copied()))
        }
        // x = [n, n_x, sigma_x, sigma_y, max_thrust, z, s]
        Family::AfsSemiAxes => {
            let afs = afs(x)?;
            let s = Relaxation::new(*x.get(6).ok_or(BAD)? as f32).map_err(|_| "bad s")?;
            let axes = afs.semi_axes(*x.get(5).ok_or(BAD)? as f32, s);
            put(&mut [axes.c_x, axes.c_y].into_iter())
        }
        // x = [n, n_x, sigma_x, sigma_y, max_thrust, u(3)]
        Family::ForceProjection => {
            let p = project_force(&afs(x)?, &v3(x, 5).ok_or(BAD)?);
            put(&mut p.force.iter().copied())
        }
        // x = [n, n_x, sigma_x, sigma_y, max_thrust, s, R_r(9), f_r(3)];
        // out = [theta, R_d(9 row-major), 1 if Planned else 0]
        Family::AttitudePlanner => {
            let s = Relaxation::new(*x.get(5).ok_or(BAD)? as f32).map_err(|_| "bad s")?;
            let plan = AttitudePlanner::new(s)
                .plan(&afs(x)?, &m3(x, 6).ok_or(BAD)?, &v3(x, 15).ok_or(BAD)?)
                .map_err(|_| "planner refused the input")?;
            let planned = if plan.status == PlannerStatus::Planned {
                1.0
            } else {
                0.0
            };
            let r = plan.r_d.transpose(); // column-major storage of R_d^T = R_d row by row
            put(&mut core::iter::once(plan.theta)
                .chain(r.iter().copied())
                .chain(core::iter::once(planned)))
        }
        // x = [position(3), angular_velocity(3), velocity(3), roll, ref position(3),
        //      ref acceleration(3), ref roll]; out = [4 x (eta_x, eta_y, thrust, omega),
        //      planner theta, 0 if Ok else 1]
        Family::ControlCycle => {
            let team = presets::a4_inc::<f32, 4>().map_err(|_| "preset team refused")?;
            let mut controller = Controller::new(
                team,
                ControllerSettings::paper(),
                RedistributedPseudoInverse,
            )
            .map_err(|_| "controller refused the preset")?;
            let mut state = RigidState::at_rest(v3(x, 0).ok_or(BAD)?);
            state.angular_velocity = v3(x, 3).ok_or(BAD)?;
            state.velocity = v3(x, 6).ok_or(BAD)?;
            state.attitude = roll(*x.get(9).ok_or(BAD)? as f32);
            let mut reference = Reference::hover(v3(x, 10).ok_or(BAD)?);
            reference.acceleration = v3(x, 13).ok_or(BAD)?;
            reference.attitude = roll(*x.get(16).ok_or(BAD)? as f32);
            let (commands, theta, held) = match controller.step(&state, &reference) {
                Ok(o) => (o.commands, o.planner.theta, 0.0),
                Err(e) => (e.commands, 0.0, 1.0),
            };
            put(&mut commands
                .iter()
                .flat_map(|c| [c.eta_x, c.eta_y, c.thrust, c.omega])
                .chain([theta, held]))
        }
    }
}

fn afs(x: &[f64]) -> Result<AttainableForceSpace<f32>, &'static str> {
    const BAD: &str = "malformed case inputs";
    AttainableForceSpace::new(
        count(x, 0).ok_or(BAD)?,
        count(x, 1).ok_or(BAD)?,
        *x.get(2).ok_or(BAD)? as f32,
        *x.get(3).ok_or(BAD)? as f32,
        *x.get(4).ok_or(BAD)? as f32,
    )
    .map_err(|_| "AFS refused the input")
}

/// One case as embedded by `build.rs`.
pub struct Case {
    /// `family[index]` in `core_vectors.json`.
    pub name: &'static str,
    /// Which computation.
    pub family: Family,
    /// Flattened f64 inputs, as in the file (rounded to f32 by `run`).
    pub input: &'static [f64],
    /// The file's f64 outputs, checked group by group.
    pub expected: &'static [f64],
    /// `(length, absolute)`: consecutive groups of `expected`; a relative group is scaled by its
    /// largest entry, as in the host suite `crates/tvmd-core/tests/reference_vectors.rs`.
    pub groups: &'static [(usize, bool)],
    /// The host's f32 outputs of `run` (bit patterns), all of them.
    pub host: &'static [u32],
}
