//! The inertia-shaped gains of SPEC (18.12): the law with Dₛ in place of
//! diag(d), its checks, its parameter, and the rule that makes it.

use adaptimp::dynamic as dy;
use adaptimp::schema::{Preset, Value};
use adaptimp::{Config, Controller, Law, Measurement, Sinusoid, Trajectory, Vector};
use nalgebra::SMatrix;

type Matrix<const N: usize> = SMatrix<f64, N, N>;

/// The robot preset's state feedback for 2 joints with unequal scales, the
/// rate Kp/d 250 /s on both, and actuators that saturate (the auxiliary
/// system acts).
fn config() -> Config<2> {
    let mut cfg = Config::robot(Law::StateFeedback);
    cfg.inertia = Vector::<2>::new(2.0, 0.5);
    cfg.kp = Vector::<2>::new(500.0, 125.0);
    cfg.kzeta = Vector::<2>::new(400.0, 400.0);
    cfg.tau_max = Vector::<2>::new(20.0, 5.0);
    cfg
}

fn measurement(k: usize) -> Measurement<2> {
    let t = k as f64 * 1e-3;
    Measurement {
        x: Vector::<2>::new(0.2 + 0.05 * t, -0.1 + 0.02 * t),
        dx: Some(Vector::<2>::new(0.3, -0.2)),
        tau_e: Vector::<2>::zeros(),
    }
}

/// The torques of 200 steps along the paper's circle.
fn torques(cfg: Config<2>) -> Vec<Vector<2>> {
    let traj = Sinusoid::paper();
    let c = Controller::for_trajectory(cfg, adaptimp::rbf::Grid::paper(), &traj).unwrap();
    let mut st = c.new_state();
    (0..200)
        .map(|k| {
            let sp = traj.sample(c.time(&st));
            c.step(&mut st, &measurement(k), &sp).unwrap().tau
        })
        .collect()
}

#[test]
fn a_diagonal_inertia_matrix_is_the_diagonal_law() {
    let diagonal = torques(config());
    // The run saturates: the auxiliary system's weighting is exercised too.
    assert!(diagonal.iter().any(|t| t[1].abs() > 5.0));
    let mut cfg = config();
    cfg.inertia_matrix = Some(Matrix::<2>::from_diagonal(&cfg.inertia));
    let shaped = torques(cfg);
    for (a, b) in diagonal.iter().zip(&shaped) {
        // R^½ diag(d) R^½ = diag(Kp) to rounding.
        assert!((a - b).amax() <= 1e-12 * a.amax().max(1.0), "{a} vs {b}");
    }
    // Coupling changes the law: an off-diagonal inertia couples the joints.
    let mut cfg = config();
    cfg.inertia_matrix = Some(Matrix::<2>::new(2.0, 0.6, 0.6, 0.5));
    let coupled = torques(cfg);
    assert!((coupled[0] - diagonal[0]).amax() > 1e-3);
}

#[test]
fn the_coupled_gain_is_made_once_from_the_rates() {
    let mut cfg = config();
    let ds = Matrix::<2>::new(2.0, 0.6, 0.6, 0.5);
    cfg.inertia_matrix = Some(ds);
    let c =
        Controller::for_trajectory(cfg, adaptimp::rbf::Grid::paper(), &Sinusoid::paper()).unwrap();
    let k = c.coupling().expect("coupled");
    // Kp = R^½ Dₛ R^½, R = diag(Kp_i/d_i) = 250 /s on both joints.
    let r = [250.0f64, 250.0];
    for i in 0..2 {
        for j in 0..2 {
            let want = r[i].sqrt() * ds[(i, j)] * r[j].sqrt();
            assert!((k.kp()[(i, j)] - want).abs() <= 1e-12 * want.abs());
        }
    }
    assert!((k.kp() * k.kp_inv() - Matrix::<2>::identity()).amax() < 1e-12);
    assert!((k.inertia() * k.inertia_inv() - Matrix::<2>::identity()).amax() < 1e-12);
    assert_eq!(k.inertia(), &ds);
}

#[test]
fn an_inertia_matrix_that_is_not_one_is_refused_by_name() {
    let build = |m: Matrix<2>| {
        let mut cfg = config();
        cfg.inertia_matrix = Some(m);
        Controller::for_trajectory(cfg, adaptimp::rbf::Grid::paper(), &Sinusoid::paper())
            .unwrap_err()
            .to_string()
    };
    let not = "inertia_matrix: must be symmetric positive definite (kg m²)";
    assert_eq!(build(Matrix::<2>::new(2.0, 0.6, 0.5, 0.5)), not);
    assert_eq!(build(Matrix::<2>::new(1.0, 2.0, 2.0, 1.0)), not);
    assert_eq!(
        build(Matrix::<2>::new(f64::NAN, 0.0, 0.0, 1.0)),
        "inertia_matrix[0] is not finite (NaN or infinite)"
    ); // Opposite signs within 1e-9 of the largest entry: not symmetric.
    assert_eq!(build(Matrix::<2>::new(1e6, 5e-4, -5e-4, 1.0)), not);
    // (λmin from the bound on λmax(Dₛ⁻¹), within 1 % of it.)
    assert_eq!(
        build(Matrix::<2>::identity() * 1e-12),
        "condition λmin(inertia_matrix) ≥ 1e-9 is violated: λmin(inertia_matrix) = 0.0000000000009972960560854704 (SPEC §10)"
    );
    let with = |f: &dyn Fn(&mut Config<2>)| {
        let mut cfg = config();
        cfg.inertia_matrix = Some(Matrix::<2>::new(2.0, 0.6, 0.6, 0.5));
        f(&mut cfg);
        Controller::for_trajectory(cfg, adaptimp::rbf::Grid::paper(), &Sinusoid::paper())
            .unwrap_err()
            .to_string()
    };
    let uniform =
        "inertia_matrix: needs K1, Kzeta and Kp/inertia the same on every joint (SPEC (18.12)); \
         gains that differ by joint take the diagonal law (no inertia_matrix: the rule's \
         coupled = false)";
    assert_eq!(with(&|c| c.k1 = Vector::<2>::new(1.0, 100.0)), uniform);
    assert_eq!(with(&|c| c.kzeta = Vector::<2>::new(400.0, 500.0)), uniform);
    assert_eq!(with(&|c| c.kp = Vector::<2>::new(500.0, 60.0)), uniform);
    assert_eq!(
        with(&|c| {
            // The paper's unit weights, for which (13) holds diagonal.
            c.conditions = adaptimp::Conditions::Paper;
            (c.inertia, c.kp, c.rho) = (Vector::<2>::repeat(1.0), Vector::<2>::repeat(5.0), 1.0);
        }),
        "inertia_matrix: needs conditions = scaled (SPEC (18.12))"
    );
}

#[test]
fn the_parameter_goes_in_and_out_row_major_and_none_is_the_default() {
    let mut s = dy::Scenario::new(2, Preset::Robot, Law::StateFeedback).unwrap();
    let mut seen = None;
    s.visit(|name, v| {
        if name == "inertia_matrix" {
            seen = Some(v == Value::None);
        }
    });
    assert_eq!(seen, Some(true));
    s.set("inertia_matrix", Value::Vec(&[2.0, 0.6, 0.6, 0.5]))
        .unwrap();
    let mut out = Vec::new();
    s.visit(|name, v| {
        if let ("inertia_matrix", Value::Vec(m)) = (name, v) {
            out = m.to_vec();
        }
    });
    assert_eq!(out, [2.0, 0.6, 0.6, 0.5]);
    let e = s
        .set("inertia_matrix", Value::Vec(&[1.0, 2.0, 3.0]))
        .unwrap_err();
    assert_eq!(
        e.to_string(),
        "inertia_matrix: wrong length: n × n values, row-major"
    );
    let c = s.controller().unwrap();
    assert_eq!(c.inertia_matrix(), Some(vec![2.0, 0.6, 0.6, 0.5]));
}

/// D(q) of a two-link arm (unit masses and lengths, centres at the tips).
fn inertia(q2: f64) -> Matrix<2> {
    let c = q2.cos();
    Matrix::<2>::new(3.0 + 2.0 * c, 1.0 + c, 1.0 + c, 1.0)
}

#[test]
fn the_rule_takes_the_harmonic_mean_and_sizes_the_margin_at_its_modes() {
    let ds: Vec<Matrix<2>> = [0.3, 1.2, 2.4].iter().map(|q| inertia(*q)).collect();
    let flat: Vec<f64> = ds
        .iter()
        .flat_map(|d| d.transpose().as_slice().to_vec())
        .collect();
    let tau = [50.0, 50.0];
    let mut t = dy::Tuning::new(Law::StateFeedback, dy::Inertia::Along(&flat), &tau, 1e-3);
    // By default the rule shapes the gains for a loop with a delay, and
    // keeps the diagonal scales without one (SPEC (18.12)).
    assert!(!t.coupled());
    let undelayed = t.suggest().unwrap();
    assert_eq!(undelayed.controller().unwrap().inertia_matrix(), None);
    t.delay = 2;
    assert!(t.coupled());
    // On a Cartesian task's orbit too (the rule of (16.10)).
    t.resolve = true;
    assert!(t.coupled());
    t.resolve = false;
    let coupled = t.suggest().unwrap();
    t.coupled = Some(false);
    let diagonal = t.suggest().unwrap();
    assert_eq!(diagonal.controller().unwrap().inertia_matrix(), None);
    t.delay = 0;
    t.coupled = Some(true);
    let asked = t.suggest().unwrap();
    assert!(asked.controller().unwrap().inertia_matrix().is_some());
    let got = coupled.controller().unwrap().inertia_matrix().unwrap();
    // (mean D⁻¹)⁻¹, computed here independently.
    let mean = ds
        .iter()
        .map(|d| d.try_inverse().unwrap())
        .sum::<Matrix<2>>()
        / 3.0;
    let want = mean.try_inverse().unwrap();
    for (g, w) in got.iter().zip(want.transpose().as_slice()) {
        assert!(
            (g - w).abs() <= 1e-12 * w.abs().max(1.0),
            "{got:?} vs {want}"
        );
    }
    // The margin of (18.11) at the largest mode of Dₛ^½ D⁻¹ Dₛ^½ (eigenvalues
    // computed here by nalgebra's symmetric eigensolver): Kp/d = g_δ/(λmax Ts)
    // (within the 1 % of the core's bound), and the coupled modes lie closer
    // together than the diagonal scales' (SPEC (18.12)).
    let lmax = |scale: &Matrix<2>| {
        let root = scale.symmetric_eigen();
        let half = root.eigenvectors
            * Matrix::<2>::from_diagonal(&root.eigenvalues.map(f64::sqrt))
            * root.eigenvectors.transpose();
        ds.iter()
            .map(|d| {
                (half * d.try_inverse().unwrap() * half)
                    .symmetric_eigen()
                    .eigenvalues
                    .max()
            })
            .fold(0.0f64, f64::max)
    };
    let rate = |s: &dy::Scenario| {
        let mut kp = Vec::new();
        let mut d = Vec::new();
        s.visit(|name, v| match (name, v) {
            ("Kp", Value::Vec(x)) => kp = x.to_vec(),
            ("inertia", Value::Vec(x)) => d = x.to_vec(),
            _ => {}
        });
        (kp[0] / d[0], d)
    };
    let g = adaptimp::tuning::loop_gain(2);
    let (coupled_rate, _) = rate(&coupled);
    let want = g / (lmax(&want) * 1e-3);
    assert!(
        coupled_rate <= want * (1.0 + 1e-9) && coupled_rate >= 0.99 * want,
        "{coupled_rate} vs {want}"
    );
    let (diagonal_rate, d) = rate(&diagonal);
    let diagonal_lmax = lmax(&Matrix::<2>::from_diagonal(
        &Vector::<2>::from_column_slice(&d),
    ));
    assert!(diagonal_rate <= g / (diagonal_lmax * 1e-3) * 1.000_001);
    assert!(coupled_rate > diagonal_rate);
}

#[test]
fn the_null_space_of_a_diagonal_kp_is_the_diagonal_one() {
    use adaptimp::TaskTorque;
    let jacobian = nalgebra::SMatrix::<f64, 6, 3>::from_fn(|r, c| {
        ((r * 3 + c) as f64 * 0.37).sin() + if r == c { 1.0 } else { 0.0 }
    });
    let t = TaskTorque::<3> {
        commanded: adaptimp::trajectory::Setpoint {
            x: Vector::<3>::zeros(),
            dx: Vector::<3>::zeros(),
            ddx: Vector::<3>::zeros(),
        },
        jacobian,
        spring: nalgebra::Vector6::zeros(),
        damping: nalgebra::Vector6::zeros(),
        twist: nalgebra::Vector6::zeros(),
        lambda2: nalgebra::Vector6::from_element(1e-3),
        share: 0.0,
    };
    let kp = Vector::<3>::new(300.0, 40.0, 5.0);
    let tau = Vector::<3>::new(1.0, -2.0, 0.5);
    let diagonal = t.null_space(&kp).apply(&tau);
    let full = t
        .null_space_of(&Matrix::<3>::from_diagonal(&kp.map(|k| 1.0 / k)))
        .apply(&tau);
    assert!(
        (diagonal - full).amax() <= 1e-12 * diagonal.amax(),
        "{diagonal} vs {full}"
    );
    // Π Kp ≼ Kp: the projection removes the task's part of the torque.
    assert!(diagonal.norm() < tau.norm());
}
