"""MuJoCo as the plant: real arms, contact from a physics engine (SPEC §13).

Needs the optional dependency MuJoCo (the extra ``mujoco``: ``pip install ".[mujoco]"``); the
rest of adaptimp never imports it.

- :class:`Plant` wraps a MuJoCo model of a serial arm with n ≤ 7 hinge joints,
  one torque actuator (``motor``) per joint: it reads τmax from the actuators'
  ``ctrlrange`` and says where the core's loop measures the force the arm
  exerts on its environment (mapped to joint space as τe = Jᵀ F_e); MuJoCo's
  constraint solver computes contact.
- :func:`simulate` closes the loop, the core's (SPEC §13.1): any controller
  with ``.step(m, **setpoint)`` (``m`` an :class:`adaptimp.Measurement`) and a period ``.Ts`` (s)
  (:class:`ControllerLike`, called back once a period), or one of the
  paper's cases by name, runs at Ts with the torque held over ``substeps``
  MuJoCo steps; returns a :class:`MujocoResult` with the SPEC §12 metrics.
- Models: :func:`two_link` (the paper's arm, packaged as ``models/two_link.xml``),
  :func:`panda` (the Franka Emika Panda of ``example-robot-data``, arm only, on a
  table), :func:`from_urdf` (any URDF arm, with motors from its effort limits).

The measured wrench. If the model has a ``force`` sensor, its site is the end
effector and F_e is read from it (with the ``torque`` sensor on the same site,
if any, for the moment; without one the moment is taken as zero). MuJoCo's
force/torque sensors measure the wrench between the site's body and its parent,
so the site should sit on a massless body welded to the last link, holding the
contact geometry: then the reading is exactly the contact wrench (the packaged
models do this). Without a force sensor, F_e is the net force of the active
contacts between the end-effector body's subtree and anything outside it,
with the moment about the end-effector point (the plant's ``tip``, by
default the last arm joint's body's origin): for a model :class:`Plant` loads from a
file and in which no contact can arise inside that subtree, from a contact
sensor it adds (the net contact wrench on the subtree, ``reduce="netforce"``;
it changes no dynamics); otherwise from the external forces MuJoCo sums from
its contact list on each body of the subtree (``cfrc_ext``: a contact inside
the subtree cancels). :attr:`Plant.wrench_source` says which is used.

Units: rad, rad/s, rad/s², N, N m, m, s. Vectors in the world frame.
"""

from __future__ import annotations

import contextlib
import copy
import math
import numbers
import os
import sys
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Protocol, Union

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._deprecated import period_of
from ._errors import ConfigError, PlantWarning, needs_extra, no_file
from ._inputs import reals

try:
    import mujoco
except ImportError as e:  # pragma: no cover - depends on the environment
    raise needs_extra("adaptimp.mujoco", "mujoco>=3", "mujoco") from e

from . import _adaptimp, _description, _mjcf, _models
from ._cartesian_task import (
    CartesianTask,
    chain_of,
    collision,
    measure,
    self_collision,
    task_of,
)
from ._faults import Fault
from ._mjcf import _full_inertia, _limits, _postures
from ._params import loop_delay
from ._plot import MUJOCO_FIGURES, MUJOCO_PLOT_KINDS
from ._pose import call_shape, task_space
from ._result import SimResult
from ._tooling import add_table, add_tool
from ._trajectory import Reference, paper_circle, sinusoid

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

__all__ = [
    "MAX_JOINTS",
    "CartesianTask",
    "ControllerLike",
    "MujocoResult",
    "Plant",
    "Reference",
    "Task",
    "cartesian_task",
    "chain_of",
    "collision",
    "default_task",
    "estimate_effort",
    "from_urdf",
    "home_posture",
    "moving_mass",
    "panda",
    "paper_circle",
    "rule_keywords",
    "self_collision",
    "simulate",
    "sinusoid",
    "two_link",
    "with_payload",
]

FloatArray = NDArray[np.float64]

MAX_JOINTS = 7
"""The most joints a :class:`Plant` accepts."""


ModelSource = Union["mujoco.MjModel", "mujoco.MjSpec", str, "os.PathLike[str]"]


class ControllerLike(Protocol):
    """What :func:`simulate` needs of a controller written in Python: a step and
    a period. The core's loop calls it back once a period (with the GIL taken
    for the call; the rest of the loop runs without it).

    ``step(m, **setpoint)`` returns the torque to apply (N m), (n,) (or one
    number for every joint; saturated by the motors). ``m`` is an
    :class:`adaptimp.Measurement`: what the loop's sensors read (with the
    disturbances of SPEC §17 and a fault, if any), ``m.q`` (rad), ``m.dq``
    (rad/s), ``m.tau_e`` (N m, (n,)) and the wrench at the tip ``m.wrench``
    F_e = [f; m] (N, N m, (6,), world frame; the plant's measurement of the
    row, the one τe is computed from): a joint-space controller reads τe, a
    task-space one F_e. Every controller of adaptimp takes the same call.
    ``setpoint`` is ``xc=, dxc=, ddxc=`` (the row's) when :func:`simulate` is
    given a ``reference``, nothing otherwise (the controller then follows
    its own trajectory). The period is ``.Ts`` (s; ``.ts`` is read,
    deprecated). Optional attributes that :func:`simulate` records when
    present: ``zeta`` (read before the step), then, after it, ``xc`` and,
    without a ``reference``, ``dxc``, ``ddxc`` (the controller's own
    commanded rates), ``xd``, ``z1``, ``dq_hat``, ``tau`` (commanded torque
    before saturation); and ``params`` (a dict; ``xc_offset``, ``xc_sin``,
    ``xc_cos``, ``xc_omega``, ``Dd``, ``Cd``, ``Gd`` are used for the metrics
    when present). An exception raised by ``step`` (or a torque of another
    shape) ends the run with it; a torque that is not finite ends it too
    (``ValueError``), unless a fault is injected: then the step is refused,
    as the core's controllers' are, and zero torque applied.

    A controller in task space says so with ``task_space = True`` (e.g.
    :class:`adaptimp.CartesianController`, which maps the wrench to the
    joints itself): its ``xc``, ``xd``, ``z1`` are then of width 3 (m).

    Deprecated (one release, with a ``DeprecationWarning``): a step that
    takes ``(q, tau_e, dq, **setpoint)`` (a step one positional argument
    cannot bind) is called so, and with ``wants_wrench = True`` (the old name
    of ``task_space``) as ``(q, dq, wrench, **setpoint)``.
    """

    # Typed by what every call needs, ``step(m)``: the setpoint keywords are
    # passed only with a ``reference``, and a step that takes them by name
    # (``xc=None, …``, as adaptimp's own controllers do) or as ``**setpoint``
    # fits alike; with ``**setpoint`` here, no named-keyword step would.
    def step(self, m: _adaptimp.Measurement, /) -> ArrayLike: ...


# ---------------------------------------------------------------------------
# Commanded trajectories.
# ---------------------------------------------------------------------------


# ---------------------------------------------------------------------------
# Models.
# ---------------------------------------------------------------------------


def two_link() -> mujoco.MjModel:
    """The paper's 2-link arm in a vertical plane (SPEC §1), ``models/two_link.xml``.

    The plane is MuJoCo's x-z plane (gravity −z), both hinges about −y, so q is
    the paper's (q1 from the horizontal, q2 relative). Motors with ctrlrange
    ±[17, 15] N m; a ceiling wall 0.20 m above the base that only the
    end-effector sphere touches; force/torque sensors at the site ``ee``;
    keyframe ``paper`` = the paper's q(0) = [0.25, −0.05]; RK4 at 50 µs.
    """
    return mujoco.MjModel.from_xml_path(str(_models.TWO_LINK_XML))


def _add_motors(spec: Any, effort: Mapping[str, float]) -> None:
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


def _spec_of(urdf: str) -> Any:
    spec = mujoco.MjSpec.from_string(urdf)
    # Keep the URDF's fixed links as bodies: a force sensor needs its own body.
    spec.compiler.fusestatic = False
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_RK4
    return spec


def _compile_arm(spec: Any, note: str = "", *, stacklevel: int = 3) -> mujoco.MjModel:
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


def _urdf_arm(
    path: str | os.PathLike[str], tip: str | None, fix: Sequence[str]
) -> _description.Arm:
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


def _arm_spec(arm: _description.Arm, timestep: float, *, drive: bool, stacklevel: int) -> Any:
    """The MjSpec of a URDF arm (its reduced URDF, RK4 at ``timestep`` s),
    with a motor per arm joint at ± its effort; where the URDF gives none,
    the estimate of :func:`estimate_effort` on the arm itself, with a warning
    at ``stacklevel``. With ``drive``, each arm joint's damping and friction
    loss as the URDF's ``<dynamics>`` states them."""
    text = arm.urdf_drive if drive else arm.urdf
    assert text is not None
    spec = _spec_of(text)
    spec.option.timestep = timestep
    missing = [j for j, e in zip(arm.joints, arm.effort) if not math.isfinite(e)]
    _add_motors(spec, {j: (e if math.isfinite(e) else 1.0) for j, e in zip(arm.joints, arm.effort)})
    if missing:
        estimate = estimate_effort(_compile_arm(spec, stacklevel=stacklevel + 1))
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
    arm = _urdf_arm(path, tip, fix)
    if not isinstance(drive, bool):  # 'yes' was taken as True
        raise TypeError(f"drive must be True or False, got {drive!r}")
    return _compile_arm(_arm_spec(arm, timestep, drive=drive, stacklevel=3))


def estimate_effort(model: mujoco.MjModel, postures: int = 256) -> FloatArray:
    """Effort limits (N m, per joint of ``model``'s arm) for an arm whose URDF
    gives none: 2 (max |G_i(q)| + 10 rad/s² · max Σ_j |D_ij(q)|) over
    ``postures`` postures within the joint limits (:func:`from_urdf`): gravity
    and an acceleration of 10 rad/s² of every joint at once, twice over (the
    core's rule, :func:`adaptimp._mjcf.estimate` without the drag terms)."""
    joints = sorted(range(model.njnt), key=lambda j: int(model.jnt_dofadr[j]))
    qadr = [int(model.jnt_qposadr[j]) for j in joints]
    dofs = [int(model.jnt_dofadr[j]) for j in joints]
    return _mjcf.estimate(model, qadr, dofs, postures, drag=False)


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
    arm = _urdf_arm(_models.panda_urdf_path(), _models.PANDA_EE, _models.PANDA_FINGERS)
    spec = _arm_spec(arm, timestep, drive=False, stacklevel=2)
    spec.modelname = "panda"
    add_tool(spec, _models.PANDA_EE, radius=tool_radius, own_body=False)
    if table_height is not None:
        add_table(spec, top=table_height, centre=(0.55, 0.0))
    spec.add_key(name="home", qpos=list(_models.PANDA_HOME))
    return spec.compile()


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


def _name(m: mujoco.MjModel, objtype: Any, i: int) -> str:
    return mujoco.mj_id2name(m, objtype, i) or f"#{i}"


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
        moves, else the origin of the last arm joint's body. A URDF's ``tip``
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
            _name(self.model, mujoco.mjtObj.mjOBJ_SITE, self._site)
            if self._site >= 0
            else _name(self.model, mujoco.mjtObj.mjOBJ_BODY, self._ee_body)
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
                objname=_name(self.model, mujoco.mjtObj.mjOBJ_BODY, self._ee_body),
                intprm=[_NETFORCE_DATA, _NETFORCE, 1],
            )
            sensed = True
        if isinstance(surface, str):
            surface = (surface,)
        for name in surface:
            _mjcf.resolve_tip(self.model, name)  # a body of the model, or refused by name
        if spec is not None and contact and _mjcf.Watch.of(self.model) is None:
            # The contacts of the arm with the rest of the scene, watched
            # through the run (SPEC §18.10): sensors, which change no dynamics.
            # The end effector on the task's own surface is the task's.
            own = [
                (_name(self.model, mujoco.mjtObj.mjOBJ_BODY, b), name)
                for b in sorted(self._ee_subtree)
                for name in surface
            ]
            sensed = _mjcf.watch_contacts(spec, self.model, self._joints, own) > 0 or sensed
        if sensed:
            assert spec is not None
            self._setup_model(spec.compile())
        self._watch = _mjcf.Watch.of(self.model) if contact else None
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
            f"the keyframe {_name(m, mujoco.mjtObj.mjOBJ_KEY, 0)!r}"
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
            name = _name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
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
                    f"{_name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a)!r}, commanded to it"
                )
            elif acts:
                out[name] = (
                    f"starts at {q:.4g} (its posture in {start}); its actuator "
                    f"{_name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, acts[0])!r} keeps the keyframe's "
                    "control (it holds no posture of its own)"
                )
            else:
                out[name] = f"passive: starts at {q:.4g} (its posture in {start})"
        return out

    # -- construction checks ------------------------------------------------

    @property
    def joint_names(self) -> list[str]:
        """The arm's joints, base to tip (the order of q)."""
        return [_name(self.model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in self._joints]

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
            f"{_name(m, mujoco.mjtObj.mjOBJ_JOINT, j)} ({mujoco.mjtJoint(m.jnt_type[j]).name})"
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
            if body == prev or prev not in self._ancestors(body):
                raise ValueError(
                    "Plant needs a serial chain, one joint per body: joint "
                    f"{_name(m, mujoco.mjtObj.mjOBJ_JOINT, j)!r} is not on a descendant "
                    f"of body {_name(m, mujoco.mjtObj.mjOBJ_BODY, prev)!r}"
                )
        self._last_body = bodies[-1]

    def _ancestors(self, body: int) -> list[int]:
        out = []
        while body > 0:
            body = int(self.model.body_parentid[body])
            out.append(body)
        return out

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
            jname = _name(m, mujoco.mjtObj.mjOBJ_JOINT, j)
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
            name = _name(m, mujoco.mjtObj.mjOBJ_SENSOR, sensors[0])
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
        subtree = [
            b for b in range(m.nbody) if b == self._ee_body or self._ee_body in self._ancestors(b)
        ]
        self._ee_subtree = frozenset(subtree)
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
        saved = mujoco.MjData(self.model)
        mujoco.mj_copyData(saved, self.model, self.data)
        try:
            yield
        finally:
            mujoco.mj_copyData(self.data, self.model, saved)

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

    def _core_spec(self, substeps: int) -> dict[str, Any]:
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
                _name(m, mujoco.mjtObj.mjOBJ_JOINT, int(m.dof_jntid[i])) for i in range(m.nv)
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
                _name(m, mujoco.mjtObj.mjOBJ_BODY, b1 if m.body_mocapid[b1] >= 0 else b2),
                _name(m, mujoco.mjtObj.mjOBJ_BODY, b2 if m.body_mocapid[b1] >= 0 else b1),
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


@dataclass(frozen=True)
class Task:
    """The default task of a plant (:func:`default_task`, SPEC §18).

    Attributes
    ----------
    home : ndarray, (n,)
        The posture the task swings about (rad).
    q0 : ndarray, (n,)
        Its start, at rest (rad): home − A.
    keywords : dict
        ``xc_offset``, ``xc_sin``, ``xc_cos``, ``xc_omega``: the controller's
        sinusoid (SPEC §4).
    period : float
        2 s.
    """

    home: FloatArray
    q0: FloatArray
    keywords: dict[str, list[float]]
    period: float

    @property
    def reference(self) -> Reference:
        """``reference(t) -> (xc, dxc, ddxc)``."""
        k = self.keywords
        return sinusoid(k["xc_offset"], k["xc_sin"], k["xc_cos"], k["xc_omega"])


HOME_SAMPLES = 256
"""Postures :func:`home_posture` compares."""

HOME_LOAD = 0.5
"""The zero posture is the home posture if gravity takes at most this share of
every effort limit over the task's swing (:func:`home_posture`)."""

HOME_CLEARANCE = 0.005
"""The clearance (m) the default task keeps between bodies that the arm moves
relative to each other (:func:`home_posture`)."""

SWING_SAMPLES = 21
"""Postures along the swing q − A … q + A at which :func:`home_posture` checks
for contact."""


def home_posture(plant: Plant) -> FloatArray:
    """A posture inside the joint limits where gravity is well within the
    effort limits and the task's swing touches nothing (SPEC §18). The
    gravity load of a posture q is the largest max_i |G_i|/τmax_i over the
    task's swing (q − A, q, q + A). Every posture is kept A = min(0.2 rad,
    range/4) inside each limit (a continuous joint ranges over [−π, π]).
    With contact on, a posture qualifies only if, at :data:`SWING_SAMPLES`
    postures along its swing q − A … q + A, no two bodies that the arm's
    joints move relative to each other (the arm and itself, or the arm and
    what is around it) come within :data:`HOME_CLEARANCE` of each other, by
    the model's own collision geometry and filters. The zero posture (the
    model's reference, clipped into the box) if it qualifies and its load is
    at most :data:`HOME_LOAD`; else the nearest qualifying posture of load at
    most :data:`HOME_LOAD` among 255 fixed-seed samples of the box drawn in
    towards it (the k-th by k/255 of the way out); else the qualifying one
    of least load.

    Raises
    ------
    ValueError
        Gravity exceeds an effort limit at every qualifying posture (the
        message gives the best load), or every posture's swing touches (the
        message names the bodies: give ``home=``).
    """
    m = plant.model
    lo, hi = _limits(m, plant._joints)
    width = np.where(np.isfinite(hi - lo), hi - lo, 2 * math.pi)
    amp = np.minimum(0.25 * width, TASK_AMPLITUDE)
    saved = (np.array(plant.data.qpos), np.array(plant.data.qvel))
    contacts = _mjcf.Contacts(m, saved[0], plant._joints, margin=HOME_CLEARANCE)
    swing = np.linspace(-1.0, 1.0, SWING_SAMPLES)
    touching: list[tuple[str, str, float]] = []

    def clear(q: FloatArray) -> bool:
        found = [c for s in swing for c in contacts.at(q + s * amp)]
        touching.extend(found)
        return not found

    samples = _postures(lo, hi, HOME_SAMPLES, amp)
    zero = samples[0]
    # Nearest the zero posture first: the samples drawn in towards it, the
    # k-th by k/(K − 1) of the way out.
    grow = np.arange(HOME_SAMPLES, dtype=np.float64)[:, None] / (HOME_SAMPLES - 1)
    near = zero + grow * (samples - zero)
    loads = [max(_gravity_load(plant, q + s * amp) for s in (-1.0, 0.0, 1.0)) for q in near]
    best, best_load = None, math.inf
    for q, load in zip(near, loads):
        if load <= HOME_LOAD and clear(q):
            best, best_load = q, load
            break
    if best is None:
        for k in np.argsort(loads, kind="stable"):
            if loads[k] < 1.0 and clear(near[k]):
                best, best_load = near[k], loads[k]
                break
        else:
            best_load = min(loads)
    plant.data.qpos[:], plant.data.qvel[:] = saved
    mujoco.mj_forward(m, plant.data)
    if best is None and touching:
        raise ValueError(
            f"the default task's swing (±A about the home posture) brings the arm's bodies "
            f"within {HOME_CLEARANCE:g} m of each other at every posture compared "
            f"({_mjcf.pairs(touching)}): give home= (rad), or simulate with contact=False"
        )
    if best is None or best_load >= 1.0:
        raise ValueError(
            f"gravity exceeds the effort limits at every posture compared: the least "
            f"max_i |G_i|/τmax_i found is {best_load:.3g} (τmax = {plant.tau_max.tolist()} N m)"
        )
    return np.asarray(best, dtype=np.float64)


def _gravity_load(plant: Plant, q: FloatArray) -> float:
    """max_i |G_i(q)|/τmax_i at rest."""
    d = plant.data
    d.qpos[plant._qadr] = q
    d.qvel[:] = 0.0
    mujoco.mj_forward(plant.model, d)
    return float(np.max(np.abs(d.qfrc_bias[plant._dofs]) / plant.tau_max))


TASK_AMPLITUDE = 0.2
"""The largest swing A (rad) of the default task."""


def default_task(plant: Plant, home: ArrayLike | None = None) -> Task:
    """The default task of ``plant`` (SPEC §18): about ``home`` (default
    :func:`home_posture`), every joint swings xc_i = home_i − A_i cos(π t)
    (period 2 s, from rest at home − A, through home, to home + A), A_i =
    min(0.2 rad, range/4), in free space. (The swing of every joint moves the
    arm's gravity and inertia, which learning must then learn; the metrics'
    windows of 2 s hold whole periods.)"""
    from . import tuning

    m = plant.model
    lo, hi = _limits(m, plant._joints)
    h = home_posture(plant) if home is None else plant._vector("home", home)
    kw = tuning.default_task(h, lo, hi)
    q0 = np.asarray(kw["xc_offset"]) + np.asarray(kw["xc_cos"])
    return Task(home=h, q0=q0, keywords=kw, period=2 * math.pi / kw["xc_omega"][0])


def rule_keywords(
    plant: Plant,
    task: Task | None = None,
    *,
    Ts: float = 1e-3,
    case: str = "sf",
    delay: int = 0,
) -> dict[str, Any]:
    """The rule's controller keywords for ``plant`` on ``task`` (default
    :func:`default_task`) at period ``Ts`` (s) for a loop of ``delay``
    periods, SPEC §18 (:func:`adaptimp.tuning.suggest` with D at the task's
    home, the plant's τmax and the task's path; (18.11) for the delay), with
    ``impedance="external"`` (in free space the controller tracks the
    reference as given). The plant's own model: give it the nominal plant (no
    payload)."""
    from . import tuning

    task = default_task(plant) if task is None else task
    saved = (np.array(plant.data.qpos), np.array(plant.data.qvel))
    kw = tuning.suggest(
        plant, task.home, plant.tau_max, Ts=Ts, path=task.reference, period=task.period,
        case=case, delay=delay,
    )  # fmt: skip
    plant.data.qpos[:], plant.data.qvel[:] = saved
    mujoco.mj_forward(plant.model, plant.data)
    kw["impedance"] = "external"
    return kw


def cartesian_task(
    model: Plant | ModelSource,
    q0: ArrayLike | None = None,
    pose: Any = None,
    *,
    Ts: float = 1e-3,
    span: float | None = None,
    tip: str | None = None,
    fix: Sequence[str] = (),
) -> CartesianTask:
    """A Cartesian task on ``model`` (SPEC §16 (16.8)–(16.11)), for
    ``simulate(case, model, T=…, task=task)``.

    ``pose`` None: the default path, hold the start pose 1 s, then a 3 cm circle
    at 0.5 Hz in the horizontal plane through it, the orientation held (an arm
    of fewer than six joints: the position only). Or the user's path: a callable
    ``t -> (p, ṗ, p̈[, R, ω, ω̇])`` (m, m/s, m/s², (3, 3), rad/s, rad/s²; world
    frame), or those arrays with a row per period ``Ts`` (K, 3), (K, 3, 3);
    ``span`` (s) the part of it the rule samples (default: the arrays' length,
    or 4 s for a callable).

    ``q0`` None: a start posture drawn by the core's posture rule (16.9):
    σmin of the 6 × n Jacobian ≥ 0.05, every joint 0.1 rad (or an eighth of
    its range) inside its limits, gravity ≤ half of every actuator, the joint
    rule's velocity loop well-conditioned and the path reachable, all along
    the task, and no self-collision there; for a given ``pose`` the start is
    the core's inverse kinematics of its first pose. A ``q0`` given must meet
    the same rule, or a ``ConfigError`` names the condition it violates.
    ``tip``, ``fix``: the end effector and the joints held, as :class:`Plant`'s
    (give the same to :func:`simulate`, or a :class:`Plant` to both).
    """
    if isinstance(model, Plant) and (tip is not None or tuple(fix)):
        raise ValueError("tip= and fix= build the Plant: give them to Plant(...), not with one")
    plant = model if isinstance(model, Plant) else Plant(model, contact=False, tip=tip, fix=fix)
    return task_of(plant, q0, pose, Ts=Ts, span=span)


class _Table:
    """A reference tabulated at t_k = k·Ts, as a callable of t (the row of t),
    with its arrays (xc, dxc, ddxc), one row per step."""

    def __init__(self, arrays: tuple[FloatArray, FloatArray, FloatArray], Ts: float) -> None:
        self.arrays, self.Ts = arrays, Ts

    def __call__(self, t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        xc, dxc, ddxc = self.arrays
        k = min(max(round(t / self.Ts), 0), xc.shape[0] - 1)
        return xc[k], dxc[k], ddxc[k]


def _checked_reference(reference: Reference, n: int) -> Reference:
    """``reference`` whose every value is checked: three arrays (xc, dxc, ddxc)
    of shape (n,), else an error naming the reference, t and what it gave (a
    2-tuple was an IndexError, a wrong length a broadcast error)."""

    def checked(t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        got = reference(t)
        values = tuple(got) if isinstance(got, (tuple, list)) else None
        if values is None or len(values) != 3:
            size = "not a tuple" if values is None else f"{len(values)} values"
            raise ValueError(
                f"reference(t) must return 3 arrays (xc, dxc, ddxc), got {size} at t = {t:g}"
            )
        out = []
        for name, v in zip(("xc", "dxc", "ddxc"), values):
            try:
                a = np.asarray(v, dtype=np.float64)
            except (TypeError, ValueError):
                raise TypeError(
                    f"reference(t)'s {name} must be reals, got {v!r} at t = {t:g}"
                ) from None
            if a.shape != (n,):
                raise ValueError(
                    f"reference(t)'s {name} must have shape ({n},), got {a.shape} at t = {t:g}"
                )
            out.append(a)
        return out[0], out[1], out[2]

    return checked


def _table_reference(reference: Any, n: int, Ts: float, steps: int) -> Reference:
    """``reference`` as a callable of t: a callable as it is; (xc, dxc, ddxc)
    arrays of shape (K, n), K ≥ ``steps`` (or an object with those attributes,
    e.g. a :class:`MujocoResult`), row k at t_k = k·Ts (n: the width of the
    controller's reference, 3 for a Cartesian controller's p_c)."""
    if isinstance(reference, _Table):
        return reference
    if callable(reference):
        return _checked_reference(reference, n)
    if all(hasattr(reference, a) for a in ("xc", "dxc", "ddxc")):
        reference = (reference.xc, reference.dxc, reference.ddxc)
    try:
        xc, dxc, ddxc = (np.asarray(a, dtype=np.float64) for a in reference)
    except (TypeError, ValueError) as e:
        raise TypeError(
            "reference must be a callable t -> (xc, dxc, ddxc), the arrays (xc, dxc, ddxc) "
            "of shape (K, n), or a result that has them"
        ) from e
    for name, a in (("xc", xc), ("dxc", dxc), ("ddxc", ddxc)):
        if a.ndim != 2 or a.shape[1] != n or a.shape[0] < steps:
            raise ValueError(
                f"reference {name} must have shape (K, {n}) with K ≥ {steps} rows (one per "
                f"step), got {a.shape}"
            )
        if not np.all(np.isfinite(a[:steps])):
            raise ValueError(f"reference {name} must be finite")
    return _Table((xc, dxc, ddxc), Ts)


# ---------------------------------------------------------------------------
# The result of a run.
# ---------------------------------------------------------------------------

PLOT_KINDS = MUJOCO_PLOT_KINDS
"""Kinds of :meth:`MujocoResult.plot`."""

ARRAYS = (
    "t", "q", "dq", "ddq", "xc", "dxc", "ddxc", "xd", "dq_hat", "tau", "tau_sat", "tau_e",
    "zeta", "z1", "x_ee", "wrench_ee",
)  # fmt: skip
"""Names of the recorded arrays of :class:`MujocoResult`."""


@dataclass(frozen=True, repr=False, eq=False)
class MujocoResult(SimResult):
    """A closed-loop run on a MuJoCo plant: one row k = 0 … K − 1 per controller
    step at t_k = k·Ts. A :class:`adaptimp.SimResult` (the same metrics,
    ``to_pandas``, ``save``), with the end effector's position and wrench, and
    the plot kinds of a MuJoCo run ("contact" besides SimResult's); ``w_norms``
    is NaN (the plant does not see the weights) and ``case`` is the
    controller's, or "custom".

    Per-joint arrays have shape (K, n); the reference arrays (K, m), m the
    dimension of the controller's xc (n in joint space).

    Attributes
    ----------
    t : (K,)
        Time t_k (s).
    q, dq, ddq : (K, n)
        Joint positions (rad), velocities (rad/s), and accelerations (rad/s²)
        at the row's state and applied torque (MuJoCo's q̈, contact included).
    xc, dxc, ddxc : (K, m)
        Commanded trajectory and its derivatives (NaN where unknown).
    xd : (K, m)
        Compliant reference (the controller's ``xd``; xc if it has none).
    dq_hat : (K, n)
        Velocity the controller used (its ``dq_hat``; dq if it has none).
    tau, tau_sat : (K, n)
        Commanded torque τ and the torque applied to the plant (N m).
    tau_e : (K, n)
        τe = Jᵀ F_e given to the controller (N m).
    zeta : (K, n)
        Auxiliary state ζ (N m; zero for controllers without one).
    z1 : (K, m)
        Tracking error xd − x (the controller's ``z1``, else xd − q).
    x_ee : (K, 3)
        End-effector position (m), world frame.
    wrench_ee : (K, 6)
        F_e: force (N) and moment (N m) the end effector exerts, world frame.
    task : dict or None
        A Cartesian controller's task-space rows (:class:`adaptimp.CartesianController`,
        the keys of its ``arrays()``): "pc", "dpc", "ddpc" (the commanded position
        and rates, = ``xc``, ``dxc``, ``ddxc``), "pd", "dpd", "ddpd" (the compliant
        reference, ``xd`` = pd), "qd" (the joint reference, (K, n)), "wrench" (the
        F_e it was given, (K, 6)), "error" (the impedance's [e_p; e_o], (K, 6)).
        None for a joint-space controller (and for a Cartesian one called back
        with ``record=False``).
    metrics : dict
        The SPEC §12 metrics, with the keys of :attr:`adaptimp.SimResult.metrics`
        (NaN where they do not apply: ``imp_err_rms_after2`` needs a joint-space
        reference).
    params : dict
        The run: ``Ts``, ``substeps``, ``timestep``, ``T``, ``settle``,
        ``contact``, ``tau_max``, ``wrench_source``, ``model``, ``joints``
        (the arm's joint names, base to tip), ``controller``,
        ``loop`` (``"native"``: the core stepped the controller;
        ``"callback"``: the core's loop called a controller written in Python).
    """

    x_ee: FloatArray | None = None
    wrench_ee: FloatArray | None = None
    task: dict[str, FloatArray] | None = None

    _own_params = ("controller", "model", "Ts", "substeps", "contact", "settle")

    def _own_arrays(self) -> dict[str, FloatArray]:
        out = {n: a for n in ("x_ee", "wrench_ee") if (a := getattr(self, n)) is not None}
        out.update({f"task.{k}": v for k, v in (self.task or {}).items()})
        return out

    @classmethod
    def _own_fields(cls, arrays: Mapping[str, Any]) -> dict[str, Any]:
        fields: dict[str, Any] = {n: arrays[n] for n in ("x_ee", "wrench_ee") if n in arrays}
        task = {k[len("task.") :]: v for k, v in arrays.items() if k.startswith("task.")}
        if task:
            fields["task"] = task
        return fields

    @property
    def rows(self) -> int:
        """Number of recorded rows K."""
        return int(self.t.shape[0])

    @property
    def pos_err(self) -> FloatArray | None:
        """A Cartesian task's position error ‖p_c − p‖ per row (m), (K,) (None for
        a run without a ``task``)."""
        return None if self.task is None else self.task.get("pos_err")

    @property
    def rot_err(self) -> FloatArray | None:
        """A Cartesian task's orientation error ‖Log(R_c Rᵀ)‖ per row (rad), (K,)
        (None for a run without a ``task``)."""
        return None if self.task is None else self.task.get("rot_err")

    @property
    def dtau(self) -> FloatArray:
        """sat(τ) − τ (N m), (K, n)."""
        return self.tau_sat - self.tau

    def plot(self, kind: str = "tracking", ax: Axes | Sequence[Axes] | None = None) -> Figure:
        """A matplotlib figure of the run, one panel per joint (or per force axis).

        kind : {"tracking", "errors", "torques", "contact"}
            q against xc and xd; z1; τ and sat(τ) with ±τmax; the end-effector
            force F_e (N) and ‖τe‖ (N m).
        ax : Axes or sequence of Axes, optional
            Draw "tracking", "errors" or "torques" into these axes, as
            :meth:`adaptimp.SimResult.plot` does.
        """
        if ax is not None:
            return super().plot(kind, ax)
        if kind not in PLOT_KINDS:
            raise ValueError(f"kind must be one of {PLOT_KINDS}, got {kind!r}")
        return MUJOCO_FIGURES[kind](self)

    def __repr__(self) -> str:
        m, p = self.metrics, self.params
        return (
            f"MujocoResult({p['controller']} on {p['model']}: {self.rows} steps of Ts = "
            f"{p['Ts']:g} s, {p['substeps']} MuJoCo steps each; contact "
            f"{'on' if p['contact'] else 'off'})\n"
            f"  RMS ‖z1‖ = {m['rms_z1']:.4g}, over t ≥ {p['settle']:g} s: "
            f"{m['rms_z1_after2']:.4g}; saturated {100 * m['sat_duty']:.1f}% of steps; "
            f"{m['steps_in_contact']} steps in contact"
        )


# ---------------------------------------------------------------------------
# The closed loop.
# ---------------------------------------------------------------------------


def _period(ctrl: Any) -> float:
    value = getattr(ctrl, "Ts", None)
    if value is not None:
        return float(value)
    old = period_of(ctrl)  # the earlier name, deprecated
    if old is not None:
        return old
    raise TypeError(f"the controller {ctrl!r} has no period: give it a .Ts (s)")


def _builtin_reference(ctrl: Any) -> Reference | None:
    """The controller's own sinusoid (SPEC §4), if its params declare one."""
    params = getattr(ctrl, "params", None)
    keys = ("xc_offset", "xc_sin", "xc_cos", "xc_omega")
    if isinstance(params, Mapping) and all(k in params for k in keys):
        return sinusoid(*(params[k] for k in keys))
    return None


DISTURBANCES = (
    "noise_q",
    "noise_dq",
    "noise_tau_e",
    "seed",
    "plant_delay",
    "jitter",
    "friction_viscous",
    "friction_coulomb",
    "friction_vs",
    "actuator_fraction",
)
"""The disturbances of SPEC §17 that :func:`simulate` takes by name (the
schema's; ``jitter`` must stay 0 on MuJoCo, whose timestep is fixed for a run)."""


def _native(ctrl: Any) -> bool:
    """Whether the core can step ``ctrl`` itself: an ``adaptimp.Controller``
    whose ``step`` is the compiled one."""
    return isinstance(ctrl, _adaptimp.Controller) and type(ctrl).step is _adaptimp.Controller.step


def _native_computed(ctrl: Any) -> bool:
    """Whether the core can step ``ctrl`` as it is in joint space: an
    :class:`adaptimp.baselines.ComputedTorque` (its own ``step``, the core's
    law of SPEC §20)."""
    baselines = sys.modules.get("adaptimp.baselines")
    return (
        baselines is not None
        and isinstance(ctrl, baselines.ComputedTorque)
        and isinstance(ctrl._core_joint, _adaptimp.ComputedTorque)
    )


def _native_cartesian(ctrl: Any) -> bool:
    """Whether the core can step ``ctrl`` as a whole: an
    :class:`adaptimp.CartesianController` (its own ``step``) in front of a
    joint controller the core steps (a case name's)."""
    from .cartesian import CartesianController

    return (
        isinstance(ctrl, CartesianController)
        and type(ctrl).step is CartesianController.step
        and ctrl._core_inner
        and (_native(ctrl.inner) or isinstance(ctrl._joint, _adaptimp.ComputedTorque))
    )


def _tabulate(
    reference: Reference, steps: int, Ts: float, width: int, k0: int = 0
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``reference((k0 + k)·Ts)`` for every row k, as three (K, ``width``)
    arrays (called in order, once per row, as the loop would; a table's own
    rows), by the core's tabulation (``_adaptimp.tabulate_joints``)."""
    if isinstance(reference, _Table) and math.isclose(reference.Ts, Ts, rel_tol=1e-12) and not k0:
        xc, dxc, ddxc = (np.ascontiguousarray(a[:steps]) for a in reference.arrays)
        return xc, dxc, ddxc
    xc, dxc, ddxc = _adaptimp.tabulate_joints(
        reference, steps, Ts, width, k0, "reference(t)", _reals_of_shape
    )
    return xc, dxc, ddxc


def _reals_of_shape(name: str, value: Any, shape: tuple[int, ...]) -> FloatArray:
    """The core's tabulation's check of a value that is not a float64 array of
    ``shape`` (:func:`adaptimp._inputs.reals`, NaN let through as before)."""
    return reals(name, value, shape, finite=False)


def _uses_rule(plant: Plant) -> bool:
    """True unless ``plant`` is the paper's arm, whose scenario has its own defaults."""
    return _model_name(plant.model) != "adaptimp_two_link"


def _model_name(model: mujoco.MjModel) -> str:
    return str(model.names[: model.names.find(b"\0")].decode())


def _payload_plant(nominal: Plant, payload: float) -> Plant:
    """The plant with ``payload`` kg at its end effector's link (the nominal
    plant itself for 0)."""
    if isinstance(payload, bool) or not isinstance(payload, (int, float, np.floating, np.integer)):
        raise TypeError(f"payload must be a number (kg), got {type(payload).__name__}")
    if payload == 0:
        return nominal
    plant = Plant(
        with_payload(nominal.model, float(payload), body=nominal._last_body),
        contact=nominal.contact,
        tip=nominal.tip,
    )
    plant.notes = nominal.notes
    return plant


def _rule_setup(
    plant: Plant,
    case: str,
    params: Mapping[str, Any],
    reference: Any,
    Ts: float,
    T: float,
    home: ArrayLike | None = None,
    delay: int = 0,
) -> tuple[Task | None, Any, dict[str, Any]]:
    """The task and the rule's keywords for a case name on ``plant`` (SPEC §18):
    the default task unless a reference or the controller's own trajectory
    (``xc_*``) is given, which is then the path."""
    own = [k for k in ("xc_offset", "xc_sin", "xc_cos", "xc_omega") if k in params]
    if home is not None and (reference is not None or own):
        raise ValueError(
            "home= sets the default task's posture: give it without a reference or xc_*"
        )
    if reference is None and not own:
        task = default_task(plant, home)
        kw = rule_keywords(plant, task, Ts=Ts, case=case, delay=delay)
        kw.pop("n")
        return task, task.reference, kw
    from . import tuning

    if reference is None:
        from ._params import defaults as scenario_defaults

        base = scenario_defaults("robot", plant.n)
        xc = {k: params.get(k, base[k]) for k in ("xc_offset", "xc_sin", "xc_cos", "xc_omega")}
        path = sinusoid(xc["xc_offset"], xc["xc_sin"], xc["xc_cos"], xc["xc_omega"])
        w = np.abs(np.broadcast_to(np.asarray(xc["xc_omega"], dtype=np.float64), (plant.n,)))
        period = 2 * math.pi / float(np.min(w[w > 0])) if np.any(w > 0) else T
    else:
        path = _table_reference(reference, plant.n, Ts, round(T / Ts))
        period = T
    home = np.asarray(path(0.0)[0], dtype=np.float64)
    saved = (np.array(plant.data.qpos), np.array(plant.data.qvel))
    kw = tuning.suggest(
        plant, home, plant.tau_max, Ts=Ts, path=path, period=period, case=case, delay=delay
    )
    plant.data.qpos[:], plant.data.qvel[:] = saved
    mujoco.mj_forward(plant.model, plant.data)
    kw.pop("n")
    kw["impedance"] = "external"
    return None, reference, kw


def simulate(
    controller: str | ControllerLike = "sf",
    model: Plant | ModelSource = "two_link",
    *,
    T: float | None = None,
    Ts: float | None = None,
    substeps: int | None = None,
    q0: ArrayLike | None = None,
    dq0: ArrayLike | None = None,
    reference: Reference | Any | None = None,
    contact: bool = True,
    settle: float | None = None,
    scenario: str = "robot",
    record_every: int = 1,
    progress: bool | Callable[[int, int], object] = False,
    fault: Fault | None = None,
    payload: float = 0.0,
    reset: bool = True,
    tip: str | None = None,
    fix: Sequence[str] = (),
    home: ArrayLike | None = None,
    task: CartesianTask | None = None,
    gravity: str | None = None,
    **params: Any,
) -> MujocoResult:
    """Run a controller on a MuJoCo plant: the loop of SPEC §11 with MuJoCo as the plant.

    At every t_k = k·Ts: MuJoCo computes contact and sensors at the state
    (with the torque applied over the last period), the controller is given
    ``(q, tau_e, dq[, xc=, dxc=, ddxc=])`` and returns a torque; it is
    saturated to the actuators' τmax and held for ``substeps`` MuJoCo steps of
    Ts / substeps each (SPEC §13.1).

    The loop, the recording and the metrics are the compiled core's, MuJoCo
    is driven through its C library and the GIL is released (Ctrl-C is
    honoured within 0.2 s, also within a period of many substeps). The core
    steps an ``adaptimp.Controller`` (or a case name), an
    :class:`adaptimp.CartesianController` in front of one (or of computed
    torque) and :class:`adaptimp.baselines.ComputedTorque` itself; any other
    controller (:class:`ControllerLike`) is called back once a period, with
    the GIL taken for that call (``params["loop"]`` is then ``"callback"``).

    Parameters
    ----------
    controller : str or controller
        ``"pd"``, ``"sf"`` or ``"of"`` builds ``adaptimp.Controller(case,
        scenario=scenario, Ts=Ts, tau_max=<the plant's>, **params)``; or any
        object of the :class:`ControllerLike` protocol (e.g. an
        ``adaptimp.Controller`` or :class:`adaptimp.baselines.ComputedTorque`),
        used as it is (reset it first if it has run before).
    model : Plant, MjModel, str or path
        The plant, or what :class:`Plant` takes (default the paper's arm).
    T : float, optional
        Duration (s); rows k = 0 … round(T/Ts) − 1. Default: the scenario's T.
    Ts : float, optional
        Controller period (s). Default: the controller's; for a case name the
        scenario's (``"robot"``: 1 ms, ``"paper"``: 50 µs). Must equal the
        period of a given controller.
    substeps : int, optional
        MuJoCo steps per period, 1 ≤ substeps ≤ 10 000; MuJoCo's timestep
        becomes Ts / substeps. Default: round(Ts / the model's timestep), at
        least 1.
    q0, dq0 : array_like, optional
        Initial joint positions (rad) and velocities (rad/s); default the
        default task's start (below), else the model's first keyframe (the
        paper's q(0) for ``two_link``), else the reference's start xc(0),
        ẋc(0), else qpos0.
    reference : callable or arrays, optional
        ``reference(t) -> (xc, dxc, ddxc)``, or the arrays (xc, dxc, ddxc) of
        shape (K, n) with a row per step (K ≥ round(T/Ts)), or a result that
        has them (e.g. a :class:`MujocoResult`: the same task again): passed
        to every step as ``xc=, dxc=, ddxc=``. None: the default task (below),
        or the controller's own trajectory.
    contact : bool
        False: free space (MuJoCo's contact disabled). Ignored for a Plant.
    settle : float, optional
        Start of the "after2" metrics (s), ≥ 0; default the scenario's (2 s),
        whose metrics are NaN for a shorter run. One given must leave a
        recorded step in the window (settle ≤ (round(T/Ts) − 1) Ts), as in
        :func:`adaptimp.simulate`.
    scenario : {"robot", "paper"}
        Defaults for a case name (see :func:`adaptimp.simulate`).
    record_every : int
        Keep every k-th row (k ≥ 1); the metrics still see every step.
    progress : bool or callable
        ``True``: a progress bar for runs longer than 2 s; a callable is called
        as ``progress(done, total)`` about every 50 ms, and once when the run ends.
    fault : adaptimp.Fault, optional
        A fault injected over a window, as for :func:`adaptimp.simulate` (the
        actuators' τmax for ``"actuator_drop"``), for any controller.
    payload : float
        A point mass (kg, ≥ 0) at the end effector's link of the plant only
        (:func:`with_payload`); the controller's gains come from the arm
        without it, and no model the controller is given has it.
    task : CartesianTask, optional
        A Cartesian task (:func:`cartesian_task`): a case name's controller is
        then the Cartesian controller of the core's rule for it
        (:meth:`adaptimp.CartesianController.from_rule`), started at
        ``task.q0``; the result carries the task's errors, ``res.pos_err``,
        ``res.rot_err`` (K,) (m, rad), and ``metrics["rms_pos_after2"]``,
        ``["rms_rot_after2"]`` (SPEC (16.11)).
    reset : bool
        True: the plant starts at ``q0``, ``dq0``. False: a :class:`Plant` goes
        on from where its last run left it (a long run in parts: with a used
        controller, the parts are the whole run's rows; each part's t starts
        at 0 and its disturbances afresh); ``q0``, ``dq0`` must then be None
        and ``payload`` 0.
    tip, fix : optional
        The end effector (a site or a body; a URDF's link) and joints to lock,
        for the :class:`Plant` built from ``model`` (not for a Plant given).
    home : array_like, optional
        The posture (rad, (n,)) the default task swings about, instead of
        :func:`home_posture`'s.
    gravity : {None, "model"}
        ``"model"``: a case name's controller (joint space, or the Cartesian
        one of ``task``) feeds the plant's nominal model's gravity G₀(q)
        forward, SPEC (20.10), read by the core from the plant's model (the
        arm without the run's ``payload``): for a robot that does not
        compensate gravity itself, the arm does not sag while the networks
        learn. None (default, SPEC's law): gravity is left to the networks,
        as on a robot that compensates it (Franka).
    **params
        The disturbances of SPEC §17 (:data:`DISTURBANCES`: sensor noise,
        delay, joint friction, weak actuators; the controller is told none of
        them), for any controller; and, for a case name, controller parameters
        (``Kp``, ``gamma``, …).

    Notes
    -----
    **Any arm, out of the box** (SPEC §18, ``docs/your_arm.md``). A case name
    on any model but the paper's ``two_link`` is built by the rule of
    :func:`rule_keywords` (gains from the arm's inertia, the centres and
    learning along the task's path, ``impedance="external"``): with no
    ``reference`` and no ``xc_*`` keyword the task is :func:`default_task`
    (a joint-space swing of ±0.2 rad at 0.5 Hz about :func:`home_posture`,
    from rest); a given ``reference`` is the path instead. Keywords given in
    ``params`` replace the rule's. The result's ``xc``, ``dxc``, ``ddxc``
    (K, n) are the reference tracked, so that any other controller can run
    the same task: ``simulate(ct, model, reference=res, q0=res.q[0],
    payload=...)``.

    Returns
    -------
    MujocoResult
        Arrays, the SPEC §12 metrics, ``.plot(kind)``.

    Raises
    ------
    DivergedError
        MuJoCo warned during a period (it resets a diverged state and only
        counts a warning), its time did not advance, or the state is not
        finite: the message names the row, the time and MuJoCo's warning.

    Examples
    --------
    >>> from adaptimp import mujoco as amj
    >>> res = amj.simulate("sf", "two_link", T=0.05, contact=False)
    >>> res.q.shape, res.params["substeps"]
    ((50, 2), 20)
    """
    if gravity not in (None, "model"):
        raise ConfigError(f"gravity must be None or 'model', got {gravity!r}")
    if task is not None:  # the Cartesian task's controller, by the core's rule
        if not isinstance(task, CartesianTask):
            raise TypeError(
                f"task must be a CartesianTask (from adaptimp.mujoco.cartesian_task), got "
                f"{type(task).__name__} {task!r:.60}"
            )
        if home is not None:
            raise ValueError("home= sets the default joint-space task: give q0= to cartesian_task")
        if reference is not None:
            raise ValueError(
                "give the task or a reference, not both: the arm would track the reference "
                "while the task's errors were measured against its own path"
            )
        if not isinstance(model, Plant):
            model = Plant(model, contact=contact, tip=tip, fix=fix)
            tip, fix = None, ()
        params = dict(params)
        if gravity is not None:
            params["gravity"] = gravity
        delay = loop_delay(params)
        controller, params = task.prepare(
            controller, model, Ts, {**params, "delay": delay}, DISTURBANCES
        )
        q0 = task.q0 if q0 is None else q0
    elif gravity is not None:
        if not isinstance(controller, str):
            raise TypeError(
                "gravity='model' builds a case name's controller ('pd', 'sf', 'of'); give "
                "your own controller its gravity itself (adaptimp.Controller(gravity=...))"
            )
        params = {**params, "gravity": gravity}
    run = _setup(
        controller, model, T=T, Ts=Ts, substeps=substeps, q0=q0, dq0=dq0, contact=contact,
        settle=settle, scenario=scenario, record_every=record_every, reference=reference,
        payload=payload, params=params, reset=reset, tip=tip, fix=fix, home=home,
    )  # fmt: skip
    from ._api import _progress

    callback, bar = _progress(progress, "mujoco.simulate")
    core_fault = None if fault is None else fault._core(run.plant.n)
    try:
        out = _LOOPS[run.kind](run, callback, core_fault)
    finally:
        if bar is not None:
            bar.close()
    targets = out.pop("targets", None)
    res = _result(run, out, out.pop("metrics"))
    if task is not None:
        task.measure(res)
    elif targets is not None:
        # A Cartesian controller's run, whichever way it was built: its pose
        # errors against the commanded pose of every row (SPEC (16.11)).
        measure(res, run.ctrl.chain, targets)
    _check_run(run, res)
    _check_delay(res)
    _check_tracking(run, res)
    _check_refused(res, fault)
    return res


RUN_TRACKING = 0.5
"""A joint-space run whose RMS tracking error over t ≥ settle exceeds this share
of the reference's own RMS motion there says so (:func:`simulate`'s check)."""


def _check_tracking(run: _Run, res: MujocoResult) -> None:
    """A joint-space run on an arm whose arm did not follow its task says so
    (a :class:`adaptimp.PlantWarning`, also in ``res.params["warnings"]``):
    the RMS ‖z1‖ over t ≥ settle beyond :data:`RUN_TRACKING` of the RMS of the
    reference's motion about its mean over the same rows (an arm that sags
    or rings through its task, whatever the reason: gains too low for its
    load, a delay that leaves little bandwidth, SPEC (18.11))."""
    if not _uses_rule(run.plant) or task_space(run.ctrl) or res.rows == 0:
        return
    rows = res.t >= run.settle - 1e-12
    if not np.any(rows) or res.xc.shape != res.q.shape:
        return
    xc = res.xc[rows]
    motion = float(np.sqrt(np.mean(np.sum((xc - xc.mean(axis=0)) ** 2, axis=1))))
    error = float(res.metrics.get("rms_z1_after2", math.nan))
    if not (motion > 0 and error > RUN_TRACKING * motion):
        return
    text = (
        f"the arm did not follow its task: RMS tracking error {error:.3g} rad over "
        f"t ≥ {run.settle:g} s, more than {RUN_TRACKING:g} of the reference's own RMS motion "
        f"{motion:.3g} rad (gains too low for the load or the loop's delay, SPEC (18.11))"
    )
    res.params.setdefault("warnings", []).append(text)
    warnings.warn(text, PlantWarning, stacklevel=3)


def _check_delay(res: MujocoResult) -> None:
    """SPEC (18.11): a controller made for a shorter delay than the plant's
    says so (a :class:`adaptimp.PlantWarning`, also in
    ``res.params["warnings"]``): its velocity loop's gains are sized for a
    loop that answers sooner than this one does, and may ring."""
    made, plant = res.params.get("delay"), int(res.params.get("plant_delay", 0))
    if made is None or made >= plant:
        return
    text = (
        f"the controller was made for a loop delay of {made} period(s), the plant's is "
        f"{plant}: its velocity loop may ring (SPEC (18.11)); build it with delay={plant}, "
        f"or give simulate delay={plant} and a case name"
    )
    res.params.setdefault("warnings", []).append(text)
    warnings.warn(text, PlantWarning, stacklevel=3)


def _check_refused(res: MujocoResult, fault: Fault | None) -> None:
    """Steps refused where no fault was injected, said (a
    :class:`adaptimp.PlantWarning`, in ``res.params["warnings"]``): with a
    fault configured a refused step applies the fallback and the run goes
    on, and a controller whose every torque was refused (a step that returned
    NaN) ran 200 of 200 rows at zero torque with no word."""
    if res.refused is None or not res.refused.any():
        return
    t = res.t
    outside = res.refused.copy()
    if fault is not None:
        start = float(fault.start)
        end = start + float(fault.duration or 0.0)
        outside &= (t < start - 1e-12) | (t >= end - 1e-12)
    if not outside.any():
        return
    first = float(t[np.flatnonzero(outside)[0]])
    text = (
        f"{int(outside.sum())} of {res.rows} recorded steps were refused"
        f"{' outside the fault' if fault is not None else ''} (the first at t = {first:.3f} s): "
        "the controller's step failed there (a torque or a measurement that was not finite, "
        "or beyond its limits) and its fallback was applied"
    )
    res.params.setdefault("warnings", []).append(text)
    warnings.warn(text, PlantWarning, stacklevel=3)


RUN_PEAK = 2.0
"""A run whose commanded |τ_i| exceeds this many τmax_i after :data:`RUN_SETTLE`
says so (:func:`simulate`'s check)."""

RUN_SETTLE = 0.1
"""The start (s) of the peak-torque check."""

RUN_SATURATED = 0.01
"""A run whose torque is at a limit in more than this share of its steps says so."""

RUN_CONTACT_EVERY = 0.01
"""The spacing (s) of the recorded rows at which a run's self-contact is checked."""


def _check_run(run: _Run, res: MujocoResult) -> None:
    """What a run found that its numbers alone do not say (SPEC §18, §18.10),
    as :class:`adaptimp.PlantWarning` and in ``res.params["warnings"]``: the
    arm touching itself (rows every :data:`RUN_CONTACT_EVERY` s replayed
    through MuJoCo's collision detection); the arm touching the rest of the
    scene (another arm, a pedestal, the table, a free body: the plant's
    watched contacts, at the end of every period; a contact task's own
    surface is not watched); a commanded torque beyond :data:`RUN_PEAK` τmax
    after :data:`RUN_SETTLE` s; the torque at a limit in more than
    :data:`RUN_SATURATED` of the steps. Every run is checked, in contact or
    not, joint or Cartesian. ``res.params["plant"]`` is what the plant made
    of the model (:attr:`Plant.notes`). Not for the paper's arm, whose
    scenario saturates by design."""
    plant = run.plant
    res.params["plant"] = dict(plant.notes)
    found: list[str] = []
    if _uses_rule(plant) and res.rows > 0:
        found += _self_contact(plant, res)
    if plant._watch is not None and _uses_rule(plant):
        found += _scene_contact(plant, int(res.metrics.get("rows", run.steps)), run.Ts)
    if _uses_rule(plant) and res.rows > 0:
        found += torque_findings(res.t, res.tau, plant.tau_max, plant.joint_names,
                                 float(res.metrics.get("sat_duty", math.nan)))  # fmt: skip
    res.params["warnings"] = found
    for text in found:
        warnings.warn(text, PlantWarning, stacklevel=3)


def torque_findings(
    t: FloatArray,
    tau: FloatArray,
    tau_max: ArrayLike,
    joints: Sequence[str],
    sat_duty: float,
) -> list[str]:
    """The torque checks of every run (SPEC §18): the commanded |τ_i| (N m,
    rows ``tau`` at times ``t``, s) beyond :data:`RUN_PEAK` τmax_i after
    :data:`RUN_SETTLE` s, and the torque at a limit in more than
    :data:`RUN_SATURATED` of the steps (``sat_duty``, the run's metric)."""
    found: list[str] = []
    limit = np.asarray(tau_max, dtype=np.float64)
    late = np.flatnonzero(np.asarray(t) >= RUN_SETTLE - 1e-12)
    if late.size:
        ratio = np.abs(np.asarray(tau)[late]) / limit
        k, i = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
        if ratio[k, i] > RUN_PEAK:
            found.append(
                f"the commanded torque reached {ratio[k, i]:.3g} τmax after {RUN_SETTLE:g} s "
                f"(joint {joints[int(i)]!r} at t = {t[late[k]]:.3f} s), beyond "
                f"{RUN_PEAK:g} τmax: the controller asks far more than the actuators give"
            )
    if sat_duty > RUN_SATURATED:
        found.append(
            f"the torque was at a limit in {100 * sat_duty:.1f} % of the steps (more than "
            f"{100 * RUN_SATURATED:g} %): the actuators saturate, so the tracking measured is "
            "theirs as much as the controller's"
        )
    return found


def _scene_contact(plant: Plant, rows: int, Ts: float) -> list[str]:
    """The warning of a run in which the arm touched the rest of the scene
    (the plant's watched contacts, SPEC §18.10), if it did."""
    assert plant._watch is not None
    return scene_contact_findings(plant._watch.found(plant.data), rows, Ts)


def scene_contact_findings(
    found: Sequence[tuple[str, str, int, float, int]], rows: int, Ts: float
) -> list[str]:
    """The warning for watched contacts ``found`` ((arm body, other body,
    periods in contact, peak force N, its row), :class:`adaptimp._mjcf.Watch`)
    over a run of ``rows`` periods of ``Ts`` s: the pairs by name, most
    steps first, each with its share of the steps, its peak force and when."""
    if not found or rows <= 0:
        return []
    pairs: dict[tuple[str, str], list[float]] = {}
    for a, b, count, peak, row in found:
        key = (a, b)
        old = pairs.get(key)
        if old is None:
            pairs[key] = [count, peak, row]
        else:  # one pair watched twice (a body and a subtree): the larger
            old[0] = max(old[0], count)
            if peak > old[1]:
                old[1], old[2] = peak, row
    order = sorted(pairs.items(), key=lambda kv: (-kv[1][0], -kv[1][1]))
    said = "; ".join(
        f"{a!r}–{b!r} in {100 * c / rows:.1f} % of the steps, up to {f:.3g} N "
        f"(t = {(r + 1) * Ts:.3f} s)"
        for (a, b), (c, f, r) in order[:3]
    )
    more = f"; and {len(order) - 3} more pairs" if len(order) > 3 else ""
    return [
        f"the arm touched the rest of the scene: {said}{more}: the task runs into what is "
        "around the arm, so the tracking measured is the contact's as much as the "
        "controller's; give another home= or reference, or move what is in the way"
    ]


def _self_contact(plant: Plant, res: MujocoResult) -> list[str]:
    """The warning of a run in which the arm touched itself, if it did."""
    m = plant.model
    if m.opt.disableflags & int(mujoco.mjtDisableBit.mjDSBL_CONTACT):
        return []
    contacts = _mjcf.Contacts(m, plant.data.qpos, plant._joints, self_only=True)
    if not contacts.possible:
        return []
    dt = float(res.t[1] - res.t[0]) if res.rows > 1 else 1.0
    stride = max(1, round(RUN_CONTACT_EVERY / dt))
    rows = range(0, res.rows, stride)
    touched: list[tuple[str, str, float]] = []
    first, hits = math.nan, 0
    for k in rows:
        found = contacts.at(res.q[k])
        if found:
            hits += 1
            touched += found
            if math.isnan(first):
                first = float(res.t[k])
    if not hits:
        return []
    return [
        f"the arm touched itself in {100 * hits / len(rows):.1f} % of the rows checked "
        f"({_mjcf.pairs(touched)}; first at t = {first:.3f} s): its own links collide along "
        "this task; give another home= or reference (or contact=False)"
    ]


def _native_loop(
    run: _Run, progress: Callable[[int, int], object] | None, fault: Any
) -> dict[str, Any]:
    """An ``adaptimp.Controller`` stepped by the core, along its own
    trajectory or the run's reference tabulated at t_k."""
    refs = (
        None if run.reference is None else _tabulate(run.reference, run.steps, run.Ts, run.plant.n)
    )
    out: dict[str, Any] = _adaptimp.simulate_mujoco(
        run.ctrl, run.plant.model, run.plant.data, run.spec, run.dist, run.T, run.settle,
        run.every, progress, refs, fault,
    )  # fmt: skip
    return out


def _cartesian_loop(
    run: _Run, progress: Callable[[int, int], object] | None, fault: Any
) -> dict[str, Any]:
    """The native loop of an :class:`adaptimp.CartesianController` whose joint
    controller the core steps: its commanded pose tabulated for every row
    (the reference at t_k, else its path on its own clock), then the core's
    loop; the controller's Python side brought up to date, whatever happens."""
    ctrl, reference = run.ctrl, run.reference
    table = reference.arrays if isinstance(reference, _Table) else reference
    targets = ctrl._targets(run.steps, table)
    k0 = ctrl._k
    task: dict[str, Any] | None = None
    try:
        out: dict[str, Any] = ctrl.outer.core.simulate_mujoco(
            ctrl._joint, run.plant.model, run.plant.data, run.spec, run.dist, run.T,
            run.settle, run.every, progress, targets, fault,
        )  # fmt: skip
        task = out["task"]
    except BaseException as e:
        # Stopped (Ctrl-C, a diverged plant): the rows of the steps it took
        # (the exception's `partial`), which the log keeps as the clock does.
        task = getattr(e, "partial", None)
        raise
    finally:
        ctrl._ran(targets, task, k0)
    out["targets"] = _pose_table(ctrl, targets, out.get("task"), run.every)
    return out


def _pose_table(
    ctrl: Any, targets: FloatArray | None, log: dict[str, FloatArray] | None, every: int
) -> FloatArray | None:
    """The commanded pose of every step of a Cartesian controller's run (steps,
    24): its ``targets``, or, where it held its last target (no path, no
    reference), the run's commanded positions ``log["pc"]`` (kept every
    ``every``-th row) with the rotation held."""
    if targets is not None:
        return targets
    if log is None or "pc" not in log or len(log["pc"]) == 0:
        return None
    pc = np.asarray(log["pc"], dtype=np.float64)
    table = np.zeros((len(pc) * every, 24))
    table[:, 0:3] = np.repeat(pc, every, axis=0)
    table[:, 9:18] = np.asarray(ctrl.outer._R, dtype=np.float64).reshape(9)
    return table


def _computed_loop(
    run: _Run, progress: Callable[[int, int], object] | None, fault: Any
) -> dict[str, Any]:
    """:class:`adaptimp.baselines.ComputedTorque` stepped by the core in joint
    space, along the run's reference or its own trajectory, tabulated at its
    t_k = (k0 + k)·Ts (k0 the steps it took before), as its ``step`` samples it."""
    ctrl, Ts = run.ctrl, run.Ts
    if run.reference is not None:
        refs = _tabulate(run.reference, run.steps, Ts, run.plant.n)
    else:
        if ctrl._trajectory is None:
            raise ValueError("no setpoint given and no trajectory to follow")
        k0 = int(ctrl._core.steps)
        refs = _tabulate(lambda t: ctrl._trajectory(t), run.steps, Ts, run.plant.n, k0)
    out: dict[str, Any] = ctrl._core.simulate_mujoco(
        run.plant.model, run.plant.data, run.spec, run.dist, run.T, run.settle, refs,
        run.every, progress, fault,
    )  # fmt: skip
    return out


_ATTRIBUTES = ("tau", "xc", "dxc", "ddxc", "xd", "z1", "dq_hat", "zeta")
"""The attributes of a controller written in Python that a run records (ControllerLike)."""


def _callback_loop(
    run: _Run, progress: Callable[[int, int], object] | None, fault: Any
) -> dict[str, Any]:
    """A controller written in Python in the core's loop, called back once a
    period (the protocol :class:`ControllerLike`): its setpoint (the
    reference's rows) and the attributes it has, the rates of its own
    trajectory (if its params declare one), and its target impedance for
    the metrics, given to the core."""
    ctrl, n, steps, Ts = run.ctrl, run.plant.n, run.steps, run.Ts
    in_task = task_space(ctrl)
    call = call_shape(ctrl)
    width = 3 if in_task else n
    has = {name: hasattr(ctrl, name) for name in _ATTRIBUTES}
    reference = run.reference
    own_rates = reference is None and has["dxc"] and has["ddxc"]
    if reference is not None:
        table = _tabulate(reference, steps, Ts, width)
    else:
        nan = np.full((steps, width), math.nan)
        # The rates of its own joint-space sinusoid, if its params declare one.
        rates = None if own_rates or in_task else _builtin_rates(ctrl, steps, Ts)
        table = (nan, *(rates or (nan, nan)))
    attrs = [name for name in ("tau", "xc", "xd", "z1", "dq_hat", "zeta") if has[name]]
    # An adaptimp.CartesianController's commanded pose of every step (or that of
    # one behind an object of the user's), for its pose errors: taken before it
    # steps (its path on its own clock).
    cartesian = in_task and hasattr(ctrl, "chain") and callable(getattr(ctrl, "_targets", None))
    poses = None
    if cartesian:
        given = reference.arrays if isinstance(reference, _Table) else reference
        poses = ctrl._targets(steps, given)
    cparams = getattr(ctrl, "params", None)
    cparams = cparams if isinstance(cparams, Mapping) else {}
    target = tuple(
        np.broadcast_to(np.asarray(cparams.get(k, v), dtype=np.float64), (n,)).tolist()
        for k, v in (("Dd", 1.0), ("Cd", 10.0), ("Gd", 60.0))
    )
    out: dict[str, Any] = _adaptimp.simulate_mujoco_callback(
        ctrl, run.plant.model, run.plant.data, run.spec, run.dist, Ts, run.T, run.settle, table,
        setpoint=reference is not None, task_space=in_task, call=call,
        attrs=attrs + (["rates"] if own_rates else []), target=target, record_every=run.every,
        progress=progress, fault=fault,
    )  # fmt: skip
    # A task-space controller's own log of this run (adaptimp.CartesianController.arrays).
    log = getattr(ctrl, "arrays", None) if in_task and getattr(ctrl, "record", False) else None
    if callable(log):
        out["task"] = {k: v[len(v) - steps :: run.every] for k, v in log().items()}
    if cartesian:
        out["targets"] = _pose_table(ctrl, poses, out.get("task"), run.every)
    return out


def _builtin_rates(ctrl: Any, steps: int, Ts: float) -> tuple[FloatArray, FloatArray] | None:
    """ẋc, ẍc of every row of the controller's own sinusoid, if its params
    declare one (for the impedance metric), on its clock from the steps it
    says it took."""
    builtin = _builtin_reference(ctrl)
    if builtin is None:
        return None
    k0 = getattr(ctrl, "steps", 0)
    k0 = k0 if isinstance(k0, int) else 0
    # (sinusoid's reference broadcasts: one row per time.)
    own = (k0 + np.arange(steps, dtype=np.float64)) * Ts
    _, dxc, ddxc = builtin(own[:, None])  # type: ignore[arg-type]
    return np.ascontiguousarray(dxc, dtype=np.float64), np.ascontiguousarray(ddxc, dtype=np.float64)


_LOOPS: dict[str, Callable[[_Run, Callable[[int, int], object] | None, Any], dict[str, Any]]] = {
    "native": _native_loop,
    "cartesian": _cartesian_loop,
    "computed": _computed_loop,
    "callback": _callback_loop,
}
"""How the core's loop takes each kind of controller (:func:`_setup` says which)."""


@dataclass
class _Run:
    """A run of :func:`simulate`, set up: its controller, plant and settings."""

    ctrl: Any
    plant: Plant
    label: str
    scenario: str
    Ts: float
    T: float
    settle: float
    substeps: int
    steps: int
    every: int
    dist: dict[str, Any]
    spec: dict[str, Any]
    kind: str
    reference: Reference | None
    task: Task | None
    payload: float
    q0: FloatArray


MAX_SUBSTEPS = 10_000
"""The most MuJoCo steps per control period (the core's bound)."""


def _check_arguments(T: object, Ts: object, substeps: object) -> None:
    """``T`` and ``Ts`` real numbers (s) or None, ``substeps`` an integer in
    1 … :data:`MAX_SUBSTEPS` or None: refused by name before any work."""
    for name, value in (("T", T), ("Ts", Ts)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, numbers.Real)):
            raise TypeError(f"{name} must be a real number (s), got {type(value).__name__}")
    if substeps is None:
        return
    if isinstance(substeps, bool) or not isinstance(substeps, numbers.Integral):
        raise TypeError(
            f"substeps must be an integer (MuJoCo steps per period), got {type(substeps).__name__}"
        )
    if not 1 <= int(substeps) <= MAX_SUBSTEPS:
        raise ConfigError(
            f"condition 1 ≤ substeps ≤ 10 000 is violated: substeps = {int(substeps)} "
            "(MuJoCo steps per period)"
        )


def _kind(ctrl: Any) -> str:
    """How the core's loop takes ``ctrl``: ``"native"`` (an
    ``adaptimp.Controller``), ``"cartesian"`` (an
    :class:`adaptimp.CartesianController` in front of a joint controller the
    core steps), ``"computed"`` (computed torque in joint space) or
    ``"callback"`` (written in Python: called back once a period)."""
    if _native_cartesian(ctrl):
        return "cartesian"
    if task_space(ctrl):
        return "callback"
    if _native(ctrl):
        return "native"
    return "computed" if _native_computed(ctrl) else "callback"


def _setup(
    controller: str | ControllerLike,
    model: Plant | ModelSource,
    *,
    T: float | None = None,
    Ts: float | None = None,
    substeps: int | None = None,
    q0: ArrayLike | None = None,
    dq0: ArrayLike | None = None,
    contact: bool = True,
    settle: float | None = None,
    scenario: str = "robot",
    record_every: int = 1,
    reference: Any = None,
    payload: float = 0.0,
    params: Mapping[str, Any],
    reset: bool = True,
    tip: str | None = None,
    fix: Sequence[str] = (),
    home: ArrayLike | None = None,
) -> _Run:
    """Everything :func:`simulate` does before the loop: the controller, the
    plant at its initial state, the settings and the kind of loop."""
    from ._api import Controller, _record_every
    from ._params import SCENARIOS, check_settle, resolve

    _check_arguments(T, Ts, substeps)
    defaults = SCENARIOS.get(scenario)
    if defaults is None:
        raise ValueError(f"scenario must be one of {sorted(SCENARIOS)}, got {scenario!r}")
    every = _record_every(record_every)
    if not reset and (q0 is not None or dq0 is not None or payload != 0):
        raise ValueError(
            "q0, dq0 and a payload start a run afresh: give them with reset=True (the default)"
        )
    if isinstance(model, Plant) and (tip is not None or tuple(fix)):
        raise ValueError("tip= and fix= build the Plant: give them to Plant(...), not with one")
    nominal = model if isinstance(model, Plant) else Plant(model, contact=contact, tip=tip, fix=fix)
    plant = _payload_plant(nominal, payload)
    task: Task | None = None
    params = dict(params)
    delay = loop_delay(params)
    disturb = {k: params.pop(k) for k in DISTURBANCES if k in params}
    if home is not None and not (isinstance(controller, str) and _uses_rule(nominal)):
        raise ValueError(
            "home= sets the default task of a case name on an arm (not the paper's two_link)"
        )
    if isinstance(controller, str):
        kwargs = dict(params)
        if _uses_rule(nominal):
            task, reference, rule = _rule_setup(
                nominal, controller, kwargs, reference, Ts or float(defaults["Ts"]),
                float(defaults["T"]) if T is None else float(T), home, delay,
            )  # fmt: skip
            kwargs = {**rule, **kwargs}
            if q0 is None and task is not None:
                q0 = task.q0
        kwargs.setdefault("tau_max", plant.tau_max.tolist())
        kwargs["delay"] = delay
        if kwargs.get("gravity") == "model":  # (20.10): the nominal plant's, no payload
            kwargs["gravity"] = nominal
        if Ts is not None:
            kwargs["Ts"] = Ts
        if plant.n != 2:
            kwargs["n"] = plant.n
        ctrl: Any = Controller(controller, scenario=scenario, **kwargs)
        label = f"adaptimp.Controller({controller!r}, scenario={scenario!r})"
    else:
        if params:
            raise TypeError(
                f"controller parameters {sorted(params)} apply to a case name only; "
                "configure the controller object itself"
            )
        ctrl = controller
        label = type(controller).__name__
        joints = getattr(ctrl, "n", None)
        if isinstance(joints, int) and not isinstance(joints, bool) and joints != plant.n:
            # It failed later as "noise_q: wrong length", noise_q never given.
            raise ConfigError(
                f"the controller ({label}) has {joints} joints, the plant {plant.n} "
                f"({', '.join(plant.joint_names)}): build the controller for the plant's arm"
            )
    period = _period(ctrl)
    if Ts is not None and not math.isclose(Ts, period, rel_tol=1e-12):
        raise ValueError(f"Ts = {Ts:g} s differs from the controller's period {period:g} s")
    Ts = period
    T = float(defaults["T"]) if T is None else float(T)
    given_settle = settle is not None
    settle = float(defaults["settle"]) if settle is None else float(settle)
    # Checked before it is used: round(inf) overflows, round(nan) raises.
    if not (math.isfinite(T) and T > 0):
        raise ValueError(f"T must be finite and > 0, got {T}")
    if T / Ts > 1e15:
        raise ValueError("T / Ts: the run must have at most 1e15 steps")
    steps = round(T / Ts)
    if steps < 1:
        raise ValueError(f"T = {T:g} s is shorter than one period Ts = {Ts:g} s")
    # As the rigid plant's simulate (the core's condition).
    if not math.isfinite(settle):
        raise ConfigError(f"settle must be finite, got {settle!r}")
    if settle < 0:
        raise ConfigError(f"condition settle ≥ 0 is violated: settle = {settle:g} (SPEC §10)")
    if given_settle:
        check_settle(settle, T, Ts)
    if substeps is None:
        substeps = max(1, round(Ts / plant.timestep))
        if substeps > MAX_SUBSTEPS:
            raise ConfigError(
                f"condition 1 ≤ substeps ≤ 10 000 is violated: substeps = round(Ts / the "
                f"model's timestep) = {substeps}: give substeps"
            )
    resolved = resolve(disturb, scenario="robot", groups=("sim",), caller="simulate()", n=plant.n)
    dist = {k: resolved[k] for k in DISTURBANCES}
    # A Cartesian controller's reference is its commanded position p_c (3,).
    in_task = task_space(ctrl)
    if reference is not None:
        reference = _table_reference(reference, 3 if in_task else plant.n, Ts, steps)
        if q0 is None and plant.model.nkey == 0 and not in_task and reset:
            start = reference(0.0)
            q0 = np.asarray(start[0], dtype=np.float64)
            dq0 = np.asarray(start[1], dtype=np.float64) if dq0 is None else dq0
    plant.timestep = Ts / int(substeps)
    if reset:
        plant.reset(q0, dq0)
    if plant._watch is not None:  # this run's contacts only
        plant._watch.clear(plant.data)
    return _Run(
        ctrl, plant, label, scenario, Ts, T, settle, int(substeps), steps, every, dist,
        plant._core_spec(int(substeps)), _kind(ctrl), reference, task, float(payload), plant.q,
    )  # fmt: skip


def _controller_delay(ctrl: Any) -> int | None:
    """The loop's delay (periods) ``ctrl`` was made for, SPEC (18.11): an
    ``adaptimp.Controller``'s ``delay``, a Cartesian controller's joint
    controller's; None for a controller that does not say."""
    for c in (ctrl, getattr(ctrl, "inner", None)):
        params = getattr(c, "params", None)
        if isinstance(params, Mapping) and isinstance(params.get("delay"), int):
            return int(params["delay"])
    return None


def _result(run: _Run, out: dict[str, Any], m: dict[str, Any]) -> MujocoResult:
    plant, ctrl = run.plant, run.ctrl
    name = plant.model.names[: plant.model.names.find(b"\0")].decode()
    params = {
        "Ts": run.Ts,
        "substeps": run.substeps,
        "timestep": plant.timestep,
        "T": run.T,
        "settle": run.settle,
        "contact": plant.contact,
        "tau_max": plant.tau_max.tolist(),
        "wrench_source": plant.wrench_source,
        "model": name,
        "joints": list(plant.joint_names),
        "controller": run.label,
        "loop": "callback" if run.kind == "callback" else "native",
        "payload": run.payload,
        "q0": run.q0.tolist(),
        **run.dist,
    }
    # SPEC (18.11): the delay the controller was made for, beside the plant's
    # (``plant_delay``); they differ only for a controller the caller made.
    params["delay"] = _controller_delay(ctrl)
    if run.task is not None:
        params["task"] = {"home": run.task.home.tolist(), **run.task.keywords}
    case = getattr(ctrl, "case", None)
    case = case if isinstance(case, str) else getattr(getattr(ctrl, "inner", None), "case", None)
    return MujocoResult(
        case=case if isinstance(case, str) else "custom",
        scenario=run.scenario,
        params=params,
        metrics=m,
        record_every=run.every,
        **out,
    )


def _run_many(
    jobs: Sequence[tuple[str, str, str, Mapping[str, Any]]],
    threads: int | None = None,
    progress: Callable[[int, int], object] | None = None,
) -> list[dict[str, Any] | str]:
    """Runs ``(case, scenario, model, keywords)`` of :func:`simulate`, their
    SPEC §12 metrics or their errors as text: in the core, on ``threads``
    threads (every core if None) with the GIL released, each run with its own
    controller and MuJoCo data; a run the core cannot take alone (a reference
    callable, a progress report) runs here through :func:`simulate`. Results
    are those of :func:`simulate`, bit for bit."""
    out: list[dict[str, Any] | str | None] = [None] * len(jobs)
    native: list[tuple[int, _Run]] = []
    for i, (case, scenario, model, kw) in enumerate(jobs):
        kw = dict(kw)
        try:
            if kw.get("reference") is not None or kw.get("progress"):
                out[i] = dict(simulate(case, model, scenario=scenario, **kw).metrics)
                continue
            names = (
                "T", "Ts", "substeps", "q0", "dq0", "contact", "settle", "record_every", "payload",
            )  # fmt: skip
            run = _setup(
                case, model, scenario=scenario, params=kw,
                **{k: kw.pop(k) for k in names if k in kw},
            )  # fmt: skip
            assert run.kind == "native", run.kind  # a case name: an adaptimp.Controller
            native.append((i, run))
        except Exception as e:  # a run's failure, whatever it is (a model's ParseError)
            out[i] = f"{type(e).__name__}: {e}"
    if native:
        results = _adaptimp.simulate_mujoco_many(
            [
                (
                    r.ctrl,
                    r.plant.model,
                    r.plant.data,
                    r.spec,
                    r.dist,
                    r.T,
                    r.settle,
                    None
                    if r.reference is None
                    else _tabulate(r.reference, r.steps, r.Ts, r.plant.n),
                )
                for _, r in native
            ],
            threads,
            progress,
        )
        for (i, _), result in zip(native, results):
            out[i] = result
    return [r if r is not None else "no result" for r in out]
