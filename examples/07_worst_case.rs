//! Worst-case step time: a 1 kHz loop cares about the slowest step, not the
//! mean. Runs each controller for 10⁶ steps in closed loop with the paper's arm
//! and wall (so the inputs are realistic), times every `step` call, and prints
//! the median, the 99.9th percentile and the maximum, with the size of each
//! controller's description and state (the state's buffer on the heap).
//!
//! ```text
//! cargo run --release --example worst_case [steps]
//! ```
//!
//! The timer (`Instant`, a vDSO clock read) adds about 20 ns to each sample.
//! On a shared machine the maximum includes preemptions by other processes:
//! for real-time figures pin the process to an isolated core.

use adaptimp::{
    rk4_step, Controller, Environment, Law, Manipulator, Measurement, Sinusoid, Trajectory,
    TwoLinkArm, Vector, Wall,
};
use std::time::Instant;

fn percentile(sorted: &[u32], p: f64) -> u32 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn main() -> Result<(), adaptimp::Error> {
    // Under `cargo test` the arguments are the test harness's: not ours.
    let steps: usize = (!cfg!(test))
        .then(|| std::env::args().nth(1))
        .flatten()
        .and_then(|s| s.parse().ok())
        .unwrap_or(if cfg!(test) { 2_000 } else { 1_000_000 });
    let arm = TwoLinkArm::paper();
    let wall = Wall::paper();
    println!(
        "{steps} steps per controller, closed loop with the paper's arm and wall (RK4, 1 substep)"
    );
    println!(
        "weight pass: {} (chosen at run time; ADAPTIMP_SIMD=portable forces the portable one)",
        Controller::paper(Law::Pd).simd()
    );
    println!(
        "| controller | Ts | description + state (bytes) | median (ns) | 99.9th percentile (ns) | max (ns) |"
    );
    println!("|---|---|---:|---:|---:|---:|");
    let cases: [(&str, Controller<2>); 5] = [
        ("pd (paper)", Controller::paper(Law::Pd)),
        ("sf (paper)", Controller::paper(Law::StateFeedback)),
        ("of (paper)", Controller::paper(Law::OutputFeedback)),
        (
            "sf (robot, hardened)",
            Controller::robot(Law::StateFeedback),
        ),
        (
            "of (robot, hardened)",
            Controller::robot(Law::OutputFeedback),
        ),
    ];
    let circle = Sinusoid::paper();
    for (name, ctrl) in cases {
        let ts = ctrl.period();
        let mut state = ctrl.new_state();
        let bytes =
            std::mem::size_of_val(&ctrl) + std::mem::size_of_val(&state) + 8 * ctrl.buffer_len();
        let (mut x, mut dx) = (Vector::<2>::new(0.25, -0.05), Vector::<2>::zeros());
        let mut times = Vec::with_capacity(steps);
        for _ in 0..steps {
            let tau_e = wall.force(0.0, &x, &dx);
            let m = Measurement {
                x,
                dx: Some(dx),
                tau_e,
            };
            let sp = circle.sample(ctrl.time(&state));
            let start = Instant::now();
            let cmd = ctrl.step(&mut state, &m, &sp)?;
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
            bytes,
            percentile(&times, 0.5),
            percentile(&times, 0.999),
            times[times.len() - 1]
        );
    }
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
