"""A Franka (FR3 or Panda) through libfranka: adaptive impedance in the robot's 1 kHz torque loop.

Needs the extra ``franka``: ``pylibfranka`` (Franka's own Python binding of
libfranka) and MuJoCo (the rule reads the arm from its URDF through
:mod:`adaptimp.mujoco`). The same script drives a simulator on loopback and
the robot (its IP address in place of ``127.0.0.1``)::

    from adaptimp import franka

    res = franka.run("sf", "fr3.urdf", "127.0.0.1", T=10.0)
    res.metrics["rms_z1_after2"]  # rad
    res.plot("tracking").savefig("sf.png")
    res.save("sf.npz")

- :func:`run`: the torque loop through libfranka (``start_torque_control``,
  ``readOnce``/``writeOnce``), the controller built by the rule from the
  URDF the user gives; returns a :class:`adaptimp.mujoco.MujocoResult` with
  ``simulate``'s metrics, plots and save.
- :func:`setup`: the controller and its task that :func:`run` builds for an
  arm standing at q, without a robot: the same rule calls as
  :func:`adaptimp.mujoco.simulate` (:func:`adaptimp.mujoco.rule_keywords`,
  :func:`adaptimp.mujoco.cartesian_task`).
- :func:`plant`: the arm as the controller acts on it on a Franka: the
  URDF's arm without gravity (the robot adds its own model's gravity torque
  to every command).
- :func:`move_to`: the robot's own joint position controller to a posture
  (libfranka's joint position interface), before a run.
- :class:`Simulator`: franky-sim's MuJoCo FR3, a server of libfranka's
  protocol, in a process of its own on a loopback address (with a load on
  the hand the controller is not told of).

Who does what. The robot adds gravity compensation g(q) of its own model
(with the end effector and the load it was told of) to every torque it is
sent, so the controller never commands gravity: the networks learn what is
left, the inertia and Coriolis terms along the task, the joints' friction,
the robot's model error and a load nobody told the robot of. The rule is
therefore given the arm without gravity (:func:`plant`): its tube is not
widened by a sag the arm does not have. The controller limits its torque to
the Franka's (87 N m on joints 1–4, 12 N m on 5–7) and its rate to libfranka's
``kMaxTorqueRate`` (1000 N m/s, 1 N m a 1 ms cycle), in the core, as
libfranka's ``limitRate`` does (SPEC (22.3): §14's ``tau_rate_max``; the limited
torque is the one the auxiliary system and the learning see). Units: rad,
rad/s, N m, N, m, s.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from ._errors import ConfigError, needs_extra

try:
    import pylibfranka
except ImportError as e:  # pragma: no cover - depends on the environment
    raise needs_extra("adaptimp.franka", "pylibfranka>=0.21", "franka") from e

from . import mujoco as amj

# Names importable from this module before it was split, kept so.
from ._adaptimp import Measurement as Measurement
from ._cartesian_task import CartesianTask as CartesianTask
from ._cartesian_task import chain_of as chain_of
from ._errors import AdaptimpError as AdaptimpError
from ._franka_loop import (
    BLEND,
    BLEND_SPEED,
    COLLISION,
    DELAY,
    LIBFRANKA_ERRORS,
    PERIOD,
    SETTLE,
    SETTLE_WAIT,
    SETTLED,
    TORQUE_RATE,
    Loop,
    RobotError,
    Setup,
    error_names,
    posture_of,
    robot_of,
    tau_limits,
)
from ._franka_loop import READY as READY
from ._franka_loop import TAU_MAX as TAU_MAX
from ._franka_loop import FloatArray as FloatArray
from ._franka_sim import SERVER as SERVER
from ._franka_sim import Simulator as Simulator
from ._tasks import rule_coupled
from .chain import Chain as Chain

__all__ = [
    "BLEND",
    "COLLISION",
    "DELAY",
    "PERIOD",
    "READY",
    "TAU_MAX",
    "TORQUE_RATE",
    "RobotError",
    "Setup",
    "Simulator",
    "move_to",
    "plant",
    "run",
    "setup",
]


def plant(urdf: str | os.PathLike[str], *, tip: str | None = None) -> amj.Plant:
    """The arm of ``urdf`` as the controller acts on it on a Franka: an
    :class:`adaptimp.mujoco.Plant` without gravity (the robot adds its own
    model's gravity torque to every command) and without contact; ``tip`` its
    end effector (a link; default the plant's)."""
    p = amj.Plant(urdf, contact=False, tip=tip)
    if p.n != 7:
        raise ConfigError(
            f"a Franka arm has 7 joints; the arm of {os.fspath(urdf)!r} has {p.n} "
            f"({p.joint_names}): give the FR3's or the Panda's URDF"
        )
    p.model.opt.gravity[:] = 0.0
    p.reset()
    return p


def setup(
    controller: str,
    urdf: str | os.PathLike[str] | amj.Plant,
    q: ArrayLike,
    *,
    task: str = "joint",
    home: ArrayLike | None = None,
    blend: float = BLEND,
    tip: str | None = None,
    coupled: bool | None = None,
    **params: Any,
) -> Setup:
    """The controller and task :func:`run` drives for an arm standing at ``q``
    (rad, (7,)), by the rule that :func:`adaptimp.mujoco.simulate` uses for a
    case name, on the arm as the controller acts on it (:func:`plant`).

    - ``task="joint"``: the default task (SPEC §18) about ``home`` (default
      ``q``): :func:`adaptimp.mujoco.default_task`, the controller of
      :func:`adaptimp.mujoco.rule_keywords` (``impedance="external"``), its
      reference blended in from ``q`` over max(``blend``, 1.875 max|Δ|/
      :data:`BLEND_SPEED`) s (Δ from ``q`` to the path's start).
    - ``task="cartesian"``: the Cartesian default task from ``q``
      (:func:`adaptimp.mujoco.cartesian_task`: hold the pose 1 s, then a
      3 cm circle at 0.5 Hz, the orientation held), its controller by
      :meth:`adaptimp.CartesianController.from_rule`. ``q`` must meet the
      posture rule (SPEC (16.9)), else the ``ConfigError`` names the
      condition (move the arm first: :func:`move_to`).

    The rule sizes the controller for libfranka's one period of delay
    (``delay`` = :data:`DELAY`, SPEC (18.11)); it gets the Franka's torque
    limits (:data:`TAU_MAX`, at most the URDF's effort) and libfranka's
    torque rate (``tau_rate_max`` = :data:`TORQUE_RATE` × 1 ms); ``params``
    replace the rule's keywords. ``coupled``: the rule's inertia-shaped gains,
    SPEC (18.12) (the default of both tasks, for libfranka's delay of one
    period; False: the diagonal gains of (18.1); see
    :func:`adaptimp.tuning.suggest`). ``gravity=`` is refused: the robot
    compensates gravity itself (SPEC (20.10)).
    """
    if controller not in ("pd", "sf", "of"):
        raise ConfigError(f"controller must be 'pd', 'sf' or 'of', got {controller!r}")
    _no_gravity(params)
    if task not in ("joint", "cartesian"):
        raise ConfigError(f"task must be 'joint' or 'cartesian', got {task!r}")
    if isinstance(urdf, amj.Plant):
        if tip is not None:
            raise ValueError("tip= builds the plant: give it to franka.plant(...), not with one")
        arm = urdf
    else:
        arm = plant(urdf, tip=tip)
    q = posture_of("q", q)
    keywords = {"tau_max": tau_limits(arm), "tau_rate_max": TORQUE_RATE * PERIOD, **params}
    if task == "cartesian":
        if home is not None:
            raise ValueError("home= sets the joint task's posture; the Cartesian task starts at q")
        try:
            ctask = amj.cartesian_task(arm, q0=q, Ts=PERIOD)
        except ConfigError as e:
            raise ConfigError(
                f"the arm stands at q = {np.round(q, 4).tolist()} rad, where {e}: move it "
                "first (run(..., start=franka.READY), or franka.move_to)"
            ) from e
        ctrl = ctask.controller(
            controller, arm, Ts=PERIOD, delay=DELAY, coupled=coupled, **keywords
        )
        return Setup(ctrl, "cartesian", arm, q, ctask, 0.0)
    h = q if home is None else posture_of("home", home)
    jtask = amj.default_task(arm, h)
    shaped = rule_coupled(coupled, params)
    kw = amj.rule_keywords(arm, jtask, Ts=PERIOD, case=controller, delay=DELAY, coupled=shaped)
    kw.pop("n")
    kw.update(keywords)
    ctrl = _adaptimp_controller(controller, kw)
    far = float(np.max(np.abs(jtask.q0 - q)))
    return Setup(ctrl, "joint", arm, q, jtask, max(float(blend), 1.875 * far / BLEND_SPEED))


def _no_gravity(params: dict[str, Any]) -> None:
    """``gravity=`` refused (the Cartesian task took ``gravity="model"``
    without a word): the robot compensates gravity itself."""
    if params.get("gravity") is not None:
        raise ConfigError(
            f"gravity={params['gravity']!r}: the Franka adds its own model's gravity torque to "
            "every command (libfranka), so the controller never commands gravity; fed forward "
            "again it would count twice: keep the default (docs/franka.md, SPEC (20.10))"
        )


def _adaptimp_controller(case: str, kw: dict[str, Any]) -> Any:
    from ._api import Controller

    return Controller(case, scenario="robot", n=7, **kw)


def move_to(
    robot: Any,
    q: ArrayLike,
    *,
    speed: float = 0.3,
    realtime: bool | None = None,
) -> None:
    """Move the arm to ``q`` (rad, (7,)) with the robot's own joint position
    controller (libfranka's joint position interface, joint impedance mode)
    along a quintic from rest to rest, no joint faster than ``speed`` (rad/s),
    then waits (at most :data:`SETTLE_WAIT` s) until no joint moves faster
    than :data:`SETTLED` (the robot's controller lags its command): a run
    started next starts at rest. ``robot`` a ``pylibfranka.Robot`` or its
    address. A libfranka exception is a :class:`RobotError` naming it."""
    r, _ = robot_of(robot, realtime)
    goal = posture_of("q", q)
    if not (math.isfinite(speed) and speed > 0):
        raise ConfigError(f"speed must be a finite number > 0 (rad/s), got {speed!r}")
    start = np.asarray(r.read_once().q, dtype=np.float64)
    far = float(np.max(np.abs(goal - start)))
    duration = max(0.5, 1.875 * far / speed)
    try:
        ctl = r.start_joint_position_control(pylibfranka.ControllerMode.JointImpedance)
        ms = 0
        while True:
            _, dt = ctl.readOnce()
            ms += round(dt.to_sec() / PERIOD)
            x = min(ms * PERIOD / duration, 1.0)
            s = x**3 * (10.0 + x * (-15.0 + 6.0 * x))
            command = pylibfranka.JointPositions((start + s * (goal - start)).tolist())
            if x >= 1.0:
                command.motion_finished = True
                ctl.writeOnce(command)
                break
            ctl.writeOnce(command)
        deadline = time.monotonic() + SETTLE_WAIT
        while time.monotonic() < deadline:
            if np.max(np.abs(r.read_once().dq)) < SETTLED:
                return
    except LIBFRANKA_ERRORS as e:
        raise RobotError(
            f"the move to {np.round(goal, 4).tolist()} stopped: libfranka raised "
            f"{type(e).__name__}: {e}",
            cause=e,
        ) from e


def run(
    controller: str,
    urdf: str | os.PathLike[str] | amj.Plant,
    robot: Any = "127.0.0.1",
    *,
    T: float = 10.0,
    task: str = "joint",
    start: ArrayLike | None = None,
    home: ArrayLike | None = None,
    blend: float = BLEND,
    settle: float = SETTLE,
    collision: Sequence[Sequence[float]] | None = COLLISION,
    realtime: bool | None = None,
    recover: bool = False,
    wrench: bool = True,
    tip: str | None = None,
    on_cycle: Callable[[int, float, Any], object] | None = None,
    **params: Any,
) -> amj.MujocoResult:
    """Run a case name's adaptive impedance on a Franka for ``T`` seconds
    through libfranka's torque interface; returns the run as a
    :class:`adaptimp.mujoco.MujocoResult` (``simulate``'s metrics, plots and
    ``save``).

    The start (SPEC (22.4)): the controller takes over the torque the robot
    holds the arm with (``tau_J_d`` just before the loop, N m, gravity
    aside; ``res.params["taken_over"]``), so the first command is within
    1 N m of it, and the task starts where the arm stands at the first
    cycle. Every cycle: ``readOnce()`` gives the state and the time since the last
    one (1 ms; more after a missed cycle); the controller's clock advances by
    it, so each step is given the setpoint at the time its state was
    measured (a missed cycle skips the rows it missed); the step's torque
    goes out by ``writeOnce``. After ``T`` the last torque goes out again
    with ``motion_finished`` (no step in torque), and the robot holds the
    arm with its own controller.

    Parameters
    ----------
    controller : {"pd", "sf", "of"}
        The case: its controller by the rule (:func:`setup`).
    urdf : str, path or Plant
        The arm's URDF (the FR3's or the Panda's, with the hand the robot is
        told of), or :func:`plant` of it.
    robot : str or pylibfranka.Robot
        The robot's (or the simulator's) address, or a connected robot.
    T : float
        Duration (s).
    task : {"joint", "cartesian"}
        The joint-space default task about where the arm stands (or ``home``),
        or the Cartesian default task from there (:func:`setup`).
    start : array_like, optional
        First move the arm there (rad) with the robot's own controller
        (:func:`move_to`), then run from there.
    home : array_like, optional
        The joint task's posture (rad); default where the arm stands.
    blend : float
        The shortest blend of the joint task's reference (s).
    settle : float
        The start of the metrics' "after2" window (s).
    collision : 4 sequences, or None
        ``set_collision_behavior``'s thresholds (:data:`COLLISION`); None
        leaves the robot's.
    realtime : bool, optional
        libfranka's ``RealtimeConfig``: True ``kEnforce``, False ``kIgnore``;
        None (default): ``kEnforce`` on a real-time kernel, else ``kIgnore``
        (``res.params["realtime"]`` says which).
    recover : bool
        If the robot reports errors before the start, or the motion ends by a
        libfranka exception, call ``automatic_error_recovery()`` (only then;
        never without this).
    wrench : bool
        Give the controller the robot's estimate of the external wrench,
        ``O_F_ext_hat_K`` (N, N m, base frame, what the robot exerts on its
        environment, moved to the chain's tip): the Cartesian controller's
        F_e, τe = Jᵀ F_e for the joint controller.
    tip : str, optional
        The chain's tip (a link of the URDF).
    on_cycle : callable, optional
        ``on_cycle(k, t, state)`` after each cycle's torque went out (row k,
        time t (s), the libfranka state): a true return ends the motion
        cleanly before T.
    **params
        Replace the rule's keywords (``Kp``, ``gamma``, …).

    Returns
    -------
    MujocoResult
        One row per cycle: t the measurement's time (a missed cycle leaves a
        gap), q, q̇ (the robot's), q̈ (their differences), xc, ẋc, ẍc, xd, z1
        (3 wide for the Cartesian task: p_c, p_d − p), τ (commanded), sat(τ)
        (sent: limited in rate and size), τe, x_ee (``O_T_EE``'s position),
        wrench_ee (``O_F_ext_hat_K``); ``params["loop"] = "libfranka"``,
        ``params["cycles"]`` (the cycles, those longer than 1 ms, the longest
        (s)), ``params["callback"]`` (the time from the state in to the
        torque out: p50, p99, max (s)), ``params["realtime"]``.

    Raises
    ------
    RobotError
        The motion ended before T (libfranka raised, the controller refused
        a step): the message names the cause; ``partial`` holds the rows
        recorded until then.
    KeyboardInterrupt
        Ctrl-C: the motion was ended (``motion_finished``) first; ``partial``
        holds the rows recorded until then.
    """
    if not (isinstance(T, (int, float)) and math.isfinite(T) and T >= PERIOD):
        raise ConfigError(f"T must be a finite number ≥ 1 ms (s), got {T!r}")
    _no_gravity(params)  # before the robot is touched
    r, enforced = robot_of(robot, realtime)
    first = r.read_once()
    errors = error_names(first.current_errors)
    if errors:
        if not recover:
            raise RobotError(
                f"the robot reports errors {errors} before the start: clear them "
                "(run(..., recover=True) calls automatic_error_recovery())",
                errors=errors,
            )
        r.automatic_error_recovery()
    if collision is not None:
        r.set_collision_behavior(*(list(map(float, c)) for c in collision))
    if start is not None:
        move_to(r, start)
    q = np.asarray(r.read_once().q, dtype=np.float64)
    s = setup(controller, urdf, q, task=task, home=home, blend=blend, tip=tip, **params)
    loop = Loop(s, T, settle, wrench)
    loop.params["realtime"] = enforced
    try:
        loop.drive(r, on_cycle)
    except KeyboardInterrupt as e:
        e.partial = loop.result()  # type: ignore[attr-defined]
        e.args = (f"Ctrl-C at t = {loop.t:.3f} s: the motion was ended (motion_finished)",)
        raise
    except RobotError as e:
        e.partial = loop.result()
        if recover and isinstance(e.cause, LIBFRANKA_ERRORS):
            r.automatic_error_recovery()
        raise
    res = loop.result()
    if res is None:  # pragma: no cover - T ≥ 1 ms gives a first row
        raise RobotError("the motion ended before its first cycle")
    return res
