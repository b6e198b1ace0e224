"""The 6-D Cartesian impedance through the public Python API (SPEC §16): the
rotation error's properties, bad targets, the parameters of the schema, the
orbit-centre rule, and the controller on MuJoCo's Panda."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import adaptimp
from adaptimp import Measurement, _models
from adaptimp import mujoco as amj
from adaptimp.cartesian import CartesianImpedance

PANDA = adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip=_models.PANDA_EE)
HOME = np.array(_models.PANDA_HOME)
K_ROT, M_ROT = 30.0, 0.08
# PD learns nothing: one RBF centre (at home) stands for the basis n = 7 needs.
ONE = {"centers": np.concatenate([HOME, np.zeros(21)])[None], "widths": np.ones(28)}


def _rot(axis: np.ndarray, theta: float) -> np.ndarray:
    """Rodrigues, independently of the core."""
    u = axis / np.linalg.norm(axis)
    k = np.array([[0, -u[2], u[1]], [u[2], 0, -u[0]], [-u[1], u[0], 0]])
    return np.eye(3) + math.sin(theta) * k + (1 - math.cos(theta)) * k @ k


def _moment(outer: CartesianImpedance, axis: np.ndarray, theta: float) -> np.ndarray:
    """The impedance's restoring moment when the commanded rotation turns by θ
    about ``axis`` from the compliant one: M_rot ω̇_d at ω_d = ω_c = 0, no wrench."""
    outer.reset()
    p0, r0 = PANDA.pose(HOME)
    outer.step(p0, R=r0)  # at rest: R_d = R_c = R(home)
    outer.step(p0, R=_rot(axis, theta) @ r0)
    return M_ROT * outer.last("dw_d")


@pytest.fixture(scope="module")
def stiff() -> CartesianImpedance:
    return CartesianImpedance(
        PANDA, Ts=1e-3, q0=HOME, Kd_rot=K_ROT, Md_rot=M_ROT, target_filter=0.0
    )


@settings(max_examples=200, deadline=None)
@given(
    a=st.floats(0.0, 2 * math.pi),
    b=st.floats(0.0, math.pi),
    deg=st.floats(0.0, 359.999),
)
def test_the_moment_is_k_theta_axis_the_short_way(a: float, b: float, deg: float) -> None:
    outer = CartesianImpedance(
        PANDA, Ts=1e-3, q0=HOME, Kd_rot=K_ROT, Md_rot=M_ROT, target_filter=0.0
    )
    u = np.array([math.sin(b) * math.cos(a), math.sin(b) * math.sin(a), math.cos(b)])
    if np.linalg.norm(u) < 0.5 or abs(deg - 180.0) < 1e-4:
        return
    u /= np.linalg.norm(u)
    theta = math.radians(deg)
    m = _moment(outer, u, theta)
    short = theta if theta < math.pi else theta - 2 * math.pi
    np.testing.assert_allclose(m, K_ROT * short * u, rtol=0, atol=1e-9 * K_ROT)
    assert np.linalg.norm(m) <= K_ROT * math.pi * (1 + 1e-12)
    assert float(m @ u) * math.copysign(1.0, short) >= -1e-12  # the shorter way round


def test_the_moment_is_continuous_except_at_180_degrees(stiff: CartesianImpedance) -> None:
    u = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])
    m = np.array([_moment(stiff, u, math.radians(d)) for d in range(360)])
    jumps = np.linalg.norm(np.diff(m, axis=0), axis=1)
    one = K_ROT * math.radians(1)
    assert np.all(np.delete(jumps, [179, 180]) <= one * (1 + 1e-9))
    # From +K(π − 1°)u to −K(π − 1°)u across exactly 180°.
    np.testing.assert_allclose(
        m[181] - m[179], -2 * K_ROT * (math.pi - math.radians(1)) * u, atol=1e-9
    )


def test_a_rotation_that_is_not_one_changes_nothing(stiff: CartesianImpedance) -> None:
    stiff.reset()
    p0, r0 = PANDA.pose(HOME)
    stiff.step(p0, R=r0)
    before = stiff.core.state("q_d"), stiff.core.steps
    with pytest.raises(adaptimp.MeasurementError, match=r"orthonormal.*R_c"):
        stiff.step(p0, R=r0 * 1.001)
    with pytest.raises(adaptimp.MeasurementError, match=r"det R = \+1"):
        stiff.step(p0, R=np.diag([1.0, 1.0, -1.0]))
    with pytest.raises(adaptimp.MeasurementError, match="wrench"):
        stiff.step(p0, R=r0, wrench=[math.nan] * 6)
    np.testing.assert_array_equal(stiff.core.state("q_d"), before[0])
    assert stiff.core.steps == before[1]


def test_parameters_come_from_the_schema() -> None:
    with pytest.raises(ValueError, match="Md_rot > 0"):
        CartesianImpedance(PANDA, Ts=1e-3, q0=HOME, Md_rot=[1.0, 0.0, 1.0])
    with pytest.raises(TypeError, match="force_feedforward must be True or False"):
        CartesianImpedance(PANDA, Ts=1e-3, q0=HOME, force_feedforward=1)
    with pytest.raises(TypeError, match="Cartesian impedance parameter"):
        adaptimp.simulate("pd", T=0.01, Kd=100.0)
    with pytest.raises(TypeError, match="did you mean 'Kd_rot'"):
        CartesianImpedance(PANDA, Ts=1e-3, q0=HOME, Kd_rott=1.0)
    outer = CartesianImpedance(PANDA, Ts=1e-3, q0=HOME, Kd=[100, 200, 300], Kd_rot=0.0)
    assert not outer.orients
    assert outer.params["Kd"] == [100.0, 200.0, 300.0]
    assert outer.params["Bd"] is None
    with pytest.raises(ValueError, match="position-only"):
        outer.set_stiffness(100.0, 5.0)
    outer.set_stiffness([50.0, 60.0, 70.0])
    np.testing.assert_array_equal(outer.core.state("stiffness"), [50, 60, 70, 0, 0, 0])


def test_the_orbit_rule_samples_the_outer_loops_joint_reference() -> None:
    """orbit_centres = the joint reference [q_d; q̇_d] of every (K // L)-th step of the
    outer loop run kinematically, widths max(2 h, tube) per block, ∞ for α1, α̇1."""
    outer = CartesianImpedance(PANDA, Ts=1e-3, q0=HOME, Kd_rot=0.0)
    p0, _ = PANDA.pose(HOME)

    def path(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        w = math.pi
        return (
            p0 + 0.04 * np.array([math.cos(w * t) - 1, math.sin(w * t), 0.0]),
            0.04 * w * np.array([-math.sin(w * t), math.cos(w * t), 0.0]),
            -0.04 * w * w * np.array([math.cos(w * t), math.sin(w * t), 0.0]),
        )

    centres, widths = outer.orbit_centres(path, 2.0, nodes=16, tube=(0.01, 0.05))
    rows = []
    for k in range(2000):
        q, dq, _ = outer.step(*path(k * 1e-3))
        if k % 125 == 0:
            rows.append(np.concatenate([q, dq]))
    expect = np.array(rows)
    np.testing.assert_array_equal(centres[:, :14], expect)
    assert np.all(centres[:, 14:] == 0.0)
    hq = np.max(np.linalg.norm(np.diff(expect[:, :7], axis=0), axis=1))
    hv = np.max(np.linalg.norm(np.diff(expect[:, 7:], axis=0), axis=1))
    np.testing.assert_allclose(widths[:7], max(2 * hq, 0.01), rtol=1e-15)
    np.testing.assert_allclose(widths[7:14], max(2 * hv, 0.05), rtol=1e-15)
    assert np.all(np.isinf(widths[14:]))


def test_without_force_feedforward_the_joint_controller_gets_no_tau_e() -> None:
    wrench = np.array([3.0, -1.0, -5.0, 0.2, 0.0, 0.1])
    for ff in (True, False):
        ctrl = adaptimp.CartesianController(
            PANDA, "pd", q0=HOME, Kd_rot=0.0, force_feedforward=ff, tau_max=87.0, Kp=5.0,
            Kzeta=25.0, **ONE,
        )  # fmt: skip
        ctrl.step(Measurement(HOME, np.zeros(7), wrench=wrench))
        expect = PANDA.jacobian(HOME).T @ wrench if ff else np.zeros(7)
        np.testing.assert_allclose(ctrl.outer.last("tau_e"), expect, rtol=0, atol=1e-12)


def test_the_controller_turns_and_moves_the_panda_in_mujoco() -> None:
    """6-D in closed loop: MuJoCo's Panda (gravity off) under PD with the core's
    outer loop reaches a pose 4 cm and 20° about z away (the target filter takes
    the jump): the tool within 1 mm and 5 mrad of the commanded pose after 3 s."""
    model = amj.panda(table_height=None)
    model.opt.gravity[:] = 0.0
    p0, r0 = PANDA.pose(HOME)
    pc, rc = p0 + np.array([0.0, 0.04, -0.02]), _rot(np.array([0.0, 0.0, 1.0]), 0.35) @ r0
    ctrl = adaptimp.CartesianController(
        PANDA,
        "pd",
        q0=HOME,
        path=lambda t: (pc, np.zeros(3), np.zeros(3), rc, np.zeros(3), np.zeros(3)),
        tau_max=list(_models.PANDA_EFFORT),
        Kp=[60.0, 60.0, 60.0, 60.0, 10.0, 10.0, 10.0],
        Kzeta=2000.0,
        K1=20.0,
        target_filter=0.2,
        **ONE,
    )
    res = amj.simulate(ctrl, amj.Plant(model, contact=False), T=3.0, q0=HOME)
    sid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, "ee")
    data = mujoco.MjData(model)
    data.qpos[:] = res.q[-1]
    mujoco.mj_kinematics(model, data)
    assert np.linalg.norm(data.site_xpos[sid] - pc) < 1e-3
    r = data.site_xmat[sid].reshape(3, 3) @ rc.T
    angle = math.acos(min(1.0, (np.trace(r) - 1) / 2))
    assert angle < 5e-3
    assert np.all(np.abs(res.tau_sat) <= np.array(_models.PANDA_EFFORT) + 1e-12)


def test_the_rules_keywords_drive_a_cartesian_controller_under_gravity() -> None:
    """docs/cartesian.md's free-space move: MuJoCo's Panda with gravity, state
    feedback with the joint keywords of ``tuning.suggest`` (which name n too:
    the chain's n is accepted, another refused by name) moves the tool 5 cm and
    ends within 1 mm of the target after 5 s."""
    from adaptimp import tuning

    p0, r0 = PANDA.pose(HOME)

    def path(t: float) -> tuple[np.ndarray, ...]:
        z = np.zeros(3)
        return p0 + np.array([0.0, 0.05 * min(t, 1.0), 0.0]), z, z, r0, z, z

    plant = amj.Plant(amj.panda(table_height=None))
    joint = tuning.suggest(plant, HOME, plant.tau_max)
    assert joint["n"] == 7
    centres, widths = CartesianImpedance(PANDA, Ts=1e-3, q0=HOME).orbit_centres(path, 2.0)
    with pytest.raises(adaptimp.ConfigError, match=r"^n = 6, but the chain has 7 joints$"):
        adaptimp.CartesianController(PANDA, "sf", "robot", q0=HOME, centers=centres, widths=widths,
                                     **{**joint, "n": 6})  # fmt: skip
    ctrl = adaptimp.CartesianController(
        PANDA, "sf", "robot", q0=HOME, path=path, centers=centres, widths=widths,
        Kd=[800, 800, 300], Kd_rot=30.0, **joint,
    )  # fmt: skip
    res = amj.simulate(ctrl, plant, T=5.0, q0=HOME)
    assert np.linalg.norm(PANDA.pose(res.q[-1])[0] - path(5.0)[0]) < 1e-3


def test_run_core_is_refused_for_a_joint_controller_stepped_from_python() -> None:
    """CartesianController.run_core runs the core's loop only where the core
    steps the joint controller: a Python one is refused by name."""

    class Joint:
        Ts = 1e-3
        impedance = "external"

        def step(self, m: Measurement, **kw: object) -> np.ndarray:
            return np.zeros(7)

    ctrl = adaptimp.CartesianController(PANDA, Joint(), q0=HOME)
    assert ctrl.core_joint is None
    with pytest.raises(TypeError, match=r"^run_core: .* this one's joint controller is a Joint$"):
        ctrl.run_core(10, None, lambda joint, targets: {})
    native = adaptimp.CartesianController(PANDA, "pd", q0=HOME, tau_max=87.0, **ONE)
    assert isinstance(native.core_joint, adaptimp.Controller)
