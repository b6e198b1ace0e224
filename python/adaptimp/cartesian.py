"""Cartesian impedance in Python: the outer admittance loop of SPEC §16 (C1–C5).

The Rust core has the outer loop (``src/cartesian/outer.rs``) for its own kinematics
(planar arms); this module is the same loop in NumPy for kinematics given as
callables, so that a real arm (the Panda, through Pinocchio) can run it with
MuJoCo as the plant:

- :class:`OuterLoop`: the compliant reference (C1), the second-order
  closed-loop inverse kinematics with damped least squares and a null-space
  posture task (C2, C3), semi-implicit Euler (C4). Given the commanded
  Cartesian point p_c (m) and the measured force F_e (N) it produces the
  joint setpoint (q_d, q̇_d, q̈_d) for a joint controller.
- :class:`CartesianImpedance`: the outer loop in front of a joint controller
  (C5): an ``adaptimp.Controller(..., impedance="external")`` or
  :class:`adaptimp.baselines.ComputedTorque` ``(impedance="external")``. It
  follows the controller protocol of :func:`adaptimp.mujoco.simulate`
  (``.step(q, tau_e, dq, **kw)``, ``.Ts``), takes the measured wrench through
  its ``wants_wrench`` hook and records what :func:`cartesian_metrics` needs.
- The scenario "panda-table" (:func:`panda_table`): the Panda's tool follows a
  circle on a table while pressing on it through the target impedance;
  :func:`panda_controller` builds the five controllers compared in
  ``examples/13_panda_table.py`` and ``docs/panda.md``.

The outer loop needs NumPy only; :func:`pinocchio_kinematics`, :func:`panda_table`
and :func:`panda_controller` import Pinocchio and MuJoCo when called.

Sign convention (SPEC §4, §16): F_e is the force the end effector exerts on
the environment (pressing down on a table, F_e,z < 0).

Units: m, m/s, m/s², rad, rad/s, rad/s², N, N m, kg, s.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._errors import period_alias

__all__ = [
    "CartesianImpedance",
    "OuterLoop",
    "OuterLoopConfig",
    "PandaTable",
    "cartesian_metrics",
    "joint_gains",
    "orbit_basis",
    "panda_controller",
    "panda_table",
    "pinocchio_kinematics",
]

FloatArray = NDArray[np.float64]
Fk = Callable[[FloatArray], FloatArray]
"""fk(q) -> p (m), (3,): the end-effector point for the joint angles q (rad), (n,)."""
Jacobian = Callable[[FloatArray], FloatArray]
"""jacobian(q) -> J (m/rad), (3, n): the position Jacobian ∂p/∂q."""
Path = Callable[[float], tuple[FloatArray, FloatArray, FloatArray]]
"""path(t) -> (p_c, ṗ_c, p̈_c) (m, m/s, m/s²), each (3,): the commanded point at t (s)."""


def _vec(name: str, value: ArrayLike, n: int) -> FloatArray:
    v = np.asarray(value, dtype=np.float64)
    if v.shape == ():
        v = np.full(n, float(v))
    if v.shape != (n,) or not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be finite with shape ({n},), got {v!r}")
    return v


# ---------------------------------------------------------------------------
# The outer loop (SPEC §16, C1-C4).
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class OuterLoopConfig:
    """Parameters of the outer loop, SPEC §16's defaults.

    Attributes
    ----------
    Md : float or (3,)
        Target inertia M_d (kg), default 2.
    Kd : float or (3,)
        Target stiffness K_d (N/m), default 500.
    Bd : float or (3,), optional
        Target damping B_d (N s/m); default 2√(K_d M_d) = 63.2 (critical).
    KP : float
        CLIK stiffness K_P (1/s²), default 1600.
    KD : float
        CLIK damping K_D (1/s), default 80 (ω = 40 rad/s, critical).
    lam : float
        Damping λ of the least squares (m), default 0.01.
    k0 : float
        Posture stiffness k_0 (1/s²) in the null space, default 25.
    d0 : float
        Null-space damping d_0 (1/s), default 10.
    jdot_step : float
        Step h (s) of the central difference J̇ q̇ ≈ (J(q + h q̇) − J(q − h q̇)) q̇ / 2h
        (the derivative of J along q̇ is J̇ for q̇ the velocity; error O(h²)), default 1e-6.
    force_filter : float
        Time constant τ_f (s) of a first-order low-pass filter on the measured
        F_e before (C1): F̃ ← F̃ + Ts/(τ_f + Ts) (F_e − F̃), F̃(0) = F_e(0).
        Default 0: no filter, SPEC §16 exactly. Beyond the SPEC: against a
        rigid surface the path F_e → p̈_d → τ → F_e is algebraic with gain
        Λ_n/M_d (Λ_n the arm's apparent mass along the normal; 2.3 for the
        Panda at home with M_d = 2 kg), so without a filter the sampled loop
        chatters at Ts (measured: the force alternates 0 / 17 N); see docs/panda.md.
    """

    Md: float | Sequence[float] = 2.0
    Kd: float | Sequence[float] = 500.0
    Bd: float | Sequence[float] | None = None
    KP: float = 1600.0
    KD: float = 80.0
    lam: float = 0.01
    k0: float = 25.0
    d0: float = 10.0
    jdot_step: float = 1e-6
    force_filter: float = 0.0

    def arrays(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """(M_d, B_d, K_d) as (3,) arrays, B_d = 2√(K_d M_d) if not given."""
        md, kd = _vec("Md", self.Md, 3), _vec("Kd", self.Kd, 3)
        bd = 2.0 * np.sqrt(kd * md) if self.Bd is None else _vec("Bd", self.Bd, 3)
        return md, bd, kd


class OuterLoop:
    """The outer loop of SPEC §16 for kinematics given as callables.

    At every step t_k, given the commanded p_c, ṗ_c, p̈_c (m, m/s, m/s²) and the
    force F_e (N) the end effector exerts on the environment:

        (C1) p̈_d = p̈_c + M_d⁻¹ (−B_d (ṗ_d − ṗ_c) − K_d (p_d − p_c) − F_e)
        (C2) q̈_d = J⁺ r + (I − J⁺ J) w = w + J⁺ (r − J w),   J = J(q_d),
             r = p̈_d − J̇ q̇_d + K_D (ṗ_d − J q̇_d) + K_P (p_d − fk(q_d)),
             w = k_0 (q_posture − q_d) − d_0 q̇_d
        (C3) J⁺ = Jᵀ (J Jᵀ + λ² I₃)⁻¹
        (C4) ṗ_d ← ṗ_d + Ts p̈_d, p_d ← p_d + Ts ṗ_d;
             q̇_d ← q̇_d + Ts q̈_d, q_d ← q_d + Ts q̇_d

    with p_d(0) = p_c(0), ṗ_d(0) = ṗ_c(0) (set at the first step), q_d(0) = q0,
    q̇_d(0) = J⁺(q0) ṗ_c(0). J̇ q̇_d is the central difference of J along q̇_d
    (:class:`OuterLoopConfig` ``jdot_step``) unless ``jdot_qdot(q, dq)`` is given.

    Parameters
    ----------
    fk, jacobian : callable
        fk(q) -> (3,) (m); jacobian(q) -> (3, n) (m/rad).
    Ts : float
        Period Ts (s).
    q0 : (n,)
        Initial joint setpoint q_d(0) (rad).
    posture : (n,), optional
        q_posture (rad) of the null-space task; default q0.
    config : OuterLoopConfig, optional
        Gains; default SPEC §16's.
    jdot_qdot : callable, optional
        jdot_qdot(q, dq) -> J̇ q̇ (m/s²), (3,).
    """

    def __init__(
        self,
        fk: Fk,
        jacobian: Jacobian,
        Ts: float,
        q0: ArrayLike,
        *,
        posture: ArrayLike | None = None,
        config: OuterLoopConfig | None = None,
        jdot_qdot: Callable[[FloatArray, FloatArray], FloatArray] | None = None,
    ) -> None:
        if not (Ts > 0 and math.isfinite(Ts)):
            raise ValueError(f"Ts must be > 0, got {Ts}")
        self.fk, self.jacobian, self.Ts = fk, jacobian, float(Ts)
        self.config = config or OuterLoopConfig()
        c = self.config
        if Ts * c.KD >= 1 or Ts**2 * c.KP >= 1:
            raise ValueError(f"need Ts·K_D < 1 and Ts²·K_P < 1 (SPEC §16), Ts = {Ts:g} s")
        if not c.force_filter >= 0:
            raise ValueError(f"force_filter must be ≥ 0 s, got {c.force_filter}")
        if c.lam <= 0 or c.KP <= 0 or c.KD <= 0 or c.k0 < 0 or c.d0 < 0:
            raise ValueError("need λ > 0, K_P > 0, K_D > 0, k_0 ≥ 0, d_0 ≥ 0 (SPEC §16)")
        self.Md, self.Bd, self.Kd = c.arrays()
        if np.any(self.Md <= 0) or np.any(self.Bd < 0) or np.any(self.Kd < 0):
            raise ValueError("need M_d > 0, B_d ≥ 0, K_d ≥ 0 (SPEC §16)")
        self.q0 = np.asarray(q0, dtype=np.float64).copy()
        self.n = int(self.q0.shape[0])
        self.posture = _vec("posture", self.q0 if posture is None else posture, self.n)
        self._jdot = jdot_qdot
        self.reset()

    @property
    def ts(self) -> float:
        """Deprecated: the period is :attr:`Ts` (s)."""
        return period_alias(self)

    def reset(self) -> None:
        """Back to t = 0 (the Cartesian state is set by the next step's p_c)."""
        self.q_d = self.q0.copy()
        self.dq_d = np.zeros(self.n)
        self.p_d: FloatArray | None = None
        self.dp_d = np.zeros(3)
        self.ddp_d = np.zeros(3)
        self.f_filt: FloatArray | None = None

    def pinv(self, jac: FloatArray, v: FloatArray) -> FloatArray:
        """J⁺ v = Jᵀ (J Jᵀ + λ² I₃)⁻¹ v (C3), one 3 × 3 solve."""
        a = jac @ jac.T + self.config.lam**2 * np.eye(3)
        return jac.T @ np.linalg.solve(a, v)

    def jdot_qdot(self, q: FloatArray, dq: FloatArray) -> FloatArray:
        """J̇(q) q̇ (m/s²), (3,): the given callable or the central difference."""
        if self._jdot is not None:
            return np.asarray(self._jdot(q, dq), dtype=np.float64)
        h = self.config.jdot_step
        return np.asarray(
            (self.jacobian(q + h * dq) - self.jacobian(q - h * dq)) @ dq / (2.0 * h),
            dtype=np.float64,
        )

    def step(
        self, pc: ArrayLike, dpc: ArrayLike, ddpc: ArrayLike, force: ArrayLike
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """One step at t_k: the joint setpoint (q_d, q̇_d, q̈_d) (rad, rad/s, rad/s²)
        at t_k from p_c, ṗ_c, p̈_c (m, m/s, m/s²) and F_e (N), each (3,); then
        every state advances to t_{k+1} (C4). ``p_d``, ``dp_d``, ``ddp_d`` hold
        the compliant reference of t_k after the call."""
        pc, dpc, ddpc = (_vec(k, v, 3) for k, v in (("pc", pc), ("dpc", dpc), ("ddpc", ddpc)))
        f = _vec("force", force, 3)
        c = self.config
        if c.force_filter > 0:
            if self.f_filt is None:
                self.f_filt = f.copy()
            else:
                self.f_filt = self.f_filt + self.Ts / (c.force_filter + self.Ts) * (f - self.f_filt)
            f = self.f_filt
        q, dq = self.q_d, self.dq_d
        if self.p_d is None:  # p_d(0) = p_c(0), ṗ_d(0) = ṗ_c(0), q̇_d(0) = J⁺(q0) ṗ_c(0)
            self.p_d, self.dp_d = pc.copy(), dpc.copy()
            dq = self.dq_d = self.pinv(np.asarray(self.jacobian(q), dtype=np.float64), dpc)
        p_d, dp_d = self.p_d, self.dp_d
        ddp_d = ddpc + (-self.Bd * (dp_d - dpc) - self.Kd * (p_d - pc) - f) / self.Md  # (C1)
        jac = np.asarray(self.jacobian(q), dtype=np.float64)
        r = (
            ddp_d
            - self.jdot_qdot(q, dq)
            + c.KD * (dp_d - jac @ dq)
            + c.KP * (p_d - np.asarray(self.fk(q), dtype=np.float64))
        )
        w = c.k0 * (self.posture - q) - c.d0 * dq
        ddq = w + self.pinv(jac, r - jac @ w)  # (C2), (C3)
        out = (q.copy(), dq.copy(), ddq)
        self.ddp_d = ddp_d
        self._pd_k, self._dpd_k = p_d.copy(), dp_d.copy()
        # (C4): semi-implicit Euler, the velocity first.
        self.dp_d = dp_d + self.Ts * ddp_d
        self.p_d = p_d + self.Ts * self.dp_d
        self.dq_d = dq + self.Ts * ddq
        self.q_d = q + self.Ts * self.dq_d
        return out

    @property
    def pd_k(self) -> FloatArray:
        """p_d (m) of the last step's t_k (before the advance)."""
        return self._pd_k

    @property
    def dpd_k(self) -> FloatArray:
        """ṗ_d (m/s) of the last step's t_k (before the advance)."""
        return self._dpd_k


# ---------------------------------------------------------------------------
# The controller: the outer loop in front of a joint controller (C5).
# ---------------------------------------------------------------------------


class CartesianImpedance:
    """SPEC §16's Cartesian impedance controller: :class:`OuterLoop` + a joint controller.

    The protocol of :func:`adaptimp.mujoco.simulate`: ``step(q, tau_e, dq, *,
    wrench=, xc=, dxc=, ddxc=)`` returns the joint controller's output (its
    sat(τ), N m), ``.Ts`` is the period. ``wants_wrench = True`` makes
    :func:`~adaptimp.mujoco.simulate` pass the measured wrench [f; m] (N, N m);
    the outer loop uses its force f = F_e. The joint controller gets the
    setpoint ``xc=q_d, dxc=q̇_d, ddxc=q̈_d`` and τe = Jᵀ F_e: the plant's τe
    (the full wrench through the 6 × n Jacobian at the measured q; C5 with
    the moment included, which the position-only outer loop leaves out).

    The Cartesian setpoint is ``xc=, dxc=, ddxc=`` (3,) when given (as
    :func:`~adaptimp.mujoco.simulate` does with ``reference=``), else ``path(t_k)``.

    Attributes after a step (the row's t_k): ``xc`` = p_c, ``xd`` = p_d
    (compliant reference), ``z1`` = p_d − fk(q) (m), ``tau`` (the joint
    controller's commanded τ, N m), ``q_d``, ``force`` (F_e, N); ``log`` holds
    every step's p_c, ṗ_c, p̈_c, p_d, ṗ_d, p̈_d, q_d, F_e (see :meth:`arrays`).

    Parameters
    ----------
    inner : joint controller
        ``adaptimp.Controller(..., impedance="external")`` or
        ``ComputedTorque(..., impedance="external")``, same period as ``outer``.
    outer : OuterLoop
    path : callable, optional
        path(t) -> (p_c, ṗ_c, p̈_c), used when a step has no setpoint.
    force_feedforward : bool
        True (SPEC (C5)): the joint controller gets τe = Jᵀ F_e, which its law
        adds to the torque (+τe in (14), (35)). False: it gets zero, and the
        contact force acts through the outer loop only. Against a stiff
        surface sampled at 1 kHz the feedforward closes a one-step loop from
        the measured force to the torque whose gain (the arm's apparent mass
        over M_d) exceeds 1, and the contact chatters (docs/panda.md).
    """

    wants_wrench = True

    def __init__(
        self,
        inner: Any,
        outer: OuterLoop,
        path: Path | None = None,
        *,
        force_feedforward: bool = True,
    ) -> None:
        Ts = getattr(inner, "Ts", None)
        if Ts is None or not math.isclose(float(Ts), outer.Ts, rel_tol=1e-12):
            raise ValueError(f"inner period {Ts} differs from the outer loop's {outer.Ts} s")
        mode = getattr(inner, "impedance", None)
        if mode is None:
            params = getattr(inner, "params", {})
            mode = params.get("impedance") if isinstance(params, dict) else None
        if mode != "external":
            raise ValueError(
                f"the joint controller must have impedance='external' (SPEC §16), got {mode!r}"
            )
        self.inner, self.outer, self.path = inner, outer, path
        self.force_feedforward = force_feedforward
        self.Ts = outer.Ts
        self._k = 0
        self.log: dict[str, list[FloatArray]] = {
            k: [] for k in ("pc", "dpc", "ddpc", "pd", "dpd", "ddpd", "qd", "force")
        }
        nan3 = np.full(3, math.nan)
        self.xc, self.xd, self.z1, self.force = nan3, nan3, nan3, nan3
        self.tau = np.full(outer.n, math.nan)
        self.q_d = outer.q0.copy()

    @property
    def ts(self) -> float:
        """Deprecated: the period is :attr:`Ts` (s)."""
        return period_alias(self)

    @property
    def params(self) -> dict[str, Any]:
        """The outer loop's target impedance and the inner controller's params."""
        p = getattr(self.inner, "params", {})
        return {
            "inner": dict(p) if isinstance(p, dict) else {},
            "Md": self.outer.Md.tolist(),
            "Bd": self.outer.Bd.tolist(),
            "Kd": self.outer.Kd.tolist(),
        }

    def step(
        self,
        q: ArrayLike,
        tau_e: ArrayLike,
        dq: ArrayLike | None = None,
        *,
        wrench: ArrayLike | None = None,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
    ) -> FloatArray:
        """One step at t_k = k·Ts; returns the joint controller's torque (N m), (n,).

        q (rad), tau_e = Jᵀ F_e (N m), dq (rad/s), each (n,); wrench [f; m]
        (N, N m), (6,) or f (3,) alone: required (the outer loop needs F_e);
        the Cartesian setpoint xc, dxc, ddxc (m, m/s, m/s²), (3,), or ``path``.
        """
        if wrench is None:
            raise ValueError("CartesianImpedance needs the measured wrench (wrench=[f; m] or f)")
        f = np.asarray(wrench, dtype=np.float64).reshape(-1)[:3]
        if xc is None:
            if self.path is None:
                raise ValueError("no Cartesian setpoint given and no path to follow")
            pc, dpc, ddpc = self.path(self._k * self.Ts)
        else:
            pc = np.asarray(xc, dtype=np.float64)
            dpc = np.zeros(3) if dxc is None else np.asarray(dxc, dtype=np.float64)
            ddpc = np.zeros(3) if ddxc is None else np.asarray(ddxc, dtype=np.float64)
        q_d, dq_d, ddq_d = self.outer.step(pc, dpc, ddpc, f)
        te = tau_e if self.force_feedforward else np.zeros(self.outer.n)
        out = np.asarray(self.inner.step(q, te, dq, xc=q_d, dxc=dq_d, ddxc=ddq_d))
        qm = np.asarray(q, dtype=np.float64)
        pd = self.outer.pd_k
        self.xc, self.xd, self.force, self.q_d = np.asarray(pc, dtype=np.float64), pd, f, q_d
        self.z1 = pd - np.asarray(self.outer.fk(qm), dtype=np.float64)
        self.tau = np.asarray(getattr(self.inner, "tau", out), dtype=np.float64)
        for key, v in zip(
            self.log, (pc, dpc, ddpc, pd, self.outer.dpd_k, self.outer.ddp_d, q_d, f), strict=True
        ):
            self.log[key].append(np.array(v, dtype=np.float64))
        self._k += 1
        return out

    def arrays(self) -> dict[str, FloatArray]:
        """The log as (K, ·) arrays: pc, dpc, ddpc, pd, dpd, ddpd, force (K, 3); qd (K, n)."""
        return {k: np.array(v, dtype=np.float64) for k, v in self.log.items()}


# ---------------------------------------------------------------------------
# Kinematics from Pinocchio.
# ---------------------------------------------------------------------------


def pinocchio_kinematics(
    model: Any = "panda", frame: str = "panda_hand_tcp"
) -> tuple[Fk, Jacobian, Any]:
    """fk, the position Jacobian (world-aligned, at the frame's origin) and the
    Pinocchio model, for :func:`adaptimp.baselines.pinocchio_model`'s ``model``."""
    import pinocchio as pin

    from .baselines import pinocchio_model

    m = pinocchio_model(model)
    data = m.createData()
    fid = m.getFrameId(frame)
    if fid >= m.nframes:
        raise ValueError(f"the model has no frame {frame!r}")

    def fk(q: FloatArray) -> FloatArray:
        pin.forwardKinematics(m, data, q)
        pin.updateFramePlacement(m, data, fid)
        return np.array(data.oMf[fid].translation, dtype=np.float64)

    def jacobian(q: FloatArray) -> FloatArray:
        j = pin.computeFrameJacobian(m, data, q, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        return np.array(j[:3], dtype=np.float64)

    return fk, jacobian, m


# ---------------------------------------------------------------------------
# The scenario "panda-table".
# ---------------------------------------------------------------------------


def _quintic(s: float) -> tuple[float, float, float]:
    """10s³ − 15s⁴ + 6s⁵ on [0, 1] (clamped) and its first two derivatives."""
    s = min(max(s, 0.0), 1.0)
    return (
        s**3 * (10 - 15 * s + 6 * s**2),
        30 * s**2 * (1 - s) ** 2,
        60 * s * (1 - s) * (1 - 2 * s),
    )


@dataclass
class PandaTable:
    """The scenario "panda-table" (:func:`panda_table`): everything a run needs.

    Attributes
    ----------
    model : mujoco.MjModel
        :func:`adaptimp.mujoco.panda` with the table's and the tool's sliding
        friction set to ``friction``.
    q0 : (7,)
        Start posture (rad): the SRDF's ``home``.
    fk, jacobian : callable
        The TCP's kinematics from Pinocchio (:func:`pinocchio_kinematics`).
    pin_model : pinocchio.Model
        The exact model (for D(q0) and :class:`~adaptimp.baselines.ComputedTorque`).
    Ts : float
        Controller period (s), 1 ms.
    radius, freq : float
        The circle's radius (m) and frequency (Hz).
    centre : (2,)
        The circle's centre (x, y) on the table (m).
    depth : float
        Commanded penetration δ_c (m): p_c,z is ``depth`` below the height at
        which the tool sphere touches the table (``surface_z``).
    surface_z : float
        TCP height (m) with the tool sphere resting on the table.
    t_approach, t_ramp : float
        The approach (quintic, from the home TCP to the circle's start point
        δ_c into the table) takes [0, t_approach) s; the circle's angular speed
        ramps from 0 to 2π·freq over [t_approach, t_approach + t_ramp) s.
    tau_max : (7,)
        Actuator limits (N m).
    """

    model: Any
    q0: FloatArray
    fk: Fk
    jacobian: Jacobian
    pin_model: Any
    Ts: float
    radius: float
    freq: float
    centre: FloatArray
    depth: float
    surface_z: float
    t_approach: float
    t_ramp: float
    tau_max: FloatArray
    p0: FloatArray = field(init=False)

    def __post_init__(self) -> None:
        self.p0 = self.fk(self.q0)

    @property
    def ts(self) -> float:
        """Deprecated: the period is :attr:`Ts` (s)."""
        return period_alias(self)

    @property
    def n(self) -> int:
        """Joints (7)."""
        return int(self.q0.shape[0])

    def path(
        self, t: float, depth: float | None = None
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The commanded TCP point p_c(t), ṗ_c, p̈_c (m, m/s, m/s²); ``depth``
        (m) overrides δ_c (0: the path on the table's surface)."""
        depth = self.depth if depth is None else depth
        r, w = self.radius, 2 * math.pi * self.freq
        start = np.array([self.centre[0] - r, self.centre[1], self.surface_z - depth])
        if t < self.t_approach:
            s, ds, dds = _quintic(t / self.t_approach)
            d = start - self.p0
            return self.p0 + s * d, ds * d / self.t_approach, dds * d / self.t_approach**2
        u = t - self.t_approach
        if u < self.t_ramp:
            v = u / self.t_ramp  # φ̇ = ω·quintic(v): φ = π + ω T_r (2.5v⁴ − 3v⁵ + v⁶)
            phi = math.pi + w * self.t_ramp * (2.5 * v**4 - 3 * v**5 + v**6)
            s, ds, _ = _quintic(v)
            dphi, ddphi = w * s, w * ds / self.t_ramp
        else:
            phi = math.pi + w * (0.5 * self.t_ramp + u - self.t_ramp)
            dphi, ddphi = w, 0.0
        c, sn = math.cos(phi), math.sin(phi)
        p = np.array([self.centre[0] + r * c, self.centre[1] + r * sn, start[2]])
        dp = np.array([-r * sn * dphi, r * c * dphi, 0.0])
        ddp = np.array([-r * sn * ddphi - r * c * dphi**2, r * c * ddphi - r * sn * dphi**2, 0.0])
        return p, dp, ddp

    def outer(self, config: OuterLoopConfig | None = None) -> OuterLoop:
        """A fresh :class:`OuterLoop` for this scenario (posture = q0)."""
        return OuterLoop(self.fk, self.jacobian, self.Ts, self.q0, config=config)

    def target_force(self, config: OuterLoopConfig | None = None) -> float:
        """The normal force (N) the target impedance prescribes against a rigid
        table in steady contact: K_d,z·δ_c (SPEC (16.1), k_e ≫ K_d)."""
        _, _, kd = (config or OuterLoopConfig()).arrays()
        return float(kd[2] * self.depth)


def panda_table(
    *,
    radius: float = 0.05,
    freq: float = 0.25,
    depth: float = 0.015,
    centre: tuple[float, float] = (0.40, 0.0),
    friction: float = 0.1,
    table_height: float = 0.45,
    tool_radius: float = 0.01,
    Ts: float = 1e-3,
    t_approach: float = 1.0,
    t_ramp: float = 1.0,
) -> PandaTable:
    """The scenario "panda-table": the Panda's tool draws a circle on a table,
    pressing on it through the target impedance (see :class:`PandaTable`).

    Defaults: a 5 cm circle at 0.25 Hz centred at (0.40, 0) m, δ_c = 15 mm
    into the table (7.5 N with K_d = 500 N/m), sliding friction 0.1 (the
    x-y admittance then yields ≤ μ F / K_d = 1.5 mm to it), table top 0.45 m
    above the base, 1 ms period. The circle is at full speed from t = 2 s.
    """
    import mujoco

    from . import _models
    from .mujoco import panda

    model = panda(table_height=table_height, tool_radius=tool_radius)
    for name in ("table", "tool"):
        gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
        model.geom_friction[gid, 0] = friction
    fk, jac, pin_model = pinocchio_kinematics("panda")
    return PandaTable(
        model=model,
        q0=np.array(_models.PANDA_HOME, dtype=np.float64),
        fk=fk,
        jacobian=jac,
        pin_model=pin_model,
        Ts=Ts,
        radius=radius,
        freq=freq,
        centre=np.array(centre, dtype=np.float64),
        depth=depth,
        surface_z=table_height + tool_radius,
        t_approach=t_approach,
        t_ramp=t_ramp,
        tau_max=np.array(_models.PANDA_EFFORT, dtype=np.float64),
    )


def orbit_basis(
    sc: PandaTable, nodes: int = 64, tube: tuple[float, float] = (0.05, 0.2)
) -> tuple[FloatArray, FloatArray]:
    """RBF centres along the joint orbit and their widths (SPEC §15).

    The outer loop runs once kinematically (F_e = 0) along the path on the
    table's surface (δ_c = 0: where the arm is while pressing with the target
    force, whereas the commanded path is δ_c below) from t = 0 over the
    approach, the ramp and one period of the circle; ``nodes`` samples evenly in
    time become the centres [q_d; q̇_d; 0; 0]. Widths per block (15.2):
    η_q = max(2 h_q, tube[0]) (rad), η_v = max(2 h_v, tube[1]) (rad/s), h_b the
    largest distance of consecutive samples in block b; α1 and α̇1 are left out
    (width +∞). Returns (centres (L, 4n), widths (4n,)).
    """
    outer = sc.outer()
    t_end = sc.t_approach + sc.t_ramp + 1.0 / sc.freq
    steps = round(t_end / sc.Ts)
    every = max(1, steps // nodes)
    qs: list[FloatArray] = []
    dqs: list[FloatArray] = []
    for k in range(steps):
        p, dp, ddp = sc.path(k * sc.Ts, depth=0.0)
        q, dq, _ = outer.step(p, dp, ddp, np.zeros(3))
        if k % every == 0 and len(qs) < nodes:
            qs.append(q)
            dqs.append(dq)
    n = sc.n
    qa, va = np.array(qs), np.array(dqs)
    hq = float(np.max(np.linalg.norm(np.diff(qa, axis=0), axis=1)))
    hv = float(np.max(np.linalg.norm(np.diff(va, axis=0), axis=1)))
    centres = np.hstack([qa, va, np.zeros((len(qa), 2 * n))])
    widths = np.concatenate(
        [np.full(n, max(2 * hq, tube[0])), np.full(n, max(2 * hv, tube[1])), np.full(2 * n, np.inf)]
    )
    return centres, widths


def joint_gains(sc: PandaTable, k1: float = 20.0, scale: float = 0.25) -> dict[str, list[float]]:
    """The joint gains shared by PD, state and output feedback (SPEC §15's rule):
    Kp_i = scale/(Ts (D⁻¹)_ii) (N m s/rad) with D the exact D(q0) from
    Pinocchio's CRBA, Kζ_i = (1 + Kp_i²)/2 + 10 (so 2Kζ − 1 − Kp² = 20 > 0),
    K1 = k1 (1/s)."""
    import pinocchio as pin

    data = sc.pin_model.createData()
    m = pin.crba(sc.pin_model, data, sc.q0)
    m = np.triu(m) + np.triu(m, 1).T
    kp = scale / (sc.Ts * np.diag(np.linalg.inv(m)))
    return {
        "Kp": kp.tolist(),
        "Kzeta": ((1 + kp**2) / 2 + 10).tolist(),
        "K1": [k1] * sc.n,
    }


def panda_controller(
    kind: str,
    sc: PandaTable,
    *,
    basis: tuple[FloatArray, FloatArray] | None = None,
    gains: dict[str, list[float]] | None = None,
    gamma: float | Sequence[float] = 1.0,
    ct_gains: tuple[float, float] = (400.0, 40.0),
    force_feedforward: bool = True,
    **params: Any,
) -> CartesianImpedance:
    """One of the five controllers of the comparison, with the outer loop in front.

    kind : {"pd", "sf", "of", "ct", "ct+30"}
        PD (Case 1), adaptive state (14) and output feedback (35), all
        ``adaptimp.Controller(kind, "robot", n=7, impedance="external")`` with
        ``gains`` (default :func:`joint_gains`), Γ = ``gamma`` for all three
        networks and the centres ``basis`` (default :func:`orbit_basis`); or
        computed torque with Pinocchio's exact model ("ct") or every link's mass
        and inertia +30 % ("ct+30"), K_P, K_D = ``ct_gains`` (1/s², 1/s).
    force_feedforward : bool
        Whether the joint controller gets τe (see :class:`CartesianImpedance`).
    **params
        Further parameters of ``adaptimp.Controller``.
    """
    if kind in ("ct", "ct+30"):
        from .baselines import ComputedTorque

        inner: Any = ComputedTorque(
            sc.pin_model,
            Ts=sc.Ts,
            Kp=ct_gains[0],
            Kd=ct_gains[1],
            tau_max=sc.tau_max,
            mass_scale=1.3 if kind == "ct+30" else 1.0,
            impedance="external",
        )
    elif kind in ("pd", "sf", "of"):
        from ._api import Controller

        centres, widths = orbit_basis(sc) if basis is None else basis
        g = joint_gains(sc) if gains is None else gains
        inner = Controller(
            kind,
            "robot",
            n=sc.n,
            centers=centres,
            widths=widths,
            impedance="external",
            Ts=sc.Ts,
            tau_max=sc.tau_max.tolist(),
            gamma=[float(gamma)] * 3 if isinstance(gamma, (int, float)) else list(gamma),
            **g,
            **params,
        )
    else:
        raise ValueError(f"kind must be one of pd, sf, of, ct, ct+30; got {kind!r}")
    return CartesianImpedance(
        inner, sc.outer(), lambda t: sc.path(t), force_feedforward=force_feedforward
    )


def cartesian_metrics(
    res: Any,
    ctrl: CartesianImpedance,
    sc: PandaTable,
    *,
    settle: float = 2.0,
    windup_after: float = 0.1,
) -> dict[str, float]:
    """The metrics of a panda-table run (``res`` from :func:`adaptimp.mujoco.simulate`).

    Over the rows with t ≥ ``settle`` (s), with p = the TCP (MuJoCo's site),
    ṗ = J(q) q̇, p̈ = J(q) q̈ + J̇ q̇ (q̈ MuJoCo's at the row's state and torque),
    p_d the controller's compliant reference and F_e its measured force:

    - ``rms_track`` (m): sqrt(mean ‖p_d − p‖²), the Cartesian tracking error.
    - ``rms_path_xy`` (m): sqrt(mean ‖(p_c − p)_xy‖²), the path on the table
      against the commanded circle.
    - ``rms_force`` (N): sqrt(mean (F_n − K_d,z δ_c)²), F_n = −F_e,z the normal
      force on the table, against the target's steady value (:meth:`PandaTable.target_force`).
    - ``rms_imp`` (N): sqrt(mean ‖M_d (p̈ − p̈_c) + B_d (ṗ − ṗ_c) + K_d (p − p_c) + F_e‖²),
      the residual of the target impedance (C1) at the arm's actual motion.
    - ``sat_duty``: fraction of all rows with sat(τ) ≠ τ on some joint.
    - ``peak_tau_ratio``: max over joints and rows with t ≥ ``windup_after`` of
      |τ_i| / τmax_i for the commanded τ (target ≤ 2: no windup).
    - ``applied_ratio``: the same for the applied sat(τ) over all rows (≤ 1).
    """
    log = ctrl.arrays()
    t = res.t
    after = t >= settle - 1e-9
    p = res.x_ee
    rows = np.flatnonzero(after)
    dp = np.empty((len(rows), 3))
    ddp = np.empty((len(rows), 3))
    for j, k in enumerate(rows):
        jac = sc.jacobian(res.q[k])
        dp[j] = jac @ res.dq[k]
        ddp[j] = jac @ res.ddq[k] + ctrl.outer.jdot_qdot(res.q[k], res.dq[k])
    md, bd, kd = ctrl.outer.Md, ctrl.outer.Bd, ctrl.outer.Kd
    f = log["force"][after]
    imp = md * (ddp - log["ddpc"][after]) + bd * (dp - log["dpc"][after])
    imp += kd * (p[after] - log["pc"][after]) + f

    def rms(x: FloatArray) -> float:
        return float(np.sqrt(np.mean(x))) if x.size else math.nan

    tau_max = np.asarray(res.params["tau_max"])
    late = t >= windup_after - 1e-9
    return {
        "rms_track": rms(np.sum((log["pd"][after] - p[after]) ** 2, axis=1)),
        "rms_path_xy": rms(np.sum((log["pc"][after, :2] - p[after, :2]) ** 2, axis=1)),
        "rms_force": rms((-f[:, 2] - float(kd[2]) * sc.depth) ** 2),
        "rms_imp": rms(np.sum(imp**2, axis=1)),
        "sat_duty": float(np.mean(np.any(res.tau_sat != res.tau, axis=1))),
        "peak_tau_ratio": float(np.max(np.abs(res.tau[late]) / tau_max)),
        "applied_ratio": float(np.max(np.abs(res.tau_sat) / tau_max)),
    }
