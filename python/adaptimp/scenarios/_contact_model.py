"""The table scenario's MuJoCo model (SPEC §19): the contact's parameters
(:data:`CLEARANCE`, :data:`CONTACT_IMPEDANCE`, ...; :func:`sliding_timeconst`,
:func:`contact_impedance`), the tool sphere and the table at the arm's tip
(:func:`arm_model`, from a URDF or an MJCF), the scene's contacts watched.

Re-exported by :mod:`adaptimp.scenarios.contact`. Units: m, s, N, N/m, kg."""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .._errors import ConfigError
from ..chain import Chain

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

NOMINAL_KD = 500.0
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

    tool, table = tool_table(model)
    inv_mass = pair_inverse_mass(model, tool, table)
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
    inv_mass = pair_inverse_mass(model, *tool_table(model))
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


def pair_inverse_mass(model: Any, tool: int, table: int) -> float:
    """A = the tool's and the table's bodies' inverse masses summed (1/kg,
    MuJoCo's ``body_invweight0``), of the geoms ``tool`` and ``table`` (ids;
    -1: none, refused)."""
    if tool < 0 or table < 0:
        raise ValueError("the model has no geoms 'tool' and 'table'")
    return float(
        model.body_invweight0[model.geom_bodyid[tool], 0]
        + model.body_invweight0[model.geom_bodyid[table], 0]
    )


def tool_table(model: Any) -> tuple[int, int]:
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


def joint_vector(name: str, value: ArrayLike, chain: Chain, hint: str = "") -> FloatArray:
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


def check_path_length(duration: float, Ts: float) -> None:
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
