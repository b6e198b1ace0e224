//! Cartesian impedance in closed loop (SPEC §16): a 3-link planar arm in a
//! vertical plane follows a Cartesian circle in free space, then presses on
//! a Cartesian wall and slides along it, with the hardened adaptive
//! state-feedback controller at 1 kHz inside. Exact assertions only: every
//! number below is a deterministic simulation's.

use adaptimp::network::weight_bounds;
use adaptimp::{
    rk4_step, CartesianConfig, CartesianController, CartesianImpedance, CartesianMeasurement,
    CartesianWall, Centers, Config, Controller, Environment, ImpedanceMode, Kinematics, Law, Link,
    Manipulator, PlanarArm, PoseTarget, Setpoint, Vector, WeightBound,
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

/// A Cartesian circle of radius 5 cm through p0, 0.25 Hz, in the x–y plane.
fn circle(t: f64) -> Setpoint<3> {
    let (r, w) = (0.05, PI / 2.0);
    let (s, c) = ((w * t).sin(), (w * t).cos());
    let p0 = p0();
    Setpoint {
        x: p0 + Vector::<3>::new(r * (c - 1.0), r * s, 0.0),
        dx: Vector::<3>::new(-r * w * s, r * w * c, 0.0),
        ddx: Vector::<3>::new(-r * w * w * c, -r * w * w * s, 0.0),
    }
}

/// The outer loop with the test's gains (SPEC §16 defaults, position-only:
/// the planar arm's orientation is no task; posture q0).
fn outer() -> CartesianImpedance<N, PlanarArm<N>> {
    CartesianImpedance::new(CartesianConfig::default().position_only(), arm(), TS)
        .expect("outer loop")
}

/// The joint controller: hardened state feedback at 1 kHz, impedance
/// external, Kp from the arm's inertia at q0 (a velocity loop of bandwidth
/// 0.25/Ts per joint), centres along the joint path of the circle.
fn controller(
    outer: &CartesianImpedance<N, PlanarArm<N>>,
) -> CartesianController<N, PlanarArm<N>, Centers<N, Vec<f64>>> {
    // The joint path of one period of the circle, in free space.
    let nodes = 32;
    let mut st = outer.start(q0());
    let mut samples = Vec::new();
    for k in 0..4000 {
        let sp = outer
            .step(
                &mut st,
                Some(&PoseTarget::from_position(&circle(k as f64 * TS))),
                &Vector::zeros(),
            )
            .expect("outer");
        if k % (4000 / nodes) == 0 {
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
    CartesianController::new(*outer, inner).expect("pair")
}

struct Run {
    p: Vec<Vector<3>>,
    pc: Vec<Vector<3>>,
    pd: Vec<Vector<3>>,
    f: Vec<Vector<3>>,
    tau_ok: bool,
    norms: [f64; 3],
    bound: [f64; 3],
}

fn simulate(
    traj: &dyn Fn(f64) -> Setpoint<3>,
    wall: &CartesianWall<PlanarArm<N>>,
    t_final: f64,
) -> Run {
    let arm = arm();
    let outer = outer();
    let ctrl = controller(&outer);
    let mut ost = outer.start(q0());
    let mut ist = ctrl.inner().new_state();
    let (mut q, mut dq) = (q0(), Vector::<N>::zeros());
    let tau_max = ctrl.inner().config().tau_max;
    let steps = (t_final / TS).round() as usize;
    let mut run = Run {
        p: Vec::new(),
        pc: Vec::new(),
        pd: Vec::new(),
        f: Vec::new(),
        tau_ok: true,
        norms: [0.0; 3],
        bound: match ctrl.inner().config().weight_bound {
            WeightBound::Fixed(b) => b,
            _ => unreachable!(),
        },
    };
    for k in 0..steps {
        let t = k as f64 * TS;
        let f_e = wall.wrench(&q, &dq);
        let c = traj(t);
        let mut wrench = Vector::<6>::zeros();
        wrench.fixed_rows_mut::<3>(0).copy_from(&f_e);
        let m = CartesianMeasurement {
            q,
            dq: Some(dq),
            wrench,
        };
        let target = PoseTarget::from_position(&c);
        let cmd = ctrl
            .step(&mut ost, &mut ist, &m, Some(&target))
            .expect("step");
        let tau = cmd.joint.tau_sat;
        run.tau_ok &= tau.iter().zip(tau_max.iter()).all(|(t, l)| t.abs() <= *l);
        run.p.push(cmd.p);
        run.pc.push(c.x);
        run.pd.push(cmd.compliant.p);
        run.f.push(f_e);
        // The plant: 10 RK4 substeps per period, τ held, contact recomputed.
        let h = TS / 10.0;
        for i in 0..10 {
            let ti = t + i as f64 * h;
            let a = arm.forward_dynamics(&q, &dq, &tau, &wall.force(ti, &q, &dq));
            (q, dq) = rk4_step(&arm, wall, ti, h, &tau, (q, dq), &a);
        }
    }
    run.norms = ist.weights().norms();
    run
}

#[test]
fn a_cartesian_circle_is_tracked_in_free_space() {
    // The wall far away: free space.
    let wall = CartesianWall::new(arm(), Vector::<3>::new(1.0, 0.0, 0.0), 10.0, 5000.0, 50.0)
        .expect("wall");
    let r = simulate(&circle, &wall, 12.0);
    let after = 4000;
    let rms = |a: &[Vector<3>], b: &[Vector<3>]| {
        (a[after..]
            .iter()
            .zip(&b[after..])
            .map(|(x, y)| (x - y).norm_squared())
            .sum::<f64>()
            / (a.len() - after) as f64)
            .sqrt()
    };
    let e_track = rms(&r.p, &r.pc);
    let e_ref = rms(&r.pd, &r.pc);
    println!(
        "free space: RMS ‖p − pc‖ = {e_track:.3e} m, ‖pd − pc‖ = {e_ref:.3e} m, weights {:?} ≤ {:?}",
        r.norms, r.bound
    );
    // In free space the compliant reference is the command (F_e = 0): only
    // the Euler discretisation of (C1) separates them (measured 7.7e-6 m).
    assert!(e_ref < 1e-4, "{e_ref}");
    // Tracking a 5 cm circle: measured 2.9 mm RMS after 4 s; a factor 1.7 of slack.
    assert!(e_track < 5e-3, "{e_track}");
    assert!(r.tau_ok, "a torque beyond its limit");
    for (n, b) in r.norms.iter().zip(r.bound) {
        assert!(n.is_finite() && *n <= b * (1.0 + 1e-12), "{:?}", r.norms);
    }
}

#[test]
fn pressing_on_a_wall_gives_the_force_the_target_impedance_prescribes() {
    let (ke, depth) = (5000.0, 0.02);
    let w = p0()[0] + 0.02;
    let wall =
        CartesianWall::new(arm(), Vector::<3>::new(1.0, 0.0, 0.0), w, ke, 50.0).expect("wall");
    // Move 4 cm along +x in 1 s (cosine blend): 2 cm into the wall; hold.
    let line = move |t: f64| {
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
    };
    let r = simulate(&line, &wall, 6.0);
    let last = r.f.len() - 1;
    let n = Vector::<3>::new(1.0, 0.0, 0.0);
    let f = n.dot(&r.f[last]);
    let kd = CartesianConfig::default().kd[0];
    // At rest the target impedance (C1) is K_d (p_c − p_d) = F_e.
    let model = kd * n.dot(&(r.pc[last] - r.pd[last]));
    // With the wall a spring ke in series with K_d, and p = p_d + e:
    // F = K_d ke/(K_d + ke) (depth + n·e) (SPEC §16).
    let series = kd * ke / (kd + ke);
    let e = n.dot(&(r.p[last] - r.pd[last]));
    println!(
        "wall: F = {f:.4} N, K_d (p_c − p_d) = {model:.4} N, K_d ke/(K_d + ke)·depth = {:.4} N, K_d·depth = {:.4} N, n·(p − p_d) = {e:.3e} m, weights {:?} ≤ {:?}",
        series * depth,
        kd * depth,
        r.norms,
        r.bound
    );
    // The outer loop has settled onto its target impedance: within 0.1 %
    // (measured 0.03 %: the last of the damped transient).
    assert!((f - model).abs() < 1e-3 * f, "{f} vs {model}");
    // The force is what the impedance prescribes for the commanded
    // penetration, up to the inner loop's tracking error along n, which the
    // series formula accounts for exactly; that error is under 1 mm (5 % of
    // the force: measured 0.58 mm, 2.9 %).
    assert!(e.abs() < 1e-3, "{e}");
    assert!(
        (f - series * (depth + e)).abs() < 2e-3 * f,
        "{f} vs {}",
        series * (depth + e)
    );
    assert!(r.tau_ok, "a torque beyond its limit");
}
