//! The kinematics of an arm's tip, SPEC §16 (16.0): what a Cartesian
//! impedance needs of an arm, for position and orientation.
//!
//! [`Kinematics`] is the trait. One call, [`Kinematics::tip`], gives at
//! (q, q̇), in one pass over the arm:
//!
//! - the pose of the tip: its position p ∈ R³ (m) and rotation R ∈ SO(3)
//!   (world ← tip), world frame;
//! - the 6 × N geometric Jacobian `J = [J_v; J_ω]`, world-aligned, at the tip
//!   origin: ṗ = J_v q̇ (m/s), ω = J_ω q̇ (rad/s);
//! - the velocity product `J̇ q̇ = [(J̇ q̇)_v; (J̇ q̇)_ω]`, the classical
//!   acceleration of the tip at q̈ = 0: p̈ = J_v q̈ + (J̇ q̇)_v (m/s²),
//!   ω̇ = J_ω q̈ + (J̇ q̇)_ω (rad/s²) (Pinocchio's
//!   `getFrameClassicalAcceleration(…, LOCAL_WORLD_ALIGNED)` with q̈ = 0).
//!
//! Implementations: [`Chain`](crate::cartesian::chain::Chain) (any serial
//! chain of up to 7 revolute or prismatic joints, from a URDF or a MuJoCo
//! model), and the simulator's planar arms (`PlanarArm`, `TwoLinkArm`, in
//! `sim::model`), in their plane: x–y, z = 0, link i's absolute angle
//! θ_i = q_1 + … + q_i measured from the x axis, the tip rotated about z by θ_N:
//!
//! ```text
//! p(q)  = Σ_a l_a (cos θ_a, sin θ_a, 0),   R(q) = Rot_z(θ_N)
//! J_i   = [Σ_{a ≥ i} l_a (−sin θ_a, cos θ_a, 0); (0, 0, 1)]
//! J̇ q̇  = [−Σ_a l_a θ̇_a² (cos θ_a, sin θ_a, 0); 0],   θ̇_a = q̇_1 + … + q̇_a
//! ```

use crate::types::{Jacobian, Vector};
use nalgebra::{Rotation3, SMatrix};

/// The `6 × N` geometric Jacobian `[J_v; J_ω]` of a tip (m/rad over rad/rad
/// for revolute joints, 1 over 0 for prismatic ones).
pub type Jacobian6<const N: usize> = SMatrix<f64, 6, N>;

/// The tip's pose, Jacobian and velocity product at one (q, q̇): see the
/// [module docs](self). World frame throughout.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Tip<const N: usize> {
    /// Position p (m).
    pub position: Vector<3>,
    /// Rotation R (world ← tip).
    pub rotation: Rotation3<f64>,
    /// `[J_v; J_ω]` (6 × N), world-aligned, at the tip origin.
    pub jacobian: Jacobian6<N>,
    /// `J̇ q̇` = [(m/s²); (rad/s²)]: the tip's classical acceleration at q̈ = 0.
    pub bias: Vector<6>,
}

/// The kinematics of an `N`-joint arm's tip.
///
/// Units: q in rad (m for a prismatic joint), q̇ in rad/s (m/s); see [`Tip`].
pub trait Kinematics<const N: usize> {
    /// Pose, Jacobian and `J̇ q̇` at (q, q̇), in one pass (the call a 1 kHz
    /// Cartesian step makes).
    fn tip(&self, q: &Vector<N>, dq: &Vector<N>) -> Tip<N>;

    /// Position p (m) and rotation R (world ← tip) at q, the pose of
    /// [`tip`](Self::tip) without its Jacobian and `J̇ q̇` (the same values:
    /// an implementation that overrides it computes them as `tip` does).
    fn pose(&self, q: &Vector<N>) -> (Vector<3>, Rotation3<f64>) {
        let t = self.tip(q, &Vector::zeros());
        (t.position, t.rotation)
    }
    /// Position p = fk(q) (m).
    fn fk(&self, q: &Vector<N>) -> Vector<3> {
        self.tip(q, &Vector::zeros()).position
    }
    /// Rotation R(q) (world ← tip).
    fn rotation(&self, q: &Vector<N>) -> Rotation3<f64> {
        self.tip(q, &Vector::zeros()).rotation
    }
    /// Geometric Jacobian `[J_v; J_ω]` (6 × N).
    fn jacobian(&self, q: &Vector<N>) -> Jacobian6<N> {
        self.tip(q, &Vector::zeros()).jacobian
    }
    /// Position Jacobian J_v = ∂p/∂q (3 × N, m/rad): the first three rows.
    fn position_jacobian(&self, q: &Vector<N>) -> Jacobian<N> {
        self.jacobian(q).fixed_rows::<3>(0).into_owned()
    }
    /// `J̇ q̇` = [(m/s²); (rad/s²)].
    fn jdot_qdot(&self, q: &Vector<N>, dq: &Vector<N>) -> Vector<6> {
        self.tip(q, dq).bias
    }
}
