//! The paper's controllers at a robot's 1 kHz: the laws as printed against
//! the hardened options of SPEC §13 (the robot scenario), for state and output
//! feedback, with the SPEC §12 metrics.
//!
//! ```text
//! cargo run --release --example robot_1khz
//! ```
//!
//! Mirrored in Python by `examples/02_robot_1khz.py` (which also draws the figure).

use adaptimp::{run, Config, Controller, Grid, Law, SimConfig, Sinusoid, TwoLinkArm, Wall};

fn main() -> Result<(), adaptimp::Error> {
    let sim = SimConfig {
        t_final: if cfg!(test) { 3.0 } else { 20.0 },
        ..SimConfig::robot()
    };
    println!("| case | laws | RMS ‖z1‖, t ≥ 2 s (rad) | saturation duty | peak |τ| (N m) |");
    println!("|---|---|---:|---:|---:|");
    for (case, law) in [("sf", Law::StateFeedback), ("of", Law::OutputFeedback)] {
        let mut printed = Config::paper(law);
        printed.ts = 1e-3;
        for (name, cfg) in [("printed", printed), ("hardened", Config::robot(law))] {
            let traj = Sinusoid::paper();
            let ctrl = Controller::for_trajectory(cfg, Grid::paper(), &traj)?;
            let mut state = ctrl.new_state();
            let m = run(
                &TwoLinkArm::paper(),
                &Wall::paper(),
                &mut ctrl.bind(&mut state),
                &traj,
                &sim,
                &mut (),
            )?;
            println!(
                "| {case} | {name} | {:.5} | {:.4} | {:.1} |",
                m.rms_z1_after2,
                m.sat_duty,
                m.peak_abs_tau.max()
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
