//! Your own control loop: a 3-joint planar arm under gravity, stepped at
//! 1 kHz by the adaptive state-feedback controller, tracking setpoints that
//! come from outside (a planner, a teleoperation device, a file) rather than
//! the controller's own trajectory. Prints the RMS tracking error of PD and of
//! the adaptive controller over the last 2 s.
//!
//! ```text
//! cargo run --release --example your_loop
//! ```
//!
//! Mirrored in Python by `examples/03_your_loop.py`.

use adaptimp::model::Link;
use adaptimp::{
    Config, Controller, Grid, Law, Manipulator, Measurement, PlanarArm, Setpoint, Sinusoid,
    Trajectory, Vector,
};

const N: usize = 3;
/// Control period Ts (s).
const TS: f64 = 1e-3;

/// RMS ‖z1‖ (rad) over the last 2 s of a `seconds`-long run of `law`.
fn run(law: Law, seconds: f64) -> Result<f64, adaptimp::Error> {
    // Three 1 kg, 0.25 m links (uniform rods) in a vertical plane.
    let link = Link {
        mass: 1.0,
        length: 0.25,
        com: 0.125,
        inertia: 1.0 * 0.25 * 0.25 / 12.0,
    };
    let arm = PlanarArm::new([link; N], 9.81)?;
    // The hardened options of the robot scenario at 1 kHz; gains for these
    // light links (the learning loop needs Ts·Kp/D well below 1).
    let mut cfg = Config::<N>::new(law, Vector::from_element(40.0)).hardened();
    cfg.ts = TS;
    cfg.kp = Vector::from_element(2.0);
    cfg.kzeta = Vector::from_element(10.0);
    cfg.k1 = Vector::from_element(10.0);
    // The planner's path; it also sets the "auto" weight bounds.
    let path = Sinusoid::new(
        Vector::from_element(0.2),
        Vector::from_element(0.1),
        Vector::zeros(),
        Vector::from_element(1.0),
    )?;
    let ctrl = Controller::for_trajectory(cfg, Grid::<N>::new(25.0)?, &path)?;
    let mut state = ctrl.new_state();
    let (mut q, mut dq) = (Vector::<N>::zeros(), Vector::<N>::zeros());
    let steps = (seconds / TS).round() as usize;
    let mut sum = 0.0;
    let last = (2.0 / TS) as usize;
    for k in 0..steps {
        // The setpoint of this period, from outside.
        let s: Setpoint<N> = path.sample(k as f64 * TS);
        let m = Measurement {
            x: q,
            dx: Some(dq),
            tau_e: Vector::zeros(),
        };
        let cmd = ctrl.step(&mut state, &m, &s)?;
        // The arm: semi-implicit Euler over the period, torque held.
        let acc = arm.forward_dynamics(&q, &dq, &cmd.tau_sat, &Vector::zeros());
        dq += TS * acc;
        q += TS * dq;
        if k + last >= steps {
            sum += cmd.z1.norm_squared();
        }
    }
    Ok((sum / last.min(steps) as f64).sqrt())
}

fn main() -> Result<(), adaptimp::Error> {
    let seconds = if cfg!(test) { 2.5 } else { 10.0 };
    println!("3-joint planar arm under gravity, 1 kHz, setpoints from outside, {seconds} s");
    let pd = run(Law::Pd, seconds)?;
    let sf = run(Law::StateFeedback, seconds)?;
    println!("RMS ‖z1‖ over the last 2 s: PD {pd:.4} rad, adaptive state feedback {sf:.4} rad");
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
