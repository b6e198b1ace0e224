//! Reproduce the paper's three simulation cases (SPEC §11) and print the
//! SPEC §12 metrics as a table.
//!
//! ```text
//! cargo run --release --example paper
//! ```
//!
//! Mirrored in Python by `examples/01_paper.py`.

use adaptimp::{run, Controller, Law, Metrics, SimConfig, Sinusoid, TwoLinkArm, Wall};
use std::time::Instant;

fn main() -> Result<(), adaptimp::Error> {
    let arm = TwoLinkArm::paper();
    let wall = Wall::paper();
    let sim = SimConfig {
        // Under `cargo test`: 2.5 s instead of the paper's 20 s.
        t_final: if cfg!(test) { 2.5 } else { 20.0 },
        ..SimConfig::paper()
    };
    let cases = [
        ("pd", Law::Pd),
        ("sf", Law::StateFeedback),
        ("of", Law::OutputFeedback),
    ];
    println!(
        "paper scenario: T = {} s, Ts = 50 µs, M = {} RK4 substep(s), q(0) = [{}, {}]",
        sim.t_final, sim.substeps, sim.q0[0], sim.q0[1]
    );
    let mut results: Vec<(&str, Metrics<2>, f64)> = Vec::new();
    for (name, law) in cases {
        // The description, and its state (20 KiB of weights, on the heap).
        let ctrl = Controller::paper(law);
        let mut state = ctrl.new_state();
        let start = Instant::now();
        let m = run(
            &arm,
            &wall,
            &mut ctrl.bind(&mut state),
            &Sinusoid::paper(),
            &sim,
            &mut (),
        )?;
        results.push((name, m, start.elapsed().as_secs_f64()));
    }
    print_table(&results);
    Ok(())
}

/// A table row: its label and how to format it from the metrics.
type Column = (&'static str, fn(&Metrics<2>) -> String);

fn print_table(results: &[(&str, Metrics<2>, f64)]) {
    let rows: [Column; 11] = [
        ("RMS ‖z1‖ (rad)", |m| format!("{:.5}", m.rms_z1)),
        ("RMS ‖z1‖, t ≥ 2 s (rad)", |m| {
            format!("{:.5}", m.rms_z1_after2)
        }),
        ("RMS z1 per joint, t ≥ 2 s (rad)", |m| {
            format!(
                "{:.5}, {:.5}",
                m.rms_z1_joint_after2[0], m.rms_z1_joint_after2[1]
            )
        }),
        ("max |z1| per joint, t ≥ 2 s (rad)", |m| {
            format!(
                "{:.5}, {:.5}",
                m.max_abs_z1_joint_after2[0], m.max_abs_z1_joint_after2[1]
            )
        }),
        ("saturation duty", |m| format!("{:.4}", m.sat_duty)),
        ("steps in contact", |m| format!("{}", m.steps_in_contact)),
        ("peak τe, t ≥ 2 s (N m)", |m| {
            format!("{:.3}", m.peak_contact_after2)
        }),
        ("mean τe in contact (N m)", |m| {
            format!("{:.3}", m.mean_contact)
        }),
        ("peak commanded |τ| (N m)", |m| {
            format!("{:.1}, {:.1}", m.peak_abs_tau[0], m.peak_abs_tau[1])
        }),
        ("impedance error RMS, t ≥ 2 s (N m)", |m| {
            format!("{:.3}", m.imp_err_rms_after2)
        }),
        ("rows", |m| format!("{}", m.rows)),
    ];
    print!("| {:<36} |", "metric");
    for (name, _, _) in results {
        print!(" {:>20} |", name);
    }
    println!();
    print!("|{:-<38}|", "");
    for _ in results {
        print!("{:->22}|", "");
    }
    println!();
    for (label, f) in rows {
        print!("| {label:<36} |");
        for (_, m, _) in results {
            print!(" {:>20} |", f(m));
        }
        println!();
    }
    print!("| {:<36} |", "wall time (s)");
    for (_, _, secs) in results {
        print!(" {:>20.2} |", secs);
    }
    println!();
}

/// `cargo test` runs this example, shortened (`cfg!(test)`).
#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main().unwrap();
    }
}
