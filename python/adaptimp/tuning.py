"""Gains, a basis and learning rates for an arm nobody tuned for (SPEC §18).

A thin front of the compiled core's rule (``src/control/tuning.rs``; C users
have the same rule). :func:`suggest` turns what a user knows about a new arm
(its inertia at the task's start, from any model: a URDF through Pinocchio or
MuJoCo, or an :class:`adaptimp.PlanarArm`; the actuator limits; the period Ts;
the task's joint path) into keyword parameters for :class:`adaptimp.Controller`
and :func:`adaptimp.simulate` in the robot scenario. Every rate is in the
joint's own units (each joint's inertia scale d_i = 1/(D⁻¹)_ii, SPEC §10):

- **Kp_i = 0.25 d_i / Ts**: the sampled velocity loop of every joint keeps its
  pole at 0.75, whatever the joint's size (with a path, d_i is the mean along
  it of 1/(D⁻¹(q))_ii, bounded so that the loop stays stable at every
  posture of it: SPEC (18.1)); **K1 = min(50 s⁻¹, 0.05/Ts)**;
  **Kζ_i = Kp_i/d_i + ρ/2** with the conditions ``"scaled"`` of SPEC §10
  (met by construction, for any arm, τmax and Ts); kr_i = φ Kp_i/2.
- **Centres along the path** (SPEC §15): L = clip(⌈2·(path length in q)/tube⌉,
  16, 256) samples of one period, widths max(2 h, tube), tube = (0.2 rad,
  0.5 rad/s), widened to twice the sag G/(Kp K1) the arm has before the
  networks learn (with a model that gives G).
- **Learning** (with a path): Ĝ at the bandwidth ω_G² = ½ (Kp/d) K1 per
  unit inertia (Γ_G = ω_G²/⟨‖S‖²⟩), D̂ and Ĉ five times slower, a leak
  time of 25 periods, and weight bounds from τmax and the basis the path
  actually excites.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._errors import ConfigError
from ._inputs import positive, reals
from ._params import flag, loop_delay

FloatArray = NDArray[np.float64]
Path = Callable[[float], tuple[ArrayLike, ArrayLike, ArrayLike]]

PATH_SAMPLES = 1000
"""Samples of one period of a path that :func:`suggest` hands the core."""

INERTIA_SAMPLES = 50
"""Postures along a path at which :func:`suggest` evaluates D(q) for the
inertia scales (SPEC (18.1): their mean along the path, bounded)."""

RULE_KEYS = (
    "Ts",
    "delay",
    "Kp",
    "K1",
    "Kzeta",
    "inertia",
    "rho",
    "conditions",
    "kr",
    "fallback_damping",
    "gamma",
    "sigma",
    "weight_bound",
    "tau_max",
)
"""The keywords :func:`suggest` returns (the rest are the robot scenario's)."""


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

        if model.nq != model.nv:  # continuous joints: angles from the neutral configuration
            q = pin.integrate(model, pin.neutral(model), q)
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


def gravity(model: Any, q: ArrayLike) -> FloatArray | None:
    """The gravity torque G(q) (N m, (n,)) of ``model`` if it can tell: an object
    with ``G(q)``, a Pinocchio ``Model`` or an ``adaptimp.mujoco.Plant``; None
    for a bare inertia matrix."""
    q = np.asarray(q, dtype=np.float64)
    if hasattr(model, "G"):
        return np.asarray(model.G(q), dtype=np.float64)
    if hasattr(model, "bias") and hasattr(model, "reset"):
        model.reset(q)
        return np.asarray(model.bias(), dtype=np.float64)
    if type(model).__name__ == "Model" and hasattr(model, "nq"):
        import pinocchio as pin

        if model.nq != model.nv:
            q = pin.integrate(model, pin.neutral(model), q)
        return np.asarray(pin.computeGeneralizedGravity(model, model.createData(), q))
    return None


def is_weightless(model: Any) -> bool:
    """Whether ``model`` has no gravity at all: an ``adaptimp.mujoco.Plant``
    whose MuJoCo gravity is zero (e.g. :func:`adaptimp.franka.plant`, the arm
    as the controller acts on it on a robot that compensates gravity), or a
    Pinocchio ``Model`` whose gravity is zero; False for any other model
    (one that gives only D(q) and G(q) cannot say it everywhere)."""
    m = getattr(model, "model", None)
    if m is not None and hasattr(m, "opt") and hasattr(model, "reset"):
        return bool(np.all(np.asarray(m.opt.gravity) == 0.0))
    if type(model).__name__ == "Model" and hasattr(model, "gravity") and hasattr(model, "nq"):
        return bool(np.all(np.asarray(model.gravity.linear) == 0.0))
    return False


def joint_damping(model: Any) -> FloatArray | None:
    """The viscous damping (N m s/rad, (n,)) of ``model``'s joints if it has any:
    an ``adaptimp.mujoco.Plant``'s (MuJoCo's ``dof_damping`` of the arm's
    joints, which MuJoCo integrates implicitly); None for every other model
    (a Pinocchio ``Model`` or a URDF compiled without its drive terms carries
    none), or if every joint's is zero."""
    m = getattr(model, "model", None)
    dofs = getattr(model, "dof_adr", None)
    if m is None or dofs is None or not hasattr(m, "dof_damping"):
        return None
    b = np.asarray(m.dof_damping[np.asarray(dofs)], dtype=np.float64)
    return b if np.any(b > 0) else None


def sample_path(path: Path, period: float, n: int) -> FloatArray:
    """One period of ``path(t) -> (q, dq, ddq)`` as a (K, 3n) array, K =
    :data:`PATH_SAMPLES` instants evenly spaced from t = 0 (the first not
    repeated)."""
    if not (period > 0 and np.isfinite(period)):
        raise ConfigError(f"a path needs its period (s) > 0, got {period}")
    rows = np.empty((PATH_SAMPLES, 3 * n))
    for k in range(PATH_SAMPLES):
        q, dq, ddq = path(period * k / PATH_SAMPLES)
        for j, v in enumerate((q, dq, ddq)):
            rows[k, j * n : (j + 1) * n] = np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
    return rows


def suggest(
    model: Any,
    q0: ArrayLike,
    tau_max: ArrayLike,
    *,
    Ts: float = 1e-3,
    path: Path | ArrayLike | None = None,
    period: float | None = None,
    case: str = "sf",
    resolve: bool = False,
    critical: bool = False,
    damping: ArrayLike | None = None,
    orbit: ArrayLike | None = None,
    delay: int = 0,
    weightless: bool | None = None,
    coupled: bool | None = None,
) -> dict[str, Any]:
    """Controller keywords for an arm from its inertia (at ``q0`` (rad), or along
    the task's joint path if given: :data:`INERTIA_SAMPLES` postures of it), its
    actuator limits ``tau_max`` (N m) and the path (SPEC §18, module docs).

    Parameters
    ----------
    model
        What gives D(q): see :func:`inertia`.
    q0 : array_like, shape (n,)
        The posture the gains are computed at without a path (rad), and the
        gravity torque for the tube with one: the task's start.
    tau_max : float or array_like, shape (n,)
        Actuator limits (N m).
    Ts : float
        Control period (s).
    path : callable or array_like, optional
        ``path(t) -> (q, dq, ddq)``, the task's joint path (rad, rad/s, rad/s²),
        periodic with ``period`` (s): the RBF centres go along it and the
        learning rates follow from the basis it excites; or its samples, (K,
        3n) rows [q, q̇, q̈] evenly spaced in time over one period. Without it:
        the gains only (a controller for n ≤ 3 then uses the vertex grid,
        beyond it the default basis along its own trajectory, SPEC §18).
    case : {"pd", "sf", "of"}
        The controller (the keywords are the same for all three).
    resolve : bool
        Narrow the tube to the path's own size, SPEC (16.10): tube_b =
        min(tube_b, ℓ_b/10), ℓ_b the closed path's length in q and in q̇ (the
        Cartesian rule's: a small joint orbit gets the joint task's resolution).
    critical : bool
        Ĝ learns at the velocity loop's critical bandwidth ω_G² = (m/Ts)²/4,
        SPEC (19.6) (the table scenario's; (18.6)'s ½ (m/Ts) K1 otherwise).
    damping : float or array_like, shape (n,), optional
        The joints' viscous damping (N m s/rad); default the plant's own
        (:func:`damping`: an ``adaptimp.mujoco.Plant``'s joints, none for
        other models). The inertia scales become those the sampled velocity
        loop sees, SPEC (18.9): d̃ = b Ts/(1 − e^(−b Ts/d)), d for b = 0.
    orbit : array_like, shape (K', n), optional
        The joint positions (rad) of one period of the motion that repeats
        (the table's circle, after the approach): the centres' widths in q at
        least its diameter, SPEC (19.11) (the table scenario's). With a path only.
    delay : int
        The loop's delay δ (periods, 0 ≤ δ ≤ 64): the torque of a sample acts
        δ periods after it was taken (libfranka: 1). The margin m of Kp = m
        d/Ts keeps the sampled velocity loop's largest mode along the path at
        the pole radius of SPEC (18.11) (δ = 0: m = 0.25 as it is); the
        controller's ``delay`` keyword.
    weightless : bool, optional
        The arm bears no gravity the controller must hold (a robot that adds
        its own model's gravity torque to every command, as a Franka does,
        or an arm in a horizontal plane): D̂ and Ĉ learn at Ĝ's bandwidth,
        SPEC (22.2). Default: whether the model has no gravity at all
        (:func:`is_weightless`).
    coupled : bool or None
        The inertia-shaped gains of SPEC (18.12): Dₛ (kg m²) the harmonic
        mean of D along the path, (mean D⁻¹)⁻¹ (D(q0) without one), in place
        of the diagonal scales in Kp, the z1 term and the learning error, and
        the margin of (18.11) at the largest mode of Dₛ^½ D⁻¹ Dₛ^½: the
        delayed loop's modes stay together where the diagonal's spread (the
        keyword ``inertia_matrix``, n × n values row-major). Default None:
        for a loop with a delay (``delay`` ≥ 1), where (18.11)'s margin
        bounds the gains (with ``resolve``, a Cartesian task's orbit, Ĝ then
        learns at ω_G² at least (m/Ts) K1: the joints' Coulomb friction,
        SPEC (18.12) "On an orbit"); False: the diagonal rule of (18.1),
        per-joint gains.

    Returns
    -------
    dict
        ``n`` and the keywords of :data:`RULE_KEYS`, ``inertia_matrix`` when
        the gains are shaped (``coupled`` True, or None with a ``delay``)
        and, with a path, ``centers`` (L, 4n) and ``widths`` (4n,): keywords of
        ``adaptimp.Controller(case, "robot", **kw)``, which construction accepts.

    Raises
    ------
    ConfigError
        D(q0) not symmetric positive definite, τmax ≤ 0, Ts outside (0, 1] s,
        a shape that does not match (each named).
    """
    # Named as written (text, bools, complex numbers, a NaN q0, a τmax of
    # another length were taken, or refused in NumPy's words).
    q0 = reals("q0", q0)
    Ts = positive("Ts", Ts)
    joints = getattr(model, "n", getattr(model, "nv", None))
    if isinstance(joints, int) and q0.shape != (joints,):
        raise ConfigError(f"q0 must have shape ({joints},) (one value per joint), got {q0.shape}")
    d = inertia(model, q0)
    n = d.shape[0]
    limits = reals("tau_max", tau_max, finite=False)
    if limits.shape not in ((), (n,)):
        raise ConfigError(f"tau_max must be a number or have shape ({n},), got {limits.shape}")
    tau = np.ascontiguousarray(np.broadcast_to(limits, (n,)))
    rows = None
    if path is not None:
        if period is None:
            raise ConfigError("a path needs its period (s)")
        if callable(path):
            rows = sample_path(path, period, n)
        else:
            rows = np.ascontiguousarray(np.asarray(path, dtype=np.float64))
        if rows.ndim != 2 or rows.shape[0] == 0 or rows.shape[1] != 3 * n:
            raise ConfigError(f"path must have shape (K, {3 * n}), got {rows.shape}")
        step = max(1, rows.shape[0] // INERTIA_SAMPLES)
        d = np.stack([inertia(model, q) for q in rows[::step, :n]])
    g = gravity(model, q0) if rows is not None else None
    b = joint_damping(model) if damping is None else damping
    b_arr = (
        None
        if b is None
        else np.ascontiguousarray(np.broadcast_to(np.asarray(b, dtype=np.float64), (n,)))
    )
    if orbit is not None:
        orbit = np.ascontiguousarray(np.asarray(orbit, dtype=np.float64))
        if orbit.ndim != 2 or orbit.shape[1] != n:
            raise ConfigError(f"orbit must have shape (K, {n}), got {orbit.shape}")
    light = is_weightless(model) if weightless is None else bool(weightless)
    out = _adaptimp.suggest(
        case, np.ascontiguousarray(d), tau, float(Ts), rows, period, g, resolve=resolve,
        critical=critical, damping=b_arr, orbit=orbit, delay=loop_delay({'delay': delay}),
        weightless=light, coupled=None if coupled is None else flag("coupled", coupled),
    )  # fmt: skip
    kw: dict[str, Any] = {"n": n}
    kw.update({k: out["params"][k] for k in RULE_KEYS})
    if out["params"]["inertia_matrix"] is not None:
        kw["inertia_matrix"] = out["params"]["inertia_matrix"]
    if "centers" in out:
        kw["centers"], kw["widths"] = out["centers"], out["widths"]
    return kw


def default_task(home: ArrayLike, lo: ArrayLike, hi: ArrayLike) -> dict[str, list[float]]:
    """The default task of SPEC §18 about the posture ``home`` (rad) for joints
    limited to [``lo``, ``hi``] (rad; ±inf for a continuous joint): every joint
    swings xc_i = home_i − A_i cos(π t) (period 2 s, from rest), A_i =
    min(0.2 rad, range/4). Returns the keywords ``xc_offset``, ``xc_sin``,
    ``xc_cos``, ``xc_omega``.

    Raises
    ------
    ConfigError
        lo ≥ hi on some joint, or ``home`` closer than A to a limit.
    """
    arrays = [np.ascontiguousarray(np.asarray(v, dtype=np.float64)) for v in (home, lo, hi)]
    o, a, b, w = _adaptimp.default_task(*arrays)
    return {"xc_offset": o, "xc_sin": a, "xc_cos": b, "xc_omega": w}
