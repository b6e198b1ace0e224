//! `CartesianController.step` as the core's own method (issue 32, item 6;
//! docs/performance.md): the common call `step(m)` (an `adaptimp.Measurement`,
//! the commanded pose from the controller's path at t_k, or held) goes from
//! Python's call straight to [`PyCartesian::step_sample`], with no Python
//! frame between. Every other call (a pose given, the deprecated arrays, a
//! joint controller written in Python) is the Python method's, called as it
//! came.

use super::cartesian::PyCartesian;
use super::measurement::PyMeasurement;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use pyo3::{PyTraverseError, PyVisit};

/// The step of one `adaptimp.CartesianController`, bound to its parts.
#[pyclass(name = "CartesianStep", module = "adaptimp._adaptimp", frozen)]
pub struct PyCartesianStep {
    /// The outer loop's core.
    core: Py<PyCartesian>,
    /// The joint controller the core steps (None: one written in Python).
    joint: Option<Py<PyAny>>,
    /// The commanded pose's path, called at t_k (None: the last target held).
    path: Option<Py<PyAny>>,
    /// The Python method, for every other call.
    other: Py<PyAny>,
    /// Keep each step's row for the log.
    record: bool,
}

#[pymethods]
impl PyCartesianStep {
    #[new]
    #[pyo3(signature = (core, joint, path, other, record))]
    fn new(
        core: Py<PyCartesian>,
        joint: Option<Py<PyAny>>,
        path: Option<Py<PyAny>>,
        other: Py<PyAny>,
        record: bool,
    ) -> Self {
        Self {
            core,
            joint,
            path,
            other,
            record,
        }
    }

    /// One step at t_k = k·Ts; returns the torque to apply (N m), (n,):
    /// `adaptimp.CartesianController.step`'s signature and meaning.
    #[pyo3(signature = (*args, **kwargs))]
    fn step<'py>(
        &self,
        py: Python<'py>,
        args: &Bound<'py, PyTuple>,
        kwargs: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        if let (Some(joint), None, 1) = (&self.joint, kwargs, args.len()) {
            let m = args.get_item(0)?;
            if m.is_instance_of::<PyMeasurement>() {
                let core = self.core.get();
                let sample = match &self.path {
                    Some(path) => Some(path.bind(py).call1((core.clock(py)?,))?),
                    None => None,
                };
                let joint = joint.bind(py);
                let tau: Bound<'py, PyArray1<f64>> =
                    core.step_sample(py, joint, &m, None, None, sample.as_ref(), self.record)?;
                return Ok(tau.into_any());
            }
        }
        self.other.bind(py).call(args, kwargs)
    }

    fn __traverse__(&self, visit: PyVisit<'_>) -> Result<(), PyTraverseError> {
        visit.call(&self.core)?;
        if let Some(j) = &self.joint {
            visit.call(j)?;
        }
        if let Some(p) = &self.path {
            visit.call(p)?;
        }
        visit.call(&self.other)
    }
}
