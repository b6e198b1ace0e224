//! Errors: the one place each where core errors become exceptions (`adaptimp._errors`): construction, a step, a state, a run.

use super::dynamic::{ParamError, RunError};
use super::hooks::*;
use adaptimp::error::Error;
use pyo3::exceptions::{PyMemoryError, PyRuntimeError};
use pyo3::prelude::*;

pyo3::import_exception!(adaptimp._errors, ConfigError);
pyo3::import_exception!(adaptimp._errors, MeasurementError);
pyo3::import_exception!(adaptimp._errors, DivergedError);
pyo3::import_exception!(adaptimp._errors, FaultError);

/// A construction error: `ConfigError` (a `ValueError`) naming the parameter.
pub(super) fn config_error(e: ParamError) -> PyErr {
    match e.name {
        Some(name) => ConfigError::new_err(format!("{name}: {}", e.error)),
        None => ConfigError::new_err(e.error.to_string()),
    }
}

/// A step's error: `DivergedError` for a diverged state, `FaultError` for a
/// latched fault, `MeasurementError` for an input (named as in Python).
pub(super) fn step_error(e: Error) -> PyErr {
    let e = python_names(e);
    // The inputs, and what the inputs would drive beyond a limit (the jump,
    // the reference a step would commit): the state is sound, the input is not.
    const INPUTS: [&str; 9] = [
        "q", "dq", "tau_e", "xc", "dxc", "ddxc", "q jump", "xd", "dxd",
    ];
    match e {
        Error::Diverged { .. } => DivergedError::new_err(e.to_string()),
        // An internal signal (ζ, z1, α1, the weights, …) beyond the finite range.
        Error::OutOfRange { what, .. } if !INPUTS.contains(&what) => {
            DivergedError::new_err(e.to_string())
        }
        Error::Faulted { .. } => FaultError::new_err(e.to_string()),
        Error::Condition { .. } | Error::Invalid { .. } => ConfigError::new_err(e.to_string()),
        _ => MeasurementError::new_err(e.to_string()),
    }
}

/// A state that cannot be restored or loaded: `ConfigError` with the core's
/// message (it names the value and the limit).
pub(super) fn state_error(e: Error) -> PyErr {
    ConfigError::new_err(python_names(e).to_string())
}

/// The fault a step call refused by its arguments' shapes or types records.
pub(super) const BAD_ARGUMENTS: Error = Error::Invalid {
    what: "step",
    reason: "an argument had the wrong shape or type (the exception raised said which)",
};

/// A run's error: as [`step_error`] with the row, or the hook's exception.
pub(super) fn run_error(e: RunError, hooks: &mut PyHooks) -> PyErr {
    match e {
        RunError::Stopped => hooks
            .error
            .take()
            .unwrap_or_else(|| PyRuntimeError::new_err("the run was stopped")),
        RunError::Plant(f) if f.fatal => PyRuntimeError::new_err(f.message),
        RunError::Plant(f) => DivergedError::new_err(f.message),
        RunError::Memory(rows) => {
            PyMemoryError::new_err(format!("cannot allocate the records of {rows} rows"))
        }
        RunError::Core(e, None) => step_error(e),
        RunError::Core(e, Some(k)) => {
            let err = step_error(e);
            Python::attach(|py| {
                let msg = format!("row {k}: {}", err.value(py));
                let ty = err.get_type(py);
                PyErr::from_type(ty, msg)
            })
        }
    }
}

/// The core's names of the measurement as Python names them.
pub(super) fn python_names(e: Error) -> Error {
    let rename = |what: &'static str| match what {
        "x" => "q",
        "dx" => "dq",
        other => other,
    };
    match e {
        Error::NonFinite { what, index } => Error::NonFinite {
            what: rename(what),
            index,
        },
        Error::OutOfRange {
            what,
            index,
            value,
            limit,
        } => Error::OutOfRange {
            what: rename(what),
            index,
            value,
            limit,
        },
        other => other,
    }
}
