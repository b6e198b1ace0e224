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
use crate::error::{check, Error, BOUND};
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
    /// The last accepted position (a jump anchor).
    pub(crate) q_prev: Vector<N>,
    /// The last measured plausible position, whatever became of its step
    /// (the other jump anchor).
    pub(crate) q_seen: Vector<N>,
    /// The torque last given to apply: the last step's sat(τ), or the
    /// fallback of a refused step after it (the rate limit's origin).
    pub(crate) applied: Vector<N>,
    /// The last failed step's error, until cleared.
    pub(crate) fault: Option<Fault>,
    layout: Layout,
    buf: S,
}

/// First two values of a snapshot: a marker and the format's version.
const SNAPSHOT_HEADER: [f64; 2] = [4_151_076.0, 3.0];
/// Values of a snapshot before its per-joint part: header, N, L, k.
const SNAPSHOT_PREFIX: usize = 5;
/// How far a stored weight norm may be from the one recomputed from the
/// stored weights (relative): the step tracks the norms by a recurrence whose
/// rounding was measured at 6.8e-14 after 400 000 steps (the paper's state
/// feedback) and 0 after 2 M (the robot scenario; `tests/fault_semantics.rs`);
/// a larger gap is a corrupt or edited snapshot.
const NORM_TOLERANCE: f64 = 1e-6;

/// A 53-bit FNV-1a hash of the bit patterns of `data`, exact as an f64: the
/// last value of a snapshot, so a corrupted one is refused.
fn checksum(data: &[f64]) -> f64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for x in data {
        for b in x.to_bits().to_le_bytes() {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    (h >> 11) as f64
}

/// A snapshot's values, checked and read, before they go into a state.
pub(crate) struct Snapshot<'a, const N: usize> {
    pub(crate) k: u64,
    pub(crate) reference: Reference<N>,
    pub(crate) zeta: Vector<N>,
    pub(crate) observer: ObserverState<N>,
    pub(crate) q_prev: Vector<N>,
    pub(crate) q_seen: Vector<N>,
    pub(crate) applied: Vector<N>,
    pub(crate) last: Command<N>,
    pub(crate) norms: [f64; 3],
    /// The norms recomputed from the weights.
    pub(crate) exact: [f64; 3],
    basis: &'a [f64],
    rows: &'a [f64],
}

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
            q_seen: Vector::zeros(),
            applied: Vector::zeros(),
            fault: None,
            layout,
            buf,
        })
    }

    /// Back to t = 0, everything as at creation: weights, ζ, observer,
    /// reference, the last command, the applied torque (zero: the next step's
    /// rate limit starts from it), the jump anchors (none: the next step has
    /// no jump check) and the fault (cleared).
    pub fn reset(&mut self) {
        self.k = 0;
        self.reference = Reference::zeros();
        self.zeta = Vector::zeros();
        self.observer = ObserverState::zeros();
        self.norms = [0.0; 3];
        self.last = Command::zeros();
        self.q_prev = Vector::zeros();
        self.q_seen = Vector::zeros();
        self.applied = Vector::zeros();
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
    /// The last accepted step's command (all zeros before the first step).
    pub fn last(&self) -> &Command<N> {
        &self.last
    }
    /// The torque last given to apply (N m): the last accepted step's
    /// sat(τ), or, after a refused step, its fallback. The torque rate limit
    /// is measured from it. Zero before the first step.
    pub fn applied(&self) -> &Vector<N> {
        &self.applied
    }
    /// The jump limit's anchors: the last accepted position and the last
    /// measured plausible position (rad), see [`Limits`](crate::Limits).
    pub fn anchors(&self) -> [&Vector<N>; 2] {
        [&self.q_prev, &self.q_seen]
    }
    /// The fault recorded by the last failed step (its error and step), if
    /// not cleared. With the "latch" fault policy, steps are refused while
    /// it is set (and it keeps the error that latched it).
    pub fn fault(&self) -> Option<Fault> {
        self.fault
    }
    /// Clear the recorded fault (the documented recovery after a latched
    /// fault): the next step runs from the state as it was before the fault,
    /// its torque rate-limited from the fallback last applied and its jump
    /// measured from the anchors (which followed the measurements during the
    /// fault). Nothing else changes.
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
    /// number of nodes, be finite and have norms within [`BOUND`] (a step
    /// refuses weights beyond it); on an error nothing changes.
    /// `Controller::load_weights` also checks the controller's projection
    /// bounds: use it when you have the controller.
    pub fn load_weights(&mut self, w: &Weights<'_, N>) -> Result<(), Error> {
        if w.nodes() != self.nodes() {
            return Err(Error::Invalid {
                what: "weights",
                reason: "their number of nodes differs from the state's",
            });
        }
        w.check_finite()?;
        let norms = w.norms();
        check_norms(&norms)?;
        let mut dst = self.parts().1;
        dst.copy_from(w);
        self.norms = norms;
        Ok(())
    }

    /// The number of reals [`save`](Self::save) writes:
    /// `12 + 18 N + L (2N² + N + 1)`.
    pub fn snapshot_len(&self) -> usize {
        SNAPSHOT_PREFIX + 18 * N + 7 + self.nodes() * (Layout::rows(N) + 1)
    }

    /// Write everything this state holds into `out` (at least
    /// [`snapshot_len`](Self::snapshot_len) reals) as a flat array of reals:
    /// a header, N, L, the step count, the reference, ζ, the observer, the
    /// last accepted position, the last command, the norms, the basis, the
    /// weights, the applied torque, the last measured position and a
    /// checksum. Returns the number written. [`load`](Self::load) restores
    /// it exactly, so a run continues bit-identically (a recorded fault is not
    /// part of a snapshot, and loading clears it). No allocation.
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
        w.put(self.applied.as_slice());
        w.put(self.q_seen.as_slice());
        let sum = checksum(&w.out[..w.at]);
        w.put(&[sum]);
        Ok(w.at)
    }

    /// Restore a snapshot written by [`save`](Self::save) for the same N and L.
    /// Every value is checked before anything changes (on an error the state
    /// is as before): the header, the sizes, a whole step count, finite
    /// numbers, the checksum, and what a step could have left: the reference
    /// and the jump anchors within the ceilings
    /// ([`CEILING_POSITION`](crate::control::safety::CEILING_POSITION)), ζ and
    /// the observer within [`BOUND`], the stored weight norms equal to the
    /// ones recomputed from the weights (to 1e-6) and within [`BOUND`].
    /// `Controller::restore` also checks the state against the controller
    /// (its torque limits, its projection bounds): use it when you have the
    /// controller.
    pub fn load(&mut self, data: &[f64]) -> Result<(), Error> {
        let snap = self.check_snapshot(data)?;
        self.commit(&snap);
        Ok(())
    }

    /// The checks of [`load`](Self::load), without a change: the envelope
    /// of the data, then the state it holds.
    pub(crate) fn check_snapshot<'a>(&self, data: &'a [f64]) -> Result<Snapshot<'a, N>, Error> {
        let k = self.check_envelope(data)?;
        let snap = self.read_snapshot(data, k);
        snap.check()?;
        Ok(snap)
    }

    /// The envelope of a snapshot, before any value is read: the header
    /// (an earlier format named), the sizes, a whole step count (returned),
    /// finite numbers, the checksum.
    fn check_envelope(&self, data: &[f64]) -> Result<u64, Error> {
        let bad = |reason| Error::Invalid {
            what: "snapshot",
            reason,
        };
        if data.len() < SNAPSHOT_PREFIX || data[0] != SNAPSHOT_HEADER[0] {
            return Err(bad("not a snapshot of adaptimp (header)"));
        }
        if data[1] == 2.0 {
            return Err(bad(
                "written by an earlier adaptimp (format 2, without the applied torque and the checksum): load its weights instead",
            ));
        }
        if data[1] != SNAPSHOT_HEADER[1] {
            return Err(bad("not a snapshot of this version (header)"));
        }
        if data[2] != N as f64 || data[3] != self.nodes() as f64 {
            return Err(bad("made for another number of joints or nodes"));
        }
        if data.len() != self.snapshot_len() {
            return Err(bad(
                "truncated or too long: not the length of a snapshot of this n and L",
            ));
        }
        let k = data[4];
        if !(0.0..=9.007_199_254_740_992e15).contains(&k) || (k as u64) as f64 != k {
            return Err(bad("the step count is not a whole number in [0, 2^53]"));
        }
        crate::error::check::finite_slice("snapshot", data)?;
        let (body, sum) = data.split_at(data.len() - 1);
        if checksum(body) != sum[0] {
            return Err(bad(
                "its checksum does not match its values: the snapshot is corrupt",
            ));
        }
        Ok(k as u64)
    }

    /// The values of a snapshot whose envelope
    /// [`check_envelope`](Self::check_envelope) passed, with step count `k`,
    /// in the order [`save`](Self::save) wrote them; the weight norms
    /// recomputed from the weights beside the stored ones.
    fn read_snapshot<'a>(&self, data: &'a [f64], k: u64) -> Snapshot<'a, N> {
        let mut r = Reader {
            data,
            at: SNAPSHOT_PREFIX,
        };
        let reference = Reference {
            xd: r.vector(),
            dxd: r.vector(),
        };
        let zeta = r.vector();
        let observer = ObserverState {
            pi1: r.vector(),
            pi2: r.vector(),
            y_prev: r.vector(),
        };
        let q_prev = r.vector();
        let mut last = Command::zeros();
        for v in [
            &mut last.tau_sat,
            &mut last.tau,
            &mut last.dtau,
            &mut last.z1,
            &mut last.z2,
            &mut last.xc,
            &mut last.xd,
            &mut last.v,
            &mut last.zeta,
        ] {
            *v = r.vector();
        }
        let norms = r.array();
        last.w_norms = r.array();
        let nodes = self.nodes();
        let basis = r.take(nodes);
        let rows = r.take(Layout::rows(N) * nodes);
        let applied = r.vector();
        let q_seen = r.vector();
        let exact = Weights::<N>::new(rows, nodes, nodes).norms();
        Snapshot {
            k,
            reference,
            zeta,
            observer,
            q_prev,
            q_seen,
            applied,
            last,
            norms,
            exact,
            basis,
            rows,
        }
    }

    /// Put a checked snapshot into this state (clearing a fault).
    pub(crate) fn commit(&mut self, snap: &Snapshot<'_, N>) {
        self.k = snap.k;
        self.reference = snap.reference;
        self.zeta = snap.zeta;
        self.observer = snap.observer;
        self.q_prev = snap.q_prev;
        self.q_seen = snap.q_seen;
        self.applied = snap.applied;
        self.last = snap.last;
        self.norms = snap.norms;
        self.fault = None;
        let nodes = self.nodes();
        let (basis, mut weights) = self.parts();
        basis.copy_from_slice(snap.basis);
        for (i, row) in snap.rows.chunks_exact(nodes).enumerate() {
            weights.row_mut(i).copy_from_slice(row);
        }
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

/// Weight norms a step can start from: each within [`BOUND`].
fn check_norms(norms: &[f64; 3]) -> Result<(), Error> {
    for (n, what) in norms.iter().zip(["weights.D", "weights.C", "weights.G"]) {
        check::within(what, &[*n], BOUND).map_err(|_| Error::OutOfRange {
            what,
            index: None,
            value: *n,
            limit: BOUND,
        })?;
    }
    Ok(())
}

impl<const N: usize> Snapshot<'_, N> {
    /// What a step could have left, independent of the controller.
    fn check(&self) -> Result<(), Error> {
        use crate::control::safety::CEILING_POSITION;
        check::within("xd", self.reference.xd.as_slice(), CEILING_POSITION)?;
        check::within(
            "dxd",
            self.reference.dxd.as_slice(),
            crate::control::safety::CEILING_VELOCITY,
        )?;
        check::within("q_prev", self.q_prev.as_slice(), CEILING_POSITION)?;
        check::within("q_seen", self.q_seen.as_slice(), CEILING_POSITION)?;
        check::within("zeta", self.zeta.as_slice(), BOUND)?;
        for v in [
            &self.observer.pi1,
            &self.observer.pi2,
            &self.observer.y_prev,
        ] {
            check::within("observer", v.as_slice(), BOUND)?;
        }
        check_norms(&self.exact)?;
        for (s, e) in self.norms.iter().zip(self.exact) {
            if (s - e).abs() > NORM_TOLERANCE * s.max(e) + 1e-12 {
                return Err(Error::Invalid {
                    what: "snapshot",
                    reason: "a stored weight norm differs from the norm of the stored weights: the snapshot is corrupt or was edited",
                });
            }
        }
        Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::config::Law;
    use crate::control::controller::Controller;
    use crate::control::io::Measurement;
    use crate::trajectory::{Sinusoid, Trajectory};

    /// A snapshot after 200 steps of `c` on a slow motion.
    fn stepped(c: &Controller<2>) -> alloc::vec::Vec<f64> {
        let mut st = c.new_state();
        for k in 0..200 {
            let s = k as f64 * 1e-3;
            let m = Measurement {
                x: Vector::<2>::new(0.2 + 0.1 * s.sin(), 0.2),
                dx: Some(Vector::<2>::new(0.1 * s.cos(), 0.0)),
                tau_e: Vector::zeros(),
            };
            let sp = Sinusoid::paper().sample(c.time(&st));
            c.step(&mut st, &m, &sp).unwrap();
        }
        let mut v = alloc::vec![0.0; st.snapshot_len()];
        st.save(&mut v).unwrap();
        v
    }

    /// The checksum made right again: what an edit by someone who knows the
    /// format looks like. The checks behind the checksum must still refuse.
    fn seal(data: &mut [f64]) {
        let n = data.len() - 1;
        data[n] = checksum(&data[..n]);
    }

    #[test]
    fn a_sealed_edit_a_step_could_never_have_left_is_refused() {
        let robot = Controller::robot(Law::StateFeedback);
        let paper = Controller::paper(Law::StateFeedback);
        let n = 2;
        let at = |field: usize| SNAPSHOT_PREFIX + field * n;
        let norms = SNAPSHOT_PREFIX + 16 * n;
        let weights = norms + 6 + 256;
        let rows = Layout::rows(2) * 256;
        let applied = weights + rows;
        // An edited weight, with its stored norm made to agree.
        let weight = |d: &mut [f64], i: usize, v: f64| {
            d[weights + i] = v;
            let w = Weights::<2>::new(&d[weights..applied], 256, 256).norms();
            d[norms..norms + 3].copy_from_slice(&w);
        };
        type Edit<'a> = dyn Fn(&mut [f64]) + 'a;
        let edits: [(&Controller<2>, &str, &Edit<'_>); 9] = [
            (&robot, "xd[0] = 1e99", &|d| d[at(0)] = 1e99),
            (&robot, "dxd[1] = 1e99", &|d| d[at(1) + 1] = 1e99),
            (&robot, "zeta[0] = 1e200", &|d| d[at(2)] = 1e200),
            (&robot, "q_seen[0] = 1e7", &|d| d[applied + n] = 1e7),
            (&robot, "tau_sat[0] = 1e99", &|d| d[at(7)] = 1e99),
            (&robot, "applied torque[1] = 1e99", &|d| {
                d[applied + 1] = 1e99
            }),
            (&robot, "a stored weight norm differs", &|d| {
                d[norms + 2] *= 2.0
            }),
            // Beyond the projection bound.
            (&robot, "‖weights.D‖ = 1e50", &|d| weight(d, 0, 1e50)),
            // Without projection, beyond the step's bound 1e100.
            (&paper, "weights.G = 1.4", &|d| {
                weight(d, 8 * 256, 1e100);
                weight(d, 8 * 256 + 1, 1e100);
            }),
        ];
        for (ctrl, expect, edit) in edits {
            let mut data = stepped(ctrl);
            edit(&mut data);
            seal(&mut data);
            let mut st = ctrl.new_state();
            let e = ctrl.restore(&mut st, &data).unwrap_err();
            let msg = alloc::format!("{e}");
            assert!(msg.contains(expect), "{expect}: {msg}");
            assert_eq!(st.k, 0);
        }
        // Unedited and sealed again: the same, and accepted.
        let good = stepped(&robot);
        let mut data = good.clone();
        seal(&mut data);
        assert_eq!(data, good);
        let mut st = robot.new_state();
        robot.restore(&mut st, &data).unwrap();
    }
}
