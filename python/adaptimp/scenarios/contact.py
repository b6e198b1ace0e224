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
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._errors import ConfigError
from ..chain import Chain
from .panda_table import PandaTable, table_metrics

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

FloatArray = NDArray[np.float64]

CLEARANCE = 0.027
"""The smallest gap (m) between the tool sphere at the home posture and the table
top (the Panda scenario's); :func:`arm_table` makes it at least :data:`SAG_MARGIN`
times the arm's :func:`sag`."""

SAG_MARGIN = 2.0
"""The table top lies at least this many times the arm's :func:`sag` below the
tool at home: the networks start at zero, and until Ĝ has learnt gravity (the
hold, :data:`T_HOLD`) the arm hangs below its path; it must not reach the table
then (SPEC (19.6))."""

CONTACT_K1 = 10.0
"""K1 (1/s) of the table's joint controllers, at most the rule's (18.2)
min(50, 0.05/Ts): the position loop that pulls the arm onto the compliant
reference, which the contact wrench moves. At 50 s⁻¹ it follows the landing's
force spike and the tool bounced off the table (87–240 N, 0.3–0.5 s off on
the Panda, the UR5 and the UR10); at 20 s⁻¹ the six arms held, but a UR10 with
three times its masses and torques landed early and rang (14 N of force error,
3.4 s off); at 10 s⁻¹, between the impedance's K_d/B_d = 7.9 s⁻¹ and its
√(K_d/M_d) = 15.8 s⁻¹, every arm measured holds. Ĝ learns at ω_G² =
(m/Ts)²/(4·1.1²), the velocity loop's pair just overdamped (``Rule::critical``),
D̂ and Ĉ at (18.6)'s bandwidth (SPEC (19.6))."""

T_HOLD = 0.5
"""The path holds the home posture this long (s) before the approach: the
networks learn the arm's gravity in free space, where they will then act."""

T_APPROACH = 1.3
"""The approach (from home to the table's surface, arriving at rest) ends at
this time (s)."""

T_PRESS = 0.5
"""After the approach the commanded depth grows from 0 to δ_c over this long
(s): the force rises from zero instead of an impact."""

OUTWARD = 0.10
"""How far (m) beyond the home TCP, away from the base's vertical axis, the
circle's centre lies (horizontally)."""

REACH_SHARE = 0.7
"""The circle's centre lies at most this share of the arm's horizontal reach
from the base's vertical axis."""

MIN_REACH_SHARE = 0.4
"""… and at least this share of it: a folded home posture (the tip above the
base, the Unitree Z1's rest) does not put the circle where the arm cannot
press on the table."""

AXIS_SHARE = 0.1
"""A home tip closer than this share of the reach to the base's vertical axis
has no outward direction of its own; the circle then lies along the base's x
axis."""

TABLE_MASS = 1.0
"""Mass (kg) of a spring-mounted table top (``spring=``); critically damped, its
weight carried by the spring's preload (the top at rest where the rigid one is)."""


SLIP_SHARE = 0.5
"""Share of the prescribed normal force that MuJoCo's friction-to-normal coupling
may reach while the tool slides (SPEC (19.5)): the friction rows' time constant
is set so that μ D_t B_t v ≤ SLIP_SHARE · F_n."""

CONTACT_IMPEDANCE = 0.95
"""The largest impedance d (``solimp``'s d0 and d_max) of the tool–table pair:
MuJoCo's default d_max; :func:`contact_impedance` lowers it for a heavy tool
(SPEC (19.9))."""

TABLE_TIMECONST = 0.01
"""Time constant (s) of the tool–table contact's normal row (``solref``, damping
ratio 1; MuJoCo's default is 0.02 s): a rigid table whose own compliance is
small against K_d and k_e (SPEC §19: at 0.02 s the Panda's tool sinks 0.13 mm
under 7.5 N, a 58 kN/m spring in series that takes 2.4 % off (16.1)'s force
on the 5 kN/m table; at 0.01 s, 4 times stiffer, 0.7 %), within MuJoCo's
stability advice (time constant ≥ 2 timesteps) for steps up to 5 ms. The
friction rows are never made stiffer than this."""


ADMITTANCE_SHARE_OF_PERIOD = 0.25
"""m of SPEC (18.1), for (19.8): the admittance's mode on the table's stiffness,
√(k_e/M_d), takes at most this share of a period (Ts √(k_e/M_d) ≤ m), as the
joint rule's sampled velocity loop takes m of its error per period."""

_NOMINAL_KD = 500.0
"""K_d,z (N/m) of SPEC §16's default impedance: the scenario's prescribed force is
K_d,z δ_c (:meth:`PandaTable.target_force`)."""


def sliding_timeconst(model: Any, *, force: float, speed: float, friction: float) -> float:
    """The time constant (s) of the tool–table contact's friction rows (MuJoCo's
    ``pair/solreffriction``, damping ratio 1) under which the tool, sliding at
    ``speed`` (m/s) with sliding friction ``friction`` while it presses with
    ``force`` (N), stays on the table (SPEC §19, (19.5)).

    MuJoCo's convex contact is one cost over the normal and the friction rows:
    while the contact slides, the friction rows' reference −B_t v (B_t =
    2/(d_max τ_t)) cannot be met and the solver moves the unmet part into the
    normal row, as an upward force of about μ D B_t v, D = d/((1 − d) A) with A
    MuJoCo's inverse-mass approximation of the contact (``body_invweight0`` of
    the tool and the table at qpos0) and d the impedance (``solimp``). When it
    exceeds the pressing force the tool lifts off for a step, falls back, and
    the force alternates. (19.5) keeps it at :data:`SLIP_SHARE` of ``force``
    with d = d_max: B_t = SLIP_SHARE · F (1 − d_max) A/(d_max μ v), τ_t =
    2/(d_max B_t), at least :data:`TABLE_TIMECONST`. ``friction``, ``speed``
    or ``force`` zero: :data:`TABLE_TIMECONST` (nothing slides under load).
    The normal row keeps its own time constant (:data:`TABLE_TIMECONST`).
    """

    tool, table = _tool_table(model)
    inv_mass = _pair_inverse_mass(model, tool, table)
    if friction <= 0 or speed <= 0 or force <= 0:
        return TABLE_TIMECONST
    dmax = float(max(model.geom_solimp[tool, 1], model.geom_solimp[table, 1]))
    damping = SLIP_SHARE * force * (1.0 - dmax) * inv_mass / (dmax * friction * speed)
    return max(TABLE_TIMECONST, 2.0 / (dmax * damping))


def contact_impedance(model: Any, *, force: float, accel: float, friction: float) -> float:
    """The impedance d (MuJoCo's ``solimp`` d0 and d_max) of the tool–table
    pair under which the tool, driven along the circle with the acceleration
    ``accel`` (m/s², v²/r) while it presses with ``force`` (N) at sliding
    friction ``friction``, stays on the table (SPEC (19.9)): MuJoCo's cone hands
    the tangential acceleration its friction rows do not meet to the normal
    row as about μ D a, D = d/((1 − d) A) (A as in :func:`sliding_timeconst`);
    d = x/(1 + x), x = :data:`SLIP_SHARE` · F A/(μ a), keeps it at
    :data:`SLIP_SHARE` of the press, and never above :data:`CONTACT_IMPEDANCE`
    (MuJoCo's own 0.95, which every arm lighter than A < 19 μ a/(s F) keeps).
    ``friction``, ``accel`` or ``force`` zero: :data:`CONTACT_IMPEDANCE`."""
    inv_mass = _pair_inverse_mass(model, *_tool_table(model))
    if friction <= 0 or accel <= 0 or force <= 0:
        return CONTACT_IMPEDANCE
    x = SLIP_SHARE * force * inv_mass / (friction * accel)
    return min(CONTACT_IMPEDANCE, x / (1.0 + x))


def _set_pair_contact(
    model: Any, *, force: float, speed: float, accel: float, friction: float
) -> None:
    """The tool–table pair's friction time constant (19.5) and impedance (19.9)."""
    model.pair_solreffriction[0] = [
        sliding_timeconst(model, force=force, speed=speed, friction=friction),
        1.0,
    ]
    d = contact_impedance(model, force=force, accel=accel, friction=friction)
    model.pair_solimp[0, 0] = min(float(model.pair_solimp[0, 0]), d)
    model.pair_solimp[0, 1] = min(float(model.pair_solimp[0, 1]), d)


def _pair_inverse_mass(model: Any, tool: int, table: int) -> float:
    """A = the tool's and the table's bodies' inverse masses summed (1/kg,
    MuJoCo's ``body_invweight0``), of the geoms ``tool`` and ``table`` (ids;
    -1: none, refused)."""
    if tool < 0 or table < 0:
        raise ValueError("the model has no geoms 'tool' and 'table'")
    return float(
        model.body_invweight0[model.geom_bodyid[tool], 0]
        + model.body_invweight0[model.geom_bodyid[table], 0]
    )


def _tool_table(model: Any) -> tuple[int, int]:
    """The ids of the tool's sphere and the table's box (-1: none): the pair
    ``tool_table``'s geoms, else the last geoms named ``tool``… and ``table``…
    (the builder adds ``_1``, ``_2``, … to a name the model has already)."""
    import mujoco

    pair = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_PAIR, "tool_table")
    if pair >= 0:
        return int(model.pair_geom1[pair]), int(model.pair_geom2[pair])
    names = [
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_GEOM, g) or "" for g in range(model.ngeom)
    ]

    def last(prefix: str) -> int:
        found = [g for g, n in enumerate(names) if n == prefix or n.startswith(prefix + "_")]
        return found[-1] if found else -1

    return last("tool"), last("table")


def _tool_and_table(
    spec: Any,
    tip: str,
    *,
    tool_radius: float,
    table_top: float | None,
    centre: ArrayLike,
    friction: float,
    spring: float | None,
    facing: bool = False,
) -> str | None:
    """The tool on a massless body of its own at the origin of body ``tip``
    and the table (the shared builder, ``adaptimp._tooling``) with this
    scenario's contact: both with sliding friction ``friction`` and the time
    constant :data:`TABLE_TIMECONST`, the table of :data:`TABLE_MASS` on a
    spring of ``spring`` N/m or static; MuJoCo's elliptic cone and, with
    friction, the tool–table pair whose friction rows get their own time
    constant (:func:`sliding_timeconst`). ``facing``: the table turned to face
    the base's vertical axis, its short side (0.7 m) along the direction from
    the axis to ``centre`` (else on the world's axes). Returns the table's body
    (None: no table)."""
    import mujoco

    from .._tooling import add_table, add_tool

    rows = [friction, 0.005, 0.0001]
    solref = [TABLE_TIMECONST, 1.0]
    _, tool = add_tool(spec, tip, radius=tool_radius, own_body=True, friction=rows, solref=solref)
    if table_top is None:
        return None
    c = np.asarray(centre, dtype=np.float64)
    table, box = add_table(
        spec, top=table_top, centre=(float(c[0]), float(c[1])), friction=rows, solref=solref,
        mass=TABLE_MASS, spring=spring,
        yaw=math.atan2(float(c[1]), float(c[0])) if facing else 0.0,
    )  # fmt: skip
    # The Coulomb cone itself, not its pyramid: a pyramid's edges mix the
    # normal into every row and scale their regulariser by 2μ² (at μ = 0,
    # MuJoCo's floor 1e-5: a contact so stiff that it lifts off for single
    # steps; SPEC §19). The tool–table contact as an explicit pair, so that its
    # friction rows get their own time constant (sliding_timeconst).
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    if friction > 0:
        spec.add_pair(
            name="tool_table",
            geomname1=tool,
            geomname2=box,
            condim=3,
            friction=[friction, friction, 0.005, 0.0001, 0.0001],
            solref=solref,
            solreffriction=solref,
        )
    return table


def _watch_scene(spec: Any, model: Any, joints: Sequence[str], table: str | None) -> Any:
    """``model`` compiled again from ``spec`` with the arm's contacts with the
    rest of the scene watched through a run (SPEC §18.10,
    :func:`adaptimp._contacts.watch_contacts`): the tool on the table is the
    task's own contact, every other one is warned of by name."""
    import mujoco

    from .. import _contacts

    ids = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in joints]
    tool = [
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, int(model.site_bodyid[s]))
        for s in range(model.nsite)
        if (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_SITE, s) or "").startswith("ee")
    ]
    surface = [(tool[-1], table)] if tool and table is not None else []
    if _contacts.watch_contacts(spec, model, ids, surface) == 0:
        return model
    return spec.compile()


def arm_model(
    urdf: str | os.PathLike[str],
    tip: str,
    *,
    fix: tuple[str, ...] = (),
    tool_radius: float = 0.01,
    table_top: float | None = None,
    centre: ArrayLike = (0.0, 0.0),
    friction: float = 0.1,
    spring: float | None = None,
    home: ArrayLike | None = None,
    timestep: float = 5e-4,
    force: float = 0.0,
    speed: float = 0.0,
    facing: bool = False,
    accel: float = 0.0,
) -> Any:
    """A URDF or MJCF arm in MuJoCo with a tool and a table (see the module doc).

    A URDF: the arm as :func:`adaptimp.mujoco.from_urdf` makes it (rigid-body
    dynamics only, a motor per joint with ctrlrange ± its effort limit, RK4),
    joints in ``fix`` fixed at zero. An MJCF file (any other suffix): the
    model as it is, its own actuators and geometry (``fix`` must be empty), RK4.
    Then the tool sphere of ``tool_radius`` (m) at the origin
    of body ``tip`` with the site ``ee`` and its force/torque sensors; a 0.7 ×
    1.0 m table whose top is at height ``table_top`` (m; None: no table),
    centred at ``centre`` (x, y), sliding friction ``friction`` for the table
    and the tool, rigid or on a vertical spring of ``spring`` N/m (a slide
    joint, mass :data:`TABLE_MASS`, critically damped). Keyframe ``home``.

    The contact (SPEC §19): MuJoCo's elliptic (Coulomb) cone, its default
    ``solimp``, ``solref`` with the time constant :data:`TABLE_TIMECONST`; with
    friction, the tool–table contact is the explicit pair ``tool_table`` whose
    friction rows have the time constant :func:`sliding_timeconst` for a tool
    pressing with ``force`` (N) while it slides at ``speed`` (m/s) (zero:
    :data:`TABLE_TIMECONST`) and, driven along the circle with ``accel`` (m/s²),
    the impedance :func:`contact_impedance`. ``facing``: the table turned to face the base's
    vertical axis (:func:`arm_table` turns it for a home whose arm would stand
    under a table on the world's axes).
    """
    import mujoco

    from .._plant_models import arm_spec, compile_arm, urdf_arm

    if Path(urdf).suffix.lower() != ".urdf":
        return _mjcf_model(
            Path(urdf), tip, fix=fix, tool_radius=tool_radius, table_top=table_top,
            centre=centre, friction=friction, spring=spring, home=home, timestep=timestep,
            force=force, speed=speed, facing=facing, accel=accel,
        )  # fmt: skip
    # The arm as adaptimp.mujoco.from_urdf makes it, by the core's one
    # reduction (SPEC §21), with its motors (efforts estimated where the URDF
    # gives none, and said so).
    arm = urdf_arm(urdf, tip, fix)
    spec = arm_spec(arm, timestep, drive=False, stacklevel=3)
    table = _tool_and_table(
        spec,
        tip,
        tool_radius=tool_radius,
        table_top=table_top,
        centre=centre,
        friction=friction,
        spring=spring,
        facing=facing,
    )
    if home is not None:
        qpos = list(np.asarray(home, dtype=np.float64))
        if spring is not None:
            qpos.append(0.0)
        spec.add_key(name="home", qpos=qpos)
    # A massless moving link: bounded as adaptimp.mujoco.from_urdf does, and
    # said as it says it (an inertia that breaks the triangle inequality the
    # reader has balanced already, for the chain and Pinocchio's model too).
    model = compile_arm(spec, " (the chain and Pinocchio's model keep the URDF's)")
    model = _watch_scene(spec, model, arm.joints, table)
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    if model.npair:
        _set_pair_contact(model, force=force, speed=speed, accel=accel, friction=friction)
    return model


def _mjcf_model(
    path: Path,
    tip: str,
    *,
    fix: tuple[str, ...],
    tool_radius: float,
    table_top: float | None,
    centre: ArrayLike,
    friction: float,
    spring: float | None,
    home: ArrayLike | None,
    timestep: float,
    force: float,
    speed: float,
    facing: bool = False,
    accel: float = 0.0,
) -> Any:
    """:func:`arm_model` for an MJCF file: the model with the tool on body ``tip``
    and the table; keyframe ``home`` at the arm's joints (the others at qpos0)."""
    import mujoco

    from .. import _mjcf

    # The file as the plant takes it (SPEC §18, adaptimp._mjcf): a torque
    # motor on each arm joint that has none, with τmax estimated where the
    # file declares no range, and the joints that are not the arm's locked
    # (those of fix= too, as for a URDF).
    prepared = _mjcf.prepare_file(path, tip, fix)
    spec = prepared.spec
    # The tool's force/torque sensor is the end effector's (a plant of the
    # model finds its end effector at the first force sensor's site): the
    # file's own (a wrist's, above its gripper) would put it at the wrist.
    for sensor in list(spec.sensors):
        kinds = (mujoco.mjtSensor.mjSENS_FORCE, mujoco.mjtSensor.mjSENS_TORQUE)
        if int(sensor.type) in [int(k) for k in kinds]:
            spec.delete(sensor)
    spec.option.timestep = timestep
    for key in list(spec.keys):  # the table may add a joint: the file's keys no longer fit
        spec.delete(key)
    arm_bodies = [b.name for b in spec.bodies if b.name and b.name != "world"]
    table = _tool_and_table(
        spec,
        tip,
        tool_radius=tool_radius,
        table_top=table_top,
        centre=centre,
        friction=friction,
        spring=spring,
        facing=facing,
    )
    if table is not None:
        # The tool presses on the table, not the arm's own geometry (a URDF arm
        # has none; an MJCF wrist around the tool would rest on the table):
        # the arm's bodies and the table do not collide.
        for name in arm_bodies:
            spec.add_exclude(bodyname1=name, bodyname2=table)
    model = spec.compile()
    # The rest of the scene where the file's first keyframe puts it (another
    # arm, a free body, a mocap body; SPEC §18), the arm at ``home``.
    qpos = np.array(model.qpos0, dtype=np.float64)
    mocap = [b for b in range(model.nbody) if int(model.body_mocapid[b]) >= 0]
    mpos = np.zeros(3 * model.nmocap)
    mquat = np.zeros(4 * model.nmocap)
    for b in mocap:
        i = int(model.body_mocapid[b])
        mpos[3 * i : 3 * i + 3], mquat[4 * i : 4 * i + 4] = model.body_pos[b], model.body_quat[b]
    file = prepared.model
    if file.nkey > 0:
        for j in range(model.njnt):
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j)
            k = mujoco.mj_name2id(file, mujoco.mjtObj.mjOBJ_JOINT, name) if name else -1
            if k >= 0 and int(file.jnt_type[k]) == int(model.jnt_type[j]):
                n = {0: 7, 1: 4}.get(int(model.jnt_type[j]), 1)
                a, fa = int(model.jnt_qposadr[j]), int(file.jnt_qposadr[k])
                qpos[a : a + n] = file.key_qpos[0, fa : fa + n]
        for b in mocap:
            name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b)
            k = mujoco.mj_name2id(file, mujoco.mjtObj.mjOBJ_BODY, name) if name else -1
            if k >= 0 and int(file.body_mocapid[k]) >= 0:
                i, fi = int(model.body_mocapid[b]), int(file.body_mocapid[k])
                mpos[3 * i : 3 * i + 3] = file.key_mpos[0, 3 * fi : 3 * fi + 3]
                mquat[4 * i : 4 * i + 4] = file.key_mquat[0, 4 * fi : 4 * fi + 4]
    if home is not None:
        ids = [
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j) for j in prepared.arm["joints"]
        ]
        qpos[[int(model.jnt_qposadr[j]) for j in ids]] = np.asarray(home, dtype=np.float64)
    spec.add_key(name="home", qpos=qpos.tolist(), mpos=mpos.tolist(), mquat=mquat.tolist())
    model = spec.compile()
    model = _watch_scene(spec, model, prepared.arm["joints"], table)
    model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    if model.npair:
        _set_pair_contact(model, force=force, speed=speed, accel=accel, friction=friction)
    return model


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
    q = _joint_vector("home", home, chain)
    unlimited = " (±π for an unlimited joint)"
    lo_given = _joint_vector("limits[0] (lo)", limits[0], chain, unlimited)
    hi_given = _joint_vector("limits[1] (hi)", limits[1], chain, unlimited)
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


def _joint_vector(name: str, value: ArrayLike, chain: Chain, hint: str = "") -> FloatArray:
    """``value`` as n finite numbers (rad), one per joint of ``chain``, or a
    ``ConfigError`` naming ``name``, the joint and the value."""
    n = chain.n
    try:
        v = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"{name} must be {n} finite numbers (rad){hint}, got {value!r}") from None
    if v.shape != (n,):
        raise ConfigError(
            f"{name} must be {n} finite numbers (rad){hint}, one per joint; got shape {v.shape}"
        )
    bad = np.flatnonzero(~np.isfinite(v))
    if bad.size:
        i = int(bad[0])
        raise ConfigError(
            f"{name} must be {n} finite numbers (rad){hint}; joint {i} "
            f"({chain.joint_names[i]!r}) is {float(v[i])!r}"
        )
    return v


def _limits(plant: Any) -> tuple[FloatArray, FloatArray]:
    """The arm's joint ranges (rad) from the MuJoCo model (±π where unlimited)."""
    m = plant.model
    lo = np.full(plant.n, -math.pi)
    hi = np.full(plant.n, math.pi)
    for i, j in enumerate(plant._joints):
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


THROUGH_TABLE = "the arm clear of the table"
"""How :func:`refusal_of` begins the refusal of an arm whose joint lies below
the table top over the table."""

TABLE_OFFSET_MARGIN = 0.2
"""The table (0.7 m deep) is centred 0.15 m beyond the circle's centre: the
circle and the tool stay on it for radius + tool_radius ≤ 0.35 − 0.15 m."""

MAX_PATH_STEPS = 1_000_000
"""The longest scenario path (periods) :func:`rule_keywords` and :func:`refusal_of`
sample: the hold, the approach, the press or ramp and one period of the circle
(1000 s at 1 kHz); a longer one (a huge ``t_press`` or ``t_ramp``, a tiny
``freq``) is refused by name."""


def _check_path_length(duration: float, Ts: float) -> None:
    """Refuse a path whose one circle after the approach lasts beyond
    :data:`MAX_PATH_STEPS` periods (a huge ``t_press`` or ``t_ramp``, a tiny
    ``freq``): the rule samples it once, period by period."""
    steps = duration / Ts
    if not steps <= MAX_PATH_STEPS:
        raise ConfigError(
            f"the scenario's path (the approach, the press or ramp and one circle: "
            f"{duration:.6g} s) is {steps:.3g} periods of Ts = {Ts:g} s, beyond "
            f"{MAX_PATH_STEPS}: give a shorter t_press or t_ramp, or a higher freq"
        )


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
        _check_press(sc.chain, plant, sc.q0, sc.tau_max, _NOMINAL_KD * depth, friction, tool_radius)
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
        _check_press(chain, bare, q0, tau_max, _NOMINAL_KD * depth, friction, tool_radius)
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
            force=_NOMINAL_KD * depth,
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
        q_home = _joint_vector("home", home, chain)
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
    driven = [obj_name(bare.model, joint, j) for j in bare._joints]
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
        body = int(plain._ee_body)
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


REFUSAL_ROWS = 40
"""Rows of the scenario's joint path at which :func:`refusal_of` checks the arm
(those of the one posture check, ``adaptimp._posture.CHECKED``)."""


def refusal_of(sc: PandaTable, *, load: float = 0.5) -> str | None:
    """Why the table cannot run at the scenario's home, or None (SPEC (19.6)).

    Along the scenario's joint path (the hold, the approach, the press and one
    circle on the table's surface, as the outer loop maps it, F_e = 0): the
    one posture check of :func:`adaptimp.mujoco.cartesian_task` and
    :meth:`adaptimp.CartesianController.from_rule` (SPEC (16.9), the position
    rows: not near a singularity, inside the joint limits with margin, gravity
    at most half of every actuator, the velocity loop well-conditioned at home
    for the table's K1 = 10 s⁻¹, the path reachable within 1 mm, no collision
    of the arm with itself and the scene, the tool left out), then the table's
    own: no joint of the arm below the table top over the table, and the rule's gains' sampled
    velocity loop stable at every posture of the path (SPEC (19.10),
    :func:`velocity_loop_radius`). ``load``: the largest gravity
    load max_i |G_i|/τmax_i allowed (1 for a home the user gives: gravity
    within the actuators; the press, SPEC (19.6), is checked apart)."""
    from .. import _posture
    from .. import mujoco as amj

    start = sc.t_approach + max(sc.t_ramp, sc.t_press)
    _check_path_length(start + 1.0 / sc.freq, sc.Ts)
    steps = round((start + 1.0 / sc.freq) / sc.Ts)
    q, _ = sc.outer().joint_orbit(lambda t: sc.path(t, depth=0.0), steps * sc.Ts, samples=steps)
    idx = _posture.checked_rows(steps)
    rows = np.ascontiguousarray(q[idx])
    targets = np.ascontiguousarray(
        np.array([sc.path(k * sc.Ts, depth=0.0)[0] for k in idx], dtype=np.float64)
    )
    plant = amj.Plant(sc.model, contact=False)
    # The one posture check (SPEC (16.9)), at the table's K1; the collisions of
    # the arm with itself and the rest of the scene (a pedestal, another arm),
    # the tool on the table left out: that is the task.
    a = _posture.assess(
        plant, sc.chain, sc.q0, rows, targets, orients=False, k1=CONTACT_K1, Ts=sc.Ts,
        load=load, tau_max=sc.tau_max, skip=frozenset({int(plant._ee_body)}),
    )  # fmt: skip
    if a["error"] is not None:
        return str(a["error"])
    through = _through_table(sc, plant, rows)
    if through is not None:
        return through
    return _velocity_loop_gain(sc, plant, rows)


ROBUST_SLOPE = 0.5
"""The slope of (18.4)'s robust term at z2 = 0 against Kp: kr_i/φ = Kp_i/2."""


def velocity_loop_radius(
    inertia: ArrayLike, gain: ArrayLike, damping: ArrayLike | None, Ts: float
) -> float:
    """The spectral radius of the sampled velocity loop, SPEC (19.10): a joint
    law whose torque τ_k = −K_v v_k is held over a period Ts (s) on an arm of
    inertia D (kg m², (n, n)) with viscous damping B = diag(``damping``)
    (N m s/rad, MuJoCo integrates it within the period; None: none) moves the
    velocity by v_(k+1) = (E − F D⁻¹ K_v) v_k, E = e^(−Ts D⁻¹B), F = ∫₀^Ts
    e^(−s D⁻¹B) ds; K_v = diag(``gain``) (N m s/rad). Stable below 1; without
    damping ρ = max_i |1 − Ts λ_i(D⁻¹ K_v)|, i.e. Ts λmax < 2."""
    d = np.asarray(inertia, dtype=np.float64)
    n = d.shape[0]
    b = np.zeros(n) if damping is None else np.asarray(damping, dtype=np.float64)
    w, u = np.linalg.eigh(d)
    half, inv_half = (u * np.sqrt(w)) @ u.T, (u / np.sqrt(w)) @ u.T
    # D⁻¹B = D^(−½) S D^(½), S = D^(−½) B D^(−½) symmetric ≥ 0.
    lam, v = np.linalg.eigh(inv_half @ np.diag(b) @ inv_half)
    lam = np.maximum(lam, 0.0)
    x = lam * Ts
    share = np.where(x > 1e-12, -np.expm1(-x) / np.where(x > 1e-12, lam, 1.0), Ts)
    e = inv_half @ (v * np.exp(-x)) @ v.T @ half
    f = inv_half @ (v * share) @ v.T @ half
    loop = e - f @ np.linalg.solve(d, np.diag(np.asarray(gain, dtype=np.float64)))
    return float(np.max(np.abs(np.linalg.eigvals(loop))))


def _velocity_loop_gain(sc: PandaTable, plant: Any, rows: FloatArray) -> str | None:
    """SPEC (19.10): the rule's joint gains (:func:`rule_keywords`: the
    inertia scales along the path) close a sampled velocity loop
    (:func:`velocity_loop_radius`, K_v = Kp (1 + :data:`ROBUST_SLOPE`), the
    plant's own damping) that must stay stable (ρ < 1) at every posture of
    ``rows``; the first posture where it is not, named with ρ, or None."""
    from .. import tuning

    kv = np.asarray(rule_keywords(sc)["gains"]["Kp"], dtype=np.float64) * (1.0 + ROBUST_SLOPE)
    damping = tuning.joint_damping(plant)
    for k, q in enumerate(rows):
        rho = velocity_loop_radius(tuning.inertia(plant, q), kv, damping, sc.Ts)
        if not rho < 1.0:
            return (
                f"{RINGING}: at row {k} of the path the sampled velocity loop's spectral "
                f"radius ρ(E − F D⁻¹ K_v) = {rho:.3g} ≥ 1 (K_v = Kp + kr/φ of the rule's "
                "gains: joints whose axes line up along the path share a light inertia)"
            )
    return None


RINGING = "the velocity loop stable along the path"
"""How :func:`refusal_of` begins the refusal of a path on which the rule's
gains would ring at half the sampling rate (SPEC (19.10))."""


def _through_table(sc: PandaTable, plant: Any, rows: FloatArray) -> str | None:
    """A joint of the arm (its anchor) below the table top over the table, at a
    posture of ``rows``, named; None if none."""
    import mujoco

    m = plant.model
    tool, g = _tool_table(m)
    if g < 0:
        return None
    d = mujoco.MjData(m)
    top = sc.surface_z - float(m.geom_size[tool, 0])
    for k, q in enumerate(rows):
        d.qpos[plant._qadr] = q
        mujoco.mj_kinematics(m, d)
        centre, half = d.geom_xpos[g], m.geom_size[g]
        axes = d.geom_xmat[g].reshape(3, 3)  # the table's axes (turned if it faces the base)
        for i, j in enumerate(plant._joints):
            a = axes.T @ (d.xanchor[j] - centre)
            over = abs(a[0]) <= half[0] and abs(a[1]) <= half[1]
            if over and d.xanchor[j][2] < top:
                return (
                    f"{THROUGH_TABLE}: at row {k} of the path joint {i} "
                    f"({sc.chain.joint_names[i]!r}) is {top - d.xanchor[j][2]:.3g} m below the "
                    "table top"
                )
    return None


def _check_press(
    chain: Chain,
    plant: Any,
    q0: FloatArray,
    tau_max: FloatArray,
    force: float,
    friction: float,
    tool_radius: float,
) -> None:
    """Refuse an arm that cannot hold the press at its home posture: joint i
    takes |G_i(q0)| + F (|J_c,z,i| + μ ‖J_c,xy,i‖) (N m), gravity and the
    prescribed normal force F (N) with its sliding friction μF in the worst
    horizontal direction, acting at the contact point (the tool's centre less
    ``tool_radius`` along z, J_c its position Jacobian); beyond τmax_i no
    controller can press (an estimated effort limit of a light wrist, say)."""
    from .. import tuning

    j = np.asarray(chain.jacobian(q0), dtype=np.float64)
    o = np.array([0.0, 0.0, -tool_radius])
    skew = np.array([[0.0, -o[2], o[1]], [o[2], 0.0, -o[0]], [-o[1], o[0], 0.0]])
    jc = j[:3] - skew @ j[3:]  # v + ω × o
    g = tuning.gravity(plant, q0)
    load = np.abs(g if g is not None else 0.0) + force * (
        np.abs(jc[2]) + friction * np.linalg.norm(jc[:2], axis=0)
    )
    over = np.flatnonzero(load > tau_max)
    if over.size:
        i = int(over[0])
        raise ConfigError(
            f"the arm cannot press on the table: at its home posture joint {i} "
            f"({chain.joint_names[i]!r}) takes {load[i]:.4g} N m (gravity and the "
            f"prescribed {force:.4g} N with friction {friction:g}) but its effort limit is "
            f"{tau_max[i]:.4g} N m; give the URDF a larger <limit effort> for it, or a "
            "smaller depth or friction"
        )


def sag(chain: Chain, model: Any, q0: ArrayLike, tau_max: ArrayLike, *, Ts: float = 1e-3) -> float:
    """How far (m) the tip hangs below its path at ``q0`` (rad) under the joint
    feedback alone, before the networks have learnt gravity: |(J Δq)_z| with
    Δq_i = G_i/(Kp_i K1) (SPEC (18.5)'s sag, in the task), Kp from the rule
    (:func:`adaptimp.tuning.suggest` with ``model``'s D(q0), ``tau_max`` (N m),
    ``Ts`` (s)), K1 = min(:data:`CONTACT_K1`, the rule's), G(q0) and J the tip's position
    Jacobian from ``chain``. ``model``: what :func:`adaptimp.tuning.gravity`
    takes (here the arm's ``adaptimp.mujoco.Plant``)."""

    q = _joint_vector("q0", q0, chain)
    data: Any = getattr(model, "data", None)
    if data is None:
        return _sag(chain, model, q, tau_max, Ts)
    saved = (data.qpos.copy(), data.qvel.copy())
    try:
        return _sag(chain, model, q, tau_max, Ts)
    finally:  # a Plant's state as the caller left it
        import mujoco

        data.qpos[:], data.qvel[:] = saved
        mujoco.mj_forward(model.model, data)


def _sag(chain: Chain, model: Any, q: FloatArray, tau_max: ArrayLike, Ts: float) -> float:
    """:func:`sag` without keeping ``model``'s state."""
    from .. import tuning

    g = tuning.gravity(model, q)
    if g is None:
        raise ConfigError(f"sag needs a model that gives G(q); got {type(model).__name__}")
    kw = tuning.suggest(model, q, tau_max, Ts=Ts)
    kp = np.asarray(kw["Kp"], dtype=np.float64)
    dq = g / (kp * min(CONTACT_K1, float(kw["K1"][0])))
    return float(abs(np.asarray(chain.jacobian(q))[2] @ dq))


def rule_keywords(sc: PandaTable, case: str = "sf") -> dict[str, Any]:
    """Keywords of :func:`adaptimp.cartesian.panda_controller` for the joint
    controller ``case`` on the scenario ``sc``, from the core's rule (SPEC §18,
    :func:`adaptimp.tuning.suggest`): gains (18.1)–(18.4) from D(q0), the RBF
    centres (18.5) and the learning (18.6)–(18.8) along the scenario's whole
    joint path (the hold, the approach, the press and one period of the circle,
    as the outer loop maps the path on the table's surface into the joints,
    F_e = 0, taken as one period of that length), the inertia scales the
    smallest along it (16.12), Ĝ's learning near the velocity loop's critical
    bandwidth (``tuning.suggest(critical=True)``) and K1 = min(:data:`CONTACT_K1`,
    the rule's (18.2)) (SPEC (19.6)), the centres' widths in q at least the
    diameter of the circle's joint orbit, one period after the approach (SPEC
    (19.11)). Returns ``gains`` (Kp, Kzeta, K1), ``basis`` (centres,
    widths) and the rest (gamma, sigma, weight_bound, kr, …) as keywords."""
    from .. import mujoco as amj
    from .. import tuning

    start = sc.t_approach + max(sc.t_ramp, sc.t_press)
    _check_path_length(start + 1.0 / sc.freq, sc.Ts)
    steps = round((start + 1.0 / sc.freq) / sc.Ts)
    q, dq = sc.outer().joint_orbit(lambda t: sc.path(t, depth=0.0), steps * sc.Ts, samples=steps)
    ddq = np.gradient(dq, sc.Ts, axis=0)

    def path(t: float) -> tuple[Any, Any, Any]:
        k = min(round(t / sc.Ts), steps - 1)
        return q[k], dq[k], ddq[k]

    # (19.11): the circle repeats, the hold and the approach do not; the
    # centres' widths in q span the circle's joint orbit.
    circle = q[min(round(start / sc.Ts), steps - 1) :]
    kw = tuning.suggest(
        amj.Plant(sc.model), sc.q0, sc.tau_max, Ts=sc.Ts, path=path, period=steps * sc.Ts,
        case=case, critical=True, orbit=circle,
    )  # fmt: skip
    kw["K1"] = [min(CONTACT_K1, float(kw["K1"][0]))] * sc.n  # never above (18.2)
    out: dict[str, Any] = {
        "gains": {k: kw[k] for k in ("Kp", "Kzeta", "K1")},
        "basis": (kw["centers"], kw["widths"]),
    }
    md = normal_inertia(sc, q)
    if md > DEFAULT_MD:  # (19.8); the default target inertia otherwise, as before
        out["Md"] = [DEFAULT_MD, DEFAULT_MD, md]
    skip = {"n", "Kp", "Kzeta", "K1", "centers", "widths", "Ts", "tau_max"}
    out.update({k: v for k, v in kw.items() if k not in skip})
    return out


DEFAULT_MD = 2.0
"""The target inertia M_d (kg) of SPEC §16's defaults, per axis."""

NORMAL_SAMPLES = 50
"""Postures of the scenario's joint path at which :func:`normal_inertia` takes
the tool's Cartesian inertia along the normal."""


def normal_inertia(sc: PandaTable, q: ArrayLike) -> float:
    """The target inertia M_d,n (kg) along the table's normal by SPEC (19.8):
    max(M_d, k Λ_c (Ts/m)²), k = 1/τ_n² the table contact's stiffness per
    unit apparent mass (τ_n = :data:`TABLE_TIMECONST`), Λ_c the
    larger of the tool's Cartesian inertia along the normal, 1/(nᵀ J D⁻¹ Jᵀ
    n), over :data:`NORMAL_SAMPLES` postures of the joint path ``q`` (K, n)
    (rad; D the plant's, armature included) and
    MuJoCo's own estimate of it (1/``body_invweight0`` of the tool and the
    table), m = :data:`ADMITTANCE_SHARE_OF_PERIOD`: the admittance's mode on
    the table's stiffness takes at most m of a period."""
    from .. import mujoco as amj
    from .. import tuning

    model = sc.model
    tool, table = _tool_table(model)
    if tool < 0 or table < 0:
        return DEFAULT_MD
    rows = np.asarray(q, dtype=np.float64)
    plant = amj.Plant(model, contact=False)
    idx = np.unique(np.linspace(0, rows.shape[0] - 1, NORMAL_SAMPLES).round().astype(int))
    lam = 0.0
    for k in idx:
        d = tuning.inertia(plant, rows[k])
        jz = np.asarray(sc.chain.jacobian(rows[k]), dtype=np.float64)[2]
        lam = max(lam, 1.0 / float(jz @ np.linalg.solve(d, jz)))
    inv_mass = _pair_inverse_mass(model, tool, table)
    if inv_mass > 0:
        lam = max(lam, 1.0 / inv_mass)
    stiffness = 1.0 / TABLE_TIMECONST**2  # 1/s², per kg of apparent mass
    return max(DEFAULT_MD, stiffness * lam * (sc.Ts / ADMITTANCE_SHARE_OF_PERIOD) ** 2)


def contact_metrics(
    res: Any, ctrl: Any, sc: PandaTable, *, settle: float = 2.0
) -> dict[str, float]:
    """The scenario's table of a run (``res`` from :func:`adaptimp.mujoco.simulate`),
    over t ≥ ``settle`` (s) unless said:

    - ``track_mm``: RMS ‖p_d − p‖ (mm), the compliant reference against the tip;
    - ``track_along_mm``: RMS ‖(p_d − p)_xy‖ (mm), its part along the table
      (the table's plane; the normal part is the force error over K_d,z);
    - ``force_target_N``: K_d,z δ_c, or for a spring table of k_e (16.1)'s
      K_d k_e/(K_d + k_e) δ_c (N);
    - ``force_rms_err_N``: RMS (F_n − target) (N), F_n = −F_e,z;
    - ``force_chatter_N``: RMS (F_n,k+1 − F_n,k) (N), the sample-to-sample change;
    - ``force_mean_N``: the mean of F_n (N);
    - ``force_16_1_N``: what (16.1) prescribes with the measured mean n·e,
      K_d k_e/(K_d + k_e)(δ_c + n·e) (K_d (δ_c + n·e) for a rigid table), n = −z,
      e = p − p_d (N);
    - ``contact_lost_s``: time (s) with F_n ≤ 0 after the first contact at or
      after the end of the approach, when the commanded point has reached δ_c
      into the table (``t_approach + t_press``; all the time after it, if
      none; NaN for a run that ends before it);
    - ``peak_force_N``: max F_n over the whole run (N), the approach's impact
      included;
    - ``peak_tau_ratio``: max_i max_{t ≥ 0.1 s} |τ_i|/τmax_i, commanded;
    - ``sat_duty``: fraction of all rows with sat(τ_i) ≠ τ_i on some joint.
    """
    m = table_metrics(res, ctrl, sc, settle=settle)
    t = np.asarray(res.t)
    if t.size > 1 and not np.allclose(np.diff(t), sc.Ts, rtol=1e-9, atol=0.0):
        raise ConfigError(
            f"contact_metrics needs every period's row (Ts = {sc.Ts:g} s; the chatter is "
            "sample to sample): run simulate with record_every=1"
        )
    return {
        "track_mm": m["rms_track"] * 1e3,
        "track_along_mm": m["rms_track_along"] * 1e3,
        "peak_force_N": m["peak_force"],
        "force_rms_err_N": m["force_rms_err"],
        "force_target_N": m["force_target"],
        "force_chatter_N": m["force_chatter"],
        "force_mean_N": m["force_mean"],
        "force_16_1_N": m["force_16_1"],
        "contact_lost_s": m["contact_lost"],
        "peak_tau_ratio": m["peak_tau_ratio"],
        "sat_duty": m["sat_duty"],
        "applied_ratio": m["applied_ratio"],
    }


SHARE = 0.3
"""The admittance's share n of the table's unified rows (docs/contact.md)."""

LEARN_KEYS = ("gamma", "sigma", "weight_bound")
"""The rule's learning keywords; the rows without learning (PD, SF with +τe and
Γ = 1) leave them out."""

TABLE_ROWS: dict[str, tuple[str, str, str, bool, bool]] = {
    "pd": ("PD, admittance", "pd", "admittance", False, False),
    "sf-printed": ("SF with +τe, Γ = 1, admittance", "sf", "admittance", True, False),
    "sf-admittance": ("SF, admittance, no τe feedforward", "sf", "admittance", False, True),
    "sf": (f"SF, unified n = {SHARE}", "sf", "unified", False, True),
    "of": (f"OF, unified n = {SHARE}", "of", "unified", False, True),
    "sf-ff": (f"SF with +τe, unified n = {SHARE}", "sf", "unified", True, True),
    "sf-impedance": ("SF, impedance", "sf", "impedance", False, True),
    "ct-admittance": ("CT exact, admittance (+τe)", "ct", "admittance", True, False),
    "ct": ("CT exact, impedance", "ct", "impedance", False, False),
    "ct+30": ("CT +30 % mass, impedance", "ct+30", "impedance", False, False),
}
"""The table's rows (docs/contact.md): name: (label, joint controller, the
impedance's formulation (SPEC §19), the +τe feedforward, the rule's learning).
Computed torque's rows ("ct…") need a URDF arm (Pinocchio's model)."""


def row_controller(name: str, sc: PandaTable, rule: dict[str, Any]) -> Any:
    """The controller of the table's row ``name`` (:data:`TABLE_ROWS`) on the
    scenario ``sc``, with the scenario's rule keywords ``rule``
    (:func:`rule_keywords`)."""
    from .panda_table import panda_controller

    if name not in TABLE_ROWS:
        raise ConfigError(f"no row {name!r}; the rows are {list(TABLE_ROWS)}")
    _, kind, formulation, ff, learn = TABLE_ROWS[name]
    extra: dict[str, Any] = {}
    if formulation == "unified":
        extra["admittance_share"] = SHARE
    if kind in ("pd", "sf", "of"):
        extra.update({k: v for k, v in rule.items() if learn or k not in LEARN_KEYS})
    elif "Md" in rule:  # the scenario's target inertia (SPEC (19.8)), whatever the joint law
        extra["Md"] = rule["Md"]
    return panda_controller(kind, sc, force_feedforward=ff, formulation=formulation, **extra)


def run_row(
    name: str,
    sc: PandaTable,
    rule: dict[str, Any],
    T: float,
    *,
    progress: Callable[[int, int], object] | None = None,
) -> tuple[Any, Any, dict[str, float]]:
    """One row of the table on the scenario: (result, controller, metrics of
    :func:`contact_metrics` over t ≥ min(2 s, T/2)); ``progress(done,
    total)`` as :func:`adaptimp.mujoco.simulate` calls it."""
    from .. import mujoco as amj

    ctrl = row_controller(name, sc, rule)
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=T, q0=sc.q0, progress=progress or False)
    return res, ctrl, contact_metrics(res, ctrl, sc, settle=min(2.0, T / 2))
