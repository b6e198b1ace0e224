"""Property tests (hypothesis): the arm's structure (SPEC §1) and a controller
step that never fails on finite, physically plausible inputs."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import adaptimp
from adaptimp import Measurement

angle = st.floats(-10.0, 10.0)
speed = st.floats(-50.0, 50.0)
joint_angles = st.tuples(angle, angle)
joint_speeds = st.tuples(speed, speed)
arms = st.fixed_dictionaries(
    {
        "m1": st.floats(0.1, 20.0),
        "m2": st.floats(0.1, 20.0),
        "l1": st.floats(0.05, 2.0),
        "l2": st.floats(0.05, 2.0),
    }
)


@given(arms, joint_angles)
def test_inertia_is_symmetric_positive_definite(params: dict[str, float], q) -> None:
    D = adaptimp.TwoLinkArm(**params).D(q)
    assert D.shape == (2, 2)
    assert D[0, 1] == D[1, 0]
    assert np.all(np.linalg.eigvalsh(D) > 0.0)


@given(arms, joint_angles, joint_speeds)
def test_ddot_minus_two_c_is_skew_symmetric(params: dict[str, float], q, dq) -> None:
    """Property 2: Ḋ − 2C is skew-symmetric; Ḋ by a central difference along q̇."""
    arm = adaptimp.TwoLinkArm(**params)
    q, dq = np.array(q), np.array(dq)
    h = 1e-6
    d_dot = (arm.D(q + h * dq) - arm.D(q - h * dq)) / (2 * h)
    n = d_dot - 2.0 * arm.C(q, dq)
    scale = 1.0 + np.abs(d_dot).max() + np.abs(arm.C(q, dq)).max()
    np.testing.assert_allclose(n + n.T, 0.0, atol=1e-6 * scale)


@given(arms, joint_angles, joint_speeds, st.tuples(speed, speed), st.tuples(speed, speed))
def test_forward_dynamics_solves_the_equation_of_motion(params, q, dq, tau, tau_e) -> None:
    arm = adaptimp.TwoLinkArm(**params)
    ddq = arm.forward_dynamics(q, dq, tau, tau_e)
    lhs = arm.D(q) @ ddq + arm.C(q, dq) @ np.array(dq) + arm.G(q)
    rhs = np.array(tau) - np.array(tau_e)
    scale = 1.0 + np.abs(arm.D(q) @ ddq).max() + np.abs(rhs).max()
    np.testing.assert_allclose(lhs, rhs, atol=1e-9 * scale)


LIMITS = np.array([17.0, 15.0])  # τmax of the paper (N m)
measurements = st.lists(
    st.tuples(joint_angles, st.tuples(st.floats(0.0, 500.0), st.floats(-50.0, 50.0)), joint_speeds),
    min_size=1,
    max_size=30,
)


@settings(max_examples=60, deadline=None)
@given(
    st.sampled_from(adaptimp.CASES),
    measurements,
    st.sampled_from(["sign", "tanh", "remark1", "none"]),
)
def test_step_never_raises_and_respects_the_limits(case: str, steps, robust: str) -> None:
    """Any sequence of finite measurements (|q| ≤ 10 rad, |dq| ≤ 50 rad/s, τe up to
    500 N m): every step returns a finite torque within ±τmax."""
    ctrl = adaptimp.Controller(case, robust=robust)
    for q, tau_e, dq in steps:
        tau = ctrl.step(Measurement(q, dq, tau_e=tau_e))
        assert np.all(np.isfinite(tau))
        assert np.all(np.abs(tau) <= LIMITS)
        np.testing.assert_array_equal(tau, np.clip(ctrl.tau, -LIMITS, LIMITS))
    assert ctrl.steps == len(steps)
