//! High-gain velocity observer, (31)–(34), SPEC §9.
//!
//! Per joint, with the measured position y = x:
//! `ε π̇1 = π2`, `ε π̇2 = −λ1 π2 − π1 + y`, and the velocity estimate
//! `ẋ̂ = π2 / ε`. Discretised exactly for a given inter-sample model of y
//! ([`Hold`]); either way `Φ = e^{A Ts}` and the discrete observer is stable
//! for every sampling period.
//!
//! **Sampling effect.** Under zero-order hold (the SPEC §11 default) the
//! sampled estimate of a ramp has gain `1 − (Ts/ε)²/12 + O((Ts/ε)⁴)` (the
//! observer responds to each step of the staircase; Euler–Maclaurin on its
//! sampled impulse response): −2.1% at the paper's Ts = 50 µs, ε = 1e-4.
//! [`Hold::Triangle`] interpolates y linearly between samples, which a ramp
//! satisfies exactly, and has no such deficit.
//!
//! **Lag.** Either way the estimate of a ramp-accelerating signal is late:
//! with y_k = ½ a t_k², the steady estimate is `ẋ̂_k = g a (t_k − L)` with the
//! gain g above (1 for the triangle hold) and the lag L of [`lag`](HighGainObserver::lag),
//! (9.1), SPEC §9: λ1 ε when Ts ≪ ε, Ts/2 when Ts ≫ ε (the backward
//! difference of the samples).

use crate::error::{check, Error};
use crate::types::{choices, Vector};
use nalgebra::{Matrix2, Matrix4, SMatrix, Vector2};

/// How the measured position is modelled between samples.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq)]
pub enum Hold {
    /// Zero-order hold: y = y_k on [t_k, t_{k+1}), SPEC §11 ("zoh" in Python).
    /// The state is advanced at the end of step k with y_k.
    #[default]
    Zero,
    /// Triangle (first-order, non-causal) hold: y linear from y_{k−1} to y_k on
    /// [t_{k−1}, t_k) ("triangle" in Python). The state is advanced at the start
    /// of step k, once y_k is measured, so the estimate at t_k uses y_k.
    Triangle,
}

choices!(Hold {
    "zoh" => Hold::Zero,
    "triangle" => Hold::Triangle,
});

/// Observer parameters and their precomputed discretisation.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HighGainObserver<const N: usize> {
    eps: f64,
    lam1: Vector<N>,
    hold: Hold,
    phi: [Matrix2<f64>; N],
    /// Response to a held input (ZOH): ∫₀^Ts e^{Aη} dη B.
    gam0: [Vector2<f64>; N],
    /// Response to the input's increment over the period, ramped (triangle hold).
    gam1: [Vector2<f64>; N],
    /// The estimate's lag L (s) to a ramp-accelerating signal, (9.1).
    lag: Vector<N>,
}

/// Observer state per joint: π1 (rad, tracks x), π2 (rad; ε × velocity), and
/// the previous measurement (for the triangle hold).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ObserverState<const N: usize> {
    /// π1 (rad).
    pub pi1: Vector<N>,
    /// π2 (rad); the velocity estimate is π2/ε.
    pub pi2: Vector<N>,
    /// Last measurement y (rad), used by [`Hold::Triangle`].
    pub y_prev: Vector<N>,
}

impl<const N: usize> ObserverState<N> {
    /// π(0) = 0, as in the paper.
    pub fn zeros() -> Self {
        Self {
            pi1: Vector::zeros(),
            pi2: Vector::zeros(),
            y_prev: Vector::zeros(),
        }
    }
}

impl<const N: usize> HighGainObserver<N> {
    /// ε > 0 (s), λ1 > 0 (per joint), sampling period `ts` > 0 (s) (SPEC §10),
    /// and the inter-sample model `hold`.
    pub fn new(eps: f64, lam1: Vector<N>, ts: f64, hold: Hold) -> Result<Self, Error> {
        check::positive("ε > 0", "eps", eps)?;
        check::positive_vec("λ1 > 0", "lam1", &lam1)?;
        check::positive("Ts > 0", "Ts", ts)?;
        // Beyond this the observer is a steady state at every sample anyway,
        // and the matrix exponential's scaling would overflow (its squaring
        // count saturates: a construction that never returns).
        check::at_most("Ts/ε ≤ 1e6", "Ts/eps", ts / eps, 1e6)?;
        check::each("λ1 ≤ 1e6", "lam1", &lam1, |_, l| 1e6 - l, false)?;
        let mut phi = [Matrix2::zeros(); N];
        let mut gam0 = [Vector2::zeros(); N];
        let mut gam1 = [Vector2::zeros(); N];
        for i in 0..N {
            // With y(t_k + sTs) = y_k + s Δ on s ∈ [0, 1], the scaled system
            // (π, y, Δ)' = [[A Ts, B Ts, 0], [0, 0, 1], [0, 0, 0]] (π, y, Δ)
            // has exp = [[Φ, Γ0, Γ1], [0, 1, 1], [0, 0, 1]]; A = (1/ε)[[0, 1], [−1, −λ1]],
            // B = (1/ε)[0, 1]ᵀ.
            let h = ts / eps;
            let mut m = Matrix4::zeros();
            m[(0, 1)] = h;
            m[(1, 0)] = -h;
            m[(1, 1)] = -lam1[i] * h;
            m[(1, 2)] = h;
            m[(2, 3)] = 1.0;
            let e = expm(&m);
            phi[i] = e.fixed_view::<2, 2>(0, 0).into_owned();
            gam0[i] = e.fixed_view::<2, 1>(0, 2).into_owned();
            gam1[i] = e.fixed_view::<2, 1>(0, 3).into_owned();
            check::finite_slice("observer discretisation", e.as_slice())?;
        }
        let mut lag = Vector::zeros();
        for i in 0..N {
            lag[i] = lag_of(&phi[i], &gam0[i], &gam1[i], ts, hold);
        }
        Ok(Self {
            eps,
            lam1,
            hold,
            phi,
            gam0,
            gam1,
            lag,
        })
    }

    /// ε (s).
    pub fn eps(&self) -> f64 {
        self.eps
    }
    /// λ1 (dimensionless), per joint.
    pub fn lam1(&self) -> &Vector<N> {
        &self.lam1
    }
    /// The inter-sample model.
    pub fn hold(&self) -> Hold {
        self.hold
    }
    /// The lag L (s) of the sampled estimate behind the velocity of a
    /// ramp-accelerating signal, per joint, (9.1), SPEC §9: with y_k = ½ a t_k²
    /// the steady estimate is g a (t_k − L) (g = 1 for the triangle hold).
    /// 0.526 ms at the robot preset's Ts = 1 ms, ε = 1e-4 s, λ1 = 3.
    pub fn lag(&self) -> &Vector<N> {
        &self.lag
    }

    /// Velocity estimate ẋ̂ = π2/ε (rad/s).
    #[inline]
    pub fn estimate(&self, st: &ObserverState<N>) -> Vector<N> {
        st.pi2 / self.eps
    }

    /// Take in the measurement `y_k` (rad) at the start of step `k`, before the
    /// estimate: for the triangle hold, advance over [t_{k−1}, t_k) with y
    /// ramping from y_{k−1} to y_k (nothing at k = 0). No-op for ZOH.
    #[inline]
    pub fn measure(&self, st: &mut ObserverState<N>, y: &Vector<N>, first: bool) {
        if self.hold == Hold::Triangle && !first {
            let prev = st.y_prev;
            for i in 0..N {
                self.advance_joint(st, i, prev[i], y[i] - prev[i]);
            }
        }
        st.y_prev = *y;
    }

    /// Finish step `k` (after the estimate was used): for ZOH, advance to
    /// t_{k+1} with y_k held (SPEC §11). No-op for the triangle hold.
    #[inline]
    pub fn finish(&self, st: &mut ObserverState<N>, y: &Vector<N>) {
        if self.hold == Hold::Zero {
            for i in 0..N {
                self.advance_joint(st, i, y[i], 0.0);
            }
        }
    }

    /// Advance the state one period with the measurement `y` (rad) held:
    /// `π ← Φ π + Γ0 y` (the SPEC §11 ZOH update, whatever [`Hold`] is set).
    #[inline]
    pub fn advance(&self, st: &mut ObserverState<N>, y: &Vector<N>) {
        for i in 0..N {
            self.advance_joint(st, i, y[i], 0.0);
        }
    }

    #[inline(always)]
    fn advance_joint(&self, st: &mut ObserverState<N>, i: usize, y: f64, dy: f64) {
        let (p1, p2) = (st.pi1[i], st.pi2[i]);
        let (f, g0, g1) = (&self.phi[i], &self.gam0[i], &self.gam1[i]);
        st.pi1[i] = f[(0, 0)] * p1 + f[(0, 1)] * p2 + g0[0] * y + g1[0] * dy;
        st.pi2[i] = f[(1, 0)] * p1 + f[(1, 1)] * p2 + g0[1] * y + g1[1] * dy;
    }
}

/// The lag L (s) of one joint's discrete observer, (9.1), SPEC §9: the
/// steady response to the samples y_k = ½ (k Ts)² is a polynomial in k,
/// π_k = p + q k + r k², since each step is
/// π_k = Φ π_{k−1} + Γ0 y_{k−1} + h Γ1 (y_k − y_{k−1}) (h = 1 for the triangle
/// hold, 0 for ZOH, the estimate read at t_k). Matching the powers of k, with
/// c = Ts²/2 and (I − Φ) invertible (Φ = e^{A Ts} is stable):
/// (I − Φ) r = c Γ0, (I − Φ) q = 2c (h Γ1 − Γ0) − 2Φ r,
/// (I − Φ) p = c (Γ0 − h Γ1) − Φ (q − r).
/// Then r₂ = 0, ẋ̂_k = (p₂ + q₂ k)/ε = g (t_k − L) with L = −Ts p₂/q₂.
/// An estimate that does not move with the signal (q₂ = 0: ZOH at Ts/ε in
/// the thousands) has no lag to speak of: 0.
fn lag_of(phi: &Matrix2<f64>, g0: &Vector2<f64>, g1: &Vector2<f64>, ts: f64, hold: Hold) -> f64 {
    let h = match hold {
        Hold::Zero => 0.0,
        Hold::Triangle => 1.0,
    };
    let Some(m) = (Matrix2::identity() - phi).try_inverse() else {
        return 0.0;
    };
    let c = 0.5 * ts * ts;
    let r = m * (g0 * c);
    let q = m * ((g1 * h - g0) * (2.0 * c) - phi * r * 2.0);
    let p = m * ((g0 - g1 * h) * c - phi * (q - r));
    let lag = -ts * p[1] / q[1];
    if lag.is_finite() {
        lag
    } else {
        0.0
    }
}

/// Matrix exponential. With `std`: nalgebra's (Padé approximant with scaling
/// and squaring, Higham 2005), accurate to ~1e-16 here. Without: a Taylor
/// series with scaling and squaring (scale to ‖M/2^s‖₁ ≤ 1/2, 18 terms,
/// square s times), accurate to a few 1e-15 at Ts/ε = 10, because each
/// squaring doubles the rounding error; nalgebra's `exp` needs `std`.
#[cfg(feature = "std")]
fn expm(m: &Matrix4<f64>) -> Matrix4<f64> {
    m.exp()
}

#[cfg(not(feature = "std"))]
fn expm(m: &Matrix4<f64>) -> Matrix4<f64> {
    expm_taylor(m)
}

/// The `no_std` matrix exponential (see [`expm`]).
#[cfg_attr(feature = "std", allow(dead_code))]
fn expm_taylor<const D: usize>(m: &SMatrix<f64, D, D>) -> SMatrix<f64, D, D> {
    let norm = m.column_iter().map(|c| c.lp_norm(1)).fold(0.0, f64::max);
    let mut squarings = 0;
    let mut scale = 1.0;
    while norm * scale > 0.5 && squarings < 1100 {
        scale *= 0.5;
        squarings += 1;
    }
    let a = m * scale;
    let mut term = SMatrix::<f64, D, D>::identity();
    let mut sum = term;
    for n in 1..=18 {
        term = term * a / n as f64;
        sum += term;
    }
    for _ in 0..squarings {
        sum = sum * sum;
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Matrix3;

    /// Max |ẋ̂ − ẋ| over t ∈ [2, 3) s of a sampled sinusoid x = A sin(ωt),
    /// relative to the amplitude Aω, and the peak |ẋ̂| over the whole run.
    fn sine_error(ts: f64, eps: f64, hold: Hold) -> (f64, f64) {
        let (a, w) = (0.3, 2.0 * core::f64::consts::PI);
        let obs = HighGainObserver::<1>::new(eps, Vector::<1>::new(3.0), ts, hold).unwrap();
        let mut st = ObserverState::zeros();
        let steps = (3.0 / ts).round() as usize;
        let (mut err, mut peak) = (0.0f64, 0.0f64);
        for k in 0..steps {
            let t = k as f64 * ts;
            let y = Vector::<1>::new(a * (w * t).sin());
            obs.measure(&mut st, &y, k == 0);
            let est = obs.estimate(&st)[0];
            peak = peak.max(est.abs());
            if t >= 2.0 {
                err = err.max((est - a * w * (w * t).cos()).abs());
            }
            obs.finish(&mut st, &y);
        }
        (err / (a * w), peak)
    }

    #[test]
    fn triangle_hold_estimates_velocity_within_one_percent_at_50us() {
        let (rel, _) = sine_error(50e-6, 1e-4, Hold::Triangle);
        assert!(rel < 0.01, "relative error {rel}");
    }

    #[test]
    fn zoh_estimate_has_the_predicted_sampling_gain() {
        // Gain 1 − (Ts/ε)²/12 = 0.9792 at Ts/ε = 0.5 (module docs); the rest
        // of the error is the phase lag ω(λ1 ε + Ts) ≈ 0.2%.
        let (rel, _) = sine_error(50e-6, 1e-4, Hold::Zero);
        let predicted = 0.25 / 12.0;
        assert!(
            (rel - predicted).abs() < 0.003,
            "relative error {rel}, predicted {predicted}"
        );
        // With Ts/ε = 0.1 the deficit is 0.08%: within 1%.
        let (rel, _) = sine_error(10e-6, 1e-4, Hold::Zero);
        assert!(rel < 0.01, "relative error {rel}");
    }

    #[test]
    fn stays_bounded_at_slow_sampling() {
        for hold in [Hold::Zero, Hold::Triangle] {
            for ts in [1e-3, 10e-3] {
                let (rel, peak) = sine_error(ts, 1e-4, hold);
                // The true velocity amplitude is 0.3·2π ≈ 1.9 rad/s.
                assert!(
                    peak.is_finite() && peak < 10.0,
                    "{hold:?} Ts = {ts}: peak {peak}"
                );
                assert!(
                    rel.is_finite() && rel < 2.0,
                    "{hold:?} Ts = {ts}: error {rel}"
                );
            }
        }
    }

    #[test]
    fn expm_matches_closed_form_of_a_rotation_and_a_decay() {
        let w = 2.5;
        let e = expm_taylor(&Matrix3::new(0.0, w, 0.0, -w, 0.0, 0.0, 0.0, 0.0, -40.0));
        assert!((e[(0, 0)] - w.cos()).abs() < 1e-14 && (e[(0, 1)] - w.sin()).abs() < 1e-14);
        assert!((e[(1, 0)] + w.sin()).abs() < 1e-14 && (e[(1, 1)] - w.cos()).abs() < 1e-14);
        assert!(
            (e[(2, 2)] - (-40.0f64).exp()).abs() < 1e-25,
            "{}",
            e[(2, 2)]
        );
    }

    /// Ts, then Φ (row-major), Γ0 and Γ1.
    type Discretisation = (f64, [f64; 4], [f64; 2], [f64; 2]);

    /// Φ, Γ0, Γ1 from scipy.linalg.expm of the scaled 4 × 4 matrix (ε = 1e-4, λ1 = 3).
    const SCIPY: [Discretisation; 2] = [
        (
            50e-6,
            [
                0.9211332218348366,
                0.24867813145602083,
                -0.24867813145602077,
                0.1750988274667742,
            ],
            [0.07886677816516337, 0.24867813145602077],
            [0.029443068096977984, 0.15773355633032676],
        ),
        (
            1e-3,
            [
                0.02568224405581328,
                0.009809744320321261,
                -0.009809744320321246,
                -0.003746988905150467,
            ],
            [0.9743177559441866, 0.0098097443203213],
            [0.7067236987847116, 0.09743177559441868],
        ),
    ];

    #[test]
    fn discretisation_matches_scipy_expm() {
        for (ts, phi, g0, g1) in SCIPY {
            let obs = HighGainObserver::<1>::new(1e-4, Vector::<1>::new(3.0), ts, Hold::Triangle)
                .unwrap();
            let p = Matrix2::new(phi[0], phi[1], phi[2], phi[3]);
            let err = [
                (obs.phi[0] - p).abs().max(),
                (obs.gam0[0] - Vector2::from(g0)).abs().max(),
                (obs.gam1[0] - Vector2::from(g1)).abs().max(),
            ]
            .into_iter()
            .fold(0.0, f64::max);
            // nalgebra's Padé exponential with std; the Taylor fallback without.
            let tol = if cfg!(feature = "std") { 1e-15 } else { 1e-14 };
            assert!(err < tol, "Ts = {ts}: error {err:e}");
        }
    }

    #[test]
    fn taylor_fallback_is_within_a_few_ulps_of_the_pade_result() {
        let h = 10.0; // Ts/ε at Ts = 1 ms
        let mut m = SMatrix::<f64, 4, 4>::zeros();
        m[(0, 1)] = h;
        m[(1, 0)] = -h;
        m[(1, 1)] = -3.0 * h;
        m[(1, 2)] = h;
        m[(2, 3)] = 1.0;
        let err = (expm_taylor(&m) - expm(&m)).abs().max();
        assert!(err < 1e-14, "{err:e}");
    }

    /// The lag (9.1) is what running the observer on y = ½ a t² shows: the
    /// last two estimates give the gain g (their slope over a) and the offset,
    /// ẋ̂_k = g a (t_k − L).
    #[test]
    fn lag_is_the_estimates_delay_on_a_ramp_accelerating_signal() {
        let a = 2.0;
        for (hold, periods) in [
            (Hold::Triangle, &[1e-5, 5e-5, 2e-4, 1e-3, 4e-3][..]),
            (Hold::Zero, &[1e-5, 5e-5, 2e-4, 1e-3][..]),
        ] {
            for &ts in periods {
                let obs =
                    HighGainObserver::<1>::new(1e-4, Vector::<1>::new(3.0), ts, hold).unwrap();
                let mut st = ObserverState::zeros();
                let steps = ((0.05 / ts).round() as usize).max(100);
                let mut est = [0.0; 2];
                for k in 0..steps {
                    let t = k as f64 * ts;
                    let y = Vector::<1>::new(0.5 * a * t * t);
                    obs.measure(&mut st, &y, k == 0);
                    est = [est[1], obs.estimate(&st)[0]];
                    obs.finish(&mut st, &y);
                }
                let t = (steps - 1) as f64 * ts;
                let g = (est[1] - est[0]) / (a * ts);
                let lag = t - est[1] / (g * a);
                let want = obs.lag()[0];
                assert!(
                    (lag - want).abs() < 1e-6 * ts,
                    "{hold:?} Ts = {ts}: ran {lag:e} s, (9.1) {want:e} s (gain {g})"
                );
                if hold == Hold::Triangle {
                    assert!((g - 1.0).abs() < 1e-6, "Ts = {ts}: gain {g}");
                }
            }
        }
    }

    #[test]
    fn the_triangle_holds_lag_is_lam1_eps_when_fast_and_half_a_period_when_slow() {
        let lag = |ts: f64| {
            HighGainObserver::<1>::new(1e-4, Vector::<1>::new(3.0), ts, Hold::Triangle)
                .unwrap()
                .lag()[0]
        };
        // Ts ≪ ε: the continuous observer's λ1 ε = 0.3 ms.
        assert!((lag(1e-6) - 3e-4).abs() < 1e-3 * 3e-4, "{:e}", lag(1e-6));
        // Ts ≫ ε: the backward difference, Ts/2 (0.526 Ts at Ts/ε = 10).
        assert!((lag(1e-2) / 1e-2 - 0.5).abs() < 1e-6, "{:e}", lag(1e-2));
        assert!((lag(1e-3) / 1e-3 - 0.5263).abs() < 1e-4, "{:e}", lag(1e-3));
    }

    #[test]
    fn constant_input_is_a_fixed_point_with_zero_velocity() {
        for hold in [Hold::Zero, Hold::Triangle] {
            let obs =
                HighGainObserver::<2>::new(1e-4, Vector::<2>::new(3.0, 3.0), 1e-3, hold).unwrap();
            let y = Vector::<2>::new(0.4, -1.0);
            let mut st = ObserverState {
                pi1: y,
                pi2: Vector::zeros(),
                y_prev: y,
            };
            obs.measure(&mut st, &y, false);
            obs.finish(&mut st, &y);
            assert!(
                (st.pi1 - y).norm() < 1e-12 && st.pi2.norm() < 1e-12,
                "{st:?}"
            );
        }
    }
}
