//! The closed loop for n joints known at run time (SPEC §11, §13.1, §17):
//! a [`Plant`] of n joints (the core's rigid bodies, [`RigidBody`]; a
//! physics engine of the caller's), a controller ([`Controlled`]: the
//! core's joint controllers, or one of the caller's over slices) along a
//! [`Reference`], or the Cartesian controller along pose targets
//! ([`simulate_cartesian`]). The loop body is the core's one,
//! [`simulate_disturbed`]: the same disturbances, faults and row semantics;
//! the rows go to the caller's [`Rows`] (kept also when a run ends with an
//! error), the SPEC §12 metrics are returned ([`Metrics`]).
//!
//! The loop itself allocates nothing: [`Rows`] are sized before the run
//! ([`Rows::new`]).

mod cartesian;
mod plant;
mod replay;
mod rows;
mod spec;

pub use cartesian::{
    cartesian_steps, drive_cartesian, reads_the_wrench, simulate_cartesian, CartesianDriver,
    CartesianLoop, LoopJoint,
};
pub use plant::{Arm, Disturbances, Injected, Injection, Jacobian3, Plant, RigidBody};
pub use replay::Replay;
pub use rows::{
    kept_rows, metrics_of, Metrics, Recorded, RowMetrics, Rows, TaskRows, TaskStep, TypedTaskStep,
};
pub use spec::{run, Loop, Output, Spec};

use super::cartesian::Joint;

use super::values::{length, mismatch, too_many, Command, Joints, Measurement, Setpoint};
use crate::cartesian as core_cartesian;
use crate::control::impedance::TargetImpedance;
use crate::control::io::{self, WrenchControl};
use crate::error::{check, Error};
use crate::sim::disturb;
use crate::sim::metrics::MetricsAccumulator;
use crate::sim::plant as core_plant;
use crate::sim::record::Recorder;
use crate::sim::simulator::{self, simulate_disturbed, Adapted, Adapter};
use crate::trajectory::{self, Continued, Tabulated, Trajectory};
use crate::types::Vector;
use alloc::vec::Vec;
use plant::Typed;

/// How a run goes: its length, what it records, what disturbs it.
#[derive(Copy, Clone, Debug)]
pub struct Run<'a> {
    /// Duration T (s): rows k = 0 … round(T/Ts) − 1.
    pub t_final: f64,
    /// Start of the metrics' "after" window (s), ≥ 0.
    pub settle: f64,
    /// Keep every `every`-th row (the metrics see every one).
    pub every: u64,
    /// The disturbances (none: the undisturbed loop).
    pub disturbances: Option<&'a Disturbances>,
    /// A fault to inject: a refused step then applies the fallback and the
    /// run goes on (without one, a refused step ends the run).
    pub injection: Option<&'a Injection>,
}

/// A joint reference tabulated at t_k = k·Ts: K rows of n values each for
/// xc, ẋc, ẍc (rad, rad/s, rad/s²), row-major; row k is the setpoint of
/// step k (beyond the last row: NaN).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Table<'a> {
    n: usize,
    x: &'a [f64],
    dx: &'a [f64],
    ddx: &'a [f64],
}

impl<'a> Table<'a> {
    /// The table of `x`, `dx`, `ddx` (K × n each, row-major).
    pub fn new(n: usize, x: &'a [f64], dx: &'a [f64], ddx: &'a [f64]) -> Result<Self, Error> {
        if n == 0 || !x.len().is_multiple_of(n) || dx.len() != x.len() || ddx.len() != x.len() {
            return Err(Error::Invalid {
                what: "reference",
                reason: "needs K rows of n values for each of xc, dxc, ddxc",
            });
        }
        Ok(Self { n, x, dx, ddx })
    }

    /// The number of rows K.
    pub fn rows(&self) -> usize {
        self.x.len() / self.n
    }

    /// The table as the trajectory the loop samples, at period `ts` (s).
    fn trajectory<const N: usize>(&self, ts: f64) -> Tabulated<'a, N> {
        Tabulated {
            rows: [self.x, self.dx, self.ddx],
            ts,
        }
    }

    /// Row k.
    pub fn row(&self, k: usize) -> Option<Setpoint<&'a [f64]>> {
        let r = k * self.n..(k + 1) * self.n;
        Some(Setpoint {
            x: self.x.get(r.clone())?,
            dx: self.dx.get(r.clone())?,
            ddx: self.ddx.get(r)?,
        })
    }
}

/// The joint reference a run follows.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Reference<'a> {
    /// The adaptive controller's own trajectory, from its clock on (a used
    /// controller goes on where it was).
    Trajectory,
    /// A table of one row per step.
    Table(Table<'a>),
}

/// The run's hook: asked every 64 periods and after the last whether to go
/// on (signals), and told the progress. `()` always goes on.
pub trait Hooks {
    /// `done` of `total` periods are taken; false stops the run.
    fn tick(&mut self, done: u64, total: u64) -> bool;
}

impl Hooks for () {
    fn tick(&mut self, _done: u64, _total: u64) -> bool {
        true
    }
}

/// Periods between two calls of [`Hooks::tick`].
pub const HOOK_EVERY: u64 = 64;

/// How a run ended when it did not finish.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum RunError {
    /// The core's error, at period `k` when the run had started (a plant
    /// that failed: ask it why).
    Core(Error, Option<u64>),
    /// The hook asked to stop.
    Stopped,
    /// The rows of this many periods did not fit in memory.
    Memory(usize),
}

impl From<Error> for RunError {
    fn from(e: Error) -> Self {
        RunError::Core(e, None)
    }
}

impl core::fmt::Display for RunError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            RunError::Core(e, Some(k)) => write!(f, "at period {k}: {e}"),
            RunError::Core(e, None) => write!(f, "{e}"),
            RunError::Stopped => f.write_str("the run was stopped"),
            RunError::Memory(rows) => write!(f, "cannot allocate the rows of {rows} periods"),
        }
    }
}

impl core::error::Error for RunError {}

/// The adapter that asks the hook every [`HOOK_EVERY`] periods.
struct Watch<'a> {
    hooks: &'a mut dyn Hooks,
    done: u64,
    total: u64,
    stopped: bool,
}

impl Watch<'_> {
    fn error(&self, e: Error) -> RunError {
        if self.stopped {
            RunError::Stopped
        } else {
            RunError::Core(e, Some(self.done))
        }
    }
}

impl<const N: usize> Adapter<N> for Watch<'_> {
    fn advance<P: core_plant::Plant<N> + ?Sized>(
        &mut self,
        plant: &mut P,
        tau: &Vector<N>,
        h: f64,
    ) -> Result<Vector<N>, Error> {
        let a = plant.advance(tau, h)?;
        self.done += 1;
        let due = self.done.is_multiple_of(HOOK_EVERY) || self.done == self.total;
        if due && !self.hooks.tick(self.done, self.total) {
            self.stopped = true;
            return Err(Error::Invalid {
                what: "run",
                reason: "stopped",
            });
        }
        Ok(a)
    }
}

// ---------------------------------------------------------------------------
// The controllers the loop steps.
// ---------------------------------------------------------------------------

/// A controller of the caller's, n joints, over slices: the run-time
/// [`WrenchControl`](crate::WrenchControl) (a controller written in another
/// language, handed the whole measurement).
pub trait Control {
    /// The number of joints n.
    fn n(&self) -> usize;
    /// Sampling period Ts (s).
    fn period(&self) -> f64;
    /// The target impedance Dd, Cd, Gd (n values each) it realises, for
    /// the metrics' impedance residual.
    fn target(&self) -> [Joints; 3];
    /// One step with the measurement `m`, the measured wrench F_e (N, N m,
    /// world frame) and the row's setpoint `c`: the torque to apply
    /// whatever happened (its fallback on an error), and the command.
    fn step(
        &mut self,
        m: &Measurement<'_>,
        wrench: &[f64; 6],
        c: &Setpoint<&[f64]>,
    ) -> (Joints, Result<Command, Error>);
}

/// What the loop steps.
#[derive(Debug)]
pub enum Controlled<'a, S = Vec<f64>> {
    /// A joint controller of the core.
    Joint(Joint<'a, S>),
    /// A controller of the caller's.
    Own(&'a mut dyn Control),
}

impl core::fmt::Debug for dyn Control + '_ {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "Control(n = {})", self.n())
    }
}

/// Computed torque as the loop's controller: its step on the row's
/// setpoint, the torque it holds on a refusal; no weights (NaN norms).
struct ComputedLoop<'a, const N: usize> {
    ctrl: &'a core_cartesian::ComputedTorque<N>,
    state: &'a mut core_cartesian::ComputedState<N>,
}

impl<const N: usize> io::Control<N> for ComputedLoop<'_, N> {
    fn period(&self) -> f64 {
        self.ctrl.period()
    }
    fn target(&self) -> &TargetImpedance<N> {
        self.ctrl.impedance()
    }
    fn step(
        &mut self,
        m: &io::Measurement<N>,
        c: &trajectory::Setpoint<N>,
    ) -> Result<io::Command<N>, Error> {
        let cmd = self.ctrl.step(self.state, m, c)?;
        Ok(io::Command {
            w_norms: [f64::NAN; 3],
            ..cmd
        })
    }
    fn step_or_fallback(
        &mut self,
        m: &io::Measurement<N>,
        c: &trajectory::Setpoint<N>,
    ) -> (Vector<N>, Result<io::Command<N>, Error>) {
        match io::Control::step(self, m, c) {
            Ok(cmd) => (cmd.tau_sat, Ok(cmd)),
            Err(e) => (self.state.applied, Err(e)),
        }
    }
}

/// A controller of the caller's as the core's [`WrenchControl`].
struct OwnLoop<'a, const N: usize> {
    ctrl: &'a mut dyn Control,
    target: TargetImpedance<N>,
}

impl<const N: usize> WrenchControl<N> for OwnLoop<'_, N> {
    fn period(&self) -> f64 {
        self.ctrl.period()
    }
    fn target(&self) -> &TargetImpedance<N> {
        &self.target
    }
    fn step_with_wrench(
        &mut self,
        m: &io::Measurement<N>,
        wrench: &[f64; 6],
        c: &trajectory::Setpoint<N>,
    ) -> (Vector<N>, Result<io::Command<N>, Error>) {
        let dx = m.dx.as_ref().map(|d| d.as_slice());
        let meas = Measurement {
            x: m.x.as_slice(),
            dx,
            tau_e: m.tau_e.as_slice(),
        };
        let sp = Setpoint {
            x: c.x.as_slice(),
            dx: c.dx.as_slice(),
            ddx: c.ddx.as_slice(),
        };
        let (tau, result) = self.ctrl.step(&meas, wrench, &sp);
        if tau.len() != N {
            return (Vector::zeros(), Err(length("the controller's torque")));
        }
        let result = result.and_then(|cmd| {
            if cmd.tau_sat.len() == N {
                Ok(cmd.vector::<N>())
            } else {
                Err(length("the controller's command"))
            }
        });
        (tau.vector(), result)
    }
}

/// The loop of the core, its errors mapped: `ctrl` along `traj` on `plant`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn drive<const N: usize, C, T, R>(
    plant: &mut dyn Plant,
    ctrl: &mut C,
    traj: &T,
    dist: Option<&disturb::Disturbances<N>>,
    run: &Run<'_>,
    hooks: &mut dyn Hooks,
    rec: &mut R,
) -> Result<(), RunError>
where
    C: io::Control<N> + ?Sized,
    T: Trajectory<N> + ?Sized,
    R: Recorder<N> + ?Sized,
{
    let ts = ctrl.period();
    let total = simulator::steps(run.t_final, ts)?;
    check::nonnegative("settle ≥ 0", "settle", run.settle)?;
    let none = disturb::Disturbances::<N>::none();
    let dist = dist.unwrap_or(&none);
    let inj = run.injection.map(Injection::typed::<N>).transpose()?;
    let mut watch = Watch {
        hooks,
        done: 0,
        total,
        stopped: false,
    };
    let mut typed = Typed::<N>(plant);
    let mut seen = Adapted::new(&mut typed, &mut watch);
    let result = simulate_disturbed(&mut seen, ctrl, traj, run.t_final, inj.as_ref(), dist, rec);
    result.map(|_| ()).map_err(|e| watch.error(e))
}

/// The table of a run: one row per step, checked before it starts.
fn table<const N: usize>(t: &Table<'_>, run: &Run<'_>, ts: f64) -> Result<(), Error> {
    let total = simulator::steps(run.t_final, ts)?;
    if t.n != N || (t.rows() as u64) < total {
        return Err(Error::Invalid {
            what: "reference",
            reason: "needs one row of n values per step",
        });
    }
    Ok(())
}

/// The closed loop of SPEC §11 for n joints: `ctrl` on `plant` along
/// `reference` for `run`, every kept row into `rows` (also those before an
/// error), the SPEC §12 metrics returned (of the controller's target
/// impedance). The core's loop ([`simulate_disturbed`]) with the same
/// values, bit for bit; from the controllers' current states (not reset:
/// a used controller goes on). [`Reference::Trajectory`] is the adaptive
/// controller's own; computed torque and a controller of the caller's
/// need a [`Table`].
pub fn simulate<S: AsRef<[f64]> + AsMut<[f64]>>(
    plant: &mut dyn Plant,
    ctrl: Controlled<'_, S>,
    reference: Reference<'_>,
    run: &Run<'_>,
    hooks: &mut dyn Hooks,
    rows: &mut Rows,
) -> Result<Metrics, RunError> {
    let n = match &ctrl {
        Controlled::Joint(j) => j.n(),
        Controlled::Own(c) => c.n(),
    };
    if plant.n() != n {
        return Err(mismatch("plant").into());
    }
    if rows.n() != n {
        return Err(mismatch("rows").into());
    }
    crate::with_joints!(n, N => {
        let dist = match run.disturbances {
            Some(d) => Some(d.inner.get::<N>().ok_or(mismatch("disturbances"))?),
            None => None,
        };
        let on = On { plant, dist, run, hooks, rows };
        match ctrl {
            Controlled::Joint(Joint::Adaptive(c, s)) => {
                let c = c.inner.get::<N>().ok_or(mismatch("controller"))?;
                let s = s.inner.get_mut::<N>().ok_or(mismatch("state"))?;
                adaptive(c, s, reference, on)
            }
            Controlled::Joint(Joint::Computed(c, s)) => {
                let c = c.inner.get::<N>().ok_or(mismatch("controller"))?;
                let s = s.inner.get_mut::<N>().ok_or(mismatch("state"))?;
                computed(c, s, reference, on)
            }
            Controlled::Own(c) => own(c, reference, on),
        }
    }, _ => Err(too_many(n).into()))
}

/// What a run of N joints goes on: the plant, its disturbances, the run,
/// the hook and the rows.
pub(crate) struct On<'a, 'b, const N: usize> {
    plant: &'a mut dyn Plant,
    dist: Option<&'a disturb::Disturbances<N>>,
    run: &'a Run<'b>,
    hooks: &'a mut dyn Hooks,
    rows: &'a mut Rows,
}

impl<const N: usize> On<'_, '_, N> {
    /// `ctrl` along `traj`, the metrics of `target`.
    fn go<C, T>(
        self,
        ctrl: &mut C,
        traj: &T,
        target: TargetImpedance<N>,
    ) -> Result<Metrics, RunError>
    where
        C: io::Control<N> + ?Sized,
        T: Trajectory<N> + ?Sized,
    {
        let mut metrics = MetricsAccumulator::new(self.run.settle, target);
        let rec = &mut (&mut metrics, &mut *self.rows);
        drive(self.plant, ctrl, traj, self.dist, self.run, self.hooks, rec)?;
        Ok(Metrics::of(&metrics.finish()))
    }
}

fn adaptive<const N: usize, S: AsRef<[f64]> + AsMut<[f64]>>(
    c: &super::controller::Ctl<N>,
    s: &mut crate::control::state::State<N, S>,
    reference: Reference<'_>,
    on: On<'_, '_, N>,
) -> Result<Metrics, RunError> {
    let ts = c.ctrl.period();
    let target = *c.ctrl.impedance();
    let k0 = s.steps();
    let mut bound = c.ctrl.bind(s);
    match reference {
        Reference::Trajectory => {
            let own = Continued {
                traj: c.traj,
                k0,
                ts,
            };
            on.go(&mut bound, &own, target)
        }
        Reference::Table(t) => {
            table::<N>(&t, on.run, ts)?;
            on.go(&mut bound, &t.trajectory::<N>(ts), target)
        }
    }
}

fn computed<const N: usize>(
    c: &core_cartesian::ComputedTorque<N>,
    s: &mut core_cartesian::ComputedState<N>,
    reference: Reference<'_>,
    on: On<'_, '_, N>,
) -> Result<Metrics, RunError> {
    let Reference::Table(t) = reference else {
        return Err(Error::Invalid {
            what: "reference",
            reason: "computed torque needs its setpoint of every step",
        }
        .into());
    };
    let ts = c.period();
    table::<N>(&t, on.run, ts)?;
    let target = *c.impedance();
    let mut ctrl = ComputedLoop { ctrl: c, state: s };
    on.go(&mut ctrl, &t.trajectory::<N>(ts), target)
}

fn own<const N: usize>(
    c: &mut dyn Control,
    reference: Reference<'_>,
    on: On<'_, '_, N>,
) -> Result<Metrics, RunError> {
    let Reference::Table(t) = reference else {
        return Err(Error::Invalid {
            what: "reference",
            reason: "a controller of the caller's needs the setpoint of every step",
        }
        .into());
    };
    let ts = c.period();
    table::<N>(&t, on.run, ts)?;
    let [dd, cd, gd] = c.target();
    if [&dd, &cd, &gd].iter().any(|v| v.len() != N) {
        return Err(length("target").into());
    }
    let target = TargetImpedance::new(dd.vector(), cd.vector(), gd.vector())?;
    let mut ctrl = OwnLoop::<N> { ctrl: c, target };
    on.go(&mut ctrl, &t.trajectory::<N>(ts), target)
}
