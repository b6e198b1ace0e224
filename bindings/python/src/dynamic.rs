//! The joint controller behind a run-time number of joints: [`JointCore`],
//! the core's run-time [`Controller`](dy::Controller) and
//! [`State`](dy::State), built by the core's one builder
//! ([`dy::Scenario`]) from the schema's parameter items
//! ([`super::items`]); for a typed loop, [`AdaptiveStep`] is the
//! const-generic controller of its N, reached through the core's accessors
//! and [`for_joints`]; its closed loops (on MuJoCo, over
//! [`super::drive`]'s loop, and on the core's rigid bodies) are here,
//! recording into the core's rows and metrics.
//!
//! Nothing here knows Python: the bindings (`controller.rs`, `runs.rs`)
//! convert arrays to slices and errors to exceptions.

use super::items::{apply, injection};
use super::mujoco::{Continued, MujocoSpec, Table};
use adaptimp::control::config::Law;
use adaptimp::control::controller::Controller;
use adaptimp::control::impedance::TargetImpedance;
use adaptimp::control::io::{self, Control, TaskTorque};
use adaptimp::control::state::HeapState;
use adaptimp::dynamic::{self as dy, for_joints, ForJoints};
use adaptimp::error::Error;
use adaptimp::networks::network::Weights;
use adaptimp::networks::rbf::{AnyBasis, Basis as _};
use adaptimp::schema::Preset;
use adaptimp::schema::Scenario;
use adaptimp::sim::disturb::TipPayload;
use adaptimp::sim::environment::{FreeSpace, Wall};
use adaptimp::sim::metrics::MetricsAccumulator;
use adaptimp::sim::model::{Link, PlanarArm};
use adaptimp::sim::plant::RigidBody;
use adaptimp::sim::simulator::run_disturbed_with;
use adaptimp::trajectory::{Setpoint, Sinusoid, Trajectory};
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use core::cell::{Cell, RefCell};
use std::any::Any;
use std::boxed::Box;
use std::vec::Vec;

pub use adaptimp::dynamic::MAX_JOINTS;

pub(crate) use super::drive::{drive_mujoco, Hooks, MujocoRun, OnMujoco, RunError, View};
use super::drive::{metrics_out, Reporting, Watch};
use std::any::TypeId;

pub use super::items::{
    scenario, ArmSpec, CentersSpec, FaultKind, FaultSpec, GravitySpec, Items, Owned, ParamError,
};

pub use adaptimp::dynamic::{Metrics, RowMetrics, Rows};

/// A step's inputs as slices of n values: the measurement, and an external
/// setpoint (xc, ẋc, ẍc) instead of the trajectory's.
pub type Inputs<'a> = (dy::Measurement<'a>, Option<dy::Setpoint<&'a [f64]>>);

/// The quantities of the last step, by name.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Last {
    /// τ.
    Tau,
    /// sat(τ).
    TauSat,
    /// Δτ.
    Dtau,
    /// z1.
    Z1,
    /// xc.
    Xc,
    /// xd.
    Xd,
    /// The velocity used.
    V,
    /// The torque last given to apply: the step's sat(τ), or a fallback.
    Applied,
}

/// The core's joint controller (the paper's laws) of any n ≤ 7, with its
/// own trajectory, and its state.
#[derive(Clone, Debug)]
pub struct JointCore {
    /// The controller.
    pub ctrl: dy::Controller,
    /// Its state.
    pub state: dy::State,
}

/// The error of a controller and a state of other numbers of joints than a
/// typed caller's (not reachable: both are made together).
pub(crate) const OTHER_N: Error = Error::Invalid {
    what: "controller",
    reason: "has another number of joints than the chain",
};

/// Build the controller `law` for n joints from `preset` and `items` by the
/// core's one builder ([`dy::Scenario::controller`], which C's builds by
/// too), with the paper's grid (n ≤ 3), the rule's default centres beyond
/// (SPEC §18), or `centers`, feeding forward `gravity`'s G(q) if given
/// (SPEC (20.10)).
pub fn build(
    n: usize,
    preset: Preset,
    law: Law,
    items: &Items,
    centers: Option<&CentersSpec>,
    gravity: Option<&GravitySpec>,
) -> Result<JointCore, ParamError> {
    let mut s = dy::Scenario::new(n, preset, law)?;
    apply(items, |name, v| s.set(name, v).map(|_| ()))?;
    if let Some(c) = centers {
        s.basis(dy::Basis::Centres(dy::Centres {
            rows: c.centers.clone(),
            widths2: Some(c.widths2.clone()),
        }));
    }
    if let Some(g) = gravity {
        s.feedforward(dy::Dynamics::new(&g.joints, &g.inertials, g.gravity)?);
    }
    let ctrl = s.controller()?;
    let state = ctrl.new_state();
    Ok(JointCore { ctrl, state })
}

impl JointCore {
    /// Joints n.
    pub fn n(&self) -> usize {
        self.ctrl.n()
    }
    /// RBF nodes L.
    pub fn nodes(&self) -> usize {
        self.ctrl.nodes()
    }
    /// The law.
    pub fn law(&self) -> Law {
        self.ctrl.law()
    }
    /// Ts (s).
    pub fn ts(&self) -> f64 {
        self.ctrl.period()
    }
    /// t_k (s) of the next step.
    pub fn time(&self) -> f64 {
        self.ctrl.time(&self.state)
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.state.steps()
    }
    /// Back to t = 0.
    pub fn reset(&mut self) {
        self.state.reset()
    }

    /// One step; writes sat(τ) into `out` (n values).
    pub fn step(&mut self, inputs: &Inputs<'_>, out: &mut [f64]) -> Result<(), Error> {
        let n = self.n();
        let on = OnceTyped {
            core: self,
            inputs,
            out,
        };
        for_joints(n, on).unwrap_or(Err(OTHER_N))
    }

    /// One step that always writes a torque to apply into `out`.
    pub fn step_or_fallback(&mut self, (m, c): &Inputs<'_>, out: &mut [f64]) -> Result<(), Error> {
        let (tau, result) = self.ctrl.step_or_fallback(&mut self.state, m, c.as_ref());
        if let Some(t) = tau {
            out.copy_from_slice(&t);
        }
        result.map(|_| ())
    }

    /// A step call refused by the front (its arguments' shapes or types):
    /// recorded as a refused step ([`dy::Controller::refuse`]).
    pub fn refuse(&mut self, error: Error) {
        self.ctrl.refuse(&mut self.state, error);
    }

    /// A quantity of the last step.
    pub fn last(&self, what: Last) -> dy::Joints {
        let c = self.state.last();
        match what {
            Last::Tau => c.tau,
            Last::TauSat => c.tau_sat,
            Last::Dtau => c.dtau,
            Last::Z1 => c.z1,
            Last::Xc => c.xc,
            Last::Xd => c.xd,
            Last::V => c.v,
            Last::Applied => self.state.applied(),
        }
    }

    /// The recorded fault: (error, step).
    pub fn fault(&self) -> Option<(Error, u64)> {
        self.state.fault().map(|f| (f.error, f.step))
    }

    /// The whole state as reals ([`State::save`](adaptimp::control::state::State::save)).
    pub fn snapshot(&self) -> Vec<f64> {
        let mut out = std::vec![0.0; self.state.snapshot_len()];
        // The buffer has exactly the length save needs.
        let _ = self.state.save(&mut out);
        out
    }

    /// The K steps of `rows` (the core's [`dy::Controller::replay`]); sat(τ)
    /// into `out` (K × n), the hooks told every [`dy::HOOK_EVERY`] rows and
    /// after the last, this controller readable then. Errors name the row.
    pub fn replay(
        &mut self,
        rows: &dy::Replay<'_>,
        out: &mut [f64],
        hooks: &mut dyn Hooks,
    ) -> Result<(), RunError> {
        let JointCore { ctrl, state } = self;
        let seen = |done, total, state: &dy::State| {
            hooks.report(
                done,
                total,
                &Seen {
                    ctrl: &*ctrl,
                    state,
                },
            )
        };
        Ok(ctrl.replay(state, rows, out, seen)?)
    }

    /// The closed loop of SPEC §11 against `arm` with the scenario of
    /// `items` (its run and wall parameters), from t = 0 (reset first) with
    /// the initial `weights` (rows as for [`dy::Controller::load_weights`]).
    pub fn simulate(
        &mut self,
        arm: &ArmSpec,
        items: &Items,
        weights: Option<&[f64]>,
        fault: Option<&FaultSpec>,
        every: u64,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError> {
        let n = self.n();
        let on = OnArm {
            core: self,
            arm,
            items,
            weights,
            fault,
            every,
            hooks,
        };
        for_joints(n, on).unwrap_or(Err(RunError::Core(OTHER_N, None)))
    }

    /// The closed loop on MuJoCo (`sim` as `spec` describes it) from the
    /// controller's current state (not reset: a used controller goes on),
    /// with the disturbances of `run.items` (SPEC §17; payload and jitter are
    /// refused: the first is a change of the model, the second of its
    /// timestep). Records every `run.every`-th row with the end effector.
    pub fn simulate_mujoco(
        &mut self,
        sim: &mut Sim,
        spec: &MujocoSpec,
        run: &MujocoRun<'_>,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError> {
        let n = self.n();
        let on = OnMujocoRun {
            core: self,
            sim,
            spec,
            run,
            hooks,
        };
        for_joints(n, on).unwrap_or(Err(RunError::Core(OTHER_N, None)))
    }
}

/// The copy of a joint controller as the bindings keep it.
impl View for JointCore {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        (part == TypeId::of::<Box<JointCore>>())
            .then(|| Box::new(Box::new(self.clone())) as Box<dyn Any + Send>)
    }
}

/// A replay's controller between two rows, as a [`View`]: a copy made when
/// asked for.
struct Seen<'a> {
    ctrl: &'a dy::Controller,
    state: &'a dy::State,
}

impl View for Seen<'_> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        (part == TypeId::of::<Box<JointCore>>()).then(|| {
            let copy = JointCore {
                ctrl: self.ctrl.clone(),
                state: self.state.clone(),
            };
            Box::new(Box::new(copy)) as Box<dyn Any + Send>
        })
    }
}

/// [`JointCore`] as its const-generic controller of N joints, with its own
/// trajectory and its state, for a typed loop; `whole`: the run-time
/// controller, of which a run copies the controller at this state for the
/// Python code it calls ([`View`]: made only when asked for).
pub struct AdaptiveStep<'a, const N: usize> {
    /// The controller.
    pub ctrl: &'a Controller<N, AnyBasis<N>>,
    /// The trajectory it tracks by default.
    pub traj: &'a Sinusoid<N>,
    /// Its state.
    pub state: &'a mut HeapState<N>,
    whole: &'a dy::Controller,
}

impl<'a, const N: usize> AdaptiveStep<'a, N> {
    /// `core` for N joints (an error if it was made for another n).
    pub fn of(core: &'a mut JointCore) -> Result<Self, Error> {
        let JointCore { ctrl: whole, state } = core;
        let (ctrl, traj) = whole.typed::<N>().ok_or(OTHER_N)?;
        let state = state.typed_mut::<N>().ok_or(OTHER_N)?;
        Ok(Self {
            ctrl,
            traj,
            state,
            whole,
        })
    }

    /// One step of the torque-level formulations (SPEC §19).
    pub fn step_task(
        &mut self,
        m: &io::Measurement<N>,
        c: &Setpoint<N>,
        t: &TaskTorque<N>,
    ) -> Result<io::Command<N>, Error> {
        self.ctrl.step_task(self.state, m, c, t)
    }

    /// Back to t = 0, and the initial `weights` if given (rows as for
    /// [`dy::Controller::load_weights`]).
    pub fn restart(&mut self, weights: Option<&[f64]>) -> Result<(), Error> {
        self.state.reset();
        if let Some(w) = weights {
            let w = Weights::<N>::from_rows(w, self.ctrl.basis().nodes())?;
            self.ctrl.load_weights(self.state, &w)?;
        }
        Ok(())
    }
}

impl<const N: usize> Control<N> for AdaptiveStep<'_, N> {
    fn period(&self) -> f64 {
        self.ctrl.period()
    }
    fn target(&self) -> &TargetImpedance<N> {
        self.ctrl.impedance()
    }
    fn step(&mut self, m: &io::Measurement<N>, c: &Setpoint<N>) -> Result<io::Command<N>, Error> {
        self.ctrl.step(self.state, m, c)
    }
    fn step_or_fallback(
        &mut self,
        m: &io::Measurement<N>,
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<io::Command<N>, Error>) {
        self.ctrl.step_or_fallback(self.state, m, c)
    }
}

/// The copy of the joint controller as the bindings keep it: the controller
/// with the state as it is now.
impl<const N: usize> View for AdaptiveStep<'_, N> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        (part == TypeId::of::<Box<JointCore>>()).then(|| {
            let mut state = self.whole.new_state();
            if let Some(s) = state.typed_mut::<N>() {
                s.clone_from(self.state);
            }
            let copy = JointCore {
                ctrl: self.whole.clone(),
                state,
            };
            Box::new(Box::new(copy)) as Box<dyn Any + Send>
        })
    }
}

/// The closed loop of a [`JointCore`] against an arm of the core, for its N.
struct OnArm<'a> {
    core: &'a mut JointCore,
    arm: &'a ArmSpec,
    items: &'a Items,
    weights: Option<&'a [f64]>,
    fault: Option<&'a FaultSpec>,
    every: u64,
    hooks: &'a mut dyn Hooks,
}

impl ForJoints for OnArm<'_> {
    type Output = Result<(Rows, Metrics), RunError>;
    fn call<const N: usize>(self) -> Self::Output {
        let law = self.core.law();
        let s = scenario::<N>(Preset::Paper, law, self.items)
            .map_err(|e| RunError::Core(e.error, None))?;
        match self.arm {
            ArmSpec::Paper(two) => {
                let mut t = AdaptiveStep::<2>::of(self.core).map_err(|_| {
                    RunError::Core(
                        Error::Invalid {
                            what: "arm",
                            reason: "TwoLinkArm has 2 joints: the controller has another number",
                        },
                        None,
                    )
                })?;
                let s2 = scenario::<2>(Preset::Paper, law, self.items)
                    .map_err(|e| RunError::Core(e.error, None))?;
                run_arm(
                    &mut t,
                    two,
                    &s2,
                    self.weights,
                    self.fault,
                    self.every,
                    self.hooks,
                )
            }
            ArmSpec::Planar { links, g } => {
                let links: [Link; N] = links.as_slice().try_into().map_err(|_| {
                    RunError::Core(
                        Error::Invalid {
                            what: "arm",
                            reason: "the arm and the controller have different numbers of joints",
                        },
                        None,
                    )
                })?;
                let arm = PlanarArm::new(links, *g)?;
                let mut t = AdaptiveStep::<N>::of(self.core)?;
                run_arm(
                    &mut t,
                    &arm,
                    &s,
                    self.weights,
                    self.fault,
                    self.every,
                    self.hooks,
                )
            }
        }
    }
}

/// [`JointCore::step`] for its N: the rows read as the core's vectors.
struct OnceTyped<'a, 'b> {
    core: &'a mut JointCore,
    inputs: &'a Inputs<'b>,
    out: &'a mut [f64],
}

impl ForJoints for OnceTyped<'_, '_> {
    type Output = Result<(), Error>;
    fn call<const N: usize>(self) -> Self::Output {
        let t = AdaptiveStep::<N>::of(self.core)?;
        let (m, c) = self.inputs;
        let v = |x: &[f64]| Vector::<N>::from_column_slice(x);
        let m = io::Measurement {
            x: v(m.x),
            dx: m.dx.map(v),
            tau_e: v(m.tau_e),
        };
        let c = match c {
            Some(c) => Setpoint {
                x: v(c.x),
                dx: v(c.dx),
                ddx: v(c.ddx),
            },
            None => t.traj.sample(t.ctrl.time(t.state)),
        };
        let cmd = t.ctrl.step(t.state, &m, &c)?;
        self.out.copy_from_slice(cmd.tau_sat.as_slice());
        Ok(())
    }
}

/// The closed loop of a [`JointCore`] on MuJoCo, for its N.
struct OnMujocoRun<'a, 'b> {
    core: &'a mut JointCore,
    sim: &'a mut Sim,
    spec: &'a MujocoSpec,
    run: &'a MujocoRun<'b>,
    hooks: &'a mut dyn Hooks,
}

impl ForJoints for OnMujocoRun<'_, '_> {
    type Output = Result<(Rows, Metrics), RunError>;
    fn call<const N: usize>(self) -> Self::Output {
        let mut t = AdaptiveStep::<N>::of(self.core)?;
        run_mujoco(&mut t, self.sim, self.spec, self.run, self.hooks)
    }
}

// ---------------------------------------------------------------------------
// The joint controller's closed loops, typed.
// ---------------------------------------------------------------------------

/// The closed loop of the joint controller on MuJoCo ([`drive_mujoco`]),
/// along its own trajectory from its clock on, or along `run.reference`.
fn run_mujoco<const N: usize>(
    t: &mut AdaptiveStep<'_, N>,
    sim: &mut Sim,
    spec: &MujocoSpec,
    run: &MujocoRun<'_>,
    hooks: &mut dyn Hooks,
) -> Result<(Rows, Metrics), RunError> {
    let ts = t.ctrl.period();
    let total = adaptimp::sim::simulator::steps(run.t_final, ts)?;
    if let Some(rows) = run.reference {
        let need = usize::try_from(total)
            .unwrap_or(usize::MAX)
            .saturating_mul(N);
        if rows.iter().any(|r| r.len() < need) {
            return Err(RunError::Core(
                Error::Invalid {
                    what: "reference",
                    reason: "needs one row per step",
                },
                None,
            ));
        }
    }
    let every = run.every.max(1);
    let kept = adaptimp::dynamic::kept_rows(total, every);
    let mut rec = Rows::new(N, kept, every)?;
    let mut metrics = MetricsAccumulator::new(run.settle, *t.ctrl.impedance());
    let k0 = t.state.steps();
    let own = Continued {
        traj: *t.traj,
        k0,
        ts,
    };
    let law = t.ctrl.config().law;
    let on = OnMujoco {
        sim,
        spec,
        t_final: run.t_final,
        settle: run.settle,
        items: run.items,
        law,
        fault: run.fault,
        abort: None,
    };
    let rec2 = &mut (&mut metrics, &mut rec);
    match run.reference {
        Some(rows) => drive_mujoco(t, &Table::<N> { rows, ts }, on, hooks, rec2),
        None => drive_mujoco(t, &own, on, hooks, rec2),
    }?;
    Ok((rec, metrics_out(&metrics.finish())?))
}

/// The closed loop of SPEC §11 of the joint controller against a rigid-body
/// arm of the core, from t = 0 with the initial `weights`.
fn run_arm<const N: usize, M: TipPayload<N> + Clone>(
    t: &mut AdaptiveStep<'_, N>,
    arm: &M,
    s: &Scenario<N>,
    weights: Option<&[f64]>,
    fault: Option<&FaultSpec>,
    every: u64,
    hooks: &mut dyn Hooks,
) -> Result<(Rows, Metrics), RunError> {
    let cfg = &s.sim;
    let inj = fault
        .map(|f| injection::<N>(f, t.ctrl.config().tau_max.as_slice()))
        .transpose()?;
    let ts = t.ctrl.period();
    let total = adaptimp::sim::simulator::steps(cfg.t_final, ts)?;
    let kept = adaptimp::dynamic::kept_rows(total, every);
    let mut rec = Rows::new(N, kept, every)?;
    t.restart(weights)?;
    let traj = *t.traj;
    // The plant the controller does not know (SPEC §17): payload and friction.
    let dist = s.disturbances()?;
    // The set-up's errors name no row: check what the run builds first.
    adaptimp::error::check::nonnegative("settle ≥ 0", "settle", cfg.settle)?;
    RigidBody::new(
        arm.with_payload(dist.payload())?,
        FreeSpace,
        cfg.q0,
        cfg.dq0,
        cfg.substeps,
    )?;
    let hooks = RefCell::new(hooks);
    let stop = Cell::new(false);
    let mut watch = Watch::new(&hooks, &stop, total);
    let mut t = Reporting::new(t, &hooks, &stop, total);
    let metrics = match s.wall {
        Some(w) => {
            let wall = Wall::<N>::new(0, w, s.ke_be[0], s.ke_be[1])?;
            run_disturbed_with(
                arm,
                &wall,
                &mut t,
                &traj,
                cfg,
                &dist,
                inj.as_ref(),
                &mut watch,
                &mut rec,
            )
        }
        None => {
            let env = FreeSpace;
            run_disturbed_with(
                arm,
                &env,
                &mut t,
                &traj,
                cfg,
                &dist,
                inj.as_ref(),
                &mut watch,
                &mut rec,
            )
        }
    }
    .map_err(|e| watch.error(e))?;
    if !t.finish() {
        return Err(RunError::Stopped);
    }
    Ok((rec, metrics_out(&metrics)?))
}
