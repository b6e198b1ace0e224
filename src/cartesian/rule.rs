//! The Cartesian rule, SPEC §16 (16.8)–(16.10): a pose task for any arm, the
//! start posture it is run from, and the basis that resolves its joint orbit.
//!
//! What a user of a new arm wants from "Cartesian in five lines" is what the
//! joint-space rule of SPEC §18 gives in joint space: a task that moves the
//! arm, a posture to run it from, and the joint controller's gains, centres
//! and learning, with nothing set per arm.
//!
//! - [`PoseCircle`] (16.8) is the default task: hold the start pose, then a
//!   circle in the horizontal plane through it, the orientation held.
//! - [`PostureRule`] (16.9) says whether a posture can run a task: the
//!   6 × N Jacobian well-conditioned along the task ([`sigma_min`]), the
//!   joint limits kept with a margin, gravity well within the actuators, the
//!   sampled velocity loop of the joint rule well-conditioned
//!   ([`loop_conditioning`]), the task reachable (the inverse kinematics on
//!   it). Each refusal names its condition.
//! - [`resolving`] (16.10) narrows the joint rule's tube to the orbit's own
//!   size, so that the RBF basis resolves a small orbit as it resolves the
//!   joint-space task.
//!
//! Everything here is `no_std` and allocation-free.

use crate::cartesian::kinematics::Kinematics;
use crate::cartesian::outer::PoseTarget;
use crate::cartesian::rotation;
use crate::control::tuning::Rule;
use crate::error::{check, Error};
use crate::trajectory::Setpoint;
use crate::types::{Matrix, Vector};
use core::fmt;
use nalgebra::Matrix3;

/// The default Cartesian task, SPEC (16.8): hold the start pose for `hold`
/// s, then a circle of `radius` (m) at `freq` (Hz) in a plane through the
/// start, the orientation held; the angular speed ramps from zero (a quintic)
/// over `ramp` s, so the path starts at rest. The plane is horizontal (its
/// normal the world z axis), or a planar arm's own ([`plane_normal`]). The
/// circle passes through the start and its centre lies `radius` from it
/// toward the base's axis (the line through the world origin along the
/// normal; along x, or y for a normal along x, for a start on that line): the
/// circle stays inside the reach of the start.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PoseCircle {
    start: Vector<3>,
    rotation: Matrix3<f64>,
    radius: f64,
    freq: f64,
    hold: f64,
    ramp: f64,
    /// Unit vectors of the plane: `u` from the start toward the centre, `v`
    /// = normal × u.
    u: Vector<3>,
    v: Vector<3>,
}

impl PoseCircle {
    /// The default radius (m): 3 cm.
    pub const RADIUS: f64 = 0.03;
    /// The default frequency (Hz): a period of 2 s.
    pub const FREQ: f64 = 0.5;
    /// The default hold (s).
    pub const HOLD: f64 = 1.0;
    /// The default ramp of the angular speed (s).
    pub const RAMP: f64 = 1.0;

    /// The default task about the start pose `start` (m), `rotation` (world ←
    /// tip). Errors for a non-finite start or a rotation that is not one.
    pub fn new(start: Vector<3>, rotation: Matrix3<f64>) -> Result<Self, Error> {
        Self::with(
            start,
            rotation,
            Self::RADIUS,
            Self::FREQ,
            Self::HOLD,
            Self::RAMP,
        )
    }

    /// The task with its own `radius` (m, > 0), `freq` (Hz, > 0), `hold` and
    /// `ramp` (s, ≥ 0), in the horizontal plane. Errors name the quantity.
    pub fn with(
        start: Vector<3>,
        rotation: Matrix3<f64>,
        radius: f64,
        freq: f64,
        hold: f64,
        ramp: f64,
    ) -> Result<Self, Error> {
        Self::in_plane(
            start,
            rotation,
            Vector::<3>::new(0.0, 0.0, 1.0),
            radius,
            freq,
            hold,
            ramp,
        )
    }

    /// [`with`](Self::with) in the plane of the unit `normal` (world frame;
    /// normalised here; finite and non-zero, else an error naming it).
    #[allow(clippy::too_many_arguments)]
    pub fn in_plane(
        start: Vector<3>,
        rotation: Matrix3<f64>,
        normal: Vector<3>,
        radius: f64,
        freq: f64,
        hold: f64,
        ramp: f64,
    ) -> Result<Self, Error> {
        check::finite_slice("start", start.as_slice())?;
        rotation::rotation("rotation", &rotation)?;
        check::positive("radius > 0", "radius", radius)?;
        check::positive("freq > 0", "freq", freq)?;
        check::nonnegative("hold ≥ 0", "hold", hold)?;
        check::nonnegative("ramp ≥ 0", "ramp", ramp)?;
        check::finite_slice("normal", normal.as_slice())?;
        let length = normal.norm();
        if length <= 0.0 {
            return Err(Error::Invalid {
                what: "normal",
                reason: "must be a non-zero vector (the circle's plane)",
            });
        }
        let n = normal / length;
        let (u, v) = if n == Vector::<3>::new(0.0, 0.0, 1.0) {
            // The horizontal plane (every arm that is not planar).
            let radial = Vector::<3>::new(start[0], start[1], 0.0);
            let r = radial.norm();
            let u = if r > 1e-3 {
                -radial / r
            } else {
                Vector::<3>::new(1.0, 0.0, 0.0)
            };
            (u, Vector::<3>::new(-u[1], u[0], 0.0))
        } else {
            let radial = start - n.dot(&start) * n;
            let r = radial.norm();
            let u = if r > 1e-3 {
                -radial / r
            } else {
                plane_axes(&n).0 // any direction of the plane
            };
            (u, n.cross(&u))
        };
        Ok(Self {
            start,
            rotation,
            radius,
            freq,
            hold,
            ramp,
            u,
            v,
        })
    }

    /// The part of the path a rule samples (s): the hold, the ramp and one
    /// period, `hold + ramp + 1/freq`.
    pub fn span(&self) -> f64 {
        self.hold + self.ramp + 1.0 / self.freq
    }

    /// The circle's centre (m).
    pub fn centre(&self) -> Vector<3> {
        self.start + self.radius * self.u
    }

    /// The commanded pose at `t` (s): p, ṗ, p̈ on the circle (m, m/s, m/s²),
    /// the start's rotation at rest. The phase φ runs from π (the start) with
    /// φ̇ = ω s(τ), s the quintic 10τ³ − 15τ⁴ + 6τ⁵ of τ = (t − hold)/ramp,
    /// so φ = π + ω·ramp·(2.5τ⁴ − 3τ⁵ + τ⁶) over the ramp, then ω = 2π·freq.
    pub fn sample(&self, t: f64) -> PoseTarget {
        let w = 2.0 * core::f64::consts::PI * self.freq;
        let s = t - self.hold;
        if s <= 0.0 {
            // The hold: the start pose itself, at rest (not centre + r·(−u),
            // which rounds).
            return PoseTarget::at(self.start, self.rotation);
        }
        let (phi, dphi, ddphi) = if s < self.ramp {
            let x = s / self.ramp;
            (
                core::f64::consts::PI + w * self.ramp * x * x * x * x * (2.5 - 3.0 * x + x * x),
                w * x * x * x * (10.0 - 15.0 * x + 6.0 * x * x),
                w * 30.0 * x * x * (1.0 - x) * (1.0 - x) / self.ramp,
            )
        } else {
            (core::f64::consts::PI + w * (s - 0.5 * self.ramp), w, 0.0)
        };
        let (sn, c) = (crate::math::sin(phi), crate::math::cos(phi));
        let radial = c * self.u + sn * self.v;
        let tangent = -sn * self.u + c * self.v;
        let r = self.radius;
        PoseTarget {
            p: self.centre() + r * radial,
            dp: r * dphi * tangent,
            ddp: r * ddphi * tangent - r * dphi * dphi * radial,
            ..PoseTarget::at(self.start, self.rotation)
        }
    }
}

/// How well a posture can run a task, SPEC (16.9): the figures along the
/// task's joint orbit (the inverse kinematics of the path from the posture,
/// F_e = 0), each the worst over the orbit.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Assessment {
    /// The smallest σmin(J) (m/rad) of the task's rows ([`sigma_min`]).
    pub sigma_min: f64,
    /// The largest gravity load max_i |G_i|/τmax_i.
    pub load: f64,
    /// λmin(Dₛ^½ D⁻¹ Dₛ^½) at the start ([`loop_conditioning`]).
    pub conditioning: f64,
    /// The smallest distance (rad) from a joint to its limit, less the
    /// margin the rule keeps there (negative: inside the margin).
    pub slack: f64,
    /// The joint of `slack`.
    pub slack_joint: usize,
    /// The largest distance (m) from the commanded position to the tip of
    /// the joint orbit: the task is reachable from the posture when small.
    pub reach: f64,
}

/// The conditions a start posture meets, SPEC (16.9) ([`Default`]: the
/// SPEC's).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct PostureRule {
    /// σmin(J) ≥ this along the task (m/rad): 0.05.
    pub sigma_min: f64,
    /// max_i |G_i|/τmax_i ≤ this along the task: 0.5 (the joint-space
    /// home's, SPEC §18).
    pub load: f64,
    /// λmin(Dₛ^½ D⁻¹ Dₛ^½) ≥ this at the start: 0.2 = K1·Ts/m of the joint
    /// rule at 1 kHz (the slowest mode of the velocity loop no slower than
    /// the position loop).
    pub conditioning: f64,
    /// Each joint stays min(this, range/8) (rad) inside its limits along the
    /// task: 0.1.
    pub margin: f64,
    /// The task's tip within this (m) of the commanded position along the
    /// joint orbit: 1 mm.
    pub reach: f64,
}

impl Default for PostureRule {
    fn default() -> Self {
        Self {
            sigma_min: 0.05,
            load: 0.5,
            conditioning: 0.2,
            margin: 0.1,
            reach: 1e-3,
        }
    }
}

impl PostureRule {
    /// The rule for a joint controller whose position loop runs at `k1`
    /// (1/s) with the velocity loop of `rule` at period `ts` (s): the
    /// conditioning threshold K1·Ts/m (0.2 for the joint rule's K1 = 50 s⁻¹
    /// at 1 kHz, 0.04 for the contact scenario's K1 = 10 s⁻¹, SPEC (19.6)).
    pub fn for_loop(k1: f64, ts: f64, rule: &Rule) -> Self {
        Self {
            conditioning: k1 * ts / rule.margin,
            ..Self::default()
        }
    }

    /// The margin (rad) joint i keeps inside [`lo`, `hi`]: min(margin,
    /// (hi − lo)/8) (the margin alone for an unlimited joint).
    pub fn margin_of(&self, lo: f64, hi: f64) -> f64 {
        let range = hi - lo;
        if range.is_finite() {
            self.margin.min(range / 8.0)
        } else {
            self.margin
        }
    }

    /// The [`Assessment`] of the joint orbit `orbit` (the joint reference of
    /// every sample, from the start), with `targets` the commanded positions
    /// (m) of the same samples, `gravity` G (N m) at each sample, `d0` the
    /// inertia matrix at the start (kg m²), the limits [`lo`, `hi`] (rad;
    /// ±∞: unlimited) and `tau_max` (N m). `orients`: the task holds the
    /// orientation (σmin of the 6 × N Jacobian; else of its translation
    /// rows; [`TaskRows`] for a planar arm's task). Errors for empty or
    /// mismatched samples, non-finite values, a `d0` that is not symmetric
    /// positive definite, τmax ≤ 0.
    #[allow(clippy::too_many_arguments)]
    pub fn assess<const N: usize, K: Kinematics<N>>(
        &self,
        kin: &K,
        task: impl Into<TaskRows>,
        orbit: &[Vector<N>],
        targets: &[Vector<3>],
        gravity: &[Vector<N>],
        d0: &Matrix<N>,
        (lo, hi): (&Vector<N>, &Vector<N>),
        tau_max: &Vector<N>,
    ) -> Result<Assessment, Error> {
        if orbit.is_empty() || targets.len() != orbit.len() || gravity.len() != orbit.len() {
            return Err(Error::Invalid {
                what: "posture assessment",
                reason:
                    "needs one target and one gravity torque per sample of the orbit (one or more)",
            });
        }
        check::positive_vec("τmax > 0", "tau_max", tau_max)?;
        let task = task.into();
        let mut a = Assessment {
            sigma_min: f64::INFINITY,
            load: 0.0,
            conditioning: loop_conditioning(d0)?,
            slack: f64::INFINITY,
            slack_joint: 0,
            reach: 0.0,
        };
        for ((q, p), g) in orbit.iter().zip(targets).zip(gravity) {
            check::finite_slice("orbit", q.as_slice())?;
            check::finite_slice("targets", p.as_slice())?;
            check::finite_slice("gravity", g.as_slice())?;
            let tip = kin.tip(q, &Vector::zeros());
            a.sigma_min = a.sigma_min.min(task.sigma_min(&tip.jacobian));
            a.reach = a.reach.max((tip.position - p).norm());
            for i in 0..N {
                a.load = a.load.max(g[i].abs() / tau_max[i]);
                let room = (q[i] - lo[i]).min(hi[i] - q[i]) - self.margin_of(lo[i], hi[i]);
                if room < a.slack {
                    a.slack = room;
                    a.slack_joint = i;
                }
            }
        }
        Ok(a)
    }

    /// Whether `a` meets the rule: the first condition it violates
    /// ([`Refusal`]: the condition with its bound, the value measured).
    pub fn check(&self, a: &Assessment) -> Result<(), Refusal> {
        for condition in Condition::ALL {
            let (value, joint) = condition.value(a);
            let threshold = condition.threshold(self);
            let met = match condition {
                Condition::Slack => value >= threshold,
                Condition::Load | Condition::Reach => value <= threshold,
                Condition::Singular | Condition::Conditioning => value >= threshold,
            };
            if !met {
                return Err(Refusal {
                    condition,
                    value,
                    threshold,
                    joint,
                    margin: self.margin,
                });
            }
        }
        Ok(())
    }

    /// What each condition needs, with the best value `best` reached (the
    /// assessment of the posture closest to passing on each condition, one
    /// condition at a time): for a refusal that says what a start would need.
    pub fn needs<'a>(&'a self, best: &'a Assessment) -> Needs<'a> {
        Needs { rule: self, best }
    }

    /// A score to rank postures that pass [`check`](Self::check) (larger is
    /// better): σmin(J)·(1 − load), the distance from a singularity
    /// discounted by the share of the actuators gravity takes.
    pub fn score(&self, a: &Assessment) -> f64 {
        a.sigma_min * (1.0 - a.load)
    }
}

/// A condition of the posture rule, SPEC (16.9), in the order it is checked.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Condition {
    /// σmin(J) ≥ [`PostureRule::sigma_min`] along the task.
    Singular,
    /// Every joint inside its limits by its margin along the task.
    Slack,
    /// The gravity load ≤ [`PostureRule::load`] along the task.
    Load,
    /// λmin(Dₛ^½ D⁻¹ Dₛ^½) ≥ [`PostureRule::conditioning`] at the start.
    Conditioning,
    /// The inverse kinematics within [`PostureRule::reach`] of the path.
    Reach,
}

impl Condition {
    /// Every condition, in the order [`PostureRule::check`] checks them.
    pub const ALL: [Condition; 5] = [
        Condition::Singular,
        Condition::Slack,
        Condition::Load,
        Condition::Conditioning,
        Condition::Reach,
    ];

    /// The value of `a` this condition bounds, and the joint it is at (for
    /// the limits' slack).
    pub fn value(self, a: &Assessment) -> (f64, Option<usize>) {
        match self {
            Condition::Singular => (a.sigma_min, None),
            Condition::Slack => (a.slack, Some(a.slack_joint)),
            Condition::Load => (a.load, None),
            Condition::Conditioning => (a.conditioning, None),
            Condition::Reach => (a.reach, None),
        }
    }

    /// Its bound in `rule`.
    pub fn threshold(self, rule: &PostureRule) -> f64 {
        match self {
            Condition::Singular => rule.sigma_min,
            Condition::Slack => 0.0,
            Condition::Load => rule.load,
            Condition::Conditioning => rule.conditioning,
            Condition::Reach => rule.reach,
        }
    }

    /// What the condition is, for a reader (with `threshold` and the limits'
    /// `margin`, rad).
    fn describe(self, f: &mut fmt::Formatter<'_>, threshold: f64, margin: f64) -> fmt::Result {
        match self {
            Condition::Singular => {
                write!(f, "σmin(J) ≥ ")?;
                significant(f, threshold)?;
                write!(f, " m/rad along the task (not near a singularity)")
            }
            Condition::Slack => {
                write!(f, "every joint min(")?;
                significant(f, margin)?;
                write!(f, " rad, range/8) inside its limits along the task")
            }
            Condition::Load => {
                write!(f, "gravity load max_i |G_i|/τmax_i ≤ ")?;
                significant(f, threshold)?;
                write!(f, " along the task (gravity within the actuators)")
            }
            Condition::Conditioning => {
                write!(
                    f,
                    "velocity-loop conditioning λmin(Dₛ^½ D⁻¹ Dₛ^½) ≥ K1·Ts/m = "
                )?;
                significant(f, threshold)?;
                write!(f, " at the start")
            }
            Condition::Reach => {
                write!(f, "the path reachable: the inverse kinematics within ")?;
                significant(f, threshold)?;
                write!(f, " m of it")
            }
        }
    }

    /// The quantity measured, as a refusal names it.
    fn quantity(self) -> &'static str {
        match self {
            Condition::Singular => "σmin(J)",
            Condition::Slack => "distance to the limit − margin (rad), joint",
            Condition::Load => "gravity load",
            Condition::Conditioning => "λmin",
            Condition::Reach => "largest distance from the path (m)",
        }
    }
}

/// A condition of the posture rule a posture violates (SPEC (16.9)): the
/// condition with its bound, the value measured (and the joint, for the
/// limits). Its text: `condition <the condition, with its bound> is violated:
/// <quantity> = <value>`.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Refusal {
    /// The condition violated.
    pub condition: Condition,
    /// The value measured.
    pub value: f64,
    /// The bound the rule needs.
    pub threshold: f64,
    /// The joint of the limits' slack.
    pub joint: Option<usize>,
    /// The rule's margin inside the limits (rad).
    pub margin: f64,
}

impl fmt::Display for Refusal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "condition ")?;
        self.condition.describe(f, self.threshold, self.margin)?;
        write!(f, " is violated: {}", self.condition.quantity())?;
        if let Some(i) = self.joint {
            write!(f, "[{i}]")?;
        }
        write!(f, " = ")?;
        significant(f, self.value)?;
        write!(f, " (SPEC (16.9))")
    }
}

#[cfg(feature = "std")]
impl std::error::Error for Refusal {}

/// [`PostureRule::needs`]: each condition with its bound and the best value
/// reached, `; `-separated.
pub struct Needs<'a> {
    rule: &'a PostureRule,
    best: &'a Assessment,
}

impl fmt::Display for Needs<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, c) in Condition::ALL.into_iter().enumerate() {
            if i > 0 {
                write!(f, "; ")?;
            }
            c.describe(f, c.threshold(self.rule), self.rule.margin)?;
            let (value, joint) = c.value(self.best);
            if !value.is_finite() {
                // No start got as far as this condition (every path checked
                // diverged, or none was checked): no value to print.
                write!(f, " (none measured: no start checked along the task)")?;
                continue;
            }
            write!(f, " (best ")?;
            significant(f, value)?;
            if let (Condition::Slack, Some(j)) = (c, joint) {
                write!(f, " rad, joint {j}")?;
            }
            write!(f, ")")?;
        }
        Ok(())
    }
}

/// `x` to four significant digits (as `%.4g`: 0.003976, 0.1781, 12.35,
/// 1.235e-05), without allocating.
fn significant(f: &mut fmt::Formatter<'_>, x: f64) -> fmt::Result {
    let a = x.abs();
    if !x.is_finite() {
        return write!(f, "{x}");
    }
    if a == 0.0 {
        return write!(f, "0");
    }
    if !(1e-4..1e4).contains(&a) {
        return write!(f, "{x:.3e}");
    }
    let mut decimals = 3usize;
    let mut scale = 1.0;
    while a < scale && decimals < 8 {
        scale /= 10.0;
        decimals += 1;
    }
    while a >= 10.0 * scale.max(1.0) && decimals > 0 {
        scale *= 10.0;
        decimals -= 1;
    }
    // Trailing zeros dropped, as %g does.
    let mut buf = [0u8; 32];
    let mut w = Cursor {
        buf: &mut buf,
        len: 0,
    };
    fmt::write(&mut w, format_args!("{x:.decimals$}"))?;
    let len = w.len;
    let text = core::str::from_utf8(&buf[..len]).map_err(|_| fmt::Error)?;
    let text = if text.contains('.') {
        text.trim_end_matches('0').trim_end_matches('.')
    } else {
        text
    };
    f.write_str(text)
}

/// A fixed buffer to format into without allocating.
struct Cursor<'a> {
    buf: &'a mut [u8],
    len: usize,
}

impl fmt::Write for Cursor<'_> {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        let end = self.len + s.len();
        if end > self.buf.len() {
            return Err(fmt::Error);
        }
        self.buf[self.len..end].copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}

/// The joint rule's constants with the tube narrowed to the orbit, SPEC
/// (16.10): tube_b = min(tube_b, ℓ_b/10), ℓ_q (rad) and ℓ_q̇ (rad/s) the
/// lengths of the closed path `path` in q and in q̇. The joint-space default
/// task of SPEC §18 (±0.2 rad on every joint, ℓ_q ≈ 2 rad, ℓ_q̇ ≈ 6 rad/s)
/// sits at the caps (0.2 rad, 0.5 rad/s); a Cartesian circle's joint orbit
/// (ℓ_q ≈ 0.5–1.7 rad) gets the same number of distinct nodes along it.
/// With a loop delay δ ≥ 1 (SPEC (18.11)), D̂ and Ĉ learn δ + 1 times
/// further inside Ĝ's bandwidth on such an orbit: its slow joint motion
/// leaves their regressors α̇1, α1 to the velocity errors of the delayed
/// loop, and at (18.6)'s ω_G/5 they rang on three arms (so without the
/// joint task's [`Rule::dc_boost`]: ω_D = ω_C = ω_G/(5(δ + 1)) of the
/// delayed loop's ω_G).
pub fn resolving<const N: usize>(rule: &Rule, path: &[Setpoint<N>]) -> Rule {
    let (mut lq, mut lv) = (0.0, 0.0);
    for (j, sp) in path.iter().enumerate() {
        let next = &path[(j + 1) % path.len()];
        lq += (next.x - sp.x).norm();
        lv += (next.dx - sp.dx).norm();
    }
    let mut out = *rule;
    for (t, l) in out.tube.iter_mut().zip([lq, lv]) {
        let narrow = l / RESOLUTION;
        if narrow.is_finite() && narrow > 0.0 {
            *t = t.min(narrow);
        }
    }
    if rule.delay > 0 {
        out.learn_dc /= rule.delay as f64 + 1.0;
        // Of the delayed loop's ω_G: not the joint task's undelayed ω_D.
        out.dc_boost = 1.0;
    }
    out
}

/// ℓ_b / tube_b of [`resolving`]: the orbit's length in tube widths (10).
pub const RESOLUTION: f64 = 10.0;

/// The rule of the inertia-shaped gains on a Cartesian task's orbit, SPEC
/// (18.12), "On an orbit": [`resolving`]'s, with Ĝ learning at ω_G² at least
/// (m/Ts) K1 ([`Rule::learn`] at least [`SHAPED_ORBIT_LEARN`]; twice (18.6)'s
/// ½, the critical rule's 1.03 kept). The joints that hold the hand's
/// orientation barely move on the orbit; their Coulomb friction flips with
/// the sign of their small velocity, and Ĝ(q) learns that step at ω_G: at
/// (18.6)'s ω_G the error it leaves was the orientation's floor. The
/// diagonal gains keep (18.6)'s ω_G (at 2× two arms rang at δ = 1).
pub fn shaped_orbit(rule: &Rule) -> Rule {
    Rule {
        learn: rule.learn.max(SHAPED_ORBIT_LEARN),
        ..*rule
    }
}

/// The least [`Rule::learn`] of [`shaped_orbit`]: ω_G² = (m/Ts) K1, the
/// geometric mean of the velocity and position loops' rates squared.
pub const SHAPED_ORBIT_LEARN: f64 = 1.0;

mod measures;
use measures::plane_axes;
pub use measures::{loop_conditioning, plane_normal, sigma_min, sigma_min_in_plane, TaskRows};

#[cfg(test)]
mod tests;
