//! Python bindings: the extension module `adaptimp._adaptimp` (cargo feature
//! `python`, built by maturin; see `pyproject.toml`).
//!
//! Thin wrappers over the core for arms of n = 1 … 7 joints with the paper's
//! vertex grid (n ≤ 3) or user RBF centres. The friendly layer (keyword
//! parameters with the paper's defaults, result objects, plots, the CLI) is
//! pure Python in `python/adaptimp/`; it hands this module complete parameter
//! dicts whose keys are the schema's names (`Ts`, `Kp`, `Kzeta`, …).
//!
//! - The controller of n joints is a [`dynamic::DynTracker`] (one
//!   monomorphised core per n behind one object-safe face), the arms are
//!   [`arm::DynArm`]s.
//! - Errors become the exception classes of `adaptimp._errors` in one place
//!   each: [`config_error`] (construction: `ConfigError`) and [`step_error`]
//!   (a step: `MeasurementError`, `DivergedError`, `FaultError`), with the
//!   measurement named as in Python (`q`, not the core's `x`).
//! - Long calls ([`simulate`], `Controller.replay`) run with the GIL released,
//!   check for signals (Ctrl-C) every 50 ms of work and report progress to an
//!   optional callback; records are moved into NumPy without copying.
//! - A controller is behind a mutex: each call is atomic; a thread that finds
//!   it in use by another waits with the GIL released (never "Already
//!   borrowed").
//!
//! Nothing here panics on user input and nothing is `unsafe`.

mod arm;
mod callback;
mod cartesian;
mod cartesian_loop;
mod computed;
mod description;
mod dynamic;
mod frames;
mod mujoco;
mod tuning;

use crate::control::config::Law;
use crate::error::Error;
use crate::schema::{Kind, Preset, Scenario, Value, PARAMS};
use crate::sim::model::{Link, TwoLinkArm};
use arm::DynArm;
use dynamic::{
    ArmSpec, CentersSpec, DynTracker, Hooks, Inputs, Last, Owned, ParamError, RunError, Tables,
    JOINT_RECORDS, MAX_JOINTS,
};
use numpy::ndarray::{Array, Dimension, IntoDimension};
use numpy::{
    IntoPyArray, PyArray, PyArray1, PyArray2, PyArrayDescrMethods, PyArrayMethods,
    PyReadonlyArray1, PyReadonlyArray2, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyMemoryError, PyOverflowError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyString};
use std::sync::{Mutex, MutexGuard, TryLockError};
use std::time::{Duration, Instant};

pyo3::import_exception!(adaptimp._errors, ConfigError);
pyo3::import_exception!(adaptimp._errors, MeasurementError);
pyo3::import_exception!(adaptimp._errors, DivergedError);
pyo3::import_exception!(adaptimp._errors, FaultError);

// ---------------------------------------------------------------------------
// Errors: the one place each where core errors become exceptions.
// ---------------------------------------------------------------------------

/// A construction error: `ConfigError` (a `ValueError`) naming the parameter.
fn config_error(e: ParamError) -> PyErr {
    match e.name {
        Some(name) => ConfigError::new_err(format!("{name}: {}", e.error)),
        None => ConfigError::new_err(e.error.to_string()),
    }
}

/// A step's error: `DivergedError` for a diverged state, `FaultError` for a
/// latched fault, `MeasurementError` for an input (named as in Python).
fn step_error(e: Error) -> PyErr {
    let e = python_names(e);
    // The inputs, and what the inputs would drive beyond a limit (the jump,
    // the reference a step would commit): the state is sound, the input is not.
    const INPUTS: [&str; 9] = [
        "q", "dq", "tau_e", "xc", "dxc", "ddxc", "q jump", "xd", "dxd",
    ];
    match e {
        Error::Diverged { .. } => DivergedError::new_err(e.to_string()),
        // An internal signal (ζ, z1, α1, the weights, …) beyond the finite range.
        Error::OutOfRange { what, .. } if !INPUTS.contains(&what) => {
            DivergedError::new_err(e.to_string())
        }
        Error::Faulted { .. } => FaultError::new_err(e.to_string()),
        Error::Condition { .. } | Error::Invalid { .. } => ConfigError::new_err(e.to_string()),
        _ => MeasurementError::new_err(e.to_string()),
    }
}

/// A state that cannot be restored or loaded: `ConfigError` with the core's
/// message (it names the value and the limit).
fn state_error(e: Error) -> PyErr {
    ConfigError::new_err(python_names(e).to_string())
}

/// The fault a step call refused by its arguments' shapes or types records.
const BAD_ARGUMENTS: Error = Error::Invalid {
    what: "step",
    reason: "an argument had the wrong shape or type (the exception raised said which)",
};

/// A run's error: as [`step_error`] with the row, or the hook's exception.
fn run_error(e: RunError, hooks: &mut PyHooks) -> PyErr {
    match e {
        RunError::Stopped => hooks
            .error
            .take()
            .unwrap_or_else(|| PyRuntimeError::new_err("the run was stopped")),
        RunError::Plant(f) if f.fatal => PyRuntimeError::new_err(f.message),
        RunError::Plant(f) => DivergedError::new_err(f.message),
        RunError::Memory(rows) => {
            PyMemoryError::new_err(format!("cannot allocate the records of {rows} rows"))
        }
        RunError::Core(e, None) => step_error(e),
        RunError::Core(e, Some(k)) => {
            let err = step_error(e);
            Python::attach(|py| {
                let msg = format!("row {k}: {}", err.value(py));
                let ty = err.get_type(py);
                PyErr::from_type(ty, msg)
            })
        }
    }
}

/// The core's names of the measurement as Python names them.
fn python_names(e: Error) -> Error {
    let rename = |what: &'static str| match what {
        "x" => "q",
        "dx" => "dq",
        other => other,
    };
    match e {
        Error::NonFinite { what, index } => Error::NonFinite {
            what: rename(what),
            index,
        },
        Error::OutOfRange {
            what,
            index,
            value,
            limit,
        } => Error::OutOfRange {
            what: rename(what),
            index,
            value,
            limit,
        },
        other => other,
    }
}

// ---------------------------------------------------------------------------
// Parameters: the schema (src/schema.rs) is the one source.
// ---------------------------------------------------------------------------

fn law_of(case: &str) -> PyResult<Law> {
    match case {
        "pd" => Ok(Law::Pd),
        "sf" => Ok(Law::StateFeedback),
        "of" => Ok(Law::OutputFeedback),
        other => Err(PyValueError::new_err(format!(
            "case must be 'pd', 'sf' or 'of', got {other:?}"
        ))),
    }
}

fn case_of(law: Law) -> &'static str {
    match law {
        Law::Pd => "pd",
        Law::StateFeedback => "sf",
        Law::OutputFeedback => "of",
    }
}

fn preset_of(scenario: &str) -> PyResult<Preset> {
    Preset::from_name(scenario).ok_or_else(|| {
        PyValueError::new_err(format!(
            "scenario must be one of 'paper', 'robot', got {scenario:?}"
        ))
    })
}

fn check_n(n: usize) -> PyResult<usize> {
    if (1..=MAX_JOINTS).contains(&n) {
        Ok(n)
    } else {
        Err(ConfigError::new_err(format!(
            "n must be between 1 and {MAX_JOINTS} joints, got {n}"
        )))
    }
}

/// A Python value in the schema's terms.
fn owned(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Owned> {
    if obj.is_none() {
        return Ok(Owned::None);
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Owned::Str(obj.extract()?));
    }
    if obj.is_instance_of::<pyo3::types::PyBool>() {
        // A flag's value; the schema refuses it for any other kind.
        return Ok(Owned::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<pyo3::types::PyInt>() {
        return match obj.extract::<i64>() {
            Ok(i) => Ok(Owned::Int(i)),
            Err(_) => Err(ConfigError::new_err(format!(
                "{name} is out of range: {}",
                obj.str().map(|s| s.to_string()).unwrap_or_default()
            ))),
        };
    }
    if let Ok(x) = obj.extract::<f64>() {
        return Ok(Owned::Real(x));
    }
    match obj.extract::<Vec<f64>>() {
        Ok(v) => Ok(Owned::Vec(v)),
        Err(_) => Err(PyTypeError::new_err(format!(
            "{name} must be a number, a sequence of numbers, a string or None"
        ))),
    }
}

fn items(params: &Bound<'_, PyDict>) -> PyResult<Vec<(String, Owned)>> {
    params
        .iter()
        .map(|(k, v)| {
            let name: String = k.extract()?;
            let o = owned(&name, &v)?;
            Ok((name, o))
        })
        .collect()
}

// ---------------------------------------------------------------------------
// Vectors in and out.
// ---------------------------------------------------------------------------

/// Up to [`MAX_JOINTS`] values on the stack.
type Buf = [f64; MAX_JOINTS];

/// A shape as Python prints it: `shape (3,)`, `shape (2, 1)`.
fn python_shape(shape: &[usize]) -> String {
    match shape {
        [n] => format!("shape ({n},)"),
        _ => {
            let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
            format!("shape ({})", dims.join(", "))
        }
    }
}

fn shape_error(what: &str, n: usize, got: &str) -> PyErr {
    MeasurementError::new_err(format!(
        "{what} must have shape ({n},) (one value per joint), got {got}"
    ))
}

fn type_error(what: &str, n: usize, obj: &Bound<'_, PyAny>) -> PyErr {
    let ty = obj
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".to_owned());
    PyTypeError::new_err(format!(
        "{what} must be a sequence or array of {n} real numbers (shape ({n},)), got {ty}"
    ))
}

/// A joint-space vector of n values from Python: an array of shape (n,) of a
/// real dtype, or a sequence of n real numbers (any values). Errors name `what`.
fn vector_any(what: &'static str, n: usize, obj: &Bound<'_, PyAny>) -> PyResult<Buf> {
    let mut out = [0.0; MAX_JOINTS];
    vector_into(what, n, obj, &mut out)?;
    Ok(out)
}

/// A list of exactly `out.len()` real numbers into `out`, without allocating
/// (the hot path of `step` with lists); false for anything else (then `out`
/// may be partly written, and the general path reads or refuses it).
fn list_into(obj: &Bound<'_, PyAny>, out: &mut [f64]) -> bool {
    let Ok(list) = obj.cast::<PyList>() else {
        return false;
    };
    if list.len() != out.len() {
        return false;
    }
    for (o, item) in out.iter_mut().zip(list.iter()) {
        match item.extract::<f64>() {
            Ok(x) => *o = x,
            Err(_) => return false,
        }
    }
    true
}

/// As [`vector_any`], into `out` (the entries past n untouched): a step's
/// arguments go straight into their buffers.
fn vector_into(
    what: &'static str,
    n: usize,
    obj: &Bound<'_, PyAny>,
    out: &mut Buf,
) -> PyResult<()> {
    if let Ok(f) = obj.cast::<PyArray1<f64>>() {
        if f.len() != n {
            return Err(shape_error(what, n, &python_shape(f.shape())));
        }
        // Element by element: no borrow tracking, no allocation (the hot path
        // of `step`); any stride.
        for (i, o) in out[..n].iter_mut().enumerate() {
            *o = f.get_owned(i).unwrap_or(f64::NAN);
        }
    } else if let Ok(arr) = obj.cast::<PyUntypedArray>() {
        if arr.ndim() != 1 || arr.len() != n {
            return Err(shape_error(what, n, &python_shape(arr.shape())));
        }
        if !matches!(arr.dtype().kind(), b'f' | b'i' | b'u') {
            return Err(PyTypeError::new_err(format!(
                "{what} must hold real numbers, got an array of dtype {}",
                arr.dtype()
            )));
        }
        let converted = obj.call_method1("astype", ("float64",))?;
        let f = converted.cast::<PyArray1<f64>>()?;
        let ro = f.try_readonly()?;
        for (o, x) in out.iter_mut().zip(ro.as_array().iter()) {
            *o = *x;
        }
    } else if list_into(obj, &mut out[..n]) {
    } else if obj.is_instance_of::<PyString>() || obj.is_instance_of::<PyBytes>() {
        return Err(type_error(what, n, obj));
    } else if let Ok(v) = obj.extract::<Vec<f64>>() {
        if v.len() != n {
            return Err(shape_error(what, n, &format!("length {}", v.len())));
        }
        out[..n].copy_from_slice(&v);
    } else if obj.extract::<f64>().is_ok() {
        return Err(shape_error(what, n, "a scalar"));
    } else {
        let e = obj.extract::<Vec<f64>>().err();
        let overflow =
            Python::attach(|py| e.is_some_and(|e| e.is_instance_of::<PyOverflowError>(py)));
        if overflow {
            return Err(MeasurementError::new_err(format!(
                "{what} holds a number too large for a float"
            )));
        }
        return Err(type_error(what, n, obj));
    }
    Ok(())
}

/// As [`vector_any`], every entry finite.
fn vector(what: &'static str, n: usize, obj: &Bound<'_, PyAny>) -> PyResult<Buf> {
    let out = vector_any(what, n, obj)?;
    if let Some(index) = out[..n].iter().position(|x| !x.is_finite()) {
        return Err(step_error(Error::NonFinite { what, index }));
    }
    Ok(out)
}

/// `m` locked; while another thread's call holds it, wait with the GIL
/// released (that call may need the GIL to finish), then try again with it.
fn wait_lock<'a, T: ?Sized + Send>(py: Python<'_>, m: &'a Mutex<T>) -> MutexGuard<'a, T> {
    loop {
        match m.try_lock() {
            Ok(g) => return g,
            Err(TryLockError::Poisoned(p)) => return p.into_inner(),
            Err(TryLockError::WouldBlock) => py.detach(|| {
                drop(m.lock());
            }),
        }
    }
}

fn array1<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v)
}

/// Move `data` (row-major) into a NumPy array of shape `shape`, without copying.
fn array<'py, D: Dimension>(
    py: Python<'py>,
    data: Vec<f64>,
    shape: impl IntoDimension<Dim = D>,
) -> PyResult<Bound<'py, PyArray<f64, D>>> {
    let a = Array::from_shape_vec(shape.into_dimension(), data)
        .map_err(|e| PyValueError::new_err(format!("internal shape mismatch: {e}")))?;
    Ok(a.into_pyarray(py))
}

/// A (K, n) float64 table, flattened row-major; the error names it.
fn table(what: &str, a: &PyReadonlyArray2<'_, f64>, rows: usize, n: usize) -> PyResult<Vec<f64>> {
    if a.shape() != [rows, n] {
        return Err(MeasurementError::new_err(format!(
            "{what} must have shape ({rows}, {n}) like q, got {}",
            python_shape(a.shape())
        )));
    }
    Ok(a.as_array().iter().copied().collect())
}

/// The rows of a reference table (xc, ẋc, ẍc, (K, n) each), checked.
fn reference_tables(
    n: usize,
    reference: Option<&PyReference<'_>>,
) -> PyResult<Option<[Vec<f64>; 3]>> {
    let Some((x, dx, ddx)) = reference else {
        return Ok(None);
    };
    let rows = x.shape()[0];
    Ok(Some([
        table("xc", x, rows, n)?,
        table("dxc", dx, rows, n)?,
        table("ddxc", ddx, rows, n)?,
    ]))
}

/// Network weights from a dict of "D" (n, n, L), "C" (n, n, L), "G" (n, L)
/// arrays, as rows ŴD[k][j], ŴC[k][j], ŴG[k]; errors name the key.
fn weight_rows(n: usize, l: usize, weights: &Bound<'_, PyDict>) -> PyResult<Vec<f64>> {
    let mut rows = Vec::with_capacity((2 * n * n + n) * l);
    for (name, shape) in [
        ("D", vec![n, n, l]),
        ("C", vec![n, n, l]),
        ("G", vec![n, l]),
    ] {
        let item = weights.get_item(name)?.ok_or_else(|| {
            ConfigError::new_err(format!("weights has no {name:?} (need D, C and G)"))
        })?;
        let arr = item.cast::<PyUntypedArray>().map_err(|_| {
            PyTypeError::new_err(format!("weights[{name:?}] must be a NumPy array"))
        })?;
        if arr.shape() != shape.as_slice() {
            return Err(ConfigError::new_err(format!(
                "weights[{name:?}] must have {}, got {}",
                python_shape(&shape),
                python_shape(arr.shape())
            )));
        }
        let f = item.call_method1("astype", ("float64",))?;
        let f = f.cast::<PyArray<f64, numpy::IxDyn>>()?.try_readonly()?;
        rows.extend(f.as_array().iter().copied());
    }
    Ok(rows)
}

// ---------------------------------------------------------------------------
// Long calls: signals and progress.
// ---------------------------------------------------------------------------

/// Checks for signals (and reports progress) at most every [`CHECK_EVERY`]
/// of work, taking the GIL only then.
struct PyHooks {
    last: Instant,
    progress: Option<Py<PyAny>>,
    error: Option<PyErr>,
}

/// Time between two checks for signals.
const CHECK_EVERY: Duration = Duration::from_millis(50);

impl PyHooks {
    fn new(progress: Option<Py<PyAny>>) -> Self {
        Self {
            last: Instant::now(),
            progress,
            error: None,
        }
    }
}

impl Hooks for PyHooks {
    fn tick(&mut self, done: u64, total: u64) -> bool {
        // The last step is always reported (a progress bar ends at 100 %,
        // however fast the run); the others at most every CHECK_EVERY.
        if done < total && self.last.elapsed() < CHECK_EVERY {
            return true;
        }
        self.last = Instant::now();
        Python::attach(|py| {
            let result = py.check_signals().and_then(|()| match &self.progress {
                Some(cb) => cb.call1(py, (done, total)).map(|_| ()),
                None => Ok(()),
            });
            match result {
                Ok(()) => true,
                Err(e) => {
                    self.error = Some(e);
                    false
                }
            }
        })
    }
}

// ---------------------------------------------------------------------------
// Controller.
// ---------------------------------------------------------------------------

/// A step's arguments, converted: n values each in fixed buffers.
struct Given {
    x: Buf,
    tau_e: Buf,
    dx: Option<Buf>,
    setpoint: Option<[Buf; 3]>,
}

impl Given {
    const EMPTY: Self = Self {
        x: [0.0; MAX_JOINTS],
        tau_e: [0.0; MAX_JOINTS],
        dx: None,
        setpoint: None,
    };

    fn inputs(&self, n: usize) -> Inputs<'_> {
        Inputs {
            x: &self.x[..n],
            dx: self.dx.as_ref().map(|d| &d[..n]),
            tau_e: &self.tau_e[..n],
            setpoint: self
                .setpoint
                .as_ref()
                .map(|s| [&s[0][..n], &s[1][..n], &s[2][..n]]),
        }
    }
}

/// One of the paper's controllers (SPEC §7) for an arm of n joints, with its
/// commanded trajectory and its state, stepped by the caller at the period
/// Ts (SPEC §11).
///
/// Built from a complete parameter dict; use `adaptimp.Controller`, which
/// fills in the defaults and checks the keywords.
#[pyclass(name = "Controller", module = "adaptimp._adaptimp", frozen, subclass)]
struct PyController {
    inner: Mutex<Box<dyn DynTracker>>,
    n: usize,
    law: Law,
}

impl PyController {
    /// The controller, waiting (with the GIL released) while another thread
    /// uses it.
    fn lock(&self, py: Python<'_>) -> MutexGuard<'_, Box<dyn DynTracker>> {
        wait_lock(py, &self.inner)
    }

    fn wrap(inner: Box<dyn DynTracker>) -> Self {
        Self {
            n: inner.n(),
            law: inner.law(),
            inner: Mutex::new(inner),
        }
    }

    fn last<'py>(&self, py: Python<'py>, what: Last) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.lock(py).last(what))
    }

    /// A step's arguments, converted into `given` (shapes and types checked;
    /// any values). In place: the buffers are not moved about per call.
    fn convert(
        &self,
        q: &Bound<'_, PyAny>,
        tau_e: &Bound<'_, PyAny>,
        dq: Option<&Bound<'_, PyAny>>,
        setpoint: [Option<&Bound<'_, PyAny>>; 3],
        given: &mut Given,
    ) -> PyResult<()> {
        let n = self.n;
        vector_into("q", n, q, &mut given.x)?;
        vector_into("tau_e", n, tau_e, &mut given.tau_e)?;
        given.dx = match (self.law, dq) {
            (Law::OutputFeedback, _) | (_, None) => None,
            (_, Some(dq)) => Some(vector_any("dq", n, dq)?),
        };
        given.setpoint = match setpoint {
            [None, None, None] => None,
            [Some(x), dx, ddx] => {
                let zero = [0.0; MAX_JOINTS];
                let conv = |what, o| vector_any(what, n, o);
                Some([
                    conv("xc", x)?,
                    dx.map(|d| conv("dxc", d)).transpose()?.unwrap_or(zero),
                    ddx.map(|d| conv("ddxc", d)).transpose()?.unwrap_or(zero),
                ])
            }
            [None, ..] => {
                return Err(PyTypeError::new_err(
                    "dxc and ddxc need xc (the commanded position)",
                ))
            }
        };
        Ok(())
    }
}

#[pymethods]
impl PyController {
    /// The controller `case` ("pd", "sf", "of") for `n` joints from the
    /// complete parameter dict `params`, with the paper's vertex grid (n ≤ 3)
    /// or the RBF `centers` (L, 4n) with squared widths `widths2` (4n,).
    #[new]
    #[pyo3(signature = (case, params, n=2, centers=None, widths2=None))]
    fn new(
        case: &str,
        params: &Bound<'_, PyDict>,
        n: usize,
        centers: Option<PyReadonlyArray2<'_, f64>>,
        widths2: Option<PyReadonlyArray1<'_, f64>>,
    ) -> PyResult<Self> {
        let n = check_n(n)?;
        let law = law_of(case)?;
        let items = items(params)?;
        let centers = match (centers, widths2) {
            (None, None) => None,
            (Some(c), Some(w)) => {
                if c.shape()[1] != 4 * n || c.shape()[0] == 0 {
                    return Err(ConfigError::new_err(format!(
                        "centers must have shape (L, {}) (L ≥ 1 rows of x, v, α1, α̇1 for {n} joints), got {}",
                        4 * n,
                        python_shape(c.shape())
                    )));
                }
                Some(CentersSpec {
                    centers: c.as_array().iter().copied().collect(),
                    widths2: w.as_array().iter().copied().collect(),
                })
            }
            _ => {
                return Err(PyTypeError::new_err(
                    "centers and widths2 go together (or neither, for the vertex grid)",
                ))
            }
        };
        let inner = dynamic::build(n, Preset::Paper, law, &items, centers.as_ref())
            .map_err(config_error)?;
        Ok(Self::wrap(inner))
    }

    /// One controller step at t_k = k·Ts: joint positions `q` (rad), the
    /// measured force on the environment `tau_e` (N m) and, for "pd" and
    /// "sf", joint velocities `dq` (rad/s; ignored by "of"); with `xc` (and
    /// optionally `dxc`, `ddxc`, zero if not given) the controller tracks
    /// that setpoint instead of its trajectory. Returns sat(τ) (N m), (n,).
    /// A refused step raises, and records the refusal as `step_or_fallback`
    /// does (the fault, the fallback as the torque applied, the measured
    /// position): the fault semantics of docs/reliability.md.
    #[pyo3(signature = (q, tau_e, dq=None, *, xc=None, dxc=None, ddxc=None))]
    #[allow(clippy::too_many_arguments)]
    fn step<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        tau_e: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
        xc: Option<&Bound<'py, PyAny>>,
        dxc: Option<&Bound<'py, PyAny>>,
        ddxc: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        // Values are the core's to judge (a non-finite one is a refused step
        // that records its fault); shapes and types are checked here.
        let mut given = Given::EMPTY;
        self.convert(q, tau_e, dq, [xc, dxc, ddxc], &mut given)
            .inspect_err(|_| self.lock(py).refuse(BAD_ARGUMENTS))?;
        let mut out = [0.0; MAX_JOINTS];
        self.lock(py)
            .step(&given.inputs(n), &mut out[..n])
            .map_err(step_error)?;
        Ok(array1(py, &out[..n]))
    }

    /// One step as `step`, but never raising for a refused step: returns the
    /// torque to apply (N m, (n,)) and the error message (None on success);
    /// after a refusal the torque is the configured fallback, and the next
    /// step's rate limit starts from it. Shapes and types are still checked
    /// (a wrong one raises, and is recorded as a refused step).
    #[pyo3(signature = (q, tau_e, dq=None, *, xc=None, dxc=None, ddxc=None))]
    #[allow(clippy::too_many_arguments)]
    fn step_or_fallback<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        tau_e: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
        xc: Option<&Bound<'py, PyAny>>,
        dxc: Option<&Bound<'py, PyAny>>,
        ddxc: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Option<String>)> {
        let n = self.n;
        // Shapes and types are checked (a refusal, recorded, then raised);
        // values are the controller's to judge.
        let mut given = Given::EMPTY;
        self.convert(q, tau_e, dq, [xc, dxc, ddxc], &mut given)
            .inspect_err(|_| self.lock(py).refuse(BAD_ARGUMENTS))?;
        let mut out = [0.0; MAX_JOINTS];
        let result = self
            .lock(py)
            .step_or_fallback(&given.inputs(n), &mut out[..n]);
        Ok((
            array1(py, &out[..n]),
            result.err().map(|e| python_names(e).to_string()),
        ))
    }

    /// The fault recorded by the last failed step: (message, step k), or None.
    #[getter]
    fn fault(&self, py: Python<'_>) -> Option<(String, u64)> {
        self.lock(py)
            .fault()
            .map(|(e, k)| (python_names(e).to_string(), k))
    }

    /// Clear the recorded fault; nothing else changes (the learned state,
    /// the torque last applied and the jump anchors are kept).
    fn clear_fault(&self, py: Python<'_>) {
        self.lock(py).clear_fault();
    }

    /// `K` steps in one call from (K, n) float64 tables, without the GIL;
    /// returns sat(τ), (K, n). Signals are checked every 50 ms of work and
    /// `progress(done, total)` is called as often. On an error at row k the
    /// steps before it have been taken and the error names the row.
    #[pyo3(signature = (q, tau_e, dq=None, *, xc=None, dxc=None, ddxc=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn replay<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
        tau_e: PyReadonlyArray2<'py, f64>,
        dq: Option<PyReadonlyArray2<'py, f64>>,
        xc: Option<PyReadonlyArray2<'py, f64>>,
        dxc: Option<PyReadonlyArray2<'py, f64>>,
        ddxc: Option<PyReadonlyArray2<'py, f64>>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.n;
        let rows = q.shape()[0];
        let x = table("q", &q, rows, n)?;
        let te = table("tau_e", &tau_e, rows, n)?;
        let dx = match (self.law, &dq) {
            (Law::OutputFeedback, _) | (_, None) => None,
            (_, Some(dq)) => Some(table("dq", dq, rows, n)?),
        };
        let zeros = || vec![0.0; rows * n];
        let sp = match (&xc, &dxc, &ddxc) {
            (None, None, None) => None,
            (Some(x), dx, ddx) => Some([
                table("xc", x, rows, n)?,
                dx.as_ref()
                    .map(|d| table("dxc", d, rows, n))
                    .transpose()?
                    .unwrap_or_else(zeros),
                ddx.as_ref()
                    .map(|d| table("ddxc", d, rows, n))
                    .transpose()?
                    .unwrap_or_else(zeros),
            ]),
            _ => {
                return Err(PyTypeError::new_err(
                    "dxc and ddxc need xc (the commanded position)",
                ))
            }
        };
        let mut out = Vec::new();
        if out.try_reserve_exact(rows * n).is_err() {
            return Err(PyMemoryError::new_err(format!(
                "cannot allocate the torques of {rows} rows"
            )));
        }
        let mut hooks = PyHooks::new(progress);
        let mut guard = self.lock(py);
        let tables = Tables {
            x: &x,
            dx: dx.as_deref(),
            tau_e: &te,
            setpoint: sp.as_ref().map(|[a, b, c]| [&a[..], &b[..], &c[..]]),
        };
        let tracker: &mut dyn DynTracker = &mut **guard;
        let result = py.detach(|| tracker.replay(rows, &tables, &mut out, &mut hooks));
        drop(guard);
        result.map_err(|e| run_error(e, &mut hooks))?;
        array(py, out, (rows, n))
    }

    /// Back to t = 0, everything as at construction: weights, ζ, observer,
    /// reference, the torque last applied (zero), the jump anchors, the fault.
    fn reset(&self, py: Python<'_>) {
        self.lock(py).reset();
    }

    /// The whole state as a flat float64 array (header, n, L, step count,
    /// reference, ζ, observer, last command, norms, basis, weights, the
    /// torque applied, the last measured position, a checksum); `restore`
    /// puts it back exactly, so a run continues bit-identically.
    fn snapshot<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let data = self.lock(py).snapshot();
        data.into_pyarray(py)
    }

    /// Restore a `snapshot` of a controller with the same n and L. Checked
    /// before anything changes (`ConfigError` naming the value): its format,
    /// its checksum, and that this controller could step it (the reference,
    /// the torques and the weights within their limits, the stored weight
    /// norms those of the weights). Clears a recorded fault.
    fn restore(&self, py: Python<'_>, data: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        let data: Vec<f64> = data.as_array().iter().copied().collect();
        self.lock(py).restore(&data).map_err(state_error)
    }

    /// Replace the network weights: "D" (n, n, L), "C" (n, n, L), "G" (n, L)
    /// float64 arrays (checked: shape, finite, norms within the projection
    /// bounds and 1e100; on an error nothing changes).
    fn load_weights(&self, py: Python<'_>, weights: &Bound<'_, PyDict>) -> PyResult<()> {
        let l = self.lock(py).nodes();
        let rows = weight_rows(self.n, l, weights)?;
        self.lock(py).load_weights(&rows).map_err(state_error)
    }

    /// "pd", "sf" or "of".
    #[getter]
    fn case(&self) -> &'static str {
        case_of(self.law)
    }

    /// Joints n.
    #[getter]
    fn n(&self) -> usize {
        self.n
    }

    /// RBF nodes L.
    #[getter]
    fn nodes(&self, py: Python<'_>) -> usize {
        self.lock(py).nodes()
    }

    /// Time of the next step t_k = k·Ts (s).
    #[getter]
    fn t(&self, py: Python<'_>) -> f64 {
        self.lock(py).time()
    }

    /// Steps taken since construction or reset.
    #[getter]
    fn steps(&self, py: Python<'_>) -> u64 {
        self.lock(py).steps()
    }

    /// Sampling period Ts (s).
    #[getter(Ts)]
    fn ts(&self, py: Python<'_>) -> f64 {
        self.lock(py).ts()
    }

    /// Auxiliary state ζ (N m) now, i.e. what the next step uses, (11).
    #[getter]
    fn zeta<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.lock(py).zeta())
    }

    /// Velocity the last step used (rad/s): dq, or the observer's estimate for "of".
    #[getter]
    fn dq_hat<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.last(py, Last::V)
    }

    /// The last step's commanded torque τ (N m), before saturation.
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.last(py, Last::Tau)
    }

    /// The last step's applied torque sat(τ) (N m).
    #[getter]
    fn tau_sat<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.last(py, Last::TauSat)
    }

    /// The torque to apply now (N m): the last accepted step's sat(τ), or,
    /// after a refused call (also one that raised), the configured fallback;
    /// the next step's rate limit is measured from it.
    #[getter]
    fn applied<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.last(py, Last::Applied)
    }

    /// The last step's Δτ = sat(τ) − τ (N m).
    #[getter]
    fn dtau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.last(py, Last::Dtau)
    }

    /// The last step's tracking error z1 = xd − q (rad).
    #[getter]
    fn z1<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.last(py, Last::Z1)
    }

    /// The last step's commanded position xc (rad).
    #[getter]
    fn xc<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.last(py, Last::Xc)
    }

    /// The last step's compliant reference xd (rad).
    #[getter]
    fn xd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        self.last(py, Last::Xd)
    }

    /// Network weights now (after the last step's update), SPEC §6:
    /// "D" (n, n, L) kg m², "C" (n, n, L) kg m²/s, "G" (n, L) N m,
    /// indexed [k][j][i] (output row, column, node).
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (mut w, l) = {
            let g = self.lock(py);
            (g.weights(), g.nodes())
        };
        let n = self.n;
        let g = w.split_off(2 * n * n * l);
        let c = w.split_off(n * n * l);
        let out = PyDict::new(py);
        out.set_item("D", array(py, w, (n, n, l))?)?;
        out.set_item("C", array(py, c, (n, n, l))?)?;
        out.set_item("G", array(py, g, (n, l))?)?;
        Ok(out)
    }

    /// The projection's weight bounds on ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F as resolved,
    /// or None.
    #[getter]
    fn weight_bound(&self, py: Python<'_>) -> Option<[f64; 3]> {
        self.lock(py).weight_bound()
    }

    /// (g, min Kp): the per-step gain of the explicit-Euler learning step at
    /// the start of the trajectory (N m per rad/s) and the smallest Kp; the
    /// learning loop is stable for g < Kp (docs/robot.md).
    #[getter]
    fn learning_gain(&self, py: Python<'_>) -> (f64, f64) {
        self.lock(py).learning_gain()
    }

    fn __repr__(&self, py: Python<'_>) -> String {
        let g = self.lock(py);
        format!(
            "<adaptimp._adaptimp.Controller case={:?} n={} L={} Ts={} s, t={} s, steps={}>",
            case_of(self.law),
            self.n,
            g.nodes(),
            g.ts(),
            g.time(),
            g.steps()
        )
    }
}

// ---------------------------------------------------------------------------
// Arms.
// ---------------------------------------------------------------------------

/// D(q), C(q, q̇), G(q) and q̈ of `arm`, for both arm classes.
fn arm_matrix<'py>(
    py: Python<'py>,
    n: usize,
    data: Vec<f64>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    array(py, data, (n, n))
}

macro_rules! arm_class {
    ($ty:ty, { $($extra:tt)* }) => {
        #[pymethods]
        impl $ty {
            $($extra)*

            /// Inertia matrix D(q) (kg m²), (n, n).
            #[pyo3(name = "D")]
            fn inertia<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let a = self.dyn_arm();
                let n = a.n();
                arm_matrix(py, n, a.inertia(&vector("q", n, q)?[..n]))
            }

            /// Coriolis and centripetal matrix C(q, dq) (kg m²/s), (n, n).
            #[pyo3(name = "C")]
            fn coriolis<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
                dq: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let a = self.dyn_arm();
                let n = a.n();
                let m = a.coriolis(&vector("q", n, q)?[..n], &vector("dq", n, dq)?[..n]);
                arm_matrix(py, n, m)
            }

            /// Gravity torque G(q) (N m), (n,).
            #[pyo3(name = "G")]
            fn gravity<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray1<f64>>> {
                let a = self.dyn_arm();
                let n = a.n();
                Ok(array1(py, &a.gravity(&vector("q", n, q)?[..n])))
            }

            /// Joint acceleration (rad/s²), (n,), from (4):
            /// D(q) q̈ = tau − tau_e − C(q, dq) dq − G(q).
            fn forward_dynamics<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
                dq: &Bound<'py, PyAny>,
                tau: &Bound<'py, PyAny>,
                tau_e: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray1<f64>>> {
                let a = self.dyn_arm();
                let n = a.n();
                let acc = a.forward_dynamics(
                    &vector("q", n, q)?[..n],
                    &vector("dq", n, dq)?[..n],
                    &vector("tau", n, tau)?[..n],
                    &vector("tau_e", n, tau_e)?[..n],
                );
                Ok(array1(py, &acc))
            }

            /// End-effector position fk(q) (m), (3,): the tip of the last link in
            /// the arm's x–y plane (z = 0), SPEC §16.
            fn fk<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray1<f64>>> {
                let a = self.dyn_arm();
                let n = a.n();
                Ok(array1(py, &a.fk(&vector("q", n, q)?[..n])))
            }

            /// Position Jacobian J(q) = ∂fk/∂q (m/rad), (3, n): ṗ = J q̇, SPEC §16.
            fn jacobian<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let a = self.dyn_arm();
                let n = a.n();
                array(py, a.jacobian(&vector("q", n, q)?[..n]), (3, n))
            }

            /// Joints n.
            #[getter]
            fn n(&self) -> usize {
                self.dyn_arm().n()
            }
        }
    };
}

/// The paper's 2-link arm in a vertical plane, (55)–(63), SPEC §1.
///
/// Built from a complete parameter dict; use `adaptimp.TwoLinkArm`.
#[pyclass(name = "TwoLinkArm", module = "adaptimp._adaptimp", frozen)]
struct PyArm {
    inner: TwoLinkArm,
}

impl PyArm {
    fn dyn_arm(&self) -> &dyn DynArm {
        &self.inner
    }
}

arm_class!(PyArm, {
    #[new]
    #[pyo3(signature = (params))]
    fn new(params: &Bound<'_, PyDict>) -> PyResult<Self> {
        let items = items(params)?;
        let s = dynamic::scenario::<2>(Preset::Paper, Law::Pd, &items).map_err(config_error)?;
        let inner = TwoLinkArm::new(s.arm.resolve()).map_err(|e| config_error(e.into()))?;
        Ok(Self { inner })
    }

    /// The arm's parameters, derived ones included: "m1", "m2" (kg), "l1",
    /// "l2", "lc1", "lc2" (m), "I1", "I2" (kg m²), "g" (m/s²).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = self.inner.params();
        let d = PyDict::new(py);
        for (name, v) in [
            ("m1", p.m1),
            ("m2", p.m2),
            ("l1", p.l1),
            ("l2", p.l2),
            ("lc1", p.lc1),
            ("lc2", p.lc2),
            ("I1", p.i1),
            ("I2", p.i2),
            ("g", p.g),
        ] {
            d.set_item(name, v)?;
        }
        Ok(d)
    }

    /// The lumped parameters p1..p5 of (59)–(63) (kg m², kg m², kg m², kg m, kg m).
    #[getter]
    fn lumped(&self) -> (f64, f64, f64, f64, f64) {
        let [p1, p2, p3, p4, p5] = self.inner.lumped();
        (p1, p2, p3, p4, p5)
    }

    fn __repr__(&self) -> String {
        let p = self.inner.params();
        format!(
            "<adaptimp._adaptimp.TwoLinkArm m=[{}, {}] kg, l=[{}, {}] m, lc=[{}, {}] m, I=[{}, {}] kg m², g={} m/s²>",
            p.m1, p.m2, p.l1, p.l2, p.lc1, p.lc2, p.i1, p.i2, p.g
        )
    }
});

/// An n-link planar arm (1 ≤ n ≤ 7) of revolute joints in a vertical plane:
/// relative joint angles, link 1's angle from the horizontal, gravity along −y.
#[pyclass(name = "PlanarArm", module = "adaptimp._adaptimp", frozen)]
struct PyPlanarArm {
    inner: Box<dyn DynArm>,
    links: Vec<Link>,
    g: f64,
}

impl PyPlanarArm {
    fn dyn_arm(&self) -> &dyn DynArm {
        self.inner.as_ref()
    }
}

arm_class!(PyPlanarArm, {
    /// Links from per-link `masses` (kg), `lengths` (m), `coms` (m, joint to
    /// centre of mass) and `inertias` (kg m², about the centre of mass), and
    /// gravity `g` (m/s²).
    #[new]
    #[pyo3(signature = (masses, lengths, coms, inertias, g))]
    fn new(
        masses: Vec<f64>,
        lengths: Vec<f64>,
        coms: Vec<f64>,
        inertias: Vec<f64>,
        g: f64,
    ) -> PyResult<Self> {
        let n = masses.len();
        if lengths.len() != n || coms.len() != n || inertias.len() != n {
            return Err(ConfigError::new_err(
                "masses, lengths, coms and inertias need one value per link each",
            ));
        }
        let links: Vec<Link> = (0..n)
            .map(|i| Link {
                mass: masses[i],
                length: lengths[i],
                com: coms[i],
                inertia: inertias[i],
            })
            .collect();
        let inner = arm::planar(&links, g).map_err(|e| config_error(e.into()))?;
        Ok(Self { inner, links, g })
    }

    /// Gravity (m/s²).
    #[getter]
    fn g(&self) -> f64 {
        self.g
    }

    fn __repr__(&self) -> String {
        format!(
            "<adaptimp._adaptimp.PlanarArm n={} g={} m/s²>",
            self.links.len(),
            self.g
        )
    }
});

// ---------------------------------------------------------------------------
// simulate.
// ---------------------------------------------------------------------------

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
fn simulate<'py>(
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
        Some(w) => Some(weight_rows(ctrl.n, ctrl.lock(py).nodes(), w)?),
        None => None,
    };
    let mut hooks = PyHooks::new(progress);
    let mut guard = ctrl.lock(py);
    let tracker: &mut dyn DynTracker = &mut **guard;
    let result = py.detach(|| {
        let w = weights.as_deref();
        tracker.simulate(&spec, &items, w, fault.as_ref(), record_every, &mut hooks)
    });
    drop(guard);
    let (rec, metrics) = result.map_err(|e| run_error(e, &mut hooks))?;
    records_dict(py, rec, metrics)
}

/// A run's records and metrics as the dict `simulate` returns: "t" (K,),
/// the per-joint arrays (K, n), "w_norms" (K, 3), "refused" (K,), with the
/// end effector "x_ee" (K, 3) and "wrench_ee" (K, 6) if recorded, and
/// "metrics".
fn records_dict<'py>(
    py: Python<'py>,
    rec: dynamic::Records,
    metrics: dynamic::MetricsOut,
) -> PyResult<Bound<'py, PyDict>> {
    let k = rec.rows();
    let n = rec.n;
    let out = PyDict::new(py);
    out.set_item("t", rec.t.into_pyarray(py))?;
    for (name, data) in JOINT_RECORDS.iter().zip(rec.joint) {
        out.set_item(*name, array(py, data, (k, n))?)?;
    }
    out.set_item("w_norms", array(py, rec.w_norms, (k, 3))?)?;
    out.set_item("refused", PyArray1::from_vec(py, rec.refused))?;
    if rec.ee {
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
fn metrics<'py>(
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
    let rows = dynamic::RowTables {
        n,
        m,
        t: &ts,
        x: [&x[0], &x[1], &x[2]],
        c: [&c[0], &c[1], &c[2]],
        z1: &z,
        tau: [&tq[0], &tq[1], &tq[2]],
    };
    let out = dynamic::metrics_of(
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
type PyFault = (String, f64, f64, Option<Vec<f64>>, Option<f64>);

/// A fault to inject from its Python form ([`PyFault`]).
fn fault_spec(f: Option<PyFault>) -> PyResult<Option<dynamic::FaultSpec>> {
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
            return Err(ConfigError::new_err(format!(
                "fault {other:?} with bias {b:?} and fraction {x:?}: the kinds are 'stale', \
                 'nan_burst', 'skipped', 'force_bias' (with bias) and 'actuator_drop' (with fraction)"
            )))
        }
    };
    Ok(Some(dynamic::FaultSpec {
        kind,
        start,
        duration,
    }))
}

// ---------------------------------------------------------------------------
// The closed loop on MuJoCo.
// ---------------------------------------------------------------------------

/// A plant description from the dict `adaptimp.mujoco.Plant` makes (see
/// [`mujoco::MujocoSpec`]).
fn mujoco_spec(d: &Bound<'_, PyDict>) -> PyResult<mujoco::MujocoSpec> {
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
fn simulate_mujoco<'py>(
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
    let mut hooks = PyHooks::new(progress);
    let mut guard = ctrl.lock(py);
    let tracker: &mut dyn DynTracker = &mut **guard;
    let result = py.detach(|| tracker.simulate_mujoco(&mut sim, &spec, &run, &mut hooks));
    drop(guard);
    drop(sim);
    let (rec, metrics) = result.map_err(|e| run_error(e, &mut hooks))?;
    records_dict(py, rec, metrics)
}

// ---------------------------------------------------------------------------
// Many runs at once: sweeps.
// ---------------------------------------------------------------------------

/// One run of a sweep, parsed while the GIL is held; a run whose parameters
/// cannot make a controller or an arm is its error message.
struct Job {
    law: Law,
    items: Vec<(String, Owned)>,
    arm: ArmSpec,
}

/// A [`ParamError`]'s message, as `config_error` words it.
fn param_message(e: ParamError) -> String {
    match e.name {
        Some(name) => format!("{name}: {}", e.error),
        None => e.error.to_string(),
    }
}

/// Stops a run when asked (from the thread that watches for signals).
struct StopHooks<'a>(&'a std::sync::atomic::AtomicBool);

impl Hooks for StopHooks<'_> {
    fn tick(&mut self, _done: u64, _total: u64) -> bool {
        !self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
}

/// One job, start to end, on the calling thread: its SPEC §12 metrics or the
/// error's message.
fn run_job(
    job: &Result<Job, String>,
    stop: &std::sync::atomic::AtomicBool,
) -> Result<dynamic::MetricsOut, String> {
    let job = job.as_ref().map_err(Clone::clone)?;
    let mut tracker =
        dynamic::build(2, Preset::Paper, job.law, &job.items, None).map_err(param_message)?;
    let mut hooks = StopHooks(stop);
    tracker
        .simulate(&job.arm, &job.items, None, None, u64::MAX, &mut hooks)
        .map(|(_, m)| m)
        .map_err(run_message)
}

fn metrics_to_dict<'py>(
    py: Python<'py>,
    metrics: dynamic::MetricsOut,
) -> PyResult<Bound<'py, PyDict>> {
    let m = PyDict::new(py);
    for (name, v) in metrics.counts {
        m.set_item(name, v)?;
    }
    for (name, v) in metrics.scalars {
        m.set_item(name, v)?;
    }
    for (name, v) in metrics.joint {
        m.set_item(name, v)?;
    }
    Ok(m)
}

/// Run every job of `jobs` — tuples (case, params, arm) of the paper's 2-joint
/// arm (`arm` a `TwoLinkArm`, or None for the arm of `params`) — on `threads`
/// threads (all cores if None), each run single-threaded, with the GIL
/// released. Returns, in order, each run's SPEC §12 metrics (a dict) or its
/// error message (a str; also for parameters that make no controller or no
/// arm): one failing run never stops the others. Results
/// equal those of running the jobs one by one, bit for bit. Ctrl-C stops the
/// batch (`KeyboardInterrupt`) within 50 ms; `progress(done, total)` is called
/// as runs finish, at most every 50 ms.
#[pyfunction]
#[pyo3(signature = (jobs, threads=None, progress=None))]
fn simulate_many<'py>(
    py: Python<'py>,
    jobs: &Bound<'py, PyList>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let mut parsed = Vec::with_capacity(jobs.len());
    for job in jobs.iter() {
        let (case, params, arm): (String, Bound<'py, PyDict>, Bound<'py, PyAny>) = job.extract()?;
        let given = if arm.is_none() {
            None
        } else if let Ok(a) = arm.cast::<PyArm>() {
            Some(ArmSpec::Paper(a.get().inner))
        } else {
            return Err(PyTypeError::new_err(
                "a sweep's arm must be a TwoLinkArm or None",
            ));
        };
        // The values are the run's: an error here is that run's error row.
        let job = (|| -> PyResult<Result<Job, String>> {
            let law = match law_of(&case) {
                Ok(law) => law,
                Err(e) => return Ok(Err(Python::attach(|py| e.value(py).to_string()))),
            };
            let items = items(&params)?;
            let arm = match given {
                Some(arm) => arm,
                None => {
                    let s = match dynamic::scenario::<2>(Preset::Paper, law, &items) {
                        Ok(s) => s,
                        Err(e) => return Ok(Err(param_message(e))),
                    };
                    match TwoLinkArm::new(s.arm.resolve()) {
                        Ok(a) => ArmSpec::Paper(a),
                        Err(e) => return Ok(Err(param_message(e.into()))),
                    }
                }
            };
            Ok(Ok(Job { law, items, arm }))
        })()?;
        parsed.push(job);
    }
    let results = in_parallel(py, &parsed, threads, progress, |job, stop| {
        run_job(job, stop)
    })?;
    let out = PyList::empty(py);
    for r in results {
        match r {
            Ok(m) => out.append(metrics_to_dict(py, m)?)?,
            Err(msg) => out.append(msg)?,
        }
    }
    Ok(out)
}

/// Run `run` on every job on `threads` threads (all cores if None) with the
/// GIL released, in order of the results; this thread watches for signals
/// and reports progress every 50 ms (Ctrl-C stops the remaining runs and
/// raises `KeyboardInterrupt`).
fn in_parallel<J: Sync>(
    py: Python<'_>,
    jobs: &[J],
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
    run: impl Fn(&J, &std::sync::atomic::AtomicBool) -> Result<dynamic::MetricsOut, String> + Sync,
) -> PyResult<Vec<Result<dynamic::MetricsOut, String>>> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the thread pool: {e}")))?;
    let stop = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    let total = jobs.len();
    let mut interrupted: Option<PyErr> = None;
    let results = py.detach(|| {
        std::thread::scope(|scope| {
            let worker = scope.spawn(|| {
                pool.install(|| {
                    jobs.par_iter()
                        .map(|job| {
                            let r = run(job, &stop);
                            done.fetch_add(1, Ordering::Relaxed);
                            r
                        })
                        .collect::<Vec<_>>()
                })
            });
            // This thread watches for signals and reports progress, every
            // 50 ms, and notices the end within 10 ms.
            let mut last = Instant::now();
            while !worker.is_finished() {
                std::thread::sleep(Duration::from_millis(10));
                if last.elapsed() < CHECK_EVERY {
                    continue;
                }
                last = Instant::now();
                let stopped = Python::attach(|py| {
                    let r = py.check_signals().and_then(|()| match &progress {
                        Some(cb) => cb
                            .call1(py, (done.load(Ordering::Relaxed), total))
                            .map(|_| ()),
                        None => Ok(()),
                    });
                    r.err()
                });
                if let Some(e) = stopped {
                    interrupted = Some(e);
                    stop.store(true, Ordering::Relaxed);
                    break;
                }
            }
            worker.join()
        })
    });
    if let Some(e) = interrupted {
        return Err(e);
    }
    results.map_err(|_| PyRuntimeError::new_err("a sweep's worker thread panicked"))
}

/// A MuJoCo job as Python gives it: (controller, model, data, spec, params, T, settle).
type PyMujocoJob<'py> = (
    Bound<'py, PyController>,
    Bound<'py, PyAny>,
    Bound<'py, PyAny>,
    Bound<'py, PyDict>,
    Bound<'py, PyDict>,
    f64,
    f64,
    Option<PyReference<'py>>,
);

/// A reference table: xc, ẋc, ẍc of every row, (K, n) each.
type PyReference<'py> = (
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, f64>,
);

/// One MuJoCo run of a sweep: its controller, plant and settings.
struct MujocoJob {
    ctrl: Py<PyController>,
    sim: Mutex<adaptimp_mujoco::Sim>,
    spec: mujoco::MujocoSpec,
    items: Vec<(String, Owned)>,
    t_final: f64,
    settle: f64,
    /// The commanded setpoints of every row (K × n each), or the controller's own trajectory.
    reference: Option<[Vec<f64>; 3]>,
}

/// The error of a run as a sweep reports it.
fn run_message(e: RunError) -> String {
    match e {
        RunError::Stopped => "stopped".to_owned(),
        RunError::Plant(f) => f.message,
        RunError::Memory(rows) => format!("cannot allocate the records of {rows} rows"),
        RunError::Core(e, None) => python_names(e).to_string(),
        RunError::Core(e, Some(k)) => format!("row {k}: {}", python_names(e)),
    }
}

/// Run every job of `jobs` — tuples (controller, model, data, spec, params,
/// T, settle) as for `simulate_mujoco`, each with its own controller and
/// `MjData` — on `threads` threads (all cores if None), with the GIL
/// released, MuJoCo driven through its C library. Returns, in order, each
/// run's SPEC §12 metrics (a dict) or its error message (a str); results
/// equal those of running each alone. Ctrl-C stops the batch within 50 ms;
/// `progress(done, total)` is called as runs finish.
#[pyfunction]
#[pyo3(signature = (jobs, threads=None, progress=None))]
fn simulate_mujoco_many<'py>(
    py: Python<'py>,
    jobs: &Bound<'py, PyList>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
) -> PyResult<Bound<'py, PyList>> {
    let mut parsed = Vec::with_capacity(jobs.len());
    for job in jobs.iter() {
        let (ctrl, model, data, spec, params, t_final, settle, reference): PyMujocoJob<'py> =
            job.extract()?;
        let reference = reference_tables(ctrl.get().n, reference.as_ref())?;
        parsed.push(MujocoJob {
            ctrl: ctrl.unbind(),
            sim: Mutex::new(adaptimp_mujoco::Sim::from_python(&model, &data)?),
            spec: mujoco_spec(&spec)?,
            items: items(&params)?,
            t_final,
            settle,
            reference,
        });
    }
    let results = in_parallel(py, &parsed, threads, progress, |job, stop| {
        let run = dynamic::MujocoRun {
            t_final: job.t_final,
            settle: job.settle,
            every: u64::MAX,
            items: &job.items,
            reference: job
                .reference
                .as_ref()
                .map(|[x, dx, ddx]| [x.as_slice(), dx.as_slice(), ddx.as_slice()]),
            fault: None,
        };
        let mut hooks = StopHooks(stop);
        let mut sim = job.sim.lock().unwrap_or_else(|p| p.into_inner());
        let mut tracker = job
            .ctrl
            .get()
            .inner
            .lock()
            .unwrap_or_else(|p| p.into_inner());
        tracker
            .simulate_mujoco(&mut sim, &job.spec, &run, &mut hooks)
            .map(|(_, m)| m)
            .map_err(run_message)
    })?;
    drop(parsed);
    let out = PyList::empty(py);
    for r in results {
        match r {
            Ok(m) => out.append(metrics_to_dict(py, m)?)?,
            Err(msg) => out.append(msg)?,
        }
    }
    Ok(out)
}

/// A schema value as Python sees it: float, int, list of floats, str, bool or None.
fn py_value<'py>(py: Python<'py>, v: Value<'_>) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Real(x) => x.into_pyobject(py)?.into_any(),
        Value::Int(i) => i.into_pyobject(py)?.into_any(),
        Value::Vec(v) => PyList::new(py, v)?.into_any(),
        Value::Str(s) => PyString::new(py, s).into_any(),
        Value::Bool(b) => pyo3::types::PyBool::new(py, b).to_owned().into_any(),
        Value::None => py.None().into_bound(py),
    })
}

/// The parameter schema (src/schema.rs), the one source of every parameter:
/// a list of dicts with "name", "group", "kind", "unit", "doc", "condition",
/// "choices" (for a choice) and "defaults" (per scenario, as the schema
/// declares them: a number may stand for every joint).
#[pyfunction]
fn schema_table(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for p in PARAMS {
        let d = PyDict::new(py);
        d.set_item("name", p.name)?;
        d.set_item("group", p.group.name())?;
        d.set_item("kind", p.kind.name())?;
        d.set_item("unit", p.unit)?;
        d.set_item("doc", p.doc)?;
        d.set_item("condition", p.condition)?;
        let choices: &[&str] = match p.kind {
            Kind::Choice(c) => c,
            _ => &[],
        };
        d.set_item("choices", PyList::new(py, choices)?)?;
        let defaults = PyDict::new(py);
        for preset in Preset::ALL {
            defaults.set_item(preset.name(), py_value(py, p.default_in(preset))?)?;
        }
        d.set_item("defaults", defaults)?;
        out.append(d)?;
    }
    Ok(out)
}

/// Every parameter's default in `scenario` ("paper" or "robot") for `n`
/// joints, keyed by name: per-joint values as lists of n, derived arm values
/// as None.
#[pyfunction]
#[pyo3(signature = (scenario="paper", n=2))]
fn defaults<'py>(py: Python<'py>, scenario: &str, n: usize) -> PyResult<Bound<'py, PyDict>> {
    let preset = preset_of(scenario)?;
    let d = PyDict::new(py);
    let mut err = Ok(());
    macro_rules! visit {
        ($($k:literal)*) => {
            match check_n(n)? {
                $($k => Scenario::<$k>::preset(preset, Law::StateFeedback).visit(|name, v| {
                    if err.is_ok() {
                        err = py_value(py, v).and_then(|v| d.set_item(name, v));
                    }
                }),)*
                _ => {}
            }
        };
    }
    visit!(1 2 3 4 5 6 7);
    err?;
    Ok(d)
}

/// Adaptive neural impedance control with input saturation (He, Dong & Sun,
/// IEEE TSMC 2016): the compiled core for arms of 1 to 7 joints. Use the
/// `adaptimp` package, which wraps this module.
#[pymodule]
#[pyo3(name = "_adaptimp")]
mod adaptimp_module {
    use pyo3::prelude::*;

    #[pymodule_export]
    use super::tuning::{
        assess_posture, default_task, pose_circle, pose_metrics, suggest, table_metrics,
    };
    #[pymodule_export]
    use super::{
        defaults, metrics, schema_table, simulate, simulate_many, simulate_mujoco,
        simulate_mujoco_many, PyArm, PyController, PyPlanarArm,
    };

    #[pymodule_export]
    use super::callback::simulate_mujoco_callback;
    #[pymodule_export]
    use super::cartesian::{centres_along, PyCartesian, PyChain};
    #[pymodule_export]
    use super::computed::PyComputedTorque;
    #[pymodule_export]
    use super::description::{arm_from_mujoco, description_kind, read_arm};

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        m.add("MAX_JOINTS", super::MAX_JOINTS)?;
        m.add("N_NODES", crate::types::grid_nodes(2))?;
        // Load NumPy's C API now, at import: loading it lazily inside a call
        // can meet a pending KeyboardInterrupt and fail with a panic.
        let _ = numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
        Ok(())
    }
}
