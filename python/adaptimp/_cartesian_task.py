"""The Cartesian task of :func:`adaptimp.mujoco.cartesian_task` (SPEC §16, (16.8)–(16.11)).

A pose task for any arm in five lines::

    from adaptimp import mujoco as amj

    task = amj.cartesian_task("my_arm.urdf")  # a start posture, the default path
    res = amj.simulate("sf", "my_arm.urdf", T=12.0, task=task)
    res.metrics["rms_pos_after2"], res.metrics["rms_rot_after2"]  # m, rad
    res.pos_err, res.rot_err  # per row

- :class:`CirclePath`: the default path, the core's (16.8): hold the start pose
  1 s, then a 3 cm circle at 0.5 Hz in the horizontal plane through it, the
  orientation held.
- :func:`task_of`: the start posture when none is given, by the core's
  posture rule (16.9) over candidates drawn within the joint limits, each
  checked along its task's joint orbit and for self-collision
  (:func:`self_collision`; the one check, :func:`adaptimp._posture.assess`);
  where none passes, the search widens (:data:`WIDENINGS`: more candidates,
  a smaller circle, the position alone) before it refuses, saying what each
  condition needs.
- :class:`CartesianTask`: the task; :meth:`CartesianTask.controller` builds
  :meth:`adaptimp.CartesianController.from_rule`, :meth:`CartesianTask.measure`
  the pose errors and their metrics in the core (16.11).

This module takes an ``adaptimp.mujoco.Plant`` object and never imports
:mod:`adaptimp.mujoco` (which imports it). Units: m, rad, s, N m.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp, _posture
from ._collision import _Probe, collision, self_collision
from ._errors import ConfigError, DivergedError
from .cartesian import CartesianController, Path, tabulate
from .chain import Chain

__all__ = [
    "CANDIDATES",
    "IK_TIME",
    "WIDENINGS",
    "CartesianTask",
    "CirclePath",
    "TablePath",
    "chain_of",
    "collision",
    "measure",
    "self_collision",
    "task_of",
]

FloatArray = NDArray[np.float64]

CANDIDATES = 512
"""Postures drawn (fixed seed) within the joint limits when no start is given."""

IK_TIME = 2.0
"""How long (s) the core's inverse kinematics (the outer loop run
kinematically, F_e = 0) holds a given path's first pose from a candidate
posture to reach it."""

GIVEN_LOAD = _posture.GIVEN_LOAD
"""The largest gravity load max_i |G_i|/τmax_i along the task of a start the
user gives (gravity within the actuators); a drawn start keeps the rule's 0.5."""

CHECKED = _posture.CHECKED
"""Rows of the task's joint orbit at which gravity and self-collision are
checked (evenly spaced); also the candidates checked along the task, best
first, before the search widens."""

WIDE = 4
"""How much the widened search draws and checks along the task: 4 ×
:data:`CANDIDATES` postures, 4 × :data:`CHECKED` of them along it."""

RADII = (0.03, 0.015, 0.0075)
"""The default circle's radius (m), then the smaller ones the widened search
tries (halved twice): a small arm's circle through a start near its base's
axis comes close to the axis, where σmin(J) vanishes."""

WIDENINGS = (
    ("the default task", 1, RADII[0], True),
    ("more candidates", WIDE, RADII[0], True),
    ("a 1.5 cm circle", WIDE, RADII[1], True),
    ("a 0.75 cm circle", WIDE, RADII[2], True),
    ("the position alone", WIDE, RADII[0], False),
    ("the position alone, a 1.5 cm circle", WIDE, RADII[1], False),
    ("the position alone, a 0.75 cm circle", WIDE, RADII[2], False),
)
"""The default task's search, in order, until a start passes (SPEC (16.9)):
(what it is, how many times :data:`CANDIDATES` postures are drawn and
:data:`CHECKED` checked along the task, the circle's radius (m), whether the
orientation is held (an arm of six joints or more; fewer hold the position
alone from the start)). The first is the default task as it always was."""


class CirclePath:
    """The default Cartesian path of SPEC (16.8) about the start pose (``p0`` (m),
    ``R0`` (3, 3), world ← tip), computed by the core: callable as ``path(t) ->
    (p, ṗ, p̈, R, ω, ω̇)`` and tabulated at once (``table``)."""

    def __init__(
        self,
        p0: ArrayLike,
        R0: ArrayLike,
        *,
        radius: float = RADII[0],
        normal: ArrayLike | None = None,
    ) -> None:
        self.p0 = np.array(p0, dtype=np.float64).reshape(3)
        self.R0 = np.array(R0, dtype=np.float64).reshape(3, 3)
        self.radius = float(radius)
        """The circle's radius (m)."""
        self.normal = None if normal is None else [float(x) for x in np.ravel(normal)]
        """The normal of its plane (None: horizontal; a planar arm's, SPEC (16.8))."""
        _, span, centre = self._rows(1.0, 0, 0.0)
        self.span = float(span)
        """Hold + ramp + one period (s): what a rule samples."""
        self.centre = np.asarray(centre, dtype=np.float64)
        """The circle's centre (m)."""

    def _rows(self, Ts: float, steps: int, start: float) -> Any:
        return _adaptimp.pose_circle(
            self.p0, self.R0, float(Ts), int(steps), start=start, radius=self.radius,
            normal=self.normal,
        )  # fmt: skip

    def table(self, steps: int, Ts: float, start: int = 0) -> FloatArray:
        """The path at t_k = (start + k)·Ts, k < steps: (steps, 24) rows of
        :func:`adaptimp.cartesian.pose_target`."""
        rows, _, _ = self._rows(Ts, steps, start * Ts)
        return np.asarray(rows, dtype=np.float64)

    def __call__(self, t: float) -> tuple[FloatArray, ...]:
        rows, _, _ = self._rows(1.0, 1, float(t))
        return _split(np.asarray(rows, dtype=np.float64).reshape(24))

    def __repr__(self) -> str:
        return (
            f"CirclePath(p0={self.p0.round(4).tolist()}, radius={self.radius:g} m, "
            f"span={self.span:g} s)"
        )


def _split(row: FloatArray) -> tuple[FloatArray, ...]:
    """A row of :func:`adaptimp.cartesian.pose_target` as (p, ṗ, p̈, R, ω, ω̇)."""
    return row[0:3], row[3:6], row[6:9], row[9:18].reshape(3, 3), row[18:21], row[21:24]


def _pose_array(name: str, x: Any) -> FloatArray:
    """A pose array of reals, or a TypeError naming it ("abc" gave NumPy's words)."""
    try:
        return np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"pose array {name} must hold real numbers, got {x!r:.40}") from None


class TablePath:
    """A path given as arrays, row k at t_k = k·``Ts``: (p, ṗ, p̈) (K, 3) each
    (m, m/s, m/s²) and optionally (R (K, 3, 3), ω, ω̇ (K, 3)); beyond its last
    row the last pose at rest."""

    def __init__(self, arrays: Sequence[ArrayLike], Ts: float) -> None:
        names = ("p", "dp", "ddp", "R", "w", "dw")
        if isinstance(arrays, (str, bytes)) or not isinstance(arrays, (Sequence, np.ndarray)):
            raise TypeError(
                "pose must be a path (a callable t -> (p, dp, ddp[, R, w, dw])) or the arrays "
                f"(p, dp, ddp[, R, w, dw]), got {type(arrays).__name__} {arrays!r:.40}"
            )
        a = [_pose_array(name, x) for name, x in zip(names, arrays)]
        if len(arrays) not in (3, 6):
            raise ConfigError(
                f"pose arrays must be (p, dp, ddp) or (p, dp, ddp, R, w, dw), got {len(a)} arrays"
            )
        k = a[0].shape[0] if a[0].ndim == 2 else 0
        shapes = [(k, 3)] * 3 + [(k, 3, 3), (k, 3), (k, 3)]
        for name, x, want in zip(names, a, shapes):
            if k == 0 or x.shape != want:
                raise ConfigError(
                    f"pose array {name} must have shape {want} (K ≥ 1), got {x.shape}"
                )
        rows = np.empty((k, 24))
        for i in range(3):
            rows[:, 3 * i : 3 * i + 3] = a[i]
        if len(a) == 6:
            rows[:, 9:18] = a[3].reshape(k, 9)
            rows[:, 18:21], rows[:, 21:24] = a[4], a[5]
        else:
            rows[:, 9:18] = np.eye(3).reshape(9)
            rows[:, 18:24] = 0.0
        if not np.isfinite(rows).all():  # one pass; the first array that is not, named
            bad = next(n for n, x in zip(names, a) if not np.all(np.isfinite(x)))
            raise ConfigError(f"pose array {bad} must be finite")
        self.rows, self.Ts, self.orients = rows, float(Ts), len(a) == 6
        self.span = k * self.Ts
        """The rows' duration (s)."""

    def table(self, steps: int, Ts: float, start: int = 0) -> FloatArray:
        """Rows start … start + steps − 1 (the table's period must be ``Ts``)."""
        if not math.isclose(Ts, self.Ts, rel_tol=1e-12):
            raise ConfigError(f"the pose arrays are at Ts = {self.Ts:g} s, not {Ts:g} s")
        if start >= 0 and start + steps <= self.rows.shape[0]:
            return self.rows[start : start + steps].copy()  # within the rows: one copy
        idx = np.arange(start, start + steps)
        out = self.rows[np.minimum(idx, self.rows.shape[0] - 1)]
        out[idx >= self.rows.shape[0], 3:9] = 0.0  # held at rest
        out[idx >= self.rows.shape[0], 18:24] = 0.0
        return out

    def __call__(self, t: float) -> tuple[FloatArray, ...]:
        k = max(round(t / self.Ts), 0)
        return _split(self.table(1, self.Ts, k)[0])


def chain_of(plant: Any) -> Chain:
    """The arm's :class:`~adaptimp.Chain` to the plant's end-effector point (its
    site, or the origin of its end-effector body), the joints in the plant's
    order."""
    m = plant.model
    site, body = int(plant.ee_site), int(plant.ee_body)
    tip = site if site >= 0 else mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, body)
    # The core's one reader of the chain (SPEC §21), to a site or a body's origin.
    chain = Chain.from_mujoco(m, tip if tip is not None else f"body#{body}")
    plant_joints = [
        mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(j)) or f"joint#{int(j)}"
        for j in plant.joint_ids
    ]
    if chain.joint_names != plant_joints:
        raise ConfigError(
            f"the chain to the end effector has the joints {chain.joint_names}, but the plant "
            f"drives {plant_joints}"
        )
    return chain


@dataclass(frozen=True)
class CartesianTask:
    """A Cartesian task on an arm (:func:`adaptimp.mujoco.cartesian_task`).

    Attributes
    ----------
    q0 : ndarray, (n,)
        The start posture (rad): the path's first pose, from rest.
    chain : Chain
        The arm's kinematics to the plant's end-effector point.
    path : callable
        ``path(t) -> (p, ṗ, p̈, R, ω, ω̇)`` (m, m/s, m/s², rotation (3, 3),
        rad/s, rad/s²; world frame): :class:`CirclePath` by default.
    span : float
        The part of the path the rule samples (s): hold + ramp + one period.
    orients : bool
        Whether the orientation is held (six joints or more); else the task
        is the position only.
    assessment : dict
        The start's figures along the task (SPEC (16.9)): ``sigma_min``
        (m/rad), ``load``, ``conditioning``, ``slack`` (rad), ``reach`` (m),
        ``score``.
    source : str
        How q0 was found: "given", or "drawn (candidate k of N)".
    """

    q0: FloatArray
    chain: Chain
    path: Path
    span: float
    orients: bool
    assessment: dict[str, Any] = field(default_factory=dict)
    source: str = "given"

    @property
    def pose0(self) -> tuple[FloatArray, FloatArray]:
        """The start pose: p (m), R (3, 3)."""
        return self.chain.pose(self.q0)

    def moved_to(self, q: ArrayLike) -> CartesianTask:
        """The same task from posture ``q`` (rad): a :class:`CirclePath` about
        the pose the arm has at ``q``, the same radius and plane (a robot's
        arm that moved between the task's set-up and its first cycle starts
        where it stands, without a step in the reference); its
        ``assessment`` stays the original start's figures (the move is small:
        the rule's checks ran there). Other paths are not moved (ConfigError)."""
        path = self.path
        if not isinstance(path, CirclePath):
            raise ConfigError(f"moved_to moves the default CirclePath, not {type(path).__name__}")
        q = np.array(q, dtype=np.float64).reshape(self.q0.shape)
        p, r = self.chain.pose(q)
        moved = CirclePath(p, r, radius=path.radius, normal=path.normal)
        return replace(
            self, q0=q, path=moved, source=f"{self.source}, moved to where the arm stands"
        )

    def targets(self, steps: int, Ts: float) -> FloatArray:
        """The path at t_k = k·Ts, (steps, 24) (:func:`adaptimp.cartesian.tabulate`)."""
        return tabulate(self.path, steps, Ts, self.pose0[1])

    def controller(self, case: str, plant: Any, *, Ts: float = 1e-3, **params: Any) -> Any:
        """The Cartesian controller of ``case`` for this task by the core's rule
        (:meth:`adaptimp.CartesianController.from_rule`, D and G from the
        ``plant``); ``params`` replace the rule's keywords."""
        if not self.orients:
            params.setdefault("Kd_rot", 0.0)
        return CartesianController.from_rule(
            self.chain, case, self.path, self.q0, model=plant, span=self.span, Ts=Ts, **params
        )

    def prepare(
        self,
        controller: Any,
        plant: Any,
        Ts: float | None,
        params: dict[str, Any],
        keep: Sequence[str],
    ) -> tuple[Any, dict[str, Any]]:
        """For ``simulate(case, model, task=self, **params)``: the controller of the
        case name by :meth:`controller`, with the ``params`` not named in
        ``keep`` (the simulator's own, e.g. disturbances), which are returned."""
        if not isinstance(controller, str):
            raise TypeError(
                "task= builds the Cartesian controller of a case name ('pd', 'sf', 'of'); "
                f"got {type(controller).__name__}: run your own controller without task="
            )
        self.check_arm(plant)
        own = {k: v for k, v in params.items() if k not in keep}
        rest = {k: v for k, v in params.items() if k in keep}
        return self.controller(controller, plant, Ts=1e-3 if Ts is None else Ts, **own), rest

    def check_arm(self, plant: Any) -> None:
        """The task is this plant's: its chain's tip is the plant's end-effector
        point (to 1e-9 m and rad) at its start and at two other postures; else a
        ConfigError with the distance (a task made on another arm was run, and
        its errors measured with the other arm's kinematics: 0.2 mm reported
        while the tip was 219 mm off)."""
        mine = chain_of(plant)
        if mine.n != self.chain.n:
            raise ConfigError(
                f"the task was made on an arm of {self.chain.n} joints, the plant has {mine.n}: "
                "make the task on this plant (cartesian_task(plant))"
            )
        worst = (0.0, 0.0)
        for shift in (0.0, 0.3, -0.5):
            q = self.q0 + shift
            (p, r), (pm, rm) = self.chain.pose(q), mine.pose(q)
            turn = float(np.linalg.norm(r.T @ rm - np.eye(3)))
            worst = max(worst, (float(np.linalg.norm(p - pm)), turn))
        if worst[0] > 1e-9 or worst[1] > 1e-9:
            raise ConfigError(
                f"the task was made on another arm: its chain's tip is {worst[0]:.3g} m (and "
                f"{worst[1]:.3g} in rotation) from this plant's end effector at the same "
                "joint values: make the task on this plant (cartesian_task(plant))"
            )

    def measure(self, res: Any) -> None:
        """The task's errors of a run (``res`` from :func:`adaptimp.mujoco.simulate`),
        in the core (SPEC (16.11)): ``res.task["pos_err"]`` (K,) ‖p_c − p‖ (m),
        ``res.task["rot_err"]`` (K,) ‖Log(R_c Rᵀ)‖ (rad) (the commanded pose
        of the row against the tip of the chain at the row's q), and the
        metrics ``rms_pos_after2``, ``rms_rot_after2`` (over t ≥ settle),
        ``max_pos_after2``, ``max_rot_after2``, ``rms_pos``, ``rms_rot``,
        ``rms_pos_first2`` (over [settle, settle + 2 s)) and ``rms_pos_last2``
        (over the run's last 2 s) added to ``res.metrics``."""
        Ts = float(res.params["Ts"])
        rows = np.rint(np.asarray(res.t, dtype=np.float64) / Ts).astype(np.int64)
        steps = int(rows[-1]) + 1 if rows.size else 0
        measure(res, self.chain, self.targets(steps, Ts))


def measure(res: Any, chain: Chain, table: FloatArray) -> None:
    """The pose errors of a run in the core (SPEC (16.11)): the tip of ``chain``
    at each row's q against the commanded pose of the row, ``table`` (steps,
    24) the commanded pose of every step of the run (row k at t_k = k·Ts; a
    run that kept every j-th row reads rows 0, j, 2j, …). Sets
    ``res.task["pos_err"]`` (K,) (m), ``res.task["rot_err"]`` (K,) (rad) and
    adds the metrics ``rms_pos_after2``, ``rms_rot_after2``,
    ``max_pos_after2``, ``max_rot_after2``, ``rms_pos``, ``rms_rot``,
    ``rms_pos_first2`` and ``rms_pos_last2`` to ``res.metrics``."""
    Ts, settle = float(res.params["Ts"]), float(res.params["settle"])
    t = np.ascontiguousarray(res.t, dtype=np.float64)
    rows = np.rint(t / Ts).astype(np.int64)
    table = np.ascontiguousarray(np.asarray(table, dtype=np.float64)[rows])
    pos, rot, m = _adaptimp.pose_metrics(
        chain, np.ascontiguousarray(res.q, dtype=np.float64), table, t, settle, Ts
    )
    res.metrics.update(m)
    if res.task is None:
        res.task = {}
    res.task["pos_err"], res.task["rot_err"] = pos, rot


def _ik(chain: Chain, q: FloatArray, path: Path, Ts: float, orients: bool) -> FloatArray:
    """The core's inverse kinematics of the path's first pose from ``q``: the
    outer loop run kinematically with that pose held for :data:`IK_TIME`."""
    from .cartesian import CartesianImpedance

    first = tuple(path(0.0))
    hold = (*first[:3], *first[3:]) if len(first) == 6 else first
    R = chain.pose(q)[1]
    held = [np.asarray(x, dtype=np.float64) for x in hold]
    if len(held) == 6:
        held[1:3] = [np.zeros(3), np.zeros(3)]
        held[4:6] = [np.zeros(3), np.zeros(3)]
    else:
        held = [held[0], np.zeros(3), np.zeros(3), R, np.zeros(3), np.zeros(3)]

    def at_rest(t: float) -> tuple[FloatArray, ...]:
        return tuple(held)

    position_only: dict[str, Any] = {} if orients else {"Kd_rot": 0.0}
    outer = CartesianImpedance(chain, Ts=Ts, q0=q, **position_only)
    steps = round(IK_TIME / Ts)
    qs, _, _ = outer.joint_path(at_rest, steps * Ts, samples=steps)
    return np.asarray(qs[-1], dtype=np.float64)


def _assess(
    plant: Any,
    probe: _Probe,
    chain: Chain,
    q0: FloatArray,
    path: Path,
    span: float,
    Ts: float,
    orients: bool,
    load: float | None = None,
) -> dict[str, Any]:
    """The one posture check (:func:`adaptimp._posture.assess`, SPEC (16.9))
    along the task's joint orbit from ``q0``: the outer loop run kinematically
    on ``path`` over ``span`` s, checked at :data:`CHECKED` rows."""
    from .cartesian import CartesianImpedance

    position_only: dict[str, Any] = {} if orients else {"Kd_rot": 0.0}
    outer = CartesianImpedance(chain, Ts=Ts, q0=q0, **position_only)
    steps = round(span / Ts)
    q, _, _ = outer.joint_path(path, steps * Ts, samples=steps)
    idx = _posture.checked_rows(q.shape[0])
    targets = tabulate(path, steps, Ts, chain.pose(q0)[1])[idx, 0:3]
    return _posture.assess(
        plant, chain, q0, q[idx], targets, orients=orients, Ts=Ts, load=load,
        dynamics=(probe.gravity, probe.inertia),
    )  # fmt: skip


def task_of(
    plant: Any,
    q0: ArrayLike | None = None,
    pose: Path | Sequence[ArrayLike] | None = None,
    *,
    Ts: float = 1e-3,
    span: float | None = None,
    seed: int = 0,
) -> CartesianTask:
    """The task of :func:`adaptimp.mujoco.cartesian_task` on ``plant`` (an
    ``adaptimp.mujoco.Plant``); see there."""
    chain = chain_of(plant)
    n = chain.n
    # Named before the search (Ts = 0 was "no start posture found … 40 tried").
    Ts = _positive("Ts", Ts)
    _configured(chain, Ts, n >= 6, plant)
    probe = _Probe(plant)
    # A planar arm's task lies in its plane (SPEC (16.8)): the circle, and the
    # rule's σmin over the plane's directions.
    planar = _posture.plane(chain)
    user_path: Path | None
    if pose is None:
        user_path = None
    elif callable(pose):
        user_path = pose
    else:
        user_path = TablePath(pose, Ts)
    if span is None:
        span = getattr(user_path, "span", None) if user_path is not None else None
    if user_path is not None and span is None:
        span = 4.0
    if span is not None:
        span = _positive("span", span)

    def path_from(q: FloatArray, radius: float, orients: bool) -> tuple[FloatArray, Path, float]:
        """The start (after the inverse kinematics of a given path), the path, its span."""
        if user_path is None:
            p, R = chain.pose(q)
            circle = CirclePath(p, R, radius=radius, normal=planar)
            return q, circle, circle.span
        assert span is not None
        return _ik(chain, q, user_path, Ts, orients), user_path, float(span)

    if q0 is not None:
        orients = n >= 6
        q = _vector("q0", q0, chain)
        lo, hi = _posture.limits_of(plant, plant.n)
        outside = np.flatnonzero((q < lo) | (q > hi))
        if outside.size:
            i = int(outside[0])
            raise ConfigError(
                f"q0 must lie within the joint limits; joint {i} ({chain.joint_names[i]!r}) has "
                f"q0 = {float(q[i])!r} outside [{float(lo[i])!r}, {float(hi[i])!r}] rad"
            )
        try:
            start, path, length = path_from(q, RADII[0], orients)
        except DivergedError as e:
            raise ConfigError(
                f"q0 cannot run the task: the inverse kinematics of the pose path's first pose "
                f"from q0 diverged ({e}): is the pose within the arm's reach?"
            ) from None
        # A start the user gives: gravity within the actuators (a drawn one: half).
        a = _assess(plant, probe, chain, start, path, length, Ts, orients, load=GIVEN_LOAD)
        if a["error"] is not None:
            raise ConfigError(f"q0 cannot run the task: {a['error']}")
        return CartesianTask(start, chain, path, length, orients, a, "given")
    return _search(plant, probe, chain, path_from, Ts, seed, user_path is not None)


def _search(
    plant: Any,
    probe: _Probe,
    chain: Chain,
    path_from: Any,
    Ts: float,
    seed: int,
    own_path: bool,
) -> CartesianTask:
    """A drawn start, by :data:`WIDENINGS` in order (a path of the user's: its
    own path, the search widened only), or a ``ConfigError`` that says what
    each condition needs, with the best value found, and what to try."""
    n = chain.n
    best: dict[str, Any] = {}
    collisions, tried_rows, drawn, failed, diverged = 0, 0, 0, "", 0
    failures: dict[str, int] = {}
    screens: dict[tuple[int, bool], list[tuple[float, int, FloatArray]]] = {}
    tried: set[tuple[int, float, bool]] = set()
    for label, wide, radius, holds in WIDENINGS:
        orients = holds and n >= 6
        if own_path and radius != RADII[0]:
            continue  # the user's path keeps its size
        if not holds and n < 6:
            continue  # the position alone from the start
        count = wide * CANDIDATES
        if (count, orients) not in screens:
            screened = []
            failures = {}  # of the latest screen: the condition that failed most, named
            for k, q in enumerate(_candidates(plant, seed, count)):
                quick = _screen(probe, chain, q, orients, plant)
                _best(best, quick, along=False)
                if quick["error"] is None:
                    screened.append((float(quick["score"]), k, q))
                else:
                    condition = str(quick["error"]).split(" is violated")[0]
                    failures[condition] = failures.get(condition, 0) + 1
            screened.sort(key=lambda x: (-x[0], x[1]))
            screens[(count, orients)] = screened
            drawn = max(drawn, count + 2)
        for _, k, q in screens[(count, orients)][: wide * CHECKED]:
            if (k, radius, orients) in tried:
                continue
            tried.add((k, radius, orients))
            tried_rows += 1
            try:
                start, path, length = path_from(q, radius, orients)
                a = _assess(plant, probe, chain, start, path, length, Ts, orients)
            except ConfigError as e:  # the core refused the orbit: not this posture
                failed = str(e)
                continue
            except DivergedError as e:  # the inverse kinematics of the path's first pose
                failed = (
                    f"the inverse kinematics of the pose path's first pose diverged ({e}): is "
                    "the pose within the arm's reach?"
                )
                diverged += 1
                continue
            if a["error"] is None:
                source = f"drawn (candidate {k} of {count + 2}; {label})"
                return CartesianTask(start, chain, path, length, orients, a, source)
            if a.get("collides"):
                collisions += 1
            else:
                _best(best, a)
            failed = a["error"]
    if not failed and failures:
        common, times = max(failures.items(), key=lambda kv: kv[1])
        failed = f"none passed the rule at its start (the {common} failed at {times} of them)"
    raise ConfigError(
        _refusal(plant, chain, best, drawn, tried_rows, collisions, diverged, failed, own_path)
    )


_BEST = {"sigma_min": max, "slack": max, "load": min, "conditioning": max, "reach": min}
"""How each figure of an assessment improves (the best over the search)."""


def _best(best: dict[str, Any], a: dict[str, Any], *, along: bool = True) -> None:
    """``best`` updated with the assessment ``a``: each figure the best seen (a
    start screened alone, ``along=False``, measures no reach: its path is not
    tracked, and its reach of 0 read "the path reachable (best 0)" when every
    path checked diverged)."""
    for key, pick in _BEST.items():
        if key == "reach" and not along:
            continue
        value = float(a[key])
        if key not in best or pick(value, best[key]) == value != best[key]:
            best[key] = value
            if key == "slack":
                best["slack_joint"] = int(a["slack_joint"])


def _refusal(
    plant: Any,
    chain: Chain,
    best: dict[str, Any],
    drawn: int,
    tried: int,
    collisions: int,
    diverged: int,
    last: str,
    own_path: bool,
) -> str:
    """The refusal of :func:`_search`: what was searched, what each condition
    needs with the best value found, what to try."""
    n = chain.n
    what = "your path" if own_path else (
        "the default task (circles of 3, 1.5 and 0.75 cm"
        + (", holding the orientation and not)" if n >= 6 else ", the position only)")
    )  # fmt: skip
    hints = []
    jv = np.asarray(chain.jacobian(_candidates(plant, 0, 0)[1]), dtype=np.float64)[:3]
    still = [chain.joint_names[i] for i in range(n) if not np.any(jv[:, i])]
    if still:
        hints.append(
            f"joint(s) {still} do not move the tip (their axes pass through it): give tip= a "
            "link, body or site beyond them"
        )
    elif n < 3 and _posture.plane(chain) is None:
        hints.append(
            f"the tip of this {n}-joint arm moves on a surface that is not a plane (its "
            "joints' axes are not parallel): no circle of the default task lies on it"
        )
    if diverged:  # a later start's refusal is not the cause (a path 1 m away: "σmin = 3e-6")
        hints.append(
            f"the inverse kinematics of the pose path's first pose diverged from {diverged} of "
            f"the {tried} starts checked: is the pose within the arm's reach?"
        )
    needs = _adaptimp.posture_needs({**_NO_BEST, **best}, load=None)
    coll = (
        f"; {collisions} of them collide along it (the arm with itself or the scene)"
        if collisions
        else ""
    )
    return (
        f"no start posture found for a Cartesian task on this arm ({n} joints "
        f"{chain.joint_names}) with {what}: {drawn} postures drawn within its joint limits, "
        f"{tried} checked along the task{coll}; the last refused: "
        f"{last or 'none passed the rule at its start'}. "
        f"Each condition of the rule (SPEC (16.9)) with what it needs and the best value found: "
        f"{needs}. "
        + (" ".join(h if h.endswith("?") else h + "." for h in hints) + " " if hints else "")
        + "Try: q0= a start of your own that meets these (cartesian_task(model, q0=...), "
        "checked with gravity up to the actuators' limits), pose= a path of your own, or "
        "tip= another end effector"
    )


_NO_BEST = {
    "sigma_min": 0.0, "slack": -math.inf, "slack_joint": 0, "load": math.inf,
    "conditioning": 0.0, "reach": math.inf,
}  # fmt: skip
"""The figures of a search that assessed nothing."""


def _candidates(plant: Any, seed: int, count: int = CANDIDATES) -> list[FloatArray]:
    """The model's reference posture (qpos0) and the middle of the joint ranges,
    each kept inside the limits with the rule's margin, then ``count``
    (:data:`CANDIDATES`) drawn uniformly there (fixed seed; ±π for an
    unlimited joint; the first draws of a larger count are those of a smaller)."""
    lo, hi = _posture.limits_of(plant, plant.n)
    lo_, hi_ = np.where(np.isfinite(lo), lo, -math.pi), np.where(np.isfinite(hi), hi, math.pi)
    margin = np.minimum(0.1, (hi_ - lo_) / 8)
    a, b = lo_ + margin, hi_ - margin
    zero = np.clip(np.asarray(plant.model.qpos0[plant.qpos_adr], dtype=np.float64), a, b)
    rng = np.random.default_rng(seed)
    return [zero, 0.5 * (a + b), *rng.uniform(a, b, size=(count, plant.n))]


def _screen(
    probe: _Probe, chain: Chain, q: FloatArray, orients: bool, plant: Any
) -> dict[str, Any]:
    """The core's posture rule (SPEC (16.9)) at the candidate alone (σmin,
    limits, gravity, conditioning): its assessment (``error`` None if it
    passes there)."""
    lo, hi = _posture.limits_of(plant, plant.n)
    a = _adaptimp.assess_posture(
        chain, q[None, :], chain.pose(q)[0][None, :], probe.gravity(q)[None, :],
        probe.inertia(q), lo, hi, np.asarray(plant.tau_max, dtype=np.float64), orients,
        normal=None if orients else _posture.plane(chain),
    )  # fmt: skip
    return dict(a)


def _positive(name: str, value: Any) -> float:
    """``value`` as a finite number > 0, or an error naming ``name`` (a
    TypeError for text or a bool, "2" gave Python's own message)."""
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"{name} must be a finite number > 0 (s), got {value!r:.40}")
    v = float(value)
    if not (math.isfinite(v) and v > 0):
        raise ConfigError(f"{name} must be a finite number > 0 (s), got {value!r}")
    return v


def _configured(chain: Chain, Ts: float, orients: bool, plant: Any) -> None:
    """The outer loop's configuration at the period ``Ts``, checked once by the
    core before any posture is tried (Ts = 0.5 s failed every candidate,
    reported as "no start posture found")."""
    from .cartesian import CartesianImpedance

    lo, hi = _posture.limits_of(plant, plant.n)
    limited = np.isfinite(lo) & np.isfinite(hi)
    mid = np.zeros(chain.n)
    mid[limited] = 0.5 * (lo[limited] + hi[limited])  # an unlimited joint at 0
    position_only: dict[str, Any] = {} if orients else {"Kd_rot": 0.0}
    try:
        CartesianImpedance(chain, Ts=Ts, q0=mid, **position_only)
    except ConfigError as e:
        raise ConfigError(f"Ts = {Ts!r} s: {e}") from None


def _vector(name: str, value: ArrayLike, chain: Chain) -> FloatArray:
    """``value`` as n finite numbers (rad), or a ``ConfigError`` naming it."""
    try:
        v = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be {chain.n} finite numbers (rad), got {value!r}") from None
    if v.shape != (chain.n,) or not np.all(np.isfinite(v)):
        raise ConfigError(f"{name} must be {chain.n} finite numbers (rad), got {value!r}")
    return v
