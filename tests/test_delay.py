"""The loop's delay (SPEC (17.1), (18.11)): part of the controller's description,
the rule's gains sized for it, the plant's delay in ``simulate``, the setpoint of
the sample's instant and the true tracking error."""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import pytest

import adaptimp
from adaptimp import tuning
from adaptimp._errors import ConfigError

amj = pytest.importorskip("adaptimp.mujoco")


def test_the_presets_carry_the_delay_a_robot_has() -> None:
    assert adaptimp.Controller("sf").params["delay"] == 0  # the paper's
    assert adaptimp.Controller("sf", scenario="robot").params["delay"] == 1
    assert adaptimp.Controller("sf", scenario="robot", delay=2).params["delay"] == 2
    with pytest.raises(ConfigError, match="0 ≤ delay ≤ 64"):
        adaptimp.Controller("sf", scenario="robot", delay=65)
    with pytest.raises(TypeError, match="delay"):
        adaptimp.Controller("sf", scenario="robot", delay=1.5)


def test_simulate_makes_the_loops_delay_the_plants_and_the_controllers() -> None:
    # delay=: the plant's, and the case name's controller is made for it.
    res = amj.simulate("pd", "two_link", T=0.05, delay=2)
    assert (res.params["plant_delay"], res.params["delay"]) == (2, 2)
    # Without it both are 0, whatever a robot controller's own default.
    res = amj.simulate("pd", "two_link", T=0.05)
    assert (res.params["plant_delay"], res.params["delay"]) == (0, 0)
    # plant_delay= alone: a controller not told of it, which the run says.
    with pytest.warns(adaptimp.PlantWarning, match="made for a loop delay of 0 period"):
        res = amj.simulate("pd", "two_link", T=0.05, plant_delay=3)
    assert (res.params["plant_delay"], res.params["delay"]) == (3, 0)
    assert any("delay=3" in w for w in res.params["warnings"])
    # A controller made for another delay is allowed, and said.
    res = amj.simulate(adaptimp.Controller("pd", "robot"), "two_link", T=0.05)
    assert (res.params["plant_delay"], res.params["delay"]) == (0, 1)
    with pytest.raises(ValueError, match="0 ≤ delay ≤ 64"):
        amj.simulate("pd", "two_link", T=0.05, delay=65)
    with pytest.raises(TypeError, match="delay must be an integer"):
        amj.simulate("pd", "two_link", T=0.05, delay=True)
    # The rigid-body simulate and sweeps alike.
    res = adaptimp.simulate("pd", "robot", T=0.05, delay=1)
    assert (res.params["plant_delay"], res.params["delay"]) == (1, 1)


def test_the_rule_without_delay_is_the_rule_as_it_was() -> None:
    plant = amj.Plant(adaptimp._models.panda_urdf_path())
    task = amj.default_task(plant)
    same = amj.rule_keywords(plant, task)
    zero = amj.rule_keywords(plant, task, delay=0)
    assert same.keys() == zero.keys()
    for key, value in same.items():
        np.testing.assert_array_equal(np.asarray(value), np.asarray(zero[key]), err_msg=key)
    late = amj.rule_keywords(plant, task, delay=1, coupled=False)
    assert (zero["delay"], late["delay"]) == (0, 1)
    # (18.11): every gain of the velocity loop by one factor f < 1, K1 with it
    # (the position loop 5× inside), the robust term off.
    f = np.asarray(late["Kp"]) / np.asarray(zero["Kp"])
    assert np.ptp(f) < 1e-12 * f[0]
    assert 0.2 < f[0] < 1.0
    np.testing.assert_allclose(np.asarray(late["K1"]), 50.0 * f[0], rtol=1e-12)
    assert np.all(np.asarray(late["kr"]) == 0.0)
    assert np.all(np.asarray(zero["kr"]) > 0.0)


@pytest.fixture(scope="module")
def panda_runs() -> dict[tuple[str, int, bool], float]:
    """RMS ‖z1‖ (t ≥ 2 s, the plant's true q) of the Panda's default task at
    δ = 1, T = 8 s: PD, SF and OF of the rule made for the delay, and SF of the
    rule made for none (a controller not told of the plant's delay)."""
    path = adaptimp._models.panda_urdf_path()
    out: dict[tuple[str, int, bool], float] = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", adaptimp.PlantWarning)
        for case in ("pd", "sf", "of"):
            res = amj.simulate(case, path, T=8.0, delay=1)
            out[case, 1, True] = float(res.metrics["rms_z1_after2"])
        for case in ("pd", "sf"):
            with pytest.warns(adaptimp.PlantWarning, match="made for a loop delay of 0"):
                res = amj.simulate(case, path, T=8.0, plant_delay=1)
            out[case, 1, False] = float(res.metrics["rms_z1_after2"])
    return out


def test_a_controller_made_for_the_delay_learns_through_it(
    panda_runs: dict[tuple[str, int, bool], float],
) -> None:
    pd = panda_runs["pd", 1, True]
    # Measured 0.073 and 0.074 (docs/your_arm.md): the target is 0.2.
    assert panda_runs["sf", 1, True] < 0.12 * pd
    assert panda_runs["of", 1, True] < 0.12 * pd
    # The undelayed rule on the delayed plant rings (measured 2.1× its PD).
    assert panda_runs["sf", 1, False] > 1.5 * panda_runs["pd", 1, False]


def test_the_loop_gives_the_setpoint_of_the_samples_instant() -> None:
    """SPEC (17.1), through a controller written in Python: with a plant delay
    of d periods, step k is given the sample of step k − d and the reference
    of that step's instant."""

    class Recorder:
        Ts = 1e-3

        def __init__(self) -> None:
            self.xc: list[np.ndarray] = []
            self.q: list[np.ndarray] = []

        def step(self, m: Any, /, **setpoint: Any) -> np.ndarray:
            self.xc.append(np.array(setpoint["xc"]))
            self.q.append(np.array(m.q))
            return np.zeros(2)

    def reference(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return np.array([0.25 + t, -0.05]), np.array([1.0, 0.0]), np.zeros(2)

    runs = {}
    for d in (0, 3):
        ctrl = Recorder()
        res = amj.simulate(ctrl, "two_link", T=0.02, reference=reference, plant_delay=d)
        runs[d] = (ctrl, res)
        assert res.params["delay"] is None  # a controller that does not say
    (now, res0), (late, res3) = runs[0], runs[3]
    np.testing.assert_array_equal(res0.q, res3.q)  # zero torque: the same motion
    for k in range(20):
        then = max(k - 3, 0)
        np.testing.assert_array_equal(late.xc[k], now.xc[then])
        np.testing.assert_array_equal(late.q[k], now.q[then])
        # The row keeps t_k's reference and state.
        np.testing.assert_array_equal(res3.xc[k], res0.xc[k])


def test_the_tracking_error_is_the_true_states() -> None:
    """SPEC (17.1): sensor noise is not tracking error."""
    clean = amj.simulate("pd", "two_link", T=0.5, contact=False)
    noisy = amj.simulate("pd", "two_link", T=0.5, contact=False, noise_q=1e-3, seed=2)
    # The row's z1 against the plant's true q (no delay: the row's own q).
    np.testing.assert_allclose(noisy.z1, noisy.xd - noisy.q, atol=1e-12)
    np.testing.assert_array_equal(clean.z1, clean.xd - clean.q)


def test_suggest_refuses_a_delay_by_name() -> None:
    d = np.diag([1.0, 0.5])
    assert tuning.suggest(d, [0.0, 0.0], [10.0, 10.0], delay=1)["delay"] == 1
    with pytest.raises(ConfigError, match="0 ≤ delay ≤ 64"):
        tuning.suggest(d, [0.0, 0.0], [10.0, 10.0], delay=-1)


def test_an_arm_that_does_not_follow_its_task_is_said_to() -> None:
    """A joint run whose error exceeds half the reference's own motion warns by
    name (the check of SPEC (18.11)); a run that tracks does not."""
    arm = adaptimp._models.panda_urdf_path()
    good = amj.simulate("pd", arm, T=3.0)
    assert not any("did not follow" in w for w in good.params["warnings"])
    kp = np.asarray(amj.rule_keywords(amj.Plant(arm))["Kp"])
    with pytest.warns(adaptimp.PlantWarning, match="the arm did not follow its task"):
        weak = amj.simulate("pd", arm, T=3.0, Kp=list(1e-3 * kp), Kzeta=260.0)
    assert any("did not follow" in w for w in weak.params["warnings"])
