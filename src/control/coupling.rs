//! The inertia-shaped gains of SPEC (18.12): the inertia scales of SPEC
//! (10.2) as a symmetric positive definite matrix Dₛ (kg m²) in place of
//! diag(d), and the feedback gain Kp = R^½ Dₛ R^½ with R = diag(Kp_i/d_i)
//! (1/s), so that a delayed loop's modes, the eigenvalues of Dₛ^½ D(q)⁻¹ Dₛ^½,
//! stay close together along a path where the diagonal's spread by 50–120×
//! (SPEC (18.11)).

use crate::control::config::Config;
use crate::error::{check, Error, PARAM_BOUND};
use crate::types::{Matrix, Vector};

/// Dₛ and the gains made from it (SPEC (18.12)); built by
/// [`Coupling::new`], used by [`Controller::with_coupling`](crate::Controller::with_coupling).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Coupling<const N: usize> {
    /// Dₛ (kg m²): the z1 term Dₛ z1 and the learning error Dₛ z2.
    inertia: Matrix<N>,
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

impl<const N: usize> Coupling<N> {
    /// The gains of `inertia` (Dₛ, kg m²: finite, symmetric to 1e-9 of its
    /// largest entry, positive definite, every entry within 1e9) for the
    /// per-joint rates Kp_i/d_i of `cfg`.
    pub fn new(inertia: &Matrix<N>, cfg: &Config<N>) -> Result<Self, Error> {
        check::finite_slice("inertia_matrix", inertia.as_slice())?;
        check::at_most_each(
            "|value| ≤ 1e9",
            "inertia_matrix",
            inertia.as_slice(),
            PARAM_BOUND,
        )?;
        let scale = inertia.amax();
        if (inertia - inertia.transpose()).amax() > 1e-9 * scale {
            return Err(NOT_INERTIA);
        }
        let inertia = (inertia + inertia.transpose()) * 0.5;
        let rates = cfg.kp.component_div(&cfg.inertia);
        check::positive_vec("Kp/d > 0", "Kp", &rates)?;
        let root = rates.map(libm::sqrt);
        let kp = Matrix::<N>::from_fn(|i, j| root[i] * inertia[(i, j)] * root[j]);
        let kp_inv = kp.cholesky().ok_or(NOT_INERTIA)?.inverse();
        check::finite_slice("Kp", kp_inv.as_slice()).map_err(|_| NOT_INERTIA)?;
        Ok(Self {
            inertia,
            kp,
            kp_inv,
        })
    }

    /// Dₛ (kg m²).
    pub fn inertia(&self) -> &Matrix<N> {
        &self.inertia
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
