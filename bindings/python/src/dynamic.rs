//! The controller behind a run-time number of joints: [`DynTracker`], an
//! object-safe face of [`Tracker<N, AnyBasis<N>, Sinusoid<N>>`] for every
//! N = 1 … [`MAX_JOINTS`], taking and giving slices, built from the schema's
//! parameter items ([`super::items`]); its closed loops are in
//! [`super::drive`], recording into the core's rows and metrics.
//!
//! Nothing here knows Python: the bindings (`mod.rs`) convert arrays to
//! slices and errors to exceptions.

use super::mujoco::MujocoSpec;
use adaptimp::control::config::Law;
use adaptimp::control::controller::Controller;
use adaptimp::control::io::{Command, Measurement};
use adaptimp::control::tracker::Tracker;
use adaptimp::control::tuning::Rule;
use adaptimp::error::Error;
use adaptimp::networks::network::{Weights, C, D, G};
use adaptimp::networks::rbf::{AnyBasis, Basis, Centers, GRID_MAX_JOINTS};
use adaptimp::schema::Preset;
use adaptimp::sim::model::{Link, PlanarArm};
use adaptimp::trajectory::{Setpoint, Trajectory};
use adaptimp::types::Vector;
use adaptimp_mujoco::Sim;
use std::any::Any;
use std::vec::Vec;

pub use adaptimp::dynamic::MAX_JOINTS;

pub(crate) use super::drive::{drive_mujoco, Hooks, MujocoRun, OnMujoco, RunError, View};
use super::drive::{run_arm, run_mujoco, HOOK_EVERY};
use std::any::TypeId;

pub(crate) use super::items::Typed;
pub use super::items::{
    scenario, ArmSpec, CentersSpec, FaultKind, FaultSpec, GravitySpec, Items, Owned, ParamError,
};

pub use adaptimp::dynamic::{Metrics, RowMetrics, Rows};

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
    /// The torque last given to apply: the step's sat(τ), or a fallback.
    Applied,
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
    /// A step call refused by the front (its arguments' shapes or types):
    /// recorded as a refused step ([`Controller::refuse`](adaptimp::Controller::refuse)).
    fn refuse(&mut self, error: Error);
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
    /// Take over from a controller that was applying `tau` (n values, N m).
    fn take_over(&mut self, tau: &[f64]) -> Result<(), Error>;
    /// The whole state as reals ([`State::save`](adaptimp::control::state::State::save)).
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
        fault: Option<&FaultSpec>,
        every: u64,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError>;
    /// The closed loop on MuJoCo (`sim` as `spec` describes it) from the
    /// controller's current state (not reset: a used controller goes on),
    /// with the disturbances of `run.items` (SPEC §17; payload and jitter are
    /// refused: the first is a change of the model, the second of its
    /// timestep). Records every `run.every`-th row with the end effector.
    fn simulate_mujoco(
        &mut self,
        sim: &mut Sim,
        spec: &MujocoSpec,
        run: &MujocoRun<'_>,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError>;
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

/// Build the controller `law` for n joints from `preset` and `items`, with the
/// paper's grid (n ≤ 3) or `centers`, feeding forward `gravity`'s G(q) if
/// given (SPEC (20.10)).
pub fn build(
    n: usize,
    preset: Preset,
    law: Law,
    items: &Items,
    centers: Option<&CentersSpec>,
    gravity: Option<&GravitySpec>,
) -> Result<Box<dyn DynTracker>, ParamError> {
    adaptimp::with_joints!(
        n,
        K => Ok(Box::new(build_n::<K>(preset, law, items, centers, gravity)?)),
        _ => Err(Error::Invalid {
            what: "n",
            reason: "the number of joints must be between 1 and 7",
        }
        .into()),
    )
}

fn build_n<const N: usize>(
    preset: Preset,
    law: Law,
    items: &Items,
    centers: Option<&CentersSpec>,
    gravity: Option<&GravitySpec>,
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
    let mut ctrl = Controller::for_trajectory(s.config, basis, &traj)?;
    if let Some(g) = gravity {
        let model =
            adaptimp::cartesian::dynamics::Dynamics::<N>::new(&g.joints, &g.inertials, g.gravity)?;
        ctrl = ctrl.with_feedforward(std::sync::Arc::new(model));
    }
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
        let (tau, result) = adaptimp::control::io::Control::step_or_fallback(self, &meas, &c);
        out.copy_from_slice(tau.as_slice());
        result.map(|_| ())
    }

    fn refuse(&mut self, error: Error) {
        Tracker::refuse(self, error);
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
            Last::Applied => self.state().applied().as_slice(),
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
        Tracker::load_weights(self, &w)
    }

    fn take_over(&mut self, tau: &[f64]) -> Result<(), Error> {
        Tracker::take_over(self, &Vector::<N>::from_column_slice(tau))
    }

    fn snapshot(&self) -> Vec<f64> {
        let st = self.state();
        let mut out = std::vec![0.0; st.snapshot_len()];
        // The buffer has exactly the length save needs.
        let _ = st.save(&mut out);
        out
    }

    fn restore(&mut self, data: &[f64]) -> Result<(), Error> {
        Tracker::restore(self, data)
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
            if k > 0
                && (k as u64).is_multiple_of(HOOK_EVERY)
                && !hooks.report(k as u64, rows as u64, &*self)
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
        // The last row reported too (a progress bar ends at 100 %).
        if rows > 0 && !hooks.report(rows as u64, rows as u64, &*self) {
            return Err(RunError::Stopped);
        }
        Ok(())
    }

    fn simulate(
        &mut self,
        arm: &ArmSpec,
        items: &Items,
        weights: Option<&[f64]>,
        fault: Option<&FaultSpec>,
        every: u64,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError> {
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
                run_arm(typed, two, &s2, weights, fault, every, hooks)
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
                run_arm(self, &arm, &s, weights, fault, every, hooks)
            }
        }
    }

    fn simulate_mujoco(
        &mut self,
        sim: &mut Sim,
        spec: &MujocoSpec,
        run: &MujocoRun<'_>,
        hooks: &mut dyn Hooks,
    ) -> Result<(Rows, Metrics), RunError> {
        run_mujoco(self, sim, spec, run, hooks)
    }

    fn as_any_mut(&mut self) -> &mut dyn Any {
        self
    }
}

/// The copy of a joint controller as the bindings keep it.
impl<const N: usize> View for Typed<N> {
    fn copy(&self, part: TypeId) -> Option<Box<dyn Any + Send>> {
        (part == TypeId::of::<Box<dyn DynTracker>>())
            .then(|| Box::new(Box::new(self.clone()) as Box<dyn DynTracker>) as Box<dyn Any + Send>)
    }
}
