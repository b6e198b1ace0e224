//! The joint controller's parameters as a C struct: every field of the
//! schema's group "controller", converted by name to the core's scenario.

use crate::fields::{controller_fields, read_into, write_from};
use crate::*;
use adaptimp::dynamic::{Basis, Centres, Controller, Inertia, Scenario, TaskPath, Tuning};
use adaptimp::schema::{Group, Preset};
use adaptimp::Law;

/// Every parameter of a controller for `n` joints (1…7): the fields of the
/// parameter schema (`adaptimp::schema::PARAMS`, group "controller"), named as
/// there, with per-joint arrays of which the first `n` entries are read.
/// Fill it with [`adaptimp_params_default`], then change fields. Every enum
/// field is read as an integer and refused (INVALID_CONFIG, naming the
/// field) if it is not a value of its enum; a NaN anywhere is a parameter
/// error (INVALID_CONFIG), as in Python.
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpParams {
    /// Number of joints, 1…7.
    pub n: usize,
    /// Which controller.
    pub law: AdaptimpLawRaw,
    /// Sampling period Ts (s).
    pub ts: f64,
    /// The loop's delay δ (periods) the controller is made for, 0…64: its
    /// torque acts δ periods after its measurement was taken (libfranka: 1),
    /// SPEC (18.11).
    pub delay: usize,
    /// K1 (1/s), (7).
    pub k1: [f64; ADAPTIMP_MAX_JOINTS],
    /// Kp (N m s/rad), (14).
    pub kp: [f64; ADAPTIMP_MAX_JOINTS],
    /// Kζ (1/s), (11).
    pub kzeta: [f64; ADAPTIMP_MAX_JOINTS],
    /// Inertia scale d of each joint (kg m²), SPEC §10.
    pub inertia: [f64; ADAPTIMP_MAX_JOINTS],
    /// Dₛ (kg m²), SPEC (18.12): the inertia-shaped gains, n × n row-major
    /// in the first n² values (symmetric positive definite); INFINITY in the
    /// first value: none, the diagonal law of `inertia` (the default).
    pub inertia_matrix: [f64; ADAPTIMP_MAX_MATRIX],
    /// Young weight ρ (1/s) of the auxiliary system, SPEC §10.
    pub rho: f64,
    /// The stability conditions checked.
    pub conditions: AdaptimpConditionsRaw,
    /// μ (N m), (11).
    pub mu: f64,
    /// Inner law of the auxiliary system.
    pub aux_law: AdaptimpAuxLawRaw,
    /// The robust term.
    pub robust: AdaptimpRobustRaw,
    /// kr (N m) of the sign and tanh terms.
    pub kr: [f64; ADAPTIMP_MAX_JOINTS],
    /// φ (rad/s) of the tanh term.
    pub phi: f64,
    /// kD (kg m²), kC (N m s/rad), kG (N m) of Remark 1, (30).
    pub k_remark1: [f64; 3],
    /// The learning step.
    pub learning_step: AdaptimpLearningStepRaw,
    /// κ of the normalised step, in (0, 1].
    pub kappa: f64,
    /// Learning under saturation.
    pub saturation_learning: AdaptimpSaturationLearningRaw,
    /// The projection of the weights.
    pub weight_bound_mode: AdaptimpWeightBoundRaw,
    /// Bounds on ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ for `ADAPTIMP_WEIGHT_BOUND_FIXED`.
    pub weight_bound: [f64; 3],
    /// Γ of D̂, Ĉ, Ĝ, (15)–(17).
    pub gamma: [f64; 3],
    /// σ of D̂, Ĉ, Ĝ, (15)–(17).
    pub sigma: [f64; 3],
    /// Observer ε (s), (31).
    pub eps: f64,
    /// Observer λ1, (31).
    pub lam1: [f64; ADAPTIMP_MAX_JOINTS],
    /// Observer start.
    pub observer_init: AdaptimpObserverInitRaw,
    /// Observer discretisation.
    pub observer_hold: AdaptimpObserverHoldRaw,
    /// Output feedback compares its estimate with the reference the
    /// observer's lag back, (9.1) (0 or 1; paper 0, robot 1).
    pub observer_lead: AdaptimpBoolRaw,
    /// Actuator limits τmax (N m).
    pub tau_max: [f64; ADAPTIMP_MAX_JOINTS],
    /// Target inertia Dd (kg m²), (3).
    pub dd: [f64; ADAPTIMP_MAX_JOINTS],
    /// Target damping Cd (N m s/rad), (3).
    pub cd: [f64; ADAPTIMP_MAX_JOINTS],
    /// Target stiffness Gd (N m/rad), (3).
    pub gd: [f64; ADAPTIMP_MAX_JOINTS],
    /// Where the target impedance acts (`ADAPTIMP_IMPEDANCE_EXTERNAL` for the
    /// joint controller of an `AdaptimpCartesian`).
    pub impedance: AdaptimpImpedanceRaw,
    /// Width η² of the vertex grid (used when `centers` is NULL and n ≤ 3).
    pub eta2: f64,
    /// User centres: `nodes` rows of 4n reals (x, v, α1, α̇1 blocks of n), or
    /// NULL for the default basis: the paper's vertex grid for n ≤ 3, the
    /// rule's centres along the commanded trajectory beyond (SPEC §18), as
    /// Python builds it. Copied at construction.
    pub centers: *const f64,
    /// The number of user centres L.
    pub nodes: usize,
    /// Widths η_d² per input dimension (4n reals, blocks as the centres;
    /// INFINITY: the dimension is left out), or NULL for `eta2` in every
    /// dimension. Copied at construction.
    pub widths2: *const f64,
    /// The commanded trajectory, xc_i = o_i + a_i sin(ω_i t) + b_i cos(ω_i t):
    /// offset o (rad), used when a step gets no setpoint.
    pub xc_offset: [f64; ADAPTIMP_MAX_JOINTS],
    /// Sine amplitude a (rad).
    pub xc_sin: [f64; ADAPTIMP_MAX_JOINTS],
    /// Cosine amplitude b (rad).
    pub xc_cos: [f64; ADAPTIMP_MAX_JOINTS],
    /// Angular frequency ω (rad/s).
    pub xc_omega: [f64; ADAPTIMP_MAX_JOINTS],
    /// The torque a refused step returns in `AdaptimpCommand.tau_sat`.
    pub fallback: AdaptimpFallbackRaw,
    /// Kd (N m s/rad) of the damping fallback.
    pub fallback_damping: [f64; ADAPTIMP_MAX_JOINTS],
    /// After a refused step: go on, or latch the fault.
    pub fault_policy: AdaptimpFaultPolicyRaw,
    /// Plausibility limit |q_i| ≤ q_max (rad; INFINITY: none, the ceiling
    /// 1e6 rad still holds). As Python's None.
    pub q_max: [f64; ADAPTIMP_MAX_JOINTS],
    /// Plausibility limit |q̇_i| ≤ dq_max (rad/s; INFINITY: none, the ceiling
    /// 1e6 rad/s still holds).
    pub dq_max: [f64; ADAPTIMP_MAX_JOINTS],
    /// Plausibility limit |τe_i| ≤ tau_e_max (N m; INFINITY: none, the
    /// ceiling 1e9 N m still holds).
    pub tau_e_max: [f64; ADAPTIMP_MAX_JOINTS],
    /// Plausibility limit on the change of q_i between samples (rad; INFINITY: none).
    pub q_jump_max: [f64; ADAPTIMP_MAX_JOINTS],
    /// Torque rate limit per step (N m; INFINITY: none), before saturation.
    pub tau_rate_max: [f64; ADAPTIMP_MAX_JOINTS],
}

pub(crate) fn law_of(law: AdaptimpLaw) -> Law {
    match law {
        AdaptimpLaw::Pd => Law::Pd,
        AdaptimpLaw::StateFeedback => Law::StateFeedback,
        AdaptimpLaw::OutputFeedback => Law::OutputFeedback,
    }
}

fn law_raw(law: Law) -> AdaptimpLawRaw {
    match law {
        Law::Pd => AdaptimpLaw::Pd,
        Law::StateFeedback => AdaptimpLaw::StateFeedback,
        Law::OutputFeedback => AdaptimpLaw::OutputFeedback,
    }
    .raw()
}

pub(crate) fn preset_of(p: AdaptimpPreset) -> Preset {
    match p {
        AdaptimpPreset::Paper => Preset::Paper,
        AdaptimpPreset::Robot => Preset::Robot,
    }
}

/// The parameters as the core's scenario of n joints (each controller
/// parameter of the schema set from its field, [`controller_fields`]), its
/// basis not yet given. Every error is a parameter's: INVALID_CONFIG
/// (BAD_SIZE for n).
pub(crate) fn scenario_of(p: &AdaptimpParams) -> Result<Scenario, AdaptimpStatus> {
    let n = p.n;
    if !(1..=ADAPTIMP_MAX_JOINTS).contains(&n) {
        return Err(bad_n(n));
    }
    let law = law_of(decode::<AdaptimpLaw>(p.law, "params.law")?);
    let mut s = Scenario::new(n, Preset::Paper, law).map_err(|e| core_error(e, Context::Config))?;
    let mut p = *p;
    read_into(
        &mut s,
        n,
        Group::Controller,
        controller_fields(&mut p),
        "params",
    )?;
    Ok(s)
}

/// The controller of `p` (its centres, if any, copied), built by the
/// core's one builder.
///
/// # Safety
/// `p.centers` and `p.widths2` are NULL or hold `nodes × 4n` and `4n` reals.
pub(crate) unsafe fn controller_of(p: &AdaptimpParams) -> Result<Controller, AdaptimpStatus> {
    let mut s = scenario_of(p)?;
    if !p.centers.is_null() {
        let len = p
            .nodes
            .checked_mul(4 * p.n)
            .ok_or_else(|| fail(AdaptimpStatus::BadSize, &"params.nodes × 4n overflows"))?;
        // SAFETY (in `slice`): the caller gives `nodes` rows of 4n reals, and 4n widths.
        let rows = unsafe { slice(p.centers, len, "params.centers") }?.to_vec();
        let widths2 = if p.widths2.is_null() {
            None
        } else {
            Some(unsafe { slice(p.widths2, 4 * p.n, "params.widths2") }?.to_vec())
        };
        s.basis(Basis::Centres(Centres { rows, widths2 }));
    }
    s.controller().map_err(|e| core_error(e, Context::Config))
}

/// Every field zero, no centres: what [`params_of`] fills in (the
/// schema's none of a limit is written as INFINITY).
// SAFETY: every field is a number, a C enum's or bool's integer, or a
// pointer, for each of which all-zero bytes are a value (NULL for a pointer).
pub(crate) const BLANK: AdaptimpParams = unsafe { std::mem::zeroed() };

/// The controller parameters of scenario `s` (centres: none); INTERNAL if
/// a value does not fit its field ([`write_from`]).
pub(crate) fn params_of(s: &Scenario) -> Result<AdaptimpParams, AdaptimpStatus> {
    let mut p = AdaptimpParams {
        n: s.n(),
        law: law_raw(s.law()),
        ..BLANK
    };
    write_from(s, Group::Controller, controller_fields(&mut p), "params")?;
    Ok(p)
}

/// Fill `out` with the defaults of `preset` for controller `law` and `n`
/// joints (1 … 7). Per-joint defaults declared for the paper's 2 joints (τmax,
/// the commanded circle) are broadcast from their first entry for other n.
/// BAD_SIZE for n outside 1 … 7, INVALID_CONFIG for a `law` or `preset` that
/// is not a value of its enum (two arguments swapped, say); on an error
/// `*out` is unchanged.
///
/// # Safety
/// `out` is NULL or points to an `AdaptimpParams`.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_params_default(
    out: *mut AdaptimpParams,
    n: usize,
    law: AdaptimpLawRaw,
    preset: AdaptimpPresetRaw,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `out`): checked for NULL; the caller's contract.
        let out = unsafe { crate::out(out, "out") }?;
        let law = law_of(decode::<AdaptimpLaw>(law, "law")?);
        let preset = preset_of(decode::<AdaptimpPreset>(preset, "preset")?);
        // The one error of a scenario's defaults is its n.
        let s = Scenario::new(n, preset, law).map_err(|_| bad_n(n))?;
        *out = params_of(&s)?;
        Ok(())
    })
}

/// The most centres the rule places ([`adaptimp_params_suggest`],
/// [`adaptimp_params_suggest_tuning`]): their `centers` buffer holds this
/// many rows of 4n reals.
pub const ADAPTIMP_SUGGEST_MAX_NODES: usize = 256;
// A literal, which the header can state; the core's bound it must equal.
const _: () = assert!(ADAPTIMP_SUGGEST_MAX_NODES == adaptimp::tuning::NODES.1);

/// The gain and basis rule of SPEC §18 for an arm of `n` joints: `*out` gets
/// the robot scenario's parameters for `law` with the rule's gains from the
/// inertia matrix `inertia` (n × n, row-major, kg m², at the task's start),
/// the limits `tau_max` (n, N m), the period `ts` (s) and the loop's delay
/// `delay` (periods, 0…64: libfranka's loop 1; the margin of SPEC (18.11)
/// at the largest mode at `inertia`), and the conditions "scaled" (SPEC
/// §10). With a `path` (`rows` rows of 3n reals: q, q̇, q̈,
/// one period of `period` s, evenly spaced in time) also the centres along
/// it, the learning rates and the weight bounds: the centres are written to
/// `centers` (room for [`ADAPTIMP_SUGGEST_MAX_NODES`] × 4n reals) and their
/// squared widths to `widths2` (4n), and `out->centers`, `out->nodes`,
/// `out->widths2` point at them. `gravity` (n, N m, G at the path's start)
/// may be NULL. With a delay (≥ 1) the gains are shaped by the inertia,
/// SPEC (18.12): `out->inertia_matrix` gets `inertia` (the only sample, so
/// Dₛ = D at the start); without one it is INFINITY first (the diagonal
/// gains of (18.1)); [`adaptimp_params_suggest_coupling`] chooses either at
/// any delay. `adaptimp_controller_new(out, …)` then builds the
/// controller. `law` outside its enum is INVALID_CONFIG; a NaN or a bad
/// value is INVALID_CONFIG naming it. On an error `*out` is left unchanged.
///
/// # Safety
/// Every pointer is NULL or valid for the lengths above; `centers` and
/// `widths2` are only read with a path.
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn adaptimp_params_suggest(
    out: *mut AdaptimpParams,
    n: usize,
    law: AdaptimpLawRaw,
    inertia: *const f64,
    tau_max: *const f64,
    ts: f64,
    delay: usize,
    path: *const f64,
    rows: usize,
    period: f64,
    gravity: *const f64,
    centers: *mut f64,
    widths2: *mut f64,
) -> AdaptimpStatus {
    // SAFETY: the caller's contract, the same as the function's below.
    unsafe {
        adaptimp_params_suggest_coupling(
            out,
            n,
            law,
            inertia,
            tau_max,
            ts,
            delay,
            AdaptimpCouplingRaw(AdaptimpCoupling::Default as u32),
            path,
            rows,
            period,
            gravity,
            centers,
            widths2,
        )
    }
}

/// [`adaptimp_params_suggest`] with the choice of gains (`Python:
/// tuning.suggest(coupled=…)`): `coupling` the rule's default, the diagonal
/// gains of SPEC (18.1) or the inertia-shaped ones of (18.12) at any delay.
/// A `coupling` outside its enum is INVALID_CONFIG naming it.
///
/// # Safety
/// As [`adaptimp_params_suggest`].
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn adaptimp_params_suggest_coupling(
    out: *mut AdaptimpParams,
    n: usize,
    law: AdaptimpLawRaw,
    inertia: *const f64,
    tau_max: *const f64,
    ts: f64,
    delay: usize,
    coupling: AdaptimpCouplingRaw,
    path: *const f64,
    rows: usize,
    period: f64,
    gravity: *const f64,
    centers: *mut f64,
    widths2: *mut f64,
) -> AdaptimpStatus {
    let mut t = tuning_of(law, inertia, tau_max, ts);
    (t.delay, t.coupling) = (delay, coupling);
    (t.path, t.rows, t.period, t.gravity) = (path, rows, period, gravity);
    // SAFETY: the caller's contract, the same as the function's below.
    unsafe { adaptimp_params_suggest_tuning(out, n, &t, centers, widths2) }
}

/// Everything the rule of SPEC §18 is given, as Python's `tuning.suggest`
/// takes it (the core's `adaptimp::dynamic::Tuning`): fill it with
/// [`adaptimp_tuning_init`], set what you know, then
/// [`adaptimp_params_suggest_tuning`]. Pointers are NULL when not given;
/// the lengths are in n, the count given to the suggest call.
#[repr(C)]
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct AdaptimpTuning {
    /// The controller's law.
    pub law: AdaptimpLawRaw,
    /// The arm's inertia (kg m², row-major): one n × n matrix D at the
    /// task's start when `inertia_samples` is 0 (SPEC (18.1)'s scales at
    /// it); K = `inertia_samples` ≥ 1 matrices of n × n at postures along
    /// the task's path (the scales along it, and (18.11)'s margin at the
    /// largest mode of them all).
    pub inertia: *const f64,
    /// 0, or the number K of matrices at `inertia` (see there).
    pub inertia_samples: usize,
    /// The actuators' limits τmax (N m, n values).
    pub tau_max: *const f64,
    /// The sampling period Ts (s).
    pub ts: f64,
    /// The loop's delay δ (periods, 0 … 64), SPEC (18.11).
    pub delay: usize,
    /// Which gains: the rule's default, diagonal or shaped (SPEC (18.12)).
    pub coupling: AdaptimpCouplingRaw,
    /// The task's path: `rows` rows of 3n reals (q, q̇, q̈) over one period
    /// of `period` s, evenly spaced in time; NULL: the gains only.
    pub path: *const f64,
    /// The path's number of rows.
    pub rows: usize,
    /// The period the path spans (s).
    pub period: f64,
    /// The gravity torque G at the path's start (N m, n values), or NULL;
    /// read with a path only.
    pub gravity: *const f64,
    /// The joints' viscous damping (N m s/rad, n values), or NULL, SPEC (18.9).
    pub damping: *const f64,
    /// The joint positions (rad) of one period of the motion that repeats,
    /// `orbit_rows` rows of n, or NULL, SPEC (19.11); read with a path only.
    pub orbit: *const f64,
    /// The orbit's number of rows.
    pub orbit_rows: usize,
    /// The tube narrowed to the path's own size, SPEC (16.10) (the
    /// Cartesian rule's); read with a path only.
    pub resolve: AdaptimpBoolRaw,
    /// Ĝ learning at the velocity loop's critical bandwidth, SPEC (19.6).
    pub critical: AdaptimpBoolRaw,
    /// The arm bears no gravity the controller must hold (a robot that
    /// compensates it itself), SPEC (22.2).
    pub weightless: AdaptimpBoolRaw,
}

/// The rule's inputs with nothing but the law, the inertia at the start, the
/// limits and the period: [`adaptimp_tuning_init`]'s.
fn tuning_of(
    law: AdaptimpLawRaw,
    inertia: *const f64,
    tau_max: *const f64,
    ts: f64,
) -> AdaptimpTuning {
    AdaptimpTuning {
        law,
        inertia,
        inertia_samples: 0,
        tau_max,
        ts,
        delay: 0,
        coupling: AdaptimpCoupling::Default.into(),
        path: std::ptr::null(),
        rows: 0,
        period: 0.0,
        gravity: std::ptr::null(),
        damping: std::ptr::null(),
        orbit: std::ptr::null(),
        orbit_rows: 0,
        resolve: false.into(),
        critical: false.into(),
        weightless: false.into(),
    }
}

/// `*out` gets the rule's inputs `law`, `inertia` (one n × n matrix at the
/// start), `tau_max` and `ts`, and nothing else: no delay, the default
/// gains, no path, no gravity, damping or orbit, every flag off (the core's
/// `Tuning::new`). The pointers are stored, not read.
///
/// # Safety
/// `out` is NULL or valid for writing one [`AdaptimpTuning`].
#[no_mangle]
pub unsafe extern "C" fn adaptimp_tuning_init(
    out: *mut AdaptimpTuning,
    law: AdaptimpLawRaw,
    inertia: *const f64,
    tau_max: *const f64,
    ts: f64,
) -> AdaptimpStatus {
    guard(|| {
        // SAFETY (in `out`): checked for NULL; the caller's contract.
        *unsafe { crate::out(out, "out") }? = tuning_of(law, inertia, tau_max, ts);
        Ok(())
    })
}

/// The rule of SPEC §18 on everything `tuning` gives, for an arm of `n`
/// joints: `*out` as [`adaptimp_params_suggest`] fills it, and the centres
/// and their squared widths into `centers` and `widths2` with a path. The
/// same inputs give the same parameters as Python's `tuning.suggest` (the
/// core's one `Tuning`); Python reads them from its model: D at the path's
/// rows `0, s, 2s, …` (s = max(1, rows / 50)), G at the path's start, the
/// damping of the plant's joints, `weightless` when the model has no
/// gravity. A field's enum or flag outside its values is INVALID_CONFIG
/// naming it, as is an orbit or a gravity given without a path; a NULL
/// pointer that must be given, NULL_POINTER naming it; a length that
/// overflows, BAD_SIZE. On an error `*out` is left unchanged.
///
/// # Safety
/// `tuning` is NULL or valid; its pointers are NULL or valid for the lengths
/// its fields document; `centers` and `widths2` as [`adaptimp_params_suggest`]'s.
#[no_mangle]
pub unsafe extern "C" fn adaptimp_params_suggest_tuning(
    out: *mut AdaptimpParams,
    n: usize,
    tuning: *const AdaptimpTuning,
    centers: *mut f64,
    widths2: *mut f64,
) -> AdaptimpStatus {
    guard(|| {
        if !(1..=ADAPTIMP_MAX_JOINTS).contains(&n) {
            return Err(bad_n(n));
        }
        // SAFETY (in `out`, `slice`): checked for NULL; the caller's contract.
        let out = unsafe { crate::out(out, "out") }?;
        let t = unsafe { tuning.as_ref() }.ok_or_else(|| null("tuning"))?;
        let law = law_of(decode::<AdaptimpLaw>(t.law, "law")?);
        let times = |k: usize, per: usize, what: &str| {
            k.checked_mul(per)
                .ok_or_else(|| fail(AdaptimpStatus::BadSize, &format_args!("{what} overflows")))
        };
        let inertia = match t.inertia_samples {
            0 => Inertia::At(unsafe { slice(t.inertia, n * n, "inertia") }?),
            k => Inertia::Along(unsafe {
                slice(
                    t.inertia,
                    times(k, n * n, "inertia_samples × n²")?,
                    "inertia",
                )
            }?),
        };
        let tau_max = unsafe { slice(t.tau_max, n, "tau_max") }?;
        let mut rule = Tuning::new(law, inertia, tau_max, t.ts);
        rule.delay = t.delay;
        rule.coupled = match decode::<AdaptimpCoupling>(t.coupling, "coupling")? {
            AdaptimpCoupling::Default => None,
            AdaptimpCoupling::Diagonal => Some(false),
            AdaptimpCoupling::Shaped => Some(true),
        };
        rule.resolve = decode_bool(t.resolve, "resolve")?;
        rule.critical = decode_bool(t.critical, "critical")?;
        rule.weightless = decode_bool(t.weightless, "weightless")?;
        let given = |p: *const f64, len: usize, what: &str| match p.is_null() {
            true => Ok(None),
            false => unsafe { slice(p, len, what) }.map(Some),
        };
        if !t.path.is_null() {
            let rows = unsafe { slice(t.path, times(t.rows, 3 * n, "rows × 3n")?, "path") }?;
            rule.path = Some(TaskPath {
                rows,
                period: t.period,
            });
        }
        rule.gravity = given(t.gravity, n, "gravity")?;
        rule.damping = given(t.damping, n, "damping")?;
        rule.orbit = given(t.orbit, times(t.orbit_rows, n, "orbit_rows × n")?, "orbit")?;
        let s = rule.suggest().map_err(|e| core_error(e, Context::Config))?;
        let mut filled = params_of(&s)?;
        if let Some(c) = s.centres() {
            // SAFETY (in `slice_mut`): the caller gives ADAPTIMP_SUGGEST_MAX_NODES
            // rows of 4n reals and 4n reals, L ≤ that.
            unsafe { slice_mut(centers, c.rows.len(), "centers") }?.copy_from_slice(&c.rows);
            filled.centers = centers;
            filled.nodes = c.rows.len() / (4 * n);
            if let Some(w) = &c.widths2 {
                unsafe { slice_mut(widths2, w.len(), "widths2") }?.copy_from_slice(w);
                filled.widths2 = widths2;
            }
        }
        *out = filled;
        Ok(())
    })
}

/// BadSize for a number of joints outside 1 … 7.
pub(crate) fn bad_n(n: usize) -> AdaptimpStatus {
    fail(
        AdaptimpStatus::BadSize,
        &format_args!("n = {n}: the number of joints must be 1 … 7"),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use adaptimp::schema::{Group, PARAMS};

    #[test]
    fn every_controller_parameter_of_the_schema_is_a_field() {
        // scenario_of sets each controller parameter by name: the defaults
        // round-trip exactly for every size and preset.
        for n in 1..=ADAPTIMP_MAX_JOINTS {
            for preset in Preset::ALL {
                for law in [Law::Pd, Law::StateFeedback, Law::OutputFeedback] {
                    let expect = Scenario::new(n, preset, law).unwrap();
                    let s = scenario_of(&params_of(&expect).unwrap()).unwrap();
                    let controller = |s: &Scenario| {
                        let mut out = Vec::new();
                        s.visit(|name, v| {
                            if PARAMS
                                .iter()
                                .any(|p| p.name == name && p.group == Group::Controller)
                            {
                                out.push(format!("{name} {v:?}"));
                            }
                        });
                        out
                    };
                    assert_eq!(controller(&s).len(), 46);
                    assert_eq!(
                        controller(&s),
                        controller(&expect),
                        "{n} {preset:?} {law:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_inertia_matrix_is_none_by_default_and_read_row_major() {
        let expect = Scenario::new(2, Preset::Robot, Law::StateFeedback).unwrap();
        let mut p = params_of(&expect).unwrap();
        assert!(p.inertia_matrix.iter().all(|x| *x == f64::INFINITY));
        assert_eq!(
            scenario_of(&p)
                .unwrap()
                .controller()
                .unwrap()
                .inertia_matrix(),
            None
        );
        p.inertia_matrix[..4].copy_from_slice(&[2.0, 0.6, 0.6, 0.5]);
        let s = scenario_of(&p).unwrap();
        assert_eq!(
            s.controller().unwrap().inertia_matrix(),
            Some(std::vec![2.0, 0.6, 0.6, 0.5])
        );
        assert_eq!(
            params_of(&s).unwrap().inertia_matrix[..4],
            [2.0, 0.6, 0.6, 0.5]
        );
    }
}
