//! What a real loop needs around the control law (beyond the paper): the
//! command to apply when a step fails, the fault policy, plausibility limits
//! on the measurements, and a torque rate limit.
//!
//! - **Fallback** ([`Fallback`]): when a step fails, the caller still gets a
//!   torque: the last applied one held, zero, or joint damping `−Kd q̇`, each
//!   saturated ([`Controller::step_or_fallback`](crate::Controller::step_or_fallback)).
//! - **Fault policy** ([`FaultPolicy`]): every failed step records a fault
//!   (its reason and step) in the state. With `Report` the next step runs as
//!   usual; with `Latch` every step is refused (returning the fallback) until
//!   the caller clears the fault, the usual behaviour of a drive's safety
//!   state machine (IEC 61800-5-2: a detected fault holds a safe state until
//!   acknowledged).
//! - **Plausibility limits** ([`Limits`]): |q_i| ≤ q_max, |q̇_i| ≤ q̇_max,
//!   |τe_i| ≤ τe_max, and a jump |q_i(t_k) − q_i(t_{k−1})| ≤ q_jump_max (a
//!   jump no motion of the arm can make in one period: a glitch). The
//!   setpoint too: |xc_i| ≤ q_max, |ẋc_i| ≤ q̇_max. Where no limit is
//!   configured a ceiling still holds ([`CEILING_POSITION`] and its
//!   siblings). An input beyond one is an error, and the step changes
//!   nothing the control law uses.
//! - **Jump anchors**: the jump is measured from the last *accepted*
//!   position and from the last *measured* plausible position (every step
//!   call records it, refused or not); a sample is refused only if it jumped
//!   from both. A one-sample glitch is refused once; a real motion made
//!   during refused steps is accepted from its second sample.
//! - **Torque rate limit**: the commanded torque moves at most `tau_rate_max`
//!   (N m per step) from the torque last *applied* — the last step's sat(τ),
//!   or the fallback of a refused step after it — before saturation; the
//!   difference shows in Δτ = sat(τ) − τ, so the auxiliary system and the
//!   learning see it as they see saturation.
//!
//! The whole table of what a refusal changes is in `docs/reliability.md`.

use crate::control::impedance::Reference;
use crate::control::io::Measurement;
use crate::error::{check, Error};
use crate::trajectory::Setpoint;
use crate::types::{choices, Vector};

/// The torque to apply when a step fails.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum Fallback {
    /// Hold the last applied torque ("hold").
    #[default]
    Hold,
    /// Zero torque ("zero").
    Zero,
    /// Joint damping −Kd q̇ ("damping"), with the measured q̇ if it is finite
    /// and plausible, else the last velocity the controller used.
    Damping,
}

choices!(Fallback {
    "hold" => Fallback::Hold,
    "zero" => Fallback::Zero,
    "damping" => Fallback::Damping,
});

/// What a failed step does to the following ones.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum FaultPolicy {
    /// Record the fault; the next step runs as usual ("report").
    #[default]
    Report,
    /// Latch the fault: refuse every step (returning the fallback) until
    /// `clear_fault` ("latch").
    Latch,
}

choices!(FaultPolicy {
    "report" => FaultPolicy::Report,
    "latch" => FaultPolicy::Latch,
});

/// Where no position limit `q_max` is configured, a position (measured,
/// commanded, the reference xd, a jump anchor) is still at most this (rad):
/// as for the configured trajectory (SPEC §14).
pub const CEILING_POSITION: f64 = 1e6;
/// The same for a velocity (measured, commanded, ẋd) without `dq_max` (rad/s).
pub const CEILING_VELOCITY: f64 = 1e6;
/// The commanded acceleration ẍc is at most this (rad/s²).
pub const CEILING_ACCELERATION: f64 = 1e6;
/// The measured τe without `tau_e_max` is at most this (N m): the magnitude
/// of any physical parameter ([`PARAM_BOUND`](crate::error::PARAM_BOUND)).
pub const CEILING_TORQUE: f64 = crate::error::PARAM_BOUND;

/// A recorded fault: the error and the step (k of t_k) it happened at.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Fault {
    /// The error.
    pub error: Error,
    /// The step count k at which it happened.
    pub step: u64,
}

/// Plausibility limits and the torque rate limit, per joint; infinity means
/// no limit.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Limits<const N: usize> {
    /// |q_i| ≤ q_max_i (rad).
    pub q: Vector<N>,
    /// |q̇_i| ≤ q̇_max_i (rad/s).
    pub dq: Vector<N>,
    /// |τe_i| ≤ τe_max_i (N m).
    pub tau_e: Vector<N>,
    /// |q_i(t_k) − q_i(t_{k−1})| ≤ q_jump_max_i (rad).
    pub q_jump: Vector<N>,
    /// |τ_i(t_k) − sat(τ)_i(t_{k−1})| ≤ tau_rate_max_i (N m per step).
    pub tau_rate: Vector<N>,
}

impl<const N: usize> Limits<N> {
    /// No limit at all.
    pub fn none() -> Self {
        let inf = Vector::from_element(f64::INFINITY);
        Self {
            q: inf,
            dq: inf,
            tau_e: inf,
            q_jump: inf,
            tau_rate: inf,
        }
    }

    /// Every limit > 0 (infinity: none); the error names it.
    pub fn validate(&self) -> Result<(), Error> {
        for (name, v) in [
            ("q_max", &self.q),
            ("dq_max", &self.dq),
            ("tau_e_max", &self.tau_e),
            ("q_jump_max", &self.q_jump),
            ("tau_rate_max", &self.tau_rate),
        ] {
            if let Some(i) = v.iter().position(|x| x.is_nan()) {
                return Err(Error::NonFinite {
                    what: name,
                    index: i,
                });
            }
            check::each("limit > 0", name, v, |_, x| x, true)?;
        }
        Ok(())
    }

    /// The bound on a position (rad): `q_max`, at most [`CEILING_POSITION`].
    pub fn position(&self) -> Vector<N> {
        self.q.map(|l| l.min(CEILING_POSITION))
    }
    /// The bound on a velocity (rad/s): `dq_max`, at most [`CEILING_VELOCITY`].
    pub fn velocity(&self) -> Vector<N> {
        self.dq.map(|l| l.min(CEILING_VELOCITY))
    }
    /// The bound on the measured τe (N m): `tau_e_max`, at most [`CEILING_TORQUE`].
    pub fn force(&self) -> Vector<N> {
        self.tau_e.map(|l| l.min(CEILING_TORQUE))
    }

    /// The measurement within the limits (each at most its ceiling), and its
    /// position within `q_jump_max` of one of the `anchors` (none at the
    /// first step): the last accepted position and the last measured one.
    pub fn check(&self, m: &Measurement<N>, anchors: Option<[&Vector<N>; 2]>) -> Result<(), Error> {
        check::within_each("q", m.x.as_slice(), self.position().as_slice())?;
        if let Some(dq) = &m.dx {
            check::within_each("dq", dq.as_slice(), self.velocity().as_slice())?;
        }
        check::within_each("tau_e", m.tau_e.as_slice(), self.force().as_slice())?;
        if let Some([accepted, seen]) = anchors {
            let from_seen = m.x - seen;
            if check::within_each("q jump", from_seen.as_slice(), self.q_jump.as_slice()).is_err() {
                let jump = m.x - accepted;
                check::within_each("q jump", jump.as_slice(), self.q_jump.as_slice())?;
            }
        }
        Ok(())
    }

    /// True if `x` is a position the jump limit may be measured from: finite
    /// and within the position bound.
    pub fn plausible_position(&self, x: &Vector<N>) -> bool {
        x.iter()
            .zip(self.position().iter())
            .all(|(x, l)| x.is_finite() && x.abs() <= *l)
    }

    /// The setpoint within the limits: |xc_i| ≤ q_max_i, |ẋc_i| ≤ dq_max_i
    /// (each at most its ceiling) and |ẍc_i| ≤ [`CEILING_ACCELERATION`]: a
    /// setpoint the arm may not take is refused like a measurement.
    pub fn check_setpoint(&self, c: &Setpoint<N>) -> Result<(), Error> {
        check::within_each("xc", c.x.as_slice(), self.position().as_slice())?;
        check::within_each("dxc", c.dx.as_slice(), self.velocity().as_slice())?;
        let a = Vector::<N>::from_element(CEILING_ACCELERATION);
        check::within_each("ddxc", c.ddx.as_slice(), a.as_slice())
    }

    /// The compliant reference a step would commit within the ceilings
    /// (|xd_i| ≤ [`CEILING_POSITION`], |ẋd_i| ≤ [`CEILING_VELOCITY`]): a
    /// reference beyond them (e.g. driven by a huge τe) would make every later
    /// step fail, so the step that would commit it is refused instead.
    pub fn check_reference(&self, r: &Reference<N>) -> Result<(), Error> {
        check::within("xd", r.xd.as_slice(), CEILING_POSITION)?;
        check::within("dxd", r.dxd.as_slice(), CEILING_VELOCITY)
    }

    /// `tau` moved at most `tau_rate_max` from `last` (N m).
    #[inline]
    pub fn rate_limit(&self, tau: &Vector<N>, last: &Vector<N>) -> Vector<N> {
        Vector::from_fn(|i, _| {
            let r = self.tau_rate[i];
            tau[i].clamp(last[i] - r, last[i] + r)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_name_the_quantity_and_the_joint() {
        let mut l = Limits::<2>::none();
        l.q = Vector::<2>::new(1.0, 2.0);
        l.q_jump = Vector::from_element(0.1);
        let m = Measurement {
            x: Vector::<2>::new(0.5, -2.5),
            dx: None,
            tau_e: Vector::zeros(),
        };
        let e = l.check(&m, None).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("q[1] = -2.5e0 is beyond its limit ±2e0"),
            "{e}"
        );
        let ok = Measurement {
            x: Vector::<2>::new(0.5, 0.0),
            ..m
        };
        let (near, far) = (Vector::<2>::new(0.45, 0.0), Vector::<2>::new(0.3, 0.0));
        assert!(l.check(&ok, Some([&near, &near])).is_ok());
        // Within the jump limit of either anchor is enough.
        assert!(l.check(&ok, Some([&far, &near])).is_ok());
        assert!(l.check(&ok, Some([&near, &far])).is_ok());
        let e = l.check(&ok, Some([&far, &far])).unwrap_err();
        assert!(e.to_string().starts_with("q jump[0]"), "{e}");
        l.tau_rate = Vector::from_element(1.0);
        let t = l.rate_limit(&Vector::<2>::new(5.0, -0.5), &Vector::<2>::new(0.0, 0.0));
        assert_eq!(t, Vector::<2>::new(1.0, -0.5));
        l.dq[0] = 0.0;
        assert!(l.validate().unwrap_err().to_string().contains("limit > 0"));
    }
}
