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
//! One module per concept. Parameters (validated once, immutable) are kept
//! apart from state (weights, ζ, observer, reference), and the hot call is
//! [`Controller::step`]: measurement in, command out, no heap allocation.
//!
//! | module | concept | paper / SPEC |
//! |---|---|---|
//! | [`model`] | manipulator dynamics D, C, G | (4), (55)–(63), §1 |
//! | [`saturation`] | actuator limits | §2 |
//! | [`environment`] | contact force τe | §3 |
//! | [`trajectory`] | commanded trajectory xc | (64), §4 |
//! | [`impedance`] | target-impedance reference xd | (3), §4 |
//! | [`rbf`] | Gaussian RBF basis S(Z) | (1), §6 |
//! | [`network`] | weights ŴD, ŴC, ŴG and update laws | (15)–(17), §6 |
//! | [`auxiliary`] | saturation compensator ζ | (11), (36), §8 |
//! | [`observer`] | high-gain velocity observer | (31)–(34), §9 |
//! | [`controller`] | PD, state and output feedback | (14), (35), §7, §11 |
//! | [`simulator`] | closed loop, RK4 plant | §11 |
//! | [`metrics`] | tracking / saturation / impedance figures | §12 |
//! | [`error`] | validation errors | §10 |
//!
//! ## Quick start
//!
//! ```
//! use adaptimp::{simulate, Controller, Law, Measurement, SimConfig, TwoLinkArm, Vector, Wall};
//!
//! // The paper's state-feedback controller with every SPEC default (Ts = 50 µs),
//! // tracking the paper's circle; it keeps its own clock t_k = k·Ts.
//! let mut ctrl = Box::new(Controller::paper(Law::StateFeedback));
//! let cmd = ctrl.step(&Measurement {
//!     x: Vector::<2>::new(0.25, -0.05),   // joint positions (rad)
//!     dx: Some(Vector::<2>::zeros()),     // joint velocities (rad/s)
//!     tau_e: Vector::<2>::new(50.0, 0.0), // force on the environment (N m)
//! })?;
//! assert_eq!(cmd.tau_sat[0], 17.0); // saturated: the commanded τ is larger
//!
//! // Or close the loop with the paper's arm and wall for 0.5 s.
//! let sim = SimConfig { t_final: 0.5, ..SimConfig::paper() };
//! let m = simulate(&TwoLinkArm::paper(), &Wall::paper(), ctrl.as_mut(), &sim, &mut ())?;
//! assert_eq!(m.rows, 10_000);
//! # Ok::<(), adaptimp::Error>(())
//! ```
//!
//! ## `no_std`
//!
//! With `default-features = false` the crate is `no_std` and needs no
//! allocator; every state lives in fixed-size fields whose sizes are const
//! generics: `N` joints and `L` RBF nodes.
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod auxiliary;
pub mod controller;
pub mod environment;
pub mod error;
pub mod impedance;
mod math;
pub mod metrics;
pub mod model;
pub mod network;
pub mod observer;
#[cfg(feature = "python")]
mod python;
pub mod rbf;
pub mod saturation;
pub mod simulator;
pub mod trajectory;

pub use auxiliary::AuxLaw;
pub use controller::{
    Command, Config, Controller, Law, LearningStep, Measurement, ObserverInit, Robust,
    SaturationLearning,
};
pub use environment::{Environment, FreeSpace, Wall};
pub use error::Error;
pub use impedance::{Reference, TargetImpedance};
pub use metrics::{Metrics, MetricsAccumulator};
pub use model::{Manipulator, PlanarArm, TwoLinkArm};
pub use network::Weights;
pub use observer::{HighGainObserver, Hold};
pub use rbf::Rbf;
pub use saturation::Saturation;
#[cfg(feature = "std")]
pub use simulator::Trace;
pub use simulator::{rk4_step, simulate, Recorder, Row, SimConfig};
pub use trajectory::{Setpoint, Sinusoid, Trajectory};

/// A column vector of `N` reals (joint-space quantities: rad, rad/s, N m, …).
pub type Vector<const N: usize> = nalgebra::SVector<f64, N>;
/// An `N × N` real matrix (inertia, Coriolis, …).
pub type Matrix<const N: usize> = nalgebra::SMatrix<f64, N, N>;

/// Number of RBF nodes of the paper's vertex grid for `n` joints: `2^(4n)`
/// (256 for the 2-link arm), SPEC §6.
pub const fn grid_nodes(n: usize) -> usize {
    1 << (4 * n)
}
