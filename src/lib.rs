//! # adaptimp
//!
//! Adaptive neural-network impedance control of robot manipulators whose
//! actuators saturate: a faithful implementation of W. He, Y. Dong and C. Sun,
//! "Adaptive Neural Impedance Control of a Robotic Manipulator With Input
//! Saturation", IEEE Trans. SMC: Systems 46(3), 2016 (DOI 10.1109/TSMC.2015.2429555).
//!
//! The equations, the paper's errata and every decision where the paper is
//! silent are in `SPEC.md` (shipped beside the repository); code comments cite
//! the paper's equation numbers and the SPEC section, e.g. `// (14), SPEC §7`.
//!
//! ## Architecture
//!
//! One module per concept. A [`Controller`] is the validated, immutable
//! description (pinocchio's Model, idsp's configuration; `Send + Sync`); a
//! [`State`] is everything a run changes (pinocchio's Data), owned by the
//! caller. The hot call takes both, in ruckig's shape:
//! `ctrl.step(&mut state, &measurement, &setpoint) -> Result<Command>`, with no
//! heap allocation. One description drives any number of states.
//!
//! | module | concept | paper / SPEC |
//! |---|---|---|
//! | [`types`], [`error`], [`trajectory`] | leaves: `Vector`/`Matrix` aliases, validation errors, the commanded trajectory xc | §10, (64), §4 |
//! | [`control`] | the controller: [`config`], [`controller`] (PD, state and output feedback: the staged step), [`state`], [`io`], [`impedance`] (target-impedance reference xd), [`auxiliary`] (saturation compensator ζ), [`observer`] (high-gain observer), [`robust`], [`saturation`], [`safety`] (fallback, faults, limits), [`tracker`] | (3), (11), (14), (31)–(36), §4–§11, §14 |
//! | [`networks`] | learning: [`rbf`] (bases S(Z): the grid, user centres, lattices, orbits), [`network`] (ŴD, ŴC, ŴG), [`learning`] (Euler, normalised, freeze, projection), [`simd`] | (1), (15)–(17), §6, §13, §15 |
//! | [`cartesian`] | task space: [`kinematics`] (pose, 6 × N Jacobian, J̇ q̇), serial [`chain`](cartesian::chain)s from joint data, the [`rotation`](cartesian::rotation) error, the 6-D Cartesian impedance outer loop and its pair with a joint controller | (3), §16 |
//! | [`description`] (feature `alloc`; URDF files with `urdf`) | reading an arm: a URDF or a compiled MuJoCo model to one kinematic tree, and the one reduction to the arm (which chain, which joints, the tip, what is held and why) | §21 |
//! | [`dynamic`] (feature `alloc`; the loop with `sim`) | the run-time API, for n known only at run time (an arm read from a file): one builder, the joint and Cartesian controllers, chain, dynamics, computed torque and the closed loop, each the const-generic type for its n (chosen once, dispatched by [`with_joints!`]); what the Python and C fronts convert to | — |
//! | [`schema`] | the parameter table: names, units, docs, conditions, defaults | §10 |
//! | `sim` (feature `sim`) | simulation only: `model` (D, C, G of the paper's and planar arms), `environment` (walls), `plant` (the `Plant` trait, RK4), `simulator` (the closed loop), `record`, `metrics`, `disturb`, `inject` | (4), (55)–(63), §1–§3, §11, §12, §17 |
//!
//! ## Quick start
//!
//! ```
//! use adaptimp::{run, Controller, Law, Measurement, SimConfig, Sinusoid, Trajectory, TwoLinkArm, Vector, Wall};
//!
//! // The paper's state-feedback controller with every SPEC default (Ts = 50 µs).
//! let ctrl = Controller::paper(Law::StateFeedback);
//! let mut state = ctrl.new_state(); // on the heap; one description, many states
//! let circle = Sinusoid::paper();    // the commanded trajectory (64)
//! let setpoint = circle.sample(ctrl.time(&state)); // xc, ẋc, ẍc at t_k
//! let measurement = Measurement {
//!     x: Vector::<2>::new(0.25, -0.05),   // joint positions (rad)
//!     dx: Some(Vector::<2>::zeros()),     // joint velocities (rad/s)
//!     tau_e: Vector::<2>::new(50.0, 0.0), // force on the environment (N m)
//! };
//! let cmd = ctrl.step(&mut state, &measurement, &setpoint)?;
//! assert_eq!(cmd.tau_sat[0], 17.0); // saturated: the commanded τ is larger
//!
//! // Or close the loop with the paper's arm and wall for 0.5 s, from a fresh state.
//! let mut state = ctrl.new_state();
//! let sim = SimConfig { t_final: 0.5, ..SimConfig::paper() };
//! let m = run(&TwoLinkArm::paper(), &Wall::paper(), &mut ctrl.bind(&mut state), &circle, &sim, &mut ())?;
//! assert_eq!(m.rows, 10_000);
//! # Ok::<(), adaptimp::Error>(())
//! ```
//!
//! ## `no_std`
//!
//! With `default-features = false` the crate is `no_std` and needs no
//! allocator: a state lives in a buffer of the caller's
//! ([`Controller::state_in`]). The feature `alloc` adds heap states
//! ([`Controller::new_state`]), [`Tracker`] and [`Trace`]; `std` (the
//! default) adds the platform's libm, `std::error::Error` and the run-time
//! check of the operating system's AVX support: without it the weight pass
//! takes AVX2/FMA only in a build for them ([`SimdPath`]).
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

#[cfg(feature = "alloc")]
extern crate alloc;

// The tree shows the architecture: leaves (`types`, `math`, `error`,
// `trajectory`), then the controller (`control`), what it learns with
// (`networks`), task space (`cartesian`), the parameter table (`schema`) and,
// behind the feature `sim`, simulation only (`sim`). Every module keeps its
// short public path (`adaptimp::controller`, …) through the re-exports below.
pub mod cartesian;
pub mod control;
#[cfg(feature = "alloc")]
pub mod description;
pub mod dynamic;
pub mod error;
mod math;
pub mod networks;
pub mod presets;
pub mod schema;
#[cfg(feature = "sim")]
pub mod sim;
pub mod trajectory;
pub mod types;

pub use cartesian::kinematics;
#[cfg(feature = "alloc")]
pub use control::tracker;
pub use control::{
    auxiliary, config, controller, impedance, io, observer, robust, safety, saturation, state,
    tuning,
};
pub use networks::{learning, network, rbf, simd};
#[cfg(feature = "sim")]
pub use sim::{disturb, environment, inject, metrics, model, plant, record, simulator};

pub use auxiliary::AuxLaw;
pub use cartesian::{
    CartesianCommand, CartesianConfig, CartesianController, CartesianImpedance,
    CartesianMeasurement, CartesianState, Chain, CompliantPose, ComputedState, ComputedTorque,
    ComputedTorqueConfig, Drive, Dynamics, Formulation, ImpedanceTorque, Inertial, Joint,
    JointKind, OuterStep, PoseGoal, PoseTarget, SampledDrive, Spring, Transform, FRICTION_VELOCITY,
    GRAVITY,
};
pub use config::{Conditions, Config, Law, ObserverInit, WeightBound};
pub use controller::{Bound, Controller, Errors};
#[cfg(feature = "sim")]
pub use disturb::{DisturbanceParams, Disturbances, Friction, TipPayload, WithFriction};
#[cfg(feature = "sim")]
pub use environment::{CartesianWall, Environment, FreeSpace, Wall};
pub use error::Error;
pub use impedance::{ImpedanceMode, Reference, TargetImpedance};
#[cfg(feature = "sim")]
pub use inject::{Injected, Injection};
pub use io::{Command, Control, Feedforward, Measurement, TaskTorque, WrenchControl};
pub use kinematics::{Jacobian6, Kinematics, Tip};
pub use learning::{Learning, LearningStep, SaturationLearning};
#[cfg(feature = "sim")]
pub use metrics::{Metrics, MetricsAccumulator};
#[cfg(feature = "sim")]
pub use model::{Link, Manipulator, PlanarArm, TwoLinkArm};
pub use network::{Weights, WeightsMut};
pub use observer::{HighGainObserver, Hold};
#[cfg(feature = "sim")]
pub use plant::{rk4_step, Plant, RigidBody};
#[cfg(feature = "alloc")]
pub use rbf::AnyBasis;
pub use rbf::{Basis, Centers, Grid};
#[cfg(all(feature = "sim", feature = "alloc"))]
pub use record::Trace;
#[cfg(feature = "sim")]
pub use record::{Recorder, Row};
pub use robust::{Robust, RobustKind};
pub use safety::{Fallback, Fault, FaultPolicy, Limits};
pub use saturation::Saturation;
pub use schema::{Preset, Scenario};
pub use simd::SimdPath;
#[cfg(feature = "sim")]
pub use simulator::{
    run, run_disturbed, run_disturbed_with, simulate, simulate_disturbed, simulate_with, Adapted,
    Adapter, SimConfig,
};
#[cfg(feature = "alloc")]
pub use state::HeapState;
pub use state::State;
#[cfg(feature = "alloc")]
pub use tracker::Tracker;
pub use trajectory::{Setpoint, Sinusoid, Trajectory};
pub use types::{grid_nodes, Jacobian, Matrix, Vector};

/// The README's Rust quick start, a whole `src/main.rs` (its `main` returns a
/// `Result`), compiled and run as a doctest (`tests/readme.rs` keeps the
/// README's copy identical).
#[cfg(doctest)]
#[doc = concat!(
    "```\n",
    include_str!("../tests/snippets/readme_quickstart.rs"),
    "```"
)]
pub struct ReadmeQuickStart;

/// docs/robot.md's Rust block, a whole program, compiled and run as a
/// doctest (`tests/test_readme.py` keeps the page's copy identical).
#[cfg(doctest)]
#[doc = concat!("```\n", include_str!("../tests/snippets/robot_hardened.rs"), "```")]
pub struct RobotHardened;
