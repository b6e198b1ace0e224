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
    /// An input, or the state a step would reach, is beyond a limit: a
    /// plausibility limit of the configuration (`q_max`, `dq_max`,
    /// `tau_e_max`, `q_jump_max`) or the bound every signal and state value
    /// of a step must respect ([`BOUND`], so nothing overflows). The step
    /// changed nothing.
    OutOfRange {
        /// Which quantity, e.g. `"q"` or `"z2"`.
        what: &'static str,
        /// Element index (joint), if a vector.
        index: Option<usize>,
        /// Its value.
        value: f64,
        /// The limit it exceeds (in magnitude).
        limit: f64,
    },
    /// A fault is latched (fault policy "latch"): the step is refused until
    /// `clear_fault`; `reason` is the error that latched it.
    Faulted {
        /// The error that latched the fault.
        reason: &'static str,
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
                // Beyond 1e15 in scientific notation (1e300, not 301 digits).
                if value.abs() >= 1e15 {
                    write!(f, " = {value:e} (SPEC §10)")
                } else {
                    write!(f, " = {value} (SPEC §10)")
                }
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
            Error::OutOfRange {
                what,
                index,
                value,
                limit,
            } => {
                write!(f, "{what}")?;
                if let Some(i) = index {
                    write!(f, "[{i}]")?;
                }
                write!(f, " = {value:e} is beyond its limit ±{limit:e}; the state was left unchanged")
            }
            Error::Faulted { reason } => write!(
                f,
                "a fault is latched ({reason}): the step is refused until clear_fault()"
            ),
            Error::Invalid { what, reason } => write!(f, "{what}: {reason}"),
        }
    }
}

impl core::error::Error for Error {}

/// The magnitude no signal or state value of a step may exceed (far from
/// f64's 1.8e308, so products of a few of them cannot overflow): a step that
/// would go beyond it returns [`Error::OutOfRange`] and changes nothing.
pub const BOUND: f64 = 1e100;

/// The magnitude no gain or physical parameter may exceed (SPEC §10,
/// extended): beyond it a configuration is accepted by the stability
/// conditions but overflows in use.
pub const PARAM_BOUND: f64 = 1e9;

impl Error {
    /// A short name of the error's kind, for a latched fault's reason.
    pub fn kind(&self) -> &'static str {
        match self {
            Error::Condition { .. } => "condition",
            Error::NonFinite { .. } => "non-finite input",
            Error::MissingVelocity => "missing velocity",
            Error::Diverged { .. } => "diverged",
            Error::OutOfRange { .. } => "out of range",
            Error::Faulted { .. } => "latched fault",
            Error::Invalid { .. } => "invalid",
        }
    }
}

/// Validation helpers shared by every constructor.
pub mod check {
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

    /// A finite scalar with `|v| ≤ bound`, else the named condition.
    pub fn at_most(
        condition: &'static str,
        what: &'static str,
        v: f64,
        bound: f64,
    ) -> Result<(), Error> {
        finite(what, v)?;
        if v.abs() <= bound {
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

    /// Every element finite with `|v_i| ≤ bound`, else the named condition
    /// naming the element and its value (not the margin).
    pub fn at_most_each(
        condition: &'static str,
        what: &'static str,
        v: &[f64],
        bound: f64,
    ) -> Result<(), Error> {
        finite_slice(what, v)?;
        match v.iter().position(|x| x.abs() > bound) {
            Some(i) => Err(Error::Condition {
                condition,
                lhs: what,
                index: Some(i),
                value: v[i],
            }),
            None => Ok(()),
        }
    }

    /// Every element with `|v_i| ≤ bound` (NaN never is), else
    /// `Error::OutOfRange` (inputs and signals of a step).
    pub fn within(what: &'static str, v: &[f64], bound: f64) -> Result<(), Error> {
        match v.iter().position(|x| x.is_nan() || x.abs() > bound) {
            Some(i) => Err(Error::OutOfRange {
                what,
                index: Some(i),
                value: v[i],
                limit: bound,
            }),
            None => Ok(()),
        }
    }

    /// Every element with `|v_i| ≤ limits_i` (NaN limits never hold).
    pub fn within_each(what: &'static str, v: &[f64], limits: &[f64]) -> Result<(), Error> {
        match v.iter().zip(limits).position(|(x, l)| x.abs() > *l) {
            Some(i) => Err(Error::OutOfRange {
                what,
                index: Some(i),
                value: v[i],
                limit: limits[i],
            }),
            None => Ok(()),
        }
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
    fn a_huge_value_is_written_in_scientific_notation() {
        let e = Error::Condition {
            condition: "|value| ≤ 1e9",
            lhs: "payload",
            index: None,
            value: 1e300,
        };
        assert_eq!(
            e.to_string(),
            "condition |value| ≤ 1e9 is violated: payload = 1e300 (SPEC §10)"
        );
    }

    #[test]
    fn a_bound_names_the_value_not_the_margin() {
        let e = check::at_most_each("|value| ≤ 1e9", "Kd", &[1.0, 1e10], PARAM_BOUND).unwrap_err();
        assert_eq!(
            e.to_string(),
            "condition |value| ≤ 1e9 is violated: Kd[1] = 10000000000 (SPEC §10)"
        );
        assert!(check::at_most_each("|value| ≤ 1e9", "Kd", &[-1e9, 1e9], PARAM_BOUND).is_ok());
        assert!(check::at_most_each("|value| ≤ 1e9", "Kd", &[f64::NAN], PARAM_BOUND).is_err());
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
