//! The fault semantics of docs/reliability.md, row by row, through the Rust
//! front (issue 20, items 1–5): every refusal latches; the torque after a
//! refusal is the fallback and the rate limit starts from it; the jump limit
//! re-anchors on the measured positions; a setpoint is checked like a
//! measurement and a reference that would leave the ceilings is refused;
//! what `clear_fault` and `reset` keep; `restore` refuses what it could not
//! step.

use adaptimp::{
    Command, Config, Controller, Error, Fallback, FaultPolicy, Grid, HeapState, Law, Measurement,
    Setpoint, Sinusoid, Trajectory, Vector, Weights,
};

fn build(cfg: Config<2>) -> Controller<2> {
    Controller::for_trajectory(cfg, Grid::paper(), &Sinusoid::paper()).expect("valid")
}

fn measurement(k: usize) -> Measurement<2> {
    let s = k as f64 * 1e-3;
    Measurement {
        x: Vector::<2>::new(0.2 + 0.1 * s.sin(), 0.2 + 0.1 * s.cos()),
        dx: Some(Vector::<2>::new(0.1 * s.cos(), -0.1 * s.sin())),
        tau_e: Vector::<2>::zeros(),
    }
}

fn circle(c: &Controller<2>, st: &HeapState<2>) -> Setpoint<2> {
    Sinusoid::paper().sample(c.time(st))
}

fn step(c: &Controller<2>, st: &mut HeapState<2>, m: &Measurement<2>) -> Result<Command<2>, Error> {
    let sp = circle(c, st);
    c.step(st, m, &sp)
}

fn snapshot(st: &HeapState<2>) -> Vec<f64> {
    let mut v = vec![0.0; st.snapshot_len()];
    st.save(&mut v).expect("save");
    v
}

/// What the control law uses: the snapshot without the refusal record (the
/// applied torque and the last measured position, N values each) and the
/// checksum, its last 2N + 1 values.
fn control(st: &HeapState<2>) -> Vec<f64> {
    let mut v = snapshot(st);
    v.truncate(v.len() - 2 * 2 - 1);
    v
}

fn nan_q(k: usize) -> Measurement<2> {
    Measurement {
        x: Vector::<2>::new(f64::NAN, 0.2),
        ..measurement(k)
    }
}

#[test]
fn every_refusal_latches_and_the_fault_that_latched_is_kept() {
    let mut cfg = Config::robot(Law::StateFeedback);
    cfg.fault_policy = FaultPolicy::Latch;
    let c = build(cfg);
    let mut st = c.new_state();
    for k in 0..10 {
        step(&c, &mut st, &measurement(k)).unwrap();
    }
    let e = step(&c, &mut st, &nan_q(10)).unwrap_err();
    assert_eq!(
        e,
        Error::NonFinite {
            what: "x",
            index: 0
        }
    );
    // Refused until cleared, with the first fault kept (not overwritten by
    // the refusals it causes).
    for _ in 0..3 {
        let e = step(&c, &mut st, &measurement(10)).unwrap_err();
        assert!(
            matches!(
                e,
                Error::Faulted {
                    reason: "non-finite input"
                }
            ),
            "{e}"
        );
        let f = st.fault().unwrap();
        assert_eq!(
            (f.error, f.step),
            (
                Error::NonFinite {
                    what: "x",
                    index: 0
                },
                10
            )
        );
    }
    st.clear_fault();
    assert!(step(&c, &mut st, &measurement(10)).is_ok());
    // A call a front refused before the core saw it (a wrong shape, a NULL
    // pointer) latches the same way.
    let bad = Error::Invalid {
        what: "step",
        reason: "an argument had the wrong shape",
    };
    let tau = c.refuse(&mut st, bad);
    assert_eq!(tau, *st.applied());
    assert_eq!(st.fault().unwrap().error, bad);
    assert!(matches!(
        step(&c, &mut st, &measurement(11)),
        Err(Error::Faulted { .. })
    ));
}

#[test]
fn the_rate_limit_starts_from_the_fallback_applied() {
    // Issue 20 item 2: steady at the limits [17, 15], a NaN sample applies
    // the zero fallback, and the next sample used to apply [17, 15] at once.
    let mut cfg = Config::robot(Law::Pd);
    cfg.fallback = Fallback::Zero;
    cfg.limits.tau_rate = Vector::from_element(1.0);
    for policy in [FaultPolicy::Report, FaultPolicy::Latch] {
        cfg.fault_policy = policy;
        let c = build(cfg);
        let mut st = c.new_state();
        let m = Measurement {
            x: Vector::zeros(),
            dx: Some(Vector::zeros()),
            tau_e: Vector::zeros(),
        };
        let far = Setpoint {
            x: Vector::<2>::new(1.0, 1.0),
            dx: Vector::zeros(),
            ddx: Vector::zeros(),
        };
        let mut tau = Vector::zeros();
        for _ in 0..200 {
            tau = c.step_or_fallback(&mut st, &m, &far).0;
        }
        assert_eq!(tau, Vector::<2>::new(17.0, 15.0));
        let bad = Measurement {
            x: Vector::<2>::new(f64::NAN, 0.0),
            ..m
        };
        let (tau, r) = c.step_or_fallback(&mut st, &bad, &far);
        assert!(r.is_err());
        assert_eq!(tau, Vector::<2>::zeros());
        assert_eq!(*st.applied(), Vector::<2>::zeros());
        if policy == FaultPolicy::Latch {
            // Still refused, still the fallback, until cleared.
            let (tau, r) = c.step_or_fallback(&mut st, &m, &far);
            assert!(matches!(r, Err(Error::Faulted { .. })));
            assert_eq!(tau, Vector::<2>::zeros());
            st.clear_fault();
        }
        // Recovery: the torque climbs back at 1 N m per step from zero.
        for k in 1..=20 {
            let (tau, r) = c.step_or_fallback(&mut st, &m, &far);
            assert!(r.is_ok());
            let expect = Vector::<2>::new((k as f64).min(17.0), (k as f64).min(15.0));
            assert_eq!(tau, expect, "step {k} after the refusal ({policy:?})");
        }
    }
}

#[test]
fn the_hold_fallback_holds_the_torque_last_applied() {
    let mut cfg = Config::robot(Law::StateFeedback);
    cfg.fallback = Fallback::Hold;
    let c = build(cfg);
    let mut st = c.new_state();
    let mut last = Vector::zeros();
    for k in 0..50 {
        last = step(&c, &mut st, &measurement(k)).unwrap().tau_sat;
    }
    for _ in 0..3 {
        let sp = circle(&c, &st);
        assert_eq!(c.step_or_fallback(&mut st, &nan_q(50), &sp).0, last);
    }
}

#[test]
fn a_real_motion_during_refused_steps_does_not_lock_the_jump_limit() {
    // Issue 20 item 3: the jump was measured from the last accepted position
    // only, so a 0.61 rad motion made during refused steps was refused for
    // ever (and clear_fault did not help).
    for policy in [FaultPolicy::Report, FaultPolicy::Latch] {
        let mut cfg = Config::robot(Law::StateFeedback);
        cfg.limits.q_jump = Vector::from_element(0.05);
        cfg.fault_policy = policy;
        let c = build(cfg);
        let mut st = c.new_state();
        for k in 0..100 {
            step(&c, &mut st, &measurement(k)).unwrap();
        }
        // 100 samples with a NaN velocity while the arm moves 0.61 rad.
        for k in 0..100 {
            let m = Measurement {
                x: measurement(100).x + Vector::<2>::new(0.0061 * k as f64, 0.0),
                dx: Some(Vector::<2>::new(f64::NAN, 0.0)),
                ..measurement(100)
            };
            assert!(step(&c, &mut st, &m).is_err());
        }
        if policy == FaultPolicy::Latch {
            st.clear_fault();
        }
        let moved = Measurement {
            x: measurement(100).x + Vector::<2>::new(0.61, 0.0),
            ..measurement(100)
        };
        // The position followed the samples: no jump, accepted at once.
        assert!(step(&c, &mut st, &moved).is_ok(), "{policy:?}");
        assert_eq!(st.anchors(), [&moved.x, &moved.x]);
    }
    // With no plausible sample during the refusals (NaN positions), the first
    // sample after them is a jump: refused once, then accepted.
    let mut cfg = Config::robot(Law::StateFeedback);
    cfg.limits.q_jump = Vector::from_element(0.05);
    let c = build(cfg);
    let mut st = c.new_state();
    for k in 0..100 {
        step(&c, &mut st, &measurement(k)).unwrap();
    }
    for _ in 0..100 {
        assert!(step(&c, &mut st, &nan_q(100)).is_err());
    }
    let moved = |dx: f64| Measurement {
        x: measurement(100).x + Vector::<2>::new(0.61 + dx, 0.0),
        ..measurement(100)
    };
    let e = step(&c, &mut st, &moved(0.0)).unwrap_err();
    assert!(matches!(e, Error::OutOfRange { what: "q jump", .. }), "{e}");
    for k in 1..1000 {
        assert!(step(&c, &mut st, &moved(1e-4 * k as f64)).is_ok(), "{k}");
    }
}

#[test]
fn a_one_sample_glitch_is_refused_once() {
    let mut cfg = Config::robot(Law::StateFeedback);
    cfg.limits.q_jump = Vector::from_element(0.05);
    let c = build(cfg);
    let (mut st, mut twin) = (c.new_state(), c.new_state());
    for k in 0..100 {
        step(&c, &mut st, &measurement(k)).unwrap();
        step(&c, &mut twin, &measurement(k)).unwrap();
    }
    let glitch = Measurement {
        x: measurement(100).x + Vector::<2>::new(0.0, 0.5),
        ..measurement(100)
    };
    let e = step(&c, &mut st, &glitch).unwrap_err();
    assert!(matches!(e, Error::OutOfRange { what: "q jump", .. }), "{e}");
    // The next true sample is within the limit of the last accepted one:
    // accepted, and the run goes on as the twin's that never saw the glitch.
    for k in 100..200 {
        assert_eq!(
            step(&c, &mut st, &measurement(k)),
            step(&c, &mut twin, &measurement(k))
        );
    }
}

#[test]
fn a_setpoint_is_checked_like_a_measurement_and_a_refused_one_changes_nothing() {
    // Issue 20 item 4: ẋc = 1e99 was accepted and committed a reference
    // every later step refused, for ever (even after clear_fault).
    let mut cfg = Config::robot(Law::StateFeedback);
    cfg.limits.q = Vector::from_element(3.0);
    cfg.limits.dq = Vector::from_element(10.0);
    let c = build(cfg);
    let (mut st, mut twin) = (c.new_state(), c.new_state());
    for k in 0..100 {
        step(&c, &mut st, &measurement(k)).unwrap();
        step(&c, &mut twin, &measurement(k)).unwrap();
    }
    let m = measurement(100);
    let sp = circle(&c, &st);
    let with = |f: &dyn Fn(&mut Setpoint<2>)| {
        let mut s = sp;
        f(&mut s);
        s
    };
    for (bad, what, limit) in [
        (with(&|s| s.dx[0] = 1e99), "dxc", 10.0),
        (with(&|s| s.x[0] = 1e50), "xc", 3.0),
        (with(&|s| s.x[1] = -3.5), "xc", 3.0),
        (with(&|s| s.dx[1] = 10.5), "dxc", 10.0),
        (with(&|s| s.ddx[0] = 2e6), "ddxc", 1e6),
    ] {
        let before = control(&st);
        match c.step(&mut st, &m, &bad).unwrap_err() {
            Error::OutOfRange {
                what: w, limit: l, ..
            } => assert_eq!((w, l), (what, limit)),
            other => panic!("{other:?}"),
        }
        assert_eq!(control(&st), before);
    }
    for k in 100..200 {
        assert_eq!(
            step(&c, &mut st, &measurement(k)),
            step(&c, &mut twin, &measurement(k))
        );
    }
    // Without configured limits the ceilings hold: 1e6 rad, 1e6 rad/s.
    let c = build(Config::paper(Law::StateFeedback));
    let mut st = c.new_state();
    let e = c.step(&mut st, &m, &with(&|s| s.x[0] = 1e50)).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("xc[0] = 1e50 is beyond its limit ±1e6"),
        "{e}"
    );
    let e = c.step(&mut st, &m, &with(&|s| s.dx[0] = 1e99)).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("dxc[0] = 1e99 is beyond its limit ±1e6"),
        "{e}"
    );
}

#[test]
fn a_force_that_would_throw_the_reference_beyond_the_ceilings_is_refused() {
    // τe = 1e99 used to be accepted and to commit ẋd ≈ 1e96: every later step
    // was refused (the weights' update overflowed), for ever.
    let c = build(Config::robot(Law::StateFeedback));
    let mut st = c.new_state();
    for k in 0..100 {
        step(&c, &mut st, &measurement(k)).unwrap();
    }
    let spike = Measurement {
        tau_e: Vector::<2>::new(1e99, 0.0),
        ..measurement(100)
    };
    let e = step(&c, &mut st, &spike).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("tau_e[0] = 1e99 is beyond its limit ±1e9"),
        "{e}"
    );
    // Within the force ceiling, a force that would take ẋd beyond 1e6 rad/s
    // in one step (Dd = 0.5: ẍd = −2e9 rad/s²) is refused too.
    let mut cfg = Config::robot(Law::StateFeedback);
    cfg.dd = Vector::from_element(0.5);
    let c = build(cfg);
    let mut st = c.new_state();
    for k in 0..100 {
        step(&c, &mut st, &measurement(k)).unwrap();
    }
    let before = control(&st);
    let spike = Measurement {
        tau_e: Vector::<2>::new(1e9, 0.0),
        ..measurement(100)
    };
    let e = step(&c, &mut st, &spike).unwrap_err();
    assert!(matches!(e, Error::OutOfRange { what: "dxd", .. }), "{e}");
    assert_eq!(control(&st), before);
    for k in 100..200 {
        step(&c, &mut st, &measurement(k)).unwrap();
    }
}

#[test]
fn clear_fault_keeps_everything_but_the_fault_and_reset_keeps_nothing() {
    let mut cfg = Config::robot(Law::StateFeedback);
    cfg.fault_policy = FaultPolicy::Latch;
    cfg.fallback = Fallback::Zero;
    let c = build(cfg);
    let mut st = c.new_state();
    for k in 0..100 {
        step(&c, &mut st, &measurement(k)).unwrap();
    }
    let _ = step(&c, &mut st, &nan_q(100));
    let before = snapshot(&st);
    st.clear_fault();
    assert!(st.fault().is_none());
    assert_eq!(snapshot(&st), before);
    st.reset();
    let fresh = c.new_state();
    assert_eq!(snapshot(&st), snapshot(&fresh));
    assert!(st.fault().is_none());
}

#[test]
fn every_state_a_step_leaves_restores_and_continues_bit_identically() {
    for cfg in [
        Config::paper(Law::OutputFeedback),
        Config::robot(Law::StateFeedback),
    ] {
        let mut cfg = cfg;
        cfg.limits.q_jump = Vector::from_element(0.05);
        cfg.fallback = Fallback::Damping;
        cfg.fallback_damping = Vector::from_element(2.0);
        let c = build(cfg);
        let mut a = c.new_state();
        for k in 0..300 {
            // Every 7th sample refused (a NaN): the refusal record travels too.
            let m = if k % 7 == 3 { nan_q(k) } else { measurement(k) };
            let sp = circle(&c, &a);
            let _ = c.step_or_fallback(&mut a, &m, &sp);
            let mut b = c.new_state();
            c.restore(&mut b, &snapshot(&a))
                .expect("a stepped state restores");
            assert_eq!(snapshot(&b), snapshot(&a));
        }
        let mut b = c.new_state();
        c.restore(&mut b, &snapshot(&a)).unwrap();
        for k in 300..400 {
            let m = if k % 7 == 3 { nan_q(k) } else { measurement(k) };
            let (sa, sb) = (circle(&c, &a), circle(&c, &b));
            assert_eq!(
                c.step_or_fallback(&mut a, &m, &sa),
                c.step_or_fallback(&mut b, &m, &sb)
            );
        }
    }
}

#[test]
fn restore_refuses_a_corrupt_or_foreign_snapshot_and_changes_nothing() {
    let c = build(Config::robot(Law::StateFeedback));
    let mut a = c.new_state();
    for k in 0..200 {
        step(&c, &mut a, &measurement(k)).unwrap();
    }
    let good = snapshot(&a);
    let mut b = c.new_state();
    for k in 0..10 {
        step(&c, &mut b, &measurement(k)).unwrap();
    }
    let before = snapshot(&b);
    // Every single bit flip anywhere in the snapshot is refused.
    let mut flips = 0;
    for i in (0..good.len()).step_by(97).chain([good.len() - 1]) {
        for bit in [0, 17, 40, 52, 62, 63] {
            let mut bad = good.clone();
            bad[i] = f64::from_bits(bad[i].to_bits() ^ (1 << bit));
            let e = c.restore(&mut b, &bad).unwrap_err();
            assert!(
                matches!(e, Error::Invalid { .. } | Error::NonFinite { .. }),
                "{e}"
            );
            assert_eq!(snapshot(&b), before);
            flips += 1;
        }
    }
    assert!(flips > 100, "{flips}");
    // A snapshot of the earlier format says so.
    let mut old = good.clone();
    old[1] = 2.0;
    let e = c.restore(&mut b, &old).unwrap_err();
    assert!(e.to_string().contains("format 2"), "{e}");
    // Into a controller with smaller torque limits: its step could never
    // have applied that torque.
    let mut small = Config::robot(Law::StateFeedback);
    small.tau_max = Vector::from_element(5.0);
    let small = build(small);
    let mut s = small.new_state();
    let e = small.restore(&mut s, &good).unwrap_err();
    assert!(e.to_string().contains("beyond its limit ±5e0"), "{e}");
    // Into a controller with smaller projection bounds.
    let mut tight = Config::robot(Law::StateFeedback);
    tight.weight_bound = adaptimp::WeightBound::Fixed([0.01; 3]);
    let tight = build(tight);
    let mut s = tight.new_state();
    let e = tight.restore(&mut s, &good).unwrap_err();
    assert!(e.to_string().starts_with("‖weights.D‖ ="), "{e}");
    assert!(c.restore(&mut b, &good).is_ok());
}

#[test]
fn load_weights_refuses_weights_a_step_could_never_use() {
    let c = build(Config::robot(Law::StateFeedback));
    let mut st = c.new_state();
    let rows = 10 * 256;
    for (value, what) in [(1e200, "‖weights.D‖"), (0.1, "‖weights.D‖")] {
        let w = vec![value; rows];
        let e = c
            .load_weights(&mut st, &Weights::from_rows(&w, 256).unwrap())
            .unwrap_err();
        assert!(e.to_string().starts_with(what), "{e}");
    }
    // Without projection the step's bound 1e100 still holds.
    let free = build(Config::paper(Law::StateFeedback));
    let mut st = free.new_state();
    let w = vec![1e200; rows];
    let e = free
        .load_weights(&mut st, &Weights::from_rows(&w, 256).unwrap())
        .unwrap_err();
    assert!(e.to_string().starts_with("weights.D = inf"), "{e}");
    let w = vec![1e-3; rows];
    free.load_weights(&mut st, &Weights::from_rows(&w, 256).unwrap())
        .unwrap();
    assert_eq!(st.weight_norms(), st.weights().norms());
}

#[test]
fn the_tracked_norms_stay_far_within_restores_tolerance() {
    // Restore refuses stored norms more than 1e-6 (relative) from the
    // weights' norms; the norms a step tracks by its recurrence drift by
    // rounding only. Measured here (`-- --nocapture` prints it).
    for (name, c, steps) in [
        (
            "paper sf",
            build(Config::paper(Law::StateFeedback)),
            400_000,
        ),
        (
            "robot sf",
            build(Config::robot(Law::StateFeedback)),
            2_000_000,
        ),
    ] {
        let mut st = c.new_state();
        let traj = Sinusoid::paper();
        for k in 0..steps {
            let t = k as f64 * 1e-3;
            let m = Measurement {
                x: Vector::<2>::new(0.2 + 0.1 * (2.0 * t).sin(), 0.2 + 0.1 * (3.0 * t).cos()),
                dx: Some(Vector::<2>::new(
                    0.2 * (2.0 * t).cos(),
                    -0.3 * (3.0 * t).sin(),
                )),
                tau_e: Vector::<2>::new((5.0 * t.sin()).max(0.0), 0.0),
            };
            let sp = traj.sample(c.time(&st));
            c.step(&mut st, &m, &sp).unwrap();
        }
        let (tracked, exact) = (st.weight_norms(), st.weights().norms());
        let drift = Vector::<3>::from_fn(|i, _| (tracked[i] - exact[i]).abs() / exact[i]);
        println!(
            "{name}, {steps} steps: relative drift of the tracked norms D, C, G: {:.1e}, {:.1e}, {:.1e}",
            drift[0], drift[1], drift[2]
        );
        assert!(drift.iter().all(|d| *d < 1e-12), "{name}: {drift:?}");
    }
}
