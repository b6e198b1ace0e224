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

/// The metrics of a pose task, SPEC (16.11), over rows t_k with the
/// position error e_p = ‖p_c − p‖ (m) and the orientation error e_o =
/// ‖Log(R_c Rᵀ)‖ (rad) of the tip (p, R) against the commanded pose (p_c,
/// R_c) ([`pose_error`]). "after" means t_k ≥ `settle` (− 1e-9 s), and a
/// window [a, b) the rows with a − 1e-9 ≤ t_k < b − 1e-9. Means over no row
/// are NaN.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PoseMetrics {
    /// Number of rows K.
    pub rows: usize,
    /// RMS e_p over the whole run (m).
    pub rms_pos: f64,
    /// RMS e_p over t ≥ settle (m).
    pub rms_pos_after2: f64,
    /// max e_p over t ≥ settle (m).
    pub max_pos_after2: f64,
    /// RMS e_o over the whole run (rad).
    pub rms_rot: f64,
    /// RMS e_o over t ≥ settle (rad).
    pub rms_rot_after2: f64,
    /// max e_o over t ≥ settle (rad).
    pub max_rot_after2: f64,
    /// RMS e_p over the first window [settle, settle + 2 s) (m).
    pub rms_pos_first2: f64,
    /// RMS e_p over the last 2 s of the rows, [t_K−1 + Ts − 2 s, end) (m):
    /// with `rms_pos_first2`, whether learning goes on.
    pub rms_pos_last2: f64,
}

/// The pose errors of the tip (p (m), rotation `r`) against the commanded
/// (p_c, R_c): (‖p_c − p‖ (m), ‖Log(R_c Rᵀ)‖ (rad)), SPEC (16.2).
pub fn pose_error(
    p: &Vector<3>,
    r: &nalgebra::UnitQuaternion<f64>,
    pc: &Vector<3>,
    rc: &nalgebra::UnitQuaternion<f64>,
) -> (f64, f64) {
    (
        (pc - p).norm(),
        crate::cartesian::rotation::rotation_error(rc, r).norm(),
    )
}

/// [`PoseMetrics`] of rows given at once: `t` (s), `pos` (m) and `rot`
/// (rad) per row, the window start `settle` (s) and the period `ts` (s)
/// (the last window ends one period after the last row).
pub fn pose_metrics(t: &[f64], pos: &[f64], rot: &[f64], settle: f64, ts: f64) -> PoseMetrics {
    let k = t.len().min(pos.len()).min(rot.len());
    let end = if k == 0 { f64::NAN } else { t[k - 1] + ts };
    let window = |a: f64, b: f64, x: &[f64], f: fn(f64, f64) -> f64, init: f64| {
        let (mut acc, mut n) = (init, 0usize);
        for i in 0..k {
            if t[i] >= a - 1e-9 && t[i] < b - 1e-9 {
                acc = f(acc, x[i]);
                n += 1;
            }
        }
        (acc, n)
    };
    let rms = |a: f64, b: f64, x: &[f64]| {
        let (s, n) = window(a, b, x, |s, v| s + v * v, 0.0);
        if n == 0 {
            f64::NAN
        } else {
            sqrt(s / n as f64)
        }
    };
    let max = |a: f64, b: f64, x: &[f64]| {
        let (m, n) = window(a, b, x, f64::max, 0.0);
        if n == 0 {
            f64::NAN
        } else {
            m
        }
    };
    let all = f64::NEG_INFINITY;
    let inf = f64::INFINITY;
    PoseMetrics {
        rows: k,
        rms_pos: rms(all, inf, pos),
        rms_pos_after2: rms(settle, inf, pos),
        max_pos_after2: max(settle, inf, pos),
        rms_rot: rms(all, inf, rot),
        rms_rot_after2: rms(settle, inf, rot),
        max_rot_after2: max(settle, inf, rot),
        rms_pos_first2: rms(settle, settle + 2.0, pos),
        rms_pos_last2: rms(end - 2.0, inf, pos),
    }
}

#[cfg(test)]
mod pose_tests {
    use super::*;

    #[test]
    fn pose_metrics_average_over_their_windows() {
        let ts = 0.5;
        let t: std::vec::Vec<f64> = (0..12).map(|k| k as f64 * ts).collect();
        let pos: std::vec::Vec<f64> = (0..12).map(|k| if k < 4 { 10.0 } else { 1.0 }).collect();
        let rot: std::vec::Vec<f64> = (0..12).map(|k| k as f64).collect();
        let m = pose_metrics(&t, &pos, &rot, 2.0, ts);
        assert_eq!(m.rows, 12);
        assert_eq!(m.rms_pos_after2, 1.0);
        assert_eq!(m.max_pos_after2, 1.0);
        assert_eq!(m.max_rot_after2, 11.0);
        // [2, 4): rows 4…7; the last 2 s of a run that ends at 6 s: rows 8…11.
        assert_eq!(m.rms_pos_first2, 1.0);
        assert_eq!(
            m.rms_rot_after2,
            (((16 + 25 + 36 + 49 + 64 + 81 + 100 + 121) as f64) / 8.0).sqrt()
        );
        assert!((m.rms_pos - ((4.0 * 100.0 + 8.0) / 12.0f64).sqrt()).abs() < 1e-15);
        let short = pose_metrics(&t[..3], &pos[..3], &rot[..3], 2.0, ts);
        assert!(short.rms_pos_after2.is_nan() && short.max_rot_after2.is_nan());
        let q = nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, 0.3);
        let (ep, eo) = pose_error(
            &Vector::<3>::new(1.0, 2.0, 3.0),
            &q,
            &Vector::<3>::new(1.0, 2.0, 3.5),
            &nalgebra::UnitQuaternion::identity(),
        );
        assert!((ep - 0.5).abs() < 1e-15 && (eo - 0.3).abs() < 1e-15);
    }
}
