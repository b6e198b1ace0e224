//! Task space in C (SPEC §16): a chain from joint data, the 6-D Cartesian
//! impedance over it with the joint controller it drives, its state and
//! step, and the orbit rule for RBF centres. Every computation is the
//! core's (`adaptimp::cartesian`); this converts and checks pointers, sizes
//! and enum values.

use crate::fields::{cartesian_fields, read_into, write_from};
use crate::handles::{buffer_size, free, handle, handle_mut, publish, publish_in, Buf, Header};
use crate::params::controller_of;
use crate::shared::{self, answer, front_step, step_entry, HoldsJoint, Output};
use crate::*;
use adaptimp::cartesian::rotation::quaternion_matrix;
use adaptimp::dynamic::{
    CartesianCommand, CartesianController, CartesianImpedance, CartesianMeasurement,
    CartesianState, Centres, Chain, Joints, Scenario, State,
};
use adaptimp::schema::{Group, Preset};
use adaptimp::{CartesianConfig, Joint, JointKind, Law, PoseTarget, Transform, Vector};
use core::ffi::c_void;
use nalgebra::{Matrix3, UnitQuaternion};

/// A rigid transform as plain data: `x_parent = rotation · x + translation`.
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpTransform {
    /// Translation (m).
    pub translation: [f64; 3],
    /// Rotation matrix, row-major (`rotation[i][j]` = R_ij); orthonormal to
    /// 1e-6 with det +1 (the chain checks it).
    pub rotation: [[f64; 3]; 3],
}

/// One joint of a chain description, base to tip (SPEC §16, (16.0)): a fixed
/// `origin` (the parent joint's frame → this joint's frame, URDF's
/// `<origin xyz rpy>`), a `kind`, and for a movable joint a non-zero `axis`
/// in its own frame (normalised by the chain) and an `offset`.
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpJoint {
    /// Fixed, revolute or prismatic (an `AdaptimpJointKind`, read as an integer).
    pub kind: AdaptimpJointKindRaw,
    /// The parent joint's frame → this joint's frame (at joint value `offset`).
    pub origin: AdaptimpTransform,
    /// The axis in this joint's frame (ignored for a fixed joint).
    pub axis: [f64; 3],
    /// The joint value (rad or m) at which the frame is `origin` (URDF: 0;
    /// MuJoCo: `qpos0`).
    pub offset: f64,
}

/// The tip of a chain at (q, q̇): the pose, the 6 × n geometric Jacobian
/// (world-aligned, at the tip) and J̇ q̇.
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpTip {
    /// Number of joints n.
    pub n: usize,
    /// Tip position p (m), world frame.
    pub position: [f64; 3],
    /// Tip rotation R (world ← tip), row-major.
    pub rotation: [[f64; 3]; 3],
    /// [J_v; J_ω], row i the task direction (x, y, z (m/rad or m/m), then
    /// rotation about x, y, z), column j the joint; the first n columns set.
    pub jacobian: [[f64; ADAPTIMP_MAX_JOINTS]; 6],
    /// J̇ q̇ = [p̈; ω̇] at q̈ = 0 (m/s², rad/s²).
    pub bias: [f64; 6],
}

/// The 6-D Cartesian impedance's parameters: the schema's group "cartesian"
/// (SPEC §16), named as there, per axis of the world frame (x, y, z). Fill it
/// with [`adaptimp_cartesian_params_default`], then change fields.
#[repr(C)]
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct AdaptimpCartesianParams {
    /// Target inertia M_d of the translation (kg), > 0.
    pub md: [f64; 3],
    /// Target damping B_d of the translation (N s/m), ≥ 0 (read if not `bd_critical`).
    pub bd: [f64; 3],
    /// True: B_d = 2√(K_d M_d) per axis, critical, following the filtered K_d (Python's `Bd=None`).
    pub bd_critical: AdaptimpBoolRaw,
    /// Target stiffness K_d of the translation (N/m), ≥ 0.
    pub kd: [f64; 3],
    /// Target inertia of the rotation (kg m²), > 0.
    pub md_rot: [f64; 3],
    /// Target damping of the rotation (N m s/rad), ≥ 0 (read if not `bd_rot_critical`).
    pub bd_rot: [f64; 3],
    /// True: critical damping of the rotation (Python's `Bd_rot=None`).
    pub bd_rot_critical: AdaptimpBoolRaw,
    /// Target stiffness of the rotation (N m/rad), ≥ 0; 0 on every axis:
    /// position-only (the orientation is no task).
    pub kd_rot: [f64; 3],
    /// CLIK gain K_P (1/s²), > 0, Ts²·K_P < 1, (C2).
    pub clik_kp: f64,
    /// CLIK gain K_D (1/s), > 0, Ts·K_D < 1, (C2).
    pub clik_kd: f64,
    /// Damping λ_p of the least-squares inverse in the translation rows (m), > 0, (C3).
    pub clik_lambda: f64,
    /// Damping λ_o of the least-squares inverse in the rotation rows, > 0, (C3).
    pub clik_lambda_rot: f64,
    /// Null-space posture stiffness k_0 (1/s²), ≥ 0.
    pub null_k: f64,
    /// Null-space damping d_0 (1/s), ≥ 0.
    pub null_d: f64,
    /// Largest translation error fed to the impedance (m), > 0, (16.5);
    /// INFINITY: no clipping (Python's None).
    pub pos_error_max: f64,
    /// Largest rotation error fed to the impedance (rad), > 0; INFINITY: no clipping.
    pub rot_error_max: f64,
    /// Time constant (s) of the filter on jumps of the commanded pose and on
    /// stiffness changes, (16.6), ≥ 0 (0: none).
    pub target_filter: f64,
    /// Time constant (s) of the filter on the measured wrench, ≥ 0 (0: none).
    pub force_filter: f64,
    /// True: the joint controller gets τe = Jᵀ F_e for its +τe feedforward
    /// (C5); false: τe = 0.
    pub force_feedforward: AdaptimpBoolRaw,
    /// How the impedance reaches the torque (an `AdaptimpFormulation`, read as
    /// an integer; SPEC §19): ADMITTANCE (the default), IMPEDANCE or UNIFIED.
    pub formulation: AdaptimpFormulationRaw,
    /// The admittance's share n ∈ [0, 1] of the torque for UNIFIED (ignored otherwise).
    pub admittance_share: f64,
}

/// A commanded pose and its rates at t_k, world frame (SPEC §16). The
/// rotation is checked at every step (orthonormal to 1e-6, det +1; else
/// INVALID_INPUT and nothing changes); fill it from a unit quaternion with
/// [`adaptimp_pose_target_set_quaternion`].
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpPoseTarget {
    /// Position p_c (m).
    pub p: [f64; 3],
    /// Velocity ṗ_c (m/s).
    pub dp: [f64; 3],
    /// Acceleration p̈_c (m/s²).
    pub ddp: [f64; 3],
    /// Rotation R_c (world ← tip), row-major; ignored by a position-only loop.
    pub rotation: [[f64; 3]; 3],
    /// Angular velocity ω_c (rad/s).
    pub w: [f64; 3],
    /// Angular acceleration ω̇_c (rad/s²).
    pub dw: [f64; 3],
}

/// What one Cartesian step computed; written on every status as
/// `AdaptimpCommand` is (see [`adaptimp_cartesian_step`]): `tau_sat` is
/// what goes to the actuators.
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpCartesianCommand {
    /// Number of joints; 0 when no controller could be asked (every field zero).
    pub n: usize,
    /// The torque to apply (N m): sat(τ), or the joint controller's fallback.
    pub tau_sat: [f64; ADAPTIMP_MAX_JOINTS],
    /// The joint controller's commanded τ (N m).
    pub tau: [f64; ADAPTIMP_MAX_JOINTS],
    /// z1 = q_d − q (rad).
    pub z1: [f64; ADAPTIMP_MAX_JOINTS],
    /// The joint reference q_d (rad) at t_k.
    pub q_d: [f64; ADAPTIMP_MAX_JOINTS],
    /// q̇_d (rad/s).
    pub dq_d: [f64; ADAPTIMP_MAX_JOINTS],
    /// q̈_d (rad/s²).
    pub ddq_d: [f64; ADAPTIMP_MAX_JOINTS],
    /// τe = Jᵀ(q) F_e (N m) the joint controller got (zero without force feedforward).
    pub tau_e: [f64; ADAPTIMP_MAX_JOINTS],
    /// The measured tip position fk(q) (m).
    pub p: [f64; 3],
    /// The measured tip rotation R(q), row-major.
    pub rotation: [[f64; 3]; 3],
    /// The compliant reference p_d (m).
    pub p_d: [f64; 3],
    /// ṗ_d (m/s).
    pub dp_d: [f64; 3],
    /// p̈_d (m/s²).
    pub ddp_d: [f64; 3],
    /// R_d, row-major.
    pub rotation_d: [[f64; 3]; 3],
    /// ω_d (rad/s).
    pub w_d: [f64; 3],
    /// ω̇_d (rad/s²).
    pub dw_d: [f64; 3],
    /// The commanded position after the target filter p_t (m).
    pub p_t: [f64; 3],
    /// The commanded rotation after the target filter R_t, row-major.
    pub rotation_t: [[f64; 3]; 3],
    /// The error [e_p (m); e_o (rad)] the impedance acted on (after clipping).
    pub error: [f64; 6],
}

impl AdaptimpCartesianCommand {
    /// Every field zero (n = 0): no controller answered.
    pub const ZERO: Self = Self {
        n: 0,
        tau_sat: [0.0; ADAPTIMP_MAX_JOINTS],
        tau: [0.0; ADAPTIMP_MAX_JOINTS],
        z1: [0.0; ADAPTIMP_MAX_JOINTS],
        q_d: [0.0; ADAPTIMP_MAX_JOINTS],
        dq_d: [0.0; ADAPTIMP_MAX_JOINTS],
        ddq_d: [0.0; ADAPTIMP_MAX_JOINTS],
        tau_e: [0.0; ADAPTIMP_MAX_JOINTS],
        p: [0.0; 3],
        rotation: [[0.0; 3]; 3],
        p_d: [0.0; 3],
        dp_d: [0.0; 3],
        ddp_d: [0.0; 3],
        rotation_d: [[0.0; 3]; 3],
        w_d: [0.0; 3],
        dw_d: [0.0; 3],
        p_t: [0.0; 3],
        rotation_t: [[0.0; 3]; 3],
        error: [0.0; 6],
    };
}

/// An arm's kinematics: a serial chain of 1 … 7 movable joints (opaque: a handle).
pub struct AdaptimpChain {
    _opaque: [u8; 0],
}

/// The object behind an [`AdaptimpChain`] handle.
#[repr(C)]
#[derive(Debug)]
pub(crate) struct ChainObject {
    head: Header,
    chain: Chain,
}
handle_kind!(AdaptimpChain => ChainObject, b"adpCHAIN");

/// The 6-D Cartesian impedance over a chain and the joint controller it
/// drives (opaque: a handle; immutable: share it between threads).
pub struct AdaptimpCartesian {
    _opaque: [u8; 0],
}

/// The object behind an [`AdaptimpCartesian`] handle.
#[repr(C)]
#[derive(Debug)]
pub(crate) struct CartesianObject {
    head: Header,
    pair: CartesianController,
}
handle_kind!(AdaptimpCartesian => CartesianObject, b"adpCARTE");

/// The state of a Cartesian run (opaque: a handle): the outer loop's and
/// the joint controller's.
pub struct AdaptimpCartesianState {
    _opaque: [u8; 0],
}

/// The object behind an [`AdaptimpCartesianState`] handle: the outer
/// loop's state, the joint controller's (its reals in `Buf`), and the start
/// (a reset goes back to it).
#[repr(C)]
#[derive(Debug)]
pub(crate) struct CartesianStateObject {
    head: Header,
    outer: CartesianState,
    joint: State<Buf>,
    q0: Joints,
}
handle_kind!(AdaptimpCartesianState => CartesianStateObject, b"adpCSTAT");

/// A chain's error: BAD_SIZE for its number of movable joints (none, or
/// more than 7), INVALID_CONFIG for every other.
pub(crate) fn chain_error(e: adaptimp::Error) -> AdaptimpStatus {
    match e {
        adaptimp::Error::Condition {
            lhs: "movable joints",
            ..
        } => fail(AdaptimpStatus::BadSize, &e),
        e => core_error(e, Context::Config),
    }
}

/// Publish `chain` as a handle.
pub(crate) fn publish_chain(chain: Chain) -> Result<*mut AdaptimpChain, AdaptimpStatus> {
    publish(Box::new(ChainObject {
        head: Header::unpublished(),
        chain,
    }))
}

fn transform_of(t: &AdaptimpTransform) -> Transform {
    Transform {
        translation: t.translation,
        rotation: t.rotation,
    }
}

fn transform_out(t: &Transform) -> AdaptimpTransform {
    AdaptimpTransform {
        translation: t.translation,
        rotation: t.rotation,
    }
}

fn rows3(m: &Matrix3<f64>) -> [[f64; 3]; 3] {
    core::array::from_fn(|i| core::array::from_fn(|j| m[(i, j)]))
}

fn rows_q(q: &UnitQuaternion<f64>) -> [[f64; 3]; 3] {
    rows3(q.to_rotation_matrix().matrix())
}

fn v3(v: &[f64; 3]) -> Vector<3> {
    Vector::<3>::from(*v)
}

fn a3(v: &Vector<3>) -> [f64; 3] {
    [v[0], v[1], v[2]]
}

fn joints7(v: &[f64]) -> [f64; ADAPTIMP_MAX_JOINTS] {
    let mut a = [0.0; ADAPTIMP_MAX_JOINTS];
    a[..v.len()].copy_from_slice(v);
    a
}

fn pose_target(t: &AdaptimpPoseTarget) -> PoseTarget {
    PoseTarget {
        p: v3(&t.p),
        dp: v3(&t.dp),
        ddp: v3(&t.ddp),
        r: Matrix3::from_fn(|i, j| t.rotation[i][j]),
        w: v3(&t.w),
        dw: v3(&t.dw),
    }
}

mod chain;
mod controller;
mod orbit;
pub use chain::*;
pub use controller::*;
pub use orbit::*;
