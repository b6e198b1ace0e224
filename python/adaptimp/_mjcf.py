"""MJCF files as their makers ship them, made into a plant (SPEC §18, docs/your_arm.md).

What :class:`adaptimp.mujoco.Plant` does to a model before it drives it, each
step a function of its own, none of them touching the file (the model is
edited in memory, through MuJoCo's ``MjSpec``):

- :func:`arm_of`: which joints are the arm's, the tip, and what is not the
  arm's and why: the core's one reduction (SPEC §21), as for a URDF.
- :func:`prepare_file` / :func:`prepare_model`: the joints of the arm's own
  body tree that are not the arm's are **locked** at their reference
  position (the joint is removed, so its bodies ride rigidly on the hand, as
  the controller's model of the arm has them; with it go its actuators, the
  tendons and equality constraints that coupled it, the sensors that read
  it); every arm joint gets **one torque motor**: a ``motor`` as it is, a
  ``position``, ``velocity`` or ``general`` actuator becomes a motor of the
  same force range, a joint without an actuator gets one. Where nothing
  declares a force range, τmax is estimated from the arm (:func:`estimate`).
- :func:`moving_contacts`: the contacts between bodies that the arm's joints
  move relative to each other (the arm with itself, or with what is around
  it), for the default task's self-collision check and the check after a run.

Needs MuJoCo. Imports nothing of the package above the core's reader
(:mod:`adaptimp._description`): :mod:`adaptimp.mujoco` and :class:`adaptimp.Chain` build on it.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from numpy.typing import NDArray

from ._mjmodel import JOINT_TRN, OBJ, file_keys, obj_name, restore_keys
from ._sampled import estimate

FloatArray = NDArray[np.float64]

FIRST_ORDER_STEP = 2.5e-4
"""The largest MuJoCo timestep (s) of a file's model integrated to first order
(Euler, implicit, implicitfast): :func:`adaptimp.mujoco.simulate` then takes
4 MuJoCo steps per 1 ms period. The rule's velocity loop moves a quarter of
its error per period (SPEC 18.1); integrated once a period, the plant's
error is of the size of what learning removes (dm_control's Kinova: SF/PD
0.225 at one Euler step per period, 0.134 at 2, 0.103 at 4, 0.088 with RK4).
A file's RK4 keeps its timestep."""

_HINGE = int(mujoco.mjtJoint.mjJNT_HINGE)
_SLIDE = int(mujoco.mjtJoint.mjJNT_SLIDE)


# ---------------------------------------------------------------------------
# The arm's joints.
# ---------------------------------------------------------------------------


def ancestors(m: mujoco.MjModel, body: int) -> list[int]:
    """The bodies ``body`` hangs from, its parent first, the world (0) last."""
    out = []
    while body > 0:
        body = int(m.body_parentid[body])
        out.append(body)
    return out


def root_body(m: mujoco.MjModel, body: int) -> int:
    """The child of the world body that ``body`` hangs from (0 for the world)."""
    while body > 0 and int(m.body_parentid[body]) > 0:
        body = int(m.body_parentid[body])
    return body


def resolve_tip(m: mujoco.MjModel, tip: str) -> tuple[int, str]:
    """A site or body of ``m`` by name: (its body, ``"site"`` or ``"body"``); a
    site first if both have the name.

    Raises
    ------
    ValueError
        Neither a site nor a body has the name (the message lists the bodies).
    """
    sid = mujoco.mj_name2id(m, OBJ.mjOBJ_SITE, tip)
    if sid >= 0:
        return int(m.site_bodyid[sid]), "site"
    bid = mujoco.mj_name2id(m, OBJ.mjOBJ_BODY, tip)
    if bid > 0:
        return bid, "body"
    bodies = [obj_name(m, OBJ.mjOBJ_BODY, b) for b in range(1, m.nbody)]
    raise ValueError(
        f"tip={tip!r}: the model has no site or body of that name (bodies: "
        f"{', '.join(bodies[:40])}{', …' if len(bodies) > 40 else ''})"
    )


def _body_of(m: mujoco.MjModel, link: str) -> int:
    """The MuJoCo body of a link of the core's tree: a body's name, ``body#i``
    for an unnamed one, ``BODY:JOINT`` between two joints of one body."""
    for name in (link, link.rpartition(":")[0]):
        b = mujoco.mj_name2id(m, OBJ.mjOBJ_BODY, name)
        if b >= 0:
            return int(b)
        if name.startswith("body#") and name[5:].isdigit():
            return int(name[5:])
    return 0


def arm_of(m: mujoco.MjModel, tip: str | None = None, fix: Sequence[str] = ()) -> dict[str, Any]:
    """The arm of a compiled MuJoCo model by the core's one reduction (SPEC
    §21, :func:`adaptimp._description.read_arm`; the rule of a URDF's arm on
    MuJoCo's body tree): the arm's hinges, the tip (``tip``, a site or a
    body, a site first; without it the site of a force sensor a hinge moves,
    else the first site on the last arm joint's body, else that body), and
    why every other joint is not the arm's (asked, mimic or coupled, a
    gripper's drive or jaw, in a hand, prismatic, off the chain).

    Returns a dict: ``joints`` (names, base to tip), ``joint_ids`` (MuJoCo
    ids), ``fixed`` ({name: reason}), ``tip`` (its name), ``tip_kind``
    ("site" or "body"), ``tip_body`` (its body id).

    Raises
    ------
    ValueError
        (``ConfigError``) An unknown ``fix`` joint or ``tip``, no joint to
        drive, chains that tie; the message names the model and what to do.
    """
    from ._description import read_arm

    arm = read_arm(m, tip, fix)
    if arm.tip_is_frame:
        site = mujoco.mj_name2id(m, OBJ.mjOBJ_SITE, arm.tip)
        if site < 0:  # an unnamed site, "site#i"
            site = int(arm.tip.rpartition("#")[2])
        tip_body, tip_kind = int(m.site_bodyid[site]), "site"
    else:
        tip_body, tip_kind = _body_of(m, arm.tip), "body"
    return {
        "joints": arm.joints,
        "joint_ids": arm.joint_ids,
        "fixed": dict(arm.fixed),
        "tip": arm.tip,
        "tip_kind": tip_kind,
        "tip_body": tip_body,
    }


def arm_tree(m: mujoco.MjModel, joint_ids: Iterable[int]) -> frozenset[int]:
    """The bodies of the arm's own tree: every body under the world's children
    that carry an arm joint (the base, the links, the hand, a gripper)."""
    roots = {root_body(m, int(m.jnt_bodyid[j])) for j in joint_ids}
    return frozenset(b for b in range(1, m.nbody) if root_body(m, b) in roots)


def movers(m: mujoco.MjModel, joint_ids: Sequence[int]) -> list[frozenset[int]]:
    """For every body, the set of arm joints that move it (relative to the world)."""
    arm = set(joint_ids)
    out: list[frozenset[int]] = [frozenset()] * m.nbody
    for b in range(1, m.nbody):
        parent = out[int(m.body_parentid[b])]
        own = {
            j
            for j in range(int(m.body_jntadr[b]), int(m.body_jntadr[b] + m.body_jntnum[b]))
            if j in arm
        }
        out[b] = parent | own
    return out


# ---------------------------------------------------------------------------
# The plant's model: joints locked, one torque motor per arm joint.
# ---------------------------------------------------------------------------


@dataclass
class Prepared:
    """A model made ready for :class:`adaptimp.mujoco.Plant`.

    Attributes
    ----------
    model : MjModel
        The compiled model (the arm's joints driven by torque motors).
    spec : MjSpec or None
        The edited spec it compiles from (a file's model), for further
        in-memory additions (a contact sensor); None for a given ``MjModel``.
    arm : dict
        :func:`arm_of`'s answer on the model as given.
    notes : dict
        What was done, for ``res.params["plant"]``: "locked" {joint: reason},
        "actuators" {joint: what its actuator was → motor}, "tau_max"
        {joint: where τmax comes from}.
    warnings : list of str
        The warnings to emit (one per kind of change).
    """

    model: mujoco.MjModel
    spec: Any
    arm: dict[str, Any]
    notes: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)


def _kind(m: mujoco.MjModel, a: int) -> str:
    """ "motor" (a torque source: no dynamics, fixed gain, no bias) or what the
    actuator is (a servo: "position", "velocity", "general")."""
    dyn, gain, bias = (
        int(m.actuator_dyntype[a]),
        int(m.actuator_gaintype[a]),
        int(m.actuator_biastype[a]),
    )
    fixed_gain = gain == int(mujoco.mjtGain.mjGAIN_FIXED)
    if (
        dyn == int(mujoco.mjtDyn.mjDYN_NONE)
        and fixed_gain
        and bias == int(mujoco.mjtBias.mjBIAS_NONE)
    ):
        return "motor"
    if fixed_gain and bias == int(mujoco.mjtBias.mjBIAS_AFFINE):
        kp, b1, b2 = (
            float(m.actuator_gainprm[a, 0]),
            float(m.actuator_biasprm[a, 1]),
            float(m.actuator_biasprm[a, 2]),
        )
        if kp > 0 and b1 == -kp:
            return "position"
        if kp > 0 and b1 == 0 and b2 == -kp:
            return "velocity"
    return "general"


def _servo(m: mujoco.MjModel, a: int, kind: str) -> str:
    """What servo actuator ``a`` of :func:`_kind` ``kind`` is, by its parameters
    (a compiled model does not say which element declared it: a ``<general>``
    with a position servo's gain and bias was named "position actuator")."""
    kp = float(m.actuator_gainprm[a, 0])
    if kind == "position":
        return f"a position servo, kp = {kp:g}: a <position>, or a <general> with its gain and bias"
    if kind == "velocity":
        return f"a velocity servo, kv = {kp:g}: a <velocity>, or a <general> with its gain and bias"
    return "a <general> actuator with dynamics, a gain or a bias of its own"


def _force_limit(m: mujoco.MjModel, a: int, joint: int) -> tuple[float, str] | None:
    """The largest joint torque (N m) actuator ``a`` can exert on ``joint`` and
    where it comes from, or None if nothing declares it: the smaller of gear ×
    its force range (a motor without one: gear × gain × its control range) and
    the joint's ``actuatorfrcrange``. A range must be symmetric about zero."""
    gear = abs(float(m.actuator_gear[a, 0]))
    name = obj_name(m, OBJ.mjOBJ_ACTUATOR, a)
    limits: list[tuple[float, str]] = []
    if m.actuator_forcelimited[a]:
        lo, hi = (float(v) for v in m.actuator_forcerange[a])
        limits.append(
            (gear * _symmetric(lo, hi, f"the forcerange of actuator {name!r}"), "forcerange")
        )
    elif m.actuator_ctrllimited[a] and _kind(m, a) == "motor":
        lo, hi = (float(v) for v in m.actuator_ctrlrange[a])
        gain = abs(float(m.actuator_gainprm[a, 0]))
        limits.append(
            (gear * gain * _symmetric(lo, hi, f"the ctrlrange of motor {name!r}"), "ctrlrange")
        )
    if m.jnt_actfrclimited[joint]:
        lo, hi = (float(v) for v in m.jnt_actfrcrange[joint])
        jname = obj_name(m, OBJ.mjOBJ_JOINT, joint)
        limits.append(
            (_symmetric(lo, hi, f"the actuatorfrcrange of joint {jname!r}"), "actuatorfrcrange")
        )
    return min(limits) if limits else None


def _symmetric(lo: float, hi: float, what: str) -> float:
    if not (hi > 0 and lo == -hi and math.isfinite(hi)):
        raise ValueError(
            f"{what} is [{lo:g}, {hi:g}]: the plant needs a range symmetric about zero "
            "(its τmax); give the joint a symmetric range"
        )
    return hi


def _label(path: str | os.PathLike[str] | None) -> str:
    return f"{Path(path).name}: " if path is not None else ""


def prepare_file(path: str | os.PathLike[str], tip: str | None, fix: Sequence[str]) -> Prepared:
    """An MJCF file's model for the plant, edited in memory (the module doc).

    Raises
    ------
    ValueError
        MuJoCo cannot compile the file (its message, with the file's name); the
        reduction's errors (:func:`arm_of`); a tendon that couples an arm joint
        with a joint to lock; an arm joint with two actuators.
    """
    from ._description import fragment_error, kind_of

    if Path(path).is_file() and kind_of(path) == "mjcf-fragment":
        raise fragment_error(path)
    try:
        spec = mujoco.MjSpec.from_file(str(path))
    except ValueError as e:
        raise ValueError(f"MuJoCo cannot load {str(path)!r}: {e}") from None
    return prepare_spec(spec, tip, fix, _label(path), "the file")


def prepare_spec(
    spec: Any, tip: str | None, fix: Sequence[str], label: str = "", given: str = "the spec given"
) -> Prepared:
    """:func:`prepare_file` for an ``MjSpec``, edited in place (give a copy);
    ``given`` names the source in the warnings ("the file", "the spec given")."""
    # The plant's motors target joints by name: an unnamed one is named here
    # (a model without actuators on unnamed joints failed in MuJoCo's compiler,
    # "unknown transmission target '#0'").
    for i, joint in enumerate(spec.joints):
        if not joint.name:
            joint.name = f"adaptimp_joint{i}"
    for i, body in enumerate(spec.bodies):  # the contact sensor names its body
        if not body.name:
            body.name = f"adaptimp_body{i}"
    try:
        m0 = spec.compile()
    except ValueError as e:
        raise ValueError(f"{label}MuJoCo cannot compile the model: {e}") from None
    try:
        arm = arm_of(m0, tip, fix)
    except ValueError as e:  # named by the file it is about
        said = str(e)
        if said.startswith(label):
            raise
        if label:  # the file says more than the compiled model's name
            said = re.sub(r"^MuJoCo model '[^']*': ", "", said)
        raise ValueError(f"{label}{said}") from None
    tree = arm_tree(m0, arm["joint_ids"])
    keep = set(arm["joint_ids"])
    lock = [j for j in range(m0.njnt) if j not in keep and int(m0.jnt_bodyid[j]) in tree]
    out = Prepared(model=m0, spec=spec, arm=arm)
    first_order = int(spec.option.integrator) != int(mujoco.mjtIntegrator.mjINT_RK4)
    if first_order and spec.option.timestep > FIRST_ORDER_STEP:
        out.notes["timestep"] = (
            f"{mujoco.mjtIntegrator(int(spec.option.integrator)).name} at "
            f"{spec.option.timestep:g} s in the file: stepped at {FIRST_ORDER_STEP:g} s"
        )
        spec.option.timestep = FIRST_ORDER_STEP
    spec_actuators = list(spec.actuators)  # index = m0's actuator id
    # The keyframes, read off the compiled model by name and taken out of the
    # spec: written back for the plant's model once its joints and actuators
    # are final (:func:`restore_keys`).
    keys = file_keys(spec, m0)
    if lock:
        _lock(spec, m0, lock, keep, spec_actuators)
        reasons = {
            obj_name(m0, OBJ.mjOBJ_JOINT, j): arm["fixed"].get(
                obj_name(m0, OBJ.mjOBJ_JOINT, j), "not a hinge of the arm"
            )
            for j in lock
        }
        out.notes["locked"] = reasons
        out.notes["locked_bodies"] = {
            obj_name(m0, OBJ.mjOBJ_JOINT, j): obj_name(m0, OBJ.mjOBJ_BODY, int(m0.jnt_bodyid[j]))
            for j in lock
        }
        out.warnings.append(
            f"{label}the joints {list(reasons)} are not the arm's "
            f"({'; '.join(f'{k}: {v}' for k, v in reasons.items())}): the plant locks them at "
            "their reference position (a rigid hand, as the controller's model of the arm "
            f"has it), with their actuators, couplings and sensors; {given} is not changed"
        )
    _motors(spec, m0, arm, out, label, spec_actuators, given)
    m1 = _compile(spec)
    # Equality constraints left inside one rigid body (a gripper's linkage).
    dead = [
        k
        for k in range(m1.neq)
        if int(m1.eq_type[k]) in (int(mujoco.mjtEq.mjEQ_CONNECT), int(mujoco.mjtEq.mjEQ_WELD))
        and len({int(m1.body_weldid[b]) for b in _eq_bodies(m1, k) or ()}) == 1
    ]
    if dead:
        equalities = list(spec.equalities)
        for k in dead:
            spec.delete(equalities[k])
        m1 = _compile(spec)
    holds = holding(m1, [mujoco.mj_name2id(m1, OBJ.mjOBJ_JOINT, n) for n in arm["joints"]])
    if holds:
        equalities = list(spec.equalities)
        for k in holds:
            equalities[k].active = False
        _note_holds(m1, holds, out, label)
        m1 = _compile(spec)
    if keys:
        restore_keys(spec, m1, keys, set(arm["joints"]))
        m1 = _compile(spec)
    _estimate_missing(spec, m1, out, label)
    out.model = spec.compile() if out.notes.get("estimated") else m1
    return out


def holding(m: mujoco.MjModel, joint_ids: Sequence[int]) -> list[int]:
    """The active connect and weld constraints that tie a body the arm moves to
    one it does not (a mocap body that drags the hand, the world, a fixture):
    they would hold the arm against the controller."""
    moved_by = movers(m, joint_ids)
    out = []
    for k in range(m.neq):
        if int(m.eq_type[k]) not in (int(mujoco.mjtEq.mjEQ_CONNECT), int(mujoco.mjtEq.mjEQ_WELD)):
            continue
        bodies = _eq_bodies(m, k)
        if bodies is not None and m.eq_active0[k] and moved_by[bodies[0]] != moved_by[bodies[1]]:
            out.append(k)
    return out


def _note_holds(m: mujoco.MjModel, holds: Sequence[int], out: Prepared, label: str) -> None:
    pairs = {}
    for k in holds:
        a, b = _eq_bodies(m, k) or (0, 0)
        name = obj_name(m, OBJ.mjOBJ_EQUALITY, k)
        pairs[name] = f"{obj_name(m, OBJ.mjOBJ_BODY, a)!r} to {obj_name(m, OBJ.mjOBJ_BODY, b)!r}"
    out.notes["released"] = pairs
    out.warnings.append(
        f"{label}the equality constraints {list(pairs)} tie the arm to what it does not move "
        f"({'; '.join(pairs.values())}: a mocap body or a fixture): the plant turns them off, "
        "as the controller drives the joints"
    )


def _compile(spec: Any) -> mujoco.MjModel:
    return spec.compile()


def _eq_bodies(m: mujoco.MjModel, e: int) -> tuple[int, int] | None:
    objtype = int(m.eq_objtype[e])
    a, b = int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
    if objtype == int(OBJ.mjOBJ_SITE):
        return int(m.site_bodyid[a]), int(m.site_bodyid[b]) if b >= 0 else 0
    if objtype == int(OBJ.mjOBJ_BODY):
        return a, max(b, 0)
    return None


def _lock(
    spec: Any, m0: mujoco.MjModel, lock: Sequence[int], keep: set[int], actuators_of: list[Any]
) -> None:
    """Remove the joints ``lock`` of ``m0`` from ``spec`` (their bodies then sit
    at the joints' reference position), with the actuators, tendons, equality
    constraints and sensors that use them (the keyframes are laid out again
    afterwards, :func:`restore_keys`)."""
    joints = {obj_name(m0, OBJ.mjOBJ_JOINT, j) for j in lock}
    tendons: set[str] = set()
    for t in range(m0.ntendon):
        adr, num = int(m0.tendon_adr[t]), int(m0.tendon_num[t])
        wrapped = [
            int(m0.wrap_objid[w])
            for w in range(adr, adr + num)
            if int(m0.wrap_type[w]) == int(mujoco.mjtWrap.mjWRAP_JOINT)
        ]
        hit = [j for j in wrapped if j in lock]
        if hit and any(j in keep for j in wrapped):
            raise ValueError(
                f"the tendon {obj_name(m0, OBJ.mjOBJ_TENDON, t)!r} couples the arm's joint(s) "
                f"{[obj_name(m0, OBJ.mjOBJ_JOINT, j) for j in wrapped if j in keep]} with "
                f"{[obj_name(m0, OBJ.mjOBJ_JOINT, j) for j in hit]}, which are not the arm's: "
                "the plant cannot lock them apart; name the arm with tip= or fix="
            )
        if hit:
            tendons.add(obj_name(m0, OBJ.mjOBJ_TENDON, t))
    actuators: set[str] = set()
    dropped: list[int] = []
    for a in range(m0.nu):
        trn, target = int(m0.actuator_trntype[a]), int(m0.actuator_trnid[a, 0])
        if (trn in JOINT_TRN and target in lock) or (
            trn == int(mujoco.mjtTrn.mjTRN_TENDON)
            and obj_name(m0, OBJ.mjOBJ_TENDON, target) in tendons
        ):
            actuators.add(obj_name(m0, OBJ.mjOBJ_ACTUATOR, a))
            dropped.append(a)
    for s in list(spec.sensors):
        objtype, obj = int(s.objtype), s.objname
        if (
            (objtype == int(OBJ.mjOBJ_JOINT) and obj in joints)
            or (objtype == int(OBJ.mjOBJ_TENDON) and obj in tendons)
            or (objtype == int(OBJ.mjOBJ_ACTUATOR) and obj in actuators)
        ):
            spec.delete(s)
    for e in list(spec.equalities):
        if (
            int(e.type) == int(mujoco.mjtEq.mjEQ_JOINT) and (e.name1 in joints or e.name2 in joints)
        ) or (
            int(e.type) == int(mujoco.mjtEq.mjEQ_TENDON)
            and (e.name1 in tendons or e.name2 in tendons)
        ):
            spec.delete(e)
    for a in dropped:
        spec.delete(actuators_of[a])
    for t in list(spec.tendons):
        if t.name in tendons:
            spec.delete(t)
    for name in joints:
        spec.delete(spec.joint(name))


def _motors(
    spec: Any,
    m0: mujoco.MjModel,
    arm: dict[str, Any],
    out: Prepared,
    label: str,
    actuators: list[Any],
    given: str,
) -> None:
    """One torque motor per arm joint in ``spec``: motors kept, servos converted
    (their force range kept), a motor added where a joint has none. Joints whose
    τmax nothing declares get ±1 for now and ``out.notes["estimated"]``."""
    by_joint: dict[int, list[int]] = {j: [] for j in arm["joint_ids"]}
    for a in range(m0.nu):
        target = int(m0.actuator_trnid[a, 0])
        if int(m0.actuator_trntype[a]) in JOINT_TRN and target in by_joint:
            by_joint[target].append(a)
    converted: dict[str, str] = {}
    kinds: set[str] = set()
    added: list[str] = []
    estimated: list[str] = []
    sources: dict[str, str] = {}
    for j in arm["joint_ids"]:
        jname = obj_name(m0, OBJ.mjOBJ_JOINT, j)
        acts = by_joint[j]
        if len(acts) > 1:
            raise ValueError(
                f"{label}joint {jname!r} has {len(acts)} actuators "
                f"({', '.join(repr(obj_name(m0, OBJ.mjOBJ_ACTUATOR, a)) for a in acts)}): "
                "the plant drives each arm joint with one torque motor; remove the others or "
                "fix= the joint"
            )
        if not acts:
            limit = _joint_limit(m0, j)
            act = spec.add_actuator(name=f"adaptimp_motor_{jname}", target=jname)
            act.trntype = mujoco.mjtTrn.mjTRN_JOINT
            act.set_to_motor()
            act.gear = [1.0, 0, 0, 0, 0, 0]
            added.append(jname)
            source = "actuatorfrcrange" if limit is not None else None
        else:
            a = acts[0]
            act = actuators[a]
            kind = _kind(m0, a)
            found = _force_limit(m0, a, j)
            limit = None if found is None else found[0] / abs(float(m0.actuator_gear[a, 0]))
            source = None if found is None else found[1]
            if kind != "motor":
                kinds.add(kind)
                servo, name = _servo(m0, a, kind), obj_name(m0, OBJ.mjOBJ_ACTUATOR, a)
                converted[jname] = f"actuator {name!r} ({servo}) → motor"
            act.set_to_motor()
            act.gear = [abs(float(m0.actuator_gear[a, 0])), 0, 0, 0, 0, 0]
            act.forcelimited = mujoco.mjtLimited.mjLIMITED_FALSE
        act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
        if limit is None:
            act.ctrlrange = [-1.0, 1.0]
            estimated.append(jname)
            sources[jname] = "estimated"
        else:
            act.ctrlrange = [-limit, limit]
            sources[jname] = str(source)
    out.notes["tau_max"] = sources
    if converted:
        out.notes["actuators"] = converted
        servo_kinds = sorted(kinds)
        out.warnings.append(
            f"{label}the actuators of {list(converted)} are {' and '.join(servo_kinds)} "
            "servos, not torque motors: the plant drives these joints with torque motors of "
            "the same force range (their forcerange where declared), as the controller "
            f"commands torque; {given} is not changed"
        )
    if added:
        out.notes["added"] = added
        out.warnings.append(
            f"{label}the joints {added} have no actuator: the plant adds a torque motor to each"
        )
    if estimated:
        out.notes["estimated"] = estimated


def _joint_limit(m: mujoco.MjModel, j: int) -> float | None:
    if m.jnt_actfrclimited[j]:
        lo, hi = (float(v) for v in m.jnt_actfrcrange[j])
        return _symmetric(
            lo, hi, f"the actuatorfrcrange of joint {obj_name(m, OBJ.mjOBJ_JOINT, j)!r}"
        )
    return None


def _estimate_missing(spec: Any, m1: mujoco.MjModel, out: Prepared, label: str) -> None:
    """τmax estimated (:func:`estimate`) for the joints in ``out.notes["estimated"]``,
    written into ``spec``'s motors."""
    missing: list[str] = out.notes.get("estimated", [])
    if not missing:
        return
    ids = [mujoco.mj_name2id(m1, OBJ.mjOBJ_JOINT, n) for n in out.arm["joints"]]
    qadr = [int(m1.jnt_qposadr[j]) for j in ids]
    dofs = [int(m1.jnt_dofadr[j]) for j in ids]
    tau = estimate(m1, qadr, dofs)
    values = {}
    for a, act in enumerate(spec.actuators):
        target = act.target
        if target in missing:
            i = out.arm["joints"].index(target)
            gear = float(m1.actuator_gear[a, 0])
            act.ctrlrange = [-tau[i] / gear, tau[i] / gear]
            values[target] = round(float(tau[i]), 3)
    out.warnings.append(
        f"{label}no force range is declared for {missing}: the plant estimates τmax = "
        f"{list(values.values())} N m (2 (max |G_i| + 10 rad/s² · max Σ_j |D_ij| + damping · "
        "1 rad/s + friction loss) within the joint limits)"
    )


def prepare_model(m: mujoco.MjModel, tip: str | None, fix: Sequence[str]) -> Prepared:
    """A given ``MjModel`` for the plant: its arm (:func:`arm_of`) and its arm
    joints' servos made torque motors in a copy (a compiled model cannot lose
    joints or gain actuators: such a model must come as a file).

    Raises
    ------
    ValueError
        Joints of the arm's tree that are not the arm's, an arm joint without
        an actuator or a force range (pass the file's path: the plant then
        edits it in memory); the reduction's errors.
    """
    import copy

    m = copy.deepcopy(m)
    arm = arm_of(m, tip, fix)
    tree = arm_tree(m, arm["joint_ids"])
    keep = set(arm["joint_ids"])
    extra = [j for j in range(m.njnt) if j not in keep and int(m.jnt_bodyid[j]) in tree]
    if extra:
        raise ValueError(
            f"joints {[obj_name(m, OBJ.mjOBJ_JOINT, j) for j in extra]} of the arm's body tree are "
            f"not the arm's ({'; '.join(f'{k}: {v}' for k, v in arm['fixed'].items())}) and a "
            "compiled MjModel cannot lock them: give the plant the file's path (it locks them "
            "in memory), or name the arm's joints with tip=/fix="
        )
    out = Prepared(model=m, spec=None, arm=arm)
    holds = holding(m, arm["joint_ids"])
    if holds:
        m.eq_active0[holds] = 0
        _note_holds(m, holds, out, "")
    converted: dict[str, str] = {}
    sources: dict[str, str] = {}
    by_joint: dict[int, list[int]] = {j: [] for j in keep}
    for a in range(m.nu):
        if int(m.actuator_trntype[a]) in JOINT_TRN and int(m.actuator_trnid[a, 0]) in by_joint:
            by_joint[int(m.actuator_trnid[a, 0])].append(a)
    for j in arm["joint_ids"]:
        jname = obj_name(m, OBJ.mjOBJ_JOINT, j)
        acts = by_joint[j]
        if len(acts) != 1:
            raise ValueError(
                f"joint {jname!r} has {len(acts)} actuators: the plant needs exactly one per arm "
                "joint (give the plant the file's path to have a motor added)"
                if not acts
                else f"joint {jname!r} has {len(acts)} actuators: the plant drives each arm "
                "joint with one torque motor; remove the others or fix= the joint"
            )
        a = acts[0]
        kind = _kind(m, a)
        found = _force_limit(m, a, j)
        if found is None:
            raise ValueError(
                f"the {'motor' if kind == 'motor' else kind + ' actuator'} of joint {jname!r} "
                "declares no force range (ctrlrange of a motor, forcerange, or the joint's "
                "actuatorfrcrange): give the plant the file's path (τmax is then estimated) or "
                "declare one"
            )
        gear = abs(float(m.actuator_gear[a, 0]))
        if kind != "motor" or float(m.actuator_gainprm[a, 0]) != 1.0:
            what = "a motor of gain ≠ 1" if kind == "motor" else _servo(m, a, kind)
            converted[jname] = f"actuator {obj_name(m, OBJ.mjOBJ_ACTUATOR, a)!r} ({what}) → motor"
        m.actuator_dyntype[a] = int(mujoco.mjtDyn.mjDYN_NONE)
        m.actuator_gaintype[a] = int(mujoco.mjtGain.mjGAIN_FIXED)
        m.actuator_biastype[a] = int(mujoco.mjtBias.mjBIAS_NONE)
        m.actuator_gainprm[a, :] = 0.0
        m.actuator_gainprm[a, 0] = 1.0
        m.actuator_biasprm[a, :] = 0.0
        m.actuator_gear[a, 0] = gear
        m.actuator_ctrllimited[a] = 1
        m.actuator_ctrlrange[a] = [-found[0] / gear, found[0] / gear]
        m.actuator_forcelimited[a] = 0
        sources[jname] = found[1]
    out.notes["tau_max"] = sources
    if converted:
        out.notes["actuators"] = converted
        out.warnings.append(
            f"the actuators of {list(converted)} are servos, not torque motors: the plant drives "
            "these joints with torque motors of the same force range (their forcerange where "
            "declared), as the controller commands torque; the model given is not changed"
        )
    return out


# ---------------------------------------------------------------------------


def end_effector(m: mujoco.MjModel, tip: str) -> tuple[int, int]:
    """The end effector ``tip`` as (site id or −1, body): a site (a site first
    if a body has the name too, ``site#i`` for an unnamed one), or a body (its
    origin; a link of the core's tree, :func:`_body_of`). ``tip`` is the one
    asked for, or the one the core's reduction found (:func:`arm_of`'s
    ``"tip"``: the site of a force sensor a hinge of the arm moves, else the
    first site on the last arm joint's body, else that body; SPEC (21.2)).

    Raises
    ------
    ValueError
        Neither a site nor a body has the name (:func:`resolve_tip`'s message).
    """
    sid = mujoco.mj_name2id(m, OBJ.mjOBJ_SITE, tip)
    if sid < 0 and tip.startswith("site#") and tip[5:].isdigit() and int(tip[5:]) < m.nsite:
        sid = int(tip[5:])
    if sid >= 0:
        return sid, int(m.site_bodyid[sid])
    body = _body_of(m, tip)
    if body > 0:
        return -1, body
    resolve_tip(m, tip)  # raises, naming the bodies
    raise AssertionError("unreachable")
