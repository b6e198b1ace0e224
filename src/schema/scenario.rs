//! A scenario's values: every parameter of [`PARAMS`] at once, set and read
//! by name ([`Scenario`]), with the arm's ([`ArmValues`]).

use super::*;

/// The arm's parameters with the derived ones (centres of mass, inertias)
/// left open: `None` takes the default derived from mass and length.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct ArmValues {
    /// m1, m2 (kg), l1, l2 (m), g (m/s²).
    pub m: [f64; 2],
    /// Link lengths (m).
    pub l: [f64; 2],
    /// Centres of mass (m); `None`: l/2.
    pub lc: [Option<f64>; 2],
    /// Inertias about the centres (kg m²); `None`: m l²/4.
    pub inertia: [Option<f64>; 2],
    /// Gravitational acceleration (m/s²).
    pub g: f64,
}

impl ArmValues {
    /// The arm's parameters, with the derived ones filled in (SPEC §1).
    #[cfg(feature = "sim")]
    pub fn resolve(&self) -> ArmParams {
        let lc = |i: usize| self.lc[i].unwrap_or(self.l[i] / 2.0);
        let inertia = |i: usize| self.inertia[i].unwrap_or(self.m[i] * self.l[i] * self.l[i] / 4.0);
        ArmParams {
            m1: self.m[0],
            m2: self.m[1],
            l1: self.l[0],
            l2: self.l[1],
            lc1: lc(0),
            lc2: lc(1),
            i1: inertia(0),
            i2: inertia(1),
            g: self.g,
        }
    }
}

/// Every parameter of a scenario at once: the controller's configuration,
/// its basis width and trajectory, the run, the wall and the arm. Built from
/// a [`Preset`] and changed by name with [`set`](Self::set); validated by the
/// constructors it feeds.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Scenario<const N: usize> {
    /// The controller's configuration.
    pub config: Config<N>,
    /// The run (feature `sim`).
    #[cfg(feature = "sim")]
    pub sim: SimConfig<N>,
    /// The disturbances of the run (SPEC §17; feature `sim`).
    #[cfg(feature = "sim")]
    pub disturb: DisturbanceParams<N>,
    /// η² of the vertex grid.
    pub eta2: f64,
    /// The commanded sinusoid: offset, sine and cosine amplitudes (rad), ω (rad/s).
    pub xc: [Vector<N>; 4],
    /// The wall position (rad), or free space.
    pub wall: Option<f64>,
    /// Wall stiffness (N m/rad) and damping (N m s/rad).
    pub ke_be: [f64; 2],
    /// The 2-link arm.
    pub arm: ArmValues,
    /// The 6-D Cartesian impedance (SPEC §16).
    pub cartesian: CartesianConfig,
}

/// A lookup that cannot fail: `name` is in [`PARAMS`] and its default suits
/// `N` (tested for N = 1 … 7).
pub(crate) fn preset_error(name: &str, e: Error) -> ! {
    unreachable!("the schema's default of {name} applies: {e}")
}

impl<const N: usize> Scenario<N> {
    /// Every default of `preset` for the controller `law`. Per-joint defaults
    /// given as one value per joint of the 2-link arm (q0, τmax, the paper's
    /// circle) apply to N = 2; for other N, give them yourself (they start at
    /// the first value, broadcast).
    pub fn preset(preset: Preset, law: Law) -> Self {
        let zero = Vector::<N>::zeros();
        let mut s = Self {
            config: Config::zeroed(law),
            #[cfg(feature = "sim")]
            sim: SimConfig {
                t_final: 0.0,
                substeps: 0,
                q0: zero,
                dq0: zero,
                settle: 0.0,
            },
            #[cfg(feature = "sim")]
            disturb: DisturbanceParams::default(),
            eta2: 0.0,
            xc: [zero; 4],
            wall: None,
            ke_be: [0.0; 2],
            arm: ArmValues {
                m: [0.0; 2],
                l: [0.0; 2],
                lc: [None; 2],
                inertia: [None; 2],
                g: 0.0,
            },
            cartesian: CartesianConfig {
                md: Vector::zeros(),
                bd: None,
                kd: Vector::zeros(),
                md_rot: Vector::zeros(),
                bd_rot: None,
                kd_rot: Vector::zeros(),
                clik_kp: 0.0,
                clik_kd: 0.0,
                clik_lambda: 0.0,
                clik_lambda_rot: 0.0,
                null_k: 0.0,
                null_d: 0.0,
                pos_error_max: None,
                rot_error_max: None,
                target_filter: 0.0,
                force_filter: 0.0,
                force_feedforward: false,
                formulation: Formulation::Admittance,
                admittance_share: 0.0,
            },
        };
        for p in PARAMS {
            if !cfg!(feature = "sim") && p.group == Group::Sim {
                continue; // the run's parameters need the feature `sim`
            }
            let v = match p.default_in(preset) {
                // A per-joint default for another number of joints: broadcast its first value.
                Value::Vec(v) if p.kind == Kind::Joint && v.len() != N => Value::Real(v[0]),
                v => v,
            };
            if let Err(e) = s.set(p.name, v) {
                preset_error(p.name, e)
            }
        }
        s
    }

    /// Set parameter `name` to `value`. Errors (naming the parameter) for an
    /// unknown name, a value of the wrong kind or length, or an unknown
    /// choice; the conditions of SPEC §10 are checked by the constructors.
    pub fn set(&mut self, name: &str, value: Value<'_>) -> Result<(), Error> {
        let p = param(name).ok_or(Error::Invalid {
            what: "parameter",
            reason: "unknown name (see adaptimp::schema::PARAMS)",
        })?;
        let n = p.name;
        let c = &mut self.config;
        match n {
            _ if p.group == Group::Sim => return self.set_run(n, value),
            _ if p.group == Group::Cartesian => return self.set_cartesian(n, value),
            "Ts" => c.ts = real(n, value)?,
            "delay" => c.delay = delay(n, value, "0 ≤ delay ≤ 64")?,
            "K1" => c.k1 = joint(n, value)?,
            "Kp" => c.kp = joint(n, value)?,
            "Kzeta" => c.kzeta = joint(n, value)?,
            "inertia" => c.inertia = joint(n, value)?,
            "inertia_matrix" => c.inertia_matrix = matrix(n, value)?,
            "rho" => c.rho = real(n, value)?,
            "conditions" => c.conditions = choice(p, value, &Conditions::ALL)?,
            "mu" => c.mu = real(n, value)?,
            "aux_law" => c.aux_law = choice(p, value, &AuxLaw::ALL)?,
            "robust" => c.robust = choice(p, value, &RobustKind::ALL)?,
            "kr" => c.kr = joint(n, value)?,
            "phi" => c.phi = real(n, value)?,
            "kD" => c.kd = real(n, value)?,
            "kC" => c.kc = real(n, value)?,
            "kG" => c.kg = real(n, value)?,
            "gamma" => c.gamma = network(n, value)?,
            "sigma" => c.sigma = network(n, value)?,
            "eta2" => self.eta2 = real(n, value)?,
            "eps" => c.eps = real(n, value)?,
            "lam1" => c.lam1 = joint(n, value)?,
            "observer_init" => c.observer_init = choice(p, value, &ObserverInit::ALL)?,
            "observer_hold" => c.observer_hold = choice(p, value, &Hold::ALL)?,
            "observer_lead" => c.observer_lead = flag(n, value)?,
            "tau_max" => c.tau_max = joint(n, value)?,
            "Dd" => c.dd = joint(n, value)?,
            "Cd" => c.cd = joint(n, value)?,
            "Gd" => c.gd = joint(n, value)?,
            "impedance" => c.impedance = choice(p, value, &ImpedanceMode::ALL)?,
            "xc_offset" => self.xc[0] = joint(n, value)?,
            "xc_sin" => self.xc[1] = joint(n, value)?,
            "xc_cos" => self.xc[2] = joint(n, value)?,
            "xc_omega" => self.xc[3] = joint(n, value)?,
            "learning_step" => c.learning_step = choice(p, value, &LearningStep::ALL)?,
            "kappa" => c.kappa = real(n, value)?,
            "saturation_learning" => {
                c.saturation_learning = choice(p, value, &SaturationLearning::ALL)?
            }
            "weight_bound" => {
                c.weight_bound = match value {
                    Value::None => WeightBound::None,
                    Value::Str("auto") => WeightBound::Auto,
                    v => WeightBound::Fixed(network(n, v)?),
                }
            }
            "fallback" => c.fallback = choice(p, value, &Fallback::ALL)?,
            "fallback_damping" => c.fallback_damping = joint(n, value)?,
            "fault_policy" => c.fault_policy = choice(p, value, &FaultPolicy::ALL)?,
            "q_max" => c.limits.q = limit(n, value)?,
            "dq_max" => c.limits.dq = limit(n, value)?,
            "tau_e_max" => c.limits.tau_e = limit(n, value)?,
            "q_jump_max" => c.limits.q_jump = limit(n, value)?,
            "tau_rate_max" => c.limits.tau_rate = limit(n, value)?,
            "wall" => self.wall = optional(n, value)?,
            "ke" => self.ke_be[0] = real(n, value)?,
            "be" => self.ke_be[1] = real(n, value)?,
            "m1" => self.arm.m[0] = real(n, value)?,
            "m2" => self.arm.m[1] = real(n, value)?,
            "l1" => self.arm.l[0] = real(n, value)?,
            "l2" => self.arm.l[1] = real(n, value)?,
            "lc1" => self.arm.lc[0] = optional(n, value)?,
            "lc2" => self.arm.lc[1] = optional(n, value)?,
            "I1" => self.arm.inertia[0] = optional(n, value)?,
            "I2" => self.arm.inertia[1] = optional(n, value)?,
            "g" => self.arm.g = real(n, value)?,
            _ => unreachable!("{n} is in PARAMS but has no setter"),
        }
        Ok(())
    }

    /// [`set`](Self::set) for a parameter of the run (group "sim").
    #[cfg(feature = "sim")]
    fn set_run(&mut self, n: &'static str, value: Value<'_>) -> Result<(), Error> {
        match n {
            "T" => self.sim.t_final = real(n, value)?,
            "substeps" => {
                let v = int(n, value)?;
                self.sim.substeps = usize::try_from(v).map_err(|_| Error::Condition {
                    condition: "1 ≤ substeps ≤ 10 000",
                    lhs: "substeps",
                    index: None,
                    value: v as f64,
                })?
            }
            "q0" => self.sim.q0 = joint(n, value)?,
            "dq0" => self.sim.dq0 = joint(n, value)?,
            "settle" => self.sim.settle = real(n, value)?,
            "payload" => self.disturb.payload = real(n, value)?,
            "noise_q" => self.disturb.noise_q = joint(n, value)?,
            "noise_dq" => self.disturb.noise_dq = joint(n, value)?,
            "noise_tau_e" => self.disturb.noise_tau_e = joint(n, value)?,
            "seed" => {
                let v = int(n, value)?;
                self.disturb.seed = u64::try_from(v).map_err(|_| Error::Condition {
                    condition: "seed ≥ 0",
                    lhs: "seed",
                    index: None,
                    value: v as f64,
                })?
            }
            "plant_delay" => self.disturb.delay = delay(n, value, "0 ≤ plant_delay ≤ 64")?,
            "jitter" => self.disturb.jitter = real(n, value)?,
            "friction_viscous" => self.disturb.friction_viscous = joint(n, value)?,
            "friction_coulomb" => self.disturb.friction_coulomb = joint(n, value)?,
            "friction_vs" => self.disturb.friction_vs = real(n, value)?,
            "actuator_fraction" => self.disturb.actuator_fraction = joint(n, value)?,
            _ => unreachable!("{n} is in PARAMS but has no setter"),
        }
        Ok(())
    }

    /// [`set`](Self::set) for a parameter of the Cartesian impedance (group "cartesian").
    fn set_cartesian(&mut self, n: &'static str, value: Value<'_>) -> Result<(), Error> {
        let c = &mut self.cartesian;
        let p = param(n).ok_or(Error::Invalid {
            what: "parameter",
            reason: "unknown name (see adaptimp::schema::PARAMS)",
        })?;
        match n {
            "Md" => c.md = joint(n, value)?,
            "Bd" => c.bd = derived_axes(n, value)?,
            "Kd" => c.kd = joint(n, value)?,
            "Md_rot" => c.md_rot = joint(n, value)?,
            "Bd_rot" => c.bd_rot = derived_axes(n, value)?,
            "Kd_rot" => c.kd_rot = joint(n, value)?,
            "clik_kp" => c.clik_kp = real(n, value)?,
            "clik_kd" => c.clik_kd = real(n, value)?,
            "clik_lambda" => c.clik_lambda = real(n, value)?,
            "clik_lambda_rot" => c.clik_lambda_rot = real(n, value)?,
            "null_k" => c.null_k = real(n, value)?,
            "null_d" => c.null_d = real(n, value)?,
            "pos_error_max" => c.pos_error_max = optional(n, value)?,
            "rot_error_max" => c.rot_error_max = optional(n, value)?,
            "target_filter" => c.target_filter = real(n, value)?,
            "force_filter" => c.force_filter = real(n, value)?,
            "force_feedforward" => c.force_feedforward = flag(n, value)?,
            "formulation" => c.formulation = choice(p, value, &Formulation::ALL)?,
            "admittance_share" => c.admittance_share = real(n, value)?,
            _ => unreachable!("{n} is in PARAMS but has no setter"),
        }
        Ok(())
    }

    /// Without the feature `sim` the run's parameters do not exist.
    #[cfg(not(feature = "sim"))]
    fn set_run(&mut self, n: &'static str, _value: Value<'_>) -> Result<(), Error> {
        Err(Error::Invalid {
            what: n,
            reason: "a parameter of the run: needs the feature `sim`",
        })
    }

    // A table, one line per parameter in PARAMS' order: cut in parts, it would read no better.
    /// Call `f` with every parameter's name and current value. Every field of
    /// every struct is destructured without `..`: a field added without a
    /// schema name is a compile error here.
    pub fn visit(&self, mut f: impl FnMut(&'static str, Value<'_>)) {
        let Config {
            law: _,
            ts,
            delay,
            k1,
            kp,
            kzeta,
            mu,
            inertia,
            inertia_matrix,
            rho,
            conditions,
            aux_law,
            robust,
            kr,
            phi,
            kd,
            kc,
            kg,
            learning_step,
            kappa,
            saturation_learning,
            weight_bound,
            gamma,
            sigma,
            eps,
            lam1,
            observer_init,
            observer_hold,
            observer_lead,
            tau_max,
            dd,
            cd,
            gd,
            impedance,
            fallback,
            fallback_damping,
            fault_policy,
            limits:
                Limits {
                    q: q_max,
                    dq: dq_max,
                    tau_e: tau_e_max,
                    q_jump: q_jump_max,
                    tau_rate: tau_rate_max,
                },
        } = &self.config;
        let Self {
            config: _,
            #[cfg(feature = "sim")]
                sim: _,
            #[cfg(feature = "sim")]
                disturb: _,
            eta2,
            xc: [xc_offset, xc_sin, xc_cos, xc_omega],
            wall,
            ke_be: [ke, be],
            arm:
                ArmValues {
                    m: [m1, m2],
                    l: [l1, l2],
                    lc: [lc1, lc2],
                    inertia: [i1, i2],
                    g,
                },
            cartesian: _,
        } = self;
        let opt = |v: &Option<f64>| v.map_or(Value::None, Value::Real);
        #[cfg(feature = "sim")]
        self.visit_run(&mut f);
        f("Ts", R(*ts));
        f("delay", I(*delay as i64));
        f("K1", V(k1.as_slice()));
        f("Kp", V(kp.as_slice()));
        f("Kzeta", V(kzeta.as_slice()));
        f("inertia", V(inertia.as_slice()));
        // Column-major: the row-major layout of a symmetric matrix (the
        // controller refuses another).
        f(
            "inertia_matrix",
            inertia_matrix
                .as_ref()
                .map_or(Value::None, |m| V(m.as_slice())),
        );
        f("rho", R(*rho));
        f("conditions", S(conditions.name()));
        f("mu", R(*mu));
        f("aux_law", S(aux_law.name()));
        f("robust", S(robust.name()));
        f("kr", V(kr.as_slice()));
        f("phi", R(*phi));
        f("kD", R(*kd));
        f("kC", R(*kc));
        f("kG", R(*kg));
        f("gamma", V(gamma));
        f("sigma", V(sigma));
        f("eta2", R(*eta2));
        f("eps", R(*eps));
        f("lam1", V(lam1.as_slice()));
        f("observer_init", S(observer_init.name()));
        f("observer_hold", S(observer_hold.name()));
        f("observer_lead", B(*observer_lead));
        f("tau_max", V(tau_max.as_slice()));
        f("Dd", V(dd.as_slice()));
        f("Cd", V(cd.as_slice()));
        f("Gd", V(gd.as_slice()));
        f("impedance", S(impedance.name()));
        f("xc_offset", V(xc_offset.as_slice()));
        f("xc_sin", V(xc_sin.as_slice()));
        f("xc_cos", V(xc_cos.as_slice()));
        f("xc_omega", V(xc_omega.as_slice()));
        f("learning_step", S(learning_step.name()));
        f("kappa", R(*kappa));
        f("saturation_learning", S(saturation_learning.name()));
        match weight_bound {
            WeightBound::None => f("weight_bound", Nil),
            WeightBound::Auto => f("weight_bound", S("auto")),
            WeightBound::Fixed(b) => f("weight_bound", V(b)),
        }
        f("fallback", S(fallback.name()));
        f("fallback_damping", V(fallback_damping.as_slice()));
        f("fault_policy", S(fault_policy.name()));
        fn lim<const N: usize>(v: &Vector<N>) -> Value<'_> {
            if v.iter().all(|x| *x == f64::INFINITY) {
                Value::None
            } else {
                Value::Vec(v.as_slice())
            }
        }
        f("q_max", lim(q_max));
        f("dq_max", lim(dq_max));
        f("tau_e_max", lim(tau_e_max));
        f("q_jump_max", lim(q_jump_max));
        f("tau_rate_max", lim(tau_rate_max));
        f("wall", opt(wall));
        f("ke", R(*ke));
        f("be", R(*be));
        f("m1", R(*m1));
        f("m2", R(*m2));
        f("l1", R(*l1));
        f("l2", R(*l2));
        f("lc1", opt(lc1));
        f("lc2", opt(lc2));
        f("I1", opt(i1));
        f("I2", opt(i2));
        f("g", R(*g));
        self.visit_cartesian(&mut f);
    }

    /// [`visit`](Self::visit) for the parameters of the Cartesian impedance
    /// (group "cartesian"), the last in [`PARAMS`].
    fn visit_cartesian(&self, f: &mut impl FnMut(&'static str, Value<'_>)) {
        let CartesianConfig {
            md,
            bd,
            kd,
            md_rot,
            bd_rot,
            kd_rot,
            clik_kp,
            clik_kd,
            clik_lambda,
            clik_lambda_rot,
            null_k,
            null_d,
            pos_error_max,
            rot_error_max,
            target_filter,
            force_filter,
            force_feedforward,
            formulation,
            admittance_share,
        } = &self.cartesian;
        let opt = |v: &Option<f64>| v.map_or(Value::None, Value::Real);
        f("Md", V(md.as_slice()));
        f("Bd", bd.as_ref().map_or(Nil, |b| V(b.as_slice())));
        f("Kd", V(kd.as_slice()));
        f("Md_rot", V(md_rot.as_slice()));
        f("Bd_rot", bd_rot.as_ref().map_or(Nil, |b| V(b.as_slice())));
        f("Kd_rot", V(kd_rot.as_slice()));
        f("clik_kp", R(*clik_kp));
        f("clik_kd", R(*clik_kd));
        f("clik_lambda", R(*clik_lambda));
        f("clik_lambda_rot", R(*clik_lambda_rot));
        f("null_k", R(*null_k));
        f("null_d", R(*null_d));
        f("pos_error_max", opt(pos_error_max));
        f("rot_error_max", opt(rot_error_max));
        f("target_filter", R(*target_filter));
        f("force_filter", R(*force_filter));
        f("force_feedforward", B(*force_feedforward));
        f("formulation", S(formulation.name()));
        f("admittance_share", R(*admittance_share));
    }

    /// [`visit`](Self::visit) for the parameters of the run (group "sim"),
    /// the first in [`PARAMS`].
    #[cfg(feature = "sim")]
    fn visit_run(&self, f: &mut impl FnMut(&'static str, Value<'_>)) {
        let SimConfig {
            t_final,
            substeps,
            q0,
            dq0,
            settle,
        } = &self.sim;
        let DisturbanceParams {
            payload,
            noise_q,
            noise_dq,
            noise_tau_e,
            seed,
            delay,
            jitter,
            friction_viscous,
            friction_coulomb,
            friction_vs,
            actuator_fraction,
        } = &self.disturb;
        f("T", R(*t_final));
        f("substeps", I(*substeps as i64));
        f("q0", V(q0.as_slice()));
        f("dq0", V(dq0.as_slice()));
        f("settle", R(*settle));
        f("payload", R(*payload));
        f("noise_q", V(noise_q.as_slice()));
        f("noise_dq", V(noise_dq.as_slice()));
        f("noise_tau_e", V(noise_tau_e.as_slice()));
        // The setter admits 0 ≤ seed ≤ i64::MAX only.
        f("seed", I(i64::try_from(*seed).unwrap_or(i64::MAX)));
        f("plant_delay", I(*delay as i64));
        f("jitter", R(*jitter));
        f("friction_viscous", V(friction_viscous.as_slice()));
        f("friction_coulomb", V(friction_coulomb.as_slice()));
        f("friction_vs", R(*friction_vs));
        f("actuator_fraction", V(actuator_fraction.as_slice()));
    }

    /// The commanded sinusoid (validated: finite).
    pub fn trajectory(&self) -> Result<Sinusoid<N>, Error> {
        let [o, a, b, w] = self.xc;
        Sinusoid::new(o, a, b, w)
    }

    /// The vertex grid of width η² (validated).
    pub fn grid(&self) -> Result<Grid<N>, Error> {
        Grid::new(self.eta2)
    }

    /// The disturbances of the run (validated; SPEC §17), the actuator
    /// fraction taken of the controller's `tau_max`. For
    /// [`run_disturbed`](crate::sim::simulator::run_disturbed).
    #[cfg(feature = "sim")]
    pub fn disturbances(&self) -> Result<Disturbances<N>, Error> {
        Disturbances::new(self.disturb, self.config.tau_max)
    }
}

#[cfg(feature = "sim")]
impl Scenario<2> {
    /// The plant's 2-link arm (validated; SPEC §1): the arm parameters m1,
    /// m2, l1, l2, lc1, lc2, I1, I2 and g, the derived ones filled in. Only
    /// the plant reads them: the controller is model-free.
    pub fn arm(&self) -> Result<TwoLinkArm, Error> {
        TwoLinkArm::new(self.arm.resolve())
    }
}

pub(super) fn kind_error(name: &'static str) -> Error {
    Error::Invalid {
        what: name,
        reason: "a value of another kind is expected (see its schema entry)",
    }
}

pub(super) fn real(name: &'static str, v: Value<'_>) -> Result<f64, Error> {
    match v {
        Value::Real(x) => Ok(x),
        Value::Int(i) => Ok(i as f64),
        _ => Err(kind_error(name)),
    }
}

pub(super) fn int(name: &'static str, v: Value<'_>) -> Result<i64, Error> {
    match v {
        Value::Int(i) => Ok(i),
        _ => Err(kind_error(name)),
    }
}

/// A delay in periods, 0 ≤ d ≤ [`MAX_DELAY`] (`condition` names it).
pub(super) fn delay(
    name: &'static str,
    v: Value<'_>,
    condition: &'static str,
) -> Result<usize, Error> {
    let v = int(name, v)?;
    usize::try_from(v)
        .ok()
        .filter(|d| *d <= MAX_DELAY)
        .ok_or(Error::Condition {
            condition,
            lhs: name,
            index: None,
            value: v as f64,
        })
}

pub(super) fn flag(name: &'static str, v: Value<'_>) -> Result<bool, Error> {
    match v {
        Value::Bool(b) => Ok(b),
        _ => Err(kind_error(name)),
    }
}

/// Three values (x, y, z), or none for the derived default.
pub(super) fn derived_axes(name: &'static str, v: Value<'_>) -> Result<Option<Vector<3>>, Error> {
    match v {
        Value::None => Ok(None),
        v => joint::<3>(name, v).map(Some),
    }
}

pub(super) fn optional(name: &'static str, v: Value<'_>) -> Result<Option<f64>, Error> {
    match v {
        Value::None => Ok(None),
        v => real(name, v).map(Some),
    }
}

pub(super) fn array<const M: usize>(name: &'static str, v: Value<'_>) -> Result<[f64; M], Error> {
    match v {
        Value::Vec(s) => s.try_into().map_err(|_| Error::Invalid {
            what: name,
            reason: "wrong length: one value per joint, per network D, C, G, or per axis x, y, z",
        }),
        v => real(name, v).map(|x| [x; M]),
    }
}

pub(super) fn joint<const N: usize>(name: &'static str, v: Value<'_>) -> Result<Vector<N>, Error> {
    array::<N>(name, v).map(Vector::from)
}

/// None, or N × N values, row-major.
pub(super) fn matrix<const N: usize>(
    name: &'static str,
    v: Value<'_>,
) -> Result<Option<crate::types::Matrix<N>>, Error> {
    match v {
        Value::None => Ok(None),
        Value::Vec(s) if s.len() == N * N => Ok(Some(crate::types::Matrix::<N>::from_row_slice(s))),
        Value::Vec(_) => Err(Error::Invalid {
            what: name,
            reason: "wrong length: n × n values, row-major",
        }),
        _ => Err(kind_error(name)),
    }
}

pub(super) fn limit<const N: usize>(name: &'static str, v: Value<'_>) -> Result<Vector<N>, Error> {
    match v {
        Value::None => Ok(Vector::from_element(f64::INFINITY)),
        v => joint(name, v),
    }
}

pub(super) fn network(name: &'static str, v: Value<'_>) -> Result<[f64; 3], Error> {
    array::<3>(name, v)
}

pub(super) fn choice<T: Copy>(p: &Param, v: Value<'_>, all: &[T]) -> Result<T, Error> {
    let (Kind::Choice(names), Value::Str(s)) = (p.kind, v) else {
        return Err(kind_error(p.name));
    };
    names
        .iter()
        .position(|n| *n == s)
        .and_then(|i| all.get(i).copied())
        .ok_or(Error::Invalid {
            what: p.name,
            reason: "not one of its choices (see its schema entry)",
        })
}
