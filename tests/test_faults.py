"""Faults injected into a closed loop (adaptimp.Fault, the core's src/sim/inject.rs),
the same on the rigid plant and on MuJoCo: the window, the refused rows, the
fallback applied, the run going on."""

from __future__ import annotations

import numpy as np
import pytest

import adaptimp
from adaptimp import mujoco as amj


def _window(res: adaptimp.SimResult, fault: adaptimp.Fault) -> np.ndarray:
    return (res.t >= fault.start - 1e-12) & (res.t < fault.start + fault.duration - 1e-12)


@pytest.mark.parametrize("plant", ["rigid", "mujoco"])
def test_a_nan_burst_is_refused_and_the_run_goes_on(plant: str) -> None:
    fault = adaptimp.Fault("nan_burst", start=0.3, duration=0.05)
    if plant == "rigid":
        res = adaptimp.simulate("sf", "robot", T=1.0, fault=fault)
    else:
        res = amj.simulate("sf", "two_link", T=1.0, fault=fault)
    assert res.refused is not None
    inside = _window(res, fault)
    assert inside.sum() == 50
    np.testing.assert_array_equal(res.refused, inside)
    # "hold": the last applied torque is held through the burst.
    first = int(np.argmax(inside))
    np.testing.assert_array_equal(res.tau_sat[inside], np.tile(res.tau_sat[first - 1], (50, 1)))
    assert np.all(np.isfinite(res.q))
    assert res.rows == 1000


@pytest.mark.parametrize("plant", ["rigid", "mujoco"])
def test_weak_actuators_and_a_force_bias(plant: str) -> None:
    drop = adaptimp.Fault("actuator_drop", start=0.2, duration=0.3, fraction=0.1)
    bias = adaptimp.Fault("force_bias", start=0.2, duration=0.3, bias=[5.0, 0.0])
    if plant == "rigid":
        run = lambda f: adaptimp.simulate("sf", "robot", T=0.8, fault=f)  # noqa: E731
    else:
        run = lambda f: amj.simulate("sf", "two_link", T=0.8, fault=f)  # noqa: E731
    weak = run(drop)
    inside = _window(weak, drop)
    limit = 0.1 * np.array([17.0, 15.0])
    assert np.all(np.abs(weak.tau_sat[inside]) <= limit + 1e-12)
    assert np.any(np.abs(weak.tau_sat[~inside]) > limit)
    assert not weak.refused.any()
    biased, clean = run(bias), run(None)
    before = biased.t < bias.start
    np.testing.assert_array_equal(biased.tau[before], clean.tau[before])
    assert not np.array_equal(biased.tau[_window(biased, bias)], clean.tau[_window(clean, bias)])


def test_faults_are_checked() -> None:
    with pytest.raises(ValueError, match="Fault kind must be one of"):
        adaptimp.Fault("meteor", 0.0, 1.0)
    with pytest.raises(TypeError, match="fraction= goes with kind 'actuator_drop'"):
        adaptimp.Fault("actuator_drop", 0.0, 1.0)
    with pytest.raises(TypeError, match="bias= goes with kind 'force_bias'"):
        adaptimp.Fault("stale", 0.0, 1.0, bias=1.0)
    with pytest.raises(adaptimp.ConfigError, match="0 ≤ fraction ≤ 1"):
        adaptimp.simulate("sf", T=0.1, fault=adaptimp.Fault("actuator_drop", 0, 1, fraction=2.0))
    with pytest.raises(adaptimp.ConfigError, match="Fault duration must be a finite number > 0"):
        amj.simulate("sf", "two_link", T=0.1, fault=adaptimp.Fault("skipped", 0.0, 0.0))
    with pytest.raises(ValueError, match=r"bias must be a number or have shape \(2,\)"):
        adaptimp.simulate("sf", T=0.1, fault=adaptimp.Fault("force_bias", 0, 1, bias=[1, 2, 3]))
