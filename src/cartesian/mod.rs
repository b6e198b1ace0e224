//! Task space: an arm's kinematics and the Cartesian impedance that drives a
//! joint controller, SPEC §16. No allocation.

pub mod kinematics;
mod outer;

pub use outer::{
    CartesianCommand, CartesianConfig, CartesianController, CartesianImpedance,
    CartesianMeasurement, CartesianState, OuterStep,
};
