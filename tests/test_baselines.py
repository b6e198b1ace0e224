"""The Panda in MuJoCo against Pinocchio, and the computed-torque baseline
(adaptimp.baselines) closing the loop on MuJoCo."""

from __future__ import annotations

import mujoco
import numpy as np
import pinocchio as pin
import pytest

import adaptimp
from adaptimp import Measurement, _models
from adaptimp import mujoco as amj
from adaptimp.baselines import ComputedTorque, pinocchio_model, scale_masses
from mujoco_probe import contact_list_wrench, ee_jacobian, ee_position

RNG_SEED = 20160301

# MuJoCo and Pinocchio compute the same rigid-body quantities by different
# recursions (CRB / RNE in different frames); with the same inertias they agree
# to rounding, measured ≤ 5e-14 (kg m², N m) for the Panda. A wrong axis, frame
# or inertia shows as O(0.1–1); 1e-9 leaves rounding ample room.
TOL = 1e-9


@pytest.fixture(scope="module")
def panda_pair() -> tuple[mujoco.MjModel, object]:
    try:
        return amj.panda(), pinocchio_model("panda")
    except ImportError as e:
        pytest.skip(str(e))


def test_panda_model(panda_pair: tuple[mujoco.MjModel, object]) -> None:
    m, model = panda_pair
    plant = amj.Plant(m)
    assert plant.n == m.nq == m.nv == 7
    assert plant.tau_max.tolist() == list(_models.PANDA_EFFORT)
    assert plant.wrench_source == "sensor"
    np.testing.assert_array_equal(plant.q, _models.PANDA_HOME)
    # The end effector is the TCP, a massless body carrying the site and the tool.
    tcp = m.body(_models.PANDA_EE).id
    assert m.site_bodyid[m.site("ee").id] == tcp
    assert m.body_mass[tcp] == 0.0
    assert m.body_subtreemass[tcp] == 0.0
    assert not np.any(m.dof_damping)
    assert not np.any(m.dof_frictionloss)
    assert not np.any(m.dof_armature)
    # Total mass: the base, the arm, the hand and both (locked) fingers
    # (Pinocchio's universe holds the fixed base link0).
    total = m.body_subtreemass[m.body("panda_link0").id]
    assert total == pytest.approx(sum(i.mass for i in model.inertias), abs=1e-12)
    assert model.nq == 7
    np.testing.assert_array_equal(model.effortLimit, _models.PANDA_EFFORT)


def test_panda_dynamics_agree_with_pinocchio(panda_pair: tuple[mujoco.MjModel, object]) -> None:
    m, model = panda_pair
    data = model.createData()
    plant = amj.Plant(m, contact=False)
    fid = model.getFrameId(_models.PANDA_EE)
    lo, hi = m.jnt_range[:, 0], m.jnt_range[:, 1]
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(50):
        q, dq = rng.uniform(lo, hi), rng.uniform(-2.0, 2.0, 7)
        plant.reset(q, dq)
        mass = pin.crba(model, data, q)
        mass = np.triu(mass) + np.triu(mass, 1).T
        np.testing.assert_allclose(plant.mass_matrix(), mass, rtol=0, atol=TOL)
        bias = pin.rnea(model, data, q, dq, np.zeros(7))
        np.testing.assert_allclose(plant.bias(), bias, rtol=0, atol=TOL)
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        np.testing.assert_allclose(ee_position(plant), data.oMf[fid].translation, atol=TOL)
        jac = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        np.testing.assert_allclose(ee_jacobian(plant), jac, rtol=0, atol=TOL)


@pytest.mark.filterwarnings("ignore:the (torque was|commanded torque):adaptimp.PlantWarning")
def test_panda_pushes_on_the_table() -> None:
    """The table 13 mm above the tool at home: held at home by computed torque
    with a stiff target impedance, the tool presses down all along; the sensor's
    and the contacts' wrenches agree (measured 2e-13 N)."""
    plant = amj.Plant(amj.panda(table_height=0.49))
    home = np.array(_models.PANDA_HOME)

    def hold(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return home, np.zeros(7), np.zeros(7)

    stiff = ComputedTorque("panda", Gd=1e4, Cd=200.0)
    res = amj.simulate(stiff, plant, T=0.3, reference=hold)
    assert res.params["loop"] == "native"
    assert res.params["substeps"] == 2
    assert res.metrics["steps_in_contact"] == res.rows  # from the first row
    # The tool pushes down on the table (world −z), by tens of newtons.
    assert np.all(res.wrench_ee[:, 2] < -1.0)
    # Where the run left the plant: the sensor the core reads and MuJoCo's contact list.
    listed = contact_list_wrench(plant)
    again = amj.simulate(stiff, plant, T=res.params["Ts"], reference=hold, reset=False)
    assert again.wrench_ee is not None
    np.testing.assert_allclose(again.wrench_ee[0], listed, rtol=0, atol=1e-8)
    np.testing.assert_allclose(res.tau_e, np.einsum("kij,kj->ki", _jacobians(res), res.wrench_ee))


def _jacobians(res: amj.MujocoResult) -> np.ndarray:
    """Jᵀ (7 × 6) of the Panda's TCP at every recorded q, from Pinocchio."""
    model = pinocchio_model("panda")
    data = model.createData()
    fid = model.getFrameId(_models.PANDA_EE)
    return np.array(
        [pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED).T for q in res.q]
    )


def test_two_link_pinocchio_model_is_the_papers() -> None:
    arm = adaptimp.TwoLinkArm()
    ct = ComputedTorque()
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(50):
        q, dq = rng.uniform(-np.pi, np.pi, 2), rng.uniform(-10.0, 10.0, 2)
        np.testing.assert_allclose(ct.mass_matrix(q), arm.D(q), rtol=0, atol=1e-12)
        bias = arm.C(q, dq) @ dq + arm.G(q)
        np.testing.assert_allclose(ct.bias(q, dq), bias, rtol=0, atol=1e-12)


def test_mass_scale_scales_the_model() -> None:
    arm = adaptimp.TwoLinkArm()
    ct = ComputedTorque(mass_scale=1.3)
    q, dq = np.array([0.3, -0.4]), np.array([1.0, -2.0])
    np.testing.assert_allclose(ct.mass_matrix(q), 1.3 * arm.D(q), rtol=1e-14)
    np.testing.assert_allclose(ct.bias(q, dq), 1.3 * (arm.C(q, dq) @ dq + arm.G(q)), rtol=1e-14)
    with pytest.raises(ValueError, match="mass_scale must be > 0"):
        scale_masses(pinocchio_model(), 0.0)


def test_computed_torque_tracks_the_circle_on_mujoco() -> None:
    """The exact model at 1 kHz: after 2 s the error is the sampling's only
    (measured RMS ‖z1‖ 1.0e-4 rad); +30 % mass gives a model error (2.3e-2 rad)."""
    exact = amj.simulate(ComputedTorque(), "two_link", T=3.0, contact=False)
    m = exact.metrics
    assert exact.params["Ts"] == 1e-3
    assert m["rms_z1_after2"] < 2e-4
    assert m["sat_duty"] < 0.01
    assert m["imp_err_rms_after2"] < 0.05
    heavy = amj.simulate(ComputedTorque(mass_scale=1.3), "two_link", T=3.0, contact=False)
    assert heavy.metrics["rms_z1_after2"] > 50 * m["rms_z1_after2"]
    # The same circle given from outside: the same run.
    given = amj.simulate(
        ComputedTorque(), "two_link", T=3.0, contact=False, reference=amj.paper_circle()
    )
    np.testing.assert_array_equal(given.q, exact.q)


def test_computed_torque_validates() -> None:
    with pytest.raises(ValueError, match=r"Kp must be a number or have shape \(2,\)"):
        ComputedTorque(Kp=[1.0, 2.0, 3.0])
    ct = ComputedTorque()
    with pytest.raises(ValueError, match="needs the measured joint velocity"):
        ct.step(Measurement([0.0, 0.0], tau_e=[0.0, 0.0]))
    with pytest.raises(ValueError, match="no setpoint given and no trajectory"):
        ComputedTorque("panda").step(Measurement(np.zeros(7), np.zeros(7), tau_e=np.zeros(7)))
    tau = ct.step(Measurement([0.25, -0.05], [0.0, 0.0], tau_e=[0.0, 0.0]))
    assert np.all(np.abs(tau) <= ct.tau_max)
    assert ct.t == pytest.approx(1e-3)
