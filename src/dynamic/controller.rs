//! The joint controller for n joints known at run time: [`Scenario`] (every
//! parameter by name, and the one builder), [`Controller`] (the validated
//! controller with its own trajectory) and [`State`] (on the heap or in the
//! caller's buffer), over the const-generic [`Controller`](crate::Controller).

use super::model::Dynamics;
use super::sized::{each, make, map, pair, ByJoints, Family};
use super::values::{mismatch, too_many, Command, Joints, Measurement, Setpoint};
use crate::cartesian::CartesianConfig;
use crate::control::config::Law;
use crate::control::controller;
use crate::control::safety::Fault;
use crate::control::state;
use crate::control::tuning::Rule;
use crate::error::Error;
use crate::networks::network::{Weights, C, D, G};
use crate::networks::rbf::{AnyBasis, Basis as _, Centers, GRID_MAX_JOINTS};
use crate::schema::{self, Preset, Value};
use crate::trajectory::{Sinusoid, Trajectory};
use crate::types::Vector;
use alloc::boxed::Box;
use alloc::vec::Vec;
use core::convert::Infallible;
use core::marker::PhantomData;

pub(crate) struct ScenarioF;
impl Family for ScenarioF {
    type Of<const N: usize> = Box<schema::Scenario<N>>;
}

impl Centres {
    /// Centres along an orbit (SPEC §15 (15.2), [`Centers::along`]): one
    /// node at each sample's [q; q̇] (n values each), widths per block
    /// max(2 h, `tube`) (rad, rad/s; h the largest spacing of consecutive
    /// samples, the last to the first too when `periodic`), α1 and α̇1 left
    /// out (width +∞).
    pub fn along(samples: &[Setpoint], tube: [f64; 2], periodic: bool) -> Result<Self, Error> {
        let n = samples.first().map_or(0, |s| s.x.len());
        crate::with_joints!(n, N => {
            let typed: Vec<crate::trajectory::Setpoint<N>> = samples
                .iter()
                .map(|s| {
                    if s.x.len() != N || s.dx.len() != N || s.ddx.len() != N {
                        return Err(super::values::length("samples"));
                    }
                    Ok(crate::trajectory::Setpoint {
                        x: s.x.vector(),
                        dx: s.dx.vector(),
                        ddx: s.ddx.vector(),
                    })
                })
                .collect::<Result<_, _>>()?;
            let c = if periodic {
                Centers::along_periodic(&typed, tube)?
            } else {
                Centers::along(&typed, tube)?
            };
            Ok(Self::of(&c))
        }, _ => Err(Error::Invalid {
            what: "samples",
            reason: "need at least one sample of 1 to 7 joints",
        }))
    }

    /// The rows and squared widths of the core's centres of N joints.
    pub(crate) fn of<const N: usize>(c: &Centers<N, Vec<f64>>) -> Self {
        Self {
            rows: c.centers().to_vec(),
            widths2: Some(c.widths2().iter().flat_map(|b| b.iter().copied()).collect()),
        }
    }
}

/// The basis the controller's networks take.
#[derive(Clone, Debug, PartialEq)]
pub enum Basis {
    /// The paper's vertex grid for n ≤ 3 (SPEC §6), the rule's centres
    /// around the commanded trajectory beyond (SPEC §18,
    /// [`Rule::default_basis`]).
    Default,
    /// The paper's vertex grid of width η² (n ≤ 3; an error beyond).
    Grid,
    /// Centres of the caller's.
    Centres(Centres),
}

/// RBF centres of the caller's (SPEC §15): L rows of 4n coordinates each,
/// in blocks (x, v, α1, α̇1), joint-minor.
#[derive(Clone, Debug, PartialEq)]
pub struct Centres {
    /// L × 4n values, row-major.
    pub rows: Vec<f64>,
    /// The squared widths η_d² of the 4n input dimensions (same order), or
    /// none: the scenario's `eta2` for every one.
    pub widths2: Option<Vec<f64>>,
}

/// Every parameter of a scenario for n joints known at run time (the
/// schema's [`Scenario`](crate::schema::Scenario), set by name), and the one
/// builder of the joint controller: the Python and C fronts both build
/// theirs here, from the same names and values.
#[derive(Clone, Debug)]
pub struct Scenario {
    inner: ByJoints<ScenarioF>,
    law: Law,
    basis: Basis,
    feedforward: Option<Dynamics>,
}

impl Scenario {
    /// Every default of `preset` for the controller `law`, for n joints
    /// (1 ≤ n ≤ [`MAX_JOINTS`](super::MAX_JOINTS)); per-joint defaults of
    /// another length are broadcast from their first value
    /// ([`schema::Scenario::preset`]).
    pub fn new(n: usize, preset: Preset, law: Law) -> Result<Self, Error> {
        let inner = make!(n, N => Ok::<_, Error>(Box::new(schema::Scenario::<N>::preset(preset, law))), _ => too_many(n))?;
        Ok(Self {
            inner,
            law,
            basis: Basis::Default,
            feedforward: None,
        })
    }

    /// Set parameter `name` (the schema's, e.g. `"Kp"`) to `value`; errors
    /// as [`schema::Scenario::set`] (an unknown name, a value of the wrong
    /// kind or length, an unknown choice), changing nothing.
    pub fn set(&mut self, name: &str, value: Value<'_>) -> Result<&mut Self, Error> {
        each!(&mut self.inner, s, N => s.set(name, value))?;
        Ok(self)
    }

    /// The basis the controller's networks take (default: [`Basis::Default`]).
    pub fn basis(&mut self, basis: Basis) -> &mut Self {
        self.basis = basis;
        self
    }

    /// Feed forward the gravity torque G(q) of the nominal `model` (n
    /// joints), SPEC (20.10): for a robot that does not compensate gravity
    /// itself ([`with_feedforward`](crate::Controller::with_feedforward));
    /// none (the default) for one that does.
    pub fn feedforward(&mut self, model: Dynamics) -> &mut Self {
        self.feedforward = Some(model);
        self
    }

    /// The centres of the caller's (or of the rule's, [`Tuning::suggest`](super::Tuning::suggest)),
    /// if the basis is made of them.
    pub fn centres(&self) -> Option<&Centres> {
        match &self.basis {
            Basis::Centres(c) => Some(c),
            _ => None,
        }
    }

    /// The scenario of N joints `inner` for `law` with `basis`.
    pub(super) fn of(inner: ByJoints<ScenarioF>, law: Law, basis: Basis) -> Self {
        Self {
            inner,
            law,
            basis,
            feedforward: None,
        }
    }

    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// The controller's law.
    pub fn law(&self) -> Law {
        self.law
    }

    /// Every parameter's name and value, in the schema's order
    /// ([`schema::Scenario::visit`]): the defaults a front shows.
    pub fn visit(&self, f: impl FnMut(&'static str, Value<'_>)) {
        each!(&self.inner, s, N => s.visit(f))
    }

    /// The 6-D Cartesian impedance's parameters (the schema's group
    /// "cartesian", SPEC §16).
    pub fn cartesian(&self) -> CartesianConfig {
        each!(&self.inner, s, N => s.cartesian)
    }

    /// The scenario of N joints (N = n).
    #[cfg(feature = "sim")]
    pub(crate) fn typed(&self) -> &ByJoints<ScenarioF> {
        &self.inner
    }

    /// The joint controller of these parameters and basis, with the
    /// commanded sinusoid as its own trajectory: validated (SPEC §10, every
    /// condition named), built once for n.
    pub fn controller(&self) -> Result<Controller, Error> {
        let inner = map!(&self.inner, s, N => {
            let model = match &self.feedforward {
                Some(m) => Some(m.inner.get::<N>().ok_or(mismatch("feedforward"))?),
                None => None,
            };
            build::<N>(s, &self.basis, model.map(|m| &**m))
        })?;
        Ok(Controller { inner })
    }
}

/// The controller of N joints of `s` with `basis`.
fn build<const N: usize>(
    s: &schema::Scenario<N>,
    basis: &Basis,
    feedforward: Option<&crate::cartesian::Dynamics<N>>,
) -> Result<Box<Ctl<N>>, Error> {
    let traj = s.trajectory()?;
    let basis = match basis {
        Basis::Default if N > GRID_MAX_JOINTS => {
            AnyBasis::Centers(Rule::default().default_basis(&traj)?)
        }
        Basis::Default | Basis::Grid => AnyBasis::Grid(s.grid()?),
        Basis::Centres(c) => {
            let widths2 = match &c.widths2 {
                None => [Vector::<N>::from_element(s.eta2); 4],
                Some(w) if w.len() == 4 * N => {
                    core::array::from_fn(|b| Vector::from_column_slice(&w[b * N..][..N]))
                }
                Some(_) => {
                    return Err(Error::Invalid {
                        what: "widths",
                        reason: "need one width per input dimension (4n: x, v, α1, α̇1)",
                    })
                }
            };
            AnyBasis::Centers(Centers::new(c.rows.clone(), widths2)?)
        }
    };
    let mut ctrl = controller::Controller::for_trajectory(s.config, basis, &traj)?;
    if let Some(model) = feedforward {
        ctrl = ctrl.with_feedforward(alloc::sync::Arc::new(*model));
    }
    Ok(Box::new(Ctl { ctrl, traj }))
}

/// A controller of N joints and the trajectory it tracks by default.
#[derive(Clone, Debug)]
pub(crate) struct Ctl<const N: usize> {
    pub(crate) ctrl: controller::Controller<N, AnyBasis<N>>,
    pub(crate) traj: Sinusoid<N>,
}

pub(crate) struct CtlF;
impl Family for CtlF {
    type Of<const N: usize> = Box<Ctl<N>>;
}

pub(crate) struct StateF<S>(PhantomData<S>);
impl<S> Family for StateF<S> {
    type Of<const N: usize> = state::State<N, S>;
}

/// The joint controller (the paper's laws, SPEC §4–§11) for n joints known
/// at run time, with the commanded trajectory it tracks when a step is
/// given no setpoint; immutable (`Send + Sync`), one description for any
/// number of [`State`]s. Built by [`Scenario::controller`].
#[derive(Clone, Debug)]
pub struct Controller {
    pub(crate) inner: ByJoints<CtlF>,
}

/// The state of one run of a [`Controller`] (the weights, ζ, the observer,
/// the reference, the last command, the fault): on the heap
/// ([`Controller::new_state`]) or in a buffer of the caller's
/// ([`Controller::state_in`]).
#[derive(Clone, Debug)]
pub struct State<S = Vec<f64>> {
    pub(crate) inner: ByJoints<StateF<S>>,
}

impl Controller {
    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// The number of RBF nodes L.
    pub fn nodes(&self) -> usize {
        each!(&self.inner, c, N => c.ctrl.basis().nodes())
    }

    /// Dₛ of SPEC (18.12) (kg m², n × n row-major), if the gains are
    /// inertia-shaped (the parameter `inertia_matrix`).
    pub fn inertia_matrix(&self) -> Option<Vec<f64>> {
        each!(&self.inner, c, N => c.ctrl.coupling().map(|k| k.inertia().transpose().as_slice().to_vec()))
    }

    /// The law.
    pub fn law(&self) -> Law {
        each!(&self.inner, c, N => c.ctrl.config().law)
    }

    /// The const-generic controller and its own trajectory, if made for N
    /// joints: for a caller generic over N (a typed loop,
    /// [`for_joints`](super::for_joints)).
    pub fn typed<const N: usize>(
        &self,
    ) -> Option<(&controller::Controller<N, AnyBasis<N>>, &Sinusoid<N>)> {
        let c: &Ctl<N> = each!(&self.inner, c, M => (&**c as &dyn core::any::Any).downcast_ref())?;
        Some((&c.ctrl, &c.traj))
    }

    /// Sampling period Ts (s).
    pub fn period(&self) -> f64 {
        each!(&self.inner, c, N => c.ctrl.period())
    }

    /// The actuators' limits τmax (N m).
    pub fn tau_max(&self) -> Joints {
        each!(&self.inner, c, N => Joints::of(&c.ctrl.config().tau_max))
    }

    /// The target impedance's Dd, Cd, Gd (n values each) it realises.
    pub fn impedance(&self) -> [Joints; 3] {
        each!(&self.inner, c, N => {
            let t = c.ctrl.impedance();
            [Joints::of(t.dd()), Joints::of(t.cd()), Joints::of(t.gd())]
        })
    }

    /// The resolved weight bounds (‖ŴD‖, ‖ŴC‖, ‖ŴG‖), if any.
    pub fn weight_bound(&self) -> Option<[f64; 3]> {
        each!(&self.inner, c, N => c.ctrl.learning().bound())
    }

    /// Its own trajectory at `t` (s): xc, ẋc, ẍc.
    pub fn sample(&self, t: f64) -> Setpoint {
        each!(&self.inner, c, N => Setpoint::of(&c.traj.sample(t)))
    }

    /// The length (in f64) of the buffer a state needs ([`state_in`](Self::state_in)).
    pub fn buffer_len(&self) -> usize {
        each!(&self.inner, c, N => c.ctrl.buffer_len())
    }

    /// A state at t = 0 on the heap.
    pub fn new_state(&self) -> State {
        let inner = map!(&self.inner, c, N => Ok::<_, Infallible>(c.ctrl.new_state()))
            .unwrap_or_else(|e| match e {});
        State { inner }
    }

    /// A state at t = 0 in the caller's buffer `buf` (at least
    /// [`buffer_len`](Self::buffer_len) reals, zeroed here).
    pub fn state_in<S: AsRef<[f64]> + AsMut<[f64]>>(&self, buf: S) -> Result<State<S>, Error> {
        let inner = map!(&self.inner, c, N => c.ctrl.state_in(buf))?;
        Ok(State { inner })
    }

    /// Time t_k = k·Ts (s) of `state`'s next step.
    pub fn time<S>(&self, state: &State<S>) -> f64 {
        // A state of another controller: its own clock at this period.
        each!(&state.inner, s, N => s.k as f64 * self.period())
    }

    /// One step at t_k (SPEC §11): the measurement `m` and the commanded
    /// setpoint `c` (none: its own trajectory at t_k) in, the command out;
    /// [`Controller::step`](crate::Controller::step), bit for bit, with no
    /// allocation. An input of another length than n is refused by name
    /// and recorded as a refused step ([`refuse`](Self::refuse)); a state of
    /// another number of joints is refused and left unchanged.
    pub fn step<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        state: &mut State<S>,
        m: &Measurement<'_>,
        c: Option<&Setpoint<&[f64]>>,
    ) -> Result<Command, Error> {
        pair!(&self.inner, &mut state.inner, c0, s, N => {
            let (meas, sp) = match inputs::<N, S>(c0, s, m, c) {
                Ok(v) => v,
                Err(e) => {
                    c0.ctrl.refuse(s, e);
                    return Err(e);
                }
            };
            c0.ctrl.step(s, &meas, &sp).map(|cmd| Command::of(&cmd))
        }, _ => Err(mismatch("state")))
    }

    /// [`step`](Self::step), and the torque to apply whatever happened: the
    /// step's sat(τ), or the configured fallback on an error (then the
    /// applied torque the next step's rate limit starts from), as
    /// [`Controller::step_or_fallback`](crate::Controller::step_or_fallback).
    /// A state of another number of joints gives no torque: `None`.
    pub fn step_or_fallback<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        state: &mut State<S>,
        m: &Measurement<'_>,
        c: Option<&Setpoint<&[f64]>>,
    ) -> (Option<Joints>, Result<Command, Error>) {
        let result = self.step(state, m, c);
        let tau = match &result {
            Ok(cmd) => Some(cmd.tau_sat),
            Err(_) if state.n() == self.n() => Some(state.applied()),
            Err(_) => None,
        };
        (tau, result)
    }

    /// A step call refused before it reached [`step`](Self::step) (by a
    /// front's check of its arguments): recorded as a refused step is, with
    /// `error` as its fault; returns the fallback torque, or `None` for a
    /// state of another number of joints.
    pub fn refuse<S>(&self, state: &mut State<S>, error: Error) -> Option<Joints> {
        pair!(&self.inner, &mut state.inner, c, s, N => Some(Joints::of(&c.ctrl.refuse(s, error))), _ => None)
    }

    /// Restore into `state` a snapshot written by [`State::save`], checked
    /// as [`Controller::restore`](crate::Controller::restore) checks it; on
    /// an error `state` is unchanged.
    pub fn restore<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        state: &mut State<S>,
        data: &[f64],
    ) -> Result<(), Error> {
        pair!(&self.inner, &mut state.inner, c, s, N => c.ctrl.restore(s, data), _ => Err(mismatch("state")))
    }

    /// Take over the actuators from a controller that was applying `tau`
    /// (N m, n values) until now: the first step's torque rate limit moves
    /// from it ([`Controller::take_over`](crate::Controller::take_over)).
    pub fn take_over<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        state: &mut State<S>,
        tau: &[f64],
    ) -> Result<(), Error> {
        pair!(&self.inner, &mut state.inner, c, s, N => {
            if tau.len() != N {
                return Err(super::values::length("torque taken over"));
            }
            c.ctrl.take_over(s, &Vector::<N>::from_column_slice(tau))
        }, _ => Err(mismatch("state")))
    }

    /// Replace the weights of `state` (a warm start) with `rows`: the
    /// `2n² + n` rows ŴD\[k\]\[j\], ŴC\[k\]\[j\], ŴG\[k\] of L values each
    /// ([`Weights::from_rows`]), checked as
    /// [`Controller::load_weights`](crate::Controller::load_weights) checks them.
    pub fn load_weights<S: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        state: &mut State<S>,
        rows: &[f64],
    ) -> Result<(), Error> {
        pair!(&self.inner, &mut state.inner, c, s, N => {
            let w = Weights::<N>::from_rows(rows, c.ctrl.basis().nodes())?;
            c.ctrl.load_weights(s, &w)
        }, _ => Err(mismatch("state")))
    }

    /// The per-step learning gain of the explicit-Euler step at the start
    /// of its trajectory, Ts ‖S(Z0)‖² (ΓD ‖ẍc(0)‖² + ΓC ‖ẋc(0)‖² + ΓG) (N m
    /// per rad/s), and min Kp_i/d_i (SPEC (10.2)): the Jury condition of
    /// `docs/robot.md` is gain < Kp.
    pub fn learning_gain(&self) -> (f64, f64) {
        each!(&self.inner, c, N => {
            let cfg = c.ctrl.config();
            let x = c.traj.sample(0.0);
            let mut s = alloc::vec![0.0; c.ctrl.basis().nodes()];
            c.ctrl.basis().eval(&[x.x, x.dx, x.dx, x.ddx], &mut s);
            let s2: f64 = s.iter().map(|v| v * v).sum();
            let [gd, gc, gg] = cfg.gamma;
            let gain = cfg.ts * s2 * (gd * x.ddx.norm_squared() + gc * x.dx.norm_squared() + gg);
            (gain, cfg.kp.component_div(&cfg.inertia).min())
        })
    }
}

/// The core's measurement and setpoint of a step (the controller's own
/// trajectory at the state's t_k when `c` is none).
fn inputs<const N: usize, S>(
    ctl: &Ctl<N>,
    s: &state::State<N, S>,
    m: &Measurement<'_>,
    c: Option<&Setpoint<&[f64]>>,
) -> Result<
    (
        crate::control::io::Measurement<N>,
        crate::trajectory::Setpoint<N>,
    ),
    Error,
> {
    let meas = m.typed::<N>()?;
    let sp = match c {
        Some(c) => c.typed::<N>()?,
        None => ctl.traj.sample(ctl.ctrl.time(s)),
    };
    Ok((meas, sp))
}

impl<S: 'static> State<S> {
    /// The const-generic state, if made for N joints: for a caller generic
    /// over N (a typed loop, [`for_joints`](super::for_joints)).
    pub fn typed<const N: usize>(&self) -> Option<&state::State<N, S>> {
        each!(&self.inner, s, M => (s as &dyn core::any::Any).downcast_ref())
    }

    /// [`typed`](Self::typed), to change.
    pub fn typed_mut<const N: usize>(&mut self) -> Option<&mut state::State<N, S>> {
        each!(&mut self.inner, s, M => (s as &mut dyn core::any::Any).downcast_mut())
    }
}

impl<S: AsRef<[f64]> + AsMut<[f64]>> State<S> {
    /// The number of joints n.
    pub fn n(&self) -> usize {
        self.inner.n()
    }

    /// Steps taken k (the next step is at t_k = k·Ts).
    pub fn steps(&self) -> u64 {
        each!(&self.inner, s, N => s.steps())
    }

    /// Back to t = 0: weights, ζ, observer, reference and applied torque as
    /// at creation, the fault cleared.
    pub fn reset(&mut self) {
        each!(&mut self.inner, s, N => s.reset())
    }

    /// ζ now (N m).
    pub fn zeta(&self) -> &[f64] {
        each!(&self.inner, s, N => s.zeta().as_slice())
    }

    /// The last accepted step's command (zeros before the first).
    pub fn last(&self) -> Command {
        each!(&self.inner, s, N => Command::of(s.last()))
    }

    /// The torque to apply now (N m): the last accepted step's sat(τ), or
    /// the fallback of a refused step after it.
    pub fn applied(&self) -> Joints {
        each!(&self.inner, s, N => Joints::of(s.applied()))
    }

    /// The last refused step's fault, if any.
    pub fn fault(&self) -> Option<Fault> {
        each!(&self.inner, s, N => s.fault())
    }

    /// Forget the recorded fault (the recovery after a latched one).
    pub fn clear_fault(&mut self) {
        each!(&mut self.inner, s, N => s.clear_fault())
    }

    /// The number of RBF nodes L.
    pub fn nodes(&self) -> usize {
        each!(&self.inner, s, N => s.nodes())
    }

    /// ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ now.
    pub fn weight_norms(&self) -> [f64; 3] {
        each!(&self.inner, s, N => s.weight_norms())
    }

    /// The weights as `2n² + n` rows of L values: ŴD\[k\]\[j\], ŴC\[k\]\[j\],
    /// ŴG\[k\] ([`Weights::from_rows`], what [`Controller::load_weights`] takes).
    pub fn weights(&self) -> Vec<f64> {
        each!(&self.inner, s, N => {
            let w = s.weights();
            let mut out = Vec::with_capacity((2 * N * N + N) * s.nodes());
            for net in [D, C, G] {
                for row in w.network(net) {
                    out.extend_from_slice(row);
                }
            }
            out
        })
    }

    /// The number of reals [`save`](Self::save) writes.
    pub fn snapshot_len(&self) -> usize {
        each!(&self.inner, s, N => s.snapshot_len())
    }

    /// Save the whole state into `out` ([`State::save`](crate::State::save)'s
    /// format); returns the number of reals written.
    pub fn save(&self, out: &mut [f64]) -> Result<usize, Error> {
        each!(&self.inner, s, N => s.save(out))
    }
}
