//! The auxiliary system that compensates saturation, (11), (36), SPEC §8.
//!
//! ```text
//! ‖ζ‖ ≥ μ:  ζ̇ = −Kζ ζ − ((|z2ᵀ Δτ| + ½ Δτᵀ Δτ) / ‖ζ‖²) ζ + Δτ
//! ‖ζ‖ < μ:  ζ̇ = −Kζ ζ + Δτ   (AuxLaw::Leaky, the SPEC default)
//!           ζ̇ = 0            (AuxLaw::Printed, as the paper prints it)
//! ```
//!
//! Erratum (SPEC §8): with the printed inner law ζ(0) = 0 never leaves the
//! origin and the compensator is dead; the default inner law leaves zero when
//! the actuator saturates and decays when it does not.
//!
//! Weighted by each joint's inertia scale d_i (kg m²) and the Young weight ρ
//! (1/s), SPEC (10.1): with Dₛ = diag(d),
//!
//! ```text
//! ζ̇ = −Kζ ζ − ((|z2ᵀ Δτ| + Δτᵀ Dₛ⁻¹ Δτ / (2ρ)) / (ζᵀ Dₛ ζ)) ζ + Dₛ⁻¹ Δτ
//! ```
//!
//! which is (11) for d = 1, ρ = 1 (the paper).

use crate::error::{check, Error};
use crate::types::{choices, Vector};

/// The law inside the ball ‖ζ‖ < μ, SPEC §8.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum AuxLaw {
    /// ζ̇ = −Kζ ζ + Δτ inside the ball (SPEC §8 default; "default" in Python).
    #[default]
    Leaky,
    /// ζ̇ = 0 inside the ball, as printed in (11) ("printed" in Python).
    Printed,
    /// ζ̇ = −Kζ ζ + Δτ everywhere, without the −β term ("linear" in Python;
    /// beyond the paper). The −β term of (11) holds ‖ζ‖ near μ whenever the
    /// actuator saturates, so ζ barely reacts; without it ζ is Δτ low-pass
    /// filtered at Kζ, the classical anti-windup signal (Åström & Rundqwist,
    /// "Integrator windup and how to avoid it", ACC 1989).
    Linear,
}

choices!(AuxLaw {
    "default" => AuxLaw::Leaky,
    "printed" => AuxLaw::Printed,
    "linear" => AuxLaw::Linear,
});

/// Parameters of the auxiliary system: Kζ (1/s, diagonal), μ (N m), the inner
/// law, the inertia scales d (kg m²) and the Young weight ρ (1/s).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Auxiliary<const N: usize> {
    kzeta: Vector<N>,
    mu: f64,
    law: AuxLaw,
    inertia: Vector<N>,
    /// 1/d_i (1/(kg m²)).
    inv_inertia: Vector<N>,
    /// 1/(2ρ) (s).
    half_inv_rho: f64,
}

impl<const N: usize> Auxiliary<N> {
    /// Validated: Kζ finite (its SPEC §10 condition involves Kp and is checked by
    /// the controller), μ > 0; the paper's weights d = 1, ρ = 1.
    pub fn new(kzeta: Vector<N>, mu: f64, law: AuxLaw) -> Result<Self, Error> {
        Self::weighted(kzeta, mu, law, Vector::from_element(1.0), 1.0)
    }

    /// As [`new`](Self::new), weighted by the inertia scales `inertia` (kg m²,
    /// each > 0) and the Young weight `rho` (1/s, > 0), SPEC (10.1).
    pub fn weighted(
        kzeta: Vector<N>,
        mu: f64,
        law: AuxLaw,
        inertia: Vector<N>,
        rho: f64,
    ) -> Result<Self, Error> {
        check::finite_slice("Kzeta", kzeta.as_slice())?;
        check::positive("μ > 0", "mu", mu)?;
        check::positive_vec("d > 0", "inertia", &inertia)?;
        check::positive("ρ > 0", "rho", rho)?;
        Ok(Self {
            kzeta,
            mu,
            law,
            inertia,
            inv_inertia: inertia.map(|d| 1.0 / d),
            half_inv_rho: 0.5 / rho,
        })
    }

    /// The inertia scales d (kg m²).
    pub fn inertia(&self) -> &Vector<N> {
        &self.inertia
    }

    /// Kζ (1/s).
    pub fn kzeta(&self) -> &Vector<N> {
        &self.kzeta
    }
    /// μ (N m).
    pub fn mu(&self) -> f64 {
        self.mu
    }
    /// The inner law.
    pub fn law(&self) -> AuxLaw {
        self.law
    }

    /// Advance ζ by one period `ts` (s) given z2 (rad/s) and Δτ = sat(τ) − τ (N m).
    ///
    /// Semi-implicit, per component (SPEC §11): with
    /// β = (|z2ᵀΔτ| + ΔτᵀDₛ⁻¹Δτ/(2ρ))/(ζᵀDₛζ) when ‖ζ‖ ≥ μ and β = 0
    /// otherwise, ζ_i ← (ζ_i + Ts Δτ_i/d_i) / (1 + Ts (Kζ_i + β)) (for d = 1,
    /// ρ = 1: β = (|z2ᵀΔτ| + ½ΔτᵀΔτ)/‖ζ‖², the paper's). Unconditionally
    /// stable in Ts; with the printed law ζ is left unchanged inside the ball.
    #[inline]
    pub fn advance(&self, zeta: &mut Vector<N>, z2: &Vector<N>, dtau: &Vector<N>, ts: f64) {
        let n2 = zeta.norm_squared();
        // ζᵀDₛζ (with d = 1, ρ = 1 every product by d_i, 1/d_i below is
        // exact: the paper's β to the last bit).
        let energy = zeta.component_mul(&self.inertia).dot(zeta);
        let beta = if self.law == AuxLaw::Linear {
            0.0
        } else if n2 >= self.mu * self.mu && energy > 0.0 {
            // (energy > 0: for μ below ~1e-154, μ² underflows to 0 and ‖ζ‖ = 0
            // would divide by zero; found by fuzzing.)
            let weighted = dtau.component_mul(&self.inv_inertia).dot(dtau);
            (z2.dot(dtau).abs() + weighted * self.half_inv_rho) / energy
        } else if self.law == AuxLaw::Printed {
            return;
        } else {
            0.0
        };
        for i in 0..N {
            zeta[i] = (zeta[i] + ts * (dtau[i] * self.inv_inertia[i]))
                / (1.0 + ts * (self.kzeta[i] + beta));
        }
    }
    /// [`advance`](Self::advance) with the scales as the matrix Dₛ (kg m²) of
    /// SPEC (18.12), `inv` = Dₛ⁻¹: β = (|z2ᵀΔτ| + ΔτᵀDₛ⁻¹Δτ/(2ρ))/(ζᵀDₛζ)
    /// and the input Dₛ⁻¹Δτ, per component as there.
    #[inline]
    pub fn advance_coupled(
        &self,
        zeta: &mut Vector<N>,
        z2: &Vector<N>,
        dtau: &Vector<N>,
        ts: f64,
        inertia: &crate::types::Matrix<N>,
        inv: &crate::types::Matrix<N>,
    ) {
        let n2 = zeta.norm_squared();
        let energy = zeta.dot(&(inertia * *zeta));
        let input = inv * dtau;
        let beta = if self.law == AuxLaw::Linear {
            0.0
        } else if n2 >= self.mu * self.mu && energy > 0.0 {
            (z2.dot(dtau).abs() + input.dot(dtau) * self.half_inv_rho) / energy
        } else if self.law == AuxLaw::Printed {
            return;
        } else {
            0.0
        };
        for i in 0..N {
            zeta[i] = (zeta[i] + ts * input[i]) / (1.0 + ts * (self.kzeta[i] + beta));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn aux(law: AuxLaw) -> Auxiliary<2> {
        Auxiliary::new(Vector::<2>::from_element(60.0), 0.01, law).unwrap()
    }

    #[test]
    fn stays_zero_without_saturation() {
        for law in [AuxLaw::Leaky, AuxLaw::Printed] {
            let mut z = Vector::<2>::zeros();
            for _ in 0..1000 {
                aux(law).advance(&mut z, &Vector::<2>::new(0.3, -0.1), &Vector::zeros(), 1e-3);
            }
            assert_eq!(z, Vector::<2>::zeros());
        }
    }

    #[test]
    fn default_law_leaves_zero_under_saturation_printed_does_not() {
        let dtau = Vector::<2>::new(-3.0, 0.5);
        let z2 = Vector::<2>::new(0.2, 0.1);
        let (mut leaky, mut printed) = (Vector::<2>::zeros(), Vector::<2>::zeros());
        let mut peak = 0.0f64;
        for _ in 0..2000 {
            aux(AuxLaw::Leaky).advance(&mut leaky, &z2, &dtau, 50e-6);
            aux(AuxLaw::Printed).advance(&mut printed, &z2, &dtau, 50e-6);
            peak = peak.max(leaky.norm());
        }
        // It leaves 0 along Δτ; once ‖ζ‖ ≥ μ the −β term pulls it back, so it
        // stays near the ball's surface (SPEC §11, Finding).
        assert!((0.01..0.02).contains(&peak), "peak ‖ζ‖ {peak}");
        assert!(leaky[0] < 0.0 && leaky[1] > 0.0, "ζ follows Δτ: {leaky}");
        assert_eq!(printed, Vector::<2>::zeros());
    }

    #[test]
    fn decays_once_saturation_ends() {
        let mut z = Vector::<2>::new(0.5, -0.5);
        for _ in 0..1000 {
            aux(AuxLaw::Leaky).advance(&mut z, &Vector::zeros(), &Vector::zeros(), 1e-3);
        }
        // e^{−60} is far below μ; once inside the ball the leaky law keeps decaying.
        assert!(z.norm() < 1e-20, "{z}");
    }
}
