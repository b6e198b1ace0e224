"""The rest of the scene (SPEC §18, §18.10, (21.4); docs/your_arm.md): what
the plant does with another arm, a keyframe, a pedestal and free bodies; the
run's checks that never go quiet; one arm and one model for every front.

The file: ``tests/data/two_arms.xml``, two 3-joint arms with two-finger
grippers and position servos on a table, a pedestal, a free box, a mocap
target and a keyframe "ready" (both arms turned away from each other, no
``ctrl``), the layout of a bimanual task scene. The left arm is chosen with
``tip="left/tcp"``; its fingers are locked, the right arm stays the scene's."""

from __future__ import annotations

import re
from pathlib import Path

import mujoco
import numpy as np
import pytest

import adaptimp
from adaptimp import _description
from adaptimp import mujoco as amj
from adaptimp.baselines import ComputedTorque

DATA = Path(__file__).parent / "data"
SCENE = DATA / "two_arms.xml"
RIGHT = ["right/waist", "right/shoulder", "right/elbow", "right/finger_a", "right/finger_b"]
READY = {"right/waist": -1.4, "right/shoulder": 0.2, "right/elbow": 0.5,
         "right/finger_a": 0.03, "right/finger_b": 0.03}  # fmt: skip


def _left() -> amj.Plant:
    with pytest.warns(adaptimp.PlantWarning):
        return amj.Plant(SCENE, tip="left/tcp")


def _qpos(m: mujoco.MjModel, d: mujoco.MjData, joint: str) -> float:
    return float(d.qpos[m.joint(joint).qposadr[0]])


def test_the_keyframe_is_laid_out_again_for_the_plants_model() -> None:
    """Two finger joints locked: every keyframe field is the file's by name,
    so the other arm, its fingers, the free box and the mocap target start
    where the file puts them (MuJoCo's keyframe would have slid by two)."""
    plant = _left()
    m, d = plant.model, plant.data
    whole = mujoco.MjModel.from_xml_path(str(SCENE))
    assert (m.nq, whole.nq) == (whole.nq - 2, 17)
    assert plant.notes["locked"] == {
        "left/finger_a": "not on the way to 'left/tcp'",
        "left/finger_b": "not on the way to 'left/tcp'",
    }
    for joint, value in READY.items():
        assert _qpos(m, d, joint) == value
    box = m.joint("box").qposadr[0]
    np.testing.assert_array_equal(d.qpos[box : box + 7], [0.1, -0.25, 0.45, 1, 0, 0, 0])
    np.testing.assert_array_equal(d.mocap_pos[0], [0.0, -0.2, 0.8])
    np.testing.assert_array_equal(d.mocap_quat[0], [1.0, 0.0, 0.0, 0.0])
    assert plant.q.tolist() == [1.4, 0.2, 0.5]
    assert m.nkey == 1
    assert m.key(0).name == "ready"
    # The box sits where the file has it, on the table, and stays there.
    plant.reset()
    for _ in range(400):
        plant.data.qfrc_applied[plant._dofs] = plant.data.qfrc_bias[plant._dofs]
        mujoco.mj_step(m, plant.data)
    np.testing.assert_allclose(plant.data.qpos[box : box + 3], [0.1, -0.25, 0.45], atol=1e-2)


def test_the_other_arms_servos_hold_the_keyframes_posture() -> None:
    """Its position servos are commanded to the keyframe's posture, not to
    zero: over 1 s (the chosen arm held by its gravity) it stays within 20
    mrad (the servos' sag under gravity: 17 mrad);
    at zero control it swings more than 1 rad, into the chosen arm's way."""
    plant = _left()
    m, d = plant.model, plant.data
    ctrl = {m.actuator(a).name: float(d.ctrl[a]) for a in range(m.nu)}
    assert {k: v for k, v in ctrl.items() if k.startswith("right/")} == READY
    assert [ctrl[k] for k in ("left/waist", "left/shoulder", "left/elbow")] == [0.0] * 3

    def swing(zero: bool) -> float:
        plant.reset()
        if zero:
            d.ctrl[:] = 0.0
        for _ in range(500):
            d.qfrc_applied[plant._dofs] = d.qfrc_bias[plant._dofs]
            mujoco.mj_step(m, d)
        return max(abs(_qpos(m, d, j) - READY[j]) for j in RIGHT[:3])

    assert swing(zero=False) < 0.02
    assert swing(zero=True) > 1.0
    assert plant.notes["scene"]["right/waist"] == (
        "held at -1.4 (its posture in the keyframe 'ready') by its servo 'right/waist', "
        "commanded to it"
    )
    assert plant.notes["scene"]["box"] == "a free body: starts at its pose in the keyframe 'ready'"
    assert set(plant.notes["scene"]) == {*RIGHT, "box"}


def test_a_run_that_touches_the_scene_says_so_by_name() -> None:
    """The other arm let go (its servos at zero, as a reset to zero control
    left it): it swings into the chosen arm, and the run names the bodies,
    the share of the steps and the peak force; with the servos holding the
    keyframe, the default task touches nothing and says nothing."""
    plant = _left()
    assert plant._watch is not None
    watched = set(plant._watch.pairs)
    assert ("left/hand", "right/hand") in watched
    assert ("left/fore", "pedestal") in watched
    assert not any(a.startswith("right/") or b.startswith("left/") for a, b in watched)
    quiet = amj.simulate("sf", plant, T=4.0)
    assert quiet.params["warnings"] == []
    task = amj.default_task(plant)
    kw = amj.rule_keywords(plant, task)
    plant.reset(task.q0)
    plant.data.ctrl[:] = 0.0
    ctrl = adaptimp.Controller("pd", "robot", **{"tau_max": plant.tau_max.tolist(), **kw})
    with pytest.warns(adaptimp.PlantWarning) as record:
        res = amj.simulate(ctrl, plant, T=4.0, reset=False, reference=task.reference)
    # What the run found, in its order: the scene touched, then the torque
    # the contact's push made saturate (checked in contact as anywhere).
    assert [str(w.message) for w in record] == res.params["warnings"]
    assert [w.split(":")[0] for w in res.params["warnings"]] == [
        "the arm touched the rest of the scene",
        "the torque was at a limit in 4.0 % of the steps (more than 1 %)",
    ]
    said = res.params["warnings"][0]
    found = r"'(left/[^']+)'–'(right/[^']+)' in ([0-9.]+) % of the steps, up to ([0-9.]+) N"
    pair = re.search(found, said)
    assert pair is not None, said
    assert 0.0 < float(pair.group(3)) <= 100.0
    assert float(pair.group(4)) > 0.0
    assert said.endswith(
        "the task runs into what is around the arm, so the tracking measured is the contact's "
        "as much as the controller's; give another home= or reference, or move what is in "
        "the way"
    )


def test_a_contact_tasks_surface_is_its_own() -> None:
    """surface= names the bodies a contact task presses on: the end effector
    on them is not watched, the rest of the arm is; an unknown body is
    refused by name."""
    with pytest.warns(adaptimp.PlantWarning):
        plant = amj.Plant(SCENE, tip="left/hand", surface="table")
    watched = set(plant._watch.pairs) if plant._watch else set()
    assert ("left/hand", "table") not in watched
    assert ("left/fore", "table") in watched
    with (
        pytest.raises(ValueError, match=r"tip='nowhere': the model has no site or body"),
        pytest.warns(adaptimp.PlantWarning),
    ):
        amj.Plant(SCENE, tip="left/hand", surface="nowhere")


def test_the_default_tasks_start_keeps_off_the_scene() -> None:
    """The default Cartesian task's start is checked against every body of
    the scene (the other arm at its keyframe, the pedestal, the table)."""
    plant = _left()
    from adaptimp._cartesian_task import collision

    # The left arm reaching down to the table, then towards the pedestal: the
    # scene is hit, not the arm itself.
    for q, body in (([0.0, 1.2, 0.2], "'table'"), ([0.6, 0.5, 0.2], "'pedestal'")):
        rows = np.array([q])
        assert amj.self_collision(plant, rows) is None
        hit = collision(plant, rows)
        assert hit is not None
        assert body in hit, hit


def test_an_mjcf_fragment_is_named_with_the_scenes_that_include_it(tmp_path: Path) -> None:
    """A file of bodies outside a <worldbody>, or a <mujocoinclude>, is not a
    model of its own (MuJoCo compiles it to an empty world): every front
    names it and the scenes beside it that include it; never URDF words."""
    (tmp_path / "arm.xml").write_text(
        '<mujoco model="arm"><body name="l1"><joint name="j1"/><geom size=".1"/></body></mujoco>'
    )
    (tmp_path / "gripper.xml").write_text(
        '<mujocoinclude><body name="g"><geom size=".1"/></body></mujocoinclude>'
    )
    (tmp_path / "task.xml").write_text(
        '<mujoco><worldbody><include file="arm.xml"/></worldbody></mujoco>'
    )
    (tmp_path / "other.xml").write_text("<mujoco><worldbody/></mujoco>")
    said = (
        "arm.xml is an MJCF fragment (its bodies are not in a <worldbody>: a file that other "
        "MJCF files include), not a model of its own: load a scene that includes it (task.xml)"
    )
    assert _description.kind_of(tmp_path / "arm.xml") == "mjcf-fragment"
    for front in (amj.Plant, adaptimp.Chain.from_mujoco, _description.read_arm):
        with pytest.raises(adaptimp.ConfigError) as e:
            front(tmp_path / "arm.xml")
        assert str(e.value) == said
    with pytest.raises(adaptimp.ConfigError, match=r"^gripper.xml is an MJCF fragment .*: load "
                       r"the scene of its package that includes it$"):  # fmt: skip
        amj.Plant(tmp_path / "gripper.xml")
    # The core's URDF reader (C's too) given its text: named, not read as a URDF.
    from adaptimp import _adaptimp

    fragment = (
        r"is an MJCF fragment \(its bodies are not in a <worldbody>: a file that other MJCF "
        r"files include\), not a URDF"
    )
    with pytest.raises(ValueError, match=fragment):
        _adaptimp.read_arm((tmp_path / "gripper.xml").read_text(), None, [])


def test_a_mujoco_models_joints_are_named_in_mujocos_words() -> None:
    """A model without a hinge is refused with MuJoCo's joint names."""
    m = mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><body><joint type="slide"/><geom size=".1"/></body></worldbody>'
        "</mujoco>"
    )
    with pytest.raises(adaptimp.ConfigError, match=r"no hinge joint to drive.*a slide joint"):
        _description.read_arm(m)


TRIANGLE = """<robot name="tri">
  <link name="base"/>
  <link name="upper"><inertial><origin xyz="0.15 0 0"/><mass value="2"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.02"/></inertial></link>
  <link name="fore"><inertial><origin xyz="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="shoulder" type="revolute"><parent link="base"/><child link="upper"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="40" velocity="2"/></joint>
  <joint name="elbow" type="revolute"><parent link="upper"/><child link="fore"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="20"
    velocity="2"/></joint>
</robot>"""


def test_a_balanced_inertia_is_one_model_said_once(tmp_path: Path) -> None:
    """An inertia that breaks the triangle inequality (0.001 + 0.001 < 0.02)
    is balanced by the core's reader (the moments set to their mean, 0.0073
    kg m²): the plant and computed torque have the same mass matrix to
    rounding, and the reader says so once."""
    path = tmp_path / "tri.urdf"
    path.write_text(TRIANGLE)
    _description._BALANCED_SAID.clear()
    with pytest.warns(adaptimp.PlantWarning) as said:
        arm, plant, ct = _description.read_arm(path), amj.Plant(path), ComputedTorque(path)
    balanced = [str(w.message) for w in said if "triangle" in str(w.message)]
    assert balanced == [
        "URDF 'tri.urdf': the inertia of ['upper'] breaks the triangle inequality (A + B ≥ C "
        "of its principal moments, which every rigid body meets): the reader balances it (the "
        "moments set to their mean, about the same centre of mass), for the plant, the chain "
        "and computed torque alike (SPEC (21.4))"
    ]
    assert arm.balanced == ("upper",)
    mean = (0.001 + 0.001 + 0.02) / 3  # about the centre of mass, every axis
    np.testing.assert_allclose(arm.inertials[0]["inertia"], np.eye(3) * mean, rtol=1e-12)
    for q in ([0.0, 0.0], [0.4, -1.1]):
        plant.reset(q)
        np.testing.assert_allclose(plant.mass_matrix(), ct.mass_matrix(q), rtol=0, atol=1e-12)


def test_a_mocap_target_welded_to_the_other_arm_holds_it_where_the_keyframe_puts_it(
    tmp_path: Path,
) -> None:
    """The other arm driven through a mocap weld (an end-effector task scene):
    the mocap body is placed where its weld holds that hand at the keyframe,
    so the weld holds the keyframe's posture instead of dragging the hand to
    the mocap body's own position."""
    text = SCENE.read_text().replace(
        "  <keyframe>",
        '  <equality><weld body1="target" body2="right/hand"/></equality>\n  <keyframe>',
    )
    path = tmp_path / "welded.xml"
    path.write_text(text)
    with pytest.warns(adaptimp.PlantWarning):
        plant = amj.Plant(path, tip="left/tcp")
    m, d = plant.model, plant.data
    welds = d.efc_type == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    assert welds.sum() == 6
    np.testing.assert_allclose(d.efc_pos[welds], 0.0, atol=1e-12)
    assert plant.notes["scene"]["target"] == (
        "a mocap body welded to 'right/hand': placed where the weld holds 'right/hand' in the "
        "keyframe 'ready'"
    )
    for joint, value in READY.items():
        assert _qpos(m, d, joint) == value
