//! Python bindings of task space (SPEC §16): `CartesianImpedance` (the
//! core's 6-D outer loop over a chain, stepped alone, with an
//! `adaptimp.Controller` — the core's joint step, no Python in between — or
//! with a joint controller written in Python). The chain is `chain`'s, the
//! outer loop behind the object `cartesian_outer`'s, the inputs read by
//! `cartesian_args`; errors become the exceptions of `adaptimp._errors`.

use super::cartesian_loop::{pose_target, CartesianRun, TARGET_LEN};
use super::computed::{ComputedCore, PyComputedTorque};
use super::dynamic::{scenario, JointCore, Owned, MAX_JOINTS};
use super::measurement::PyMeasurement;
use super::shared::{Read, Shared, Slot, Write};
use super::{array, array1, config_error, items, shape_error, vector, ConfigError, PyController};
use adaptimp::cartesian::PoseTarget;
use adaptimp::control::config::Law;
use adaptimp::error::Error;
use adaptimp::schema::Preset;
use adaptimp_mujoco::Sim;
use nalgebra::Matrix3;
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::vec::Vec;

use super::cartesian_args::*;
use super::cartesian_outer::*;
pub use super::chain::{centres_along, PyChain};

/// The core's joint controller behind a Python object, locked: an
/// `adaptimp.Controller` or a `ComputedTorque` (SPEC §20) of n joints, with
/// where a run publishes its copy.
enum Locked<'a> {
    Adaptive(Write<'a, JointCore>, &'a dyn Slot),
    Computed(Write<'a, ComputedCore>, &'a dyn Slot),
}

impl<'a> Locked<'a> {
    fn joint(&mut self) -> JointRef<'_> {
        match self {
            Locked::Adaptive(g, _) => JointRef::Adaptive(g),
            Locked::Computed(g, _) => JointRef::Computed(g),
        }
    }

    fn slot(&self) -> &'a dyn Slot {
        match self {
            Locked::Adaptive(_, s) | Locked::Computed(_, s) => *s,
        }
    }
}

fn lock_joint<'a>(
    py: Python<'_>,
    controller: &'a Bound<'_, PyAny>,
    n: usize,
) -> PyResult<Locked<'a>> {
    let (got, locked) = if let Ok(c) = controller.cast::<PyController>() {
        let c = c.get();
        (c.n, Locked::Adaptive(c.lock(py)?, c.slot()))
    } else if let Ok(c) = controller.cast::<PyComputedTorque>() {
        let c = c.get();
        (c.n, Locked::Computed(c.lock(py)?, c.slot()))
    } else {
        return Err(PyTypeError::new_err(
            "the joint controller must be an adaptimp.Controller or a core ComputedTorque",
        ));
    };
    if got != n {
        return Err(ConfigError::new_err(format!(
            "the joint controller has {got} joints, the chain {n}"
        )));
    }
    Ok(locked)
}

// ---------------------------------------------------------------------------
// CartesianImpedance.
// ---------------------------------------------------------------------------

/// The 6-D Cartesian impedance outer loop of SPEC §16 over a `Chain`, with its
/// state; stepped alone (`reference`), with an `adaptimp.Controller`
/// (`step_controller`: the core's joint step) or with a joint controller
/// written in Python (`step_python`). Use `adaptimp.CartesianController`.
#[pyclass(name = "CartesianImpedance", module = "adaptimp._adaptimp", frozen)]
pub struct PyCartesian {
    inner: Shared<OuterCore>,
    n: usize,
}

impl PyCartesian {
    /// The outer loop for a call that may change it ([`Shared::write`]).
    fn lock(&self, py: Python<'_>) -> PyResult<Write<'_, OuterCore>> {
        self.inner.write(py)
    }

    /// The outer loop to read ([`Shared::read`]).
    fn read(&self, py: Python<'_>) -> PyResult<Read<'_, OuterCore>> {
        self.inner.read(py)
    }

    /// The time of the next step, t_k = k·Ts (s).
    pub(super) fn clock(&self, py: Python<'_>) -> PyResult<f64> {
        let g = self.read(py)?;
        Ok(g.steps() as f64 * g.ts())
    }

    fn measurement<'a>(
        &self,
        q: &'a [f64; MAX_JOINTS],
        dq: Option<&'a [f64; MAX_JOINTS]>,
        wrench: [f64; 6],
        target: Option<PoseTarget>,
    ) -> StepIn<'a> {
        StepIn {
            q: &q[..self.n],
            dq: dq.map(|d| &d[..self.n]),
            wrench,
            target,
        }
    }
}

#[pymethods]
impl PyCartesian {
    /// The outer loop with the complete Cartesian parameter dict `params`
    /// (the schema's group "cartesian") over `chain`, at period `ts` (s),
    /// started at `q0` (rad), with the null-space `posture` (default q0).
    #[new]
    #[pyo3(signature = (chain, params, ts, q0, posture=None))]
    fn new(
        chain: &PyChain,
        params: &Bound<'_, PyDict>,
        ts: f64,
        q0: &Bound<'_, PyAny>,
        posture: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let n = chain.inner.n();
        let items: Vec<(String, Owned)> = items(params)?;
        let cfg = scenario::<1>(Preset::Robot, Law::Pd, &items)
            .map_err(config_error)?
            .cartesian;
        let q0 = vector("q0", n, q0)?;
        let posture = posture.map(|p| vector("posture", n, p)).transpose()?;
        let inner = OuterCore::new(
            &chain.inner,
            cfg,
            ts,
            &q0[..n],
            posture.as_ref().map(|p| &p[..n]),
        )
        .map_err(|e| ConfigError::new_err(e.to_string()))?;
        Ok(Self {
            inner: Shared::new(Box::new(inner), "CartesianController"),
            n,
        })
    }

    /// Joints n.
    #[getter]
    fn n(&self) -> usize {
        self.n
    }

    /// Period Ts (s).
    #[getter]
    fn ts(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.read(py)?.ts())
    }

    /// Steps taken.
    #[getter]
    fn steps(&self, py: Python<'_>) -> PyResult<u64> {
        Ok(self.read(py)?.steps())
    }

    /// Whether the orientation is a task (False: position-only, Kd_rot = 0).
    #[getter]
    fn orients(&self, py: Python<'_>) -> PyResult<bool> {
        Ok(self.read(py)?.orients())
    }

    /// Back to t = 0 at `q0` (rad; default the start's); the posture is kept.
    #[pyo3(signature = (q0=None))]
    fn reset(&self, py: Python<'_>, q0: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
        let q0 = q0.map(|q| vector("q0", self.n, q)).transpose()?;
        self.lock(py)?
            .reset(q0.as_ref().map(|q| &q[..self.n]))
            .map_err(|e| ConfigError::new_err(e.to_string()))
    }

    /// The null-space posture q_posture (rad), (n,).
    fn set_posture(&self, py: Python<'_>, posture: &Bound<'_, PyAny>) -> PyResult<()> {
        let p = vector("posture", self.n, posture)?;
        self.lock(py)?
            .set_posture(&p[..self.n])
            .map_err(|e| ConfigError::new_err(e.to_string()))
    }

    /// Check a flat pose target (24,) as a step would (its parts finite and
    /// within their ceilings, R_c a rotation), changing nothing:
    /// MeasurementError naming the part.
    fn check_target(&self, py: Python<'_>, target: &Bound<'_, PyAny>) -> PyResult<()> {
        let t = target_of(Some(target))?;
        match t {
            Some(t) => self.read(py)?.check_target(&t).map_err(cartesian_error),
            None => Ok(()),
        }
    }

    /// Ask for the stiffness `Kd` (N/m, (3,)) and `Kd_rot` (N m/rad, (3,)): the
    /// impedance moves to it through the target filter (SPEC (16.6)).
    #[allow(non_snake_case)]
    #[pyo3(name = "set_stiffness", signature = (Kd, Kd_rot))]
    fn set_stiffness(
        &self,
        py: Python<'_>,
        Kd: &Bound<'_, PyAny>,
        Kd_rot: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        let (a, b) = (flat("Kd", 3, Kd)?, flat("Kd_rot", 3, Kd_rot)?);
        self.lock(py)?
            .set_stiffness([a[0], a[1], a[2]], [b[0], b[1], b[2]])
            .map_err(|e| ConfigError::new_err(e.to_string()))
    }

    /// The outer loop alone, one committed step: `target` the commanded pose
    /// flat (24,: p, ṗ, p̈, R row-major, ω, ω̇; None: hold the last one),
    /// `wrench` F_e = [f; m] (N, N m). Returns (q_d, q̇_d, q̈_d) of t_k.
    #[pyo3(signature = (target, wrench))]
    #[allow(clippy::type_complexity)]
    fn reference<'py>(
        &self,
        py: Python<'py>,
        target: Option<&Bound<'py, PyAny>>,
        wrench: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        let target = target_of(target)?;
        let wrench = wrench_of(wrench)?;
        let mut g = self.lock(py)?;
        g.reference(target.as_ref(), wrench)
            .map_err(cartesian_error)?;
        Ok((
            array1(py, &g.last(0)),
            array1(py, &g.last(1)),
            array1(py, &g.last(2)),
        ))
    }

    /// One Cartesian step with `controller` (an `adaptimp.Controller` with
    /// impedance "external", the same n and Ts): the core's outer loop and
    /// joint step, no Python in between. Returns sat(τ) (N m), (n,).
    #[pyo3(signature = (controller, q, dq, wrench, target=None))]
    fn step_controller<'py>(
        &self,
        py: Python<'py>,
        controller: &Bound<'py, PyAny>,
        q: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
        wrench: &Bound<'py, PyAny>,
        target: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        let q = vector("q", n, q)?;
        let dq = dq.map(|d| vector("dq", n, d)).transpose()?;
        let f_e = wrench_of(wrench)?;
        let m = self.measurement(&q, dq.as_ref(), f_e, target_of(target)?);
        let mut joint = lock_joint(py, controller, n)?;
        let mut g = self.lock(py)?;
        g.step_tracker(joint.joint(), &m).map_err(cartesian_error)?;
        Ok(array1(py, &g.last(16)))
    }

    /// One step of `CartesianController.step` with the core's joint
    /// `controller`, in one call: an `adaptimp.Measurement` as `q` (dq and
    /// wrench None), or q (rad), dq (rad/s), each (n,), the wrench
    /// F_e = [f; m] (N, N m; (6,), f (3,) alone, or None: no contact), the
    /// commanded pose `sample`: None (hold the last target), the tuple (p,
    /// ṗ, p̈) or (p, ṗ, p̈, R, ω, ω̇) a path returns (m, m/s, m/s², (3, 3),
    /// rad/s, rad/s²; a rate None is 0, R None the held rotation, a given R
    /// held from now on) or a flat target (24,); with `record`, the step's row
    /// kept for [`take_log`](Self::take_log). Shapes and types are checked
    /// here, the values by the core (a refused step records its fault).
    /// Returns sat(τ) (N m), (n,).
    #[pyo3(signature = (controller, q, dq, wrench, sample, record))]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step_sample<'py>(
        &self,
        py: Python<'py>,
        controller: &Bound<'py, PyAny>,
        q: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
        wrench: Option<&Bound<'py, PyAny>>,
        sample: Option<&Bound<'py, PyAny>>,
        record: bool,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        let mut qb = [0.0; MAX_JOINTS];
        let mut dqb = [0.0; MAX_JOINTS];
        let (measured_dq, f) = if let Ok(m) = q.cast::<PyMeasurement>() {
            // An adaptimp.Measurement: read as it is, no array made.
            let m = m.get();
            if dq.is_some() || wrench.is_some() {
                return Err(PyTypeError::new_err(
                    "give the measurement as an adaptimp.Measurement or as arrays, not both",
                ));
            }
            if m.n != n {
                return Err(shape_error("q", n, &format!("length {}", m.n)));
            }
            qb = m.q;
            dqb = m.dq.unwrap_or(dqb);
            (m.dq.is_some(), m.wrench.unwrap_or([0.0; 6]))
        } else {
            super::vector_into("q", n, q, &mut qb)?;
            if let Some(d) = dq {
                super::vector_into("dq", n, d, &mut dqb)?;
            }
            let f = match wrench {
                None => [0.0; 6],
                Some(w) => wrench_sample(w)?,
            };
            (dq.is_some(), f)
        };
        let mut joint = lock_joint(py, controller, n)?;
        let mut g = self.lock(py)?;
        // The rotation a sample sets is held only once the core accepted the
        // step: a refused one (a rotation that is not one) keeps nothing.
        let target = match sample {
            None => None,
            Some(s) => Some(sample_target(s, g.held())?),
        };
        let m = self.measurement(&qb, measured_dq.then_some(&dqb), f, target);
        g.step_tracker(joint.joint(), &m).map_err(cartesian_error)?;
        if let Some(t) = &target {
            g.held_mut().hold(t.r);
        }
        if record {
            g.record();
        }
        Ok(array1(py, &g.applied()[..n]))
    }

    /// The commanded rotation a target without one keeps, (3, 3).
    fn held_rotation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let r = *self.read(py)?.held().rotation();
        array(py, r.transpose().as_slice().to_vec(), (3, 3))
    }

    /// Hold the commanded rotation `r` (3, 3) from now on.
    fn set_held_rotation(&self, py: Python<'_>, r: &Bound<'_, PyAny>) -> PyResult<()> {
        let v = flat("R", 9, r)?;
        self.lock(py)?.held_mut().hold(Matrix3::from_row_slice(&v));
        Ok(())
    }

    /// The rows `step_sample` kept since the last call, (K, 30 + n): p_c,
    /// ṗ_c, p̈_c, p_d, ṗ_d, p̈_d (3 each), q_d (n), F_e (6), the error (6).
    fn take_log<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        // A callback of a run of this controller reads a copy, which keeps
        // no rows: the run's rows join the log when it ends.
        let (v, rows) = match self.inner.write_or_copy(py)? {
            Some(mut g) => g.take_log(),
            None => (Vec::new(), 0),
        };
        array(py, v, (rows, LOG_WIDTH + self.n))
    }

    /// One Cartesian step with a joint controller written in Python:
    /// `inner.step(m, xc=q_d, dxc=q̇_d, ddxc=q̈_d)` is called with the
    /// measurement (q, q̇, τe = Jᵀ F_e, the wrench) and the core's joint
    /// reference (`measurement=False`: the deprecated `inner.step(q, tau_e,
    /// dq, …)`), and the outer state is committed only if it returns.
    /// Returns its torque (N m), (n,).
    #[pyo3(signature = (inner, q, dq, wrench, target=None, *, measurement=true))]
    #[allow(clippy::too_many_arguments)]
    fn step_python<'py>(
        &self,
        py: Python<'py>,
        inner: &Bound<'py, PyAny>,
        q: &Bound<'py, PyAny>,
        dq: Option<&Bound<'py, PyAny>>,
        wrench: &Bound<'py, PyAny>,
        target: Option<&Bound<'py, PyAny>>,
        measurement: bool,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        let q = vector("q", n, q)?;
        let dq = dq.map(|d| vector("dq", n, d)).transpose()?;
        let f_e = wrench_of(wrench)?;
        let m = self.measurement(&q, dq.as_ref(), f_e, target_of(target)?);
        let mut raised: Option<PyErr> = None;
        let mut g = self.lock(py)?;
        // The joint controller may read this one: the state before the step.
        let shown = self.inner.showing(g.view());
        let mut call = |q: &[f64],
                        dq: Option<&[f64]>,
                        tau_e: &[f64],
                        r: [&[f64]; 3],
                        task: Option<(&[f64], &[f64])>,
                        out: &mut [f64]|
         -> Result<(), Error> {
            let result = (|| -> PyResult<Vec<f64>> {
                let kw = PyDict::new(py);
                kw.set_item("xc", array1(py, r[0]))?;
                kw.set_item("dxc", array1(py, r[1]))?;
                kw.set_item("ddxc", array1(py, r[2]))?;
                if let Some((torque, jt)) = task {
                    // Jᵀ is n × 6 column-major: J (6 × n) row-major.
                    kw.set_item("task_torque", array1(py, torque))?;
                    let j = numpy::PyArray1::from_slice(py, jt).reshape([6, torque.len()])?;
                    kw.set_item("jacobian", j)?;
                }
                let tau = if measurement {
                    let meas = PyMeasurement::of(q, dq, Some(tau_e), Some(&f_e));
                    inner.call_method("step", (Bound::new(py, meas)?,), Some(&kw))?
                } else {
                    let dq = dq.map(|d| array1(py, d));
                    inner.call_method("step", (array1(py, q), array1(py, tau_e), dq), Some(&kw))?
                };
                super::callback::numeric_torque(&tau, out.len())?;
                let v = flat("the joint controller's torque", out.len(), &tau)?;
                Ok(v)
            })();
            match result {
                Ok(v) => {
                    out.copy_from_slice(&v);
                    Ok(())
                }
                Err(e) => {
                    raised = Some(e);
                    Err(Error::Invalid {
                        what: "joint controller",
                        reason: "raised",
                    })
                }
            }
        };
        let r = g.step_joint(&m, &mut call);
        drop(shown);
        if let Some(e) = raised {
            return Err(e);
        }
        r.map_err(cartesian_error)?;
        Ok(array1(py, &g.last(16)))
    }

    /// A quantity of the last step by name: "q_d", "dq_d", "ddq_d" (n,);
    /// "p_d", "dp_d", "ddp_d", "w_d", "dw_d" (3,) and "R_d" (3, 3), the
    /// compliant reference; "p_t" (3,), "R_t" (3, 3), the filtered target;
    /// "error" (6,) [e_p; e_o] after clipping; "p" (3,), "R" (3, 3), the
    /// measured tip; "tau_e", "tau", "tau_sat", "z1" (n,); "p_c", "dp_c",
    /// "ddp_c" (3,), the commanded position and rates (the filtered target
    /// p_t at rest when the step had none); "wrench" (6,), the F_e it was
    /// given (NaN before a step).
    fn last<'py>(&self, py: Python<'py>, what: &str) -> PyResult<Bound<'py, PyAny>> {
        let i = LAST
            .iter()
            .position(|n| *n == what)
            .ok_or_else(|| PyValueError::new_err(format!("last: one of {LAST:?}, got {what:?}")))?;
        let v = self.read(py)?.last(i);
        if v.len() == 9 && what.starts_with('R') {
            Ok(array(py, v, (3, 3))?.into_any())
        } else {
            Ok(array1(py, &v).into_any())
        }
    }

    /// A quantity of the state by name: "p_d" (3,), "R_d" (3, 3), "q_d",
    /// "dq_d", "posture" (n,), "stiffness", "stiffness_filtered" (6,)
    /// [K_d; K_d,rot], "offset" (6,) of the target filter, "wrench" (6,)
    /// filtered.
    fn state<'py>(&self, py: Python<'py>, what: &str) -> PyResult<Bound<'py, PyAny>> {
        let i = STATE.iter().position(|n| *n == what).ok_or_else(|| {
            PyValueError::new_err(format!("state: one of {STATE:?}, got {what:?}"))
        })?;
        let v = self.read(py)?.state(i);
        if what == "R_d" {
            Ok(array(py, v, (3, 3))?.into_any())
        } else {
            Ok(array1(py, &v).into_any())
        }
    }

    /// The closed loop on MuJoCo of this outer loop in front of `controller`
    /// (an `adaptimp.Controller` with impedance "external", the same n and
    /// Ts), from both states (not reset), with the GIL released: the core's
    /// loop (`adaptimp.mujoco.simulate`'s native loop, SPEC §13.1) with the
    /// measured wrench. `model`, `data`, `spec`, `params` (the disturbances
    /// of SPEC §17), `t_final`, `settle`, `record_every`, `progress`,
    /// `fault` as for `simulate_mujoco`; `targets` the commanded pose of
    /// every row (K, 24) (None: the last target held). Returns the dict of
    /// `simulate_mujoco` with the reference in task space ("xc", "dxc",
    /// "ddxc" = p_c, ṗ_c, p̈_c; "xd" = p_d; "z1" = p_d − p(q); (K, 3)), the
    /// metrics of task space, and "task": a dict of "pc", "dpc", "ddpc",
    /// "pd", "dpd", "ddpd" (K, 3), "qd" (K, n), "wrench", "error" (K, 6).
    /// Afterwards `last` gives the last step taken, also after an error.
    #[pyo3(signature = (controller, model, data, spec, params, t_final, settle, record_every=1, progress=None, targets=None, fault=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate_mujoco<'py>(
        &self,
        py: Python<'py>,
        controller: &Bound<'py, PyAny>,
        model: &Bound<'py, PyAny>,
        data: &Bound<'py, PyAny>,
        spec: &Bound<'py, PyDict>,
        params: &Bound<'py, PyDict>,
        t_final: f64,
        settle: f64,
        record_every: u64,
        progress: Option<Py<PyAny>>,
        targets: Option<PyReadonlyArray2<'py, f64>>,
        fault: Option<super::PyFault>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let fault = super::fault_spec(fault)?;
        if record_every == 0 {
            return Err(ConfigError::new_err("record_every must be ≥ 1"));
        }
        let mut joint = lock_joint(py, controller, self.n)?;
        let spec = super::mujoco_spec(spec)?;
        let items = items(params)?;
        let targets = match &targets {
            None => None,
            Some(t) => Some(rows(t.shape()[0], "targets", t, TARGET_LEN)?),
        };
        let mut sim = Sim::from_python(model, data)?;
        let run = CartesianRun {
            t_final,
            settle,
            every: record_every,
            items: &items,
            targets: targets.as_deref(),
            fault: fault.as_ref(),
        };
        let mut hooks = super::PyHooks::holding(progress, vec![&self.inner, joint.slot()]);
        let mut outer = self.lock(py)?;
        let mut partial = None;
        let result = {
            let (t, o): (JointRef<'_>, &mut OuterCore) = (joint.joint(), &mut outer);
            py.detach(|| o.simulate_mujoco(t, &mut sim, &spec, &run, &mut hooks, &mut partial))
        };
        drop(outer);
        drop(joint);
        drop(sim);
        let (rec, task, metrics) = match result {
            Ok(out) => out,
            Err(e) => {
                // The rows of the steps taken before the error (Ctrl-C, a
                // diverged plant), as the exception's `partial`: the
                // controller's log keeps them.
                let err = super::run_error(e, &mut hooks);
                if let Some(task) = partial {
                    let k = task.z1.len() / 3;
                    err.value(py).setattr("partial", task_dict(py, task, k)?)?;
                }
                return Err(err);
            }
        };
        let k = rec.len();
        let out = super::records_dict(py, rec, metrics, true)?;
        for (name, v) in [
            ("xc", &task.pc[0]),
            ("dxc", &task.pc[1]),
            ("ddxc", &task.pc[2]),
            ("xd", &task.pd[0]),
            ("z1", &task.z1),
        ] {
            out.set_item(name, array(py, v.clone(), (k, 3))?)?;
        }
        out.set_item("task", task_dict(py, task, k)?)?;
        Ok(out)
    }

    /// Steps of this outer loop in front of `controller` (as for
    /// `step_controller`) over recorded rows, the core's alone with the GIL
    /// released: q, dq (K, n) (rad, rad/s), wrench (K, 6) (N, N m),
    /// `targets` (K, 24) (None: the last target held). Returns sat(τ) (K, n)
    /// (N m); errors name the row. For the cost of the controller without a
    /// plant.
    #[pyo3(signature = (controller, q, dq, wrench, targets=None, progress=None))]
    #[allow(clippy::too_many_arguments)]
    fn replay<'py>(
        &self,
        py: Python<'py>,
        controller: &Bound<'py, PyAny>,
        q: PyReadonlyArray2<'py, f64>,
        dq: PyReadonlyArray2<'py, f64>,
        wrench: PyReadonlyArray2<'py, f64>,
        targets: Option<PyReadonlyArray2<'py, f64>>,
        progress: Option<Py<PyAny>>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let n = self.n;
        let k = q.shape()[0];
        let q = super::table("q", &q, k, n)?;
        let dq = super::table("dq", &dq, k, n)?;
        let wrench = super::table("wrench", &wrench, k, 6)?;
        let targets = match &targets {
            None => None,
            Some(t) => Some(super::table("targets", t, k, TARGET_LEN)?),
        };
        let mut out = Vec::with_capacity(k * n);
        let mut joint = lock_joint(py, controller, n)?;
        let mut hooks = super::PyHooks::holding(progress, vec![&self.inner, joint.slot()]);
        let mut outer = self.lock(py)?;
        let result = {
            let (t, o): (JointRef<'_>, &mut OuterCore) = (joint.joint(), &mut outer);
            py.detach(|| {
                o.replay(
                    t,
                    k,
                    [&q, &dq, &wrench],
                    targets.as_deref(),
                    &mut out,
                    &mut hooks,
                )
            })
        };
        drop(outer);
        drop(joint);
        result.map_err(|e| super::run_error(e, &mut hooks))?;
        array(py, out, (k, n))
    }

    /// The steps round(T/Ts) of an orbit of `T` (s) at this loop's period
    /// (1 … 1e6) and the number of samples `nodes` (an integer ≥ 1), checked
    /// by name before a path is tabulated.
    #[pyo3(name = "orbit_size", signature = (T, nodes))]
    #[allow(non_snake_case)]
    fn orbit_size(
        &self,
        py: Python<'_>,
        T: &Bound<'_, PyAny>,
        nodes: &Bound<'_, PyAny>,
    ) -> PyResult<(usize, usize)> {
        let t = real("T", T)?;
        let nodes = count("nodes", nodes)?;
        let ts = self.read(py)?.ts();
        let steps = adaptimp::cartesian::orbit_steps(t, ts)
            .map_err(|e| ConfigError::new_err(e.to_string()))?;
        Ok((steps, nodes))
    }

    /// The orbit rule (SPEC §15, §16): run this outer loop kinematically
    /// (F_e = 0) from `q0` along `targets` (K, 24) (one flat pose target per
    /// step) and return the joint reference (q_d, q̇_d, q̈_d, each (L, n)) of
    /// every max(1, K // nodes)-th step, L ≤ `nodes`. This loop's state is
    /// unchanged.
    #[allow(clippy::type_complexity)]
    fn orbit<'py>(
        &self,
        py: Python<'py>,
        q0: &Bound<'py, PyAny>,
        targets: PyReadonlyArray2<'py, f64>,
        nodes: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        let n = self.n;
        let q0 = vector("q0", n, q0)?;
        let nodes = count("nodes", nodes)?;
        let k = targets.shape()[0];
        let flat_rows = rows(k, "targets", &targets, TARGET_LEN)?;
        let ts: Vec<PoseTarget> = flat_rows.chunks(TARGET_LEN).map(pose_target).collect();
        let g = self.read(py)?;
        let [q, dq, ddq] = py
            .detach(|| g.orbit(&q0[..n], &ts, nodes))
            .map_err(cartesian_error)?;
        let l = q.len() / n;
        Ok((
            array(py, q, (l, n))?,
            array(py, dq, (l, n))?,
            array(py, ddq, (l, n))?,
        ))
    }
}
