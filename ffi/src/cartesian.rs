//! Task space in C (SPEC §16): a chain from joint data, the 6-D Cartesian
//! impedance over it with the joint controller it drives, its state and
//! step, and the orbit rule for RBF centres. Every computation is the
//! core's (`adaptimp::cartesian`); this converts and checks pointers, sizes
//! and enum values.

use crate::fields::{cartesian_fields, read_into, write_from};
use crate::handles::{buffer_size, free, handle, handle_mut, publish, publish_in, Buf, Header};
use crate::joint::{copy_sized, fault_of};
use crate::params::controller_of;
use crate::*;
use adaptimp::cartesian::rotation::quaternion_matrix;
use adaptimp::dynamic::{
    CartesianCommand, CartesianController, CartesianImpedance, CartesianMeasurement,
    CartesianState, Centres, Chain, Joints, Scenario, State,
};
use adaptimp::schema::Preset;
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

// ---------------------------------------------------------------------------
// Transforms and chains.
// ---------------------------------------------------------------------------

/// URDF's `<origin xyz="…" rpy="…">`: translation `xyz` (3 reals, m) and the
/// fixed-axis roll, pitch, yaw `rpy` (3 reals, rad), R = Rot_z(yaw)
/// Rot_y(pitch) Rot_x(roll). Values are checked by the chain.
///
/// # Safety
/// `xyz` and `rpy` are NULL or hold 3 reals; `out` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_transform_xyz_rpy(
    xyz: *const f64,
    rpy: *const f64,
    out: *mut AdaptimpTransform,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let xyz = unsafe { slice(xyz, 3, "xyz") }?;
        let rpy = unsafe { slice(rpy, 3, "rpy") }?;
        let out = unsafe { crate::out(out, "out") }?;
        *out = transform_out(&Transform::from_xyz_rpy(
            [xyz[0], xyz[1], xyz[2]],
            [rpy[0], rpy[1], rpy[2]],
        ));
        Ok(())
    })
}

/// A position `pos` (3 reals, m) and a quaternion `quat` = [w, x, y, z]
/// (MuJoCo's `body_pos`, `body_quat`; normalised as MuJoCo does, finite and
/// non-zero, else INVALID_CONFIG).
///
/// # Safety
/// `pos` holds 3 reals, `quat` 4, or is NULL; `out` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_transform_pos_quat(
    pos: *const f64,
    quat: *const f64,
    out: *mut AdaptimpTransform,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let pos = unsafe { slice(pos, 3, "pos") }?;
        let quat = unsafe { slice(quat, 4, "quat") }?;
        let out = unsafe { crate::out(out, "out") }?;
        let t = Transform::from_pos_quat(
            [pos[0], pos[1], pos[2]],
            [quat[0], quat[1], quat[2], quat[3]],
        )
        .map_err(|e| core_error(e, Context::Config))?;
        *out = transform_out(&t);
        Ok(())
    })
}

/// A 4 × 4 homogeneous transform `m` (16 reals, row-major: [R p; 0 0 0 1]).
/// Its last row must be 0 0 0 1 (to 1e-6; else INVALID_CONFIG); R is checked
/// by the chain.
///
/// # Safety
/// `m` is NULL or holds 16 reals; `out` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_transform_matrix(
    m: *const f64,
    out: *mut AdaptimpTransform,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let m = unsafe { slice(m, 16, "m") }?;
        let out = unsafe { crate::out(out, "out") }?;
        let m: [f64; 16] = core::array::from_fn(|i| m[i]);
        let t = Transform::from_matrix(&m).map_err(|e| core_error(e, Context::Config))?;
        *out = transform_out(&t);
        Ok(())
    })
}

/// The chain of `count` joints `joints` (base to tip, fixed ones included;
/// 1 … 7 movable) and the `tip` transform (the last joint's frame → the
/// tip; NULL: the identity) into `*out` (free it with
/// [`adaptimp_chain_free`]). Checked by the core, each error naming the
/// condition and the joint's index: a zero or non-finite axis, a rotation
/// that is not orthonormal or is a reflection, an origin beyond 1e6 m
/// (INVALID_CONFIG); a `kind` that is not an `AdaptimpJointKind`
/// (INVALID_CONFIG); no or more than 7 movable joints (BAD_SIZE).
///
/// # Safety
/// `joints` is NULL or holds `count` joints; `tip` and `out` are NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_chain_new(
    joints: *const AdaptimpJoint,
    count: usize,
    tip: *const AdaptimpTransform,
    out: *mut *mut AdaptimpChain,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let given = if count == 0 {
            &[][..]
        } else {
            unsafe { slice(joints, count, "joints") }?
        };
        let out = unsafe { crate::out(out, "out") }?;
        let tip = if tip.is_null() {
            Transform::IDENTITY
        } else {
            transform_of(unsafe { read(tip, "tip") }?)
        };
        let mut js = Vec::with_capacity(count);
        for (i, j) in given.iter().enumerate() {
            let kind = match decode::<AdaptimpJointKind>(j.kind, &format!("joints[{i}].kind"))? {
                AdaptimpJointKind::Fixed => JointKind::Fixed,
                AdaptimpJointKind::Revolute => JointKind::Revolute,
                AdaptimpJointKind::Prismatic => JointKind::Prismatic,
            };
            js.push(Joint {
                kind,
                origin: transform_of(&j.origin),
                axis: j.axis,
                offset: j.offset,
            });
        }
        *out = publish_chain(Chain::new(&js, &tip).map_err(chain_error)?)?;
        Ok(())
    })
}

/// Free a chain (NULL and dead handles are ignored). A Cartesian controller
/// keeps its own copy: the chain can be freed after `adaptimp_cartesian_new`.
///
/// # Safety
/// `chain` is NULL or came from `adaptimp_chain_new`.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_chain_free(chain: *mut AdaptimpChain) {
    // SAFETY: the caller's contract.
    unsafe { free(chain, "chain") }
}

/// The chain's number of movable joints, or 0 for NULL or a dead handle.
///
/// # Safety
/// `chain` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_chain_joints(chain: *const AdaptimpChain) -> usize {
    // SAFETY (in `handle`): checked.
    match unsafe { handle(chain, "chain") } {
        Ok(c) => c.chain.n(),
        Err(_) => 0,
    }
}

/// The tip at q (rad or m, `n` reals) and q̇ (`n` reals; NULL: zero) into
/// `*out`: pose, Jacobian, J̇ q̇ (the core's one pass, (16.0)). NON_FINITE
/// for a q or q̇ that is not finite; BAD_SIZE for n ≠ the chain's.
///
/// # Safety
/// `chain` and `out` are NULL or valid; `q`, `dq` NULL or hold `n` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_chain_tip(
    chain: *const AdaptimpChain,
    n: usize,
    q: *const f64,
    dq: *const f64,
    out: *mut AdaptimpTip,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let c = unsafe { handle(chain, "chain") }?;
        let out = unsafe { crate::out(out, "out") }?;
        let c = &c.chain;
        check_n(n, c.n(), "chain")?;
        let q = unsafe { slice(q, n, "q") }?;
        let zero = [0.0; ADAPTIMP_MAX_JOINTS];
        let dq = if dq.is_null() {
            &zero[..n]
        } else {
            unsafe { slice(dq, n, "dq") }?
        };
        let t = c.tip(q, dq).map_err(|e| core_error(e, Context::Step))?;
        out.n = n;
        out.position = a3(&t.position);
        out.rotation = rows3(t.rotation.matrix());
        out.jacobian = core::array::from_fn(|i| {
            let mut row = [0.0; ADAPTIMP_MAX_JOINTS];
            for (j, v) in row.iter_mut().enumerate().take(n) {
                *v = t.jacobian[(i, j)];
            }
            row
        });
        out.bias = core::array::from_fn(|i| t.bias[i]);
        Ok(())
    })
}

// ---------------------------------------------------------------------------
// Cartesian parameters.
// ---------------------------------------------------------------------------

/// The parameters as the core's configuration, each set from its field
/// ([`cartesian_fields`]).
fn cartesian_of(p: &AdaptimpCartesianParams) -> Result<CartesianConfig, AdaptimpStatus> {
    let mut s =
        Scenario::new(1, Preset::Robot, Law::Pd).map_err(|e| core_error(e, Context::Config))?;
    let mut p = *p;
    read_into(&mut s, 1, cartesian_fields(&mut p), "cart")?;
    Ok(s.cartesian())
}

/// Fill `out` with the schema's defaults of the group "cartesian" (SPEC
/// §16: M_d = 2 kg, K_d = 500 N/m, critical damping, M_d,rot = 0.08 kg m²,
/// K_d,rot = 20 N m/rad, …; no clipping).
///
/// # Safety
/// `out` is NULL or points to an `AdaptimpCartesianParams`.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_params_default(
    out: *mut AdaptimpCartesianParams,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `out`): checked for NULL.
        let out = unsafe { crate::out(out, "out") }?;
        let s =
            Scenario::new(1, Preset::Robot, Law::Pd).map_err(|e| core_error(e, Context::Config))?;
        let mut p = AdaptimpCartesianParams::default();
        write_from(&s, &mut cartesian_fields(&mut p));
        *out = p;
        Ok(())
    })
}

// ---------------------------------------------------------------------------
// The Cartesian controller.
// ---------------------------------------------------------------------------

/// The 6-D Cartesian impedance of `cart` over `chain` (copied), driving the
/// joint controller of `joint` (its `n` the chain's, `impedance` =
/// `ADAPTIMP_IMPEDANCE_EXTERNAL`: the Cartesian impedance is the only one),
/// at the joint controller's period Ts, into `*out` (free it with
/// [`adaptimp_cartesian_free`]). Every condition is the core's
/// (INVALID_CONFIG naming it); BAD_SIZE if `joint.n` is not the chain's.
///
/// # Safety
/// `chain`, `cart`, `joint` and `out` are NULL or valid (and `joint`'s
/// pointers as `adaptimp_controller_new` says).
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_new(
    chain: *const AdaptimpChain,
    cart: *const AdaptimpCartesianParams,
    joint: *const AdaptimpParams,
    out: *mut *mut AdaptimpCartesian,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let chain = unsafe { handle(chain, "chain") }?;
        let cart = unsafe { read(cart, "cart") }?;
        let joint = unsafe { read(joint, "joint") }?;
        let out = unsafe { crate::out(out, "out") }?;
        let cfg = cartesian_of(cart)?;
        let chain = &chain.chain;
        if joint.n != chain.n() {
            return Err(fail(
                AdaptimpStatus::BadSize,
                &format_args!(
                    "joint.n = {}, but the chain has {} joints",
                    joint.n,
                    chain.n()
                ),
            ));
        }
        // SAFETY (in `controller_of`): `joint`'s pointers are the caller's.
        let ctrl = unsafe { controller_of(joint) }?;
        let config = |e| core_error(e, Context::Config);
        let outer = CartesianImpedance::new(cfg, chain, ctrl.period()).map_err(config)?;
        let pair = CartesianController::new(outer, ctrl).map_err(config)?;
        *out = publish(Box::new(CartesianObject {
            head: Header::unpublished(),
            pair,
        }))?;
        Ok(())
    })
}

/// Free a Cartesian controller (NULL and dead handles are ignored). Free its
/// states first.
///
/// # Safety
/// `cart` is NULL or came from `adaptimp_cartesian_new`.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_free(cart: *mut AdaptimpCartesian) {
    // SAFETY: the caller's contract.
    unsafe { free(cart, "cart") }
}

/// The number of joints, or 0 for NULL or a dead handle.
///
/// # Safety
/// `cart` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_joints(cart: *const AdaptimpCartesian) -> usize {
    // SAFETY (in `handle`): checked.
    match unsafe { handle(cart, "cart") } {
        Ok(c) => c.pair.joint().n(),
        Err(_) => 0,
    }
}

/// The period Ts (s), or NaN for NULL or a dead handle.
///
/// # Safety
/// `cart` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_period(cart: *const AdaptimpCartesian) -> f64 {
    // SAFETY (in `handle`): checked.
    match unsafe { handle(cart, "cart") } {
        Ok(c) => c.pair.outer().period(),
        Err(_) => f64::NAN,
    }
}

/// A state at t = 0 of `pair` started at `q0` over `buf`.
///
/// # Safety
/// `q0` is NULL or holds `n` reals.
unsafe fn cstate_over(
    pair: &CartesianController,
    n: usize,
    q0: *const f64,
    buf: Buf,
) -> Result<CartesianStateObject, AdaptimpStatus> {
    check_n(n, pair.joint().n(), "Cartesian controller")?;
    // SAFETY: the caller's contract.
    let q0 = unsafe { slice(q0, n, "q0") }?;
    let config = |e| core_error(e, Context::Config);
    Ok(CartesianStateObject {
        head: Header::unpublished(),
        outer: pair.start(q0).map_err(config)?,
        joint: pair.joint().state_in(buf).map_err(config)?,
        q0: Joints::from_slice(q0).map_err(config)?,
    })
}

/// A state at t = 0 of `cart` into `*out`, on the heap (free it with
/// [`adaptimp_cartesian_state_free`]), started at `q0` (`n` reals, rad: the
/// measured start; the joint reference q_d(0) and the null-space posture).
/// The first step's target should be near fk(q0) (the inverse kinematics
/// pulls fk(q_d) onto it). For a state in memory of your own, see
/// [`adaptimp_cartesian_state_init`].
///
/// # Safety
/// `cart` and `out` are NULL or valid; `q0` is NULL or holds `n` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_new(
    cart: *const AdaptimpCartesian,
    n: usize,
    q0: *const f64,
    out: *mut *mut AdaptimpCartesianState,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let c = unsafe { handle(cart, "cart") }?;
        let out = unsafe { crate::out(out, "out") }?;
        let buf = Buf::Heap(vec![0.0; c.pair.joint().buffer_len()]);
        // SAFETY (in `cstate_over`): `q0` is the caller's.
        *out = publish(Box::new(unsafe { cstate_over(&c.pair, n, q0, buf) }?))?;
        Ok(())
    })
}

/// The size (bytes) and alignment a caller buffer for a state of `cart`
/// needs ([`adaptimp_cartesian_state_init`]).
///
/// # Safety
/// `cart` is NULL or valid; `size` and `align` are NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_buffer_size(
    cart: *const AdaptimpCartesian,
    size: *mut usize,
    align: *mut usize,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let c = unsafe { handle(cart, "cart") }?;
        let size = unsafe { crate::out(size, "size") }?;
        let align = unsafe { crate::out(align, "align") }?;
        (*size, *align) = buffer_size::<AdaptimpCartesianState>(c.pair.joint().buffer_len())?;
        Ok(())
    })
}

/// A state of `cart` started at `q0` in the caller's buffer `buf` of `size`
/// bytes, no allocation: as [`adaptimp_state_init`] for a joint state (the
/// buffer stays put and unused otherwise while the state lives;
/// [`adaptimp_cartesian_state_free`] ends its life and frees nothing).
///
/// # Safety
/// `cart` and `out` are NULL or valid; `q0` NULL or `n` reals; `buf` NULL or
/// `size` writable bytes that nothing else uses while the state lives.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_init(
    cart: *const AdaptimpCartesian,
    n: usize,
    q0: *const f64,
    buf: *mut c_void,
    size: usize,
    out: *mut *mut AdaptimpCartesianState,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let c = unsafe { handle(cart, "cart") }?;
        let out = unsafe { crate::out(out, "out") }?;
        // SAFETY (in `publish_in`, `cstate_over`): `buf`, `size` and `q0` are the caller's.
        *out = unsafe {
            publish_in(
                buf,
                size,
                c.pair.joint().buffer_len(),
                "adaptimp_cartesian_state_buffer_size",
                |buf| cstate_over(&c.pair, n, q0, buf),
            )
        }?;
        Ok(())
    })
}

/// Free a Cartesian state (NULL and dead handles ignored); for one in a
/// caller buffer, end its life (nothing is freed).
///
/// # Safety
/// `state` is NULL or came from `adaptimp_cartesian_state_new` or `_init`.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_free(state: *mut AdaptimpCartesianState) {
    // SAFETY: the caller's contract.
    unsafe { free(state, "state") }
}

/// Back to t = 0: the outer loop started at `q0` (`n` reals; NULL: the
/// start's), the null-space posture kept, the joint state as at creation.
///
/// # Safety
/// `cart` and `state` are NULL or valid; `q0` NULL or holds `n` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_reset(
    cart: *const AdaptimpCartesian,
    state: *mut AdaptimpCartesianState,
    n: usize,
    q0: *const f64,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked; the caller's contract.
        let c = unsafe { handle(cart, "cart") }?;
        let s = unsafe { handle_mut(state, "state") }?;
        same_joints(c.pair.joint().n(), s.joint.n(), "Cartesian controller")?;
        check_n(n, s.joint.n(), "state")?;
        let q0 = if q0.is_null() {
            s.q0
        } else {
            let q0 = unsafe { slice(q0, n, "q0") }?;
            Joints::from_slice(q0).map_err(|e| core_error(e, Context::Config))?
        };
        c.pair
            .restart(&mut s.outer, &q0)
            .map_err(|e| core_error(e, Context::Config))?;
        s.q0 = q0;
        s.joint.reset();
        Ok(())
    })
}

/// The null-space posture (rad, `n` reals) of `state` under `cart` from
/// the next step on. The core checks it, as the step would need it:
/// finite, within the joint controller's `q_max` (at most 1e6 rad), and
/// null_k·|posture − q_d| ≤ 1e6 rad/s² (the ceiling of q̈_d) per joint;
/// else INVALID_CONFIG naming `posture` and the joint, nothing changed.
///
/// # Safety
/// `cart`, `state` NULL or valid; `posture` NULL or holds `n` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_set_posture(
    cart: *const AdaptimpCartesian,
    state: *mut AdaptimpCartesianState,
    n: usize,
    posture: *const f64,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked; the caller's contract.
        let c = unsafe { handle(cart, "cart") }?;
        let s = unsafe { handle_mut(state, "state") }?;
        same_joints(c.pair.joint().n(), s.joint.n(), "Cartesian controller")?;
        check_n(n, s.joint.n(), "state")?;
        let posture = unsafe { slice(posture, n, "posture") }?;
        c.pair
            .set_posture(&mut s.outer, posture)
            .map_err(|e| core_error(e, Context::Config))
    })
}

/// Ask for the stiffness `kd` (3 reals, N/m) and `kd_rot` (3 reals, N m/rad):
/// the impedance moves to it through the target filter, (16.6). The core
/// checks it (≥ 0, finite, ≤ 1e9, none > 0 for a position-only loop:
/// INVALID_CONFIG, nothing changed).
///
/// # Safety
/// `cart`, `state` NULL or valid; `kd`, `kd_rot` NULL or hold 3 reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_set_stiffness(
    cart: *const AdaptimpCartesian,
    state: *mut AdaptimpCartesianState,
    kd: *const f64,
    kd_rot: *const f64,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked; the caller's contract.
        let c = unsafe { handle(cart, "cart") }?;
        let s = unsafe { handle_mut(state, "state") }?;
        let kd = unsafe { slice(kd, 3, "kd") }?;
        let kd_rot = unsafe { slice(kd_rot, 3, "kd_rot") }?;
        let (kd, kd_rot) = (
            Vector::<3>::from_column_slice(kd),
            Vector::<3>::from_column_slice(kd_rot),
        );
        same_joints(c.pair.joint().n(), s.joint.n(), "Cartesian controller")?;
        c.pair
            .outer()
            .set_stiffness(&mut s.outer, &kd, &kd_rot)
            .map_err(|e| core_error(e, Context::Config))
    })
}

/// True if a refused step recorded a fault in the joint controller's state
/// (as [`adaptimp_state_fault`]); `*step` gets its step. False for NULL.
///
/// # Safety
/// `state` is NULL or valid; `step` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_fault(
    state: *const AdaptimpCartesianState,
    step: *mut u64,
) -> bool {
    // SAFETY (in `handle`): checked.
    let Ok(s) = (unsafe { handle(state, "state") }) else {
        return false;
    };
    fault_of(s.joint.fault(), step)
}

/// Clear the recorded fault (as [`adaptimp_state_clear_fault`]).
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_clear_fault(
    state: *mut AdaptimpCartesianState,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `handle_mut`): checked.
        let s = unsafe { handle_mut(state, "state") }?;
        s.joint.clear_fault();
        Ok(())
    })
}

/// Steps taken since creation or reset, or 0 for NULL or a dead handle.
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_steps(
    state: *const AdaptimpCartesianState,
) -> u64 {
    // SAFETY (in `handle`): checked.
    match unsafe { handle(state, "state") } {
        Ok(s) => s.joint.steps(),
        Err(_) => 0,
    }
}

/// The torque to apply now (N m, `n` reals), as [`adaptimp_state_applied`].
///
/// # Safety
/// `state` is NULL or valid; `tau` NULL or holds `n` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_applied(
    state: *const AdaptimpCartesianState,
    n: usize,
    tau: *mut f64,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked; the caller's contract.
        let s = unsafe { handle(state, "state") }?;
        let tau = unsafe { slice_mut(tau, n, "tau") }?;
        copy_sized(&s.joint.applied(), tau, "tau")
    })
}

/// The unit quaternion `quat` = [w, x, y, z] as `target`'s rotation matrix
/// (the core's conversion: a quaternion whose norm is not 1 to 1e-6, or not
/// finite, is refused with INVALID_INPUT and `target` is unchanged).
///
/// # Safety
/// `target` is NULL or valid; `quat` NULL or holds 4 reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_pose_target_set_quaternion(
    target: *mut AdaptimpPoseTarget,
    quat: *const f64,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked; the caller's contract.
        let t = unsafe { crate::out(target, "target") }?;
        let q = unsafe { slice(quat, 4, "quat") }?;
        let m = quaternion_matrix("quat", &[q[0], q[1], q[2], q[3]])
            .map_err(|e| core_error(e, Context::Step))?;
        t.rotation = rows3(&m);
        Ok(())
    })
}

/// One Cartesian step at t_k = k·Ts (SPEC §16, (C0)–(C5)): the measured q
/// (rad, `n` reals), q̇ (rad/s, `n` reals; NULL for output feedback), the
/// measured wrench F_e = [f (N); m (N m)] (6 reals, world frame, what the
/// tip exerts on the environment, the moment about the tip) and the
/// commanded pose `target` (NULL: hold the last one; at the first step the
/// start pose fk(q0)) in; the command out. The outer loop is staged, the
/// joint step runs, and only if it succeeds is anything committed: on a
/// refusal both states are as before but for the refusal, recorded in the
/// joint state as a refused joint step (the fault semantics of
/// docs/reliability.md). No allocation.
///
/// `*out` is written on every status, as [`adaptimp_step`]'s table says:
/// the command on OK; the joint controller's fallback in `tau_sat` (n set,
/// the rest zero) on a refusal by the core (NON_FINITE, OUT_OF_RANGE,
/// INVALID_INPUT for a target rotation that is not one, MISSING_VELOCITY,
/// FAULTED, …) or by this front with live handles of one size
/// (NULL_POINTER for `q`, `wrench`, `out`; BAD_SIZE for `n`), the refusal
/// recorded; every field zero with n = 0 when there is no controller to ask
/// (NULL or dead `cart` or `state`, WRONG_STATE, INTERNAL).
///
/// # Safety
/// Each pointer is NULL or valid for what it holds (`q`, `dq`: `n` reals;
/// `wrench`: 6; `target`, `out`: one struct).
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn adaptimp_cartesian_step(
    cart: *const AdaptimpCartesian,
    state: *mut AdaptimpCartesianState,
    n: usize,
    q: *const f64,
    dq: *const f64,
    wrench: *const f64,
    target: *const AdaptimpPoseTarget,
    out: *mut AdaptimpCartesianCommand,
) -> AdaptimpStatus {
    let status = guard(|| {
        // SAFETY (in the helpers): each pointer checked for NULL; the caller's contract.
        let mut cmd = unsafe { out.as_mut() };
        if let Some(o) = cmd.as_deref_mut() {
            *o = AdaptimpCartesianCommand::ZERO;
        }
        let c = unsafe { handle(cart, "cart") }?;
        let s = unsafe { handle_mut(state, "state") }?;
        let args = CartArgs {
            n,
            q,
            dq,
            wrench,
            target,
        };
        same_joints(c.pair.joint().n(), s.joint.n(), "Cartesian controller")?;
        cart_step(&c.pair, s, &args, cmd)
    });
    if status == AdaptimpStatus::Internal && !out.is_null() {
        // SAFETY: non-NULL; the caller's contract.
        unsafe { *out = AdaptimpCartesianCommand::ZERO };
    }
    status
}

/// A Cartesian step's pointers, as the caller gave them.
struct CartArgs {
    n: usize,
    q: *const f64,
    dq: *const f64,
    wrench: *const f64,
    target: *const AdaptimpPoseTarget,
}

/// A refused step's output: the fallback to apply (none: no controller
/// answered, n = 0), n, the rest zero.
fn write_fallback(tau: Option<&[f64]>, out: &mut AdaptimpCartesianCommand) {
    *out = AdaptimpCartesianCommand::ZERO;
    if let Some(tau) = tau {
        out.n = tau.len();
        out.tau_sat = joints7(tau);
    }
}

/// The refusal of a step the front refused (`status` already the last error).
fn refused(
    pair: &CartesianController,
    s: &mut CartesianStateObject,
    out: Option<&mut AdaptimpCartesianCommand>,
    status: AdaptimpStatus,
) -> AdaptimpStatus {
    let tau = pair.joint().refuse(&mut s.joint, BAD_ARGUMENTS);
    if let Some(out) = out {
        write_fallback(tau.as_deref(), out);
    }
    status
}

/// The step of a Cartesian controller and a state of the same n.
fn cart_step(
    pair: &CartesianController,
    s: &mut CartesianStateObject,
    a: &CartArgs,
    out: Option<&mut AdaptimpCartesianCommand>,
) -> Result<(), AdaptimpStatus> {
    let n = pair.joint().n();
    if let Err(status) = check_n(a.n, n, "Cartesian controller") {
        return Err(refused(pair, s, out, status));
    }
    let Some(out) = out else {
        return Err(refused(pair, s, None, null("out")));
    };
    // SAFETY (in `slice`, `read`): checked for NULL; the caller's contract.
    let inputs = (|| {
        let q = unsafe { slice(a.q, n, "q") }?;
        let wrench = unsafe { slice(a.wrench, 6, "wrench") }?;
        let dq = if a.dq.is_null() {
            None
        } else {
            Some(unsafe { slice(a.dq, n, "dq") }?)
        };
        let target = if a.target.is_null() {
            None
        } else {
            Some(unsafe { read(a.target, "target") }?)
        };
        Ok((q, wrench, dq, target))
    })();
    let (q, wrench, dq, target) = match inputs {
        Ok(v) => v,
        Err(status) => return Err(refused(pair, s, Some(out), status)),
    };
    let m = CartesianMeasurement {
        q,
        dq,
        wrench: Vector::<6>::from_column_slice(wrench),
    };
    let target = target.map(pose_target);
    match pair.step_or_fallback(&mut s.outer, &mut s.joint, &m, target.as_ref()) {
        (_, Ok(cmd)) => {
            write_cartesian(&cmd, out);
            Ok(())
        }
        (fallback, Err(e)) => {
            write_fallback(fallback.as_deref(), out);
            Err(core_error(e, Context::Step))
        }
    }
}

/// An accepted step's output.
fn write_cartesian(cmd: &CartesianCommand, out: &mut AdaptimpCartesianCommand) {
    out.n = cmd.joint.tau_sat.len();
    out.tau_sat = joints7(&cmd.joint.tau_sat);
    out.tau = joints7(&cmd.joint.tau);
    out.z1 = joints7(&cmd.joint.z1);
    out.q_d = joints7(&cmd.reference.x);
    out.dq_d = joints7(&cmd.reference.dx);
    out.ddq_d = joints7(&cmd.reference.ddx);
    out.tau_e = joints7(&cmd.tau_e);
    out.p = a3(&cmd.p);
    out.rotation = rows3(cmd.r.matrix());
    out.p_d = a3(&cmd.compliant.p);
    out.dp_d = a3(&cmd.compliant.dp);
    out.ddp_d = a3(&cmd.compliant.ddp);
    out.rotation_d = rows_q(&cmd.compliant.r);
    out.w_d = a3(&cmd.compliant.w);
    out.dw_d = a3(&cmd.compliant.dw);
    out.p_t = a3(&cmd.target.0);
    out.rotation_t = rows_q(&cmd.target.1);
    out.error = core::array::from_fn(|i| cmd.error[i]);
}

// ---------------------------------------------------------------------------
// The orbit rule.
// ---------------------------------------------------------------------------

/// RBF centres along the joint orbit of a Cartesian path (SPEC §15, (15.2),
/// and §16): the core runs the outer loop of `cart` over `chain` at period
/// `ts` kinematically (F_e = 0) from `q0` (`n` reals, rad) along `targets`
/// (`steps` poses, one per step), keeps the joint reference (q_d, q̇_d) of
/// every max(1, ⌊steps/nodes⌋)-th step (L ≤ `nodes` samples), and makes them
/// centres with widths per block η_q = max(2 h_q, `tube[0]`) (rad), η_v =
/// max(2 h_v, `tube[1]`) (rad/s) (α1, α̇1 left out: width INFINITY). Writes
/// the centres into `centers` (room for `nodes` rows of 4n reals; L rows
/// written), the squared widths into `widths2` (4n reals) and L into
/// `*written`: what `AdaptimpParams.centers`, `.nodes` and `.widths2` take.
///
/// # Safety
/// `chain`, `cart` NULL or valid; `q0` NULL or `n` reals; `targets` NULL or
/// `steps` poses; `tube` NULL or 2 reals; `centers` NULL or `nodes × 4n`
/// reals; `widths2` NULL or `4n` reals; `written` NULL or valid.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn adaptimp_cartesian_orbit_centres(
    chain: *const AdaptimpChain,
    cart: *const AdaptimpCartesianParams,
    ts: f64,
    n: usize,
    q0: *const f64,
    targets: *const AdaptimpPoseTarget,
    steps: usize,
    nodes: usize,
    tube: *const f64,
    centers: *mut f64,
    widths2: *mut f64,
    written: *mut usize,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let chain = unsafe { handle(chain, "chain") }?;
        let cfg = cartesian_of(unsafe { read(cart, "cart") }?)?;
        let targets = unsafe { slice(targets, steps, "targets") }?;
        let tube = unsafe { slice(tube, 2, "tube") }?;
        let written = unsafe { out(written, "written") }?;
        if nodes == 0 {
            return Err(fail(AdaptimpStatus::BadSize, &"nodes must be ≥ 1"));
        }
        let c = &chain.chain;
        check_n(n, c.n(), "chain")?;
        let q0 = unsafe { slice(q0, n, "q0") }?;
        let len = nodes
            .checked_mul(4 * n)
            .ok_or_else(|| fail(AdaptimpStatus::BadSize, &"nodes × 4n overflows"))?;
        let centers = unsafe { slice_mut(centers, len, "centers") }?;
        let widths2 = unsafe { slice_mut(widths2, 4 * n, "widths2") }?;
        let config = |e| core_error(e, Context::Config);
        let outer = CartesianImpedance::new(cfg, c, ts).map_err(config)?;
        let samples = outer
            .orbit(q0, targets.len(), |k| pose_target(&targets[k]), nodes)
            .map_err(config)?;
        let along = Centres::along(&samples, [tube[0], tube[1]], false).map_err(config)?;
        centers[..along.rows.len()].copy_from_slice(&along.rows);
        if let Some(w) = &along.widths2 {
            widths2.copy_from_slice(w);
        }
        *written = samples.len();
        Ok(())
    })
}
