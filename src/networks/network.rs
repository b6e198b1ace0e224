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

mod kernels;
pub(crate) use kernels::*;

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
mod tests;
