//! Python bindings: the extension module `adaptimp._adaptimp` (cargo feature
//! `python`, built by maturin; see `pyproject.toml`).
//!
//! Thin wrappers over the core for the paper's arm: N = 2 joints and the
//! L = 2^(4N) = 256-node RBF grid. The friendly layer (keyword parameters with
//! the paper's defaults, result objects, plots, the CLI) is pure Python in
//! `python/adaptimp/`; it hands this module complete parameter dicts whose
//! keys are the Python parameter names (`Ts`, `Kp`, `Kzeta`, …).
//!
//! - Every [`Error`] of the core becomes a `ValueError` with its `Display`
//!   text (which names the SPEC §10 condition and the value) in one place:
//!   `impl From<Error> for PyErr` below.
//! - [`simulate`] runs with the GIL released and hands its records to NumPy
//!   without copying (one `Vec<f64>` per quantity, moved into the array).
//! - Vectors from Python are checked here for shape, type and finiteness, so
//!   the error names the Python argument (`q`, `dq`, `tau_e`, …).
//!
//! Nothing here panics on user input and nothing is `unsafe`.

use crate::config::Law;
use crate::controller::Controller;
use crate::environment::{FreeSpace, Wall};
use crate::error::Error;
use crate::io::{Command, Measurement};
use crate::metrics::Metrics;
use crate::model::{Manipulator, TwoLinkArm};
use crate::rbf::Grid;
use crate::record::{Recorder, Row};
use crate::schema::{Kind, Preset, Scenario, Value, PARAMS};
use crate::simulator::run;
use crate::tracker::Tracker;
use crate::trajectory::Sinusoid;
use crate::types::{grid_nodes, Vector};
use numpy::ndarray::{Array, Dimension, IntoDimension};
use numpy::{
    IntoPyArray, PyArray, PyArray1, PyArray2, PyArrayDescrMethods, PyArrayMethods,
    PyReadonlyArray2, PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyMemoryError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyString};

/// Joints of the paper's arm.
const N: usize = 2;
/// RBF nodes of the paper's vertex grid, 2^(4N).
const L: usize = grid_nodes(N);

type Ctrl = Tracker<N, Grid<N>, Sinusoid<N>>;

/// The one place where core errors become Python exceptions: `ValueError`
/// with the core's message (condition, quantity and value for SPEC §10).
impl From<Error> for PyErr {
    fn from(e: Error) -> PyErr {
        PyValueError::new_err(e.to_string())
    }
}

// ---------------------------------------------------------------------------
// Parameters: the schema (src/schema.rs) is the one source. The Python layer
// (`_params.py`) builds its keyword table from `schema()` and its defaults
// from `defaults()`, and hands complete dicts back; they are applied here by
// name through `Scenario::set`.
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

/// A step's error with the measurement named as in Python (`q`, `dq`, not
/// the core's `x`, `dx`).
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

/// A Python value in the schema's terms, owned.
enum Owned {
    Real(f64),
    Int(i64),
    Vec(Vec<f64>),
    Str(String),
    None,
}

impl Owned {
    fn extract(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Self> {
        if obj.is_none() {
            return Ok(Owned::None);
        }
        if obj.is_instance_of::<PyString>() {
            return Ok(Owned::Str(obj.extract()?));
        }
        if obj.is_instance_of::<pyo3::types::PyBool>() {
            return Err(PyTypeError::new_err(format!(
                "{name} must be a number, got bool"
            )));
        }
        if obj.is_instance_of::<pyo3::types::PyInt>() {
            return match obj.extract::<i64>() {
                Ok(i) => Ok(Owned::Int(i)),
                Err(_) => Err(PyValueError::new_err(format!(
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

    fn value(&self) -> Value<'_> {
        match self {
            Owned::Real(x) => Value::Real(*x),
            Owned::Int(i) => Value::Int(*i),
            Owned::Vec(v) => Value::Vec(v),
            Owned::Str(s) => Value::Str(s),
            Owned::None => Value::None,
        }
    }
}

/// The paper scenario's defaults for `case` updated by every item of `params`
/// (keys are schema names). The error names the key.
fn scenario(case: &str, params: &Bound<'_, PyDict>) -> PyResult<Scenario<N>> {
    let mut s = Scenario::<N>::preset(Preset::Paper, law_of(case)?);
    for (key, value) in params.iter() {
        let name: String = key.extract()?;
        let v = Owned::extract(&name, &value)?;
        s.set(&name, v.value())
            .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
    }
    Ok(s)
}

fn build_controller(case: &str, params: &Bound<'_, PyDict>) -> PyResult<Ctrl> {
    let s = scenario(case, params)?;
    let traj = s.trajectory()?;
    let ctrl = Controller::for_trajectory(s.config, s.grid()?, &traj)?;
    Ok(Tracker::new(ctrl, traj))
}

// ---------------------------------------------------------------------------
// Vectors in and out.
// ---------------------------------------------------------------------------

fn shape_error(what: &str, got: &str) -> PyErr {
    PyValueError::new_err(format!(
        "{what} must have shape ({N},) (one value per joint), got {got}"
    ))
}

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

fn type_error(what: &str, obj: &Bound<'_, PyAny>) -> PyErr {
    let ty = obj
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".to_owned());
    PyTypeError::new_err(format!(
        "{what} must be a sequence or array of {N} real numbers (shape ({N},)), got {ty}"
    ))
}

/// A joint-space vector from Python: an array of shape (N,) of a real dtype,
/// or a sequence of N real numbers (any values). Errors name `what`.
fn vector_any(what: &'static str, obj: &Bound<'_, PyAny>) -> PyResult<Vector<N>> {
    let mut out = [0.0; N];
    if let Ok(arr) = obj.cast::<PyUntypedArray>() {
        if arr.ndim() != 1 || arr.len() != N {
            return Err(shape_error(what, &python_shape(arr.shape())));
        }
        if !matches!(arr.dtype().kind(), b'f' | b'i' | b'u') {
            return Err(PyTypeError::new_err(format!(
                "{what} must hold real numbers, got an array of dtype {}",
                arr.dtype()
            )));
        }
        let converted;
        let f = match obj.cast::<PyArray1<f64>>() {
            Ok(f) => f,
            Err(_) => {
                converted = obj.call_method1("astype", ("float64",))?;
                converted.cast::<PyArray1<f64>>()?
            }
        };
        let ro = f.try_readonly()?;
        for (o, x) in out.iter_mut().zip(ro.as_array().iter()) {
            *o = *x;
        }
    } else if obj.is_instance_of::<PyString>() || obj.is_instance_of::<PyBytes>() {
        return Err(type_error(what, obj));
    } else if let Ok(v) = obj.extract::<Vec<f64>>() {
        if v.len() != N {
            return Err(shape_error(what, &format!("length {}", v.len())));
        }
        out.copy_from_slice(&v);
    } else if obj.extract::<f64>().is_ok() {
        return Err(shape_error(what, "a scalar"));
    } else {
        return Err(type_error(what, obj));
    }
    Ok(Vector::from(out))
}

/// As `vector_any`, every entry finite.
fn vector(what: &'static str, obj: &Bound<'_, PyAny>) -> PyResult<Vector<N>> {
    let out = vector_any(what, obj)?;
    if let Some(index) = out.iter().position(|x| !x.is_finite()) {
        return Err(Error::NonFinite { what, index }.into());
    }
    Ok(out)
}

fn array1<'py>(py: Python<'py>, v: &Vector<N>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v.as_slice())
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

/// The rows of a weight table, concatenated (row-major over [k][j][i]).
fn flatten<'a>(rows: impl Iterator<Item = &'a [f64]>) -> Vec<f64> {
    let mut v = Vec::with_capacity(N * N * L);
    for row in rows {
        v.extend_from_slice(row);
    }
    v
}

// ---------------------------------------------------------------------------
// Controller.
// ---------------------------------------------------------------------------

/// One of the paper's controllers (SPEC §7) for the 2-link arm, with its
/// state, stepped by the caller at the period Ts (SPEC §11).
///
/// Built from a complete parameter dict; use `adaptimp.Controller`, which
/// fills in the paper's defaults and checks the keywords.
#[pyclass(name = "Controller", module = "adaptimp._adaptimp")]
struct PyController {
    inner: Box<Ctrl>,
}

#[pymethods]
impl PyController {
    #[new]
    #[pyo3(signature = (case, params))]
    fn new(case: &str, params: &Bound<'_, PyDict>) -> PyResult<Self> {
        Ok(Self {
            inner: Box::new(build_controller(case, params)?),
        })
    }

    /// One controller step at t_k = k·Ts: joint positions `q` (rad), the
    /// measured force on the environment `tau_e` (N m) and, for "pd" and
    /// "sf", joint velocities `dq` (rad/s; ignored by "of"). Returns the
    /// applied torque sat(τ) (N m), shape (2,).
    #[pyo3(signature = (q, tau_e, dq=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        tau_e: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let x = vector("q", q)?;
        let tau_e = vector("tau_e", tau_e)?;
        let dx = match (self.inner.controller().config().law, dq) {
            (Law::OutputFeedback, _) | (_, None) => None,
            (_, Some(dq)) => Some(vector("dq", dq)?),
        };
        let cmd = self
            .inner
            .step(&Measurement { x, dx, tau_e })
            .map_err(python_names)?;
        Ok(array1(py, &cmd.tau_sat))
    }

    /// One step as `step`, but never raising for a failed step: returns the
    /// torque to apply (N m, shape (2,)): the step's sat(τ), or on a failed
    /// step the configured fallback ("hold", "zero" or "damping", saturated),
    /// and the error message (None on success). Shapes and types are still
    /// checked (TypeError/ValueError).
    #[pyo3(signature = (q, tau_e, dq=None))]
    fn step_or_fallback<'py>(
        &mut self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        tau_e: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Option<String>)> {
        // Shapes are checked; values are the controller's to judge.
        let x = vector_any("q", q)?;
        let tau_e = vector_any("tau_e", tau_e)?;
        let dx = match (self.inner.controller().config().law, dq) {
            (Law::OutputFeedback, _) | (_, None) => None,
            (_, Some(dq)) => Some(vector_any("dq", dq)?),
        };
        let (tau, result) = self.inner.step_or_fallback(&Measurement { x, dx, tau_e });
        Ok((
            array1(py, &tau),
            result.err().map(|e| python_names(e).to_string()),
        ))
    }

    /// The fault recorded by the last failed step: (message, step k), or None.
    #[getter]
    fn fault(&self) -> Option<(String, u64)> {
        self.inner
            .state()
            .fault()
            .map(|f| (f.error.to_string(), f.step))
    }

    /// Clear the recorded fault (with fault_policy="latch", steps are refused
    /// until this is called).
    fn clear_fault(&mut self) {
        self.inner.state_mut().clear_fault();
    }

    /// `K` steps in one call, replaying logged measurements: `q`, `tau_e` and
    /// (for "pd", "sf") `dq` of shape (K, 2), float64, C-contiguous. Returns
    /// the applied torques, shape (K, 2). Runs without the GIL. On an error at
    /// row k the steps before it have been taken and the error names the row.
    #[pyo3(signature = (q, tau_e, dq=None))]
    fn replay<'py>(
        &mut self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
        tau_e: PyReadonlyArray2<'py, f64>,
        dq: Option<PyReadonlyArray2<'py, f64>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows = q.shape()[0];
        let table = |what: &str, a: &PyReadonlyArray2<'py, f64>| -> PyResult<Vec<f64>> {
            if a.shape() != [rows, N] {
                return Err(PyValueError::new_err(format!(
                    "{what} must have shape ({rows}, {N}) like q, got {}",
                    python_shape(a.shape())
                )));
            }
            Ok(a.as_array().iter().copied().collect())
        };
        let x = table("q", &q)?;
        let te = table("tau_e", &tau_e)?;
        let law = self.inner.controller().config().law;
        let dx = match (law, &dq) {
            (Law::OutputFeedback, _) | (_, None) => None,
            (_, Some(dq)) => Some(table("dq", dq)?),
        };
        let ctrl = &mut self.inner;
        let out = py.detach(|| -> Result<Vec<f64>, (usize, Error)> {
            let mut out = Vec::with_capacity(rows * N);
            let row = |v: &[f64], k: usize| Vector::<N>::from_column_slice(&v[k * N..(k + 1) * N]);
            for k in 0..rows {
                let m = Measurement {
                    x: row(&x, k),
                    dx: dx.as_ref().map(|d| row(d, k)),
                    tau_e: row(&te, k),
                };
                let cmd = ctrl.step(&m).map_err(|e| (k, e))?;
                out.extend_from_slice(cmd.tau_sat.as_slice());
            }
            Ok(out)
        });
        match out {
            Ok(out) => array(py, out, (rows, N)),
            Err((k, e)) => Err(PyValueError::new_err(format!("row {k}: {e}"))),
        }
    }

    /// Back to t = 0: weights, ζ, observer and reference as at construction.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// "pd", "sf" or "of".
    #[getter]
    fn case(&self) -> &'static str {
        case_of(self.inner.controller().config().law)
    }

    /// Time of the next step t_k = k·Ts (s).
    #[getter]
    fn t(&self) -> f64 {
        self.inner.time()
    }

    /// Steps taken since construction or reset.
    #[getter]
    fn steps(&self) -> u64 {
        self.inner.state().steps()
    }

    /// Sampling period Ts (s).
    #[getter]
    fn ts(&self) -> f64 {
        self.inner.controller().period()
    }

    /// Auxiliary state ζ (N m) now, i.e. what the next step uses, (11).
    #[getter]
    fn zeta<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, self.inner.state().zeta())
    }

    /// Velocity the last step used (rad/s): dq, or the observer's estimate for "of".
    #[getter]
    fn dq_hat<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.last().v)
    }

    /// The last step's commanded torque τ (N m), before saturation.
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.last().tau)
    }

    /// The last step's applied torque sat(τ) (N m).
    #[getter]
    fn tau_sat<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.last().tau_sat)
    }

    /// The last step's Δτ = sat(τ) − τ (N m).
    #[getter]
    fn dtau<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.last().dtau)
    }

    /// The last step's tracking error z1 = xd − q (rad).
    #[getter]
    fn z1<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.last().z1)
    }

    /// The last step's commanded position xc (rad).
    #[getter]
    fn xc<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.last().xc)
    }

    /// The last step's compliant reference xd (rad).
    #[getter]
    fn xd<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.last().xd)
    }

    /// Network weights now (after the last step's update), SPEC §6:
    /// "D" (2, 2, 256) kg m², "C" (2, 2, 256) kg m²/s, "G" (2, 256) N m,
    /// indexed [k][j][i] (output row, column, node).
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let w = self.inner.state().weights();
        let out = PyDict::new(py);
        for (name, net) in [("D", crate::network::D), ("C", crate::network::C)] {
            out.set_item(name, array(py, flatten(w.network(net)), (N, N, L))?)?;
        }
        out.set_item(
            "G",
            array(py, flatten(w.network(crate::network::G)), (N, L))?,
        )?;
        Ok(out)
    }

    /// The projection's weight bounds on ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F as resolved
    /// (kg m², kg m²/s, N m; "auto" derived from τmax and the trajectory),
    /// or None.
    #[getter]
    fn weight_bound(&self) -> Option<[f64; 3]> {
        self.inner.controller().learning().bound()
    }

    fn __repr__(&self) -> String {
        format!(
            "<adaptimp._adaptimp.Controller case={:?} Ts={} s, t={} s, steps={}>",
            self.case(),
            self.ts(),
            self.t(),
            self.steps()
        )
    }
}

impl PyController {
    fn last(&self) -> &Command<N> {
        self.inner.state().last()
    }
}

// ---------------------------------------------------------------------------
// TwoLinkArm.
// ---------------------------------------------------------------------------

/// The paper's 2-link arm in a vertical plane, (55)–(63), SPEC §1.
///
/// Built from a complete parameter dict; use `adaptimp.TwoLinkArm`, which
/// fills in the defaults.
#[pyclass(name = "TwoLinkArm", module = "adaptimp._adaptimp", frozen)]
struct PyArm {
    inner: TwoLinkArm,
}

#[pymethods]
impl PyArm {
    #[new]
    #[pyo3(signature = (params))]
    fn new(params: &Bound<'_, PyDict>) -> PyResult<Self> {
        let s = scenario("pd", params)?;
        Ok(Self {
            inner: TwoLinkArm::new(s.arm.resolve())?,
        })
    }

    /// Inertia matrix D(q) (kg m²), shape (2, 2), (56).
    #[pyo3(name = "D")]
    fn inertia<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray<f64, numpy::Ix2>>> {
        let m = self.inner.inertia(&vector("q", q)?);
        array(py, m.transpose().as_slice().to_vec(), (N, N))
    }

    /// Coriolis and centripetal matrix C(q, dq) (kg m²/s), shape (2, 2), (57).
    #[pyo3(name = "C")]
    fn coriolis<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        dq: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray<f64, numpy::Ix2>>> {
        let m = self.inner.coriolis(&vector("q", q)?, &vector("dq", dq)?);
        array(py, m.transpose().as_slice().to_vec(), (N, N))
    }

    /// Gravity torque G(q) (N m), shape (2,), (58).
    #[pyo3(name = "G")]
    fn gravity<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(array1(py, &self.inner.gravity(&vector("q", q)?)))
    }

    /// Joint acceleration (rad/s²), shape (2,), from (4):
    /// D(q) q̈ = tau − tau_e − C(q, dq) dq − G(q), with `tau` the applied
    /// (saturated) torque and `tau_e` the force on the environment (N m).
    fn forward_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        dq: &Bound<'py, PyAny>,
        tau: &Bound<'py, PyAny>,
        tau_e: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let a = self.inner.forward_dynamics(
            &vector("q", q)?,
            &vector("dq", dq)?,
            &vector("tau", tau)?,
            &vector("tau_e", tau_e)?,
        );
        Ok(array1(py, &a))
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
}

// ---------------------------------------------------------------------------
// simulate.
// ---------------------------------------------------------------------------

/// Every recorded row, one flat row-major buffer per quantity.
#[derive(Default)]
struct Buffers {
    t: Vec<f64>,
    q: Vec<f64>,
    dq: Vec<f64>,
    xc: Vec<f64>,
    xd: Vec<f64>,
    dq_hat: Vec<f64>,
    tau: Vec<f64>,
    tau_sat: Vec<f64>,
    tau_e: Vec<f64>,
    zeta: Vec<f64>,
    z1: Vec<f64>,
    w_norms: Vec<f64>,
}

impl Buffers {
    /// Buffers with room for `rows` rows; `MemoryError` if that cannot be had.
    fn with_rows(rows: usize) -> PyResult<Self> {
        let mut b = Self::default();
        let oom = |_| PyMemoryError::new_err(format!("cannot allocate the records of {rows} rows"));
        b.t.try_reserve_exact(rows).map_err(oom)?;
        for v in [
            &mut b.q,
            &mut b.dq,
            &mut b.xc,
            &mut b.xd,
            &mut b.dq_hat,
            &mut b.tau,
            &mut b.tau_sat,
            &mut b.tau_e,
            &mut b.zeta,
            &mut b.z1,
        ] {
            v.try_reserve_exact(rows.saturating_mul(N)).map_err(oom)?;
        }
        b.w_norms
            .try_reserve_exact(rows.saturating_mul(3))
            .map_err(oom)?;
        Ok(b)
    }
}

impl Recorder<N> for Buffers {
    fn record(&mut self, r: &Row<N>) {
        self.t.push(r.t);
        self.q.extend_from_slice(r.x.as_slice());
        self.dq.extend_from_slice(r.dx.as_slice());
        self.xc.extend_from_slice(r.xc.as_slice());
        self.xd.extend_from_slice(r.xd.as_slice());
        self.dq_hat.extend_from_slice(r.dx_hat.as_slice());
        self.tau.extend_from_slice(r.tau.as_slice());
        self.tau_sat.extend_from_slice(r.tau_sat.as_slice());
        self.tau_e.extend_from_slice(r.tau_e.as_slice());
        self.zeta.extend_from_slice(r.zeta.as_slice());
        self.z1.extend_from_slice(r.z1.as_slice());
        self.w_norms.extend_from_slice(&r.w_norms);
    }
}

fn metrics_dict<'py>(py: Python<'py>, m: &Metrics<N>) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let joint = |v: &Vector<N>| v.as_slice().to_vec();
    d.set_item("rows", m.rows)?;
    d.set_item("rms_z1", m.rms_z1)?;
    d.set_item("rms_z1_after2", m.rms_z1_after2)?;
    d.set_item("rms_z1_joint_after2", joint(&m.rms_z1_joint_after2))?;
    d.set_item("max_abs_z1_joint_after2", joint(&m.max_abs_z1_joint_after2))?;
    d.set_item("sat_duty", m.sat_duty)?;
    d.set_item("steps_in_contact", m.steps_in_contact)?;
    d.set_item("peak_contact_after2", m.peak_contact_after2)?;
    d.set_item("mean_contact", m.mean_contact)?;
    d.set_item("peak_abs_tau", joint(&m.peak_abs_tau))?;
    d.set_item("imp_err_rms_after2", m.imp_err_rms_after2)?;
    Ok(d)
}

/// Close the loop of `controller` (reset first) with the arm `arm` and the
/// wall (or free space) of `params`, integrating the plant with RK4 (SPEC
/// §11), with the GIL released. Returns a dict of the recorded arrays
/// ("t" (K,), "q", "dq", "xc", "xd", "dq_hat", "tau", "tau_sat", "tau_e",
/// "zeta", "z1" (K, 2), "w_norms" (K, 3)) and "metrics" (SPEC §12).
/// `controller` is left in its state at the end of the run.
#[pyfunction]
#[pyo3(signature = (controller, arm, params))]
fn simulate<'py>(
    py: Python<'py>,
    controller: &Bound<'py, PyController>,
    arm: &Bound<'py, PyArm>,
    params: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    let s = scenario("pd", params)?;
    let wall = match s.wall {
        Some(w) => Some(Wall::<N>::new(0, w, s.ke_be[0], s.ke_be[1])?),
        None => None,
    };
    let plant = arm.get().inner;
    let mut guard = controller.try_borrow_mut()?;
    let ctrl: &mut Ctrl = &mut guard.inner;
    // Room for every row (the core re-checks T and Ts and reports bad ones).
    let rows = crate::simulator::steps(s.sim.t_final, ctrl.controller().period())
        .ok()
        .and_then(|r| usize::try_from(r).ok())
        .unwrap_or(0);
    let mut rec = Buffers::with_rows(rows)?;
    let cfg = s.sim;
    let metrics = py.detach(|| {
        ctrl.reset();
        let traj = *ctrl.trajectory();
        match wall {
            Some(w) => run(&plant, &w, ctrl, &traj, &cfg, &mut rec),
            None => run(&plant, &FreeSpace, ctrl, &traj, &cfg, &mut rec),
        }
    })?;
    drop(guard);

    let k = rec.t.len();
    let out = PyDict::new(py);
    out.set_item("t", rec.t.into_pyarray(py))?;
    for (name, data) in [
        ("q", rec.q),
        ("dq", rec.dq),
        ("xc", rec.xc),
        ("xd", rec.xd),
        ("dq_hat", rec.dq_hat),
        ("tau", rec.tau),
        ("tau_sat", rec.tau_sat),
        ("tau_e", rec.tau_e),
        ("zeta", rec.zeta),
        ("z1", rec.z1),
    ] {
        out.set_item(name, array(py, data, (k, N))?)?;
    }
    out.set_item("w_norms", array(py, rec.w_norms, (k, 3))?)?;
    out.set_item("metrics", metrics_dict(py, &metrics)?)?;
    Ok(out)
}

/// A schema value as Python sees it: float, int, list of floats, str or None.
fn py_value<'py>(py: Python<'py>, v: Value<'_>) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Real(x) => x.into_pyobject(py)?.into_any(),
        Value::Int(i) => i.into_pyobject(py)?.into_any(),
        Value::Vec(v) => PyList::new(py, v)?.into_any(),
        Value::Str(s) => PyString::new(py, s).into_any(),
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

/// Every parameter's default in `scenario` ("paper" or "robot") for the
/// paper's 2-link arm, keyed by name: per-joint values as lists of 2, derived
/// arm values as None.
#[pyfunction]
#[pyo3(signature = (scenario="paper"))]
fn defaults<'py>(py: Python<'py>, scenario: &str) -> PyResult<Bound<'py, PyDict>> {
    let preset = Preset::from_name(scenario).ok_or_else(|| {
        PyValueError::new_err(format!(
            "scenario must be one of 'paper', 'robot', got {scenario:?}"
        ))
    })?;
    let d = PyDict::new(py);
    let mut err = Ok(());
    Scenario::<N>::preset(preset, Law::StateFeedback).visit(|name, v| {
        if err.is_ok() {
            err = py_value(py, v).and_then(|v| d.set_item(name, v));
        }
    });
    err?;
    Ok(d)
}

/// Adaptive neural impedance control with input saturation (He, Dong & Sun,
/// IEEE TSMC 2016): the compiled core for the paper's 2-link arm. Use the
/// `adaptimp` package, which wraps this module.
#[pymodule]
#[pyo3(name = "_adaptimp")]
mod adaptimp_module {
    use pyo3::prelude::*;

    #[pymodule_export]
    use super::{defaults, schema_table, simulate, PyArm, PyController};

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        m.add("N_JOINTS", super::N)?;
        m.add("N_NODES", super::L)?;
        Ok(())
    }
}
