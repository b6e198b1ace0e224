"""The core's rigid-body dynamics and computed torque (SPEC §20) against
Pinocchio: RNEA and the mass matrix on the arms of example-robot-data, the
computed-torque law against the same law written here with Pinocchio's
algorithms, and its native MuJoCo run against the same controller called back
through its Python ``step``, bit for bit."""

from __future__ import annotations

import importlib.metadata
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest

import adaptimp
from adaptimp import Measurement, _sampled
from adaptimp import mujoco as amj
from adaptimp.baselines import ComputedTorque, core_description, pinocchio_model
from adaptimp.scenarios import panda_table as apt
from adaptimp.scenarios.panda_table import POSITION_ONLY

ROBOTS = Path(
    str(
        importlib.metadata.distribution("example-robot-data").locate_file(
            "cmeel.prefix/share/example-robot-data/robots"
        )
    )
)

# Two implementations of the same model (the core's in its links' frames with
# every joint about z, Pinocchio's in the URDF's joint frames) agree to
# rounding, relative to the largest entry; a wrong axis, frame, lever or
# inertia shows as O(1e-2) and more.
RTOL = 1e-12

ARMS = {
    "panda": "panda",
    "ur3": ROBOTS / "ur_description/urdf/ur3_robot.urdf",
    "ur5": ROBOTS / "ur_description/urdf/ur5_robot.urdf",
    "ur10": ROBOTS / "ur_description/urdf/ur10_robot.urdf",
    "xarm7": ROBOTS / "xarm_description/urdf/xarm7.urdf",
    "kinova": ROBOTS / "kinova_description/robots/kinova.urdf",
    "z1": ROBOTS / "z1_description/urdf/z1.urdf",
    "two_link": "two_link",
}


def _config(model: Any, q: np.ndarray) -> np.ndarray:
    """Pinocchio's configuration of the joint angles q (continuous joints are
    (cos, sin) pairs there)."""
    if model.nq == model.nv:
        return q
    return np.asarray(pin.integrate(model, pin.neutral(model), q))


@pytest.mark.parametrize("arm", sorted(ARMS))
def test_rnea_and_the_mass_matrix_equal_pinocchio(arm: str) -> None:
    model = pinocchio_model(ARMS[arm])
    data = model.createData()
    n = model.nv
    ct = ComputedTorque(model, tau_max=np.full(n, 100.0))
    rng = np.random.default_rng(20161116)
    for _ in range(20):
        q, dq, ddq = rng.uniform(-3, 3, n), rng.uniform(-4, 4, n), rng.uniform(-10, 10, n)
        want = pin.rnea(model, data, _config(model, q), dq, ddq)
        got = ct.inverse_dynamics(q, dq, ddq)
        np.testing.assert_allclose(got, want, rtol=0, atol=RTOL * np.abs(want).max())
        m = pin.crba(model, data, _config(model, q))
        m = np.triu(m) + np.triu(m, 1).T
        np.testing.assert_allclose(ct.mass_matrix(q), m, rtol=0, atol=RTOL * np.abs(m).max())
        g = pin.computeGeneralizedGravity(model, data, _config(model, q))
        np.testing.assert_allclose(
            ct.bias(q, np.zeros(n)), g, rtol=0, atol=RTOL * max(1, np.abs(g).max())
        )


def test_the_models_description_keeps_pinocchios_parameters() -> None:
    model = pinocchio_model("panda")
    joints, inertials, gravity = core_description(model)
    assert len(joints) == len(inertials) == 7
    assert gravity == [0.0, 0.0, -9.81]
    masses = [i["mass"] for i in inertials]
    assert masses == [float(model.inertias[j].mass) for j in range(1, 8)]
    core = adaptimp._adaptimp.ComputedTorque(
        joints, inertials, gravity, Ts=1e-3, Kp=400.0, Kd=40.0, tau_max=87.0,
        Dd=1.0, Cd=10.0, Gd=60.0, impedance="joint", mass_scale=1.0, payload=0.5,
    )  # fmt: skip
    assert core.mass == pytest.approx(sum(masses) + 0.5, rel=1e-15)
    bad = [dict(i) for i in inertials]
    bad[3]["mass"] = -1.0
    with pytest.raises(ValueError, match=r"mass ≥ 0 is violated: link mass\[3\] = -1"):
        adaptimp._adaptimp.ComputedTorque(
            joints, bad, gravity, Ts=1e-3, Kp=400.0, Kd=40.0, tau_max=87.0,
            Dd=1.0, Cd=10.0, Gd=60.0, impedance="joint", mass_scale=1.0, payload=0.0,
        )  # fmt: skip


def _law(model: Any, data: Any, q: np.ndarray, dq: np.ndarray, a: np.ndarray) -> np.ndarray:
    """M(q) a + C(q, q̇) q̇ + G(q) from Pinocchio's CRBA and RNEA at q̈ = 0."""
    m = pin.crba(model, data, q)
    m = np.triu(m) + np.triu(m, 1).T
    return np.asarray(m @ a + pin.rnea(model, data, q, dq, np.zeros(len(q))))


def test_the_joint_law_is_computed_torque_with_pinocchios_dynamics() -> None:
    """(20.3) in the joint mode along a run of setpoints: the compliant reference
    of SPEC §4, advanced exactly for the acceleration ẍd held over the period,
    and τ = M (ẍd + K_D ė + K_P e) + C q̇ + G + τe, clipped at τmax."""
    model = pinocchio_model("panda")
    data = model.createData()
    n = 7
    kp, kd = np.linspace(300, 500, n), np.linspace(30, 50, n)
    tau_max = np.array([87.0] * 4 + [12.0] * 3)
    ct = ComputedTorque(model, Kp=kp, Kd=kd, tau_max=tau_max, Gd=80.0, Cd=12.0, Dd=1.5)
    rng = np.random.default_rng(7)
    xd = dxd = None
    for k in range(200):
        q, dq = rng.uniform(-2, 2, n), rng.uniform(-1, 1, n)
        tau_e = rng.uniform(-5, 5, n)
        xc, dxc, ddxc = np.sin(0.01 * k + np.arange(n)), np.cos(0.01 * k) * np.ones(n), np.zeros(n)
        if xd is None:
            xd, dxd = xc.copy(), dxc.copy()
        ddxd = ddxc + (12.0 * (dxc - dxd) + 80.0 * (xc - xd) - tau_e) / 1.5
        a = ddxd + kd * (dxd - dq) + kp * (xd - q)
        want = np.clip(_law(model, data, q, dq, a) + tau_e, -tau_max, tau_max)
        got = ct.step(Measurement(q, dq, tau_e=tau_e), xc=xc, dxc=dxc, ddxc=ddxc)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.abs(want).max())
        # The reference moves as the arm does under the held torque (SPEC (20.3)).
        xd = xd + 1e-3 * dxd + 0.5e-6 * ddxd
        dxd = dxd + 1e-3 * ddxd
    assert ct.t == pytest.approx(0.2)


@pytest.fixture(scope="module")
def sc() -> apt.PandaTable:
    return apt.panda_table()


class _PinocchioLaw(ComputedTorque):
    """The PD+ law of SPEC (20.4) at n = 0 written with Pinocchio's algorithms
    (its own ``step``: the Cartesian controller calls it from Python with the
    commanded reference, the task torque and the task Jacobian)."""

    def step(  # type: ignore[override]
        self,
        m: Any,
        *,
        xc: Any = None,
        dxc: Any = None,
        ddxc: Any = None,
        task_torque: Any = None,
        jacobian: Any = None,
    ) -> np.ndarray:
        q, dq = m.q, m.dq
        model = self.pin
        data = model.createData()
        j = np.asarray(jacobian).reshape(6, self.n)
        # Π of (19.3) for a uniform K_P: I − Jᵀ (J Jᵀ + Λ²)⁻¹ J, Λ² of (C3).
        null = np.eye(self.n) - j.T @ np.linalg.solve(j @ j.T + 1e-4 * np.eye(6), j)
        m = pin.crba(model, data, q)
        m = np.triu(m) + np.triu(m, 1).T
        pd = self.Kp * (xc - q) + self.Kd * (dxc - dq)
        tau = _law(model, data, q, dq, ddxc) + task_torque + null @ (m @ pd)
        self.out = np.clip(tau, -self.tau_max, self.tau_max)
        return self.out


def test_the_torque_level_law_is_pinocchios_pd_plus(sc: apt.PandaTable) -> None:
    """(20.4) with n = 0 behind the Cartesian impedance on the Panda table: the
    core's step and the law written with Pinocchio, row by row on the rows of a
    native run pressing on the table."""
    res = amj.simulate(
        apt.panda_controller("ct", sc, formulation="impedance", force_feedforward=False),
        amj.Plant(sc.model),
        T=1.0,
        q0=sc.q0,
    )
    assert res.params["loop"] == "native"
    assert res.metrics["steps_in_contact"] > 300
    assert res.task is not None
    core = apt.panda_controller("ct", sc, formulation="impedance", force_feedforward=False)
    law = _PinocchioLaw(sc.pin_model, Ts=sc.Ts, tau_max=sc.tau_max, impedance="external")
    law.pin = sc.pin_model
    written = adaptimp.CartesianController(
        sc.chain, law, q0=sc.q0, path=sc.path, force_feedforward=False,
        formulation="impedance", **POSITION_ONLY,
    )  # fmt: skip
    for k in range(len(res.t)):
        q, dq, f = res.q[k], res.dq[k], res.task["wrench"][k]
        got = core.step(Measurement(q, dq, wrench=f))
        want = written.step(Measurement(q, dq, wrench=f))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-9 * np.abs(want).max(), err_msg=k)
    np.testing.assert_array_equal(got, res.tau_sat[-1])


def test_the_native_run_equals_the_callback_in_every_formulation(sc: apt.PandaTable) -> None:
    """Computed torque behind the Cartesian impedance steps in the core's native
    loop, bit for bit the run calling the same controller back through its
    Python ``step`` (the five controllers' table, issue of engine speed)."""
    from test_mujoco_cartesian import _InPython

    for kind, formulation, share in (
        ("ct", "impedance", None),
        ("ct", "admittance", None),
        ("ct+30", "unified", 0.3),
    ):
        kw: dict[str, Any] = {"formulation": formulation, "force_feedforward": share is None}
        if share is not None:
            kw["admittance_share"] = share
        a, b = apt.panda_controller(kind, sc, **kw), apt.panda_controller(kind, sc, **kw)
        native = amj.simulate(a, amj.Plant(sc.model), T=1.0, q0=sc.q0)
        python = amj.simulate(_InPython(b), amj.Plant(sc.model), T=1.0, q0=sc.q0)
        assert (native.params["loop"], python.params["loop"]) == ("native", "callback")
        for name in ("q", "dq", "tau", "tau_sat", "z1", "xd", "x_ee", "wrench_ee"):
            np.testing.assert_array_equal(getattr(native, name), getattr(python, name), name)
        assert set(native.metrics) == set(python.metrics)
        for key, value in python.metrics.items():
            np.testing.assert_array_equal(native.metrics[key], value, err_msg=key)
        assert native.metrics["steps_in_contact"] > 150


# The drive of SPEC (20.5): per joint armature (kg m²) and viscous damping
# (N m s/rad), different on every joint so that a term on the wrong joint shows.
ARMATURE = np.array([0.1, 0.2, 0.3, 0.05, 0.02, 0.01])
DAMPING = np.array([1.0, 2.0, 0.5, 0.3, 0.2, 0.1])


def test_the_drive_terms_equal_mujocos_inverse_dynamics() -> None:
    """ID of (20.5) on the UR5 against MuJoCo's ``mj_inverse`` of the model with
    ``dof_armature`` and ``dof_damping`` (M_a q̈ + bias − qfrc_passive), and M_a
    against ``mj_fullM``."""
    import mujoco

    urdf = ARMS["ur5"]
    m = amj.from_urdf(urdf)
    m.dof_armature[:] = ARMATURE
    m.dof_damping[:] = DAMPING
    d = mujoco.MjData(m)
    ct = ComputedTorque(urdf, tau_max=np.full(6, 100.0), armature=ARMATURE, damping=DAMPING)
    rigid = ComputedTorque(urdf, tau_max=np.full(6, 100.0))
    rng = np.random.default_rng(29)
    for _ in range(10):
        q, dq, ddq = rng.uniform(-3, 3, 6), rng.uniform(-4, 4, 6), rng.uniform(-10, 10, 6)
        d.qpos[:], d.qvel[:], d.qacc[:] = q, dq, ddq
        mujoco.mj_inverse(m, d)
        got = ct.inverse_dynamics(q, dq, ddq)
        want = d.qfrc_inverse
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
        full = np.zeros((6, 6))
        _sampled._full_inertia(m, d, full)
        np.testing.assert_allclose(ct.mass_matrix(q), full, rtol=0, atol=1e-12 * np.abs(full).max())
        # The drive's share is there (not a model MuJoCo and the core both lack).
        extra = got - rigid.inverse_dynamics(q, dq, ddq)
        np.testing.assert_allclose(extra, ARMATURE * ddq + DAMPING * dq, rtol=1e-9, atol=1e-12)


def test_the_drive_terms_equal_pinocchios() -> None:
    """Pinocchio's ``crba`` and ``rnea`` with ``model.armature`` (its rnea adds
    armature ⊙ q̈ and leaves ``model.damping`` out: b ⊙ q̇ added here)."""
    for arm in ("panda", "xarm7", "ur5"):
        model = pinocchio_model(ARMS[arm]).copy()
        n = model.nv
        armature, damping = np.linspace(0.05, 0.4, n), np.linspace(0.2, 2.0, n)
        model.armature[:] = armature
        data = model.createData()
        ct = ComputedTorque(model, tau_max=np.full(n, 100.0), armature=armature, damping=damping)
        rng = np.random.default_rng(4)
        for _ in range(10):
            q, dq, ddq = rng.uniform(-3, 3, n), rng.uniform(-4, 4, n), rng.uniform(-10, 10, n)
            want = pin.rnea(model, data, q, dq, ddq) + damping * dq
            got = ct.inverse_dynamics(q, dq, ddq)
            np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())
            m = pin.crba(model, data, q)
            m = np.triu(m) + np.triu(m, 1).T
            np.testing.assert_allclose(ct.mass_matrix(q), m, rtol=0, atol=1e-12 * np.abs(m).max())


def test_computed_torque_compensates_the_drives_friction() -> None:
    """(20.6): the step with a drive is the rigid step plus I_a ⊙ a + b ⊙ q̇ +
    F ⊙ tanh(v / 0.01), v the slower of ẋ_c and q̇ where they agree in sign,
    else 0 (external mode: the reference moves at ẋ_c), and the keywords are
    refused by name when negative."""
    n = 7
    friction = np.linspace(0.5, 2.0, n)
    kw: dict[str, Any] = {
        "tau_max": np.full(n, 1e3),
        "impedance": "external",
        "Kp": 100.0,
        "Kd": 40.0,
    }
    rigid = ComputedTorque("panda", **kw)
    driven = ComputedTorque("panda", armature=0.1, damping=0.5, friction=friction, **kw)
    rng = np.random.default_rng(11)
    q, dq, xc = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    dxc, ddxc = np.linspace(-0.03, 0.03, n), rng.uniform(-1, 1, n)
    a = ddxc + 40.0 * (dxc - dq) + 100.0 * (xc - q)
    m = Measurement(q, dq)
    got = driven.step(m, xc=xc, dxc=dxc, ddxc=ddxc) - rigid.step(m, xc=xc, dxc=dxc, ddxc=ddxc)
    v = np.where(dq * dxc > 0, np.sign(dxc) * np.minimum(abs(dq), abs(dxc)), 0.0)
    assert 2 <= np.count_nonzero(v) <= n - 2  # joints with and against their reference
    want = 0.1 * a + 0.5 * dq + friction * np.tanh(v / 0.01)
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-10)
    for key in ("armature", "damping", "friction"):
        bad = np.zeros(n)
        bad[3] = -1.0
        with pytest.raises(ValueError, match=rf"{key} ≥ 0 is violated: {key}\[3\] = -1"):
            ComputedTorque("panda", **{key: bad}, **kw)


GRAVCOMP_MJCF = """<mujoco><option gravity='0.3 -0.2 -9.81'/><worldbody>
<body name='a' pos='0 0 0.1'><joint name='j1' axis='0 0 1'/><geom size='0.05' mass='1'/>
 <body name='b' pos='0.3 0 0' gravcomp='0.5'><joint name='j2' axis='0 1 0'/>
  <geom type='capsule' fromto='0 0 0 0.25 0 0' size='0.03' mass='2'/>
  <body name='held' pos='0.25 0 0' gravcomp='1'>
   <geom size='0.04' pos='0.02 0.01 0' mass='0.5'/></body>
  <body name='c' pos='0.25 0 0' gravcomp='0.2'><joint name='j3' axis='0 1 0'/>
   <geom type='box' size='0.1 0.02 0.02' pos='0.1 0 0' mass='0.7'/><site name='tip' pos='0.2 0 0'/>
  </body></body></body></worldbody>
<actuator><motor joint='j1' ctrlrange='-50 50'/><motor joint='j2' ctrlrange='-50 50'/>
<motor joint='j3' ctrlrange='-50 50'/></actuator></mujoco>"""


# Shares of both signs in one moving body: b lifts 0.5 × 2 kg, the welded
# body adds 2 × 0.5 kg: no net mass lifted, a couple (a first moment) left.
COUPLE_MJCF = GRAVCOMP_MJCF.replace(
    "name='held' pos='0.25 0 0' gravcomp='1'", "name='held' pos='0.25 0 0' gravcomp='-2'"
)


@pytest.mark.parametrize("xml", [GRAVCOMP_MJCF, COUPLE_MJCF], ids=["shares", "couple"])
def test_inverse_dynamics_takes_mujocos_gravity_compensation(xml: str) -> None:
    """A body's ``gravcomp`` lifts that share of its weight in the plant
    (MuJoCo's ``qfrc_gravcomp``, a passive force); computed torque's model
    lifts the same (SPEC (20.1')), a welded body with its own share folded
    in, shares of both signs too (a couple, no net mass): inverse dynamics is
    ``mj_inverse``'s to rounding. It was off by exactly ``qfrc_gravcomp``
    (1.3 N m on the UR-sized arm of the report)."""
    import mujoco

    assert xml.count("gravcomp='-2'") == (xml is COUPLE_MJCF)
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    ct = ComputedTorque(m, tip="tip")
    rng = np.random.default_rng(3)
    for _ in range(10):
        q, dq, ddq = rng.uniform(-2, 2, 3), rng.normal(size=3), rng.normal(size=3)
        d.qpos[:], d.qvel[:], d.qacc[:] = q, dq, ddq
        mujoco.mj_inverse(m, d)
        assert np.abs(d.qfrc_gravcomp).max() > 0.1
        want = d.qfrc_inverse
        got = ct.inverse_dynamics(q, dq, ddq)
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * np.abs(want).max())


def _opspace_lambda(D: np.ndarray, J: np.ndarray, uncoupled: bool) -> np.ndarray:
    """Λ as robosuite 1.5's ``opspace_matrices`` computes it (its lines, NumPy's
    ``pinv`` with its default rcond 1e-15), SPEC (23.7)."""
    Dinv = np.linalg.inv(D)
    if not uncoupled:
        return np.asarray(np.linalg.pinv(J @ Dinv @ J.T))
    lam = np.zeros((6, 6))
    for k in (0, 3):
        jk = J[k : k + 3]
        lam[k : k + 3, k : k + 3] = np.linalg.pinv(jk @ Dinv @ jk.T)
    return lam


def _kept_condition(A: np.ndarray, uncoupled: bool) -> float:
    """The condition number of J D⁻¹ Jᵀ (of its worse block, uncoupled) over
    the singular values the pseudo-inverse keeps (> 1e-15 σmax)."""
    worst = 1.0
    for b in (A[:3, :3], A[3:, 3:]) if uncoupled else (A,):
        s = np.linalg.svd(b, compute_uv=False)
        worst = max(worst, s[0] / s[s > 1e-15 * s[0]][-1])
    return float(worst)


@pytest.mark.parametrize("arm", sorted(ARMS))
def test_the_operational_inertia_is_robosuites_on_pinocchios_model(arm: str) -> None:
    """SPEC (23.7) in the core against robosuite's NumPy lines, on Pinocchio's
    mass matrix and tip Jacobian at random postures: the same Λ, coupled or
    not, to rounding (10 ε cond(J D⁻¹ Jᵀ), relative to Λ's largest entry: the
    two decompositions differ by 0.3–1.9 ε cond on these arms, where a wrong
    block or cut-off differs by O(1)). The two-link arm's Λ has rank 2: the
    same directions dropped."""
    model = pinocchio_model(ARMS[arm])
    data = model.createData()
    fid = model.nframes - 1
    rng = np.random.default_rng(20161116)
    for _ in range(10):
        q = _config(model, rng.uniform(-3, 3, model.nv))
        D = pin.crba(model, data, q)
        D = np.triu(D) + np.triu(D, 1).T
        J = pin.computeFrameJacobian(model, data, q, fid, pin.LOCAL_WORLD_ALIGNED)
        for uncoupled in (True, False):
            got = adaptimp._adaptimp.operational_inertia(J, D, uncoupled)
            want = _opspace_lambda(D, J, uncoupled)
            cond = _kept_condition(J @ np.linalg.inv(D) @ J.T, uncoupled)
            tol = 10 * np.finfo(np.float64).eps * cond * np.abs(want).max()
            np.testing.assert_allclose(got, want, rtol=0, atol=tol)
            assert np.array_equal(got, got.T)


def test_the_operational_inertia_refuses_by_name() -> None:
    oi = adaptimp._adaptimp.operational_inertia
    J, D = np.eye(6), np.eye(6)
    with pytest.raises(
        adaptimp.ConfigError, match=r"^jacobian must have shape \(6, n\), got shape \(5, 6\)$"
    ):
        oi(J[:5], D)
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^inertia must have shape \(6, 6\) \(n: the jacobian's columns\), "
        r"got shape \(5, 5\)$",
    ):
        oi(J, D[:5, :5])
    with pytest.raises(
        adaptimp.ConfigError, match=r"^jacobian: needs 6 × n values, row-major, n = 1 … 7 joints$"
    ):
        oi(np.zeros((6, 8)), np.eye(8))
    bad = D.copy()
    bad[2, 3] = np.nan
    with pytest.raises(
        adaptimp.ConfigError, match=r"^inertia\[15\] is not finite \(NaN or infinite\)$"
    ):
        oi(J, bad)
    bad = D.copy()
    bad[0, 1] = 0.5
    with pytest.raises(adaptimp.ConfigError, match=r"^inertia: must be symmetric"):
        oi(J, bad)
    with pytest.raises(adaptimp.ConfigError, match=r"^inertia: must be positive definite"):
        oi(J, -D)
