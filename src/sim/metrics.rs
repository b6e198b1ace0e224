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

/// The rows of a task-space run that the table's metrics read, SPEC (19.7):
/// flat, row-major, K rows each (every period's row: the chatter is sample
/// to sample).
#[derive(Copy, Clone, Debug)]
pub struct TableRows<'a> {
    /// t_k (s), K.
    pub t: &'a [f64],
    /// The tip p (m), K × 3.
    pub p: &'a [f64],
    /// Its velocity ṗ = J q̇ (m/s), K × 3.
    pub dp: &'a [f64],
    /// Its acceleration p̈ = J q̈ + J̇ q̇ (m/s²), K × 3.
    pub ddp: &'a [f64],
    /// The compliant reference p_d (m), K × 3.
    pub pd: &'a [f64],
    /// The commanded p_c, ṗ_c, p̈_c (m, m/s, m/s²), K × 3 each.
    pub pc: [&'a [f64]; 3],
    /// The wrench the controller was given, F_e = [f; m] (N, N m), K × 6.
    pub wrench: &'a [f64],
    /// The normal force on the table F_n = −F_e,z at the plant (N), K.
    pub normal: &'a [f64],
    /// Commanded τ and applied sat(τ) (N m), K × n each.
    pub tau: [&'a [f64]; 2],
}

/// What the table's metrics compare against, SPEC (19.7).
#[derive(Copy, Clone, Debug)]
pub struct TableSpec<'a> {
    /// τmax (N m), n.
    pub tau_max: &'a [f64],
    /// The target impedance M_d, B_d, K_d (kg, N s/m, N/m), per axis.
    pub md: [f64; 3],
    /// B_d.
    pub bd: [f64; 3],
    /// K_d.
    pub kd: [f64; 3],
    /// The commanded depth δ_c (m).
    pub depth: f64,
    /// The stiffness in series with the depth (N/m): K_d,z on a rigid table,
    /// K_d k_e/(K_d + k_e) on a spring of k_e (16.1).
    pub series: f64,
    /// The start of the averaging window (s).
    pub settle: f64,
    /// The peak commanded torque counts from here (s).
    pub windup_after: f64,
    /// The approach's end, the commanded point δ_c into the table (s).
    pub approach_end: f64,
    /// The period (s).
    pub ts: f64,
}

/// The table's metrics of a run, SPEC (19.7) (docs/contact.md, docs/panda.md):
/// over t ≥ settle unless said.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TableMetrics {
    /// RMS ‖p_d − p‖ (m).
    pub rms_track: f64,
    /// RMS ‖(p_d − p)_xy‖ (m): along the table.
    pub rms_track_along: f64,
    /// RMS ‖(p_c − p)_xy‖ (m): the path on the table against the commanded.
    pub rms_path_xy: f64,
    /// RMS (−f_z − K_d,z δ_c) of the wrench the controller got (N).
    pub rms_force: f64,
    /// RMS ‖M_d (p̈ − p̈_c) + B_d (ṗ − ṗ_c) + K_d (p − p_c) + f‖ (N): the
    /// residual of the target impedance (C1) at the arm's motion.
    pub rms_imp: f64,
    /// The force the impedance prescribes, `series`·δ_c (N).
    pub force_target: f64,
    /// RMS (F_n − target) (N).
    pub force_rms_err: f64,
    /// RMS (F_n,k+1 − F_n,k) (N).
    pub force_chatter: f64,
    /// Mean F_n (N).
    pub force_mean: f64,
    /// (16.1) with the measured mean n·e: `series`·(δ_c + mean(p_d,z − p_z)) (N).
    pub force_16_1: f64,
    /// max F_n over the whole run (N).
    pub peak_force: f64,
    /// Time (s) with F_n ≤ 0 after the first contact at or after the
    /// approach's end (all of it after, if none; NaN for a run ending before).
    pub contact_lost: f64,
    /// The share of all rows with sat(τ_i) ≠ τ_i on some joint.
    pub sat_duty: f64,
    /// max_i max_{t ≥ windup_after} |τ_i|/τmax_i, commanded.
    pub peak_tau_ratio: f64,
    /// max_i max_k |sat(τ)_i|/τmax_i, applied (≤ 1).
    pub applied_ratio: f64,
}

/// [`TableMetrics`] of `rows` against `spec`. Errors for rows of unequal
/// length, no row, or τmax of another length than τ's width.
pub fn table_metrics(
    rows: &TableRows<'_>,
    spec: &TableSpec<'_>,
) -> Result<TableMetrics, crate::error::Error> {
    let (k, n) = table_widths(rows, spec)?;
    let target = spec.series * spec.depth;
    let s = TableSums::settled(rows, spec, k, target);
    let avg = |s: f64, m: usize| if m == 0 { f64::NAN } else { s / m as f64 };
    let rms = |s: f64, m: usize| sqrt(avg(s, m));
    let contact_lost = table_contact_lost(rows, spec, k);
    let (sat, peak, applied) = table_torque(rows, spec, k, n);
    Ok(TableMetrics {
        rms_track: rms(s.track, s.n_after),
        rms_track_along: rms(s.along, s.n_after),
        rms_path_xy: rms(s.path, s.n_after),
        rms_force: rms(s.force, s.n_after),
        rms_imp: rms(s.imp, s.n_after),
        force_target: target,
        force_rms_err: rms(s.err, s.n_after),
        force_chatter: rms(s.chatter, s.n_chatter),
        force_mean: avg(s.mean, s.n_after),
        force_16_1: spec.series * (spec.depth + avg(s.ne, s.n_after)),
        peak_force: rows
            .normal
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max),
        contact_lost,
        sat_duty: sat as f64 / k as f64,
        peak_tau_ratio: peak,
        applied_ratio: applied,
    })
}

/// The row count K and the joint count n of a table run, SPEC (19.7):
/// errors unless K ≥ 1, n ≥ 1 and every quantity has K rows at its width.
fn table_widths(
    rows: &TableRows<'_>,
    spec: &TableSpec<'_>,
) -> Result<(usize, usize), crate::error::Error> {
    let k = rows.t.len();
    let n = spec.tau_max.len();
    let sized = |v: &[f64], w: usize| v.len() == k * w;
    let ok = k > 0
        && n > 0
        && sized(rows.p, 3)
        && sized(rows.dp, 3)
        && sized(rows.ddp, 3)
        && sized(rows.pd, 3)
        && rows.pc.iter().all(|v| sized(v, 3))
        && sized(rows.wrench, 6)
        && sized(rows.normal, 1)
        && rows.tau.iter().all(|v| sized(v, n));
    if !ok {
        return Err(crate::error::Error::Invalid {
            what: "table metrics",
            reason: "need K ≥ 1 rows of every quantity at its width, and τmax of τ's width",
        });
    }
    Ok((k, n))
}

/// The sums of SPEC (19.7)'s settled figures over the rows t_k ≥ `settle`
/// (the chatter's over consecutive pairs from there), in row order.
struct TableSums {
    n_after: usize,
    track: f64,
    along: f64,
    path: f64,
    force: f64,
    imp: f64,
    err: f64,
    mean: f64,
    ne: f64,
    chatter: f64,
    n_chatter: usize,
}

impl TableSums {
    /// Accumulate the settled rows of a checked table run of `k` rows:
    /// tracking, path, force and the impedance residual (C1), against the
    /// prescribed force `target` (SPEC (19.7), (16.1)).
    fn settled(rows: &TableRows<'_>, spec: &TableSpec<'_>, k: usize, target: f64) -> Self {
        let v3 = |a: &[f64], i: usize| Vector::<3>::new(a[3 * i], a[3 * i + 1], a[3 * i + 2]);
        let sq = |x: f64| x * x;
        let after = |i: usize| rows.t[i] >= spec.settle - 1e-9;
        let (mut n_after, mut track, mut along, mut path, mut force, mut imp) =
            (0usize, 0.0, 0.0, 0.0, 0.0, 0.0);
        let (mut err, mut mean, mut ne) = (0.0, 0.0, 0.0);
        let (mut chatter, mut n_chatter) = (0.0, 0usize);
        let (md, bd, kd) = (
            Vector::<3>::from(spec.md),
            Vector::<3>::from(spec.bd),
            Vector::<3>::from(spec.kd),
        );
        for i in 0..k {
            if !after(i) {
                continue;
            }
            n_after += 1;
            let (p, pd) = (v3(rows.p, i), v3(rows.pd, i));
            let (pc, dpc, ddpc) = (v3(rows.pc[0], i), v3(rows.pc[1], i), v3(rows.pc[2], i));
            let e = pd - p;
            track += e.norm_squared();
            along += e[0] * e[0] + e[1] * e[1];
            let c = pc - p;
            path += c[0] * c[0] + c[1] * c[1];
            let f = Vector::<3>::new(
                rows.wrench[6 * i],
                rows.wrench[6 * i + 1],
                rows.wrench[6 * i + 2],
            );
            force += sq(-f[2] - kd[2] * spec.depth);
            let r = md.component_mul(&(v3(rows.ddp, i) - ddpc))
                + bd.component_mul(&(v3(rows.dp, i) - dpc))
                + kd.component_mul(&(p - pc))
                + f;
            imp += r.norm_squared();
            let fn_ = rows.normal[i];
            err += sq(fn_ - target);
            mean += fn_;
            ne += pd[2] - p[2];
            if i + 1 < k {
                chatter += sq(rows.normal[i + 1] - fn_);
                n_chatter += 1;
            }
        }
        Self {
            n_after,
            track,
            along,
            path,
            force,
            imp,
            err,
            mean,
            ne,
            chatter,
            n_chatter,
        }
    }
}

/// SPEC (19.7)'s time off the table (s): rows with F_n ≤ 0 after the first
/// contact at or after the approach's end (all of them after it, if none;
/// NaN for a run ending before).
fn table_contact_lost(rows: &TableRows<'_>, spec: &TableSpec<'_>, k: usize) -> f64 {
    // Time off the table after the approach.
    let approach = |i: usize| rows.t[i] >= spec.approach_end - 1e-9;
    let first_after = (0..k).find(|&i| approach(i));
    match first_after {
        None => f64::NAN,
        Some(a) => {
            let start = (a..k).find(|&i| rows.normal[i] > 0.0).unwrap_or(a);
            (start..k).filter(|&i| rows.normal[i] <= 0.0).count() as f64 * spec.ts
        }
    }
}

/// SPEC (19.7)'s torque figures of `k` rows of `n` joints: the rows with
/// sat(τ) ≠ τ, max |τ_i|/τmax_i commanded from `windup_after` on, and
/// max |sat(τ)_i|/τmax_i applied.
fn table_torque(
    rows: &TableRows<'_>,
    spec: &TableSpec<'_>,
    k: usize,
    n: usize,
) -> (usize, f64, f64) {
    let (mut sat, mut peak, mut applied) = (0usize, 0.0f64, 0.0f64);
    for i in 0..k {
        let (tau, tsat) = (
            &rows.tau[0][i * n..(i + 1) * n],
            &rows.tau[1][i * n..(i + 1) * n],
        );
        if tau.iter().zip(tsat).any(|(a, b)| a != b) {
            sat += 1;
        }
        for j in 0..n {
            if rows.t[i] >= spec.windup_after - 1e-9 {
                peak = peak.max(tau[j].abs() / spec.tau_max[j]);
            }
            applied = applied.max(tsat[j].abs() / spec.tau_max[j]);
        }
    }
    (sat, peak, applied)
}

#[cfg(test)]
mod table_tests {
    use super::*;
    use std::vec::Vec;

    #[test]
    fn the_table_metrics_count_chatter_and_time_off_the_table() {
        // 10 rows at 0.5 s; the force 7.5 N but 0 at rows 6 and 8 (after the
        // approach's end at 2 s, the first contact at row 4).
        let k = 10;
        let t: Vec<f64> = (0..k).map(|i| 0.5 * i as f64).collect();
        let normal: Vec<f64> = (0..k)
            .map(|i| if i < 4 || i == 6 || i == 8 { 0.0 } else { 7.5 })
            .collect();
        let zeros3 = std::vec![0.0; 3 * k];
        let mut wrench = std::vec![0.0; 6 * k];
        for i in 0..k {
            wrench[6 * i + 2] = -normal[i];
        }
        let tau: Vec<f64> = (0..k).map(|i| if i == 9 { 20.0 } else { 1.0 }).collect();
        let sat: Vec<f64> = tau.iter().map(|x| x.min(10.0)).collect();
        let rows = TableRows {
            t: &t,
            p: &zeros3,
            dp: &zeros3,
            ddp: &zeros3,
            pd: &zeros3,
            pc: [&zeros3, &zeros3, &zeros3],
            wrench: &wrench,
            normal: &normal,
            tau: [&tau, &sat],
        };
        let spec = TableSpec {
            tau_max: &[10.0],
            md: [2.0; 3],
            bd: [63.2; 3],
            kd: [500.0; 3],
            depth: 0.015,
            series: 500.0,
            settle: 2.0,
            windup_after: 0.1,
            approach_end: 2.0,
            ts: 0.5,
        };
        let m = table_metrics(&rows, &spec).unwrap();
        assert_eq!(m.force_target, 7.5);
        assert_eq!(m.contact_lost, 1.0); // rows 6 and 8
        assert_eq!(m.sat_duty, 0.1);
        assert_eq!(m.peak_tau_ratio, 2.0);
        assert_eq!(m.applied_ratio, 1.0);
        // Rows 4…9: errors 0, 0, 7.5, 0, 7.5, 0; changes 0, 7.5, 7.5, 7.5, 7.5.
        assert!((m.force_rms_err - (2.0 * 56.25 / 6.0f64).sqrt()).abs() < 1e-12);
        assert!((m.force_chatter - (4.0 * 56.25 / 5.0f64).sqrt()).abs() < 1e-12);
        let short = TableRows { t: &t[..2], ..rows };
        assert!(table_metrics(&short, &spec).is_err());
    }
}
