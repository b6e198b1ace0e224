//! Instruction counts of the n = 7 Cartesian step (SPEC §16) by branch, for
//! `valgrind --tool=callgrind` (a real-time bound on a shared machine is
//! counted, not timed):
//!
//! ```text
//! cargo bench --bench cartesian_cost --no-run
//! valgrind --tool=callgrind --toggle-collect='*measured*' \
//!     target/release/deps/cartesian_cost-<hash> free      # or costly, joint
//! ```
//!
//! Each run takes 200 steps to settle, then `STEPS` measured steps inside
//! `measured`; Ir / STEPS is the count per step. Branches:
//!
//! - `free`: free motion: the arm 0.01 rad off the joint reference, no
//!   contact; no saturation, no projection, no clipping.
//! - `costly`: saturated, projecting, clipping, in contact: the arm 0.02 rad
//!   off on every joint, the limits of joints 1–4 lowered to 1 N m (their
//!   torques beyond them; the other rows keep learning), a wrench of 20 N and
//!   2 N m, the error clipped to 1 mm and 1 mrad, and weight bounds of 1e-3
//!   (the projection acts at every step).
//! - `joint`: the n = 7 joint step alone (the joint controller of the pair with
//!   the reference of the free run), for the ratio to the joint step.
//!
//! The run prints what the branch did (saturated joints, weight norms against
//! the bound, the error's norm) so that the branch is checked, not assumed.
//!
//! `cargo bench --bench cartesian_cost -- time [STEPS]` (without valgrind)
//! times every step of the free branch and of the joint step alone with the
//! wall clock and prints their percentiles: reported, not a target, on a
//! shared machine (SPEC §15).

#[path = "../tests/common/mod.rs"]
mod common;

use adaptimp::{
    CartesianCommand, CartesianController, CartesianMeasurement, CartesianState, Centers, Chain,
    HeapState, Kinematics, Measurement, PoseTarget, Vector,
};
use std::hint::black_box;

const STEPS: u64 = 1000;

type Pair = CartesianController<7, Chain<7>, Centers<7, Vec<f64>>>;

#[inline(never)]
fn measured(
    pair: &Pair,
    ost: &mut CartesianState<7>,
    ist: &mut HeapState<7>,
    m: &CartesianMeasurement<7>,
    c: &PoseTarget,
) -> CartesianCommand<7> {
    pair.step(ost, ist, black_box(m), Some(black_box(c)))
        .expect("step")
}

#[inline(never)]
fn measured_joint(
    pair: &Pair,
    ist: &mut HeapState<7>,
    m: &Measurement<7>,
    r: &adaptimp::Setpoint<7>,
) -> adaptimp::Command<7> {
    pair.inner()
        .step(ist, black_box(m), black_box(r))
        .expect("joint step")
}

/// The percentiles 50, 99, 99.9 of `t` (ns), sorted in place.
fn percentiles(t: &mut [u128]) -> [u128; 3] {
    t.sort_unstable();
    let at = |p: f64| t[((t.len() as f64 - 1.0) * p).round() as usize];
    [at(0.5), at(0.99), at(0.999)]
}

/// Wall-clock percentiles of the free Cartesian step and of the joint step alone.
fn time(steps: usize) {
    use std::time::Instant;
    let pair = common::cart7(100.0, None, common::PANDA_EFFORT);
    let q0 = Vector::<7>::from_column_slice(&common::PANDA_HOME);
    let tip = pair.outer().kinematics().tip(&q0, &Vector::zeros());
    for joint in [false, true] {
        let (mut ost, mut ist) = (pair.outer().start(q0), pair.inner().new_state());
        let mut t = Vec::with_capacity(steps);
        for k in 0..steps {
            let c = common::circle(&tip, k as f64 * 1e-3);
            let m = CartesianMeasurement {
                q: ost.qd + Vector::<7>::from_element(0.01),
                dq: Some(ost.dqd),
                wrench: Vector::zeros(),
            };
            if joint {
                let s = pair
                    .outer()
                    .stage(&ost, Some(&c), &m.wrench)
                    .expect("stage");
                let jm = Measurement {
                    x: m.q,
                    dx: m.dq,
                    tau_e: Vector::zeros(),
                };
                let start = Instant::now();
                black_box(measured_joint(&pair, &mut ist, &jm, &s.reference));
                t.push(start.elapsed().as_nanos());
                ost = s.next;
            } else {
                let start = Instant::now();
                black_box(measured(&pair, &mut ost, &mut ist, &m, &c));
                t.push(start.elapsed().as_nanos());
            }
        }
        // Steps beyond 100 µs: a preemption of the process (a scheduler
        // quantum is milliseconds), not the step's work.
        let slow = t.iter().filter(|x| **x > 100_000).count();
        let [p50, p99, p999] = percentiles(&mut t);
        let what = if joint {
            "joint step"
        } else {
            "Cartesian step"
        };
        println!(
            "{what}: {steps} steps, median {:.2} µs, 99th percentile {:.2} µs, 99.9th {:.2} µs; {slow} steps beyond 100 µs",
            p50 as f64 / 1e3,
            p99 as f64 / 1e3,
            p999 as f64 / 1e3
        );
    }
}

fn main() {
    let branch = std::env::args().nth(1).unwrap_or_else(|| "free".into());
    if branch == "time" {
        let steps = std::env::args()
            .nth(2)
            .and_then(|s| s.parse().ok())
            .unwrap_or(100_000);
        time(steps);
        return;
    }
    let costly = branch == "costly";
    let pair = if costly {
        common::cart7(1e-3, Some(1e-3), [1.0, 1.0, 1.0, 1.0, 12.0, 12.0, 12.0])
    } else {
        common::cart7(100.0, None, common::PANDA_EFFORT)
    };
    let q0 = Vector::<7>::from_column_slice(&common::PANDA_HOME);
    let tip = pair.outer().kinematics().tip(&q0, &Vector::zeros());
    let (mut ost, mut ist) = (pair.outer().start(q0), pair.inner().new_state());
    let wrench = if costly {
        Vector::<6>::new(0.0, 0.0, -20.0, 2.0, 0.0, 0.0)
    } else {
        Vector::<6>::zeros()
    };
    let offset = Vector::<7>::from_element(if costly { 0.02 } else { 0.01 });
    let measurement = |st: &CartesianState<7>| CartesianMeasurement {
        q: st.qd + offset,
        dq: Some(st.dqd),
        wrench,
    };
    let mut last = None;
    let (mut saturated, mut clipped) = (0u64, 0u64);
    for k in 0..200 + STEPS {
        let c = common::circle(&tip, k as f64 * 1e-3);
        let m = measurement(&ost);
        let cmd = if k < 200 {
            pair.step(&mut ost, &mut ist, &m, Some(&c)).expect("step")
        } else if branch == "joint" {
            // The joint step with the free run's reference, without the outer loop.
            let s = pair
                .outer()
                .stage(&ost, Some(&c), &m.wrench)
                .expect("stage");
            let jm = Measurement {
                x: m.q,
                dx: m.dq,
                tau_e: Vector::zeros(),
            };
            let joint = measured_joint(&pair, &mut ist, &jm, &s.reference);
            ost = s.next;
            if joint.dtau.iter().any(|d| *d != 0.0) {
                saturated += 1;
            }
            continue;
        } else {
            measured(&pair, &mut ost, &mut ist, &m, &c)
        };
        if k >= 200 {
            if cmd.joint.dtau.iter().any(|d| *d != 0.0) {
                saturated += 1;
            }
            if (cmd.error.fixed_rows::<3>(0).norm() - 1e-3).abs() < 1e-12 {
                clipped += 1;
            }
        }
        last = Some(cmd);
    }
    let norms = ist.weights().norms();
    if let Some(c) = &last {
        println!(
            "dtau {:?} tau {:?}",
            c.joint.dtau.as_slice(),
            c.joint.tau.as_slice()
        );
    }
    println!(
        "{branch}: {STEPS} steps measured; saturated in {saturated}, error clipped in {clipped}; weight norms {norms:?} (bound {}); last error {:?}",
        if costly { 1e-3 } else { 100.0 },
        last.map(|c| c.error.norm())
    );
}
