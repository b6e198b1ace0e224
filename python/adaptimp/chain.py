"""Serial-chain kinematics of any arm (SPEC §16): :class:`Chain`.

A chain is the path of joints from a robot's root to its tip: each joint's
fixed origin transform, its kind (revolute, prismatic, fixed) and axis. The
compiled core reads a URDF (SPEC §21: the one reduction that also builds
adaptimp's MuJoCo plants and computed-torque models), folds the fixed
joints, validates everything and computes the tip's pose, its 6 × n
geometric Jacobian and J̇ q̇ in one pass (no NumPy copy of the
kinematics); this module passes a MuJoCo model's joint data to it.

Conventions: world frame = the URDF's root link (MuJoCo's world body);
the Jacobian is ``[J_v; J_ω]``, world-aligned, at the tip origin (Pinocchio's
``LOCAL_WORLD_ALIGNED``); J̇ q̇ is the tip's classical acceleration at q̈ = 0.
Units: m, rad, m/s, rad/s.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._errors import ConfigError

__all__ = ["Chain"]

FloatArray = NDArray[np.float64]


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
    fixed : dict
        The description's other joints held by the reduction, and why
        (:meth:`from_urdf`; empty otherwise).
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
    fixed: dict[str, str]

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
        self.fixed = {}
        return self

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        """Everything happens in ``__new__`` (the compiled core is immutable)."""

    @classmethod
    def from_urdf(
        cls,
        path: str | os.PathLike[str],
        tip: str | None = None,
        *,
        fix: Sequence[str] = (),
    ) -> Chain:
        """The chain of the arm of the URDF (or xacro) at ``path``, read by the
        core's one reduction (SPEC §21): to the link ``tip`` (the revolute,
        continuous and prismatic joints on the way are the chain's), or, by
        default, the arm the rule finds (the longest chain of revolute
        joints, ending at a hand or a gripper) to its last joint's link.

        Fixed joints on the way fold into the next origin; ``continuous``
        joints are revolute; a ``<mimic>`` joint and the joints named in
        ``fix`` are held at their zero value (``chain.fixed`` says why).
        Errors (``ValueError`` naming the file and the element) for a URDF
        that cannot be read, a joint naming a missing link, a kinematic
        loop, chains that tie for the arm when ``tip`` is not given, an
        unknown ``tip``, a floating or planar joint on the path, more than 7
        joints (hold some with ``fix``).
        """
        from ._description import read_arm

        arm = read_arm(path, tip, fix)
        if arm.n > 7:
            raise ConfigError(
                f"{arm.source}: the chain to {arm.tip!r} has {arm.n} joints "
                f"({', '.join(arm.joints)}); a chain has at most 7: hold some with fix=(...)"
            )
        chain = cls(
            arm.chain,
            arm.tip_origin,
            names=arm.joints,
            source=f"{arm.source} to {arm.tip!r}",
        )
        chain.fixed = dict(arm.fixed)
        return chain

    @classmethod
    def from_mujoco(cls, model: Any, site: str | int) -> Chain:
        """The chain from MuJoCo's world body to the site ``site`` (name or id)
        of the ``mujoco.MjModel`` ``model``: each body's ``body_pos``,
        ``body_quat``, each hinge or slide joint's ``jnt_pos`` (its anchor),
        ``jnt_axis`` and ``qpos0`` (the value at which the body has its model
        frame), the site's ``site_pos``, ``site_quat``. q is the path's joint
        positions in ``qpos`` order along the chain (``joint_names``).

        Errors (``ValueError``) for an unknown site, a free or ball joint on
        the path, more than 7 joints.
        """
        import mujoco

        if isinstance(site, str):
            sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, site)
            if sid < 0:
                raise ConfigError(f"the MuJoCo model has no site named {site!r}")
        else:
            sid = int(site)
            if not 0 <= sid < model.nsite:
                raise ConfigError(f"the MuJoCo model has no site {sid} ({model.nsite} sites)")
        bodies: list[int] = []
        b = int(model.site_bodyid[sid])
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
                kind = kinds.get(int(model.jnt_type[j]))
                name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint{j}"
                if kind is None:
                    raise ConfigError(
                        f"the MuJoCo joint {name!r} on the way to the site is free or ball: "
                        "a chain has hinge and slide joints only"
                    )
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
        tip = {"pos": model.site_pos[sid].tolist(), "quat": model.site_quat[sid].tolist()}
        label = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, sid) or str(sid)
        return cls(joints, tip, names=names, source=f"MuJoCo model to site {label!r}")

    def pose(self, q: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """The tip's position (m), (3,), and rotation (world ← tip), (3, 3), at q."""
        t = self.fk(q)
        return t[:3, 3].copy(), t[:3, :3].copy()

    def __repr__(self) -> str:
        return f"adaptimp.Chain({self.source}: {self.n} joints {self.joint_names})"
