"""A Franka for tests of adaptimp.franka's loop without a server: pylibfranka's
``Robot`` and active torque control, in a test's own time.

The arm is the URDF's in MuJoCo, without gravity (the robot's compensation,
exact); each command acts from the next 1 ms tick (libfranka's one cycle of
delay) and is held until another arrives. Everything is recorded: the
commands, the recoveries, the collision thresholds. Deterministic: no wall
clock, no thread, no socket.
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from adaptimp import franka
from adaptimp._cartesian_task import chain_of


def _fr3() -> str:
    spec = importlib.util.find_spec("franky_sim")
    if spec is None or spec.origin is None:
        raise ImportError("the test extra installs franky-sim, whose FR3 URDF these tests use")
    return str(Path(spec.origin).parent / "assets" / "fr3.urdf")


FR3 = _fr3()
"""franky-sim's own FR3 URDF, as its maker ships it."""


class Period:
    """The time since the last state, as pylibfranka's ``Duration``."""

    def __init__(self, ms: int) -> None:
        self.ms = ms

    def to_sec(self) -> float:
        return self.ms * 1e-3


class Errors:
    """pylibfranka's ``Errors``: false when empty; ``str`` lists the names."""

    def __init__(self, names: Sequence[str] = ()) -> None:
        self.names = list(names)

    def __bool__(self) -> bool:
        return bool(self.names)

    def __str__(self) -> str:
        return "[" + ", ".join(f'"{n}"' for n in self.names) + "]"


@dataclass
class State:
    """The fields of a ``RobotState`` the loop reads (lists, as pylibfranka's)."""

    q: list[float]
    dq: list[float]
    O_F_ext_hat_K: list[float]
    O_T_EE: list[float]
    EE_T_K: list[float]
    tau_J_d: list[float]
    current_errors: Errors = field(default_factory=Errors)
    last_motion_errors: Errors = field(default_factory=Errors)


@dataclass
class FakeRobot:
    """pylibfranka's ``Robot`` over a MuJoCo arm without gravity.

    Parameters: ``urdf`` and the start posture ``q0``; ``stretch``: cycles
    after which the client is late (cycle → ms until its next state);
    ``wrench``: the constant ``O_F_ext_hat_K``; ``state_hook(cycle, state)``
    may edit a state before it is returned; ``fail``: cycle → the exception
    ``readOnce`` raises there (then ``last_motion_errors`` holds
    ``fail_errors``); ``errors``: the robot's errors before any start.
    """

    urdf: str
    q0: Sequence[float] = franka.READY
    stretch: Mapping[int, int] = field(default_factory=dict)
    wrench: Sequence[float] = (0.0,) * 6
    state_hook: Callable[[int, State], None] | None = None
    fail: Mapping[int, BaseException] = field(default_factory=dict)
    fail_errors: Sequence[str] = ()
    errors: Sequence[str] = ()

    def __post_init__(self) -> None:
        self.plant = franka.plant(self.urdf)
        self.plant.reset(np.asarray(self.q0, dtype=np.float64))
        self.plant.timestep = franka.PERIOD
        self.chain = chain_of(self.plant)
        self.sent: list[tuple[list[float], bool]] = []
        self.recoveries = 0
        self.collision: tuple[Any, ...] | None = None
        self.current = Errors(self.errors)
        self.last_motion = Errors()
        self.applied = np.zeros(7)
        self.pending = np.zeros(7)

    def state(self) -> State:
        q = self.plant.q
        pose = self.chain.fk(q)
        return State(
            q=q.tolist(),
            dq=self.plant.dq.tolist(),
            O_F_ext_hat_K=list(map(float, self.wrench)),
            O_T_EE=pose.flatten(order="F").tolist(),
            EE_T_K=np.eye(4).flatten(order="F").tolist(),
            tau_J_d=self.applied.tolist(),
            current_errors=self.current,
            last_motion_errors=self.last_motion,
        )

    def tick(self) -> None:
        """One 1 ms step with the torque that acts now; the last command
        received acts from the next."""
        d = self.plant.data
        d.ctrl[:] = self.applied
        mujoco.mj_step(self.plant.model, d)
        self.applied = self.pending.copy()

    # pylibfranka's Robot
    def read_once(self) -> State:
        return self.state()

    def set_collision_behavior(self, *thresholds: Any) -> None:
        self.collision = thresholds

    def automatic_error_recovery(self) -> None:
        self.recoveries += 1
        self.current = Errors()

    def start_torque_control(self) -> Control:
        return Control(self)


class Control:
    """The active torque control: ``readOnce`` and ``writeOnce``."""

    def __init__(self, robot: FakeRobot) -> None:
        self.robot = robot
        self.cycle = -1
        self.late = 0  # ms until the next state
        self.finished = False

    def readOnce(self) -> tuple[State, Period]:
        r = self.robot
        assert not self.finished, "readOnce after the motion finished"
        self.cycle += 1
        if self.cycle in r.fail:
            r.last_motion = Errors(r.fail_errors)
            raise r.fail[self.cycle]
        ms = 0 if self.cycle == 0 else self.late
        for _ in range(ms):
            r.tick()
        state = r.state()
        if r.state_hook is not None:
            r.state_hook(self.cycle, state)
        return state, Period(ms)

    def writeOnce(self, command: Any) -> None:
        r = self.robot
        assert not self.finished, "writeOnce after the motion finished"
        tau = list(command.tau_J)
        r.sent.append((tau, bool(command.motion_finished)))
        r.pending = np.asarray(tau, dtype=np.float64)
        self.finished = bool(command.motion_finished)
        self.late = int(r.stretch.get(self.cycle, 1))


class PositionControl(Control):
    """The robot's own joint position controller, ideal: each command's
    posture is where the arm stands at the next state."""

    def readOnce(self) -> tuple[State, Period]:
        assert not self.finished, "readOnce after the motion finished"
        self.cycle += 1
        return self.robot.state(), Period(0 if self.cycle == 0 else 1)

    def writeOnce(self, command: Any) -> None:
        r = self.robot
        assert not self.finished, "writeOnce after the motion finished"
        q = list(command.q)
        r.sent.append((q, bool(command.motion_finished)))
        r.plant.reset(np.asarray(q, dtype=np.float64))
        self.finished = bool(command.motion_finished)


def _position_control(self: FakeRobot, mode: Any) -> PositionControl:
    self.position_mode = mode
    return PositionControl(self)


FakeRobot.start_joint_position_control = _position_control  # type: ignore[attr-defined]
