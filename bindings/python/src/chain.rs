//! `adaptimp.Chain` (serial-chain kinematics from joint data, n = 1 … 7,
//! the core's run-time `dynamic::Chain`) and `centres_along` (SPEC §15's
//! rule, the core's `dynamic::Centres::along`).

use super::cartesian_args::*;
use super::dynamic::MAX_JOINTS;
use super::frames::{joint, transform};
use super::MeasurementError;
use super::{array, array1, python_shape, vector, ConfigError};
use adaptimp::cartesian::chain::MAX_CHAIN_JOINTS;
use adaptimp::cartesian::Transform;
use adaptimp::dynamic::{Centres, Joints};
use adaptimp::error::Error;
use numpy::{PyArray1, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::vec::Vec;

// ---------------------------------------------------------------------------
// Chain.
// ---------------------------------------------------------------------------

/// A serial chain of n = 1 … 7 movable (revolute or prismatic) joints and a
/// tip, from joint data (SPEC §16): pose, 6 × n Jacobian and J̇ q̇ of the tip.
/// Use `adaptimp.Chain`, which reads URDF files and MuJoCo models.
#[pyclass(name = "Chain", module = "adaptimp._adaptimp", frozen, subclass)]
pub struct PyChain {
    pub(super) inner: adaptimp::dynamic::Chain,
}

impl PyChain {
    fn qv(&self, what: &'static str, obj: &Bound<'_, PyAny>) -> PyResult<[f64; MAX_JOINTS]> {
        vector(what, self.inner.n(), obj)
    }

    /// The chain behind the object.
    pub(super) fn chain(&self) -> &adaptimp::dynamic::Chain {
        &self.inner
    }
}

#[pymethods]
impl PyChain {
    /// The chain of `joints` (dicts, base to tip: "kind" ("fixed",
    /// "revolute", "prismatic"), the origin as "xyz" and "rpy" (m, rad),
    /// "pos" and "quat" ([w, x, y, z]) or "translation" and "rotation" (3 × 3),
    /// "axis" (3) and "offset" (rad or m, default 0)) and the `tip` transform
    /// (a dict of the same origin keys).
    #[new]
    #[pyo3(signature = (joints, tip=None))]
    fn new(joints: Vec<Bound<'_, PyDict>>, tip: Option<Bound<'_, PyDict>>) -> PyResult<Self> {
        let js = joints.iter().map(joint).collect::<PyResult<Vec<_>>>()?;
        let tip = match tip {
            Some(t) => transform(&t)?,
            None => Transform::IDENTITY,
        };
        let err = |e: Error| ConfigError::new_err(e.to_string());
        let inner = adaptimp::dynamic::Chain::new(&js, &tip).map_err(err)?;
        Ok(Self { inner })
    }

    /// Movable joints n.
    #[getter]
    fn n(&self) -> usize {
        self.inner.n()
    }

    /// Whether each joint is prismatic (else revolute), (n,).
    #[getter]
    fn prismatic(&self) -> Vec<bool> {
        (0..self.inner.n())
            .map(|i| self.inner.is_prismatic(i))
            .collect()
    }

    /// The tip's pose at q: the homogeneous transform (4, 4), world ← tip (m).
    fn fk<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.inner.n();
        let q = self.qv("q", q)?;
        let (p, r) = self.inner.pose(&q[..n]).map_err(cartesian_error)?;
        let mut pose = std::vec![0.0; 16];
        for i in 0..3 {
            pose[4 * i..4 * i + 3].copy_from_slice(&[r[(i, 0)], r[(i, 1)], r[(i, 2)]]);
            pose[4 * i + 3] = p[i];
        }
        pose[15] = 1.0;
        array(py, pose, (4, 4))
    }

    /// The tip's twist and acceleration along recorded rows q, q̇, q̈ (K, n)
    /// (rad, rad/s, rad/s²): (V (K, 6), A (K, 6)) with V = J(q) q̇ = [ṗ; ω]
    /// (m/s, rad/s) and A = J(q) q̈ + J̇ q̇ = [p̈; ω̇] (m/s², rad/s²), one pass
    /// of the chain per row, the GIL released.
    #[allow(clippy::type_complexity)]
    fn motion<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        dq: &Bound<'py, PyAny>,
        ddq: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
        let n = self.inner.n();
        let (k, q) = rows_of("q", q, None, n)?;
        let (_, dq) = rows_of("dq", dq, Some(k), n)?;
        let (_, ddq) = rows_of("ddq", ddq, Some(k), n)?;
        for (what, t) in [("q", &q), ("dq", &dq), ("ddq", &ddq)] {
            if let Some(i) = t.iter().position(|x| !x.is_finite()) {
                return Err(MeasurementError::new_err(format!(
                    "{what}[{}, {}] is not finite (NaN or infinite)",
                    i / n,
                    i % n
                )));
            }
        }
        let inner = &self.inner;
        let (v, a) = py
            .detach(|| {
                let (mut v, mut a) = (std::vec![0.0; 6 * k], std::vec![0.0; 6 * k]);
                for r in 0..k {
                    let rows = r * n..(r + 1) * n;
                    let (tv, ta) = inner
                        .motion(&q[rows.clone()], &dq[rows.clone()], &ddq[rows])
                        .map_err(|e| (r, e))?;
                    v[6 * r..6 * r + 6].copy_from_slice(tv.as_slice());
                    a[6 * r..6 * r + 6].copy_from_slice(ta.as_slice());
                }
                Ok((v, a))
            })
            .map_err(|(r, e): (usize, Error)| {
                MeasurementError::new_err(format!("row {r}: {}", super::python_names(e)))
            })?;
        Ok((array(py, v, (k, 6))?, array(py, a, (k, 6))?))
    }

    /// The geometric Jacobian [J_v; J_ω] at q, (6, n), world-aligned, at the
    /// tip origin: ṗ = J_v q̇ (m/s), ω = J_ω q̇ (rad/s).
    fn jacobian<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.inner.n();
        let q = self.qv("q", q)?;
        let mut rows = std::vec![0.0; 6 * n];
        self.inner
            .jacobian_rows(&q[..n], &mut rows)
            .map_err(cartesian_error)?;
        array(py, rows, (6, n))
    }

    /// J̇ q̇ at (q, q̇), (6,): the tip's classical acceleration at q̈ = 0,
    /// [m/s²; rad/s²] (p̈ = J_v q̈ + (J̇ q̇)_v, ω̇ = J_ω q̈ + (J̇ q̇)_ω).
    fn jdot_qdot<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        dq: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.inner.n();
        let (q, dq) = (self.qv("q", q)?, self.qv("dq", dq)?);
        let bias = self
            .inner
            .bias(&q[..n], &dq[..n])
            .map_err(cartesian_error)?;
        Ok(array1(py, bias.as_slice()))
    }
}

/// RBF centres along an orbit, SPEC §15 (15.2) (`Centers::along`, or
/// `along_periodic` for one period of a periodic orbit): the samples q (L, n)
/// (rad) and q̇ (L, n) (rad/s), the tube (rad, rad/s). Returns the centres
/// (L, 4n) and the squared widths (4n,) (infinite for α1, α̇1).
#[pyfunction]
#[pyo3(signature = (q, dq, tube, periodic=false))]
#[allow(clippy::type_complexity)]
pub fn centres_along<'py>(
    py: Python<'py>,
    q: PyReadonlyArray2<'py, f64>,
    dq: PyReadonlyArray2<'py, f64>,
    tube: (f64, f64),
    periodic: bool,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray1<f64>>)> {
    let (l, n) = (q.shape()[0], q.shape()[1]);
    if !(1..=MAX_CHAIN_JOINTS).contains(&n) || l == 0 {
        return Err(ConfigError::new_err(format!(
            "q must have shape (L, n) with L ≥ 1 and 1 ≤ n ≤ 7, got {}",
            python_shape(q.shape())
        )));
    }
    let qs = rows(l, "q", &q, n)?;
    let dqs = rows(l, "dq", &dq, n)?;
    let samples = qs
        .chunks(n)
        .zip(dqs.chunks(n))
        .map(|(x, dx)| {
            Ok(adaptimp::dynamic::Setpoint {
                x: Joints::from_slice(x)?,
                dx: Joints::from_slice(dx)?,
                ddx: Joints::zeros(n)?,
            })
        })
        .collect::<Result<Vec<_>, Error>>();
    let c = samples
        .and_then(|s| Centres::along(&s, [tube.0, tube.1], periodic))
        .map_err(|e| ConfigError::new_err(e.to_string()))?;
    let (c, w) = (c.rows, c.widths2.unwrap_or_default());
    Ok((array(py, c, (l, 4 * n))?, array1(py, &w)))
}

/// The operational-space inertia Λ (6, 6) of robosuite's OSC_POSE, SPEC
/// (23.7), the core's `dynamic::operational_inertia`: kg on the translation
/// rows, kg m² on the rotation rows, kg m across; `jacobian` the tip's
/// geometric Jacobian [J_v; J_ω] (6, n), `inertia` the joint-space inertia D
/// (n, n; kg m²), `uncoupled` OSC's `uncouple_pos_ori` (Λ block-diagonal).
#[pyfunction]
#[pyo3(signature = (jacobian, inertia, uncoupled=true))]
pub fn operational_inertia<'py>(
    py: Python<'py>,
    jacobian: PyReadonlyArray2<'py, f64>,
    inertia: PyReadonlyArray2<'py, f64>,
    uncoupled: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let n = jacobian.shape()[1];
    if jacobian.shape()[0] != 6 {
        return Err(ConfigError::new_err(format!(
            "jacobian must have shape (6, n), got {}",
            python_shape(jacobian.shape())
        )));
    }
    if inertia.shape() != [n, n] {
        return Err(ConfigError::new_err(format!(
            "inertia must have shape ({n}, {n}) (n: the jacobian's columns), got {}",
            python_shape(inertia.shape())
        )));
    }
    let j: Vec<f64> = jacobian.as_array().iter().copied().collect();
    let d: Vec<f64> = inertia.as_array().iter().copied().collect();
    let lam = adaptimp::dynamic::operational_inertia(&j, &d, uncoupled)
        .map_err(|e| ConfigError::new_err(e.to_string()))?;
    array(py, lam.to_vec(), (6, 6))
}
