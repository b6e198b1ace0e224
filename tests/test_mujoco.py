"""MuJoCo as the plant (adaptimp.mujoco): the packaged 2-link model against SPEC §1,
the plant's checks and force measurement, and the closed loop against the core's
own simulator."""

from __future__ import annotations

import importlib
import importlib.resources
import sys

import mujoco
import numpy as np
import pytest

import adaptimp
from adaptimp import _models
from adaptimp import mujoco as amj

RNG_SEED = 20160301


@pytest.fixture(scope="module")
def two_link() -> mujoco.MjModel:
    return amj.two_link()


def test_two_link_xml_is_packaged_data() -> None:
    xml = importlib.resources.files("adaptimp") / "models" / "two_link.xml"
    assert xml.is_file()
    assert _models.TWO_LINK_XML.is_file()


def test_two_link_xml_has_the_paper_parameters(two_link: mujoco.MjModel) -> None:
    m = two_link
    p = adaptimp.TwoLinkArm().params
    link1, link2 = m.body("link1").id, m.body("link2").id
    assert m.body_mass[[link1, link2]] == pytest.approx([p["m1"], p["m2"]], abs=1e-15)
    assert m.body_ipos[link1] == pytest.approx([p["lc1"], 0, 0], abs=1e-15)
    assert m.body_ipos[link2] == pytest.approx([p["lc2"], 0, 0], abs=1e-15)
    assert m.body_pos[link2] == pytest.approx([p["l1"], 0, 0], abs=1e-15)
    assert m.body_pos[m.body("end_effector").id] == pytest.approx([p["l2"], 0, 0], abs=1e-15)
    # The inertia about the hinge axis (body y) is the paper's I about the centre.
    assert m.body_inertia[link1, 1] == pytest.approx(p["I1"], abs=1e-15)
    assert m.body_inertia[link2, 1] == pytest.approx(p["I2"], abs=1e-15)
    assert m.opt.gravity == pytest.approx([0, 0, -p["g"]], abs=1e-15)
    tau_max = adaptimp._adaptimp.defaults("paper")["tau_max"]
    assert m.actuator_ctrlrange.tolist() == [[-tau_max[0], tau_max[0]], [-tau_max[1], tau_max[1]]]
    assert m.actuator_gear[:, 0].tolist() == [1.0, 1.0]
    # Nothing extra: no damping, armature, friction loss, springs.
    for arr in (m.dof_damping, m.dof_armature, m.dof_frictionloss, m.jnt_stiffness):
        assert not np.any(arr)
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4
    assert m.opt.timestep == adaptimp._adaptimp.defaults("paper")["Ts"]
    assert m.key("paper").qpos.tolist() == adaptimp._adaptimp.defaults("paper")["q0"]


def test_two_link_dynamics_are_the_papers(two_link: mujoco.MjModel) -> None:
    """MuJoCo's D(q) and C(q, q̇) q̇ + G(q) are SPEC §1's, to 1e-12, over random states."""
    arm = adaptimp.TwoLinkArm()
    plant = amj.Plant(two_link)
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(200):
        q, dq = rng.uniform(-np.pi, np.pi, 2), rng.uniform(-10.0, 10.0, 2)
        plant.reset(q, dq)
        np.testing.assert_allclose(plant.mass_matrix(), arm.D(q), rtol=0, atol=1e-12)
        bias = arm.C(q, dq) @ dq + arm.G(q)
        np.testing.assert_allclose(plant.bias(), bias, rtol=0, atol=1e-12)


def test_plant_reads_limits_and_sensor(two_link: mujoco.MjModel) -> None:
    plant = amj.Plant(two_link)
    assert plant.n == 2
    assert plant.tau_max.tolist() == [17.0, 15.0]
    assert plant.wrench_source == "sensor"
    # q(0) from the keyframe; the end effector at forward kinematics.
    np.testing.assert_array_equal(plant.q, [0.25, -0.05])
    p = adaptimp.TwoLinkArm().params
    x = p["l1"] * np.cos(0.25) + p["l2"] * np.cos(0.2)
    z = p["l1"] * np.sin(0.25) + p["l2"] * np.sin(0.2)
    np.testing.assert_allclose(plant.ee_position(), [x, 0.0, z], atol=1e-15)
    # Saturation is the actuators'.
    np.testing.assert_array_equal(plant.apply([100.0, -100.0]), [17.0, -15.0])
    # Free space: the sensor reads exactly zero.
    np.testing.assert_array_equal(plant.tau_e(), [0.0, 0.0])


def _push_into_wall(plant: amj.Plant, target: list[float]) -> np.ndarray:
    """Press the end effector against the ceiling: gravity compensation and a
    joint PD towards ``target`` (rad, beyond the wall), until at rest. Returns the
    torque applied at rest (N m)."""
    arm = adaptimp.TwoLinkArm()
    plant.timestep = 1e-4
    plant.reset([0.1, 0.1])
    for _ in range(20_000):
        plant.apply(arm.G(plant.q) + 20.0 * (np.array(target) - plant.q) - 3.0 * plant.dq)
        plant.step()
    tau = plant.apply(arm.G(plant.q) + 20.0 * (np.array(target) - plant.q))
    plant.forward()
    return tau


def test_wall_force_balances_the_dynamics(two_link: mujoco.MjModel) -> None:
    """Against the wall, (4) gives τe = τ − D q̈ − C q̇ − G: the sensor's Jᵀ F_e
    does, to rounding (the sensor's body is massless); nearly at rest, τ − G."""
    plant = amj.Plant(two_link)
    tau = _push_into_wall(plant, [0.4, 0.2])
    assert plant.data.ncon == 1
    arm = adaptimp.TwoLinkArm()
    q, dq, ddq = plant.q, plant.dq, plant.ddq
    assert np.max(np.abs(dq)) < 1e-4  # resting (soft contact creeps slowly)
    expected = tau - arm.D(q) @ ddq - arm.C(q, dq) @ dq - arm.G(q)
    np.testing.assert_allclose(plant.tau_e(), expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(plant.tau_e(), tau - arm.G(q), rtol=0, atol=1e-3)
    # The arm pushes the ceiling up, by several newtons.
    assert plant.wrench()[2] > 1.0


def test_sensor_and_contact_forces_agree(two_link: mujoco.MjModel) -> None:
    plant = amj.Plant(two_link)
    _push_into_wall(plant, [0.5, 0.0])
    np.testing.assert_allclose(plant.sensor_wrench(), plant.contact_wrench(), rtol=0, atol=1e-9)
    # A model without sensors measures through the contacts.
    spec = mujoco.MjSpec.from_file(str(_models.TWO_LINK_XML))
    for sensor in list(spec.sensors):
        spec.delete(sensor)
    bare = amj.Plant(spec.compile())
    assert bare.wrench_source == "contact"
    with pytest.raises(ValueError, match="no force sensor"):
        bare.sensor_wrench()


def _mjcf(body: str, actuators: str = "") -> mujoco.MjModel:
    xml = f"""<mujoco><worldbody>{body}</worldbody><actuator>{actuators}</actuator></mujoco>"""
    return mujoco.MjModel.from_xml_string(xml)


_LINK = '<body><joint name="{n}" type="{t}"/><geom size="0.1" mass="1"/>{inner}</body>'


def _chain(n: int, kind: str = "hinge") -> str:
    body = ""
    for i in reversed(range(n)):
        body = _LINK.format(n=f"j{i}", t=kind if i == n - 1 else "hinge", inner=body)
    return body


def _motors(n: int, extra: str = 'ctrlrange="-1 1"') -> str:
    return "".join(f'<motor joint="j{i}" {extra}/>' for i in range(n))


def test_plant_rejects_models_it_cannot_drive() -> None:
    with pytest.raises(ValueError, match=r"hinge joints only; not hinges: j1 \(mjJNT_SLIDE\)"):
        amj.Plant(_mjcf(_chain(2, "slide"), _motors(2)))
    with pytest.raises(ValueError, match="1 to 7 joints, the model has 8"):
        amj.Plant(_mjcf(_chain(8), _motors(8)))
    with pytest.raises(ValueError, match="joint 'j1' has 0"):
        amj.Plant(_mjcf(_chain(2), '<motor joint="j0" ctrlrange="-1 1"/>'))
    with pytest.raises(ValueError, match="'a' is not a torque actuator"):
        amj.Plant(_mjcf(_chain(1), '<position name="a" joint="j0" ctrlrange="-1 1"/>'))
    with pytest.raises(ValueError, match=r"symmetric ctrlrange .* \[-1, 2\]"):
        amj.Plant(_mjcf(_chain(1), '<motor joint="j0" ctrlrange="-1 2"/>'))
    with pytest.raises(ValueError, match="symmetric ctrlrange"):
        amj.Plant(_mjcf(_chain(1), '<motor joint="j0"/>'))  # unlimited
    branches = _LINK.format(n="j0", t="hinge", inner="") + _LINK.format(n="j1", t="hinge", inner="")
    with pytest.raises(ValueError, match="serial chain"):
        amj.Plant(_mjcf(branches, _motors(2)))
    with pytest.raises(ValueError, match=r"no file 'nowhere\.xml'"):
        amj.Plant("nowhere.xml")


def test_a_urdf_arm_is_its_chain_with_the_gripper_fixed() -> None:
    path = _models.panda_urdf_path()
    arm = _models.arm_urdf(path.read_text())
    assert arm.joints == _models.PANDA_JOINTS
    assert arm.effort == _models.PANDA_EFFORT
    assert arm.tip == "panda_link7"
    prismatic = "prismatic (the arm's joints are revolute)"
    assert arm.fixed == dict.fromkeys(_models.PANDA_FINGERS, prismatic)
    plant = amj.Plant(path)
    assert plant.n == 7
    assert plant.tau_max.tolist() == list(_models.PANDA_EFFORT)
    # The plant itself still refuses a slide joint, by name.
    spec, effort = amj._urdf_spec(path.read_text())
    amj._add_motors(spec, effort)
    with pytest.raises(ValueError, match=r"panda_finger_joint1 \(mjJNT_SLIDE\)"):
        amj.Plant(spec.compile())


def test_import_error_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "mujoco", None)
    monkeypatch.delitem(sys.modules, "adaptimp.mujoco")
    with pytest.raises(ImportError, match=r"pip install adaptimp\[mujoco\]"):
        importlib.import_module("adaptimp.mujoco")


# ---------------------------------------------------------------------------
# The closed loop, against the core's simulator (SPEC §11) in free space.
# ---------------------------------------------------------------------------


def _compare_metrics(got: dict[str, object], want: dict[str, object], rel: float) -> None:
    assert set(got) == set(want)
    for key, value in want.items():
        assert got[key] == pytest.approx(value, rel=rel, abs=1e-15), key


def test_pd_matches_the_core_simulator_row_by_row() -> None:
    """The paper's PD in free space: MuJoCo's RK4 at Ts = 50 µs is the core's RK4
    (one substep), so the runs agree to rounding (measured 6e-17 rad, 7e-15 N m)."""
    T = 2.5
    got = amj.simulate("pd", "two_link", T=T, scenario="paper", contact=False)
    want = adaptimp.simulate("pd", T=T, wall=None)
    assert got.params["substeps"] == 1
    assert got.rows == want.rows == 50_000
    np.testing.assert_array_equal(got.t, want.t)
    for name in ("q", "dq", "z1", "xd"):
        np.testing.assert_allclose(getattr(got, name), getattr(want, name), rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.tau_sat, want.tau_sat, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(got.xc, want.xc)
    _compare_metrics(got.metrics, want.metrics, rel=1e-9)
    assert got.metrics["steps_in_contact"] == 0


def test_robot_state_feedback_matches_the_core_simulator() -> None:
    """The adaptive controller at 1 kHz, 10 RK4 substeps in both: the same to
    rounding over 3 s (measured 2e-16 rad); its tracking after 2 s is ~1e-3 rad."""
    T = 3.0
    got = amj.simulate("sf", "two_link", T=T, substeps=10, contact=False)
    want = adaptimp.simulate("sf", scenario="robot", T=T, wall=None)
    assert got.params["timestep"] == pytest.approx(1e-4)
    np.testing.assert_allclose(got.q, want.q, rtol=0, atol=1e-10)
    _compare_metrics(got.metrics, want.metrics, rel=1e-7)
    assert got.metrics["rms_z1_after2"] < 2e-3


def test_paper_state_feedback_metrics_match_the_core_simulator() -> None:
    """The paper's state feedback is chaotic (SPEC §12): runs that differ at
    rounding part by ~1e-6 rad within 2.5 s, so compare metrics (measured
    relative differences ≤ 2e-3 for the 'after2' figures at T = 2.5 s)."""
    T = 2.5
    got = amj.simulate("sf", "two_link", T=T, scenario="paper", contact=False)
    want = adaptimp.simulate("sf", T=T, wall=None)
    for key in ("rms_z1", "sat_duty", "peak_abs_tau"):
        assert got.metrics[key] == pytest.approx(want.metrics[key], rel=1e-6), key
    for key in ("rms_z1_after2", "rms_z1_joint_after2", "imp_err_rms_after2"):
        assert got.metrics[key] == pytest.approx(want.metrics[key], rel=1e-2), key
    assert got.metrics["rms_z1_after2"] < 1e-3


def test_the_wall_is_felt_through_the_sensor() -> None:
    res = amj.simulate("sf", "two_link", T=3.0, contact=True)
    m = res.metrics
    assert res.params["wrench_source"] == "sensor"
    assert 0 < m["steps_in_contact"] < res.rows
    assert m["mean_contact"] > 0.1
    # τe = Jᵀ F_e row by row, and the arm pushes the ceiling up (F_e,z ≥ 0).
    assert np.all(res.wrench_ee[:, 2] >= -1e-9)
    in_contact = np.any(res.tau_e != 0, axis=1)
    assert np.all(res.x_ee[in_contact, 2] > 0.18)
    # The compliant reference gives way where the wall pushes back.
    assert np.max(np.abs(res.xd - res.xc)[in_contact]) > 1e-3
    assert np.isfinite(m["rms_z1_after2"])


class _Hold:
    """The smallest controller: a constant torque, a period, nothing else."""

    ts = 1e-3

    def __init__(self, tau: list[float]) -> None:
        self.tau_cmd = np.array(tau)
        self.calls: list[dict[str, object]] = []

    def step(self, q: object, tau_e: object, dq: object = None, **setpoint: object) -> np.ndarray:
        self.calls.append(setpoint)
        return self.tau_cmd


def test_any_controller_object_runs_and_gets_the_reference() -> None:
    ctrl = _Hold([0.0, 0.0])
    res = amj.simulate(ctrl, "two_link", T=0.01, q0=[0.0, 0.0], reference=amj.paper_circle())
    assert res.rows == 10
    assert set(ctrl.calls[0]) == {"xc", "dxc", "ddxc"}
    np.testing.assert_allclose(ctrl.calls[3]["xc"], amj.paper_circle()(0.003)[0])
    # Zero torque from rest: the arm falls (q1 decreases), nothing is saturated.
    assert res.q[-1, 0] < 0
    assert res.metrics["sat_duty"] == 0.0
    np.testing.assert_array_equal(res.z1, res.xc - res.q)
    # Without a reference, no setpoint is passed.
    ctrl = _Hold([0.0, 0.0])
    amj.simulate(ctrl, "two_link", T=0.003)
    assert ctrl.calls == [{}, {}, {}]
    with pytest.raises(ValueError, match="differs from the controller's period"):
        amj.simulate(_Hold([0.0, 0.0]), "two_link", T=0.01, Ts=5e-5)
    with pytest.raises(TypeError, match="apply to a case name only"):
        amj.simulate(_Hold([0.0, 0.0]), "two_link", T=0.01, Kp=3.0)


def test_result_plots(close_figures: None) -> None:
    from matplotlib.figure import Figure

    res = amj.simulate("sf", "two_link", T=0.2)
    for kind in amj.PLOT_KINDS:
        assert isinstance(res.plot(kind), Figure)
    with pytest.raises(ValueError, match="kind must be one of"):
        res.plot("bode")
    assert "MujocoResult" in repr(res)


def test_module_examples_run() -> None:
    import doctest

    assert doctest.testmod(amj, raise_on_error=False).failed == 0


def test_mujoco_result_is_a_sim_result() -> None:
    """adaptimp.mujoco.simulate returns a SimResult: the same metrics, pandas, plots."""
    res = amj.simulate("pd", "two_link", T=0.05, contact=False)
    assert isinstance(res, adaptimp.SimResult)
    assert res.case == "pd"
    assert set(adaptimp._result.METRIC_KEYS) <= set(res.metrics)
    df = res.to_pandas()
    assert "q1 [rad]" in df.columns
    assert res.x_ee is not None
    assert res.x_ee.shape == (50, 3)
