//! What the joint and the Cartesian entry points share: a step's frame (its
//! output written on every status, the front's refusals recorded as the
//! core records one) and the joint state's accessors, for any handle that
//! holds a joint state.

use crate::handles::{handle, handle_mut, Handle};
use crate::*;
use adaptimp::dynamic::{Controller, Joints, State};
use handles::Buf;

/// A step's output struct: all zero (no controller answered, n = 0), or a
/// refused step's fallback.
pub(crate) trait Output {
    /// Every field zero, n = 0.
    fn zero() -> Self;
    /// The fallback `tau` to apply, n = its length (the rest zero).
    fn fallback(tau: &[f64]) -> Self;
}

/// A refused step's output: the fallback (none: no controller answered).
pub(crate) fn write_fallback<O: Output>(tau: Option<&[f64]>, out: &mut O) {
    *out = tau.map_or_else(O::zero, O::fallback);
}

/// A step entry point: `*out` (if not NULL) zeroed before `f` runs and
/// after a panic in it (INTERNAL: no controller answered).
///
/// # Safety
/// `out` is NULL or valid.
pub(crate) unsafe fn step_entry<O: Output>(
    out: *mut O,
    f: impl FnOnce(Option<&mut O>) -> Result<(), AdaptimpStatus>,
) -> AdaptimpStatus {
    let status = guard(|| {
        // SAFETY: NULL or valid (the caller's contract).
        let mut cmd = unsafe { out.as_mut() };
        if let Some(o) = cmd.as_deref_mut() {
            *o = O::zero();
        }
        f(cmd)
    });
    if status == AdaptimpStatus::Internal && !out.is_null() {
        // SAFETY: non-NULL; the caller's contract.
        unsafe { *out = O::zero() };
    }
    status
}

/// The step of joint controller `c` (of the `what` the caller steps) with
/// its state `s` once the front's checks pass: the caller's `n`, `out`, and
/// its inputs (`inputs`, given n). A refusal here is recorded in `s` as the
/// core records one and `out` gets the fallback; else `step` runs with the
/// inputs.
pub(crate) fn front_step<O: Output, I>(
    c: &Controller,
    s: &mut State<Buf>,
    n: usize,
    what: &str,
    out: Option<&mut O>,
    inputs: impl FnOnce(usize) -> Result<I, AdaptimpStatus>,
    step: impl FnOnce(I, &mut State<Buf>, &mut O) -> Result<(), AdaptimpStatus>,
) -> Result<(), AdaptimpStatus> {
    let refused = |s: &mut State<Buf>, out: Option<&mut O>, status| {
        let tau = c.refuse(s, BAD_ARGUMENTS);
        if let Some(out) = out {
            write_fallback(tau.as_deref(), out);
        }
        status
    };
    if let Err(status) = check_n(n, c.n(), what) {
        return Err(refused(s, out, status));
    }
    let Some(out) = out else {
        return Err(refused(s, None, null("out")));
    };
    match inputs(c.n()) {
        Ok(i) => step(i, s, out),
        Err(status) => Err(refused(s, Some(out), status)),
    }
}

/// The core's answer to a step: the command written (`write`), or the
/// fallback and the error's status.
pub(crate) fn answer<C, O: Output>(
    (fallback, result): (Option<Joints>, Result<C, adaptimp::Error>),
    out: &mut O,
    write: fn(&C, &mut O),
) -> Result<(), AdaptimpStatus> {
    match result {
        Ok(cmd) => {
            write(&cmd, out);
            Ok(())
        }
        Err(e) => {
            write_fallback(fallback.as_deref(), out);
            Err(core_error(e, Context::Step))
        }
    }
}

/// A handle whose object holds a joint controller's state.
pub(crate) trait HoldsJoint: Handle {
    /// The joint state.
    fn joint(o: &Self::Object) -> &State<Buf>;
    /// The joint state, to change.
    fn joint_mut(o: &mut Self::Object) -> &mut State<Buf>;
}

/// Whether there is a fault, its step written to `step` if not NULL.
fn fault_of(fault: Option<adaptimp::Fault>, step: *mut u64) -> bool {
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

/// `adaptimp_*state_fault`: false for NULL or a dead handle.
///
/// # Safety
/// `state` is NULL or valid; `step` is NULL or valid.
pub(crate) unsafe fn state_fault<H: HoldsJoint>(state: *const H, step: *mut u64) -> bool {
    // SAFETY (in `handle`): checked for NULL and for a live handle.
    match unsafe { handle(state, "state") } {
        Ok(s) => fault_of(H::joint(s).fault(), step),
        Err(_) => false,
    }
}

/// `adaptimp_*state_clear_fault`.
///
/// # Safety
/// `state` is NULL or valid.
pub(crate) unsafe fn state_clear_fault<H: HoldsJoint>(state: *mut H) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `handle_mut`): checked for NULL and for a live handle.
        let s = unsafe { handle_mut(state, "state") }?;
        H::joint_mut(s).clear_fault();
        Ok(())
    })
}

/// `adaptimp_*state_steps`: 0 for NULL or a dead handle.
///
/// # Safety
/// `state` is NULL or valid.
pub(crate) unsafe fn state_steps<H: HoldsJoint>(state: *const H) -> u64 {
    // SAFETY (in `handle`): checked for NULL and for a live handle.
    match unsafe { handle(state, "state") } {
        Ok(s) => H::joint(s).steps(),
        Err(_) => 0,
    }
}

/// `adaptimp_*state_applied`: the torque to apply now into `tau` (`n`
/// reals, the state's number of joints, else BAD_SIZE).
///
/// # Safety
/// `state` is NULL or valid; `tau` is NULL or holds `n` reals.
pub(crate) unsafe fn state_applied<H: HoldsJoint>(
    state: *const H,
    n: usize,
    tau: *mut f64,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in the helpers): checked for NULL; the caller's contract.
        let s = unsafe { handle(state, "state") }?;
        let tau = unsafe { slice_mut(tau, n, "tau") }?;
        let src = H::joint(s).applied();
        if src.len() != tau.len() {
            return Err(fail(
                AdaptimpStatus::BadSize,
                &format_args!("tau: n = {n}, but the state has {} joints", src.len()),
            ));
        }
        tau.copy_from_slice(&src);
        Ok(())
    })
}
