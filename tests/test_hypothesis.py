"""Property tests over the Python API's parameters (hypothesis): whatever a
user passes, only ValueError or TypeError (or their subclasses) escape, and
nothing hangs."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import adaptimp
from adaptimp import Measurement
from adaptimp._params import BY_NAME, PARAMS

# Numbers a user may pass: ordinary, extreme, non-finite, and of other types.
numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-10.0, max_value=10.0),
    st.integers(min_value=-(2**70), max_value=2**70),
    st.sampled_from([0.0, -0.0, 1e-300, 1e300, math.pi, True, False]),
)
values = st.one_of(
    numbers,
    st.lists(numbers, min_size=0, max_size=4),
    st.none(),
    st.text(max_size=8),
    st.sampled_from(["auto", "euler", "normalized", "tanh", "latch", "damping", "zoh"]),
    st.builds(lambda xs: np.array(xs), st.lists(numbers, min_size=1, max_size=3)),
    st.just({"a": 1}),
)

CONTROLLER = [p.name for p in PARAMS if p.group == "controller"]


@settings(
    max_examples=300,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)
@given(
    case=st.sampled_from(["pd", "sf", "of", "xx", 3]),
    scenario=st.sampled_from(["paper", "robot"]),
    params=st.dictionaries(st.sampled_from(CONTROLLER), values, max_size=4),
)
def test_controller_parameters_only_raise_value_or_type_errors(
    case: Any, scenario: str, params: dict[str, Any]
) -> None:
    try:
        ctrl = adaptimp.Controller(case, scenario=scenario, **params)
    except (ValueError, TypeError):
        return
    # A controller that was accepted steps (or refuses a step) cleanly.
    for _ in range(3):
        try:
            tau = ctrl.step(Measurement([0.25, -0.05], [0.0, 0.0], tau_e=[1.0, 0.0]))
        except ValueError:
            continue
        assert np.all(np.isfinite(tau))
        assert np.all(np.abs(tau) <= np.array(ctrl.params["tau_max"]) + 1e-12)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    case=st.sampled_from(["pd", "sf", "of"]),
    params=st.dictionaries(
        st.sampled_from([p.name for p in PARAMS if p.group != "controller"] + CONTROLLER),
        values,
        max_size=3,
    ),
)
def test_simulate_parameters_only_raise_value_or_type_errors(
    case: str, params: dict[str, Any]
) -> None:
    # Keep each run short: the duration and integration are fixed here.
    params = {**params, "T": 0.005, "substeps": 1}
    try:
        res = adaptimp.simulate(case, **params)
    except (ValueError, TypeError):
        return
    assert res.rows >= 1
    assert np.all(np.isfinite(res.tau_sat))


@settings(max_examples=200, deadline=None)
@given(
    name=st.sampled_from([p.name for p in PARAMS if p.group == "arm"]),
    value=values,
)
def test_arm_parameters_only_raise_value_or_type_errors(name: str, value: Any) -> None:
    try:
        arm = adaptimp.TwoLinkArm(**{name: value})
    except (ValueError, TypeError):
        return
    assert BY_NAME[name].group == "arm"
    assert np.all(np.isfinite(arm.D([0.1, 0.2])))
