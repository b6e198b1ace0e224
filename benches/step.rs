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
//!   output and writes it once for the update, from one contiguous array.
//! - `paper/*`: one whole paper-scenario run (SPEC §11, 400 000 steps).

use adaptimp::network::{Rates, Weights};
use adaptimp::{
    simulate, Controller, Environment, Law, Manipulator, Measurement, Rbf, SimConfig, TwoLinkArm,
    Vector, Wall,
};
use criterion::{criterion_group, criterion_main, Criterion};
use nalgebra::SVector;
use std::hint::black_box;
use wide::f64x4;

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
    let grid = Rbf::<2, L>::grid(25.0).expect("grid");
    let direct = grid.to_custom();
    let mut s = SVector::<f64, L>::zeros();
    let z = z_sample();
    c.bench_function("basis/grid_separable", |b| {
        b.iter(|| {
            grid.eval(black_box(&z), &mut s);
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

/// One pass of the three networks (output, update and norms) alone.
fn network(c: &mut Criterion) {
    let grid = Rbf::<2, L>::grid(25.0).expect("grid");
    let mut s = SVector::<f64, L>::zeros();
    grid.eval(&z_sample(), &mut s);
    let mut w = Box::new(Weights::<2, L>::zeros());
    let rates = Rates::new(50e-6, [100.0; 3], [0.01; 3]).expect("rates");
    let (da, a, z2) = (
        Vector::<2>::new(-2.0, 3.5),
        Vector::<2>::new(0.6, 1.1),
        Vector::<2>::new(0.01, -0.02),
    );
    let mut norms = [0.0; 3];
    c.bench_function("network/fused_step", |b| {
        b.iter(|| black_box(w.fused_step(black_box(&s), &da, &a, &z2, &rates, &mut norms)))
    });
}

fn steps(c: &mut Criterion) {
    for (name, law) in [
        ("step/pd", Law::Pd),
        ("step/sf", Law::StateFeedback),
        ("step/of", Law::OutputFeedback),
    ] {
        let mut ctrl = Box::new(Controller::paper(law));
        let m = Measurement {
            x: Vector::<2>::new(0.25, -0.05),
            dx: Some(Vector::<2>::new(0.3, -0.2)),
            tau_e: Vector::<2>::new(5.0, 0.0),
        };
        c.bench_function(name, |b| {
            b.iter(|| black_box(ctrl.step(black_box(&m))));
            ctrl.reset();
        });
    }
}

fn plant(c: &mut Criterion) {
    let arm = TwoLinkArm::paper();
    let wall = Wall::paper();
    let tau = Vector::<2>::new(10.0, -4.0);
    let h = 50e-6;
    c.bench_function("plant/rk4", |b| {
        let (mut x, mut v) = (Vector::<2>::new(0.25, -0.05), Vector::<2>::zeros());
        b.iter(|| {
            let f = |x: &Vector<2>, v: &Vector<2>| {
                arm.forward_dynamics(x, v, &tau, &wall.force(0.0, x, v))
            };
            let k1 = f(&x, &v);
            let (x2, v2) = (x + 0.5 * h * v, v + 0.5 * h * k1);
            let k2 = f(&x2, &v2);
            let (x3, v3) = (x + 0.5 * h * v2, v + 0.5 * h * k2);
            let k3 = f(&x3, &v3);
            let (x4, v4) = (x + h * v3, v + h * k3);
            let k4 = f(&x4, &v4);
            x += h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4);
            v += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            black_box((&x, &v));
        })
    });
}

/// Rows of the lower bound: (2n² + n) = 10 rows of l weights.
const ROWS: usize = 10;

/// One row of the bound: `Ŵ·S` of the old row, then `Ŵ ← a Ŵ + b S`, with
/// explicit 4-wide vectors as in `src/network.rs` (two accumulators).
#[inline(always)]
fn bound_row(w: &mut SVector<f64, L>, s: &SVector<f64, L>, a: f64, b: f64) -> f64 {
    let load = |v: &[f64]| f64x4::from(<[f64; 4]>::try_from(v).unwrap_or([0.0; 4]));
    let (av, bv) = (f64x4::splat(a), f64x4::splat(b));
    let (mut d0, mut d1) = (f64x4::ZERO, f64x4::ZERO);
    let rows = w.as_mut_slice().chunks_exact_mut(8);
    for (wv, sv) in rows.zip(s.as_slice().chunks_exact(8)) {
        let (w0, w1, s0, s1) = (
            load(&wv[..4]),
            load(&wv[4..]),
            load(&sv[..4]),
            load(&sv[4..]),
        );
        d0 += w0 * s0;
        d1 += w1 * s1;
        wv[..4].copy_from_slice(&(av * w0 + bv * s0).to_array());
        wv[4..].copy_from_slice(&(av * w1 + bv * s1).to_array());
    }
    (d0 + d1).reduce_add()
}

/// The weight pass of the bound, kept out of line so that it is compiled as
/// the library's pass is (inlined into a closure it was not vectorised).
#[inline(never)]
fn bound_pass(
    w: &mut [SVector<f64, L>; ROWS],
    s: &SVector<f64, L>,
    a: f64,
    b: &[f64; ROWS],
) -> [f64; ROWS] {
    core::array::from_fn(|r| bound_row(&mut w[r], s, a, b[r]))
}

/// The least work of one state-feedback step: the basis, then one pass that
/// reads each of the 2560 weights once (for the output) and writes it once
/// (the update), and nothing else: no norms, no control law, no reference,
/// no saturation, no observer.
fn bound(c: &mut Criterion) {
    let grid = Rbf::<2, L>::grid(25.0).expect("grid");
    let mut s = SVector::<f64, L>::zeros();
    let mut w = Box::new([SVector::<f64, L>::from_element(0.001); ROWS]);
    let z = z_sample();
    let a = black_box(1.0 - 5e-5);
    let b: [f64; ROWS] = black_box(core::array::from_fn(|r| 1e-6 * (r as f64 + 1.0)));
    c.bench_function("bound/sf_step", |bench| {
        bench.iter(|| {
            grid.eval(black_box(&z), &mut s);
            black_box(bound_pass(&mut w, &s, a, &b))
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
        let mut ctrl = Box::new(Controller::paper(law));
        g.bench_function(name, |b| {
            b.iter(|| {
                black_box(simulate(&arm, &wall, ctrl.as_mut(), &sim, &mut ()).expect("simulate"))
            })
        });
    }
    g.finish();
}

criterion_group!(benches, basis, network, steps, plant, bound, paper);
criterion_main!(benches);
