//! Python bindings of the arm reader (SPEC §21): `read_arm` (a URDF path or
//! text) and `arm_from_mujoco` (a compiled MuJoCo model's arrays), each
//! the one reduction's arm as a dict; `adaptimp._description` is their front.

use super::ConfigError;
use adaptimp::cartesian::chain::{JointKind, Transform};
use adaptimp::description::{self, urdf, Arm, DescriptionError, ErrorKind, MujocoArrays, Tree};
use pyo3::exceptions::{PyFileNotFoundError, PyTypeError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::string::String;
use std::vec::Vec;

pyo3::import_exception!(adaptimp._errors, XacroError);

/// A reader's error as Python's: a missing file `FileNotFoundError`, xacro
/// `XacroError`, the rest `ConfigError` (each a `ValueError` but the first).
fn error(e: DescriptionError) -> PyErr {
    match e.kind() {
        ErrorKind::Io => PyFileNotFoundError::new_err(e.message().to_owned()),
        ErrorKind::Xacro => XacroError::new_err(e.message().to_owned()),
        _ => ConfigError::new_err(e.message().to_owned()),
    }
}

fn transform<'py>(py: Python<'py>, t: &Transform) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("translation", t.translation.to_vec())?;
    d.set_item(
        "rotation",
        t.rotation.iter().map(|r| r.to_vec()).collect::<Vec<_>>(),
    )?;
    Ok(d)
}

/// The arm as the contract's dict (docs in `adaptimp._description`).
fn arm_dict<'py>(
    py: Python<'py>,
    tree: &Tree,
    arm: &Arm,
    with_urdf: bool,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let col =
        |f: fn(&description::ArmJoint) -> f64| -> Vec<f64> { arm.joints.iter().map(f).collect() };
    d.set_item("source", &arm.source)?;
    d.set_item(
        "joints",
        arm.joints
            .iter()
            .map(|j| j.name.clone())
            .collect::<Vec<_>>(),
    )?;
    d.set_item(
        "prismatic",
        arm.joints.iter().map(|j| j.prismatic).collect::<Vec<_>>(),
    )?;
    d.set_item("lower", col(|j| j.lower))?;
    d.set_item("upper", col(|j| j.upper))?;
    d.set_item("effort", col(|j| j.effort))?;
    d.set_item("velocity", col(|j| j.velocity))?;
    d.set_item("armature", col(|j| j.armature))?;
    d.set_item("damping", col(|j| j.damping))?;
    d.set_item("friction", col(|j| j.friction))?;
    let chain = PyList::empty(py);
    for j in &arm.chain {
        let e = transform(py, &j.origin)?;
        e.set_item(
            "kind",
            if j.kind == JointKind::Prismatic {
                "prismatic"
            } else {
                "revolute"
            },
        )?;
        e.set_item("axis", j.axis.to_vec())?;
        e.set_item("offset", j.offset)?;
        chain.append(e)?;
    }
    d.set_item("chain", chain)?;
    d.set_item("tip_origin", transform(py, &arm.tip_origin)?)?;
    let inertials = PyList::empty(py);
    for i in &arm.inertials {
        let e = transform(py, &i.origin)?;
        e.set_item("mass", i.mass)?;
        e.set_item(
            "inertia",
            i.inertia.iter().map(|r| r.to_vec()).collect::<Vec<_>>(),
        )?;
        inertials.append(e)?;
    }
    d.set_item("inertials", inertials)?;
    let lifted = PyList::empty(py);
    for l in &arm.lifted {
        let e = PyDict::new(py);
        e.set_item("mass", l.mass)?;
        e.set_item("moment", l.moment.to_vec())?;
        lifted.append(e)?;
    }
    d.set_item("lifted", lifted)?;
    d.set_item("warnings", arm.warnings.clone())?;
    d.set_item(
        "inertia_error",
        arm.inertia_error.as_ref().map(|e| e.message().to_owned()),
    )?;
    d.set_item("base", &arm.base)?;
    d.set_item("tip", &arm.tip)?;
    d.set_item("tip_is_frame", arm.tip_is_frame)?;
    let fixed = PyDict::new(py);
    let held = PyDict::new(py);
    for h in &arm.held {
        fixed.set_item(&h.name, h.reason.to_string())?;
        held.set_item(&h.name, h.value)?;
    }
    d.set_item("fixed", fixed)?;
    d.set_item("balanced", arm.balanced.clone())?;
    d.set_item("held", held)?;
    for (key, drive) in [("urdf", false), ("urdf_drive", true)] {
        if with_urdf {
            d.set_item(key, urdf::reduced_urdf(tree, arm, drive).map_err(error)?)?;
        } else {
            d.set_item(key, py.None())?;
        }
    }
    Ok(d)
}

/// The arm of a URDF (SPEC §21): `source` is the path of a URDF file or,
/// if it starts with "<", URDF text; `tip` a link (None: found by the
/// rule of (21.2)); `fix` joints to hold. Returns the arm as a dict.
/// Errors: `FileNotFoundError` (no such file), `XacroError` (xacro markup),
/// `ConfigError` naming the file, the element and what to do.
/// `label` names URDF text in messages (default "URDF text").
#[pyfunction]
#[pyo3(signature = (source, tip=None, fix=None, label=None))]
pub fn read_arm<'py>(
    py: Python<'py>,
    source: &str,
    tip: Option<&str>,
    fix: Option<Vec<String>>,
    label: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let fix = fix.unwrap_or_default();
    let fix: Vec<&str> = fix.iter().map(String::as_str).collect();
    let mut signals = Signals::new();
    let (tree, arm) = py
        .detach(|| {
            let go_on = &mut || signals.go_on();
            let tree = if urdf::is_text(source) {
                urdf::read_str_with(source, label, go_on)?
            } else {
                urdf::read_file_with(source, go_on)?
            };
            let arm = description::reduce(&tree, tip, &fix)?;
            Ok::<_, DescriptionError>((tree, arm))
        })
        .map_err(|e| signals.error(e))?;
    arm_dict(py, &tree, &arm, true)
}

/// A reading's Ctrl-C: signals checked at most every 50 ms of its work,
/// with the GIL taken only then; the error (`KeyboardInterrupt`) kept.
struct Signals {
    last: std::time::Instant,
    raised: Option<PyErr>,
}

impl Signals {
    fn new() -> Self {
        Self {
            last: std::time::Instant::now(),
            raised: None,
        }
    }

    fn go_on(&mut self) -> bool {
        if self.last.elapsed() < super::hooks::CHECK_EVERY {
            return true;
        }
        self.last = std::time::Instant::now();
        match Python::attach(|py| py.check_signals()) {
            Ok(()) => true,
            Err(e) => {
                self.raised = Some(e);
                false
            }
        }
    }

    /// The reading's error as Python's: the signal's own if it stopped it.
    fn error(&mut self, e: DescriptionError) -> PyErr {
        match (e.kind(), self.raised.take()) {
            (ErrorKind::Stopped, Some(raised)) => raised,
            _ => error(e),
        }
    }
}

/// What the file at `path` is: "urdf", "xacro", "mjcf", "mjcf-fragment" or "unknown" (by its
/// root element and its markup). `FileNotFoundError` if it cannot be read.
#[pyfunction]
pub fn description_kind(py: Python<'_>, path: &str) -> PyResult<&'static str> {
    let text = urdf::read_text(std::path::Path::new(path), "description").map_err(|e| {
        PyFileNotFoundError::new_err(format!(
            "cannot read '{}': {e}: give the path of a URDF, xacro or MJCF file",
            urdf::shown_path(std::path::Path::new(path))
        ))
    })?;
    let mut signals = Signals::new();
    py.detach(|| urdf::kind_of_with(&text, &mut || signals.go_on()))
        .map_err(|e| signals.error(e))
}

fn get<'py, T: FromPyObjectOwned<'py>>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<T> {
    match d.get_item(key)? {
        Some(v) => v
            .extract()
            .map_err(|_| PyTypeError::new_err(format!("arrays[{key:?}] has the wrong type"))),
        None => Err(PyTypeError::new_err(format!("arrays has no {key:?}"))),
    }
}

fn mujoco_arrays(d: &Bound<'_, PyDict>) -> PyResult<MujocoArrays> {
    Ok(MujocoArrays {
        model_name: get(d, "model_name")?,
        body_name: get(d, "body_name")?,
        body_parentid: get(d, "body_parentid")?,
        body_pos: get(d, "body_pos")?,
        body_quat: get(d, "body_quat")?,
        body_mass: get(d, "body_mass")?,
        body_gravcomp: match d.get_item("body_gravcomp")? {
            Some(_) => get(d, "body_gravcomp")?,
            None => Vec::new(),
        },
        body_ipos: get(d, "body_ipos")?,
        body_iquat: get(d, "body_iquat")?,
        body_inertia: get(d, "body_inertia")?,
        jnt_name: get(d, "jnt_name")?,
        jnt_type: get(d, "jnt_type")?,
        jnt_bodyid: get(d, "jnt_bodyid")?,
        jnt_pos: get(d, "jnt_pos")?,
        jnt_axis: get(d, "jnt_axis")?,
        jnt_limited: get(d, "jnt_limited")?,
        jnt_range: get(d, "jnt_range")?,
        jnt_qpos0: get(d, "jnt_qpos0")?,
        jnt_armature: get(d, "jnt_armature")?,
        jnt_damping: get(d, "jnt_damping")?,
        jnt_frictionloss: get(d, "jnt_frictionloss")?,
        jnt_actfrclimited: get(d, "jnt_actfrclimited")?,
        jnt_actfrcrange: get(d, "jnt_actfrcrange")?,
        site_name: get(d, "site_name")?,
        site_bodyid: get(d, "site_bodyid")?,
        site_pos: get(d, "site_pos")?,
        site_quat: get(d, "site_quat")?,
        actuator_trntype: get(d, "actuator_trntype")?,
        actuator_trnid: get(d, "actuator_trnid")?,
        actuator_gear: get(d, "actuator_gear")?,
        actuator_forcelimited: get(d, "actuator_forcelimited")?,
        actuator_forcerange: get(d, "actuator_forcerange")?,
        actuator_ctrllimited: get(d, "actuator_ctrllimited")?,
        actuator_ctrlrange: get(d, "actuator_ctrlrange")?,
        actuator_gaintype: get(d, "actuator_gaintype")?,
        actuator_gain: get(d, "actuator_gain")?,
        actuator_biastype: get(d, "actuator_biastype")?,
        eq_type: get(d, "eq_type")?,
        eq_obj1id: get(d, "eq_obj1id")?,
        eq_obj2id: get(d, "eq_obj2id")?,
        eq_data: get(d, "eq_data")?,
        eq_active: get(d, "eq_active")?,
        force_sites: get(d, "force_sites")?,
        tendons: get(d, "tendons")?,
    })
}

/// The arm of a compiled MuJoCo model (SPEC §21): `arrays` its arrays as
/// `adaptimp._description.mujoco_arrays` gathers them, `source` its label
/// for messages (e.g. "MJCF 'robot.xml'"), `tip` a body or a site, `fix`
/// joints to hold. Returns the arm as a dict (its "urdf" is None).
#[pyfunction]
#[pyo3(signature = (arrays, source, tip=None, fix=None))]
pub fn arm_from_mujoco<'py>(
    py: Python<'py>,
    arrays: &Bound<'py, PyDict>,
    source: &str,
    tip: Option<&str>,
    fix: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let arrays = mujoco_arrays(arrays)?;
    let fix = fix.unwrap_or_default();
    let fix: Vec<&str> = fix.iter().map(String::as_str).collect();
    let (tree, arm) = py
        .detach(|| {
            let tree = arrays.tree(source)?;
            let arm = description::reduce(&tree, tip, &fix)?;
            Ok::<_, DescriptionError>((tree, arm))
        })
        .map_err(error)?;
    arm_dict(py, &tree, &arm, false)
}

/// The effort limits (N m, per joint) of an arm whose description states
/// none, by the core's one rule (`adaptimp::dynamic::estimate_effort`):
/// 2 (max |G_i| + 10 rad/s² · max Σ_j |D_ij| + b_i · 1 rad/s + F_i) over the
/// sampled postures. `gravity` (K, n; N m) and `inertia` (K, n, n; kg m²)
/// at K postures; `damping` (n,; N m s/rad) and `friction` (n,; N m), both
/// or neither.
#[pyfunction]
#[pyo3(signature = (gravity, inertia, damping=None, friction=None))]
pub fn estimate_effort<'py>(
    py: Python<'py>,
    gravity: numpy::PyReadonlyArray2<'py, f64>,
    inertia: numpy::PyReadonlyArray3<'py, f64>,
    damping: Option<numpy::PyReadonlyArray1<'py, f64>>,
    friction: Option<numpy::PyReadonlyArray1<'py, f64>>,
) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
    use numpy::PyUntypedArrayMethods;
    let n = gravity.shape()[1];
    let flat = |a: numpy::PyReadonlyArray1<'py, f64>| a.as_array().to_vec();
    let g: Vec<f64> = gravity.as_array().iter().copied().collect();
    let d: Vec<f64> = inertia.as_array().iter().copied().collect();
    if inertia.shape()[1..] != [n, n] || inertia.shape()[0] != gravity.shape()[0] {
        return Err(ConfigError::new_err(format!(
            "inertia must have shape ({}, {n}, {n}), got {:?}",
            gravity.shape()[0],
            inertia.shape()
        )));
    }
    let drag = match (damping, friction) {
        (None, None) => None,
        (Some(b), Some(f)) => Some((flat(b), flat(f))),
        _ => {
            return Err(ConfigError::new_err(
                "damping and friction are given together (N m s/rad, N m), or neither",
            ))
        }
    };
    let s = adaptimp::dynamic::Sampled {
        n,
        gravity: &g,
        inertia: &d,
    };
    let out = adaptimp::dynamic::estimate_effort(
        &s,
        drag.as_ref().map(|(b, f)| (b.as_slice(), f.as_slice())),
    )
    .map_err(|e| super::config_error(e.into()))?;
    Ok(numpy::PyArray1::from_vec(py, out))
}
