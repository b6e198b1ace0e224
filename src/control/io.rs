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
