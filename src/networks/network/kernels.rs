//! The weight pass's kernels on explicit SIMD lanes (pulp): the dot products
//! and the leakage updates of SPEC (6), over groups of lanes and the rest
//! real by real, the same sums on every path.

use super::*;

/// The vectors of `w` and `s` (equal lengths) in groups of `2 · G` reals
/// (`G = S::F64_LANES`, 4 on both paths), and the rest, which the kernels sum
/// and update real by real, on every path alike.
#[inline(always)]
#[allow(clippy::type_complexity)]
pub(super) fn groups_mut<'w, 's, S: Simd>(
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
pub(super) fn for_groups<'w, 's, S: Simd>(
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
pub(super) fn dot_update<S: Simd>(simd: S, w: &mut [f64], s: &[f64], a: f64, b: f64) -> f64 {
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
pub(super) fn dot_update_pair<S: Simd>(
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
pub(super) fn update_row<S: Simd>(simd: S, w: &mut [f64], s: &[f64], a: f64, b: f64) -> f64 {
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
pub(super) fn dot_rows<S: Simd, const R: usize>(simd: S, rows: [&[f64]; R], s: &[f64]) -> [f64; R] {
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
pub(super) fn update_pair<S: Simd>(
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
