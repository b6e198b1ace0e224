//! Cartesian impedance (SPEC §16) with a 3-link planar arm in a vertical
//! plane at 1 kHz: the end effector follows a 5 cm circle in free space, then
//! presses 2 cm into a Cartesian wall (a penalty plane, ke = 5000 N/m) and
//! holds. Prints the tracking error and the contact force against what the
//! target impedance prescribes.
//!
//! ```text
//! cargo run --release --example cartesian
//! ```

use adaptimp::network::weight_bounds;
use adaptimp::{
    rk4_step, CartesianConfig, CartesianController, CartesianImpedance, CartesianMeasurement,
    CartesianWall, Centers, Config, Controller, Environment, Error, ImpedanceMode, Kinematics, Law,
    Link, Manipulator, PlanarArm, PoseTarget, Setpoint, Vector, WeightBound,
};
use std::f64::consts::PI;

const N: usize = 3;
const TS: f64 = 1e-3;

fn arm() -> Result<PlanarArm<N>, Error> {
    let link = |mass: f64, length: f64| Link {
        mass,
        length,
        com: length / 2.0,
        inertia: mass * length * length / 12.0,
    };
    PlanarArm::new([link(2.0, 0.4), link(1.5, 0.35), link(1.0, 0.25)], 9.81)
}

/// The outer loop (SPEC §16 defaults, position-only: a planar arm's
/// orientation is no task) and the hardened adaptive joint controller with
/// centres along the joint path of the circle (SPEC §15's orbit rule).
fn controller(
    arm: PlanarArm<N>,
    q0: Vector<N>,
    circle: &dyn Fn(f64) -> Setpoint<3>,
) -> Result<CartesianController<N, PlanarArm<N>, Centers<N, Vec<f64>>>, Error> {
    let outer = CartesianImpedance::new(CartesianConfig::default().position_only(), arm, TS)?;
    let zero = Setpoint {
        x: Vector::<N>::zeros(),
        dx: Vector::zeros(),
        ddx: Vector::zeros(),
    };
    let mut samples = vec![zero; 32];
    let path = |k: usize| PoseTarget::from_position(&circle(k as f64 * TS));
    let written = outer.orbit(q0, 4000, path, &mut samples)?;
    let basis = Centers::along(&samples[..written], [0.2, 0.5])?;
    let tau_max = Vector::<N>::new(60.0, 30.0, 15.0);
    let mut cfg = Config::<N>::new(Law::StateFeedback, tau_max).hardened();
    cfg.ts = TS;
    cfg.impedance = ImpedanceMode::External;
    let d = arm
        .inertia(&q0)
        .try_inverse()
        .unwrap_or_else(adaptimp::Matrix::<N>::identity);
    cfg.kp = d.diagonal().map(|x| 0.25 / (TS * x));
    cfg.kzeta = cfg.kp.map(|k| (1.0 + k * k) / 2.0 + 10.0);
    cfg.k1 = Vector::from_element(20.0);
    cfg.gamma = [1.0; 3];
    cfg.weight_bound = WeightBound::Fixed(weight_bounds(&tau_max, samples.len(), 1.0, 10.0));
    CartesianController::new(outer, Controller::new(cfg, basis)?)
}

/// Run `t_final` seconds; returns RMS ‖p − p_c‖ after 4 s and the last
/// command, force and setpoint.
fn simulate(
    ctrl: &CartesianController<N, PlanarArm<N>, Centers<N, Vec<f64>>>,
    traj: &dyn Fn(f64) -> Setpoint<3>,
    wall: &CartesianWall<PlanarArm<N>>,
    q0: Vector<N>,
    t_final: f64,
) -> Result<
    (
        f64,
        adaptimp::CartesianCommand<N>,
        Vector<3>,
        Setpoint<3>,
        f64,
    ),
    Error,
> {
    let arm = *ctrl.outer().kinematics();
    let mut ost = ctrl.outer().start(q0);
    let mut ist = ctrl.inner().new_state();
    let (mut q, mut dq) = (q0, Vector::<N>::zeros());
    let (mut sum, mut rows, mut peak) = (0.0, 0, 0.0f64);
    let steps = (t_final / TS).round() as usize;
    let mut last = None;
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
        let cmd = ctrl.step(&mut ost, &mut ist, &m, Some(&PoseTarget::from_position(&c)))?;
        if t >= 4.0 {
            sum += (cmd.p - c.x).norm_squared();
            rows += 1;
        }
        let tau = cmd.joint.tau_sat;
        peak = peak.max(tau.amax());
        let h = TS / 10.0;
        for i in 0..10 {
            let ti = t + i as f64 * h;
            let a = arm.forward_dynamics(&q, &dq, &tau, &wall.force(ti, &q, &dq));
            (q, dq) = rk4_step(&arm, wall, ti, h, &tau, (q, dq), &a);
        }
        last = Some((cmd, f_e, c));
    }
    let (cmd, f, c) = last.ok_or(Error::Invalid {
        what: "run",
        reason: "no steps",
    })?;
    Ok(((sum / rows.max(1) as f64).sqrt(), cmd, f, c, peak))
}

fn main() -> Result<(), Error> {
    let arm = arm()?;
    let q0 = Vector::<N>::new(1.2, -1.2, -0.6);
    let p0 = arm.fk(&q0);
    let circle = move |t: f64| {
        let (r, w) = (0.05, PI / 2.0);
        let (s, c) = ((w * t).sin(), (w * t).cos());
        Setpoint {
            x: p0 + Vector::<3>::new(r * (c - 1.0), r * s, 0.0),
            dx: Vector::<3>::new(-r * w * s, r * w * c, 0.0),
            ddx: Vector::<3>::new(-r * w * w * c, -r * w * w * s, 0.0),
        }
    };
    let ctrl = controller(arm, q0, &circle)?;
    let n = Vector::<3>::new(1.0, 0.0, 0.0);
    println!(
        "3-link planar arm, Ts = 1 ms, hardened state feedback inside, {} centres along the joint path",
        adaptimp::Basis::nodes(ctrl.inner().basis())
    );

    let far = CartesianWall::new(arm, n, 10.0, 5000.0, 50.0)?;
    let (rms, _, _, _, peak) = simulate(
        &ctrl,
        &circle,
        &far,
        q0,
        if cfg!(test) { 5.0 } else { 12.0 },
    )?;
    println!(
        "circle r = 5 cm, free space: RMS ‖p − p_c‖ (t ≥ 4 s) = {:.2} mm, peak |τ| = {peak:.1} N m",
        rms * 1e3
    );

    let (ke, depth) = (5000.0, 0.02);
    let wall = CartesianWall::new(arm, n, p0[0] + 0.02, ke, 50.0)?;
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
            x: p0 + Vector::<3>::new(d * s, 0.0, 0.0),
            dx: Vector::<3>::new(d * ds, 0.0, 0.0),
            ddx: Vector::<3>::new(d * dds, 0.0, 0.0),
        }
    };
    let (_, cmd, f, c, peak) = simulate(&ctrl, &line, &wall, q0, 6.0)?;
    let kd = ctrl.outer().config().kd[0];
    println!("press 2 cm into a wall (ke = {ke} N/m), at t = 6 s:");
    println!("  contact force F_e·n            = {:.3} N", n.dot(&f));
    println!(
        "  target impedance K_d (p_c − p_d) = {:.3} N",
        kd * n.dot(&(c.x - cmd.compliant.p))
    );
    println!(
        "  K_d ke/(K_d + ke) · depth        = {:.3} N (stiff-wall limit K_d · depth = {:.1} N)",
        kd * ke / (kd + ke) * depth,
        kd * depth
    );
    println!(
        "  tracking n·(p − p_d)             = {:.3} mm; peak |τ| = {peak:.1} N m",
        n.dot(&(cmd.p - cmd.compliant.p)) * 1e3
    );
    Ok(())
}

/// `cargo test` runs this example, shortened (`cfg!(test)`).
#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main().unwrap();
    }
}
