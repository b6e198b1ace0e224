//! Forward kinematics and the Jacobian of the end-effector position,
//! SPEC §16: what a Cartesian impedance needs of an arm.
//!
//! [`Kinematics`] is the trait; [`PlanarArm`] and [`TwoLinkArm`] implement
//! it in their plane: x–y, z = 0, link i's absolute angle θ_i = q_1 + … + q_i
//! measured from the x axis (the horizontal; gravity acts along −y):
//!
//! ```text
//! p(q)  = Σ_a l_a (cos θ_a, sin θ_a, 0)
//! J_i   = ∂p/∂q_i = Σ_{a ≥ i} l_a (−sin θ_a, cos θ_a, 0)
//! J̇ q̇  = −Σ_a l_a θ̇_a² (cos θ_a, sin θ_a, 0),   θ̇_a = q̇_1 + … + q̇_a
//! ```

use crate::math::{cos, sin};
use crate::model::{PlanarArm, TwoLinkArm};
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

/// Link lengths and the absolute angles' sines, cosines and rates, then the
/// three sums of the module docs.
fn planar<const N: usize>(
    lengths: &[f64; N],
    q: &Vector<N>,
    dq: Option<&Vector<N>>,
) -> (Vector<3>, Jacobian<N>, Vector<3>) {
    let mut p = Vector::<3>::zeros();
    let mut jac = Jacobian::<N>::zeros();
    let mut jdq = Vector::<3>::zeros();
    let (mut theta, mut rate) = (0.0, 0.0);
    for a in 0..N {
        theta += q[a];
        let (s, c) = (sin(theta), cos(theta));
        let l = lengths[a];
        p[0] += l * c;
        p[1] += l * s;
        // Link a moves with every joint i ≤ a.
        for i in 0..=a {
            jac[(0, i)] -= l * s;
            jac[(1, i)] += l * c;
        }
        if let Some(dq) = dq {
            rate += dq[a];
            jdq[0] -= l * rate * rate * c;
            jdq[1] -= l * rate * rate * s;
        }
    }
    (p, jac, jdq)
}

impl<const N: usize> Kinematics<N> for PlanarArm<N> {
    fn fk(&self, q: &Vector<N>) -> Vector<3> {
        planar(&self.links().map(|l| l.length), q, None).0
    }
    fn jacobian(&self, q: &Vector<N>) -> Jacobian<N> {
        planar(&self.links().map(|l| l.length), q, None).1
    }
    fn jacobian_dot_qdot(&self, q: &Vector<N>, dq: &Vector<N>) -> Vector<3> {
        planar(&self.links().map(|l| l.length), q, Some(dq)).2
    }
}

impl Kinematics<2> for TwoLinkArm {
    fn fk(&self, q: &Vector<2>) -> Vector<3> {
        planar(&self.lengths(), q, None).0
    }
    fn jacobian(&self, q: &Vector<2>) -> Jacobian<2> {
        planar(&self.lengths(), q, None).1
    }
    fn jacobian_dot_qdot(&self, q: &Vector<2>, dq: &Vector<2>) -> Vector<3> {
        planar(&self.lengths(), q, Some(dq)).2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Link;

    fn arm3() -> PlanarArm<3> {
        let link = |mass, length: f64| Link {
            mass,
            length,
            com: length / 2.0,
            inertia: mass * length * length / 12.0,
        };
        PlanarArm::new([link(2.0, 0.4), link(1.5, 0.35), link(1.0, 0.25)], 9.81).unwrap()
    }

    /// The numerical default of J̇ q̇, for comparison with the closed forms.
    struct Numeric<'a>(&'a PlanarArm<3>);
    impl Kinematics<3> for Numeric<'_> {
        fn fk(&self, q: &Vector<3>) -> Vector<3> {
            self.0.fk(q)
        }
        fn jacobian(&self, q: &Vector<3>) -> Jacobian<3> {
            self.0.jacobian(q)
        }
    }

    #[test]
    fn jacobian_and_its_derivative_match_finite_differences() {
        let arm = arm3();
        let q = Vector::<3>::new(0.3, -0.8, 1.1);
        let dq = Vector::<3>::new(0.7, -1.2, 0.4);
        let j = arm.jacobian(&q);
        let h = 1e-6;
        for i in 0..3 {
            let mut e = Vector::<3>::zeros();
            e[i] = h;
            let col = (arm.fk(&(q + e)) - arm.fk(&(q - e))) / (2.0 * h);
            assert!((col - j.column(i)).norm() < 1e-8, "column {i}");
        }
        let closed = arm.jacobian_dot_qdot(&q, &dq);
        let numeric = Numeric(&arm).jacobian_dot_qdot(&q, &dq);
        assert!((closed - numeric).norm() < 1e-7, "{closed} vs {numeric}");
        assert_eq!(arm.fk(&q)[2], 0.0);
    }

    #[test]
    fn two_link_arm_reaches_l1_plus_l2_stretched_out() {
        let arm = TwoLinkArm::paper();
        let p = arm.fk(&Vector::<2>::zeros());
        assert!((p[0] - 0.66).abs() < 1e-15 && p[1] == 0.0, "{p}");
        let p = arm.fk(&Vector::<2>::new(core::f64::consts::FRAC_PI_2, 0.0));
        assert!((p[1] - 0.66).abs() < 1e-15, "{p}");
    }
}
