"""Every kind of bad input raises its documented error, naming what is wrong."""

from __future__ import annotations

import math

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement

Q, TE, DQ = [0.25, -0.05], [0.0, 0.0], [0.0, 0.0]


# -- keywords ---------------------------------------------------------------


def test_unknown_keyword_is_named_with_a_suggestion_and_the_valid_names() -> None:
    with pytest.raises(
        TypeError, match=r"'Kzetta'.*did you mean 'Kzeta'.*Valid names: T, substeps"
    ):
        adaptimp.simulate("sf", Kzetta=60.0)
    with pytest.raises(TypeError, match=r"'kp' \(did you mean 'Kp'\?\)"):
        adaptimp.Controller("sf", kp=10.0)
    with pytest.raises(TypeError, match=r"unknown keyword argument 'xyz'\. Valid names"):
        adaptimp.simulate("sf", xyz=1)


def test_controller_rejects_the_run_wall_and_arm_keywords() -> None:
    for key, group in (("T", "simulation"), ("wall", "environment"), ("m1", "arm")):
        with pytest.raises(TypeError, match=rf"'{key}': it is an? {group} parameter"):
            adaptimp.Controller("sf", **{key: 1.0})


def test_arm_rejects_controller_keywords() -> None:
    with pytest.raises(TypeError, match=r"'Kp': it is a controller parameter"):
        adaptimp.TwoLinkArm(Kp=1.0)


@pytest.mark.parametrize(
    ("call", "error", "pattern"),
    [
        (lambda: adaptimp.simulate("xf"), ValueError, r"case must be one of \('pd', 'sf', 'of'\)"),
        (lambda: adaptimp.simulate(3), TypeError, r"case must be a string"),
        (lambda: adaptimp.Controller("PD"), ValueError, r"case must be one of"),
        (
            lambda: adaptimp.simulate("sf", "factory"),
            ValueError,
            r"scenario must be one of \('paper', 'robot'\)",
        ),
        (lambda: adaptimp.simulate(robust="sgn"), ValueError, r"robust must be one of \('sign'"),
        (lambda: adaptimp.simulate(aux_law=1), TypeError, r"aux_law must be a string"),
        (
            lambda: adaptimp.simulate(observer_hold="foh"),
            ValueError,
            r"observer_hold must be one of",
        ),
    ],
)
def test_unknown_case_scenario_and_choices(call, error, pattern) -> None:
    with pytest.raises(error, match=pattern):
        call()


# -- shapes, types, finiteness of parameters --------------------------------


@pytest.mark.parametrize(
    ("params", "error", "pattern"),
    [
        (
            {"Kp": [10.0, 10.0, 10.0]},
            ValueError,
            r"Kp must be a number or have shape \(2,\) \(one value per joint\), got shape \(3,\)",
        ),
        ({"q0": np.zeros((2, 2))}, ValueError, r"q0 .* got shape \(2, 2\)"),
        (
            {"gamma": [1.0, 2.0]},
            ValueError,
            r"gamma .* shape \(3,\) \(one value per network D, C, G\)",
        ),
        ({"Kp": [[1.0], [2.0, 3.0]]}, ValueError, r"Kp must be a number or have shape \(2,\)"),
        ({"T": [1.0, 2.0]}, ValueError, r"T must be a single number \(s\), got shape \(2,\)"),
        ({"Kp": "10"}, TypeError, r"Kp must be a number or a sequence of 2 numbers"),
        ({"Kp": [1.0, "a"]}, TypeError, r"Kp must be a number or a sequence of 2"),
        ({"T": "1"}, TypeError, r"T must be a real number \(s\), got str"),
        ({"T": True}, TypeError, r"T must be a real number"),
        ({"substeps": 1.5}, TypeError, r"substeps must be an integer, got float"),
        ({"wall": "none"}, TypeError, r"wall must be a real number \(rad\)"),
        ({"Kp": math.nan}, ValueError, r"Kp\[0\] must be finite, got nan"),
        ({"q0": [0.0, math.inf]}, ValueError, r"q0\[1\] must be finite, got inf"),
        ({"T": math.inf}, ValueError, r"T must be finite, got inf"),
        ({"m1": math.nan}, ValueError, r"m1 must be finite"),
    ],
)
def test_bad_parameter_shapes_types_and_values(params, error, pattern) -> None:
    with pytest.raises(error, match=pattern):
        adaptimp.simulate("sf", **params)


# -- SPEC §10 and the other validity conditions, from the Rust core ---------

CONDITIONS = [
    ({"Ts": 0.0}, "Ts > 0", "Ts = 0"),
    ({"K1": [6.0, 0.0]}, "K1 > 0", "K1[1] = 0"),
    ({"Kp": 0.25}, "2Kp − I > 0", "2·Kp − 1[0] = -0.5"),
    ({"Kzeta": 50.0}, "2Kζ − I − KpᵀKp > 0", "2·Kzeta − 1 − Kp²[0] = -1"),
    # SPEC §10's conditions with inertia scales (conditions "scaled").
    ({"conditions": "scaled", "Kp": [10.0, -1.0]}, "Kp > 0", "Kp[1] = -1"),
    (
        {"conditions": "scaled", "Kzeta": 5.0},
        "2Kζ − ρ − Kp/d > 0",
        "2·Kzeta − rho − Kp/inertia[0] = -1",
    ),
    ({"conditions": "scaled", "inertia": [1.0, 1e-12]}, "d ≥ 1e-9", "inertia[1] = 0.000000000001"),
    ({"conditions": "scaled", "rho": 0.0}, "ρ ≥ 1e-9", "rho = 0"),
    ({"gamma": [100.0, 0.0, 100.0]}, "Γ > 0", "gamma[1] = 0"),
    ({"sigma": -0.01}, "σ > 0", "sigma[0] = -0.01"),
    ({"eta2": 0.0}, "η² > 0", "eta2 = 0"),
    ({"eps": -1e-4}, "ε > 0", "eps = -0.0001"),
    ({"lam1": [3.0, -3.0]}, "λ1 > 0", "lam1[1] = -3"),
    ({"mu": 0.0}, "μ > 0", "mu = 0"),
    ({"tau_max": [17.0, 0.0]}, "τmax > 0", "tau_max[1] = 0"),
    ({"Dd": 0.0}, "Dd > 0", "Dd[0] = 0"),
    ({"Cd": -1.0}, "Cd ≥ 0", "Cd[0] = -1"),
    ({"Gd": [60.0, -5.0]}, "Gd ≥ 0", "Gd[1] = -5"),
    ({"kr": -0.5}, "kr ≥ 0", "kr[0] = -0.5"),
    ({"robust": "tanh", "phi": 0.0}, "φ > 0", "phi = 0"),
    ({"robust": "remark1", "kD": -1.0}, "kD ≥ 0", "kD = -1"),
    ({"T": 0.0}, "T > 0", "T = 0"),
    ({"substeps": 0}, "1 ≤ substeps ≤ 10 000", "substeps = 0"),
    ({"substeps": -2}, "1 ≤ substeps ≤ 10 000", "substeps = -2"),
    ({"ke": -1.0}, "ke ≥ 0", "ke = -1"),
    ({"m2": 0.0}, "m2 > 0", "m2 = 0"),
    ({"I1": -0.1}, "I1 ≥ 0", "I1 = -0.1"),
    ({"lc1": 0.0, "I1": 0.0, "I2": 0.0}, "D(q) > 0 for all q", "p1·p2 − p3² = "),
]


@pytest.mark.parametrize(("params", "condition", "value"), CONDITIONS)
def test_each_violated_condition_reaches_python_as_value_error(params, condition, value) -> None:
    with pytest.raises(ValueError, match="is violated") as info:
        adaptimp.simulate("sf", **{"T": 0.01, **params})
    message = str(info.value)
    assert f"condition {condition} is violated" in message
    assert value in message


def test_the_papers_conditions_need_the_papers_weights() -> None:
    with pytest.raises(ValueError, match=r"conditions = paper: \(13\) is proved for the paper's"):
        adaptimp.Controller("sf", inertia=[1.0, 2.0])
    with pytest.raises(ValueError, match="use conditions = scaled"):
        adaptimp.Controller("sf", rho=2.0)
    # A light joint is not refused for being light: Kp = 0.03 N m s/rad on
    # an inertia scale of 0.001 kg m² (Kp/d = 30 s⁻¹).
    with pytest.raises(ValueError, match=r"2Kp − I > 0.*raise Kp above 0\.5"):
        adaptimp.Controller("sf", Kp=[10.0, 0.03])
    adaptimp.Controller(
        "sf", conditions="scaled", Kp=[10.0, 0.03], inertia=[1.0, 0.001], Kzeta=[60.0, 20.0]
    )
    with pytest.raises(ValueError, match=r"raise Kzeta above 15\.5 for Kp = 0\.03 and inertia"):
        adaptimp.Controller(
            "sf", conditions="scaled", Kp=[10.0, 0.03], inertia=[1.0, 0.001], Kzeta=[60.0, 15.0]
        )


def test_controller_and_arm_report_conditions_too() -> None:
    with pytest.raises(ValueError, match=r"condition 2Kζ − I − KpᵀKp > 0 is violated"):
        adaptimp.Controller("of", Kp=11.0)
    with pytest.raises(ValueError, match=r"condition l1 > 0 is violated: l1 = -0.3"):
        adaptimp.TwoLinkArm(l1=-0.3)


# -- Controller.step and the arm's methods ----------------------------------


@pytest.mark.parametrize("case", ["pd", "sf"])
def test_missing_dq_is_an_error_for_state_feedback_and_pd(case: str) -> None:
    ctrl = adaptimp.Controller(case)
    with pytest.raises(ValueError, match="uses the measured velocity: pass dq"):
        ctrl.step(Measurement(Q, tau_e=TE))
    assert ctrl.steps == 0


@pytest.mark.parametrize(
    ("args", "error", "pattern"),
    [
        (
            ([0.1, 0.2, 0.3], [0.0] * 3, [0.0] * 3),  # a measurement of 3 joints
            ValueError,
            r"q must have shape \(2,\) \(one value per joint\), got length 3",
        ),
        (
            (Q, np.zeros((2, 1)), DQ),
            ValueError,
            r"tau_e must have shape \(2,\) .*got shape \(2, 1\)",
        ),
        (
            (0.25, TE, DQ),
            ValueError,
            r"q must be one value per joint \(a 1-D array\), got a scalar",
        ),
        (("ab", TE, DQ), TypeError, r"q must be a sequence or array of 2 real numbers .*got str"),
        ((Q, TE, {"a": 1}), TypeError, r"dq must be a sequence or array of 2 real numbers"),
        ((Q, TE, [1.0, "x"]), TypeError, r"dq must be a sequence or array"),
        ((Q, TE, [10**400, 0.0]), ValueError, r"dq holds a number too large for a float"),
        (
            ([0.1, 0.2, 0.3, 0.4], [0.0] * 4, [0.0] * 4),
            ValueError,
            r"q must have shape \(2,\) .*got length 4",
        ),
        (
            (np.array([1 + 1j, 0]), TE, DQ),
            TypeError,
            r"q must hold real numbers, got an array of dtype complex128",
        ),
        (([math.nan, 0.0], TE, DQ), ValueError, r"q\[0\] is not finite"),
        ((Q, [0.0, math.inf], DQ), ValueError, r"tau_e\[1\] is not finite"),
        ((Q, TE, np.array([0.0, -np.inf])), ValueError, r"dq\[1\] is not finite"),
    ],
)
def test_bad_step_inputs_raise_and_leave_the_state_untouched(args, error, pattern) -> None:
    ctrl = adaptimp.Controller("sf")
    ctrl.step(Measurement(Q, DQ, tau_e=TE))
    zeta, weights = ctrl.zeta, ctrl.weights
    with pytest.raises(error, match=pattern):
        ctrl.step(Measurement(args[0], args[2], tau_e=args[1]))
    assert ctrl.steps == 1
    np.testing.assert_array_equal(ctrl.zeta, zeta)
    np.testing.assert_array_equal(ctrl.weights["G"], weights["G"])


def test_lists_tuples_and_arrays_step_alike() -> None:
    """A list (of floats, ints or NumPy scalars), a tuple and an array of the same
    numbers give the same torque, bit for bit."""
    forms = [
        (np.array([0.1, 0.2]), np.array([0.0, 1.0]), np.array([0.5, -0.5])),
        ([0.1, 0.2], [0, 1], [0.5, -0.5]),
        ((0.1, 0.2), (0.0, 1.0), (0.5, -0.5)),
        ([np.float64(0.1), np.float32(0.2).item()], [0.0, 1.0], [np.float64(0.5), -0.5]),
    ]
    torques = []
    for q, te, dq in forms:
        ctrl = adaptimp.Controller("sf")
        torques.append(ctrl.step(Measurement(q, dq, tau_e=te)))
    for tau in torques[1:3]:
        assert np.array_equal(tau, torques[0])
    assert not np.array_equal(torques[3], torques[0])  # 0.2 as a float32 is another number


def test_arm_methods_check_their_inputs() -> None:
    arm = adaptimp.TwoLinkArm()
    with pytest.raises(ValueError, match=r"q must have shape \(2,\)"):
        arm.D([0.0])
    with pytest.raises(ValueError, match=r"dq\[0\] is not finite"):
        arm.C([0.0, 0.0], [math.nan, 0.0])
    with pytest.raises(TypeError, match=r"tau must be a sequence or array"):
        arm.forward_dynamics([0.0, 0.0], [0.0, 0.0], None, [0.0, 0.0])


def test_plot_kind_is_checked() -> None:
    res = adaptimp.simulate("pd", T=0.01)
    with pytest.raises(
        ValueError, match=r"kind must be one of \('tracking', 'errors', 'torques'\)"
    ):
        res.plot("bode")
