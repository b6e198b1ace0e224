//! The 6-D Cartesian impedance (SPEC §16) on a 7-joint arm (the Panda's joint
//! data): the rotation error's properties through the public API, the
//! filters that keep the torque from jumping when the stiffness or the
//! target changes, and the 6-D inverse kinematics in free space.

mod common;

use adaptimp::cartesian::rotation::{exp, log_quaternion, rotation_error};
use adaptimp::{
    CartesianConfig, CartesianController, CartesianImpedance, CartesianMeasurement, CartesianState,
    Centers, Chain, Config, Controller, ImpedanceMode, Kinematics, Law, PoseTarget, Setpoint,
    Vector,
};
use nalgebra::{Matrix3, SMatrix, UnitQuaternion, Vector3};
use proptest::prelude::*;
use std::f64::consts::PI;

const TS: f64 = 1e-3;

fn home() -> Vector<7> {
    Vector::from_column_slice(&common::PANDA_HOME)
}

fn outer(cfg: CartesianConfig) -> CartesianImpedance<7, Chain<7>> {
    CartesianImpedance::new(cfg, common::panda(), TS).expect("outer loop")
}

/// A unit axis from two angles.
fn axis(a: f64, b: f64) -> Vector3<f64> {
    Vector3::new(b.sin() * a.cos(), b.sin() * a.sin(), b.cos())
}

/// The start pose of the Panda at home, and a state that has taken one step
/// there (at rest: R_d = R_c = R(home), ω_d = 0).
fn at_rest(o: &CartesianImpedance<7, Chain<7>>) -> (PoseTarget, CartesianState<7>) {
    let tip = o.kinematics().tip(&home(), &Vector::zeros());
    let c = PoseTarget::at(tip.position, *tip.rotation.matrix());
    let mut st = o.start(home());
    o.step(&mut st, Some(&c), &Vector::zeros()).expect("step");
    (c, st)
}

/// The restoring moment K_rot e_o (N m) of the impedance when the commanded
/// rotation is turned by θ about u from the compliant one, read off the
/// compliant reference's angular acceleration: M_rot ω̇_d with ω_d = ω_c = 0 and
/// no wrench (C1).
fn moment(
    o: &CartesianImpedance<7, Chain<7>>,
    rest: &(PoseTarget, CartesianState<7>),
    u: Vector3<f64>,
    theta: f64,
) -> Vector3<f64> {
    let (c, st) = rest;
    let turned = exp(&(theta * u)) * UnitQuaternion::from_matrix(&c.r);
    let target = PoseTarget::at(c.p, *turned.to_rotation_matrix().matrix());
    let s = o.stage(st, Some(&target), &Vector::zeros()).expect("stage");
    o.config().md_rot.component_mul(&s.compliant.dw)
}

/// The loop of the orientation tests: K_rot = 30 N m/rad on every axis, no
/// target filter (the moment answers the target at once), no clipping.
fn stiff() -> CartesianImpedance<7, Chain<7>> {
    outer(CartesianConfig {
        kd_rot: Vector::from_element(30.0),
        target_filter: 0.0,
        ..CartesianConfig::default()
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Below 180° the moment is exactly K θ u (so K θ u for small angles);
    /// beyond it, K (θ − 2π) u: the short way round, never more than K π.
    #[test]
    fn the_restoring_moment_is_k_theta_u_the_short_way_round(
        a in 0.0..2.0 * PI,
        b in 0.0..PI,
        deg in 0.0f64..360.0,
    ) {
        let o = stiff();
        let rest = at_rest(&o);
        let u = axis(a, b);
        let theta = deg.to_radians();
        prop_assume!((theta - PI).abs() > 1e-6);
        let m = moment(&o, &rest, u, theta);
        let k = 30.0;
        let short = if theta < PI { theta } else { theta - 2.0 * PI };
        let expect = k * short * u;
        prop_assert!((m - expect).norm() <= 1e-9 * k, "θ = {deg}°: {m} vs {expect}");
        prop_assert!(m.norm() <= k * PI * (1.0 + 1e-12));
        // Never the long way: the moment turns toward the target by the shorter angle.
        prop_assert!(m.dot(&u) * short >= 0.0);
    }

    /// The rotation error itself: Log(R_a R_bᵀ) takes b onto a, and it is antisymmetric.
    #[test]
    fn the_rotation_error_takes_b_onto_a(
        a1 in 0.0..2.0 * PI, b1 in 0.0..PI, t1 in -3.0f64..3.0,
        a2 in 0.0..2.0 * PI, b2 in 0.0..PI, t2 in -3.0f64..3.0,
    ) {
        let qa = exp(&(t1 * axis(a1, b1)));
        let qb = exp(&(t2 * axis(a2, b2)));
        let e = rotation_error(&qa, &qb);
        prop_assume!(e.norm() < PI - 1e-6);
        prop_assert!((exp(&e) * qb).angle_to(&qa) < 1e-12);
        prop_assert!((e + rotation_error(&qb, &qa)).norm() < 1e-12);
        prop_assert!((log_quaternion(&exp(&e)) - e).norm() < 1e-12);
    }
}

/// 0 … 359° in steps of 1° about a fixed oblique axis: the moment changes by at
/// most K·1° between neighbours except across 180° (where it flips from +Kπ u
/// to −Kπ u, both the shortest way), and nowhere else.
#[test]
fn the_restoring_moment_is_continuous_except_at_exactly_180_degrees() {
    let o = stiff();
    let rest = at_rest(&o);
    let u = axis(0.7, 1.1);
    let k = 30.0;
    let step = 1f64.to_radians();
    let moments: Vec<_> = (0..360)
        .map(|d| moment(&o, &rest, u, (d as f64).to_radians()))
        .collect();
    for d in 0..359 {
        let jump = (moments[d + 1] - moments[d]).norm();
        if d == 179 || d == 180 {
            continue; // 179° → 180° → 181°: the flip at exactly 180°
        }
        assert!(jump <= k * step * (1.0 + 1e-9), "{d}° → {}°: {jump}", d + 1);
    }
    // Across 180°: from +K(π − 1°)u to −K(π − 1°)u.
    let across = moments[181] - moments[179];
    assert!(
        (across + 2.0 * k * (PI - step) * u).norm() < 1e-9,
        "{across}"
    );
}

/// J⁺ = Jᵀ (J Jᵀ + Λ²)⁻¹ of (C3), explicitly, and its largest singular value.
fn pinv_norm(o: &CartesianImpedance<7, Chain<7>>, q: &Vector<7>) -> f64 {
    let j = o.kinematics().jacobian(q);
    let cfg = o.config();
    let (lp, lo) = (cfg.clik_lambda.powi(2), cfg.clik_lambda_rot.powi(2));
    let lam = SMatrix::<f64, 6, 6>::from_diagonal(&Vector::<6>::new(lp, lp, lp, lo, lo, lo));
    let a = (j * j.transpose() + lam)
        .try_inverse()
        .expect("positive definite");
    let pinv = j.transpose() * a;
    pinv.svd(false, false).singular_values.max()
}

/// A stiffness change or a target jump reaches the joint reference through
/// the first-order filter of (16.6): at the step of the change, q̈_d (what
/// every joint law's torque answers at once) moves by a_t = Ts/(τ_t + Ts) of
/// what it would move without the filter, and by at most
/// ‖J⁺‖ a_t ‖(ΔK ⊙ e + K ⊙ Δ)/M‖ (SPEC (16.7)).
#[test]
fn a_change_of_stiffness_or_target_moves_the_reference_by_a_t_of_a_jump() {
    for tau_t in [0.05, 0.2] {
        let filtered = outer(CartesianConfig {
            target_filter: tau_t,
            ..CartesianConfig::default()
        });
        let bare = outer(CartesianConfig {
            target_filter: 0.0,
            ..CartesianConfig::default()
        });
        let at = TS / (tau_t + TS);
        // Settle under a constant wrench: the compliant pose is deflected by K⁻¹ F.
        let wrench = Vector::<6>::new(6.0, -2.0, -4.0, 0.3, 0.0, -0.2);
        let (c, _) = at_rest(&filtered);
        let settle = |o: &CartesianImpedance<7, Chain<7>>| {
            let mut st = o.start(home());
            for _ in 0..6000 {
                o.step(&mut st, Some(&c), &wrench).expect("step");
            }
            st
        };
        let (sf, sb) = (settle(&filtered), settle(&bare));
        let cfg = *filtered.config();
        let m = Vector::<6>::from_iterator(cfg.md.iter().chain(cfg.md_rot.iter()).copied());
        let k = sf.stiffness;
        let norm = pinv_norm(&filtered, &sf.qd);
        assert!(norm <= 1.0 / (2.0 * cfg.clik_lambda.min(cfg.clik_lambda_rot)));

        // (a) K doubled on every axis.
        let base_f = filtered
            .stage(&sf, Some(&c), &wrench)
            .expect("stage")
            .reference
            .ddx;
        let base_b = bare
            .stage(&sb, Some(&c), &wrench)
            .expect("stage")
            .reference
            .ddx;
        let (mut f2, mut b2) = (sf, sb);
        let kd2 = 2.0 * cfg.kd;
        let kr2 = 2.0 * cfg.kd_rot;
        filtered
            .set_stiffness(&mut f2, &kd2, &kr2)
            .expect("stiffness");
        bare.set_stiffness(&mut b2, &kd2, &kr2).expect("stiffness");
        let step_f = filtered.stage(&f2, Some(&c), &wrench).expect("stage");
        let step_b = bare.stage(&b2, Some(&c), &wrench).expect("stage");
        let (df, db) = (step_f.reference.ddx - base_f, step_b.reference.ddx - base_b);
        assert!(db.norm() > 1.0, "a jump to filter: {}", db.norm());
        // Linear in the filtered stiffness up to the damping 2√(K M), which moves
        // with √K on a compliant velocity that has settled to ~0.
        assert!(
            (df - at * db).norm() <= 1e-6 * db.norm(),
            "{df} vs {}",
            at * db
        );
        let e = step_f.error;
        let dr = (at * k.component_mul(&e)).component_div(&m); // ΔK = K
        assert!(
            df.norm() <= norm * dr.norm() * (1.0 + 1e-9),
            "{} > {}",
            df.norm(),
            norm * dr.norm()
        );

        // (b) the target jumps 5 cm along x and 10° about z (from rest, no wrench).
        let (c0, rest_f) = at_rest(&filtered);
        let (_, rest_b) = at_rest(&bare);
        let mut jumped = c0;
        jumped.p[0] += 0.05;
        let turn = exp(&Vector::<3>::new(0.0, 0.0, 10f64.to_radians()));
        jumped.r = *(turn * UnitQuaternion::from_matrix(&c0.r))
            .to_rotation_matrix()
            .matrix();
        let base_f = filtered
            .stage(&rest_f, Some(&c0), &Vector::zeros())
            .expect("stage");
        let base_b = bare
            .stage(&rest_b, Some(&c0), &Vector::zeros())
            .expect("stage");
        let step_f = filtered
            .stage(&rest_f, Some(&jumped), &Vector::zeros())
            .expect("stage");
        let step_b = bare
            .stage(&rest_b, Some(&jumped), &Vector::zeros())
            .expect("stage");
        let df = step_f.reference.ddx - base_f.reference.ddx;
        let db = step_b.reference.ddx - base_b.reference.ddx;
        assert!(
            (df - at * db).norm() <= 1e-9 * db.norm(),
            "{df} vs {}",
            at * db
        );
        let delta = Vector::<6>::new(0.05, 0.0, 0.0, 0.0, 0.0, 10f64.to_radians());
        let dr = (at * k.component_mul(&delta)).component_div(&m);
        let norm = pinv_norm(&filtered, &rest_f.qd);
        assert!(df.norm() <= norm * dr.norm() * (1.0 + 1e-9));
    }
}

/// The pair on the held arm (q, q̇ fixed: only the reference moves), the PD
/// joint law τ = Kp (z2 + ζ) (no robust term, nothing saturates): after a target jump of 5 cm and 10° the commanded torque's change per
/// step stays below a_t times the total variation of the unfiltered torque
/// response (16.7), and its first response is a_t times the unfiltered one.
#[test]
fn a_target_jump_changes_the_torque_by_at_most_a_t_times_its_variation_per_step() {
    let run = |tau_t: f64, jump: bool| -> Vec<Vector<7>> {
        let o = outer(CartesianConfig {
            target_filter: tau_t,
            ..CartesianConfig::default()
        });
        let (c0, _) = at_rest(&o);
        let sample = Setpoint {
            x: home(),
            dx: Vector::zeros(),
            ddx: Vector::zeros(),
        };
        let basis = Centers::along(&[sample], [0.2, 0.5]).expect("basis");
        let mut cfg = Config::<7>::new(Law::Pd, Vector::from_element(1e6)).hardened();
        cfg.ts = TS;
        cfg.impedance = ImpedanceMode::External;
        cfg.kp = Vector::from_element(20.0);
        cfg.kzeta = cfg.kp.map(|k| (1.0 + k * k) / 2.0 + 10.0);
        cfg.k1 = Vector::from_element(20.0);
        cfg.weight_bound = adaptimp::WeightBound::None;
        // τ = Kp (z2 + ζ): linear in the reference (no tanh), no saturation.
        cfg.robust = adaptimp::RobustKind::None;
        let inner = Controller::new(cfg, basis).expect("joint controller");
        let pair = CartesianController::new(o, inner).expect("pair");
        let (mut ost, mut ist) = (pair.outer().start(home()), pair.inner().new_state());
        let m = CartesianMeasurement {
            q: home(),
            dq: Some(Vector::zeros()),
            wrench: Vector::zeros(),
        };
        let mut jumped = c0;
        jumped.p[0] += 0.05;
        let turn = exp(&Vector::<3>::new(0.0, 0.0, 10f64.to_radians()));
        jumped.r = *(turn * UnitQuaternion::from_matrix(&c0.r))
            .to_rotation_matrix()
            .matrix();
        (0..1500)
            .map(|k| {
                let c = if jump && k >= 500 { jumped } else { c0 };
                pair.step(&mut ost, &mut ist, &m, Some(&c))
                    .expect("step")
                    .joint
                    .tau
            })
            .collect()
    };
    let tau_t = 0.05;
    let at = TS / (tau_t + TS);
    let response = |tau_t: f64| -> Vec<Vector<7>> {
        let (a, b) = (run(tau_t, true), run(tau_t, false));
        a.iter().zip(&b).map(|(x, y)| x - y).collect()
    };
    let (filtered, bare) = (response(tau_t), response(0.0));
    let steps =
        |r: &[Vector<7>]| -> Vec<f64> { r.windows(2).map(|w| (w[1] - w[0]).amax()).collect() };
    let variation: f64 = steps(&bare).iter().sum();
    let worst = steps(&filtered).into_iter().fold(0.0, f64::max);
    let first = steps(&bare).into_iter().fold(0.0, f64::max);
    println!(
        "torque per step after a 5 cm, 10° jump: filtered max {worst:.4} N m, bound a_t·TV = {:.4} N m, unfiltered max {first:.4} N m",
        at * variation
    );
    assert!(worst <= at * variation, "{worst} > {}", at * variation);
    // The PD law answers the reference of t_k (q_d, q̇_d: set before the jump)
    // only one step later, through q̇_d += Ts q̈_d: that first response is a_t
    // times the unfiltered one, exactly (q̈_d is, at the step of the jump).
    assert_eq!(filtered[500], Vector::<7>::zeros());
    assert_eq!(bare[500], Vector::<7>::zeros());
    let (f1, b1) = (filtered[501], bare[501]);
    assert!(b1.amax() > 0.1, "{b1}");
    assert!(
        (f1 - at * b1).amax() <= 1e-9 * b1.amax(),
        "{f1} vs {}",
        at * b1
    );
}

/// Free space, the outer loop alone: a pose path (a 5 cm circle while turning
/// ±0.3 rad about the vertical) is followed by fk(q_d) to the CLIK's error,
/// and the compliant pose is the command (F_e = 0).
#[test]
fn the_six_d_inverse_kinematics_follows_a_pose_path() {
    let o = outer(CartesianConfig::default());
    let tip = o.kinematics().tip(&home(), &Vector::zeros());
    let (p0, r0) = (
        tip.position,
        UnitQuaternion::from_rotation_matrix(&tip.rotation),
    );
    let w = PI / 2.0;
    let path = |t: f64| {
        let (s, c) = ((w * t).sin(), (w * t).cos());
        let yaw = 0.3 * s;
        PoseTarget {
            p: p0 + Vector::<3>::new(0.05 * (c - 1.0), 0.05 * s, 0.0),
            dp: Vector::<3>::new(-0.05 * w * s, 0.05 * w * c, 0.0),
            ddp: Vector::<3>::new(-0.05 * w * w * c, -0.05 * w * w * s, 0.0),
            r: *(exp(&Vector::<3>::new(0.0, 0.0, yaw)) * r0)
                .to_rotation_matrix()
                .matrix(),
            w: Vector::<3>::new(0.0, 0.0, 0.3 * w * c),
            dw: Vector::<3>::new(0.0, 0.0, -0.3 * w * w * s),
        }
    };
    let mut st = o.start(home());
    let (mut worst_p, mut worst_r, mut worst_c) = (0.0f64, 0.0f64, 0.0f64);
    for k in 0..4000 {
        let target = path(k as f64 * TS);
        let s = o
            .stage(&st, Some(&target), &Vector::zeros())
            .expect("stage");
        if k >= 500 {
            let at = o.kinematics().tip(&s.reference.x, &Vector::zeros());
            let rq = UnitQuaternion::from_rotation_matrix(&at.rotation);
            worst_p = worst_p.max((at.position - s.compliant.p).norm());
            worst_r = worst_r.max(rotation_error(&s.compliant.r, &rq).norm());
            let rc = UnitQuaternion::from_matrix(&target.r);
            worst_c = worst_c
                .max((s.compliant.p - target.p).norm())
                .max(rotation_error(&rc, &s.compliant.r).norm());
        }
        st = s.next;
    }
    println!("6-D CLIK: |p(q_d) − p_d| ≤ {worst_p:.2e} m, |e_o| ≤ {worst_r:.2e} rad; |x_d − x_c| ≤ {worst_c:.2e}");
    assert!(worst_p < 1e-4 && worst_r < 1e-4, "{worst_p} {worst_r}");
    // The compliant pose is the command up to the Euler discretisation of (C1).
    assert!(worst_c < 1e-4, "{worst_c}");
}

/// A bad target changes nothing and names the condition.
#[test]
fn a_rotation_that_is_not_one_is_refused() {
    let o = outer(CartesianConfig::default());
    let (c, st) = at_rest(&o);
    let mut skew = c;
    skew.r = c.r + Matrix3::from_element(1e-3);
    let e = o.stage(&st, Some(&skew), &Vector::zeros()).unwrap_err();
    assert!(e.to_string().contains("orthonormal"), "{e}");
    assert!(e.to_string().contains("R_c"), "{e}");
}
