//! The closed loop of a controller written in Python on MuJoCo
//! (`callback.rs`): its rows with the controller's own quantities and a
//! reference of width m, their SPEC §12 metrics by the core's
//! [`RowMetrics`], and the run of N joints over the core's loop.

use super::callback::{row_of, Attrs, Buf, CallShape, CallbackRun, PyStep, Report, W};
use super::cartesian_loop::reads_the_wrench;
use super::dynamic::{
    drive_mujoco, Hooks, Metrics, OnMujoco, RowMetrics, Rows as JointRows, RunError,
};
use super::mujoco::MujocoSpec;
use adaptimp::control::config::Law;
use adaptimp::control::impedance::TargetImpedance;
use adaptimp::error::Error;
use adaptimp::sim::record::{Recorder, Row};
use adaptimp::trajectory::Clock;
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use core::cell::Cell;
use numpy::{PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::vec::Vec;

/// The rows of the reference's width m: xc, ẋc, ẍc, xd, z1 (m per row each,
/// row-major, in the order of [`REFERENCE`]).
type RefRows = [Vec<f64>; 5];

/// The names of the m-wide rows (they replace the joint rows of these names).
pub const REFERENCE: [&str; 5] = ["xc", "dxc", "ddxc", "xd", "z1"];

/// The loop's rows with the controller's quantities, and their metrics.
struct Rows<'a, const N: usize, const M: usize> {
    run: &'a CallbackRun<'a>,
    report: &'a Cell<Report>,
    joint: JointRows,
    every: u64,
    reference: RefRows,
    metrics: RowMetrics,
    /// A row the metrics refused (none: every row fits by construction).
    refused: Option<Error>,
    seen: u64,
}

impl<const N: usize, const M: usize> Rows<'_, N, M> {
    /// The reference-side values of row `r` (width m): xc, ẋc, ẍc, xd, z1.
    fn reference(&self, r: &Row<N>, rep: &Report) -> [Buf; 5] {
        let (run, w) = (self.run, self.run.m);
        let k = row_of(r.t, run.ts);
        let row = |t: &[f64]| -> Buf {
            let mut o = [f64::NAN; W];
            if let Some(v) = t.get(k * w..(k + 1) * w) {
                o[..w].copy_from_slice(v);
            }
            o
        };
        let mut q = [0.0; W];
        q[..N].copy_from_slice(r.x.as_slice());
        let xc = match rep.xc {
            Some(x) if !run.setpoint => x,
            _ if run.setpoint => row(run.table[0]),
            _ => q,
        };
        let (dxc, ddxc) = match rep.rates {
            Some(r) if !run.setpoint => r,
            _ => (row(run.table[1]), row(run.table[2])),
        };
        let xd = rep.xd.unwrap_or(xc);
        let z1 = match rep.z1 {
            // A refused row: the error of the last reference (the core's rule).
            Some(_) if r.refused && w == N => core::array::from_fn(|i| xd[i] - q[i]),
            // SPEC (17.1): with noise or delay, the loop's row carries (the
            // step's z1, zero here, plus) the sample's error y_q − q_true: the
            // controller's z1 becomes the error of the plant's true q.
            Some(z) if w == N && r.z1.iter().any(|e| *e != 0.0) => {
                core::array::from_fn(|i| if i < N { z[i] + r.z1[i] } else { z[i] })
            }
            Some(z) => z,
            None => core::array::from_fn(|i| xd[i] - q[i]),
        };
        [xc, dxc, ddxc, xd, z1]
    }
}

impl<const N: usize, const M: usize> Recorder<N> for Rows<'_, N, M> {
    fn record(&mut self, r: &Row<N>) {
        let rep = self.report.get();
        let [xc, dxc, ddxc, xd, z1] = self.reference(r, &rep);
        let w = self.run.m;
        let tau = if r.refused {
            r.tau
        } else {
            Vector::from_fn(|i, _| rep.tau[i])
        };
        let own = |v: Option<Buf>, or: Vector<N>| v.map_or(or, |b| Vector::from_fn(|i, _| b[i]));
        let row = Row {
            tau,
            dx_hat: own(rep.dq_hat, r.dx),
            zeta: Vector::from_fn(|i, _| rep.zeta[i]),
            // No weights are read (also on a row refused before any step).
            w_norms: [f64::NAN; 3],
            ..*r
        };
        self.joint.record(&row);
        if self.seen.is_multiple_of(self.every) {
            for (out, v) in self.reference.iter_mut().zip([xc, dxc, ddxc, xd, z1]) {
                out.extend_from_slice(&v[..w]);
            }
        }
        self.seen += 1;
        // A refused row: sat(τ) = τ, the torque held (no saturation, as the core counts it).
        let sat = if r.refused {
            tau
        } else {
            Vector::<N>::from_fn(|i, _| rep.sat[i])
        };
        let pushed = self.metrics.push(
            r.t,
            [r.x.as_slice(), r.dx.as_slice(), r.ddx.as_slice()],
            [&xc[..w], &dxc[..w], &ddxc[..w]],
            &z1[..w],
            [tau.as_slice(), sat.as_slice(), r.tau_e.as_slice()],
        );
        if let Err(e) = pushed {
            self.refused.get_or_insert(e);
        }
    }
}

/// What a run gives back: the joint rows, the reference rows (m wide) and
/// the metrics, or how it ended; and the exception the controller raised,
/// which ended it.
pub struct RunOut {
    /// The rows and metrics, or the run's error.
    pub rows: Result<(JointRows, RefRows, Metrics), RunError>,
    /// The controller's exception.
    pub raised: Option<PyErr>,
}

impl From<RunError> for RunOut {
    fn from(e: RunError) -> Self {
        Self {
            rows: Err(e),
            raised: None,
        }
    }
}

/// A run's records, metrics and target, made before it starts: the table
/// and the disturbances checked, the rows allocated.
struct Prepared<const N: usize, const M: usize> {
    joint: JointRows,
    reference: RefRows,
    metrics: RowMetrics,
    target: TargetImpedance<N>,
}

fn prepare<const N: usize, const M: usize>(
    run: &CallbackRun<'_>,
) -> Result<Prepared<N, M>, RunError> {
    let w = run.m;
    let total = adaptimp::sim::simulator::steps(run.t_final, run.ts)?;
    let need = usize::try_from(total)
        .unwrap_or(usize::MAX)
        .saturating_mul(w);
    if run.table.iter().any(|t| t.len() < need) {
        return Err(invalid("table", "needs one row per step"));
    }
    if run.task_space {
        reads_the_wrench::<N>(Law::Pd, run.items, run.fault)?;
    }
    let every = run.every.max(1);
    let kept = adaptimp::dynamic::kept_rows(total, every);
    let joint = JointRows::new(N, kept, every)?;
    let mut reference = RefRows::default();
    for v in &mut reference {
        let room = kept.checked_mul(w).ok_or(RunError::Memory(kept))?;
        v.try_reserve_exact(room)
            .map_err(|_| RunError::Memory(kept))?;
    }
    let joint_space = !run.task_space && w == N;
    let (metrics, target) = metrics_and_target::<N, M>(run, joint_space)?;
    Ok(Prepared {
        joint,
        reference,
        metrics,
        target,
    })
}

/// The closed loop of the Python controller `ctrl` on MuJoCo (`sim` as
/// `spec` describes it), with the reference's width M = max(N, m) in the
/// metrics' accumulator.
fn run_m<const N: usize, const M: usize>(
    ctrl: &Py<PyAny>,
    sim: &mut Sim,
    spec: &MujocoSpec,
    run: &CallbackRun<'_>,
    hooks: &mut dyn Hooks,
) -> RunOut {
    let p = match prepare::<N, M>(run) {
        Ok(p) => p,
        Err(e) => return e.into(),
    };
    let (clock, report, abort) = (Cell::new(0.0), Cell::new(Report::NONE), Cell::new(false));
    let tau_max =
        Vector::<N>::from_fn(|i, _| spec.tau_max.get(i).copied().unwrap_or(f64::INFINITY));
    let mut step = PyStep::<N> {
        ctrl,
        run,
        target: p.target,
        tau_max,
        clock: &clock,
        report: &report,
        abort: &abort,
        error: None,
    };
    let mut rows = Rows::<N, M> {
        run,
        report: &report,
        joint: p.joint,
        every: run.every.max(1),
        reference: p.reference,
        metrics: p.metrics,
        refused: None,
        seen: 0,
    };
    let on = OnMujoco {
        sim,
        spec,
        t_final: run.t_final,
        settle: run.settle,
        items: run.items,
        law: Law::Pd,
        fault: run.fault,
        abort: Some(&abort),
    };
    let result = drive_mujoco(&mut step, &Clock(&clock), on, hooks, &mut rows);
    RunOut {
        rows: result.and_then(|()| match rows.refused {
            Some(e) => Err(RunError::Core(e, None)),
            None => Ok((rows.joint, rows.reference, rows.metrics.finish())),
        }),
        raised: step.error,
    }
}

fn invalid(what: &'static str, reason: &'static str) -> RunError {
    RunError::Core(Error::Invalid { what, reason }, None)
}

/// The metrics' accumulator (n joints, the reference m wide) and the target
/// impedance of the run.
fn metrics_and_target<const N: usize, const M: usize>(
    run: &CallbackRun<'_>,
    joint_space: bool,
) -> Result<(RowMetrics, TargetImpedance<N>), Error> {
    let metrics = RowMetrics::new(N, run.m, joint_space, run.settle, run.target)?;
    let t = |v: &[f64]| Vector::<N>::from_fn(|i, _| v.get(i).copied().unwrap_or(1.0));
    let target = match TargetImpedance::new(t(run.target[0]), t(run.target[1]), t(run.target[2])) {
        Ok(tgt) => tgt,
        // Only the metrics read the target; in task space they do not.
        Err(_) => {
            TargetImpedance::new(Vector::from_element(1.0), Vector::zeros(), Vector::zeros())?
        }
    };
    Ok((metrics, target))
}

/// The run of `ctrl` for N joints: M = N in joint space, max(N, 3) in task space.
fn run_n<const N: usize>(
    ctrl: &Py<PyAny>,
    sim: &mut Sim,
    spec: &MujocoSpec,
    run: &CallbackRun<'_>,
    hooks: &mut dyn Hooks,
) -> RunOut {
    if run.m == 3 && N < 3 {
        run_m::<N, 3>(ctrl, sim, spec, run, hooks)
    } else if run.m == 3 || run.m == N {
        run_m::<N, N>(ctrl, sim, spec, run, hooks)
    } else {
        invalid("m", "the reference has n values, or 3 (task space)").into()
    }
}

/// The closed loop of the Python controller `ctrl` (n joints) on MuJoCo.
pub fn simulate(
    n: usize,
    ctrl: &Py<PyAny>,
    sim: &mut Sim,
    spec: &MujocoSpec,
    run: &CallbackRun<'_>,
    hooks: &mut dyn Hooks,
) -> RunOut {
    let on = OnJoints {
        ctrl,
        sim,
        spec,
        run,
        hooks,
    };
    adaptimp::dynamic::for_joints(n, on)
        .unwrap_or_else(|| invalid("n", "the number of joints must be between 1 and 7").into())
}

/// [`simulate`] for N joints.
struct OnJoints<'a, 'b> {
    ctrl: &'a Py<PyAny>,
    sim: &'a mut Sim,
    spec: &'a MujocoSpec,
    run: &'a CallbackRun<'b>,
    hooks: &'a mut dyn Hooks,
}

impl adaptimp::dynamic::ForJoints for OnJoints<'_, '_> {
    type Output = RunOut;
    fn call<const N: usize>(self) -> RunOut {
        run_n::<N>(self.ctrl, self.sim, self.spec, self.run, self.hooks)
    }
}

/// Close the loop of `controller`, a controller written in Python (the
/// protocol `adaptimp.mujoco.ControllerLike`), with the MuJoCo `model` and
/// its `data` as `spec` describes the plant, at the period `ts` (s) for
/// `t_final` (s): the core's loop with the GIL released, taken once a period
/// for the controller's step (and its attributes `attrs`: "tau", "xc",
/// "rates" (its `dxc` and `ddxc`), "xd", "z1", "dq_hat", "zeta"). `table`
/// = (xc, dxc, ddxc), (K, m) each with K ≥ the steps: passed to the step as
/// keywords with `setpoint`, else the rows' rates. `task_space`: the
/// controller reads the wrench, its reference m = 3 wide. `call`: how its
/// step is called, "measurement" (`step(m, **setpoint)`), or the deprecated
/// "joint" (`step(q, tau_e, dq, …)`) and "wrench" (`step(q, dq, wrench, …)`). `target` = (Dd, Cd,
/// Gd), n values each, for the impedance metric. `params` (the disturbances
/// of SPEC §17), `settle`, `record_every`, `progress`, `fault` as for
/// `simulate_mujoco`. Returns its dict, with "xc", "dxc", "ddxc", "xd", "z1"
/// (K, m). An exception of the controller ends the run and is raised.
#[pyfunction]
#[pyo3(signature = (controller, model, data, spec, params, ts, t_final, settle, table, *, setpoint, task_space, call, attrs, target, record_every=1, progress=None, fault=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_mujoco_callback<'py>(
    py: Python<'py>,
    controller: Bound<'py, PyAny>,
    model: &Bound<'py, PyAny>,
    data: &Bound<'py, PyAny>,
    spec: &Bound<'py, PyDict>,
    params: &Bound<'py, PyDict>,
    ts: f64,
    t_final: f64,
    settle: f64,
    table: (
        PyReadonlyArray2<'py, f64>,
        PyReadonlyArray2<'py, f64>,
        PyReadonlyArray2<'py, f64>,
    ),
    setpoint: bool,
    task_space: bool,
    call: &str,
    attrs: Vec<String>,
    target: (Vec<f64>, Vec<f64>, Vec<f64>),
    record_every: u64,
    progress: Option<Py<PyAny>>,
    fault: Option<super::PyFault>,
) -> PyResult<Bound<'py, PyDict>> {
    let fault = super::fault_spec(fault)?;
    if record_every == 0 {
        return Err(super::ConfigError::new_err("record_every must be ≥ 1"));
    }
    let spec = super::mujoco_spec(spec)?;
    let items = super::items(params)?;
    let attrs = Attrs::from_names(&attrs).map_err(PyValueError::new_err)?;
    let (rows, m) = (table.0.shape()[0], table.0.shape()[1]);
    let tab = [
        super::table("table xc", &table.0, rows, m)?,
        super::table("table dxc", &table.1, rows, m)?,
        super::table("table ddxc", &table.2, rows, m)?,
    ];
    let mut sim = Sim::from_python(model, data)?;
    let run = CallbackRun {
        ts,
        t_final,
        settle,
        every: record_every,
        items: &items,
        fault: fault.as_ref(),
        m,
        table: [&tab[0], &tab[1], &tab[2]],
        setpoint,
        task_space,
        shape: CallShape::from_name(call)?,
        attrs,
        target: [&target.0, &target.1, &target.2],
    };
    let ctrl = controller.unbind();
    let n = spec.qadr.len();
    let mut hooks = super::PyHooks::new(progress);
    let result = py.detach(|| simulate(n, &ctrl, &mut sim, &spec, &run, &mut hooks));
    drop(sim);
    if let Some(raised) = result.raised {
        return Err(raised);
    }
    let (rec, reference, metrics) = result.rows.map_err(|e| super::run_error(e, &mut hooks))?;
    let k = rec.len();
    let out = super::records_dict(py, rec, metrics, true)?;
    for (name, rows) in REFERENCE.iter().zip(reference) {
        out.set_item(*name, super::array(py, rows, (k, m))?)?;
    }
    Ok(out)
}
