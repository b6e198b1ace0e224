//! A run-time step's typed input and output (ruckig's input and output
//! parameters): [`Measurement`] and [`Setpoint`] borrow the caller's n
//! values per quantity; [`Command`] gives n values per quantity by value,
//! in [`Joints`] (no allocation, no buffer to keep).

use super::MAX_JOINTS;
use crate::control::io;
use crate::error::Error;
use crate::trajectory;
use crate::types::Vector;
use core::ops::{Deref, DerefMut};

/// n values, one per joint (n ≤ [`MAX_JOINTS`]), by value: a joint
/// quantity of a step's output. Reads as the slice of its n values.
#[derive(Copy, Clone)]
pub struct Joints {
    n: usize,
    v: [f64; MAX_JOINTS],
}

impl Joints {
    /// n zeros (n ≤ [`MAX_JOINTS`], else an error naming `n`).
    pub fn zeros(n: usize) -> Result<Self, Error> {
        if n > MAX_JOINTS {
            return Err(too_many(n));
        }
        Ok(Self {
            n,
            v: [0.0; MAX_JOINTS],
        })
    }

    /// A copy of `v` (at most [`MAX_JOINTS`] values).
    pub fn from_slice(v: &[f64]) -> Result<Self, Error> {
        let mut j = Self::zeros(v.len())?;
        j.copy_from_slice(v);
        Ok(j)
    }

    /// The n values.
    pub fn as_slice(&self) -> &[f64] {
        &self.v[..self.n]
    }

    /// The n values, to change.
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.v[..self.n]
    }

    /// The core's vector of `v`'s N values.
    pub(crate) fn of<const N: usize>(v: &Vector<N>) -> Self {
        let mut out = [0.0; MAX_JOINTS];
        out[..N].copy_from_slice(v.as_slice());
        Self { n: N, v: out }
    }

    /// The N values as the core's vector (N = n).
    pub(crate) fn vector<const N: usize>(&self) -> Vector<N> {
        Vector::from_column_slice(&self.v[..N])
    }
}

impl Deref for Joints {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        self.as_slice()
    }
}

impl DerefMut for Joints {
    fn deref_mut(&mut self) -> &mut [f64] {
        self.as_mut_slice()
    }
}

impl PartialEq for Joints {
    fn eq(&self, other: &Self) -> bool {
        self.as_slice() == other.as_slice()
    }
}

impl core::fmt::Debug for Joints {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        self.as_slice().fmt(f)
    }
}

/// The error of a count of joints beyond what the run-time API is built for.
pub(crate) fn too_many(n: usize) -> Error {
    Error::Condition {
        condition: "1 ≤ n ≤ 7 joints",
        lhs: "n",
        index: None,
        value: n as f64,
    }
}

/// The error of an input with another number of values than the joints.
pub(crate) fn length(what: &'static str) -> Error {
    Error::Invalid {
        what,
        reason: "needs one value per joint (as many as the controller has)",
    }
}

/// The error of two objects made for different numbers of joints.
pub(crate) fn mismatch(what: &'static str) -> Error {
    Error::Invalid {
        what,
        reason: "was made for another number of joints",
    }
}

/// `v` as the core's vector of N values, or the [`length`] error naming `what`.
pub(crate) fn vector<const N: usize>(what: &'static str, v: &[f64]) -> Result<Vector<N>, Error> {
    if v.len() != N {
        return Err(length(what));
    }
    Ok(Vector::from_column_slice(v))
}

/// One sample from the sensors at t_k, n values each: the run-time
/// [`Measurement`](crate::Measurement).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Measurement<'a> {
    /// Joint position x (rad).
    pub x: &'a [f64],
    /// Joint velocity ẋ (rad/s): required by PD and state feedback, ignored
    /// by output feedback (which estimates it).
    pub dx: Option<&'a [f64]>,
    /// Force the robot exerts on the environment τe (N m).
    pub tau_e: &'a [f64],
}

impl Measurement<'_> {
    /// The core's measurement of N joints; an input of another length is
    /// refused by name (`x`, `dx`, `tau_e`).
    pub(crate) fn typed<const N: usize>(&self) -> Result<io::Measurement<N>, Error> {
        Ok(io::Measurement {
            x: vector("x", self.x)?,
            dx: self.dx.map(|d| vector("dx", d)).transpose()?,
            tau_e: vector("tau_e", self.tau_e)?,
        })
    }
}

/// Position, velocity and acceleration of a joint trajectory at one
/// instant (rad, rad/s, rad/s²), n values each: borrowed slices
/// (`Setpoint<&[f64]>`) going into a step, [`Joints`] coming out.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Setpoint<V = Joints> {
    /// Position (rad).
    pub x: V,
    /// Velocity (rad/s).
    pub dx: V,
    /// Acceleration (rad/s²).
    pub ddx: V,
}

impl Setpoint<&[f64]> {
    /// The core's setpoint of N joints; another length is refused by name
    /// (`xc`, `dxc`, `ddxc`).
    pub(crate) fn typed<const N: usize>(&self) -> Result<trajectory::Setpoint<N>, Error> {
        Ok(trajectory::Setpoint {
            x: vector("xc", self.x)?,
            dx: vector("dxc", self.dx)?,
            ddx: vector("ddxc", self.ddx)?,
        })
    }
}

impl Setpoint<Joints> {
    /// The run-time setpoint of the core's.
    pub(crate) fn of<const N: usize>(c: &trajectory::Setpoint<N>) -> Self {
        Self {
            x: Joints::of(&c.x),
            dx: Joints::of(&c.dx),
            ddx: Joints::of(&c.ddx),
        }
    }

    /// Borrowed, as a step takes it.
    pub fn as_slices(&self) -> Setpoint<&[f64]> {
        Setpoint {
            x: self.x.as_slice(),
            dx: self.dx.as_slice(),
            ddx: self.ddx.as_slice(),
        }
    }
}

/// What one step computed, n values per joint quantity: the run-time
/// [`Command`](crate::Command). `tau_sat` goes to the actuators.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Command {
    /// Applied torque sat(τ) (N m).
    pub tau_sat: Joints,
    /// Commanded torque τ before saturation (N m).
    pub tau: Joints,
    /// Δτ = sat(τ) − τ (N m).
    pub dtau: Joints,
    /// Tracking error z1 = xd − x (rad), (6).
    pub z1: Joints,
    /// z2 = α1 − v (rad/s), (8); ẑ2 for output feedback.
    pub z2: Joints,
    /// Commanded position xc(t_k) (rad).
    pub xc: Joints,
    /// Compliant reference xd(t_k) (rad).
    pub xd: Joints,
    /// Velocity the controller used (rad/s): measured, or the observer's estimate.
    pub v: Joints,
    /// Auxiliary state ζ(t_k) (N m) used in this step.
    pub zeta: Joints,
    /// Frobenius norms ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ before this step's update (zero for PD).
    pub w_norms: [f64; 3],
}

impl Command {
    /// The run-time command of the core's.
    pub(crate) fn of<const N: usize>(c: &io::Command<N>) -> Self {
        Self {
            tau_sat: Joints::of(&c.tau_sat),
            tau: Joints::of(&c.tau),
            dtau: Joints::of(&c.dtau),
            z1: Joints::of(&c.z1),
            z2: Joints::of(&c.z2),
            xc: Joints::of(&c.xc),
            xd: Joints::of(&c.xd),
            v: Joints::of(&c.v),
            zeta: Joints::of(&c.zeta),
            w_norms: c.w_norms,
        }
    }

    /// The core's command of N joints (N = n).
    #[cfg(feature = "sim")]
    pub(crate) fn vector<const N: usize>(&self) -> io::Command<N> {
        io::Command {
            tau_sat: self.tau_sat.vector(),
            tau: self.tau.vector(),
            dtau: self.dtau.vector(),
            z1: self.z1.vector(),
            z2: self.z2.vector(),
            xc: self.xc.vector(),
            xd: self.xd.vector(),
            v: self.v.vector(),
            zeta: self.zeta.vector(),
            w_norms: self.w_norms,
        }
    }

    /// All zeros for n joints (the "last command" before the first step).
    pub fn zeros(n: usize) -> Result<Self, Error> {
        let z = Joints::zeros(n)?;
        Ok(Self {
            tau_sat: z,
            tau: z,
            dtau: z,
            z1: z,
            z2: z,
            xc: z,
            xd: z,
            v: z,
            zeta: z,
            w_norms: [0.0; 3],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joints_read_as_their_n_values_and_refuse_more_than_the_largest_count() {
        let j = Joints::from_slice(&[1.0, 2.0, 3.0]).unwrap();
        assert_eq!(&*j, &[1.0, 2.0, 3.0]);
        assert_eq!(j.len(), 3);
        assert_eq!(format!("{j:?}"), "[1.0, 2.0, 3.0]");
        let e = Joints::from_slice(&[0.0; 8]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "condition 1 ≤ n ≤ 7 joints is violated: n = 8 (SPEC §10)"
        );
        let m = Measurement {
            x: &[0.0; 2],
            dx: Some(&[0.0; 3]),
            tau_e: &[0.0; 2],
        };
        assert_eq!(
            m.typed::<2>().unwrap_err().to_string(),
            "dx: needs one value per joint (as many as the controller has)"
        );
    }
}
