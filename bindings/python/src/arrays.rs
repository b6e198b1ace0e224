//! Vectors and tables in and out: NumPy arrays and sequences to slices (named in every error), slices to NumPy arrays.

use super::dynamic::MAX_JOINTS;
use super::errors::*;
use adaptimp::error::Error;
use numpy::ndarray::{Array, Dimension, IntoDimension};
use numpy::{
    IntoPyArray, PyArray, PyArray1, PyArrayDescrMethods, PyArrayMethods, PyReadonlyArray2,
    PyUntypedArray, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyOverflowError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyDict, PyList, PyString, PyTuple};
use std::sync::{Mutex, MutexGuard, TryLockError};

/// Up to [`MAX_JOINTS`] values on the stack.
pub(super) type Buf = [f64; MAX_JOINTS];

/// A shape as Python prints it: `shape (3,)`, `shape (2, 1)`.
pub(super) fn python_shape(shape: &[usize]) -> String {
    match shape {
        [n] => format!("shape ({n},)"),
        _ => {
            let dims: Vec<String> = shape.iter().map(|d| d.to_string()).collect();
            format!("shape ({})", dims.join(", "))
        }
    }
}

pub(super) fn shape_error(what: &str, n: usize, got: &str) -> PyErr {
    MeasurementError::new_err(format!(
        "{what} must have shape ({n},) (one value per joint), got {got}"
    ))
}

pub(super) fn type_error(what: &str, n: usize, obj: &Bound<'_, PyAny>) -> PyErr {
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
pub(super) fn vector_any(what: &'static str, n: usize, obj: &Bound<'_, PyAny>) -> PyResult<Buf> {
    let mut out = [0.0; MAX_JOINTS];
    vector_into(what, n, obj, &mut out)?;
    Ok(out)
}

/// A list of exactly `out.len()` real numbers into `out`, without allocating
/// (the hot path of `step` with lists); false for anything else (then `out`
/// may be partly written, and the general path reads or refuses it).
pub(super) fn list_into(obj: &Bound<'_, PyAny>, out: &mut [f64]) -> bool {
    let Ok(list) = obj.cast::<PyList>() else {
        return false;
    };
    if list.len() != out.len() {
        return false;
    }
    for (o, item) in out.iter_mut().zip(list.iter()) {
        if item.is_instance_of::<PyBool>() {
            return false; // the general path refuses it by name
        }
        match item.extract::<f64>() {
            Ok(x) => *o = x,
            Err(_) => return false,
        }
    }
    true
}

/// The index of the first bool in a list or tuple `obj` (a bool is not a
/// number here: `[True, False]` was taken as [1, 0]).
fn first_bool(obj: &Bound<'_, PyAny>) -> Option<usize> {
    let items: Vec<Bound<'_, PyAny>> = if let Ok(l) = obj.cast::<PyList>() {
        l.iter().collect()
    } else if let Ok(t) = obj.cast::<PyTuple>() {
        t.iter().collect()
    } else {
        return None;
    };
    items.iter().position(|i| i.is_instance_of::<PyBool>())
}

/// As [`vector_any`], into `out` (the entries past n untouched): a step's
/// arguments go straight into their buffers.
pub(super) fn vector_into(
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
    } else if let Some(i) = first_bool(obj) {
        return Err(PyTypeError::new_err(format!(
            "{what} must hold real numbers, got a bool at [{i}]"
        )));
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
pub(super) fn vector(what: &'static str, n: usize, obj: &Bound<'_, PyAny>) -> PyResult<Buf> {
    let out = vector_any(what, n, obj)?;
    if let Some(index) = out[..n].iter().position(|x| !x.is_finite()) {
        return Err(step_error(Error::NonFinite { what, index }));
    }
    Ok(out)
}

/// `m` locked; while another thread's call holds it, wait with the GIL
/// released (that call may need the GIL to finish), then try again with it.
pub(super) fn wait_lock<'a, T: ?Sized + Send>(
    py: Python<'_>,
    m: &'a Mutex<T>,
) -> MutexGuard<'a, T> {
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

pub(super) fn array1<'py>(py: Python<'py>, v: &[f64]) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v)
}

/// Move `data` (row-major) into a NumPy array of shape `shape`, without copying.
pub(super) fn array<'py, D: Dimension>(
    py: Python<'py>,
    data: Vec<f64>,
    shape: impl IntoDimension<Dim = D>,
) -> PyResult<Bound<'py, PyArray<f64, D>>> {
    let a = Array::from_shape_vec(shape.into_dimension(), data)
        .map_err(|e| PyValueError::new_err(format!("internal shape mismatch: {e}")))?;
    Ok(a.into_pyarray(py))
}

/// A (K, n) float64 table, flattened row-major; the error names it.
pub(super) fn table(
    what: &str,
    a: &PyReadonlyArray2<'_, f64>,
    rows: usize,
    n: usize,
) -> PyResult<Vec<f64>> {
    if a.shape() != [rows, n] {
        return Err(MeasurementError::new_err(format!(
            "{what} must have shape ({rows}, {n}) like q, got {}",
            python_shape(a.shape())
        )));
    }
    Ok(a.as_array().iter().copied().collect())
}

/// The rows of a reference table (xc, ẋc, ẍc, (K, n) each), checked.
pub(super) fn reference_tables(
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
pub(super) fn weight_rows(n: usize, l: usize, weights: &Bound<'_, PyDict>) -> PyResult<Vec<f64>> {
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

/// A reference table: xc, ẋc, ẍc of every row, (K, n) each.
pub(super) type PyReference<'py> = (
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, f64>,
    PyReadonlyArray2<'py, f64>,
);
