//! The Cartesian controller in the run-time closed loop (SPEC §13.1,
//! §16): the outer loop and its joint controller as the loop's controller,
//! with the measured wrench, recorded in task space ([`TaskRows`]) and
//! measured by the one accumulator of the SPEC §12 metrics.

use super::super::cartesian::{CartesianImpedance, CartesianState, Joint};
use super::super::sized::each;
use super::super::values::mismatch;
use super::rows::{TaskMetrics, TypedTaskStep};
use super::{
    drive, Disturbances, Hooks, Injected, Injection, Metrics, Plant, Rows, Run, RunError, TaskRows,
};
use crate::cartesian::{self, PoseTarget};
use crate::control::impedance::TargetImpedance;
use crate::control::io::{self, WrenchControl};
use crate::error::Error;
use crate::sim::record::{Recorder, Row};
use crate::sim::simulator;
use crate::trajectory::{self, Clock};
use crate::types::Vector;
use core::cell::{Cell, RefCell};

/// The joint controller behind a typed outer loop in the closed loop
/// ([`drive_cartesian`]): a [`JointLaw`](cartesian::JointLaw) that gives
/// the target impedance it realises and the torque it applies now. The
/// paper's laws and computed torque are two; a front may wrap its own.
pub trait LoopJoint<const N: usize>: cartesian::JointLaw<N> {
    /// The target impedance (3) (for the impedance residual of SPEC §12).
    fn target(&self) -> &TargetImpedance<N>;
    /// The torque it applies now (N m): the last step's, or its fallback.
    fn applied(&self) -> Vector<N>;
}

impl<const N: usize, S: AsRef<[f64]> + AsMut<[f64]>> LoopJoint<N>
    for (
        &crate::control::controller::Controller<N, crate::networks::rbf::AnyBasis<N>>,
        &mut crate::control::state::State<N, S>,
    )
{
    fn target(&self) -> &TargetImpedance<N> {
        self.0.impedance()
    }
    fn applied(&self) -> Vector<N> {
        *self.1.applied()
    }
}

impl<const N: usize> LoopJoint<N>
    for (
        &cartesian::ComputedTorque<N>,
        &mut cartesian::ComputedState<N>,
    )
{
    fn target(&self) -> &TargetImpedance<N> {
        self.0.impedance()
    }
    fn applied(&self) -> Vector<N> {
        self.1.applied
    }
}

/// The typed outer loop and the joint controller behind it as the loop's
/// controller ([`WrenchControl`]): the Cartesian step with the measured
/// wrench and the row's pose target, the step kept for the recorder (and
/// for a front's copy of the state between two steps: [`state`](Self::state),
/// [`last`](Self::last), [`joint`](Self::joint)).
pub struct CartesianLoop<'a, const N: usize, J> {
    outer: &'a cartesian::CartesianImpedance<N, cartesian::Chain<N>>,
    state: &'a mut cartesian::CartesianState<N>,
    joint: J,
    targets: Option<&'a [PoseTarget]>,
    clock: &'a Cell<f64>,
    last: &'a RefCell<Option<TypedTaskStep<N>>>,
    pending: &'a Cell<bool>,
}

impl<const N: usize, J> CartesianLoop<'_, N, J> {
    /// The outer loop's state now.
    pub fn state(&self) -> &cartesian::CartesianState<N> {
        self.state
    }
    /// The joint controller.
    pub fn joint(&self) -> &J {
        &self.joint
    }
    /// The last step this run took (none yet: `None`).
    pub fn last(&self) -> Option<TypedTaskStep<N>> {
        *self.last.borrow()
    }
}

impl<const N: usize, J: LoopJoint<N>> WrenchControl<N> for CartesianLoop<'_, N, J> {
    fn period(&self) -> f64 {
        self.outer.period()
    }
    fn target(&self) -> &TargetImpedance<N> {
        self.joint.target()
    }
    fn step_with_wrench(
        &mut self,
        m: &io::Measurement<N>,
        wrench: &[f64; 6],
        _c: &trajectory::Setpoint<N>,
    ) -> (Vector<N>, Result<io::Command<N>, Error>) {
        let target = self.targets.map(|tab| {
            let k = libm::round(self.clock.get() / self.outer.period()) as usize;
            tab[k]
        });
        let meas = cartesian::CartesianMeasurement {
            q: m.x,
            dq: m.dx,
            wrench: Vector::<6>::from(*wrench),
        };
        match self
            .outer
            .step_joint(self.state, &mut self.joint, &meas, target.as_ref())
        {
            Ok(cmd) => {
                *self.last.borrow_mut() = Some(TypedTaskStep::new(cmd, target.as_ref(), *wrench));
                self.pending.set(true);
                (cmd.joint.tau_sat, Ok(cmd.joint))
            }
            Err(e) => (self.joint.applied(), Err(e)),
        }
    }
}

/// The joint rows, the task rows and the task-space metrics of every row.
struct TaskRecorder<'a, const N: usize, const M: usize> {
    joint: &'a mut Rows,
    task: &'a mut TaskRows,
    metrics: &'a mut TaskMetrics<M>,
    last: &'a RefCell<Option<TypedTaskStep<N>>>,
    pending: &'a Cell<bool>,
}

impl<const N: usize, const M: usize> Recorder<N> for TaskRecorder<'_, N, M> {
    fn record(&mut self, r: &Row<N>) {
        self.pending.set(false);
        self.joint.record(r);
        let step = self.last.borrow().as_ref().map(TypedTaskStep::run_time);
        let nan = [Vector::<3>::from_element(f64::NAN); 3];
        let (pc, z1) = match step.as_ref() {
            Some(s) => (&s.commanded, s.z1()),
            None => (&nan, nan[0]),
        };
        self.task.record(step.as_ref(), &z1);
        self.metrics.push(
            r.t,
            [r.x.as_slice(), r.dx.as_slice(), r.ddx.as_slice()],
            [pc[0].as_slice(), pc[1].as_slice(), pc[2].as_slice()],
            z1.as_slice(),
            [r.tau.as_slice(), r.tau_sat.as_slice(), r.tau_e.as_slice()],
        );
    }
}

/// How a Cartesian loop of the typed outer loop runs: the plant, its
/// disturbances and faults, the hooks. The run-time loop's own plant
/// ([`simulate_cartesian`]), or a front's (a physics engine it steps, with
/// the copies of the controllers it shows its callbacks).
pub trait CartesianDriver<const N: usize, J> {
    /// How a run ends when it does not finish.
    type Error: From<Error>;
    /// The core's loop ([`simulate_disturbed`](crate::sim::simulator::simulate_disturbed))
    /// of `ctrl` along `clock` (the loop's time into the cell the controller
    /// reads its row from), every row to `rec`.
    fn drive<R: Recorder<N>>(
        self,
        ctrl: &mut CartesianLoop<'_, N, J>,
        clock: &Clock<'_>,
        rec: &mut R,
    ) -> Result<(), Self::Error>;
}

/// The closed loop of the typed outer loop `outer` (its state `state`) in
/// front of `joint`, run by `driver`, from both controllers' current
/// states: the commanded pose of row k the k-th of `targets` (checked
/// against the run's length by the caller; none: the last target held),
/// the joint rows to `rows`, the task rows to `task` and the last step
/// taken to `last` (also those before an error; the step of the period an
/// error stopped recorded too); returns the SPEC §12 metrics in task space
/// (z1 = p_d − p, m = 3; the impedance residual NaN) after `settle` (s).
/// What [`simulate_cartesian`] runs for N joints; a front with its own
/// plant gives its own `driver`.
#[allow(clippy::too_many_arguments)]
pub fn drive_cartesian<const N: usize, J: LoopJoint<N>, D: CartesianDriver<N, J>>(
    driver: D,
    outer: &cartesian::CartesianImpedance<N, cartesian::Chain<N>>,
    state: &mut cartesian::CartesianState<N>,
    joint: J,
    targets: Option<&[PoseTarget]>,
    settle: f64,
    rows: &mut Rows,
    task: &mut TaskRows,
    last: &mut Option<TypedTaskStep<N>>,
) -> Result<Metrics, D::Error> {
    if N <= 3 {
        cartesian_m::<N, 3, J, D>(
            driver, outer, state, joint, targets, settle, rows, task, last,
        )
    } else {
        cartesian_m::<N, N, J, D>(
            driver, outer, state, joint, targets, settle, rows, task, last,
        )
    }
}

/// [`drive_cartesian`] with the metrics in M = max(N, 3) slots.
#[allow(clippy::too_many_arguments)]
fn cartesian_m<const N: usize, const M: usize, J: LoopJoint<N>, D: CartesianDriver<N, J>>(
    driver: D,
    outer: &cartesian::CartesianImpedance<N, cartesian::Chain<N>>,
    state: &mut cartesian::CartesianState<N>,
    joint: J,
    targets: Option<&[PoseTarget]>,
    settle: f64,
    rows: &mut Rows,
    task: &mut TaskRows,
    last: &mut Option<TypedTaskStep<N>>,
) -> Result<Metrics, D::Error> {
    let ones = [1.0; N];
    let mut metrics = TaskMetrics::<M>::new(N, 3, false, settle, [&ones, &ones, &ones])?;
    let clock = Cell::new(0.0);
    // This run's steps (the previous run's last step is kept until one is taken).
    let steps = RefCell::new(None);
    let pending = Cell::new(false);
    let mut ctrl = CartesianLoop {
        outer,
        state,
        joint,
        targets,
        clock: &clock,
        last: &steps,
        pending: &pending,
    };
    let mut recorder = TaskRecorder {
        joint: rows,
        task,
        metrics: &mut metrics,
        last: &steps,
        pending: &pending,
    };
    let result = driver.drive(&mut ctrl, &Clock(&clock), &mut recorder);
    let taken = steps.into_inner();
    if taken.is_some() {
        task.last = taken.as_ref().map(TypedTaskStep::run_time);
        *last = taken;
    }
    if result.is_err() && pending.get() {
        // A step taken in the period the error stopped: its task row too
        // (the controller's clock counts it).
        if let Some(s) = task.last {
            task.record(Some(&s), &s.z1());
        }
    }
    result?;
    Ok(metrics.finish())
}

/// The steps of a Cartesian run of `t_final` (s) at the outer loop's
/// period `ts` (s), checked before it starts: the joint controller at the
/// same period (`joint_ts`), a pose target per step (`targets`: how many
/// the run has, none: the last target held).
pub fn cartesian_steps(
    ts: f64,
    joint_ts: f64,
    t_final: f64,
    targets: Option<usize>,
) -> Result<u64, Error> {
    if joint_ts != ts {
        return Err(Error::Invalid {
            what: "joint controller of a Cartesian impedance",
            reason: "needs the same Ts as the Cartesian impedance",
        });
    }
    let total = simulator::steps(t_final, ts)?;
    if targets.is_some_and(|t| (t as u64) < total) {
        return Err(Error::Invalid {
            what: "targets",
            reason: "needs one pose target per step",
        });
    }
    Ok(total)
}

/// A Cartesian controller reads the wrench F_e, not τe: a run that puts
/// sensor noise on τe (`noise_on_tau_e`) or a bias on it (`force_bias`)
/// would disturb nothing, and is refused.
pub fn reads_the_wrench(noise_on_tau_e: bool, force_bias: bool) -> Result<(), Error> {
    if noise_on_tau_e {
        return Err(Error::Invalid {
            what: "noise_tau_e",
            reason: "a Cartesian controller reads the wrench F_e, not τe: sensor noise on τe would act on nothing",
        });
    }
    if force_bias {
        return Err(Error::Invalid {
            what: "force_bias",
            reason: "a Cartesian controller reads the wrench F_e, not τe: a bias on τe would act on nothing",
        });
    }
    Ok(())
}

/// The closed loop of the Cartesian controller (SPEC §13.1, §16): the
/// outer loop `outer` (its state `state`) in front of `joint` on `plant`,
/// with the measured wrench, the commanded pose of row k the k-th of
/// `targets` (none: the last target held), for `run`. The joint rows go to
/// `rows` (xc, ẋc, ẍc NaN: the reference is in task space), the task rows
/// and the last step to `task` (also those before an error); returns the
/// SPEC §12 metrics in task space (z1 = p_d − p, m = 3; the impedance
/// residual NaN). From both controllers' current states. A disturbance or
/// a fault acting on τe alone is refused: the controller reads F_e.
#[allow(clippy::too_many_arguments)]
pub fn simulate_cartesian<S: AsRef<[f64]> + AsMut<[f64]>>(
    plant: &mut dyn Plant,
    outer: &CartesianImpedance,
    state: &mut CartesianState,
    joint: Joint<'_, S>,
    targets: Option<&[PoseTarget]>,
    run: &Run<'_>,
    hooks: &mut dyn Hooks,
    rows: &mut Rows,
    task: &mut TaskRows,
) -> Result<Metrics, RunError> {
    let n = outer.n();
    if plant.n() != n {
        return Err(mismatch("plant").into());
    }
    if rows.n() != n || task.n != n {
        return Err(mismatch("rows").into());
    }
    cartesian_steps(
        outer.period(),
        joint.period(),
        run.t_final,
        targets.map(<[PoseTarget]>::len),
    )?;
    let force_bias = matches!(
        run.injection,
        Some(Injection {
            fault: Injected::ForceBias(_),
            ..
        })
    );
    reads_the_wrench(
        run.disturbances.is_some_and(Disturbances::noise_on_tau_e),
        force_bias,
    )?;
    each!(&outer.inner, o, N => {
        let st = state.inner.get_mut::<N>().ok_or(mismatch("state"))?;
        let dist = match run.disturbances {
            Some(d) => Some(d.inner.get::<N>().ok_or(mismatch("disturbances"))?),
            None => None,
        };
        let on = OnPlant { plant, dist, run, hooks };
        let mut last = None;
        match joint {
            Joint::Adaptive(c, s) => {
                let c = c.inner.get::<N>().ok_or(mismatch("joint controller"))?;
                let s = s.inner.get_mut::<N>().ok_or(mismatch("joint state"))?;
                drive_cartesian(on, o, st, (&c.ctrl, s), targets, run.settle, rows, task, &mut last)
            }
            Joint::Computed(c, s) => {
                let c = c.inner.get::<N>().ok_or(mismatch("joint controller"))?;
                let s = s.inner.get_mut::<N>().ok_or(mismatch("joint state"))?;
                drive_cartesian(on, o, st, (&**c, s), targets, run.settle, rows, task, &mut last)
            }
        }
    })
}

/// The run-time loop's plant, disturbances, run and hooks as the driver of
/// [`drive_cartesian`].
struct OnPlant<'a, 'b, const N: usize> {
    plant: &'a mut dyn Plant,
    dist: Option<&'a crate::sim::disturb::Disturbances<N>>,
    run: &'a Run<'b>,
    hooks: &'a mut dyn Hooks,
}

impl<const N: usize, J: LoopJoint<N>> CartesianDriver<N, J> for OnPlant<'_, '_, N> {
    type Error = RunError;
    fn drive<R: Recorder<N>>(
        self,
        ctrl: &mut CartesianLoop<'_, N, J>,
        clock: &Clock<'_>,
        rec: &mut R,
    ) -> Result<(), RunError> {
        drive(
            self.plant, ctrl, clock, self.dist, self.run, self.hooks, rec,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cartesian_run_is_checked_before_it_starts() {
        assert_eq!(cartesian_steps(1e-3, 1e-3, 0.01, None), Ok(10));
        assert_eq!(cartesian_steps(1e-3, 1e-3, 0.01, Some(10)), Ok(10));
        let msg = |r: Result<_, Error>| r.map(|_: u64| ()).unwrap_err().to_string();
        assert_eq!(
            msg(cartesian_steps(1e-3, 1e-3, 0.01, Some(9))),
            "targets: needs one pose target per step"
        );
        assert!(msg(cartesian_steps(1e-3, 2e-3, 0.01, None)).contains("same Ts"));
        assert_eq!(reads_the_wrench(false, false), Ok(()));
        for (noise, bias, what) in [(true, false, "noise_tau_e"), (false, true, "force_bias")] {
            let e = reads_the_wrench(noise, bias).unwrap_err().to_string();
            assert!(e.starts_with(what), "{e}");
            assert!(e.contains("reads the wrench F_e, not τe"), "{e}");
        }
    }
}
