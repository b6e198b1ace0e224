//! A 7-joint arm's 6-D Cartesian loop (SPEC §16), the same in Rust, Python
//! (`examples/14_cartesian_pose.py`) and C: the Franka Emika Panda's
//! kinematics from its joint data (example-robot-data's URDF), the core's
//! Cartesian controller (6-D outer loop, hardened state feedback with RBF
//! centres along the joint orbit), and a simple plant: decoupled joint
//! inertias I q̈ = sat(τ) − Jᵀ F_e, no gravity, against a table (a penalty
//! plane, k_e = 5000 N/m, b_e = 50 N s/m).
//!
//! The tool goes 5 cm forward and 4 cm down in 1 s (a quintic) while
//! turning 20° about the vertical: 1 cm into the table. Then it holds. The
//! example prints the pose error during the motion, the contact force
//! against what the target impedance prescribes, (16.1), and the torques.
//!
//! ```text
//! cargo run --release --example cartesian_pose
//! ```

use adaptimp::cartesian::rotation::{exp, rotation_error};
use adaptimp::{
    CartesianConfig, CartesianController, CartesianImpedance, CartesianMeasurement, Centers, Chain,
    Config, Controller, Error, ImpedanceMode, Joint, Kinematics, Law, PoseTarget, Setpoint,
    Transform, Vector, WeightBound,
};
use nalgebra::UnitQuaternion;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

const TS: f64 = 1e-3;
/// The plant's joint inertias (kg m²): the Panda's D(q0)_ii-equivalent
/// (1/(D⁻¹)_ii at home, from Pinocchio's CRBA).
const INERTIA: [f64; 7] = [0.27, 0.97, 0.54, 0.40, 0.037, 0.034, 0.0065];
/// The Panda's torque limits (N m).
const TAU_MAX: [f64; 7] = [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0];
/// The Panda's home posture (rad).
// The SRDF's numbers as written (close to, not exactly, π/4 and π/2).
#[allow(clippy::approx_constant)]
const HOME: [f64; 7] = [0.0, -0.785398, 0.0, -2.35619, 0.0, 1.5707, 0.785398];
/// The table: stiffness (N/m), damping (N s/m), how far below the home TCP (m).
const TABLE: (f64, f64, f64) = (5000.0, 50.0, 0.03);

/// The Panda to its tool centre point, from the URDF's joint data.
fn panda() -> Result<Chain<7>, Error> {
    let rev = |xyz: [f64; 3], roll: f64| {
        Joint::revolute(
            Transform::from_xyz_rpy(xyz, [roll, 0.0, 0.0]),
            [0.0, 0.0, 1.0],
        )
    };
    let joints = [
        rev([0.0, 0.0, 0.333], 0.0),
        rev([0.0, 0.0, 0.0], -FRAC_PI_2),
        rev([0.0, -0.316, 0.0], FRAC_PI_2),
        rev([0.0825, 0.0, 0.0], FRAC_PI_2),
        rev([-0.0825, 0.384, 0.0], -FRAC_PI_2),
        rev([0.0, 0.0, 0.0], FRAC_PI_2),
        rev([0.088, 0.0, 0.0], FRAC_PI_2),
        Joint::fixed(Transform::from_xyz_rpy([0.0, 0.0, 0.107], [0.0; 3])),
        Joint::fixed(Transform::from_xyz_rpy([0.0; 3], [0.0, 0.0, -FRAC_PI_4])),
    ];
    Chain::new(
        &joints,
        &Transform::from_xyz_rpy([0.0, 0.0, 0.1034], [0.0; 3]),
    )
}

/// The commanded pose at t (s): from (p0, R0), 5 cm along x, 4 cm down and 20°
/// about z in 1 s (10s³ − 15s⁴ + 6s⁵), then held.
fn target(p0: &Vector<3>, r0: &UnitQuaternion<f64>, t: f64) -> PoseTarget {
    let s = (t / 1.0).clamp(0.0, 1.0);
    let (f, df, ddf) = (
        s * s * s * (10.0 - 15.0 * s + 6.0 * s * s),
        30.0 * s * s * (1.0 - s) * (1.0 - s),
        60.0 * s * (1.0 - s) * (1.0 - 2.0 * s),
    );
    let d = Vector::<3>::new(0.05, 0.0, -0.04);
    let yaw = Vector::<3>::new(0.0, 0.0, 20f64.to_radians());
    PoseTarget {
        p: p0 + f * d,
        dp: df * d,
        ddp: ddf * d,
        r: *(exp(&(f * yaw)) * r0).to_rotation_matrix().matrix(),
        w: df * yaw,
        dw: ddf * yaw,
    }
}

/// The wrench the tool exerts on the table: F_e = [0, 0, −max(0, k_e δ − b_e ż),
/// 0, 0, 0] for δ = z_table − z > 0 (pressing down; the table pushes back up).
fn table(z_table: f64, p: &Vector<3>, dp: &Vector<3>) -> Vector<6> {
    let (ke, be, _) = TABLE;
    let depth = z_table - p[2];
    let push = if depth > 0.0 {
        (ke * depth - be * dp[2]).max(0.0)
    } else {
        0.0
    };
    Vector::<6>::new(0.0, 0.0, -push, 0.0, 0.0, 0.0)
}

type Pair = CartesianController<7, Chain<7>, Centers<7, Vec<f64>>>;

/// The outer loop (SPEC §16 defaults, 6-D) and the hardened state-feedback
/// joint controller, centres along the joint orbit of the commanded motion.
fn controller(chain: Chain<7>, q0: Vector<7>) -> Result<Pair, Error> {
    let outer = CartesianImpedance::new(CartesianConfig::default(), chain, TS)?;
    let tip = chain.tip(&q0, &Vector::zeros());
    let (p0, r0) = (
        tip.position,
        UnitQuaternion::from_rotation_matrix(&tip.rotation),
    );
    let zero = Setpoint {
        x: Vector::<7>::zeros(),
        dx: Vector::zeros(),
        ddx: Vector::zeros(),
    };
    let mut samples = vec![zero; 32];
    let written = outer.orbit(q0, 1500, |k| target(&p0, &r0, k as f64 * TS), &mut samples)?;
    let basis = Centers::along(&samples[..written], [0.05, 0.2])?;
    let tau_max = Vector::<7>::from(TAU_MAX);
    let mut cfg = Config::<7>::new(Law::StateFeedback, tau_max).hardened();
    cfg.ts = TS;
    cfg.impedance = ImpedanceMode::External;
    cfg.kp = Vector::<7>::from(INERTIA).map(|i| 0.25 * i / TS);
    cfg.kzeta = cfg.kp.map(|k| (1.0 + k * k) / 2.0 + 10.0);
    cfg.k1 = Vector::from_element(20.0);
    cfg.gamma = [1.0; 3];
    // ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ ≤ ‖τmax‖/√L over 10 rad/s², 1 rad/s, 1 (L = 32), rounded.
    cfg.weight_bound = WeightBound::Fixed([3.1, 31.0, 31.0]);
    CartesianController::new(outer, Controller::new(cfg, basis)?)
}

fn main() -> Result<(), Error> {
    let chain = panda()?;
    let q0 = Vector::<7>::from(HOME);
    let pair = controller(chain, q0)?;
    let tip0 = chain.tip(&q0, &Vector::zeros());
    let (p0, r0) = (
        tip0.position,
        UnitQuaternion::from_rotation_matrix(&tip0.rotation),
    );
    let z_table = p0[2] - TABLE.2;
    let inertia = Vector::<7>::from(INERTIA);
    let (mut ost, mut ist) = (pair.outer().start(q0), pair.inner().new_state());
    let (mut q, mut dq) = (q0, Vector::<7>::zeros());
    let t_final = if cfg!(test) { 1.2 } else { 2.0 };
    let steps = (t_final / TS).round() as usize;
    let (mut worst_p, mut worst_r, mut peak) = (0.0f64, 0.0f64, 0.0f64);
    let mut last = None;
    for k in 0..steps {
        let t = k as f64 * TS;
        let at = chain.tip(&q, &dq);
        let dp = at.jacobian.fixed_rows::<3>(0) * dq;
        let wrench = table(z_table, &at.position, &dp);
        let c = target(&p0, &r0, t);
        let m = CartesianMeasurement {
            q,
            dq: Some(dq),
            wrench,
        };
        let cmd = pair.step(&mut ost, &mut ist, &m, Some(&c))?;
        if (0.2..0.6).contains(&t) {
            // In free motion, before the table: the tool against the command.
            let r = UnitQuaternion::from_rotation_matrix(&at.rotation);
            worst_p = worst_p.max((at.position - c.p).norm());
            worst_r = worst_r.max(rotation_error(&UnitQuaternion::from_matrix(&c.r), &r).norm());
        }
        let tau = cmd.joint.tau_sat;
        for i in 0..7 {
            peak = peak.max(tau[i].abs() / TAU_MAX[i]);
        }
        // The plant: 10 semi-implicit Euler substeps, τ held, the contact recomputed.
        let h = TS / 10.0;
        for _ in 0..10 {
            let at = chain.tip(&q, &dq);
            let dp = at.jacobian.fixed_rows::<3>(0) * dq;
            let f = table(z_table, &at.position, &dp);
            let ddq = (tau - at.jacobian.transpose() * f).component_div(&inertia);
            dq += h * ddq;
            q += h * dq;
        }
        last = Some((cmd, wrench, c));
    }
    let (cmd, wrench, c) = last.ok_or(Error::Invalid {
        what: "run",
        reason: "no steps",
    })?;
    let kd = pair.outer().config().kd[2];
    let (ke, _, _) = TABLE;
    let depth = z_table - c.p[2];
    let e = cmd.p[2] - cmd.compliant.p[2];
    let series = kd * ke / (kd + ke);
    let r = UnitQuaternion::from_rotation_matrix(&cmd.r);
    println!(
        "Panda (7 joints), 6-D Cartesian impedance, state feedback, Ts = 1 ms, t = {t_final} s"
    );
    println!(
        "  moving (0.2 s ≤ t < 0.6 s): |p − p_c| ≤ {:.3} mm, |e_o| ≤ {:.3} mrad",
        worst_p * 1e3,
        worst_r * 1e3
    );
    println!("  normal force on the table       = {:.3} N", -wrench[2]);
    println!(
        "  target impedance K_d (p_c − p_d)_z = {:.3} N",
        -kd * (c.p[2] - cmd.compliant.p[2])
    );
    println!(
        "  (16.1): K_d k_e/(K_d + k_e)(δ_c + n·e) = {:.3} N (δ_c = {:.1} mm, n·e = {:.4} mm)",
        series * (depth - e),
        depth * 1e3,
        -e * 1e3
    );
    println!(
        "  orientation error |Log(R_c Rᵀ)| = {:.3} mrad; peak |τ_i|/τmax_i = {peak:.3}",
        rotation_error(&UnitQuaternion::from_matrix(&c.r), &r).norm() * 1e3
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
