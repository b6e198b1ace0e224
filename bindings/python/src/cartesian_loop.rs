//! The Cartesian controller in the core's closed loop on MuJoCo (SPEC §13.1,
//! §16): the core's outer loop over a [`Chain`] and the joint controller
//! behind it ([`Typed`]) as one [`Control`], stepped by the core's loop
//! ([`drive_mujoco`]) with the measured end-effector wrench
//! ([`Control::step_with_wrench`]), recorded in task space and measured by
//! the one implementation of the SPEC §12 metrics ([`TaskMetrics`]).
//!
//! The commanded pose of row k is the k-th of a table (tabulated by the
//! caller from a path or a reference at t_k = k·Ts), or none: the last
//! target held. The loop's clock reaches the controller through the
//! trajectory it samples at every row ([`Clock`]): a fault that skips rows
//! does not shift the path.
//!
//! What each row records, as the Python loop records it for
//! `adaptimp.CartesianController`: xc = p_c (the commanded position; the
//! filtered target p_t when held), ẋc, ẍc (ṗ_c, p̈_c; zero when held), xd =
//! p_d (the compliant reference), z1 = p_d − p(q) (m, with p(q) the chain's
//! tip at the measured q), and beside them ṗ_d, p̈_d, q_d, the impedance's
//! error and the wrench the controller was given (the core's [`TaskRows`]). The
//! joint quantities (q, τ, sat(τ), τe, ζ, the velocity used) are the joint
//! controller's, as for a joint-space run.

use super::computed::Computed;
use super::dynamic::{
    drive_mujoco, FaultKind, FaultSpec, Hooks, Items, Metrics, OnMujoco, RowMetrics, Rows,
    RunError, Typed, View,
};
use super::mujoco::MujocoSpec;
use adaptimp::cartesian::{
    CartesianCommand, CartesianImpedance, CartesianMeasurement, CartesianState, Chain, PoseTarget,
};
use adaptimp::control::config::Law;
use adaptimp::control::impedance::TargetImpedance;
use adaptimp::control::io::TaskTorque;
use adaptimp::control::io::{Command, Measurement, WrenchControl};
use adaptimp::dynamic::{self as dy, TaskRows, TaskStep};
use adaptimp::error::Error;
use adaptimp::sim::record::{Recorder, Row};
use adaptimp::trajectory::{Clock, Setpoint};
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use core::any::{Any, TypeId};
use core::cell::{Cell, RefCell};
use std::vec::Vec;

pub use adaptimp::dynamic::TARGET_LEN;

/// A Cartesian run on MuJoCo ([`simulate_mujoco`]).
pub struct CartesianRun<'a> {
    /// Duration T (s).
    pub t_final: f64,
    /// Start of the "after" window of the metrics (s).
    pub settle: f64,
    /// Keep every `every`-th row.
    pub every: u64,
    /// The disturbance parameters (SPEC §17) by schema name.
    pub items: &'a Items,
    /// The commanded pose of every row, [`TARGET_LEN`] values each (p, ṗ,
    /// p̈, R row-major, ω, ω̇), row-major; none: the last target held.
    pub targets: Option<&'a [f64]>,
    /// A fault to inject (τmax: the plant's actuators').
    pub fault: Option<&'a FaultSpec>,
}

/// A joint controller of the core behind a Cartesian impedance: the
/// paper's laws ([`Typed`]) or computed torque ([`Computed`]), as the
/// Cartesian step and the native loop drive it; copied for the Python code
/// a run calls ([`View`]).
pub(crate) trait JointStep<const N: usize>: View {
    /// Ts (s).
    fn period(&self) -> f64;
    /// The target impedance (3) (for the impedance residual of SPEC §12).
    fn impedance(&self) -> &TargetImpedance<N>;
    /// The law whose preset the run's scenario takes (SPEC §17).
    fn law(&self) -> Law;
    /// One step on the compliant reference `r`.
    fn step_with(&mut self, m: &Measurement<N>, r: &Setpoint<N>) -> Result<Command<N>, Error>;
    /// One step of the torque-level formulations (SPEC §19).
    fn step_task(
        &mut self,
        m: &Measurement<N>,
        r: &Setpoint<N>,
        t: &TaskTorque<N>,
    ) -> Result<Command<N>, Error>;
    /// A step refused before it reached the controller, recorded.
    fn refuse(&mut self, e: Error);
    /// The torque it applies now (N m): the last step's, or its fallback.
    fn applied(&self) -> Vector<N>;
}

impl<const N: usize> JointStep<N> for Typed<N> {
    fn period(&self) -> f64 {
        self.controller().period()
    }
    fn impedance(&self) -> &TargetImpedance<N> {
        self.controller().impedance()
    }
    fn law(&self) -> Law {
        self.controller().config().law
    }
    fn step_with(&mut self, m: &Measurement<N>, r: &Setpoint<N>) -> Result<Command<N>, Error> {
        Typed::step_with(self, m, r)
    }
    fn step_task(
        &mut self,
        m: &Measurement<N>,
        r: &Setpoint<N>,
        t: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        Typed::step_task(self, m, r, t)
    }
    fn refuse(&mut self, e: Error) {
        Typed::refuse(self, e);
    }
    fn applied(&self) -> Vector<N> {
        *self.state().applied()
    }
}

impl<const N: usize> JointStep<N> for Computed<N> {
    fn period(&self) -> f64 {
        self.ctrl.period()
    }
    fn impedance(&self) -> &TargetImpedance<N> {
        self.ctrl.impedance()
    }
    /// PD's preset: a model-based law has no network or observer.
    fn law(&self) -> Law {
        Law::Pd
    }
    fn step_with(&mut self, m: &Measurement<N>, r: &Setpoint<N>) -> Result<Command<N>, Error> {
        self.ctrl.step(&mut self.state, m, r)
    }
    fn step_task(
        &mut self,
        m: &Measurement<N>,
        r: &Setpoint<N>,
        t: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        self.ctrl.step_task(&mut self.state, m, r, t)
    }
    fn refuse(&mut self, e: Error) {
        self.ctrl.refuse(&mut self.state, e);
    }
    fn applied(&self) -> Vector<N> {
        self.state.applied
    }
}

/// The row of a table for t_k = k·Ts.
fn row_of(t: f64, ts: f64) -> usize {
    libm::round(t / ts) as usize
}

/// The last step of an outer loop, with what it was given: the command,
/// the commanded position and rates p_c, ṗ_c, p̈_c (the target's; without
/// one, the held target after its filter, p_t, at rest) and the wrench.
#[derive(Copy, Clone, Debug, PartialEq)]
pub(crate) struct LastStep<const N: usize> {
    /// The step's command.
    pub cmd: CartesianCommand<N>,
    /// p_c, ṗ_c, p̈_c (m, m/s, m/s²).
    pub commanded: [Vector<3>; 3],
    /// F_e (N, N m).
    pub wrench: [f64; 6],
}

impl<const N: usize> LastStep<N> {
    /// The step of `cmd` with its `target` and `wrench`.
    pub fn new(cmd: CartesianCommand<N>, target: Option<&PoseTarget>, wrench: [f64; 6]) -> Self {
        let commanded = match target {
            Some(t) => [t.p, t.dp, t.ddp],
            None => [cmd.target.0, Vector::zeros(), Vector::zeros()],
        };
        Self {
            cmd,
            commanded,
            wrench,
        }
    }

    /// The step as the core's task rows record it.
    fn task_step(&self) -> TaskStep {
        TaskStep {
            command: dy::CartesianCommand::of(&self.cmd),
            commanded: self.commanded,
            wrench: self.wrench,
        }
    }
}

/// One Cartesian step of `outer` (its state `state`) with the core's joint
/// controller `joint` (SPEC §16, (C0)–(C5)), under the fault semantics of
/// every step: a step the joint controller refuses is recorded there (the
/// fault, its fallback as the applied torque); so is one the outer loop
/// refuses before the joint step runs (a non-finite q, wrench or target), as
/// a front's refused call is ([`Tracker::refuse`](adaptimp::control::tracker::Tracker::refuse)).
pub(crate) fn cartesian_step<const N: usize, J: JointStep<N> + ?Sized>(
    outer: &CartesianImpedance<N, Chain<N>>,
    state: &mut CartesianState<N>,
    joint: &mut J,
    m: &CartesianMeasurement<N>,
    target: Option<&PoseTarget>,
) -> Result<CartesianCommand<N>, Error> {
    let mut ran = false;
    let result = outer.step_with(state, m, target, |jm, r, task| {
        ran = true;
        match task {
            Some(t) => joint.step_task(jm, r, t),
            None => joint.step_with(jm, r),
        }
    });
    if let Err(e) = result {
        if !ran {
            joint.refuse(e);
        }
    }
    result
}

/// A row of a flat table as the core's pose target
/// ([`adaptimp::dynamic::pose_target`]); a short row is NaN, which the
/// step refuses.
pub(crate) fn pose_target(row: &[f64]) -> PoseTarget {
    adaptimp::dynamic::pose_target(row.first_chunk().unwrap_or(&[f64::NAN; TARGET_LEN]))
}

/// How a run copies its outer loop for the Python code it calls (a
/// progress callback): the copy a binding keeps as the type `part` (None:
/// another type), from the outer loop's state and the run's last step (None:
/// none taken yet). The binding that starts the run knows the rest of it.
pub(crate) type OuterCopy<'a, const N: usize> =
    dyn Fn(TypeId, &CartesianState<N>, Option<&LastStep<N>>) -> Option<Box<dyn Any + Send>> + 'a;

/// The outer loop and the joint controller behind it as the loop's
/// [`Control`]: [`Control::step_with_wrench`] runs
/// [`CartesianImpedance::step_with`] with the measured wrench and the
/// joint controller's step, the commanded pose of the row from the table.
/// The step is kept in `last`, where the recorder reads the row's task
/// quantities (no copy of them per row).
struct Cartesian<'a, const N: usize, J: ?Sized> {
    outer: &'a CartesianImpedance<N, Chain<N>>,
    state: &'a mut CartesianState<N>,
    joint: &'a mut J,
    targets: Option<&'a [f64]>,
    clock: &'a Cell<f64>,
    last: &'a RefCell<Option<LastStep<N>>>,
    /// Whether `last` holds a step the recorder has not recorded yet.
    pending: &'a Cell<bool>,
    copy: &'a OuterCopy<'a, N>,
}

impl<const N: usize, J: JointStep<N> + ?Sized> View for Cartesian<'_, N, J> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        (self.copy)(part, self.state, self.last.borrow().as_ref()).or_else(|| self.joint.copy(part))
    }
}

/// The state of a replay between two rows, as a [`View`].
struct Replayed<'a, const N: usize, J: ?Sized> {
    state: &'a CartesianState<N>,
    last: Option<&'a LastStep<N>>,
    joint: &'a J,
    copy: &'a OuterCopy<'a, N>,
}

impl<const N: usize, J: JointStep<N> + ?Sized> View for Replayed<'_, N, J> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        (self.copy)(part, self.state, self.last).or_else(|| self.joint.copy(part))
    }
}

impl<const N: usize, J: JointStep<N> + ?Sized> Cartesian<'_, N, J> {
    fn step_cartesian(
        &mut self,
        m: &Measurement<N>,
        wrench: &[f64; 6],
    ) -> Result<Command<N>, Error> {
        let target = self.targets.map(|tab| {
            let k = row_of(self.clock.get(), self.outer.period());
            pose_target(&tab[k * TARGET_LEN..(k + 1) * TARGET_LEN])
        });
        let meas = CartesianMeasurement {
            q: m.x,
            dq: m.dx,
            wrench: Vector::<6>::from(*wrench),
        };
        let cmd = cartesian_step(self.outer, self.state, self.joint, &meas, target.as_ref())?;
        let mut slot = self.last.borrow_mut();
        let last = slot.insert(LastStep::new(cmd, target.as_ref(), *wrench));
        self.pending.set(true);
        Ok(last.cmd.joint)
    }
}

impl<const N: usize, J: JointStep<N> + ?Sized> WrenchControl<N> for Cartesian<'_, N, J> {
    fn period(&self) -> f64 {
        self.outer.period()
    }
    fn target(&self) -> &TargetImpedance<N> {
        self.joint.impedance()
    }
    /// The Cartesian step; on an error (of the outer loop or of the joint
    /// step, recorded in the joint controller: [`cartesian_step`]) its
    /// fallback, the torque it now applies.
    fn step_with_wrench(
        &mut self,
        m: &Measurement<N>,
        wrench: &[f64; 6],
        _c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        match self.step_cartesian(m, wrench) {
            Ok(cmd) => (cmd.tau_sat, Ok(cmd)),
            Err(e) => (self.joint.applied(), Err(e)),
        }
    }
}

/// The joint rows, the task rows and the task-space metrics of every row.
struct TaskRecorder<'a, const N: usize, const M: usize> {
    joint: &'a mut Rows,
    task: &'a mut TaskRows,
    metrics: &'a mut RowMetrics,
    /// A row the metrics refused (none: every row fits by construction).
    refused: Option<Error>,
    width: core::marker::PhantomData<[(); M]>,
    last: &'a RefCell<Option<LastStep<N>>>,
    pending: &'a Cell<bool>,
}

impl<const N: usize, const M: usize> Recorder<N> for TaskRecorder<'_, N, M> {
    fn record(&mut self, r: &Row<N>) {
        self.pending.set(false);
        self.joint.record(r);
        let step = self.last.borrow().as_ref().map(LastStep::task_step);
        let nan = [Vector::<3>::from_element(f64::NAN); 3];
        let (pc, z1) = match &step {
            Some(s) => (&s.commanded, s.z1()),
            None => (&nan, nan[0]),
        };
        self.task.record(step.as_ref(), &z1);
        let pushed = self.metrics.push(
            r.t,
            [r.x.as_slice(), r.dx.as_slice(), r.ddx.as_slice()],
            [pc[0].as_slice(), pc[1].as_slice(), pc[2].as_slice()],
            z1.as_slice(),
            [r.tau.as_slice(), r.tau_sat.as_slice(), r.tau_e.as_slice()],
        );
        if let Err(e) = pushed {
            self.refused.get_or_insert(e);
        }
    }
}

/// What a Cartesian run gives back: the joint rows, the task rows and the
/// SPEC §12 metrics of task space (z1 = p_d − p, m = 3).
pub type CartesianOut = (Rows, TaskRows, Metrics);

fn invalid(what: &'static str, reason: &'static str) -> RunError {
    RunError::Core(Error::Invalid { what, reason }, None)
}

/// The closed loop of the outer loop `outer` (its state `state`) in front of
/// the joint controller `joint` on MuJoCo (`sim` as `spec` describes it),
/// from both controllers' current states (not reset: a used controller goes
/// on). Returns the records and the task-space metrics, and leaves the last
/// step taken in `last` (also when the run ends with an error); when it ends
/// with an error (Ctrl-C, a diverged plant), the task rows of the steps it
/// took in `partial` (the controller's log keeps them).
#[allow(clippy::too_many_arguments)]
pub(crate) fn simulate_mujoco<const N: usize, J: JointStep<N> + ?Sized>(
    outer: &CartesianImpedance<N, Chain<N>>,
    state: &mut CartesianState<N>,
    joint: &mut J,
    last: &mut Option<LastStep<N>>,
    sim: &mut Sim,
    spec: &MujocoSpec,
    run: &CartesianRun<'_>,
    hooks: &mut dyn Hooks,
    partial: &mut Option<TaskRows>,
    copy: &OuterCopy<'_, N>,
) -> Result<CartesianOut, RunError> {
    if N <= 3 {
        run_m::<N, 3, J>(
            outer, state, joint, last, sim, spec, run, hooks, partial, copy,
        )
    } else {
        run_m::<N, N, J>(
            outer, state, joint, last, sim, spec, run, hooks, partial, copy,
        )
    }
}

/// [`simulate_mujoco`] with the metrics' accumulator of M = max(N, 3) slots
/// (as [`metrics_of`](super::dynamic::metrics_of) takes for the same rows).
#[allow(clippy::too_many_arguments)]
fn run_m<const N: usize, const M: usize, J: JointStep<N> + ?Sized>(
    outer: &CartesianImpedance<N, Chain<N>>,
    state: &mut CartesianState<N>,
    joint: &mut J,
    last: &mut Option<LastStep<N>>,
    sim: &mut Sim,
    spec: &MujocoSpec,
    run: &CartesianRun<'_>,
    hooks: &mut dyn Hooks,
    partial: &mut Option<TaskRows>,
    copy: &OuterCopy<'_, N>,
) -> Result<CartesianOut, RunError> {
    let total = checked(outer, &*joint, run)?;
    let every = run.every.max(1);
    let kept = usize::try_from(total.div_ceil(every)).unwrap_or(usize::MAX);
    let mut rec = Rows::new(N, kept, every)?;
    let mut task = TaskRows::new(N, kept, every)?;
    let ones = [1.0; N];
    let mut metrics = RowMetrics::new(N, 3, false, run.settle, [&ones, &ones, &ones])?;
    let clock = Cell::new(0.0);
    // This run's steps (the previous run's last step is kept until one is taken).
    let steps = RefCell::new(None);
    let pending = Cell::new(false);
    let mut ctrl = Cartesian {
        outer,
        state,
        joint,
        targets: run.targets,
        clock: &clock,
        last: &steps,
        pending: &pending,
        copy,
    };
    let law = ctrl.joint.law();
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
    let mut recorder = TaskRecorder {
        joint: &mut rec,
        task: &mut task,
        metrics: &mut metrics,
        refused: None,
        width: core::marker::PhantomData::<[(); M]>,
        last: &steps,
        pending: &pending,
    };
    let result = drive_mujoco(&mut ctrl, &Clock(&clock), on, hooks, &mut recorder);
    let result = match recorder.refused {
        Some(e) => result.and(Err(RunError::Core(e, None))),
        None => result,
    };
    let taken = steps.into_inner();
    if taken.is_some() {
        task.last = taken.as_ref().map(LastStep::task_step);
        *last = taken;
    }
    if let Err(e) = result {
        // A step taken in the period the error stopped: its task row too
        // (the controller's clock counts it).
        if pending.get() {
            if let Some(s) = task.last {
                task.record(Some(&s), &s.z1());
            }
        }
        *partial = Some(task);
        return Err(e);
    }
    Ok((rec, task, metrics.finish()))
}

/// The steps of `run`, checked before it starts: the joint controller at the
/// outer loop's period, a pose target per step, nothing that acts on τe.
fn checked<const N: usize, J: JointStep<N> + ?Sized>(
    outer: &CartesianImpedance<N, Chain<N>>,
    joint: &J,
    run: &CartesianRun<'_>,
) -> Result<u64, RunError> {
    let ts = outer.period();
    if joint.period() != ts {
        return Err(invalid(
            "joint controller of a Cartesian impedance",
            "needs the same Ts as the Cartesian impedance",
        ));
    }
    let total = adaptimp::sim::simulator::steps(run.t_final, ts)?;
    if let Some(tab) = run.targets {
        let need = usize::try_from(total)
            .unwrap_or(usize::MAX)
            .saturating_mul(TARGET_LEN);
        if tab.len() < need {
            return Err(invalid("targets", "needs one pose target per step"));
        }
    }
    reads_the_wrench::<N>(joint.law(), run.items, run.fault)?;
    Ok(total)
}

/// A Cartesian controller (the core's, or one written in Python with the
/// wrench hook) reads the wrench, not τe: the disturbances of `items` (for
/// `law`'s scenario) and the `fault` must not act on τe alone, which would
/// act on nothing.
pub(crate) fn reads_the_wrench<const N: usize>(
    law: Law,
    items: &Items,
    fault: Option<&FaultSpec>,
) -> Result<(), RunError> {
    let s = super::dynamic::scenario::<N>(adaptimp::schema::Preset::Robot, law, items)
        .map_err(|e| RunError::Core(e.error, None))?;
    if s.disturbances()?
        .params()
        .noise_tau_e
        .iter()
        .any(|v| *v != 0.0)
    {
        return Err(invalid(
            "noise_tau_e",
            "a Cartesian controller reads the wrench F_e, not τe: sensor noise on τe would act on nothing",
        ));
    }
    if let Some(FaultSpec {
        kind: FaultKind::ForceBias(_),
        ..
    }) = fault
    {
        return Err(invalid(
            "force_bias",
            "a Cartesian controller reads the wrench F_e, not τe: a bias on τe would act on nothing",
        ));
    }
    Ok(())
}

/// A Cartesian step per row of recorded tables, the core's alone (for the
/// cost of the controller without a plant): q, q̇ (K × n), the wrench (K ×
/// 6), the pose targets (K × [`TARGET_LEN`], or none: held). Writes sat(τ)
/// rows into `out`. Errors name the row.
#[allow(clippy::too_many_arguments)]
pub(crate) fn replay<const N: usize, J: JointStep<N> + ?Sized>(
    outer: &CartesianImpedance<N, Chain<N>>,
    state: &mut CartesianState<N>,
    joint: &mut J,
    last: &mut Option<LastStep<N>>,
    rows: usize,
    tables: [&[f64]; 3],
    targets: Option<&[f64]>,
    out: &mut Vec<f64>,
    hooks: &mut dyn Hooks,
    copy: &OuterCopy<'_, N>,
) -> Result<(), RunError> {
    let [q, dq, wrench] = tables;
    if q.len() < rows * N || dq.len() < rows * N || wrench.len() < rows * 6 {
        return Err(invalid("rows", "every table needs K rows of its width"));
    }
    if targets.is_some_and(|t| t.len() < rows * TARGET_LEN) {
        return Err(invalid("targets", "needs one pose target per row"));
    }
    for k in 0..rows {
        if k > 0 && k % 64 == 0 {
            let view = Replayed {
                state: &*state,
                last: last.as_ref(),
                joint: &*joint,
                copy,
            };
            if !hooks.report(k as u64, rows as u64, &view) {
                return Err(RunError::Stopped);
            }
        }
        let m = CartesianMeasurement {
            q: Vector::<N>::from_column_slice(&q[k * N..(k + 1) * N]),
            dq: Some(Vector::<N>::from_column_slice(&dq[k * N..(k + 1) * N])),
            wrench: Vector::<6>::from_column_slice(&wrench[k * 6..(k + 1) * 6]),
        };
        let target = targets.map(|t| pose_target(&t[k * TARGET_LEN..(k + 1) * TARGET_LEN]));
        let cmd = cartesian_step(outer, state, joint, &m, target.as_ref())
            .map_err(|e| RunError::Core(e, Some(k as u64)))?;
        out.extend_from_slice(cmd.joint.tau_sat.as_slice());
        *last = Some(LastStep::new(cmd, target.as_ref(), m.wrench.into()));
    }
    // The last row reported too (a progress bar ends at 100 %).
    let view = Replayed {
        state: &*state,
        last: last.as_ref(),
        joint: &*joint,
        copy,
    };
    if rows > 0 && !hooks.report(rows as u64, rows as u64, &view) {
        return Err(RunError::Stopped);
    }
    Ok(())
}
