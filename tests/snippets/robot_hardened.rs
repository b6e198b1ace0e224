use adaptimp::{run, Config, Controller, Grid, Law, SimConfig, Sinusoid, TwoLinkArm, Wall};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let circle = Sinusoid::paper();
    // "auto" weight bounds are resolved from the trajectory the controller tracks.
    let ctrl = Controller::for_trajectory(Config::robot(Law::StateFeedback), Grid::paper(), &circle)?;
    let mut state = ctrl.new_state();
    let sim = SimConfig { t_final: 3.0, ..SimConfig::robot() };
    let m = run(&TwoLinkArm::paper(), &Wall::paper(), &mut ctrl.bind(&mut state), &circle, &sim, &mut ())?;
    println!("RMS ‖z1‖ over t ≥ 2 s: {:.5} rad", m.rms_z1_after2);
    // Or any configuration hardened: Config::paper(law).hardened(), or set the fields.
    Ok(())
}
