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
//! `Ŵ ← a Ŵ + b S` with `a = 1 − Ts Γ σ`, `b = Ts Γ u_j z2_k`. [`Weights::fused_step`]
//! does both in one pass over the weights, reading and writing each once.

use crate::error::{check, Error};
use crate::math::sqrt;
use crate::Vector;
use nalgebra::SVector;
use wide::f64x4;

/// Index of the three networks in `[f64; 3]` parameter arrays.
pub const D: usize = 0;
/// Index of the Ĉ network.
pub const C: usize = 1;
/// Index of the Ĝ network.
pub const G: usize = 2;

/// Weights of the three networks, all zero at t = 0 (SPEC §6).
///
/// `d[k][j]` is the row `ŴD[k][j][·]` over the `L` nodes, `c[k][j]` likewise,
/// `g[k]` is `ŴG[k][·]`. Units: D̂ weights in kg m², Ĉ in kg m²/s, Ĝ in N m
/// (each times the dimensionless basis).
#[repr(C)]
#[derive(Clone, Debug, PartialEq)]
pub struct Weights<const N: usize, const L: usize> {
    /// `ŴD[k][j]` (kg m²).
    pub d: [[SVector<f64, L>; N]; N],
    /// `ŴC[k][j]` (kg m²/s).
    pub c: [[SVector<f64, L>; N]; N],
    /// `ŴG[k]` (N m).
    pub g: [SVector<f64, L>; N],
}

/// The basis and the weights, laid out for the fused pass.
///
/// The pass streams every weight row against the basis, so layout decides its
/// speed (measured: 315 against 425 ns for n = 2, l = 256): rows start on
/// 64-byte boundaries, so no vector load straddles a cache line, and the basis
/// lies 1 KiB away from every row modulo 4 KiB (for rows of 2 KiB), so loads of
/// S do not falsely wait on stores to Ŵ ("4K aliasing").
#[repr(C, align(64))]
#[derive(Clone, Debug, PartialEq)]
pub struct Workspace<const N: usize, const L: usize> {
    /// The basis S(Z) of the current step.
    pub basis: SVector<f64, L>,
    gap: [u64; 128],
    /// The network weights.
    pub weights: Weights<N, L>,
}

impl<const N: usize, const L: usize> Workspace<N, L> {
    /// Zero basis and weights.
    pub fn zeros() -> Self {
        Self {
            basis: SVector::zeros(),
            gap: [0; 128],
            weights: Weights::zeros(),
        }
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

    /// Coefficients for sampling period `ts` (s), gains Γ and leakages σ, validated > 0.
    pub fn new(ts: f64, gamma: [f64; 3], sigma: [f64; 3]) -> Result<Self, Error> {
        check::positive_vec("Γ > 0", "gamma", &Vector::<3>::from(gamma))?;
        check::positive_vec("σ > 0", "sigma", &Vector::<3>::from(sigma))?;
        Ok(Self {
            decay: core::array::from_fn(|n| 1.0 - ts * gamma[n] * sigma[n]),
            gain: core::array::from_fn(|n| ts * gamma[n]),
        })
    }
}

/// Bounds on the weight norms ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F (for
/// [`Config::weight_bound`](crate::Config::weight_bound)) derived from the
/// actuator limits: each network may produce at most the actuator's torque
/// ‖τmax‖ for the commanded trajectory's regressor scale.
///
/// Since every S_i ≤ 1, ‖S‖ ≤ √L and `‖Ĝ‖ ≤ ‖ŴG‖_F √L`, `‖D̂ α̇1‖ ≤ ‖ŴD‖_F √L ‖α̇1‖`,
/// `‖Ĉ α1‖ ≤ ‖ŴC‖_F √L ‖α1‖`. With `speed` and `accel` the peak commanded
/// ‖ẋc‖ (rad/s) and ‖ẍc‖ (rad/s²) standing in for ‖α1‖ and ‖α̇1‖:
/// `[‖τmax‖/(√L accel), ‖τmax‖/(√L speed), ‖τmax‖/√L]`.
pub fn weight_bounds<const N: usize>(
    tau_max: &Vector<N>,
    nodes: usize,
    speed: f64,
    accel: f64,
) -> [f64; 3] {
    let scale = tau_max.norm() / sqrt(nodes as f64);
    [scale / accel, scale / speed, scale]
}

/// One row: returns `Ŵ·S` of the old row, and writes `Ŵ ← a Ŵ + b S`.
///
/// Explicit 4-wide vectors (`wide::f64x4`: 256-bit AVX when built for it, two
/// SSE2 registers otherwise) rather than arrays left to the autovectoriser,
/// which vectorised the ten inlined copies of this loop unevenly (some at
/// half width). Products and sums stay separate (Rust never fuses a·b + c), so
/// the results are the same on every target.
#[inline(always)]
fn dot_update<const L: usize>(w: &mut SVector<f64, L>, s: &SVector<f64, L>, a: f64, b: f64) -> f64 {
    let (w, s) = (w.as_mut_slice(), s.as_slice());
    let (av, bv) = (f64x4::splat(a), f64x4::splat(b));
    // Two independent 4-wide accumulators hide the latency of the additions.
    let (mut d0, mut d1) = (f64x4::ZERO, f64x4::ZERO);
    let mut wc = w.chunks_exact_mut(8);
    let mut sc = s.chunks_exact(8);
    for (wv, sv) in (&mut wc).zip(&mut sc) {
        let (w0, w1) = (load(&wv[..4]), load(&wv[4..]));
        let (s0, s1) = (load(&sv[..4]), load(&sv[4..]));
        d0 += w0 * s0;
        d1 += w1 * s1;
        wv[..4].copy_from_slice(&(av * w0 + bv * s0).to_array());
        wv[4..].copy_from_slice(&(av * w1 + bv * s1).to_array());
    }
    let mut dot = (d0 + d1).reduce_add();
    for (wv, &sv) in wc.into_remainder().iter_mut().zip(sc.remainder()) {
        dot += *wv * sv;
        *wv = a * *wv + b * sv;
    }
    dot
}

/// Two rows sharing the basis, each chunk of S loaded once for both: returns
/// `Ŵ0·S`, `Ŵ1·S` of the old rows and writes `Ŵr ← ar Ŵr + br S`.
#[inline(always)]
fn dot_update_pair<const L: usize>(
    w0: &mut SVector<f64, L>,
    w1: &mut SVector<f64, L>,
    s: &SVector<f64, L>,
    (a0, b0): (f64, f64),
    (a1, b1): (f64, f64),
) -> (f64, f64) {
    let (w0, w1, s) = (w0.as_mut_slice(), w1.as_mut_slice(), s.as_slice());
    let (a0v, b0v, a1v, b1v) = (
        f64x4::splat(a0),
        f64x4::splat(b0),
        f64x4::splat(a1),
        f64x4::splat(b1),
    );
    let (mut d0, mut d1) = (f64x4::ZERO, f64x4::ZERO);
    let mut c0 = w0.chunks_exact_mut(4);
    let mut c1 = w1.chunks_exact_mut(4);
    let mut cs = s.chunks_exact(4);
    for ((v0, v1), sv) in (&mut c0).zip(&mut c1).zip(&mut cs) {
        let (x0, x1, sx) = (load(v0), load(v1), load(sv));
        d0 += x0 * sx;
        d1 += x1 * sx;
        v0.copy_from_slice(&(a0v * x0 + b0v * sx).to_array());
        v1.copy_from_slice(&(a1v * x1 + b1v * sx).to_array());
    }
    let (mut r0, mut r1) = (d0.reduce_add(), d1.reduce_add());
    let rest = c0
        .into_remainder()
        .iter_mut()
        .zip(c1.into_remainder().iter_mut());
    for ((v0, v1), &sx) in rest.zip(cs.remainder()) {
        r0 += *v0 * sx;
        r1 += *v1 * sx;
        *v0 = a0 * *v0 + b0 * sx;
        *v1 = a1 * *v1 + b1 * sx;
    }
    (r0, r1)
}

/// Four lanes from a slice of exactly four.
#[inline(always)]
fn load(v: &[f64]) -> f64x4 {
    let mut a = [0.0; 4];
    a.copy_from_slice(v);
    f64x4::from(a)
}

/// One row: `Ŵ ← a Ŵ + b S`; returns `‖Ŵ‖²` of the new row.
#[inline(always)]
fn update_row<const L: usize>(w: &mut SVector<f64, L>, s: &SVector<f64, L>, a: f64, b: f64) -> f64 {
    let (w, s) = (w.as_mut_slice(), s.as_slice());
    let (av, bv) = (f64x4::splat(a), f64x4::splat(b));
    let (mut q0, mut q1) = (f64x4::ZERO, f64x4::ZERO);
    let mut wc = w.chunks_exact_mut(8);
    let mut sc = s.chunks_exact(8);
    for (wv, sv) in (&mut wc).zip(&mut sc) {
        let n0 = av * load(&wv[..4]) + bv * load(&sv[..4]);
        let n1 = av * load(&wv[4..]) + bv * load(&sv[4..]);
        q0 += n0 * n0;
        q1 += n1 * n1;
        wv[..4].copy_from_slice(&n0.to_array());
        wv[4..].copy_from_slice(&n1.to_array());
    }
    let mut sq = (q0 + q1).reduce_add();
    for (wv, &sv) in wc.into_remainder().iter_mut().zip(sc.remainder()) {
        *wv = a * *wv + b * sv;
        sq += *wv * *wv;
    }
    sq
}

impl<const N: usize, const L: usize> Weights<N, L> {
    /// All weights zero.
    pub fn zeros() -> Self {
        Self {
            d: [[SVector::zeros(); N]; N],
            c: [[SVector::zeros(); N]; N],
            g: [SVector::zeros(); N],
        }
    }

    /// Every weight finite.
    pub fn check_finite(&self) -> Result<(), Error> {
        for row in self.d.iter().flatten() {
            check::finite_slice("weights.D", row.as_slice())?;
        }
        for row in self.c.iter().flatten() {
            check::finite_slice("weights.C", row.as_slice())?;
        }
        for row in &self.g {
            check::finite_slice("weights.G", row.as_slice())?;
        }
        Ok(())
    }

    /// Frobenius norms ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F.
    pub fn norms(&self) -> [f64; 3] {
        let sq = |rows: &mut dyn Iterator<Item = &SVector<f64, L>>| {
            sqrt(rows.map(|r| r.norm_squared()).sum())
        };
        [
            sq(&mut self.d.iter().flatten()),
            sq(&mut self.c.iter().flatten()),
            sq(&mut self.g.iter()),
        ]
    }

    /// Network output `D̂ α̇1 + Ĉ α1 + Ĝ` (N m) for basis `s`, without learning.
    pub fn output(
        &self,
        s: &SVector<f64, L>,
        dalpha1: &Vector<N>,
        alpha1: &Vector<N>,
    ) -> Vector<N> {
        Vector::from_fn(|k, _| {
            let mut out = self.g[k].dot(s);
            for j in 0..N {
                out += self.d[k][j].dot(s) * dalpha1[j] + self.c[k][j].dot(s) * alpha1[j];
            }
            out
        })
    }

    /// One step of the networks in a single pass over the weights: returns the
    /// output `D̂ α̇1 + Ĉ α1 + Ĝ` (N m) with the current weights, then applies
    /// the explicit-Euler update of (15)–(17) with error signal `z2` (rad/s;
    /// ẑ2 for output feedback, (37)–(39)), the learning step scaled by `scale`
    /// (1 for the printed law).
    ///
    /// `norms` holds the Frobenius norms ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ of the weights
    /// before the step and is brought up to date without a second pass: for
    /// every row, ‖a Ŵ + b S‖² = a² ‖Ŵ‖² + 2ab (Ŵ·S) + b² ‖S‖², and Ŵ·S is the
    /// dot product the output needs anyway.
    #[inline]
    pub fn fused_step(
        &mut self,
        s: &SVector<f64, L>,
        dalpha1: &Vector<N>,
        alpha1: &Vector<N>,
        z2: &Vector<N>,
        rates: &Rates,
        norms: &mut [f64; 3],
    ) -> Vector<N> {
        let mut out = Vector::<N>::zeros();
        // Per network: Σ_rows b·(Ŵ·S) and Σ_rows b².
        let mut cross = [0.0; 3];
        let mut bb = [0.0; 3];
        let (a, g) = (rates.decay, rates.gain);
        for k in 0..N {
            let gz = z2[k];
            for j in 0..N {
                // ŴD[k][j] and ŴC[k][j] share one pass over S.
                let (bd, bc) = (g[D] * dalpha1[j] * gz, g[C] * alpha1[j] * gz);
                let (dd, dc) = dot_update_pair(
                    &mut self.d[k][j],
                    &mut self.c[k][j],
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
            let b = g[G] * gz;
            let dot = dot_update(&mut self.g[k], s, a[G], b);
            out[k] += dot;
            cross[G] += b * dot;
            bb[G] += b * b;
        }
        let s2 = s.norm_squared();
        for net in 0..3 {
            let n2 = a[net] * a[net] * norms[net] * norms[net]
                + 2.0 * a[net] * cross[net]
                + s2 * bb[net];
            // Rounding can take an exact zero a hair below it.
            norms[net] = sqrt(n2.max(0.0));
        }
        out
    }
}

impl<const N: usize, const L: usize> Weights<N, L> {
    /// The explicit-Euler update of (15)–(17) alone (after [`output`](Self::output)
    /// has used the old weights). Rows of joint k learn from `z2[k]`; pass
    /// 0 there to freeze joint k's learning (its weights then only leak).
    /// Returns the Frobenius norms of the new weights.
    pub fn update(
        &mut self,
        s: &SVector<f64, L>,
        dalpha1: &Vector<N>,
        alpha1: &Vector<N>,
        z2: &Vector<N>,
        rates: &Rates,
    ) -> [f64; 3] {
        let mut sq = [0.0; 3];
        let gain = rates.gain;
        for k in 0..N {
            let gz = z2[k];
            for j in 0..N {
                sq[D] += update_row(
                    &mut self.d[k][j],
                    s,
                    rates.decay[D],
                    gain[D] * dalpha1[j] * gz,
                );
                sq[C] += update_row(
                    &mut self.c[k][j],
                    s,
                    rates.decay[C],
                    gain[C] * alpha1[j] * gz,
                );
            }
            sq[G] += update_row(&mut self.g[k], s, rates.decay[G], gain[G] * gz);
        }
        sq.map(sqrt)
    }

    /// Multiply every weight of network `net` ([`D`], [`C`] or [`G`]) by `factor`.
    pub fn scale_network(&mut self, net: usize, factor: f64) {
        let rows: &mut dyn Iterator<Item = &mut SVector<f64, L>> = match net {
            D => &mut self.d.iter_mut().flatten(),
            C => &mut self.c.iter_mut().flatten(),
            _ => &mut self.g.iter_mut(),
        };
        for row in rows {
            *row *= factor;
        }
    }
}

impl<const N: usize, const L: usize> Default for Weights<N, L> {
    fn default() -> Self {
        Self::zeros()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn basis() -> SVector<f64, 16> {
        SVector::from_fn(|i, _| 0.1 + 0.05 * i as f64)
    }

    #[test]
    fn fused_step_equals_output_then_euler_update() {
        let mut w = Weights::<1, 16>::zeros();
        // Some non-zero weights.
        for (i, v) in w.d[0][0].iter_mut().enumerate() {
            *v = 0.01 * i as f64;
        }
        w.c[0][0].fill(-0.2);
        w.g[0].fill(0.3);
        let s = basis();
        let (da, a, z2) = (
            Vector::<1>::new(2.0),
            Vector::<1>::new(-0.5),
            Vector::<1>::new(0.1),
        );
        let ts = 1e-3;
        let (gamma, sigma) = ([100.0; 3], [0.01; 3]);
        let rates = Rates::new(ts, gamma, sigma).unwrap();
        let expect_out = w.output(&s, &da, &a);
        let expect_norms = w.norms();
        // The SPEC's form: Ŵ ← Ŵ + Ts Γ (S u z2 − σ Ŵ).
        let mut expect_w = w.clone();
        for i in 0..16 {
            expect_w.d[0][0][i] += ts * gamma[D] * (s[i] * da[0] * z2[0] - sigma[D] * w.d[0][0][i]);
            expect_w.c[0][0][i] += ts * gamma[C] * (s[i] * a[0] * z2[0] - sigma[C] * w.c[0][0][i]);
            expect_w.g[0][i] += ts * gamma[G] * (s[i] * z2[0] - sigma[G] * w.g[0][i]);
        }
        let mut w2 = w.clone();
        let mut norms = expect_norms;
        let out = w.fused_step(&s, &da, &a, &z2, &rates, &mut norms);
        // The separate update does the same.
        let new_norms = w2.update(&s, &da, &a, &z2, &rates);
        assert_eq!(w2, w);
        assert!((out - expect_out).norm() < 1e-14, "{out} vs {expect_out}");
        // The norms were brought up to date without a second pass.
        let exact = w.norms();
        for n in 0..3 {
            assert!(
                (norms[n] - exact[n]).abs() < 1e-13 * exact[n],
                "{norms:?} vs {exact:?}"
            );
            assert!((new_norms[n] - exact[n]).abs() < 1e-13 * exact[n]);
        }
        for i in 0..16 {
            assert!((w.d[0][0][i] - expect_w.d[0][0][i]).abs() < 1e-15);
            assert!((w.c[0][0][i] - expect_w.c[0][0][i]).abs() < 1e-15);
            assert!((w.g[0][i] - expect_w.g[0][i]).abs() < 1e-15);
        }
    }

    #[test]
    fn rates_reject_nonpositive_gain_by_name() {
        let e = Rates::new(1e-3, [100.0, 0.0, 100.0], [0.01; 3]).unwrap_err();
        assert!(e.to_string().contains("Γ > 0"), "{e}");
        let e = Rates::new(1e-3, [100.0; 3], [0.01, 0.01, -1.0]).unwrap_err();
        assert!(e.to_string().contains("σ > 0"), "{e}");
    }
}
