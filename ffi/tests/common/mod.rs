//! Helpers of the ABI's tests: the last error, defaults, owned handles.
#![allow(dead_code)] // each test binary uses some of them

use adaptimp_ffi::*;
use std::ffi::CStr;
use std::ptr;

pub fn last_error() -> String {
    // SAFETY: the library returns a NUL-terminated thread-local buffer.
    unsafe { CStr::from_ptr(adaptimp_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// The defaults of `preset` for `law` and n joints.
pub fn defaults(n: usize, law: AdaptimpLaw, preset: AdaptimpPreset) -> AdaptimpParams {
    let mut p = std::mem::MaybeUninit::uninit();
    // SAFETY: a valid place; Ok means it was written whole.
    unsafe {
        assert_eq!(
            adaptimp_params_default(p.as_mut_ptr(), n, law.into(), preset.into()),
            AdaptimpStatus::Ok
        );
        p.assume_init()
    }
}

/// A controller and a heap state, freed on drop.
pub struct Handles {
    pub ctrl: *mut AdaptimpController,
    pub state: *mut AdaptimpState,
}

impl Handles {
    pub fn new(params: &AdaptimpParams) -> Result<Self, (AdaptimpStatus, String)> {
        let mut ctrl = ptr::null_mut();
        // SAFETY: valid pointers.
        let s = unsafe { adaptimp_controller_new(params, &mut ctrl) };
        if s != AdaptimpStatus::Ok {
            return Err((s, last_error()));
        }
        let mut state = ptr::null_mut();
        // SAFETY: a valid controller and out pointer.
        assert_eq!(
            unsafe { adaptimp_state_new(ctrl, &mut state) },
            AdaptimpStatus::Ok
        );
        Ok(Self { ctrl, state })
    }

    /// One step with the controller's own trajectory: the status and the output.
    pub fn step_raw(
        &self,
        q: &[f64],
        dq: Option<&[f64]>,
        te: &[f64],
        sp: Option<&AdaptimpSetpoint>,
    ) -> (AdaptimpStatus, AdaptimpCommand) {
        let mut out = poisoned();
        // SAFETY: valid handles; slices of n reals.
        let s = unsafe {
            adaptimp_step(
                self.ctrl,
                self.state,
                q.len(),
                q.as_ptr(),
                dq.map_or(ptr::null(), |d| d.as_ptr()),
                te.as_ptr(),
                sp.map_or(ptr::null(), |s| s as *const _),
                &mut out,
            )
        };
        (s, out)
    }

    pub fn step(
        &self,
        q: &[f64],
        dq: Option<&[f64]>,
        te: &[f64],
    ) -> Result<AdaptimpCommand, AdaptimpStatus> {
        match self.step_raw(q, dq, te, None) {
            (AdaptimpStatus::Ok, out) => Ok(out),
            (s, _) => Err(s),
        }
    }

    /// The state's snapshot.
    pub fn snapshot(&self) -> Vec<f64> {
        // SAFETY: a valid state and a buffer of its length.
        unsafe {
            let len = adaptimp_state_snapshot_len(self.state);
            let mut buf = vec![0.0; len];
            assert_eq!(
                adaptimp_state_save(self.state, buf.as_mut_ptr(), len, ptr::null_mut()),
                AdaptimpStatus::Ok
            );
            buf
        }
    }

    /// The torque to apply now.
    pub fn applied(&self, n: usize) -> Vec<f64> {
        let mut tau = vec![f64::NAN; n];
        // SAFETY: a valid state; n reals.
        assert_eq!(
            unsafe { adaptimp_state_applied(self.state, n, tau.as_mut_ptr()) },
            AdaptimpStatus::Ok
        );
        tau
    }

    /// The recorded fault's step, if any.
    pub fn fault(&self) -> Option<u64> {
        let mut k = u64::MAX;
        // SAFETY: a valid state and out pointer.
        unsafe { adaptimp_state_fault(self.state, &mut k) }.then_some(k)
    }
}

impl Drop for Handles {
    fn drop(&mut self) {
        // SAFETY: created by the library, freed once.
        unsafe {
            adaptimp_state_free(self.state);
            adaptimp_controller_free(self.ctrl);
        }
    }
}

/// An output struct full of a value no step writes (NaN, n = 99), to see what a call wrote.
pub fn poisoned() -> AdaptimpCommand {
    AdaptimpCommand {
        n: 99,
        tau_sat: [f64::NAN; 7],
        tau: [f64::NAN; 7],
        dtau: [f64::NAN; 7],
        z1: [f64::NAN; 7],
        z2: [f64::NAN; 7],
        xc: [f64::NAN; 7],
        xd: [f64::NAN; 7],
        v: [f64::NAN; 7],
        zeta: [f64::NAN; 7],
        w_norms: [f64::NAN; 3],
    }
}
