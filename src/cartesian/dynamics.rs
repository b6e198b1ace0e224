//! Rigid-body dynamics of a serial chain, SPEC §20: the inertials of its
//! links (20.1), the recursive Newton–Euler algorithm (20.2),
//! τ = M(q) q̈ + C(q, q̇) q̇ + G(q), the mass matrix and the gravity torque,
//! and the joints' drive terms (20.5): armature, viscous damping and the dry
//! friction that computed torque compensates (20.6). No allocation; validation at construction returns errors
//! naming the condition and the entry, never panics.
//!
//! Units: kg, m, kg m², rad (m for a prismatic joint), N m (N).

use crate::cartesian::chain::{Chain, Frame, Joint, JointKind, Link, Transform};
use crate::error::{check, Error, PARAM_BOUND};
use crate::math::{sin_cos, tanh};
use crate::types::{Matrix, Vector};
use nalgebra::{Matrix3, Vector3};

mod drive;
mod inertial;
pub use drive::*;
pub use inertial::*;

/// Standard gravity (m/s²), along −z of the chain's base frame: the default
/// of [`Dynamics::new`]'s `gravity`.
pub const GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// The rigid body of one movable joint, in its frame, (20.1): the mass m
/// (kg), the first moment h = m c (kg m) and the inertia about the frame's
/// origin (kg m²).
#[derive(Copy, Clone, Debug, PartialEq)]
struct Body {
    m: f64,
    h: Vector3<f64>,
    i: Matrix3<f64>,
}

impl Body {
    const EMPTY: Self = Self {
        m: 0.0,
        h: Vector3::new(0.0, 0.0, 0.0),
        i: Matrix3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    };

    /// Add a mass `m` at `c` with the inertia `ic` about `c` (the body's
    /// axes): the parallel-axis theorem.
    fn add(&mut self, m: f64, c: Vector3<f64>, ic: Matrix3<f64>) {
        self.m += m;
        self.h += m * c;
        self.i += ic + m * (Matrix3::identity() * c.norm_squared() - c * c.transpose());
    }
}

/// A chain with the inertials of its links and gravity: inverse dynamics by
/// the recursive Newton–Euler algorithm, SPEC §20. Cheap to copy (N ≤ 7
/// bodies of 13 reals and the chain).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Dynamics<const N: usize> {
    chain: Chain<N>,
    bodies: [Body; N],
    /// The weight each body's gravity compensation lifts (MuJoCo's
    /// `gravcomp`): the mass m and first moment h of what it lifts, in the
    /// body's frame (its inertia unused); None: no compensation.
    lifted: Option<[Body; N]>,
    gravity: Vector3<f64>,
    drive: Drive<N>,
    sampled: Option<SampledDrive<N>>,
    spring: Option<Spring<N>>,
}

impl<const N: usize> Dynamics<N> {
    /// The dynamics of the chain of `joints` (as [`Chain::new`] takes them)
    /// with `inertials[k]` the inertial of joint k's child link in that
    /// link's frame (one per entry of `joints`, fixed ones too;
    /// [`Inertial::NONE`] for none), under `gravity` (m/s², in the base frame;
    /// [`GRAVITY`] on Earth). Each inertial belongs to the last movable
    /// joint at or before its entry (the fixed joints fold); those before the
    /// first movable joint are the base's and take no part (20.1).
    ///
    /// Errors, naming the condition and the entry: those of [`Chain::new`],
    /// another number of inertials than joints, a negative or non-finite
    /// mass, an inertia that is not finite or symmetric or has a negative
    /// diagonal, a non-finite gravity.
    pub fn new(joints: &[Joint], inertials: &[Inertial], gravity: [f64; 3]) -> Result<Self, Error> {
        let (chain, aligns) = Chain::<N>::aligned(joints, &Transform::IDENTITY)?;
        if inertials.len() != joints.len() {
            return Err(Error::Condition {
                condition: "one inertial per joint of the list (fixed ones too)",
                lhs: "inertials",
                index: None,
                value: inertials.len() as f64,
            });
        }
        check::at_most_each("|value| ≤ 1e9", "gravity", &gravity, PARAM_BOUND)?;
        let bodies = fold::<N>(joints, inertials, &aligns)?;
        Ok(Self {
            chain,
            bodies,
            lifted: None,
            gravity: Vector3::from(gravity),
            drive: Drive::none(),
            sampled: None,
            spring: None,
        })
    }

    /// The model with gravity compensation (MuJoCo's `gravcomp`, SPEC
    /// (20.1')): `lifted[k]` what is lifted in the link of entry k of
    /// `joints` (as [`new`](Self::new) took them, fixed ones too). Inverse
    /// dynamics and the gravity torque then carry the weight less what is
    /// lifted: MuJoCo's `qfrc_gravcomp` taken off. Replaces any compensation
    /// set before.
    ///
    /// Errors, naming the entry: other joints than the model's, another
    /// number of entries, a mass or moment not finite or beyond 1e9.
    pub fn with_gravity_compensation(
        mut self,
        joints: &[Joint],
        lifted: &[Lifted],
    ) -> Result<Self, Error> {
        let (chain, aligns) = Chain::<N>::aligned(joints, &Transform::IDENTITY)?;
        if chain != self.chain {
            return Err(Error::Invalid {
                what: "gravity compensation",
                reason: "needs the joints the model was built from",
            });
        }
        if lifted.len() != joints.len() {
            return Err(Error::Condition {
                condition: "one lifted mass per joint of the list (fixed ones too)",
                lhs: "lifted",
                index: None,
                value: lifted.len() as f64,
            });
        }
        let mut bodies = [Body::EMPTY; N];
        let mut body: Option<usize> = None;
        let mut pending = Frame::IDENTITY;
        for (index, (j, l)) in joints.iter().zip(lifted).enumerate() {
            check::finite("lifted mass", l.mass)?;
            check::finite_slice("lifted moment", &l.moment)?;
            for v in [l.mass, l.moment[0], l.moment[1], l.moment[2]] {
                check::at_most(
                    "|value| ≤ 1e9",
                    "lifted mass or moment",
                    v.abs(),
                    PARAM_BOUND,
                )?;
            }
            if j.kind == JointKind::Fixed {
                pending = pending.then(&j.origin.check(index)?);
            } else {
                body = Some(body.map_or(0, |b| b + 1));
                pending = Frame::IDENTITY;
            }
            if let Some(b) = body {
                bodies[b].m += l.mass;
                bodies[b].h += pending.r * Vector3::from(l.moment) + l.mass * pending.p;
            }
        }
        for (b, a) in bodies.iter_mut().zip(&aligns) {
            b.h = a.tr_mul(&b.h);
        }
        self.lifted = bodies
            .iter()
            .any(|b| b.m != 0.0 || b.h != Vector3::zeros())
            .then_some(bodies);
        Ok(self)
    }

    /// The model with the joints' drive terms `drive` (SPEC (20.5)): the
    /// mass matrix gains diag(armature), inverse dynamics armature ⊙ q̈ +
    /// damping ⊙ q̇, and computed torque compensates the friction (20.6).
    /// Replaces any drive set before.
    ///
    /// Errors, naming the term and the joint: a negative or non-finite entry.
    pub fn with_drive(mut self, drive: Drive<N>) -> Result<Self, Error> {
        drive.check()?;
        self.drive = drive;
        Ok(self)
    }

    /// The model with how a simulated plant realises the drive within a
    /// period (SPEC (20.9)): computed torque then inverts the plant's period
    /// joint by joint for its damping and friction, in place of (20.6).
    ///
    /// Errors, naming the term: h ≤ 0 or beyond 1 s, s outside 1 … 1000, a
    /// negative or non-finite R or b_r.
    pub fn with_sampled_drive(mut self, sampled: SampledDrive<N>) -> Result<Self, Error> {
        sampled.check()?;
        self.sampled = Some(sampled);
        Ok(self)
    }

    /// The model with passive joint springs (SPEC (20.5')): inverse dynamics
    /// gains k ⊙ (q − q_s). Errors, naming the term and the joint: a negative
    /// or non-finite stiffness, a reference not finite or beyond 1e9.
    pub fn with_spring(mut self, spring: Spring<N>) -> Result<Self, Error> {
        check::nonnegative_vec("stiffness ≥ 0", "stiffness", &spring.stiffness)?;
        for (what, v) in [
            ("stiffness", &spring.stiffness),
            ("spring reference", &spring.reference),
        ] {
            check::finite_slice(what, v.as_slice())?;
            check::at_most_each("|value| ≤ 1e9", what, v.as_slice(), PARAM_BOUND)?;
        }
        self.spring = Some(spring);
        Ok(self)
    }

    /// The passive springs, if given ([`with_spring`](Self::with_spring)).
    pub fn spring(&self) -> Option<&Spring<N>> {
        self.spring.as_ref()
    }

    /// How far back (s) the plant's reported velocity is (SPEC (20.9')):
    /// h/2 for semi-implicit integrator steps, else 0.
    pub fn velocity_lag(&self) -> f64 {
        match &self.sampled {
            Some(s) if s.semi_implicit => 0.5 * s.substep,
            _ => 0.0,
        }
    }

    /// How the plant realises the drive, if given ([`with_sampled_drive`](Self::with_sampled_drive)).
    pub fn sampled_drive(&self) -> Option<&SampledDrive<N>> {
        self.sampled.as_ref()
    }

    /// The drive's torque beyond the rigid links' that computed torque
    /// applies at (q, q̇) for the acceleration `a` (rad/s²) it commands, on
    /// the reference velocity `v_r`: with a [`SampledDrive`], (20.9): for
    /// each joint with damping or friction, the torque that gives joint i
    /// the velocity q̇_i + a_i·s·h after the plant's period, less the
    /// continuous model's own M_ii a_i + b_i q̇_i (which
    /// [`inverse_dynamics`](Self::inverse_dynamics) holds); without one, the
    /// compensation (20.6).
    pub fn drive_torque(
        &self,
        q: &Vector<N>,
        dq: &Vector<N>,
        a: &Vector<N>,
        v_r: &Vector<N>,
    ) -> Vector<N> {
        let Some(s) = &self.sampled else {
            return self.drive.friction_torque(v_r, dq);
        };
        let d = &self.drive;
        if d.damping.iter().chain(d.friction.iter()).all(|x| *x == 0.0) {
            return Vector::zeros();
        }
        let m = self.mass_matrix(q);
        Vector::from_fn(|i, _| {
            let joint = JointTerms {
                m: m[(i, i)],
                b: d.damping[i],
                f: d.friction[i],
                r: s.regularisation[i],
                br: s.rate[i],
            };
            if (joint.b == 0.0 && joint.f == 0.0) || joint.m.is_nan() || joint.m <= 0.0 {
                return 0.0;
            }
            let continuous = joint.m * a[i] + joint.b * dq[i];
            s.joint_torque(joint, dq[i], a[i], continuous) - continuous
        })
    }

    /// The joints' drive terms (zeros unless [`with_drive`](Self::with_drive)).
    pub fn drive(&self) -> &Drive<N> {
        &self.drive
    }

    /// The chain (for its kinematics; its tip is the last joint's frame).
    pub fn chain(&self) -> &Chain<N> {
        &self.chain
    }

    /// Gravity (m/s², base frame).
    pub fn gravity(&self) -> [f64; 3] {
        self.gravity.into()
    }

    /// Total mass of the moving links (kg).
    pub fn mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.m).sum()
    }

    /// Every mass and inertia times `factor` (> 0, finite), the centres of
    /// mass kept: a uniform change of density (20.1). Each link's mass and
    /// inertia stay at most 1e9, as a given link's (a factor of 1e300 was
    /// accepted, and the model overflowed in use).
    pub fn scaled(mut self, factor: f64) -> Result<Self, Error> {
        check::positive("mass_scale > 0", "mass_scale", factor)?;
        check::at_most("|value| ≤ 1e9", "mass_scale", factor, PARAM_BOUND)?;
        for b in self
            .bodies
            .iter_mut()
            .chain(self.lifted.iter_mut().flatten())
        {
            b.m *= factor;
            b.h *= factor;
            b.i *= factor;
        }
        self.check_bodies("mass_scale·mass ≤ 1e9 kg and mass_scale·inertia ≤ 1e9 kg m²")?;
        Ok(self)
    }

    /// A point mass `mass` (kg, ≥ 0, at most 1e9, finite) at the origin of
    /// the last joint's frame added (a payload, 20.1).
    pub fn with_payload(mut self, mass: f64) -> Result<Self, Error> {
        check::nonnegative("payload ≥ 0", "payload", mass)?;
        check::at_most("|value| ≤ 1e9", "payload", mass, PARAM_BOUND)?;
        if let Some(b) = self.bodies.last_mut() {
            b.m += mass;
        }
        self.check_bodies("mass + payload ≤ 1e9 kg")?;
        Ok(self)
    }

    /// Every body's mass and inertia at most [`PARAM_BOUND`], else `condition`.
    fn check_bodies(&self, condition: &'static str) -> Result<(), Error> {
        for (index, b) in self.bodies.iter().enumerate() {
            let big = b.m.max(b.i.amax()).max(b.h.amax());
            if big.is_nan() || big > PARAM_BOUND {
                return Err(Error::Condition {
                    condition,
                    lhs: "link mass or inertia",
                    index: Some(index),
                    value: big,
                });
            }
        }
        Ok(())
    }

    /// [`inverse_dynamics`](Self::inverse_dynamics) for a front that hands a
    /// user's values in: q, q̇, q̈ finite and within their ceilings (1e6 rad,
    /// rad/s, rad/s², as a step's), the torque finite. Errors name the input.
    pub fn inverse_dynamics_checked(
        &self,
        q: &Vector<N>,
        dq: &Vector<N>,
        ddq: &Vector<N>,
    ) -> Result<Vector<N>, Error> {
        use crate::control::safety::{CEILING_ACCELERATION, CEILING_POSITION, CEILING_VELOCITY};
        for (what, v, ceiling) in [
            ("q", q, CEILING_POSITION),
            ("dq", dq, CEILING_VELOCITY),
            ("ddq", ddq, CEILING_ACCELERATION),
        ] {
            check::finite_slice(what, v.as_slice())?;
            check::within(what, v.as_slice(), ceiling)?;
        }
        let tau = self.inverse_dynamics(q, dq, ddq);
        if tau.iter().any(|t| !t.is_finite()) {
            return Err(Error::Diverged {
                what: "inverse dynamics (the torque)",
            });
        }
        Ok(tau)
    }

    /// [`mass_matrix`](Self::mass_matrix) at a q finite and within 1e6, its
    /// entries finite; else an error naming `q`.
    pub fn mass_matrix_checked(&self, q: &Vector<N>) -> Result<Matrix<N>, Error> {
        use crate::control::safety::CEILING_POSITION;
        check::finite_slice("q", q.as_slice())?;
        check::within("q", q.as_slice(), CEILING_POSITION)?;
        let m = self.mass_matrix(q);
        if m.iter().any(|x| !x.is_finite()) {
            return Err(Error::Diverged {
                what: "the mass matrix",
            });
        }
        Ok(m)
    }

    /// ID(q, q̇, q̈) = M(q) q̈ + C(q, q̇) q̇ + G(q) + I_a ⊙ q̈ + b ⊙ q̇ (N m,
    /// N): RNEA (20.2) with the drive's armature and damping (20.5), and
    /// + k ⊙ (q − q_s) with springs (20.5').
    #[inline]
    pub fn inverse_dynamics(&self, q: &Vector<N>, dq: &Vector<N>, ddq: &Vector<N>) -> Vector<N> {
        let tau = self.rnea(q, dq, ddq, -self.gravity) - self.lifted_torque(q)
            + self.drive.armature.component_mul(ddq)
            + self.drive.damping.component_mul(dq);
        match &self.spring {
            None => tau,
            Some(s) => tau + s.stiffness.component_mul(&(q - s.reference)),
        }
    }

    /// G(q) = RNEA(q, 0, 0) (N m, N), less what gravity compensation lifts.
    pub fn gravity_torque(&self, q: &Vector<N>) -> Vector<N> {
        let z = Vector::<N>::zeros();
        self.rnea(q, &z, &z, -self.gravity) - self.lifted_torque(q)
    }

    /// The torque of the weight gravity compensation lifts at q (N m, N):
    /// MuJoCo's `qfrc_gravcomp` with the opposite sign (zero without it).
    fn lifted_torque(&self, q: &Vector<N>) -> Vector<N> {
        match &self.lifted {
            None => Vector::zeros(),
            Some(lifted) => {
                let z = Vector::<N>::zeros();
                self.rnea_of(lifted, q, &z, &z, -self.gravity)
            }
        }
    }
}

/// The model's gravity G(q) fed forward by a joint controller, SPEC (20.10)
/// ([`Controller::with_feedforward`](crate::control::controller::Controller::with_feedforward)).
impl<const N: usize> crate::control::io::Feedforward<N> for Dynamics<N> {
    fn torque(&self, q: &Vector<N>) -> Vector<N> {
        self.gravity_torque(q)
    }
}

impl<const N: usize> Dynamics<N> {
    /// M_a(q) v = RNEA₀(q, 0, v) + I_a ⊙ v, without gravity (N m, N), (20.5).
    #[inline]
    pub fn mass_times(&self, q: &Vector<N>, v: &Vector<N>) -> Vector<N> {
        self.rnea(q, &Vector::zeros(), v, Vector3::zeros()) + self.drive.armature.component_mul(v)
    }

    /// M_a(q) = M(q) + diag(I_a) (kg m², kg), (20.5): the composite-rigid-body
    /// algorithm, SPEC (20.2).
    pub fn mass_matrix(&self, q: &Vector<N>) -> Matrix<N> {
        let links = self.chain.links();
        // Each link's place in the previous link's frame (the first one's
        // does not enter M): sin and cos of its angle, its origin.
        let mut sc = [(0.0, 1.0); N];
        let mut r = [Vector3::zeros(); N];
        for i in 1..N {
            (sc[i], r[i]) = place(&links[i], q[i]);
        }
        // Tip to base: the composite body k (the links from k to the tip, in
        // link k's frame) gives column k (the force and moment it needs for
        // q̈_k = 1) and joins link k − 1; every column j ≥ k is carried into
        // link k − 1's frame, where M_{k−1,j} = z · (the moment, or the force
        // for a prismatic joint k − 1).
        let mut cols = [[0.0; N]; N];
        let mut f = [Vector3::zeros(); N];
        let mut n = [Vector3::zeros(); N];
        let mut comp = self.bodies[N - 1];
        for k in (0..N).rev() {
            let (fj, nj) = if links[k].prismatic {
                (
                    Vector3::new(0.0, 0.0, comp.m),
                    Vector3::new(comp.h[1], -comp.h[0], 0.0),
                )
            } else {
                (
                    Vector3::new(-comp.h[1], comp.h[0], 0.0),
                    comp.i.column(2).into_owned(),
                )
            };
            (f[k], n[k]) = (fj, nj);
            cols[k][k] = if links[k].prismatic { fj[2] } else { nj[2] } + self.drive.armature[k];
            if k == 0 {
                break;
            }
            let l = &links[k];
            let (sn, cs) = sc[k];
            let rk = r[k];
            // The composite into link k − 1's frame, joined to its body:
            // + E I Eᵀ + m(|r|² 1 − r rᵀ) + 2 (r·h) 1 − r hᵀ − h rᵀ.
            let (m, h, x) = (
                comp.m,
                l.parent_of(sn, cs, &comp.h),
                l.sandwich(sn, cs, &comp.i),
            );
            let u = rk * m + h;
            let d = rk.dot(&(u + h));
            let mut next = self.bodies[k - 1];
            next.m += m;
            next.h += u;
            for a in 0..3 {
                for b in a..3 {
                    let v = x[(a, b)] - rk[a] * u[b] - h[a] * rk[b] + if a == b { d } else { 0.0 };
                    next.i[(a, b)] += v;
                    if a != b {
                        next.i[(b, a)] += v;
                    }
                }
            }
            comp = next;
            let z_of = |f: &Vector3<f64>, n: &Vector3<f64>| {
                if links[k - 1].prismatic {
                    f[2]
                } else {
                    n[2]
                }
            };
            let e = l.rotation(sn, cs);
            for j in k..N {
                let fp = e * f[j];
                let np = e * n[j] + rk.cross(&fp);
                let v = z_of(&fp, &np);
                cols[j][k - 1] = v;
                cols[k - 1][j] = v;
                (f[j], n[j]) = (fp, np);
            }
        }
        Matrix::from_data(nalgebra::ArrayStorage(cols))
    }

    /// The recursion of (20.2) in the links' frames with the base
    /// accelerating at `a0` (world): τ of the rigid links (no drive).
    #[inline]
    fn rnea(&self, q: &Vector<N>, dq: &Vector<N>, ddq: &Vector<N>, a0: Vector3<f64>) -> Vector<N> {
        self.rnea_of(&self.bodies, q, dq, ddq, a0)
    }

    /// [`rnea`](Self::rnea) of other bodies on the same chain.
    #[inline]
    fn rnea_of(
        &self,
        bodies: &[Body; N],
        q: &Vector<N>,
        dq: &Vector<N>,
        ddq: &Vector<N>,
        a0: Vector3<f64>,
    ) -> Vector<N> {
        let links = self.chain.links();
        let mut sc = [(0.0, 1.0); N];
        let mut r = [Vector3::zeros(); N];
        let mut f = [Vector3::zeros(); N];
        let mut n = [Vector3::zeros(); N];
        // Forward: each link's angular velocity w, acceleration al and the
        // classical acceleration a of its origin, in its own frame.
        let (mut w, mut al, mut a) = (Vector3::zeros(), Vector3::zeros(), a0);
        for (i, l) in links.iter().enumerate() {
            let ((sn, cs), ri) = place(l, q[i]);
            (sc[i], r[i]) = ((sn, cs), ri);
            // The previous link's motion at this link's origin, in its axes.
            if i > 0 {
                a += al.cross(&ri) + w.cross(&w.cross(&ri));
            }
            a = l.child_of(sn, cs, &a);
            w = l.child_of(sn, cs, &w);
            if l.prismatic {
                // The link slides along z at q̇, q̈ (its origin r_i moved).
                al = l.child_of(sn, cs, &al);
                a += Vector3::new(w[1], -w[0], 0.0) * (2.0 * dq[i]);
                a[2] += ddq[i];
            } else {
                // al = Eᵀ al + w' × z q̇ + z q̈, w' = Eᵀ w.
                al = l.child_of(sn, cs, &al) + Vector3::new(w[1], -w[0], 0.0) * dq[i];
                al[2] += ddq[i];
                w[2] += dq[i];
            }
            let b = &bodies[i];
            let iw = b.i * w;
            f[i] = a * b.m + al.cross(&b.h) + w.cross(&w.cross(&b.h));
            n[i] = b.i * al + w.cross(&iw) + b.h.cross(&a);
        }
        // Backward: what each joint transmits, tip to base.
        let mut tau = Vector::<N>::zeros();
        for i in (0..N).rev() {
            tau[i] = if links[i].prismatic { f[i][2] } else { n[i][2] };
            if i > 0 {
                let (sn, cs) = sc[i];
                let l = &links[i];
                let fp = l.parent_of(sn, cs, &f[i]);
                let np = l.parent_of(sn, cs, &n[i]) + r[i].cross(&fp);
                f[i - 1] += fp;
                n[i - 1] += np;
            }
        }
        tau
    }
}

/// The bodies of (20.1) of `inertials` on `joints` (one each, fixed ones
/// too): each inertial belongs to the last movable joint at or before its
/// entry (those before the first movable joint to the base, left out), in
/// the links' frames of the core's form (`aligns`, [`Chain::aligned`]).
fn fold<const N: usize>(
    joints: &[Joint],
    inertials: &[Inertial],
    aligns: &[Matrix3<f64>; N],
) -> Result<[Body; N], Error> {
    let mut bodies = [Body::EMPTY; N];
    // The body the entries belong to, and the frame of the current entry's
    // child link in that body's frame.
    let mut body: Option<usize> = None;
    let mut pending = Frame::IDENTITY;
    for (index, (j, inertial)) in joints.iter().zip(inertials).enumerate() {
        let (origin, ic) = inertial.check(index)?;
        if j.kind == JointKind::Fixed {
            pending = pending.then(&j.origin.check(index)?);
        } else {
            body = Some(body.map_or(0, |b| b + 1));
            pending = Frame::IDENTITY;
        }
        if let Some(b) = body {
            let f = pending.then(&origin);
            bodies[b].add(inertial.mass, f.p, f.r * ic * f.r.transpose());
        }
    }
    // Into the links' frames of the core's form (the description's frame of
    // joint i is link i's times A_iᵀ).
    for (b, a) in bodies.iter_mut().zip(aligns) {
        b.h = a.tr_mul(&b.h);
        b.i = a.tr_mul(&b.i) * a;
    }
    Ok(bodies)
}

/// Link `l`'s place in the previous link's frame at its joint value `q`:
/// (sin θ, cos θ) of its angle ((0, 1) for a prismatic joint) and its origin
/// (p, or p + o z (q + offset) for a prismatic joint).
#[inline(always)]
fn place(l: &Link, q: f64) -> ((f64, f64), Vector3<f64>) {
    if l.prismatic {
        ((0.0, 1.0), l.p + l.o.column(2) * (q + l.offset))
    } else {
        (sin_cos(q + l.offset), l.p)
    }
}

#[cfg(test)]
mod tests;
