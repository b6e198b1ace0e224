"""The fault semantics of docs/reliability.md through the Python front (issue
20, items 1-5 and the Python minor items): every refusal latches, the torque
after a refusal is the fallback and the rate limit starts from it, the jump
limit re-anchors on the measured positions, setpoints are checked like
measurements, restore and load_state_dict refuse what the controller could
never step."""

from __future__ import annotations

import copy
import pickle
import re

import numpy as np
import pytest

import adaptimp
from adaptimp import ConfigError, FaultError, Measurement, MeasurementError


def _inputs(k: int) -> tuple[list[float], list[float], list[float]]:
    s = k * 1e-3
    return (
        [0.2 + 0.1 * np.sin(s), 0.2 + 0.1 * np.cos(s)],
        [0.0, 0.0],
        [0.1 * np.cos(s), -0.1 * np.sin(s)],
    )


def _m(k: int) -> Measurement:
    """The measurement of step k (`_inputs`)."""
    q, tau_e, dq = _inputs(k)
    return Measurement(q, dq, tau_e=tau_e)


def _run(ctrl: adaptimp.Controller, k0: int, k1: int) -> None:
    for k in range(k0, k1):
        ctrl.step(_m(k))


# -- item 1: every refusal latches -------------------------------------------


@pytest.mark.parametrize("bad", [[np.nan, 0.0], [np.inf, 0.0], [0.0, -np.inf]])
def test_a_non_finite_measurement_raised_by_step_latches(bad: list[float]) -> None:
    ctrl = adaptimp.Controller("sf", scenario="robot", fault_policy="latch")
    _run(ctrl, 0, 10)
    with pytest.raises(MeasurementError, match=r"q\[\d\] is not finite"):
        ctrl.step(Measurement(bad, [0.0, 0.0], tau_e=[0.0, 0.0]))
    assert ctrl.fault is not None
    assert ctrl.fault[1] == 10
    # The next valid step is refused (it used to be accepted).
    with pytest.raises(FaultError, match=r"latched \(non-finite input\)"):
        ctrl.step(_m(10))
    # The fault that latched is kept, not replaced by the refusals it causes.
    assert ctrl.fault[0].startswith("q[")
    ctrl.clear_fault()
    ctrl.step(_m(10))
    assert ctrl.steps == 11


@pytest.mark.parametrize(
    ("kwargs", "exc"),
    [
        ({"q": [0.1, 0.2, 0.3]}, MeasurementError),
        ({"q": "ab"}, TypeError),
        ({"dxc": [0.0, 0.0]}, TypeError),
        ({"tau_e": np.zeros(2, dtype=complex)}, TypeError),
    ],
)
# The arrays' call shape (deprecated) hands the controller what a Measurement
# would refuse before any call: it refuses them too, and records it.
@pytest.mark.filterwarnings("ignore:Controller.step.* is deprecated:DeprecationWarning")
def test_a_step_refused_for_its_arguments_latches_too(
    kwargs: dict[str, object], exc: type[Exception]
) -> None:
    for call in ("step", "step_or_fallback"):
        ctrl = adaptimp.Controller("sf", scenario="robot", fault_policy="latch")
        _run(ctrl, 0, 5)
        q, te, dq = _inputs(5)
        args: dict[str, object] = {"q": q, "tau_e": te, "dq": dq, **kwargs}
        with pytest.raises(exc):
            getattr(ctrl, call)(**args)
        assert ctrl.fault is not None
        assert "wrong shape or type" in ctrl.fault[0]
        # The torque to apply: the fallback (hold: the torque before).
        np.testing.assert_array_equal(ctrl.applied, ctrl.tau_sat)
        with pytest.raises(FaultError):
            ctrl.step(_m(5))


# -- item 2: the rate limit starts from the torque applied --------------------


def test_the_rate_limit_starts_from_the_fallback_after_a_refusal_and_clear_fault() -> None:
    for policy in ("report", "latch"):
        ctrl = adaptimp.Controller(
            "pd", scenario="robot", fallback="zero", tau_rate_max=1.0, fault_policy=policy
        )
        zero, far = [0.0, 0.0], [1.0, 1.0]
        for _ in range(200):
            tau, error = ctrl.step_or_fallback(Measurement(zero, zero, tau_e=zero), xc=far)
        np.testing.assert_array_equal(tau, [17.0, 15.0])
        with pytest.raises(MeasurementError):
            ctrl.step(Measurement([np.nan, 0.0], zero, tau_e=zero), xc=far)
        np.testing.assert_array_equal(ctrl.applied, [0.0, 0.0])
        tau, error = ctrl.step_or_fallback(Measurement([np.nan, 0.0], zero, tau_e=zero), xc=far)
        assert error is not None
        np.testing.assert_array_equal(tau, [0.0, 0.0])
        if policy == "latch":
            ctrl.clear_fault()
        # It used to jump back to [17, 15] at once.
        for k in range(1, 20):
            tau, error = ctrl.step_or_fallback(Measurement(zero, zero, tau_e=zero), xc=far)
            assert error is None
            np.testing.assert_array_equal(tau, [min(k, 17.0), min(k, 15.0)])


# -- item 3: the jump limit re-anchors ---------------------------------------


def test_a_motion_during_refused_steps_does_not_lock_out_the_jump_limit() -> None:
    ctrl = adaptimp.Controller("sf", scenario="robot", q_jump_max=0.05, fault_policy="latch")
    _run(ctrl, 0, 100)
    q, te, dq = _inputs(100)
    _, error = ctrl.step_or_fallback(Measurement([np.nan, q[1]], dq, tau_e=te))
    assert error is not None
    for _ in range(50):  # latched while the arm moves 0.61 rad
        _, error = ctrl.step_or_fallback(Measurement([np.nan, q[1]], dq, tau_e=te))
    ctrl.clear_fault()
    moved = [q[0] + 0.61, q[1]]
    # No plausible sample in between: the first is a jump, refused once ...
    _, error = ctrl.step_or_fallback(Measurement(moved, dq, tau_e=te))
    assert error is not None
    assert error.startswith("q jump[0] = 6.1")
    ctrl.clear_fault()
    # ... and the motion is accepted from its second sample (it used to be
    # refused 1000 times out of 1000, clear_fault or not).
    for k in range(1000):
        _, error = ctrl.step_or_fallback(Measurement([moved[0] + 1e-5 * k, moved[1]], dq, tau_e=te))
        assert error is None


def test_a_jump_is_a_measurement_error() -> None:
    ctrl = adaptimp.Controller("sf", scenario="robot", q_jump_max=0.05)
    _run(ctrl, 0, 10)
    q, te, dq = _inputs(10)
    with pytest.raises(MeasurementError, match=r"q jump\[1\]"):
        ctrl.step(Measurement([q[0], q[1] + 0.5], dq, tau_e=te))


# -- item 4: setpoints are checked like measurements --------------------------


@pytest.mark.parametrize(
    ("setpoint", "message"),
    [
        ({"dxc": [1e99, 0.0]}, r"dxc\[0\] = 1e99 is beyond its limit ±1e1"),
        ({"dxc": [0.0, 10.5]}, r"dxc\[1\] = 1.05e1 is beyond its limit ±1e1"),
        ({"xc": [1e50, 0.0]}, r"xc\[0\] = 1e50 is beyond its limit ±3e0"),
        ({"xc": [0.0, -3.5]}, r"xc\[1\] = -3.5e0 is beyond its limit ±3e0"),
        ({"ddxc": [0.0, 2e6]}, r"ddxc\[1\] = 2e6 is beyond its limit ±1e6"),
        ({"dxc": [np.nan, 0.0]}, r"dxc\[0\] is not finite"),
    ],
)
def test_a_bad_setpoint_is_refused_and_changes_nothing(
    setpoint: dict[str, list[float]], message: str
) -> None:
    ctrl, twin = (
        adaptimp.Controller("sf", scenario="robot", q_max=3.0, dq_max=10.0) for _ in range(2)
    )
    _run(ctrl, 0, 100)
    _run(twin, 0, 100)
    q, te, dq = _inputs(100)
    xc = setpoint.pop("xc", q)
    with pytest.raises(MeasurementError, match=message):
        ctrl.step(Measurement(q, dq, tau_e=te), xc=xc, **setpoint)
    # It used to commit a reference every later step refused, for ever.
    for k in range(100, 200):
        np.testing.assert_array_equal(ctrl.step(_m(k)), twin.step(_m(k)))


def test_without_limits_the_ceilings_hold() -> None:
    ctrl = adaptimp.Controller("sf")
    q, te, dq = _inputs(0)
    with pytest.raises(MeasurementError, match=r"xc\[0\] = 1e50 is beyond its limit ±1e6"):
        ctrl.step(Measurement(q, dq, tau_e=te), xc=[1e50, 0.0])
    with pytest.raises(MeasurementError, match=r"tau_e\[0\] = 1e99 is beyond its limit ±1e9"):
        ctrl.step(Measurement(q, dq, tau_e=[1e99, 0.0]))
    with pytest.raises(MeasurementError, match=r"q\[1\] = 2e6 is beyond its limit ±1e6"):
        ctrl.step(Measurement([0.0, 2e6], dq, tau_e=te))
    assert ctrl.steps == 0


# -- item 5: restore refuses what it cannot step -------------------------------


def _trained() -> adaptimp.Controller:
    ctrl = adaptimp.Controller("sf", scenario="robot")
    _run(ctrl, 0, 300)
    return ctrl


def test_an_edited_or_corrupt_snapshot_is_refused_and_changes_nothing() -> None:
    ctrl = _trained()
    snap = ctrl.snapshot()
    target = adaptimp.Controller("sf", scenario="robot")
    _run(target, 0, 5)
    before = target.snapshot()
    n, nodes = 2, 256
    weights = 5 + 16 * n + 6 + nodes
    for index, value in [
        (weights, 1e200),  # a weight: robot scenario, the projection used to zero them
        (5, 1e99),  # the reference xd
        (5 + 7 * n, 1e99),  # the last tau_sat
        (5 + 16 * n, 0.0),  # a stored weight norm
        (len(snap) - 1, 0.0),  # the checksum
    ]:
        bad = snap.copy()
        bad[index] = value
        with pytest.raises(ConfigError, match="checksum does not match"):
            target.restore(bad)
        np.testing.assert_array_equal(target.snapshot(), before)
    # One bit flipped anywhere: refused.
    rng = np.random.default_rng(0)
    for i in rng.integers(0, len(snap), 200):
        bad = snap.copy()
        bits = bad.view(np.uint64)
        bits[i] ^= np.uint64(1) << np.uint64(rng.integers(0, 64))
        with pytest.raises(ConfigError):
            target.restore(bad)
    np.testing.assert_array_equal(target.snapshot(), before)
    target.restore(snap)
    np.testing.assert_array_equal(target.snapshot(), snap)
    # Truncated or extended: named as what it is, not by the Rust call it fails.
    for bad in (snap[:-1], np.append(snap, 0.0)):
        with pytest.raises(
            ConfigError,
            match=r"truncated or too long: not the length of a snapshot of this n and L",
        ):
            target.restore(bad)
    np.testing.assert_array_equal(target.snapshot(), snap)


def test_a_raw_fault_of_no_kind_is_named_in_pythons_words() -> None:
    from adaptimp import _adaptimp

    ctrl = adaptimp.Controller("sf")
    arm = adaptimp.TwoLinkArm()
    with pytest.raises(
        ConfigError,
        match=re.escape(
            "fault 'stale' with bias [1.0, 2.0] and fraction 0.5: the kinds are 'stale', "
        ),
    ):
        _adaptimp.simulate(ctrl, arm.core, {}, fault=("stale", 0.0, 1.0, [1.0, 2.0], 0.5))
    gone = "fault 'gone' with bias None and fraction None"
    with pytest.raises(ConfigError, match=re.escape(gone)):
        _adaptimp.simulate(ctrl, arm.core, {}, fault=("gone", 0.0, 1.0, None, None))


def test_weights_no_step_could_use_are_refused() -> None:
    ctrl = _trained()
    w = ctrl.weights
    for scale, message in [(1e200, r"‖weights\.D‖ = inf"), (100.0, r"‖weights\.D‖ = ")]:
        with pytest.raises(ConfigError, match=message):
            ctrl.load_weights({k: v * scale if k == "D" else v for k, v in w.items()})
    # Without projection the step's own bound (1e100) still holds.
    free = adaptimp.Controller("sf")
    with pytest.raises(ConfigError, match=r"weights\.G = "):
        free.load_weights({**free.weights, "G": np.full((2, 256), 1e99)})


def test_load_state_dict_refuses_keys_that_disagree_with_the_snapshot() -> None:
    ctrl = _trained()
    state = ctrl.state_dict()
    other = adaptimp.Controller("sf", scenario="robot")
    for key, edit in [
        ("W_D", lambda v: v * 2.0),
        ("W_G", lambda v: v + 1e-9),
        ("steps", lambda v: v + 1),
        ("zeta", lambda v: v + 1.0),
    ]:
        edited = {**state, key: edit(state[key])}
        with pytest.raises(ConfigError, match=f"state\\['{key}'\\] disagrees with"):
            other.load_state_dict(edited)
        assert other.steps == 0
    # Edited weights load on their own, as documented.
    edited = {**state, "W_D": state["W_D"] * 0.5}
    other.load_state_dict(edited, weights_only=True)
    np.testing.assert_array_equal(other.weights["D"], state["W_D"] * 0.5)
    # A state of another case is refused as a whole (its weights load).
    of = adaptimp.Controller("of", scenario="robot")
    with pytest.raises(ConfigError, match="state is of case 'sf', this controller 'of'"):
        of.load_state_dict(state)
    of.load_state_dict(state, weights_only=True)
    # The whole state, unedited: continues bit-identically.
    other.load_state_dict(state)
    for k in range(300, 400):
        np.testing.assert_array_equal(other.step(_m(k)), ctrl.step(_m(k)))


def test_copies_and_pickles_carry_the_refusal_record() -> None:
    ctrl = adaptimp.Controller(
        "sf", scenario="robot", fallback="zero", tau_rate_max=0.5, q_jump_max=0.05
    )
    _run(ctrl, 0, 100)
    ctrl.step_or_fallback(Measurement([np.nan, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]))
    twins = (copy.deepcopy(ctrl), pickle.loads(pickle.dumps(ctrl)))
    for k in range(100, 150):
        tau = ctrl.step_or_fallback(_m(k))[0]
        if k == 100:  # rate-limited from the zero fallback
            np.testing.assert_array_equal(np.abs(tau), [0.5, 0.5])
        for twin in twins:
            np.testing.assert_array_equal(twin.step_or_fallback(_m(k))[0], tau)


# -- minor items --------------------------------------------------------------


def test_an_infinite_limit_means_none_as_in_c() -> None:
    assert adaptimp.Controller("sf", q_jump_max=np.inf).params["q_jump_max"] is None
    ctrl = adaptimp.Controller("sf", q_jump_max=[0.05, np.inf])
    assert ctrl.params["q_jump_max"] == [0.05, np.inf]
    q, te, dq = _inputs(0)
    ctrl.step(Measurement(q, dq, tau_e=te))
    ctrl.step(Measurement([q[0], q[1] + 0.5], dq, tau_e=te))  # no limit on joint 2
    with pytest.raises(MeasurementError, match=r"q jump\[0\]"):
        ctrl.step(Measurement([q[0] + 0.5, q[1] + 0.5], dq, tau_e=te))
    with pytest.raises(ConfigError, match=r"q_jump_max\[0\] must be a number \(inf: no limit\)"):
        adaptimp.Controller("sf", q_jump_max=np.nan)
    with pytest.raises(ConfigError, match="limit > 0"):
        adaptimp.Controller("sf", q_max=-np.inf)


@pytest.mark.parametrize("T", [np.inf, np.nan, -1.0])
def test_mujoco_simulate_names_a_bad_duration(T: float) -> None:
    from adaptimp import mujoco as amj

    with pytest.raises(ValueError, match="T must be finite and > 0"):
        amj.simulate("pd", "two_link", T=T)
    with pytest.raises(ValueError, match="at most 1e15 steps"):
        amj.simulate("pd", "two_link", T=1e300)
