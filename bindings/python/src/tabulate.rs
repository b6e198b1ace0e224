//! `tabulate_path`: a path written in Python, called at t_k = (start + k)·Ts
//! and laid out as the rows (steps, 24) of the core's pose targets (SPEC §16,
//! the layout of `pose_target`); `tabulate_joints`: a joint reference
//! likewise, as the tables (steps, n) of xc, ẋc, ẍc. The loop, the reading of each returned
//! value and the layout run here; a value that is not a float64 NumPy array of
//! its exact shape goes to the caller's `check(name, value, shape)` (the
//! Python front's one validation, which converts it or raises naming it), so
//! every error is the same as the front's own.
//!
//! `adaptimp.cartesian.tabulate` calls it for each run of the core's loop
//! along a Python path: before, the same loop in Python spent about 2 µs a
//! period around the path's own call (`benches/mujoco_loop.py`, its column
//! (d) against (a) − (b) − (c)).

use numpy::{PyArray1, PyArray2, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::format;
use std::vec::Vec;

/// Values in a row: p, ṗ, p̈ (3 each), R (9, row-major), ω, ω̇ (3 each).
const ROW: usize = 24;

/// The identity rotation, row-major.
const EYE: [f64; 9] = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];

/// `v`, the value `what[index]`, into `out` (its length 3 or 9: shape (3,)
/// or (3, 3)): straight from a float64 array of that shape, else through
/// `check(name, v, shape)` (the name made only then).
fn read(
    check: &Bound<'_, PyAny>,
    (what, index): (&str, usize),
    v: &Bound<'_, PyAny>,
    out: &mut [f64],
) -> PyResult<()> {
    if out.len() == 3 {
        if let Ok(a) = v.cast::<PyArray1<f64>>() {
            if a.len() == 3 {
                for (i, o) in out.iter_mut().enumerate() {
                    *o = a.get_owned(i).unwrap_or(f64::NAN);
                }
                return Ok(());
            }
        }
    } else if let Ok(a) = v.cast::<PyArray2<f64>>() {
        if a.shape() == [3, 3] {
            for (i, o) in out.iter_mut().enumerate() {
                *o = a.get_owned([i / 3, i % 3]).unwrap_or(f64::NAN);
            }
            return Ok(());
        }
    }
    let shape = if out.len() == 3 {
        PyTuple::new(v.py(), [3])?
    } else {
        PyTuple::new(v.py(), [3, 3])?
    };
    let checked = check.call1((format!("{what}[{index}]"), v, shape))?;
    let flat = checked.call_method0("ravel")?;
    let a = flat.cast::<PyArray1<f64>>()?;
    for (i, o) in out.iter_mut().enumerate() {
        *o = a.get_owned(i).unwrap_or(f64::NAN);
    }
    Ok(())
}

/// The rows (steps, 24) of `path` at t_k = (start + k)·Ts: a 3-tuple
/// (p, ṗ, p̈) keeps the rotation of the row before (`r0`, (9,) row-major,
/// until a 6-tuple gives one) and ω = ω̇ = 0; a 6-tuple (p, ṗ, p̈, R, ω, ω̇)
/// sets them (None: the identity, or zero rates). `what` names the path
/// in errors (`what[i]`); `check` is the front's validation of one value.
#[pyfunction]
#[pyo3(signature = (path, steps, ts, r0, start, what, check))]
#[allow(clippy::too_many_arguments)]
pub fn tabulate_path<'py>(
    py: Python<'py>,
    path: &Bound<'py, PyAny>,
    steps: usize,
    ts: f64,
    r0: [f64; 9],
    start: u64,
    what: &str,
    check: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let mut out = Vec::new();
    // A table too large for memory is Python's MemoryError, not an abort.
    out.try_reserve_exact(steps.saturating_mul(ROW))
        .map_err(|_| PyMemoryError::new_err(format!("a path table of {steps} rows")))?;
    let mut r = r0;
    for k in 0..steps as u64 {
        let sample = path.call1((((start + k) as f64) * ts,))?;
        let values: Vec<Bound<'py, PyAny>> = match sample.cast::<PyTuple>() {
            Ok(t) => t.iter().collect(),
            Err(_) => sample.try_iter()?.collect::<PyResult<_>>()?,
        };
        let mut row = [0.0; ROW];
        match values.len() {
            3 => {
                for (i, v) in values.iter().enumerate() {
                    read(check, (what, i), v, &mut row[3 * i..3 * i + 3])?;
                }
                row[9..18].copy_from_slice(&r);
            }
            6 => {
                for (i, v) in values.iter().enumerate() {
                    let at = match i {
                        0..=2 => 3 * i..3 * i + 3,
                        3 => 9..18,
                        _ => 18 + 3 * (i - 4)..21 + 3 * (i - 4),
                    };
                    if !v.is_none() {
                        read(check, (what, i), v, &mut row[at])?;
                    } else if i == 3 {
                        row[at].copy_from_slice(&EYE);
                    }
                }
                r.copy_from_slice(&row[9..18]);
            }
            n => {
                return Err(PyValueError::new_err(format!(
                    "{what} must return 3 or 6 arrays (p, dp, ddp[, R, w, dw]), got {n}"
                )))
            }
        }
        out.extend_from_slice(&row);
    }
    super::arrays::array(py, out, (steps, ROW))
}

/// `v`, the value `name`, into `out` (n values, shape (n,)): straight from a
/// float64 array of that shape, else through `check(name, v, (n,))`.
fn read_joints(
    check: &Bound<'_, PyAny>,
    name: impl FnOnce() -> String,
    v: &Bound<'_, PyAny>,
    out: &mut [f64],
) -> PyResult<()> {
    if let Ok(a) = v.cast::<PyArray1<f64>>() {
        if a.len() == out.len() {
            for (i, o) in out.iter_mut().enumerate() {
                *o = a.get_owned(i).unwrap_or(f64::NAN);
            }
            return Ok(());
        }
    }
    let shape = PyTuple::new(v.py(), [out.len()])?;
    let checked = check.call1((name(), v, shape))?;
    let flat = checked.call_method0("ravel")?;
    let a = flat.cast::<PyArray1<f64>>()?;
    for (i, o) in out.iter_mut().enumerate() {
        *o = a.get_owned(i).unwrap_or(f64::NAN);
    }
    Ok(())
}

/// A joint reference written in Python, `reference(t)` → (x, ẋ, ẍ) (n
/// values each), at t_k = (start + k)·Ts for k < `steps`: the three tables
/// (steps, n) of xc, ẋc, ẍc, beside [`tabulate_path`]'s pose targets. Each
/// value that is not a float64 array of shape (n,) goes to `check(name,
/// value, shape)`, `name` being `what[i]` (i = 0, 1, 2).
#[pyfunction]
#[pyo3(signature = (reference, steps, ts, n, start, what, check))]
#[allow(clippy::too_many_arguments)]
pub fn tabulate_joints<'py>(
    py: Python<'py>,
    reference: &Bound<'py, PyAny>,
    steps: usize,
    ts: f64,
    n: usize,
    start: u64,
    what: &str,
    check: &Bound<'py, PyAny>,
) -> PyResult<[Bound<'py, PyArray2<f64>>; 3]> {
    let len = steps.saturating_mul(n);
    let mut tables: [Vec<f64>; 3] = Default::default();
    for t in &mut tables {
        // A table too large for memory is Python's MemoryError, not an abort.
        t.try_reserve_exact(len).map_err(|_| {
            PyMemoryError::new_err(format!("a reference table of {steps} rows of {n}"))
        })?;
    }
    let mut row = std::vec![0.0; n];
    for k in 0..steps as u64 {
        let sample = reference.call1((((start + k) as f64) * ts,))?;
        let values: Vec<Bound<'py, PyAny>> = match sample.cast::<PyTuple>() {
            Ok(t) => t.iter().collect(),
            Err(_) => sample.try_iter()?.collect::<PyResult<_>>()?,
        };
        if values.len() != 3 {
            return Err(PyValueError::new_err(format!(
                "{what} must return 3 arrays (x, dx, ddx), got {}",
                values.len()
            )));
        }
        for (i, (v, table)) in values.iter().zip(&mut tables).enumerate() {
            read_joints(check, || format!("{what}[{i}]"), v, &mut row)?;
            table.extend_from_slice(&row);
        }
    }
    let [x, dx, ddx] = tables;
    let array = |t: Vec<f64>| super::arrays::array(py, t, (steps, n));
    Ok([array(x)?, array(dx)?, array(ddx)?])
}
