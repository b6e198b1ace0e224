//! SPEC §10: every condition, violated, gives its own error naming it and the
//! value; non-finite inputs give an error and change no state.

use adaptimp::{Config, Controller, Error, Grid, Law, Measurement, RobustKind, Tracker, Vector};
use std::collections::HashSet;

type Cfg = Config<2>;

fn build(cfg: Cfg) -> Result<Controller<2>, Error> {
    Controller::new(cfg, Grid::paper())
}

/// A condition of SPEC §10 and a change to the paper configuration that violates it.
type Violation = (&'static str, Box<dyn Fn(&mut Cfg)>);

/// Each mutation violates exactly one condition of SPEC §10.
fn violations() -> Vec<Violation> {
    vec![
        ("K1 > 0", Box::new(|c: &mut Cfg| c.k1[1] = 0.0)),
        ("2Kp − I > 0", Box::new(|c: &mut Cfg| c.kp[0] = 0.5)),
        (
            "2Kζ − I − KpᵀKp > 0",
            Box::new(|c: &mut Cfg| c.kzeta[1] = 50.0),
        ),
        ("Γ > 0", Box::new(|c: &mut Cfg| c.gamma[2] = -1.0)),
        ("σ > 0", Box::new(|c: &mut Cfg| c.sigma[0] = 0.0)),
        ("ε > 0", Box::new(|c: &mut Cfg| c.eps = 0.0)),
        ("λ1 > 0", Box::new(|c: &mut Cfg| c.lam1[0] = -3.0)),
        ("μ > 0", Box::new(|c: &mut Cfg| c.mu = 0.0)),
        ("τmax > 0", Box::new(|c: &mut Cfg| c.tau_max[1] = 0.0)),
        ("Dd > 0", Box::new(|c: &mut Cfg| c.dd[0] = 0.0)),
        ("Ts > 0", Box::new(|c: &mut Cfg| c.ts = -1e-3)),
    ]
}

#[test]
fn each_condition_violated_gives_its_own_error() {
    let mut seen = HashSet::new();
    for (condition, mutate) in violations() {
        let mut cfg = Cfg::paper(Law::StateFeedback);
        mutate(&mut cfg);
        let err = build(cfg).expect_err(condition);
        match err {
            Error::Condition {
                condition: c,
                value,
                ..
            } => {
                assert_eq!(c, condition);
                assert!(value.is_finite());
            }
            other => panic!("{condition}: unexpected {other:?}"),
        }
        let msg = err.to_string();
        assert!(msg.contains(condition), "{msg}");
        assert!(seen.insert(condition), "{condition} listed twice");
    }
}

#[test]
fn eta2_condition_is_checked_by_the_basis() {
    let err = Grid::<2>::new(-25.0).unwrap_err();
    assert!(
        matches!(err, Error::Condition { condition: "η² > 0", value, .. } if value == -25.0),
        "{err}"
    );
}

#[test]
fn messages_name_the_offending_value_and_index() {
    let mut cfg = Cfg::paper(Law::Pd);
    cfg.kzeta[1] = 50.0; // 2·50 − 1 − 10² = −1
    let msg = build(cfg).unwrap_err().to_string();
    assert!(msg.contains("2·Kzeta − 1 − Kp²[1] = -1"), "{msg}");
    let mut cfg = Cfg::paper(Law::Pd);
    cfg.ts = -0.001;
    let msg = build(cfg).unwrap_err().to_string();
    assert!(msg.contains("Ts = -0.001"), "{msg}");
}

#[test]
fn the_boundary_itself_is_rejected_and_just_inside_accepted() {
    // 2Kζ − 1 − Kp² > 0 with Kp = 10 needs Kζ > 50.5 (SPEC §8).
    let mut cfg = Cfg::paper(Law::Pd);
    cfg.kzeta = Vector::<2>::from_element(50.5);
    assert!(build(cfg).is_err());
    cfg.kzeta = Vector::<2>::from_element(50.5 + 1e-9);
    assert!(build(cfg).is_ok());
}

#[test]
fn non_finite_parameters_are_errors() {
    let mut cfg = Cfg::paper(Law::OutputFeedback);
    cfg.kp[1] = f64::NAN;
    assert_eq!(
        build(cfg).unwrap_err(),
        Error::NonFinite {
            what: "Kp",
            index: 1
        }
    );
    let mut cfg = Cfg::paper(Law::OutputFeedback);
    cfg.eps = f64::INFINITY;
    assert_eq!(
        build(cfg).unwrap_err(),
        Error::NonFinite {
            what: "eps",
            index: 0
        }
    );
    let mut cfg = Cfg::paper(Law::OutputFeedback);
    cfg.robust = RobustKind::Tanh;
    cfg.phi = 0.0;
    assert!(build(cfg).unwrap_err().to_string().contains("φ > 0"));
}

fn measurement(x: [f64; 2], dx: [f64; 2], te: [f64; 2]) -> Measurement<2> {
    Measurement {
        x: Vector::<2>::from(x),
        dx: Some(Vector::<2>::from(dx)),
        tau_e: Vector::<2>::from(te),
    }
}

/// Everything observable about a controller's state.
fn snapshot(c: &Tracker<2>) -> String {
    let s = c.state();
    format!(
        "{:?} {:?} {:?} {:?} {:?} {:?} {:?}",
        s.steps(),
        s.zeta(),
        s.reference(),
        s.observer(),
        s.weights(),
        s.weight_norms(),
        s.last()
    )
}

#[test]
fn non_finite_measurement_is_an_error_and_changes_no_state() {
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        let mut c = Tracker::paper(law);
        for _ in 0..50 {
            c.step(&measurement([0.25, -0.05], [0.1, 0.0], [10.0, 0.0]))
                .unwrap();
        }
        let before = snapshot(&c);
        let bad = [
            (measurement([f64::NAN, 0.0], [0.0, 0.0], [0.0, 0.0]), "x"),
            (
                measurement([0.0, 0.0], [0.0, 0.0], [0.0, f64::INFINITY]),
                "tau_e",
            ),
        ];
        for (m, what) in bad {
            let err = c.step(&m).unwrap_err();
            assert!(
                matches!(err, Error::NonFinite { what: w, .. } if w == what),
                "{law:?}: {err:?}"
            );
            assert_eq!(snapshot(&c), before, "{law:?}: state changed on {what}");
        }
        let nan_dx = measurement([0.0, 0.0], [0.0, f64::NEG_INFINITY], [0.0, 0.0]);
        if law == Law::OutputFeedback {
            // Output feedback ignores the velocity it is given.
            assert!(c.step(&nan_dx).is_ok());
        } else {
            assert_eq!(
                c.step(&nan_dx).unwrap_err(),
                Error::NonFinite {
                    what: "dx",
                    index: 1
                }
            );
            assert_eq!(snapshot(&c), before);
            let missing = Measurement { dx: None, ..nan_dx };
            assert_eq!(c.step(&missing).unwrap_err(), Error::MissingVelocity);
            assert_eq!(snapshot(&c), before);
        }
    }
}

/// SPEC §10 (10.3): the conditions with inertia scales, each violated alone,
/// its boundary rejected and just inside accepted; the paper's (13) kept for
/// its unit weights only.
#[test]
fn the_scaled_conditions_name_themselves_and_their_boundary() {
    use adaptimp::Conditions;
    let scaled = || {
        let mut c = Cfg::paper(Law::StateFeedback);
        c.conditions = Conditions::Scaled;
        // A light second joint: Kp/d = 0.03/0.001 = 30 s⁻¹.
        c.kp = Vector::<2>::new(10.0, 0.03);
        c.inertia = Vector::<2>::new(1.0, 0.001);
        c.kzeta = Vector::<2>::new(60.0, 20.0);
        c
    };
    assert!(build(scaled()).is_ok());
    let cases: Vec<Violation> = vec![
        ("Kp > 0", Box::new(|c: &mut Cfg| c.kp[1] = 0.0)),
        (
            "2Kζ − ρ − Kp/d > 0",
            Box::new(|c: &mut Cfg| c.kzeta[1] = 15.5),
        ),
        ("d ≥ 1e-9", Box::new(|c: &mut Cfg| c.inertia[0] = 1e-10)),
        ("ρ ≥ 1e-9", Box::new(|c: &mut Cfg| c.rho = -1.0)),
    ];
    for (condition, mutate) in cases {
        let mut cfg = scaled();
        mutate(&mut cfg);
        let e = build(cfg).expect_err(condition);
        assert!(
            matches!(e, Error::Condition { condition: c, .. } if c == condition),
            "{condition}: {e}"
        );
    }
    // (2·15.5 − 1 − 30 = 0 is the boundary; just inside passes.)
    let mut cfg = scaled();
    cfg.kzeta[1] = 15.5 + 1e-9;
    assert!(build(cfg).is_ok());
    // The paper's conditions with other weights are refused, by name.
    let mut cfg = Cfg::paper(Law::StateFeedback);
    cfg.inertia[1] = 0.5;
    let e = build(cfg).unwrap_err().to_string();
    assert!(e.contains("use conditions = scaled"), "{e}");
}
