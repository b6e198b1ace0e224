//! The outer loop behind `adaptimp.CartesianImpedance`: one monomorphised
//! core per n behind an object-safe face ([`DynOuter`]), slices in and out,
//! until the bindings' joint controllers are the core's run-time ones and
//! the outer loop can be the core's `dynamic::CartesianImpedance`.

use super::cartesian_loop::{self, CartesianOut, CartesianRun, JointStep, OuterRun};
use super::computed::{ComputedCore, ComputedStep};
use super::dynamic::{AdaptiveStep, Hooks, JointCore, RunError, MAX_JOINTS};
use super::mujoco::MujocoSpec;
use adaptimp::cartesian::{
    CartesianConfig, CartesianImpedance, CartesianMeasurement, CartesianState, Chain, Joint,
    JointKind, PoseTarget, Transform,
};
use adaptimp::dynamic::HeldRotation;
use adaptimp::dynamic::{TaskRows, TypedTaskStep};
use adaptimp::error::Error;
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use core::any::{Any, TypeId};
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

pub(super) fn vector_of<const N: usize>(v: &[f64]) -> Vector<N> {
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
        partial: &mut Option<TaskRows>,
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

/// The typed joint controller of N joints behind `joint`; `run`: for a run,
/// which publishes copies of it for the Python code it calls.
pub(super) fn typed<const N: usize>(
    joint: JointRef<'_>,
    run: bool,
) -> Result<TypedJoint<'_, N>, Error> {
    match joint {
        JointRef::Adaptive(c) => AdaptiveStep::of(c, run).map(TypedJoint::Adaptive),
        JointRef::Computed(c) => ComputedStep::of(c, run).map(TypedJoint::Computed),
    }
}

pub(super) struct Outer<const N: usize> {
    outer: CartesianImpedance<N, Chain<N>>,
    state: CartesianState<N>,
    q0: Vector<N>,
    posture: Vector<N>,
    last: Option<TypedTaskStep<N>>,
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
    fn at(&self, state: &CartesianState<N>, last: Option<&TypedTaskStep<N>>) -> Self {
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
        last: Option<&TypedTaskStep<N>>,
    ) -> Option<Box<dyn Any + Send>> {
        (part == TypeId::of::<Box<dyn DynOuter>>()).then(|| {
            Box::new(Box::new(self.at(state, last)) as Box<dyn DynOuter>) as Box<dyn Any + Send>
        })
    }

    /// A run of this loop in front of `joint` (a MuJoCo run, a replay):
    /// `run` gets the loop's parts, the typed joint controller and how the
    /// run copies this loop for the Python code it calls (the loop as
    /// before the run, at the run's state and last step).
    fn run_with<R>(
        &mut self,
        joint: JointRef<'_>,
        run: impl FnOnce(OuterRun<'_, N>) -> Result<R, RunError>,
    ) -> Result<R, RunError> {
        let mut joint = typed::<N>(joint, true)?;
        let before = self.at(&self.state, None);
        let copy = |part: TypeId, state: &CartesianState<N>, last: Option<&TypedTaskStep<N>>| {
            before.copy_as(part, state, last)
        };
        run(OuterRun {
            outer: &self.outer,
            state: &mut self.state,
            joint: joint.step(),
            last: &mut self.last,
            copy: &copy,
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

pub(super) fn quaternion_rows(q: &nalgebra::UnitQuaternion<f64>) -> Vec<f64> {
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
        let c = &last.command;
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
        let cmd = self
            .outer
            .reference(&mut self.state, target, &wrench.into())?;
        self.last = Some(TypedTaskStep::new(cmd, target, wrench));
        Ok(())
    }
    fn step_tracker(&mut self, joint: JointRef<'_>, m: &StepIn<'_>) -> Result<(), Error> {
        let mut typed = typed::<N>(joint, false)?;
        let meas = Self::measurement(m);
        let cmd = cartesian_loop::cartesian_step(
            &self.outer,
            &mut self.state,
            typed.step(),
            &meas,
            m.target.as_ref(),
        )?;
        self.last = Some(TypedTaskStep::new(cmd, m.target.as_ref(), m.wrench));
        Ok(())
    }
    fn step_joint(&mut self, m: &StepIn<'_>, joint: &mut JointFn<'_>) -> Result<(), Error> {
        let meas = Self::measurement(m);
        let target = m.target.as_ref();
        let cmd = self
            .outer
            .step_with_torque(&mut self.state, &meas, target, |jm, r, task| {
                let mut tau = [0.0; MAX_JOINTS];
                // Jᵀ (n × 6) column-major: J (6 × n) row-major.
                let rows = task.map(|(torque, j)| (torque, j.transpose()));
                joint(
                    jm.x.as_slice(),
                    jm.dx.as_ref().map(|d| d.as_slice()),
                    jm.tau_e.as_slice(),
                    [r.x.as_slice(), r.dx.as_slice(), r.ddx.as_slice()],
                    rows.as_ref().map(|(t, j)| (t.as_slice(), j.as_slice())),
                    &mut tau[..N],
                )?;
                Ok(vector_of::<N>(&tau))
            })?;
        self.last = Some(TypedTaskStep::new(cmd, m.target.as_ref(), m.wrench));
        Ok(())
    }
    fn applied(&self) -> [f64; MAX_JOINTS] {
        let mut out = [f64::NAN; MAX_JOINTS];
        if let Some(last) = &self.last {
            out[..N].copy_from_slice(last.command.joint.tau_sat.as_slice());
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
        let c = &last.command;
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
        let out = self
            .outer
            .orbit_samples(q0, targets.len(), |k| targets[k], nodes)?;
        let q = out.iter().flat_map(|s| s.x.iter().copied()).collect();
        let dq = out.iter().flat_map(|s| s.dx.iter().copied()).collect();
        let ddq = out.iter().flat_map(|s| s.ddx.iter().copied()).collect();
        Ok([q, dq, ddq])
    }
    fn simulate_mujoco(
        &mut self,
        joint: JointRef<'_>,
        sim: &mut Sim,
        spec: &MujocoSpec,
        run: &CartesianRun<'_>,
        hooks: &mut dyn Hooks,
        partial: &mut Option<TaskRows>,
    ) -> Result<CartesianOut, RunError> {
        self.run_with(joint, |o| {
            cartesian_loop::simulate_mujoco(o, sim, spec, run, hooks, partial)
        })
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
        self.run_with(joint, |o| {
            cartesian_loop::replay(o, rows, tables, targets, out, hooks)
        })
    }
    fn view(&self) -> Box<dyn DynOuter> {
        Box::new(self.at(&self.state, None))
    }
}
