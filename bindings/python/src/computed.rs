//! Python bindings of the core's rigid-body dynamics and computed torque
//! (SPEC §20): `ComputedTorque`, the core's run-time controller and its
//! state ([`ComputedCore`]); `adaptimp.baselines.ComputedTorque` is its
//! front. As a joint controller behind `CartesianImpedance` it steps in the
//! core's Cartesian step and native loop like `Controller`, through the
//! const-generic controller of its n ([`ComputedStep`]); alone, in joint
//! space, it is a [`Control`] of the core's loop on MuJoCo along its
//! setpoint of every row.

use super::dynamic::{Hooks, Metrics, MujocoRun, Rows, RunError, View, MAX_JOINTS, OTHER_N};
use super::frames::{inertial, joint};
use super::measurement::JointCall;
use super::mujoco::MujocoSpec;
use super::shared::{Read, Shared, Slot, Write};
use super::{array, array1, vector, vector_into, ConfigError, MeasurementError};
use adaptimp::cartesian::dynamics::Lifted;
use adaptimp::cartesian::{ComputedState, ComputedTorque};
use adaptimp::control::impedance::{ImpedanceMode, TargetImpedance};
use adaptimp::control::io::{Command, Control, Measurement};
use adaptimp::dynamic::{self as dy, for_joints, ForJoints};
use adaptimp::error::Error;
use adaptimp::trajectory::Setpoint;
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use numpy::PyArray1;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use std::any::{Any, TypeId};
use std::sync::Mutex;
use std::vec::Vec;

/// The core's computed-torque controller of any n ≤ 7 with its state.
#[derive(Clone, Debug)]
pub struct ComputedCore {
    /// The controller.
    pub ctrl: dy::ComputedTorque,
    /// Its state.
    pub state: dy::ComputedState,
}

/// An input of a model query refused (MeasurementError, named), or a result
/// that is not finite (DivergedError).
fn input_error(e: Error) -> pyo3::PyErr {
    // Named as in Python: q, dq (the core's x, dx).
    let e = super::python_names(e);
    match e {
        Error::Diverged { .. } => super::DivergedError::new_err(e.to_string()),
        _ => super::MeasurementError::new_err(e.to_string()),
    }
}

/// [`ComputedCore`] as its const-generic controller of N joints, with its
/// state, for a typed loop; `whole`: the run-time controller, of which a run
/// copies the controller at this state for the Python code it calls
/// ([`View`]: made only when asked for).
pub struct ComputedStep<'a, const N: usize> {
    /// The controller.
    pub ctrl: &'a ComputedTorque<N>,
    /// Its state.
    pub state: &'a mut ComputedState<N>,
    whole: &'a dy::ComputedTorque,
}

impl<'a, const N: usize> ComputedStep<'a, N> {
    /// `core` for N joints (an error if it was made for another n).
    pub fn of(core: &'a mut ComputedCore) -> Result<Self, Error> {
        let ComputedCore { ctrl: whole, state } = core;
        let ctrl = whole.typed::<N>().ok_or(OTHER_N)?;
        let state = state.typed_mut::<N>().ok_or(OTHER_N)?;
        Ok(Self { ctrl, state, whole })
    }
}

/// Computed torque as a joint controller of the core's loop: its step on
/// the loop's setpoint; a refused step holds the torque last applied. It
/// has no weights: their norms are NaN in the rows.
impl<const N: usize> Control<N> for ComputedStep<'_, N> {
    fn period(&self) -> f64 {
        self.ctrl.period()
    }
    fn target(&self) -> &TargetImpedance<N> {
        self.ctrl.impedance()
    }
    fn step(&mut self, m: &Measurement<N>, c: &Setpoint<N>) -> Result<Command<N>, Error> {
        let cmd = self.ctrl.step(self.state, m, c)?;
        Ok(Command {
            w_norms: [f64::NAN; 3],
            ..cmd
        })
    }
    fn step_or_fallback(
        &mut self,
        m: &Measurement<N>,
        c: &Setpoint<N>,
    ) -> (Vector<N>, Result<Command<N>, Error>) {
        match Control::step(self, m, c) {
            Ok(cmd) => (cmd.tau_sat, Ok(cmd)),
            Err(e) => (self.state.applied, Err(e)),
        }
    }
}

/// The copy of computed torque as the bindings keep it: the controller with
/// the state as it is now.
impl<const N: usize> View for ComputedStep<'_, N> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        (part == TypeId::of::<Box<ComputedCore>>()).then(|| {
            let mut state = self.whole.new_state();
            if let Some(s) = state.typed_mut::<N>() {
                *s = *self.state;
            }
            let copy = ComputedCore {
                ctrl: self.whole.clone(),
                state,
            };
            Box::new(Box::new(copy)) as Box<dyn Any + Send>
        })
    }
}

/// The closed loop of [`ComputedCore`] on MuJoCo for its N.
struct OnMujoco<'a, H> {
    core: &'a mut ComputedCore,
    sim: &'a mut Sim,
    spec: &'a MujocoSpec,
    run: &'a MujocoRun<'a>,
    hooks: &'a mut H,
}

impl<H: Hooks> ForJoints for OnMujoco<'_, H> {
    type Output = Result<(Rows, Metrics), RunError>;
    fn call<const N: usize>(self) -> Self::Output {
        let mut step = ComputedStep::<N>::of(self.core)?;
        super::drive::run_computed(&mut step, self.sim, self.spec, self.run, self.hooks)
    }
}

/// The parameters of a [`ComputedCore`], as reals per joint.
struct Params<'a> {
    ts: f64,
    kp: &'a [f64],
    kd: &'a [f64],
    tau_max: &'a [f64],
    dd: &'a [f64],
    cd: &'a [f64],
    gd: &'a [f64],
    mode: ImpedanceMode,
    mass_scale: f64,
    payload: f64,
    drive: dy::Drive<'a>,
    /// SPEC (20.9), if given.
    sampled: Option<dy::SampledDrive<'a>>,
    /// SPEC (20.5'), if any stiffness is given.
    spring: Option<dy::Spring<'a>>,
    /// What gravity compensation lifts, one per joint entry (SPEC (20.1')).
    lifted: Option<&'a [Lifted]>,
}

/// The core's controller of `p` on the model of `joints`, `inertials`
/// and `gravity`, composed as SPEC §20 states it.
fn computed(
    joints: &[adaptimp::cartesian::Joint],
    inertials: &[adaptimp::cartesian::Inertial],
    gravity: [f64; 3],
    p: &Params<'_>,
) -> Result<ComputedCore, Error> {
    let model = dy::Dynamics::new(joints, inertials, gravity)?;
    let model = match p.lifted {
        Some(lifted) => model.with_gravity_compensation(joints, lifted)?,
        None => model,
    };
    let model = model
        .scaled(p.mass_scale)?
        .with_payload(p.payload)?
        .with_drive(&p.drive)?;
    let model = match &p.sampled {
        None => model,
        Some(s) => model.with_sampled_drive(s)?,
    };
    let model = match &p.spring {
        None => model,
        Some(s) => model.with_spring(s)?,
    };
    let cfg = dy::ComputedTorqueConfig {
        ts: p.ts,
        kp: p.kp,
        kd: p.kd,
        tau_max: p.tau_max,
        dd: p.dd,
        cd: p.cd,
        gd: p.gd,
        mode: p.mode,
    };
    let ctrl = dy::ComputedTorque::new(&cfg, model)?;
    let state = ctrl.new_state();
    Ok(ComputedCore { ctrl, state })
}

/// What gravity compensation lifts of one link: {"mass" (kg), "moment" (kg m, 3)}.
fn lifted_of(d: &Bound<'_, PyDict>) -> PyResult<Lifted> {
    let get = |key: &str| {
        d.get_item(key)?
            .ok_or_else(|| PyTypeError::new_err(format!("a lifted mass needs its {key}")))
    };
    Ok(Lifted {
        mass: get("mass")?.extract()?,
        moment: get("moment")?.extract()?,
    })
}

fn per_joint(what: &'static str, n: usize, obj: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let v = match obj.extract::<f64>() {
        Ok(x) => std::vec![x; n],
        Err(_) => obj
            .extract::<Vec<f64>>()
            .map_err(|_| PyTypeError::new_err(format!("{what} must be a number or {n} numbers")))?,
    };
    if v.len() != n {
        return Err(ConfigError::new_err(format!(
            "{what} must be a number or have {n} values, got {}",
            v.len()
        )));
    }
    Ok(v)
}

const LAST: [&str; 5] = ["tau", "tau_sat", "xc", "xd", "z1"];

/// Computed-torque impedance control on the core's rigid-body model (SPEC
/// §20). Use `adaptimp.baselines.ComputedTorque`, which builds it from a
/// Pinocchio model.
#[pyclass(
    name = "ComputedTorque",
    module = "adaptimp._adaptimp",
    frozen,
    subclass
)]
pub struct PyComputedTorque {
    inner: Shared<ComputedCore>,
    /// Joints n.
    pub n: usize,
    /// `trajectory(t) -> (xc, dxc, ddxc)` for a step given no setpoint.
    trajectory: Mutex<Option<Py<PyAny>>>,
}

impl PyComputedTorque {
    /// The setpoint (xc, ẋc, ẍc) into `b[3..6]` from the trajectory at t =
    /// steps·Ts (called without holding the controller, which it may read).
    fn setpoint_of_trajectory(
        &self,
        py: Python<'_>,
        rates_given: bool,
        b: &mut [[f64; MAX_JOINTS]; 6],
    ) -> PyResult<()> {
        if rates_given {
            return Err(MeasurementError::new_err("give xc with dxc and ddxc"));
        }
        let traj = super::wait_lock(py, &self.trajectory)
            .as_ref()
            .map(|t| t.clone_ref(py));
        let Some(traj) = traj else {
            return Err(MeasurementError::new_err(
                "no setpoint given and no trajectory to follow",
            ));
        };
        let t = {
            let g = self.read(py)?;
            g.state.steps() as f64 * g.ctrl.period()
        };
        let out = traj.call1(py, (t,))?;
        let out = out.bind(py);
        for (i, what) in ["xc", "dxc", "ddxc"].into_iter().enumerate() {
            vector_into(what, self.n, &out.get_item(i)?, &mut b[3 + i])?;
        }
        Ok(())
    }

    /// The controller for a call that may change it, waiting (with the GIL
    /// released) while another thread uses it.
    pub(super) fn lock(&self, py: Python<'_>) -> PyResult<Write<'_, ComputedCore>> {
        self.inner.write(py)
    }

    /// The controller to read (during a run of its own, the copy the run
    /// publishes for the Python code it calls).
    pub(super) fn read(&self, py: Python<'_>) -> PyResult<Read<'_, ComputedCore>> {
        self.inner.read(py)
    }

    /// Where a run of this controller publishes its copy.
    pub(super) fn slot(&self) -> &dyn Slot {
        &self.inner
    }
}

fn config_err(e: Error) -> PyErr {
    ConfigError::new_err(e.to_string())
}

#[pymethods]
impl PyComputedTorque {
    /// The controller of the chain `joints` (dicts as `Chain` takes them)
    /// with `inertials[k]` the inertial of joint k's child link (dicts:
    /// "mass" (kg), the centre of mass and the inertia's axes as origin keys,
    /// "inertia" 3 × 3 (kg m²) about the centre of mass), `gravity` (m/s²),
    /// period `Ts` (s), K_P (1/s²), K_D (1/s), τmax (N m), the target
    /// impedance Dd, Cd, Gd, `impedance` ("joint" or "external"), the model's
    /// masses times `mass_scale`, a `payload` (kg) at the last joint, and the
    /// joints' drive (SPEC (20.5), (20.6); a number or one per joint, ≥ 0,
    /// default 0): `armature` (kg m²), viscous `damping` (N m s/rad) and dry
    /// `friction` loss (N m) (kg, N s/m, N for a prismatic joint). With
    /// `substep` h (s), the plant's period as it is simulated (SPEC (20.9)):
    /// `substeps` integrator steps of h, the damping integrated implicitly
    /// if `implicit_damping`, the position moved with the new velocity if
    /// `semi_implicit` (its velocity then compared h/2 back, (20.9')), the friction a soft constraint of
    /// regularisation `friction_regularisation` R and reference damping
    /// `friction_rate` b_r (per joint, default 0); computed torque inverts
    /// that period in place of (20.6). `stiffness` k (N m/rad) and
    /// `spring_reference` q_s (rad): passive joint springs (SPEC (20.5')).
    #[new]
    #[pyo3(signature = (joints, inertials, gravity, *, Ts, Kp, Kd, tau_max, Dd, Cd, Gd, impedance, mass_scale, payload, armature=None, damping=None, friction=None, substep=None, substeps=1, implicit_damping=false, semi_implicit=false, friction_regularisation=None, friction_rate=None, stiffness=None, spring_reference=None, lifted=None))]
    #[allow(clippy::too_many_arguments, non_snake_case)]
    fn new(
        joints: Vec<Bound<'_, PyDict>>,
        inertials: Vec<Bound<'_, PyDict>>,
        gravity: [f64; 3],
        Ts: f64,
        Kp: &Bound<'_, PyAny>,
        Kd: &Bound<'_, PyAny>,
        tau_max: &Bound<'_, PyAny>,
        Dd: &Bound<'_, PyAny>,
        Cd: &Bound<'_, PyAny>,
        Gd: &Bound<'_, PyAny>,
        impedance: &str,
        mass_scale: f64,
        payload: f64,
        armature: Option<&Bound<'_, PyAny>>,
        damping: Option<&Bound<'_, PyAny>>,
        friction: Option<&Bound<'_, PyAny>>,
        substep: Option<f64>,
        substeps: u32,
        implicit_damping: bool,
        semi_implicit: bool,
        friction_regularisation: Option<&Bound<'_, PyAny>>,
        friction_rate: Option<&Bound<'_, PyAny>>,
        stiffness: Option<&Bound<'_, PyAny>>,
        spring_reference: Option<&Bound<'_, PyAny>>,
        lifted: Option<Vec<Bound<'_, PyDict>>>,
    ) -> PyResult<Self> {
        let js = joints.iter().map(joint).collect::<PyResult<Vec<_>>>()?;
        let lifted = lifted
            .map(|l| l.iter().map(lifted_of).collect::<PyResult<Vec<_>>>())
            .transpose()?;
        let ins = inertials
            .iter()
            .map(inertial)
            .collect::<PyResult<Vec<_>>>()?;
        let n = js
            .iter()
            .filter(|j| j.kind != adaptimp::cartesian::chain::JointKind::Fixed)
            .count();
        let mode = match impedance {
            "joint" => ImpedanceMode::Joint,
            "external" => ImpedanceMode::External,
            other => {
                return Err(ConfigError::new_err(format!(
                    "impedance must be 'joint' or 'external', got {other:?}"
                )))
            }
        };
        let (kp, kd, tm) = (
            per_joint("Kp", n, Kp)?,
            per_joint("Kd", n, Kd)?,
            per_joint("tau_max", n, tau_max)?,
        );
        let (dd, cd, gd) = (
            per_joint("Dd", n, Dd)?,
            per_joint("Cd", n, Cd)?,
            per_joint("Gd", n, Gd)?,
        );
        let drive = |what: &'static str, v: Option<&Bound<'_, PyAny>>| match v {
            Some(v) => per_joint(what, n, v),
            None => Ok(std::vec![0.0; n]),
        };
        let (armature, damping, friction) = (
            drive("armature", armature)?,
            drive("damping", damping)?,
            drive("friction", friction)?,
        );
        let (regularisation, rate) = (
            drive("friction_regularisation", friction_regularisation)?,
            drive("friction_rate", friction_rate)?,
        );
        let (k, qs) = (
            drive("stiffness", stiffness)?,
            drive("spring_reference", spring_reference)?,
        );
        let p = Params {
            ts: Ts,
            kp: &kp,
            kd: &kd,
            tau_max: &tm,
            dd: &dd,
            cd: &cd,
            gd: &gd,
            mode,
            mass_scale,
            payload,
            drive: dy::Drive {
                armature: &armature,
                damping: &damping,
                friction: &friction,
            },
            sampled: substep.map(|substep| dy::SampledDrive {
                substep,
                substeps,
                implicit_damping,
                semi_implicit,
                regularisation: &regularisation,
                rate: &rate,
            }),
            spring: stiffness.map(|_| dy::Spring {
                stiffness: &k,
                reference: &qs,
            }),
            lifted: lifted.as_deref(),
        };
        let inner = computed(&js, &ins, gravity, &p).map_err(config_err)?;
        Ok(Self {
            n: inner.ctrl.n(),
            inner: Shared::new(Box::new(inner), "ComputedTorque"),
            trajectory: Mutex::new(None),
        })
    }

    /// The setpoint of a step given none: `trajectory(t) -> (xc, dxc,
    /// ddxc)` at t = steps·Ts (None: a step must give xc).
    #[pyo3(signature = (trajectory=None))]
    fn set_trajectory(&self, py: Python<'_>, trajectory: Option<Py<PyAny>>) {
        *super::wait_lock(py, &self.trajectory) = trajectory;
    }

    /// Joints n.
    #[getter]
    fn n(&self) -> usize {
        self.n
    }

    /// Period Ts (s).
    #[getter]
    #[allow(non_snake_case)]
    fn Ts(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.read(py)?.ctrl.period())
    }

    /// Steps taken k (the next step is at t_k = k·Ts).
    #[getter]
    fn steps(&self, py: Python<'_>) -> PyResult<u64> {
        Ok(self.read(py)?.state.steps())
    }

    /// Total mass of the model's moving links (kg).
    #[getter]
    fn mass(&self, py: Python<'_>) -> PyResult<f64> {
        Ok(self.read(py)?.ctrl.mass())
    }

    /// Back to t = 0 (the reference starts at the next setpoint).
    fn reset(&self, py: Python<'_>) -> PyResult<()> {
        self.lock(py)?.state.reset();
        Ok(())
    }

    /// One step (SPEC (20.3)) from the measurement `m`
    /// (`adaptimp.Measurement`: q (rad), dq (rad/s, required), tau_e (N m;
    /// none: zeros)) and the setpoint xc (rad), dxc (rad/s), ddxc (rad/s²)
    /// (default 0), each (n,), or none (the trajectory's). Returns sat(τ)
    /// (N m), (n,). Shapes and types are checked here; the values are the
    /// core's to judge (a non-finite or out-of-range one is a refused step
    /// that records its fault). The old call `step(q, tau_e, dq, …)` works,
    /// with a `DeprecationWarning`.
    #[pyo3(signature = (*args, **kwargs))]
    fn step<'py>(
        &self,
        py: Python<'py>,
        args: &Bound<'py, PyTuple>,
        kwargs: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        let call = JointCall::parse("ComputedTorque.step", args, kwargs)?;
        let [xc, dxc, ddxc] = &call.setpoint;
        let given = call.inputs(n)?;
        let Some(dq) = given.dq else {
            return Err(MeasurementError::new_err(
                "ComputedTorque needs the measured joint velocity dq",
            ));
        };
        // q, tau_e, dq, xc, dxc, ddxc: straight into their buffers.
        let mut b = [
            given.q,
            given.tau_e,
            dq,
            [0.0; MAX_JOINTS],
            [0.0; MAX_JOINTS],
            [0.0; MAX_JOINTS],
        ];
        match xc {
            Some(xc) => {
                vector_into("xc", n, xc, &mut b[3])?;
                if let Some(d) = dxc {
                    vector_into("dxc", n, d, &mut b[4])?;
                }
                if let Some(d) = ddxc {
                    vector_into("ddxc", n, d, &mut b[5])?;
                }
            }
            None => self.setpoint_of_trajectory(py, dxc.is_some() || ddxc.is_some(), &mut b)?,
        }
        let mut guard = self.lock(py)?;
        let core = &mut **guard;
        let m = dy::Measurement {
            x: &b[0][..n],
            dx: Some(&b[2][..n]),
            tau_e: &b[1][..n],
        };
        let c = dy::Setpoint {
            x: &b[3][..n],
            dx: &b[4][..n],
            ddx: &b[5][..n],
        };
        let cmd = core
            .ctrl
            .step(&mut core.state, &m, &c)
            .map_err(input_error)?;
        Ok(array1(py, &cmd.tau_sat))
    }

    /// RNEA(q, q̇, q̈) = M q̈ + C q̇ + G of the controller's model (N m), (n,).
    fn inverse_dynamics<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
        dq: &Bound<'py, PyAny>,
        ddq: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let n = self.n;
        let (q, dq, ddq) = (
            vector("q", n, q)?,
            vector("dq", n, dq)?,
            vector("ddq", n, ddq)?,
        );
        let tau = self
            .read(py)?
            .ctrl
            .inverse_dynamics(&q[..n], &dq[..n], &ddq[..n])
            .map_err(input_error)?;
        Ok(array1(py, &tau))
    }

    /// M(q) of the controller's model (kg m²), (n, n).
    fn mass_matrix<'py>(
        &self,
        py: Python<'py>,
        q: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        let n = self.n;
        let q = vector("q", n, q)?;
        let m = self
            .read(py)?
            .ctrl
            .mass_matrix(&q[..n])
            .map_err(input_error)?;
        // Column-major storage of a symmetric matrix: its rows.
        array(py, m.matrix().iter().copied().collect(), (n, n))
    }

    /// A quantity of the last step by name: "tau", "tau_sat", "xc", "xd",
    /// "z1" (n,) (zeros before the first step).
    fn last<'py>(&self, py: Python<'py>, what: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let i = LAST
            .iter()
            .position(|w| *w == what)
            .ok_or_else(|| ConfigError::new_err(format!("last() knows {LAST:?}, got {what:?}")))?;
        let c = self.read(py)?.state.last();
        Ok(array1(py, [&c.tau, &c.tau_sat, &c.xc, &c.xd, &c.z1][i]))
    }

    /// The last refused step as (message, step), or None.
    #[getter]
    fn fault(&self, py: Python<'_>) -> PyResult<Option<(String, u64)>> {
        Ok(self
            .read(py)?
            .state
            .fault()
            .map(|f| (f.error.to_string(), f.step)))
    }

    /// The closed loop on MuJoCo in joint space, from the controller's
    /// current state (not reset), with the GIL released: the core's loop
    /// (`adaptimp.mujoco.simulate`, SPEC §13.1) along `reference` = (xc, dxc,
    /// ddxc), (K, n) each with K ≥ the steps (the run's reference, or the
    /// controller's own trajectory tabulated). `model`, `data`, `spec`,
    /// `params` (the disturbances of SPEC §17), `t_final`, `settle`,
    /// `record_every`, `progress`, `fault` as for `simulate_mujoco`, whose
    /// dict it returns.
    #[pyo3(signature = (model, data, spec, params, t_final, settle, reference, record_every=1, progress=None, fault=None))]
    #[allow(clippy::too_many_arguments)]
    fn simulate_mujoco<'py>(
        &self,
        py: Python<'py>,
        model: &Bound<'py, PyAny>,
        data: &Bound<'py, PyAny>,
        spec: &Bound<'py, PyDict>,
        params: &Bound<'py, PyDict>,
        t_final: f64,
        settle: f64,
        reference: super::PyReference<'py>,
        record_every: u64,
        progress: Option<Py<PyAny>>,
        fault: Option<super::PyFault>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let fault = super::fault_spec(fault)?;
        if record_every == 0 {
            return Err(ConfigError::new_err("record_every must be ≥ 1"));
        }
        let spec = super::mujoco_spec(spec)?;
        let items = super::items(params)?;
        let tables = super::reference_tables(self.n, Some(&reference))?;
        let mut sim = Sim::from_python(model, data)?;
        let run = MujocoRun {
            t_final,
            settle,
            every: record_every,
            items: &items,
            reference: tables.as_ref().map(|[a, b, c]| [&a[..], &b[..], &c[..]]),
            fault: fault.as_ref(),
        };
        let mut hooks = super::PyHooks::holding(progress, vec![self.slot()]);
        let mut guard = self.lock(py)?;
        let core: &mut ComputedCore = &mut guard;
        let n = self.n;
        let result = py.detach(|| {
            let on = OnMujoco {
                core,
                sim: &mut sim,
                spec: &spec,
                run: &run,
                hooks: &mut hooks,
            };
            for_joints(n, on).unwrap_or(Err(RunError::Core(OTHER_N, None)))
        });
        drop(guard);
        drop(sim);
        let (rec, metrics) = result.map_err(|e| super::run_error(e, &mut hooks))?;
        super::records_dict(py, rec, metrics, true)
    }
}
