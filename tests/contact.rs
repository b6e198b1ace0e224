//! Contact that holds (SPEC §19): the formulations of the Cartesian
//! impedance against a wall, on the 3-link planar arm of `tests/cartesian.rs`
//! in a vertical plane, hardened adaptive state feedback at 1 kHz. Exact
//! assertions on deterministic simulations.

use adaptimp::network::weight_bounds;
use adaptimp::{
    rk4_step, CartesianConfig, CartesianController, CartesianImpedance, CartesianMeasurement,
    CartesianWall, Centers, Config, Controller, Environment, Formulation, ImpedanceMode,
    Kinematics, Law, Link, Manipulator, PlanarArm, PoseTarget, Setpoint, Vector, WeightBound,
};
use core::f64::consts::PI;

const N: usize = 3;
const TS: f64 = 1e-3;

fn arm() -> PlanarArm<N> {
    let link = |mass: f64, length: f64| Link {
        mass,
        length,
        com: length / 2.0,
        inertia: mass * length * length / 12.0,
    };
    PlanarArm::new([link(2.0, 0.4), link(1.5, 0.35), link(1.0, 0.25)], 9.81).expect("arm")
}

fn q0() -> Vector<N> {
    Vector::<N>::new(1.2, -1.2, -0.6)
}

fn p0() -> Vector<3> {
    arm().fk(&q0())
}

/// The outer loop (SPEC §16 defaults, position-only) with `formulation`.
fn outer(formulation: Formulation, share: f64) -> CartesianImpedance<N, PlanarArm<N>> {
    let cfg = CartesianConfig {
        formulation,
        admittance_share: share,
        ..CartesianConfig::default().position_only()
    };
    CartesianImpedance::new(cfg, arm(), TS).expect("outer loop")
}

type Pair = CartesianController<N, PlanarArm<N>, Centers<N, Vec<f64>>>;

/// Hardened state feedback, Kp = 0.25/(Ts (D⁻¹)_ii) at q0, K1 = 20, Γ = 1,
/// centres along the joint path of the press (as `tests/cartesian.rs`);
/// `feedforward`: the law's +τe (C5, the paper's law as printed).
fn controller(
    outer: CartesianImpedance<N, PlanarArm<N>>,
    feedforward: bool,
    path: &dyn Fn(f64) -> Setpoint<3>,
) -> Pair {
    let nodes = 32;
    let mut st = outer.start(q0());
    let mut samples = Vec::new();
    for k in 0..2000 {
        let sp = outer
            .step(
                &mut st,
                Some(&PoseTarget::from_position(&path(k as f64 * TS))),
                &Vector::zeros(),
            )
            .expect("outer");
        if k % (2000 / nodes) == 0 {
            samples.push(sp);
        }
    }
    let basis = Centers::along(&samples, [0.2, 0.5]).expect("basis");
    let tau_max = Vector::<N>::new(60.0, 30.0, 15.0);
    let mut cfg = Config::<N>::new(Law::StateFeedback, tau_max).hardened();
    cfg.ts = TS;
    cfg.impedance = ImpedanceMode::External;
    let dinv = arm()
        .inertia(&q0())
        .try_inverse()
        .expect("D > 0")
        .diagonal();
    cfg.kp = dinv.map(|x| 0.25 / (TS * x));
    cfg.kzeta = cfg.kp.map(|k| (1.0 + k * k) / 2.0 + 10.0);
    cfg.k1 = Vector::from_element(20.0);
    cfg.gamma = [1.0; 3];
    cfg.weight_bound = WeightBound::Fixed(weight_bounds(&tau_max, samples.len(), 1.0, 10.0));
    let inner = Controller::new(cfg, basis).expect("joint controller");
    let cfg = CartesianConfig {
        force_feedforward: feedforward,
        ..*outer.config()
    };
    let outer = CartesianImpedance::new(cfg, arm(), TS).expect("outer");
    CartesianController::new(outer, inner).expect("pair")
}

/// Move `2 cm + depth` along +x in 1 s (cosine blend) from p0, then hold:
/// `depth` into a wall 2 cm in front of p0.
fn press(depth: f64) -> impl Fn(f64) -> Setpoint<3> {
    move |t: f64| {
        let d = 0.02 + depth;
        let (s, ds, dds) = if t < 1.0 {
            (
                (1.0 - (PI * t).cos()) / 2.0,
                PI * (PI * t).sin() / 2.0,
                PI * PI * (PI * t).cos() / 2.0,
            )
        } else {
            (1.0, 0.0, 0.0)
        };
        Setpoint {
            x: p0() + Vector::<3>::new(d * s, 0.0, 0.0),
            dx: Vector::<3>::new(d * ds, 0.0, 0.0),
            ddx: Vector::<3>::new(d * dds, 0.0, 0.0),
        }
    }
}

struct Run {
    /// The normal force n·F_e at every step (N).
    f: Vec<f64>,
    /// p_c, p_d, p at the last step.
    last: [Vector<3>; 3],
    tau: Vec<Vector<N>>,
    norms: Vec<[f64; 3]>,
    tau_ok: bool,
}

fn simulate(
    ctrl: &Pair,
    wall: &CartesianWall<PlanarArm<N>>,
    path: &dyn Fn(f64) -> Setpoint<3>,
    t_final: f64,
) -> Run {
    let arm = arm();
    let mut ost = ctrl.outer().start(q0());
    let mut ist = ctrl.inner().new_state();
    let (mut q, mut dq) = (q0(), Vector::<N>::zeros());
    let tau_max = ctrl.inner().config().tau_max;
    let mut run = Run {
        f: Vec::new(),
        last: [Vector::zeros(); 3],
        tau: Vec::new(),
        norms: Vec::new(),
        tau_ok: true,
    };
    let n = Vector::<3>::new(1.0, 0.0, 0.0);
    for k in 0..(t_final / TS).round() as usize {
        let t = k as f64 * TS;
        let f_e = wall.wrench(&q, &dq);
        let c = path(t);
        let mut wrench = Vector::<6>::zeros();
        wrench.fixed_rows_mut::<3>(0).copy_from(&f_e);
        let m = CartesianMeasurement {
            q,
            dq: Some(dq),
            wrench,
        };
        let cmd = ctrl
            .step(&mut ost, &mut ist, &m, Some(&PoseTarget::from_position(&c)))
            .expect("step");
        let tau = cmd.joint.tau_sat;
        run.tau_ok &= tau.iter().zip(tau_max.iter()).all(|(t, l)| t.abs() <= *l);
        run.f.push(n.dot(&f_e));
        run.tau.push(cmd.joint.tau);
        run.norms.push(cmd.joint.w_norms);
        run.last = [c.x, cmd.compliant.p, cmd.p];
        let h = TS / 10.0;
        for i in 0..10 {
            let ti = t + i as f64 * h;
            let a = arm.forward_dynamics(&q, &dq, &tau, &wall.force(ti, &q, &dq));
            (q, dq) = rk4_step(&arm, wall, ti, h, &tau, (q, dq), &a);
        }
    }
    run
}

/// RMS of the sample-to-sample difference of `f` over the steps from `from` (N).
fn chatter(f: &[f64], from: usize) -> f64 {
    let d: Vec<f64> = f[from..].windows(2).map(|w| w[1] - w[0]).collect();
    (d.iter().map(|x| x * x).sum::<f64>() / d.len() as f64).sqrt()
}

fn wall(ke: f64) -> CartesianWall<PlanarArm<N>> {
    // Critically damped for the arm's ≈ 1 kg along x.
    CartesianWall::new(
        arm(),
        Vector::<3>::new(1.0, 0.0, 0.0),
        p0()[0] + 0.02,
        ke,
        2.0 * ke.sqrt(),
    )
    .expect("wall")
}

#[test]
fn an_admittance_share_of_one_is_the_admittance_step() {
    let path = press(0.01);
    let w = wall(5000.0);
    let a = simulate(
        &controller(outer(Formulation::Admittance, 0.0), true, &path),
        &w,
        &path,
        2.0,
    );
    let u = simulate(
        &controller(outer(Formulation::Unified, 1.0), true, &path),
        &w,
        &path,
        2.0,
    );
    assert_eq!(a.tau, u.tau);
    assert_eq!(a.f, u.f);
}

#[test]
fn the_torque_level_step_does_not_carry_this_samples_wrench() {
    // (19.2) with n = 0: the measured wrench reaches the compliant reference
    // and the learning error, never the torque of the same sample.
    let path = press(0.01);
    let ctrl = controller(outer(Formulation::Impedance, 0.0), false, &path);
    let st = ctrl.outer().start(q0());
    let ist = ctrl.inner().new_state();
    let m = |f: f64| CartesianMeasurement {
        q: q0() + Vector::<N>::new(0.01, -0.02, 0.03),
        dq: Some(Vector::<N>::new(0.1, 0.2, -0.1)),
        wrench: Vector::<6>::new(f, -0.5 * f, 0.0, 0.0, 0.0, 0.0),
    };
    let target = PoseTarget::from_position(&path(0.3));
    let mut taus = Vec::new();
    for f in [0.0, 7.5, -40.0] {
        let (mut o, mut i) = (st, ist.clone());
        // The wrench of step 1 moves p̈_d at once, q̇_d at step 2 (not the
        // torque: n = 0) and, through the learning error of step 2, the
        // weights and the torque of step 3.
        let first = ctrl
            .step(&mut o, &mut i, &m(f), Some(&target))
            .expect("step");
        let second = ctrl
            .step(&mut o, &mut i, &m(0.0), Some(&target))
            .expect("step");
        let third = ctrl
            .step(&mut o, &mut i, &m(0.0), Some(&target))
            .expect("step");
        taus.push((
            first.joint.tau,
            first.compliant.ddp,
            third.joint.tau,
            second.joint.tau,
        ));
    }
    for k in 1..3 {
        assert_eq!(
            taus[k].0, taus[0].0,
            "the same sample's torque moved with the wrench"
        );
        assert_eq!(taus[k].3, taus[0].3, "the next sample's torque moved");
        assert_ne!(
            taus[k].1, taus[0].1,
            "the wrench did not reach the compliant reference"
        );
        assert_ne!(
            taus[k].2, taus[0].2,
            "the wrench did not reach the learning"
        );
    }
    // The admittance (C5 with +τe) answers the same sample's wrench.
    let adm = controller(outer(Formulation::Admittance, 0.0), true, &path);
    let (mut o1, mut i1, mut o2, mut i2) =
        (st, adm.inner().new_state(), st, adm.inner().new_state());
    let a1 = adm
        .step(&mut o1, &mut i1, &m(0.0), Some(&target))
        .expect("step");
    let a2 = adm
        .step(&mut o2, &mut i2, &m(7.5), Some(&target))
        .expect("step");
    assert_ne!(a1.joint.tau, a2.joint.tau);
}

#[test]
fn the_admittance_share_is_checked_by_name() {
    let cfg = CartesianConfig {
        formulation: Formulation::Unified,
        admittance_share: 1.5,
        ..CartesianConfig::default().position_only()
    };
    let e = CartesianImpedance::new(cfg, arm(), TS).unwrap_err();
    assert!(e.to_string().contains("0 ≤ admittance_share ≤ 1"), "{e}");
    let cfg = CartesianConfig {
        admittance_share: -0.1,
        ..cfg
    };
    let e = CartesianImpedance::new(cfg, arm(), TS).unwrap_err();
    assert!(e.to_string().contains("0 ≤ admittance_share ≤ 1"), "{e}");
}

/// (16.1) for a wall of stiffness ke in series with K_d, with p = p_d + e.
fn prescribed(ke: f64, depth: f64, run: &Run) -> (f64, f64) {
    let kd = CartesianConfig::default().kd[0];
    let n = Vector::<3>::new(1.0, 0.0, 0.0);
    let e = n.dot(&(run.last[2] - run.last[1]));
    (kd * ke / (kd + ke) * (depth + e), e)
}

#[test]
fn a_stiff_wall_is_held_by_the_torque_level_formulation_and_not_by_the_admittance() {
    // A wall of 1 MN/m, critically damped (0.005 mm under the 5 N the
    // impedance prescribes for δ_c = 1 cm): the admittance's stiff joint
    // loop around a reference the wrench drives is a loop of gain > 1
    // through the wall, with the paper's +τe feedforward (C5) or without.
    let (ke, depth) = (1e6, 0.01);
    let kd_depth = CartesianConfig::default().kd[0] * depth;
    let path = press(depth);
    let w = wall(ke);
    let from = 2000;
    let mut rows = Vec::new();
    for (formulation, share, ff) in [
        (Formulation::Admittance, 0.0, true),
        (Formulation::Admittance, 0.0, false),
        (Formulation::Impedance, 0.0, false),
        (Formulation::Unified, 0.3, true),
        (Formulation::Unified, 0.5, true),
    ] {
        let r = simulate(
            &controller(outer(formulation, share), ff, &path),
            &w,
            &path,
            6.0,
        );
        let tail = &r.f[from..];
        let mean = tail.iter().sum::<f64>() / tail.len() as f64;
        let rms =
            (tail.iter().map(|x| (x - kd_depth).powi(2)).sum::<f64>() / tail.len() as f64).sqrt();
        let lost = tail.iter().filter(|x| **x <= 0.0).count();
        let c = chatter(&r.f, from);
        println!(
            "{formulation:?} n = {share}, +τe {ff}: mean {mean:.4} N, RMS (F − K_d δ_c) {rms:.4} N, chatter {c:.4} N, {lost} steps without contact (t ≥ 2 s)"
        );
        rows.push((rms, c, lost, r.tau_ok));
    }
    // Admittance, with and without +τe: the force jumps by more than twice
    // K_d δ_c per sample (measured 30–34 N) and the tool leaves the wall.
    for r in [&rows[0], &rows[1]] {
        assert!(r.1 > 2.0 * kd_depth && r.2 > 0, "{r:?}");
    }
    // Torque-level, and unified with n = 0.3 and 0.5 and the paper's +τe:
    // chatter under 0.1 % of K_d δ_c (measured 0.0002–0.0004 N), contact
    // never lost, the force within 10 % and 15 % RMS of K_d δ_c while the
    // networks still learn (6 s; measured 8.7 %, 11.1 % and 10.2 %). Unified
    // n = 0.5 chattered (30 N per sample) while D̂'s regressor carried the
    // compliant acceleration, i.e. this sample's wrench (SPEC (19.2)).
    for (r, within) in [(&rows[2], 0.10), (&rows[3], 0.15), (&rows[4], 0.15)] {
        assert!(
            r.0 < within * kd_depth && r.1 < 1e-3 * kd_depth && r.2 == 0 && r.3,
            "{r:?}"
        );
    }
}

#[test]
fn against_a_5_kn_per_m_wall_the_force_is_what_16_1_prescribes() {
    let (ke, depth) = (5000.0, 0.02);
    let path = press(depth);
    for (formulation, share) in [
        (Formulation::Admittance, 0.0),
        (Formulation::Impedance, 0.0),
        (Formulation::Unified, 0.5),
    ] {
        let r = simulate(
            &controller(outer(formulation, share), false, &path),
            &wall(ke),
            &path,
            6.0,
        );
        let f = *r.f.last().expect("rows");
        let (prescribed, e) = prescribed(ke, depth, &r);
        println!("{formulation:?}: F = {f:.4} N, (16.1) {prescribed:.4} N, n·e = {e:.3e} m");
        assert!(
            (f - prescribed).abs() < 0.02 * prescribed,
            "{f} vs {prescribed}"
        );
        assert!(r.tau_ok);
    }
}

#[test]
fn learning_in_contact_holds_the_force_and_the_weights_level_out() {
    // 40 s pressing on the stiff wall with the torque-level formulation: the
    // networks learn from the compliant error, so they do not integrate the
    // contact force (the force stays at K_d k_e/(K_d + k_e)(δ_c + n·e)), and
    // the weight norms level out.
    let (ke, depth) = (1e6, 0.01);
    let path = press(depth);
    let r = simulate(
        &controller(outer(Formulation::Impedance, 0.0), false, &path),
        &wall(ke),
        &path,
        40.0,
    );
    let (f, e) = prescribed(ke, depth, &r);
    let at = |t: f64| r.norms[(t / TS) as usize - 1];
    let tail = &r.f[r.f.len() - 10_000..];
    let mean = tail.iter().sum::<f64>() / tail.len() as f64;
    println!(
        "40 s: mean force {mean:.4} N (last 10 s), prescribed {f:.4} N, n·e = {e:.3e} m; weight norms at 20 s {:?}, 30 s {:?}, 40 s {:?}",
        at(20.0),
        at(30.0),
        at(40.0)
    );
    // (16.1) with the measured n·e, and K_d δ_c itself: within 2 %
    // (measured 0.0 % and 1.3 %).
    assert!((mean - f).abs() < 0.02 * f, "{mean} vs {f}");
    let kd_depth = CartesianConfig::default().kd[0] * depth;
    assert!((mean - kd_depth).abs() < 0.02 * kd_depth, "{mean}");
    // Ŵ_G level (within 0.1 % over the last 20 s); Ŵ_D, Ŵ_C, whose
    // regressors q̈_c, q̇_c vanish while the command holds, only leak.
    let (a, b) = (at(20.0), at(40.0));
    assert!((b[2] - a[2]).abs() <= 1e-3 * a[2], "{a:?} → {b:?}");
    assert!(b[0] <= a[0] && b[1] <= a[1], "{a:?} → {b:?}");
}
