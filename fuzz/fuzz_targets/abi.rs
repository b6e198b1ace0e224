//! Fuzzed C ABI: controllers built from arbitrary parameter structs (n, gains,
//! user centres), stepped with arbitrary sizes, NULL pointers and values,
//! snapshots restored from arbitrary data. Every call returns a status; no
//! panic crosses it (a caught one would be ADAPTIMP_STATUS_INTERNAL, which is
//! a failure here), and an accepted step's torque is finite.
#![no_main]

use adaptimp_ffi::*;
use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use std::ptr;

#[derive(Arbitrary, Debug)]
struct Input {
    n: u8,
    law: u8,
    robot: bool,
    gains: Vec<(u8, f64)>,
    centers: Option<Vec<f64>>,
    widths: Option<Vec<f64>>,
    steps: Vec<([f64; 7], [f64; 7], [f64; 7], u8, bool, bool)>,
    snapshot: Vec<f64>,
}

fn params(input: &Input) -> Option<AdaptimpParams> {
    let n = usize::from(input.n % 9); // 0 and 8 are invalid
    let law = [
        AdaptimpLaw::Pd,
        AdaptimpLaw::StateFeedback,
        AdaptimpLaw::OutputFeedback,
    ][usize::from(input.law % 3)];
    let preset = if input.robot {
        AdaptimpPreset::Robot
    } else {
        AdaptimpPreset::Paper
    };
    let mut p = std::mem::MaybeUninit::<AdaptimpParams>::uninit();
    // SAFETY: a valid place; Ok means it was written whole.
    let status = unsafe { adaptimp_params_default(p.as_mut_ptr(), n, law, preset) };
    assert_ne!(status, AdaptimpStatus::Internal);
    if status != AdaptimpStatus::Ok {
        return None;
    }
    // SAFETY: written whole (status Ok).
    let mut p = unsafe { p.assume_init() };
    for (i, v) in input.gains.iter().take(8) {
        let j = usize::from(*i) % 7;
        match i % 8 {
            0 => p.kp[j] = *v,
            1 => p.k1[j] = *v,
            2 => p.kzeta[j] = *v,
            3 => p.tau_max[j] = *v,
            4 => p.ts = *v,
            5 => p.eps = *v,
            6 => p.gamma[j % 3] = *v,
            _ => p.q_max[j] = *v,
        }
    }
    Some(p)
}

fuzz_target!(|input: Input| {
    let Some(mut p) = params(&input) else { return };
    let n = p.n;
    if let Some(c) = &input.centers {
        // The pointer is valid for what `nodes` promises.
        p.nodes = c.len() / (4 * n);
        p.centers = c.as_ptr();
        if let Some(w) = &input.widths {
            if w.len() >= 4 * n {
                p.widths2 = w.as_ptr();
            }
        }
    }
    let mut ctrl = ptr::null_mut();
    // SAFETY: valid pointers for what they promise.
    let status = unsafe { adaptimp_controller_new(&p, &mut ctrl) };
    assert_ne!(status, AdaptimpStatus::Internal);
    if status != AdaptimpStatus::Ok {
        return;
    }
    let mut state = ptr::null_mut();
    // SAFETY: a valid controller.
    assert_eq!(
        unsafe { adaptimp_state_new(ctrl, &mut state) },
        AdaptimpStatus::Ok
    );
    // SAFETY: zeroed is a valid command (numbers only).
    let mut out: AdaptimpCommand = unsafe { std::mem::zeroed() };
    for (q, dq, te, size, null_dq, null_out) in input.steps.iter().take(8) {
        let size = usize::from(*size) % 8; // may differ from n: refused by status
        let status = unsafe {
            // SAFETY: the arrays hold 7 ≥ size reals.
            adaptimp_step(
                ctrl,
                state,
                size,
                q.as_ptr(),
                if *null_dq { ptr::null() } else { dq.as_ptr() },
                te.as_ptr(),
                ptr::null(),
                if *null_out { ptr::null_mut() } else { &mut out },
            )
        };
        assert_ne!(status, AdaptimpStatus::Internal);
        if status == AdaptimpStatus::Ok {
            assert!(out.tau_sat[..n].iter().all(|t| t.is_finite()));
        }
    }
    // SAFETY: valid handles and a buffer of the stated length.
    unsafe {
        let s = adaptimp_state_restore(state, input.snapshot.as_ptr(), input.snapshot.len());
        assert_ne!(s, AdaptimpStatus::Internal);
        adaptimp_state_free(state);
        adaptimp_controller_free(ctrl);
    }
});
