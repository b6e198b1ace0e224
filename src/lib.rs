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
//! | [`types`] | `Vector`, `Matrix` aliases (a leaf) | |
//! | [`model`] | manipulator dynamics D, C, G | (4), (55)–(63), §1 |
//! | [`saturation`] | actuator limits | §2 |
//! | [`environment`] | contact force τe; a Cartesian wall (τe = Jᵀ F_e) | §3, §16 |
//! | [`trajectory`] | commanded trajectory xc | (64), §4 |
//! | [`impedance`] | target-impedance reference xd; where it acts | (3), §4 |
//! | [`kinematics`] | end-effector position and Jacobian | §16 |
//! | [`cartesian`] | Cartesian impedance, inverse kinematics, the pair with a joint controller | (3), §16 |
//! | [`rbf`] | Gaussian RBF bases S(Z): the grid, user centres, lattices, centres along an orbit | (1), §6, §15 |
//! | [`network`] | weights ŴD, ŴC, ŴG: storage, output, update | (15)–(17), §6 |
//! | [`learning`] | learning policies (Euler, normalised, freeze, projection) | §11, §13 |
//! | [`simd`] | the weight pass's instruction set, chosen at run time | |
//! | [`robust`] | robust term r(z2) | §7 |
//! | [`auxiliary`] | saturation compensator ζ | (11), (36), §8 |
//! | [`safety`] | fallback command, fault policy, plausibility and rate limits | beyond the paper |
//! | [`observer`] | high-gain velocity observer | (31)–(34), §9 |
//! | [`config`] | every parameter, presets | §4–§11, §13 |
//! | [`schema`] | the parameter table: names, units, docs, conditions, defaults | §10 |
//! | [`io`] | measurement, command, the `Control` trait | §11 |
//! | [`state`] | the caller-owned state | §11 |
//! | [`controller`] | PD, state and output feedback: the staged step | (14), (35), §7, §11 |
//! | [`tracker`] | a controller with its trajectory and state | §11 |
//! | [`plant`] | the `Plant` trait, the rigid-body RK4 plant | §11 |
//! | [`record`] | recorded rows, the `Recorder` trait | §11 |
//! | [`metrics`] | tracking / saturation / impedance figures | §12 |
//! | [`simulator`] | the closed loop | §11 |
//! | [`inject`] | faults injected into a closed loop | beyond the paper |
//! | [`disturb`] | payload, sensor noise and delay, jitter, friction, weak actuators | beyond the paper, §15 |
//! | [`error`] | validation errors | §10 |
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

pub mod auxiliary;
pub mod cartesian;
pub mod config;
pub mod controller;
pub mod disturb;
pub mod environment;
pub mod error;
pub mod impedance;
pub mod inject;
pub mod io;
pub mod kinematics;
pub mod learning;
mod math;
pub mod metrics;
pub mod model;
pub mod network;
pub mod observer;
pub mod plant;
#[cfg(feature = "python")]
mod python;
pub mod rbf;
pub mod record;
pub mod robust;
pub mod safety;
pub mod saturation;
pub mod schema;
pub mod simd;
pub mod simulator;
pub mod state;
#[cfg(feature = "alloc")]
pub mod tracker;
pub mod trajectory;
pub mod types;

pub use auxiliary::AuxLaw;
pub use cartesian::{
    CartesianCommand, CartesianConfig, CartesianController, CartesianImpedance,
    CartesianMeasurement, CartesianState, OuterStep,
};
pub use config::{Config, Law, ObserverInit, WeightBound};
pub use controller::{Bound, Controller, Errors};
pub use disturb::{DisturbanceParams, Disturbances, Friction, TipPayload, WithFriction};
pub use environment::{CartesianWall, Environment, FreeSpace, Wall};
pub use error::Error;
pub use impedance::{ImpedanceMode, Reference, TargetImpedance};
pub use inject::{Injected, Injection};
pub use io::{Command, Control, Measurement};
pub use kinematics::Kinematics;
pub use learning::{Learning, LearningStep, SaturationLearning};
pub use metrics::{Metrics, MetricsAccumulator};
pub use model::{Link, Manipulator, PlanarArm, TwoLinkArm};
pub use network::{Weights, WeightsMut};
pub use observer::{HighGainObserver, Hold};
pub use plant::{rk4_step, Plant, RigidBody};
#[cfg(feature = "alloc")]
pub use rbf::AnyBasis;
pub use rbf::{Basis, Centers, Grid};
#[cfg(feature = "alloc")]
pub use record::Trace;
pub use record::{Recorder, Row};
pub use robust::{Robust, RobustKind};
pub use safety::{Fallback, Fault, FaultPolicy, Limits};
pub use saturation::Saturation;
pub use schema::{Preset, Scenario};
pub use simd::SimdPath;
pub use simulator::{run, run_disturbed, simulate, simulate_disturbed, simulate_with, SimConfig};
#[cfg(feature = "alloc")]
pub use state::HeapState;
pub use state::State;
#[cfg(feature = "alloc")]
pub use tracker::Tracker;
pub use trajectory::{Setpoint, Sinusoid, Trajectory};
pub use types::{grid_nodes, Jacobian, Matrix, Vector};

/// The README's Rust quick start, compiled and run as a doctest inside
/// `fn main() -> Result<(), Box<dyn std::error::Error>>` (`tests/readme.rs`
/// keeps the README's copy identical).
#[cfg(doctest)]
#[doc = concat!(
    "```\nfn main() -> Result<(), Box<dyn std::error::Error>> {\n",
    include_str!("../tests/snippets/readme_quickstart.rs"),
    "Ok(())\n}\n```"
)]
pub struct ReadmeQuickStart;
