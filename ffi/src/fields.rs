//! The parameter structs read and written through the core's schema: a C
//! field is its parameter's name in lower case, so the tables here
//! ([`controller_fields`], [`cartesian_fields`]) say only where each
//! parameter sits in its struct; what the field means is the parameter's
//! kind in `adaptimp::schema::PARAMS` (an optional's none is INFINITY, a
//! limit's none INFINITY per joint, a choice the C enum's value in the
//! order of the kind's names), and the schema's scenario checks the value.

use crate::*;
use adaptimp::dynamic::Scenario;
use adaptimp::schema::{param, Group, Kind, Param, Value, PARAMS};

/// Where a parameter sits in a C struct, by the C type that holds it.
pub(crate) enum Field<'a> {
    /// A real (INFINITY: none, for an optional parameter).
    Real(&'a mut f64),
    /// A count (the loop's delay).
    Count(&'a mut usize),
    /// One real per joint, of which the first n are read.
    Joint(&'a mut [f64; ADAPTIMP_MAX_JOINTS]),
    /// n × n row-major in the first n² values; INFINITY first: none.
    Matrix(&'a mut [f64; ADAPTIMP_MAX_MATRIX]),
    /// Three reals (per network, per axis).
    Three(&'a mut [f64; 3]),
    /// Three reals, or the schema's none (derived: critical damping) when
    /// the flag (`<name>_critical`) is set.
    Derived(&'a mut [f64; 3], &'a mut AdaptimpBoolRaw),
    /// A C bool.
    Flag(&'a mut AdaptimpBoolRaw),
    /// An enum's integer: its position in the enum (INVALID_CONFIG naming
    /// the field if it is none of its values), and the integer at a position
    /// (none past the enum's end).
    Choice(
        &'a mut u32,
        fn(u32, &str) -> Result<usize, AdaptimpStatus>,
        fn(usize) -> Option<u32>,
    ),
    /// The weight bound: its mode (`<name>_mode`) and its three bounds.
    Bound(&'a mut AdaptimpWeightBoundRaw, &'a mut [f64; 3]),
}

impl<'a> Field<'a> {
    /// The field of enum `E` whose integer is `raw`.
    pub(crate) fn choice<E: CEnum>(raw: &'a mut u32) -> Self {
        Field::Choice(
            raw,
            |v, field| Ok(decode::<E>(E::from_raw(v), field)?.index()),
            |i| E::ALL.get(i).map(|e| e.value()),
        )
    }
}

macro_rules! from_places {
    ($($t:ty => $v:ident),+) => {
        $(impl<'a> From<&'a mut $t> for Field<'a> {
            fn from(x: &'a mut $t) -> Self {
                Field::$v(x)
            }
        })+
    };
}

from_places! {
    f64 => Real,
    usize => Count,
    [f64; ADAPTIMP_MAX_JOINTS] => Joint,
    [f64; ADAPTIMP_MAX_MATRIX] => Matrix,
    [f64; 3] => Three,
    AdaptimpBoolRaw => Flag
}

/// `v` into the first `len` of `dst`, or INTERNAL naming `field` if `v`
/// has another length or `dst` is shorter: a value the struct cannot hold
/// is never cut or dropped.
fn copy(dst: &mut [f64], len: usize, v: &[f64], field: &str) -> Result<(), AdaptimpStatus> {
    match dst.get_mut(..len) {
        Some(dst) if v.len() == len => {
            dst.copy_from_slice(v);
            Ok(())
        }
        _ => Err(internal(&format_args!(
            "{field}: the core gave {} values, the field takes {len} (of its {})",
            v.len(),
            dst.len()
        ))),
    }
}

/// INTERNAL, with `what` recorded: the schema and a struct's table disagree
/// (a bug of this crate, not of the caller's values).
fn internal(what: &dyn std::fmt::Display) -> AdaptimpStatus {
    fail(AdaptimpStatus::Internal, what)
}

/// The names of a choice parameter's values (none for another kind).
fn names(kind: Kind) -> &'static [&'static str] {
    match kind {
        Kind::Choice(names) => names,
        _ => &[],
    }
}

impl Field<'_> {
    /// The value the caller gave for a parameter of `kind` (the first `n`
    /// of a per-joint field), or INVALID_CONFIG naming a field (`field`,
    /// the struct's name of the parameter) that is no value of its enum.
    fn value(&self, kind: Kind, n: usize, field: &str) -> Result<Value<'_>, AdaptimpStatus> {
        Ok(match self {
            Field::Real(x) if **x == f64::INFINITY && kind == Kind::Optional => Value::None,
            Field::Real(x) => Value::Real(**x),
            // usize → i64: a count beyond i64 is refused by the schema's check (≤ 64).
            Field::Count(d) => Value::Int(i64::try_from(**d).unwrap_or(i64::MAX)),
            Field::Joint(v) => Value::Vec(&v[..n]),
            Field::Matrix(v) if v[0] == f64::INFINITY => Value::None,
            Field::Matrix(v) => Value::Vec(&v[..n * n]),
            Field::Three(v) => Value::Vec(&v[..]),
            Field::Derived(v, critical) => {
                match decode_bool(**critical, &format!("{field}_critical"))? {
                    true => Value::None,
                    false => Value::Vec(&v[..]),
                }
            }
            Field::Flag(b) => Value::Bool(decode_bool(**b, field)?),
            Field::Choice(raw, index, _) => {
                let i = index(**raw, field)?;
                Value::Str(names(kind).get(i).copied().ok_or_else(|| {
                    fail(
                        AdaptimpStatus::Internal,
                        &format_args!("{field}: the schema has no choice {i}"),
                    )
                })?)
            }
            Field::Bound(mode, v) => {
                match decode::<AdaptimpWeightBound>(**mode, &format!("{field}_mode"))? {
                    AdaptimpWeightBound::None => Value::None,
                    AdaptimpWeightBound::Fixed => Value::Vec(&v[..]),
                    AdaptimpWeightBound::Auto => Value::Str("auto"),
                }
            }
        })
    }

    /// Set from the schema's value `v` of a parameter of `kind` (`n`
    /// values of a per-joint one), or INTERNAL naming `field` if the field
    /// cannot hold `v` as it is: another kind, another length, a choice the
    /// C enum lacks, a negative count.
    fn put(
        &mut self,
        kind: Kind,
        n: usize,
        v: Value<'_>,
        field: &str,
    ) -> Result<(), AdaptimpStatus> {
        match (self, v) {
            (Field::Real(x), Value::Real(y)) => **x = y,
            (Field::Real(x), Value::None) if kind == Kind::Optional => **x = f64::INFINITY,
            (Field::Count(d), Value::Int(i)) => {
                **d = usize::try_from(i)
                    .map_err(|_| internal(&format_args!("{field}: the count {i} is negative")))?;
            }
            (Field::Joint(dst), Value::Vec(v)) => copy(&mut dst[..], n, v, field)?,
            (Field::Joint(dst), Value::None) if kind == Kind::Limit => dst.fill(f64::INFINITY),
            (Field::Matrix(dst), Value::Vec(v)) => copy(&mut dst[..], n * n, v, field)?,
            (Field::Matrix(dst), Value::None) => dst.fill(f64::INFINITY),
            (Field::Three(dst), Value::Vec(v)) => copy(&mut dst[..], 3, v, field)?,
            (Field::Derived(dst, critical), Value::None) => {
                **dst = [0.0; 3];
                **critical = true.into();
            }
            (Field::Derived(dst, critical), Value::Vec(v)) => {
                copy(&mut dst[..], 3, v, field)?;
                **critical = false.into();
            }
            (Field::Flag(b), Value::Bool(x)) => **b = x.into(),
            (Field::Choice(raw, _, int), Value::Str(s)) => {
                let i = names(kind).iter().position(|n| *n == s);
                **raw = i.and_then(int).ok_or_else(|| {
                    internal(&format_args!("{field}: the C enum has no value \"{s}\""))
                })?;
            }
            (Field::Bound(mode, _), Value::None) => **mode = AdaptimpWeightBound::None.raw(),
            (Field::Bound(mode, _), Value::Str("auto")) => {
                **mode = AdaptimpWeightBound::Auto.raw();
            }
            (Field::Bound(mode, dst), Value::Vec(v)) => {
                copy(&mut dst[..], 3, v, field)?;
                **mode = AdaptimpWeightBound::Fixed.raw();
            }
            (_, v) => {
                return Err(internal(&format_args!(
                    "{field}: the field cannot hold the {} value {v:?}",
                    kind.name()
                )))
            }
        }
        Ok(())
    }
}

/// A struct's table: each parameter's name (the schema's, but for case)
/// and where it sits.
pub(crate) type Table<'a> = Vec<(&'static str, Field<'a>)>;

/// The field of `table` that holds parameter `p`.
fn field_of<'t, 'a>(table: &'t mut Table<'a>, p: &Param) -> Option<&'t mut Field<'a>> {
    table
        .iter_mut()
        .find(|(name, _)| name.eq_ignore_ascii_case(p.name))
        .map(|(_, f)| f)
}

/// Set each parameter of `group` in `s` from its field of `table` (the
/// first `n` values of a per-joint one), in the schema's order; every error
/// is a parameter's: INVALID_CONFIG, naming the field as `owner` names the
/// struct ("params", "cart") and the field as the schema names the
/// parameter (in lower case).
pub(crate) fn read_into(
    s: &mut Scenario,
    n: usize,
    group: Group,
    mut table: Table<'_>,
    owner: &str,
) -> Result<(), AdaptimpStatus> {
    for p in PARAMS.iter().filter(|p| p.group == group) {
        let field = &format!("{owner}.{}", p.name.to_lowercase());
        let Some(f) = field_of(&mut table, p) else {
            return Err(fail(AdaptimpStatus::Internal, &format_args!("no {field}")));
        };
        let v = f.value(p.kind, n, field)?;
        s.set(p.name, v)
            .map_err(|e| core_error(e, Context::Config))?;
    }
    Ok(())
}

/// Each field of `table` from the value of its parameter (of `group`) in
/// `s` (the first `s.n()` of a per-joint one), or INTERNAL naming the first
/// parameter of `group` that has no field or whose value its field cannot
/// hold (`owner` names the struct, as in [`read_into`]): nothing is skipped.
pub(crate) fn write_from(
    s: &Scenario,
    group: Group,
    mut table: Table<'_>,
    owner: &str,
) -> Result<(), AdaptimpStatus> {
    let mut out = Ok(());
    s.visit(|name, v| {
        if out.is_err() {
            return;
        }
        let Some(p) = param(name) else {
            out = Err(internal(&format_args!(
                "the schema has no parameter {name}"
            )));
            return;
        };
        if p.group != group {
            return;
        }
        let field = &format!("{owner}.{}", p.name.to_lowercase());
        out = match field_of(&mut table, p) {
            Some(f) => f.put(p.kind, s.n(), v, field),
            None => Err(internal(&format_args!("no {field}"))),
        };
    });
    out
}

/// The table of `$p`: each named field by its own name, then the others.
macro_rules! table {
    ($p:ident: $($f:ident),+; $($name:literal => $field:expr),+ $(,)?) => {
        vec![$((stringify!($f), Field::from(&mut $p.$f)),)+ $(($name, $field)),+]
    };
}

/// Every controller parameter of the schema as a field of `p` (`n`, `law`
/// and the centres are not parameters).
pub(crate) fn controller_fields(p: &mut AdaptimpParams) -> Table<'_> {
    let [kd, kc, kg] = &mut p.k_remark1;
    table!(p: ts, delay, k1, kp, kzeta, inertia, inertia_matrix, rho, conditions, mu, aux_law, robust, kr,
        phi, learning_step, kappa, saturation_learning, gamma, sigma, eps, lam1,
        observer_init, observer_hold, observer_lead, tau_max, dd, cd, gd, impedance, eta2,
        xc_offset, xc_sin, xc_cos, xc_omega, fallback, fallback_damping, fault_policy, q_max,
        dq_max, tau_e_max, q_jump_max, tau_rate_max;
        "kD" => Field::Real(kd),
        "kC" => Field::Real(kc),
        "kG" => Field::Real(kg),
        "weight_bound" => Field::Bound(&mut p.weight_bound_mode, &mut p.weight_bound),
    )
}

/// Every parameter of the schema's group "cartesian" as a field of `p`.
pub(crate) fn cartesian_fields(p: &mut AdaptimpCartesianParams) -> Table<'_> {
    table!(p: md, kd, md_rot, kd_rot, clik_kp, clik_kd, clik_lambda, clik_lambda_rot, null_k,
        null_d, pos_error_max, rot_error_max, target_filter, force_filter, force_feedforward,
        formulation, admittance_share;
        "Bd" => Field::Derived(&mut p.bd, &mut p.bd_critical),
        "Bd_rot" => Field::Derived(&mut p.bd_rot, &mut p.bd_rot_critical),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The schema's parameters of `group`, and which of them `table` holds
    /// (each once).
    fn coverage(table: &mut Table<'_>, group: Group) {
        let names: Vec<_> = PARAMS.iter().filter(|p| p.group == group).collect();
        assert_eq!(table.len(), names.len(), "{group:?}");
        for p in names {
            let held = table
                .iter()
                .filter(|(n, _)| n.eq_ignore_ascii_case(p.name))
                .count();
            assert_eq!(held, 1, "{}", p.name);
            assert!(field_of(table, p).is_some());
        }
    }

    #[test]
    fn each_table_holds_each_parameter_of_its_group_once() {
        let mut p = crate::params::BLANK;
        coverage(&mut controller_fields(&mut p), Group::Controller);
        let mut c = AdaptimpCartesianParams::default();
        coverage(&mut cartesian_fields(&mut c), Group::Cartesian);
    }

    /// The fields of `pub struct <name>` in `source`, in order.
    fn struct_fields<'s>(source: &'s str, name: &str) -> Vec<&'s str> {
        let head = format!("pub struct {name} {{");
        let body = source.split(&head).nth(1).unwrap_or_default();
        let body = body.split("\n}").next().unwrap_or_default();
        body.lines()
            .filter_map(|l| l.trim().strip_prefix("pub "))
            .filter_map(|l| l.split(':').next())
            .collect()
    }

    /// Every field of a parameter struct is in its table, or is one of the
    /// few that hold no parameter of their own name (the joint count, the
    /// law, the centres, a composite's parts): a field added to the struct
    /// and not to the table is named here, not dropped.
    #[test]
    fn each_struct_field_is_a_parameter_or_named_as_not_one() {
        fn unmapped(fields: Vec<&str>, table: &Table<'_>) -> Vec<String> {
            assert!(!fields.is_empty());
            fields
                .into_iter()
                .filter(|f| !table.iter().any(|(n, _)| n == f))
                .map(str::to_string)
                .collect()
        }
        let mut p = crate::params::BLANK;
        let fields = struct_fields(include_str!("params.rs"), "AdaptimpParams");
        assert_eq!(
            unmapped(fields, &controller_fields(&mut p)),
            [
                "n",
                "law",
                "k_remark1",
                "weight_bound_mode",
                "centers",
                "nodes",
                "widths2"
            ]
        );
        let mut c = AdaptimpCartesianParams::default();
        let fields = struct_fields(include_str!("cartesian.rs"), "AdaptimpCartesianParams");
        assert_eq!(
            unmapped(fields, &cartesian_fields(&mut c)),
            ["bd", "bd_critical", "bd_rot", "bd_rot_critical"]
        );
    }

    /// This thread's last error message.
    fn last_error() -> String {
        // SAFETY: the library's NUL-terminated buffer.
        unsafe { std::ffi::CStr::from_ptr(crate::adaptimp_last_error()) }
            .to_string_lossy()
            .into_owned()
    }

    /// The Cartesian table of `c` with parameter Md's field replaced by
    /// `md` (none: left out).
    fn with_md<'a>(c: &'a mut AdaptimpCartesianParams, md: Option<Field<'a>>) -> Table<'a> {
        let mut table: Table<'a> = cartesian_fields(c)
            .into_iter()
            .filter(|(name, _)| *name != "md")
            .collect();
        table.extend(md.map(|f| ("md", f)));
        table
    }

    /// A value its field cannot hold (another length, another kind) and a
    /// parameter without a field are INTERNAL errors naming the field, never
    /// cut to fit or skipped: the three values of Md in a per-joint field of
    /// a 2-joint scenario were once cut to the first two, and a field of
    /// another kind or none at all left the struct's value as it was.
    #[test]
    fn a_value_its_field_cannot_hold_is_an_error_naming_the_field() {
        let s = Scenario::new(2, adaptimp::schema::Preset::Robot, adaptimp::Law::Pd).unwrap();
        let mut c = AdaptimpCartesianParams::default();
        let mut joint = [-1.0; ADAPTIMP_MAX_JOINTS];
        let table = with_md(&mut c, Some(Field::Joint(&mut joint)));
        let out = write_from(&s, Group::Cartesian, table, "cart");
        assert_eq!(out, Err(AdaptimpStatus::Internal));
        assert_eq!(
            last_error(),
            "cart.md: the core gave 3 values, the field takes 2 (of its 7)"
        );
        assert_eq!(joint, [-1.0; ADAPTIMP_MAX_JOINTS]);

        let mut c = AdaptimpCartesianParams::default();
        let mut real = -1.0;
        let table = with_md(&mut c, Some(Field::Real(&mut real)));
        let out = write_from(&s, Group::Cartesian, table, "cart");
        assert_eq!(out, Err(AdaptimpStatus::Internal));
        assert_eq!(
            last_error(),
            "cart.md: the field cannot hold the axes value Vec([2.0, 2.0, 2.0])"
        );
        assert_eq!(real, -1.0);

        let mut c = AdaptimpCartesianParams::default();
        let out = write_from(&s, Group::Cartesian, with_md(&mut c, None), "cart");
        assert_eq!(out, Err(AdaptimpStatus::Internal));
        assert_eq!(last_error(), "no cart.md");

        // Each struct's own table holds every default of every size.
        for n in 1..=ADAPTIMP_MAX_JOINTS {
            let s = Scenario::new(n, adaptimp::schema::Preset::Robot, adaptimp::Law::Pd).unwrap();
            let mut c = AdaptimpCartesianParams::default();
            assert_eq!(
                write_from(&s, Group::Cartesian, cartesian_fields(&mut c), "cart"),
                Ok(())
            );
        }
    }

    #[test]
    fn the_c_enums_follow_the_schemas_choice_order() {
        fn check<E: CEnum>(name: &str) {
            let names = names(param(name).unwrap().kind);
            assert_eq!(E::ALL.len(), names.len(), "{}", E::NAME);
            for (c, n) in E::ALL.iter().zip(names) {
                assert_eq!(format!("{c:?}").to_lowercase(), *n, "{}", E::NAME);
            }
        }
        check::<AdaptimpAuxLaw>("aux_law");
        check::<AdaptimpConditions>("conditions");
        check::<AdaptimpFormulation>("formulation");
        check::<AdaptimpRobust>("robust");
        check::<AdaptimpLearningStep>("learning_step");
        check::<AdaptimpSaturationLearning>("saturation_learning");
        check::<AdaptimpObserverInit>("observer_init");
        check::<AdaptimpObserverHold>("observer_hold");
        check::<AdaptimpImpedance>("impedance");
        check::<AdaptimpFallback>("fallback");
        check::<AdaptimpFaultPolicy>("fault_policy");
    }
}
