"""Gains and a basis for an arm nobody tuned for (SPEC §18).

:func:`suggest` turns what a user knows about a new arm (its inertia at a
posture, from any model: a URDF through Pinocchio or MuJoCo, or an
:class:`adaptimp.PlanarArm`; the actuator limits; the period Ts; the task's
joint path) into keyword parameters for :class:`adaptimp.Controller` and
:func:`adaptimp.simulate` in the robot scenario:

- **Kp_i = m / (Ts (D⁻¹)_ii)** with the margin m = 0.25: the velocity loop
  z2⁺ ≈ (1 − Ts Kp (D⁻¹)_ii) z2 of one sampled joint keeps its pole at 0.75
  (stable for m < 2, not ringing for m < 1), whatever the arm's size; the
  paper's Kp = 10 is this rule for its arm's heavy first joint.
- **K1 = min(20 s⁻¹, 0.05 / Ts)**: the position loop 5× slower than the
  velocity loop at most.
- **Kζ_i = (1 + Kp_i²)/2 + 10**: SPEC §10's 2Kζ − 1 − Kp² > 0 with a margin.
- **Γ = 1** for the three networks, the normalised learning step and the rest
  of the robot scenario's hardening (SPEC §13).
- **Centres along the task's joint path** (SPEC §15): L = 2·(path length in
  q)/tube_q samples over one period, clipped to [16, 256], at [q; q̇] of the
  samples, widths η_b = max(2 h_b, tube_b) (h_b the largest spacing of
  consecutive samples), α1 and α̇1 left out (infinite widths).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]
Path = Callable[[float], tuple[ArrayLike, ArrayLike, ArrayLike]]


def inertia(model: Any, q: ArrayLike) -> FloatArray:
    """The inertia matrix D(q) (kg m², (n, n)) of ``model``: an object with ``D(q)``
    (``PlanarArm``, ``TwoLinkArm``), a Pinocchio ``Model``, an
    ``adaptimp.mujoco.Plant``, or D itself as an (n, n) array."""
    q = np.asarray(q, dtype=np.float64)
    if hasattr(model, "D"):
        return np.asarray(model.D(q), dtype=np.float64)
    if hasattr(model, "mass_matrix") and hasattr(model, "reset"):
        model.reset(q)
        return np.asarray(model.mass_matrix(), dtype=np.float64)
    if type(model).__name__ == "Model" and hasattr(model, "nq"):
        import pinocchio as pin

        d = pin.crba(model, model.createData(), q)
        return np.asarray(np.triu(d) + np.triu(d, 1).T, dtype=np.float64)
    try:
        arr = np.asarray(model, dtype=np.float64)
    except (TypeError, ValueError):
        arr = np.zeros(0)
    if arr.ndim != 2 or arr.shape[0] != arr.shape[1]:
        raise TypeError(
            "model must have D(q), be a Pinocchio Model or an adaptimp.mujoco.Plant, "
            f"or be an (n, n) inertia matrix; got {type(model).__name__}"
        )
    return arr


def orbit_centres(
    samples_q: ArrayLike, samples_dq: ArrayLike, tube: tuple[float, float] = (0.2, 0.5)
) -> tuple[FloatArray, FloatArray]:
    """Centres at the samples [q; q̇] of one period of a joint path (rows) and their
    widths (4n,), SPEC (15.2): η_b = max(2 h_b, tube_b) for b = q (rad), q̇ (rad/s),
    infinite for α1, α̇1; the period closes on itself (the core's
    ``Centers::along_periodic``)."""
    from . import _adaptimp

    q = np.ascontiguousarray(np.atleast_2d(np.asarray(samples_q, dtype=np.float64)))
    dq = np.ascontiguousarray(np.atleast_2d(np.asarray(samples_dq, dtype=np.float64)))
    centres, widths2 = _adaptimp.centres_along(
        q, dq, (float(tube[0]), float(tube[1])), periodic=True
    )
    return np.asarray(centres, dtype=np.float64), np.sqrt(widths2)


def suggest(
    model: Any,
    q0: ArrayLike,
    tau_max: ArrayLike,
    *,
    Ts: float = 1e-3,
    path: Path | None = None,
    period: float | None = None,
    tube: tuple[float, float] = (0.2, 0.5),
    margin: float = 0.25,
) -> dict[str, Any]:
    """Controller keywords for an arm from its inertia at ``q0`` (rad), its actuator
    limits ``tau_max`` (N m) and the task's joint path (SPEC §18, module docs).

    Parameters
    ----------
    model
        What gives D(q): see :func:`inertia`.
    q0 : array_like, shape (n,)
        The posture the gains are computed at (rad): the task's start.
    tau_max : float or array_like, shape (n,)
        Actuator limits (N m).
    Ts : float
        Control period (s).
    path : callable, optional
        ``path(t) -> (q, dq, ddq)``, the task's joint path (rad, rad/s, rad/s²),
        periodic with ``period`` (s): the RBF centres go along it. Without it
        the result has no ``centers`` (the vertex grid, n ≤ 3).
    tube : (float, float)
        How far from the path (rad, rad/s) the networks should act.
    margin : float
        m of Kp_i = m/(Ts (D⁻¹)_ii), in (0, 1).

    Returns
    -------
    dict
        ``n``, ``Kp``, ``K1``, ``Kzeta``, ``gamma``, ``tau_max`` and, with a
        path, ``centers`` (L, 4n) and ``widths`` (4n,): keywords of
        ``adaptimp.Controller(case, "robot", **kw)``.
    """
    if not 0 < margin < 1:
        raise ValueError(f"margin must be in (0, 1), got {margin}")
    d = inertia(model, q0)
    n = d.shape[0]
    dinv = np.diag(np.linalg.inv(d))
    if np.any(dinv <= 0) or not np.all(np.isfinite(dinv)):
        raise ValueError("the inertia matrix at q0 is not positive definite")
    kp = margin / (Ts * dinv)
    out: dict[str, Any] = {
        "n": n,
        "Kp": [float(x) for x in kp],
        "K1": float(min(20.0, 0.05 / Ts)),
        "Kzeta": [float((1 + x * x) / 2 + 10) for x in kp],
        "gamma": 1.0,
        "tau_max": [float(x) for x in np.broadcast_to(np.asarray(tau_max, float), (n,))],
    }
    if path is not None:
        if period is None or not period > 0:
            raise ValueError("a path needs its period (s) > 0")

        def at(t: float, k: int) -> FloatArray:
            return np.broadcast_to(np.asarray(path(t)[k], dtype=np.float64), (n,))

        fine = np.array([at(t, 0) for t in np.linspace(0, period, 1001)])
        length = float(np.sum(np.linalg.norm(np.diff(fine, axis=0), axis=1)))
        nodes = int(min(256, max(16, math.ceil(2 * length / tube[0]))))
        times = np.arange(nodes) * period / nodes
        q = np.array([at(t, 0) for t in times])
        dq = np.array([at(t, 1) for t in times])
        out["centers"], out["widths"] = orbit_centres(q, dq, tube)
    return out
