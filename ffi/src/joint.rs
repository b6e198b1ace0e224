//! The joint-space controller: its handle, its states (on the heap or in a
//! caller buffer), the step, snapshots.

use crate::handles::{buffer_size, free, handle, handle_mut, publish, publish_in, Buf, Header};
use crate::shared::{self, answer, front_step, step_entry, HoldsJoint, Output};
use crate::*;
use adaptimp::dynamic::{Command, Controller, Measurement, Setpoint, State};
use core::ffi::c_void;

/// A commanded setpoint at t_k: position (rad), velocity (rad/s) and
/// acceleration (rad/s²); the first n entries are read.
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpSetpoint {
    /// xc (rad).
    pub x: [f64; ADAPTIMP_MAX_JOINTS],
    /// ẋc (rad/s).
    pub dx: [f64; ADAPTIMP_MAX_JOINTS],
    /// ẍc (rad/s²).
    pub ddx: [f64; ADAPTIMP_MAX_JOINTS],
}

/// What one step computed; the first `n` entries of each array are set, the
/// others zero. Written on every status (see [`adaptimp_step`]): `tau_sat`
/// is what goes to the actuators.
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpCommand {
    /// Number of joints; 0 when no controller could be asked (then every
    /// field is zero).
    pub n: usize,
    /// The torque to apply (N m): sat(τ) of an accepted step, the configured
    /// fallback of a refused one.
    pub tau_sat: [f64; ADAPTIMP_MAX_JOINTS],
    /// Commanded torque τ (N m).
    pub tau: [f64; ADAPTIMP_MAX_JOINTS],
    /// Δτ = sat(τ) − τ (N m).
    pub dtau: [f64; ADAPTIMP_MAX_JOINTS],
    /// z1 = xd − x (rad).
    pub z1: [f64; ADAPTIMP_MAX_JOINTS],
    /// z2 (rad/s).
    pub z2: [f64; ADAPTIMP_MAX_JOINTS],
    /// xc (rad).
    pub xc: [f64; ADAPTIMP_MAX_JOINTS],
    /// xd (rad).
    pub xd: [f64; ADAPTIMP_MAX_JOINTS],
    /// The velocity used (rad/s): measured, or the observer's estimate.
    pub v: [f64; ADAPTIMP_MAX_JOINTS],
    /// ζ (N m).
    pub zeta: [f64; ADAPTIMP_MAX_JOINTS],
    /// ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ before the step's update.
    pub w_norms: [f64; 3],
}

impl AdaptimpCommand {
    /// Every field zero (n = 0): no controller answered.
    pub const ZERO: Self = Self {
        n: 0,
        tau_sat: [0.0; ADAPTIMP_MAX_JOINTS],
        tau: [0.0; ADAPTIMP_MAX_JOINTS],
        dtau: [0.0; ADAPTIMP_MAX_JOINTS],
        z1: [0.0; ADAPTIMP_MAX_JOINTS],
        z2: [0.0; ADAPTIMP_MAX_JOINTS],
        xc: [0.0; ADAPTIMP_MAX_JOINTS],
        xd: [0.0; ADAPTIMP_MAX_JOINTS],
        v: [0.0; ADAPTIMP_MAX_JOINTS],
        zeta: [0.0; ADAPTIMP_MAX_JOINTS],
        w_norms: [0.0; 3],
    };
}

/// A validated controller description (opaque: a handle, see
/// `ADAPTIMP_MAX_HANDLES`).
pub struct AdaptimpController {
    _opaque: [u8; 0],
}

/// The object behind an [`AdaptimpController`] handle.
#[repr(C)]
#[derive(Debug)]
pub(crate) struct ControllerObject {
    head: Header,
    ctrl: Controller,
}
handle_kind!(AdaptimpController => ControllerObject, b"adp-CTRL");

/// A controller's state (opaque: a handle): on the heap
/// ([`adaptimp_state_new`]) or in a buffer of the caller's
/// ([`adaptimp_state_init`]).
pub struct AdaptimpState {
    _opaque: [u8; 0],
}

/// The object behind an [`AdaptimpState`] handle: the state by value (in
/// one block, the heap's or the caller's), its reals in `Buf`.
#[repr(C)]
#[derive(Debug)]
pub(crate) struct StateObject {
    head: Header,
    state: State<Buf>,
}
handle_kind!(AdaptimpState => StateObject, b"adpSTATE");

// ---------------------------------------------------------------------------
// The API.
// ---------------------------------------------------------------------------

/// Validate `params` (SPEC §10 and every other condition) and build a
/// controller into `*out` (free it with [`adaptimp_controller_free`]). On an
/// error `*out` is left unchanged: INVALID_CONFIG (a condition, a NaN, an
/// enum value), BAD_SIZE (n), NULL_POINTER.
///
/// # Safety
/// `params` and `out` are NULL or valid; `params.centers` and
/// `params.widths2` are NULL or hold `nodes × 4n` and `4n` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_controller_new(
    params: *const AdaptimpParams,
    out: *mut *mut AdaptimpController,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `read`, `out`): checked for NULL; the caller's contract.
        let p = unsafe { read(params, "params") }?;
        let out = unsafe { crate::out(out, "out") }?;
        // SAFETY (in `controller_of`): `params`' pointers are the caller's.
        let ctrl = unsafe { controller_of(p) }?;
        *out = publish(Box::new(ControllerObject {
            head: Header::unpublished(),
            ctrl,
        }))?;
        Ok(())
    })
}

/// The controller of `preset` for the paper's 2-link arm (the 256-node grid,
/// the paper's circle as the default trajectory). A `preset` or `law` that
/// is not a value of its enum (the two swapped, say) is refused
/// (INVALID_CONFIG).
///
/// # Safety
/// `out` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_controller_new_preset(
    preset: AdaptimpPresetRaw,
    law: AdaptimpLawRaw,
    out: *mut *mut AdaptimpController,
) -> AdaptimpStatus {
    let mut p = std::mem::MaybeUninit::<AdaptimpParams>::uninit();
    // SAFETY: `p` is a valid place for the defaults to be written to.
    let status = unsafe { adaptimp_params_default(p.as_mut_ptr(), 2, law, preset) };
    if status != AdaptimpStatus::Ok {
        return status;
    }
    // SAFETY: `adaptimp_params_default` returned Ok, so it wrote `p` whole.
    let p = unsafe { p.assume_init() };
    // SAFETY: `p` is valid; `out` is the caller's.
    unsafe { adaptimp_controller_new(&p, out) }
}

/// Free a controller (NULL is ignored, and so is a handle that is not a
/// live controller: freeing twice does nothing the second time). Free its
/// states first: a state does not keep its controller alive.
///
/// # Safety
/// `ctrl` is NULL or came from `adaptimp_controller_new*`.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_controller_free(ctrl: *mut AdaptimpController) {
    // SAFETY: the caller's contract.
    unsafe { free(ctrl, "ctrl") }
}

/// The controller's number of joints, or 0 for NULL or a dead handle.
///
/// # Safety
/// `ctrl` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_controller_joints(ctrl: *const AdaptimpController) -> usize {
    // SAFETY (in `handle`): checked for NULL and for a live handle.
    match unsafe { handle(ctrl, "ctrl") } {
        Ok(c) => c.ctrl.n(),
        Err(_) => 0,
    }
}

/// The controller's sampling period Ts (s), or NaN for NULL or a dead handle.
///
/// # Safety
/// `ctrl` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_controller_period(ctrl: *const AdaptimpController) -> f64 {
    // SAFETY (in `handle`): checked for NULL and for a live handle.
    match unsafe { handle(ctrl, "ctrl") } {
        Ok(c) => c.ctrl.period(),
        Err(_) => f64::NAN,
    }
}

/// A state at t = 0 for `ctrl` into `*out`, on the heap (free it with
/// [`adaptimp_state_free`]). This allocates; the step does not. For a state
/// in memory of your own (firmware), see [`adaptimp_state_init`].
///
/// # Safety
/// `ctrl` and `out` are NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_new(
    ctrl: *const AdaptimpController,
    out: *mut *mut AdaptimpState,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `handle`, `out`): checked for NULL; the caller's contract.
        let c = unsafe { handle(ctrl, "ctrl") }?;
        let out = unsafe { crate::out(out, "out") }?;
        let buf = Buf::Heap(vec![0.0; c.ctrl.buffer_len()]);
        *out = publish(Box::new(state_over(&c.ctrl, buf)?))?;
        Ok(())
    })
}

/// The size (bytes) and alignment a caller buffer for a state of `ctrl`
/// needs ([`adaptimp_state_init`]): fixed for a controller and a build of
/// the library.
///
/// # Safety
/// `ctrl` is NULL or valid; `size` and `align` are NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_buffer_size(
    ctrl: *const AdaptimpController,
    size: *mut usize,
    align: *mut usize,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let c = unsafe { handle(ctrl, "ctrl") }?;
        let size = unsafe { out(size, "size") }?;
        let align = unsafe { out(align, "align") }?;
        (*size, *align) = buffer_size::<AdaptimpState>(c.ctrl.buffer_len())?;
        Ok(())
    })
}

/// A state at t = 0 for `ctrl` in the caller's buffer `buf` of `size` bytes
/// (at least what [`adaptimp_state_buffer_size`] says, aligned as it says),
/// no allocation: for firmware without a heap, or to place the state
/// yourself. `*out` gets the handle (a number, as every handle: not the
/// buffer's address); use it as any state. The buffer must stay where it is
/// and must not be used otherwise while the state lives (a state cannot be
/// moved or copied bytewise: save and restore it); [`adaptimp_state_free`]
/// ends its life and gives the buffer back (it frees nothing). BAD_SIZE
/// for a buffer too small or misaligned.
///
/// # Safety
/// `ctrl` and `out` are NULL or valid; `buf` is NULL or `size` writable
/// bytes that nothing else uses while the state lives.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_init(
    ctrl: *const AdaptimpController,
    buf: *mut c_void,
    size: usize,
    out: *mut *mut AdaptimpState,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `handle`, `out`): checked for NULL; the caller's contract.
        let c = unsafe { handle(ctrl, "ctrl") }?;
        let out = unsafe { crate::out(out, "out") }?;
        // SAFETY (in `publish_in`): `buf` and `size` are the caller's.
        *out = unsafe {
            publish_in(
                buf,
                size,
                c.ctrl.buffer_len(),
                "adaptimp_state_buffer_size",
                |buf| state_over(&c.ctrl, buf),
            )
        }?;
        Ok(())
    })
}

/// Free a state (NULL is ignored, and so is a pointer that is not a live
/// state): a heap state's memory is freed; a state in a caller buffer
/// ([`adaptimp_state_init`]) ends its life and its buffer is the caller's
/// again. Using its handle after this is refused (BAD_HANDLE), even once
/// its memory holds a new state (which has a handle of its own).
///
/// # Safety
/// `state` is NULL or came from `adaptimp_state_new` or `adaptimp_state_init`.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_free(state: *mut AdaptimpState) {
    // SAFETY: the caller's contract.
    unsafe { free(state, "state") }
}

/// Back to t = 0: weights, ζ, observer, reference and applied torque as at
/// creation, the fault cleared.
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_reset(state: *mut AdaptimpState) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `handle_mut`): checked for NULL and for a live handle.
        let s = unsafe { handle_mut(state, "state") }?;
        s.state.reset();
        Ok(())
    })
}

/// True if a refused step recorded a fault (with fault policy "latch", steps
/// are refused until it is cleared); `*step` (if not NULL) gets the step at
/// which it happened. False for NULL or a dead handle.
///
/// # Safety
/// `state` is NULL or valid; `step` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_fault(state: *const AdaptimpState, step: *mut u64) -> bool {
    // SAFETY: the caller's contract.
    unsafe { shared::state_fault(state, step) }
}

/// Clear the recorded fault: the documented recovery after a latched fault
/// (the next step's torque climbs from the fallback at the rate limit).
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_clear_fault(state: *mut AdaptimpState) -> AdaptimpStatus {
    // SAFETY: the caller's contract.
    unsafe { shared::state_clear_fault(state) }
}

/// Steps taken since creation or reset, or 0 for NULL or a dead handle.
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_steps(state: *const AdaptimpState) -> u64 {
    // SAFETY: the caller's contract.
    unsafe { shared::state_steps(state) }
}

/// The torque to apply now (N m) into `tau` (`n` reals, the state's number
/// of joints): the last accepted step's sat(τ), or the fallback of a refused
/// call after it (the origin of the next step's rate limit); zero after
/// creation and reset.
///
/// # Safety
/// `state` is NULL or valid; `tau` is NULL or holds `n` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_applied(
    state: *const AdaptimpState,
    n: usize,
    tau: *mut f64,
) -> AdaptimpStatus {
    // SAFETY: the caller's contract.
    unsafe { shared::state_applied(state, n, tau) }
}

/// The number of reals [`adaptimp_state_save`] writes for this state,
/// `12 + 18 n + L (2n² + n + 1)` (L the nodes), or 0 for NULL or a dead handle.
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_snapshot_len(state: *const AdaptimpState) -> usize {
    // SAFETY (in `handle`): checked for NULL and for a live handle.
    match unsafe { handle(state, "state") } {
        Ok(s) => s.state.snapshot_len(),
        Err(_) => 0,
    }
}

/// Save the whole state into the caller's buffer `buf` of `len` reals (at
/// least [`adaptimp_state_snapshot_len`]); `*written` (if not NULL) gets the
/// number written. No allocation. The format (3): a header, n, L, the step
/// count, the reference, ζ, the observer, the last accepted position, the
/// last command, the norms, the basis, the weights, the applied torque, the
/// last measured position and a checksum; a recorded fault is not part of
/// it.
///
/// # Safety
/// `state` is NULL or valid; `buf` is NULL or holds `len` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_save(
    state: *const AdaptimpState,
    buf: *mut f64,
    len: usize,
    written: *mut usize,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `handle`, `slice_mut`): checked for NULL; the caller's contract.
        let s = unsafe { handle(state, "state") }?;
        let buf = unsafe { slice_mut(buf, len, "buf") }?;
        let n = s
            .state
            .save(buf)
            .map_err(|e| fail(AdaptimpStatus::BadSize, &e))?;
        if !written.is_null() {
            // SAFETY: non-NULL; the caller's contract.
            unsafe { *written = n };
        }
        Ok(())
    })
}

/// Restore into `state` a snapshot of `len` reals written by
/// [`adaptimp_state_save`], checked as Rust's `Controller::restore` and
/// Python's `Controller.restore` check it: its format, sizes and checksum,
/// and that `ctrl`'s step could have left it (the reference and ζ within
/// their ceilings, the weights' norms as stored and within the projection
/// bounds, the applied and last torques within τmax). On an error the state
/// is unchanged: BAD_SNAPSHOT (the snapshot), WRONG_STATE (a state of
/// another controller). The recorded fault is cleared.
///
/// # Safety
/// `ctrl` and `state` are NULL or valid; `buf` is NULL or holds `len` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_restore(
    ctrl: *const AdaptimpController,
    state: *mut AdaptimpState,
    buf: *const f64,
    len: usize,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let c = unsafe { handle(ctrl, "ctrl") }?;
        let s = unsafe { handle_mut(state, "state") }?;
        let buf = unsafe { slice(buf, len, "buf") }?;
        same_joints(c.ctrl.n(), s.state.n(), "controller")?;
        c.ctrl
            .restore(&mut s.state, buf)
            .map_err(|e| core_error(e, Context::Restore))
    })
}

/// Take over the actuators from a controller that was applying `tau` (`n`
/// reals, N m) until now (a robot's own, holding the arm where it stands:
/// libfranka's `tau_J_d` read before the torque loop starts, with libfranka's
/// own `limitRate` off): the first step's torque rate limit moves from it,
/// so the first command continues it, as Rust's `Controller::take_over` and
/// Python's `Controller.take_over`.
/// Before the first step only. On an error the state is unchanged:
/// BAD_SIZE (`n`), INVALID_CONFIG (after the first step, a torque not finite
/// or beyond τmax, named), WRONG_STATE (a state of another controller).
///
/// # Safety
/// `ctrl` and `state` are NULL or valid; `tau` is NULL or holds `n` reals.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_take_over(
    ctrl: *const AdaptimpController,
    state: *mut AdaptimpState,
    tau: *const f64,
    n: usize,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let c = unsafe { handle(ctrl, "ctrl") }?;
        let s = unsafe { handle_mut(state, "state") }?;
        check_n(n, c.ctrl.n(), "controller")?;
        let tau = unsafe { slice(tau, n, "tau") }?;
        same_joints(c.ctrl.n(), s.state.n(), "controller")?;
        c.ctrl
            .take_over(&mut s.state, tau)
            .map_err(|e| core_error(e, Context::Config))
    })
}

/// One controller step at t_k = k·Ts. `q` (rad), `tau_e` (N m) and `dq`
/// (rad/s; required by PD and state feedback, may be NULL for output
/// feedback) hold `n` reals, the controller's number of joints. `setpoint` is
/// the commanded xc, ẋc, ẍc at t_k, or NULL for the controller's own
/// trajectory at t_k. No allocation.
///
/// `*out` is written on every status, and `out->tau_sat` is the torque to
/// apply (docs/reliability.md, "The fault semantics"):
///
/// | status | `out` | recorded in the state |
/// |---|---|---|
/// | OK | the command, `tau_sat` = sat(τ) | the step |
/// | refused by the controller: NON_FINITE, OUT_OF_RANGE, MISSING_VELOCITY, DIVERGED, FAULTED, INVALID_INPUT, WRONG_STATE (another basis) | `tau_sat` = the configured fallback, n set, the rest zero | the fault (a latched one kept), the fallback as applied torque |
/// | refused here, with a live controller and a state of its size: NULL_POINTER (`q`, `tau_e`, `out`), BAD_SIZE (`n`) | as above (nothing if `out` is NULL) | as above |
/// | no controller to ask: NULL_POINTER or BAD_HANDLE (`ctrl`, `state`), WRONG_STATE (a state of another size), INTERNAL | every field zero, n = 0 | nothing |
///
/// So a loop applies `out->tau_sat` after any status with `out->n` equal to
/// its joints; `out->n == 0` is a programming error (stop the arm by your
/// own means). The applied torque stays readable with
/// [`adaptimp_state_applied`].
///
/// # Safety
/// Each pointer is NULL or valid for `n` reals (`setpoint`, `out`: one struct).
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn adaptimp_step(
    ctrl: *const AdaptimpController,
    state: *mut AdaptimpState,
    n: usize,
    q: *const f64,
    dq: *const f64,
    tau_e: *const f64,
    setpoint: *const AdaptimpSetpoint,
    out: *mut AdaptimpCommand,
) -> AdaptimpStatus {
    // SAFETY (in the helpers): each pointer checked for NULL; the caller's contract.
    unsafe {
        step_entry(out, |cmd| {
            let c = handle(ctrl, "ctrl")?;
            let s = handle_mut(state, "state")?;
            same_joints(c.ctrl.n(), s.state.n(), "controller")?;
            let inputs = |n| {
                let q = slice(q, n, "q")?;
                let tau_e = slice(tau_e, n, "tau_e")?;
                let dq = if dq.is_null() {
                    None
                } else {
                    Some(slice(dq, n, "dq")?)
                };
                let sp = if setpoint.is_null() {
                    None
                } else {
                    Some(read(setpoint, "setpoint")?)
                };
                Ok((
                    Measurement {
                        x: q,
                        dx: dq,
                        tau_e,
                    },
                    sp,
                ))
            };
            front_step(
                &c.ctrl,
                &mut s.state,
                n,
                "controller",
                cmd,
                inputs,
                |(m, sp), s, out| {
                    let sp = sp.map(|sp| Setpoint {
                        x: &sp.x[..m.x.len()],
                        dx: &sp.dx[..m.x.len()],
                        ddx: &sp.ddx[..m.x.len()],
                    });
                    answer(
                        c.ctrl.step_or_fallback(s, &m, sp.as_ref()),
                        out,
                        write_command,
                    )
                },
            )
        })
    }
}

/// A state of `ctrl` over `buf`, at t = 0.
fn state_over(ctrl: &Controller, buf: Buf) -> Result<StateObject, AdaptimpStatus> {
    let state = ctrl
        .state_in(buf)
        .map_err(|e| core_error(e, Context::Config))?;
    Ok(StateObject {
        head: Header::unpublished(),
        state,
    })
}

impl Output for AdaptimpCommand {
    fn zero() -> Self {
        Self::ZERO
    }
    fn fallback(tau: &[f64]) -> Self {
        let mut out = Self::ZERO;
        out.n = tau.len();
        out.tau_sat[..tau.len()].copy_from_slice(tau);
        out
    }
}

impl HoldsJoint for AdaptimpState {
    fn joint(o: &StateObject) -> &State<Buf> {
        &o.state
    }
    fn joint_mut(o: &mut StateObject) -> &mut State<Buf> {
        &mut o.state
    }
}

/// An accepted step's output, n = the command's joints.
fn write_command(cmd: &Command, out: &mut AdaptimpCommand) {
    let n = cmd.tau_sat.len();
    out.n = n;
    for (dst, src) in [
        (&mut out.tau_sat, &cmd.tau_sat),
        (&mut out.tau, &cmd.tau),
        (&mut out.dtau, &cmd.dtau),
        (&mut out.z1, &cmd.z1),
        (&mut out.z2, &cmd.z2),
        (&mut out.xc, &cmd.xc),
        (&mut out.xd, &cmd.xd),
        (&mut out.v, &cmd.v),
        (&mut out.zeta, &cmd.zeta),
    ] {
        dst.fill(0.0);
        dst[..n].copy_from_slice(src);
    }
    out.w_norms = cmd.w_norms;
}
