//! Physics properties of the models, over random states (proptest).

use adaptimp::model::{Link, PlanarArm};
use adaptimp::{Manipulator, Matrix, TwoLinkArm, Vector};
use proptest::prelude::*;

/// Ḋ along q̇ by a central difference: (D(q + h q̇) − D(q − h q̇)) / 2h.
fn d_dot<const N: usize, M: Manipulator<N>>(m: &M, q: &Vector<N>, dq: &Vector<N>) -> Matrix<N> {
    let h = 1e-6;
    (m.inertia(&(q + h * dq)) - m.inertia(&(q - h * dq))) / (2.0 * h)
}

fn assert_properties<const N: usize, M: Manipulator<N>>(m: &M, q: &Vector<N>, dq: &Vector<N>) {
    let d = m.inertia(q);
    // Property 1: D symmetric positive definite.
    assert!(
        (d - d.transpose()).abs().max() <= 1e-15 * d.abs().max(),
        "D not symmetric: {d}"
    );
    // Cholesky succeeds exactly for symmetric positive definite matrices.
    assert!(d.cholesky().is_some(), "D not positive definite: {d}");
    // Property 2: Ḋ − 2C skew-symmetric.
    let s = d_dot(m, q, dq) - 2.0 * m.coriolis(q, dq);
    let scale = 1.0 + d.abs().max() * dq.abs().max();
    assert!(
        (s + s.transpose()).abs().max() <= 1e-7 * scale,
        "Ḋ − 2C not skew-symmetric: {s}"
    );
}

fn three_links() -> PlanarArm<3> {
    let link = |mass: f64, length: f64| Link {
        mass,
        length,
        com: length / 2.0,
        inertia: mass * length * length / 12.0,
    };
    PlanarArm::new([link(2.0, 0.4), link(1.2, 0.3), link(0.5, 0.2)], 9.81).expect("valid arm")
}

fn angle() -> impl Strategy<Value = f64> {
    -10.0..10.0f64
}
fn rate() -> impl Strategy<Value = f64> {
    -20.0..20.0f64
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn two_link_arm_properties(q1 in angle(), q2 in angle(), v1 in rate(), v2 in rate()) {
        let q = Vector::<2>::new(q1, q2);
        let dq = Vector::<2>::new(v1, v2);
        assert_properties(&TwoLinkArm::paper(), &q, &dq);
    }

    #[test]
    fn planar_three_link_arm_properties(
        q in prop::array::uniform3(angle()),
        dq in prop::array::uniform3(rate()),
    ) {
        assert_properties(&three_links(), &Vector::<3>::from(q), &Vector::<3>::from(dq));
    }

    #[test]
    fn planar_arm_with_two_links_is_the_paper_arm(q1 in angle(), q2 in angle(), v1 in rate(), v2 in rate()) {
        let arm = TwoLinkArm::paper();
        let a = arm.params();
        let planar = PlanarArm::new(
            [
                Link { mass: a.m1, length: a.l1, com: a.lc1, inertia: a.i1 },
                Link { mass: a.m2, length: a.l2, com: a.lc2, inertia: a.i2 },
            ],
            a.g,
        ).expect("valid arm");
        let q = Vector::<2>::new(q1, q2);
        let dq = Vector::<2>::new(v1, v2);
        prop_assert!((arm.inertia(&q) - planar.inertia(&q)).abs().max() < 1e-14);
        prop_assert!((arm.coriolis(&q, &dq) - planar.coriolis(&q, &dq)).abs().max() < 1e-12);
        prop_assert!((arm.gravity(&q) - planar.gravity(&q)).abs().max() < 1e-13);
    }

    #[test]
    fn forward_dynamics_solves_the_equation_of_motion(
        q in prop::array::uniform3(angle()),
        dq in prop::array::uniform3(rate()),
        tau in prop::array::uniform3(-20.0..20.0f64),
    ) {
        let arm = three_links();
        let (q, dq, tau) = (Vector::<3>::from(q), Vector::<3>::from(dq), Vector::<3>::from(tau));
        let tau_e = Vector::<3>::new(1.0, 0.0, -0.5);
        let ddq = arm.forward_dynamics(&q, &dq, &tau, &tau_e);
        let lhs = arm.inertia(&q) * ddq + arm.coriolis(&q, &dq) * dq + arm.gravity(&q);
        prop_assert!((lhs - (tau - tau_e)).norm() < 1e-9 * (1.0 + tau.norm() + dq.norm_squared()));
    }
}

#[test]
fn planar_gravity_is_the_gradient_of_potential_energy() {
    // G = ∂P/∂q with P = Σ m_k g y_k; check against a central difference of P.
    let arm = three_links();
    let potential = |q: &Vector<3>| {
        let mut theta = 0.0;
        let mut y = 0.0;
        let mut p = 0.0;
        for (link, &qi) in arm.links().iter().zip(q.iter()) {
            theta += qi;
            p += link.mass * 9.81 * (y + link.com * theta.sin());
            y += link.length * theta.sin();
        }
        p
    };
    let q = Vector::<3>::new(0.3, -0.8, 1.1);
    let h = 1e-6;
    for i in 0..3 {
        let mut e = Vector::<3>::zeros();
        e[i] = h;
        let fd = (potential(&(q + e)) - potential(&(q - e))) / (2.0 * h);
        assert!((arm.gravity(&q)[i] - fd).abs() < 1e-7, "joint {i}");
    }
}

/// An inertia matrix (kg m²) with joint scales λ_i = 10^e_i over four
/// decades and random coupling: S (A Aᵀ/N + I) S, S = diag(√λ), A random.
fn inertia_matrix<const N: usize>(entries: &[f64], exps: &[f64]) -> Matrix<N> {
    let a = Matrix::<N>::from_iterator(entries.iter().copied());
    let s = Matrix::<N>::from_diagonal(&Vector::<N>::from_iterator(
        exps.iter().map(|e| 10f64.powf(*e).sqrt()),
    ));
    let d = s * (a * a.transpose() / N as f64 + Matrix::<N>::identity()) * s;
    (d + d.transpose()) / 2.0
}

/// SPEC §18: construction accepts the rule's configuration for any arm
/// (inertias over four decades, any coupling), τmax and Ts, for each law.
fn rule_builds<const N: usize>(entries: &[f64], exps: &[f64], tau: &[f64], ts: f64, amp: f64) {
    use adaptimp::tuning::{default_task, Rule};
    use adaptimp::{Controller, Law};
    let d = inertia_matrix::<N>(entries, exps);
    let tau_max = Vector::<N>::from_iterator(tau.iter().map(|e| 10f64.powf(*e)));
    let lim = Vector::<N>::from_element(amp.max(1e-3) * 4.0);
    let task = default_task(&Vector::zeros(), &-lim, &lim).expect("task");
    let path = Rule::sample(&task, 2.0);
    for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
        let s = Rule::default()
            .suggest(law, &d, &tau_max, ts, &path, 2.0, None)
            .expect("the rule applies");
        Controller::new(s.config, s.centers).expect("construction accepts the rule");
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 200,
        rng_seed: proptest::test_runner::RngSeed::Fixed(18),
        ..ProptestConfig::default()
    })]

    #[test]
    fn the_rule_always_builds_for_three_joints(
        entries in prop::collection::vec(-1.0..1.0f64, 9),
        exps in prop::collection::vec(-2.0..2.0f64, 3),
        tau in prop::collection::vec(-2.0..3.0f64, 3),
        ts in 1e-4..1e-2f64,
        amp in 0.0..0.5f64,
    ) {
        rule_builds::<3>(&entries, &exps, &tau, ts, amp);
    }

    #[test]
    fn the_rule_always_builds_for_seven_joints(
        entries in prop::collection::vec(-1.0..1.0f64, 49),
        exps in prop::collection::vec(-2.0..2.0f64, 7),
        tau in prop::collection::vec(-2.0..3.0f64, 7),
        ts in 1e-4..1e-2f64,
        amp in 0.0..0.5f64,
    ) {
        rule_builds::<7>(&entries, &exps, &tau, ts, amp);
    }
}
