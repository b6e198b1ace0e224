"""Any arm, out of the box (SPEC §18, docs/your_arm.md): ``adaptimp.mujoco.simulate``
given only a URDF chooses a home posture, a default task, gains and a basis by
the rule, and the adaptive laws then track far better than PD with the same
gains, without drift, within the torque limits, and better than computed
torque with the nominal model once a payload nobody told the controller about
rides on the arm. The arms are the UR5 and the Panda of example-robot-data
(installed by the test extra) and a light servo arm with a gripper
(``tests/data/hobby_arm.urdf``); nothing is tuned per arm."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest

from adaptimp import _models, _sampled, _tasks
from adaptimp import mujoco as amj
from adaptimp._description import read_arm
from adaptimp.baselines import ComputedTorque, pinocchio_model
from adaptimp.baselines import with_payload as pin_payload

ROBOTS = _models.panda_urdf_path().parents[2]
UR5 = ROBOTS / "ur_description" / "urdf" / "ur5_robot.urdf"
PANDA = _models.panda_urdf_path()
HOBBY = Path(__file__).parent / "data" / "hobby_arm.urdf"
T = 10.0


def _targets(res: Any) -> dict[str, float]:
    """RMS ‖z1‖ over t ≥ 2 s, over [2, 4) and over the last 2 s, and the peak
    commanded |τ_i|/τmax_i after 0.1 s."""
    t, z = res.t, np.sum(res.z1**2, axis=1)

    def rms(a: float, b: float) -> float:
        return float(np.sqrt(np.mean(z[(t >= a - 1e-9) & (t < b - 1e-9)])))

    tau_max = np.asarray(res.params["tau_max"])
    assert np.all(np.abs(res.tau_sat) <= tau_max * (1 + 1e-12)), "applied torque within limits"
    return {
        "rms": res.metrics["rms_z1_after2"],
        "early": rms(2.0, 4.0),
        "late": rms(T - 2.0, T + 1.0),
        "peak": float(np.max(np.abs(res.tau[t >= 0.1]) / tau_max)),
    }


@pytest.fixture(scope="module", params=["ur5", "panda"])
def arm_runs(request: pytest.FixtureRequest) -> dict[str, Any]:
    path = {"ur5": UR5, "panda": PANDA}[request.param]
    return {case: amj.simulate(case, path, T=T) for case in ("pd", "sf", "of")}


def test_the_default_route_meets_the_targets(arm_runs: dict[str, Any]) -> None:
    m = {case: _targets(res) for case, res in arm_runs.items()}
    for case in ("sf", "of"):
        assert m[case]["rms"] <= 0.2 * m["pd"]["rms"], (case, m)  # SF, OF ≤ 0.2 × PD
        assert m[case]["late"] <= m[case]["early"], (case, m)  # no drift
    for case in m:
        assert m[case]["peak"] <= 2.0, (case, m)
    # The three ran the same task, with the rule's gains, from the same start.
    pd, sf = arm_runs["pd"], arm_runs["sf"]
    np.testing.assert_array_equal(pd.xc, sf.xc)
    assert pd.params["task"] == sf.params["task"]
    np.testing.assert_array_equal(pd.q[0], sf.xc[0])


def test_the_task_swings_about_a_home_posture_inside_the_limits() -> None:
    plant = amj.Plant(PANDA)
    task = amj.default_task(plant)
    lo, hi = _sampled._limits(plant.model, plant._joints)
    amp = -np.asarray(task.keywords["xc_cos"])
    assert np.all(amp == 0.2)
    assert np.all(task.home - amp >= lo - 1e-12)
    assert np.all(task.home + amp <= hi + 1e-12)
    np.testing.assert_array_equal(task.q0, task.home - amp)
    # The Panda's zero posture is outside joint 4's limits [−3.07, −0.07]: clipped.
    assert task.home[3] == pytest.approx(-0.0698 - 0.2, abs=1e-3)


def test_a_payload_nobody_told_the_controller_about() -> None:
    """UR5, 10 % of its moving mass at the last link: state feedback learns it
    and beats computed torque with the nominal model 5× over, and computed
    torque with the exact model beats SF (issue targets; the default gains of
    SPEC (20.8), the same for both models)."""
    nominal = amj.Plant(UR5)
    kg = 0.1 * amj.moving_mass(nominal.model)
    assert kg == pytest.approx(1.699, abs=1e-3)
    sf = amj.simulate("sf", UR5, T=T, payload=kg)
    pd = amj.simulate("pd", UR5, T=T, payload=kg)
    tau_max = sf.params["tau_max"]
    rms = {"sf": _targets(sf)["rms"], "pd": _targets(pd)["rms"]}
    for name, model_payload in (("ct_exact", kg), ("ct_nominal", 0.0)):
        ct = ComputedTorque(UR5, Ts=1e-3, tau_max=tau_max, payload=model_payload)
        res = amj.simulate(ct, UR5, T=T, reference=sf, q0=sf.q[0], payload=kg)
        np.testing.assert_array_equal(res.xc, sf.xc)  # the same task
        rms[name] = _targets(res)["rms"]
    assert rms["ct_exact"] <= rms["sf"] <= 0.2 * rms["ct_nominal"], rms
    assert rms["sf"] < 0.2 * rms["pd"], rms


def test_the_payload_is_the_same_point_mass_in_both_engines() -> None:
    """MuJoCo's plant with a payload against Pinocchio's model with the same
    point mass: D(q) and C(q, q̇) q̇ + G(q) agree to 1e-9 over random states."""
    kg = 1.5
    plant = amj.Plant(amj.with_payload(amj.Plant(UR5).model, kg))
    model = pin_payload(pinocchio_model(UR5), kg)
    data = model.createData()
    rng = np.random.default_rng(22)
    for _ in range(20):
        q, dq = rng.uniform(-3.0, 3.0, 6), rng.uniform(-2.0, 2.0, 6)
        plant.reset(q, dq)
        m = pin.crba(model, data, q)
        np.testing.assert_allclose(plant.mass_matrix(), np.triu(m) + np.triu(m, 1).T, atol=1e-9)
        bias = pin.rnea(model, data, q, dq, np.zeros(6))
        np.testing.assert_allclose(plant.bias(), bias, atol=1e-9)
    # The plant's mass grew by the payload; the nominal model's did not.
    assert amj.moving_mass(plant.model) == pytest.approx(amj.moving_mass(amj.from_urdf(UR5)) + kg)


def test_a_light_servo_arm_with_a_gripper(recwarn: pytest.WarningsRecorder) -> None:
    """Five revolute joints (one continuous, without an effort limit), a
    revolute jaw and a mimic finger fixed, light links, servos of 1–2.5 N m."""
    arm = read_arm(HOBBY)
    assert arm.joints == ("base_yaw", "shoulder_pitch", "elbow_pitch", "wrist_pitch", "wrist_roll")
    assert arm.fixed == {
        "gripper_jaw": "drives a gripper ('finger' mimic it)",
        "finger": "mimics 'gripper_jaw': it moves with 'gripper_jaw', not on its own",
    }
    with pytest.warns(UserWarning, match=r"no effort limit for \['wrist_roll'\]"):
        model = amj.from_urdf(HOBBY)
    plant = amj.Plant(model)
    assert plant.tau_max[:4].tolist() == [2.5, 2.5, 2.5, 1.0]
    assert 0 < plant.tau_max[4] < 0.1
    runs = {case: amj.simulate(case, model, T=T) for case in ("pd", "sf")}
    m = {case: _targets(res) for case, res in runs.items()}
    assert m["sf"]["rms"] <= 0.2 * m["pd"]["rms"], m
    assert m["sf"]["late"] <= m["sf"]["early"], m
    assert max(v["peak"] for v in m.values()) <= 2.0, m


def _edited(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_weak_or_missing_effort_limits(tmp_path: Path) -> None:
    text = UR5.read_text()

    def scaled(f: float) -> str:
        return re.sub(r'effort="([0-9.]+)"', lambda m: f'effort="{float(m[1]) * f:g}"', text)

    # Gravity takes more than half of the limits at the zero posture: the home
    # posture is the one of least load among the samples, and it is lighter.
    weak = amj.Plant(_edited(tmp_path, "weak.urdf", scaled(0.3)))
    zero_load = max(_tasks._gravity_load(weak, np.array([0, 0, 0, 0, s * 0.2, 0])) for s in (-1, 1))
    home = amj.home_posture(weak)
    assert np.any(home != 0.0)
    assert _tasks._gravity_load(weak, home) < 0.5 < zero_load
    # Nowhere to hold itself: a clear error.
    with pytest.raises(ValueError, match="gravity exceeds the effort limits at every posture"):
        amj.home_posture(amj.Plant(_edited(tmp_path, "feeble.urdf", scaled(0.001))))
    # No effort limits at all: estimated, with a warning.
    none = re.sub(r' effort="[0-9.]+"', "", text)
    with pytest.warns(UserWarning, match="the URDF gives no effort limit"):
        plant = amj.Plant(amj.from_urdf(_edited(tmp_path, "none.urdf", none)))
    assert np.all(plant.tau_max > 0)


def test_references_as_arrays_must_cover_the_run() -> None:
    res = amj.simulate("pd", UR5, T=0.05)
    ct = ComputedTorque(UR5, Ts=1e-3, tau_max=res.params["tau_max"])
    again = amj.simulate(ct, UR5, T=0.05, reference=(res.xc, res.dxc, res.ddxc))
    np.testing.assert_array_equal(again.xc, res.xc)
    np.testing.assert_array_equal(again.q[0], res.xc[0])  # no keyframe: xc(0)
    with pytest.raises(ValueError, match=r"K ≥ 60 rows"):
        amj.simulate(ct, UR5, T=0.06, reference=res)
    with pytest.raises(TypeError, match="reference must be a callable"):
        amj.simulate(ct, UR5, T=0.05, reference=3.0)


def _urdf(joints: list[tuple[str, str, str, str, str]]) -> str:
    """A URDF of unit boxes: (name, type, parent, child, limits) per joint."""
    links = {"root"} | {j[3] for j in joints}
    inertial = (
        '<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" '
        'iyz="0" izz="0.01"/></inertial>'
    )
    out = ['<robot name="t">']
    out += [f'<link name="{name}">{inertial}</link>' for name in sorted(links)]
    for name, kind, parent, child, limits in joints:
        out.append(
            f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
            f'<origin xyz="0 0 0.1"/><axis xyz="0 1 0"/>{limits}</joint>'
        )
    return "".join([*out, "</robot>"])


LIM = '<limit lower="-2" upper="2" effort="10" velocity="1"/>'


def test_the_arm_of_a_urdf_is_its_serial_chain() -> None:
    # An arm of three joints holding a hand of two 2-joint fingers: the arm
    # ends at the hand (each finger is shorter than the arm).
    arm = [("a1", "revolute", "root", "l1", LIM), ("a2", "revolute", "l1", "l2", LIM)]
    arm.append(("a3", "revolute", "l2", "palm", LIM))
    hand = [
        ("f1a", "revolute", "palm", "f1", LIM),
        ("f1b", "revolute", "f1", "f1t", LIM),
        ("f2a", "revolute", "palm", "f2", LIM),
        ("f2b", "revolute", "f2", "f2t", LIM),
    ]
    a = read_arm(_urdf(arm + hand))
    assert a.joints == ("a1", "a2", "a3")
    assert a.tip == "palm"
    assert a.fixed == dict.fromkeys(
        ("f1a", "f1b", "f2a", "f2b"),
        "in the hand at 'palm' (branches of joints start there: two or more each shorter "
        "than the arm, or three or more none longer)",
    )
    # A torso of one joint with two arms of three: the chain goes on along an
    # arm (the arms are longer than the torso), but the two tie: which one is
    # the user's to say (tip=); the other is then fixed.
    body = [("t", "revolute", "root", "torso", LIM)]
    for side in ("l", "r"):
        parent = "torso"
        for k in range(3):
            body.append((f"{side}{k}", "revolute", parent, f"{side}{k}link", LIM))
            parent = f"{side}{k}link"
    with pytest.raises(ValueError, match=r"2 serial chains of 4 joints .* 'l2link', 'r2link'"):
        read_arm(_urdf(body))
    a = read_arm(_urdf(body), tip="l2link")
    assert a.joints == ("t", "l0", "l1", "l2")
    assert a.fixed == dict.fromkeys(("r0", "r1", "r2"), "not on the way to 'l2link'")
    # A robot that is itself a finger keeps its joints; limits of "0 0" mean
    # none (a continuous joint); no effort limit is NaN.
    finger = [
        ("finger_1", "revolute", "root", "l1", '<limit lower="0" upper="0" effort="1"/>'),
        ("finger_2", "revolute", "l1", "l2", '<limit lower="-1" upper="1"/>'),
    ]
    a = read_arm(_urdf(finger))
    assert a.joints == ("finger_1", "finger_2")
    assert a.lower[0] == -np.inf
    assert a.upper[0] == np.inf
    assert np.isnan(a.effort[1])
    with pytest.raises(ValueError, match="no revolute or continuous joint to drive"):
        read_arm(_urdf([("s", "prismatic", "root", "l1", LIM)]))
