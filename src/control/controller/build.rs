//! A controller built and read: its validation against SPEC §10 (the
//! stability and magnitude conditions), its accessors, and its states (on
//! the heap or in a caller's buffer).

use super::*;

impl<const N: usize, B: Basis<N>> Controller<N, B> {
    /// Validate `cfg` against every condition of SPEC §10 and build the
    /// controller with basis `basis`. The error names the condition and the
    /// value. A [`WeightBound::Auto`] needs the trajectory: use
    /// [`for_trajectory`](Self::for_trajectory).
    ///
    /// The weight pass's instruction set is chosen here, once
    /// ([`SimdPath::detect`]): AVX2 and FMA if the CPU has them (x86-64-v3,
    /// no build flag needed), the portable path otherwise. With `std`, the
    /// environment variable `ADAPTIMP_SIMD=portable` forces the portable path
    /// (e.g. to compare the two); [`simd`](Self::simd) tells which was taken
    /// and [`with_simd`](Self::with_simd) changes it. Both give the same
    /// results.
    pub fn new(cfg: Config<N>, basis: B) -> Result<Self, Error> {
        if N == 0 || basis.nodes() == 0 {
            return Err(Error::Invalid {
                what: "controller",
                reason: "needs at least one joint and one RBF node",
            });
        }
        check::positive("Ts > 0", "Ts", cfg.ts)?;
        check::positive_vec("K1 > 0", "K1", &cfg.k1)?;
        Self::check_stability(&cfg)?;
        Self::check_magnitudes(&cfg)?;
        check::nonnegative_vec("Kd ≥ 0", "fallback_damping", &cfg.fallback_damping)?;
        cfg.limits.validate()?;
        let robust = Robust::from_config(cfg.robust, cfg.kr, cfg.phi, [cfg.kd, cfg.kc, cfg.kg]);
        robust.validate()?;
        let bound = match cfg.weight_bound {
            WeightBound::None => None,
            WeightBound::Fixed(b) => Some(b),
            WeightBound::Auto => {
                return Err(Error::Invalid {
                    what: "weight_bound = auto",
                    reason: "derives from the commanded trajectory: build with Controller::for_trajectory, or give fixed bounds",
                })
            }
        };
        let obs = HighGainObserver::new(cfg.eps, cfg.lam1, cfg.ts, cfg.observer_hold)?;
        let lead = (cfg.law == Law::OutputFeedback && cfg.observer_lead).then(|| *obs.lag());
        // SPEC (18.12): the inertia-shaped gains, checked and made once.
        let coupling = match &cfg.inertia_matrix {
            Some(m) => Some(Coupling::new(m, &cfg)?),
            None => None,
        };
        Ok(Self {
            sat: Saturation::new(cfg.tau_max)?,
            imp: TargetImpedance::new(cfg.dd, cfg.cd, cfg.gd)?,
            aux: Auxiliary::weighted(cfg.kzeta, cfg.mu, cfg.aux_law, cfg.inertia, cfg.rho)?,
            obs,
            lead,
            learning: Learning::new(
                cfg.ts,
                cfg.gamma,
                cfg.sigma,
                cfg.learning_step,
                cfg.kappa,
                cfg.saturation_learning,
                bound,
                // min_k Kp_k/d_k (1/s; min Kp for d = 1, exactly).
                cfg.kp.component_div(&cfg.inertia).min(),
            )?,
            robust,
            cfg,
            basis,
            simd: SimdPath::detect(),
            #[cfg(feature = "alloc")]
            feedforward: None,
            coupling,
        })
    }

    /// The inertia-shaped gains of SPEC (18.12), if
    /// [`Config::inertia_matrix`] is set.
    pub fn coupling(&self) -> Option<&Coupling<N>> {
        self.coupling.as_ref()
    }

    /// This controller with `feedforward`'s torque added to the law's at
    /// every step, SPEC (20.10): τ = τ_law + τ_ff(q) at the measured q, before
    /// the rate limit and the saturation (Δτ of the auxiliary system includes
    /// it). The nominal model's gravity (a `cartesian::Dynamics`) for a robot
    /// that does not compensate it itself; none (the default) for one that
    /// does, as Franka's torque interface.
    #[cfg(feature = "alloc")]
    pub fn with_feedforward(mut self, feedforward: alloc::sync::Arc<dyn Feedforward<N>>) -> Self {
        self.feedforward = Some(feedforward);
        self
    }

    /// The torque fed forward, if any ([`with_feedforward`](Self::with_feedforward)).
    #[cfg(feature = "alloc")]
    pub fn feedforward(&self) -> Option<&dyn Feedforward<N>> {
        self.feedforward.as_deref()
    }

    /// The stability conditions of SPEC §10 that [`Config::conditions`]
    /// names: the paper's (13), or the inertia-scaled (10.3).
    pub(super) fn check_stability(cfg: &Config<N>) -> Result<(), Error> {
        check::finite_slice("Kp", cfg.kp.as_slice())?;
        check::finite_slice("Kzeta", cfg.kzeta.as_slice())?;
        check::finite_slice("inertia", cfg.inertia.as_slice())?;
        if let Some(i) = cfg.inertia.iter().position(|d| *d < MIN_SCALE) {
            return Err(Error::Condition {
                condition: "d ≥ 1e-9",
                lhs: "inertia",
                index: Some(i),
                value: cfg.inertia[i],
            });
        }
        check::finite("rho", cfg.rho)?;
        if cfg.rho < MIN_SCALE {
            return Err(Error::Condition {
                condition: "ρ ≥ 1e-9",
                lhs: "rho",
                index: None,
                value: cfg.rho,
            });
        }
        match cfg.conditions {
            Conditions::Paper => {
                // (13) is proved with the paper's unit weights only (SPEC §10).
                if cfg.inertia.iter().any(|d| *d != 1.0) || cfg.rho != 1.0 {
                    return Err(Error::Invalid {
                        what: "conditions = paper",
                        reason: "(13) is proved for the paper's unit weights (inertia = 1, rho = 1): use conditions = scaled",
                    });
                }
                check::each(
                    "2Kp − I > 0",
                    "2·Kp − 1",
                    &cfg.kp,
                    |_, kp| 2.0 * kp - 1.0,
                    true,
                )?;
                check::each(
                    "2Kζ − I − KpᵀKp > 0",
                    "2·Kzeta − 1 − Kp²",
                    &cfg.kzeta,
                    |i, kz| 2.0 * kz - 1.0 - cfg.kp[i] * cfg.kp[i],
                    true,
                )
            }
            Conditions::Scaled => {
                check::each("Kp > 0", "Kp", &cfg.kp, |_, kp| kp, true)?;
                check::each(
                    "2Kζ − ρ − Kp/d > 0",
                    "2·Kzeta − rho − Kp/inertia",
                    &cfg.kzeta,
                    |i, kz| 2.0 * kz - cfg.rho - cfg.kp[i] / cfg.inertia[i],
                    true,
                )
            }
        }
    }

    /// Every gain and physical parameter at most [`PARAM_BOUND`] (1e9) in
    /// magnitude: the stability conditions of SPEC §10 accept, e.g., K1 = 1e300,
    /// which then overflows within two steps.
    pub(super) fn check_magnitudes(cfg: &Config<N>) -> Result<(), Error> {
        let vectors = [
            ("K1", &cfg.k1),
            ("Kp", &cfg.kp),
            ("Kzeta", &cfg.kzeta),
            ("inertia", &cfg.inertia),
            ("kr", &cfg.kr),
            ("lam1", &cfg.lam1),
            ("tau_max", &cfg.tau_max),
            ("Dd", &cfg.dd),
            ("Cd", &cfg.cd),
            ("Gd", &cfg.gd),
            ("fallback_damping", &cfg.fallback_damping),
        ];
        for (what, v) in vectors {
            check::at_most_each("|value| ≤ 1e9", what, v.as_slice(), PARAM_BOUND)?;
        }
        let scalars = [
            ("mu", cfg.mu),
            ("rho", cfg.rho),
            ("phi", cfg.phi),
            ("kD", cfg.kd),
            ("kC", cfg.kc),
            ("kG", cfg.kg),
            ("kappa", cfg.kappa),
            ("eps", cfg.eps),
            ("gamma", cfg.gamma[0]),
            ("gamma", cfg.gamma[1]),
            ("gamma", cfg.gamma[2]),
            ("sigma", cfg.sigma[0]),
            ("sigma", cfg.sigma[1]),
            ("sigma", cfg.sigma[2]),
        ];
        for (what, x) in scalars {
            check::at_most("|value| ≤ 1e9", what, x, PARAM_BOUND)?;
        }
        check::at_most(
            "0 ≤ delay ≤ 64",
            "delay",
            cfg.delay as f64,
            MAX_DELAY as f64,
        )?;
        check::at_most("Ts ≤ 1 s", "Ts", cfg.ts, 1.0)
    }

    /// As [`new`](Self::new), with a [`WeightBound::Auto`] resolved for the
    /// trajectory `traj` the controller will track (its
    /// [`peak_rates`](Trajectory::peak_rates)).
    pub fn for_trajectory<T: Trajectory<N> + ?Sized>(
        cfg: Config<N>,
        basis: B,
        traj: &T,
    ) -> Result<Self, Error> {
        let cfg = match (cfg.weight_bound, traj.peak_rates()) {
            (WeightBound::Auto, Some(rates)) => cfg.resolve(basis.nodes(), rates),
            (WeightBound::Auto, None) => {
                return Err(Error::Invalid {
                    what: "weight_bound = auto",
                    reason: "the trajectory does not know its peak speed and acceleration: give fixed bounds",
                })
            }
            _ => cfg,
        };
        Self::new(cfg, basis)
    }

    /// The validated configuration.
    pub fn config(&self) -> &Config<N> {
        &self.cfg
    }
    /// The RBF basis.
    pub fn basis(&self) -> &B {
        &self.basis
    }
    /// The actuator model the controller saturates with.
    pub fn saturation(&self) -> &Saturation<N> {
        &self.sat
    }
    /// The target impedance.
    pub fn impedance(&self) -> &TargetImpedance<N> {
        &self.imp
    }
    /// The high-gain observer (output feedback).
    pub fn observer(&self) -> &HighGainObserver<N> {
        &self.obs
    }
    /// The robust term.
    pub fn robust(&self) -> &Robust<N> {
        &self.robust
    }
    /// The learning policy.
    pub fn learning(&self) -> &Learning {
        &self.learning
    }
    /// The instruction set of the weight pass: `simd().name()` is
    /// `"avx2-fma"` or `"portable"` (see [`new`](Self::new)).
    pub fn simd(&self) -> SimdPath {
        self.simd
    }
    /// The same controller with the weight pass on `path`, e.g.
    /// [`SimdPath::portable`]. A fast path can only come from detection
    /// ([`SimdPath::fastest`]), so this never asks for instructions the CPU
    /// lacks.
    pub fn with_simd(mut self, path: SimdPath) -> Self {
        self.simd = path;
        self
    }
    /// Sampling period Ts (s).
    pub fn period(&self) -> f64 {
        self.cfg.ts
    }

    /// The length (in f64) of the buffer a state of this controller needs.
    pub fn buffer_len(&self) -> usize {
        crate::networks::network::Layout::buffer_len(N, self.basis.nodes()).unwrap_or(usize::MAX)
    }

    /// A state at t = 0 in the caller's buffer `buf` (at least
    /// [`buffer_len`](Self::buffer_len) reals, zeroed here): for firmware
    /// without an allocator, or to place the state yourself.
    pub fn state_in<S: AsRef<[f64]> + AsMut<[f64]>>(&self, buf: S) -> Result<State<N, S>, Error> {
        State::new_in(self.basis.nodes(), buf)
    }

    /// A state at t = 0 on the heap (its buffer allocated zeroed, never built
    /// on the stack).
    #[cfg(feature = "alloc")]
    pub fn new_state(&self) -> crate::control::state::HeapState<N> {
        // The buffer is allocated zeroed; `new_in` only fails if it is short.
        State::new_in(self.basis.nodes(), alloc::vec![0.0; self.buffer_len()])
            .unwrap_or_else(|e| unreachable!("the buffer has buffer_len(): {e}"))
    }

    /// Time t_k = k·Ts (s) of `state`'s next step.
    pub fn time<S>(&self, state: &State<N, S>) -> f64 {
        state.k as f64 * self.cfg.ts
    }

    /// The observer's current velocity estimate π2/ε (rad/s) in `state`.
    pub fn velocity_estimate<S>(&self, state: &State<N, S>) -> Vector<N> {
        self.obs.estimate(&state.observer)
    }

    /// This controller driving `state`, as a [`Control`] for a closed loop.
    pub fn bind<'a, S>(&'a self, state: &'a mut State<N, S>) -> Bound<'a, N, B, S> {
        Bound { ctrl: self, state }
    }
}
