//! The joints' drive, SPEC (20.5), (20.6), (20.9): what the rigid links do
//! not have ([`Drive`]), how a simulated plant realises it within a period
//! ([`SampledDrive`]), and a passive spring ([`Spring`]).

use super::*;

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

    pub(super) fn check(&self) -> Result<(), Error> {
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
    pub(super) fn velocity_after(&self, u: f64, v0: f64, joint: JointTerms) -> f64 {
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
    pub(super) fn joint_torque(&self, joint: JointTerms, v0: f64, a: f64, guess: f64) -> f64 {
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

    pub(super) fn check(&self) -> Result<(), Error> {
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
pub(super) struct JointTerms {
    pub(super) m: f64,
    pub(super) b: f64,
    pub(super) f: f64,
    pub(super) r: f64,
    pub(super) br: f64,
}

impl<const N: usize> Default for Drive<N> {
    fn default() -> Self {
        Self::none()
    }
}
