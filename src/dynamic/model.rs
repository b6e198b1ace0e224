//! The arm's model for n joints known at run time: [`Chain`] (kinematics),
//! [`Dynamics`] (rigid-body dynamics with the drive), both from joint data
//! or from an [`Arm`] read from a URDF or an MJCF (SPEC §21), and
//! [`ComputedTorque`] with its [`ComputedState`] (SPEC §20).

use super::sized::{each, make, map, pair, ByJoints, Family};
use super::values::{length, mismatch, vector, Command, Joints, Measurement, Setpoint};
use super::MAX_JOINTS;
use crate::cartesian::{
    self, Assessment, Inertial, Joint, JointKind, Kinematics, PostureRule, TaskRows, Transform,
};
use crate::control::impedance::{ImpedanceMode, TargetImpedance};
use crate::control::safety::{Fault, CEILING_POSITION};
use crate::description::{Arm, DescriptionError, ErrorKind};
use crate::error::{check, Error};
use crate::types::{Matrix, Vector};
use alloc::boxed::Box;
use alloc::format;
use alloc::vec::Vec;
use core::convert::Infallible;
use nalgebra::{Const, Dyn, MatrixView, Rotation3, SMatrix};

/// The error of a chain whose number of movable joints is not 1 … 7.
fn movable(n: usize) -> Error {
    Error::Condition {
        condition: "1 ≤ n ≤ 7 movable joints",
        lhs: "movable joints",
        index: None,
        value: n as f64,
    }
}

/// The movable joints of a chain description.
fn movable_joints(joints: &[Joint]) -> usize {
    joints.iter().filter(|j| j.kind != JointKind::Fixed).count()
}

/// The error of a result that is not finite from checked inputs.
const TIP_DIVERGED: Error = Error::Diverged {
    what: "the chain's tip (pose, Jacobian or J̇ q̇)",
};

pub(crate) struct ChainF;
impl Family for ChainF {
    type Of<const N: usize> = Box<cartesian::Chain<N>>;
}

/// A serial chain of n movable joints (SPEC §16): the run-time
/// [`Chain`](crate::Chain). Its queries take q (rad, or m for a prismatic
/// joint) and q̇ of n values each, finite and within their ceilings (1e6),
/// as a step's measurement; every result is checked finite.
#[derive(Clone, Debug)]
pub struct Chain {
    pub(crate) inner: ByJoints<ChainF>,
}

/// The `6 × n` geometric Jacobian `[J_v; J_ω]` of a tip, world-aligned, at
/// the tip origin: row i the task direction (x, y, z, then the rotation
/// about x, y, z), column j the joint.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Jacobian {
    n: usize,
    m: SMatrix<f64, 6, MAX_JOINTS>,
}

impl Jacobian {
    pub(crate) fn of<const N: usize>(j: &cartesian::Jacobian6<N>) -> Self {
        let mut m = SMatrix::<f64, 6, MAX_JOINTS>::zeros();
        m.fixed_columns_mut::<N>(0).copy_from(j);
        Self { n: N, m }
    }

    /// The number of joints n (columns).
    pub fn n(&self) -> usize {
        self.n
    }

    /// The 6 × n matrix.
    pub fn matrix(&self) -> MatrixView<'_, f64, Const<6>, Dyn, Const<1>, Const<6>> {
        self.m.columns(0, self.n)
    }
}

impl core::ops::Index<(usize, usize)> for Jacobian {
    type Output = f64;
    fn index(&self, (row, col): (usize, usize)) -> &f64 {
        assert!(col < self.n, "column {col} of a 6 × {} Jacobian", self.n);
        &self.m[(row, col)]
    }
}

/// An `n × n` joint-space matrix (the mass matrix M(q), kg m²).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct JointMatrix {
    n: usize,
    m: SMatrix<f64, MAX_JOINTS, MAX_JOINTS>,
}

impl JointMatrix {
    pub(crate) fn of<const N: usize>(v: &crate::types::Matrix<N>) -> Self {
        let mut m = SMatrix::<f64, MAX_JOINTS, MAX_JOINTS>::zeros();
        m.fixed_view_mut::<N, N>(0, 0).copy_from(v);
        Self { n: N, m }
    }

    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The n × n matrix.
    pub fn matrix(&self) -> MatrixView<'_, f64, Dyn, Dyn, Const<1>, Const<MAX_JOINTS>> {
        self.m.view((0, 0), (self.n, self.n))
    }
}

impl core::ops::Index<(usize, usize)> for JointMatrix {
    type Output = f64;
    fn index(&self, (row, col): (usize, usize)) -> &f64 {
        assert!(
            row < self.n && col < self.n,
            "({row}, {col}) of an n = {} matrix",
            self.n
        );
        &self.m[(row, col)]
    }
}

/// The tip's pose, Jacobian and velocity product at one (q, q̇), world
/// frame: the run-time [`Tip`](crate::Tip).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Tip {
    /// Position p (m).
    pub position: Vector<3>,
    /// Rotation R (world ← tip).
    pub rotation: Rotation3<f64>,
    /// `[J_v; J_ω]` (6 × n).
    pub jacobian: Jacobian,
    /// `J̇ q̇` = [(m/s²); (rad/s²)]: the tip's classical acceleration at q̈ = 0.
    pub bias: Vector<6>,
}

impl Tip {
    fn of<const N: usize>(t: &cartesian::Tip<N>) -> Self {
        Self {
            position: t.position,
            rotation: t.rotation,
            jacobian: Jacobian::of(&t.jacobian),
            bias: t.bias,
        }
    }
}

impl Chain {
    /// The chain of `joints` (base to tip, fixed ones included) and the
    /// `tip` transform, with as many joints n as it has movable ones
    /// (1 … 7): [`Chain::new`](crate::Chain::new)'s checks.
    pub fn new(joints: &[Joint], tip: &Transform) -> Result<Self, Error> {
        let n = movable_joints(joints);
        let inner =
            make!(n, N => cartesian::Chain::<N>::new(joints, tip).map(Box::new), _ => movable(n))?;
        Ok(Self { inner })
    }

    /// The kinematics of `arm` (a URDF's or an MJCF's, reduced by the one
    /// rule of SPEC §21) to its tip.
    pub fn from_arm(arm: &Arm) -> Result<Self, Error> {
        Self::new(&arm.chain, &arm.tip_origin)
    }

    /// The number of movable joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// Whether joint `i` is prismatic (else revolute).
    pub fn is_prismatic(&self, i: usize) -> bool {
        each!(&self.inner, c, N => c.is_prismatic(i))
    }

    /// The tip at (q, q̇): [`Chain::tip_checked`](crate::Chain::tip_checked).
    pub fn tip(&self, q: &[f64], dq: &[f64]) -> Result<Tip, Error> {
        each!(&self.inner, c, N => c.tip_checked(&vector("q", q)?, &vector("dq", dq)?).map(|t| Tip::of(&t)))
    }

    /// The tip at (q, q̇), unchecked: for rules that hand in postures of
    /// their own (errors only for a length other than n).
    pub fn tip_unchecked(&self, q: &[f64], dq: &[f64]) -> Result<Tip, Error> {
        each!(&self.inner, c, N => Ok(Tip::of(&Kinematics::tip(&**c, &vector("q", q)?, &vector("dq", dq)?))))
    }

    /// The tip's pose at q: position p (m) and rotation R (world ← tip).
    pub fn pose(&self, q: &[f64]) -> Result<(Vector<3>, Rotation3<f64>), Error> {
        each!(&self.inner, c, N => {
            let q = vector::<N>("q", q)?;
            c.check_motion(&q, None)?;
            let (p, r) = c.pose(&q);
            if p.iter().chain(r.matrix().iter()).all(|x| x.is_finite()) {
                Ok((p, r))
            } else {
                Err(TIP_DIVERGED)
            }
        })
    }

    /// The Jacobian at q (6 × n).
    pub fn jacobian(&self, q: &[f64]) -> Result<Jacobian, Error> {
        each!(&self.inner, c, N => {
            let q = vector::<N>("q", q)?;
            c.check_motion(&q, None)?;
            let j = c.pose_jacobian(&q).jacobian;
            if j.iter().all(|x| x.is_finite()) {
                Ok(Jacobian::of(&j))
            } else {
                Err(TIP_DIVERGED)
            }
        })
    }

    /// The Jacobian at q written row-major into `out` (6 × n values, as
    /// a front's array holds it), checked as [`jacobian`](Self::jacobian).
    pub fn jacobian_rows(&self, q: &[f64], out: &mut [f64]) -> Result<(), Error> {
        each!(&self.inner, c, N => {
            let q = vector::<N>("q", q)?;
            if out.len() != 6 * N {
                return Err(length("out"));
            }
            c.check_motion(&q, None)?;
            // Jᵀ's column-major storage is J row-major.
            let jt = c.pose_jacobian(&q).jacobian.transpose();
            if !jt.iter().all(|x| x.is_finite()) {
                return Err(TIP_DIVERGED);
            }
            out.copy_from_slice(jt.as_slice());
            Ok(())
        })
    }

    /// J̇ q̇ at (q, q̇): [(m/s²); (rad/s²)].
    pub fn bias(&self, q: &[f64], dq: &[f64]) -> Result<Vector<6>, Error> {
        each!(&self.inner, c, N => {
            let (q, dq) = (vector::<N>("q", q)?, vector::<N>("dq", dq)?);
            c.check_motion(&q, Some(&dq))?;
            let b = c.bias(&q, &dq);
            if b.iter().all(|x| x.is_finite()) {
                Ok(b)
            } else {
                Err(TIP_DIVERGED)
            }
        })
    }
}

impl Chain {
    /// The tip's pose at q unchecked (errors only for a length other than
    /// n): for postures a run recorded, whatever they are.
    pub fn pose_unchecked(&self, q: &[f64]) -> Result<(Vector<3>, Rotation3<f64>), Error> {
        each!(&self.inner, c, N => Ok(c.pose(&vector::<N>("q", q)?)))
    }

    /// The tip's twist V = J(q) q̇ = [ṗ; ω] (m/s, rad/s) and acceleration
    /// A = J(q) q̈ + J̇ q̇ = [p̈; ω̇] (m/s², rad/s²) at one row (q, q̇, q̈),
    /// (q, q̇) checked as [`tip`](Self::tip) checks them.
    pub fn motion(
        &self,
        q: &[f64],
        dq: &[f64],
        ddq: &[f64],
    ) -> Result<(Vector<6>, Vector<6>), Error> {
        each!(&self.inner, c, N => {
            let (dq, ddq) = (vector::<N>("dq", dq)?, vector::<N>("ddq", ddq)?);
            let t = c.tip_checked(&vector::<N>("q", q)?, &dq)?;
            let dot = |i: usize, x: &Vector<N>| (0..N).map(|j| t.jacobian[(i, j)] * x[j]).sum::<f64>();
            Ok((
                Vector::<6>::from_fn(|i, _| dot(i, &dq)),
                Vector::<6>::from_fn(|i, _| dot(i, &ddq) + t.bias[i]),
            ))
        })
    }

    /// The posture rule's assessment of SPEC (16.9) on this chain
    /// ([`PostureRule::assess`](crate::cartesian::PostureRule::assess)):
    /// the orbit's postures q (K × n, rad), the tip's targets p (K × 3, m),
    /// the gravity torque along it (K × n, N m), the inertia matrix at its
    /// start `d0` (n × n, kg m²), the limits (n each, rad) and τmax (n, N m),
    /// all row-major. Errors name a table of another width.
    #[allow(clippy::too_many_arguments)]
    pub fn assess_posture(
        &self,
        rule: &PostureRule,
        task: TaskRows,
        (orbit, targets, gravity): (&[f64], &[f64], &[f64]),
        d0: &[f64],
        (lo, hi): (&[f64], &[f64]),
        tau_max: &[f64],
    ) -> Result<Assessment, Error> {
        each!(&self.inner, c, N => {
            let rows = |what: &'static str, v: &[f64]| -> Result<Vec<Vector<N>>, Error> {
                if !v.len().is_multiple_of(N) {
                    return Err(length(what));
                }
                Ok(v.chunks_exact(N).map(Vector::<N>::from_column_slice).collect())
            };
            if !targets.len().is_multiple_of(3) {
                return Err(Error::Invalid {
                    what: "targets",
                    reason: "needs 3 values (a position) per row",
                });
            }
            if d0.len() != N * N {
                return Err(length("d0"));
            }
            let targets: Vec<Vector<3>> = targets
                .chunks_exact(3)
                .map(Vector::<3>::from_column_slice)
                .collect();
            rule.assess(
                &**c,
                task,
                &rows("orbit", orbit)?,
                &targets,
                &rows("gravity", gravity)?,
                &Matrix::<N>::from_row_slice(d0),
                (&vector::<N>("lo", lo)?, &vector::<N>("hi", hi)?),
                &vector::<N>("tau_max", tau_max)?,
            )
        })
    }
}

impl Jacobian {
    /// A 6 × n Jacobian from its rows (6 × n values, row-major,
    /// 1 ≤ n ≤ [`MAX_JOINTS`]).
    pub fn from_rows(rows: &[f64]) -> Result<Self, Error> {
        let n = rows.len() / 6;
        if rows.len() != 6 * n || !(1..=MAX_JOINTS).contains(&n) {
            return Err(Error::Invalid {
                what: "jacobian",
                reason: "needs 6 rows of n values, 1 ≤ n ≤ 7",
            });
        }
        let mut m = SMatrix::<f64, 6, MAX_JOINTS>::zeros();
        for (k, v) in rows.iter().enumerate() {
            m[(k / n, k % n)] = *v;
        }
        Ok(Self { n, m })
    }

    /// The normal of a planar arm's plane, SPEC (16.8)
    /// ([`plane_normal`](crate::cartesian::rule::plane_normal)), or `None`
    /// for an arm that is not planar.
    pub fn plane_normal(&self) -> Option<Vector<3>> {
        crate::with_joints!(self.n, N => {
            crate::cartesian::rule::plane_normal(&self.m.fixed_columns::<N>(0).into_owned())
        }, _ => None)
    }
}

pub(crate) struct DynamicsF;
impl Family for DynamicsF {
    type Of<const N: usize> = Box<cartesian::Dynamics<N>>;
}

/// The rigid-body dynamics of a chain of n joints with its drive (SPEC
/// §20): the run-time [`Dynamics`](crate::Dynamics).
#[derive(Clone, Debug)]
pub struct Dynamics {
    pub(crate) inner: ByJoints<DynamicsF>,
}

/// The drive of each joint, n values each (SPEC (20.5), (20.6)): the
/// run-time [`Drive`](crate::Drive).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Drive<'a> {
    /// Armature I_a (kg m², kg).
    pub armature: &'a [f64],
    /// Viscous damping b (N m s/rad, N s/m).
    pub damping: &'a [f64],
    /// Dry friction loss F (N m, N).
    pub friction: &'a [f64],
}

/// How a simulated plant realises the drive within one period, SPEC
/// (20.9): the run-time [`SampledDrive`](crate::SampledDrive).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SampledDrive<'a> {
    /// The plant's integrator step h (s).
    pub substep: f64,
    /// Integrator steps per period s.
    pub substeps: u32,
    /// Whether the damping is integrated implicitly.
    pub implicit_damping: bool,
    /// Whether each integrator step moves the position with the new velocity.
    pub semi_implicit: bool,
    /// The friction constraint's regularisation R, n values.
    pub regularisation: &'a [f64],
    /// The friction constraint's reference damping b_r (1/s), n values.
    pub rate: &'a [f64],
}

/// Passive joint springs, SPEC (20.5'): the run-time [`Spring`](crate::Spring).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Spring<'a> {
    /// Stiffness k (N m/rad, N/m), n values.
    pub stiffness: &'a [f64],
    /// The rest position q_s (rad, m), n values.
    pub reference: &'a [f64],
}

impl Dynamics {
    /// The dynamics of the chain `joints` with `inertials[k]` the inertial
    /// of joint k's child link, under `gravity` (m/s², base frame):
    /// [`Dynamics::new`](crate::Dynamics::new)'s checks.
    pub fn new(joints: &[Joint], inertials: &[Inertial], gravity: [f64; 3]) -> Result<Self, Error> {
        let n = movable_joints(joints);
        let inner = make!(n, N => cartesian::Dynamics::<N>::new(joints, inertials, gravity).map(Box::new), _ => movable(n))?;
        Ok(Self { inner })
    }

    /// The dynamics of `arm` (its links, and its joints' drive terms) under
    /// `gravity` (m/s², base frame). Errors name the description: an
    /// inertia no rigid body has names its link ([`Arm::inertia_error`]),
    /// as [`Arm::to_dynamics`] does.
    pub fn from_arm(arm: &Arm, gravity: [f64; 3]) -> Result<Self, DescriptionError> {
        let n = arm.n();
        let named =
            |e: Error| DescriptionError::new(ErrorKind::Value, format!("{}: {e}", arm.source));
        let inner = make!(n, N => {
            arm.to_dynamics::<N>(gravity).and_then(|d| {
                arm.drive::<N>()
                    .and_then(|drive| d.with_drive(drive))
                    .map(Box::new)
                    .map_err(named)
            })
        }, _ => named(movable(n)))?;
        Ok(Self { inner })
    }

    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// Total mass of the moving links (kg).
    pub fn mass(&self) -> f64 {
        each!(&self.inner, d, N => d.mass())
    }

    /// Gravity (m/s², base frame).
    pub fn gravity(&self) -> [f64; 3] {
        each!(&self.inner, d, N => d.gravity())
    }

    /// The chain of its joints (its tip is the last joint's frame).
    pub fn chain(&self) -> Chain {
        let inner = map!(&self.inner, d, N => Ok::<_, Infallible>(Box::new(*d.chain())))
            .unwrap_or_else(|e| match e {});
        Chain { inner }
    }

    /// The model with gravity compensation, SPEC (20.1'): `lifted[k]` what is
    /// lifted in the link of entry k of `joints` (as [`new`](Self::new) took
    /// them, fixed ones too)
    /// ([`Dynamics::with_gravity_compensation`](crate::Dynamics::with_gravity_compensation)).
    pub fn with_gravity_compensation(
        self,
        joints: &[Joint],
        lifted: &[cartesian::Lifted],
    ) -> Result<Self, Error> {
        let inner =
            map!(self.inner, d, N => d.with_gravity_compensation(joints, lifted).map(Box::new))?;
        Ok(Self { inner })
    }

    /// Every mass and inertia times `factor` ([`Dynamics::scaled`](crate::Dynamics::scaled)).
    pub fn scaled(self, factor: f64) -> Result<Self, Error> {
        let inner = map!(self.inner, d, N => d.scaled(factor).map(Box::new))?;
        Ok(Self { inner })
    }

    /// A payload (kg) at the last joint's frame ([`Dynamics::with_payload`](crate::Dynamics::with_payload)).
    pub fn with_payload(self, mass: f64) -> Result<Self, Error> {
        let inner = map!(self.inner, d, N => d.with_payload(mass).map(Box::new))?;
        Ok(Self { inner })
    }

    /// The joints' drive terms ([`Dynamics::with_drive`](crate::Dynamics::with_drive)).
    pub fn with_drive(self, drive: &Drive<'_>) -> Result<Self, Error> {
        let inner = map!(self.inner, d, N => {
            let drive = cartesian::Drive {
                armature: vector::<N>("armature", drive.armature)?,
                damping: vector::<N>("damping", drive.damping)?,
                friction: vector::<N>("friction", drive.friction)?,
            };
            d.with_drive(drive).map(Box::new)
        })?;
        Ok(Self { inner })
    }

    /// How a simulated plant realises the drive ([`Dynamics::with_sampled_drive`](crate::Dynamics::with_sampled_drive)).
    pub fn with_sampled_drive(self, s: &SampledDrive<'_>) -> Result<Self, Error> {
        let inner = map!(self.inner, d, N => {
            let s = cartesian::SampledDrive {
                substep: s.substep,
                substeps: s.substeps,
                implicit_damping: s.implicit_damping,
                semi_implicit: s.semi_implicit,
                regularisation: vector::<N>("friction_regularisation", s.regularisation)?,
                rate: vector::<N>("friction_rate", s.rate)?,
            };
            d.with_sampled_drive(s).map(Box::new)
        })?;
        Ok(Self { inner })
    }

    /// Passive joint springs ([`Dynamics::with_spring`](crate::Dynamics::with_spring)).
    pub fn with_spring(self, s: &Spring<'_>) -> Result<Self, Error> {
        let inner = map!(self.inner, d, N => {
            let s = cartesian::Spring {
                stiffness: vector::<N>("stiffness", s.stiffness)?,
                reference: vector::<N>("spring_reference", s.reference)?,
            };
            d.with_spring(s).map(Box::new)
        })?;
        Ok(Self { inner })
    }

    /// ID(q, q̇, q̈) (N m, N): [`Dynamics::inverse_dynamics_checked`](crate::Dynamics::inverse_dynamics_checked).
    pub fn inverse_dynamics(&self, q: &[f64], dq: &[f64], ddq: &[f64]) -> Result<Joints, Error> {
        each!(&self.inner, d, N => inverse_dynamics::<N>(d, q, dq, ddq))
    }

    /// M(q) (kg m², kg): [`Dynamics::mass_matrix_checked`](crate::Dynamics::mass_matrix_checked).
    pub fn mass_matrix(&self, q: &[f64]) -> Result<JointMatrix, Error> {
        each!(&self.inner, d, N => mass_matrix::<N>(d, q))
    }

    /// G(q) = RNEA(q, 0, 0) (N m, N), at a q finite and within 1e6, its
    /// entries finite; else an error naming `q`.
    pub fn gravity_torque(&self, q: &[f64]) -> Result<Joints, Error> {
        each!(&self.inner, d, N => {
            let q = vector::<N>("q", q)?;
            check::finite_slice("q", q.as_slice())?;
            check::within("q", q.as_slice(), CEILING_POSITION)?;
            let g = d.gravity_torque(&q);
            if g.iter().all(|x| x.is_finite()) {
                Ok(Joints::of(&g))
            } else {
                Err(Error::Diverged { what: "the gravity torque" })
            }
        })
    }
}

fn inverse_dynamics<const N: usize>(
    d: &cartesian::Dynamics<N>,
    q: &[f64],
    dq: &[f64],
    ddq: &[f64],
) -> Result<Joints, Error> {
    let (q, dq, ddq) = (vector("q", q)?, vector("dq", dq)?, vector("ddq", ddq)?);
    d.inverse_dynamics_checked(&q, &dq, &ddq)
        .map(|t| Joints::of(&t))
}

fn mass_matrix<const N: usize>(
    d: &cartesian::Dynamics<N>,
    q: &[f64],
) -> Result<JointMatrix, Error> {
    d.mass_matrix_checked(&vector("q", q)?)
        .map(|m| JointMatrix::of(&m))
}

pub(crate) struct ComputedF;
impl Family for ComputedF {
    type Of<const N: usize> = Box<cartesian::ComputedTorque<N>>;
}

pub(crate) struct ComputedStateF;
impl Family for ComputedStateF {
    type Of<const N: usize> = cartesian::ComputedState<N>;
}

/// The parameters of a computed-torque controller (20.3), n values per
/// joint: the run-time [`ComputedTorqueConfig`](crate::ComputedTorqueConfig).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ComputedTorqueConfig<'a> {
    /// Sampling period Ts (s).
    pub ts: f64,
    /// Stiffness K_P of the error dynamics (1/s²).
    pub kp: &'a [f64],
    /// Damping K_D of the error dynamics (1/s).
    pub kd: &'a [f64],
    /// Actuator limits τmax (N m).
    pub tau_max: &'a [f64],
    /// The target impedance's inertia Dd (kg m²).
    pub dd: &'a [f64],
    /// Its damping Cd (N m s/rad).
    pub cd: &'a [f64],
    /// Its stiffness Gd (N m/rad).
    pub gd: &'a [f64],
    /// Where the impedance is realised.
    pub mode: ImpedanceMode,
}

/// Computed-torque impedance control on the core's rigid-body model (SPEC
/// §20): the run-time [`ComputedTorque`](crate::ComputedTorque), immutable.
#[derive(Clone, Debug)]
pub struct ComputedTorque {
    pub(crate) inner: ByJoints<ComputedF>,
}

/// The state of a [`ComputedTorque`] run.
#[derive(Clone, Debug)]
pub struct ComputedState {
    pub(crate) inner: ByJoints<ComputedStateF>,
}

impl ComputedTorque {
    /// The controller of `cfg` (n values per joint, n the model's) with the
    /// model `model`: [`ComputedTorque::new`](crate::ComputedTorque::new)'s checks.
    pub fn new(cfg: &ComputedTorqueConfig<'_>, model: Dynamics) -> Result<Self, Error> {
        let inner = map!(model.inner, d, N => {
            let c = cartesian::ComputedTorqueConfig {
                ts: cfg.ts,
                kp: vector::<N>("Kp", cfg.kp)?,
                kd: vector::<N>("Kd", cfg.kd)?,
                tau_max: vector::<N>("tau_max", cfg.tau_max)?,
                impedance: TargetImpedance::new(
                    vector::<N>("Dd", cfg.dd)?,
                    vector::<N>("Cd", cfg.cd)?,
                    vector::<N>("Gd", cfg.gd)?,
                )?,
                mode: cfg.mode,
            };
            cartesian::ComputedTorque::new(c, *d).map(Box::new)
        })?;
        Ok(Self { inner })
    }

    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// The const-generic controller, if made for N joints: for a caller
    /// generic over N (a typed loop, [`for_joints`](super::for_joints)).
    pub fn typed<const N: usize>(&self) -> Option<&cartesian::ComputedTorque<N>> {
        each!(&self.inner, c, M => (&**c as &dyn core::any::Any).downcast_ref())
    }

    /// Sampling period Ts (s).
    pub fn period(&self) -> f64 {
        each!(&self.inner, c, N => c.period())
    }

    /// The model's total moving mass (kg).
    pub fn mass(&self) -> f64 {
        each!(&self.inner, c, N => c.model().mass())
    }

    /// ID(q, q̇, q̈) of its model (N m), checked as [`Dynamics::inverse_dynamics`].
    pub fn inverse_dynamics(&self, q: &[f64], dq: &[f64], ddq: &[f64]) -> Result<Joints, Error> {
        each!(&self.inner, c, N => inverse_dynamics::<N>(c.model(), q, dq, ddq))
    }

    /// M(q) of its model (kg m²), checked as [`Dynamics::mass_matrix`].
    pub fn mass_matrix(&self, q: &[f64]) -> Result<JointMatrix, Error> {
        each!(&self.inner, c, N => mass_matrix::<N>(c.model(), q))
    }

    /// The target impedance's Dd, Cd, Gd (n values each).
    pub fn impedance(&self) -> [Joints; 3] {
        each!(&self.inner, c, N => {
            let t = c.impedance();
            [Joints::of(t.dd()), Joints::of(t.cd()), Joints::of(t.gd())]
        })
    }

    /// A state at t = 0.
    pub fn new_state(&self) -> ComputedState {
        let inner = map!(&self.inner, _c, N => Ok::<_, Infallible>(cartesian::ComputedState::<N>::default()))
            .unwrap_or_else(|e| match e {});
        ComputedState { inner }
    }

    /// One step (20.3) at t_k: the measurement `m` (q̇ required) and the
    /// setpoint `c` in, the command out; [`ComputedTorque::step`](crate::ComputedTorque::step)
    /// bit for bit, no allocation. An input of another length than n is
    /// refused by name and recorded.
    pub fn step(
        &self,
        state: &mut ComputedState,
        m: &Measurement<'_>,
        c: &Setpoint<&[f64]>,
    ) -> Result<Command, Error> {
        pair!(&self.inner, &mut state.inner, ct, s, N => {
            let inputs = m.typed::<N>().and_then(|m| Ok((m, c.typed::<N>()?)));
            match inputs {
                Ok((m, c)) => ct.step(s, &m, &c).map(|cmd| Command::of(&cmd)),
                Err(e) => {
                    ct.refuse(s, e);
                    Err(e)
                }
            }
        }, _ => Err(mismatch("state")))
    }

    /// A step refused before it reached the controller, recorded; returns
    /// the torque held, or `None` for a state of another number of joints.
    pub fn refuse(&self, state: &mut ComputedState, error: Error) -> Option<Joints> {
        pair!(&self.inner, &mut state.inner, c, s, N => Some(Joints::of(&c.refuse(s, error))), _ => None)
    }
}

impl ComputedState {
    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// The const-generic state, if made for N joints: for a caller generic
    /// over N (a typed loop, [`for_joints`](super::for_joints)).
    pub fn typed<const N: usize>(&self) -> Option<&cartesian::ComputedState<N>> {
        each!(&self.inner, s, M => (s as &dyn core::any::Any).downcast_ref())
    }

    /// [`typed`](Self::typed), to change.
    pub fn typed_mut<const N: usize>(&mut self) -> Option<&mut cartesian::ComputedState<N>> {
        each!(&mut self.inner, s, M => (s as &mut dyn core::any::Any).downcast_mut())
    }

    /// Steps taken k.
    pub fn steps(&self) -> u64 {
        each!(&self.inner, s, N => s.k)
    }

    /// Back to t = 0.
    pub fn reset(&mut self) {
        each!(&mut self.inner, s, N => *s = cartesian::ComputedState::default())
    }

    /// The last step's command (zeros before the first).
    pub fn last(&self) -> Command {
        each!(&self.inner, s, N => Command::of(&s.last))
    }

    /// The torque last applied (N m).
    pub fn applied(&self) -> Joints {
        each!(&self.inner, s, N => Joints::of(&s.applied))
    }

    /// The last refused step's fault, if any.
    pub fn fault(&self) -> Option<Fault> {
        each!(&self.inner, s, N => s.fault)
    }
}
