//! Serial-chain kinematics, SPEC §16 (16.0): any arm of up to 7 revolute or
//! prismatic joints, described by plain joint data (what a URDF or a MuJoCo
//! model holds), with its tip pose, 6 × N Jacobian and `J̇ q̇` in one pass.
//!
//! The description is a list of [`Joint`]s from the base to the tip, each a
//! fixed `origin` transform (the parent joint's frame → this joint's frame,
//! URDF's `<origin xyz rpy>`), a `kind` and, for a movable joint, a unit
//! `axis` in its own frame. Fixed joints are folded into the next origin;
//! what follows the last movable joint, and the `tip` transform, into the tip.
//! A movable joint's frame moves by `Rot(axis, q − offset)` (revolute) or
//! `Trans(axis (q − offset))` (prismatic); `offset` is the joint value at
//! which the frame coincides with its origin (0 in a URDF; MuJoCo's
//! `qpos0`).
//!
//! The kinematics, per joint i with z_i its world axis, o_i its origin and ω,
//! α the angular velocity and classical acceleration of the link before it
//! (Siciliano et al., *Robotics*, Springer 2009, §3.1 (geometric Jacobian),
//! §7.5 (the recursion of velocities and accelerations, here with q̈ = 0)):
//!
//! ```text
//! J_i = [z_i × (p − o_i); z_i]  (revolute),   [z_i; 0]  (prismatic)
//! revolute:  ω_i = ω + z_i q̇_i,  α_i = α + ω × z_i q̇_i
//! prismatic: c_i = o_i + z_i q_i,
//!            a(c_i) = a(o_i) + α × z_i q_i + ω × (ω × z_i q_i) + 2 ω × z_i q̇_i
//! rigid link from c to d: a(d) = a(c) + α × (d − c) + ω × (ω × (d − c))
//! J̇ q̇ = [a(p); α_N]
//! ```
//!
//! No allocation; validation at construction returns errors naming the
//! condition and the joint, never panics.

use crate::cartesian::kinematics::{Jacobian6, Kinematics, Tip};
use crate::cartesian::rotation::ROTATION_TOLERANCE;
use crate::error::{check, Error};
use crate::math::{cos, sin, sqrt};
use crate::types::Vector;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// The most movable joints a [`Chain`] has (a 7-joint arm; the bindings are
/// built for 1 … 7).
pub const MAX_CHAIN_JOINTS: usize = 7;

/// What a joint of a chain does.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum JointKind {
    /// Rigid: folded into the next origin (URDF `fixed`).
    Fixed,
    /// Rotation about its axis by q (rad) (URDF `revolute`, `continuous`; MuJoCo `hinge`).
    Revolute,
    /// Translation along its axis by q (m) (URDF `prismatic`; MuJoCo `slide`).
    Prismatic,
}

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

    /// From a translation (m) and a rotation matrix.
    pub fn from_parts(translation: Vector3<f64>, rotation: &Matrix3<f64>) -> Self {
        Self {
            translation: translation.into(),
            rotation: core::array::from_fn(|i| core::array::from_fn(|j| rotation[(i, j)])),
        }
    }

    fn vector(&self) -> Vector3<f64> {
        Vector3::from(self.translation)
    }

    fn matrix(&self) -> Matrix3<f64> {
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
        Ok(Frame { p, r })
    }
}

/// One joint of a chain description, base to tip: see the [module docs](self).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Joint {
    /// Fixed, revolute or prismatic.
    pub kind: JointKind,
    /// The parent joint's frame → this joint's frame (at joint value `offset`).
    pub origin: Transform,
    /// The axis in this joint's frame; normalised here; non-zero and finite
    /// for a movable joint, ignored for a fixed one.
    pub axis: [f64; 3],
    /// The joint value (rad or m) at which the frame is `origin` (URDF: 0;
    /// MuJoCo: `qpos0`).
    pub offset: f64,
}

impl Joint {
    /// A fixed joint.
    pub fn fixed(origin: Transform) -> Self {
        Self {
            kind: JointKind::Fixed,
            origin,
            axis: [0.0; 3],
            offset: 0.0,
        }
    }
    /// A revolute joint about `axis` with offset 0.
    pub fn revolute(origin: Transform, axis: [f64; 3]) -> Self {
        Self {
            kind: JointKind::Revolute,
            origin,
            axis,
            offset: 0.0,
        }
    }
    /// A prismatic joint along `axis` with offset 0.
    pub fn prismatic(origin: Transform, axis: [f64; 3]) -> Self {
        Self {
            kind: JointKind::Prismatic,
            origin,
            axis,
            offset: 0.0,
        }
    }
}

/// A rigid transform: x_parent = r x + p.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct Frame {
    pub(crate) p: Vector3<f64>,
    pub(crate) r: Matrix3<f64>,
}

impl Frame {
    pub(crate) const IDENTITY: Self = Self {
        p: Vector3::new(0.0, 0.0, 0.0),
        r: Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
    };

    /// `self ∘ other`.
    pub(crate) fn then(&self, other: &Frame) -> Frame {
        Frame {
            p: self.p + self.r * other.p,
            r: self.r * other.r,
        }
    }
}

/// One movable joint, its fixed predecessors folded into its origin.
#[derive(Copy, Clone, Debug, PartialEq)]
struct Link {
    origin: Frame,
    axis: Vector3<f64>,
    prismatic: bool,
}

/// The rotation by `theta` (rad) about the unit `axis` (Rodrigues).
pub(crate) fn axis_rotation(axis: &Vector3<f64>, theta: f64) -> Matrix3<f64> {
    let (s, c) = (sin(theta), cos(theta));
    let k = axis.cross_matrix();
    Matrix3::identity() + k * s + k * k * (1.0 - c)
}

/// A serial chain of `N` movable joints (1 ≤ N ≤ 7): see the [module docs](self).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Chain<const N: usize> {
    links: [Link; N],
    tip: Frame,
}

impl<const N: usize> Chain<N> {
    /// The chain of `joints` (base to tip, fixed ones included; exactly `N`
    /// movable) and the `tip` transform (the last joint's frame → the tip).
    ///
    /// Errors, naming the condition and the joint's index in `joints`: N = 0
    /// or N > 7, another number of movable joints than N, a non-finite value,
    /// an origin beyond 1e6 m, a rotation that is not orthonormal (to 1e-6)
    /// or is a reflection, a zero or non-finite axis (a movable joint's axis
    /// is normalised), a non-finite or larger than 1e6 offset.
    pub fn new(joints: &[Joint], tip: &Transform) -> Result<Self, Error> {
        if N == 0 || N > MAX_CHAIN_JOINTS {
            return Err(Error::Condition {
                condition: "1 ≤ n ≤ 7 movable joints",
                lhs: "n",
                index: None,
                value: N as f64,
            });
        }
        let movable = joints.iter().filter(|j| j.kind != JointKind::Fixed).count();
        if movable != N {
            return Err(Error::Condition {
                condition: "the chain has n movable joints (the Chain's N)",
                lhs: "movable joints",
                index: None,
                value: movable as f64,
            });
        }
        let mut links = [Link {
            origin: Frame::IDENTITY,
            axis: Vector3::z(),
            prismatic: false,
        }; N];
        let mut pending = Frame::IDENTITY;
        let mut i = 0;
        for (index, j) in joints.iter().enumerate() {
            let origin = pending.then(&j.origin.check(index)?);
            if j.kind == JointKind::Fixed {
                pending = origin;
                continue;
            }
            let axis = Vector3::from(j.axis);
            check::finite_slice("joint axis", axis.as_slice())?;
            let len = axis.norm();
            if len.partial_cmp(&1e-12) != Some(core::cmp::Ordering::Greater) {
                return Err(Error::Condition {
                    condition: "‖axis‖ > 0 (a movable joint needs an axis)",
                    lhs: "joint axis",
                    index: Some(index),
                    value: len,
                });
            }
            let axis = axis / len;
            check::finite("joint offset", j.offset)?;
            if j.offset.abs() > 1e6 {
                return Err(Error::Condition {
                    condition: "|offset| ≤ 1e6",
                    lhs: "joint offset",
                    index: Some(index),
                    value: j.offset,
                });
            }
            let prismatic = j.kind == JointKind::Prismatic;
            // The frame at q = 0: the motion by −offset folded into the origin.
            let at_zero = if prismatic {
                Frame {
                    p: axis * -j.offset,
                    r: Matrix3::identity(),
                }
            } else {
                Frame {
                    p: Vector3::zeros(),
                    r: axis_rotation(&axis, -j.offset),
                }
            };
            links[i] = Link {
                origin: origin.then(&at_zero),
                axis,
                prismatic,
            };
            pending = Frame::IDENTITY;
            i += 1;
        }
        let tip = pending.then(&tip.check(joints.len())?);
        Ok(Self { links, tip })
    }

    /// Whether joint `i` (of the N movable ones) is prismatic.
    pub fn is_prismatic(&self, i: usize) -> bool {
        self.links.get(i).is_some_and(|l| l.prismatic)
    }
}

/// The motion of one movable joint's frame in the world, from
/// [`Chain::walk`]: its rotation `r` and origin `c` (on the axis of a
/// revolute joint), the angular velocity `w` and acceleration `al` of its
/// link, the classical acceleration `a` of `c`, the joint's world axis `z`
/// and origin `o` (before a prismatic joint's travel).
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct LinkMotion {
    pub r: Matrix3<f64>,
    pub c: Vector3<f64>,
    pub w: Vector3<f64>,
    pub al: Vector3<f64>,
    pub a: Vector3<f64>,
    pub z: Vector3<f64>,
    pub o: Vector3<f64>,
}

impl<const N: usize> Chain<N> {
    /// The forward recursion of (16.0), base to tip, with the joint
    /// accelerations `ddq` (none: q̈ = 0) and the base's acceleration `a0`
    /// (m/s²; −g for the dynamics, SPEC (20.2)): calls `visit(i, motion)`
    /// for every movable joint i, and returns the last one's motion.
    #[inline]
    pub(crate) fn walk<F: FnMut(usize, &LinkMotion)>(
        &self,
        q: &Vector<N>,
        dq: &Vector<N>,
        ddq: Option<&Vector<N>>,
        a0: Vector3<f64>,
        mut visit: F,
    ) -> LinkMotion {
        // The frame of the link before joint i: rotation r, origin c, the
        // angular velocity w and acceleration al, and the acceleration a of
        // c (no velocity of a point enters an acceleration).
        let mut m = LinkMotion {
            r: Matrix3::identity(),
            c: Vector3::zeros(),
            w: Vector3::zeros(),
            al: Vector3::zeros(),
            a: a0,
            z: Vector3::zeros(),
            o: Vector3::zeros(),
        };
        for (i, link) in self.links.iter().enumerate() {
            let d = m.r * link.origin.p;
            let wxd = m.w.cross(&d);
            let (oi, ao) = (m.c + d, m.a + m.al.cross(&d) + m.w.cross(&wxd));
            let r0 = m.r * link.origin.r;
            let zi = r0 * link.axis;
            let zdq = zi * dq[i];
            if link.prismatic {
                let s = zi * q[i];
                let wxs = m.w.cross(&s);
                m.r = r0;
                m.c = oi + s;
                m.a = ao + m.al.cross(&s) + m.w.cross(&wxs) + 2.0 * m.w.cross(&zdq);
                if let Some(dd) = ddq {
                    m.a += zi * dd[i];
                }
            } else {
                m.r = r0 * axis_rotation(&link.axis, q[i]);
                m.al += m.w.cross(&zdq);
                if let Some(dd) = ddq {
                    m.al += zi * dd[i];
                }
                m.w += zdq;
                m.c = oi;
                m.a = ao;
            }
            m.z = zi;
            m.o = oi;
            visit(i, &m);
        }
        m
    }
}

impl<const N: usize> Kinematics<N> for Chain<N> {
    fn tip(&self, q: &Vector<N>, dq: &Vector<N>) -> Tip<N> {
        let mut z = [Vector3::zeros(); N];
        let mut o = [Vector3::zeros(); N];
        let last = self.walk(q, dq, None, Vector3::zeros(), |i, m| {
            z[i] = m.z;
            o[i] = m.o;
        });
        let LinkMotion { r, c, w, al, a, .. } = last;
        let d = r * self.tip.p;
        let p = c + d;
        let wxd = w.cross(&d);
        let ap = a + al.cross(&d) + w.cross(&wxd);
        let mut jac = Jacobian6::<N>::zeros();
        for (i, link) in self.links.iter().enumerate() {
            let lin = if link.prismatic {
                z[i]
            } else {
                z[i].cross(&(p - o[i]))
            };
            jac.fixed_view_mut::<3, 1>(0, i).copy_from(&lin);
            if !link.prismatic {
                jac.fixed_view_mut::<3, 1>(3, i).copy_from(&z[i]);
            }
        }
        let mut bias = Vector::<6>::zeros();
        bias.fixed_rows_mut::<3>(0).copy_from(&ap);
        bias.fixed_rows_mut::<3>(3).copy_from(&al);
        Tip {
            position: p,
            rotation: Rotation3::from_matrix_unchecked(r * self.tip.r),
            jacobian: jac,
            bias,
        }
    }
}

/// Three movable joints with every kind of element, for tests: a fixed base
/// offset, a revolute joint with a tilted origin, a prismatic joint, a fixed
/// elbow, a revolute joint about an oblique axis with an offset.
#[cfg(test)]
pub(crate) fn sample_joints() -> [Joint; 5] {
    [
        Joint::fixed(Transform::from_xyz_rpy([0.0, 0.0, 0.1], [0.0, 0.0, 0.3])),
        Joint::revolute(
            Transform::from_xyz_rpy([0.0, 0.05, 0.2], [0.2, -0.1, 0.0]),
            [0.0, 0.0, 1.0],
        ),
        Joint::prismatic(
            Transform::from_xyz_rpy([0.3, 0.0, 0.0], [0.0, 0.5, 0.0]),
            [1.0, 0.0, 0.0],
        ),
        Joint::fixed(Transform::from_xyz_rpy([0.1, 0.0, 0.0], [0.0, 0.0, 1.0])),
        Joint {
            offset: 0.25,
            ..Joint::revolute(
                Transform::from_xyz_rpy([0.0, 0.2, 0.0], [0.0, 0.0, 0.0]),
                [1.0, 2.0, 2.0],
            )
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3-joint arm with every kind of element ([`sample_joints`]).
    fn arm() -> Chain<3> {
        Chain::new(
            &sample_joints(),
            &Transform::from_xyz_rpy([0.0, 0.0, 0.15], [0.1, 0.2, 0.3]),
        )
        .unwrap()
    }

    #[test]
    fn jacobian_and_bias_are_the_derivatives_of_the_pose() {
        let c = arm();
        let q = Vector::<3>::new(0.4, 0.12, -0.7);
        let dq = Vector::<3>::new(0.9, -0.3, 1.4);
        let h = 1e-6;
        let j = c.jacobian(&q);
        for i in 0..3 {
            let mut e = Vector::<3>::zeros();
            e[i] = h;
            let dp = (c.fk(&(q + e)) - c.fk(&(q - e))) / (2.0 * h);
            let dr = c.rotation(&(q + e)) * c.rotation(&(q - e)).inverse();
            let w = crate::cartesian::rotation::log_quaternion(
                &nalgebra::UnitQuaternion::from_rotation_matrix(&dr),
            ) / (2.0 * h);
            assert!(
                (dp - j.fixed_view::<3, 1>(0, i)).norm() < 1e-8,
                "J_v column {i}"
            );
            assert!(
                (w - j.fixed_view::<3, 1>(3, i)).norm() < 1e-8,
                "J_ω column {i}"
            );
        }
        let numeric = (c.jacobian(&(q + h * dq)) - c.jacobian(&(q - h * dq))) / (2.0 * h) * dq;
        let bias = c.jdot_qdot(&q, &dq);
        assert!((bias - numeric).norm() < 1e-7, "{bias} vs {numeric}");
    }

    #[test]
    fn bad_descriptions_are_refused_by_name() {
        let ok = Joint::revolute(Transform::IDENTITY, [0.0, 0.0, 1.0]);
        let e = Chain::<1>::new(
            &[Joint::revolute(Transform::IDENTITY, [0.0; 3])],
            &Transform::IDENTITY,
        )
        .unwrap_err();
        assert!(e.to_string().contains("‖axis‖ > 0"), "{e}");
        assert!(e.to_string().contains("joint axis[0]"), "{e}");
        let mut skew = Transform::IDENTITY;
        skew.rotation[0][1] = 0.1;
        let e = Chain::<1>::new(
            &[Joint::revolute(skew, [0.0, 0.0, 1.0])],
            &Transform::IDENTITY,
        )
        .unwrap_err();
        assert!(e.to_string().contains("orthonormal"), "{e}");
        let e = Chain::<2>::new(&[ok], &Transform::IDENTITY).unwrap_err();
        assert!(e.to_string().contains("movable joints = 1"), "{e}");
        let e = Chain::<8>::new(&[ok; 8], &Transform::IDENTITY).unwrap_err();
        assert!(e.to_string().contains("1 ≤ n ≤ 7"), "{e}");
        assert!(Transform::from_pos_quat([0.0; 3], [0.0; 4]).is_err());
    }

    #[test]
    fn offset_shifts_the_joint_value() {
        let origin = Transform::from_xyz_rpy([0.1, 0.0, 0.0], [0.0, 0.0, 0.0]);
        let tip = Transform::from_xyz_rpy([0.3, 0.0, 0.0], [0.0, 0.0, 0.0]);
        let plain = Chain::<1>::new(&[Joint::revolute(origin, [0.0, 0.0, 1.0])], &tip).unwrap();
        let shifted = Chain::<1>::new(
            &[Joint {
                offset: 0.4,
                ..Joint::revolute(origin, [0.0, 0.0, 1.0])
            }],
            &tip,
        )
        .unwrap();
        let q = Vector::<1>::new(0.9);
        let a = plain.fk(&Vector::<1>::new(0.5));
        let b = shifted.fk(&q);
        assert!((a - b).norm() < 1e-15, "{a} vs {b}");
    }
}
