//! The robust term r(z2) of the control laws (N m), SPEC §7.

use crate::error::{check, Error};
use crate::math::{sgn, tanh};
use crate::types::{choices, Vector};

/// Which robust term, in a configuration (its gains are separate fields).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum RobustKind {
    /// `Kr sgn(z2)`, the paper's term ("sign").
    #[default]
    Sign,
    /// `Kr tanh(z2/φ)` ("tanh").
    Tanh,
    /// Remark 1, (30) ("remark1").
    Remark1,
    /// No robust term ("none").
    None,
}

choices!(RobustKind {
    "sign" => RobustKind::Sign,
    "tanh" => RobustKind::Tanh,
    "remark1" => RobustKind::Remark1,
    "none" => RobustKind::None,
});

/// The robust term r(z2) (N m), SPEC §7. Each is a choice, not a different controller.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Robust<const N: usize> {
    /// No robust term ("none" in Python).
    None,
    /// `Kr sgn(z2)`, the paper's term ("sign"); `kr` in N m (SPEC default 0.5).
    Sign {
        /// Gain kr per joint (N m).
        kr: Vector<N>,
    },
    /// Smooth boundary layer `Kr tanh(z2/φ)` ("tanh"); `kr` in N m, `phi` in rad/s.
    Tanh {
        /// Gain kr per joint (N m).
        kr: Vector<N>,
        /// Boundary-layer width φ (rad/s), > 0.
        phi: f64,
    },
    /// Remark 1, (30) ("remark1"): `kr_i sgn(z2_i)` with `kr_i = kD |α̇1_i| + kC |α1_i| + kG`.
    Remark1 {
        /// kD (N m per rad/s², i.e. kg m²).
        kd: f64,
        /// kC (N m per rad/s).
        kc: f64,
        /// kG (N m).
        kg: f64,
    },
}

impl<const N: usize> Robust<N> {
    /// The term `kind` with its gains: kr (N m), φ (rad/s), kD (kg m²), kC
    /// (N m s/rad), kG (N m); the gains a kind does not use are ignored.
    pub fn from_config(kind: RobustKind, kr: Vector<N>, phi: f64, gains: [f64; 3]) -> Self {
        let [kd, kc, kg] = gains;
        match kind {
            RobustKind::Sign => Robust::Sign { kr },
            RobustKind::Tanh => Robust::Tanh { kr, phi },
            RobustKind::Remark1 => Robust::Remark1 { kd, kc, kg },
            RobustKind::None => Robust::None,
        }
    }

    /// Every gain finite and ≥ 0, φ > 0; the error names the parameter.
    pub fn validate(&self) -> Result<(), Error> {
        match self {
            Robust::None => Ok(()),
            Robust::Sign { kr } => check::nonnegative_vec("kr ≥ 0", "kr", kr),
            Robust::Tanh { kr, phi } => {
                check::nonnegative_vec("kr ≥ 0", "kr", kr)?;
                check::positive("φ > 0", "phi", *phi)
            }
            Robust::Remark1 { kd, kc, kg } => {
                check::nonnegative("kD ≥ 0", "kD", *kd)?;
                check::nonnegative("kC ≥ 0", "kC", *kc)?;
                check::nonnegative("kG ≥ 0", "kG", *kg)
            }
        }
    }

    /// r(z2) (N m) given z2 (rad/s), α1 (rad/s) and α̇1 (rad/s²).
    #[inline]
    pub fn eval(&self, z2: &Vector<N>, alpha1: &Vector<N>, dalpha1: &Vector<N>) -> Vector<N> {
        match self {
            Robust::None => Vector::zeros(),
            Robust::Sign { kr } => Vector::from_fn(|i, _| kr[i] * sgn(z2[i])),
            Robust::Tanh { kr, phi } => Vector::from_fn(|i, _| kr[i] * tanh(z2[i] / phi)),
            Robust::Remark1 { kd, kc, kg } => Vector::from_fn(|i, _| {
                (kd * dalpha1[i].abs() + kc * alpha1[i].abs() + kg) * sgn(z2[i])
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_term_at_a_known_error() {
        let z2 = Vector::<2>::new(0.1, -0.2);
        let (a, da) = (Vector::<2>::new(1.0, -2.0), Vector::<2>::new(3.0, 4.0));
        let kr = Vector::<2>::new(0.5, 2.0);
        assert_eq!(Robust::None.eval(&z2, &a, &da), Vector::<2>::zeros());
        assert_eq!(
            Robust::Sign { kr }.eval(&z2, &a, &da),
            Vector::<2>::new(0.5, -2.0)
        );
        let t = Robust::Tanh { kr, phi: 0.1 }.eval(&z2, &a, &da);
        assert!((t[0] - 0.5 * 1f64.tanh()).abs() < 1e-15);
        let r = Robust::<2>::Remark1 {
            kd: 1.0,
            kc: 2.0,
            kg: 3.0,
        }
        .eval(&z2, &a, &da);
        assert_eq!(r, Vector::<2>::new(3.0 + 2.0 + 3.0, -(4.0 + 4.0 + 3.0)));
        let e = Robust::Tanh { kr, phi: 0.0 }.validate().unwrap_err();
        assert!(e.to_string().contains("φ > 0"), "{e}");
    }
}
