//! The gain and basis rule of SPEC §18 for n joints known at run time: the
//! arm's inertia, limits and period (and the task's path, if known) in, a
//! [`Scenario`] of the robot preset with the rule's gains (and its centres
//! along the path) out, the one builder of both fronts then making the
//! controller. Each step is the const-generic [`Rule`]'s, in the order the
//! fronts took them: [`Rule::with_delay`], [`Rule::weightless`],
//! [`Rule::critical`], the inertia
//! scales, [`Rule::bounded`] by [`loop_bound`] (SPEC (18.11)),
//! [`damped_scales`], [`resolving`], [`Rule::spanning`], then
//! [`Rule::gains_scaled`] or [`Rule::suggest_scaled`].

use super::controller::{Basis, Centres, Scenario};
use super::sized::make;
use super::values::{length, too_many, vector, Joints};
use crate::cartesian::rule::{resolving, shaped_orbit};
use crate::control::config::Law;
use crate::control::tuning::{
    damped_scales, inertia_scales, inertia_scales_along, largest_eigenvalue, loop_bound, Rule,
};
use crate::error::{check, Error};
use crate::schema::{self, Preset};
use crate::trajectory::Setpoint;
use crate::types::{Matrix, Vector};
use alloc::boxed::Box;
use alloc::vec::Vec;

/// The arm's inertia the rule scales its gains by, SPEC (18.1).
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Inertia<'a> {
    /// The inertia matrix D(q) (kg m², n × n, row-major) at the task's start
    /// ([`inertia_scales`]).
    At(&'a [f64]),
    /// D at K ≥ 1 postures along the task's path (K matrices of n × n,
    /// row-major each): the scales along it ([`inertia_scales_along`]); the
    /// margin of SPEC (18.11) at the largest mode of them all.
    Along(&'a [f64]),
}

/// One period of the task's path, evenly spaced in time.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct TaskPath<'a> {
    /// K rows of 3n values: q (rad), q̇ (rad/s), q̈ (rad/s²).
    pub rows: &'a [f64],
    /// The period the K rows span (s).
    pub period: f64,
}

/// What the rule of SPEC §18 is given for an arm of n joints (n: the
/// length of `tau_max`); [`suggest`](Self::suggest) applies it.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Tuning<'a> {
    /// The controller's law.
    pub law: Law,
    /// The arm's inertia.
    pub inertia: Inertia<'a>,
    /// The actuators' limits τmax (N m), n values.
    pub tau_max: &'a [f64],
    /// The sampling period Ts (s).
    pub ts: f64,
    /// The loop's delay δ (periods, 0 … 64), SPEC (18.11).
    pub delay: usize,
    /// The task's path: with it, the centres along it, the learning rates
    /// and the weight bounds too ([`Rule::suggest_scaled`]).
    pub path: Option<TaskPath<'a>>,
    /// The gravity torque G (N m, n values) at the path's start: the tube
    /// holding the sag ([`Rule::holding`]); read with a path only.
    pub gravity: Option<&'a [f64]>,
    /// The joints' viscous damping (N m s/rad, n values), if the plant has
    /// it: the scales as the sampled velocity loop sees them, SPEC (18.9).
    pub damping: Option<&'a [f64]>,
    /// The joint positions (rad, K' rows of n) of one period of the motion
    /// that repeats: the widths in q at least its diameter, SPEC (19.11);
    /// read with a path only.
    pub orbit: Option<&'a [f64]>,
    /// The tube narrowed to the path's own size, SPEC (16.10) (the
    /// Cartesian rule's); read with a path only.
    pub resolve: bool,
    /// Ĝ learning at the velocity loop's critical bandwidth, SPEC (19.6).
    pub critical: bool,
    /// The arm bears no gravity the controller must hold (a robot that
    /// compensates it itself): D̂ and Ĉ learn at Ĝ's bandwidth, SPEC (22.2).
    pub weightless: bool,
    /// The inertia-shaped gains of SPEC (18.12): Dₛ the harmonic mean of D
    /// along the path (the parameter `inertia_matrix`),
    /// the margin of (18.11) at the largest mode of Dₛ^½ D⁻¹ Dₛ^½.
    /// `None` (the default): on for a loop with a delay (δ ≥ 1), where
    /// (18.11)'s margin bounds the gain, on a joint task and on a Cartesian
    /// task's orbit (`resolve`, where Ĝ then learns faster:
    /// [`shaped_orbit`]); off, the diagonal scales of (18.1).
    pub coupled: Option<bool>,
}

impl<'a> Tuning<'a> {
    /// The rule for `law` on an arm of inertia `inertia`, limits `tau_max`
    /// (N m, n values) and period `ts` (s); no delay, no path, nothing else.
    pub fn new(law: Law, inertia: Inertia<'a>, tau_max: &'a [f64], ts: f64) -> Self {
        Self {
            law,
            inertia,
            tau_max,
            ts,
            delay: 0,
            path: None,
            gravity: None,
            damping: None,
            orbit: None,
            resolve: false,
            critical: false,
            weightless: false,
            coupled: None,
        }
    }

    /// Whether the rule shapes the gains by the inertia, SPEC (18.12):
    /// as asked, else for a loop with a delay (δ ≥ 1).
    pub fn coupled(&self) -> bool {
        self.coupled.unwrap_or(self.delay >= 1)
    }

    /// The robot scenario's parameters for `law` with the rule's gains and
    /// the conditions "scaled" (SPEC §10); with a path, also its learning
    /// rates, weight bounds and centres along it (the scenario's basis, read
    /// with [`Scenario::centres`]). Errors name the input or the condition.
    pub fn suggest(&self) -> Result<Scenario, Error> {
        let n = self.tau_max.len();
        let mut centres = None;
        let inner = make!(n, N => typed::<N>(self, &mut centres), _ => too_many(n))?;
        let basis = centres.map_or(Basis::Default, Basis::Centres);
        Ok(Scenario::of(inner, self.law, basis))
    }
}

/// The error of an inertia of another number of values than K n².
const INERTIA_SHAPE: Error = Error::Invalid {
    what: "inertia",
    reason: "needs n × n values (n: tau_max's), or K ≥ 1 matrices of n × n along a path",
};

/// The inertia-shaped scale of SPEC (18.12) along `ds`: Dₛ = (mean D⁻¹)⁻¹,
/// and λmax of Dₛ^½ D⁻¹ Dₛ^½ over the samples (as Lᵀ D⁻¹ L, Dₛ = L Lᵀ:
/// the same eigenvalues), bounded from above within 1 %.
fn coupled_scale<const N: usize>(ds: &[Matrix<N>]) -> Result<(Matrix<N>, f64), Error> {
    let spd = Error::Invalid {
        what: "inertia matrix",
        reason: "must be positive definite",
    };
    let inverses = ds
        .iter()
        .map(|d| d.cholesky().map(|c| c.inverse()).ok_or(spd))
        .collect::<Result<Vec<_>, _>>()?;
    let mean = inverses.iter().fold(Matrix::<N>::zeros(), |a, b| a + b) / inverses.len() as f64;
    let scale = mean.cholesky().ok_or(spd)?.inverse();
    let l = scale.cholesky().ok_or(spd)?.l();
    let mut largest = 0.0f64;
    for inv in &inverses {
        let m = l.transpose() * inv * l;
        largest = largest.max(largest_eigenvalue(&((m + m.transpose()) * 0.5)));
    }
    Ok((scale, largest))
}

/// [`Tuning::suggest`] for N joints: the scenario, and the centres into `centres`.
fn typed<const N: usize>(
    t: &Tuning<'_>,
    centres: &mut Option<Centres>,
) -> Result<Box<schema::Scenario<N>>, Error> {
    let (flat, along) = match t.inertia {
        Inertia::At(d) => (d, false),
        Inertia::Along(d) => (d, true),
    };
    if flat.is_empty() || flat.len() % (N * N) != 0 || (!along && flat.len() != N * N) {
        return Err(INERTIA_SHAPE);
    }
    let mut rule = Rule::default().with_delay(t.delay)?;
    if t.weightless {
        rule = rule.weightless();
    }
    if t.critical {
        check::positive("Ts > 0", "Ts", t.ts)?;
        rule = rule.critical(t.ts);
    }
    // Row-major into nalgebra's column-major: D is symmetric, but a
    // non-symmetric input must be reported, not transposed silently.
    let ds: Vec<Matrix<N>> = flat
        .chunks_exact(N * N)
        .map(Matrix::<N>::from_row_slice)
        .collect();
    let scales = if along {
        inertia_scales_along(&ds)
    } else {
        inertia_scales(&ds[0])
    }?;
    // SPEC (18.11): the margin at the largest mode of the undamped scales;
    // (18.12): of the inertia-shaped scale's, when coupled.
    let shaped = t.coupled().then(|| coupled_scale(&ds)).transpose()?;
    rule = rule.bounded(match &shaped {
        Some((_, lmax)) => *lmax,
        None => loop_bound(&ds, &scales)?,
    });
    let undamped = scales;
    let scales = match t.damping {
        None => scales,
        Some(b) => damped_scales(&scales, &vector::<N>("damping", b)?, t.ts)?,
    };
    // (18.12): the damping's reduction of (18.9) per joint, as a congruence.
    let shaped = shaped.map(|(m, _)| {
        let c = Matrix::<N>::from_diagonal(&scales.zip_map(&undamped, |a, b| libm::sqrt(a / b)));
        let m = c * m * c;
        // Exactly symmetric: its row-major and column-major layouts agree.
        (m + m.transpose()) * 0.5
    });
    let tau = vector::<N>("tau_max", t.tau_max)?;
    // What is read with a path only is refused without one, not ignored.
    if t.path.is_none() {
        for (what, given) in [
            ("orbit", t.orbit.is_some()),
            ("gravity", t.gravity.is_some()),
        ] {
            if given {
                return Err(Error::Invalid {
                    what,
                    reason: "is read with the task's path only: give the path too",
                });
            }
        }
    }
    if let Some(o) = t.orbit {
        if o.is_empty() || !o.len().is_multiple_of(N) {
            return Err(Error::Invalid {
                what: "orbit",
                reason: "needs one row of n joint positions or more",
            });
        }
        // Row-major K' × n: the element (row, joint) is o[n row + joint].
        check::finite_slice("orbit", o)?;
    }
    let mut s = schema::Scenario::<N>::preset(Preset::Robot, t.law);
    match &t.path {
        None => s.config = rule.gains_scaled(t.law, &scales, &tau, t.ts)?,
        Some(p) => {
            if !p.rows.len().is_multiple_of(3 * N) {
                return Err(length("path"));
            }
            let samples: Vec<Setpoint<N>> = p
                .rows
                .chunks_exact(3 * N)
                .map(|r| Setpoint {
                    x: Vector::from_column_slice(&r[..N]),
                    dx: Vector::from_column_slice(&r[N..2 * N]),
                    ddx: Vector::from_column_slice(&r[2 * N..]),
                })
                .collect();
            if t.resolve && !samples.is_empty() {
                let learn_dc = rule.learn_dc;
                rule = resolving(&rule, &samples);
                if shaped.is_some() {
                    rule = shaped_orbit(&rule);
                }
                if t.weightless {
                    // (22.2): D̂ and Ĉ at Ĝ's bandwidth, whatever the orbit.
                    rule.learn_dc = learn_dc;
                }
            }
            if let Some(o) = t.orbit {
                let qs: Vec<Vector<N>> = o.chunks_exact(N).map(Vector::from_column_slice).collect();
                rule = rule.spanning(&qs);
            }
            let g = t.gravity.map(|g| vector::<N>("gravity", g)).transpose()?;
            let sug =
                rule.suggest_scaled(t.law, &scales, &tau, t.ts, &samples, p.period, g.as_ref())?;
            s.config = sug.config;
            *centres = Some(Centres::of(&sug.centers));
        }
    }
    s.config.inertia_matrix = shaped;
    Ok(Box::new(s))
}

/// The default task of SPEC §18 about `home` within [`lo`, `hi`] (rad, n
/// values each; ±∞ for a continuous joint): the const-generic
/// [`default_task`](crate::control::tuning::default_task)'s sinusoid as its
/// offset, sine and cosine amplitudes (rad) and angular frequencies
/// (rad/s), the controller's `xc_*` parameters. Its errors, and one naming
/// `lo` or `hi` of another length than `home`.
pub fn default_task(home: &[f64], lo: &[f64], hi: &[f64]) -> Result<[Joints; 4], Error> {
    let n = home.len();
    crate::with_joints!(n, N => {
        let t = crate::control::tuning::default_task(
            &vector::<N>("home", home)?,
            &vector::<N>("lo", lo)?,
            &vector::<N>("hi", hi)?,
        )?;
        Ok([t.offset(), t.sin_amplitude(), t.cos_amplitude(), t.omega()].map(Joints::of))
    }, _ => Err(too_many(n)))
}
