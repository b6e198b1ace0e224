//! The commanded pose: plain data a caller fills ([`PoseTarget`]), and its
//! validated form with the rotation as a unit quaternion.

use super::*;

/// A commanded pose and its rates at t_k, world frame; plain data (a C
/// caller fills it). The rotation is validated at every step (orthonormal to
/// 1e-6, det +1).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PoseTarget {
    /// Position p_c (m).
    pub p: Vector<3>,
    /// Velocity ṗ_c (m/s).
    pub dp: Vector<3>,
    /// Acceleration p̈_c (m/s²).
    pub ddp: Vector<3>,
    /// Rotation R_c (world ← tip); ignored by a position-only loop.
    pub r: Matrix3<f64>,
    /// Angular velocity ω_c (rad/s), world frame.
    pub w: Vector<3>,
    /// Angular acceleration ω̇_c (rad/s²), world frame.
    pub dw: Vector<3>,
}

impl PoseTarget {
    /// The pose (p, R) at rest.
    pub fn at(p: Vector<3>, r: Matrix3<f64>) -> Self {
        Self {
            p,
            dp: Vector::zeros(),
            ddp: Vector::zeros(),
            r,
            w: Vector::zeros(),
            dw: Vector::zeros(),
        }
    }

    /// A position setpoint (p_c, ṗ_c, p̈_c) with the identity rotation at
    /// rest (for a position-only loop, which ignores the rotation).
    pub fn from_position(c: &Setpoint<3>) -> Self {
        Self {
            p: c.x,
            dp: c.dx,
            ddp: c.ddx,
            ..Self::at(c.x, Matrix3::identity())
        }
    }
}

/// A validated target: the rotation as a unit quaternion.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(super) struct Target {
    pub(super) p: Vector<3>,
    pub(super) dp: Vector<3>,
    pub(super) ddp: Vector<3>,
    pub(super) q: UnitQuaternion<f64>,
    pub(super) w: Vector<3>,
    pub(super) dw: Vector<3>,
}

impl Target {
    pub(super) fn check(t: &PoseTarget, orients: bool) -> Result<Self, Error> {
        // The ceilings of a joint setpoint (docs/reliability.md), in m and rad:
        // no plan gives more, and beyond them one sample throws the reference
        // so far that the arm is driven at saturation.
        for (what, v, ceiling) in [
            ("p_c", &t.p, CEILING_POSITION),
            ("dp_c", &t.dp, CEILING_VELOCITY),
            ("ddp_c", &t.ddp, CEILING_ACCELERATION),
            ("w_c", &t.w, CEILING_VELOCITY),
            ("dw_c", &t.dw, CEILING_ACCELERATION),
        ] {
            check::finite_slice(what, v.as_slice())?;
            check::within(what, v.as_slice(), ceiling)?;
        }
        let q = if orients {
            rotation::rotation("R_c", &t.r)?
        } else {
            UnitQuaternion::identity()
        };
        Ok(Self {
            p: t.p,
            dp: t.dp,
            ddp: t.ddp,
            q,
            w: t.w,
            dw: t.dw,
        })
    }

    /// The same pose at rest (a step without a target holds the last one).
    pub(super) fn held(&self) -> Self {
        Self {
            dp: Vector::zeros(),
            ddp: Vector::zeros(),
            w: Vector::zeros(),
            dw: Vector::zeros(),
            ..*self
        }
    }
}
