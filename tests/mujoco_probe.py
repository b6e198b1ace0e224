"""Test helpers for adaptimp.mujoco: what the core's loop measures at the plant's
current state, and independent references to check it against (MuJoCo's own
contact list and Jacobians, read here in Python)."""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from adaptimp import mujoco as amj


class Hold:
    """A constant torque at period ``Ts``: a controller written in Python."""

    def __init__(self, tau: Any, Ts: float = 1e-3) -> None:
        self.tau_cmd = np.asarray(tau, dtype=np.float64)
        self.Ts = Ts

    def step(self, m: Any, **setpoint: Any) -> np.ndarray:
        return self.tau_cmd


def measure(plant: amj.Plant, tau: Any) -> amj.MujocoResult:
    """One period of the core's loop from the plant's current state (its last
    forward computation) with ``tau`` (N m) applied: row 0 holds what the
    core measures there (x_ee, wrench_ee, tau_e at the torque held so far)
    and q̈ under ``tau``."""
    Ts = plant.timestep
    return amj.simulate(Hold(tau, Ts), plant, T=Ts, substeps=1, reset=False)


def push(plant: amj.Plant, target: Any, gravity: Any, steps: int = 20_000) -> np.ndarray:
    """Press the end effector against the environment with MuJoCo alone:
    gravity compensation ``gravity(q)`` and a joint PD towards ``target``
    (rad), at a timestep of 0.1 ms, until at rest; then the torque without
    the damping term held, and MuJoCo's forward computation. Returns it (N m)."""
    plant.timestep = 1e-4
    plant.reset(np.full(plant.n, 0.1))
    m, d = plant.model, plant.data
    act, gear, target = plant._act, plant._gear, np.asarray(target, dtype=np.float64)

    def apply(tau: np.ndarray) -> np.ndarray:
        tau = np.clip(tau, -plant.tau_max, plant.tau_max)
        d.ctrl[act] = tau / gear
        return tau

    for _ in range(steps):
        apply(gravity(plant.q) + 20.0 * (target - plant.q) - 3.0 * plant.dq)
        mujoco.mj_step(m, d)
    tau = apply(gravity(plant.q) + 20.0 * (target - plant.q))
    mujoco.mj_forward(m, d)
    return tau


def contact_list_wrench(plant: amj.Plant) -> np.ndarray:
    """F_e (6,) summed over MuJoCo's contact list by ``mj_contactForce``: the
    contacts of the end effector's subtree with anything else, the force on
    the environment and its moment about the end-effector point (world frame)."""
    m, d = plant.model, plant.data
    point = ee_position(plant)
    out, local = np.zeros(6), np.zeros(6)
    for i in range(d.ncon):
        c = d.contact[i]
        if c.efc_address < 0:
            continue
        b1 = int(m.geom_bodyid[c.geom1]) in plant._ee_subtree
        b2 = int(m.geom_bodyid[c.geom2]) in plant._ee_subtree
        if b1 == b2:
            continue
        mujoco.mj_contactForce(m, d, i, local)
        frame = c.frame.reshape(3, 3)
        f, t = frame.T @ local[:3], frame.T @ local[3:]
        sign = 1.0 if b1 else -1.0
        out[:3] += sign * f
        out[3:] += sign * (np.cross(c.pos - point, f) + t)
    return out


def ee_position(plant: amj.Plant) -> np.ndarray:
    """The end-effector point (m), (3,), of MuJoCo's last forward computation."""
    d = plant.data
    site = plant._site
    return np.array(d.site_xpos[site] if site >= 0 else d.xpos[plant._ee_body])


def ee_jacobian(plant: amj.Plant) -> np.ndarray:
    """[J_p; J_r] (6, n) of the end-effector point, world frame."""
    m, d = plant.model, plant.data
    jac = np.zeros((6, m.nv))
    if plant._site >= 0:
        mujoco.mj_jacSite(m, d, jac[:3], jac[3:], plant._site)
    else:
        mujoco.mj_jacBody(m, d, jac[:3], jac[3:], plant._ee_body)
    return jac[:, plant._dofs]
