"""The torque loop of :func:`adaptimp.franka.run` through libfranka (SPEC §22):
the Franka's limits and the run's timing (:data:`PERIOD`, :data:`TAU_MAX`,
...), the robot's errors by name (:class:`RobotError`), and the loop itself
(:class:`Loop`: each 1 ms cycle's measurement, the controller's step, the
rate limit, the rows it records).

Re-exported by :mod:`adaptimp.franka`. Units: rad, rad/s, N m, s."""

from __future__ import annotations

import gc
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._errors import AdaptimpError, ConfigError, needs_extra

try:
    import pylibfranka
except ImportError as e:  # pragma: no cover - depends on the environment
    raise needs_extra("adaptimp.franka", "pylibfranka>=0.21", "franka") from e

from . import _adaptimp
from . import mujoco as amj
from ._adaptimp import Measurement
from ._cartesian_task import CartesianTask, CirclePath, chain_of
from ._description import model_name
from .chain import Chain

FloatArray = NDArray[np.float64]

PERIOD = 1e-3
"""libfranka's control period (s): a state in and a torque out every 1 ms."""

DELAY = 1
"""Periods from the state a torque was computed from to the tick it acts at:
libfranka applies a torque at the next 1 ms tick (the controller's ``delay``,
SPEC (17.1), (18.11))."""

TAU_MAX = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)
"""The FR3's and the Panda's joint torque limits (N m)."""

TORQUE_RATE = 1000.0
"""libfranka's ``kMaxTorqueRate`` (N m/s per joint): the commanded torque moves
at most this × 1 ms from one command to the next."""

READY = (0.0, -math.pi / 4, 0.0, -3 * math.pi / 4, 0.0, math.pi / 2, math.pi / 4)
"""The posture libfranka's examples move the arm to first (rad)."""

COLLISION = (
    (20.0, 20.0, 18.0, 18.0, 16.0, 14.0, 12.0),
    (20.0, 20.0, 18.0, 18.0, 16.0, 14.0, 12.0),
    (20.0, 20.0, 20.0, 25.0, 25.0, 25.0),
    (20.0, 20.0, 20.0, 25.0, 25.0, 25.0),
)
"""The collision thresholds :func:`run` sets (``set_collision_behavior``):
lower and upper external joint torques (N m, 7 each), lower and upper
external wrench (N, N m, 6 each), pylibfranka's examples' values. Beyond an
upper threshold the robot stops the motion by a reflex."""

BLEND = 1.0
"""The shortest time (s) over which the joint task's reference is blended in
from the posture the robot stands in."""

BLEND_SPEED = 0.5
"""The blend is long enough that it alone moves no joint faster than this (rad/s)."""

SETTLE = 2.0
"""The start (s) of the metrics' "after2" window, as :func:`adaptimp.mujoco.simulate`'s."""

SETTLED = 0.01
"""After :func:`move_to`, the arm is at rest when no joint moves faster (rad/s)."""

SETTLE_WAIT = 2.0
"""How long (s) :func:`move_to` waits at most for the arm to come to rest."""


class RobotError(AdaptimpError, RuntimeError):
    """The motion ended before its time: libfranka raised (a reflex, the
    network), the controller refused a step, or the robot reported errors
    before the start. The message names the cause, when it happened and how
    the motion ended; ``cause`` is the exception, ``errors`` the robot's
    error names (``current_errors``/``last_motion_errors``), ``partial`` the
    result of the rows recorded until then (None before the first)."""

    def __init__(
        self,
        message: str,
        *,
        cause: BaseException | None = None,
        errors: Sequence[str] = (),
        partial: amj.MujocoResult | None = None,
    ) -> None:
        super().__init__(message)
        self.cause = cause
        self.errors = list(errors)
        self.partial = partial


def tau_limits(p: amj.Plant) -> list[float]:
    """The torque limits: the URDF's effort, at most the Franka's (N m)."""
    limits: list[float] = np.minimum(p.tau_max, TAU_MAX).tolist()
    return limits


def posture_of(name: str, q: ArrayLike) -> FloatArray:
    v = np.asarray(q, dtype=np.float64)
    if v.shape != (7,) or not np.all(np.isfinite(v)):
        raise ConfigError(f"{name} must be 7 finite joint positions (rad), got {q!r}")
    return v


@dataclass(frozen=True)
class Setup:
    """The controller :func:`run` drives and its task, for an arm standing at ``q``.

    Attributes
    ----------
    controller : adaptimp.Controller or adaptimp.CartesianController
        The rule's controller of the case name, at Ts = 1 ms, made for
        libfranka's one period of delay (:data:`DELAY`), with the Franka's
        torque limits and libfranka's torque rate.
    kind : {"joint", "cartesian"}
        The task's space.
    plant : adaptimp.mujoco.Plant
        The arm the rule read (:func:`plant`: no gravity).
    q : ndarray, (7,)
        The posture the arm stands in (rad).
    task : adaptimp.mujoco.Task or adaptimp.mujoco.CartesianTask
        The joint-space default task about ``home`` (SPEC §18), or the
        Cartesian default task from ``q`` (SPEC (16.8)).
    blend : float
        The joint task's reference is blended in from the standing posture
        over this time (s) (0 for the Cartesian task, whose path starts at
        the standing pose at rest).
    """

    controller: Any
    kind: str
    plant: amj.Plant
    q: FloatArray
    task: Any
    blend: float

    def reference(self, steps: int, q: ArrayLike | None = None) -> tuple[FloatArray, ...]:
        """The setpoint of rows k = 0 … ``steps`` − 1 at t_k = k·1 ms: for the
        joint task (xc, ẋc, ẍc), (steps, 7) each, the task's path blended in
        from ``q`` (default the setup's posture) by the quintic
        s(t/blend) = 10 x³ − 15 x⁴ + 6 x⁵: xc = q + s (path − q) (at rest at
        t = 0, the path from t = blend on); for the Cartesian task the pose
        targets (steps, 24) (:func:`adaptimp.cartesian.pose_target`)."""
        t = np.arange(steps, dtype=np.float64) * PERIOD
        if self.kind == "cartesian":
            return (np.ascontiguousarray(self.task.targets(steps, PERIOD)),)
        xc, dxc, ddxc = (np.asarray(a, dtype=np.float64) for a in self.task.reference(t[:, None]))
        q0 = self.q if q is None else posture_of("q", q)
        return _blend(t, (xc, dxc, ddxc), q0, self.blend)

    def __repr__(self) -> str:
        what = "joint-space swing" if self.kind == "joint" else "Cartesian circle"
        return (
            f"adaptimp.franka.Setup({what} from q = {np.round(self.q, 4).tolist()}, "
            f"{self.controller!r})"
        )


def _blend(
    t: FloatArray, path: tuple[FloatArray, FloatArray, FloatArray], q: FloatArray, blend: float
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``path`` (xc, ẋc, ẍc) at ``t`` blended in from rest at ``q``: r = q + s (p − q),
    ṙ = ṡ (p − q) + s ṗ, r̈ = s̈ (p − q) + 2 ṡ ṗ + s p̈, s the quintic of t/blend."""
    p, dp, ddp = (np.ascontiguousarray(a, dtype=np.float64) for a in path)
    if blend <= 0:
        return p, dp, ddp
    x = np.clip(t / blend, 0.0, 1.0)[:, None]
    s = x**3 * (10.0 + x * (-15.0 + 6.0 * x))
    ds = 30.0 * x**2 * (1.0 - x) ** 2 / blend
    dds = 60.0 * x * (1.0 - x) * (1.0 - 2.0 * x) / blend**2
    e = p - q
    return q + s * e, ds * e + s * dp, dds * e + 2.0 * ds * dp + s * ddp


# ---------------------------------------------------------------------------
# The loop.
# ---------------------------------------------------------------------------


def robot_of(robot: Any, realtime: bool | None) -> tuple[Any, bool]:
    """A ``pylibfranka.Robot`` connected to ``robot`` (an address), or ``robot``
    itself; and whether libfranka enforces real-time scheduling."""
    if not isinstance(robot, str):
        return robot, bool(realtime)
    if realtime is None:
        realtime = _realtime_kernel()
    config = pylibfranka.RealtimeConfig.kEnforce if realtime else pylibfranka.RealtimeConfig.kIgnore
    return pylibfranka.Robot(robot, config), realtime


def _realtime_kernel() -> bool:
    """Whether the running kernel is a real-time one (libfranka's own test:
    ``/sys/kernel/realtime`` reads 1)."""
    try:
        return Path("/sys/kernel/realtime").read_text().strip() == "1"
    except OSError:
        return False


def error_names(errors: Any) -> list[str]:
    """The names of the errors a ``pylibfranka.Errors`` holds (``str`` of it
    is the list ``[name, …]``)."""
    text = str(errors).strip()
    if not text or text == "[]":
        return []
    return [e.strip().strip("\"'") for e in text.strip("[]").split(",") if e.strip()]


LIBFRANKA_ERRORS = (
    pylibfranka.FrankaException,
    pylibfranka.ControlException,
    pylibfranka.NetworkException,
    pylibfranka.CommandException,
    pylibfranka.RealtimeException,
    pylibfranka.InvalidOperationException,
)
"""The exceptions libfranka raises (through pylibfranka)."""


class _Stop(Exception):
    """A hook's request to end the motion cleanly."""


class Loop:
    """One run's state: the controller, its setpoint tables and the rows."""

    def __init__(self, s: Setup, T: float, settle: float, wrench: bool) -> None:
        self.s, self.T, self.settle, self.wrench = s, float(T), float(settle), wrench
        self.steps = round(self.T / PERIOD)
        self.ctrl = s.controller
        self.cartesian = s.kind == "cartesian"
        self.chain: Chain = s.controller.chain if self.cartesian else chain_of(s.plant)
        self.source = s.controller.inner if self.cartesian else s.controller
        self.tables = s.reference(self.steps)
        if not self.cartesian:
            # The path itself, for the blend from where the arm stands at the first cycle.
            t = np.arange(self.steps, dtype=np.float64)[:, None] * PERIOD
            self.path = tuple(np.asarray(a, dtype=np.float64) for a in s.task.reference(t))
        self.t = 0.0
        self.cycle = 0
        # Every row's quantities, written in place (no object per row for the
        # garbage collector to walk mid-run).
        self.rows = {name: np.zeros((self.steps, w)) for name, w in _ROWS.items()}
        self.k = np.zeros(self.steps, dtype=np.int64)
        self.ns = np.zeros(self.steps, dtype=np.int64)
        self.times = np.zeros(self.steps)
        self.K = 0
        self.last_sent: list[float] | None = None
        self.no_wrench = np.zeros(6)
        self.params: dict[str, Any] = {}

    def blend_from(self, q: Sequence[float]) -> None:
        """The blended rows of the joint task's setpoint, from ``q`` (rad)."""
        rows = min(self.steps, math.ceil(self.s.blend / PERIOD) + 1)
        t = np.arange(rows, dtype=np.float64) * PERIOD
        path = (self.path[0][:rows], self.path[1][:rows], self.path[2][:rows])
        # The set-up as run: from the first cycle's posture.
        self.s = replace(self.s, q=np.array(q, dtype=np.float64))
        blended = _blend(t, path, self.s.q, self.s.blend)
        for table, rows_ in zip(self.tables, blended):
            table[: len(rows_)] = rows_

    def take_over(self, state: Any) -> tuple[FloatArray, ...]:
        """Just before the torque loop starts, from the robot's ``state`` then
        (SPEC (22.4)), every check before anything moves: the controller takes
        over the torque the robot holds the arm with (``tau_J_d``, gravity
        aside; with a load its model lacks, the load's weight too: the set-up
        read the posture earlier, and the arm sags under the robot's own
        controller in between), so the first command continues it; the
        Cartesian task starts from the pose the arm stands in
        (:meth:`CartesianTask.moved_to`, the outer loop restarted there, its
        null-space posture too if it was the set-up's). Returns the rows."""
        held = [float(x) for x in state.tau_J_d]
        try:
            self.ctrl.take_over(held)
        except ConfigError as e:
            raise ConfigError(
                f"the torque the robot holds the arm with, {np.round(held, 3).tolist()} N m, "
                f"cannot be taken over: {e}"
            ) from e
        self.params["taken_over"] = held
        task = self.s.task
        if self.cartesian and isinstance(task, CartesianTask) and isinstance(task.path, CirclePath):
            outer = self.ctrl.outer
            default = np.array_equal(outer.core.state("posture"), self.s.q)
            moved = task.moved_to(state.q)
            # The set-up as run: the task moved to where the arm stands.
            self.s = replace(self.s, q=moved.q0, task=moved)
            outer.reset(moved.q0)
            if default:
                outer.set_posture(moved.q0)
            self.tables = self.s.reference(self.steps)
        return self.tables

    def measurement(self, state: Any) -> Any:
        """The step's measurement from the state: q, q̇ and the wrench (moved
        from the stiffness frame K to the chain's tip), or τe = Jᵀ F_e."""
        q, dq = state.q, state.dq
        f = state.O_F_ext_hat_K if self.wrench else None
        if f is None or not any(f):
            return Measurement(q, dq), None
        f = np.asarray(f, dtype=np.float64)
        tip = self.chain.fk(q)[:3, 3]
        k = np.asarray(state.O_T_EE, dtype=np.float64).reshape(4, 4, order="F")
        ek = np.asarray(state.EE_T_K, dtype=np.float64).reshape(4, 4, order="F")
        p_k = (k @ ek)[:3, 3]
        f_tip = np.concatenate([f[:3], f[3:] + np.cross(p_k - tip, f[:3])])
        if self.cartesian:
            return Measurement(q, dq, wrench=f_tip), f_tip
        tau_e = self.chain.jacobian(q).T @ f_tip
        return Measurement(q, dq, tau_e=tau_e), tau_e

    def drive(self, r: Any, on_cycle: Callable[[int, float, Any], object] | None) -> None:
        """The torque loop until T, Ctrl-C, a refused step or a libfranka exception."""
        ctrl, steps = self.ctrl, self.steps
        core = ctrl.outer.core if self.cartesian else None
        joint = ctrl.core_joint if self.cartesian else None
        record = ctrl.record if self.cartesian else False
        last = -1  # the row of the last step
        Torques = pylibfranka.Torques
        clock = time.perf_counter_ns
        tables = self.take_over(r.read_once())
        ctl = r.start_torque_control()
        collecting = gc.isenabled()
        gc.disable()  # no collection pause inside a 1 ms cycle
        read = True  # whether the next call libfranka expects is readOnce
        try:
            while True:
                state, period = ctl.readOnce()
                t_in = clock()
                read = False
                # The clock in whole cycles: libfranka's durations are whole milliseconds.
                k = self.cycle = self.cycle + round(period.to_sec() / PERIOD)
                self.t = k * PERIOD
                if k >= steps:
                    self.finish(ctl)
                    return
                if not self.K and not self.cartesian:
                    self.blend_from(state.q)
                m, tau_e = self.measurement(state)
                try:
                    if core is not None:
                        # A late cycle: the outer loop's joint reference is
                        # integrated over the cycles missed too (its clock
                        # advances by the duration), kinematically.
                        for j in range(last + 1, k):
                            core.reference(tables[0][j], self.no_wrench if tau_e is None else tau_e)
                        last = k
                        tau = core.step_sample(joint, m, None, None, tables[0][k], record)
                    else:
                        tau = ctrl.step(m, tables[0][k], tables[1][k], tables[2][k])
                except (ValueError, ArithmeticError, RuntimeError) as e:
                    self.finish(ctl)
                    read = True
                    raise RobotError(
                        f"the controller refused the step at t = {self.t:.3f} s (row {k}): "
                        f"{type(e).__name__}: {e}; the motion was ended (motion_finished, the "
                        "last torque held)",
                        cause=e,
                    ) from e
                sent = tau.tolist()
                ctl.writeOnce(Torques(sent))
                t_out = clock()
                read = True
                self.last_sent = sent
                self.keep(k, state, m, tau, tau_e, t_out - t_in)
                if on_cycle is not None and on_cycle(k, self.t, state):
                    raise _Stop
        except _Stop:
            ctl.readOnce()
            self.finish(ctl)
        except KeyboardInterrupt:
            if read:
                ctl.readOnce()
            self.finish(ctl)
            raise
        except RobotError:
            raise
        except LIBFRANKA_ERRORS as e:
            errors = self.robot_errors(r)
            raise RobotError(
                f"libfranka raised {type(e).__name__} at t = {self.t:.3f} s: {e}"
                + (f"; the robot's errors: {errors}" if errors else "")
                + "; the robot ended the motion",
                cause=e,
                errors=errors,
            ) from e
        except Exception as e:
            # Anything else (the hook's own error): the motion ended, then named.
            if read:
                ctl.readOnce()
            self.finish(ctl)
            raise RobotError(
                f"{type(e).__name__} at t = {self.t:.3f} s: {e}; the motion was ended "
                "(motion_finished, the last torque held)",
                cause=e,
            ) from e
        finally:
            if collecting:
                gc.enable()

    def finish(self, ctl: Any) -> None:
        """End the motion: the last torque sent, again, with ``motion_finished``."""
        # Nothing sent yet: the torque taken over (no step from what held the arm).
        last = self.last_sent if self.last_sent is not None else self.params["taken_over"]
        command = pylibfranka.Torques(last)
        command.motion_finished = True
        ctl.writeOnce(command)

    @staticmethod
    def robot_errors(r: Any) -> list[str]:
        try:
            state = r.read_once()
        except LIBFRANKA_ERRORS:
            return []
        return error_names(state.last_motion_errors) or error_names(state.current_errors)

    def keep(self, k: int, state: Any, m: Any, tau: Any, tau_e: Any, ns: int) -> None:
        """The row of this cycle (the controller's quantities read after its step)."""
        rows, ctrl, i = self.rows, self.ctrl, self.K
        self.k[i], self.times[i], self.ns[i] = k, self.t, ns
        rows["q"][i] = state.q
        rows["dq"][i] = state.dq
        rows["tau_sat"][i] = tau
        if tau_e is not None and not self.cartesian:
            rows["tau_e"][i] = tau_e
        rows["ee"][i] = state.O_T_EE
        rows["f"][i] = state.O_F_ext_hat_K
        source = self.source
        rows["tau"][i] = source.tau
        rows["zeta"][i] = source.zeta
        rows["dq_hat"][i] = source.dq_hat
        if not self.cartesian:
            rows["xd"][i] = ctrl.xd
            rows["z1"][i] = ctrl.z1
        self.K = i + 1

    def result(self) -> amj.MujocoResult | None:
        """The rows kept as a result with simulate's metrics (None without rows)."""
        K = self.K
        if K == 0:
            return None
        n = 7
        rows = {name: a[:K].copy() for name, a in self.rows.items()}
        idx = self.k[:K]
        t = self.times[:K].copy()
        q, dq = rows["q"], rows["dq"]
        ddq = np.gradient(dq, t, axis=0) if K > 1 else np.zeros_like(dq)
        tau_sat, tau_e = rows["tau_sat"], rows["tau_e"]
        x_ee = np.ascontiguousarray(rows["ee"][:, 12:15])
        wrench_ee = rows["f"]
        task: dict[str, FloatArray] | None = None
        if self.cartesian:
            log = self.ctrl.arrays()
            log = {key: v[len(v) - K :] for key, v in log.items()}
            xc, dxc, ddxc, xd = log["pc"], log["dpc"], log["ddpc"], log["pd"]
            p = np.asarray([self.chain.fk(x)[:3, 3] for x in q], dtype=np.float64)
            z1 = xd - p
            task = dict(log)
        else:
            xc, dxc, ddxc = (a[idx] for a in self.tables)
            xd, z1 = rows["xd"], rows["z1"]
        tau, zeta, dq_hat = rows["tau"], rows["zeta"], rows["dq_hat"]
        ctrl_params = self.ctrl.params if not self.cartesian else self.ctrl.params["inner"]
        target = tuple(
            np.broadcast_to(np.asarray(ctrl_params.get(key, v), dtype=np.float64), (n,)).tolist()
            for key, v in (("Dd", 1.0), ("Cd", 10.0), ("Gd", 60.0))
        )
        settle = self.settle
        arrays = {
            name: np.ascontiguousarray(a, dtype=np.float64)
            for name, a in (
                ("xc", xc), ("dxc", dxc), ("ddxc", ddxc), ("z1", z1), ("tau", tau),
            )
        }  # fmt: skip
        metrics = dict(
            _adaptimp.metrics(
                t, q, dq, ddq, arrays["xc"], arrays["dxc"], arrays["ddxc"], arrays["z1"],
                arrays["tau"], tau_sat, tau_e, settle, target, not self.cartesian,
            )
        )  # fmt: skip
        ns = self.ns[:K] * 1e-9
        gaps = np.diff(np.concatenate([[0.0], idx])) if K else np.zeros(0)
        case = self.ctrl.case if not self.cartesian else self.ctrl.inner.case
        params: dict[str, Any] = {
            "Ts": PERIOD,
            "substeps": 1,
            "timestep": PERIOD,
            "T": self.T,
            "settle": settle,
            "contact": False,
            "tau_max": tau_limits(self.s.plant),
            "wrench_source": "O_F_ext_hat_K",
            "model": model_name(self.s.plant.model),
            "controller": f"adaptimp.franka.setup({case!r}, task={self.s.kind!r})",
            "loop": "libfranka",
            "payload": 0.0,
            # Where the run started: the first cycle's posture (the joint task's
            # blend, the Cartesian task moved there).
            "q0": self.s.q.tolist(),
            "task": self.s.kind,
            "blend": self.s.blend,
            "cycles": {
                "total": K,
                "missed": int(np.sum(gaps[1:] > 1)) if K > 1 else 0,
                "longest": float(np.max(gaps[1:]) * PERIOD) if K > 1 else PERIOD,
            },
            "callback": {
                "p50": float(np.percentile(ns, 50)),
                "p99": float(np.percentile(ns, 99)),
                "max": float(np.max(ns)),
            },
            **self.params,
        }
        res = amj.MujocoResult(
            case=case,
            scenario="robot",
            params=params,
            metrics=metrics,
            t=t,
            q=q,
            dq=dq,
            ddq=ddq,
            xc=arrays["xc"],
            dxc=arrays["dxc"],
            ddxc=arrays["ddxc"],
            xd=np.ascontiguousarray(xd, dtype=np.float64),
            dq_hat=np.ascontiguousarray(dq_hat, dtype=np.float64),
            tau=arrays["tau"],
            tau_sat=tau_sat,
            tau_e=tau_e,
            zeta=np.ascontiguousarray(zeta, dtype=np.float64),
            z1=arrays["z1"],
            w_norms=np.full((K, 3), math.nan),
            x_ee=np.ascontiguousarray(x_ee),
            wrench_ee=np.ascontiguousarray(wrench_ee),
            task=task,
        )
        if self.cartesian and isinstance(self.s.task, CartesianTask):
            self.s.task.measure(res)
        return res


_ROWS = {
    "q": 7, "dq": 7, "tau_sat": 7, "tau_e": 7, "ee": 16, "f": 6, "tau": 7, "xd": 7, "z1": 7,
    "zeta": 7, "dq_hat": 7,
}  # fmt: skip
"""The width of each recorded quantity (the robot's state's, the controller's)."""
