//! The controller behind a run-time number of joints: [`DynTracker`], an
//! object-safe face of [`Tracker<N, AnyBasis<N>, Sinusoid<N>>`] for every
//! N = 1 … [`MAX_JOINTS`], taking and giving slices, built from the schema's
//! parameter items, and the closed loop over it with decimated records, a
//! signal/progress hook and the SPEC §12 metrics.
//!
//! Nothing here knows Python: the bindings (`mod.rs`) convert arrays to
//! slices and errors to exceptions.

use crate::control::config::Law;
use crate::control::controller::Controller;
use crate::control::io::{Command, Measurement};
use crate::control::tracker::Tracker;
use crate::control::tuning::Rule;
use crate::error::Error;
use crate::networks::network::{Weights, C, D, G};
use crate::networks::rbf::{AnyBasis, Basis, Centers, GRID_MAX_JOINTS};
use crate::schema::{Preset, Scenario, Value};
use crate::sim::disturb::{Disturbances, TipPayload, WithFriction};
use crate::sim::environment::{FreeSpace, Wall};
use crate::sim::metrics::MetricsAccumulator;
use crate::sim::model::{Link, PlanarArm, TwoLinkArm};
use crate::sim::plant::{Plant, RigidBody};
use crate::sim::record::{Recorder, Row};
use crate::sim::simulator::simulate_disturbed;
use crate::trajectory::{Setpoint, Sinusoid, Trajectory};
use crate::types::Vector;
use std::any::Any;
use std::vec::Vec;

/// Joints the bindings are built for: 1 … 7.
pub const MAX_JOINTS: usize = 7;

/// A parameter value, owned (the schema's [`Value`] borrows).
#[derive(Clone, Debug, PartialEq)]
pub enum Owned {
    /// A number.
    Real(f64),
    /// An integer.
    Int(i64),
    /// One number per joint or network.
    Vec(Vec<f64>),
    /// A name.
    Str(String),
    /// None.
    None,
}

impl Owned {
    fn value(&self) -> Value<'_> {
        match self {
            Owned::Real(x) => Value::Real(*x),
            Owned::Int(i) => Value::Int(*i),
            Owned::Vec(v) => Value::Vec(v),
            Owned::Str(s) => Value::Str(s),
            Owned::None => Value::None,
        }
    }
}

/// Parameter items by schema name.
pub type Items = [(String, Owned)];

/// An error of the scenario, with the parameter it came from (if any).
#[derive(Clone, Debug)]
pub struct ParamError {
    /// The parameter's name, when one parameter was at fault.
    pub name: Option<String>,
    /// The core's error.
    pub error: Error,
}

impl From<Error> for ParamError {
    fn from(error: Error) -> Self {
        Self { name: None, error }
    }
}

/// `preset` for `law` with every item applied, for N joints.
pub fn scenario<const N: usize>(
    preset: Preset,
    law: Law,
    items: &Items,
) -> Result<Scenario<N>, ParamError> {
    let mut s = Scenario::<N>::preset(preset, law);
    for (name, v) in items {
        s.set(name, v.value()).map_err(|error| ParamError {
            name: Some(name.clone()),
            error,
        })?;
    }
    Ok(s)
}

/// User RBF centres: L rows of 4n coordinates (x, v, α1, α̇1) and the
/// squared widths η_d² per input dimension (4n).
#[derive(Clone, Debug, PartialEq)]
pub struct CentersSpec {
    /// Row-major, L × 4n.
    pub centers: Vec<f64>,
    /// 4n squared widths, block-major (x, v, α1, α̇1), joint-minor.
    pub widths2: Vec<f64>,
}

/// The arm a run's plant is built from.
#[derive(Clone, Debug, PartialEq)]
pub enum ArmSpec {
    /// The paper's 2-link arm (55)–(63).
    Paper(TwoLinkArm),
    /// A planar arm of n links.
    Planar {
        /// The links, joint 1 first.
        links: Vec<Link>,
        /// Gravity (m/s²).
        g: f64,
    },
}

/// The run-time hook of long calls: asked every few steps whether to go on
/// (signals) and told the progress.
pub trait Hooks {
    /// `done` of `total` steps are taken; false stops the run.
    fn tick(&mut self, done: u64, total: u64) -> bool;
}

/// Every recorded row (every `every`-th step), one flat row-major buffer per
/// quantity; `n` values per row for the per-joint ones, 3 for `w_norms`.
#[derive(Clone, Debug, Default)]
pub struct Records {
    /// Joints.
    pub n: usize,
    /// Keep every `every`-th row (≥ 1).
    pub every: u64,
    seen: u64,
    /// t (s).
    pub t: Vec<f64>,
    /// The per-joint quantities by name, in this order: q, dq, ddq, xc, dxc,
    /// ddxc, xd, dq_hat, tau, tau_sat, tau_e, zeta, z1.
    pub joint: [Vec<f64>; 13],
    /// ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ before the step's update.
    pub w_norms: Vec<f64>,
    /// The rows the controller refused (fallback applied).
    pub refused: Vec<bool>,
}

/// The names of [`Records::joint`], in order.
pub const JOINT_RECORDS: [&str; 13] = [
    "q", "dq", "ddq", "xc", "dxc", "ddxc", "xd", "dq_hat", "tau", "tau_sat", "tau_e", "zeta", "z1",
];

impl Records {
    /// Room for `rows` kept rows of `n` joints; `None` if it cannot be had.
    pub fn with_rows(n: usize, rows: usize, every: u64) -> Option<Self> {
        let mut r = Self {
            n,
            every: every.max(1),
            ..Self::default()
        };
        r.t.try_reserve_exact(rows).ok()?;
        r.refused.try_reserve_exact(rows).ok()?;
        for v in &mut r.joint {
            v.try_reserve_exact(rows.checked_mul(n)?).ok()?;
        }
        r.w_norms.try_reserve_exact(rows.checked_mul(3)?).ok()?;
        Some(r)
    }

    /// Rows kept.
    pub fn rows(&self) -> usize {
        self.t.len()
    }
}

impl<const N: usize> Recorder<N> for Records {
    fn record(&mut self, r: &Row<N>) {
        let keep = self.seen.is_multiple_of(self.every);
        self.seen += 1;
        if !keep {
            return;
        }
        self.t.push(r.t);
        let rows = [
            &r.x, &r.dx, &r.ddx, &r.xc, &r.dxc, &r.ddxc, &r.xd, &r.dx_hat, &r.tau, &r.tau_sat,
            &r.tau_e, &r.zeta, &r.z1,
        ];
        for (v, x) in self.joint.iter_mut().zip(rows) {
            v.extend_from_slice(x.as_slice());
        }
        self.w_norms.extend_from_slice(&r.w_norms);
        self.refused.push(r.refused);
    }
}

/// The SPEC §12 metrics with per-joint values as vectors.
#[derive(Clone, Debug, PartialEq)]
pub struct MetricsOut {
    /// Scalars by name, in SPEC §12 order.
    pub scalars: Vec<(&'static str, f64)>,
    /// Counts by name.
    pub counts: Vec<(&'static str, usize)>,
    /// Per-joint values by name.
    pub joint: Vec<(&'static str, Vec<f64>)>,
}

/// How a run ended when it did not finish.
#[derive(Clone, Debug)]
pub enum RunError {
    /// The core's error (at step `k`, when the run had started).
    Core(Error, Option<u64>),
    /// The hook asked to stop.
    Stopped,
    /// The records did not fit in memory.
    Memory(usize),
}

impl From<Error> for RunError {
    fn from(e: Error) -> Self {
        RunError::Core(e, None)
    }
}

/// A step's inputs as slices of n values.
pub struct Inputs<'a> {
    /// Joint positions (rad).
    pub x: &'a [f64],
    /// Joint velocities (rad/s), if measured.
    pub dx: Option<&'a [f64]>,
    /// Force on the environment (N m).
    pub tau_e: &'a [f64],
    /// An external setpoint (xc, ẋc, ẍc) instead of the trajectory's.
    pub setpoint: Option<[&'a [f64]; 3]>,
}

/// The quantities of the last step, by name.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Last {
    /// τ.
    Tau,
    /// sat(τ).
    TauSat,
    /// Δτ.
    Dtau,
    /// z1.
    Z1,
    /// xc.
    Xc,
    /// xd.
    Xd,
    /// The velocity used.
    V,
}

/// A controller with its trajectory and state, for any N ≤ [`MAX_JOINTS`].
pub trait DynTracker: Send + Sync {
    /// Joints n.
    fn n(&self) -> usize;
    /// RBF nodes L.
    fn nodes(&self) -> usize;
    /// The law.
    fn law(&self) -> Law;
    /// Ts (s).
    fn ts(&self) -> f64;
    /// t_k (s) of the next step.
    fn time(&self) -> f64;
    /// Steps taken.
    fn steps(&self) -> u64;
    /// Back to t = 0.
    fn reset(&mut self);
    /// One step; writes sat(τ) into `out` (n values).
    fn step(&mut self, m: &Inputs<'_>, out: &mut [f64]) -> Result<(), Error>;
    /// One step that always writes a torque to apply into `out`.
    fn step_or_fallback(&mut self, m: &Inputs<'_>, out: &mut [f64]) -> Result<(), Error>;
    /// A quantity of the last step.
    fn last(&self, what: Last) -> &[f64];
    /// ζ now.
    fn zeta(&self) -> &[f64];
    /// The recorded fault: (error, step).
    fn fault(&self) -> Option<(Error, u64)>;
    /// Forget the recorded fault.
    fn clear_fault(&mut self);
    /// The resolved weight bounds.
    fn weight_bound(&self) -> Option<[f64; 3]>;
    /// The weights, row-major over ŴD[k][j], ŴC[k][j], ŴG[k], each over L nodes.
    fn weights(&self) -> Vec<f64>;
    /// Replace the weights (same layout as [`weights`](Self::weights)).
    fn load_weights(&mut self, rows: &[f64]) -> Result<(), Error>;
    /// The whole state as reals ([`State::save`](crate::control::state::State::save)).
    fn snapshot(&self) -> Vec<f64>;
    /// Restore a [`snapshot`](Self::snapshot).
    fn restore(&mut self, data: &[f64]) -> Result<(), Error>;
    /// The per-step learning gain of the explicit-Euler step at the start of
    /// the trajectory, Ts ‖S(Z0)‖² (ΓD ‖ẍc(0)‖² + ΓC ‖ẋc(0)‖² + ΓG) (N m per
    /// rad/s), and min Kp: the Jury condition of `docs/robot.md` is gain < Kp.
    fn learning_gain(&self) -> (f64, f64);
    /// `rows` steps from row-major tables; writes sat(τ) rows into `out`.
    /// Errors name the row.
    fn replay(
        &mut self,
        rows: usize,
        tables: &Tables<'_>,
        out: &mut Vec<f64>,
        hooks: &mut dyn Hooks,
    ) -> Result<(), RunError>;
    /// The closed loop of SPEC §11 against `arm` with the scenario of
    /// `items` (its run and wall parameters), from t = 0 (reset first) with
    /// the initial `weights` (rows as for [`load_weights`](Self::load_weights)).
    fn simulate(
        &mut self,
        arm: &ArmSpec,
        items: &Items,
        weights: Option<&[f64]>,
        every: u64,
        hooks: &mut dyn Hooks,
    ) -> Result<(Records, MetricsOut), RunError>;
    /// As [`Any`], for the typed paths.
    fn as_any_mut(&mut self) -> &mut dyn Any;
}

/// Row-major tables of a replay: K × n each.
pub struct Tables<'a> {
    /// Positions.
    pub x: &'a [f64],
    /// Velocities.
    pub dx: Option<&'a [f64]>,
    /// Forces.
    pub tau_e: &'a [f64],
    /// Setpoints (xc, ẋc, ẍc).
    pub setpoint: Option<[&'a [f64]; 3]>,
}

type Typed<const N: usize> = Tracker<N, AnyBasis<N>, Sinusoid<N>>;

/// Build the controller `law` for n joints from `preset` and `items`, with the
/// paper's grid (n ≤ 3) or `centers`.
pub fn build(
    n: usize,
    preset: Preset,
    law: Law,
    items: &Items,
    centers: Option<&CentersSpec>,
) -> Result<Box<dyn DynTracker>, ParamError> {
    macro_rules! arms {
        ($($k:literal)*) => {
            match n {
                $($k => Ok(Box::new(build_n::<$k>(preset, law, items, centers)?)),)*
                _ => Err(Error::Invalid {
                    what: "n",
                    reason: "the number of joints must be between 1 and 7",
                }
                .into()),
            }
        };
    }
    arms!(1 2 3 4 5 6 7)
}

fn build_n<const N: usize>(
    preset: Preset,
    law: Law,
    items: &Items,
    centers: Option<&CentersSpec>,
) -> Result<Typed<N>, ParamError> {
    let s = scenario::<N>(preset, law, items)?;
    let traj = s.trajectory()?;
    let basis = match centers {
        // Beyond the vertex grid: the rule's default basis, SPEC §18.
        None if N > GRID_MAX_JOINTS => AnyBasis::Centers(Rule::default().default_basis(&traj)?),
        None => AnyBasis::Grid(s.grid()?),
        Some(c) => {
            if c.widths2.len() != 4 * N {
                return Err(Error::Invalid {
                    what: "widths",
                    reason: "need one width per input dimension (4n: x, v, α1, α̇1)",
                }
                .into());
            }
            let w: [Vector<N>; 4] =
                core::array::from_fn(|b| Vector::from_column_slice(&c.widths2[b * N..][..N]));
            AnyBasis::Centers(Centers::new(c.centers.clone(), w)?)
        }
    };
    let ctrl = Controller::for_trajectory(s.config, basis, &traj)?;
    Ok(Tracker::new(ctrl, traj))
}

fn vector<const N: usize>(v: &[f64]) -> Vector<N> {
    Vector::from_column_slice(v)
}

fn measurement<const N: usize>(m: &Inputs<'_>) -> Measurement<N> {
    Measurement {
        x: vector(m.x),
        dx: m.dx.map(vector),
        tau_e: vector(m.tau_e),
    }
}

fn setpoint<const N: usize>(s: [&[f64]; 3]) -> Setpoint<N> {
    Setpoint {
        x: vector(s[0]),
        dx: vector(s[1]),
        ddx: vector(s[2]),
    }
}

fn metrics_out<const N: usize>(m: &crate::sim::metrics::Metrics<N>) -> MetricsOut {
    let v = |x: &Vector<N>| x.as_slice().to_vec();
    MetricsOut {
        scalars: Vec::from([
            ("rms_z1", m.rms_z1),
            ("rms_z1_after2", m.rms_z1_after2),
            ("sat_duty", m.sat_duty),
            ("peak_contact_after2", m.peak_contact_after2),
            ("mean_contact", m.mean_contact),
            ("imp_err_rms_after2", m.imp_err_rms_after2),
        ]),
        counts: Vec::from([("rows", m.rows), ("steps_in_contact", m.steps_in_contact)]),
        joint: Vec::from([
            ("rms_z1_joint_after2", v(&m.rms_z1_joint_after2)),
            ("max_abs_z1_joint_after2", v(&m.max_abs_z1_joint_after2)),
            ("peak_abs_tau", v(&m.peak_abs_tau)),
        ]),
    }
}

/// A plant that asks the hook every [`HOOK_EVERY`] steps whether to go on.
struct Watched<'a, P> {
    plant: P,
    hooks: &'a mut dyn Hooks,
    done: u64,
    total: u64,
    stopped: bool,
}

/// Steps between two calls of [`Hooks::tick`].
const HOOK_EVERY: u64 = 64;

impl<const N: usize, P: Plant<N>> Plant<N> for Watched<'_, P> {
    fn state(&self) -> (Vector<N>, Vector<N>) {
        self.plant.state()
    }
    fn contact(&self) -> Vector<N> {
        self.plant.contact()
    }
    fn advance(&mut self, tau: &Vector<N>, h: f64) -> Result<Vector<N>, Error> {
        let a = self.plant.advance(tau, h)?;
        self.done += 1;
        if self.done.is_multiple_of(HOOK_EVERY) && !self.hooks.tick(self.done, self.total) {
            self.stopped = true;
            return Err(Error::Invalid {
                what: "run",
                reason: "stopped",
            });
        }
        Ok(a)
    }
}

fn run_arm<const N: usize, M: TipPayload<N> + Clone>(
    t: &mut Typed<N>,
    arm: &M,
    s: &Scenario<N>,
    weights: Option<&[f64]>,
    every: u64,
    hooks: &mut dyn Hooks,
) -> Result<(Records, MetricsOut), RunError> {
    let cfg = &s.sim;
    crate::error::check::finite("settle", cfg.settle)?;
    let ts = t.controller().period();
    let total = crate::sim::simulator::steps(cfg.t_final, ts)?;
    let kept = usize::try_from(total.div_ceil(every.max(1))).unwrap_or(usize::MAX);
    let mut rec = Records::with_rows(N, kept, every).ok_or(RunError::Memory(kept))?;
    let mut metrics = MetricsAccumulator::new(cfg.settle, *t.controller().impedance());
    t.reset();
    if let Some(w) = weights {
        DynTracker::load_weights(t, w)?;
    }
    let traj = *t.trajectory();
    // The plant the controller does not know (SPEC §17): payload and friction.
    let dist = s.disturbances()?;
    let arm = WithFriction::new(arm.with_payload(dist.payload())?, *dist.friction());
    let rec2 = &mut (&mut metrics, &mut rec);
    let result = match s.wall {
        Some(w) => {
            let wall = Wall::<N>::new(0, w, s.ke_be[0], s.ke_be[1])?;
            let plant = RigidBody::new(arm, wall, cfg.q0, cfg.dq0, cfg.substeps)?;
            watched(plant, t, &traj, cfg.t_final, total, &dist, rec2, hooks)
        }
        None => {
            let plant = RigidBody::new(arm, FreeSpace, cfg.q0, cfg.dq0, cfg.substeps)?;
            watched(plant, t, &traj, cfg.t_final, total, &dist, rec2, hooks)
        }
    };
    result?;
    Ok((rec, metrics_out(&metrics.finish())))
}

#[allow(clippy::too_many_arguments)]
fn watched<const N: usize, P: Plant<N>>(
    plant: P,
    t: &mut Typed<N>,
    traj: &Sinusoid<N>,
    t_final: f64,
    total: u64,
    dist: &Disturbances<N>,
    rec: &mut impl Recorder<N>,
    hooks: &mut dyn Hooks,
) -> Result<(), RunError> {
    let mut p = Watched {
        plant,
        hooks,
        done: 0,
        total,
        stopped: false,
    };
    match simulate_disturbed(&mut p, t, traj, t_final, None, dist, rec) {
        Ok(_) => Ok(()),
        Err(_) if p.stopped => Err(RunError::Stopped),
        Err(e) => Err(RunError::Core(e, Some(p.done))),
    }
}

impl<const N: usize> DynTracker for Typed<N> {
    fn n(&self) -> usize {
        N
    }
    fn nodes(&self) -> usize {
        self.controller().basis().nodes()
    }
    fn law(&self) -> Law {
        self.controller().config().law
    }
    fn ts(&self) -> f64 {
        self.controller().period()
    }
    fn time(&self) -> f64 {
        Tracker::time(self)
    }
    fn steps(&self) -> u64 {
        self.state().steps()
    }
    fn reset(&mut self) {
        Tracker::reset(self)
    }

    fn step(&mut self, m: &Inputs<'_>, out: &mut [f64]) -> Result<(), Error> {
        let meas = measurement::<N>(m);
        let cmd = match m.setpoint {
            Some(s) => self.step_with(&meas, &setpoint(s))?,
            None => Tracker::step(self, &meas)?,
        };
        out.copy_from_slice(cmd.tau_sat.as_slice());
        Ok(())
    }

    fn step_or_fallback(&mut self, m: &Inputs<'_>, out: &mut [f64]) -> Result<(), Error> {
        let meas = measurement::<N>(m);
        let c = match m.setpoint {
            Some(s) => setpoint(s),
            None => self.trajectory().sample(Tracker::time(self)),
        };
        let (tau, result) = crate::control::io::Control::step_or_fallback(self, &meas, &c);
        out.copy_from_slice(tau.as_slice());
        result.map(|_| ())
    }

    fn last(&self, what: Last) -> &[f64] {
        let c: &Command<N> = self.state().last();
        match what {
            Last::Tau => c.tau.as_slice(),
            Last::TauSat => c.tau_sat.as_slice(),
            Last::Dtau => c.dtau.as_slice(),
            Last::Z1 => c.z1.as_slice(),
            Last::Xc => c.xc.as_slice(),
            Last::Xd => c.xd.as_slice(),
            Last::V => c.v.as_slice(),
        }
    }

    fn zeta(&self) -> &[f64] {
        self.state().zeta().as_slice()
    }

    fn fault(&self) -> Option<(Error, u64)> {
        self.state().fault().map(|f| (f.error, f.step))
    }

    fn clear_fault(&mut self) {
        self.state_mut().clear_fault()
    }

    fn weight_bound(&self) -> Option<[f64; 3]> {
        self.controller().learning().bound()
    }

    fn weights(&self) -> Vec<f64> {
        let w = self.state().weights();
        let mut out = Vec::with_capacity((2 * N * N + N) * self.nodes());
        for net in [D, C, G] {
            for row in w.network(net) {
                out.extend_from_slice(row);
            }
        }
        out
    }

    fn load_weights(&mut self, rows: &[f64]) -> Result<(), Error> {
        let w = Weights::<N>::from_rows(rows, self.nodes())?;
        self.state_mut().load_weights(&w)
    }

    fn snapshot(&self) -> Vec<f64> {
        let st = self.state();
        let mut out = std::vec![0.0; st.snapshot_len()];
        // The buffer has exactly the length save needs.
        let _ = st.save(&mut out);
        out
    }

    fn restore(&mut self, data: &[f64]) -> Result<(), Error> {
        self.state_mut().load(data)
    }

    fn learning_gain(&self) -> (f64, f64) {
        let ctrl = self.controller();
        let cfg = ctrl.config();
        let c = self.trajectory().sample(0.0);
        let mut s = std::vec![0.0; self.nodes()];
        ctrl.basis().eval(&[c.x, c.dx, c.dx, c.ddx], &mut s);
        let s2: f64 = s.iter().map(|x| x * x).sum();
        let [gd, gc, gg] = cfg.gamma;
        let gain = cfg.ts * s2 * (gd * c.ddx.norm_squared() + gc * c.dx.norm_squared() + gg);
        // Per unit inertia scale, SPEC (10.2): joint k's rows learn at Γ d_k
        // against Kp_k (Kp for the paper's d = 1).
        (gain, cfg.kp.component_div(&cfg.inertia).min())
    }

    fn replay(
        &mut self,
        rows: usize,
        t: &Tables<'_>,
        out: &mut Vec<f64>,
        hooks: &mut dyn Hooks,
    ) -> Result<(), RunError> {
        let row = |v: &[f64], k: usize| Vector::<N>::from_column_slice(&v[k * N..(k + 1) * N]);
        for k in 0..rows {
            if k > 0 && (k as u64).is_multiple_of(HOOK_EVERY) && !hooks.tick(k as u64, rows as u64)
            {
                return Err(RunError::Stopped);
            }
            let m = Measurement {
                x: row(t.x, k),
                dx: t.dx.map(|d| row(d, k)),
                tau_e: row(t.tau_e, k),
            };
            let cmd = match t.setpoint {
                Some([x, dx, ddx]) => {
                    let c = Setpoint {
                        x: row(x, k),
                        dx: row(dx, k),
                        ddx: row(ddx, k),
                    };
                    self.step_with(&m, &c)
                }
                None => Tracker::step(self, &m),
            }
            .map_err(|e| RunError::Core(e, Some(k as u64)))?;
            out.extend_from_slice(cmd.tau_sat.as_slice());
        }
        Ok(())
    }

    fn simulate(
        &mut self,
        arm: &ArmSpec,
        items: &Items,
        weights: Option<&[f64]>,
        every: u64,
        hooks: &mut dyn Hooks,
    ) -> Result<(Records, MetricsOut), RunError> {
        let preset = Preset::Paper;
        let s =
            scenario::<N>(preset, self.law(), items).map_err(|e| RunError::Core(e.error, None))?;
        match arm {
            ArmSpec::Paper(two) => {
                let typed = self
                    .as_any_mut()
                    .downcast_mut::<Typed<2>>()
                    .ok_or(RunError::Core(
                        Error::Invalid {
                            what: "arm",
                            reason: "TwoLinkArm has 2 joints: the controller has another number",
                        },
                        None,
                    ))?;
                let s2 = scenario::<2>(preset, typed.law(), items)
                    .map_err(|e| RunError::Core(e.error, None))?;
                run_arm(typed, two, &s2, weights, every, hooks)
            }
            ArmSpec::Planar { links, g } => {
                let links: [Link; N] = links.as_slice().try_into().map_err(|_| {
                    RunError::Core(
                        Error::Invalid {
                            what: "arm",
                            reason: "the arm and the controller have different numbers of joints",
                        },
                        None,
                    )
                })?;
                let arm = PlanarArm::new(links, *g)?;
                run_arm(self, &arm, &s, weights, every, hooks)
            }
        }
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}
