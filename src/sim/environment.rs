//! The environment the robot touches: the contact force τe, SPEC §3.
//!
//! τe is the force (N m, in joint space) that the robot exerts on the
//! environment; the environment pushes back with −τe, (4). A force sensor
//! measures it and the controller reads it.

use crate::cartesian::kinematics::Kinematics;
use crate::error::{check, Error, PARAM_BOUND};
use crate::types::Vector;

/// A contact model: τe as a function of time and the robot's state.
pub trait Environment<const N: usize> {
    /// τe (N m) at time `t` (s), joint position `x` (rad) and velocity `dx` (rad/s).
    fn force(&self, t: f64, x: &Vector<N>, dx: &Vector<N>) -> Vector<N>;
}

/// No contact: τe ≡ 0.
#[derive(Copy, Clone, Debug, Default, PartialEq)]
pub struct FreeSpace;

impl<const N: usize> Environment<N> for FreeSpace {
    fn force(&self, _t: f64, _x: &Vector<N>, _dx: &Vector<N>) -> Vector<N> {
        Vector::zeros()
    }
}

/// A penalty wall that blocks `x[joint] > position`, SPEC §3.
///
/// With δ = x_j − w: `f = max(0, ke δ + be ẋ_j)` if δ > 0, else 0; τe = f e_j.
/// (The `max` keeps a receding wall from pulling the robot.)
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Wall<const N: usize> {
    joint: usize,
    position: f64,
    ke: f64,
    be: f64,
}

impl<const N: usize> Wall<N> {
    /// A wall on `joint` (0-based) at `position` (rad) with stiffness `ke`
    /// (N m/rad) and damping `be` (N m s/rad), both ≥ 0.
    pub fn new(joint: usize, position: f64, ke: f64, be: f64) -> Result<Self, Error> {
        if joint >= N {
            return Err(Error::Invalid {
                what: "wall joint",
                reason: "must be less than the number of joints",
            });
        }
        check::at_most("|wall| ≤ 1e6 rad", "wall", position, 1e6)?;
        check::nonnegative("ke ≥ 0", "ke", ke)?;
        check::nonnegative("be ≥ 0", "be", be)?;
        check::at_most("|value| ≤ 1e9", "ke", ke, PARAM_BOUND)?;
        check::at_most("|value| ≤ 1e9", "be", be, PARAM_BOUND)?;
        Ok(Self {
            joint,
            position,
            ke,
            be,
        })
    }

    /// The joint the wall acts on (0-based).
    pub fn joint(&self) -> usize {
        self.joint
    }
    /// The wall position w (rad).
    pub fn position(&self) -> f64 {
        self.position
    }
    /// Stiffness ke (N m/rad).
    pub fn ke(&self) -> f64 {
        self.ke
    }
    /// Damping be (N m s/rad).
    pub fn be(&self) -> f64 {
        self.be
    }
}

impl<const N: usize> Environment<N> for Wall<N> {
    #[inline]
    fn force(&self, _t: f64, x: &Vector<N>, dx: &Vector<N>) -> Vector<N> {
        let mut tau_e = Vector::zeros();
        let delta = x[self.joint] - self.position;
        if delta > 0.0 {
            tau_e[self.joint] = (self.ke * delta + self.be * dx[self.joint]).max(0.0);
        }
        tau_e
    }
}

/// A penalty wall in task space, SPEC §16: the half-space `n·p > w` of
/// end-effector positions p (m) is solid, with the unit normal n pointing
/// into it. With δ = n·p − w (m) and the kinematics of the arm:
///
/// `F_e = max(0, ke δ + be n·ṗ) n` if δ > 0, else 0 (N, the force the end
/// effector exerts on the wall), and `τe = Jᵀ(q) F_e` (N m).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct CartesianWall<K> {
    kin: K,
    normal: Vector<3>,
    position: f64,
    ke: f64,
    be: f64,
}

impl<K> CartesianWall<K> {
    /// A wall with normal `normal` (normalised here; non-zero and finite), at
    /// `position` w (m) along it, stiffness `ke` (N/m) and damping `be`
    /// (N s/m), both ≥ 0, for the arm of kinematics `kin`.
    pub fn new(kin: K, normal: Vector<3>, position: f64, ke: f64, be: f64) -> Result<Self, Error> {
        check::finite_slice("normal", normal.as_slice())?;
        let len = normal.norm();
        check::positive("‖normal‖ > 0", "‖normal‖", len)?;
        check::at_most("|wall| ≤ 1e6 m", "wall", position, 1e6)?;
        check::nonnegative("ke ≥ 0", "ke", ke)?;
        check::nonnegative("be ≥ 0", "be", be)?;
        check::at_most("|value| ≤ 1e9", "ke", ke, PARAM_BOUND)?;
        check::at_most("|value| ≤ 1e9", "be", be, PARAM_BOUND)?;
        Ok(Self {
            kin,
            normal: normal / len,
            position,
            ke,
            be,
        })
    }

    /// The unit normal n, pointing into the wall.
    pub fn normal(&self) -> &Vector<3> {
        &self.normal
    }
    /// The wall's position w (m) along n.
    pub fn position(&self) -> f64 {
        self.position
    }
    /// Stiffness ke (N/m).
    pub fn ke(&self) -> f64 {
        self.ke
    }

    /// The contact force F_e (N) at end-effector position `p` (m) and velocity `dp` (m/s).
    pub fn force_at(&self, p: &Vector<3>, dp: &Vector<3>) -> Vector<3> {
        let delta = self.normal.dot(p) - self.position;
        if delta > 0.0 {
            (self.ke * delta + self.be * self.normal.dot(dp)).max(0.0) * self.normal
        } else {
            Vector::zeros()
        }
    }

    /// The contact force F_e (N) at joint position `q` (rad) and velocity `dq` (rad/s).
    pub fn wrench<const N: usize>(&self, q: &Vector<N>, dq: &Vector<N>) -> Vector<3>
    where
        K: Kinematics<N>,
    {
        let tip = self.kin.tip(q, dq);
        let j = tip.jacobian.fixed_rows::<3>(0);
        self.force_at(&tip.position, &(j * dq))
    }
}

impl<const N: usize, K: Kinematics<N>> Environment<N> for CartesianWall<K> {
    fn force(&self, _t: f64, x: &Vector<N>, dx: &Vector<N>) -> Vector<N> {
        let tip = self.kin.tip(x, dx);
        let j = tip.jacobian.fixed_rows::<3>(0);
        let f = self.force_at(&tip.position, &(j * dx));
        j.transpose() * f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_pushes_only_when_penetrated_and_never_pulls() {
        let w = Wall::paper();
        let z = Vector::<2>::zeros();
        assert_eq!(w.force(0.0, &Vector::<2>::new(0.19, 0.0), &z), z);
        let f = w.force(0.0, &Vector::<2>::new(0.25, 0.0), &z);
        assert!((f[0] - 50.0).abs() < 1e-12 && f[1] == 0.0, "{f}");
        // Leaving the wall fast: ke δ + be ẋ < 0 is clipped to 0 (no adhesion).
        let f = w.force(
            0.0,
            &Vector::<2>::new(0.201, 0.0),
            &Vector::<2>::new(-1.0, 0.0),
        );
        assert_eq!(f, z);
    }

    #[test]
    fn rejects_joint_out_of_range() {
        assert!(Wall::<2>::new(2, 0.2, 1.0, 1.0).is_err());
        assert!(Wall::<3>::new(2, 0.2, 1.0, 1.0).is_ok());
    }
}
