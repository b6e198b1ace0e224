//! The Cartesian controller for n joints known at run time (SPEC §16): the
//! 6-D outer loop over a [`Chain`] ([`CartesianImpedance`], its
//! [`CartesianState`]) stepped with a joint controller of the core
//! ([`Joint`]: the paper's laws or computed torque) or of the caller's
//! ([`CartesianImpedance::step_with`]), and the validated pair of the outer
//! loop and its joint controller ([`CartesianController`]).

use super::controller::{Controller, State};
use super::model::{Chain, ComputedState, ComputedTorque, Jacobian};
use super::sized::{each, map, pair, ByJoints, Family};
use super::values::{mismatch, vector, Command, Joints, Measurement, Setpoint};
use crate::cartesian::{
    self, check_joint, set_pair_posture, start_pair, CartesianConfig, CompliantPose, PoseTarget,
};
use crate::error::Error;
use crate::types::Vector;
use alloc::boxed::Box;
use alloc::vec::Vec;
use nalgebra::{Rotation3, UnitQuaternion};

pub(crate) struct OuterF;
impl Family for OuterF {
    type Of<const N: usize> = Box<cartesian::CartesianImpedance<N, cartesian::Chain<N>>>;
}

pub(crate) struct OuterStateF;
impl Family for OuterStateF {
    type Of<const N: usize> = cartesian::CartesianState<N>;
}

/// The 6-D Cartesian impedance outer loop over a chain of n joints (SPEC
/// §16): the run-time [`CartesianImpedance`](crate::CartesianImpedance),
/// validated and immutable.
#[derive(Clone, Debug)]
pub struct CartesianImpedance {
    pub(crate) inner: ByJoints<OuterF>,
}

/// The state of the outer loop (the compliant reference, the joint
/// reference, the filters): the run-time [`CartesianState`](crate::CartesianState).
#[derive(Clone, Debug)]
pub struct CartesianState {
    pub(crate) inner: ByJoints<OuterStateF>,
}

/// One sample from the sensors at t_k: the run-time
/// [`CartesianMeasurement`](crate::CartesianMeasurement).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianMeasurement<'a> {
    /// Joint position q (rad), n values.
    pub q: &'a [f64],
    /// Joint velocity q̇ (rad/s), n values, if measured.
    pub dq: Option<&'a [f64]>,
    /// The wrench the tip exerts on the environment F_e = [f (N); m (N m)],
    /// world frame, the moment about the tip.
    pub wrench: Vector<6>,
}

impl CartesianMeasurement<'_> {
    fn typed<const N: usize>(&self) -> Result<cartesian::CartesianMeasurement<N>, Error> {
        Ok(cartesian::CartesianMeasurement {
            q: vector("q", self.q)?,
            dq: self.dq.map(|d| vector("dq", d)).transpose()?,
            wrench: self.wrench,
        })
    }
}

/// What a Cartesian step computed: the run-time
/// [`CartesianCommand`](crate::CartesianCommand); `joint.tau_sat` goes to
/// the actuators.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianCommand {
    /// The joint controller's command (τ, sat(τ), z1 = q_d − q, …).
    pub joint: Command,
    /// The joint reference q_d, q̇_d, q̈_d (rad, rad/s, rad/s²) at t_k.
    pub reference: Setpoint,
    /// The commanded joint reference q_c, q̇_c, q̈_c at t_k (SPEC §19).
    pub commanded: Setpoint,
    /// The compliant reference pose at t_k.
    pub compliant: CompliantPose,
    /// The commanded pose at t_k after the target filter (p_t (m), R_t).
    pub target: (Vector<3>, UnitQuaternion<f64>),
    /// The error [e_p (m); e_o (rad)] the impedance acted on (after clipping).
    pub error: Vector<6>,
    /// The measured tip position fk(q) (m).
    pub p: Vector<3>,
    /// The measured tip rotation R(q).
    pub r: Rotation3<f64>,
    /// τe = Jᵀ(q) F_e (N m) the joint controller got (zero without
    /// `force_feedforward`).
    pub tau_e: Joints,
}

impl CartesianCommand {
    /// The run-time command of the const-generic outer loop's `c`, its
    /// values copied bit for bit (a loop that steps the const-generic
    /// controller and records its steps in [`TaskRows`](crate::dynamic::TaskRows)).
    pub fn of<const N: usize>(c: &cartesian::CartesianCommand<N>) -> Self {
        Self {
            joint: Command::of(&c.joint),
            reference: Setpoint::of(&c.reference),
            commanded: Setpoint::of(&c.commanded),
            compliant: c.compliant,
            target: c.target,
            error: c.error,
            p: c.p,
            r: c.r,
            tau_e: Joints::of(&c.tau_e),
        }
    }
}

/// The joint controller of the core an outer loop drives, with its state:
/// the paper's laws or computed torque (SPEC §20).
#[derive(Debug)]
pub enum Joint<'a, S = Vec<f64>> {
    /// A [`Controller`] (with `impedance = "external"`) and its state.
    Adaptive(&'a Controller, &'a mut State<S>),
    /// A [`ComputedTorque`] (in the external mode) and its state.
    Computed(&'a ComputedTorque, &'a mut ComputedState),
}

impl<S: AsRef<[f64]> + AsMut<[f64]>> Joint<'_, S> {
    /// Its number of joints (the controller's).
    pub fn n(&self) -> usize {
        match self {
            Joint::Adaptive(c, _) => c.n(),
            Joint::Computed(c, _) => c.n(),
        }
    }

    /// Its period Ts (s).
    pub fn period(&self) -> f64 {
        match self {
            Joint::Adaptive(c, _) => c.period(),
            Joint::Computed(c, _) => c.period(),
        }
    }

    /// Record a step refused before it reached it (an input of the wrong
    /// length); `None` for a state of another number of joints.
    pub fn refuse(&mut self, error: Error) -> Option<Joints> {
        match self {
            Joint::Adaptive(c, s) => c.refuse(s, error),
            Joint::Computed(c, s) => c.refuse(s, error),
        }
    }

    /// The torque it applies now (N m): the last step's, or its fallback.
    pub fn applied(&self) -> Joints {
        match self {
            Joint::Adaptive(_, s) => s.applied(),
            Joint::Computed(_, s) => s.applied(),
        }
    }
}

/// What a joint law of the caller's gets at a Cartesian step
/// ([`CartesianImpedance::step_with`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct JointInput<'a> {
    /// q, q̇ as measured and τe = Jᵀ(q) F_e (zero without `force_feedforward`).
    pub measurement: Measurement<'a>,
    /// The joint reference to track: the compliant q_d, q̇_d, q̈_d; for the
    /// torque-level formulations (SPEC §19) the commanded q_c, q̇_c, q̈_c.
    pub reference: Setpoint<&'a [f64]>,
    /// For the torque-level formulations: the task part.
    pub task: Option<TaskInput<'a>>,
}

/// The task part of a torque-level Cartesian step (SPEC §19) for a joint
/// law of the caller's.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TaskInput<'a> {
    /// The task torque Jᵀ(K̃e + B(ṗ_c − J q̇)) (N m) at the measured q̇.
    pub torque: &'a [f64],
    /// The task Jacobian J(q) (6 × n).
    pub jacobian: &'a Jacobian,
}

impl CartesianImpedance {
    /// Validate `cfg` (each condition named, as SPEC §10) over `chain` at the
    /// period `ts` (s): [`CartesianImpedance::new`](crate::CartesianImpedance::new).
    pub fn new(cfg: CartesianConfig, chain: &Chain, ts: f64) -> Result<Self, Error> {
        let inner = map!(&chain.inner, c, N => {
            cartesian::CartesianImpedance::new(cfg, **c, ts).map(Box::new)
        })?;
        Ok(Self { inner })
    }

    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// Ts (s).
    pub fn period(&self) -> f64 {
        each!(&self.inner, o, N => o.period())
    }

    /// The const-generic outer loop, if made for N joints: for a caller
    /// generic over N (a typed loop, [`for_joints`](super::for_joints)).
    pub fn typed<const N: usize>(
        &self,
    ) -> Option<&cartesian::CartesianImpedance<N, cartesian::Chain<N>>> {
        each!(&self.inner, o, M => (&**o as &dyn core::any::Any).downcast_ref())
    }

    /// Whether the orientation is a task (Kd_rot > 0).
    pub fn orients(&self) -> bool {
        each!(&self.inner, o, N => o.orients())
    }

    /// The validated parameters.
    pub fn config(&self) -> &CartesianConfig {
        each!(&self.inner, o, N => o.config())
    }

    /// A state at t = 0 at `q0` (rad, n values), checked:
    /// [`CartesianImpedance::start_checked`](crate::CartesianImpedance::start_checked).
    pub fn start(&self, q0: &[f64]) -> Result<CartesianState, Error> {
        let inner = map!(&self.inner, o, N => o.start_checked(&vector::<N>("q0", q0)?))?;
        Ok(CartesianState { inner })
    }

    /// `state` back to t = 0 at `q0` (rad, n values), checked as
    /// [`start`](Self::start) checks it, its null-space posture kept; on an
    /// error `state` is unchanged.
    pub fn restart(&self, state: &mut CartesianState, q0: &[f64]) -> Result<(), Error> {
        pair!(&self.inner, &mut state.inner, o, s, N => {
            let fresh = o.start_checked(&vector::<N>("q0", q0)?)?;
            let posture = s.posture;
            *s = fresh;
            s.posture = posture;
            Ok(())
        }, _ => Err(mismatch("state")))
    }

    /// The null-space posture (rad) from the next step on:
    /// [`CartesianImpedance::set_posture`](crate::CartesianImpedance::set_posture).
    pub fn set_posture(&self, state: &mut CartesianState, posture: &[f64]) -> Result<(), Error> {
        pair!(&self.inner, &mut state.inner, o, s, N => o.set_posture(s, &vector::<N>("posture", posture)?), _ => Err(mismatch("state")))
    }

    /// Ask for the stiffness `kd` (N/m) and `kd_rot` (N m/rad):
    /// [`CartesianImpedance::set_stiffness`](crate::CartesianImpedance::set_stiffness).
    pub fn set_stiffness(
        &self,
        state: &mut CartesianState,
        kd: &Vector<3>,
        kd_rot: &Vector<3>,
    ) -> Result<(), Error> {
        pair!(&self.inner, &mut state.inner, o, s, N => o.set_stiffness(s, kd, kd_rot), _ => Err(mismatch("state")))
    }

    /// Check a commanded pose as a step would, changing nothing.
    pub fn check_target(&self, target: &PoseTarget) -> Result<(), Error> {
        each!(&self.inner, o, N => o.check_target(target))
    }

    /// The outer loop alone, one committed step (F_e = `wrench`): the joint
    /// reference of t_k for a joint controller stepped elsewhere, in a
    /// command whose joint part is zero and whose measured tip is fk(q_d).
    pub fn reference(
        &self,
        state: &mut CartesianState,
        target: Option<&PoseTarget>,
        wrench: &Vector<6>,
    ) -> Result<CartesianCommand, Error> {
        pair!(&self.inner, &mut state.inner, o, s, N => {
            o.reference(s, target, wrench).map(|cmd| CartesianCommand::of(&cmd))
        }, _ => Err(mismatch("state")))
    }

    /// One Cartesian step at t_k with the core's joint controller `joint`:
    /// [`CartesianImpedance::step_joint`](crate::CartesianImpedance::step_joint)
    /// bit for bit, no allocation (the pair's step,
    /// [`CartesianController::step`](crate::CartesianController::step), for
    /// the paper's laws). A measurement of another length than n is refused
    /// by name and recorded in `joint`; a state or a joint controller of
    /// another number of joints is refused and nothing changes.
    pub fn step<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        state: &mut CartesianState,
        joint: Joint<'_, S>,
        m: &CartesianMeasurement<'_>,
        target: Option<&PoseTarget>,
    ) -> Result<CartesianCommand, Error> {
        each!(&self.inner, o, N => {
            let st = state.inner.get_mut::<N>().ok_or(mismatch("state"))?;
            match joint {
                Joint::Adaptive(c, s) => {
                    let c = c.inner.get::<N>().ok_or(mismatch("joint controller"))?;
                    let s = s.inner.get_mut::<N>().ok_or(mismatch("joint state"))?;
                    let m = match m.typed::<N>() {
                        Ok(m) => m,
                        Err(e) => {
                            c.ctrl.refuse(s, e);
                            return Err(e);
                        }
                    };
                    o.step_joint(st, &mut (&c.ctrl, s), &m, target)
                }
                Joint::Computed(c, s) => {
                    let c = c.inner.get::<N>().ok_or(mismatch("joint controller"))?;
                    let s = s.inner.get_mut::<N>().ok_or(mismatch("joint state"))?;
                    let m = match m.typed::<N>() {
                        Ok(m) => m,
                        Err(e) => {
                            c.refuse(s, e);
                            return Err(e);
                        }
                    };
                    o.step_joint(st, &mut (&**c, s), &m, target)
                }
            }
            .map(|cmd| CartesianCommand::of(&cmd))
        })
    }

    /// One Cartesian step with a joint law of the caller's (a controller
    /// written in another language): `joint` gets the measurement with τe =
    /// Jᵀ F_e, the joint reference and, for the torque-level formulations,
    /// the task part ([`JointInput`]), and returns the torque to apply (N m,
    /// n values). The outer state is committed only if it returns a torque.
    /// The command's joint part is that torque (τ = sat(τ)) with z1 = q_d −
    /// q and xc = xd = q_d.
    pub fn step_with<F>(
        &self,
        state: &mut CartesianState,
        m: &CartesianMeasurement<'_>,
        target: Option<&PoseTarget>,
        joint: F,
    ) -> Result<CartesianCommand, Error>
    where
        F: FnOnce(&JointInput<'_>) -> Result<Joints, Error>,
    {
        pair!(&self.inner, &mut state.inner, o, s, N => {
            let m = m.typed::<N>()?;
            o.step_with_torque(s, &m, target, |jm, reference, task| {
                let task = task.map(|(torque, j)| (Joints::of(torque), Jacobian::of(j)));
                let input = JointInput {
                    measurement: Measurement {
                        x: jm.x.as_slice(),
                        dx: jm.dx.as_ref().map(|d| d.as_slice()),
                        tau_e: jm.tau_e.as_slice(),
                    },
                    reference: Setpoint {
                        x: reference.x.as_slice(),
                        dx: reference.dx.as_slice(),
                        ddx: reference.ddx.as_slice(),
                    },
                    task: task.as_ref().map(|(torque, jacobian)| TaskInput {
                        torque: torque.as_slice(),
                        jacobian,
                    }),
                };
                vector::<N>("the joint controller's torque", &joint(&input)?)
            })
            .map(|cmd| CartesianCommand::of(&cmd))
        }, _ => Err(mismatch("state")))
    }

    /// The orbit rule (SPEC §15, §16): run the outer loop kinematically
    /// (F_e = 0) from `q0` (rad, finite) for `steps` steps along `path(k)`,
    /// keeping the joint reference of every max(1, ⌊steps / L⌋)-th step,
    /// L = min(`nodes`, `steps`) at most:
    /// [`CartesianImpedance::orbit`](crate::CartesianImpedance::orbit).
    pub fn orbit<P: FnMut(usize) -> PoseTarget>(
        &self,
        q0: &[f64],
        steps: usize,
        path: P,
        nodes: usize,
    ) -> Result<Vec<Setpoint>, Error> {
        each!(&self.inner, o, N => {
            let q0 = vector::<N>("q0", q0)?;
            let out = o.orbit_samples(q0, steps, path, nodes)?;
            Ok(out.iter().map(Setpoint::of).collect())
        })
    }
}

impl CartesianState {
    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// The const-generic state, if made for N joints: for a caller generic
    /// over N (a typed loop, [`for_joints`](super::for_joints)).
    pub fn typed<const N: usize>(&self) -> Option<&cartesian::CartesianState<N>> {
        each!(&self.inner, s, M => (s as &dyn core::any::Any).downcast_ref())
    }

    /// [`typed`](Self::typed), to change.
    pub fn typed_mut<const N: usize>(&mut self) -> Option<&mut cartesian::CartesianState<N>> {
        each!(&mut self.inner, s, M => (s as &mut dyn core::any::Any).downcast_mut())
    }

    /// Steps taken k.
    pub fn steps(&self) -> u64 {
        each!(&self.inner, s, N => s.k)
    }

    /// The compliant reference position p_d (m) and rotation R_d.
    pub fn pose_d(&self) -> (Vector<3>, UnitQuaternion<f64>) {
        each!(&self.inner, s, N => (s.pd, s.rd))
    }

    /// The joint reference q_d (rad) and q̇_d (rad/s).
    pub fn joint_d(&self) -> (Joints, Joints) {
        each!(&self.inner, s, N => (Joints::of(&s.qd), Joints::of(&s.dqd)))
    }

    /// The null-space posture (rad).
    pub fn posture(&self) -> Joints {
        each!(&self.inner, s, N => Joints::of(&s.posture))
    }

    /// The stiffness asked for and the filtered one the impedance uses,
    /// [K_d; K_d,rot] each (N/m, N m/rad).
    pub fn stiffness(&self) -> (Vector<6>, Vector<6>) {
        each!(&self.inner, s, N => (s.stiffness, s.stiffness_filtered))
    }

    /// The target filter's offset [o_p (m); o_r (rad)] and the filtered
    /// wrench [f (N); m (N m)] (16.6).
    pub fn filters(&self) -> (Vector<6>, Vector<6>) {
        each!(&self.inner, s, N => (s.offset, s.wrench))
    }
}

/// The 6-D Cartesian impedance and the joint controller it drives (C5),
/// validated as a pair: the run-time
/// [`CartesianController`](crate::CartesianController).
#[derive(Clone, Debug)]
pub struct CartesianController {
    outer: CartesianImpedance,
    joint: Controller,
}

impl CartesianController {
    /// The pair, validated as [`CartesianController::new`](crate::CartesianController::new)
    /// validates it (the joint controller with `impedance = "external"` and
    /// the same Ts), and of one number of joints.
    pub fn new(outer: CartesianImpedance, joint: Controller) -> Result<Self, Error> {
        pair!(&outer.inner, &joint.inner, o, c, N => check_joint(&**o, &c.ctrl), _ => Err(mismatch("joint controller")))?;
        Ok(Self { outer, joint })
    }

    /// The outer loop.
    pub fn outer(&self) -> &CartesianImpedance {
        &self.outer
    }

    /// The joint controller.
    pub fn joint(&self) -> &Controller {
        &self.joint
    }

    /// A state of the outer loop at `q0`, checked as the pair checks it
    /// (also within the joint controller's `q_max`).
    pub fn start(&self, q0: &[f64]) -> Result<CartesianState, Error> {
        let inner = map!(&self.outer.inner, o, N => {
            let c = self.joint.inner.get::<N>().ok_or(mismatch("joint controller"))?;
            start_pair(&**o, &c.ctrl, &vector::<N>("q0", q0)?)
        })?;
        Ok(CartesianState { inner })
    }

    /// `state` back to t = 0 at `q0` (rad, n values), checked as
    /// [`start`](Self::start) checks it, its null-space posture kept; on an
    /// error `state` is unchanged.
    pub fn restart(&self, state: &mut CartesianState, q0: &[f64]) -> Result<(), Error> {
        each!(&self.outer.inner, o, N => {
            let c = self.joint.inner.get::<N>().ok_or(mismatch("joint controller"))?;
            let s = state.inner.get_mut::<N>().ok_or(mismatch("state"))?;
            let fresh = start_pair(&**o, &c.ctrl, &vector::<N>("q0", q0)?)?;
            let posture = s.posture;
            *s = fresh;
            s.posture = posture;
            Ok(())
        })
    }

    /// The null-space posture (rad) from the next step on, checked as the
    /// pair checks it.
    pub fn set_posture(&self, state: &mut CartesianState, posture: &[f64]) -> Result<(), Error> {
        each!(&self.outer.inner, o, N => {
            let c = self.joint.inner.get::<N>().ok_or(mismatch("joint controller"))?;
            let s = state.inner.get_mut::<N>().ok_or(mismatch("state"))?;
            set_pair_posture(&**o, &c.ctrl, s, &vector::<N>("posture", posture)?)
        })
    }

    /// One step at t_k: [`CartesianController::step`](crate::CartesianController::step)
    /// bit for bit, no allocation; `outer` the outer loop's state, `joint`
    /// the joint controller's.
    pub fn step<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        outer: &mut CartesianState,
        joint: &mut State<S>,
        m: &CartesianMeasurement<'_>,
        target: Option<&PoseTarget>,
    ) -> Result<CartesianCommand, Error> {
        self.outer
            .step(outer, Joint::Adaptive(&self.joint, joint), m, target)
    }

    /// [`step`](Self::step), and the torque to apply whatever happened: the
    /// step's sat(τ), or the joint controller's fallback; `None` for states
    /// of another number of joints.
    pub fn step_or_fallback<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        outer: &mut CartesianState,
        joint: &mut State<S>,
        m: &CartesianMeasurement<'_>,
        target: Option<&PoseTarget>,
    ) -> (Option<Joints>, Result<CartesianCommand, Error>) {
        let result = self.step(outer, joint, m, target);
        let tau = match &result {
            Ok(cmd) => Some(cmd.joint.tau_sat),
            Err(_) if joint.n() == self.joint.n() => Some(joint.applied()),
            Err(_) => None,
        };
        (tau, result)
    }
}
