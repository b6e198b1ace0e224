//! Robot descriptions, read once for every front (SPEC §21): a URDF file
//! (feature `urdf`) or a compiled MuJoCo model's arrays become one
//! kinematic [`Tree`]; one [`reduce`] turns a tree into the [`Arm`] adaptimp
//! drives: which chain, which joints are the arm's, the tip, what is held
//! fixed and why, and the arm's [`Chain`](crate::Chain), bodies
//! ([`Dynamics`](crate::Dynamics)), limits, efforts and drive terms.
//! Python's `adaptimp.Chain.from_urdf`, `adaptimp.mujoco.from_urdf`,
//! `adaptimp.baselines.ComputedTorque` and C's `adaptimp_chain_from_urdf`
//! all call it.
//!
//! Readers apart from algorithms (pinocchio's `parsers/`): this module
//! knows files and names; the chain and the dynamics know numbers.
//!
//! ```
//! # #[cfg(feature = "urdf")] {
//! use adaptimp::description::{reduce, urdf};
//! use adaptimp::{Chain, Dynamics, Kinematics, Vector, GRAVITY};
//!
//! let text = r#"<robot name="two">
//!   <link name="base"/>
//!   <link name="upper"><inertial><origin xyz="0.15 0 0"/><mass value="2"/>
//!     <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.02"/></inertial></link>
//!   <link name="fore"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
//!     <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
//!   <link name="tool"/>
//!   <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
//!     <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="20" velocity="2"/>
//!     <dynamics damping="0.5"/></joint>
//!   <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
//!     <origin xyz="0.3 0 0"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="10" velocity="2"/></joint>
//!   <joint name="flange" type="fixed"><parent link="fore"/><child link="tool"/>
//!     <origin xyz="0.2 0 0"/></joint>
//! </robot>"#;
//! let tree = urdf::read_str(text)?;                 // or urdf::read_file("arm.urdf")
//! let arm = reduce(&tree, Some("tool"), &[])?;      // the chain from the root to "tool"
//! let chain: Chain<2> = arm.to_chain()?;            // kinematics to the tip
//! let dynamics: Dynamics<2> = arm.to_dynamics(GRAVITY)?.with_drive(arm.drive()?)?;
//! let tip = chain.fk(&Vector::<2>::new(0.0, 0.0));
//! assert!((tip.x - 0.5).abs() < 1e-15);             // 0.3 m + 0.2 m along x
//! assert_eq!(arm.joints[1].effort, 10.0);           // N m
//! assert!((dynamics.mass() - 3.0).abs() < 1e-15);   // kg
//! assert_eq!(dynamics.drive().damping[0], 0.5);      // N m s/rad, its <dynamics damping>
//! # }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod error;
pub mod mujoco;
mod reduce;
mod tree;
#[cfg(feature = "urdf")]
pub mod urdf;

pub use error::{DescriptionError, ErrorKind};
pub use mujoco::MujocoArrays;
pub use reduce::{reduce, Arm, ArmJoint, Held, HeldJoint, GRIPPER_WORDS};
pub use tree::{
    Dialect, JointType, Link, LinkInertial, Mimic, NamedFrame, Origin, Tree, TreeJoint,
};
