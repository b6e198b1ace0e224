"""The plant of :mod:`adaptimp.mujoco` and its preparation (SPEC §18):
:class:`Plant` (a MuJoCo model of a serial arm, edited in memory by
:mod:`adaptimp._mjcf`, its end effector, τmax, where the wrench is measured),
what it keeps of the scene (:func:`mocap_welds`, :func:`holding_controls`)
and the settings the core's loop takes from it.

Re-exported by :mod:`adaptimp.mujoco`. Units: rad, rad/s, N, N m, m, s."""

from __future__ import annotations

import contextlib
import math
import os
import warnings
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import _contacts, _mjcf
from ._description import model_name
from ._errors import PlantWarning, no_file
from ._inputs import reals
from ._mjmodel import obj_name
from ._plant_models import MAX_JOINTS, ModelSource, from_urdf, panda, two_link
from ._sampled import _full_inertia

FloatArray = NDArray[np.float64]


def _prepare(source: ModelSource, tip: str | None, fix: tuple[str, ...]) -> _mjcf.Prepared:
    """The plant's model of ``source`` (SPEC §18, ``adaptimp._mjcf``): an MJCF
    file edited in memory (joints that are not the arm's locked, one torque
    motor per arm joint), a URDF through :func:`from_urdf` (``tip`` a link),
    a given ``MjModel`` or a packaged model checked (servos made motors)."""
    if isinstance(source, mujoco.MjModel):
        return _mjcf.prepare_model(source, tip, fix)
    if isinstance(source, mujoco.MjSpec):
        return _mjcf.prepare_spec(source.copy(), tip, fix)
    if isinstance(source, str) and source in _BUILTIN:
        return _mjcf.prepare_model(_BUILTIN[source](), tip, fix)
    path = _model_path(source)
    if path.suffix.lower() in (".urdf", ".xacro"):
        return _mjcf.prepare_model(from_urdf(path, fix=fix, tip=tip), tip, ())
    return _mjcf.prepare_file(path, tip, fix)


def _model_path(source: str | os.PathLike[str]) -> Path:
    path = Path(source)
    if not path.is_file():
        raise no_file(
            f"model must be an MjModel, one of {sorted(_BUILTIN)} or a path to an MJCF or URDF "
            "file",
            path,
        )
    return path


_BUILTIN: dict[str, Callable[[], mujoco.MjModel]] = {"two_link": two_link, "panda": panda}


# ---------------------------------------------------------------------------
# The plant.
# ---------------------------------------------------------------------------


def _source_label(model: object) -> str:
    """``"name.xml: "`` for a model given as a file, else ``""`` (a message's prefix)."""
    if isinstance(model, (str, os.PathLike)) and str(model) not in _BUILTIN:
        return f"{Path(model).name}: "
    return ""


class Plant:
    """A MuJoCo model of a serial arm as the plant of a control loop.

    ``D(q) q̈ + C(q, q̇) q̇ + G(q) = sat(τ) − τe`` with everything MuJoCo adds
    (contact, joint limits, joint damping, armature and friction loss, whatever
    the model declares). The plant owns a copy of the model (``model``) and
    its ``data``.

    A model as its maker ships it (SPEC §18, ``docs/your_arm.md``): the arm is
    the model's serial chain of hinge joints (:func:`adaptimp._mjcf.arm_of`,
    the URDF reduction's rules on MuJoCo's body tree), ending at ``tip`` if
    given. Joints of the arm's own body tree that are not the arm's (a
    gripper's fingers, coupled joints, a slide, a head) are **locked at their
    reference position** (removed from an in-memory copy of the file with
    their actuators, couplings and sensors: the hand is then one rigid body,
    as the controller's model of the arm has it, and no finger swings
    unmodelled on the wrist). Every arm joint is driven by **one torque
    motor**: a ``motor`` as it is; a ``position``, ``velocity`` or
    ``general`` actuator becomes a motor of the same force range (the
    controller commands torque); a joint without one gets one. τmax is gear ×
    the actuator's ``forcerange`` (a motor's ``ctrlrange``), or the joint's
    ``actuatorfrcrange`` if smaller; where nothing declares it, it is
    estimated from the arm, 2 (max |G_i| + 10 rad/s² · max Σ_j |D_ij|) within
    the joint limits. Each change is a :class:`adaptimp.PlantWarning` and an
    entry of :attr:`notes` (``res.params["plant"]``); the file is never
    written. Joints on other body trees (a door, a table on a spring) are the
    environment's and stay as they are.

    Parameters
    ----------
    model : MjModel, MjSpec, str or path
        An ``MjModel``; an ``MjSpec`` (e.g. an arm with a gripper attached; a
        copy is edited); ``"two_link"`` or ``"panda"`` (the packaged models, see
        :func:`two_link`, :func:`panda`); or a path to an MJCF file, or to a
        URDF (compiled by :func:`from_urdf`). A compiled ``MjModel`` cannot
        lose joints or gain actuators: one whose arm tree holds joints that
        are not the arm's, or an arm joint without an actuator, is refused
        (give the file's path instead).
    contact : bool
        False disables every contact (MuJoCo's ``mjDSBL_CONTACT``): free space.
    tip : str, optional
        The end effector, a site or a body (its origin; a site if both have
        the name): the arm is the hinges on the way to it. Default: the core's
        rule (SPEC (21.2)), the site of a force sensor that a hinge of the arm
        moves, else the first site on the last arm joint's body, else that
        body's origin. A URDF's ``tip``
        is a link.
    fix : tuple of str
        Joints to lock as well (at their reference position), by name.
    surface : str or tuple of str
        The bodies a contact task presses on (a table): their contacts with
        the end effector's subtree are the task's own, not watched. Every
        other contact of the arm with the scene is watched through a run
        and warned of by name (SPEC §18.10).
    site : str, optional
        The end-effector site (the earlier name of ``tip`` for a site).

    Raises
    ------
    ValueError
        The model is not an arm this class can drive; the message names the
        file, joint, body or actuator and what to do (at most
        :data:`MAX_JOINTS` arm joints along one kinematic chain, one joint per
        body; one actuator per arm joint; a force range symmetric about 0).

    Attributes
    ----------
    n : int
        Number of joints.
    joint_names : list of str
        The arm's joints, base to tip.
    tau_max : ndarray, (n,)
        Actuator limits τmax (N m): gear × ctrlrange of the plant's motors.
    wrench_source : str
        ``"sensor"`` (force/torque sensor), ``"contact sensor"`` (the net contact
        wrench on the end effector's subtree, a MuJoCo contact sensor) or
        ``"contact"`` (the contacts' forces on the subtree's bodies, which
        MuJoCo sums from its contact list: ``cfrc_ext``).
    tip : str or None
        The end effector asked for (``tip`` or ``site``; None: found as above).
    site : str or None
        The end-effector site asked for with ``site=``.
    notes : dict
        What the plant made of the model: "locked" {joint: why}, "actuators"
        {joint: servo → motor}, "added" [joints given a motor], "scene"
        {joint that is not the arm's and is kept: where it starts and what
        holds it (another arm's servos hold the keyframe's posture)}, "tau_max"
        {joint: where τmax comes from: "forcerange", "ctrlrange",
        "actuatorfrcrange" or "estimated"}, "timestep" (a file's Euler or
        implicit integrator is stepped at ≤ 0.25 ms,
        :data:`adaptimp._mjcf.FIRST_ORDER_STEP`), "wrench" (a force sensor
        not used), "warnings" [their texts], "tip".
    """

    def __init__(
        self,
        model: ModelSource = "two_link",
        *,
        contact: bool = True,
        site: str | None = None,
        tip: str | None = None,
        fix: Sequence[str] = (),
        surface: Sequence[str] = (),
    ) -> None:
        if site is not None and tip is not None:
            raise ValueError("give the end effector as tip= (a site or a body) or site=, not both")
        if isinstance(fix, str):
            raise TypeError(f"fix must be a tuple of joint names, got the string {fix!r}")
        if not isinstance(model, (str, os.PathLike, mujoco.MjModel, mujoco.MjSpec)):
            raise TypeError(
                "model must be 'two_link', 'panda', the path of an MJCF or URDF file, a "
                f"mujoco.MjModel or a mujoco.MjSpec, got {type(model).__name__} {model!r:.40}"
            )
        self.contact = contact
        self.site = site
        self.tip = tip if tip is not None else site
        self.fix = tuple(fix)
        prepared = _prepare(model, self.tip, self.fix)
        self._arm_names: tuple[str, ...] = prepared.arm["joints"]
        # The end effector asked for, else the one the core's reduction found.
        self._tip_name: str = self.tip if self.tip is not None else prepared.arm["tip"]
        self.notes: dict[str, Any] = {**prepared.notes, "warnings": list(prepared.warnings)}
        for text in prepared.warnings:
            warnings.warn(text, PlantWarning, stacklevel=2)
        try:
            self._setup_model(prepared.model)
        except ValueError as e:  # a file's arm that cannot be a plant: name the file
            label = _source_label(model)
            if str(e).startswith(label):
                raise
            raise ValueError(f"{label}{e}") from None
        self.notes["tip"] = (
            obj_name(self.model, mujoco.mjtObj.mjOBJ_SITE, self._site)
            if self._site >= 0
            else obj_name(self.model, mujoco.mjtObj.mjOBJ_BODY, self._ee_body)
        )
        spec, sensed = prepared.spec, False
        if self.wrench_source == "contact" and self._contact_sensor_fits(model):
            # A file's model: measure the contacts with a sensor of its own (the
            # net contact wrench on the end effector's subtree), which the core's
            # loop reads like the force sensor. A sensor changes no dynamics.
            assert spec is not None
            spec.add_sensor(
                name=_CONTACT_SENSOR,
                type=mujoco.mjtSensor.mjSENS_CONTACT,
                objtype=mujoco.mjtObj.mjOBJ_XBODY,
                objname=obj_name(self.model, mujoco.mjtObj.mjOBJ_BODY, self._ee_body),
                intprm=[_NETFORCE_DATA, _NETFORCE, 1],
            )
            sensed = True
        if isinstance(surface, str):
            surface = (surface,)
        for name in surface:
            _mjcf.resolve_tip(self.model, name)  # a body of the model, or refused by name
        if spec is not None and contact and _contacts.Watch.of(self.model) is None:
            # The contacts of the arm with the rest of the scene, watched
            # through the run (SPEC §18.10): sensors, which change no dynamics.
            # The end effector on the task's own surface is the task's.
            own = [
                (obj_name(self.model, mujoco.mjtObj.mjOBJ_BODY, b), name)
                for b in sorted(self._ee_subtree)
                for name in surface
            ]
            sensed = _contacts.watch_contacts(spec, self.model, self._joints, own) > 0 or sensed
        if sensed:
            assert spec is not None
            self._setup_model(spec.compile())
        self._watch = _contacts.Watch.of(self.model) if contact else None
        m = self.model
        self.data = mujoco.MjData(m)
        self._mass = np.zeros((m.nv, m.nv))
        self.reset()
        scene = self._scene_notes()
        if scene:
            self.notes["scene"] = scene

    def _scene_notes(self) -> dict[str, str]:
        """What the plant does with the joints that are not the arm's and that
        it keeps (another arm, a free body, a door): each starts where the
        file's first keyframe (or qpos0) puts it; a position servo holds that
        posture (:func:`holding_controls`), other actuators keep the
        keyframe's control; the rest is passive."""
        m, d = self.model, self.data
        start = (
            f"the keyframe {obj_name(m, mujoco.mjtObj.mjOBJ_KEY, 0)!r}"
            if m.nkey > 0 and mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_KEY, 0)
            else "the file's keyframe"
            if m.nkey > 0
            else "qpos0 (no keyframe)"
        )
        held = holding_controls(m, d, self._act)
        arm = set(self._joints)
        out: dict[str, str] = {}
        for mocap, body in mocap_welds(m, d, self._joints):
            out[mocap] = (
                f"a mocap body welded to {body!r}: placed where the weld holds {body!r} in {start}"
            )
        for j in range(m.njnt):
            if j in arm:
                continue
            name = obj_name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
            acts = [
                a
                for a in range(m.nu)
                if int(m.actuator_trntype[a]) in (0, 1) and int(m.actuator_trnid[a, 0]) == j
            ]
            q = float(d.qpos[int(m.jnt_qposadr[j])])
            if int(m.jnt_type[j]) == int(mujoco.mjtJoint.mjJNT_FREE):
                out[name] = f"a free body: starts at its pose in {start}"
            elif any(a in held for a in acts):
                a = next(a for a in acts if a in held)
                out[name] = (
                    f"held at {q:.4g} (its posture in {start}) by its servo "
                    f"{obj_name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a)!r}, commanded to it"
                )
            elif acts:
                out[name] = (
                    f"starts at {q:.4g} (its posture in {start}); its actuator "
                    f"{obj_name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, acts[0])!r} keeps the keyframe's "
                    "control (it holds no posture of its own)"
                )
            else:
                out[name] = f"passive: starts at {q:.4g} (its posture in {start})"
        return out

    # -- construction checks ------------------------------------------------

    @property
    def joint_names(self) -> list[str]:
        """The arm's joints, base to tip (the order of q)."""
        return [obj_name(self.model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in self._joints]

    # What the run, the tasks and the scenarios read of the plant's model
    # (read-only): MuJoCo's ids and addresses, base to tip.

    @property
    def joint_ids(self) -> list[int]:
        """MuJoCo's ids of the arm's joints, base to tip (the order of q)."""
        return list(self._joints)

    @property
    def qpos_adr(self) -> NDArray[np.int_]:
        """Where each arm joint's angle lies in ``data.qpos``, (n,)."""
        return np.array(self._qadr)

    @property
    def dof_adr(self) -> NDArray[np.int_]:
        """Where each arm joint's rate lies in ``data.qvel`` (and its dof), (n,)."""
        return np.array(self._dofs)

    @property
    def ee_site(self) -> int:
        """The end effector's site id, or −1 (the origin of :attr:`ee_body`)."""
        return int(self._site)

    @property
    def ee_body(self) -> int:
        """The end effector's body id."""
        return int(self._ee_body)

    @property
    def last_body(self) -> int:
        """The body of the last arm joint (where a payload is added)."""
        return int(self._last_body)

    @property
    def watch(self) -> _contacts.Watch | None:
        """The contact sensors that watch the arm's contacts with the scene
        through a run (SPEC §18.10), or None."""
        return self._watch

    def vector(self, name: str, value: ArrayLike) -> FloatArray:
        """``value`` as one finite value per arm joint, (n,) (a scalar: every
        joint), else an error naming ``name``."""
        return self._vector(name, value)

    def _setup_model(self, model: mujoco.MjModel) -> None:
        self.model = model
        if not self.contact:
            model.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        self._check_joints()
        self._check_actuators()
        self._find_end_effector(self._tip_name)

    def _contact_sensor_fits(self, source: ModelSource) -> bool:
        """Whether a contact sensor can measure this plant's wrench as the module
        doc defines it (the contacts of the subtree with anything outside it):
        the model comes from an MJCF file (so
        it can be rebuilt with the sensor; :func:`from_urdf` gives no contact
        geometry), a contact can reach the end effector, and no contact can
        arise inside its subtree (the sensor would count it; the contact list
        skips it). Conservative: no explicit contact pairs, and no two geoms of
        the subtree on different weld bodies whose contype and conaffinity meet."""
        if isinstance(source, mujoco.MjModel) or (isinstance(source, str) and source in _BUILTIN):
            return False
        suffix = "" if isinstance(source, mujoco.MjSpec) else Path(source).suffix.lower()
        if suffix in (".urdf", ".xacro"):
            return False
        m = self.model
        if m.npair > 0 or not self._contact_possible():
            return False
        inside = [g for g in range(m.ngeom) if int(m.geom_bodyid[g]) in self._ee_subtree]
        ct, ca, weld = m.geom_contype, m.geom_conaffinity, m.body_weldid
        return not any(
            ((ct[a] & ca[b]) or (ct[b] & ca[a]))
            and weld[m.geom_bodyid[a]] != weld[m.geom_bodyid[b]]
            for i, a in enumerate(inside)
            for b in inside[i + 1 :]
        )

    def _check_joints(self) -> None:
        m = self.model
        ids = [mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) for n in self._arm_names]
        if not 1 <= len(ids) <= MAX_JOINTS:
            raise ValueError(
                f"Plant needs 1 to {MAX_JOINTS} joints; the arm has {len(ids)} "
                f"({', '.join(self._arm_names)}): fix some with fix=(...) or name the "
                "arm's end with tip="
            )
        hinge = int(mujoco.mjtJoint.mjJNT_HINGE)
        bad = [
            f"{obj_name(m, mujoco.mjtObj.mjOBJ_JOINT, j)} ({mujoco.mjtJoint(m.jnt_type[j]).name})"
            for j in ids
            if m.jnt_type[j] != hinge
        ]
        if bad:
            raise ValueError(f"Plant needs hinge joints only; not hinges: {', '.join(bad)}")
        self.n = len(ids)
        # Joints in kinematic order (hinges: one qpos and one dof each).
        self._joints = sorted(ids, key=lambda j: int(m.jnt_dofadr[j]))
        self._qadr = np.array([m.jnt_qposadr[j] for j in self._joints])
        self._dofs = np.array([m.jnt_dofadr[j] for j in self._joints])
        bodies = [int(m.jnt_bodyid[j]) for j in self._joints]
        for prev, (j, body) in zip(bodies, list(zip(self._joints, bodies))[1:]):
            if body == prev or prev not in _mjcf.ancestors(m, body):
                raise ValueError(
                    "Plant needs a serial chain, one joint per body: joint "
                    f"{obj_name(m, mujoco.mjtObj.mjOBJ_JOINT, j)!r} is not on a descendant "
                    f"of body {obj_name(m, mujoco.mjtObj.mjOBJ_BODY, prev)!r}"
                )
        self._last_body = bodies[-1]

    def _check_actuators(self) -> None:
        """The arm joints' motors (one each, :func:`_prepare` made them), their
        gear and τmax; actuators of the environment are left alone (zero
        control)."""
        m = self.model
        joint_trn = int(mujoco.mjtTrn.mjTRN_JOINT)
        act_of: dict[int, list[int]] = {j: [] for j in self._joints}
        for a in range(m.nu):
            target = int(m.actuator_trnid[a, 0])
            if m.actuator_trntype[a] == joint_trn and target in act_of:
                act_of[target].append(a)
        self._act = np.zeros(self.n, dtype=int)
        self._gear = np.zeros(self.n)
        self.tau_max = np.zeros(self.n)
        for i, j in enumerate(self._joints):
            jname = obj_name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
            acts = act_of[j]
            if len(acts) != 1:
                raise ValueError(
                    f"Plant needs exactly one torque actuator per joint; joint {jname!r} has "
                    f"{len(acts)}"
                )
            a = acts[0]
            lo, hi = (float(v) for v in m.actuator_ctrlrange[a])
            gear = float(m.actuator_gear[a, 0])
            if not (m.actuator_ctrllimited[a] and gear > 0 and hi > 0 and lo == -hi):
                raise ValueError(
                    f"the motor of joint {jname!r} needs ctrllimited with a symmetric ctrlrange "
                    f"and gear > 0 (its τmax); got ctrlrange [{lo:g}, {hi:g}], gear {gear:g}"
                )
            self._act[i] = a
            self._gear[i] = gear
            self.tau_max[i] = gear * hi

    def _find_end_effector(self, tip: str) -> None:
        m = self.model
        force = int(mujoco.mjtSensor.mjSENS_FORCE)
        torque = int(mujoco.mjtSensor.mjSENS_TORQUE)
        sid, self._ee_body = _mjcf.end_effector(m, tip)
        self._site = sid
        sensors = [s for s in range(m.nsensor) if m.sensor_type[s] == force]
        sensors = [s for s in sensors if m.sensor_objid[s] == sid and sid >= 0]
        carried = float(m.body_subtreemass[self._ee_body])
        if sensors and carried > 0:
            # The sensor reads the force between the site's body and its parent:
            # with mass below it (a gripper) that is gravity and inertia too, not
            # the contact wrench. The contacts are measured instead.
            name = obj_name(m, mujoco.mjtObj.mjOBJ_SENSOR, sensors[0])
            self.notes["wrench"] = (
                f"the force sensor {name!r} carries {carried:.3g} kg below it (it reads "
                "gravity and inertia as well as contact): the wrench comes from the contacts"
            )
            sensors = []
        self._force_adr = int(m.sensor_adr[sensors[0]]) if sensors else -1
        torques = [
            s
            for s in range(m.nsensor)
            if m.sensor_type[s] == torque and m.sensor_objid[s] == sid and sensors
        ]
        self._torque_adr = int(m.sensor_adr[torques[0]]) if torques else -1
        ee = self._ee_body
        self._ee_subtree = frozenset(
            b for b in range(m.nbody) if b == ee or ee in _mjcf.ancestors(m, b)
        )
        # A contact sensor of the net contact wrench on the end effector's subtree.
        nets = [
            s
            for s in range(m.nsensor)
            if m.sensor_type[s] == int(mujoco.mjtSensor.mjSENS_CONTACT)
            and m.sensor_objtype[s] == int(mujoco.mjtObj.mjOBJ_XBODY)
            and m.sensor_objid[s] == self._ee_body
            and m.sensor_reftype[s] == int(mujoco.mjtObj.mjOBJ_UNKNOWN)
            and list(m.sensor_intprm[s]) == [_NETFORCE_DATA, _NETFORCE, 1]
        ]
        self._contact_adr = int(m.sensor_adr[nets[0]]) if nets and self._force_adr < 0 else -1
        self.wrench_source = (
            "sensor"
            if self._force_adr >= 0
            else "contact sensor"
            if self._contact_adr >= 0
            else "contact"
        )

    # -- state ----------------------------------------------------------------

    def reset(self, q0: ArrayLike | None = None, dq0: ArrayLike | None = None) -> None:
        """Back to the first keyframe (or ``qpos0`` without one), then q = ``q0``
        (rad) and q̇ = ``dq0`` (rad/s) where given; zero torque on the arm's
        motors; every other position servo (another arm's, a gripper's of the
        scene) commanded to hold the keyframe's posture (:func:`holding_controls`)."""
        m, d = self.model, self.data
        if m.nkey > 0:
            mujoco.mj_resetDataKeyframe(m, d, 0)
        else:
            mujoco.mj_resetData(m, d)
        mujoco.mj_forward(m, d)
        held = holding_controls(m, d, self._act)
        d.ctrl[:] = 0.0
        for a, (ctrl, act) in held.items():
            d.ctrl[a] = ctrl
            if act is not None:
                d.act[int(m.actuator_actadr[a])] = act
        if mocap_welds(m, d, self._joints):
            mujoco.mj_forward(m, d)
        if q0 is not None:
            d.qpos[self._qadr] = self._vector("q0", q0)
        if dq0 is not None:
            d.qvel[self._dofs] = self._vector("dq0", dq0)
        mujoco.mj_forward(m, d)

    @contextlib.contextmanager
    def state_kept(self) -> Iterator[None]:
        """The plant's whole state (MuJoCo's data: positions, velocities,
        controls, activations, time) as it is now, put back when the block
        ends, whatever it did (a rule that reads D(q) and G(q) at postures of
        its own, :meth:`adaptimp.CartesianController.from_rule`)."""
        m, d = self.model, self.data
        copy_data = getattr(mujoco, "mj_copyData", None)
        if copy_data is not None:
            saved = mujoco.MjData(m)
            copy_data(saved, m, d)
            try:
                yield
            finally:
                copy_data(d, m, saved)
            return
        # MuJoCo bindings without mj_copyData (robosuite's 3.3): the
        # state that integration reads, and the rest recomputed from it.
        spec = mujoco.mjtState.mjSTATE_INTEGRATION
        state = np.empty(mujoco.mj_stateSize(m, spec))
        mujoco.mj_getState(m, d, state, spec)
        try:
            yield
        finally:
            mujoco.mj_setState(m, d, state, spec)
            mujoco.mj_forward(m, d)

    def _vector(self, name: str, value: ArrayLike) -> FloatArray:
        v = reals(name, value, finite=False)
        if v.shape == ():
            v = np.full(self.n, float(v))
        if v.shape != (self.n,):
            raise ValueError(f"{name} must have shape ({self.n},), got {v.shape}")
        if not np.all(np.isfinite(v)):
            raise ValueError(f"{name} must be finite, got {v}")
        return v

    @property
    def q(self) -> FloatArray:
        """Joint positions (rad), (n,)."""
        return np.array(self.data.qpos[self._qadr], dtype=np.float64)

    @property
    def dq(self) -> FloatArray:
        """Joint velocities (rad/s), (n,)."""
        return np.array(self.data.qvel[self._dofs], dtype=np.float64)

    @property
    def timestep(self) -> float:
        """MuJoCo's timestep (s)."""
        return float(self.model.opt.timestep)

    @timestep.setter
    def timestep(self, value: float) -> None:
        if not (value > 0 and math.isfinite(value)):
            raise ValueError(f"timestep must be > 0, got {value}")
        self.model.opt.timestep = value

    # -- the model, as the core's loop and the rule read it -------------------

    def _contact_possible(self) -> bool:
        """Whether a contact can involve the end effector's subtree (contact
        enabled, and a geom of the subtree whose contype/conaffinity meets a
        geom outside it, or explicit contact pairs)."""
        m = self.model
        if m.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_CONTACT):
            return False
        if m.npair > 0:
            return True
        inside = [g for g in range(m.ngeom) if int(m.geom_bodyid[g]) in self._ee_subtree]
        outside = [g for g in range(m.ngeom) if int(m.geom_bodyid[g]) not in self._ee_subtree]
        ct, ca = m.geom_contype, m.geom_conaffinity
        return any((ct[a] & ca[b]) or (ct[b] & ca[a]) for a in inside for b in outside)

    def core_spec(self, substeps: int) -> dict[str, Any]:
        """The plant as the core's loop drives it (SPEC §13.1): where its joints,
        motors and end effector are, and where the wrench is read: the force
        (and torque) sensor, the contact sensor, or, without either when a
        contact can reach the end effector, the external forces MuJoCo sums
        from its contact list on each body of the end effector's subtree
        (``subtree``, ``cfrc_ext``)."""
        m = self.model
        listed = self.wrench_source == "contact" and self._contact_possible()
        return {
            "qadr": [int(a) for a in self._qadr],
            "dofs": [int(a) for a in self._dofs],
            "act": [int(a) for a in self._act],
            "gear": [float(g) for g in self._gear],
            "tau_max": [float(t) for t in self.tau_max],
            "site": int(self._site) if self._site >= 0 else None,
            "ee_body": int(self._ee_body),
            "force_adr": int(self._force_adr) if self._force_adr >= 0 else None,
            "torque_adr": int(self._torque_adr) if self._torque_adr >= 0 else None,
            "contact_adr": int(self._contact_adr) if self._contact_adr >= 0 else None,
            "subtree": sorted(int(b) for b in self._ee_subtree) if listed else [],
            "root": int(m.body_rootid[self._ee_body]),
            "substeps": int(substeps),
            "timestep": float(m.opt.timestep),
            "integrator": int(m.opt.integrator),
            "pure_sensors": _pure_sensors(m),
            "watch": self._watch.adr if self._watch is not None else [],
            "watch_out": self._watch.out if self._watch is not None else None,
            "dof_names": [
                obj_name(m, mujoco.mjtObj.mjOBJ_JOINT, int(m.dof_jntid[i])) for i in range(m.nv)
            ],
            "warning_names": _warning_names(),
        }

    def mass_matrix(self) -> FloatArray:
        """Joint-space inertia D(q) (kg m²), (n, n), of the last :meth:`forward`."""
        _full_inertia(self.model, self.data, self._mass)
        return np.array(self._mass[np.ix_(self._dofs, self._dofs)], dtype=np.float64)

    def bias(self) -> FloatArray:
        """C(q, q̇) q̇ + G(q) (N m), (n,), of the last :meth:`forward`."""
        return np.array(self.data.qfrc_bias[self._dofs], dtype=np.float64)

    def __repr__(self) -> str:
        name = self.model.names[: self.model.names.find(b"\0")].decode() or "model"
        return (
            f"adaptimp.mujoco.Plant({name!r}: {self.n} joints, τmax = {self.tau_max.tolist()} N m,"
            f" wrench from {self.wrench_source}, timestep {self.timestep:g} s)"
        )


def mocap_welds(
    m: mujoco.MjModel, d: mujoco.MjData, arm: Sequence[int] | FloatArray
) -> list[tuple[str, str]]:
    """Each mocap body welded (an active weld) to a body the ``arm``'s joints
    do not move (another arm's hand, driven through its mocap target) put
    where the weld holds that body at the state of ``d`` (after
    ``mj_forward``: the keyframe's posture), as a task scene's reset does;
    (18.10). Returns the (mocap body, body) pairs moved. With the weld's
    relative pose (p_r, q_r) of body 2 in body 1: q_1 = q_2 q_r⁻¹,
    p_1 = p_2 − R_1 p_r, or q_2 = q_1 q_r, p_2 = p_1 + R_1 p_r."""
    moved = _mjcf.movers(m, [int(j) for j in arm])
    out: list[tuple[str, str]] = []
    for k in range(m.neq):
        if int(m.eq_type[k]) != int(mujoco.mjtEq.mjEQ_WELD) or not d.eq_active[k]:
            continue
        if int(m.eq_objtype[k]) != int(mujoco.mjtObj.mjOBJ_BODY):
            continue
        b1, b2 = int(m.eq_obj1id[k]), int(m.eq_obj2id[k])
        if b2 < 0 or moved[b1] or moved[b2]:
            continue
        relpos, relq = np.array(m.eq_data[k, 3:6]), np.array(m.eq_data[k, 6:10])
        if int(m.body_mocapid[b1]) >= 0 and int(m.body_mocapid[b2]) < 0:
            inv, q1, r1 = np.zeros(4), np.zeros(4), np.zeros(9)
            mujoco.mju_negQuat(inv, relq)
            mujoco.mju_mulQuat(q1, np.array(d.xquat[b2]), inv)
            mujoco.mju_quat2Mat(r1, q1)
            i = int(m.body_mocapid[b1])
            d.mocap_pos[i] = d.xpos[b2] - r1.reshape(3, 3) @ relpos
            d.mocap_quat[i] = q1
        elif int(m.body_mocapid[b2]) >= 0 and int(m.body_mocapid[b1]) < 0:
            q2, r1 = np.zeros(4), np.zeros(9)
            mujoco.mju_mulQuat(q2, np.array(d.xquat[b1]), relq)
            mujoco.mju_quat2Mat(r1, np.array(d.xquat[b1]))
            i = int(m.body_mocapid[b2])
            d.mocap_pos[i] = d.xpos[b1] + r1.reshape(3, 3) @ relpos
            d.mocap_quat[i] = q2
        else:
            continue
        out.append(
            (
                obj_name(m, mujoco.mjtObj.mjOBJ_BODY, b1 if m.body_mocapid[b1] >= 0 else b2),
                obj_name(m, mujoco.mjtObj.mjOBJ_BODY, b2 if m.body_mocapid[b1] >= 0 else b1),
            )
        )
    return out


def holding_controls(
    m: mujoco.MjModel, d: mujoco.MjData, arm: Sequence[int] | FloatArray
) -> dict[int, tuple[float, float | None]]:
    """The control (and activation) under which each position-like servo that
    is not one of the ``arm``'s actuators holds the posture of ``d`` (after
    ``mj_forward``): force = g ctrl + b0 + b1 l + b2 l̇ vanishes at rest at
    its length l, ctrl = −(b0 + b1 l)/g (fixed gain g ≠ 0, affine bias with
    b1 ≠ 0: MuJoCo's ``position`` and the Menagerie's ``general`` servos),
    within its control range. A filter's activation starts there too; an
    integrator's activation holds it at zero control. Other actuators are not
    in the answer (a motor or a velocity servo holds no posture: they keep the
    keyframe's control). Returns {actuator: (ctrl, act or None)}."""
    out: dict[int, tuple[float, float | None]] = {}
    arm_set = {int(a) for a in arm}
    fixed = int(mujoco.mjtGain.mjGAIN_FIXED)
    affine = int(mujoco.mjtBias.mjBIAS_AFFINE)
    for a in range(m.nu):
        g, b0, b1 = (float(m.actuator_gainprm[a, 0]), *map(float, m.actuator_biasprm[a, :2]))
        if a in arm_set or int(m.actuator_gaintype[a]) != fixed:
            continue
        if int(m.actuator_biastype[a]) != affine or g == 0.0 or b1 == 0.0:
            continue
        target = -(b0 + b1 * float(d.actuator_length[a])) / g
        if m.actuator_ctrllimited[a]:
            lo, hi = (float(v) for v in m.actuator_ctrlrange[a])
            target = min(max(target, lo), hi)
        dyn = int(m.actuator_dyntype[a])
        has_act = int(m.actuator_actnum[a]) > 0 and int(m.actuator_actadr[a]) >= 0
        if dyn == int(mujoco.mjtDyn.mjDYN_INTEGRATOR) and has_act:
            out[a] = (0.0, target)
        elif has_act:
            out[a] = (target, target)
        else:
            out[a] = (target, None)
    return out


_CONTACT_SENSOR = "adaptimp_ee_contact"
"""The name of the contact sensor :class:`Plant` adds to a file's model."""

_NETFORCE = 3
"""The contact sensor's ``reduce="netforce"`` (MuJoCo's sensor_intprm[1])."""

_NETFORCE_DATA = sum(
    1 << int(f)
    for f in (
        mujoco.mjtConDataField.mjCONDATA_FORCE,
        mujoco.mjtConDataField.mjCONDATA_TORQUE,
        mujoco.mjtConDataField.mjCONDATA_POS,
    )
)
"""The contact sensor's ``data="force torque pos"`` (sensor_intprm[0])."""


def _pure_sensors(m: Any) -> bool:
    """Whether every sensor of ``m`` is a pure function of the state: no
    noise, history, delay or interval (fields of newer MuJoCo, absent:
    none), no user or plugin sensors, no plugins. A MuJoCo step inside a
    control period may then skip the sensors (only the period's last forward
    computation is read)."""
    if m.nplugin or m.nsensor == 0:
        return bool(m.nplugin == 0)
    kinds = {int(mujoco.mjtSensor.mjSENS_USER), int(mujoco.mjtSensor.mjSENS_PLUGIN)}
    if any(int(t) in kinds for t in m.sensor_type):
        return False
    for field in ("sensor_noise", "sensor_history", "sensor_delay", "sensor_interval"):
        values = getattr(m, field, None)
        if values is not None and np.any(np.asarray(values) != 0):
            return False
    return True


def _warning_names() -> list[str]:
    """MuJoCo's warning kinds by index (``mjtWarning``, without ``mjNWARNING``)."""
    return [mujoco.mjtWarning(i).name for i in range(int(mujoco.mjtWarning.mjNWARNING))]


# ---------------------------------------------------------------------------
# An arm nobody configured: payload, home posture, default task, the rule
# (SPEC §18). Each a function of its own that simulate calls before its loop.
# ---------------------------------------------------------------------------


def uses_rule(plant: Plant) -> bool:
    """True unless ``plant`` is the paper's arm, whose scenario has its own defaults."""
    return model_name(plant.model) != "adaptimp_two_link"
