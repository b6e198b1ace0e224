use super::*;
use crate::control::controller::Controller;

/// Two seconds of the default task on three joints about zero (±1 rad limits).
fn default_path() -> alloc::vec::Vec<Setpoint<3>> {
    let traj = default_task(
        &Vector::<3>::zeros(),
        &Vector::from_element(-1.0),
        &Vector::from_element(1.0),
    )
    .unwrap();
    Rule::sample(&traj, 2.0)
}

fn arm_matrix() -> Matrix<3> {
    Matrix::<3>::new(2.0, 0.5, 0.1, 0.5, 1.0, 0.2, 0.1, 0.2, 0.05)
}

#[test]
fn gains_follow_the_rule_and_build() {
    let d = arm_matrix();
    let tau = Vector::<3>::new(50.0, 20.0, 5.0);
    let cfg = Rule::default()
        .gains(Law::StateFeedback, &d, &tau, 1e-3)
        .unwrap();
    let inv = d.try_inverse().unwrap();
    for i in 0..3 {
        let di = 1.0 / inv[(i, i)];
        assert!((cfg.inertia[i] - di).abs() < 1e-12 * di);
        assert!((cfg.kp[i] - 250.0 * di).abs() < 1e-9 * cfg.kp[i]);
    }
    assert_eq!(cfg.k1, Vector::<3>::from_element(50.0));
    assert_eq!(cfg.conditions, Conditions::Scaled);
    let path = default_path();
    let s = Rule::default()
        .suggest(Law::StateFeedback, &d, &tau, 1e-3, &path, 2.0, None)
        .unwrap();
    Controller::new(s.config, s.centers).unwrap();
}

#[test]
fn scales_along_a_path_average_and_keep_the_bound() {
    let d = arm_matrix();
    let (bound, exact) = (largest_eigenvalue(&d), d.symmetric_eigenvalues().max());
    assert!(exact <= bound && bound <= 1.01 * exact, "{bound} {exact}");
    // One posture: its own scales.
    let one = inertia_scales_along(&[d]).unwrap();
    assert!((one - inertia_scales(&d).unwrap()).norm() < 1e-15);
    // Two axes nearly in line at one posture (d_i ≪ D_ii there), apart at
    // the other: the mean, capped so that λmax(D⁻¹Dₛ) ≤ N at both.
    let lined = Matrix::<2>::new(1.0, 0.999, 0.999, 1.0);
    let apart = Matrix::<2>::identity();
    let s = inertia_scales_along(&[lined, apart]).unwrap();
    let mean = (inertia_scales(&lined).unwrap() + inertia_scales(&apart).unwrap()) / 2.0;
    let ratio = s.component_div(&mean);
    assert!(
        (ratio[0] - ratio[1]).abs() < 1e-12 && ratio[0] < 1.0,
        "{ratio}"
    );
    for m in [lined, apart] {
        let l = (m.try_inverse().unwrap() * Matrix::<2>::from_diagonal(&s))
            .eigenvalues()
            .unwrap();
        assert!(l.max() <= 2.0 + 1e-9, "{l}");
    }
    assert!(inertia_scales_along::<2>(&[]).is_err());
}

#[test]
fn bad_inertia_matrices_are_named() {
    let mut d = arm_matrix();
    d[(0, 1)] = 0.7;
    let e = inertia_scales(&d).unwrap_err();
    assert!(e.to_string().contains("symmetric"), "{e}");
    let e = inertia_scales(&-arm_matrix()).unwrap_err();
    assert!(e.to_string().contains("positive definite"), "{e}");
}

#[test]
fn a_damped_joint_scale_answers_a_held_torque_as_the_joint_does() {
    let ts = 1e-3;
    let d = Vector::<3>::new(2.0, 1e-2, 1e-6);
    // No damping: the scales as they are, bit for bit.
    let same = damped_scales(&d, &Vector::<3>::zeros(), ts).unwrap();
    assert_eq!(same, d);
    let b = Vector::<3>::new(0.0, 0.1, 0.01);
    let s = damped_scales(&d, &b, ts).unwrap();
    assert_eq!(s[0], d[0]);
    // Small β = b Ts/d = 0.01: d (1 + β/2 + β²/12 + …).
    let beta = 0.1 * ts / 1e-2;
    assert!((s[1] / d[1] - (1.0 + beta / 2.0 + beta * beta / 12.0)).abs() < 1e-9);
    // A wrist its damping dominates (β = 10): b Ts/(1 − e^(−10)).
    assert!((s[2] - 0.01 * ts / (1.0 - (-10.0f64).exp())).abs() < 1e-18);
    // A held torque τ over Ts moves the damped joint's velocity by
    // (1 − e^(−β)) τ/b, the scale's joint by Ts τ/d̃: the same.
    for i in 1..3 {
        let beta = b[i] * ts / d[i];
        let damped = (1.0 - (-beta).exp()) / b[i];
        assert!((ts / s[i] - damped).abs() < 1e-9 * damped);
    }
    for (bad, what) in [
        (Vector::<3>::new(0.0, -0.1, 0.0), "damping"),
        (Vector::<3>::new(0.0, f64::NAN, 0.0), "damping"),
    ] {
        let e = damped_scales(&d, &bad, ts).unwrap_err().to_string();
        assert!(e.contains(what), "{e}");
    }
    assert!(damped_scales(&Vector::<3>::new(1.0, 0.0, 1.0), &b, ts).is_err());
    assert!(damped_scales(&d, &b, 0.0).is_err());
}

#[test]
fn the_default_task_starts_at_rest_inside_the_limits() {
    let lo = Vector::<2>::new(-1.0, 0.0);
    let hi = Vector::<2>::new(1.0, 0.4);
    let home = Vector::<2>::new(0.3, 0.2);
    let t = default_task(&home, &lo, &hi).unwrap();
    let s0 = t.sample(0.0);
    assert_eq!(s0.dx, Vector::<2>::zeros());
    assert!((s0.x - Vector::<2>::new(0.1, 0.1)).norm() < 1e-15);
    assert!((t.sample(1.0).x - Vector::<2>::new(0.5, 0.3)).norm() < 1e-15);
    let e = default_task(&Vector::<2>::new(0.9, 0.2), &lo, &hi).unwrap_err();
    assert!(e.to_string().contains("lo + A ≤ home ≤ hi − A"), "{e}");
}

#[test]
fn centres_that_span_the_orbit_keep_their_places_and_learn_at_the_same_bandwidth() {
    // Four points of a circle of radius 0.3 rad in two joints: diameter 0.6.
    let r = 0.3;
    let ring = [
        Vector::<2>::new(r, 0.0),
        Vector::<2>::new(0.0, r),
        Vector::<2>::new(-r, 0.0),
        Vector::<2>::new(0.0, -r),
    ];
    assert!((diameter(&ring) - 2.0 * r).abs() < 1e-15);
    assert_eq!(diameter::<2>(&ring[..1]), 0.0);
    assert!(diameter(&[Vector::<2>::new(f64::NAN, 0.0), ring[0]]).is_nan());
    let rule = Rule::default();
    assert_eq!(rule.span, 0.0);
    assert_eq!(rule.spanning::<2>(&[]), rule);
    assert_eq!(
        rule.spanning(&[Vector::<2>::new(f64::NAN, 0.0), ring[0]]),
        rule
    );
    // The default task on three joints (±0.2 rad): the rule's widths in q
    // are below 1 rad; spanning an orbit of diameter 1.5 rad widens them
    // to 1.5 and nothing else: the same centres, the same q̇ widths, and
    // Γ_G ⟨‖S‖²⟩ = ω_G² for the wider basis as for the rule's (18.6).
    let d = arm_matrix();
    let tau = Vector::<3>::new(50.0, 20.0, 5.0);
    let path = default_path();
    let orbit = [Vector::<3>::zeros(), Vector::<3>::new(1.5, 0.0, 0.0)];
    let wide = rule.spanning(&orbit);
    assert_eq!(wide.span, 1.5);
    let suggest = |r: &Rule| {
        r.suggest(Law::StateFeedback, &d, &tau, 1e-3, &path, 2.0, None)
            .unwrap()
    };
    let (a, b) = (suggest(&rule), suggest(&wide));
    assert_eq!(a.centers.centers(), b.centers.centers());
    assert_eq!(a.centers.widths2()[1], b.centers.widths2()[1]);
    let (wa, wb) = (a.centers.widths2()[0][0], b.centers.widths2()[0][0]);
    assert!(
        sqrt(wa) < 1.0 && (sqrt(wb) - 1.5).abs() < 1e-12,
        "{wa} {wb}"
    );
    let s2 = |c: &Centers<3, alloc::vec::Vec<f64>>| {
        let mut s = alloc::vec![0.0; c.nodes()];
        path.iter()
            .map(|sp| {
                c.eval(&[sp.x, sp.dx, sp.dx, sp.ddx], &mut s);
                s.iter().map(|v| v * v).sum::<f64>()
            })
            .sum::<f64>()
            / path.len() as f64
    };
    let omega2 = |g: f64, c| g * s2(c);
    let (oa, ob) = (
        omega2(a.config.gamma[2], &a.centers),
        omega2(b.config.gamma[2], &b.centers),
    );
    assert!((oa - ob).abs() < 1e-9 * oa, "{oa} {ob}");
    assert!(b.config.gamma[2] < a.config.gamma[2]);
    Controller::new(b.config, b.centers).unwrap();
}

/// The largest root modulus of z^(δ+1) − z^δ + g (companion matrix).
fn radius(delay: usize, g: f64) -> f64 {
    let n = delay + 1;
    let mut c = nalgebra::DMatrix::<f64>::zeros(n, n);
    // z^n = z^(n−1) − g: the first row holds the coefficients.
    c[(0, 0)] = 1.0;
    c[(0, n - 1)] -= g;
    for i in 1..n {
        c[(i, i - 1)] = 1.0;
    }
    c.complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

#[test]
fn the_loop_gain_puts_the_delayed_loops_poles_on_the_pole_radius() {
    assert_eq!(pole_radius(0), 0.75);
    assert_eq!(pole_radius(1), 0.75);
    assert!((pole_radius(2) - 5.0 / 6.0).abs() < 1e-15);
    assert_eq!(loop_gain(0), 1.75);
    // δ = 1: the pair √g reaches r at g = r².
    assert!((loop_gain(1) - 0.5625).abs() < 1e-12, "{}", loop_gain(1));
    for delay in 1..=6 {
        let (g, r) = (loop_gain(delay), pole_radius(delay));
        assert!((radius(delay, g) - r).abs() < 1e-9, "δ = {delay}");
        // Just above g_δ a pole leaves the radius; below, the poles stay in.
        assert!(radius(delay, 1.001 * g) > r, "δ = {delay}");
        assert!(radius(delay, 0.999 * g) <= r + 1e-12, "δ = {delay}");
        // Inside the stability limit 2 sin(π/(4δ + 2)).
        let limit = 2.0 * libm::sin(core::f64::consts::PI / (4.0 * delay as f64 + 2.0));
        assert!(
            g < limit && radius(delay, limit) > 1.0 - 1e-9,
            "δ = {delay}"
        );
    }
}

#[test]
fn a_delayed_rule_slows_the_loop_at_the_paths_largest_mode() {
    let (d, tau) = (arm_matrix(), Vector::<3>::new(50.0, 20.0, 5.0));
    let rule = Rule::default();
    // δ = 0: the rule as it is, whatever the mode.
    assert_eq!(rule.bounded(6.0), rule);
    assert_eq!(rule.with_delay(0).unwrap().bounded(6.0), rule);
    let e = rule.with_delay(65).unwrap_err().to_string();
    assert!(e.contains("0 ≤ delay ≤ 64"), "{e}");
    // δ = 1 at λmax = 4: m = 0.5625/4, K1 = 0.2 m/Ts, no robust term.
    let late = rule.with_delay(1).unwrap().bounded(4.0);
    assert!((late.margin - 0.5625 / 4.0).abs() < 1e-15);
    assert!((late.k1(1e-3) - 0.2 * late.margin / 1e-3).abs() < 1e-9);
    let cfg = late.gains(Law::StateFeedback, &d, &tau, 1e-3).unwrap();
    assert_eq!(cfg.delay, 1);
    assert_eq!(cfg.kr, Vector::<3>::zeros());
    let undelayed = rule.gains(Law::StateFeedback, &d, &tau, 1e-3).unwrap();
    for i in 0..3 {
        let ratio = cfg.kp[i] / undelayed.kp[i];
        assert!((ratio - late.margin / 0.25).abs() < 1e-12, "{ratio}");
    }
    let s = late
        .suggest(
            Law::StateFeedback,
            &d,
            &tau,
            1e-3,
            &default_path(),
            2.0,
            None,
        )
        .unwrap();
    assert_eq!((s.config.delay, s.config.kr), (1, Vector::<3>::zeros()));
    Controller::new(s.config, s.centers).unwrap();
    // A small mode keeps m: the delayed loop is well inside r_δ already.
    assert_eq!(rule.with_delay(1).unwrap().bounded(1.0).margin, 0.25);
    // The bound of the loop along a path: λmax of Dₛ^½ D⁻¹ Dₛ^½.
    let s = inertia_scales(&d).unwrap();
    let lb = loop_bound(&[d], &s).unwrap();
    let exact = (Matrix::<3>::from_diagonal(&s.map(sqrt))
        * d.try_inverse().unwrap()
        * Matrix::<3>::from_diagonal(&s.map(sqrt)))
    .symmetric_eigenvalues()
    .max();
    assert!(
        exact * (1.0 - 1e-12) <= lb && lb <= 1.01 * exact,
        "{lb} {exact}"
    );
    assert!(loop_bound::<3>(&[], &s).is_err());
}

#[test]
fn a_delayed_rule_keeps_d_and_cs_undelayed_bandwidth() {
    let rule = Rule::default();
    let d = arm_matrix();
    let tau = Vector::<3>::new(50.0, 20.0, 5.0);
    let (path, g) = (default_path(), Vector::<3>::zeros());
    let suggest = |r: &Rule| {
        r.suggest(Law::StateFeedback, &d, &tau, 1e-3, &path, 2.0, Some(&g))
            .unwrap()
            .config
    };
    let late_rule = rule.with_delay(1).unwrap().bounded(4.0);
    let f = late_rule.margin / rule.margin;
    assert!((late_rule.dc_boost * f - 1.0).abs() < 1e-15);
    let (base, late) = (suggest(&rule), suggest(&late_rule));
    // Ĝ: ω_G² ∝ m K1 ∝ m², so Γ_G falls by f²; D̂ and Ĉ learn as undelayed.
    assert!((late.gamma[2] / base.gamma[2] / (f * f) - 1.0).abs() < 1e-12);
    for i in 0..2 {
        assert!((late.gamma[i] / base.gamma[i] - 1.0).abs() < 1e-12, "{i}");
    }
    // Never faster than Ĝ: ω_D ≤ ω_G (learn_dc · dc_boost ≤ 1).
    let slow = rule.with_delay(2).unwrap().bounded(100.0);
    assert_eq!(slow.dc_boost, 1.0 / rule.learn_dc);
    // Undelayed, or a mode small enough for m: no boost.
    assert_eq!(rule.bounded(4.0).dc_boost, 1.0);
    assert_eq!(rule.with_delay(1).unwrap().bounded(1.0).dc_boost, 1.0);
    // A weightless arm's D̂ and Ĉ are at ω_G already.
    assert_eq!(
        rule.weightless()
            .with_delay(1)
            .unwrap()
            .bounded(4.0)
            .dc_boost,
        1.0
    );
}

#[test]
fn a_weightless_arm_learns_d_and_c_at_gs_bandwidth() {
    let rule = Rule::default();
    let light = rule.weightless();
    assert_eq!(light.learn_dc, 1.0);
    assert_eq!(
        Rule {
            learn_dc: 0.2,
            ..light
        },
        rule
    );
    let d = arm_matrix();
    let tau = Vector::<3>::new(50.0, 20.0, 5.0);
    let path = default_path();
    let g = Vector::<3>::zeros();
    let base = rule
        .suggest(Law::StateFeedback, &d, &tau, 1e-3, &path, 2.0, Some(&g))
        .unwrap()
        .config;
    let fast = light
        .suggest(Law::StateFeedback, &d, &tau, 1e-3, &path, 2.0, Some(&g))
        .unwrap()
        .config;
    // Γ_D, Γ_C 25× (ω² ∝ learn_dc²), σ 1/25× (the same leak time), Γ_G as it was.
    for i in 0..2 {
        assert!((fast.gamma[i] / base.gamma[i] - 25.0).abs() < 1e-12);
        assert!((fast.sigma[i] * 25.0 / base.sigma[i] - 1.0).abs() < 1e-12);
    }
    assert_eq!(fast.gamma[2], base.gamma[2]);
    assert_eq!(fast.kp, base.kp);
}

#[test]
fn a_posture_to_hold_gets_the_star() {
    let c = Rule::default()
        .default_basis(&Sinusoid::<4>::constant(Vector::from_element(0.5)).unwrap())
        .unwrap();
    assert_eq!(c.nodes(), 9);
    assert_eq!(c.centers()[4 * 4], 0.7);
    assert_eq!(c.centers()[2 * 4 * 4], 0.3);
}
