"""The arms :class:`adaptimp.mujoco.Plant` is built from: the packaged models
(:func:`two_link`, :func:`panda`), a URDF compiled by MuJoCo (:func:`from_urdf`,
its effort limits or the core's estimate, :func:`estimate_effort`), and a
model with a payload (:func:`with_payload`, :func:`moving_mass`).

Re-exported by :mod:`adaptimp.mujoco`. Units: m, kg, s, N m."""

from __future__ import annotations

import copy
import math
import os
import warnings
from collections.abc import Mapping, Sequence
from typing import Any, Union

import mujoco
import numpy as np
from numpy.typing import NDArray

from . import _description, _models, _sampled
from ._errors import ConfigError
from ._tooling import add_table, add_tool

FloatArray = NDArray[np.float64]


MAX_JOINTS = 7
"""The most joints a :class:`Plant` accepts."""


ModelSource = Union["mujoco.MjModel", "mujoco.MjSpec", str, "os.PathLike[str]"]


def two_link() -> mujoco.MjModel:
    """The paper's 2-link arm in a vertical plane (SPEC §1), ``models/two_link.xml``.

    The plane is MuJoCo's x-z plane (gravity −z), both hinges about −y, so q is
    the paper's (q1 from the horizontal, q2 relative). Motors with ctrlrange
    ±[17, 15] N m; a ceiling wall 0.20 m above the base that only the
    end-effector sphere touches; force/torque sensors at the site ``ee``;
    keyframe ``paper`` = the paper's q(0) = [0.25, −0.05]; RK4 at 50 µs.
    """
    return mujoco.MjModel.from_xml_path(str(_models.TWO_LINK_XML))


def add_motors(spec: Any, effort: Mapping[str, float]) -> None:
    """A motor (gear 1, ctrlrange ±effort) for every joint of ``effort``."""
    for name, limit in effort.items():
        spec.add_actuator(
            name=name,
            target=name,
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            gear=[1.0, 0, 0, 0, 0, 0],
            ctrllimited=mujoco.mjtLimited.mjLIMITED_TRUE,
            ctrlrange=[-limit, limit],
        )


def spec_of(urdf: str) -> Any:
    spec = mujoco.MjSpec.from_string(urdf)
    # Keep the URDF's fixed links as bodies: a force sensor needs its own body.
    spec.compiler.fusestatic = False
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    return spec


def compile_arm(spec: Any, note: str = "", *, stacklevel: int = 3) -> mujoco.MjModel:
    """``spec`` compiled; if a URDF's inertias do not compile as they are (a
    massless moving link, an inertia that violates the triangle inequality),
    compiled again with every body bounded and balanced (1e-6 kg, 1e-10 kg m²,
    far below any real link), with a warning (``note`` added to it) pointing at
    the caller of the function that called this one."""
    try:
        return spec.compile()
    except ValueError as e:
        spec.compiler.boundmass = 1e-6
        spec.compiler.boundinertia = 1e-10
        spec.compiler.balanceinertia = True
        model = spec.compile()
        warnings.warn(
            f"the URDF's inertias do not compile as they are ({e}); every body now has "
            f"at least 1e-6 kg and 1e-10 kg m², and inertias are balanced{note}",
            stacklevel=stacklevel,
        )
        return model


def urdf_arm(path: str | os.PathLike[str], tip: str | None, fix: Sequence[str]) -> _description.Arm:
    """The arm of a URDF (or xacro) file by the core's one reduction (SPEC §21)."""
    arm = _description.read_arm(path, tip, fix)
    _description.say_balanced(arm, stacklevel=5)
    if arm.inertia_error is not None:  # MuJoCo refuses it, unnamed
        raise ConfigError(arm.inertia_error)
    if arm.urdf is None:
        raise ValueError(
            f"{arm.source} is not a URDF: from_urdf reads URDF and xacro files; give an MJCF "
            "path to Plant or simulate directly"
        )
    if arm.n > MAX_JOINTS:
        raise ValueError(
            f"the URDF's arm has {arm.n} joints ({', '.join(arm.joints)}); "
            f"adaptimp drives at most {MAX_JOINTS}: fix some with fix=(...)"
        )
    return arm


def arm_spec(arm: _description.Arm, timestep: float, *, drive: bool, stacklevel: int) -> Any:
    """The MjSpec of a URDF arm (its reduced URDF, RK4 at ``timestep`` s),
    with a motor per arm joint at ± its effort; where the URDF gives none,
    the estimate of :func:`estimate_effort` on the arm itself, with a warning
    at ``stacklevel``. With ``drive``, each arm joint's damping and friction
    loss as the URDF's ``<dynamics>`` states them."""
    text = arm.urdf_drive if drive else arm.urdf
    assert text is not None
    spec = spec_of(text)
    spec.option.timestep = timestep
    missing = [j for j, e in zip(arm.joints, arm.effort) if not math.isfinite(e)]
    add_motors(spec, {j: (e if math.isfinite(e) else 1.0) for j, e in zip(arm.joints, arm.effort)})
    if missing:
        estimate = estimate_effort(compile_arm(spec, stacklevel=stacklevel + 1))
        for j, name in enumerate(arm.joints):
            if name in missing:
                spec.actuator(name).ctrlrange = [-estimate[j], estimate[j]]
        warnings.warn(
            f"the URDF gives no effort limit for {missing}: estimated "
            f"{[round(float(estimate[arm.joints.index(j)]), 3) for j in missing]} N m "
            "(2 (max |G_i| + 10 rad/s² · max Σ_j |D_ij|) within the joint limits)",
            stacklevel=stacklevel,
        )
    return spec


def from_urdf(
    path: str | os.PathLike[str],
    timestep: float = 1e-3,
    *,
    fix: tuple[str, ...] = (),
    tip: str | None = None,
    drive: bool = False,
) -> mujoco.MjModel:
    """A URDF (or xacro) arm as a MuJoCo model :class:`Plant` accepts.

    The arm is the one the core's reduction finds (SPEC §21, the same rule
    for the chain, the computed-torque model and C): the longest chain of
    revolute and continuous joints from the root, ending at a hand or a
    gripper (recognised by its structure: mimic joints, a joint other joints
    mimic, a jaw beside the tool frame, a branching hand; by name last);
    every other joint held fixed at its zero position (mimic joints where
    their master's zero puts them), and the joints named in ``fix``. Chains
    that tie for the longest (a quadruped's legs, two arms) are an error
    listing the link each ends at: ``tip`` names the link that ends the arm
    (the movable joints on the way to it are the arm's). MuJoCo compiles the
    reduced URDF the core writes: the links' inertials (no visual or
    collision elements, so no mesh files and no contact geometry) and the
    arm joints' limits: the rigid-body dynamics only, unless ``drive``
    (then each arm joint's ``<dynamics>`` damping and friction loss as the
    URDF states them; :class:`adaptimp.baselines.ComputedTorque` takes the
    same ``drive``). Continuous joints are unlimited hinges. If the
    inertias do not compile as they are (a massless moving link, an inertia
    that violates the triangle inequality), every body gets at least 1e-6 kg
    and 1e-10 kg m² and inertias are balanced (MuJoCo's ``boundmass``,
    ``boundinertia``, ``balanceinertia``), with a warning. Each arm joint
    gets a motor with ctrlrange ± its ``<limit effort>`` (N m); where the
    URDF gives none (or zero) the limit is estimated from the arm itself,
    2 (max |G_i| + 10 rad/s² · max Σ_j |D_ij|) over 256 postures within the
    joint limits (:func:`estimate_effort`), with a warning. RK4 at
    ``timestep`` (s).

    Raises
    ------
    ValueError
        The URDF has no revolute or continuous joint to drive, more than
        :data:`MAX_JOINTS` on its arm, or several chains that tie for the
        longest and no ``tip`` (the message names the file and what to do).
    """
    arm = urdf_arm(path, tip, fix)
    if not isinstance(drive, bool):  # 'yes' was taken as True
        raise TypeError(f"drive must be True or False, got {drive!r}")
    return compile_arm(arm_spec(arm, timestep, drive=drive, stacklevel=3))


def estimate_effort(model: mujoco.MjModel, postures: int = 256) -> FloatArray:
    """Effort limits (N m, per joint of ``model``'s arm) for an arm whose URDF
    gives none: 2 (max |G_i(q)| + 10 rad/s² · max Σ_j |D_ij(q)|) over
    ``postures`` postures within the joint limits (:func:`from_urdf`): gravity
    and an acceleration of 10 rad/s² of every joint at once, twice over (the
    core's rule, :func:`adaptimp._sampled.estimate` without the drag terms)."""
    joints = sorted(range(model.njnt), key=lambda j: int(model.jnt_dofadr[j]))
    qadr = [int(model.jnt_qposadr[j]) for j in joints]
    dofs = [int(model.jnt_dofadr[j]) for j in joints]
    return _sampled.estimate(model, qadr, dofs, postures, drag=False)


def panda(
    table_height: float | None = 0.45,
    *,
    tool_radius: float = 0.01,
    timestep: float = 5e-4,
) -> mujoco.MjModel:
    """The Franka Emika Panda (example-robot-data's URDF, no download), arm only.

    The URDF's kinematics and inertias as they are; both finger joints fixed
    closed (their 15 g each ride on the hand); no joint damping or friction;
    one motor per joint with ctrlrange ±[87, 87, 87, 87, 12, 12, 12] N m (the
    URDF's effort limits). The end effector is the tool centre point
    ``panda_hand_tcp`` (0.1034 m beyond the flange-mounted hand): a massless
    body with the site ``ee``, force/torque sensors ``ee_force``/``ee_torque``
    and the only collision geometry of the arm, a sphere of ``tool_radius`` (m)
    at the TCP. Keyframe ``home`` is the SRDF's default posture, joint limits
    from the URDF, RK4 at ``timestep`` (s).

    Parameters
    ----------
    table_height : float or None
        Height (m) above the robot's base of the top of a table box in front of
        the arm (x from 0.2 to 0.9 m, y within ±0.5 m); None: no table. At the
        home posture the TCP is at (0.307, 0, 0.487) m, the bottom of the tool
        sphere 0.477 m above the base (for the default radius): 27 mm above the
        default table.
    tool_radius : float
        Radius of the tool sphere (m).
    timestep : float
        MuJoCo's timestep (s); :func:`simulate` resets it to Ts / substeps.
    """
    arm = urdf_arm(_models.panda_urdf_path(), _models.PANDA_EE, _models.PANDA_FINGERS)
    spec = arm_spec(arm, timestep, drive=False, stacklevel=2)
    spec.modelname = "panda"
    add_tool(spec, _models.PANDA_EE, radius=tool_radius, own_body=False)
    if table_height is not None:
        add_table(spec, top=table_height, centre=(0.55, 0.0))
    spec.add_key(name="home", qpos=list(_models.PANDA_HOME))
    return spec.compile()


def moving_mass(model: mujoco.MjModel) -> float:
    """The arm's moving mass (kg): every body below the first joint."""
    plant_bodies = [int(model.jnt_bodyid[j]) for j in range(model.njnt)]
    if not plant_bodies:
        return 0.0
    first = min(plant_bodies)

    def below(b: int) -> bool:
        while b > 0:
            if b == first:
                return True
            b = int(model.body_parentid[b])
        return False

    return float(sum(model.body_mass[b] for b in range(model.nbody) if below(b)))


def with_payload(model: mujoco.MjModel, mass: float, body: int | None = None) -> mujoco.MjModel:
    """A copy of ``model`` with a point mass ``mass`` (kg, 0 … 1e9, the bound of
    every physical parameter) at the origin of
    ``body`` (default: the body of the last joint, the end effector's link;
    SPEC §17's payload for a MuJoCo arm). The body's mass, centre of mass and
    inertia change by the parallel-axis theorem; nothing else does. Give it
    to the plant only: the controller is not told."""
    if not (math.isfinite(mass) and 0 <= mass <= 1e9):
        # (1e300 kg was accepted, and the run ended in a DivergedError of MuJoCo's.)
        raise ConfigError(f"payload must be ≥ 0 and ≤ 1e9 kg, got {mass}")
    m = copy.deepcopy(model)
    if mass == 0:
        return m
    if body is None:
        last = max(range(m.njnt), key=lambda j: int(m.jnt_dofadr[j]))
        body = int(m.jnt_bodyid[last])
    mb, c = float(m.body_mass[body]), np.array(m.body_ipos[body], dtype=np.float64)
    rot = np.zeros(9)
    mujoco.mju_quat2Mat(rot, m.body_iquat[body])
    r = rot.reshape(3, 3)
    inertia = r @ np.diag(m.body_inertia[body]) @ r.T
    total = mb + mass
    com = mb * c / total

    def steiner(k: float, x: FloatArray) -> FloatArray:
        return np.asarray(k * (x @ x * np.eye(3) - np.outer(x, x)), dtype=np.float64)

    inertia = inertia + steiner(mb, c - com) + steiner(mass, -com)
    w, v = np.linalg.eigh(inertia)
    if np.linalg.det(v) < 0:
        v[:, 0] = -v[:, 0]
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, v.flatten())
    m.body_mass[body] = total
    m.body_ipos[body] = com
    m.body_iquat[body] = quat
    m.body_inertia[body] = np.maximum(w, 0.0)
    mujoco.mj_setConst(m, mujoco.MjData(m))
    return m
