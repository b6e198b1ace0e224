//! Worst-case step time: a 1 kHz loop cares about the slowest step, not the
//! mean. Runs each controller for 10⁶ steps in closed loop with the paper's arm
//! and wall (so the inputs are realistic), times every `step` call, and prints
//! the median, the 99.9th percentile and the maximum, with `size_of` each
//! controller.
//!
//! ```text
//! cargo run --release --example worst_case [steps]
//! ```
//!
//! The timer (`Instant`, a vDSO clock read) adds about 20 ns to each sample.
//! On a shared machine the maximum includes preemptions by other processes:
//! for real-time figures pin the process to an isolated core.

use adaptimp::{
    rk4_step, Config, Controller, Environment, Law, Manipulator, Measurement, Sinusoid, TwoLinkArm,
    Vector, Wall,
};
use std::time::Instant;

fn percentile(sorted: &[u32], p: f64) -> u32 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn main() -> Result<(), adaptimp::Error> {
    let steps: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1_000_000);
    let arm = TwoLinkArm::paper();
    let wall = Wall::paper();
    println!(
        "{steps} steps per controller, closed loop with the paper's arm and wall (RK4, 1 substep)"
    );
    println!(
        "| controller | Ts | size_of (bytes) | median (ns) | 99.9th percentile (ns) | max (ns) |"
    );
    println!("|---|---|---:|---:|---:|---:|");
    let cases: [(&str, Config<2, 256>); 5] = [
        ("pd (paper)", Config::paper(Law::Pd)),
        ("sf (paper)", Config::paper(Law::StateFeedback)),
        ("of (paper)", Config::paper(Law::OutputFeedback)),
        ("sf (robot, hardened)", Config::robot(Law::StateFeedback)),
        ("of (robot, hardened)", Config::robot(Law::OutputFeedback)),
    ];
    for (name, cfg) in cases {
        let ts = cfg.ts;
        let mut ctrl = Box::new(Controller::new(cfg, Sinusoid::paper())?);
        let (mut x, mut dx) = (Vector::<2>::new(0.25, -0.05), Vector::<2>::zeros());
        let mut times = Vec::with_capacity(steps);
        for _ in 0..steps {
            let tau_e = wall.force(0.0, &x, &dx);
            let m = Measurement {
                x,
                dx: Some(dx),
                tau_e,
            };
            let start = Instant::now();
            let cmd = ctrl.step(&m)?;
            let elapsed = start.elapsed();
            times.push(u32::try_from(elapsed.as_nanos()).unwrap_or(u32::MAX));
            // RK4, one substep, torque held.
            let a = arm.forward_dynamics(&x, &dx, &cmd.tau_sat, &tau_e);
            (x, dx) = rk4_step(&arm, &wall, 0.0, ts, &cmd.tau_sat, (x, dx), &a);
        }
        times.sort_unstable();
        println!(
            "| {name} | {} ms | {} | {} | {} | {} |",
            ts * 1e3,
            std::mem::size_of::<Controller<2, 256>>(),
            percentile(&times, 0.5),
            percentile(&times, 0.999),
            times[times.len() - 1]
        );
    }
    Ok(())
}
