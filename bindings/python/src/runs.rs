//! `simulate`, `metrics`, `simulate_mujoco`: one closed run, with the GIL released, and its SPEC §12 metrics.

use super::dynamic::{ArmSpec, JointCore};
use super::{arrays::*, controller::*, errors::*, hooks::*, models::*, params::*};
use super::{dynamic, mujoco};
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Close the loop of `controller` (reset first) with `arm` (a `TwoLinkArm` or
/// a `PlanarArm` of the controller's n joints) and the wall (or free space)
/// of `params`, integrating the plant with RK4 (SPEC §11), with the GIL
/// released, from the initial `weights` (a dict as for
/// `Controller.load_weights`; zero if None). Keeps every `record_every`-th row (the metrics see every step);
/// checks for signals every 50 ms and calls `progress(done, total)` as often.
/// Returns a dict of the arrays ("t" (K,), per-joint (K, n): "q", "dq",
/// "ddq", "xc", "dxc", "ddxc", "xd", "dq_hat", "tau", "tau_sat", "tau_e",
/// "zeta", "z1"; "w_norms" (K, 3); "refused" (K,) bool) and "metrics"
/// (SPEC §12). `controller` is left in its state at the end of the run.
/// With `fault` = (kind, start, duration, bias, fraction), that fault is
/// injected (`src/sim/inject.rs`): a refused step applies the fallback and
/// the run goes on, the row marked "refused".
#[pyfunction]
#[pyo3(signature = (controller, arm, params, record_every=1, progress=None, weights=None, fault=None))]
#[allow(clippy::too_many_arguments)]
pub(super) fn simulate<'py>(
    py: Python<'py>,
    controller: &Bound<'py, PyController>,
    arm: &Bound<'py, PyAny>,
    params: &Bound<'py, PyDict>,
    record_every: u64,
    progress: Option<Py<PyAny>>,
    weights: Option<&Bound<'py, PyDict>>,
    fault: Option<PyFault>,
) -> PyResult<Bound<'py, PyDict>> {
    let fault = fault_spec(fault)?;
    if record_every == 0 {
        return Err(ConfigError::new_err("record_every must be ≥ 1"));
    }
    let spec = if let Ok(a) = arm.cast::<PyArm>() {
        ArmSpec::Paper(a.get().inner)
    } else if let Ok(a) = arm.cast::<PyPlanarArm>() {
        ArmSpec::Planar {
            links: a.get().links.clone(),
            g: a.get().g,
        }
    } else {
        return Err(PyTypeError::new_err(
            "arm must be an adaptimp TwoLinkArm or PlanarArm",
        ));
    };
    let items = items(params)?;
    let ctrl = controller.get();
    let weights = match weights {
        Some(w) => Some(weight_rows(ctrl.n, ctrl.read(py)?.nodes(), w)?),
        None => None,
    };
    let mut hooks = PyHooks::holding(progress, vec![ctrl.slot()]);
    let mut guard = ctrl.lock(py)?;
    let core: &mut JointCore = &mut guard;
    let result = py.detach(|| {
        let w = weights.as_deref();
        core.simulate(&spec, &items, w, fault.as_ref(), record_every, &mut hooks)
    });
    drop(guard);
    let (rec, metrics) = result.map_err(|e| run_error(e, &mut hooks))?;
    records_dict(py, rec, metrics, false)
}

/// A run's records and metrics as the dict `simulate` returns: "t" (K,),
/// the per-joint arrays (K, n), "w_norms" (K, 3), "refused" (K,), with the
/// end effector "x_ee" (K, 3) and "wrench_ee" (K, 6) if recorded, and
/// "metrics".
pub(super) fn records_dict<'py>(
    py: Python<'py>,
    rec: dynamic::Rows,
    metrics: dynamic::Metrics,
    ee: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let k = rec.len();
    let n = rec.n();
    let out = PyDict::new(py);
    out.set_item("t", rec.t.into_pyarray(py))?;
    let joint = [
        ("q", rec.x),
        ("dq", rec.dx),
        ("ddq", rec.ddx),
        ("xc", rec.xc),
        ("dxc", rec.dxc),
        ("ddxc", rec.ddxc),
        ("xd", rec.xd),
        ("dq_hat", rec.dx_hat),
        ("tau", rec.tau),
        ("tau_sat", rec.tau_sat),
        ("tau_e", rec.tau_e),
        ("zeta", rec.zeta),
        ("z1", rec.z1),
    ];
    for (name, data) in joint {
        out.set_item(name, array(py, data, (k, n))?)?;
    }
    out.set_item("w_norms", array(py, rec.w_norms, (k, 3))?)?;
    out.set_item("refused", PyArray1::from_vec(py, rec.refused))?;
    if ee {
        out.set_item("x_ee", array(py, rec.x_ee, (k, 3))?)?;
        out.set_item("wrench_ee", array(py, rec.wrench, (k, 6))?)?;
    }
    out.set_item("metrics", metrics_to_dict(py, metrics)?)?;
    Ok(out)
}

/// The SPEC §12 metrics of recorded rows, by the core's accumulator (the
/// metrics of a loop that ran in Python: `adaptimp.mujoco.simulate` with a
/// Python controller): `t` (K,), `q`, `dq`, `ddq`, `tau`, `tau_sat`, `tau_e`
/// (K, n), `xc`, `dxc`, `ddxc`, `z1` (K, m), the window after `settle` (s)
/// and the target impedance (Dd, Cd, Gd), n values each. `joint_space`:
/// whether the reference is in joint space (m = n; None: whether m = n); in
/// task space the impedance residual is NaN. Returns the dict of
/// `SimResult.metrics`.
#[pyfunction]
#[pyo3(signature = (t, q, dq, ddq, xc, dxc, ddxc, z1, tau, tau_sat, tau_e, settle, target, joint_space=None))]
#[allow(clippy::too_many_arguments)]
pub(super) fn metrics<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    q: PyReadonlyArray2<'py, f64>,
    dq: PyReadonlyArray2<'py, f64>,
    ddq: PyReadonlyArray2<'py, f64>,
    xc: PyReadonlyArray2<'py, f64>,
    dxc: PyReadonlyArray2<'py, f64>,
    ddxc: PyReadonlyArray2<'py, f64>,
    z1: PyReadonlyArray2<'py, f64>,
    tau: PyReadonlyArray2<'py, f64>,
    tau_sat: PyReadonlyArray2<'py, f64>,
    tau_e: PyReadonlyArray2<'py, f64>,
    settle: f64,
    target: (Vec<f64>, Vec<f64>, Vec<f64>),
    joint_space: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    let k = t.len();
    let (n, m) = (q.shape()[1], xc.shape()[1]);
    let tab = |name: &str, a: &PyReadonlyArray2<'py, f64>, w: usize| table(name, a, k, w);
    let x = [tab("q", &q, n)?, tab("dq", &dq, n)?, tab("ddq", &ddq, n)?];
    let c = [
        tab("xc", &xc, m)?,
        tab("dxc", &dxc, m)?,
        tab("ddxc", &ddxc, m)?,
    ];
    let z = tab("z1", &z1, m)?;
    let tq = [
        tab("tau", &tau, n)?,
        tab("tau_sat", &tau_sat, n)?,
        tab("tau_e", &tau_e, n)?,
    ];
    let ts: Vec<f64> = t.as_array().iter().copied().collect();
    let rows = adaptimp::dynamic::Recorded {
        n,
        m,
        t: &ts,
        x: [&x[0], &x[1], &x[2]],
        c: [&c[0], &c[1], &c[2]],
        z1: &z,
        tau: [&tq[0], &tq[1], &tq[2]],
    };
    let out = adaptimp::dynamic::metrics_of(
        &rows,
        settle,
        [&target.0, &target.1, &target.2],
        joint_space,
    )
    .map_err(step_error)?;
    metrics_to_dict(py, out)
}

/// A fault as `adaptimp.Fault` hands it to the core: (kind, start (s),
/// duration (s), bias (N m, per joint) or None, fraction or None).
pub(super) type PyFault = (String, f64, f64, Option<Vec<f64>>, Option<f64>);

/// A fault to inject from its Python form ([`PyFault`]).
pub(super) fn fault_spec(f: Option<PyFault>) -> PyResult<Option<dynamic::FaultSpec>> {
    let Some((kind, start, duration, bias, fraction)) = f else {
        return Ok(None);
    };
    use dynamic::FaultKind as K;
    let kind = match (kind.as_str(), bias, fraction) {
        ("stale", None, None) => K::Stale,
        ("nan_burst", None, None) => K::NanBurst,
        ("skipped", None, None) => K::Skipped,
        ("force_bias", Some(b), None) => K::ForceBias(b),
        ("actuator_drop", None, Some(x)) => K::ActuatorDrop(x),
        (other, b, x) => {
            // As Python writes them: None, [1.0, 2.0], 0.5.
            let b = b.map_or("None".to_string(), |v| format!("{v:?}"));
            let x = x.map_or("None".to_string(), |v| format!("{v:?}"));
            return Err(ConfigError::new_err(format!(
                "fault '{other}' with bias {b} and fraction {x}: the kinds are 'stale', \
                 'nan_burst', 'skipped', 'force_bias' (with bias) and 'actuator_drop' (with fraction)"
            )));
        }
    };
    Ok(Some(dynamic::FaultSpec {
        kind,
        start,
        duration,
    }))
}

// The closed loop on MuJoCo.

/// A plant description from the dict `adaptimp.mujoco.Plant` makes (see
/// [`mujoco::MujocoSpec`]).
pub(super) fn mujoco_spec(d: &Bound<'_, PyDict>) -> PyResult<mujoco::MujocoSpec> {
    fn get<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<T> {
        d.get_item(key)?
            .ok_or_else(|| PyTypeError::new_err(format!("the plant description has no {key:?}")))?
            .extract()
            .map_err(Into::into)
    }
    Ok(mujoco::MujocoSpec {
        qadr: get(d, "qadr")?,
        dofs: get(d, "dofs")?,
        act: get(d, "act")?,
        gear: get(d, "gear")?,
        tau_max: get(d, "tau_max")?,
        site: get(d, "site")?,
        ee_body: get(d, "ee_body")?,
        force_adr: get(d, "force_adr")?,
        torque_adr: get(d, "torque_adr")?,
        contact_adr: get(d, "contact_adr")?,
        subtree: get(d, "subtree")?,
        root: get(d, "root")?,
        substeps: get(d, "substeps")?,
        timestep: get(d, "timestep")?,
        integrator: match get::<i32>(d, "integrator")? {
            i @ 0..=3 => i,
            other => {
                return Err(ConfigError::new_err(format!(
                    "the model's integrator must be 0 (Euler), 1 (RK4), 2 (implicit) or 3 \
                     (implicitfast), got {other}"
                )))
            }
        },
        pure_sensors: get(d, "pure_sensors")?,
        watch: match d.get_item("watch")? {
            Some(v) => v.extract()?,
            None => Vec::new(),
        },
        watch_out: match d.get_item("watch_out")? {
            Some(v) => v.extract()?,
            None => None,
        },
        dof_names: get(d, "dof_names")?,
        warning_names: get(d, "warning_names")?,
    })
}

/// Close the loop of `controller` (from its current state) with the MuJoCo
/// `model` and its `data` (`mujoco.MjModel`, `mujoco.MjData`) as `spec`
/// describes the plant, for `t_final` (s), with the GIL released and MuJoCo
/// driven through its C library (SPEC §13.1): the disturbances of `params`
/// (SPEC §17), the setpoints `reference` = (xc, dxc, ddxc), each (K, n) with
/// K ≥ the steps (None: the controller's own trajectory), the metrics after
/// `settle` (s). Keeps every `record_every`-th row; checks for signals every
/// 50 ms and calls `progress(done, total)` as often. Returns the dict of
/// `simulate` with "x_ee" (K, 3) and "wrench_ee" (K, 6). A period after
/// which MuJoCo warned (it resets a diverged state) raises `DivergedError`
/// naming the row, the time and MuJoCo's message.
#[pyfunction]
#[pyo3(signature = (controller, model, data, spec, params, t_final, settle, record_every=1, progress=None, reference=None, fault=None))]
#[allow(clippy::too_many_arguments)]
pub(super) fn simulate_mujoco<'py>(
    py: Python<'py>,
    controller: &Bound<'py, PyController>,
    model: &Bound<'py, PyAny>,
    data: &Bound<'py, PyAny>,
    spec: &Bound<'py, PyDict>,
    params: &Bound<'py, PyDict>,
    t_final: f64,
    settle: f64,
    record_every: u64,
    progress: Option<Py<PyAny>>,
    reference: Option<PyReference<'py>>,
    fault: Option<PyFault>,
) -> PyResult<Bound<'py, PyDict>> {
    let fault = fault_spec(fault)?;
    if record_every == 0 {
        return Err(ConfigError::new_err("record_every must be ≥ 1"));
    }
    let spec = mujoco_spec(spec)?;
    let items = items(params)?;
    let ctrl = controller.get();
    let n = ctrl.n;
    let tables = reference_tables(n, reference.as_ref())?;
    let mut sim = adaptimp_mujoco::Sim::from_python(model, data)?;
    let run = dynamic::MujocoRun {
        t_final,
        settle,
        every: record_every,
        items: &items,
        reference: tables.as_ref().map(|[a, b, c]| [&a[..], &b[..], &c[..]]),
        fault: fault.as_ref(),
    };
    let mut hooks = PyHooks::holding(progress, vec![ctrl.slot()]);
    let mut guard = ctrl.lock(py)?;
    let core: &mut JointCore = &mut guard;
    let result = py.detach(|| core.simulate_mujoco(&mut sim, &spec, &run, &mut hooks));
    drop(guard);
    drop(sim);
    let (rec, metrics) = result.map_err(|e| run_error(e, &mut hooks))?;
    records_dict(py, rec, metrics, true)
}

/// The SPEC §12 metrics of a run as a dict of numbers and per-joint lists.
pub(super) fn metrics_to_dict<'py>(
    py: Python<'py>,
    metrics: dynamic::Metrics,
) -> PyResult<Bound<'py, PyDict>> {
    let m = PyDict::new(py);
    m.set_item("rows", metrics.rows)?;
    m.set_item("steps_in_contact", metrics.steps_in_contact)?;
    for (name, v) in [
        ("rms_z1", metrics.rms_z1),
        ("rms_z1_after2", metrics.rms_z1_after2),
        ("sat_duty", metrics.sat_duty),
        ("peak_contact_after2", metrics.peak_contact_after2),
        ("mean_contact", metrics.mean_contact),
        ("imp_err_rms_after2", metrics.imp_err_rms_after2),
    ] {
        m.set_item(name, v)?;
    }
    for (name, v) in [
        ("rms_z1_joint_after2", metrics.rms_z1_joint_after2),
        ("max_abs_z1_joint_after2", metrics.max_abs_z1_joint_after2),
        ("peak_abs_tau", metrics.peak_abs_tau),
    ] {
        m.set_item(name, v.as_slice())?;
    }
    Ok(m)
}
