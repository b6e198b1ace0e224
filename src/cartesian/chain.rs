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
use crate::math::{sin_cos, sqrt};
use crate::types::Vector;
use nalgebra::{Matrix3, Rotation3, Vector3};

mod transform;
pub use transform::*;

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

/// One movable joint in the core's form, its fixed predecessors folded in:
/// the frame of link i (the joint's child) is
///
/// ```text
/// F_i = F_{i−1} ∘ Trans(p) ∘ Rot(o) ∘ Rot_z(q_i + offset)     (revolute)
/// F_i = F_{i−1} ∘ Trans(p) ∘ Rot(o) ∘ Trans(z (q_i + offset))  (prismatic)
/// ```
///
/// so that every joint turns or slides along its own frame's z: the
/// description's frame of joint i is F_i B_iᵀ with B_i a constant rotation
/// (it takes z onto the joint's axis, [`align`]). Between two revolute
/// joints, o is moreover a twist about x, Rot_x(α) (the rest of o is turned
/// into the two joints' angles, [`untwist`]), as in the modified
/// Denavit–Hartenberg convention (Craig, *Introduction to Robotics*, 3rd ed.,
/// Pearson 2005, §3.4), which makes a link's transform cheaper to apply.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct Link {
    /// The joint's origin in the previous link's frame (m).
    pub(crate) p: Vector3<f64>,
    /// The joint frame's axes in the previous link's frame (at q_i = −offset).
    pub(crate) o: Matrix3<f64>,
    /// (cos α, sin α) when o = Rot_x(α).
    pub(crate) twist: Option<(f64, f64)>,
    /// Added to q_i (rad, m).
    pub(crate) offset: f64,
    /// Slides (true) or turns (false) along z.
    pub(crate) prismatic: bool,
}

impl Link {
    /// `r o`: the joint frame's axes in the world, given the previous
    /// link's `r`.
    #[inline(always)]
    pub(crate) fn axes(&self, r: &Matrix3<f64>) -> Matrix3<f64> {
        match self.twist {
            Some((c, s)) => {
                let (y, z) = (r.column(1), r.column(2));
                Matrix3::from_columns(&[r.column(0).into_owned(), y * c + z * s, z * c - y * s])
            }
            None => r * self.o,
        }
    }
}

impl Link {
    /// E = o Rot_z(θ) (o for a prismatic joint), s = sin θ, c = cos θ: link
    /// i's axes in link i − 1's frame.
    #[inline(always)]
    pub(crate) fn rotation(&self, s: f64, c: f64) -> Matrix3<f64> {
        match (self.prismatic, self.twist) {
            (true, _) => self.o,
            (false, Some((ca, sa))) => {
                Matrix3::new(c, -s, 0.0, ca * s, ca * c, -sa, sa * s, sa * c, ca)
            }
            (false, None) => turn(&self.o, s, c),
        }
    }

    /// E v: `v` of link i's frame in link i − 1's axes, E = o Rot_z(θ) (o
    /// for a prismatic joint), s = sin θ, c = cos θ.
    #[inline(always)]
    pub(crate) fn parent_of(&self, s: f64, c: f64, v: &Vector3<f64>) -> Vector3<f64> {
        let u = if self.prismatic {
            *v
        } else {
            Vector3::new(c * v[0] - s * v[1], s * v[0] + c * v[1], v[2])
        };
        match self.twist {
            Some((ca, sa)) => Vector3::new(u[0], ca * u[1] - sa * u[2], sa * u[1] + ca * u[2]),
            None => self.o * u,
        }
    }

    /// Eᵀ v: `v` of link i − 1's frame in link i's axes.
    #[inline(always)]
    pub(crate) fn child_of(&self, s: f64, c: f64, v: &Vector3<f64>) -> Vector3<f64> {
        let u = match self.twist {
            Some((ca, sa)) => Vector3::new(v[0], ca * v[1] + sa * v[2], ca * v[2] - sa * v[1]),
            None => self.o.tr_mul(v),
        };
        if self.prismatic {
            u
        } else {
            Vector3::new(c * u[0] + s * u[1], c * u[1] - s * u[0], u[2])
        }
    }

    /// E X Eᵀ for a symmetric X (the inertia of link i's frame in link
    /// i − 1's axes).
    #[inline(always)]
    pub(crate) fn sandwich(&self, s: f64, c: f64, x: &Matrix3<f64>) -> Matrix3<f64> {
        let x = if self.prismatic {
            *x
        } else {
            sandwich_z(x, s, c)
        };
        match self.twist {
            Some((ca, sa)) => sandwich_x(&x, ca, sa),
            None => {
                let y = self.o * x;
                let e = |a: usize, b: usize| y.row(a).dot(&self.o.row(b));
                let (xx, yy, zz, xy, xz, yz) =
                    (e(0, 0), e(1, 1), e(2, 2), e(0, 1), e(0, 2), e(1, 2));
                Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
            }
        }
    }
}

/// Rot_z(θ) X Rot_z(θ)ᵀ for a symmetric X, s = sin θ, c = cos θ.
#[inline(always)]
fn sandwich_z(i: &Matrix3<f64>, s: f64, c: f64) -> Matrix3<f64> {
    let (xx, yy, xy) = (i[(0, 0)], i[(1, 1)], i[(0, 1)]);
    let (xz, yz) = (i[(0, 2)], i[(1, 2)]);
    let (cc, ss, cs) = (c * c, s * s, c * s);
    let m = 2.0 * cs * xy;
    let nxx = cc * xx + ss * yy - m;
    let nyy = ss * xx + cc * yy + m;
    let nxy = cs * (xx - yy) + (cc - ss) * xy;
    let nxz = c * xz - s * yz;
    let nyz = s * xz + c * yz;
    Matrix3::new(nxx, nxy, nxz, nxy, nyy, nyz, nxz, nyz, i[(2, 2)])
}

/// Rot_x(α) X Rot_x(α)ᵀ for a symmetric X, c = cos α, s = sin α.
#[inline(always)]
fn sandwich_x(i: &Matrix3<f64>, c: f64, s: f64) -> Matrix3<f64> {
    let (yy, zz, yz) = (i[(1, 1)], i[(2, 2)], i[(1, 2)]);
    let (xy, xz) = (i[(0, 1)], i[(0, 2)]);
    let (cc, ss, cs) = (c * c, s * s, c * s);
    let m = 2.0 * cs * yz;
    let nyy = cc * yy + ss * zz - m;
    let nzz = ss * yy + cc * zz + m;
    let nyz = cs * (yy - zz) + (cc - ss) * yz;
    let nxy = c * xy - s * xz;
    let nxz = s * xy + c * xz;
    Matrix3::new(i[(0, 0)], nxy, nxz, nxy, nyy, nyz, nxz, nyz, nzz)
}

/// Rot_z(θ) for s = sin θ, c = cos θ.
fn rot_z(s: f64, c: f64) -> Matrix3<f64> {
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// o's decomposition Rot_z(a) Rot_x(α) Rot_z(c) (z–x–z Euler angles): (a,
/// (cos α, sin α), c), or None if o is not one to 1e-15 (it always is, up to
/// rounding).
fn untwist(o: &Matrix3<f64>) -> Option<(f64, (f64, f64), f64)> {
    let sin_b = sqrt(o[(0, 2)] * o[(0, 2)] + o[(1, 2)] * o[(1, 2)]);
    let (a, c) = if sin_b > 1e-12 {
        (
            libm::atan2(o[(0, 2)], -o[(1, 2)]),
            libm::atan2(o[(2, 0)], o[(2, 1)]),
        )
    } else {
        // α = 0 or π: o = Rot_z(a) Rot_x(α), c = 0.
        (libm::atan2(o[(1, 0)], o[(0, 0)]), 0.0)
    };
    let (sa, ca) = sin_cos(a);
    let (sc, cc) = sin_cos(c);
    let x = rot_z(sa, ca).transpose() * o * rot_z(sc, cc).transpose();
    let off = [x[(0, 1)], x[(0, 2)], x[(1, 0)], x[(2, 0)], x[(0, 0)] - 1.0];
    if off.iter().any(|v| v.abs() > 1e-15) {
        return None;
    }
    let (cb, sb) = (0.5 * (x[(1, 1)] + x[(2, 2)]), 0.5 * (x[(2, 1)] - x[(1, 2)]));
    let norm = sqrt(cb * cb + sb * sb);
    Some((a, (cb / norm, sb / norm), c))
}

/// A constant rotation A with A z = `axis` (unit): its columns are an
/// orthonormal frame (u, axis × u, axis) with det +1. Exact (entries 0 and
/// ±1) for an axis along ±x, ±y or ±z.
fn align(axis: &Vector3<f64>) -> Matrix3<f64> {
    let across = Vector3::y().cross(axis);
    let u = if across.norm_squared() > 0.25 {
        across.normalize()
    } else {
        Vector3::x().cross(axis).normalize()
    };
    Matrix3::from_columns(&[u, axis.cross(&u), *axis])
}

/// A movable joint's unit axis in its own frame (SPEC §16 (16.0), the
/// chain's description), checked with its offset: a finite, non-zero axis
/// (normalised; scaled first, so an axis of 1e300 does not overflow), a
/// finite offset of at most 1e6; the errors name joint `index`.
fn movable_axis(j: &Joint, index: usize) -> Result<Vector3<f64>, Error> {
    let axis = Vector3::from(j.axis);
    check::finite_slice("joint axis", axis.as_slice())?;
    // Scaled first: the norm of an axis of 1e300 overflows (to an
    // axis of zeros, and a frame of NaN in `align`).
    let scale = axis.amax();
    let unit = if scale > 0.0 { axis / scale } else { axis };
    let len = scale * unit.norm();
    if len.partial_cmp(&1e-12) != Some(core::cmp::Ordering::Greater) {
        return Err(Error::Condition {
            condition: "‖axis‖ > 0 (a movable joint needs an axis)",
            lhs: "joint axis",
            index: Some(index),
            value: len,
        });
    }
    let axis = unit / unit.norm();
    check::finite("joint offset", j.offset)?;
    if j.offset.abs() > 1e6 {
        return Err(Error::Condition {
            condition: "|offset| ≤ 1e6",
            lhs: "joint offset",
            index: Some(index),
            value: j.offset,
        });
    }
    Ok(axis)
}

/// `r Rot_z(θ)` for s = sin θ, c = cos θ: the first two columns turned.
#[inline(always)]
pub(crate) fn turn(r: &Matrix3<f64>, s: f64, c: f64) -> Matrix3<f64> {
    let (x, y) = (r.column(0), r.column(1));
    Matrix3::from_columns(&[x * c + y * s, y * c - x * s, r.column(2).into_owned()])
}

/// The rotation by `theta` (rad) about the unit `axis` (Rodrigues), for the
/// description's tree.
#[cfg(feature = "alloc")]
pub(crate) fn axis_rotation(axis: &Vector3<f64>, theta: f64) -> Matrix3<f64> {
    let (s, c) = sin_cos(theta);
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
        Self::aligned(joints, tip).map(|(chain, _)| chain)
    }

    /// [`new`](Self::new), and the rotations A_i of [`Link`]: the
    /// description's frame of movable joint i is link i's frame times A_iᵀ.
    pub(crate) fn aligned(
        joints: &[Joint],
        tip: &Transform,
    ) -> Result<(Self, [Matrix3<f64>; N]), Error> {
        Self::check_count(joints)?;
        let mut links = [Link {
            p: Vector3::zeros(),
            o: Matrix3::identity(),
            twist: None,
            offset: 0.0,
            prismatic: false,
        }; N];
        let mut aligns = [Matrix3::identity(); N];
        // The previous link's A (the base's frame is the description's).
        let mut prev = Matrix3::identity();
        let mut pending = Frame::IDENTITY;
        let mut i = 0;
        for (index, j) in joints.iter().enumerate() {
            let origin = pending.then(&j.origin.check(index)?);
            if j.kind == JointKind::Fixed {
                pending = origin;
                continue;
            }
            let axis = movable_axis(j, index)?;
            // Rot(axis, θ) = A Rot_z(θ) Aᵀ and Trans(axis d) = A Trans(z d) Aᵀ:
            // the Aᵀ folds into what follows (the next origin, the tip, the
            // link's inertials), the A into this origin.
            let a = align(&axis);
            links[i] = Link {
                p: prev.tr_mul(&origin.p),
                o: prev.tr_mul(&origin.r) * a,
                twist: None,
                offset: -j.offset,
                prismatic: j.kind == JointKind::Prismatic,
            };
            aligns[i] = a;
            prev = a;
            pending = Frame::IDENTITY;
            i += 1;
        }
        let t = pending.then(&tip.check(joints.len())?);
        let tip = Frame {
            p: prev.tr_mul(&t.p),
            r: prev.tr_mul(&t.r),
        };
        Self::untwist_links(&mut links, &mut aligns);
        Ok((Self { links, tip }, aligns))
    }

    /// The first check of [`aligned`](Self::aligned) (SPEC §16 (16.0)):
    /// 1 ≤ N ≤ 7, and the description has exactly N movable joints.
    fn check_count(joints: &[Joint]) -> Result<(), Error> {
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
        Ok(())
    }

    /// The last stage of [`aligned`](Self::aligned): between two revolute
    /// joints, o = Rot_z(a) Rot_x(α) Rot_z(c): Rot_z(a) turns link i − 1
    /// (its angle + a, its frame by Rot_z(a): B_{i−1}), Rot_z(c) adds to
    /// joint i's angle, o becomes the twist Rot_x(α) (modified DH, [`Link`]).
    fn untwist_links(links: &mut [Link; N], aligns: &mut [Matrix3<f64>; N]) {
        for i in 1..N {
            if links[i - 1].prismatic || links[i].prismatic {
                continue;
            }
            let Some((a, (ca, sa), c)) = untwist(&links[i].o) else {
                continue;
            };
            let (sn, cs) = sin_cos(a);
            let turn_a = rot_z(sn, cs);
            links[i - 1].offset += a;
            aligns[i - 1] *= turn_a;
            links[i].p = turn_a.tr_mul(&links[i].p);
            links[i].offset += c;
            links[i].o = Matrix3::new(1.0, 0.0, 0.0, 0.0, ca, -sa, 0.0, sa, ca);
            links[i].twist = Some((ca, sa));
        }
    }

    /// The joints in the core's form, base to tip.
    pub(crate) fn links(&self) -> &[Link; N] {
        &self.links
    }

    /// Whether joint `i` (of the N movable ones) is prismatic.
    pub fn is_prismatic(&self, i: usize) -> bool {
        self.links.get(i).is_some_and(|l| l.prismatic)
    }

    /// q (and q̇) as [`Chain::tip_checked`] takes them: finite and within
    /// their ceilings; the error names `q` or `dq` and the joint.
    pub fn check_motion(&self, q: &Vector<N>, dq: Option<&Vector<N>>) -> Result<(), Error> {
        use crate::control::safety::{CEILING_POSITION, CEILING_VELOCITY};
        check::finite_slice("q", q.as_slice())?;
        check::within("q", q.as_slice(), CEILING_POSITION)?;
        if let Some(dq) = dq {
            check::finite_slice("dq", dq.as_slice())?;
            check::within("dq", dq.as_slice(), CEILING_VELOCITY)?;
        }
        Ok(())
    }

    /// [`Kinematics::tip`] for a front that hands a user's values in: q (rad
    /// or m) and q̇ (rad/s or m/s) finite and within their ceilings (1e6, as
    /// a step's measurement; docs/reliability.md), so the pose, Jacobian and
    /// J̇ q̇ are finite (checked too). Errors name `q` or `dq` and the joint.
    pub fn tip_checked(&self, q: &Vector<N>, dq: &Vector<N>) -> Result<Tip<N>, Error> {
        self.check_motion(q, Some(dq))?;
        let t = self.tip(q, dq);
        let finite = t.position.iter().all(|x| x.is_finite())
            && t.rotation.matrix().iter().all(|x| x.is_finite())
            && t.jacobian.iter().all(|x| x.is_finite())
            && t.bias.iter().all(|x| x.is_finite());
        if !finite {
            return Err(Error::Diverged {
                what: "the chain's tip (pose, Jacobian or J̇ q̇)",
            });
        }
        Ok(t)
    }
}

/// The motion of one link in the world, from [`Chain::walk`]: its frame's
/// rotation `r` and origin `c` (on the axis of a revolute joint), its
/// angular velocity `w` and acceleration `al`, the classical acceleration
/// `a` of `c`, the joint's world axis `z` and origin `o` (before a prismatic
/// joint's travel).
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
    /// The forward recursion of (16.0), base to tip, world frame, with the
    /// joint accelerations `ddq` (none: q̈ = 0) and the base's acceleration
    /// `a0` (m/s²): calls `visit(i, motion)` for every link i, and returns
    /// the last one's motion.
    #[inline(always)]
    pub(crate) fn walk<F: FnMut(usize, &LinkMotion)>(
        &self,
        q: &Vector<N>,
        dq: &Vector<N>,
        ddq: Option<&Vector<N>>,
        a0: Vector3<f64>,
        mut visit: F,
    ) -> LinkMotion {
        // The link before joint i: its frame (r, c), the angular velocity w
        // and acceleration al, the acceleration a of c (no velocity of a
        // point enters an acceleration).
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
            let (r0, oi) = if i == 0 {
                (link.o, link.p)
            } else {
                (link.axes(&m.r), m.c + m.r * link.p)
            };
            let d = oi - m.c;
            let wxd = m.w.cross(&d);
            let ao = m.a + m.al.cross(&d) + m.w.cross(&wxd);
            let zi = r0.column(2).into_owned();
            let zdq = zi * dq[i];
            if link.prismatic {
                let s = zi * (q[i] + link.offset);
                let wxs = m.w.cross(&s);
                m.r = r0;
                m.c = oi + s;
                m.a = ao + m.al.cross(&s) + m.w.cross(&wxs) + 2.0 * m.w.cross(&zdq);
                if let Some(dd) = ddq {
                    m.a += zi * dd[i];
                }
            } else {
                let (sn, cs) = sin_cos(q[i] + link.offset);
                m.r = turn(&r0, sn, cs);
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

    /// The positions' pass of (16.0): link i's frame (rotation, origin)
    /// from the base out, calling `visit(i, z_i, o_i)` with joint i's world
    /// axis and origin (before a prismatic joint's travel); returns the last
    /// link's frame.
    #[inline(always)]
    fn frames<F: FnMut(usize, &Vector3<f64>, &Vector3<f64>)>(
        &self,
        q: &Vector<N>,
        mut visit: F,
    ) -> (Matrix3<f64>, Vector3<f64>) {
        let (mut r, mut c) = (Matrix3::identity(), Vector3::zeros());
        for (i, link) in self.links.iter().enumerate() {
            let (r0, oi) = if i == 0 {
                (link.o, link.p)
            } else {
                (link.axes(&r), c + r * link.p)
            };
            let z = r0.column(2).into_owned();
            visit(i, &z, &oi);
            if link.prismatic {
                r = r0;
                c = oi + z * (q[i] + link.offset);
            } else {
                let (sn, cs) = sin_cos(q[i] + link.offset);
                r = turn(&r0, sn, cs);
                c = oi;
            }
        }
        (r, c)
    }

    /// The tip's position p (m) and rotation R (world ← tip) at q.
    #[inline]
    pub fn pose(&self, q: &Vector<N>) -> (Vector3<f64>, Rotation3<f64>) {
        let (r, c) = self.frames(q, |_, _, _| {});
        (
            c + r * self.tip.p,
            Rotation3::from_matrix_unchecked(r * self.tip.r),
        )
    }

    /// The tip's pose and Jacobian at q (J̇ q̇ zero): (16.0)'s positions
    /// alone, without the recursion of velocities and accelerations.
    #[inline]
    pub fn pose_jacobian(&self, q: &Vector<N>) -> Tip<N> {
        let mut z = [Vector3::zeros(); N];
        let mut o = [Vector3::zeros(); N];
        let (r, c) = self.frames(q, |i, zi, oi| {
            z[i] = *zi;
            o[i] = *oi;
        });
        let p = c + r * self.tip.p;
        Tip {
            position: p,
            rotation: Rotation3::from_matrix_unchecked(r * self.tip.r),
            jacobian: self.jacobian_of(&p, &z, &o),
            bias: Vector::<6>::zeros(),
        }
    }

    /// J's columns [z_i × (p − o_i); z_i] (revolute), [z_i; 0] (prismatic).
    #[inline(always)]
    fn jacobian_of(
        &self,
        p: &Vector3<f64>,
        z: &[Vector3<f64>; N],
        o: &[Vector3<f64>; N],
    ) -> Jacobian6<N> {
        let mut jac = Jacobian6::<N>::zeros();
        for (i, link) in self.links.iter().enumerate() {
            if link.prismatic {
                jac.fixed_view_mut::<3, 1>(0, i).copy_from(&z[i]);
            } else {
                jac.fixed_view_mut::<3, 1>(0, i)
                    .copy_from(&z[i].cross(&(p - o[i])));
                jac.fixed_view_mut::<3, 1>(3, i).copy_from(&z[i]);
            }
        }
        jac
    }

    /// J̇ q̇ = [a(p); α_N] at (q, q̇) (m/s², rad/s²), (16.0), without the
    /// Jacobian.
    #[inline]
    pub fn bias(&self, q: &Vector<N>, dq: &Vector<N>) -> Vector<6> {
        let m = self.walk(q, dq, None, Vector3::zeros(), |_, _| {});
        let d = m.r * self.tip.p;
        let ap = m.a + m.al.cross(&d) + m.w.cross(&m.w.cross(&d));
        Vector::<6>::new(ap[0], ap[1], ap[2], m.al[0], m.al[1], m.al[2])
    }
}

impl<const N: usize> Kinematics<N> for Chain<N> {
    fn tip(&self, q: &Vector<N>, dq: &Vector<N>) -> Tip<N> {
        if dq.iter().all(|v| *v == 0.0) {
            // At rest J̇ q̇ = 0: the positions' pass alone.
            return self.pose_jacobian(q);
        }
        let mut z = [Vector3::zeros(); N];
        let mut o = [Vector3::zeros(); N];
        let last = self.walk(q, dq, None, Vector3::zeros(), |i, m| {
            z[i] = m.z;
            o[i] = m.o;
        });
        let LinkMotion { r, c, w, al, a, .. } = last;
        let d = r * self.tip.p;
        let p = c + d;
        let ap = a + al.cross(&d) + w.cross(&w.cross(&d));
        Tip {
            position: p,
            rotation: Rotation3::from_matrix_unchecked(r * self.tip.r),
            jacobian: self.jacobian_of(&p, &z, &o),
            bias: Vector::<6>::new(ap[0], ap[1], ap[2], al[0], al[1], al[2]),
        }
    }

    fn pose(&self, q: &Vector<N>) -> (Vector<3>, Rotation3<f64>) {
        Chain::pose(self, q)
    }
    fn fk(&self, q: &Vector<N>) -> Vector<3> {
        Chain::pose(self, q).0
    }
    fn rotation(&self, q: &Vector<N>) -> Rotation3<f64> {
        Chain::pose(self, q).1
    }
    fn jacobian(&self, q: &Vector<N>) -> Jacobian6<N> {
        self.pose_jacobian(q).jacobian
    }
    fn jdot_qdot(&self, q: &Vector<N>, dq: &Vector<N>) -> Vector<6> {
        self.bias(q, dq)
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
mod tests;
