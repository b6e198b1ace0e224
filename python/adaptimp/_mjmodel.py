"""Reading a compiled MuJoCo model by name: an object's name
(:func:`obj_name`), a joint's widths in qpos and qvel, and the file's
keyframes by name (:func:`file_keys`, :func:`restore_keys`), kept across the
plant's edits of :mod:`adaptimp._mjcf` (joints locked, actuators replaced).

Needs MuJoCo; imports nothing of the package. Units: rad, m, s."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

OBJ = mujoco.mjtObj
JOINT_TRN = (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))
"""The transmissions of an actuator that drives a joint."""


def obj_name(m: mujoco.MjModel, objtype: Any, i: int) -> str:
    return mujoco.mj_id2name(m, objtype, i) or f"#{i}"


def _nq(m: mujoco.MjModel, j: int) -> int:
    return {0: 7, 1: 4}.get(int(m.jnt_type[j]), 1)


def _nv(m: mujoco.MjModel, j: int) -> int:
    return {0: 6, 1: 3}.get(int(m.jnt_type[j]), 1)


@dataclass
class _Key:
    """A keyframe of the file, by name: every joint's qpos and qvel, every
    actuator's ctrl and act, every mocap body's mpos and mquat."""

    name: str
    time: float
    qpos: dict[str, FloatArray]
    qvel: dict[str, FloatArray]
    ctrl: dict[str, float]
    act: dict[str, FloatArray]
    mpos: dict[str, FloatArray]
    mquat: dict[str, FloatArray]


def file_keys(spec: Any, m0: mujoco.MjModel) -> list[_Key]:
    """The keyframes of ``m0`` (compiled from ``spec``) by name, removed from
    ``spec``: the plant's edits (joints locked, actuators made motors or
    removed) change the keyframes' layout, and MuJoCo's compiler checks their
    sizes, not their meaning."""
    out = []
    for k in range(m0.nkey):
        qpos, qvel, act = {}, {}, {}
        for j in range(m0.njnt):
            name = obj_name(m0, OBJ.mjOBJ_JOINT, j)
            qa, da = int(m0.jnt_qposadr[j]), int(m0.jnt_dofadr[j])
            qpos[name] = np.array(m0.key_qpos[k, qa : qa + _nq(m0, j)])
            qvel[name] = np.array(m0.key_qvel[k, da : da + _nv(m0, j)])
        for a in range(m0.nu):
            adr, num = int(m0.actuator_actadr[a]), int(m0.actuator_actnum[a])
            if adr >= 0 and num > 0:
                act[obj_name(m0, OBJ.mjOBJ_ACTUATOR, a)] = np.array(m0.key_act[k, adr : adr + num])
        mocap = [b for b in range(m0.nbody) if int(m0.body_mocapid[b]) >= 0]
        out.append(
            _Key(
                name=obj_name(m0, OBJ.mjOBJ_KEY, k)
                if mujoco.mj_id2name(m0, OBJ.mjOBJ_KEY, k)
                else "",
                time=float(m0.key_time[k]),
                qpos=qpos,
                qvel=qvel,
                ctrl={
                    obj_name(m0, OBJ.mjOBJ_ACTUATOR, a): float(m0.key_ctrl[k, a])
                    for a in range(m0.nu)
                },
                act=act,
                mpos={
                    obj_name(m0, OBJ.mjOBJ_BODY, b): np.array(m0.key_mpos[k, 3 * i : 3 * i + 3])
                    for b in mocap
                    for i in [int(m0.body_mocapid[b])]
                },
                mquat={
                    obj_name(m0, OBJ.mjOBJ_BODY, b): np.array(m0.key_mquat[k, 4 * i : 4 * i + 4])
                    for b in mocap
                    for i in [int(m0.body_mocapid[b])]
                },
            )
        )
    for key in list(spec.keys):
        spec.delete(key)
    # <size nkey> reserves keyframes, which a compile adds to the spec as
    # blank ones: the file's (blank ones too) are all in ``out``.
    spec.nkey = 0
    return out


def restore_keys(spec: Any, m: mujoco.MjModel, keys: Sequence[_Key], arm: set[str]) -> None:
    """The file's keyframes in ``spec``, laid out for ``m`` (compiled from it
    without keyframes): each joint, actuator and mocap body that ``m`` keeps
    has the file's values; a locked joint has gone with its entries; the arm's
    motors start at zero torque (the controller commands them)."""
    mocap = [b for b in range(m.nbody) if int(m.body_mocapid[b]) >= 0]
    for key in keys:
        qpos, qvel = np.array(m.qpos0), np.zeros(m.nv)
        for j in range(m.njnt):
            name = obj_name(m, OBJ.mjOBJ_JOINT, j)
            if name in key.qpos and key.qpos[name].size == _nq(m, j):
                qa, da = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
                qpos[qa : qa + _nq(m, j)] = key.qpos[name]
                qvel[da : da + _nv(m, j)] = key.qvel[name]
        ctrl, act = np.zeros(m.nu), np.zeros(m.na)
        for a in range(m.nu):
            name = obj_name(m, OBJ.mjOBJ_ACTUATOR, a)
            target = int(m.actuator_trnid[a, 0])
            motor = int(m.actuator_trntype[a]) in JOINT_TRN and (
                obj_name(m, OBJ.mjOBJ_JOINT, target) in arm
            )
            if not motor:
                ctrl[a] = key.ctrl.get(name, 0.0)
            adr, num = int(m.actuator_actadr[a]), int(m.actuator_actnum[a])
            if adr >= 0 and not motor and name in key.act and key.act[name].size == num > 0:
                act[adr : adr + num] = key.act[name]
        mpos, mquat = np.zeros(3 * m.nmocap), np.zeros(4 * m.nmocap)
        for b in mocap:
            i, name = int(m.body_mocapid[b]), obj_name(m, OBJ.mjOBJ_BODY, b)
            mpos[3 * i : 3 * i + 3] = key.mpos.get(name, m.body_pos[b])
            mquat[4 * i : 4 * i + 4] = key.mquat.get(name, m.body_quat[b])
        spec.add_key(
            name=key.name,
            time=key.time,
            qpos=qpos.tolist(),
            qvel=qvel.tolist(),
            ctrl=ctrl.tolist(),
            act=act.tolist(),
            mpos=mpos.tolist(),
            mquat=mquat.tolist(),
        )
