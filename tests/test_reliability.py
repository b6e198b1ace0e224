"""Reliability from Python: configurations that hung are refused at once by
named conditions, a spike poisons nothing, and the fail-safe step."""

from __future__ import annotations

import signal
import time

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"eps": 1e-80}, "Ts/ε ≤ 1e6"),
        ({"Ts": 1e45}, "Ts ≤ 1 s"),
        ({"K1": 1e300}, "|value| ≤ 1e9"),
        ({"xc_offset": 1e300}, "|xc| ≤ 1e6 rad"),
        ({"xc_omega": 1e300}, "|ẋc| ≤ 1e6 rad/s"),
        ({"sigma": 50.0, "Ts": 1e-3}, "Ts Γ σ < 1"),
    ],
)
def test_configurations_that_hung_or_overflowed_are_refused(
    kwargs: dict[str, float], message: str
) -> None:
    with pytest.raises(ValueError, match=message.replace("|", r"\|")):
        adaptimp.Controller("sf", **kwargs)


def test_simulate_refuses_a_hanging_observer_and_huge_substeps() -> None:
    with pytest.raises(ValueError, match="Ts/ε ≤ 1e6"):
        adaptimp.simulate("sf", T=0.05, eps=1e-50)
    with pytest.raises(ValueError, match="1 ≤ substeps ≤ 10 000"):
        adaptimp.simulate("pd", T=0.05, substeps=2**31)
    with pytest.raises(ValueError, match="substeps is out of range"):
        adaptimp.simulate("pd", T=0.05, substeps=2**63)


def _inputs(k: int) -> tuple[list[float], list[float], list[float]]:
    s = k * 1e-3
    return (
        [0.2 + 0.1 * np.sin(s), 0.2 + 0.1 * np.cos(s)],
        [max(0.0, 10 * np.sin(s)), 0.0],
        [0.1 * np.cos(s), -0.1 * np.sin(s)],
    )


@pytest.mark.parametrize(
    "spike",
    [
        {"q": [1e151, 0.2]},
        {"dq": [0.0, -1e151]},
        {"tau_e": [1e155, 0.0]},
    ],
)
def test_a_spike_is_refused_and_nothing_learned_is_lost(spike: dict[str, list[float]]) -> None:
    ctrl, twin = (adaptimp.Controller("sf", scenario="robot") for _ in range(2))
    for k in range(300):
        q, te, dq = _inputs(k)
        ctrl.step(Measurement(q, dq, tau_e=te))
        twin.step(Measurement(q, dq, tau_e=te))
    before = ctrl.weights
    q, te, dq = _inputs(300)
    args = {"q": q, "tau_e": te, "dq": dq, **spike}
    with pytest.raises(ValueError, match="beyond its limit"):
        ctrl.step(Measurement(args["q"], args["dq"], tau_e=args["tau_e"]))
    for name, w in ctrl.weights.items():
        np.testing.assert_array_equal(w, before[name])
    assert ctrl.fault is not None
    assert ctrl.fault[1] == 300
    for k in range(300, 400):
        q, te, dq = _inputs(k)
        np.testing.assert_array_equal(
            ctrl.step(Measurement(q, dq, tau_e=te)), twin.step(Measurement(q, dq, tau_e=te))
        )


def test_the_fail_safe_step_returns_the_fallback_and_latches() -> None:
    ctrl = adaptimp.Controller(
        "sf", scenario="robot", fallback="damping", fallback_damping=2.0, fault_policy="latch"
    )
    for k in range(100):
        q, te, dq = _inputs(k)
        tau, error = ctrl.step_or_fallback(Measurement(q, dq, tau_e=te))
        assert error is None
    q, te, dq = _inputs(100)
    tau, error = ctrl.step_or_fallback(Measurement([np.nan, q[1]], [0.5, -0.5], tau_e=te))
    assert error == "q[0] is not finite (NaN or infinite)"
    np.testing.assert_array_equal(tau, [-1.0, 1.0])
    # Latched: refused until cleared, then the run goes on.
    tau, error = ctrl.step_or_fallback(Measurement(q, dq, tau_e=te))
    assert error is not None
    assert "clear_fault()" in error
    assert ctrl.steps == 100
    ctrl.clear_fault()
    assert ctrl.fault is None
    tau, error = ctrl.step_or_fallback(Measurement(q, dq, tau_e=te))
    assert error is None
    assert ctrl.steps == 101


def test_plausibility_and_rate_limits_from_python() -> None:
    ctrl = adaptimp.Controller("sf", scenario="robot", q_max=1.0, tau_rate_max=[0.5, 0.5])
    with pytest.raises(ValueError, match=r"q\[0\] = 1.5e0 is beyond its limit"):
        ctrl.step(Measurement([1.5, 0.0], [0.0, 0.0], tau_e=[0.0, 0.0]))
    last = np.zeros(2)
    for k in range(50):
        q, te, dq = _inputs(k)
        tau = ctrl.step(Measurement(q, dq, tau_e=te))
        assert np.max(np.abs(tau - last)) <= 0.5 + 1e-12
        last = tau
    assert adaptimp.Controller("sf", q_max=None).params["q_max"] is None


def _chain_urdf(n: int) -> str:
    """A URDF of ``n`` links in a chain: fixed joints, the last three revolute."""
    parts = ["<robot name='big'>", "<link name='l0'/>"]
    for i in range(1, n + 1):
        parts.append(f"<link name='l{i}'/>")
        if i + 3 > n:
            parts.append(
                f"<joint name='j{i}' type='revolute'><parent link='l{i - 1}'/>"
                f"<child link='l{i}'/><axis xyz='0 0 1'/>"
                "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint>"
            )
        else:
            parts.append(
                f"<joint name='j{i}' type='fixed'><parent link='l{i - 1}'/>"
                f"<child link='l{i}'/><origin xyz='0 0 0.001'/></joint>"
            )
    parts.append("</robot>")
    return "\n".join(parts)


class _Interrupted(Exception):
    pass


def test_reading_a_large_urdf_stops_on_a_signal() -> None:
    """A signal's handler runs while a URDF is read, and its exception stops
    the reading there (Ctrl-C's KeyboardInterrupt is such an exception): the
    reader asks between two pieces of its work. Timed in CPU seconds by the
    process's own profiling timer, which fires after 0.1 s of CPU whatever
    the machine's load: the interrupted reading spends a small part of a
    whole one's CPU (it spent all of it before: no signal was seen until the
    reading returned)."""
    n = 40_000
    text = _chain_urdf(n)
    t0 = time.process_time()
    assert adaptimp.Chain.from_urdf(text, tip=f"l{n}").n == 3
    whole = time.process_time() - t0

    def interrupt(signum: int, frame: object) -> None:
        raise _Interrupted

    old = signal.signal(signal.SIGPROF, interrupt)
    try:
        signal.setitimer(signal.ITIMER_PROF, 0.1)
        t0 = time.process_time()
        with pytest.raises(_Interrupted) as stopped:
            adaptimp.Chain.from_urdf(text, tip=f"l{n}")
        spent = time.process_time() - t0
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, old)
    # Raised inside the reading, not after it ended (then with its context).
    assert stopped.value.__context__ is None
    assert spent < 0.5 * whole, (spent, whole)


def test_a_controller_takes_over_a_robots_torque() -> None:
    """take_over(tau): the first step's rate limit moves from the torque a
    robot's own controller held the arm with (libfranka's limitRate from
    tau_J_d), not from zero; only before the first step, finite, within τmax,
    each refused by name with nothing changed."""
    c = adaptimp.Controller("sf", "robot", n=2, tau_rate_max=0.5)
    cold = adaptimp.Controller("sf", "robot", n=2, tau_rate_max=0.5)
    with pytest.raises(
        adaptimp.MeasurementError, match=r"^tau\[0\] is not finite \(NaN or infinite\)$"
    ):
        c.take_over([np.nan, 0.0])
    with pytest.raises(
        adaptimp.ConfigError,
        match=r"^torque taken over\[1\] = 1e3 is beyond its limit ±1\.5e1; "
        r"the state was left unchanged$",
    ):
        c.take_over([0.0, 1e3])
    np.testing.assert_array_equal(c.applied, [0.0, 0.0])
    c.take_over([6.0, -4.0])
    np.testing.assert_array_equal(c.applied, [6.0, -4.0])
    m = adaptimp.Measurement([0.1, 0.2], [0.0, 0.0])
    np.testing.assert_array_equal(c.step(m), [5.5, -3.5])
    np.testing.assert_array_equal(cold.step(m), [-0.5, 0.5])
    with pytest.raises(adaptimp.ConfigError, match=r"^take_over: only before the first step$"):
        c.take_over([0.0, 0.0])
    c.reset()
    np.testing.assert_array_equal(c.applied, [0.0, 0.0])
