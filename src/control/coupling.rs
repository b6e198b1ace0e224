//! The inertia-shaped gains of SPEC (18.12): the inertia scales of SPEC
//! (10.2) as a symmetric positive definite matrix Dₛ (kg m²) in place of
//! diag(d), and the feedback gain Kp = R^½ Dₛ R^½ with R = diag(Kp_i/d_i)
//! (1/s), so that a delayed loop's modes, the eigenvalues of Dₛ^½ D(q)⁻¹ Dₛ^½,
//! stay close together along a path where the diagonal's spread by 50–120×
//! (SPEC (18.11)). The auxiliary system is weighted by Dₛ too
//! ([`Auxiliary::advance_coupled`](crate::control::auxiliary::Auxiliary::advance_coupled)).

/// The smallest inertia scale (kg m²), as the diagonal's d ≥ 1e-9.
const MIN_SCALE: f64 = 1e-9;

use crate::control::config::{Conditions, Config};
use crate::error::{check, Error, PARAM_BOUND};
use crate::types::{Matrix, Vector};

/// Dₛ and the gains made from it (SPEC (18.12)), made once when a
/// controller of [`Config::inertia_matrix`] is built.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Coupling<const N: usize> {
    /// Dₛ (kg m²): the z1 term Dₛ z1, the learning error Dₛ z2 and the
    /// auxiliary system's weight.
    inertia: Matrix<N>,
    /// Dₛ⁻¹ (1/(kg m²)): the auxiliary system's input Dₛ⁻¹ Δτ.
    inertia_inv: Matrix<N>,
    /// Kp = R^½ Dₛ R^½ (N m s/rad).
    kp: Matrix<N>,
    /// Kp⁻¹, for the task's null space (19.3).
    kp_inv: Matrix<N>,
}

/// The error of a matrix that is not an inertia.
const NOT_INERTIA: Error = Error::Invalid {
    what: "inertia_matrix",
    reason: "must be symmetric positive definite (kg m²)",
};

/// The same value on every joint, to 1e-12 of the largest.
fn uniform<const N: usize>(v: &Vector<N>) -> bool {
    v.max() - v.min() <= 1e-12 * v.amax()
}

impl<const N: usize> Coupling<N> {
    /// The gains of `inertia` (Dₛ, kg m²) for `cfg`. Dₛ must be finite,
    /// symmetric (each pair within 1e-12 of the larger; it is then made
    /// exactly so), positive definite with λmin ≥ 1e-9 and every entry
    /// within 1e9, as must every entry of Kp; the conditions "scaled", and
    /// K1, Kζ and the rates Kp_i/d_i the same on every joint, for which the
    /// conditions (10.3) on the rates are the matrix conditions of (18.12).
    pub fn new(inertia: &Matrix<N>, cfg: &Config<N>) -> Result<Self, Error> {
        check::finite_slice("inertia_matrix", inertia.as_slice())?;
        check::at_most_each(
            "|value| ≤ 1e9",
            "inertia_matrix",
            inertia.as_slice(),
            PARAM_BOUND,
        )?;
        for i in 0..N {
            for j in 0..i {
                let (a, b) = (inertia[(i, j)], inertia[(j, i)]);
                if (a - b).abs() > 1e-12 * a.abs().max(b.abs()) {
                    return Err(NOT_INERTIA);
                }
            }
        }
        if cfg.conditions != Conditions::Scaled {
            return Err(Error::Invalid {
                what: "inertia_matrix",
                reason: "needs conditions = scaled (SPEC (18.12))",
            });
        }
        let rates = cfg.kp.component_div(&cfg.inertia);
        check::positive_vec("Kp/d > 0", "Kp", &rates)?;
        if !(uniform(&cfg.k1) && uniform(&cfg.kzeta) && uniform(&rates)) {
            return Err(Error::Invalid {
                what: "inertia_matrix",
                reason: "needs K1, Kzeta and Kp/inertia the same on every joint (SPEC (18.12)); \
                         gains that differ by joint take the diagonal law (no inertia_matrix: \
                         the rule's coupled = false)",
            });
        }
        let inertia = (inertia + inertia.transpose()) * 0.5;
        let inertia_inv = inertia.cholesky().ok_or(NOT_INERTIA)?.inverse();
        // λmin(Dₛ) = 1/λmax(Dₛ⁻¹), the bound within 1 % from above.
        let least = 1.0 / largest_eigenvalue(&inertia_inv);
        if least.is_nan() || least < MIN_SCALE {
            return Err(Error::Condition {
                condition: "λmin(inertia_matrix) ≥ 1e-9",
                lhs: "λmin(inertia_matrix)",
                index: None,
                value: least,
            });
        }
        let root = rates.map(libm::sqrt);
        let kp = Matrix::<N>::from_fn(|i, j| root[i] * inertia[(i, j)] * root[j]);
        check::at_most_each("|value| ≤ 1e9", "Kp", kp.as_slice(), PARAM_BOUND)?;
        let kp_inv = kp.cholesky().ok_or(NOT_INERTIA)?.inverse();
        check::finite_slice("Kp", kp_inv.as_slice()).map_err(|_| NOT_INERTIA)?;
        Ok(Self {
            inertia,
            inertia_inv,
            kp,
            kp_inv,
        })
    }

    /// Dₛ (kg m²).
    pub fn inertia(&self) -> &Matrix<N> {
        &self.inertia
    }

    /// Dₛ⁻¹ (1/(kg m²)).
    pub fn inertia_inv(&self) -> &Matrix<N> {
        &self.inertia_inv
    }

    /// Kp = R^½ Dₛ R^½ (N m s/rad).
    pub fn kp(&self) -> &Matrix<N> {
        &self.kp
    }

    /// Kp⁻¹ (rad/(N m s)).
    pub fn kp_inv(&self) -> &Matrix<N> {
        &self.kp_inv
    }
}

/// Kp v: the coupled gain's, else the diagonal's Kp∘v.
#[inline]
pub(crate) fn kp_times<const N: usize>(
    c: Option<&Coupling<N>>,
    cfg: &Config<N>,
    v: &Vector<N>,
) -> Vector<N> {
    match c {
        Some(c) => c.kp * v,
        None => cfg.kp.component_mul(v),
    }
}

/// Dₛ v: the coupled inertia's, else the scales' d∘v.
#[inline]
pub(crate) fn inertia_times<const N: usize>(
    c: Option<&Coupling<N>>,
    cfg: &Config<N>,
    v: &Vector<N>,
) -> Vector<N> {
    match c {
        Some(c) => c.inertia * v,
        None => cfg.inertia.component_mul(v),
    }
}

/// An upper bound on the largest eigenvalue of a symmetric positive definite
/// `m`, within 1 % of it: λmax ≤ (tr m^(2^k))^(2^−k) ≤ N^(2^−k) λmax, k = 8
/// (repeated squaring, each power scaled to unit trace).
pub fn largest_eigenvalue<const N: usize>(m: &Matrix<N>) -> f64 {
    const K: i32 = 8;
    let t = m.trace();
    let mut a = m / t;
    let mut log_c = libm::log(t);
    for _ in 0..K {
        let sq = a * a;
        let t = sq.trace();
        a = sq / t;
        log_c = 2.0 * log_c + libm::log(t);
    }
    libm::exp(log_c / f64::from(1 << K))
}
