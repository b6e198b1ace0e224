//! The parameter schema: every parameter's name (as Python and the command
//! line spell it), group, kind, unit, one-line doc, validity condition and
//! per-scenario default, declared once, in [`PARAMS`].
//!
//! Everything else derives from this table: the presets (`src/presets.rs`,
//! above this module: `Config::paper`, `Controller::robot`, …), the setter by name ([`Scenario::set`]) through which the
//! Python bindings and the C ABI build configurations, and, in Python, the
//! keyword table, `help(adaptimp.simulate)`, the command line and the stubs.
//! [`Scenario::visit`] destructures every configuration struct exhaustively, so
//! a field added without a schema name does not compile, and a test checks
//! that the names it visits are exactly those of [`PARAMS`].

use crate::cartesian::{CartesianConfig, Formulation};
use crate::control::auxiliary::AuxLaw;
use crate::control::config::MAX_DELAY;
use crate::control::config::{Conditions, Config, Law, ObserverInit, WeightBound};
use crate::control::impedance::ImpedanceMode;
use crate::control::observer::Hold;
use crate::control::robust::RobustKind;
use crate::control::safety::{Fallback, FaultPolicy, Limits};
use crate::error::Error;
use crate::networks::learning::{LearningStep, SaturationLearning};
use crate::networks::rbf::Grid;
#[cfg(feature = "sim")]
use crate::sim::disturb::{DisturbanceParams, Disturbances};
#[cfg(feature = "sim")]
use crate::sim::model::{ArmParams, TwoLinkArm};
#[cfg(feature = "sim")]
use crate::sim::simulator::SimConfig;
use crate::trajectory::Sinusoid;
use crate::types::Vector;

/// The group a parameter belongs to (the Python keyword sets).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Group {
    /// The run: duration, integration, initial state, metrics window.
    Sim,
    /// The controller, its basis and its commanded trajectory.
    Controller,
    /// The environment (the wall).
    Env,
    /// The paper's 2-link arm (the plant).
    Arm,
    /// The 6-D Cartesian impedance (SPEC §16).
    Cartesian,
}

impl Group {
    /// The group's name in Python ("sim", "controller", "env", "arm", "cartesian").
    pub fn name(self) -> &'static str {
        match self {
            Group::Sim => "sim",
            Group::Controller => "controller",
            Group::Env => "env",
            Group::Arm => "arm",
            Group::Cartesian => "cartesian",
        }
    }
}

/// The kind of value a parameter takes.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A finite number.
    Real,
    /// An integer.
    Int,
    /// One number per joint (a scalar is broadcast).
    Joint,
    /// One number per network D̂, Ĉ, Ĝ (a scalar is broadcast).
    Network,
    /// One of the listed names.
    Choice(&'static [&'static str]),
    /// A number, or none.
    Optional,
    /// A number, or none for the value derived from other parameters.
    Derived,
    /// None, "auto", or one number per network.
    Bound,
    /// None (no limit), or a number > 0 per joint (a scalar is broadcast).
    Limit,
    /// One number per task axis x, y, z (a scalar is broadcast).
    Axes,
    /// One number per task axis, or none for the value derived from other parameters.
    DerivedAxes,
    /// True or false.
    Flag,
}

impl Kind {
    /// The kind's name in Python ("real", "int", "joint", "network",
    /// "choice", "optional", "derived", "bound", "limit", "axes",
    /// "derived_axes", "flag").
    pub fn name(self) -> &'static str {
        match self {
            Kind::Real => "real",
            Kind::Int => "int",
            Kind::Joint => "joint",
            Kind::Network => "network",
            Kind::Choice(_) => "choice",
            Kind::Optional => "optional",
            Kind::Derived => "derived",
            Kind::Bound => "bound",
            Kind::Limit => "limit",
            Kind::Axes => "axes",
            Kind::DerivedAxes => "derived_axes",
            Kind::Flag => "flag",
        }
    }
}

/// A parameter value. Per-joint and per-network values are slices; a
/// [`Value::Real`] given for them is broadcast.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Value<'a> {
    /// A number.
    Real(f64),
    /// An integer.
    Int(i64),
    /// One number per joint or per network.
    Vec(&'a [f64]),
    /// A choice's name, or "auto".
    Str(&'a str),
    /// A flag.
    Bool(bool),
    /// No value (free space, a derived default, no bound).
    None,
}

/// The scenarios with their own defaults.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Preset {
    /// The paper scenario, SPEC §1–§12 (Ts = 50 µs).
    Paper,
    /// The robot scenario, SPEC §13 (Ts = 1 ms, the hardened options).
    Robot,
}

impl Preset {
    /// Every preset.
    pub const ALL: [Preset; 2] = [Preset::Paper, Preset::Robot];

    /// Its name in Python ("paper", "robot").
    pub fn name(self) -> &'static str {
        match self {
            Preset::Paper => "paper",
            Preset::Robot => "robot",
        }
    }

    /// The preset called `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }
}

/// One parameter: see the [module docs](self).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Param {
    /// Its name in Python and on the command line, e.g. `"Kzeta"`.
    pub name: &'static str,
    /// Its group.
    pub group: Group,
    /// Its kind of value.
    pub kind: Kind,
    /// Its unit (empty if dimensionless).
    pub unit: &'static str,
    /// What it means, in one line.
    pub doc: &'static str,
    /// The condition a valid value meets (SPEC §10 style), or "" if any
    /// finite value is valid.
    pub condition: &'static str,
    /// Its default in the paper scenario.
    pub paper: Value<'static>,
    /// Its default in the robot scenario, if it differs.
    pub robot: Option<Value<'static>>,
}

impl Param {
    /// Its default in `preset`.
    pub fn default_in(&self, preset: Preset) -> Value<'static> {
        match (preset, self.robot) {
            (Preset::Robot, Some(v)) => v,
            _ => self.paper,
        }
    }
}

const fn p(
    name: &'static str,
    group: Group,
    kind: Kind,
    unit: &'static str,
    doc: &'static str,
    condition: &'static str,
    paper: Value<'static>,
) -> Param {
    Param {
        name,
        group,
        kind,
        unit,
        doc,
        condition,
        paper,
        robot: None,
    }
}

/// The same parameter with a robot-scenario default of its own.
const fn robot(param: Param, value: Value<'static>) -> Param {
    Param {
        robot: Some(value),
        ..param
    }
}

use Group::{Arm, Cartesian as Cart, Controller as Ctrl, Env, Sim};
use Kind::{Axes, Bound, Derived, DerivedAxes, Flag, Int, Joint, Limit, Network, Optional, Real};
use Value::{Bool as B, Int as I, None as Nil, Real as R, Str as S, Vec as V};

const PI: f64 = core::f64::consts::PI;

/// Every parameter, in the order of the documentation.
pub const PARAMS: &[Param] = &[
    // The run, SPEC §11 (the robot scenario: SPEC §13).
    p("T", Sim, Real, "s", "duration; rows k = 0 … round(T/Ts) − 1 are recorded", "T > 0", R(20.0)),
    robot(
        p("substeps", Sim, Int, "", "RK4 substeps M of the plant per controller period", "1 ≤ substeps ≤ 10 000", I(1)),
        I(10),
    ),
    p("q0", Sim, Joint, "rad", "initial joint position q(0), (65)", "", V(&[0.25, -0.05])),
    p("dq0", Sim, Joint, "rad/s", "initial joint velocity q̇(0)", "", R(0.0)),
    p("settle", Sim, Real, "s", "start of the 'after2' window of the metrics (SPEC §12)", "settle ≥ 0", R(2.0)),
    // Disturbances a real robot has (SPEC §17, src/sim/disturb.rs); the defaults
    // disturb nothing. The controller is told none of them.
    p("payload", Sim, Real, "kg", "point mass at the tip of the last link (the plant's only)", "payload ≥ 0", R(0.0)),
    p("noise_q", Sim, Joint, "rad", "standard deviation of the Gaussian noise on each measured q_i", "noise ≥ 0", R(0.0)),
    p("noise_dq", Sim, Joint, "rad/s", "standard deviation of the Gaussian noise on each measured q̇_i", "noise ≥ 0", R(0.0)),
    p(
        "noise_tau_e",
        Sim,
        Joint,
        "N m",
        "standard deviation of the Gaussian noise on each measured τe_i",
        "noise ≥ 0",
        R(0.0),
    ),
    p("seed", Sim, Int, "", "seed of the noise and jitter generators (xoshiro256++): same seed, same run", "seed ≥ 0", I(0)),
    p(
        "plant_delay",
        Sim,
        Int,
        "steps",
        "the loop's delay alone, the controller not told of it: the controller sees the sample of step k − d (simulate's delay= sets it and the controller's delay)",
        "0 ≤ plant_delay ≤ 64",
        I(0),
    ),
    p(
        "jitter",
        Sim,
        Real,
        "",
        "sampling-time jitter j: the plant advances Ts (1 + u), u uniform on [−j, j), the controller assumes Ts",
        "0 ≤ jitter < 1",
        R(0.0),
    ),
    p("friction_viscous", Sim, Joint, "N m s/rad", "viscous joint friction b of τf = −b q̇ − fc tanh(q̇/v_s)", "b ≥ 0", R(0.0)),
    p("friction_coulomb", Sim, Joint, "N m", "Coulomb joint friction level fc of τf", "fc ≥ 0", R(0.0)),
    p("friction_vs", Sim, Real, "rad/s", "velocity scale v_s of the smooth Coulomb term fc tanh(q̇/v_s)", "v_s > 0", R(0.01)),
    p(
        "actuator_fraction",
        Sim,
        Joint,
        "",
        "fraction ρ of its limit τmax each actuator delivers: the applied torque is clamped to ±ρ τmax",
        "0 < ρ ≤ 1",
        R(1.0),
    ),
    // The controller, SPEC §4–§9, §11.
    robot(p("Ts", Ctrl, Real, "s", "sampling period of the controller", "Ts > 0", R(50e-6)), R(1e-3)),
    robot(
        p(
            "delay",
            Ctrl,
            Int,
            "periods",
            "the loop's delay δ the controller is made for: its torque acts δ periods after its measurement was taken (libfranka: 1); in simulate, also the plant's (SPEC (18.11))",
            "0 ≤ delay ≤ 64",
            I(0),
        ),
        I(1),
    ),
    p("K1", Ctrl, Joint, "1/s", "K1 of α1 = ẋd + K1 z1, (7)", "K1 > 0", R(6.0)),
    p(
        "Kp",
        Ctrl,
        Joint,
        "N m s/rad",
        "feedback gain Kp, (14)",
        "2Kp − I > 0 (conditions 'paper'); Kp > 0 ('scaled')",
        R(10.0),
    ),
    p(
        "Kzeta",
        Ctrl,
        Joint,
        "1/s",
        "auxiliary-system gain Kζ, (11)",
        "2Kζ − I − KpᵀKp > 0 (conditions 'paper'); 2Kζ − ρ − Kp/d > 0 ('scaled')",
        R(60.0),
    ),
    // SPEC §10: the Lyapunov function weighted by each joint's inertia scale.
    p(
        "inertia",
        Ctrl,
        Joint,
        "kg m²",
        "inertia scale d of each joint: the auxiliary system takes Δτ/d, the z1 term d·z1, the learning error d·z2 (SPEC §10)",
        "1e-9 ≤ d ≤ 1e9",
        R(1.0),
    ),
    p("rho", Ctrl, Real, "1/s", "Young weight ρ of ζᵀΔτ in the auxiliary system's β (SPEC §10)", "1e-9 ≤ ρ ≤ 1e9", R(1.0)),
    robot(
        p(
            "conditions",
            Ctrl,
            Kind::Choice(&Conditions::NAMES),
            "",
            "stability conditions checked: the paper's (13) (unit weights: inertia = 1, rho = 1), or 'scaled' (SPEC (10.3): Kp > 0, 2Kζ − ρ − Kp/d > 0)",
            "",
            S("paper"),
        ),
        S("scaled"),
    ),
    p("mu", Ctrl, Real, "N m", "radius μ of the auxiliary system's inner ball, (11)", "μ > 0", R(0.01)),
    p(
        "aux_law",
        Ctrl,
        Kind::Choice(&AuxLaw::NAMES),
        "",
        "auxiliary law: inside ‖ζ‖ < μ ζ̇ = −Kζ ζ + Δτ, or the printed ζ̇ = 0 (SPEC §8); 'linear': ζ̇ = −Kζ ζ + Δτ everywhere, without the −β term (SPEC §13)",
        "",
        S("default"),
    ),
    robot(
        p(
            "robust",
            Ctrl,
            Kind::Choice(&RobustKind::NAMES),
            "",
            "robust term r(z2): kr sgn z2, kr tanh(z2/φ), Remark 1's gain, none (SPEC §7)",
            "",
            S("sign"),
        ),
        S("tanh"),
    ),
    p("kr", Ctrl, Joint, "N m", "gain of the 'sign' and 'tanh' robust terms (SPEC §7)", "kr ≥ 0", R(0.5)),
    // φ is of the order of the adaptive loops' |z2| after settling (measured on
    // joint 1: median 0.015, RMS 0.09 rad/s), so tanh is smooth near the target.
    p("phi", Ctrl, Real, "rad/s", "boundary layer φ of the 'tanh' robust term", "φ > 0", R(0.05)),
    // The Remark 1 gains make kr ≈ 0.55 N m on the paper's circle, close to the sign term's.
    p("kD", Ctrl, Real, "kg m²", "Remark 1 (30): kr_i = kD |α̇1_i| + kC |α1_i| + kG", "kD ≥ 0", R(0.01)),
    p("kC", Ctrl, Real, "N m s/rad", "Remark 1 (30): gain on |α1_i|", "kC ≥ 0", R(0.05)),
    p("kG", Ctrl, Real, "N m", "Remark 1 (30): constant part", "kG ≥ 0", R(0.5)),
    p("gamma", Ctrl, Network, "", "learning gains Γ of D̂, Ĉ, Ĝ, (15)–(17)", "Γ > 0", R(100.0)),
    p("sigma", Ctrl, Network, "", "leakages σ of D̂, Ĉ, Ĝ, (15)–(17)", "σ > 0", R(0.01)),
    p("eta2", Ctrl, Real, "", "RBF width η² of the vertex grid (the paper's 'variance 25'), SPEC §6", "η² > 0", R(25.0)),
    // SPEC §9: ε = 1e-4 s, not the paper's 1e-3.
    p("eps", Ctrl, Real, "s", "high-gain observer ε, (31)", "ε > 0", R(1e-4)),
    p("lam1", Ctrl, Joint, "", "high-gain observer λ1, (31)", "λ1 > 0", R(3.0)),
    robot(
        p(
            "observer_init",
            Ctrl,
            Kind::Choice(&ObserverInit::NAMES),
            "",
            "observer start: π(0) = 0 (paper), or π1(0) = the first measurement",
            "",
            S("zero"),
        ),
        S("first"),
    ),
    robot(
        p(
            "observer_hold",
            Ctrl,
            Kind::Choice(&Hold::NAMES),
            "",
            "observer discretisation: zero-order hold (SPEC §11) or triangle hold",
            "",
            S("zoh"),
        ),
        S("triangle"),
    ),
    robot(
        p(
            "observer_lead",
            Ctrl,
            Flag,
            "",
            "output feedback compares its velocity estimate with the reference the observer's lag back, ẑ2 = α1 − L α̇1 − ẋ̂ (L: Ts/2 at Ts ≫ ε), (9.1); False: the paper's ẑ2 = α1 − ẋ̂",
            "",
            B(false),
        ),
        B(true),
    ),
    p("tau_max", Ctrl, Joint, "N m", "actuator limits τmax (SPEC §2)", "τmax > 0", V(&[17.0, 15.0])),
    p("Dd", Ctrl, Joint, "kg m²", "target inertia Dd, (3)", "Dd > 0", R(1.0)),
    p("Cd", Ctrl, Joint, "N m s/rad", "target damping Cd, (3)", "Cd ≥ 0", R(10.0)),
    p("Gd", Ctrl, Joint, "N m/rad", "target stiffness Gd, (3)", "Gd ≥ 0", R(60.0)),
    p(
        "impedance",
        Ctrl,
        Kind::Choice(&ImpedanceMode::NAMES),
        "",
        "where the target impedance acts: 'joint', the reference model of SPEC §4 (Dd, Cd, Gd); 'external', the setpoint is already the compliant reference (xd = xc, e.g. a Cartesian impedance, SPEC §16)",
        "",
        S("joint"),
    ),
    // (64): xc = [0.2 − 0.2 cos(πt), 0.2 + 0.2 sin(πt)].
    p(
        "xc_offset",
        Ctrl,
        Joint,
        "rad",
        "commanded trajectory xc_i = o_i + a_i sin(ω_i t) + b_i cos(ω_i t): offset o",
        "",
        V(&[0.2, 0.2]),
    ),
    p("xc_sin", Ctrl, Joint, "rad", "commanded trajectory: sine amplitude a", "", V(&[0.0, 0.2])),
    p("xc_cos", Ctrl, Joint, "rad", "commanded trajectory: cosine amplitude b", "", V(&[-0.2, 0.0])),
    p("xc_omega", Ctrl, Joint, "rad/s", "commanded trajectory: angular frequency ω", "", R(PI)),
    // Hardened options (SPEC §13, beyond the paper; the robot scenario's defaults).
    robot(
        p(
            "learning_step",
            Ctrl,
            Kind::Choice(&LearningStep::NAMES),
            "",
            "learning step: explicit Euler of (15)–(17), or normalised so that one step's gain from z2 to the network output stays below κ·Kp",
            "",
            S("euler"),
        ),
        S("normalized"),
    ),
    p("kappa", Ctrl, Real, "", "κ of the normalised step", "0 < κ ≤ 1", R(0.5)),
    robot(
        p(
            "saturation_learning",
            Ctrl,
            Kind::Choice(&SaturationLearning::NAMES),
            "",
            "learning while a joint saturates: as printed, or conditional integration (no step that pushes τ further beyond the limit)",
            "",
            S("ignore"),
        ),
        S("freeze"),
    ),
    robot(
        p(
            "weight_bound",
            Ctrl,
            Bound,
            "",
            "projection onto ‖Ŵ‖_F ≤ b for D̂, Ĉ, Ĝ: None (none), 'auto' (derived from tau_max, the number of nodes and the commanded trajectory's peak speed and acceleration), or b",
            "weight bound > 0",
            Nil,
        ),
        S("auto"),
    ),
    // Safety around the control law (beyond the paper; src/control/safety.rs).
    p(
        "fallback",
        Ctrl,
        Kind::Choice(&Fallback::NAMES),
        "",
        "the torque returned when a step fails: the last applied one held, zero, or joint damping −Kd q̇ (each saturated)",
        "",
        S("hold"),
    ),
    p("fallback_damping", Ctrl, Joint, "N m s/rad", "Kd of the damping fallback", "Kd ≥ 0", R(1.0)),
    p(
        "fault_policy",
        Ctrl,
        Kind::Choice(&FaultPolicy::NAMES),
        "",
        "after a failed step: record the fault and go on, or latch it and refuse every step until clear_fault()",
        "",
        S("report"),
    ),
    p("q_max", Ctrl, Limit, "rad", "plausibility limit |q_i| ≤ q_max (None: none)", "limit > 0", Nil),
    p("dq_max", Ctrl, Limit, "rad/s", "plausibility limit |q̇_i| ≤ dq_max (None: none)", "limit > 0", Nil),
    p("tau_e_max", Ctrl, Limit, "N m", "plausibility limit |τe_i| ≤ tau_e_max (None: none)", "limit > 0", Nil),
    p(
        "q_jump_max",
        Ctrl,
        Limit,
        "rad",
        "plausibility limit on the change of q_i between two samples (None: none)",
        "limit > 0",
        Nil,
    ),
    p(
        "tau_rate_max",
        Ctrl,
        Limit,
        "N m",
        "torque rate limit per step, applied before saturation and visible in Δτ (None: none)",
        "limit > 0",
        Nil,
    ),
    // The environment, SPEC §3.
    p("wall", Env, Optional, "rad", "wall on joint 1 at this position; None: free space", "", R(0.2)),
    p("ke", Env, Real, "N m/rad", "wall stiffness", "ke ≥ 0", R(1000.0)),
    p("be", Env, Real, "N m s/rad", "wall damping", "be ≥ 0", R(10.0)),
    // The arm, SPEC §1 (the plant only: the controller is model-free). Table I
    // is missing; the same group's arm.
    p("m1", Arm, Real, "kg", "mass of link 1", "m1 > 0", R(2.0)),
    p("m2", Arm, Real, "kg", "mass of link 2", "m2 > 0", R(0.85)),
    p("l1", Arm, Real, "m", "length of link 1", "l1 > 0", R(0.35)),
    p("l2", Arm, Real, "m", "length of link 2", "l2 > 0", R(0.31)),
    p("lc1", Arm, Derived, "m", "joint 1 to the centre of mass of link 1 (None: l1/2)", "lc1 ≥ 0", Nil),
    p("lc2", Arm, Derived, "m", "joint 2 to the centre of mass of link 2 (None: l2/2)", "lc2 ≥ 0", Nil),
    p("I1", Arm, Derived, "kg m²", "inertia of link 1 about its centre (None: m1 l1²/4)", "I1 ≥ 0", Nil),
    p("I2", Arm, Derived, "kg m²", "inertia of link 2 about its centre (None: m2 l2²/4)", "I2 ≥ 0", Nil),
    p("g", Arm, Real, "m/s²", "gravitational acceleration (vertical plane)", "", R(9.81)),
    // The 6-D Cartesian impedance, SPEC §16 (src/cartesian/outer.rs): world-frame
    // axes; the translation at ω = √(K/M) = 15.8 rad/s, the rotation at the same.
    p("Md", Cart, Axes, "kg", "target inertia M_d of the translation, (C1)", "Md > 0", R(2.0)),
    p(
        "Bd",
        Cart,
        DerivedAxes,
        "N s/m",
        "target damping B_d of the translation, (C1) (None: critical, 2√(K_d M_d), following the filtered K_d)",
        "Bd ≥ 0",
        Nil,
    ),
    p("Kd", Cart, Axes, "N/m", "target stiffness K_d of the translation, (C1)", "Kd ≥ 0", R(500.0)),
    p("Md_rot", Cart, Axes, "kg m²", "target inertia of the rotation, (C1)", "Md_rot > 0", R(0.08)),
    p(
        "Bd_rot",
        Cart,
        DerivedAxes,
        "N m s/rad",
        "target damping of the rotation, (C1) (None: critical, 2√(K_d,rot M_d,rot))",
        "Bd_rot ≥ 0",
        Nil,
    ),
    p(
        "Kd_rot",
        Cart,
        Axes,
        "N m/rad",
        "target stiffness of the rotation, (C1); 0 on every axis: position-only (the orientation is no task)",
        "Kd_rot ≥ 0",
        R(20.0),
    ),
    p("clik_kp", Cart, Real, "1/s²", "CLIK gain K_P: the pose error of fk(q_d) obeys ë + K_D ė + K_P e = 0, (C2)", "clik_kp > 0", R(1600.0)),
    p("clik_kd", Cart, Real, "1/s", "CLIK gain K_D, (C2)", "clik_kd > 0", R(80.0)),
    p("clik_lambda", Cart, Real, "m", "damping λ_p of the least-squares inverse in the translation rows, (C3)", "clik_lambda > 0", R(0.01)),
    p("clik_lambda_rot", Cart, Real, "", "damping λ_o of the least-squares inverse in the rotation rows, (C3)", "clik_lambda_rot > 0", R(0.01)),
    p("null_k", Cart, Real, "1/s²", "null-space posture stiffness k_0, (C2)", "null_k ≥ 0", R(25.0)),
    p("null_d", Cart, Real, "1/s", "null-space damping d_0, (C2)", "null_d ≥ 0", R(10.0)),
    p("pos_error_max", Cart, Optional, "m", "largest translation error fed to the impedance, (16.5) (None: no clipping)", "pos_error_max > 0", Nil),
    p("rot_error_max", Cart, Optional, "rad", "largest rotation error fed to the impedance, (16.5) (None: no clipping)", "rot_error_max > 0", Nil),
    p(
        "target_filter",
        Cart,
        Real,
        "s",
        "time constant of the first-order filter on jumps of the commanded pose and on stiffness changes, (16.6) (0: none)",
        "target_filter ≥ 0",
        R(0.05),
    ),
    p("force_filter", Cart, Real, "s", "time constant of the first-order filter on the measured wrench, (16.6) (0: none)", "force_filter ≥ 0", R(0.0)),
    p(
        "force_feedforward",
        Cart,
        Flag,
        "",
        "the joint controller gets τe = Jᵀ F_e for its +τe feedforward (C5); False: τe = 0, the contact acts through (C1) only",
        "",
        B(true),
    ),
    // How the impedance reaches the torque, SPEC §19.
    p(
        "formulation",
        Cart,
        Kind::Choice(&Formulation::NAMES),
        "",
        "how the impedance reaches the torque: 'admittance', the joint law tracks the compliant reference (C1)–(C5); 'impedance', τ = Jᵀ(K e + B ė) at the measured pose with the learned terms along the commanded motion, the wrench only in the learning error (holds a rigid contact); 'unified', their convex combination (SPEC §19)",
        "",
        S("admittance"),
    ),
    p(
        "admittance_share",
        Cart,
        Real,
        "",
        "the admittance's share n of the torque for formulation 'unified' (0: impedance, 1: admittance), SPEC §19",
        "0 ≤ admittance_share ≤ 1",
        R(0.3),
    ),
];

/// The parameter called `name`.
pub fn param(name: &str) -> Option<&'static Param> {
    PARAMS.iter().find(|p| p.name == name)
}

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

fn kind_error(name: &'static str) -> Error {
    Error::Invalid {
        what: name,
        reason: "a value of another kind is expected (see its schema entry)",
    }
}

fn real(name: &'static str, v: Value<'_>) -> Result<f64, Error> {
    match v {
        Value::Real(x) => Ok(x),
        Value::Int(i) => Ok(i as f64),
        _ => Err(kind_error(name)),
    }
}

fn int(name: &'static str, v: Value<'_>) -> Result<i64, Error> {
    match v {
        Value::Int(i) => Ok(i),
        _ => Err(kind_error(name)),
    }
}

/// A delay in periods, 0 ≤ d ≤ [`MAX_DELAY`] (`condition` names it).
fn delay(name: &'static str, v: Value<'_>, condition: &'static str) -> Result<usize, Error> {
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

fn flag(name: &'static str, v: Value<'_>) -> Result<bool, Error> {
    match v {
        Value::Bool(b) => Ok(b),
        _ => Err(kind_error(name)),
    }
}

/// Three values (x, y, z), or none for the derived default.
fn derived_axes(name: &'static str, v: Value<'_>) -> Result<Option<Vector<3>>, Error> {
    match v {
        Value::None => Ok(None),
        v => joint::<3>(name, v).map(Some),
    }
}

fn optional(name: &'static str, v: Value<'_>) -> Result<Option<f64>, Error> {
    match v {
        Value::None => Ok(None),
        v => real(name, v).map(Some),
    }
}

fn array<const M: usize>(name: &'static str, v: Value<'_>) -> Result<[f64; M], Error> {
    match v {
        Value::Vec(s) => s.try_into().map_err(|_| Error::Invalid {
            what: name,
            reason: "wrong length: one value per joint, per network D, C, G, or per axis x, y, z",
        }),
        v => real(name, v).map(|x| [x; M]),
    }
}

fn joint<const N: usize>(name: &'static str, v: Value<'_>) -> Result<Vector<N>, Error> {
    array::<N>(name, v).map(Vector::from)
}

fn limit<const N: usize>(name: &'static str, v: Value<'_>) -> Result<Vector<N>, Error> {
    match v {
        Value::None => Ok(Vector::from_element(f64::INFINITY)),
        v => joint(name, v),
    }
}

fn network(name: &'static str, v: Value<'_>) -> Result<[f64; 3], Error> {
    array::<3>(name, v)
}

fn choice<T: Copy>(p: &Param, v: Value<'_>, all: &[T]) -> Result<T, Error> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn visit_names_exactly_the_schema_in_its_order() {
        let s = Scenario::<2>::preset(Preset::Robot, Law::StateFeedback);
        let mut seen = alloc::vec::Vec::new();
        s.visit(|name, _| seen.push(name));
        let table: alloc::vec::Vec<_> = PARAMS.iter().map(|p| p.name).collect();
        assert_eq!(seen, table);
    }

    #[test]
    fn every_value_round_trips_through_set_and_visit() {
        for preset in Preset::ALL {
            let s = Scenario::<2>::preset(preset, Law::OutputFeedback);
            let mut copy = Scenario::<2>::preset(Preset::Paper, Law::OutputFeedback);
            s.visit(|name, v| copy.set(name, v).unwrap());
            assert_eq!(copy, s, "{preset:?}");
            // The defaults the table declares are the values visited.
            s.visit(|name, v| {
                let d = param(name).unwrap().default_in(preset);
                match (d, v) {
                    (Value::Real(x), Value::Vec(y)) => assert!(y.iter().all(|y| *y == x), "{name}"),
                    (d, v) => assert_eq!(d, v, "{name}"),
                }
            });
        }
    }

    #[test]
    fn presets_apply_for_every_size() {
        fn check<const N: usize>() {
            for preset in Preset::ALL {
                let s = Scenario::<N>::preset(preset, Law::StateFeedback);
                assert_eq!(s.config.kp, Vector::<N>::from_element(10.0));
            }
        }
        check::<1>();
        check::<2>();
        check::<3>();
        check::<5>();
        check::<7>();
    }

    #[test]
    fn every_choice_name_maps_to_a_distinct_variant() {
        let mut s = Scenario::<2>::preset(Preset::Paper, Law::Pd);
        for p in PARAMS {
            if let Kind::Choice(names) = p.kind {
                for name in names {
                    s.set(p.name, Value::Str(name)).unwrap();
                    s.visit(|n, v| {
                        if n == p.name {
                            assert_eq!(v, Value::Str(name));
                        }
                    });
                }
                let e = s.set(p.name, Value::Str("nonsense")).unwrap_err();
                assert!(e.to_string().contains("not one of its choices"), "{e}");
            }
        }
    }

    #[test]
    fn bad_names_and_kinds_are_errors() {
        let mut s = Scenario::<2>::preset(Preset::Paper, Law::Pd);
        assert!(s.set("Kpp", Value::Real(1.0)).is_err());
        assert!(s.set("Kp", Value::Str("x")).is_err());
        assert!(s.set("Kp", Value::Vec(&[1.0, 2.0, 3.0])).is_err());
        let e = s.set("substeps", Value::Int(-1)).unwrap_err();
        assert!(e.to_string().contains("1 ≤ substeps ≤ 10 000"), "{e}");
        s.set("weight_bound", Value::Vec(&[1.0, 2.0, 3.0])).unwrap();
        assert_eq!(s.config.weight_bound, WeightBound::Fixed([1.0, 2.0, 3.0]));
        s.set("weight_bound", Value::Real(2.0)).unwrap();
        assert_eq!(s.config.weight_bound, WeightBound::Fixed([2.0; 3]));
    }
}
