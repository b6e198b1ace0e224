//! The gain and basis rule of SPEC §18 for Python (`adaptimp.tuning`), a thin
//! face of [`crate::control::tuning`]: arrays in, the schema's names out.

use super::{config_error, law_of, py_value, ConfigError};
use crate::control::tuning::{default_task as core_default_task, inertia_scales_along, Rule};
use crate::error::Error;
use crate::schema::{Group, Preset, Scenario, PARAMS};
use crate::trajectory::Setpoint;
use crate::types::{Matrix, Vector};
use numpy::{
    PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArrayDyn,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn shape_error(what: &str, want: String, got: &[usize]) -> PyErr {
    ConfigError::new_err(format!("{what} must have shape {want}, got {got:?}"))
}

/// The rule's controller keywords (every controller parameter of the schema,
/// by name), the centres (L, 4n) and their widths η (4n,) for `case`, an arm
/// of inertia matrix `inertia` (n, n; kg m²; or (K, n, n): the inertia at K
/// postures along the task's path, SPEC (18.1)'s scales along it), limits
/// `tau_max` (n,; N m),
/// period `ts` (s) and, if given, the task's `path` (K, 3n: q, q̇, q̈ per
/// row, one period of `period` s, evenly spaced in time) with the gravity
/// torque `gravity` (n,; N m) at its start, if known.
#[pyfunction]
#[pyo3(signature = (case, inertia, tau_max, ts, path=None, period=None, gravity=None))]
#[allow(clippy::too_many_arguments)]
pub fn suggest<'py>(
    py: Python<'py>,
    case: &str,
    inertia: PyReadonlyArrayDyn<'py, f64>,
    tau_max: PyReadonlyArray1<'py, f64>,
    ts: f64,
    path: Option<PyReadonlyArray2<'py, f64>>,
    period: Option<f64>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, PyDict>> {
    let law = law_of(case)?;
    let shape = inertia.shape();
    let (k, n) = match shape {
        [a, b] if a == b => (1, *a),
        [k, a, b] if a == b && *k > 0 => (*k, *a),
        _ => (0, 0),
    };
    if !(1..=super::MAX_JOINTS).contains(&n) {
        return Err(shape_error(
            "inertia",
            "(n, n) or (K, n, n), 1 ≤ n ≤ 7".into(),
            shape,
        ));
    }
    let along = shape.len() == 3;
    if tau_max.shape() != [n] {
        return Err(shape_error("tau_max", format!("({n},)"), tau_max.shape()));
    }
    let d: Vec<f64> = inertia.as_array().iter().copied().collect();
    let tau: Vec<f64> = tau_max.as_array().iter().copied().collect();
    let gravity: Option<Vec<f64>> = match gravity {
        None => None,
        Some(g) if g.shape() == [n] => Some(g.as_array().iter().copied().collect()),
        Some(g) => return Err(shape_error("gravity", format!("({n},)"), g.shape())),
    };
    let path: Option<(Vec<f64>, f64)> = match (path, period) {
        (None, _) => None,
        (Some(p), Some(period)) => {
            if p.shape()[1] != 3 * n || p.shape()[0] == 0 {
                return Err(shape_error("path", format!("(K, {})", 3 * n), p.shape()));
            }
            Some((p.as_array().iter().copied().collect(), period))
        }
        (Some(_), None) => {
            return Err(ConfigError::new_err("a path needs its period (s)"));
        }
    };
    let out = PyDict::new(py);
    crate::with_joints!(
        n,
        K => fill::<K>(py, &out, law, (&d, k, along), &tau, ts, path.as_ref(), gravity.as_deref()),
        _ => unreachable!("n checked above"),
    )?;
    Ok(out)
}

#[allow(clippy::too_many_arguments)]
fn fill<'py, const N: usize>(
    py: Python<'py>,
    out: &Bound<'py, PyDict>,
    law: crate::control::config::Law,
    (d, k, along): (&[f64], usize, bool),
    tau: &[f64],
    ts: f64,
    path: Option<&(Vec<f64>, f64)>,
    gravity: Option<&[f64]>,
) -> PyResult<()> {
    let err = |e: Error| config_error(e.into());
    let rule = Rule::default();
    // Row-major (n, n) into nalgebra's column-major: D is symmetric, but a
    // non-symmetric input must be reported, not transposed silently.
    let ds: Vec<Matrix<N>> = (0..k)
        .map(|i| Matrix::<N>::from_row_slice(&d[i * N * N..(i + 1) * N * N]))
        .collect();
    let scales = if along {
        inertia_scales_along(&ds)
    } else {
        crate::control::tuning::inertia_scales(&ds[0])
    }
    .map_err(err)?;
    let tau = Vector::<N>::from_column_slice(tau);
    let mut s = Scenario::<N>::preset(Preset::Robot, law);
    let centers = match path {
        None => {
            s.config = rule.gains_scaled(law, &scales, &tau, ts).map_err(err)?;
            None
        }
        Some((rows, period)) => {
            let samples: Vec<Setpoint<N>> = rows
                .chunks_exact(3 * N)
                .map(|r| Setpoint {
                    x: Vector::from_column_slice(&r[..N]),
                    dx: Vector::from_column_slice(&r[N..2 * N]),
                    ddx: Vector::from_column_slice(&r[2 * N..]),
                })
                .collect();
            let g = gravity.map(Vector::<N>::from_column_slice);
            let sug = rule
                .suggest_scaled(law, &scales, &tau, ts, &samples, *period, g.as_ref())
                .map_err(err)?;
            s.config = sug.config;
            Some(sug.centers)
        }
    };
    let params = PyDict::new(py);
    let mut res = Ok(());
    s.visit(|name, v| {
        let controller = PARAMS
            .iter()
            .any(|p| p.name == name && p.group == Group::Controller);
        if controller && res.is_ok() {
            res = py_value(py, v).and_then(|v| params.set_item(name, v));
        }
    });
    res?;
    out.set_item("params", params)?;
    if let Some(c) = centers {
        let l = c.centers().len() / (4 * N);
        let rows = PyArray1::from_slice(py, c.centers()).reshape([l, 4 * N])?;
        let widths: Vec<f64> = c
            .widths2()
            .iter()
            .flat_map(|b| b.iter().map(|w| w.sqrt()).collect::<Vec<_>>())
            .collect();
        out.set_item("centers", rows)?;
        out.set_item("widths", PyArray1::from_vec(py, widths))?;
    }
    Ok(())
}

/// The default task of SPEC §18 about `home` within [`lo`, `hi`] (rad, (n,)
/// each; ±inf for a continuous joint): (offset, sin, cos, omega), the
/// controller's `xc_*` keywords.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn default_task(
    home: PyReadonlyArray1<'_, f64>,
    lo: PyReadonlyArray1<'_, f64>,
    hi: PyReadonlyArray1<'_, f64>,
) -> PyResult<(Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>)> {
    let n = home.len();
    if !(1..=super::MAX_JOINTS).contains(&n) || lo.len() != n || hi.len() != n {
        return Err(ConfigError::new_err(format!(
            "home, lo and hi must have the same shape (n,), 1 ≤ n ≤ 7; got {}, {}, {}",
            n,
            lo.len(),
            hi.len()
        )));
    }
    let [h, l, u] = [home, lo, hi].map(|a| a.as_array().iter().copied().collect::<Vec<f64>>());
    crate::with_joints!(
        n,
        K => {
            let v = |x: &[f64]| Vector::<K>::from_column_slice(x);
            let t = core_default_task(&v(&h), &v(&l), &v(&u))
                .map_err(|e| config_error(e.into()))?;
            Ok((
                t.offset().as_slice().to_vec(),
                t.sin_amplitude().as_slice().to_vec(),
                t.cos_amplitude().as_slice().to_vec(),
                t.omega().as_slice().to_vec(),
            ))
        },
        _ => unreachable!("n checked above"),
    )
}
