"""Contact that holds (SPEC §19, ``docs/contact.md``): the table scenario on any arm.

:func:`arm_table` builds the scenario "panda-table" (:mod:`adaptimp.scenarios.panda_table`)
for any serial arm given as a URDF: the arm in MuJoCo with a tool sphere and a
force/torque sensor at its tip, a table in front of it, the path (the home
posture held while the networks learn gravity, an approach arriving at rest
on the table's surface, the depth δ_c pressed in, then a 5 cm circle at 0.25
Hz on it; SPEC (19.6)), placed from the arm's reach at its home posture. The
table is rigid (MuJoCo's contact) or, with ``spring=k_e``, mounted on a
vertical spring of stiffness k_e (N/m): a compliant environment where SPEC
(16.1) prescribes the force.

:func:`contact_metrics` gives a run's metrics under the names of the
scenario's JSON table: ``track_mm``, ``force_rms_err_N``, ``force_target_N``,
``force_chatter_N``, ``contact_lost_s``, ``peak_tau_ratio``, ``sat_duty``.

MuJoCo and Pinocchio are imported when a function needs them. Units: m, s,
rad, N, N m, kg.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .._errors import ConfigError
from ..chain import Chain
from ._contact_checks import DEFAULT_MD as DEFAULT_MD
from ._contact_checks import LEARN_KEYS as LEARN_KEYS
from ._contact_checks import NORMAL_SAMPLES as NORMAL_SAMPLES
from ._contact_checks import REFUSAL_ROWS as REFUSAL_ROWS
from ._contact_checks import RINGING as RINGING
from ._contact_checks import ROBUST_SLOPE as ROBUST_SLOPE
from ._contact_checks import SHARE as SHARE
from ._contact_checks import TABLE_ROWS as TABLE_ROWS
from ._contact_checks import check_press, refusal_of, sag
from ._contact_checks import contact_metrics as contact_metrics
from ._contact_checks import normal_inertia as normal_inertia
from ._contact_checks import row_controller as row_controller
from ._contact_checks import rule_keywords as rule_keywords
from ._contact_checks import run_row as run_row
from ._contact_checks import velocity_loop_radius as velocity_loop_radius
from ._contact_model import ADMITTANCE_SHARE_OF_PERIOD as ADMITTANCE_SHARE_OF_PERIOD
from ._contact_model import (
    AXIS_SHARE,
    CLEARANCE,
    CONTACT_K1,
    MIN_REACH_SHARE,
    NOMINAL_KD,
    OUTWARD,
    REACH_SHARE,
    SAG_MARGIN,
    T_APPROACH,
    T_HOLD,
    T_PRESS,
    TABLE_OFFSET_MARGIN,
    THROUGH_TABLE,
    FloatArray,
    arm_model,
    joint_vector,
)
from ._contact_model import CONTACT_IMPEDANCE as CONTACT_IMPEDANCE
from ._contact_model import MAX_PATH_STEPS as MAX_PATH_STEPS
from ._contact_model import SLIP_SHARE as SLIP_SHARE
from ._contact_model import TABLE_MASS as TABLE_MASS
from ._contact_model import TABLE_TIMECONST as TABLE_TIMECONST
from ._contact_model import contact_impedance as contact_impedance
from ._contact_model import sliding_timeconst as sliding_timeconst
from .panda_table import PandaTable
from .panda_table import table_metrics as table_metrics  # (importable from here before)

__all__ = [
    "ADMITTANCE_SHARE_OF_PERIOD",
    "AXIS_SHARE",
    "CLEARANCE",
    "CONTACT_IMPEDANCE",
    "CONTACT_K1",
    "MAX_PATH_STEPS",
    "MIN_REACH_SHARE",
    "OUTWARD",
    "REACH_SHARE",
    "SAG_MARGIN",
    "SLIP_SHARE",
    "TABLE_MASS",
    "TABLE_TIMECONST",
    "T_APPROACH",
    "T_HOLD",
    "T_PRESS",
    "arm_model",
    "arm_table",
    "contact_impedance",
    "contact_metrics",
    "normal_inertia",
    "placement",
    "placements",
    "refusal_of",
    "rule_keywords",
    "sag",
    "sliding_timeconst",
    "velocity_loop_radius",
]


def placement(
    chain: Chain,
    home: ArrayLike,
    limits: tuple[ArrayLike, ArrayLike],
    *,
    tool_radius: float = 0.01,
    seed: int = 0,
    clearance: float = CLEARANCE,
) -> tuple[FloatArray, float, float]:
    """Where the table and the circle go for an arm at ``home`` (rad), from its
    reach (SPEC §19, "the scenario on any arm").

    With p_h the tip at home and u the horizontal unit vector from the base's
    vertical axis to p_h (the base's x axis if p_h is within :data:`AXIS_SHARE`
    of R of that axis): the circle's centre lies :data:`OUTWARD` beyond p_h
    along u, but at least :data:`MIN_REACH_SHARE` and at most
    :data:`REACH_SHARE` of the horizontal reach R (the
    largest horizontal distance of the tip over 1024 postures drawn uniformly
    within ``limits`` = (lo, hi) (rad), each clipped to ±π, seed ``seed``); the
    table top lies ``clearance`` (m, default :data:`CLEARANCE`) below the tool
    sphere at home.

    Returns (centre (2,) m, table top m, R m). ``ConfigError`` (naming it and
    the value) for a ``tool_radius`` that is not a finite number > 0, a
    ``clearance`` that is not a finite number ≥ 0, a
    ``home`` or a limit that is not n finite numbers, and lo > hi.
    """
    _check_scenario(tool_radius=tool_radius, clearance=clearance)
    tool_radius, clearance = float(tool_radius), float(clearance)
    q = joint_vector("home", home, chain)
    unlimited = " (±π for an unlimited joint)"
    lo_given = joint_vector("limits[0] (lo)", limits[0], chain, unlimited)
    hi_given = joint_vector("limits[1] (hi)", limits[1], chain, unlimited)
    inverted = np.flatnonzero(lo_given > hi_given)
    if inverted.size:
        i = int(inverted[0])
        raise ConfigError(
            f"limits must have lo ≤ hi for every joint; joint {i} ({chain.joint_names[i]!r}) "
            f"has lo = {float(lo_given[i])!r} > hi = {float(hi_given[i])!r}"
        )
    p = np.asarray(chain.fk(q)[:3, 3], dtype=np.float64)
    lo = np.clip(lo_given, -math.pi, math.pi)
    hi = np.clip(hi_given, -math.pi, math.pi)
    samples = np.random.default_rng(seed).uniform(lo, hi, size=(1024, q.shape[0]))
    reach = max(float(np.linalg.norm(chain.fk(s)[:2, 3])) for s in samples)
    radial = float(np.linalg.norm(p[:2]))
    # A tip near the base's axis (a folded arm at rest) has no direction of
    # its own: the base's forward axis x.
    u = p[:2] / radial if radial > AXIS_SHARE * reach else np.array([1.0, 0.0])
    dist = min(max(radial + OUTWARD, MIN_REACH_SHARE * reach), REACH_SHARE * reach)
    return dist * u, float(p[2] - tool_radius - clearance), reach


def _limits(plant: Any) -> tuple[FloatArray, FloatArray]:
    """The arm's joint ranges (rad) from the MuJoCo model (±π where unlimited)."""
    m = plant.model
    lo = np.full(plant.n, -math.pi)
    hi = np.full(plant.n, math.pi)
    for i, j in enumerate(plant.joint_ids):
        if m.jnt_limited[j]:
            lo[i], hi[i] = m.jnt_range[j]
    return lo, hi


def _home(urdf: Path, chain: Chain, plant: Any) -> FloatArray:
    """The rule's home posture (SPEC §18) if this version has it
    (``adaptimp.mujoco.home_posture``), else the zero posture."""
    from .. import mujoco as amj

    rule = getattr(amj, "home_posture", None)
    if rule is not None:
        return np.asarray(rule(plant), dtype=np.float64)
    return np.zeros(chain.n)


def _check_scenario(**values: float | None) -> None:
    """Refuse, by name, a scenario quantity that is not a finite number in its
    range (before any model is built)."""
    ranges: dict[str, tuple[str, Callable[[float], bool]]] = {
        "spring": ("> 0 (N/m), or None for a rigid table", lambda v: v > 0),
        "friction": ("≥ 0", lambda v: v >= 0),
        "radius": ("> 0 (m)", lambda v: v > 0),
        "freq": ("> 0 (Hz)", lambda v: v > 0),
        "depth": ("≥ 0 (m)", lambda v: v >= 0),
        "tool_radius": ("> 0 (m)", lambda v: v > 0),
        "Ts": ("> 0 (s)", lambda v: v > 0),
        "t_approach": ("≥ 0 (s)", lambda v: v >= 0),
        "t_ramp": ("≥ 0 (s)", lambda v: v >= 0),
        "t_hold": ("≥ 0 (s)", lambda v: v >= 0),
        "t_press": ("≥ 0 (s)", lambda v: v >= 0),
        "clearance": ("≥ 0 (m)", lambda v: v >= 0),
    }
    for name, value in values.items():
        if value is None and name == "spring":
            continue
        what, ok = ranges[name]
        try:
            # A bool is not a quantity (True would be 1 m, 1 s, 1 N/m).
            v = math.nan if isinstance(value, bool) else float(value)  # type: ignore[arg-type]
        except (TypeError, ValueError):
            v = math.nan
        if not (math.isfinite(v) and ok(v)):
            raise ConfigError(f"{name} must be a finite number {what}, got {value!r}")


def arm_table(
    urdf: str | os.PathLike[str] | None = None,
    *,
    tip: str | None = None,
    fix: tuple[str, ...] = (),
    home: ArrayLike | None = None,
    spring: float | None = None,
    friction: float = 0.1,
    radius: float = 0.05,
    freq: float = 0.25,
    depth: float = 0.015,
    tool_radius: float = 0.01,
    Ts: float = 1e-3,
    t_approach: float = T_APPROACH,
    t_ramp: float = 1.0,
    t_hold: float = T_HOLD,
    t_press: float = T_PRESS,
    facing: bool | None = None,
) -> PandaTable:
    """The table scenario for the arm of ``urdf`` (None: the Panda of
    :func:`adaptimp.scenarios.panda_table.panda_table`, whose table and circle are kept,
    and which refuses ``tip``, ``fix`` and ``home``: it has its own).

    The path (SPEC (19.6)): the home posture held over [0, ``t_hold``) s, the
    approach to the circle's start on the table's surface, arriving at rest at
    ``t_approach`` s, then the commanded depth δ_c pressed in over ``t_press``
    s while the circle's speed ramps up over ``t_ramp`` s (``t_hold`` =
    ``t_press`` = 0: the earlier path, straight from home to δ_c into the
    table by ``t_approach``). For a URDF arm the table top lies
    max(:data:`CLEARANCE`, :data:`SAG_MARGIN` · :func:`sag`) below the tool
    at home.

    Refused with a ``ConfigError`` naming the argument (before anything is
    built where it can be): a quantity that is not a finite number in its
    range (a bool is not one; a string or NumPy number that reads as one is
    taken as that number), ``t_hold`` ≥ ``t_approach``, ``freq`` ≥ 1/(2 Ts),
    a circle that leaves the table (``radius`` + ``tool_radius`` > 0.2 m),
    ``fix`` that is not a tuple of the URDF's joint names, a ``home``
    outside the joint limits, and an arm that cannot hold gravity and the
    press with its friction at home (the joint and both torques named).

    ``tip``: the tool's body (default: the child link of the arm's last joint).
    The arm's joints are those :func:`adaptimp.mujoco.simulate` drives, by
    the core's one rule (SPEC §21, as :func:`adaptimp.mujoco.from_urdf` with
    ``tip``): a gripper's, prismatic, mimic and off-chain joints are fixed,
    and chains that tie (legs, two arms) need ``tip``; ``home`` (rad): default the rule's home
    posture; ``spring``: the table's spring stiffness k_e (N/m), None: rigid;
    ``friction``: sliding friction of table and tool. The rest as
    :func:`~adaptimp.scenarios.panda_table.panda_table`. The table and the circle are
    placed by :func:`placement`; ``facing``: the table turned to face the
    base's vertical axis (its short side along the reach) or on the world's
    axes (False); None (default): on the world's axes, turned for a ``home``
    given whose arm would otherwise stand under the table (the posture is the
    user's; a drawn one, :func:`placements`, is drawn again instead).
    """
    from .. import _models
    from .. import mujoco as amj
    from ..baselines import pinocchio_model
    from .panda_table import panda_table

    _check_scenario(
        spring=spring, friction=friction, radius=radius, freq=freq, depth=depth,
        tool_radius=tool_radius, Ts=Ts, t_approach=t_approach, t_ramp=t_ramp,
        t_hold=t_hold, t_press=t_press,
    )  # fmt: skip
    # The checked values as numbers (a string that reads as one, a NumPy scalar).
    friction, radius, freq, depth = float(friction), float(radius), float(freq), float(depth)
    tool_radius, Ts, t_ramp = float(tool_radius), float(Ts), float(t_ramp)
    spring = None if spring is None else float(spring)
    t_hold, t_press, t_approach = float(t_hold), float(t_press), float(t_approach)
    if freq >= 0.5 / Ts:
        raise ConfigError(
            f"freq must lie below the sampling's 1/(2 Ts) = {0.5 / Ts:g} Hz, got {freq!r}"
        )
    if radius + tool_radius > TABLE_OFFSET_MARGIN:
        raise ConfigError(
            f"radius must keep the circle and the tool on the table (radius + tool_radius ≤ "
            f"{TABLE_OFFSET_MARGIN:g} m), got radius = {radius!r}"
        )
    given: object = fix  # typed a tuple; a caller may still pass a bare string
    if not isinstance(given, (tuple, list)) or not all(isinstance(j, str) for j in given):
        raise ConfigError(f"fix must be a tuple of joint names, got {fix!r}")
    if t_hold > 0 and t_hold >= t_approach:
        raise ConfigError(
            f"t_hold must end before the approach does (t_hold < t_approach), got "
            f"t_hold = {t_hold!r} and t_approach = {t_approach!r}"
        )
    speed = 2.0 * math.pi * freq * radius
    if urdf is None:
        # The Panda's scenario has its own tool body, fixed fingers and home.
        given = {"tip": tip, "fix": fix or None, "home": home, "facing": facing or None}
        ignored = [k for k, v in given.items() if v is not None]
        if ignored:
            raise ConfigError(
                f"{', '.join(ignored)} {'applies' if len(ignored) == 1 else 'apply'} to the arm "
                "of a URDF; the Panda's scenario (urdf=None) has its own tool body, fixed "
                "fingers and home posture: give the Panda's URDF path to set them"
            )
        sc = panda_table(
            radius=radius,
            freq=freq,
            depth=depth,
            friction=friction,
            tool_radius=tool_radius,
            Ts=Ts,
            t_approach=t_approach,
            t_ramp=t_ramp,
        )
        # The Panda of adaptimp.mujoco.panda (the same URDF, inertias, motors
        # and table), with the tool on a body of its own and this module's
        # contact (arm_model).
        sc.model = arm_model(
            _models.panda_urdf_path(),
            _models.PANDA_EE,
            fix=_models.PANDA_FINGERS,
            tool_radius=tool_radius,
            table_top=sc.surface_z - tool_radius,
            centre=(0.55, 0.0),
            friction=friction,
            spring=spring,
            home=sc.q0,
            force=sc.target_force(),
            speed=speed,
            accel=speed**2 / radius,
        )
        sc.t_hold, sc.t_press = float(t_hold), float(t_press)
        sc.__post_init__()
        plant = amj.Plant(sc.model)
        check_press(sc.chain, plant, sc.q0, sc.tau_max, NOMINAL_KD * depth, friction, tool_radius)
        return sc
    path = Path(urdf)
    if path.suffix.lower() == ".urdf":
        chain, bare, tip, fix = _urdf_arm(path, tip, fix, tool_radius)
        pin_model: Any = pinocchio_model(path, tip=tip, fix=fix)
    else:
        chain, bare, tip = _mjcf_arm(path, tip, fix, tool_radius)
        pin_model = None  # computed torque's model is Pinocchio's, from a URDF
    tau_max = np.asarray(bare.tau_max, dtype=np.float64)
    lo, hi = _limits(bare)

    def build(q0: FloatArray, facing: bool = False) -> PandaTable:
        """The scenario with its home at ``q0``: the press checked, the table
        and the circle placed from the arm's reach (``facing``: the table
        turned to face the base)."""
        outside = np.flatnonzero((q0 < lo - 1e-12) | (q0 > hi + 1e-12))
        if outside.size:
            i = int(outside[0])
            raise ConfigError(
                f"home must lie within the joint limits; joint {i} ({chain.joint_names[i]!r}) "
                f"has home = {float(q0[i])!r} outside [{float(lo[i])!r}, {float(hi[i])!r}] rad"
            )
        check_press(chain, bare, q0, tau_max, NOMINAL_KD * depth, friction, tool_radius)
        clearance = max(CLEARANCE, SAG_MARGIN * sag(chain, bare, q0, tau_max, Ts=Ts))
        centre, top, _ = placement(
            chain, q0, _limits(bare), tool_radius=tool_radius, clearance=clearance
        )
        table_centre = centre + 0.15 * centre / max(float(np.linalg.norm(centre)), 1e-9)
        model = arm_model(
            path,
            tip,
            fix=fix,
            tool_radius=tool_radius,
            table_top=top,
            centre=table_centre,
            friction=friction,
            spring=spring,
            home=q0,
            force=NOMINAL_KD * depth,
            speed=speed,
            facing=facing,
            accel=speed**2 / radius,
        )
        return PandaTable(
            model=model,
            chain=chain,
            q0=q0,
            pin_model=pin_model,
            Ts=Ts,
            radius=radius,
            freq=freq,
            centre=np.asarray(centre, dtype=np.float64),
            depth=depth,
            surface_z=top + tool_radius,
            t_approach=t_approach,
            t_ramp=t_ramp,
            tau_max=tau_max,
            t_hold=float(t_hold),
            t_press=float(t_press),
        )

    if home is not None:
        q_home = joint_vector("home", home, chain)
        sc = build(q_home, facing=bool(facing))
        refusal = refusal_of(sc, load=1.0)
        if facing is None and refusal is not None and refusal.startswith(THROUGH_TABLE):
            # The posture is the user's: a table on the world's axes that
            # reaches under the arm's base is the placement's fault, not the
            # posture's. Turned to face the base it lies beyond the tool.
            sc = build(q_home, facing=True)
            refusal = refusal_of(sc, load=1.0)
        if refusal is not None:
            raise ConfigError(f"the home posture cannot run the table: {refusal}")
        return sc
    return _drawn(lambda q: build(q, facing=bool(facing)), path, chain, bare, (lo, hi), seed=0)


def _urdf_arm(
    path: Path, tip: str | None, fix: tuple[str, ...], tool_radius: float
) -> tuple[Chain, Any, str, tuple[str, ...]]:
    """A URDF arm's chain to the tool's body, its bare model's Plant (the tool,
    no table), the tip and the joints fixed: by the core's one rule (SPEC §21),
    as :func:`adaptimp.mujoco.simulate` simulates it and the computed torque
    models it (a gripper's, prismatic, mimic and off-chain joints are held; by
    default the tool goes on the last arm joint's link). A ``fix`` name the
    URDF does not have is refused."""
    import mujoco

    from .. import mujoco as amj
    from .._description import read_arm
    from .._mjmodel import obj_name

    arm = read_arm(path, tip, fix)
    tip = arm.tip if tip is None else tip
    fix = (*fix, *(j for j in arm.fixed if j not in fix))
    chain = Chain.from_urdf(path, tip=tip, fix=fix)
    bare = amj.Plant(arm_model(path, tip, fix=fix, tool_radius=tool_radius))
    joint = mujoco.mjtObj.mjOBJ_JOINT
    driven = [obj_name(bare.model, joint, j) for j in bare.joint_ids]
    if driven != chain.joint_names:
        raise ConfigError(
            f"the chain to {tip!r} has the joints {chain.joint_names}, but the arm's model "
            f"drives {driven} (fix={fix!r}): give a tip whose path holds exactly the "
            "driven joints, or fix the others"
        )
    return chain, bare, tip, fix


def _mjcf_arm(
    path: Path, tip: str | None, fix: tuple[str, ...], tool_radius: float
) -> tuple[Chain, Any, str]:
    """An MJCF arm's chain to the tool's site ``ee``, its bare model's Plant
    (the tool, no table) and the tool's body (default: the arm's end
    effector's body as :class:`adaptimp.mujoco.Plant` finds it, or the body
    its single chain of bodies without joints ends at: a hand, a flange)."""
    import mujoco

    from .. import mujoco as amj

    if tip is None:
        plain = amj.Plant(str(path), fix=fix)
        m = plain.model
        # The bodies that carry a joint in the file (the plant's model has
        # lost the ones it locks: a jaw is no flange).
        jointed = {
            mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b)
            for b in range(m.nbody)
            if m.body_jntnum[b] > 0
        } | {
            str(plain.notes["locked_bodies"][j])
            for j in plain.notes.get("locked", {})
            if j in plain.notes.get("locked_bodies", {})
        }
        body = plain.ee_body
        while True:
            children = [b for b in range(m.nbody) if int(m.body_parentid[b]) == body and b != 0]
            name = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, children[0]) if children else None
            if len(children) != 1 or name in jointed:
                break
            body = children[0]
        tip = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, body)
    if tip is None:
        raise ConfigError(f"the end effector's body of {path.name} has no name: give tip=")
    model = arm_model(path, tip, fix=fix, tool_radius=tool_radius)
    # The tool's site: the one on the body added at the tip (named "ee", or
    # "ee_1", … where the file has an "ee" already).
    body = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, tip)
    held = [b for b in range(model.nbody) if int(model.body_parentid[b]) == body]
    sites = [s for s in range(model.nsite) if int(model.site_bodyid[s]) in held]
    name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, sites[-1])
    bare = amj.Plant(model, site=name)
    return amj.chain_of(bare), bare, tip


HOME_CANDIDATES = 64
"""Postures :func:`arm_table` tries, after the rule's home, when no ``home`` is given."""


def _drawn(
    build: Callable[[FloatArray], PandaTable],
    urdf: Path,
    chain: Chain,
    plant: Any,
    limits: tuple[FloatArray, FloatArray],
    *,
    seed: int,
    skip: int = 0,
) -> PandaTable:
    """The first home posture the table can run (:func:`refusal_of`): the
    rule's home (SPEC §18), then postures drawn within the joint limits with
    the posture rule's margin (fixed ``seed``), best first by the posture
    rule's score at the start (SPEC (16.9)), the ``skip`` first passing ones
    skipped."""
    found = 0
    first, last = "", "none was tried"
    draws = _draws(limits, chain.n, seed, HOME_CANDIDATES)
    scores = [_start_score(chain, plant, q, limits) for q in draws]
    ranked = [draws[i] for i in sorted(range(len(draws)), key=lambda i: -scores[i])]
    for q in [_home(urdf, chain, plant), *ranked]:
        q = np.clip(q, limits[0], limits[1])
        try:
            sc = build(q)
        except ConfigError as e:
            last = str(e)
            first = first or last
            continue
        refusal = refusal_of(sc)
        if refusal is not None:
            last = refusal
            first = first or last
            continue
        if found == skip:
            return sc
        found += 1
    raise ConfigError(
        f"no home posture found for the table on this arm ({HOME_CANDIDATES + 1} tried, "
        f"{found} passed, {skip + 1} needed); at the rule's home: {first}; at the last one "
        f"tried: {last}"
    )


def _start_score(
    chain: Chain, plant: Any, q: FloatArray, limits: tuple[FloatArray, FloatArray]
) -> float:
    """The core's posture score at ``q`` alone (SPEC (16.9), the position rows),
    −inf if the rule refuses it there already."""
    from .. import _adaptimp, tuning

    p = np.asarray(chain.fk(q)[:3, 3], dtype=np.float64)
    a = _adaptimp.assess_posture(
        chain, q[None, :], p[None, :], np.asarray(tuning.gravity(plant, q))[None, :],
        tuning.inertia(plant, q), limits[0], limits[1],
        np.asarray(plant.tau_max, dtype=np.float64), False, k1=CONTACT_K1,
    )  # fmt: skip
    return -math.inf if a["error"] is not None else float(a["score"])


def _draws(limits: tuple[FloatArray, FloatArray], n: int, seed: int, count: int) -> FloatArray:
    """``count`` postures drawn uniformly (``seed``) min(0.1 rad, range/8) inside
    the limits (±π for an unlimited joint)."""
    lo = np.where(np.isfinite(limits[0]), limits[0], -math.pi)
    hi = np.where(np.isfinite(limits[1]), limits[1], math.pi)
    margin = np.minimum(0.1, (hi - lo) / 8)
    return np.random.default_rng(seed).uniform(lo + margin, hi - margin, size=(count, n))


def placements(
    urdf: str | os.PathLike[str], count: int = 8, *, seed: int = 1, **kwargs: Any
) -> list[PandaTable]:
    """``count`` table scenarios of the arm of ``urdf`` at home postures drawn
    min(0.1 rad, range/8) inside its joint limits (``seed``), each one the
    table can run (:func:`refusal_of`): reachable, well-conditioned placements
    on which to measure the table's targets. ``kwargs`` as :func:`arm_table`
    (not ``home``). A ``ConfigError`` if fewer than ``count`` of
    4·:data:`HOME_CANDIDATES` draws pass."""
    from .. import mujoco as amj

    if "home" in kwargs:
        raise ConfigError("placements draws the home postures: give no home")
    kwargs.setdefault("facing", False)  # a drawn home is drawn again, not given a turned table
    first = arm_table(urdf, **kwargs)
    limits = _limits(amj.Plant(first.model))
    out: list[PandaTable] = []
    draws = _draws(limits, first.n, seed, 4 * HOME_CANDIDATES)
    for q in draws:
        try:
            out.append(arm_table(urdf, home=q, **kwargs))
        except ConfigError:
            continue
        if len(out) == count:
            return out
    raise ConfigError(
        f"only {len(out)} of {len(draws)} homes drawn (seed {seed}) can run the table; "
        f"{count} asked"
    )
