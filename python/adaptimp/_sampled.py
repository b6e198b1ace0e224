"""An arm at postures sampled within its joint limits (SPEC §18): the postures
(:func:`_postures`), the joints' limits (:func:`_limits`), MuJoCo's dense
inertia (:func:`_full_inertia`), and the effort estimate where nothing
declares τmax (:func:`estimate`, the core's one rule).

Needs MuJoCo; imports nothing of the package but the extension. Units: rad,
N m, kg m²."""

from __future__ import annotations

import math
from collections.abc import Sequence

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def _limits(model: mujoco.MjModel, joints: Sequence[int]) -> tuple[FloatArray, FloatArray]:
    """Position limits (rad) of ``joints``; ∓inf where a hinge is unlimited."""
    lo = np.full(len(joints), -math.inf)
    hi = np.full(len(joints), math.inf)
    for i, j in enumerate(joints):
        if model.jnt_limited[j]:
            lo[i], hi[i] = model.jnt_range[j]
    return lo, hi


def _postures(lo: FloatArray, hi: FloatArray, count: int, margin: ArrayLike = 0.0) -> FloatArray:
    """``count`` postures (rad), deterministic, uniform in the box [lo + margin,
    hi − margin] (±π for an unlimited joint): the zero posture clipped into the
    box first, then the box's middle, then samples of a fixed-seed generator."""
    m = np.asarray(margin, dtype=np.float64)
    a: FloatArray = np.where(np.isfinite(lo), lo, -math.pi) + m
    b: FloatArray = np.where(np.isfinite(hi), hi, math.pi) - m
    rng = np.random.default_rng(0)
    out = rng.uniform(a, b, size=(count, len(lo)))
    out[0] = np.clip(0.0, a, b)
    if count > 1:
        out[1] = (a + b) / 2
    return np.asarray(out, dtype=np.float64)


def _full_inertia(m: mujoco.MjModel, d: mujoco.MjData, out: FloatArray) -> None:
    """The dense joint-space inertia into ``out`` (mj_fullM's signature changed in MuJoCo 4)."""
    try:
        mujoco.mj_fullM(m, d, out)
    except TypeError:  # MuJoCo 3: mj_fullM(m, dst, qM)
        mujoco.mj_fullM(m, out, d.qM)


# ---------------------------------------------------------------------------


def estimate(
    m: mujoco.MjModel,
    qadr: Sequence[int],
    dofs: Sequence[int],
    postures: int = 256,
    *,
    drag: bool = True,
) -> FloatArray:
    """τmax (N m) per arm joint where nothing declares it: 2 (max |G_i| + 10
    rad/s² · max Σ_j |D_ij| + b_i · 1 rad/s + F_i) over ``postures`` postures
    within the joint limits, by the core's one rule
    (``_adaptimp.estimate_effort``; D with the rotors' armature). With
    ``drag``, the joint's own viscous damping b_i at 1 rad/s and dry friction
    F_i (``frictionloss``), which a file may make the larger part
    (metaworld's Sawyer: b = 10 N m s/rad on a wrist of 0.01 kg m²); without
    it (a URDF's arm, :func:`adaptimp.mujoco.estimate_effort`), b = F = 0. G
    and D are MuJoCo's at each posture."""
    from . import _adaptimp

    joints = [int(m.dof_jntid[d]) for d in dofs]
    lo, hi = _limits(m, joints)
    data = mujoco.MjData(m)
    full = np.zeros((m.nv, m.nv))
    samples = _postures(lo, hi, postures)
    g = np.empty((len(samples), len(dofs)))
    d = np.empty((len(samples), len(dofs), len(dofs)))
    for k, q in enumerate(samples):
        data.qpos[:] = m.qpos0
        data.qpos[list(qadr)] = q
        data.qvel[:] = 0.0
        mujoco.mj_forward(m, data)
        _full_inertia(m, data, full)
        g[k] = data.qfrc_bias[list(dofs)]
        d[k] = full[np.ix_(dofs, dofs)]
    if not drag:
        return np.asarray(_adaptimp.estimate_effort(g, d), dtype=np.float64)
    drag_terms = (m.dof_damping[list(dofs)], m.dof_frictionloss[list(dofs)])
    return np.asarray(_adaptimp.estimate_effort(g, d, *drag_terms), dtype=np.float64)
