//! The three controllers of the paper and their discrete-time step, SPEC §7, §11.
//!
//! - [`Law::Pd`], Case 1 (Section IV-A as printed): `τ = Kp (z2 + ζ) + r(z2)`.
//! - [`Law::StateFeedback`], Case 2, (14) with the sign of z1 corrected (SPEC §7):
//!   `τ = z1 + D̂ α̇1 + Ĉ α1 + Ĝ + Kp (z2 + ζ) + r(z2) + τe`.
//! - [`Law::OutputFeedback`], Case 3, (35): the same with ẑ2, S(Ẑ) and α̇1
//!   computed from the high-gain observer's velocity estimate (SPEC §9).
//!
//! A [`Controller`] is the validated, immutable description (`Send + Sync`:
//! share it by reference across threads); a [`State`] holds everything a run
//! changes. [`Controller::step`] takes both, ruckig's shape: description by
//! `&`, state by `&mut`, measurement and setpoint in, command out. The step
//! runs as named stages, each a small method below: reference, errors,
//! velocity source, basis, networks, robust term, saturation, learning,
//! advance.

use crate::control::auxiliary::Auxiliary;
use crate::control::config::{Conditions, Config, Law, ObserverInit, WeightBound, MAX_DELAY};
use crate::control::impedance::{ImpedanceMode, Reference, TargetImpedance};
#[cfg(feature = "alloc")]
use crate::control::io::Feedforward;
use crate::control::io::{Command, Control, Measurement, TaskTorque};
use crate::control::observer::{HighGainObserver, ObserverState};
use crate::control::robust::Robust;
use crate::control::safety::{Fallback, Fault, FaultPolicy};
use crate::control::saturation::Saturation;
use crate::control::state::State;
use crate::error::{check, Error, BOUND, PARAM_BOUND};
use crate::networks::learning::{Learning, Signals};
use crate::networks::rbf::{Basis, Grid};
use crate::networks::simd::SimdPath;
use crate::trajectory::{Setpoint, Trajectory};
use crate::types::Vector;

/// The smallest inertia scale d (kg m²) and Young weight ρ (1/s), SPEC §10:
/// 1/d and 1/ρ multiply Δτ, so a smaller one could take ζ beyond [`BOUND`].
pub const MIN_SCALE: f64 = 1e-9;

/// A validated controller of the paper: its configuration, its basis and
/// what is precomputed from them. Immutable; see the [module docs](self).
#[derive(Clone, Debug)]
pub struct Controller<const N: usize, B = Grid<N>> {
    cfg: Config<N>,
    basis: B,
    sat: Saturation<N>,
    imp: TargetImpedance<N>,
    aux: Auxiliary<N>,
    obs: HighGainObserver<N>,
    /// Output feedback with `observer_lead`: the observer's lag L (s) per
    /// joint, by which ẑ2 compares with the reference half a period back (9.1).
    lead: Option<Vector<N>>,
    robust: Robust<N>,
    learning: Learning,
    /// The weight pass's instruction set, chosen once in [`Controller::new`].
    simd: SimdPath,
    /// A torque added to the law's at the measured position (the nominal
    /// model's gravity, SPEC (20.10)); none by default.
    #[cfg(feature = "alloc")]
    feedforward: Option<alloc::sync::Arc<dyn Feedforward<N>>>,
}

/// The errors of one step at t_k, SPEC §5, from the reference and the velocity used.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Errors<const N: usize> {
    /// Reference acceleration ẍd (rad/s²), SPEC §4.
    pub ddxd: Vector<N>,
    /// z1 = xd − x (rad), (6).
    pub z1: Vector<N>,
    /// α1 = ẋd + K1 z1 (rad/s), (7).
    pub alpha1: Vector<N>,
    /// z2 = α1 − v (rad/s), (8); with `observer_lead`, ẑ2 = α1 − L α̇1° − v,
    /// α̇1° = ẍc + K1 (ẋd − v) (9.1), (9.2), SPEC §9.
    pub z2: Vector<N>,
    /// α̇1 = ẍd + K1 (ẋd − v) (rad/s²).
    pub dalpha1: Vector<N>,
}

impl<const N: usize> Errors<N> {
    /// The signals the learning laws use, with the learning error z2 (the
    /// paper's, for unit inertia scales).
    pub fn signals(&self) -> Signals<N> {
        Signals {
            dalpha1: self.dalpha1,
            alpha1: self.alpha1,
            z2: self.z2,
        }
    }

    /// The signals the learning laws use, with the learning error d∘z2 (N m s)
    /// weighted by the inertia scales d (kg m²), SPEC (10.2): joint k's rows
    /// learn at Γ d_k and leak at Γσ.
    pub fn signals_scaled(&self, inertia: &Vector<N>) -> Signals<N> {
        Signals {
            z2: self.z2.component_mul(inertia),
            ..self.signals()
        }
    }
}

/// The torque-level terms of a step of (19.2).
#[derive(Copy, Clone, Debug)]
struct Task<const N: usize> {
    /// (7), (8) on the commanded reference.
    errors: Errors<N>,
    /// Jᵀ(K̃e + B ė) + Π (z1_c + Kp z2_c + r(z2_c)) (N m), (19.3).
    torque: Vector<N>,
    /// The admittance's share n.
    share: f64,
    /// The commanded joint reference (q_c, q̇_c, q̈_c).
    commanded: Setpoint<N>,
}

impl<const N: usize> Task<N> {
    /// The learning signals of (19.2): the regressors q̈_c + n (α̇1 − ẍd),
    /// n α1 + (1 − n) q̇_c and the paper's z2 of `e` (on the compliant
    /// reference: the networks learn what the impedance leaves undone, never
    /// the contact force it prescribes), weighted d∘z2 by the inertia scales
    /// as (10.2). The acceleration regressor takes the commanded q̈_c in place
    /// of the compliant ẍd, which carries this sample's wrench (ẍd ∋ J⁺F_e/M_d):
    /// through D̂ that closed the admittance's algebraic loop with the learnt
    /// inertia's gain, and the unified step rang on a rigid table once D̂ had
    /// learnt (SPEC (19.2)).
    fn signals(&self, e: &Errors<N>, inertia: &Vector<N>) -> Signals<N> {
        let n = self.share;
        Signals {
            dalpha1: self.commanded.ddx + n * (e.dalpha1 - e.ddxd),
            alpha1: n * e.alpha1 + (1.0 - n) * self.commanded.dx,
            z2: e.z2.component_mul(inertia),
        }
    }

    /// The networks' input [x; v] of (19.2): n [q; v] + (1 − n) [q_c; q̇_c].
    fn input(&self, x: &Vector<N>, v: &Vector<N>) -> (Vector<N>, Vector<N>) {
        let n = self.share;
        (
            n * x + (1.0 - n) * self.commanded.x,
            n * v + (1.0 - n) * self.commanded.dx,
        )
    }
}

/// The small state a step changes, staged until its commit.
#[derive(Copy, Clone, Debug)]
struct Staged<const N: usize> {
    observer: ObserverState<N>,
    reference: Reference<N>,
}

impl<const N: usize, B: Basis<N>> Controller<N, B> {
    /// Validate `cfg` against every condition of SPEC §10 and build the
    /// controller with basis `basis`. The error names the condition and the
    /// value. A [`WeightBound::Auto`] needs the trajectory: use
    /// [`for_trajectory`](Self::for_trajectory).
    ///
    /// The weight pass's instruction set is chosen here, once
    /// ([`SimdPath::detect`]): AVX2 and FMA if the CPU has them (x86-64-v3,
    /// no build flag needed), the portable path otherwise. With `std`, the
    /// environment variable `ADAPTIMP_SIMD=portable` forces the portable path
    /// (e.g. to compare the two); [`simd`](Self::simd) tells which was taken
    /// and [`with_simd`](Self::with_simd) changes it. Both give the same
    /// results.
    pub fn new(cfg: Config<N>, basis: B) -> Result<Self, Error> {
        if N == 0 || basis.nodes() == 0 {
            return Err(Error::Invalid {
                what: "controller",
                reason: "needs at least one joint and one RBF node",
            });
        }
        check::positive("Ts > 0", "Ts", cfg.ts)?;
        check::positive_vec("K1 > 0", "K1", &cfg.k1)?;
        Self::check_stability(&cfg)?;
        Self::check_magnitudes(&cfg)?;
        check::nonnegative_vec("Kd ≥ 0", "fallback_damping", &cfg.fallback_damping)?;
        cfg.limits.validate()?;
        let robust = Robust::from_config(cfg.robust, cfg.kr, cfg.phi, [cfg.kd, cfg.kc, cfg.kg]);
        robust.validate()?;
        let bound = match cfg.weight_bound {
            WeightBound::None => None,
            WeightBound::Fixed(b) => Some(b),
            WeightBound::Auto => {
                return Err(Error::Invalid {
                    what: "weight_bound = auto",
                    reason: "derives from the commanded trajectory: build with Controller::for_trajectory, or give fixed bounds",
                })
            }
        };
        let obs = HighGainObserver::new(cfg.eps, cfg.lam1, cfg.ts, cfg.observer_hold)?;
        let lead = (cfg.law == Law::OutputFeedback && cfg.observer_lead).then(|| *obs.lag());
        Ok(Self {
            sat: Saturation::new(cfg.tau_max)?,
            imp: TargetImpedance::new(cfg.dd, cfg.cd, cfg.gd)?,
            aux: Auxiliary::weighted(cfg.kzeta, cfg.mu, cfg.aux_law, cfg.inertia, cfg.rho)?,
            obs,
            lead,
            learning: Learning::new(
                cfg.ts,
                cfg.gamma,
                cfg.sigma,
                cfg.learning_step,
                cfg.kappa,
                cfg.saturation_learning,
                bound,
                // min_k Kp_k/d_k (1/s; min Kp for d = 1, exactly).
                cfg.kp.component_div(&cfg.inertia).min(),
            )?,
            robust,
            cfg,
            basis,
            simd: SimdPath::detect(),
            #[cfg(feature = "alloc")]
            feedforward: None,
        })
    }

    /// This controller with `feedforward`'s torque added to the law's at
    /// every step, SPEC (20.10): τ = τ_law + τ_ff(q) at the measured q, before
    /// the rate limit and the saturation (Δτ of the auxiliary system includes
    /// it). The nominal model's gravity (a `cartesian::Dynamics`) for a robot
    /// that does not compensate it itself; none (the default) for one that
    /// does, as Franka's torque interface.
    #[cfg(feature = "alloc")]
    pub fn with_feedforward(mut self, feedforward: alloc::sync::Arc<dyn Feedforward<N>>) -> Self {
        self.feedforward = Some(feedforward);
        self
    }

    /// The torque fed forward, if any ([`with_feedforward`](Self::with_feedforward)).
    #[cfg(feature = "alloc")]
    pub fn feedforward(&self) -> Option<&dyn Feedforward<N>> {
        self.feedforward.as_deref()
    }

    /// The stability conditions of SPEC §10 that [`Config::conditions`]
    /// names: the paper's (13), or the inertia-scaled (10.3).
    fn check_stability(cfg: &Config<N>) -> Result<(), Error> {
        check::finite_slice("Kp", cfg.kp.as_slice())?;
        check::finite_slice("Kzeta", cfg.kzeta.as_slice())?;
        check::finite_slice("inertia", cfg.inertia.as_slice())?;
        if let Some(i) = cfg.inertia.iter().position(|d| *d < MIN_SCALE) {
            return Err(Error::Condition {
                condition: "d ≥ 1e-9",
                lhs: "inertia",
                index: Some(i),
                value: cfg.inertia[i],
            });
        }
        check::finite("rho", cfg.rho)?;
        if cfg.rho < MIN_SCALE {
            return Err(Error::Condition {
                condition: "ρ ≥ 1e-9",
                lhs: "rho",
                index: None,
                value: cfg.rho,
            });
        }
        match cfg.conditions {
            Conditions::Paper => {
                // (13) is proved with the paper's unit weights only (SPEC §10).
                if cfg.inertia.iter().any(|d| *d != 1.0) || cfg.rho != 1.0 {
                    return Err(Error::Invalid {
                        what: "conditions = paper",
                        reason: "(13) is proved for the paper's unit weights (inertia = 1, rho = 1): use conditions = scaled",
                    });
                }
                check::each(
                    "2Kp − I > 0",
                    "2·Kp − 1",
                    &cfg.kp,
                    |_, kp| 2.0 * kp - 1.0,
                    true,
                )?;
                check::each(
                    "2Kζ − I − KpᵀKp > 0",
                    "2·Kzeta − 1 − Kp²",
                    &cfg.kzeta,
                    |i, kz| 2.0 * kz - 1.0 - cfg.kp[i] * cfg.kp[i],
                    true,
                )
            }
            Conditions::Scaled => {
                check::each("Kp > 0", "Kp", &cfg.kp, |_, kp| kp, true)?;
                check::each(
                    "2Kζ − ρ − Kp/d > 0",
                    "2·Kzeta − rho − Kp/inertia",
                    &cfg.kzeta,
                    |i, kz| 2.0 * kz - cfg.rho - cfg.kp[i] / cfg.inertia[i],
                    true,
                )
            }
        }
    }

    /// Every gain and physical parameter at most [`PARAM_BOUND`] (1e9) in
    /// magnitude: the stability conditions of SPEC §10 accept, e.g., K1 = 1e300,
    /// which then overflows within two steps.
    fn check_magnitudes(cfg: &Config<N>) -> Result<(), Error> {
        let vectors = [
            ("K1", &cfg.k1),
            ("Kp", &cfg.kp),
            ("Kzeta", &cfg.kzeta),
            ("inertia", &cfg.inertia),
            ("kr", &cfg.kr),
            ("lam1", &cfg.lam1),
            ("tau_max", &cfg.tau_max),
            ("Dd", &cfg.dd),
            ("Cd", &cfg.cd),
            ("Gd", &cfg.gd),
            ("fallback_damping", &cfg.fallback_damping),
        ];
        for (what, v) in vectors {
            check::at_most_each("|value| ≤ 1e9", what, v.as_slice(), PARAM_BOUND)?;
        }
        let scalars = [
            ("mu", cfg.mu),
            ("rho", cfg.rho),
            ("phi", cfg.phi),
            ("kD", cfg.kd),
            ("kC", cfg.kc),
            ("kG", cfg.kg),
            ("kappa", cfg.kappa),
            ("eps", cfg.eps),
            ("gamma", cfg.gamma[0]),
            ("gamma", cfg.gamma[1]),
            ("gamma", cfg.gamma[2]),
            ("sigma", cfg.sigma[0]),
            ("sigma", cfg.sigma[1]),
            ("sigma", cfg.sigma[2]),
        ];
        for (what, x) in scalars {
            check::at_most("|value| ≤ 1e9", what, x, PARAM_BOUND)?;
        }
        check::at_most(
            "0 ≤ delay ≤ 64",
            "delay",
            cfg.delay as f64,
            MAX_DELAY as f64,
        )?;
        check::at_most("Ts ≤ 1 s", "Ts", cfg.ts, 1.0)
    }

    /// As [`new`](Self::new), with a [`WeightBound::Auto`] resolved for the
    /// trajectory `traj` the controller will track (its
    /// [`peak_rates`](Trajectory::peak_rates)).
    pub fn for_trajectory<T: Trajectory<N> + ?Sized>(
        cfg: Config<N>,
        basis: B,
        traj: &T,
    ) -> Result<Self, Error> {
        let cfg = match (cfg.weight_bound, traj.peak_rates()) {
            (WeightBound::Auto, Some(rates)) => cfg.resolve(basis.nodes(), rates),
            (WeightBound::Auto, None) => {
                return Err(Error::Invalid {
                    what: "weight_bound = auto",
                    reason: "the trajectory does not know its peak speed and acceleration: give fixed bounds",
                })
            }
            _ => cfg,
        };
        Self::new(cfg, basis)
    }

    /// The validated configuration.
    pub fn config(&self) -> &Config<N> {
        &self.cfg
    }
    /// The RBF basis.
    pub fn basis(&self) -> &B {
        &self.basis
    }
    /// The actuator model the controller saturates with.
    pub fn saturation(&self) -> &Saturation<N> {
        &self.sat
    }
    /// The target impedance.
    pub fn impedance(&self) -> &TargetImpedance<N> {
        &self.imp
    }
    /// The high-gain observer (output feedback).
    pub fn observer(&self) -> &HighGainObserver<N> {
        &self.obs
    }
    /// The robust term.
    pub fn robust(&self) -> &Robust<N> {
        &self.robust
    }
    /// The learning policy.
    pub fn learning(&self) -> &Learning {
        &self.learning
    }
    /// The instruction set of the weight pass: `simd().name()` is
    /// `"avx2-fma"` or `"portable"` (see [`new`](Self::new)).
    pub fn simd(&self) -> SimdPath {
        self.simd
    }
    /// The same controller with the weight pass on `path`, e.g.
    /// [`SimdPath::portable`]. A fast path can only come from detection
    /// ([`SimdPath::fastest`]), so this never asks for instructions the CPU
    /// lacks.
    pub fn with_simd(mut self, path: SimdPath) -> Self {
        self.simd = path;
        self
    }
    /// Sampling period Ts (s).
    pub fn period(&self) -> f64 {
        self.cfg.ts
    }

    /// The length (in f64) of the buffer a state of this controller needs.
    pub fn buffer_len(&self) -> usize {
        crate::networks::network::Layout::buffer_len(N, self.basis.nodes()).unwrap_or(usize::MAX)
    }

    /// A state at t = 0 in the caller's buffer `buf` (at least
    /// [`buffer_len`](Self::buffer_len) reals, zeroed here): for firmware
    /// without an allocator, or to place the state yourself.
    pub fn state_in<S: AsRef<[f64]> + AsMut<[f64]>>(&self, buf: S) -> Result<State<N, S>, Error> {
        State::new_in(self.basis.nodes(), buf)
    }

    /// A state at t = 0 on the heap (its buffer allocated zeroed, never built
    /// on the stack).
    #[cfg(feature = "alloc")]
    pub fn new_state(&self) -> crate::control::state::HeapState<N> {
        // The buffer is allocated zeroed; `new_in` only fails if it is short.
        State::new_in(self.basis.nodes(), alloc::vec![0.0; self.buffer_len()])
            .unwrap_or_else(|e| unreachable!("the buffer has buffer_len(): {e}"))
    }

    /// Time t_k = k·Ts (s) of `state`'s next step.
    pub fn time<S>(&self, state: &State<N, S>) -> f64 {
        state.k as f64 * self.cfg.ts
    }

    /// The observer's current velocity estimate π2/ε (rad/s) in `state`.
    pub fn velocity_estimate<S>(&self, state: &State<N, S>) -> Vector<N> {
        self.obs.estimate(&state.observer)
    }

    /// This controller driving `state`, as a [`Control`] for a closed loop.
    pub fn bind<'a, S>(&'a self, state: &'a mut State<N, S>) -> Bound<'a, N, B, S> {
        Bound { ctrl: self, state }
    }

    /// One controller step at t_k (SPEC §11, steps 1–5): the measurement `m`
    /// and the commanded setpoint `c` (xc, ẋc, ẍc at t_k; the reference starts
    /// at the first step's) in, the command out; `tau_sat` goes to the
    /// actuators. No allocation.
    ///
    /// **Transactional**: the step first checks its inputs (finite, within the
    /// plausibility limits and their ceilings, the setpoint too), every signal
    /// within [`BOUND`], the reference it would commit within the ceilings,
    /// and that the weights' update keeps them within the bound; only then
    /// does it change the state. A refused step changes nothing the control
    /// law uses (clock, reference, ζ, observer, weights, last command, last
    /// accepted position); it records the refusal: the fault
    /// ([`State::fault`]; with [`FaultPolicy::Latch`] later steps are refused
    /// until [`State::clear_fault`], and the fault that latched is kept), the
    /// fallback as the applied torque ([`State::applied`]) and the measured
    /// position if plausible (a jump anchor). The table is in
    /// `docs/reliability.md`. [`step_or_fallback`](Self::step_or_fallback)
    /// also gives the torque to apply then.
    pub fn step<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> Result<Command<N>, Error> {
        self.step_inner(st, m, c, None)
    }

    /// One step of the torque-level formulations of a Cartesian impedance
    /// (SPEC §19, (19.2)), with `impedance = "external"`: `c` is the
    /// compliant joint reference (q_d, q̇_d, q̈_d), `task` the torque-level
    /// part. With n = `task.share`,
    ///
    /// ```text
    /// τ = n [Kp z2 + r(z2) + d∘z1 + τe] + (1 − n) [Jᵀ(K̃e + B(ṗ_c − J v)) + Π (d∘z1_c + Kp z2_c + r(z2_c))]
    ///     + Kp ζ + ŴD S α̇ + ŴC S α + ŴG S
    /// ```
    ///
    /// (the z1 terms, τe and the networks for the learning laws only; d the
    /// inertia scales of SPEC (10.2)), with the regressors α = n α1 + (1 −
    /// n) q̇_c, α̇ = q̈_c + n (α̇1 − ẍd) and the input n [q; v] + (1 − n)
    /// [q_c; q̇_c], where z1_c, z2_c are (6), (8) on the commanded reference
    /// and Π is (19.3); the networks learn from the paper's z2 on the
    /// compliant reference. With n = 1 it is [`step`](Self::step) (the same
    /// result); transactional as [`step`](Self::step).
    pub fn step_task<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
        task: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        self.step_inner(st, m, c, Some(task))
    }

    /// [`step`](Self::step) or [`step_task`](Self::step_task): the step, and
    /// on a refusal its record.
    fn step_inner<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
        task: Option<&TaskTorque<N>>,
    ) -> Result<Command<N>, Error> {
        match self.try_step(st, m, c, task) {
            Ok(cmd) => Ok(cmd),
            Err(error) => {
                self.refuse_measured(st, m, error);
                Err(error)
            }
        }
    }

    /// [`step`](Self::step), and the torque to apply whatever happened: the
    /// step's `tau_sat`, or on an error the configured [`Fallback`] (the last
    /// applied torque held, zero, or joint damping −Kd q̇, saturated), which
    /// is then the applied torque the next step's rate limit starts from.
    pub fn step_or_fallback<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        match self.step(st, m, c) {
            Ok(cmd) => (cmd.tau_sat, Ok(cmd)),
            Err(e) => (st.applied, Err(e)),
        }
    }

    /// A step call a front refused before it reached [`step`](Self::step)
    /// (an argument of the wrong shape or type, a missing measurement):
    /// recorded as a refused step is, with `error` as its fault, and the
    /// fallback returned (damping uses the last velocity the controller used).
    /// So every refusal latches, whichever front saw it first.
    pub fn refuse<S>(&self, st: &mut State<N, S>, error: Error) -> Vector<N> {
        self.record(st, None, error);
        st.applied
    }

    /// A step refused before it reached [`step`](Self::step) by a caller
    /// that has its measurement `m` (a Cartesian outer loop that refused its
    /// target or wrench, SPEC §16): recorded exactly as a refused step is
    /// (the fault, the fallback as the applied torque, with damping from the
    /// measured q̇ if usable, and q as the last measured position if
    /// plausible), and the fallback returned.
    pub fn refuse_measured<S>(
        &self,
        st: &mut State<N, S>,
        m: &Measurement<N>,
        error: Error,
    ) -> Vector<N> {
        if self.cfg.limits.plausible_position(&m.x) {
            st.q_seen = m.x;
        }
        self.record(st, m.dx.as_ref(), error);
        st.applied
    }

    /// Record a refused step: the fault (a latched one is kept), and the
    /// fallback as the applied torque.
    fn record<S>(&self, st: &mut State<N, S>, dx: Option<&Vector<N>>, error: Error) {
        let latched = self.cfg.fault_policy == FaultPolicy::Latch && st.fault.is_some();
        if !latched {
            st.fault = Some(Fault { error, step: st.k });
        }
        st.applied = self.fallback_with(st, dx);
    }

    /// The configured fallback torque (N m, saturated) for `state` given the
    /// measurement `m`: for hold, the torque last applied; for damping, its
    /// velocity if finite and within `dq_max`, else the last velocity the
    /// controller used.
    pub fn fallback<S>(&self, st: &State<N, S>, m: &Measurement<N>) -> Vector<N> {
        self.fallback_with(st, m.dx.as_ref())
    }

    /// [`fallback`](Self::fallback) with the measured velocity `dx`, if any.
    fn fallback_with<S>(&self, st: &State<N, S>, dx: Option<&Vector<N>>) -> Vector<N> {
        let tau = match self.cfg.fallback {
            Fallback::Hold => st.applied,
            Fallback::Zero => Vector::zeros(),
            Fallback::Damping => {
                let bound = self.cfg.limits.velocity();
                let usable = |v: &Vector<N>| {
                    v.iter()
                        .zip(bound.iter())
                        .all(|(x, l)| x.is_finite() && x.abs() <= *l)
                };
                let v = match dx {
                    Some(dx) if usable(dx) => *dx,
                    _ => st.last.v,
                };
                -self.cfg.fallback_damping.component_mul(&v)
            }
        };
        self.sat.apply(&tau)
    }

    /// Restore into `st` a snapshot written by [`State::save`], checked as
    /// [`State::load`] checks it and against this controller: its basis, the
    /// applied and last torques within τmax, the weight norms within the
    /// projection bounds. A state this controller's step could never have
    /// left is refused; on an error `st` is as before.
    pub fn restore<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        data: &[f64],
    ) -> Result<(), Error> {
        self.check_nodes(st)?;
        let snap = st.check_snapshot(data)?;
        let tau_max = self.sat.limits();
        check::within_each(
            "applied torque",
            snap.applied.as_slice(),
            tau_max.as_slice(),
        )?;
        check::within_each("tau_sat", snap.last.tau_sat.as_slice(), tau_max.as_slice())?;
        self.check_projection(&snap.exact)?;
        st.commit(&snap);
        Ok(())
    }

    /// Replace the weights of `st` (a warm start), checked as
    /// [`State::load_weights`] checks them and against the projection bounds.
    pub fn load_weights<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        w: &crate::networks::network::Weights<'_, N>,
    ) -> Result<(), Error> {
        self.check_nodes(st)?;
        w.check_finite()?;
        self.check_projection(&w.norms())?;
        st.load_weights(w)
    }

    /// Weight norms within the projection bounds (to rounding), if any.
    fn check_projection(&self, norms: &[f64; 3]) -> Result<(), Error> {
        if let Some(bound) = self.learning.bound() {
            for ((n, b), what) in
                norms
                    .iter()
                    .zip(bound)
                    .zip(["‖weights.D‖", "‖weights.C‖", "‖weights.G‖"])
            {
                if n.is_nan() || *n > b * (1.0 + 1e-9) {
                    return Err(Error::OutOfRange {
                        what,
                        index: None,
                        value: *n,
                        limit: b,
                    });
                }
            }
        }
        Ok(())
    }

    /// The state made for this basis.
    fn check_nodes<S: AsRef<[f64]> + AsMut<[f64]>>(&self, st: &State<N, S>) -> Result<(), Error> {
        if st.nodes() != self.basis.nodes() {
            return Err(Error::Invalid {
                what: "state",
                reason: "was made for a basis with another number of nodes",
            });
        }
        Ok(())
    }

    /// The step itself: checks, then stages on local copies, then the commit.
    fn try_step<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
        task: Option<&TaskTorque<N>>,
    ) -> Result<Command<N>, Error> {
        if let (FaultPolicy::Latch, Some(f)) = (self.cfg.fault_policy, st.fault) {
            return Err(Error::Faulted {
                reason: f.error.kind(),
            });
        }
        self.check(st, m, c)?;
        // Staged on copies: the observer takes in the measurement, the
        // reference starts at the first step's setpoint.
        let mut staged = Staged {
            observer: st.observer,
            reference: match (st.k, self.cfg.impedance) {
                (0, _) | (_, ImpedanceMode::External) => Reference::start(c),
                (_, ImpedanceMode::Joint) => st.reference,
            },
        };
        let v = self.velocity(st.k, &mut staged.observer, m)?;
        // (9.2), SPEC §9: the lead extrapolates the commanded motion, never
        // the compliance that this sample's wrench accelerates.
        let planned = match task {
            Some(t) if t.share < 1.0 => t.commanded.ddx,
            _ => c.ddx,
        };
        let e = self.errors_along(&staged.reference, c, m, &v, &planned);
        self.check_bounded(st, &e, &v)?;
        let task = match task {
            // n = 1 is the admittance law itself, bit for bit.
            Some(t) if t.share < 1.0 => Some(self.task_terms(t, m, &v)?),
            Some(t) => {
                Self::check_share(t.share)?;
                None
            }
            None => None,
        };
        if let Some(t) = &task {
            // The commanded errors within BOUND, and the weights within it
            // after the update with the blended regressors (19.2).
            for (what, x) in [
                ("z1_c", &t.errors.z1),
                ("alpha1_c", &t.errors.alpha1),
                ("z2_c", &t.errors.z2),
                ("dalpha1_c", &t.errors.dalpha1),
            ] {
                check::within(what, x.as_slice(), BOUND)?;
            }
            if self.cfg.law.learns() {
                self.learning.check_bounded(
                    &st.norms,
                    &t.signals(&e, &self.cfg.inertia),
                    self.basis.nodes(),
                )?;
            }
        }
        // The reference this step would commit, within the ceilings.
        let mut next = staged.reference;
        next.advance(&e.ddxd, self.cfg.ts);
        self.cfg.limits.check_reference(&next)?;
        // Every check has passed: from here on the state changes, and with
        // every signal and weight within BOUND nothing below can overflow.
        let cmd = self.command(st, m, c, &e, &v, &staged.reference, task.as_ref())?;
        staged.reference = next;
        self.advance(st, staged, m, &e, &cmd);
        Ok(cmd)
    }

    /// Every signal of the step and ζ within [`BOUND`], and the weights
    /// within it after this step's update ([`Learning::check_bounded`]).
    fn check_bounded<S>(
        &self,
        st: &State<N, S>,
        e: &Errors<N>,
        v: &Vector<N>,
    ) -> Result<(), Error> {
        for (what, x) in [
            ("v", v),
            ("z1", &e.z1),
            ("alpha1", &e.alpha1),
            ("z2", &e.z2),
            ("dalpha1", &e.dalpha1),
            ("zeta", &st.zeta),
        ] {
            check::within(what, x.as_slice(), BOUND)?;
        }
        if self.cfg.law.learns() {
            self.learning.check_bounded(
                &st.norms,
                &e.signals_scaled(&self.cfg.inertia),
                self.basis.nodes(),
            )?;
        }
        Ok(())
    }

    /// Stages "robust term", "networks", "saturation" and "learning": the
    /// command of the step (SPEC §7), the rate limit and the saturation, and
    /// the weights' update.
    #[allow(clippy::too_many_arguments)]
    fn command<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
        e: &Errors<N>,
        v: &Vector<N>,
        reference: &Reference<N>,
        task: Option<&Task<N>>,
    ) -> Result<Command<N>, Error> {
        let learns = self.cfg.law.learns();
        let d = &self.cfg.inertia;
        let (sig, mut tau) = match task {
            None => (e.signals_scaled(d), self.feedback(e, &st.zeta)),
            Some(t) => {
                // (19.2): the admittance's share and the torque-level part.
                let n = t.share;
                let mut adm = self.cfg.kp.component_mul(&e.z2)
                    + self.robust.eval(&e.z2, &e.alpha1, &e.dalpha1);
                if learns {
                    adm += e.z1.component_mul(d) + m.tau_e;
                }
                let tau = n * adm + (1.0 - n) * t.torque + self.cfg.kp.component_mul(&st.zeta);
                (t.signals(e, d), tau)
            }
        };
        let w_norms = if learns {
            let before = st.norms;
            if task.is_none() {
                // (14), (35) with +z1 (erratum, SPEC §7), weighted d∘z1 (SPEC (10.2)).
                tau += e.z1.component_mul(d) + self.networks(st, &m.x, v, &sig) + m.tau_e;
            } else {
                let (x, v) = task.map_or((m.x, *v), |t| t.input(&m.x, v));
                tau += self.networks(st, &x, &v, &sig);
            }
            before
        } else {
            [0.0; 3]
        };
        // (20.10): the nominal model's gravity at the measured position.
        #[cfg(feature = "alloc")]
        if let Some(f) = &self.feedforward {
            tau += f.torque(&m.x);
        }
        if tau.iter().any(|t| !t.is_finite()) {
            // Unreachable when the checks hold (SPEC §14); kept so that a
            // non-finite torque is never returned, whatever the cause.
            return Err(Error::Diverged { what: "tau" });
        }
        // The rate limit starts from the torque last applied (a fallback too).
        let limited = self.cfg.limits.rate_limit(&tau, &st.applied);
        let tau_sat = self.sat.apply(&limited);
        let dtau = tau_sat - tau;
        if learns {
            self.learn(st, &sig, &dtau);
        }
        Ok(Command {
            tau_sat,
            tau,
            dtau,
            z1: e.z1,
            z2: e.z2,
            xc: task.map_or(c.x, |t| t.commanded.x),
            xd: reference.xd,
            v: *v,
            zeta: st.zeta,
            w_norms,
        })
    }

    /// Stage "advance", SPEC §11 step 5: ζ, the reference (`staged` holds it
    /// advanced already), the observer and the clock to t_{k+1}, from this
    /// step's values only; the commit.
    fn advance<S>(
        &self,
        st: &mut State<N, S>,
        mut staged: Staged<N>,
        m: &Measurement<N>,
        e: &Errors<N>,
        cmd: &Command<N>,
    ) {
        let ts = self.cfg.ts;
        self.aux.advance(&mut st.zeta, &e.z2, &cmd.dtau, ts);
        if self.cfg.law == Law::OutputFeedback {
            self.obs.finish(&mut staged.observer, &m.x);
        }
        st.reference = staged.reference;
        st.observer = staged.observer;
        st.q_prev = m.x;
        st.q_seen = m.x;
        st.applied = cmd.tau_sat;
        st.k += 1;
        st.last = *cmd;
    }

    /// Inputs finite and within the plausibility limits and their ceilings
    /// (the setpoint too), and the state made for this basis.
    fn check<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &State<N, S>,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> Result<(), Error> {
        self.check_nodes(st)?;
        for (what, v) in [
            ("x", &m.x),
            ("tau_e", &m.tau_e),
            ("xc", &c.x),
            ("dxc", &c.dx),
            ("ddxc", &c.ddx),
        ] {
            check::finite_slice(what, v.as_slice())?;
        }
        if let (Some(dx), Law::Pd | Law::StateFeedback) = (&m.dx, self.cfg.law) {
            check::finite_slice("dx", dx.as_slice())?;
        }
        let anchors = (st.k > 0).then_some([&st.q_prev, &st.q_seen]);
        let m = match self.cfg.law {
            // Output feedback ignores a measured velocity: so do its limits.
            Law::OutputFeedback => &Measurement { dx: None, ..*m },
            Law::Pd | Law::StateFeedback => m,
        };
        self.cfg.limits.check(m, anchors)?;
        self.cfg.limits.check_setpoint(c)
    }

    /// Stage "velocity source", SPEC §11 step 2: the measured ẋ (PD, state
    /// feedback) or the observer's estimate at t_k (output feedback), which
    /// takes in the measurement (on the caller's copy of the observer state).
    fn velocity(
        &self,
        k: u64,
        observer: &mut ObserverState<N>,
        m: &Measurement<N>,
    ) -> Result<Vector<N>, Error> {
        match self.cfg.law {
            Law::OutputFeedback => {
                let first = k == 0;
                if first && self.cfg.observer_init == ObserverInit::FirstMeasurement {
                    observer.pi1 = m.x;
                    observer.pi2 = Vector::zeros();
                }
                self.obs.measure(observer, &m.x, first);
                Ok(self.obs.estimate(observer))
            }
            Law::Pd | Law::StateFeedback => m.dx.ok_or(Error::MissingVelocity),
        }
    }

    /// Stages "reference" and "errors", SPEC §4, §5: ẍd from the target
    /// impedance (ẍc with [`ImpedanceMode::External`], SPEC §16), then z1,
    /// α1, z2, α̇1 with the velocity `v` (rad/s); output feedback with
    /// `observer_lead` compares with α1 the observer's lag back, (9.1), along
    /// the setpoint's acceleration ẍc, (9.2), SPEC §9.
    pub fn errors(
        &self,
        r: &Reference<N>,
        c: &Setpoint<N>,
        m: &Measurement<N>,
        v: &Vector<N>,
    ) -> Errors<N> {
        self.errors_along(r, c, m, v, &c.ddx)
    }

    /// [`errors`](Self::errors) with the lead of (9.1) along the commanded
    /// acceleration `planned` (rad/s²), (9.2): α1 − L (ẍc + K1 (ẋd − v)).
    fn errors_along(
        &self,
        r: &Reference<N>,
        c: &Setpoint<N>,
        m: &Measurement<N>,
        v: &Vector<N>,
        planned: &Vector<N>,
    ) -> Errors<N> {
        let ddxd = match self.cfg.impedance {
            ImpedanceMode::Joint => self.imp.accel(c, r, &m.tau_e),
            ImpedanceMode::External => c.ddx,
        };
        let k1 = &self.cfg.k1;
        let z1 = r.xd - m.x;
        let alpha1 = r.dxd + k1.component_mul(&z1);
        let dalpha1 = ddxd + k1.component_mul(&(r.dxd - v));
        let mut z2 = alpha1 - v;
        if let Some(lag) = &self.lead {
            // (9.1), SPEC §9: the estimate is the velocity L back; so is α1,
            // extrapolated along the commanded acceleration, (9.2): ẍd holds
            // the sampled wrench, which the lead would feed through.
            let along = planned + k1.component_mul(&(r.dxd - v));
            z2 -= lag.component_mul(&along);
        }
        Errors {
            ddxd,
            z1,
            alpha1,
            z2,
            dalpha1,
        }
    }

    /// 0 ≤ n ≤ 1.
    fn check_share(share: f64) -> Result<(), Error> {
        check::finite_slice("share", &[share])?;
        check::nonnegative("0 ≤ admittance_share ≤ 1", "admittance_share", share)?;
        check::at_most("0 ≤ admittance_share ≤ 1", "admittance_share", share, 1.0)
    }

    /// The torque-level part of (19.2) at the velocity `v` (rad/s): the
    /// errors (7), (8) on the commanded reference and
    /// `Jᵀ(K̃e + B(ṗ_c − J v)) + N (z1_c + Kp N z2_c + r(N z2_c))` (N m;
    /// z1_c for the learning laws only). Checks its inputs (finite, within
    /// [`BOUND`], 0 ≤ n ≤ 1).
    fn task_terms(
        &self,
        t: &TaskTorque<N>,
        m: &Measurement<N>,
        v: &Vector<N>,
    ) -> Result<Task<N>, Error> {
        Self::check_share(t.share)?;
        for (what, x) in [
            ("xc", t.commanded.x.as_slice()),
            ("dxc", t.commanded.dx.as_slice()),
            ("ddxc", t.commanded.ddx.as_slice()),
            ("jacobian", t.jacobian.as_slice()),
            ("spring", t.spring.as_slice()),
            ("damping", t.damping.as_slice()),
            ("twist", t.twist.as_slice()),
            ("lambda2", t.lambda2.as_slice()),
        ] {
            check::finite_slice(what, x)?;
            check::within(what, x, BOUND)?;
        }
        let errors = self.errors(&Reference::start(&t.commanded), &t.commanded, m, v);
        let j = &t.jacobian;
        let force = t.force(v);
        // (19.3) the joint law's feedback without its task part:
        // Π τ = τ − Jᵀ (J Kp⁻¹ Jᵀ + k̄ Λ²)⁻¹ J Kp⁻¹ τ, so Π Kp = Kp − Jᵀ Λ_K J ≼ Kp.
        let null = t.null_space(&self.cfg.kp);
        let mut inner = self.cfg.kp.component_mul(&errors.z2)
            + self
                .robust
                .eval(&errors.z2, &errors.alpha1, &errors.dalpha1);
        if self.cfg.law.learns() {
            inner += errors.z1.component_mul(&self.cfg.inertia);
        }
        let torque = j.transpose() * force + null.apply(&inner);
        check::within("tau_task", torque.as_slice(), BOUND)?;
        Ok(Task {
            errors,
            torque,
            share: t.share,
            commanded: t.commanded,
        })
    }

    /// Stage "robust term" with the feedback it adds to: `Kp (z2 + ζ) + r(z2)`
    /// (N m), SPEC §7.
    pub fn feedback(&self, e: &Errors<N>, zeta: &Vector<N>) -> Vector<N> {
        self.cfg.kp.component_mul(&(e.z2 + zeta)) + self.robust.eval(&e.z2, &e.alpha1, &e.dalpha1)
    }

    /// Stages "basis" and "networks": S(Z) at Z = [x; v; α1; α̇1] into the
    /// state, then the networks' output (and, for the printed law, their
    /// update in the same pass; see [`Learning::output`]).
    fn networks<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        x: &Vector<N>,
        v: &Vector<N>,
        sig: &Signals<N>,
    ) -> Vector<N> {
        let mut norms = st.norms;
        let (s, mut w) = st.parts();
        self.simd
            .eval_basis(&self.basis, &[*x, *v, sig.alpha1, sig.dalpha1], s);
        let out = self.learning.output(self.simd, &mut w, s, sig, &mut norms);
        st.norms = norms;
        out
    }

    /// Stage "learning", after saturation: the deferred update of the
    /// hardened policies ([`Learning::learn`]).
    fn learn<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        sig: &Signals<N>,
        dtau: &Vector<N>,
    ) {
        let mut norms = st.norms;
        let (s, mut w) = st.parts();
        self.learning
            .learn(self.simd, &mut w, s, sig, dtau, &mut norms);
        st.norms = norms;
    }
}

/// A [`Controller`] bound to a [`State`]: the [`Control`] a closed loop drives
/// ([`Controller::bind`]).
#[derive(Debug)]
pub struct Bound<'a, const N: usize, B, S> {
    ctrl: &'a Controller<N, B>,
    state: &'a mut State<N, S>,
}

impl<const N: usize, B: Basis<N>, S: AsRef<[f64]> + AsMut<[f64]>> Control<N>
    for Bound<'_, N, B, S>
{
    fn period(&self) -> f64 {
        self.ctrl.period()
    }
    fn target(&self) -> &TargetImpedance<N> {
        self.ctrl.impedance()
    }
    fn step(&mut self, m: &Measurement<N>, c: &Setpoint<N>) -> Result<Command<N>, Error> {
        self.ctrl.step(self.state, m, c)
    }
    fn step_or_fallback(
        &mut self,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        self.ctrl.step_or_fallback(self.state, m, c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::state::HeapState;
    use crate::networks::learning::{LearningStep, SaturationLearning};
    use crate::trajectory::Sinusoid;

    fn measurement() -> Measurement<2> {
        Measurement {
            x: Vector::<2>::new(0.15, 0.25),
            dx: Some(Vector::<2>::new(0.4, -0.3)),
            tau_e: Vector::<2>::zeros(),
        }
    }

    /// The circle's setpoint at the state's next step.
    fn setpoint(c: &Controller<2>, st: &HeapState<2>) -> Setpoint<2> {
        Sinusoid::paper().sample(c.time(st))
    }

    /// Change of the network output per unit z2 made by one learning step,
    /// at that step's basis: the per-step learning gain (N m per rad/s).
    fn per_step_gain(cfg: Config<2>) -> Vector<2> {
        let c = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).unwrap();
        let mut st = c.new_state();
        let m = measurement();
        let before: Vec<f64> = (0..10).flat_map(|i| row(&st, i)).collect();
        let sp = setpoint(&c, &st);
        let cmd = c.step(&mut st, &m, &sp).unwrap();
        let s = st.basis().to_vec();
        let e = c.errors(
            &Reference::start(&Sinusoid::paper().sample(0.0)),
            &Sinusoid::paper().sample(0.0),
            &m,
            &m.dx.unwrap(),
        );
        let old = crate::networks::network::Weights::<2>::from_rows(&before, 256).unwrap();
        let out = |w: &crate::networks::network::Weights<'_, 2>| {
            w.output(c.simd(), &s, &e.dalpha1, &e.alpha1)
        };
        let delta = out(&st.weights()) - out(&old);
        delta.component_div(&cmd.z2)
    }

    fn row(st: &HeapState<2>, i: usize) -> Vec<f64> {
        let w = st.weights();
        match i {
            0..=3 => w.d(i / 2, i % 2).to_vec(),
            4..=7 => w.c((i - 4) / 2, i % 2).to_vec(),
            _ => w.g(i - 8).to_vec(),
        }
    }

    #[test]
    fn the_unified_regressors_do_not_carry_the_compliant_acceleration() {
        // (19.2): ẍd of the compliant reference holds this sample's wrench
        // (J⁺F_e/M_d); the regressor D̂ multiplies must not, or the learnt
        // inertia closes the admittance's algebraic loop through the contact.
        let commanded = Setpoint {
            x: Vector::<2>::new(0.1, 0.2),
            dx: Vector::<2>::new(0.3, -0.1),
            ddx: Vector::<2>::new(-2.0, 1.5),
        };
        let task = Task {
            errors: Errors {
                ddxd: Vector::zeros(),
                z1: Vector::zeros(),
                alpha1: Vector::zeros(),
                z2: Vector::zeros(),
                dalpha1: Vector::zeros(),
            },
            torque: Vector::zeros(),
            share: 0.3,
            commanded,
        };
        let errors = |ddxd: Vector<2>| Errors {
            ddxd,
            z1: Vector::<2>::new(1e-3, -2e-3),
            alpha1: Vector::<2>::new(0.25, -0.05),
            z2: Vector::<2>::new(0.01, 0.02),
            dalpha1: ddxd + Vector::<2>::new(0.5, -0.25), // ẍd + K1 (ẋd − v)
        };
        let d = Vector::<2>::new(2.0, 0.5);
        let quiet = task.signals(&errors(Vector::<2>::new(0.1, -0.2)), &d);
        let pushed = task.signals(&errors(Vector::<2>::new(50.0, -80.0)), &d);
        assert_eq!(quiet.dalpha1, pushed.dalpha1);
        // q̈_c + n K1 (ẋd − v): the commanded acceleration and the share's feedback.
        let expected = commanded.ddx + 0.3 * Vector::<2>::new(0.5, -0.25);
        assert!((quiet.dalpha1 - expected).amax() < 1e-15, "{quiet:?}");
        assert_eq!(quiet.z2, Vector::<2>::new(0.02, 0.01));
    }

    /// A feedforward of a constant torque, for (20.10)'s test.
    #[derive(Debug)]
    struct Constant(Vector<2>);

    impl Feedforward<2> for Constant {
        fn torque(&self, _q: &Vector<2>) -> Vector<2> {
            self.0
        }
    }

    #[test]
    fn the_feedforward_adds_to_the_law_before_the_saturation() {
        // SPEC (20.10): τ = τ_law + τ_ff; sat(τ) of the sum; Δτ of ζ from the sum.
        let plain = Controller::paper(Law::StateFeedback);
        let ff = Vector::<2>::new(3.0, -40.0); // the second beyond τmax = 15 N m
        let fed = plain
            .clone()
            .with_feedforward(alloc::sync::Arc::new(Constant(ff)));
        assert!(plain.feedforward().is_none());
        assert!(fed.feedforward().is_some());
        let (mut a, mut b) = (plain.new_state(), fed.new_state());
        let m = measurement();
        let (sa, sb) = (setpoint(&plain, &a), setpoint(&fed, &b));
        let without = plain.step(&mut a, &m, &sa).unwrap();
        let with = fed.step(&mut b, &m, &sb).unwrap();
        assert_eq!(with.tau, without.tau + ff);
        assert_eq!(with.tau_sat, fed.saturation().apply(&with.tau));
        assert_eq!(with.dtau, with.tau_sat - with.tau);
        assert!(with.tau_sat[1] == -15.0 && with.dtau[1] > 0.0, "{with:?}");
    }

    #[test]
    fn printed_euler_gain_exceeds_kp_at_1ms_normalized_stays_below_kappa_kp() {
        let mut printed = Config::paper(Law::StateFeedback);
        printed.ts = 1e-3;
        let g = per_step_gain(printed);
        // The Jury condition for explicit-Euler learning is g < Kp = 10.
        assert!(g.min() > 10.0, "printed per-step gain {g}");
        let mut normalized = printed;
        normalized.learning_step = LearningStep::Normalized;
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
        let g_printed = per_step_gain(printed);
        let mut normalized = printed;
        normalized.learning_step = LearningStep::Normalized;
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
        let c = Controller::new(cfg, Grid::paper()).unwrap();
        let mut st = c.new_state();
        let mut w = vec![0.0; 10 * 256];
        w[8 * 256..].fill(0.01); // ŴG
        st.load_weights(&crate::networks::network::Weights::from_rows(&w, 256).unwrap())
            .unwrap();
        let m = measurement();
        let sp = setpoint(&c, &st);
        let cmd = c.step(&mut st, &m, &sp).unwrap();
        // Joint 1 saturates with learning pushing out: z2 and Δτ of opposite signs.
        assert!(
            cmd.dtau[0] != 0.0 && cmd.z2[0] * cmd.dtau[0] < 0.0,
            "{cmd:?}"
        );
        assert_eq!(cmd.dtau[1], 0.0);
        let decay = 1.0 - c.config().ts * 100.0 * 0.01;
        // Joint 1's rows only leak; joint 2's rows learn.
        let w = st.weights();
        assert!(w.g(0).iter().all(|&v| (v - 0.01 * decay).abs() < 1e-18));
        assert!(w.d(0, 1).iter().all(|&v| v == 0.0));
        assert!(w.g(1).iter().any(|&v| (v - 0.01 * decay).abs() > 1e-12));
    }

    #[test]
    fn projection_keeps_each_network_in_its_ball() {
        let mut cfg = Config::paper(Law::StateFeedback);
        cfg.ts = 1e-3;
        let bound = [1e-3, 2e-3, 3e-3];
        cfg.weight_bound = WeightBound::Fixed(bound);
        let c = Controller::new(cfg, Grid::paper()).unwrap();
        let mut st = c.new_state();
        let m = measurement();
        let mut hit = [false; 3];
        for _ in 0..200 {
            let sp = setpoint(&c, &st);
            c.step(&mut st, &m, &sp).unwrap();
            let n = st.weights().norms();
            for net in 0..3 {
                assert!(n[net] <= bound[net] * (1.0 + 1e-12), "{n:?}");
                hit[net] |= n[net] > 0.999 * bound[net];
            }
            // The cached norms reported next step are the weights' norms.
            let cached = st.weight_norms();
            assert!(
                (cached[0] - n[0]).abs() <= 1e-12 * n[0],
                "{cached:?} vs {n:?}"
            );
        }
        assert_eq!(hit, [true; 3], "every bound was reached");
    }

    #[test]
    fn auto_bounds_need_the_trajectory_and_match_the_documented_values() {
        let e = Controller::new(Config::robot(Law::StateFeedback), Grid::paper()).unwrap_err();
        assert!(e.to_string().contains("Controller::for_trajectory"), "{e}");
        let c = Controller::robot(Law::StateFeedback);
        let b = c.learning().bound().unwrap();
        for (v, e) in b.iter().zip([0.718, 2.255, 1.417]) {
            assert!((v - e).abs() < 1e-3, "{b:?}");
        }
    }

    #[test]
    fn one_description_drives_many_states_and_is_shareable() {
        fn shareable<T: Send + Sync>(_: &T) {}
        let c = Controller::paper(Law::StateFeedback);
        shareable(&c);
        let (mut a, mut b) = (c.new_state(), c.new_state());
        let m = measurement();
        for _ in 0..10 {
            let sp = setpoint(&c, &a);
            let ca = c.step(&mut a, &m, &sp).unwrap();
            let cb = c.step(&mut b, &m, &sp).unwrap();
            assert_eq!(ca, cb);
        }
        // A state of another basis is refused, and left as it was.
        let small = Controller::new(
            Config::new(Law::StateFeedback, Vector::<2>::new(1.0, 1.0)),
            crate::networks::rbf::Centers::uniform(vec![0.0; 8], 1.0).unwrap(),
        )
        .unwrap();
        let sp = setpoint(&c, &a);
        let e = small.step(&mut a, &m, &sp).unwrap_err();
        assert!(e.to_string().contains("another number of nodes"), "{e}");
        assert_eq!(a.steps(), 10);
    }

    #[test]
    fn a_snapshot_restores_a_state_that_continues_bit_identically() {
        for c in [
            Controller::paper(Law::OutputFeedback),
            Controller::robot(Law::StateFeedback),
        ] {
            let m = measurement();
            let circle = Sinusoid::paper();
            let mut a = c.new_state();
            for _ in 0..100 {
                let sp = circle.sample(c.time(&a));
                c.step(&mut a, &m, &sp).unwrap();
            }
            let mut snap = vec![0.0; a.snapshot_len()];
            assert_eq!(a.save(&mut snap).unwrap(), snap.len());
            let mut b = c.new_state();
            b.load(&snap).unwrap();
            for k in 0..50 {
                let x = m.x + Vector::<2>::from_element(1e-3 * k as f64);
                let mk = Measurement { x, ..m };
                let sp = circle.sample(c.time(&a));
                assert_eq!(c.step(&mut a, &mk, &sp), c.step(&mut b, &mk, &sp));
            }
            assert_eq!(a.weight_norms(), b.weight_norms());
            // A corrupt snapshot is refused and changes nothing.
            let before = format!("{:?}", b.weights());
            let last = snap.len() - 1;
            snap[last] = f64::NAN;
            assert!(b.load(&snap).is_err());
            snap[4] = 0.5;
            let e = b.load(&snap).unwrap_err();
            assert!(e.to_string().contains("whole number"), "{e}");
            assert!(b.load(&snap[1..]).is_err());
            assert_eq!(format!("{:?}", b.weights()), before);
        }
    }

    #[test]
    fn external_impedance_tracks_the_setpoint_itself_under_contact() {
        // Joint: the reference yields to τe; external: xd = xc whatever τe.
        let mut cfg = Config::paper(Law::StateFeedback);
        let joint = Controller::new(cfg, Grid::paper()).unwrap();
        cfg.impedance = crate::control::impedance::ImpedanceMode::External;
        let external = Controller::new(cfg, Grid::paper()).unwrap();
        let m = Measurement {
            tau_e: Vector::<2>::new(30.0, -5.0),
            ..measurement()
        };
        let (mut a, mut b) = (joint.new_state(), external.new_state());
        let (mut ca, mut cb) = (Command::zeros(), Command::zeros());
        for _ in 0..100 {
            let sp = setpoint(&joint, &a);
            ca = joint.step(&mut a, &m, &sp).unwrap();
            cb = external.step(&mut b, &m, &sp).unwrap();
            assert_eq!(cb.xd, sp.x);
            assert_eq!(cb.z1, sp.x - m.x);
        }
        assert!((ca.xd - ca.xc).norm() > 1e-4, "{ca:?}");
        assert_ne!(ca.tau, cb.tau);
    }

    /// The mean estimated error ẑ2 over t ∈ [0.1, 0.5) s of output feedback
    /// (robot preset, external impedance: xd = xc) whose measurement follows a
    /// ramp-accelerating setpoint exactly, xc = x0 + ½ a t²: the true z2 is 0.
    fn estimated_error_on_a_parabola(lead: bool) -> (Vector<2>, Vector<2>, Vector<2>) {
        let mut cfg = Config::robot(Law::OutputFeedback);
        cfg.impedance = crate::control::impedance::ImpedanceMode::External;
        cfg.observer_lead = lead;
        let c = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).unwrap();
        let (x0, a) = (Vector::<2>::new(0.1, -0.2), Vector::<2>::new(2.0, -1.5));
        let mut st = c.new_state();
        let (mut sum, mut rows) = (Vector::<2>::zeros(), 0.0);
        for k in 0..500 {
            let t = k as f64 * c.period();
            let sp = Setpoint {
                x: x0 + a * (0.5 * t * t),
                dx: a * t,
                ddx: a,
            };
            let m = Measurement {
                x: sp.x,
                dx: None,
                tau_e: Vector::zeros(),
            };
            let cmd = c.step(&mut st, &m, &sp).unwrap();
            assert_eq!(cmd.z1, Vector::<2>::zeros());
            if k >= 100 {
                sum += cmd.z2;
                rows += 1.0;
            }
        }
        (sum / rows, a, *c.observer().lag())
    }

    /// (9.1), SPEC §9: without the lead the estimated error of exact tracking
    /// is a L (the estimate half a period late: learning would drive the true
    /// z2 to −a L); with it, −K1 a L², second order (K1 L = 0.003 here).
    #[test]
    fn the_lead_removes_the_estimated_errors_bias_on_a_ramp_accelerating_path() {
        let (paper, a, lag) = estimated_error_on_a_parabola(false);
        let (lead, ..) = estimated_error_on_a_parabola(true);
        let k1 = Config::<2>::robot(Law::OutputFeedback).k1;
        assert!((lag[0] / 1e-3 - 0.5263).abs() < 1e-4, "{lag}");
        for i in 0..2 {
            let bias = a[i] * lag[i];
            assert!(
                (paper[i] - bias).abs() < 1e-6 * bias.abs(),
                "joint {i}: {} against a L = {bias}",
                paper[i]
            );
            let second = -k1[i] * a[i] * lag[i] * lag[i];
            assert!(
                (lead[i] - second).abs() < 1e-6 * second.abs(),
                "joint {i}: {} against −K1 a L² = {second}",
                lead[i]
            );
            assert!(lead[i].abs() < 0.02 * paper[i].abs(), "{lead} vs {paper}");
        }
    }

    /// (9.2), SPEC §9: the lead extrapolates the commanded motion, so the
    /// wrench sampled at t_k (in ẍd: τe in the joint impedance, the compliant
    /// reference's acceleration J⁺F/M_d in the torque-level formulations)
    /// does not reach ẑ2 of the same step; it still reaches the torque
    /// (τe, α̇1), so the steps compared are not one and the same.
    #[test]
    fn the_lead_does_not_feed_the_sampled_wrench_through() {
        let steps = |cfg: Config<2>, wrench: f64| {
            let c = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).unwrap();
            let mut st = c.new_state();
            let task = |sp: Setpoint<2>, share: f64| TaskTorque {
                commanded: sp,
                jacobian: nalgebra::SMatrix::<f64, 6, 2>::from_fn(|r, k| {
                    if r < 2 {
                        0.3 + 0.1 * (r + 2 * k) as f64
                    } else {
                        0.0
                    }
                }),
                spring: Vector::<6>::from_element(1.0),
                damping: Vector::<6>::from_element(20.0),
                twist: Vector::zeros(),
                lambda2: Vector::<6>::from_element(1e-4),
                share,
            };
            let mut cmd = None;
            for k in 0..40 {
                let sp = Sinusoid::paper().sample(c.time(&st));
                let x = sp.x + Vector::<2>::new(1e-3, -2e-3) * (k as f64 * 0.1).sin();
                let last = k == 39;
                let w = if last { wrench } else { 0.0 };
                let m = Measurement {
                    x,
                    dx: None,
                    tau_e: Vector::<2>::new(3.0, -2.0) * w,
                };
                // The compliant reference the outer loop hands over: the
                // commanded one, but accelerated by this sample's wrench.
                let compliant = Setpoint {
                    ddx: sp.ddx + Vector::<2>::new(40.0, 25.0) * w,
                    ..sp
                };
                cmd = Some(match cfg.impedance {
                    ImpedanceMode::Joint => c.step(&mut st, &m, &sp),
                    ImpedanceMode::External => c.step_task(&mut st, &m, &compliant, &task(sp, 0.3)),
                });
            }
            cmd.unwrap().unwrap()
        };
        for impedance in [ImpedanceMode::Joint, ImpedanceMode::External] {
            let mut cfg = Config::robot(Law::OutputFeedback);
            cfg.impedance = impedance;
            assert!(cfg.observer_lead);
            let (free, pressed) = (steps(cfg, 0.0), steps(cfg, 1.0));
            assert_eq!(free.z2, pressed.z2, "{impedance:?}");
            assert_ne!(free.tau, pressed.tau, "{impedance:?}");
            // The lead is on: ẑ2 is not the paper's.
            cfg.observer_lead = false;
            assert_ne!(steps(cfg, 1.0).z2, pressed.z2, "{impedance:?}");
        }
    }

    #[test]
    fn the_lead_is_output_feedbacks_only_and_the_papers_is_off() {
        assert!(!Config::<2>::paper(Law::OutputFeedback).observer_lead);
        assert!(Config::<2>::robot(Law::OutputFeedback).observer_lead);
        // State feedback measures the velocity at t_k: no lag, no lead.
        let mut on = Config::robot(Law::StateFeedback);
        on.observer_lead = true;
        let mut off = on;
        off.observer_lead = false;
        let [a, b] = [on, off].map(|cfg| {
            let c = Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).unwrap();
            let mut st = c.new_state();
            let m = measurement();
            (0..20)
                .map(|k| {
                    let sp = Sinusoid::paper().sample(k as f64 * c.period());
                    c.step(&mut st, &m, &sp).unwrap()
                })
                .last()
                .unwrap()
        });
        assert_eq!(a, b);
    }

    #[test]
    fn a_state_in_a_caller_buffer_steps_like_a_heap_state() {
        let c = Controller::paper(Law::OutputFeedback);
        let mut buf = vec![0.0; c.buffer_len()];
        let mut st = c.state_in(&mut buf[..]).unwrap();
        let mut heap = c.new_state();
        let m = measurement();
        for k in 0..5 {
            let sp = Sinusoid::paper().sample(k as f64 * c.period());
            assert_eq!(c.step(&mut st, &m, &sp), c.step(&mut heap, &m, &sp));
        }
        let e = c.state_in(&mut buf[..10]).unwrap_err();
        assert!(e.to_string().contains("buffer_len"), "{e}");
    }
}
