//! Fuzzed configuration construction: any sequence of parameter settings by
//! name (arbitrary numbers, lengths, strings), then the controller built from
//! them. Construction returns Ok or an error, never panics or hangs; a
//! controller that was built steps with finite torques within its limits.
#![no_main]

use adaptimp::schema::{Preset, Scenario, Value, PARAMS};
use adaptimp::{Controller, Law, Measurement, Trajectory, Vector};
use arbitrary::Arbitrary;
use libfuzzer_sys::fuzz_target;

#[derive(Arbitrary, Debug)]
enum Val {
    Real(f64),
    Int(i64),
    Vec(Vec<f64>),
    Str(u8),
    None,
}

#[derive(Arbitrary, Debug)]
struct Input {
    robot: bool,
    law: u8,
    settings: Vec<(u8, Val)>,
    q: [f64; 2],
    dq: [f64; 2],
    tau_e: [f64; 2],
}

fuzz_target!(|input: Input| {
    let law = [Law::Pd, Law::StateFeedback, Law::OutputFeedback][usize::from(input.law % 3)];
    let preset = if input.robot {
        Preset::Robot
    } else {
        Preset::Paper
    };
    let mut s = Scenario::<2>::preset(preset, law);
    let words = [
        "auto",
        "euler",
        "normalized",
        "tanh",
        "latch",
        "damping",
        "zoh",
        "first",
        "x",
    ];
    for (i, v) in input.settings.iter().take(8) {
        let p = &PARAMS[usize::from(*i) % PARAMS.len()];
        let value = match v {
            Val::Real(x) => Value::Real(*x),
            Val::Int(i) => Value::Int(*i),
            Val::Vec(v) => Value::Vec(v),
            Val::Str(k) => Value::Str(words[usize::from(*k) % words.len()]),
            Val::None => Value::None,
        };
        let _ = s.set(p.name, value);
    }
    let (Ok(traj), Ok(grid)) = (s.trajectory(), s.grid()) else {
        return;
    };
    let Ok(ctrl) = Controller::for_trajectory(s.config, grid, &traj) else {
        return;
    };
    let mut state = ctrl.new_state();
    let m = Measurement {
        x: Vector::from(input.q),
        dx: Some(Vector::from(input.dq)),
        tau_e: Vector::from(input.tau_e),
    };
    for _ in 0..3 {
        let sp = traj.sample(ctrl.time(&state));
        if let Ok(cmd) = ctrl.step(&mut state, &m, &sp) {
            let limits = ctrl.saturation().limits();
            assert!(cmd
                .tau_sat
                .iter()
                .zip(limits.iter())
                .all(|(t, l)| t.is_finite() && t.abs() <= *l));
        }
    }
});
