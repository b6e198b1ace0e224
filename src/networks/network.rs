//! The three RBF networks D̂, Ĉ, Ĝ: their weights, output and update laws,
//! (14)–(17), (37)–(39), SPEC §6.
//!
//! With the shared basis S(Z) ∈ R^L:
//!
//! ```text
//! (D̂ α̇1)_k = Σ_j Σ_i ŴD[k][j][i] S_i α̇1_j      ≈ (D(q) α̇1)_k
//! (Ĉ α1)_k  = Σ_j Σ_i ŴC[k][j][i] S_i α1_j       ≈ (C(q, q̇) α1)_k
//! Ĝ_k       = Σ_i ŴG[k][i] S_i                   ≈ G_k(q)
//! dŴD[k][j][i]/dt = ΓD (S_i α̇1_j z2_k − σD ŴD[k][j][i])     (15)
//! dŴC[k][j][i]/dt = ΓC (S_i α1_j  z2_k − σC ŴC[k][j][i])     (16)
//! dŴG[k][i]/dt    = ΓG (S_i z2_k       − σG ŴG[k][i])        (17)
//! ```
//!
//! Each weight row `Ŵ[k][j]` (a vector over the nodes) appears once in the
//! output, as a dot product with S, and once in the explicit-Euler update
//! `Ŵ ← a Ŵ + b S` with `a = 1 − Ts Γ σ`, `b = Ts Γ u_j z2_k`.
//! [`WeightsMut::fused_step`] does both in one pass over the weights, reading
//! and writing each once.
//!
//! ## Storage
//!
//! The basis and the `(2N² + N)` weight rows live in one flat `f64` buffer
//! owned by the caller's state (heap, or a buffer of the caller's), laid out by
//! [`Layout`]; [`Weights`] and [`WeightsMut`] are views of it. The number of
//! nodes L is a run-time value, so any basis fits and nothing large is ever
//! built on the stack.

use crate::error::{check, Error};
use crate::math::sqrt;
use crate::networks::simd::SimdPath;
use crate::types::Vector;
use pulp::{Simd, WithSimd};

/// Index of the D̂ network in `[f64; 3]` parameter arrays.
pub const D: usize = 0;
/// Index of the Ĉ network.
pub const C: usize = 1;
/// Index of the Ĝ network.
pub const G: usize = 2;

/// f64s per 64-byte cache line.
const LINE: usize = 8;
/// Space between the basis and the weights (1 KiB): loads of S then never
/// share their address modulo 4 KiB with the stores to a weight row that
/// runs beside them (measured for n = 2, l = 256: 315 against 425 ns per pass
/// when they do, "4K aliasing").
const GAP: usize = 128;

/// Where the basis and the weight rows lie in a state's buffer.
///
/// Rows start on 64-byte boundaries (each padded to a multiple of 8 reals), so
/// no vector load straddles a cache line; the weight rows follow the basis
/// after a 1 KiB gap. Order of the rows: ŴD\[k\]\[j\] (N² rows), ŴC\[k\]\[j\] (N²),
/// ŴG\[k\] (N).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct Layout {
    nodes: usize,
    stride: usize,
    rows: usize,
    basis: usize,
}

impl Layout {
    /// Weight rows of `n` joints: `2n² + n`.
    pub const fn rows(n: usize) -> usize {
        2 * n * n + n
    }

    /// The length of a buffer (in f64) that holds the basis and weights of
    /// `n` joints and `nodes` nodes, wherever it starts in memory; `None` if
    /// that overflows `usize`.
    pub const fn buffer_len(n: usize, nodes: usize) -> Option<usize> {
        let stride = match nodes.checked_next_multiple_of(LINE) {
            Some(s) => s,
            None => return None,
        };
        match stride.checked_mul(Self::rows(n) + 1) {
            Some(v) => v.checked_add(LINE + GAP),
            None => None,
        }
    }

    /// The layout inside `buf` (whose first element is at `addr` bytes):
    /// aligned from there; `None` if `buf_len` is too short.
    pub(crate) fn new(n: usize, nodes: usize, addr: usize, buf_len: usize) -> Option<Self> {
        let need = Self::buffer_len(n, nodes)?;
        if buf_len < need {
            return None;
        }
        // Reals to skip to the next 64-byte boundary.
        let basis = (LINE - (addr / 8) % LINE) % LINE;
        Some(Self {
            nodes,
            stride: nodes.next_multiple_of(LINE),
            rows: Self::rows(n),
            basis,
        })
    }

    /// The number of nodes L.
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    fn weights(&self) -> usize {
        self.basis + self.stride + GAP
    }

    /// The basis (length L) and the weight rows (`rows × stride`) of `buf`.
    pub(crate) fn split<'a>(&self, buf: &'a [f64]) -> (&'a [f64], &'a [f64]) {
        let w = self.weights();
        (
            &buf[self.basis..self.basis + self.nodes],
            &buf[w..w + self.rows * self.stride],
        )
    }

    /// The same, mutable.
    pub(crate) fn split_mut<'a>(&self, buf: &'a mut [f64]) -> (&'a mut [f64], &'a mut [f64]) {
        let w = self.weights();
        let (head, tail) = buf.split_at_mut(w);
        (
            &mut head[self.basis..self.basis + self.nodes],
            &mut tail[..self.rows * self.stride],
        )
    }
}

/// Per-step update coefficients of the explicit-Euler learning law.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Rates {
    /// `a = 1 − Ts Γ σ` per network (D, C, G).
    pub decay: [f64; 3],
    /// `Ts Γ` per network (D, C, G) (s times the gain).
    pub gain: [f64; 3],
}

impl Rates {
    /// The same with the learning step scaled by `scale` (the gains Ts Γ times
    /// `scale`, the leakage unchanged), as the normalised step does.
    pub fn scaled(&self, scale: f64) -> Self {
        Self {
            decay: self.decay,
            gain: self.gain.map(|g| g * scale),
        }
    }

    /// Coefficients for sampling period `ts` (s), gains Γ and leakages σ,
    /// validated > 0, with `Ts Γ σ < 1` (the leakage of one explicit-Euler
    /// step, `a = 1 − Ts Γ σ`, must keep the sign of the weights: a ≤ 0
    /// flips or zeroes them every step).
    pub fn new(ts: f64, gamma: [f64; 3], sigma: [f64; 3]) -> Result<Self, Error> {
        check::positive_vec("Γ > 0", "gamma", &Vector::<3>::from(gamma))?;
        check::positive_vec("σ > 0", "sigma", &Vector::<3>::from(sigma))?;
        let leak = Vector::<3>::from_fn(|n, _| ts * gamma[n] * sigma[n]);
        check::each(
            "Ts Γ σ < 1",
            "1 − Ts·gamma·sigma",
            &leak,
            |_, l| 1.0 - l,
            true,
        )?;
        Ok(Self {
            decay: core::array::from_fn(|n| 1.0 - ts * gamma[n] * sigma[n]),
            gain: core::array::from_fn(|n| ts * gamma[n]),
        })
    }
}

/// Bounds on the weight norms ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F (for the projection of
/// `Learning`) derived from the actuator limits:
/// each network may produce at most the actuator's torque ‖τmax‖ for the
/// commanded trajectory's regressor scale.
///
/// Since every S_i ≤ 1, ‖S‖ ≤ √L and `‖Ĝ‖ ≤ ‖ŴG‖_F √L`, `‖D̂ α̇1‖ ≤ ‖ŴD‖_F √L ‖α̇1‖`,
/// `‖Ĉ α1‖ ≤ ‖ŴC‖_F √L ‖α1‖`. With `speed` and `accel` the peak commanded
/// ‖ẋc‖ (rad/s) and ‖ẍc‖ (rad/s²) standing in for ‖α1‖ and ‖α̇1‖ (a
/// trajectory that does not move uses 1 rad/s and 1 rad/s²):
/// `[‖τmax‖/(√L accel), ‖τmax‖/(√L speed), ‖τmax‖/√L]`.
pub fn weight_bounds<const N: usize>(
    tau_max: &Vector<N>,
    nodes: usize,
    speed: f64,
    accel: f64,
) -> [f64; 3] {
    let scale = tau_max.norm() / sqrt(nodes as f64);
    let or_one = |r: f64| if r > 0.0 { r } else { 1.0 };
    [scale / or_one(accel), scale / or_one(speed), scale]
}

/// The vectors of `w` and `s` (equal lengths) in groups of `2 · G` reals
/// (`G = S::F64_LANES`, 4 on both paths), and the rest, which the kernels sum
/// and update real by real, on every path alike.
#[inline(always)]
#[allow(clippy::type_complexity)]
fn groups_mut<'w, 's, S: Simd>(
    w: &'w mut [f64],
    s: &'s [f64],
) -> (
    (&'w mut [[S::f64s; 2]], &'s [[S::f64s; 2]]),
    (&'w mut [f64], &'s [f64]),
) {
    let n = w.len().min(s.len());
    let n = n - n % (2 * S::F64_LANES);
    let (wh, wr) = w.split_at_mut(n);
    let (sh, sr) = s.split_at(n);
    let (wv, _) = pulp::as_arrays_mut::<2, _>(S::as_mut_simd_f64s(wh).0);
    let (sv, _) = pulp::as_arrays::<2, _>(S::as_simd_f64s(sh).0);
    ((wv, sv), (wr, sr))
}

/// `unit` on each group of two vectors of `w` and `s`, in order, two groups
/// per loop iteration (see [`dot_update`]); returns the scalar tails.
#[inline(always)]
fn for_groups<'w, 's, S: Simd>(
    w: &'w mut [f64],
    s: &'s [f64],
    mut unit: impl FnMut(&mut [S::f64s; 2], &[S::f64s; 2]),
) -> (&'w mut [f64], &'s [f64]) {
    let ((wv, sv), tails) = groups_mut::<S>(w, s);
    let ((w2, w1), (s2, s1)) = (pulp::as_arrays_mut::<2, _>(wv), pulp::as_arrays::<2, _>(sv));
    for ([x0, x1], [y0, y1]) in w2.iter_mut().zip(s2) {
        unit(x0, y0);
        unit(x1, y1);
    }
    for (x, y) in w1.iter_mut().zip(s1) {
        unit(x, y);
    }
    tails
}

/// One row: returns `Ŵ·S` of the old row, and writes `Ŵ ← a Ŵ + b S`.
///
/// Explicit vectors of pulp's [`Simd`] (4 lanes on both paths, see
/// [`crate::networks::simd`]) rather than arrays left to the autovectoriser, which
/// vectorised the ten inlined copies of this loop unevenly (some at half
/// width). Each group of two vectors feeds two independent accumulators.
/// Products and sums stay separate (never fused into an FMA), so the results
/// are the same on every path and target.
///
/// The loops over the vectors take two steps (`unit`) per iteration: what
/// `-C target-cpu=x86-64-v3` made of them. The function pulp compiles for
/// AVX2 keeps the generic tuning, which does not unroll, so it is spelt out
/// (callgrind: 5% fewer instructions per pass). The steps, and so every sum,
/// keep their order.
#[inline(always)]
fn dot_update<S: Simd>(simd: S, w: &mut [f64], s: &[f64], a: f64, b: f64) -> f64 {
    let (av, bv) = (simd.splat_f64s(a), simd.splat_f64s(b));
    // Two independent accumulators hide the latency of the additions.
    let mut d = [simd.splat_f64s(0.0); 2];
    let unit = |w: &mut [S::f64s; 2], s: &[S::f64s; 2]| {
        for i in 0..2 {
            d[i] = simd.add_f64s(d[i], simd.mul_f64s(w[i], s[i]));
            w[i] = simd.add_f64s(simd.mul_f64s(av, w[i]), simd.mul_f64s(bv, s[i]));
        }
    };
    let (wr, sr) = for_groups::<S>(w, s, unit);
    let mut dot = simd.reduce_sum_f64s(simd.add_f64s(d[0], d[1]));
    for (wv, &sv) in wr.iter_mut().zip(sr) {
        dot += *wv * sv;
        *wv = a * *wv + b * sv;
    }
    dot
}

/// Two rows sharing the basis, each vector of S loaded once for both: returns
/// `Ŵ0·S`, `Ŵ1·S` of the old rows and writes `Ŵr ← ar Ŵr + br S`. One
/// accumulator per row.
#[inline(always)]
fn dot_update_pair<S: Simd>(
    simd: S,
    w0: &mut [f64],
    w1: &mut [f64],
    s: &[f64],
    (a0, b0): (f64, f64),
    (a1, b1): (f64, f64),
) -> (f64, f64) {
    let (a0v, b0v, a1v, b1v) = (
        simd.splat_f64s(a0),
        simd.splat_f64s(b0),
        simd.splat_f64s(a1),
        simd.splat_f64s(b1),
    );
    let (mut d0, mut d1) = (simd.splat_f64s(0.0), simd.splat_f64s(0.0));
    let (c0, r0) = S::as_mut_simd_f64s(w0);
    let (c1, r1) = S::as_mut_simd_f64s(w1);
    let (cs, rs) = S::as_simd_f64s(s);
    let mut unit = |v0: &mut S::f64s, v1: &mut S::f64s, sx: S::f64s| {
        let (x0, x1) = (*v0, *v1);
        d0 = simd.add_f64s(d0, simd.mul_f64s(x0, sx));
        d1 = simd.add_f64s(d1, simd.mul_f64s(x1, sx));
        *v0 = simd.add_f64s(simd.mul_f64s(a0v, x0), simd.mul_f64s(b0v, sx));
        *v1 = simd.add_f64s(simd.mul_f64s(a1v, x1), simd.mul_f64s(b1v, sx));
    };
    // Two steps per iteration, as in `dot_update`.
    let (p0, o0) = pulp::as_arrays_mut::<2, _>(c0);
    let (p1, o1) = pulp::as_arrays_mut::<2, _>(c1);
    let (ps, os) = pulp::as_arrays::<2, _>(cs);
    for ((x0, x1), sx) in p0.iter_mut().zip(p1.iter_mut()).zip(ps) {
        unit(&mut x0[0], &mut x1[0], sx[0]);
        unit(&mut x0[1], &mut x1[1], sx[1]);
    }
    for ((v0, v1), &sx) in o0.iter_mut().zip(o1.iter_mut()).zip(os) {
        unit(v0, v1, sx);
    }
    let (mut e0, mut e1) = (simd.reduce_sum_f64s(d0), simd.reduce_sum_f64s(d1));
    for ((v0, v1), &sx) in r0.iter_mut().zip(r1.iter_mut()).zip(rs) {
        e0 += *v0 * sx;
        e1 += *v1 * sx;
        *v0 = a0 * *v0 + b0 * sx;
        *v1 = a1 * *v1 + b1 * sx;
    }
    (e0, e1)
}

/// One row: `Ŵ ← a Ŵ + b S`; returns `‖Ŵ‖²` of the new row.
#[inline(always)]
fn update_row<S: Simd>(simd: S, w: &mut [f64], s: &[f64], a: f64, b: f64) -> f64 {
    let (av, bv) = (simd.splat_f64s(a), simd.splat_f64s(b));
    let mut q = [simd.splat_f64s(0.0); 2];
    let unit = |w: &mut [S::f64s; 2], s: &[S::f64s; 2]| {
        for i in 0..2 {
            let n = simd.add_f64s(simd.mul_f64s(av, w[i]), simd.mul_f64s(bv, s[i]));
            q[i] = simd.add_f64s(q[i], simd.mul_f64s(n, n));
            w[i] = n;
        }
    };
    let (wr, sr) = for_groups::<S>(w, s, unit);
    let mut sq = simd.reduce_sum_f64s(simd.add_f64s(q[0], q[1]));
    for (wv, &sv) in wr.iter_mut().zip(sr) {
        *wv = a * *wv + b * sv;
        sq += *wv * *wv;
    }
    sq
}

/// `a · b` over the shorter length, on vectors with two accumulators (a
/// scalar sum is a chain of dependent additions, four times slower).
#[inline(always)]
pub(crate) fn dot<S: Simd>(simd: S, a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let n = n - n % (2 * S::F64_LANES);
    let (ah, ar) = a.split_at(n);
    let (bh, br) = b.split_at(n);
    let (av, _) = pulp::as_arrays::<2, _>(S::as_simd_f64s(ah).0);
    let (bv, _) = pulp::as_arrays::<2, _>(S::as_simd_f64s(bh).0);
    let mut d = [simd.splat_f64s(0.0); 2];
    let mut unit = |x: &[S::f64s; 2], y: &[S::f64s; 2]| {
        for i in 0..2 {
            d[i] = simd.add_f64s(d[i], simd.mul_f64s(x[i], y[i]));
        }
    };
    // Two steps per iteration, as in `dot_update`.
    let (a2, a1) = pulp::as_arrays::<2, _>(av);
    let (b2, b1) = pulp::as_arrays::<2, _>(bv);
    for ([x0, x1], [y0, y1]) in a2.iter().zip(b2) {
        unit(x0, y0);
        unit(x1, y1);
    }
    for (x, y) in a1.iter().zip(b1) {
        unit(x, y);
    }
    let mut sum = simd.reduce_sum_f64s(simd.add_f64s(d[0], d[1]));
    for (x, y) in ar.iter().zip(br) {
        sum += x * y;
    }
    sum
}

/// `a · b` on `path` (see [`dot`]).
pub(crate) fn dot_on(path: SimdPath, a: &[f64], b: &[f64]) -> f64 {
    struct Dot<'a>(&'a [f64], &'a [f64]);
    impl WithSimd for Dot<'_> {
        type Output = f64;
        #[inline(always)]
        fn with_simd<S: Simd>(self, simd: S) -> f64 {
            dot(simd, self.0, self.1)
        }
    }
    path.run(Dot(a, b))
}

/// `Ŵr · S` of `R` rows sharing the basis, each vector of S loaded once
/// for all of them. Each row's sum is [`dot`]'s, operation for operation
/// (two accumulators, even and odd vectors, then the scalar tail), so the
/// results are the same bits as `R` calls of [`dot`]; each row at least as
/// long as S. Plain loops over the rows (no closures, which would leave the
/// vector operations outside the instruction set's compiled function).
#[inline(always)]
fn dot_rows<S: Simd, const R: usize>(simd: S, rows: [&[f64]; R], s: &[f64]) -> [f64; R] {
    let l = s.len();
    let n = l - l % (2 * S::F64_LANES);
    let (sh, sr) = s.split_at(n);
    let (sv, _) = pulp::as_arrays::<2, _>(S::as_simd_f64s(sh).0);
    let pairs = sv.len();
    let mut wv: [&[[S::f64s; 2]]; R] = [&[]; R];
    for r in 0..R {
        wv[r] = &pulp::as_arrays::<2, _>(S::as_simd_f64s(&rows[r][..n]).0).0[..pairs];
    }
    let mut d = [[simd.splat_f64s(0.0); 2]; R];
    for (p, y) in sv.iter().enumerate() {
        for r in 0..R {
            let x = &wv[r][p];
            for i in 0..2 {
                d[r][i] = simd.add_f64s(d[r][i], simd.mul_f64s(x[i], y[i]));
            }
        }
    }
    let mut out = [0.0; R];
    for r in 0..R {
        let mut sum = simd.reduce_sum_f64s(simd.add_f64s(d[r][0], d[r][1]));
        for (x, y) in rows[r][n..l].iter().zip(sr) {
            sum += x * y;
        }
        out[r] = sum;
    }
    out
}

/// `Ŵ0 ← a0 Ŵ0 + b0 S` and `Ŵ1 ← a1 Ŵ1 + b1 S`, each vector of S loaded
/// once for both; returns each new row's `‖Ŵr‖²`. Each row is
/// [`update_row`]'s, operation for operation (the same bits); both rows as
/// long as S.
#[inline(always)]
fn update_pair<S: Simd>(
    simd: S,
    w0: &mut [f64],
    w1: &mut [f64],
    s: &[f64],
    (a0, b0): (f64, f64),
    (a1, b1): (f64, f64),
) -> (f64, f64) {
    let l = s.len();
    let n = l - l % (2 * S::F64_LANES);
    let (sh, sr) = s.split_at(n);
    let (sv, _) = pulp::as_arrays::<2, _>(S::as_simd_f64s(sh).0);
    let pairs = sv.len();
    let (h0, t0) = w0[..l].split_at_mut(n);
    let (h1, t1) = w1[..l].split_at_mut(n);
    let h0 = &mut pulp::as_arrays_mut::<2, _>(S::as_mut_simd_f64s(h0).0).0[..pairs];
    let h1 = &mut pulp::as_arrays_mut::<2, _>(S::as_mut_simd_f64s(h1).0).0[..pairs];
    let (a0v, b0v, a1v, b1v) = (
        simd.splat_f64s(a0),
        simd.splat_f64s(b0),
        simd.splat_f64s(a1),
        simd.splat_f64s(b1),
    );
    let (mut q0, mut q1) = ([simd.splat_f64s(0.0); 2], [simd.splat_f64s(0.0); 2]);
    for ((x0, x1), y) in h0.iter_mut().zip(h1.iter_mut()).zip(sv) {
        for i in 0..2 {
            let v0 = simd.add_f64s(simd.mul_f64s(a0v, x0[i]), simd.mul_f64s(b0v, y[i]));
            let v1 = simd.add_f64s(simd.mul_f64s(a1v, x1[i]), simd.mul_f64s(b1v, y[i]));
            q0[i] = simd.add_f64s(q0[i], simd.mul_f64s(v0, v0));
            q1[i] = simd.add_f64s(q1[i], simd.mul_f64s(v1, v1));
            x0[i] = v0;
            x1[i] = v1;
        }
    }
    let mut sq0 = simd.reduce_sum_f64s(simd.add_f64s(q0[0], q0[1]));
    let mut sq1 = simd.reduce_sum_f64s(simd.add_f64s(q1[0], q1[1]));
    for ((v0, v1), &sv) in t0.iter_mut().zip(t1.iter_mut()).zip(sr) {
        *v0 = a0 * *v0 + b0 * sv;
        sq0 += *v0 * *v0;
        *v1 = a1 * *v1 + b1 * sv;
        sq1 += *v1 * *v1;
    }
    (sq0, sq1)
}

/// The weights of the three networks, read-only: a view of a state's buffer
/// (or of a caller's flat array, [`Weights::from_rows`]).
///
/// Units: D̂ weights in kg m², Ĉ in kg m²/s, Ĝ in N m (each times the
/// dimensionless basis).
#[derive(Copy, Clone, Debug)]
pub struct Weights<'a, const N: usize> {
    rows: &'a [f64],
    nodes: usize,
    stride: usize,
}

/// The weights of the three networks, writable (see [`Weights`]).
#[derive(Debug)]
pub struct WeightsMut<'a, const N: usize> {
    rows: &'a mut [f64],
    nodes: usize,
    stride: usize,
}

/// Offset of row `r` of network `net` ([`D`], [`C`]: r = k·N + j; [`G`]: r = k).
#[inline(always)]
const fn row_index(n: usize, net: usize, r: usize) -> usize {
    net * n * n + r
}

impl<'a, const N: usize> Weights<'a, N> {
    pub(crate) fn new(rows: &'a [f64], nodes: usize, stride: usize) -> Self {
        Self {
            rows,
            nodes,
            stride,
        }
    }

    /// A view of `data`: the `2N² + N` rows of `nodes` reals each, back to back,
    /// in the order ŴD\[k\]\[j\], ŴC\[k\]\[j\], ŴG\[k\] (row-major over k, j). Errors if
    /// the length is not `(2N² + N)·nodes`.
    pub fn from_rows(data: &'a [f64], nodes: usize) -> Result<Self, Error> {
        if nodes == 0 || data.len() != Layout::rows(N) * nodes {
            return Err(Error::Invalid {
                what: "weights",
                reason: "need (2n² + n)·L values: ŴD[k][j], ŴC[k][j], ŴG[k], each over the L nodes",
            });
        }
        Ok(Self::new(data, nodes, nodes))
    }

    /// The number of nodes L.
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    fn row(&self, i: usize) -> &'a [f64] {
        &self.rows[i * self.stride..i * self.stride + self.nodes]
    }

    /// Row `ŴD[k][j]` over the nodes (kg m²).
    pub fn d(&self, k: usize, j: usize) -> &'a [f64] {
        self.row(row_index(N, D, k * N + j))
    }
    /// Row `ŴC[k][j]` over the nodes (kg m²/s).
    pub fn c(&self, k: usize, j: usize) -> &'a [f64] {
        self.row(row_index(N, C, k * N + j))
    }
    /// Row `ŴG[k]` over the nodes (N m).
    pub fn g(&self, k: usize) -> &'a [f64] {
        self.row(row_index(N, G, k))
    }

    /// Every row of network `net` ([`D`], [`C`] or [`G`]).
    pub fn network(&self, net: usize) -> impl Iterator<Item = &'a [f64]> + '_ {
        let (first, count) = match net {
            D => (row_index(N, D, 0), N * N),
            C => (row_index(N, C, 0), N * N),
            _ => (row_index(N, G, 0), N),
        };
        (first..first + count).map(|i| self.row(i))
    }

    /// Every weight finite.
    pub fn check_finite(&self) -> Result<(), Error> {
        for (net, what) in [(D, "weights.D"), (C, "weights.C"), (G, "weights.G")] {
            for row in self.network(net) {
                check::finite_slice(what, row)?;
            }
        }
        Ok(())
    }

    /// Frobenius norms ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F, recomputed from the weights
    /// on the portable path (off the step: a controller tracks the norms from
    /// its passes, [`WeightsMut::fused_step`]; both paths give the same sums).
    pub fn norms(&self) -> [f64; 3] {
        let simd = pulp::Scalar256b;
        [D, C, G].map(|net| sqrt(self.network(net).map(|r| dot(simd, r, r)).sum()))
    }

    /// Network output `D̂ α̇1 + Ĉ α1 + Ĝ` (N m) for basis `s`, without
    /// learning, on the instruction set `path` (a controller passes its own,
    /// [`Controller::simd`](crate::Controller::simd)).
    pub fn output(
        &self,
        path: SimdPath,
        s: &[f64],
        dalpha1: &Vector<N>,
        alpha1: &Vector<N>,
    ) -> Vector<N> {
        struct Output<'w, 'v, const N: usize> {
            w: &'v Weights<'w, N>,
            s: &'v [f64],
            dalpha1: &'v Vector<N>,
            alpha1: &'v Vector<N>,
        }
        impl<const N: usize> WithSimd for Output<'_, '_, N> {
            type Output = Vector<N>;
            #[inline(always)]
            fn with_simd<S: Simd>(self, simd: S) -> Vector<N> {
                let Self {
                    w,
                    s,
                    dalpha1,
                    alpha1,
                } = self;
                // Each row's dot as `dot` sums it, four rows per pass over
                // S (the sums, and so the output, are the same bits).
                let s = &s[..s.len().min(w.nodes)];
                Vector::from_fn(|k, _| {
                    let [mut out] = dot_rows(simd, [w.g(k)], s);
                    let mut j = 0;
                    while j + 1 < N {
                        let [d0, c0, d1, c1] = dot_rows(
                            simd,
                            [w.d(k, j), w.c(k, j), w.d(k, j + 1), w.c(k, j + 1)],
                            s,
                        );
                        out += d0 * dalpha1[j] + c0 * alpha1[j];
                        out += d1 * dalpha1[j + 1] + c1 * alpha1[j + 1];
                        j += 2;
                    }
                    if j < N {
                        let [d0, c0] = dot_rows(simd, [w.d(k, j), w.c(k, j)], s);
                        out += d0 * dalpha1[j] + c0 * alpha1[j];
                    }
                    out
                })
            }
        }
        path.run(Output {
            w: self,
            s,
            dalpha1,
            alpha1,
        })
    }
}

impl<'a, const N: usize> WeightsMut<'a, N> {
    pub(crate) fn new(rows: &'a mut [f64], nodes: usize, stride: usize) -> Self {
        Self {
            rows,
            nodes,
            stride,
        }
    }

    /// A read-only view.
    pub fn as_ref(&self) -> Weights<'_, N> {
        Weights::new(self.rows, self.nodes, self.stride)
    }

    pub(crate) fn row_mut(&mut self, i: usize) -> &mut [f64] {
        &mut self.rows[i * self.stride..i * self.stride + self.nodes]
    }

    /// Row `ŴD[k][j]`, writable.
    pub fn d_mut(&mut self, k: usize, j: usize) -> &mut [f64] {
        self.row_mut(row_index(N, D, k * N + j))
    }
    /// Row `ŴC[k][j]`, writable.
    pub fn c_mut(&mut self, k: usize, j: usize) -> &mut [f64] {
        self.row_mut(row_index(N, C, k * N + j))
    }
    /// Row `ŴG[k]`, writable.
    pub fn g_mut(&mut self, k: usize) -> &mut [f64] {
        self.row_mut(row_index(N, G, k))
    }

    /// Copy every weight from `src` (same N and L; the caller checks L).
    pub(crate) fn copy_from(&mut self, src: &Weights<'_, N>) {
        for i in 0..Layout::rows(N) {
            self.row_mut(i).copy_from_slice(src.row(i));
        }
    }

    /// All weights zero.
    pub fn fill_zero(&mut self) {
        self.rows.fill(0.0);
    }

    /// Multiply every weight of network `net` ([`D`], [`C`] or [`G`]) by `factor`.
    pub fn scale_network(&mut self, net: usize, factor: f64) {
        self.scale_network_on(SimdPath::portable(), net, factor);
    }

    /// [`scale_network`](Self::scale_network) on the instruction set `path`
    /// (each weight times `factor`, the same bits on every path).
    pub fn scale_network_on(&mut self, path: SimdPath, net: usize, factor: f64) {
        struct Scale<'w, 'v, const N: usize> {
            w: &'v mut WeightsMut<'w, N>,
            net: usize,
            factor: f64,
        }
        impl<const N: usize> WithSimd for Scale<'_, '_, N> {
            type Output = ();
            #[inline(always)]
            fn with_simd<S: Simd>(self, simd: S) {
                let Self { w, net, factor } = self;
                let (first, count) = match net {
                    D => (row_index(N, D, 0), N * N),
                    C => (row_index(N, C, 0), N * N),
                    _ => (row_index(N, G, 0), N),
                };
                let f = simd.splat_f64s(factor);
                for i in first..first + count {
                    let (head, tail) = S::as_mut_simd_f64s(w.row_mut(i));
                    for v in head {
                        *v = simd.mul_f64s(*v, f);
                    }
                    for x in tail {
                        *x *= factor;
                    }
                }
            }
        }
        path.run(Scale {
            w: self,
            net,
            factor,
        });
    }

    /// One step of the networks in a single pass over the weights, on the
    /// instruction set `path` (a controller passes its own,
    /// [`Controller::simd`](crate::Controller::simd)): returns the output
    /// `D̂ α̇1 + Ĉ α1 + Ĝ` (N m) with the current weights, then applies the
    /// explicit-Euler update of (15)–(17) with error signal `z2` (rad/s; ẑ2
    /// for output feedback, (37)–(39)) at `rates`.
    ///
    /// `norms` holds the Frobenius norms ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ of the weights
    /// before the step and is brought up to date without a second pass: for
    /// every row, ‖a Ŵ + b S‖² = a² ‖Ŵ‖² + 2ab (Ŵ·S) + b² ‖S‖², and Ŵ·S is the
    /// dot product the output needs anyway.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    pub fn fused_step(
        &mut self,
        path: SimdPath,
        s: &[f64],
        dalpha1: &Vector<N>,
        alpha1: &Vector<N>,
        z2: &Vector<N>,
        rates: &Rates,
        norms: &mut [f64; 3],
    ) -> Vector<N> {
        struct Fused<'w, 'v, const N: usize> {
            w: &'v mut WeightsMut<'w, N>,
            s: &'v [f64],
            dalpha1: &'v Vector<N>,
            alpha1: &'v Vector<N>,
            z2: &'v Vector<N>,
            rates: &'v Rates,
            norms: &'v mut [f64; 3],
        }
        impl<const N: usize> WithSimd for Fused<'_, '_, N> {
            type Output = Vector<N>;
            #[inline(always)]
            fn with_simd<S: Simd>(self, simd: S) -> Vector<N> {
                let Self {
                    w,
                    s,
                    dalpha1,
                    alpha1,
                    z2,
                    rates,
                    norms,
                } = self;
                w.fused_step_on(simd, s, dalpha1, alpha1, z2, rates, norms)
            }
        }
        path.run(Fused {
            w: self,
            s,
            dalpha1,
            alpha1,
            z2,
            rates,
            norms,
        })
    }

    /// [`fused_step`](Self::fused_step) on the vectors of `simd`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn fused_step_on<S: Simd>(
        &mut self,
        simd: S,
        s: &[f64],
        dalpha1: &Vector<N>,
        alpha1: &Vector<N>,
        z2: &Vector<N>,
        rates: &Rates,
        norms: &mut [f64; 3],
    ) -> Vector<N> {
        let (l, stride) = (self.nodes, self.stride);
        let s = &s[..l];
        let (d, rest) = self.rows.split_at_mut(N * N * stride);
        let (c, g) = rest.split_at_mut(N * N * stride);
        let mut out = Vector::<N>::zeros();
        // Per network: Σ_rows b·(Ŵ·S) and Σ_rows b².
        let mut cross = [0.0; 3];
        let mut bb = [0.0; 3];
        let (a, gain) = (rates.decay, rates.gain);
        for k in 0..N {
            let gz = z2[k];
            for j in 0..N {
                let r = (k * N + j) * stride;
                // ŴD[k][j] and ŴC[k][j] share one pass over S.
                let (bd, bc) = (gain[D] * dalpha1[j] * gz, gain[C] * alpha1[j] * gz);
                let (dd, dc) = dot_update_pair(
                    simd,
                    &mut d[r..r + l],
                    &mut c[r..r + l],
                    s,
                    (a[D], bd),
                    (a[C], bc),
                );
                out[k] += dd * dalpha1[j] + dc * alpha1[j];
                cross[D] += bd * dd;
                cross[C] += bc * dc;
                bb[D] += bd * bd;
                bb[C] += bc * bc;
            }
            let b = gain[G] * gz;
            let dot = dot_update(simd, &mut g[k * stride..k * stride + l], s, a[G], b);
            out[k] += dot;
            cross[G] += b * dot;
            bb[G] += b * b;
        }
        let s2 = dot(simd, s, s);
        for net in 0..3 {
            let n2 = a[net] * a[net] * norms[net] * norms[net]
                + 2.0 * a[net] * cross[net]
                + s2 * bb[net];
            // Rounding can take an exact zero a hair below it.
            norms[net] = sqrt(n2.max(0.0));
        }
        out
    }

    /// The explicit-Euler update of (15)–(17) alone (after
    /// [`Weights::output`] has used the old weights), on the instruction set
    /// `path`. Rows of joint k learn from `z2[k]`; pass 0 there to freeze
    /// joint k's learning (its weights then only leak). Returns the Frobenius
    /// norms of the new weights.
    pub fn update(
        &mut self,
        path: SimdPath,
        s: &[f64],
        dalpha1: &Vector<N>,
        alpha1: &Vector<N>,
        z2: &Vector<N>,
        rates: &Rates,
    ) -> [f64; 3] {
        struct Update<'w, 'v, const N: usize> {
            w: &'v mut WeightsMut<'w, N>,
            s: &'v [f64],
            dalpha1: &'v Vector<N>,
            alpha1: &'v Vector<N>,
            z2: &'v Vector<N>,
            rates: &'v Rates,
        }
        impl<const N: usize> WithSimd for Update<'_, '_, N> {
            type Output = [f64; 3];
            #[inline(always)]
            fn with_simd<S: Simd>(self, simd: S) -> [f64; 3] {
                let Self {
                    w,
                    s,
                    dalpha1,
                    alpha1,
                    z2,
                    rates,
                } = self;
                let s = &s[..w.nodes];
                let mut sq = [0.0; 3];
                let (a, gain) = (rates.decay, rates.gain);
                let (l, stride) = (w.nodes, w.stride);
                let (d, rest) = w.rows.split_at_mut(N * N * stride);
                let (c, g) = rest.split_at_mut(N * N * stride);
                for k in 0..N {
                    let gz = z2[k];
                    for j in 0..N {
                        let (bd, bc) = (gain[D] * dalpha1[j] * gz, gain[C] * alpha1[j] * gz);
                        // ŴD[k][j] and ŴC[k][j] in one pass over S, each row
                        // as `update_row` updates it; the norms summed in order.
                        let r = (k * N + j) * stride;
                        let (nd, nc) = update_pair(
                            simd,
                            &mut d[r..r + l],
                            &mut c[r..r + l],
                            s,
                            (a[D], bd),
                            (a[C], bc),
                        );
                        sq[D] += nd;
                        sq[C] += nc;
                    }
                    sq[G] += update_row(
                        simd,
                        &mut g[k * stride..k * stride + l],
                        s,
                        a[G],
                        gain[G] * gz,
                    );
                }
                sq.map(sqrt)
            }
        }
        path.run(Update {
            w: self,
            s,
            dalpha1,
            alpha1,
            z2,
            rates,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const L: usize = 16;

    fn basis() -> [f64; L] {
        core::array::from_fn(|i| 0.1 + 0.05 * i as f64)
    }

    /// A buffer and its layout for N = 1, L = 16.
    fn buffer() -> (Vec<f64>, Layout) {
        let len = Layout::buffer_len(1, L).unwrap();
        let buf = vec![0.0; len];
        let layout = Layout::new(1, L, buf.as_ptr() as usize, len).unwrap();
        (buf, layout)
    }

    #[test]
    fn layout_aligns_rows_and_keeps_the_gap() {
        let (buf, layout) = buffer();
        let (s, w) = layout.split(&buf);
        assert_eq!(s.len(), L);
        assert_eq!(w.len(), 3 * 16);
        assert_eq!(s.as_ptr() as usize % 64, 0);
        assert_eq!(w.as_ptr() as usize % 64, 0);
        assert_eq!(w.as_ptr() as usize - s.as_ptr() as usize, 8 * (16 + GAP));
        assert!(Layout::new(1, L, 0, Layout::buffer_len(1, L).unwrap() - 1).is_none());
        assert_eq!(Layout::buffer_len(7, usize::MAX), None);
    }

    #[test]
    fn fused_step_equals_output_then_euler_update() {
        let (mut buf, layout) = buffer();
        let (_, rows) = layout.split_mut(&mut buf);
        let mut w = WeightsMut::<1>::new(rows, L, layout.stride);
        // Some non-zero weights.
        for (i, v) in w.d_mut(0, 0).iter_mut().enumerate() {
            *v = 0.01 * i as f64;
        }
        w.c_mut(0, 0).fill(-0.2);
        w.g_mut(0).fill(0.3);
        let s = basis();
        let (da, a, z2) = (
            Vector::<1>::new(2.0),
            Vector::<1>::new(-0.5),
            Vector::<1>::new(0.1),
        );
        let ts = 1e-3;
        let (gamma, sigma) = ([100.0; 3], [0.01; 3]);
        let rates = Rates::new(ts, gamma, sigma).unwrap();
        let expect_out = w.as_ref().output(SimdPath::portable(), &s, &da, &a);
        let expect_norms = w.as_ref().norms();
        // The SPEC's form: Ŵ ← Ŵ + Ts Γ (S u z2 − σ Ŵ).
        let old: Vec<Vec<f64>> = (0..3).map(|i| w.as_ref().row(i).to_vec()).collect();
        let u = [da[0], a[0], 1.0];
        let mut copy: Vec<f64> = (0..3).flat_map(|i| w.as_ref().row(i).to_vec()).collect();
        let mut w2 = WeightsMut::<1>::new(&mut copy, L, L);
        let mut norms = expect_norms;
        let out = w.fused_step(SimdPath::fastest(), &s, &da, &a, &z2, &rates, &mut norms);
        // The separate update does the same.
        let new_norms = w2.update(SimdPath::fastest(), &s, &da, &a, &z2, &rates);
        for i in 0..3 {
            assert_eq!(w2.as_ref().row(i), w.as_ref().row(i));
            for n in 0..L {
                let expect =
                    old[i][n] + ts * gamma[i] * (s[n] * u[i] * z2[0] - sigma[i] * old[i][n]);
                assert!((w.as_ref().row(i)[n] - expect).abs() < 1e-15);
            }
        }
        assert!((out - expect_out).norm() < 1e-14, "{out} vs {expect_out}");
        // The norms were brought up to date without a second pass.
        let exact = w.as_ref().norms();
        for n in 0..3 {
            assert!(
                (norms[n] - exact[n]).abs() < 1e-13 * exact[n],
                "{norms:?} vs {exact:?}"
            );
            assert!((new_norms[n] - exact[n]).abs() < 1e-13 * exact[n]);
        }
    }

    #[test]
    fn from_rows_checks_the_length() {
        let data = [0.0; 3 * L];
        assert!(Weights::<1>::from_rows(&data, L).is_ok());
        let e = Weights::<1>::from_rows(&data[1..], L).unwrap_err();
        assert!(e.to_string().contains("(2n² + n)·L"), "{e}");
    }

    #[test]
    fn rates_reject_nonpositive_gain_by_name() {
        let e = Rates::new(1e-3, [100.0, 0.0, 100.0], [0.01; 3]).unwrap_err();
        assert!(e.to_string().contains("Γ > 0"), "{e}");
        let e = Rates::new(1e-3, [100.0; 3], [0.01, 0.01, -1.0]).unwrap_err();
        assert!(e.to_string().contains("σ > 0"), "{e}");
    }
}
