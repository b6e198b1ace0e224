//! Reliability: configurations that would hang or overflow are refused at
//! construction by named conditions; the step is transactional (a spike is
//! refused and changes nothing); the fail-safe step, the fault policy, the
//! plausibility limits and the torque rate limit.

use adaptimp::{
    Config, Controller, Error, Fallback, FaultPolicy, Grid, HeapState, Law, Measurement, SimConfig,
    Sinusoid, Trajectory, Vector,
};

fn robot(law: Law) -> Config<2> {
    Config::robot(law)
}

fn build(cfg: Config<2>) -> Result<Controller<2>, Error> {
    Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper())
}

fn condition(e: Error) -> &'static str {
    match e {
        Error::Condition { condition, .. } => condition,
        other => panic!("not a condition: {other:?}"),
    }
}

/// A change to a configuration.
type Mutation = Box<dyn Fn(&mut Config<2>)>;

#[test]
fn configurations_that_hung_or_overflowed_are_refused_by_name() {
    let cases: [(&str, Mutation); 6] = [
        // nalgebra's matrix exponential never returned for these (issue 13).
        ("Ts/ε ≤ 1e6", Box::new(|c| c.eps = 1e-80)),
        ("Ts ≤ 1 s", Box::new(|c| c.ts = 1e45)),
        ("|value| ≤ 1e9", Box::new(|c| c.k1[0] = 1e300)),
        ("|value| ≤ 1e9", Box::new(|c| c.gamma[1] = 1e20)),
        ("Ts Γ σ < 1", Box::new(|c| c.sigma = [10.0; 3])),
        ("λ1 ≤ 1e6", Box::new(|c| c.lam1[1] = 1e8)),
    ];
    for (expect, mutate) in cases {
        let mut cfg = robot(Law::OutputFeedback);
        mutate(&mut cfg);
        assert_eq!(condition(build(cfg).unwrap_err()), expect);
    }
    // The trajectory's magnitudes are bounded where it is built.
    let big = |o: f64, a: f64, w: f64| {
        Sinusoid::new(
            Vector::<2>::from_element(o),
            Vector::<2>::from_element(a),
            Vector::zeros(),
            Vector::from_element(w),
        )
    };
    assert_eq!(
        condition(big(1e300, 0.0, 1.0).unwrap_err()),
        "|xc| ≤ 1e6 rad"
    );
    assert_eq!(
        condition(big(0.0, 0.2, 1e300).unwrap_err()),
        "|ẋc| ≤ 1e6 rad/s"
    );
    assert_eq!(
        condition(big(0.0, 0.2, 1e4).unwrap_err()),
        "|ẍc| ≤ 1e6 rad/s²"
    );
    assert!(
        big(0.0, 0.0, 1e300).is_ok(),
        "a frequency without amplitude moves nothing"
    );
    // substeps has an upper bound (2^31 would run for days).
    let sim = SimConfig {
        substeps: 1 << 31,
        ..SimConfig::paper()
    };
    let e = adaptimp::RigidBody::new(
        adaptimp::TwoLinkArm::paper(),
        adaptimp::Wall::paper(),
        sim.q0,
        sim.dq0,
        sim.substeps,
    )
    .unwrap_err();
    assert_eq!(condition(e), "1 ≤ substeps ≤ 10 000");
}

fn measurement(k: usize) -> Measurement<2> {
    let s = k as f64 * 1e-3;
    Measurement {
        x: Vector::<2>::new(0.2 + 0.1 * s.sin(), 0.2 + 0.1 * s.cos()),
        dx: Some(Vector::<2>::new(0.1 * s.cos(), -0.1 * s.sin())),
        tau_e: Vector::<2>::new((10.0 * s.sin()).max(0.0), 0.0),
    }
}

fn snapshot(st: &HeapState<2>) -> Vec<f64> {
    let mut v = vec![0.0; st.snapshot_len()];
    st.save(&mut v).expect("save");
    v
}

/// The snapshot of what the control law uses: without the refusal record a
/// refused step writes (the applied torque, the last measured position: N
/// values each) and the checksum, the snapshot's last 2N + 1 values.
fn control(st: &HeapState<2>) -> Vec<f64> {
    let mut v = snapshot(st);
    v.truncate(v.len() - 2 * 2 - 1);
    v
}

fn step(
    c: &Controller<2>,
    st: &mut HeapState<2>,
    m: &Measurement<2>,
) -> Result<adaptimp::Command<2>, Error> {
    let sp = Sinusoid::paper().sample(c.time(st));
    c.step(st, m, &sp)
}

#[test]
fn a_finite_spike_is_refused_and_poisons_nothing() {
    for cfg in [
        Config::paper(Law::StateFeedback),
        robot(Law::StateFeedback),
        robot(Law::OutputFeedback),
        robot(Law::Pd),
    ] {
        let c = build(cfg).unwrap();
        let (mut st, mut twin) = (c.new_state(), c.new_state());
        for k in 0..1000 {
            step(&c, &mut st, &measurement(k)).unwrap();
            step(&c, &mut twin, &measurement(k)).unwrap();
        }
        let before = control(&st);
        let m = measurement(1000);
        let spikes = [
            Measurement {
                x: Vector::<2>::new(1e151, 0.2),
                ..m
            },
            Measurement {
                dx: Some(Vector::<2>::new(0.0, -1e151)),
                ..m
            },
            Measurement {
                tau_e: Vector::<2>::new(1e155, 0.0),
                ..m
            },
            Measurement {
                x: Vector::<2>::new(1e300, -1e300),
                ..m
            },
        ];
        for (i, spike) in spikes.into_iter().enumerate() {
            if i == 1 && c.config().law == Law::OutputFeedback {
                continue; // output feedback ignores a measured velocity
            }
            let e = step(&c, &mut st, &spike).unwrap_err();
            assert!(matches!(e, Error::OutOfRange { .. }), "{e:?}");
            assert_eq!(control(&st), before, "{e}");
            assert_eq!(st.fault().map(|f| f.step), Some(1000));
        }
        // Nothing learned was lost: the run continues exactly as its twin's.
        for k in 1000..1500 {
            assert_eq!(
                step(&c, &mut st, &measurement(k)),
                step(&c, &mut twin, &measurement(k))
            );
        }
    }
}

#[test]
fn a_subnormal_mu_does_not_divide_by_zero() {
    // Found by fuzzing (fuzz/fuzz_targets/config.rs): μ = 9.7e-309 passed
    // μ > 0, μ² underflowed to 0, and ‖ζ‖ = 0 counted as outside the ball.
    let mut cfg = robot(Law::Pd);
    cfg.mu = 9.734889110590228e-309;
    let c = build(cfg).unwrap();
    let mut st = c.new_state();
    let m = Measurement {
        x: Vector::<2>::zeros(),
        dx: Some(Vector::zeros()),
        tau_e: Vector::zeros(),
    };
    for _ in 0..3 {
        let cmd = step(&c, &mut st, &m).unwrap();
        assert!(cmd.tau_sat.iter().all(|t| t.is_finite()), "{cmd:?}");
        assert!(st.zeta().iter().all(|z| z.is_finite()));
    }
}

#[test]
fn a_subnormal_width_is_refused() {
    // Found by fuzzing: η² = 9.1e-316 passed η² > 0, 1/η² overflowed, and the
    // basis at a centre was exp(−0·∞) = NaN.
    let e = Grid::<2>::new(9.1155762e-316).unwrap_err();
    assert_eq!(condition(e), "η² ≥ 1e-12");
    let e = adaptimp::Centers::<1, _>::new([0.0; 4], [Vector::<1>::new(1e-300); 4]).unwrap_err();
    assert_eq!(condition(e), "η² ≥ 1e-12");
}

#[test]
fn the_fallback_is_returned_with_the_error() {
    let nan = Measurement {
        x: Vector::<2>::new(f64::NAN, 0.0),
        ..measurement(0)
    };
    for (fallback, expect) in [
        (Fallback::Hold, None),
        (Fallback::Zero, Some(Vector::<2>::zeros())),
        (Fallback::Damping, Some(Vector::<2>::new(-2.0 * 0.1, 0.0))),
    ] {
        let mut cfg = robot(Law::StateFeedback);
        cfg.fallback = fallback;
        cfg.fallback_damping = Vector::from_element(2.0);
        let c = build(cfg).unwrap();
        let mut st = c.new_state();
        let mut last = Vector::zeros();
        for k in 0..100 {
            last = step(&c, &mut st, &measurement(k)).unwrap().tau_sat;
        }
        let m = Measurement {
            dx: Some(Vector::<2>::new(0.1, 0.0)),
            ..nan
        };
        let sp = Sinusoid::paper().sample(c.time(&st));
        let (tau, result) = c.step_or_fallback(&mut st, &m, &sp);
        assert!(
            matches!(result, Err(Error::NonFinite { what: "x", .. })),
            "{result:?}"
        );
        assert_eq!(tau, expect.unwrap_or(last), "{fallback:?}");
        assert_eq!(st.fault().unwrap().error, result.unwrap_err());
    }
    // Damping is saturated like every command.
    let mut cfg = robot(Law::Pd);
    cfg.fallback = Fallback::Damping;
    cfg.fallback_damping = Vector::from_element(1e6);
    let c = build(cfg).unwrap();
    let mut st = c.new_state();
    let m = Measurement {
        dx: Some(Vector::<2>::new(1.0, -1.0)),
        ..nan
    };
    let (tau, _) = c.step_or_fallback(&mut st, &m, &Sinusoid::paper().sample(0.0));
    assert_eq!(tau, Vector::<2>::new(-17.0, 15.0));
}

#[test]
fn a_latched_fault_refuses_steps_until_cleared() {
    let mut cfg = robot(Law::StateFeedback);
    cfg.fault_policy = FaultPolicy::Latch;
    let c = build(cfg).unwrap();
    let (mut st, mut twin) = (c.new_state(), c.new_state());
    for k in 0..200 {
        step(&c, &mut st, &measurement(k)).unwrap();
        step(&c, &mut twin, &measurement(k)).unwrap();
    }
    let bad = Measurement {
        tau_e: Vector::<2>::new(f64::INFINITY, 0.0),
        ..measurement(200)
    };
    assert!(step(&c, &mut st, &bad).is_err());
    let e = step(&c, &mut st, &measurement(200)).unwrap_err();
    assert_eq!(
        e,
        Error::Faulted {
            reason: "non-finite input"
        }
    );
    assert!(e.to_string().contains("until clear_fault()"), "{e}");
    assert_eq!(st.steps(), 200);
    st.clear_fault();
    for k in 200..300 {
        assert_eq!(
            step(&c, &mut st, &measurement(k)),
            step(&c, &mut twin, &measurement(k))
        );
    }
}

#[test]
fn plausibility_limits_refuse_a_measurement_and_change_nothing() {
    let mut cfg = robot(Law::StateFeedback);
    cfg.limits.q = Vector::from_element(1.0);
    cfg.limits.dq = Vector::from_element(2.0);
    cfg.limits.tau_e = Vector::from_element(100.0);
    cfg.limits.q_jump = Vector::from_element(0.05);
    let c = build(cfg).unwrap();
    let mut st = c.new_state();
    for k in 0..10 {
        step(&c, &mut st, &measurement(k)).unwrap();
    }
    let before = control(&st);
    let m = measurement(10);
    for (bad, what) in [
        (
            Measurement {
                x: Vector::<2>::new(1.5, 0.2),
                ..m
            },
            "q",
        ),
        (
            Measurement {
                dx: Some(Vector::<2>::new(0.0, 3.0)),
                ..m
            },
            "dq",
        ),
        (
            Measurement {
                tau_e: Vector::<2>::new(150.0, 0.0),
                ..m
            },
            "tau_e",
        ),
        (
            Measurement {
                x: m.x + Vector::<2>::new(0.0, 0.1),
                ..m
            },
            "q jump",
        ),
    ] {
        match step(&c, &mut st, &bad).unwrap_err() {
            Error::OutOfRange { what: w, .. } => assert_eq!(w, what),
            other => panic!("{other:?}"),
        }
        assert_eq!(control(&st), before);
    }
    assert!(step(&c, &mut st, &m).is_ok());
}

#[test]
fn the_rate_limit_bounds_the_change_of_torque_and_shows_in_dtau() {
    let mut cfg = robot(Law::StateFeedback);
    cfg.limits.tau_rate = Vector::from_element(0.5);
    let c = build(cfg).unwrap();
    let mut st = c.new_state();
    let mut last = Vector::<2>::zeros();
    let mut limited = false;
    for k in 0..500 {
        let cmd = step(&c, &mut st, &measurement(k)).unwrap();
        assert!((cmd.tau_sat - last).amax() <= 0.5 + 1e-12, "k={k}");
        assert_eq!(cmd.dtau, cmd.tau_sat - cmd.tau);
        limited |= cmd.dtau.amax() > 0.0 && cmd.tau.amax() < 15.0;
        last = cmd.tau_sat;
    }
    assert!(limited, "the rate limit acted below the saturation limits");
}

#[test]
fn a_controller_takes_over_the_torque_it_is_handed() {
    // The first step's rate limit moves from the torque taken over (what a
    // robot's own controller held the arm with), not from zero.
    let mut cfg = robot(Law::StateFeedback);
    cfg.limits.tau_rate = Vector::from_element(0.5);
    let c = build(cfg).unwrap();
    let held = Vector::<2>::new(6.0, -4.0);
    let mut cold = c.new_state();
    let mut st = c.new_state();
    c.take_over(&mut st, &held).unwrap();
    assert_eq!(st.applied(), &held);
    let first = step(&c, &mut st, &measurement(0)).unwrap();
    assert!(
        (first.tau_sat - held).amax() <= 0.5 + 1e-12,
        "{}",
        first.tau_sat
    );
    let from_zero = step(&c, &mut cold, &measurement(0)).unwrap();
    assert!(from_zero.tau_sat.amax() <= 0.5 + 1e-12);
    // Only before the first step; finite; within τmax. Nothing changes on an error.
    let e = c.take_over(&mut st, &held).unwrap_err();
    assert_eq!(e.to_string(), "take_over: only before the first step");
    let mut fresh = c.new_state();
    let e = c
        .take_over(&mut fresh, &Vector::<2>::new(f64::NAN, 0.0))
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "torque taken over[0] is not finite (NaN or infinite)"
    );
    let e = c
        .take_over(&mut fresh, &Vector::<2>::new(0.0, 1e3))
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "torque taken over[1] = 1e3 is beyond its limit ±1.5e1; the state was left unchanged"
    );
    assert_eq!(fresh.applied(), &Vector::<2>::zeros());
    // reset: back to zero.
    st.reset();
    assert_eq!(st.applied(), &Vector::<2>::zeros());
}

/// The URDF reader (SPEC §21) on documents no robot file is: nested 100 000
/// deep (the XML reader builds and drops elements recursively: this
/// overflowed the stack, and 10⁶ deep took minutes), a device that never
/// ends, a directory. Each is a refusal that says why, at once.
#[cfg(feature = "urdf")]
#[test]
fn descriptions_that_would_overflow_or_never_end_are_refused() {
    use adaptimp::description::urdf;
    for depth in [1001, 100_000, 1_000_000] {
        let text = format!(
            "<robot name='r'>{}{}</robot>",
            "<a>".repeat(depth),
            "</a>".repeat(depth)
        );
        let e = urdf::read_str(&text).expect_err("nested too deep");
        assert!(
            e.to_string()
                .contains("its elements nest more than 1000 deep (a URDF nests 5)"),
            "{e}"
        );
        assert_eq!(urdf::kind_of(&text), "unknown");
    }
    // 999 deep (with comments, CDATA and quoted '>' that do not count) reads
    // as XML and as a (linkless) URDF.
    let text = format!(
        "<robot name='r'><!-- <a><a> --><![CDATA[<a>]]>{}<b c='>'/>{}</robot>",
        "<a x=\"<a>\">".repeat(998),
        "</a>".repeat(998)
    );
    assert_eq!(urdf::kind_of(&text), "urdf");
    let tree = urdf::read_str(&text).expect("999 deep is XML");
    assert!(tree.links().is_empty());
    for (path, why) in [
        (
            "/dev/zero",
            "it is not a regular file (a device or a pipe), not a URDF",
        ),
        ("/", "it is a directory"),
    ] {
        let e = urdf::read_file(path).expect_err("not a file");
        assert_eq!(
            e.to_string(),
            format!("cannot read the URDF '{path}': {why}: give the path of a URDF file")
        );
    }
}

/// A URDF limit that is not a number, or a negative effort or speed, is
/// refused by name (NaN made a revolute joint continuous, silently).
#[cfg(feature = "urdf")]
#[test]
fn a_urdf_limit_that_is_not_a_number_is_refused() {
    use adaptimp::description::urdf;
    for (attr, value) in [
        ("lower", "nan"),
        ("upper", "nan"),
        ("effort", "nan"),
        ("effort", "-1"),
        ("velocity", "-3"),
    ] {
        let mut limit = std::collections::BTreeMap::from([
            ("lower", "-1"),
            ("upper", "1"),
            ("effort", "5"),
            ("velocity", "2"),
        ]);
        limit.insert(attr, value);
        let text = format!(
            "<robot name='r'><link name='a'/><link name='b'/><joint name='j' type='revolute'>\
             <parent link='a'/><child link='b'/><limit lower='{}' upper='{}' effort='{}' \
             velocity='{}'/></joint></robot>",
            limit["lower"], limit["upper"], limit["effort"], limit["velocity"]
        );
        let e = urdf::read_str(&text).expect_err("refused");
        let v = if value == "nan" { "NaN" } else { value };
        assert!(
            e.to_string().starts_with(&format!(
                "URDF text: joint 'j' has <limit {attr}=\"{v}\">: give a number"
            )),
            "{e}"
        );
    }
}
