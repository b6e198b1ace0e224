"""MuJoCo as the plant (adaptimp.mujoco): the packaged 2-link model against SPEC §1,
the plant's checks and force measurement, and the closed loop against the core's
own simulator."""

from __future__ import annotations

import importlib
import importlib.resources
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

import adaptimp
from adaptimp import _models, _plant, _plant_models
from adaptimp import mujoco as amj
from adaptimp._contacts import WATCH
from adaptimp._description import read_arm
from mujoco_probe import contact_list_wrench, measure, push

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
    row = measure(plant, [100.0, -100.0])
    assert row.x_ee is not None
    np.testing.assert_allclose(row.x_ee[0], [x, 0.0, z], atol=1e-15)
    # Saturation is the actuators'.
    np.testing.assert_array_equal(row.tau_sat[0], [17.0, -15.0])
    np.testing.assert_array_equal(row.tau[0], [100.0, -100.0])
    # Free space: the sensor reads exactly zero.
    np.testing.assert_array_equal(row.tau_e[0], [0.0, 0.0])


def _push_into_wall(plant: amj.Plant, target: list[float]) -> np.ndarray:
    """Press the end effector against the ceiling: gravity compensation and a
    joint PD towards ``target`` (rad, beyond the wall), until at rest. Returns the
    torque applied at rest (N m)."""
    return push(plant, target, adaptimp.TwoLinkArm().G)


def test_wall_force_balances_the_dynamics(two_link: mujoco.MjModel) -> None:
    """Against the wall, (4) gives τe = τ − D q̈ − C q̇ − G: the core's Jᵀ F_e
    from the sensor does, to rounding (the sensor's body is massless); nearly
    at rest, τ − G."""
    plant = amj.Plant(two_link)
    tau = _push_into_wall(plant, [0.4, 0.2])
    assert plant.data.ncon == 1
    arm = adaptimp.TwoLinkArm()
    row = measure(plant, tau)
    q, dq, ddq, tau_e = row.q[0], row.dq[0], row.ddq[0], row.tau_e[0]
    assert np.max(np.abs(dq)) < 1e-4  # resting (soft contact creeps slowly)
    expected = tau - arm.D(q) @ ddq - arm.C(q, dq) @ dq - arm.G(q)
    np.testing.assert_allclose(tau_e, expected, rtol=0, atol=1e-9)
    np.testing.assert_allclose(tau_e, tau - arm.G(q), rtol=0, atol=1e-3)
    # The arm pushes the ceiling up, by several newtons.
    assert row.wrench_ee is not None
    assert row.wrench_ee[0, 2] > 1.0


def _bare() -> mujoco.MjSpec:
    """The paper's arm without its sensors."""
    spec = mujoco.MjSpec.from_file(str(_models.TWO_LINK_XML))
    for sensor in list(spec.sensors):
        spec.delete(sensor)
    return spec


def test_sensor_and_contact_forces_agree(two_link: mujoco.MjModel) -> None:
    """The force/torque sensor the core reads and MuJoCo's contact list agree;
    so do, on a model without sensors, the contact forces the core reads from
    the bodies of the end effector's subtree (MuJoCo's cfrc_ext)."""
    plant = amj.Plant(two_link)
    tau = _push_into_wall(plant, [0.5, 0.0])
    listed = contact_list_wrench(plant)
    sensed = measure(plant, tau).wrench_ee
    assert sensed is not None
    np.testing.assert_allclose(sensed[0], listed, rtol=0, atol=1e-9)
    assert listed[2] > 1.0
    # A model without sensors measures through the contacts.
    bare = amj.Plant(_bare().compile())
    assert bare.wrench_source == "contact"
    tau = _push_into_wall(bare, [0.5, 0.0])
    listed = contact_list_wrench(bare)
    summed = measure(bare, tau)
    assert summed.wrench_ee is not None
    assert summed.params["loop"] == "callback"
    np.testing.assert_allclose(summed.wrench_ee[0], listed, rtol=0, atol=1e-12)
    assert listed[2] > 1.0


def test_a_files_model_without_force_sensor_gets_a_contact_sensor(
    tmp_path: Path, two_link: mujoco.MjModel
) -> None:
    """An MJCF file without a force sensor whose end effector can touch something:
    Plant adds a contact sensor (the net contact wrench on the end effector's
    subtree), whose wrench is the contact list's to rounding; a controller
    native and called back give the same bits on it. The same model as an
    MjModel (it cannot be rebuilt with a sensor) is measured through the
    external forces on the end effector's bodies, the same to rounding."""
    spec = _bare()
    path = tmp_path / "bare.xml"
    path.write_text(spec.to_xml())
    plant = amj.Plant(path)
    assert plant.wrench_source == "contact sensor"
    names = [plant.model.sensor(s).name for s in range(plant.model.nsensor)]
    assert [n for n in names if not n.startswith(WATCH)] == [_plant._CONTACT_SENSOR]
    tau = _push_into_wall(plant, [0.5, 0.0])
    listed = contact_list_wrench(plant)
    sensed = measure(plant, tau).wrench_ee
    assert sensed is not None
    np.testing.assert_allclose(sensed[0], listed, rtol=0, atol=1e-12)
    assert listed[2] > 1.0
    native = amj.simulate(adaptimp.Controller("sf", "robot"), path, T=2.0)
    python = amj.simulate(_InPython(adaptimp.Controller("sf", "robot")), path, T=2.0)
    assert native.params["loop"] == "native"
    assert python.params["loop"] == "callback"
    _assert_same_run(native, python)
    assert native.metrics["steps_in_contact"] > 100
    same = mujoco.MjModel.from_xml_path(str(path))
    listed_run = amj.simulate(adaptimp.Controller("sf", "robot"), same, T=2.0)
    assert listed_run.params["wrench_source"] == "contact"
    assert listed_run.params["loop"] == "native"
    # The sensor and the bodies' external forces sum the same contact forces
    # in another order: the runs part at rounding (measured over these 2 s:
    # q 1e-15 rad, the wrench 1.6e-9 N of 8 N).
    np.testing.assert_allclose(listed_run.q, native.q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(listed_run.wrench_ee, native.wrench_ee, rtol=0, atol=1e-8)
    assert listed_run.metrics["steps_in_contact"] == native.metrics["steps_in_contact"]
    # Explicit contact pairs could collide geoms of the subtree with each other,
    # which the sensor would count and the contact list skips: the list stays.
    spec.add_pair(geomname1="ee", geomname2="wall")
    paired = tmp_path / "paired.xml"
    paired.write_text(spec.to_xml())
    assert amj.Plant(paired).wrench_source == "contact"
    assert amj.Plant(two_link).wrench_source == "sensor"


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
    """A compiled MjModel cannot be edited: what a file's plant would lock or
    add is refused by name, with what to do (adaptimp._mjcf; test_mjcf.py
    has the files)."""
    with pytest.raises(ValueError, match=r"joints \['j1'\] of the arm's body tree are not the arm"):
        amj.Plant(_mjcf(_chain(2, "slide"), _motors(2)))
    with pytest.raises(
        ValueError, match=r"1 to 7 joints; the arm has 8 \(j0, j1, .*fix=\(\.\.\.\)"
    ):
        amj.Plant(_mjcf(_chain(8), _motors(8)))
    with pytest.raises(ValueError, match=r"joint 'j1' has 0 actuators: .* the file's path"):
        amj.Plant(_mjcf(_chain(2), '<motor joint="j0" ctrlrange="-1 1"/>'))
    with pytest.raises(ValueError, match="the position actuator of joint 'j0' declares no force"):
        amj.Plant(_mjcf(_chain(1), '<position name="a" joint="j0" ctrlrange="-1 1"/>'))
    with pytest.raises(ValueError, match=r"ctrlrange of motor '#0' is \[-1, 2\]: .* symmetric"):
        amj.Plant(_mjcf(_chain(1), '<motor joint="j0" ctrlrange="-1 2"/>'))
    with pytest.raises(ValueError, match="the motor of joint 'j0' declares no force range"):
        amj.Plant(_mjcf(_chain(1), '<motor joint="j0"/>'))  # unlimited
    branches = _LINK.format(n="j0", t="hinge", inner="") + _LINK.format(n="j1", t="hinge", inner="")
    with pytest.raises(ValueError, match=r"2 serial chains of 1 joints from the root tie .* tip="):
        amj.Plant(_mjcf(branches, _motors(2)))
    with pytest.raises(FileNotFoundError, match=r"no file 'nowhere\.xml'"):
        amj.Plant("nowhere.xml")


def test_a_urdf_arm_is_its_chain_with_the_gripper_fixed() -> None:
    path = _models.panda_urdf_path()
    arm = read_arm(path)
    assert arm.joints == _models.PANDA_JOINTS
    assert arm.effort == _models.PANDA_EFFORT
    assert arm.tip == "panda_link7"
    finger1, finger2 = _models.PANDA_FINGERS
    assert arm.fixed == {
        finger1: "in the hand at 'panda_hand' (branches of joints start there: two or more "
        "each shorter than the arm, or three or more none longer)",
        finger2: f"mimics '{finger1}': it moves with '{finger1}', not on its own",
    }
    plant = amj.Plant(path)
    assert plant.n == 7
    assert plant.tau_max.tolist() == list(_models.PANDA_EFFORT)
    # A compiled model with a finger's slide (the chain to a finger drives
    # it: tip= names the path) cannot lock it: refused by name; its spec (the
    # same model, editable) is locked in memory.
    finger = read_arm(path, tip="panda_leftfinger")
    assert finger.joints == (*_models.PANDA_JOINTS, finger1)
    assert finger.urdf is not None
    spec = _plant_models.spec_of(finger.urdf)
    _plant_models.add_motors(spec, dict(zip(finger.joints, finger.effort)))
    with pytest.raises(ValueError, match=r"\['panda_finger_joint1'\]"):
        amj.Plant(spec.compile())
    with pytest.warns(adaptimp.PlantWarning, match="the plant locks them at their reference"):
        locked = amj.Plant(spec)
    assert locked.joint_names == list(_models.PANDA_JOINTS)


def test_import_error_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "mujoco", None)
    monkeypatch.delitem(sys.modules, "adaptimp.mujoco")
    with pytest.raises(ImportError, match=r'pip install "\.\[mujoco\]" from a checkout, pip inst'):
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

    Ts = 1e-3

    def __init__(self, tau: list[float]) -> None:
        self.tau_cmd = np.array(tau)
        self.calls: list[dict[str, object]] = []

    def step(self, m: object, **setpoint: object) -> np.ndarray:
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


# ---------------------------------------------------------------------------
# The native loop (SPEC §13.1): the core's loop, recorder and metrics.
# ---------------------------------------------------------------------------


class _InPython:
    """An adaptimp.Controller behind a Python object: the core's loop calls its
    Python ``step`` back once a period."""

    def __init__(self, inner: adaptimp.Controller) -> None:
        self.inner = inner
        self.Ts = inner.Ts
        self.params = inner.params

    def step(self, m: object, **sp: object) -> np.ndarray:
        return self.inner.step(m, **sp)

    def __getattr__(self, name: str) -> object:
        return getattr(self.inner, name)


_ARRAYS = (
    "t", "q", "dq", "ddq", "xc", "dxc", "ddxc", "xd", "dq_hat", "tau", "tau_sat", "tau_e",
    "zeta", "z1", "x_ee", "wrench_ee",
)  # fmt: skip


def _assert_same_run(got: amj.MujocoResult, want: amj.MujocoResult) -> None:
    for name in _ARRAYS:
        np.testing.assert_array_equal(getattr(got, name), getattr(want, name), err_msg=name)
    assert set(got.metrics) == set(want.metrics)
    for key, value in want.metrics.items():
        np.testing.assert_array_equal(got.metrics[key], value, err_msg=key)


@pytest.mark.parametrize("contact", [False, True])
@pytest.mark.parametrize("case", ["pd", "sf", "of"])
def test_a_controller_called_back_gives_the_native_bits(case: str, contact: bool) -> None:
    """The core's loop stepping a controller natively and calling the same
    controller's Python ``step`` back give the same bits, row by row and
    metric by metric, in contact too."""
    T = 2.5
    native = amj.simulate(adaptimp.Controller(case, "robot"), "two_link", T=T, contact=contact)
    python = amj.simulate(
        _InPython(adaptimp.Controller(case, "robot")), "two_link", T=T, contact=contact
    )
    assert native.params["loop"] == "native"
    assert python.params["loop"] == "callback"
    _assert_same_run(native, python)
    if contact:
        assert native.metrics["steps_in_contact"] > 100
    # The native run records what a controller called back does not say: the weights.
    assert case == "pd" or native.w_norms[-1, 2] > 0
    assert np.all(np.isnan(python.w_norms))


def _lean_down(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Panda's reference from its home: the shoulder leans towards the
    table at 0.6 rad/s, so the tool meets it within 0.3 s."""
    xc = np.array(_models.PANDA_HOME)
    xc[1] += 0.6 * t
    v = np.zeros(7)
    v[1] = 0.6
    return xc, v, np.zeros(7)


def _panda_pd() -> adaptimp.Controller:
    """A joint PD for the Panda pressing on its table."""
    return adaptimp.Controller(
        "pd", "robot", n=7, tau_max=list(_models.PANDA_EFFORT), impedance="external",
        Kp=[40.0, 40.0, 40.0, 40.0, 4.0, 4.0, 4.0], K1=20.0, Kzeta=1000.0,
        centers=np.zeros((1, 28)), widths=1.0,
    )  # fmt: skip


@pytest.mark.filterwarnings("ignore:the (torque was|commanded torque):adaptimp.PlantWarning")
def test_the_native_loop_with_a_reference_and_seven_joints_in_contact() -> None:
    """The Panda on its table, a reference callable: the controller native and
    called back agree."""
    q0 = np.array(_models.PANDA_HOME)
    plant = amj.Plant("panda")
    native = amj.simulate(_panda_pd(), plant, T=0.6, q0=q0, reference=_lean_down)
    python = amj.simulate(_InPython(_panda_pd()), plant, T=0.6, q0=q0, reference=_lean_down)
    assert native.params["loop"] == "native"
    _assert_same_run(native, python)
    assert native.metrics["steps_in_contact"] > 50
    # The wrench is the sensor's, and τe = Jᵀ F_e row by row.
    assert np.max(np.abs(native.wrench_ee[:, 2])) > 1.0


@pytest.mark.filterwarnings("ignore:the (torque was|commanded torque):adaptimp.PlantWarning")
def test_steps_inside_a_period_skip_pure_sensors_and_change_nothing(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The Panda on its table (two MuJoCo steps a period, a force and a torque
    sensor at the tool): the step inside each period leaves the sensors out
    (they are pure functions of the state, and only the period's end is
    sensed), and the run is the same bits as with every step's sensors, in
    contact too. A sensor with noise is not pure."""
    q0 = np.array(_models.PANDA_HOME)

    def run() -> amj.MujocoResult:
        return amj.simulate(_panda_pd(), amj.Plant("panda"), T=0.6, q0=q0, reference=_lean_down)

    plant = amj.Plant("panda")
    assert plant.model.nsensor >= 2
    assert _plant._pure_sensors(plant.model)
    quiet = run()
    monkeypatch.setattr(_plant, "_pure_sensors", lambda m: False)
    every = run()
    _assert_same_run(quiet, every)
    assert quiet.metrics["steps_in_contact"] > 50
    np.testing.assert_array_equal(quiet.wrench_ee, every.wrench_ee)
    monkeypatch.undo()
    noisy = amj.panda(table_height=None)
    noisy.sensor_noise[0] = 0.1
    assert not _plant._pure_sensors(noisy)


def test_a_used_controller_goes_on_along_its_trajectory() -> None:
    """A controller that has run before is used as it is: its clock goes on."""
    a = adaptimp.Controller("sf", "robot")
    amj.simulate(a, "two_link", T=0.5, contact=False)
    b = adaptimp.Controller("sf", "robot")
    amj.simulate(_InPython(b), "two_link", T=0.5, contact=False)
    assert a.steps == b.steps == 500
    _assert_same_run(
        amj.simulate(a, "two_link", T=0.5, contact=False),
        amj.simulate(_InPython(b), "two_link", T=0.5, contact=False),
    )


def test_the_core_metrics_serve_both_loops() -> None:
    """_adaptimp.metrics (the core's accumulator over recorded rows) gives
    adaptimp.simulate's own metrics for its rows: one implementation."""
    res = adaptimp.simulate("sf", "robot", T=3.0)
    p = res.params
    assert res.ddq is not None
    assert res.dxc is not None
    assert res.ddxc is not None
    m = adaptimp._adaptimp.metrics(
        res.t, res.q, res.dq, res.ddq, res.xc, res.dxc, res.ddxc, res.z1, res.tau,
        res.tau_sat, res.tau_e, p["settle"], (p["Dd"], p["Cd"], p["Gd"]),
    )  # fmt: skip
    assert m == res.metrics
    # Task-space rows (z1 of width 3 on 2 joints): the per-joint z1 figures
    # have z1's width, τ's have n; no impedance residual.
    k = res.rows
    z3 = np.column_stack([res.z1, np.zeros(k)])
    x3 = np.zeros((k, 3))
    m3 = adaptimp._adaptimp.metrics(
        res.t, res.q, res.dq, res.ddq, x3, x3, x3, z3, res.tau, res.tau_sat, res.tau_e,
        p["settle"], (p["Dd"], p["Cd"], p["Gd"]),
    )  # fmt: skip
    assert m3["rms_z1"] == res.metrics["rms_z1"]
    assert m3["rms_z1_joint_after2"] == [*res.metrics["rms_z1_joint_after2"], 0.0]
    assert m3["peak_abs_tau"] == res.metrics["peak_abs_tau"]
    assert np.isnan(m3["imp_err_rms_after2"])


# ---------------------------------------------------------------------------
# A run that explodes (MuJoCo resets the state and only warns).
# ---------------------------------------------------------------------------

_FEATHER = """<mujoco><option integrator="RK4" timestep="0.001"/><worldbody>
<body><joint name="j" type="hinge" axis="0 1 0"/><geom type="sphere" size=".01" mass="1e-6"/>
<site name="ee"/></body></worldbody>
<actuator><motor joint="j" ctrlrange="-1e6 1e6" ctrllimited="true"/></actuator></mujoco>"""
"""A 1 mg arm with a 1 MN m motor: full torque is q̈ ~ 1e12 rad/s², beyond MuJoCo's bound."""


class _Kick:
    """Zero torque, then full torque from row ``at`` on."""

    Ts = 1e-3

    def __init__(self, at: int) -> None:
        self.at, self.k = at, 0

    def step(self, m: object, **sp: object) -> np.ndarray:
        self.k += 1
        return np.array([0.0 if self.k <= self.at else 1e6])


def _kicking_controller() -> adaptimp.Controller:
    return adaptimp.Controller(
        "pd", "robot", n=1, tau_max=1e6, xc_offset=0.0, xc_sin=0.0, xc_cos=0.0, Kp=1e4,
        Kzeta=6e7, impedance="external",
    )  # fmt: skip


def _step_at(k: int) -> object:
    """A reference that jumps by 10 rad at row k (the PD then saturates)."""
    return lambda t: ([0.0 if t < (k - 0.5) * 1e-3 else 10.0], [0.0], [0.0])


def test_an_exploding_run_raises_and_names_the_row_the_time_and_the_cause(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue 20, item 6: MuJoCo resets a diverged state and only warns, so the
    run used to end at data.time = 0.001 s with a normal-looking result. A
    controller called back and a native one raise DivergedError with the row,
    the time and MuJoCo's words."""
    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warnings to MUJOCO_LOG.TXT here
    model = mujoco.MjModel.from_xml_string(_FEATHER)
    want = (
        "the MuJoCo plant diverged in the period of row 5 (t = 0.005 s to 0.006 s): "
        "MuJoCo warned mjWARN_BADQACC: Nan, Inf or huge value in QACC at DOF 0. "
        'The simulation is unstable. (joint "j"); MuJoCo reset its state '
        "(its time is 0.001 s, not 0.006 s)"
    )
    with pytest.raises(adaptimp.DivergedError) as python:
        amj.simulate(_Kick(5), model, T=1.0)
    assert str(python.value) == want
    with pytest.raises(adaptimp.DivergedError) as native:
        amj.simulate(_kicking_controller(), model, T=1.0, reference=_step_at(5))
    assert str(native.value) == want
    # From the first row: the reset is at t = 0, the warning still tells.
    # (q0 given: without it the run starts on the reference, xc(0) = 10 rad.)
    with pytest.raises(adaptimp.DivergedError, match=r"row 0 \(t = 0 s to 0.001 s\): MuJoCo"):
        amj.simulate(_kicking_controller(), model, T=1.0, reference=_step_at(0), q0=[0.0])


def test_after_an_error_the_plant_and_controller_run_again() -> None:
    """The native run gives its MuJoCo data back on every exit, Ctrl-C included."""
    plant = amj.Plant("two_link")
    ctrl = adaptimp.Controller("sf", "robot")

    def interrupt(done: int, total: int) -> None:
        raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        amj.simulate(ctrl, plant, T=30.0, progress=interrupt)
    assert 0 < ctrl.steps < 30_000
    ctrl.reset()
    again = amj.simulate(ctrl, plant, T=0.2)
    fresh = amj.simulate(adaptimp.Controller("sf", "robot"), "two_link", T=0.2)
    _assert_same_run(again, fresh)


# ---------------------------------------------------------------------------
# Disturbances (SPEC §17) on MuJoCo.
# ---------------------------------------------------------------------------


def test_disturbances_act_on_the_mujoco_plant() -> None:
    base = amj.simulate("sf", "two_link", T=1.0, contact=False)
    assert base.params["noise_q"] == [0.0, 0.0]
    a = amj.simulate("sf", "two_link", T=1.0, contact=False, noise_q=1e-3, seed=1)
    b = amj.simulate("sf", "two_link", T=1.0, contact=False, noise_q=1e-3, seed=1)
    c = amj.simulate("sf", "two_link", T=1.0, contact=False, noise_q=1e-3, seed=2)
    _assert_same_run(a, b)
    assert not np.array_equal(a.tau, c.tau)
    assert not np.array_equal(a.tau, base.tau)
    # The rows hold the true state: the first row is the plant's q0.
    np.testing.assert_array_equal(a.q[0], base.q[0])
    weak = amj.simulate("sf", "two_link", T=1.0, actuator_fraction=0.25)
    assert np.all(np.abs(weak.tau_sat) <= 0.25 * np.array([17.0, 15.0]) + 1e-12)
    assert weak.metrics["sat_duty"] > base.metrics["sat_duty"]
    late = amj.simulate("sf", "two_link", T=1.0, contact=False, delay=3)
    assert not np.array_equal(late.tau, base.tau)
    slow = amj.simulate("pd", "two_link", T=1.0, contact=False, friction_viscous=2.0)
    free = amj.simulate("pd", "two_link", T=1.0, contact=False)
    assert slow.metrics["rms_z1"] > free.metrics["rms_z1"]
    with pytest.raises(adaptimp.ConfigError, match="jitter"):
        amj.simulate("sf", "two_link", T=0.1, jitter=0.1)
    with pytest.raises(ValueError, match="0 ≤ delay ≤ 64"):
        amj.simulate("sf", "two_link", T=0.1, delay=65)


@pytest.mark.parametrize("copy_data", [True, False], ids=["mj_copyData", "mj_setState"])
def test_state_kept_puts_the_plants_state_back(
    monkeypatch: pytest.MonkeyPatch, copy_data: bool
) -> None:
    """Plant.state_kept: what a rule does to the plant inside the block (D and G
    read at postures of its own) is undone, with MuJoCo's mj_copyData or, on
    bindings without it (robosuite's MuJoCo 3.3), the integration state."""
    if not copy_data:
        monkeypatch.delattr(mujoco, "mj_copyData", raising=False)
    plant = amj.Plant(adaptimp._models.panda_urdf_path(), contact=False)
    d = plant.data
    d.qpos[:] += 0.1
    d.qvel[:] = 0.3
    d.ctrl[:] = 0.5
    d.time = 1.25
    mujoco.mj_forward(plant.model, d)
    before = {k: np.array(getattr(d, k)) for k in ("qpos", "qvel", "ctrl", "xpos")}
    with plant.state_kept():
        d.qpos[:] = 0.0
        d.qvel[:] = 0.0
        d.ctrl[:] = 0.0
        d.time = 9.0
        mujoco.mj_forward(plant.model, d)
    for k, v in before.items():
        np.testing.assert_array_equal(getattr(d, k), v, err_msg=k)
    assert d.time == 1.25
