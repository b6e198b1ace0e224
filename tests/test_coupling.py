"""The inertia-shaped gains of SPEC (18.12) through Python: the rule's option
``coupled``, the controller keyword ``inertia_matrix``, and the delayed loop
on example-robot-data's Panda."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import adaptimp
from adaptimp._errors import ConfigError

amj = pytest.importorskip("adaptimp.mujoco")


def test_the_keyword_is_none_by_default_and_refused_by_name() -> None:
    ctrl = adaptimp.Controller("sf", "robot")
    assert ctrl.params["inertia_matrix"] is None
    shaped = adaptimp.Controller("sf", "robot", inertia_matrix=[[2.0, 0.6], [0.6, 0.5]])
    assert shaped.params["inertia_matrix"] == [2.0, 0.6, 0.6, 0.5]
    with pytest.raises(ConfigError, match=r"^inertia_matrix must have shape \(2, 2\), got \(3,\)$"):
        adaptimp.Controller("sf", "robot", inertia_matrix=[1.0, 2.0, 3.0])
    with pytest.raises(
        ConfigError, match=r"inertia_matrix: must be symmetric positive definite \(kg m²\)"
    ):
        adaptimp.Controller("sf", "robot", inertia_matrix=[[1.0, 2.0], [2.0, 1.0]])


@pytest.fixture(scope="module")
def panda() -> amj.Plant:
    return amj.Plant(adaptimp._models.panda_urdf_path())


def test_the_rule_shapes_the_gains_by_the_paths_inertia(panda: amj.Plant) -> None:
    task = amj.default_task(panda)
    diagonal = amj.rule_keywords(panda, task, delay=2, coupled=False)
    coupled = amj.rule_keywords(panda, task, delay=2)
    assert "inertia_matrix" not in diagonal
    # The default for a loop with a delay; without one, the diagonal rule's
    # unless asked (SPEC (18.12)).
    assert "inertia_matrix" not in amj.rule_keywords(panda, task)
    asked = amj.rule_keywords(panda, task, coupled=True)
    np.testing.assert_array_equal(asked["inertia_matrix"], coupled["inertia_matrix"])
    m = np.asarray(coupled["inertia_matrix"]).reshape(7, 7)
    np.testing.assert_array_equal(m, m.T)
    assert np.linalg.eigvalsh(m).min() > 0.0
    # Its modes lie closer together, so the delayed loop's rate Kp/d is larger
    # (SPEC (18.11), (18.12)); the rest of the keywords are the diagonal rule's.
    rate = [np.asarray(kw["Kp"]) / np.asarray(kw["inertia"]) for kw in (diagonal, coupled)]
    assert rate[1][0] > 1.5 * rate[0][0]
    assert set(coupled) == set(diagonal) | {"inertia_matrix"}


def test_the_coupled_rule_holds_the_panda_two_periods_late(panda: amj.Plant) -> None:
    out = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", adaptimp.PlantWarning)
        for case in ("pd", "sf", "of"):
            res = amj.simulate(case, panda, T=8.0, delay=2)
            out[case] = float(res.metrics["rms_z1_after2"])
            assert res.params["inertia_matrix"] is not None
        diagonal = amj.simulate("pd", panda, T=8.0, delay=2, coupled=False)
        assert diagonal.params.get("inertia_matrix") is None
    # Measured: PD 0.0379 rad diagonal, 0.0088 coupled; SF/PD and OF/PD 0.076
    # (docs/your_arm.md, "Inertia-shaped gains").
    assert out["pd"] < 0.3 * float(diagonal.metrics["rms_z1_after2"])
    assert out["sf"] < 0.12 * out["pd"]
    assert out["of"] < 0.12 * out["pd"]


def test_coupled_is_a_rule_option_of_a_case_name_on_an_arm(panda: amj.Plant) -> None:
    ctrl = adaptimp.Controller("sf", "robot", n=7)
    with pytest.raises(TypeError, match=r"^coupled= is an option of the rule that builds"):
        amj.simulate(ctrl, panda, T=0.01, coupled=True)
    with pytest.raises(ValueError, match=r"^coupled= shapes the rule's gains on an arm"):
        amj.simulate("sf", "two_link", T=0.01, coupled=True)
    # Told either way where no rule runs, it is refused, not dropped.
    with pytest.raises(TypeError, match=r"^coupled= is an option of the rule that builds"):
        amj.simulate(ctrl, panda, T=0.01, coupled=False)
    with pytest.raises(ValueError, match=r"^coupled= shapes the rule's gains on an arm"):
        amj.simulate("sf", "two_link", T=0.01, coupled=False)
    # A flag: "false" is not taken for True.
    with pytest.raises(TypeError, match=r"^coupled must be True or False, got str$"):
        amj.simulate("sf", panda, T=0.01, coupled="false")
    with pytest.raises(TypeError, match=r"^coupled must be True or False, got int$"):
        adaptimp.tuning.suggest(panda, panda.q, panda.tau_max, coupled=1)


@pytest.mark.parametrize(
    ("value", "message"),
    [
        (True, r"^inertia_matrix must be an \(2, 2\) array of real numbers \(kg m²\), got bool$"),
        ([["1", "0"], ["0", "1"]], r"got list of dtype <U1$"),
        (np.eye(2, dtype=bool), r"got ndarray of dtype bool$"),
        (np.eye(2) * (1 + 1j), r"got ndarray of dtype complex128$"),
    ],
)
def test_the_keyword_takes_real_numbers_only(value: object, message: str) -> None:
    with pytest.raises(TypeError, match=message):
        adaptimp.Controller("sf", "robot", inertia_matrix=value)


def test_the_cartesian_task_takes_the_shaped_gains_with_a_delay() -> None:
    """SPEC (18.12): on a Cartesian task's orbit the rule's default is the
    shaped gains for a delay ≥ 1 and the diagonal ones without;
    ``coupled=False`` asks for the diagonal ones (on the Panda)."""
    plant = amj.Plant(adaptimp._models.panda_urdf_path(), contact=False)
    task = amj.cartesian_task(plant)
    default = amj.simulate("sf", plant, T=0.05, task=task, delay=2)
    undelayed = amj.simulate("sf", plant, T=0.05, task=task, delay=0)
    diagonal = amj.simulate("sf", plant, T=0.05, task=task, delay=2, coupled=False)
    assert undelayed.params.get("inertia_matrix") is None
    assert diagonal.params.get("inertia_matrix") is None
    m = np.asarray(default.params["inertia_matrix"]).reshape(7, 7)
    np.testing.assert_array_equal(m, m.T)
    # Ĝ on the shaped gains' orbit at least at (m/Ts) K1: twice (18.6)'s ω_G²
    # (δ = 0: the same rates Kp/d, K1 and basis), so twice the learning rates
    # (D̂'s and Ĉ's go with ω_G, SPEC (18.6)).
    shaped = task.controller("sf", plant, delay=0, coupled=True).inner.params
    plain = task.controller("sf", plant, delay=0, coupled=False).inner.params
    np.testing.assert_array_equal(shaped["K1"], plain["K1"])
    np.testing.assert_allclose(shaped["gamma"], 2.0 * np.asarray(plain["gamma"]), rtol=1e-12)


def test_gains_of_the_users_own_take_the_diagonal_law_unless_asked(panda: amj.Plant) -> None:
    """With a delay the rule's default shapes the gains (SPEC (18.12)); a user
    who sets Kp, inertia, K1 or Kzeta gets the diagonal law their per-joint
    gains ran with before (``rule_coupled``); asked for the shaped law, gains
    that differ by joint are refused with the way out."""
    kw = amj.rule_keywords(panda, amj.default_task(panda), delay=1, coupled=False)
    kp = (np.asarray(kw["Kp"]) * np.array([1, 1, 1, 1, 0.5, 0.5, 0.5])).tolist()
    res = amj.simulate("sf", panda, T=0.01, delay=1, Kp=kp)
    assert res.params.get("inertia_matrix") is None
    same = amj.simulate("sf", panda, T=0.01, delay=1, Kp=kp, coupled=False)
    np.testing.assert_array_equal(res.tau, same.tau)
    assert amj.rule_coupled(None, {"K1": 5.0}) is False
    assert amj.rule_coupled(True, {"K1": 5.0}) is True
    assert amj.rule_coupled(None, {"gamma": 1.0}) is None
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^inertia_matrix: needs K1, Kzeta and Kp/inertia the same on every joint "
        r"\(SPEC \(18\.12\)\); gains that differ by joint take the diagonal law \(no "
        r"inertia_matrix: the rule's coupled = false\)$",
    ):
        amj.simulate("sf", panda, T=0.01, delay=1, Kp=kp, coupled=True)
