//! Task space: an arm's kinematics (pose, 6 × N Jacobian, J̇ q̇), serial
//! chains from joint data, the rotation error on SO(3), and the 6-D Cartesian
//! impedance that drives a joint controller, SPEC §16. No allocation.

pub mod chain;
pub mod computed;
pub mod dynamics;
pub mod impedance_torque;
pub mod kinematics;
pub mod opspace;
mod outer;
mod pair;
pub mod rotation;
pub mod rule;

pub use chain::{Chain, Joint, JointKind, Transform, MAX_CHAIN_JOINTS};
pub use computed::{ComputedState, ComputedTorque, ComputedTorqueConfig};
pub use dynamics::{
    Drive, Dynamics, Inertial, Lifted, SampledDrive, Spring, FRICTION_VELOCITY, GRAVITY,
};
pub use impedance_torque::{ImpedanceTorque, PoseGoal};
pub use kinematics::{Jacobian6, Kinematics, Tip};
pub use outer::{
    orbit_steps, CartesianConfig, CartesianImpedance, CartesianState, CompliantPose, Formulation,
    OuterStep, PoseTarget, ORBIT_MAX_STEPS,
};
#[cfg(feature = "alloc")]
pub(crate) use pair::{check_joint, set_posture as set_pair_posture, start as start_pair};
pub use pair::{CartesianCommand, CartesianController, CartesianMeasurement, JointLaw};
pub use rule::{Assessment, PoseCircle, PostureRule, Refusal, TaskRows};
