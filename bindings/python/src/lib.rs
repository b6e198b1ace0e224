//! Python bindings: the extension module `adaptimp._adaptimp`, a crate of its
//! own over the core `adaptimp` (built by maturin; see `pyproject.toml`), so
//! the core's dependency tree has no pyo3 or numpy.
//!
//! Thin wrappers over the core for arms of n = 1 … 7 joints with the paper's
//! vertex grid (n ≤ 3) or user RBF centres. The friendly layer (keyword
//! parameters with the paper's defaults, result objects, plots, the CLI) is
//! pure Python in `python/adaptimp/`; it hands this module complete parameter
//! dicts whose keys are the schema's names (`Ts`, `Kp`, `Kzeta`, …).
//!
//! - The controller of n joints is the core's run-time
//!   `adaptimp::dynamic::Controller` and `State` (`dynamic::JointCore`),
//!   built by the core's one builder (`adaptimp::dynamic::Scenario`), as
//!   C's is; the arms are the core's run-time `adaptimp::dynamic::ModelArm`s.
//! - Errors become the exception classes of `adaptimp._errors` in one place
//!   each: `config_error` (construction: `ConfigError`) and `step_error`
//!   (a step: `MeasurementError`, `DivergedError`, `FaultError`), with the
//!   measurement named as in Python (`q`, not the core's `x`).
//! - Long calls (`simulate`, `Controller.replay`) run with the GIL released,
//!   check for signals (Ctrl-C) every 50 ms of work and report progress to an
//!   optional callback; records are moved into NumPy without copying.
//! - A controller is behind a mutex: each call is atomic; a thread that finds
//!   it in use by another waits with the GIL released (never "Already
//!   borrowed"). Python code a call runs (a progress callback, a joint
//!   controller written in Python, a path) reads the object that called it
//!   from a copy the call publishes, and cannot change it (`shared`): no
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
//! classes (`chain`, `cartesian` with `cartesian_outer` and
//! `cartesian_args`, `computed`, `description`, `tuning`), what builds a
//! controller (`items`), and the loops (`dynamic`, `drive`, `mujoco`,
//! `cartesian_loop`, `callback`, `callback_loop`): the MuJoCo plant is the
//! core's run-time `adaptimp::dynamic::Plant`, the rows and metrics the
//! core's `adaptimp::dynamic::{Rows, Metrics, RowMetrics}`. The joint count
//! is dispatched by the core's `for_joints` (src/dynamic/mod.rs) for every
//! typed loop.

mod arrays;
mod callback;
mod callback_loop;
mod cartesian;
mod cartesian_args;
mod cartesian_loop;
mod cartesian_outer;
mod cartesian_step;
mod chain;
mod computed;
mod controller;
mod description;
mod drive;
mod dynamic;
mod errors;
mod export;
mod frames;
mod hooks;
mod items;
mod measurement;
mod models;
mod module;
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
