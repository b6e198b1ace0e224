//! The inverse kinematics of the outer loop, SPEC §16 (C2)–(C3'): the
//! damped-least-squares solve weighted per task direction, grown near a
//! singularity, and the second-order closed-loop inverse kinematics with
//! its null-space posture task.

use super::*;

/// The singular region of (C3'), s: the damping grows when the smallest
/// singular value of Λ⁻¹J falls below s (with the default λ_p = λ_o = 0.01,
/// σ_min(J) < 0.05 m/rad: the posture rule's threshold, SPEC (16.9)).
pub const SINGULAR_REGION: f64 = 5.0;

/// The direction (C3')'s inverse iteration starts from (not unit; any
/// vector with a component along the weakest direction converges to it).
pub(super) fn weak_start() -> Vector<6> {
    Vector::<6>::new(1.0, 0.9, 0.8, 0.7, 0.6, 0.5)
}

impl<const N: usize, K: Kinematics<N>> CartesianImpedance<N, K> {
    /// The damped-least-squares solve `J⁺ v = Jᵀ (J Jᵀ + μ² Λ²)⁻¹ v` (C3),
    /// (C3'): 6 × 6, positive definite for λ > 0 (zero if a non-finite J makes
    /// it indefinite; the step's checks then refuse the result). μ = 1 unless
    /// the weakest direction of Λ⁻¹J, tracked in `weak` by one step of inverse
    /// iteration per call, has a singular value σ̃ below [`SINGULAR_REGION`]
    /// s: then μ² = 1 + s² − σ̃² (continuous at σ̃ = s), so that ‖J⁺Λ‖₂ ≤
    /// 1/(2μ), 1/(2√(1 + s²)) at a singularity (1/2 with the fixed λ), and
    /// the weakest direction's gain is σ̃/(1 + s²).
    pub(super) fn dls(&self, j: &Jacobian6<N>, v: &Vector<6>, weak: &mut Vector<6>) -> Vector<N> {
        let jjt = j * j.transpose();
        let a = jjt + SMatrix::<f64, 6, 6>::from_diagonal(&self.lambda2);
        let Some(ch) = a.cholesky() else {
            return Vector::zeros();
        };
        let mu2 = self.damping(j, &a, &ch, weak);
        if mu2 == 1.0 {
            return j.transpose() * ch.solve(v);
        }
        let damped = jjt + SMatrix::<f64, 6, 6>::from_diagonal(&(mu2 * self.lambda2));
        match damped.cholesky() {
            Some(ch) => j.transpose() * ch.solve(v),
            None => Vector::zeros(),
        }
    }

    /// μ² of (C3') for the Jacobian `j` with `a` = J Jᵀ + Λ² and its
    /// Cholesky factor `ch`; advances the weakest direction `weak` by one
    /// step of inverse iteration on Ã = Λ⁻¹ a Λ⁻¹ = J̃J̃ᵀ + I (J̃ = Λ⁻¹J)
    /// restricted to the rows J has (a row of zeros, the rotation of a
    /// position-only loop or the third axis of a planar arm, is no direction
    /// the arm can lose), whose Rayleigh quotient ρ ≥ 1 + σ̃²_min estimates
    /// σ̃² = ρ − 1 of it.
    pub(super) fn damping(
        &self,
        j: &Jacobian6<N>,
        a: &SMatrix<f64, 6, 6>,
        ch: &nalgebra::Cholesky<f64, nalgebra::Const<6>>,
        weak: &mut Vector<6>,
    ) -> f64 {
        let lambda = self.lambda2.map(sqrt);
        let mask = Vector::<6>::from_fn(|i, _| {
            if j.row(i).iter().any(|x| *x != 0.0) {
                1.0
            } else {
                0.0
            }
        });
        let mut w = weak.component_mul(&mask);
        if w.norm() < 1e-6 {
            w = weak_start().component_mul(&mask);
        }
        if w.norm() == 0.0 {
            return 1.0;
        }
        // w ← Ã⁻¹ w = Λ a⁻¹ Λ w, normalised.
        let x = lambda.component_mul(&ch.solve(&lambda.component_mul(&w)));
        let norm = x.norm();
        if !(norm > 0.0 && norm.is_finite()) {
            return 1.0;
        }
        *weak = x / norm;
        let u = weak.component_div(&lambda);
        let sigma2 = (u.dot(&(a * u)) - 1.0).max(0.0);
        let region2 = SINGULAR_REGION * SINGULAR_REGION;
        if sigma2 >= region2 {
            1.0
        } else {
            1.0 + region2 - sigma2
        }
    }

    /// The orientation rows zeroed for a position-only loop (the selection of (C2)).
    pub(super) fn select(&self, mut v: Vector<6>) -> Vector<6> {
        if !self.orients {
            v.fixed_rows_mut::<3>(3).fill(0.0);
        }
        v
    }

    pub(super) fn select_jacobian(&self, mut j: Jacobian6<N>) -> Jacobian6<N> {
        if !self.orients {
            j.fixed_rows_mut::<3>(3).fill(0.0);
        }
        j
    }

    /// (C2): the second-order CLIK acceleration q̈ at (q, q̇) toward the pose
    /// (p, ṗ, p̈) and (R, ω, ω̇) (the rotation rows only when orienting),
    /// the posture in the null space; `tip` is the kinematics at (q, q̇).
    pub(super) fn clik(
        &self,
        tip: &crate::cartesian::kinematics::Tip<N>,
        (q, dq, posture): (&Vector<N>, &Vector<N>, &Vector<N>),
        (p, dp, ddp): (&Vector<3>, &Vector<3>, &Vector<3>),
        (rq, w, dw): (&UnitQuaternion<f64>, &Vector<3>, &Vector<3>),
        weak: &mut Vector<6>,
    ) -> Vector<N> {
        let cfg = &self.cfg;
        let j = self.select_jacobian(tip.jacobian);
        let twist = j * dq;
        let mut r = Vector::<6>::zeros();
        let ep_ik = p - tip.position;
        r.fixed_rows_mut::<3>(0).copy_from(
            &(ddp - tip.bias.fixed_rows::<3>(0)
                + cfg.clik_kd * (dp - twist.fixed_rows::<3>(0))
                + cfg.clik_kp * ep_ik),
        );
        if self.orients {
            let eo_ik = rotation_error(rq, &UnitQuaternion::from_rotation_matrix(&tip.rotation));
            r.fixed_rows_mut::<3>(3).copy_from(
                &(dw - tip.bias.fixed_rows::<3>(3)
                    + cfg.clik_kd * (w - twist.fixed_rows::<3>(3))
                    + cfg.clik_kp * eo_ik),
            );
        }
        let wn = cfg.null_k * (posture - q) - cfg.null_d * dq;
        wn + self.dls(&j, &(r - j * wn), weak)
    }
}
