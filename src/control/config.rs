//! Every parameter of a controller, with the paper's defaults and the robot
//! scenario's presets, SPEC §4–§11, §13. Validated by
//! `Controller::new`; the parameter schema
//! (`src/schema.rs`, re-exported as `adaptimp::schema`) documents each field.

use crate::control::auxiliary::AuxLaw;
use crate::control::impedance::ImpedanceMode;
use crate::control::observer::Hold;
use crate::control::robust::RobustKind;
use crate::control::safety::{Fallback, FaultPolicy, Limits};
use crate::networks::learning::{LearningStep, SaturationLearning};
use crate::types::{choices, Matrix, Vector};

/// Which of the paper's controllers, SPEC §7.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Law {
    /// Case 1: PD with the auxiliary system, no learning ("pd" in Python).
    Pd,
    /// Case 2: adaptive neural state feedback (14) ("sf").
    StateFeedback,
    /// Case 3: adaptive neural output feedback with a high-gain observer (35) ("of").
    OutputFeedback,
}

/// Which stability conditions construction checks, SPEC §10.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum Conditions {
    /// The paper's (13): 2Kp − I > 0, 2Kζ − I − KpᵀKp > 0 ("paper"). Proved
    /// for the unit weights of the paper's Lyapunov function only: it needs
    /// `inertia` = 1 and ρ = 1.
    #[default]
    Paper,
    /// SPEC (10.3), from the Lyapunov function weighted by each joint's inertia
    /// scale d_i with the cross term split at Kp ("scaled"): Kp_i > 0 and
    /// 2Kζ_i − ρ − Kp_i/d_i > 0, every term in 1/s.
    Scaled,
}

choices!(Conditions {
    "paper" => Conditions::Paper,
    "scaled" => Conditions::Scaled,
});

impl Law {
    /// True for the two adaptive (learning) laws.
    pub fn learns(self) -> bool {
        !matches!(self, Law::Pd)
    }
}

/// How the observer state starts (SPEC §9).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum ObserverInit {
    /// π(0) = 0, as in the paper ("zero").
    #[default]
    Zero,
    /// π1(0) = the first measured position, π2(0) = 0 (no start-up peak; "first").
    FirstMeasurement,
}

choices!(ObserverInit {
    "zero" => ObserverInit::Zero,
    "first" => ObserverInit::FirstMeasurement,
});

/// Projection of each network's weights onto a ball ‖Ŵ‖_F ≤ b (D̂, Ĉ, Ĝ),
/// beyond the paper (Ioannou & Sun 1996, ch. 4 and 8).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub enum WeightBound {
    /// No projection (the paper; `None` in Python).
    #[default]
    None,
    /// The bounds b for D̂ (kg m²), Ĉ (kg m²/s), Ĝ (N m).
    Fixed([f64; 3]),
    /// Derived from τmax, the number of nodes and the commanded trajectory's
    /// peak speed and acceleration by [`network::weight_bounds`](crate::networks::network::weight_bounds)
    /// ("auto"): no network can then produce more than the actuator's torque
    /// at the commanded regressor scale. Resolved when the trajectory is known
    /// ([`Config::resolve`]); ≈ [0.718, 2.255, 1.417] for the paper.
    Auto,
}

/// The longest loop delay (periods) a controller is made for, and the
/// longest measurement delay the simulator's delay line holds.
pub const MAX_DELAY: usize = 64;

/// Every parameter of a controller. Start from [`Config::paper`] (or
/// [`Config::new`] for other sizes) and change fields;
/// `Controller::new` validates. Gains are diagonal
/// and given by their diagonals. Each field is a parameter of the schema
/// (`schema::PARAMS`), where its default is declared.
#[derive(Copy, Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct Config<const N: usize> {
    /// Which controller.
    pub law: Law,
    /// Sampling period Ts (s).
    pub ts: f64,
    /// The loop's delay δ (periods): a step's torque starts to act δ periods
    /// after the instant its measurement was taken (libfranka: 1), SPEC
    /// (18.11). The step is given the setpoint of the measurement's instant;
    /// the rule ([`Rule`](crate::control::tuning::Rule)) sizes the gains for
    /// δ. Paper: 0; robot preset: 1. 0 ≤ δ ≤ [`MAX_DELAY`].
    pub delay: usize,
    /// K1 (1/s), (7): α1 = ẋd + K1 z1. Paper: 6.
    pub k1: Vector<N>,
    /// Kp (N m s/rad), (14). Paper: 10.
    pub kp: Vector<N>,
    /// Kζ (1/s), (11). SPEC §8: 60 (must exceed (1 + Kp²)/2).
    pub kzeta: Vector<N>,
    /// μ (N m), radius of the auxiliary system's inner ball. SPEC §8: 0.01.
    pub mu: f64,
    /// Inertia scale d_i of each joint (kg m²), SPEC §10: weights the
    /// auxiliary system (Δτ_i/d_i), the z1 term (d_i z1_i) and the learning
    /// error (d_i z2_i). Paper: 1.
    pub inertia: Vector<N>,
    /// Dₛ (kg m², symmetric positive definite), SPEC (18.12): the inertia
    /// scales as a matrix, in place of diag([`inertia`](Self::inertia)) in
    /// the z1 term and the learning error, and the feedback gain Kp = R^½
    /// Dₛ R^½, R = diag(Kp_i/d_i) (the auxiliary system keeps d). None
    /// (paper, robot): the diagonal law.
    pub inertia_matrix: Option<Matrix<N>>,
    /// Young weight ρ (1/s) of ζᵀΔτ in the auxiliary system's β, SPEC §10. Paper: 1.
    pub rho: f64,
    /// Which stability conditions construction checks, SPEC §10.
    pub conditions: Conditions,
    /// Inner law of the auxiliary system. SPEC §8: [`AuxLaw::Leaky`].
    pub aux_law: AuxLaw,
    /// Robust term. SPEC §7: `Sign` with kr = 0.5 N m.
    pub robust: RobustKind,
    /// Gain kr of the sign and tanh robust terms (N m). SPEC §7: 0.5.
    pub kr: Vector<N>,
    /// Boundary layer φ of the tanh robust term (rad/s).
    pub phi: f64,
    /// kD of Remark 1's robust gain, (30) (kg m²).
    pub kd: f64,
    /// kC of Remark 1's robust gain (N m s/rad).
    pub kc: f64,
    /// kG of Remark 1's robust gain (N m).
    pub kg: f64,
    /// The learning step. Paper: explicit Euler.
    pub learning_step: LearningStep,
    /// κ of the normalised learning step, in (0, 1].
    pub kappa: f64,
    /// Learning under saturation. Paper: ignore it.
    pub saturation_learning: SaturationLearning,
    /// Projection of the weights. Paper: none.
    pub weight_bound: WeightBound,
    /// Learning gains Γ for D̂, Ĉ, Ĝ. Paper: 100.
    pub gamma: [f64; 3],
    /// Leakages σ for D̂, Ĉ, Ĝ. Paper: 0.01.
    pub sigma: [f64; 3],
    /// Observer ε (s). SPEC §9: 1e-4.
    pub eps: f64,
    /// Observer λ1 per joint. Paper: 3.
    pub lam1: Vector<N>,
    /// Observer start. Paper: π(0) = 0.
    pub observer_init: ObserverInit,
    /// Observer inter-sample model. SPEC §11: zero-order hold.
    pub observer_hold: Hold,
    /// Output feedback compares the estimate with the reference the
    /// observer's lag L back, ẑ2 = α1 − L α̇1 − ẋ̂, (9.1), SPEC §9. Paper: off.
    pub observer_lead: bool,
    /// Actuator limits τmax (N m). Paper: [17, 15].
    pub tau_max: Vector<N>,
    /// Desired inertia Dd (kg m²). Paper: 1.
    pub dd: Vector<N>,
    /// Desired damping Cd (N m s/rad). Paper: 10.
    pub cd: Vector<N>,
    /// Desired stiffness Gd (N m/rad). Paper: 60.
    pub gd: Vector<N>,
    /// Where the target impedance is realised. Paper: in joint space.
    pub impedance: ImpedanceMode,
    /// The torque to apply when a step fails (beyond the paper).
    pub fallback: Fallback,
    /// Kd (N m s/rad) of the damping fallback −Kd q̇.
    pub fallback_damping: Vector<N>,
    /// What a failed step does to the following ones.
    pub fault_policy: FaultPolicy,
    /// Plausibility limits on the measurements and the torque rate limit
    /// (infinity: none).
    pub limits: Limits<N>,
}

impl<const N: usize> Config<N> {
    /// Every number zero, every choice its first (for the schema to fill in).
    pub(crate) fn zeroed(law: Law) -> Self {
        let z = Vector::zeros();
        Self {
            law,
            ts: 0.0,
            delay: 0,
            k1: z,
            kp: z,
            kzeta: z,
            mu: 0.0,
            inertia: z,
            inertia_matrix: None,
            rho: 0.0,
            conditions: Conditions::Paper,
            aux_law: AuxLaw::Leaky,
            robust: RobustKind::Sign,
            kr: z,
            phi: 0.0,
            kd: 0.0,
            kc: 0.0,
            kg: 0.0,
            learning_step: LearningStep::Euler,
            kappa: 0.0,
            saturation_learning: SaturationLearning::Ignore,
            weight_bound: WeightBound::None,
            gamma: [0.0; 3],
            sigma: [0.0; 3],
            eps: 0.0,
            lam1: z,
            observer_init: ObserverInit::Zero,
            observer_hold: Hold::Zero,
            observer_lead: false,
            tau_max: z,
            dd: z,
            cd: z,
            gd: z,
            impedance: ImpedanceMode::Joint,
            fallback: Fallback::Hold,
            fallback_damping: z,
            fault_policy: FaultPolicy::Report,
            limits: Limits::none(),
        }
    }

    /// The same with [`WeightBound::Auto`] replaced by its bounds for `nodes`
    /// RBF nodes and a trajectory of peak speed and acceleration `rates`
    /// (rad/s, rad/s²; see `Trajectory::peak_rates`).
    pub fn resolve(mut self, nodes: usize, rates: (f64, f64)) -> Self {
        if self.weight_bound == WeightBound::Auto {
            self.weight_bound = WeightBound::Fixed(crate::networks::network::weight_bounds(
                &self.tau_max,
                nodes,
                rates.0,
                rates.1,
            ));
        }
        self
    }
}
