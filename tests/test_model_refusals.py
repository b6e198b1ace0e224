"""Models that overflow in use are refused when given, by name (issue 33,
minor items): a computed-torque controller's mass_scale, period and gains, a
payload on a MuJoCo plant; its model's queries refuse inputs beyond their
ceilings instead of returning NaN."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

import adaptimp
from adaptimp.baselines import ComputedTorque


@pytest.mark.parametrize(
    ("kw", "message"),
    [
        (
            {"mass_scale": 1e300},
            "condition |value| ≤ 1e9 is violated: mass_scale = 1e300 (SPEC §10)",
        ),
        ({"Ts": 1e9}, "condition Ts ≤ 1 s is violated: Ts = 1000000000 (SPEC §10)"),
        ({"payload": 1e300}, "condition |value| ≤ 1e9 is violated: payload = 1e300 (SPEC §10)"),
        ({"Kp": 1e10}, "condition |value| ≤ 1e9 is violated: Kp[0] = 10000000000 (SPEC §10)"),
    ],
)
def test_a_computed_torque_model_that_would_overflow_is_refused(
    kw: dict[str, Any], message: str
) -> None:
    with pytest.raises(adaptimp.ConfigError) as e:
        ComputedTorque(**kw)
    assert str(e.value).endswith(message), str(e.value)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (([0, 0], [1e200, 0], [0, 0]), "dq[0] = 1e200 is beyond its limit ±1e6"),
        (([0, 0], [0, 0], [0, 1e7]), "ddq[1] = 1e7 is beyond its limit ±1e6"),
        (([1e300, 0], [0, 0], [0, 0]), "q[0] = 1e300 is beyond its limit ±1e6"),
    ],
)
def test_inverse_dynamics_refuses_inputs_whose_torque_would_not_be_finite(
    args: tuple[list[float], ...], message: str
) -> None:
    ct = ComputedTorque()
    with pytest.raises(adaptimp.MeasurementError) as e:
        ct.inverse_dynamics(*args)
    assert str(e.value).startswith(message)
    with pytest.raises(ValueError, match=r"^q must be finite, got \[ 0\. nan\]$"):
        ct.inverse_dynamics([0, math.nan], [0, 0], [0, 0])
    tau = ct.inverse_dynamics([0.1, 0.2], [1e6, -1e6], [1e6, 0.0])
    assert np.isfinite(tau).all()


def test_a_payload_beyond_any_arm_is_refused_as_a_payload() -> None:
    from adaptimp import mujoco as amj

    with pytest.raises(adaptimp.ConfigError) as e:
        amj.simulate("pd", "two_link", T=0.01, payload=1e300)
    assert str(e.value) == "payload must be ≥ 0 and ≤ 1e9 kg, got 1e+300"
