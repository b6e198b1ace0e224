//! MuJoCo as a [`Plant`] of the core's closed loop (the run-time
//! [`adaptimp::dynamic::Plant`] of n joints): [`MjPlant`] drives a
//! model through [`adaptimp_mujoco::Sim`] (the engine's C library, no Python
//! in the loop) with the semantics of `adaptimp.mujoco` (SPEC §13.1):
//!
//! - at t_k, the state, the end-effector position, the wrench F_e (from the
//!   force/torque sensors, a contact sensor of the net contact wrench on the
//!   end effector's subtree, or the contact forces on that subtree's bodies,
//!   MuJoCo's `cfrc_ext`) and τe = Jᵀ F_e are those of MuJoCo's forward
//!   computation at x_k with the previous torque held (sensors and contact
//!   as a real sensor reads them just before the new command);
//! - the command is saturated to the actuators' τmax (gear × ctrlrange) and
//!   held for `substeps` MuJoCo steps of Ts/substeps; ẍ_k is MuJoCo's q̈ at
//!   x_k with that torque (`mj_forwardSkip` from the velocity stage: the
//!   acceleration of `mj_forward`, without recomputing positions and
//!   velocities); after the steps, `mj_forward` at x_{k+1};
//! - a period after which MuJoCo has warned (it resets the state on a bad
//!   position, velocity or acceleration and only counts a warning), whose
//!   time did not advance by Ts, or whose state is not finite, ends the run
//!   with the row, the time and MuJoCo's own message ([`MjPlant::failure`]);
//! - the run's hook (signals, progress) is asked every 64 MuJoCo steps and
//!   at the end, so a period of many substeps is interrupted within it
//!   ([`MjPlant::watch`]); a flag raised by the controller (a controller
//!   written in Python that raised) stops the run before the next period
//!   ([`MjPlant::abort_on`]).
//!
//! Nothing here is `unsafe`: the FFI lives in the `adaptimp-mujoco` crate.

use adaptimp::dynamic::{Disturbances, Plant};
use adaptimp::error::Error;
use adaptimp::types::Vector;
use adaptimp_mujoco::{Sim, MAX_WARNINGS};

/// The run's references, the core's ([`Tabulated`](adaptimp::trajectory::Tabulated)
/// as `Table`).
pub use adaptimp::trajectory::{Continued, Tabulated as Table};
use core::cell::Cell;
use std::string::String;
use std::vec::Vec;

/// Where a plant's joints, actuators and end effector are in the model.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MujocoSpec {
    /// `qpos` address of each joint, in kinematic order.
    pub qadr: Vec<usize>,
    /// DOF address of each joint.
    pub dofs: Vec<usize>,
    /// The motor of each joint.
    pub act: Vec<usize>,
    /// Each motor's gear (τ = gear · ctrl).
    pub gear: Vec<f64>,
    /// τmax (N m) of each joint: gear × ctrlrange.
    pub tau_max: Vec<f64>,
    /// The end-effector site, or none (then the body's origin).
    pub site: Option<usize>,
    /// The end-effector body.
    pub ee_body: usize,
    /// `sensordata` address of the force sensor at the site; none: the model
    /// measures no wrench (no contact can reach the end effector).
    pub force_adr: Option<usize>,
    /// `sensordata` address of the torque sensor at the site, if any.
    pub torque_adr: Option<usize>,
    /// `sensordata` address of a contact sensor of the net contact wrench on
    /// the end effector's subtree (`reduce="netforce"`, `data="force torque
    /// pos"`: f, t about the centroid c, c; world frame), used without a
    /// force sensor.
    pub contact_adr: Option<usize>,
    /// The bodies of the end effector's subtree, whose external forces
    /// (`cfrc_ext`: MuJoCo's contact list, summed by MuJoCo) are the
    /// wrench when the model has neither sensor (empty: not read).
    pub subtree: Vec<usize>,
    /// The root body of the end effector (`body_rootid`): `cfrc_ext` is
    /// about its `subtree_com`.
    pub root: usize,
    /// MuJoCo steps per period.
    pub substeps: usize,
    /// MuJoCo's timestep (s): Ts / substeps.
    pub timestep: f64,
    /// The model's integrator (`mjtIntegrator`: 0 Euler, 1 RK4, 2 implicit,
    /// 3 implicitfast).
    pub integrator: i32,
    /// Whether every sensor of the model is a pure function of the state
    /// (none with noise, history, delay or interval, no user or plugin
    /// sensors): a MuJoCo step inside a period may then leave the sensors
    /// out of its forward computation, as only the period's last forward
    /// computation is sensed ([`Sim::step_without_sensors`]).
    pub pure_sensors: bool,
    /// Contacts watched (SPEC §18.10): the `sensordata` address of each
    /// contact sensor whose first value is the number of contacts it found
    /// and the next three their net force (N), read at the end of each
    /// period.
    pub watch: Vec<usize>,
    /// Where in `userdata` the plant keeps, for each watched sensor, three
    /// numbers: the periods at whose end it found a contact, the largest
    /// ‖force‖ (N) and the row of that largest (none: nothing watched).
    pub watch_out: Option<usize>,
    /// The joint name of each DOF of the model (for messages).
    pub dof_names: Vec<String>,
    /// The names of MuJoCo's warning kinds, by index (`mjtWarning`).
    pub warning_names: Vec<String>,
}

/// The run's hook as the plant asks it: `(periods done, periods in all)`
/// in, false to stop.
pub type Tick<'a> = dyn FnMut(u64, u64) -> bool + 'a;

/// MuJoCo steps between two calls of the run's hook.
const TICK_STEPS: u32 = 64;

/// MuJoCo as a [`Plant`] of n joints (n = the spec's joints).
pub struct MjPlant<'a> {
    sim: &'a mut Sim,
    spec: &'a MujocoSpec,
    /// The joint friction (SPEC §17), if the plant has any.
    friction: Option<Disturbances>,
    /// n values of scratch: the velocities, then the friction torque.
    scratch: [Vec<f64>; 2],
    ts: f64,
    rows: u64,
    tau_e: Vec<f64>,
    wrench: [f64; 6],
    x_ee: [f64; 3],
    failure: Option<Failure>,
    tick: Option<&'a mut Tick<'a>>,
    total: u64,
    since: u32,
    abort: Option<&'a Cell<bool>>,
    stopped: bool,
    /// MuJoCo's time where the last period ended (or the run started), read
    /// then: the next period's start when nothing touches the data between
    /// periods (no controller written in Python, see [`MjPlant::period_start`]).
    time: Option<f64>,
}

/// How the plant ended a run.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    /// MuJoCo raised a fatal error (`mju_error`), rather than a warning or a
    /// non-finite state.
    pub fatal: bool,
    /// The message: the row, the time and MuJoCo's words.
    pub message: String,
}

fn invalid(what: &'static str, reason: &'static str) -> Error {
    Error::Invalid { what, reason }
}

fn indices(v: &[usize], n: usize, bound: usize, what: &'static str) -> Result<(), Error> {
    if v.len() != n {
        return Err(invalid(what, "need one per joint"));
    }
    if v.iter().any(|&i| i >= bound) {
        return Err(invalid(what, "out of the model's range"));
    }
    Ok(())
}

/// The wrench [f; t + (c − p) × f] of the force f and the moment t about c
/// (world frame), with the moment moved to p.
fn moved(f: &[f64], t: &[f64], c: &[f64], p: &[f64; 3]) -> [f64; 6] {
    let d = [c[0] - p[0], c[1] - p[1], c[2] - p[2]];
    [
        f[0],
        f[1],
        f[2],
        t[0] + (d[1] * f[2] - d[2] * f[1]),
        t[1] + (d[2] * f[0] - d[0] * f[2]),
        t[2] + (d[0] * f[1] - d[1] * f[0]),
    ]
}

/// The wrench's sources of `spec` in `sim`: one at most, every address in range.
fn check_wrench(spec: &MujocoSpec, sim: &Sim) -> Result<(), Error> {
    let sensors = sim.sensordata().len();
    let bodies = sim.xpos().len() / 3;
    for adr in [spec.force_adr, spec.torque_adr].into_iter().flatten() {
        if adr + 3 > sensors {
            return Err(invalid("sensor", "address out of sensordata"));
        }
    }
    if spec.contact_adr.is_some_and(|adr| adr + 9 > sensors) {
        return Err(invalid("contact sensor", "address out of sensordata"));
    }
    if spec.subtree.iter().any(|&b| b >= bodies) || spec.root >= bodies {
        return Err(invalid("subtree", "out of the model's range"));
    }
    let sources = [
        spec.force_adr.is_some(),
        spec.contact_adr.is_some(),
        !spec.subtree.is_empty(),
    ];
    if sources.iter().filter(|s| **s).count() > 1 {
        return Err(invalid(
            "wrench",
            "comes from the force sensor, the contact sensor or the subtree's forces: one",
        ));
    }
    if spec.force_adr.is_none() && spec.torque_adr.is_some() {
        return Err(invalid("sensor", "a torque sensor needs a force sensor"));
    }
    if spec.watch.iter().any(|&adr| adr + 4 > sensors) {
        return Err(invalid("watch", "address out of sensordata"));
    }
    if !spec.watch.is_empty() {
        let fits = spec
            .watch_out
            .is_some_and(|base| base + 3 * spec.watch.len() <= sim.userdata_len());
        if !fits {
            return Err(invalid(
                "watch_out",
                "needs three userdata values per watched sensor",
            ));
        }
    }
    match spec.site {
        Some(s) if s >= sim.site_xpos().len() / 3 => {
            Err(invalid("site", "out of the model's range"))
        }
        None if spec.ee_body >= bodies => Err(invalid("ee_body", "out of the model's range")),
        None if spec.force_adr.is_some() => Err(invalid("sensor", "a force sensor needs its site")),
        _ => Ok(()),
    }
}

impl<'a> MjPlant<'a> {
    /// The plant of `sim` as `spec` describes it (n = its joints), at the
    /// period `ts` (s), with the joint friction of `disturbances` (SPEC
    /// §17, n joints) applied through `qfrc_applied` (held over each MuJoCo
    /// step). Reads the state MuJoCo's last forward computation left (the
    /// caller has run one, e.g. a reset).
    pub fn new(
        sim: &'a mut Sim,
        spec: &'a MujocoSpec,
        ts: f64,
        disturbances: &Disturbances,
    ) -> Result<Self, Error> {
        let n = spec.qadr.len();
        if n == 0 || disturbances.n() != n {
            return Err(invalid(
                "qadr",
                "need one per joint of the disturbances, at least one",
            ));
        }
        let nv = sim.nv();
        indices(&spec.qadr, n, sim.qpos().len(), "qadr")?;
        indices(&spec.dofs, n, nv, "dofs")?;
        indices(&spec.act, n, sim.ctrl_mut().len(), "act")?;
        for (v, what) in [(&spec.gear, "gear"), (&spec.tau_max, "tau_max")] {
            if v.len() != n || v.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
                return Err(invalid(what, "need one finite value > 0 per joint"));
            }
        }
        check_wrench(spec, sim)?;
        if spec.substeps == 0 || !(spec.timestep > 0.0 && spec.timestep.is_finite()) {
            return Err(invalid("substeps", "need substeps ≥ 1 and a timestep > 0"));
        }
        let friction = disturbances.has_friction().then(|| disturbances.clone());
        Ok(Self {
            sim,
            spec,
            friction,
            scratch: [std::vec![0.0; n], std::vec![0.0; n]],
            ts,
            rows: 0,
            tau_e: std::vec![0.0; n],
            wrench: [0.0; 6],
            x_ee: [0.0; 3],
            failure: None,
            tick: None,
            total: 0,
            since: 0,
            abort: None,
            stopped: false,
            time: None,
        })
    }

    /// Ask `tick` every 64 MuJoCo steps (also within a period) and at the
    /// end of the run of `total` periods; when it returns false the period
    /// stops there ([`MjPlant::stopped`]), between two MuJoCo steps.
    pub fn watch(&mut self, tick: &'a mut Tick<'a>, total: u64) {
        self.tick = Some(tick);
        self.total = total;
    }

    /// Stop the run before the next period once `flag` is raised (by the
    /// controller, between its step and the plant's advance).
    pub fn abort_on(&mut self, flag: &'a Cell<bool>) {
        self.abort = Some(flag);
    }

    /// Whether the hook or the flag stopped the run.
    pub fn stopped(&self) -> bool {
        self.stopped
    }

    /// Periods completed.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Ask the hook, with `done` periods completed; an error if it stops the run.
    fn ask(&mut self, done: u64) -> Result<(), Error> {
        self.since = 0;
        let go_on = match self.tick.as_mut() {
            Some(tick) => tick(done, self.total),
            None => true,
        };
        if go_on {
            return Ok(());
        }
        self.stopped = true;
        Err(invalid("run", "stopped"))
    }

    /// One MuJoCo step done: the hook every [`TICK_STEPS`]. Stopped within a
    /// period, the data is left at the state reached, computed forward (as a
    /// period leaves it: a run continued from it reads it).
    fn stepped(&mut self) -> Result<(), Error> {
        self.since += 1;
        if self.since >= TICK_STEPS {
            if let Err(e) = self.ask(self.rows) {
                if let Err(fatal) = self.sim.forward() {
                    return Err(self.fatal(fatal));
                }
                return Err(e);
            }
        }
        Ok(())
    }

    /// Read the end effector at the state MuJoCo's last forward computation
    /// left: call once before the run.
    pub fn start(&mut self) -> Result<(), Error> {
        self.time = Some(self.sim.time());
        self.sense()
    }

    /// MuJoCo's time at the start of this period: the time the last period
    /// ended at (read by its check, [`MjPlant::check`]), unless a controller
    /// written in Python runs between periods ([`MjPlant::abort_on`]), which
    /// could change the data (a reset): then read again. Between two periods
    /// of the core's controllers only the controller's step and the records
    /// run, and the run's hook is asked inside a period (a reset there is
    /// caught by the period's check) or after the last one.
    fn period_start(&self) -> f64 {
        match (self.abort, self.time) {
            (None, Some(t)) => t,
            _ => self.sim.time(),
        }
    }

    /// Why the run ended, if the plant ended it.
    pub fn failure(&self) -> Option<&Failure> {
        self.failure.as_ref()
    }

    /// A MuJoCo call's fatal error, recorded as the failure of the period.
    fn fatal(&mut self, e: adaptimp_mujoco::Error) -> Error {
        let t0 = self.rows as f64 * self.ts;
        self.failure = Some(Failure {
            fatal: true,
            message: std::format!(
                "the MuJoCo plant failed in the period of row {} (t = {t0} s): {e}",
                self.rows
            ),
        });
        Error::Diverged { what: "MuJoCo" }
    }

    /// The end effector's position, wrench and τe at the current forward
    /// computation.
    fn sense(&mut self) -> Result<(), Error> {
        let spec = self.spec;
        let point = match spec.site {
            Some(s) => &self.sim.site_xpos()[3 * s..3 * s + 3],
            None => &self.sim.xpos()[3 * spec.ee_body..3 * spec.ee_body + 3],
        };
        self.x_ee.copy_from_slice(point);
        let w = if spec.force_adr.is_some() {
            self.sensor_wrench()
        } else if let Some(a) = spec.contact_adr {
            let data = self.sim.sensordata();
            let (f, t, c) = (&data[a..a + 3], &data[a + 3..a + 6], &data[a + 6..a + 9]);
            moved(f, t, c, &self.x_ee)
        } else if !spec.subtree.is_empty() {
            self.body_forces()?
        } else {
            [0.0; 6]
        };
        self.wrench = w;
        self.tau_e.fill(0.0);
        if w.iter().any(|x| *x != 0.0) {
            self.joint_torque(&w)?;
        }
        Ok(())
    }

    /// The watched contacts at this period's end (SPEC §18.10): for each
    /// watched sensor that found a contact, one more period in contact and
    /// the largest ‖force‖ so far with its row, kept in `userdata`.
    fn watch_contacts(&mut self) {
        let (spec, row) = (self.spec, self.rows as f64);
        let Some(base) = spec.watch_out else {
            return;
        };
        for (i, &adr) in spec.watch.iter().enumerate() {
            let data = self.sim.sensordata();
            if data[adr] <= 0.0 {
                continue;
            }
            let f = libm::sqrt(
                data[adr + 1] * data[adr + 1]
                    + data[adr + 2] * data[adr + 2]
                    + data[adr + 3] * data[adr + 3],
            );
            let out = &mut self.sim.userdata_mut()[base + 3 * i..base + 3 * i + 3];
            out[0] += 1.0;
            if f > out[1] {
                out[1] = f;
                out[2] = row;
            }
        }
    }

    /// F_e from the force (and torque) sensor at the site, which measure in
    /// the site's frame: F_world = R F_site.
    fn sensor_wrench(&self) -> [f64; 6] {
        let spec = self.spec;
        let sid = spec.site.unwrap_or(0);
        let r = &self.sim.site_xmat()[9 * sid..9 * sid + 9];
        let data = self.sim.sensordata();
        let mut w = [0.0; 6];
        for (block, adr) in [(0, spec.force_adr), (3, spec.torque_adr)] {
            if let Some(a) = adr {
                for i in 0..3 {
                    w[block + i] = r[3 * i] * data[a]
                        + r[3 * i + 1] * data[a + 1]
                        + r[3 * i + 2] * data[a + 2];
                }
            }
        }
        w
    }

    /// F_e from the external forces on the end effector's subtree
    /// (`cfrc_ext`, [torque; force] on each body about the root's
    /// `subtree_com` c, world frame): minus their sum, the force the arm
    /// exerts, with the moment moved to the end-effector point. A contact of
    /// two bodies of the subtree adds opposite forces: it cancels, as the
    /// contact list's sum skips it.
    fn body_forces(&mut self) -> Result<[f64; 6], Error> {
        if let Err(e) = self.sim.rne_post_constraint() {
            return Err(self.fatal(e));
        }
        let ext = self.sim.cfrc_ext();
        let (mut t, mut f) = ([0.0; 3], [0.0; 3]);
        for &b in &self.spec.subtree {
            for i in 0..3 {
                t[i] += ext[6 * b + i];
                f[i] += ext[6 * b + 3 + i];
            }
        }
        let root = self.spec.root;
        let c = &self.sim.subtree_com()[3 * root..3 * root + 3];
        let w = moved(&f, &t, c, &self.x_ee);
        // On the environment, not on the arm: −F (0 − x: no negative zeros).
        Ok(w.map(|x| 0.0 - x))
    }

    /// τe = Jᵀ F_e (J = [Jp; Jr], 6 × n) at the current forward computation,
    /// into `tau_e`.
    fn joint_torque(&mut self, w: &[f64; 6]) -> Result<(), Error> {
        let nv = self.sim.nv();
        let dofs = &self.spec.dofs;
        let (by_site, id) = match self.spec.site {
            Some(s) => (true, s),
            None => (false, self.spec.ee_body),
        };
        let (jp, jr) = match self.sim.jacobian(by_site, id) {
            Ok(j) => j,
            Err(e) => return Err(self.fatal(e)),
        };
        for (te, &d) in self.tau_e.iter_mut().zip(dofs) {
            let mut acc = 0.0;
            for r in 0..3 {
                acc += jp[r * nv + d] * w[r];
            }
            for r in 0..3 {
                acc += jr[r * nv + d] * w[3 + r];
            }
            *te = acc;
        }
        Ok(())
    }

    /// The period's end: MuJoCo's warnings, the time, the state.
    fn check(&mut self, before: &[(i32, i32); MAX_WARNINGS], t0: f64) -> Result<(), Error> {
        let (after, count) = self.sim.warnings();
        let k = self.rows;
        let start = k as f64 * self.ts;
        let mut expected = t0;
        for _ in 0..self.spec.substeps {
            expected += self.spec.timestep; // as mj_step advances d->time
        }
        let time = self.sim.time();
        self.time = Some(time);
        let warned = (0..count).find(|&i| after[i].0 != before[i].0);
        let nonfinite = {
            let (qpos, qvel) = (self.sim.qpos(), self.sim.qvel());
            let x = self.spec.qadr.iter().map(|&a| qpos[a]);
            let dx = self.spec.dofs.iter().map(|&d| qvel[d]);
            x.chain(dx).any(|v| !v.is_finite())
        };
        // A reset puts the time back to 0: half a timestep tells it from rounding.
        let reset = (time - expected).abs() > 0.5 * self.spec.timestep;
        if warned.is_none() && !reset && !nonfinite {
            return Ok(());
        }
        let cause = match warned {
            Some(i) => {
                let info = after[i].1;
                let text = self.sim.library().warning_text(i, info);
                let name = self.spec.warning_names.get(i).map_or("", String::as_str);
                let joint = match (name, usize::try_from(info)) {
                    (
                        "mjWARN_BADQPOS" | "mjWARN_BADQVEL" | "mjWARN_BADQACC" | "mjWARN_INERTIA",
                        Ok(d),
                    ) => self
                        .spec
                        .dof_names
                        .get(d)
                        .map(|j| std::format!(" (joint {j:?})"))
                        .unwrap_or_default(),
                    _ => String::new(),
                };
                let reset = if reset {
                    std::format!(
                        "; MuJoCo reset its state (its time is {time} s, not {expected} s)"
                    )
                } else {
                    String::new()
                };
                std::format!("MuJoCo warned {name}: {text}{joint}{reset}")
            }
            None if nonfinite => String::from("the state is not finite"),
            None => {
                std::format!("MuJoCo's time is {time} s, not {expected} s (its state was reset)")
            }
        };
        self.failure = Some(Failure {
            fatal: false,
            message: std::format!(
                "the MuJoCo plant diverged in the period of row {k} (t = {start} s to {} s): {cause}",
                (k + 1) as f64 * self.ts
            ),
        });
        Err(Error::Diverged {
            what: "MuJoCo state",
        })
    }
}

impl Plant for MjPlant<'_> {
    fn n(&self) -> usize {
        self.spec.qadr.len()
    }

    fn state(&self, x: &mut [f64], dx: &mut [f64]) {
        let (qpos, qvel) = (self.sim.qpos(), self.sim.qvel());
        for (x, &a) in x.iter_mut().zip(&self.spec.qadr) {
            *x = qpos[a];
        }
        for (dx, &d) in dx.iter_mut().zip(&self.spec.dofs) {
            *dx = qvel[d];
        }
    }

    fn contact(&self, tau_e: &mut [f64]) {
        tau_e.copy_from_slice(&self.tau_e);
    }

    fn actuate(&self, tau: &[f64], out: &mut [f64]) {
        for ((o, t), m) in out.iter_mut().zip(tau).zip(&self.spec.tau_max) {
            *o = t.max(-m).min(*m);
        }
    }

    fn wrench(&self) -> [f64; 6] {
        self.wrench
    }

    fn end_effector(&self) -> [f64; 3] {
        self.x_ee
    }

    fn advance(&mut self, tau: &[f64], h: f64, ddx: &mut [f64]) -> Result<(), Error> {
        if self.abort.is_some_and(Cell::get) {
            self.stopped = true;
            return Err(invalid("run", "stopped by the controller"));
        }
        if h != self.ts {
            return Err(invalid(
                "jitter",
                "the MuJoCo plant advances by Ts exactly (its timestep is fixed for a run)",
            ));
        }
        let spec = self.spec;
        let ctrl = self.sim.ctrl_mut();
        for (((&a, &g), t), m) in spec.act.iter().zip(&spec.gear).zip(tau).zip(&spec.tau_max) {
            ctrl[a] = t.max(-m).min(*m) / g;
        }
        if let Err(e) = self.sim.forward_acceleration() {
            return Err(self.fatal(e));
        }
        let qacc = self.sim.qacc();
        for (a, &d) in ddx.iter_mut().zip(&spec.dofs) {
            *a = qacc[d];
        }
        let (before, _) = self.sim.warnings();
        let t0 = self.period_start();
        for sub in 0..spec.substeps {
            let Some(friction) = &self.friction else {
                // The forward computation at x_k with these controls is the
                // one just done for the row's q̈: `mj_step` without it.
                let stepped = if sub == 0 {
                    self.sim.step_computed(spec.integrator)
                } else {
                    self.inner_step()
                };
                if let Err(e) = stepped {
                    return Err(self.fatal(e));
                }
                self.stepped()?;
                continue;
            };
            let [dq, f] = &mut self.scratch;
            let qvel = self.sim.qvel();
            for (v, &d) in dq.iter_mut().zip(&spec.dofs) {
                *v = qvel[d];
            }
            friction.friction_torque(dq, f)?;
            let applied = self.sim.qfrc_applied_mut();
            for (&d, &t) in spec.dofs.iter().zip(f.iter()) {
                applied[d] = t;
            }
            if let Err(e) = self.inner_step() {
                return Err(self.fatal(e));
            }
            self.stepped()?;
        }
        if let Err(e) = self.sim.forward() {
            return Err(self.fatal(e));
        }
        self.check(&before, t0)?;
        self.sense()?;
        self.watch_contacts();
        self.rows += 1;
        if self.rows == self.total {
            self.ask(self.rows)?;
        }
        Ok(())
    }
}

impl MjPlant<'_> {
    /// A MuJoCo step inside the period: its sensors are not read (the
    /// period's last forward computation is sensed).
    fn inner_step(&mut self) -> Result<(), adaptimp_mujoco::Error> {
        if self.spec.pure_sensors {
            self.sim.step_without_sensors(self.spec.integrator)
        } else {
            self.sim.step()
        }
    }
}

/// The plant for the const-generic loop of N joints (N = n), through the
/// run-time face.
impl<const N: usize> adaptimp::sim::plant::Plant<N> for MjPlant<'_> {
    fn state(&self) -> (Vector<N>, Vector<N>) {
        let (mut x, mut dx) = (Vector::<N>::zeros(), Vector::<N>::zeros());
        Plant::state(self, x.as_mut_slice(), dx.as_mut_slice());
        (x, dx)
    }

    fn contact(&self) -> Vector<N> {
        Vector::from_column_slice(&self.tau_e)
    }

    fn actuate(&self, tau: &Vector<N>) -> Vector<N> {
        let mut out = Vector::<N>::zeros();
        Plant::actuate(self, tau.as_slice(), out.as_mut_slice());
        out
    }

    fn wrench(&self) -> [f64; 6] {
        self.wrench
    }

    fn end_effector(&self) -> [f64; 3] {
        self.x_ee
    }

    fn advance(&mut self, tau: &Vector<N>, h: f64) -> Result<Vector<N>, Error> {
        let mut a = Vector::<N>::zeros();
        Plant::advance(self, tau.as_slice(), h, a.as_mut_slice())?;
        Ok(a)
    }
}
