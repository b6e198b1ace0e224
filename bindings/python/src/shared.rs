//! A binding's state behind a mutex that Python code called by its own run
//! can read: a progress callback, a joint controller written in Python, a
//! path. No call deadlocks on the thread that holds the state.
//!
//! Each call takes the state whole ([`Shared::write`]: steps, runs, resets),
//! or reads it ([`Shared::read`]). A run that calls Python code while it
//! holds the state first publishes a copy of it ([`Slot::publish`], the
//! state as it is at that call) and withdraws it when the code returns
//! ([`Slot::retract`]); meanwhile reads get the copy, on any thread. A call
//! that would change the state from the thread that holds it (a callback
//! that steps or resets its own controller) is refused with a
//! `RuntimeError` naming the object; a read there without a published copy
//! (a signal handler run inside a period) likewise. Another thread waits,
//! with the GIL released, until the state is free.

use super::dynamic::View;
use core::any::TypeId;
use core::ops::{Deref, DerefMut};
use core::sync::atomic::{AtomicU64, Ordering};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use std::sync::{Mutex, MutexGuard, TryLockError};

/// A number for the calling thread, never 0 and never given to another.
fn thread_token() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    std::thread_local! {
        static TOKEN: u64 = NEXT.fetch_add(1, Ordering::Relaxed);
    }
    TOKEN.with(|t| *t)
}

fn unpoisoned<G>(r: Result<G, std::sync::PoisonError<G>>) -> G {
    r.unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// The state of a Python object (`what`: its class name, for messages).
pub(super) struct Shared<T: ?Sized> {
    live: Mutex<Box<T>>,
    /// The thread that holds `live` for a [`Write`] (0: none).
    holder: AtomicU64,
    /// A copy of the state while its holder runs Python code.
    view: Mutex<Option<Box<T>>>,
    what: &'static str,
}

/// A read of the state: the state itself, or the copy its run published.
pub(super) enum Read<'a, T: ?Sized> {
    Live(MutexGuard<'a, Box<T>>),
    View(MutexGuard<'a, Option<Box<T>>>),
}

impl<T: ?Sized> Deref for Read<'_, T> {
    type Target = T;
    fn deref(&self) -> &T {
        match self {
            Read::Live(g) => g,
            // A `View` guard is made only over a published copy.
            Read::View(g) => g.as_deref().unwrap_or_else(|| unreachable!()),
        }
    }
}

/// The state, held by this thread for a call that may change it.
pub(super) struct Write<'a, T: ?Sized> {
    guard: MutexGuard<'a, Box<T>>,
    holder: &'a AtomicU64,
}

impl<T: ?Sized> Deref for Write<'_, T> {
    type Target = Box<T>;
    fn deref(&self) -> &Box<T> {
        &self.guard
    }
}

impl<T: ?Sized> DerefMut for Write<'_, T> {
    fn deref_mut(&mut self) -> &mut Box<T> {
        &mut self.guard
    }
}

impl<T: ?Sized> Drop for Write<'_, T> {
    fn drop(&mut self) {
        // Before the guard is released (the fields drop after this).
        self.holder.store(0, Ordering::Release);
    }
}

impl<T: ?Sized + Send> Shared<T> {
    pub(super) fn new(state: Box<T>, what: &'static str) -> Self {
        Self {
            live: Mutex::new(state),
            holder: AtomicU64::new(0),
            view: Mutex::new(None),
            what,
        }
    }

    /// Whether this thread holds the state (a call up the stack does).
    fn held_here(&self) -> bool {
        self.holder.load(Ordering::Acquire) == thread_token()
    }

    fn busy(&self, change: bool) -> PyErr {
        let what = self.what;
        PyRuntimeError::new_err(if change {
            format!(
                "this {what} is in a call (a run or a step) that called the code now \
                 running: that code can read the {what}, not change it"
            )
        } else {
            format!(
                "this {what} is in a call (a run or a step) on this thread that publishes \
                 no copy of it here: read it from the run's progress callback, the joint \
                 controller's step or the path, or after the call"
            )
        })
    }

    /// The state for a call that may change it; while another thread's call
    /// holds it, wait with the GIL released (that call may need the GIL to
    /// finish). `RuntimeError` if a call up this thread's stack holds it.
    pub(super) fn write(&self, py: Python<'_>) -> PyResult<Write<'_, T>> {
        loop {
            let guard = match self.live.try_lock() {
                Ok(g) => g,
                Err(TryLockError::Poisoned(p)) => p.into_inner(),
                Err(TryLockError::WouldBlock) => {
                    if self.held_here() {
                        return Err(self.busy(true));
                    }
                    py.detach(|| drop(self.live.lock()));
                    continue;
                }
            };
            self.holder.store(thread_token(), Ordering::Release);
            return Ok(Write {
                guard,
                holder: &self.holder,
            });
        }
    }

    /// The state for a call that may change it, on a thread without the GIL
    /// (a sweep's worker): waits until it is free.
    pub(super) fn write_blocking(&self) -> Write<'_, T> {
        let guard = unpoisoned(self.live.lock());
        self.holder.store(thread_token(), Ordering::Release);
        Write {
            guard,
            holder: &self.holder,
        }
    }

    /// The state for a call that may change it, or None where a call up this
    /// thread's stack holds it and publishes a copy (a run's callback: the
    /// caller reads the copy instead, [`Self::read`]).
    pub(super) fn write_or_copy(&self, py: Python<'_>) -> PyResult<Option<Write<'_, T>>> {
        match self.write(py) {
            Ok(w) => Ok(Some(w)),
            Err(e) if unpoisoned(self.view.lock()).is_some() => {
                drop(e);
                Ok(None)
            }
            Err(e) => Err(e),
        }
    }

    /// `copy` published, as the state, until the guard drops: for Python
    /// code a call that holds the state calls in the middle of a step.
    pub(super) fn showing(&self, copy: Box<T>) -> Showing<'_, T> {
        *unpoisoned(self.view.lock()) = Some(copy);
        Showing(self)
    }

    /// The state to read: itself, or while a run that holds it runs Python
    /// code, the copy it published (the state at that call).
    pub(super) fn read(&self, py: Python<'_>) -> PyResult<Read<'_, T>> {
        loop {
            match self.live.try_lock() {
                Ok(g) => return Ok(Read::Live(g)),
                Err(TryLockError::Poisoned(p)) => return Ok(Read::Live(p.into_inner())),
                Err(TryLockError::WouldBlock) => {}
            }
            let view = unpoisoned(self.view.lock());
            if view.is_some() {
                return Ok(Read::View(view));
            }
            drop(view);
            if self.held_here() {
                return Err(self.busy(false));
            }
            py.detach(|| drop(self.live.lock()));
        }
    }
}

/// A copy published by [`Shared::showing`], withdrawn when this drops.
pub(super) struct Showing<'a, T: ?Sized>(&'a Shared<T>);

impl<T: ?Sized> Drop for Showing<'_, T> {
    fn drop(&mut self) {
        *unpoisoned(self.0.view.lock()) = None;
    }
}

/// Where a run publishes the part of its state one Python object holds.
pub(super) trait Slot: Sync {
    /// Publish `view`'s copy of this object's state (if the run has one).
    fn publish(&self, view: &dyn View);
    /// Withdraw it: the run goes on.
    fn retract(&self);
}

impl<T: ?Sized + Send + 'static> Slot for Shared<T> {
    fn publish(&self, view: &dyn View) {
        let copy = view
            .copy(TypeId::of::<Box<T>>())
            .and_then(|b| b.downcast::<Box<T>>().ok());
        if let Some(copy) = copy {
            *unpoisoned(self.view.lock()) = Some(*copy);
        }
    }
    fn retract(&self) {
        *unpoisoned(self.view.lock()) = None;
    }
}

/// The copies of `slots` published while `f` runs (Python code of the run
/// that holds them), withdrawn after, whatever `f` does.
pub(super) fn published<R>(slots: &[&dyn Slot], view: &dyn View, f: impl FnOnce() -> R) -> R {
    struct Retract<'a, 'b>(&'a [&'b dyn Slot]);
    impl Drop for Retract<'_, '_> {
        fn drop(&mut self) {
            for s in self.0 {
                s.retract();
            }
        }
    }
    for s in slots {
        s.publish(view);
    }
    let _retract = Retract(slots);
    f()
}
