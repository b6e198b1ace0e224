//! Forward kinematics and the Jacobian of the end-effector position,
//! SPEC §16: what a Cartesian impedance needs of an arm.
//!
//! [`Kinematics`] is the trait; the simulator's planar arms
//! (`PlanarArm`, `TwoLinkArm`, in `sim::model`) implement it in their plane: x–y, z = 0, link i's absolute angle θ_i = q_1 + … + q_i
//! measured from the x axis (the horizontal; gravity acts along −y):
//!
//! ```text
//! p(q)  = Σ_a l_a (cos θ_a, sin θ_a, 0)
//! J_i   = ∂p/∂q_i = Σ_{a ≥ i} l_a (−sin θ_a, cos θ_a, 0)
//! J̇ q̇  = −Σ_a l_a θ̇_a² (cos θ_a, sin θ_a, 0),   θ̇_a = q̇_1 + … + q̇_a
//! ```

use crate::types::{Jacobian, Vector};

/// The position kinematics of an `N`-joint arm's end effector.
///
/// Units: q in rad, q̇ in rad/s, p in m, J in m/rad, J̇ q̇ in m/s².
pub trait Kinematics<const N: usize> {
    /// End-effector position p = fk(q) (m).
    fn fk(&self, q: &Vector<N>) -> Vector<3>;
    /// Jacobian J(q) = ∂p/∂q (3 × N, m/rad): ṗ = J q̇.
    fn jacobian(&self, q: &Vector<N>) -> Jacobian<N>;
    /// The velocity product J̇(q, q̇) q̇ (m/s²): p̈ = J q̈ + J̇ q̇.
    ///
    /// The default differentiates J along q̇ by a central difference with a
    /// step of 1e-6 rad along q̇/‖q̇‖ (relative error ≈ 1e-10 for smooth
    /// kinematics); implementations with a closed form override it.
    fn jacobian_dot_qdot(&self, q: &Vector<N>, dq: &Vector<N>) -> Vector<3> {
        let speed = dq.norm();
        if speed == 0.0 || !speed.is_finite() {
            return Vector::zeros();
        }
        let h = 1e-6 / speed;
        let dj = (self.jacobian(&(q + h * dq)) - self.jacobian(&(q - h * dq))) / (2.0 * h);
        dj * dq
    }
}
