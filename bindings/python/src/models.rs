//! `TwoLinkArm` and `PlanarArm`: the simulation's arm models (src/sim/model.rs).

use super::dynamic;
use super::{arrays::*, errors::*, params::*};
use adaptimp::control::config::Law;
use adaptimp::dynamic::{JointMatrix, ModelArm};
use adaptimp::schema::Preset;
use adaptimp::sim::model::{Link, TwoLinkArm};
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// D(q) or C(q, q̇) of an arm as a NumPy array (n, n).
fn arm_matrix<'py>(
    py: Python<'py>,
    m: Result<JointMatrix, adaptimp::error::Error>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let m = m.map_err(|e| config_error(e.into()))?;
    let n = m.n();
    let v = m.matrix();
    array(py, (0..n * n).map(|k| v[(k / n, k % n)]).collect(), (n, n))
}

/// A joint quantity of an arm as a NumPy array (n,).
fn arm_vector<'py>(
    py: Python<'py>,
    v: Result<adaptimp::dynamic::Joints, adaptimp::error::Error>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    Ok(array1(py, &v.map_err(|e| config_error(e.into()))?))
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
                let a = self.model();
                let n = a.n();
                arm_matrix(py, a.inertia(&vector("q", n, q)?[..n]))
            }

            /// Coriolis and centripetal matrix C(q, dq) (kg m²/s), (n, n).
            #[pyo3(name = "C")]
            fn coriolis<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
                dq: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let a = self.model();
                let n = a.n();
                arm_matrix(py, a.coriolis(&vector("q", n, q)?[..n], &vector("dq", n, dq)?[..n]))
            }

            /// Gravity torque G(q) (N m), (n,).
            #[pyo3(name = "G")]
            fn gravity<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray1<f64>>> {
                let a = self.model();
                let n = a.n();
                arm_vector(py, a.gravity(&vector("q", n, q)?[..n]))
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
                let a = self.model();
                let n = a.n();
                let acc = a.forward_dynamics(
                    &vector("q", n, q)?[..n],
                    &vector("dq", n, dq)?[..n],
                    &vector("tau", n, tau)?[..n],
                    &vector("tau_e", n, tau_e)?[..n],
                );
                arm_vector(py, acc)
            }

            /// End-effector position fk(q) (m), (3,): the tip of the last link in
            /// the arm's x–y plane (z = 0), SPEC §16.
            fn fk<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray1<f64>>> {
                let a = self.model();
                let n = a.n();
                let (p, _) = a.kinematics(&vector("q", n, q)?[..n]).map_err(|e| config_error(e.into()))?;
                Ok(array1(py, p.as_slice()))
            }

            /// Position Jacobian J(q) = ∂fk/∂q (m/rad), (3, n): ṗ = J q̇, SPEC §16.
            fn jacobian<'py>(
                &self,
                py: Python<'py>,
                q: &Bound<'py, PyAny>,
            ) -> PyResult<Bound<'py, PyArray2<f64>>> {
                let a = self.model();
                let n = a.n();
                let (_, j) = a.kinematics(&vector("q", n, q)?[..n]).map_err(|e| config_error(e.into()))?;
                let j = j.matrix();
                array(py, (0..3 * n).map(|k| j[(k / n, k % n)]).collect(), (3, n))
            }

            /// Joints n.
            #[getter]
            fn n(&self) -> usize {
                self.model().n()
            }
        }
    };
}

/// The paper's 2-link arm in a vertical plane, (55)–(63), SPEC §1.
///
/// Built from a complete parameter dict; use `adaptimp.TwoLinkArm`.
#[pyclass(name = "TwoLinkArm", module = "adaptimp._adaptimp", frozen)]
pub(super) struct PyArm {
    pub(super) inner: TwoLinkArm,
}

impl PyArm {
    fn model(&self) -> ModelArm {
        ModelArm::Paper(self.inner)
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
pub(super) struct PyPlanarArm {
    arm: ModelArm,
    pub(super) links: Vec<Link>,
    pub(super) g: f64,
}

impl PyPlanarArm {
    fn model(&self) -> &ModelArm {
        &self.arm
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
        let arm = ModelArm::planar(&links, g).map_err(|e| config_error(e.into()))?;
        Ok(Self { arm, links, g })
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
