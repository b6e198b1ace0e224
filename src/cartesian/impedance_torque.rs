//! A torque-level Cartesian impedance as robot users write it, SPEC (20.7):
//! the law of libfranka's `cartesian_impedance_control` example, with the
//! core's rotation error (16.2) and a damped null-space projector.
//!
//! ```text
//! e   = [p − p_d; Log(R R_dᵀ)]
//! τ_0 = k_n (q_n − q) − d_n q̇
//! τ   = Jᵀ (−K e − D J q̇) + τ_0 − Jᵀ (J Jᵀ + Λ²)⁻¹ J τ_0
//! ```
//!
//! Units: m, rad, N, N m, s. No allocation; [`ImpedanceTorque::new`]
//! validates once.

use crate::cartesian::kinematics::Tip;
use crate::cartesian::rotation::log_quaternion;
use crate::error::{check, Error};
use crate::types::Vector;
use nalgebra::{Rotation3, SMatrix, UnitQuaternion};

/// The parameters of (20.7): see the [module docs](self).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ImpedanceTorque<const N: usize> {
    /// K: translation (N/m) ×3, rotation (N m/rad) ×3, world axes, ≥ 0.
    pub stiffness: Vector<6>,
    /// D: translation (N s/m) ×3, rotation (N m s/rad) ×3, ≥ 0.
    pub damping: Vector<6>,
    /// k_n, the posture's stiffness (N m/rad), ≥ 0.
    pub null_stiffness: f64,
    /// d_n, the posture's damping (N m s/rad), ≥ 0.
    pub null_damping: f64,
    /// Λ² of the null-space projector (m², m², m², 1, 1, 1), > 0: (C3)'s.
    pub lambda2: Vector<6>,
}

/// The pose a [`ImpedanceTorque`] holds the tool at: position p_d (m) and
/// rotation R_d (world ← tool).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PoseGoal {
    /// p_d (m), world frame.
    pub position: Vector<3>,
    /// R_d.
    pub rotation: Rotation3<f64>,
}

impl<const N: usize> ImpedanceTorque<N> {
    /// Validated: every entry finite, K, D, k_n, d_n ≥ 0, Λ² > 0; errors name
    /// the parameter and the axis.
    pub fn new(
        stiffness: Vector<6>,
        damping: Vector<6>,
        null_stiffness: f64,
        null_damping: f64,
        lambda2: Vector<6>,
    ) -> Result<Self, Error> {
        check::nonnegative_vec("stiffness ≥ 0", "stiffness", &stiffness)?;
        check::nonnegative_vec("damping ≥ 0", "damping", &damping)?;
        check::nonnegative("null_stiffness ≥ 0", "null_stiffness", null_stiffness)?;
        check::nonnegative("null_damping ≥ 0", "null_damping", null_damping)?;
        check::positive_vec("lambda2 > 0", "lambda2", &lambda2)?;
        Ok(Self {
            stiffness,
            damping,
            null_stiffness,
            null_damping,
            lambda2,
        })
    }

    /// The pose error e = [p − p_d; Log(R R_dᵀ)] (m, rad) of the tool `tip`
    /// (its pose at the measured q), (16.2).
    pub fn error(tip: &Tip<N>, goal: &PoseGoal) -> Vector<6> {
        let r = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
            tip.rotation.matrix() * goal.rotation.matrix().transpose(),
        ));
        let (ep, eo) = (tip.position - goal.position, log_quaternion(&r));
        Vector::<6>::new(ep[0], ep[1], ep[2], eo[0], eo[1], eo[2])
    }

    /// τ of (20.7) (N m) at the measured (q, q̇) (rad, rad/s) with the
    /// tool's pose and Jacobian `tip` at q, the goal and the posture q_n
    /// (rad). Zero null-space term if J Jᵀ + Λ² is not positive definite
    /// (only for a non-finite input).
    pub fn torque(
        &self,
        tip: &Tip<N>,
        goal: &PoseGoal,
        posture: &Vector<N>,
        q: &Vector<N>,
        dq: &Vector<N>,
    ) -> Vector<N> {
        let j = &tip.jacobian;
        let e = Self::error(tip, goal);
        let f = -self.stiffness.component_mul(&e) - self.damping.component_mul(&(j * dq));
        let t0 = (posture - q) * self.null_stiffness - dq * self.null_damping;
        let a = j * j.transpose() + SMatrix::<f64, 6, 6>::from_diagonal(&self.lambda2);
        let y = match a.cholesky() {
            Some(ch) => ch.solve(&(j * t0)),
            None => Vector::<6>::zeros(),
        };
        j.tr_mul(&(f - y)) + t0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cartesian::chain::{sample_joints, Chain, Transform};
    use crate::cartesian::kinematics::Kinematics;

    fn law() -> ImpedanceTorque<3> {
        ImpedanceTorque::new(
            Vector::<6>::new(500.0, 400.0, 300.0, 20.0, 15.0, 10.0),
            Vector::<6>::new(40.0, 35.0, 30.0, 8.0, 7.0, 6.0),
            25.0,
            10.0,
            Vector::<6>::from_element(1e-4),
        )
        .unwrap()
    }

    #[test]
    fn the_law_is_its_equation() {
        // (20.7) term by term with the projector as a matrix.
        let chain = Chain::<3>::new(
            &sample_joints(),
            &Transform::from_xyz_rpy([0.0, 0.0, 0.15], [0.1, 0.2, 0.3]),
        )
        .unwrap();
        let law = law();
        let (q0, q) = (
            Vector::<3>::new(0.1, 0.05, 0.3),
            Vector::<3>::new(0.4, 0.12, -0.7),
        );
        let dq = Vector::<3>::new(0.9, -0.3, 1.4);
        let home = chain.tip(&q0, &Vector::zeros());
        let goal = PoseGoal {
            position: home.position,
            rotation: home.rotation,
        };
        let tip = chain.tip(&q, &Vector::zeros());
        let j = tip.jacobian;
        let e = ImpedanceTorque::error(&tip, &goal);
        // The rotation error is (16.2)'s: R = Exp(e_o) R_d.
        let back =
            crate::cartesian::rotation::exp(&e.fixed_rows::<3>(3).into_owned()) * goal.rotation;
        assert!(back.angle_to(&UnitQuaternion::from_rotation_matrix(&tip.rotation)) < 1e-12);
        let proj = nalgebra::SMatrix::<f64, 3, 3>::identity()
            - j.transpose()
                * (j * j.transpose() + SMatrix::<f64, 6, 6>::from_diagonal(&law.lambda2))
                    .try_inverse()
                    .unwrap()
                * j;
        let want = j.transpose()
            * (-law.stiffness.component_mul(&e) - law.damping.component_mul(&(j * dq)))
            + proj * ((q0 - q) * 25.0 - dq * 10.0);
        let got = law.torque(&tip, &goal, &q0, &q, &dq);
        assert!((got - want).amax() < 1e-9 * want.amax(), "{got} vs {want}");
        // At the goal, at rest, in the posture: no torque.
        let still = law.torque(&home, &goal, &q0, &q0, &Vector::zeros());
        assert!(still.amax() < 1e-12, "{still}");
    }

    #[test]
    fn bad_parameters_are_refused_by_name() {
        let ok = Vector::<6>::from_element(1.0);
        let mut bad = ok;
        bad[4] = -1.0;
        let e = ImpedanceTorque::<3>::new(bad, ok, 1.0, 1.0, ok).unwrap_err();
        assert!(e.to_string().contains("stiffness[4]"), "{e}");
        let e = ImpedanceTorque::<3>::new(ok, ok, 1.0, 1.0, Vector::zeros()).unwrap_err();
        assert!(e.to_string().contains("lambda2 > 0"), "{e}");
        let e = ImpedanceTorque::<3>::new(ok, ok, f64::NAN, 1.0, ok).unwrap_err();
        assert!(e.to_string().contains("null_stiffness"), "{e}");
    }
}
