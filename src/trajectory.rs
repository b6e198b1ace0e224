//! Commanded trajectories xc(t), (64), SPEC §4.

use crate::error::{check, Error};
use crate::math::{cos, sin, sqrt};
use crate::types::Vector;
use core::cell::Cell;

/// Position, velocity and acceleration of a trajectory at one instant
/// (rad, rad/s, rad/s²).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Setpoint<const N: usize> {
    /// Position (rad).
    pub x: Vector<N>,
    /// Velocity (rad/s).
    pub dx: Vector<N>,
    /// Acceleration (rad/s²).
    pub ddx: Vector<N>,
}

/// A commanded trajectory, twice differentiable: xc(t), ẋc(t), ẍc(t).
///
/// Closures `Fn(f64) -> Setpoint<N>` are trajectories too.
pub trait Trajectory<const N: usize> {
    /// The setpoint at time `t` (s).
    fn sample(&self, t: f64) -> Setpoint<N>;

    /// The peak commanded speed ‖ẋc‖ (rad/s) and acceleration ‖ẍc‖ (rad/s²)
    /// over the trajectory, if known: `weight_bound = auto` derives the weight
    /// bounds from them (`WeightBound::Auto`).
    fn peak_rates(&self) -> Option<(f64, f64)> {
        None
    }
}

impl<const N: usize, F: Fn(f64) -> Setpoint<N>> Trajectory<N> for F {
    fn sample(&self, t: f64) -> Setpoint<N> {
        self(t)
    }
}

/// The clock of a loop that has no joint-space reference (a Cartesian run,
/// a controller of the caller's): the trajectory the loop samples at every
/// row, t_k written to the cell, NaN out. What the row commands is read
/// elsewhere at the row of t_k.
#[derive(Copy, Clone, Debug)]
pub struct Clock<'a>(pub &'a Cell<f64>);

impl<const N: usize> Trajectory<N> for Clock<'_> {
    fn sample(&self, t: f64) -> Setpoint<N> {
        self.0.set(t);
        let nan = Vector::from_element(f64::NAN);
        Setpoint {
            x: nan,
            dx: nan,
            ddx: nan,
        }
    }
}

/// A trajectory tabulated at t_k = k·Ts: K rows of N values each for xc,
/// ẋc, ẍc (row-major); row round(t/Ts) is the setpoint at t (beyond the
/// last row: NaN). The reference of a run whose setpoints were computed
/// before it (a table, a path written in another language).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Tabulated<'a, const N: usize> {
    /// xc, ẋc, ẍc, row-major K × N.
    pub rows: [&'a [f64]; 3],
    /// Ts (s).
    pub ts: f64,
}

impl<const N: usize> Trajectory<N> for Tabulated<'_, N> {
    fn sample(&self, t: f64) -> Setpoint<N> {
        let k = libm::round(t / self.ts) as usize;
        let row = |v: &[f64]| match v.get(k * N..(k + 1) * N) {
            Some(r) => Vector::from_column_slice(r),
            None => Vector::from_element(f64::NAN),
        };
        Setpoint {
            x: row(self.rows[0]),
            dx: row(self.rows[1]),
            ddx: row(self.rows[2]),
        }
    }
}

/// A controller's own sinusoid on its own clock: at a run's t = k·Ts, the
/// trajectory at (k0 + k)·Ts, k0 the steps the controller had taken before
/// the run (a used controller goes on where it was).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Continued<const N: usize> {
    /// The trajectory.
    pub traj: Sinusoid<N>,
    /// Steps taken before the run.
    pub k0: u64,
    /// Ts (s).
    pub ts: f64,
}

impl<const N: usize> Trajectory<N> for Continued<N> {
    fn sample(&self, t: f64) -> Setpoint<N> {
        let k = libm::round(t / self.ts) as u64;
        self.traj.sample((self.k0 + k) as f64 * self.ts)
    }
}

/// Per-joint sinusoid `x_i(t) = o_i + a_i sin(ω_i t) + b_i cos(ω_i t)`.
///
/// The paper's circle (64), `xc = [0.2 − 0.2 cos(πt), 0.2 + 0.2 sin(πt)]`,
/// is [`Sinusoid::paper`].
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Sinusoid<const N: usize> {
    offset: Vector<N>,
    sin: Vector<N>,
    cos: Vector<N>,
    omega: Vector<N>,
}

impl<const N: usize> Sinusoid<N> {
    /// Offset o (rad), sine and cosine amplitudes a, b (rad), angular frequency ω (rad/s).
    /// Every entry finite, and per joint, with r = √(a² + b²): |o| + r ≤ 1e6 rad,
    /// |ω| r ≤ 1e6 rad/s and ω² r ≤ 1e6 rad/s² (a trajectory beyond them
    /// overflows the controller's signals; the error names the bound).
    pub fn new(
        offset: Vector<N>,
        sin: Vector<N>,
        cos: Vector<N>,
        omega: Vector<N>,
    ) -> Result<Self, Error> {
        check::finite_slice("xc_offset", offset.as_slice())?;
        check::finite_slice("xc_sin", sin.as_slice())?;
        check::finite_slice("xc_cos", cos.as_slice())?;
        check::finite_slice("xc_omega", omega.as_slice())?;
        for i in 0..N {
            let r = sqrt(sin[i] * sin[i] + cos[i] * cos[i]);
            let w = omega[i].abs();
            check::at_most(
                "|xc| ≤ 1e6 rad",
                "xc_offset + amplitude",
                offset[i].abs() + r,
                1e6,
            )?;
            if r > 0.0 {
                check::at_most("|ẋc| ≤ 1e6 rad/s", "xc_omega · amplitude", w * r, 1e6)?;
                check::at_most("|ẍc| ≤ 1e6 rad/s²", "xc_omega² · amplitude", w * w * r, 1e6)?;
            }
        }
        Ok(Self {
            offset,
            sin,
            cos,
            omega,
        })
    }

    /// A constant setpoint at `x` (rad).
    pub fn constant(x: Vector<N>) -> Result<Self, Error> {
        Self::new(x, Vector::zeros(), Vector::zeros(), Vector::zeros())
    }

    /// Offset o (rad).
    pub fn offset(&self) -> &Vector<N> {
        &self.offset
    }
    /// Sine amplitudes a (rad).
    pub fn sin_amplitude(&self) -> &Vector<N> {
        &self.sin
    }
    /// Cosine amplitudes b (rad).
    pub fn cos_amplitude(&self) -> &Vector<N> {
        &self.cos
    }
    /// Angular frequencies ω (rad/s).
    pub fn omega(&self) -> &Vector<N> {
        &self.omega
    }

    /// The period 2π/ω (s) of the slowest joint that moves (a ≠ 0 or b ≠ 0,
    /// ω ≠ 0), or `None` if none does.
    pub fn period(&self) -> Option<f64> {
        let slowest = (0..N)
            .filter(|&i| (self.sin[i] != 0.0 || self.cos[i] != 0.0) && self.omega[i] != 0.0)
            .map(|i| self.omega[i].abs())
            .fold(f64::INFINITY, f64::min);
        slowest
            .is_finite()
            .then(|| 2.0 * core::f64::consts::PI / slowest)
    }
}

/// Samples per period for [`Sinusoid`]'s peak rates.
const PEAK_SAMPLES: usize = 4096;

impl<const N: usize> Trajectory<N> for Sinusoid<N> {
    /// Peak ‖ẋc‖ and ‖ẍc‖ from 4096 samples over one period of the slowest
    /// non-zero frequency (exact for the paper's circle, whose speed and
    /// acceleration are constant); (0, 0) if nothing moves.
    fn peak_rates(&self) -> Option<(f64, f64)> {
        let slowest = self
            .omega
            .iter()
            .map(|w| w.abs())
            .filter(|w| *w > 0.0)
            .fold(f64::INFINITY, f64::min);
        if !slowest.is_finite() {
            return Some((0.0, 0.0));
        }
        let period = 2.0 * core::f64::consts::PI / slowest;
        let (mut speed, mut accel) = (0.0f64, 0.0f64);
        for k in 0..PEAK_SAMPLES {
            let sp = self.sample(period * k as f64 / (PEAK_SAMPLES - 1) as f64);
            speed = speed.max(sp.dx.norm());
            accel = accel.max(sp.ddx.norm());
        }
        Some((speed, accel))
    }

    #[inline]
    fn sample(&self, t: f64) -> Setpoint<N> {
        let mut sp = Setpoint {
            x: self.offset,
            dx: Vector::zeros(),
            ddx: Vector::zeros(),
        };
        // Joints that share a frequency (the paper's circle) share one sin/cos.
        let (mut w_prev, mut s, mut c) = (f64::NAN, 0.0, 0.0);
        for i in 0..N {
            let w = self.omega[i];
            if w != w_prev {
                (s, c) = (sin(w * t), cos(w * t));
                w_prev = w;
            }
            let (a, b) = (self.sin[i], self.cos[i]);
            sp.x[i] += a * s + b * c;
            sp.dx[i] = w * (a * c - b * s);
            sp.ddx[i] = -w * w * (a * s + b * c);
        }
        sp
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    #[test]
    fn paper_circle_matches_64() {
        let tr = Sinusoid::paper();
        for &t in &[0.0, 0.3, 1.7, 12.25] {
            let sp = tr.sample(t);
            assert!((sp.x[0] - (0.2 - 0.2 * (PI * t).cos())).abs() < 1e-15);
            assert!((sp.x[1] - (0.2 + 0.2 * (PI * t).sin())).abs() < 1e-15);
            assert!((sp.dx[0] - 0.2 * PI * (PI * t).sin()).abs() < 1e-14);
            assert!((sp.dx[1] - 0.2 * PI * (PI * t).cos()).abs() < 1e-14);
            assert!((sp.ddx[0] - 0.2 * PI * PI * (PI * t).cos()).abs() < 1e-13);
            assert!((sp.ddx[1] + 0.2 * PI * PI * (PI * t).sin()).abs() < 1e-13);
        }
    }

    #[test]
    fn derivatives_are_consistent_by_finite_differences() {
        let tr = Sinusoid::<3>::new(
            Vector::<3>::new(0.1, -0.2, 0.3),
            Vector::<3>::new(0.5, 0.0, -0.1),
            Vector::<3>::new(0.0, 0.2, 0.4),
            Vector::<3>::new(1.0, 2.0, 3.0),
        )
        .unwrap();
        let (t, h) = (0.7, 1e-6);
        let (a, b, c) = (tr.sample(t - h), tr.sample(t), tr.sample(t + h));
        assert!(((c.x - a.x) / (2.0 * h) - b.dx).norm() < 1e-8);
        assert!(((c.dx - a.dx) / (2.0 * h) - b.ddx).norm() < 1e-7);
    }
}
