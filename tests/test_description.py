"""The arm reader from Python (SPEC §21): URDF, xacro and MJCF files read by the
core's one reduction; every front (the chain, the MuJoCo plant, the computed
torque) takes the same arm; MJCF kinematics and dynamics equal MuJoCo's."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

import adaptimp
from adaptimp import _adaptimp, _mjmodel
from adaptimp import mujoco as amj
from adaptimp._description import read_arm
from adaptimp.baselines import ComputedTorque, pinocchio_model

DATA = Path(__file__).parent / "data"
HOBBY = DATA / "hobby_arm.urdf"
XACRO = DATA / "demo_description" / "urdf" / "arm.urdf.xacro"

# A 3-joint arm with its drive terms, motors, a hand body with a site, and two
# slide fingers coupled by an equality (finger_r follows finger_l).
MJCF = """
<mujoco model="demo">
  <compiler angle="radian"/>
  <option gravity="0 0 -9.81"/>
  <default><geom contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="upper" pos="0 0 0.1">
      <joint name="shoulder" axis="0 0 1" range="-3 3" armature="0.1" damping="0.5"
             frictionloss="0.2"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="2"/>
      <body name="fore" pos="0.3 0 0" quat="0.95 0.1 0.2 0.2">
        <joint name="elbow" axis="0 1 0" pos="0 0.01 0" range="-2 2" armature="0.05"
               damping="0.3"/>
        <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.025" mass="1"/>
        <body name="hand" pos="0.2 0 0">
          <joint name="wrist" axis="1 0 0" armature="0.01" damping="0.1" ref="0.2"/>
          <geom type="box" size="0.02 0.04 0.02" mass="0.3"/>
          <site name="grip" pos="0.06 0 0"/>
          <body name="finger_l" pos="0.04 0.02 0">
            <joint name="finger_l" type="slide" axis="0 1 0" range="0 0.04"/>
            <geom type="box" size="0.01 0.005 0.02" mass="0.02"/>
          </body>
          <body name="finger_r" pos="0.04 -0.02 0">
            <joint name="finger_r" type="slide" axis="0 -1 0" range="0 0.04"/>
            <geom type="box" size="0.01 0.005 0.02" mass="0.02"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <equality><joint joint1="finger_r" joint2="finger_l"/></equality>
  <actuator>
    <motor joint="shoulder" ctrlrange="-20 20" ctrllimited="true"/>
    <motor joint="elbow" ctrlrange="-10 10" ctrllimited="true" gear="2"/>
    <position joint="wrist" kp="50" forcerange="-3 3" forcelimited="true"/>
    <position joint="finger_l" kp="100" ctrlrange="0 0.04"/>
  </actuator>
</mujoco>
"""


@pytest.fixture
def mjcf(tmp_path: Path) -> Path:
    path = tmp_path / "demo.xml"
    path.write_text(MJCF)
    return path


def test_a_mimic_gripper_is_held_and_every_front_drives_the_same_joints() -> None:
    arm = read_arm(HOBBY)
    joints = ("base_yaw", "shoulder_pitch", "elbow_pitch", "wrist_pitch", "wrist_roll")
    assert arm.joints == joints
    assert arm.fixed == {
        "gripper_jaw": "drives a gripper ('finger' mimic it)",
        "finger": "mimics 'gripper_jaw': it moves with 'gripper_jaw', not on its own",
    }
    assert adaptimp.Chain.from_urdf(HOBBY).joint_names == list(joints)
    with pytest.warns(UserWarning, match=r"no effort limit for \['wrist_roll'\]"):
        plant = amj.Plant(amj.from_urdf(HOBBY))
    joint = mujoco.mjtObj.mjOBJ_JOINT
    assert [_mjmodel.obj_name(plant.model, joint, j) for j in plant._joints] == list(joints)
    model = pinocchio_model(HOBBY)
    assert [model.names[j] for j in range(1, model.njoints)] == list(joints)
    assert ComputedTorque(HOBBY, tau_max=1.0).n == len(joints)


def test_a_knuckle_gripper_and_a_hand_by_structure() -> None:
    """A UR-like arm with a Robotiq-like linkage gripper: the drive named
    "…knuckle…" and the joints that mimic it are held; a palm of three
    fingers as long as the arm ends the arm."""

    def urdf(joints: list[tuple[str, str, str, str]], mimic: dict[str, str]) -> str:
        inertial = (
            '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
            'iyz="0" izz="0.01"/></inertial>'
        )
        links = ["root", *(j[3] for j in joints)]
        out = ['<robot name="t">', *(f'<link name="{n}">{inertial}</link>' for n in links)]
        for name, kind, parent, child in joints:
            m = f'<mimic joint="{mimic[name]}"/>' if name in mimic else ""
            out.append(
                f'<joint name="{name}" type="{kind}"><parent link="{parent}"/>'
                f'<child link="{child}"/><origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>'
                f'<limit lower="-1" upper="1" effort="5" velocity="1"/>{m}</joint>'
            )
        return "".join([*out, "</robot>"])

    arm = [(f"a{i}", "revolute", f"l{i - 1}" if i > 1 else "root", f"l{i}") for i in range(1, 7)]
    gripper = [
        ("robotiq_85_left_knuckle_joint", "revolute", "l6", "lk"),
        ("robotiq_85_left_finger_tip_joint", "revolute", "lk", "lt"),
        ("robotiq_85_right_knuckle_joint", "revolute", "l6", "rk"),
        ("robotiq_85_right_finger_tip_joint", "revolute", "rk", "rt"),
    ]
    drive = "robotiq_85_left_knuckle_joint"
    mimic = {g[0]: drive for g in gripper[1:]}
    a = read_arm(urdf(arm + gripper, mimic))
    assert a.joints == tuple(f"a{i}" for i in range(1, 7))
    assert a.fixed[drive] == (
        "drives a gripper ('robotiq_85_left_finger_tip_joint', "
        "'robotiq_85_right_knuckle_joint', 'robotiq_85_right_finger_tip_joint' mimic it)"
    )
    # Fingers as long as a short arm: three or more of them make a hand.
    short = arm[:2]
    fingers = [
        (f"f{k}{i}", "revolute", "l2" if i == 1 else f"f{k}l{i - 1}", f"f{k}l{i}")
        for k in range(3)
        for i in (1, 2)
    ]
    a = read_arm(urdf(short + fingers, {}))
    assert a.joints == ("a1", "a2")
    assert a.fixed["f01"].startswith("in the hand at 'l2'")


def test_two_tied_arms_are_refused_by_every_front_until_one_is_named(tmp_path: Path) -> None:
    def side(s: str) -> str:
        return "".join(
            f'<joint name="{s}{i}" type="revolute"><parent link="{s}{i - 1 if i else "t"}"/>'
            f'<child link="{s}{i}"/><origin xyz="0 0.1 0"/><axis xyz="1 0 0"/>'
            '<limit lower="-1" upper="1" effort="5" velocity="1"/></joint>'
            for i in range(3)
        ).replace(f'parent link="{s}t"', 'parent link="torso"')

    links = "".join(f'<link name="{n}"/>' for n in ("torso", "l0", "l1", "l2", "r0", "r1", "r2"))
    path = tmp_path / "two_arms.urdf"
    path.write_text(f'<robot name="two">{links}{side("l")}{side("r")}</robot>')
    message = (
        "URDF 'two_arms.urdf': 2 serial chains of 3 joints from the root tie for the arm "
        "(legs, or two arms), ending at the links 'l2', 'r2': name one with tip= or hold the "
        "others' joints with fix="
    )
    for front in (read_arm, adaptimp.Chain.from_urdf, amj.from_urdf, pinocchio_model):
        with pytest.raises(adaptimp.ConfigError, match=f"^{re.escape(message)}$"):
            front(path)
    assert adaptimp.Chain.from_urdf(path, tip="r2").joint_names == ["r0", "r1", "r2"]
    assert read_arm(path, fix=("l0",)).joints == ("r0", "r1", "r2")


def test_a_xacro_arm_is_expanded_or_refused_with_the_command(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """tests/data/demo_description: a macro from an included file found
    through $(find demo_description), properties and expressions; its jaw
    (beside the tool frame) is held."""
    arm = read_arm(XACRO)
    assert arm.source == "xacro 'arm.urdf.xacro'"
    assert arm.joints == ("shoulder", "elbow")
    assert arm.fixed == {
        "jaw_joint": "moves a jaw beside the tool frame 'tool' (the arm ends at the tool)"
    }
    np.testing.assert_allclose(arm.lower, [-np.pi / 2, -np.pi * 0.75], rtol=0, atol=1e-15)
    assert arm.damping == (0.0, 0.2)
    chain = adaptimp.Chain.from_urdf(XACRO, tip="tool")
    np.testing.assert_allclose(chain.fk([0.0, 0.0])[:3, 3], [0.5, 0.0, 0.1], atol=1e-15)
    plant = amj.Plant(XACRO)
    assert plant.n == 2
    assert plant.tau_max.tolist() == [20.0, 10.0]
    # Without the extra: refused, saying what the file is and the command.
    monkeypatch.setitem(sys.modules, "xacro", None)
    message = (
        f"'{XACRO}' is xacro: expand it into a URDF with `xacro {XACRO} -o robot.urdf` "
        "(pip install xacro), or install adaptimp's extra that expands it for you: "
        "pip install 'adaptimp[xacro]'"
    )
    with pytest.raises(adaptimp.XacroError, match=f"^{re.escape(message)}$"):
        read_arm(XACRO)
    # Xacro markup in a .urdf is found by the core, which gives the command too.
    with pytest.raises(adaptimp.XacroError, match=r"it has the element <xacro:include>"):
        _adaptimp.read_arm(str(XACRO))
    assert _adaptimp.description_kind(str(XACRO)) == "xacro"
    assert _adaptimp.description_kind(str(HOBBY)) == "urdf"


def test_errors_name_the_file_and_what_to_do(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError, match=r"^cannot read 'nowhere\.urdf': "):
        read_arm("nowhere.urdf")
    bad = tmp_path / "bad.urdf"
    bad.write_text(
        '<robot name="b"><link name="a"/><link name="b"/><joint name="j" '
        'type="revolute"><parent link="a"/><child link="b"/>'
        '<axis xyz="0 0 1 0"/></joint></robot>'
    )
    with pytest.raises(
        adaptimp.ConfigError,
        match=r'bad\.urdf as a URDF: <joint name="j">: .*'
        r"expected 3 found 4.*correct it against the URDF format",
    ):
        read_arm(bad)
    with pytest.raises(adaptimp.ConfigError, match=r"^fix must be a tuple of joint names"):
        read_arm(HOBBY, fix="finger")


def test_a_mjcf_arm_reads_as_mujoco_compiles_it(mjcf: Path) -> None:
    model = mujoco.MjModel.from_xml_path(str(mjcf))
    arm = read_arm(mjcf)
    assert arm.source == "MJCF 'demo.xml'"
    assert arm.joints == ("shoulder", "elbow", "wrist")
    assert arm.joint_ids == (0, 1, 2)
    assert arm.fixed == {
        "finger_l": "in the hand at 'hand' (branches of joints start there: two or more each "
        "shorter than the arm, or three or more none longer)",
        "finger_r": "mimics 'finger_l': it moves with 'finger_l', not on its own",
    }
    assert arm.armature == (0.1, 0.05, 0.01)
    assert arm.damping == (0.5, 0.3, 0.1)
    assert arm.friction == (0.2, 0.0, 0.0)
    # A motor's ctrlrange × gear, a position actuator's force range.
    assert arm.effort == (20.0, 20.0, 3.0)
    assert arm.upper[2] == np.inf
    assert arm.gravity == (0.0, 0.0, -9.81)
    # The pose and the Jacobian at a body and at a site equal MuJoCo's.
    data = mujoco.MjData(model)
    rng = np.random.default_rng(5)
    for tip, kind in (("hand", mujoco.mjtObj.mjOBJ_BODY), ("grip", mujoco.mjtObj.mjOBJ_SITE)):
        a = read_arm(model, tip=tip)
        assert a.tip_kind == ("link" if tip == "hand" else "frame")
        chain = adaptimp.Chain(a.chain, a.tip_origin, names=a.joints)
        jp, jr = np.zeros((3, model.nv)), np.zeros((3, model.nv))
        for _ in range(4):
            q = rng.uniform(-1.5, 1.5, 3)
            data.qpos[:3] = q
            data.qpos[3:] = model.qpos0[3:]
            mujoco.mj_kinematics(model, data)
            mujoco.mj_comPos(model, data)
            i = mujoco.mj_name2id(model, kind, tip)
            if tip == "hand":
                mujoco.mj_jacBody(model, data, jp, jr, i)
                p, r = data.xpos[i], data.xmat[i]
            else:
                mujoco.mj_jacSite(model, data, jp, jr, i)
                p, r = data.site_xpos[i], data.site_xmat[i]
            t = chain.fk(q)
            np.testing.assert_allclose(t[:3, 3], p, rtol=0, atol=1e-12)
            np.testing.assert_allclose(t[:3, :3], r.reshape(3, 3), rtol=0, atol=1e-12)
            np.testing.assert_allclose(chain.jacobian(q), np.vstack([jp, jr])[:, :3], atol=1e-12)


def test_the_exact_model_of_a_mjcf_has_its_drive_terms(mjcf: Path) -> None:
    """ComputedTorque(MJCF path): the core's arm with the model's armature,
    damping and friction loss; its inverse dynamics equal MuJoCo's (the
    fingers held where the reduction holds them, the dry friction apart)."""
    ct = ComputedTorque(mjcf, Ts=1e-3)
    assert ct.n == 3
    assert ct.tau_max.tolist() == [20.0, 20.0, 3.0]
    assert ct.drive == {
        "armature": [0.1, 0.05, 0.01],
        "damping": [0.5, 0.3, 0.1],
        "friction": [0.2, 0.0, 0.0],
    }
    assert ct.params["friction"] == [0.2, 0.0, 0.0]
    # MuJoCo's model of the arm alone: the fingers welded where they are held.
    spec = mujoco.MjSpec.from_string(MJCF)
    for e in [*spec.equalities, *spec.actuators[3:]]:
        spec.delete(e)
    for name in ("finger_l", "finger_r"):
        spec.delete(spec.joint(name))
    spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_FRICTIONLOSS
    model = spec.compile()
    data = mujoco.MjData(model)
    rng = np.random.default_rng(9)
    for _ in range(5):
        q, dq, ddq = rng.uniform(-1, 1, 3), rng.normal(size=3), rng.normal(size=3)
        data.qpos[:], data.qvel[:], data.qacc[:] = q, dq, ddq
        mujoco.mj_inverse(model, data)
        np.testing.assert_allclose(
            ct.inverse_dynamics(q, dq, ddq), data.qfrc_inverse, rtol=0, atol=1e-9
        )
    # A URDF's plant is the rigid body (from_urdf), so is its exact model;
    # drive=True takes the file's damping and friction for both.
    assert ComputedTorque(XACRO).drive["damping"] == [0.0, 0.0]
    assert ComputedTorque(XACRO, drive=True).drive["damping"] == [0.0, 0.2]
    model = amj.from_urdf(XACRO, drive=True)
    assert model.dof_damping.tolist() == [0.0, 0.2]
    assert model.dof_frictionloss.tolist() == [0.0, 0.1]
    assert amj.from_urdf(XACRO).dof_damping.tolist() == [0.0, 0.0]


# A 3-joint arm whose joints declare armature, damping and friction loss,
# torque motors only (the plant simulate drives as it is).
DRIVEN = """
<mujoco model="driven">
  <compiler angle="radian"/>
  <option timestep="0.001" integrator="RK4"/>
  <default><geom contype="0" conaffinity="0"/></default>
  <worldbody>
    <body name="upper" pos="0 0 0.1">
      <joint name="shoulder" axis="0 0 1" range="-3 3" armature="0.2" damping="2"
             frictionloss="FRICTION"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="2"/>
      <body name="fore" pos="0.3 0 0">
        <joint name="elbow" axis="0 1 0" range="-2 2" armature="0.1" damping="1"
               frictionloss="FRICTION"/>
        <geom type="capsule" fromto="0 0 0 0.25 0 0" size="0.025" mass="1"/>
        <body name="hand" pos="0.25 0 0">
          <joint name="wrist" axis="0 1 0" range="-2 2" armature="0.05" damping="0.5"/>
          <geom type="box" size="0.04 0.02 0.02" pos="0.04 0 0" mass="0.5"/>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="shoulder" ctrlrange="-40 40" ctrllimited="true"/>
    <motor joint="elbow" ctrlrange="-30 30" ctrllimited="true"/>
    <motor joint="wrist" ctrlrange="-10 10" ctrllimited="true"/>
  </actuator>
</mujoco>
"""


def test_the_exact_model_has_the_drive_the_file_declares(tmp_path: Path) -> None:
    """On a model that declares armature, damping and friction loss, computed
    torque with the exact model (the file's drive terms, read by the core)
    tracks far better than the rigid-body model without them (the baseline
    before) and than the model without the friction term."""
    path = tmp_path / "driven.xml"
    path.write_text(DRIVEN.replace("FRICTION", "0.5"))
    sf = amj.simulate("sf", path, T=4.0)
    tau_max = sf.params["tau_max"]
    exact = ComputedTorque(path, Ts=1e-3, tau_max=tau_max)
    assert exact.drive == {
        "armature": [0.2, 0.1, 0.05],
        "damping": [2.0, 1.0, 0.5],
        "friction": [0.5, 0.5, 0.0],
    }
    rms = {}
    for name, drive in (
        ("exact", {}),
        ("no friction term", {"friction": 0.0}),
        ("rigid", {"armature": 0.0, "damping": 0.0, "friction": 0.0}),
    ):
        ct = ComputedTorque(path, Ts=1e-3, tau_max=tau_max, **drive)
        res = amj.simulate(ct, path, T=4.0, reference=sf, q0=sf.q[0])
        rms[name] = res.metrics["rms_z1_after2"]
    assert rms["exact"] < 0.1 * rms["no friction term"] < 0.1 * rms["rigid"], rms
