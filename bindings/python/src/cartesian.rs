//! Python bindings of task space (SPEC §16): `Chain` (serial-chain
//! kinematics from joint data, n = 1 … 7) and `CartesianImpedance` (the core's
//! 6-D outer loop over a chain, stepped alone, with an `adaptimp.Controller`
//! — the core's joint step, no Python in between — or with a joint
//! controller written in Python), and `centres_along` (SPEC §15's rule).
//!
//! As for the controller: one monomorphised core per n behind an object-safe
//! face ([`DynChain`], [`DynOuter`]), slices in and out; errors become the
//! exceptions of `adaptimp._errors`.

use super::cartesian_loop::{
    self, pose_target, CartesianOut, CartesianRun, JointStep, LastStep, TaskRecords, TARGET_LEN,
};
use super::computed::{Computed, DynComputed, PyComputedTorque};
use super::dynamic::{scenario, DynTracker, Hooks, Owned, RunError, Typed, MAX_JOINTS};
use super::frames::{joint, transform};
use super::measurement::PyMeasurement;
use super::mujoco::MujocoSpec;
use super::shared::{Read, Shared, Slot, Write};
use super::{
    array, array1, config_error, items, python_shape, shape_error, vector, ConfigError,
    PyController,
};
use super::{DivergedError, MeasurementError};
use adaptimp::cartesian::chain::MAX_CHAIN_JOINTS;
use adaptimp::cartesian::{
    CartesianCommand, CartesianConfig, CartesianImpedance, CartesianMeasurement, CartesianState,
    Chain, Joint, JointKind, Kinematics, PoseTarget, Transform,
};
use adaptimp::control::config::Law;
use adaptimp::control::io::Command;
use adaptimp::dynamic::{Centres, HeldRotation, Joints};
use adaptimp::error::Error;
use adaptimp::schema::Preset;
use adaptimp::trajectory::Setpoint;
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use core::any::{Any, TypeId};
use nalgebra::Matrix3;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::vec::Vec;

// ---------------------------------------------------------------------------
// The object-safe faces.
// ---------------------------------------------------------------------------

/// The chain's typed outer loop: what [`PyCartesian`] is built on until
/// the outer loop is the core's run-time one.
pub trait DynChain: Send + Sync {
    /// The outer loop of `cfg` over this chain at period `ts`, started at `q0`.
    fn outer(
        &self,
        cfg: CartesianConfig,
        ts: f64,
        q0: &[f64],
        posture: Option<&[f64]>,
    ) -> Result<Box<dyn DynOuter>, Error>;
}

fn vector_of<const N: usize>(v: &[f64]) -> Vector<N> {
    Vector::from_column_slice(&v[..N])
}

impl<const N: usize> DynChain for Chain<N> {
    fn outer(
        &self,
        cfg: CartesianConfig,
        ts: f64,
        q0: &[f64],
        posture: Option<&[f64]>,
    ) -> Result<Box<dyn DynOuter>, Error> {
        let outer = CartesianImpedance::new(cfg, *self, ts)?;
        let q0 = vector_of::<N>(q0);
        let posture = posture.map_or(q0, vector_of::<N>);
        let mut state = outer.start_checked(&q0)?;
        outer.set_posture(&mut state, &posture)?;
        Ok(Box::new(Outer {
            outer,
            state,
            q0,
            posture,
            last: None,
            held: HeldRotation::default(),
            log: Vec::new(),
            rows: 0,
        }))
    }
}

/// A chain of `joints` (base to tip, fixed ones included) and `tip`, with as
/// many joints as it has movable ones (1 … 7).
pub fn chain(joints: &[Joint], tip: &Transform) -> Result<Box<dyn DynChain>, Error> {
    let n = joints.iter().filter(|j| j.kind != JointKind::Fixed).count();
    adaptimp::with_joints!(
        n,
        K => Ok(Box::new(Chain::<K>::new(joints, tip)?)),
        _ => Err(Error::Condition {
            condition: "1 ≤ n ≤ 7 movable joints",
            lhs: "movable joints",
            index: None,
            value: n as f64,
        }),
    )
}

/// The quantities of the last Cartesian step, by name.
const LAST: [&str; 22] = [
    "q_d", "dq_d", "ddq_d", "p_d", "dp_d", "ddp_d", "R_d", "w_d", "dw_d", "p_t", "R_t", "error",
    "p", "R", "tau_e", "tau", "tau_sat", "z1", "p_c", "dp_c", "ddp_c", "wrench",
];

/// The quantities of the outer state, by name.
const STATE: [&str; 9] = [
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

/// The outer loop over a chain, for any n ≤ 7, with its state.
pub trait DynOuter: Send + Sync {
    /// Ts (s).
    fn ts(&self) -> f64;
    /// Steps taken.
    fn steps(&self) -> u64;
    /// Whether the orientation is a task.
    fn orients(&self) -> bool;
    /// Back to t = 0 at `q0` (the start's, if none), the posture kept.
    fn reset(&mut self, q0: Option<&[f64]>) -> Result<(), Error>;
    /// The null-space posture (rad).
    fn set_posture(&mut self, posture: &[f64]) -> Result<(), Error>;
    /// Check a commanded pose as a step would, changing nothing.
    fn check_target(&self, target: &PoseTarget) -> Result<(), Error>;
    /// The stiffness asked for (N/m, N m/rad).
    fn set_stiffness(&mut self, kd: [f64; 3], kd_rot: [f64; 3]) -> Result<(), Error>;
    /// The outer loop alone: one committed step.
    fn reference(&mut self, target: Option<&PoseTarget>, wrench: [f64; 6]) -> Result<(), Error>;
    /// One step with the core's joint controller `joint`.
    fn step_tracker(&mut self, joint: JointRef<'_>, m: &StepIn<'_>) -> Result<(), Error>;
    /// One step with a joint controller of the caller's.
    fn step_joint(&mut self, m: &StepIn<'_>, joint: &mut JointFn<'_>) -> Result<(), Error>;
    /// A quantity of the last step (see [`LAST`]).
    fn last(&self, what: usize) -> Vec<f64>;
    /// The last step's applied torque sat(τ) (N m), first n values (NaN
    /// before a step): `last("tau_sat")` without its name's lookup or a
    /// vector made.
    fn applied(&self) -> [f64; MAX_JOINTS];
    /// The commanded rotation held when a target gives none.
    fn held(&self) -> &HeldRotation;
    /// The same, to change.
    fn held_mut(&mut self) -> &mut HeldRotation;
    /// Keep the last step's row of `CartesianController.log` (p_c, ṗ_c, p̈_c,
    /// p_d, ṗ_d, p̈_d, q_d, F_e, the error: [`LOG_WIDTH`] + n values).
    fn record(&mut self);
    /// The rows kept since the last call, flat, and their number.
    fn take_log(&mut self) -> (Vec<f64>, usize);
    /// A quantity of the state (see [`STATE`]).
    fn state(&self, what: usize) -> Vec<f64>;
    /// The orbit rule: (q_d rows, q̇_d rows) of `nodes` samples along `targets`.
    fn orbit(
        &self,
        q0: &[f64],
        targets: &[PoseTarget],
        nodes: usize,
    ) -> Result<[Vec<f64>; 3], Error>;
    /// The closed loop on MuJoCo of this outer loop in front of the core's
    /// joint controller behind `tracker`, from both states
    /// ([`cartesian_loop::simulate_mujoco`]).
    fn simulate_mujoco(
        &mut self,
        joint: JointRef<'_>,
        sim: &mut Sim,
        spec: &MujocoSpec,
        run: &CartesianRun<'_>,
        hooks: &mut dyn Hooks,
        partial: &mut Option<TaskRecords>,
    ) -> Result<CartesianOut, RunError>;
    /// Steps over recorded rows, the core's alone ([`cartesian_loop::replay`]).
    fn replay(
        &mut self,
        joint: JointRef<'_>,
        rows: usize,
        tables: [&[f64]; 3],
        targets: Option<&[f64]>,
        out: &mut Vec<f64>,
        hooks: &mut dyn Hooks,
    ) -> Result<(), RunError>;
    /// A copy of the state, without the kept log rows: what Python code a
    /// step or a run calls reads meanwhile.
    fn view(&self) -> Box<dyn DynOuter>;
}

/// A joint controller of the core, of any n: the paper's laws or computed
/// torque (SPEC §20).
pub enum JointRef<'a> {
    /// An `adaptimp.Controller`.
    Adaptive(&'a mut dyn DynTracker),
    /// An `adaptimp.baselines.ComputedTorque`.
    Computed(&'a mut dyn DynComputed),
}

/// The typed joint controller of N joints behind `joint`.
fn typed<'a, const N: usize>(joint: JointRef<'a>) -> Result<&'a mut dyn JointStep<N>, Error> {
    let other = Error::Invalid {
        what: "controller",
        reason: "has another number of joints than the chain",
    };
    match joint {
        JointRef::Adaptive(t) => t
            .as_any_mut()
            .downcast_mut::<Typed<N>>()
            .map(|t| t as &mut dyn JointStep<N>)
            .ok_or(other),
        JointRef::Computed(c) => c
            .as_any_mut()
            .downcast_mut::<Computed<N>>()
            .map(|c| c as &mut dyn JointStep<N>)
            .ok_or(other),
    }
}

struct Outer<const N: usize> {
    outer: CartesianImpedance<N, Chain<N>>,
    state: CartesianState<N>,
    q0: Vector<N>,
    posture: Vector<N>,
    last: Option<LastStep<N>>,
    /// The commanded rotation a target without one keeps.
    held: HeldRotation,
    /// Kept rows of the log, flat ([`LOG_WIDTH`] + N each), and their number.
    log: Vec<f64>,
    rows: usize,
}

/// The width of a log row besides q_d's n values: p_c, ṗ_c, p̈_c, p_d,
/// ṗ_d, p̈_d (3 each), F_e and the error (6 each).
pub const LOG_WIDTH: usize = 30;

impl<const N: usize> Outer<N> {
    /// This loop at `state`, after `last` (None: the last step kept), without
    /// its log: a copy for the Python code a run calls.
    fn at(&self, state: &CartesianState<N>, last: Option<&LastStep<N>>) -> Self {
        Self {
            state: *state,
            last: last.copied().or(self.last),
            log: Vec::new(),
            rows: 0,
            ..*self
        }
    }

    /// [`Self::at`] for the part `part` a binding keeps, as a run's
    /// [`OuterCopy`] gives it.
    fn copy_as(
        &self,
        part: TypeId,
        state: &CartesianState<N>,
        last: Option<&LastStep<N>>,
    ) -> Option<Box<dyn Any + Send>> {
        (part == TypeId::of::<Box<dyn DynOuter>>()).then(|| {
            Box::new(Box::new(self.at(state, last)) as Box<dyn DynOuter>) as Box<dyn Any + Send>
        })
    }

    fn measurement(m: &StepIn<'_>) -> CartesianMeasurement<N> {
        CartesianMeasurement {
            q: vector_of(m.q),
            dq: m.dq.map(vector_of),
            wrench: Vector::<6>::from(m.wrench),
        }
    }
}

fn quaternion_rows(q: &nalgebra::UnitQuaternion<f64>) -> Vec<f64> {
    let r = q.to_rotation_matrix();
    (0..9).map(|k| r[(k / 3, k % 3)]).collect()
}

impl<const N: usize> DynOuter for Outer<N> {
    fn ts(&self) -> f64 {
        self.outer.period()
    }
    fn steps(&self) -> u64 {
        self.state.k
    }
    fn orients(&self) -> bool {
        self.outer.orients()
    }
    fn reset(&mut self, q0: Option<&[f64]>) -> Result<(), Error> {
        let q0 = q0.map_or(self.q0, vector_of::<N>);
        let state = self.outer.start_checked(&q0)?;
        self.q0 = q0;
        self.state = state;
        self.state.posture = self.posture;
        self.last = None;
        self.log.clear();
        self.rows = 0;
        Ok(())
    }
    fn held(&self) -> &HeldRotation {
        &self.held
    }
    fn held_mut(&mut self) -> &mut HeldRotation {
        &mut self.held
    }
    fn record(&mut self) {
        let Some(last) = &self.last else {
            return;
        };
        let c = &last.cmd;
        for v in last
            .commanded
            .iter()
            .chain([&c.compliant.p, &c.compliant.dp, &c.compliant.ddp])
        {
            self.log.extend_from_slice(v.as_slice());
        }
        self.log.extend_from_slice(c.reference.x.as_slice());
        self.log.extend_from_slice(&last.wrench);
        self.log.extend_from_slice(c.error.as_slice());
        self.rows += 1;
    }
    fn take_log(&mut self) -> (Vec<f64>, usize) {
        let rows = core::mem::replace(&mut self.rows, 0);
        (core::mem::take(&mut self.log), rows)
    }
    fn set_posture(&mut self, posture: &[f64]) -> Result<(), Error> {
        let p = vector_of::<N>(posture);
        self.outer.set_posture(&mut self.state, &p)?;
        self.posture = p;
        Ok(())
    }
    fn set_stiffness(&mut self, kd: [f64; 3], kd_rot: [f64; 3]) -> Result<(), Error> {
        self.outer
            .set_stiffness(&mut self.state, &kd.into(), &kd_rot.into())
    }
    fn check_target(&self, target: &PoseTarget) -> Result<(), Error> {
        self.outer.check_target(target)
    }
    fn reference(&mut self, target: Option<&PoseTarget>, wrench: [f64; 6]) -> Result<(), Error> {
        let staged = self.outer.stage(&self.state, target, &wrench.into())?;
        let tip = Kinematics::tip(
            self.outer.kinematics(),
            &staged.reference.x,
            &Vector::zeros(),
        );
        self.state = staged.next;
        let cmd = CartesianCommand {
            joint: Command::zeros(),
            reference: staged.reference,
            commanded: staged.commanded,
            compliant: staged.compliant,
            target: staged.target,
            error: staged.error,
            p: tip.position,
            r: tip.rotation,
            tau_e: Vector::zeros(),
        };
        self.last = Some(LastStep::new(cmd, target, wrench));
        Ok(())
    }
    fn step_tracker(&mut self, joint: JointRef<'_>, m: &StepIn<'_>) -> Result<(), Error> {
        let typed = typed::<N>(joint)?;
        let meas = Self::measurement(m);
        let cmd = cartesian_loop::cartesian_step(
            &self.outer,
            &mut self.state,
            typed,
            &meas,
            m.target.as_ref(),
        )?;
        self.last = Some(LastStep::new(cmd, m.target.as_ref(), m.wrench));
        Ok(())
    }
    fn step_joint(&mut self, m: &StepIn<'_>, joint: &mut JointFn<'_>) -> Result<(), Error> {
        let meas = Self::measurement(m);
        let cmd =
            self.outer
                .step_with(&mut self.state, &meas, m.target.as_ref(), |jm, r, task| {
                    let mut tau = [0.0; MAX_JOINTS];
                    let (reference, extra) = match task {
                        // The torque-level formulations (SPEC §19): the commanded
                        // reference and the task torque at the measured q̇.
                        Some(t) if t.share < 1.0 => {
                            let dq = jm.dx.ok_or(Error::MissingVelocity)?;
                            let torque = t.jacobian.transpose() * t.force(&dq);
                            let rows = t.jacobian.transpose();
                            (t.commanded, Some((torque, rows)))
                        }
                        _ => (*r, None),
                    };
                    joint(
                        jm.x.as_slice(),
                        jm.dx.as_ref().map(|d| d.as_slice()),
                        jm.tau_e.as_slice(),
                        [
                            reference.x.as_slice(),
                            reference.dx.as_slice(),
                            reference.ddx.as_slice(),
                        ],
                        extra.as_ref().map(|(t, j)| (t.as_slice(), j.as_slice())),
                        &mut tau[..N],
                    )?;
                    let t = vector_of::<N>(&tau);
                    Ok(Command {
                        tau_sat: t,
                        tau: t,
                        z1: r.x - jm.x,
                        xc: r.x,
                        xd: r.x,
                        ..Command::zeros()
                    })
                })?;
        self.last = Some(LastStep::new(cmd, m.target.as_ref(), m.wrench));
        Ok(())
    }
    fn applied(&self) -> [f64; MAX_JOINTS] {
        let mut out = [f64::NAN; MAX_JOINTS];
        if let Some(last) = &self.last {
            out[..N].copy_from_slice(last.cmd.joint.tau_sat.as_slice());
        }
        out
    }
    fn last(&self, what: usize) -> Vec<f64> {
        let Some(last) = &self.last else {
            let width = match LAST[what] {
                "R_d" | "R_t" | "R" => 9,
                "q_d" | "dq_d" | "ddq_d" | "tau_e" | "tau" | "tau_sat" | "z1" => N,
                "error" | "wrench" => 6,
                _ => 3,
            };
            return std::vec![f64::NAN; width];
        };
        let c = &last.cmd;
        let v3 = |v: &Vector<3>| v.as_slice().to_vec();
        let vn = |v: &Vector<N>| v.as_slice().to_vec();
        match LAST[what] {
            "q_d" => vn(&c.reference.x),
            "dq_d" => vn(&c.reference.dx),
            "ddq_d" => vn(&c.reference.ddx),
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
            "tau_e" => vn(&c.tau_e),
            "tau" => vn(&c.joint.tau),
            "tau_sat" => vn(&c.joint.tau_sat),
            "p_c" => v3(&last.commanded[0]),
            "dp_c" => v3(&last.commanded[1]),
            "ddp_c" => v3(&last.commanded[2]),
            "wrench" => last.wrench.to_vec(),
            _ => vn(&c.joint.z1),
        }
    }
    fn state(&self, what: usize) -> Vec<f64> {
        let s = &self.state;
        match STATE[what] {
            "p_d" => s.pd.as_slice().to_vec(),
            "R_d" => quaternion_rows(&s.rd),
            "q_d" => s.qd.as_slice().to_vec(),
            "dq_d" => s.dqd.as_slice().to_vec(),
            "posture" => s.posture.as_slice().to_vec(),
            "stiffness" => s.stiffness.as_slice().to_vec(),
            "stiffness_filtered" => s.stiffness_filtered.as_slice().to_vec(),
            "offset" => s.offset.as_slice().to_vec(),
            _ => s.wrench.as_slice().to_vec(),
        }
    }
    fn orbit(
        &self,
        q0: &[f64],
        targets: &[PoseTarget],
        nodes: usize,
    ) -> Result<[Vec<f64>; 3], Error> {
        let q0 = vector_of::<N>(q0);
        adaptimp::error::check::finite_slice("q0", q0.as_slice())?;
        let zero = Setpoint {
            x: Vector::<N>::zeros(),
            dx: Vector::zeros(),
            ddx: Vector::zeros(),
        };
        // At most one sample a step: a huge `nodes` allocates no more.
        let mut out = std::vec![zero; nodes.min(targets.len()).max(1)];
        let k = self
            .outer
            .orbit(q0, targets.len(), |k| targets[k], &mut out)?;
        let q = out[..k].iter().flat_map(|s| s.x.iter().copied()).collect();
        let dq = out[..k].iter().flat_map(|s| s.dx.iter().copied()).collect();
        let ddq = out[..k]
            .iter()
            .flat_map(|s| s.ddx.iter().copied())
            .collect();
        Ok([q, dq, ddq])
    }
    fn simulate_mujoco(
        &mut self,
        joint: JointRef<'_>,
        sim: &mut Sim,
        spec: &MujocoSpec,
        run: &CartesianRun<'_>,
        hooks: &mut dyn Hooks,
        partial: &mut Option<TaskRecords>,
    ) -> Result<CartesianOut, RunError> {
        let joint = typed::<N>(joint)?;
        let before = self.at(&self.state, None);
        let copy = |part: TypeId, state: &CartesianState<N>, last: Option<&LastStep<N>>| {
            before.copy_as(part, state, last)
        };
        cartesian_loop::simulate_mujoco(
            &self.outer,
            &mut self.state,
            joint,
            &mut self.last,
            sim,
            spec,
            run,
            hooks,
            partial,
            &copy,
        )
    }
    fn replay(
        &mut self,
        joint: JointRef<'_>,
        rows: usize,
        tables: [&[f64]; 3],
        targets: Option<&[f64]>,
        out: &mut Vec<f64>,
        hooks: &mut dyn Hooks,
    ) -> Result<(), RunError> {
        let joint = typed::<N>(joint)?;
        let before = self.at(&self.state, None);
        let copy = |part: TypeId, state: &CartesianState<N>, last: Option<&LastStep<N>>| {
            before.copy_as(part, state, last)
        };
        cartesian_loop::replay(
            &self.outer,
            &mut self.state,
            joint,
            &mut self.last,
            rows,
            tables,
            targets,
            out,
            hooks,
            &copy,
        )
    }
    fn view(&self) -> Box<dyn DynOuter> {
        Box::new(self.at(&self.state, None))
    }
}

/// The core's joint controller behind a Python object, locked: an
/// `adaptimp.Controller` or a `ComputedTorque` (SPEC §20) of n joints, with
/// where a run publishes its copy.
enum Locked<'a> {
    Adaptive(Write<'a, dyn DynTracker>, &'a dyn Slot),
    Computed(Write<'a, dyn DynComputed>, &'a dyn Slot),
}

impl<'a> Locked<'a> {
    fn joint(&mut self) -> JointRef<'_> {
        match self {
            Locked::Adaptive(g, _) => JointRef::Adaptive(&mut ***g),
            Locked::Computed(g, _) => JointRef::Computed(&mut ***g),
        }
    }

    fn slot(&self) -> &'a dyn Slot {
        match self {
            Locked::Adaptive(_, s) | Locked::Computed(_, s) => *s,
        }
    }
}

fn lock_joint<'a>(
    py: Python<'_>,
    controller: &'a Bound<'_, PyAny>,
    n: usize,
) -> PyResult<Locked<'a>> {
    let (got, locked) = if let Ok(c) = controller.cast::<PyController>() {
        let c = c.get();
        (c.n, Locked::Adaptive(c.lock(py)?, c.slot()))
    } else if let Ok(c) = controller.cast::<PyComputedTorque>() {
        let c = c.get();
        (c.n, Locked::Computed(c.lock(py)?, c.slot()))
    } else {
        return Err(PyTypeError::new_err(
            "the joint controller must be an adaptimp.Controller or a core ComputedTorque",
        ));
    };
    if got != n {
        return Err(ConfigError::new_err(format!(
            "the joint controller has {got} joints, the chain {n}"
        )));
    }
    Ok(locked)
}

// ---------------------------------------------------------------------------
// Conversions.
// ---------------------------------------------------------------------------

/// A step's error, named as in Python: the measurement and the target are
/// inputs (`MeasurementError`), a signal beyond the finite range is
/// `DivergedError`, a parameter `ConfigError`.
fn cartesian_error(e: Error) -> PyErr {
    const INPUTS: [&str; 13] = [
        "q",
        "x",
        "dq",
        "dx",
        "wrench",
        "p_c",
        "dp_c",
        "ddp_c",
        "R_c",
        "max |R_cᵀR_c − I| of R_c",
        "det R_c",
        "w_c",
        "dw_c",
    ];
    let input = match e {
        Error::NonFinite { what, .. } | Error::OutOfRange { what, .. } => INPUTS.contains(&what),
        Error::Condition { lhs, .. } => INPUTS.contains(&lhs),
        Error::MissingVelocity => true,
        _ => false,
    };
    match e {
        _ if input => MeasurementError::new_err(super::python_names(e).to_string()),
        Error::OutOfRange { .. } | Error::Diverged { .. } => DivergedError::new_err(e.to_string()),
        _ => super::step_error(e),
    }
}

/// A flat vector of exactly `len` finite reals (a sequence or an array).
fn flat(what: &'static str, len: usize, obj: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let v = flat_values(what, len, obj)?;
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(MeasurementError::new_err(format!(
            "{what}[{i}] is not finite (NaN or infinite)"
        )));
    }
    Ok(v)
}

/// `len` reals from a 1-D sequence or array (another shape, e.g. a (2, 3)
/// wrench, is refused naming `what`), finite or not.
fn flat_values(what: &'static str, len: usize, obj: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if let Ok(shape) = obj.getattr("shape").and_then(|s| s.extract::<Vec<usize>>()) {
        if shape.len() != 1 {
            return Err(MeasurementError::new_err(format!(
                "{what} must have shape ({len},), got {}",
                python_shape(&shape)
            )));
        }
    }
    let v: Vec<f64> = match obj.cast::<PyArray1<f64>>() {
        Ok(a) => a.try_readonly()?.as_array().iter().copied().collect(),
        Err(_) => obj
            .call_method1("__array__", ())
            .ok()
            .and_then(|a| a.call_method1("astype", ("float64",)).ok())
            .and_then(|a| a.call_method0("ravel").ok())
            .and_then(|a| a.extract::<Vec<f64>>().ok())
            .or_else(|| obj.extract::<Vec<f64>>().ok())
            .ok_or_else(|| {
                PyTypeError::new_err(format!("{what} must be a sequence or array of {len} reals"))
            })?,
    };
    if v.len() != len {
        return Err(MeasurementError::new_err(format!(
            "{what} must have {len} values, got {}",
            v.len()
        )));
    }
    Ok(v)
}

/// `L` reals: an array of shape (L,) read in place, else any sequence
/// ([`flat`]); None gives zeros.
fn reals<const L: usize>(what: &'static str, obj: Option<&Bound<'_, PyAny>>) -> PyResult<[f64; L]> {
    let mut out = [0.0; L];
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(out);
    };
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        if a.len() == L {
            for (i, o) in out.iter_mut().enumerate() {
                *o = a.get_owned(i).unwrap_or(f64::NAN);
            }
            return Ok(out);
        }
    }
    let v = flat_any(what, L, obj)?;
    out.copy_from_slice(&v);
    Ok(out)
}

/// NumPy's shape of `obj` ("(2, 3)"), if it is not `want` (a (9,) R or a
/// (2, 3) wrench was read flat, silently).
fn shape_other_than(obj: &Bound<'_, PyAny>, want: &[&[usize]]) -> Option<String> {
    let shape: Vec<usize> = obj
        .py()
        .import("numpy")
        .and_then(|np| np.call_method1("shape", (obj,)))
        .and_then(|s| s.extract())
        .ok()?;
    if want.contains(&shape.as_slice()) {
        return None;
    }
    let dims: Vec<String> = shape.iter().map(ToString::to_string).collect();
    Some(match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    })
}

/// F_e from (6,), or f (3,) alone (no moment).
fn wrench_sample(obj: &Bound<'_, PyAny>) -> PyResult<[f64; 6]> {
    if obj.is_none() {
        return Ok([0.0; 6]);
    }
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        if a.len() == 6 || a.len() == 3 {
            let mut out = [0.0; 6];
            for (i, o) in out.iter_mut().enumerate().take(a.len()) {
                *o = a.get_owned(i).unwrap_or(f64::NAN);
            }
            return Ok(out);
        }
    }
    if let Some(shape) = shape_other_than(obj, &[&[6], &[3]]) {
        return Err(MeasurementError::new_err(format!(
            "wrench must have shape (6,) or (3,), got shape {shape}"
        )));
    }
    let v = flat_any("wrench", 0, obj)?;
    match v.len() {
        3 | 6 => Ok(core::array::from_fn(|i| v.get(i).copied().unwrap_or(0.0))),
        k => Err(MeasurementError::new_err(format!(
            "wrench must have shape (6,) or (3,), got {k} values"
        ))),
    }
}

/// The commanded pose of a step: a path's (p, ṗ, p̈) or (p, ṗ, p̈, R, ω, ω̇)
/// (rates None: 0; R None: the rotation `held`), or a flat target (24,).
fn sample_target(obj: &Bound<'_, PyAny>, held: &HeldRotation) -> PyResult<PoseTarget> {
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        let v = flat("target", TARGET_LEN, a.as_any())?;
        return Ok(pose_target(&v));
    }
    // A tuple (a path's return) is read in place; any other iterable is
    // collected first.
    let tuple = obj.cast::<pyo3::types::PyTuple>().ok();
    let collected: Vec<Bound<'_, PyAny>> = match tuple {
        Some(_) => Vec::new(),
        None => obj
            .try_iter()
            .and_then(|it| it.collect::<PyResult<Vec<_>>>())
            .map_err(|_| {
                let got = obj
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".to_owned(), |n| n.to_string());
                PyTypeError::new_err(format!(
                    "a path returns (p, dp, ddp) or (p, dp, ddp, R, w, dw) (a tuple of arrays), \
                     got {got}"
                ))
            })?,
    };
    let len = tuple.map_or(collected.len(), |t| t.len());
    if len != 3 && len != 6 {
        return Err(PyValueError::new_err(format!(
            "path(t) must return 3 or 6 arrays (p, dp, ddp[, R, w, dw]), got {len}"
        )));
    }
    let get = |i: usize| -> Option<Bound<'_, PyAny>> {
        let item = match tuple {
            Some(t) if i < len => t.get_item(i).ok(),
            Some(_) => None,
            None => collected.get(i).cloned(),
        };
        item.filter(|o| !o.is_none())
    };
    let p = match get(0) {
        Some(p) => reals::<3>("p_c", Some(&p))?,
        None => {
            return Err(MeasurementError::new_err(
                "the commanded position p_c is missing",
            ))
        }
    };
    let v3 =
        |what: &'static str, i: usize| reals::<3>(what, get(i).as_ref()).map(Vector::<3>::from);
    let rates = [v3("dp_c", 1)?, v3("ddp_c", 2)?];
    let r = match get(3) {
        None => None,
        Some(r) => Some(match r.cast::<PyArray2<f64>>() {
            Ok(a) if a.shape() == [3, 3] => {
                Matrix3::from_fn(|i, j| a.get_owned([i, j]).unwrap_or(f64::NAN))
            }
            _ => {
                if let Some(shape) = shape_other_than(&r, &[&[3, 3]]) {
                    return Err(MeasurementError::new_err(format!(
                        "R_c must have shape (3, 3), got shape {shape}"
                    )));
                }
                Matrix3::from_row_slice(&flat_any("R_c", 9, &r)?)
            }
        }),
    };
    let w = [v3("w_c", 4)?, v3("dw_c", 5)?];
    Ok(held.target(Vector::<3>::from(p), rates, r, w))
}

/// As [`flat`], without the finiteness check (the core's), of any length
/// when `len` is 0.
fn flat_any(what: &'static str, len: usize, obj: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let v: Vec<f64> = obj
        .call_method1("__array__", ())
        .ok()
        .and_then(|a| a.call_method1("astype", ("float64",)).ok())
        .and_then(|a| a.call_method0("ravel").ok())
        .and_then(|a| a.extract::<Vec<f64>>().ok())
        .or_else(|| obj.extract::<Vec<f64>>().ok())
        .ok_or_else(|| {
            PyTypeError::new_err(format!("{what} must be a sequence or array of reals"))
        })?;
    if len > 0 && v.len() != len {
        return Err(MeasurementError::new_err(format!(
            "{what} must have {len} values, got {}",
            v.len()
        )));
    }
    Ok(v)
}

/// A flat target (24,); a value that is not finite is refused by the
/// core's check of the target, naming its part (p_c, R_c, w_c, …).
fn target_of(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<PoseTarget>> {
    obj.map(|o| flat_values("target", TARGET_LEN, o).map(|v| pose_target(&v)))
        .transpose()
}

fn wrench_of(obj: &Bound<'_, PyAny>) -> PyResult<[f64; 6]> {
    let v = flat("wrench", 6, obj)?;
    Ok(core::array::from_fn(|i| v[i]))
}

/// A Cartesian run's task rows (`k` of them) as the dict of
/// `CartesianController.arrays()`'s keys.
fn task_dict(py: Python<'_>, task: TaskRecords, k: usize) -> PyResult<Bound<'_, PyDict>> {
    let n = task.n;
    let [pc, dpc, ddpc] = task.pc;
    let [pd, dpd, ddpd] = task.pd;
    let d = PyDict::new(py);
    for (name, v, w) in [
        ("pc", pc, 3),
        ("dpc", dpc, 3),
        ("ddpc", ddpc, 3),
        ("pd", pd, 3),
        ("dpd", dpd, 3),
        ("ddpd", ddpd, 3),
        ("qd", task.qd, n),
        ("wrench", task.wrench, 6),
        ("error", task.error, 6),
    ] {
        d.set_item(name, array(py, v, (k, w))?)?;
    }
    Ok(d)
}

/// The rows of a table (K, n) of reals from any array or nested sequence
/// (K given: of that many rows), else a MeasurementError (TypeError for
/// values that are not reals) naming `what` and the shape it had.
fn rows_of(
    what: &str,
    obj: &Bound<'_, PyAny>,
    k: Option<usize>,
    n: usize,
) -> PyResult<(usize, Vec<f64>)> {
    let np = obj.py().import("numpy")?;
    let given = np
        .call_method1("asarray", (obj,))
        .map_err(|_| PyTypeError::new_err(format!("{what} must be an array of reals")))?;
    // Reals only: a complex row lost its imaginary part, text became numbers.
    let kind: String = given.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u") {
        return Err(PyTypeError::new_err(format!(
            "{what} must hold real numbers, got an array of dtype {}",
            given.getattr("dtype")?.str()?
        )));
    }
    let a = given.call_method1("astype", ("float64",))?;
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    let rows = k.unwrap_or(shape.first().copied().unwrap_or(0));
    if shape != [rows, n] {
        let like = if k.is_some() { " like q" } else { "" };
        return Err(MeasurementError::new_err(format!(
            "{what} must have shape ({}, {n}){like}, got {}",
            k.map_or("K".to_string(), |k| k.to_string()),
            python_shape(&shape)
        )));
    }
    let v: Vec<f64> = a.call_method0("ravel")?.extract()?;
    Ok((rows, v))
}

/// A count given as a Python integer (not a bool, not a float): ≥ 1, else
/// a ConfigError (TypeError for another type) naming `what`.
fn count(what: &str, obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    use pyo3::types::{PyBool, PyInt};
    if obj.is_instance_of::<PyBool>() || !obj.is_instance_of::<PyInt>() {
        return Err(PyTypeError::new_err(format!(
            "{what} must be an integer ≥ 1, got {}",
            obj.repr()?
        )));
    }
    match obj.extract::<i128>() {
        Ok(v) if v >= 1 => Ok(usize::try_from(v).unwrap_or(usize::MAX)),
        _ => Err(ConfigError::new_err(format!(
            "{what} must be an integer ≥ 1, got {}",
            obj.repr()?
        ))),
    }
}

/// A real number (a Python or NumPy int or float; not a bool, not a
/// string), else a TypeError naming `what`.
fn real(what: &str, obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    use pyo3::types::PyBool;
    let v = if obj.is_instance_of::<PyBool>() {
        None
    } else {
        obj.extract::<f64>().ok()
    };
    v.ok_or_else(|| {
        let shown = obj.repr().map_or_else(|_| "?".into(), |r| r.to_string());
        PyTypeError::new_err(format!("{what} must be a real number, got {shown}"))
    })
}

fn rows(n: usize, what: &str, a: &PyReadonlyArray2<'_, f64>, width: usize) -> PyResult<Vec<f64>> {
    if a.shape()[1] != width || a.shape()[0] != n {
        return Err(MeasurementError::new_err(format!(
            "{what} must have shape ({n}, {width}), got {}",
            python_shape(a.shape())
        )));
    }
    // A C-contiguous array (as NumPy makes one) in one copy; any other
    // layout element by element, in the same row-major order.
    Ok(match a.as_slice() {
        Ok(flat) => flat.to_vec(),
        Err(_) => a.as_array().iter().copied().collect(),
    })
}

// ---------------------------------------------------------------------------
// Chain.
// ---------------------------------------------------------------------------

/// A serial chain of n = 1 … 7 movable (revolute or prismatic) joints and a
/// tip, from joint data (SPEC §16): pose, 6 × n Jacobian and J̇ q̇ of the tip.
/// Use `adaptimp.Chain`, which reads URDF files and MuJoCo models.
#[pyclass(name = "Chain", module = "adaptimp._adaptimp", frozen, subclass)]
pub struct PyChain {
    inner: adaptimp::dynamic::Chain,
    typed: Box<dyn DynChain>,
}

impl PyChain {
    fn qv(&self, what: &'static str, obj: &Bound<'_, PyAny>) -> PyResult<[f64; MAX_JOINTS]> {
        vector(what, self.inner.n(), obj)
    }

    /// The chain behind the object.
    pub(super) fn chain(&self) -> &adaptimp::dynamic::Chain {
        &self.inner
    }
}

#[pymethods]
impl PyChain {
    /// The chain of `joints` (dicts, base to tip: "kind" ("fixed",
    /// "revolute", "prismatic"), the origin as "xyz" and "rpy" (m, rad),
    /// "pos" and "quat" ([w, x, y, z]) or "translation" and "rotation" (3 × 3),
    /// "axis" (3) and "offset" (rad or m, default 0)) and the `tip` transform
    /// (a dict of the same origin keys).
    #[new]
    #[pyo3(signature = (joints, tip=None))]
    fn new(joints: Vec<Bound<'_, PyDict>>, tip: Option<Bound<'_, PyDict>>) -> PyResult<Self> {
        let js = joints.iter().map(joint).collect::<PyResult<Vec<_>>>()?;
        let tip = match tip {
            Some(t) => transform(&t)?,
            None => Transform::IDENTITY,
        };
        let err = |e: Error| ConfigError::new_err(e.to_string());
        let inner = adaptimp::dynamic::Chain::new(&js, &tip).map_err(err)?;
        let typed = chain(&js, &tip).map_err(err)?;
        Ok(Self { inner, typed })
    }

    /// Movable joints n.
    #[getter]
    fn n(&self) -> usize {
        self.inner.n()
    }

    /// Whether each joint is prismatic (else revolute), (n,).
    #[getter]
    fn prismatic(&self) -> Vec<bool> {
        (0..self.inner.n())
            .map(|i| self.inner.is_prismatic(i))
            .collect()
    }

    /// The tip's pose at q: the homogeneous transform (4, 4), world ← tip (m).
    fn fk<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.inner.n();
        let q = self.qv("q", q)?;
        let (p, r) = self.inner.pose(&q[..n]).map_err(cartesian_error)?;
        let mut pose = std::vec![0.0; 16];
        for i in 0..3 {
            pose[4 * i..4 * i + 3].copy_from_slice(&[r[(i, 0)], r[(i, 1)], r[(i, 2)]]);
            pose[4 * i + 3] = p[i];
        }
        pose[15] = 1.0;
        array(py, pose, (4, 4))
    }

    /// The tip's twist and acceleration along recorded rows q, q̇, q̈ (K, n)
    /// (rad, rad/s, rad/s²): (V (K, 6), A (K, 6)) with V = J(q) q̇ = [ṗ; ω]
    /// (m/s, rad/s) and A = J(q) q̈ + J̇ q̇ = [p̈; ω̇] (m/s², rad/s²), one pass
    /// of the chain per row, the GIL released.
    #[allow(clippy::type_complexity)]
    fn motion<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        dq: &Bound<'py, PyAny>,
        ddq: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
        let n = self.inner.n();
        let (k, q) = rows_of("q", q, None, n)?;
        let (_, dq) = rows_of("dq", dq, Some(k), n)?;
        let (_, ddq) = rows_of("ddq", ddq, Some(k), n)?;
        for (what, t) in [("q", &q), ("dq", &dq), ("ddq", &ddq)] {
            if let Some(i) = t.iter().position(|x| !x.is_finite()) {
                return Err(MeasurementError::new_err(format!(
                    "{what}[{}, {}] is not finite (NaN or infinite)",
                    i / n,
                    i % n
                )));
            }
        }
        let inner = &self.inner;
        let (v, a) = py
            .detach(|| {
                let (mut v, mut a) = (std::vec![0.0; 6 * k], std::vec![0.0; 6 * k]);
                for r in 0..k {
                    let rows = r * n..(r + 1) * n;
                    let (tv, ta) = inner
                        .motion(&q[rows.clone()], &dq[rows.clone()], &ddq[rows])
                        .map_err(|e| (r, e))?;
                    v[6 * r..6 * r + 6].copy_from_slice(tv.as_slice());
                    a[6 * r..6 * r + 6].copy_from_slice(ta.as_slice());
                }
                Ok((v, a))
            })
            .map_err(|(r, e): (usize, Error)| {
                MeasurementError::new_err(format!("row {r}: {}", super::python_names(e)))
            })?;
        Ok((array(py, v, (k, 6))?, array(py, a, (k, 6))?))
    }

    /// The geometric Jacobian [J_v; J_ω] at q, (6, n), world-aligned, at the
    /// tip origin: ṗ = J_v q̇ (m/s), ω = J_ω q̇ (rad/s).
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.inner.n();
        let q = self.qv("q", q)?;
        let j = self.inner.jacobian(&q[..n]).map_err(cartesian_error)?;
        let rows = (0..6).flat_map(|i| (0..n).map(move |c| (i, c)));
        array(py, rows.map(|ij| j[ij]).collect(), (6, n))
    }

    /// J̇ q̇ at (q, q̇), (6,): the tip's classical acceleration at q̈ = 0,
    /// [m/s²; rad/s²] (p̈ = J_v q̈ + (J̇ q̇)_v, ω̇ = J_ω q̈ + (J̇ q̇)_ω).
    fn jdot_qdot<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        dq: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.inner.n();
        let (q, dq) = (self.qv("q", q)?, self.qv("dq", dq)?);
        let bias = self
            .inner
            .bias(&q[..n], &dq[..n])
            .map_err(cartesian_error)?;
        Ok(array1(py, bias.as_slice()))
    }
}

// ---------------------------------------------------------------------------
// CartesianImpedance.
// ---------------------------------------------------------------------------

/// The 6-D Cartesian impedance outer loop of SPEC §16 over a `Chain`, with its
/// state; stepped alone (`reference`), with an `adaptimp.Controller`
/// (`step_controller`: the core's joint step) or with a joint controller
/// written in Python (`step_python`). Use `adaptimp.CartesianController`.
#[pyclass(name = "CartesianImpedance", module = "adaptimp._adaptimp", frozen)]
pub struct PyCartesian {
    inner: Shared<dyn DynOuter>,
    n: usize,
}

impl PyCartesian {
    /// The outer loop for a call that may change it ([`Shared::write`]).
    fn lock(&self, py: Python<'_>) -> PyResult<Write<'_, dyn DynOuter>> {
        self.inner.write(py)
    }

    /// The outer loop to read ([`Shared::read`]).
    fn read(&self, py: Python<'_>) -> PyResult<Read<'_, dyn DynOuter>> {
        self.inner.read(py)
    }

    /// The time of the next step, t_k = k·Ts (s).
    pub(super) fn clock(&self, py: Python<'_>) -> PyResult<f64> {
        let g = self.read(py)?;
        Ok(g.steps() as f64 * g.ts())
    }

    fn measurement<'a>(
        &self,
        q: &'a [f64; MAX_JOINTS],
        dq: Option<&'a [f64; MAX_JOINTS]>,
        wrench: [f64; 6],
        target: Option<PoseTarget>,
    ) -> StepIn<'a> {
        StepIn {
            q: &q[..self.n],
            dq: dq.map(|d| &d[..self.n]),
            wrench,
            target,
        }
    }
}

#[pymethods]
impl PyCartesian {
    /// The outer loop with the complete Cartesian parameter dict `params`
    /// (the schema's group "cartesian") over `chain`, at period `ts` (s),
    /// started at `q0` (rad), with the null-space `posture` (default q0).
    #[new]
    #[pyo3(signature = (chain, params, ts, q0, posture=None))]
    fn new(
        chain: &PyChain,
        params: &Bound<'_, PyDict>,
        ts: f64,
        q0: &Bound<'_, PyAny>,
        posture: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let n = chain.inner.n();
        let items: Vec<(String, Owned)> = items(params)?;
        let cfg = scenario::<1>(Preset::Robot, Law::Pd, &items)
            .map_err(config_error)?
            .cartesian;
        let q0 = vector("q0", n, q0)?;
        let posture = posture.map(|p| vector("posture", n, p)).transpose()?;
        let inner = chain
            .typed
            .outer(cfg, ts, &q0[..n], posture.as_ref().map(|p| &p[..n]))
            .map_err(|e| ConfigError::new_err(e.to_string()))?;
        Ok(Self {
            inner: Shared::new(inner, "CartesianController"),
            n,
        })
    }

    /// Joints n.
    #[getter]
    fn n(&self) -> usize {
        self.n
    }

    /// Period Ts (s).
    #[getter]
    fn ts(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.read(py)?.ts())
    }

    /// Steps taken.
    #[getter]
    fn steps(&self, py: Python<'_>) -> PyResult<u64> {
        Ok(self.read(py)?.steps())
    }

    /// Whether the orientation is a task (False: position-only, Kd_rot = 0).
    #[getter]
    fn orients(&self, py: Python<'_>) -> PyResult<bool> {
        Ok(self.read(py)?.orients())
    }

    /// Back to t = 0 at `q0` (rad; default the start's); the posture is kept.
    #[pyo3(signature = (q0=None))]
    fn reset(&self, py: Python<'_>, q0: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let q0 = q0.map(|q| vector("q0", self.n, q)).transpose()?;
        self.lock(py)?
            .reset(q0.as_ref().map(|q| &q[..self.n]))
            .map_err(|e| ConfigError::new_err(e.to_string()))
    }

    /// The null-space posture q_posture (rad), (n,).
    fn set_posture(&self, py: Python<'_>, posture: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = vector("posture", self.n, posture)?;
        self.lock(py)?
            .set_posture(&p[..self.n])
            .map_err(|e| ConfigError::new_err(e.to_string()))
    }

    /// Check a flat pose target (24,) as a step would (its parts finite and
    /// within their ceilings, R_c a rotation), changing nothing:
    /// MeasurementError naming the part.
    fn check_target(&self, py: Python<'_>, target: &Bound<'_, PyAny>) -> PyResult<()> {
        let t = target_of(Some(target))?;
        match t {
            Some(t) => self.read(py)?.check_target(&t).map_err(cartesian_error),
            None => Ok(()),
        }
    }

    /// Ask for the stiffness `Kd` (N/m, (3,)) and `Kd_rot` (N m/rad, (3,)): the
    /// impedance moves to it through the target filter (SPEC (16.6)).
    #[allow(non_snake_case)]
    #[pyo3(name = "set_stiffness", signature = (Kd, Kd_rot))]
    fn set_stiffness(
        &self,
        py: Python<'_>,
        Kd: &Bound<'_, PyAny>,
        Kd_rot: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let (a, b) = (flat("Kd", 3, Kd)?, flat("Kd_rot", 3, Kd_rot)?);
        self.lock(py)?
            .set_stiffness([a[0], a[1], a[2]], [b[0], b[1], b[2]])
            .map_err(|e| ConfigError::new_err(e.to_string()))
    }

    /// The outer loop alone, one committed step: `target` the commanded pose
    /// flat (24,: p, ṗ, p̈, R row-major, ω, ω̇; None: hold the last one),
    /// `wrench` F_e = [f; m] (N, N m). Returns (q_d, q̇_d, q̈_d) of t_k.
    #[pyo3(signature = (target, wrench))]
    #[allow(clippy::type_complexity)]
    fn reference<'py>(
        &self,
        py: Python<'py>,
        target: Option<&Bound<'py, PyAny>>,
        wrench: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let target = target_of(target)?;
        let wrench = wrench_of(wrench)?;
        let mut g = self.lock(py)?;
        g.reference(target.as_ref(), wrench)
            .map_err(cartesian_error)?;
        Ok((
            array1(py, &g.last(0)),
            array1(py, &g.last(1)),
            array1(py, &g.last(2)),
        ))
    }

    /// One Cartesian step with `controller` (an `adaptimp.Controller` with
    /// impedance "external", the same n and Ts): the core's outer loop and
    /// joint step, no Python in between. Returns sat(τ) (N m), (n,).
    #[pyo3(signature = (controller, q, dq, wrench, target=None))]
    fn step_controller<'py>(
        &self,
        py: Python<'py>,
        controller: &Bound<'py, PyAny>,
        q: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
        wrench: &Bound<'py, PyAny>,
        target: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        let q = vector("q", n, q)?;
        let dq = dq.map(|d| vector("dq", n, d)).transpose()?;
        let f_e = wrench_of(wrench)?;
        let m = self.measurement(&q, dq.as_ref(), f_e, target_of(target)?);
        let mut joint = lock_joint(py, controller, n)?;
        let mut g = self.lock(py)?;
        g.step_tracker(joint.joint(), &m).map_err(cartesian_error)?;
        Ok(array1(py, &g.last(16)))
    }

    /// One step of `CartesianController.step` with the core's joint
    /// `controller`, in one call: an `adaptimp.Measurement` as `q` (dq and
    /// wrench None), or q (rad), dq (rad/s), each (n,), the wrench
    /// F_e = [f; m] (N, N m; (6,), f (3,) alone, or None: no contact), the
    /// commanded pose `sample`: None (hold the last target), the tuple (p,
    /// ṗ, p̈) or (p, ṗ, p̈, R, ω, ω̇) a path returns (m, m/s, m/s², (3, 3),
    /// rad/s, rad/s²; a rate None is 0, R None the held rotation, a given R
    /// held from now on) or a flat target (24,); with `record`, the step's row
    /// kept for [`take_log`](Self::take_log). Shapes and types are checked
    /// here, the values by the core (a refused step records its fault).
    /// Returns sat(τ) (N m), (n,).
    #[pyo3(signature = (controller, q, dq, wrench, sample, record))]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step_sample<'py>(
        &self,
        py: Python<'py>,
        controller: &Bound<'py, PyAny>,
        q: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
        wrench: Option<&Bound<'py, PyAny>>,
        sample: Option<&Bound<'py, PyAny>>,
        record: bool,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        let mut qb = [0.0; MAX_JOINTS];
        let mut dqb = [0.0; MAX_JOINTS];
        let (measured_dq, f) = if let Ok(m) = q.cast::<PyMeasurement>() {
            // An adaptimp.Measurement: read as it is, no array made.
            let m = m.get();
            if dq.is_some() || wrench.is_some() {
                return Err(PyTypeError::new_err(
                    "give the measurement as an adaptimp.Measurement or as arrays, not both",
                ));
            }
            if m.n != n {
                return Err(shape_error("q", n, &format!("length {}", m.n)));
            }
            qb = m.q;
            dqb = m.dq.unwrap_or(dqb);
            (m.dq.is_some(), m.wrench.unwrap_or([0.0; 6]))
        } else {
            super::vector_into("q", n, q, &mut qb)?;
            if let Some(d) = dq {
                super::vector_into("dq", n, d, &mut dqb)?;
            }
            let f = match wrench {
                None => [0.0; 6],
                Some(w) => wrench_sample(w)?,
            };
            (dq.is_some(), f)
        };
        let mut joint = lock_joint(py, controller, n)?;
        let mut g = self.lock(py)?;
        // The rotation a sample sets is held only once the core accepted the
        // step: a refused one (a rotation that is not one) keeps nothing.
        let target = match sample {
            None => None,
            Some(s) => Some(sample_target(s, g.held())?),
        };
        let m = self.measurement(&qb, measured_dq.then_some(&dqb), f, target);
        g.step_tracker(joint.joint(), &m).map_err(cartesian_error)?;
        if let Some(t) = &target {
            g.held_mut().hold(t.r);
        }
        if record {
            g.record();
        }
        Ok(array1(py, &g.applied()[..n]))
    }

    /// The commanded rotation a target without one keeps, (3, 3).
    fn held_rotation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = *self.read(py)?.held().rotation();
        array(py, r.transpose().as_slice().to_vec(), (3, 3))
    }

    /// Hold the commanded rotation `r` (3, 3) from now on.
    fn set_held_rotation(&self, py: Python<'_>, r: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = flat("R", 9, r)?;
        self.lock(py)?.held_mut().hold(Matrix3::from_row_slice(&v));
        Ok(())
    }

    /// The rows `step_sample` kept since the last call, (K, 30 + n): p_c,
    /// ṗ_c, p̈_c, p_d, ṗ_d, p̈_d (3 each), q_d (n), F_e (6), the error (6).
    fn take_log<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        // A callback of a run of this controller reads a copy, which keeps
        // no rows: the run's rows join the log when it ends.
        let (v, rows) = match self.inner.write_or_copy(py)? {
            Some(mut g) => g.take_log(),
            None => (Vec::new(), 0),
        };
        array(py, v, (rows, LOG_WIDTH + self.n))
    }

    /// One Cartesian step with a joint controller written in Python:
    /// `inner.step(m, xc=q_d, dxc=q̇_d, ddxc=q̈_d)` is called with the
    /// measurement (q, q̇, τe = Jᵀ F_e, the wrench) and the core's joint
    /// reference (`measurement=False`: the deprecated `inner.step(q, tau_e,
    /// dq, …)`), and the outer state is committed only if it returns.
    /// Returns its torque (N m), (n,).
    #[pyo3(signature = (inner, q, dq, wrench, target=None, *, measurement=true))]
    #[allow(clippy::too_many_arguments)]
    fn step_python<'py>(
        &self,
        py: Python<'py>,
        inner: &Bound<'py, PyAny>,
        q: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
        wrench: &Bound<'py, PyAny>,
        target: Option<&Bound<'py, PyAny>>,
        measurement: bool,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        let q = vector("q", n, q)?;
        let dq = dq.map(|d| vector("dq", n, d)).transpose()?;
        let f_e = wrench_of(wrench)?;
        let m = self.measurement(&q, dq.as_ref(), f_e, target_of(target)?);
        let mut raised: Option<PyErr> = None;
        let mut g = self.lock(py)?;
        // The joint controller may read this one: the state before the step.
        let shown = self.inner.showing(g.view());
        let mut call = |q: &[f64],
                        dq: Option<&[f64]>,
                        tau_e: &[f64],
                        r: [&[f64]; 3],
                        task: Option<(&[f64], &[f64])>,
                        out: &mut [f64]|
         -> Result<(), Error> {
            let result = (|| -> PyResult<Vec<f64>> {
                let kw = PyDict::new(py);
                kw.set_item("xc", array1(py, r[0]))?;
                kw.set_item("dxc", array1(py, r[1]))?;
                kw.set_item("ddxc", array1(py, r[2]))?;
                if let Some((torque, jt)) = task {
                    // Jᵀ is n × 6 column-major: J (6 × n) row-major.
                    kw.set_item("task_torque", array1(py, torque))?;
                    let j = numpy::PyArray1::from_slice(py, jt).reshape([6, torque.len()])?;
                    kw.set_item("jacobian", j)?;
                }
                let tau = if measurement {
                    let meas = PyMeasurement::of(q, dq, Some(tau_e), Some(&f_e));
                    inner.call_method("step", (Bound::new(py, meas)?,), Some(&kw))?
                } else {
                    let dq = dq.map(|d| array1(py, d));
                    inner.call_method("step", (array1(py, q), array1(py, tau_e), dq), Some(&kw))?
                };
                super::callback::numeric_torque(&tau, out.len())?;
                let v = flat("the joint controller's torque", out.len(), &tau)?;
                Ok(v)
            })();
            match result {
                Ok(v) => {
                    out.copy_from_slice(&v);
                    Ok(())
                }
                Err(e) => {
                    raised = Some(e);
                    Err(Error::Invalid {
                        what: "joint controller",
                        reason: "raised",
                    })
                }
            }
        };
        let r = g.step_joint(&m, &mut call);
        drop(shown);
        if let Some(e) = raised {
            return Err(e);
        }
        r.map_err(cartesian_error)?;
        Ok(array1(py, &g.last(16)))
    }

    /// A quantity of the last step by name: "q_d", "dq_d", "ddq_d" (n,);
    /// "p_d", "dp_d", "ddp_d", "w_d", "dw_d" (3,) and "R_d" (3, 3), the
    /// compliant reference; "p_t" (3,), "R_t" (3, 3), the filtered target;
    /// "error" (6,) [e_p; e_o] after clipping; "p" (3,), "R" (3, 3), the
    /// measured tip; "tau_e", "tau", "tau_sat", "z1" (n,); "p_c", "dp_c",
    /// "ddp_c" (3,), the commanded position and rates (the filtered target
    /// p_t at rest when the step had none); "wrench" (6,), the F_e it was
    /// given (NaN before a step).
    fn last<'py>(&self, py: Python<'py>, what: &str) -> PyResult<Bound<'py, PyAny>> {
        let i = LAST
            .iter()
            .position(|n| *n == what)
            .ok_or_else(|| PyValueError::new_err(format!("last: one of {LAST:?}, got {what:?}")))?;
        let v = self.read(py)?.last(i);
        if v.len() == 9 && what.starts_with('R') {
            Ok(array(py, v, (3, 3))?.into_any())
        } else {
            Ok(array1(py, &v).into_any())
        }
    }

    /// A quantity of the state by name: "p_d" (3,), "R_d" (3, 3), "q_d",
    /// "dq_d", "posture" (n,), "stiffness", "stiffness_filtered" (6,)
    /// [K_d; K_d,rot], "offset" (6,) of the target filter, "wrench" (6,)
    /// filtered.
    fn state<'py>(&self, py: Python<'py>, what: &str) -> PyResult<Bound<'py, PyAny>> {
        let i = STATE.iter().position(|n| *n == what).ok_or_else(|| {
            PyValueError::new_err(format!("state: one of {STATE:?}, got {what:?}"))
        })?;
        let v = self.read(py)?.state(i);
        if what == "R_d" {
            Ok(array(py, v, (3, 3))?.into_any())
        } else {
            Ok(array1(py, &v).into_any())
        }
    }

    /// The closed loop on MuJoCo of this outer loop in front of `controller`
    /// (an `adaptimp.Controller` with impedance "external", the same n and
    /// Ts), from both states (not reset), with the GIL released: the core's
    /// loop (`adaptimp.mujoco.simulate`'s native loop, SPEC §13.1) with the
    /// measured wrench. `model`, `data`, `spec`, `params` (the disturbances
    /// of SPEC §17), `t_final`, `settle`, `record_every`, `progress`,
    /// `fault` as for `simulate_mujoco`; `targets` the commanded pose of
    /// every row (K, 24) (None: the last target held). Returns the dict of
    /// `simulate_mujoco` with the reference in task space ("xc", "dxc",
    /// "ddxc" = p_c, ṗ_c, p̈_c; "xd" = p_d; "z1" = p_d − p(q); (K, 3)), the
    /// metrics of task space, and "task": a dict of "pc", "dpc", "ddpc",
    /// "pd", "dpd", "ddpd" (K, 3), "qd" (K, n), "wrench", "error" (K, 6).
    /// Afterwards `last` gives the last step taken, also after an error.
    #[pyo3(signature = (controller, model, data, spec, params, t_final, settle, record_every=1, progress=None, targets=None, fault=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate_mujoco<'py>(
        &self,
        py: Python<'py>,
        controller: &Bound<'py, PyAny>,
        model: &Bound<'py, PyAny>,
        data: &Bound<'py, PyAny>,
        spec: &Bound<'py, PyDict>,
        params: &Bound<'py, PyDict>,
        t_final: f64,
        settle: f64,
        record_every: u64,
        progress: Option<Py<PyAny>>,
        targets: Option<PyReadonlyArray2<'py, f64>>,
        fault: Option<super::PyFault>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let fault = super::fault_spec(fault)?;
        if record_every == 0 {
            return Err(ConfigError::new_err("record_every must be ≥ 1"));
        }
        let mut joint = lock_joint(py, controller, self.n)?;
        let spec = super::mujoco_spec(spec)?;
        let items = items(params)?;
        let targets = match &targets {
            None => None,
            Some(t) => Some(rows(t.shape()[0], "targets", t, TARGET_LEN)?),
        };
        let mut sim = Sim::from_python(model, data)?;
        let run = CartesianRun {
            t_final,
            settle,
            every: record_every,
            items: &items,
            targets: targets.as_deref(),
            fault: fault.as_ref(),
        };
        let mut hooks = super::PyHooks::holding(progress, vec![&self.inner, joint.slot()]);
        let mut outer = self.lock(py)?;
        let mut partial = None;
        let result = {
            let (t, o): (JointRef<'_>, &mut dyn DynOuter) = (joint.joint(), &mut **outer);
            py.detach(|| o.simulate_mujoco(t, &mut sim, &spec, &run, &mut hooks, &mut partial))
        };
        drop(outer);
        drop(joint);
        drop(sim);
        let (rec, task, metrics) = match result {
            Ok(out) => out,
            Err(e) => {
                // The rows of the steps taken before the error (Ctrl-C, a
                // diverged plant), as the exception's `partial`: the
                // controller's log keeps them.
                let err = super::run_error(e, &mut hooks);
                if let Some(task) = partial {
                    let k = task.z1.len() / 3;
                    err.value(py).setattr("partial", task_dict(py, task, k)?)?;
                }
                return Err(err);
            }
        };
        let k = rec.len();
        let out = super::records_dict(py, rec, metrics, true)?;
        for (name, v) in [
            ("xc", &task.pc[0]),
            ("dxc", &task.pc[1]),
            ("ddxc", &task.pc[2]),
            ("xd", &task.pd[0]),
            ("z1", &task.z1),
        ] {
            out.set_item(name, array(py, v.clone(), (k, 3))?)?;
        }
        out.set_item("task", task_dict(py, task, k)?)?;
        Ok(out)
    }

    /// Steps of this outer loop in front of `controller` (as for
    /// `step_controller`) over recorded rows, the core's alone with the GIL
    /// released: q, dq (K, n) (rad, rad/s), wrench (K, 6) (N, N m),
    /// `targets` (K, 24) (None: the last target held). Returns sat(τ) (K, n)
    /// (N m); errors name the row. For the cost of the controller without a
    /// plant.
    #[pyo3(signature = (controller, q, dq, wrench, targets=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn replay<'py>(
        &self,
        py: Python<'py>,
        controller: &Bound<'py, PyAny>,
        q: PyReadonlyArray2<'py, f64>,
        dq: PyReadonlyArray2<'py, f64>,
        wrench: PyReadonlyArray2<'py, f64>,
        targets: Option<PyReadonlyArray2<'py, f64>>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.n;
        let k = q.shape()[0];
        let q = super::table("q", &q, k, n)?;
        let dq = super::table("dq", &dq, k, n)?;
        let wrench = super::table("wrench", &wrench, k, 6)?;
        let targets = match &targets {
            None => None,
            Some(t) => Some(super::table("targets", t, k, TARGET_LEN)?),
        };
        let mut out = Vec::with_capacity(k * n);
        let mut joint = lock_joint(py, controller, n)?;
        let mut hooks = super::PyHooks::holding(progress, vec![&self.inner, joint.slot()]);
        let mut outer = self.lock(py)?;
        let result = {
            let (t, o): (JointRef<'_>, &mut dyn DynOuter) = (joint.joint(), &mut **outer);
            py.detach(|| {
                o.replay(
                    t,
                    k,
                    [&q, &dq, &wrench],
                    targets.as_deref(),
                    &mut out,
                    &mut hooks,
                )
            })
        };
        drop(outer);
        drop(joint);
        result.map_err(|e| super::run_error(e, &mut hooks))?;
        array(py, out, (k, n))
    }

    /// The steps round(T/Ts) of an orbit of `T` (s) at this loop's period
    /// (1 … 1e6) and the number of samples `nodes` (an integer ≥ 1), checked
    /// by name before a path is tabulated.
    #[pyo3(name = "orbit_size", signature = (T, nodes))]
    #[allow(non_snake_case)]
    fn orbit_size(
        &self,
        py: Python<'_>,
        T: &Bound<'_, PyAny>,
        nodes: &Bound<'_, PyAny>,
    ) -> PyResult<(usize, usize)> {
        let t = real("T", T)?;
        let nodes = count("nodes", nodes)?;
        let ts = self.read(py)?.ts();
        let steps = adaptimp::cartesian::orbit_steps(t, ts)
            .map_err(|e| ConfigError::new_err(e.to_string()))?;
        Ok((steps, nodes))
    }

    /// The orbit rule (SPEC §15, §16): run this outer loop kinematically
    /// (F_e = 0) from `q0` along `targets` (K, 24) (one flat pose target per
    /// step) and return the joint reference (q_d, q̇_d, q̈_d, each (L, n)) of
    /// every max(1, K // nodes)-th step, L ≤ `nodes`. This loop's state is
    /// unchanged.
    #[allow(clippy::type_complexity)]
    fn orbit<'py>(
        &self,
        py: Python<'py>,
        q0: &Bound<'py, PyAny>,
        targets: PyReadonlyArray2<'py, f64>,
        nodes: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        let n = self.n;
        let q0 = vector("q0", n, q0)?;
        let nodes = count("nodes", nodes)?;
        let k = targets.shape()[0];
        let flat_rows = rows(k, "targets", &targets, TARGET_LEN)?;
        let ts: Vec<PoseTarget> = flat_rows.chunks(TARGET_LEN).map(pose_target).collect();
        let g = self.read(py)?;
        let [q, dq, ddq] = py
            .detach(|| g.orbit(&q0[..n], &ts, nodes))
            .map_err(cartesian_error)?;
        let l = q.len() / n;
        Ok((
            array(py, q, (l, n))?,
            array(py, dq, (l, n))?,
            array(py, ddq, (l, n))?,
        ))
    }
}

/// RBF centres along an orbit, SPEC §15 (15.2) (`Centers::along`, or
/// `along_periodic` for one period of a periodic orbit): the samples q (L, n)
/// (rad) and q̇ (L, n) (rad/s), the tube (rad, rad/s). Returns the centres
/// (L, 4n) and the squared widths (4n,) (infinite for α1, α̇1).
#[pyfunction]
#[pyo3(signature = (q, dq, tube, periodic=false))]
#[allow(clippy::type_complexity)]
pub fn centres_along<'py>(
    py: Python<'py>,
    q: PyReadonlyArray2<'py, f64>,
    dq: PyReadonlyArray2<'py, f64>,
    tube: (f64, f64),
    periodic: bool,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>)> {
    let (l, n) = (q.shape()[0], q.shape()[1]);
    if !(1..=MAX_CHAIN_JOINTS).contains(&n) || l == 0 {
        return Err(ConfigError::new_err(format!(
            "q must have shape (L, n) with L ≥ 1 and 1 ≤ n ≤ 7, got {}",
            python_shape(q.shape())
        )));
    }
    let qs = rows(l, "q", &q, n)?;
    let dqs = rows(l, "dq", &dq, n)?;
    let samples = qs
        .chunks(n)
        .zip(dqs.chunks(n))
        .map(|(x, dx)| {
            Ok(adaptimp::dynamic::Setpoint {
                x: Joints::from_slice(x)?,
                dx: Joints::from_slice(dx)?,
                ddx: Joints::zeros(n)?,
            })
        })
        .collect::<Result<Vec<_>, Error>>();
    let c = samples
        .and_then(|s| Centres::along(&s, [tube.0, tube.1], periodic))
        .map_err(|e| ConfigError::new_err(e.to_string()))?;
    let (c, w) = (c.rows, c.widths2.unwrap_or_default());
    Ok((array(py, c, (l, 4 * n))?, array1(py, &w)))
}
