//! The controller behind a run-time number of joints: [`DynTracker`], an
//! object-safe face of [`Tracker<N, AnyBasis<N>, Sinusoid<N>>`] for every
//! N = 1 … [`MAX_JOINTS`], taking and giving slices, built from the schema's
//! parameter items, and the closed loop over it with decimated records, a
//! signal/progress hook and the SPEC §12 metrics.
//!
//! Nothing here knows Python: the bindings (`mod.rs`) convert arrays to
//! slices and errors to exceptions.

use super::mujoco::{Continued, Failure, MjPlant, MujocoSpec, Table};
use adaptimp::control::config::Law;
use adaptimp::control::controller::Controller;
use adaptimp::control::impedance::TargetImpedance;
use adaptimp::control::io::{Command, Control, Measurement};
use adaptimp::control::tracker::Tracker;
use adaptimp::control::tuning::Rule;
use adaptimp::error::Error;
use adaptimp::networks::network::{Weights, C, D, G};
use adaptimp::networks::rbf::{AnyBasis, Basis, Centers, GRID_MAX_JOINTS};
use adaptimp::schema::{Preset, Scenario, Value};
use adaptimp::sim::disturb::TipPayload;
use adaptimp::sim::environment::{FreeSpace, Wall};
use adaptimp::sim::inject::{Injected, Injection};
use adaptimp::sim::metrics::MetricsAccumulator;
use adaptimp::sim::model::{Link, PlanarArm, TwoLinkArm};
use adaptimp::sim::plant::{Plant, RigidBody};
use adaptimp::sim::record::Recorder;
use adaptimp::sim::simulator::{run_disturbed_with, simulate_disturbed, Adapter};
use adaptimp::trajectory::{Setpoint, Sinusoid, Trajectory};
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use core::cell::{Cell, RefCell};
use std::any::{Any, TypeId};
use std::vec::Vec;

pub use adaptimp::dynamic::MAX_JOINTS;

/// A parameter value, owned (the schema's [`Value`] borrows).
#[derive(Clone, Debug, PartialEq)]
pub enum Owned {
    /// A number.
    Real(f64),
    /// An integer.
    Int(i64),
    /// One number per joint or network.
    Vec(Vec<f64>),
    /// A name.
    Str(String),
    /// A flag.
    Bool(bool),
    /// None.
    None,
}

impl Owned {
    fn value(&self) -> Value<'_> {
        match self {
            Owned::Real(x) => Value::Real(*x),
            Owned::Int(i) => Value::Int(*i),
            Owned::Vec(v) => Value::Vec(v),
            Owned::Str(s) => Value::Str(s),
            Owned::Bool(b) => Value::Bool(*b),
            Owned::None => Value::None,
        }
    }
}

/// Parameter items by schema name.
pub type Items = [(String, Owned)];

/// An error of the scenario, with the parameter it came from (if any).
#[derive(Clone, Debug)]
pub struct ParamError {
    /// The parameter's name, when one parameter was at fault.
    pub name: Option<String>,
    /// The core's error.
    pub error: Error,
}

impl From<Error> for ParamError {
    fn from(error: Error) -> Self {
        Self { name: None, error }
    }
}

/// `preset` for `law` with every item applied, for N joints.
pub fn scenario<const N: usize>(
    preset: Preset,
    law: Law,
    items: &Items,
) -> Result<Scenario<N>, ParamError> {
    let mut s = Scenario::<N>::preset(preset, law);
    for (name, v) in items {
        s.set(name, v.value()).map_err(|error| ParamError {
            name: Some(name.clone()),
            error,
        })?;
    }
    Ok(s)
}

/// User RBF centres: L rows of 4n coordinates (x, v, α1, α̇1) and the
/// squared widths η_d² per input dimension (4n).
#[derive(Clone, Debug, PartialEq)]
pub struct CentersSpec {
    /// Row-major, L × 4n.
    pub centers: Vec<f64>,
    /// 4n squared widths, block-major (x, v, α1, α̇1), joint-minor.
    pub widths2: Vec<f64>,
}

/// The nominal model whose gravity a joint controller feeds forward, SPEC
/// (20.10): a chain's joints and inertials and the gravity vector, as
/// computed torque takes them.
#[derive(Clone, Debug, PartialEq)]
pub struct GravitySpec {
    /// The chain's joints (fixed ones too).
    pub joints: Vec<adaptimp::cartesian::chain::Joint>,
    /// One inertial per joint.
    pub inertials: Vec<adaptimp::cartesian::dynamics::Inertial>,
    /// Gravity (m/s², base frame).
    pub gravity: [f64; 3],
}

/// The arm a run's plant is built from.
#[derive(Clone, Debug, PartialEq)]
pub enum ArmSpec {
    /// The paper's 2-link arm (55)–(63).
    Paper(TwoLinkArm),
    /// A planar arm of n links.
    Planar {
        /// The links, joint 1 first.
        links: Vec<Link>,
        /// Gravity (m/s²).
        g: f64,
    },
}

/// A fault to inject into a run (`src/sim/inject.rs`), for any number of joints.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultSpec {
    /// What goes wrong.
    pub kind: FaultKind,
    /// Start of the window (s).
    pub start: f64,
    /// Length of the window (s).
    pub duration: f64,
}

/// The kinds of [`Injected`] faults.
#[derive(Clone, Debug, PartialEq)]
pub enum FaultKind {
    /// The sensors repeat their last sample.
    Stale,
    /// The position sensor reads NaN.
    NanBurst,
    /// The force sensor reads τe + bias (N m, one per joint).
    ForceBias(Vec<f64>),
    /// The actuators deliver at most this fraction of τmax.
    ActuatorDrop(f64),
    /// No control step runs: the last applied torque is held.
    Skipped,
}

/// The core's injection of `f`, with the actuators' limits `tau_max` (N m).
fn injection<const N: usize>(f: &FaultSpec, tau_max: &Vector<N>) -> Result<Injection<N>, Error> {
    adaptimp::error::check::nonnegative("fault start ≥ 0", "start", f.start)?;
    adaptimp::error::check::positive("fault duration > 0", "duration", f.duration)?;
    let fault = match &f.kind {
        FaultKind::Stale => Injected::Stale,
        FaultKind::NanBurst => Injected::NanBurst,
        FaultKind::Skipped => Injected::Skipped,
        FaultKind::ForceBias(b) => {
            if b.len() != N {
                return Err(Error::Invalid {
                    what: "bias",
                    reason: "needs one value per joint (N m)",
                });
            }
            adaptimp::error::check::finite_slice("bias", b)?;
            Injected::ForceBias {
                bias: Vector::from_column_slice(b),
            }
        }
        FaultKind::ActuatorDrop(fraction) => {
            if !(0.0..=1.0).contains(fraction) {
                return Err(Error::Condition {
                    condition: "0 ≤ fraction ≤ 1",
                    lhs: "fraction",
                    index: None,
                    value: *fraction,
                });
            }
            Injected::ActuatorDrop {
                tau_max: *tau_max,
                fraction: *fraction,
            }
        }
    };
    Ok(Injection {
        fault,
        start: f.start,
        duration: f.duration,
    })
}

/// The run-time hook of long calls: asked every few steps whether to go on
/// (signals) and told the progress.
pub trait Hooks {
    /// `done` of `total` steps are taken; false stops the run. Asked where
    /// the run's controllers cannot be read (within a period): the hook
    /// checks for signals only.
    fn tick(&mut self, done: u64, total: u64) -> bool;
    /// `done` of `total` steps are taken, between two steps, the run's
    /// controllers readable through `view` (a binding publishes them for the
    /// progress callback it calls here); false stops the run.
    fn report(&mut self, done: u64, total: u64, view: &dyn View) -> bool {
        let _ = view;
        self.tick(done, total)
    }
}

/// What a run's controllers are at a [`Hooks::report`], copied on demand.
pub trait View {
    /// A copy of the part of the run's state that a binding keeps as the
    /// type `part` (the `TypeId` of a `Box<dyn DynTracker>`, of a
    /// `Box<dyn DynOuter>`, …), boxed as `Any`; None if the run has no such
    /// part.
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>>;
}

/// A run with nothing to copy (a controller written in Python).
impl View for () {
    fn copy(&self, _part: TypeId) -> Option<Box<dyn Any + Send>> {
        None
    }
}

/// The copy of a joint controller as the bindings keep it.
impl<const N: usize> View for Typed<N> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        (part == TypeId::of::<Box<dyn DynTracker>>())
            .then(|| Box::new(Box::new(self.clone()) as Box<dyn DynTracker>) as Box<dyn Any + Send>)
    }
}

/// A run's controller that reports to the hooks ([`Hooks::report`]) after
/// every [`HOOK_EVERY`]-th of its steps, readable then; when they say stop,
/// `stop` is raised and the plant ends the run before its next period.
pub(crate) struct Reporting<'a, 'h, C: ?Sized> {
    ctrl: &'a mut C,
    hooks: &'a RefCell<&'h mut dyn Hooks>,
    stop: &'a Cell<bool>,
    done: u64,
    total: u64,
}

impl<'a, 'h, C: View + ?Sized> Reporting<'a, 'h, C> {
    pub(crate) fn new(
        ctrl: &'a mut C,
        hooks: &'a RefCell<&'h mut dyn Hooks>,
        stop: &'a Cell<bool>,
        total: u64,
    ) -> Self {
        Self {
            ctrl,
            hooks,
            stop,
            done: 0,
            total,
        }
    }

    /// One step taken (or refused).
    fn stepped(&mut self) {
        self.done += 1;
        if self.done.is_multiple_of(HOOK_EVERY) || self.done == self.total {
            self.report(self.done);
        }
    }

    fn report(&mut self, done: u64) {
        let view = ViewOf(&*self.ctrl);
        if !self.hooks.borrow_mut().report(done, self.total, &view) {
            self.stop.set(true);
        }
    }

    /// After the run: the last report, if the steps did not make it (a
    /// fault skipped some); whether the hooks let the run end.
    pub(crate) fn finish(&mut self) -> bool {
        if self.done < self.total && !self.stop.get() {
            self.report(self.total);
        }
        !self.stop.get()
    }
}

/// `&C` as a [`View`], for a `C` that may be unsized.
struct ViewOf<'a, C: ?Sized>(&'a C);

impl<C: View + ?Sized> View for ViewOf<'_, C> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        self.0.copy(part)
    }
}

impl<const N: usize, C: Control<N> + View + ?Sized> Control<N> for Reporting<'_, '_, C> {
    fn period(&self) -> f64 {
        self.ctrl.period()
    }
    fn target(&self) -> &TargetImpedance<N> {
        self.ctrl.target()
    }
    fn step(&mut self, m: &Measurement<N>, c: &Setpoint<N>) -> Result<Command<N>, Error> {
        let r = self.ctrl.step(m, c);
        self.stepped();
        r
    }
    fn step_or_fallback(
        &mut self,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        let r = self.ctrl.step_or_fallback(m, c);
        self.stepped();
        r
    }
    fn step_with_wrench(
        &mut self,
        m: &Measurement<N>,
        wrench: &[f64; 6],
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        let r = self.ctrl.step_with_wrench(m, wrench, c);
        self.stepped();
        r
    }
}

pub use adaptimp::dynamic::{Metrics, RowMetrics, Rows};

/// How a run ended when it did not finish.
#[derive(Clone, Debug)]
pub enum RunError {
    /// The plant ended it (a MuJoCo run that diverged, or MuJoCo's fatal
    /// error): how, with the row and the time.
    Plant(Failure),
    /// The core's error (at step `k`, when the run had started).
    Core(Error, Option<u64>),
    /// The hook asked to stop.
    Stopped,
    /// The records did not fit in memory.
    Memory(usize),
}

impl From<Error> for RunError {
    fn from(e: Error) -> Self {
        RunError::Core(e, None)
    }
}

impl From<adaptimp::dynamic::RunError> for RunError {
    fn from(e: adaptimp::dynamic::RunError) -> Self {
        match e {
            adaptimp::dynamic::RunError::Core(e, k) => RunError::Core(e, k),
            adaptimp::dynamic::RunError::Stopped => RunError::Stopped,
            adaptimp::dynamic::RunError::Memory(rows) => RunError::Memory(rows),
        }
    }
}

/// A step's inputs as slices of n values.
pub struct Inputs<'a> {
    /// Joint positions (rad).
    pub x: &'a [f64],
    /// Joint velocities (rad/s), if measured.
    pub dx: Option<&'a [f64]>,
    /// Force on the environment (N m).
    pub tau_e: &'a [f64],
    /// An external setpoint (xc, ẋc, ẍc) instead of the trajectory's.
    pub setpoint: Option<[&'a [f64]; 3]>,
}

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

/// A controller with its trajectory and state, for any N ≤ [`MAX_JOINTS`].
pub trait DynTracker: Send + Sync {
    /// Joints n.
    fn n(&self) -> usize;
    /// RBF nodes L.
    fn nodes(&self) -> usize;
    /// The law.
    fn law(&self) -> Law;
    /// Ts (s).
    fn ts(&self) -> f64;
    /// t_k (s) of the next step.
    fn time(&self) -> f64;
    /// Steps taken.
    fn steps(&self) -> u64;
    /// Back to t = 0.
    fn reset(&mut self);
    /// One step; writes sat(τ) into `out` (n values).
    fn step(&mut self, m: &Inputs<'_>, out: &mut [f64]) -> Result<(), Error>;
    /// One step that always writes a torque to apply into `out`.
    fn step_or_fallback(&mut self, m: &Inputs<'_>, out: &mut [f64]) -> Result<(), Error>;
    /// A step call refused by the front (its arguments' shapes or types):
    /// recorded as a refused step ([`Controller::refuse`](adaptimp::Controller::refuse)).
    fn refuse(&mut self, error: Error);
    /// A quantity of the last step.
    fn last(&self, what: Last) -> &[f64];
    /// ζ now.
    fn zeta(&self) -> &[f64];
    /// The recorded fault: (error, step).
    fn fault(&self) -> Option<(Error, u64)>;
    /// Forget the recorded fault.
    fn clear_fault(&mut self);
    /// The resolved weight bounds.
    fn weight_bound(&self) -> Option<[f64; 3]>;
    /// The weights, row-major over ŴD[k][j], ŴC[k][j], ŴG[k], each over L nodes.
    fn weights(&self) -> Vec<f64>;
    /// Replace the weights (same layout as [`weights`](Self::weights)).
    fn load_weights(&mut self, rows: &[f64]) -> Result<(), Error>;
    /// The whole state as reals ([`State::save`](adaptimp::control::state::State::save)).
    fn snapshot(&self) -> Vec<f64>;
    /// Restore a [`snapshot`](Self::snapshot).
    fn restore(&mut self, data: &[f64]) -> Result<(), Error>;
    /// The per-step learning gain of the explicit-Euler step at the start of
    /// the trajectory, Ts ‖S(Z0)‖² (ΓD ‖ẍc(0)‖² + ΓC ‖ẋc(0)‖² + ΓG) (N m per
    /// rad/s), and min Kp: the Jury condition of `docs/robot.md` is gain < Kp.
    fn learning_gain(&self) -> (f64, f64);
    /// `rows` steps from row-major tables; writes sat(τ) rows into `out`.
    /// Errors name the row.
    fn replay(
        &mut self,
        rows: usize,
        tables: &Tables<'_>,
        out: &mut Vec<f64>,
        hooks: &mut dyn Hooks,
    ) -> Result<(), RunError>;
    /// The closed loop of SPEC §11 against `arm` with the scenario of
    /// `items` (its run and wall parameters), from t = 0 (reset first) with
    /// the initial `weights` (rows as for [`load_weights`](Self::load_weights)).
    fn simulate(
        &mut self,
        arm: &ArmSpec,
        items: &Items,
        weights: Option<&[f64]>,
        fault: Option<&FaultSpec>,
        every: u64,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError>;
    /// The closed loop on MuJoCo (`sim` as `spec` describes it) from the
    /// controller's current state (not reset: a used controller goes on),
    /// with the disturbances of `run.items` (SPEC §17; payload and jitter are
    /// refused: the first is a change of the model, the second of its
    /// timestep). Records every `run.every`-th row with the end effector.
    fn simulate_mujoco(
        &mut self,
        sim: &mut Sim,
        spec: &MujocoSpec,
        run: &MujocoRun<'_>,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError>;
    /// As [`Any`], for the typed paths.
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

/// A run of [`DynTracker::simulate_mujoco`].
pub struct MujocoRun<'a> {
    /// Duration T (s).
    pub t_final: f64,
    /// Start of the "after" window of the metrics (s).
    pub settle: f64,
    /// Keep every `every`-th row.
    pub every: u64,
    /// The disturbance parameters (SPEC §17) by schema name.
    pub items: &'a Items,
    /// The commanded setpoints xc, ẋc, ẍc of every row (K × n each,
    /// row-major), or none: the controller's own trajectory.
    pub reference: Option<[&'a [f64]; 3]>,
    /// A fault to inject (τmax: the plant's actuators').
    pub fault: Option<&'a FaultSpec>,
}

fn invalid_tau_max() -> Error {
    Error::Invalid {
        what: "tau_max",
        reason: "the plant needs one limit per joint",
    }
}

fn run_mujoco<const N: usize>(
    t: &mut Typed<N>,
    sim: &mut Sim,
    spec: &MujocoSpec,
    run: &MujocoRun<'_>,
    hooks: &mut dyn Hooks,
) -> Result<(Rows, Metrics), RunError> {
    let ts = t.controller().period();
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
    let kept = usize::try_from(total.div_ceil(every)).unwrap_or(usize::MAX);
    let mut rec = Rows::new(N, kept, every)?;
    let mut metrics = MetricsAccumulator::new(run.settle, *t.controller().impedance());
    let k0 = t.steps();
    let own = Continued {
        traj: *t.trajectory(),
        k0,
        ts,
    };
    let law = t.law();
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

/// A run's plant on MuJoCo and the settings of its loop ([`drive_mujoco`]).
pub(crate) struct OnMujoco<'a> {
    /// The model and its data.
    pub sim: &'a mut Sim,
    /// Where the plant's joints, actuators and end effector are.
    pub spec: &'a MujocoSpec,
    /// Duration T (s).
    pub t_final: f64,
    /// Start of the metrics' "after" window (s) (checked here).
    pub settle: f64,
    /// The disturbance parameters (SPEC §17) by schema name.
    pub items: &'a Items,
    /// The controller's law (whose scenario reads the items).
    pub law: Law,
    /// A fault to inject (τmax: the plant's actuators').
    pub fault: Option<&'a FaultSpec>,
    /// Raised by the controller to end the run before the next period (a
    /// controller written in Python that raised), whatever the fault.
    pub abort: Option<&'a core::cell::Cell<bool>>,
}

/// The core's loop ([`simulate_disturbed`]) of `ctrl` along `traj` on MuJoCo,
/// every row to `rec`: the disturbances of `on.items` (payload and jitter
/// refused: the first is a change of the model, the second of its
/// timestep), the fault, the hook every 64 MuJoCo steps ([`MjPlant::watch`]);
/// the plant's own failure (a diverged or fatal MuJoCo) as
/// [`RunError::Plant`], a stop (the hook, or `on.abort`) as
/// [`RunError::Stopped`]. One loop for every controller: the joint ones, the
/// Cartesian ones, computed torque and a controller written in Python.
pub(crate) fn drive_mujoco<const N: usize, C, T, R>(
    ctrl: &mut C,
    traj: &T,
    on: OnMujoco<'_>,
    hooks: &mut dyn Hooks,
    rec: &mut R,
) -> Result<(), RunError>
where
    C: adaptimp::control::io::Control<N> + View + ?Sized,
    T: Trajectory<N> + ?Sized,
    R: Recorder<N> + ?Sized,
{
    let ts = ctrl.period();
    let total = adaptimp::sim::simulator::steps(on.t_final, ts)?;
    adaptimp::error::check::nonnegative("settle ≥ 0", "settle", on.settle)?;
    let s = scenario::<N>(Preset::Robot, on.law, on.items)
        .map_err(|e| RunError::Core(e.error, None))?;
    let dist = s.disturbances()?;
    if dist.payload() != 0.0 {
        return Err(RunError::Core(
            Error::Invalid {
                what: "payload",
                reason: "on MuJoCo the payload is a change of the model, not of the loop",
            },
            None,
        ));
    }
    if dist.params().jitter != 0.0 {
        return Err(RunError::Core(
            Error::Invalid {
                what: "jitter",
                reason: "the MuJoCo plant advances by Ts exactly (its timestep is fixed for a run)",
            },
            None,
        ));
    }
    let spec = on.spec;
    let inj = match on.fault {
        Some(f) => {
            if spec.tau_max.len() != N {
                return Err(RunError::Core(invalid_tau_max(), None));
            }
            Some(injection::<N>(
                f,
                &Vector::from_column_slice(&spec.tau_max),
            )?)
        }
        None => None,
    };
    // Signals within a period (the plant's hook); the progress between
    // periods, the controller readable (`Reporting`), which stops the run
    // through the plant's flag (the controller's own, if it has one).
    let hooks = RefCell::new(hooks);
    let own = Cell::new(false);
    let stop = on.abort.unwrap_or(&own);
    let mut tick = |done: u64, total: u64| hooks.borrow_mut().tick(done, total);
    let mut run_time = adaptimp::dynamic::Scenario::new(N, Preset::Robot, on.law)?;
    for (name, v) in on.items {
        run_time.set(name, v.value())?;
    }
    let friction = run_time.disturbances()?;
    let mut plant = MjPlant::new(on.sim, spec, ts, &friction)?;
    plant.watch(&mut tick, total);
    plant.abort_on(stop);
    if let Err(e) = plant.start() {
        return Err(match plant.failure() {
            Some(f) => RunError::Plant(f.clone()),
            None => RunError::Core(e, None),
        });
    }
    let mut reporting = Reporting::new(ctrl, &hooks, stop, total);
    let result = simulate_disturbed(
        &mut plant,
        &mut reporting,
        traj,
        on.t_final,
        inj.as_ref(),
        &dist,
        rec,
    );
    match result {
        Ok(_) if reporting.finish() => Ok(()),
        Ok(_) => Err(RunError::Stopped),
        Err(e) => Err(match plant.failure() {
            Some(f) => RunError::Plant(f.clone()),
            None if plant.stopped() => RunError::Stopped,
            None => RunError::Core(e, Some(plant.rows())),
        }),
    }
}

/// Row-major tables of a replay: K × n each.
pub struct Tables<'a> {
    /// Positions.
    pub x: &'a [f64],
    /// Velocities.
    pub dx: Option<&'a [f64]>,
    /// Forces.
    pub tau_e: &'a [f64],
    /// Setpoints (xc, ẋc, ẍc).
    pub setpoint: Option<[&'a [f64]; 3]>,
}

/// The typed controller behind a [`DynTracker`] of N joints (the Cartesian
/// bindings step it directly, `bindings/python/src/cartesian.rs`).
pub(crate) type Typed<const N: usize> = Tracker<N, AnyBasis<N>, Sinusoid<N>>;

/// Build the controller `law` for n joints from `preset` and `items`, with the
/// paper's grid (n ≤ 3) or `centers`, feeding forward `gravity`'s G(q) if
/// given (SPEC (20.10)).
pub fn build(
    n: usize,
    preset: Preset,
    law: Law,
    items: &Items,
    centers: Option<&CentersSpec>,
    gravity: Option<&GravitySpec>,
) -> Result<Box<dyn DynTracker>, ParamError> {
    adaptimp::with_joints!(
        n,
        K => Ok(Box::new(build_n::<K>(preset, law, items, centers, gravity)?)),
        _ => Err(Error::Invalid {
            what: "n",
            reason: "the number of joints must be between 1 and 7",
        }
        .into()),
    )
}

fn build_n<const N: usize>(
    preset: Preset,
    law: Law,
    items: &Items,
    centers: Option<&CentersSpec>,
    gravity: Option<&GravitySpec>,
) -> Result<Typed<N>, ParamError> {
    let s = scenario::<N>(preset, law, items)?;
    let traj = s.trajectory()?;
    let basis = match centers {
        // Beyond the vertex grid: the rule's default basis, SPEC §18.
        None if N > GRID_MAX_JOINTS => AnyBasis::Centers(Rule::default().default_basis(&traj)?),
        None => AnyBasis::Grid(s.grid()?),
        Some(c) => {
            if c.widths2.len() != 4 * N {
                return Err(Error::Invalid {
                    what: "widths",
                    reason: "need one width per input dimension (4n: x, v, α1, α̇1)",
                }
                .into());
            }
            let w: [Vector<N>; 4] =
                core::array::from_fn(|b| Vector::from_column_slice(&c.widths2[b * N..][..N]));
            AnyBasis::Centers(Centers::new(c.centers.clone(), w)?)
        }
    };
    let mut ctrl = Controller::for_trajectory(s.config, basis, &traj)?;
    if let Some(g) = gravity {
        let model =
            adaptimp::cartesian::dynamics::Dynamics::<N>::new(&g.joints, &g.inertials, g.gravity)?;
        ctrl = ctrl.with_feedforward(std::sync::Arc::new(model));
    }
    Ok(Tracker::new(ctrl, traj))
}

fn vector<const N: usize>(v: &[f64]) -> Vector<N> {
    Vector::from_column_slice(v)
}

fn measurement<const N: usize>(m: &Inputs<'_>) -> Measurement<N> {
    Measurement {
        x: vector(m.x),
        dx: m.dx.map(vector),
        tau_e: vector(m.tau_e),
    }
}

fn setpoint<const N: usize>(s: [&[f64]; 3]) -> Setpoint<N> {
    Setpoint {
        x: vector(s[0]),
        dx: vector(s[1]),
        ddx: vector(s[2]),
    }
}

/// The const-generic loop's metrics as the run-time ones.
fn metrics_out<const N: usize>(m: &adaptimp::sim::metrics::Metrics<N>) -> Result<Metrics, Error> {
    let v = |x: &Vector<N>| adaptimp::dynamic::Joints::from_slice(x.as_slice());
    Ok(Metrics {
        rows: m.rows,
        rms_z1: m.rms_z1,
        rms_z1_after2: m.rms_z1_after2,
        rms_z1_joint_after2: v(&m.rms_z1_joint_after2)?,
        max_abs_z1_joint_after2: v(&m.max_abs_z1_joint_after2)?,
        sat_duty: m.sat_duty,
        steps_in_contact: m.steps_in_contact,
        peak_contact_after2: m.peak_contact_after2,
        mean_contact: m.mean_contact,
        peak_abs_tau: v(&m.peak_abs_tau)?,
        imp_err_rms_after2: m.imp_err_rms_after2,
    })
}

/// The adapter that asks the hook every [`HOOK_EVERY`] periods whether to go
/// on (signals), and ends the run once `stop` is raised (by [`Reporting`]).
pub(crate) struct Watch<'a, 'h> {
    hooks: &'a RefCell<&'h mut dyn Hooks>,
    stop: &'a Cell<bool>,
    done: u64,
    total: u64,
    stopped: bool,
}

/// Steps between two calls of [`Hooks::tick`].
const HOOK_EVERY: u64 = 64;

impl<'a, 'h> Watch<'a, 'h> {
    pub(crate) fn new(
        hooks: &'a RefCell<&'h mut dyn Hooks>,
        stop: &'a Cell<bool>,
        total: u64,
    ) -> Self {
        Self {
            hooks,
            stop,
            done: 0,
            total,
            stopped: false,
        }
    }

    /// The run's error, with the period it happened in.
    pub(crate) fn error(&self, e: Error) -> RunError {
        if self.stopped {
            RunError::Stopped
        } else {
            RunError::Core(e, Some(self.done))
        }
    }
}

fn stopped() -> Error {
    Error::Invalid {
        what: "run",
        reason: "stopped",
    }
}

impl<const N: usize> Adapter<N> for Watch<'_, '_> {
    fn advance<P: Plant<N> + ?Sized>(
        &mut self,
        plant: &mut P,
        tau: &Vector<N>,
        h: f64,
    ) -> Result<Vector<N>, Error> {
        if self.stop.get() {
            self.stopped = true;
            return Err(stopped());
        }
        let a = plant.advance(tau, h)?;
        self.done += 1;
        let due = self.done.is_multiple_of(HOOK_EVERY) || self.done == self.total;
        if due && !self.hooks.borrow_mut().tick(self.done, self.total) {
            self.stopped = true;
            return Err(stopped());
        }
        Ok(a)
    }
}

fn run_arm<const N: usize, M: TipPayload<N> + Clone>(
    t: &mut Typed<N>,
    arm: &M,
    s: &Scenario<N>,
    weights: Option<&[f64]>,
    fault: Option<&FaultSpec>,
    every: u64,
    hooks: &mut dyn Hooks,
) -> Result<(Rows, Metrics), RunError> {
    let cfg = &s.sim;
    let inj = fault
        .map(|f| injection::<N>(f, &t.controller().config().tau_max))
        .transpose()?;
    let ts = t.controller().period();
    let total = adaptimp::sim::simulator::steps(cfg.t_final, ts)?;
    let kept = usize::try_from(total.div_ceil(every.max(1))).unwrap_or(usize::MAX);
    let mut rec = Rows::new(N, kept, every)?;
    t.reset();
    if let Some(w) = weights {
        DynTracker::load_weights(t, w)?;
    }
    let traj = *t.trajectory();
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

impl<const N: usize> DynTracker for Typed<N> {
    fn n(&self) -> usize {
        N
    }
    fn nodes(&self) -> usize {
        self.controller().basis().nodes()
    }
    fn law(&self) -> Law {
        self.controller().config().law
    }
    fn ts(&self) -> f64 {
        self.controller().period()
    }
    fn time(&self) -> f64 {
        Tracker::time(self)
    }
    fn steps(&self) -> u64 {
        self.state().steps()
    }
    fn reset(&mut self) {
        Tracker::reset(self)
    }

    fn step(&mut self, m: &Inputs<'_>, out: &mut [f64]) -> Result<(), Error> {
        let meas = measurement::<N>(m);
        let cmd = match m.setpoint {
            Some(s) => self.step_with(&meas, &setpoint(s))?,
            None => Tracker::step(self, &meas)?,
        };
        out.copy_from_slice(cmd.tau_sat.as_slice());
        Ok(())
    }

    fn step_or_fallback(&mut self, m: &Inputs<'_>, out: &mut [f64]) -> Result<(), Error> {
        let meas = measurement::<N>(m);
        let c = match m.setpoint {
            Some(s) => setpoint(s),
            None => self.trajectory().sample(Tracker::time(self)),
        };
        let (tau, result) = adaptimp::control::io::Control::step_or_fallback(self, &meas, &c);
        out.copy_from_slice(tau.as_slice());
        result.map(|_| ())
    }

    fn refuse(&mut self, error: Error) {
        Tracker::refuse(self, error);
    }

    fn last(&self, what: Last) -> &[f64] {
        let c: &Command<N> = self.state().last();
        match what {
            Last::Tau => c.tau.as_slice(),
            Last::TauSat => c.tau_sat.as_slice(),
            Last::Dtau => c.dtau.as_slice(),
            Last::Z1 => c.z1.as_slice(),
            Last::Xc => c.xc.as_slice(),
            Last::Xd => c.xd.as_slice(),
            Last::V => c.v.as_slice(),
            Last::Applied => self.state().applied().as_slice(),
        }
    }

    fn zeta(&self) -> &[f64] {
        self.state().zeta().as_slice()
    }

    fn fault(&self) -> Option<(Error, u64)> {
        self.state().fault().map(|f| (f.error, f.step))
    }

    fn clear_fault(&mut self) {
        self.state_mut().clear_fault()
    }

    fn weight_bound(&self) -> Option<[f64; 3]> {
        self.controller().learning().bound()
    }

    fn weights(&self) -> Vec<f64> {
        let w = self.state().weights();
        let mut out = Vec::with_capacity((2 * N * N + N) * self.nodes());
        for net in [D, C, G] {
            for row in w.network(net) {
                out.extend_from_slice(row);
            }
        }
        out
    }

    fn load_weights(&mut self, rows: &[f64]) -> Result<(), Error> {
        let w = Weights::<N>::from_rows(rows, self.nodes())?;
        Tracker::load_weights(self, &w)
    }

    fn snapshot(&self) -> Vec<f64> {
        let st = self.state();
        let mut out = std::vec![0.0; st.snapshot_len()];
        // The buffer has exactly the length save needs.
        let _ = st.save(&mut out);
        out
    }

    fn restore(&mut self, data: &[f64]) -> Result<(), Error> {
        Tracker::restore(self, data)
    }

    fn learning_gain(&self) -> (f64, f64) {
        let ctrl = self.controller();
        let cfg = ctrl.config();
        let c = self.trajectory().sample(0.0);
        let mut s = std::vec![0.0; self.nodes()];
        ctrl.basis().eval(&[c.x, c.dx, c.dx, c.ddx], &mut s);
        let s2: f64 = s.iter().map(|x| x * x).sum();
        let [gd, gc, gg] = cfg.gamma;
        let gain = cfg.ts * s2 * (gd * c.ddx.norm_squared() + gc * c.dx.norm_squared() + gg);
        // Per unit inertia scale, SPEC (10.2): joint k's rows learn at Γ d_k
        // against Kp_k (Kp for the paper's d = 1).
        (gain, cfg.kp.component_div(&cfg.inertia).min())
    }

    fn replay(
        &mut self,
        rows: usize,
        t: &Tables<'_>,
        out: &mut Vec<f64>,
        hooks: &mut dyn Hooks,
    ) -> Result<(), RunError> {
        let row = |v: &[f64], k: usize| Vector::<N>::from_column_slice(&v[k * N..(k + 1) * N]);
        for k in 0..rows {
            if k > 0
                && (k as u64).is_multiple_of(HOOK_EVERY)
                && !hooks.report(k as u64, rows as u64, &*self)
            {
                return Err(RunError::Stopped);
            }
            let m = Measurement {
                x: row(t.x, k),
                dx: t.dx.map(|d| row(d, k)),
                tau_e: row(t.tau_e, k),
            };
            let cmd = match t.setpoint {
                Some([x, dx, ddx]) => {
                    let c = Setpoint {
                        x: row(x, k),
                        dx: row(dx, k),
                        ddx: row(ddx, k),
                    };
                    self.step_with(&m, &c)
                }
                None => Tracker::step(self, &m),
            }
            .map_err(|e| RunError::Core(e, Some(k as u64)))?;
            out.extend_from_slice(cmd.tau_sat.as_slice());
        }
        // The last row reported too (a progress bar ends at 100 %).
        if rows > 0 && !hooks.report(rows as u64, rows as u64, &*self) {
            return Err(RunError::Stopped);
        }
        Ok(())
    }

    fn simulate(
        &mut self,
        arm: &ArmSpec,
        items: &Items,
        weights: Option<&[f64]>,
        fault: Option<&FaultSpec>,
        every: u64,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError> {
        let preset = Preset::Paper;
        let s =
            scenario::<N>(preset, self.law(), items).map_err(|e| RunError::Core(e.error, None))?;
        match arm {
            ArmSpec::Paper(two) => {
                let typed = self
                    .as_any_mut()
                    .downcast_mut::<Typed<2>>()
                    .ok_or(RunError::Core(
                        Error::Invalid {
                            what: "arm",
                            reason: "TwoLinkArm has 2 joints: the controller has another number",
                        },
                        None,
                    ))?;
                let s2 = scenario::<2>(preset, typed.law(), items)
                    .map_err(|e| RunError::Core(e.error, None))?;
                run_arm(typed, two, &s2, weights, fault, every, hooks)
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
                run_arm(self, &arm, &s, weights, fault, every, hooks)
            }
        }
    }

    fn simulate_mujoco(
        &mut self,
        sim: &mut Sim,
        spec: &MujocoSpec,
        run: &MujocoRun<'_>,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError> {
        run_mujoco(self, sim, spec, run, hooks)
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
