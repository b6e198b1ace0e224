//! `adaptimp.Measurement`: one sample of the sensors, the one input of every
//! controller's step (joint or Cartesian, compiled or written in Python), as
//! ruckig's input object is (SPEC §13.1). Each controller reads the part it
//! needs: a joint controller q, q̇ and τe; a Cartesian one q, q̇ and the
//! wrench F_e.
//!
//! Shapes are checked when a measurement is made; values are not (a NaN
//! from a sensor is the controller's to refuse, and a refused step records
//! its fault: the fault semantics of docs/reliability.md).

use super::arrays::*;
use super::dynamic::MAX_JOINTS;
use super::errors::*;
use numpy::{PyArray1, PyUntypedArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyDeprecationWarning, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};
use std::ffi::CString;
use std::format;
use std::string::String;

/// One sample of the sensors at t_k.
#[pyclass(module = "adaptimp", name = "Measurement", frozen)]
pub struct PyMeasurement {
    pub(super) n: usize,
    pub(super) q: Buf,
    pub(super) dq: Option<Buf>,
    pub(super) tau_e: Option<Buf>,
    pub(super) wrench: Option<[f64; 6]>,
}

impl PyMeasurement {
    /// A measurement of n = `q.len()` ≤ 7 joints from the core's slices.
    pub(super) fn of(
        q: &[f64],
        dq: Option<&[f64]>,
        tau_e: Option<&[f64]>,
        wrench: Option<&[f64; 6]>,
    ) -> Self {
        let n = q.len().min(MAX_JOINTS);
        let buf = |v: &[f64]| {
            let mut b = [0.0; MAX_JOINTS];
            b[..n].copy_from_slice(&v[..n]);
            b
        };
        Self {
            n,
            q: buf(q),
            dq: dq.map(buf),
            tau_e: tau_e.map(buf),
            wrench: wrench.copied(),
        }
    }
}

/// How many values `obj` holds, for a vector whose length it sets; `want`
/// says what it must be ("one value per joint (a 1-D array)").
fn length(what: &str, want: &str, obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    if let Ok(arr) = obj.cast::<PyUntypedArray>() {
        if arr.ndim() != 1 {
            return Err(MeasurementError::new_err(format!(
                "{what} must {want}, got {}",
                python_shape(arr.shape())
            )));
        }
        return Ok(arr.len());
    }
    if obj.extract::<f64>().is_ok() {
        return Err(MeasurementError::new_err(format!(
            "{what} must {want}, got a scalar"
        )));
    }
    obj.len().map_err(|_| {
        let ty = obj
            .get_type()
            .name()
            .map(|n| n.to_string())
            .unwrap_or_else(|_| "?".to_owned());
        PyTypeError::new_err(format!(
            "{what} must be a sequence or array of real numbers, got {ty}"
        ))
    })
}

/// The wrench F_e = [f; m] (6 values; 3 values are f alone, m = 0).
fn wrench(obj: &Bound<'_, PyAny>) -> PyResult<[f64; 6]> {
    const WANT: &str = "have shape (6,) ([f; m], N and N m) or (3,) (f alone)";
    let mut buf = [0.0; MAX_JOINTS];
    let len = length("wrench", WANT, obj)?;
    if len != 3 && len != 6 {
        return Err(MeasurementError::new_err(format!(
            "wrench must {WANT}, got shape ({len},)"
        )));
    }
    vector_into("wrench", len, obj, &mut buf)?;
    let mut w = [0.0; 6];
    w[..len].copy_from_slice(&buf[..len]);
    Ok(w)
}

fn optional(what: &'static str, n: usize, obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Buf>> {
    obj.filter(|o| !o.is_none())
        .map(|o| vector_any(what, n, o))
        .transpose()
}

/// [`optional`] for a measurement, whose length q set: a length that
/// differs names both (a q one short was reported as "dq must have shape").
fn like_q(what: &'static str, n: usize, obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Buf>> {
    let read = optional(what, n, obj);
    if let (Err(e), Some(o)) = (&read, obj) {
        let shape = e.is_instance_of::<MeasurementError>(o.py());
        if let (true, Ok(k)) = (shape, length(what, "be one value per joint", o)) {
            if k != n {
                return Err(MeasurementError::new_err(format!(
                    "{what} has {k} values and q {n}: one value per joint each"
                )));
            }
        }
    }
    read
}

#[pymethods]
impl PyMeasurement {
    /// A measurement: joint positions `q` (rad), velocities `dq` (rad/s;
    /// None where not measured: output feedback estimates them), the torque
    /// the arm exerts on the environment `tau_e` (N m; None: no contact,
    /// zeros), and the wrench at the tip F_e = [f; m] (N, N m, world frame;
    /// (3,) is f alone; None: no contact). q sets the joint count (1 to 7);
    /// dq and tau_e must match it. Values are not judged here: a non-finite
    /// one is the controller's to refuse.
    #[new]
    #[pyo3(signature = (q, dq=None, *, tau_e=None, wrench=None))]
    fn new(
        q: &Bound<'_, PyAny>,
        dq: Option<&Bound<'_, PyAny>>,
        tau_e: Option<&Bound<'_, PyAny>>,
        wrench: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let n = length("q", "be one value per joint (a 1-D array)", q)?;
        if n == 0 || n > MAX_JOINTS {
            return Err(MeasurementError::new_err(format!(
                "q must have 1 to {MAX_JOINTS} values (one per joint), got {n}"
            )));
        }
        Ok(Self {
            n,
            q: vector_any("q", n, q)?,
            dq: like_q("dq", n, dq)?,
            tau_e: like_q("tau_e", n, tau_e)?,
            wrench: wrench
                .filter(|o| !o.is_none())
                .map(self::wrench)
                .transpose()?,
        })
    }

    /// The number of joints n.
    #[getter]
    fn n(&self) -> usize {
        self.n
    }

    /// Joint positions q (rad), (n,).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        array1(py, &self.q[..self.n])
    }

    /// Joint velocities q̇ (rad/s), (n,), or None.
    #[getter]
    fn dq<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.dq.as_ref().map(|v| array1(py, &v[..self.n]))
    }

    /// The torque the arm exerts on the environment τe (N m), (n,), or None.
    #[getter]
    fn tau_e<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.tau_e.as_ref().map(|v| array1(py, &v[..self.n]))
    }

    /// The wrench at the tip F_e = [f; m] (N, N m, world frame), (6,), or None.
    #[getter]
    fn wrench<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.wrench.as_ref().map(|v| array1(py, v))
    }

    /// The arguments `pickle` and `copy` make it again with (`__new__`'s).
    #[allow(clippy::type_complexity)]
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(
        (Bound<'py, PyArray1<f64>>, Option<Bound<'py, PyArray1<f64>>>),
        Bound<'py, PyDict>,
    )> {
        let kw = PyDict::new(py);
        kw.set_item("tau_e", self.tau_e(py))?;
        kw.set_item("wrench", self.wrench(py))?;
        Ok(((self.q(py), self.dq(py)), kw))
    }

    /// Equal when every part is, value for value (a NaN never is).
    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        let Ok(o) = other.cast::<PyMeasurement>() else {
            return false;
        };
        let o = o.get();
        let n = self.n;
        let same = |a: &Option<Buf>, b: &Option<Buf>| match (a, b) {
            (Some(a), Some(b)) => a[..n] == b[..n],
            (None, None) => true,
            _ => false,
        };
        n == o.n
            && self.q[..n] == o.q[..n]
            && same(&self.dq, &o.dq)
            && same(&self.tau_e, &o.tau_e)
            && self.wrench == o.wrench
    }

    fn __repr__(&self) -> String {
        let show = |v: Option<&[f64]>| match v {
            Some(v) => format!("{v:?}"),
            None => "None".to_owned(),
        };
        format!(
            "adaptimp.Measurement(q={}, dq={}, tau_e={}, wrench={})",
            show(Some(&self.q[..self.n])),
            show(self.dq.as_ref().map(|v| &v[..self.n])),
            show(self.tau_e.as_ref().map(|v| &v[..self.n])),
            show(self.wrench.as_ref().map(|v| &v[..])),
        )
    }
}

/// A joint step's inputs: q, τe (zeros when not measured) and q̇.
pub(super) struct JointInputs {
    pub(super) q: Buf,
    pub(super) tau_e: Buf,
    pub(super) dq: Option<Buf>,
}

/// The parameters of a joint step with a measurement, and of the deprecated
/// call with arrays.
const TYPED: [&str; 4] = ["m", "xc", "dxc", "ddxc"];
const ARRAYS: [&str; 6] = ["q", "tau_e", "dq", "xc", "dxc", "ddxc"];

/// A joint step's call, read from its `(*args, **kwargs)`: `step(m, xc=None,
/// dxc=None, ddxc=None)` with a [`PyMeasurement`] (the setpoint positional
/// or by keyword: positional arguments skip the keyword dictionary, which
/// an abi3 call pays for), or the deprecated `step(q, tau_e, dq=None,
/// xc=None, dxc=None, ddxc=None)`, which warns once per call site. A `None`
/// is an argument not given.
pub(super) struct JointCall<'py> {
    /// Who is called, for the messages: "Controller.step".
    who: &'static str,
    /// The measurement, or the arrays' q, τe, q̇.
    slots: [Option<Bound<'py, PyAny>>; 3],
    typed: bool,
    /// The setpoint xc, ẋc, ẍc.
    pub(super) setpoint: [Option<Bound<'py, PyAny>>; 3],
}

impl<'py> JointCall<'py> {
    /// The call `who(*args, **kwargs)`, its arguments matched to the
    /// parameters of its shape (Python's own errors for a wrong count, a
    /// repeated or an unknown keyword).
    pub(super) fn parse(
        who: &'static str,
        args: &Bound<'py, PyTuple>,
        kwargs: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Self> {
        let first = match args.get_item(0) {
            Ok(a) => Some(a),
            Err(_) => kwargs.and_then(|k| k.get_item("m").ok().flatten()),
        };
        let typed = first.is_some_and(|f| f.is_instance_of::<PyMeasurement>());
        let names: &[&str] = if typed { &TYPED } else { &ARRAYS };
        if args.len() > names.len() {
            return Err(PyTypeError::new_err(format!(
                "{who}() takes at most {} positional arguments ({} given)",
                names.len(),
                args.len()
            )));
        }
        let mut slots: [Option<Bound<'py, PyAny>>; 6] = Default::default();
        for (slot, a) in slots.iter_mut().zip(args.iter()) {
            *slot = Some(a);
        }
        for (k, v) in kwargs.into_iter().flat_map(|k| k.iter()) {
            let k = k.cast_into::<PyString>()?;
            let k = k.to_cow()?;
            let Some(i) = names.iter().position(|n| *n == k) else {
                return Err(PyTypeError::new_err(format!(
                    "{who}() got an unexpected keyword argument '{k}'"
                )));
            };
            if slots[i].is_some() {
                return Err(PyTypeError::new_err(format!(
                    "{who}() got multiple values for argument '{k}'"
                )));
            }
            slots[i] = Some(v);
        }
        let [a, b, c, d, e, f] = slots.map(|s| s.filter(|v| !v.is_none()));
        Ok(if typed {
            Self {
                who,
                slots: [a, None, None],
                typed,
                setpoint: [b, c, d],
            }
        } else {
            Self {
                who,
                slots: [a, b, c],
                typed,
                setpoint: [d, e, f],
            }
        })
    }

    /// The inputs for `n` joints; shapes and types checked, values not.
    pub(super) fn inputs(&self, n: usize) -> PyResult<JointInputs> {
        let who = self.who;
        if self.typed {
            let Some(m) = self.slots[0]
                .as_ref()
                .and_then(|m| m.cast::<PyMeasurement>().ok())
            else {
                return Err(PyTypeError::new_err(format!("{who} needs a measurement")));
            };
            let m = m.get();
            if m.n != n {
                return Err(shape_error("q", n, &format!("length {}", m.n)));
            }
            return Ok(JointInputs {
                q: m.q,
                tau_e: m.tau_e.unwrap_or([0.0; MAX_JOINTS]),
                dq: m.dq,
            });
        }
        let [q, tau_e, dq] = &self.slots;
        let Some(q) = q else {
            return Err(PyTypeError::new_err(format!(
                "{who} needs a measurement: step(adaptimp.Measurement(q, dq, tau_e=…))"
            )));
        };
        let Some(tau_e) = tau_e else {
            return Err(PyTypeError::new_err(format!(
                "{who}(q, tau_e, dq) needs tau_e; better, pass adaptimp.Measurement(q, dq, tau_e=…)"
            )));
        };
        deprecated(q.py(), who)?;
        Ok(JointInputs {
            q: vector_any("q", n, q)?,
            tau_e: vector_any("tau_e", n, tau_e)?,
            dq: optional("dq", n, dq.as_ref())?,
        })
    }
}

/// The `DeprecationWarning` of the old call shape `who(q, tau_e, dq)`.
pub(super) fn deprecated(py: Python<'_>, who: &str) -> PyResult<()> {
    let msg = format!(
        "{who}(q, tau_e, dq) is deprecated: pass one adaptimp.Measurement(q, dq, tau_e=tau_e)"
    );
    let msg = CString::new(msg).unwrap_or_default();
    PyErr::warn(py, &py.get_type::<PyDeprecationWarning>(), &msg, 1)
}
