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
use crate::control::coupling::{inertia_times, kp_times, Coupling};
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

mod build;
mod refusal;

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
    /// The inertia-shaped gains, SPEC (18.12) (none: diagonal).
    coupling: Option<Coupling<N>>,
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
    /// as (10.2) (`z2`: Dₛ z2 with the coupled gains of (18.12)). The acceleration regressor takes the commanded q̈_c in place
    /// of the compliant ẍd, which carries this sample's wrench (ẍd ∋ J⁺F_e/M_d):
    /// through D̂ that closed the admittance's algebraic loop with the learnt
    /// inertia's gain, and the unified step rang on a rigid table once D̂ had
    /// learnt (SPEC (19.2)).
    fn signals(&self, e: &Errors<N>, z2: Vector<N>) -> Signals<N> {
        let n = self.share;
        Signals {
            dalpha1: self.commanded.ddx + n * (e.dalpha1 - e.ddxd),
            alpha1: n * e.alpha1 + (1.0 - n) * self.commanded.dx,
            z2,
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

    /// Take over the actuators from a controller that was applying `tau`
    /// (N m) until now (a robot's own, holding the arm where it stands:
    /// libfranka's `tau_J_d` read before the torque loop starts): the first
    /// step's torque rate limit moves from it, and a refused first step
    /// holds it, SPEC (22.4). Without it the first step's rate limit moves
    /// from zero, a step in torque of what held the arm. Only before the first step (refused after it: "take_over: only
    /// before the first step"); `tau` finite and within τmax, each refused
    /// by name. On an error `st` is as before.
    pub fn take_over<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        st: &mut State<N, S>,
        tau: &Vector<N>,
    ) -> Result<(), Error> {
        self.check_nodes(st)?;
        if st.steps() != 0 {
            return Err(Error::Invalid {
                what: "take_over",
                reason: "only before the first step",
            });
        }
        check::finite_slice("torque taken over", tau.as_slice())?;
        check::within_each(
            "torque taken over",
            tau.as_slice(),
            self.sat.limits().as_slice(),
        )?;
        st.applied = *tau;
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
                    &t.signals(&e, self.weighted(&e.z2)),
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
        self.advance(st, &mut staged, m, &e, &cmd);
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
            self.learning
                .check_bounded(&st.norms, &self.joint_signals(e), self.basis.nodes())?;
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
        let (k, cfg) = (self.coupling.as_ref(), &self.cfg);
        let (sig, mut tau) = match task {
            None => (self.joint_signals(e), self.feedback(e, &st.zeta)),
            Some(t) => {
                // (19.2): the admittance's share and the torque-level part.
                let n = t.share;
                let mut adm =
                    kp_times(k, cfg, &e.z2) + self.robust.eval(&e.z2, &e.alpha1, &e.dalpha1);
                if learns {
                    adm += inertia_times(k, cfg, &e.z1) + m.tau_e;
                }
                let tau = n * adm + (1.0 - n) * t.torque + kp_times(k, cfg, &st.zeta);
                (t.signals(e, self.weighted(&e.z2)), tau)
            }
        };
        let w_norms = if learns {
            let before = st.norms;
            if task.is_none() {
                // (14), (35) with +z1 (erratum, SPEC §7), weighted d∘z1 (SPEC (10.2)).
                tau += inertia_times(k, cfg, &e.z1) + self.networks(st, &m.x, v, &sig) + m.tau_e;
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
        staged: &mut Staged<N>,
        m: &Measurement<N>,
        e: &Errors<N>,
        cmd: &Command<N>,
    ) {
        let ts = self.cfg.ts;
        match &self.coupling {
            Some(k) => self.aux.advance_coupled(
                &mut st.zeta,
                &e.z2,
                &cmd.dtau,
                ts,
                k.inertia(),
                k.inertia_inv(),
            ),
            None => self.aux.advance(&mut st.zeta, &e.z2, &cmd.dtau, ts),
        }
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
        let (c, cfg) = (self.coupling.as_ref(), &self.cfg);
        let null = match c {
            Some(c) => t.null_space_of(c.kp_inv()),
            None => t.null_space(&cfg.kp),
        };
        let mut inner = kp_times(c, cfg, &errors.z2)
            + self
                .robust
                .eval(&errors.z2, &errors.alpha1, &errors.dalpha1);
        if self.cfg.law.learns() {
            inner += inertia_times(c, cfg, &errors.z1);
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

    /// Dₛ v: d∘v, or the coupled inertia's product (SPEC (10.2), (18.12)).
    fn weighted(&self, v: &Vector<N>) -> Vector<N> {
        inertia_times(self.coupling.as_ref(), &self.cfg, v)
    }

    /// The joint law's learning signals, with the error Dₛ z2 (SPEC (10.2), (18.12)).
    fn joint_signals(&self, e: &Errors<N>) -> Signals<N> {
        Signals {
            z2: self.weighted(&e.z2),
            ..e.signals()
        }
    }

    /// Stage "robust term" with the feedback it adds to: `Kp (z2 + ζ) + r(z2)`
    /// (N m), SPEC §7.
    pub fn feedback(&self, e: &Errors<N>, zeta: &Vector<N>) -> Vector<N> {
        kp_times(self.coupling.as_ref(), &self.cfg, &(e.z2 + zeta))
            + self.robust.eval(&e.z2, &e.alpha1, &e.dalpha1)
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
mod tests;
