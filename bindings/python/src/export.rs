//! The schema's table and a scenario's defaults, for the Python layer's docs and keyword parameters.

use super::errors::config_error;
use super::params::*;
use adaptimp::control::config::Law;
use adaptimp::schema::{Kind, Preset, Value, PARAMS};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString};

/// A schema value as Python sees it: float, int, list of floats, str, bool or None.
pub(super) fn py_value<'py>(py: Python<'py>, v: Value<'_>) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Real(x) => x.into_pyobject(py)?.into_any(),
        Value::Int(i) => i.into_pyobject(py)?.into_any(),
        Value::Vec(v) => PyList::new(py, v)?.into_any(),
        Value::Str(s) => PyString::new(py, s).into_any(),
        Value::Bool(b) => pyo3::types::PyBool::new(py, b).to_owned().into_any(),
        Value::None => py.None().into_bound(py),
    })
}

/// The parameter schema (src/schema.rs), the one source of every parameter:
/// a list of dicts with "name", "group", "kind", "unit", "doc", "condition",
/// "choices" (for a choice) and "defaults" (per scenario, as the schema
/// declares them: a number may stand for every joint).
#[pyfunction]
pub(super) fn schema_table(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for p in PARAMS {
        let d = PyDict::new(py);
        d.set_item("name", p.name)?;
        d.set_item("group", p.group.name())?;
        d.set_item("kind", p.kind.name())?;
        d.set_item("unit", p.unit)?;
        d.set_item("doc", p.doc)?;
        d.set_item("condition", p.condition)?;
        let choices: &[&str] = match p.kind {
            Kind::Choice(c) => c,
            _ => &[],
        };
        d.set_item("choices", PyList::new(py, choices)?)?;
        let defaults = PyDict::new(py);
        for preset in Preset::ALL {
            defaults.set_item(preset.name(), py_value(py, p.default_in(preset))?)?;
        }
        d.set_item("defaults", defaults)?;
        out.append(d)?;
    }
    Ok(out)
}

/// Every parameter's default in `scenario` ("paper" or "robot") for `n`
/// joints, keyed by name: per-joint values as lists of n, derived arm values
/// as None.
#[pyfunction]
#[pyo3(signature = (scenario="paper", n=2))]
pub(super) fn defaults<'py>(
    py: Python<'py>,
    scenario: &str,
    n: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let preset = preset_of(scenario)?;
    let d = PyDict::new(py);
    let mut err = Ok(());
    adaptimp::dynamic::Scenario::new(check_n(n)?, preset, Law::StateFeedback)
        .map_err(|e| config_error(e.into()))?
        .visit(|name, v| {
            if err.is_ok() {
                err = py_value(py, v).and_then(|v| d.set_item(name, v));
            }
        });
    err?;
    Ok(d)
}
