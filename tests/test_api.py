"""The Python API: shapes, dtypes, parameters, the controller's clock and state."""

from __future__ import annotations

import doctest
import json
import math
import threading
import time

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement, SimResult, _adaptimp
from adaptimp._params import ALL_GROUPS, names, resolve
from adaptimp._result import ARRAYS, METRIC_KEYS

PER_JOINT = ("q", "dq", "xc", "xd", "dq_hat", "tau", "tau_sat", "tau_e", "zeta", "z1")


@pytest.mark.parametrize("case", adaptimp.CASES)
def test_arrays_have_documented_shapes_and_dtypes(runs: dict[str, SimResult], case: str) -> None:
    res = runs[case]
    k = round(res.params["T"] / 50e-6)
    assert res.rows == k
    assert res.t.shape == (k,)
    for name in PER_JOINT:
        arr = getattr(res, name)
        assert arr.shape == (k, 2), name
        assert arr.dtype == np.float64, name
        assert arr.flags.c_contiguous, name
    assert res.w_norms.shape == (k, 3)
    assert res.w_norms.dtype == np.float64
    # t_k = k·Ts exactly, as the core computes it.
    np.testing.assert_array_equal(res.t, np.arange(k) * 50e-6)
    assert res.dtau.shape == (k, 2)
    assert res.case == case
    assert res.scenario == "paper"


def test_metrics_have_every_documented_key(runs: dict[str, SimResult]) -> None:
    for res in runs.values():
        assert set(res.metrics) == {*METRIC_KEYS, "rows"}
        for key in ("rms_z1_joint_after2", "max_abs_z1_joint_after2", "peak_abs_tau"):
            assert len(res.metrics[key]) == 2
        assert res.metrics["rows"] == res.rows


def test_pd_learns_nothing_and_adaptive_laws_learn(runs: dict[str, SimResult]) -> None:
    assert np.all(runs["pd"].w_norms == 0.0)
    for case in ("sf", "of"):
        w = runs[case].w_norms
        assert np.all(w[0] == 0.0)  # zero weights at t = 0 (SPEC §6)
        assert np.all(w[-1] > 0.0)


def test_state_feedback_uses_the_measured_velocity(runs: dict[str, SimResult]) -> None:
    np.testing.assert_array_equal(runs["sf"].dq_hat, runs["sf"].dq)
    # The observer's estimate differs from the true velocity (and starts at zero).
    of = runs["of"]
    assert np.all(of.dq_hat[0] == 0.0)
    assert not np.array_equal(of.dq_hat, of.dq)


def test_params_are_complete_and_json_serialisable(runs: dict[str, SimResult]) -> None:
    params = runs["sf"].params
    assert list(params) == names()
    assert json.loads(json.dumps(params)) == params
    assert params["T"] == 3.0  # the fixture's T, other values the paper's
    # Derived arm values are recorded as the numbers that ran.
    assert params["lc1"] == pytest.approx(0.35 / 2)
    assert params["I2"] == pytest.approx(0.85 * 0.31**2 / 4)


def test_paper_table_is_the_core_schema() -> None:
    """The Python keyword table and defaults are the core's schema, read at import."""
    core = _adaptimp.defaults("paper")
    assert list(core) == names(*ALL_GROUPS)
    table = resolve({}, scenario="paper", groups=ALL_GROUPS)
    for key, value in core.items():
        assert table[key] == value, key


def test_scalars_broadcast_to_every_joint_and_network() -> None:
    p = resolve({"Kp": 12, "gamma": 50.0, "q0": np.array([0.1, 0.2], dtype=np.float32)})
    assert p["Kp"] == [12.0, 12.0]
    assert p["gamma"] == [50.0, 50.0, 50.0]
    assert p["q0"] == pytest.approx([0.1, 0.2])
    assert resolve({"sigma": (0.1, 0.2, 0.3)})["sigma"] == [0.1, 0.2, 0.3]
    assert resolve({"Kp": np.float64(11.0)})["Kp"] == [11.0, 11.0]


def test_overrides_reach_the_run() -> None:
    res = adaptimp.simulate("pd", T=0.2, Kp=[10.5, 9.0], tau_max=[20.0, 16.0], wall=None)
    assert res.params["Kp"] == [10.5, 9.0]
    assert res.params["wall"] is None
    # Free space: no contact force, and xd follows xc (SPEC §4) up to the
    # first-order discretisation of the reference model (SPEC §11), O(Ts).
    assert np.all(res.tau_e == 0.0)
    assert res.metrics["steps_in_contact"] == 0
    np.testing.assert_allclose(res.xd, res.xc, atol=2e-5)
    assert np.max(np.abs(res.tau_sat[:, 0])) <= 20.0


def test_arm_defaults_derive_from_the_given_masses_and_lengths() -> None:
    arm = adaptimp.TwoLinkArm(m1=3.0, l1=0.5)
    p = arm.params
    assert p["lc1"] == 0.25
    assert p["I1"] == pytest.approx(3.0 * 0.25 / 4)
    explicit = adaptimp.TwoLinkArm(m1=3.0, l1=0.5, lc1=0.25, I1=3.0 * 0.25 / 4)
    q = [0.3, -0.7]
    np.testing.assert_array_equal(arm.D(q), explicit.D(q))
    # The plant of simulate() uses the arm parameters: a heavier arm tracks differently.
    light = adaptimp.simulate("pd", T=0.2)
    heavy = adaptimp.simulate("pd", T=0.2, m2=2.0)
    assert not np.allclose(light.q, heavy.q)


def test_arm_matches_the_spec_formulas() -> None:
    arm = adaptimp.TwoLinkArm()
    p1, p2, p3, p4, p5 = arm.lumped
    q, dq, g = np.array([0.4, -1.1]), np.array([0.7, -0.3]), 9.81
    c2, s2 = math.cos(q[1]), math.sin(q[1])
    D = [[p1 + p2 + 2 * p3 * c2, p2 + p3 * c2], [p2 + p3 * c2, p2]]
    C = [[-p3 * dq[1] * s2, -p3 * (dq[0] + dq[1]) * s2], [p3 * dq[0] * s2, 0.0]]
    G = [p4 * g * math.cos(q[0]) + p5 * g * math.cos(q[0] + q[1]), p5 * g * math.cos(q.sum())]
    np.testing.assert_allclose(arm.D(q), D, rtol=1e-14)
    np.testing.assert_allclose(arm.C(q, dq), C, rtol=1e-14)
    np.testing.assert_allclose(arm.G(q), G, rtol=1e-14)
    # (62) erratum: p4 = m1 lc1 + m2 l1.
    assert p4 == pytest.approx(2.0 * 0.175 + 0.85 * 0.35)
    tau, tau_e = np.array([3.0, -1.0]), np.array([2.0, 0.0])
    ddq = arm.forward_dynamics(q, dq, tau, tau_e)
    np.testing.assert_allclose(np.linalg.solve(D, tau - tau_e - np.dot(C, dq) - G), ddq)


def test_controller_keeps_its_clock_and_resets() -> None:
    ctrl = adaptimp.Controller("sf", Ts=1e-3, learning_step="normalized")
    assert (ctrl.t, ctrl.steps, ctrl.Ts, ctrl.case) == (0.0, 0, 1e-3, "sf")
    for _ in range(3):
        tau = ctrl.step(Measurement([0.25, -0.05], [0.0, 0.0], tau_e=[5.0, 0.0]))
    assert tau.shape == (2,)
    assert tau.dtype == np.float64
    assert ctrl.steps == 3
    assert ctrl.t == pytest.approx(3e-3)
    np.testing.assert_array_equal(ctrl.tau_sat, tau)
    np.testing.assert_allclose(ctrl.dtau, ctrl.tau_sat - ctrl.tau)
    w = ctrl.weights
    assert {k: v.shape for k, v in w.items()} == {"D": (2, 2, 256), "C": (2, 2, 256), "G": (2, 256)}
    assert all(np.any(v != 0.0) for v in w.values())
    ctrl.reset()
    assert (ctrl.t, ctrl.steps) == (0.0, 0)
    assert all(np.all(v == 0.0) for v in ctrl.weights.values())
    np.testing.assert_array_equal(ctrl.zeta, [0.0, 0.0])
    np.testing.assert_array_equal(ctrl.tau, [0.0, 0.0])


def test_controller_tracks_its_own_trajectory() -> None:
    ctrl = adaptimp.Controller("pd", xc_offset=[0.1, 0.3], xc_sin=0.0, xc_cos=0.0)
    ctrl.step(Measurement([0.0, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]))
    np.testing.assert_array_equal(ctrl.xc, [0.1, 0.3])
    np.testing.assert_array_equal(ctrl.xd, [0.1, 0.3])
    np.testing.assert_array_equal(ctrl.z1, [0.1, 0.3])


def test_controller_params_hold_only_controller_parameters() -> None:
    ctrl = adaptimp.Controller("of", Kp=10.5)
    assert list(ctrl.params) == names("controller")
    assert ctrl.params["Kp"] == [10.5, 10.5]
    ctrl.params["Kp"] = [0.0, 0.0]  # a copy: the controller is unaffected
    assert ctrl.params["Kp"] == [10.5, 10.5]
    assert "Controller('of'" in repr(ctrl)


def test_output_feedback_ignores_dq_and_estimates_the_velocity() -> None:
    a, b = adaptimp.Controller("of"), adaptimp.Controller("of")
    for k in range(50):
        q = [0.25 + 1e-4 * k, -0.05]
        np.testing.assert_array_equal(
            a.step(Measurement(q, tau_e=[0.0, 0.0])),
            b.step(Measurement(q, [9.0, 9.0], tau_e=[0.0, 0.0])),
        )
    np.testing.assert_array_equal(a.dq_hat, b.dq_hat)


@pytest.mark.parametrize(("hold", "gain"), [("zoh", 1 - 0.5**2 / 12), ("triangle", 1.0)])
def test_observer_estimates_a_ramp(hold: str, gain: float) -> None:
    """A ramp of 2 rad/s: the ZOH observer's sampled gain is 1 − (Ts/ε)²/12
    (README, observer.rs), the triangle hold's is 1."""
    ctrl = adaptimp.Controller("of", observer_init="first", observer_hold=hold)
    for k in range(2000):
        ctrl.step(Measurement([0.25 + 2.0 * k * 50e-6, -0.05], tau_e=[0.0, 0.0]))
    assert ctrl.dq_hat[0] == pytest.approx(2.0 * gain, rel=2e-3)
    assert ctrl.dq_hat[1] == pytest.approx(0.0, abs=1e-6)


def test_controller_matches_the_step_of_simulate(runs: dict[str, SimResult]) -> None:
    """Feeding the recorded measurements back reproduces the recorded commands."""
    res = runs["sf"]
    ctrl = adaptimp.Controller("sf")
    for k in range(200):
        tau_sat = ctrl.step(Measurement(res.q[k], res.dq[k], tau_e=res.tau_e[k]))
        np.testing.assert_array_equal(tau_sat, res.tau_sat[k])
        np.testing.assert_array_equal(ctrl.tau, res.tau[k])
        np.testing.assert_array_equal(ctrl.z1, res.z1[k])


def test_step_accepts_lists_tuples_and_any_real_array() -> None:
    ctrl = adaptimp.Controller("pd")
    a = ctrl.step(Measurement([0.25, -0.05], np.zeros(2, dtype=np.int64), tau_e=(0.0, 0.0)))
    ctrl.reset()
    b = ctrl.step(
        Measurement(
            np.array([0.25, -0.05, 9.0])[:2], np.zeros(4)[::2], tau_e=np.zeros(2, np.float32)
        )
    )
    np.testing.assert_array_equal(a, b)


def test_save_and_load_round_trip(runs: dict[str, SimResult], tmp_path) -> None:
    res = runs["of"]
    path = res.save(tmp_path / "run")
    assert path.name == "run.npz"
    back = SimResult.load(path)
    for name in ARRAYS:
        np.testing.assert_array_equal(getattr(back, name), getattr(res, name))
    assert back.params == res.params
    assert back.metrics == res.metrics
    assert (back.case, back.scenario) == ("of", "paper")
    # Readable without pickle.
    with np.load(path, allow_pickle=False) as f:
        assert json.loads(str(f["params"]))["Ts"] == 50e-6


def test_repr_summarises_the_run(runs: dict[str, SimResult]) -> None:
    text = repr(runs["sf"])
    assert "state feedback" in text
    assert "60000 steps" in text
    assert f"{runs['sf'].metrics['rms_z1_after2']:.4g} rad" in text


def test_short_runs_report_nan_for_the_after_window() -> None:
    res = adaptimp.simulate("pd", T=0.1)
    assert math.isnan(res.metrics["rms_z1_after2"])
    assert math.isnan(res.metrics["imp_err_rms_after2"])
    assert not math.isnan(res.metrics["rms_z1"])


def test_metrics_table_lists_every_run(runs: dict[str, SimResult]) -> None:
    table = adaptimp.metrics_table(runs.values())
    lines = table.splitlines()
    header = [c.strip() for c in lines[0].strip("|").split("|")]
    assert header == ["metric (SPEC §12)", "PD", "state feedback", "output feedback"]
    assert len(lines) == 2 + 11
    rms = f"{runs['pd'].metrics['rms_z1_after2']:.5f}"
    assert rms in table


def test_simulate_releases_the_gil() -> None:
    """Python code runs in another thread while the core simulates."""
    window: list[float] = []

    def run() -> None:
        window.append(time.perf_counter())
        adaptimp.simulate("sf", T=4.0)
        window.append(time.perf_counter())

    worker = threading.Thread(target=run)
    ticks: list[float] = []
    worker.start()
    while worker.is_alive():
        ticks.append(time.perf_counter())
    worker.join()
    start, end = window
    assert end - start > 0.02
    # With the GIL held for the whole run this thread could not tick inside it.
    inside = [t for t in ticks if start + 0.3 * (end - start) < t < end - 0.3 * (end - start)]
    assert len(inside) > 100


def test_docstring_examples_run() -> None:
    from adaptimp import _api

    result = doctest.testmod(_api, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 3
    assert result.failed == 0
