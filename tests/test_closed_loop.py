"""Controller.step in a Python loop with TwoLinkArm.forward_dynamics, the wall
and RK4 (SPEC §11) reproduces simulate()."""

from __future__ import annotations

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement

WALL, KE, BE = 0.2, 1000.0, 10.0


def wall_force(q: np.ndarray, dq: np.ndarray) -> np.ndarray:
    """τe (N m) of the penalty wall on joint 1 (SPEC §3)."""
    delta = q[0] - WALL
    f = max(0.0, KE * delta + BE * dq[0]) if delta > 0.0 else 0.0
    return np.array([f, 0.0])


def python_loop(case: str, T: float, substeps: int = 1) -> dict[str, np.ndarray]:
    """The closed loop of SPEC §11 written in Python around the compiled pieces."""
    ctrl = adaptimp.Controller(case)
    arm = adaptimp.TwoLinkArm()
    h = ctrl.Ts / substeps
    q, dq = np.array([0.25, -0.05]), np.zeros(2)
    rec: dict[str, list[np.ndarray]] = {"q": [], "dq": [], "tau": [], "tau_sat": [], "tau_e": []}
    for _ in range(round(T / ctrl.Ts)):
        tau_e = wall_force(q, dq)
        tau_s = ctrl.step(Measurement(q, dq, tau_e=tau_e))
        for name, value in (("q", q), ("dq", dq), ("tau", ctrl.tau), ("tau_sat", tau_s)):
            rec[name].append(value)
        rec["tau_e"].append(tau_e)

        def accel(x: np.ndarray, v: np.ndarray, tau_s: np.ndarray = tau_s) -> np.ndarray:
            return arm.forward_dynamics(x, v, tau_s, wall_force(x, v))

        for _ in range(substeps):
            k1v, k1a = dq, accel(q, dq)
            x2, v2 = q + 0.5 * h * k1v, dq + 0.5 * h * k1a
            k2a = accel(x2, v2)
            x3, v3 = q + 0.5 * h * v2, dq + 0.5 * h * k2a
            k3a = accel(x3, v3)
            x4, v4 = q + h * v3, dq + h * k3a
            k4a = accel(x4, v4)
            q = q + h / 6.0 * (k1v + 2.0 * v2 + 2.0 * v3 + v4)
            dq = dq + h / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a)
    return {name: np.array(values) for name, values in rec.items()}


def test_pd_python_loop_reproduces_simulate() -> None:
    T = 0.5
    mine = python_loop("pd", T)
    res = adaptimp.simulate("pd", T=T)
    assert res.metrics["steps_in_contact"] > 0  # the run includes the contact transient
    for name, values in mine.items():
        np.testing.assert_allclose(getattr(res, name), values, rtol=0, atol=1e-9, err_msg=name)


@pytest.mark.parametrize("case", ["sf", "of"])
def test_adaptive_python_loop_reproduces_simulate_over_a_short_run(case: str) -> None:
    """The adaptive loops are chaotic (SPEC §12), so only a short run is compared
    trajectory by trajectory; with two substeps to cover the substep loop."""
    T = 0.05
    mine = python_loop(case, T, substeps=2)
    res = adaptimp.simulate(case, T=T, substeps=2)
    for name, values in mine.items():
        np.testing.assert_allclose(getattr(res, name), values, rtol=0, atol=1e-9, err_msg=name)
