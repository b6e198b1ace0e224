//! The closed loops the bindings still run over the typed controllers: the
//! run's hooks (signals, progress, a copy of the controller for the Python
//! code it calls), the loop on MuJoCo ([`drive_mujoco`], over the plant of
//! `mujoco.rs`), computed torque's run on it, and how a run ended; the
//! joint controller's loops are `dynamic`'s.

use super::items::{injection, scenario, FaultSpec, Items};
use super::mujoco::{Failure, MjPlant, MujocoSpec, Table};
use adaptimp::control::config::Law;
use adaptimp::control::impedance::TargetImpedance;
use adaptimp::control::io::{Command, Control, Measurement};
use adaptimp::error::Error;
use adaptimp::schema::Preset;
use adaptimp::sim::plant::Plant;
use adaptimp::sim::record::{Recorder, Row};
use adaptimp::sim::simulator::{simulate_disturbed, Adapter};
use adaptimp::trajectory::{Setpoint, Trajectory};
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use core::cell::{Cell, RefCell};
use std::any::{Any, TypeId};

pub use adaptimp::dynamic::{Metrics, RowMetrics, Rows};

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
    /// type `part` (the `TypeId` of a `Box<JointCore>`, of a
    /// `Box<OuterCore>`, …), boxed as `Any`; None if the run has no such
    /// part.
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>>;
}

/// A run with nothing to copy (a controller written in Python).
impl View for () {
    fn copy(&self, _part: TypeId) -> Option<Box<dyn Any + Send>> {
        None
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

/// A run of [`JointCore::simulate_mujoco`](super::dynamic::JointCore::simulate_mujoco).
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
            Some(injection::<N>(f, &spec.tau_max)?)
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

/// The const-generic loop's metrics as the run-time ones.
pub(crate) fn metrics_out<const N: usize>(
    m: &adaptimp::sim::metrics::Metrics<N>,
) -> Result<Metrics, Error> {
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
pub(crate) const HOOK_EVERY: u64 = 64;

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

// ---------------------------------------------------------------------------
// Computed torque alone on MuJoCo, along its setpoint of every row.
// ---------------------------------------------------------------------------

impl<const N: usize, C: Control<N> + View> View for Stepped<'_, N, C> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        self.c.copy(part)
    }
}

/// Computed torque as the loop steps it, keeping the torque it gives to
/// apply (its sat(τ), or the torque it holds on a refusal).
struct Stepped<'a, const N: usize, C> {
    c: &'a mut C,
    applied: &'a Cell<Vector<N>>,
}

impl<const N: usize, C: Control<N> + View> Control<N> for Stepped<'_, N, C> {
    fn period(&self) -> f64 {
        Control::period(self.c)
    }
    fn target(&self) -> &TargetImpedance<N> {
        Control::target(self.c)
    }
    fn step(&mut self, m: &Measurement<N>, c: &Setpoint<N>) -> Result<Command<N>, Error> {
        Control::step(self.c, m, c)
    }
    fn step_or_fallback(
        &mut self,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        let (tau, result) = self.c.step_or_fallback(m, c);
        self.applied.set(tau);
        (tau, result)
    }
}

/// The rows of a joint-space run and the SPEC §12 metrics of every row (the
/// accumulator of `_adaptimp.metrics`, as the Python loop measured computed
/// torque), with the saturation the metrics count: the torque the
/// controller gives within the actuators' limits, before a disturbance
/// weakens it (a refused row: none).
struct JointRows<'a, const N: usize> {
    rec: Rows,
    metrics: RowMetrics,
    /// A row the metrics refused (none: every row fits by construction).
    refused: Option<Error>,
    applied: &'a Cell<Vector<N>>,
    tau_max: Vector<N>,
}

impl<const N: usize> Recorder<N> for JointRows<'_, N> {
    fn record(&mut self, r: &Row<N>) {
        self.rec.record(r);
        let sat = if r.refused {
            r.tau
        } else {
            self.applied
                .get()
                .zip_map(&self.tau_max, |t, m| t.max(-m).min(m))
        };
        let pushed = self.metrics.push(
            r.t,
            [r.x.as_slice(), r.dx.as_slice(), r.ddx.as_slice()],
            [r.xc.as_slice(), r.dxc.as_slice(), r.ddxc.as_slice()],
            r.z1.as_slice(),
            [r.tau.as_slice(), sat.as_slice(), r.tau_e.as_slice()],
        );
        if let Err(e) = pushed {
            self.refused.get_or_insert(e);
        }
    }
}

pub(crate) fn run_computed<const N: usize, C: Control<N> + View>(
    c: &mut C,
    sim: &mut Sim,
    spec: &MujocoSpec,
    run: &MujocoRun<'_>,
    hooks: &mut dyn Hooks,
) -> Result<(Rows, Metrics), RunError> {
    let ts = Control::period(c);
    let total = adaptimp::sim::simulator::steps(run.t_final, ts)?;
    let need = usize::try_from(total)
        .unwrap_or(usize::MAX)
        .saturating_mul(N);
    let rows = match run.reference {
        Some(rows) if rows.iter().all(|r| r.len() >= need) => rows,
        _ => {
            return Err(RunError::Core(
                Error::Invalid {
                    what: "reference",
                    reason: "computed torque needs its setpoint of every step",
                },
                None,
            ))
        }
    };
    let every = run.every.max(1);
    let kept = adaptimp::dynamic::kept_rows(total, every);
    let rec = Rows::new(N, kept, every)?;
    let imp = *Control::target(c);
    let target = [
        imp.dd().as_slice(),
        imp.cd().as_slice(),
        imp.gd().as_slice(),
    ];
    let metrics = RowMetrics::new(N, N, true, run.settle, target)?;
    let applied = Cell::new(Vector::<N>::zeros());
    let tau_max =
        Vector::<N>::from_fn(|i, _| spec.tau_max.get(i).copied().unwrap_or(f64::INFINITY));
    let mut out = JointRows {
        rec,
        metrics,
        refused: None,
        applied: &applied,
        tau_max,
    };
    let on = OnMujoco {
        sim,
        spec,
        t_final: run.t_final,
        settle: run.settle,
        items: run.items,
        law: Law::Pd,
        fault: run.fault,
        abort: None,
    };
    let mut stepped = Stepped {
        c,
        applied: &applied,
    };
    drive_mujoco(&mut stepped, &Table::<N> { rows, ts }, on, hooks, &mut out)?;
    match out.refused {
        Some(e) => Err(RunError::Core(e, None)),
        None => Ok((out.rec, out.metrics.finish())),
    }
}
