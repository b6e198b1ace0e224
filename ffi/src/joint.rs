//! The joint-space controller: its handle, its states (on the heap or in a
//! caller buffer), the step, snapshots.

use crate::handles::{free, handle, handle_mut, publish, publish_at, release, Header};
use crate::*;
use adaptimp::{
    AnyBasis, Centers, Command, Controller, Grid, Measurement, Setpoint, Sinusoid, State,
    Trajectory, Vector,
};
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

/// One controller of N joints with the trajectory it tracks by default.
#[derive(Debug)]
pub(crate) struct Ctl<const N: usize> {
    pub(crate) ctrl: Controller<N, AnyBasis<N>>,
    pub(crate) traj: Sinusoid<N>,
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
    inner: Inner,
}
handle_kind!(AdaptimpController => ControllerObject, b"adp-CTRL");

/// The buffer of a state: the heap's, or the caller's.
#[derive(Debug)]
pub(crate) enum Buf {
    Heap(Vec<f64>),
    Caller(&'static mut [f64]),
}

impl AsRef<[f64]> for Buf {
    fn as_ref(&self) -> &[f64] {
        match self {
            Buf::Heap(v) => v,
            Buf::Caller(s) => s,
        }
    }
}

impl AsMut<[f64]> for Buf {
    fn as_mut(&mut self) -> &mut [f64] {
        match self {
            Buf::Heap(v) => v,
            Buf::Caller(s) => s,
        }
    }
}

/// A state of N joints over either buffer.
pub(crate) type St<const N: usize> = State<N, Buf>;

/// Where a state's memory is.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub(crate) enum Place {
    /// A `Box` of this library's: freed by `adaptimp_state_free`.
    Heap,
    /// The caller's buffer: `adaptimp_state_free` only ends its life.
    Caller,
}

/// A controller's state (opaque: a handle): on the heap
/// ([`adaptimp_state_new`]) or in a buffer of the caller's
/// ([`adaptimp_state_init`]).
pub struct AdaptimpState {
    _opaque: [u8; 0],
}

/// The object behind an [`AdaptimpState`] handle.
#[repr(C)]
#[derive(Debug)]
pub(crate) struct StateObject {
    head: Header,
    place: Place,
    states: States,
}
handle_kind!(AdaptimpState => StateObject, b"adpSTATE");

macro_rules! sized {
    ($($v:ident => $n:literal),+) => {
        #[derive(Debug)]
        pub(crate) enum Inner { $($v(Box<Ctl<$n>>)),+ }
        // By value: a state lives in one block, the heap's or the caller's.
        #[allow(clippy::large_enum_variant)]
        #[derive(Debug)]
        pub(crate) enum States { $($v(St<$n>)),+ }
        /// `$body` with `$c` the controller of its size, typed.
        macro_rules! with_ctl {
            ($e:expr, $c:ident => $body:expr) => {
                match $e { $(Inner::$v($c) => $body),+ }
            };
        }
        /// `$body` with `$c`, `$s` a controller and a state of one size, or WrongState.
        macro_rules! with_pair {
            ($ce:expr, $se:expr, $c:ident, $s:ident => $body:expr) => {
                match ($ce, $se) {
                    $((Inner::$v($c), States::$v($s)) => $body,)+
                    #[allow(unreachable_patterns)]
                    _ => Err(fail(AdaptimpStatus::WrongState, &"the state was made for a controller with another number of joints")),
                }
            };
        }
        /// `$body` with `$s` the state of its size.
        macro_rules! with_state {
            ($e:expr, $s:ident => $body:expr) => {
                match $e { $(States::$v($s) => $body),+ }
            };
        }
        pub(crate) fn build(p: &AdaptimpParams) -> Result<Inner, AdaptimpStatus> {
            match p.n {
                $($n => Ok(Inner::$v(Box::new(build_sized::<$n>(p)?))),)+
                n => Err(bad_n(n)),
            }
        }
        $(impl IntoStates for St<$n> {
            fn into_states(self) -> States {
                States::$v(self)
            }
        })+
    };
}

/// A state of one size as the enum.
pub(crate) trait IntoStates {
    fn into_states(self) -> States;
}

adaptimp::joint_counts!(sized);

pub(crate) fn build_sized<const N: usize>(p: &AdaptimpParams) -> Result<Ctl<N>, AdaptimpStatus> {
    let s = scenario_of::<N>(p)?;
    let config = |e| core_error(e, Context::Config);
    let basis = if p.centers.is_null() {
        AnyBasis::Grid(Grid::new(s.eta2).map_err(config)?)
    } else {
        let len = p
            .nodes
            .checked_mul(4 * N)
            .ok_or_else(|| fail(AdaptimpStatus::BadSize, &"params.nodes × 4n overflows"))?;
        // SAFETY (in `slice`): the caller gives `nodes` rows of 4n reals.
        let c = unsafe { slice(p.centers, len, "params.centers") }?.to_vec();
        let widths2 = if p.widths2.is_null() {
            [Vector::<N>::from_element(s.eta2); 4]
        } else {
            // SAFETY (in `slice`): the caller gives 4n reals.
            let w = unsafe { slice(p.widths2, 4 * N, "params.widths2") }?;
            core::array::from_fn(|b| Vector::<N>::from_column_slice(&w[b * N..(b + 1) * N]))
        };
        AnyBasis::Centers(Centers::new(c, widths2).map_err(config)?)
    };
    let traj = s.trajectory().map_err(config)?;
    let ctrl = Controller::for_trajectory(s.config, basis, &traj).map_err(config)?;
    Ok(Ctl { ctrl, traj })
}

fn joints_of<const N: usize>(_: &Ctl<N>) -> usize {
    N
}

/// The size of a state's header in a caller buffer, in bytes: its buffer of
/// reals follows, aligned for them.
const STATE_HEADER: usize = std::mem::size_of::<StateObject>().next_multiple_of(8);
/// The alignment a caller buffer for a state needs.
const STATE_ALIGN: usize = if std::mem::align_of::<StateObject>() > 8 {
    std::mem::align_of::<StateObject>()
} else {
    8
};

/// The bytes of a caller buffer for a state of `c`.
fn state_bytes<const N: usize>(c: &Ctl<N>) -> Result<usize, AdaptimpStatus> {
    c.ctrl
        .buffer_len()
        .checked_mul(8)
        .and_then(|b| b.checked_add(STATE_HEADER))
        .ok_or_else(|| fail(AdaptimpStatus::BadSize, &"the state's size overflows"))
}

/// A new state of `c` over `buf`, as the enum.
fn state_over<const N: usize>(c: &Ctl<N>, buf: Buf) -> Result<States, AdaptimpStatus>
where
    St<N>: IntoStates,
{
    c.ctrl
        .state_in(buf)
        .map(IntoStates::into_states)
        .map_err(|e| core_error(e, Context::Config))
}

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
        let inner = build(p)?;
        *out = publish(Box::new(ControllerObject {
            head: Header::unpublished(),
            inner,
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
        Ok(c) => with_ctl!(&c.inner, c => joints_of(c)),
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
        Ok(c) => with_ctl!(&c.inner, c => c.ctrl.period()),
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
        let states =
            with_ctl!(&c.inner, c => state_over(c, Buf::Heap(vec![0.0; c.ctrl.buffer_len()])))?;
        *out = publish(Box::new(StateObject {
            head: Header::unpublished(),
            place: Place::Heap,
            states,
        }))?;
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
        *size = with_ctl!(&c.inner, c => state_bytes(c))?;
        *align = STATE_ALIGN;
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
        if buf.is_null() {
            return Err(null("buf"));
        }
        let need = with_ctl!(&c.inner, c => state_bytes(c))?;
        if size < need || !(buf as usize).is_multiple_of(STATE_ALIGN) {
            return Err(fail(
                AdaptimpStatus::BadSize,
                &format_args!(
                    "buf: {size} bytes at an address {} a multiple of {STATE_ALIGN}; a state of this controller needs {need} bytes aligned to {STATE_ALIGN} (adaptimp_state_buffer_size)",
                    if (buf as usize).is_multiple_of(STATE_ALIGN) { "that is" } else { "that is not" }
                ),
            ));
        }
        let reals = (need - STATE_HEADER) / 8;
        // SAFETY: `buf` holds `size` ≥ STATE_HEADER + 8·reals writable bytes,
        // aligned to 8 (the caller's contract, checked above): the reals after
        // the header are zeroed (so initialised) before a slice is made, and
        // the header is written once with `write`. The slice and the header do
        // not overlap; 'static is the caller's promise that the buffer
        // outlives the state.
        unsafe {
            let data = buf.cast::<u8>().add(STATE_HEADER).cast::<f64>();
            std::ptr::write_bytes(data, 0, reals);
            let data: &'static mut [f64] = std::slice::from_raw_parts_mut(data, reals);
            let states = with_ctl!(&c.inner, c => state_over(c, Buf::Caller(data)))?;
            let p = buf.cast::<StateObject>();
            p.write(StateObject {
                head: Header::unpublished(),
                place: Place::Caller,
                states,
            });
            match publish_at::<AdaptimpState>(p) {
                Ok(h) => *out = h,
                Err(status) => {
                    p.drop_in_place();
                    return Err(status);
                }
            }
        }
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
    let Some(o) = release(state, "state") else {
        return;
    };
    // SAFETY: a live object until `release`, now unreachable by its handle:
    // a heap one came from `publish` (Box::into_raw); one in a caller's
    // buffer is dropped in place (it owns no other memory) and the buffer is
    // the caller's again.
    unsafe {
        if (*o).place == Place::Heap {
            drop(Box::from_raw(o));
        } else {
            o.drop_in_place();
        }
    }
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
        with_state!(&mut s.states, s => s.reset());
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
    // SAFETY (in `handle`): checked for NULL and for a live handle.
    let Ok(s) = (unsafe { handle(state, "state") }) else {
        return false;
    };
    fault_of(with_state!(&s.states, s => s.fault()), step)
}

/// Whether there is a fault, its step written to `step` if not NULL.
pub(crate) fn fault_of(fault: Option<adaptimp::Fault>, step: *mut u64) -> bool {
    match fault {
        Some(f) => {
            if !step.is_null() {
                // SAFETY: non-NULL; the caller's contract.
                unsafe { *step = f.step };
            }
            true
        }
        None => false,
    }
}

/// Clear the recorded fault: the documented recovery after a latched fault
/// (the next step's torque climbs from the fallback at the rate limit).
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_clear_fault(state: *mut AdaptimpState) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `handle_mut`): checked for NULL and for a live handle.
        let s = unsafe { handle_mut(state, "state") }?;
        with_state!(&mut s.states, s => s.clear_fault());
        Ok(())
    })
}

/// Steps taken since creation or reset, or 0 for NULL or a dead handle.
///
/// # Safety
/// `state` is NULL or valid.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_state_steps(state: *const AdaptimpState) -> u64 {
    // SAFETY (in `handle`): checked for NULL and for a live handle.
    match unsafe { handle(state, "state") } {
        Ok(s) => with_state!(&s.states, s => s.steps()),
        Err(_) => 0,
    }
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
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let s = unsafe { handle(state, "state") }?;
        let tau = unsafe { slice_mut(tau, n, "tau") }?;
        with_state!(&s.states, s => copy_sized(s.applied().as_slice(), tau, "tau"))
    })
}

/// `src` into `dst` if their lengths match, else BadSize naming `what`.
pub(crate) fn copy_sized(src: &[f64], dst: &mut [f64], what: &str) -> Result<(), AdaptimpStatus> {
    if src.len() != dst.len() {
        return Err(fail(
            AdaptimpStatus::BadSize,
            &format_args!(
                "{what}: n = {}, but the state has {} joints",
                dst.len(),
                src.len()
            ),
        ));
    }
    dst.copy_from_slice(src);
    Ok(())
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
        Ok(s) => with_state!(&s.states, s => s.snapshot_len()),
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
        let n = with_state!(&s.states, s => s.save(buf))
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
        with_pair!(&c.inner, &mut s.states, c, s => c
            .ctrl
            .restore(s, buf)
            .map_err(|e| core_error(e, Context::Restore)))
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
    let status = guard(|| {
        // SAFETY (in the helpers): each pointer checked for NULL; the caller's contract.
        let mut cmd = unsafe { out.as_mut() };
        if let Some(o) = cmd.as_deref_mut() {
            *o = AdaptimpCommand::ZERO;
        }
        let c = unsafe { handle(ctrl, "ctrl") }?;
        let s = unsafe { handle_mut(state, "state") }?;
        let args = StepArgs {
            n,
            q,
            dq,
            tau_e,
            setpoint,
        };
        with_pair!(&c.inner, &mut s.states, c, s => step_sized(c, s, &args, cmd))
    });
    if status == AdaptimpStatus::Internal && !out.is_null() {
        // SAFETY: non-NULL; the caller's contract.
        unsafe { *out = AdaptimpCommand::ZERO };
    }
    status
}

/// A step's pointers, as the caller gave them.
struct StepArgs {
    n: usize,
    q: *const f64,
    dq: *const f64,
    tau_e: *const f64,
    setpoint: *const AdaptimpSetpoint,
}

/// The fallback of a step the front refused (`status` already recorded as
/// the last error): the refusal recorded in the state as the core records
/// one, the fallback written.
fn refused<const N: usize>(
    c: &Ctl<N>,
    s: &mut St<N>,
    out: Option<&mut AdaptimpCommand>,
    status: AdaptimpStatus,
) -> AdaptimpStatus {
    let tau = c.ctrl.refuse(s, BAD_ARGUMENTS);
    if let Some(out) = out {
        write_fallback(&tau, out);
    }
    status
}

fn step_sized<const N: usize>(
    c: &Ctl<N>,
    s: &mut St<N>,
    a: &StepArgs,
    out: Option<&mut AdaptimpCommand>,
) -> Result<(), AdaptimpStatus> {
    if a.n != N {
        let e = fail(
            AdaptimpStatus::BadSize,
            &format_args!("n = {}, but the controller has {N} joints", a.n),
        );
        return Err(refused(c, s, out, e));
    }
    let Some(out) = out else {
        return Err(refused(c, s, None, null("out")));
    };
    // SAFETY (in `slice`, `read`): checked for NULL; the caller's contract.
    let inputs = (|| {
        let q = unsafe { slice(a.q, N, "q") }?;
        let tau_e = unsafe { slice(a.tau_e, N, "tau_e") }?;
        let dq = if a.dq.is_null() {
            None
        } else {
            Some(unsafe { slice(a.dq, N, "dq") }?)
        };
        let sp = if a.setpoint.is_null() {
            None
        } else {
            Some(unsafe { read(a.setpoint, "setpoint") }?)
        };
        Ok((q, tau_e, dq, sp))
    })();
    let (q, tau_e, dq, sp) = match inputs {
        Ok(v) => v,
        Err(status) => return Err(refused(c, s, Some(out), status)),
    };
    let m = Measurement {
        x: Vector::<N>::from_column_slice(q),
        dx: dq.map(Vector::<N>::from_column_slice),
        tau_e: Vector::<N>::from_column_slice(tau_e),
    };
    let setpoint = match sp {
        Some(sp) => Setpoint {
            x: Vector::<N>::from_column_slice(&sp.x[..N]),
            dx: Vector::<N>::from_column_slice(&sp.dx[..N]),
            ddx: Vector::<N>::from_column_slice(&sp.ddx[..N]),
        },
        None => c.traj.sample(c.ctrl.time(s)),
    };
    match c.ctrl.step_or_fallback(s, &m, &setpoint) {
        (_, Ok(cmd)) => {
            write_command(&cmd, out);
            Ok(())
        }
        (fallback, Err(e)) => {
            write_fallback(&fallback, out);
            Err(core_error(e, Context::Step))
        }
    }
}

/// A refused step's output: the fallback to apply, n, every other field zero.
pub(crate) fn write_fallback<const N: usize>(tau: &Vector<N>, out: &mut AdaptimpCommand) {
    let mut cmd = Command::<N>::zeros();
    cmd.tau_sat = *tau;
    write_command(&cmd, out);
}

pub(crate) fn write_command<const N: usize>(cmd: &Command<N>, out: &mut AdaptimpCommand) {
    out.n = N;
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
        dst[..N].copy_from_slice(src.as_slice());
    }
    out.w_norms = cmd.w_norms;
}
