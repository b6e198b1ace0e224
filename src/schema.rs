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

mod scenario;
pub use scenario::*;

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
    /// None, or n × n numbers (row-major; symmetric).
    Matrix,
}

impl Kind {
    /// The kind's name in Python ("real", "int", "joint", "network",
    /// "choice", "optional", "derived", "bound", "limit", "axes",
    /// "derived_axes", "flag", "matrix").
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
            Kind::Matrix => "matrix",
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
use Kind::{
    Axes, Bound, Derived, DerivedAxes, Flag, Int, Joint, Limit, Matrix, Network, Optional, Real,
};
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
    // SPEC (18.12): the scales as a matrix, and the gains shaped by it.
    p(
        "inertia_matrix",
        Ctrl,
        Matrix,
        "kg m²",
        "inertia-shaped gains: Dₛ (n × n, row-major) in place of diag(d) in the z1 term and the learning error, and Kp = R^½ Dₛ R^½ with R = diag(Kp/d) (SPEC (18.12); None: diagonal)",
        "symmetric positive definite",
        Nil,
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

#[cfg(test)]
mod tests;
