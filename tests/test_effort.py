"""The effort estimate of an arm whose description states no limits is the
core's one rule (``_adaptimp.estimate_effort``): bit for bit what the URDF
front (:func:`adaptimp.mujoco.estimate_effort`) computes, and what the MJCF
front (``adaptimp._sampled.estimate``, which calls it, with the joints' damping
and friction) computed in NumPy before."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from adaptimp import _adaptimp, _sampled
from adaptimp import mujoco as am

DATA = Path(__file__).parent / "data"


def _samples(
    model: mujoco.MjModel, dofs: list[int], qadr: list[int]
) -> tuple[np.ndarray, np.ndarray]:
    """G (K, n) and D (K, n, n) at the fronts' 256 postures."""
    joints = [int(model.dof_jntid[d]) for d in dofs]
    lo, hi = _sampled._limits(model, joints)
    data = mujoco.MjData(model)
    full = np.zeros((model.nv, model.nv))
    g, d = [], []
    for q in _sampled._postures(lo, hi, 256):
        data.qpos[:] = model.qpos0
        data.qpos[qadr] = q
        data.qvel[:] = 0.0
        mujoco.mj_forward(model, data)
        _sampled._full_inertia(model, data, full)
        g.append(data.qfrc_bias[dofs].copy())
        d.append(full[np.ix_(dofs, dofs)].copy())
    return np.array(g), np.array(d)


def test_the_urdf_estimate_is_the_cores() -> None:
    model = am.panda(None)
    joints = sorted(range(model.njnt), key=lambda j: int(model.jnt_dofadr[j]))
    dofs = [int(model.jnt_dofadr[j]) for j in joints]
    qadr = [int(model.jnt_qposadr[j]) for j in joints]
    g, d = _samples(model, dofs, qadr)
    assert np.array_equal(_adaptimp.estimate_effort(g, d), am.estimate_effort(model))


def test_the_mjcf_estimate_with_damping_and_friction_is_the_cores() -> None:
    model = mujoco.MjModel.from_xml_path(str(DATA / "fold_arm.xml"))
    dofs = list(range(model.nv))
    qadr = [int(model.jnt_qposadr[model.dof_jntid[v]]) for v in dofs]
    model.dof_damping[:] = 0.3 + 0.1 * np.arange(model.nv)
    model.dof_frictionloss[:] = 0.05
    g, d = _samples(model, dofs, qadr)
    b, f = model.dof_damping[dofs], model.dof_frictionloss[dofs]
    core = _adaptimp.estimate_effort(g, d, b, f)
    assert np.array_equal(core, _sampled.estimate(model, qadr, dofs))
    # The NumPy formula the front had: the same bits.
    gmax = np.max(np.abs(g), axis=0)
    dmax = np.max(np.sum(np.abs(d), axis=2), axis=0)
    assert np.array_equal(core, 2.0 * (gmax + 10.0 * dmax + (1.0 * b + f)))
    # Without the drag terms, 2 (b_i · 1 rad/s + F_i) less.
    bare = _adaptimp.estimate_effort(g, d)
    np.testing.assert_allclose(core - bare, 2 * (model.dof_damping + 0.05), rtol=1e-12)


def test_wrong_shapes_are_named() -> None:
    g = np.zeros((3, 2))
    with pytest.raises(ValueError, match=r"inertia must have shape \(3, 2, 2\), got \[3, 2, 3\]"):
        _adaptimp.estimate_effort(g, np.zeros((3, 2, 3)))
    with pytest.raises(ValueError, match="damping and friction are given together"):
        _adaptimp.estimate_effort(g, np.zeros((3, 2, 2)), np.zeros(2))
    with pytest.raises(ValueError, match=r"^gravity: needs K ≥ 1 rows of n values$"):
        _adaptimp.estimate_effort(np.zeros((0, 2)), np.zeros((0, 2, 2)))
    with pytest.raises(ValueError, match=r"^damping: needs n values$"):
        _adaptimp.estimate_effort(g, np.zeros((3, 2, 2)), np.zeros(3), np.zeros(2))
