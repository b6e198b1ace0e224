//! The target impedance (3) realised as a reference model, SPEC §4.
//!
//! The compliant reference xd obeys
//! `Dd (ẍc − ẍd) + Cd (ẋc − ẋd) + Gd (xc − xd) = τe`, so in free space
//! (τe = 0) xd ≡ xc, and in contact xd yields to the force like a
//! mass–spring–damper; the inner adaptive loop then makes x track xd.

use crate::error::{check, Error};
use crate::trajectory::Setpoint;
use crate::types::{choices, Vector};

/// Where the target impedance is realised (schema keyword `impedance`).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum ImpedanceMode {
    /// In joint space by the reference model of SPEC §4 ("joint", the paper).
    #[default]
    Joint,
    /// Outside the controller ("external"): the setpoint already is the
    /// compliant reference, xd = xc, ẋd = ẋc, ẍd = ẍc, and τe only enters the
    /// control law's feedforward (SPEC §16; e.g. from a Cartesian impedance).
    External,
}

choices!(ImpedanceMode {
    "joint" => ImpedanceMode::Joint,
    "external" => ImpedanceMode::External,
});

/// Target impedance: diagonal desired inertia Dd (kg m²), damping Cd
/// (N m s/rad) and stiffness Gd (N m/rad), (3), (66).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TargetImpedance<const N: usize> {
    dd: Vector<N>,
    cd: Vector<N>,
    gd: Vector<N>,
}

impl<const N: usize> TargetImpedance<N> {
    /// Validated: Dd > 0 (SPEC §10), Cd ≥ 0 and Gd ≥ 0 (a negative damping or
    /// stiffness would make the reference itself unstable), all finite and at
    /// most 1e9 (as every gain: beyond, the reference overflows in use).
    pub fn new(dd: Vector<N>, cd: Vector<N>, gd: Vector<N>) -> Result<Self, Error> {
        check::positive_vec("Dd > 0", "Dd", &dd)?;
        check::nonnegative_vec("Cd ≥ 0", "Cd", &cd)?;
        check::nonnegative_vec("Gd ≥ 0", "Gd", &gd)?;
        for (what, v) in [("Dd", &dd), ("Cd", &cd), ("Gd", &gd)] {
            check::at_most_each(
                "|value| ≤ 1e9",
                what,
                v.as_slice(),
                crate::error::PARAM_BOUND,
            )?;
        }
        Ok(Self { dd, cd, gd })
    }

    /// The paper's (66): Dd = diag(1), Cd = diag(10), Gd = diag(60), for any N.
    pub fn paper() -> Self {
        Self {
            dd: Vector::from_element(1.0),
            cd: Vector::from_element(10.0),
            gd: Vector::from_element(60.0),
        }
    }

    /// Desired inertia Dd (kg m²).
    pub fn dd(&self) -> &Vector<N> {
        &self.dd
    }
    /// Desired damping Cd (N m s/rad).
    pub fn cd(&self) -> &Vector<N> {
        &self.cd
    }
    /// Desired stiffness Gd (N m/rad).
    pub fn gd(&self) -> &Vector<N> {
        &self.gd
    }

    /// Reference acceleration, SPEC §4:
    /// `ẍd = ẍc + Dd⁻¹ [Cd (ẋc − ẋd) + Gd (xc − xd) − τe]` (rad/s²).
    #[inline]
    pub fn accel(&self, c: &Setpoint<N>, r: &Reference<N>, tau_e: &Vector<N>) -> Vector<N> {
        let mut a = c.ddx;
        for i in 0..N {
            a[i] += (self.cd[i] * (c.dx[i] - r.dxd[i]) + self.gd[i] * (c.x[i] - r.xd[i])
                - tau_e[i])
                / self.dd[i];
        }
        a
    }

    /// Residual of the target impedance (3) for a motion (x, ẋ, ẍ) under τe:
    /// `Dd (ẍc − ẍ) + Cd (ẋc − ẋ) + Gd (xc − x) − τe` (N m), SPEC §12.
    pub fn residual(
        &self,
        c: &Setpoint<N>,
        x: &Vector<N>,
        dx: &Vector<N>,
        ddx: &Vector<N>,
        tau_e: &Vector<N>,
    ) -> Vector<N> {
        self.dd.component_mul(&(c.ddx - ddx))
            + self.cd.component_mul(&(c.dx - dx))
            + self.gd.component_mul(&(c.x - x))
            - tau_e
    }
}

/// State of the reference model: xd (rad) and ẋd (rad/s).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Reference<const N: usize> {
    /// Compliant reference position xd (rad).
    pub xd: Vector<N>,
    /// Compliant reference velocity ẋd (rad/s).
    pub dxd: Vector<N>,
}

impl<const N: usize> Reference<N> {
    /// All zeros (before the first step).
    pub fn zeros() -> Self {
        Self {
            xd: Vector::zeros(),
            dxd: Vector::zeros(),
        }
    }

    /// Start on the commanded trajectory: xd(0) = xc(0), ẋd(0) = ẋc(0), SPEC §4.
    pub fn start(c: &Setpoint<N>) -> Self {
        Self { xd: c.x, dxd: c.dx }
    }

    /// Semi-implicit Euler step, SPEC §11: ẋd ← ẋd + Ts ẍd, then xd ← xd + Ts ẋd (new ẋd).
    #[inline]
    pub fn advance(&mut self, ddxd: &Vector<N>, ts: f64) {
        self.dxd += ts * ddxd;
        self.xd += ts * self.dxd;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trajectory::{Sinusoid, Trajectory};

    #[test]
    fn free_space_reference_follows_the_command() {
        let imp = TargetImpedance::<2>::paper();
        let tr = Sinusoid::paper();
        let mut r = Reference::start(&tr.sample(0.0));
        let ts = 1e-4;
        for k in 0..20_000 {
            let c = tr.sample(k as f64 * ts);
            let a = imp.accel(&c, &r, &Vector::zeros());
            r.advance(&a, ts);
        }
        let c = tr.sample(2.0);
        assert!((r.xd - c.x).norm() < 1e-4, "{} vs {}", r.xd, c.x);
    }

    #[test]
    fn constant_force_gives_static_deflection_tau_over_gd() {
        // Dd ẍ + Cd ẋ + Gd (xc − xd) = τe at rest ⇒ xd = xc − τe/Gd.
        let imp = TargetImpedance::<2>::paper();
        let c = Setpoint {
            x: Vector::<2>::new(0.3, 0.1),
            dx: Vector::zeros(),
            ddx: Vector::zeros(),
        };
        let mut r = Reference::start(&c);
        let te = Vector::<2>::new(6.0, 0.0);
        for _ in 0..200_000 {
            let a = imp.accel(&c, &r, &te);
            r.advance(&a, 1e-4);
        }
        assert!((r.xd[0] - (0.3 - 0.1)).abs() < 1e-9, "{}", r.xd);
        assert!((r.xd[1] - 0.1).abs() < 1e-12);
    }
}
