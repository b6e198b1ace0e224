"""The run of :mod:`adaptimp.mujoco` (SPEC §13.1): :func:`simulate` (the
set-up of the controller, the plant and the loop, then the core's loop
through :mod:`adaptimp._loops`, then the result and its checks), and many
runs at once (:func:`run_many`).

Re-exported by :mod:`adaptimp.mujoco`. Units: rad, rad/s, N m, m, s."""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Mapping, Sequence
from typing import Any, Protocol

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._cartesian_task import CartesianTask, measure
from ._errors import ConfigError
from ._faults import Fault
from ._loops import (
    DISTURBANCES,
    LOOPS,
    Run,
    native,
    native_cartesian,
    native_computed,
    period_of_controller,
    table_reference,
    tabulate,
)
from ._mujoco_result import MujocoResult
from ._params import flag, loop_delay
from ._plant import Plant, uses_rule
from ._plant_models import ModelSource, with_payload
from ._pose import task_space
from ._run_checks import check_delay, check_refused, check_run, check_tracking
from ._tasks import Task, default_task, rule_coupled, rule_keywords
from ._trajectory import Reference, sinusoid

FloatArray = NDArray[np.float64]


class ControllerLike(Protocol):
    """What :func:`simulate` needs of a controller written in Python: a step and
    a period. The core's loop calls it back once a period (with the GIL taken
    for the call; the rest of the loop runs without it).

    ``step(m, **setpoint)`` returns the torque to apply (N m), (n,) (or one
    number for every joint; saturated by the motors). ``m`` is an
    :class:`adaptimp.Measurement`: what the loop's sensors read (with the
    disturbances of SPEC §17 and a fault, if any), ``m.q`` (rad), ``m.dq``
    (rad/s), ``m.tau_e`` (N m, (n,)) and the wrench at the tip ``m.wrench``
    F_e = [f; m] (N, N m, (6,), world frame; the plant's measurement of the
    row, the one τe is computed from): a joint-space controller reads τe, a
    task-space one F_e. Every controller of adaptimp takes the same call.
    ``setpoint`` is ``xc=, dxc=, ddxc=`` (the row's) when :func:`simulate` is
    given a ``reference``, nothing otherwise (the controller then follows
    its own trajectory). The period is ``.Ts`` (s; ``.ts`` is read,
    deprecated). Optional attributes that :func:`simulate` records when
    present: ``zeta`` (read before the step), then, after it, ``xc`` and,
    without a ``reference``, ``dxc``, ``ddxc`` (the controller's own
    commanded rates), ``xd``, ``z1``, ``dq_hat``, ``tau`` (commanded torque
    before saturation); and ``params`` (a dict; ``xc_offset``, ``xc_sin``,
    ``xc_cos``, ``xc_omega``, ``Dd``, ``Cd``, ``Gd`` are used for the metrics
    when present). An exception raised by ``step`` (or a torque of another
    shape) ends the run with it; a torque that is not finite ends it too
    (``ValueError``), unless a fault is injected: then the step is refused,
    as the core's controllers' are, and zero torque applied.

    A controller in task space says so with ``task_space = True`` (e.g.
    :class:`adaptimp.CartesianController`, which maps the wrench to the
    joints itself): its ``xc``, ``xd``, ``z1`` are then of width 3 (m).

    Deprecated (one release, with a ``DeprecationWarning``): a step that
    takes ``(q, tau_e, dq, **setpoint)`` (a step one positional argument
    cannot bind) is called so, and with ``wants_wrench = True`` (the old name
    of ``task_space``) as ``(q, dq, wrench, **setpoint)``.
    """

    # Typed by what every call needs, ``step(m)``: the setpoint keywords are
    # passed only with a ``reference``, and a step that takes them by name
    # (``xc=None, …``, as adaptimp's own controllers do) or as ``**setpoint``
    # fits alike; with ``**setpoint`` here, no named-keyword step would.
    def step(self, m: _adaptimp.Measurement, /) -> ArrayLike: ...


# ---------------------------------------------------------------------------
# Commanded trajectories.
# ---------------------------------------------------------------------------


# ---------------------------------------------------------------------------
# Models.
# ---------------------------------------------------------------------------


def _payload_plant(nominal: Plant, payload: float) -> Plant:
    """The plant with ``payload`` kg at its end effector's link (the nominal
    plant itself for 0)."""
    if isinstance(payload, bool) or not isinstance(payload, (int, float, np.floating, np.integer)):
        raise TypeError(f"payload must be a number (kg), got {type(payload).__name__}")
    if payload == 0:
        return nominal
    plant = Plant(
        with_payload(nominal.model, float(payload), body=nominal.last_body),
        contact=nominal.contact,
        tip=nominal.tip,
    )
    plant.notes = nominal.notes
    return plant


def _rule_setup(
    plant: Plant,
    case: str,
    params: Mapping[str, Any],
    reference: Any,
    Ts: float,
    T: float,
    home: ArrayLike | None = None,
    delay: int = 0,
    coupled: bool | None = None,
) -> tuple[Task | None, Any, dict[str, Any]]:
    """The task and the rule's keywords for a case name on ``plant`` (SPEC §18):
    the default task unless a reference or the controller's own trajectory
    (``xc_*``) is given, which is then the path."""
    own = [k for k in ("xc_offset", "xc_sin", "xc_cos", "xc_omega") if k in params]
    if home is not None and (reference is not None or own):
        raise ValueError(
            "home= sets the default task's posture: give it without a reference or xc_*"
        )
    if reference is None and not own:
        task = default_task(plant, home)
        kw = rule_keywords(plant, task, Ts=Ts, case=case, delay=delay, coupled=coupled)
        kw.pop("n")
        return task, task.reference, kw
    from . import tuning

    if reference is None:
        from ._params import defaults as scenario_defaults

        base = scenario_defaults("robot", plant.n)
        xc = {k: params.get(k, base[k]) for k in ("xc_offset", "xc_sin", "xc_cos", "xc_omega")}
        path = sinusoid(xc["xc_offset"], xc["xc_sin"], xc["xc_cos"], xc["xc_omega"])
        w = np.abs(np.broadcast_to(np.asarray(xc["xc_omega"], dtype=np.float64), (plant.n,)))
        period = 2 * math.pi / float(np.min(w[w > 0])) if np.any(w > 0) else T
    else:
        path = table_reference(reference, plant.n, Ts, round(T / Ts))
        period = T
    home = np.asarray(path(0.0)[0], dtype=np.float64)
    saved = (np.array(plant.data.qpos), np.array(plant.data.qvel))
    kw = tuning.suggest(
        plant, home, plant.tau_max, Ts=Ts, path=path, period=period, case=case, delay=delay,
        coupled=coupled,
    )  # fmt: skip
    plant.data.qpos[:], plant.data.qvel[:] = saved
    mujoco.mj_forward(plant.model, plant.data)
    kw.pop("n")
    kw["impedance"] = "external"
    return None, reference, kw


def simulate(
    controller: str | ControllerLike = "sf",
    model: Plant | ModelSource = "two_link",
    *,
    T: float | None = None,
    Ts: float | None = None,
    substeps: int | None = None,
    q0: ArrayLike | None = None,
    dq0: ArrayLike | None = None,
    reference: Reference | Any | None = None,
    contact: bool = True,
    settle: float | None = None,
    scenario: str = "robot",
    record_every: int = 1,
    progress: bool | Callable[[int, int], object] = False,
    fault: Fault | None = None,
    payload: float = 0.0,
    reset: bool = True,
    tip: str | None = None,
    fix: Sequence[str] = (),
    home: ArrayLike | None = None,
    task: CartesianTask | None = None,
    gravity: str | None = None,
    **params: Any,
) -> MujocoResult:
    """Run a controller on a MuJoCo plant: the loop of SPEC §11 with MuJoCo as the plant.

    At every t_k = k·Ts: MuJoCo computes contact and sensors at the state
    (with the torque applied over the last period), the controller is given
    ``(q, tau_e, dq[, xc=, dxc=, ddxc=])`` and returns a torque; it is
    saturated to the actuators' τmax and held for ``substeps`` MuJoCo steps of
    Ts / substeps each (SPEC §13.1).

    The loop, the recording and the metrics are the compiled core's, MuJoCo
    is driven through its C library and the GIL is released (Ctrl-C is
    honoured within 0.2 s, also within a period of many substeps). The core
    steps an ``adaptimp.Controller`` (or a case name), an
    :class:`adaptimp.CartesianController` in front of one (or of computed
    torque) and :class:`adaptimp.baselines.ComputedTorque` itself; any other
    controller (:class:`ControllerLike`) is called back once a period, with
    the GIL taken for that call (``params["loop"]`` is then ``"callback"``).

    Parameters
    ----------
    controller : str or controller
        ``"pd"``, ``"sf"`` or ``"of"`` builds ``adaptimp.Controller(case,
        scenario=scenario, Ts=Ts, tau_max=<the plant's>, **params)``; or any
        object of the :class:`ControllerLike` protocol (e.g. an
        ``adaptimp.Controller`` or :class:`adaptimp.baselines.ComputedTorque`),
        used as it is (reset it first if it has run before).
    model : Plant, MjModel, str or path
        The plant, or what :class:`Plant` takes (default the paper's arm).
    T : float, optional
        Duration (s); rows k = 0 … round(T/Ts) − 1. Default: the scenario's T.
    Ts : float, optional
        Controller period (s). Default: the controller's; for a case name the
        scenario's (``"robot"``: 1 ms, ``"paper"``: 50 µs). Must equal the
        period of a given controller.
    substeps : int, optional
        MuJoCo steps per period, 1 ≤ substeps ≤ 10 000; MuJoCo's timestep
        becomes Ts / substeps. Default: round(Ts / the model's timestep), at
        least 1.
    q0, dq0 : array_like, optional
        Initial joint positions (rad) and velocities (rad/s); default the
        default task's start (below), else the model's first keyframe (the
        paper's q(0) for ``two_link``), else the reference's start xc(0),
        ẋc(0), else qpos0.
    reference : callable or arrays, optional
        ``reference(t) -> (xc, dxc, ddxc)``, or the arrays (xc, dxc, ddxc) of
        shape (K, n) with a row per step (K ≥ round(T/Ts)), or a result that
        has them (e.g. a :class:`MujocoResult`: the same task again): passed
        to every step as ``xc=, dxc=, ddxc=``. None: the default task (below),
        or the controller's own trajectory.
    contact : bool
        False: free space (MuJoCo's contact disabled). Ignored for a Plant.
    settle : float, optional
        Start of the "after2" metrics (s), ≥ 0; default the scenario's (2 s),
        whose metrics are NaN for a shorter run. One given must leave a
        recorded step in the window (settle ≤ (round(T/Ts) − 1) Ts), as in
        :func:`adaptimp.simulate`.
    scenario : {"robot", "paper"}
        Defaults for a case name (see :func:`adaptimp.simulate`).
    record_every : int
        Keep every k-th row (k ≥ 1); the metrics still see every step.
    progress : bool or callable
        ``True``: a progress bar for runs longer than 2 s; a callable is called
        as ``progress(done, total)`` about every 50 ms, and once when the run ends.
    fault : adaptimp.Fault, optional
        A fault injected over a window, as for :func:`adaptimp.simulate` (the
        actuators' τmax for ``"actuator_drop"``), for any controller.
    payload : float
        A point mass (kg, ≥ 0) at the end effector's link of the plant only
        (:func:`with_payload`); the controller's gains come from the arm
        without it, and no model the controller is given has it.
    task : CartesianTask, optional
        A Cartesian task (:func:`cartesian_task`): a case name's controller is
        then the Cartesian controller of the core's rule for it
        (:meth:`adaptimp.CartesianController.from_rule`), started at
        ``task.q0``; the result carries the task's errors, ``res.pos_err``,
        ``res.rot_err`` (K,) (m, rad), and ``metrics["rms_pos_after2"]``,
        ``["rms_rot_after2"]`` (SPEC (16.11)).
    reset : bool
        True: the plant starts at ``q0``, ``dq0``. False: a :class:`Plant` goes
        on from where its last run left it (a long run in parts: with a used
        controller, the parts are the whole run's rows; each part's t starts
        at 0 and its disturbances afresh); ``q0``, ``dq0`` must then be None
        and ``payload`` 0.
    tip, fix : optional
        The end effector (a site or a body; a URDF's link) and joints to lock,
        for the :class:`Plant` built from ``model`` (not for a Plant given).
    home : array_like, optional
        The posture (rad, (n,)) the default task swings about, instead of
        :func:`home_posture`'s.
    gravity : {None, "model"}
        ``"model"``: a case name's controller (joint space, or the Cartesian
        one of ``task``) feeds the plant's nominal model's gravity G₀(q)
        forward, SPEC (20.10), read by the core from the plant's model (the
        arm without the run's ``payload``): for a robot that does not
        compensate gravity itself, the arm does not sag while the networks
        learn. None (default, SPEC's law): gravity is left to the networks,
        as on a robot that compensates it (Franka).
    **params
        The disturbances of SPEC §17 (:data:`DISTURBANCES`: sensor noise,
        delay, joint friction, weak actuators; the controller is told none of
        them), for any controller; and, for a case name, controller parameters
        (``Kp``, ``gamma``, …) and ``coupled``: the rule's inertia-shaped
        gains of SPEC (18.12) (default: on with a delay, ``delay`` ≥ 1, on
        the joint task and the Cartesian one; ``coupled=False``: the diagonal gains of (18.1)
        always, ``True``: the shaped ones always; see
        :func:`adaptimp.tuning.suggest`).

    Notes
    -----
    **Any arm, out of the box** (SPEC §18, ``docs/your_arm.md``). A case name
    on any model but the paper's ``two_link`` is built by the rule of
    :func:`rule_keywords` (gains from the arm's inertia, the centres and
    learning along the task's path, ``impedance="external"``): with no
    ``reference`` and no ``xc_*`` keyword the task is :func:`default_task`
    (a joint-space swing of ±0.2 rad at 0.5 Hz about :func:`home_posture`,
    from rest); a given ``reference`` is the path instead. Keywords given in
    ``params`` replace the rule's. The result's ``xc``, ``dxc``, ``ddxc``
    (K, n) are the reference tracked, so that any other controller can run
    the same task: ``simulate(ct, model, reference=res, q0=res.q[0],
    payload=...)``.

    Returns
    -------
    MujocoResult
        Arrays, the SPEC §12 metrics, ``.plot(kind)``.

    Raises
    ------
    DivergedError
        MuJoCo warned during a period (it resets a diverged state and only
        counts a warning), its time did not advance, or the state is not
        finite: the message names the row, the time and MuJoCo's warning.

    Examples
    --------
    >>> from adaptimp import mujoco as amj
    >>> res = amj.simulate("sf", "two_link", T=0.05, contact=False)
    >>> res.q.shape, res.params["substeps"]
    ((50, 2), 20)
    """
    if gravity not in (None, "model"):
        raise ConfigError(f"gravity must be None or 'model', got {gravity!r}")
    if task is not None:  # the Cartesian task's controller, by the core's rule
        if not isinstance(task, CartesianTask):
            raise TypeError(
                f"task must be a CartesianTask (from adaptimp.mujoco.cartesian_task), got "
                f"{type(task).__name__} {task!r:.60}"
            )
        if home is not None:
            raise ValueError("home= sets the default joint-space task: give q0= to cartesian_task")
        if reference is not None:
            raise ValueError(
                "give the task or a reference, not both: the arm would track the reference "
                "while the task's errors were measured against its own path"
            )
        if not isinstance(model, Plant):
            model = Plant(model, contact=contact, tip=tip, fix=fix)
            tip, fix = None, ()
        params = dict(params)
        if gravity is not None:
            params["gravity"] = gravity
        delay = loop_delay(params)
        controller, params = task.prepare(
            controller, model, Ts, {**params, "delay": delay}, DISTURBANCES
        )
        q0 = task.q0 if q0 is None else q0
    elif gravity is not None:
        if not isinstance(controller, str):
            raise TypeError(
                "gravity='model' builds a case name's controller ('pd', 'sf', 'of'); give "
                "your own controller its gravity itself (adaptimp.Controller(gravity=...))"
            )
        params = {**params, "gravity": gravity}
    run = _setup(
        controller, model, T=T, Ts=Ts, substeps=substeps, q0=q0, dq0=dq0, contact=contact,
        settle=settle, scenario=scenario, record_every=record_every, reference=reference,
        payload=payload, params=params, reset=reset, tip=tip, fix=fix, home=home,
    )  # fmt: skip
    from ._api import _progress

    callback, bar = _progress(progress, "mujoco.simulate")
    core_fault = None if fault is None else fault.core(run.plant.n)
    try:
        out = LOOPS[run.kind](run, callback, core_fault)
    finally:
        if bar is not None:
            bar.close()
    targets = out.pop("targets", None)
    res = _result(run, out, out.pop("metrics"))
    if task is not None:
        task.measure(res)
    elif targets is not None:
        # A Cartesian controller's run, whichever way it was built: its pose
        # errors against the commanded pose of every row (SPEC (16.11)).
        measure(res, run.ctrl.chain, targets)
    check_run(run, res)
    check_delay(res)
    check_tracking(run, res)
    check_refused(res, fault)
    return res


MAX_SUBSTEPS = 10_000
"""The most MuJoCo steps per control period (the core's bound)."""


def _check_arguments(T: object, Ts: object, substeps: object) -> None:
    """``T`` and ``Ts`` real numbers (s) or None, ``substeps`` an integer in
    1 … :data:`MAX_SUBSTEPS` or None: refused by name before any work."""
    for name, value in (("T", T), ("Ts", Ts)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, numbers.Real)):
            raise TypeError(f"{name} must be a real number (s), got {type(value).__name__}")
    if substeps is None:
        return
    if isinstance(substeps, bool) or not isinstance(substeps, numbers.Integral):
        raise TypeError(
            f"substeps must be an integer (MuJoCo steps per period), got {type(substeps).__name__}"
        )
    if not 1 <= int(substeps) <= MAX_SUBSTEPS:
        raise ConfigError(
            f"condition 1 ≤ substeps ≤ 10 000 is violated: substeps = {int(substeps)} "
            "(MuJoCo steps per period)"
        )


def _kind(ctrl: Any) -> str:
    """How the core's loop takes ``ctrl``: ``"native"`` (an
    ``adaptimp.Controller``), ``"cartesian"`` (an
    :class:`adaptimp.CartesianController` in front of a joint controller the
    core steps), ``"computed"`` (computed torque in joint space) or
    ``"callback"`` (written in Python: called back once a period)."""
    if native_cartesian(ctrl):
        return "cartesian"
    if task_space(ctrl):
        return "callback"
    if native(ctrl):
        return "native"
    return "computed" if native_computed(ctrl) else "callback"


def _setup(
    controller: str | ControllerLike,
    model: Plant | ModelSource,
    *,
    T: float | None = None,
    Ts: float | None = None,
    substeps: int | None = None,
    q0: ArrayLike | None = None,
    dq0: ArrayLike | None = None,
    contact: bool = True,
    settle: float | None = None,
    scenario: str = "robot",
    record_every: int = 1,
    reference: Any = None,
    payload: float = 0.0,
    params: Mapping[str, Any],
    reset: bool = True,
    tip: str | None = None,
    fix: Sequence[str] = (),
    home: ArrayLike | None = None,
) -> Run:
    """Everything :func:`simulate` does before the loop: the controller, the
    plant at its initial state, the settings and the kind of loop."""
    from ._api import Controller, _record_every
    from ._params import SCENARIOS, check_settle, resolve

    _check_arguments(T, Ts, substeps)
    defaults = SCENARIOS.get(scenario)
    if defaults is None:
        raise ValueError(f"scenario must be one of {sorted(SCENARIOS)}, got {scenario!r}")
    every = _record_every(record_every)
    if not reset and (q0 is not None or dq0 is not None or payload != 0):
        raise ValueError(
            "q0, dq0 and a payload start a run afresh: give them with reset=True (the default)"
        )
    if isinstance(model, Plant) and (tip is not None or tuple(fix)):
        raise ValueError("tip= and fix= build the Plant: give them to Plant(...), not with one")
    nominal = model if isinstance(model, Plant) else Plant(model, contact=contact, tip=tip, fix=fix)
    plant = _payload_plant(nominal, payload)
    task: Task | None = None
    params = dict(params)
    delay = loop_delay(params)
    # SPEC (18.12): a rule option of a case name, not a parameter; the rule's
    # default (None) shapes the gains for a loop with a delay.
    asked = params.pop("coupled", None)
    asked = None if asked is None else flag("coupled", asked)
    if asked is not None and not isinstance(controller, str):
        raise TypeError(
            "coupled= is an option of the rule that builds a case name's controller: "
            "build your controller with it (tuning.suggest(coupled=True))"
        )
    disturb = {k: params.pop(k) for k in DISTURBANCES if k in params}
    if home is not None and not (isinstance(controller, str) and uses_rule(nominal)):
        raise ValueError(
            "home= sets the default task of a case name on an arm (not the paper's two_link)"
        )
    if asked is not None and not uses_rule(nominal):
        raise ValueError(
            "coupled= shapes the rule's gains on an arm: the paper's two_link runs the paper's "
            "controller, not the rule's"
        )
    if isinstance(controller, str):
        kwargs = dict(params)
        if uses_rule(nominal):
            task, reference, rule = _rule_setup(
                nominal, controller, kwargs, reference, Ts or float(defaults["Ts"]),
                float(defaults["T"]) if T is None else float(T), home, delay,
                rule_coupled(asked, kwargs),
            )  # fmt: skip
            kwargs = {**rule, **kwargs}
            if q0 is None and task is not None:
                q0 = task.q0
        kwargs.setdefault("tau_max", plant.tau_max.tolist())
        kwargs["delay"] = delay
        if kwargs.get("gravity") == "model":  # (20.10): the nominal plant's, no payload
            kwargs["gravity"] = nominal
        if Ts is not None:
            kwargs["Ts"] = Ts
        if plant.n != 2:
            kwargs["n"] = plant.n
        ctrl: Any = Controller(controller, scenario=scenario, **kwargs)
        label = f"adaptimp.Controller({controller!r}, scenario={scenario!r})"
    else:
        if params:
            raise TypeError(
                f"controller parameters {sorted(params)} apply to a case name only; "
                "configure the controller object itself"
            )
        ctrl = controller
        label = type(controller).__name__
        joints = getattr(ctrl, "n", None)
        if isinstance(joints, int) and not isinstance(joints, bool) and joints != plant.n:
            # It failed later as "noise_q: wrong length", noise_q never given.
            raise ConfigError(
                f"the controller ({label}) has {joints} joints, the plant {plant.n} "
                f"({', '.join(plant.joint_names)}): build the controller for the plant's arm"
            )
    period = period_of_controller(ctrl)
    if Ts is not None and not math.isclose(Ts, period, rel_tol=1e-12):
        raise ValueError(f"Ts = {Ts:g} s differs from the controller's period {period:g} s")
    Ts = period
    T = float(defaults["T"]) if T is None else float(T)
    given_settle = settle is not None
    settle = float(defaults["settle"]) if settle is None else float(settle)
    # Checked before it is used: round(inf) overflows, round(nan) raises.
    if not (math.isfinite(T) and T > 0):
        raise ValueError(f"T must be finite and > 0, got {T}")
    if T / Ts > 1e15:
        raise ValueError("T / Ts: the run must have at most 1e15 steps")
    steps = round(T / Ts)
    if steps < 1:
        raise ValueError(f"T = {T:g} s is shorter than one period Ts = {Ts:g} s")
    # As the rigid plant's simulate (the core's condition).
    if not math.isfinite(settle):
        raise ConfigError(f"settle must be finite, got {settle!r}")
    if settle < 0:
        raise ConfigError(f"condition settle ≥ 0 is violated: settle = {settle:g} (SPEC §10)")
    if given_settle:
        check_settle(settle, T, Ts)
    if substeps is None:
        substeps = max(1, round(Ts / plant.timestep))
        if substeps > MAX_SUBSTEPS:
            raise ConfigError(
                f"condition 1 ≤ substeps ≤ 10 000 is violated: substeps = round(Ts / the "
                f"model's timestep) = {substeps}: give substeps"
            )
    resolved = resolve(disturb, scenario="robot", groups=("sim",), caller="simulate()", n=plant.n)
    dist = {k: resolved[k] for k in DISTURBANCES}
    # A Cartesian controller's reference is its commanded position p_c (3,).
    in_task = task_space(ctrl)
    if reference is not None:
        reference = table_reference(reference, 3 if in_task else plant.n, Ts, steps)
        if q0 is None and plant.model.nkey == 0 and not in_task and reset:
            start = reference(0.0)
            q0 = np.asarray(start[0], dtype=np.float64)
            dq0 = np.asarray(start[1], dtype=np.float64) if dq0 is None else dq0
    plant.timestep = Ts / int(substeps)
    if reset:
        plant.reset(q0, dq0)
    if plant.watch is not None:  # this run's contacts only
        plant.watch.clear(plant.data)
    return Run(
        ctrl, plant, label, scenario, Ts, T, settle, int(substeps), steps, every, dist,
        plant.core_spec(int(substeps)), _kind(ctrl), reference, task, float(payload), plant.q,
    )  # fmt: skip


def _controller_delay(ctrl: Any) -> int | None:
    """The loop's delay (periods) ``ctrl`` was made for, SPEC (18.11): an
    ``adaptimp.Controller``'s ``delay``, a Cartesian controller's joint
    controller's; None for a controller that does not say."""
    delay = _controller_param(ctrl, "delay", int)
    return None if delay is None else int(delay)


def _controller_param(ctrl: Any, name: str, kind: type = object) -> Any:
    """Parameter ``name`` of ``ctrl`` (an ``adaptimp.Controller``) or of a
    Cartesian controller's joint controller, the first that is a ``kind``;
    None for one that does not say."""
    for c in (ctrl, getattr(ctrl, "inner", None)):
        params = getattr(c, "params", None)
        if isinstance(params, Mapping):
            value = params.get(name)
            if value is not None and isinstance(value, kind):
                return value
    return None


def _result(run: Run, out: dict[str, Any], m: dict[str, Any]) -> MujocoResult:
    plant, ctrl = run.plant, run.ctrl
    name = plant.model.names[: plant.model.names.find(b"\0")].decode()
    params = {
        "Ts": run.Ts,
        "substeps": run.substeps,
        "timestep": plant.timestep,
        "T": run.T,
        "settle": run.settle,
        "contact": plant.contact,
        "tau_max": plant.tau_max.tolist(),
        "wrench_source": plant.wrench_source,
        "model": name,
        "joints": list(plant.joint_names),
        "controller": run.label,
        "loop": "callback" if run.kind == "callback" else "native",
        "payload": run.payload,
        "q0": run.q0.tolist(),
        **run.dist,
    }
    # SPEC (18.11): the delay the controller was made for, beside the plant's
    # (``plant_delay``); they differ only for a controller the caller made.
    params["delay"] = _controller_delay(ctrl)
    # SPEC (18.12): the inertia-shaped gains, when the controller has them.
    shaped = _controller_param(ctrl, "inertia_matrix")
    if shaped is not None:
        params["inertia_matrix"] = shaped
    if run.task is not None:
        params["task"] = {"home": run.task.home.tolist(), **run.task.keywords}
    case = getattr(ctrl, "case", None)
    case = case if isinstance(case, str) else getattr(getattr(ctrl, "inner", None), "case", None)
    return MujocoResult(
        case=case if isinstance(case, str) else "custom",
        scenario=run.scenario,
        params=params,
        metrics=m,
        record_every=run.every,
        **out,
    )


def run_many(
    jobs: Sequence[tuple[str, str, str, Mapping[str, Any]]],
    threads: int | None = None,
    progress: Callable[[int, int], object] | None = None,
) -> list[dict[str, Any] | str]:
    """Runs ``(case, scenario, model, keywords)`` of :func:`simulate`, their
    SPEC §12 metrics or their errors as text: in the core, on ``threads``
    threads (every core if None) with the GIL released, each run with its own
    controller and MuJoCo data; a run the core cannot take alone (a reference
    callable, a progress report) runs here through :func:`simulate`. Results
    are those of :func:`simulate`, bit for bit."""
    out: list[dict[str, Any] | str | None] = [None] * len(jobs)
    native: list[tuple[int, Run]] = []
    for i, (case, scenario, model, kw) in enumerate(jobs):
        kw = dict(kw)
        try:
            if kw.get("reference") is not None or kw.get("progress"):
                out[i] = dict(simulate(case, model, scenario=scenario, **kw).metrics)
                continue
            names = (
                "T", "Ts", "substeps", "q0", "dq0", "contact", "settle", "record_every", "payload",
            )  # fmt: skip
            run = _setup(
                case, model, scenario=scenario, params=kw,
                **{k: kw.pop(k) for k in names if k in kw},
            )  # fmt: skip
            assert run.kind == "native", run.kind  # a case name: an adaptimp.Controller
            native.append((i, run))
        except Exception as e:  # a run's failure, whatever it is (a model's ParseError)
            out[i] = f"{type(e).__name__}: {e}"
    if native:
        results = _adaptimp.simulate_mujoco_many(
            [
                (
                    r.ctrl,
                    r.plant.model,
                    r.plant.data,
                    r.spec,
                    r.dist,
                    r.T,
                    r.settle,
                    None
                    if r.reference is None
                    else tabulate(r.reference, r.steps, r.Ts, r.plant.n),
                )
                for _, r in native
            ],
            threads,
            progress,
        )
        for (i, _), result in zip(native, results):
            out[i] = result
    return [r if r is not None else "no result" for r in out]
