//! The plant a closed loop controls: a [`Plant`] trait (its state, the contact
//! force it measures, advance by h under a torque), and [`RigidBody`], the
//! rigid-body arm against an environment integrated by classical RK4 (SPEC §11).
//! A physics engine that advances itself implements the same trait.

use crate::error::{check, Error};
use crate::sim::environment::Environment;
use crate::sim::model::Manipulator;
use crate::types::Vector;

/// A plant with `N` actuated joints.
pub trait Plant<const N: usize> {
    /// Joint position x (rad) and velocity ẋ (rad/s) now.
    fn state(&self) -> (Vector<N>, Vector<N>);
    /// The force the robot exerts on the environment τe (N m), as a force
    /// sensor measures it now.
    fn contact(&self) -> Vector<N>;
    /// Advance by `h` (s) with the applied torque `tau` (N m) held. Returns
    /// the acceleration ẍ (rad/s²) at the start of the interval (for the
    /// impedance residual, SPEC §12). Errors if the state becomes non-finite
    /// (or, for [`RigidBody`], leaves the ceilings of SPEC §14).
    fn advance(&mut self, tau: &Vector<N>, h: f64) -> Result<Vector<N>, Error>;
    /// The torque (N m) the actuators deliver for the command `tau`: the
    /// plant's own limits (a physics engine's actuator range). The loop
    /// records it as the applied torque and advances with it. Default: `tau`
    /// itself (the rigid-body plants have no limits of their own).
    fn actuate(&self, tau: &Vector<N>) -> Vector<N> {
        *tau
    }
    /// The wrench F_e = [f; m] the end effector exerts on the environment
    /// now, force (N) and moment (N m) in the world frame, as a force/torque
    /// sensor measures it (τe = Jᵀ F_e). Default: zeros (a plant that
    /// measures no Cartesian quantity: the joint-space rigid bodies, whose
    /// contact is τe; zeros rather than NaN keep rows comparable).
    fn wrench(&self) -> [f64; 6] {
        [0.0; 6]
    }
    /// The end-effector position (m), world frame, now. Default: zeros (as
    /// [`wrench`](Self::wrench)).
    fn end_effector(&self) -> [f64; 3] {
        [0.0; 3]
    }
}

/// One classical RK4 step of the arm from time `t` (s) over `h` (s), with the
/// applied torque `tau` (N m) held and τe recomputed from the environment at
/// every stage. `(x, dx)` is the state (rad, rad/s) at `t` and `a` its
/// acceleration there (rad/s², as `forward_dynamics` gives it with τe at that
/// state), which the caller often has already. Returns the state at `t + h`.
#[inline(always)]
pub fn rk4_step<const N: usize, M, E>(
    arm: &M,
    env: &E,
    t: f64,
    h: f64,
    tau: &Vector<N>,
    (x, dx): (Vector<N>, Vector<N>),
    a: &Vector<N>,
) -> (Vector<N>, Vector<N>)
where
    M: Manipulator<N> + ?Sized,
    E: Environment<N> + ?Sized,
{
    let accel = |ts: f64, x: &Vector<N>, dx: &Vector<N>| {
        arm.forward_dynamics(x, dx, tau, &env.force(ts, x, dx))
    };
    let (x2, v2) = (x + 0.5 * h * dx, dx + 0.5 * h * a);
    let k2 = accel(t + 0.5 * h, &x2, &v2);
    let (x3, v3) = (x + 0.5 * h * v2, dx + 0.5 * h * k2);
    let k3 = accel(t + 0.5 * h, &x3, &v3);
    let (x4, v4) = (x + h * v3, dx + h * k3);
    let k4 = accel(t + h, &x4, &v4);
    (
        x + h / 6.0 * (dx + 2.0 * v2 + 2.0 * v3 + v4),
        dx + h / 6.0 * (a + 2.0 * k2 + 2.0 * k3 + k4),
    )
}

/// A rigid-body arm `M` against an environment `E`, integrated with `substeps`
/// classical RK4 steps per [`advance`](Plant::advance), τe recomputed from the
/// state at every stage (SPEC §11).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct RigidBody<const N: usize, M, E> {
    arm: M,
    env: E,
    substeps: usize,
    t: f64,
    x: Vector<N>,
    dx: Vector<N>,
}

impl<const N: usize, M: Manipulator<N>, E: Environment<N>> RigidBody<N, M, E> {
    /// At t = 0 with position `q0` (rad) and velocity `dq0` (rad/s), finite;
    /// 1 ≤ `substeps` ≤ 10 000.
    pub fn new(
        arm: M,
        env: E,
        q0: Vector<N>,
        dq0: Vector<N>,
        substeps: usize,
    ) -> Result<Self, Error> {
        if substeps == 0 || substeps > 10_000 {
            return Err(Error::Condition {
                condition: "1 ≤ substeps ≤ 10 000",
                lhs: "substeps",
                index: None,
                value: substeps as f64,
            });
        }
        check::finite_slice("q0", q0.as_slice())?;
        check::finite_slice("dq0", dq0.as_slice())?;
        Ok(Self {
            arm,
            env,
            substeps,
            t: 0.0,
            x: q0,
            dx: dq0,
        })
    }

    /// The arm.
    pub fn arm(&self) -> &M {
        &self.arm
    }
    /// The environment.
    pub fn environment(&self) -> &E {
        &self.env
    }
    /// Time t (s) of the state.
    pub fn time(&self) -> f64 {
        self.t
    }
}

impl<const N: usize, M: Manipulator<N>, E: Environment<N>> Plant<N> for RigidBody<N, M, E> {
    fn state(&self) -> (Vector<N>, Vector<N>) {
        (self.x, self.dx)
    }

    fn contact(&self) -> Vector<N> {
        self.env.force(self.t, &self.x, &self.dx)
    }

    fn advance(&mut self, tau: &Vector<N>, h: f64) -> Result<Vector<N>, Error> {
        let sub = h / self.substeps as f64;
        let (t, mut x, mut dx) = (self.t, self.x, self.dx);
        // The acceleration at the start: the result, and the first RK4 stage.
        let a0 = self.arm.forward_dynamics(&x, &dx, tau, &self.contact());
        for m in 0..self.substeps {
            let t0 = t + m as f64 * sub;
            let a = if m == 0 {
                a0
            } else {
                let f = self.env.force(t0, &x, &dx);
                self.arm.forward_dynamics(&x, &dx, tau, &f)
            };
            (x, dx) = rk4_step(&self.arm, &self.env, t0, sub, tau, (x, dx), &a);
        }
        if x.iter().chain(dx.iter()).any(|v| !v.is_finite()) {
            return Err(Error::Diverged {
                what: "plant state",
            });
        }
        // Beyond the ceilings no controller step accepts the state: the run
        // has diverged (SPEC §14), say so here rather than as a refused step.
        use crate::control::safety::{CEILING_POSITION, CEILING_VELOCITY};
        check::within("plant state q", x.as_slice(), CEILING_POSITION)?;
        check::within("plant state dq", dx.as_slice(), CEILING_VELOCITY)?;
        (self.t, self.x, self.dx) = (t + h, x, dx);
        Ok(a0)
    }
}
