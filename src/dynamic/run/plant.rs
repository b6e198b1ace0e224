//! The plant of a run-time closed loop ([`Plant`], the core's rigid bodies
//! [`RigidBody`]) and what disturbs a run (SPEC §14, §17: [`Disturbances`],
//! [`Injection`]).

use super::super::controller::Scenario;
use super::super::model::JointMatrix;
use super::super::sized::{each, make, map, ByJoints, Family};
use super::super::values::{length, mismatch, too_many, vector, Joints};
use super::super::MAX_JOINTS;
use crate::error::{check, Error};
use crate::sim::disturb::{self, WithFriction};
use crate::sim::environment::{FreeSpace, Wall};
use crate::sim::inject;
use crate::sim::model::{Link, PlanarArm, TwoLinkArm};
use crate::sim::plant as core_plant;
use crate::types::Vector;
use alloc::boxed::Box;
use alloc::vec::Vec;

/// A plant of n actuated joints, n known at run time: the core's
/// [`Plant`](crate::Plant) over slices of n values. A physics engine (MuJoCo
/// through the bindings, a robot's simulator) implements it; the loop reads
/// it through the core's trait, with the same values.
pub trait Plant {
    /// The number of joints n.
    fn n(&self) -> usize;
    /// Joint position x (rad) and velocity ẋ (rad/s) now, into `x`, `dx`.
    fn state(&self, x: &mut [f64], dx: &mut [f64]);
    /// The force the robot exerts on the environment τe (N m) now, into `tau_e`.
    fn contact(&self, tau_e: &mut [f64]);
    /// Advance by `h` (s) with the applied torque `tau` (N m) held; the
    /// acceleration ẍ (rad/s²) at the start of the interval into `ddx`.
    fn advance(&mut self, tau: &[f64], h: f64, ddx: &mut [f64]) -> Result<(), Error>;
    /// The torque (N m) the actuators deliver for the command `tau`, into
    /// `out`: the plant's own limits. Default: `tau` itself.
    fn actuate(&self, tau: &[f64], out: &mut [f64]) {
        out.copy_from_slice(tau);
    }
    /// The wrench F_e = [f; m] (N, N m, world frame) the end effector exerts
    /// now. Default: zeros.
    fn wrench(&self) -> [f64; 6] {
        [0.0; 6]
    }
    /// The end-effector position (m), world frame, now. Default: zeros.
    fn end_effector(&self) -> [f64; 3] {
        [0.0; 3]
    }
}

/// A run-time plant as the core's [`Plant`](crate::Plant) of N joints.
pub(crate) struct Typed<'a, const N: usize>(pub(crate) &'a mut dyn Plant);

impl<const N: usize> core_plant::Plant<N> for Typed<'_, N> {
    fn state(&self) -> (Vector<N>, Vector<N>) {
        let (mut x, mut dx) = (Vector::<N>::zeros(), Vector::<N>::zeros());
        self.0.state(x.as_mut_slice(), dx.as_mut_slice());
        (x, dx)
    }
    fn contact(&self) -> Vector<N> {
        let mut t = Vector::<N>::zeros();
        self.0.contact(t.as_mut_slice());
        t
    }
    fn advance(&mut self, tau: &Vector<N>, h: f64) -> Result<Vector<N>, Error> {
        let mut a = Vector::<N>::zeros();
        self.0.advance(tau.as_slice(), h, a.as_mut_slice())?;
        Ok(a)
    }
    fn actuate(&self, tau: &Vector<N>) -> Vector<N> {
        let mut out = Vector::<N>::zeros();
        self.0.actuate(tau.as_slice(), out.as_mut_slice());
        out
    }
    fn wrench(&self) -> [f64; 6] {
        self.0.wrench()
    }
    fn end_effector(&self) -> [f64; 3] {
        self.0.end_effector()
    }
}

/// The arm of a [`RigidBody`]: the paper's 2-link arm (SPEC §1) or a planar
/// arm of n links.
#[derive(Clone, Debug, PartialEq)]
pub enum Arm {
    /// The paper's 2-link arm (55)–(63).
    Paper(TwoLinkArm),
    /// A planar arm of n links, joint 1 first, under gravity `g` (m/s²).
    Planar {
        /// The links.
        links: Vec<Link>,
        /// Gravity (m/s²).
        g: f64,
    },
}

/// `$body` with `$m` the typed model of `$arm` (the paper's arm, or a
/// planar arm of N links) and `$N` its joint count.
macro_rules! on_model {
    ($arm:expr, $m:ident, $N:ident => $body:expr) => {
        match $arm {
            Arm::Paper(a) => {
                const $N: usize = 2;
                let $m = a;
                $body
            }
            Arm::Planar { links, g } => crate::with_joints!(links.len(), $N => {
                let links: [Link; $N] = links.as_slice().try_into().map_err(|_| mismatch("arm"))?;
                let $m = &PlanarArm::new(links, *g)?;
                $body
            }, _ => Err(too_many(links.len()))),
        }
    };
}

impl Arm {
    /// A planar arm of `links` (1 … 7) under gravity `g` (m/s²), checked
    /// as [`PlanarArm::new`] checks it.
    pub fn planar(links: &[Link], g: f64) -> Result<Self, Error> {
        if !(1..=MAX_JOINTS).contains(&links.len()) {
            return Err(Error::Invalid {
                what: "n",
                reason: "the number of links must be between 1 and 7",
            });
        }
        let arm = Arm::Planar {
            links: links.to_vec(),
            g,
        };
        on_model!(&arm, _m, _N => Ok::<(), Error>(()))?;
        Ok(arm)
    }

    /// The number of joints n.
    pub fn n(&self) -> usize {
        match self {
            Arm::Paper(_) => 2,
            Arm::Planar { links, .. } => links.len(),
        }
    }

    /// The inertia matrix D(q) (kg m²) of (4), n × n.
    pub fn inertia(&self, q: &[f64]) -> Result<JointMatrix, Error> {
        use crate::sim::model::Manipulator;
        on_model!(self, m, N => Ok(JointMatrix::of(&m.inertia(&vector::<N>("q", q)?))))
    }

    /// The Coriolis and centripetal matrix C(q, q̇) (kg m²/s) of (4), n × n.
    pub fn coriolis(&self, q: &[f64], dq: &[f64]) -> Result<JointMatrix, Error> {
        use crate::sim::model::Manipulator;
        on_model!(self, m, N => {
            let (q, dq) = (vector::<N>("q", q)?, vector::<N>("dq", dq)?);
            Ok(JointMatrix::of(&m.coriolis(&q, &dq)))
        })
    }

    /// The gravity torque G(q) (N m) of (4).
    pub fn gravity(&self, q: &[f64]) -> Result<Joints, Error> {
        use crate::sim::model::Manipulator;
        on_model!(self, m, N => Ok(Joints::of(&m.gravity(&vector::<N>("q", q)?))))
    }

    /// q̈ (rad/s²) of (4), D(q) q̈ = τ − τe − C(q, q̇) q̇ − G(q).
    pub fn forward_dynamics(
        &self,
        q: &[f64],
        dq: &[f64],
        tau: &[f64],
        tau_e: &[f64],
    ) -> Result<Joints, Error> {
        use crate::sim::model::Manipulator;
        on_model!(self, m, N => {
            let (q, dq) = (vector::<N>("q", q)?, vector::<N>("dq", dq)?);
            let (tau, tau_e) = (vector::<N>("tau", tau)?, vector::<N>("tau_e", tau_e)?);
            Ok(Joints::of(&m.forward_dynamics(&q, &dq, &tau, &tau_e)))
        })
    }

    /// D(q), C(q, q̇), G(q) and q̈ of (4) at (q, q̇) under τ and τe (n
    /// values each; the paper's arm's (55)–(63), a planar arm's):
    /// [`Manipulator`](crate::Manipulator)'s, checked for their lengths.
    pub fn dynamics(
        &self,
        q: &[f64],
        dq: &[f64],
        tau: &[f64],
        tau_e: &[f64],
    ) -> Result<(JointMatrix, JointMatrix, Joints, Joints), Error> {
        Ok((
            self.inertia(q)?,
            self.coriolis(q, dq)?,
            self.gravity(q)?,
            self.forward_dynamics(q, dq, tau, tau_e)?,
        ))
    }

    /// The end-effector position p = fk(q) (m) and the position Jacobian
    /// ∂p/∂q (3 × n, m/rad) at q (SPEC §16).
    pub fn kinematics(&self, q: &[f64]) -> Result<(Vector<3>, Jacobian3), Error> {
        use crate::cartesian::Kinematics;
        on_model!(self, k, N => {
            let q = vector::<N>("q", q)?;
            let j = k.position_jacobian(&q);
            let mut m = nalgebra::SMatrix::<f64, 3, MAX_JOINTS>::zeros();
            m.fixed_columns_mut::<N>(0).copy_from(&j);
            Ok((k.fk(&q), Jacobian3 { n: N, m }))
        })
    }
}

/// The `3 × n` position Jacobian ∂p/∂q of an arm model's end effector (m/rad).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Jacobian3 {
    n: usize,
    m: nalgebra::SMatrix<f64, 3, MAX_JOINTS>,
}

impl Jacobian3 {
    /// The number of joints n (columns).
    pub fn n(&self) -> usize {
        self.n
    }

    /// The 3 × n matrix.
    pub fn matrix(
        &self,
    ) -> nalgebra::MatrixView<
        '_,
        f64,
        nalgebra::Const<3>,
        nalgebra::Dyn,
        nalgebra::Const<1>,
        nalgebra::Const<3>,
    > {
        self.m.columns(0, self.n)
    }
}

struct RigidF;
impl Family for RigidF {
    type Of<const N: usize> = Box<dyn core_plant::Plant<N> + Send>;
}

/// The core's rigid-body plant of SPEC §11 for n joints: an [`Arm`] with
/// the plant's disturbances (payload, friction, SPEC §17) against the
/// scenario's wall (or free space), integrated by RK4.
pub struct RigidBody {
    inner: ByJoints<RigidF>,
}

impl RigidBody {
    /// The plant of `arm` for the scenario `s`: its initial state q0, q̇0 and
    /// RK4 substeps, its wall (`wall`, `ke`, `be`; none: free space), the
    /// payload and the joint friction of `disturbances` (as
    /// [`run_disturbed`](crate::sim::simulator::run_disturbed) builds it).
    pub fn new(arm: &Arm, s: &Scenario, disturbances: &Disturbances) -> Result<Self, Error> {
        let inner = match arm {
            Arm::Paper(two) => {
                let s = s.typed().get::<2>().ok_or(Error::Invalid {
                    what: "arm",
                    reason: "TwoLinkArm has 2 joints: the scenario has another number",
                })?;
                let d = disturbances
                    .inner
                    .get::<2>()
                    .ok_or(mismatch("disturbances"))?;
                ByJoints::J2(plant::<2, _>(two, s, d)?)
            }
            Arm::Planar { links, g } => map!(s.typed(), s, N => {
                let d = disturbances.inner.get::<N>().ok_or(mismatch("disturbances"))?;
                let links: [Link; N] = links.as_slice().try_into().map_err(|_| mismatch("arm"))?;
                plant::<N, _>(&PlanarArm::new(links, *g)?, s, d)
            })?,
        };
        Ok(Self { inner })
    }
}

/// The rigid body of `arm` for the scenario `s` with the disturbances `d`.
fn plant<const N: usize, M>(
    arm: &M,
    s: &crate::schema::Scenario<N>,
    d: &disturb::Disturbances<N>,
) -> Result<Box<dyn core_plant::Plant<N> + Send>, Error>
where
    M: disturb::TipPayload<N> + Clone + Send + 'static,
{
    let arm = WithFriction::new(arm.with_payload(d.payload())?, *d.friction());
    let cfg = &s.sim;
    Ok(match s.wall {
        Some(w) => {
            let wall = Wall::<N>::new(0, w, s.ke_be[0], s.ke_be[1])?;
            Box::new(core_plant::RigidBody::new(
                arm,
                wall,
                cfg.q0,
                cfg.dq0,
                cfg.substeps,
            )?)
        }
        None => Box::new(core_plant::RigidBody::new(
            arm,
            FreeSpace,
            cfg.q0,
            cfg.dq0,
            cfg.substeps,
        )?),
    })
}

impl Plant for RigidBody {
    fn n(&self) -> usize {
        self.inner.n()
    }
    fn state(&self, x: &mut [f64], dx: &mut [f64]) {
        each!(&self.inner, p, N => {
            let (a, b) = p.state();
            x.copy_from_slice(a.as_slice());
            dx.copy_from_slice(b.as_slice());
        })
    }
    fn contact(&self, tau_e: &mut [f64]) {
        each!(&self.inner, p, N => tau_e.copy_from_slice(p.contact().as_slice()))
    }
    fn advance(&mut self, tau: &[f64], h: f64, ddx: &mut [f64]) -> Result<(), Error> {
        each!(&mut self.inner, p, N => {
            let a = p.advance(&Vector::<N>::from_column_slice(tau), h)?;
            ddx.copy_from_slice(a.as_slice());
            Ok(())
        })
    }
    fn actuate(&self, tau: &[f64], out: &mut [f64]) {
        each!(&self.inner, p, N => {
            out.copy_from_slice(p.actuate(&Vector::<N>::from_column_slice(tau)).as_slice())
        })
    }
    fn wrench(&self) -> [f64; 6] {
        each!(&self.inner, p, N => p.wrench())
    }
    fn end_effector(&self) -> [f64; 3] {
        each!(&self.inner, p, N => p.end_effector())
    }
}

// ---------------------------------------------------------------------------
// The run's settings.
// ---------------------------------------------------------------------------

pub(crate) struct DisturbF;
impl Family for DisturbF {
    type Of<const N: usize> = disturb::Disturbances<N>;
}

/// The validated disturbances of a run (SPEC §17) for n joints: the
/// run-time [`Disturbances`](crate::Disturbances).
#[derive(Clone, Debug)]
pub struct Disturbances {
    pub(crate) inner: ByJoints<DisturbF>,
}

impl Disturbances {
    /// None, for n joints: every run is the undisturbed one, bit for bit.
    pub fn none(n: usize) -> Result<Self, Error> {
        let inner =
            make!(n, N => Ok::<_, Error>(disturb::Disturbances::<N>::none()), _ => too_many(n))?;
        Ok(Self { inner })
    }

    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// Whether the plant's joints have friction (SPEC §17).
    pub fn has_friction(&self) -> bool {
        each!(&self.inner, d, N => !d.friction().is_none())
    }

    /// The payload (kg): the plant's.
    pub fn payload(&self) -> f64 {
        each!(&self.inner, d, N => d.payload())
    }

    /// The sampling-time jitter j.
    pub fn jitter(&self) -> f64 {
        each!(&self.inner, d, N => d.params().jitter)
    }

    /// Whether any sensor noise acts on τe.
    pub fn noise_on_tau_e(&self) -> bool {
        each!(&self.inner, d, N => d.params().noise_tau_e.iter().any(|v| *v != 0.0))
    }

    /// The joint friction's torque τf(q̇) (N m) at `dq` into `out`; false
    /// (and zeros) when the plant has none.
    pub fn friction_torque(&self, dq: &[f64], out: &mut [f64]) -> Result<bool, Error> {
        each!(&self.inner, d, N => {
            let f = d.friction();
            let t = f.torque(&vector::<N>("dq", dq)?);
            if out.len() != N {
                return Err(length("friction torque"));
            }
            out.copy_from_slice(t.as_slice());
            Ok(!f.is_none())
        })
    }
}

impl Scenario {
    /// The disturbances of the scenario's parameters (SPEC §17), the
    /// actuator fraction taken of the controller's `tau_max`.
    pub fn disturbances(&self) -> Result<Disturbances, Error> {
        let inner = map!(self.typed(), s, N => s.disturbances())?;
        Ok(Disturbances { inner })
    }

    /// The run's duration T (s), its metrics' `settle` (s) and the RK4
    /// substeps of the rigid-body plant.
    pub fn run_settings(&self) -> (f64, f64, usize) {
        each!(self.typed(), s, N => (s.sim.t_final, s.sim.settle, s.sim.substeps))
    }
}

/// A fault to inject into a run (SPEC §14), n values where per joint: the
/// run-time [`Injected`](crate::Injected).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Injected {
    /// The sensors repeat their last sample.
    Stale,
    /// The position sensor reads NaN.
    NanBurst,
    /// The force sensor reads τe + `bias` (N m).
    ForceBias(Joints),
    /// The actuators deliver at most `fraction` (in [0, 1]) × `tau_max` (N m).
    ActuatorDrop {
        /// The nominal limits τmax (N m).
        tau_max: Joints,
        /// The fraction delivered.
        fraction: f64,
    },
    /// No control step runs: the last applied torque is held.
    Skipped,
}

/// A fault and the window it acts in, `start ≤ t < start + duration` (s):
/// the run-time [`Injection`](crate::Injection).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Injection {
    /// The fault.
    pub fault: Injected,
    /// Start of the window (s), ≥ 0.
    pub start: f64,
    /// Length of the window (s), > 0.
    pub duration: f64,
}

impl Injection {
    /// The core's injection of N joints, checked: the window, the bias
    /// finite with one value per joint, 0 ≤ fraction ≤ 1, τmax of N values
    /// (for a caller generic over N, a typed loop).
    pub fn typed<const N: usize>(&self) -> Result<inject::Injection<N>, Error> {
        check::nonnegative("fault start ≥ 0", "start", self.start)?;
        check::positive("fault duration > 0", "duration", self.duration)?;
        let fault = match &self.fault {
            Injected::Stale => inject::Injected::Stale,
            Injected::NanBurst => inject::Injected::NanBurst,
            Injected::Skipped => inject::Injected::Skipped,
            Injected::ForceBias(b) => {
                if b.len() != N {
                    return Err(Error::Invalid {
                        what: "bias",
                        reason: "needs one value per joint (N m)",
                    });
                }
                check::finite_slice("bias", b)?;
                inject::Injected::ForceBias { bias: b.vector() }
            }
            Injected::ActuatorDrop { tau_max, fraction } => {
                if !(0.0..=1.0).contains(fraction) {
                    return Err(Error::Condition {
                        condition: "0 ≤ fraction ≤ 1",
                        lhs: "fraction",
                        index: None,
                        value: *fraction,
                    });
                }
                if tau_max.len() != N {
                    return Err(length("tau_max"));
                }
                inject::Injected::ActuatorDrop {
                    tau_max: tau_max.vector(),
                    fraction: *fraction,
                }
            }
        };
        Ok(inject::Injection {
            fault,
            start: self.start,
            duration: self.duration,
        })
    }
}
