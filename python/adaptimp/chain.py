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
from pathlib import Path
from typing import Any, cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._errors import ConfigError, no_file

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
        if names is not None and (isinstance(names, str) or len(names) != len(movable)):
            raise ConfigError(
                f"{source}: names must give one name per movable joint ({len(movable)}), "
                f"got {names!r}"
            )
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
        default the plant's end effector (:class:`adaptimp.mujoco.Plant`), the
        core's rule (SPEC (21.2)): the site of a force sensor that a hinge of
        the arm moves, else the first site on the last arm joint's body, else
        that body. The chain's joints are the arm's
        (the core's one reduction, SPEC §21: the hinges and slides on the way
        to the tip that it does not hold, a gripper's coupled joints and those
        named in ``fix``); any other joint on the way is held at its
        ``qpos0``, as the plant locks it. Without ``tip``, the joints the
        plant's rule holds on the way to its end effector (a slide off a
        revolute arm) are held too: the chain and the plant drive the same
        joints. From each body's ``body_pos``,
        ``body_quat``, each arm joint's ``jnt_pos`` (its anchor), ``jnt_axis``
        and ``qpos0`` (the value at which the body has its model frame), the
        site's ``site_pos``,
        ``site_quat``. q is the arm's joint positions base to tip
        (``joint_names``); pose and Jacobian equal MuJoCo's (``mj_jacSite``,
        ``mj_jacBody`` on those joints' columns) to rounding.

        Errors (``ValueError``) for a file MuJoCo cannot load, an unknown tip
        or ``fix`` joint, a free or ball joint on the way, more than 7 joints.
        """
        import mujoco

        from . import _mjcf
        from ._description import _fix

        if site is not None and tip is not None:
            raise ConfigError("give the end effector as tip= (a site or a body) or site=, not both")
        tip = site if tip is None else tip
        fix = _fix(fix)  # a name alone was iterated: "j1" as ('j', '1')
        if not isinstance(model, (mujoco.MjModel, str, os.PathLike)):
            raise TypeError(
                "model must be a mujoco.MjModel or the path of an MJCF or URDF file, got "
                f"{type(model).__name__} {model!r:.40}"
            )
        if not isinstance(model, mujoco.MjModel):
            path = Path(model)
            if not path.is_file():
                raise no_file("model must be an MjModel or the path of an MJCF or URDF file", path)
            if path.suffix.lower() in (".urdf", ".xacro"):
                if tip is not None and not isinstance(tip, str):
                    raise ConfigError(f"the tip of a URDF is a link's name, got {tip!r}")
                # The same reader and reduction as the MuJoCo model
                # adaptimp.mujoco.from_urdf compiles from it (SPEC §21).
                return cls.from_urdf(path, tip, fix=fix)
            from ._description import fragment_error, kind_of

            if kind_of(path) == "mjcf-fragment":
                raise fragment_error(path)
            try:
                model = mujoco.MjModel.from_xml_path(str(path))
            except ValueError as e:
                raise ConfigError(f"MuJoCo cannot load {str(path)!r}: {e}") from None
        found: dict[str, Any] | None = None
        try:
            if isinstance(tip, bool) or not isinstance(tip, (str, int, np.integer, type(None))):
                raise TypeError(f"tip must be a site's or body's name or a site id, got {tip!r}")
            if isinstance(tip, (int, np.integer)):
                sid = int(tip)
                if not 0 <= sid < model.nsite:
                    raise ConfigError(f"the MuJoCo model has no site {sid} ({model.nsite} sites)")
                body = int(model.site_bodyid[sid])
            elif tip is None:
                found = _mjcf.arm_of(model, None, tuple(fix))
                sid, body = _mjcf.end_effector(model, found["tip"])
            else:
                sid, body = _mjcf.end_effector(model, str(tip))
        except ValueError as e:
            raise ConfigError(str(e)) from None
        # The chain to that site or body by the core's one reduction (SPEC
        # §21): the path's hinges and slides, but for the joints it holds (a
        # gripper's linkage, those named in fix) at their reference.
        from ._description import read_arm

        if sid >= 0:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, sid) or f"site#{sid}"
            label = f"site {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, sid) or sid!r}"
        else:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or f"body#{body}"
            label = f"body {mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, body) or body!r}"
        arm = read_arm(model, name, fix)
        if found is not None and arm.joints != tuple(found["joints"]):
            # The default tip is the end of the arm the rule finds (the
            # plant's): the joints it holds on the way there (a slide, a
            # rail) are held here too, for their reason, so the chain and
            # the plant count the same joints.
            extra = [j for j in arm.joints if j not in found["joints"]]
            arm = read_arm(model, name, (*fix, *extra))
            arm.fixed.update({j: found["fixed"][j] for j in extra if j in found["fixed"]})
        if arm.n > 7:
            raise ConfigError(
                f"{arm.source}: the chain to {name!r} has {arm.n} joints "
                f"({', '.join(arm.joints)}); a chain has at most 7: hold some with fix=(...)"
            )
        chain = cls(arm.chain, arm.tip_origin, names=arm.joints, source=f"MuJoCo model to {label}")
        chain.fixed = dict(arm.fixed)
        return chain

    def pose(self, q: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """The tip's position (m), (3,), and rotation (world ← tip), (3, 3), at q."""
        t = self.fk(q)
        return t[:3, 3].copy(), t[:3, :3].copy()

    def __repr__(self) -> str:
        return f"adaptimp.Chain({self.source}: {self.n} joints {self.joint_names})"
