//! Python bindings: the extension module `adaptimp._adaptimp` (cargo feature
//! `python`, built by maturin; see `pyproject.toml`).
//!
//! Thin wrappers over the core for arms of n = 1 … 7 joints with the paper's
//! vertex grid (n ≤ 3) or user RBF centres. The friendly layer (keyword
//! parameters with the paper's defaults, result objects, plots, the CLI) is
//! pure Python in `python/adaptimp/`; it hands this module complete parameter
//! dicts whose keys are the schema's names (`Ts`, `Kp`, `Kzeta`, …).
//!
//! - The controller of n joints is a [`dynamic::DynTracker`] (one
//!   monomorphised core per n behind one object-safe face), the arms are
//!   the core's run-time [`crate::dynamic::ModelArm`]s.
//! - Errors become the exception classes of `adaptimp._errors` in one place
//!   each: [`config_error`] (construction: `ConfigError`) and [`step_error`]
//!   (a step: `MeasurementError`, `DivergedError`, `FaultError`), with the
//!   measurement named as in Python (`q`, not the core's `x`).
//! - Long calls ([`simulate`], `Controller.replay`) run with the GIL released,
//!   check for signals (Ctrl-C) every 50 ms of work and report progress to an
//!   optional callback; records are moved into NumPy without copying.
//! - A controller is behind a mutex: each call is atomic; a thread that finds
//!   it in use by another waits with the GIL released (never "Already
//!   borrowed"). Python code a call runs (a progress callback, a joint
//!   controller written in Python, a path) reads the object that called it
//!   from a copy the call publishes, and cannot change it ([`shared`]): no
//!   call deadlocks on its own thread.
//!
//! Nothing here panics on user input and nothing is `unsafe`.
//!
//! One file a concern: `errors` (core errors to exceptions), `params` (names
//! and the schema's items), `arrays` (NumPy in and out), `hooks` (Ctrl-C and
//! progress), `shared` (the state a call holds, read by the Python code it
//! calls), `controller`, `models` (the simulation's arms), `runs`
//! (`simulate`, `metrics`, `simulate_mujoco`), `sweeps` (`simulate_many`,
//! `simulate_mujoco_many`), `export` (the schema's table); the task-space
//! classes (`cartesian`, `computed`, `description`, `tuning`) and the loops
//! (`dynamic`, `mujoco`, `cartesian_loop`, `callback`). The joint count is
//! dispatched by the core's `with_joints!` (src/dynamic.rs) for every front.

mod arrays;
mod callback;
mod cartesian;
mod cartesian_loop;
mod cartesian_step;
mod computed;
mod controller;
mod description;
mod dynamic;
mod errors;
mod export;
mod frames;
mod hooks;
mod measurement;
mod models;
mod mujoco;
mod params;
mod runs;
mod shared;
mod sweeps;
mod tabulate;
mod tuning;

use self::{
    arrays::*, controller::*, errors::*, export::*, hooks::*, models::*, params::*, runs::*,
    sweeps::*,
};
use dynamic::MAX_JOINTS;
use pyo3::prelude::*;

/// Adaptive neural impedance control with input saturation (He, Dong & Sun,
/// IEEE TSMC 2016): the compiled core for arms of 1 to 7 joints. Use the
/// `adaptimp` package, which wraps this module.
#[pymodule]
#[pyo3(name = "_adaptimp")]
mod adaptimp_module {
    use pyo3::prelude::*;

    #[pymodule_export]
    use super::tuning::{
        assess_posture, default_task, plane_normal, pose_circle, pose_metrics, posture_needs,
        suggest, table_metrics,
    };
    #[pymodule_export]
    use super::{
        defaults, metrics, schema_table, simulate, simulate_many, simulate_mujoco,
        simulate_mujoco_many, PyArm, PyController, PyPlanarArm,
    };

    #[pymodule_export]
    use super::callback::simulate_mujoco_callback;
    #[pymodule_export]
    use super::cartesian::{centres_along, PyCartesian, PyChain};
    #[pymodule_export]
    use super::cartesian_step::PyCartesianStep;
    #[pymodule_export]
    use super::computed::PyComputedTorque;
    #[pymodule_export]
    use super::description::{arm_from_mujoco, description_kind, estimate_effort, read_arm};
    #[pymodule_export]
    use super::measurement::PyMeasurement;
    #[pymodule_export]
    use super::tabulate::{tabulate_joints, tabulate_path};

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        m.add("__version__", env!("CARGO_PKG_VERSION"))?;
        m.add("MAX_JOINTS", super::MAX_JOINTS)?;
        m.add("N_NODES", crate::types::grid_nodes(2))?;
        // Load NumPy's C API now, at import: loading it lazily inside a call
        // can meet a pending KeyboardInterrupt and fail with a panic.
        let _ = numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
        Ok(())
    }
}
