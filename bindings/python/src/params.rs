//! Parameters by name: the schema (src/schema.rs) is the one source; a Python dict of parameters to the core's items.

use super::dynamic::{Owned, MAX_JOINTS};
use super::errors::*;
use adaptimp::control::config::Law;
use adaptimp::schema::Preset;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};

pub(super) fn law_of(case: &str) -> PyResult<Law> {
    match case {
        "pd" => Ok(Law::Pd),
        "sf" => Ok(Law::StateFeedback),
        "of" => Ok(Law::OutputFeedback),
        other => Err(PyValueError::new_err(format!(
            "case must be 'pd', 'sf' or 'of', got {other:?}"
        ))),
    }
}

pub(super) fn case_of(law: Law) -> &'static str {
    match law {
        Law::Pd => "pd",
        Law::StateFeedback => "sf",
        Law::OutputFeedback => "of",
    }
}

pub(super) fn preset_of(scenario: &str) -> PyResult<Preset> {
    Preset::from_name(scenario).ok_or_else(|| {
        PyValueError::new_err(format!(
            "scenario must be one of 'paper', 'robot', got {scenario:?}"
        ))
    })
}

pub(super) fn check_n(n: usize) -> PyResult<usize> {
    if (1..=MAX_JOINTS).contains(&n) {
        Ok(n)
    } else {
        Err(ConfigError::new_err(format!(
            "n must be between 1 and {MAX_JOINTS} joints, got {n}"
        )))
    }
}

/// A Python value in the schema's terms.
pub(super) fn owned(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Owned> {
    if obj.is_none() {
        return Ok(Owned::None);
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Owned::Str(obj.extract()?));
    }
    if obj.is_instance_of::<pyo3::types::PyBool>() {
        // A flag's value; the schema refuses it for any other kind.
        return Ok(Owned::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<pyo3::types::PyInt>() {
        return match obj.extract::<i64>() {
            Ok(i) => Ok(Owned::Int(i)),
            Err(_) => Err(ConfigError::new_err(format!(
                "{name} is out of range: {}",
                obj.str().map(|s| s.to_string()).unwrap_or_default()
            ))),
        };
    }
    if let Ok(x) = obj.extract::<f64>() {
        return Ok(Owned::Real(x));
    }
    match obj.extract::<Vec<f64>>() {
        Ok(v) => Ok(Owned::Vec(v)),
        Err(_) => Err(PyTypeError::new_err(format!(
            "{name} must be a number, a sequence of numbers, a string or None"
        ))),
    }
}

pub(super) fn items(params: &Bound<'_, PyDict>) -> PyResult<Vec<(String, Owned)>> {
    params
        .iter()
        .map(|(k, v)| {
            let name: String = k.extract()?;
            let o = owned(&name, &v)?;
            Ok((name, o))
        })
        .collect()
}
