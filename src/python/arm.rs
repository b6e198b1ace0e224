//! Arm models behind a run-time number of joints: [`DynArm`], an object-safe
//! face of [`Manipulator<N>`] over slices, for the paper's [`TwoLinkArm`] and
//! [`PlanarArm<N>`] with N = 1 … 7.

use crate::cartesian::kinematics::Kinematics;
use crate::error::Error;
use crate::sim::model::{Link, Manipulator, PlanarArm, TwoLinkArm};
use crate::types::Vector;
use std::vec::Vec;

/// D(q), C(q, q̇), G(q) and the forward dynamics of an arm of n joints, over
/// slices of n values; matrices row-major.
pub trait DynArm: Send + Sync {
    /// Joints n.
    fn n(&self) -> usize;
    /// D(q) (kg m²), n × n row-major.
    fn inertia(&self, q: &[f64]) -> Vec<f64>;
    /// C(q, q̇) (kg m²/s), n × n row-major.
    fn coriolis(&self, q: &[f64], dq: &[f64]) -> Vec<f64>;
    /// G(q) (N m).
    fn gravity(&self, q: &[f64]) -> Vec<f64>;
    /// q̈ (rad/s²) from (4).
    fn forward_dynamics(&self, q: &[f64], dq: &[f64], tau: &[f64], tau_e: &[f64]) -> Vec<f64>;
    /// End-effector position p = fk(q) (m), 3 values (SPEC §16).
    fn fk(&self, q: &[f64]) -> Vec<f64>;
    /// Position Jacobian ∂p/∂q (m/rad), 3 × n row-major (SPEC §16).
    fn jacobian(&self, q: &[f64]) -> Vec<f64>;
}

fn v<const N: usize>(x: &[f64]) -> Vector<N> {
    Vector::from_column_slice(x)
}

fn rows<const N: usize>(m: crate::types::Matrix<N>) -> Vec<f64> {
    m.transpose().as_slice().to_vec()
}

macro_rules! dyn_arm {
    ($ty:ty, $n:expr) => {
        fn n(&self) -> usize {
            $n
        }
        fn inertia(&self, q: &[f64]) -> Vec<f64> {
            rows(Manipulator::inertia(self, &v(q)))
        }
        fn coriolis(&self, q: &[f64], dq: &[f64]) -> Vec<f64> {
            rows(Manipulator::coriolis(self, &v(q), &v(dq)))
        }
        fn gravity(&self, q: &[f64]) -> Vec<f64> {
            Manipulator::gravity(self, &v(q)).as_slice().to_vec()
        }
        fn forward_dynamics(&self, q: &[f64], dq: &[f64], tau: &[f64], tau_e: &[f64]) -> Vec<f64> {
            Manipulator::forward_dynamics(self, &v(q), &v(dq), &v(tau), &v(tau_e))
                .as_slice()
                .to_vec()
        }
        fn fk(&self, q: &[f64]) -> Vec<f64> {
            Kinematics::fk(self, &v(q)).as_slice().to_vec()
        }
        fn jacobian(&self, q: &[f64]) -> Vec<f64> {
            Kinematics::position_jacobian(self, &v(q))
                .transpose()
                .as_slice()
                .to_vec()
        }
    };
}

impl DynArm for TwoLinkArm {
    dyn_arm!(TwoLinkArm, 2);
}

impl<const N: usize> DynArm for PlanarArm<N> {
    dyn_arm!(PlanarArm<N>, N);
}

/// A planar arm of `links.len()` (1 … 7) links.
pub fn planar(links: &[Link], g: f64) -> Result<Box<dyn DynArm>, Error> {
    crate::with_joints!(
        links.len(),
        K => {
            let l: [Link; K] = core::array::from_fn(|i| links[i]);
            Ok(Box::new(PlanarArm::<K>::new(l, g)?))
        },
        _ => Err(Error::Invalid {
            what: "n",
            reason: "the number of links must be between 1 and 7",
        }),
    )
}
