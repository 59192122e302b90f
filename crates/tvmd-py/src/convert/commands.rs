//! The actions of `tvmd.sim.Simulation`: per-agent commands (`step`) and a body wrench
//! (`step_wrench`), checked here (shape, finite values, rotor speeds not negative) so that a bad
//! action raises `ValueError` naming the argument and never reaches the simulator. A batch's
//! values are not checked for finiteness here: a non-finite value is its team's error in the
//! simulator's batch (`errors`), and the other teams step, as in Rust.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use tvmd_plant::actuators::ActuatorCommand;

use super::{array, check_finite, finite, shape_error, table};

/// The commands of a `step` for `n` agents: `(n, 3)` rows `eta_x, eta_y, thrust` (rad, rad, N)
/// or `(n, 4)` rows `eta_x, eta_y, thrust, omega` (`tvmd.Controller`'s layout). With
/// `rotor_speeds`, the last column is the normalized rotor speed `omega` (1 at `max_thrust`)
/// and the thrust is `max_thrust omega^2`; otherwise the third column is the thrust.
pub(crate) fn commands_arg(
    obj: &Bound<'_, PyAny>,
    n: usize,
    rotor_speeds: bool,
    max_thrust: f64,
) -> PyResult<Vec<ActuatorCommand>> {
    let name = "commands";
    let a = array(obj, name)?;
    let cols = match a.shape() {
        [rows, cols @ (3 | 4)] if *rows == n => *cols,
        shape => return Err(shape_error(name, &format!("({n}, 3) or ({n}, 4)"), shape)),
    };
    check_finite(a.iter(), name)?;
    let values: Vec<f64> = a.iter().copied().collect();
    rows(&values, cols, rotor_speeds, max_thrust, name)
}

/// The commands of a batch step for `b` teams of `n` agents: `(b, n, 3)` or `(b, n, 4)`, each
/// team's `(n, ...)` as [`commands_arg`] reads it but for finiteness (a team's non-finite
/// command is that team's error in the batch).
pub(crate) fn batch_commands_arg(
    obj: &Bound<'_, PyAny>,
    b: usize,
    n: usize,
    rotor_speeds: bool,
    max_thrust: f64,
) -> PyResult<Vec<Vec<ActuatorCommand>>> {
    let name = "commands";
    let a = array(obj, name)?;
    let cols = match a.shape() {
        [teams, rows, cols @ (3 | 4)] if *teams == b && *rows == n => *cols,
        shape => {
            let want = format!("({b}, {n}, 3) or ({b}, {n}, 4)");
            return Err(shape_error(name, &want, shape));
        }
    };
    let values: Vec<f64> = a.iter().copied().collect();
    values
        .chunks_exact(n * cols)
        .map(|team| rows(team, cols, rotor_speeds, max_thrust, name))
        .collect()
}

/// Rows of `cols` values (3 or 4) as commands.
fn rows(
    values: &[f64],
    cols: usize,
    rotor_speeds: bool,
    max_thrust: f64,
    name: &str,
) -> PyResult<Vec<ActuatorCommand>> {
    values
        .chunks_exact(cols)
        .enumerate()
        .map(|(i, row)| {
            let (eta_x, eta_y, third, last) = match *row {
                [a, b, c] => (a, b, c, c),
                [a, b, c, d] => (a, b, c, d),
                // Rows have 3 or 4 values (the shape was checked).
                _ => {
                    return Err(PyValueError::new_err(format!(
                        "`{name}` has rows of {} values",
                        row.len()
                    )))
                }
            };
            let thrust = if rotor_speeds {
                let omega = last;
                if omega < 0.0 {
                    return Err(PyValueError::new_err(format!(
                        "`{name}`: agent {i} has the negative rotor speed {omega}"
                    )));
                }
                max_thrust * omega * omega
            } else {
                third
            };
            Ok(ActuatorCommand {
                eta_x,
                eta_y,
                thrust,
            })
        })
        .collect()
}

/// `(b, 6)` body wrenches of a batch step (a team's non-finite wrench is that team's error in
/// the batch).
pub(crate) fn batch_wrench_arg(obj: &Bound<'_, PyAny>, b: usize) -> PyResult<Vec<[f64; 6]>> {
    let w = table::<6>(obj, "wrenches", Some(b))?;
    Ok(w.into_iter().map(Into::into).collect())
}

/// The `(6,)` body wrench `[u_tau; u_f]` (N m, N) of a `step_wrench`, every value finite.
pub(crate) fn wrench_arg(obj: &Bound<'_, PyAny>) -> PyResult<[f64; 6]> {
    Ok(finite::<6, 1>(obj, "wrench")?.into())
}
