//! Gaussian RBF bases S(Z), (1), SPEC §6, as two types behind one trait.
//!
//! The network input is `Z = [x; v; α1; α̇1] ∈ R^{4N}`, passed as four blocks
//! of `N`. One basis is shared by the three networks D̂, Ĉ, Ĝ (ZD = ZC = ZG).
//!
//! - [`Grid`]: the paper's `L = 2^{4N}` centres at the vertices of
//!   `[−1, 1]^{4N}`, one width η², evaluated by a separable fast path. It
//!   exists for N ≤ 3 (4096 nodes); beyond, 2^{4N} nodes are not a basis one
//!   can store (2^28 at N = 7).
//! - [`Centers`]: user-chosen centres, held in any `AsRef<[f64]>` (a `Vec` or
//!   `Box<[f64]>` on the heap, or a borrowed slice), with one width per input
//!   dimension, since x, ẋ, α1 and α̇1 have different units:
//!   `S_j(Z) = exp(−Σ_d (Z_d − μ_jd)² / η_d²)`.
//!
//! ## Node order of the vertex grid
//!
//! Node `j` has `μ_j[d] = +1` if bit `d` of `j` is set and `−1` otherwise,
//! where `d = b·N + i` indexes component `i` of block `b` (b = 0: x, 1: v,
//! 2: α1, 3: α̇1).
//!
//! ## The separable fast path
//!
//! On the grid, ‖Z − μ_j‖² = Σ_d (|Z_d| − 1)² + Σ_{d far} 4|Z_d|, where "far"
//! are the dimensions in which μ_j has the opposite sign of Z_d. Hence
//! `S_j = exp(−Σ_d (|Z_d| − 1)²/η²) · Π_{d far} r_d` with `r_d = exp(−4|Z_d|/η²)`:
//! 4N + 1 exponentials instead of L, all of non-positive arguments (no
//! overflow for any finite Z), and the L products built by doubling, L − 1
//! multiplications in all.

use crate::error::{check, Error};
use crate::math::exp;
use crate::trajectory::Setpoint;
use crate::types::{grid_nodes, Vector};

/// A basis S(Z) ∈ R^L over the network input Z = [x; v; α1; α̇1].
pub trait Basis<const N: usize> {
    /// The number of nodes L.
    fn nodes(&self) -> usize;
    /// Evaluate S(Z) into `s` (length [`nodes`](Self::nodes)); `z` = [x, v, α1, α̇1].
    /// Allocation-free; every S_j in [0, 1] for finite `z`.
    fn eval(&self, z: &[Vector<N>; 4], s: &mut [f64]);
}

/// A width η² ≥ 1e-12 (in the squared unit of its dimension): below, 1/η²
/// overflows and S_j = exp(−0 · ∞) is NaN at a centre (found by fuzzing).
fn check_width(what: &'static str, eta2: f64) -> Result<(), Error> {
    if eta2 >= 1e-12 {
        Ok(())
    } else {
        Err(Error::Condition {
            condition: "η² ≥ 1e-12",
            lhs: what,
            index: None,
            value: eta2,
        })
    }
}

/// The largest N for which the vertex grid exists here (2^{4·3} = 4096 nodes).
pub const GRID_MAX_JOINTS: usize = 3;

/// The paper's vertex grid of `L = 2^{4N}` nodes with width η², SPEC §6.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Grid<const N: usize> {
    eta2: f64,
    inv_eta2: f64,
}

impl<const N: usize> Grid<N> {
    /// The grid with width η² (the paper's "variance 25" is η² = 25). Errors if
    /// η² is not > 0, or for N > [`GRID_MAX_JOINTS`] (use [`Centers`]).
    pub fn new(eta2: f64) -> Result<Self, Error> {
        if N == 0 || N > GRID_MAX_JOINTS {
            return Err(Error::Invalid {
                what: "RBF vertex grid",
                reason: "the grid has 2^(4n) nodes and exists for 1 ≤ n ≤ 3; use user centres",
            });
        }
        check::positive("η² > 0", "eta2", eta2)?;
        check_width("eta2", eta2)?;
        Ok(Self {
            eta2,
            inv_eta2: 1.0 / eta2,
        })
    }

    /// The width η² (squared distance units of Z).
    pub fn eta2(&self) -> f64 {
        self.eta2
    }

    /// Centre μ_j as four blocks (x, v, α1, α̇1). Panics if `j >= L`.
    pub fn center(&self, j: usize) -> [Vector<N>; 4] {
        assert!(j < grid_nodes(N), "node index {j} out of range");
        core::array::from_fn(|b| {
            Vector::from_fn(|i, _| {
                if (j >> (b * N + i)) & 1 == 1 {
                    1.0
                } else {
                    -1.0
                }
            })
        })
    }

    /// The same basis with its centres stored explicitly (evaluated node by
    /// node): the reference the fast path is tested against.
    #[cfg(feature = "alloc")]
    pub fn to_centers(&self) -> Centers<N, alloc::vec::Vec<f64>> {
        let mut c = alloc::vec::Vec::with_capacity(grid_nodes(N) * 4 * N);
        for j in 0..grid_nodes(N) {
            for block in self.center(j) {
                c.extend_from_slice(block.as_slice());
            }
        }
        Centers {
            quads: quads(&c, 4 * N),
            centers: c,
            nodes: grid_nodes(N),
            inv_w2: [Vector::from_element(self.inv_eta2); 4],
            active: [true; 4],
        }
    }
}

impl<const N: usize> Basis<N> for Grid<N> {
    fn nodes(&self) -> usize {
        grid_nodes(N)
    }

    // Inlined into the controller's weight-pass path
    // (`SimdPath::eval_basis`), so the doubling loops compile for AVX2 when
    // the CPU has it (callgrind: ~170 instructions fewer per step).
    #[inline(always)]
    fn eval(&self, z: &[Vector<N>; 4], s: &mut [f64]) {
        let inv = self.inv_eta2;
        let comps = || z.iter().flat_map(|b| b.iter().copied());
        // Distance to the nearest vertex: Σ_d (|Z_d| − 1)².
        let near: f64 = comps().map(|zd| (zd.abs() - 1.0) * (zd.abs() - 1.0)).sum();
        s[0] = exp(-near * inv);
        // Doubling over dimensions d: nodes with bit d clear take the factor for
        // μ_d = −1, nodes with it set the factor for μ_d = +1; the far one is r_d.
        let mut len = 1;
        for zd in comps() {
            let r = exp(-4.0 * zd.abs() * inv);
            let (lo, hi) = s[..2 * len].split_at_mut(len);
            if zd >= 0.0 {
                // μ_d = +1 is near: bit set keeps the value, bit clear takes r.
                hi.copy_from_slice(lo);
                lo.iter_mut().for_each(|v| *v *= r);
            } else {
                hi.iter_mut().zip(lo.iter()).for_each(|(h, &l)| *h = l * r);
            }
            len *= 2;
        }
    }
}

/// User-chosen centres with a width per input dimension.
///
/// `centers` holds L rows of 4N coordinates, node j's at
/// `[j·4N, (j+1)·4N)`, in the order x (rad), v (rad/s), α1 (rad/s), α̇1
/// (rad/s²), N each. `S_j(Z) = exp(−Σ_d (Z_d − μ_jd)² / η_d²)` with η_d² the
/// width of dimension d in that dimension's squared unit.
///
/// A width η_d² = +∞ leaves dimension d out of the distance (1/η_d² = 0):
/// the basis then does not depend on that input, as in the per-network
/// inputs of Ge, Lee & Harris (ZD = ZG = q, ZC = [q; q̇]; SPEC §15). A block
/// whose widths are all infinite is skipped by [`eval`](Basis::eval).
#[derive(Clone, Debug, PartialEq)]
pub struct Centers<const N: usize, C> {
    centers: C,
    nodes: usize,
    inv_w2: [Vector<N>; 4],
    /// The blocks with at least one finite width (the others add nothing).
    active: [bool; 4],
    /// The centres of the first ⌊L/4⌋·4 nodes by groups of four, coordinate
    /// by coordinate (group g: μ_{4g..4g+4, d} for d = 0, 1, …): the
    /// evaluation takes four nodes per pass over Z, lane by lane, each node's
    /// sum in the order of the row-major one (the same bits). With a heap only.
    #[cfg(feature = "alloc")]
    quads: alloc::vec::Vec<f64>,
}

/// The centres `c` (rows of `width` coordinates) of the first ⌊L/4⌋·4 nodes
/// by groups of four, coordinate by coordinate ([`Centers`]' `quads`).
#[cfg(feature = "alloc")]
fn quads(c: &[f64], width: usize) -> alloc::vec::Vec<f64> {
    let groups = c.len() / width / 4;
    let mut out = alloc::vec::Vec::with_capacity(groups * 4 * width);
    for g in 0..groups {
        for d in 0..width {
            for l in 0..4 {
                out.push(c[(4 * g + l) * width + d]);
            }
        }
    }
    out
}

impl<const N: usize, C: AsRef<[f64]>> Centers<N, C> {
    /// Centres `centers` (length L·4N, L ≥ 1, finite) with widths η_d² per
    /// input dimension, `widths2[b][i]` for block b (x, v, α1, α̇1) and joint i,
    /// each > 0 and either finite (≥ 1e-12) or +∞ (the dimension is left
    /// out; at least one width must be finite).
    pub fn new(centers: C, widths2: [Vector<N>; 4]) -> Result<Self, Error> {
        let len = centers.as_ref().len();
        if N == 0 || len == 0 || len % (4 * N) != 0 {
            return Err(Error::Invalid {
                what: "RBF centres",
                reason: "need L ≥ 1 rows of 4n coordinates (x, v, α1, α̇1)",
            });
        }
        check::finite_slice("centers", centers.as_ref())?;
        for w in &widths2 {
            // +∞ is the one non-finite width allowed: check the rest.
            let finite = w.map(|x| if x == f64::INFINITY { 1.0 } else { x });
            check::positive_vec("η² > 0", "widths", &finite)?;
            for &x in finite.iter() {
                check_width("widths", x)?;
            }
        }
        let inv_w2 = widths2.map(|w| w.map(|v| 1.0 / v));
        let active = inv_w2.map(|w| w.iter().any(|v| *v > 0.0));
        if !active.iter().any(|a| *a) {
            return Err(Error::Invalid {
                what: "RBF widths",
                reason: "every width is infinite: the basis would be constant",
            });
        }
        Ok(Self {
            nodes: len / (4 * N),
            #[cfg(feature = "alloc")]
            quads: quads(centers.as_ref(), 4 * N),
            centers,
            inv_w2,
            active,
        })
    }

    /// Centres with one width η² for every dimension (as the paper's grid).
    pub fn uniform(centers: C, eta2: f64) -> Result<Self, Error> {
        check::positive("η² > 0", "eta2", eta2)?;
        Self::new(centers, [Vector::from_element(eta2); 4])
    }

    /// The centres, L rows of 4N coordinates.
    pub fn centers(&self) -> &[f64] {
        self.centers.as_ref()
    }

    /// The widths η_d² per block and joint.
    pub fn widths2(&self) -> [Vector<N>; 4] {
        self.inv_w2.map(|w| w.map(|v| 1.0 / v))
    }
}

impl<const N: usize, C: AsRef<[f64]>> Basis<N> for Centers<N, C> {
    fn nodes(&self) -> usize {
        self.nodes
    }

    // Inlined into the controller's instruction-set dispatch, as the grid's.
    #[inline(always)]
    fn eval(&self, z: &[Vector<N>; 4], s: &mut [f64]) {
        let c = self.centers.as_ref();
        // Four nodes per pass over Z from the grouped centres: each lane's
        // sum term by term as the pairs' below (the same bits), the four
        // lanes one vector operation where the path has them.
        #[cfg(feature = "alloc")]
        let (s, c) = {
            let groups = s.len().min(self.nodes) / 4;
            for (sg, mg) in s
                .chunks_exact_mut(4)
                .zip(self.quads.chunks_exact(16 * N))
                .take(groups)
            {
                let mut acc = [0.0f64; 4];
                for (b, (zb, wb)) in z.iter().zip(&self.inv_w2).enumerate() {
                    if !self.active[b] {
                        continue;
                    }
                    let block = &mg[4 * b * N..4 * (b + 1) * N];
                    for ((zi, wi), m) in zb.iter().zip(wb.iter()).zip(block.chunks_exact(4)) {
                        for l in 0..4 {
                            let e = zi - m[l];
                            acc[l] += e * e * wi;
                        }
                    }
                }
                for l in 0..4 {
                    sg[l] = exp(-acc[l]);
                }
            }
            (&mut s[4 * groups..], &c[16 * N * groups..])
        };
        // Σ_d (Z_d − μ_jd)² / η_d² over the active blocks, in order: one
        // bounds check per block (not per term), two nodes per iteration
        // sharing each Z_d and 1/η_d² (each node's sum is the same bits).
        let mut pairs = s.chunks_exact_mut(2).zip(c.chunks_exact(8 * N));
        for (sj, mu) in &mut pairs {
            let (m0, m1) = mu.split_at(4 * N);
            let (mut d0, mut d1) = (0.0, 0.0);
            for (b, (zb, wb)) in z.iter().zip(&self.inv_w2).enumerate() {
                if !self.active[b] {
                    continue;
                }
                let terms = zb.iter().zip(wb.iter());
                let blocks = m0[b * N..(b + 1) * N].iter().zip(&m1[b * N..(b + 1) * N]);
                for ((zi, wi), (u0, u1)) in terms.zip(blocks) {
                    let (e0, e1) = (zi - u0, zi - u1);
                    d0 += e0 * e0 * wi;
                    d1 += e1 * e1 * wi;
                }
            }
            sj[0] = exp(-d0);
            sj[1] = exp(-d1);
        }
        // The node left over (L odd), as each of a pair.
        let done = s.len().min(c.len() / (4 * N)) / 2 * 2;
        for (sj, mu) in s[done..]
            .iter_mut()
            .zip(c[done * 4 * N..].chunks_exact(4 * N))
        {
            let mut d2 = 0.0;
            for (b, (zb, wb)) in z.iter().zip(&self.inv_w2).enumerate() {
                if !self.active[b] {
                    continue;
                }
                for ((zi, wi), mi) in zb.iter().zip(wb.iter()).zip(&mu[b * N..(b + 1) * N]) {
                    let e = zi - mi;
                    d2 += e * e * wi;
                }
            }
            *sj = exp(-d2);
        }
    }
}

/// The most nodes [`Centers::lattice`] builds (as many as the grid at n = 3).
pub const LATTICE_MAX_NODES: usize = 4096;

/// The overlap factor ρ of [`Centers::along`]: each width is at least ρ times
/// the largest spacing of neighbouring centres, so that S_j of a neighbour is
/// ≥ exp(−1/ρ²) at a centre and the sum of the basis along the orbit varies
/// by under 12 % (ρ = 2: exp(−1/4) = 0.78 at the neighbour, 0.88 halfway).
pub const ALONG_OVERLAP: f64 = 2.0;

impl<const N: usize, C: AsRef<[f64]> + AsMut<[f64]>> Centers<N, C> {
    /// Centres along an orbit, in the caller's buffer `buf` (length L·4N for
    /// L = `samples.len()`), SPEC §15: deterministic learning (Wang & Hill,
    /// *Deterministic Learning Theory for Identification, Recognition, and
    /// Control*, CRC 2009, ch. 3) places the centres where the network input
    /// goes, along the periodic orbit, and only those neurons learn.
    ///
    /// Node j is centred at `[q_j; q̇_j]` of sample j (the joint reference's
    /// xc, ẋc); the network inputs α1, α̇1 are left out (width +∞), since
    /// the networks multiply them outside (D̂ α̇1, Ĉ α1) and D, C, G depend
    /// on q and q̇ only (Ge, Lee & Harris 1998, ch. 3: ZD = ZG = q, ZC = [q; q̇]).
    /// Widths, per block b (x: rad, v: rad/s), with the largest spacing
    /// `h_b = max_j ‖μ_{j+1,b} − μ_{j,b}‖` of consecutive samples:
    /// `η_b = max(ρ h_b, tube_b)` ([`ALONG_OVERLAP`] ρ = 2), the same for
    /// each joint: `tube` = [rad, rad/s] is how far from the orbit the
    /// networks should still act (compliant deflection, transients), finite
    /// and > 0.
    pub fn along_in(buf: C, samples: &[Setpoint<N>], tube: [f64; 2]) -> Result<Self, Error> {
        Self::along_spaced(buf, samples, tube, false)
    }

    /// [`along_in`](Self::along_in) for the samples of one period of a
    /// periodic orbit: the spacing h_b also counts the step from the last
    /// sample back to the first (the orbit closes on itself).
    pub fn along_periodic_in(
        buf: C,
        samples: &[Setpoint<N>],
        tube: [f64; 2],
    ) -> Result<Self, Error> {
        Self::along_spaced(buf, samples, tube, true)
    }

    fn along_spaced(
        buf: C,
        samples: &[Setpoint<N>],
        tube: [f64; 2],
        closed: bool,
    ) -> Result<Self, Error> {
        let mut buf = buf;
        check::positive("tube > 0", "tube", tube[0])?;
        check::positive("tube > 0", "tube", tube[1])?;
        let rows = buf.as_mut();
        if N == 0 || samples.is_empty() || rows.len() != samples.len() * 4 * N {
            return Err(Error::Invalid {
                what: "RBF centres along an orbit",
                reason: "need L ≥ 1 samples and a buffer of L·4n reals",
            });
        }
        let mut h = [0.0f64; 2];
        for (j, sp) in samples.iter().enumerate() {
            check::finite_slice("samples", sp.x.as_slice())?;
            check::finite_slice("samples", sp.dx.as_slice())?;
            let row = &mut rows[j * 4 * N..(j + 1) * 4 * N];
            row[..N].copy_from_slice(sp.x.as_slice());
            row[N..2 * N].copy_from_slice(sp.dx.as_slice());
            row[2 * N..].fill(0.0);
            let next = match samples.get(j + 1) {
                Some(next) => Some(next),
                None if closed => samples.first(),
                None => None,
            };
            if let Some(next) = next {
                h[0] = h[0].max((next.x - sp.x).norm());
                h[1] = h[1].max((next.dx - sp.dx).norm());
            }
        }
        let eta = |b: usize| {
            let w = (ALONG_OVERLAP * h[b]).max(tube[b]);
            Vector::<N>::from_element(w * w)
        };
        let inf = Vector::<N>::from_element(f64::INFINITY);
        Self::new(buf, [eta(0), eta(1), inf, inf])
    }

    /// A lattice over the joint positions, in the caller's buffer `buf`
    /// (length `points^N · 4N`), SPEC §15: `points` ≥ 2 nodes per joint,
    /// evenly from `lo` to `hi` (rad, lo < hi), `L = points^N ≤ 4096`, each
    /// width the mesh spacing, η_i = (hi_i − lo_i)/(points − 1) (Sanner &
    /// Slotine, "Gaussian networks for direct adaptive control", IEEE TNN
    /// 3(6), 1992: a regular lattice with widths of the order of the mesh).
    /// Only q enters (ZD = ZG = q, Ge, Lee & Harris 1998): the other blocks
    /// have width +∞, so Ĉ is a function of q alone, which suits slow motions.
    /// Node j's joint i takes level `(j / points^i) % points`.
    pub fn lattice_in(
        buf: C,
        lo: &Vector<N>,
        hi: &Vector<N>,
        points: usize,
    ) -> Result<Self, Error> {
        let mut buf = buf;
        check::finite_slice("lo", lo.as_slice())?;
        check::finite_slice("hi", hi.as_slice())?;
        check::each("hi > lo", "hi − lo", &(hi - lo), |_, d| d, true)?;
        let nodes = lattice_nodes(N, points).ok_or(Error::Invalid {
            what: "RBF lattice",
            reason: "needs points ≥ 2 and L = points^n ≤ 4096 (use centres along the orbit)",
        })?;
        let rows = buf.as_mut();
        if rows.len() != nodes * 4 * N {
            return Err(Error::Invalid {
                what: "RBF lattice",
                reason: "needs a buffer of points^n · 4n reals",
            });
        }
        let step = (hi - lo) / (points - 1) as f64;
        for (j, row) in rows.chunks_exact_mut(4 * N).enumerate() {
            let mut rest = j;
            for i in 0..N {
                row[i] = lo[i] + (rest % points) as f64 * step[i];
                rest /= points;
            }
            row[N..].fill(0.0);
        }
        let inf = Vector::<N>::from_element(f64::INFINITY);
        Self::new(buf, [step.component_mul(&step), inf, inf, inf])
    }
}

/// `points^n` if points ≥ 2 and it is at most [`LATTICE_MAX_NODES`].
pub fn lattice_nodes(n: usize, points: usize) -> Option<usize> {
    if points < 2 {
        return None;
    }
    let mut l = 1usize;
    for _ in 0..n {
        l = l.checked_mul(points).filter(|l| *l <= LATTICE_MAX_NODES)?;
    }
    Some(l)
}

#[cfg(feature = "alloc")]
impl<const N: usize> Centers<N, alloc::vec::Vec<f64>> {
    /// [`along_in`](Centers::along_in) on the heap: one node per sample.
    pub fn along(samples: &[Setpoint<N>], tube: [f64; 2]) -> Result<Self, Error> {
        Self::along_in(alloc::vec![0.0; samples.len() * 4 * N], samples, tube)
    }

    /// [`along_periodic_in`](Centers::along_periodic_in) on the heap.
    pub fn along_periodic(samples: &[Setpoint<N>], tube: [f64; 2]) -> Result<Self, Error> {
        Self::along_periodic_in(alloc::vec![0.0; samples.len() * 4 * N], samples, tube)
    }

    /// [`lattice_in`](Centers::lattice_in) on the heap.
    pub fn lattice(lo: &Vector<N>, hi: &Vector<N>, points: usize) -> Result<Self, Error> {
        let nodes = lattice_nodes(N, points).unwrap_or(0);
        Self::lattice_in(alloc::vec![0.0; nodes * 4 * N], lo, hi, points)
    }
}

/// Either basis, chosen at run time (feature `alloc`): for bindings that
/// take the paper's grid or user centres from their caller.
#[cfg(feature = "alloc")]
#[derive(Clone, Debug, PartialEq)]
pub enum AnyBasis<const N: usize> {
    /// The paper's vertex grid.
    Grid(Grid<N>),
    /// User centres on the heap.
    Centers(Centers<N, alloc::vec::Vec<f64>>),
}

#[cfg(feature = "alloc")]
impl<const N: usize> Basis<N> for AnyBasis<N> {
    fn nodes(&self) -> usize {
        match self {
            AnyBasis::Grid(g) => g.nodes(),
            AnyBasis::Centers(c) => c.nodes(),
        }
    }

    #[inline]
    fn eval(&self, z: &[Vector<N>; 4], s: &mut [f64]) {
        match self {
            AnyBasis::Grid(g) => g.eval(z, s),
            AnyBasis::Centers(c) => c.eval(z, s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn z_of(v: [f64; 8]) -> [Vector<2>; 4] {
        core::array::from_fn(|b| Vector::<2>::new(v[2 * b], v[2 * b + 1]))
    }

    #[test]
    fn zero_input_gives_exp_minus_8_over_25_everywhere() {
        let rbf = Grid::<2>::new(25.0).unwrap();
        let mut s = [0.0; 256];
        rbf.eval(&z_of([0.0; 8]), &mut s);
        let expect = (-8.0f64 / 25.0).exp();
        for &v in s.iter() {
            assert!((v - expect).abs() < 1e-15, "{v} vs {expect}");
        }
    }

    #[test]
    fn input_on_a_vertex_gives_one_there() {
        let rbf = Grid::<2>::new(25.0).unwrap();
        let mut s = [0.0; 256];
        // Z = μ_j for j = 0b1010_0110.
        let j = 0b1010_0110usize;
        let mu = rbf.center(j);
        rbf.eval(&mu, &mut s);
        assert!((s[j] - 1.0).abs() < 1e-15);
        // Its opposite vertex is at distance² 4·8 = 32.
        assert!((s[255 - j] - (-32.0f64 / 25.0).exp()).abs() < 1e-15);
    }

    #[test]
    fn fast_grid_path_equals_direct_evaluation() {
        let grid = Grid::<2>::new(25.0).unwrap();
        let direct = grid.to_centers();
        assert_eq!(direct.nodes(), 256);
        let inputs = [
            [0.3, -0.2, 1.5, -4.0, 0.0, 2.5, -0.7, 11.0],
            [-1.0, 1.0, 0.0, -0.0, 3.0, -3.0, 0.5, -0.5],
            [40.0, -60.0, 0.1, 0.2, -90.0, 5.0, 7.0, -1e3],
        ];
        let (mut a, mut b) = ([0.0; 256], [0.0; 256]);
        for v in inputs {
            grid.eval(&z_of(v), &mut a);
            direct.eval(&z_of(v), &mut b);
            for j in 0..256 {
                let tol = 1e-13 * b[j].abs() + 1e-300;
                assert!((a[j] - b[j]).abs() <= tol, "node {j}: {} vs {}", a[j], b[j]);
            }
        }
    }

    #[test]
    fn grouped_nodes_give_each_node_its_own_sum_bit_for_bit() {
        // L = 11: two groups of four, a pair and one node left over; a block
        // left out (infinite widths) and one infinite width inside a block.
        const L: usize = 11;
        let c: [f64; L * 8] = core::array::from_fn(|i| ((i * 37 % 101) as f64 - 50.0) / 17.0);
        let mut w = [Vector::<2>::new(0.7, 1.3); 4];
        w[1] = Vector::<2>::from_element(f64::INFINITY);
        w[3] = Vector::<2>::new(2.5, f64::INFINITY);
        let basis = Centers::<2, &[f64]>::new(&c[..], w).unwrap();
        let z = z_of([0.3, -1.2, 4.0, -0.5, 0.9, 0.0, -2.2, 1.7]);
        let mut s = [0.0; L];
        basis.eval(&z, &mut s);
        let inv = w.map(|b| b.map(|v| 1.0 / v));
        for (j, sj) in s.iter().enumerate() {
            let mut d = 0.0;
            for b in [0, 2, 3] {
                for i in 0..2 {
                    let e = z[b][i] - c[j * 8 + b * 2 + i];
                    d += e * e * inv[b][i];
                }
            }
            assert_eq!(sj.to_bits(), exp(-d).to_bits(), "node {j}");
        }
    }

    #[test]
    fn widths_per_dimension_scale_each_dimension() {
        // One node at the origin of R^4 (N = 1); widths 1, 4, 9, 16.
        let w = [1.0, 4.0, 9.0, 16.0].map(Vector::<1>::new);
        let c = Centers::<1, _>::new([0.0; 4], w).unwrap();
        let mut s = [0.0];
        c.eval(&[1.0, 2.0, 3.0, 4.0].map(Vector::<1>::new), &mut s);
        assert!((s[0] - (-4.0f64).exp()).abs() < 1e-15, "{}", s[0]);
        // Borrowed centres work as well as owned ones.
        let owned = [0.5; 8];
        let b = Centers::<1, &[f64]>::uniform(&owned[..], 2.0).unwrap();
        assert_eq!(b.nodes(), 2);
    }

    #[test]
    fn huge_inputs_underflow_to_zero_without_nan() {
        let rbf = Grid::<2>::new(25.0).unwrap();
        let mut s = [0.0; 256];
        rbf.eval(
            &z_of([1e200, -1e200, 1e300, 0.0, 0.0, 0.0, 0.0, 0.0]),
            &mut s,
        );
        assert!(s.iter().all(|v| *v == 0.0));
    }

    #[test]
    fn lattice_and_orbit_bases_follow_their_rules() {
        let lo = Vector::<2>::new(-1.0, 0.0);
        let hi = Vector::<2>::new(1.0, 0.5);
        let l = Centers::<2, _>::lattice(&lo, &hi, 3).unwrap();
        assert_eq!(l.nodes(), 9);
        // Node 5 = level 2 of joint 1, level 1 of joint 2.
        assert_eq!(&l.centers()[5 * 8..5 * 8 + 2], &[1.0, 0.25]);
        let w = l.widths2();
        assert_eq!((w[0][0], w[0][1]), (1.0, 0.0625));
        assert!(w[1..].iter().all(|b| b.iter().all(|x| *x == f64::INFINITY)));
        // Only q enters: v, α1, α̇1 change nothing.
        let (mut a, mut b) = ([0.0; 9], [0.0; 9]);
        let q = Vector::<2>::new(0.3, 0.1);
        l.eval(
            &[q, Vector::zeros(), Vector::zeros(), Vector::zeros()],
            &mut a,
        );
        l.eval(
            &[
                q,
                Vector::from_element(9.0),
                Vector::from_element(-7.0),
                Vector::from_element(1e3),
            ],
            &mut b,
        );
        assert_eq!(a, b);
        let e =
            Centers::<7, _>::lattice(&Vector::zeros(), &Vector::from_element(1.0), 4).unwrap_err();
        assert!(e.to_string().contains("4096"), "{e}");
        let e = Centers::<2, _>::lattice(&hi, &lo, 2).unwrap_err();
        assert!(e.to_string().contains("hi > lo"), "{e}");

        // Along an orbit: the widths are ρ times the largest spacing, or the tube.
        let samples: alloc::vec::Vec<_> = (0..4)
            .map(|j| Setpoint {
                x: Vector::<2>::new(0.1 * j as f64, 0.0),
                dx: Vector::<2>::new(0.0, 1.0),
                ddx: Vector::zeros(),
            })
            .collect();
        let c = Centers::along(&samples, [0.05, 0.5]).unwrap();
        let w = c.widths2();
        assert!((w[0][0] - 0.04).abs() < 1e-15, "{w:?}"); // (2 · 0.1)²
        assert_eq!(w[1][1], 0.25); // the tube: no spacing in v
        assert_eq!(w[3][0], f64::INFINITY);
        // A periodic orbit also counts the way back from the last sample to the first.
        let p = Centers::along_periodic(&samples, [0.05, 0.5]).unwrap();
        assert!(
            (p.widths2()[0][0] - 0.36).abs() < 1e-15,
            "{:?}",
            p.widths2()
        ); // (2 · 0.3)²
        let mut s = [0.0; 4];
        c.eval(
            &[
                samples[2].x,
                samples[2].dx,
                Vector::zeros(),
                Vector::from_element(5.0),
            ],
            &mut s,
        );
        assert_eq!(s[2], 1.0);
        assert!((s[1] - (-0.25f64).exp()).abs() < 1e-15, "{s:?}");
        let e = Centers::<2, _>::along(&samples, [0.0, 1.0]).unwrap_err();
        assert!(e.to_string().contains("tube > 0"), "{e}");
        let e =
            Centers::<1, _>::new([0.0; 4], [Vector::from_element(f64::INFINITY); 4]).unwrap_err();
        assert!(e.to_string().contains("every width is infinite"), "{e}");
    }

    #[test]
    fn bad_grids_and_centres_are_rejected_by_name() {
        assert!(Grid::<4>::new(25.0).is_err());
        assert!(Grid::<1>::new(25.0).is_ok());
        let e = Grid::<2>::new(0.0).unwrap_err();
        assert!(e.to_string().contains("η² > 0"), "{e}");
        let e = Centers::<2, _>::uniform([0.0; 7], 1.0).unwrap_err();
        assert!(e.to_string().contains("rows of 4n"), "{e}");
        let e = Centers::<1, _>::uniform([0.0, f64::NAN, 0.0, 0.0], 1.0).unwrap_err();
        assert!(e.to_string().starts_with("centers[1]"), "{e}");
    }
}
