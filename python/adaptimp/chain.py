"""Serial-chain kinematics of any arm (SPEC §16): :class:`Chain`.

A chain is the path of joints from a robot's root to its tip: each joint's
fixed origin transform, its kind (revolute, prismatic, fixed) and axis. This
module only *reads* that joint data, from a URDF file (with the standard
library's XML parser) or a MuJoCo model, and hands it to the compiled core,
which folds the fixed joints, validates everything and computes the tip's
pose, its 6 × n geometric Jacobian and J̇ q̇ in one pass (no NumPy copy of
the kinematics).

Conventions: world frame = the URDF's root link (MuJoCo's world body);
the Jacobian is ``[J_v; J_ω]``, world-aligned, at the tip origin (Pinocchio's
``LOCAL_WORLD_ALIGNED``); J̇ q̇ is the tip's classical acceleration at q̈ = 0.
Units: m, rad, m/s, rad/s.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._errors import ConfigError

__all__ = ["Chain"]

FloatArray = NDArray[np.float64]

_MOVABLE = {"revolute": "revolute", "continuous": "revolute", "prismatic": "prismatic"}


@dataclass(frozen=True)
class _UrdfJoint:
    name: str
    kind: str
    parent: str
    child: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float]


def _triple(text: str | None, what: str, default: tuple[float, float, float]) -> Any:
    if text is None:
        return default
    try:
        values = tuple(float(x) for x in text.split())
    except ValueError:
        raise ConfigError(f"{what} must be three numbers, got {text!r}") from None
    if len(values) != 3:
        raise ConfigError(f"{what} must be three numbers, got {text!r}")
    return values


def _read_urdf(source: str | os.PathLike[str]) -> tuple[set[str], dict[str, _UrdfJoint]]:
    """The links and the joints (by child link) of a URDF; errors for a missing
    link, a link with two parents and a loop."""
    try:
        root = ET.parse(source).getroot()
    except (ET.ParseError, OSError) as e:
        raise ConfigError(f"cannot read the URDF {str(source)!r}: {e}") from None
    if root.tag != "robot":
        raise ConfigError(f"{str(source)!r} is not a URDF: its root element is <{root.tag}>")
    links = {link.get("name", "") for link in root.findall("link")}
    by_child: dict[str, _UrdfJoint] = {}
    for j in root.findall("joint"):
        name = j.get("name", "")
        parent, child = j.find("parent"), j.find("child")
        p = "" if parent is None else parent.get("link", "")
        c = "" if child is None else child.get("link", "")
        for role, link in (("parent", p), ("child", c)):
            if link not in links:
                raise ConfigError(
                    f"URDF joint {name!r} names the {role} link {link!r}, which the URDF "
                    "does not declare (a missing link)"
                )
        if c in by_child:
            raise ConfigError(
                f"URDF link {c!r} is the child of two joints ({by_child[c].name!r} and "
                f"{name!r}): a kinematic loop, which a serial chain cannot describe"
            )
        origin = j.find("origin")
        axis = j.find("axis")
        by_child[c] = _UrdfJoint(
            name=name,
            kind=j.get("type", ""),
            parent=p,
            child=c,
            xyz=_triple(
                None if origin is None else origin.get("xyz"), f"{name} origin xyz", (0.0,) * 3
            ),
            rpy=_triple(
                None if origin is None else origin.get("rpy"), f"{name} origin rpy", (0.0,) * 3
            ),
            axis=_triple(
                None if axis is None else axis.get("xyz"), f"{name} axis", (1.0, 0.0, 0.0)
            ),
        )
    # Every link's way up must end at a root, not run in a circle.
    for start in by_child:
        seen = {start}
        link = start
        while link in by_child:
            link = by_child[link].parent
            if link in seen:
                raise ConfigError(
                    f"URDF joints form a loop through the link {link!r}: "
                    "a serial chain cannot describe it"
                )
            seen.add(link)
    return links, by_child


def _default_tip(links: set[str], by_child: dict[str, _UrdfJoint]) -> str:
    """The deepest link of the single chain of movable joints from the root."""
    children: dict[str, list[_UrdfJoint]] = {}
    for j in by_child.values():
        children.setdefault(j.parent, []).append(j)
    roots = sorted(links - set(by_child))
    if len(roots) != 1:
        raise ConfigError(
            f"the URDF has {len(roots)} root links {roots}: give tip= (the chain's last link)"
        )

    def movable_below(link: str) -> bool:
        return any(j.kind in _MOVABLE or movable_below(j.child) for j in children.get(link, []))

    link, tip = roots[0], None
    while True:
        branches = [
            j for j in children.get(link, []) if j.kind in _MOVABLE or movable_below(j.child)
        ]
        if not branches:
            break
        if len(branches) > 1:
            names = ", ".join(repr(j.name) for j in branches)
            raise ConfigError(
                f"the movable joints branch at the link {link!r} ({names}): give tip= "
                "(the link that ends the chain)"
            )
        link = branches[0].child
        if branches[0].kind in _MOVABLE:
            tip = link
    if tip is None:
        raise ConfigError("the URDF has no movable joint (revolute, continuous or prismatic)")
    return tip


class Chain(_adaptimp.Chain):
    """The kinematics of a serial chain of n = 1 … 7 revolute or prismatic joints
    and a tip, computed by the compiled core (SPEC §16).

    Build it with :meth:`from_urdf`, :meth:`from_mujoco`, or from joint data:
    ``Chain(joints, tip=None)`` with ``joints`` a list of dicts (base to tip),
    each with ``"kind"`` (``"fixed"``, ``"revolute"``, ``"prismatic"``), the
    origin (the parent joint's frame → this joint's frame) as ``"xyz"`` and
    ``"rpy"`` (m, rad; URDF), ``"pos"`` and ``"quat"`` ([w, x, y, z]; MuJoCo) or
    ``"translation"`` and ``"rotation"`` (3 × 3), an ``"axis"`` (3,) in that
    frame and an ``"offset"`` (the joint value at which the frame is its
    origin, default 0); ``tip`` a dict of the same origin keys. A zero axis, a
    rotation that is not one, more than 7 movable joints are ``ValueError``\\ s
    naming the joint.

    Attributes
    ----------
    n : int
        Movable joints, base to tip: q has n entries (rad, or m for prismatic).
    joint_names : list of str
        Their names (from the URDF or the MuJoCo model), in the order of q.
    prismatic : list of bool
        Which are prismatic.

    Methods (the core's): ``fk(q) -> (4, 4)`` the homogeneous pose of the tip
    (world ← tip; m); ``jacobian(q) -> (6, n)`` the geometric Jacobian
    [J_v; J_ω] (world-aligned, at the tip origin); ``jdot_qdot(q, dq) -> (6,)``
    J̇ q̇ [m/s²; rad/s²] (the classical acceleration of the tip at q̈ = 0).

    Examples
    --------
    >>> import adaptimp
    >>> arm = adaptimp.Chain(
    ...     [
    ...         {"kind": "revolute", "axis": [0, 0, 1]},
    ...         {"kind": "revolute", "xyz": [0.3, 0, 0], "axis": [0, 0, 1]},
    ...     ],
    ...     tip={"xyz": [0.2, 0, 0]},
    ... )
    >>> arm.fk([0.0, 0.0])[:3, 3].tolist()
    [0.5, 0.0, 0.0]
    """

    joint_names: list[str]
    source: str

    def __new__(
        cls,
        joints: Sequence[Mapping[str, Any]],
        tip: Mapping[str, Any] | None = None,
        *,
        names: Sequence[str] | None = None,
        source: str = "joints",
    ) -> Chain:
        data = [dict(j) for j in joints]
        try:
            self = cast(Chain, super().__new__(cls, data, None if tip is None else dict(tip)))
        except ValueError as e:
            raise ConfigError(f"{source}: {e}") from None
        movable = [j for j in data if j.get("kind") != "fixed"]
        self.joint_names = (
            list(names) if names is not None else [f"joint{i}" for i in range(len(movable))]
        )
        self.source = source
        return self

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        """Everything happens in ``__new__`` (the compiled core is immutable)."""

    @classmethod
    def from_urdf(cls, path: str | os.PathLike[str], tip: str | None = None) -> Chain:
        """The chain from the root link of the URDF at ``path`` to the link ``tip``
        (default: the deepest link of the single chain of movable joints).

        Fixed joints on the way fold into the next origin; ``continuous`` joints
        are revolute; a ``<mimic>`` joint counts as an independent joint (as
        Pinocchio loads it). Errors (``ValueError``) for a URDF that cannot be
        read, a joint naming a missing link, a kinematic loop, branching movable
        joints when ``tip`` is not given, an unknown ``tip``, a joint of another
        kind (``floating``, ``planar``) on the path, more than 7 movable joints.
        """
        links, by_child = _read_urdf(path)
        if tip is None:
            tip = _default_tip(links, by_child)
        elif tip not in links:
            raise ConfigError(f"the URDF {str(path)!r} has no link named {tip!r}")
        path_joints: list[_UrdfJoint] = []
        link = tip
        while link in by_child:
            path_joints.append(by_child[link])
            link = by_child[link].parent
        path_joints.reverse()
        joints: list[dict[str, Any]] = []
        names: list[str] = []
        for j in path_joints:
            if j.kind == "fixed":
                kind = "fixed"
            elif j.kind in _MOVABLE:
                kind = _MOVABLE[j.kind]
                names.append(j.name)
            else:
                raise ConfigError(
                    f"the URDF joint {j.name!r} on the way to {tip!r} is of type {j.kind!r}: "
                    "a chain has revolute, continuous, prismatic and fixed joints only"
                )
            joints.append({"kind": kind, "xyz": j.xyz, "rpy": j.rpy, "axis": j.axis})
        return cls(joints, None, names=names, source=f"URDF {Path(path).name} to {tip!r}")

    @classmethod
    def from_mujoco(
        cls,
        model: Any,
        tip: str | int | None = None,
        *,
        fix: Sequence[str] = (),
        site: str | int | None = None,
    ) -> Chain:
        """The chain from MuJoCo's world body to the end effector ``tip`` of
        ``model``: a ``mujoco.MjModel``, or the path of an MJCF file (compiled
        as it is, nothing edited) or of a URDF (:func:`adaptimp.mujoco.from_urdf`).

        ``tip`` is a site (its frame) or a body (its frame, the point MuJoCo's
        ``mj_jacBody`` differentiates), by name (a site first if both have
        it), or a site id; ``site=`` is the earlier keyword for a site. By
        default the plant's end effector (:class:`adaptimp.mujoco.Plant`): the
        site of the model's force sensor, or the first site of the last arm
        joint's body, or that body. The chain's joints are the arm's
        (``adaptimp._mjcf.arm_of``: the hinges on the way to the tip that are
        not a gripper's coupled joints, a slide or named in ``fix``); any
        other joint on the way is held at its ``qpos0``, as the plant locks
        it. From each body's ``body_pos``, ``body_quat``, each arm joint's
        ``jnt_pos`` (its anchor), ``jnt_axis`` and ``qpos0`` (the value at
        which the body has its model frame), the site's ``site_pos``,
        ``site_quat``. q is the arm's joint positions base to tip
        (``joint_names``); pose and Jacobian equal MuJoCo's (``mj_jacSite``,
        ``mj_jacBody`` on those joints' columns) to rounding.

        Errors (``ValueError``) for a file MuJoCo cannot load, an unknown tip
        or ``fix`` joint, a free or ball joint on the way, more than 7 joints.
        """
        import mujoco

        from . import _mjcf

        if site is not None and tip is not None:
            raise ConfigError("give the end effector as tip= (a site or a body) or site=, not both")
        tip = site if tip is None else tip
        if not isinstance(model, mujoco.MjModel):
            path = Path(model)
            if not path.is_file():
                raise ConfigError(
                    "model must be an MjModel or the path of an MJCF or URDF file; "
                    f"no file {str(path)!r}"
                )
            if path.suffix.lower() == ".urdf":
                from .mujoco import from_urdf

                model = from_urdf(path, fix=tuple(fix), tip=tip if isinstance(tip, str) else None)
                fix = ()
            else:
                try:
                    model = mujoco.MjModel.from_xml_path(str(path))
                except ValueError as e:
                    raise ConfigError(f"MuJoCo cannot load {str(path)!r}: {e}") from None
        try:
            if isinstance(tip, bool) or not isinstance(tip, (str, int, np.integer, type(None))):
                raise TypeError(f"tip must be a site's or body's name or a site id, got {tip!r}")
            if isinstance(tip, (int, np.integer)):
                sid = int(tip)
                if not 0 <= sid < model.nsite:
                    raise ConfigError(f"the MuJoCo model has no site {sid} ({model.nsite} sites)")
                body = int(model.site_bodyid[sid])
            elif tip is None:
                arm = _mjcf.arm_of(model, None, tuple(fix))
                last = int(model.jnt_bodyid[arm["joint_ids"][-1]])
                sid, body = _mjcf.end_effector(model, None, last)
            else:
                sid, body = _mjcf.end_effector(model, str(tip), 0)
        except ValueError as e:
            raise ConfigError(str(e)) from None
        # The path's hinges and slides, but for joints another one dictates (a
        # gripper's linkage) and those named in fix.
        held = set(_mjcf.coupled_joints(model)) | {
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, f) for f in fix
        }
        bodies: list[int] = []
        b = body
        while b != 0:
            bodies.append(b)
            b = int(model.body_parentid[b])
        bodies.reverse()
        kinds = {
            int(mujoco.mjtJoint.mjJNT_HINGE): "revolute",
            int(mujoco.mjtJoint.mjJNT_SLIDE): "prismatic",
        }
        joints: list[dict[str, Any]] = []
        names: list[str] = []
        for b in bodies:
            joints.append(
                {
                    "kind": "fixed",
                    "pos": model.body_pos[b].tolist(),
                    "quat": model.body_quat[b].tolist(),
                }
            )
            first = int(model.body_jntadr[b])
            for j in range(first, first + int(model.body_jntnum[b])):
                name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}"
                kind = kinds.get(int(model.jnt_type[j]))
                if kind is None:
                    raise ConfigError(
                        f"the MuJoCo joint {name!r} on the way to the tip is free or ball: "
                        "a chain has hinge and slide joints only"
                    )
                if j in held:
                    continue  # held at qpos0: the body at its model frame
                anchor = model.jnt_pos[j].tolist()
                joints.append(
                    {
                        "kind": kind,
                        "pos": anchor,
                        "axis": model.jnt_axis[j].tolist(),
                        "offset": float(model.qpos0[model.jnt_qposadr[j]]),
                    }
                )
                joints.append({"kind": "fixed", "pos": [-x for x in anchor]})
                names.append(name)
        if sid >= 0:
            end = {"pos": model.site_pos[sid].tolist(), "quat": model.site_quat[sid].tolist()}
            label = f"site {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, sid) or sid!r}"
        else:
            end = None
            label = f"body {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or body!r}"
        return cls(joints, end, names=names, source=f"MuJoCo model to {label}")

    def pose(self, q: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """The tip's position (m), (3,), and rotation (world ← tip), (3, 3), at q."""
        t = self.fk(q)
        return t[:3, 3].copy(), t[:3, :3].copy()

    def __repr__(self) -> str:
        return f"adaptimp.Chain({self.source}: {self.n} joints {self.joint_names})"
