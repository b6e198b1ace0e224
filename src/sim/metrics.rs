//! The figures of SPEC §12, accumulated row by row without allocation: a
//! [`Recorder`].

use crate::control::impedance::TargetImpedance;
use crate::math::sqrt;
use crate::sim::record::{Recorder, Row};
use crate::trajectory::Setpoint;
use crate::types::Vector;

/// SPEC §12 metrics of one run. "after" means rows with t_k ≥ `settle`
/// (2 s by default; a row counts if t_k ≥ settle − 1e-9 s). Means over an
/// empty set are NaN.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Metrics<const N: usize> {
    /// Number of rows K.
    pub rows: usize,
    /// RMS ‖z1‖ over the whole run (rad).
    pub rms_z1: f64,
    /// RMS ‖z1‖ over t ≥ settle (rad).
    pub rms_z1_after2: f64,
    /// Per-joint RMS z1_i over t ≥ settle (rad).
    pub rms_z1_joint_after2: Vector<N>,
    /// Per-joint max |z1_i| over t ≥ settle (rad).
    pub max_abs_z1_joint_after2: Vector<N>,
    /// Fraction of rows with any Δτ_i ≠ 0.
    pub sat_duty: f64,
    /// Rows with τe ≠ 0.
    pub steps_in_contact: usize,
    /// Peak ‖τe‖ over t ≥ settle (N m).
    pub peak_contact_after2: f64,
    /// Mean ‖τe‖ over the rows in contact (N m).
    pub mean_contact: f64,
    /// Peak commanded |τ_i| per joint over the run (N m): windup shows here.
    pub peak_abs_tau: Vector<N>,
    /// RMS over t ≥ settle of ‖Dd(ẍc − ẍ) + Cd(ẋc − ẋ) + Gd(xc − x) − τe‖ (N m).
    pub imp_err_rms_after2: f64,
}

/// Running sums for [`Metrics`]; feed it every row with [`push`](Self::push)
/// (or use it as a [`Recorder`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct MetricsAccumulator<const N: usize> {
    settle: f64,
    target: TargetImpedance<N>,
    rows: usize,
    rows_after: usize,
    sum_z1: f64,
    sum_z1_after: f64,
    sum_joint_after: Vector<N>,
    max_joint_after: Vector<N>,
    sat_rows: usize,
    contact_rows: usize,
    peak_contact_after: f64,
    sum_contact: f64,
    peak_tau: Vector<N>,
    sum_imp_after: f64,
}

impl<const N: usize> MetricsAccumulator<N> {
    /// Start empty; `settle` (s) is where the "after" figures begin (SPEC §12:
    /// 2 s); `target` is the impedance the residual is measured against.
    pub fn new(settle: f64, target: TargetImpedance<N>) -> Self {
        Self {
            settle,
            target,
            rows: 0,
            rows_after: 0,
            sum_z1: 0.0,
            sum_z1_after: 0.0,
            sum_joint_after: Vector::zeros(),
            max_joint_after: Vector::zeros(),
            sat_rows: 0,
            contact_rows: 0,
            peak_contact_after: 0.0,
            sum_contact: 0.0,
            peak_tau: Vector::zeros(),
            sum_imp_after: 0.0,
        }
    }

    /// Add one row.
    pub fn push(&mut self, row: &Row<N>) {
        let after = row.t >= self.settle - 1e-9;
        let z2 = row.z1.norm_squared();
        self.rows += 1;
        self.sum_z1 += z2;
        if row.dtau.iter().any(|d| *d != 0.0) {
            self.sat_rows += 1;
        }
        let contact = row.tau_e.norm();
        if row.tau_e.iter().any(|f| *f != 0.0) {
            self.contact_rows += 1;
            self.sum_contact += contact;
        }
        self.peak_tau = self.peak_tau.zip_map(&row.tau, |p, t| p.max(t.abs()));
        if after {
            self.rows_after += 1;
            self.sum_z1_after += z2;
            self.sum_joint_after += row.z1.component_mul(&row.z1);
            self.max_joint_after = self.max_joint_after.zip_map(&row.z1, |m, z| m.max(z.abs()));
            self.peak_contact_after = self.peak_contact_after.max(contact);
            let c = Setpoint {
                x: row.xc,
                dx: row.dxc,
                ddx: row.ddxc,
            };
            let residual = self
                .target
                .residual(&c, &row.x, &row.dx, &row.ddx, &row.tau_e);
            self.sum_imp_after += residual.norm_squared();
        }
    }

    /// The metrics of the rows so far.
    pub fn finish(&self) -> Metrics<N> {
        let mean = |s: f64, n: usize| if n == 0 { f64::NAN } else { s / n as f64 };
        let ka = self.rows_after;
        Metrics {
            rows: self.rows,
            rms_z1: sqrt(mean(self.sum_z1, self.rows)),
            rms_z1_after2: sqrt(mean(self.sum_z1_after, ka)),
            rms_z1_joint_after2: self.sum_joint_after.map(|s| sqrt(mean(s, ka))),
            max_abs_z1_joint_after2: if ka == 0 {
                Vector::from_element(f64::NAN)
            } else {
                self.max_joint_after
            },
            sat_duty: mean(self.sat_rows as f64, self.rows),
            steps_in_contact: self.contact_rows,
            peak_contact_after2: if ka == 0 {
                f64::NAN
            } else {
                self.peak_contact_after
            },
            mean_contact: if self.contact_rows == 0 {
                0.0
            } else {
                self.sum_contact / self.contact_rows as f64
            },
            peak_abs_tau: self.peak_tau,
            imp_err_rms_after2: sqrt(mean(self.sum_imp_after, ka)),
        }
    }
}

impl<const N: usize> Recorder<N> for MetricsAccumulator<N> {
    fn record(&mut self, row: &Row<N>) {
        self.push(row);
    }
}
