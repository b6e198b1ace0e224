//! The operational-space inertia Λ of SPEC (23.7) for n joints known at run
//! time: the const-generic [`operational_inertia`](crate::cartesian::opspace::operational_inertia)
//! for N = n, on row-major slices. No allocation; no `alloc` needed.

use super::MAX_JOINTS;
use crate::cartesian::kinematics::Jacobian6;
use crate::cartesian::opspace;
use crate::error::{check, Error};
use crate::types::Matrix;

/// The error of a Jacobian of another number of values than 6 n.
const JACOBIAN_SHAPE: Error = Error::Invalid {
    what: "jacobian",
    reason: "needs 6 × n values, row-major, n = 1 … 7 joints",
};

/// Λ of SPEC (23.7), 6 × 6 row-major (kg, kg m², kg m across), as robosuite's
/// OSC_POSE computes it: `jacobian` the tip's 6 × n geometric Jacobian
/// [J_v; J_ω] (row-major, world-aligned; n = 1 … [`MAX_JOINTS`]), `inertia`
/// the n × n joint-space inertia D (row-major, kg m²), `uncoupled`
/// OSC_POSE's `uncouple_pos_ori` (Λ block-diagonal). See the const-generic
/// [`operational_inertia`](crate::cartesian::opspace::operational_inertia)
/// for the errors; here also the shapes (`jacobian` not 6 n values with
/// 1 ≤ n ≤ 7, `inertia` not n²), and non-finite entries indexed row-major.
pub fn operational_inertia(
    jacobian: &[f64],
    inertia: &[f64],
    uncoupled: bool,
) -> Result<[f64; 36], Error> {
    let n = jacobian.len() / 6;
    if n == 0 || n > MAX_JOINTS || jacobian.len() != 6 * n {
        return Err(JACOBIAN_SHAPE);
    }
    if inertia.len() != n * n {
        return Err(Error::Invalid {
            what: "inertia",
            reason: "needs n × n values, row-major (n: the jacobian's columns)",
        });
    }
    check::finite_slice("jacobian", jacobian)?;
    check::finite_slice("inertia", inertia)?;
    let lam = with_joints!(n, N => opspace::operational_inertia(
        &Jacobian6::<N>::from_row_slice(jacobian),
        &Matrix::<N>::from_row_slice(inertia),
        uncoupled,
    ), _ => Err(JACOBIAN_SHAPE))?;
    let mut out = [0.0; 36];
    for (k, v) in out.iter_mut().enumerate() {
        *v = lam[(k / 6, k % 6)];
    }
    Ok(out)
}
