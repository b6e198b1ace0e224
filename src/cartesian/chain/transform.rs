//! A rigid transform as plain data ([`Transform`]): what a URDF's origin or a
//! caller's matrix gives, read and checked (a rotation orthonormal to rounding).

use super::*;

/// A rigid transform as plain data: a translation (m) and a rotation matrix
/// (row-major, `rotation[i][j]` = R_ij), mapping this frame's coordinates to
/// its parent's: `x_parent = R x + translation`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Transform {
    /// Translation (m).
    pub translation: [f64; 3],
    /// Rotation matrix, row-major.
    pub rotation: [[f64; 3]; 3],
}

impl Transform {
    /// No translation, no rotation.
    pub const IDENTITY: Self = Self {
        translation: [0.0; 3],
        rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    /// URDF's `<origin xyz="…" rpy="…">`: translation `xyz` (m) and the
    /// fixed-axis roll, pitch, yaw (rad), R = Rot_z(yaw) Rot_y(pitch) Rot_x(roll).
    pub fn from_xyz_rpy(xyz: [f64; 3], rpy: [f64; 3]) -> Self {
        let r = Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]);
        Self::from_parts(Vector3::from(xyz), r.matrix())
    }

    /// A position (m) and a unit quaternion `[w, x, y, z]` (MuJoCo's
    /// `body_pos`, `body_quat`); the quaternion is normalised, and must be
    /// finite and non-zero.
    pub fn from_pos_quat(pos: [f64; 3], quat: [f64; 4]) -> Result<Self, Error> {
        check::finite_slice("quaternion", &quat)?;
        // Scaled by its largest entry first: a quaternion of norm 1e-200 is
        // non-zero (its squares underflowed, and it was refused as zero).
        let largest = quat.iter().fold(0.0_f64, |m, x| m.max(x.abs()));
        check::positive("‖quaternion‖ > 0", "‖quaternion‖", largest)?;
        let quat = quat.map(|x| x / largest);
        let norm = sqrt(quat.iter().map(|x| x * x).sum::<f64>());
        check::positive("‖quaternion‖ > 0", "‖quaternion‖", norm)?;
        let q = nalgebra::UnitQuaternion::new_normalize(nalgebra::Quaternion::new(
            quat[0], quat[1], quat[2], quat[3],
        ));
        Ok(Self::from_parts(
            Vector3::from(pos),
            q.to_rotation_matrix().matrix(),
        ))
    }

    /// A 4 × 4 homogeneous transform `m`, row-major ([R p; 0 0 0 1]): its
    /// last row must be 0 0 0 1 to 1e-6 (an error naming the entry
    /// otherwise); R is checked where the transform is used (a chain's
    /// origin, its tip).
    pub fn from_matrix(m: &[f64; 16]) -> Result<Self, Error> {
        const LAST: [f64; 4] = [0.0, 0.0, 0.0, 1.0];
        for (j, want) in LAST.iter().enumerate() {
            let off = (m[12 + j] - want).abs();
            // A NaN is not within the tolerance either.
            if off.is_nan() || off > 1e-6 {
                return Err(Error::Condition {
                    condition: "the last row of a homogeneous transform is 0 0 0 1 (to 1e-6)",
                    lhs: "m[3]",
                    index: Some(j),
                    value: m[12 + j],
                });
            }
        }
        Ok(Self {
            translation: [m[3], m[7], m[11]],
            rotation: core::array::from_fn(|i| core::array::from_fn(|j| m[4 * i + j])),
        })
    }

    /// From a translation (m) and a rotation matrix.
    pub fn from_parts(translation: Vector3<f64>, rotation: &Matrix3<f64>) -> Self {
        Self {
            translation: translation.into(),
            rotation: core::array::from_fn(|i| core::array::from_fn(|j| rotation[(i, j)])),
        }
    }

    pub(super) fn vector(&self) -> Vector3<f64> {
        Vector3::from(self.translation)
    }

    pub(super) fn matrix(&self) -> Matrix3<f64> {
        Matrix3::from_fn(|i, j| self.rotation[i][j])
    }

    /// Validated: every value finite, |translation| ≤ 1e6 m, the rotation
    /// orthonormal (|RᵀR − I| ≤ 1e-6) with det R = +1.
    pub(crate) fn check(&self, index: usize) -> Result<Frame, Error> {
        let (p, r) = (self.vector(), self.matrix());
        check::finite_slice("joint origin translation", p.as_slice())?;
        check::finite_slice("joint origin rotation", r.as_slice())?;
        let far = p.amax();
        if far > 1e6 {
            return Err(Error::Condition {
                condition: "|origin| ≤ 1e6 m",
                lhs: "joint origin translation",
                index: Some(index),
                value: far,
            });
        }
        let dev = (r.transpose() * r - Matrix3::identity()).amax();
        if dev > ROTATION_TOLERANCE {
            return Err(Error::Condition {
                condition: "RᵀR = I (an orthonormal rotation matrix, to 1e-6)",
                lhs: "joint origin rotation",
                index: Some(index),
                value: dev,
            });
        }
        let det = r.determinant();
        if det <= 0.0 {
            return Err(Error::Condition {
                condition: "det R = +1 (a rotation, not a reflection)",
                lhs: "joint origin rotation",
                index: Some(index),
                value: det,
            });
        }
        // Within the tolerance but not orthonormal to rounding (a matrix
        // printed with 7 digits): the nearest rotation, so that seven such
        // origins do not multiply into a matrix that is not one.
        let r = if dev > ORTHONORMAL_TO_ROUNDING {
            orthonormalised(r)
        } else {
            r
        };
        Ok(Frame { p, r })
    }
}

/// |RᵀR − I| of a rotation matrix computed in floating point (a URDF's rpy,
/// a unit quaternion's matrix): kept as given.
pub(super) const ORTHONORMAL_TO_ROUNDING: f64 = 1e-12;

/// The nearest rotation to `r` (|RᵀR − I| ≤ 1e-6, det > 0): the polar
/// factor by the Newton–Schulz iteration R ← R (3I − RᵀR)/2, which doubles
/// the digits each time (1e-6 → 1e-12 → rounding).
pub(super) fn orthonormalised(mut r: Matrix3<f64>) -> Matrix3<f64> {
    for _ in 0..3 {
        r = 0.5 * r * (3.0 * Matrix3::identity() - r.transpose() * r);
    }
    r
}
