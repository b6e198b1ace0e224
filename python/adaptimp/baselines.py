"""Model-based baselines to compare the paper's model-free controllers against.

Needs the optional dependency Pinocchio (the extra ``pinocchio``: ``pip install ".[pinocchio]"``);
the rest of adaptimp never imports it.

:class:`ComputedTorque` is the textbook computed-torque (inverse-dynamics)
impedance controller, in joint space: with the compliant reference xd of SPEC §4
(the same target impedance Dd, Cd, Gd as the paper's controllers, driven by the
measured τe),

    τ = M̂(q) (ẍd + K_D (ẋd − q̇) + K_P (xd − q)) + ĥ(q, q̇) + τe,   sat(τ) applied,

with M̂ from Pinocchio's CRBA and ĥ = Ĉ q̇ + Ĝ from its RNEA at zero
acceleration. With the exact model and no saturation, the error obeys
ë + K_D ė + K_P e = 0. ``mass_scale`` multiplies every link's mass and inertia
(e.g. 1.3 for a +30 % model error).

:func:`pinocchio_model` gives the Pinocchio models of the packaged arms:
``"two_link"`` (the paper's arm, SPEC §1, as in ``models/two_link.xml``) and
``"panda"`` (example-robot-data's URDF, fingers locked closed), or loads a URDF.

Units: rad, rad/s, rad/s², N m, kg, s.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._adaptimp import Measurement
from ._deprecated import period_alias
from ._errors import ConfigError, needs_extra, no_file

try:
    import pinocchio as pin
except ImportError as e:  # pragma: no cover - depends on the environment
    raise needs_extra("adaptimp.baselines", "pin>=3", "pinocchio") from e

from . import _models
from ._trajectory import Reference, paper_circle

__all__ = [
    "ComputedTorque",
    "core_description",
    "default_gains",
    "pinocchio_model",
    "plant_drive",
    "with_payload",
]

FloatArray = NDArray[np.float64]


def _two_link(params: dict[str, float]) -> Any:
    """The paper's arm (SPEC §1) as a Pinocchio model: hinges about −y, links
    along x, gravity −z (the plane and axes of ``models/two_link.xml``)."""
    model = pin.Model()
    model.gravity.linear = np.array([0.0, 0.0, -params["g"]])
    axis = np.array([0.0, -1.0, 0.0])
    parent, offset = 0, 0.0
    for i in (1, 2):
        placement = pin.SE3(np.eye(3), np.array([offset, 0.0, 0.0]))
        joint = model.addJoint(
            parent, pin.JointModelRevoluteUnaligned(axis), placement, f"joint{i}"
        )
        inertia = pin.Inertia(
            params[f"m{i}"],
            np.array([params[f"lc{i}"], 0.0, 0.0]),
            np.eye(3) * params[f"I{i}"],
        )
        model.appendBodyToJoint(joint, inertia, pin.SE3.Identity())
        parent, offset = joint, params[f"l{i}"]
    model.addFrame(
        pin.Frame(
            "ee", parent, pin.SE3(np.eye(3), np.array([offset, 0.0, 0.0])), pin.FrameType.OP_FRAME
        )
    )
    return model


def _is_file(source: Any) -> bool:
    return isinstance(source, os.PathLike) or (
        isinstance(source, str) and source not in ("two_link", "panda")
    )


def _arm(source: Any, tip: str | None, fix: Sequence[str]) -> Any:
    """The core's arm (SPEC §21) of ``"panda"``, a path or a MuJoCo model."""
    from ._description import read_arm, say_balanced

    if isinstance(source, str) and source == "panda":
        if tip is not None or fix:
            raise ValueError(
                "'panda' has its tip and fixed fingers; give the Panda's URDF path to set them"
            )
        return read_arm(_models.panda_urdf_path(), _models.PANDA_EE, _models.PANDA_FINGERS)
    if _is_file(source) and not Path(source).is_file():
        raise no_file(
            "source must be 'two_link', 'panda', a URDF or MJCF path, a mujoco.MjModel or a "
            "pinocchio.Model",
            source,
        )
    arm = read_arm(source, tip, fix)
    say_balanced(arm, stacklevel=5)
    return arm


def plant_drive(
    model: Any, Ts: float, joints: Sequence[str], tip: str | None = None, fix: Sequence[str] = ()
) -> dict[str, Any] | None:
    """What adaptimp's MuJoCo plant of ``model`` (an MJCF path or a compiled
    ``MjModel``, with ``tip``/``fix``) has of the drive of ``joints`` beyond
    the arm's description, as ``_adaptimp.ComputedTorque``'s keywords.

    The passive springs ``stiffness`` k and ``spring_reference`` q_s (SPEC
    (20.5'), MuJoCo's ``jnt_stiffness`` and ``qpos_spring``; only if some
    k > 0), and how the plant realises the drive over a period ``Ts`` (s),
    SPEC (20.9): ``substep`` h and ``substeps`` s as
    :func:`adaptimp.mujoco.simulate` steps it (s = round(Ts / the plant's
    timestep), h = Ts / s); ``implicit_damping`` (MuJoCo's Euler unless
    ``eulerdamp`` is disabled, implicit and implicitfast integrate the
    damping implicitly; RK4 does not); ``semi_implicit`` (all but RK4 move
    the position with the new velocity: the plant's velocity is h/2 old,
    SPEC (20.9')); per joint the friction-loss
    constraint's ``friction_regularisation`` R = (1 − d)/d ·
    ``dof_invweight0`` (d = ``solimp[0]``) and ``friction_rate`` b_r =
    2/(``solimp[1]`` · max(``solref[0]``, 2 h)) (−``solref[1]``/``solimp[1]``
    for a direct ``solref``). None if the plant cannot be built from
    ``model`` or drives other joints."""
    import warnings

    import mujoco

    from . import mujoco as amj

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            plant = amj.Plant(model, tip=tip, fix=fix)
    except (ValueError, TypeError):
        return None
    m = plant.model
    names = list(plant.joint_names)
    if sorted(names) != sorted(joints):
        return None
    dofs = np.array([plant.dof_adr[names.index(j)] for j in joints])
    substeps = max(1, round(Ts / float(m.opt.timestep)))
    h = Ts / substeps
    integrator = int(m.opt.integrator)
    rk4 = integrator == int(mujoco.mjtIntegrator.mjINT_RK4)
    euler = integrator == int(mujoco.mjtIntegrator.mjINT_EULER)
    no_eulerdamp = bool(int(m.opt.disableflags) & int(mujoco.mjtDisableBit.mjDSBL_EULERDAMP))
    solimp, solref = m.dof_solimp[dofs], m.dof_solref[dofs]
    d, dmax = solimp[:, 0], solimp[:, 1]
    regularisation = (1.0 - d) / d * m.dof_invweight0[dofs]
    direct = solref[:, 0] < 0
    rate = np.where(
        direct,
        -solref[:, 1] / dmax,
        2.0 / (dmax * np.maximum(np.abs(solref[:, 0]), 2.0 * h)),
    )
    out: dict[str, Any] = {}
    jids = [int(m.dof_jntid[i]) for i in dofs]
    stiffness = m.jnt_stiffness[jids]
    if np.any(stiffness > 0):
        out["stiffness"] = stiffness.tolist()
        out["spring_reference"] = m.qpos_spring[m.jnt_qposadr[jids]].tolist()
    return out | {
        "substep": h,
        "substeps": substeps,
        "implicit_damping": not rk4 and not (euler and no_eulerdamp),
        "semi_implicit": not rk4,
        "friction_regularisation": regularisation.tolist(),
        "friction_rate": rate.tolist(),
    }


def default_gains(Ts: float) -> tuple[float, float]:
    """Computed torque's default (K_P, K_D) at period ``Ts`` (s), SPEC (20.8):
    the error dynamics ë + K_D ė + K_P e = 0 with a double pole at ω = 20
    rad/s, (400 s⁻², 40 s⁻¹), for every model and period (the gains that
    meet both of issue 29's payload targets on the most files measured;
    gains tied to the rule's bandwidth did not)."""
    if not (Ts > 0 and math.isfinite(Ts)):
        raise ValueError(f"Ts must be > 0, got {Ts}")
    return 400.0, 40.0


def pinocchio_model(
    source: Any = "two_link",
    *,
    tip: str | None = None,
    fix: Sequence[str] = (),
    **arm: float,
) -> Any:
    """A Pinocchio ``Model`` of an arm.

    Parameters
    ----------
    source : {"two_link", "panda"}, path or pinocchio.Model
        ``"two_link"``: the paper's arm (SPEC §1; ``arm`` keywords override its
        parameters, as for :class:`adaptimp.TwoLinkArm`), with frame ``"ee"``
        at the tip of link 2. ``"panda"``: the Franka Emika Panda of
        example-robot-data's URDF (Pinocchio's parser) with both finger joints
        locked closed (``buildReducedModel``), 7 joints, frame
        ``"panda_hand_tcp"``. A path: a URDF or xacro file, its
        arm as the core's one reduction finds it (SPEC §21, with ``tip`` and
        ``fix``, as :func:`adaptimp.mujoco.from_urdf`): Pinocchio reads the
        reduced URDF the core writes. A ``pinocchio.Model`` is returned as it is.
    """
    if isinstance(source, pin.Model):
        return source
    if isinstance(source, str) and source == "two_link":
        from ._arms import TwoLinkArm

        return _two_link(TwoLinkArm(**arm).params)
    if arm:
        raise TypeError(f"arm parameters {sorted(arm)} apply to 'two_link' only")
    if isinstance(source, str) and source == "panda":
        if tip is not None or fix:
            raise ValueError(
                "'panda' has its tip and fixed fingers; give the Panda's URDF path to set them"
            )
        # Pinocchio's own model of the file (its parser, not adaptimp's), the
        # fingers locked closed: the model the Panda table's numbers were made with.
        full = pin.buildModelFromUrdf(str(_models.panda_urdf_path()))
        lock = [full.getJointId(name) for name in _models.PANDA_FINGERS]
        return pin.buildReducedModel(full, lock, pin.neutral(full))
    if _is_file(source):
        described = _arm(source, tip, fix)
        if described.urdf is None:
            raise ValueError(
                f"{described.source} is not a URDF: Pinocchio reads URDF; the core's "
                "ComputedTorque reads this file itself (ComputedTorque(path))"
            )
        return pin.buildModelFromXML(described.urdf)
    raise ValueError(
        f"source must be 'two_link', 'panda', a URDF path or a pinocchio.Model, got {source!r}"
    )


def scale_masses(model: Any, factor: float) -> Any:
    """A copy of ``model`` with every body's mass and rotational inertia times
    ``factor`` (centres of mass unchanged: a uniform change of density)."""
    if not (factor > 0 and math.isfinite(factor)):
        raise ValueError(f"mass_scale must be > 0, got {factor}")
    out = model.copy()
    for i in range(1, out.njoints):
        inertia = out.inertias[i]
        out.inertias[i] = pin.Inertia(
            factor * inertia.mass, inertia.lever.copy(), factor * inertia.inertia
        )
    return out


def with_payload(model: Any, mass: float) -> Any:
    """A copy of ``model`` with a point mass ``mass`` (kg, ≥ 0) at the origin
    of its last joint's frame: the payload of
    :func:`adaptimp.mujoco.with_payload` (the body of the last joint), for a
    computed torque with the exact model of a loaded plant."""
    if not (math.isfinite(mass) and mass >= 0):
        raise ValueError(f"payload must be ≥ 0 kg, got {mass}")
    out = model.copy()
    j = out.njoints - 1
    out.inertias[j] = out.inertias[j] + pin.Inertia(mass, np.zeros(3), np.zeros((3, 3)))
    return out


def _joint(name: str, value: ArrayLike, n: int) -> FloatArray:
    """``value`` as n reals (one number for every joint), named in every error:
    text, bools, complex numbers and other objects are refused (``"x"`` gave
    NumPy's own message)."""
    if isinstance(value, (str, bytes, bool)):
        raise TypeError(f"{name} must be a number or {n} numbers, got {value!r:.60}")
    try:
        given = np.asarray(value)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name} must be a number or {n} numbers ({e})") from None
    if given.dtype.kind not in "fiu":
        raise TypeError(f"{name} must hold real numbers, got an array of dtype {given.dtype}")
    v = given.astype(np.float64)
    if v.shape == ():
        v = np.full(n, float(v))
    if v.shape != (n,):
        raise ValueError(f"{name} must be a number or have shape ({n},), got shape {v.shape}")
    if not np.all(np.isfinite(v)):
        raise ValueError(f"{name} must be finite, got {v}")
    return v


_AXES = {"X": [1.0, 0.0, 0.0], "Y": [0.0, 1.0, 0.0], "Z": [0.0, 0.0, 1.0]}


def core_description(model: Any) -> tuple[list[dict[str, Any]], list[dict[str, Any]], list[float]]:
    """A serial Pinocchio ``Model`` as the core's joint data (as
    :class:`adaptimp.Chain` takes it), one inertial per joint (mass, centre
    of mass and inertia about it in the joint's frame: Pinocchio's, its
    fixed links already merged) and gravity (m/s²): what
    ``adaptimp._adaptimp.ComputedTorque`` takes (SPEC §20).

    Revolute (bounded or continuous, about a frame axis or any axis) and
    prismatic joints, each the child of the one before; anything else is a
    ``ValueError`` naming the joint.
    """
    joints: list[dict[str, Any]] = []
    inertials: list[dict[str, Any]] = []
    for j in range(1, model.njoints):
        name = model.names[j]
        if model.parents[j] != j - 1:
            raise ValueError(
                f"joint {name!r} is not the child of the joint before it: "
                "the core's dynamics takes a serial chain"
            )
        jm = model.joints[j]
        short = jm.shortname()
        kind: str | None = None
        axis: list[float] | None = None
        if short.startswith("JointModelR"):
            kind = "revolute"
        elif short.startswith("JointModelP"):
            kind = "prismatic"
        if short[-1] in _AXES and short[-2:-1] in ("R", "P", "B"):
            axis = _AXES[short[-1]]
        elif short.endswith("Unaligned"):
            axis = [float(x) for x in np.asarray(jm.extract().axis).ravel()]
        if kind is None or axis is None:
            raise ValueError(
                f"joint {name!r} is a {short}: the core's dynamics takes revolute and "
                "prismatic joints only"
            )
        placement = model.jointPlacements[j]
        joints.append(
            {
                "kind": kind,
                "translation": placement.translation.tolist(),
                "rotation": placement.rotation.tolist(),
                "axis": axis,
            }
        )
        inertia = model.inertias[j]
        inertials.append(
            {
                "mass": float(inertia.mass),
                "translation": inertia.lever.tolist(),
                "inertia": np.asarray(inertia.inertia).tolist(),
            }
        )
    return joints, inertials, [float(x) for x in model.gravity.linear]


class ComputedTorque:
    """Computed-torque impedance control (module doc), stepped by the core
    (SPEC §20) with the inertials of a Pinocchio model.

    The controller protocol of :func:`adaptimp.mujoco.simulate`: ``step(m,
    xc=, dxc=, ddxc=)`` (``m`` an :class:`adaptimp.Measurement`) at t_k =
    k·Ts returns the applied torque
    sat(τ) (N m); without a setpoint it follows ``trajectory`` (by default,
    for two joints, the paper's circle (64)). Behind an
    :class:`adaptimp.CartesianController` the core steps it in its own
    Cartesian step and native MuJoCo loop, in every formulation (SPEC (20.4)).

    Parameters
    ----------
    model : str, path, mujoco.MjModel or pinocchio.Model
        ``"two_link"`` (the paper's arm, the default), ``"panda"``, a URDF,
        xacro or MJCF path or a compiled MuJoCo model (read by the core, SPEC
        §21: the arm adaptimp's plant of the file drives, with ``tip`` and
        ``fix`` as :func:`adaptimp.mujoco.from_urdf` and
        :class:`adaptimp.mujoco.Plant` take them), or a serial
        ``pinocchio.Model``. The dynamics are the core's.
    Ts : float
        Period (s).
    Kp : float or (n,), optional
        Stiffness K_P of the error dynamics (1/s²): default 400 (ω = 20
        rad/s; SPEC (20.8), :func:`default_gains`).
    Kd : float or (n,), optional
        Damping K_D (1/s): default 40 (critically damped).
    tau_max : float or (n,), optional
        Actuator limits (N m); default the description's effort limits (the
        URDF's, the MJCF's actuators'), or the paper's [17, 15] for the
        paper's arm.
    mass_scale : float
        Every link mass and inertia of the controller's model times this
        (1: the exact model; 1.3: +30 %).
    payload : float
        A point mass (kg) at the last joint's frame of the controller's model:
        the exact model of a plant simulated with
        ``adaptimp.mujoco.simulate(..., payload=...)``; 0: the nominal model.
    Dd, Cd, Gd : float or (n,)
        Target impedance (3) (kg m², N m s/rad, N m/rad); default the paper's
        1, 10, 60.
    trajectory : callable, optional
        ``trajectory(t) -> (xc, dxc, ddxc)`` for steps given no setpoint.
    tip, fix :
        For a description: the link (body) or frame (site) that ends the arm,
        and joints to hold (SPEC §21).
    drive : bool, optional
        Whether the model has the description's drive terms (armature,
        viscous damping, friction loss), as the plant has them: None (the
        default) for an MJCF's (MuJoCo compiles them) and none for a URDF
        (:func:`adaptimp.mujoco.from_urdf` models the rigid body only, unless
        its ``drive=True``). ``.drive`` holds the values used.
    impedance : {"joint", "external"}
        ``"joint"`` (default): the compliant reference of SPEC §4 as above.
        ``"external"``: the setpoint is already compliant (an outer loop such
        as that of :class:`adaptimp.CartesianController` made it, SPEC §16):
        xd = xc, ẋd = ẋc, ẍd = ẍc, and τe enters only as the feedforward +τe.
    armature, damping, friction : float or (n,), optional
        The joints' drive in the controller's model (SPEC (20.5), (20.6); ≥ 0):
        the rotor inertia added to the mass matrix's diagonal (kg m²), the
        viscous damping b q̇ (N m s/rad) and the dry friction loss (N m) that
        the law compensates on its reference's velocity (MuJoCo's
        ``dof_armature``, ``dof_damping``, ``dof_frictionloss``). None (the
        default): the description's, as ``drive`` says (0 for a model).
    """

    def __init__(
        self,
        model: Any = "two_link",
        *,
        Ts: float = 1e-3,
        Kp: ArrayLike | None = None,
        Kd: ArrayLike | None = None,
        tau_max: ArrayLike | None = None,
        mass_scale: float = 1.0,
        payload: float = 0.0,
        Dd: ArrayLike = 1.0,
        Cd: ArrayLike = 10.0,
        Gd: ArrayLike = 60.0,
        trajectory: Reference | None = None,
        impedance: str = "joint",
        armature: ArrayLike | None = None,
        damping: ArrayLike | None = None,
        friction: ArrayLike | None = None,
        tip: str | None = None,
        fix: Sequence[str] = (),
        drive: bool | None = None,
    ) -> None:
        from . import _adaptimp

        if impedance not in ("joint", "external"):
            raise ValueError(f"impedance must be 'joint' or 'external', got {impedance!r}")
        self.impedance = impedance
        if drive is not None and not isinstance(drive, bool):  # 'yes' was taken as True
            raise TypeError(f"drive must be True, False or None, got {drive!r}")
        for name, value in (("Ts", Ts), ("mass_scale", mass_scale), ("payload", payload)):
            real = isinstance(value, (int, float, np.integer, np.floating))
            if isinstance(value, bool) or not real:
                raise TypeError(f"{name} must be a number, got {value!r:.60}")
        if not (mass_scale > 0 and math.isfinite(mass_scale)):
            raise ValueError(f"mass_scale must be > 0, got {mass_scale}")
        if not (math.isfinite(payload) and payload >= 0):
            raise ValueError(f"payload must be ≥ 0 kg, got {payload}")
        limits: FloatArray | None
        paper = isinstance(model, pin.Model) or (isinstance(model, str) and model == "two_link")
        if paper:
            if tip is not None or fix or drive:
                raise ValueError("tip, fix and drive apply to a robot description, not a model")
            exact = pinocchio_model(model)
            joints, inertials, gravity = core_description(exact)
            limits = np.asarray(exact.effortLimit, dtype=np.float64)
            lifted: list[dict[str, Any]] = []
            nothing = [0.0] * len(joints)
            self.drive: dict[str, list[float]] = dict.fromkeys(
                ("armature", "damping", "friction"), nothing
            )
        else:
            # A description (SPEC §21): the core's arm, its chain and bodies.
            arm = _arm(model, tip, fix)
            if arm.inertia_error is not None:
                raise ConfigError(arm.inertia_error)
            joints, inertials, gravity = arm.chain, arm.inertials, list(arm.gravity)
            # What an MJCF's gravity compensation (gravcomp) lifts: the plant's
            # qfrc_gravcomp, SPEC (20.1').
            lifted = (
                arm.lifted if any(x["mass"] != 0.0 or any(x["moment"]) for x in arm.lifted) else []
            )
            limits = np.asarray(arm.effort, dtype=np.float64)
            # The drive terms adaptimp's plant of the file has: an MJCF's
            # (MuJoCo compiles them), none for a URDF unless drive=True
            # (adaptimp.mujoco.from_urdf(..., drive=True)).
            use = arm.urdf is None if drive is None else drive
            zero = [0.0] * arm.n
            self.drive = {
                "armature": list(arm.armature) if use else zero,
                "damping": list(arm.damping) if use else zero,
                "friction": list(arm.friction) if use else zero,
            }
        n = self.n = len(joints)
        if not (Ts > 0 and math.isfinite(Ts)):
            raise ValueError(f"Ts must be > 0, got {Ts}")
        # SPEC (20.5'), (20.9): an MJCF's springs, and its drive as adaptimp's
        # plant of the file realises it over a period (its integrator's steps,
        # MuJoCo's soft friction).
        self.plant_drive: dict[str, Any] | None = None
        if not paper and use and arm.urdf is None:
            self.plant_drive = plant_drive(model, float(Ts), list(arm.joints), tip, fix)
        self._ts = float(Ts)
        kp, kd = default_gains(self._ts)
        self.Kp = _joint("Kp", kp if Kp is None else Kp, n)
        self.Kd = _joint("Kd", kd if Kd is None else Kd, n)
        self.Dd, self.Cd, self.Gd = _joint("Dd", Dd, n), _joint("Cd", Cd, n), _joint("Gd", Gd, n)
        if np.any(self.Dd <= 0):
            raise ValueError(f"Dd must be > 0, got {self.Dd}")
        if tau_max is None:
            usable = limits.shape == (n,) and np.all((limits > 0) & (limits < 1e300))
            tau_max = limits if usable else [17.0, 15.0] if n == 2 else None
            if tau_max is None:
                raise ValueError("the model has no effort limits: give tau_max")
        self.tau_max = _joint("tau_max", tau_max, n)
        self.mass_scale = float(mass_scale)
        given = {"armature": armature, "damping": damping, "friction": friction}
        self.drive = {
            k: _joint(k, self.drive[k] if v is None else v, n).tolist() for k, v in given.items()
        }
        self._core = _adaptimp.ComputedTorque(
            joints,
            inertials,
            gravity,
            Ts=self._ts,
            Kp=self.Kp.tolist(),
            Kd=self.Kd.tolist(),
            tau_max=self.tau_max.tolist(),
            Dd=self.Dd.tolist(),
            Cd=self.Cd.tolist(),
            Gd=self.Gd.tolist(),
            impedance=impedance,
            mass_scale=self.mass_scale,
            payload=float(payload),
            armature=self.drive["armature"],
            damping=self.drive["damping"],
            friction=self.drive["friction"],
            **(self.plant_drive or {}),
            lifted=lifted or None,
        )
        self._params: dict[str, Any] = {
            "Ts": self._ts,
            "Kp": self.Kp.tolist(),
            "Kd": self.Kd.tolist(),
            "tau_max": self.tau_max.tolist(),
            "mass_scale": self.mass_scale,
            "payload": float(payload),
            "Dd": self.Dd.tolist(),
            "Cd": self.Cd.tolist(),
            "Gd": self.Gd.tolist(),
            "impedance": impedance,
            **self.drive,
            "plant_drive": self.plant_drive,
        }
        if trajectory is None and n == 2:
            trajectory = paper_circle()
            self._params.update(
                xc_offset=[0.2, 0.2], xc_sin=[0.0, 0.2], xc_cos=[-0.2, 0.0], xc_omega=[math.pi] * 2
            )
        self._trajectory = trajectory
        self._core.set_trajectory(trajectory)
        self._step = self._core.step
        # The per-sample call goes straight to the core (its signature is
        # step's, below): no Python frame in between (docs/performance.md).
        if type(self).step is ComputedTorque.step:  # not a subclass's own step
            self.step = self._step  # type: ignore[method-assign,assignment]

    def reset(self) -> None:
        """Back to t = 0; the reference starts at the next setpoint."""
        self._core.reset()

    @property
    def core(self) -> Any:
        """The compiled controller (``adaptimp._adaptimp.ComputedTorque``) the
        core's loops step."""
        return self._core

    @property
    def trajectory(self) -> Callable[[float], Any] | None:
        """The built-in reference t -> (xc, dxc, ddxc) (rad, rad/s, rad/s²), or None."""
        return self._trajectory

    @property
    def core_joint(self) -> Any:
        """The core's controller, which a Cartesian controller steps itself
        (None for a subclass with a ``step`` of its own)."""
        return self._core if type(self).step is ComputedTorque.step else None

    @property
    def Ts(self) -> float:
        """Period Ts (s)."""
        return self._ts

    @property
    def ts(self) -> float:
        """Deprecated: the period is :attr:`Ts` (s)."""
        return period_alias(self)

    @property
    def t(self) -> float:
        """Time of the next step t_k = k·Ts (s)."""
        return int(self._core.steps) * self._ts

    @property
    def params(self) -> dict[str, Any]:
        """The gains, limits, target impedance and (if built in) the trajectory."""
        return dict(self._params)

    def _last(self, what: str) -> FloatArray:
        if self._core.steps == 0:
            return np.full(self.n, math.nan)
        return np.asarray(self._core.last(what), dtype=np.float64)

    @property
    def tau(self) -> FloatArray:
        """The last step's commanded torque τ before saturation (N m), (n,)."""
        return self._last("tau")

    @property
    def tau_sat(self) -> FloatArray:
        """The last step's applied torque sat(τ) (N m), (n,)."""
        return self._last("tau_sat")

    @property
    def xc(self) -> FloatArray:
        """The last step's setpoint (rad), (n,)."""
        return self._last("xc")

    @property
    def xd(self) -> FloatArray:
        """The last step's reference x_d (rad), (n,)."""
        return self._last("xd")

    @property
    def z1(self) -> FloatArray:
        """The last step's error x_d − q (rad), (n,)."""
        return self._last("z1")

    def mass_matrix(self, q: ArrayLike) -> FloatArray:
        """The controller's model M̂(q) (kg m²), (n, n) (the core's, SPEC (20.2))."""
        return np.asarray(self._core.mass_matrix(_joint("q", q, self.n)), dtype=np.float64)

    def bias(self, q: ArrayLike, dq: ArrayLike) -> FloatArray:
        """The controller's model ĥ = Ĉ(q, q̇) q̇ + Ĝ(q) (N m), (n,): RNEA with q̈ = 0."""
        q, dq = _joint("q", q, self.n), _joint("dq", dq, self.n)
        return np.asarray(self._core.inverse_dynamics(q, dq, np.zeros(self.n)), dtype=np.float64)

    def inverse_dynamics(self, q: ArrayLike, dq: ArrayLike, ddq: ArrayLike) -> FloatArray:
        """The controller's model M̂ q̈ + Ĉ q̇ + Ĝ (N m), (n,) (RNEA, SPEC (20.2);
        with the drive's armature and damping, (20.5)). q (rad), dq (rad/s), ddq
        (rad/s²), each (n,), checked (shape, finiteness) by the core."""
        return self._core.inverse_dynamics(q, dq, ddq)

    @overload
    def step(
        self,
        m: Measurement,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
    ) -> FloatArray: ...
    @overload
    def step(  # deprecated: the arrays' call, with a DeprecationWarning
        self,
        m: ArrayLike,
        tau_e: ArrayLike,
        dq: ArrayLike | None = None,
        xc: ArrayLike | None = None,
        dxc: ArrayLike | None = None,
        ddxc: ArrayLike | None = None,
    ) -> FloatArray: ...
    def step(self, *args: Any, **kwargs: Any) -> FloatArray:
        """One step at t_k = k·Ts (SPEC (20.3)); returns the applied torque
        sat(τ) (N m), (n,).

        ``m`` is an :class:`adaptimp.Measurement`: q (rad), dq (rad/s;
        required), tau_e (N m; None: zeros), each (n,); the setpoint xc
        (rad), dxc (rad/s), ddxc (rad/s²), (n,) (dxc, ddxc default 0; given
        positionally, a call skips the keyword dictionary), or none of them
        (then the built-in ``trajectory``). The arrays' call ``step(q, tau_e,
        dq, xc=, dxc=, ddxc=)`` works, with a ``DeprecationWarning``. An
        instance's ``step`` is the core's own method (this signature, no
        Python in between).
        """
        out: FloatArray = self._step(*args, **kwargs)
        return out

    def __repr__(self) -> str:
        return (
            f"adaptimp.baselines.ComputedTorque({self.n} joints, Ts = {self._ts:g} s, "
            f"mass_scale = {self.mass_scale:g})"
        )
