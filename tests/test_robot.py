"""The robot scenario (SPEC §13): the hardened options from Python, and replay."""

from __future__ import annotations

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement, _adaptimp
from adaptimp._params import ALL_GROUPS, resolve


@pytest.fixture(scope="module")
def robot() -> dict[str, adaptimp.SimResult]:
    return {case: adaptimp.simulate(case, scenario="robot") for case in ("sf", "of")}


def test_robot_table_is_the_core_schema() -> None:
    core = _adaptimp.defaults("robot")
    table = resolve({}, scenario="robot", groups=ALL_GROUPS)
    assert table == core
    assert table["Ts"] == 1e-3
    assert table["substeps"] == 10
    assert table["weight_bound"] == "auto"


@pytest.mark.parametrize(("case", "target"), [("sf", 0.010), ("of", 0.030)])
def test_robot_scenario_meets_its_targets(
    robot: dict[str, adaptimp.SimResult], case: str, target: float
) -> None:
    r = robot[case]
    m = r.metrics
    assert r.t.shape == (20_000,)
    assert m["rms_z1_after2"] <= target
    assert m["sat_duty"] <= 0.35
    # |τ_i| ≤ 2 τmax_i after the first step; the first is (14) at the paper's
    # initial state, 0.05 rad inside the wall (docs/robot.md).
    tau_max = np.array(r.params["tau_max"])
    assert np.all(np.abs(r.tau[1:]) <= 2 * tau_max)
    first = -0.25 - 15.0 - 0.5 * np.tanh(1.5 / 0.05) + 50.0
    if case == "of":
        # Output feedback compares with α1 the observer's lag L back, SPEC (9.1),
        # along the commanded motion, (9.2): Kp L α̇1° less, α̇1°(0) = ẍc(0) =
        # 0.2π² on joint 1 (not ẍd(0), which holds the wall's −τe/Dd of this
        # sample), and L = 0.526 Ts at Ts/ε = 10.
        lag = (first - r.tau[0, 0]) / (10.0 * 0.2 * np.pi**2)
        assert lag / 1e-3 == pytest.approx(0.5263, abs=1e-4)
    else:
        assert r.tau[0, 0] == pytest.approx(first)
    # The projection holds every network within its bound.
    assert np.all(r.w_norms <= np.array(r.params["weight_bound"]) * (1 + 1e-12))


def test_printed_laws_at_1khz_wind_up() -> None:
    # The StabilityWarning foretells it: the per-step learning gain exceeds Kp.
    with pytest.warns(adaptimp.StabilityWarning, match=r"exceeds Kp = 10 .*scenario='robot'"):
        r = adaptimp.simulate("sf", Ts=1e-3, substeps=10, T=5.0)
    assert r.metrics["sat_duty"] > 0.9
    assert np.max(np.abs(r.tau)) > 1e3


def _bound(**params: object) -> np.ndarray:
    """The weight bound the core resolved for a robot controller with ``params``."""
    return np.array(adaptimp.Controller("sf", scenario="robot", **params).params["weight_bound"])


def test_auto_weight_bound_follows_the_limits_and_the_trajectory() -> None:
    paper = _bound()
    assert paper == pytest.approx([0.71785, 2.25518, 1.41697], rel=1e-5)
    assert _bound(tau_max=[34.0, 30.0]) == pytest.approx(2 * paper)
    # Twice the speed: Ĉ's bound halves, D̂'s (acceleration, ω²) quarters.
    assert _bound(xc_omega=2 * np.pi) == pytest.approx(paper / [4, 2, 1])
    # A trajectory that does not move uses unit rates.
    assert _bound(xc_omega=0.0)[:2] == pytest.approx([paper[2]] * 2)
    # simulate() resolves "auto" the same way, and records the numbers.
    r = adaptimp.simulate("sf", scenario="robot", T=0.01, xc_omega=6.0)
    assert r.params["weight_bound"] == pytest.approx(_bound(xc_omega=6.0))
    assert r.params["weight_bound"][0] == pytest.approx(paper[0] * (np.pi / 6) ** 2)


def test_hardened_options_are_validated() -> None:
    with pytest.raises(ValueError, match="weight_bound must be None, 'auto' or numbers"):
        adaptimp.Controller("sf", weight_bound="automatic")
    with pytest.raises(ValueError, match=r"weight bound > 0"):
        adaptimp.Controller("sf", weight_bound=[1.0, -1.0, 1.0])
    with pytest.raises(ValueError, match="κ ≤ 1"):
        adaptimp.Controller("sf", learning_step="normalized", kappa=2.0)
    with pytest.raises(ValueError, match="learning_step must be one of"):
        adaptimp.Controller("sf", learning_step="adam")
    # The options reach the core: a bound this small pins the weights to it.
    c = adaptimp.Controller("sf", Ts=1e-3, weight_bound=1e-3, learning_step="normalized")
    for _ in range(50):
        c.step(Measurement([0.1, 0.3], [0.2, -0.1], tau_e=[0.0, 0.0]))
    assert np.linalg.norm(c.weights["G"]) == pytest.approx(1e-3)


def _log(k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t = np.arange(k)[:, None] * 1e-3
    q = np.hstack([0.2 + 0.1 * np.sin(3 * t), 0.1 * np.cos(2 * t)])
    dq = np.hstack([0.3 * np.cos(3 * t), -0.2 * np.sin(2 * t)])
    tau_e = np.hstack([np.maximum(0.0, 1000 * (q[:, :1] - 0.2)), np.zeros((k, 1))])
    return q, dq, tau_e


@pytest.mark.parametrize("case", ["pd", "sf", "of"])
def test_replay_equals_a_step_loop(case: str) -> None:
    q, dq, tau_e = _log(300)
    a = adaptimp.Controller(case, scenario="robot")
    b = adaptimp.Controller(case, scenario="robot")
    stepped = np.array([a.step(Measurement(q[k], dq[k], tau_e=tau_e[k])) for k in range(len(q))])
    replayed = b.replay(q, tau_e, dq)
    assert replayed.shape == (300, 2)
    np.testing.assert_array_equal(replayed, stepped)
    np.testing.assert_array_equal(a.weights["D"], b.weights["D"])
    assert a.t == b.t


def test_replay_errors_name_the_shape_and_the_row() -> None:
    q, dq, tau_e = _log(10)
    c = adaptimp.Controller("sf")
    with pytest.raises(ValueError, match=r"tau_e must have shape \(K, 2\)"):
        c.replay(q, tau_e[:, :1], dq)
    with pytest.raises(ValueError, match=r"tau_e must have shape \(10, 2\) like q"):
        c.replay(q, tau_e[:5], dq)
    with pytest.raises(TypeError, match="array of real numbers"):
        c.replay(q.astype(str), tau_e, dq)
    q[3, 1] = np.nan
    with pytest.raises(ValueError, match=r"row 3: q\[1\] is not finite"):
        c.replay(q, tau_e, dq)
    assert c.steps == 3  # the rows before the bad one were stepped
    with pytest.raises(ValueError, match="row 0: this controller uses the measured velocity"):
        adaptimp.Controller("sf").replay(q[:2], tau_e[:2])
