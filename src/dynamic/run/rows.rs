//! What a run-time closed loop records: the joint [`Rows`], the task rows
//! of a Cartesian run ([`TaskRows`]) and the SPEC §12 [`Metrics`], by the
//! core's one accumulator (also of rows recorded elsewhere: [`metrics_of`]).

use super::super::cartesian::CartesianCommand;
use super::super::sized::{each, make, ByJoints, Family};
use super::super::values::Joints;
use super::{Run, RunError};
use crate::cartesian::{self, PoseTarget};
use crate::control::impedance::TargetImpedance;
use crate::error::Error;
use crate::sim::metrics::{self as core_metrics, MetricsAccumulator};
use crate::sim::record::{Recorder, Row};
use crate::sim::simulator;
use crate::types::Vector;
use alloc::vec::Vec;

/// Every kept row of a run (every `every`-th), one row-major table per
/// quantity: n values per row for the joint quantities (names as
/// [`Row`](crate::Row)'s), 3 for `w_norms` and `x_ee`, 6 for `wrench`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Rows {
    n: usize,
    every: u64,
    seen: u64,
    /// t_k (s).
    pub t: Vec<f64>,
    /// Plant position x (rad).
    pub x: Vec<f64>,
    /// Plant velocity ẋ (rad/s).
    pub dx: Vec<f64>,
    /// Plant acceleration ẍ (rad/s²).
    pub ddx: Vec<f64>,
    /// Commanded position xc (rad).
    pub xc: Vec<f64>,
    /// Commanded velocity ẋc (rad/s).
    pub dxc: Vec<f64>,
    /// Commanded acceleration ẍc (rad/s²).
    pub ddxc: Vec<f64>,
    /// Compliant reference xd (rad).
    pub xd: Vec<f64>,
    /// The velocity the controller used (rad/s).
    pub dx_hat: Vec<f64>,
    /// Commanded torque τ (N m).
    pub tau: Vec<f64>,
    /// Applied torque sat(τ) (N m).
    pub tau_sat: Vec<f64>,
    /// Contact force τe (N m).
    pub tau_e: Vec<f64>,
    /// ζ (N m).
    pub zeta: Vec<f64>,
    /// z1 = xd − x (rad).
    pub z1: Vec<f64>,
    /// ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ before the step's update.
    pub w_norms: Vec<f64>,
    /// Whether the row's step was refused (a fallback applied).
    pub refused: Vec<bool>,
    /// End-effector position (m).
    pub x_ee: Vec<f64>,
    /// End-effector wrench [f; m] (N, N m).
    pub wrench: Vec<f64>,
}

/// The rows a run of `total` periods keeps when it keeps every `every`-th
/// (0 is taken as 1): ⌈total / every⌉, what [`Rows::new`] and
/// [`TaskRows::new`] are sized for.
pub fn kept_rows(total: u64, every: u64) -> usize {
    usize::try_from(total.div_ceil(every.max(1))).unwrap_or(usize::MAX)
}

impl Rows {
    /// Room for `rows` kept rows of n joints, keeping every `every`-th
    /// (≥ 1); [`RunError::Memory`] if it cannot be had.
    pub fn new(n: usize, rows: usize, every: u64) -> Result<Self, RunError> {
        let memory = RunError::Memory(rows);
        let mut r = Self {
            n,
            every: every.max(1),
            ..Self::default()
        };
        let reserve = |v: &mut Vec<f64>, w: usize| -> Result<(), RunError> {
            let len = rows.checked_mul(w).ok_or(memory)?;
            v.try_reserve_exact(len).map_err(|_| memory)
        };
        reserve(&mut r.t, 1)?;
        for v in [
            &mut r.x,
            &mut r.dx,
            &mut r.ddx,
            &mut r.xc,
            &mut r.dxc,
            &mut r.ddxc,
            &mut r.xd,
            &mut r.dx_hat,
            &mut r.tau,
            &mut r.tau_sat,
            &mut r.tau_e,
            &mut r.zeta,
            &mut r.z1,
        ] {
            reserve(v, n)?;
        }
        reserve(&mut r.w_norms, 3)?;
        reserve(&mut r.x_ee, 3)?;
        reserve(&mut r.wrench, 6)?;
        r.refused.try_reserve_exact(rows).map_err(|_| memory)?;
        Ok(r)
    }

    /// Rows for the run `run` of a controller of period `ts` (s): one for
    /// every `run.every`-th of its round(T/Ts) periods.
    pub fn for_run(n: usize, run: &Run<'_>, ts: f64) -> Result<Self, RunError> {
        let total = simulator::steps(run.t_final, ts)?;
        Self::new(n, kept_rows(total, run.every), run.every)
    }

    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The number of rows kept K.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// Whether no row is kept.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}

impl<const N: usize> Recorder<N> for Rows {
    fn record(&mut self, r: &Row<N>) {
        let keep = self.seen.is_multiple_of(self.every);
        self.seen += 1;
        if !keep {
            return;
        }
        self.t.push(r.t);
        for (v, x) in [
            (&mut self.x, &r.x),
            (&mut self.dx, &r.dx),
            (&mut self.ddx, &r.ddx),
            (&mut self.xc, &r.xc),
            (&mut self.dxc, &r.dxc),
            (&mut self.ddxc, &r.ddxc),
            (&mut self.xd, &r.xd),
            (&mut self.dx_hat, &r.dx_hat),
            (&mut self.tau, &r.tau),
            (&mut self.tau_sat, &r.tau_sat),
            (&mut self.tau_e, &r.tau_e),
            (&mut self.zeta, &r.zeta),
            (&mut self.z1, &r.z1),
        ] {
            v.extend_from_slice(x.as_slice());
        }
        self.w_norms.extend_from_slice(&r.w_norms);
        self.refused.push(r.refused);
        self.x_ee.extend_from_slice(&r.x_ee);
        self.wrench.extend_from_slice(&r.wrench);
    }
}

/// The SPEC §12 metrics of a run: the run-time [`Metrics`](crate::Metrics).
/// In task space (a Cartesian run) z1 is p_d − p (m, 3 values per row) and
/// the impedance residual is NaN.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Metrics {
    /// Number of rows K.
    pub rows: usize,
    /// RMS ‖z1‖ over the whole run.
    pub rms_z1: f64,
    /// RMS ‖z1‖ over t ≥ settle.
    pub rms_z1_after2: f64,
    /// Per coordinate of z1, RMS over t ≥ settle.
    pub rms_z1_joint_after2: Joints,
    /// Per coordinate of z1, max |z1_i| over t ≥ settle.
    pub max_abs_z1_joint_after2: Joints,
    /// Fraction of rows with any Δτ_i ≠ 0.
    pub sat_duty: f64,
    /// Rows with τe ≠ 0.
    pub steps_in_contact: usize,
    /// Peak ‖τe‖ over t ≥ settle (N m).
    pub peak_contact_after2: f64,
    /// Mean ‖τe‖ over the rows in contact (N m).
    pub mean_contact: f64,
    /// Peak commanded |τ_i| per joint over the run (N m).
    pub peak_abs_tau: Joints,
    /// RMS over t ≥ settle of the impedance residual (N m).
    pub imp_err_rms_after2: f64,
}

impl Metrics {
    pub(crate) fn of<const N: usize>(m: &core_metrics::Metrics<N>) -> Self {
        Self {
            rows: m.rows,
            rms_z1: m.rms_z1,
            rms_z1_after2: m.rms_z1_after2,
            rms_z1_joint_after2: Joints::of(&m.rms_z1_joint_after2),
            max_abs_z1_joint_after2: Joints::of(&m.max_abs_z1_joint_after2),
            sat_duty: m.sat_duty,
            steps_in_contact: m.steps_in_contact,
            peak_contact_after2: m.peak_contact_after2,
            mean_contact: m.mean_contact,
            peak_abs_tau: Joints::of(&m.peak_abs_tau),
            imp_err_rms_after2: m.imp_err_rms_after2,
        }
    }
}

/// The SPEC §12 metrics of rows given one at a time as slices: n joints
/// (q, q̇, q̈, τ, sat(τ), τe) and a reference of width m (xc, ẋc, ẍc, z1),
/// in an accumulator of M ≥ max(n, m) slots, the narrower quantities padded
/// with zeros (which change no norm, peak or count).
pub(crate) struct TaskMetrics<const M: usize> {
    acc: MetricsAccumulator<M>,
    n: usize,
    m: usize,
    joint: bool,
}

impl<const M: usize> TaskMetrics<M> {
    /// For n joints and a reference of width m, after `settle` (s); `joint`:
    /// the reference is in joint space (m = n; the impedance residual with
    /// `target` = (Dd, Cd, Gd), n values each).
    pub(crate) fn new(
        n: usize,
        m: usize,
        joint: bool,
        settle: f64,
        target: [&[f64]; 3],
    ) -> Result<Self, Error> {
        let bad = |reason| Error::Invalid {
            what: "rows",
            reason,
        };
        if n == 0 || m == 0 || n > M || m > M {
            return Err(bad("need at least one joint and one reference coordinate"));
        }
        if joint && m != n {
            return Err(bad(
                "a joint-space reference needs one coordinate per joint (m = n)",
            ));
        }
        if target.iter().any(|v| v.len() != n) {
            return Err(bad("the target impedance needs n values per matrix"));
        }
        let ones = Vector::<M>::from_element(1.0);
        let tgt = if joint {
            let t = |v: &[f64]| {
                let mut o = ones;
                o.as_mut_slice()[..n].copy_from_slice(v);
                o
            };
            TargetImpedance::new(t(target[0]), t(target[1]), t(target[2]))?
        } else {
            TargetImpedance::new(ones, ones, ones)?
        };
        Ok(Self {
            acc: MetricsAccumulator::new(settle, tgt),
            n,
            m,
            joint,
        })
    }

    /// One row: t (s); q, q̇, q̈ (n each); xc, ẋc, ẍc (m each); z1 (m); τ,
    /// sat(τ), τe (n each).
    pub(crate) fn push(
        &mut self,
        t: f64,
        x: [&[f64]; 3],
        c: [&[f64]; 3],
        z1: &[f64],
        tau: [&[f64]; 3],
    ) {
        let (n, m) = (self.n, self.m);
        let pad = |v: &[f64], w: usize| {
            let mut out = Vector::<M>::zeros();
            out.as_mut_slice()[..w].copy_from_slice(&v[..w]);
            out
        };
        let zero = Vector::<M>::zeros();
        let (tau_m, tau_sat) = (pad(tau[0], n), pad(tau[1], n));
        let joint = self.joint;
        self.acc.push(&Row {
            t,
            x: pad(x[0], n),
            dx: pad(x[1], n),
            ddx: pad(x[2], n),
            xc: if joint { pad(c[0], m) } else { zero },
            dxc: if joint { pad(c[1], m) } else { zero },
            ddxc: if joint { pad(c[2], m) } else { zero },
            xd: zero,
            dx_hat: zero,
            tau: tau_m,
            tau_sat,
            dtau: tau_sat - tau_m,
            tau_e: pad(tau[2], n),
            zeta: zero,
            z1: pad(z1, m),
            w_norms: [0.0; 3],
            x_ee: [0.0; 3],
            wrench: [0.0; 6],
            refused: false,
        });
    }

    /// The metrics: per-coordinate figures of z1 cut to m, of τ to n; the
    /// impedance residual NaN in task space.
    pub(crate) fn finish(&self) -> Metrics {
        let mut out = Metrics::of(&self.acc.finish());
        let cut = |j: &mut Joints, w: usize| {
            if let Ok(c) = Joints::from_slice(&j[..w]) {
                *j = c;
            }
        };
        cut(&mut out.rms_z1_joint_after2, self.m);
        cut(&mut out.max_abs_z1_joint_after2, self.m);
        cut(&mut out.peak_abs_tau, self.n);
        if !self.joint {
            out.imp_err_rms_after2 = f64::NAN;
        }
        out
    }
}

struct RowMetricsF;
impl Family for RowMetricsF {
    type Of<const N: usize> = TaskMetrics<N>;
}

/// The SPEC §12 metrics of rows given one at a time as slices (a loop that
/// runs in another language, row by row): n joints (q, q̇, q̈, τ, sat(τ),
/// τe) and a reference of width m (xc, ẋc, ẍc, z1), by the core's one
/// accumulator, sized once for max(n, m) (the narrower quantities padded
/// with zeros, which change no norm, peak or count). [`metrics_of`] is it
/// over tables.
pub struct RowMetrics {
    inner: ByJoints<RowMetricsF>,
}

impl RowMetrics {
    /// For n joints and a reference of width m (1 ≤ n, m ≤ 7), the window
    /// after `settle` (s); `joint`: the reference is in joint space (m = n;
    /// the impedance residual against `target` = (Dd, Cd, Gd), n values
    /// each), else the impedance residual is NaN.
    pub fn new(
        n: usize,
        m: usize,
        joint: bool,
        settle: f64,
        target: [&[f64]; 3],
    ) -> Result<Self, Error> {
        let inner = make!(
            n.max(m),
            K => TaskMetrics::<K>::new(n, m, joint, settle, target),
            _ => Error::Invalid {
                what: "rows",
                reason: "the joints and the reference's width must be between 1 and 7",
            }
        )?;
        Ok(Self { inner })
    }

    /// One row: t (s); q, q̇, q̈ (n each); xc, ẋc, ẍc (m each); z1 (m); τ,
    /// sat(τ), τe (n each). A slice shorter than its width is an error.
    pub fn push(
        &mut self,
        t: f64,
        x: [&[f64]; 3],
        c: [&[f64]; 3],
        z1: &[f64],
        tau: [&[f64]; 3],
    ) -> Result<(), Error> {
        each!(&mut self.inner, a, K => {
            let (n, m) = (a.n, a.m);
            if x.iter().chain(tau.iter()).any(|v| v.len() < n)
                || c.iter().chain([&z1]).any(|v| v.len() < m)
            {
                return Err(Error::Invalid {
                    what: "rows",
                    reason: "a row needs n values per joint quantity, m per reference one",
                });
            }
            a.push(t, x, c, z1, tau);
            Ok(())
        })
    }

    /// The metrics of the rows so far: per-coordinate figures of z1 cut to
    /// m, of τ to n.
    pub fn finish(&self) -> Metrics {
        each!(&self.inner, a, K => a.finish())
    }
}

impl core::fmt::Debug for RowMetrics {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        each!(&self.inner, a, K => f
            .debug_struct("RowMetrics")
            .field("n", &a.n)
            .field("m", &a.m)
            .field("joint", &a.joint)
            .finish())
    }
}

/// Rows recorded elsewhere (a loop that ran in another language), K of
/// them, row-major: n values per row for the plant's quantities, m for the
/// reference's (m = n in joint space, else the task's width).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Recorded<'a> {
    /// Joints n.
    pub n: usize,
    /// Width m of the reference and of z1.
    pub m: usize,
    /// t_k (s), K values.
    pub t: &'a [f64],
    /// q, q̇, q̈ (K × n each).
    pub x: [&'a [f64]; 3],
    /// xc, ẋc, ẍc (K × m each).
    pub c: [&'a [f64]; 3],
    /// z1 (K × m).
    pub z1: &'a [f64],
    /// τ, sat(τ), τe (K × n each).
    pub tau: [&'a [f64]; 3],
}

/// The SPEC §12 metrics of rows recorded elsewhere, by the core's one
/// accumulator: `joint_space` whether the reference and z1 are in joint
/// space (then m = n, the impedance residual against `target` = (Dd, Cd,
/// Gd), n values each; none: whether m = n). In task space the impedance
/// residual is NaN.
pub fn metrics_of(
    r: &Recorded<'_>,
    settle: f64,
    target: [&[f64]; 3],
    joint_space: Option<bool>,
) -> Result<Metrics, Error> {
    let (n, m, k) = (r.n, r.m, r.t.len());
    if r.x.iter().chain(r.tau.iter()).any(|v| v.len() != k * n)
        || r.c.iter().chain([&r.z1]).any(|v| v.len() != k * m)
    {
        return Err(Error::Invalid {
            what: "rows",
            reason: "every table needs K rows of its width",
        });
    }
    let joint = joint_space.unwrap_or(m == n);
    let mut acc = RowMetrics::new(n, m, joint, settle, target)?;
    fn row(v: &[f64], w: usize, i: usize) -> &[f64] {
        &v[i * w..(i + 1) * w]
    }
    for i in 0..k {
        acc.push(
            r.t[i],
            [row(r.x[0], n, i), row(r.x[1], n, i), row(r.x[2], n, i)],
            [row(r.c[0], m, i), row(r.c[1], m, i), row(r.c[2], m, i)],
            row(r.z1, m, i),
            [
                row(r.tau[0], n, i),
                row(r.tau[1], n, i),
                row(r.tau[2], n, i),
            ],
        )?;
    }
    Ok(acc.finish())
}

/// The last step of a Cartesian run with what it was given: the command,
/// the commanded position and rates p_c, ṗ_c, p̈_c (the target's; without
/// one, the held target after its filter, p_t, at rest) and the wrench.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TaskStep {
    /// The step's command.
    pub command: CartesianCommand,
    /// p_c, ṗ_c, p̈_c (m, m/s, m/s²).
    pub commanded: [Vector<3>; 3],
    /// F_e (N, N m).
    pub wrench: [f64; 6],
}

/// p_c, ṗ_c, p̈_c of a step given the commanded pose `target`; none: the
/// held target `held` (the filtered p_t) at rest.
fn commanded(target: Option<&PoseTarget>, held: &Vector<3>) -> [Vector<3>; 3] {
    match target {
        Some(t) => [t.p, t.dp, t.ddp],
        None => [*held, Vector::zeros(), Vector::zeros()],
    }
}

impl TaskStep {
    /// The step of `command`, given the commanded pose `target` (none: the
    /// held target, p_c = p_t at rest) and the wrench F_e: as
    /// [`TypedTaskStep::new`], at run time.
    pub fn new(command: CartesianCommand, target: Option<&PoseTarget>, wrench: [f64; 6]) -> Self {
        let commanded = commanded(target, &command.target.0);
        Self {
            command,
            commanded,
            wrench,
        }
    }

    /// z1 = p_d − p(q) (m).
    pub fn z1(&self) -> Vector<3> {
        self.command.compliant.p - self.command.p
    }
}

/// [`TaskStep`] for the typed outer loop of N joints: what a loop over
/// [`CartesianImpedance`](crate::CartesianImpedance) keeps of its last step.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TypedTaskStep<const N: usize> {
    /// The step's command.
    pub command: cartesian::CartesianCommand<N>,
    /// p_c, ṗ_c, p̈_c (m, m/s, m/s²).
    pub commanded: [Vector<3>; 3],
    /// F_e (N, N m).
    pub wrench: [f64; 6],
}

impl<const N: usize> TypedTaskStep<N> {
    /// The step of `command`, given the commanded pose `target` (none: the
    /// held target, p_c = p_t at rest) and the wrench F_e.
    pub fn new(
        command: cartesian::CartesianCommand<N>,
        target: Option<&PoseTarget>,
        wrench: [f64; 6],
    ) -> Self {
        let commanded = commanded(target, &command.target.0);
        Self {
            command,
            commanded,
            wrench,
        }
    }

    /// The step at run time, its values copied bit for bit.
    pub fn run_time(&self) -> TaskStep {
        TaskStep {
            command: CartesianCommand::of(&self.command),
            commanded: self.commanded,
            wrench: self.wrench,
        }
    }
}

/// Every kept row's task-space quantities, one row-major table each; and
/// the run's last step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TaskRows {
    pub(crate) n: usize,
    every: u64,
    seen: u64,
    /// p_c, ṗ_c, p̈_c (m, m/s, m/s²), 3 per row each.
    pub pc: [Vec<f64>; 3],
    /// p_d, ṗ_d, p̈_d (m, m/s, m/s²), 3 per row each.
    pub pd: [Vec<f64>; 3],
    /// q_d (rad), n per row.
    pub qd: Vec<f64>,
    /// The impedance's error [e_p; e_o] (m, rad), 6 per row.
    pub error: Vec<f64>,
    /// The wrench the controller was given (N, N m), 6 per row.
    pub wrench: Vec<f64>,
    /// z1 = p_d − p(q) (m), 3 per row.
    pub z1: Vec<f64>,
    /// The last step the run took (also when it ended with an error).
    pub last: Option<TaskStep>,
}

impl TaskRows {
    /// Room for `rows` kept rows of n joints, keeping every `every`-th.
    pub fn new(n: usize, rows: usize, every: u64) -> Result<Self, RunError> {
        let memory = RunError::Memory(rows);
        let mut r = Self {
            n,
            every: every.max(1),
            ..Self::default()
        };
        let reserve = |v: &mut Vec<f64>, w: usize| -> Result<(), RunError> {
            let len = rows.checked_mul(w).ok_or(memory)?;
            v.try_reserve_exact(len).map_err(|_| memory)
        };
        for v in r.pc.iter_mut().chain(r.pd.iter_mut()).chain([&mut r.z1]) {
            reserve(v, 3)?;
        }
        reserve(&mut r.qd, n)?;
        reserve(&mut r.error, 6)?;
        reserve(&mut r.wrench, 6)?;
        Ok(r)
    }

    /// Rows for the run `run` at the period `ts` (s), as [`Rows::for_run`].
    pub fn for_run(n: usize, run: &Run<'_>, ts: f64) -> Result<Self, RunError> {
        let total = simulator::steps(run.t_final, ts)?;
        Self::new(n, kept_rows(total, run.every), run.every)
    }

    /// The number of joints n (the width of `qd`).
    pub fn n(&self) -> usize {
        self.n
    }

    /// The number of rows kept.
    pub fn len(&self) -> usize {
        self.z1.len() / 3
    }

    /// Whether no row is kept.
    pub fn is_empty(&self) -> bool {
        self.z1.is_empty()
    }

    /// The row of `step` (its z1 given), kept if it is an `every`-th;
    /// none: a row before any step, NaN (z1 as given). A loop of its own (a
    /// front's) records its steps here as the run-time loop does.
    pub fn record(&mut self, step: Option<&TaskStep>, z1: &Vector<3>) {
        let keep = self.seen.is_multiple_of(self.every);
        self.seen += 1;
        if !keep {
            return;
        }
        let Some(s) = step else {
            for out in self.pc.iter_mut().chain(self.pd.iter_mut()) {
                out.extend_from_slice(&[f64::NAN; 3]);
            }
            self.qd.extend((0..self.n).map(|_| f64::NAN));
            self.error.extend_from_slice(&[f64::NAN; 6]);
            self.wrench.extend_from_slice(&[f64::NAN; 6]);
            self.z1.extend_from_slice(z1.as_slice());
            return;
        };
        let (cmd, c) = (&s.command, &s.command.compliant);
        for (out, v) in self.pc.iter_mut().zip(&s.commanded) {
            out.extend_from_slice(v.as_slice());
        }
        for (out, v) in self.pd.iter_mut().zip([&c.p, &c.dp, &c.ddp]) {
            out.extend_from_slice(v.as_slice());
        }
        self.qd.extend_from_slice(&cmd.reference.x);
        self.error.extend_from_slice(cmd.error.as_slice());
        self.wrench.extend_from_slice(&s.wrench);
        self.z1.extend_from_slice(z1.as_slice());
    }
}
