//! Errors: validation at construction (SPEC §10) and bad inputs to a step.
//!
//! [`Error`] is a small `Copy` enum that formats without allocating, so it is
//! usable in `no_std` firmware; with `std` it implements `std::error::Error`.

use core::fmt;

/// Everything that can go wrong in adaptimp.
#[derive(Copy, Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// A condition of SPEC §10 (or another validity condition) does not hold.
    ///
    /// `condition` is the inequality as written in the SPEC, `lhs` names the
    /// quantity that was evaluated (by the parameter names used in Python),
    /// `index` the joint or element it failed at (if the parameter is a
    /// vector) and `value` its value.
    Condition {
        /// The violated condition, e.g. `"2Kζ − I − KpᵀKp > 0"`.
        condition: &'static str,
        /// The quantity evaluated, e.g. `"2·Kzeta − 1 − Kp²"`.
        lhs: &'static str,
        /// Element index (joint), if the quantity is a vector.
        index: Option<usize>,
        /// The offending value of `lhs`.
        value: f64,
    },
    /// A parameter or an input is NaN or infinite.
    NonFinite {
        /// Which quantity, e.g. `"x"` or `"Kp"`.
        what: &'static str,
        /// Element index of the first non-finite entry.
        index: usize,
    },
    /// State and PD feedback need the measured velocity, and none was given.
    MissingVelocity,
    /// The controller's output is not finite although its inputs are: its
    /// state has diverged (e.g. weights overflowed). Call `reset()`.
    Diverged {
        /// Which quantity became non-finite.
        what: &'static str,
    },
    /// A structural mismatch, e.g. an RBF grid whose node count is not 2^(4n).
    Invalid {
        /// Which quantity.
        what: &'static str,
        /// Why it is invalid.
        reason: &'static str,
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Error::Condition {
                condition,
                lhs,
                index,
                value,
            } => {
                write!(f, "condition {condition} is violated: {lhs}")?;
                if let Some(i) = index {
                    write!(f, "[{i}]")?;
                }
                write!(f, " = {value} (SPEC §10)")
            }
            Error::NonFinite { what, index } => {
                write!(f, "{what}[{index}] is not finite (NaN or infinite)")
            }
            Error::MissingVelocity => f.write_str(
                "this controller uses the measured velocity: pass dq (only output feedback estimates it)",
            ),
            Error::Diverged { what } => write!(
                f,
                "{what} became non-finite from finite inputs: the controller state diverged; call reset()"
            ),
            Error::Invalid { what, reason } => write!(f, "{what}: {reason}"),
        }
    }
}

impl core::error::Error for Error {}

/// Validation helpers shared by every constructor.
pub(crate) mod check {
    use super::Error;
    use crate::types::Vector;

    /// Every entry finite.
    pub fn finite_slice(what: &'static str, v: &[f64]) -> Result<(), Error> {
        match v.iter().position(|x| !x.is_finite()) {
            Some(index) => Err(Error::NonFinite { what, index }),
            None => Ok(()),
        }
    }

    /// A finite scalar.
    pub fn finite(what: &'static str, v: f64) -> Result<(), Error> {
        finite_slice(what, &[v])
    }

    /// A finite scalar with `v > 0` (`strict`) or `v >= 0`, else the named condition.
    fn sign(
        condition: &'static str,
        what: &'static str,
        v: f64,
        strict: bool,
    ) -> Result<(), Error> {
        finite(what, v)?;
        if (strict && v > 0.0) || (!strict && v >= 0.0) {
            Ok(())
        } else {
            Err(Error::Condition {
                condition,
                lhs: what,
                index: None,
                value: v,
            })
        }
    }

    /// A finite scalar with `v > 0`, else the named condition.
    pub fn positive(condition: &'static str, what: &'static str, v: f64) -> Result<(), Error> {
        sign(condition, what, v, true)
    }

    /// A finite scalar with `v >= 0`.
    pub fn nonnegative(condition: &'static str, what: &'static str, v: f64) -> Result<(), Error> {
        sign(condition, what, v, false)
    }

    /// `f(v_i) > 0` for every element, where `f` is the left-hand side of the condition.
    pub fn each<const N: usize>(
        condition: &'static str,
        lhs: &'static str,
        v: &Vector<N>,
        f: impl Fn(usize, f64) -> f64,
        strict: bool,
    ) -> Result<(), Error> {
        for (i, &x) in v.iter().enumerate() {
            let value = f(i, x);
            let ok = if strict { value > 0.0 } else { value >= 0.0 };
            if !ok {
                return Err(Error::Condition {
                    condition,
                    lhs,
                    index: Some(i),
                    value,
                });
            }
        }
        Ok(())
    }

    /// Every element finite and `> 0`.
    pub fn positive_vec<const N: usize>(
        condition: &'static str,
        what: &'static str,
        v: &Vector<N>,
    ) -> Result<(), Error> {
        finite_slice(what, v.as_slice())?;
        each(condition, what, v, |_, x| x, true)
    }

    /// Every element finite and `>= 0`.
    pub fn nonnegative_vec<const N: usize>(
        condition: &'static str,
        what: &'static str,
        v: &Vector<N>,
    ) -> Result<(), Error> {
        finite_slice(what, v.as_slice())?;
        each(condition, what, v, |_, x| x, false)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn condition_message_names_condition_and_value() {
        let e = Error::Condition {
            condition: "2Kζ − I − KpᵀKp > 0",
            lhs: "2·Kzeta − 1 − Kp²",
            index: Some(1),
            value: -1.0,
        };
        let s = e.to_string();
        assert!(s.contains("2Kζ − I − KpᵀKp > 0"), "{s}");
        assert!(s.contains("Kzeta"), "{s}");
        assert!(s.contains("[1]"), "{s}");
        assert!(s.contains("= -1"), "{s}");
    }

    #[test]
    fn nonfinite_message_names_quantity() {
        let s = Error::NonFinite {
            what: "x",
            index: 0,
        }
        .to_string();
        assert!(s.starts_with("x[0] is not finite"), "{s}");
    }
}
