//! Fuzzed step sequences: the paper's and the robot scenario's controllers fed
//! arbitrary measurements and setpoints (NaN, infinities, spikes). Every step
//! returns a finite torque within the limits, or an error that leaves what
//! the control law uses exactly as it was (and records a fallback within the
//! limits); the weights never become non-finite; every state a step leaves
//! is one `Controller::restore` accepts.
#![no_main]

use adaptimp::{Controller, Error, Law, Measurement, Setpoint, Sinusoid, Trajectory, Vector};
use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

/// The six controllers (paper and robot, each law), built once: building
/// one resolves "auto" weight bounds from 4096 samples of the circle.
fn controllers() -> &'static [Controller<2>; 6] {
    static CTRL: OnceLock<[Controller<2>; 6]> = OnceLock::new();
    CTRL.get_or_init(|| {
        let laws = [Law::Pd, Law::StateFeedback, Law::OutputFeedback];
        core::array::from_fn(|i| {
            if i < 3 {
                Controller::paper(laws[i])
            } else {
                Controller::robot(laws[i - 3])
            }
        })
    })
}

#[derive(Arbitrary, Debug)]
struct Step {
    q: [f64; 2],
    dq: Option<[f64; 2]>,
    tau_e: [f64; 2],
    setpoint: Option<[f64; 6]>,
    repeat: u8,
}

#[derive(Arbitrary, Debug)]
struct Input {
    robot: bool,
    law: u8,
    steps: Vec<Step>,
}

fuzz_target!(|input: Input| {
    let ctrl = &controllers()[usize::from(input.law % 3) + if input.robot { 3 } else { 0 }];
    let limits = *ctrl.saturation().limits();
    let mut state = ctrl.new_state();
    let mut before = vec![0.0; state.snapshot_len()];
    let mut after = vec![0.0; state.snapshot_len()];
    for s in input.steps.iter().take(16) {
        let m = Measurement {
            x: Vector::from(s.q),
            dx: s.dq.map(Vector::from),
            tau_e: Vector::from(s.tau_e),
        };
        let sp = match s.setpoint {
            Some(v) => Setpoint {
                x: Vector::<2>::new(v[0], v[1]),
                dx: Vector::<2>::new(v[2], v[3]),
                ddx: Vector::<2>::new(v[4], v[5]),
            },
            None => Sinusoid::paper().sample(ctrl.time(&state)),
        };
        for _ in 0..=(s.repeat % 4) {
            state.save(&mut before).expect("save");
            match ctrl.step(&mut state, &m, &sp) {
                Ok(cmd) => {
                    for i in 0..2 {
                        assert!(cmd.tau_sat[i].is_finite() && cmd.tau_sat[i].abs() <= limits[i]);
                    }
                }
                Err(e) => {
                    assert!(!matches!(e, Error::Diverged { .. }), "{e}");
                    state.save(&mut after).expect("save");
                    // What the control law uses is unchanged: all but the
                    // refusal record (the applied torque, the last measured
                    // position) and the checksum, the last 2N + 1 values.
                    let control = before.len() - 2 * 2 - 1;
                    assert!(
                        before[..control]
                            .iter()
                            .zip(&after[..control])
                            .all(|(a, b)| a.to_bits() == b.to_bits()),
                        "{e}"
                    );
                    let applied = state.applied();
                    for i in 0..2 {
                        assert!(applied[i].is_finite() && applied[i].abs() <= limits[i]);
                    }
                }
            }
            assert!(state.weights().norms().iter().all(|n| n.is_finite()));
            // Every state a step leaves, the controller restores.
            state.save(&mut after).expect("save");
            let mut copy = ctrl.new_state();
            ctrl.restore(&mut copy, &after)
                .expect("a stepped state restores");
        }
    }
});
