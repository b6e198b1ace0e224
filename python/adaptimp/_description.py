"""Robot descriptions, read once, by the core (SPEC §21): :func:`read_arm`.

A URDF (a path or its text) is read by the compiled core; a ``.xacro`` file
(or a URDF with xacro markup) is expanded first by the PyPI package
``xacro`` (the extra ``xacro``) or refused with the command that expands
it; an MJCF file is compiled by MuJoCo, and the compiled model's arrays
(:func:`mujoco_arrays`) go to the core. Either way one tree, one reduction:
which chain, which joints are the arm's, the tip, what is held fixed and
why. This module parses no XML.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from . import _adaptimp
from ._errors import ConfigError, PlantWarning, XacroError

__all__ = ["Arm", "mujoco_arrays", "read_arm"]


@dataclass(frozen=True)
class Arm:
    """The arm of a robot description, as the core's one reduction finds it
    (SPEC (21.2)).

    Attributes
    ----------
    source : str
        What it was read from (for messages).
    joints : tuple of str
        The arm's joints, base to tip (the order of q).
    prismatic : tuple of bool
        Which are prismatic (m, N) rather than revolute (rad, N m).
    lower, upper : tuple of float
        Position limits (rad or m); ∓inf for an unlimited joint.
    effort : tuple of float
        The drive's largest torque (N m) or force (N); NaN where the
        description states none.
    velocity : tuple of float
        The largest speed (rad/s or m/s); NaN where none is stated.
    armature, damping, friction : tuple of float
        Drive terms: rotor inertia (kg m²), viscous damping (N m s/rad), dry
        friction loss (N m), 0 where none is stated.
    chain : list of dict
        The joint dicts :class:`adaptimp.Chain` takes (the arm's joints, the
        fixed ones before each folded into its origin).
    tip_origin : dict
        The last joint's frame → the tip (``translation``, ``rotation``).
    inertials : list of dict
        Per joint, the body it moves (its link and everything fixed to it):
        ``mass`` (kg), the centre of mass ``translation`` (m) in the joint's
        frame, ``inertia`` about it (kg m², 3 × 3).
    lifted : list of dict
        Per joint, what gravity compensation lifts of its body (MuJoCo's
        ``gravcomp``; zeros for a URDF): ``mass`` (kg, gravcomp × mass summed
        over its links) and its first ``moment`` (kg m, gravcomp × mass ×
        centre summed, in the joint's frame; SPEC (20.1')).
    warnings : tuple of str
        The description's mistakes the arm does not depend on, held (a mimic
        joint off the arm whose master is not a joint of it): warned as
        :class:`adaptimp.PlantWarning` when the arm is read.
    inertia_error : str or None
        The first link the arm moves whose inertia no rigid body has (not
        positive semi-definite), named with the file: a model of the arm's
        dynamics is refused with it (its kinematics reads).
    base, tip : str
        The root link, and the link (or frame, MuJoCo site) that ends the arm.
    tip_is_frame : bool
        Whether ``tip`` names a frame (a site) rather than a link (a body).
    fixed : dict
        Every other joint with a coordinate and why it is held.
    held : dict
        The value each of those is held at (rad or m).
    urdf : str or None
        For a URDF: the reduced URDF for MuJoCo's compiler (inertials only,
        held joints fixed, the arm's joints with their limits).
    urdf_drive : str or None
        The same with the arm joints' ``<dynamics damping friction>``.
    gravity : tuple of float
        Gravity in the base frame (m/s²): the MuJoCo model's, or standard
        gravity along −z for a URDF.
    joint_ids : tuple of int
        For a MuJoCo model: the arm's joints' ids in it (empty otherwise).
    balanced : tuple of str
        The links whose inertia breaks the triangle inequality (A + B ≥ C of
        its principal moments) and which the reader balanced (the moments
        set to their mean, SPEC (21.4)): the plant, the chain, computed
        torque and Pinocchio's model all have the balanced one.
    """

    source: str
    joints: tuple[str, ...]
    prismatic: tuple[bool, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    effort: tuple[float, ...]
    velocity: tuple[float, ...]
    armature: tuple[float, ...]
    damping: tuple[float, ...]
    friction: tuple[float, ...]
    chain: list[dict[str, Any]]
    tip_origin: dict[str, Any]
    inertials: list[dict[str, Any]]
    base: str
    tip: str
    tip_is_frame: bool
    fixed: dict[str, str]
    held: dict[str, float]
    urdf: str | None
    urdf_drive: str | None
    gravity: tuple[float, float, float] = (0.0, 0.0, -9.81)
    joint_ids: tuple[int, ...] = ()
    balanced: tuple[str, ...] = ()
    lifted: list[dict[str, Any]] = field(default_factory=list)
    inertia_error: str | None = None
    warnings: tuple[str, ...] = ()

    @property
    def n(self) -> int:
        """The number of arm joints."""
        return len(self.joints)

    @property
    def has_drive(self) -> bool:
        """Whether the description states armature, damping or friction loss."""
        return any(x != 0.0 for x in (*self.armature, *self.damping, *self.friction))

    @property
    def tip_kind(self) -> str:
        """``"frame"`` if the tip is a frame (a MuJoCo site), else ``"link"`` (a body)."""
        return "frame" if self.tip_is_frame else "link"

    @classmethod
    def _of(cls, d: dict[str, Any], **extra: Any) -> Arm:
        tuples = (
            "joints",
            "prismatic",
            "lower",
            "upper",
            "effort",
            "velocity",
            "armature",
            "damping",
            "friction",
            "balanced",
            "warnings",
        )
        fields: dict[str, Any] = {k: tuple(v) if k in tuples else v for k, v in d.items()}
        arm = cls(**fields, **extra)
        for text in arm.warnings:
            warnings.warn(text, PlantWarning, stacklevel=4)
        return arm


_BALANCED_SAID: set[tuple[str, tuple[str, ...]]] = set()


def say_balanced(arm: Arm, stacklevel: int = 4) -> None:
    """The reader's balancing of ``arm``'s inertias (SPEC (21.4)), said once
    per file and links in a process by the fronts that build its dynamics
    (the plant, computed torque): they read the same balanced inertia, one
    model, one warning. A chain (kinematics) has no inertia to speak of."""
    key = (arm.source, arm.balanced)
    if not arm.balanced or key in _BALANCED_SAID:
        return
    _BALANCED_SAID.add(key)
    import warnings

    from ._errors import PlantWarning

    warnings.warn(
        f"{arm.source}: the inertia of {list(arm.balanced)} breaks the triangle inequality "
        "(A + B ≥ C of its principal moments, which every rigid body meets): the reader "
        "balances it (the moments set to their mean, about the same centre of mass), for "
        "the plant, the chain and computed torque alike (SPEC (21.4))",
        PlantWarning,
        stacklevel=stacklevel,
    )


def _fix(fix: object) -> tuple[str, ...]:
    if isinstance(fix, str) or not isinstance(fix, (tuple, list)):
        raise ConfigError(f"fix must be a tuple of joint names, got {fix!r}")
    if not all(isinstance(j, str) for j in fix):
        raise ConfigError(f"fix must be a tuple of joint names, got {fix!r}")
    return tuple(fix)


class _NoPackage(ConfigError):
    """A ``$(find PKG)`` that names no directory (raised inside xacro)."""


def _find_package(start: Path) -> Any:
    """``$(find PKG)`` for xacro without ROS: the directory PKG in a folder of
    ``$ROS_PACKAGE_PATH``, or in (or one level below) the nearest ancestor of
    ``start`` that holds one."""

    def find(pkg: str) -> str:
        roots = [Path(p) for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]
        for folder in (*roots, start, *start.parents):
            for candidate in (folder / pkg, *sorted(folder.glob(f"*/{pkg}"))):
                if candidate.is_dir():
                    return str(candidate)
        raise _NoPackage(
            f"xacro asks for $(find {pkg}), and no directory {pkg!r} lies beside {str(start)!r}, "
            "in one of its parents or in $ROS_PACKAGE_PATH: add the package's parent folder to "
            "ROS_PACKAGE_PATH, or expand the file where ROS finds it (xacro FILE -o robot.urdf)"
        )

    return find


@contextmanager
def _packages(start: Path) -> Iterator[None]:
    from xacro import substitution_args

    try:
        import ament_index_python  # noqa: F401

        yield
        return
    except ImportError:
        pass
    saved = substitution_args._eval_find
    substitution_args._eval_find = _find_package(start)
    try:
        yield
    finally:
        substitution_args._eval_find = saved


def expand_xacro(path: str | os.PathLike[str]) -> str:
    """The URDF text of the xacro file at ``path`` (the extra ``xacro``);
    ``$(find PKG)`` without ROS is the directory PKG in ``$ROS_PACKAGE_PATH``
    or beside the file or one of its parents."""
    try:
        import xacro
    except ImportError as e:
        raise XacroError(
            f"{str(path)!r} is xacro: expand it into a URDF with `xacro {path} -o robot.urdf` "
            "(pip install xacro), or install adaptimp's extra that expands it for you: "
            "pip install 'adaptimp[xacro]'"
        ) from e
    p = Path(path).resolve()
    try:
        with _packages(p.parent):
            doc = xacro.process_file(str(p))
    except Exception as e:  # xacro raises its own and Python's exceptions
        inner = getattr(e, "exc", None)
        if isinstance(inner, _NoPackage):
            raise XacroError(f"cannot expand {str(path)!r}: {inner}") from None
        raise XacroError(f"xacro could not expand {str(path)!r}: {e}") from None
    return str(doc.toxml())


def mujoco_arrays(model: Any) -> dict[str, Any]:
    """The arrays of a compiled ``mujoco.MjModel`` that the core builds the
    tree from (SPEC (21.1)): bodies, joints (with each one's qpos0, armature,
    damping and friction loss), sites, actuators and equalities."""
    import mujoco

    obj = mujoco.mjtObj

    def names(kind: Any, count: int) -> list[str]:
        return [mujoco.mj_id2name(model, kind, i) or "" for i in range(count)]

    def flags(a: Any) -> list[bool]:
        return [bool(x) for x in a]

    return {
        "model_name": model_name(model),
        "body_name": names(obj.mjOBJ_BODY, model.nbody),
        "body_parentid": model.body_parentid.tolist(),
        "body_pos": model.body_pos.tolist(),
        "body_quat": model.body_quat.tolist(),
        "body_mass": model.body_mass.tolist(),
        "body_ipos": model.body_ipos.tolist(),
        "body_iquat": model.body_iquat.tolist(),
        "body_inertia": model.body_inertia.tolist(),
        "body_gravcomp": model.body_gravcomp.tolist(),
        "jnt_name": names(obj.mjOBJ_JOINT, model.njnt),
        "jnt_type": model.jnt_type.tolist(),
        "jnt_bodyid": model.jnt_bodyid.tolist(),
        "jnt_pos": model.jnt_pos.tolist(),
        "jnt_axis": model.jnt_axis.tolist(),
        "jnt_limited": flags(model.jnt_limited),
        "jnt_range": model.jnt_range.tolist(),
        "jnt_qpos0": [float(model.qpos0[a]) for a in model.jnt_qposadr],
        "jnt_armature": [float(model.dof_armature[d]) for d in model.jnt_dofadr],
        "jnt_damping": [float(model.dof_damping[d]) for d in model.jnt_dofadr],
        "jnt_frictionloss": [float(model.dof_frictionloss[d]) for d in model.jnt_dofadr],
        "jnt_actfrclimited": flags(model.jnt_actfrclimited),
        "jnt_actfrcrange": model.jnt_actfrcrange.tolist(),
        "site_name": names(obj.mjOBJ_SITE, model.nsite),
        "site_bodyid": model.site_bodyid.tolist(),
        "site_pos": model.site_pos.tolist(),
        "site_quat": model.site_quat.tolist(),
        "actuator_trntype": model.actuator_trntype.tolist(),
        "actuator_trnid": model.actuator_trnid[:, 0].tolist(),
        "actuator_gear": model.actuator_gear[:, 0].tolist(),
        "actuator_forcelimited": flags(model.actuator_forcelimited),
        "actuator_forcerange": model.actuator_forcerange.tolist(),
        "actuator_ctrllimited": flags(model.actuator_ctrllimited),
        "actuator_ctrlrange": model.actuator_ctrlrange.tolist(),
        "actuator_gaintype": model.actuator_gaintype.tolist(),
        "actuator_gain": model.actuator_gainprm[:, 0].tolist(),
        "actuator_biastype": model.actuator_biastype.tolist(),
        "eq_type": model.eq_type.tolist(),
        "eq_obj1id": model.eq_obj1id.tolist(),
        "eq_obj2id": model.eq_obj2id.tolist(),
        "eq_data": model.eq_data[:, :5].tolist(),
        "eq_active": flags(model.eq_active0),
        "force_sites": [
            int(model.sensor_objid[s])
            for s in range(model.nsensor)
            if model.sensor_type[s] == mujoco.mjtSensor.mjSENS_FORCE
            and model.sensor_objtype[s] == obj.mjOBJ_SITE
        ],
        "tendons": [
            (
                mujoco.mj_id2name(model, obj.mjOBJ_TENDON, t) or "",
                [int(model.wrap_objid[k]) for k in range(a, a + n)],
            )
            for t, (a, n) in enumerate(zip(model.tendon_adr, model.tendon_num))
            if all(model.wrap_type[k] == mujoco.mjtWrap.mjWRAP_JOINT for k in range(a, a + n))
        ],
    }


def model_name(model: Any) -> str:
    return bytes(model.names[: bytes(model.names).find(b"\0")]).decode()


def _from_model(model: Any, label: str, tip: str | None, fix: tuple[str, ...]) -> Arm:
    """The arm of a compiled MuJoCo model, with its gravity and joint ids."""
    import mujoco

    d = _adaptimp.arm_from_mujoco(mujoco_arrays(model), label, tip, list(fix))
    ids = []
    for name in d["joints"]:
        j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, name)
        ids.append(j if j >= 0 else int(name.rpartition("#")[2]))
    gravity = tuple(float(g) for g in model.opt.gravity)
    return Arm._of(d, gravity=gravity, joint_ids=tuple(ids))


def _is_model(source: object) -> bool:
    return type(source).__name__ == "MjModel" and hasattr(source, "body_parentid")


def kind_of(source: str | os.PathLike[str]) -> str:
    """What the file at ``source`` is: ``"urdf"``, ``"xacro"``, ``"mjcf"`` or
    ``"mjcf-fragment"`` (a file MJCF scenes include; the core looks at its
    root element and its markup)."""
    path = Path(source)
    if path.suffix.lower() == ".xacro":
        return "xacro"
    return str(_adaptimp.description_kind(str(path)))


def fragment_error(path: str | os.PathLike[str]) -> ConfigError:
    """The refusal of an MJCF fragment (a ``<mujocoinclude>``, or a ``<mujoco>``
    whose bodies are not in a ``<worldbody>``: a file that a package's task
    scenes include), naming the files beside it (and one folder up) that
    include it: load one of those."""
    import re

    p = Path(path)
    pattern = re.compile(r"<include\s+file\s*=\s*[\"']([^\"']*)[\"']")
    includers: list[str] = []
    for folder in (p.parent, p.parent.parent):
        for other in sorted(folder.glob("*.xml"))[:500]:
            if other == p or other.stat().st_size > 4 << 20:
                continue
            try:
                text = other.read_text(errors="replace")
            except OSError:
                continue
            if any((folder / f).resolve() == p.resolve() for f in pattern.findall(text)):
                includers.append(str(other.relative_to(p.parent.parent)) if folder != p.parent
                                 else other.name)  # fmt: skip
    hint = (
        f"load a scene that includes it ({', '.join(includers[:8])}"
        f"{', …' if len(includers) > 8 else ''})"
        if includers
        else "load the scene of its package that includes it"
    )
    return ConfigError(
        f"{p.name} is an MJCF fragment (its bodies are not in a <worldbody>: a file that other "
        f"MJCF files include), not a model of its own: {hint}"
    )


def read_arm(
    source: Any,
    tip: str | None = None,
    fix: Sequence[str] = (),
) -> Arm:
    """The arm of a robot description (SPEC §21), by the core's one rule.

    Parameters
    ----------
    source : path, str or mujoco.MjModel
        A URDF file, a ``.xacro`` file (expanded by the extra ``xacro``), an
        MJCF file (compiled by MuJoCo), URDF text (a string starting with
        ``<``) or a compiled ``MjModel``.
    tip : str, optional
        The link (MuJoCo body) or frame (MuJoCo site) that ends the arm; the
        movable joints on the way to it are the arm's. None: found by the
        rule of SPEC (21.2).
    fix : tuple of str
        Joints to hold at their reference value (0 in a URDF, qpos0 in MuJoCo).

    Raises
    ------
    FileNotFoundError
        No such file.
    XacroError
        Xacro that cannot be expanded here (the message gives the command).
    ConfigError
        Anything else, naming the file, the element and what to do.
    """
    fix = _fix(fix)
    if tip is not None and not isinstance(tip, str):
        raise ConfigError(f"tip must be a link or site name, got {tip!r}")
    if _is_model(source):
        label = f"MuJoCo model '{model_name(source)}'"
        return _from_model(source, label, tip, fix)
    if isinstance(source, str) and source.removeprefix("\ufeff").lstrip().startswith("<"):
        return Arm._of(_adaptimp.read_arm(source, tip, list(fix)))
    if not isinstance(source, (str, os.PathLike)):
        raise ConfigError(
            f"source must be a path, URDF text or a mujoco.MjModel, got {type(source).__name__}"
        )
    path = Path(source)
    kind = kind_of(path)
    if kind == "xacro":
        text = expand_xacro(path)
        return Arm._of(_adaptimp.read_arm(text, tip, list(fix), f"xacro '{path.name}'"))
    if kind == "mjcf-fragment":
        raise fragment_error(path)
    if kind == "mjcf":
        try:
            import mujoco
        except ImportError as e:
            from ._errors import needs_extra

            raise needs_extra("reading an MJCF file", "mujoco>=3", "mujoco") from e
        try:
            model = mujoco.MjModel.from_xml_path(str(path))
        except ValueError as e:
            raise ConfigError(f"MuJoCo cannot compile the MJCF {str(path)!r}: {e}") from None
        return _from_model(model, f"MJCF '{path.name}'", tip, fix)
    return Arm._of(_adaptimp.read_arm(str(path), tip, list(fix)))
