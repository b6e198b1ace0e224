"""Models that overflow in use are refused when given, by name (issue 33,
minor items): a computed-torque controller's mass_scale, period and gains, a
payload on a MuJoCo plant; its model's queries refuse inputs beyond their
ceilings instead of returning NaN."""

from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import adaptimp
from adaptimp.baselines import ComputedTorque


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        (
            {"mass_scale": 1e300},
            "condition |value| ≤ 1e9 is violated: mass_scale = 1e300 (SPEC §10)",
        ),
        ({"Ts": 1e9}, "condition Ts ≤ 1 s is violated: Ts = 1000000000 (SPEC §10)"),
        ({"payload": 1e300}, "condition |value| ≤ 1e9 is violated: payload = 1e300 (SPEC §10)"),
        ({"Kp": 1e10}, "condition |value| ≤ 1e9 is violated: Kp[0] = 10000000000 (SPEC §10)"),
    ],
)
def test_a_computed_torque_model_that_would_overflow_is_refused(
    kw: dict[str, Any], message: str
) -> None:
    with pytest.raises(adaptimp.ConfigError) as e:
        ComputedTorque(**kw)
    assert str(e.value).endswith(message), str(e.value)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (([0, 0], [1e200, 0], [0, 0]), "dq[0] = 1e200 is beyond its limit ±1e6"),
        (([0, 0], [0, 0], [0, 1e7]), "ddq[1] = 1e7 is beyond its limit ±1e6"),
        (([1e300, 0], [0, 0], [0, 0]), "q[0] = 1e300 is beyond its limit ±1e6"),
    ],
)
def test_inverse_dynamics_refuses_inputs_whose_torque_would_not_be_finite(
    args: tuple[list[float], ...], message: str
) -> None:
    ct = ComputedTorque()
    with pytest.raises(adaptimp.MeasurementError) as e:
        ct.inverse_dynamics(*args)
    assert str(e.value).startswith(message)
    with pytest.raises(adaptimp.MeasurementError, match=r"^q\[1\] is not finite"):
        ct.inverse_dynamics([0, math.nan], [0, 0], [0, 0])
    tau = ct.inverse_dynamics([0.1, 0.2], [1e6, -1e6], [1e6, 0.0])
    assert np.isfinite(tau).all()


def test_a_payload_beyond_any_arm_is_refused_as_a_payload() -> None:
    from adaptimp import mujoco as amj

    with pytest.raises(adaptimp.ConfigError) as e:
        amj.simulate("pd", "two_link", T=0.01, payload=1e300)
    assert str(e.value) == "payload must be ≥ 0 and ≤ 1e9 kg, got 1e+300"


def test_a_model_without_actuators_gets_the_plants_motors(tmp_path: Any) -> None:
    """It said "Plant needs 1 to 7 joints, the model has 0"; then (the plant adds a
    motor where a joint has none) MuJoCo's "unknown transmission target '#0'" for
    unnamed joints: they are named, the motors added, τmax estimated and said."""
    from adaptimp import mujoco as amj

    path = tmp_path / "no_motors.xml"
    path.write_text(
        '<mujoco><worldbody><body><joint type="hinge"/><geom size=".1" mass="1"/>'
        '<body pos="0 0 .3"><joint type="hinge" axis="0 1 0"/><geom size=".1" mass="1"/>'
        "</body></body></worldbody></mujoco>"
    )
    with pytest.warns(adaptimp.PlantWarning) as seen:
        plant = amj.Plant(str(path))
    said = [str(w.message) for w in seen]
    assert (
        "no_motors.xml: the joints ['adaptimp_joint0', 'adaptimp_joint1'] have no actuator: "
        "the plant adds a torque motor to each"
    ) in [m[: m.index("each") + 4] for m in said if "each" in m], said
    assert plant.n == 2
    assert plant.joint_names == ["adaptimp_joint0", "adaptimp_joint1"]


@pytest.mark.parametrize(
    ("reference", "error", "message"),
    [
        (lambda t: (np.zeros(2), np.zeros(2)), ValueError,
         "reference(t) must return 3 arrays (xc, dxc, ddxc), got 2 values at t = 0"),
        (lambda t: np.zeros(2), ValueError,
         "reference(t) must return 3 arrays (xc, dxc, ddxc), got not a tuple at t = 0"),
        (lambda t: (np.zeros(3), np.zeros(2), np.zeros(2)), ValueError,
         "reference(t)'s xc must have shape (2,), got (3,) at t = 0"),
        (lambda t: (np.zeros(2), ["a", 0], np.zeros(2)), TypeError,
         "reference(t)'s dxc must be reals, got ['a', 0] at t = 0"),
    ],
)  # fmt: skip
def test_a_reference_of_the_wrong_shape_is_refused_by_name(
    reference: Any, error: type[Exception], message: str
) -> None:
    from adaptimp import mujoco as amj

    with pytest.raises(error) as e:  # a 2-tuple was an IndexError
        amj.simulate("pd", "two_link", T=0.01, reference=reference)
    assert str(e.value) == message


@pytest.mark.parametrize(
    ("name", "text", "message"),
    [
        ("a_free_body.xml",
         '<mujoco><worldbody><body><freejoint/><geom size=".1"/></body></worldbody></mujoco>',
         "a_free_body.xml: it has no hinge joint to drive (held: "
         "'adaptimp_joint0' a free joint: an arm's joints have one coordinate each): "
         "name a tip (tip=) to drive a slide joint"),
        ("nine.xml", None,
         "nine.xml: Plant needs 1 to 7 joints; the arm has 9 (j0, j1, j2, j3, j4, j5, j6, j7, "
         "j8): fix some with fix=(...) or name the arm's end with tip="),
    ],
)  # fmt: skip
def test_a_file_that_cannot_be_a_plant_is_named(
    name: str, text: str | None, message: str, tmp_path: Any
) -> None:
    from adaptimp import mujoco as amj

    if text is None:  # nine hinges in a chain, each with a motor
        inner = ""
        for i in reversed(range(9)):
            inner = (
                f'<body name="b{i}" pos="0 0 .1"><joint name="j{i}" type="hinge" axis="0 1 0"/>'
                f'<geom size=".05" mass="1"/>{inner}</body>'
            )
        motors = "".join(f'<motor joint="j{i}" ctrlrange="-5 5"/>' for i in range(9))
        text = f"<mujoco><worldbody>{inner}</worldbody><actuator>{motors}</actuator></mujoco>"
    (tmp_path / name).write_text(text)
    with pytest.raises(ValueError, match=f"^{re.escape(name)}: ") as e:
        amj.Plant(str(tmp_path / name))
    assert str(e.value) == message


def test_drive_that_is_not_a_bool_is_refused() -> None:
    """drive='yes' (or 1.5) was taken as True: the description's drive terms in
    the model, silently."""
    from adaptimp import mujoco as amj

    hobby = Path(__file__).parent / "data" / "hobby_arm.urdf"
    for drive in ("yes", 1.5, 1):
        with pytest.raises(TypeError, match=r"^drive must be True, False or None, got "):
            ComputedTorque(str(hobby), drive=drive, tau_max=5.0)
        with pytest.raises(TypeError, match=r"^drive must be True or False, got "):
            amj.from_urdf(hobby, drive=drive)
    assert ComputedTorque(str(hobby), drive=True, tau_max=5.0).drive["damping"][0] == 0.1


@pytest.mark.parametrize(
    ("attribute", "value", "moments"),
    [
        ("ixy", "5", "-5.000e0, 5.000e-5, 5.000e0"),
        ("ixx", "-0.01", "-1.000e-2, 5.000e-5, 5.000e-5"),
    ],
)
def test_an_inertia_no_rigid_body_has_is_refused_by_link_and_file(
    tmp_path: Path, attribute: str, value: str, moments: str
) -> None:
    """An inertia that is not positive semi-definite made M(q) indefinite
    (ixy = 5: its smallest eigenvalue −11.1) and was accepted; MuJoCo refuses
    such a file, unnamed. The core's reduction names the link and the file,
    and the arm's dynamics is refused with it, by computed torque and the
    plant alike (ixx < 0 was refused by the dynamics with no name); its
    kinematics, which the inertia plays no part in, reads (real files have
    such links: example-robot-data's Romeo's hips)."""
    from adaptimp import mujoco as amj

    hobby = Path(__file__).parent / "data" / "hobby_arm.urdf"
    text = hobby.read_text()
    found = list(re.finditer(rf'{attribute}="[^"]*"', text))[1]
    path = tmp_path / "bad_inertia.urdf"
    path.write_text(text[: found.start()] + f'{attribute}="{value}"' + text[found.end() :])
    for read in (ComputedTorque, amj.from_urdf):
        with pytest.raises(adaptimp.ConfigError) as e:
            read(path)
        message = str(e.value)
        assert message.startswith("URDF 'bad_inertia.urdf': link 'shoulder' has the inertia ")
        assert f"its principal moments are {moments} kg m², one negative" in message
    assert adaptimp.Chain.from_urdf(path).n == 5


def test_a_file_of_the_kinematics_alone_is_refused_by_every_front(tmp_path: Path) -> None:
    """SPEC (21.5): a URDF without one ``<inertial>`` on the arm (as
    robotics-toolbox-python's xacro ABB IRB140 and Puma 560 ship) compiled with
    MuJoCo's bounds into a 1e-6 kg arm that the rule tuned and the Cartesian
    task ran on. The plant, computed torque and the dynamics refuse it by
    name; its kinematics reads."""
    from adaptimp import mujoco as amj

    hobby = Path(__file__).parent / "data" / "hobby_arm.urdf"
    path = tmp_path / "kinematic.urdf"
    path.write_text(re.sub(r"<inertial>.*?</inertial>", "", hobby.read_text(), flags=re.S))
    for read in (ComputedTorque, amj.from_urdf, amj.Plant):
        with pytest.raises(
            adaptimp.ConfigError,
            match=r"^URDF 'kinematic\.urdf': no link the arm moves states a mass "
            r"\(<inertial>\): the file describes the arm's kinematics alone",
        ):
            read(path)
    assert adaptimp.Chain.from_urdf(path).n == 5


ARMATURE_ARM = """<mujoco model="wrist">
  <worldbody>
    <body name="upper">
      <joint name="j1" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03"/>
      <body name="hand" pos="0.3 0 0">
        <joint name="j2" type="hinge" axis="1 0 0"{armature}/>
        <inertial pos="0 0 0" mass="1e-9" diaginertia="1e-13 1e-13 1e-13"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="j1" ctrlrange="-10 10"/>
    <motor joint="j2" ctrlrange="-10 10"/>
  </actuator>
</mujoco>
"""


def test_a_last_joint_is_moved_by_its_armature_too(tmp_path: Path) -> None:
    """SPEC (21.5) counts the joint's armature (rotor inertia) with its link:
    dm_control's Jaco ends in a 1e-9 kg ring with ``armature="2"``, which
    MuJoCo's mass matrix and the core's dynamics both carry. Without the
    armature the same wrist moves nothing about its axis and is refused."""
    path = tmp_path / "wrist.xml"
    path.write_text(ARMATURE_ARM.format(armature=' armature="2"'))
    assert ComputedTorque(path).n == 2
    path.write_text(ARMATURE_ARM.format(armature=""))
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^MJCF 'wrist\.xml': the last arm joint 'j2' moves 1e-13 kg m² about its axis "
        r"\(less than 1e-9, its armature included\)",
    ):
        ComputedTorque(path)
