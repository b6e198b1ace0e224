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

/// Standard gravity (m/s²), along −z of the chain's base frame: the default
/// of [`Dynamics::new`]'s `gravity`.
pub const GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];

/// The velocity scale v_s of the dry-friction compensation (rad/s, or m/s
/// for a prismatic joint), SPEC (20.6): τ_F = F tanh(v_r / v_s).
pub const FRICTION_VELOCITY: f64 = 0.01;

/// The drive of each joint, SPEC (20.5), (20.6): what the rigid links do not
/// have. Every entry ≥ 0 and finite ([`Dynamics::with_drive`] checks).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Drive<const N: usize> {
    /// Armature I_a (kg m², kg for a prismatic joint): the rotor's inertia
    /// through the gear, added to the mass matrix's diagonal (MuJoCo's
    /// `dof_armature`, Pinocchio's `model.armature`).
    pub armature: Vector<N>,
    /// Viscous damping b (N m s/rad, N s/m): the torque b q̇ (MuJoCo's
    /// `dof_damping`, URDF's `<dynamics damping>`).
    pub damping: Vector<N>,
    /// Dry friction loss F (N m, N): the largest torque the friction
    /// exerts (MuJoCo's `frictionloss`, URDF's `<dynamics friction>`).
    pub friction: Vector<N>,
}

impl<const N: usize> Drive<N> {
    /// No armature, damping or friction: the rigid links alone.
    pub fn none() -> Self {
        Self {
            armature: Vector::zeros(),
            damping: Vector::zeros(),
            friction: Vector::zeros(),
        }
    }

    /// The dry-friction compensation τ_F = F ⊙ tanh(v / v_s) (N m, N), SPEC
    /// (20.6), on the motion the joint and its reference agree on: v_i =
    /// sign(v_r,i) min(|q̇_i|, |v_r,i|) where the measured `dq` and the
    /// reference velocity `v_r` (rad/s, m/s) have the same sign, else 0.
    pub fn friction_torque(&self, v_r: &Vector<N>, dq: &Vector<N>) -> Vector<N> {
        Vector::from_fn(|i, _| {
            let (f, r, m) = (self.friction[i], v_r[i], dq[i]);
            if f == 0.0 || r * m <= 0.0 || r.is_nan() || m.is_nan() {
                0.0
            } else {
                f * tanh(r.signum() * r.abs().min(m.abs()) / FRICTION_VELOCITY)
            }
        })
    }

    fn check(&self) -> Result<(), Error> {
        for (what, condition, v) in [
            ("armature", "armature ≥ 0", &self.armature),
            ("damping", "damping ≥ 0", &self.damping),
            ("friction", "friction ≥ 0", &self.friction),
        ] {
            check::nonnegative_vec(condition, what, v)?;
            check::at_most_each("|value| ≤ 1e9", what, v.as_slice(), PARAM_BOUND)?;
        }
        Ok(())
    }
}

/// How a simulated plant realises the drive within one period, SPEC
/// (20.9): the period is `substeps` integrator steps of `substep` h (s), the
/// viscous damping is integrated implicitly or not, and the dry friction is a
/// soft constraint (MuJoCo's friction loss) whose force, below its bound F,
/// is −(a + b_r q̇)/R. Computed torque then inverts the plant's own period,
/// joint by joint, in place of (20.6). Every entry finite; checked by
/// [`Dynamics::with_sampled_drive`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SampledDrive<const N: usize> {
    /// The plant's integrator step h (s), > 0.
    pub substep: f64,
    /// Integrator steps per period s (1 ≤ s ≤ 1000): the torque is held over
    /// s·h.
    pub substeps: u32,
    /// Whether the damping is integrated implicitly, (M + h b) q̈ = τ − b q̇ − …
    /// (MuJoCo's Euler, implicit and implicitfast integrators), or
    /// explicitly (RK4).
    pub implicit_damping: bool,
    /// Whether each integrator step updates the position with the new
    /// velocity, q ← q + h q̇_{j+1} (MuJoCo's Euler, implicit and
    /// implicitfast; not RK4): the velocity the plant reports is then the
    /// mean over its last step, the continuous velocity h/2 back (20.9').
    pub semi_implicit: bool,
    /// The friction constraint's regularisation R (rad/s² per N m, ≥ 0):
    /// (1 − d)/d · `dof_invweight0` with d = `solimp[0]` in MuJoCo.
    pub regularisation: Vector<N>,
    /// The friction constraint's reference damping b_r (1/s, ≥ 0): `2/(d_max
    /// · max(solref[0], 2 h))` in MuJoCo (`d_max = solimp[1]`).
    pub rate: Vector<N>,
}

impl<const N: usize> SampledDrive<N> {
    /// The joint velocity after one period from `v0` under the torque `u`
    /// held (N m; gravity, Coriolis and coupling already taken off): `s`
    /// steps of (20.9) for a joint of inertia `m`, damping `b`, friction loss
    /// `f` and constraint terms `r`, `br`.
    fn velocity_after(&self, u: f64, v0: f64, joint: JointTerms) -> f64 {
        let JointTerms { m, b, f, r, br } = joint;
        let h = self.substep;
        let implicit = if self.implicit_damping { h * b } else { 0.0 };
        let mut v = v0;
        for _ in 0..self.substeps {
            // The friction constraint's force at the acceleration the step
            // would have without it: −(a + b_r v)/R, a = (u − b v + force)/m,
            // bounded by F (MuJoCo's Huber cost: linear beyond R·F).
            let force = if f > 0.0 {
                let free = (u - b * v) / m;
                (-(free + br * v) / (r + 1.0 / m)).clamp(-f, f)
            } else {
                0.0
            };
            v += h * (u - b * v + force) / (m + implicit);
        }
        v
    }

    /// (20.9): the torque u (N m) that takes joint `joint` from `v0` to `v0 +
    /// a·s·h` over the period, by bisection on the plant's own period
    /// (monotone in u). `guess` starts the bracket (the continuous inverse
    /// m a + b v0); returned unchanged if no bracket is found (a value that
    /// is not finite).
    fn joint_torque(&self, joint: JointTerms, v0: f64, a: f64, guess: f64) -> f64 {
        let target = v0 + a * self.substep * f64::from(self.substeps);
        let below = |u: f64| self.velocity_after(u, v0, joint) < target;
        let width = 1.0 + 2.0 * joint.f + guess.abs();
        let (mut lo, mut hi) = (guess - width, guess + width);
        let mut grow = width;
        let mut tries = 0;
        while !below(lo) || below(hi) {
            tries += 1;
            if tries > 60 || !lo.is_finite() || !hi.is_finite() {
                return guess;
            }
            grow *= 2.0;
            if !below(lo) {
                lo -= grow;
            } else {
                hi += grow;
            }
        }
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break;
            }
            if below(mid) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    fn check(&self) -> Result<(), Error> {
        check::positive("substep > 0", "substep", self.substep)?;
        check::at_most("substep ≤ 1 s", "substep", self.substep, 1.0)?;
        if self.substeps == 0 || self.substeps > 1000 {
            return Err(Error::Condition {
                condition: "1 ≤ substeps ≤ 1000",
                lhs: "substeps",
                index: None,
                value: f64::from(self.substeps),
            });
        }
        for (what, condition, v) in [
            ("regularisation", "regularisation ≥ 0", &self.regularisation),
            ("rate", "rate ≥ 0", &self.rate),
        ] {
            check::nonnegative_vec(condition, what, v)?;
            check::at_most_each("|value| ≤ 1e9", what, v.as_slice(), PARAM_BOUND)?;
        }
        Ok(())
    }
}

/// A passive joint spring, SPEC (20.5'): the torque k ⊙ (q − q_s) the
/// joint needs against it (MuJoCo's `jnt_stiffness` about `qpos_spring`).
/// Every entry finite, k ≥ 0 ([`Dynamics::with_spring`] checks).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Spring<const N: usize> {
    /// Stiffness k (N m/rad, N/m), ≥ 0.
    pub stiffness: Vector<N>,
    /// The spring's rest position q_s (rad, m).
    pub reference: Vector<N>,
}

/// One joint's terms in (20.9): inertia m (the mass matrix's diagonal, with
/// the armature), damping b, friction loss F, the constraint's R and b_r.
#[derive(Copy, Clone, Debug)]
struct JointTerms {
    m: f64,
    b: f64,
    f: f64,
    r: f64,
    br: f64,
}

impl<const N: usize> Default for Drive<N> {
    fn default() -> Self {
        Self::none()
    }
}

/// The inertial of one link as a URDF or a MuJoCo model states it: the
/// mass, and the rotational inertia about the centre of mass in the frame
/// `origin` (the centre of mass and the inertia's axes in the link's frame).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Inertial {
    /// Mass m (kg), ≥ 0.
    pub mass: f64,
    /// The centre of mass (translation, m) and the axes of `inertia`
    /// (rotation) in the link's frame (URDF's `<inertial><origin>`).
    pub origin: Transform,
    /// Rotational inertia about the centre of mass in `origin`'s axes (kg
    /// m², row-major), symmetric and positive semi-definite
    /// ([`principal_moments`] ≥ 0).
    pub inertia: [[f64; 3]; 3],
}

/// What gravity compensation lifts of one link (MuJoCo's body `gravcomp`,
/// SPEC (20.1')): the mass l whose weight is lifted (kg; Σ gravcomp × mass,
/// negative where a negative share adds weight) and its first moment λ = Σ
/// gravcomp × mass × centre (kg m), in the link's frame. A first moment, not
/// a centre: shares of both signs can lift a couple with l = 0.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct Lifted {
    /// l (kg).
    pub mass: f64,
    /// λ (kg m), in the link's frame.
    pub moment: [f64; 3],
}

/// The principal moments of the inertia `i` (kg m², the symmetric part's
/// eigenvalues), smallest first. A rigid body's are ≥ 0 (and any two sum to
/// at least the third): a negative one makes the mass matrix indefinite.
pub fn principal_moments(i: &[[f64; 3]; 3]) -> [f64; 3] {
    let m = Matrix3::from_fn(|r, c| 0.5 * (i[r][c] + i[c][r]));
    let e = m.symmetric_eigenvalues();
    let mut v = [e[0], e[1], e[2]];
    v.sort_unstable_by(f64::total_cmp);
    v
}

/// The most negative smallest principal moment an inertia may have,
/// relative to its largest (rounding in a file that prints six digits of a
/// singular inertia: a rod, a thin plate).
pub const INERTIA_TOLERANCE: f64 = 1e-6;

/// A principal moment (kg m²) no arm's dynamics can tell from zero: an
/// exported file's rounding noise on a massless link (1e-35 in a file of
/// example-robot-data's iCub).
pub const INERTIA_FLOOR: f64 = 1e-12;

/// Whether the inertia `i` is one a rigid body has: positive semi-definite,
/// its smallest principal moment ≥ −([`INERTIA_TOLERANCE`] × its largest +
/// [`INERTIA_FLOOR`]). Returns the principal moments (smallest first) on
/// failure.
pub fn physical_inertia(i: &[[f64; 3]; 3]) -> Result<(), [f64; 3]> {
    let m = principal_moments(i);
    if m[0] >= -(INERTIA_TOLERANCE * m[2].abs() + INERTIA_FLOOR) {
        Ok(())
    } else {
        Err(m)
    }
}

impl Inertial {
    /// No mass (a link whose inertial is not given).
    pub const NONE: Self = Self {
        mass: 0.0,
        origin: Transform::IDENTITY,
        inertia: [[0.0; 3]; 3],
    };

    /// A point mass `mass` (kg) at `com` (m) of the link's frame.
    pub fn point(mass: f64, com: [f64; 3]) -> Self {
        Self {
            mass,
            origin: Transform {
                translation: com,
                ..Transform::IDENTITY
            },
            inertia: [[0.0; 3]; 3],
        }
    }

    /// Validated: finite, mass ≥ 0, the inertia symmetric (to 1e-9 of its
    /// largest entry) with a non-negative diagonal.
    fn check(&self, index: usize) -> Result<(Frame, Matrix3<f64>), Error> {
        let frame = self.origin.check(index)?;
        check::finite("link mass", self.mass)?;
        if self.mass < 0.0 {
            return Err(Error::Condition {
                condition: "mass ≥ 0",
                lhs: "link mass",
                index: Some(index),
                value: self.mass,
            });
        }
        // Bounded as every physical parameter (beyond, a model overflows in use).
        if self.mass > PARAM_BOUND {
            return Err(Error::Condition {
                condition: "|value| ≤ 1e9",
                lhs: "link mass",
                index: Some(index),
                value: self.mass,
            });
        }
        let i = Matrix3::from_fn(|r, c| self.inertia[r][c]);
        check::finite_slice("link inertia", i.as_slice())?;
        if i.amax() > PARAM_BOUND {
            return Err(Error::Condition {
                condition: "|value| ≤ 1e9",
                lhs: "link inertia",
                index: Some(index),
                value: i.amax(),
            });
        }
        let scale = i.amax();
        let asym = (i - i.transpose()).amax();
        if asym > 1e-9 * scale {
            return Err(Error::Condition {
                condition: "the inertia is symmetric (|I − Iᵀ| ≤ 1e-9 |I|)",
                lhs: "link inertia asymmetry",
                index: Some(index),
                value: asym,
            });
        }
        if let Err(m) = physical_inertia(&self.inertia) {
            return Err(Error::Condition {
                condition: "the inertia is positive semi-definite (its principal moments ≥ 0)",
                lhs: "link inertia's smallest principal moment",
                index: Some(index),
                value: m[0],
            });
        }
        Ok((frame, i))
    }
}

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
mod tests {
    use super::*;
    use crate::cartesian::chain::Transform;

    /// The chain tests' joints (every kind of element; the fixed elbow
    /// carries a second inertial), inertials with rotated axes.
    fn arm() -> Dynamics<3> {
        let joints = crate::cartesian::chain::sample_joints();
        let inertial = |m: f64, xyz: [f64; 3], rpy: [f64; 3], d: [f64; 3]| Inertial {
            mass: m,
            origin: Transform::from_xyz_rpy(xyz, rpy),
            inertia: [[d[0], 0.01, 0.0], [0.01, d[1], 0.002], [0.0, 0.002, d[2]]],
        };
        let inertials = [
            inertial(5.0, [0.0; 3], [0.0; 3], [1.0; 3]),
            inertial(2.0, [0.1, 0.02, 0.05], [0.3, 0.1, -0.2], [0.05, 0.04, 0.03]),
            inertial(
                1.5,
                [0.15, 0.0, -0.01],
                [0.0, 0.2, 0.0],
                [0.02, 0.03, 0.025],
            ),
            inertial(
                0.7,
                [0.05, 0.01, 0.0],
                [0.1, 0.0, 0.4],
                [0.01, 0.012, 0.011],
            ),
            inertial(0.9, [0.0, 0.1, 0.03], [-0.2, 0.3, 0.1], [0.015, 0.01, 0.02]),
        ];
        Dynamics::new(&joints, &inertials, [0.3, -0.2, -9.81]).unwrap()
    }

    fn state() -> (Vector<3>, Vector<3>, Vector<3>) {
        (
            Vector::<3>::new(0.4, 0.12, -0.7),
            Vector::<3>::new(0.9, -0.3, 1.4),
            Vector::<3>::new(-1.1, 0.6, 2.0),
        )
    }

    #[test]
    fn the_mass_matrix_is_symmetric_positive_definite() {
        let d = arm();
        let (q, _, _) = state();
        let m = d.mass_matrix(&q);
        let mut raw = Matrix::<3>::zeros();
        for j in 0..3 {
            let mut e = Vector::<3>::zeros();
            e[j] = 1.0;
            raw.set_column(j, &d.mass_times(&q, &e));
        }
        assert!((raw - raw.transpose()).amax() < 1e-12, "{raw}");
        assert!(m.cholesky().is_some(), "{m}");
        // Affine in q̈ with the mass matrix as its slope.
        let (q, dq, ddq) = state();
        let lhs = d.inverse_dynamics(&q, &dq, &ddq) - d.inverse_dynamics(&q, &dq, &Vector::zeros());
        assert!((lhs - m * ddq).amax() < 1e-12, "{lhs} vs {}", m * ddq);
    }

    /// The potential energy −Σ m_i gᵀ p_ci from the bodies' centres of mass.
    fn potential(d: &Dynamics<3>, q: &Vector<3>) -> f64 {
        let mut v = 0.0;
        d.chain
            .walk(q, &Vector::zeros(), None, Vector3::zeros(), |i, m| {
                let b = &d.bodies[i];
                v -= d.gravity.dot(&(b.m * m.c + m.r * b.h));
            });
        v
    }

    #[test]
    fn gravity_compensation_lifts_its_share_of_each_weight() {
        // Every link's whole weight lifted (MuJoCo's gravcomp = 1): no
        // gravity torque, the rest of inverse dynamics unchanged; half of it:
        // half the gravity torque.
        let joints = crate::cartesian::chain::sample_joints();
        let d = arm();
        let (q, dq, ddq) = state();
        let inertials = [
            (5.0, [0.0; 3]),
            (2.0, [0.1, 0.02, 0.05]),
            (1.5, [0.15, 0.0, -0.01]),
            (0.7, [0.05, 0.01, 0.0]),
            (0.9, [0.0, 0.1, 0.03]),
        ];
        let lift = |share: f64| {
            inertials.map(|(m, c)| Lifted {
                mass: share * m,
                moment: c.map(|x| share * m * x),
            })
        };
        let whole = d.with_gravity_compensation(&joints, &lift(1.0)).unwrap();
        assert!(whole.gravity_torque(&q).amax() < 1e-12);
        let free = d.inverse_dynamics(&q, &dq, &ddq) - d.gravity_torque(&q);
        assert!((whole.inverse_dynamics(&q, &dq, &ddq) - free).amax() < 1e-12);
        let half = d.with_gravity_compensation(&joints, &lift(0.5)).unwrap();
        assert!((half.gravity_torque(&q) - 0.5 * d.gravity_torque(&q)).amax() < 1e-12);
        // Scaled with the masses; refused on other joints.
        let scaled = half.scaled(2.0).unwrap();
        assert!((scaled.gravity_torque(&q) - d.gravity_torque(&q)).amax() < 1e-12);
        assert!(d
            .with_gravity_compensation(&joints[1..], &lift(1.0)[1..])
            .is_err());
    }

    #[test]
    fn gravity_is_the_gradient_of_the_potential_energy() {
        let d = arm();
        let (q, _, _) = state();
        let g = d.gravity_torque(&q);
        let h = 1e-6;
        for i in 0..3 {
            let mut e = Vector::<3>::zeros();
            e[i] = h;
            let num = (potential(&d, &(q + e)) - potential(&d, &(q - e))) / (2.0 * h);
            assert!((num - g[i]).abs() < 1e-7, "joint {i}: {num} vs {}", g[i]);
        }
    }

    #[test]
    fn the_power_of_the_torque_is_the_rate_of_the_kinetic_energy() {
        // q̇ᵀ(τ − G) = d/dt (½ q̇ᵀ M q̇) along q(t) = q0 + t q̇0 + t²/2 q̈0.
        let d = arm();
        let (q0, dq0, ddq) = state();
        let at = |t: f64| (q0 + t * dq0 + 0.5 * t * t * ddq, dq0 + t * ddq);
        let kinetic = |t: f64| {
            let (q, dq) = at(t);
            0.5 * dq.dot(&(d.mass_matrix(&q) * dq))
        };
        let h = 1e-5;
        let rate = (kinetic(h) - kinetic(-h)) / (2.0 * h);
        let power = dq0.dot(&(d.inverse_dynamics(&q0, &dq0, &ddq) - d.gravity_torque(&q0)));
        assert!((rate - power).abs() < 1e-7, "{rate} vs {power}");
    }

    #[test]
    fn scale_and_payload_change_the_model_as_stated() {
        let d = arm();
        let (q, dq, ddq) = state();
        let tau = d.inverse_dynamics(&q, &dq, &ddq);
        let scaled = d.scaled(1.3).unwrap().inverse_dynamics(&q, &dq, &ddq);
        assert!((scaled - 1.3 * tau).amax() < 1e-12);
        // A payload at the last origin weighs on every joint by its gravity.
        let loaded = d.with_payload(2.0).unwrap();
        assert!((loaded.mass() - d.mass() - 2.0).abs() < 1e-15);
        assert!(d.scaled(0.0).is_err() && d.with_payload(-1.0).is_err());
    }

    #[test]
    fn a_model_that_would_overflow_in_use_is_refused_by_name() {
        let d = arm();
        let e = d.scaled(1e300).unwrap_err();
        assert_eq!(
            e.to_string(),
            "condition |value| ≤ 1e9 is violated: mass_scale = 1e300 (SPEC §10)"
        );
        let e = d.with_payload(1e300).unwrap_err();
        assert_eq!(
            e.to_string(),
            "condition |value| ≤ 1e9 is violated: payload = 1e300 (SPEC §10)"
        );
        assert!(
            d.scaled(1e9).is_err(),
            "each link's mass then beyond 1e9 kg"
        );
        let (q, dq, ddq) = state();
        assert_eq!(
            d.inverse_dynamics_checked(&q, &dq, &ddq),
            Ok(d.inverse_dynamics(&q, &dq, &ddq))
        );
        let mut huge = dq;
        huge[0] = 1e200; // the torque was NaN
        let e = d.inverse_dynamics_checked(&q, &huge, &ddq).unwrap_err();
        assert_eq!(
            e.to_string(),
            "dq[0] = 1e200 is beyond its limit ±1e6; the state was left unchanged"
        );
        assert!(d.mass_matrix_checked(&(q * 1e300)).is_err());
    }

    fn sampled(regularisation: f64, rate: f64) -> SampledDrive<3> {
        SampledDrive {
            substep: 2.5e-4,
            substeps: 4,
            implicit_damping: true,
            semi_implicit: true,
            regularisation: Vector::from_element(regularisation),
            rate: Vector::from_element(rate),
        }
    }

    #[test]
    fn the_plants_period_is_inverted_as_stated() {
        // (20.9) with damping only, implicit steps: the closed form
        // u = b v0 + b a s h / (1 − ρ^s), ρ = m / (m + h b), beside ID's m a + b v0.
        let (q, dq, a) = state();
        let drive = Drive {
            armature: Vector::<3>::new(0.1, 0.0, 0.0),
            damping: Vector::<3>::new(1.5, 0.0, 40.0),
            friction: Vector::zeros(),
        };
        let d = arm().with_drive(drive).unwrap();
        let s = sampled(0.0, 0.0);
        let p = d.with_sampled_drive(s).unwrap();
        let tau = p.drive_torque(&q, &dq, &a, &dq);
        let m = p.mass_matrix(&q);
        for i in [0, 2] {
            let (mi, b) = (m[(i, i)], drive.damping[i]);
            let rho = mi / (mi + s.substep * b);
            let u = b * dq[i] + b * a[i] * 1e-3 / (1.0 - libm::pow(rho, 4.0));
            let want = u - (mi * a[i] + b * dq[i]);
            assert!(
                (tau[i] - want).abs() < 1e-9 * (1.0 + u.abs()),
                "{i}: {tau} vs {want}"
            );
        }
        assert_eq!(tau[1], 0.0, "no damping, no friction: ID's torque exactly");
        // First order in h b/m: the damping of the period's mean velocity.
        let first = drive.damping[0] * (1e-3 + s.substep) / 2.0 * a[0];
        assert!(
            (tau[0] - first).abs() < 0.05 * first.abs(),
            "{} vs {first}",
            tau[0]
        );
        // Friction only, far beyond its bound (|q̇| ≫ F R / b_r): (20.6)'s F sign(q̇).
        let drive = Drive {
            armature: Vector::zeros(),
            damping: Vector::zeros(),
            friction: Vector::<3>::new(2.0, 1.0, 0.5),
        };
        let f = arm()
            .with_drive(drive)
            .unwrap()
            .with_sampled_drive(sampled(1e-6, 100.0))
            .unwrap();
        let v = Vector::<3>::new(1.0, -0.5, 2.0);
        let tau = f.drive_torque(&q, &v, &a, &v);
        let want = Vector::<3>::new(2.0, -1.0, 0.5);
        assert!((tau - want).amax() < 1e-9, "{tau} vs {want}");
        // Below the bound it is MuJoCo's regularised force: at rest, asked
        // for no acceleration, nothing; a light joint's friction with a
        // large R is a small damping b_r/R q̇, not F.
        let rest = Vector::<3>::zeros();
        assert!(f.drive_torque(&q, &rest, &rest, &rest).amax() < 1e-12);
        let soft = arm()
            .with_drive(drive)
            .unwrap()
            .with_sampled_drive(sampled(1e4, 100.0))
            .unwrap()
            .drive_torque(&q, &v, &rest, &v);
        let damping = v * (100.0 / 1e4);
        assert!(
            (soft - damping).amax() < 0.1 * damping.amax(),
            "{soft} vs {damping}"
        );
        // Without a SampledDrive: (20.6) as before.
        let plain = arm().with_drive(drive).unwrap();
        assert_eq!(
            plain.drive_torque(&q, &v, &a, &v),
            drive.friction_torque(&v, &v)
        );
    }

    #[test]
    fn a_semi_implicit_plants_velocity_is_half_a_step_old() {
        // (20.9'): h/2 for semi-implicit steps; 0 for RK4 or no SampledDrive.
        let d = arm();
        assert_eq!(d.velocity_lag(), 0.0);
        let s = sampled(1.0, 1.0);
        assert_eq!(d.with_sampled_drive(s).unwrap().velocity_lag(), 1.25e-4);
        let rk4 = SampledDrive {
            semi_implicit: false,
            ..s
        };
        assert_eq!(d.with_sampled_drive(rk4).unwrap().velocity_lag(), 0.0);
    }

    #[test]
    fn springs_and_sampled_drives_are_checked() {
        let d = arm();
        let (q, dq, ddq) = state();
        let spring = Spring {
            stiffness: Vector::<3>::new(10.0, 0.0, 2.0),
            reference: Vector::<3>::new(0.1, 0.2, -0.3),
        };
        let k = d.with_spring(spring).unwrap();
        let tau = k.inverse_dynamics(&q, &dq, &ddq) - d.inverse_dynamics(&q, &dq, &ddq);
        let want = spring.stiffness.component_mul(&(q - spring.reference));
        assert!((tau - want).amax() < 1e-13, "{tau} vs {want}");
        let mut bad = spring;
        bad.stiffness[1] = -1.0;
        let e = d.with_spring(bad).unwrap_err().to_string();
        assert!(e.contains("stiffness") && e.contains("[1]"), "{e}");
        bad = spring;
        bad.reference[2] = f64::NAN;
        assert!(d.with_spring(bad).is_err());
        for (what, s) in [
            (
                "substep",
                SampledDrive {
                    substep: 0.0,
                    ..sampled(1.0, 1.0)
                },
            ),
            (
                "substeps",
                SampledDrive {
                    substeps: 0,
                    ..sampled(1.0, 1.0)
                },
            ),
            (
                "substeps",
                SampledDrive {
                    substeps: 1001,
                    ..sampled(1.0, 1.0)
                },
            ),
            ("regularisation", sampled(-1.0, 1.0)),
            ("rate", sampled(1.0, f64::NAN)),
        ] {
            let e = d.with_sampled_drive(s).unwrap_err().to_string();
            assert!(e.contains(what), "{what}: {e}");
        }
    }

    #[test]
    fn the_drive_adds_armature_and_damping_as_stated() {
        // (20.5): M_a = M + diag(I_a), ID = RNEA + I_a ⊙ q̈ + b ⊙ q̇, G unchanged.
        let d = arm();
        let drive = Drive {
            armature: Vector::<3>::new(0.1, 0.25, 0.04),
            damping: Vector::<3>::new(1.5, 0.0, 0.3),
            friction: Vector::<3>::new(2.0, 1.0, 0.0),
        };
        let a = d.with_drive(drive).unwrap();
        let (q, dq, ddq) = state();
        let m = a.mass_matrix(&q) - d.mass_matrix(&q);
        assert!(
            (m - Matrix::<3>::from_diagonal(&drive.armature)).amax() < 1e-14,
            "{m}"
        );
        let tau = a.inverse_dynamics(&q, &dq, &ddq) - d.inverse_dynamics(&q, &dq, &ddq);
        let want = drive.armature.component_mul(&ddq) + drive.damping.component_mul(&dq);
        assert!((tau - want).amax() < 1e-13, "{tau} vs {want}");
        assert_eq!(a.gravity_torque(&q), d.gravity_torque(&q));
        let mv = a.mass_times(&q, &ddq) - a.mass_matrix(&q) * ddq;
        assert!(mv.amax() < 1e-12, "{mv}");
        // (20.6): the full friction beyond a few v_s when the joint moves
        // with its reference, none at rest or against it, odd.
        let drive = a.drive();
        let v = Vector::<3>::new(1.0, -1.0, 1.0);
        let f = drive.friction_torque(&v, &v);
        assert!((f - Vector::<3>::new(2.0, -1.0, 0.0)).amax() < 1e-12, "{f}");
        let zero = Vector::<3>::zeros();
        assert_eq!(drive.friction_torque(&zero, &v), zero);
        assert_eq!(drive.friction_torque(&v, &zero), zero);
        assert_eq!(drive.friction_torque(&v, &-v), zero);
        // The slower of the two: a joint starting to follow its reference.
        let slow = drive.friction_torque(&v, &Vector::from_element(FRICTION_VELOCITY));
        assert!((slow[0] - 2.0 * libm::tanh(1.0)).abs() < 1e-15, "{slow}");
        assert!(slow[1] == 0.0, "{slow}");
        // The default is no drive, bit for bit the rigid model.
        assert_eq!(d.with_drive(Drive::none()).unwrap(), d);
    }

    #[test]
    fn a_bad_drive_is_refused_by_term_and_joint() {
        let d = arm();
        let bad = |f: fn(&mut Drive<3>)| {
            let mut drive = Drive::none();
            f(&mut drive);
            d.with_drive(drive).unwrap_err().to_string()
        };
        let e = bad(|d| d.armature[1] = -0.1);
        assert!(
            e.contains("armature ≥ 0 is violated: armature[1] = -0.1"),
            "{e}"
        );
        let e = bad(|d| d.damping[2] = -1.0);
        assert!(e.contains("damping ≥ 0") && e.contains("damping[2]"), "{e}");
        let e = bad(|d| d.friction[0] = f64::NAN);
        assert!(e.contains("friction") && e.contains("[0]"), "{e}");
        let e = bad(|d| d.armature[0] = f64::INFINITY);
        assert!(e.contains("armature"), "{e}");
    }

    #[test]
    fn bad_inertials_are_refused_by_name() {
        let joints = [Joint::revolute(Transform::IDENTITY, [0.0, 0.0, 1.0])];
        let e =
            Dynamics::<1>::new(&joints, &[Inertial::point(-1.0, [0.0; 3])], GRAVITY).unwrap_err();
        assert!(
            e.to_string()
                .contains("mass ≥ 0 is violated: link mass[0] = -1"),
            "{e}"
        );
        let mut skew = Inertial::point(1.0, [0.0; 3]);
        skew.inertia = [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        let e = Dynamics::<1>::new(&joints, &[skew], GRAVITY).unwrap_err();
        assert!(e.to_string().contains("symmetric"), "{e}");
        let e = Dynamics::<1>::new(&joints, &[], GRAVITY).unwrap_err();
        assert!(e.to_string().contains("one inertial per joint"), "{e}");
        let e = Dynamics::<1>::new(&joints, &[Inertial::NONE], [0.0, f64::NAN, 0.0]).unwrap_err();
        assert!(e.to_string().contains("gravity"), "{e}");
    }
}
