//! Your own RBF centres instead of the paper's vertex grid.
//!
//! The vertex grid has 2^(4n) nodes (256 for the paper's arm) and exists for
//! n ≤ 3. Any n takes user centres: L points in the networks' input space
//! Z = [x, v, α1, α̇1] with a width per input dimension. Here L = 32 centres
//! are placed along the commanded circle (x = xc(t_i), v = α1 = ẋc(t_i),
//! α̇1 = ẍc(t_i)), as in deterministic learning (Wang & Hill, IEEE TNN 17(1),
//! 2006), and state feedback in the robot scenario is compared with the grid.
//!
//! ```text
//! cargo run --release --example custom_basis
//! ```
//!
//! Mirrored in Python by `examples/04_custom_basis.py`.

use adaptimp::{
    run, Basis, Centers, Config, Controller, Grid, Law, Metrics, SimConfig, Sinusoid, Trajectory,
    TwoLinkArm, Vector, Wall,
};
use std::f64::consts::PI;

/// `nodes` centres along `traj`'s period, rows of (x, v, α1 = v, α̇1 = ẍ).
fn orbit_centres(traj: &Sinusoid<2>, omega: f64, nodes: usize) -> Vec<f64> {
    let mut out = Vec::with_capacity(nodes * 8);
    for i in 0..nodes {
        let s = traj.sample(i as f64 * 2.0 * PI / (nodes as f64 * omega));
        for block in [s.x, s.dx, s.dx, s.ddx] {
            out.extend_from_slice(block.as_slice());
        }
    }
    out
}

fn sim<B: Basis<2>>(basis: B, t_final: f64) -> Result<Metrics<2>, adaptimp::Error> {
    let traj = Sinusoid::paper();
    let ctrl = Controller::for_trajectory(Config::robot(Law::StateFeedback), basis, &traj)?;
    let mut state = ctrl.new_state();
    let cfg = SimConfig {
        t_final,
        ..SimConfig::robot()
    };
    run(
        &TwoLinkArm::paper(),
        &Wall::paper(),
        &mut ctrl.bind(&mut state),
        &traj,
        &cfg,
        &mut (),
    )
}

fn main() -> Result<(), adaptimp::Error> {
    let t_final = if cfg!(test) { 4.0 } else { 20.0 };
    let centres = orbit_centres(&Sinusoid::paper(), PI, 32);
    let widths2 = [Vector::from_element(1.0); 4];
    let grid = sim(Grid::paper(), t_final)?;
    let user = sim(Centers::new(centres, widths2)?, t_final)?;
    println!("state feedback, robot scenario, T = {t_final} s");
    for (name, m, nodes) in [
        ("vertex grid", grid, 256),
        ("32 centres on the orbit", user, 32),
    ] {
        println!(
            "  {name:<24} L = {nodes:>3}: RMS ‖z1‖ (t ≥ 2 s) = {:.5} rad, saturation duty {:.4}",
            m.rms_z1_after2, m.sat_duty
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
