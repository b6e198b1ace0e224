//! The closed loop: a [`Control`] at Ts against a [`Plant`], SPEC §11.
//!
//! At every t_k = k·Ts: the plant's state and contact force, one controller
//! step with the trajectory's setpoint at t_k, the plant advanced to t_{k+1}
//! with the applied torque held, and the row recorded.

use crate::control::io::{Command, Control, Measurement};
use crate::error::{check, Error};
use crate::sim::disturb::{Disturbances, Sample, TipPayload, WithFriction};
use crate::sim::environment::Environment;
use crate::sim::inject::Injection;
use crate::sim::metrics::{Metrics, MetricsAccumulator};
use crate::sim::model::Manipulator;
use crate::sim::plant::{Plant, RigidBody};
use crate::sim::record::{Recorder, Row};
use crate::trajectory::{Setpoint, Trajectory};
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
    simulate_with(plant, ctrl, traj, t_final, None, rec)
}

/// [`simulate`] with a fault injected ([`Injection`]): the sensors, the
/// actuators or the control period misbehave during its window. A step the
/// controller refuses does not end the run: its fallback torque is applied
/// (as a real loop would) and the row is marked `refused`. Without an
/// injection a refused step ends the run with its error.
pub fn simulate_with<const N: usize, P, C, T, R>(
    plant: &mut P,
    ctrl: &mut C,
    traj: &T,
    t_final: f64,
    injection: Option<&Injection<N>>,
    rec: &mut R,
) -> Result<u64, Error>
where
    P: Plant<N> + ?Sized,
    C: Control<N> + ?Sized,
    T: Trajectory<N> + ?Sized,
    R: Recorder<N> + ?Sized,
{
    let none = Disturbances::none();
    simulate_disturbed(plant, ctrl, traj, t_final, injection, &none, rec)
}

/// [`simulate_with`] in a disturbed loop (SPEC §17): the loop's own
/// disturbances of `disturbances` act at every step, the plant's (payload,
/// friction) are `plant`'s to have ([`run_disturbed`] builds them in).
///
/// At step k, with t_k = k·Ts on the controller's clock:
///
/// 1. the sensors sample the plant; noise is added and the controller sees
///    the noisy sample of step k − d ([`Disturbances::measure`]), then the
///    injected fault, if any, acts on what it sees;
/// 2. the controller steps with the trajectory at the instant its sample
///    was taken, t_{k−d} (SPEC (17.1); it assumes Ts);
/// 3. the actuators deliver the applied torque (the injected fault, then the
///    fraction ρ: [`Disturbances::actuate`], then the plant's own limits:
///    [`Plant::actuate`]), recorded as `tau_sat`;
/// 4. the plant advances by the true interval h_k = Ts (1 + u_k)
///    ([`Disturbances::interval`]).
///
/// The controller also gets the plant's end-effector wrench
/// ([`Control::step_with_wrench`]) through the same sensor path: delayed
/// with the joint sample, frozen with it by a stale-sensor fault, without
/// noise ([`Disturbances::measure_with_wrench`],
/// [`Injection::measure_wrench`]). Rows carry t_k, the plant's true state,
/// end-effector position and wrench at t_k, the trajectory at t_k, and z1:
/// the controller's reference less the plant's true q at the sample's
/// instant (with noise or delay, not the noisy sample it saw). With
/// [`Disturbances::none`] it is [`simulate_with`], bit for bit. The
/// generators start from the seed at every call: the same arguments give the
/// same rows. Allocation-free itself.
pub fn simulate_disturbed<const N: usize, P, C, T, R>(
    plant: &mut P,
    ctrl: &mut C,
    traj: &T,
    t_final: f64,
    injection: Option<&Injection<N>>,
    disturbances: &Disturbances<N>,
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
    let mut noise = disturbances.new_state();
    let (x0, dx0) = plant.state();
    let mut carried = Carried {
        sensed: (x0, dx0, plant.contact()),
        sensed_wrench: plant.wrench(),
        applied: Vector::<N>::zeros(),
        last: Command::<N>::zeros(),
    };
    for k in 0..steps {
        let t = k as f64 * ts;
        let (x, dx) = plant.state();
        let tau_e = plant.contact();
        let (wrench, x_ee) = (plant.wrench(), plant.end_effector());
        let seen = disturbances.sense(&mut noise, (x, dx, tau_e), wrench);
        carried.sense(t, (seen.sample, seen.wrench), injection);
        let c = traj.sample(t);
        // SPEC (17.1): the setpoint of the instant the sample was taken, as a
        // robot's loop samples its trajectory at the measurement's time stamp.
        let c_seen = if seen.step == k {
            c
        } else {
            traj.sample(seen.step as f64 * ts)
        };
        let refused = carried.control(ctrl, t, &c_seen, injection)?;
        let delivered = injection.map_or(carried.applied, |i| i.actuate(t, &carried.applied));
        let delivered = plant.actuate(&disturbances.actuate(&delivered));
        let h = disturbances.interval(&mut noise, ts);
        let ddx = plant.advance(&delivered, h)?;
        let last = &carried.last;
        rec.record(&Row {
            t,
            x,
            dx,
            ddx,
            xc: c.x,
            dxc: c.dx,
            ddxc: c.ddx,
            xd: last.xd,
            dx_hat: last.v,
            tau: if refused { delivered } else { last.tau },
            tau_sat: delivered,
            dtau: if refused { Vector::zeros() } else { last.dtau },
            tau_e,
            zeta: last.zeta,
            // SPEC (17.1): the tracking error of the plant's true q at the
            // sample's instant, not of the noisy sample the controller saw.
            z1: if refused {
                last.xd - seen.truth
            } else if seen.step == k && seen.sample.0 == seen.truth {
                last.z1
            } else {
                last.z1 + (carried.sensed.0 - seen.truth)
            },
            w_norms: last.w_norms,
            x_ee,
            wrench,
            refused,
        });
    }
    Ok(steps)
}

/// What the loop of [`simulate_disturbed`] carries from one period to the next.
struct Carried<const N: usize> {
    /// The sample the controller was last given (a stale sensor repeats it).
    sensed: Sample<N>,
    /// The wrench it was last given.
    sensed_wrench: [f64; 6],
    /// The torque it last asked for (held while a step is skipped).
    applied: Vector<N>,
    /// Its last accepted command.
    last: Command<N>,
}

impl<const N: usize> Carried<N> {
    /// Step 1, the sensor path: the disturbed sample and wrench `seen`,
    /// through the injected fault if any ([`Injection::measure`],
    /// [`Injection::measure_wrench`]).
    fn sense(&mut self, t: f64, seen: (Sample<N>, [f64; 6]), injection: Option<&Injection<N>>) {
        let (seen, seen_wrench) = seen;
        if let Some(inj) = injection {
            self.sensed = inj.measure(t, seen, self.sensed);
            self.sensed_wrench = inj.measure_wrench(t, seen_wrench, self.sensed_wrench);
        } else {
            self.sensed = seen;
            self.sensed_wrench = seen_wrench;
        }
    }

    /// Step 2, the controller's step on the sensed sample toward `c`:
    /// whether it was refused (skipped by the injected fault, or an error
    /// while a fault is injected; without one, an error is returned). The
    /// torque it asks for is `applied` even when it refuses.
    fn control<C: Control<N> + ?Sized>(
        &mut self,
        ctrl: &mut C,
        t: f64,
        c: &Setpoint<N>,
        injection: Option<&Injection<N>>,
    ) -> Result<bool, Error> {
        if injection.is_some_and(|i| i.skips(t)) {
            return Ok(true);
        }
        let m = Measurement {
            x: self.sensed.0,
            dx: Some(self.sensed.1),
            tau_e: self.sensed.2,
        };
        let (tau, result) = ctrl.step_with_wrench(&m, &self.sensed_wrench, c);
        self.applied = tau;
        match result {
            Ok(cmd) => {
                self.last = cmd;
                Ok(false)
            }
            Err(e) if injection.is_none() => Err(e),
            Err(_) => Ok(true),
        }
    }
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
    check::nonnegative("settle ≥ 0", "settle", cfg.settle)?;
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

/// [`run`] with the disturbances a real robot has (SPEC §17): the arm of
/// the plant carries `disturbances`' payload and joint friction, and the
/// loop has its sensor noise, measurement delay, sampling jitter and weak
/// actuators ([`simulate_disturbed`]). The controller is told none of them.
/// With [`Disturbances::none`] it is [`run`], bit for bit. The entry point
/// of the bindings: with a `schema::Scenario` `s` (for the 2-link arm),
/// `run_disturbed(&s.arm()?, &wall, ctrl, &traj, &s.sim, &s.disturbances()?, rec)`.
/// Allocation-free itself.
pub fn run_disturbed<const N: usize, M, E, C, T, R>(
    arm: &M,
    env: &E,
    ctrl: &mut C,
    traj: &T,
    cfg: &SimConfig<N>,
    disturbances: &Disturbances<N>,
    rec: &mut R,
) -> Result<Metrics<N>, Error>
where
    M: TipPayload<N> + Clone,
    E: Environment<N> + Clone,
    C: Control<N> + ?Sized,
    T: Trajectory<N> + ?Sized,
    R: Recorder<N> + ?Sized,
{
    run_disturbed_with(arm, env, ctrl, traj, cfg, disturbances, None, &mut (), rec)
}

/// [`run_disturbed`] with a fault injected (`injection`, as
/// [`simulate_with`]: a refused step applies the fallback and the run goes
/// on) and the plant seen through `adapter` (e.g. one that checks for a stop
/// request after every period: [`Adapter`]). With `None` and `()` it is
/// [`run_disturbed`], bit for bit.
#[allow(clippy::too_many_arguments)]
pub fn run_disturbed_with<const N: usize, M, E, C, T, A, R>(
    arm: &M,
    env: &E,
    ctrl: &mut C,
    traj: &T,
    cfg: &SimConfig<N>,
    disturbances: &Disturbances<N>,
    injection: Option<&Injection<N>>,
    adapter: &mut A,
    rec: &mut R,
) -> Result<Metrics<N>, Error>
where
    M: TipPayload<N> + Clone,
    E: Environment<N> + Clone,
    C: Control<N> + ?Sized,
    T: Trajectory<N> + ?Sized,
    A: Adapter<N> + ?Sized,
    R: Recorder<N> + ?Sized,
{
    check::nonnegative("settle ≥ 0", "settle", cfg.settle)?;
    let arm = WithFriction::new(
        arm.with_payload(disturbances.payload())?,
        *disturbances.friction(),
    );
    let mut plant = RigidBody::new(arm, env.clone(), cfg.q0, cfg.dq0, cfg.substeps)?;
    let mut metrics = MetricsAccumulator::new(cfg.settle, *ctrl.target());
    simulate_disturbed(
        &mut Adapted::new(&mut plant, adapter),
        ctrl,
        traj,
        cfg.t_final,
        injection,
        disturbances,
        &mut (&mut metrics, rec),
    )?;
    Ok(metrics.finish())
}

/// What a closed loop's caller adds to a plant without changing it: a hook
/// around every [`Plant::advance`] (a stop request, progress, a watchdog).
/// `()` adds nothing.
pub trait Adapter<const N: usize> {
    /// Advance `plant` by `h` (s) with `tau` (N m) held: by default exactly
    /// `plant.advance(tau, h)`. An error ends the run.
    fn advance<P: Plant<N> + ?Sized>(
        &mut self,
        plant: &mut P,
        tau: &Vector<N>,
        h: f64,
    ) -> Result<Vector<N>, Error> {
        plant.advance(tau, h)
    }
}

impl<const N: usize> Adapter<N> for () {}

/// A plant seen through an [`Adapter`]: everything is the plant's, its
/// advance goes through the adapter.
pub struct Adapted<'a, P: ?Sized, A: ?Sized> {
    plant: &'a mut P,
    adapter: &'a mut A,
}

impl<'a, P: ?Sized, A: ?Sized> Adapted<'a, P, A> {
    /// `plant` through `adapter`.
    pub fn new(plant: &'a mut P, adapter: &'a mut A) -> Self {
        Self { plant, adapter }
    }
}

impl<const N: usize, P: Plant<N> + ?Sized, A: Adapter<N> + ?Sized> Plant<N> for Adapted<'_, P, A> {
    fn state(&self) -> (Vector<N>, Vector<N>) {
        self.plant.state()
    }
    fn contact(&self) -> Vector<N> {
        self.plant.contact()
    }
    fn advance(&mut self, tau: &Vector<N>, h: f64) -> Result<Vector<N>, Error> {
        self.adapter.advance(&mut *self.plant, tau, h)
    }
    fn actuate(&self, tau: &Vector<N>) -> Vector<N> {
        self.plant.actuate(tau)
    }
    fn wrench(&self) -> [f64; 6] {
        self.plant.wrench()
    }
    fn end_effector(&self) -> [f64; 3] {
        self.plant.end_effector()
    }
}

/// [`run`] with a fault injected (feature `alloc`): the rigid-body scenario of
/// `cfg`, `injection` acting in its window, and the figures of
/// [`FaultFigures`](crate::sim::inject::FaultFigures) for actuator limits `tau_max` (N m).
#[cfg(feature = "alloc")]
pub fn run_with_injection<const N: usize, M, E, C, T>(
    arm: &M,
    env: &E,
    ctrl: &mut C,
    traj: &T,
    cfg: &SimConfig<N>,
    injection: &Injection<N>,
    tau_max: &Vector<N>,
) -> Result<crate::sim::inject::FaultFigures, Error>
where
    M: Manipulator<N> + Clone,
    E: Environment<N> + Clone,
    C: Control<N> + ?Sized,
    T: Trajectory<N> + ?Sized,
{
    struct Report<'a, const N: usize>(crate::sim::inject::FaultReport, &'a Vector<N>);
    impl<const N: usize> Recorder<N> for Report<'_, N> {
        fn record(&mut self, row: &Row<N>) {
            self.0.push(row, self.1);
        }
    }
    let mut plant = RigidBody::new(arm.clone(), env.clone(), cfg.q0, cfg.dq0, cfg.substeps)?;
    let ts = ctrl.period();
    let mut report = Report(crate::sim::inject::FaultReport::default(), tau_max);
    simulate_with(
        &mut plant,
        ctrl,
        traj,
        cfg.t_final,
        Some(injection),
        &mut report,
    )?;
    Ok(report.0.finish(injection, ts))
}
