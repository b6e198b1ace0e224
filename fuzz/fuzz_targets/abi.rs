//! Fuzzed C ABI: controllers built from arbitrary parameter structs (n, gains,
//! user centres, enum fields as arbitrary integers), stepped with arbitrary
//! sizes, NULL pointers and values, on the heap or in a caller buffer;
//! snapshots restored from arbitrary data; chains from arbitrary joint data
//! and Cartesian steps with arbitrary targets and wrenches. Every call
//! returns a status; no panic crosses it (a caught one would be
//! ADAPTIMP_STATUS_INTERNAL, a failure here); the output is written on every
//! status (n is the controller's whenever it could be asked, else 0) and an
//! accepted step's torque is finite.
#![no_main]

use adaptimp_ffi::*;
use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use std::ptr;

#[derive(Arbitrary, Debug)]
struct Input {
    n: u8,
    law: u32,
    preset: u32,
    gains: Vec<(u8, f64)>,
    enums: Vec<(u8, u32)>,
    centers: Option<Vec<f64>>,
    widths: Option<Vec<f64>>,
    in_place: bool,
    steps: Vec<([f64; 7], [f64; 7], [f64; 7], u8, bool, bool)>,
    snapshot: Vec<f64>,
    joints: Vec<(u32, [f64; 3], [f64; 3], [f64; 3], f64)>,
    cartesian: Vec<([f64; 7], [f64; 6], [f64; 15], [f64; 9], bool)>,
}

/// A valid value most of the time, any integer otherwise.
fn pick(raw: u32, base: u32, count: u32) -> u32 {
    if raw % 8 == 7 {
        raw
    } else {
        base + raw % count
    }
}

fn params(input: &Input) -> Option<AdaptimpParams> {
    let n = usize::from(input.n % 9); // 0 and 8 are invalid
    let mut p = std::mem::MaybeUninit::<AdaptimpParams>::uninit();
    // SAFETY: a valid place; Ok means it was written whole.
    let status = unsafe {
        adaptimp_params_default(
            p.as_mut_ptr(),
            n,
            AdaptimpLawRaw(pick(input.law, 100, 3)),
            AdaptimpPresetRaw(pick(input.preset, 200, 2)),
        )
    };
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
    for (field, raw) in input.enums.iter().take(4) {
        match field % 7 {
            0 => p.fallback = AdaptimpFallbackRaw(pick(*raw, 1100, 3)),
            1 => p.fault_policy = AdaptimpFaultPolicyRaw(pick(*raw, 1200, 2)),
            2 => p.robust = AdaptimpRobustRaw(pick(*raw, 400, 4)),
            3 => p.impedance = AdaptimpImpedanceRaw(pick(*raw, 1000, 2)),
            4 => p.weight_bound_mode = AdaptimpWeightBoundRaw(pick(*raw, 700, 3)),
            5 => p.conditions = AdaptimpConditionsRaw(pick(*raw, 1400, 2)),
            _ => p.law = AdaptimpLawRaw(pick(*raw, 100, 3)),
        }
    }
    Some(p)
}

fn joint_steps(input: &Input, p: &AdaptimpParams) {
    let n = p.n;
    let mut ctrl = ptr::null_mut();
    // SAFETY: valid pointers for what they promise.
    let status = unsafe { adaptimp_controller_new(p, &mut ctrl) };
    assert_ne!(status, AdaptimpStatus::Internal);
    if status != AdaptimpStatus::Ok {
        return;
    }
    let mut state = ptr::null_mut();
    let mut buf: Vec<u64> = Vec::new();
    if input.in_place {
        let (mut size, mut align) = (0, 0);
        // SAFETY: valid pointers; the buffer holds `size` bytes aligned to 8.
        unsafe {
            assert_eq!(
                adaptimp_state_buffer_size(ctrl, &mut size, &mut align),
                AdaptimpStatus::Ok
            );
            assert!(align <= 8);
            buf = vec![0; size.div_ceil(8)];
            assert_eq!(
                adaptimp_state_init(ctrl, buf.as_mut_ptr().cast(), size, &mut state),
                AdaptimpStatus::Ok
            );
        }
    } else {
        // SAFETY: a valid controller.
        assert_eq!(
            unsafe { adaptimp_state_new(ctrl, &mut state) },
            AdaptimpStatus::Ok
        );
    }
    for (q, dq, te, size, null_dq, null_out) in input.steps.iter().take(8) {
        let size = usize::from(*size) % 8; // may differ from n: refused by status
                                           // SAFETY: zeroed is a valid command (numbers only).
        let mut out: AdaptimpCommand = unsafe { std::mem::zeroed() };
        out.n = 99;
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
        if !*null_out {
            assert_eq!(out.n, n, "written on every status: {status:?}");
            assert!(out.tau_sat.iter().all(|t| t.is_finite()));
        }
    }
    // SAFETY: valid handles and a buffer of the stated length.
    unsafe {
        let s = adaptimp_state_restore(ctrl, state, input.snapshot.as_ptr(), input.snapshot.len());
        assert_ne!(s, AdaptimpStatus::Internal);
        adaptimp_state_free(state);
        adaptimp_controller_free(ctrl);
    }
    drop(buf);
}

fn cartesian_steps(input: &Input) {
    if input.joints.is_empty() {
        return;
    }
    let joints: Vec<AdaptimpJoint> = input
        .joints
        .iter()
        .take(9)
        .map(|(kind, xyz, rpy, axis, offset)| {
            let mut origin = AdaptimpTransform {
                translation: [0.0; 3],
                rotation: [[0.0; 3]; 3],
            };
            // SAFETY: 3 reals each, a valid out pointer.
            let s = unsafe { adaptimp_transform_xyz_rpy(xyz.as_ptr(), rpy.as_ptr(), &mut origin) };
            assert_eq!(s, AdaptimpStatus::Ok);
            AdaptimpJoint {
                kind: AdaptimpJointKindRaw(pick(*kind, 1300, 3)),
                origin,
                axis: *axis,
                offset: *offset,
            }
        })
        .collect();
    let mut chain = ptr::null_mut();
    // SAFETY: valid arrays and out pointer.
    let s = unsafe { adaptimp_chain_new(joints.as_ptr(), joints.len(), ptr::null(), &mut chain) };
    assert_ne!(s, AdaptimpStatus::Internal);
    if s != AdaptimpStatus::Ok {
        return;
    }
    // SAFETY: a valid chain.
    let n = unsafe { adaptimp_chain_joints(chain) };
    let mut joint = std::mem::MaybeUninit::<AdaptimpParams>::uninit();
    let mut cart = std::mem::MaybeUninit::<AdaptimpCartesianParams>::uninit();
    // SAFETY: valid places, written whole on Ok.
    let (joint, cart) = unsafe {
        assert_eq!(
            adaptimp_params_default(
                joint.as_mut_ptr(),
                n,
                AdaptimpLaw::Pd.into(),
                AdaptimpPreset::Robot.into()
            ),
            AdaptimpStatus::Ok
        );
        assert_eq!(
            adaptimp_cartesian_params_default(cart.as_mut_ptr()),
            AdaptimpStatus::Ok
        );
        (joint.assume_init(), cart.assume_init())
    };
    let mut joint = joint;
    joint.impedance = AdaptimpImpedance::External.into();
    joint.eta2 = 25.0;
    // The grid exists for n ≤ 3; one centre otherwise.
    let centre = vec![0.0; 4 * n];
    if n > 3 {
        joint.centers = centre.as_ptr();
        joint.nodes = 1;
    }
    let mut c = ptr::null_mut();
    let mut st = ptr::null_mut();
    // SAFETY: valid handles and structs; 7 ≥ n reals.
    unsafe {
        assert_eq!(
            adaptimp_cartesian_new(chain, &cart, &joint, &mut c),
            AdaptimpStatus::Ok
        );
        adaptimp_chain_free(chain);
        let q0 = [0.0; 7];
        let s = adaptimp_cartesian_state_new(c, n, q0.as_ptr(), &mut st);
        assert_eq!(s, AdaptimpStatus::Ok);
        for (q, wrench, t, r, hold) in input.cartesian.iter().take(6) {
            let target = AdaptimpPoseTarget {
                p: [t[0], t[1], t[2]],
                dp: [t[3], t[4], t[5]],
                ddp: [t[6], t[7], t[8]],
                rotation: [[r[0], r[1], r[2]], [r[3], r[4], r[5]], [r[6], r[7], r[8]]],
                w: [t[9], t[10], t[11]],
                dw: [t[12], t[13], t[14]],
            };
            let mut out = AdaptimpCartesianCommand::ZERO;
            out.n = 99;
            let s = adaptimp_cartesian_step(
                c,
                st,
                n,
                q.as_ptr(),
                q.as_ptr(),
                wrench.as_ptr(),
                if *hold { ptr::null() } else { &target },
                &mut out,
            );
            assert_ne!(s, AdaptimpStatus::Internal);
            assert_eq!(out.n, n, "written on every status: {s:?}");
            assert!(out.tau_sat.iter().all(|t| t.is_finite()));
        }
        adaptimp_cartesian_state_free(st);
        adaptimp_cartesian_free(c);
    }
}

fuzz_target!(|input: Input| {
    if let Some(mut p) = params(&input) {
        let n = p.n;
        let keep = input.centers.clone();
        if let Some(c) = &keep {
            // The pointer is valid for what `nodes` promises.
            p.nodes = c.len() / (4 * n);
            p.centers = c.as_ptr();
            if let Some(w) = &input.widths {
                if w.len() >= 4 * n {
                    p.widths2 = w.as_ptr();
                }
            }
        }
        joint_steps(&input, &p);
    }
    cartesian_steps(&input);
});
