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
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

FIRST_ORDER_STEP = 2.5e-4
"""The largest MuJoCo timestep (s) of a file's model integrated to first order
(Euler, implicit, implicitfast): :func:`adaptimp.mujoco.simulate` then takes
4 MuJoCo steps per 1 ms period. The rule's velocity loop moves a quarter of
its error per period (SPEC 18.1); integrated once a period, the plant's
error is of the size of what learning removes (dm_control's Kinova: SF/PD
0.225 at one Euler step per period, 0.134 at 2, 0.103 at 4, 0.088 with RK4).
A file's RK4 keeps its timestep."""

_OBJ = mujoco.mjtObj
_HINGE = int(mujoco.mjtJoint.mjJNT_HINGE)
_SLIDE = int(mujoco.mjtJoint.mjJNT_SLIDE)
_JOINT_TRN = (int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT))


def _name(m: mujoco.MjModel, objtype: Any, i: int) -> str:
    return mujoco.mj_id2name(m, objtype, i) or f"#{i}"


# ---------------------------------------------------------------------------
# The arm's joints.
# ---------------------------------------------------------------------------


def _ancestors(m: mujoco.MjModel, body: int) -> list[int]:
    out = []
    while body > 0:
        body = int(m.body_parentid[body])
        out.append(body)
    return out


def _root(m: mujoco.MjModel, body: int) -> int:
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
    sid = mujoco.mj_name2id(m, _OBJ.mjOBJ_SITE, tip)
    if sid >= 0:
        return int(m.site_bodyid[sid]), "site"
    bid = mujoco.mj_name2id(m, _OBJ.mjOBJ_BODY, tip)
    if bid > 0:
        return bid, "body"
    bodies = [_name(m, _OBJ.mjOBJ_BODY, b) for b in range(1, m.nbody)]
    raise ValueError(
        f"tip={tip!r}: the model has no site or body of that name (bodies: "
        f"{', '.join(bodies[:40])}{', …' if len(bodies) > 40 else ''})"
    )


def _body_of(m: mujoco.MjModel, link: str) -> int:
    """The MuJoCo body of a link of the core's tree: a body's name, ``body#i``
    for an unnamed one, ``BODY:JOINT`` between two joints of one body."""
    for name in (link, link.rpartition(":")[0]):
        b = mujoco.mj_name2id(m, _OBJ.mjOBJ_BODY, name)
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
    else the body of the last arm joint), and why every other joint is not
    the arm's (asked, mimic or coupled, a gripper's drive or jaw, in a hand,
    prismatic, off the chain).

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
        site = mujoco.mj_name2id(m, _OBJ.mjOBJ_SITE, arm.tip)
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
    roots = {_root(m, int(m.jnt_bodyid[j])) for j in joint_ids}
    return frozenset(b for b in range(1, m.nbody) if _root(m, b) in roots)


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
    name = _name(m, _OBJ.mjOBJ_ACTUATOR, a)
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
        jname = _name(m, _OBJ.mjOBJ_JOINT, joint)
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
    # are final (:func:`_restore_keys`).
    keys = _file_keys(spec, m0)
    if lock:
        _lock(spec, m0, lock, keep, spec_actuators)
        reasons = {
            _name(m0, _OBJ.mjOBJ_JOINT, j): arm["fixed"].get(
                _name(m0, _OBJ.mjOBJ_JOINT, j), "not a hinge of the arm"
            )
            for j in lock
        }
        out.notes["locked"] = reasons
        out.notes["locked_bodies"] = {
            _name(m0, _OBJ.mjOBJ_JOINT, j): _name(m0, _OBJ.mjOBJ_BODY, int(m0.jnt_bodyid[j]))
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
    holds = holding(m1, [mujoco.mj_name2id(m1, _OBJ.mjOBJ_JOINT, n) for n in arm["joints"]])
    if holds:
        equalities = list(spec.equalities)
        for k in holds:
            equalities[k].active = False
        _note_holds(m1, holds, out, label)
        m1 = _compile(spec)
    if keys:
        _restore_keys(spec, m1, keys, set(arm["joints"]))
        m1 = _compile(spec)
    _estimate_missing(spec, m1, out, label)
    out.model = spec.compile() if out.notes.get("estimated") else m1
    return out


@dataclass
class _Key:
    """A keyframe of the file, by name: every joint's qpos and qvel, every
    actuator's ctrl and act, every mocap body's mpos and mquat."""

    name: str
    time: float
    qpos: dict[str, FloatArray]
    qvel: dict[str, FloatArray]
    ctrl: dict[str, float]
    act: dict[str, FloatArray]
    mpos: dict[str, FloatArray]
    mquat: dict[str, FloatArray]


def _file_keys(spec: Any, m0: mujoco.MjModel) -> list[_Key]:
    """The keyframes of ``m0`` (compiled from ``spec``) by name, removed from
    ``spec``: the plant's edits (joints locked, actuators made motors or
    removed) change the keyframes' layout, and MuJoCo's compiler checks their
    sizes, not their meaning."""
    out = []
    for k in range(m0.nkey):
        qpos, qvel, act = {}, {}, {}
        for j in range(m0.njnt):
            name = _name(m0, _OBJ.mjOBJ_JOINT, j)
            qa, da = int(m0.jnt_qposadr[j]), int(m0.jnt_dofadr[j])
            qpos[name] = np.array(m0.key_qpos[k, qa : qa + _nq(m0, j)])
            qvel[name] = np.array(m0.key_qvel[k, da : da + _nv(m0, j)])
        for a in range(m0.nu):
            adr, num = int(m0.actuator_actadr[a]), int(m0.actuator_actnum[a])
            if adr >= 0 and num > 0:
                act[_name(m0, _OBJ.mjOBJ_ACTUATOR, a)] = np.array(m0.key_act[k, adr : adr + num])
        mocap = [b for b in range(m0.nbody) if int(m0.body_mocapid[b]) >= 0]
        out.append(
            _Key(
                name=_name(m0, _OBJ.mjOBJ_KEY, k)
                if mujoco.mj_id2name(m0, _OBJ.mjOBJ_KEY, k)
                else "",
                time=float(m0.key_time[k]),
                qpos=qpos,
                qvel=qvel,
                ctrl={
                    _name(m0, _OBJ.mjOBJ_ACTUATOR, a): float(m0.key_ctrl[k, a])
                    for a in range(m0.nu)
                },
                act=act,
                mpos={
                    _name(m0, _OBJ.mjOBJ_BODY, b): np.array(m0.key_mpos[k, 3 * i : 3 * i + 3])
                    for b in mocap
                    for i in [int(m0.body_mocapid[b])]
                },
                mquat={
                    _name(m0, _OBJ.mjOBJ_BODY, b): np.array(m0.key_mquat[k, 4 * i : 4 * i + 4])
                    for b in mocap
                    for i in [int(m0.body_mocapid[b])]
                },
            )
        )
    for key in list(spec.keys):
        spec.delete(key)
    # <size nkey> reserves keyframes, which a compile adds to the spec as
    # blank ones: the file's (blank ones too) are all in ``out``.
    spec.nkey = 0
    return out


def _restore_keys(spec: Any, m: mujoco.MjModel, keys: Sequence[_Key], arm: set[str]) -> None:
    """The file's keyframes in ``spec``, laid out for ``m`` (compiled from it
    without keyframes): each joint, actuator and mocap body that ``m`` keeps
    has the file's values; a locked joint has gone with its entries; the arm's
    motors start at zero torque (the controller commands them)."""
    mocap = [b for b in range(m.nbody) if int(m.body_mocapid[b]) >= 0]
    for key in keys:
        qpos, qvel = np.array(m.qpos0), np.zeros(m.nv)
        for j in range(m.njnt):
            name = _name(m, _OBJ.mjOBJ_JOINT, j)
            if name in key.qpos and key.qpos[name].size == _nq(m, j):
                qa, da = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
                qpos[qa : qa + _nq(m, j)] = key.qpos[name]
                qvel[da : da + _nv(m, j)] = key.qvel[name]
        ctrl, act = np.zeros(m.nu), np.zeros(m.na)
        for a in range(m.nu):
            name = _name(m, _OBJ.mjOBJ_ACTUATOR, a)
            target = int(m.actuator_trnid[a, 0])
            motor = int(m.actuator_trntype[a]) in _JOINT_TRN and (
                _name(m, _OBJ.mjOBJ_JOINT, target) in arm
            )
            if not motor:
                ctrl[a] = key.ctrl.get(name, 0.0)
            adr, num = int(m.actuator_actadr[a]), int(m.actuator_actnum[a])
            if adr >= 0 and not motor and name in key.act and key.act[name].size == num > 0:
                act[adr : adr + num] = key.act[name]
        mpos, mquat = np.zeros(3 * m.nmocap), np.zeros(4 * m.nmocap)
        for b in mocap:
            i, name = int(m.body_mocapid[b]), _name(m, _OBJ.mjOBJ_BODY, b)
            mpos[3 * i : 3 * i + 3] = key.mpos.get(name, m.body_pos[b])
            mquat[4 * i : 4 * i + 4] = key.mquat.get(name, m.body_quat[b])
        spec.add_key(
            name=key.name,
            time=key.time,
            qpos=qpos.tolist(),
            qvel=qvel.tolist(),
            ctrl=ctrl.tolist(),
            act=act.tolist(),
            mpos=mpos.tolist(),
            mquat=mquat.tolist(),
        )


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
        name = _name(m, _OBJ.mjOBJ_EQUALITY, k)
        pairs[name] = f"{_name(m, _OBJ.mjOBJ_BODY, a)!r} to {_name(m, _OBJ.mjOBJ_BODY, b)!r}"
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
    if objtype == int(_OBJ.mjOBJ_SITE):
        return int(m.site_bodyid[a]), int(m.site_bodyid[b]) if b >= 0 else 0
    if objtype == int(_OBJ.mjOBJ_BODY):
        return a, max(b, 0)
    return None


def _lock(
    spec: Any, m0: mujoco.MjModel, lock: Sequence[int], keep: set[int], actuators_of: list[Any]
) -> None:
    """Remove the joints ``lock`` of ``m0`` from ``spec`` (their bodies then sit
    at the joints' reference position), with the actuators, tendons, equality
    constraints and sensors that use them (the keyframes are laid out again
    afterwards, :func:`_restore_keys`)."""
    joints = {_name(m0, _OBJ.mjOBJ_JOINT, j) for j in lock}
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
                f"the tendon {_name(m0, _OBJ.mjOBJ_TENDON, t)!r} couples the arm's joint(s) "
                f"{[_name(m0, _OBJ.mjOBJ_JOINT, j) for j in wrapped if j in keep]} with "
                f"{[_name(m0, _OBJ.mjOBJ_JOINT, j) for j in hit]}, which are not the arm's: "
                "the plant cannot lock them apart; name the arm with tip= or fix="
            )
        if hit:
            tendons.add(_name(m0, _OBJ.mjOBJ_TENDON, t))
    actuators: set[str] = set()
    dropped: list[int] = []
    for a in range(m0.nu):
        trn, target = int(m0.actuator_trntype[a]), int(m0.actuator_trnid[a, 0])
        if (trn in _JOINT_TRN and target in lock) or (
            trn == int(mujoco.mjtTrn.mjTRN_TENDON)
            and _name(m0, _OBJ.mjOBJ_TENDON, target) in tendons
        ):
            actuators.add(_name(m0, _OBJ.mjOBJ_ACTUATOR, a))
            dropped.append(a)
    for s in list(spec.sensors):
        objtype, obj = int(s.objtype), s.objname
        if (
            (objtype == int(_OBJ.mjOBJ_JOINT) and obj in joints)
            or (objtype == int(_OBJ.mjOBJ_TENDON) and obj in tendons)
            or (objtype == int(_OBJ.mjOBJ_ACTUATOR) and obj in actuators)
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


def _nq(m: mujoco.MjModel, j: int) -> int:
    return {0: 7, 1: 4}.get(int(m.jnt_type[j]), 1)


def _nv(m: mujoco.MjModel, j: int) -> int:
    return {0: 6, 1: 3}.get(int(m.jnt_type[j]), 1)


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
        if int(m0.actuator_trntype[a]) in _JOINT_TRN and target in by_joint:
            by_joint[target].append(a)
    converted: dict[str, str] = {}
    kinds: set[str] = set()
    added: list[str] = []
    estimated: list[str] = []
    sources: dict[str, str] = {}
    for j in arm["joint_ids"]:
        jname = _name(m0, _OBJ.mjOBJ_JOINT, j)
        acts = by_joint[j]
        if len(acts) > 1:
            raise ValueError(
                f"{label}joint {jname!r} has {len(acts)} actuators "
                f"({', '.join(repr(_name(m0, _OBJ.mjOBJ_ACTUATOR, a)) for a in acts)}): the plant "
                "drives each arm joint with one torque motor; remove the others or fix= the joint"
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
                servo, name = _servo(m0, a, kind), _name(m0, _OBJ.mjOBJ_ACTUATOR, a)
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
            lo, hi, f"the actuatorfrcrange of joint {_name(m, _OBJ.mjOBJ_JOINT, j)!r}"
        )
    return None


def _estimate_missing(spec: Any, m1: mujoco.MjModel, out: Prepared, label: str) -> None:
    """τmax estimated (:func:`estimate`) for the joints in ``out.notes["estimated"]``,
    written into ``spec``'s motors."""
    missing: list[str] = out.notes.get("estimated", [])
    if not missing:
        return
    ids = [mujoco.mj_name2id(m1, _OBJ.mjOBJ_JOINT, n) for n in out.arm["joints"]]
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
            f"joints {[_name(m, _OBJ.mjOBJ_JOINT, j) for j in extra]} of the arm's body tree are "
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
        if int(m.actuator_trntype[a]) in _JOINT_TRN and int(m.actuator_trnid[a, 0]) in by_joint:
            by_joint[int(m.actuator_trnid[a, 0])].append(a)
    for j in arm["joint_ids"]:
        jname = _name(m, _OBJ.mjOBJ_JOINT, j)
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
            converted[jname] = f"actuator {_name(m, _OBJ.mjOBJ_ACTUATOR, a)!r} ({what}) → motor"
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
# Contacts the arm's motion makes.
# ---------------------------------------------------------------------------


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
        pair = sorted((_name(m, _OBJ.mjOBJ_BODY, b1), _name(m, _OBJ.mjOBJ_BODY, b2)))
        out.append((pair[0], pair[1], float(c.dist)))
    return out


def end_effector(m: mujoco.MjModel, tip: str) -> tuple[int, int]:
    """The end effector ``tip`` as (site id or −1, body): a site (a site first
    if a body has the name too, ``site#i`` for an unnamed one), or a body (its
    origin; a link of the core's tree, :func:`_body_of`). ``tip`` is the one
    asked for, or the one the core's reduction found (:func:`arm_of`'s
    ``"tip"``: the site of a force sensor a hinge of the arm moves, else the
    body of the last arm joint; SPEC (21.2)).

    Raises
    ------
    ValueError
        Neither a site nor a body has the name (:func:`resolve_tip`'s message).
    """
    sid = mujoco.mj_name2id(m, _OBJ.mjOBJ_SITE, tip)
    if sid < 0 and tip.startswith("site#") and tip[5:].isdigit() and int(tip[5:]) < m.nsite:
        sid = int(tip[5:])
    if sid >= 0:
        return sid, int(m.site_bodyid[sid])
    body = _body_of(m, tip)
    if body > 0:
        return -1, body
    resolve_tip(m, tip)  # raises, naming the bodies
    raise AssertionError("unreachable")


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
        ia, ib = (mujoco.mj_name2id(m, _OBJ.mjOBJ_BODY, n) for n in (a, b))
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
        roots.setdefault(_root(m, o) if o > 0 else 0, []).append(o)
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
            objtype=_OBJ.mjOBJ_BODY,
            objname=_name(m, _OBJ.mjOBJ_BODY, a),
            reftype=_OBJ.mjOBJ_XBODY if subtree else _OBJ.mjOBJ_BODY,
            refname="world" if o == 0 else _name(m, _OBJ.mjOBJ_BODY, o),
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
            if (mujoco.mj_id2name(m, _OBJ.mjOBJ_SENSOR, s) or "").startswith(WATCH)
            and int(m.sensor_type[s]) == int(mujoco.mjtSensor.mjSENS_CONTACT)
        ]
        if not ids or m.nuserdata < 3 * len(ids):
            return None
        return Watch(
            adr=[int(m.sensor_adr[s]) for s in ids],
            pairs=[
                (
                    _name(m, _OBJ.mjOBJ_BODY, int(m.sensor_objid[s])),
                    _name(m, _OBJ.mjOBJ_BODY, int(m.sensor_refid[s])),
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
