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

fn main() {
    let branch = std::env::args().nth(1).unwrap_or_else(|| "free".into());
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
