//! The C ABI against the Rust API: the same torques (bit for bit) for the
//! same inputs, user centres for n = 3, snapshots, and misuse by status.

use adaptimp::{Controller, Law, Measurement, Sinusoid, Tracker, Trajectory, Vector};
use adaptimp_ffi::*;
use std::ffi::CStr;
use std::ptr;

fn last_error() -> String {
    // SAFETY: the library returns a NUL-terminated thread-local buffer.
    unsafe { CStr::from_ptr(adaptimp_last_error()) }
        .to_string_lossy()
        .into_owned()
}

struct Handles {
    ctrl: *mut AdaptimpController,
    state: *mut AdaptimpState,
}

impl Handles {
    fn new(params: &AdaptimpParams) -> Result<Self, (AdaptimpStatus, String)> {
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

    fn step(
        &self,
        q: &[f64],
        dq: Option<&[f64]>,
        te: &[f64],
    ) -> Result<AdaptimpCommand, AdaptimpStatus> {
        // SAFETY: zeroed is a valid AdaptimpCommand (numbers only).
        let mut out: AdaptimpCommand = unsafe { std::mem::zeroed() };
        // SAFETY: valid handles; slices of n reals.
        let s = unsafe {
            adaptimp_step(
                self.ctrl,
                self.state,
                q.len(),
                q.as_ptr(),
                dq.map_or(ptr::null(), |d| d.as_ptr()),
                te.as_ptr(),
                ptr::null(),
                &mut out,
            )
        };
        if s == AdaptimpStatus::Ok {
            Ok(out)
        } else {
            Err(s)
        }
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

fn defaults(n: usize, law: AdaptimpLaw, preset: AdaptimpPreset) -> AdaptimpParams {
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

/// The fixed input sequence of ffi/examples/paper.c at step k.
fn inputs(k: usize) -> ([f64; 2], [f64; 2], [f64; 2]) {
    let s = k as f64;
    (
        [
            0.25 + 0.01 * (0.1 * s).sin(),
            -0.05 + 0.01 * (0.07 * s).cos(),
        ],
        [0.1 * (0.1 * s).cos(), -0.1 * (0.07 * s).sin()],
        [(5.0 * (0.05 * s).sin()).max(0.0), 0.0],
    )
}

#[test]
fn torques_through_the_abi_equal_the_rust_api_bit_for_bit() {
    for (law, claw) in [
        (Law::Pd, AdaptimpLaw::Pd),
        (Law::StateFeedback, AdaptimpLaw::StateFeedback),
        (Law::OutputFeedback, AdaptimpLaw::OutputFeedback),
    ] {
        for (preset, rust) in [
            (AdaptimpPreset::Paper, Tracker::paper(law)),
            (AdaptimpPreset::Robot, Tracker::robot(law)),
        ] {
            let mut rust = rust;
            let c = Handles::new(&defaults(2, claw, preset)).expect("controller");
            for k in 0..500 {
                let (q, dq, te) = inputs(k);
                let ours = c.step(&q, Some(&dq), &te).expect("step");
                let theirs = rust
                    .step(&Measurement {
                        x: Vector::<2>::from(q),
                        dx: Some(Vector::<2>::from(dq)),
                        tau_e: Vector::<2>::from(te),
                    })
                    .expect("step");
                assert_eq!(ours.n, 2);
                assert_eq!(
                    &ours.tau_sat[..2],
                    theirs.tau_sat.as_slice(),
                    "{law:?} {preset:?} k={k}"
                );
                assert_eq!(&ours.tau[..2], theirs.tau.as_slice());
                assert_eq!(ours.w_norms, theirs.w_norms);
                assert!(ours.tau_sat[2..].iter().all(|v| *v == 0.0));
            }
        }
    }
}

#[test]
fn three_joints_with_user_centres_and_widths() {
    const N: usize = 3;
    let mut p = defaults(N, AdaptimpLaw::StateFeedback, AdaptimpPreset::Robot);
    p.tau_max[..N].copy_from_slice(&[40.0, 30.0, 20.0]);
    let nodes = 50;
    let centers: Vec<f64> = (0..nodes * 4 * N)
        .map(|i| ((i * 7919) % 200) as f64 / 100.0 - 1.0)
        .collect();
    let widths2: Vec<f64> = (0..4 * N).map(|i| 1.0 + i as f64).collect();
    p.centers = centers.as_ptr();
    p.nodes = nodes;
    p.widths2 = widths2.as_ptr();
    let c = Handles::new(&p).expect("controller");
    // SAFETY: valid handle.
    assert_eq!(unsafe { adaptimp_controller_joints(c.ctrl) }, N);
    // The same controller built in Rust.
    let widths: [Vector<N>; 4] =
        core::array::from_fn(|b| Vector::<N>::from_column_slice(&widths2[b * N..(b + 1) * N]));
    let basis =
        adaptimp::AnyBasis::Centers(adaptimp::Centers::new(centers.clone(), widths).unwrap());
    let s = adaptimp::Scenario::<N>::preset(adaptimp::Preset::Robot, Law::StateFeedback);
    let mut cfg = s.config;
    cfg.tau_max = Vector::<N>::new(40.0, 30.0, 20.0);
    let traj = s.trajectory().unwrap();
    let ctrl = Controller::for_trajectory(cfg, basis, &traj).unwrap();
    let mut st = ctrl.new_state();
    for k in 0..300 {
        let q = [0.1 * (k as f64 * 0.01).sin(), 0.2, -0.1];
        let dq = [0.01, 0.0, -0.02];
        let ours = c.step(&q, Some(&dq), &[0.0; 3]).expect("step");
        let sp = traj.sample(ctrl.time(&st));
        let theirs = ctrl
            .step(
                &mut st,
                &Measurement {
                    x: Vector::from(q),
                    dx: Some(Vector::from(dq)),
                    tau_e: Vector::zeros(),
                },
                &sp,
            )
            .unwrap();
        assert_eq!(&ours.tau_sat[..N], theirs.tau_sat.as_slice(), "k={k}");
    }
    // Mis-sized inputs are refused by status.
    assert_eq!(
        c.step(&[0.0; 2], Some(&[0.0; 2]), &[0.0; 2]).unwrap_err(),
        AdaptimpStatus::BadSize
    );
    assert!(
        last_error().contains("the controller has 3 joints"),
        "{}",
        last_error()
    );
}

#[test]
fn more_than_three_joints_without_centres_get_the_one_builders_default_basis() {
    // NULL centres with n > 3: the rule's centres along the commanded
    // trajectory (SPEC §18), as `dynamic::Scenario::controller` (Python's
    // builder too) makes them: the same torques, bit for bit.
    use adaptimp::dynamic;
    for n in 4..=7 {
        for (law, c_law) in [
            (Law::Pd, AdaptimpLaw::Pd),
            (Law::StateFeedback, AdaptimpLaw::StateFeedback),
            (Law::OutputFeedback, AdaptimpLaw::OutputFeedback),
        ] {
            let p = defaults(n, c_law, AdaptimpPreset::Robot);
            assert!(p.centers.is_null());
            let c = Handles::new(&p).expect("controller");
            let ctrl = dynamic::Scenario::new(n, adaptimp::Preset::Robot, law)
                .unwrap()
                .controller()
                .unwrap();
            assert!(ctrl.nodes() > 0);
            let mut st = ctrl.new_state();
            for k in 0..20 {
                let q: Vec<f64> = (0..n)
                    .map(|i| 0.1 * (0.01 * k as f64 + i as f64).sin())
                    .collect();
                let dq: Vec<f64> = (0..n).map(|i| 0.01 * i as f64).collect();
                let te = vec![0.0; n];
                let ours = c.step(&q, Some(&dq), &te).expect("step");
                let m = dynamic::Measurement {
                    x: &q,
                    dx: Some(&dq),
                    tau_e: &te,
                };
                let theirs = ctrl.step(&mut st, &m, None).unwrap();
                assert_eq!(&ours.tau_sat[..n], &*theirs.tau_sat, "n={n} {law:?} k={k}");
                assert_eq!(&ours.tau[..n], &*theirs.tau, "n={n} {law:?} k={k}");
            }
        }
    }
}

#[test]
fn a_snapshot_restored_continues_bit_identically_and_a_bad_one_changes_nothing() {
    let p = defaults(2, AdaptimpLaw::OutputFeedback, AdaptimpPreset::Robot);
    let (a, b) = (Handles::new(&p).unwrap(), Handles::new(&p).unwrap());
    for k in 0..100 {
        let (q, _, te) = inputs(k);
        a.step(&q, None, &te).unwrap();
    }
    // SAFETY: valid handles and buffers of the stated lengths.
    unsafe {
        let len = adaptimp_state_snapshot_len(a.state);
        let mut buf = vec![0.0; len];
        let mut written = 0;
        assert_eq!(
            adaptimp_state_save(a.state, buf.as_mut_ptr(), len, &mut written),
            AdaptimpStatus::Ok
        );
        assert_eq!(written, len);
        assert_eq!(
            adaptimp_state_restore(b.ctrl, b.state, buf.as_ptr(), len),
            AdaptimpStatus::Ok
        );
        assert_eq!(adaptimp_state_steps(b.state), 100);
        for k in 100..200 {
            let (q, _, te) = inputs(k);
            assert_eq!(
                a.step(&q, None, &te).unwrap(),
                b.step(&q, None, &te).unwrap()
            );
        }
        buf[3] += 1.0; // another number of nodes
        assert_eq!(
            adaptimp_state_restore(b.ctrl, b.state, buf.as_ptr(), len),
            AdaptimpStatus::BadSnapshot
        );
        assert!(last_error().contains("another number of joints or nodes"));
        assert_eq!(adaptimp_state_steps(b.state), 200);
        assert_eq!(
            adaptimp_state_restore(b.ctrl, b.state, ptr::null(), len),
            AdaptimpStatus::NullPointer
        );
        // A state of another size is refused by the step.
        let three = Handles::new(&{
            let mut p3 = defaults(3, AdaptimpLaw::Pd, AdaptimpPreset::Paper);
            p3.eta2 = 25.0;
            p3
        })
        .unwrap();
        let mut out: AdaptimpCommand = std::mem::zeroed();
        let q = [0.0; 2];
        let s = adaptimp_step(
            a.ctrl,
            three.state,
            2,
            q.as_ptr(),
            q.as_ptr(),
            q.as_ptr(),
            ptr::null(),
            &mut out,
        );
        assert_eq!(s, AdaptimpStatus::WrongState);
    }
}

#[test]
fn a_state_takes_over_a_robots_torque_before_its_first_step() {
    let mut p = defaults(2, AdaptimpLaw::StateFeedback, AdaptimpPreset::Robot);
    p.tau_rate_max[..2].copy_from_slice(&[0.5, 0.5]);
    let (a, cold) = (Handles::new(&p).unwrap(), Handles::new(&p).unwrap());
    let held = [6.0, -4.0];
    // SAFETY: valid handles; slices of the stated lengths.
    unsafe {
        assert_eq!(
            adaptimp_state_take_over(a.ctrl, a.state, held.as_ptr(), 3),
            AdaptimpStatus::BadSize
        );
        assert_eq!(
            adaptimp_state_take_over(a.ctrl, a.state, held.as_ptr(), 2),
            AdaptimpStatus::Ok
        );
    }
    let (q, dq, te) = inputs(0);
    let first = a.step(&q, Some(&dq), &te).unwrap();
    let from_zero = cold.step(&q, Some(&dq), &te).unwrap();
    for (i, h) in held.iter().enumerate() {
        assert!((first.tau_sat[i] - h).abs() <= 0.5 + 1e-12);
        assert!(from_zero.tau_sat[i].abs() <= 0.5 + 1e-12);
    }
    // SAFETY: as above.
    unsafe {
        assert_eq!(
            adaptimp_state_take_over(a.ctrl, a.state, held.as_ptr(), 2),
            AdaptimpStatus::InvalidConfig
        );
    }
    assert_eq!(last_error(), "take_over: only before the first step");
}

#[test]
fn the_circle_of_the_preset_is_the_default_setpoint() {
    // A NULL setpoint tracks the controller's own trajectory, as Tracker does.
    let c = Handles::new(&defaults(
        2,
        AdaptimpLaw::StateFeedback,
        AdaptimpPreset::Paper,
    ))
    .unwrap();
    let out = c
        .step(&[0.25, -0.05], Some(&[0.0, 0.0]), &[0.0, 0.0])
        .unwrap();
    assert_eq!(&out.xc[..2], Sinusoid::paper().sample(0.0).x.as_slice());
}

/// SPEC §18 through the C ABI: `adaptimp_params_suggest` fills the rule's
/// gains, centres and learning, and the controller it builds steps bit for
/// bit as the Rust rule's.
#[test]
fn the_rule_through_the_abi_is_the_cores() {
    use adaptimp::schema::{Preset, Scenario};
    use adaptimp::tuning::{default_task, Rule};
    use adaptimp::{Centers, Matrix};
    let d = [2.0, 0.5, 0.1, 0.5, 1.0, 0.2, 0.1, 0.2, 0.05];
    let tau = [50.0, 20.0, 5.0];
    let gravity = [0.0, -3.0, -0.4];
    let task = default_task(
        &Vector::<3>::zeros(),
        &Vector::from_element(-1.0),
        &Vector::from_element(1.0),
    )
    .expect("task");
    let path = Rule::sample(&task, 2.0);
    let rows: Vec<f64> = path
        .iter()
        .flat_map(|s| s.x.iter().chain(s.dx.iter()).chain(s.ddx.iter()).copied())
        .collect();
    let mut centers = vec![0.0; ADAPTIMP_SUGGEST_MAX_NODES * 12];
    let mut widths2 = [0.0; 12];
    let mut p = defaults(3, AdaptimpLaw::StateFeedback, AdaptimpPreset::Paper);
    // SAFETY: valid pointers with the documented lengths.
    let s = unsafe {
        adaptimp_params_suggest(
            &mut p,
            3,
            AdaptimpLaw::StateFeedback.into(),
            d.as_ptr(),
            tau.as_ptr(),
            1e-3,
            0,
            rows.as_ptr(),
            path.len(),
            2.0,
            gravity.as_ptr(),
            centers.as_mut_ptr(),
            widths2.as_mut_ptr(),
        )
    };
    assert_eq!(s, AdaptimpStatus::Ok, "{}", last_error());
    let sug = Rule::default()
        .suggest(
            Law::StateFeedback,
            &Matrix::<3>::from_row_slice(&d),
            &Vector::from(tau),
            1e-3,
            &path,
            2.0,
            Some(&Vector::from(gravity)),
        )
        .expect("rule");
    assert_eq!(&p.kp[..3], sug.config.kp.as_slice());
    assert_eq!(&p.inertia[..3], sug.config.inertia.as_slice());
    assert_eq!(p.conditions, AdaptimpConditions::Scaled.into());
    assert_eq!(p.gamma, sug.config.gamma);
    assert_eq!(p.nodes * 12, sug.centers.centers().len());
    assert_eq!(p.centers, centers.as_ptr());
    assert_eq!(&centers[..p.nodes * 12], sug.centers.centers());
    let traj = Scenario::<3>::preset(Preset::Robot, Law::StateFeedback)
        .trajectory()
        .expect("trajectory");
    let ctrl = Controller::for_trajectory(
        sug.config,
        Centers::new(sug.centers.centers().to_vec(), sug.centers.widths2()).expect("centres"),
        &traj,
    )
    .expect("the rule builds");
    let mut rust = Tracker::new(ctrl, traj);
    let c = Handles::new(&p).expect("the rule builds through the ABI");
    for k in 0..300 {
        let t = k as f64 * 1e-3;
        let q = [0.1 * t.sin(), -0.2 * t, 0.05];
        let dq = [0.1 * t.cos(), -0.2, 0.0];
        let ours = c.step(&q, Some(&dq), &[0.0; 3]).expect("step");
        let theirs = rust
            .step(&Measurement {
                x: Vector::from(q),
                dx: Some(Vector::from(dq)),
                tau_e: Vector::zeros(),
            })
            .expect("step");
        assert_eq!(&ours.tau_sat[..3], theirs.tau_sat.as_slice(), "k = {k}");
    }
    // Misuse is a status: a matrix that is not positive definite.
    let bad = [1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0];
    // SAFETY: valid pointers; no path.
    let s = unsafe {
        adaptimp_params_suggest(
            &mut p,
            3,
            AdaptimpLaw::Pd.into(),
            bad.as_ptr(),
            tau.as_ptr(),
            1e-3,
            0,
            ptr::null(),
            0,
            0.0,
            ptr::null(),
            ptr::null_mut(),
            ptr::null_mut(),
        )
    };
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(
        last_error().contains("positive definite"),
        "{}",
        last_error()
    );
}

/// SPEC (18.12) through the C ABI: with a delay the rule shapes the gains by
/// the inertia given (its only sample: Dₛ = D), without one it leaves
/// `inertia_matrix` empty (INFINITY first), as the core's `Tuning` does.
#[test]
fn the_rule_through_the_abi_shapes_the_gains_with_a_delay() {
    let d = [2.0, 0.5, 0.1, 0.5, 1.0, 0.2, 0.1, 0.2, 0.05];
    let tau = [50.0, 20.0, 5.0];
    let suggest = |delay: usize, coupling: u32| {
        let mut p = defaults(3, AdaptimpLaw::Pd, AdaptimpPreset::Robot);
        // SAFETY: valid pointers with the documented lengths; no path.
        let s = unsafe {
            adaptimp_params_suggest_coupling(
                &mut p,
                3,
                AdaptimpLaw::Pd.into(),
                d.as_ptr(),
                tau.as_ptr(),
                1e-3,
                delay,
                AdaptimpCouplingRaw(coupling),
                ptr::null(),
                0,
                0.0,
                ptr::null(),
                ptr::null_mut(),
                ptr::null_mut(),
            )
        };
        (s, p)
    };
    let ok = |delay: usize, coupling: AdaptimpCoupling| {
        let (s, p) = suggest(delay, coupling as u32);
        assert_eq!(s, AdaptimpStatus::Ok, "{}", last_error());
        p
    };
    let shaped = |p: &AdaptimpParams| {
        for (got, want) in p.inertia_matrix[..9].iter().zip(d) {
            assert!(
                (got - want).abs() <= 1e-12 * want,
                "{:?}",
                &p.inertia_matrix[..9]
            );
        }
    };
    // The rule's default, as adaptimp_params_suggest gives it: shaped with
    // a delay, diagonal without.
    assert_eq!(
        ok(0, AdaptimpCoupling::Default).inertia_matrix[0],
        f64::INFINITY
    );
    let p = ok(1, AdaptimpCoupling::Default);
    shaped(&p);
    let mut q = defaults(3, AdaptimpLaw::Pd, AdaptimpPreset::Robot);
    // SAFETY: valid pointers with the documented lengths; no path.
    let s = unsafe {
        adaptimp_params_suggest(
            &mut q,
            3,
            AdaptimpLaw::Pd.into(),
            d.as_ptr(),
            tau.as_ptr(),
            1e-3,
            1,
            ptr::null(),
            0,
            0.0,
            ptr::null(),
            ptr::null_mut(),
            ptr::null_mut(),
        )
    };
    assert_eq!(s, AdaptimpStatus::Ok, "{}", last_error());
    assert_eq!(q.inertia_matrix, p.inertia_matrix);
    assert_eq!(q.kp, p.kp);
    // Either at any delay, as asked.
    assert_eq!(
        ok(1, AdaptimpCoupling::Diagonal).inertia_matrix[0],
        f64::INFINITY
    );
    shaped(&ok(0, AdaptimpCoupling::Shaped));
    // The rate Kp/d is the same on every joint (SPEC (18.12)), and the
    // controller builds from what the ABI filled.
    let rate = p.kp[0] / p.inertia[0];
    for i in 1..3 {
        assert!((p.kp[i] / p.inertia[i] - rate).abs() <= 1e-12 * rate);
    }
    Handles::new(&p).expect("the shaped rule builds through the ABI");
    // A value outside the enum is refused by name.
    let (s, _) = suggest(1, 7);
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(last_error().contains("coupling"), "{}", last_error());
}

/// The rule's inputs in one struct (`AdaptimpTuning`): misuse is a status
/// naming the field, and `*out` is left as it was.
#[test]
fn the_rule_struct_refuses_by_name() {
    let d = [2.0, 0.5, 0.5, 1.0];
    let tau = [50.0, 20.0];
    let orbit = [0.1, 0.2, f64::NAN, 0.3];
    // One period of 2 s, 400 rows of q, q̇, q̈.
    let path: Vec<f64> = (0..400)
        .flat_map(|k| {
            let (w, t) = (std::f64::consts::PI, k as f64 * 0.005);
            let (s, c) = (0.3 * (w * t).sin(), 0.3 * (w * t).cos());
            [s, 0.5 * s, w * c, 0.5 * w * c, -w * w * s, -0.5 * w * w * s]
        })
        .collect();
    let call = |edit: &dyn Fn(&mut AdaptimpTuning)| {
        let mut t = std::mem::MaybeUninit::<AdaptimpTuning>::uninit();
        // SAFETY: a valid out pointer; the inputs are stored, not read.
        let s = unsafe {
            adaptimp_tuning_init(
                t.as_mut_ptr(),
                AdaptimpLaw::StateFeedback.into(),
                d.as_ptr(),
                tau.as_ptr(),
                1e-3,
            )
        };
        assert_eq!(s, AdaptimpStatus::Ok);
        // SAFETY: initialised by the call above.
        let mut t = unsafe { t.assume_init() };
        edit(&mut t);
        let mut p = defaults(2, AdaptimpLaw::Pd, AdaptimpPreset::Paper);
        let before = p;
        let mut centers = vec![0.0; ADAPTIMP_SUGGEST_MAX_NODES * 8];
        let mut widths2 = [0.0; 8];
        // SAFETY: valid pointers with the documented lengths.
        let s = unsafe {
            adaptimp_params_suggest_tuning(
                &mut p,
                2,
                &t,
                centers.as_mut_ptr(),
                widths2.as_mut_ptr(),
            )
        };
        if s != AdaptimpStatus::Ok {
            assert_eq!(p, before, "*out changed on {s:?}");
        }
        (s, last_error())
    };
    assert_eq!(call(&|_| {}).0, AdaptimpStatus::Ok);
    let (s, e) = call(&|t| t.resolve = AdaptimpBoolRaw(2));
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert_eq!(e, "resolve = 2 is not a bool (0 or 1)");
    let (s, e) = call(&|t| t.coupling = AdaptimpCouplingRaw(3));
    assert_eq!(s, AdaptimpStatus::InvalidConfig);
    assert!(e.contains("coupling"), "{e}");
    let (s, e) = call(&|t| t.inertia_samples = usize::MAX);
    assert_eq!(s, AdaptimpStatus::BadSize);
    assert!(e.contains("inertia_samples × n² overflows"), "{e}");
    let (s, e) = call(&|t| {
        t.path = path.as_ptr();
        t.rows = 400;
        t.period = 2.0;
        t.orbit = orbit.as_ptr();
        t.orbit_rows = 2;
    });
    assert_eq!(s, AdaptimpStatus::InvalidConfig, "{e}");
    assert!(e.contains("orbit"), "{e}");
    // What is read with a path only is refused without one, by name.
    let g = [1.0, 2.0];
    let with_orbit = |t: &mut AdaptimpTuning| {
        t.orbit = orbit.as_ptr();
        t.orbit_rows = 1;
    };
    let with_gravity = |t: &mut AdaptimpTuning| t.gravity = g.as_ptr();
    for (what, edit) in [
        ("orbit", &with_orbit as &dyn Fn(&mut AdaptimpTuning)),
        ("gravity", &with_gravity),
    ] {
        let (s, e) = call(edit);
        assert_eq!(s, AdaptimpStatus::InvalidConfig, "{e}");
        assert!(
            e.contains(&format!("{what}: is read with the task's path only")),
            "{e}"
        );
    }
    let mut p = defaults(2, AdaptimpLaw::Pd, AdaptimpPreset::Paper);
    // SAFETY: a NULL struct is refused before anything is read.
    let s = unsafe {
        adaptimp_params_suggest_tuning(&mut p, 2, ptr::null(), ptr::null_mut(), ptr::null_mut())
    };
    assert_eq!(s, AdaptimpStatus::NullPointer);
    assert!(last_error().contains("tuning"), "{}", last_error());
}
