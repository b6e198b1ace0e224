//! Fault injection for the simulator: what goes wrong on a real robot,
//! injected into a closed loop over a time window (beyond the paper).
//!
//! | fault | what happens during the window |
//! |---|---|
//! | [`Injected::Stale`] | the sensors repeat their last sample (q, q̇, τe frozen) |
//! | [`Injected::NanBurst`] | the position sensor reads NaN |
//! | [`Injected::ForceBias`] | the force sensor reads τe + bias (N m) |
//! | [`Injected::ActuatorDrop`] | each actuator delivers at most `fraction` of its limit |
//! | [`Injected::Skipped`] | no control step runs: the last applied torque is held |

use crate::types::Vector;

/// One injected fault.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Injected<const N: usize> {
    /// The sensors repeat their last sample (a stale bus frame).
    Stale,
    /// The position sensor reads NaN (a burst of corrupt frames).
    NanBurst,
    /// The force sensor's reading is offset by `bias` (N m): a bias step.
    ForceBias {
        /// The offset added to τe (N m).
        bias: Vector<N>,
    },
    /// The actuators deliver at most `fraction` × `tau_max` (N m): a drive
    /// derating, a supply sag.
    ActuatorDrop {
        /// The nominal limits τmax (N m).
        tau_max: Vector<N>,
        /// The fraction of them delivered, in [0, 1].
        fraction: f64,
    },
    /// Control periods are skipped: the controller is not called and the
    /// last applied torque is held (a missed deadline).
    Skipped,
}

/// A fault and the window of time it acts in: `start ≤ t < start + duration` (s).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Injection<const N: usize> {
    /// The fault.
    pub fault: Injected<N>,
    /// Start of the window (s).
    pub start: f64,
    /// Length of the window (s).
    pub duration: f64,
}

impl<const N: usize> Injection<N> {
    /// True at time `t` (s).
    pub fn active(&self, t: f64) -> bool {
        t >= self.start && t < self.start + self.duration
    }

    /// The measurement the controller sees at `t`, from the true one and the
    /// last sample the sensors delivered.
    pub fn measure(
        &self,
        t: f64,
        truth: (Vector<N>, Vector<N>, Vector<N>),
        last: (Vector<N>, Vector<N>, Vector<N>),
    ) -> (Vector<N>, Vector<N>, Vector<N>) {
        if !self.active(t) {
            return truth;
        }
        match self.fault {
            Injected::Stale => last,
            Injected::NanBurst => (Vector::from_element(f64::NAN), truth.1, truth.2),
            Injected::ForceBias { bias } => (truth.0, truth.1, truth.2 + bias),
            Injected::ActuatorDrop { .. } | Injected::Skipped => truth,
        }
    }

    /// The end-effector wrench F_e (N, N m) the controller sees at `t`, from
    /// the true one and the last the sensor delivered: the last during a
    /// [`Injected::Stale`] window (the force/torque sensor freezes with the
    /// others), the true one otherwise ([`Injected::ForceBias`] acts on τe,
    /// N m per joint, and [`Injected::NanBurst`] on the position sensor).
    pub fn measure_wrench(&self, t: f64, truth: [f64; 6], last: [f64; 6]) -> [f64; 6] {
        match self.fault {
            Injected::Stale if self.active(t) => last,
            _ => truth,
        }
    }

    /// The torque the actuators deliver at `t` for the applied command `tau` (N m).
    pub fn actuate(&self, t: f64, tau: &Vector<N>) -> Vector<N> {
        match self.fault {
            Injected::ActuatorDrop { tau_max, fraction } if self.active(t) => {
                tau.zip_map(&tau_max, |x, m| x.clamp(-fraction * m, fraction * m))
            }
            _ => *tau,
        }
    }

    /// True if the control step is skipped at `t`.
    pub fn skips(&self, t: f64) -> bool {
        matches!(self.fault, Injected::Skipped) && self.active(t)
    }
}

/// What a run with an injected fault showed (see [`FaultReport`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct FaultFigures {
    /// Peak applied |τ_i| / τmax_i over the run (≤ 1: never beyond the limits).
    pub peak_applied_ratio: f64,
    /// Peak commanded |τ_i| (N m) from the fault's start on.
    pub peak_commanded: f64,
    /// RMS ‖z1‖ (rad) over the 2 s before the fault.
    pub rms_before: f64,
    /// Time (s) from the fault's end until the RMS ‖z1‖ over a 0.5 s window
    /// is back within 10% of `rms_before` (or 1 mrad of it); `None` if never.
    pub recovery: Option<f64>,
    /// Rows at which the controller refused the step or did not run.
    pub refused: usize,
    /// True if any recorded value was NaN or infinite.
    pub non_finite: bool,
    /// Weight norms ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ just before the fault and at the end.
    pub norms: ([f64; 3], [f64; 3]),
}

/// A recorder of the facts [`FaultFigures`] reports (feature `alloc`: it
/// keeps one running sum per row).
#[cfg(feature = "alloc")]
#[derive(Clone, Debug, Default)]
pub struct FaultReport {
    t: alloc::vec::Vec<f64>,
    /// Running sum of ‖z1‖² up to and including each row.
    cumulative: alloc::vec::Vec<f64>,
    applied_ratio: alloc::vec::Vec<f64>,
    commanded: alloc::vec::Vec<f64>,
    norms: alloc::vec::Vec<[f64; 3]>,
    refused: usize,
    non_finite: bool,
}

#[cfg(feature = "alloc")]
impl FaultReport {
    /// Record `row` (with the actuators' limits `tau_max`, N m).
    pub fn push<const N: usize>(&mut self, row: &crate::sim::record::Row<N>, tau_max: &Vector<N>) {
        let z = row.z1.norm_squared();
        let last = self.cumulative.last().copied().unwrap_or(0.0);
        self.t.push(row.t);
        self.cumulative.push(last + z);
        self.applied_ratio
            .push(row.tau_sat.zip_map(tau_max, |t, m| t.abs() / m).max());
        self.commanded.push(row.tau.amax());
        self.norms.push(row.w_norms);
        self.refused += usize::from(row.refused);
        let values = [
            row.x,
            row.dx,
            row.tau,
            row.tau_sat,
            row.z1,
            row.zeta,
            row.dx_hat,
        ];
        self.non_finite |= values.iter().any(|v| v.iter().any(|x| !x.is_finite()))
            || row.w_norms.iter().any(|x| !x.is_finite());
    }

    /// The figures of the run for `injection`, which ran at period `ts` (s).
    pub fn finish<const N: usize>(&self, injection: &Injection<N>, ts: f64) -> FaultFigures {
        let row = |t: f64| libm::round(t / ts).max(0.0) as usize;
        let rms = |a: usize, b: usize| {
            let b = b.min(self.cumulative.len());
            if b <= a {
                return f64::NAN;
            }
            let before = if a == 0 { 0.0 } else { self.cumulative[a - 1] };
            crate::math::sqrt((self.cumulative[b - 1] - before) / (b - a) as f64)
        };
        let start = row(injection.start);
        let end = row(injection.start + injection.duration);
        let rms_before = rms(row(injection.start - 2.0), start);
        let window = row(0.5);
        let target = (1.1 * rms_before).max(rms_before + 1e-3);
        let recovery = (end..self.cumulative.len().saturating_sub(window))
            .find(|&k| rms(k, k + window) <= target)
            .map(|k| (k - end) as f64 * ts);
        let peak = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(*x));
        FaultFigures {
            peak_applied_ratio: peak(&self.applied_ratio),
            peak_commanded: peak(self.commanded.get(start..).unwrap_or(&[])),
            rms_before,
            recovery,
            refused: self.refused,
            non_finite: self.non_finite,
            norms: (
                self.norms.get(start).copied().unwrap_or([0.0; 3]),
                self.norms.last().copied().unwrap_or([0.0; 3]),
            ),
        }
    }
}
