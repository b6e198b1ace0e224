//! A controller's state, owned by the caller (pinocchio's Data, idsp's
//! state): the clock, the compliant reference, ζ, the observer, the basis
//! values, the weights and their norms, and the last command.
//!
//! One `Controller` (the validated description) drives
//! any number of states. The large part, the basis and the `(2N² + N) L`
//! weights, lives in one flat `f64` buffer `S`: a `Vec<f64>` on the heap
//! (feature `alloc`, `Controller::new_state`),
//! or any buffer of the caller's, e.g. a `static mut` array in firmware
//! (`Controller::state_in`). Either way it is
//! zeroed in place: no large value is ever built on the stack.

use crate::control::impedance::Reference;
use crate::control::io::Command;
use crate::control::observer::ObserverState;
use crate::control::safety::Fault;
use crate::error::Error;
use crate::networks::network::{Layout, Weights, WeightsMut};
use crate::types::Vector;

/// The state of one controller run. See the [module docs](self).
#[derive(Clone, Debug)]
pub struct State<const N: usize, S> {
    /// Steps taken since the start (k of t_k = k·Ts for the next step).
    pub(crate) k: u64,
    pub(crate) reference: Reference<N>,
    pub(crate) zeta: Vector<N>,
    pub(crate) observer: ObserverState<N>,
    /// ‖Ŵ‖_F of the current weights (kept up to date by every update).
    pub(crate) norms: [f64; 3],
    pub(crate) last: Command<N>,
    /// The last measured position (for the jump limit).
    pub(crate) q_prev: Vector<N>,
    /// The last failed step's error, until cleared.
    pub(crate) fault: Option<Fault>,
    layout: Layout,
    buf: S,
}

/// First two values of a snapshot: a marker and the format's version.
const SNAPSHOT_HEADER: [f64; 2] = [4_151_076.0, 2.0];
/// Values of a snapshot before its per-joint part: header, N, L, k.
const SNAPSHOT_PREFIX: usize = 5;

/// A state whose buffer is on the heap.
#[cfg(feature = "alloc")]
pub type HeapState<const N: usize> = State<N, alloc::vec::Vec<f64>>;

impl<const N: usize, S: AsRef<[f64]> + AsMut<[f64]>> State<N, S> {
    /// A state at t = 0 (weights zero) for a basis of `nodes` nodes in `buf`,
    /// which must hold at least [`Layout::buffer_len`]`(N, nodes)` reals; it is
    /// zeroed. Errors if it is too short.
    pub fn new_in(nodes: usize, mut buf: S) -> Result<Self, Error> {
        if N == 0 || nodes == 0 {
            return Err(Error::Invalid {
                what: "state",
                reason: "needs at least one joint and one node",
            });
        }
        let slice = buf.as_mut();
        let layout =
            Layout::new(N, nodes, slice.as_ptr() as usize, slice.len()).ok_or(Error::Invalid {
                what: "state buffer",
                reason: "too short for the basis and weights: see Controller::buffer_len",
            })?;
        slice.fill(0.0);
        Ok(Self {
            k: 0,
            reference: Reference::zeros(),
            zeta: Vector::zeros(),
            observer: ObserverState::zeros(),
            norms: [0.0; 3],
            last: Command::zeros(),
            q_prev: Vector::zeros(),
            fault: None,
            layout,
            buf,
        })
    }

    /// Back to t = 0: weights, ζ, observer and reference as at creation.
    pub fn reset(&mut self) {
        self.k = 0;
        self.reference = Reference::zeros();
        self.zeta = Vector::zeros();
        self.observer = ObserverState::zeros();
        self.norms = [0.0; 3];
        self.last = Command::zeros();
        self.q_prev = Vector::zeros();
        self.fault = None;
        self.buf.as_mut().fill(0.0);
    }

    /// Number of steps taken since creation or reset.
    pub fn steps(&self) -> u64 {
        self.k
    }
    /// Auxiliary state ζ (N m), (11), for the next step.
    pub fn zeta(&self) -> &Vector<N> {
        &self.zeta
    }
    /// The compliant reference (xd, ẋd) for the next step (it starts at the
    /// first step's setpoint, SPEC §4).
    pub fn reference(&self) -> &Reference<N> {
        &self.reference
    }
    /// Observer state π (output feedback only; zeros otherwise).
    pub fn observer(&self) -> &ObserverState<N> {
        &self.observer
    }
    /// The last step's command (all zeros before the first step).
    pub fn last(&self) -> &Command<N> {
        &self.last
    }
    /// The fault recorded by the last failed step (its error and step), if
    /// not cleared. With the "latch" fault policy, steps are refused while
    /// it is set.
    pub fn fault(&self) -> Option<Fault> {
        self.fault
    }
    /// Clear the recorded fault (the documented recovery after a latched
    /// fault): the next step runs from the state as it was before the fault.
    pub fn clear_fault(&mut self) {
        self.fault = None;
    }
    /// The number of basis nodes L this state was made for.
    pub fn nodes(&self) -> usize {
        self.layout.nodes()
    }
    /// The basis S(Z) of the last step (zeros before the first, and for PD).
    pub fn basis(&self) -> &[f64] {
        self.layout.split(self.buf.as_ref()).0
    }
    /// The network weights (after the last step's update).
    pub fn weights(&self) -> Weights<'_, N> {
        let (_, rows) = self.layout.split(self.buf.as_ref());
        Weights::new(rows, self.layout.nodes(), rows.len() / Layout::rows(N))
    }
    /// Frobenius norms ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ of the current weights, as the
    /// controller tracks them step by step (see
    /// [`WeightsMut::fused_step`]); [`Weights::norms`] recomputes them.
    pub fn weight_norms(&self) -> [f64; 3] {
        self.norms
    }

    /// Replace the weights (e.g. to warm-start from a previous run, or from a
    /// file through [`Weights::from_rows`]). They must have this state's
    /// number of nodes and be finite; on an error nothing changes.
    pub fn load_weights(&mut self, w: &Weights<'_, N>) -> Result<(), Error> {
        if w.nodes() != self.nodes() {
            return Err(Error::Invalid {
                what: "weights",
                reason: "their number of nodes differs from the state's",
            });
        }
        w.check_finite()?;
        let mut dst = self.parts().1;
        dst.copy_from(w);
        self.norms = dst.as_ref().norms();
        Ok(())
    }

    /// The number of reals [`save`](Self::save) writes:
    /// `11 + 16 N + L (2N² + N + 1)`.
    pub fn snapshot_len(&self) -> usize {
        SNAPSHOT_PREFIX + 16 * N + 6 + self.nodes() * (Layout::rows(N) + 1)
    }

    /// Write everything this state holds into `out` (at least
    /// [`snapshot_len`](Self::snapshot_len) reals) as a flat array of reals:
    /// a header, N, L, the step count, the reference, ζ, the observer, the
    /// last position, the norms, the last command, the basis and the weights.
    /// Returns the number written. [`load`](Self::load) restores it exactly,
    /// so a run continues bit-identically (a recorded fault is not part of a
    /// snapshot, and loading clears it). No allocation.
    pub fn save(&self, out: &mut [f64]) -> Result<usize, Error> {
        let len = self.snapshot_len();
        let out = out.get_mut(..len).ok_or(Error::Invalid {
            what: "snapshot buffer",
            reason: "too short: see State::snapshot_len",
        })?;
        let mut w = Writer { out, at: 0 };
        w.put(&SNAPSHOT_HEADER);
        w.put(&[N as f64, self.nodes() as f64, self.k as f64]);
        let c = &self.last;
        for v in [
            &self.reference.xd,
            &self.reference.dxd,
            &self.zeta,
            &self.observer.pi1,
            &self.observer.pi2,
            &self.observer.y_prev,
            &self.q_prev,
            &c.tau_sat,
            &c.tau,
            &c.dtau,
            &c.z1,
            &c.z2,
            &c.xc,
            &c.xd,
            &c.v,
            &c.zeta,
        ] {
            w.put(v.as_slice());
        }
        w.put(&self.norms);
        w.put(&c.w_norms);
        w.put(self.basis());
        let weights = self.weights();
        for net in [
            crate::networks::network::D,
            crate::networks::network::C,
            crate::networks::network::G,
        ] {
            for row in weights.network(net) {
                w.put(row);
            }
        }
        Ok(w.at)
    }

    /// Restore a snapshot written by [`save`](Self::save) for the same N and L.
    /// Every value is checked (header, sizes, a whole step count, finite
    /// numbers) before anything changes: on an error the state is as before.
    pub fn load(&mut self, data: &[f64]) -> Result<(), Error> {
        let bad = |reason| Error::Invalid {
            what: "snapshot",
            reason,
        };
        if data.len() != self.snapshot_len() {
            return Err(bad("its length is not State::snapshot_len() of this state"));
        }
        if data[..2] != SNAPSHOT_HEADER {
            return Err(bad("not a snapshot of this version (header)"));
        }
        if data[2] != N as f64 || data[3] != self.nodes() as f64 {
            return Err(bad("made for another number of joints or nodes"));
        }
        let k = data[4];
        if !(0.0..=9.007_199_254_740_992e15).contains(&k) || (k as u64) as f64 != k {
            return Err(bad("the step count is not a whole number in [0, 2^53]"));
        }
        crate::error::check::finite_slice("snapshot", data)?;
        let mut r = Reader {
            data,
            at: SNAPSHOT_PREFIX,
        };
        self.k = k as u64;
        self.reference.xd = r.vector();
        self.reference.dxd = r.vector();
        self.zeta = r.vector();
        self.observer.pi1 = r.vector();
        self.observer.pi2 = r.vector();
        self.observer.y_prev = r.vector();
        self.q_prev = r.vector();
        self.fault = None;
        let c = &mut self.last;
        for v in [
            &mut c.tau_sat,
            &mut c.tau,
            &mut c.dtau,
            &mut c.z1,
            &mut c.z2,
            &mut c.xc,
            &mut c.xd,
            &mut c.v,
            &mut c.zeta,
        ] {
            *v = r.vector();
        }
        self.norms = r.array();
        c.w_norms = r.array();
        let (basis, mut weights) = self.parts();
        basis.copy_from_slice(r.take(basis.len()));
        let nodes = basis.len();
        for i in 0..Layout::rows(N) {
            weights.row_mut(i).copy_from_slice(r.take(nodes));
        }
        Ok(())
    }

    /// The basis buffer and the weights, writable: for benchmarks and for
    /// learning laws of your own. The tracked norms
    /// ([`weight_norms`](Self::weight_norms)) are not updated by edits made
    /// here: call [`refresh_norms`](Self::refresh_norms) after them.
    pub fn networks_mut(&mut self) -> (&mut [f64], WeightsMut<'_, N>) {
        self.parts()
    }

    /// Recompute the tracked norms from the weights.
    pub fn refresh_norms(&mut self) {
        self.norms = self.weights().norms();
    }

    /// The basis buffer and the weights, writable.
    pub(crate) fn parts(&mut self) -> (&mut [f64], WeightsMut<'_, N>) {
        let nodes = self.layout.nodes();
        let (basis, rows) = self.layout.split_mut(self.buf.as_mut());
        let stride = rows.len() / Layout::rows(N);
        (basis, WeightsMut::new(rows, nodes, stride))
    }
}

/// Sequential writes into a snapshot.
struct Writer<'a> {
    out: &'a mut [f64],
    at: usize,
}

impl Writer<'_> {
    fn put(&mut self, v: &[f64]) {
        self.out[self.at..self.at + v.len()].copy_from_slice(v);
        self.at += v.len();
    }
}

/// Sequential reads from a snapshot whose length was checked.
struct Reader<'a> {
    data: &'a [f64],
    at: usize,
}

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> &'a [f64] {
        let v = &self.data[self.at..self.at + n];
        self.at += n;
        v
    }
    fn vector<const N: usize>(&mut self) -> Vector<N> {
        Vector::from_column_slice(self.take(N))
    }
    fn array(&mut self) -> [f64; 3] {
        let mut a = [0.0; 3];
        a.copy_from_slice(self.take(3));
        a
    }
}
