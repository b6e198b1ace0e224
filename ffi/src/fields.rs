//! The parameter structs' fields by the schema's names, declared once: each
//! struct's table ([`controller_fields`], [`cartesian_fields`]) says which
//! field holds which parameter of the schema and how C writes it (an enum
//! as an integer, INFINITY for none, a flag for a derived value), and the
//! same table reads a struct into the core's scenario ([`read_into`]) and
//! writes the scenario's values into a struct ([`write_from`]).

use crate::*;
use adaptimp::dynamic::Scenario;
use adaptimp::schema::Value;
use adaptimp::{
    AuxLaw, Conditions, Fallback, FaultPolicy, Formulation, Hold, ImpedanceMode, LearningStep,
    ObserverInit, RobustKind, SaturationLearning,
};

/// A C enum whose values are a schema choice's names, in their order.
pub(crate) trait Choice: CEnum {
    /// The schema's names of its values.
    const NAMES: &'static [&'static str];
}

macro_rules! choices {
    ($($e:ident => $names:expr),+ $(,)?) => {
        $(impl Choice for $e {
            const NAMES: &'static [&'static str] = &$names;
        })+
    };
}

choices! {
    AdaptimpAuxLaw => AuxLaw::NAMES,
    AdaptimpConditions => Conditions::NAMES,
    AdaptimpRobust => RobustKind::NAMES,
    AdaptimpLearningStep => LearningStep::NAMES,
    AdaptimpSaturationLearning => SaturationLearning::NAMES,
    AdaptimpObserverInit => ObserverInit::NAMES,
    AdaptimpObserverHold => Hold::NAMES,
    AdaptimpImpedance => ImpedanceMode::NAMES,
    AdaptimpFallback => Fallback::NAMES,
    AdaptimpFaultPolicy => FaultPolicy::NAMES,
    AdaptimpFormulation => Formulation::NAMES,
}

/// The schema's name of choice `raw` of `E`, or INVALID_CONFIG naming `field`.
fn read_choice<E: Choice>(raw: u32, field: &str) -> Result<&'static str, AdaptimpStatus> {
    Ok(E::NAMES[decode::<E>(E::from_raw(raw), field)?.index()])
}

/// The integer of `E`'s choice named `name` by the schema.
fn write_choice<E: Choice>(name: &str) -> u32 {
    E::ALL[E::NAMES.iter().position(|n| *n == name).unwrap_or(0)].value()
}

/// A field of a parameter struct, as the schema's value it carries.
pub(crate) enum Field<'a> {
    /// A real.
    Real(&'a mut f64),
    /// A real whose INFINITY is the schema's none (no clipping).
    Clip(&'a mut f64),
    /// A count (the loop's delay).
    Count(&'a mut usize),
    /// One real per joint, of which the first n are read.
    Joint(&'a mut [f64; ADAPTIMP_MAX_JOINTS]),
    /// Three reals (per network, per axis).
    Three(&'a mut [f64; 3]),
    /// Three reals, or the schema's none (derived: critical damping) when
    /// the flag (`<name>_critical`) is set.
    Derived(&'a mut [f64; 3], &'a mut AdaptimpBoolRaw),
    /// A C bool.
    Flag(&'a mut AdaptimpBoolRaw),
    /// An enum's integer, read and written by its enum.
    Choice(
        &'a mut u32,
        fn(u32, &str) -> Result<&'static str, AdaptimpStatus>,
        fn(&str) -> u32,
    ),
    /// The weight bound: its mode (`<name>_mode`) and its three bounds.
    Bound(&'a mut AdaptimpWeightBoundRaw, &'a mut [f64; 3]),
}

/// The field of enum `E` whose integer is `raw`.
fn choice<E: Choice>(raw: &mut u32) -> Field<'_> {
    Field::Choice(raw, read_choice::<E>, write_choice::<E>)
}

/// `v` into the first of `dst`.
fn copy(dst: &mut [f64], v: &[f64]) {
    let k = v.len().min(dst.len());
    dst[..k].copy_from_slice(&v[..k]);
}

impl Field<'_> {
    /// The value the caller gave (the first `n` of a per-joint field), or
    /// INVALID_CONFIG naming a field (`field`, the struct's name of the
    /// parameter) that is no value of its enum.
    fn value(&self, n: usize, field: &str) -> Result<Value<'_>, AdaptimpStatus> {
        Ok(match self {
            Field::Real(x) => Value::Real(**x),
            Field::Clip(x) if **x == f64::INFINITY => Value::None,
            Field::Clip(x) => Value::Real(**x),
            // usize → i64: a count beyond i64 is refused by the schema's check (≤ 64).
            Field::Count(d) => Value::Int(i64::try_from(**d).unwrap_or(i64::MAX)),
            Field::Joint(v) => Value::Vec(&v[..n]),
            Field::Three(v) => Value::Vec(&v[..]),
            Field::Derived(v, critical) => {
                match decode_bool(**critical, &format!("{field}_critical"))? {
                    true => Value::None,
                    false => Value::Vec(&v[..]),
                }
            }
            Field::Flag(b) => Value::Bool(decode_bool(**b, field)?),
            Field::Choice(raw, read, _) => Value::Str(read(**raw, field)?),
            Field::Bound(mode, v) => {
                match decode::<AdaptimpWeightBound>(**mode, &format!("{field}_mode"))? {
                    AdaptimpWeightBound::None => Value::None,
                    AdaptimpWeightBound::Fixed => Value::Vec(&v[..]),
                    AdaptimpWeightBound::Auto => Value::Str("auto"),
                }
            }
        })
    }

    /// Set from the schema's value `v`.
    fn put(&mut self, v: Value<'_>) {
        match (self, v) {
            (Field::Real(x) | Field::Clip(x), Value::Real(y)) => **x = y,
            (Field::Clip(x), Value::None) => **x = f64::INFINITY,
            (Field::Count(d), Value::Int(i)) => **d = usize::try_from(i).unwrap_or(0),
            (Field::Joint(dst), Value::Vec(v)) => copy(&mut dst[..], v),
            (Field::Three(dst), Value::Vec(v)) => copy(&mut dst[..], v),
            (Field::Derived(dst, critical), Value::None) => {
                **dst = [0.0; 3];
                **critical = true.into();
            }
            (Field::Derived(dst, critical), Value::Vec(v)) => {
                copy(&mut dst[..], v);
                **critical = false.into();
            }
            (Field::Flag(b), Value::Bool(x)) => **b = x.into(),
            (Field::Choice(raw, _, write), Value::Str(s)) => **raw = write(s),
            (Field::Bound(mode, _), Value::None) => **mode = AdaptimpWeightBound::None.raw(),
            (Field::Bound(mode, _), Value::Str(_)) => **mode = AdaptimpWeightBound::Auto.raw(),
            (Field::Bound(mode, dst), Value::Vec(v)) => {
                **mode = AdaptimpWeightBound::Fixed.raw();
                copy(&mut dst[..], v);
            }
            _ => {}
        }
    }
}

/// Set each parameter of `fields` (the first `n` values of a per-joint
/// one) in `s`; every error is a parameter's: INVALID_CONFIG, naming the
/// field as `owner` names the struct ("params", "cart") and the field as
/// the schema names the parameter (in lower case).
pub(crate) fn read_into<'a>(
    s: &mut Scenario,
    n: usize,
    fields: impl IntoIterator<Item = (&'static str, Field<'a>)>,
    owner: &str,
) -> Result<(), AdaptimpStatus> {
    for (name, field) in fields {
        let v = field.value(n, &format!("{owner}.{}", name.to_lowercase()))?;
        s.set(name, v).map_err(|e| core_error(e, Context::Config))?;
    }
    Ok(())
}

/// Each field of `fields` from the value of its parameter in `s`.
pub(crate) fn write_from(s: &Scenario, fields: &mut [(&'static str, Field<'_>)]) {
    s.visit(|name, v| {
        if let Some((_, field)) = fields.iter_mut().find(|(n, _)| *n == name) {
            field.put(v);
        }
    });
}

/// Every controller parameter of the schema as a field of `p`, in the
/// schema's order (the destructuring fails to compile if a field is added
/// without being mapped; `n`, `law` and the centres are not parameters).
pub(crate) fn controller_fields(p: &mut AdaptimpParams) -> [(&'static str, Field<'_>); 45] {
    use Field::{Bound, Count, Flag, Joint, Real, Three};
    let AdaptimpParams {
        n: _,
        law: _,
        centers: _,
        nodes: _,
        widths2: _,
        ts,
        delay,
        k1,
        kp,
        kzeta,
        inertia,
        rho,
        conditions,
        mu,
        aux_law,
        robust,
        kr,
        phi,
        k_remark1: [kd, kc, kg],
        learning_step,
        kappa,
        saturation_learning,
        weight_bound_mode,
        weight_bound,
        gamma,
        sigma,
        eps,
        lam1,
        observer_init,
        observer_hold,
        observer_lead,
        tau_max,
        dd,
        cd,
        gd,
        impedance,
        eta2,
        xc_offset,
        xc_sin,
        xc_cos,
        xc_omega,
        fallback,
        fallback_damping,
        fault_policy,
        q_max,
        dq_max,
        tau_e_max,
        q_jump_max,
        tau_rate_max,
    } = p;
    [
        ("Ts", Real(ts)),
        ("delay", Count(delay)),
        ("K1", Joint(k1)),
        ("Kp", Joint(kp)),
        ("Kzeta", Joint(kzeta)),
        ("inertia", Joint(inertia)),
        ("rho", Real(rho)),
        (
            "conditions",
            choice::<AdaptimpConditions>(&mut conditions.0),
        ),
        ("mu", Real(mu)),
        ("aux_law", choice::<AdaptimpAuxLaw>(&mut aux_law.0)),
        ("robust", choice::<AdaptimpRobust>(&mut robust.0)),
        ("kr", Joint(kr)),
        ("phi", Real(phi)),
        ("kD", Real(kd)),
        ("kC", Real(kc)),
        ("kG", Real(kg)),
        ("gamma", Three(gamma)),
        ("sigma", Three(sigma)),
        ("eta2", Real(eta2)),
        ("eps", Real(eps)),
        ("lam1", Joint(lam1)),
        (
            "observer_init",
            choice::<AdaptimpObserverInit>(&mut observer_init.0),
        ),
        (
            "observer_hold",
            choice::<AdaptimpObserverHold>(&mut observer_hold.0),
        ),
        ("observer_lead", Flag(observer_lead)),
        ("tau_max", Joint(tau_max)),
        ("Dd", Joint(dd)),
        ("Cd", Joint(cd)),
        ("Gd", Joint(gd)),
        ("impedance", choice::<AdaptimpImpedance>(&mut impedance.0)),
        ("xc_offset", Joint(xc_offset)),
        ("xc_sin", Joint(xc_sin)),
        ("xc_cos", Joint(xc_cos)),
        ("xc_omega", Joint(xc_omega)),
        (
            "learning_step",
            choice::<AdaptimpLearningStep>(&mut learning_step.0),
        ),
        ("kappa", Real(kappa)),
        (
            "saturation_learning",
            choice::<AdaptimpSaturationLearning>(&mut saturation_learning.0),
        ),
        ("weight_bound", Bound(weight_bound_mode, weight_bound)),
        ("fallback", choice::<AdaptimpFallback>(&mut fallback.0)),
        ("fallback_damping", Joint(fallback_damping)),
        (
            "fault_policy",
            choice::<AdaptimpFaultPolicy>(&mut fault_policy.0),
        ),
        ("q_max", Joint(q_max)),
        ("dq_max", Joint(dq_max)),
        ("tau_e_max", Joint(tau_e_max)),
        ("q_jump_max", Joint(q_jump_max)),
        ("tau_rate_max", Joint(tau_rate_max)),
    ]
}

/// Every parameter of the schema's group "cartesian" as a field of `p`, in
/// the schema's order (the destructuring fails to compile if a field is
/// added without being mapped).
pub(crate) fn cartesian_fields(p: &mut AdaptimpCartesianParams) -> [(&'static str, Field<'_>); 19] {
    use Field::{Clip, Derived, Flag, Real, Three};
    let AdaptimpCartesianParams {
        md,
        bd,
        bd_critical,
        kd,
        md_rot,
        bd_rot,
        bd_rot_critical,
        kd_rot,
        clik_kp,
        clik_kd,
        clik_lambda,
        clik_lambda_rot,
        null_k,
        null_d,
        pos_error_max,
        rot_error_max,
        target_filter,
        force_filter,
        force_feedforward,
        formulation,
        admittance_share,
    } = p;
    [
        ("Md", Three(md)),
        ("Bd", Derived(bd, bd_critical)),
        ("Kd", Three(kd)),
        ("Md_rot", Three(md_rot)),
        ("Bd_rot", Derived(bd_rot, bd_rot_critical)),
        ("Kd_rot", Three(kd_rot)),
        ("clik_kp", Real(clik_kp)),
        ("clik_kd", Real(clik_kd)),
        ("clik_lambda", Real(clik_lambda)),
        ("clik_lambda_rot", Real(clik_lambda_rot)),
        ("null_k", Real(null_k)),
        ("null_d", Real(null_d)),
        ("pos_error_max", Clip(pos_error_max)),
        ("rot_error_max", Clip(rot_error_max)),
        ("target_filter", Real(target_filter)),
        ("force_filter", Real(force_filter)),
        ("force_feedforward", Flag(force_feedforward)),
        (
            "formulation",
            choice::<AdaptimpFormulation>(&mut formulation.0),
        ),
        ("admittance_share", Real(admittance_share)),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use adaptimp::schema::{Group, PARAMS};

    fn group(g: Group) -> Vec<&'static str> {
        PARAMS
            .iter()
            .filter(|p| p.group == g)
            .map(|p| p.name)
            .collect()
    }

    #[test]
    fn each_table_is_its_groups_parameters_in_the_schemas_order() {
        let mut p = crate::params::BLANK;
        let names: Vec<_> = controller_fields(&mut p).iter().map(|(n, _)| *n).collect();
        assert_eq!(names, group(Group::Controller));
        let mut c = AdaptimpCartesianParams::default();
        let names: Vec<_> = cartesian_fields(&mut c).iter().map(|(n, _)| *n).collect();
        assert_eq!(names, group(Group::Cartesian));
    }

    #[test]
    fn the_c_enums_follow_the_schemas_choice_order() {
        fn check<E: Choice>() {
            assert_eq!(E::ALL.len(), E::NAMES.len(), "{}", E::NAME);
            for (c, name) in E::ALL.iter().zip(E::NAMES) {
                assert_eq!(format!("{c:?}").to_lowercase(), *name, "{}", E::NAME);
            }
        }
        check::<AdaptimpAuxLaw>();
        check::<AdaptimpConditions>();
        check::<AdaptimpFormulation>();
        check::<AdaptimpRobust>();
        check::<AdaptimpLearningStep>();
        check::<AdaptimpSaturationLearning>();
        check::<AdaptimpObserverInit>();
        check::<AdaptimpObserverHold>();
        check::<AdaptimpImpedance>();
        check::<AdaptimpFallback>();
        check::<AdaptimpFaultPolicy>();
    }
}
