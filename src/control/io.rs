//! What goes into a controller step and what comes out (ruckig's input /
//! output), and the [`Control`] trait a closed loop drives.

use crate::control::impedance::TargetImpedance;
use crate::error::Error;
use crate::trajectory::Setpoint;
use crate::types::Vector;

/// One sample from the sensors at t_k.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Measurement<const N: usize> {
    /// Joint position x (rad).
    pub x: Vector<N>,
    /// Joint velocity ẋ (rad/s): required by PD and state feedback, ignored by
    /// output feedback (which estimates it).
    pub dx: Option<Vector<N>>,
    /// Force the robot exerts on the environment τe (N m), from a force sensor.
    pub tau_e: Vector<N>,
}

/// The torque-level part of a Cartesian impedance, for the joint step of the
/// formulations "impedance" and "unified" (SPEC §19, (19.2)): everything the
/// joint law needs besides the compliant reference, none of it carrying the
/// measured wrench.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TaskTorque<const N: usize> {
    /// The commanded joint reference q_c, q̇_c, q̈_c (rad, rad/s, rad/s²): the
    /// inverse kinematics of the commanded pose alone (19.1).
    pub commanded: Setpoint<N>,
    /// The task Jacobian J(q) at the measured q (6 × N; the rotation rows zero
    /// for a position-only task).
    pub jacobian: nalgebra::SMatrix<f64, 6, N>,
    /// The spring K̃ e (N, N m) at the measured pose, e = [p_t − p; Log(R_t Rᵀ)]
    /// (clipped as (16.5)).
    pub spring: Vector<6>,
    /// The damping B (N s/m, N m s/rad) per task axis.
    pub damping: Vector<6>,
    /// The commanded twist [ṗ_c; ω_c] (m/s, rad/s).
    pub twist: Vector<6>,
    /// The damping Λ² of the least-squares inverse per task row, (C3)
    /// (m², 1): the joint law regularises its task projection with it.
    pub lambda2: Vector<6>,
    /// The admittance's share n ∈ [0, 1] of the torque (0: torque-level
    /// impedance, 1: the admittance law alone).
    pub share: f64,
}

impl<const N: usize> TaskTorque<N> {
    /// The task force F = K̃ e + B (ẋ_c − J q̇) at the joint velocity `dq`
    /// (rad/s): the wrench of τ_I that the torque-level impedance applies (N,
    /// N m), SPEC §19.
    pub fn force(&self, dq: &Vector<N>) -> Vector<6> {
        self.spring
            + self
                .damping
                .component_mul(&(self.twist - self.jacobian * dq))
    }

    /// Π of (19.3) for a joint law of stiffness `kp` (> 0 each): its
    /// feedback acts in the null space of this task.
    pub fn null_space(&self, kp: &Vector<N>) -> NullSpace<N> {
        let j = self.jacobian;
        let kinv = kp.map(|k| 1.0 / k);
        let kbar = kinv.sum() / N as f64;
        let jk = nalgebra::SMatrix::<f64, 6, N>::from_fn(|r, c| j[(r, c)] * kinv[c]);
        let a = jk * j.transpose()
            + nalgebra::SMatrix::<f64, 6, 6>::from_diagonal(&(kbar * self.lambda2));
        NullSpace {
            j,
            jk,
            ch: a.cholesky(),
        }
    }

    /// Π of (19.3) for a joint law of full stiffness Kp, given `kp_inv` =
    /// Kp⁻¹ (SPEC (18.12)): J Kp⁻¹ Jᵀ + k̄ Λ², k̄ = tr(Kp⁻¹)/N (the
    /// diagonal's mean of 1/Kp_i).
    pub fn null_space_of(&self, kp_inv: &crate::types::Matrix<N>) -> NullSpace<N> {
        let j = self.jacobian;
        let kbar = kp_inv.trace() / N as f64;
        let jk = j * kp_inv;
        let a = jk * j.transpose()
            + nalgebra::SMatrix::<f64, 6, 6>::from_diagonal(&(kbar * self.lambda2));
        NullSpace {
            j,
            jk,
            ch: a.cholesky(),
        }
    }
}

/// The projection Π of (19.3) onto the null space of a task Jacobian J,
/// weighted by a joint law's stiffness Kp (SPEC §19, §20):
/// Π τ = τ − Jᵀ (J Kp⁻¹ Jᵀ + k̄ Λ²)⁻¹ J Kp⁻¹ τ, k̄ = (1/N) Σ_i 1/Kp_i.
#[derive(Copy, Clone, Debug)]
pub struct NullSpace<const N: usize> {
    j: nalgebra::SMatrix<f64, 6, N>,
    jk: nalgebra::SMatrix<f64, 6, N>,
    ch: Option<nalgebra::Cholesky<f64, nalgebra::Const<6>>>,
}

impl<const N: usize> NullSpace<N> {
    /// Π τ (N m); zero if J Kp⁻¹ Jᵀ + k̄ Λ² is not positive definite (a
    /// non-finite input the caller's checks refuse first).
    #[inline]
    pub fn apply(&self, tau: &Vector<N>) -> Vector<N> {
        match &self.ch {
            Some(ch) => tau - self.j.transpose() * ch.solve(&(self.jk * tau)),
            None => Vector::zeros(),
        }
    }
}

/// What one step computed. `tau_sat` goes to the actuators; the rest is for logging.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Command<const N: usize> {
    /// Applied torque sat(τ) (N m).
    pub tau_sat: Vector<N>,
    /// Commanded torque τ before saturation (N m).
    pub tau: Vector<N>,
    /// Δτ = sat(τ) − τ (N m).
    pub dtau: Vector<N>,
    /// Tracking error z1 = xd − x (rad), (6).
    pub z1: Vector<N>,
    /// z2 = α1 − v (rad/s), (8); ẑ2 for output feedback.
    pub z2: Vector<N>,
    /// Commanded position xc(t_k) (rad).
    pub xc: Vector<N>,
    /// Compliant reference xd(t_k) (rad).
    pub xd: Vector<N>,
    /// Velocity the controller used (rad/s): measured, or the observer's estimate.
    pub v: Vector<N>,
    /// Auxiliary state ζ(t_k) (N m) used in this step.
    pub zeta: Vector<N>,
    /// Frobenius norms ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ before this step's update (zero for PD).
    pub w_norms: [f64; 3],
}

impl<const N: usize> Command<N> {
    /// All zeros (the "last command" before the first step).
    pub fn zeros() -> Self {
        let z = Vector::zeros();
        Self {
            tau_sat: z,
            tau: z,
            dtau: z,
            z1: z,
            z2: z,
            xc: z,
            xd: z,
            v: z,
            zeta: z,
            w_norms: [0.0; 3],
        }
    }
}

/// A torque (N m, per joint) the joint law adds to its own at the measured
/// position q (rad), before the rate limit and the saturation: the nominal
/// model's gravity G₀(q) fed forward, SPEC (20.10)
/// ([`Controller::with_feedforward`](crate::control::controller::Controller::with_feedforward);
/// a `Dynamics<N>` of the `cartesian` module is one). It must not allocate
/// and must be finite for a finite q.
pub trait Feedforward<const N: usize>: core::fmt::Debug + Send + Sync {
    /// The torque at the measured position `q` (rad).
    fn torque(&self, q: &Vector<N>) -> Vector<N>;
}

/// A controller as a closed loop sees it: a period, the target impedance it
/// realises, and a step from measurement and commanded setpoint to command.
///
/// Implemented by a `Controller` bound to a state
/// (`Controller::bind`) and by
/// `Tracker`; implement it to drive the simulator with a
/// controller of your own.
pub trait Control<const N: usize> {
    /// Sampling period Ts (s).
    fn period(&self) -> f64;
    /// The target impedance (3) the controller realises (for the impedance
    /// residual of SPEC §12).
    fn target(&self) -> &TargetImpedance<N>;
    /// One step at t_k: the measurement and the commanded setpoint (xc, ẋc, ẍc) in,
    /// the command out.
    fn step(&mut self, m: &Measurement<N>, c: &Setpoint<N>) -> Result<Command<N>, Error>;
    /// The step, and the torque to apply whatever happened: the command's,
    /// or a fallback on an error (zero unless the controller says otherwise).
    fn step_or_fallback(
        &mut self,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        match self.step(m, c) {
            Ok(cmd) => (cmd.tau_sat, Ok(cmd)),
            Err(e) => (Vector::zeros(), Err(e)),
        }
    }
    /// [`step_or_fallback`](Self::step_or_fallback) with the measured
    /// end-effector wrench F_e = [f; m] (N, N m, world frame; zeros where the
    /// plant measures none), which the closed loop passes at every step: a
    /// controller in task space (a Cartesian impedance) uses it; the default
    /// ignores it, as a joint-space controller does.
    fn step_with_wrench(
        &mut self,
        m: &Measurement<N>,
        wrench: &[f64; 6],
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        let _ = wrench;
        self.step_or_fallback(m, c)
    }
}

/// A controller of the closed loop that reads the measured wrench at every
/// step (a task-space law, or a controller written in another language that
/// is handed the whole measurement): implement its one step, and
/// [`Control`]'s steps follow from it, with a zero wrench where none is
/// measured.
pub trait WrenchControl<const N: usize> {
    /// Sampling period Ts (s).
    fn period(&self) -> f64;
    /// The target impedance (3) the controller realises (SPEC §12).
    fn target(&self) -> &TargetImpedance<N>;
    /// The step with the measured wrench F_e = [f; m] (N, N m, world frame),
    /// and the torque to apply whatever happened (its fallback on an error).
    fn step_with_wrench(
        &mut self,
        m: &Measurement<N>,
        wrench: &[f64; 6],
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>);
}

impl<const N: usize, T: WrenchControl<N>> Control<N> for T {
    fn period(&self) -> f64 {
        WrenchControl::period(self)
    }
    fn target(&self) -> &TargetImpedance<N> {
        WrenchControl::target(self)
    }
    fn step(&mut self, m: &Measurement<N>, c: &Setpoint<N>) -> Result<Command<N>, Error> {
        WrenchControl::step_with_wrench(self, m, &[0.0; 6], c).1
    }
    fn step_or_fallback(
        &mut self,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        WrenchControl::step_with_wrench(self, m, &[0.0; 6], c)
    }
    fn step_with_wrench(
        &mut self,
        m: &Measurement<N>,
        wrench: &[f64; 6],
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        WrenchControl::step_with_wrench(self, m, wrench, c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A law that pushes back along the measured force: τ = −f (the first
    /// N components of the wrench), refusing a NaN wrench.
    struct Pushback(TargetImpedance<2>);

    impl WrenchControl<2> for Pushback {
        fn period(&self) -> f64 {
            1e-3
        }
        fn target(&self) -> &TargetImpedance<2> {
            &self.0
        }
        fn step_with_wrench(
            &mut self,
            _m: &Measurement<2>,
            wrench: &[f64; 6],
            _c: &Setpoint<2>,
        ) -> (Vector<2>, Result<Command<2>, Error>) {
            if wrench.iter().any(|w| w.is_nan()) {
                let e = Error::NonFinite {
                    what: "wrench",
                    index: 0,
                };
                return (Vector::<2>::zeros(), Err(e));
            }
            let tau = Vector::<2>::new(-wrench[0], -wrench[1]);
            let cmd = Command {
                tau_sat: tau,
                tau,
                ..Command::zeros()
            };
            (tau, Ok(cmd))
        }
    }

    #[test]
    fn a_wrench_controller_is_a_control_that_reads_no_wrench_where_none_is_given() {
        let mut law = Pushback(TargetImpedance::paper());
        let m = Measurement {
            x: Vector::<2>::zeros(),
            dx: None,
            tau_e: Vector::<2>::zeros(),
        };
        let z = Vector::<2>::zeros();
        let c = Setpoint {
            x: z,
            dx: z,
            ddx: z,
        };
        let w = [3.0, -2.0, 0.0, 0.0, 0.0, 0.0];
        let (tau, cmd) = Control::step_with_wrench(&mut law, &m, &w, &c);
        assert_eq!(tau, Vector::<2>::new(-3.0, 2.0));
        assert_eq!(cmd.map(|c| c.tau), Ok(tau));
        assert_eq!(
            Control::step(&mut law, &m, &c).map(|c| c.tau),
            Ok(Vector::<2>::zeros())
        );
        assert_eq!(
            Control::step_or_fallback(&mut law, &m, &c).0,
            Vector::<2>::zeros()
        );
        assert_eq!(Control::period(&law), 1e-3);
        let nan = [f64::NAN; 6];
        let (tau, err) = Control::step_with_wrench(&mut law, &m, &nan, &c);
        assert_eq!(
            (tau, err.err()),
            (
                Vector::<2>::zeros(),
                Some(Error::NonFinite {
                    what: "wrench",
                    index: 0
                })
            )
        );
    }
}
