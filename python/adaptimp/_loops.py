"""The run's dispatch (SPEC §13.1): which of the core's loops steps a
controller (:data:`LOOPS`: the core's controller, a Cartesian controller,
computed torque, a controller written in Python called back), the state a
run hands them (:class:`Run`), and a reference tabulated for them.

Units: rad, rad/s, rad/s², N m, m, s."""

from __future__ import annotations

import math
import sys
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import _adaptimp
from ._deprecated import period_of
from ._inputs import reals
from ._plant import Plant
from ._pose import call_shape, task_space
from ._tasks import Task
from ._trajectory import Reference, sinusoid

FloatArray = NDArray[np.float64]


class _Table:
    """A reference tabulated at t_k = k·Ts, as a callable of t (the row of t),
    with its arrays (xc, dxc, ddxc), one row per step."""

    def __init__(self, arrays: tuple[FloatArray, FloatArray, FloatArray], Ts: float) -> None:
        self.arrays, self.Ts = arrays, Ts

    def __call__(self, t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        xc, dxc, ddxc = self.arrays
        k = min(max(round(t / self.Ts), 0), xc.shape[0] - 1)
        return xc[k], dxc[k], ddxc[k]


def _checked_reference(reference: Reference, n: int) -> Reference:
    """``reference`` whose every value is checked: three arrays (xc, dxc, ddxc)
    of shape (n,), else an error naming the reference, t and what it gave (a
    2-tuple was an IndexError, a wrong length a broadcast error)."""

    def checked(t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        got = reference(t)
        values = tuple(got) if isinstance(got, (tuple, list)) else None
        if values is None or len(values) != 3:
            size = "not a tuple" if values is None else f"{len(values)} values"
            raise ValueError(
                f"reference(t) must return 3 arrays (xc, dxc, ddxc), got {size} at t = {t:g}"
            )
        out = []
        for name, v in zip(("xc", "dxc", "ddxc"), values):
            try:
                a = np.asarray(v, dtype=np.float64)
            except (TypeError, ValueError):
                raise TypeError(
                    f"reference(t)'s {name} must be reals, got {v!r} at t = {t:g}"
                ) from None
            if a.shape != (n,):
                raise ValueError(
                    f"reference(t)'s {name} must have shape ({n},), got {a.shape} at t = {t:g}"
                )
            out.append(a)
        return out[0], out[1], out[2]

    return checked


def table_reference(reference: Any, n: int, Ts: float, steps: int) -> Reference:
    """``reference`` as a callable of t: a callable as it is; (xc, dxc, ddxc)
    arrays of shape (K, n), K ≥ ``steps`` (or an object with those attributes,
    e.g. a :class:`MujocoResult`), row k at t_k = k·Ts (n: the width of the
    controller's reference, 3 for a Cartesian controller's p_c)."""
    if isinstance(reference, _Table):
        return reference
    if callable(reference):
        return _checked_reference(reference, n)
    if all(hasattr(reference, a) for a in ("xc", "dxc", "ddxc")):
        reference = (reference.xc, reference.dxc, reference.ddxc)
    try:
        xc, dxc, ddxc = (np.asarray(a, dtype=np.float64) for a in reference)
    except (TypeError, ValueError) as e:
        raise TypeError(
            "reference must be a callable t -> (xc, dxc, ddxc), the arrays (xc, dxc, ddxc) "
            "of shape (K, n), or a result that has them"
        ) from e
    for name, a in (("xc", xc), ("dxc", dxc), ("ddxc", ddxc)):
        if a.ndim != 2 or a.shape[1] != n or a.shape[0] < steps:
            raise ValueError(
                f"reference {name} must have shape (K, {n}) with K ≥ {steps} rows (one per "
                f"step), got {a.shape}"
            )
        if not np.all(np.isfinite(a[:steps])):
            raise ValueError(f"reference {name} must be finite")
    return _Table((xc, dxc, ddxc), Ts)


def period_of_controller(ctrl: Any) -> float:
    """The period Ts (s) of a controller: its ``.Ts``, else the deprecated
    earlier name (warning); TypeError if it has neither."""
    value = getattr(ctrl, "Ts", None)
    if value is not None:
        return float(value)
    old = period_of(ctrl)  # the earlier name, deprecated
    if old is not None:
        return old
    raise TypeError(f"the controller {ctrl!r} has no period: give it a .Ts (s)")


def _builtin_reference(ctrl: Any) -> Reference | None:
    """The controller's own sinusoid (SPEC §4), if its params declare one."""
    params = getattr(ctrl, "params", None)
    keys = ("xc_offset", "xc_sin", "xc_cos", "xc_omega")
    if isinstance(params, Mapping) and all(k in params for k in keys):
        return sinusoid(*(params[k] for k in keys))
    return None


DISTURBANCES = (
    "noise_q",
    "noise_dq",
    "noise_tau_e",
    "seed",
    "plant_delay",
    "jitter",
    "friction_viscous",
    "friction_coulomb",
    "friction_vs",
    "actuator_fraction",
)
"""The disturbances of SPEC §17 that :func:`simulate` takes by name (the
schema's; ``jitter`` must stay 0 on MuJoCo, whose timestep is fixed for a run)."""


def native(ctrl: Any) -> bool:
    """Whether the core can step ``ctrl`` itself: an ``adaptimp.Controller``
    whose ``step`` is the compiled one."""
    return isinstance(ctrl, _adaptimp.Controller) and type(ctrl).step is _adaptimp.Controller.step


def native_computed(ctrl: Any) -> bool:
    """Whether the core can step ``ctrl`` as it is in joint space: an
    :class:`adaptimp.baselines.ComputedTorque` (its own ``step``, the core's
    law of SPEC §20)."""
    baselines = sys.modules.get("adaptimp.baselines")
    return (
        baselines is not None
        and isinstance(ctrl, baselines.ComputedTorque)
        and isinstance(ctrl.core_joint, _adaptimp.ComputedTorque)
    )


def native_cartesian(ctrl: Any) -> bool:
    """Whether the core can step ``ctrl`` as a whole: an
    :class:`adaptimp.CartesianController` (its own ``step``) in front of a
    joint controller the core steps (a case name's)."""
    from .cartesian import CartesianController

    return (
        isinstance(ctrl, CartesianController)
        and type(ctrl).step is CartesianController.step
        and ctrl.core_joint is not None
        and (native(ctrl.inner) or isinstance(ctrl.core_joint, _adaptimp.ComputedTorque))
    )


def tabulate(
    reference: Reference, steps: int, Ts: float, width: int, k0: int = 0
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``reference((k0 + k)·Ts)`` for every row k, as three (K, ``width``)
    arrays (called in order, once per row, as the loop would; a table's own
    rows), by the core's tabulation (``_adaptimp.tabulate_joints``)."""
    if isinstance(reference, _Table) and math.isclose(reference.Ts, Ts, rel_tol=1e-12) and not k0:
        xc, dxc, ddxc = (np.ascontiguousarray(a[:steps]) for a in reference.arrays)
        return xc, dxc, ddxc
    xc, dxc, ddxc = _adaptimp.tabulate_joints(
        reference, steps, Ts, width, k0, "reference(t)", _reals_of_shape
    )
    return xc, dxc, ddxc


def _reals_of_shape(name: str, value: Any, shape: tuple[int, ...]) -> FloatArray:
    """The core's tabulation's check of a value that is not a float64 array of
    ``shape`` (:func:`adaptimp._inputs.reals`, NaN let through as before)."""
    return reals(name, value, shape, finite=False)


def _native_loop(
    run: Run, progress: Callable[[int, int], object] | None, fault: Any
) -> dict[str, Any]:
    """An ``adaptimp.Controller`` stepped by the core, along its own
    trajectory or the run's reference tabulated at t_k."""
    refs = (
        None if run.reference is None else tabulate(run.reference, run.steps, run.Ts, run.plant.n)
    )
    out: dict[str, Any] = _adaptimp.simulate_mujoco(
        run.ctrl, run.plant.model, run.plant.data, run.spec, run.dist, run.T, run.settle,
        run.every, progress, refs, fault,
    )  # fmt: skip
    return out


def _cartesian_loop(
    run: Run, progress: Callable[[int, int], object] | None, fault: Any
) -> dict[str, Any]:
    """The native loop of an :class:`adaptimp.CartesianController` whose joint
    controller the core steps (:meth:`~adaptimp.CartesianController.run_core`),
    along the reference at t_k, else its path on its own clock."""
    ctrl, reference = run.ctrl, run.reference
    table = reference.arrays if isinstance(reference, _Table) else reference

    def loop(joint: Any, targets: FloatArray | None) -> dict[str, Any]:
        out: dict[str, Any] = ctrl.outer.core.simulate_mujoco(
            joint, run.plant.model, run.plant.data, run.spec, run.dist, run.T,
            run.settle, run.every, progress, targets, fault,
        )  # fmt: skip
        return out

    ran: tuple[dict[str, Any], FloatArray | None] = ctrl.run_core(run.steps, table, loop)
    out, targets = ran
    out["targets"] = _pose_table(ctrl, targets, out.get("task"), run.every)
    return out


def _pose_table(
    ctrl: Any, targets: FloatArray | None, log: dict[str, FloatArray] | None, every: int
) -> FloatArray | None:
    """The commanded pose of every step of a Cartesian controller's run (steps,
    24): its ``targets``, or, where it held its last target (no path, no
    reference), the run's commanded positions ``log["pc"]`` (kept every
    ``every``-th row) with the rotation held."""
    if targets is not None:
        return targets
    if log is None or "pc" not in log or len(log["pc"]) == 0:
        return None
    pc = np.asarray(log["pc"], dtype=np.float64)
    table = np.zeros((len(pc) * every, 24))
    table[:, 0:3] = np.repeat(pc, every, axis=0)
    table[:, 9:18] = np.asarray(ctrl.outer.held_rotation, dtype=np.float64).reshape(9)
    return table


def _computed_loop(
    run: Run, progress: Callable[[int, int], object] | None, fault: Any
) -> dict[str, Any]:
    """:class:`adaptimp.baselines.ComputedTorque` stepped by the core in joint
    space, along the run's reference or its own trajectory, tabulated at its
    t_k = (k0 + k)·Ts (k0 the steps it took before), as its ``step`` samples it."""
    ctrl, Ts = run.ctrl, run.Ts
    if run.reference is not None:
        refs = tabulate(run.reference, run.steps, Ts, run.plant.n)
    else:
        if ctrl.trajectory is None:
            raise ValueError("no setpoint given and no trajectory to follow")
        k0 = int(ctrl.core.steps)
        refs = tabulate(ctrl.trajectory, run.steps, Ts, run.plant.n, k0)
    out: dict[str, Any] = ctrl.core.simulate_mujoco(
        run.plant.model, run.plant.data, run.spec, run.dist, run.T, run.settle, refs,
        run.every, progress, fault,
    )  # fmt: skip
    return out


_ATTRIBUTES = ("tau", "xc", "dxc", "ddxc", "xd", "z1", "dq_hat", "zeta")
"""The attributes of a controller written in Python that a run records (ControllerLike)."""


def _callback_loop(
    run: Run, progress: Callable[[int, int], object] | None, fault: Any
) -> dict[str, Any]:
    """A controller written in Python in the core's loop, called back once a
    period (the protocol :class:`ControllerLike`): its setpoint (the
    reference's rows) and the attributes it has, the rates of its own
    trajectory (if its params declare one), and its target impedance for
    the metrics, given to the core."""
    ctrl, n, steps, Ts = run.ctrl, run.plant.n, run.steps, run.Ts
    in_task = task_space(ctrl)
    call = call_shape(ctrl)
    width = 3 if in_task else n
    has = {name: hasattr(ctrl, name) for name in _ATTRIBUTES}
    reference = run.reference
    own_rates = reference is None and has["dxc"] and has["ddxc"]
    if reference is not None:
        table = tabulate(reference, steps, Ts, width)
    else:
        nan = np.full((steps, width), math.nan)
        # The rates of its own joint-space sinusoid, if its params declare one.
        rates = None if own_rates or in_task else _builtin_rates(ctrl, steps, Ts)
        table = (nan, *(rates or (nan, nan)))
    attrs = [name for name in ("tau", "xc", "xd", "z1", "dq_hat", "zeta") if has[name]]
    # An adaptimp.CartesianController's commanded pose of every step (or that of
    # one behind an object of the user's), for its pose errors: taken before it
    # steps (its path on its own clock).
    poses_of: Any = getattr(ctrl, "commanded_poses", None) if in_task else None
    cartesian = in_task and hasattr(ctrl, "chain") and callable(poses_of)
    poses = None
    if cartesian:
        given = reference.arrays if isinstance(reference, _Table) else reference
        poses = poses_of(steps, given)
    cparams = getattr(ctrl, "params", None)
    cparams = cparams if isinstance(cparams, Mapping) else {}
    target = tuple(
        np.broadcast_to(np.asarray(cparams.get(k, v), dtype=np.float64), (n,)).tolist()
        for k, v in (("Dd", 1.0), ("Cd", 10.0), ("Gd", 60.0))
    )
    out: dict[str, Any] = _adaptimp.simulate_mujoco_callback(
        ctrl, run.plant.model, run.plant.data, run.spec, run.dist, Ts, run.T, run.settle, table,
        setpoint=reference is not None, task_space=in_task, call=call,
        attrs=attrs + (["rates"] if own_rates else []), target=target, record_every=run.every,
        progress=progress, fault=fault,
    )  # fmt: skip
    # A task-space controller's own log of this run (adaptimp.CartesianController.arrays).
    log = getattr(ctrl, "arrays", None) if in_task and getattr(ctrl, "record", False) else None
    if callable(log):
        out["task"] = {k: v[len(v) - steps :: run.every] for k, v in log().items()}
    if cartesian:
        out["targets"] = _pose_table(ctrl, poses, out.get("task"), run.every)
    return out


def _builtin_rates(ctrl: Any, steps: int, Ts: float) -> tuple[FloatArray, FloatArray] | None:
    """ẋc, ẍc of every row of the controller's own sinusoid, if its params
    declare one (for the impedance metric), on its clock from the steps it
    says it took."""
    builtin = _builtin_reference(ctrl)
    if builtin is None:
        return None
    k0 = getattr(ctrl, "steps", 0)
    k0 = k0 if isinstance(k0, int) else 0
    # (sinusoid's reference broadcasts: one row per time.)
    own = (k0 + np.arange(steps, dtype=np.float64)) * Ts
    _, dxc, ddxc = builtin(own[:, None])  # type: ignore[arg-type]
    return np.ascontiguousarray(dxc, dtype=np.float64), np.ascontiguousarray(ddxc, dtype=np.float64)


LOOPS: dict[str, Callable[[Run, Callable[[int, int], object] | None, Any], dict[str, Any]]] = {
    "native": _native_loop,
    "cartesian": _cartesian_loop,
    "computed": _computed_loop,
    "callback": _callback_loop,
}
"""How the core's loop takes each kind of controller (:func:`_setup` says which)."""


@dataclass
class Run:
    """A run of :func:`simulate`, set up: its controller, plant and settings."""

    ctrl: Any
    plant: Plant
    label: str
    scenario: str
    Ts: float
    T: float
    settle: float
    substeps: int
    steps: int
    every: int
    dist: dict[str, Any]
    spec: dict[str, Any]
    kind: str
    reference: Reference | None
    task: Task | None
    payload: float
    q0: FloatArray
