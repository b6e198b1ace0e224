"""The gain and basis rule of SPEC §18 (the core's ``control::tuning``, through
``adaptimp.tuning``): it follows its equations, and construction accepts what
it returns for any serial arm of 1 to 7 joints, any τmax and any Ts."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import adaptimp
from adaptimp import Measurement, tuning


def _swing(q0: np.ndarray, amp: float = 0.2, w: float = math.pi) -> Any:
    """xc = q0 − A cos(ωt) on every joint (the default task's shape)."""
    ones = np.ones_like(q0)
    return lambda t: (
        q0 - amp * np.cos(w * t),
        amp * w * np.sin(w * t) * ones,
        amp * w * w * np.cos(w * t) * ones,
    )


def test_suggest_follows_the_rule() -> None:
    arm = adaptimp.PlanarArm(3, masses=[2.0, 1.5, 1.0], lengths=[0.4, 0.35, 0.25])
    q0 = np.array([0.3, 0.3, 0.3])
    path = _swing(q0)
    kw = tuning.suggest(arm, q0, [60.0, 30.0, 15.0], Ts=1e-3, path=path, period=2.0)
    # (18.1): the mean along the path (50 postures) of 1/(D⁻¹)_ii, shrunk if
    # needed so that λmax(D⁻¹ diag(d)) ≤ n at each of them (here it is not).
    ds = [arm.D(path(2.0 * k / 50)[0]) for k in range(50)]
    d = np.mean([1.0 / np.diag(np.linalg.inv(m)) for m in ds], axis=0)
    worst = max(np.max(np.linalg.eigvals(np.linalg.solve(m, np.diag(d))).real) for m in ds)
    assert worst < 3
    np.testing.assert_allclose(kw["inertia"], d, rtol=1e-12)
    np.testing.assert_allclose(kw["Kp"], 0.25 * d / 1e-3, rtol=1e-12)  # (18.1)
    assert kw["K1"] == [50.0] * 3  # (18.2): min(50, 0.05/Ts)
    assert kw["Kzeta"] == [250.5] * 3  # (18.3): Kp/d + ρ/2
    assert kw["conditions"] == "scaled"
    # SPEC (10.3), with the margin Kp/d of the rule.
    kp, kz = np.array(kw["Kp"]), np.array(kw["Kzeta"])
    np.testing.assert_allclose(2 * kz - 1.0 - kp / d, 250.0, rtol=1e-12)
    # Centres along the path: L = ⌈2 · 4 · 0.2 · √3 / 0.2⌉ = 14 → 16, on q, q̇ only.
    assert kw["centers"].shape == (16, 12)
    assert np.all(np.isinf(kw["widths"][6:]))
    # Learning (18.6): Ĝ's bandwidth ω² = ½ (Kp/d) K1 = 6250 s⁻², D̂ and Ĉ
    # 25 times less in ω²; the leak after 25 periods.
    gamma, sigma = np.array(kw["gamma"]), np.array(kw["sigma"])
    np.testing.assert_allclose(gamma * sigma * 25 * 2.0, 1.0, rtol=1e-12)
    assert gamma[2] > 0
    assert np.all(np.array(kw["weight_bound"]) > 0)
    for case in adaptimp.CASES:
        adaptimp.Controller(case, "robot", **kw)


def test_centres_that_span_the_orbit() -> None:
    # SPEC (19.11): given one period of the motion that repeats, the widths in
    # q are at least its diameter; the centres, their number and q̇'s widths
    # are the rule's, and Ĝ's rate is normalised on the wider basis.
    arm = adaptimp.PlanarArm(3, masses=[2.0, 1.5, 1.0], lengths=[0.4, 0.35, 0.25])
    q0 = np.array([0.3, 0.3, 0.3])
    args = (arm, q0, [60.0, 30.0, 15.0])
    opts: dict[str, Any] = {"Ts": 1e-3, "path": _swing(q0), "period": 2.0}
    rule = tuning.suggest(*args, **opts)
    # A circle of radius 0.4 rad in joints 1 and 2: diameter 0.8 rad.
    phi = np.linspace(0.0, 2 * math.pi, 400, endpoint=False)
    orbit = q0 + 0.4 * np.stack([np.cos(phi), np.sin(phi), 0 * phi], axis=1)
    wide = tuning.suggest(*args, **opts, orbit=orbit)
    assert rule["widths"][0] < 0.8
    np.testing.assert_allclose(wide["widths"][:3], 0.8, rtol=1e-12)
    np.testing.assert_array_equal(wide["widths"][3:], rule["widths"][3:])
    np.testing.assert_array_equal(wide["centers"], rule["centers"])
    assert wide["gamma"][2] < rule["gamma"][2]
    assert wide["Kp"] == rule["Kp"]
    assert wide["K1"] == rule["K1"]
    # An orbit inside the rule's widths changes nothing.
    small = tuning.suggest(*args, **opts, orbit=q0 + 0.01 * np.eye(3))
    for key in ("centers", "widths", "gamma", "sigma", "weight_bound"):
        np.testing.assert_array_equal(small[key], rule[key])
    adaptimp.Controller("sf", "robot", **wide)
    with pytest.raises(adaptimp.ConfigError, match="orbit must have shape"):
        tuning.suggest(*args, **opts, orbit=orbit[:, :2])
    bad = orbit.copy()
    bad[3, 1] = np.nan
    with pytest.raises(
        adaptimp.ConfigError, match=r"^orbit must be finite \(rad\), got NaN at row 3, joint 1$"
    ):
        tuning.suggest(*args, **opts, orbit=bad)


def test_gains_alone_without_a_path() -> None:
    kw = tuning.suggest(np.diag([2.0, 0.5]), [0.0, 0.0], 10.0, Ts=2e-3)
    np.testing.assert_allclose(kw["Kp"], [250.0, 62.5], rtol=1e-15)
    assert kw["K1"] == [25.0, 25.0]
    # An orbit is read with the path only: without one it is refused, not ignored.
    with pytest.raises(
        adaptimp.ConfigError, match=r"^orbit: is read with the task's path only: give the path too"
    ):
        tuning.suggest(np.diag([2.0, 0.5]), [0.0, 0.0], 10.0, Ts=2e-3, orbit=np.zeros((4, 2)))
    assert "centers" not in kw
    adaptimp.Controller("sf", "robot", **kw)


def test_a_damped_joint_gets_the_scale_its_sampled_loop_sees() -> None:
    # SPEC (18.9): d̃ = b Ts/(1 − e^(−β)), β = b Ts/d; a near-massless wrist
    # (1e-6 kg m²) with 0.01 N m s/rad of damping (β = 10) gets ≈ b Ts, ten
    # times d; an undamped joint keeps its scale bit for bit.
    ts, d = 1e-3, np.diag([2.0, 0.5, 1e-6])
    plain = tuning.suggest(d, [0.0] * 3, 10.0, Ts=ts)
    damped = tuning.suggest(d, [0.0] * 3, 10.0, Ts=ts, damping=[0.0, 0.1, 0.01])
    assert damped["inertia"][0] == plain["inertia"][0]
    beta = np.array([0.1 * ts / 0.5, 0.01 * ts / 1e-6])
    expected = np.array([0.1, 0.01]) * ts / -np.expm1(-beta)
    np.testing.assert_allclose(damped["inertia"][1:], expected, rtol=1e-12)
    np.testing.assert_allclose(damped["Kp"], 0.25 * np.array(damped["inertia"]) / ts, rtol=1e-12)
    assert damped["inertia"][2] == pytest.approx(1e-5, rel=1e-4)
    with pytest.raises(adaptimp.ConfigError, match="damping"):
        tuning.suggest(d, [0.0] * 3, 10.0, Ts=ts, damping=[0.0, -1.0, 0.0])
    # A model that is not a MuJoCo plant has no damping to take.
    assert tuning.joint_damping(d) is None


@pytest.mark.filterwarnings("ignore:the URDF gives no effort limit:UserWarning")
def test_an_arm_without_gravity_learns_d_and_c_at_gs_bandwidth() -> None:
    """SPEC (22.2): Γ_D, Γ_C 25 times (18.6)'s (ω_D = ω_G instead of ω_G/5), σ
    with the same leak time, the rest as it was; by default for a model
    without gravity (a plant whose MuJoCo gravity is zero), never for D alone."""
    from adaptimp import mujoco as amj

    plant = amj.Plant(str(Path(__file__).parent / "data" / "hobby_arm.urdf"), contact=False)
    task = amj.default_task(plant)
    args = (plant, task.home, plant.tau_max)
    opts: dict[str, Any] = {"Ts": 1e-3, "path": task.reference, "period": task.period}
    heavy = tuning.suggest(*args, **opts)
    light = tuning.suggest(*args, **opts, weightless=True)
    for i in (0, 1):
        assert light["gamma"][i] == pytest.approx(25 * heavy["gamma"][i], rel=1e-12)
        assert light["sigma"][i] == pytest.approx(heavy["sigma"][i] / 25, rel=1e-12)
    assert light["gamma"][2] == heavy["gamma"][2]
    assert light["Kp"] == heavy["Kp"]
    assert not tuning.is_weightless(plant)
    assert not tuning.is_weightless(np.eye(5))
    plant.model.opt.gravity[:] = 0.0
    assert tuning.is_weightless(plant)
    inferred = tuning.suggest(plant, task.home, plant.tau_max, **opts)
    told = tuning.suggest(plant, task.home, plant.tau_max, **opts, weightless=True)
    assert inferred["gamma"] == told["gamma"]
    assert tuning.suggest(plant, task.home, plant.tau_max, **opts, weightless=False)["gamma"][
        0
    ] == pytest.approx(inferred["gamma"][0] / 25, rel=1e-12)


def test_bad_arms_are_errors_naming_the_condition() -> None:
    with pytest.raises(adaptimp.ConfigError, match="positive definite"):
        tuning.suggest(np.diag([1.0, -1.0]), [0.0, 0.0], 10.0)
    with pytest.raises(adaptimp.ConfigError, match="symmetric"):
        tuning.suggest(np.array([[1.0, 0.5], [0.0, 1.0]]), [0.0, 0.0], 10.0)
    with pytest.raises(adaptimp.ConfigError, match=r"τmax > 0.*tau_max\[1\] = 0"):
        tuning.suggest(np.eye(2), [0.0, 0.0], [1.0, 0.0])
    with pytest.raises(adaptimp.ConfigError, match=r"condition Ts ≤ 1 s"):
        tuning.suggest(np.eye(2), [0.0, 0.0], 1.0, Ts=2.0)
    with pytest.raises(adaptimp.ConfigError, match=r"d ≥ 1e-9"):
        tuning.suggest(np.eye(2) * 1e-12, [0.0, 0.0], 1.0)
    with pytest.raises(adaptimp.ConfigError, match="a path needs its period"):
        tuning.suggest(np.eye(2), [0.0, 0.0], 1.0, path=_swing(np.zeros(2)))


# -- A rule that always builds (property test over random arms) -------------

decade = st.floats(min_value=-2.0, max_value=2.0)


@st.composite
def arms(draw: st.DrawFn) -> tuple[adaptimp.PlanarArm, np.ndarray]:
    """A serial arm of 1 … 7 links, masses and inertias each over four decades
    (1e-2 … 1e2 kg; 1e-2 … 1e2 times a rod's), lengths 0.05 … 1 m, in a random
    posture."""
    n = draw(st.integers(min_value=1, max_value=7))
    masses = [10 ** draw(decade) for _ in range(n)]
    lengths = [draw(st.floats(min_value=0.05, max_value=1.0)) for _ in range(n)]
    inertias = [m * x * x / 12 * 10 ** draw(decade) for m, x in zip(masses, lengths)]
    arm = adaptimp.PlanarArm(n, masses=masses, lengths=lengths, inertias=inertias)
    q0 = np.array([draw(st.floats(min_value=-math.pi, max_value=math.pi)) for _ in range(n)])
    return arm, q0


@settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)
@given(
    arm=arms(),
    tau_exp=st.lists(st.floats(min_value=-2.0, max_value=3.0), min_size=7, max_size=7),
    ts=st.sampled_from([1e-4, 2.5e-4, 5e-4, 1e-3, 2e-3, 4e-3, 1e-2]),
    amp=st.floats(min_value=0.0, max_value=1.0),
    w=st.floats(min_value=0.1, max_value=20.0),
)
def test_the_rule_always_builds(
    arm: tuple[adaptimp.PlanarArm, np.ndarray],
    tau_exp: list[float],
    ts: float,
    amp: float,
    w: float,
) -> None:
    model, q0 = arm
    tau_max = [10**e for e in tau_exp[: model.n]]
    kw = tuning.suggest(model, q0, tau_max, Ts=ts, path=_swing(q0, amp, w), period=2 * math.pi / w)
    for case in adaptimp.CASES:
        ctrl = adaptimp.Controller(case, "robot", **kw)
        # It also steps: the first step of an arm at rest on its path.
        tau = ctrl.step(Measurement(q0 - amp, np.zeros(model.n), tau_e=np.zeros(model.n)))
        assert np.all(np.isfinite(tau))
        assert np.all(np.abs(tau) <= np.array(tau_max))
    # And the gains alone, for the vertex grid (n ≤ 3) or the default basis.
    kw = tuning.suggest(model, q0, tau_max, Ts=ts)
    kw.pop("n")
    adaptimp.Controller("sf", "robot", n=model.n, **kw)


# -- The default task and the pieces a model gives ---------------------------


def test_the_default_task_swings_from_rest_within_the_limits() -> None:
    kw = tuning.default_task([0.0, 1.0, 0.0], [-1.0, 0.9, -math.inf], [1.0, 1.3, math.inf])
    assert kw["xc_offset"] == [0.0, 1.0, 0.0]
    # A = min(0.2, range/4): the second joint's range is 0.4 rad.
    np.testing.assert_allclose(kw["xc_cos"], [-0.2, -0.1, -0.2])
    assert kw["xc_sin"] == [0.0, 0.0, 0.0]
    assert kw["xc_omega"] == [math.pi] * 3
    with pytest.raises(adaptimp.ConfigError, match="lo \\+ A ≤ home ≤ hi − A"):
        tuning.default_task([0.95], [-1.0], [1.0])


def test_inertia_and_gravity_from_every_kind_of_model(tmp_path: Path) -> None:
    arm = adaptimp.PlanarArm(2)
    q = [0.1, 0.2]
    np.testing.assert_array_equal(tuning.inertia(arm, q), arm.D(q))
    np.testing.assert_array_equal(tuning.inertia(arm.D(q), q), arm.D(q))
    np.testing.assert_array_equal(tuning.gravity(arm, q), arm.G(q))
    assert tuning.gravity(arm.D(q), q) is None
    with pytest.raises(TypeError, match="must have D"):
        tuning.inertia("not a model", q)
