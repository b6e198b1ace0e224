//! Disturbances a real robot has, as simulator options (beyond the paper,
//! SPEC §17): the plant differs from the nominal one, the sensors are noisy
//! and late, the sampling instants jitter, the joints have friction and the
//! actuators are weaker than rated. The controller knows none of them.
//!
//! | option | unit | acts on | where |
//! |---|---|---|---|
//! | `payload` | kg | point mass at the tip of the last link | the plant's arm ([`TipPayload`]) |
//! | `noise_q`, `noise_dq`, `noise_tau_e` | rad, rad/s, N m | Gaussian noise on each sample, seeded | the measurement |
//! | `seed` | | the generator of the noise and the jitter | |
//! | `delay` | steps | the controller sees the sample of step k − d (the end-effector wrench too) | the measurement |
//! | `jitter` | | the true interval is Ts (1 + u), u ~ U[−j, j) | the plant's integration |
//! | `friction_viscous`, `friction_coulomb`, `friction_vs` | N m s/rad, N m, rad/s | τf = −b q̇ − fc tanh(q̇/v_s) | the plant's arm ([`WithFriction`]) |
//! | `actuator_fraction` | | the delivered torque is clamped to ±ρ τmax | the actuators |
//!
//! [`DisturbanceParams`] holds the numbers (its [`Default`] is no
//! disturbance at all); [`Disturbances`] is the validated, immutable
//! description; [`DisturbanceState`] is what a run changes (the generators
//! and the delay line), created by [`Disturbances::new_state`]. Masses and
//! lengths that differ from the nominal ones are the arm's own parameters
//! (`m1`, `m2`, `l1`, `l2`, … of the schema); the controller is model-free
//! and never reads them.
//!
//! Determinism: one run draws from two xoshiro256++ streams seeded from
//! `seed` (SplitMix64, as [`SeedableRng::seed_from_u64`] does): the noise
//! stream, and the jitter stream 2^192 draws further on (`long_jump`). Each
//! sample draws 3N standard normals (q, then q̇, then τe, joint by joint)
//! whenever any noise is on, so the noise on one channel does not depend on
//! which other channels are on. The same seed and options give the same run,
//! bit for bit, in any thread.

use crate::error::{check, Error, PARAM_BOUND};
use crate::math::tanh;
use crate::sim::model::{ArmParams, Link, Manipulator, PlanarArm, TwoLinkArm};
use crate::types::{Matrix, Vector};
use rand_distr::{Distribution, StandardNormal, StandardUniform};
use rand_xoshiro::rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// The longest measurement delay, in controller steps (the delay line is a
/// fixed array of `MAX_DELAY + 1` samples: no allocation); the same bound as
/// a controller's own delay.
pub use crate::control::config::MAX_DELAY;

/// What the sensors deliver at one sample: joint position q (rad), joint
/// velocity q̇ (rad/s) and the contact force τe (N m).
pub type Sample<const N: usize> = (Vector<N>, Vector<N>, Vector<N>);

/// The disturbances as numbers, one field per schema name (group "sim").
/// [`Default`] is no disturbance: every existing result is unchanged.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct DisturbanceParams<const N: usize> {
    /// Point mass at the tip of the last link (kg), ≥ 0. The plant's only.
    pub payload: f64,
    /// Standard deviation of the noise on each measured q_i (rad), ≥ 0.
    pub noise_q: Vector<N>,
    /// Standard deviation of the noise on each measured q̇_i (rad/s), ≥ 0.
    pub noise_dq: Vector<N>,
    /// Standard deviation of the noise on each measured τe_i (N m), ≥ 0.
    pub noise_tau_e: Vector<N>,
    /// Seed of the noise and jitter generators.
    pub seed: u64,
    /// Measurement delay d (controller steps), 0 ≤ d ≤ [`MAX_DELAY`].
    pub delay: usize,
    /// Sampling-time jitter j: the true interval is Ts (1 + u), u uniform on
    /// [−j, j); 0 ≤ j < 1.
    pub jitter: f64,
    /// Viscous friction b_i (N m s/rad), ≥ 0.
    pub friction_viscous: Vector<N>,
    /// Coulomb friction level fc_i (N m), ≥ 0.
    pub friction_coulomb: Vector<N>,
    /// Velocity scale v_s of the smooth Coulomb term fc tanh(q̇/v_s) (rad/s), > 0.
    pub friction_vs: f64,
    /// Fraction ρ_i of its limit τmax_i that actuator i delivers, 0 < ρ_i ≤ 1.
    pub actuator_fraction: Vector<N>,
}

impl<const N: usize> Default for DisturbanceParams<N> {
    /// No disturbance: zero payload, noise, delay, jitter and friction,
    /// ρ = 1, seed 0, v_s = 0.01 rad/s (the schema's defaults).
    fn default() -> Self {
        let zero = Vector::zeros();
        Self {
            payload: 0.0,
            noise_q: zero,
            noise_dq: zero,
            noise_tau_e: zero,
            seed: 0,
            delay: 0,
            jitter: 0.0,
            friction_viscous: zero,
            friction_coulomb: zero,
            friction_vs: 0.01,
            actuator_fraction: Vector::from_element(1.0),
        }
    }
}

/// Joint friction, SPEC §17: τf(q̇) = −b∘q̇ − fc∘tanh(q̇/v_s) (N m), the
/// viscous plus Coulomb model of Olsson et al. (1998) with the sign function
/// smoothed by tanh so that RK4 integrates a smooth right-hand side.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Friction<const N: usize> {
    viscous: Vector<N>,
    coulomb: Vector<N>,
    vs: f64,
    zero: bool,
}

impl<const N: usize> Friction<N> {
    /// No friction.
    pub fn none() -> Self {
        Self {
            viscous: Vector::zeros(),
            coulomb: Vector::zeros(),
            vs: 1.0,
            zero: true,
        }
    }

    /// Viscous `viscous` (N m s/rad) and Coulomb `coulomb` (N m) friction per
    /// joint, both ≥ 0, with velocity scale `vs` (rad/s) > 0.
    pub fn new(viscous: Vector<N>, coulomb: Vector<N>, vs: f64) -> Result<Self, Error> {
        check::nonnegative_vec("b ≥ 0", "friction_viscous", &viscous)?;
        check::nonnegative_vec("fc ≥ 0", "friction_coulomb", &coulomb)?;
        check::positive("v_s > 0", "friction_vs", vs)?;
        for (what, v) in [
            ("friction_viscous", &viscous),
            ("friction_coulomb", &coulomb),
        ] {
            check::at_most("|value| ≤ 1e9", what, v.amax(), PARAM_BOUND)?;
        }
        check::at_most("|value| ≤ 1e9", "friction_vs", vs, PARAM_BOUND)?;
        let zero = viscous.iter().chain(coulomb.iter()).all(|x| *x == 0.0);
        Ok(Self {
            viscous,
            coulomb,
            vs,
            zero,
        })
    }

    /// True if every coefficient is zero.
    pub fn is_none(&self) -> bool {
        self.zero
    }

    /// The friction torque τf (N m) at joint velocity `dq` (rad/s): it opposes
    /// the motion, so q̇ᵀτf ≤ 0 (it only dissipates).
    #[inline]
    pub fn torque(&self, dq: &Vector<N>) -> Vector<N> {
        let mut tau = Vector::zeros();
        for i in 0..N {
            tau[i] = -(self.viscous[i] * dq[i] + self.coulomb[i] * tanh(dq[i] / self.vs));
        }
        tau
    }
}

/// An arm with joint friction: the same D, C, G, and a forward dynamics in
/// which the joints also receive the friction torque,
/// `D q̈ + C q̇ + G = τ + τf(q̇) − τe` (SPEC §17). RK4 evaluates it at every
/// stage with that stage's velocity.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct WithFriction<const N: usize, M> {
    arm: M,
    friction: Friction<N>,
}

impl<const N: usize, M: Manipulator<N>> WithFriction<N, M> {
    /// `arm` with `friction`.
    pub fn new(arm: M, friction: Friction<N>) -> Self {
        Self { arm, friction }
    }
    /// The arm without friction.
    pub fn arm(&self) -> &M {
        &self.arm
    }
    /// The friction.
    pub fn friction(&self) -> &Friction<N> {
        &self.friction
    }
}

impl<const N: usize, M: Manipulator<N>> Manipulator<N> for WithFriction<N, M> {
    fn inertia(&self, q: &Vector<N>) -> Matrix<N> {
        self.arm.inertia(q)
    }
    fn coriolis(&self, q: &Vector<N>, dq: &Vector<N>) -> Matrix<N> {
        self.arm.coriolis(q, dq)
    }
    fn gravity(&self, q: &Vector<N>) -> Vector<N> {
        self.arm.gravity(q)
    }
    #[inline]
    fn forward_dynamics(
        &self,
        q: &Vector<N>,
        dq: &Vector<N>,
        tau: &Vector<N>,
        tau_e: &Vector<N>,
    ) -> Vector<N> {
        if self.friction.zero {
            // Exactly the arm's arithmetic: no friction changes no bit.
            return self.arm.forward_dynamics(q, dq, tau, tau_e);
        }
        let tau = tau + self.friction.torque(dq);
        self.arm.forward_dynamics(q, dq, &tau, tau_e)
    }
}

/// A manipulator that can carry a payload: a point mass at the tip of its
/// last link (the plant only; the controller is not told).
pub trait TipPayload<const N: usize>: Manipulator<N> + Sized {
    /// The same arm with a point mass `mass` (kg, ≥ 0) at the tip of its last
    /// link. A zero mass returns the arm unchanged, bit for bit.
    fn with_payload(&self, mass: f64) -> Result<Self, Error>;
}

/// A link of mass `m` (kg), centre of mass at `c` (m) from its proximal
/// joint and inertia `i` (kg m²) about it, with a point mass `mp` (kg) added
/// at distance `l` (m) on its axis: the combined mass, centre of mass and
/// inertia about that centre (parallel-axis theorem, SPEC §17).
fn add_point_mass(m: f64, c: f64, i: f64, mp: f64, l: f64) -> (f64, f64, f64) {
    let mass = m + mp;
    let com = (m * c + mp * l) / mass;
    let inertia = i + m * (c - com) * (c - com) + mp * (l - com) * (l - com);
    (mass, com, inertia)
}

fn check_payload(mass: f64) -> Result<(), Error> {
    check::nonnegative("payload ≥ 0", "payload", mass)?;
    check::at_most("|value| ≤ 1e9", "payload", mass, PARAM_BOUND)
}

impl TipPayload<2> for TwoLinkArm {
    fn with_payload(&self, mass: f64) -> Result<Self, Error> {
        check_payload(mass)?;
        if mass == 0.0 {
            return Ok(*self);
        }
        let a = *self.params();
        let (m2, lc2, i2) = add_point_mass(a.m2, a.lc2, a.i2, mass, a.l2);
        TwoLinkArm::new(ArmParams { m2, lc2, i2, ..a })
    }
}

impl<const N: usize> TipPayload<N> for PlanarArm<N> {
    fn with_payload(&self, mass: f64) -> Result<Self, Error> {
        check_payload(mass)?;
        let mut links = *self.links();
        let Some(last) = links.last_mut() else {
            return Ok(*self);
        };
        if mass == 0.0 {
            return Ok(*self);
        }
        let (m, com, inertia) =
            add_point_mass(last.mass, last.com, last.inertia, mass, last.length);
        *last = Link {
            mass: m,
            com,
            inertia,
            length: last.length,
        };
        PlanarArm::new(links, self.g())
    }
}

/// The validated disturbances of a run (immutable; see the [module docs](self)).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Disturbances<const N: usize> {
    params: DisturbanceParams<N>,
    friction: Friction<N>,
    /// ρ∘τmax (N m).
    delivered: Vector<N>,
    noisy: bool,
    weak: bool,
}

impl<const N: usize> Default for Disturbances<N> {
    fn default() -> Self {
        Self::none()
    }
}

impl<const N: usize> Disturbances<N> {
    /// No disturbance: a run with it is bit for bit a run without.
    pub fn none() -> Self {
        Self {
            params: DisturbanceParams::default(),
            friction: Friction::none(),
            delivered: Vector::from_element(f64::INFINITY),
            noisy: false,
            weak: false,
        }
    }

    /// `params`, validated (each condition named as in the schema), for
    /// actuators rated `tau_max` (N m, > 0: the limits ρ applies to).
    pub fn new(params: DisturbanceParams<N>, tau_max: Vector<N>) -> Result<Self, Error> {
        let p = &params;
        check_payload(p.payload)?;
        for (what, v) in [
            ("noise_q", &p.noise_q),
            ("noise_dq", &p.noise_dq),
            ("noise_tau_e", &p.noise_tau_e),
        ] {
            check::nonnegative_vec("noise ≥ 0", what, v)?;
            check::at_most("|value| ≤ 1e9", what, v.amax(), PARAM_BOUND)?;
        }
        if p.delay > MAX_DELAY {
            return Err(Error::Condition {
                condition: "0 ≤ delay ≤ 64",
                lhs: "delay",
                index: None,
                value: p.delay as f64,
            });
        }
        check::nonnegative("0 ≤ jitter < 1", "jitter", p.jitter)?;
        if p.jitter >= 1.0 {
            return Err(Error::Condition {
                condition: "0 ≤ jitter < 1",
                lhs: "jitter",
                index: None,
                value: p.jitter,
            });
        }
        let friction = Friction::new(p.friction_viscous, p.friction_coulomb, p.friction_vs)?;
        let rho = &p.actuator_fraction;
        check::finite_slice("actuator_fraction", rho.as_slice())?;
        if let Some(i) = rho.iter().position(|r| !(*r > 0.0 && *r <= 1.0)) {
            return Err(Error::Condition {
                condition: "0 < ρ ≤ 1",
                lhs: "actuator_fraction",
                index: Some(i),
                value: rho[i],
            });
        }
        let weak = rho.iter().any(|r| *r < 1.0);
        if weak {
            check::positive_vec("τmax > 0", "tau_max", &tau_max)?;
        }
        let noisy = [p.noise_q, p.noise_dq, p.noise_tau_e]
            .iter()
            .any(|v| v.iter().any(|s| *s > 0.0));
        Ok(Self {
            params,
            friction,
            delivered: rho.component_mul(&tau_max),
            noisy,
            weak,
        })
    }

    /// The numbers.
    pub fn params(&self) -> &DisturbanceParams<N> {
        &self.params
    }
    /// The payload (kg).
    pub fn payload(&self) -> f64 {
        self.params.payload
    }
    /// The joint friction of the plant.
    pub fn friction(&self) -> &Friction<N> {
        &self.friction
    }
    /// True if nothing is disturbed.
    pub fn is_none(&self) -> bool {
        self.params.payload == 0.0 && self.friction.zero && self.is_clean_loop()
    }
    /// True if the loop itself is undisturbed (no noise, delay, jitter or
    /// weak actuator): only the plant, if anything, differs.
    fn is_clean_loop(&self) -> bool {
        !self.noisy && self.params.delay == 0 && self.params.jitter == 0.0 && !self.weak
    }

    /// A fresh state for one run: the generators seeded from `seed`, the
    /// delay line empty.
    pub fn new_state(&self) -> DisturbanceState<N> {
        let noise = Xoshiro256PlusPlus::seed_from_u64(self.params.seed);
        let mut jitter = noise.clone();
        jitter.long_jump();
        let zero = Vector::zeros();
        DisturbanceState {
            noise,
            jitter,
            line: [(zero, zero, zero); MAX_DELAY + 1],
            wrenches: [[0.0; 6]; MAX_DELAY + 1],
            truths: [zero; MAX_DELAY + 1],
            k: 0,
        }
    }

    /// What the controller sees at the current step from the sensors' true
    /// `sample`: the sample plus noise, n_i ~ N(0, σ_i²), entered into the
    /// delay line; out comes the noisy sample of step k − d (of step 0 while
    /// k < d: the first sample is held until the line fills). Call once per
    /// step, in order.
    pub fn measure(&self, state: &mut DisturbanceState<N>, sample: Sample<N>) -> Sample<N> {
        self.measure_with_wrench(state, sample, [0.0; 6]).0
    }

    /// [`measure`](Self::measure) with the end effector's wrench F_e = [f; m]
    /// (N, N m) as a force/torque sensor delivers it (what a Cartesian
    /// controller reads instead of τe): it goes through the same delay line,
    /// so the controller sees the wrench of step k − d with the joint sample
    /// of step k − d. No noise is added to it (the noise of SPEC §17 is on
    /// τe, N m per joint) and no draw is taken for it: the joint sample is
    /// exactly [`measure`](Self::measure)'s.
    pub fn measure_with_wrench(
        &self,
        state: &mut DisturbanceState<N>,
        sample: Sample<N>,
        wrench: [f64; 6],
    ) -> (Sample<N>, [f64; 6]) {
        let seen = self.sense(state, sample, wrench);
        (seen.sample, seen.wrench)
    }

    /// [`measure_with_wrench`](Self::measure_with_wrench) with what the loop
    /// needs besides: the step the sample was taken at (k − d, 0 while k < d)
    /// and the true joint position q of that step, before the noise. The
    /// loop gives the controller the setpoint of that step's instant and
    /// measures its tracking error against that true q (SPEC §17).
    pub fn sense(
        &self,
        state: &mut DisturbanceState<N>,
        sample: Sample<N>,
        wrench: [f64; 6],
    ) -> Seen<N> {
        let k = state.k;
        state.k = k + 1;
        if !self.noisy && self.params.delay == 0 {
            return Seen {
                sample,
                wrench,
                step: k,
                truth: sample.0,
            };
        }
        let truth = sample.0;
        let (mut q, mut dq, mut tau_e) = sample;
        if self.noisy {
            let p = &self.params;
            for (v, sd) in [
                (&mut q, &p.noise_q),
                (&mut dq, &p.noise_dq),
                (&mut tau_e, &p.noise_tau_e),
            ] {
                for i in 0..N {
                    let n: f64 = StandardNormal.sample(&mut state.noise);
                    v[i] += sd[i] * n;
                }
            }
        }
        let slots = (MAX_DELAY + 1) as u64;
        state.line[(k % slots) as usize] = (q, dq, tau_e);
        state.wrenches[(k % slots) as usize] = wrench;
        state.truths[(k % slots) as usize] = truth;
        let step = k.saturating_sub(self.params.delay as u64);
        let then = (step % slots) as usize;
        Seen {
            sample: state.line[then],
            wrench: state.wrenches[then],
            step,
            truth: state.truths[then],
        }
    }

    /// The true interval (s) between this sample and the next, for the
    /// controller's period `ts` (s): Ts (1 + u), u = j (2r − 1) with r
    /// uniform on [0, 1) at 53-bit resolution, so u ∈ [−j, j). Exactly `ts`
    /// without jitter. Call once per step, in order.
    pub fn interval(&self, state: &mut DisturbanceState<N>, ts: f64) -> f64 {
        let j = self.params.jitter;
        if j == 0.0 {
            return ts;
        }
        let r: f64 = StandardUniform.sample(&mut state.jitter);
        ts * (1.0 + j * (2.0 * r - 1.0))
    }

    /// The torque the actuators deliver for the applied command `tau` (N m):
    /// clamped to ±ρ_i τmax_i (unchanged when every ρ_i = 1).
    pub fn actuate(&self, tau: &Vector<N>) -> Vector<N> {
        if !self.weak {
            return *tau;
        }
        tau.zip_map(&self.delivered, |t, m| t.clamp(-m, m))
    }
}

/// What the controller is given at one step ([`Disturbances::sense`]).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Seen<const N: usize> {
    /// The sample as the sensors deliver it: noisy, of step `step`.
    pub sample: Sample<N>,
    /// The end effector's wrench of the same step (N, N m).
    pub wrench: [f64; 6],
    /// The step the sample was taken at: k − d (0 while k < d).
    pub step: u64,
    /// The true joint position q (rad) at that step, without the noise.
    pub truth: Vector<N>,
}

/// What a run with [`Disturbances`] changes: the noise and jitter generators
/// and the delay line (a fixed array; `(MAX_DELAY + 1)·(4N + 6)` reals).
#[derive(Clone, Debug)]
pub struct DisturbanceState<const N: usize> {
    noise: Xoshiro256PlusPlus,
    jitter: Xoshiro256PlusPlus,
    line: [Sample<N>; MAX_DELAY + 1],
    /// The wrenches of the same samples ([`Disturbances::measure_with_wrench`]).
    wrenches: [[f64; 6]; MAX_DELAY + 1],
    /// The true joint positions of the same samples, before the noise
    /// ([`Disturbances::sense`]).
    truths: [Vector<N>; MAX_DELAY + 1],
    /// Samples taken.
    k: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params() -> DisturbanceParams<2> {
        DisturbanceParams::default()
    }
    fn tau_max() -> Vector<2> {
        Vector::<2>::new(17.0, 15.0)
    }

    #[test]
    fn default_is_none() {
        let d = Disturbances::new(params(), tau_max()).unwrap();
        assert!(d.is_none());
        assert!(Disturbances::<2>::none().is_none());
        let mut s = d.new_state();
        let x = (
            Vector::<2>::new(0.1, -0.0),
            Vector::<2>::new(-0.0, 2.0),
            Vector::<2>::new(3.0, 0.0),
        );
        assert_eq!(d.measure(&mut s, x), x);
        assert_eq!(d.interval(&mut s, 1e-3), 1e-3);
        let t = Vector::<2>::new(-17.0, 15.0);
        assert_eq!(d.actuate(&t), t);
    }

    #[test]
    fn every_condition_is_named() {
        let bad = |p: DisturbanceParams<2>, condition: &str| {
            let e = Disturbances::new(p, tau_max()).unwrap_err();
            assert!(e.to_string().contains(condition), "{e} lacks {condition}");
        };
        let d = params();
        bad(DisturbanceParams { payload: -1.0, ..d }, "payload ≥ 0");
        bad(
            DisturbanceParams {
                noise_dq: Vector::<2>::new(0.0, -1e-3),
                ..d
            },
            "noise ≥ 0",
        );
        bad(DisturbanceParams { delay: 65, ..d }, "0 ≤ delay ≤ 64");
        bad(DisturbanceParams { jitter: 1.0, ..d }, "0 ≤ jitter < 1");
        bad(DisturbanceParams { jitter: -0.1, ..d }, "0 ≤ jitter < 1");
        bad(
            DisturbanceParams {
                friction_viscous: Vector::<2>::new(-1.0, 0.0),
                ..d
            },
            "b ≥ 0",
        );
        bad(
            DisturbanceParams {
                friction_coulomb: Vector::<2>::new(0.0, -1.0),
                ..d
            },
            "fc ≥ 0",
        );
        bad(
            DisturbanceParams {
                friction_vs: 0.0,
                ..d
            },
            "v_s > 0",
        );
        for rho in [0.0, 1.5, -0.5] {
            bad(
                DisturbanceParams {
                    actuator_fraction: Vector::<2>::new(1.0, rho),
                    ..d
                },
                "0 < ρ ≤ 1",
            );
        }
        let e = Disturbances::new(
            DisturbanceParams {
                jitter: f64::NAN,
                ..d
            },
            tau_max(),
        )
        .unwrap_err();
        assert_eq!(
            e,
            Error::NonFinite {
                what: "jitter",
                index: 0
            }
        );
        assert!(Disturbances::new(DisturbanceParams { delay: 64, ..d }, tau_max()).is_ok());
    }

    #[test]
    fn delay_line_returns_the_sample_of_k_minus_d() {
        for d in [0, 1, 3, MAX_DELAY] {
            let dist = Disturbances::new(
                DisturbanceParams {
                    delay: d,
                    ..params()
                },
                tau_max(),
            )
            .unwrap();
            let mut s = dist.new_state();
            let sample = |k: usize| {
                let v = Vector::<2>::new(k as f64, -(k as f64));
                (v, 2.0 * v, 3.0 * v)
            };
            for k in 0..500 {
                assert_eq!(
                    dist.measure(&mut s, sample(k)),
                    sample(k.saturating_sub(d)),
                    "d = {d}, k = {k}"
                );
            }
        }
    }

    #[test]
    fn noise_is_seeded_and_its_standard_deviation_is_as_given() {
        let make = |seed| {
            Disturbances::new(
                DisturbanceParams {
                    noise_q: Vector::<2>::new(1e-3, 2e-3),
                    noise_dq: Vector::<2>::new(0.1, 0.0),
                    noise_tau_e: Vector::<2>::new(0.5, 0.5),
                    seed,
                    ..params()
                },
                tau_max(),
            )
            .unwrap()
        };
        let draw = |d: &Disturbances<2>| {
            let mut s = d.new_state();
            let zero = Vector::<2>::zeros();
            (0..20_000)
                .map(|_| d.measure(&mut s, (zero, zero, zero)))
                .collect::<alloc::vec::Vec<_>>()
        };
        let a = draw(&make(7));
        assert_eq!(a, draw(&make(7)), "same seed, same noise");
        assert_ne!(a, draw(&make(8)), "another seed, other noise");
        let stats = |f: &dyn Fn(&Sample<2>) -> f64| {
            let n = a.len() as f64;
            let mean = a.iter().map(f).sum::<f64>() / n;
            let var = a.iter().map(|x| (f(x) - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (mean, var.sqrt())
        };
        // 20 000 samples: the sample std is within ~0.5 % of σ (1 σ); 2 % is
        // four of those, for this fixed seed a deterministic pass.
        for (f, sd) in [
            (
                &(|x: &Sample<2>| x.0[0]) as &dyn Fn(&Sample<2>) -> f64,
                1e-3,
            ),
            (&|x: &Sample<2>| x.0[1], 2e-3),
            (&|x: &Sample<2>| x.1[0], 0.1),
            (&|x: &Sample<2>| x.2[1], 0.5),
        ] {
            let (mean, std) = stats(f);
            assert!((std / sd - 1.0).abs() < 0.02, "std {std} vs {sd}");
            assert!(
                mean.abs() < 4.0 * sd / (a.len() as f64).sqrt(),
                "mean {mean}"
            );
        }
        // A channel with σ = 0 stays exact.
        assert!(a.iter().all(|x| x.1[1] == 0.0));
    }

    #[test]
    fn jitter_intervals_stay_within_their_band_and_average_ts() {
        let d = Disturbances::new(
            DisturbanceParams {
                jitter: 0.2,
                seed: 3,
                ..params()
            },
            tau_max(),
        )
        .unwrap();
        let mut s = d.new_state();
        let ts = 1e-3;
        let h: alloc::vec::Vec<f64> = (0..10_000).map(|_| d.interval(&mut s, ts)).collect();
        assert!(h.iter().all(|h| (0.8 * ts..1.2 * ts).contains(h)));
        let mean = h.iter().sum::<f64>() / h.len() as f64;
        // u ~ U[−0.2, 0.2): std 0.115, so the mean of 10⁴ is within 0.5 % of Ts (4 σ).
        assert!((mean / ts - 1.0).abs() < 5e-3, "{mean}");
        assert!(h.iter().any(|h| *h < 0.81 * ts) && h.iter().any(|h| *h > 1.19 * ts));
    }

    #[test]
    fn weak_actuators_deliver_at_most_rho_tau_max() {
        let d = Disturbances::new(
            DisturbanceParams {
                actuator_fraction: Vector::<2>::new(0.5, 0.25),
                ..params()
            },
            tau_max(),
        )
        .unwrap();
        let t = d.actuate(&Vector::<2>::new(17.0, -15.0));
        assert_eq!(t, Vector::<2>::new(8.5, -3.75));
        let t = d.actuate(&Vector::<2>::new(1.0, -2.0));
        assert_eq!(t, Vector::<2>::new(1.0, -2.0));
    }

    #[test]
    fn friction_opposes_motion() {
        let f =
            Friction::new(Vector::<2>::new(0.1, 0.2), Vector::<2>::new(0.5, 0.3), 0.01).unwrap();
        for v in [-3.0, -0.004, 0.0, 1e-3, 2.0] {
            let dq = Vector::<2>::new(v, -v);
            let t = f.torque(&dq);
            assert!(dq.dot(&t) <= 0.0);
            assert!(t.iter().all(|x| x.is_finite()));
        }
        // Far beyond v_s: b q̇ + fc (tanh(200) rounds to 1).
        let t = f.torque(&Vector::<2>::new(2.0, 0.0));
        assert_eq!(t[0], -(0.1 * 2.0 + 0.5));
        assert_eq!(f.torque(&Vector::<2>::zeros()), Vector::<2>::zeros());
    }

    #[test]
    fn payload_adds_m_g_lever_to_gravity() {
        let arm = TwoLinkArm::paper();
        let a = *arm.params();
        let mp = 0.5;
        let loaded = arm.with_payload(mp).unwrap();
        for q in [Vector::<2>::zeros(), Vector::<2>::new(0.3, -1.1)] {
            let dg = loaded.gravity(&q) - arm.gravity(&q);
            let c1 = q[0].cos();
            let c12 = (q[0] + q[1]).cos();
            let expect =
                Vector::<2>::new(mp * a.g * (a.l1 * c1 + a.l2 * c12), mp * a.g * a.l2 * c12);
            assert!((dg - expect).norm() < 1e-12, "{dg} vs {expect}");
        }
        // The inertia about the joints gains mp |r_tip|², and the rest stays.
        let q = Vector::<2>::new(0.0, 0.0);
        let dd = loaded.inertia(&q) - arm.inertia(&q);
        let r = a.l1 + a.l2;
        assert!((dd[(0, 0)] - mp * r * r).abs() < 1e-12, "{dd}");
        assert!((dd[(1, 1)] - mp * a.l2 * a.l2).abs() < 1e-12, "{dd}");
        assert_eq!(arm.with_payload(0.0).unwrap(), arm);
        assert!(arm.with_payload(-0.1).is_err());
    }

    #[test]
    fn planar_payload_matches_the_two_link_one() {
        let a = *TwoLinkArm::paper().params();
        let links = [
            Link {
                mass: a.m1,
                length: a.l1,
                com: a.lc1,
                inertia: a.i1,
            },
            Link {
                mass: a.m2,
                length: a.l2,
                com: a.lc2,
                inertia: a.i2,
            },
        ];
        let planar = PlanarArm::new(links, a.g)
            .unwrap()
            .with_payload(0.7)
            .unwrap();
        let two = TwoLinkArm::paper().with_payload(0.7).unwrap();
        let q = Vector::<2>::new(0.4, 0.9);
        assert!((planar.gravity(&q) - two.gravity(&q)).norm() < 1e-12);
        assert!((planar.inertia(&q) - two.inertia(&q)).norm() < 1e-12);
    }
}
