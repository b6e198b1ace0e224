//! The closed loop: a [`Control`] at Ts against a [`Plant`], SPEC §11.
//!
//! At every t_k = k·Ts: the plant's state and contact force, one controller
//! step with the trajectory's setpoint at t_k, the plant advanced to t_{k+1}
//! with the applied torque held, and the row recorded.

use crate::environment::Environment;
use crate::error::{check, Error};
use crate::io::{Control, Measurement};
use crate::metrics::{Metrics, MetricsAccumulator};
use crate::model::Manipulator;
use crate::plant::{Plant, RigidBody};
use crate::record::{Recorder, Row};
use crate::trajectory::Trajectory;
use crate::types::Vector;

/// Run settings (SPEC §11) of the rigid-body scenarios.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct SimConfig<const N: usize> {
    /// Duration T (s); rows k = 0 … round(T/Ts) − 1.
    pub t_final: f64,
    /// RK4 substeps M per controller period (≥ 1). SPEC default 10; paper scenario 1.
    pub substeps: usize,
    /// Initial joint position q(0) (rad).
    pub q0: Vector<N>,
    /// Initial joint velocity q̇(0) (rad/s).
    pub dq0: Vector<N>,
    /// Start of the "after" window of the metrics (s). SPEC §12: 2.
    pub settle: f64,
}

/// The number of steps of a run of `t_final` (s) at period `ts` (s):
/// round(T/Ts), between 1 and 1e15.
pub fn steps(t_final: f64, ts: f64) -> Result<u64, Error> {
    check::positive("T > 0", "T", t_final)?;
    let steps = libm::round(t_final / ts);
    if !(1.0..=1e15).contains(&steps) {
        return Err(Error::Invalid {
            what: "T / Ts",
            reason: "the run must have between 1 and 1e15 steps",
        });
    }
    Ok(steps as u64)
}

/// Close the loop of `plant` and `ctrl`, tracking `traj`, for `t_final` (s):
/// every row goes to `rec`. Allocation-free itself. Returns the number of
/// rows. Errors on a bad duration, a failed step, or a diverged plant.
pub fn simulate<const N: usize, P, C, T, R>(
    plant: &mut P,
    ctrl: &mut C,
    traj: &T,
    t_final: f64,
    rec: &mut R,
) -> Result<u64, Error>
where
    P: Plant<N> + ?Sized,
    C: Control<N> + ?Sized,
    T: Trajectory<N> + ?Sized,
    R: Recorder<N> + ?Sized,
{
    let ts = ctrl.period();
    let steps = steps(t_final, ts)?;
    for k in 0..steps {
        let t = k as f64 * ts;
        let (x, dx) = plant.state();
        let tau_e = plant.contact();
        let c = traj.sample(t);
        let cmd = ctrl.step(
            &Measurement {
                x,
                dx: Some(dx),
                tau_e,
            },
            &c,
        )?;
        let ddx = plant.advance(&cmd.tau_sat, ts)?;
        rec.record(&Row {
            t,
            x,
            dx,
            ddx,
            xc: c.x,
            dxc: c.dx,
            ddxc: c.ddx,
            xd: cmd.xd,
            dx_hat: cmd.v,
            tau: cmd.tau,
            tau_sat: cmd.tau_sat,
            dtau: cmd.dtau,
            tau_e,
            zeta: cmd.zeta,
            z1: cmd.z1,
            w_norms: cmd.w_norms,
        });
    }
    Ok(steps)
}

/// The rigid-body scenario of SPEC §11 in one call: `arm` against `env` from
/// `cfg`'s initial state, integrated with `cfg.substeps` RK4 steps per period,
/// `ctrl` tracking `traj` for `cfg.t_final`. Every row goes to `rec`; returns
/// the SPEC §12 metrics. Allocation-free itself.
pub fn run<const N: usize, M, E, C, T, R>(
    arm: &M,
    env: &E,
    ctrl: &mut C,
    traj: &T,
    cfg: &SimConfig<N>,
    rec: &mut R,
) -> Result<Metrics<N>, Error>
where
    M: Manipulator<N> + Clone,
    E: Environment<N> + Clone,
    C: Control<N> + ?Sized,
    T: Trajectory<N> + ?Sized,
    R: Recorder<N> + ?Sized,
{
    check::finite("settle", cfg.settle)?;
    let mut plant = RigidBody::new(arm.clone(), env.clone(), cfg.q0, cfg.dq0, cfg.substeps)?;
    let mut metrics = MetricsAccumulator::new(cfg.settle, *ctrl.target());
    simulate(
        &mut plant,
        ctrl,
        traj,
        cfg.t_final,
        &mut (&mut metrics, rec),
    )?;
    Ok(metrics.finish())
}
