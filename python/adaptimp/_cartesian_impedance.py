"""The core's 6-D outer loop alone (SPEC §16): :class:`CartesianImpedance`
(commanded pose and measured wrench in, the joint reference out; the
orbit-centre rule of SPEC §15 for a Cartesian path), and the conversions of a
commanded pose and a measured wrench into the core's flat layout
(:func:`pose_target`, :func:`tabulate`) that it and
:class:`adaptimp.CartesianController` share.

Re-exported by :mod:`adaptimp.cartesian`. Units: m, m/s, m/s², rad, rad/s,
rad/s², N, N m, s."""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._adaptimp import Measurement
from ._deprecated import old_cartesian_step, period_alias
from ._errors import ConfigError, MeasurementError
from ._inputs import reals
from ._params import check_scenario, resolve
from ._pose import CartesianStep, PoseTarget
from .chain import Chain

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


def finite_pose(flat: FloatArray, names: Sequence[str]) -> None:
    """Every part of ``flat`` finite, else a MeasurementError naming the part as
    ``names`` do (the user's keywords) and its index."""
    bad = np.flatnonzero(~np.isfinite(flat))
    if bad.size:
        k = int(bad[0])
        part = next(i for i, (a, b) in enumerate(_SLICES) if a <= k < b)
        raise MeasurementError(
            f"{names[part]}[{k - _SLICES[part][0]}] is not finite (NaN or infinite)"
        )


def as_given(e: MeasurementError, names: Sequence[str]) -> MeasurementError:
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


def wrench_of(wrench: ArrayLike | None) -> FloatArray:
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


def measured_of(
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


def pose_of(sample: Any, R: FloatArray) -> FloatArray:
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
        self.held_rotation = chain.fk(self.q0)[:3, :3].copy()

    @property
    def ts(self) -> float:
        """Deprecated name of :attr:`Ts`."""
        return period_alias(self)

    @property
    def held_rotation(self) -> FloatArray:
        """The commanded rotation a target without one keeps (3, 3), world ←
        tip, held by the core."""
        return np.asarray(self._core.held_rotation())

    @held_rotation.setter
    def held_rotation(self, R: ArrayLike) -> None:
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
        out = flat_target(self, (p, dp, ddp, R, w, dw))
        try:
            self._core.check_target(out)
        except MeasurementError as e:
            raise as_given(e, _POSE_NAMES) from None
        commit_rotation(self, out, R)
        return out

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
        flat = None if p is None else flat_target(self, (p, dp, ddp, R, w, dw))
        q, dq, ddq = self._core.reference(flat, wrench_of(wrench))
        commit_rotation(self, flat, R)
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
        self.held_rotation = self.chain.fk(self.q0)[:3, :3].copy()

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


def flat_target(
    outer: CartesianImpedance,
    values: Sequence[ArrayLike | None],
    names: Sequence[str] = _POSE_NAMES,
) -> FloatArray:
    """The flat target (24,) of (p, dp, ddp, R, w, dw), R the outer loop's held
    rotation if None; nothing kept (see :func:`commit_rotation`)."""
    v = list(values)
    if v[3] is None:
        v[3] = outer.held_rotation
    return _pose(v, names)


def commit_rotation(outer: CartesianImpedance, target: FloatArray | None, R: object) -> None:
    """After the core accepted ``target``: its rotation is the one the outer
    loop holds if it set one (``R`` given, or a path's 6-tuple)."""
    if target is not None and R is not None:
        outer.held_rotation = target[9:18].reshape(3, 3).copy()
