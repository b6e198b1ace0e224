//! What a front gives to build a joint controller and its runs, as plain
//! values: parameter items by schema name, user centres, the nominal model
//! of the gravity fed forward, the arm of a run's plant, a fault to inject
//! (nothing here knows Python).

use adaptimp::control::config::Law;
use adaptimp::dynamic as dy;
use adaptimp::error::Error;
use adaptimp::schema::{Preset, Scenario, Value};
use adaptimp::sim::inject::Injection;
use adaptimp::sim::model::{Link, TwoLinkArm};
use std::vec::Vec;

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
    /// A flag.
    Bool(bool),
    /// None.
    None,
}

impl Owned {
    pub(crate) fn value(&self) -> Value<'_> {
        match self {
            Owned::Real(x) => Value::Real(*x),
            Owned::Int(i) => Value::Int(*i),
            Owned::Vec(v) => Value::Vec(v),
            Owned::Str(s) => Value::Str(s),
            Owned::Bool(b) => Value::Bool(*b),
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

/// Every item given to `set` in turn, by name; the first refusal names its
/// parameter.
pub(crate) fn apply<T>(
    items: &Items,
    mut set: impl FnMut(&str, Value<'_>) -> Result<T, Error>,
) -> Result<(), ParamError> {
    for (name, v) in items {
        set(name, v.value()).map_err(|error| ParamError {
            name: Some(name.clone()),
            error,
        })?;
    }
    Ok(())
}

/// `preset` for `law` with every item applied, for N joints.
pub fn scenario<const N: usize>(
    preset: Preset,
    law: Law,
    items: &Items,
) -> Result<Scenario<N>, ParamError> {
    let mut s = Scenario::<N>::preset(preset, law);
    apply(items, |name, v| s.set(name, v))?;
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

/// The nominal model whose gravity a joint controller feeds forward, SPEC
/// (20.10): a chain's joints and inertials and the gravity vector, as
/// computed torque takes them.
#[derive(Clone, Debug, PartialEq)]
pub struct GravitySpec {
    /// The chain's joints (fixed ones too).
    pub joints: Vec<adaptimp::cartesian::chain::Joint>,
    /// One inertial per joint.
    pub inertials: Vec<adaptimp::cartesian::dynamics::Inertial>,
    /// Gravity (m/s², base frame).
    pub gravity: [f64; 3],
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

/// A fault to inject into a run (`src/sim/inject.rs`), for any number of joints.
#[derive(Clone, Debug, PartialEq)]
pub struct FaultSpec {
    /// What goes wrong.
    pub kind: FaultKind,
    /// Start of the window (s).
    pub start: f64,
    /// Length of the window (s).
    pub duration: f64,
}

/// The kinds of [`Injected`] faults.
#[derive(Clone, Debug, PartialEq)]
pub enum FaultKind {
    /// The sensors repeat their last sample.
    Stale,
    /// The position sensor reads NaN.
    NanBurst,
    /// The force sensor reads τe + bias (N m, one per joint).
    ForceBias(Vec<f64>),
    /// The actuators deliver at most this fraction of τmax.
    ActuatorDrop(f64),
    /// No control step runs: the last applied torque is held.
    Skipped,
}

/// The core's injection of `f` for N joints, with the actuators' limits
/// `tau_max` (N m), checked by the core ([`dy::Injection::typed`]).
pub(crate) fn injection<const N: usize>(
    f: &FaultSpec,
    tau_max: &[f64],
) -> Result<Injection<N>, Error> {
    let fault = match &f.kind {
        FaultKind::Stale => dy::Injected::Stale,
        FaultKind::NanBurst => dy::Injected::NanBurst,
        FaultKind::Skipped => dy::Injected::Skipped,
        // More than 7 values: the core's refusal of a bias of another length.
        FaultKind::ForceBias(b) => {
            dy::Injected::ForceBias(dy::Joints::from_slice(b).or_else(|_| dy::Joints::zeros(0))?)
        }
        FaultKind::ActuatorDrop(fraction) => dy::Injected::ActuatorDrop {
            tau_max: dy::Joints::from_slice(tau_max)?,
            fraction: *fraction,
        },
    };
    dy::Injection {
        fault,
        start: f.start,
        duration: f.duration,
    }
    .typed::<N>()
}
