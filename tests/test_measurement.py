"""One step signature (issue: typed I/O): every controller takes an
``adaptimp.Measurement``, and the old call shapes give the same bits with a
``DeprecationWarning`` naming the new call."""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import pytest

import adaptimp
import adaptimp.mujoco as amj
from adaptimp import Measurement, MeasurementError

Q, DQ, TE = [0.25, -0.05], [0.1, -0.2], [0.5, 0.0]


def test_a_measurement_holds_what_it_was_given() -> None:
    m = Measurement(Q, DQ, tau_e=TE, wrench=[1.0, 2.0, 3.0])
    assert m.n == 2
    np.testing.assert_array_equal(m.q, Q)
    np.testing.assert_array_equal(m.dq, DQ)
    np.testing.assert_array_equal(m.tau_e, TE)
    np.testing.assert_array_equal(m.wrench, [1.0, 2.0, 3.0, 0.0, 0.0, 0.0])  # f alone: m = 0
    bare = Measurement(np.array(Q))
    assert (bare.dq, bare.tau_e, bare.wrench) == (None, None, None)
    assert repr(bare) == "adaptimp.Measurement(q=[0.25, -0.05], dq=None, tau_e=None, wrench=None)"
    with pytest.raises(AttributeError):
        m.q = np.zeros(2)  # type: ignore[misc]


def test_a_measurement_pickles_copies_and_compares_by_value() -> None:
    import copy
    import pickle

    m = Measurement(Q, DQ, tau_e=TE, wrench=[1.0, 2.0, 3.0])
    for twin in (pickle.loads(pickle.dumps(m)), copy.deepcopy(m)):
        assert twin == m
        assert repr(twin) == repr(m)
    assert Measurement(Q) == Measurement(np.array(Q))
    assert Measurement(Q) != Measurement(Q, DQ)
    assert Measurement(Q, wrench=[0.0] * 6) != Measurement(Q)
    assert Measurement([np.nan]) != Measurement([np.nan])


def test_a_measurement_keeps_a_sensor_nan_for_the_controller_to_refuse() -> None:
    m = Measurement([np.nan, 0.0], DQ)
    assert np.isnan(m.q[0])
    ctrl = adaptimp.Controller("sf", scenario="robot")
    tau, error = ctrl.step_or_fallback(m)
    assert error == "q[0] is not finite (NaN or infinite)"
    np.testing.assert_array_equal(tau, [0.0, 0.0])
    assert ctrl.fault == ("q[0] is not finite (NaN or infinite)", 0)


@pytest.mark.parametrize(
    ("make", "error", "message"),
    [
        (lambda: Measurement([]), MeasurementError,
         "q must have 1 to 7 values (one per joint), got 0"),
        (lambda: Measurement(np.zeros(8)), MeasurementError,
         "q must have 1 to 7 values (one per joint), got 8"),
        (lambda: Measurement(0.5), MeasurementError,
         "q must be one value per joint (a 1-D array), got a scalar"),
        (lambda: Measurement(np.zeros((2, 1))), MeasurementError,
         "q must be one value per joint (a 1-D array), got shape (2, 1)"),
        # Both named: the length q set, and the one that differs.
        (lambda: Measurement(Q, [0.0]), MeasurementError,
         "dq has 1 values and q 2: one value per joint each"),
        (lambda: Measurement(Q, tau_e=[0.0] * 3), MeasurementError,
         "tau_e has 3 values and q 2: one value per joint each"),
        (lambda: Measurement(Q, wrench=[0.0] * 5), MeasurementError,
         "wrench must have shape (6,) ([f; m], N and N m) or (3,) (f alone), got shape (5,)"),
        (lambda: Measurement(object()), TypeError,
         "q must be a sequence or array of real numbers, got object"),
    ],
)  # fmt: skip
def test_a_measurement_of_a_wrong_shape_is_refused_by_name(
    make: Any, error: type[Exception], message: str
) -> None:
    with pytest.raises(error) as e:
        make()
    assert str(e.value) == message


def test_a_measurement_of_other_joints_is_refused_and_recorded() -> None:
    ctrl = adaptimp.Controller("sf", scenario="robot")
    with pytest.raises(
        MeasurementError, match=r"^q must have shape \(2,\) \(one value per joint\), got length 3$"
    ):
        ctrl.step(Measurement([0.0] * 3, [0.0] * 3))
    assert ctrl.fault is not None
    assert "wrong shape or type" in ctrl.fault[0]
    with pytest.raises(
        TypeError, match=r"^Controller\.step\(\) got an unexpected keyword argument 'q'$"
    ):
        ctrl.step(Measurement(Q, DQ), q=Q)
    with pytest.raises(
        TypeError, match=r"^Controller\.step\(\) got multiple values for argument 'xc'$"
    ):
        ctrl.step(Measurement(Q, DQ), Q, xc=Q)
    with pytest.raises(TypeError, match=r"^Controller\.step\(\) takes at most 4 positional"):
        ctrl.step(Measurement(Q, DQ), Q, DQ, DQ, DQ)
    # The setpoint positionally (no keyword dictionary) or by keyword: the same step.
    a, b = (adaptimp.Controller("sf", scenario="robot") for _ in range(2))
    np.testing.assert_array_equal(
        a.step(Measurement(Q, DQ), [0.3, 0.0], [0.1, 0.0]),
        b.step(Measurement(Q, DQ), xc=[0.3, 0.0], dxc=[0.1, 0.0]),
    )


def _deprecated(call: Any, message: str) -> Any:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = call()
    assert [str(w.message) for w in caught] == [message]
    assert caught[0].category is DeprecationWarning
    assert caught[0].filename == __file__  # the user's line, not the package's
    return out


def test_the_joint_controllers_old_call_gives_the_same_bits() -> None:
    new, old = (
        adaptimp.Controller("sf", scenario="robot"),
        adaptimp.Controller("sf", scenario="robot"),
    )
    message = (
        "Controller.step(q, tau_e, dq) is deprecated: pass one "
        "adaptimp.Measurement(q, dq, tau_e=tau_e)"
    )
    for k in range(20):
        q = [0.25 + 1e-3 * k, -0.05]
        a = new.step(Measurement(q, DQ, tau_e=TE))
        b = _deprecated(lambda q=q: old.step(q, TE, DQ), message)
        np.testing.assert_array_equal(a, b)
    # A joint controller reads τe, not the wrench.
    np.testing.assert_array_equal(
        adaptimp.Controller("pd").step(Measurement(Q, DQ, tau_e=TE, wrench=[9.0] * 6)),
        adaptimp.Controller("pd").step(Measurement(Q, DQ, tau_e=TE)),
    )


def test_computed_torques_old_call_gives_the_same_bits() -> None:
    pytest.importorskip("pinocchio")
    from adaptimp.baselines import ComputedTorque

    new, old = ComputedTorque(Ts=1e-3), ComputedTorque(Ts=1e-3)
    message = (
        "ComputedTorque.step(q, tau_e, dq) is deprecated: pass one "
        "adaptimp.Measurement(q, dq, tau_e=tau_e)"
    )
    a = new.step(Measurement(Q, DQ, tau_e=TE), xc=[0.3, 0.0])
    b = _deprecated(lambda: old.step(Q, TE, DQ, xc=[0.3, 0.0]), message)
    np.testing.assert_array_equal(a, b)
    with pytest.raises(
        MeasurementError, match="ComputedTorque needs the measured joint velocity dq"
    ):
        new.step(Measurement(Q))


def _arm() -> adaptimp.Chain:
    return adaptimp.Chain(
        [
            {"kind": "revolute", "axis": [0, 0, 1]},
            {"kind": "revolute", "xyz": [0.3, 0, 0], "axis": [0, 0, 1]},
        ],
        tip={"xyz": [0.2, 0, 0]},
    )


def test_the_cartesian_controllers_old_call_gives_the_same_bits() -> None:
    kw: dict[str, Any] = {
        "q0": [0.3, 0.6],
        "Kd_rot": 0.0,
        "tau_max": 20.0,
        "Kp": 5.0,
        "Kzeta": 25.0,
    }
    new = adaptimp.CartesianController(_arm(), "pd", **kw)
    old = adaptimp.CartesianController(_arm(), "pd", **kw)
    message = (
        "CartesianController.step(q, dq, wrench) is deprecated: pass one "
        "adaptimp.Measurement(q, dq, wrench=wrench)"
    )
    wrench = [0.5, -0.2, 0.0, 0.0, 0.0, 0.1]
    for k in range(10):
        q = [0.3 + 1e-3 * k, 0.6]
        a = new.step(Measurement(q, [0.0, 0.0], wrench=wrench))
        b = _deprecated(lambda q=q: old.step(q, [0.0, 0.0], wrench), message)
        np.testing.assert_array_equal(a, b)
    # A Cartesian controller reads the wrench, not τe.
    twin = adaptimp.CartesianController(_arm(), "pd", **kw)
    twin.step(Measurement([0.3, 0.6], [0.0, 0.0], tau_e=[9.0, 9.0]))
    np.testing.assert_array_equal(
        twin.tau,
        adaptimp.CartesianController(_arm(), "pd", **kw).step(Measurement([0.3, 0.6], [0.0, 0.0])),
    )


def test_the_cartesian_step_is_the_cores_own_method() -> None:
    """``CartesianController.step(m)`` goes from the call to the core (no
    Python frame between: docs/performance.md) with the Python method's bits;
    a path or ``record`` set later takes effect; a path that holds its
    controller is collected with it."""
    import gc
    import weakref

    kw: dict[str, Any] = {"q0": [0.3, 0.6], "Kd_rot": 0.0, "tau_max": 20.0, "Kp": 5.0}
    p0 = _arm().pose(np.array(kw["q0"]))[0]

    def circle(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        c, s = np.cos(np.pi * t), np.sin(np.pi * t)
        p = p0 + 0.01 * np.array([c - 1.0, s, 0.0])
        return p, 0.01 * np.pi * np.array([-s, c, 0.0]), np.zeros(3)

    fast = adaptimp.CartesianController(_arm(), "sf", path=circle, **kw)
    slow = adaptimp.CartesianController(_arm(), "sf", path=circle, **kw)
    assert type(fast.step).__name__ == "builtin_function_or_method"
    python_step = adaptimp.CartesianController.step  # the method written in Python
    wrench = [0.5, -0.2, 0.0, 0.0, 0.0, 0.1]
    for k in range(20):
        m = Measurement([0.3 + 1e-3 * k, 0.6 - 1e-3 * k], [0.01, -0.02], wrench=wrench)
        if k == 10:
            fast.path = slow.path = None  # from now on the last target held
        if k == 15:
            fast.record = slow.record = False
        np.testing.assert_array_equal(fast.step(m), python_step(slow, m))
    assert fast._k == slow._k == 20
    for key, rows in fast.arrays().items():
        np.testing.assert_array_equal(rows, slow.arrays()[key])
        assert len(rows) == 15  # rows 15 to 19 not kept
    np.testing.assert_array_equal(fast.arrays()["pc"][9], circle(9e-3)[0])
    # A path that refers to its controller: a cycle through the core's step.
    held = adaptimp.CartesianController(_arm(), "sf", **kw)
    held.path = lambda t, ctrl=held: circle(t + ctrl.Ts)
    held.step(Measurement(kw["q0"], [0.0, 0.0]))
    gone = weakref.ref(held)
    del held
    gc.collect()
    assert gone() is None


class _PD:
    """A joint PD written in Python, in the protocol's call shape."""

    Ts = 1e-3

    def __init__(self) -> None:
        self.seen: list[Measurement] = []

    def step(self, m: Measurement, **sp: Any) -> np.ndarray:
        self.seen.append(m)
        assert m.dq is not None
        assert m.tau_e is not None
        assert m.wrench is not None
        return 20.0 * (np.array([0.3, 0.1]) - m.q) - 2.0 * m.dq - m.tau_e


class _OldPD:
    """The same PD in the deprecated call shape."""

    Ts = 1e-3

    def step(self, q: Any, tau_e: Any, dq: Any = None, **sp: Any) -> np.ndarray:
        return 20.0 * (np.array([0.3, 0.1]) - q) - 2.0 * dq - tau_e


def test_the_loop_calls_every_python_controller_with_one_measurement() -> None:
    new = _PD()
    a = amj.simulate(new, "two_link", T=0.05)
    assert len(new.seen) == 50
    assert all(isinstance(m, Measurement) for m in new.seen)
    # The measurement is the loop's: the plant's q of each row.
    np.testing.assert_array_equal(new.seen[10].q, a.q[10])
    message = (
        "_OldPD.step(q, tau_e, dq) is deprecated: write step(m, **setpoint), m an "
        "adaptimp.Measurement (m.q, m.dq, m.tau_e, m.wrench)"
    )
    b = _deprecated(lambda: amj.simulate(_OldPD(), "two_link", T=0.05), message)
    np.testing.assert_array_equal(a.tau, b.tau)
    np.testing.assert_array_equal(a.q, b.q)
