"""Tasks and postures of an arm nobody configured (SPEC §18): the home
posture (:func:`home_posture`), the default joint task (:func:`default_task`,
:class:`Task`), the rule's keywords (:func:`rule_keywords`) and the Cartesian
task (:func:`cartesian_task`).

Re-exported by :mod:`adaptimp.mujoco`. Units: rad, rad/s, N m, m, s."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _contacts
from ._cartesian_task import CartesianTask, task_of
from ._plant import Plant
from ._plant_models import ModelSource
from ._sampled import _limits, _postures
from ._trajectory import Reference, sinusoid

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Task:
    """The default task of a plant (:func:`default_task`, SPEC §18).

    Attributes
    ----------
    home : ndarray, (n,)
        The posture the task swings about (rad).
    q0 : ndarray, (n,)
        Its start, at rest (rad): home − A.
    keywords : dict
        ``xc_offset``, ``xc_sin``, ``xc_cos``, ``xc_omega``: the controller's
        sinusoid (SPEC §4).
    period : float
        2 s.
    """

    home: FloatArray
    q0: FloatArray
    keywords: dict[str, list[float]]
    period: float

    @property
    def reference(self) -> Reference:
        """``reference(t) -> (xc, dxc, ddxc)``."""
        k = self.keywords
        return sinusoid(k["xc_offset"], k["xc_sin"], k["xc_cos"], k["xc_omega"])


HOME_SAMPLES = 256
"""Postures :func:`home_posture` compares."""

HOME_LOAD = 0.5
"""The zero posture is the home posture if gravity takes at most this share of
every effort limit over the task's swing (:func:`home_posture`)."""

HOME_CLEARANCE = 0.005
"""The clearance (m) the default task keeps between bodies that the arm moves
relative to each other (:func:`home_posture`)."""

SWING_SAMPLES = 21
"""Postures along the swing q − A … q + A at which :func:`home_posture` checks
for contact."""


def home_posture(plant: Plant) -> FloatArray:
    """A posture inside the joint limits where gravity is well within the
    effort limits and the task's swing touches nothing (SPEC §18). The
    gravity load of a posture q is the largest max_i |G_i|/τmax_i over the
    task's swing (q − A, q, q + A). Every posture is kept A = min(0.2 rad,
    range/4) inside each limit (a continuous joint ranges over [−π, π]).
    With contact on, a posture qualifies only if, at :data:`SWING_SAMPLES`
    postures along its swing q − A … q + A, no two bodies that the arm's
    joints move relative to each other (the arm and itself, or the arm and
    what is around it) come within :data:`HOME_CLEARANCE` of each other, by
    the model's own collision geometry and filters. The zero posture (the
    model's reference, clipped into the box) if it qualifies and its load is
    at most :data:`HOME_LOAD`; else the nearest qualifying posture of load at
    most :data:`HOME_LOAD` among 255 fixed-seed samples of the box drawn in
    towards it (the k-th by k/255 of the way out); else the qualifying one
    of least load.

    Raises
    ------
    ValueError
        Gravity exceeds an effort limit at every qualifying posture (the
        message gives the best load), or every posture's swing touches (the
        message names the bodies: give ``home=``).
    """
    m = plant.model
    lo, hi = _limits(m, plant.joint_ids)
    width = np.where(np.isfinite(hi - lo), hi - lo, 2 * math.pi)
    amp = np.minimum(0.25 * width, TASK_AMPLITUDE)
    saved = (np.array(plant.data.qpos), np.array(plant.data.qvel))
    contacts = _contacts.Contacts(m, saved[0], plant.joint_ids, margin=HOME_CLEARANCE)
    swing = np.linspace(-1.0, 1.0, SWING_SAMPLES)
    touching: list[tuple[str, str, float]] = []

    def clear(q: FloatArray) -> bool:
        found = [c for s in swing for c in contacts.at(q + s * amp)]
        touching.extend(found)
        return not found

    samples = _postures(lo, hi, HOME_SAMPLES, amp)
    zero = samples[0]
    # Nearest the zero posture first: the samples drawn in towards it, the
    # k-th by k/(K − 1) of the way out.
    grow = np.arange(HOME_SAMPLES, dtype=np.float64)[:, None] / (HOME_SAMPLES - 1)
    near = zero + grow * (samples - zero)
    loads = [max(_gravity_load(plant, q + s * amp) for s in (-1.0, 0.0, 1.0)) for q in near]
    best, best_load = None, math.inf
    for q, load in zip(near, loads):
        if load <= HOME_LOAD and clear(q):
            best, best_load = q, load
            break
    if best is None:
        for k in np.argsort(loads, kind="stable"):
            if loads[k] < 1.0 and clear(near[k]):
                best, best_load = near[k], loads[k]
                break
        else:
            best_load = min(loads)
    plant.data.qpos[:], plant.data.qvel[:] = saved
    mujoco.mj_forward(m, plant.data)
    if best is None and touching:
        raise ValueError(
            f"the default task's swing (±A about the home posture) brings the arm's bodies "
            f"within {HOME_CLEARANCE:g} m of each other at every posture compared "
            f"({_contacts.pairs(touching)}): give home= (rad), or simulate with contact=False"
        )
    if best is None or best_load >= 1.0:
        raise ValueError(
            f"gravity exceeds the effort limits at every posture compared: the least "
            f"max_i |G_i|/τmax_i found is {best_load:.3g} (τmax = {plant.tau_max.tolist()} N m)"
        )
    return np.asarray(best, dtype=np.float64)


def _gravity_load(plant: Plant, q: FloatArray) -> float:
    """max_i |G_i(q)|/τmax_i at rest."""
    d = plant.data
    d.qpos[plant.qpos_adr] = q
    d.qvel[:] = 0.0
    mujoco.mj_forward(plant.model, d)
    return float(np.max(np.abs(d.qfrc_bias[plant.dof_adr]) / plant.tau_max))


TASK_AMPLITUDE = 0.2
"""The largest swing A (rad) of the default task."""


def default_task(plant: Plant, home: ArrayLike | None = None) -> Task:
    """The default task of ``plant`` (SPEC §18): about ``home`` (default
    :func:`home_posture`), every joint swings xc_i = home_i − A_i cos(π t)
    (period 2 s, from rest at home − A, through home, to home + A), A_i =
    min(0.2 rad, range/4), in free space. (The swing of every joint moves the
    arm's gravity and inertia, which learning must then learn; the metrics'
    windows of 2 s hold whole periods.)"""
    from . import tuning

    m = plant.model
    lo, hi = _limits(m, plant.joint_ids)
    h = home_posture(plant) if home is None else plant.vector("home", home)
    kw = tuning.default_task(h, lo, hi)
    q0 = np.asarray(kw["xc_offset"]) + np.asarray(kw["xc_cos"])
    return Task(home=h, q0=q0, keywords=kw, period=2 * math.pi / kw["xc_omega"][0])


#: The keywords whose per-joint values the inertia-shaped gains of SPEC
#: (18.12) tie together (K1, Kζ and the rate Kp/d the same on every joint).
SHAPED_KEYS = ("Kp", "inertia", "K1", "Kzeta")


def rule_coupled(coupled: bool | None, params: Mapping[str, Any]) -> bool | None:
    """The rule's ``coupled`` (SPEC (18.12)) for a caller's keywords ``params``:
    as asked; else, where they set any of :data:`SHAPED_KEYS` (gains of their
    own, which may differ by joint), the diagonal law (False); else the
    rule's default (None: shaped with a delay)."""
    if coupled is None and any(k in params for k in SHAPED_KEYS):
        return False
    return coupled


def rule_keywords(
    plant: Plant,
    task: Task | None = None,
    *,
    Ts: float = 1e-3,
    case: str = "sf",
    delay: int = 0,
    coupled: bool | None = None,
) -> dict[str, Any]:
    """The rule's controller keywords for ``plant`` on ``task`` (default
    :func:`default_task`) at period ``Ts`` (s) for a loop of ``delay``
    periods, SPEC §18 (:func:`adaptimp.tuning.suggest` with D at the task's
    home, the plant's τmax and the task's path; (18.11) for the delay;
    ``coupled``: the inertia-shaped gains of (18.12), by default for a
    ``delay`` ≥ 1 on the joint task), with
    ``impedance="external"`` (in free space the controller tracks the
    reference as given). The plant's own model: give it the nominal plant (no
    payload)."""
    from . import tuning

    task = default_task(plant) if task is None else task
    saved = (np.array(plant.data.qpos), np.array(plant.data.qvel))
    kw = tuning.suggest(
        plant, task.home, plant.tau_max, Ts=Ts, path=task.reference, period=task.period,
        case=case, delay=delay, coupled=coupled,
    )  # fmt: skip
    plant.data.qpos[:], plant.data.qvel[:] = saved
    mujoco.mj_forward(plant.model, plant.data)
    kw["impedance"] = "external"
    return kw


def cartesian_task(
    model: Plant | ModelSource,
    q0: ArrayLike | None = None,
    pose: Any = None,
    *,
    Ts: float = 1e-3,
    span: float | None = None,
    tip: str | None = None,
    fix: Sequence[str] = (),
) -> CartesianTask:
    """A Cartesian task on ``model`` (SPEC §16 (16.8)–(16.11)), for
    ``simulate(case, model, T=…, task=task)``.

    ``pose`` None: the default path, hold the start pose 1 s, then a 3 cm circle
    at 0.5 Hz in the horizontal plane through it, the orientation held (an arm
    of fewer than six joints: the position only). Or the user's path: a callable
    ``t -> (p, ṗ, p̈[, R, ω, ω̇])`` (m, m/s, m/s², (3, 3), rad/s, rad/s²; world
    frame), or those arrays with a row per period ``Ts`` (K, 3), (K, 3, 3);
    ``span`` (s) the part of it the rule samples (default: the arrays' length,
    or 4 s for a callable).

    ``q0`` None: a start posture drawn by the core's posture rule (16.9):
    σmin of the 6 × n Jacobian ≥ 0.05, every joint 0.1 rad (or an eighth of
    its range) inside its limits, gravity ≤ half of every actuator, the joint
    rule's velocity loop well-conditioned and the path reachable, all along
    the task, and no self-collision there; for a given ``pose`` the start is
    the core's inverse kinematics of its first pose. A ``q0`` given must meet
    the same rule, or a ``ConfigError`` names the condition it violates.
    ``tip``, ``fix``: the end effector and the joints held, as :class:`Plant`'s
    (give the same to :func:`simulate`, or a :class:`Plant` to both).
    """
    if isinstance(model, Plant) and (tip is not None or tuple(fix)):
        raise ValueError("tip= and fix= build the Plant: give them to Plant(...), not with one")
    plant = model if isinstance(model, Plant) else Plant(model, contact=False, tip=tip, fix=fix)
    return task_of(plant, q0, pose, Ts=Ts, span=span)
