//! Joints and frames of a serial chain from Python dicts (the joint data
//! `Chain` and `ComputedTorque` take): the conversions both bindings use.

use super::errors::ConfigError;
use adaptimp::cartesian::dynamics::Inertial;
use adaptimp::cartesian::{Joint, JointKind, Transform};
use adaptimp::error::Error;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::vec::Vec;

/// The keys of an origin in a joint's or the tip's dict.
const ORIGIN_KEYS: [&str; 6] = ["xyz", "rpy", "pos", "quat", "translation", "rotation"];

/// A transform from a dict: {"xyz", "rpy"} (URDF), {"pos", "quat"} (MuJoCo,
/// [w, x, y, z]) or {"translation", "rotation"} (3 × 3, row-major); empty:
/// the identity.
pub fn transform(d: &Bound<'_, PyDict>) -> PyResult<Transform> {
    let get = |key: &str, len: usize| -> PyResult<Option<Vec<f64>>> {
        match d.get_item(key)? {
            None => Ok(None),
            Some(v) => {
                let v: Vec<f64> = v
                    .call_method0("__iter__")
                    .ok()
                    .and_then(|_| {
                        v.extract::<Vec<Vec<f64>>>()
                            .ok()
                            .map(|rows| rows.concat())
                            .or_else(|| v.extract::<Vec<f64>>().ok())
                    })
                    .ok_or_else(|| {
                        PyTypeError::new_err(format!("{key} must be a sequence of {len} reals"))
                    })?;
                if v.len() != len {
                    return Err(ConfigError::new_err(format!(
                        "{key} must have {len} values, got {}",
                        v.len()
                    )));
                }
                Ok(Some(v))
            }
        }
    };
    let a3 = |v: Vec<f64>| -> [f64; 3] { core::array::from_fn(|i| v[i]) };
    let err = |e: Error| ConfigError::new_err(e.to_string());
    // One convention per origin: two given together (quat and rpy, a rotation
    // and rpy, xyz and pos) were read as one of them, the other ignored.
    let given: Vec<&str> = ORIGIN_KEYS
        .iter()
        .copied()
        .filter(|k| d.contains(*k).unwrap_or(false))
        .collect();
    let fits = |set: &[&str]| given.iter().all(|k| set.contains(k));
    let conventions: [&[&str]; 4] = [
        &["xyz", "rpy"],
        &["pos", "rpy"],
        &["pos", "quat"],
        &["translation", "rotation"],
    ];
    if !conventions.iter().any(|set| fits(set)) {
        return Err(ConfigError::new_err(format!(
            "an origin is given by xyz and rpy (URDF), pos and quat (MuJoCo) or translation \
             and rotation, one convention at a time; got {}",
            given.join(" and ")
        )));
    }
    if let Some(q) = get("quat", 4)? {
        let pos = get("pos", 3)?.map_or([0.0; 3], a3);
        return Transform::from_pos_quat(pos, core::array::from_fn(|i| q[i])).map_err(err);
    }
    if let Some(r) = get("rotation", 9)? {
        let t = get("translation", 3)?.map_or([0.0; 3], a3);
        return Ok(Transform {
            translation: t,
            rotation: core::array::from_fn(|i| core::array::from_fn(|j| r[3 * i + j])),
        });
    }
    let xyz = get("xyz", 3)?
        .or(get("pos", 3)?)
        .or(get("translation", 3)?)
        .map_or([0.0; 3], a3);
    let rpy = get("rpy", 3)?.map_or([0.0; 3], a3);
    Ok(Transform::from_xyz_rpy(xyz, rpy))
}

/// A joint from a dict (see `Chain`): "kind", the origin's keys, "axis",
/// "offset".
pub fn joint(d: &Bound<'_, PyDict>) -> PyResult<Joint> {
    let kind: String = match d.get_item("kind")? {
        Some(k) => k.extract()?,
        None => return Err(PyTypeError::new_err("a joint needs its kind")),
    };
    let kind = match kind.as_str() {
        "fixed" => JointKind::Fixed,
        "revolute" => JointKind::Revolute,
        "prismatic" => JointKind::Prismatic,
        other => {
            return Err(ConfigError::new_err(format!(
                "joint kind must be 'fixed', 'revolute' or 'prismatic', got {other:?}"
            )))
        }
    };
    let axis: [f64; 3] = match d.get_item("axis")? {
        Some(a) => {
            let v: Vec<f64> = a.extract()?;
            if v.len() != 3 {
                return Err(ConfigError::new_err(format!(
                    "axis must have 3 values, got {}",
                    v.len()
                )));
            }
            [v[0], v[1], v[2]]
        }
        None if kind == JointKind::Fixed => [0.0; 3],
        None => return Err(PyTypeError::new_err("a movable joint needs its axis")),
    };
    let offset: f64 = match d.get_item("offset")? {
        Some(o) => o.extract()?,
        None => 0.0,
    };
    Ok(Joint {
        kind,
        origin: transform(d)?,
        axis,
        offset,
    })
}

/// A 3 × 3 matrix from a nested or a flat sequence of 9 reals.
fn matrix3(key: &str, v: &Bound<'_, PyAny>) -> PyResult<[[f64; 3]; 3]> {
    let flat = v
        .extract::<Vec<Vec<f64>>>()
        .map(|rows| rows.concat())
        .or_else(|_| v.extract::<Vec<f64>>())
        .map_err(|_| PyTypeError::new_err(format!("{key} must be 3 × 3 reals")))?;
    if flat.len() != 9 {
        return Err(ConfigError::new_err(format!(
            "{key} must have 3 × 3 values, got {}",
            flat.len()
        )));
    }
    Ok(core::array::from_fn(|i| {
        core::array::from_fn(|j| flat[3 * i + j])
    }))
}

/// An inertial from its dict: `mass` (kg), the centre of mass as a frame's
/// `translation` (m) and `rotation`, `inertia` (kg m², 3 × 3) about it.
pub(super) fn inertial(d: &Bound<'_, PyDict>) -> PyResult<Inertial> {
    let mass: f64 = match d.get_item("mass")? {
        Some(m) => m.extract()?,
        None => return Err(PyTypeError::new_err("an inertial needs its mass (kg)")),
    };
    let inertia = match d.get_item("inertia")? {
        Some(i) => matrix3("inertia", &i)?,
        None => [[0.0; 3]; 3],
    };
    Ok(Inertial {
        mass,
        origin: transform(d)?,
        inertia,
    })
}
