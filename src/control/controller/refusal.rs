//! A refused step: recorded as the fault it is, and the fallback torque
//! applied in its place (SPEC §14).

use super::*;

impl<const N: usize, B: Basis<N>> Controller<N, B> {
    /// A step call a front refused before it reached [`step`](Self::step)
    /// (an argument of the wrong shape or type, a missing measurement):
    /// recorded as a refused step is, with `error` as its fault, and the
    /// fallback returned (damping uses the last velocity the controller used).
    /// So every refusal latches, whichever front saw it first.
    pub fn refuse<S>(&self, st: &mut State<N, S>, error: Error) -> Vector<N> {
        self.record(st, None, error);
        st.applied
    }

    /// A step refused before it reached [`step`](Self::step) by a caller
    /// that has its measurement `m` (a Cartesian outer loop that refused its
    /// target or wrench, SPEC §16): recorded exactly as a refused step is
    /// (the fault, the fallback as the applied torque, with damping from the
    /// measured q̇ if usable, and q as the last measured position if
    /// plausible), and the fallback returned.
    pub fn refuse_measured<S>(
        &self,
        st: &mut State<N, S>,
        m: &Measurement<N>,
        error: Error,
    ) -> Vector<N> {
        if self.cfg.limits.plausible_position(&m.x) {
            st.q_seen = m.x;
        }
        self.record(st, m.dx.as_ref(), error);
        st.applied
    }

    /// Record a refused step: the fault (a latched one is kept), and the
    /// fallback as the applied torque.
    pub(super) fn record<S>(&self, st: &mut State<N, S>, dx: Option<&Vector<N>>, error: Error) {
        let latched = self.cfg.fault_policy == FaultPolicy::Latch && st.fault.is_some();
        if !latched {
            st.fault = Some(Fault { error, step: st.k });
        }
        st.applied = self.fallback_with(st, dx);
    }

    /// The configured fallback torque (N m, saturated) for `state` given the
    /// measurement `m`: for hold, the torque last applied; for damping, its
    /// velocity if finite and within `dq_max`, else the last velocity the
    /// controller used.
    pub fn fallback<S>(&self, st: &State<N, S>, m: &Measurement<N>) -> Vector<N> {
        self.fallback_with(st, m.dx.as_ref())
    }

    /// [`fallback`](Self::fallback) with the measured velocity `dx`, if any.
    pub(super) fn fallback_with<S>(&self, st: &State<N, S>, dx: Option<&Vector<N>>) -> Vector<N> {
        let tau = match self.cfg.fallback {
            Fallback::Hold => st.applied,
            Fallback::Zero => Vector::zeros(),
            Fallback::Damping => {
                let bound = self.cfg.limits.velocity();
                let usable = |v: &Vector<N>| {
                    v.iter()
                        .zip(bound.iter())
                        .all(|(x, l)| x.is_finite() && x.abs() <= *l)
                };
                let v = match dx {
                    Some(dx) if usable(dx) => *dx,
                    _ => st.last.v,
                };
                -self.cfg.fallback_damping.component_mul(&v)
            }
        };
        self.sat.apply(&tau)
    }
}
