"""adaptimp's Cartesian impedance as a robosuite controller: ``ADAPTIMP``.

Needs robosuite ≥ 1.5 and the MuJoCo it runs on (the extra ``robosuite``;
robosuite 1.5.2 runs on MuJoCo 3.3.x). Importing this module registers the
composite controller ``ADAPTIMP`` in robosuite's registry
(``register_composite_controller``); nothing inside robosuite is changed::

    import robosuite as suite
    import adaptimp.robosuite

    config = adaptimp.robosuite.controller_config("Panda")
    env = suite.make("Lift", robots="Panda", controller_configs=config)

(``controller_config(robot)`` is robosuite's own default configuration of the
robot, ``load_composite_controller_config(robot=robot)``, with ``"type":
"ADAPTIMP"``.) Per arm of the robot:

- **The action is OSC_POSE's.** The arm's part configuration stays
  robosuite's (``OSC_POSE`` or ``OSC_POSITION``: ``input_max``,
  ``output_max``, ``input_type``, ``input_ref_frame``…), and robosuite's own
  part controller turns each action into the goal pose, as it does for its
  operational-space controller (the delta clipped and scaled, in the base
  frame, from the pose reached): the same action dimension, limits and
  frames. A script or a policy written for OSC_POSE runs unchanged; the
  gripper keeps robosuite's own part controller, as do a torso, a head, a base.
- **The torque is adaptimp's**: the core's Cartesian controller
  (:meth:`adaptimp.CartesianController.from_rule`, case ``"sf"``) steps
  towards that goal pose, world frame, at the gripper's grip site (the point
  robosuite's OSC controls), at every model timestep (robosuite's controller
  rate, 2 ms by default). It is built by the rule, nothing set per arm, from
  robosuite's compiled model: the chain by :meth:`adaptimp.Chain.from_mujoco`
  (gripper included: its fingers are not on the way to the grip site, so
  they ride on the hand), the inertia D(q) and gravity G(q) the rule sizes
  the joint controller by from MuJoCo's mass matrix (armature included) and
  bias of that same model with the gripper's joints where they are, the
  actuator limits robosuite gives the arm, the period of the model timestep,
  and a loop delay of 0: robosuite computes the torque from the state after
  ``mj_step1`` and applies it in ``mj_step2`` of the same timestep
  (``MujocoEnv.step``). SPEC §23 has the equations and the decisions:
  :func:`impedance` (the target impedance at the joint loop's bandwidth, no
  filter on the goal's jumps, which are robosuite's by design), the wrench
  (:class:`SceneWrench`: contact with the fixed scene, filtered over one
  policy period, no feedforward).
- ``reset()``: robosuite builds its controllers anew at every
  ``env.reset()``, and so does ADAPTIMP (the networks start from zero, the
  outer loop at the arm's posture). ``reset_goal()`` (robosuite's
  ``composite_controller.reset()``) holds the pose reached, as OSC's does, and
  restarts the outer loop at the measured posture (the networks keep what
  they learnt).

Per-arm options (the ``"adaptimp"`` entry of the arm's part configuration,
:func:`controller_config`'s keywords): ``case`` ("sf", "pd", "of"),
``stiffness`` ("osc", the default: OSC_POSE's stiffness per axis at the
start posture, diag(Λ) k_p, at the joint loop's bandwidth K1,
:func:`osc_stiffness`, SPEC (23.1), (23.6); "rule": K_d = M_d K1² with the
schema's M_d), and any
parameter of :class:`adaptimp.CartesianController` (``Kd``, ``Md``,
``force_filter``, ``gamma``, …), which replaces the rule's.

Units: m, rad, s, N, N m; vectors in the world frame.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._errors import ConfigError, PlantWarning, needs_extra

try:
    import mujoco
    from robosuite.controllers import controller_factory, load_composite_controller_config
    from robosuite.controllers.composite.composite_controller import (
        CompositeController,
        register_composite_controller,
    )
except ImportError as e:  # pragma: no cover - depends on the environment
    raise needs_extra("adaptimp.robosuite", "robosuite>=1.5", "robosuite") from e

from . import _adaptimp, tuning
from ._adaptimp import Measurement
from ._cartesian_task import CirclePath
from ._description import read_arm
from ._params import defaults
from .cartesian import CartesianController
from .chain import Chain

__all__ = [
    "ARM_TYPES",
    "NAME",
    "AdaptimpComposite",
    "ArmController",
    "SceneWrench",
    "arm_chain",
    "controller_config",
    "held_joints",
    "impedance",
    "osc_stiffness",
]

FloatArray = NDArray[np.float64]

NAME = "ADAPTIMP"
"""The composite controller's name in robosuite's registry (a configuration's ``"type"``)."""

ARM_TYPES = ("OSC_POSE", "OSC_POSITION")
"""The arm part types whose actions ADAPTIMP takes."""

STIFFNESS = ("osc", "rule")
"""The option ``stiffness``: ``"osc"`` (the default) OSC_POSE's stiffness per
axis at the start posture, at the joint loop's bandwidth (SPEC (23.6));
``"rule"`` that bandwidth with the schema's target inertia (SPEC (23.1))."""


def controller_config(robot: str, **params: Any) -> dict[str, Any]:
    """robosuite's own default controller configuration of ``robot`` (as
    ``load_composite_controller_config(robot=robot)`` loads it) with the
    composite type ADAPTIMP: the arms' OSC_POSE parts, and so the actions,
    unchanged. ``params`` go to every arm's adaptimp controller (its part's
    ``"adaptimp"`` entry): ``case`` and the parameters of
    :class:`adaptimp.CartesianController`."""
    config: dict[str, Any] = load_composite_controller_config(robot=robot)
    config["type"] = NAME
    if params:
        for part in config["body_parts"].values():
            if isinstance(part, dict) and part.get("type") in ARM_TYPES:
                part["adaptimp"] = dict(params)
    return config


def impedance(
    k1: float, policy_period: float, stiffness: ArrayLike | None = None
) -> dict[str, Any]:
    """The Cartesian parameters ADAPTIMP gives the rule (SPEC (23.1)–(23.3)),
    for a joint loop whose position gain is ``k1`` (1/s, the rule's K1) under
    a policy that sets a goal every ``policy_period`` (s):

    - the target impedance at the joint loop's bandwidth, critically damped:
      K_d = M_d K1², K_d,rot = M_d,rot K1² (N/m, N m/rad; M_d, M_d,rot the
      schema's, B_d, B_d,rot critical); with ``stiffness`` (6,), the target
      stiffness per world axis [K_d (N/m) ×3, K_d,rot (N m/rad) ×3] at that
      same bandwidth: M_d = K_d / K1², M_d,rot = K_d,rot / K1² (SPEC (23.6));
    - no filter on the commanded pose (``target_filter = 0``): robosuite's goal
      jumps at every action by design, and OSC takes it as it jumps;
    - the measured wrench filtered over one policy period, and not fed
      forward to the joint law (``force_filter``, ``force_feedforward``)."""
    if stiffness is None:
        d = defaults("robot")
        md = np.asarray(d["Md"], dtype=np.float64)
        mr = np.asarray(d["Md_rot"], dtype=np.float64)
        kd, kr = md * k1 * k1, mr * k1 * k1
    else:
        k = np.asarray(stiffness, dtype=np.float64)
        if k.shape != (6,) or not np.all(np.isfinite(k)) or np.any(k <= 0.0):
            raise ConfigError(f"{NAME}: stiffness must be 6 positive numbers, got {stiffness!r}")
        kd, kr = k[:3], k[3:]
        md, mr = kd / (k1 * k1), kr / (k1 * k1)
    out: dict[str, Any] = {"Kd": kd.tolist(), "Kd_rot": kr.tolist()}
    if stiffness is not None:
        out.update(Md=md.tolist(), Md_rot=mr.tolist())
    out.update(target_filter=0.0, force_filter=float(policy_period), force_feedforward=False)
    return out


def osc_stiffness(
    jacobian: ArrayLike, inertia: ArrayLike, kp: ArrayLike, *, uncoupled: bool = True
) -> FloatArray:
    """The stiffness per world axis (N/m ×3, N m/rad ×3), (6,), of robosuite's
    operational-space controller OSC_POSE at a posture (SPEC (23.6)):
    diag(Λ) k_p, Λ its operational-space inertia on the arm's inertia D(q)
    (kg m², (n, n)) and the grip site's geometric Jacobian [J_v; J_ω] (6, n):
    Λ_v = (J_v D⁻¹ J_vᵀ)⁻¹ and Λ_ω = (J_ω D⁻¹ J_ωᵀ)⁻¹ when ``uncoupled`` (OSC's
    ``uncouple_pos_ori``, its default), Λ = (J D⁻¹ Jᵀ)⁻¹ otherwise; ``kp``
    OSC's stiffness gains (1/s², a number or 6). The inverses are
    pseudo-inverses as robosuite's ``opspace_matrices`` takes them, in the
    core (SPEC (23.7)); a D that is not finite, symmetric and positive
    definite raises ConfigError."""
    J = np.asarray(jacobian, dtype=np.float64)
    D = np.asarray(inertia, dtype=np.float64)
    lam = np.diag(_adaptimp.operational_inertia(J, D, uncoupled))
    gains = np.broadcast_to(np.asarray(kp, dtype=np.float64), (6,))
    return np.asarray(lam * gains, dtype=np.float64)


class _ArmModel:
    """The inertia D(q) (kg m², (n, n)) and gravity G(q) (N m, (n,)) of an arm
    of a compiled MuJoCo model, as the rule reads a model
    (:func:`adaptimp.tuning.inertia`): MuJoCo's mass matrix (armature
    included) and bias at rest, on a state of its own in which every other
    joint (a gripper's fingers, the scene's objects) stays where ``data`` has it."""

    def __init__(self, model: Any, data: Any, qpos: ArrayLike, dofs: ArrayLike) -> None:
        self._m = model
        self._d = mujoco.MjData(model)
        self._d.qpos[:] = data.qpos
        self._qpos = np.asarray(qpos, dtype=np.intp)
        self._dofs = np.asarray(dofs, dtype=np.intp)
        self._full = np.zeros((model.nv, model.nv))

    def _at(self, q: ArrayLike) -> None:
        self._d.qpos[self._qpos] = q
        self._d.qvel[:] = 0.0
        mujoco.mj_forward(self._m, self._d)

    def D(self, q: ArrayLike) -> FloatArray:
        """D(q) (kg m²), (n, n)."""
        self._at(q)
        mujoco.mj_fullM(self._m, self._full, self._d.qM)
        return np.array(self._full[np.ix_(self._dofs, self._dofs)], dtype=np.float64)

    def G(self, q: ArrayLike) -> FloatArray:
        """G(q) (N m), (n,)."""
        self._at(q)
        return np.array(self._d.qfrc_bias[self._dofs], dtype=np.float64)


def held_joints(model: Any, data: Any, joints: ArrayLike) -> dict[int, str]:
    """The arm joints (ids among ``joints``) that a contact of the arm with
    itself pins where it stands (SPEC (23.5)): a contact, in ``data``'s
    contact list, between two bodies of the arm (its base and everything
    below it) on either side of the joint in the kinematic tree. Such a joint
    cannot turn without sliding that contact: robosuite's Sawyer stands with
    its first link on its base (MuJoCo does not filter a contact with a parent
    welded to the world), and 80 N m turn it by 0.4 mrad in 1 s. Returns
    {joint id: the contact's bodies}."""
    ids = [int(j) for j in np.asarray(joints).ravel()]
    parent = np.asarray(model.body_parentid)
    base = int(parent[int(model.jnt_bodyid[ids[0]])])
    arm = _subtree(model, base)

    def above(b: int) -> set[int]:
        out = {b}
        while b > 0:
            b = int(parent[b])
            out.add(b)
        return out

    held: dict[int, str] = {}
    for i in range(data.ncon):
        a, b = (int(model.geom_bodyid[g]) for g in data.contact.geom[i])
        if not (arm[a] and arm[b]):
            continue
        path_a, path_b = above(a), above(b)
        for j in ids:
            if (int(model.jnt_bodyid[j]) in path_a) != (int(model.jnt_bodyid[j]) in path_b):
                held.setdefault(j, " and ".join(_body_name(model, x) for x in (a, b)))
    return held


def arm_chain(model: Any, site: str, held: Mapping[str, float] | None = None) -> Chain:
    """The chain of a compiled MuJoCo model's arm to ``site``
    (:meth:`adaptimp.Chain.from_mujoco`), with the joints named in ``held``
    held at the given values (rad or m): each folds into the next joint's
    origin as a fixed joint turned (or slid) by its value from its reference."""
    if not held:
        return Chain.from_mujoco(model, site)
    arm = read_arm(model, site)
    joints: list[dict[str, Any]] = []
    names: list[str] = []
    for name, joint in zip(arm.joints, arm.chain):
        if name not in held:
            joints.append(joint)
            names.append(name)
            continue
        axis = np.asarray(joint["axis"], dtype=np.float64)
        axis = axis / np.linalg.norm(axis)
        shift = float(held[name]) - float(joint.get("offset", 0.0))
        joints.append({**{k: v for k, v in joint.items() if k not in ("axis", "offset")},
                       "kind": "fixed"})  # fmt: skip
        if joint["kind"] == "prismatic":
            joints.append({"kind": "fixed", "translation": (shift * axis).tolist()})
        else:  # the turn about the axis, as a quaternion [w, x, y, z]
            half = 0.5 * shift
            joints.append({"kind": "fixed", "quat": [math.cos(half), *(math.sin(half) * axis)]})
    chain = Chain(joints, arm.tip_origin, names=names, source=f"MuJoCo model to site {site!r}")
    chain.fixed = {**arm.fixed, **{n: f"held at {held[n]:.6g}" for n in held}}
    return chain


def _body_name(model: Any, b: int) -> str:
    return mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or f"body {b}"


def _subtree(model: Any, top: int) -> NDArray[np.bool_]:
    """Which bodies are ``top`` or below it."""
    parent = np.asarray(model.body_parentid)
    inside = np.zeros(model.nbody, dtype=bool)
    for b in range(model.nbody):
        c = b
        while c > 0 and c != top:
            c = int(parent[c])
        inside[b] = c == top
    return inside


_PAIR = np.array([3, 1])  # a contact's (code1, code2) · _PAIR (SceneWrench)
_SIDE = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0])  # +1 at 5, −1 at 7
_XYZ = np.arange(3)
# (r × f)_i = r_{i+1} f_{i+2} − r_{i+2} f_{i+1}, for i = 0, 1, 2
_NEXT, _LAST = np.array([1, 2, 0]), np.array([2, 0, 1])


class SceneWrench:
    """The wrench F_e = [f; m] (N, N m), (6,), that the end effector exerts on
    the fixed scene, world frame, the moment about the grip site (SPEC
    (23.4)): the sum of MuJoCo's contact forces (``mj_contactForce``) between
    the end effector (the body of the arm's last joint and everything below
    it: hand and gripper) and the bodies welded to the world (a table, a
    wall). A free object in the gripper (a cube) is a load the arm carries,
    which the networks learn, not a wrench to comply with.

    robosuite runs its controllers between ``mj_step1`` and ``mj_step2``: the
    contacts are the timestep's (their Jacobian and reference acceleration
    made by ``mj_step1``), their forces not yet solved. This does not solve
    them: it evaluates them (``mj_constraintUpdate``) at the acceleration
    MuJoCo solved at the last timestep and keeps for its warm start
    (``qacc_warmstart``; after a reset, before any step, the reset's
    ``mj_forward``'s ``qacc``), the forces the last solve's acceleration
    gives the timestep's contacts; ``mj_step2`` solves them once, as without ADAPTIMP."""

    def __init__(self, model: Any, data: Any, last_joint: int, site: int) -> None:
        self._m, self._d, self._site = model, data, site
        body = np.asarray(model.geom_bodyid)
        ee = _subtree(model, int(model.jnt_bodyid[last_joint]))[body]
        fixed = (np.asarray(model.body_weldid) == 0)[body]
        # Per geom: 1 on the end effector, 2 welded to the world, 0 else; a
        # contact's pair (geom1, geom2) is 3 code1 + code2: 5 the end effector
        # first, 7 second.
        self._code = np.where(ee, 1, np.where(fixed, 2, 0)).astype(np.intp)
        self._elliptic = int(model.opt.cone) == int(mujoco.mjtCone.mjCONE_ELLIPTIC)
        self.wrench = np.zeros(6)
        """The last wrench (N, N m), (6,): read it, do not keep it (overwritten)."""

    def _local(self, contact: Any, hits: NDArray[np.intp], force: FloatArray) -> FloatArray:
        """The contacts' forces (N), (k, 3), in their frames: normal, tangents
        (``mj_contactForce``'s, read from ``force``, MuJoCo's efc_force, for
        the contacts ``hits`` at once: an elliptic cone's rows are the force,
        a pyramid's edges decode as ``mju_decodePyramid`` does)."""
        adr = np.asarray(contact.efc_address[hits], dtype=np.intp)
        dim = np.asarray(contact.dim[hits], dtype=np.intp)
        if self._elliptic and dim.min() >= 3 and adr.min() >= 0:
            return np.asarray(force[adr[:, None] + _XYZ], dtype=np.float64)  # its first 3 rows
        on = adr >= 0  # a contact without constraint rows exerts nothing
        if force.size == 0:
            return np.zeros((hits.size, 3))
        last = force.size - 1
        out = np.zeros((hits.size, 3))
        if self._elliptic:
            rows = np.minimum(adr[:, None] + np.arange(3), last)
            out[:] = np.where(np.arange(3) < np.minimum(dim, 3)[:, None], force[rows], 0.0)
        else:
            edges = 2 * (dim - 1)
            width = max(int(edges.max()), 1)
            rows = np.minimum(adr[:, None] + np.arange(width), last)
            p = np.where(np.arange(width) < edges[:, None], force[rows], 0.0)
            out[:, 0] = np.where(dim == 1, force[np.minimum(adr, last)], p.sum(axis=1))
            if width >= 2:
                mu = np.asarray(contact.friction[hits], dtype=np.float64)
                out[:, 1] = (p[:, 0] - p[:, 1]) * mu[:, 0]
                if width >= 4:
                    out[:, 2] = (p[:, 2] - p[:, 3]) * mu[:, 1]
        out[~on] = 0.0
        return out

    def __call__(self) -> FloatArray:
        """F_e now (N, N m), (6,)."""
        m, d, w = self._m, self._d, self.wrench
        w[:] = 0.0
        if d.ncon == 0:
            return w
        contact = d.contact
        side = _SIDE[self._code[contact.geom] @ _PAIR]
        hits = np.flatnonzero(side)
        if hits.size == 0:
            return w
        # jar = J a − a_ref at the last solve's acceleration a (SPEC (23.4')):
        # mj_step2's, kept for the warm start; before the first step after a
        # reset (a warm start of zeros), the reset's mj_forward's (qacc).
        acc = d.qacc_warmstart if d.qacc_warmstart.any() else d.qacc
        jar = np.empty(d.nefc)
        mujoco.mj_mulJacVec(m, d, jar, acc)
        jar -= d.efc_aref
        mujoco.mj_constraintUpdate(m, d, jar, None, 0)
        local = self._local(contact, hits, d.efc_force)
        # The force on geom2 in the world frame (the frame's rows are the
        # contact's axes, the normal from geom1 to geom2): what the end
        # effector exerts when it is geom1, the opposite when it is geom2.
        f = np.einsum("kji,kj,k->ki", contact.frame[hits].reshape(-1, 3, 3), local, side[hits])
        w[:3] = f.sum(axis=0)
        r = contact.pos[hits] - d.site_xpos[self._site]
        rf = r.T @ f  # Σ r × f = (S_12 − S_21, S_20 − S_02, S_01 − S_10), S = Σ r fᵀ
        w[3:] = rf[_NEXT, _LAST] - rf[_LAST, _NEXT]
        return w


class ArmController:
    """One arm of ADAPTIMP: robosuite's OSC part controller ``osc`` reads the
    action into the goal pose; adaptimp's Cartesian controller :attr:`ctrl`
    computes the torque. Every attribute but the ones below is ``osc``'s (the
    goal, the reference pose, the limits robosuite reads).

    Parameters
    ----------
    osc : robosuite OperationalSpaceController
        The arm's part controller as robosuite's ``controller_factory`` makes it.
    params : dict, optional
        ``case`` and :class:`adaptimp.CartesianController` parameters replacing
        the rule's.
    """

    def __init__(self, osc: Any, params: Mapping[str, Any] | None = None) -> None:
        self.osc = osc
        sim = osc.sim
        self._model, self._data = sim.model._model, sim.data._data
        m = self._model
        self.held = {
            mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) or f"joint {j}": bodies
            for j, bodies in held_joints(m, self._data, osc.joint_index).items()
        }
        """The arm's joints a contact of the arm with itself pins, and the
        contact's bodies (:func:`held_joints`): held, the chain without them,
        no torque."""
        for name, bodies in self.held.items():
            warnings.warn(
                f"{NAME}: the arm touches itself across joint {name!r} ({bodies}), which "
                "cannot turn without sliding that contact: the joint is held where it "
                "stands (no torque), the arm's other joints do the task",
                PlantWarning,
                stacklevel=4,
            )
        names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(j)) for j in osc.joint_index]
        self._active = np.array([n not in self.held for n in names])
        self._qpos = np.asarray(osc.qpos_index, dtype=np.intp)[self._active]
        self._qvel = np.asarray(osc.qvel_index, dtype=np.intp)[self._active]
        self._tau = np.zeros(len(names))
        self.params = dict(params or {})
        self.ctrl = self._build()
        """The arm's :class:`adaptimp.CartesianController`."""
        site = mujoco.mj_name2id(self._model, mujoco.mjtObj.mjOBJ_SITE, osc.ref_name)
        self.wrench = SceneWrench(self._model, self._data, int(osc.joint_index[-1]), site)
        """The arm's :class:`SceneWrench`."""

    def _build(self) -> CartesianController:
        m, d, osc = self._model, self._data, self.osc
        joint = mujoco.mjtObj.mjOBJ_JOINT
        where = {n: float(d.qpos[m.jnt_qposadr[mujoco.mj_name2id(m, joint, n)]]) for n in self.held}
        chain = arm_chain(m, osc.ref_name, where)
        names = [
            mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(j))
            for j, on in zip(osc.joint_index, self._active)
            if on
        ]
        if chain.joint_names != names:
            raise ConfigError(
                f"robosuite's arm joints {names} are not the chain to its grip site "
                f"{osc.ref_name!r} ({chain.joint_names})"
            )
        q0 = np.array(d.qpos[self._qpos], dtype=np.float64)
        model = _ArmModel(m, d, self._qpos, self._qvel)
        tau_max = np.asarray(osc.actuator_max, dtype=np.float64)[self._active]
        Ts = float(m.opt.timestep)
        kw = dict(self.params)
        case = kw.pop("case", "sf")
        stiffness = kw.pop("stiffness", "osc")
        if not (isinstance(stiffness, str) and stiffness in STIFFNESS):
            raise ConfigError(
                f"{NAME}: stiffness must be one of {', '.join(map(repr, STIFFNESS))}, "
                f"got {stiffness!r}"
            )
        # The rule's position gain K1 (one value for every joint, SPEC (18.2)).
        k1 = float(np.min(tuning.suggest(model, q0, tau_max, Ts=Ts, case=case)["K1"]))
        k = None
        if stiffness == "osc":  # OSC_POSE's at the start posture, SPEC (23.6)
            k = osc_stiffness(
                chain.jacobian(q0), model.D(q0), osc.kp, uncoupled=bool(osc.uncoupling)
            )
            if not np.all(k > 0.0):
                raise ConfigError(
                    f"{NAME}: OSC_POSE's stiffness at the start posture is {k.tolist()} "
                    "(N/m, N m/rad): not positive on every axis (a singular posture, or a "
                    "kp of 0); give stiffness='rule' or Kd, Md"
                )
        self.stiffness = None if k is None else k.copy()
        """The matched stiffness per world axis (N/m ×3, N m/rad ×3), (6,),
        with ``stiffness="osc"``; None with the rule's."""
        rule = impedance(k1, 1.0 / float(osc.control_freq), k)
        rule.update(kw)
        ctrl = CartesianController.from_rule(
            chain, case, CirclePath(*chain.pose(q0)), q0, model=model, tau_max=tau_max, Ts=Ts,
            delay=0, **rule,
        )  # fmt: skip
        ctrl.record = False
        return ctrl

    def __getattr__(self, name: str) -> Any:
        if name == "osc":  # not yet set: construction failed
            raise AttributeError(name)
        return getattr(self.osc, name)

    def goal(self) -> tuple[FloatArray, FloatArray]:
        """The goal pose robosuite's OSC derives from the action, world frame:
        the grip site's position (m), (3,), and rotation (world ← site), (3, 3)."""
        o = self.osc
        if o.input_ref_frame == "base":
            return o.origin_pos + o.origin_ori @ o.goal_pos, o.origin_ori @ o.goal_ori
        return np.asarray(o.goal_pos, dtype=np.float64), np.asarray(o.goal_ori, dtype=np.float64)

    def run_controller(self) -> FloatArray:
        """The torque (N m), (n,), of one model timestep towards :meth:`goal`."""
        p, R = self.goal()
        d = self._data
        m = Measurement(d.qpos[self._qpos], d.qvel[self._qvel], wrench=self.wrench())
        tau = self._tau
        tau[self._active] = self.ctrl.step(m, xc=p, R=R)
        out = tau.copy()
        o = self.osc
        o.torques = out
        o.new_update = True  # robosuite reads the state again at the next action, as after OSC
        return out

    def reset_goal(self, *args: Any, **kwargs: Any) -> None:
        """OSC's ``reset_goal`` (the goal: the pose reached, read now), and the
        outer loop restarted at the measured posture."""
        self.osc.update()  # the pose reached (OSC reads it at every step; ADAPTIMP at actions)
        self.osc.reset_goal(*args, **kwargs)
        self.ctrl.outer.reset(np.array(self._data.qpos[self._qpos], dtype=np.float64))

    @property
    def name(self) -> str:
        """``"ADAPTIMP_OSC_POSE"`` (or ``_OSC_POSITION``)."""
        return f"{NAME}_{self.osc.name}"


@register_composite_controller
class AdaptimpComposite(CompositeController):  # type: ignore[misc]
    """robosuite's composite controller with adaptimp on the arms (module doc)."""

    name = NAME

    def _init_controllers(self) -> None:
        for part, params in self.part_controller_config.items():
            kind = params["type"]
            arm = part in self.arms
            if arm:
                _check_arm(part, params)
            own = controller_factory(part_name=part, controller_type=kind, controller_params=params)
            self.part_controllers[part] = ArmController(own, params.get("adaptimp")) if arm else own


def _check_arm(part: str, params: Mapping[str, Any]) -> None:
    """An arm part configuration ADAPTIMP can take, or a ConfigError naming what not."""
    kind = params["type"]
    if kind not in ARM_TYPES:
        raise ConfigError(
            f"{NAME} takes the actions of {' or '.join(ARM_TYPES)} on arm {part!r}, got {kind!r}"
        )
    if params.get("interpolation") not in (None, "null"):
        raise ConfigError(
            f"{NAME} steps towards the goal robosuite's OSC sets at each action; arm {part!r} "
            f"asks for interpolation {params['interpolation']!r} (give null)"
        )
    mode = params.get("impedance_mode", "fixed")
    if mode != "fixed":
        raise ConfigError(
            f"{NAME} sizes its impedance by the rule; arm {part!r} asks for impedance_mode "
            f"{mode!r}, whose actions set OSC's gains (give 'fixed')"
        )
