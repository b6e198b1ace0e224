//! Python values to the Cartesian controller's inputs (a wrench, a path's
//! sample, a flat pose target, tables of rows, counts) and its errors to
//! the exceptions of `adaptimp._errors`.

use super::cartesian_loop::{pose_target, TARGET_LEN};
use super::{array, python_shape, ConfigError};
use super::{DivergedError, MeasurementError};
use adaptimp::cartesian::PoseTarget;
use adaptimp::dynamic::{HeldRotation, TaskRows};
use adaptimp::error::Error;
use adaptimp::types::Vector;
use nalgebra::Matrix3;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::vec::Vec;

// ---------------------------------------------------------------------------
// Conversions.
// ---------------------------------------------------------------------------

/// A step's error, named as in Python: the measurement and the target are
/// inputs (`MeasurementError`), a signal beyond the finite range is
/// `DivergedError`, a parameter `ConfigError`.
pub(super) fn cartesian_error(e: Error) -> PyErr {
    const INPUTS: [&str; 13] = [
        "q",
        "x",
        "dq",
        "dx",
        "wrench",
        "p_c",
        "dp_c",
        "ddp_c",
        "R_c",
        "max |R_cᵀR_c − I| of R_c",
        "det R_c",
        "w_c",
        "dw_c",
    ];
    let input = match e {
        Error::NonFinite { what, .. } | Error::OutOfRange { what, .. } => INPUTS.contains(&what),
        Error::Condition { lhs, .. } => INPUTS.contains(&lhs),
        Error::MissingVelocity => true,
        _ => false,
    };
    match e {
        _ if input => MeasurementError::new_err(super::python_names(e).to_string()),
        Error::OutOfRange { .. } | Error::Diverged { .. } => DivergedError::new_err(e.to_string()),
        _ => super::step_error(e),
    }
}

/// A flat vector of exactly `len` finite reals (a sequence or an array).
pub(super) fn flat(what: &'static str, len: usize, obj: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let v = flat_values(what, len, obj)?;
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(MeasurementError::new_err(format!(
            "{what}[{i}] is not finite (NaN or infinite)"
        )));
    }
    Ok(v)
}

/// `len` reals from a 1-D sequence or array (another shape, e.g. a (2, 3)
/// wrench, is refused naming `what`), finite or not.
pub(super) fn flat_values(
    what: &'static str,
    len: usize,
    obj: &Bound<'_, PyAny>,
) -> PyResult<Vec<f64>> {
    if let Ok(shape) = obj.getattr("shape").and_then(|s| s.extract::<Vec<usize>>()) {
        if shape.len() != 1 {
            return Err(MeasurementError::new_err(format!(
                "{what} must have shape ({len},), got {}",
                python_shape(&shape)
            )));
        }
    }
    let v: Vec<f64> = match obj.cast::<PyArray1<f64>>() {
        Ok(a) => a.try_readonly()?.as_array().iter().copied().collect(),
        Err(_) => obj
            .call_method1("__array__", ())
            .ok()
            .and_then(|a| a.call_method1("astype", ("float64",)).ok())
            .and_then(|a| a.call_method0("ravel").ok())
            .and_then(|a| a.extract::<Vec<f64>>().ok())
            .or_else(|| obj.extract::<Vec<f64>>().ok())
            .ok_or_else(|| {
                PyTypeError::new_err(format!("{what} must be a sequence or array of {len} reals"))
            })?,
    };
    if v.len() != len {
        return Err(MeasurementError::new_err(format!(
            "{what} must have {len} values, got {}",
            v.len()
        )));
    }
    Ok(v)
}

/// `L` reals: an array of shape (L,) read in place, else any sequence
/// ([`flat`]); None gives zeros.
pub(super) fn reals<const L: usize>(
    what: &'static str,
    obj: Option<&Bound<'_, PyAny>>,
) -> PyResult<[f64; L]> {
    let mut out = [0.0; L];
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(out);
    };
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        if a.len() == L {
            for (i, o) in out.iter_mut().enumerate() {
                *o = a.get_owned(i).unwrap_or(f64::NAN);
            }
            return Ok(out);
        }
    }
    let v = flat_any(what, L, obj)?;
    out.copy_from_slice(&v);
    Ok(out)
}

/// NumPy's shape of `obj` ("(2, 3)"), if it is not `want` (a (9,) R or a
/// (2, 3) wrench was read flat, silently).
pub(super) fn shape_other_than(obj: &Bound<'_, PyAny>, want: &[&[usize]]) -> Option<String> {
    let shape: Vec<usize> = obj
        .py()
        .import("numpy")
        .and_then(|np| np.call_method1("shape", (obj,)))
        .and_then(|s| s.extract())
        .ok()?;
    if want.contains(&shape.as_slice()) {
        return None;
    }
    let dims: Vec<String> = shape.iter().map(ToString::to_string).collect();
    Some(match dims.len() {
        1 => format!("({},)", dims[0]),
        _ => format!("({})", dims.join(", ")),
    })
}

/// F_e from (6,), or f (3,) alone (no moment).
pub(super) fn wrench_sample(obj: &Bound<'_, PyAny>) -> PyResult<[f64; 6]> {
    if obj.is_none() {
        return Ok([0.0; 6]);
    }
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        if a.len() == 6 || a.len() == 3 {
            let mut out = [0.0; 6];
            for (i, o) in out.iter_mut().enumerate().take(a.len()) {
                *o = a.get_owned(i).unwrap_or(f64::NAN);
            }
            return Ok(out);
        }
    }
    if let Some(shape) = shape_other_than(obj, &[&[6], &[3]]) {
        return Err(MeasurementError::new_err(format!(
            "wrench must have shape (6,) or (3,), got shape {shape}"
        )));
    }
    let v = flat_any("wrench", 0, obj)?;
    match v.len() {
        3 | 6 => Ok(core::array::from_fn(|i| v.get(i).copied().unwrap_or(0.0))),
        k => Err(MeasurementError::new_err(format!(
            "wrench must have shape (6,) or (3,), got {k} values"
        ))),
    }
}

/// The commanded pose of a step: a path's (p, ṗ, p̈) or (p, ṗ, p̈, R, ω, ω̇)
/// (rates None: 0; R None: the rotation `held`), or a flat target (24,).
pub(super) fn sample_target(obj: &Bound<'_, PyAny>, held: &HeldRotation) -> PyResult<PoseTarget> {
    if let Ok(a) = obj.cast::<PyArray1<f64>>() {
        let v = flat("target", TARGET_LEN, a.as_any())?;
        return Ok(pose_target(&v));
    }
    // A tuple (a path's return) is read in place; any other iterable is
    // collected first.
    let tuple = obj.cast::<pyo3::types::PyTuple>().ok();
    let collected: Vec<Bound<'_, PyAny>> = match tuple {
        Some(_) => Vec::new(),
        None => obj
            .try_iter()
            .and_then(|it| it.collect::<PyResult<Vec<_>>>())
            .map_err(|_| {
                let got = obj
                    .get_type()
                    .name()
                    .map_or_else(|_| "?".to_owned(), |n| n.to_string());
                PyTypeError::new_err(format!(
                    "a path returns (p, dp, ddp) or (p, dp, ddp, R, w, dw) (a tuple of arrays), \
                     got {got}"
                ))
            })?,
    };
    let len = tuple.map_or(collected.len(), |t| t.len());
    if len != 3 && len != 6 {
        return Err(PyValueError::new_err(format!(
            "path(t) must return 3 or 6 arrays (p, dp, ddp[, R, w, dw]), got {len}"
        )));
    }
    let get = |i: usize| -> Option<Bound<'_, PyAny>> {
        let item = match tuple {
            Some(t) if i < len => t.get_item(i).ok(),
            Some(_) => None,
            None => collected.get(i).cloned(),
        };
        item.filter(|o| !o.is_none())
    };
    let p = match get(0) {
        Some(p) => reals::<3>("p_c", Some(&p))?,
        None => {
            return Err(MeasurementError::new_err(
                "the commanded position p_c is missing",
            ))
        }
    };
    let v3 =
        |what: &'static str, i: usize| reals::<3>(what, get(i).as_ref()).map(Vector::<3>::from);
    let rates = [v3("dp_c", 1)?, v3("ddp_c", 2)?];
    let r = match get(3) {
        None => None,
        Some(r) => Some(match r.cast::<PyArray2<f64>>() {
            Ok(a) if a.shape() == [3, 3] => {
                Matrix3::from_fn(|i, j| a.get_owned([i, j]).unwrap_or(f64::NAN))
            }
            _ => {
                if let Some(shape) = shape_other_than(&r, &[&[3, 3]]) {
                    return Err(MeasurementError::new_err(format!(
                        "R_c must have shape (3, 3), got shape {shape}"
                    )));
                }
                Matrix3::from_row_slice(&flat_any("R_c", 9, &r)?)
            }
        }),
    };
    let w = [v3("w_c", 4)?, v3("dw_c", 5)?];
    Ok(held.target(Vector::<3>::from(p), rates, r, w))
}

/// As [`flat`], without the finiteness check (the core's), of any length
/// when `len` is 0.
pub(super) fn flat_any(
    what: &'static str,
    len: usize,
    obj: &Bound<'_, PyAny>,
) -> PyResult<Vec<f64>> {
    let v: Vec<f64> = obj
        .call_method1("__array__", ())
        .ok()
        .and_then(|a| a.call_method1("astype", ("float64",)).ok())
        .and_then(|a| a.call_method0("ravel").ok())
        .and_then(|a| a.extract::<Vec<f64>>().ok())
        .or_else(|| obj.extract::<Vec<f64>>().ok())
        .ok_or_else(|| {
            PyTypeError::new_err(format!("{what} must be a sequence or array of reals"))
        })?;
    if len > 0 && v.len() != len {
        return Err(MeasurementError::new_err(format!(
            "{what} must have {len} values, got {}",
            v.len()
        )));
    }
    Ok(v)
}

/// A flat target (24,); a value that is not finite is refused by the
/// core's check of the target, naming its part (p_c, R_c, w_c, …).
pub(super) fn target_of(obj: Option<&Bound<'_, PyAny>>) -> PyResult<Option<PoseTarget>> {
    obj.map(|o| flat_values("target", TARGET_LEN, o).map(|v| pose_target(&v)))
        .transpose()
}

pub(super) fn wrench_of(obj: &Bound<'_, PyAny>) -> PyResult<[f64; 6]> {
    let v = flat("wrench", 6, obj)?;
    Ok(core::array::from_fn(|i| v[i]))
}

/// A Cartesian run's task rows (`k` of them) as the dict of
/// `CartesianController.arrays()`'s keys.
pub(super) fn task_dict(py: Python<'_>, task: TaskRows, k: usize) -> PyResult<Bound<'_, PyDict>> {
    let n = task.n();
    let [pc, dpc, ddpc] = task.pc;
    let [pd, dpd, ddpd] = task.pd;
    let d = PyDict::new(py);
    for (name, v, w) in [
        ("pc", pc, 3),
        ("dpc", dpc, 3),
        ("ddpc", ddpc, 3),
        ("pd", pd, 3),
        ("dpd", dpd, 3),
        ("ddpd", ddpd, 3),
        ("qd", task.qd, n),
        ("wrench", task.wrench, 6),
        ("error", task.error, 6),
    ] {
        d.set_item(name, array(py, v, (k, w))?)?;
    }
    Ok(d)
}

/// The rows of a table (K, n) of reals from any array or nested sequence
/// (K given: of that many rows), else a MeasurementError (TypeError for
/// values that are not reals) naming `what` and the shape it had.
pub(super) fn rows_of(
    what: &str,
    obj: &Bound<'_, PyAny>,
    k: Option<usize>,
    n: usize,
) -> PyResult<(usize, Vec<f64>)> {
    let np = obj.py().import("numpy")?;
    let given = np
        .call_method1("asarray", (obj,))
        .map_err(|_| PyTypeError::new_err(format!("{what} must be an array of reals")))?;
    // Reals only: a complex row lost its imaginary part, text became numbers.
    let kind: String = given.getattr("dtype")?.getattr("kind")?.extract()?;
    if !matches!(kind.as_str(), "f" | "i" | "u") {
        return Err(PyTypeError::new_err(format!(
            "{what} must hold real numbers, got an array of dtype {}",
            given.getattr("dtype")?.str()?
        )));
    }
    let a = given.call_method1("astype", ("float64",))?;
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    let rows = k.unwrap_or(shape.first().copied().unwrap_or(0));
    if shape != [rows, n] {
        let like = if k.is_some() { " like q" } else { "" };
        return Err(MeasurementError::new_err(format!(
            "{what} must have shape ({}, {n}){like}, got {}",
            k.map_or("K".to_string(), |k| k.to_string()),
            python_shape(&shape)
        )));
    }
    let v: Vec<f64> = a.call_method0("ravel")?.extract()?;
    Ok((rows, v))
}

/// A count given as a Python integer (not a bool, not a float): ≥ 1, else
/// a ConfigError (TypeError for another type) naming `what`.
pub(super) fn count(what: &str, obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    use pyo3::types::{PyBool, PyInt};
    if obj.is_instance_of::<PyBool>() || !obj.is_instance_of::<PyInt>() {
        return Err(PyTypeError::new_err(format!(
            "{what} must be an integer ≥ 1, got {}",
            obj.repr()?
        )));
    }
    match obj.extract::<i128>() {
        Ok(v) if v >= 1 => Ok(usize::try_from(v).unwrap_or(usize::MAX)),
        _ => Err(ConfigError::new_err(format!(
            "{what} must be an integer ≥ 1, got {}",
            obj.repr()?
        ))),
    }
}

/// A real number (a Python or NumPy int or float; not a bool, not a
/// string), else a TypeError naming `what`.
pub(super) fn real(what: &str, obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    use pyo3::types::PyBool;
    let v = if obj.is_instance_of::<PyBool>() {
        None
    } else {
        obj.extract::<f64>().ok()
    };
    v.ok_or_else(|| {
        let shown = obj.repr().map_or_else(|_| "?".into(), |r| r.to_string());
        PyTypeError::new_err(format!("{what} must be a real number, got {shown}"))
    })
}

pub(super) fn rows(
    n: usize,
    what: &str,
    a: &PyReadonlyArray2<'_, f64>,
    width: usize,
) -> PyResult<Vec<f64>> {
    if a.shape()[1] != width || a.shape()[0] != n {
        return Err(MeasurementError::new_err(format!(
            "{what} must have shape ({n}, {width}), got {}",
            python_shape(a.shape())
        )));
    }
    // A C-contiguous array (as NumPy makes one) in one copy; any other
    // layout element by element, in the same row-major order.
    Ok(match a.as_slice() {
        Ok(flat) => flat.to_vec(),
        Err(_) => a.as_array().iter().copied().collect(),
    })
}
