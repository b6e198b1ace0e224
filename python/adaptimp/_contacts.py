"""Contacts of a MuJoCo plant (SPEC §18.10): the contacts the arm's motion
makes (:func:`movers`, :func:`moving_contacts`, :class:`Contacts` at postures,
for the default task's self-collision check and the check after a run), and
the contacts watched through a run by sensors the plant adds
(:func:`watch_contacts`, :class:`Watch`).

Below :mod:`adaptimp._plant`; takes the arm's tree from
:mod:`adaptimp._mjcf`. Units: m, N."""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from ._mjcf import arm_tree, movers, root_body
from ._mjmodel import OBJ, obj_name

FloatArray = NDArray[np.float64]


# Contacts the arm's motion makes.
# ---------------------------------------------------------------------------


def moving_contacts(
    m: mujoco.MjModel,
    d: mujoco.MjData,
    moved_by: Sequence[frozenset[int]],
    tree: frozenset[int] | None = None,
    clearance: float = 0.0,
) -> list[tuple[str, str, float]]:
    """The contacts in ``d`` (after collision detection) between two bodies the
    arm's joints move relative to each other (their sets in ``moved_by``
    differ) and closer than ``clearance`` (m; 0: touching or penetrating), as
    (body, body, distance in m); with ``tree``, only those whose
    two bodies are in it (the arm touching itself). Two links that meet at a
    joint (one the other's parent) do not count, as MuJoCo's parent filter
    has it, also where the parent is welded to the world (a base, whose
    geometry often meets the first link's at the joint whatever the task)."""
    weld, parent = m.body_weldid, m.body_parentid
    out = []
    for c in d.contact[: d.ncon]:
        b1, b2 = int(m.geom_bodyid[c.geom1]), int(m.geom_bodyid[c.geom2])
        if moved_by[b1] == moved_by[b2] or c.dist >= clearance:
            continue
        w1, w2 = int(weld[b1]), int(weld[b2])
        if int(weld[parent[w1]]) == w2 or int(weld[parent[w2]]) == w1:
            continue  # links that meet at their joint (as MuJoCo's filterparent)
        if tree is not None and not (b1 in tree and b2 in tree):
            continue
        pair = sorted((obj_name(m, OBJ.mjOBJ_BODY, b1), obj_name(m, OBJ.mjOBJ_BODY, b2)))
        out.append((pair[0], pair[1], float(c.dist)))
    return out


class Contacts:
    """Collision detection at postures of the arm, on a copy of ``model``
    (SPEC §18's safety checks): :meth:`at` gives :func:`moving_contacts` at a
    posture q of the arm's joints (the other joints at the plant's current
    state ``qpos``), with every geom's margin raised to ``margin`` (m) so that
    a near miss counts too.

    Parameters
    ----------
    model : MjModel
        The plant's model (not changed).
    qpos : array
        The full configuration the arm's joints are set into.
    joint_ids : sequence of int
        The arm's joints.
    margin : float
        Clearance (m) below which two geoms count as touching.
    self_only : bool
        Only contacts between bodies of the arm's own tree.
    """

    def __init__(
        self,
        model: mujoco.MjModel,
        qpos: FloatArray,
        joint_ids: Sequence[int],
        margin: float = 0.0,
        self_only: bool = False,
    ) -> None:
        self._source = model
        self._copy: tuple[mujoco.MjModel, mujoco.MjData] | None = None
        self._flags = int(model.opt.disableflags)  # the copy's, whenever it is made
        self.qpos = np.array(qpos, dtype=np.float64)
        self.qadr = [int(model.jnt_qposadr[j]) for j in joint_ids]
        self.moved_by = movers(model, joint_ids)
        self.tree = arm_tree(model, joint_ids) if self_only else None
        self.clearance = margin
        self.possible = self._possible()

    def _copied(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """The copy of the model collision detection runs on (margins raised,
        gaps zero) and its data, made at the first check: a check that finds
        no possible contact (:attr:`possible`) costs no copy (the Panda's:
        0.5 ms)."""
        if self._copy is None:
            import copy

            m = copy.deepcopy(self._source)
            m.geom_margin[:] = np.maximum(m.geom_margin, self.clearance)
            m.geom_gap[:] = 0.0
            m.opt.disableflags = self._flags
            self._copy = (m, mujoco.MjData(m))
        return self._copy

    def _possible(self) -> bool:
        """Whether any two geoms that the arm moves relative to each other can
        collide (read from the model given: the copy differs in margins and
        gaps only)."""
        m = self._source
        if self._flags & int(mujoco.mjtDisableBit.mjDSBL_CONTACT):
            return False
        if m.npair > 0:
            return True
        ct, ca = m.geom_contype, m.geom_conaffinity
        geoms = [
            g
            for g in range(m.ngeom)
            if (ct[g] or ca[g]) and (self.tree is None or int(m.geom_bodyid[g]) in self.tree)
        ]
        groups: dict[frozenset[int], list[int]] = {}
        for g in geoms:
            groups.setdefault(self.moved_by[int(m.geom_bodyid[g])], []).append(g)
        keys = list(groups)
        for i, a in enumerate(keys):
            for b in keys[i + 1 :]:
                for ga in groups[a]:
                    if any((ct[ga] & ca[gb]) or (ct[gb] & ca[ga]) for gb in groups[b]):
                        return True
        return False

    def at(self, q: FloatArray) -> list[tuple[str, str, float]]:
        """The contacts at the arm's posture ``q`` (rad)."""
        if not self.possible:
            return []
        m, d = self._copied()
        d.qpos[:] = self.qpos
        d.qpos[self.qadr] = q
        mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)
        return moving_contacts(m, d, self.moved_by, self.tree, self.clearance)


def pairs(found: Iterable[tuple[str, str, float]]) -> str:
    """Contacts as "'a'–'b', 'c'–'d'" (each pair once, in order of first sight)."""
    seen: dict[tuple[str, str], None] = {}
    for a, b, _ in found:
        seen.setdefault((a, b), None)
    return ", ".join(f"{a!r}–{b!r}" for a, b in seen)


# Contacts watched during a run.
# ---------------------------------------------------------------------------

WATCH = "adaptimp_watch"
"""The name prefix of the contact sensors :func:`watch_contacts` adds."""

WATCH_MAX = 400
"""The most (arm body, other body) pairs watched one by one; beyond, the other
side is watched by the subtree of each child of the world."""

_CONDATA_FOUND_FORCE = (1 << int(mujoco.mjtConDataField.mjCONDATA_FOUND)) | (
    1 << int(mujoco.mjtConDataField.mjCONDATA_FORCE)
)
_NETFORCE = 3  # the contact sensor's reduce="netforce"


def _collidable(m: mujoco.MjModel) -> tuple[dict[int, list[int]], set[tuple[int, int]]]:
    """The geoms of each body that take part in contacts, and the body pairs of
    explicit contact pairs (both orders)."""
    geoms: dict[int, list[int]] = {}
    for g in range(m.ngeom):
        if m.geom_contype[g] or m.geom_conaffinity[g]:
            geoms.setdefault(int(m.geom_bodyid[g]), []).append(g)
    paired: set[tuple[int, int]] = set()
    for p in range(m.npair):
        a, b = (int(m.geom_bodyid[m.pair_geom1[p]]), int(m.geom_bodyid[m.pair_geom2[p]]))
        paired |= {(a, b), (b, a)}
        geoms.setdefault(a, [])
        geoms.setdefault(b, [])
    return geoms, paired


def _excluded(m: mujoco.MjModel) -> set[tuple[int, int]]:
    """Body pairs of the model's ``<exclude>`` elements (both orders)."""
    out: set[tuple[int, int]] = set()
    for s in np.asarray(m.exclude_signature, dtype=np.int64):
        a, b = int(s) >> 16, int(s) & 0xFFFF
        out |= {(a, b), (b, a)}
    return out


def watch_pairs(
    m: mujoco.MjModel,
    joint_ids: Sequence[int],
    surface: Iterable[tuple[str, str]] = (),
) -> list[tuple[int, int, bool]]:
    """The contacts a run watches (SPEC §18.10): each body the arm's joints
    move that has collision geometry, against each body outside the arm's own
    body tree that can touch it by the model's filters (contype/conaffinity,
    explicit pairs, excludes; the world's own geoms too), as (arm body, other
    body, other is a subtree). ``surface``: (arm body, other body) names of
    the task's own contact (a tool on its table), left out. Beyond
    :data:`WATCH_MAX` pairs the other side is each child of the world's
    subtree. The arm touching itself is the run's other check (it depends on
    the arm's posture alone)."""
    geoms, paired = _collidable(m)
    excluded = _excluded(m)
    moved = movers(m, joint_ids)
    tree = arm_tree(m, joint_ids)
    skip = set()
    for a, b in surface:
        ia, ib = (mujoco.mj_name2id(m, OBJ.mjOBJ_BODY, n) for n in (a, b))
        skip |= {(ia, ib), (ib, ia)}
    ct, ca = m.geom_contype, m.geom_conaffinity

    def meet(a: int, b: int) -> bool:
        if (a, b) in skip or (a, b) in excluded:
            return False
        if (a, b) in paired:
            return True
        return any((ct[x] & ca[y]) or (ct[y] & ca[x]) for x in geoms[a] for y in geoms[b])

    arm = [b for b in sorted(geoms) if moved[b] and b in tree]
    others = [b for b in sorted(geoms) if b not in tree]
    pairs = [(a, o, False) for a in arm for o in others if meet(a, o)]
    if len(pairs) <= WATCH_MAX:
        return pairs
    roots: dict[int, list[int]] = {}
    for o in others:
        roots.setdefault(root_body(m, o) if o > 0 else 0, []).append(o)
    return [
        (a, r, r > 0)
        for a in arm
        for r, members in roots.items()
        if any(meet(a, o) for o in members)
    ]


def watch_contacts(
    spec: Any,
    m: mujoco.MjModel,
    joint_ids: Sequence[int],
    surface: Iterable[tuple[str, str]] = (),
) -> int:
    """Add to ``spec`` (compiled as ``m``) a contact sensor for each pair of
    :func:`watch_pairs` (the number of contacts found and their net force, N)
    and three ``userdata`` values each, where the run's loop keeps the periods
    in contact, the peak force and its row (SPEC §18.10). A sensor reads and
    changes nothing of the dynamics. Returns the number of sensors."""
    pairs = watch_pairs(m, joint_ids, surface)
    for i, (a, o, subtree) in enumerate(pairs):
        spec.add_sensor(
            name=f"{WATCH}{i}",
            type=mujoco.mjtSensor.mjSENS_CONTACT,
            objtype=OBJ.mjOBJ_BODY,
            objname=obj_name(m, OBJ.mjOBJ_BODY, a),
            reftype=OBJ.mjOBJ_XBODY if subtree else OBJ.mjOBJ_BODY,
            refname="world" if o == 0 else obj_name(m, OBJ.mjOBJ_BODY, o),
            intprm=[_CONDATA_FOUND_FORCE, _NETFORCE, 1],
        )
    spec.nuserdata = int(spec.nuserdata) + 3 * len(pairs)
    return len(pairs)


@dataclass(frozen=True)
class Watch:
    """The watched contacts of a compiled model (its sensors named
    :data:`WATCH`…): each sensor's ``sensordata`` address, its two bodies'
    names and where their three ``userdata`` values start."""

    adr: list[int]
    pairs: list[tuple[str, str]]
    out: int

    @staticmethod
    def of(m: mujoco.MjModel) -> Watch | None:
        ids = [
            s
            for s in range(m.nsensor)
            if (mujoco.mj_id2name(m, OBJ.mjOBJ_SENSOR, s) or "").startswith(WATCH)
            and int(m.sensor_type[s]) == int(mujoco.mjtSensor.mjSENS_CONTACT)
        ]
        if not ids or m.nuserdata < 3 * len(ids):
            return None
        return Watch(
            adr=[int(m.sensor_adr[s]) for s in ids],
            pairs=[
                (
                    obj_name(m, OBJ.mjOBJ_BODY, int(m.sensor_objid[s])),
                    obj_name(m, OBJ.mjOBJ_BODY, int(m.sensor_refid[s])),
                )
                for s in ids
            ],
            out=int(m.nuserdata) - 3 * len(ids),
        )

    def clear(self, d: mujoco.MjData) -> None:
        """Forget what a run found (before the next)."""
        d.userdata[self.out : self.out + 3 * len(self.adr)] = 0.0

    def found(self, d: mujoco.MjData) -> list[tuple[str, str, int, float, int]]:
        """What the last run found: (arm body, other body, periods in contact,
        peak force in N, its row), for each pair that touched."""
        v = np.asarray(d.userdata[self.out : self.out + 3 * len(self.adr)]).reshape(-1, 3)
        return [
            (a, b, int(c), float(f), int(r)) for (a, b), (c, f, r) in zip(self.pairs, v) if c > 0
        ]
