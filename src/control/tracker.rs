//! The convenience of one controller that tracks its own trajectory: a
//! [`Controller`], a [`Trajectory`] and a heap [`State`](crate::control::state::State) in one value, with
//! the clock t_k = k·Ts (feature `alloc`).

use crate::control::controller::Controller;
use crate::control::impedance::TargetImpedance;
use crate::control::io::{Command, Control, Measurement, TaskTorque};
use crate::control::state::HeapState;
use crate::error::Error;
use crate::networks::rbf::{Basis, Grid};
use crate::trajectory::{Setpoint, Sinusoid, Trajectory};

/// A controller with its trajectory and its state: `step(&measurement)` samples
/// the trajectory at t_k = k·Ts and takes the step.
#[derive(Clone, Debug)]
pub struct Tracker<const N: usize, B = Grid<N>, T = Sinusoid<N>> {
    ctrl: Controller<N, B>,
    traj: T,
    state: HeapState<N>,
}

impl<const N: usize, B: Basis<N>, T: Trajectory<N>> Tracker<N, B, T> {
    /// `ctrl` tracking `traj`, from t = 0 (a new heap state).
    pub fn new(ctrl: Controller<N, B>, traj: T) -> Self {
        let state = ctrl.new_state();
        Self { ctrl, traj, state }
    }

    /// One step at t_k = k·Ts with the trajectory sampled there (SPEC §11).
    #[inline]
    pub fn step(&mut self, m: &Measurement<N>) -> Result<Command<N>, Error> {
        let c = self.traj.sample(self.time());
        self.ctrl.step(&mut self.state, m, &c)
    }

    /// One step with an external setpoint `c` instead of the trajectory's
    /// (the clock still advances).
    #[inline]
    pub fn step_with(&mut self, m: &Measurement<N>, c: &Setpoint<N>) -> Result<Command<N>, Error> {
        self.ctrl.step(&mut self.state, m, c)
    }

    /// One step of the torque-level formulations of a Cartesian impedance
    /// with the compliant reference `c` and the torque-level part `task`
    /// ([`Controller::step_task`], SPEC §19; the clock still advances).
    #[inline]
    pub fn step_task(
        &mut self,
        m: &Measurement<N>,
        c: &Setpoint<N>,
        task: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        self.ctrl.step_task(&mut self.state, m, c, task)
    }

    /// [`step`](Self::step), and the torque to apply whatever happened (the
    /// step's, or the configured fallback): see [`Controller::step_or_fallback`].
    pub fn step_or_fallback(
        &mut self,
        m: &Measurement<N>,
    ) -> (crate::types::Vector<N>, Result<Command<N>, Error>) {
        let c = self.traj.sample(self.time());
        self.ctrl.step_or_fallback(&mut self.state, m, &c)
    }

    /// A step call refused before it reached the controller (see
    /// [`Controller::refuse`]): recorded as a refused step, the fallback returned.
    pub fn refuse(&mut self, error: Error) -> crate::types::Vector<N> {
        self.ctrl.refuse(&mut self.state, error)
    }

    /// Back to t = 0 (weights, ζ, observer and reference as at construction).
    pub fn reset(&mut self) {
        self.state.reset();
    }

    /// Restore a snapshot, checked against the controller
    /// ([`Controller::restore`]); on an error nothing changes.
    pub fn restore(&mut self, data: &[f64]) -> Result<(), Error> {
        self.ctrl.restore(&mut self.state, data)
    }

    /// Take over from a controller that was applying `tau` (N m), checked
    /// ([`Controller::take_over`]); on an error nothing changes.
    pub fn take_over(&mut self, tau: &crate::types::Vector<N>) -> Result<(), Error> {
        self.ctrl.take_over(&mut self.state, tau)
    }

    /// Replace the weights, checked against the controller
    /// ([`Controller::load_weights`]); on an error nothing changes.
    pub fn load_weights(
        &mut self,
        w: &crate::networks::network::Weights<'_, N>,
    ) -> Result<(), Error> {
        self.ctrl.load_weights(&mut self.state, w)
    }

    /// Time t_k = k·Ts (s) of the next step.
    pub fn time(&self) -> f64 {
        self.ctrl.time(&self.state)
    }
    /// The controller (description).
    pub fn controller(&self) -> &Controller<N, B> {
        &self.ctrl
    }
    /// The commanded trajectory.
    pub fn trajectory(&self) -> &T {
        &self.traj
    }
    /// The state.
    pub fn state(&self) -> &HeapState<N> {
        &self.state
    }
    /// The state, writable (e.g. to load weights).
    pub fn state_mut(&mut self) -> &mut HeapState<N> {
        &mut self.state
    }
}

/// The tracker as a closed loop's [`Control`]: the loop supplies the setpoint
/// (normally from the same trajectory).
impl<const N: usize, B: Basis<N>, T: Trajectory<N>> Control<N> for Tracker<N, B, T> {
    fn period(&self) -> f64 {
        self.ctrl.period()
    }
    fn target(&self) -> &TargetImpedance<N> {
        self.ctrl.impedance()
    }
    fn step(&mut self, m: &Measurement<N>, c: &Setpoint<N>) -> Result<Command<N>, Error> {
        self.step_with(m, c)
    }
    fn step_or_fallback(
        &mut self,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> (crate::types::Vector<N>, Result<Command<N>, Error>) {
        self.ctrl.step_or_fallback(&mut self.state, m, c)
    }
}
