//! What a closed loop records at every t_k: a [`Row`], handed to a
//! [`Recorder`] (rows in memory, metrics, or both).

use crate::types::Vector;

/// One recorded row at t_k (units as in `Command`).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Row<const N: usize> {
    /// t_k (s).
    pub t: f64,
    /// Plant position x_k (rad).
    pub x: Vector<N>,
    /// Plant velocity ẋ_k (rad/s).
    pub dx: Vector<N>,
    /// Plant acceleration ẍ_k (rad/s²) at the row's state with the applied torque.
    pub ddx: Vector<N>,
    /// Commanded position xc (rad).
    pub xc: Vector<N>,
    /// Commanded velocity ẋc (rad/s).
    pub dxc: Vector<N>,
    /// Commanded acceleration ẍc (rad/s²).
    pub ddxc: Vector<N>,
    /// Compliant reference xd (rad).
    pub xd: Vector<N>,
    /// Velocity the controller used (rad/s): the observer's estimate for output feedback.
    pub dx_hat: Vector<N>,
    /// Commanded torque τ (N m).
    pub tau: Vector<N>,
    /// Applied torque sat(τ) (N m).
    pub tau_sat: Vector<N>,
    /// Δτ (N m).
    pub dtau: Vector<N>,
    /// Contact force τe (N m).
    pub tau_e: Vector<N>,
    /// Auxiliary state ζ (N m).
    pub zeta: Vector<N>,
    /// Tracking error z1 = xd − x (rad).
    pub z1: Vector<N>,
    /// ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F before the step's update.
    pub w_norms: [f64; 3],
    /// End-effector position (m), world frame, at x_k ([`Plant::end_effector`](crate::sim::plant::Plant::end_effector); zeros for the joint-space plants).
    pub x_ee: [f64; 3],
    /// End-effector wrench F_e = [f; m] (N, N m), world frame, measured at
    /// x_k ([`Plant::wrench`](crate::sim::plant::Plant::wrench); zeros for the joint-space plants).
    pub wrench: [f64; 6],
    /// True if no command was computed at this row (the step was refused or
    /// skipped): `tau_sat` is then the fallback or held torque, the other
    /// controller fields those of the last computed command.
    pub refused: bool,
}

/// Receives every row of a simulation. `()` discards them; a pair records
/// into both.
pub trait Recorder<const N: usize> {
    /// Called once per row, in order.
    fn record(&mut self, row: &Row<N>);
}

impl<const N: usize> Recorder<N> for () {
    fn record(&mut self, _row: &Row<N>) {}
}

impl<const N: usize, A: Recorder<N> + ?Sized, B: Recorder<N> + ?Sized> Recorder<N>
    for (&mut A, &mut B)
{
    fn record(&mut self, row: &Row<N>) {
        self.0.record(row);
        self.1.record(row);
    }
}

/// Every row of a run, in memory (feature `alloc`).
#[cfg(feature = "alloc")]
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace<const N: usize> {
    /// The rows, k = 0 … K − 1.
    pub rows: alloc::vec::Vec<Row<N>>,
}

#[cfg(feature = "alloc")]
impl<const N: usize> Recorder<N> for Trace<N> {
    fn record(&mut self, row: &Row<N>) {
        self.rows.push(*row);
    }
}
