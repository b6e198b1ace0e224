//! Orientation error and integration on SO(3), SPEC §16 (16.2)–(16.4).
//!
//! **Decision: the rotation vector of the relative rotation (the SO(3)
//! logarithm), computed through the unit quaternion on its w ≥ 0
//! hemisphere.** For a rotation `R_a R_bᵀ` by θ ∈ [0, π] about the unit axis
//! u, [`rotation_error`] returns `e = θ u`:
//!
//! - it is the angle/axis error of Siciliano, Sciavicco, Villani & Oriolo,
//!   *Robotics* (Springer 2009), §3.7.3, and the one Caccavale, Natale,
//!   Siciliano & Villani, "Six-DOF impedance control based on angle/axis
//!   representations" (IEEE Trans. Robot. Autom. 15(2), 1999) analyse; a
//!   spring `K e` on it is linear in the angle at every angle, so a stiffness
//!   means the same at 5° and at 90° (the quaternion form `2 η ε = 2 sin(θ/2) u`
//!   of libfranka's `cartesian_impedance_control.cpp` and of Ott, *Cartesian
//!   Impedance Control of Redundant and Flexible-Joint Robots*, Springer
//!   2008, ch. 3, softens to 2/π ≈ 0.64 of it at 180°);
//! - it is hemisphere-safe: the quaternion q of `R_a R_bᵀ` is taken with
//!   w ≥ 0 (q and −q are the same rotation; libfranka flips the sign the
//!   same way), so θ = 2 atan2(‖v‖, w) ∈ [0, π]: the error never points the
//!   long way round, is continuous everywhere except at exactly θ = π (where
//!   both axes ±u are equally short), and equals θ u, hence K θ u as a
//!   moment, exactly;
//! - atan2 of the quaternion is accurate at every angle, where the classical
//!   `acos((tr R − 1)/2)` loses half the digits near 0 and π (Solà, Deray &
//!   Atchuthan, "A micro Lie theory for state estimation in robotics",
//!   arXiv:1812.01537, 2018, eq. (46)–(48)).
//!
//! Everything here is `no_std` and allocation-free.

use crate::error::Error;
use crate::math::sqrt;
use crate::types::Vector;
use nalgebra::{Matrix3, Rotation3, UnitQuaternion};

/// The tolerance of [`rotation`]: |RᵀR − I| and |det R − 1| at most this.
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// The rotation vector θ u (rad) of the unit quaternion `q` taken on its
/// w ≥ 0 hemisphere: θ = 2 atan2(‖v‖, |w|) ∈ [0, π] (SO(3) log, (16.2)).
pub fn log_quaternion(q: &UnitQuaternion<f64>) -> Vector<3> {
    let (w, v) = (q.w, q.imag());
    let (w, v) = if w < 0.0 { (-w, -v) } else { (w, v) };
    let s = v.norm();
    if s < 1e-9 {
        // θ/sin(θ/2) = 2/cos(θ/2)·(1 + O(θ²)): 2/w to 1e-18 relative here.
        return v * (2.0 / w);
    }
    v * (2.0 * crate::math::atan2(s, w) / s)
}

/// The rotation error `e = Log(R_a R_bᵀ)` (rad), world frame, (16.2): the
/// rotation vector θ u of the shortest rotation that takes `b` onto `a`
/// (θ ∈ [0, π]; `R_a = Exp(e) R_b`).
pub fn rotation_error(a: &UnitQuaternion<f64>, b: &UnitQuaternion<f64>) -> Vector<3> {
    log_quaternion(&(a * b.inverse()))
}

/// `Exp(φ)` for a rotation vector φ (rad): the unit quaternion of the
/// rotation by ‖φ‖ about φ/‖φ‖ (identity for φ = 0).
pub fn exp(phi: &Vector<3>) -> UnitQuaternion<f64> {
    let theta2 = phi.norm_squared();
    let theta = sqrt(theta2);
    let (w, k) = if theta < 1e-6 {
        // cos(θ/2) and sin(θ/2)/θ to O(θ⁴) ≈ 1e-25.
        (1.0 - theta2 / 8.0, 0.5 - theta2 / 48.0)
    } else {
        let h = 0.5 * theta;
        (crate::math::cos(h), crate::math::sin(h) / theta)
    };
    UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
        w,
        k * phi[0],
        k * phi[1],
        k * phi[2],
    ))
}

/// Scale `e` to norm at most `max` (no change if `max` is +∞ or ‖e‖ ≤ max):
/// the error clipping of (16.5), which keeps the direction.
pub fn clip(e: &Vector<3>, max: f64) -> Vector<3> {
    let n = e.norm();
    if n > max {
        e * (max / n)
    } else {
        *e
    }
}

/// `m` as a rotation, validated: every entry finite, |RᵀR − I| ≤
/// [`ROTATION_TOLERANCE`] entrywise and det R > 0; else an error naming
/// `what` and the deviation. The quaternion of the matrix is normalised.
pub fn rotation(what: &'static str, m: &Matrix3<f64>) -> Result<UnitQuaternion<f64>, Error> {
    // Named by its row-major index, as a caller writes R (nalgebra stores
    // it by columns).
    if let Some(index) = (0..9).find(|k| !m[(k / 3, k % 3)].is_finite()) {
        return Err(Error::NonFinite { what, index });
    }
    let dev = (m.transpose() * m - Matrix3::identity()).amax();
    if dev > ROTATION_TOLERANCE {
        return Err(Error::Condition {
            condition: "RᵀR = I (an orthonormal rotation matrix, to 1e-6)",
            lhs: named(what).0,
            index: None,
            value: dev,
        });
    }
    let det = m.determinant();
    if det <= 0.0 {
        return Err(Error::Condition {
            condition: "det R = +1 (a rotation, not a reflection)",
            lhs: named(what).1,
            index: None,
            value: det,
        });
    }
    Ok(UnitQuaternion::from_rotation_matrix(
        &Rotation3::from_matrix_unchecked(*m),
    ))
}

/// What [`rotation`]'s refusals measure of the matrix `what`, named with
/// it (the deviation was printed as if it were the matrix: "R_c = 0.21"):
/// its largest |RᵀR − I| entry, its determinant.
fn named(what: &'static str) -> (&'static str, &'static str) {
    match what {
        "R_c" => ("max |R_cᵀR_c − I| of R_c", "det R_c"),
        "R" => ("max |RᵀR − I| of R", "det R"),
        "rotation" => ("max |RᵀR − I| of the rotation", "det of the rotation"),
        _ => ("max |RᵀR − I| of the matrix", "det of the matrix"),
    }
}

/// The rotation matrix of the unit quaternion `q = [w, x, y, z]` (world ←
/// tip; MuJoCo's and Eigen's order of the coefficients), for a rotation
/// target given as a quaternion. Every coefficient finite and |‖q‖ − 1| ≤
/// [`ROTATION_TOLERANCE`], else an error naming `what` and the value: a
/// quaternion that is not a rotation is refused as a matrix that is not one
/// is, never normalised behind the caller's back. q and −q give the same
/// matrix.
pub fn quaternion_matrix(what: &'static str, q: &[f64; 4]) -> Result<Matrix3<f64>, Error> {
    crate::error::check::finite_slice(what, q)?;
    let norm = sqrt(q.iter().map(|c| c * c).sum::<f64>());
    if (norm - 1.0).abs() > ROTATION_TOLERANCE {
        return Err(Error::Condition {
            condition: "‖q‖ = 1 (a unit quaternion, to 1e-6)",
            lhs: what,
            index: None,
            value: norm,
        });
    }
    let [w, x, y, z] = *q;
    Ok(Matrix3::new(
        1.0 - 2.0 * (y * y + z * z),
        2.0 * (x * y - w * z),
        2.0 * (x * z + w * y),
        2.0 * (x * y + w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z - w * x),
        2.0 * (x * z - w * y),
        2.0 * (y * z + w * x),
        1.0 - 2.0 * (x * x + y * y),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn log_of_exp_is_the_rotation_vector_below_pi() {
        for phi in [
            Vector::<3>::new(0.3, -0.2, 0.1),
            Vector::<3>::new(0.0, 0.0, 3.1),
            Vector::<3>::new(1e-12, 0.0, 0.0),
            Vector::<3>::zeros(),
        ] {
            let e = log_quaternion(&exp(&phi));
            assert!((e - phi).norm() < 1e-14, "{phi} → {e}");
        }
        // Beyond π the short way round: 3π/2 about z is −π/2 about z.
        let e = log_quaternion(&exp(&Vector::<3>::new(
            0.0,
            0.0,
            1.5 * core::f64::consts::PI,
        )));
        assert!((e - Vector::<3>::new(0.0, 0.0, -0.5 * core::f64::consts::PI)).norm() < 1e-14);
    }

    #[test]
    fn a_unit_quaternion_gives_its_rotation_and_any_other_is_refused() {
        let q = UnitQuaternion::from_euler_angles(0.3, -0.7, 1.9);
        let c = [q.w, q.i, q.j, q.k];
        let m = quaternion_matrix("R_c", &c).unwrap();
        assert!((m - q.to_rotation_matrix().matrix()).amax() < 1e-15);
        let neg = quaternion_matrix("R_c", &c.map(|v| -v)).unwrap();
        assert_eq!(m, neg);
        let e = quaternion_matrix("R_c", &[0.0, 0.0, 2.0, 0.0]).unwrap_err();
        assert!(e.to_string().contains("‖q‖ = 1"), "{e}");
        assert!(e.to_string().contains("R_c = 2 "), "{e}");
        assert!(quaternion_matrix("R_c", &[f64::NAN, 0.0, 0.0, 1.0]).is_err());
        assert!(quaternion_matrix("R_c", &[0.0; 4]).is_err());
    }

    #[test]
    fn non_rotations_are_refused_by_name() {
        let e = rotation("R_c", &(Matrix3::identity() * 1.01)).unwrap_err();
        assert!(e.to_string().contains("orthonormal"), "{e}");
        let e = rotation(
            "R_c",
            &Matrix3::from_diagonal(&Vector::<3>::new(1.0, 1.0, -1.0)),
        )
        .unwrap_err();
        assert!(e.to_string().contains("det R = +1"), "{e}");
        let mut m = Matrix3::identity();
        m[(0, 1)] = f64::NAN;
        assert!(rotation("R_c", &m).is_err());
    }
}
