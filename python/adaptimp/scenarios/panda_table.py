"""The scenario "panda-table" (``docs/panda.md``, ``examples/13_panda_table.py``).

The Franka Emika Panda (example-robot-data's URDF) in MuJoCo draws a circle on
a table with its tool while pressing into it through the target impedance of
SPEC §16. Everything Cartesian runs in the core
(:class:`adaptimp.cartesian.CartesianController` over the Panda's
:class:`adaptimp.Chain`); this module only defines the task:

- :func:`panda_table` (:class:`PandaTable`): the model, the start, the path;
- :func:`orbit_basis`: RBF centres along the joint orbit (the core's rule);
- :func:`panda_controller`: the controllers compared, with the core's gain rule
  (:func:`rule_gains`);
- :func:`cartesian_metrics`: the table's metrics of a run.

MuJoCo and Pinocchio are imported when a function needs them.

Units: m, m/s, m/s², rad, rad/s, rad/s², N, N m, kg, s.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from .._errors import ConfigError
from ..chain import Chain

if TYPE_CHECKING:
    from ..cartesian import CartesianController, CartesianImpedance

__all__ = [
    "PandaTable",
    "cartesian_metrics",
    "orbit_basis",
    "panda_controller",
    "panda_table",
    "pinocchio_kinematics",
    "rule_gains",
    "table_metrics",
    "table_spring",
]

FloatArray = NDArray[np.float64]
Fk = Callable[[FloatArray], FloatArray]
"""fk(q) -> p (m), (3,): the end-effector point for the joint angles q (rad), (n,)."""
Jacobian = Callable[[FloatArray], FloatArray]
"""jacobian(q) -> J (m/rad), (3, n): the position Jacobian ∂p/∂q."""

POSITION_ONLY = {"Kd_rot": 0.0}
"""The scenario's outer loop: SPEC §16's defaults, position-only (the tool's
orientation is left to the null-space posture, as documented in docs/panda.md)."""


def pinocchio_kinematics(
    model: Any = "panda", frame: str = "panda_hand_tcp"
) -> tuple[Fk, Jacobian, Any]:
    """fk, the position Jacobian (world-aligned, at the frame's origin) and the
    Pinocchio model, for :func:`adaptimp.baselines.pinocchio_model`'s ``model``
    (an independent engine, to check :class:`adaptimp.Chain` against)."""
    import pinocchio as pin

    from ..baselines import pinocchio_model

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
    chain : Chain
        The Panda from its URDF to the TCP ``panda_hand_tcp`` (the core's kinematics).
    q0 : (7,)
        Start posture (rad): the SRDF's ``home``.
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
        δ_c into the table, or on its surface with ``t_press`` > 0) ends at
        t_approach s; the circle's angular speed ramps from 0 to 2π·freq over
        [t_approach, t_approach + t_ramp) s.
    tau_max : (7,)
        Actuator limits (N m).
    t_hold : float
        The path holds the home TCP over [0, t_hold) s, then approaches over
        [t_hold, t_approach) (default 0: the approach starts at once).
    t_press : float
        0 (default): the approach ends δ_c into the table, and the tool lands
        with the quintic's speed. > 0: the approach ends on the table's
        surface (the tool arrives at rest, touching), and the commanded depth
        then grows from 0 to δ_c over [t_approach, t_approach + t_press) s
        (a quintic): the force rises from zero instead of an impact.
    """

    model: Any
    chain: Chain
    q0: FloatArray
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
    t_hold: float = 0.0
    t_press: float = 0.0
    p0: FloatArray = field(init=False)

    def __post_init__(self) -> None:
        for name in ("t_hold", "t_press"):
            v = getattr(self, name)
            real = isinstance(v, numbers.Real) and not isinstance(v, bool)
            if not (real and math.isfinite(v) and v >= 0):
                raise ConfigError(f"{name} must be a finite number ≥ 0 (s), got {v!r}")
        if self.t_hold > 0 and self.t_hold >= self.t_approach:
            raise ConfigError(
                f"t_hold must end before the approach does (t_hold < t_approach), got "
                f"t_hold = {self.t_hold!r} and t_approach = {self.t_approach!r}"
            )
        self.p0 = self.fk(self.q0)

    @property
    def n(self) -> int:
        """Joints (7)."""
        return int(self.q0.shape[0])

    def fk(self, q: FloatArray) -> FloatArray:
        """The TCP's position (m), (3,), at q (the core's chain)."""
        return np.asarray(self.chain.fk(q)[:3, 3], dtype=np.float64)

    def jacobian(self, q: FloatArray) -> FloatArray:
        """The TCP's position Jacobian (m/rad), (3, 7), world-aligned (the core's chain)."""
        return np.asarray(self.chain.jacobian(q)[:3], dtype=np.float64)

    def path(
        self, t: float, depth: float | None = None
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The commanded TCP point p_c(t), ṗ_c, p̈_c (m, m/s, m/s²); ``depth``
        (m) overrides δ_c (0: the path on the table's surface)."""
        depth = self.depth if depth is None else depth
        r, w = self.radius, 2 * math.pi * self.freq
        soft = self.t_press > 0
        start = np.array([self.centre[0] - r, self.centre[1], self.surface_z - depth])
        if t < self.t_approach:
            if t < self.t_hold:
                return self.p0.copy(), np.zeros(3), np.zeros(3)
            span = self.t_approach - self.t_hold
            s, ds, dds = _quintic((t - self.t_hold) / span)
            d = start - self.p0
            if soft:  # to the surface: the depth comes after the approach
                d[2] += depth
            return self.p0 + s * d, ds * d / span, dds * d / span**2
        u = t - self.t_approach
        # The commanded depth: all of it at once, or pressed in over t_press.
        z, dz, ddz = start[2], 0.0, 0.0
        if soft:
            s, ds, dds = _quintic(u / self.t_press)
            z = self.surface_z - s * depth
            dz, ddz = -ds * depth / self.t_press, -dds * depth / self.t_press**2
        if u < self.t_ramp:
            v = u / self.t_ramp  # φ̇ = ω·quintic(v): φ = π + ω T_r (2.5v⁴ − 3v⁵ + v⁶)
            phi = math.pi + w * self.t_ramp * (2.5 * v**4 - 3 * v**5 + v**6)
            s, ds, _ = _quintic(v)
            dphi, ddphi = w * s, w * ds / self.t_ramp
        else:
            phi = math.pi + w * (0.5 * self.t_ramp + u - self.t_ramp)
            dphi, ddphi = w, 0.0
        c, sn = math.cos(phi), math.sin(phi)
        p = np.array([self.centre[0] + r * c, self.centre[1] + r * sn, z])
        dp = np.array([-r * sn * dphi, r * c * dphi, dz])
        ddp = np.array([-r * sn * ddphi - r * c * dphi**2, r * c * ddphi - r * sn * dphi**2, ddz])
        return p, dp, ddp

    def outer(self, **params: Any) -> CartesianImpedance:
        """A fresh outer loop for this scenario (the core's
        :class:`~adaptimp.cartesian.CartesianImpedance`, position-only, posture
        q0), with ``params`` of the group "cartesian"."""
        from ..cartesian import CartesianImpedance

        return CartesianImpedance(self.chain, Ts=self.Ts, q0=self.q0, **{**POSITION_ONLY, **params})

    def target_force(self, Kd: float = 500.0) -> float:
        """The normal force (N) the target impedance prescribes against a rigid
        table in steady contact: K_d,z·δ_c (SPEC (16.1), k_e ≫ K_d)."""
        return float(Kd * self.depth)


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

    from .. import _models
    from ..baselines import pinocchio_model
    from ..mujoco import panda

    model = panda(table_height=table_height, tool_radius=tool_radius)
    for name in ("table", "tool"):
        gid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, name)
        model.geom_friction[gid, 0] = friction
    return PandaTable(
        model=model,
        chain=Chain.from_urdf(_models.panda_urdf_path(), tip=_models.PANDA_EE),
        q0=np.array(_models.PANDA_HOME, dtype=np.float64),
        pin_model=pinocchio_model("panda"),
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
    """RBF centres along the joint orbit and their widths (SPEC §15), by the core's
    rule (:meth:`adaptimp.cartesian.CartesianImpedance.orbit_centres`).

    The scenario's outer loop runs kinematically (F_e = 0) along the path on the
    table's surface (δ_c = 0: where the arm is while pressing with the target
    force, whereas the commanded path is δ_c below) from t = 0 over the approach,
    the ramp and one period of the circle; ``nodes`` samples evenly in time
    become the centres. Returns (centres (L, 4n), widths (4n,)).
    """
    t_end = sc.t_approach + sc.t_ramp + 1.0 / sc.freq
    return sc.outer().orbit_centres(lambda t: sc.path(t, depth=0.0), t_end, nodes=nodes, tube=tube)


GAINS = ("Kp", "K1", "Kzeta", "inertia", "rho", "conditions", "kr", "fallback_damping")
"""The joint controller's gains the core's rule gives (SPEC (18.1)–(18.4)), the
default gains of :func:`panda_controller`."""


def rule_gains(sc: PandaTable) -> dict[str, Any]:
    """The core's gain rule for the scenario's arm (SPEC (18.1)–(18.4),
    :func:`adaptimp.tuning.suggest`): D(q0) from Pinocchio's CRBA on the
    arm's URDF (from MuJoCo's model for an MJCF arm), τmax, Ts; the keywords
    :data:`GAINS`."""
    from .. import mujoco as amj
    from .. import tuning

    model = sc.pin_model if sc.pin_model is not None else amj.Plant(sc.model)
    kw = tuning.suggest(model, sc.q0, sc.tau_max, Ts=sc.Ts)
    return {k: kw[k] for k in GAINS}


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
) -> CartesianController:
    """One of the five controllers of the comparison, with the outer loop in front.

    kind : {"pd", "sf", "of", "ct", "ct+30"}
        PD (Case 1), adaptive state (14) and output feedback (35), all
        ``adaptimp.Controller(kind, "robot", n=7, impedance="external")`` with
        ``gains`` (default :func:`rule_gains`, the core's rule), Γ = ``gamma`` for all three
        networks and the centres ``basis`` (default :func:`orbit_basis`); or
        computed torque with Pinocchio's exact model ("ct") or every link's mass
        and inertia +30 % ("ct+30"), K_P, K_D = ``ct_gains`` (1/s², 1/s).
    force_feedforward : bool
        Whether the joint controller gets τe (the schema's ``force_feedforward``).
    **params
        Further parameters of ``adaptimp.Controller`` and of the outer loop
        (group "cartesian"; the scenario's is position-only).
    """
    from ..cartesian import CartesianController

    common: dict[str, Any] = {
        "q0": sc.q0,
        "path": sc.path,
        "force_feedforward": force_feedforward,
        **POSITION_ONLY,
    }
    if kind in ("ct", "ct+30"):
        from ..baselines import ComputedTorque

        if sc.pin_model is None:
            raise ConfigError(
                f"{kind!r} needs the arm's Pinocchio model, which this scenario has only for "
                "a URDF arm"
            )
        inner = ComputedTorque(
            sc.pin_model,
            Ts=sc.Ts,
            Kp=ct_gains[0],
            Kd=ct_gains[1],
            tau_max=sc.tau_max,
            mass_scale=1.3 if kind == "ct+30" else 1.0,
            impedance="external",
        )
        return CartesianController(sc.chain, inner, **common, **params)
    if kind in ("pd", "sf", "of"):
        centres, widths = orbit_basis(sc) if basis is None else basis
        g: dict[str, Any] = dict(rule_gains(sc) if gains is None else gains)
        return CartesianController(
            sc.chain,
            kind,
            "robot",
            centers=centres,
            widths=widths,
            Ts=sc.Ts,
            tau_max=sc.tau_max.tolist(),
            gamma=[float(gamma)] * 3 if isinstance(gamma, (int, float)) else list(gamma),
            **g,
            **common,
            **params,
        )
    raise ValueError(f"kind must be one of pd, sf, of, ct, ct+30; got {kind!r}")


def _check_windows(t: FloatArray, **windows: float) -> None:
    """Refuse a window start (s) that is not a finite number ≥ 0, or that no
    row of the run reaches (its metrics would be means over no rows)."""
    for name, start in windows.items():
        if isinstance(start, bool) or not (
            isinstance(start, (int, float)) and math.isfinite(start) and start >= 0
        ):
            raise ConfigError(f"{name} must be a finite number ≥ 0 (s), got {start!r}")
    last = float(t[-1]) if t.size else math.nan
    for name, start in windows.items():
        if not (t.size and last >= start - 1e-9):
            span = f"its last row at t = {last:g} s" if t.size else "no rows"
            hint = (
                "or give a smaller settle"
                if name == "settle"
                else "peak_tau_ratio leaves out the start-up transient"
            )
            raise ConfigError(
                f"the metrics' window t ≥ {name} = {start:g} s holds no row of the run "
                f"({t.size} rows, {span}): run for longer than {start:g} s ({hint})"
            )


def cartesian_metrics(
    res: Any,
    ctrl: CartesianController,
    sc: PandaTable,
    *,
    settle: float = 2.0,
    windup_after: float = 0.1,
) -> dict[str, float]:
    """The metrics of a panda-table run (``res`` from :func:`adaptimp.mujoco.simulate`).

    Over the rows with t ≥ ``settle`` (s), with p = the TCP (MuJoCo's site),
    ṗ = J(q) q̇, p̈ = J(q) q̈ + J̇ q̇ (q̈ MuJoCo's at the row's state and torque;
    J and J̇ q̇ the core's chain), p_d the controller's compliant reference and
    F_e its measured force (the run's task-space rows, ``res.task``; the
    controller's log ``ctrl.arrays()`` if the run has none):

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

    A ``ConfigError`` if ``settle`` or ``windup_after`` is not a finite number
    ≥ 0, or if the run has no row in one of the windows (a run that ends
    before ``settle`` or ``windup_after``): its metrics would be empty.
    """
    m = table_metrics(res, ctrl, sc, settle=settle, windup_after=windup_after)
    return {
        "rms_track": m["rms_track"],
        "rms_path_xy": m["rms_path_xy"],
        "rms_force": m["rms_force"],
        "rms_imp": m["rms_imp"],
        "sat_duty": m["sat_duty"],
        "peak_tau_ratio": m["peak_tau_ratio"],
        "applied_ratio": m["applied_ratio"],
    }


def table_metrics(
    res: Any,
    ctrl: CartesianController,
    sc: PandaTable,
    *,
    settle: float = 2.0,
    windup_after: float = 0.1,
) -> dict[str, float]:
    """Every metric of a table run, computed once, in the core (SPEC (19.7),
    ``adaptimp._adaptimp.table_metrics``): the rows of ``res`` (the tip, its
    twist and acceleration along the chain, the run's task-space rows, the
    plant's normal force, τ and sat(τ)) against the controller's impedance
    and the scenario's depth (and its table's spring). :func:`cartesian_metrics`
    and :func:`adaptimp.scenarios.contact.contact_metrics` take their names
    from it. Refused as :func:`cartesian_metrics`."""
    from .. import _adaptimp

    t = np.ascontiguousarray(res.t, dtype=np.float64)
    _check_windows(t, settle=settle, windup_after=windup_after)
    log = ctrl.arrays() if getattr(res, "task", None) is None else res.task
    twist, accel = sc.chain.motion(
        np.ascontiguousarray(res.q), np.ascontiguousarray(res.dq), np.ascontiguousarray(res.ddq)
    )
    prm = ctrl.params
    md, kd = np.asarray(prm["Md"], dtype=np.float64), np.asarray(prm["Kd"], dtype=np.float64)
    bd = 2.0 * np.sqrt(kd * md) if prm["Bd"] is None else np.asarray(prm["Bd"], dtype=np.float64)
    spring = table_spring(sc)
    series = float(kd[2]) if spring is None else float(kd[2]) * spring / (float(kd[2]) + spring)

    def c(a: Any) -> FloatArray:
        return np.ascontiguousarray(a, dtype=np.float64)

    out: dict[str, float] = _adaptimp.table_metrics(
        t, c(res.x_ee), c(twist[:, :3]), c(accel[:, :3]), c(log["pd"]),
        (c(log["pc"]), c(log["dpc"]), c(log["ddpc"])), c(log["wrench"]),
        c(-np.asarray(res.wrench_ee)[:, 2]), (c(res.tau), c(res.tau_sat)),
        c(res.params["tau_max"]), (md.tolist(), bd.tolist(), kd.tolist()),
        float(sc.depth), series, (float(settle), float(windup_after),
        sc.t_approach + sc.t_press), float(sc.Ts),
    )  # fmt: skip
    return out


def table_spring(sc: PandaTable) -> float | None:
    """The table's spring stiffness k_e (N/m), None for a rigid table."""
    import mujoco

    j = mujoco.mj_name2id(sc.model, mujoco.mjtObj.mjOBJ_JOINT, "table_spring")
    return None if j < 0 else float(sc.model.jnt_stiffness[j])
