"""Type stubs of the compiled core ``adaptimp._adaptimp`` (bindings/python/src/).

The classes take complete parameter dicts keyed by the Python parameter names;
``adaptimp.Controller``, ``adaptimp.TwoLinkArm`` and ``adaptimp.simulate`` build
them from keywords with the paper's defaults.
"""

from collections.abc import Callable, Sequence
from typing import Any, Literal, TypedDict, final, overload, type_check_only

import numpy as np
from numpy.typing import ArrayLike, NDArray
from typing_extensions import deprecated, disjoint_base

__all__ = [
    "EFFORT_ACCEL",
    "MAX_JOINTS",
    "N_NODES",
    "CartesianImpedance",
    "CartesianStep",
    "Chain",
    "ComputedTorque",
    "Controller",
    "Measurement",
    "PlanarArm",
    "TwoLinkArm",
    "__version__",
    "arm_from_mujoco",
    "assess_posture",
    "centres_along",
    "default_task",
    "defaults",
    "description_kind",
    "estimate_effort",
    "metrics",
    "operational_inertia",
    "plane_normal",
    "pose_circle",
    "pose_metrics",
    "posture_needs",
    "read_arm",
    "schema_table",
    "simulate",
    "simulate_many",
    "simulate_mujoco",
    "simulate_mujoco_callback",
    "simulate_mujoco_many",
    "suggest",
    "table_metrics",
    "tabulate_joints",
    "tabulate_path",
]

__version__: str
MAX_JOINTS: int
EFFORT_ACCEL: float
N_NODES: int

_F = NDArray[np.float64]
_Joint = Sequence[float]

# BEGIN GENERATED from src/schema.rs by scripts/gen_stubs.py: do not edit

@type_check_only
class ControllerParams(TypedDict, total=False):
    """Controller parameters (SPEC §4–§11, §13)."""

    Ts: float
    """sampling period of the controller (s)."""
    delay: int
    """the loop's delay δ the controller is made for: its torque acts δ periods after its
    measurement was taken (libfranka: 1); in simulate, also the plant's (SPEC (18.11))
    (periods)."""
    K1: float | _Joint
    """K1 of α1 = ẋd + K1 z1, (7) (1/s)."""
    Kp: float | _Joint
    """feedback gain Kp, (14) (N m s/rad)."""
    Kzeta: float | _Joint
    """auxiliary-system gain Kζ, (11) (1/s)."""
    inertia: float | _Joint
    """inertia scale d of each joint: the auxiliary system takes Δτ/d, the z1 term d·z1, the
    learning error d·z2 (SPEC §10) (kg m²)."""
    inertia_matrix: Sequence[float] | Sequence[Sequence[float]] | None
    """inertia-shaped gains: Dₛ (n × n, row-major) in place of diag(d) in the z1 term and the
    learning error, and Kp = R^½ Dₛ R^½ with R = diag(Kp/d) (SPEC (18.12); None: diagonal)
    (kg m²)."""
    rho: float
    """Young weight ρ of ζᵀΔτ in the auxiliary system's β (SPEC §10) (1/s)."""
    conditions: Literal["paper", "scaled"]
    """stability conditions checked: the paper's (13) (unit weights: inertia = 1, rho = 1), or
    'scaled' (SPEC (10.3): Kp > 0, 2Kζ − ρ − Kp/d > 0)."""
    mu: float
    """radius μ of the auxiliary system's inner ball, (11) (N m)."""
    aux_law: Literal["default", "printed", "linear"]
    """auxiliary law: inside ‖ζ‖ < μ ζ̇ = −Kζ ζ + Δτ, or the printed ζ̇ = 0 (SPEC §8);
    'linear': ζ̇ = −Kζ ζ + Δτ everywhere, without the −β term (SPEC §13)."""
    robust: Literal["sign", "tanh", "remark1", "none"]
    """robust term r(z2): kr sgn z2, kr tanh(z2/φ), Remark 1's gain, none (SPEC §7)."""
    kr: float | _Joint
    """gain of the 'sign' and 'tanh' robust terms (SPEC §7) (N m)."""
    phi: float
    """boundary layer φ of the 'tanh' robust term (rad/s)."""
    kD: float
    """Remark 1 (30): kr_i = kD |α̇1_i| + kC |α1_i| + kG (kg m²)."""
    kC: float
    """Remark 1 (30): gain on |α1_i| (N m s/rad)."""
    kG: float
    """Remark 1 (30): constant part (N m)."""
    gamma: float | Sequence[float]
    """learning gains Γ of D̂, Ĉ, Ĝ, (15)–(17)."""
    sigma: float | Sequence[float]
    """leakages σ of D̂, Ĉ, Ĝ, (15)–(17)."""
    eta2: float
    """RBF width η² of the vertex grid (the paper's 'variance 25'), SPEC §6."""
    eps: float
    """high-gain observer ε, (31) (s)."""
    lam1: float | _Joint
    """high-gain observer λ1, (31)."""
    observer_init: Literal["zero", "first"]
    """observer start: π(0) = 0 (paper), or π1(0) = the first measurement."""
    observer_hold: Literal["zoh", "triangle"]
    """observer discretisation: zero-order hold (SPEC §11) or triangle hold."""
    observer_lead: bool
    """output feedback compares its velocity estimate with the reference the observer's lag
    back, ẑ2 = α1 − L α̇1 − ẋ̂ (L: Ts/2 at Ts ≫ ε), (9.1); False: the paper's ẑ2 = α1 − ẋ̂."""
    tau_max: float | _Joint
    """actuator limits τmax (SPEC §2) (N m)."""
    Dd: float | _Joint
    """target inertia Dd, (3) (kg m²)."""
    Cd: float | _Joint
    """target damping Cd, (3) (N m s/rad)."""
    Gd: float | _Joint
    """target stiffness Gd, (3) (N m/rad)."""
    impedance: Literal["joint", "external"]
    """where the target impedance acts: 'joint', the reference model of SPEC §4 (Dd, Cd, Gd);
    'external', the setpoint is already the compliant reference (xd = xc, e.g. a Cartesian
    impedance, SPEC §16)."""
    xc_offset: float | _Joint
    """commanded trajectory xc_i = o_i + a_i sin(ω_i t) + b_i cos(ω_i t): offset o (rad)."""
    xc_sin: float | _Joint
    """commanded trajectory: sine amplitude a (rad)."""
    xc_cos: float | _Joint
    """commanded trajectory: cosine amplitude b (rad)."""
    xc_omega: float | _Joint
    """commanded trajectory: angular frequency ω (rad/s)."""
    learning_step: Literal["euler", "normalized"]
    """learning step: explicit Euler of (15)–(17), or normalised so that one step's gain from
    z2 to the network output stays below κ·Kp."""
    kappa: float
    """κ of the normalised step."""
    saturation_learning: Literal["ignore", "freeze"]
    """learning while a joint saturates: as printed, or conditional integration (no step that
    pushes τ further beyond the limit)."""
    weight_bound: float | Sequence[float] | Literal["auto"] | None
    """projection onto ‖Ŵ‖_F ≤ b for D̂, Ĉ, Ĝ: None (none), 'auto' (derived from tau_max, the
    number of nodes and the commanded trajectory's peak speed and acceleration), or b."""
    fallback: Literal["hold", "zero", "damping"]
    """the torque returned when a step fails: the last applied one held, zero, or joint damping
    −Kd q̇ (each saturated)."""
    fallback_damping: float | _Joint
    """Kd of the damping fallback (N m s/rad)."""
    fault_policy: Literal["report", "latch"]
    """after a failed step: record the fault and go on, or latch it and refuse every step until
    clear_fault()."""
    q_max: float | _Joint | None
    """plausibility limit |q_i| ≤ q_max (None: none) (rad)."""
    dq_max: float | _Joint | None
    """plausibility limit |q̇_i| ≤ dq_max (None: none) (rad/s)."""
    tau_e_max: float | _Joint | None
    """plausibility limit |τe_i| ≤ tau_e_max (None: none) (N m)."""
    q_jump_max: float | _Joint | None
    """plausibility limit on the change of q_i between two samples (None: none) (rad)."""
    tau_rate_max: float | _Joint | None
    """torque rate limit per step, applied before saturation and visible in Δτ (None: none) (N
    m)."""

@type_check_only
class SimParams(TypedDict, total=False):
    """Run and environment parameters (SPEC §3, §11)."""

    T: float
    """duration; rows k = 0 … round(T/Ts) − 1 are recorded (s)."""
    substeps: int
    """RK4 substeps M of the plant per controller period."""
    q0: float | _Joint
    """initial joint position q(0), (65) (rad)."""
    dq0: float | _Joint
    """initial joint velocity q̇(0) (rad/s)."""
    settle: float
    """start of the 'after2' window of the metrics (SPEC §12) (s)."""
    payload: float
    """point mass at the tip of the last link (the plant's only) (kg)."""
    noise_q: float | _Joint
    """standard deviation of the Gaussian noise on each measured q_i (rad)."""
    noise_dq: float | _Joint
    """standard deviation of the Gaussian noise on each measured q̇_i (rad/s)."""
    noise_tau_e: float | _Joint
    """standard deviation of the Gaussian noise on each measured τe_i (N m)."""
    seed: int
    """seed of the noise and jitter generators (xoshiro256++): same seed, same run."""
    plant_delay: int
    """the loop's delay alone, the controller not told of it: the controller sees the sample of
    step k − d (simulate's delay= sets it and the controller's delay) (steps)."""
    jitter: float
    """sampling-time jitter j: the plant advances Ts (1 + u), u uniform on [−j, j), the
    controller assumes Ts."""
    friction_viscous: float | _Joint
    """viscous joint friction b of τf = −b q̇ − fc tanh(q̇/v_s) (N m s/rad)."""
    friction_coulomb: float | _Joint
    """Coulomb joint friction level fc of τf (N m)."""
    friction_vs: float
    """velocity scale v_s of the smooth Coulomb term fc tanh(q̇/v_s) (rad/s)."""
    actuator_fraction: float | _Joint
    """fraction ρ of its limit τmax each actuator delivers: the applied torque is clamped to ±ρ
    τmax."""
    wall: float | None
    """wall on joint 1 at this position; None: free space (rad)."""
    ke: float
    """wall stiffness (N m/rad)."""
    be: float
    """wall damping (N m s/rad)."""

@type_check_only
class ArmParams(TypedDict, total=False):
    """Arm parameters (SPEC §1)."""

    m1: float
    """mass of link 1 (kg)."""
    m2: float
    """mass of link 2 (kg)."""
    l1: float
    """length of link 1 (m)."""
    l2: float
    """length of link 2 (m)."""
    lc1: float | None
    """joint 1 to the centre of mass of link 1 (None: l1/2) (m)."""
    lc2: float | None
    """joint 2 to the centre of mass of link 2 (None: l2/2) (m)."""
    I1: float | None
    """inertia of link 1 about its centre (None: m1 l1²/4) (kg m²)."""
    I2: float | None
    """inertia of link 2 about its centre (None: m2 l2²/4) (kg m²)."""
    g: float
    """gravitational acceleration (vertical plane) (m/s²)."""

@type_check_only
class CartesianParams(TypedDict, total=False):
    """Cartesian impedance parameters (SPEC §16)."""

    Md: float | Sequence[float]
    """target inertia M_d of the translation, (C1) (kg)."""
    Bd: float | Sequence[float] | None
    """target damping B_d of the translation, (C1) (None: critical, 2√(K_d M_d), following the
    filtered K_d) (N s/m)."""
    Kd: float | Sequence[float]
    """target stiffness K_d of the translation, (C1) (N/m)."""
    Md_rot: float | Sequence[float]
    """target inertia of the rotation, (C1) (kg m²)."""
    Bd_rot: float | Sequence[float] | None
    """target damping of the rotation, (C1) (None: critical, 2√(K_d,rot M_d,rot)) (N m s/rad)."""
    Kd_rot: float | Sequence[float]
    """target stiffness of the rotation, (C1); 0 on every axis: position-only (the orientation
    is no task) (N m/rad)."""
    clik_kp: float
    """CLIK gain K_P: the pose error of fk(q_d) obeys ë + K_D ė + K_P e = 0, (C2) (1/s²)."""
    clik_kd: float
    """CLIK gain K_D, (C2) (1/s)."""
    clik_lambda: float
    """damping λ_p of the least-squares inverse in the translation rows, (C3) (m)."""
    clik_lambda_rot: float
    """damping λ_o of the least-squares inverse in the rotation rows, (C3)."""
    null_k: float
    """null-space posture stiffness k_0, (C2) (1/s²)."""
    null_d: float
    """null-space damping d_0, (C2) (1/s)."""
    pos_error_max: float | None
    """largest translation error fed to the impedance, (16.5) (None: no clipping) (m)."""
    rot_error_max: float | None
    """largest rotation error fed to the impedance, (16.5) (None: no clipping) (rad)."""
    target_filter: float
    """time constant of the first-order filter on jumps of the commanded pose and on stiffness
    changes, (16.6) (0: none) (s)."""
    force_filter: float
    """time constant of the first-order filter on the measured wrench, (16.6) (0: none) (s)."""
    force_feedforward: bool
    """the joint controller gets τe = Jᵀ F_e for its +τe feedforward (C5); False: τe = 0, the
    contact acts through (C1) only."""
    formulation: Literal["admittance", "impedance", "unified"]
    """how the impedance reaches the torque: 'admittance', the joint law tracks the compliant
    reference (C1)–(C5); 'impedance', τ = Jᵀ(K e + B ė) at the measured pose with the
    learned terms along the commanded motion, the wrench only in the learning error (holds a
    rigid contact); 'unified', their convex combination (SPEC §19)."""
    admittance_share: float
    """the admittance's share n of the torque for formulation 'unified' (0: impedance, 1:
    admittance), SPEC §19."""

# END GENERATED

@final
class Measurement:
    """One sample of the sensors: q (rad), dq (rad/s), tau_e (N m), wrench (N, N m)."""

    def __new__(
        cls,
        q: ArrayLike,
        dq: ArrayLike | None = None,
        *,
        tau_e: ArrayLike | None = None,
        wrench: ArrayLike | None = None,
    ) -> Measurement: ...
    @property
    def n(self) -> int: ...
    @property
    def q(self) -> _F: ...
    @property
    def dq(self) -> _F | None: ...
    @property
    def tau_e(self) -> _F | None: ...
    @property
    def wrench(self) -> _F | None: ...
    def __getnewargs_ex__(self) -> tuple[tuple[_F, _F | None], dict[str, _F | None]]: ...
    def __eq__(self, value: object, /) -> bool: ...

@disjoint_base
class Controller:
    """One of the paper's controllers for an arm of n joints, with its state."""

    def __new__(
        cls,
        case: str,
        params: ControllerParams | dict[str, Any],
        n: int = 2,
        centers: _F | None = None,
        widths2: _F | None = None,
        gravity: tuple[list[dict[str, Any]], list[dict[str, Any]], Sequence[float]] | None = None,
    ) -> Controller: ...
    @overload
    def step(
        self,
        m: Measurement,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
    ) -> _F:
        """One step from a :class:`Measurement`; sat(τ) (N m), (n,)."""
    @overload
    @deprecated("step(q, tau_e, dq): pass one adaptimp.Measurement(q, dq, tau_e=tau_e)")
    def step(
        self,
        q: ArrayLike,
        tau_e: ArrayLike,
        dq: ArrayLike | None = None,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
    ) -> _F: ...
    @overload
    def step_or_fallback(
        self,
        m: Measurement,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
    ) -> tuple[_F, str | None]: ...
    @overload
    @deprecated("step_or_fallback(q, tau_e, dq): pass one adaptimp.Measurement(q, dq, tau_e=tau_e)")
    def step_or_fallback(
        self,
        q: ArrayLike,
        tau_e: ArrayLike,
        dq: ArrayLike | None = None,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
    ) -> tuple[_F, str | None]: ...
    @property
    def fault(self) -> tuple[str, int] | None: ...
    def clear_fault(self) -> None: ...
    def replay(
        self,
        q: _F,
        tau_e: _F,
        dq: _F | None = None,
        *,
        xc: _F | None = None,
        dxc: _F | None = None,
        ddxc: _F | None = None,
        progress: Callable[[int, int], object] | None = None,
    ) -> _F:
        """K steps from (K, n) float64 tables; applied torques (K, n) (N m)."""
    def reset(self) -> None: ...
    def snapshot(self) -> _F: ...
    def restore(self, data: _F) -> None: ...
    def load_weights(self, weights: dict[str, _F]) -> None: ...
    def take_over(self, tau: ArrayLike) -> None:
        """Take over from a controller that was applying ``tau`` (n,) (N m): the
        first step's torque rate limit moves from it (SPEC (22.4)). Before the
        first step only; finite, within τmax."""
    @property
    def case(self) -> str: ...
    @property
    def n(self) -> int: ...
    @property
    def nodes(self) -> int: ...
    @property
    def t(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def Ts(self) -> float: ...
    @property
    def zeta(self) -> _F: ...
    @property
    def dq_hat(self) -> _F: ...
    @property
    def tau(self) -> _F: ...
    @property
    def tau_sat(self) -> _F: ...
    @property
    def applied(self) -> _F: ...
    @property
    def dtau(self) -> _F: ...
    @property
    def z1(self) -> _F: ...
    @property
    def xc(self) -> _F: ...
    @property
    def xd(self) -> _F: ...
    @property
    def weights(self) -> dict[str, _F]: ...
    @property
    def weight_bound(self) -> list[float] | None: ...
    @property
    def learning_gain(self) -> tuple[float, float]: ...

@final
class TwoLinkArm:
    """The paper's 2-link arm, (55)–(63)."""

    def __new__(cls, params: ArmParams | dict[str, Any]) -> TwoLinkArm: ...
    def D(self, q: ArrayLike) -> _F: ...
    def C(self, q: ArrayLike, dq: ArrayLike) -> _F: ...
    def G(self, q: ArrayLike) -> _F: ...
    def forward_dynamics(
        self, q: ArrayLike, dq: ArrayLike, tau: ArrayLike, tau_e: ArrayLike
    ) -> _F: ...
    def fk(self, q: ArrayLike) -> _F: ...
    def jacobian(self, q: ArrayLike) -> _F: ...
    @property
    def n(self) -> int: ...
    @property
    def params(self) -> dict[str, float]: ...
    @property
    def lumped(self) -> tuple[float, float, float, float, float]: ...

@final
class PlanarArm:
    """An n-link planar arm (1 ≤ n ≤ 7)."""

    def __new__(
        cls,
        masses: Sequence[float],
        lengths: Sequence[float],
        coms: Sequence[float],
        inertias: Sequence[float],
        g: float,
    ) -> PlanarArm: ...
    def D(self, q: ArrayLike) -> _F: ...
    def C(self, q: ArrayLike, dq: ArrayLike) -> _F: ...
    def G(self, q: ArrayLike) -> _F: ...
    def forward_dynamics(
        self, q: ArrayLike, dq: ArrayLike, tau: ArrayLike, tau_e: ArrayLike
    ) -> _F: ...
    def fk(self, q: ArrayLike) -> _F: ...
    def jacobian(self, q: ArrayLike) -> _F: ...
    @property
    def n(self) -> int: ...
    @property
    def g(self) -> float: ...

def simulate(
    controller: Controller,
    arm: TwoLinkArm | PlanarArm,
    params: SimParams | dict[str, Any],
    record_every: int = 1,
    progress: Callable[[int, int], object] | None = None,
    weights: dict[str, _F] | None = None,
    fault: tuple[str, float, float, list[float] | None, float | None] | None = None,
) -> dict[str, Any]:
    """Close the loop with the GIL released; returns the arrays and "metrics"."""

def simulate_many(
    jobs: Sequence[tuple[str, dict[str, Any], TwoLinkArm | None]],
    threads: int | None = None,
    progress: Callable[[int, int], object] | None = None,
) -> list[dict[str, Any] | str]:
    """Run independent jobs (case, params, arm) on every core; metrics or error texts."""

def simulate_mujoco(
    controller: Controller,
    model: Any,
    data: Any,
    spec: dict[str, Any],
    params: dict[str, Any],
    t_final: float,
    settle: float,
    record_every: int = 1,
    progress: Callable[[int, int], object] | None = None,
    reference: tuple[_F, _F, _F] | None = None,
    fault: tuple[str, float, float, list[float] | None, float | None] | None = None,
) -> dict[str, Any]:
    """The closed loop on a MuJoCo MjModel/MjData with the GIL released (SPEC §13.2)."""

def simulate_mujoco_callback(
    controller: Any,
    model: Any,
    data: Any,
    spec: dict[str, Any],
    params: dict[str, Any],
    ts: float,
    t_final: float,
    settle: float,
    table: tuple[_F, _F, _F],
    *,
    setpoint: bool,
    task_space: bool,
    call: str,
    attrs: list[str],
    target: tuple[list[float], list[float], list[float]],
    record_every: int = 1,
    progress: Callable[[int, int], object] | None = None,
    fault: tuple[str, float, float, list[float] | None, float | None] | None = None,
) -> dict[str, Any]:
    """The closed loop on MuJoCo of a controller written in Python, called back once a period."""

def simulate_mujoco_many(
    jobs: Sequence[
        tuple[
            Controller,
            Any,
            Any,
            dict[str, Any],
            dict[str, Any],
            float,
            float,
            tuple[_F, _F, _F] | None,
        ]
    ],
    threads: int | None = None,
    progress: Callable[[int, int], object] | None = None,
) -> list[dict[str, Any] | str]:
    """Run independent MuJoCo jobs on every core; metrics or error texts."""

def metrics(
    t: _F,
    q: _F,
    dq: _F,
    ddq: _F,
    xc: _F,
    dxc: _F,
    ddxc: _F,
    z1: _F,
    tau: _F,
    tau_sat: _F,
    tau_e: _F,
    settle: float,
    target: tuple[Sequence[float], Sequence[float], Sequence[float]],
    joint_space: bool | None = None,
) -> dict[str, Any]:
    """The SPEC §12 metrics of recorded rows, by the core's accumulator."""

def schema_table() -> list[dict[str, Any]]:
    """The parameter schema: name, group, kind, unit, doc, condition, choices, defaults."""

def defaults(scenario: str = "paper", n: int = 2) -> dict[str, Any]:
    """Every parameter's default in ``scenario`` ("paper" or "robot") for n joints."""

def read_arm(
    source: str,
    tip: str | None = None,
    fix: Sequence[str] | None = None,
    label: str | None = None,
) -> dict[str, Any]:
    """The arm of a URDF path or URDF text (SPEC §21), as a dict of the arm's
    joints, limits, efforts, drive terms, chain, bodies, tip, held joints and
    the reduced URDF."""

def arm_from_mujoco(
    arrays: dict[str, Any],
    source: str,
    tip: str | None = None,
    fix: Sequence[str] | None = None,
) -> dict[str, Any]:
    """The arm of a compiled MuJoCo model's arrays (SPEC §21), as :func:`read_arm`'s dict."""

def description_kind(path: str) -> str:
    """What the file at ``path`` is: "urdf", "xacro", "mjcf", "mjcf-fragment" or "unknown"."""

def estimate_effort(
    gravity: NDArray[np.float64],
    inertia: NDArray[np.float64],
    damping: NDArray[np.float64] | None = None,
    friction: NDArray[np.float64] | None = None,
) -> NDArray[np.float64]:
    """Effort limits (N m per joint) where a description states none: 2 (max |G_i| +
    10 rad/s² · max Σ_j |D_ij| + b_i · 1 rad/s + F_i) over the sampled postures
    (``gravity`` (K, n), ``inertia`` (K, n, n))."""

def operational_inertia(
    jacobian: NDArray[np.float64], inertia: NDArray[np.float64], uncoupled: bool = True
) -> NDArray[np.float64]:
    """The operational-space inertia Λ (6, 6) of robosuite's OSC_POSE (SPEC (23.7)):
    kg on the translation rows, kg m² on the rotation rows, kg m across;
    ``jacobian`` [J_v; J_ω] (6, n), ``inertia`` D (n, n; kg m²), ``uncoupled``
    OSC's ``uncouple_pos_ori`` (Λ block-diagonal)."""

@disjoint_base
class Chain:
    """A serial chain of 1 … 7 revolute or prismatic joints and a tip (SPEC §16)."""

    def __new__(
        cls, joints: Sequence[dict[str, Any]], tip: dict[str, Any] | None = None
    ) -> Chain: ...
    @property
    def n(self) -> int: ...
    @property
    def prismatic(self) -> list[bool]: ...
    def fk(self, q: ArrayLike) -> _F: ...
    def jacobian(self, q: ArrayLike) -> _F: ...
    def jdot_qdot(self, q: ArrayLike, dq: ArrayLike) -> _F: ...
    def motion(self, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike) -> tuple[_F, _F]:
        """The tip's twist J q̇ and acceleration J q̈ + J̇ q̇ along rows, each (K, 6)."""

@final
class CartesianImpedance:
    """The 6-D Cartesian impedance outer loop over a Chain, with its state (SPEC §16)."""

    def __new__(
        cls,
        chain: Chain,
        params: CartesianParams | dict[str, Any],
        ts: float,
        q0: ArrayLike,
        posture: ArrayLike | None = None,
    ) -> CartesianImpedance: ...
    @property
    def n(self) -> int: ...
    @property
    def ts(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def orients(self) -> bool: ...
    def reset(self, q0: ArrayLike | None = None) -> None: ...
    def set_posture(self, posture: ArrayLike) -> None: ...
    def set_stiffness(self, Kd: ArrayLike, Kd_rot: ArrayLike) -> None: ...
    def reference(self, target: ArrayLike | None, wrench: ArrayLike) -> list[_F]: ...
    def step_controller(
        self,
        controller: Controller | ComputedTorque,
        q: ArrayLike,
        dq: ArrayLike | None,
        wrench: ArrayLike,
        target: ArrayLike | None = None,
    ) -> _F: ...
    def step_sample(
        self,
        controller: Controller | ComputedTorque,
        q: ArrayLike,
        dq: ArrayLike | None,
        wrench: ArrayLike | None,
        sample: Any,
        record: bool,
    ) -> _F:
        """One step of ``CartesianController.step`` in one call; sat(τ) (N m), (n,)."""
    def held_rotation(self) -> _F: ...
    def set_held_rotation(self, r: ArrayLike) -> None: ...
    def take_log(self) -> _F: ...
    def step_python(
        self,
        inner: Any,
        q: ArrayLike,
        dq: ArrayLike | None,
        wrench: ArrayLike,
        target: ArrayLike | None = None,
        *,
        measurement: bool = True,
    ) -> _F: ...
    def last(self, what: str) -> _F: ...
    def state(self, what: str) -> _F: ...
    def orbit(self, q0: ArrayLike, targets: _F, nodes: int) -> list[_F]: ...
    def orbit_size(self, T: float, nodes: int) -> tuple[int, int]: ...
    def check_target(self, target: ArrayLike) -> None: ...
    def simulate_mujoco(
        self,
        controller: Controller | ComputedTorque,
        model: Any,
        data: Any,
        spec: dict[str, Any],
        params: dict[str, Any],
        t_final: float,
        settle: float,
        record_every: int = 1,
        progress: Callable[[int, int], object] | None = None,
        targets: _F | None = None,
        fault: tuple[str, float, float, list[float] | None, float | None] | None = None,
    ) -> dict[str, Any]:
        """The closed loop on MuJoCo with this outer loop in front of ``controller``."""
    def replay(
        self,
        controller: Controller | ComputedTorque,
        q: _F,
        dq: _F,
        wrench: _F,
        targets: _F | None = None,
        progress: Callable[[int, int], object] | None = None,
    ) -> _F:
        """The core's Cartesian steps over recorded rows; sat(τ) (K, n)."""

def centres_along(
    q: _F, dq: _F, tube: tuple[float, float], periodic: bool = False
) -> tuple[_F, _F]:
    """RBF centres (L, 4n) along an orbit and their squared widths (4n,), SPEC (15.2)."""

def tabulate_joints(
    reference: Callable[[float], Any],
    steps: int,
    ts: float,
    n: int,
    start: int,
    what: str,
    check: Callable[[str, Any, tuple[int, ...]], _F],
) -> list[_F]:
    """The tables (steps, n) of xc, ẋc, ẍc (rad, rad/s, rad/s²) of a Python
    joint reference at t_k = (start + k)·Ts (s)."""

def tabulate_path(
    path: Callable[[float], Any],
    steps: int,
    ts: float,
    r0: _F,
    start: int,
    what: str,
    check: Callable[[str, Any, tuple[int, ...]], _F],
) -> _F:
    """The rows (steps, 24) of a Python path at t_k = (start + k)·Ts (s), as
    pose targets (m, m/s, m/s², R row-major, rad/s, rad/s²)."""

def suggest(
    case: str,
    inertia: NDArray[np.float64],
    tau_max: NDArray[np.float64],
    ts: float,
    path: NDArray[np.float64] | None = None,
    period: float | None = None,
    gravity: NDArray[np.float64] | None = None,
    resolve: bool = False,
    critical: bool = False,
    damping: NDArray[np.float64] | None = None,
    orbit: NDArray[np.float64] | None = None,
    delay: int = 0,
    weightless: bool = False,
    coupled: bool | None = None,
) -> dict[str, Any]:
    """The gain and basis rule of SPEC §18 for ``inertia`` (n, n), or (K, n, n)
    samples along the path (SPEC (18.1)'s scales along it): "params" (every
    controller keyword), with a path also "centers" (L, 4n) and "widths" (4n,);
    ``resolve``: the tube narrowed to the path's size, SPEC (16.10); ``critical``:
    Ĝ learning at the velocity loop's critical bandwidth, SPEC (19.6); ``damping``
    (n,): the joints' viscous damping, the scales as the sampled loop sees them,
    SPEC (18.9); ``orbit`` (K', n): one period of the joint positions that repeat,
    the widths in q at least its diameter, SPEC (19.11); ``weightless``: D̂ and Ĉ
    learning at Ĝ's bandwidth, an arm without gravity, SPEC (22.2); ``coupled``: the
    inertia-shaped gains of SPEC (18.12) (the keyword ``inertia_matrix``; None:
    the core's default, on for a delay ≥ 1; with ``resolve``, Ĝ then learns at
    least at (m/Ts) K1)."""

def pose_circle(
    p0: NDArray[np.float64],
    r0: NDArray[np.float64],
    ts: float,
    steps: int,
    radius: float | None = None,
    freq: float | None = None,
    hold: float | None = None,
    ramp: float | None = None,
    start: float = 0.0,
    normal: Sequence[float] | None = None,
) -> tuple[_F, float, list[float]]:
    """The default Cartesian task of SPEC (16.8) tabulated: (targets (steps, 24),
    span (s), centre (3,)); ``normal``: its plane (None: horizontal)."""

def plane_normal(jacobian: NDArray[np.float64]) -> list[float] | None:
    """A planar arm's plane normal from its 6 × n Jacobian (SPEC (16.8)), or None."""

def posture_needs(
    best: dict[str, Any],
    k1: float | None = None,
    ts: float | None = None,
    load: float | None = None,
) -> str:
    """What each condition of the posture rule (SPEC (16.9)) needs, with the best
    value found of each."""

def assess_posture(
    chain: Chain,
    q: NDArray[np.float64],
    p: NDArray[np.float64],
    gravity: NDArray[np.float64],
    d0: NDArray[np.float64],
    lo: NDArray[np.float64],
    hi: NDArray[np.float64],
    tau_max: NDArray[np.float64],
    orients: bool,
    k1: float | None = None,
    ts: float | None = None,
    load: float | None = None,
    normal: Sequence[float] | None = None,
) -> dict[str, Any]:
    """How well a posture runs a task, SPEC (16.9): the figures along its joint
    orbit, the score, the first condition it violates ("error", or None) and
    the rule's bounds ("needs"); ``k1`` (1/s), ``ts`` (s): the joint
    controller's (conditioning ≥ K1·Ts/m); ``normal``: a planar arm's plane."""

def pose_metrics(
    chain: Chain,
    q: NDArray[np.float64],
    targets: NDArray[np.float64],
    t: NDArray[np.float64],
    settle: float,
    ts: float,
) -> tuple[_F, _F, dict[str, float]]:
    """The pose errors e_p (K,) (m), e_o (K,) (rad) of a run and their metrics,
    SPEC (16.11)."""

def table_metrics(
    t: _F,
    p: _F,
    dp: _F,
    ddp: _F,
    pd: _F,
    pc: tuple[_F, _F, _F],
    wrench: _F,
    normal: _F,
    tau: tuple[_F, _F],
    tau_max: _F,
    impedance: tuple[Sequence[float], Sequence[float], Sequence[float]],
    depth: float,
    series: float,
    windows: tuple[float, float, float],
    ts: float,
) -> dict[str, float]:
    """The table's metrics of a run, SPEC (19.7), by name."""

def default_task(
    home: NDArray[np.float64], lo: NDArray[np.float64], hi: NDArray[np.float64]
) -> tuple[list[float], list[float], list[float], list[float]]:
    """The default task of SPEC §18: (xc_offset, xc_sin, xc_cos, xc_omega)."""

@final
class CartesianStep:
    """``CartesianController.step`` as the core's own method: ``step(m)`` goes
    straight to the core; any other call to ``other``."""

    def __new__(
        cls,
        core: CartesianImpedance,
        joint: Controller | ComputedTorque | None,
        path: Any,
        other: Callable[..., _F],
        record: bool,
    ) -> CartesianStep: ...
    def step(self, *args: Any, **kwargs: Any) -> _F: ...

@disjoint_base
class ComputedTorque:
    """Computed-torque impedance control on the core's rigid-body model (SPEC §20)."""

    def __new__(
        cls,
        joints: list[dict[str, Any]],
        inertials: list[dict[str, Any]],
        gravity: Sequence[float],
        *,
        Ts: float,
        Kp: float | Sequence[float],
        Kd: float | Sequence[float],
        tau_max: float | Sequence[float],
        Dd: float | Sequence[float],
        Cd: float | Sequence[float],
        Gd: float | Sequence[float],
        impedance: str,
        mass_scale: float,
        payload: float,
        armature: float | Sequence[float] | None = None,
        damping: float | Sequence[float] | None = None,
        friction: float | Sequence[float] | None = None,
        substep: float | None = None,
        substeps: int = 1,
        implicit_damping: bool = False,
        semi_implicit: bool = False,
        friction_regularisation: float | Sequence[float] | None = None,
        friction_rate: float | Sequence[float] | None = None,
        stiffness: float | Sequence[float] | None = None,
        spring_reference: float | Sequence[float] | None = None,
        lifted: list[dict[str, Any]] | None = None,
    ) -> ComputedTorque: ...
    @property
    def n(self) -> int: ...
    @property
    def Ts(self) -> float: ...
    @property
    def steps(self) -> int: ...
    @property
    def mass(self) -> float: ...
    @property
    def fault(self) -> tuple[str, int] | None: ...
    def reset(self) -> None: ...
    def set_trajectory(self, trajectory: Callable[[float], Any] | None = None) -> None: ...
    @overload
    def step(
        self,
        m: Measurement,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
    ) -> _F:
        """One step (SPEC (20.3)); sat(τ) (N m), (n,)."""
    @overload
    @deprecated("step(q, tau_e, dq): pass one adaptimp.Measurement(q, dq, tau_e=tau_e)")
    def step(
        self,
        q: ArrayLike,
        tau_e: ArrayLike,
        dq: ArrayLike | None = None,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
    ) -> _F: ...
    def inverse_dynamics(self, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike) -> _F:
        """RNEA(q, q̇, q̈) = M q̈ + C q̇ + G (N m), (n,)."""
    def mass_matrix(self, q: ArrayLike) -> _F:
        """M(q) (kg m²), (n, n)."""
    def last(self, what: str) -> _F: ...
    def simulate_mujoco(
        self,
        model: Any,
        data: Any,
        spec: dict[str, Any],
        params: dict[str, Any],
        t_final: float,
        settle: float,
        reference: tuple[_F, _F, _F],
        record_every: int = 1,
        progress: Callable[[int, int], object] | None = None,
        fault: tuple[str, float, float, list[float] | None, float | None] | None = None,
    ) -> dict[str, Any]:
        """The closed loop on MuJoCo in joint space along ``reference`` (every row)."""
