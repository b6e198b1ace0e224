//! The Cartesian controller and its state (on the heap or in a caller's
//! buffer): built over a chain and a joint controller, stepped, restarted,
//! its posture and stiffness changed.

use super::*;

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
pub(super) unsafe fn cstate_over(
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
    // SAFETY: the caller's contract.
    unsafe { shared::state_fault(state, step) }
}

/// Clear the recorded fault (as [`adaptimp_state_clear_fault`]).
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_clear_fault(
    state: *mut AdaptimpCartesianState,
) -> AdaptimpStatus {
    // SAFETY: the caller's contract.
    unsafe { shared::state_clear_fault(state) }
}

/// Steps taken since creation or reset, or 0 for NULL or a dead handle.
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_cartesian_state_steps(
    state: *const AdaptimpCartesianState,
) -> u64 {
    // SAFETY: the caller's contract.
    unsafe { shared::state_steps(state) }
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
    // SAFETY: the caller's contract.
    unsafe { shared::state_applied(state, n, tau) }
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
    // SAFETY (in the helpers): each pointer checked for NULL; the caller's contract.
    unsafe {
        step_entry(out, |cmd| {
            let c = handle(cart, "cart")?;
            let s = handle_mut(state, "state")?;
            same_joints(c.pair.joint().n(), s.joint.n(), "Cartesian controller")?;
            let inputs = |n| {
                let q = slice(q, n, "q")?;
                let wrench = slice(wrench, 6, "wrench")?;
                let dq = if dq.is_null() {
                    None
                } else {
                    Some(slice(dq, n, "dq")?)
                };
                let target = if target.is_null() {
                    None
                } else {
                    Some(read(target, "target")?)
                };
                let wrench = Vector::<6>::from_column_slice(wrench);
                Ok((
                    CartesianMeasurement { q, dq, wrench },
                    target.map(pose_target),
                ))
            };
            let CartesianStateObject { outer, joint, .. } = s;
            let what = "Cartesian controller";
            front_step(
                c.pair.joint(),
                joint,
                n,
                what,
                cmd,
                inputs,
                |(m, t), joint, out| {
                    let answered = c.pair.step_or_fallback(outer, joint, &m, t.as_ref());
                    answer(answered, out, write_cartesian)
                },
            )
        })
    }
}

impl Output for AdaptimpCartesianCommand {
    fn zero() -> Self {
        Self::ZERO
    }
    fn fallback(tau: &[f64]) -> Self {
        Self {
            n: tau.len(),
            tau_sat: joints7(tau),
            ..Self::ZERO
        }
    }
}

impl HoldsJoint for AdaptimpCartesianState {
    fn joint(o: &CartesianStateObject) -> &State<Buf> {
        &o.joint
    }
    fn joint_mut(o: &mut CartesianStateObject) -> &mut State<Buf> {
        &mut o.joint
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
