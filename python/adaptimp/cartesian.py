"""Cartesian impedance (SPEC §16): the compiled core's 6-D outer loop in front of a
joint controller, for any arm given as a :class:`~adaptimp.Chain`.

- :class:`CartesianController`: the controller a robot engineer specifies on
  the tip's pose: stiffness, damping and inertia for the translation and the
  rotation (per axis, world frame), a null-space posture, error clipping,
  filters on the target, the stiffness and the measured wrench. Its ``step(q,
  dq, wrench, …) -> tau`` runs the core's outer loop and, for a case name
  (``"pd"``, ``"sf"``, ``"of"``), the core's joint step with no Python in
  between; a joint controller written in Python (e.g.
  :class:`adaptimp.baselines.ComputedTorque`) can take its place, the outer
  loop still running in the core. It is a controller of
  :func:`adaptimp.mujoco.simulate`.
- :class:`CartesianImpedance`: the core's outer loop alone: commanded pose and
  measured wrench in, the joint reference (q_d, q̇_d, q̈_d) out; and the
  orbit-centre rule of SPEC §15 for a Cartesian path (:meth:`~CartesianImpedance.orbit_centres`).

Every parameter is declared once, in the core's schema (group ``"cartesian"``:
``Md``, ``Bd``, ``Kd``, ``Md_rot``, ``Bd_rot``, ``Kd_rot``, ``clik_kp``,
``clik_kd``, ``clik_lambda``, ``clik_lambda_rot``, ``null_k``, ``null_d``,
``pos_error_max``, ``rot_error_max``, ``target_filter``, ``force_filter``,
``force_feedforward``; ``adaptimp params`` lists them with units and defaults).
``Kd_rot = 0`` makes the loop position-only.

The scenarios over this API (the Panda drawing a circle on a table, the same
table for any arm) live in :mod:`adaptimp.scenarios`; this module imports none.

Sign convention (SPEC §4, §16): the wrench F_e = [f; m] (N, N m) is what the
tip exerts on the environment, world frame, the moment about the tip (pressing
down on a table: f_z < 0). Units: m, m/s, m/s², rad, rad/s, rad/s², N, N m, kg,
kg m², s.
"""

from __future__ import annotations

import contextlib
import math
import types
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._adaptimp import Measurement
from ._deprecated import old_cartesian_step, period_alias
from ._errors import ConfigError, MeasurementError
from ._inputs import reals
from ._params import BY_NAME, check_scenario, describe, resolve
from ._pose import CartesianStep, PoseTarget, call_shape
from .chain import Chain

__all__ = [
    "CartesianController",
    "CartesianImpedance",
    "CartesianStep",
    "Chain",
    "Path",
    "PoseTarget",
    "pose_target",
]

FloatArray = NDArray[np.float64]
Path = Callable[[float], Sequence[ArrayLike]]
"""path(t) -> (p_c, ṗ_c, p̈_c) (m, m/s, m/s², each (3,)), or with the rotation
(p_c, ṗ_c, p̈_c, R_c, ω_c, ω̇_c) (R_c (3, 3), world ← tip; ω_c, ω̇_c (3,), rad/s,
rad/s², world frame): the commanded pose at t (s)."""

_EYE = np.eye(3)


def _array(name: str, v: ArrayLike, shape: tuple[int, ...]) -> FloatArray:
    """``v`` as reals of exactly ``shape``, else an error naming ``name`` (no
    reshape: a flat (9,) R or a (2, 3) wrench is refused, not read; text,
    bools and complex numbers refused, not converted)."""
    a = reals(name, v, finite=False)
    if a.shape != shape:
        raise MeasurementError(f"{name} must have shape {shape}, got shape {a.shape}")
    return a


_POSE_NAMES = ("p", "dp", "ddp", "R", "w", "dw")

_CORE_POSE = ("p_c", "dp_c", "ddp_c", "R_c", "w_c", "dw_c")
"""The core's names of a pose target's parts (SPEC §16)."""

# Where each part of a flat target (24,) lies: p, ṗ, p̈ (3 each), R (9), ω, ω̇.
_SLICES = ((0, 3), (3, 6), (6, 9), (9, 18), (18, 21), (21, 24))


def _finite_pose(flat: FloatArray, names: Sequence[str]) -> None:
    """Every part of ``flat`` finite, else a MeasurementError naming the part as
    ``names`` do (the user's keywords) and its index."""
    bad = np.flatnonzero(~np.isfinite(flat))
    if bad.size:
        k = int(bad[0])
        part = next(i for i, (a, b) in enumerate(_SLICES) if a <= k < b)
        raise MeasurementError(
            f"{names[part]}[{k - _SLICES[part][0]}] is not finite (NaN or infinite)"
        )


def _as_given(e: MeasurementError, names: Sequence[str]) -> MeasurementError:
    """The core's refusal of a target, its parts named as the caller gave them
    (``xc``, not ``p_c``)."""
    import re

    mapping = dict(zip(_CORE_POSE, names))
    text = re.sub(
        r"(?<![A-Za-z_])(ddp_c|dp_c|p_c|dw_c|w_c|R_c)(?![A-Za-z_])",
        lambda m: mapping[m.group(1)],
        str(e),
    )
    return type(e)(text)


def _pose(values: Sequence[ArrayLike | None], names: Sequence[str] = _POSE_NAMES) -> FloatArray:
    """:func:`pose_target` of (p, dp, ddp, R, w, dw), each checked by the name in ``names``."""
    out = np.zeros(24)
    for i, (v, name) in enumerate(zip(values, names)):
        if i == 3:
            out[9:18] = (_EYE if v is None else _array(name, v, (3, 3))).ravel()
        elif v is not None:
            at = 3 * i if i < 3 else 18 + 3 * (i - 4)
            out[at : at + 3] = _array(name, v, (3,))
    return out


def pose_target(
    p: ArrayLike,
    dp: ArrayLike | None = None,
    ddp: ArrayLike | None = None,
    R: ArrayLike | None = None,
    w: ArrayLike | None = None,
    dw: ArrayLike | None = None,
) -> FloatArray:
    """The flat pose target (24,) the core takes: p_c, ṗ_c, p̈_c (m, m/s, m/s², (3,)
    each), R_c (3, 3) row-major (default the identity), ω_c, ω̇_c (rad/s, rad/s²,
    (3,)); rates default to 0. Another shape is a MeasurementError naming it."""
    return _pose((p, dp, ddp, R, w, dw))


def _wrench(wrench: ArrayLike | None) -> FloatArray:
    """F_e = [f; m] (6,) from (6,), f (3,) alone (no moment) or None (no contact)."""
    f = np.zeros(6)
    if wrench is not None:
        try:
            w = np.asarray(wrench, dtype=np.float64)
        except (TypeError, ValueError):
            raise TypeError(f"wrench must be an array of reals, got {wrench!r}") from None
        if w.shape not in ((3,), (6,)):
            raise MeasurementError(f"wrench must have shape (6,) or (3,), got shape {w.shape}")
        f[: w.shape[0]] = w
    return f


def _measured(
    n: int, m: Any, dq: ArrayLike | None, wrench: ArrayLike | None, q: ArrayLike | None
) -> tuple[Any, Any, Any]:
    """q, q̇ and the wrench of a Cartesian step: from an
    :class:`adaptimp.Measurement` ``m``, or the deprecated arrays (warned)."""
    if isinstance(m, Measurement):
        if dq is not None or wrench is not None or q is not None:
            raise TypeError(
                "CartesianController.step: give the measurement as an adaptimp.Measurement "
                "or as arrays, not both"
            )
        if m.n != n:
            raise MeasurementError(
                f"q must have shape ({n},) (one value per joint), got length {m.n}"
            )
        return m.q, m.dq, m.wrench
    if m is not None and q is not None:
        raise TypeError("CartesianController.step: q given twice (positionally and by keyword)")
    q = m if m is not None else q
    if q is None:
        raise TypeError(
            "CartesianController.step needs a measurement: "
            "step(adaptimp.Measurement(q, dq, wrench=…))"
        )
    old_cartesian_step()
    return q, dq, wrench


def _per_axis(name: str, v: ArrayLike) -> FloatArray:
    """A value per axis x, y, z: a scalar (every axis) or (3,), else a
    ConfigError naming ``name``."""
    try:
        a = np.asarray(v, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a real or 3 reals, got {v!r}") from None
    if a.shape not in ((), (3,)):
        raise ConfigError(
            f"{name} must be a scalar or have shape (3,) (x, y, z), got shape {a.shape}"
        )
    return np.broadcast_to(a, (3,)).copy()


def _pose_of(sample: Any, R: FloatArray) -> FloatArray:
    """A path's value (p, ṗ, p̈[, R, ω, ω̇]) as a flat target; a 3-tuple keeps R."""
    s = tuple(sample)
    names = tuple(f"path(t)[{i}]" for i in range(6))
    if len(s) == 3:
        return _pose((*s, R), names)
    if len(s) == 6:
        return _pose(s, names)
    raise ValueError(f"path(t) must return 3 or 6 arrays (p, dp, ddp[, R, w, dw]), got {len(s)}")


def tabulate(
    path: Path, steps: int, Ts: float, R: ArrayLike, *, start: int = 0, what: str = "path(t)"
) -> FloatArray:
    """The commanded pose of ``steps`` steps at t_k = (``start`` + k)·``Ts``, as
    the rows (steps, 24) of :func:`pose_target`: the one tabulation of a path
    (the outer loop's orbit, a run of the core's loop, a task's metrics).

    ``path(t)`` returns (p, ṗ, p̈) or (p, ṗ, p̈, R, ω, ω̇) (:data:`Path`); a
    3-tuple keeps the last rotation a 6-tuple gave (``R`` (3, 3) until one
    does). A path with a ``table(steps, Ts, start)`` method (the default task's,
    :func:`adaptimp.mujoco.cartesian_task`) tabulates itself in the core.
    """
    table = getattr(path, "table", None)
    if callable(table):
        return np.asarray(table(steps, Ts, start), dtype=np.float64)
    # The loop, the reads and the layout in the core; a value that is not a
    # float64 array of its shape goes through _array, which names it.
    r0 = np.asarray(R, dtype=np.float64).reshape(9)
    out: FloatArray = _adaptimp.tabulate_path(path, steps, Ts, r0, start, what, _array)
    return out


class CartesianImpedance:
    """The 6-D Cartesian impedance outer loop of SPEC §16 (C0)–(C4), in the core.

    At every step t_k, given the commanded pose (p_c, R_c) and its rates and the
    measured wrench F_e: the target filter (16.6), the target impedance (C1) on
    the clipped pose error (16.5) with the rotation error Log(R_t R_dᵀ) (16.2),
    the second-order CLIK with damped least squares and the null-space posture
    (C2), (C3), semi-implicit Euler (C4). Returns the joint reference
    (q_d, q̇_d, q̈_d) of t_k.

    Parameters
    ----------
    chain : Chain
        The arm's kinematics.
    Ts : float
        Period (s).
    q0 : (n,)
        Initial joint reference q_d(0) (rad): the measured start.
    posture : (n,), optional
        Null-space posture (rad); default q0.
    scenario : str
        Whose defaults (the Cartesian ones are the same in every scenario).
    **params
        The group "cartesian" of the schema (``Kd``, ``Kd_rot``, …).
        ``admittance_share`` applies to ``formulation="unified"`` only: given
        with another formulation it is a ``ConfigError`` naming both.
    """

    def __init__(
        self,
        chain: Chain,
        *,
        Ts: float,
        q0: ArrayLike,
        posture: ArrayLike | None = None,
        scenario: str = "robot",
        **params: Any,
    ) -> None:
        check_scenario(scenario)
        self.chain = chain
        self.params = resolve(
            params, scenario=scenario, groups=("cartesian",), caller="CartesianImpedance()"
        )
        if "admittance_share" in params and self.params["formulation"] != "unified":
            # The schema keeps a default share in every parameter set; one the
            # caller gives with another formulation would be ignored unseen.
            raise ConfigError(
                f"admittance_share = {params['admittance_share']!r} has no effect with "
                f"formulation={self.params['formulation']!r}: it is the admittance's share "
                "of the torque for formulation='unified' only (give formulation='unified', "
                "or leave admittance_share out)"
            )
        # Types here (text, bools, complex numbers), shapes and values by the core.
        self.q0 = reals("q0", q0, finite=False).copy()
        if posture is not None:
            posture = reals("posture", posture, finite=False)
        self._core = _adaptimp.CartesianImpedance(chain, self.params, float(Ts), self.q0, posture)
        self.Ts = float(Ts)
        self._R = chain.fk(self.q0)[:3, :3].copy()

    @property
    def ts(self) -> float:
        """Deprecated name of :attr:`Ts`."""
        return period_alias(self)

    @property
    def _R(self) -> FloatArray:
        """The commanded rotation a target without one keeps (3, 3), held by the core."""
        return np.asarray(self._core.held_rotation())

    @_R.setter
    def _R(self, R: ArrayLike) -> None:
        self._core.set_held_rotation(np.asarray(R, dtype=np.float64).reshape(9))

    @property
    def n(self) -> int:
        """Joints."""
        return int(self._core.n)

    @property
    def core(self) -> Any:
        """The compiled outer loop (``adaptimp._adaptimp.CartesianImpedance``)."""
        return self._core

    @property
    def orients(self) -> bool:
        """Whether the orientation is a task (False: position-only, ``Kd_rot = 0``)."""
        return bool(self._core.orients)

    def target(
        self,
        p: ArrayLike,
        dp: ArrayLike | None = None,
        ddp: ArrayLike | None = None,
        R: ArrayLike | None = None,
        w: ArrayLike | None = None,
        dw: ArrayLike | None = None,
    ) -> FloatArray:
        """:func:`pose_target`, with R the last commanded rotation when not given
        (initially the start's, fk(q0)). The core checks the target as a step
        would (a rotation that is not one, a value not finite or beyond its
        ceiling: MeasurementError); only a good R is kept as the last one."""
        out = self._target((p, dp, ddp, R, w, dw))
        try:
            self._core.check_target(out)
        except MeasurementError as e:
            raise _as_given(e, _POSE_NAMES) from None
        self._commit(out, R)
        return out

    def _target(
        self, values: Sequence[ArrayLike | None], names: Sequence[str] = _POSE_NAMES
    ) -> FloatArray:
        """The flat target of (p, dp, ddp, R, w, dw), R the last commanded one if
        None; nothing kept (see :meth:`_commit`)."""
        v = list(values)
        if v[3] is None:
            v[3] = self._R
        return _pose(v, names)

    def _commit(self, target: FloatArray | None, R: object) -> None:
        """After the core accepted ``target``: its rotation is the last commanded
        one if it set one (``R`` given, or a path's 6-tuple)."""
        if target is not None and R is not None:
            self._R = target[9:18].reshape(3, 3).copy()

    def step(
        self,
        p: ArrayLike | None = None,
        dp: ArrayLike | None = None,
        ddp: ArrayLike | None = None,
        *,
        R: ArrayLike | None = None,
        w: ArrayLike | None = None,
        dw: ArrayLike | None = None,
        wrench: ArrayLike | None = None,
        target: PoseTarget | None = None,
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """One committed step: the commanded pose (p_c (m); ṗ_c, p̈_c, R_c, ω_c,
        ω̇_c; None: hold the last), or a :class:`PoseTarget` ``target``, and
        F_e = [f; m] ((6,), or f (3,) alone; default 0) in; (q_d, q̇_d, q̈_d)
        of t_k out (rad, rad/s, rad/s²); the rest of the step by name in
        :attr:`output`."""
        if target is not None:
            if p is not None:
                raise TypeError("give the commanded pose as p=… or as target=…, not both")
            p, dp, ddp, R, w, dw = target.p, target.dp, target.ddp, target.R, target.w, target.dw
        flat = None if p is None else self._target((p, dp, ddp, R, w, dw))
        q, dq, ddq = self._core.reference(flat, _wrench(wrench))
        self._commit(flat, R)
        return q, dq, ddq

    def last(self, what: str) -> FloatArray:
        """A quantity of the last step (``q_d``, ``p_d``, ``R_d``, ``error``, …; see
        ``adaptimp._adaptimp.CartesianImpedance.last``)."""
        return np.asarray(self._core.last(what))

    @property
    def output(self) -> CartesianStep:
        """Every quantity of the last step by name, with its unit
        (:class:`CartesianStep`; NaN before a first step)."""
        return CartesianStep.of(self._core)

    def reset(self, q0: ArrayLike | None = None) -> None:
        """Back to t = 0 (at ``q0``, default the start's). A ``q0`` the core
        refuses (another shape, not finite, beyond 1e6 rad) changes nothing."""
        start = self.q0 if q0 is None else np.array(q0, dtype=np.float64)
        self._core.reset(start)
        self.q0 = start
        self._R = self.chain.fk(self.q0)[:3, :3].copy()

    def set_stiffness(self, Kd: ArrayLike, Kd_rot: ArrayLike | None = None) -> None:
        """Ask for the stiffness ``Kd`` (N/m) and ``Kd_rot`` (N m/rad; default
        unchanged): the impedance moves to it through the target filter, so the
        torque does not jump (SPEC (16.6))."""
        kd = _per_axis("Kd", Kd)
        kr = _per_axis("Kd_rot", self._core.state("stiffness")[3:] if Kd_rot is None else Kd_rot)
        self._core.set_stiffness(kd, kr)

    def set_posture(self, posture: ArrayLike) -> None:
        """The null-space posture q_posture (rad), (n,), from the next step on. The
        core refuses (ConfigError, nothing changed) one not finite, beyond 1e6
        rad, or farther from q_d than the posture task may pull (null_k·|q_posture
        − q_d| ≤ 1e6 rad/s², the ceiling of q̈_d)."""
        self._core.set_posture(posture)

    def orbit_centres(
        self,
        path: Path,
        T: float,
        *,
        nodes: int = 64,
        tube: tuple[float, float] = (0.05, 0.2),
        q0: ArrayLike | None = None,
    ) -> tuple[FloatArray, FloatArray]:
        """RBF centres along the joint orbit of a Cartesian path (SPEC §15, (15.2)).

        The core runs this outer loop kinematically (F_e = 0; this loop's state is
        unchanged) from ``q0`` (default the start's) along ``path`` sampled at
        k·Ts for t < ``T``, takes the joint reference [q_d; q̇_d] of ``nodes``
        steps evenly in time as centres, with widths per block η_q = max(2 h_q,
        tube[0]) (rad), η_v = max(2 h_v, tube[1]) (rad/s), h_b the largest
        spacing of consecutive samples, α1 and α̇1 left out (width ∞). Returns
        (centres (L, 4n), widths (4n,)) for ``adaptimp.Controller(centers=,
        widths=)``.
        """
        q, dq = self.joint_orbit(path, T, samples=nodes, q0=q0)
        centres, widths2 = _adaptimp.centres_along(q, dq, (float(tube[0]), float(tube[1])))
        return centres, np.sqrt(widths2)

    def joint_orbit(
        self, path: Path, T: float, *, samples: int, q0: ArrayLike | None = None
    ) -> tuple[FloatArray, FloatArray]:
        """The joint reference (q_d, q̇_d) (rad, rad/s), each (``samples``, n), at
        ``samples`` steps evenly in time of this outer loop run kinematically
        (F_e = 0; its state unchanged) from ``q0`` (default the start's) along
        ``path`` sampled at k·Ts for t < ``T`` (the core's orbit; ``samples`` =
        round(T/Ts): every step)."""
        q, dq, _ = self.joint_path(path, T, samples=samples, q0=q0)
        return q, dq

    def joint_path(
        self, path: Path, T: float, *, samples: int, q0: ArrayLike | None = None
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """:meth:`joint_orbit` with the accelerations: (q_d, q̇_d, q̈_d) (rad,
        rad/s, rad/s²), each (``samples``, n), q̈_d the inverse kinematics' own
        (C2)."""
        # T (1 … 1e6 periods) and samples (an integer ≥ 1), refused by name
        # before the path is tabulated.
        steps, samples = self._core.orbit_size(T, samples)
        start = self.q0 if q0 is None else np.asarray(q0, dtype=np.float64)
        table = tabulate(path, steps, self.Ts, self.chain.fk(start)[:3, :3])
        q, dq, ddq = self._core.orbit(start, table, samples)
        return tuple(np.asarray(a, dtype=np.float64) for a in (q, dq, ddq))  # type: ignore[return-value]


class CartesianController:
    """SPEC §16's 6-D Cartesian impedance: the core's outer loop and a joint controller.

    Parameters
    ----------
    chain : Chain
        The arm's kinematics (:meth:`Chain.from_urdf`, :meth:`Chain.from_mujoco`).
    controller : {"pd", "sf", "of"} or joint controller
        A case name builds ``adaptimp.Controller(controller, scenario, n=chain.n,
        impedance="external", centers=, widths=, **controller parameters)``, and
        each step is the core's (outer loop and joint step in one call). Or a
        joint controller written in Python with ``step(q, tau_e, dq, *, xc, dxc,
        ddxc)``, ``impedance = "external"`` and the period ``ts``/``Ts`` (e.g.
        ``ComputedTorque(..., impedance="external")``): the core's outer loop
        hands it its reference.
    scenario : {"robot", "paper"}
        The defaults of a case name's controller.
    q0 : (n,)
        The start (rad): the outer loop's q_d(0) and (default) posture.
    posture : (n,), optional
        The null-space posture (rad); default q0.
    path : callable, optional
        :data:`Path`, the commanded pose when a step is given none; without it a
        step without a target holds the last one (at first the start pose).
    centers, widths : array_like, optional
        RBF centres and widths of a case name's controller (see
        :meth:`CartesianImpedance.orbit_centres`).
    record : bool
        Keep every step's p_c, ṗ_c, p̈_c, p_d, ṗ_d, p̈_d, q_d, F_e (:meth:`arrays`).
    **params
        The Cartesian parameters (group "cartesian": ``Kd``, ``Kd_rot``,
        ``force_feedforward``, …) and, for a case name, the joint controller's
        (``Ts``, ``Kp``, ``tau_max``, ``gamma``, …).

    Notes
    -----
    The :func:`adaptimp.mujoco.simulate` protocol: ``task_space = True``, so it
    reads the measurement's wrench; ``step(m, xc=, dxc=, ddxc=)``; ``.Ts``; after a step
    ``xc``, ``dxc``, ``ddxc`` = p_c, ṗ_c, p̈_c (the commanded position and its
    rates; when no target is given, the held target after its filter, p_t, at
    rest), ``xd`` = p_d (the compliant reference), ``z1`` = p_d − p(q) (m,
    (3,)), ``tau`` (the joint controller's commanded τ, N m), ``q_d``,
    ``force`` (f, N); ``zeta`` and ``dq_hat`` are the joint controller's (if it
    has them). With a case name's joint controller, :func:`adaptimp.mujoco.simulate`
    runs the whole loop in the core (the path or the reference tabulated
    first, at the loop's t_k); afterwards the controller is as after the same
    steps taken one by one (its log holds the run's kept rows).

    Examples
    --------
    >>> import adaptimp
    >>> arm = adaptimp.Chain(
    ...     [
    ...         {"kind": "revolute", "axis": [0, 0, 1]},
    ...         {"kind": "revolute", "xyz": [0.3, 0, 0], "axis": [0, 0, 1]},
    ...     ],
    ...     tip={"xyz": [0.2, 0, 0]},
    ... )
    >>> ctrl = adaptimp.CartesianController(
    ...     arm, "pd", q0=[0.3, 0.6], Kd_rot=0.0, tau_max=20.0, Kp=5.0, Kzeta=25.0
    ... )
    >>> tau = ctrl.step(adaptimp.Measurement([0.3, 0.6], [0.0, 0.0]))
    >>> tau.shape
    (2,)
    """

    task_space = True

    def __init__(
        self,
        chain: Chain,
        controller: Any = "sf",
        scenario: str = "robot",
        *,
        q0: ArrayLike,
        posture: ArrayLike | None = None,
        path: Path | None = None,
        centers: ArrayLike | None = None,
        widths: ArrayLike | None = None,
        record: bool = True,
        **params: Any,
    ) -> None:
        from ._api import Controller

        check_scenario(scenario)
        cart = {k: v for k, v in params.items() if k in BY_NAME and BY_NAME[k].group == "cartesian"}
        joint = {k: v for k, v in params.items() if k not in cart}
        if isinstance(controller, str):
            if joint.get("impedance", "external") != "external":
                raise ConfigError(
                    "the joint controller of a Cartesian impedance has impedance='external' "
                    "(the Cartesian impedance is the only one, SPEC §16)"
                )
            joint["impedance"] = "external"
            # The chain fixes n; an n given too (e.g. in tuning.suggest's keywords) must agree.
            n = joint.pop("n", chain.n)
            if n != chain.n:
                raise ConfigError(f"n = {n!r}, but the chain has {chain.n} joints")
            inner: Any = Controller(
                controller,
                scenario,
                n=chain.n,
                centers=centers,
                widths=widths,
                **joint,
            )
            self._core_inner = True
            self._joint: Any = inner
        else:
            if joint or centers is not None or widths is not None:
                raise TypeError(
                    f"parameters {sorted(joint)} of a joint controller apply to a case name "
                    "only; configure the controller object itself"
                )
            mode = getattr(controller, "impedance", None) or inner_params(controller).get(
                "impedance"
            )
            if mode != "external":
                raise ConfigError(
                    f"the joint controller must have impedance='external' (SPEC §16), got {mode!r}"
                )
            inner = controller
            # A joint controller the core steps (computed torque, SPEC §20).
            core_joint = getattr(controller, "_core_joint", None)
            self._core_inner = isinstance(core_joint, _adaptimp.ComputedTorque)
            self._joint = core_joint if self._core_inner else controller
            # A joint controller written in Python: called as the protocol says.
            self._inner_measurement = self._core_inner or call_shape(controller) == "measurement"
        Ts = getattr(inner, "Ts", None)
        if Ts is None:
            raise TypeError(f"the joint controller {inner!r} has no period .Ts (s)")
        self.inner = inner
        self.outer = CartesianImpedance(chain, Ts=float(Ts), q0=q0, posture=posture, **cart)
        self.chain = chain
        self._path, self._record = path, bool(record)
        self._Ts = float(Ts)
        self._tau = np.full(chain.n, math.nan)
        self._log: dict[str, list[FloatArray]] = {k: [] for k in _LOG}
        self._bind()

    def _bind(self) -> None:
        """The per-sample step as the core's own method (docs/performance.md):
        ``step(m)`` goes from the call to the core with no Python frame
        between; any other call is :meth:`step`'s. A subclass's own ``step``
        is left as it is."""
        if type(self).step is not CartesianController.step:
            return
        joint = self._joint if self._core_inner else None
        # Any call but step(m) goes on to the method below, as written in Python.
        other = types.MethodType(CartesianController.step, self)
        bound = _adaptimp.CartesianStep(self.outer.core, joint, self._path, other, self._record)
        self.step = bound.step  # type: ignore[method-assign]

    @property
    def path(self) -> Path | None:
        """The commanded pose's path ``path(t) -> (p, ṗ, p̈[, R, ω, ω̇])``, called
        at t_k by a step given no pose (None: the last target held)."""
        return self._path

    @path.setter
    def path(self, path: Path | None) -> None:
        self._path = path
        self._bind()

    @property
    def record(self) -> bool:
        """Whether each step's row is kept for :attr:`log` and :meth:`arrays`."""
        return self._record

    @record.setter
    def record(self, record: bool) -> None:
        self._record = bool(record)
        self._bind()

    @property
    def _k(self) -> int:
        """Steps taken: the outer loop's clock, t_k = k·Ts."""
        return int(self.outer.core.steps)

    @classmethod
    def from_rule(
        cls,
        chain: Chain,
        controller: str,
        path: Path,
        q0: ArrayLike,
        *,
        model: Any,
        tau_max: ArrayLike | None = None,
        span: float | None = None,
        Ts: float = 1e-3,
        delay: int = 0,
        **params: Any,
    ) -> CartesianController:
        """The Cartesian controller of a case name built by the core's rule
        (SPEC §16 (16.10), §18): nothing set per arm.

        The outer loop (the schema's Cartesian defaults; position-only for an
        arm of fewer than six joints, which cannot hold an orientation) runs
        kinematically from ``q0`` along ``path`` over its ``span`` (the
        hold, the ramp and one period of a periodic path); the joint rule
        then takes D and G from ``model``, the actuators' ``tau_max`` and that
        joint path (q_d, q̇_d, q̈_d of every step): the gains (18.1)–(18.4)
        with the inertia scales the smallest along the path (16.12), the
        centres along the joint orbit with the tube narrowed to the orbit
        (16.10), the learning (18.6)–(18.8).

        The start must pass the posture rule along that joint path, the one
        check :func:`adaptimp.mujoco.cartesian_task` and the table scenario
        apply (SPEC (16.9): σmin(J), the joint limits with their margin,
        gravity within the actuators, the velocity loop's conditioning at
        K1·Ts/m of the controller built, the path within 1 mm; for an
        ``adaptimp.mujoco.Plant`` the arm free of collisions), or a
        ``ConfigError`` names the condition, its bound and the value.

        Parameters
        ----------
        chain : Chain
            The arm's kinematics, to the point the task moves.
        controller : {"pd", "sf", "of"}
            The joint controller's case.
        path : callable
            :data:`Path`, the commanded pose (m, rad; world frame).
        q0 : (n,)
            The start posture (rad), an inverse-kinematics solution of
            ``path(0)``.
        model
            What gives D(q) and G(q): an ``adaptimp.mujoco.Plant``, a
            Pinocchio ``Model``, an object with ``D(q)`` and ``G(q)``
            (:func:`adaptimp.tuning.inertia`, :func:`adaptimp.tuning.gravity`).
        tau_max : (n,), optional
            Actuator limits (N m); default ``model.tau_max``.
        span : float, optional
            The part of the path the rule samples (s); default ``path.span``
            (the default task's: hold + ramp + one period).
        Ts : float
            The period (s).
        delay : int
            The loop's delay (periods) the rule sizes the joint gains for,
            SPEC (18.11) (libfranka: 1); the joint controller's ``delay``.
        **params
            Replace the rule's keywords (Cartesian parameters, e.g. ``Kd``,
            and the joint controller's, e.g. ``gamma``). ``gravity="model"``:
            the joint controller feeds ``model``'s gravity forward, SPEC
            (20.10) (an ``adaptimp.mujoco.Plant``; or give the description
            itself, ``gravity=PATH``), for a robot that does not compensate it.

        Raises
        ------
        ConfigError
            ``q0`` cannot run the path (the condition with its bound and the
            value measured), or a keyword is refused.
        """
        from . import _posture, tuning

        if params.get("gravity") == "model":
            if not hasattr(model, "_qadr"):
                raise ConfigError(
                    "gravity='model' reads the model's description from an "
                    "adaptimp.mujoco.Plant: give the arm's file itself, gravity=PATH"
                )
            params = {**params, "gravity": model}
        if not isinstance(controller, str):
            raise TypeError(
                f"from_rule builds a case name's controller ('pd', 'sf', 'of'), got {controller!r}"
            )
        q0 = np.asarray(q0, dtype=np.float64)
        span = getattr(path, "span", None) if span is None else span
        if (
            span is None
            or isinstance(span, bool)
            or not (
                isinstance(span, (int, float, np.floating)) and math.isfinite(span) and span > 0
            )
        ):
            raise ConfigError(
                f"span must be a finite number > 0 (s): the part of the path the rule samples "
                f"(the path has no .span); got {span!r}"
            )
        limits = getattr(model, "tau_max", None) if tau_max is None else tau_max
        if limits is None:
            raise ConfigError("tau_max (N m) is needed: the model has no .tau_max")
        cart = {k: v for k, v in params.items() if k in BY_NAME and BY_NAME[k].group == "cartesian"}
        if chain.n < 6:
            cart.setdefault("Kd_rot", 0.0)
        outer = CartesianImpedance(chain, Ts=Ts, q0=q0, **cart)
        steps = round(float(span) / Ts)
        q, dq, ddq = outer.joint_path(path, steps * Ts, samples=steps)
        # A Plant's state as the caller left it, whatever the check and the rule
        # read D and G at.
        kept = getattr(model, "state_kept", None)
        with kept() if callable(kept) else contextlib.nullcontext():
            # The one posture check (SPEC (16.9)) along the joint path, at the K1
            # of the controller built (the rule's, or the one given); a start
            # given: gravity within the actuators.
            idx = _posture.checked_rows(q.shape[0])
            targets = tabulate(path, steps, Ts, chain.pose(q0)[1])[idx, 0:3]
            k1 = params.get("K1")
            a = _posture.assess(
                model, chain, q0, q[idx], targets, orients=outer.orients,
                k1=None if k1 is None else float(np.min(np.asarray(k1, dtype=np.float64))),
                Ts=Ts, load=_posture.GIVEN_LOAD, tau_max=limits,
            )  # fmt: skip
            if a["error"] is not None:
                raise ConfigError(f"q0 cannot run the path: {a['error']}")
            kw = tuning.suggest(
                model, q0, limits, Ts=Ts, path=np.hstack([q, dq, ddq]), period=steps * Ts,
                case=controller, resolve=True, delay=delay,
            )  # fmt: skip
        kw.pop("n")
        joint = {k: v for k, v in params.items() if k not in cart}
        centres, widths = (
            joint.pop("centers", kw.pop("centers")),
            joint.pop("widths", kw.pop("widths")),
        )
        kw.update(joint)
        return cls(
            chain, controller, "robot", q0=q0, path=path, centers=centres, widths=widths,
            **cart, **kw,
        )  # fmt: skip

    @property
    def Ts(self) -> float:
        """Period Ts (s)."""
        return self._Ts

    @property
    def ts(self) -> float:
        """Deprecated name of :attr:`Ts`."""
        return period_alias(self)

    @property
    def zeta(self) -> FloatArray:
        """The joint controller's auxiliary state ζ now (N m), (n,) (AttributeError
        if it has none)."""
        return np.asarray(self.inner.zeta, dtype=np.float64)

    @property
    def dq_hat(self) -> FloatArray:
        """The velocity the joint controller used in the last step (rad/s), (n,)
        (AttributeError if it does not say)."""
        return np.asarray(self.inner.dq_hat, dtype=np.float64)

    @property
    def n(self) -> int:
        """Joints."""
        return self.chain.n

    def _last(self, what: str) -> FloatArray:
        return np.asarray(self.outer.core.last(what), dtype=np.float64)

    @property
    def output(self) -> CartesianStep:
        """Every quantity of the last step by name, with its unit
        (:class:`CartesianStep`; NaN before a first step)."""
        return CartesianStep.of(self.outer.core)

    @property
    def xc(self) -> FloatArray:
        """The last step's commanded position p_c (m), (3,) (NaN before a step)."""
        return self._last("p_c")

    @property
    def dxc(self) -> FloatArray:
        """The last step's ṗ_c (m/s), (3,)."""
        return self._last("dp_c")

    @property
    def ddxc(self) -> FloatArray:
        """The last step's p̈_c (m/s²), (3,)."""
        return self._last("ddp_c")

    @property
    def xd(self) -> FloatArray:
        """The last step's compliant reference p_d (m), (3,)."""
        return self._last("p_d")

    @property
    def z1(self) -> FloatArray:
        """The last step's p_d − p(q) (m), (3,)."""
        return self._last("p_d") - self._last("p")

    @property
    def force(self) -> FloatArray:
        """The last step's measured force f (N), (3,)."""
        return self._last("wrench")[:3]

    @property
    def q_d(self) -> FloatArray:
        """The joint reference q_d of the last step (rad), (n,) (q0 before one)."""
        q = self._last("q_d")
        return self.outer.q0.copy() if np.isnan(q).all() else q

    @property
    def tau(self) -> FloatArray:
        """The last step's commanded τ of the joint controller (N m), (n,)."""
        return self._last("tau") if self._core_inner else self._tau

    @property
    def log(self) -> dict[str, list[FloatArray]]:
        """The kept rows, per quantity (see :meth:`arrays`): lists of rows or blocks."""
        rows = self.outer.core.take_log()
        if len(rows):
            n = self.chain.n
            cuts = np.cumsum([3, 3, 3, 3, 3, 3, n, 6])
            for key, block in zip(_LOG, np.split(rows, cuts, axis=1)):
                self._log[key].append(block)
        return self._log

    @property
    def params(self) -> dict[str, Any]:
        """The Cartesian parameters, and the joint controller's under ``"inner"``."""
        p = inner_params(self.inner)
        return {**self.outer.params, "inner": dict(p)}

    def reset(self) -> None:
        """Back to t = 0: the outer loop at its start, the joint controller reset
        (if it has ``reset``), the log emptied."""
        self.outer.reset()
        reset = getattr(self.inner, "reset", None)
        if callable(reset):
            reset()
        for v in self.log.values():
            v.clear()

    def step(
        self,
        m: Measurement | ArrayLike | None = None,
        dq: ArrayLike | None = None,
        wrench: ArrayLike | None = None,
        *,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
        R: ArrayLike | None = None,
        w: ArrayLike | None = None,
        dw: ArrayLike | None = None,
        target: PoseTarget | None = None,
        q: ArrayLike | None = None,
    ) -> FloatArray:
        """One step at t_k = k·Ts; returns the torque to apply (N m), (n,).

        ``m`` is an :class:`adaptimp.Measurement`: q (rad), dq (rad/s) (n,),
        and the wrench F_e = [f; m] (N, N m), (6,) (f (3,) alone: no moment;
        None: no contact); its tau_e is not read (the step maps the wrench to
        the joints itself). The commanded pose: ``xc`` = p_c (m), ``dxc``,
        ``ddxc`` (m/s, m/s²), ``R`` (3, 3), ``w``, ``dw`` (rad/s, rad/s²),
        each optional (R: the last commanded rotation), or all of it as a
        :class:`PoseTarget` ``target``; without either the ``path`` at t_k,
        or the last target held. The rest of the step by name:
        :attr:`output`. ``step(q, dq, wrench)`` works, with a
        ``DeprecationWarning``.
        """
        measured: Any
        if self._core_inner and type(m) is Measurement and dq is wrench is q is None:
            measured = m  # the core reads it itself: no arrays made here
        else:
            q, dq, wrench = _measured(self.chain.n, m, dq, wrench, q)
            measured = q
        names = ("xc", "dxc", "ddxc", "R", "w", "dw")
        if target is not None:
            if xc is not None:
                raise TypeError("give the commanded pose as xc=… or as target=…, not both")
            if not isinstance(target, PoseTarget):
                raise TypeError(f"target must be a PoseTarget, got {type(target).__name__}")
            xc, dxc, ddxc, R, w, dw = target.p, target.dp, target.ddp, target.R, target.w, target.dw
            names = ("target.p", "target.dp", "target.ddp", "target.R", "target.w", "target.dw")
        given: FloatArray | None = None
        if xc is not None:
            # Read here, each part named as given (the core reads p_c, R_c, …).
            given = self.outer._target((xc, dxc, ddxc, R, w, dw), names)
            _finite_pose(given, names)
            sample: Any = given
        elif self.path is not None:
            sample = self.path(self._k * self._Ts)
            if sample is None:  # held silently before (the core's step refuses it too)
                raise TypeError(
                    "a path returns (p, dp, ddp) or (p, dp, ddp, R, w, dw) (a tuple of arrays), "
                    "got NoneType"
                )
        else:
            sample = None
        if self._core_inner:
            # One call of the core: the pose and wrench read, the step, the row kept.
            core = self.outer.core
            try:
                out: FloatArray = core.step_sample(
                    self._joint, measured, dq, wrench, sample, self.record
                )
            except MeasurementError as e:
                if given is None:
                    raise
                raise _as_given(e, names) from None
            return out
        f = _wrench(wrench)
        # The rotation a target sets is kept only once the core accepted the step.
        flat: FloatArray | None = None
        turned: object = None
        if given is not None:
            flat, turned = given, R
        elif sample is not None:
            flat = _pose_of(sample, self.outer._R)
            turned = True
        core = self.outer.core
        try:
            out = core.step_python(self.inner, q, dq, f, flat, measurement=self._inner_measurement)
        except MeasurementError as e:
            if given is None:
                raise
            raise _as_given(e, names) from None
        self._tau = np.asarray(getattr(self.inner, "tau", out), dtype=np.float64)
        self.outer._commit(flat, turned)
        if self.record:
            for key, v in zip(
                _LOG,
                (
                    self.xc,
                    self.dxc,
                    self.ddxc,
                    self.xd,
                    core.last("dp_d"),
                    core.last("ddp_d"),
                    self.q_d,
                    f,
                    core.last("error"),
                ),
            ):
                self._log[key].append(np.array(v, dtype=np.float64))
        return np.asarray(out)

    def arrays(self) -> dict[str, FloatArray]:
        """The log as (K, ·) arrays: pc, dpc, ddpc (the commanded position and its
        rates, as ``xc``, ``dxc``, ``ddxc``), pd, dpd, ddpd (K, 3); qd (K, n);
        wrench, error (K, 6)."""
        n = self.chain.n
        width = {"qd": n, "wrench": 6, "error": 6}
        # Each entry of the log is a step's row, or a block of rows (a run of the core's loop).
        return {
            k: np.vstack(v) if v else np.zeros((0, width.get(k, 3))) for k, v in self.log.items()
        }

    def _targets(
        self,
        steps: int,
        reference: Callable[[float], Sequence[ArrayLike]] | Sequence[FloatArray] | None,
    ) -> FloatArray | None:
        """The commanded pose of the next ``steps`` steps at t_k = k·Ts of a loop,
        (steps, 24), as :meth:`step` would take them one by one: ``reference(t_k)``
        or the row k of a tabulated reference (xc, dxc, ddxc) (position, rates;
        the rotation held), else the path on this controller's clock, else None
        (the last target held)."""
        path = self.path
        if reference is None and path is None:
            return None
        if reference is not None and not callable(reference):
            out = np.zeros((steps, 24))
            out[:, 9:18] = self.outer._R.ravel()
            for i in range(3):
                out[:, 3 * i : 3 * i + 3] = reference[i][:steps]
            return out
        if reference is not None:
            return tabulate(reference, steps, self.Ts, self.outer._R, what="reference(t)")
        assert path is not None
        return tabulate(path, steps, self.Ts, self.outer._R, start=self._k)

    def _ran(self, targets: FloatArray | None, task: dict[str, FloatArray] | None, k0: int) -> None:
        """After a run of the core's loop (:func:`adaptimp.mujoco.simulate`) along
        ``targets`` (of :meth:`_targets`), whole or stopped by an error: the clock,
        the held rotation and the attributes as after the steps it took; the log
        extended by the run's kept rows ``task`` (None: none); ``k0`` the steps
        taken before it."""
        if self._k > k0 and targets is not None and self.path is not None:
            self.outer._R = targets[self._k - k0 - 1, 9:18].reshape(3, 3).copy()
        if self.record and task is not None and len(task["pc"]):
            log = self.log
            for key in _LOG:
                log[key].append(task[key])

    def __repr__(self) -> str:
        kind = "position-only" if not self.outer.orients else "6-D"
        inner = getattr(self.inner, "case", type(self.inner).__name__)
        return (
            f"adaptimp.CartesianController({self.chain.source}, {inner!r}): {kind}, "
            f"Ts = {self.Ts:g} s, {self._k} steps"
        )


_LOG = ("pc", "dpc", "ddpc", "pd", "dpd", "ddpd", "qd", "wrench", "error")

_PARAMS_DOC = (
    "\n    Cartesian parameters by name (unit; default)\n"
    "    --------------------------------------------\n"
)
CartesianController.__doc__ = (
    (CartesianController.__doc__ or "") + _PARAMS_DOC + describe("cartesian", scenario="robot")
)


def inner_params(inner: Any) -> dict[str, Any]:
    """A joint controller's ``params`` dict (empty if it has none)."""
    p = getattr(inner, "params", None)
    return dict(p) if isinstance(p, dict) else {}
