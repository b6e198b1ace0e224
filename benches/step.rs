//! Criterion benchmarks of the hot paths (n = 2, l = 256 unless stated).
//!
//! ```text
//! cargo bench --bench step
//! ```
//!
//! - `basis/*`: S(Z) on the paper grid, by the separable fast path and node by node.
//! - `network/fused_step`: the three networks' output, update and norms, one pass.
//! - `step/*`: one controller step of each law.
//! - `plant/rk4`: one RK4 step of the 2-link arm with the wall.
//! - `bound/sf_step`: the least work any state-feedback step must do: the basis,
//!   then one pass that reads each of the (2n² + n) l = 2560 weights once for the
//!   output and writes it once for the update.
//! - `paper/*`: one whole paper-scenario run (SPEC §11, 400 000 steps).
//! - `step/sf7`, `bound/sf7_step`: n = 7 at 1 kHz with L = 64 centres along
//!   the orbit (SPEC §15): the hardened state-feedback step, and its lower
//!   bound as above, (2·49 + 7)·64 = 6720 weights.
//! - `step/cart7`: the n = 7 Cartesian step (SPEC §16) beside it: the Panda's
//!   chain (kinematics at q_d and at q), the 6-D outer loop, and the same
//!   kind of hardened state-feedback joint step (L = 64), in free motion.

use adaptimp::network::Rates;
use adaptimp::{
    rk4_step, run, Basis, Centers, Config, Controller, Environment, Grid, HeapState, Law, Link,
    Manipulator, Measurement, PlanarArm, SimConfig, SimdPath, Sinusoid, Trajectory, TwoLinkArm,
    Vector, Wall,
};
use criterion::{criterion_group, criterion_main, Criterion};

#[path = "../tests/common/mod.rs"]
mod common;
use std::hint::black_box;

const L: usize = 256;

fn z_sample() -> [Vector<2>; 4] {
    [
        Vector::<2>::new(0.25, -0.05),
        Vector::<2>::new(0.3, -0.2),
        Vector::<2>::new(0.6, 1.1),
        Vector::<2>::new(-2.0, 3.5),
    ]
}

fn basis(c: &mut Criterion) {
    let grid = Grid::<2>::paper();
    let direct = grid.to_centers();
    let mut s = [0.0; L];
    let z = z_sample();
    let simd = Controller::paper(Law::StateFeedback).simd();
    c.bench_function("basis/grid_separable", |b| {
        b.iter(|| {
            // On the controller's instruction set, as its step evaluates it.
            simd.eval_basis(&grid, black_box(&z), &mut s);
            black_box(&s);
        })
    });
    c.bench_function("basis/direct_256_exp", |b| {
        b.iter(|| {
            direct.eval(black_box(&z), &mut s);
            black_box(&s);
        })
    });
}

/// A state of the paper's controller (basis and weights in the controller's
/// layout: the pass's speed depends on it), the basis set at a typical input,
/// and the controller's instruction set for the pass (`ADAPTIMP_SIMD=portable`
/// forces the portable one).
fn net() -> (HeapState<2>, SimdPath) {
    let ctrl = Controller::paper(Law::StateFeedback);
    let mut st = ctrl.new_state();
    let (s, _) = st.networks_mut();
    Grid::<2>::paper().eval(&z_sample(), s);
    (st, ctrl.simd())
}

/// Learning rates (paper, 50 µs) and α̇1, α1, z2 for one pass of the networks.
fn pass_inputs() -> (Rates, Vector<2>, Vector<2>, Vector<2>) {
    let rates = Rates::new(50e-6, [100.0; 3], [0.01; 3]).expect("rates");
    let da = Vector::<2>::new(-2.0, 3.5);
    let a = Vector::<2>::new(0.6, 1.1);
    let z2 = Vector::<2>::new(0.01, -0.02);
    (rates, da, a, z2)
}

/// One pass of the three networks (output, update and norms) alone.
fn network(c: &mut Criterion) {
    let (mut n, simd) = net();
    let (rates, da, a, z2) = pass_inputs();
    let mut norms = [0.0; 3];
    c.bench_function("network/fused_step", |b| {
        b.iter(|| {
            let (basis, mut weights) = n.networks_mut();
            let s = black_box(basis);
            black_box(weights.fused_step(simd, s, &da, &a, &z2, &rates, &mut norms))
        })
    });
}

fn steps(c: &mut Criterion) {
    for (name, law) in [
        ("step/pd", Law::Pd),
        ("step/sf", Law::StateFeedback),
        ("step/of", Law::OutputFeedback),
    ] {
        let ctrl = Controller::paper(law);
        let mut state = ctrl.new_state();
        let circle = Sinusoid::paper();
        let m = Measurement {
            x: Vector::<2>::new(0.25, -0.05),
            dx: Some(Vector::<2>::new(0.3, -0.2)),
            tau_e: Vector::<2>::new(5.0, 0.0),
        };
        c.bench_function(name, |b| {
            b.iter(|| {
                // The trajectory sampled at the state's clock, as in a loop.
                let sp = circle.sample(ctrl.time(&state));
                black_box(ctrl.step(&mut state, black_box(&m), &sp))
            });
            state.reset();
        });
    }
}

fn plant(c: &mut Criterion) {
    let arm = TwoLinkArm::paper();
    let wall = Wall::paper();
    let tau = Vector::<2>::new(10.0, -4.0);
    let h = 50e-6;
    c.bench_function("plant/rk4", |b| {
        let mut state = (Vector::<2>::new(0.25, -0.05), Vector::<2>::zeros());
        b.iter(|| {
            let (x, v) = state;
            let a = arm.forward_dynamics(&x, &v, &tau, &wall.force(0.0, &x, &v));
            state = rk4_step(&arm, &wall, 0.0, h, &tau, state, &a);
            black_box(&state);
        })
    });
}

/// The least work of one state-feedback step: the basis, then one pass that
/// reads each of the (2n² + n) l = 2560 weights once (for the output) and
/// writes it once (the update). The library's fused pass is that work and no
/// more (S shared by pairs of rows, O(rows) bookkeeping for the norms): a
/// hand-written standalone kernel measured no faster. So the bound is the basis
/// plus that pass, without the rest of the step (trajectory, reference,
/// errors, control law, saturation, auxiliary system), and step ÷ bound is
/// the cost of everything that is not the networks.
fn bound(c: &mut Criterion) {
    let grid = Grid::<2>::paper();
    let (mut n, simd) = net();
    let (rates, da, a, z2) = pass_inputs();
    let z = z_sample();
    let mut norms = [0.0; 3];
    c.bench_function("bound/sf_step", |b| {
        b.iter(|| {
            let (basis, mut weights) = n.networks_mut();
            simd.eval_basis(&grid, black_box(&z), basis);
            black_box(weights.fused_step(simd, basis, &da, &a, &z2, &rates, &mut norms))
        })
    });
}

fn paper(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper");
    g.sample_size(10);
    let arm = TwoLinkArm::paper();
    let wall = Wall::paper();
    let sim = SimConfig::paper();
    for (name, law) in [
        ("pd", Law::Pd),
        ("sf", Law::StateFeedback),
        ("of", Law::OutputFeedback),
    ] {
        let ctrl = Controller::paper(law);
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut state = ctrl.new_state();
                let m = run(
                    &arm,
                    &wall,
                    &mut ctrl.bind(&mut state),
                    &Sinusoid::paper(),
                    &sim,
                    &mut (),
                );
                black_box(m.expect("simulate"))
            })
        });
    }
    g.finish();
}

/// The n = 7 controller of `examples/11_worst_case_7.rs` (SPEC §15): a 7-link
/// planar arm's gains, 64 centres along the commanded orbit, Ts = 1 ms.
fn seven() -> (Controller<7, Centers<7, Vec<f64>>>, Sinusoid<7>) {
    let masses = [4.0, 3.5, 3.0, 2.5, 2.0, 1.5, 1.0];
    let arm = PlanarArm::new(
        masses.map(|m| Link {
            mass: m,
            length: 0.2,
            com: 0.1,
            inertia: m * 0.04 / 12.0,
        }),
        0.0,
    )
    .expect("arm");
    let traj = Sinusoid::<7>::new(
        Vector::from_column_slice(&[0.6, -0.3, -0.3, 0.2, -0.2, 0.3, -0.2]),
        Vector::from_element(0.15),
        Vector::from_column_slice(&[0.0, 0.1, -0.1, 0.1, 0.0, -0.1, 0.1]),
        Vector::from_element(1.0),
    )
    .expect("trajectory");
    let nodes = 64;
    let period = 2.0 * std::f64::consts::PI;
    let samples: Vec<_> = (0..nodes)
        .map(|j| traj.sample(period * j as f64 / nodes as f64))
        .collect();
    let basis = Centers::along(&samples, [0.3, 1.0]).expect("basis");
    let tau_max = Vector::<7>::from_column_slice(&[200.0, 150.0, 100.0, 60.0, 35.0, 15.0, 5.0]);
    let mut cfg = Config::<7>::new(Law::StateFeedback, tau_max).hardened();
    cfg.ts = 1e-3;
    let dinv = arm
        .inertia(&traj.sample(0.0).x)
        .try_inverse()
        .expect("D > 0")
        .diagonal();
    cfg.kp = dinv.map(|x| 0.25 / (cfg.ts * x));
    cfg.kzeta = cfg.kp.map(|k| (1.0 + k * k) / 2.0 + 10.0);
    cfg.k1 = Vector::from_element(20.0);
    cfg.gamma = [1.0; 3];
    let ctrl = Controller::for_trajectory(cfg, basis, &traj).expect("controller");
    (ctrl, traj)
}

fn seven_joints(c: &mut Criterion) {
    let (ctrl, traj) = seven();
    let mut state = ctrl.new_state();
    let sp0 = traj.sample(0.3);
    let m = Measurement {
        x: sp0.x + Vector::<7>::from_element(0.01),
        dx: Some(sp0.dx),
        tau_e: Vector::<7>::zeros(),
    };
    c.bench_function("step/sf7", |b| {
        b.iter(|| {
            let sp = traj.sample(ctrl.time(&state));
            black_box(ctrl.step(&mut state, black_box(&m), &sp))
        });
        state.reset();
    });
    // The bound: the basis, then one fused pass over the 105 × 64 weights.
    let simd = ctrl.simd();
    let rates = Rates::new(1e-3, [1.0; 3], [0.01; 3]).expect("rates");
    let z = [sp0.x, sp0.dx, sp0.dx, sp0.ddx];
    let (da, a) = (sp0.ddx, sp0.dx);
    let z2 = Vector::<7>::from_element(0.01);
    let mut norms = [0.0; 3];
    let mut st = ctrl.new_state();
    c.bench_function("bound/sf7_step", |b| {
        b.iter(|| {
            let (basis, mut weights) = st.networks_mut();
            simd.eval_basis(ctrl.basis(), black_box(&z), basis);
            black_box(weights.fused_step(simd, basis, &da, &a, &z2, &rates, &mut norms))
        })
    });
}

/// The n = 7 Cartesian step, free motion: a 4 cm circle commanded, the arm
/// 0.01 rad off the joint reference on every joint (as `step/sf7`), no contact.
fn cartesian_seven(c: &mut Criterion) {
    use adaptimp::{CartesianMeasurement, Kinematics};
    let pair = common::cart7(100.0, None, common::PANDA_EFFORT);
    let q0 = Vector::<7>::from_column_slice(&common::PANDA_HOME);
    let tip = pair.outer().kinematics().tip(&q0, &Vector::zeros());
    let (mut ost, mut ist) = (pair.outer().start(q0), pair.inner().new_state());
    c.bench_function("step/cart7", |b| {
        b.iter(|| {
            let target = common::circle(&tip, ost.k as f64 * 1e-3);
            let m = CartesianMeasurement {
                q: ost.qd + Vector::<7>::from_element(0.01),
                dq: Some(ost.dqd),
                wrench: Vector::<6>::zeros(),
            };
            black_box(pair.step(&mut ost, &mut ist, black_box(&m), Some(&target)))
        });
        ost = pair.outer().start(q0);
        ist.reset();
    });
}

criterion_group!(
    benches,
    basis,
    network,
    steps,
    plant,
    bound,
    paper,
    seven_joints,
    cartesian_seven
);
criterion_main!(benches);
