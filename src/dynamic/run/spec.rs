//! One typed run: [`run`] takes a [`Spec`] (the plant, what it steps, the
//! run's settings and hook) and returns an [`Output`] (the rows, the task
//! rows of a Cartesian run, and how it ended: the SPEC §12 metrics or the
//! error), the rows sized for the run before it starts. The one entry of
//! [`simulate`] and [`simulate_cartesian`] for a caller that wants the whole
//! run as a value.

use super::super::cartesian::{CartesianImpedance, CartesianState, Joint};
use super::{
    simulate, simulate_cartesian, Controlled, Hooks, Metrics, Plant, Reference, Rows, Run,
    RunError, TaskRows,
};
use crate::cartesian::PoseTarget;
use alloc::vec::Vec;

/// What a run steps.
#[derive(Debug)]
pub enum Loop<'a, S = Vec<f64>> {
    /// A joint controller (the core's, or one of the caller's) along a
    /// joint reference.
    Joint {
        /// The controller and its state.
        ctrl: Controlled<'a, S>,
        /// The joint reference.
        reference: Reference<'a>,
    },
    /// The Cartesian controller: the outer loop in front of a joint
    /// controller, along pose targets (none: the last target held).
    Cartesian {
        /// The outer loop.
        outer: &'a CartesianImpedance,
        /// Its state.
        state: &'a mut CartesianState,
        /// The joint controller behind it and its state.
        joint: Joint<'a, S>,
        /// The commanded pose of every step, or none.
        targets: Option<&'a [PoseTarget]>,
    },
}

impl<S: AsRef<[f64]> + AsMut<[f64]>> Loop<'_, S> {
    /// Its number of joints n.
    pub fn n(&self) -> usize {
        match self {
            Loop::Joint { ctrl, .. } => match ctrl {
                Controlled::Joint(j) => j.n(),
                Controlled::Own(c) => c.n(),
            },
            Loop::Cartesian { outer, .. } => outer.n(),
        }
    }

    /// Its period Ts (s).
    pub fn period(&self) -> f64 {
        match self {
            Loop::Joint { ctrl, .. } => match ctrl {
                Controlled::Joint(j) => j.period(),
                Controlled::Own(c) => c.period(),
            },
            Loop::Cartesian { outer, .. } => outer.period(),
        }
    }
}

/// A whole run: the plant, what it steps, the run's settings and its hook.
pub struct Spec<'a, S = Vec<f64>> {
    /// The plant (its n: the controller's).
    pub plant: &'a mut dyn Plant,
    /// What the loop steps.
    pub looped: Loop<'a, S>,
    /// Length, recording and disturbances.
    pub run: Run<'a>,
    /// Asked every 64 periods whether to go on (none: always).
    pub hooks: Option<&'a mut dyn Hooks>,
}

/// What a run gives back.
#[derive(Debug)]
pub struct Output {
    /// Every kept row in joint space (also those before an error; none if
    /// the rows could not be sized).
    pub rows: Rows,
    /// A Cartesian run's rows in task space and its last step.
    pub task: Option<TaskRows>,
    /// How it ended: the SPEC §12 metrics (in task space for a Cartesian
    /// run), or the error that ended it.
    pub ended: Result<Metrics, RunError>,
}

/// The run of `spec`: the rows sized for it (round(T/Ts) periods, every
/// `run.every`-th kept), then [`simulate`] or [`simulate_cartesian`] with
/// the same values, bit for bit. An error before the first step (a size,
/// memory for the rows) ends it with no rows.
pub fn run<S: AsRef<[f64]> + AsMut<[f64]>>(spec: Spec<'_, S>) -> Output {
    let Spec {
        plant,
        looped,
        run,
        hooks,
    } = spec;
    let (n, ts) = (looped.n(), looped.period());
    let mut always = ();
    let hooks: &mut dyn Hooks = match hooks {
        Some(h) => h,
        None => &mut always,
    };
    let empty = |ended: RunError| Output {
        rows: Rows::default(),
        task: None,
        ended: Err(ended),
    };
    let mut rows = match Rows::for_run(n, &run, ts) {
        Ok(r) => r,
        Err(e) => return empty(e),
    };
    match looped {
        Loop::Joint { ctrl, reference } => {
            let ended = simulate(plant, ctrl, reference, &run, hooks, &mut rows);
            Output {
                rows,
                task: None,
                ended,
            }
        }
        Loop::Cartesian {
            outer,
            state,
            joint,
            targets,
        } => {
            let mut task = match TaskRows::for_run(n, &run, ts) {
                Ok(t) => t,
                Err(e) => return empty(e),
            };
            let ended = simulate_cartesian(
                plant, outer, state, joint, targets, &run, hooks, &mut rows, &mut task,
            );
            Output {
                rows,
                task: Some(task),
                ended,
            }
        }
    }
}
