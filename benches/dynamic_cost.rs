//! Instruction counts of a step of the run-time API (`adaptimp::dynamic`)
//! against the const-generic step it wraps, n = 7, for
//! `valgrind --tool=callgrind` (counted, not timed, on a shared machine):
//!
//! ```text
//! cargo bench --bench dynamic_cost --no-run
//! valgrind --tool=callgrind --toggle-collect='*measured*' \
//!     target/release/deps/dynamic_cost-<hash> joint     # or dyn-joint, cart, dyn-cart
//! ```
//!
//! Both sides are built from the same parameters (the robot preset, the
//! Panda's effort limits, state feedback, the rule's default basis for n =
//! 7; the Cartesian pair on the Panda's chain with SPEC §16's defaults), take
//! 200 steps to settle, then `STEPS` measured steps inside `measured`; Ir /
//! STEPS is the count per step. The run prints a digest of the torques so
//! the two sides are seen to compute the same.
//!
//! `cargo bench --bench dynamic_cost -- time [STEPS]` (without valgrind)
//! times every step of each of the four with the wall clock and prints the
//! median and the worst (µs): reported, not a target.

#[path = "../tests/common/mod.rs"]
mod common;

use adaptimp::control::tuning::Rule;
use adaptimp::dynamic as dy;
use adaptimp::schema::{Preset, Scenario, Value};
use adaptimp::{
    AnyBasis, CartesianController, CartesianImpedance, CartesianMeasurement, Controller, Joint,
    Kinematics, Law, Measurement, PoseTarget, Sinusoid, Trajectory, Transform, Vector,
};
use std::hint::black_box;

const STEPS: usize = 1000;
const N: usize = 7;

/// The Panda's joints (tests/common's chain, as joint data).
fn joints() -> Vec<Joint> {
    let h = std::f64::consts::FRAC_PI_2;
    let rev = |xyz: [f64; 3], roll: f64| {
        Joint::revolute(
            Transform::from_xyz_rpy(xyz, [roll, 0.0, 0.0]),
            [0.0, 0.0, 1.0],
        )
    };
    vec![
        rev([0.0, 0.0, 0.333], 0.0),
        rev([0.0, 0.0, 0.0], -h),
        rev([0.0, -0.316, 0.0], h),
        rev([0.0825, 0.0, 0.0], h),
        rev([-0.0825, 0.384, 0.0], -h),
        rev([0.0, 0.0, 0.0], h),
        rev([0.088, 0.0, 0.0], h),
    ]
}

const TIP: [f64; 3] = [0.0, 0.0, 0.2104];

/// The same parameters for both sides.
fn scenarios(external: bool) -> (dy::Scenario, Scenario<N>) {
    let law = Law::StateFeedback;
    let mut d = dy::Scenario::new(N, Preset::Robot, law).expect("n");
    let mut s = Scenario::<N>::preset(Preset::Robot, law);
    let items: [(&str, Value<'_>); 2] = [
        ("tau_max", Value::Vec(&common::PANDA_EFFORT)),
        ("xc_offset", Value::Vec(&common::PANDA_HOME)),
    ];
    for (name, v) in items {
        d.set(name, v).expect(name);
        s.set(name, v).expect(name);
    }
    if external {
        d.set("impedance", Value::Str("external"))
            .expect("impedance");
        s.set("impedance", Value::Str("external"))
            .expect("impedance");
    }
    (d, s)
}

fn typed(s: &Scenario<N>) -> (Controller<N, AnyBasis<N>>, Sinusoid<N>) {
    let traj = s.trajectory().expect("trajectory");
    let basis = AnyBasis::Centers(Rule::default().default_basis(&traj).expect("basis"));
    let ctrl = Controller::for_trajectory(s.config, basis, &traj).expect("controller");
    (ctrl, traj)
}

/// The measurement of step k: 0.01 rad off the trajectory.
fn sample(traj: &Sinusoid<N>, k: usize) -> Measurement<N> {
    let c = traj.sample(k as f64 * 1e-3);
    Measurement {
        x: c.x + Vector::<N>::from_element(0.01),
        dx: Some(c.dx),
        tau_e: Vector::zeros(),
    }
}

/// A 4 cm circle about `p0`, the rotation `r0` held.
fn circle(p0: Vector<3>, r0: nalgebra::Matrix3<f64>, k: usize) -> PoseTarget {
    let t = k as f64 * 1e-3;
    let w = std::f64::consts::PI;
    let (s, c) = ((w * t).sin(), (w * t).cos());
    PoseTarget {
        p: p0 + Vector::<3>::new(0.04 * (c - 1.0), 0.04 * s, 0.0),
        dp: Vector::<3>::new(-0.04 * w * s, 0.04 * w * c, 0.0),
        ..PoseTarget::at(p0, r0)
    }
}

/// One of the four: `f(k)` for the settling steps, then for the measured
/// ones inside `measured`, the wall-clock time of each kept when `times`.
fn run(mut f: impl FnMut(usize) -> f64, times: Option<&mut Vec<u128>>) -> f64 {
    #[inline(never)]
    fn measured(f: &mut impl FnMut(usize) -> f64, k: usize) -> f64 {
        f(black_box(k))
    }
    let mut digest = 0.0;
    for k in 0..200 {
        digest += f(k);
    }
    match times {
        None => {
            for k in 200..200 + STEPS {
                digest += measured(&mut f, k);
            }
        }
        Some(t) => {
            for k in 200..200 + t.capacity() {
                let start = std::time::Instant::now();
                digest += measured(&mut f, k);
                t.push(start.elapsed().as_nanos());
            }
        }
    }
    digest
}

fn one(which: &str, times: Option<&mut Vec<u128>>) -> f64 {
    let q0 = common::PANDA_HOME;
    match which {
        "joint" => {
            let (_, s) = scenarios(false);
            let (ctrl, traj) = typed(&s);
            let mut st = ctrl.new_state();
            run(
                |k| {
                    let m = sample(&traj, k);
                    let c = traj.sample(ctrl.time(&st));
                    ctrl.step(&mut st, black_box(&m), &c).expect("step").tau_sat[0]
                },
                times,
            )
        }
        "dyn-joint" => {
            let (d, s) = scenarios(false);
            let ctrl = d.controller().expect("controller");
            let (_, traj) = typed(&s);
            let mut st = ctrl.new_state();
            run(
                |k| {
                    let m = sample(&traj, k);
                    let dm = dy::Measurement {
                        x: m.x.as_slice(),
                        dx: m.dx.as_ref().map(|v| v.as_slice()),
                        tau_e: m.tau_e.as_slice(),
                    };
                    ctrl.step(&mut st, black_box(&dm), None)
                        .expect("step")
                        .tau_sat[0]
                },
                times,
            )
        }
        "cart" => {
            let (_, s) = scenarios(true);
            let (ctrl, _) = typed(&s);
            let tip = Transform::from_xyz_rpy(TIP, [0.0; 3]);
            let chain = adaptimp::Chain::<N>::new(&joints(), &tip).expect("chain");
            let outer = CartesianImpedance::new(s.cartesian, chain, 1e-3).expect("outer");
            let pair = CartesianController::new(outer, ctrl).expect("pair");
            let q = Vector::<N>::from(q0);
            let t0 = chain.tip(&q, &Vector::zeros());
            let (mut ost, mut ist) = (pair.start(&q).expect("start"), pair.inner().new_state());
            run(
                |k| {
                    let c = circle(t0.position, *t0.rotation.matrix(), k);
                    let m = CartesianMeasurement {
                        q: ost.qd + Vector::<N>::from_element(0.01),
                        dq: Some(ost.dqd),
                        wrench: Vector::zeros(),
                    };
                    pair.step(&mut ost, &mut ist, black_box(&m), Some(&c))
                        .expect("step")
                        .joint
                        .tau_sat[0]
                },
                times,
            )
        }
        "dyn-cart" => {
            let (d, _) = scenarios(true);
            let tip = Transform::from_xyz_rpy(TIP, [0.0; 3]);
            let chain = dy::Chain::new(&joints(), &tip).expect("chain");
            let outer = dy::CartesianImpedance::new(d.cartesian(), &chain, 1e-3).expect("outer");
            let pair =
                dy::CartesianController::new(outer, d.controller().expect("joint")).expect("pair");
            let t0 = chain.tip(&q0, &[0.0; N]).expect("tip");
            let (mut ost, mut ist) = (pair.start(&q0).expect("start"), pair.joint().new_state());
            run(
                |k| {
                    let c = circle(t0.position, *t0.rotation.matrix(), k);
                    let (qd, dqd) = ost.joint_d();
                    let q: [f64; N] = std::array::from_fn(|i| qd[i] + 0.01);
                    let m = dy::CartesianMeasurement {
                        q: &q,
                        dq: Some(&dqd),
                        wrench: Vector::zeros(),
                    };
                    pair.step(&mut ost, &mut ist, black_box(&m), Some(&c))
                        .expect("step")
                        .joint
                        .tau_sat[0]
                },
                times,
            )
        }
        other => panic!("joint, dyn-joint, cart, dyn-cart or time, not {other:?}"),
    }
}

fn main() {
    let which = std::env::args().nth(1).unwrap_or_else(|| "joint".into());
    if which == "time" {
        let steps = std::env::args()
            .nth(2)
            .and_then(|s| s.parse().ok())
            .unwrap_or(20_000);
        for w in ["joint", "dyn-joint", "cart", "dyn-cart"] {
            let mut t = Vec::with_capacity(steps);
            let digest = one(w, Some(&mut t));
            t.sort_unstable();
            println!(
                "{w}: {steps} steps, median {:.2} µs, worst {:.2} µs (digest {digest:e})",
                t[t.len() / 2] as f64 / 1e3,
                t[t.len() - 1] as f64 / 1e3
            );
        }
        return;
    }
    println!("{which}: digest {:e}", one(&which, None));
}
