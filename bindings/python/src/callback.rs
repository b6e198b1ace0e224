//! A controller written in Python in the core's closed loop on MuJoCo (SPEC
//! §13.1): [`PyStep`] is the loop's [`Control`], and its step calls the
//! Python object's `step` once a period with the GIL taken for that call
//! only (the loop runs with it released). The protocol is
//! `adaptimp.mujoco.ControllerLike`:
//!
//! - `step(m, **setpoint)`, `m` an `adaptimp.Measurement` (q, q̇, τe and the
//!   wrench F_e, as the core's loop measures them, SPEC §17's disturbances
//!   and faults included; a joint controller reads τe, a task-space one
//!   F_e), or one of the deprecated shapes [`CallShape`] names, `setpoint` the
//!   keywords `xc`, `dxc`, `ddxc` of the row when the run has a reference;
//!   it returns the torque (n values, or one for every joint);
//! - the attributes the run reads when the controller has them (Python
//!   tells which, [`Attrs`]): `zeta` before the step; after it `xc` (and its
//!   own `dxc`, `ddxc`) without a reference, then `xd`, `z1`, `dq_hat`,
//!   `tau` (the order of the Python loop this replaces).
//!
//! A non-finite torque is a refused step (with a fault injected, the loop
//! applies zero torque and goes on; without one, the run ends with
//! `ValueError`, as before). An exception raised by the call, a torque of
//! another shape, or an attribute of another width ends the run with that
//! exception, before the plant advances: the rows recorded are those of the
//! periods before, the plant at the start of the period that raised.
//!
//! The rows are the loop's, with the controller's own quantities in place
//! of the core's (its τ, ζ, the velocity it used, its reference of width m
//! = n, or 3 for a task-space controller), and the SPEC §12 metrics of the
//! same rows by the core's [`RowMetrics`] (as `_adaptimp.metrics` computed them for
//! the Python loop: the same bits).

use super::dynamic::{FaultSpec, Items};
use super::measurement::PyMeasurement;
use adaptimp::control::impedance::TargetImpedance;
use adaptimp::control::io::{Command, Measurement, WrenchControl};
use adaptimp::error::Error;
use adaptimp::trajectory::Setpoint;
use adaptimp::types::Vector;
use core::cell::Cell;
use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};
use std::string::String;

/// The most values of a row's vector (n ≤ 7 joints; a reference of m ≤ 7).
pub(super) const W: usize = 7;

/// A vector of up to [`W`] values.
pub(super) type Buf = [f64; W];

/// The attributes a controller has, read every period (`hasattr` in Python).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Attrs {
    /// τ before saturation (n).
    pub tau: bool,
    /// Its commanded xc (m), read without a reference.
    pub xc: bool,
    /// Its own ẋc, ẍc (m), read without a reference.
    pub rates: bool,
    /// Its compliant reference xd (m).
    pub xd: bool,
    /// Its error z1 (m).
    pub z1: bool,
    /// The velocity it used (n).
    pub dq_hat: bool,
    /// ζ (n), read before the step.
    pub zeta: bool,
}

impl Attrs {
    /// From the names the controller has (unknown names are an error).
    pub fn from_names(names: &[String]) -> Result<Self, String> {
        let mut a = Self::default();
        for name in names {
            match name.as_str() {
                "tau" => a.tau = true,
                "xc" => a.xc = true,
                "rates" => a.rates = true,
                "xd" => a.xd = true,
                "z1" => a.z1 = true,
                "dq_hat" => a.dq_hat = true,
                "zeta" => a.zeta = true,
                other => return Err(std::format!("no controller attribute {other:?} is read")),
            }
        }
        Ok(a)
    }
}

/// A run of a controller written in Python ([`simulate`]).
pub struct CallbackRun<'a> {
    /// Ts (s).
    pub ts: f64,
    /// Duration T (s).
    pub t_final: f64,
    /// Start of the "after" window of the metrics (s).
    pub settle: f64,
    /// Keep every `every`-th row.
    pub every: u64,
    /// The disturbance parameters (SPEC §17) by schema name.
    pub items: &'a Items,
    /// A fault to inject (τmax: the plant's actuators').
    pub fault: Option<&'a FaultSpec>,
    /// The width m of the controller's reference: n, or 3 (task space).
    pub m: usize,
    /// xc, ẋc, ẍc of every row, K × m each, row-major: the keywords of the
    /// step with `setpoint`; without, the rows' ẋc, ẍc (NaN: unknown).
    pub table: [&'a [f64]; 3],
    /// Pass the table's row to the step as `xc=`, `dxc=`, `ddxc=`.
    pub setpoint: bool,
    /// A task-space controller: it reads the wrench (the plant must
    /// measure it), and its reference is m = 3 wide.
    pub task_space: bool,
    /// How its step is called.
    pub shape: CallShape,
    /// The attributes read.
    pub attrs: Attrs,
    /// The target impedance Dd, Cd, Gd (n values each) of the metrics.
    pub target: [&'a [f64]; 3],
}

/// How a Python controller's step is called.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CallShape {
    /// `step(m, **setpoint)` with an `adaptimp.Measurement`: the protocol.
    Measurement,
    /// `step(q, tau_e, dq, **setpoint)`: deprecated (the caller warned).
    Joint,
    /// `step(q, dq, wrench, **setpoint)`: deprecated (the caller warned).
    Wrench,
}

impl CallShape {
    pub(super) fn from_name(name: &str) -> PyResult<Self> {
        match name {
            "measurement" => Ok(Self::Measurement),
            "joint" => Ok(Self::Joint),
            "wrench" => Ok(Self::Wrench),
            _ => Err(PyValueError::new_err(format!(
                "call must be 'measurement', 'joint' or 'wrench', got {name:?}"
            ))),
        }
    }
}

/// What the controller told about the row it stepped last.
#[derive(Clone, Copy, Debug)]
pub(super) struct Report {
    /// Its xc, when it has one and the run no reference.
    pub(super) xc: Option<Buf>,
    /// Its ẋc, ẍc, when it has them and the run no reference.
    pub(super) rates: Option<(Buf, Buf)>,
    pub(super) xd: Option<Buf>,
    pub(super) z1: Option<Buf>,
    pub(super) dq_hat: Option<Buf>,
    /// Its τ, else the torque it returned.
    pub(super) tau: Buf,
    /// The torque it returned within the actuators' limits (the metrics'
    /// sat(τ): saturated by the controller or the motors, not weakened by
    /// a disturbance).
    pub(super) sat: Buf,
    /// ζ before the step (zero if it has none).
    pub(super) zeta: Buf,
}

impl Report {
    pub(super) const NONE: Self = Self {
        xc: None,
        rates: None,
        xd: None,
        z1: None,
        dq_hat: None,
        tau: [f64::NAN; W],
        sat: [f64::NAN; W],
        zeta: [0.0; W],
    };
}

/// The attribute `name` of `ctrl`: `width` reals of a 1-D float64 array (the
/// fast path), or of whatever `numpy.asarray` makes of it, flattened.
fn floats(
    py: Python<'_>,
    ctrl: &Bound<'_, PyAny>,
    name: &Bound<'_, PyString>,
    width: usize,
) -> PyResult<Buf> {
    let obj = ctrl.getattr(name)?;
    let mut out = [0.0; W];
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        if let Ok(r) = a.try_readonly() {
            if let Ok(s) = r.as_slice() {
                if s.len() == width {
                    out[..width].copy_from_slice(s);
                    return Ok(out);
                }
            }
        }
    }
    let a = as_float_array(py, &obj)?;
    let r = a.try_readonly()?;
    let v = r.as_array();
    if v.len() != width {
        let shape = a.getattr(intern!(py, "shape"))?.str()?;
        return Err(PyValueError::new_err(std::format!(
            "the controller's {name} must have {width} values, got shape {shape}"
        )));
    }
    for (o, x) in out.iter_mut().zip(v.iter()) {
        *o = *x;
    }
    Ok(out)
}

/// `numpy.asarray(obj, dtype=numpy.float64)`.
fn as_float_array<'py>(
    py: Python<'py>,
    obj: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let np = py.import(intern!(py, "numpy"))?;
    let kw = PyDict::new(py);
    kw.set_item(intern!(py, "dtype"), np.getattr(intern!(py, "float64"))?)?;
    let a = np
        .getattr(intern!(py, "asarray"))?
        .call((obj,), Some(&kw))?;
    Ok(a.cast_into::<PyArrayDyn<f64>>()?)
}

/// A controller's step returned numbers for its torque (reals: a number, a
/// sequence or an array of a real dtype), else a `TypeError` naming tau and
/// what it returned: None (a step that forgot to return: it became NaN), text
/// ("3.5" became 3.5 N m), a dict, bools.
pub(super) fn numeric_torque(obj: &Bound<'_, PyAny>, n: usize) -> PyResult<()> {
    let py = obj.py();
    let refuse = |what: &str| {
        Err(pyo3::exceptions::PyTypeError::new_err(std::format!(
            "the controller's step returned {what} for its torque: return tau, {n} real \
             numbers (N m), as an array or a sequence (or one number for every joint)"
        )))
    };
    if obj.is_none() {
        return refuse("None");
    }
    let np = py.import(intern!(py, "numpy"))?;
    let a = match np.getattr(intern!(py, "asarray"))?.call1((obj,)) {
        Ok(a) => a,
        Err(_) => return refuse(&std::format!("a {}", obj.get_type().name()?)),
    };
    let kind: String = a
        .getattr(intern!(py, "dtype"))?
        .getattr(intern!(py, "kind"))?
        .extract()?;
    if matches!(kind.as_str(), "f" | "i" | "u") {
        return Ok(());
    }
    let dtype = a.getattr(intern!(py, "dtype"))?.str()?;
    refuse(&std::format!(
        "a {} of dtype {dtype}",
        obj.get_type().name()?
    ))
}

/// The torque a step returned, as the Python loop's plant took it: n
/// values, or one for every joint; an error naming its shape otherwise.
/// `Ok(Err(e))`: not finite (`e` says so, as the Python loop did).
fn torque(py: Python<'_>, obj: &Bound<'_, PyAny>, n: usize) -> PyResult<Result<Buf, PyErr>> {
    let mut out = [0.0; W];
    let fast = obj
        .cast::<PyArray1<f64>>()
        .ok()
        .and_then(|a| a.try_readonly().ok())
        .is_some_and(|r| match r.as_slice() {
            Ok(s) if s.len() == n => {
                out[..n].copy_from_slice(s);
                true
            }
            _ => false,
        });
    let mut given = None;
    if !fast {
        numeric_torque(obj, n)?;
        let a = as_float_array(py, obj)?;
        let r = a.try_readonly()?;
        let v = r.as_array();
        match a.shape() {
            [] => out[..n].fill(v.iter().copied().next().unwrap_or(f64::NAN)),
            [k] if *k == n => {
                for (o, x) in out.iter_mut().zip(v.iter()) {
                    *o = *x;
                }
                given = Some(a.clone());
            }
            _ => {
                let shape = a.getattr(intern!(py, "shape"))?.str()?;
                return Err(PyValueError::new_err(std::format!(
                    "tau must have shape ({n},), got {shape}"
                )));
            }
        }
    }
    if out[..n].iter().all(|x| x.is_finite()) {
        return Ok(Ok(out));
    }
    let text = match given {
        Some(a) => a.str()?,
        None => PyArray1::from_slice(py, &out[..n]).str()?,
    };
    Ok(Err(PyValueError::new_err(std::format!(
        "tau must be finite, got {text}"
    ))))
}

/// The row of a table for t_k = k·Ts.
pub(super) fn row_of(t: f64, ts: f64) -> usize {
    libm::round(t / ts) as usize
}

/// The Python controller as the loop's [`Control`].
pub(super) struct PyStep<'a, const N: usize> {
    pub(super) ctrl: &'a Py<PyAny>,
    pub(super) run: &'a CallbackRun<'a>,
    pub(super) target: TargetImpedance<N>,
    pub(super) tau_max: Vector<N>,
    pub(super) clock: &'a Cell<f64>,
    pub(super) report: &'a Cell<Report>,
    pub(super) abort: &'a Cell<bool>,
    /// The exception that ended the run.
    pub(super) error: Option<PyErr>,
}

/// A controller written in Python has no state of the core's to copy.
impl<const N: usize> super::dynamic::View for PyStep<'_, N> {
    fn copy(&self, _part: core::any::TypeId) -> Option<Box<dyn core::any::Any + Send>> {
        None
    }
}

/// How a call ended.
enum Called {
    /// The torque to apply.
    Torque(Buf),
    /// A torque that is not finite (the message of the Python loop).
    NotFinite(PyErr),
}

impl<const N: usize> PyStep<'_, N> {
    /// The step's arguments: a measurement (or the deprecated (q, tau_e, dq)
    /// or (q, dq, wrench)), and the row's setpoint as keywords.
    fn arguments<'py>(
        &self,
        py: Python<'py>,
        k: usize,
        m: &Measurement<N>,
        wrench: &[f64; 6],
    ) -> PyResult<(Bound<'py, PyTuple>, Option<Bound<'py, PyDict>>)> {
        let args = match self.run.shape {
            CallShape::Measurement => {
                let meas = PyMeasurement::of(
                    m.x.as_slice(),
                    m.dx.as_ref().map(|d| d.as_slice()),
                    Some(m.tau_e.as_slice()),
                    Some(wrench),
                );
                PyTuple::new(py, [Bound::new(py, meas)?.into_any()])?
            }
            shape => {
                let q = PyArray1::from_slice(py, m.x.as_slice());
                let dq = m.dx.unwrap_or(m.x.map(|_| f64::NAN));
                let dq = PyArray1::from_slice(py, dq.as_slice());
                if shape == CallShape::Wrench {
                    PyTuple::new(py, [q, dq, PyArray1::from_slice(py, wrench)])?
                } else {
                    let tau_e = PyArray1::from_slice(py, m.tau_e.as_slice());
                    PyTuple::new(py, [q, tau_e, dq])?
                }
            }
        };
        if !self.run.setpoint {
            return Ok((args, None));
        }
        let w = self.run.m;
        let kw = PyDict::new(py);
        for (name, t) in [
            (intern!(py, "xc"), self.run.table[0]),
            (intern!(py, "dxc"), self.run.table[1]),
            (intern!(py, "ddxc"), self.run.table[2]),
        ] {
            kw.set_item(name, PyArray1::from_slice(py, &t[k * w..(k + 1) * w]))?;
        }
        Ok((args, Some(kw)))
    }

    /// One call of the Python step at row `k`, and the attributes after it.
    fn call(
        &self,
        py: Python<'_>,
        k: usize,
        m: &Measurement<N>,
        wrench: &[f64; 6],
    ) -> PyResult<Called> {
        let ctrl = self.ctrl.bind(py);
        let (a, w) = (self.run.attrs, self.run.m);
        let get = |name: &Bound<'_, PyString>, width: usize| floats(py, ctrl, name, width);
        let mut r = Report::NONE;
        if a.zeta {
            r.zeta = get(intern!(py, "zeta"), N)?;
        }
        let (args, kw) = self.arguments(py, k, m, wrench)?;
        let out = ctrl.call_method(intern!(py, "step"), args, kw.as_ref())?;
        let tau = match torque(py, &out, N)? {
            Ok(t) => t,
            Err(e) => return Ok(Called::NotFinite(e)),
        };
        if !self.run.setpoint {
            if a.xc {
                r.xc = Some(get(intern!(py, "xc"), w)?);
            }
            if a.rates {
                r.rates = Some((get(intern!(py, "dxc"), w)?, get(intern!(py, "ddxc"), w)?));
            }
        }
        if a.xd {
            r.xd = Some(get(intern!(py, "xd"), w)?);
        }
        if a.z1 {
            r.z1 = Some(get(intern!(py, "z1"), w)?);
        }
        if a.dq_hat {
            r.dq_hat = Some(get(intern!(py, "dq_hat"), N)?);
        }
        r.tau = if a.tau {
            get(intern!(py, "tau"), N)?
        } else {
            tau
        };
        for ((s, t), m) in r.sat.iter_mut().zip(&tau).zip(self.tau_max.iter()) {
            *s = t.max(-m).min(*m);
        }
        self.report.set(r);
        Ok(Called::Torque(tau))
    }

    /// The step: the torque, or a refusal (a non-finite torque) or the end
    /// of the run (an exception: [`PyStep::error`], the abort flag raised).
    fn step_python(&mut self, m: &Measurement<N>, wrench: &[f64; 6]) -> Result<Vector<N>, Error> {
        let k = row_of(self.clock.get(), self.run.ts);
        match Python::attach(|py| self.call(py, k, m, wrench)) {
            Ok(Called::Torque(t)) => Ok(Vector::from_fn(|i, _| t[i])),
            Ok(Called::NotFinite(e)) => {
                // Without a fault the run ends, as the Python loop's did.
                if self.run.fault.is_none() {
                    self.error = Some(e);
                    self.abort.set(true);
                }
                Err(Error::Diverged { what: "tau" })
            }
            Err(e) => {
                self.error = Some(e);
                self.abort.set(true);
                Err(Error::Invalid {
                    what: "controller",
                    reason: "its step raised an exception",
                })
            }
        }
    }
}

impl<const N: usize> WrenchControl<N> for PyStep<'_, N> {
    fn period(&self) -> f64 {
        self.run.ts
    }
    fn target(&self) -> &TargetImpedance<N> {
        &self.target
    }
    /// The Python step; on a refusal zero torque (the trait's fallback).
    fn step_with_wrench(
        &mut self,
        m: &Measurement<N>,
        wrench: &[f64; 6],
        _c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        match self.step_python(m, wrench) {
            Ok(tau) => {
                let cmd = Command {
                    tau_sat: tau,
                    tau,
                    w_norms: [f64::NAN; 3],
                    ..Command::zeros()
                };
                (tau, Ok(cmd))
            }
            Err(e) => (Vector::zeros(), Err(e)),
        }
    }
}
