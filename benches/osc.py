"""adaptimp against robosuite's operational-space controller, OSC_POSE, head to head
on robosuite's own environments and arms.

Both controllers run the same scripted policies (closed-loop scripts that send
OSC_POSE actions, exactly as a policy does: a delta of the grip site's pose in
the base frame, scaled by the arm's ``output_max``, and the gripper), switched
only by ``controller_configs`` as docs/robosuite.md shows:

- **square**: ``Lift``'s arm traces a 10 cm square in the air at 5 cm/s, the
  orientation held, with a 1 s hold at each corner (13 s). Success: every
  corner reached within 5 mm at the end of its hold.
- **lift**: ``Lift``: above the cube, down, grasp, up 15 cm, hold (9 s).
  Success: robosuite's own (the cube 4 cm above the table) at the end.
- **wipe**: ``Wipe``: down onto the table at the dirt's start, then along the
  dirt's markers at 5 cm/s, pressing 1 cm below the surface (15 s). Success:
  robosuite's own (every marker wiped).

Model errors neither controller is told of (robosuite's OSC reads MuJoCo's
mass matrix and bias of the arm; adaptimp's rule reads the same model once):

- **cube**: ``Lift``'s cube at 1 kg (its density raised; the lift task only);
- **payload**: a body of 10 % of the arm's mass on the hand (welded to it by
  an equality constraint: its weight and inertia act on the arm, and neither
  the arm's mass matrix nor its bias holds it);
- **friction**: every arm joint's ``frictionloss`` and ``damping`` × 5.

Reported per arm, task, model error and controller, over ``--seeds`` seeds
(``suite.make(..., seed=s)``: the cube's place, the start's noise, the dirt's
path): RMS position (mm) and orientation (mrad) error of the grip site
against the goal pose the controller derives from the action (the goal
robosuite's OSC computes, the same for both; sampled at every model
timestep, when the torque is computed), the task's successes, and the
median ``env.step`` time (ms, one policy step: 25 model timesteps).

    python benches/osc.py [--json] [--arms Panda Sawyer ...] [--tasks square lift wipe]
        [--errors none cube payload friction] [--seeds 10] [--update FILE]
        [--params '{"stiffness": "osc"}']   # ADAPTIMP's options
    python benches/osc.py --phases [--json] [--arms ...] [--errors ...]   # the lift's phases
    python benches/osc.py --markdown FILE   # the tables of docs/robosuite.md from a --json FILE
"""

from __future__ import annotations

import abc
import argparse
import json
import statistics
import sys
import time
import xml.etree.ElementTree as ET
from typing import Any

import numpy as np
import robosuite as suite
import robosuite.utils.transform_utils as T
from robosuite.controllers import load_composite_controller_config
from robosuite.utils.log_utils import ROBOSUITE_DEFAULT_LOGGER

import adaptimp.robosuite as ars

ROBOSUITE_DEFAULT_LOGGER.setLevel("ERROR")

ARMS = ["Panda", "Sawyer", "IIWA", "UR5e", "Kinova3", "Jaco"]
TASKS = ["square", "lift", "wipe"]
ERRORS = ["none", "cube", "payload", "friction"]
CONTROLLERS = ["OSC_POSE", "ADAPTIMP"]
POLICY_DT = 0.05  # s: robosuite's control_freq of 20 Hz
PAYLOAD_SHARE = 0.10
FRICTION_FACTOR = 5.0
CUBE_MASS = 1.0  # kg


def config(robot: str, controller: str, params: dict[str, Any]) -> dict[str, Any]:
    """robosuite's default configuration of ``robot`` (OSC_POSE), or ADAPTIMP's."""
    if controller == "ADAPTIMP":
        return ars.controller_config(robot, **params)
    return load_composite_controller_config(robot=robot)


# -- model errors -----------------------------------------------------------------


def arm_mass(env: Any) -> float:
    """The arm's moving mass (kg): the bodies of the robot's model below its base,
    gripper included."""
    sim = env.sim
    robot = env.robots[0]
    first = sim.model.joint_name2id(robot.robot_joints[0])
    root = int(sim.model.jnt_bodyid[first])
    m = sim.model._model

    def below(b: int) -> bool:
        while b > 0:
            if b == root:
                return True
            b = int(m.body_parentid[b])
        return False

    return float(sum(m.body_mass[b] for b in range(m.nbody) if below(b)))


def add_payload(env: Any, mass: float) -> None:
    """A sphere of ``mass`` (kg) welded to the hand's origin: a free body of the
    scene (no collision), held by an equality constraint."""
    hand = env.robots[0].robot_model.eef_name["right"]
    root = ET.fromstring(env.model.get_xml())
    world = root.find("worldbody")
    assert world is not None
    body = ET.SubElement(world, "body", name="bench_payload", pos="0 0 0")
    ET.SubElement(body, "freejoint", name="bench_payload_joint")
    r = 0.03
    inertia = 0.4 * mass * r * r
    ET.SubElement(body, "inertial", pos="0 0 0", mass=f"{mass:.6g}",
                  diaginertia=f"{inertia:.6g} {inertia:.6g} {inertia:.6g}")  # fmt: skip
    ET.SubElement(body, "geom", type="sphere", size=f"{r}", contype="0", conaffinity="0",
                  group="1", rgba="0.9 0.6 0.1 1", mass="0")  # fmt: skip
    eq = root.find("equality")
    if eq is None:
        eq = ET.SubElement(root, "equality")
    ET.SubElement(eq, "weld", body1=hand, body2="bench_payload", relpose="0 0 0 1 0 0 0")
    env.reset_from_xml_string(ET.tostring(root, encoding="unicode"))


def place_payload(env: Any) -> None:
    """The payload where the weld holds it (after a reset put it at the origin)."""
    sim = env.sim
    try:
        j = sim.model.joint_name2id("bench_payload_joint")
    except ValueError:
        return
    hand = sim.model.body_name2id(env.robots[0].robot_model.eef_name["right"])
    adr = int(sim.model.jnt_qposadr[j])
    sim.data.qpos[adr : adr + 3] = sim.data.body_xpos[hand]
    sim.data.qpos[adr + 3 : adr + 7] = sim.data.body_xquat[hand]
    dadr = int(sim.model.jnt_dofadr[j])
    sim.data.qvel[dadr : dadr + 6] = 0.0
    sim.forward()


def apply_error(env: Any, error: str) -> None:
    """Apply the model error ``error`` to a new environment (made with hard_reset=False)."""
    if error == "payload":
        add_payload(env, PAYLOAD_SHARE * arm_mass(env))
    m = env.sim.model._model
    if error == "friction":
        dofs = env.robots[0]._ref_joint_vel_indexes
        m.dof_frictionloss[dofs] *= FRICTION_FACTOR
        m.dof_damping[dofs] *= FRICTION_FACTOR
    if error == "cube":
        b = env.sim.model.body_name2id(env.cube.root_body)
        scale = CUBE_MASS / float(m.body_mass[b])
        m.body_mass[b] *= scale
        m.body_inertia[b] *= scale


# -- the error probe ------------------------------------------------------------------


class Probe:
    """Records, at every model timestep, the grip site's pose against the goal pose
    robosuite's OSC derives from the action (the same computation for both)."""

    def __init__(self) -> None:
        self.pos: list[float] = []
        self.rot: list[float] = []
        self.vertical: list[float] = []

    def attach(self, env: Any) -> None:
        robot = env.robots[0]
        comp = robot.composite_controller
        part = robot.part_controllers["right"]
        osc = getattr(part, "osc", part)
        sim = env.sim
        site = sim.model.site_name2id(osc.ref_name)
        run = comp.run_controller

        def probed(enabled: Any) -> Any:
            if osc.goal_pos is not None and osc.origin_pos is not None:
                if osc.input_ref_frame == "base":
                    p = osc.origin_pos + osc.origin_ori @ osc.goal_pos
                    R = osc.origin_ori @ osc.goal_ori
                else:
                    p, R = osc.goal_pos, osc.goal_ori
                x = sim.data.site_xpos[site]
                Rx = sim.data.site_xmat[site].reshape(3, 3)
                self.pos.append(float(np.sum((p - x) ** 2)))
                self.vertical.append(float((p[2] - x[2]) ** 2))
                self.rot.append(float(np.sum(T.quat2axisangle(T.mat2quat(R @ Rx.T)) ** 2)))
            return run(enabled)

        comp.run_controller = probed


# -- the scripted policies -----------------------------------------------------------


class Script(abc.ABC):
    """A closed-loop scripted policy: a reference pose r(t) of the grip site and
    a gripper command; the action moves the goal to r(t + Δt) (clipped as
    OSC_POSE clips it), in the arm's base frame."""

    duration: float

    def __init__(self, env: Any, obs: dict[str, Any]) -> None:
        self.env = env
        robot = env.robots[0]
        part = robot.part_controllers["right"]
        self.out_pos = np.asarray(part.output_max[:3], dtype=np.float64)
        self.out_rot = np.asarray(part.output_max[3:6], dtype=np.float64)
        self.base_R = np.asarray(robot.base_ori, dtype=np.float64)
        self.p0 = np.array(obs["robot0_eef_pos"], dtype=np.float64)
        self.R0 = T.quat2mat(obs["robot0_eef_quat"])
        self.R_target = self.R0

    @abc.abstractmethod
    def reference(self, t: float) -> tuple[np.ndarray, float]:
        """The grip site's reference position (m, world frame) at time ``t`` (s)
        and the gripper command (−1 open … 1 closed): each task's own script."""

    def action(self, obs: dict[str, Any], t: float) -> np.ndarray:
        target, grip = self.reference(t + POLICY_DT)
        pos = obs["robot0_eef_pos"]
        R = T.quat2mat(obs["robot0_eef_quat"])
        a = np.zeros(self.env.action_dim)
        a[:3] = np.clip(self.base_R.T @ (target - pos) / self.out_pos, -1.0, 1.0)
        turn = T.quat2axisangle(T.mat2quat(self.R_target @ R.T))
        a[3:6] = np.clip(self.base_R.T @ turn / self.out_rot, -1.0, 1.0)
        a[6:] = grip
        return a

    def success(self) -> bool:
        return bool(self.env._check_success())

    def observe(self, obs: dict[str, Any], t: float) -> None:  # noqa: B027 (an optional hook)
        """Called after every step (a script that checks its own success)."""


def waypoints(points: list[np.ndarray], speed: float, holds: list[float], t: float) -> np.ndarray:
    """The point at t of a path that holds at each point ``holds[i]`` s and
    moves to the next at ``speed`` (m/s)."""
    for i, (a, hold) in enumerate(zip(points, holds)):
        if t < hold:
            return a
        t -= hold
        if i + 1 == len(points):
            return a
        b = points[i + 1]
        seg = float(np.linalg.norm(b - a)) / speed
        if t < seg:
            return a + (b - a) * (t / seg)
        t -= seg
    return points[-1]


class Square(Script):
    SIDE, SPEED, HOLD = 0.10, 0.05, 1.0
    TOL = 0.005  # m

    def __init__(self, env: Any, obs: dict[str, Any]) -> None:
        super().__init__(env, obs)
        s = self.SIDE
        corners = [(0, 0), (s, 0), (s, s), (0, s), (0, 0)]
        self.points = [self.p0 + self.base_R @ np.array([x, y, 0.0]) for x, y in corners]
        self.holds = [self.HOLD] * len(self.points)
        seg = s / self.SPEED
        self.ends = [self.HOLD * (i + 1) + seg * i for i in range(len(self.points))]
        self.duration = self.ends[-1]
        self.reached = [False] * len(self.points)

    def reference(self, t: float) -> tuple[np.ndarray, float]:
        return waypoints(self.points, self.SPEED, self.holds, t), -1.0

    def observe(self, obs: dict[str, Any], t: float) -> None:
        for i, end in enumerate(self.ends):
            if abs(t - end) < POLICY_DT / 2:
                self.reached[i] = bool(np.linalg.norm(obs["robot0_eef_pos"] - self.points[i])
                                       <= self.TOL)  # fmt: skip

    def success(self) -> bool:
        return all(self.reached)


class Lift(Script):
    """Open the gripper (0.5 s), above the cube (the gripper turned about the
    vertical to the cube's faces, modulo 90°), down to it, close until the
    fingers stop (at most 8 s: robosuite's Jaco hand closes at 0.01 of its
    range a step), up 15 cm, hold 2 s."""

    SPEED = 0.10
    ABOVE, LIFT = 0.10, 0.15
    CLOSE_MIN, CLOSE_MAX, STILL = 0.5, 8.0, 0.05  # s, s, rad/s (or m/s) of the fingers

    def __init__(self, env: Any, obs: dict[str, Any]) -> None:
        super().__init__(env, obs)
        cube = np.array(obs["cube_pos"], dtype=np.float64)
        yaw = np.arctan2(*T.quat2mat(obs["cube_quat"])[1::-1, 0])
        hand = np.arctan2(*self.R0[1::-1, 0])
        turn = (yaw - hand + np.pi / 4) % (np.pi / 2) - np.pi / 4
        c, s = np.cos(turn), np.sin(turn)
        self.R_target = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ self.R0
        self.down = [self.p0, cube + np.array([0.0, 0.0, self.ABOVE]), cube]
        self.holds = [0.5, 0.3, 0.0]
        self.up = [cube, cube + np.array([0.0, 0.0, self.LIFT])]
        d = [np.linalg.norm(b - a) for a, b in zip(self.down[:-1], self.down[1:])]
        self.close_at = sum(self.holds) + sum(d) / self.SPEED
        self.lift_at: float | None = None
        up = self.LIFT / self.SPEED + 2.0
        self.duration = self.close_at + self.CLOSE_MAX + up

    def reference(self, t: float) -> tuple[np.ndarray, float]:
        if t < self.close_at:
            grip = -1.0 if t < self.holds[0] else 0.0  # open, then leave it
            return waypoints(self.down, self.SPEED, self.holds, t), grip
        if self.lift_at is None or t < self.lift_at:
            return self.down[-1], 1.0
        return waypoints(self.up, self.SPEED, [0.0, 0.0], t - self.lift_at), 1.0

    def observe(self, obs: dict[str, Any], t: float) -> None:
        closing = t - self.close_at
        still = np.max(np.abs(obs["robot0_gripper_qvel"])) < self.STILL
        if (
            self.lift_at is None
            and closing >= self.CLOSE_MIN
            and (still or closing >= self.CLOSE_MAX)
        ):
            self.lift_at = t
            self.duration = t + self.LIFT / self.SPEED + 2.0


class Wipe(Script):
    SPEED, PRESS, ABOVE = 0.05, 0.01, 0.05

    def __init__(self, env: Any, obs: dict[str, Any]) -> None:
        super().__init__(env, obs)
        sim = env.sim
        markers = env.model.mujoco_arena.markers
        xy = [np.array(sim.data.body_xpos[sim.model.body_name2id(m.root_body)]) for m in markers]
        top = float(xy[0][2])  # the markers lie on the table's top
        # The grip site's height when the tool's face is on the table (at the start).
        face = self._face_offset()
        z = top + face - self.PRESS
        path = [np.array([p[0], p[1], z]) for p in xy]
        start_above = path[0] + np.array([0.0, 0.0, self.ABOVE + self.PRESS])
        self.points = [self.p0, start_above, *path]
        self.holds = [0.5, 0.5] + [0.0] * len(path)
        d = [np.linalg.norm(b - a) for a, b in zip(self.points[:-1], self.points[1:])]
        self.duration = sum(self.holds) + sum(d) / self.SPEED + 0.5

    def _face_offset(self) -> float:
        """The grip site's height above the tool's face (m), at the start."""
        env = self.env
        sim = env.sim
        gripper = env.robots[0].gripper["right"]
        corners = gripper.important_geoms["corners"]
        low = min(float(sim.data.geom_xpos[sim.model.geom_name2id(g)][2]) for g in corners)
        site = env.robots[0].part_controllers["right"].ref_name
        return float(sim.data.site_xpos[sim.model.site_name2id(site)][2]) - low

    def reference(self, t: float) -> tuple[np.ndarray, float]:
        return waypoints(self.points, self.SPEED, self.holds, t), 0.0


SCRIPTS: dict[str, tuple[str, type[Script]]] = {
    "square": ("Lift", Square),
    "lift": ("Lift", Lift),
    "wipe": ("Wipe", Wipe),
}


# -- episodes, in lockstep ---------------------------------------------------------------


class Episode:
    """One episode of a task under one controller, stepped from outside."""

    def __init__(self, robot: str, task: str, error: str, controller: str, seed: int,
                 params: dict[str, Any]) -> None:  # fmt: skip
        env_name, script_class = SCRIPTS[task]
        self.task = task
        self.env = suite.make(
            env_name, robots=robot, controller_configs=config(robot, controller, params),
            has_renderer=False, has_offscreen_renderer=False, use_camera_obs=False,
            hard_reset=False, horizon=10_000, seed=seed,
        )  # fmt: skip
        apply_error(self.env, error)
        self.obs = self.env.reset()
        place_payload(self.env)
        self.probe = Probe()
        self.probe.attach(self.env)
        self.script = script_class(self.env, self.obs)
        self.k = 0
        self.done = False
        self.times: list[float] = []
        self.forces: list[float] = []

    @property
    def running(self) -> bool:
        return not self.done and self.k * POLICY_DT < self.script.duration - 1e-9

    def step(self) -> None:
        a = self.script.action(self.obs, self.k * POLICY_DT)
        start = time.perf_counter()
        self.obs, _, self.done, _ = self.env.step(a)
        self.times.append(time.perf_counter() - start)
        self.k += 1
        self.script.observe(self.obs, self.k * POLICY_DT)
        # robosuite's own force reading at the hand (N), as Wipe's checks read it.
        self.forces.append(float(np.linalg.norm(self.env.robots[0].ee_force["right"])))

    def row(self) -> dict[str, Any]:
        env, probe = self.env, self.probe
        row = {
            "pos_ms": float(np.mean(probe.pos)),
            "rot_ms": float(np.mean(probe.rot)),
            "vertical_ms": float(np.mean(probe.vertical)),
            "success": self.script.success(),
            "step_s": self.times,
            "terminated": bool(self.done and self.k * POLICY_DT < self.script.duration - 1e-9),
            "force_max": max(self.forces),
            "force_mean": float(np.mean(self.forces)),
            "wiped": len(env.wiped_markers) / env.num_markers if self.task == "wipe" else None,
        }
        env.close()
        return row


def lockstep(robot: str, task: str, error: str, seed: int,
             params: dict[str, Any]) -> dict[str, dict[str, Any]]:  # fmt: skip
    """One episode per controller, the same seed, stepped in turn (each
    ``env.step`` timed under the same load as the other's)."""
    order = CONTROLLERS if seed % 2 == 0 else CONTROLLERS[::-1]
    episodes = {c: Episode(robot, task, error, c, seed, params) for c in order}
    while any(e.running for e in episodes.values()):
        for c in order:
            if episodes[c].running:
                episodes[c].step()
    return {c: episodes[c].row() for c in CONTROLLERS}


def measure(robot: str, task: str, error: str, seeds: int,
            params: dict[str, Any]) -> dict[str, Any]:  # fmt: skip
    """Both controllers on ``seeds`` seeds."""
    rows: dict[str, list[dict[str, Any]]] = {c: [] for c in CONTROLLERS}
    for s in range(seeds):
        for c, row in lockstep(robot, task, error, s, params).items():
            rows[c].append(row)
    out: dict[str, Any] = {}
    for c, rs in rows.items():
        steps = [t for r in rs for t in r["step_s"]]
        out[c] = {
            "rms_pos_mm": round(1e3 * float(np.sqrt(np.mean([r["pos_ms"] for r in rs]))), 3),
            "rms_rot_mrad": round(1e3 * float(np.sqrt(np.mean([r["rot_ms"] for r in rs]))), 3),
            "success": sum(r["success"] for r in rs),
            "seeds": len(rs),
            "terminated": sum(r["terminated"] for r in rs),
            "step_ms": round(1e3 * statistics.median(steps), 3),
            "rms_vertical_mm": round(
                1e3 * float(np.sqrt(np.mean([r["vertical_ms"] for r in rs]))), 3
            ),
            "force_max_N": round(max(r["force_max"] for r in rs), 2),
            "force_mean_N": round(float(np.mean([r["force_mean"] for r in rs])), 2),
        }
        if rs[0]["wiped"] is not None:
            out[c]["wiped"] = round(float(np.mean([r["wiped"] for r in rs])), 3)
    a, o = out["ADAPTIMP"], out["OSC_POSE"]
    out["pos_ratio"] = round(a["rms_pos_mm"] / o["rms_pos_mm"], 3) if o["rms_pos_mm"] else None
    out["step_ratio"] = round(a["step_ms"] / o["step_ms"], 3)
    return out


PHASES = ["approach", "grasp", "lift", "hold"]


def lift_phases(robot: str, error: str, seed: int = 0) -> dict[str, Any]:
    """Where the lift's error is: the RMS position error (mm) of each
    controller over each phase of the lift script (down to the cube at 10
    cm/s, the grasp, up 15 cm at 10 cm/s, the 2 s hold), one seed, the two
    episodes stepped in turn."""
    episodes = {c: Episode(robot, "lift", error, c, seed, {}) for c in CONTROLLERS}
    marks: dict[str, list[int]] = {c: [] for c in CONTROLLERS}
    while any(e.running for e in episodes.values()):
        for c, e in episodes.items():
            if e.running:
                e.step()
                marks[c].append(len(e.probe.pos))
    out: dict[str, Any] = {"arm": robot, "error": error, "seed": seed}
    for c, e in episodes.items():
        script = e.script
        assert isinstance(script, Lift)
        assert script.lift_at is not None
        k = [
            0,
            round(script.close_at / POLICY_DT),
            round(script.lift_at / POLICY_DT),
            round((script.lift_at + script.LIFT / script.SPEED) / POLICY_DT),
            len(marks[c]) - 1,
        ]
        pos = np.asarray(e.probe.pos)
        out[c] = {
            name: round(1e3 * float(np.sqrt(pos[marks[c][a] : marks[c][b]].mean())), 3)
            for name, a, b in zip(PHASES, k[:-1], k[1:])
        }
        e.env.close()
    return out


def phases_markdown(rows: list[dict[str, Any]]) -> str:
    """The lift's error per phase, OSC_POSE → ADAPTIMP (ADAPTIMP ÷ OSC)."""
    out = [
        "| arm | model error | " + " | ".join(f"{p} (mm)" for p in PHASES) + " |",
        "|---|---|" + "---:|" * len(PHASES),
    ]
    for r in rows:
        o, a = r["OSC_POSE"], r["ADAPTIMP"]
        cells = " | ".join(f"{o[p]:.2f} → {a[p]:.2f} ({a[p] / o[p]:.2f})" for p in PHASES)
        out.append(f"| {r['arm']} | {ERROR_NAMES[r['error']]} | {cells} |")
    return "\n".join(out) + "\n"


TASK_TITLES = {
    "square": "A square in the air (Lift's arm: 10 cm at 5 cm/s, 1 s at each corner)",
    "lift": "Pick and lift (Lift's cube: down, grasp, up 15 cm, hold 2 s)",
    "wipe": "Wipe (Wipe's table: pressed 1 cm in, along the dirt at 5 cm/s)",
}
ERROR_NAMES = {
    "none": "none",
    "cube": "cube 1 kg",
    "payload": "payload 10 %",
    "friction": "friction ×5",
}


def _pair(o: float, a: float, digits: int = 2) -> str:
    return f"{o:.{digits}f} → {a:.{digits}f}"


def _horizontal(c: dict[str, Any]) -> float:
    """The RMS error along the table (mm): the position's less the vertical's
    (both means over the same samples)."""
    return float(np.sqrt(max(c["rms_pos_mm"] ** 2 - c["rms_vertical_mm"] ** 2, 0.0)))


def _cut_short(r: dict[str, Any]) -> bool:
    """robosuite ended every episode of both controllers before the script
    did, and none succeeded (Wipe ends an episode on any contact of the robot)."""
    return all(r[c]["terminated"] == r[c]["seeds"] and r[c]["success"] == 0 for c in CONTROLLERS)


def markdown(results: list[dict[str, Any]]) -> str:
    """The tables of docs/robosuite.md from ``--json``'s results: one per task
    (OSC_POSE → ADAPTIMP in each cell), then the targets per arm."""
    out: list[str] = []
    for task in TASKS:
        rows = [r for r in results if r["task"] == task]
        if not rows:
            continue
        seeds = rows[0]["OSC_POSE"]["seeds"]
        out.append(f"#### {TASK_TITLES[task]}, {seeds} seeds\n")
        wipe = task == "wipe"
        extra = (
            " along the table (mm) | ÷ | vertical (mm) | ADAPTIMP's vertical ÷ OSC's position "
            "| wiped (%) | peak force (N) |"
            if wipe
            else ""
        )
        out.append(
            "| arm | model error | position (mm) | ADAPTIMP ÷ OSC | orientation (mrad) "
            f"| successes | env.step (ms) |{extra}"
        )
        out.append("|---|---|---:|---:|---:|---:|---:|" + ("---:|" * 6 if wipe else ""))
        for r in rows:
            o, a = r["OSC_POSE"], r["ADAPTIMP"]
            if _cut_short(r):
                out.append(
                    f"| {r['arm']} | {ERROR_NAMES[r['error']]} | robosuite ends every "
                    "episode before the script does, under either controller | — | — | "
                    f"{o['success']} → {a['success']} | — |" + (" — |" * 6 if wipe else "")
                )
                continue
            ratio = "—" if r["pos_ratio"] is None else f"**{r['pos_ratio']:.3f}**"
            line = (
                f"| {r['arm']} | {ERROR_NAMES[r['error']]} | "
                f"{_pair(o['rms_pos_mm'], a['rms_pos_mm'])} | {ratio} | "
                f"{_pair(o['rms_rot_mrad'], a['rms_rot_mrad'])} | "
                f"{o['success']} → {a['success']} | {_pair(o['step_ms'], a['step_ms'])} |"
            )
            if wipe:
                ho, ha = _horizontal(o), _horizontal(a)
                line += (
                    f" {_pair(ho, ha)} | {ha / ho:.3f} | "
                    f"{_pair(o['rms_vertical_mm'], a['rms_vertical_mm'])} | "
                    f"{a['rms_vertical_mm'] / o['rms_pos_mm']:.3f} | "
                    f"{_pair(100 * o['wiped'], 100 * a['wiped'], 0)} | "
                    f"{_pair(o['force_max_N'], a['force_max_N'], 1)} |"
                )
            out.append(line)
        out.append("")
    out.append(targets_markdown(results))
    return "\n".join(out)


def targets_markdown(results: list[dict[str, Any]]) -> str:
    """Per arm, the issue's targets against the rows: the largest ADAPTIMP ÷
    OSC_POSE position ratio under model error (target ≤ 0.5) and without
    (≤ 1.0), the successes summed over those rows (ADAPTIMP ≥ OSC_POSE), the
    largest env.step ratio (≤ 1.0). Rows robosuite cut short are left out."""
    out = [
        "#### The targets per arm (the rows above)\n",
        "| arm | model error: largest ÷ (≤ 0.5) | its row | successes OSC → ADAPTIMP "
        "| no model error: largest ÷ (≤ 1.0) | successes OSC → ADAPTIMP "
        "| env.step: largest ÷ (≤ 1.0) |",
        "|---|---:|---|---:|---:|---:|---:|",
    ]
    for arm in dict.fromkeys(r["arm"] for r in results):
        rows = [r for r in results if r["arm"] == arm and not _cut_short(r)]
        err = [r for r in rows if r["error"] != "none"]
        nom = [r for r in rows if r["error"] == "none"]
        if not err or not nom:
            continue
        worst = max(err, key=lambda r: r["pos_ratio"])

        def wins(rs: list[dict[str, Any]]) -> str:
            o = sum(r["OSC_POSE"]["success"] for r in rs)
            a = sum(r["ADAPTIMP"]["success"] for r in rs)
            n = sum(r["OSC_POSE"]["seeds"] for r in rs)
            return f"{o} → {a} of {n}"

        out.append(
            f"| {arm} | **{worst['pos_ratio']:.3f}** | {worst['task']}, "
            f"{ERROR_NAMES[worst['error']]} | {wins(err)} | "
            f"**{max(r['pos_ratio'] for r in nom):.3f}** | {wins(nom)} | "
            f"**{max(r['step_ratio'] for r in rows):.3f}** |"
        )
    return "\n".join(out) + "\n"


def update(path: str, rows: list[dict[str, Any]]) -> None:
    """Replace the rows of the ``--json`` results in ``path`` that ``rows``
    measured again (the same arm, task and model error), keep the others in
    their order, and write ``path`` back."""
    with open(path, encoding="utf-8") as f:
        data = json.load(f)
    new = {(r["arm"], r["task"], r["error"]): r for r in rows}
    kept = data["results"]
    data["results"] = [new.pop((r["arm"], r["task"], r["error"]), r) for r in kept]
    data["results"] += list(new.values())
    with open(path, "w", encoding="utf-8") as f:
        json.dump(data, f, indent=1)
        f.write("\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument(
        "--markdown", metavar="FILE", help="print the tables of a --json output FILE and exit"
    )
    ap.add_argument("--arms", nargs="+", default=ARMS)
    ap.add_argument("--tasks", nargs="+", default=TASKS, choices=TASKS)
    ap.add_argument("--errors", nargs="+", default=ERRORS, choices=ERRORS)
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument(
        "--phases",
        action="store_true",
        help="the lift's error per phase of its script, one seed (JSON with --json)",
    )
    ap.add_argument(
        "--update",
        metavar="FILE",
        help="measure, then replace those rows of a --json output FILE (the others kept)",
    )
    ap.add_argument(
        "--params",
        type=json.loads,
        default={},
        help="ADAPTIMP's options, a JSON object (controller_config's keywords), "
        'e.g. \'{"stiffness": "osc"}\'',
    )
    args = ap.parse_args()
    if args.markdown:
        with open(args.markdown, encoding="utf-8") as f:
            data = json.load(f)
        print(phases_markdown(data["phases"]) if "phases" in data else markdown(data["results"]))
        return
    if args.phases:
        rows = [lift_phases(robot, error) for robot in args.arms for error in args.errors]
        if args.json:
            json.dump({"phases": rows}, sys.stdout, indent=1)
            print()
        else:
            print(phases_markdown(rows))
        return
    results: list[dict[str, Any]] = []
    for robot in args.arms:
        for task in args.tasks:
            for error in args.errors:
                if error == "cube" and task != "lift":
                    continue
                got = measure(robot, task, error, args.seeds, args.params)
                row = {"arm": robot, "task": task, "error": error, **got}
                results.append(row)
                if args.update:  # row by row: a run cut short keeps what it measured
                    update(args.update, [row])
                if args.json:
                    print(f"{robot} {task} {error}: {got['pos_ratio']}", file=sys.stderr)
                elif _cut_short(row):
                    print(f"{robot:8s} {task:6s} {error:8s} cut short by robosuite", flush=True)
                else:
                    a, o = got["ADAPTIMP"], got["OSC_POSE"]
                    print(
                        f"{robot:8s} {task:6s} {error:8s} pos {o['rms_pos_mm']:7.2f} → "
                        f"{a['rms_pos_mm']:7.2f} mm ({got['pos_ratio']:.3f})  rot "
                        f"{o['rms_rot_mrad']:6.2f} → {a['rms_rot_mrad']:6.2f} mrad  success "
                        f"{o['success']}/{o['seeds']} → {a['success']}/{a['seeds']}  step "
                        f"{o['step_ms']:.2f} → {a['step_ms']:.2f} ms",
                        flush=True,
                    )
    if args.json:
        json.dump({"results": results}, sys.stdout, indent=1)
        print()


if __name__ == "__main__":
    main()
