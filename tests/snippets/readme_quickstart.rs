// src/main.rs of a crate with, in its Cargo.toml, the checkout as a dependency:
//   [dependencies]
//   adaptimp = { path = "path/to/adaptimp" }
use adaptimp::{
    run, Controller, Law, Measurement, SimConfig, Sinusoid, Trajectory, TwoLinkArm, Vector, Wall,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // The paper's state-feedback controller, validated once against SPEC §10: an
    // immutable description (Send + Sync), shareable across threads.
    let ctrl = Controller::paper(Law::StateFeedback);
    // Its state (clock, reference, ζ, observer, weights), on the heap. One
    // description drives any number of states.
    let mut state = ctrl.new_state();
    // The commanded trajectory lives outside the controller: the paper's circle (64).
    let circle = Sinusoid::paper();

    // One step at t_k = k·Ts: measurement and setpoint in, command out, no allocation.
    let setpoint = circle.sample(ctrl.time(&state)); // xc, ẋc, ẍc (rad, rad/s, rad/s²)
    let measurement = Measurement {
        x: Vector::<2>::new(0.25, -0.05),   // joint positions (rad)
        dx: Some(Vector::<2>::zeros()),     // joint velocities (rad/s)
        tau_e: Vector::<2>::new(50.0, 0.0), // force on the environment (N m)
    };
    let cmd = ctrl.step(&mut state, &measurement, &setpoint)?;
    assert!(cmd.tau_sat[0] <= 17.0); // applied torque, saturated (N m)

    // Or close the loop with the paper's arm and wall for 2 s, from a fresh state.
    let mut state = ctrl.new_state();
    let sim = SimConfig { t_final: 2.0, ..SimConfig::paper() };
    let m = run(&TwoLinkArm::paper(), &Wall::paper(), &mut ctrl.bind(&mut state), &circle, &sim, &mut ())?;
    println!("RMS tracking error {:.4} rad, saturated {:.0}% of the time", m.rms_z1, 100.0 * m.sat_duty);
    Ok(())
}
