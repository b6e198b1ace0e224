"""The one posture check of SPEC (16.9): whether a posture can run a task.

:func:`adaptimp.mujoco.cartesian_task` (a start drawn or given),
:meth:`adaptimp.CartesianController.from_rule` (a start given) and the table
scenario (:func:`adaptimp.scenarios.contact.refusal_of`) all call
:func:`assess`: the core's posture rule (``PostureRule``, ``src/cartesian/rule.rs``)
along the task's joint orbit, with gravity, inertia, the joint limits and τmax
from the arm's model, then (for an :class:`adaptimp.mujoco.Plant`) the arm's
self-collision along it. The conditions and their bounds are the core's; the
threshold of the velocity loop's conditioning, K1·Ts/m, is that of the joint
controller that will run (K1 = 50 s⁻¹ for the free-space rule at 1 kHz, 10 s⁻¹
on the table). A refusal names the condition with its bound and the value
measured.

No MuJoCo import here: a Plant's own data is probed through
:mod:`adaptimp._collision`, imported only for one.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp

FloatArray = NDArray[np.float64]

CHECKED = 40
"""Rows of a task's joint orbit at which the rule is checked (evenly spaced)."""

GIVEN_LOAD = 1.0
"""The largest gravity load max_i |G_i|/τmax_i along the task of a start the
user gives (gravity within the actuators); a drawn start keeps the rule's 0.5."""


def checked_rows(steps: int) -> NDArray[np.int64]:
    """The :data:`CHECKED` rows (indices) of an orbit of ``steps`` rows at which
    the rule is checked, evenly spaced from the first to the last."""
    return np.unique(np.linspace(0, steps - 1, CHECKED).round().astype(np.int64))


def plane(chain: Any) -> list[float] | None:
    """The normal of a planar arm's plane (SPEC (16.8): every revolute axis
    parallel, the tip in the plane at right angles to them), from its
    Jacobian; None for an arm that is not planar."""
    normal = _adaptimp.plane_normal(chain.jacobian(np.zeros(chain.n)))
    return None if normal is None else [float(x) for x in normal]


def _is_plant(model: Any) -> bool:
    return hasattr(model, "qpos_adr") and hasattr(model, "model") and hasattr(model, "tau_max")


def limits_of(model: Any, n: int) -> tuple[FloatArray, FloatArray]:
    """The joint ranges (rad) of ``model``, ±inf where a joint is unlimited or
    the model does not say: an ``adaptimp.mujoco.Plant``'s (MuJoCo's), a
    Pinocchio ``Model``'s position limits (a continuous joint's, ±1.8e308,
    as unlimited), none for another model."""
    lo, hi = np.full(n, -math.inf), np.full(n, math.inf)
    if _is_plant(model):
        m = model.model
        for i, j in enumerate(model.joint_ids):
            if m.jnt_limited[j]:
                lo[i], hi[i] = m.jnt_range[j]
    elif (
        type(model).__name__ == "Model"
        and hasattr(model, "lowerPositionLimit")
        and model.nq == model.nv == n
    ):
        a = np.asarray(model.lowerPositionLimit, dtype=np.float64)
        b = np.asarray(model.upperPositionLimit, dtype=np.float64)
        bounded = (np.abs(a) < 1e300) & (np.abs(b) < 1e300) & (a < b)
        lo, hi = np.where(bounded, a, lo), np.where(bounded, b, hi)
    return lo, hi


def _dynamics(model: Any) -> tuple[Any, Any]:
    """G(q) and D(q) of ``model``, as functions of q: a Plant's on a data of its
    own (its state untouched), else :func:`adaptimp.tuning.gravity` and
    :func:`adaptimp.tuning.inertia`."""
    if _is_plant(model):
        from ._collision import _Probe

        probe = _Probe(model)
        return probe.gravity, probe.inertia
    from . import tuning

    def gravity(q: FloatArray) -> FloatArray:
        g = tuning.gravity(model, q)
        return np.zeros(len(q)) if g is None else np.asarray(g, dtype=np.float64)

    return gravity, lambda q: tuning.inertia(model, q)


def assess(
    model: Any,
    chain: Any,
    q0: ArrayLike,
    rows: ArrayLike,
    targets: ArrayLike,
    *,
    orients: bool,
    k1: float | None = None,
    Ts: float = 1e-3,
    load: float | None = None,
    tau_max: ArrayLike | None = None,
    dynamics: tuple[Any, Any] | None = None,
    skip: frozenset[int] = frozenset(),
) -> dict[str, Any]:
    """The posture rule of SPEC (16.9) at the orbit's ``rows`` (K, n; rad: the
    joint reference along the task from the start ``q0``) against the
    commanded positions ``targets`` (K, 3; m) of the same rows, on the arm of
    ``model`` (an ``adaptimp.mujoco.Plant``, a Pinocchio ``Model`` or an
    object with ``D(q)`` and ``G(q)``): σmin(J) along the task (the 6 × n
    Jacobian when it ``orients``, else its translation rows; a planar arm's
    within its plane, :func:`plane`), the joint limits
    with their margin, the gravity load (≤ ``load``: 0.5 by default, 1 for a
    start the user gives), the velocity loop's conditioning at ``q0`` (≥
    K1·Ts/m, ``k1`` (1/s) and ``Ts`` (s) of the joint controller; default the
    rule's K1 at ``Ts``), the path within 1 mm; then, for a Plant, the arm free
    of collisions at the rows, with itself and the rest of the scene
    (:func:`adaptimp.mujoco.collision`; the bodies ``skip`` left out: a tool
    meant to touch). ``tau_max`` (N m): default the model's. ``dynamics``:
    (G(q), D(q)) functions to use instead of the model's.

    Returns the core's assessment (``sigma_min``, ``load``, ``conditioning``,
    ``slack``, ``slack_joint``, ``reach``, ``score``, ``needs``: the bounds)
    with ``error``: None, or the first condition violated, with its bound and
    the value measured."""
    q0 = np.asarray(q0, dtype=np.float64)
    rows = np.ascontiguousarray(rows, dtype=np.float64)
    n = rows.shape[1]
    limits = getattr(model, "tau_max", None) if tau_max is None else tau_max
    if limits is None:
        from ._errors import ConfigError

        raise ConfigError("tau_max (N m) is needed: the model has no .tau_max")
    gravity, inertia = _dynamics(model) if dynamics is None else dynamics
    lo, hi = limits_of(model, n)
    a = dict(
        _adaptimp.assess_posture(
            chain, rows, np.ascontiguousarray(targets, dtype=np.float64),
            np.array([gravity(x) for x in rows]), inertia(q0), lo, hi,
            np.ascontiguousarray(np.broadcast_to(np.asarray(limits, dtype=np.float64), (n,))),
            orients, k1=k1, ts=Ts, load=load, normal=None if orients else plane(chain),
        )
    )  # fmt: skip
    if a["error"] is None and _is_plant(model):
        from ._collision import collision

        hit = collision(model, rows, skip=skip)
        if hit is not None:
            a["error"] = f"free of collision along the task (with itself and the scene): {hit}"
            a["collides"] = True
    return a
