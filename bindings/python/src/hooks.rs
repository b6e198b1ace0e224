//! Long calls: Ctrl-C and progress, checked every 50 ms of work with the GIL
//! taken only then; the progress callback called with the run's controllers
//! readable ([`super::shared`]).

use super::dynamic::{Hooks, View};
use super::shared::{published, Slot};
use pyo3::prelude::*;
use std::time::{Duration, Instant};

/// Checks for signals (and reports progress) at most every [`CHECK_EVERY`]
/// of work, taking the GIL only then.
pub(super) struct PyHooks<'a> {
    /// The last check for signals.
    pub(super) last: Instant,
    /// The last call of `progress`.
    reported: Instant,
    pub(super) progress: Option<Py<PyAny>>,
    pub(super) error: Option<PyErr>,
    /// The Python objects whose state the run holds: their copies are
    /// published while `progress` runs.
    slots: Vec<&'a dyn Slot>,
}

/// Time between two checks for signals.
pub(super) const CHECK_EVERY: Duration = Duration::from_millis(50);

impl<'a> PyHooks<'a> {
    pub(super) fn new(progress: Option<Py<PyAny>>) -> Self {
        let now = Instant::now();
        Self {
            last: now,
            reported: now,
            progress,
            error: None,
            slots: Vec::new(),
        }
    }

    /// The same, the run holding the state of `slots` (a controller, a
    /// Cartesian controller and its joint controller): the progress
    /// callback reads their copies.
    pub(super) fn holding(progress: Option<Py<PyAny>>, slots: Vec<&'a dyn Slot>) -> Self {
        Self {
            slots,
            ..Self::new(progress)
        }
    }

    /// Run `f` with the GIL; an error it returns stops the run.
    fn attach(&mut self, f: impl FnOnce(Python<'_>) -> PyResult<()>) -> bool {
        match Python::attach(f) {
            Ok(()) => true,
            Err(e) => {
                self.error = Some(e);
                false
            }
        }
    }
}

impl Hooks for PyHooks<'_> {
    fn tick(&mut self, done: u64, total: u64) -> bool {
        if done < total && self.last.elapsed() < CHECK_EVERY {
            return true;
        }
        self.last = Instant::now();
        self.attach(|py| py.check_signals())
    }

    fn report(&mut self, done: u64, total: u64, view: &dyn View) -> bool {
        // The last step is always reported (a progress bar ends at 100 %,
        // however fast the run); the others at most every CHECK_EVERY.
        if done < total && self.reported.elapsed() < CHECK_EVERY {
            return true;
        }
        let now = Instant::now();
        (self.reported, self.last) = (now, now);
        let progress = self.progress.take();
        let slots = core::mem::take(&mut self.slots);
        let go_on = published(&slots, view, || {
            self.attach(|py| {
                py.check_signals()?;
                match &progress {
                    Some(cb) => cb.call1(py, (done, total)).map(|_| ()),
                    None => Ok(()),
                }
            })
        });
        (self.progress, self.slots) = (progress, slots);
        go_on
    }
}
