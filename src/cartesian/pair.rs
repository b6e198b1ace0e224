//! The Cartesian controller: the 6-D outer loop of SPEC §16 and the joint
//! controller it drives (C5), one step over plain data (q, q̇, the measured
//! wrench, an optional pose target), transactional, allocation-free.

use crate::cartesian::computed::{ComputedState, ComputedTorque};
use crate::cartesian::kinematics::{Jacobian6, Kinematics};
use crate::cartesian::outer::Formulation;
use crate::cartesian::outer::{CartesianImpedance, CartesianState, CompliantPose, PoseTarget};
use crate::control::controller::Controller;
use crate::control::impedance::ImpedanceMode;
use crate::control::io::{Command, Measurement, TaskTorque};
use crate::control::state::State;
use crate::error::{check, Error, BOUND};
use crate::networks::rbf::Basis;
use crate::trajectory::Setpoint;
use crate::types::Vector;
use nalgebra::{Rotation3, UnitQuaternion};

/// One sample from the sensors at t_k.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianMeasurement<const N: usize> {
    /// Joint position q (rad).
    pub q: Vector<N>,
    /// Joint velocity q̇ (rad/s), as [`Measurement::dx`].
    pub dq: Option<Vector<N>>,
    /// The wrench the tip exerts on the environment, F_e = [f (N); m (N m)],
    /// world frame, the moment about the tip (the environment pushes back
    /// with −F_e); from a force/torque sensor.
    pub wrench: Vector<6>,
}

/// What a Cartesian step computed; `joint.tau_sat` goes to the actuators.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianCommand<const N: usize> {
    /// The joint controller's command (τ, sat(τ), z1 = q_d − q, …).
    pub joint: Command<N>,
    /// The joint reference q_d, q̇_d, q̈_d (rad, rad/s, rad/s²) at t_k.
    pub reference: Setpoint<N>,
    /// The commanded joint reference q_c, q̇_c, q̈_c at t_k (SPEC §19; the
    /// reference itself for the admittance formulation).
    pub commanded: Setpoint<N>,
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
    /// τe = Jᵀ(q) F_e (N m), or zero without `force_feedforward`: what the
    /// joint controller got.
    pub tau_e: Vector<N>,
}

/// The outer Cartesian impedance and the joint controller it drives.
#[derive(Clone, Debug)]
pub struct CartesianController<const N: usize, K, B> {
    outer: CartesianImpedance<N, K>,
    inner: Controller<N, B>,
}

impl<const N: usize, K: Kinematics<N>, B: Basis<N>> CartesianController<N, K, B> {
    /// The pair, validated: the joint controller must have
    /// `impedance = "external"` (the Cartesian impedance is the only one:
    /// a joint impedance would answer τe a second time) and the same Ts.
    pub fn new(outer: CartesianImpedance<N, K>, inner: Controller<N, B>) -> Result<Self, Error> {
        check_joint(&outer, &inner)?;
        Ok(Self { outer, inner })
    }

    /// The outer loop.
    pub fn outer(&self) -> &CartesianImpedance<N, K> {
        &self.outer
    }
    /// The joint controller.
    pub fn inner(&self) -> &Controller<N, B> {
        &self.inner
    }

    /// A state of the outer loop at `q0`, checked as a joint position the
    /// joint controller's step would accept as its reference: finite and
    /// within `q_max` (at most 1e6 rad). Errors name `q0` and the joint.
    pub fn start(&self, q0: &Vector<N>) -> Result<CartesianState<N>, Error> {
        start(&self.outer, &self.inner, q0)
    }

    /// Set the null-space posture (rad) from the next step on, checked as
    /// [`CartesianImpedance::check_posture`] checks it and within the joint
    /// controller's `q_max`; on an error nothing changes.
    pub fn set_posture(
        &self,
        outer: &mut CartesianState<N>,
        posture: &Vector<N>,
    ) -> Result<(), Error> {
        set_posture(&self.outer, &self.inner, outer, posture)
    }

    /// One step at t_k: the measurement `m` and the commanded pose `target`
    /// (`None`: hold the last one) in, the command out; no allocation. The
    /// outer loop is staged, the joint step runs with the joint reference and
    /// τe = Jᵀ(q) F_e (or zero without `force_feedforward`), and only if it
    /// succeeds is the outer state committed. On an error both states are as
    /// before but for the refusal, recorded in the joint state as a refused
    /// joint step records it (the fault semantics of `docs/reliability.md`),
    /// whether the joint step refused or the outer loop did before it (a
    /// target that is not a rotation, a wrench not finite, a result beyond
    /// the bound).
    pub fn step<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        outer: &mut CartesianState<N>,
        inner: &mut State<N, S>,
        m: &CartesianMeasurement<N>,
        target: Option<&PoseTarget>,
    ) -> Result<CartesianCommand<N>, Error> {
        // `step_joint` with this pair's joint controller, written out: the
        // pair's step compiles as it did before `step_joint` (the same
        // instructions, `benches/cartesian_cost.rs`); tests/dynamic.rs checks
        // the two give the same bits.
        let mut reached = false;
        let result = self.outer.step_with(outer, m, target, |meas, r, task| {
            reached = true;
            match task {
                Some(t) => self.inner.step_task(inner, meas, r, t),
                None => self.inner.step(inner, meas, r),
            }
        });
        if let (Err(e), false) = (&result, reached) {
            let meas = Measurement {
                x: m.q,
                dx: m.dq,
                tau_e: Vector::zeros(),
            };
            self.inner.refuse_measured(inner, &meas, *e);
        }
        result
    }

    /// [`step`](Self::step), and the torque to apply whatever happened: the
    /// step's `joint.tau_sat`, or on an error the joint controller's
    /// configured fallback (then the applied torque the next step's rate
    /// limit starts from), as [`Controller::step_or_fallback`].
    pub fn step_or_fallback<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        outer: &mut CartesianState<N>,
        inner: &mut State<N, S>,
        m: &CartesianMeasurement<N>,
        target: Option<&PoseTarget>,
    ) -> (Vector<N>, Result<CartesianCommand<N>, Error>) {
        match self.step(outer, inner, m, target) {
            Ok(cmd) => (cmd.joint.tau_sat, Ok(cmd)),
            Err(e) => (*inner.applied(), Err(e)),
        }
    }
}

/// The pair's checks: the joint controller `inner` of the outer loop
/// `outer` has `impedance = "external"` and the same Ts.
pub(crate) fn check_joint<const N: usize, K, B: Basis<N>>(
    outer: &CartesianImpedance<N, K>,
    inner: &Controller<N, B>,
) -> Result<(), Error>
where
    K: Kinematics<N>,
{
    if inner.config().impedance != ImpedanceMode::External {
        return Err(Error::Invalid {
            what: "joint controller of a Cartesian impedance",
            reason: "needs impedance = \"external\" (ImpedanceMode::External): the joint impedance would act on τe a second time",
        });
    }
    if inner.period() != outer.period() {
        return Err(Error::Invalid {
            what: "joint controller of a Cartesian impedance",
            reason: "needs the same Ts as the Cartesian impedance",
        });
    }
    Ok(())
}

/// [`CartesianController::start`] of the pair `outer`, `inner`.
pub(crate) fn start<const N: usize, K: Kinematics<N>, B: Basis<N>>(
    outer: &CartesianImpedance<N, K>,
    inner: &Controller<N, B>,
    q0: &Vector<N>,
) -> Result<CartesianState<N>, Error> {
    let st = outer.start_checked(q0)?;
    check::within_each(
        "q0",
        q0.as_slice(),
        inner.config().limits.position().as_slice(),
    )?;
    Ok(st)
}

/// [`CartesianController::set_posture`] of the pair `outer`, `inner`.
pub(crate) fn set_posture<const N: usize, K: Kinematics<N>, B: Basis<N>>(
    outer: &CartesianImpedance<N, K>,
    inner: &Controller<N, B>,
    st: &mut CartesianState<N>,
    posture: &Vector<N>,
) -> Result<(), Error> {
    outer.check_posture(&st.qd, posture)?;
    check::within_each(
        "posture",
        posture.as_slice(),
        inner.config().limits.position().as_slice(),
    )?;
    st.posture = *posture;
    Ok(())
}

/// A joint controller a Cartesian impedance drives (C5), with its state:
/// what [`CartesianImpedance::step_joint`] steps. The paper's laws
/// (`(&Controller, &mut State)`) and computed torque (`(&ComputedTorque,
/// &mut ComputedState)`, SPEC §20) are two.
pub trait JointLaw<const N: usize> {
    /// One step on the compliant joint reference `r` (q_d, q̇_d, q̈_d).
    fn step(&mut self, m: &Measurement<N>, r: &Setpoint<N>) -> Result<Command<N>, Error>;
    /// One step of the torque-level formulations (SPEC §19).
    fn step_task(
        &mut self,
        m: &Measurement<N>,
        r: &Setpoint<N>,
        task: &TaskTorque<N>,
    ) -> Result<Command<N>, Error>;
    /// A step the outer loop refused before the joint step ran (a target
    /// that is not a rotation, a wrench not finite, a result beyond the
    /// bound), recorded as a refused joint step with its measurement `m`.
    fn refuse(&mut self, m: &Measurement<N>, error: Error);
}

impl<const N: usize, B: Basis<N>, S: AsRef<[f64]> + AsMut<[f64]>> JointLaw<N>
    for (&Controller<N, B>, &mut State<N, S>)
{
    fn step(&mut self, m: &Measurement<N>, r: &Setpoint<N>) -> Result<Command<N>, Error> {
        self.0.step(self.1, m, r)
    }
    fn step_task(
        &mut self,
        m: &Measurement<N>,
        r: &Setpoint<N>,
        task: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        self.0.step_task(self.1, m, r, task)
    }
    fn refuse(&mut self, m: &Measurement<N>, error: Error) {
        self.0.refuse_measured(self.1, m, error);
    }
}

impl<const N: usize> JointLaw<N> for (&ComputedTorque<N>, &mut ComputedState<N>) {
    fn step(&mut self, m: &Measurement<N>, r: &Setpoint<N>) -> Result<Command<N>, Error> {
        self.0.step(self.1, m, r)
    }
    fn step_task(
        &mut self,
        m: &Measurement<N>,
        r: &Setpoint<N>,
        task: &TaskTorque<N>,
    ) -> Result<Command<N>, Error> {
        self.0.step_task(self.1, m, r, task)
    }
    fn refuse(&mut self, _m: &Measurement<N>, error: Error) {
        self.0.refuse(self.1, error);
    }
}

impl<const N: usize, K: Kinematics<N>> CartesianImpedance<N, K> {
    /// The Cartesian step with the joint controller `joint` (C5): stage the
    /// outer loop, step `joint` on the joint reference (the torque-level
    /// formulations' part too, SPEC §19), and commit the outer state only
    /// if it succeeds. A refusal of the outer loop before the joint step
    /// ran is recorded in `joint` ([`JointLaw::refuse`]), so every refusal
    /// has its fault and fallback. [`CartesianController::step`] is this
    /// with the pair's joint controller.
    pub fn step_joint<J: JointLaw<N> + ?Sized>(
        &self,
        outer: &mut CartesianState<N>,
        joint: &mut J,
        m: &CartesianMeasurement<N>,
        target: Option<&PoseTarget>,
    ) -> Result<CartesianCommand<N>, Error> {
        let mut reached = false;
        let result = self.step_with(outer, m, target, |meas, r, task| {
            reached = true;
            match task {
                Some(t) => joint.step_task(meas, r, t),
                None => joint.step(meas, r),
            }
        });
        if let (Err(e), false) = (&result, reached) {
            let meas = Measurement {
                x: m.q,
                dx: m.dq,
                tau_e: Vector::zeros(),
            };
            joint.refuse(&meas, *e);
        }
        result
    }
}

impl<const N: usize, K: Kinematics<N>> CartesianImpedance<N, K> {
    /// The outer loop alone, one committed step (F_e = `wrench`): the joint
    /// reference of t_k for a joint controller stepped elsewhere, in a
    /// command whose joint part and τe are zero and whose measured tip is
    /// fk(q_d). Errors as [`stage`](Self::stage), changing nothing.
    pub fn reference(
        &self,
        outer: &mut CartesianState<N>,
        target: Option<&PoseTarget>,
        wrench: &Vector<6>,
    ) -> Result<CartesianCommand<N>, Error> {
        let staged = self.stage(outer, target, wrench)?;
        let tip = self.kinematics().tip(&staged.reference.x, &Vector::zeros());
        *outer = staged.next;
        Ok(CartesianCommand {
            joint: Command::zeros(),
            reference: staged.reference,
            commanded: staged.commanded,
            compliant: staged.compliant,
            target: staged.target,
            error: staged.error,
            p: tip.position,
            r: tip.rotation,
            tau_e: Vector::zeros(),
        })
    }
}

impl<const N: usize, K: Kinematics<N>> CartesianImpedance<N, K> {
    /// [`step_with`](Self::step_with) for a joint law that gives only its
    /// torque (a controller written in another language): `joint` gets the
    /// measurement (τe = Jᵀ(q) F_e, zero without `force_feedforward`), the
    /// joint reference to track (the compliant q_d, q̇_d, q̈_d; for the
    /// torque-level formulations, SPEC §19, the commanded q_c, q̇_c, q̈_c)
    /// and, for those, the task torque Jᵀ(K̃e + B(ṗ_c − J q̇)) (N m) at the
    /// measured q̇ with the task Jacobian J (6 × n), and returns the torque
    /// to apply (N m). The command's joint part is that torque (τ = sat(τ))
    /// with z1 = q_d − q and xc = xd = q_d.
    pub fn step_with_torque<F>(
        &self,
        outer: &mut CartesianState<N>,
        m: &CartesianMeasurement<N>,
        target: Option<&PoseTarget>,
        joint: F,
    ) -> Result<CartesianCommand<N>, Error>
    where
        F: FnOnce(
            &Measurement<N>,
            &Setpoint<N>,
            Option<(&Vector<N>, &Jacobian6<N>)>,
        ) -> Result<Vector<N>, Error>,
    {
        self.step_with(outer, m, target, |jm, r, task| {
            let (reference, torque) = match task {
                // The torque-level formulations (SPEC §19): the commanded
                // reference and the task torque at the measured q̇.
                Some(t) if t.share < 1.0 => {
                    let dq = jm.dx.ok_or(Error::MissingVelocity)?;
                    let torque = t.jacobian.transpose() * t.force(&dq);
                    (t.commanded, Some((torque, &t.jacobian)))
                }
                _ => (*r, None),
            };
            let t = joint(jm, &reference, torque.as_ref().map(|(tau, j)| (tau, *j)))?;
            Ok(Command {
                tau_sat: t,
                tau: t,
                z1: r.x - jm.x,
                xc: r.x,
                xd: r.x,
                ..Command::zeros()
            })
        })
    }
}

impl<const N: usize, K: Kinematics<N>> CartesianImpedance<N, K> {
    /// The Cartesian step with any joint controller `joint` (C5): stage the
    /// outer loop, call `joint(measurement, reference, task)` with the joint
    /// reference (q_d, q̇_d, q̈_d), τe = Jᵀ(q) F_e (zero without
    /// `force_feedforward`) and, for the formulations other than admittance,
    /// the torque-level part (SPEC §19, [`TaskTorque`]), and commit the
    /// outer state only if it succeeds. [`CartesianController::step`] is
    /// this with the core's joint controller; a binding passes its own.
    pub fn step_with<F>(
        &self,
        outer: &mut CartesianState<N>,
        m: &CartesianMeasurement<N>,
        target: Option<&PoseTarget>,
        joint: F,
    ) -> Result<CartesianCommand<N>, Error>
    where
        F: FnOnce(
            &Measurement<N>,
            &Setpoint<N>,
            Option<&TaskTorque<N>>,
        ) -> Result<Command<N>, Error>,
    {
        check::finite_slice("q", m.q.as_slice())?;
        check::within("q", m.q.as_slice(), BOUND)?;
        let staged = self.stage(outer, target, &m.wrench)?;
        let cfg = self.config();
        let torque_level = cfg.formulation != Formulation::Admittance;
        // The Jacobian at the measured q only when the force feed-forward or
        // a torque-level formulation needs it; the pose alone otherwise (the
        // same values).
        let mut tau_e = Vector::zeros();
        let mut task = None;
        let (position, rotation) = if cfg.force_feedforward || torque_level {
            let tip = self.kinematics().tip(&m.q, &Vector::zeros());
            if cfg.force_feedforward {
                tau_e = tip.jacobian.transpose() * m.wrench;
            }
            if torque_level {
                task = Some(self.task_torque(&staged, &tip));
            }
            (tip.position, tip.rotation)
        } else {
            self.kinematics().pose(&m.q)
        };
        let meas = Measurement {
            x: m.q,
            dx: m.dq,
            tau_e,
        };
        let joint = joint(&meas, &staged.reference, task.as_ref())?;
        *outer = staged.next;
        Ok(CartesianCommand {
            joint,
            reference: staged.reference,
            commanded: staged.commanded,
            compliant: staged.compliant,
            target: staged.target,
            error: staged.error,
            p: position,
            r: rotation,
            tau_e,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cartesian::outer::CartesianConfig;
    use crate::control::config::{Config, Law};
    use crate::networks::rbf::Grid;
    use crate::sim::model::TwoLinkArm;

    #[test]
    fn a_refusal_of_the_outer_loop_is_recorded_as_a_refused_joint_step() {
        let outer =
            CartesianImpedance::new(CartesianConfig::default(), TwoLinkArm::paper(), 1e-3).unwrap();
        let mut cfg = Config::paper(Law::Pd);
        cfg.ts = 1e-3;
        cfg.impedance = ImpedanceMode::External;
        cfg.fallback = crate::control::safety::Fallback::Zero;
        let pair =
            CartesianController::new(outer, Controller::new(cfg, Grid::paper()).unwrap()).unwrap();
        let q = Vector::<2>::new(0.5, 1.0);
        let (mut ost, mut ist) = (pair.outer().start(q), pair.inner().new_state());
        let m = CartesianMeasurement {
            q: q + Vector::<2>::new(0.01, 0.0),
            dq: Some(Vector::zeros()),
            wrench: Vector::zeros(),
        };
        let (tau, r) = pair.step_or_fallback(&mut ost, &mut ist, &m, None);
        assert_eq!(tau, r.unwrap().joint.tau_sat);
        assert!(tau.norm() > 0.0);
        let before = ost;
        let p = pair.outer().kinematics().fk(&q);
        let mirror = PoseTarget::at(
            p,
            nalgebra::Matrix3::from_diagonal(&Vector::<3>::new(1.0, 1.0, -1.0)),
        );
        let (tau, r) = pair.step_or_fallback(&mut ost, &mut ist, &m, Some(&mirror));
        let e = r.unwrap_err();
        assert!(e.to_string().contains("det R = +1"), "{e}");
        assert_eq!(ost, before);
        assert_eq!(ist.fault().map(|f| f.error), Some(e));
        assert_eq!(tau, Vector::<2>::zeros());
        assert_eq!(*ist.applied(), Vector::<2>::zeros());
        assert_eq!(ist.steps(), 1);
    }

    #[test]
    fn the_outer_loop_alone_commits_its_staged_step_with_the_tip_at_q_d() {
        let outer =
            CartesianImpedance::new(CartesianConfig::default(), TwoLinkArm::paper(), 1e-3).unwrap();
        let q = Vector::<2>::new(0.5, 1.0);
        let mut st = outer.start(q);
        let p = outer.kinematics().fk(&q) + Vector::<3>::new(0.01, 0.0, 0.0);
        let target = PoseTarget::at(p, nalgebra::Matrix3::identity());
        let wrench = Vector::<6>::new(1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let staged = outer.stage(&st, Some(&target), &wrench).unwrap();
        let cmd = outer.reference(&mut st, Some(&target), &wrench).unwrap();
        assert_eq!(st, staged.next);
        assert_eq!(
            (cmd.reference, cmd.commanded),
            (staged.reference, staged.commanded)
        );
        let tip = outer
            .kinematics()
            .tip(&staged.reference.x, &Vector::zeros());
        assert_eq!((cmd.p, cmd.r), (tip.position, tip.rotation));
        assert_eq!(cmd.joint, Command::zeros());
        assert_eq!(cmd.tau_e, Vector::<2>::zeros());
        let before = st;
        let nan = Vector::<6>::from_element(f64::NAN);
        let e = outer.reference(&mut st, None, &nan).unwrap_err();
        assert!(e.to_string().contains("wrench"), "{e}");
        assert_eq!(st, before);
    }

    #[test]
    fn the_joint_controller_must_leave_the_impedance_to_the_outer_loop() {
        let outer = || {
            CartesianImpedance::new(CartesianConfig::default(), TwoLinkArm::paper(), 1e-3).unwrap()
        };
        let mut cfg = Config::paper(Law::StateFeedback);
        cfg.ts = 1e-3;
        let joint = Controller::new(cfg, Grid::paper()).unwrap();
        let e = CartesianController::new(outer(), joint).unwrap_err();
        assert!(e.to_string().contains("external"), "{e}");
        cfg.impedance = ImpedanceMode::External;
        let joint = Controller::new(cfg, Grid::paper()).unwrap();
        assert!(CartesianController::new(outer(), joint).is_ok());
        cfg.ts = 2e-3;
        let joint = Controller::new(cfg, Grid::paper()).unwrap();
        let e = CartesianController::new(outer(), joint).unwrap_err();
        assert!(e.to_string().contains("same Ts"), "{e}");
    }
}
