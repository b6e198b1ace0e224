//! Gains, a basis and learning rates for an arm nobody tuned for, SPEC §18.
//!
//! What a user knows about a new arm: its inertia matrix D(q0) at a posture
//! (any URDF through Pinocchio or MuJoCo gives it), the actuator limits τmax,
//! the period Ts and the task's joint path. [`Rule`] turns these into a
//! [`Config`] that construction accepts, in each joint's own units (SPEC §10:
//! d_i = 1/(D⁻¹(q0))_ii, every rate in 1/s):
//!
//! ```text
//! Kp_i = m d_i / Ts,   m = 0.25                          (18.1)
//! K1   = min(50 s⁻¹, 0.2 m / Ts)                        (18.2)
//! Kζ_i = Kp_i/d_i + ρ/2,  ρ = 1 s⁻¹  (conditions "scaled") (18.3)
//! kr_i = φ Kp_i / 2,  Kd_i (fallback) = Kp_i             (18.4)
//! ```
//!
//! and, for a basis along the path ([`Rule::centres`], SPEC §15), the
//! learning of [`Rule::learning`]:
//!
//! ```text
//! Γ_G = ω_G² / ⟨‖S‖²⟩,  ω_G² = ½ (m/Ts) K1               (18.6)
//! Γ_D = (ω_G/5)² / (⟨‖S‖²⟩ ⟨‖ẍc‖²⟩),  Γ_C = (ω_G/5)² / (⟨‖S‖²⟩ ⟨‖ẋc‖²⟩)
//! σ = 1 / (Γ τ_leak),  τ_leak = 25 periods                (18.7)
//! b_G = 2 ‖τmax‖ √L / min ΣS_j,  b_D = b_G / max‖ẍc‖,  b_C = b_G / max‖ẋc‖  (18.8)
//! ```
//!
//! (⟨·⟩ the mean, min and max over the path; ‖ẍc‖ and ‖ẋc‖ floored at 1
//! rad/s² and 1 rad/s). The reasons are in SPEC §18.
//! [`default_task`] is the joint-space motion `adaptimp.mujoco.simulate` runs
//! when given only a model.

use crate::control::config::{Conditions, Config, Law, WeightBound, MAX_DELAY};
use crate::control::controller::MIN_SCALE;
use crate::error::{check, Error, PARAM_BOUND};
use crate::math::sqrt;
use crate::networks::rbf::{Basis, Centers};
#[cfg(feature = "alloc")]
use crate::trajectory::Trajectory;
use crate::trajectory::{Setpoint, Sinusoid};
use crate::types::{Matrix, Vector};

/// The damping ratio ζ of the learning loop's pair in [`Rule::critical`]
/// (1.1: just overdamped), SPEC (19.6).
pub const LEARN_DAMPING: f64 = 1.1;

/// The robust term's slope kr/φ as a share of Kp, (18.4): kr = s φ Kp.
pub const ROBUST_SHARE: f64 = 0.5;

/// The pole radius r_δ the sampled velocity loop of a loop of `delay`
/// periods keeps in its largest mode, SPEC (18.11): 1 − m = 0.75, the
/// undelayed rule's pole (18.1), or, where a δ-periods-late loop cannot
/// reach it (its fastest pole is δ/(δ+1): δ ≥ 3), halfway from there to
/// the unit circle, (2δ + 1)/(2δ + 2).
pub fn pole_radius(delay: usize) -> f64 {
    let d = delay as f64;
    (1.0 - Rule::default().margin).max((2.0 * d + 1.0) / (2.0 * d + 2.0))
}

/// The largest per-period gain g of the sampled velocity loop of a loop of
/// `delay` periods whose poles stay within [`pole_radius`], SPEC (18.11):
/// the roots of z^(δ+1) − z^δ + g = 0 (one joint, unit inertia scale: the
/// torque −g d/Ts · v of sample k acts over period k + δ) lie in |z| ≤ r
/// for g ∈ [r^δ (1 − r), g_δ]. δ = 0: g = 1 + r (the real root at −r);
/// δ ≥ 1: a complex pair reaches |z| = r at z = r e^(iθ) with
/// δθ + arg(r e^(iθ) − 1) = π, θ ∈ (0, π), and g = r^δ |r e^(iθ) − 1|
/// (θ by bisection to machine precision). δ = 1: r², 0.5625.
pub fn loop_gain(delay: usize) -> f64 {
    let r = pole_radius(delay);
    if delay == 0 {
        return 1.0 + r;
    }
    let d = delay as f64;
    let f = |th: f64| {
        let (s, c) = (libm::sin(th), libm::cos(th));
        d * th + libm::atan2(r * s, r * c - 1.0) - core::f64::consts::PI
    };
    // f < 0 just above 0 (r/(1 − r) > δ by pole_radius), f(π) = δπ > 0.
    let (mut lo, mut hi) = (1e-12, core::f64::consts::PI);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= f64::EPSILON * hi {
            break;
        }
    }
    let th = 0.5 * (lo + hi);
    let (s, c) = (libm::sin(th), libm::cos(th));
    libm::pow(r, d) * libm::hypot(r * c - 1.0, r * s)
}

/// The largest mode of the sampled velocity loop along a path, SPEC
/// (18.11): max over the samples `ds` (D(q_k), kg m²) of λmax(Dₛ^½ D(q_k)⁻¹
/// Dₛ^½) for the scales `scales` (Dₛ = diag(d), kg m²; ≤ N for the scales
/// of [`inertia_scales_along`]), bounded from above within 1 %. Errors if
/// `ds` is empty or a sample is not symmetric positive definite.
pub fn loop_bound<const N: usize>(ds: &[Matrix<N>], scales: &Vector<N>) -> Result<f64, Error> {
    if ds.is_empty() {
        return Err(Error::Invalid {
            what: "inertia samples",
            reason: "needs one posture or more",
        });
    }
    check::positive_vec("inertia scale > 0", "inertia scale", scales)?;
    let root = scales.map(sqrt);
    let mut largest = 0.0f64;
    for d in ds {
        inertia_scales(d)?;
        let inv = d.cholesky().map(|c| c.inverse()).ok_or(Error::Invalid {
            what: "inertia matrix",
            reason: "must be positive definite",
        })?;
        let m = Matrix::<N>::from_fn(|i, j| root[i] * inv[(i, j)] * root[j]);
        largest = largest.max(largest_eigenvalue(&m));
    }
    Ok(largest)
}

/// The smallest and largest number of centres [`Rule::nodes`] gives.
pub const NODES: (usize, usize) = (16, 256);

/// Samples of one period of a [`Trajectory`] the alloc conveniences take.
pub const PATH_SAMPLES: usize = 1000;

/// The constants of the rule, SPEC §18 ([`Rule::default`] is the SPEC's):
/// the diagonal gains of (18.1)–(18.11). The inertia-shaped gains of (18.12),
/// the default of the run-time rule for a joint task with a delay, are
/// `dynamic::Tuning`'s.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Rule {
    /// m of Kp_i = m d_i/Ts: each joint's sampled velocity loop keeps its
    /// pole at 1 − m (0.25).
    pub margin: f64,
    /// The largest K1 (1/s) (50).
    pub k1_max: f64,
    /// K1 ≤ this · m/Ts: the position loop 5× inside the velocity loop's
    /// rate a = m/Ts (0.2; K1 ≤ 0.05/Ts at the rule's m = 0.25).
    pub k1_share: f64,
    /// ω_G² = this · (m/Ts) · K1: the Ĝ loop's slow pole near K1/3 (0.5).
    pub learn: f64,
    /// ω_D = ω_C = this · ω_G: D̂ and Ĉ learn slower than Ĝ (0.2).
    pub learn_dc: f64,
    /// The leak time τ_leak in periods of the path (25).
    pub leak_periods: f64,
    /// How far from the path the networks act, (rad, rad/s) ((0.2, 0.5)).
    pub tube: [f64; 2],
    /// The factor on the smallest bound that realises τmax (2).
    pub bound_margin: f64,
    /// The smallest width in q (rad) of the centres along the path, whatever
    /// their spacing: the diameter of the orbit that repeats, SPEC (19.11)
    /// ([`spanning`](Self::spanning); 0, none, by default).
    pub span: f64,
    /// The loop's delay δ (periods) the gains are made for, SPEC (18.11)
    /// (0 by default: the torque acts over the period its sample opens).
    pub delay: usize,
    /// The factor on ω_D = ω_C that [`bounded`](Self::bounded) sets when it
    /// slows the loop for a delay, SPEC (18.11): m/m_δ, so that D̂ and Ĉ keep
    /// the undelayed rule's bandwidth, at most Ĝ's (1 without a delay).
    pub dc_boost: f64,
}

impl Default for Rule {
    fn default() -> Self {
        Self {
            margin: 0.25,
            k1_max: 50.0,
            k1_share: 0.2,
            learn: 0.5,
            learn_dc: 0.2,
            leak_periods: 25.0,
            tube: [0.2, 0.5],
            bound_margin: 2.0,
            span: 0.0,
            delay: 0,
            dc_boost: 1.0,
        }
    }
}

/// The inertia scales d_i = 1/(D⁻¹)_ii (kg m²) of an inertia matrix `d`
/// (kg m², symmetric positive definite), SPEC §10: joint i's inertia with
/// the other joints free. Errors if `d` is not finite, not symmetric (to
/// 1e-9 relative) or not positive definite.
pub fn inertia_scales<const N: usize>(d: &Matrix<N>) -> Result<Vector<N>, Error> {
    check::finite_slice("inertia matrix", d.as_slice())?;
    let scale = d.amax();
    if (d - d.transpose()).amax() > 1e-9 * scale {
        return Err(Error::Invalid {
            what: "inertia matrix",
            reason: "must be symmetric",
        });
    }
    let inv = d
        .cholesky()
        .ok_or(Error::Invalid {
            what: "inertia matrix",
            reason: "must be positive definite",
        })?
        .inverse();
    let scales = inv.diagonal().map(|x| 1.0 / x);
    check::finite_slice("inertia scale", scales.as_slice())?;
    Ok(scales)
}

/// The inertia scales of an arm along a task's path, SPEC (18.1): the mean
/// over the samples `ds` (D(q_k), kg m², symmetric positive definite) of
/// each posture's scales d_i(q_k) = 1/(D(q_k)⁻¹)_ii, shrunk by one common
/// factor c = min(1, N / max_k λmax(D(q_k)⁻¹ Dₛ)), Dₛ = diag(d) (λmax bounded
/// from above within 1 %), so that at every sample the eigenvalues of
/// D⁻¹Dₛ stay ≤ N, the bound one posture's
/// own scales have (Dₛ^½ D⁻¹ Dₛ^½ has a unit diagonal). One posture's
/// scales collapse near a posture where joint axes line up (a joint's
/// motion is then absorbed by its neighbours: d_i ≪ D_ii), and gains from
/// such a posture are too small along the rest of the path. Errors if `ds`
/// is empty or a sample is not an inertia matrix ([`inertia_scales`]).
pub fn inertia_scales_along<const N: usize>(ds: &[Matrix<N>]) -> Result<Vector<N>, Error> {
    if ds.is_empty() {
        return Err(Error::Invalid {
            what: "inertia samples",
            reason: "needs one posture or more",
        });
    }
    let mut mean = Vector::<N>::zeros();
    for d in ds {
        mean += inertia_scales(d)?;
    }
    mean /= ds.len() as f64;
    let root = mean.map(sqrt);
    let mut largest = 0.0f64;
    for d in ds {
        // d is positive definite (inertia_scales checked it).
        let inv = d.cholesky().map(|c| c.inverse()).ok_or(Error::Invalid {
            what: "inertia matrix",
            reason: "must be positive definite",
        })?;
        let m = Matrix::<N>::from_fn(|i, j| root[i] * inv[(i, j)] * root[j]);
        largest = largest.max(largest_eigenvalue(&m));
    }
    let cap = N as f64 / largest;
    let scales = if cap < 1.0 { mean * cap } else { mean };
    check::finite_slice("inertia scale", scales.as_slice())?;
    Ok(scales)
}

/// The inertia scales `scales` (kg m², each > 0) of joints with viscous
/// damping `damping` (N m s/rad, each ≥ 0, the plant's own) as the sampled
/// velocity loop at period `ts` (s) sees them, SPEC (18.9):
///
/// ```text
/// d̃_i = b_i Ts / (1 − e^(−β_i)),   β_i = b_i Ts / d_i
/// ```
///
/// Over one period a held torque τ moves a damped joint's velocity by
/// (1 − e^(−β)) τ/b where an undamped one moves by Ts τ/d: d̃ is the inertia
/// that answers a held torque as the damped joint does, so the rule's
/// Kp = m d̃/Ts takes the share m of the velocity error per period on either
/// (18.1). d̃ = d for b = 0 (bit for bit), d (1 + β/2 + O(β²)) for a damping
/// small against d/Ts, and b Ts for a joint its damping dominates (a
/// near-massless wrist). Errors if a scale is not finite and > 0, a damping
/// not finite and ≥ 0, or `ts` not finite and > 0.
pub fn damped_scales<const N: usize>(
    scales: &Vector<N>,
    damping: &Vector<N>,
    ts: f64,
) -> Result<Vector<N>, Error> {
    check::positive("Ts > 0", "Ts", ts)?;
    check::positive_vec("inertia scale > 0", "inertia scale", scales)?;
    check::nonnegative_vec("damping ≥ 0", "damping", damping)?;
    let mut out = *scales;
    for i in 0..N {
        let (d, b) = (scales[i], damping[i]);
        let beta = b * ts / d;
        if beta > 0.0 {
            // −expm1(−β) = 1 − e^(−β), accurate for small β.
            out[i] = b * ts / -libm::expm1(-beta);
        }
    }
    check::finite_slice("inertia scale", out.as_slice())?;
    Ok(out)
}

pub use crate::control::coupling::largest_eigenvalue;

impl Rule {
    /// The rule with its tube widened to hold the sag of the arm under the
    /// feedback alone, SPEC (18.5): the weights start at zero, so at first the
    /// arm hangs G_i/(Kp_i K1_i) (rad) below the path, and the networks must
    /// still act there: tube_q ≥ 2 max_i |G_i|/(Kp_i K1_i). `gravity` (N m) is
    /// G at the path's start; `cfg` the [`gains`](Self::gains).
    pub fn holding<const N: usize>(&self, cfg: &Config<N>, gravity: &Vector<N>) -> Self {
        let sag = (0..N)
            .map(|i| gravity[i].abs() / (cfg.kp[i] * cfg.k1[i]))
            .fold(0.0, f64::max);
        let mut rule = *self;
        if sag.is_finite() {
            rule.tube[0] = rule.tube[0].max(2.0 * sag);
        }
        rule
    }

    /// The rule whose centres span the orbit `orbit` (its joint positions,
    /// rad; one period of the motion that repeats), SPEC (19.11): the widths
    /// in q at least its diameter max_{j,k} ‖q_j − q_k‖, so that every node
    /// acts over the whole orbit. The number of centres (18.5) and their
    /// places are unchanged; [`learning`](Self::learning) then normalises Γ
    /// by the wider basis's ⟨‖S‖²⟩ as before. An empty orbit, or one whose
    /// diameter is not finite, leaves the rule as it is.
    #[must_use]
    pub fn spanning<const N: usize>(&self, orbit: &[Vector<N>]) -> Self {
        let d = diameter(orbit);
        let mut rule = *self;
        if d.is_finite() {
            rule.span = rule.span.max(d);
        }
        rule
    }

    /// The rule for a loop of `delay` periods, SPEC (18.11): the margin of
    /// (18.1) is then taken at the path's largest mode
    /// ([`bounded`](Self::bounded)). Errors unless 0 ≤ δ ≤ [`MAX_DELAY`].
    pub fn with_delay(self, delay: usize) -> Result<Self, Error> {
        check::at_most("0 ≤ delay ≤ 64", "delay", delay as f64, MAX_DELAY as f64)?;
        Ok(Self { delay, ..self })
    }

    /// The rule whose margin m keeps the sampled velocity loop of a loop of
    /// [`delay`](Self::delay) periods at the pole radius r_δ in its largest
    /// mode `lmax` (λmax of Dₛ^½ D⁻¹ Dₛ^½ along the path, [`loop_bound`]),
    /// SPEC (18.11):
    ///
    /// ```text
    /// m_δ = min(m, g_δ / λmax)     (δ ≥ 1: the robust term off, (18.4))
    /// ```
    ///
    /// with g_δ = [`loop_gain`]`(δ)`; K1 (18.2) and Ĝ's learning (18.6)
    /// follow m_δ, while D̂ and Ĉ keep the undelayed rule's bandwidth
    /// ([`dc_boost`](Self::dc_boost) = m/m_δ, ω_D = ω_C ≤ ω_G). δ = 0 keeps m
    /// (18.1) as it is, bit for bit. A `lmax` that is not finite and > 0
    /// leaves the rule as it is.
    #[must_use]
    pub fn bounded(&self, lmax: f64) -> Self {
        let mut rule = *self;
        if self.delay > 0 && lmax.is_finite() && lmax > 0.0 {
            let m = loop_gain(self.delay) / ((1.0 + self.robust_share()) * lmax);
            if m < rule.margin {
                // D̂ and Ĉ keep the undelayed bandwidth ω_G(m)/5, at most ω_G.
                let most = (1.0 / self.learn_dc).max(1.0);
                rule.dc_boost = (self.dc_boost * rule.margin / m)
                    .min(most)
                    .max(self.dc_boost);
                rule.margin = m;
            }
        }
        rule
    }

    /// The robust term's slope kr/φ as a share of Kp, (18.4), (18.11):
    /// [`ROBUST_SHARE`] without delay, 0 with one (a delayed loop's gain is
    /// spent on Kp, not on the robust term's slope at z2 = 0).
    pub fn robust_share(&self) -> f64 {
        if self.delay == 0 {
            ROBUST_SHARE
        } else {
            0.0
        }
    }

    /// K1 (1/s) at period `ts` (s), (18.2): min(k1_max, k1_share · m/Ts),
    /// with the rule's margin m (the delay's, SPEC (18.11)).
    pub fn k1(&self, ts: f64) -> f64 {
        self.k1_max.min(self.k1_share * self.margin / ts)
    }

    /// The rule with Ĝ learning near the velocity loop's critical bandwidth,
    /// SPEC (19.6): ω_G² = a²/(4ζ²), a = m/Ts, ζ = [`LEARN_DAMPING`] (the
    /// learning loop's pair s² + a s + ω_G² just overdamped), i.e. `learn` =
    /// a/(4ζ² K1) for the K1 of (18.2) at `ts` (1.03 at 1 kHz: 2.07 times
    /// (18.6)'s ½). The table scenario's K1 = 10 s⁻¹ slows the learning
    /// pole's reach (it tends to −K1 as ω_G grows); there the learning goes
    /// as fast as the velocity loop lets it. ζ = 1 (critical) was too close:
    /// output feedback, whose velocity is the samples' difference, lost the
    /// UR5's table for 1.6 s after landing. D̂ and Ĉ keep their bandwidth ω_D
    /// = ω_C of (18.6): faster, D̂ α̇1 carried the paper's +τe feedforward's
    /// loop through the contact and the tool chattered (the Panda's table
    /// with +τe: 10.5 N).
    pub fn critical(&self, ts: f64) -> Self {
        let learn = self.margin / ts / (4.0 * LEARN_DAMPING * LEARN_DAMPING * self.k1(ts));
        Self {
            learn,
            learn_dc: self.learn_dc * sqrt(self.learn / learn),
            ..*self
        }
    }

    /// The rule for an arm that bears no gravity the controller must hold,
    /// SPEC (22.2): a robot that adds its own model's gravity torque to every
    /// command (a Franka through libfranka), or an arm moving in a
    /// horizontal plane. What the networks learn is then the inertia the
    /// model lacks (a drive's rotor, its inertia times the gear ratio
    /// squared, which a URDF's links do not carry), the Coriolis terms and
    /// friction: D̂'s regressor α̇1 carries an inertia error with one weight
    /// along the whole orbit, so D̂ and Ĉ learn at Ĝ's bandwidth
    /// (`learn_dc` = 1, ω_D = ω_C = ω_G of (18.6)).
    #[must_use]
    pub fn weightless(&self) -> Self {
        Self {
            learn_dc: 1.0,
            ..*self
        }
    }

    /// The robot-scenario configuration of `law` for an arm of inertia matrix
    /// `d` (kg m², at the task's start), limits `tau_max` (N m) and period
    /// `ts` (s): (18.1)–(18.4), the hardened options of SPEC §13 and the
    /// conditions "scaled" (SPEC §10), which it meets by construction.
    /// Learning keeps the schema's Γ, σ and "auto" bound until
    /// [`learning`](Self::learning) sets them for a basis.
    ///
    /// Errors name the condition: `d` symmetric positive definite, τmax > 0,
    /// 0 < Ts ≤ 1 s, every inertia scale in [1e-9, 1e9] kg m², every gain
    /// within 1e9.
    pub fn gains<const N: usize>(
        &self,
        law: Law,
        d: &Matrix<N>,
        tau_max: &Vector<N>,
        ts: f64,
    ) -> Result<Config<N>, Error> {
        self.gains_scaled(law, &inertia_scales(d)?, tau_max, ts)
    }

    /// [`gains`](Self::gains) from the inertia scales d_i (kg m²) themselves,
    /// e.g. [`inertia_scales_along`] a path.
    pub fn gains_scaled<const N: usize>(
        &self,
        law: Law,
        scales: &Vector<N>,
        tau_max: &Vector<N>,
        ts: f64,
    ) -> Result<Config<N>, Error> {
        check::positive("Ts > 0", "Ts", ts)?;
        check::at_most("Ts ≤ 1 s", "Ts", ts, 1.0)?;
        check::positive_vec("τmax > 0", "tau_max", tau_max)?;
        check::finite_slice("inertia scale", scales.as_slice())?;
        let scales = *scales;
        if let Some(i) = scales
            .iter()
            .position(|d| *d < MIN_SCALE || *d > PARAM_BOUND)
        {
            return Err(Error::Condition {
                condition: if scales[i] < MIN_SCALE {
                    "d ≥ 1e-9"
                } else {
                    "|value| ≤ 1e9"
                },
                lhs: "inertia",
                index: Some(i),
                value: scales[i],
            });
        }
        let mut cfg = Config::<N>::new(law, *tau_max).hardened();
        cfg.ts = ts;
        cfg.conditions = Conditions::Scaled;
        cfg.inertia = scales;
        cfg.rho = 1.0;
        let rate = self.margin / ts; // Kp/d (1/s)
        cfg.kp = scales * rate;
        cfg.k1 = Vector::from_element(self.k1(ts));
        cfg.kzeta = Vector::from_element(rate + 0.5 * cfg.rho);
        cfg.kr = cfg.kp * (self.robust_share() * cfg.phi);
        cfg.delay = self.delay;
        cfg.fallback_damping = cfg.kp;
        Ok(cfg)
    }

    /// The number of centres L for a path given by `path`, samples evenly
    /// spaced in time over one period (the first not repeated), SPEC (18.5):
    /// L = clip(⌈2 ℓ / tube_q⌉, 16, 256), ℓ the length of the closed path
    /// in q (rad).
    pub fn nodes<const N: usize>(&self, path: &[Setpoint<N>]) -> usize {
        let mut length = 0.0;
        for (j, sp) in path.iter().enumerate() {
            let next = &path[(j + 1) % path.len()];
            length += (next.x - sp.x).norm();
        }
        let l = libm::ceil(2.0 * length / self.tube[0]);
        if l.is_finite() && l > NODES.0 as f64 {
            (l as usize).min(NODES.1)
        } else {
            NODES.0
        }
    }

    /// Centres along `path` (one period, evenly spaced in time; see
    /// [`nodes`](Self::nodes)) in the caller's buffer `buf` (length
    /// [`nodes`](Self::nodes) · 4N): sample `⌊j·K/L⌋` for node j, widths
    /// (15.2) with the rule's tube ([`Centers::along_in`], SPEC §15), in q at
    /// least the rule's [`span`](Self::span) (SPEC (19.11)).
    /// `scratch` holds L setpoints.
    pub fn centres_in<const N: usize, C: AsRef<[f64]> + AsMut<[f64]>>(
        &self,
        path: &[Setpoint<N>],
        buf: C,
        scratch: &mut [Setpoint<N>],
    ) -> Result<Centers<N, C>, Error> {
        let l = scratch.len();
        if path.len() < l || l == 0 {
            return Err(Error::Invalid {
                what: "path",
                reason: "needs at least as many samples as centres (and one)",
            });
        }
        for (j, s) in scratch.iter_mut().enumerate() {
            *s = path[j * path.len() / l];
        }
        // (19.11): widths in q of at least the span; the spacing (18.5) as it is.
        Centers::along_in(buf, scratch, [self.tube[0].max(self.span), self.tube[1]])
    }

    /// The learning of SPEC (18.6)–(18.8) into `cfg` for `basis` along `path`
    /// (one period of `period` s, evenly spaced in time): Γ, σ and fixed
    /// weight bounds. `scratch` holds the basis (length L). The rates are in
    /// the inertia-scaled units of `cfg.inertia` (SPEC (10.2)), so they need
    /// the [`gains`](Self::gains) of the same rule.
    pub fn learning<const N: usize, B: Basis<N>>(
        &self,
        cfg: &mut Config<N>,
        basis: &B,
        path: &[Setpoint<N>],
        period: f64,
        scratch: &mut [f64],
    ) -> Result<(), Error> {
        let l = basis.nodes();
        if path.is_empty() || scratch.len() != l {
            return Err(Error::Invalid {
                what: "path",
                reason: "needs one sample or more, and a scratch buffer of L reals",
            });
        }
        check::positive("period > 0", "period", period)?;
        let (mut s2, mut sum_min) = (0.0, f64::INFINITY);
        let (mut a2, mut v2, mut a_max, mut v_max) = (0.0, 0.0, 0.0f64, 0.0f64);
        for sp in path {
            // On the path z1 = 0: α1 = ẋc, α̇1 = ẍc.
            basis.eval(&[sp.x, sp.dx, sp.dx, sp.ddx], scratch);
            s2 += scratch.iter().map(|s| s * s).sum::<f64>();
            sum_min = sum_min.min(scratch.iter().sum::<f64>());
            a2 += sp.ddx.norm_squared();
            v2 += sp.dx.norm_squared();
            a_max = a_max.max(sp.ddx.norm());
            v_max = v_max.max(sp.dx.norm());
        }
        let k = path.len() as f64;
        // Regressor scales floored at 1 rad/s² and 1 rad/s: a path that barely
        // moves must not make Γ_D, Γ_C (or the bounds b_D, b_C) unbounded.
        let (s2, a2, v2) = (s2 / k, (a2 / k).max(1.0), (v2 / k).max(1.0));
        let (a_max, v_max) = (a_max.max(1.0), v_max.max(1.0));
        if !(s2 > 0.0 && sum_min > 0.0) {
            return Err(Error::Invalid {
                what: "basis",
                reason: "does not reach the path (every S_j ≈ 0 somewhere on it)",
            });
        }
        let rate = cfg.kp.component_div(&cfg.inertia).min();
        let omega2 = self.learn * rate * cfg.k1.min();
        let dc = self.learn_dc * self.dc_boost;
        let dc2 = dc * dc * omega2;
        let or_one = |x: f64| if x > 0.0 { x } else { 1.0 };
        let gamma_g = omega2 / s2;
        cfg.gamma = [dc2 / (s2 * or_one(a2)), dc2 / (s2 * or_one(v2)), gamma_g];
        let leak = self.leak_periods * period;
        cfg.sigma = cfg.gamma.map(|g| 1.0 / (g * leak));
        let b_g = self.bound_margin * cfg.tau_max.norm() * sqrt(l as f64) / sum_min;
        cfg.weight_bound = WeightBound::Fixed([b_g / a_max, b_g / v_max, b_g]);
        Ok(())
    }
}

/// The rule's centres and configuration together (feature `alloc`).
#[cfg(feature = "alloc")]
#[derive(Clone, Debug, PartialEq)]
pub struct Suggestion<const N: usize> {
    /// The controller's configuration.
    pub config: Config<N>,
    /// The centres along the path.
    pub centers: Centers<N, alloc::vec::Vec<f64>>,
}

#[cfg(feature = "alloc")]
impl Rule {
    /// One period of `traj` from t = 0 as [`PATH_SAMPLES`] setpoints.
    pub fn sample<const N: usize, T: Trajectory<N> + ?Sized>(
        traj: &T,
        period: f64,
    ) -> alloc::vec::Vec<Setpoint<N>> {
        (0..PATH_SAMPLES)
            .map(|k| traj.sample(period * k as f64 / PATH_SAMPLES as f64))
            .collect()
    }

    /// [`centres_in`](Self::centres_in) on the heap, [`nodes`](Self::nodes) centres.
    pub fn centres<const N: usize>(
        &self,
        path: &[Setpoint<N>],
    ) -> Result<Centers<N, alloc::vec::Vec<f64>>, Error> {
        let l = self.nodes(path);
        let mut scratch = alloc::vec![path.first().copied().ok_or(Error::Invalid {
            what: "path",
            reason: "needs at least one sample",
        })?; l];
        self.centres_in(path, alloc::vec![0.0; l * 4 * N], &mut scratch)
    }

    /// Everything at once: [`gains`](Self::gains), [`centres`](Self::centres)
    /// and [`learning`](Self::learning) for `path` (one period of `period`
    /// s, evenly spaced in time, e.g. [`Rule::sample`]); with `gravity` (G
    /// at the path's start, N m) the tube [`holding`](Self::holding) the sag.
    #[allow(clippy::too_many_arguments)]
    pub fn suggest<const N: usize>(
        &self,
        law: Law,
        d: &Matrix<N>,
        tau_max: &Vector<N>,
        ts: f64,
        path: &[Setpoint<N>],
        period: f64,
        gravity: Option<&Vector<N>>,
    ) -> Result<Suggestion<N>, Error> {
        self.suggest_scaled(law, &inertia_scales(d)?, tau_max, ts, path, period, gravity)
    }

    /// [`suggest`](Self::suggest) from the inertia scales d_i (kg m²)
    /// themselves: [`inertia_scales_along`] the path for SPEC (18.1).
    #[allow(clippy::too_many_arguments)]
    pub fn suggest_scaled<const N: usize>(
        &self,
        law: Law,
        scales: &Vector<N>,
        tau_max: &Vector<N>,
        ts: f64,
        path: &[Setpoint<N>],
        period: f64,
        gravity: Option<&Vector<N>>,
    ) -> Result<Suggestion<N>, Error> {
        let mut config = self.gains_scaled(law, scales, tau_max, ts)?;
        if let Some(g) = gravity {
            check::finite_slice("gravity", g.as_slice())?;
        }
        let rule = gravity.map_or(*self, |g| self.holding(&config, g));
        let centers = rule.centres(path)?;
        let mut scratch = alloc::vec![0.0; centers.nodes()];
        rule.learning(&mut config, &centers, path, period, &mut scratch)?;
        Ok(Suggestion { config, centers })
    }

    /// A basis for a controller given none, beyond the vertex grid (n > 3),
    /// SPEC §18: centres along one period of `traj` (the slowest frequency,
    /// [`Sinusoid::period`]) if it moves; else the "star" of 2N + 1 centres
    /// at its offset and ±tube_q along each joint, widths tube (a posture to
    /// hold).
    pub fn default_basis<const N: usize>(
        &self,
        traj: &Sinusoid<N>,
    ) -> Result<Centers<N, alloc::vec::Vec<f64>>, Error> {
        if let Some(period) = traj.period() {
            return self.centres(&Self::sample(traj, period));
        }
        let mut c = alloc::vec![0.0; (2 * N + 1) * 4 * N];
        for (j, row) in c.chunks_exact_mut(4 * N).enumerate() {
            row[..N].copy_from_slice(traj.offset().as_slice());
            if j > 0 {
                let sign = if j % 2 == 1 { 1.0 } else { -1.0 };
                row[(j - 1) / 2] += sign * self.tube[0];
            }
        }
        let w = |t: f64| Vector::<N>::from_element(t * t);
        let inf = Vector::<N>::from_element(f64::INFINITY);
        Centers::new(c, [w(self.tube[0]), w(self.tube[1]), inf, inf])
    }
}

/// The default task about the posture `home` (rad) for joints limited to
/// [`lo`, `hi`] (rad; ±∞ for a continuous joint), SPEC §18: every joint
/// swings `xc_i = home_i − A_i cos(π t)` (period 2 s, from rest at home − A,
/// through home, to home + A), with A_i = min(0.2 rad, (hi_i − lo_i)/4)
/// (the swing covers at most half the range). Errors unless lo < hi per
/// joint and `home` is inside [lo + A, hi − A].
pub fn default_task<const N: usize>(
    home: &Vector<N>,
    lo: &Vector<N>,
    hi: &Vector<N>,
) -> Result<Sinusoid<N>, Error> {
    check::finite_slice("home", home.as_slice())?;
    check::each("hi > lo", "hi − lo", &(hi - lo), |_, d| d, true)?;
    let amp = Vector::<N>::from_fn(|i, _| (0.25 * (hi[i] - lo[i])).min(TASK_AMPLITUDE));
    // (1e-9 rad of rounding allowed: a home clipped onto lo + A is inside.)
    check::each(
        "lo + A ≤ home ≤ hi − A",
        "distance from home to the nearest limit − A",
        home,
        |i, h| (h - lo[i]).min(hi[i] - h) - amp[i] + 1e-9,
        false,
    )?;
    Sinusoid::new(
        *home,
        Vector::zeros(),
        -amp,
        Vector::from_element(core::f64::consts::PI),
    )
}

/// The diameter max_{j,k} ‖q_j − q_k‖ (rad) of the joint positions `orbit`
/// (0 for fewer than two), SPEC (19.11). NaN if a position is not finite.
pub fn diameter<const N: usize>(orbit: &[Vector<N>]) -> f64 {
    let mut d2 = 0.0f64;
    for (j, a) in orbit.iter().enumerate() {
        for b in &orbit[j + 1..] {
            let e = (a - b).norm_squared();
            if !e.is_finite() {
                return f64::NAN;
            }
            d2 = d2.max(e);
        }
    }
    sqrt(d2)
}

/// The largest swing A (rad) of [`default_task`].
pub const TASK_AMPLITUDE: f64 = 0.2;

#[cfg(test)]
mod tests;
