//! The operational-space inertia Λ of an arm's tip as robosuite's
//! operational-space controller OSC_POSE computes it, SPEC (23.7): from the
//! 6 × N geometric Jacobian [J_v; J_ω] and the joint-space inertia D,
//! Λ = (J D⁻¹ Jᵀ)⁺, or block by block, Λ = diag((J_v D⁻¹ J_vᵀ)⁺,
//! (J_ω D⁻¹ J_ωᵀ)⁺), when translation and rotation are uncoupled
//! (OSC_POSE's `uncouple_pos_ori`). No allocation.

use crate::cartesian::kinematics::Jacobian6;
use crate::error::{check, Error};
use crate::types::Matrix;
use nalgebra::{SMatrix, SymmetricEigen};

/// The relative cut-off of the pseudo-inverse ⁺ of SPEC (23.7): a singular
/// value σ of J D⁻¹ Jᵀ (or of a block) at or below `PINV_RCOND` · σmax is
/// taken as zero, its 1/σ dropped (NumPy's and Numba's `pinv` default,
/// which robosuite's `opspace_matrices` uses).
pub const PINV_RCOND: f64 = 1e-15;

/// The sweeps the symmetric eigen-decomposition of J D⁻¹ Jᵀ may take (it
/// takes a few dozen on a 6 × 6 matrix; finite inputs always converge).
const MAX_SWEEPS: usize = 10_000;

/// The error of an inertia that is not symmetric.
const NOT_SYMMETRIC: Error = Error::Invalid {
    what: "inertia",
    reason: "must be symmetric (D_ij = D_ji to 1e-12 relative)",
};

/// The error of an inertia that is not positive definite.
const NOT_SPD: Error = Error::Invalid {
    what: "inertia",
    reason: "must be positive definite (its Cholesky factorisation failed: D is singular)",
};

/// The error of a Λ beyond f64: J D⁻¹ Jᵀ too near zero (whole, or a block
/// the joints move, underflowed to zero).
const TOO_NEAR_ZERO: Error = Error::Invalid {
    what: "Λ",
    reason: "beyond f64 (J D⁻¹ Jᵀ too near zero: a jacobian near 0, or an inertia too large)",
};

/// Λ of SPEC (23.7), 6 × 6, symmetric (kg on the translation rows, kg m² on
/// the rotation rows, kg m across): robosuite's `opspace_matrices`
/// (`lambda_full`, or `lambda_pos` and `lambda_ori` on the diagonal blocks
/// when `uncoupled`, the off-diagonal blocks then zero), at the tip whose
/// geometric Jacobian is `j` (world-aligned, [J_v; J_ω]) on an arm of
/// joint-space inertia `d` (kg m², symmetric positive definite). The
/// pseudo-inverse drops the directions the arm cannot move in: an arm of
/// fewer than 6 joints has Λ of rank N at most, and a block the joints do
/// not move at all is zero.
///
/// Errors: a non-finite entry of `j` or `d` ([`Error::NonFinite`], `index`
/// column-major); `d` not symmetric or not positive definite
/// ([`Error::Invalid`] named `inertia`); J D⁻¹ Jᵀ or Λ beyond f64
/// ([`Error::Invalid`] named `J D⁻¹ Jᵀ` or `Λ`; a block whose J D⁻¹ Jᵀ
/// underflows to zero while its rows of J do not, too): never a NaN, an
/// infinity or a spurious zero.
pub fn operational_inertia<const N: usize>(
    j: &Jacobian6<N>,
    d: &Matrix<N>,
    uncoupled: bool,
) -> Result<Matrix<6>, Error> {
    check::finite_slice("jacobian", j.as_slice())?;
    check::finite_slice("inertia", d.as_slice())?;
    for r in 0..N {
        for c in 0..r {
            let (a, b) = (d[(r, c)], d[(c, r)]);
            if (a - b).abs() > 1e-12 * a.abs().max(b.abs()) {
                return Err(NOT_SYMMETRIC);
            }
        }
    }
    // (23.7), SPEC §23: J D⁻¹ Jᵀ = Xᵀ X, X = L⁻¹ Jᵀ, D = L Lᵀ (symmetric by
    // construction), then its pseudo-inverse, whole or by blocks.
    let l = d.cholesky().ok_or(NOT_SPD)?.unpack();
    let x = l.solve_lower_triangular(&j.transpose()).ok_or(NOT_SPD)?;
    let a = x.transpose() * x;
    if a.iter().any(|v| !v.is_finite()) {
        return Err(Error::Invalid {
            what: "J D⁻¹ Jᵀ",
            reason: "beyond f64 (a jacobian too large, or an inertia too near singular)",
        });
    }
    // Rows of J that move the tip but whose J D⁻¹ Jᵀ underflowed to zero:
    // Λ there is beyond f64, not a direction the joints cannot move.
    let underflow = |rows: core::ops::Range<usize>| {
        let moved = rows.clone().any(|r| j.row(r).iter().any(|v| *v != 0.0));
        moved && rows.clone().all(|r| rows.clone().all(|c| a[(r, c)] == 0.0))
    };
    let lam = if uncoupled {
        let mut lam = Matrix::<6>::zeros();
        for k in [0, 3] {
            if underflow(k..k + 3) {
                return Err(TOO_NEAR_ZERO);
            }
            let block = pinv(a.fixed_view::<3, 3>(k, k).into_owned())?;
            lam.fixed_view_mut::<3, 3>(k, k).copy_from(&block);
        }
        lam
    } else {
        if underflow(0..6) {
            return Err(TOO_NEAR_ZERO);
        }
        pinv(a)?
    };
    if lam.iter().any(|v| !v.is_finite()) {
        return Err(TOO_NEAR_ZERO);
    }
    Ok(lam)
}

/// The pseudo-inverse of SPEC (23.7) of a symmetric positive semi-definite
/// matrix: its singular values are |λ| of its eigenvalues λ, so
/// A⁺ = Σ_{|λ_k| > PINV_RCOND · max|λ|} v_k v_kᵀ / λ_k, made exactly symmetric.
fn pinv<const M: usize>(a: SMatrix<f64, M, M>) -> Result<SMatrix<f64, M, M>, Error>
where
    SMatrix<f64, M, M>: Eigen<M>,
{
    let (values, vectors) = a.eigen().ok_or(Error::Invalid {
        what: "inertia",
        reason: "the eigen-decomposition of J D⁻¹ Jᵀ did not converge",
    })?;
    let largest = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let cut = PINV_RCOND * largest;
    let mut out = SMatrix::<f64, M, M>::zeros();
    for (k, &v) in values.iter().enumerate() {
        if v.abs() > cut {
            let col = vectors.column(k);
            out += col * col.transpose() / v;
        }
    }
    Ok((out + out.transpose()) * 0.5)
}

/// The symmetric eigen-decomposition of the sizes (23.7) inverts: 3 × 3
/// blocks and the whole 6 × 6.
trait Eigen<const M: usize> {
    /// Eigenvalues and eigenvectors (columns), or None if it did not converge.
    fn eigen(self) -> Option<(SMatrix<f64, M, 1>, SMatrix<f64, M, M>)>;
}

macro_rules! eigen {
    ($($m:literal),*) => {$(
        impl Eigen<$m> for SMatrix<f64, $m, $m> {
            fn eigen(self) -> Option<(SMatrix<f64, $m, 1>, SMatrix<f64, $m, $m>)> {
                SymmetricEigen::try_new(self, f64::EPSILON, MAX_SWEEPS)
                    .map(|e| (e.eigenvalues, e.eigenvectors))
            }
        }
    )*};
}
eigen!(3, 6);

#[cfg(test)]
mod tests;
