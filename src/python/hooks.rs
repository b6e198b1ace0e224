//! Long calls: Ctrl-C and progress, checked every 50 ms of work with the GIL taken only then.

use super::dynamic::Hooks;
use pyo3::prelude::*;
use std::time::{Duration, Instant};

/// Checks for signals (and reports progress) at most every [`CHECK_EVERY`]
/// of work, taking the GIL only then.
pub(super) struct PyHooks {
    pub(super) last: Instant,
    pub(super) progress: Option<Py<PyAny>>,
    pub(super) error: Option<PyErr>,
}

/// Time between two checks for signals.
pub(super) const CHECK_EVERY: Duration = Duration::from_millis(50);

impl PyHooks {
    pub(super) fn new(progress: Option<Py<PyAny>>) -> Self {
        Self {
            last: Instant::now(),
            progress,
            error: None,
        }
    }
}

impl Hooks for PyHooks {
    fn tick(&mut self, done: u64, total: u64) -> bool {
        // The last step is always reported (a progress bar ends at 100 %,
        // however fast the run); the others at most every CHECK_EVERY.
        if done < total && self.last.elapsed() < CHECK_EVERY {
            return true;
        }
        self.last = Instant::now();
        Python::attach(|py| {
            let result = py.check_signals().and_then(|()| match &self.progress {
                Some(cb) => cb.call1(py, (done, total)).map(|_| ()),
                None => Ok(()),
            });
            match result {
                Ok(()) => true,
                Err(e) => {
                    self.error = Some(e);
                    false
                }
            }
        })
    }
}
