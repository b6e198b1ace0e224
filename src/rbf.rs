//! Gaussian RBF basis S(Z), (1), SPEC §6.
//!
//! `S_j(Z) = exp(−‖Z − μ_j‖² / η²)`, j = 1..L, with the network input
//! `Z = [x; v; α1; α̇1] ∈ R^{4N}` passed as four blocks of `N`. One basis is
//! shared by the three networks D̂, Ĉ, Ĝ (ZD = ZC = ZG).
//!
//! ## Node order of the vertex grid
//!
//! The paper's grid puts the `L = 2^{4N}` centres at the vertices of
//! `[−1, 1]^{4N}`. Node `j` has `μ_j[d] = +1` if bit `d` of `j` is set and
//! `−1` otherwise, where `d = b·N + i` indexes component `i` of block `b`
//! (b = 0: x, 1: v, 2: α1, 3: α̇1).
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
use crate::{grid_nodes, Vector};
use nalgebra::{SMatrix, SVector};

/// Where the centres are.
#[derive(Clone, Debug, PartialEq)]
enum Centers<const N: usize, const L: usize> {
    /// The paper's vertex grid (see the module docs for the node order).
    Grid,
    /// User-chosen centres, one `N × L` matrix per input block (x, v, α1, α̇1).
    Custom([SMatrix<f64, N, L>; 4]),
}

/// A Gaussian RBF basis of `L` nodes over the `4N`-dimensional input, SPEC §6.
#[derive(Clone, Debug, PartialEq)]
pub struct Rbf<const N: usize, const L: usize> {
    eta2: f64,
    inv_eta2: f64,
    centers: Centers<N, L>,
}

impl<const N: usize, const L: usize> Rbf<N, L> {
    /// The paper's vertex grid of `L = 2^{4N}` nodes with width η² (the paper's
    /// "variance 25" is η² = 25). Errors if `L ≠ 2^{4N}` or η² is not > 0.
    pub fn grid(eta2: f64) -> Result<Self, Error> {
        if 4 * N >= usize::BITS as usize || L != grid_nodes(N) {
            return Err(Error::Invalid {
                what: "RBF vertex grid",
                reason: "the number of nodes L must be 2^(4n)",
            });
        }
        check::positive("η² > 0", "eta2", eta2)?;
        Ok(Self {
            eta2,
            inv_eta2: 1.0 / eta2,
            centers: Centers::Grid,
        })
    }

    /// User-chosen centres: `centers[b]` column `j` is block `b` of μ_j
    /// (blocks x, v, α1, α̇1 in rad, rad/s, rad/s, rad/s²), width η².
    pub fn custom(centers: [SMatrix<f64, N, L>; 4], eta2: f64) -> Result<Self, Error> {
        if L == 0 {
            return Err(Error::Invalid {
                what: "RBF centres",
                reason: "at least one node is needed",
            });
        }
        for block in &centers {
            check::finite_slice("centers", block.as_slice())?;
        }
        check::positive("η² > 0", "eta2", eta2)?;
        Ok(Self {
            eta2,
            inv_eta2: 1.0 / eta2,
            centers: Centers::Custom(centers),
        })
    }

    /// The width η² (squared distance units of Z).
    pub fn eta2(&self) -> f64 {
        self.eta2
    }

    /// True for the paper's vertex grid (evaluated by the separable fast path).
    pub fn is_grid(&self) -> bool {
        matches!(self.centers, Centers::Grid)
    }

    /// Centre μ_j as four blocks (x, v, α1, α̇1). Panics if `j >= L`.
    pub fn center(&self, j: usize) -> [Vector<N>; 4] {
        assert!(j < L, "node index {j} out of range (L = {L})");
        match &self.centers {
            Centers::Grid => core::array::from_fn(|b| {
                Vector::from_fn(|i, _| {
                    if (j >> (b * N + i)) & 1 == 1 {
                        1.0
                    } else {
                        -1.0
                    }
                })
            }),
            Centers::Custom(c) => core::array::from_fn(|b| c[b].column(j).into_owned()),
        }
    }

    /// The same basis with its centres stored explicitly (evaluated node by
    /// node): the reference the grid's fast path is tested against.
    pub fn to_custom(&self) -> Self {
        let centers =
            core::array::from_fn(|b| SMatrix::<f64, N, L>::from_fn(|i, j| self.center(j)[b][i]));
        Self {
            eta2: self.eta2,
            inv_eta2: self.inv_eta2,
            centers: Centers::Custom(centers),
        }
    }

    /// Evaluate S(Z) into `s`. `z` = [x, v, α1, α̇1]. Allocation-free.
    #[inline]
    pub fn eval(&self, z: &[Vector<N>; 4], s: &mut SVector<f64, L>) {
        match &self.centers {
            Centers::Grid => self.eval_grid(z, s),
            Centers::Custom(c) => self.eval_direct(c, z, s),
        }
    }

    fn eval_direct(
        &self,
        c: &[SMatrix<f64, N, L>; 4],
        z: &[Vector<N>; 4],
        s: &mut SVector<f64, L>,
    ) {
        for (j, sj) in s.iter_mut().enumerate() {
            let mut d2 = 0.0;
            for (block, zb) in c.iter().zip(z) {
                for i in 0..N {
                    let e = zb[i] - block[(i, j)];
                    d2 += e * e;
                }
            }
            *sj = exp(-d2 * self.inv_eta2);
        }
    }

    fn eval_grid(&self, z: &[Vector<N>; 4], s: &mut SVector<f64, L>) {
        let inv = self.inv_eta2;
        let comps = || z.iter().flat_map(|b| b.iter().copied());
        // Distance to the nearest vertex: Σ_d (|Z_d| − 1)².
        let near: f64 = comps().map(|zd| (zd.abs() - 1.0) * (zd.abs() - 1.0)).sum();
        let s = s.as_mut_slice();
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

#[cfg(test)]
mod tests {
    use super::*;

    fn z_of(v: [f64; 8]) -> [Vector<2>; 4] {
        core::array::from_fn(|b| Vector::<2>::new(v[2 * b], v[2 * b + 1]))
    }

    #[test]
    fn zero_input_gives_exp_minus_8_over_25_everywhere() {
        let rbf = Rbf::<2, 256>::grid(25.0).unwrap();
        let mut s = SVector::<f64, 256>::zeros();
        rbf.eval(&z_of([0.0; 8]), &mut s);
        let expect = (-8.0f64 / 25.0).exp();
        for &v in s.iter() {
            assert!((v - expect).abs() < 1e-15, "{v} vs {expect}");
        }
    }

    #[test]
    fn input_on_a_vertex_gives_one_there() {
        let rbf = Rbf::<2, 256>::grid(25.0).unwrap();
        let mut s = SVector::<f64, 256>::zeros();
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
        let grid = Rbf::<2, 256>::grid(25.0).unwrap();
        let direct = grid.to_custom();
        assert!(grid.is_grid() && !direct.is_grid());
        let inputs = [
            [0.3, -0.2, 1.5, -4.0, 0.0, 2.5, -0.7, 11.0],
            [-1.0, 1.0, 0.0, -0.0, 3.0, -3.0, 0.5, -0.5],
            [40.0, -60.0, 0.1, 0.2, -90.0, 5.0, 7.0, -1e3],
        ];
        let (mut a, mut b) = (SVector::<f64, 256>::zeros(), SVector::<f64, 256>::zeros());
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
    fn huge_inputs_underflow_to_zero_without_nan() {
        let rbf = Rbf::<2, 256>::grid(25.0).unwrap();
        let mut s = SVector::<f64, 256>::zeros();
        rbf.eval(
            &z_of([1e200, -1e200, 1e300, 0.0, 0.0, 0.0, 0.0, 0.0]),
            &mut s,
        );
        assert!(s.iter().all(|v| *v == 0.0));
    }

    #[test]
    fn grid_requires_two_to_the_four_n_nodes() {
        assert!(Rbf::<2, 255>::grid(25.0).is_err());
        assert!(Rbf::<1, 16>::grid(25.0).is_ok());
        let e = Rbf::<2, 256>::grid(0.0).unwrap_err();
        assert!(e.to_string().contains("η² > 0"), "{e}");
    }
}
