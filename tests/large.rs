//! Large controllers never touch the stack: a 7-joint controller with 1024
//! user centres, built and stepped on a thread with a 2 MiB stack (its
//! weights alone are 105 × 1024 reals, 860 KiB).

use adaptimp::{
    Centers, Config, Controller, Law, Measurement, Setpoint, Sinusoid, Trajectory, Vector,
};

const N: usize = 7;
const L: usize = 1024;

/// A deterministic pseudo-random number in [−1, 1).
fn lcg(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

#[test]
fn seven_joints_and_1024_nodes_run_on_a_2_mib_stack() {
    let worker = std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(|| {
            let mut seed = 1;
            let centers: Vec<f64> = (0..L * 4 * N).map(|_| lcg(&mut seed)).collect();
            let basis = Centers::<N, _>::uniform(centers, 4.0).expect("centres");
            let mut cfg = Config::<N>::new(Law::StateFeedback, Vector::<N>::from_element(80.0));
            cfg.ts = 1e-3;
            let ctrl = Controller::new(cfg, basis).expect("controller");
            let mut state = ctrl.new_state();
            let traj = Sinusoid::<N>::new(
                Vector::from_element(0.1),
                Vector::from_element(0.2),
                Vector::zeros(),
                Vector::from_element(1.0),
            )
            .expect("trajectory");
            let mut last = None;
            for k in 0..100 {
                let c: Setpoint<N> = traj.sample(k as f64 * 1e-3);
                let m = Measurement {
                    x: Vector::from_element(0.05),
                    dx: Some(Vector::zeros()),
                    tau_e: Vector::zeros(),
                };
                last = Some(ctrl.step(&mut state, &m, &c).expect("step"));
            }
            (state.steps(), state.nodes(), state.weights().norms(), last)
        })
        .expect("spawn");
    let (steps, nodes, norms, last) = worker.join().expect("no stack overflow");
    assert_eq!((steps, nodes), (100, L));
    // It learned: every network moved away from zero, and the command is finite.
    assert!(norms.iter().all(|n| *n > 0.0 && n.is_finite()), "{norms:?}");
    let cmd = last.expect("a command");
    assert!(cmd.tau_sat.iter().all(|t| t.is_finite() && t.abs() <= 80.0));
}
