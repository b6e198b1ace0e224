//! How the network weights learn: the step (explicit Euler or normalised),
//! what learning does under saturation, and the projection onto a ball.
//! The printed law is explicit Euler of (15)–(17), SPEC §11; the rest is
//! beyond the paper (SPEC §13, `docs/robot.md`).
//!
//! A step of the controller uses a policy in two stages:
//! [`Learning::output`] (the networks' output, and for a policy that needs no
//! saturation information the update in the same pass) and
//! [`Learning::learn`] (after saturation: the deferred update, the freeze
//! under saturation, the projection). Adding a learning law touches this
//! module and the parameter schema, nothing else.

use crate::error::{check, Error, BOUND};
use crate::math::sqrt;
use crate::networks::network::{Rates, WeightsMut, C, D, G};
use crate::networks::simd::SimdPath;
use crate::types::{choices, Vector};

/// How the weights take one learning step (beyond the paper, SPEC §13).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum LearningStep {
    /// Explicit Euler of (15)–(17), SPEC §11 ("euler" in Python).
    #[default]
    Euler,
    /// Normalised step ("normalized"): the Euler step divided by `1 + g/(κ min Kp)`,
    /// where `g = Ts ‖S‖² (ΓD ‖α̇1‖² + ΓC ‖α1‖² + ΓG)` (N m per rad/s) is the
    /// gain one Euler step adds from z2 to the network output. Explicit-Euler
    /// learning against the plant is stable only for g < Kp (a two-state Jury
    /// test of z2 and the learned term), so the normalised step keeps the
    /// per-step gain below κ Kp at any Ts, and is the printed law when g ≪ κ Kp.
    /// The discrete normalised gradient (projection) algorithm: Goodwin & Sin,
    /// *Adaptive Filtering, Prediction and Control*, 1984, ch. 3; Ioannou & Sun,
    /// *Robust Adaptive Control*, 1996, ch. 4.
    Normalized,
}

choices!(LearningStep {
    "euler" => LearningStep::Euler,
    "normalized" => LearningStep::Normalized,
});

/// What learning does while the actuator saturates (beyond the paper, SPEC §13).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum SaturationLearning {
    /// Learn as if nothing saturated, as printed ("ignore" in Python): the
    /// weights integrate an error the actuator cannot remove, and wind up.
    #[default]
    Ignore,
    /// Conditional integration ("freeze"): while joint k saturates, its rows do
    /// not take the learning step that would push τ_k further beyond the limit
    /// (they still leak by σ, and learn in the unwinding direction). Åström &
    /// Hägglund, *Advanced PID Control*, 2006 (integrator windup); for adaptive laws, the
    /// "stop adaptation under saturation" of Kárason & Annaswamy, IEEE TAC 39(11), 1994.
    Freeze,
}

choices!(SaturationLearning {
    "ignore" => SaturationLearning::Ignore,
    "freeze" => SaturationLearning::Freeze,
});

/// The signals a learning step uses: α̇1 (rad/s²), α1 (rad/s) and z2 (rad/s;
/// ẑ2 for output feedback).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Signals<const N: usize> {
    /// α̇1 (rad/s²), the regressor of D̂.
    pub dalpha1: Vector<N>,
    /// α1 (rad/s), the regressor of Ĉ.
    pub alpha1: Vector<N>,
    /// The learning error z2 (rad/s).
    pub z2: Vector<N>,
}

/// A validated learning policy with its precomputed rates.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Learning {
    rates: Rates,
    step: LearningStep,
    saturation: SaturationLearning,
    bound: Option<[f64; 3]>,
    /// κ · min Kp (N m s/rad) for the normalised step.
    gain_cap: f64,
}

impl Learning {
    /// Validated: Γ > 0, σ > 0 (SPEC §10), 0 < κ ≤ 1 (normalised step only),
    /// every weight bound > 0.
    /// `ts` (s) is the sampling period, `kp_min` the smallest Kp (N m s/rad).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        ts: f64,
        gamma: [f64; 3],
        sigma: [f64; 3],
        step: LearningStep,
        kappa: f64,
        saturation: SaturationLearning,
        bound: Option<[f64; 3]>,
        kp_min: f64,
    ) -> Result<Self, Error> {
        let rates = Rates::new(ts, gamma, sigma)?;
        let mut gain_cap = 0.0;
        if step == LearningStep::Normalized {
            check::positive("κ > 0", "kappa", kappa)?;
            if kappa > 1.0 {
                return Err(Error::Condition {
                    condition: "κ ≤ 1",
                    lhs: "kappa",
                    index: None,
                    value: kappa,
                });
            }
            gain_cap = kappa * kp_min;
        }
        if let Some(b) = bound {
            check::positive_vec("weight bound > 0", "weight_bound", &Vector::<3>::from(b))?;
        }
        Ok(Self {
            rates,
            step,
            saturation,
            bound,
            gain_cap,
        })
    }

    /// The per-step rates Ts Γ, 1 − Ts Γ σ (before any normalisation).
    pub fn rates(&self) -> &Rates {
        &self.rates
    }
    /// The learning step.
    pub fn step(&self) -> LearningStep {
        self.step
    }
    /// Learning under saturation.
    pub fn saturation(&self) -> SaturationLearning {
        self.saturation
    }
    /// The projection's bounds on ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F, if any.
    pub fn bound(&self) -> Option<[f64; 3]> {
        self.bound
    }

    /// The weights after this step's update stay within [`BOUND`]: with the
    /// current norms ‖Ŵ‖ (`norms`) the new ones are at most
    /// `|a| ‖Ŵ‖ + Ts Γ ‖u‖ ‖z2‖ ‖S‖`, ‖S‖ ≤ √L (u = α̇1 for D̂, α1 for Ĉ, 1
    /// for Ĝ; normalisation and freezing only shrink the step). Checked
    /// before the pass that writes them, so a failed check changes nothing.
    pub fn check_bounded<const N: usize>(
        &self,
        norms: &[f64; 3],
        sig: &Signals<N>,
        nodes: usize,
    ) -> Result<(), Error> {
        let (a, g) = (self.rates.decay, self.rates.gain);
        let step = sig.z2.norm() * sqrt(nodes as f64);
        let u = [sig.dalpha1.norm(), sig.alpha1.norm(), 1.0];
        for (net, what) in ["weights.D", "weights.C", "weights.G"]
            .into_iter()
            .enumerate()
        {
            let bound = a[net].abs() * norms[net] + g[net] * u[net] * step;
            // NaN (from an infinite norm times zero) is out of range too.
            if bound.is_nan() || bound > BOUND {
                return Err(Error::OutOfRange {
                    what,
                    index: None,
                    value: bound,
                    limit: BOUND,
                });
            }
        }
        Ok(())
    }

    /// True if the update needs this step's saturation, so it follows the output.
    pub fn deferred(&self) -> bool {
        self.saturation == SaturationLearning::Freeze || self.bound.is_some()
    }

    /// This step's rates: the normalised step scales the gains by
    /// `1/(1 + g/(κ min Kp))` (see [`LearningStep::Normalized`]); ‖S‖² is
    /// summed on the instruction set `path`.
    pub fn step_rates<const N: usize>(&self, path: SimdPath, s: &[f64], sig: &Signals<N>) -> Rates {
        match self.step {
            LearningStep::Euler => self.rates,
            LearningStep::Normalized => {
                let g = self.rates.gain;
                let s2 = crate::networks::network::dot_on(path, s, s);
                let gain = s2
                    * (g[D] * sig.dalpha1.norm_squared() + g[C] * sig.alpha1.norm_squared() + g[G]);
                self.rates.scaled(1.0 / (1.0 + gain / self.gain_cap))
            }
        }
    }

    /// Stage "networks": the output `D̂ α̇1 + Ĉ α1 + Ĝ` (N m) with the current
    /// weights; for a policy that is not [`deferred`](Self::deferred), the
    /// update (15)–(17) in the same pass (it uses only this step's values,
    /// SPEC §11, step 5). `norms` (‖Ŵ‖_F) is kept up to date. The passes
    /// run on the instruction set `path` (the controller's,
    /// [`Controller::simd`](crate::Controller::simd)).
    #[inline]
    pub fn output<const N: usize>(
        &self,
        path: SimdPath,
        w: &mut WeightsMut<'_, N>,
        s: &[f64],
        sig: &Signals<N>,
        norms: &mut [f64; 3],
    ) -> Vector<N> {
        if self.deferred() {
            w.as_ref().output(path, s, &sig.dalpha1, &sig.alpha1)
        } else {
            let rates = self.step_rates(path, s, sig);
            w.fused_step(path, s, &sig.dalpha1, &sig.alpha1, &sig.z2, &rates, norms)
        }
    }

    /// Stage "learning", after saturation (Δτ = sat(τ) − τ, N m): for a
    /// [`deferred`](Self::deferred) policy, the update with the freeze under
    /// saturation and the projection onto the weight bounds. No-op otherwise.
    /// The pass runs on the instruction set `path`.
    #[inline]
    pub fn learn<const N: usize>(
        &self,
        path: SimdPath,
        w: &mut WeightsMut<'_, N>,
        s: &[f64],
        sig: &Signals<N>,
        dtau: &Vector<N>,
        norms: &mut [f64; 3],
    ) {
        if !self.deferred() {
            return;
        }
        let rates = self.step_rates(path, s, sig);
        let z2 = self.learning_error(&sig.z2, dtau);
        let mut new = w.update(path, s, &sig.dalpha1, &sig.alpha1, &z2, &rates);
        if let Some(bound) = self.bound {
            project_on(path, w, &mut new, &bound);
        }
        *norms = new;
    }

    /// The error each joint's rows learn from: z2, with the joints whose
    /// learning step would push τ further beyond the limit set to 0 under
    /// [`SaturationLearning::Freeze`].
    pub fn learning_error<const N: usize>(&self, z2: &Vector<N>, dtau: &Vector<N>) -> Vector<N> {
        match self.saturation {
            SaturationLearning::Ignore => *z2,
            // Learning moves out_k along z2_k; Δτ_k points back inside.
            SaturationLearning::Freeze => {
                z2.zip_map(dtau, |z, d| if z * d < 0.0 { 0.0 } else { z })
            }
        }
    }
}

/// Projection of each network onto the ball ‖Ŵ‖_F ≤ bound (Ioannou & Sun
/// 1996, ch. 4 and 8: the Euler step followed by the projection). `norms` are
/// the networks' norms, updated.
pub fn project<const N: usize>(w: &mut WeightsMut<'_, N>, norms: &mut [f64; 3], bound: &[f64; 3]) {
    project_on(SimdPath::portable(), w, norms, bound);
}

/// [`project`] with the scaling on the instruction set `path` (the same
/// bits; a controller passes its own).
pub fn project_on<const N: usize>(
    path: SimdPath,
    w: &mut WeightsMut<'_, N>,
    norms: &mut [f64; 3],
    bound: &[f64; 3],
) {
    for net in 0..3 {
        if norms[net] > bound[net] {
            w.scale_network_on(path, net, bound[net] / norms[net]);
            norms[net] = bound[net];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn freeze_zeroes_only_the_joints_learning_into_the_limit() {
        let l = Learning::new(
            1e-3,
            [1.0; 3],
            [0.1; 3],
            LearningStep::Euler,
            0.5,
            SaturationLearning::Freeze,
            None,
            10.0,
        )
        .unwrap();
        let z2 = Vector::<3>::new(1.0, 1.0, -1.0);
        let dtau = Vector::<3>::new(-0.5, 0.0, -0.5);
        assert_eq!(
            l.learning_error(&z2, &dtau),
            Vector::<3>::new(0.0, 1.0, -1.0)
        );
        assert!(l.deferred());
    }

    #[test]
    fn kappa_and_bounds_are_validated_by_name() {
        let new = |step, kappa, bound| {
            Learning::new(
                1e-3,
                [1.0; 3],
                [0.1; 3],
                step,
                kappa,
                SaturationLearning::Ignore,
                bound,
                10.0,
            )
        };
        let e = new(LearningStep::Normalized, 1.5, None).unwrap_err();
        assert!(e.to_string().contains("κ ≤ 1"), "{e}");
        // κ is only read by the normalised step.
        assert!(new(LearningStep::Euler, 1.5, None).is_ok());
        let e = new(LearningStep::Euler, 0.5, Some([1.0, 0.0, 1.0])).unwrap_err();
        assert!(e.to_string().contains("weight bound > 0"), "{e}");
        assert!(!new(LearningStep::Euler, 0.5, None).unwrap().deferred());
    }
}
