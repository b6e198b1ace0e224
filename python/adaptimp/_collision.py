"""Collisions and the arm's dynamics at postures, on a MuJoCo plant's model
(SPEC (16.9)): what the one posture check (:mod:`adaptimp._posture`) reads of
an ``adaptimp.mujoco.Plant`` without touching its state. Imported only for a
Plant (MuJoCo is the extra ``mujoco``). Units: m, rad, N m, kg m².
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from . import _contacts

FloatArray = NDArray[np.float64]

SKELETON_RADIUS = 0.04
"""The radius of a link of the skeleton check (:func:`self_collision`), as a
share of the sum of the skeleton's segment lengths (the arm's length)."""


class _Probe:
    """Gravity, inertia and self-collision of the plant's model at postures,
    on a data of its own (the plant's state untouched)."""

    def __init__(self, plant: Any) -> None:
        self.plant, self.m = plant, plant.model
        self.d = mujoco.MjData(self.m)
        self.qadr = np.asarray(plant.qpos_adr)
        self.dofs = np.asarray(plant.dof_adr)
        self._full = np.zeros((self.m.nv, self.m.nv))

    def at(self, q: FloatArray) -> None:
        self.d.qpos[:] = self.m.qpos0
        self.d.qpos[self.qadr] = q
        self.d.qvel[:] = 0.0
        mujoco.mj_forward(self.m, self.d)

    def gravity(self, q: FloatArray) -> FloatArray:
        self.at(q)
        return np.array(self.d.qfrc_bias[self.dofs], dtype=np.float64)

    def inertia(self, q: FloatArray) -> FloatArray:
        self.at(q)
        try:
            mujoco.mj_fullM(self.m, self.d, self._full)
        except TypeError:  # MuJoCo 3: mj_fullM(m, dst, qM)
            mujoco.mj_fullM(self.m, self._full, self.d.qM)
        return np.array(self._full[np.ix_(self.dofs, self.dofs)], dtype=np.float64)


def self_collision(plant: Any, rows: FloatArray) -> str | None:
    """The first collision of the arm with itself at the postures ``rows``
    (K, n) (rad), named ("row k: 'a'–'b' touch"), or None (:func:`collision`
    among the arm's own bodies)."""
    return collision(plant, rows, scene=False)


def collision(
    plant: Any, rows: FloatArray, *, scene: bool = True, skip: frozenset[int] = frozenset()
) -> str | None:
    """The first collision of the arm at the postures ``rows`` (K, n) (rad),
    with itself or (``scene``) with the rest of the scene (another arm, a
    pedestal, the table, a free or mocap body, where the plant's state puts
    them: the file's keyframe), named ("row k: 'a'–'b' touch"), or None.
    Contacts of the bodies ``skip`` (ids: a tool meant to touch) are left out.

    With the model's collision geometry (two bodies that the arm's joints
    move relative to each other and that can collide): MuJoCo's collision
    detection, contacts enabled, as the joint-space task's check has it
    (``_contacts.Contacts``, SPEC §18: its exclusions and parent–child filter
    kept).
    Without (a URDF compiled as :func:`adaptimp.mujoco.from_urdf` does, which
    keeps no collision geometry): the arm's skeleton, capsules along the
    segments between consecutive distinct joint anchors and the end effector,
    of radius r = :data:`SKELETON_RADIUS` times the skeleton's length, each
    less r where it meets the next; two links that are not neighbours must not
    come within 2r.
    """
    m = plant.model
    flags = int(m.opt.disableflags)
    m.opt.disableflags = flags & ~int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    try:  # the copy Contacts makes has contacts on, whatever the plant's setting
        contacts = _contacts.Contacts(
            m, plant.data.qpos, list(plant.joint_ids), self_only=not scene
        )
    finally:
        m.opt.disableflags = flags
    names = {mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) for b in skip}
    if contacts.possible:
        for k, q in enumerate(rows):
            found = [c for c in contacts.at(q) if c[0] not in names and c[1] not in names]
            if found:
                return f"row {k}: {_contacts.pairs(found)} touch"
        return None
    probe = _Probe(plant)
    for k, q in enumerate(rows):
        probe.at(q)
        points = [np.array(probe.d.xanchor[j]) for j in plant.joint_ids]
        site = plant.ee_site
        points.append(
            np.array(probe.d.site_xpos[site] if site >= 0 else probe.d.xpos[plant.ee_body])
        )
        pts = [np.zeros(3)]
        for p in points:
            if np.linalg.norm(p - pts[-1]) > 1e-6:
                pts.append(p)
        length = sum(float(np.linalg.norm(b - a)) for a, b in zip(pts, pts[1:]))
        r = SKELETON_RADIUS * length
        segs = [
            _trimmed(a, b, r, first=i == 0, last=i == len(pts) - 2)
            for i, (a, b) in enumerate(zip(pts, pts[1:]))
        ]
        for i, si in enumerate(segs):
            for j in range(i + 2, len(segs)):
                sj = segs[j]
                if si is None or sj is None:
                    continue
                if _segment_distance(si[0], si[1], sj[0], sj[1]) < 2 * r:
                    return (
                        f"row {k}: the skeleton's links {i} and {j} (between joint anchors) "
                        f"come within {2 * r:.3g} m"
                    )
    return None


def _trimmed(
    a: FloatArray, b: FloatArray, r: float, *, first: bool, last: bool
) -> tuple[FloatArray, FloatArray] | None:
    """The segment [a, b] less a length ``r`` at each end where it meets another
    link (not at the base or the end effector), or None if nothing is left:
    two links meet at a joint, and their capsules overlap there by design."""
    length = float(np.linalg.norm(b - a))
    cut_a, cut_b = (0.0 if first else r), (0.0 if last else r)
    if length <= cut_a + cut_b:
        return None
    u = (b - a) / length
    return a + cut_a * u, b - cut_b * u


def _segment_distance(p1: FloatArray, q1: FloatArray, p2: FloatArray, q2: FloatArray) -> float:
    """The distance (m) between the segments [p1, q1] and [p2, q2] (Ericson,
    *Real-Time Collision Detection*, 2005, §5.1.9)."""
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a, e, f = float(d1 @ d1), float(d2 @ d2), float(d2 @ r)
    if a <= 1e-12 and e <= 1e-12:
        return float(np.linalg.norm(r))
    if a <= 1e-12:
        s, t = 0.0, min(max(f / e, 0.0), 1.0)
    else:
        c = float(d1 @ r)
        if e <= 1e-12:
            s, t = min(max(-c / a, 0.0), 1.0), 0.0
        else:
            b = float(d1 @ d2)
            den = a * e - b * b
            s = min(max((b * f - c * e) / den, 0.0), 1.0) if den > 1e-12 else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                s, t = min(max(-c / a, 0.0), 1.0), 0.0
            elif t > 1.0:
                s, t = min(max((b - c) / a, 0.0), 1.0), 1.0
    return float(np.linalg.norm(p1 + d1 * s - (p2 + d2 * t)))
