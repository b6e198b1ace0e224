"""adaptimp.CartesianController in the core's closed loop on MuJoCo (SPEC §13.1,
§16): stepped natively it equals the same controller called back through its Python
``step`` bit for bit (every row, the task-space rows, the metrics, the controller
left behind), with disturbances and faults, and an exploding run raises."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest

import adaptimp
from adaptimp import _models
from adaptimp import mujoco as amj
from adaptimp.scenarios import panda_table as apt

_ARRAYS = (
    "t", "q", "dq", "ddq", "xc", "dxc", "ddxc", "xd", "dq_hat", "tau", "tau_sat", "tau_e",
    "zeta", "z1", "x_ee", "wrench_ee",
)  # fmt: skip
_ATTRS = ("xc", "dxc", "ddxc", "xd", "z1", "force", "tau", "q_d", "_k")


class _InPython:
    """A CartesianController behind a Python object: the core's loop calls its
    Python ``step`` back once a period."""

    def __init__(self, inner: adaptimp.CartesianController) -> None:
        self.inner = inner

    def step(self, *args: Any, **kwargs: Any) -> Any:
        return self.inner.step(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


def _assert_same_run(
    got: amj.MujocoResult,
    want: amj.MujocoResult,
    a: adaptimp.CartesianController,
    b: adaptimp.CartesianController,
    every: int = 1,
) -> None:
    """Every row, task row and metric, and the two controllers left behind (whose
    logs hold every step taken through ``step``, the kept rows of the native run)."""
    for name in _ARRAYS:
        np.testing.assert_array_equal(getattr(got, name), getattr(want, name), err_msg=name)
    assert got.task is not None
    assert want.task is not None
    assert set(got.task) == set(want.task)
    for name, value in want.task.items():
        np.testing.assert_array_equal(got.task[name], value, err_msg=name)
    assert set(got.metrics) == set(want.metrics)
    for key, value in want.metrics.items():
        np.testing.assert_array_equal(got.metrics[key], value, err_msg=key)
    for name in _ATTRS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    for name, value in b.arrays().items():
        np.testing.assert_array_equal(a.arrays()[name], value[::every], err_msg=name)
    np.testing.assert_array_equal(a.outer.core.state("q_d"), b.outer.core.state("q_d"))
    np.testing.assert_array_equal(a.inner.zeta, b.inner.zeta)
    np.testing.assert_array_equal(a.inner.weights["G"], b.inner.weights["G"])


@pytest.fixture(scope="module")
def sc() -> apt.PandaTable:
    return apt.panda_table()


@pytest.fixture(scope="module")
def basis(sc: apt.PandaTable) -> tuple[np.ndarray, np.ndarray]:
    return apt.orbit_basis(sc)


@pytest.mark.filterwarnings("ignore:the (torque was|commanded torque):adaptimp.PlantWarning")
@pytest.mark.parametrize("kind", ["pd", "sf", "of"])
def test_the_panda_table_runs_natively_and_equals_the_callback(
    sc: apt.PandaTable, basis: Any, kind: str
) -> None:
    """The scenario of examples/13 (the Panda's tool pressing on the table along its
    path): natively and called back, the same bits, and the Cartesian metrics
    of docs/panda.md from the rows of either."""
    native_ctrl = apt.panda_controller(kind, sc, basis=basis)
    python_ctrl = apt.panda_controller(kind, sc, basis=basis)
    native = amj.simulate(native_ctrl, amj.Plant(sc.model), T=1.5, q0=sc.q0)
    python = amj.simulate(_InPython(python_ctrl), amj.Plant(sc.model), T=1.5, q0=sc.q0)
    assert native.params["loop"] == "native"
    assert python.params["loop"] == "callback"
    _assert_same_run(native, python, native_ctrl, python_ctrl)
    assert native.metrics["steps_in_contact"] > 50
    assert native.xc.shape == native.z1.shape == (1500, 3)
    # Task space: xc, xd and z1 are p_c, p_d and p_d − p(q) (m).
    assert native.task is not None
    np.testing.assert_array_equal(native.xc, native.task["pc"])
    np.testing.assert_array_equal(native.xd, native.task["pd"])
    p = np.array([sc.fk(q) for q in native.q])
    np.testing.assert_allclose(native.z1, native.task["pd"] - p, rtol=0, atol=1e-15)
    # The joint controller's own quantities (ζ, its weights) are recorded natively.
    assert kind == "pd" or native.w_norms[-1, 2] > 0
    got = apt.cartesian_metrics(native, native_ctrl, sc, settle=1.0)
    assert got == apt.cartesian_metrics(python, python_ctrl, sc, settle=1.0)
    assert all(math.isfinite(v) for v in got.values())


def test_a_python_joint_controller_is_called_back(sc: apt.PandaTable) -> None:
    """A joint controller with a ``step`` of its own (here computed torque's,
    wrapped in Python) behind the core's outer loop: the core's loop calls the
    Cartesian controller back, and it gives computed torque's run; the core's
    own is native."""
    from adaptimp.baselines import ComputedTorque

    class Own(ComputedTorque):
        def step(self, *args: Any, **kwargs: Any) -> Any:
            return super().step(*args, **kwargs)

    inner = Own(sc.pin_model, Ts=sc.Ts, tau_max=sc.tau_max, impedance="external")
    ctrl = adaptimp.CartesianController(
        sc.chain, inner, q0=sc.q0, path=sc.path, Kd_rot=0.0, force_feedforward=True
    )
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=0.05, q0=sc.q0)
    assert res.params["loop"] == "callback"
    core = amj.simulate(apt.panda_controller("ct", sc), amj.Plant(sc.model), T=0.05, q0=sc.q0)
    assert core.params["loop"] == "native"
    np.testing.assert_array_equal(res.tau_sat, core.tau_sat)
    assert res.task is not None
    np.testing.assert_array_equal(res.xc, res.task["pc"])


def _two_link() -> tuple[mujoco.MjModel, adaptimp.Chain, np.ndarray, np.ndarray]:
    model = amj.two_link()
    chain = adaptimp.Chain.from_mujoco(model, "ee")
    q0 = np.array([0.25, -0.05])
    return model, chain, q0, chain.pose(q0)[0]


def _up(p0: np.ndarray) -> Any:
    """The tip up at 0.1 m/s for 1 s, then held: into the ceiling."""

    def path(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = min(t, 1.0)
        v = 0.1 if t < 1.0 else 0.0
        return p0 + np.array([0.0, 0.0, 0.1 * s]), np.array([0.0, 0.0, v]), np.zeros(3)

    return path


@pytest.mark.parametrize("case", ["pd", "sf", "of"])
def test_two_joints_against_the_ceiling_with_a_reference(case: str) -> None:
    """Two joints (the Cartesian task has more rows than joints), the commanded
    pose from simulate's reference, every third row kept: the same bits."""
    model, chain, q0, p0 = _two_link()

    def make() -> adaptimp.CartesianController:
        return adaptimp.CartesianController(chain, case, q0=q0, Kd_rot=0.0, tau_max=[17.0, 15.0])

    a, b = make(), make()
    kw: dict[str, Any] = {"T": 1.5, "reference": _up(p0), "q0": q0, "record_every": 3}
    native = amj.simulate(a, model, **kw)
    python = amj.simulate(_InPython(b), model, **kw)
    assert native.params["loop"] == "native"
    _assert_same_run(native, python, a, b, every=3)
    assert native.rows == 500
    assert case == "pd" or native.metrics["steps_in_contact"] > 20
    np.testing.assert_array_equal(native.dxc[:10], np.tile([0.0, 0.0, 0.1], (10, 1)))


def test_a_held_target_and_a_used_controller() -> None:
    """No path and no reference: the start pose held (xc = the filtered target,
    at rest); a second run goes on from the first's state and clock, natively
    and called back."""
    model, chain, q0, _ = _two_link()

    def make() -> adaptimp.CartesianController:
        return adaptimp.CartesianController(
            chain, "sf", q0=q0, Kd_rot=0.0, tau_max=[17.0, 15.0], path=None
        )

    a, b = make(), make()
    for _ in range(2):
        native = amj.simulate(a, model, T=0.4, q0=q0, contact=False)
        python = amj.simulate(_InPython(b), model, T=0.4, q0=q0, contact=False)
        _assert_same_run(native, python, a, b)
    assert a._k == 800
    assert np.all(native.dxc == 0.0)
    assert len(a.arrays()["pc"]) == 800


@pytest.mark.filterwarnings("ignore:the (torque was|commanded torque):adaptimp.PlantWarning")
def test_a_path_goes_on_along_the_controllers_clock(sc: apt.PandaTable, basis: Any) -> None:
    """A used controller's path is sampled at its own t_k, natively and called back."""
    a = apt.panda_controller("sf", sc, basis=basis)
    b = apt.panda_controller("sf", sc, basis=basis)
    plant = amj.Plant(sc.model)
    for _ in range(2):
        native = amj.simulate(a, plant, T=0.3, q0=sc.q0)
        python = amj.simulate(_InPython(b), plant, T=0.3, q0=sc.q0)
        _assert_same_run(native, python, a, b)
    np.testing.assert_array_equal(native.xc[0], sc.path(0.3)[0])


def test_six_d_turning_the_panda_equals_the_callback() -> None:
    """The 6-D loop (orientation a task, the path giving R_c, ω_c): the same bits."""
    model = amj.panda(table_height=None)
    model.opt.gravity[:] = 0.0
    chain = adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip=_models.PANDA_EE)
    home = np.array(_models.PANDA_HOME)
    p0, r0 = chain.pose(home)
    c, s = math.cos(0.35), math.sin(0.35)
    rc = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ r0
    pc = p0 + np.array([0.0, 0.04, -0.02])
    z3 = np.zeros(3)

    def make() -> adaptimp.CartesianController:
        return adaptimp.CartesianController(
            chain, "pd", q0=home, path=lambda t: (pc, z3, z3, rc, z3, z3),
            tau_max=list(_models.PANDA_EFFORT), Kp=[60.0] * 4 + [10.0] * 3, Kzeta=2000.0,
            K1=20.0, target_filter=0.2,
            centers=np.concatenate([home, np.zeros(21)])[None], widths=np.ones(28),
        )  # fmt: skip

    a, b = make(), make()
    native = amj.simulate(a, amj.Plant(model, contact=False), T=0.5, q0=home)
    python = amj.simulate(_InPython(b), amj.Plant(model, contact=False), T=0.5, q0=home)
    assert native.params["loop"] == "native"
    _assert_same_run(native, python, a, b)
    # The orientation is a task: the tool turned by 0.35 rad about z (0.1 rad so far).
    r = chain.pose(native.q[-1])[1] @ r0.T
    assert math.acos(min(1.0, (np.trace(r) - 1) / 2)) > 0.1


def test_the_replay_gives_the_runs_torques(sc: apt.PandaTable, basis: Any) -> None:
    """CartesianImpedance.replay: the core's steps over a run's rows give its
    torques again (the controller's cost without a plant, benches/mujoco_loop.py)."""
    ctrl = apt.panda_controller("of", sc, basis=basis)
    targets = ctrl.commanded_poses(400, None)
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=0.4, q0=sc.q0)
    assert res.task is not None
    again = apt.panda_controller("of", sc, basis=basis)
    tau = again.outer.core.replay(again.inner, res.q, res.dq, res.task["wrench"], targets)
    np.testing.assert_array_equal(tau, res.tau_sat)
    with pytest.raises(adaptimp.MeasurementError, match=r"targets must have shape \(400, 24\)"):
        again.outer.core.replay(again.inner, res.q, res.dq, res.task["wrench"], targets[:9])


@pytest.mark.filterwarnings("ignore:the (torque was|commanded torque):adaptimp.PlantWarning")
def test_disturbances_and_faults_act_on_a_cartesian_run(sc: apt.PandaTable, basis: Any) -> None:
    """SPEC §17 on the Cartesian loop: the wrench is delayed with the joint sample,
    a stale sensor freezes it, a NaN burst is refused with the joint controller's
    fallback; what acts on τe alone (which a Cartesian controller does not read)
    is refused by name."""

    def run(**kw: Any) -> amj.MujocoResult:
        ctrl = apt.panda_controller("sf", sc, basis=basis)
        return amj.simulate(ctrl, amj.Plant(sc.model), T=1.2, q0=sc.q0, **kw)

    base = run()
    # The table's controller is made for the robot preset's delay of 1 (SPEC (18.11)).
    with pytest.warns(adaptimp.PlantWarning, match="made for a loop delay of 1 period"):
        late = run(delay=3)
    assert late.task is not None
    assert base.task is not None
    np.testing.assert_array_equal(late.task["wrench"][3:], late.wrench_ee[:-3])
    np.testing.assert_array_equal(late.task["wrench"][:3], np.tile(late.wrench_ee[0], (3, 1)))
    assert not np.array_equal(late.tau, base.tau)
    assert np.any(late.wrench_ee[:, 2] != 0.0)
    noisy = run(noise_q=1e-4, seed=3)
    assert not np.array_equal(noisy.tau, base.tau)
    stale = run(fault=adaptimp.Fault("stale", 1.0, 0.05))
    assert stale.task is not None
    k = 1000
    frozen = stale.task["wrench"][k : k + 50]
    np.testing.assert_array_equal(frozen, np.tile(stale.wrench_ee[k - 1], (50, 1)))
    burst = run(fault=adaptimp.Fault("nan_burst", 1.0, 0.01))
    assert burst.refused is not None
    assert int(np.sum(burst.refused)) == 10
    assert np.all(np.isfinite(burst.tau_sat))
    with pytest.raises(adaptimp.ConfigError, match="noise_tau_e: a Cartesian controller reads"):
        run(noise_tau_e=0.1)
    with pytest.raises(adaptimp.ConfigError, match="force_bias: a Cartesian controller reads"):
        run(fault=adaptimp.Fault("force_bias", 0.5, 0.1, bias=[1.0] * 7))


_FEATHER = """<mujoco><option integrator="RK4" timestep="0.001"/><worldbody>
<body><joint name="j" type="hinge" axis="0 1 0"/><geom type="sphere" size=".01" mass="1e-6"/>
<site name="ee" pos="0.1 0 0"/></body></worldbody>
<actuator><motor joint="j" ctrlrange="-1e6 1e6" ctrllimited="true"/></actuator></mujoco>"""
"""A 1 mg arm with a 1 MN m motor: full torque is q̈ ~ 1e12 rad/s², beyond MuJoCo's bound."""


def test_an_exploding_cartesian_run_raises_and_names_the_row(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """MuJoCo resets a diverged state and only warns: the native Cartesian run
    raises DivergedError with the row, the time and MuJoCo's words, as the run
    calling it back does, and the controller's clock is that of the steps it took."""
    monkeypatch.chdir(tmp_path)  # MuJoCo writes its warnings to MUJOCO_LOG.TXT here
    model = mujoco.MjModel.from_xml_string(_FEATHER)
    chain = adaptimp.Chain.from_mujoco(model, "ee")

    def jump(t: float) -> tuple[list[float], list[float], list[float]]:
        return ([0.1, 0.0, 0.0 if t < 0.0045 else -0.05], [0.0] * 3, [0.0] * 3)

    def make() -> adaptimp.CartesianController:
        return adaptimp.CartesianController(
            chain, "pd", q0=[0.0], Kd_rot=0.0, tau_max=1e6, Kp=1e4, Kzeta=6e7, Kd=1e6,
            centers=np.zeros((1, 4)), widths=1.0,
        )  # fmt: skip

    a, b = make(), make()
    errors = []
    for ctrl in (a, _InPython(b)):
        with pytest.raises(adaptimp.DivergedError) as e:
            amj.simulate(ctrl, model, T=1.0, reference=jump, q0=[0.0])
        errors.append(str(e.value))
    assert errors[0] == errors[1]
    assert errors[0].startswith("the MuJoCo plant diverged in the period of row 6 (t = 0.006 s")
    assert "MuJoCo warned mjWARN_BADQACC" in errors[0]
    # Both controllers are left after the same steps, their last one's attributes set.
    assert a._k == b._k == 7
    for name in _ATTRS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_a_reference_given_as_arrays(sc: apt.PandaTable, basis: Any) -> None:
    """simulate(reference=(xc, dxc, ddxc)) tabulated at k·Ts: the run of the same
    reference as a callable, natively and called back, joint space and task space."""
    steps = 300
    rows = [sc.path(k * sc.Ts) for k in range(steps + 5)]
    table = tuple(np.array([r[i] for r in rows]) for i in range(3))

    def reference(t: float) -> Any:
        return sc.path(t)

    def make() -> adaptimp.CartesianController:
        ctrl = apt.panda_controller("sf", sc, basis=basis)
        ctrl.path = None  # the reference of simulate instead
        return ctrl

    plant = amj.Plant(sc.model)
    runs = []
    for ref in (table, reference):
        for native in (True, False):
            ctrl = make()
            res = amj.simulate(
                ctrl if native else _InPython(ctrl), plant, T=0.3, q0=sc.q0, reference=ref
            )
            assert res.params["loop"] == ("native" if native else "callback")
            runs.append((ctrl, res))
    for ctrl, res in runs[1:]:
        _assert_same_run(res, runs[0][1], ctrl, runs[0][0])
    # Joint space: the native loop with a table is the one with the callable.
    q0 = np.array([0.25, -0.05])
    joint = tuple(np.tile(v, (steps, 1)) for v in (q0, np.zeros(2), np.zeros(2)))
    a = amj.simulate(adaptimp.Controller("pd", "robot"), "two_link", T=0.3, reference=joint)
    b = amj.simulate(
        adaptimp.Controller("pd", "robot"), "two_link", T=0.3,
        reference=lambda t: (q0, np.zeros(2), np.zeros(2)),
    )  # fmt: skip
    for name in _ARRAYS:
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    with pytest.raises(ValueError, match=r"reference dxc must have shape \(K, 2\) with K ≥ 300"):
        amj.simulate("pd", "two_link", T=0.3, reference=(joint[0], joint[1][:10], joint[2]))
    with pytest.raises(TypeError, match="reference must be a callable t -> "):
        amj.simulate("pd", "two_link", T=0.3, reference=joint[:2])
    # A Cartesian controller's reference is its p_c: three columns.
    with pytest.raises(ValueError, match=r"reference xc must have shape \(K, 3\)"):
        amj.simulate(make(), plant, T=0.3, q0=sc.q0, reference=joint)
    bad = joint[0].copy()
    bad[7, 1] = math.nan
    with pytest.raises(ValueError, match="reference xc must be finite"):
        amj.simulate("pd", "two_link", T=0.3, reference=(bad, joint[1], joint[2]))


def test_a_long_run_in_parts_is_the_whole_run(sc: apt.PandaTable, basis: Any) -> None:
    """reset=False: the plant goes on from where the last part left it, the used
    controller along its path: two parts give the rows of one run, bit for bit."""
    plant = amj.Plant(sc.model)
    whole_ctrl = apt.panda_controller("sf", sc, basis=basis)
    whole = amj.simulate(whole_ctrl, plant, T=1.4, q0=sc.q0)
    ctrl = apt.panda_controller("sf", sc, basis=basis)
    first = amj.simulate(ctrl, plant, T=0.7, q0=sc.q0)
    second = amj.simulate(ctrl, plant, T=0.7, reset=False)
    for name in _ARRAYS[1:]:
        got = np.concatenate([getattr(first, name), getattr(second, name)])
        np.testing.assert_array_equal(got, getattr(whole, name), err_msg=name)
    np.testing.assert_array_equal(second.t, first.t)
    assert whole.metrics["steps_in_contact"] > 0
    for name, value in whole_ctrl.arrays().items():
        np.testing.assert_array_equal(ctrl.arrays()[name], value, err_msg=name)
    with pytest.raises(ValueError, match="q0, dq0 and a payload start a run afresh"):
        amj.simulate(ctrl, plant, T=0.1, q0=sc.q0, reset=False)


@pytest.mark.parametrize("options", [{}, {"every": 3}, {"compress": False}])
def test_a_cartesian_run_saves_its_task_rows(
    sc: apt.PandaTable, basis: Any, tmp_path: Path, options: dict[str, Any]
) -> None:
    """A MuJoCo result keeps, through save and load, the end effector's position
    and wrench and the task-space rows (the Cartesian metrics read them)."""
    ctrl = apt.panda_controller("sf", sc, basis=basis)
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=0.2, q0=sc.q0)
    assert res.task is not None
    assert res.x_ee is not None
    assert res.wrench_ee is not None
    back = amj.MujocoResult.load(res.save(tmp_path / "run", **options))
    k = options.get("every", 1)
    np.testing.assert_array_equal(back.x_ee, res.x_ee[::k])
    np.testing.assert_array_equal(back.wrench_ee, res.wrench_ee[::k])
    assert back.task is not None
    assert sorted(back.task) == sorted(res.task)
    for name, rows in res.task.items():
        np.testing.assert_array_equal(back.task[name], rows[::k], err_msg=name)
