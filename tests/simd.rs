//! The weight pass's two instruction sets (`adaptimp::simd`): the path a
//! controller takes by default, and the same torques and weights on both.
//! Deterministic, no timing. `tests/simd_env.rs` checks `ADAPTIMP_SIMD` in a
//! process of its own (environment variables are process-wide).

use adaptimp::{
    run, Controller, Law, SimConfig, SimdPath, Sinusoid, Trace, TwoLinkArm, Vector, Wall,
};

/// Steps compared per controller.
const STEPS: usize = 2000;

/// True if this CPU (and OS) has AVX2 and FMA.
fn cpu_has_avx2_fma() -> bool {
    #[cfg(any(target_arch = "x86", target_arch = "x86_64"))]
    {
        std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma")
    }
    #[cfg(not(any(target_arch = "x86", target_arch = "x86_64")))]
    {
        false
    }
}

#[test]
fn a_new_controller_takes_the_fast_path_when_the_cpu_has_it() {
    let fast = SimdPath::fastest();
    assert_eq!(fast.is_portable(), !cpu_has_avx2_fma(), "{fast}");
    assert_eq!(
        fast.name(),
        if cpu_has_avx2_fma() {
            "avx2-fma"
        } else {
            "portable"
        }
    );
    let ctrl = Controller::paper(Law::StateFeedback);
    if std::env::var_os("ADAPTIMP_SIMD").is_some_and(|v| v == "portable") {
        assert!(ctrl.simd().is_portable());
    } else {
        assert_eq!(ctrl.simd(), fast, "Controller::new picks the fastest path");
    }
    let portable = ctrl.with_simd(SimdPath::portable());
    assert_eq!(portable.simd().name(), "portable");
}

/// `|a − b|∞ / max(|a|∞, |b|∞)` (0 if both are zero).
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = a.iter().chain(b).fold(0.0f64, |m, x| m.max(x.abs()));
    let diff = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if diff == 0.0 {
        0.0
    } else {
        diff / scale
    }
}

/// `STEPS` closed-loop steps of `ctrl` on `path` with the paper's arm, wall
/// and circle: the rows and every weight at the end.
fn closed_loop(ctrl: &Controller<2>, path: SimdPath) -> (Trace<2>, Vec<f64>, [f64; 3]) {
    let ctrl = ctrl.clone().with_simd(path);
    assert_eq!(ctrl.simd(), path);
    let mut state = ctrl.new_state();
    let sim = SimConfig {
        t_final: STEPS as f64 * ctrl.period(),
        substeps: 1,
        ..SimConfig::paper()
    };
    let mut trace = Trace::default();
    run(
        &TwoLinkArm::paper(),
        &Wall::paper(),
        &mut ctrl.bind(&mut state),
        &Sinusoid::paper(),
        &sim,
        &mut trace,
    )
    .expect("the closed loop runs");
    assert_eq!(trace.rows.len(), STEPS);
    let w = state.weights();
    let weights = (0..3)
        .flat_map(|net| w.network(net).flatten().copied().collect::<Vec<_>>())
        .collect();
    (trace, weights, state.weight_norms())
}

#[test]
fn both_paths_give_the_same_torques_and_weights() {
    let fast = SimdPath::fastest();
    if fast.is_portable() {
        eprintln!(
            "skipped: this CPU lacks AVX2/FMA, so only the portable path runs here \
             (nothing to compare it with)"
        );
        return;
    }
    let laws = [Law::Pd, Law::StateFeedback, Law::OutputFeedback];
    let mut worst = 0.0f64;
    let mut check = |what: &str, a: &[f64], b: &[f64]| {
        let d = rel_diff(a, b);
        assert!(d <= 1e-12, "{what}: relative difference {d:e}");
        worst = worst.max(d);
    };
    for (scenario, make) in [
        ("paper", Controller::paper as fn(Law) -> Controller<2>),
        ("robot", Controller::robot),
    ] {
        for law in laws {
            let ctrl = make(law);
            let (a, wa, na) = closed_loop(&ctrl, fast);
            let (b, wb, nb) = closed_loop(&ctrl, SimdPath::portable());
            for (k, (ra, rb)) in a.rows.iter().zip(&b.rows).enumerate() {
                let flat = |v: [Vector<2>; 2]| [v[0][0], v[0][1], v[1][0], v[1][1]];
                check(
                    &format!("{scenario} {law:?} step {k}: τ, sat(τ)"),
                    &flat([ra.tau, ra.tau_sat]),
                    &flat([rb.tau, rb.tau_sat]),
                );
            }
            check(&format!("{scenario} {law:?}: weights"), &wa, &wb);
            check(&format!("{scenario} {law:?}: weight norms"), &na, &nb);
            if law != Law::Pd {
                assert!(na.iter().all(|&n| n > 0.0), "{scenario} {law:?} learned");
            }
        }
    }
    // Same operations in the same order: today the paths agree exactly.
    eprintln!("{fast} vs portable: worst relative difference {worst:e}");
}
