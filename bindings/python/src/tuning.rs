//! The gain and basis rule of SPEC §18 for Python (`adaptimp.tuning`), a thin
//! face of [`adaptimp::control::tuning`]: arrays in, the schema's names out.

use super::cartesian_loop::TARGET_LEN;
use super::chain::PyChain;
use super::{array, config_error, law_of, py_value, ConfigError};
use adaptimp::cartesian::rule::{PoseCircle, PostureRule, TaskRows};
use adaptimp::control::tuning::Rule;
use adaptimp::dynamic::{Inertia, TaskPath, Tuning};
use adaptimp::error::Error;
use adaptimp::schema::{Group, PARAMS};
use adaptimp::types::Vector;
use numpy::{
    PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyReadonlyArrayDyn,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

fn shape_error(what: &str, want: String, got: &[usize]) -> PyErr {
    ConfigError::new_err(format!("{what} must have shape {want}, got {got:?}"))
}

/// The rule's controller keywords (every controller parameter of the schema,
/// by name), the centres (L, 4n) and their widths η (4n,) for `case`, an arm
/// of inertia matrix `inertia` (n, n; kg m²; or (K, n, n): the inertia at K
/// postures along the task's path, SPEC (18.1)'s scales along it), limits
/// `tau_max` (n,; N m),
/// period `ts` (s) and, if given, the task's `path` (K, 3n: q, q̇, q̈ per
/// row, one period of `period` s, evenly spaced in time) with the gravity
/// torque `gravity` (n,; N m) at its start, if known. `resolve`: the tube
/// narrowed to the path's own size, SPEC (16.10) (the Cartesian rule's).
/// `critical`: Ĝ learns at the velocity loop's critical bandwidth, SPEC
/// (19.6) (the table scenario's). `damping` (n,; N m s/rad): the joints'
/// viscous damping, if the plant has it: the scales as the sampled velocity
/// loop sees them, SPEC (18.9). `orbit` (K', n; rad): the joint positions of
/// one period of the motion that repeats (the table's circle): the widths in
/// q at least its diameter, SPEC (19.11) (the table scenario's).
/// `weightless`: the arm bears no gravity the controller must hold (a robot
/// that compensates it itself): D̂ and Ĉ learn at Ĝ's bandwidth, SPEC (22.2).
/// `coupled`: the inertia-shaped gains of SPEC (18.12) (the parameter
/// `inertia_matrix`, n × n values row-major); None: the core's default, on
/// for a loop with a delay (δ ≥ 1; with `resolve`, Ĝ then learns faster).
#[pyfunction]
#[pyo3(signature = (case, inertia, tau_max, ts, path=None, period=None, gravity=None, resolve=false, critical=false, damping=None, orbit=None, delay=0, weightless=false, coupled=None))]
#[allow(clippy::too_many_arguments)]
pub fn suggest<'py>(
    py: Python<'py>,
    case: &str,
    inertia: PyReadonlyArrayDyn<'py, f64>,
    tau_max: PyReadonlyArray1<'py, f64>,
    ts: f64,
    path: Option<PyReadonlyArray2<'py, f64>>,
    period: Option<f64>,
    gravity: Option<PyReadonlyArray1<'py, f64>>,
    resolve: bool,
    critical: bool,
    damping: Option<PyReadonlyArray1<'py, f64>>,
    orbit: Option<PyReadonlyArray2<'py, f64>>,
    delay: usize,
    weightless: bool,
    coupled: Option<bool>,
) -> PyResult<Bound<'py, PyDict>> {
    let law = law_of(case)?;
    let shape = inertia.shape();
    let n = match shape {
        [a, b] if a == b => *a,
        [k, a, b] if a == b && *k > 0 => *a,
        _ => 0,
    };
    if !(1..=super::MAX_JOINTS).contains(&n) {
        return Err(shape_error(
            "inertia",
            "(n, n) or (K, n, n), 1 ≤ n ≤ 7".into(),
            shape,
        ));
    }
    let along = shape.len() == 3;
    if tau_max.shape() != [n] {
        return Err(shape_error("tau_max", format!("({n},)"), tau_max.shape()));
    }
    let d: Vec<f64> = inertia.as_array().iter().copied().collect();
    let tau: Vec<f64> = tau_max.as_array().iter().copied().collect();
    let gravity: Option<Vec<f64>> = match gravity {
        None => None,
        Some(g) if g.shape() == [n] => Some(g.as_array().iter().copied().collect()),
        Some(g) => return Err(shape_error("gravity", format!("({n},)"), g.shape())),
    };
    let damping: Option<Vec<f64>> = match damping {
        None => None,
        Some(b) if b.shape() == [n] => Some(b.as_array().iter().copied().collect()),
        Some(b) => return Err(shape_error("damping", format!("({n},)"), b.shape())),
    };
    let orbit: Option<Vec<f64>> = match orbit {
        None => None,
        Some(o) if o.shape()[1] == n => Some(o.as_array().iter().copied().collect()),
        Some(o) => return Err(shape_error("orbit", format!("(K, {n})"), o.shape())),
    };
    let path: Option<(Vec<f64>, f64)> = match (path, period) {
        (None, _) => None,
        (Some(p), Some(period)) => {
            if p.shape()[1] != 3 * n || p.shape()[0] == 0 {
                return Err(shape_error("path", format!("(K, {})", 3 * n), p.shape()));
            }
            Some((p.as_array().iter().copied().collect(), period))
        }
        (Some(_), None) => {
            return Err(ConfigError::new_err("a path needs its period (s)"));
        }
    };
    let mut rule = Tuning::new(
        law,
        if along {
            Inertia::Along(&d)
        } else {
            Inertia::At(&d)
        },
        &tau,
        ts,
    );
    rule.delay = delay;
    rule.path = path.as_ref().map(|(rows, period)| TaskPath {
        rows,
        period: *period,
    });
    rule.gravity = gravity.as_deref();
    rule.damping = damping.as_deref();
    rule.orbit = orbit.as_deref();
    (rule.resolve, rule.critical, rule.weightless) = (resolve, critical, weightless);
    rule.coupled = coupled;
    let s = rule.suggest().map_err(|e| match (e, orbit.as_deref()) {
        // The core's flat index as the array's row and joint.
        (
            Error::NonFinite {
                what: "orbit",
                index,
            },
            Some(o),
        ) => ConfigError::new_err(format!(
            "orbit must be finite (rad), got {} at row {}, joint {}",
            o[index],
            index / n,
            index % n
        )),
        (e, _) => config_error(e.into()),
    })?;
    let out = PyDict::new(py);
    let params = PyDict::new(py);
    let mut res = Ok(());
    s.visit(|name, v| {
        let controller = PARAMS
            .iter()
            .any(|p| p.name == name && p.group == Group::Controller);
        if controller && res.is_ok() {
            res = py_value(py, v).and_then(|v| params.set_item(name, v));
        }
    });
    res?;
    out.set_item("params", params)?;
    if let Some(c) = s.centres() {
        let rows = PyArray1::from_slice(py, &c.rows).reshape([c.rows.len() / (4 * n), 4 * n])?;
        let widths: Vec<f64> = c.widths2.iter().flatten().map(|w| w.sqrt()).collect();
        out.set_item("centers", rows)?;
        out.set_item("widths", PyArray1::from_vec(py, widths))?;
    }
    Ok(out)
}

/// The default task of SPEC §18 about `home` within [`lo`, `hi`] (rad, (n,)
/// each; ±inf for a continuous joint): (offset, sin, cos, omega), the
/// controller's `xc_*` keywords.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn default_task(
    home: PyReadonlyArray1<'_, f64>,
    lo: PyReadonlyArray1<'_, f64>,
    hi: PyReadonlyArray1<'_, f64>,
) -> PyResult<(Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>)> {
    let n = home.len();
    if !(1..=super::MAX_JOINTS).contains(&n) || lo.len() != n || hi.len() != n {
        return Err(ConfigError::new_err(format!(
            "home, lo and hi must have the same shape (n,), 1 ≤ n ≤ 7; got {}, {}, {}",
            n,
            lo.len(),
            hi.len()
        )));
    }
    let [h, l, u] = [home, lo, hi].map(|a| a.as_array().iter().copied().collect::<Vec<f64>>());
    let [offset, sin, cos, omega] = adaptimp::dynamic::default_task(&h, &l, &u)
        .map_err(|e| config_error(e.into()))?
        .map(|v| v.to_vec());
    Ok((offset, sin, cos, omega))
}

/// The default Cartesian task of SPEC (16.8) about the start pose `p0` (3,;
/// m) and `r0` (3, 3; world ← tip), tabulated at t_k = `start` + k·`ts`
/// for k < `steps`: (targets (steps, 24): p, ṗ, p̈, R row-major, ω, ω̇ per
/// row; the span hold + ramp + 1/freq (s); the circle's centre (3,; m)).
/// `radius` (m), `freq` (Hz), `hold`, `ramp` (s): None, the defaults of
/// SPEC (16.8) (3 cm, 0.5 Hz, 1 s, 1 s); `normal` (3,): the circle's plane
/// (None: horizontal; a planar arm's, [`plane_normal`]).
#[pyfunction]
#[pyo3(signature = (p0, r0, ts, steps, radius=None, freq=None, hold=None, ramp=None, start=0.0, normal=None))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
pub fn pose_circle<'py>(
    py: Python<'py>,
    p0: PyReadonlyArray1<'py, f64>,
    r0: PyReadonlyArray2<'py, f64>,
    ts: f64,
    steps: usize,
    radius: Option<f64>,
    freq: Option<f64>,
    hold: Option<f64>,
    ramp: Option<f64>,
    start: f64,
    normal: Option<[f64; 3]>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, f64, Vec<f64>)> {
    if p0.shape() != [3] || r0.shape() != [3, 3] {
        return Err(ConfigError::new_err(format!(
            "p0 must have shape (3,) and r0 (3, 3), got {:?} and {:?}",
            p0.shape(),
            r0.shape()
        )));
    }
    let err = |e: Error| config_error(e.into());
    adaptimp::error::check::positive("Ts > 0", "Ts", ts).map_err(err)?;
    adaptimp::error::check::finite("start", start).map_err(err)?;
    if steps > 100_000_000 {
        return Err(ConfigError::new_err(format!(
            "steps must be at most 1e8, got {steps}"
        )));
    }
    let p = Vector::<3>::from_iterator(p0.as_array().iter().copied());
    let r = nalgebra::Matrix3::from_iterator(r0.as_array().t().iter().copied());
    let c = PoseCircle::in_plane(
        p,
        r,
        Vector::<3>::from(normal.unwrap_or([0.0, 0.0, 1.0])),
        radius.unwrap_or(PoseCircle::RADIUS),
        freq.unwrap_or(PoseCircle::FREQ),
        hold.unwrap_or(PoseCircle::HOLD),
        ramp.unwrap_or(PoseCircle::RAMP),
    )
    .map_err(err)?;
    let mut out = Vec::with_capacity(steps * TARGET_LEN);
    for k in 0..steps {
        let t = c.sample(start + k as f64 * ts);
        for v in [&t.p, &t.dp, &t.ddp] {
            out.extend_from_slice(v.as_slice());
        }
        for i in 0..3 {
            for j in 0..3 {
                out.push(t.r[(i, j)]);
            }
        }
        out.extend_from_slice(t.w.as_slice());
        out.extend_from_slice(t.dw.as_slice());
    }
    Ok((
        array(py, out, (steps, TARGET_LEN))?,
        c.span(),
        c.centre().as_slice().to_vec(),
    ))
}

/// How well a posture runs a task, SPEC (16.9): `chain`, the task's joint
/// orbit `q` (K, n; rad), its commanded positions `p` (K, 3; m), the gravity
/// torque along it `gravity` (K, n; N m), the inertia matrix at its start
/// `d0` (n, n; kg m²), the limits `lo`, `hi` (n,; rad, ±inf: unlimited),
/// `tau_max` (n,; N m), `orients` (the 6 × n Jacobian, else its 3
/// translation rows; `normal` (3,): a planar arm's task, its translation rows
/// within that plane), `k1` (1/s) and `ts` (s) of the joint controller (the
/// conditioning threshold K1·Ts/m; default the joint rule's at 1 kHz),
/// `load` the largest gravity load allowed (default 0.5; 1: gravity within
/// the actuators, for a posture the caller gave).
/// Returns a dict: "sigma_min", "load", "conditioning", "slack",
/// "slack_joint", "reach", "score", "error" (the first condition it
/// violates, with its bound and the value, or None) and "needs" (what each
/// condition needs: the rule's bounds "sigma_min", "load", "conditioning",
/// "reach" and the limits' "margin").
#[pyfunction]
#[pyo3(signature = (chain, q, p, gravity, d0, lo, hi, tau_max, orients, k1=None, ts=None, load=None, normal=None))]
#[allow(clippy::too_many_arguments)]
pub fn assess_posture<'py>(
    py: Python<'py>,
    chain: &PyChain,
    q: PyReadonlyArray2<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
    gravity: PyReadonlyArray2<'py, f64>,
    d0: PyReadonlyArray2<'py, f64>,
    lo: PyReadonlyArray1<'py, f64>,
    hi: PyReadonlyArray1<'py, f64>,
    tau_max: PyReadonlyArray1<'py, f64>,
    orients: bool,
    k1: Option<f64>,
    ts: Option<f64>,
    load: Option<f64>,
    normal: Option<[f64; 3]>,
) -> PyResult<Bound<'py, PyDict>> {
    let rule = posture_rule(k1, ts, load)?;
    let task = match normal {
        None => TaskRows::from(orients),
        Some(n) if !orients => {
            let n = Vector::<3>::from(n);
            let size = n.norm();
            if !(size.is_finite() && size > 0.0) {
                return Err(ConfigError::new_err(format!(
                    "normal must be a finite non-zero vector, got {n:?}"
                )));
            }
            TaskRows::Plane(n / size)
        }
        Some(_) => {
            return Err(ConfigError::new_err(
                "a planar task (normal=) holds no orientation: give orients=False",
            ))
        }
    };
    let kin = chain.chain();
    let n = kin.n();
    check_posture_shapes((&q, &p, &gravity, &d0), (&lo, &hi, &tau_max), n)?;
    let flat = |a: &PyReadonlyArray2<'py, f64>| a.as_array().iter().copied().collect::<Vec<_>>();
    let flat1 = |a: &PyReadonlyArray1<'py, f64>| a.as_array().iter().copied().collect::<Vec<_>>();
    let (q, p, g, d) = (flat(&q), flat(&p), flat(&gravity), flat(&d0));
    let (lo, hi, tau) = (flat1(&lo), flat1(&hi), flat1(&tau_max));
    let a = kin
        .assess_posture(&rule, task, (&q, &p, &g), &d, (&lo, &hi), &tau)
        .map_err(|e| config_error(e.into()))?;
    let error = rule.check(&a).err().map(|e| e.to_string());
    let score = rule.score(&a);
    let out = assessment_dict(py, &a, score, error)?;
    let needs = PyDict::new(py);
    needs.set_item("sigma_min", rule.sigma_min)?;
    needs.set_item("load", rule.load)?;
    needs.set_item("conditioning", rule.conditioning)?;
    needs.set_item("reach", rule.reach)?;
    needs.set_item("margin", rule.margin)?;
    out.set_item("needs", needs)?;
    Ok(out)
}

/// The posture rule of SPEC (16.9) for a joint controller of `k1` (1/s) at
/// `ts` (s) (default the joint rule's at 1 kHz), with the gravity load bound
/// `load` (default 0.5).
fn posture_rule(k1: Option<f64>, ts: Option<f64>, load: Option<f64>) -> PyResult<PostureRule> {
    let joint_rule = Rule::default();
    let ts = ts.unwrap_or(1e-3);
    let mut rule = PostureRule::for_loop(k1.unwrap_or_else(|| joint_rule.k1(ts)), ts, &joint_rule);
    if let Some(l) = load {
        adaptimp::error::check::positive("load > 0", "load", l)
            .map_err(|e| config_error(e.into()))?;
        rule.load = l;
    }
    Ok(rule)
}

/// What each condition of the posture rule (SPEC (16.9); `k1`, `ts`, `load`
/// as [`assess_posture`]'s) needs, with the best value found of each:
/// `best` a dict with "sigma_min", "slack", "slack_joint", "load",
/// "conditioning", "reach" (an assessment, or the best of each over many).
#[pyfunction]
#[pyo3(signature = (best, k1=None, ts=None, load=None))]
pub fn posture_needs(
    best: &Bound<'_, PyDict>,
    k1: Option<f64>,
    ts: Option<f64>,
    load: Option<f64>,
) -> PyResult<String> {
    let rule = posture_rule(k1, ts, load)?;
    let get = |key: &str| -> PyResult<f64> {
        best.get_item(key)?
            .ok_or_else(|| ConfigError::new_err(format!("best needs {key:?}")))?
            .extract()
    };
    let a = adaptimp::cartesian::Assessment {
        sigma_min: get("sigma_min")?,
        load: get("load")?,
        conditioning: get("conditioning")?,
        slack: get("slack")?,
        slack_joint: get("slack_joint")? as usize,
        reach: get("reach")?,
    };
    Ok(rule.needs(&a).to_string())
}

/// The normal (3,) of a planar arm's plane from its 6 × n Jacobian at any
/// posture, SPEC (16.8) ([`adaptimp::cartesian::rule::plane_normal`]), or None
/// for an arm that is not planar.
#[pyfunction]
pub fn plane_normal(jacobian: PyReadonlyArray2<'_, f64>) -> PyResult<Option<[f64; 3]>> {
    let shape = jacobian.shape();
    if shape.len() != 2 || shape[0] != 6 || !(1..=super::MAX_JOINTS).contains(&shape[1]) {
        return Err(shape_error("jacobian", "(6, n), 1 ≤ n ≤ 7".into(), shape));
    }
    let j: Vec<f64> = jacobian.as_array().iter().copied().collect();
    let j = adaptimp::dynamic::Jacobian::from_rows(&j).map_err(|e| config_error(e.into()))?;
    Ok(j.plane_normal().map(|v| [v[0], v[1], v[2]]))
}

/// [`assess_posture`]'s shapes, SPEC (16.9): q (K, n), p (K, 3), gravity
/// (K, n), d0 (n, n), lo, hi, τmax (n,) with K ≥ 1; else a `ConfigError`
/// naming the shapes given.
fn check_posture_shapes(
    (q, p, gravity, d0): (
        &PyReadonlyArray2<'_, f64>,
        &PyReadonlyArray2<'_, f64>,
        &PyReadonlyArray2<'_, f64>,
        &PyReadonlyArray2<'_, f64>,
    ),
    (lo, hi, tau_max): (
        &PyReadonlyArray1<'_, f64>,
        &PyReadonlyArray1<'_, f64>,
        &PyReadonlyArray1<'_, f64>,
    ),
    n: usize,
) -> PyResult<()> {
    let k = q.shape()[0];
    let shape_ok = q.shape() == [k, n]
        && p.shape() == [k, 3]
        && gravity.shape() == [k, n]
        && d0.shape() == [n, n]
        && lo.shape() == [n]
        && hi.shape() == [n]
        && tau_max.shape() == [n];
    if !shape_ok || k == 0 {
        return Err(ConfigError::new_err(format!(
            "assess_posture needs q (K, {n}), p (K, 3), gravity (K, {n}), d0 ({n}, {n}), \
             lo, hi, tau_max ({n},) with K ≥ 1; got q {:?}, p {:?}, gravity {:?}, d0 {:?}",
            q.shape(),
            p.shape(),
            gravity.shape(),
            d0.shape()
        )));
    }
    Ok(())
}

/// [`assess_posture`]'s result, SPEC (16.9): the assessment's figures,
/// the score and the first violated condition as a dict.
fn assessment_dict<'py>(
    py: Python<'py>,
    a: &adaptimp::cartesian::Assessment,
    score: f64,
    error: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("sigma_min", a.sigma_min)?;
    out.set_item("load", a.load)?;
    out.set_item("conditioning", a.conditioning)?;
    out.set_item("slack", a.slack)?;
    out.set_item("slack_joint", a.slack_joint)?;
    out.set_item("reach", a.reach)?;
    out.set_item("score", score)?;
    out.set_item("error", error)?;
    Ok(out)
}

/// The pose errors of a run, SPEC (16.11): the tip of `chain` at every row
/// of `q` (K, n; rad) against the commanded pose of the same row of
/// `targets` (K, 24), with the rows' times `t` (K,; s), the window start
/// `settle` (s) and the period `ts` (s). Returns (e_p (K,; m), e_o (K,;
/// rad), the metrics: a dict of `adaptimp`'s names).
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn pose_metrics<'py>(
    py: Python<'py>,
    chain: &PyChain,
    q: PyReadonlyArray2<'py, f64>,
    targets: PyReadonlyArray2<'py, f64>,
    t: PyReadonlyArray1<'py, f64>,
    settle: f64,
    ts: f64,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyDict>,
)> {
    let kin = chain.chain();
    let n = kin.n();
    let k = q.shape()[0];
    if q.shape() != [k, n] || targets.shape() != [k, TARGET_LEN] || t.shape() != [k] {
        return Err(ConfigError::new_err(format!(
            "pose_metrics needs q (K, {n}), targets (K, {TARGET_LEN}) and t (K,); got {:?}, {:?}, {:?}",
            q.shape(),
            targets.shape(),
            t.shape()
        )));
    }
    let q: Vec<f64> = q.as_array().iter().copied().collect();
    let tg: Vec<f64> = targets.as_array().iter().copied().collect();
    let t: Vec<f64> = t.as_array().iter().copied().collect();
    let (pos, rot) = py
        .detach(|| -> Result<_, Error> {
            let (mut pos, mut rot) = (Vec::with_capacity(k), Vec::with_capacity(k));
            for r in 0..k {
                let (position, rotation) = kin.pose_unchecked(&q[r * n..(r + 1) * n])?;
                let row = &tg[r * TARGET_LEN..(r + 1) * TARGET_LEN];
                let target = nalgebra::Rotation3::from_matrix_unchecked(
                    nalgebra::Matrix3::from_row_slice(&row[9..18]),
                );
                let (ep, eo) = adaptimp::sim::metrics::pose_error(
                    &position,
                    &nalgebra::UnitQuaternion::from_rotation_matrix(&rotation),
                    &Vector::<3>::from_column_slice(&row[..3]),
                    &nalgebra::UnitQuaternion::from_rotation_matrix(&target),
                );
                pos.push(ep);
                rot.push(eo);
            }
            Ok((pos, rot))
        })
        .map_err(|e| config_error(e.into()))?;
    let m = adaptimp::sim::metrics::pose_metrics(&t, &pos, &rot, settle, ts);
    let out = PyDict::new(py);
    for (name, v) in [
        ("rms_pos", m.rms_pos),
        ("rms_pos_after2", m.rms_pos_after2),
        ("max_pos_after2", m.max_pos_after2),
        ("rms_rot", m.rms_rot),
        ("rms_rot_after2", m.rms_rot_after2),
        ("max_rot_after2", m.max_rot_after2),
        ("rms_pos_first2", m.rms_pos_first2),
        ("rms_pos_last2", m.rms_pos_last2),
    ] {
        out.set_item(name, v)?;
    }
    Ok((
        PyArray1::from_vec(py, pos),
        PyArray1::from_vec(py, rot),
        out,
    ))
}

/// The table's metrics of a run, SPEC (19.7) ([`adaptimp::sim::metrics::table_metrics`]):
/// the rows (each K × width, row-major: `t` (K,), `p`, `dp`, `ddp`, `pd`,
/// `pc`, `dpc`, `ddpc` (K, 3), `wrench` (K, 6), `normal` (K,), `tau`,
/// `tau_sat` (K, n)) and what they are compared with (`tau_max` (n,), `md`,
/// `bd`, `kd` (3,), `depth` (m), `series` (N/m), `settle`, `windup_after`,
/// `approach_end`, `ts` (s)). Returns a dict of the metrics by name.
#[pyfunction]
#[allow(clippy::too_many_arguments)]
pub fn table_metrics<'py>(
    py: Python<'py>,
    t: PyReadonlyArray1<'py, f64>,
    p: PyReadonlyArray2<'py, f64>,
    dp: PyReadonlyArray2<'py, f64>,
    ddp: PyReadonlyArray2<'py, f64>,
    pd: PyReadonlyArray2<'py, f64>,
    pc: (
        PyReadonlyArray2<'py, f64>,
        PyReadonlyArray2<'py, f64>,
        PyReadonlyArray2<'py, f64>,
    ),
    wrench: PyReadonlyArray2<'py, f64>,
    normal: PyReadonlyArray1<'py, f64>,
    tau: (PyReadonlyArray2<'py, f64>, PyReadonlyArray2<'py, f64>),
    tau_max: PyReadonlyArray1<'py, f64>,
    impedance: ([f64; 3], [f64; 3], [f64; 3]),
    depth: f64,
    series: f64,
    windows: (f64, f64, f64),
    ts: f64,
) -> PyResult<Bound<'py, PyDict>> {
    use adaptimp::sim::metrics::{table_metrics as core_metrics, TableRows, TableSpec};
    let flat1 = |a: &PyReadonlyArray1<'py, f64>| a.as_array().iter().copied().collect::<Vec<_>>();
    let flat = |a: &PyReadonlyArray2<'py, f64>| a.as_array().iter().copied().collect::<Vec<_>>();
    let (t, normal, tau_max) = (flat1(&t), flat1(&normal), flat1(&tau_max));
    let (p, dp, ddp, pd, wrench) = (flat(&p), flat(&dp), flat(&ddp), flat(&pd), flat(&wrench));
    let (pc0, pc1, pc2) = (flat(&pc.0), flat(&pc.1), flat(&pc.2));
    let (tau0, tau1) = (flat(&tau.0), flat(&tau.1));
    let rows = TableRows {
        t: &t,
        p: &p,
        dp: &dp,
        ddp: &ddp,
        pd: &pd,
        pc: [&pc0, &pc1, &pc2],
        wrench: &wrench,
        normal: &normal,
        tau: [&tau0, &tau1],
    };
    let spec = TableSpec {
        tau_max: &tau_max,
        md: impedance.0,
        bd: impedance.1,
        kd: impedance.2,
        depth,
        series,
        settle: windows.0,
        windup_after: windows.1,
        approach_end: windows.2,
        ts,
    };
    let m = core_metrics(&rows, &spec).map_err(|e| config_error(e.into()))?;
    let out = PyDict::new(py);
    for (name, v) in [
        ("rms_track", m.rms_track),
        ("rms_track_along", m.rms_track_along),
        ("rms_path_xy", m.rms_path_xy),
        ("rms_force", m.rms_force),
        ("rms_imp", m.rms_imp),
        ("force_target", m.force_target),
        ("force_rms_err", m.force_rms_err),
        ("force_chatter", m.force_chatter),
        ("force_mean", m.force_mean),
        ("force_16_1", m.force_16_1),
        ("peak_force", m.peak_force),
        ("contact_lost", m.contact_lost),
        ("sat_duty", m.sat_duty),
        ("peak_tau_ratio", m.peak_tau_ratio),
        ("applied_ratio", m.applied_ratio),
    ] {
        out.set_item(name, v)?;
    }
    Ok(out)
}
