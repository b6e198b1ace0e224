//! The C items of issue 20 through the ABI, each as it was reported: enum
//! values outside their enums, swapped enum arguments, NaN parameters, the
//! output of a refused call, a setpoint sample that bricked the controller,
//! restore without the controller, freed handles. The fault semantics are
//! docs/reliability.md's.

use adaptimp_ffi::*;
use std::ptr;

mod common;
use common::{defaults, last_error, poisoned, Handles};

const Q: [f64; 2] = [0.25, -0.05];
const DQ: [f64; 2] = [0.0, 0.0];
const TE: [f64; 2] = [0.0, 0.0];

/// A change to the parameters.
type Edit = fn(&mut AdaptimpParams);

fn robot_sf() -> AdaptimpParams {
    defaults(2, AdaptimpLaw::StateFeedback, AdaptimpPreset::Robot)
}

fn refused(p: &AdaptimpParams) -> (AdaptimpStatus, String) {
    match Handles::new(p) {
        Ok(_) => panic!("accepted"),
        Err(e) => e,
    }
}

#[test]
fn an_enum_field_outside_its_enum_is_refused_by_name() {
    // Reported: law = 7, fallback = 3 were accepted.
    let mut p = robot_sf();
    p.law = AdaptimpLawRaw(7);
    assert_eq!(
        refused(&p),
        (
            AdaptimpStatus::InvalidConfig,
            "params.law = 7 is not an AdaptimpLaw (one of ADAPTIMP_LAW_PD = 100 … \
             ADAPTIMP_LAW_OUTPUT_FEEDBACK = 102)"
                .to_string()
        )
    );
    let mut p = robot_sf();
    p.fallback = AdaptimpFallbackRaw(3);
    let (s, msg) = refused(&p);
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(
        msg.starts_with("params.fallback = 3 is not an AdaptimpFallback"),
        "{msg}"
    );
    // Every enum field, and one value past each enum's last.
    let fields: [(&str, Edit); 11] = [
        ("law", |p| p.law = AdaptimpLawRaw(103)),
        ("aux_law", |p| p.aux_law = AdaptimpAuxLawRaw(303)),
        ("robust", |p| p.robust = AdaptimpRobustRaw(404)),
        ("learning_step", |p| {
            p.learning_step = AdaptimpLearningStepRaw(502)
        }),
        ("saturation_learning", |p| {
            p.saturation_learning = AdaptimpSaturationLearningRaw(602)
        }),
        ("weight_bound_mode", |p| {
            p.weight_bound_mode = AdaptimpWeightBoundRaw(703)
        }),
        ("observer_init", |p| {
            p.observer_init = AdaptimpObserverInitRaw(802)
        }),
        ("observer_hold", |p| {
            p.observer_hold = AdaptimpObserverHoldRaw(902)
        }),
        ("impedance", |p| p.impedance = AdaptimpImpedanceRaw(1002)),
        ("fallback", |p| p.fallback = AdaptimpFallbackRaw(1103)),
        ("fault_policy", |p| {
            p.fault_policy = AdaptimpFaultPolicyRaw(u32::MAX)
        }),
    ];
    for (name, set) in fields {
        let mut p = robot_sf();
        set(&mut p);
        let (s, msg) = refused(&p);
        assert_eq!(s, AdaptimpStatus::InvalidConfig, "{name}");
        assert!(msg.starts_with(&format!("params.{name} = ")), "{msg}");
    }
    // A zeroed struct (instead of adaptimp_params_default) is refused, not read as PD.
    // SAFETY: every field of AdaptimpParams is valid as zero bits (integers, reals, NULL).
    let mut zeroed: AdaptimpParams = unsafe { std::mem::zeroed() };
    zeroed.n = 2;
    let (s, msg) = refused(&zeroed);
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(
        msg.starts_with("params.law = 0 is not an AdaptimpLaw"),
        "{msg}"
    );
}

#[test]
fn swapped_enum_arguments_are_refused_and_said_to_be_swapped() {
    // Reported: adaptimp_controller_new_preset(law, preset) silently built
    // another controller (PD for the robot became state feedback for the paper).
    let mut ctrl = ptr::null_mut();
    // SAFETY: a valid out pointer.
    let s = unsafe {
        adaptimp_controller_new_preset(
            AdaptimpPresetRaw(AdaptimpLaw::Pd as u32),
            AdaptimpLawRaw(AdaptimpPreset::Robot as u32),
            &mut ctrl,
        )
    };
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(ctrl.is_null());
    assert_eq!(
        last_error(),
        "law = 201 is not an AdaptimpLaw (one of ADAPTIMP_LAW_PD = 100 … \
         ADAPTIMP_LAW_OUTPUT_FEEDBACK = 102): 201 is ADAPTIMP_PRESET_ROBOT, a value of \
         AdaptimpPreset (two arguments swapped?)"
    );
    // preset = 9, and the same swap through adaptimp_params_default.
    // SAFETY: a valid out pointer.
    let s = unsafe {
        adaptimp_controller_new_preset(
            AdaptimpPresetRaw(9),
            AdaptimpLaw::StateFeedback.into(),
            &mut ctrl,
        )
    };
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(last_error().starts_with("preset = 9 is not an AdaptimpPreset"));
    let mut p = robot_sf();
    let before = p;
    // SAFETY: a valid place.
    let s = unsafe {
        adaptimp_params_default(
            &mut p,
            2,
            AdaptimpLawRaw(AdaptimpPreset::Paper as u32),
            AdaptimpPresetRaw(AdaptimpLaw::Pd as u32),
        )
    };
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(last_error().contains("two arguments swapped?"));
    assert_eq!(p, before, "unchanged on an error");
}

#[test]
fn a_nan_parameter_is_a_configuration_error_as_in_python() {
    // Reported: NON_FINITE, which the header documents for measurements.
    let cases: [(&str, Edit); 5] = [
        ("Kp[0]", |p| p.kp[0] = f64::NAN),
        ("Ts", |p| p.ts = f64::NAN),
        ("eps", |p| p.eps = f64::NAN),
        ("q_max[1]", |p| p.q_max[1] = f64::NAN),
        ("tau_max[0]", |p| p.tau_max[0] = f64::INFINITY),
    ];
    for (what, set) in cases {
        let mut p = robot_sf();
        set(&mut p);
        let (s, msg) = refused(&p);
        assert_eq!(s, AdaptimpStatus::InvalidConfig, "{what}: {msg}");
        assert!(msg.contains(what), "{what}: {msg}");
    }
}

#[test]
fn infinity_is_no_limit_as_none_is_in_python() {
    // Python accepts q_jump_max = inf as None; C documents INFINITY as none.
    let mut p = robot_sf();
    p.q_jump_max = [f64::INFINITY; 7];
    p.q_max = [3.0, f64::INFINITY, 0.0, 0.0, 0.0, 0.0, 0.0];
    let h = Handles::new(&p).expect("INFINITY is no limit");
    h.step(&Q, Some(&DQ), &TE).unwrap();
    // A jump of 2 rad is no jump beyond a limit.
    h.step(&[Q[0] + 2.0, Q[1]], Some(&DQ), &TE).unwrap();
    // 1e6 rad is still the ceiling.
    assert_eq!(
        h.step(&[Q[0], 2e6], Some(&DQ), &TE).unwrap_err(),
        AdaptimpStatus::OutOfRange
    );
}

#[test]
fn a_refused_call_writes_the_fallback_and_records_the_refusal() {
    // Reported: on NULL_POINTER, BAD_SIZE and WRONG_STATE the output's
    // tau_sat was not written (torque_callback.cpp applied it anyway).
    let mut p = robot_sf();
    p.fallback = AdaptimpFallback::Zero.into();
    let h = Handles::new(&p).unwrap();
    let ok = h.step(&Q, Some(&DQ), &TE).unwrap();
    assert!(ok.tau_sat[..2].iter().any(|t| *t != 0.0));
    let steps = |h: &Handles| unsafe { adaptimp_state_steps(h.state) };
    // q NULL, tau_e NULL, n wrong: the fallback (zero) written with n, recorded.
    type Call = fn(&Handles, &mut AdaptimpCommand) -> AdaptimpStatus;
    let calls: [(&str, AdaptimpStatus, Call); 3] = [
        ("q is NULL", AdaptimpStatus::NullPointer, |h, out| unsafe {
            adaptimp_step(
                h.ctrl,
                h.state,
                2,
                ptr::null(),
                DQ.as_ptr(),
                TE.as_ptr(),
                ptr::null(),
                out,
            )
        }),
        (
            "tau_e is NULL",
            AdaptimpStatus::NullPointer,
            |h, out| unsafe {
                adaptimp_step(
                    h.ctrl,
                    h.state,
                    2,
                    Q.as_ptr(),
                    DQ.as_ptr(),
                    ptr::null(),
                    ptr::null(),
                    out,
                )
            },
        ),
        (
            "n = 3, but the controller has 2 joints",
            AdaptimpStatus::BadSize,
            |h, out| unsafe {
                let q = [0.0; 3];
                adaptimp_step(
                    h.ctrl,
                    h.state,
                    3,
                    q.as_ptr(),
                    q.as_ptr(),
                    q.as_ptr(),
                    ptr::null(),
                    out,
                )
            },
        ),
    ];
    for (msg, status, call) in calls {
        let mut out = poisoned();
        assert_eq!(call(&h, &mut out), status, "{msg}");
        assert_eq!(last_error(), msg);
        assert_eq!(out, {
            let mut z = AdaptimpCommand::ZERO;
            z.n = 2;
            z
        });
        assert_eq!(h.applied(2), [0.0, 0.0]);
        assert_eq!(h.fault(), Some(1), "{msg}");
        assert_eq!(steps(&h), 1);
        // SAFETY: a valid state.
        unsafe { adaptimp_state_clear_fault(h.state) };
    }
    // out NULL: nothing to write, the refusal recorded.
    // SAFETY: valid handles and inputs.
    let s = unsafe {
        adaptimp_step(
            h.ctrl,
            h.state,
            2,
            Q.as_ptr(),
            DQ.as_ptr(),
            TE.as_ptr(),
            ptr::null(),
            ptr::null_mut(),
        )
    };
    assert_eq!(s, AdaptimpStatus::NullPointer);
    assert_eq!(h.fault(), Some(1));
    // No controller to ask: every field zero, n = 0.
    let other = Handles::new(&defaults(3, AdaptimpLaw::Pd, AdaptimpPreset::Robot)).unwrap();
    let mut out = poisoned();
    // SAFETY: valid handles of different sizes; n reals.
    let s = unsafe {
        adaptimp_step(
            h.ctrl,
            other.state,
            2,
            Q.as_ptr(),
            DQ.as_ptr(),
            TE.as_ptr(),
            ptr::null(),
            &mut out,
        )
    };
    assert_eq!(s, AdaptimpStatus::WrongState);
    assert_eq!(out, AdaptimpCommand::ZERO);
    assert_eq!(other.fault(), None);
    let mut out = poisoned();
    // SAFETY: NULL controller; the rest valid.
    let s = unsafe {
        adaptimp_step(
            ptr::null(),
            h.state,
            2,
            Q.as_ptr(),
            DQ.as_ptr(),
            TE.as_ptr(),
            ptr::null(),
            &mut out,
        )
    };
    assert_eq!(s, AdaptimpStatus::NullPointer);
    assert_eq!(out, AdaptimpCommand::ZERO);
}

#[test]
fn with_a_latched_fault_every_refusal_keeps_the_fault_and_applies_the_fallback() {
    let mut p = robot_sf();
    p.fault_policy = AdaptimpFaultPolicy::Latch.into();
    p.fallback = AdaptimpFallback::Hold.into();
    let h = Handles::new(&p).unwrap();
    let held = h.step(&Q, Some(&DQ), &TE).unwrap().tau_sat;
    let (s, out) = h.step_raw(&[f64::NAN, 0.0], Some(&DQ), &TE, None);
    assert_eq!(s, AdaptimpStatus::NonFinite);
    assert_eq!(out.tau_sat, held);
    for _ in 0..3 {
        let (s, out) = h.step_raw(&Q, Some(&DQ), &TE, None);
        assert_eq!(s, AdaptimpStatus::Faulted);
        assert_eq!(out.tau_sat, held);
        assert!(
            last_error().contains("non-finite input"),
            "{}",
            last_error()
        );
    }
    // A front refusal while latched keeps the latched fault too.
    let (s, out) = h.step_raw(&[0.0; 3], Some(&[0.0; 3]), &[0.0; 3], None);
    assert_eq!(s, AdaptimpStatus::BadSize);
    assert_eq!(out.tau_sat, held);
    assert_eq!(h.fault(), Some(1));
    // SAFETY: a valid state.
    unsafe { adaptimp_state_clear_fault(h.state) };
    assert!(h.step(&Q, Some(&DQ), &TE).is_ok());
}

#[test]
fn one_setpoint_sample_does_not_brick_the_controller() {
    // Reported: step(xc = q, dxc = [1e99, 0]) was accepted and every later
    // step diverged, even after clear_fault; xc = 1e50 drove the arm at
    // saturation. Through the C ABI, as in Python.
    for law in [
        AdaptimpLaw::Pd,
        AdaptimpLaw::StateFeedback,
        AdaptimpLaw::OutputFeedback,
    ] {
        let h = Handles::new(&defaults(2, law, AdaptimpPreset::Robot)).unwrap();
        let twin = Handles::new(&defaults(2, law, AdaptimpPreset::Robot)).unwrap();
        h.step(&Q, Some(&DQ), &TE).unwrap();
        twin.step(&Q, Some(&DQ), &TE).unwrap();
        let mut sp = AdaptimpSetpoint {
            x: [0.0; 7],
            dx: [0.0; 7],
            ddx: [0.0; 7],
        };
        sp.x[..2].copy_from_slice(&Q);
        sp.dx[0] = 1e99;
        let (s, out) = h.step_raw(&Q, Some(&DQ), &TE, Some(&sp));
        assert_eq!(s, AdaptimpStatus::OutOfRange, "{law:?}");
        assert!(last_error().starts_with("dxc[0] = 1e99 is beyond its limit"));
        assert_eq!(out.tau_sat[..2], h.applied(2)[..]);
        let mut far = sp;
        far.dx[0] = 0.0;
        far.x[0] = 1e50;
        let (s, _) = h.step_raw(&Q, Some(&DQ), &TE, Some(&far));
        assert_eq!(s, AdaptimpStatus::OutOfRange);
        assert!(last_error().starts_with("xc[0] = 1e50"));
        // SAFETY: a valid state.
        unsafe { adaptimp_state_clear_fault(h.state) };
        // The run goes on as its twin's, which never saw the samples (the
        // hold fallback leaves the applied torque as it was).
        for k in 0..200 {
            let q = [Q[0] + 1e-4 * k as f64, Q[1]];
            let a = h.step(&q, Some(&DQ), &TE).expect("not bricked");
            let b = twin.step(&q, Some(&DQ), &TE).unwrap();
            assert_eq!(a, b, "{law:?} k = {k}");
        }
    }
}

#[test]
fn restore_refuses_a_state_this_controller_could_never_have_left() {
    // Reported: C restore checked finiteness and sizes only (State::load),
    // not the torque limits and projection bounds of Controller::restore.
    let small = Handles::new(&robot_sf()).unwrap();
    let mut p = robot_sf();
    p.tau_max[..2].copy_from_slice(&[50.0, 50.0]);
    let big = Handles::new(&p).unwrap();
    for _ in 0..20 {
        big.step(&[1.0, -1.0], Some(&DQ), &TE).unwrap();
    }
    assert!(big.applied(2).iter().any(|t| t.abs() > 17.0));
    let snap = big.snapshot();
    let before = small.snapshot();
    // SAFETY: valid handles and a buffer of its length.
    let s = unsafe { adaptimp_state_restore(small.ctrl, small.state, snap.as_ptr(), snap.len()) };
    assert_eq!(s, AdaptimpStatus::BadSnapshot);
    assert!(
        last_error().starts_with("applied torque[0] = -5e1 is beyond its limit ±1.7e1"),
        "{}",
        last_error()
    );
    assert_eq!(small.snapshot(), before, "unchanged");
    // Its own controller takes it; a state of the other size is WRONG_STATE.
    // SAFETY: as above.
    let s = unsafe { adaptimp_state_restore(big.ctrl, small.state, snap.as_ptr(), snap.len()) };
    assert_eq!(s, AdaptimpStatus::Ok);
    let three = Handles::new(&defaults(3, AdaptimpLaw::Pd, AdaptimpPreset::Robot)).unwrap();
    // SAFETY: as above.
    let s = unsafe { adaptimp_state_restore(big.ctrl, three.state, snap.as_ptr(), snap.len()) };
    assert_eq!(s, AdaptimpStatus::WrongState);
    // A bit flipped anywhere: refused, unchanged.
    let own = big.snapshot();
    for i in [0, 4, 7, own.len() / 2, own.len() - 20, own.len() - 1] {
        let mut bad = own.clone();
        bad[i] = f64::from_bits(bad[i].to_bits() ^ 1);
        // SAFETY: as above.
        let s = unsafe { adaptimp_state_restore(big.ctrl, big.state, bad.as_ptr(), bad.len()) };
        assert_eq!(s, AdaptimpStatus::BadSnapshot, "bit flipped at {i}");
        assert_eq!(big.snapshot(), own);
    }
}

#[test]
fn the_snapshot_length_is_the_documented_one() {
    // 12 + 18 n + L (2n² + n + 1) (format 3).
    for (n, law) in [
        (1, AdaptimpLaw::Pd),
        (2, AdaptimpLaw::StateFeedback),
        (3, AdaptimpLaw::OutputFeedback),
    ] {
        let mut p = defaults(n, law, AdaptimpPreset::Robot);
        p.eta2 = 25.0;
        let h = Handles::new(&p).unwrap();
        let l = 1usize << (4 * n);
        // SAFETY: a valid state.
        let len = unsafe { adaptimp_state_snapshot_len(h.state) };
        assert_eq!(len, 12 + 18 * n + l * (2 * n * n + n + 1));
        assert_eq!(h.snapshot().len(), len);
    }
}

#[test]
fn a_freed_or_foreign_pointer_is_refused_not_used() {
    let h = Handles::new(&robot_sf()).unwrap();
    // A state in a buffer of ours, freed: the memory is still ours, the handle dead.
    let (mut size, mut align) = (0, 0);
    // SAFETY: valid pointers.
    assert_eq!(
        unsafe { adaptimp_state_buffer_size(h.ctrl, &mut size, &mut align) },
        AdaptimpStatus::Ok
    );
    let mut buf = vec![0u64; size.div_ceil(8)];
    assert!(align <= 8);
    let mut st = ptr::null_mut();
    // SAFETY: a buffer of `size` bytes, aligned to 8, unused otherwise.
    unsafe {
        assert_eq!(
            adaptimp_state_init(h.ctrl, buf.as_mut_ptr().cast(), size, &mut st),
            AdaptimpStatus::Ok
        );
        adaptimp_state_free(st);
        assert_eq!(adaptimp_state_reset(st), AdaptimpStatus::BadHandle);
        assert!(last_error().contains("not a live AdaptimpState"));
        let mut out = poisoned();
        let s = adaptimp_step(
            h.ctrl,
            st,
            2,
            Q.as_ptr(),
            DQ.as_ptr(),
            TE.as_ptr(),
            ptr::null(),
            &mut out,
        );
        assert_eq!(s, AdaptimpStatus::BadHandle);
        assert_eq!(out, AdaptimpCommand::ZERO);
        assert_eq!(adaptimp_state_steps(st), 0);
        assert!(!adaptimp_state_fault(st, ptr::null_mut()));
        // Freeing it again does nothing.
        adaptimp_state_free(st);
        // A controller given as a state, a state given as a controller.
        assert_eq!(
            adaptimp_state_clear_fault(h.ctrl.cast()),
            AdaptimpStatus::BadHandle
        );
        assert_eq!(adaptimp_controller_joints(h.state.cast()), 0);
        assert!(adaptimp_controller_period(h.state.cast()).is_nan());
        // Zeroed memory.
        let zeros = [0u64; 64];
        assert_eq!(
            adaptimp_state_new(zeros.as_ptr().cast(), &mut st),
            AdaptimpStatus::BadHandle
        );
        adaptimp_controller_free(zeros.as_ptr().cast_mut().cast());
        // A misaligned pointer.
        let odd = (buf.as_mut_ptr() as *mut u8).add(1);
        assert_eq!(adaptimp_state_reset(odd.cast()), AdaptimpStatus::BadHandle);
    }
    // The handles still work.
    assert!(h.step(&Q, Some(&DQ), &TE).is_ok());
}

/// URDF text that starts with a byte-order mark (as an editor on Windows
/// saves it) is text, not a path: it was taken for a file name, and the
/// whole text printed as one.
#[test]
fn urdf_text_with_a_byte_order_mark_is_read_as_text() {
    let text = "\u{feff}<robot name='r'><link name='a'/><link name='b'/>\
                <joint name='j' type='revolute'><parent link='a'/><child link='b'/>\
                <axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/>\
                </joint></robot>";
    let source = std::ffi::CString::new(text).unwrap();
    let mut chain: *mut AdaptimpChain = ptr::null_mut();
    // SAFETY: NUL-terminated strings, a valid out pointer, no fix names.
    let status = unsafe {
        adaptimp_chain_from_urdf(
            source.as_ptr(),
            ptr::null(),
            ptr::null(),
            0,
            &mut chain,
            ptr::null_mut(),
        )
    };
    assert_eq!(status, AdaptimpStatus::Ok, "{}", last_error());
    // SAFETY: the chain the call made.
    unsafe { adaptimp_chain_free(chain) };
    // A path that does not exist is named, a long one shortened.
    let long = std::ffi::CString::new(format!("/nope/{}\nmore", "x".repeat(300))).unwrap();
    // SAFETY: as above.
    let status = unsafe {
        adaptimp_chain_from_urdf(
            long.as_ptr(),
            ptr::null(),
            ptr::null(),
            0,
            &mut chain,
            ptr::null_mut(),
        )
    };
    assert_eq!(status, AdaptimpStatus::InvalidConfig);
    let e = last_error();
    assert!(e.starts_with("cannot read the URDF '/nope/xxx"), "{e}");
    assert!(e.contains("… (311 characters)"), "{e}");
    assert!(e.len() < 300, "{e}");
}

/// A mimic joint of a joint the file lacks, or of itself, on the arm's way
/// was held silently in C as in Python (the arm one joint short): refused
/// by name, by the core's reduction every front shares.
#[test]
fn a_mimic_of_no_joint_on_the_way_is_refused_in_c() {
    for (master, why) in [
        (
            "nope",
            "joint 'j2' mimics 'nope', which is not a joint of it",
        ),
        ("j2", "joint 'j2' mimics itself"),
    ] {
        let text = format!(
            "<robot name='r'><link name='a'/><link name='b'/><link name='c'/>\
             <joint name='j1' type='revolute'><parent link='a'/><child link='b'/>\
             <axis xyz='0 0 1'/><limit lower='-1' upper='1' effort='1' velocity='1'/>\
             </joint><joint name='j2' type='revolute'><parent link='b'/><child link='c'/>\
             <origin xyz='0 0 0.1'/><axis xyz='0 1 0'/>\
             <limit lower='-1' upper='1' effort='1' velocity='1'/><mimic joint='{master}'/>\
             </joint></robot>"
        );
        let source = std::ffi::CString::new(text).unwrap();
        for tip in [None, Some(c"c")] {
            let mut chain: *mut AdaptimpChain = ptr::null_mut();
            // SAFETY: NUL-terminated strings, a valid out pointer, no fix names.
            let status = unsafe {
                adaptimp_chain_from_urdf(
                    source.as_ptr(),
                    tip.map_or(ptr::null(), |t| t.as_ptr()),
                    ptr::null(),
                    0,
                    &mut chain,
                    ptr::null_mut(),
                )
            };
            assert_eq!(status, AdaptimpStatus::InvalidConfig, "{tip:?}");
            assert!(chain.is_null());
            let e = last_error();
            assert!(
                e.starts_with(&format!("URDF text: {why}, on the way to 'c'")),
                "{e}"
            );
        }
    }
}
