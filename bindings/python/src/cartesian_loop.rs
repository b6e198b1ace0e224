//! The Cartesian controller in the core's closed loop on MuJoCo (SPEC §13.1,
//! §16): the core's Cartesian loop ([`drive_cartesian`]: the outer loop over a
//! [`Chain`] and the joint controller behind it, recorded in task space,
//! measured by the one implementation of the SPEC §12 metrics), driven on
//! the MuJoCo plant by [`drive_mujoco`], with the copies of the controllers
//! the Python code a run calls reads ([`View`]).
//!
//! The commanded pose of row k is the k-th of a table (tabulated by the
//! caller from a path or a reference at t_k = k·Ts), or none: the last
//! target held.
//!
//! What each row records is the core's [`TaskRows`]: xc = p_c (the
//! commanded position; the filtered target p_t when held), ẋc, ẍc (ṗ_c, p̈_c;
//! zero when held), xd = p_d, z1 = p_d − p(q), ṗ_d, p̈_d, q_d, the
//! impedance's error and the wrench. The joint quantities (q, τ, sat(τ), τe,
//! ζ, the velocity used) are the joint controller's, as for a joint-space run.

use super::computed::ComputedStep;
use super::dynamic::{
    drive_mujoco, AdaptiveStep, FaultKind, FaultSpec, Hooks, Items, Metrics, OnMujoco, Rows,
    RunError, View,
};
use super::mujoco::MujocoSpec;
use adaptimp::cartesian::{
    CartesianCommand, CartesianImpedance, CartesianMeasurement, CartesianState, Chain, JointLaw,
    PoseTarget,
};
use adaptimp::control::config::Law;
use adaptimp::control::impedance::TargetImpedance;
use adaptimp::control::io::TaskTorque;
use adaptimp::control::io::{Command, Measurement, WrenchControl};
use adaptimp::dynamic::{
    self as dy, drive_cartesian, CartesianDriver, CartesianLoop, LoopJoint, TaskRows, TypedTaskStep,
};
use adaptimp::error::Error;
use adaptimp::sim::record::Recorder;
use adaptimp::trajectory::{Clock, Setpoint};
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use core::any::{Any, TypeId};
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
/// paper's laws ([`AdaptiveStep`]) or computed torque ([`ComputedStep`]), as the
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
    /// A step refused before it reached the controller (the outer loop's
    /// refusal of measurement `m`), recorded as the core's pairs record it.
    fn refuse(&mut self, m: &Measurement<N>, e: Error);
    /// The torque it applies now (N m): the last step's, or its fallback.
    fn applied(&self) -> Vector<N>;
}

impl<const N: usize> JointStep<N> for AdaptiveStep<'_, N> {
    fn period(&self) -> f64 {
        self.ctrl.period()
    }
    fn impedance(&self) -> &TargetImpedance<N> {
        self.ctrl.impedance()
    }
    fn law(&self) -> Law {
        self.ctrl.config().law
    }
    fn step_with(&mut self, m: &Measurement<N>, r: &Setpoint<N>) -> Result<Command<N>, Error> {
        self.ctrl.step(self.state, m, r)
    }
    fn step_task(
        &mut self,
        m: &Measurement<N>,
        r: &Setpoint<N>,
        t: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        AdaptiveStep::step_task(self, m, r, t)
    }
    fn refuse(&mut self, m: &Measurement<N>, e: Error) {
        self.ctrl.refuse_measured(self.state, m, e);
    }
    fn applied(&self) -> Vector<N> {
        *self.state.applied()
    }
}

impl<const N: usize> JointStep<N> for ComputedStep<'_, N> {
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
        self.ctrl.step(self.state, m, r)
    }
    fn step_task(
        &mut self,
        m: &Measurement<N>,
        r: &Setpoint<N>,
        t: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        self.ctrl.step_task(self.state, m, r, t)
    }
    fn refuse(&mut self, _m: &Measurement<N>, e: Error) {
        self.ctrl.refuse(self.state, e);
    }
    fn applied(&self) -> Vector<N> {
        self.state.applied
    }
}

/// A joint controller of the bindings as the core's Cartesian step drives
/// it ([`JointLaw`], [`LoopJoint`]). A step the outer loop refuses before
/// the joint step runs is recorded with its measurement
/// ([`JointStep::refuse`]), as the core's run-time step records it.
pub(crate) struct Joint<'a, J: ?Sized>(pub &'a mut J);

impl<const N: usize, J: JointStep<N> + ?Sized> JointLaw<N> for Joint<'_, J> {
    fn step(&mut self, m: &Measurement<N>, r: &Setpoint<N>) -> Result<Command<N>, Error> {
        self.0.step_with(m, r)
    }
    fn step_task(
        &mut self,
        m: &Measurement<N>,
        r: &Setpoint<N>,
        task: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        self.0.step_task(m, r, task)
    }
    fn refuse(&mut self, m: &Measurement<N>, error: Error) {
        self.0.refuse(m, error);
    }
}

impl<const N: usize, J: JointStep<N> + ?Sized> LoopJoint<N> for Joint<'_, J> {
    fn target(&self) -> &TargetImpedance<N> {
        self.0.impedance()
    }
    fn applied(&self) -> Vector<N> {
        self.0.applied()
    }
}

/// One Cartesian step of `outer` (its state `state`) with the core's joint
/// controller `joint` (SPEC §16, (C0)–(C5)), under the fault semantics of
/// every step ([`CartesianImpedance::step_joint`]).
pub(crate) fn cartesian_step<const N: usize, J: JointStep<N> + ?Sized>(
    outer: &CartesianImpedance<N, Chain<N>>,
    state: &mut CartesianState<N>,
    joint: &mut J,
    m: &CartesianMeasurement<N>,
    target: Option<&PoseTarget>,
) -> Result<CartesianCommand<N>, Error> {
    outer.step_joint(state, &mut Joint(joint), m, target)
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
pub(crate) type OuterCopy<'a, const N: usize> = dyn Fn(TypeId, &CartesianState<N>, Option<&TypedTaskStep<N>>) -> Option<Box<dyn Any + Send>>
    + 'a;

/// What a run ([`simulate_mujoco`], [`replay`]) goes on: the outer loop,
/// its state and last step, the joint controller behind it, and how the
/// run copies the outer loop for the Python code it calls.
pub(crate) struct OuterRun<'a, const N: usize> {
    pub outer: &'a CartesianImpedance<N, Chain<N>>,
    pub state: &'a mut CartesianState<N>,
    pub joint: &'a mut dyn JointStep<N>,
    pub last: &'a mut Option<TypedTaskStep<N>>,
    pub copy: &'a OuterCopy<'a, N>,
}

/// The state of a replay between two rows, as a [`View`].
struct Replayed<'a, const N: usize, J: ?Sized> {
    state: &'a CartesianState<N>,
    last: Option<&'a TypedTaskStep<N>>,
    joint: &'a J,
    copy: &'a OuterCopy<'a, N>,
}

impl<const N: usize, J: JointStep<N> + ?Sized> View for Replayed<'_, N, J> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        (self.copy)(part, self.state, self.last).or_else(|| self.joint.copy(part))
    }
}

/// The core's Cartesian loop as the MuJoCo loop steps it: its step, and
/// between two steps a copy of both controllers for the Python code the
/// run calls.
struct Shown<'c, 'l, 'j, const N: usize, J: ?Sized> {
    ctrl: &'c mut CartesianLoop<'l, N, Joint<'j, J>>,
    copy: &'c OuterCopy<'c, N>,
}

impl<const N: usize, J: JointStep<N> + ?Sized> View for Shown<'_, '_, '_, N, J> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        let last = self.ctrl.last();
        (self.copy)(part, self.ctrl.state(), last.as_ref())
            .or_else(|| self.ctrl.joint().0.copy(part))
    }
}

impl<const N: usize, J: JointStep<N> + ?Sized> WrenchControl<N> for Shown<'_, '_, '_, N, J> {
    fn period(&self) -> f64 {
        WrenchControl::period(self.ctrl)
    }
    fn target(&self) -> &TargetImpedance<N> {
        WrenchControl::target(self.ctrl)
    }
    fn step_with_wrench(
        &mut self,
        m: &Measurement<N>,
        wrench: &[f64; 6],
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        self.ctrl.step_with_wrench(m, wrench, c)
    }
}

/// The MuJoCo plant, its run and hooks as the driver of the core's
/// Cartesian loop.
struct OnSim<'a, 'c, const N: usize> {
    on: OnMujoco<'a>,
    hooks: &'a mut dyn Hooks,
    copy: &'a OuterCopy<'c, N>,
}

impl<'j, const N: usize, J: JointStep<N> + ?Sized> CartesianDriver<N, Joint<'j, J>>
    for OnSim<'_, '_, N>
{
    type Error = RunError;
    fn drive<R: Recorder<N>>(
        self,
        ctrl: &mut CartesianLoop<'_, N, Joint<'j, J>>,
        clock: &Clock<'_>,
        rec: &mut R,
    ) -> Result<(), RunError> {
        let mut shown = Shown {
            ctrl,
            copy: self.copy,
        };
        drive_mujoco(&mut shown, clock, self.on, self.hooks, rec)
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
/// on): the core's Cartesian loop ([`drive_cartesian`]). Returns the records
/// and the task-space metrics, and leaves the last step taken in `last`
/// (also when the run ends with an error); when it ends with an error
/// (Ctrl-C, a diverged plant), the task rows of the steps it took in
/// `partial` (the controller's log keeps them).
pub(crate) fn simulate_mujoco<const N: usize>(
    o: OuterRun<'_, N>,
    sim: &mut Sim,
    spec: &MujocoSpec,
    run: &CartesianRun<'_>,
    hooks: &mut dyn Hooks,
    partial: &mut Option<TaskRows>,
) -> Result<CartesianOut, RunError> {
    let OuterRun {
        outer,
        state,
        joint,
        last,
        copy,
    } = o;
    let total = checked(outer, &*joint, run)?;
    let every = run.every.max(1);
    let kept = adaptimp::dynamic::kept_rows(total, every);
    let mut rec = Rows::new(N, kept, every)?;
    let mut task = TaskRows::new(N, kept, every)?;
    // The table's rows as the core's pose targets (checked: one per step).
    let steps = usize::try_from(total).unwrap_or(usize::MAX);
    let targets: Option<Vec<PoseTarget>> = run.targets.map(|tab| {
        tab.chunks(TARGET_LEN)
            .take(steps)
            .map(pose_target)
            .collect()
    });
    let on = OnMujoco {
        sim,
        spec,
        t_final: run.t_final,
        settle: run.settle,
        items: run.items,
        law: joint.law(),
        fault: run.fault,
        abort: None,
    };
    let driver = OnSim { on, hooks, copy };
    let result = drive_cartesian(
        driver,
        outer,
        state,
        Joint(joint),
        targets.as_deref(),
        run.settle,
        &mut rec,
        &mut task,
        last,
    );
    match result {
        Ok(metrics) => Ok((rec, task, metrics)),
        Err(e) => {
            *partial = Some(task);
            Err(e)
        }
    }
}

/// The steps of `run`, checked before it starts: the joint controller at the
/// outer loop's period, a pose target per step, nothing that acts on τe.
fn checked<const N: usize, J: JointStep<N> + ?Sized>(
    outer: &CartesianImpedance<N, Chain<N>>,
    joint: &J,
    run: &CartesianRun<'_>,
) -> Result<u64, RunError> {
    let targets = run.targets.map(|tab| tab.len() / TARGET_LEN);
    let total = dy::cartesian_steps(outer.period(), joint.period(), run.t_final, targets)?;
    reads_the_wrench::<N>(joint.law(), run.items, run.fault)?;
    Ok(total)
}

/// A Cartesian controller (the core's, or one written in Python with the
/// wrench hook) reads the wrench, not τe: the disturbances of `items` (for
/// `law`'s scenario) and the `fault` must not act on τe alone, which would
/// act on nothing ([`dy::reads_the_wrench`]).
pub(crate) fn reads_the_wrench<const N: usize>(
    law: Law,
    items: &Items,
    fault: Option<&FaultSpec>,
) -> Result<(), RunError> {
    let s = super::dynamic::scenario::<N>(adaptimp::schema::Preset::Robot, law, items)
        .map_err(|e| RunError::Core(e.error, None))?;
    let noise = s
        .disturbances()?
        .params()
        .noise_tau_e
        .iter()
        .any(|v| *v != 0.0);
    let bias = matches!(
        fault,
        Some(FaultSpec {
            kind: FaultKind::ForceBias(_),
            ..
        })
    );
    Ok(dy::reads_the_wrench(noise, bias)?)
}

/// A Cartesian step per row of recorded tables, the core's alone (for the
/// cost of the controller without a plant): q, q̇ (K × n), the wrench (K ×
/// 6), the pose targets (K × [`TARGET_LEN`], or none: held). Writes sat(τ)
/// rows into `out`. Errors name the row.
pub(crate) fn replay<const N: usize>(
    o: OuterRun<'_, N>,
    rows: usize,
    tables: [&[f64]; 3],
    targets: Option<&[f64]>,
    out: &mut Vec<f64>,
    hooks: &mut dyn Hooks,
) -> Result<(), RunError> {
    let OuterRun {
        outer,
        state,
        joint,
        last,
        copy,
    } = o;
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
        *last = Some(TypedTaskStep::new(cmd, target.as_ref(), m.wrench.into()));
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
