//! The outer loop behind `adaptimp.CartesianImpedance`: the core's
//! run-time [`CartesianImpedance`](dy::CartesianImpedance) and its state
//! ([`OuterCore`]), slices in and out; a run reaches the const-generic outer
//! loop of its N through the core's accessors and [`for_joints`].

use super::cartesian_loop::{self, CartesianOut, CartesianRun, JointStep, OuterRun};
use super::computed::{ComputedCore, ComputedStep};
use super::dynamic::{AdaptiveStep, Hooks, JointCore, RunError, MAX_JOINTS, OTHER_N};
use super::mujoco::MujocoSpec;
use adaptimp::cartesian::{CartesianConfig, CartesianState, PoseTarget};
use adaptimp::dynamic::{self as dy, for_joints, ForJoints, HeldRotation};
use adaptimp::dynamic::{TaskRows, TaskStep, TypedTaskStep};
use adaptimp::error::Error;
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use core::any::{Any, TypeId};
use std::boxed::Box;
use std::vec::Vec;

/// The quantities of the last Cartesian step, by name.
pub(super) const LAST: [&str; 22] = [
    "q_d", "dq_d", "ddq_d", "p_d", "dp_d", "ddp_d", "R_d", "w_d", "dw_d", "p_t", "R_t", "error",
    "p", "R", "tau_e", "tau", "tau_sat", "z1", "p_c", "dp_c", "ddp_c", "wrench",
];

/// The quantities of the outer state, by name.
pub(super) const STATE: [&str; 9] = [
    "p_d",
    "R_d",
    "q_d",
    "dq_d",
    "posture",
    "stiffness",
    "stiffness_filtered",
    "offset",
    "wrench",
];

/// A step's measurement and target, n ≤ 7 values each.
pub struct StepIn<'a> {
    /// q (rad).
    pub q: &'a [f64],
    /// q̇ (rad/s), if measured.
    pub dq: Option<&'a [f64]>,
    /// F_e = [f; m] (N, N m).
    pub wrench: [f64; 6],
    /// The commanded pose, or none (hold).
    pub target: Option<PoseTarget>,
}

/// A joint controller written in the caller's language: given q, q̇, τe, the
/// joint reference (q_d, q̇_d, q̈_d; for the torque-level formulations the
/// commanded q_c, q̇_c, q̈_c) and, for those, the task torque
/// Jᵀ(K̃e + B(ṗ_c − J q̇)) (n) with the task Jacobian (6 × n, row-major),
/// write the torque to apply into the last slice.
pub type JointFn<'a> = dyn FnMut(
        &[f64],
        Option<&[f64]>,
        &[f64],
        [&[f64]; 3],
        Option<(&[f64], &[f64])>,
        &mut [f64],
    ) -> Result<(), Error>
    + 'a;

/// The outer loop over a chain of any n ≤ 7 with its state (the null-space
/// posture in it), the start it was given, its last step, the rotation a
/// target without one keeps, and the rows `CartesianController.log` has not
/// taken yet.
#[derive(Clone, Debug)]
pub struct OuterCore {
    outer: dy::CartesianImpedance,
    state: dy::CartesianState,
    q0: dy::Joints,
    last: Option<TaskStep>,
    /// The commanded rotation a target without one keeps.
    held: HeldRotation,
    /// Kept rows of the log, flat ([`LOG_WIDTH`] + n each), and their number.
    log: Vec<f64>,
    rows: usize,
}

impl OuterCore {
    /// The outer loop of `cfg` over `chain` at period `ts`, started at `q0`
    /// with the null-space `posture` (q0 if none).
    pub fn new(
        chain: &dy::Chain,
        cfg: CartesianConfig,
        ts: f64,
        q0: &[f64],
        posture: Option<&[f64]>,
    ) -> Result<Self, Error> {
        let outer = dy::CartesianImpedance::new(cfg, chain, ts)?;
        let mut state = outer.start(q0)?;
        outer.set_posture(&mut state, posture.unwrap_or(q0))?;
        Ok(Self {
            outer,
            state,
            q0: dy::Joints::from_slice(q0)?,
            last: None,
            held: HeldRotation::default(),
            log: Vec::new(),
            rows: 0,
        })
    }

    /// Ts (s).
    pub fn ts(&self) -> f64 {
        self.outer.period()
    }
    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.state.steps()
    }
    /// Whether the orientation is a task.
    pub fn orients(&self) -> bool {
        self.outer.orients()
    }

    /// Back to t = 0 at `q0` (the start's, if none), the posture kept.
    pub fn reset(&mut self, q0: Option<&[f64]>) -> Result<(), Error> {
        let q0 = match q0 {
            Some(q) => dy::Joints::from_slice(q)?,
            None => self.q0,
        };
        self.outer.restart(&mut self.state, &q0)?;
        self.q0 = q0;
        self.last = None;
        self.log.clear();
        self.rows = 0;
        Ok(())
    }

    /// The commanded rotation held when a target gives none.
    pub fn held(&self) -> &HeldRotation {
        &self.held
    }
    /// The same, to change.
    pub fn held_mut(&mut self) -> &mut HeldRotation {
        &mut self.held
    }

    /// Keep the last step's row of `CartesianController.log` (p_c, ṗ_c, p̈_c,
    /// p_d, ṗ_d, p̈_d, q_d, F_e, the error: [`LOG_WIDTH`] + n values).
    pub fn record(&mut self) {
        let Some(last) = &self.last else {
            return;
        };
        let c = &last.command;
        for v in last
            .commanded
            .iter()
            .chain([&c.compliant.p, &c.compliant.dp, &c.compliant.ddp])
        {
            self.log.extend_from_slice(v.as_slice());
        }
        self.log.extend_from_slice(&c.reference.x);
        self.log.extend_from_slice(&last.wrench);
        self.log.extend_from_slice(c.error.as_slice());
        self.rows += 1;
    }

    /// The rows kept since the last call, flat, and their number.
    pub fn take_log(&mut self) -> (Vec<f64>, usize) {
        let rows = core::mem::replace(&mut self.rows, 0);
        (core::mem::take(&mut self.log), rows)
    }

    /// The null-space posture (rad).
    pub fn set_posture(&mut self, posture: &[f64]) -> Result<(), Error> {
        self.outer.set_posture(&mut self.state, posture)
    }

    /// The stiffness asked for (N/m, N m/rad).
    pub fn set_stiffness(&mut self, kd: [f64; 3], kd_rot: [f64; 3]) -> Result<(), Error> {
        self.outer
            .set_stiffness(&mut self.state, &kd.into(), &kd_rot.into())
    }

    /// Check a commanded pose as a step would, changing nothing.
    pub fn check_target(&self, target: &PoseTarget) -> Result<(), Error> {
        self.outer.check_target(target)
    }

    /// The outer loop alone: one committed step.
    pub fn reference(
        &mut self,
        target: Option<&PoseTarget>,
        wrench: [f64; 6],
    ) -> Result<(), Error> {
        let cmd = self
            .outer
            .reference(&mut self.state, target, &wrench.into())?;
        self.last = Some(TaskStep::new(cmd, target, wrench));
        Ok(())
    }

    fn measurement<'a>(m: &StepIn<'a>) -> dy::CartesianMeasurement<'a> {
        dy::CartesianMeasurement {
            q: m.q,
            dq: m.dq,
            wrench: Vector::<6>::from(m.wrench),
        }
    }

    /// One step with the core's joint controller `joint`.
    pub fn step_tracker(&mut self, joint: JointRef<'_>, m: &StepIn<'_>) -> Result<(), Error> {
        let joint = match joint {
            JointRef::Adaptive(c) => dy::Joint::Adaptive(&c.ctrl, &mut c.state),
            JointRef::Computed(c) => dy::Joint::Computed(&c.ctrl, &mut c.state),
        };
        let target = m.target.as_ref();
        let cmd = self
            .outer
            .step(&mut self.state, joint, &Self::measurement(m), target)?;
        self.last = Some(TaskStep::new(cmd, target, m.wrench));
        Ok(())
    }

    /// One step with a joint controller of the caller's.
    pub fn step_joint(&mut self, m: &StepIn<'_>, joint: &mut JointFn<'_>) -> Result<(), Error> {
        let target = m.target.as_ref();
        let cmd =
            self.outer
                .step_with(&mut self.state, &Self::measurement(m), target, |input| {
                    let n = input.measurement.x.len();
                    let mut tau = dy::Joints::zeros(n)?;
                    // J (6 × n) row-major, as the caller's code reads it.
                    let mut rows = [0.0; 6 * MAX_JOINTS];
                    let task = input.task.as_ref().map(|t| {
                        let j = t.jacobian.matrix();
                        for (k, v) in rows[..6 * n].iter_mut().enumerate() {
                            *v = j[(k / n, k % n)];
                        }
                        (t.torque, &rows[..6 * n])
                    });
                    let r = &input.reference;
                    let mi = &input.measurement;
                    joint(mi.x, mi.dx, mi.tau_e, [r.x, r.dx, r.ddx], task, &mut tau)?;
                    Ok(tau)
                })?;
        self.last = Some(TaskStep::new(cmd, target, m.wrench));
        Ok(())
    }

    /// The last step's applied torque sat(τ) (N m), first n values (NaN
    /// before a step): `last("tau_sat")` without its name's lookup or a
    /// vector made.
    pub fn applied(&self) -> [f64; MAX_JOINTS] {
        let mut out = [f64::NAN; MAX_JOINTS];
        if let Some(last) = &self.last {
            let tau = &last.command.joint.tau_sat;
            out[..tau.len()].copy_from_slice(tau);
        }
        out
    }

    /// A quantity of the last step (see [`LAST`]).
    pub fn last(&self, what: usize) -> Vec<f64> {
        let n = self.outer.n();
        let Some(last) = &self.last else {
            let width = match LAST[what] {
                "R_d" | "R_t" | "R" => 9,
                "q_d" | "dq_d" | "ddq_d" | "tau_e" | "tau" | "tau_sat" | "z1" => n,
                "error" | "wrench" => 6,
                _ => 3,
            };
            return std::vec![f64::NAN; width];
        };
        let c = &last.command;
        let v3 = |v: &Vector<3>| v.as_slice().to_vec();
        match LAST[what] {
            "q_d" => c.reference.x.to_vec(),
            "dq_d" => c.reference.dx.to_vec(),
            "ddq_d" => c.reference.ddx.to_vec(),
            "p_d" => v3(&c.compliant.p),
            "dp_d" => v3(&c.compliant.dp),
            "ddp_d" => v3(&c.compliant.ddp),
            "R_d" => quaternion_rows(&c.compliant.r),
            "w_d" => v3(&c.compliant.w),
            "dw_d" => v3(&c.compliant.dw),
            "p_t" => v3(&c.target.0),
            "R_t" => quaternion_rows(&c.target.1),
            "error" => c.error.as_slice().to_vec(),
            "p" => v3(&c.p),
            "R" => (0..9).map(|k| c.r[(k / 3, k % 3)]).collect(),
            "tau_e" => c.tau_e.to_vec(),
            "tau" => c.joint.tau.to_vec(),
            "tau_sat" => c.joint.tau_sat.to_vec(),
            "p_c" => v3(&last.commanded[0]),
            "dp_c" => v3(&last.commanded[1]),
            "ddp_c" => v3(&last.commanded[2]),
            "wrench" => last.wrench.to_vec(),
            _ => c.joint.z1.to_vec(),
        }
    }

    /// A quantity of the state (see [`STATE`]).
    pub fn state(&self, what: usize) -> Vec<f64> {
        let s = &self.state;
        match STATE[what] {
            "p_d" => s.pose_d().0.as_slice().to_vec(),
            "R_d" => quaternion_rows(&s.pose_d().1),
            "q_d" => s.joint_d().0.to_vec(),
            "dq_d" => s.joint_d().1.to_vec(),
            "posture" => s.posture().to_vec(),
            "stiffness" => s.stiffness().0.as_slice().to_vec(),
            "stiffness_filtered" => s.stiffness().1.as_slice().to_vec(),
            "offset" => s.filters().0.as_slice().to_vec(),
            _ => s.filters().1.as_slice().to_vec(),
        }
    }

    /// The orbit rule: (q_d rows, q̇_d rows, q̈_d rows) of `nodes` samples
    /// along `targets`.
    pub fn orbit(
        &self,
        q0: &[f64],
        targets: &[PoseTarget],
        nodes: usize,
    ) -> Result<[Vec<f64>; 3], Error> {
        let out = self.outer.orbit(q0, targets.len(), |k| targets[k], nodes)?;
        let q = out.iter().flat_map(|s| s.x.iter().copied()).collect();
        let dq = out.iter().flat_map(|s| s.dx.iter().copied()).collect();
        let ddq = out.iter().flat_map(|s| s.ddx.iter().copied()).collect();
        Ok([q, dq, ddq])
    }

    /// The closed loop on MuJoCo of this outer loop in front of the core's
    /// joint controller behind `joint`, from both states
    /// ([`cartesian_loop::simulate_mujoco`]).
    pub fn simulate_mujoco(
        &mut self,
        joint: JointRef<'_>,
        sim: &mut Sim,
        spec: &MujocoSpec,
        run: &CartesianRun<'_>,
        hooks: &mut dyn Hooks,
        partial: &mut Option<TaskRows>,
    ) -> Result<CartesianOut, RunError> {
        let n = self.outer.n();
        let on = OnSim {
            core: self,
            joint,
            sim,
            spec,
            run,
            hooks,
            partial,
        };
        for_joints(n, on).unwrap_or(Err(RunError::Core(OTHER_N, None)))
    }

    /// Steps over recorded rows, the core's alone ([`cartesian_loop::replay`]).
    pub fn replay(
        &mut self,
        joint: JointRef<'_>,
        rows: usize,
        tables: [&[f64]; 3],
        targets: Option<&[f64]>,
        out: &mut Vec<f64>,
        hooks: &mut dyn Hooks,
    ) -> Result<(), RunError> {
        let n = self.outer.n();
        let on = OnRows {
            core: self,
            joint,
            rows,
            tables,
            targets,
            out,
            hooks,
        };
        for_joints(n, on).unwrap_or(Err(RunError::Core(OTHER_N, None)))
    }

    /// A copy of the state, without the kept log rows: what Python code a
    /// step or a run calls reads meanwhile.
    pub fn view(&self) -> Box<OuterCore> {
        Box::new(Self {
            outer: self.outer.clone(),
            state: self.state.clone(),
            q0: self.q0,
            last: self.last,
            held: self.held,
            log: Vec::new(),
            rows: 0,
        })
    }

    /// This loop as a run's copy for the Python code it calls shows it: at
    /// the run's `state` and last step (none taken yet: the last before the
    /// run), as the binding keeps it (`part`).
    fn copy_as<const N: usize>(
        &self,
        part: TypeId,
        state: &CartesianState<N>,
        last: Option<&TypedTaskStep<N>>,
    ) -> Option<Box<dyn Any + Send>> {
        (part == TypeId::of::<Box<OuterCore>>()).then(|| {
            let mut copy = self.clone();
            if let Some(s) = copy.state.typed_mut::<N>() {
                *s = *state;
            }
            if let Some(l) = last {
                copy.last = Some(l.run_time());
            }
            Box::new(Box::new(copy)) as Box<dyn Any + Send>
        })
    }
}

/// A run of `core` in front of `joint` (a MuJoCo run, a replay), for N
/// joints: `run` gets the typed loop's parts, the typed joint controller and
/// how the run copies this loop for the Python code it calls (the loop as
/// before the run, at the run's state and last step); the run's last step
/// is kept.
fn run_typed<const N: usize, R>(
    core: &mut OuterCore,
    joint: JointRef<'_>,
    run: impl FnOnce(OuterRun<'_, N>) -> Result<R, RunError>,
) -> Result<R, RunError> {
    let mut joint = typed::<N>(joint)?;
    let before = core.view();
    let copy = |part: TypeId, state: &CartesianState<N>, last: Option<&TypedTaskStep<N>>| {
        before.copy_as(part, state, last)
    };
    let mut last = None;
    let outer = core.outer.typed::<N>().ok_or(OTHER_N)?;
    let state = core.state.typed_mut::<N>().ok_or(OTHER_N)?;
    let result = run(OuterRun {
        outer,
        state,
        joint: joint.step(),
        last: &mut last,
        copy: &copy,
    });
    if let Some(l) = last {
        core.last = Some(l.run_time());
    }
    result
}

/// [`OuterCore::simulate_mujoco`] for its N.
struct OnSim<'a, 'b> {
    core: &'a mut OuterCore,
    joint: JointRef<'a>,
    sim: &'a mut Sim,
    spec: &'a MujocoSpec,
    run: &'a CartesianRun<'b>,
    hooks: &'a mut dyn Hooks,
    partial: &'a mut Option<TaskRows>,
}

impl ForJoints for OnSim<'_, '_> {
    type Output = Result<CartesianOut, RunError>;
    fn call<const N: usize>(self) -> Self::Output {
        let Self {
            core,
            joint,
            sim,
            spec,
            run,
            hooks,
            partial,
        } = self;
        run_typed::<N, _>(core, joint, |o| {
            cartesian_loop::simulate_mujoco(o, sim, spec, run, hooks, partial)
        })
    }
}

/// [`OuterCore::replay`] for its N.
struct OnRows<'a> {
    core: &'a mut OuterCore,
    joint: JointRef<'a>,
    rows: usize,
    tables: [&'a [f64]; 3],
    targets: Option<&'a [f64]>,
    out: &'a mut Vec<f64>,
    hooks: &'a mut dyn Hooks,
}

impl ForJoints for OnRows<'_> {
    type Output = Result<(), RunError>;
    fn call<const N: usize>(self) -> Self::Output {
        let Self {
            core,
            joint,
            rows,
            tables,
            targets,
            out,
            hooks,
        } = self;
        run_typed::<N, _>(core, joint, |o| {
            cartesian_loop::replay(o, rows, tables, targets, out, hooks)
        })
    }
}

/// A joint controller of the core, of any n: the paper's laws or computed
/// torque (SPEC §20).
pub enum JointRef<'a> {
    /// An `adaptimp.Controller`.
    Adaptive(&'a mut JointCore),
    /// An `adaptimp.baselines.ComputedTorque`.
    Computed(&'a mut ComputedCore),
}

/// The typed joint controller of N joints behind a [`JointRef`].
pub(super) enum TypedJoint<'a, const N: usize> {
    /// The paper's laws.
    Adaptive(AdaptiveStep<'a, N>),
    /// Computed torque.
    Computed(ComputedStep<'a, N>),
}

impl<const N: usize> TypedJoint<'_, N> {
    /// As the Cartesian loop steps it.
    pub(super) fn step(&mut self) -> &mut dyn JointStep<N> {
        match self {
            TypedJoint::Adaptive(t) => t,
            TypedJoint::Computed(c) => c,
        }
    }
}

/// The typed joint controller of N joints behind `joint`, for a run (which
/// publishes copies of it for the Python code it calls).
pub(super) fn typed<const N: usize>(joint: JointRef<'_>) -> Result<TypedJoint<'_, N>, Error> {
    match joint {
        JointRef::Adaptive(c) => AdaptiveStep::of(c).map(TypedJoint::Adaptive),
        JointRef::Computed(c) => ComputedStep::of(c).map(TypedJoint::Computed),
    }
}

/// The width of a log row besides q_d's n values: p_c, ṗ_c, p̈_c, p_d,
/// ṗ_d, p̈_d (3 each), F_e and the error (6 each).
pub const LOG_WIDTH: usize = 30;

pub(super) fn quaternion_rows(q: &nalgebra::UnitQuaternion<f64>) -> Vec<f64> {
    let r = q.to_rotation_matrix();
    (0..9).map(|k| r[(k / 3, k % 3)]).collect()
}
