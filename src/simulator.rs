//! The closed loop: controller at Ts, plant integrated by RK4, SPEC §11.
//!
//! At every t_k = k·Ts: τe_k from the environment at the plant state, one
//! controller step, the row recorded, then the plant integrated from t_k to
//! t_{k+1} with the applied torque held, in `substeps` classical RK4 steps,
//! recomputing τe from the plant state at every stage.

use crate::controller::{Controller, Measurement};
use crate::environment::Environment;
use crate::error::{check, Error};
use crate::metrics::{Metrics, MetricsAccumulator};
use crate::model::Manipulator;
use crate::trajectory::Trajectory;
use crate::Vector;

/// Run settings (SPEC §11).
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

impl SimConfig<2> {
    /// The paper scenario: T = 20 s, M = 1, q(0) = [0.25, −0.05], q̇(0) = 0 (SPEC §11, (65)).
    pub fn paper() -> Self {
        Self {
            t_final: 20.0,
            substeps: 1,
            q0: Vector::<2>::new(0.25, -0.05),
            dq0: Vector::zeros(),
            settle: 2.0,
        }
    }
}

impl SimConfig<2> {
    /// The "robot" scenario's run: the paper scenario with M = 10 RK4 substeps
    /// per 1 ms period (SPEC §13). Use with [`Config::robot`](crate::Config::robot).
    pub fn robot() -> Self {
        Self {
            substeps: 10,
            ..Self::paper()
        }
    }
}

/// One recorded row at t_k (units as in [`Command`](crate::Command)).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Row<const N: usize> {
    /// t_k (s).
    pub t: f64,
    /// Plant position x_k (rad).
    pub x: Vector<N>,
    /// Plant velocity ẋ_k (rad/s).
    pub dx: Vector<N>,
    /// Commanded position xc (rad).
    pub xc: Vector<N>,
    /// Compliant reference xd (rad).
    pub xd: Vector<N>,
    /// Velocity the controller used (rad/s): the observer's estimate for output feedback.
    pub dx_hat: Vector<N>,
    /// Commanded torque τ (N m).
    pub tau: Vector<N>,
    /// Applied torque sat(τ) (N m).
    pub tau_sat: Vector<N>,
    /// Δτ (N m).
    pub dtau: Vector<N>,
    /// Contact force τe (N m).
    pub tau_e: Vector<N>,
    /// Auxiliary state ζ (N m).
    pub zeta: Vector<N>,
    /// Tracking error z1 = xd − x (rad).
    pub z1: Vector<N>,
    /// ‖ŴD‖_F, ‖ŴC‖_F, ‖ŴG‖_F before the step's update.
    pub w_norms: [f64; 3],
}

/// Receives every row of a simulation. `()` discards them.
pub trait Recorder<const N: usize> {
    /// Called once per row, in order.
    fn record(&mut self, row: &Row<N>);
}

impl<const N: usize> Recorder<N> for () {
    fn record(&mut self, _row: &Row<N>) {}
}

/// Every row of a run, in memory (needs `std`).
#[cfg(feature = "std")]
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace<const N: usize> {
    /// The rows, k = 0 … K − 1.
    pub rows: Vec<Row<N>>,
}

#[cfg(feature = "std")]
impl<const N: usize> Recorder<N> for Trace<N> {
    fn record(&mut self, row: &Row<N>) {
        self.rows.push(*row);
    }
}

/// One classical RK4 step of the plant from time `t` (s) over `h` (s), with the
/// applied torque `tau` (N m) held and τe recomputed from the environment at
/// every stage. `(x, dx)` is the state (rad, rad/s) at `t` and `a` its
/// acceleration there (rad/s², as `forward_dynamics` gives it with τe at that
/// state), which the caller often has already. Returns the state at `t + h`.
#[inline(always)]
pub fn rk4_step<const N: usize, M, E>(
    plant: &M,
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
        plant.forward_dynamics(x, dx, tau, &env.force(ts, x, dx))
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

/// Simulate the closed loop of `plant`, `env` and `ctrl` (reset first) and
/// return the SPEC §12 metrics; every row goes to `rec`. Allocation-free
/// itself. Errors on an invalid `cfg`, or if the plant state becomes non-finite.
pub fn simulate<const N: usize, const L: usize, M, E, T, R>(
    plant: &M,
    env: &E,
    ctrl: &mut Controller<N, L, T>,
    cfg: &SimConfig<N>,
    rec: &mut R,
) -> Result<Metrics<N>, Error>
where
    M: Manipulator<N>,
    E: Environment<N>,
    T: Trajectory<N>,
    R: Recorder<N> + ?Sized,
{
    check::positive("T > 0", "T", cfg.t_final)?;
    if cfg.substeps == 0 {
        return Err(Error::Condition {
            condition: "substeps ≥ 1",
            lhs: "substeps",
            index: None,
            value: 0.0,
        });
    }
    check::finite_slice("q0", cfg.q0.as_slice())?;
    check::finite_slice("dq0", cfg.dq0.as_slice())?;
    check::finite("settle", cfg.settle)?;
    let ts = ctrl.config().ts;
    let steps = libm::round(cfg.t_final / ts);
    if !(1.0..=1e15).contains(&steps) {
        return Err(Error::Invalid {
            what: "T / Ts",
            reason: "the run must have between 1 and 1e15 steps",
        });
    }
    let steps = steps as u64;
    ctrl.reset();
    let imp = *ctrl.impedance();
    let mut acc = MetricsAccumulator::new(cfg.settle);
    let (mut x, mut dx) = (cfg.q0, cfg.dq0);
    let h = ts / cfg.substeps as f64;
    for k in 0..steps {
        let t = k as f64 * ts;
        let tau_e = env.force(t, &x, &dx);
        // The controller's own trajectory at its own clock (t_k = k·Ts), sampled
        // once for the step and the impedance residual.
        let c = ctrl.trajectory().sample(t);
        let cmd = ctrl.step_with(
            &Measurement {
                x,
                dx: Some(dx),
                tau_e,
            },
            &c,
        )?;
        // The plant's acceleration at the row: for the impedance residual, and
        // the first RK4 stage of the first substep.
        let a0 = plant.forward_dynamics(&x, &dx, &cmd.tau_sat, &tau_e);
        let row = Row {
            t,
            x,
            dx,
            xc: cmd.xc,
            xd: cmd.xd,
            dx_hat: cmd.v,
            tau: cmd.tau,
            tau_sat: cmd.tau_sat,
            dtau: cmd.dtau,
            tau_e,
            zeta: cmd.zeta,
            z1: cmd.z1,
            w_norms: cmd.w_norms,
        };
        acc.push(&row, &imp.residual(&c, &x, &dx, &a0, &tau_e));
        rec.record(&row);

        for m in 0..cfg.substeps {
            let t0 = t + m as f64 * h;
            let a = if m == 0 {
                a0
            } else {
                plant.forward_dynamics(&x, &dx, &cmd.tau_sat, &env.force(t0, &x, &dx))
            };
            (x, dx) = rk4_step(plant, env, t0, h, &cmd.tau_sat, (x, dx), &a);
        }
        if x.iter().chain(dx.iter()).any(|v| !v.is_finite()) {
            return Err(Error::Diverged {
                what: "plant state",
            });
        }
    }
    Ok(acc.finish())
}
