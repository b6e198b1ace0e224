//! Fault injection in the robot scenario (Ts = 1 ms, the hardened options):
//! for PD, state feedback and output feedback, each fault of
//! `adaptimp::inject` injected at t = 5 s. Prints a Markdown table: peak
//! applied and commanded torque, the time to recover the pre-fault RMS
//! tracking error after the fault ends, whether any NaN appeared, and the
//! weight norms before the fault and at the end.
//!
//! ```text
//! cargo run --release --example faults
//! ```

use adaptimp::simulator::run_with_injection;
use adaptimp::{
    Controller, Injected, Injection, Law, SimConfig, Sinusoid, TwoLinkArm, Vector, Wall,
};

/// The faults of the table: a name and the injection (starting at 5 s).
fn faults(tau_max: Vector<2>) -> [(&'static str, Injection<2>); 5] {
    let at = |fault, duration| Injection {
        fault,
        start: 5.0,
        duration,
    };
    [
        ("stale sample, 50 ms", at(Injected::Stale, 0.05)),
        ("NaN burst on q, 50 ms", at(Injected::NanBurst, 0.05)),
        (
            "force-sensor bias +5 N m on joint 1, 1 s",
            at(
                Injected::ForceBias {
                    bias: Vector::<2>::new(5.0, 0.0),
                },
                1.0,
            ),
        ),
        (
            "actuators at 30% of their limits, 0.5 s",
            at(
                Injected::ActuatorDrop {
                    tau_max,
                    fraction: 0.3,
                },
                0.5,
            ),
        ),
        ("20 control periods skipped", at(Injected::Skipped, 0.02)),
    ]
}

fn main() -> Result<(), adaptimp::Error> {
    let sim = SimConfig {
        t_final: if cfg!(test) { 3.0 } else { 10.0 },
        ..SimConfig::robot()
    };
    println!("| controller | fault | peak applied \\|τ\\|/τmax | peak commanded \\|τ\\| (N m) | refused rows | recovery (s) | NaN | ‖Ŵ‖ D, C, G before → end |");
    println!("|---|---|---:|---:|---:|---:|---|---|");
    for (name, law) in [
        ("PD", Law::Pd),
        ("state feedback", Law::StateFeedback),
        ("output feedback", Law::OutputFeedback),
    ] {
        let ctrl = Controller::robot(law);
        let tau_max = *ctrl.saturation().limits();
        for (fault, injection) in faults(tau_max) {
            let mut state = ctrl.new_state();
            let f = run_with_injection(
                &TwoLinkArm::paper(),
                &Wall::paper(),
                &mut ctrl.bind(&mut state),
                &Sinusoid::paper(),
                &sim,
                &injection,
                &tau_max,
            )?;
            let recovery = f.recovery.map_or("never".to_owned(), |r| format!("{r:.3}"));
            let (b, e) = f.norms;
            println!(
                "| {name} | {fault} | {:.3} | {:.1} | {} | {recovery} | {} | {:.2}, {:.2}, {:.2} → {:.2}, {:.2}, {:.2} |",
                f.peak_applied_ratio,
                f.peak_commanded,
                f.refused,
                if f.non_finite { "yes" } else { "no" },
                b[0], b[1], b[2], e[0], e[1], e[2]
            );
        }
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
