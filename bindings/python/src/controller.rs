//! `Controller`: the joint-space controller of n joints behind a mutex, each
//! call atomic, readable by the Python code its own runs call
//! ([`super::shared`]).

use super::dynamic;
use super::dynamic::{CentersSpec, Inputs, JointCore, Last, MAX_JOINTS};
use super::measurement::JointCall;
use super::shared::{Read, Shared, Slot, Write};
use super::{arrays::*, errors::*, hooks::*, params::*};
use adaptimp::control::config::Law;
use adaptimp::schema::Preset;
use numpy::{
    IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyMemoryError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

/// A step's arguments, converted: n values each in fixed buffers.
pub(super) struct Given {
    pub(super) x: Buf,
    pub(super) tau_e: Buf,
    pub(super) dx: Option<Buf>,
    pub(super) setpoint: Option<[Buf; 3]>,
}

impl Given {
    const EMPTY: Self = Self {
        x: [0.0; MAX_JOINTS],
        tau_e: [0.0; MAX_JOINTS],
        dx: None,
        setpoint: None,
    };

    pub(super) fn inputs(&self, n: usize) -> Inputs<'_> {
        let m = adaptimp::dynamic::Measurement {
            x: &self.x[..n],
            dx: self.dx.as_ref().map(|d| &d[..n]),
            tau_e: &self.tau_e[..n],
        };
        let c = self.setpoint.as_ref().map(|s| adaptimp::dynamic::Setpoint {
            x: &s[0][..n],
            dx: &s[1][..n],
            ddx: &s[2][..n],
        });
        (m, c)
    }
}

/// A nominal model as the constructor takes it, SPEC (20.10): the chain's
/// joints and their inertials (dicts) and the gravity vector (m/s²).
type GravityModel<'py> = (Vec<Bound<'py, PyDict>>, Vec<Bound<'py, PyDict>>, [f64; 3]);

/// One of the paper's controllers (SPEC §7) for an arm of n joints, with its
/// commanded trajectory and its state, stepped by the caller at the period
/// Ts (SPEC §11).
///
/// Built from a complete parameter dict; use `adaptimp.Controller`, which
/// fills in the defaults and checks the keywords.
#[pyclass(name = "Controller", module = "adaptimp._adaptimp", frozen, subclass)]
pub(super) struct PyController {
    pub(super) inner: Shared<JointCore>,
    pub(super) n: usize,
    pub(super) law: Law,
}

impl PyController {
    /// The controller for a call that may change it, waiting (with the GIL
    /// released) while another thread uses it.
    pub(super) fn lock(&self, py: Python<'_>) -> PyResult<Write<'_, JointCore>> {
        self.inner.write(py)
    }

    /// The controller to read (during a run of its own, the copy the run
    /// publishes for the Python code it calls).
    pub(super) fn read(&self, py: Python<'_>) -> PyResult<Read<'_, JointCore>> {
        self.inner.read(py)
    }

    /// Where a run of this controller publishes its copy.
    pub(super) fn slot(&self) -> &dyn Slot {
        &self.inner
    }

    pub(super) fn wrap(inner: JointCore) -> Self {
        Self {
            n: inner.n(),
            law: inner.law(),
            inner: Shared::new(Box::new(inner), "Controller"),
        }
    }

    pub(super) fn last<'py>(
        &self,
        py: Python<'py>,
        what: Last,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(array1(py, &self.read(py)?.last(what)))
    }

    /// A step's arguments, converted into `given` (shapes and types checked;
    /// any values). In place: the buffers are not moved about per call.
    pub(super) fn convert(&self, call: &JointCall<'_>, given: &mut Given) -> PyResult<()> {
        let n = self.n;
        let m = call.inputs(n)?;
        given.x = m.q;
        given.tau_e = m.tau_e;
        given.dx = match self.law {
            Law::OutputFeedback => None,
            _ => m.dq,
        };
        given.setpoint = match &call.setpoint {
            [None, None, None] => None,
            [Some(x), dx, ddx] => {
                let zero = [0.0; MAX_JOINTS];
                let conv = |what, o| vector_any(what, n, o);
                Some([
                    conv("xc", x)?,
                    dx.as_ref()
                        .map(|d| conv("dxc", d))
                        .transpose()?
                        .unwrap_or(zero),
                    ddx.as_ref()
                        .map(|d| conv("ddxc", d))
                        .transpose()?
                        .unwrap_or(zero),
                ])
            }
            [None, ..] => {
                return Err(PyTypeError::new_err(
                    "dxc and ddxc need xc (the commanded position)",
                ))
            }
        };
        Ok(())
    }
}

/// A step's arguments refused before the core saw them: recorded as a
/// refused step ([`BAD_ARGUMENTS`]), unless what stopped the call is a
/// warning turned into an error (the deprecated call shape under
/// `-W error`): the call was not made, nothing was wrong with the
/// measurement.
fn refused_arguments(py: Python<'_>, e: &PyErr, g: &mut Write<'_, JointCore>) {
    if !e.is_instance_of::<pyo3::exceptions::PyWarning>(py) {
        g.refuse(BAD_ARGUMENTS);
    }
}

#[pymethods]
impl PyController {
    /// The controller `case` ("pd", "sf", "of") for `n` joints from the
    /// complete parameter dict `params`, with the paper's vertex grid (n ≤ 3)
    /// or the RBF `centers` (L, 4n) with squared widths `widths2` (4n,);
    /// `gravity`: (joints, inertials, gravity (3,)) of a nominal model (dicts
    /// as computed torque takes them) whose G(q) the law adds, SPEC (20.10).
    #[new]
    #[pyo3(signature = (case, params, n=2, centers=None, widths2=None, gravity=None))]
    fn new(
        case: &str,
        params: &Bound<'_, PyDict>,
        n: usize,
        centers: Option<PyReadonlyArray2<'_, f64>>,
        widths2: Option<PyReadonlyArray1<'_, f64>>,
        gravity: Option<GravityModel<'_>>,
    ) -> PyResult<Self> {
        let n = check_n(n)?;
        let law = law_of(case)?;
        let items = items(params)?;
        let centers = match (centers, widths2) {
            (None, None) => None,
            (Some(c), Some(w)) => {
                if c.shape()[1] != 4 * n || c.shape()[0] == 0 {
                    return Err(ConfigError::new_err(format!(
                        "centers must have shape (L, {}) (L ≥ 1 rows of x, v, α1, α̇1 for {n} joints), got {}",
                        4 * n,
                        python_shape(c.shape())
                    )));
                }
                Some(CentersSpec {
                    centers: c.as_array().iter().copied().collect(),
                    widths2: w.as_array().iter().copied().collect(),
                })
            }
            _ => {
                return Err(PyTypeError::new_err(
                    "centers and widths2 go together (or neither, for the vertex grid)",
                ))
            }
        };
        let gravity = match gravity {
            None => None,
            Some((joints, inertials, g)) => Some(dynamic::GravitySpec {
                joints: joints
                    .iter()
                    .map(super::frames::joint)
                    .collect::<PyResult<Vec<_>>>()?,
                inertials: inertials
                    .iter()
                    .map(super::frames::inertial)
                    .collect::<PyResult<Vec<_>>>()?,
                gravity: g,
            }),
        };
        if let Some(g) = &gravity {
            let movable = g
                .joints
                .iter()
                .filter(|j| j.kind != adaptimp::cartesian::chain::JointKind::Fixed)
                .count();
            if movable != n {
                return Err(ConfigError::new_err(format!(
                    "gravity's model has {movable} movable joints, the controller {n}"
                )));
            }
        }
        let inner = dynamic::build(
            n,
            Preset::Paper,
            law,
            &items,
            centers.as_ref(),
            gravity.as_ref(),
        )
        .map_err(config_error)?;
        Ok(Self::wrap(inner))
    }

    /// One controller step at t_k = k·Ts from the measurement `m`
    /// (`adaptimp.Measurement`): joint positions q (rad), the measured force
    /// on the environment τe (N m; none: zeros) and, for "pd" and "sf",
    /// joint velocities q̇ (rad/s; ignored by "of"); with `xc` (and
    /// optionally `dxc`, `ddxc`, zero if not given) the controller tracks
    /// that setpoint instead of its trajectory. Returns sat(τ) (N m), (n,).
    /// The old call `step(q, tau_e, dq)` still works, with a
    /// `DeprecationWarning`.
    /// A refused step raises, and records the refusal as `step_or_fallback`
    /// does (the fault, the fallback as the torque applied, the measured
    /// position): the fault semantics of docs/reliability.md.
    #[pyo3(signature = (*args, **kwargs))]
    fn step<'py>(
        &self,
        py: Python<'py>,
        args: &Bound<'py, PyTuple>,
        kwargs: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        // Values are the core's to judge (a non-finite one is a refused step
        // that records its fault); shapes and types are checked here.
        let mut given = Given::EMPTY;
        let call = JointCall::parse("Controller.step", args, kwargs)?;
        // Converted before the controller is taken: a value's own Python
        // code (an `__float__`) may read it.
        let converted = self.convert(&call, &mut given);
        let mut g = self.lock(py)?;
        converted.inspect_err(|e| refused_arguments(py, e, &mut g))?;
        let mut out = [0.0; MAX_JOINTS];
        g.step(&given.inputs(n), &mut out[..n])
            .map_err(step_error)?;
        Ok(array1(py, &out[..n]))
    }

    /// One step as `step`, but never raising for a refused step: returns the
    /// torque to apply (N m, (n,)) and the error message (None on success);
    /// after a refusal the torque is the configured fallback, and the next
    /// step's rate limit starts from it. Shapes and types are still checked
    /// (a wrong one raises, and is recorded as a refused step).
    #[pyo3(signature = (*args, **kwargs))]
    fn step_or_fallback<'py>(
        &self,
        py: Python<'py>,
        args: &Bound<'py, PyTuple>,
        kwargs: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Option<String>)> {
        let n = self.n;
        // Shapes and types are checked (a refusal, recorded, then raised);
        // values are the controller's to judge.
        let mut given = Given::EMPTY;
        let call = JointCall::parse("Controller.step_or_fallback", args, kwargs)?;
        // Converted before the controller is taken: a value's own Python
        // code (an `__float__`) may read it.
        let converted = self.convert(&call, &mut given);
        let mut g = self.lock(py)?;
        converted.inspect_err(|e| refused_arguments(py, e, &mut g))?;
        let mut out = [0.0; MAX_JOINTS];
        let result = g.step_or_fallback(&given.inputs(n), &mut out[..n]);
        Ok((
            array1(py, &out[..n]),
            result.err().map(|e| python_names(e).to_string()),
        ))
    }

    /// The fault recorded by the last failed step: (message, step k), or None.
    #[getter]
    fn fault(&self, py: Python<'_>) -> PyResult<Option<(String, u64)>> {
        Ok(self
            .read(py)?
            .fault()
            .map(|(e, k)| (python_names(e).to_string(), k)))
    }

    /// Clear the recorded fault; nothing else changes (the learned state,
    /// the torque last applied and the jump anchors are kept).
    fn clear_fault(&self, py: Python<'_>) -> PyResult<()> {
        self.lock(py)?.state.clear_fault();
        Ok(())
    }

    /// `K` steps in one call from (K, n) float64 tables, without the GIL;
    /// returns sat(τ), (K, n). Signals are checked every 50 ms of work and
    /// `progress(done, total)` is called as often. On an error at row k the
    /// steps before it have been taken and the error names the row.
    #[pyo3(signature = (q, tau_e, dq=None, *, xc=None, dxc=None, ddxc=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn replay<'py>(
        &self,
        py: Python<'py>,
        q: PyReadonlyArray2<'py, f64>,
        tau_e: PyReadonlyArray2<'py, f64>,
        dq: Option<PyReadonlyArray2<'py, f64>>,
        xc: Option<PyReadonlyArray2<'py, f64>>,
        dxc: Option<PyReadonlyArray2<'py, f64>>,
        ddxc: Option<PyReadonlyArray2<'py, f64>>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.n;
        let rows = q.shape()[0];
        let x = table("q", &q, rows, n)?;
        let te = table("tau_e", &tau_e, rows, n)?;
        let dx = match (self.law, &dq) {
            (Law::OutputFeedback, _) | (_, None) => None,
            (_, Some(dq)) => Some(table("dq", dq, rows, n)?),
        };
        let zeros = || vec![0.0; rows * n];
        let sp = match (&xc, &dxc, &ddxc) {
            (None, None, None) => None,
            (Some(x), dx, ddx) => Some([
                table("xc", x, rows, n)?,
                dx.as_ref()
                    .map(|d| table("dxc", d, rows, n))
                    .transpose()?
                    .unwrap_or_else(zeros),
                ddx.as_ref()
                    .map(|d| table("ddxc", d, rows, n))
                    .transpose()?
                    .unwrap_or_else(zeros),
            ]),
            _ => {
                return Err(PyTypeError::new_err(
                    "dxc and ddxc need xc (the commanded position)",
                ))
            }
        };
        let mut out = Vec::new();
        if out.try_reserve_exact(rows * n).is_err() {
            return Err(PyMemoryError::new_err(format!(
                "cannot allocate the torques of {rows} rows"
            )));
        }
        out.resize(rows * n, 0.0);
        let mut hooks = PyHooks::holding(progress, vec![self.slot()]);
        let mut guard = self.lock(py)?;
        let tables = adaptimp::dynamic::Replay {
            x: &x,
            dx: dx.as_deref(),
            tau_e: &te,
            setpoint: sp.as_ref().map(|[a, b, c]| [&a[..], &b[..], &c[..]]),
        };
        let core: &mut JointCore = &mut guard;
        let result = py.detach(|| core.replay(&tables, &mut out, &mut hooks));
        drop(guard);
        result.map_err(|e| run_error(e, &mut hooks))?;
        array(py, out, (rows, n))
    }

    /// Back to t = 0, everything as at construction: weights, ζ, observer,
    /// reference, the torque last applied (zero), the jump anchors, the fault.
    fn reset(&self, py: Python<'_>) -> PyResult<()> {
        self.lock(py)?.reset();
        Ok(())
    }

    /// The whole state as a flat float64 array (header, n, L, step count,
    /// reference, ζ, observer, last command, norms, basis, weights, the
    /// torque applied, the last measured position, a checksum); `restore`
    /// puts it back exactly, so a run continues bit-identically.
    fn snapshot<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let data = self.read(py)?.snapshot();
        Ok(data.into_pyarray(py))
    }

    /// Restore a `snapshot` of a controller with the same n and L. Checked
    /// before anything changes (`ConfigError` naming the value): its format,
    /// its checksum, and that this controller could step it (the reference,
    /// the torques and the weights within their limits, the stored weight
    /// norms those of the weights). Clears a recorded fault.
    fn restore(&self, py: Python<'_>, data: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        let data: Vec<f64> = data.as_array().iter().copied().collect();
        let g = &mut *self.lock(py)?;
        g.ctrl.restore(&mut g.state, &data).map_err(state_error)
    }

    /// Replace the network weights: "D" (n, n, L), "C" (n, n, L), "G" (n, L)
    /// float64 arrays (checked: shape, finite, norms within the projection
    /// bounds and 1e100; on an error nothing changes).
    fn load_weights(&self, py: Python<'_>, weights: &Bound<'_, PyDict>) -> PyResult<()> {
        let l = self.read(py)?.nodes();
        let rows = weight_rows(self.n, l, weights)?;
        let g = &mut *self.lock(py)?;
        g.ctrl
            .load_weights(&mut g.state, &rows)
            .map_err(state_error)
    }

    /// Take over the actuators from a controller that was applying ``tau``
    /// (n,) (N m) until now (a robot's own, holding the arm: libfranka's
    /// ``tau_J_d`` read before the torque loop starts): the first step's
    /// torque rate limit moves from it, SPEC (22.4). Before
    /// the first step only; ``tau`` finite and within τmax (ConfigError
    /// naming what is wrong; on an error nothing changes).
    fn take_over(&self, py: Python<'_>, tau: &Bound<'_, PyAny>) -> PyResult<()> {
        let t = vector("tau", self.n, tau)?;
        let g = &mut *self.lock(py)?;
        g.ctrl
            .take_over(&mut g.state, &t[..self.n])
            .map_err(state_error)
    }

    /// "pd", "sf" or "of".
    #[getter]
    fn case(&self) -> &'static str {
        case_of(self.law)
    }

    /// Joints n.
    #[getter]
    fn n(&self) -> usize {
        self.n
    }

    /// RBF nodes L.
    #[getter]
    fn nodes(&self, py: Python<'_>) -> PyResult<usize> {
        Ok(self.read(py)?.nodes())
    }

    /// Time of the next step t_k = k·Ts (s).
    #[getter]
    fn t(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.read(py)?.time())
    }

    /// Steps taken since construction or reset.
    #[getter]
    fn steps(&self, py: Python<'_>) -> PyResult<u64> {
        Ok(self.read(py)?.steps())
    }

    /// Sampling period Ts (s).
    #[getter(Ts)]
    fn ts(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.read(py)?.ts())
    }

    /// Auxiliary state ζ (N m) now, i.e. what the next step uses, (11).
    #[getter]
    fn zeta<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        Ok(array1(py, self.read(py)?.state.zeta()))
    }

    /// Velocity the last step used (rad/s): dq, or the observer's estimate for "of".
    #[getter]
    fn dq_hat<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.last(py, Last::V)
    }

    /// The last step's commanded torque τ (N m), before saturation.
    #[getter]
    fn tau<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.last(py, Last::Tau)
    }

    /// The last step's applied torque sat(τ) (N m).
    #[getter]
    fn tau_sat<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.last(py, Last::TauSat)
    }

    /// The torque to apply now (N m): the last accepted step's sat(τ), or,
    /// after a refused call (also one that raised), the configured fallback;
    /// the next step's rate limit is measured from it.
    #[getter]
    fn applied<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.last(py, Last::Applied)
    }

    /// The last step's Δτ = sat(τ) − τ (N m).
    #[getter]
    fn dtau<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.last(py, Last::Dtau)
    }

    /// The last step's tracking error z1 = xd − q (rad).
    #[getter]
    fn z1<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.last(py, Last::Z1)
    }

    /// The last step's commanded position xc (rad).
    #[getter]
    fn xc<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.last(py, Last::Xc)
    }

    /// The last step's compliant reference xd (rad).
    #[getter]
    fn xd<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.last(py, Last::Xd)
    }

    /// Network weights now (after the last step's update), SPEC §6:
    /// "D" (n, n, L) kg m², "C" (n, n, L) kg m²/s, "G" (n, L) N m,
    /// indexed [k][j][i] (output row, column, node).
    #[getter]
    fn weights<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let (mut w, l) = {
            let g = self.read(py)?;
            (g.state.weights(), g.nodes())
        };
        let n = self.n;
        let g = w.split_off(2 * n * n * l);
        let c = w.split_off(n * n * l);
        let out = PyDict::new(py);
        out.set_item("D", array(py, w, (n, n, l))?)?;
        out.set_item("C", array(py, c, (n, n, l))?)?;
        out.set_item("G", array(py, g, (n, l))?)?;
        Ok(out)
    }

    /// The projection's weight bounds on ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F as resolved,
    /// or None.
    #[getter]
    fn weight_bound(&self, py: Python<'_>) -> PyResult<Option<[f64; 3]>> {
        Ok(self.read(py)?.ctrl.weight_bound())
    }

    /// (g, min Kp): the per-step gain of the explicit-Euler learning step at
    /// the start of the trajectory (N m per rad/s) and the smallest Kp; the
    /// learning loop is stable for g < Kp (docs/robot.md).
    #[getter]
    fn learning_gain(&self, py: Python<'_>) -> PyResult<(f64, f64)> {
        Ok(self.read(py)?.ctrl.learning_gain())
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let g = self.read(py)?;
        Ok(format!(
            "<adaptimp._adaptimp.Controller case={:?} n={} L={} Ts={} s, t={} s, steps={}>",
            case_of(self.law),
            self.n,
            g.nodes(),
            g.ts(),
            g.time(),
            g.steps()
        ))
    }
}
