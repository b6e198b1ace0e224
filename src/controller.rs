//! The three controllers of the paper and their discrete-time step, SPEC §7, §11.
//!
//! - [`Law::Pd`], Case 1 (Section IV-A as printed): `τ = Kp (z2 + ζ) + r(z2)`.
//! - [`Law::StateFeedback`], Case 2, (14) with the sign of z1 corrected (SPEC §7):
//!   `τ = z1 + D̂ α̇1 + Ĉ α1 + Ĝ + Kp (z2 + ζ) + r(z2) + τe`.
//! - [`Law::OutputFeedback`], Case 3, (35): the same with ẑ2, S(Ẑ) and α̇1
//!   computed from the high-gain observer's velocity estimate (SPEC §9).
//!
//! [`Config`] holds every parameter (public fields, the paper's defaults from
//! [`Config::paper`]); [`Controller::new`] validates it once (SPEC §10) and
//! precomputes what the step needs. [`Controller::step`] then takes a
//! [`Measurement`] and returns a [`Command`], with no heap allocation, no
//! panic on any finite input, and an error (state untouched) on a non-finite one.

use crate::auxiliary::{AuxLaw, Auxiliary};
use crate::error::{check, Error};
use crate::impedance::{Reference, TargetImpedance};
use crate::math::{sgn, tanh};
use crate::network::{self, Rates, Weights, Workspace};
use crate::observer::{HighGainObserver, Hold, ObserverState};
use crate::rbf::Rbf;
use crate::saturation::Saturation;
use crate::trajectory::{Setpoint, Sinusoid, Trajectory};
use crate::Vector;
use nalgebra::SVector;

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

impl Law {
    /// True for the two adaptive (learning) laws.
    pub fn learns(self) -> bool {
        !matches!(self, Law::Pd)
    }
}

/// The robust term r(z2) (N m), SPEC §7. Each is a choice, not a different controller.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Robust<const N: usize> {
    /// No robust term.
    None,
    /// `Kr sgn(z2)`, the paper's term; `kr` in N m (SPEC default 0.5).
    Sign {
        /// Gain kr per joint (N m).
        kr: Vector<N>,
    },
    /// Smooth boundary layer `Kr tanh(z2/φ)`; `kr` in N m, `phi` in rad/s.
    Tanh {
        /// Gain kr per joint (N m).
        kr: Vector<N>,
        /// Boundary-layer width φ (rad/s), > 0.
        phi: f64,
    },
    /// Remark 1, (30): `kr_i sgn(z2_i)` with `kr_i = kD |α̇1_i| + kC |α1_i| + kG`.
    Remark1 {
        /// kD (N m per rad/s², i.e. kg m²).
        kd: f64,
        /// kC (N m per rad/s).
        kc: f64,
        /// kG (N m).
        kg: f64,
    },
}

impl<const N: usize> Robust<N> {
    fn validate(&self) -> Result<(), Error> {
        match self {
            Robust::None => Ok(()),
            Robust::Sign { kr } => check::nonnegative_vec("kr ≥ 0", "kr", kr),
            Robust::Tanh { kr, phi } => {
                check::nonnegative_vec("kr ≥ 0", "kr", kr)?;
                check::positive("φ > 0", "phi", *phi)
            }
            Robust::Remark1 { kd, kc, kg } => {
                check::nonnegative("kD ≥ 0", "kD", *kd)?;
                check::nonnegative("kC ≥ 0", "kC", *kc)?;
                check::nonnegative("kG ≥ 0", "kG", *kg)
            }
        }
    }

    #[inline]
    fn eval(&self, z2: &Vector<N>, alpha1: &Vector<N>, dalpha1: &Vector<N>) -> Vector<N> {
        match self {
            Robust::None => Vector::zeros(),
            Robust::Sign { kr } => Vector::from_fn(|i, _| kr[i] * sgn(z2[i])),
            Robust::Tanh { kr, phi } => Vector::from_fn(|i, _| kr[i] * tanh(z2[i] / phi)),
            Robust::Remark1 { kd, kc, kg } => Vector::from_fn(|i, _| {
                (kd * dalpha1[i].abs() + kc * alpha1[i].abs() + kg) * sgn(z2[i])
            }),
        }
    }
}

/// How the weights take one learning step (beyond the paper, SPEC §13).
#[derive(Copy, Clone, Debug, Default, PartialEq)]
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
    Normalized {
        /// κ in (0, 1]: the per-step learning gain's bound as a fraction of Kp.
        kappa: f64,
    },
}

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

/// How the observer state starts (SPEC §9).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum ObserverInit {
    /// π(0) = 0, as in the paper (the estimate peaks at start-up).
    #[default]
    Zero,
    /// π1(0) = the first measured position, π2(0) = 0 (no start-up peak).
    FirstMeasurement,
}

/// Every parameter of a controller. Start from [`Config::paper`] (or
/// [`Config::new`] for other sizes) and change fields; [`Controller::new`]
/// validates. Gains are diagonal and given by their diagonals.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct Config<const N: usize, const L: usize> {
    /// Which controller.
    pub law: Law,
    /// Sampling period Ts (s).
    pub ts: f64,
    /// K1 (1/s), (7): α1 = ẋd + K1 z1. Paper: 6.
    pub k1: Vector<N>,
    /// Kp (N m s/rad), (14). Paper: 10.
    pub kp: Vector<N>,
    /// Kζ (1/s), (11). SPEC §8: 60 (must exceed (1 + Kp²)/2).
    pub kzeta: Vector<N>,
    /// μ (N m), radius of the auxiliary system's inner ball. SPEC §8: 0.01.
    pub mu: f64,
    /// Inner law of the auxiliary system. SPEC §8: [`AuxLaw::Leaky`].
    pub aux_law: AuxLaw,
    /// Robust term. SPEC §7: `Sign` with kr = 0.5 N m.
    pub robust: Robust<N>,
    /// The learning step. Paper: explicit Euler.
    pub learning_step: LearningStep,
    /// Learning under saturation. Paper: ignore it.
    pub saturation_learning: SaturationLearning,
    /// Projection of each network's weights onto the ball ‖Ŵ‖_F ≤ bound
    /// (D̂, Ĉ, Ĝ). Paper: none. (Ioannou & Sun 1996, ch. 4 and 8, applied after
    /// each step: the Euler step followed by the projection onto the ball.)
    pub weight_bound: Option<[f64; 3]>,
    /// Learning gains Γ for D̂, Ĉ, Ĝ. Paper: 100.
    pub gamma: [f64; 3],
    /// Leakages σ for D̂, Ĉ, Ĝ. Paper: 0.01.
    pub sigma: [f64; 3],
    /// The RBF basis (centres and η²). Paper: the 2^{4N} vertex grid, η² = 25.
    pub rbf: Rbf<N, L>,
    /// Observer ε (s). SPEC §9: 1e-4.
    pub eps: f64,
    /// Observer λ1 per joint. Paper: 3.
    pub lam1: Vector<N>,
    /// Observer start. Paper: π(0) = 0.
    pub observer_init: ObserverInit,
    /// Observer inter-sample model. SPEC §11: zero-order hold.
    pub observer_hold: Hold,
    /// Actuator limits τmax (N m). Paper: [17, 15].
    pub tau_max: Vector<N>,
    /// Desired inertia Dd (kg m²). Paper: 1.
    pub dd: Vector<N>,
    /// Desired damping Cd (N m s/rad). Paper: 10.
    pub cd: Vector<N>,
    /// Desired stiffness Gd (N m/rad). Paper: 60.
    pub gd: Vector<N>,
}

impl<const N: usize, const L: usize> Config<N, L> {
    /// The paper's gains for `N` joints with limits `tau_max` (N m) and basis `rbf`;
    /// Ts = 50 µs (the paper scenario, SPEC §11).
    pub fn new(law: Law, tau_max: Vector<N>, rbf: Rbf<N, L>) -> Self {
        let imp = TargetImpedance::<N>::paper();
        Self {
            law,
            ts: 50e-6,
            k1: Vector::from_element(6.0),
            kp: Vector::from_element(10.0),
            kzeta: Vector::from_element(60.0),
            mu: 0.01,
            aux_law: AuxLaw::Leaky,
            robust: Robust::Sign {
                kr: Vector::from_element(0.5),
            },
            learning_step: LearningStep::Euler,
            saturation_learning: SaturationLearning::Ignore,
            weight_bound: None,
            gamma: [100.0; 3],
            sigma: [0.01; 3],
            rbf,
            eps: 1e-4,
            lam1: Vector::from_element(3.0),
            observer_init: ObserverInit::Zero,
            observer_hold: Hold::Zero,
            tau_max,
            dd: *imp.dd(),
            cd: *imp.cd(),
            gd: *imp.gd(),
        }
    }
}

impl Config<2, 256> {
    /// The paper scenario (SPEC §11) for the 2-link arm: every default of the SPEC.
    pub fn paper(law: Law) -> Self {
        let rbf = Rbf::grid(25.0).unwrap_or_else(|_| unreachable!("256 = 2^(4·2) and η² = 25 > 0"));
        Self::new(law, Vector::<2>::new(17.0, 15.0), rbf)
    }
}

impl Config<2, 256> {
    /// The "robot" scenario (SPEC §13, beyond the paper): the paper's arm,
    /// gains, Γ, σ, η² and 256 nodes at a robot's Ts = 1 ms, with the
    /// [hardened](Self::hardened) options as defaults.
    pub fn robot(law: Law) -> Self {
        let mut cfg = Self::paper(law).hardened();
        cfg.ts = 1e-3;
        cfg
    }

    /// This configuration with every hardened option of the robot scenario
    /// (SPEC §13), whatever Ts is:
    ///
    /// - [`LearningStep::Normalized`] with κ = 0.5 (the per-step learning gain
    ///   stays below Kp/2; the printed Euler step exceeds Kp at 1 ms);
    /// - [`SaturationLearning::Freeze`] (no learning into the limits);
    /// - `weight_bound` from [`network::weight_bounds`] for this τmax and the
    ///   paper circle (peak ‖ẋc‖ = 0.2π rad/s, ‖ẍc‖ = 0.2π² rad/s²);
    ///   ≈ [0.72, 2.26, 1.42] for τmax = [17, 15] N m;
    /// - [`Robust::Tanh`] with the current kr (or 0.5 N m) and φ = 0.05 rad/s
    ///   (sgn chatters at 1 kHz);
    /// - observer: [`Hold::Triangle`] (at Ts ≫ ε it is the backward difference
    ///   of the samples, where ZOH estimates ≈ 0 at the sample instants),
    ///   started at the first measurement.
    pub fn hardened(mut self) -> Self {
        let pi = core::f64::consts::PI;
        self.learning_step = LearningStep::Normalized { kappa: 0.5 };
        self.saturation_learning = SaturationLearning::Freeze;
        self.weight_bound = Some(network::weight_bounds(
            &self.tau_max,
            256,
            0.2 * pi,
            0.2 * pi * pi,
        ));
        let kr = match self.robust {
            Robust::Sign { kr } | Robust::Tanh { kr, .. } => kr,
            Robust::None | Robust::Remark1 { .. } => Vector::from_element(0.5),
        };
        self.robust = Robust::Tanh { kr, phi: 0.05 };
        self.observer_hold = Hold::Triangle;
        self.observer_init = ObserverInit::FirstMeasurement;
        self
    }
}

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

/// Validated parameters and what is precomputed from them.
#[derive(Clone, Debug)]
struct Parts<const N: usize> {
    sat: Saturation<N>,
    imp: TargetImpedance<N>,
    aux: Auxiliary<N>,
    obs: HighGainObserver<N>,
    rates: Rates,
}

/// A controller of the paper with its state, generic over the number of
/// joints `N`, the number of RBF nodes `L` and the commanded trajectory `T`.
///
/// Size: the weights are `(2N² + N) L` reals (20 KiB for the paper's N = 2,
/// L = 256), kept in place. Construct once, then call [`step`](Self::step)
/// every Ts; the controller keeps its clock t_k = k·Ts.
#[derive(Clone, Debug)]
pub struct Controller<const N: usize, const L: usize, T = Sinusoid<N>> {
    cfg: Config<N, L>,
    parts: Parts<N>,
    traj: T,
    // State.
    k: u64,
    reference: Reference<N>,
    zeta: Vector<N>,
    observer: ObserverState<N>,
    /// The basis and the weights.
    net: Workspace<N, L>,
    /// ‖Ŵ‖_F of the current weights (kept up to date by every update).
    norms: [f64; 3],
    last: Command<N>,
}

impl Controller<2, 256, Sinusoid<2>> {
    /// The paper's controller `law` with every SPEC default, tracking the
    /// paper's circle (64).
    pub fn paper(law: Law) -> Self {
        Self::new(Config::paper(law), Sinusoid::paper())
            .unwrap_or_else(|e| unreachable!("the paper configuration is valid: {e}"))
    }
}

impl<const N: usize, const L: usize, T: Trajectory<N>> Controller<N, L, T> {
    /// Validate `cfg` against every condition of SPEC §10 and build the
    /// controller, tracking `traj`. The error names the condition and the value.
    pub fn new(cfg: Config<N, L>, traj: T) -> Result<Self, Error> {
        check::positive("Ts > 0", "Ts", cfg.ts)?;
        check::positive_vec("K1 > 0", "K1", &cfg.k1)?;
        check::finite_slice("Kp", cfg.kp.as_slice())?;
        check::each(
            "2Kp − I > 0",
            "2·Kp − 1",
            &cfg.kp,
            |_, kp| 2.0 * kp - 1.0,
            true,
        )?;
        check::finite_slice("Kzeta", cfg.kzeta.as_slice())?;
        check::each(
            "2Kζ − I − KpᵀKp > 0",
            "2·Kzeta − 1 − Kp²",
            &cfg.kzeta,
            |i, kz| 2.0 * kz - 1.0 - cfg.kp[i] * cfg.kp[i],
            true,
        )?;
        check::positive("η² > 0", "eta2", cfg.rbf.eta2())?;
        cfg.robust.validate()?;
        if let LearningStep::Normalized { kappa } = cfg.learning_step {
            check::positive("κ > 0", "kappa", kappa)?;
            if kappa > 1.0 {
                return Err(Error::Condition {
                    condition: "κ ≤ 1",
                    lhs: "kappa",
                    index: None,
                    value: kappa,
                });
            }
        }
        if let Some(bound) = cfg.weight_bound {
            check::positive_vec(
                "weight bound > 0",
                "weight_bound",
                &Vector::<3>::from(bound),
            )?;
        }
        let parts = Parts {
            sat: Saturation::new(cfg.tau_max)?,
            imp: TargetImpedance::new(cfg.dd, cfg.cd, cfg.gd)?,
            aux: Auxiliary::new(cfg.kzeta, cfg.mu, cfg.aux_law)?,
            obs: HighGainObserver::new(cfg.eps, cfg.lam1, cfg.ts, cfg.observer_hold)?,
            rates: Rates::new(cfg.ts, cfg.gamma, cfg.sigma)?,
        };
        let start = traj.sample(0.0);
        check::finite_slice("xc(0)", start.x.as_slice())?;
        check::finite_slice("dxc(0)", start.dx.as_slice())?;
        Ok(Self {
            cfg,
            parts,
            traj,
            k: 0,
            reference: Reference::start(&start),
            zeta: Vector::zeros(),
            observer: ObserverState::zeros(),
            net: Workspace::zeros(),
            norms: [0.0; 3],
            last: Command::zeros(),
        })
    }

    /// Back to t = 0: weights, ζ, observer and reference as at construction.
    pub fn reset(&mut self) {
        self.k = 0;
        self.reference = Reference::start(&self.traj.sample(0.0));
        self.zeta = Vector::zeros();
        self.observer = ObserverState::zeros();
        self.net = Workspace::zeros();
        self.norms = [0.0; 3];
        self.last = Command::zeros();
    }

    /// One controller step at t_k = k·Ts with the trajectory sampled at t_k
    /// (SPEC §11, steps 1–5). Returns the command; `tau_sat` goes to the
    /// actuators. On an error nothing changes, except for
    /// [`Error::Diverged`] (then call [`reset`](Self::reset)).
    #[inline]
    pub fn step(&mut self, m: &Measurement<N>) -> Result<Command<N>, Error> {
        let c = self.traj.sample(self.time());
        self.step_with(m, &c)
    }

    /// One step with an externally supplied commanded setpoint `c` (xc, ẋc, ẍc at
    /// t_k) instead of the controller's own trajectory; the clock still advances.
    pub fn step_with(&mut self, m: &Measurement<N>, c: &Setpoint<N>) -> Result<Command<N>, Error> {
        let law = self.cfg.law;
        check::finite_slice("x", m.x.as_slice())?;
        check::finite_slice("tau_e", m.tau_e.as_slice())?;
        check::finite_slice("xc", c.x.as_slice())?;
        check::finite_slice("dxc", c.dx.as_slice())?;
        check::finite_slice("ddxc", c.ddx.as_slice())?;
        let p = &self.parts;
        let ts = self.cfg.ts;

        // 2. Velocity: measured, or the observer's estimate at t_k.
        let v = match law {
            Law::OutputFeedback => {
                let first = self.k == 0;
                if first && self.cfg.observer_init == ObserverInit::FirstMeasurement {
                    self.observer.pi1 = m.x;
                    self.observer.pi2 = Vector::zeros();
                }
                p.obs.measure(&mut self.observer, &m.x, first);
                p.obs.estimate(&self.observer)
            }
            Law::Pd | Law::StateFeedback => {
                let dx = m.dx.ok_or(Error::MissingVelocity)?;
                check::finite_slice("dx", dx.as_slice())?;
                dx
            }
        };

        // 1. Reference acceleration from the target impedance, SPEC §4.
        let r = &self.reference;
        let ddxd = p.imp.accel(c, r, &m.tau_e);

        // 3. Errors (6)–(8), SPEC §5.
        let k1 = &self.cfg.k1;
        let z1 = r.xd - m.x;
        let alpha1 = r.dxd + k1.component_mul(&z1);
        let z2 = alpha1 - v;
        let dalpha1 = ddxd + k1.component_mul(&(r.dxd - v));

        // 4. Control law, SPEC §7.
        let mut tau = self.cfg.kp.component_mul(&(z2 + self.zeta))
            + self.cfg.robust.eval(&z2, &alpha1, &dalpha1);
        let mut w_norms = [0.0; 3];
        // The learning step's scale (1 for the printed law), SPEC §13.
        let mut scale = 1.0;
        let deferred = self.cfg.saturation_learning == SaturationLearning::Freeze
            || self.cfg.weight_bound.is_some();
        if law.learns() {
            self.cfg
                .rbf
                .eval(&[m.x, v, alpha1, dalpha1], &mut self.net.basis);
            if let LearningStep::Normalized { kappa } = self.cfg.learning_step {
                let g = p.rates.gain;
                let gain = self.net.basis.norm_squared()
                    * (g[network::D] * dalpha1.norm_squared()
                        + g[network::C] * alpha1.norm_squared()
                        + g[network::G]);
                scale = 1.0 / (1.0 + gain / (kappa * self.cfg.kp.min()));
            }
            // ‖Ŵ‖ before this step's update.
            w_norms = self.norms;
            let nn = if deferred {
                self.net.weights.output(&self.net.basis, &dalpha1, &alpha1)
            } else {
                // Output and update (15)–(17) / (37)–(39) in one pass; the update
                // uses only this step's values (SPEC §11, step 5).
                let Workspace { basis, weights, .. } = &mut self.net;
                weights.fused_step(
                    basis,
                    &dalpha1,
                    &alpha1,
                    &z2,
                    &p.rates.scaled(scale),
                    &mut self.norms,
                )
            };
            // (14), (35) with +z1 (erratum, SPEC §7).
            tau += z1 + nn + m.tau_e;
        }
        if tau.iter().any(|t| !t.is_finite()) {
            return Err(Error::Diverged { what: "tau" });
        }
        let tau_sat = p.sat.apply(&tau);
        let dtau = tau_sat - tau;
        if law.learns() && deferred {
            // The update needs this step's saturation: after the output.
            let mut z2_learn = z2;
            if self.cfg.saturation_learning == SaturationLearning::Freeze {
                for k in 0..N {
                    // Learning moves out_k along z2_k; Δτ_k points back inside.
                    if z2[k] * dtau[k] < 0.0 {
                        z2_learn[k] = 0.0;
                    }
                }
            }
            let Workspace { basis, weights, .. } = &mut self.net;
            let mut norms =
                weights.update(basis, &dalpha1, &alpha1, &z2_learn, &p.rates.scaled(scale));
            if let Some(bound) = self.cfg.weight_bound {
                for net in 0..3 {
                    if norms[net] > bound[net] {
                        // Projection onto the ball ‖Ŵ‖_F ≤ bound.
                        weights.scale_network(net, bound[net] / norms[net]);
                        norms[net] = bound[net];
                    }
                }
            }
            self.norms = norms;
        }

        let cmd = Command {
            tau_sat,
            tau,
            dtau,
            z1,
            z2,
            xc: c.x,
            xd: r.xd,
            v,
            zeta: self.zeta,
            w_norms,
        };

        // 5. Advance every internal state to t_{k+1}.
        p.aux.advance(&mut self.zeta, &z2, &dtau, ts);
        self.reference.advance(&ddxd, ts);
        if law == Law::OutputFeedback {
            p.obs.finish(&mut self.observer, &m.x);
        }
        self.k += 1;
        self.last = cmd;
        Ok(cmd)
    }

    /// The validated configuration.
    pub fn config(&self) -> &Config<N, L> {
        &self.cfg
    }
    /// The commanded trajectory.
    pub fn trajectory(&self) -> &T {
        &self.traj
    }
    /// Number of steps taken since construction or reset.
    pub fn steps(&self) -> u64 {
        self.k
    }
    /// Time t_k = k·Ts (s) of the next step.
    pub fn time(&self) -> f64 {
        self.k as f64 * self.cfg.ts
    }
    /// Auxiliary state ζ (N m), (11).
    pub fn zeta(&self) -> &Vector<N> {
        &self.zeta
    }
    /// The compliant reference (xd, ẋd) for the next step.
    pub fn reference(&self) -> &Reference<N> {
        &self.reference
    }
    /// Observer state π (output feedback only; zeros otherwise).
    pub fn observer_state(&self) -> &ObserverState<N> {
        &self.observer
    }
    /// The observer's current velocity estimate π2/ε (rad/s).
    pub fn velocity_estimate(&self) -> Vector<N> {
        self.parts.obs.estimate(&self.observer)
    }
    /// The network weights.
    pub fn weights(&self) -> &Weights<N, L> {
        &self.net.weights
    }
    /// Frobenius norms ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ of the current weights, as the
    /// controller tracks them step by step (see [`Weights::fused_step`]);
    /// [`Weights::norms`] recomputes them from the weights.
    pub fn weight_norms(&self) -> [f64; 3] {
        self.norms
    }
    /// Replace the weights (e.g. to warm-start from a previous run). Every
    /// weight must be finite.
    pub fn set_weights(&mut self, w: Weights<N, L>) -> Result<(), Error> {
        w.check_finite()?;
        self.norms = w.norms();
        self.net.weights = w;
        Ok(())
    }
    /// The basis S(Z) of the last step (zeros before the first, and for PD).
    pub fn basis(&self) -> &SVector<f64, L> {
        &self.net.basis
    }
    /// The last step's command (all zeros before the first step).
    pub fn last(&self) -> &Command<N> {
        &self.last
    }
    /// The actuator model the controller saturates with.
    pub fn saturation(&self) -> &Saturation<N> {
        &self.parts.sat
    }
    /// The target impedance.
    pub fn impedance(&self) -> &TargetImpedance<N> {
        &self.parts.imp
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn measurement() -> Measurement<2> {
        Measurement {
            x: Vector::<2>::new(0.15, 0.25),
            dx: Some(Vector::<2>::new(0.4, -0.3)),
            tau_e: Vector::<2>::zeros(),
        }
    }

    /// α1 and α̇1 of the step `c` is about to take with `m` (SPEC §5).
    fn alphas(c: &Controller<2, 256>, m: &Measurement<2>) -> (Vector<2>, Vector<2>, Vector<2>) {
        let sp = c.trajectory().sample(c.time());
        let r = c.reference();
        let ddxd = c.impedance().accel(&sp, r, &m.tau_e);
        let v = m.dx.unwrap_or_else(Vector::zeros);
        let k1 = &c.config().k1;
        let alpha1 = r.dxd + k1.component_mul(&(r.xd - m.x));
        let dalpha1 = ddxd + k1.component_mul(&(r.dxd - v));
        (alpha1, dalpha1, alpha1 - v)
    }

    /// Change of the network output per unit z2 made by one learning step,
    /// at that step's basis: the per-step learning gain (N m per rad/s).
    fn per_step_gain(cfg: Config<2, 256>) -> Vector<2> {
        let mut c = Controller::new(cfg, Sinusoid::paper()).unwrap();
        let m = measurement();
        let (alpha1, dalpha1, z2) = alphas(&c, &m);
        let before = c.weights().clone();
        c.step(&m).unwrap();
        let s = c.basis();
        let delta = c.weights().output(s, &dalpha1, &alpha1) - before.output(s, &dalpha1, &alpha1);
        delta.component_div(&z2)
    }

    #[test]
    fn printed_euler_gain_exceeds_kp_at_1ms_normalized_stays_below_kappa_kp() {
        let mut printed = Config::paper(Law::StateFeedback);
        printed.ts = 1e-3;
        let g = per_step_gain(printed.clone());
        // The Jury condition for explicit-Euler learning is g < Kp = 10.
        assert!(g.min() > 10.0, "printed per-step gain {g}");
        let mut normalized = printed;
        normalized.learning_step = LearningStep::Normalized { kappa: 0.5 };
        let g = per_step_gain(normalized);
        assert!(
            g.max() <= 5.0 + 1e-9 && g.min() > 0.0,
            "normalised per-step gain {g}"
        );
    }

    #[test]
    fn normalized_step_is_the_printed_step_when_the_gain_is_small() {
        // At Ts = 1 µs the per-step gain is tiny and the scale is ≈ 1.
        let mut printed = Config::paper(Law::StateFeedback);
        printed.ts = 1e-6;
        let g_printed = per_step_gain(printed.clone());
        let mut normalized = printed;
        normalized.learning_step = LearningStep::Normalized { kappa: 0.5 };
        let g = per_step_gain(normalized);
        assert!(
            ((g - g_printed).norm() / g_printed.norm()) < 0.01,
            "{g} vs {g_printed}"
        );
    }

    #[test]
    fn freeze_stops_learning_into_the_limit_only() {
        let mut cfg = Config::paper(Law::StateFeedback);
        cfg.saturation_learning = SaturationLearning::Freeze;
        cfg.tau_max = Vector::<2>::new(0.1, 100.0); // joint 1 saturates
        let mut c = Controller::new(cfg, Sinusoid::paper()).unwrap();
        let mut w = Weights::<2, 256>::zeros();
        w.g[0].fill(0.01);
        w.g[1].fill(0.01);
        c.set_weights(w).unwrap();
        let m = measurement();
        let cmd = c.step(&m).unwrap();
        // Joint 1 saturates with learning pushing out: z2 and Δτ of opposite signs.
        assert!(
            cmd.dtau[0] != 0.0 && cmd.z2[0] * cmd.dtau[0] < 0.0,
            "{cmd:?}"
        );
        assert_eq!(cmd.dtau[1], 0.0);
        let decay = 1.0 - c.config().ts * 100.0 * 0.01;
        // Joint 1's rows only leak; joint 2's rows learn.
        assert!(c.weights().g[0]
            .iter()
            .all(|&v| (v - 0.01 * decay).abs() < 1e-18));
        assert!(c.weights().d[0][1].iter().all(|&v| v == 0.0));
        assert!(c.weights().g[1]
            .iter()
            .any(|&v| (v - 0.01 * decay).abs() > 1e-12));
    }

    #[test]
    fn projection_keeps_each_network_in_its_ball() {
        let mut cfg = Config::paper(Law::StateFeedback);
        cfg.ts = 1e-3;
        cfg.weight_bound = Some([1e-3, 2e-3, 3e-3]);
        let mut c = Controller::new(cfg, Sinusoid::paper()).unwrap();
        let m = measurement();
        let mut hit = [false; 3];
        for _ in 0..200 {
            c.step(&m).unwrap();
            let n = c.weights().norms();
            for net in 0..3 {
                let bound = [1e-3, 2e-3, 3e-3][net];
                assert!(n[net] <= bound * (1.0 + 1e-12), "{n:?}");
                hit[net] |= n[net] > 0.999 * bound;
            }
            // The cached norms reported next step are the weights' norms.
            assert!(
                (c.norms[0] - n[0]).abs() <= 1e-12 * n[0],
                "{:?} vs {n:?}",
                c.norms
            );
        }
        assert_eq!(hit, [true; 3], "every bound was reached");
    }

    #[test]
    fn hardening_options_are_validated() {
        let mut cfg = Config::paper(Law::StateFeedback);
        cfg.learning_step = LearningStep::Normalized { kappa: 1.5 };
        let e = Controller::new(cfg, Sinusoid::paper()).unwrap_err();
        assert!(e.to_string().contains("κ ≤ 1"), "{e}");
        let mut cfg = Config::paper(Law::StateFeedback);
        cfg.weight_bound = Some([1.0, 0.0, 1.0]);
        let e = Controller::new(cfg, Sinusoid::paper()).unwrap_err();
        assert!(e.to_string().contains("weight bound > 0"), "{e}");
    }

    #[test]
    fn robot_bounds_match_the_documented_values() {
        let b = Config::robot(Law::StateFeedback).weight_bound.unwrap();
        for (v, e) in b.iter().zip([0.718, 2.255, 1.417]) {
            assert!((v - e).abs() < 1e-3, "{b:?}");
        }
    }
}
