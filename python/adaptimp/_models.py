"""Robot descriptions shipped with, or found by, adaptimp (standard library only).

- ``two_link.xml`` (packaged): the paper's 2-link arm as MJCF, SPEC §1.
- The Franka Emika Panda of the ``example-robot-data`` package (installed data,
  no download): its URDF path, and the arm-only URDF that
  :func:`adaptimp.mujoco.panda` compiles (finger joints fixed, joint dynamics
  and meshes removed).

Nothing here imports MuJoCo or Pinocchio; :mod:`adaptimp.mujoco` and
:mod:`adaptimp.baselines` build their models from these.
"""

from __future__ import annotations

import importlib.metadata
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

from ._errors import needs_extra

MODELS_DIR = Path(__file__).resolve().parent / "models"
"""The packaged model files."""

TWO_LINK_XML = MODELS_DIR / "two_link.xml"
"""MJCF of the paper's 2-link arm in a vertical plane (SPEC §1), with a ceiling wall."""

PANDA_JOINTS = tuple(f"panda_joint{i}" for i in range(1, 8))
"""The Panda's seven arm joints, base to flange."""

PANDA_FINGERS = ("panda_finger_joint1", "panda_finger_joint2")
"""The Panda's two prismatic finger joints (locked closed, at 0 m, in every adaptimp model)."""

PANDA_EFFORT = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)
"""The Panda's joint torque limits (N m), the URDF's ``<limit effort>``."""

PANDA_HOME = (0.0, -0.785398, 0.0, -2.35619, 0.0, 1.5707, 0.785398)
"""The Panda's reference posture (rad): the ``default`` state of example-robot-data's SRDF."""

PANDA_EE = "panda_hand_tcp"
"""The Panda's end-effector frame: the tool centre point, 0.1034 m beyond the hand
along its z axis (the SRDF's ``end_effector``)."""

_ERD = "example-robot-data"
_PANDA_URDF = "cmeel.prefix/share/example-robot-data/robots/panda_description/urdf/panda.urdf"


def panda_urdf_path() -> Path:
    """Path of the Panda's URDF in the installed ``example-robot-data`` package.

    The package (data only since its version 4.4; the Python loaders are the
    separate ``example-robot-data-loaders``) installs its robots under its
    ``cmeel.prefix``. ``$ADAPTIMP_PANDA_URDF`` overrides the lookup.

    Raises
    ------
    ImportError
        ``example-robot-data`` is not installed (the extra ``pinocchio``).
    """
    override = os.environ.get("ADAPTIMP_PANDA_URDF")
    if override:
        return Path(override)
    try:
        dist = importlib.metadata.distribution(_ERD)
    except importlib.metadata.PackageNotFoundError as e:
        raise needs_extra("the Panda model", "example-robot-data>=4", "pinocchio") from e
    path = Path(str(dist.locate_file(_PANDA_URDF)))
    if not path.is_file():
        raise ImportError(f"example-robot-data {dist.version} has no Panda URDF at {path}")
    return path


def adapt_urdf(text: str, fix: tuple[str, ...] = ()) -> tuple[str, dict[str, float]]:
    """A URDF reduced to its kinematics and inertias, and its joints' effort limits.

    Removes every ``<visual>`` and ``<collision>`` (so no mesh file is needed),
    every joint's ``<dynamics>`` (damping, friction: the plant adds nothing to
    the rigid-body dynamics), ``<safety_controller>`` and ``<mimic>``, and makes
    the joints named in ``fix`` fixed at their zero position.

    Returns the new URDF text and ``{joint name: effort limit (N m)}`` for the
    remaining revolute, continuous and prismatic joints that declare one.
    """
    root = ET.fromstring(text)
    for link in root.findall("link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
    effort: dict[str, float] = {}
    for joint in root.findall("joint"):
        for tag in ("dynamics", "safety_controller", "mimic"):
            for e in joint.findall(tag):
                joint.remove(e)
        name = joint.get("name", "")
        if name in fix:
            joint.set("type", "fixed")
            for tag in ("axis", "limit"):
                for e in joint.findall(tag):
                    joint.remove(e)
        elif joint.get("type") in ("revolute", "continuous", "prismatic"):
            limit = joint.find("limit")
            if limit is not None and limit.get("effort") is not None:
                effort[name] = float(limit.get("effort", "nan"))
    return ET.tostring(root, encoding="unicode"), effort


def panda_arm_urdf() -> str:
    """The Panda's URDF as adaptimp uses it: :func:`adapt_urdf` with both finger
    joints fixed (closed, the fingers' masses then ride on the hand)."""
    text, _ = adapt_urdf(panda_urdf_path().read_text(), fix=PANDA_FINGERS)
    return text


GRIPPER_WORDS = ("gripper", "finger", "jaw", "claw")
"""Joint names containing one of these (any case) belong to a gripper, which
:func:`arm_urdf` fixes."""


@dataclass(frozen=True)
class ArmURDF:
    """A URDF reduced to the serial arm adaptimp drives (:func:`arm_urdf`).

    Attributes
    ----------
    text : str
        The reduced URDF (kinematics and inertias only; every joint not in
        ``joints`` made fixed at its zero position).
    joints : tuple of str
        The arm's joints, base to tip: the revolute and continuous joints of
        the longest serial chain from the root.
    lower, upper : tuple of float
        Their position limits (rad); ∓inf for a continuous joint.
    effort : tuple of float
        Their ``<limit effort>`` (N m); NaN where the URDF gives none or zero.
    tip : str
        The child link of the last joint: the end-effector body.
    fixed : dict
        Every other movable joint of the URDF and why it was fixed.
    """

    text: str
    joints: tuple[str, ...]
    lower: tuple[float, ...]
    upper: tuple[float, ...]
    effort: tuple[float, ...]
    tip: str
    fixed: dict[str, str] = field(default_factory=dict)


def _float(e: ET.Element | None, name: str, default: float) -> float:
    if e is None or e.get(name) is None:
        return default
    try:
        return float(e.get(name, "nan"))
    except ValueError:
        return default


def arm_urdf(text: str, fix: tuple[str, ...] = (), *, tip: str | None = None) -> ArmURDF:
    """The serial arm of a URDF, as :func:`adaptimp.mujoco.from_urdf` and
    :func:`adaptimp.baselines.pinocchio_model` load it (one reduction for both).

    :func:`adapt_urdf`'s clean-up (no meshes, no joint dynamics), then:

    - joints named in ``fix``, prismatic joints (a linear axis or a finger)
      and mimic joints are fixed;
    - the arm is the longest serial chain of the remaining revolute and
      continuous joints from the root (the most of them on one path; chains
      that tie, such as a quadruped's legs or a robot's two arms, are an
      error that lists where each ends, unless ``tip`` names the link that
      ends the arm), and it ends where the tree branches
      into two or more subtrees with movable joints that are each shorter
      than the chain so far (a hand: fingers are shorter than the arm that
      holds them; a humanoid's arms are longer than its torso, so the chain
      goes on along one of them);
    - a joint whose name contains a word of :data:`GRIPPER_WORDS` is fixed
      when it comes after a joint of the arm whose name does not (a gripper
      on the arm; a robot that is itself a finger keeps its joints);
    - movable joints off the arm (another arm, a head, a hand) are fixed;
    - with ``tip`` (a link), the arm is the movable joints on the path from
      the root to it, the rules above fixing the rest.

    A revolute joint whose limits leave no range (lower ≥ upper, often
    "0 0" in exported files) is taken as unlimited: a continuous joint.
    Every fixed joint is fixed at its zero position. Raises ``ValueError`` if
    no movable joint is left.
    """
    root = ET.fromstring(text)
    mimic = {j.get("name", "") for j in root.findall("joint") if j.find("mimic") is not None}
    base, _ = adapt_urdf(text)
    root = ET.fromstring(base)
    fixed: dict[str, str] = {}
    children: dict[str, list[ET.Element]] = {}
    parents: set[str] = set()
    for joint in root.findall("joint"):
        name = joint.get("name", "")
        kind = joint.get("type", "")
        parent = joint.find("parent")
        child = joint.find("child")
        if parent is None or child is None:
            raise ValueError(f"URDF joint {name!r} has no parent or child link")
        children.setdefault(parent.get("link", ""), []).append(joint)
        parents.add(child.get("link", ""))
        limit = joint.find("limit")
        lo, hi = _float(limit, "lower", -math.inf), _float(limit, "upper", math.inf)
        if kind == "revolute" and not lo < hi:
            joint.set("type", "continuous")  # no range given: unlimited
            if limit is not None:
                for attr in ("lower", "upper"):
                    limit.attrib.pop(attr, None)
        if kind in ("fixed", "floating", "planar"):
            continue
        if name in fix:
            fixed[name] = "asked"
        elif kind == "prismatic":
            fixed[name] = "prismatic (the arm's joints are revolute)"
        elif name in mimic:
            fixed[name] = "mimic joint"
    roots = [
        link.get("name", "") for link in root.findall("link") if link.get("name") not in parents
    ]
    if len(roots) != 1:
        raise ValueError(f"the URDF must have one root link, found {roots}")

    def movable(j: ET.Element) -> bool:
        return j.get("type") in ("revolute", "continuous") and j.get("name") not in fixed

    def gripper(j: ET.Element) -> str | None:
        words = [w for w in GRIPPER_WORDS if w in j.get("name", "").lower()]
        return words[0] if words else None

    def longest(link: str, held: int, arm: bool) -> list[list[ET.Element]]:
        """The movable joints of the arm's chain below ``link``, with ``held``
        joints above it, ``arm`` if one of them is not a gripper's: every chain
        of the greatest length (several if they tie)."""
        per_child: list[list[list[ET.Element]]] = []
        for j in children.get(link, []):
            child = j.find("child")
            assert child is not None
            word = gripper(j)
            if word is not None and arm and movable(j):
                fixed[j.get("name", "")] = f"a gripper joint (its name contains {word!r})"
            own = [j] if movable(j) else []
            below = longest(
                child.get("link", ""), held + len(own), arm or (bool(own) and word is None)
            )
            per_child.append([own + b for b in below])
        carrying = [c[0] for c in per_child if c[0]]
        if held > 0 and len(carrying) >= 2 and all(len(c) < held for c in carrying):
            return [[]]  # a hand: the arm ends here
        every = [c for options in per_child for c in options]
        best = max((len(c) for c in every), default=0)
        return [c for c in every if len(c) == best] if best > 0 else [[]]

    def link_of(j: ET.Element) -> str:
        child = j.find("child")
        return "" if child is None else child.get("link", "")

    longest_chains = longest(roots[0], 0, False)
    if tip is not None:
        by_child = {link_of(j): j for j in root.findall("joint")}
        if tip not in by_child and tip != roots[0]:
            raise ValueError(f"the URDF has no link named {tip!r} (tip=)")
        path: list[ET.Element] = []
        link = tip
        while link in by_child:
            path.append(by_child[link])
            parent = by_child[link].find("parent")
            link = "" if parent is None else parent.get("link", "")
        chain = [j for j in reversed(path) if movable(j)]
        if not chain:
            raise ValueError(
                f"the URDF has no revolute or continuous joint to drive on the way to {tip!r}"
            )
    else:
        chain = longest_chains[0]
        if len(longest_chains) > 1:
            tips = ", ".join(repr(link_of(c[-1])) for c in longest_chains)
            raise ValueError(
                f"the URDF has {len(longest_chains)} serial chains of {len(chain)} joints "
                f"from the root that tie for the arm (legs, or two arms), ending at the "
                f"links {tips}: name one with tip= (adaptimp.mujoco.from_urdf(path, tip=...), "
                "adaptimp.contact.arm_table(path, tip=...)) or fix the others' joints with fix="
            )
    on_chain = {j.get("name", "") for j in chain}
    for j in root.findall("joint"):
        name = j.get("name", "")
        if movable(j) and name not in on_chain:
            fixed[name] = "off the arm's chain (a branch)"
    if not chain:
        raise ValueError(
            "the URDF has no revolute or continuous joint to drive"
            + (f" (fixed: {fixed})" if fixed else "")
        )
    for j in root.findall("joint"):
        if j.get("name", "") in fixed:
            j.set("type", "fixed")
            for tag in ("axis", "limit"):
                for e in j.findall(tag):
                    j.remove(e)
    lower: list[float] = []
    upper: list[float] = []
    effort: list[float] = []
    for j in chain:
        lim = j.find("limit")
        if j.get("type") == "continuous":
            lower.append(-math.inf)
            upper.append(math.inf)
        else:
            lower.append(_float(lim, "lower", -math.inf))
            upper.append(_float(lim, "upper", math.inf))
        given = _float(lim, "effort", math.nan)
        effort.append(given if given > 0 and math.isfinite(given) else math.nan)
    end = chain[-1].find("child")
    assert end is not None
    return ArmURDF(
        text=ET.tostring(root, encoding="unicode"),
        joints=tuple(j.get("name", "") for j in chain),
        lower=tuple(lower),
        upper=tuple(upper),
        effort=tuple(effort),
        tip=end.get("link", ""),
        fixed=fixed,
    )
