"""MJCF files as their makers ship them (SPEC §18, docs/your_arm.md): the plant
edits the model in memory, never the file — servos driven as torque motors of
their force range, a gripper's coupled joints locked, a motor added where a
joint has none, τmax estimated where nothing declares it; the end effector a
body or a site everywhere; a default task that keeps the arm off itself; runs
that say when the arm touched itself or the torque went beyond its limits.

The files: ``tests/data/ur5_gripper.xml`` (the UR5 of example-robot-data as a
Menagerie-style file: position servos, ``tool0`` a body without a site,
collision capsules, a gripper whose knuckle joints are coupled; written by
``scripts/make_test_mjcf.py``) and ``tests/data/fold_arm.xml`` (a 3-joint arm
whose hand folds back onto its upper arm at the zero posture)."""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

import adaptimp
from adaptimp import _contacts, _mjcf, _sampled
from adaptimp import mujoco as amj
from mujoco_probe import measure

DATA = Path(__file__).parent / "data"
UR5 = DATA / "ur5_gripper.xml"
FOLD = DATA / "fold_arm.xml"
ARM = [
    "shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint",
    "wrist_1_joint", "wrist_2_joint", "wrist_3_joint",
]  # fmt: skip

LOCKED = (
    "ur5_gripper.xml: the joints ['left_knuckle_joint', 'right_knuckle_joint'] are not the "
    "arm's (left_knuckle_joint: drives a gripper ('right_knuckle_joint' mimic it); "
    "right_knuckle_joint: mimics 'left_knuckle_joint': it moves with 'left_knuckle_joint', "
    "not on its own): the plant "
    "locks them at their reference position (a rigid hand, as the controller's model of the "
    "arm has it), with their actuators, couplings and sensors; the file is not changed"
)
SERVOS = (
    f"ur5_gripper.xml: the actuators of {ARM} are position servos, not torque motors: the "
    "plant drives these joints with torque motors of the same force range (their forcerange "
    "where declared), as the controller commands torque; the file is not changed"
)


def _ur5() -> amj.Plant:
    with pytest.warns(adaptimp.PlantWarning) as record:
        plant = amj.Plant(UR5)
    assert [str(w.message) for w in record] == [LOCKED, SERVOS]
    return plant


def test_a_menagerie_style_file_becomes_a_torque_plant_in_memory() -> None:
    before = UR5.read_bytes()
    plant = _ur5()
    assert UR5.read_bytes() == before  # the file is not changed
    assert plant.joint_names == ARM
    # τmax = gear × forcerange; every arm joint has one motor (gain 1, no bias).
    assert plant.tau_max.tolist() == [150.0, 150.0, 150.0, 28.0, 28.0, 28.0]
    m = plant.model
    assert (m.njnt, m.nu, m.neq) == (6, 6, 0)
    assert np.all(m.actuator_gaintype == int(mujoco.mjtGain.mjGAIN_FIXED))
    assert np.all(m.actuator_gainprm[:, 0] == 1.0)
    assert np.all(m.actuator_biastype == int(mujoco.mjtBias.mjBIAS_NONE))
    notes = plant.notes
    assert notes["tau_max"] == dict.fromkeys(ARM, "forcerange")
    # Named by what it does (a <general> like it was called a "position actuator").
    assert notes["actuators"]["wrist_1_joint"] == (
        "actuator 'wrist_1' (a position servo, kp = 560: a <position>, or a <general> with its "
        "gain and bias) → motor"
    )
    assert set(notes["locked"]) == {"left_knuckle_joint", "right_knuckle_joint"}
    assert notes["timestep"] == "mjINT_EULER at 0.002 s in the file: stepped at 0.00025 s"
    assert notes["tip"] == "wrist_3_link"
    assert notes["warnings"] == [LOCKED, SERVOS]
    # The gripper's 0.4 kg ride on the hand: the moving mass is the file's.
    whole = mujoco.MjModel.from_xml_path(str(UR5))
    assert amj.moving_mass(m) == pytest.approx(amj.moving_mass(whole), rel=1e-12)
    # The locked fingers sit at their reference (the file's qpos0), not at the keyframe.
    plant.reset()
    d = mujoco.MjData(whole)
    mujoco.mj_resetDataKeyframe(whole, d, 0)
    d.qpos[6:] = whole.qpos0[6:]
    mujoco.mj_forward(whole, d)
    for body in ("left_finger", "right_finger", "palm"):
        np.testing.assert_allclose(
            plant.data.xpos[m.body(body).id], d.xpos[whole.body(body).id], atol=1e-12
        )


def test_tip_is_a_body_or_a_site_and_fix_locks_more() -> None:
    with pytest.warns(adaptimp.PlantWarning):
        plant = amj.Plant(UR5, tip="tool0", fix=("wrist_3_joint",))
    assert plant.joint_names == ARM[:5]
    assert plant.notes["tip"] == "tool0"
    assert "wrist_3_joint" in plant.notes["locked"]
    assert plant.notes["locked"]["wrist_3_joint"] == "asked (fix=)"
    # The end effector is tool0's origin: its position and Jacobian are MuJoCo's.
    tool = plant.model.body("tool0").id
    plant.reset(np.full(5, 0.3))
    expected = plant.data.xpos[tool].copy()
    res = measure(plant, np.zeros(5))  # what the core's loop reads there
    np.testing.assert_array_equal(res.x_ee[0], expected)
    with pytest.raises(ValueError, match=r"tip= 'nowhere' is neither a link nor a frame"):
        amj.Plant(UR5, tip="nowhere")
    with pytest.raises(ValueError, match=r"fix= names joints it does not have: \['elbow'\]"):
        amj.Plant(UR5, fix=("elbow",))
    with pytest.raises(TypeError, match="fix must be a tuple of joint names"):
        amj.Plant(UR5, fix="elbow_joint")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"tip= .* or site=, not both"):
        amj.Plant(UR5, tip="tool0", site="ee")


def test_the_chain_to_a_body_or_a_site_is_mujocos() -> None:
    """Chain.from_mujoco(PATH, tip=BODY): pose and 6 × n Jacobian equal
    mj_jacBody's on the file as it is (the gripper's joints at qpos0)."""
    model = mujoco.MjModel.from_xml_path(str(UR5))
    data = mujoco.MjData(model)
    spec = mujoco.MjSpec.from_file(str(UR5))
    spec.body("palm").add_site(name="pinch", pos=[0.01, 0.02, 0.08], euler=[0.3, 0.2, 0.1])
    with_site = spec.compile()
    rng = np.random.default_rng(29)
    jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
    for tip in ("tool0", "palm", "wrist_2_link"):
        chain = adaptimp.Chain.from_mujoco(UR5, tip=tip)
        body = model.body(tip).id
        n = chain.n
        assert chain.joint_names == ARM[:n]
        for _ in range(5):
            q = rng.uniform(-3.0, 3.0, n)
            data.qpos[:] = model.qpos0
            data.qpos[:n] = q
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
            mujoco.mj_jacBody(model, data, jp, jr, body)
            p, r = chain.pose(q)
            np.testing.assert_allclose(p, data.xpos[body], rtol=0, atol=1e-9)
            np.testing.assert_allclose(r, data.xmat[body].reshape(3, 3), rtol=0, atol=1e-9)
            jac = np.vstack([jp, jr])[:, :n]
            np.testing.assert_allclose(chain.jacobian(q), jac, rtol=0, atol=1e-9)
    chain = adaptimp.Chain.from_mujoco(with_site, tip="pinch")
    sid = with_site.site("pinch").id
    d = mujoco.MjData(with_site)
    q = rng.uniform(-3.0, 3.0, 6)
    d.qpos[:6] = q
    mujoco.mj_kinematics(with_site, d)
    mujoco.mj_comPos(with_site, d)
    mujoco.mj_jacSite(with_site, d, jp, jr, sid)
    np.testing.assert_allclose(chain.fk(q)[:3, 3], d.site_xpos[sid], atol=1e-9)
    np.testing.assert_allclose(chain.jacobian(q), np.vstack([jp, jr])[:, :6], atol=1e-9)
    # No tip: the plant's end effector (the last arm joint's body, no site on it).
    assert adaptimp.Chain.from_mujoco(UR5).source == "MuJoCo model to body 'wrist_3_link'"
    with pytest.raises(adaptimp.ConfigError, match="no site or body of that name"):
        adaptimp.Chain.from_mujoco(UR5, tip="nowhere")
    with pytest.raises(FileNotFoundError, match=r"no file 'nowhere\.xml'"):
        adaptimp.Chain.from_mujoco("nowhere.xml")


def test_the_default_tip_is_the_cores(tmp_path: Path) -> None:
    """Without tip=, the plant's end effector, the chain's tip and the Cartesian
    task's chain are the core's reduction's (SPEC (21.2) rules 2 and 7): the
    last arm joint's body's origin; the first site on that body (the tool
    point the file's author named there); a force sensor's site a hinge of
    the arm moves, before either."""
    spec = mujoco.MjSpec.from_file(str(UR5))
    path = tmp_path / "ur5_marker.xml"
    core = _mjcf.arm_of(mujoco.MjModel.from_xml_path(str(UR5)))
    assert core["tip"] == "wrist_3_link"
    spec.body("wrist_3_link").add_site(name="marker", pos=[0.0, 0.05, 0.0])
    spec.body("wrist_3_link").add_site(name="second", pos=[0.0, 0.0, 0.05])
    spec.body("shoulder_link").add_site(name="elsewhere", pos=[0.0, 0.0, 0.05])
    path.write_text(spec.to_xml())
    with pytest.warns(adaptimp.PlantWarning):
        plant = amj.Plant(str(path))
    core = _mjcf.arm_of(mujoco.MjModel.from_xml_path(str(path)))
    assert core["tip"] == "marker"
    assert plant.notes["tip"] == "marker"
    assert plant.ee_site == plant.model.site("marker").id
    assert plant.ee_body == plant.model.body("wrist_3_link").id
    assert adaptimp.Chain.from_mujoco(str(path)).source == "MuJoCo model to site 'marker'"
    assert amj.chain_of(plant).source == "MuJoCo model to site 'marker'"
    # A force sensor's site comes first, wherever the arm moves it.
    spec.add_sensor(
        type=mujoco.mjtSensor.mjSENS_FORCE, objtype=mujoco.mjtObj.mjOBJ_SITE, objname="second"
    )
    path.write_text(spec.to_xml())
    with pytest.warns(adaptimp.PlantWarning):
        plant = amj.Plant(str(path))
    assert plant.notes["tip"] == "second"
    assert plant.ee_site == plant.model.site("second").id
    assert amj.chain_of(plant).source == "MuJoCo model to site 'second'"


def test_a_compiled_model_is_refused_where_only_the_file_can_be_edited() -> None:
    model = mujoco.MjModel.from_xml_path(str(UR5))
    with pytest.raises(
        ValueError,
        match=re.escape(
            "joints ['left_knuckle_joint', 'right_knuckle_joint'] of the arm's body tree are "
            "not the arm's"
        )
        + ".* give the plant the file's path",
    ):
        amj.Plant(model)
    # A spec (e.g. an arm with a gripper attached in memory) is edited as a copy.
    spec = mujoco.MjSpec.from_file(str(UR5))
    with pytest.warns(adaptimp.PlantWarning) as record:
        plant = amj.Plant(spec)
    assert str(record[0].message).endswith("; the spec given is not changed")
    assert plant.n == 6
    assert len(spec.joints) == 8


MOTORLESS = """
<mujoco model="bare">
  <compiler angle="radian"/>
  <worldbody>
    <body name="l1"><joint name="a" axis="0 1 0" range="-2 2" actuatorfrcrange="-30 30"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="2"/>
      <body name="l2" pos="0.3 0 0"><joint name="b" axis="0 1 0" range="-2 2" armature="0.01"/>
        <geom type="capsule" fromto="0 0 0 0.25 0 0" size="0.03" mass="1"/>
      </body>
    </body>
    <body name="target" mocap="true" pos="0.5 0 0"/>
  </worldbody>
  <equality><weld name="drag" body1="target" body2="l2"/></equality>
</mujoco>
"""


def test_joints_without_actuators_get_motors(tmp_path: Path) -> None:
    """dm_control's arms ship without actuators: the plant adds motors, τmax
    from the joint's actuatorfrcrange, or estimated from the arm. A mocap
    body welded to the hand (gymnasium's Fetch, metaworld's Sawyer) is let go."""
    path = tmp_path / "bare.xml"
    path.write_text(MOTORLESS)
    with pytest.warns(adaptimp.PlantWarning) as record:
        plant = amj.Plant(path)
    estimate = _sampled.estimate(plant.model, plant._qadr, plant._dofs)[1]
    assert plant.tau_max[0] == 30.0
    assert plant.tau_max[1] == pytest.approx(estimate, rel=1e-12)
    assert estimate > 2 * 9.81 * 0.125  # at least twice the 1 kg link's gravity torque
    assert [str(w.message) for w in record] == [
        "bare.xml: the joints ['a', 'b'] have no actuator: the plant adds a torque motor to each",
        "bare.xml: the equality constraints ['drag'] tie the arm to what it does not move "
        "('target' to 'l2': a mocap body or a fixture): the plant turns them off, as the "
        "controller drives the joints",
        "bare.xml: no force range is declared for ['b']: the plant estimates τmax = "
        f"[{round(estimate, 3)}] N m (2 (max |G_i| + 10 rad/s² · max Σ_j |D_ij| + damping · "
        "1 rad/s + friction loss) within the joint limits)",
    ]
    assert plant.notes["tau_max"] == {"a": "actuatorfrcrange", "b": "estimated"}
    assert plant.model.eq_active0.tolist() == [0]


def test_the_default_task_keeps_the_arm_off_itself() -> None:
    """At the zero posture the hand of fold_arm.xml lies in its upper arm: the
    home is the nearest posture whose swing keeps 5 mm between them."""
    plant = amj.Plant(FOLD)
    contacts = _contacts.Contacts(plant.model, plant.data.qpos, plant._joints, margin=0.005)
    assert contacts.at(np.zeros(3))[0][:2] == ("hand", "upper")
    task = amj.default_task(plant)
    amp = -np.asarray(task.keywords["xc_cos"])
    for s in np.linspace(-1.0, 1.0, 41):
        assert contacts.at(task.home + s * amp) == []
    assert np.max(np.abs(task.home)) < 1.0  # near the zero posture, not anywhere
    with pytest.raises(
        ValueError, match=r"home= sets the default task.s posture: give it without a reference"
    ):
        amj.simulate("pd", FOLD, T=0.1, home=np.zeros(3), reference=lambda t: (0, 0, 0))


def test_a_run_says_when_the_arm_touched_itself() -> None:
    with pytest.warns(adaptimp.PlantWarning) as record:
        res = amj.simulate("pd", FOLD, T=0.5, home=np.zeros(3))
    rows = np.arange(0, res.rows, 10)
    touching = [k for k in rows if _touching(res, k)]
    text = (
        f"the arm touched itself in {100 * len(touching) / len(rows):.1f} % of the rows checked "
        f"('hand'–'upper'; first at t = {res.t[touching[0]]:.3f} s): its own links collide "
        "along this task; give another home= or reference (or contact=False)"
    )
    assert [str(w.message) for w in record] == [text]
    assert res.params["warnings"] == [text]
    assert res.params["plant"]["tip"] == "hand"


def _touching(res: amj.MujocoResult, k: int) -> bool:
    model = mujoco.MjModel.from_xml_path(str(FOLD))
    data = mujoco.MjData(model)
    data.qpos[:] = res.q[k]
    mujoco.mj_forward(model, data)
    names = {
        (model.body(model.geom_bodyid[c.geom1]).name, model.body(model.geom_bodyid[c.geom2]).name)
        for c in data.contact[: data.ncon]
    }
    return ("hand", "upper") in names or ("upper", "hand") in names


def test_a_run_says_when_the_torque_went_beyond_its_limits() -> None:
    """Gains 30 times the rule's in free space: the sampled loop is unstable and
    the motors saturate; the run says both, and where."""
    with pytest.warns(adaptimp.PlantWarning) as record:
        res = amj.simulate("pd", FOLD, T=0.5, contact=False, Kp=[40, 40, 10], Kzeta=[2e5] * 3)
    tau_max = np.asarray(res.params["tau_max"])
    late = res.t >= 0.1
    ratio = np.abs(res.tau[late]) / tau_max
    k, i = np.unravel_index(int(np.argmax(ratio)), ratio.shape)
    assert [str(w.message) for w in record] == [
        f"the commanded torque reached {ratio[k, i]:.3g} τmax after 0.1 s (joint "
        f"'j{i + 1}' at t = {res.t[late][k]:.3f} s), beyond 2 τmax: the controller asks far "
        "more than the actuators give",
        f"the torque was at a limit in {100 * res.metrics['sat_duty']:.1f} % of the steps "
        "(more than 1 %): the actuators saturate, so the tracking measured is theirs as much "
        "as the controller's",
    ]


def test_the_file_meets_the_targets_as_shipped() -> None:
    """docs/your_arm.md's targets on the Menagerie-style UR5 (T = 8 s, metrics
    over t ≥ 2 s): SF ≤ 0.2 PD, no drift, peak commanded torque ≤ 2 τmax after
    0.1 s, at a limit in ≤ 1 % of the steps, and nothing to warn about."""
    with pytest.warns(adaptimp.PlantWarning):
        plant = amj.Plant(UR5)
    runs = {case: amj.simulate(case, plant, T=8.0) for case in ("pd", "sf")}
    pd, sf = (runs[c].metrics["rms_z1_after2"] for c in ("pd", "sf"))
    assert sf <= 0.2 * pd, (sf, pd)
    t, z = runs["sf"].t, np.sum(runs["sf"].z1 ** 2, axis=1)
    assert np.mean(z[t >= 6.0]) <= np.mean(z[(t >= 2.0) & (t < 4.0)])
    for res in runs.values():
        assert res.params["warnings"] == []
        assert np.max(np.abs(res.tau[t >= 0.1]) / plant.tau_max) <= 2.0
        assert res.metrics["sat_duty"] <= 0.01


def test_a_force_sensor_with_a_gripper_below_it_is_not_the_wrench() -> None:
    """robosuite's grippers carry a force/torque sensor at their mounting flange:
    it reads the gripper's weight and inertia as well as contact, so the
    plant measures the contacts instead (and the run is the core's)."""
    spec = mujoco.MjSpec.from_file(str(UR5))
    spec.body("tool0").add_site(name="ft_frame")
    for kind in (mujoco.mjtSensor.mjSENS_FORCE, mujoco.mjtSensor.mjSENS_TORQUE):
        spec.add_sensor(type=kind, objtype=mujoco.mjtObj.mjOBJ_SITE, objname="ft_frame")
    with pytest.warns(adaptimp.PlantWarning):
        plant = amj.Plant(spec)
    assert plant.notes["tip"] == "ft_frame"
    assert plant.notes["wrench"] == (
        "the force sensor '#0' carries 0.4 kg below it (it reads gravity and inertia as well "
        "as contact): the wrench comes from the contacts"
    )
    assert plant.wrench_source == "contact sensor"
    res = amj.simulate("pd", plant, T=0.05)
    assert res.params["loop"] == "native"
    assert np.all(res.wrench_ee == 0.0)
