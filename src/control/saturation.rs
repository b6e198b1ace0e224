//! Actuator saturation `sat_i(τ_i) = clamp(τ_i, −τmax_i, τmax_i)`, SPEC §2.

use crate::error::{check, Error};
use crate::types::Vector;

/// Symmetric per-joint torque limits τmax (N m), SPEC §2.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Saturation<const N: usize> {
    tau_max: Vector<N>,
}

impl<const N: usize> Saturation<N> {
    /// Limits τmax (N m), each finite and > 0 (SPEC §10).
    pub fn new(tau_max: Vector<N>) -> Result<Self, Error> {
        check::positive_vec("τmax > 0", "tau_max", &tau_max)?;
        Ok(Self { tau_max })
    }

    /// The limits τmax (N m).
    pub fn limits(&self) -> &Vector<N> {
        &self.tau_max
    }

    /// `sat(τ)` (N m). A NaN entry stays NaN; this never panics.
    #[inline]
    pub fn apply(&self, tau: &Vector<N>) -> Vector<N> {
        tau.zip_map(&self.tau_max, |t, m| t.clamp(-m, m))
    }
}

impl Saturation<2> {
    /// The paper's limits, τmax = [17.0, 15.0] N m (SPEC §2).
    pub fn paper() -> Self {
        Self {
            tau_max: Vector::<2>::new(17.0, 15.0),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clamps_each_joint_to_its_own_limit() {
        let s = Saturation::paper();
        let out = s.apply(&Vector::<2>::new(20.0, -16.0));
        assert_eq!(out, Vector::<2>::new(17.0, -15.0));
        let inside = Vector::<2>::new(-3.0, 14.9);
        assert_eq!(s.apply(&inside), inside);
    }

    #[test]
    fn rejects_nonpositive_limit() {
        let e = Saturation::new(Vector::<2>::new(1.0, 0.0)).unwrap_err();
        assert!(
            matches!(
                e,
                Error::Condition {
                    condition: "τmax > 0",
                    index: Some(1),
                    ..
                }
            ),
            "{e}"
        );
    }
}
