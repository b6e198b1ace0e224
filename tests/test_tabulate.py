"""``adaptimp.cartesian.tabulate``: a Python path laid out as the core's pose
targets (steps, 24) by the core's loop (``_adaptimp.tabulate_path``), every
value read where it is a float64 array of its shape and checked by name
otherwise. The rows are asserted value for value against the layout of
``pose_target``; the errors word for word."""

from __future__ import annotations

from typing import Any

import numpy as np
import pytest

from adaptimp import MeasurementError
from adaptimp.cartesian import pose_target, tabulate

TS = 1e-3
R0 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
R1 = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def mixed(t: float) -> Any:
    """Every form a path may return, by the step k = round(t / Ts)."""
    k = round(t / TS)
    p, dp, ddp = np.array([t, 2 * t, 3 * t]), np.full(3, k + 0.5), np.full(3, -k - 0.25)
    if k < 2:  # 3 lists: read through the check; the rotation given to tabulate
        return [list(p), list(dp), list(ddp)]
    if k < 4:  # 6 arrays: a rotation and its rates
        return (p, dp, ddp, R1, np.full(3, 0.5 * k), np.full(3, -1.5 * k))
    if k < 6:  # 3 arrays: that rotation kept, zero rates
        return (p, dp, ddp)
    if k < 7:  # 6 values, None: the identity, zero rates; float32 and a list
        return (p.astype(np.float32), dp, list(ddp), None, None, None)
    return iter((p, dp, ddp))  # any iterable of 3


def expected(start: int, steps: int) -> np.ndarray:
    rows, r = [], R0
    for k in range(start, start + steps):
        t = k * TS
        p, dp, ddp = np.array([t, 2 * t, 3 * t]), np.full(3, k + 0.5), np.full(3, -k - 0.25)
        if 2 <= k < 4:
            r = R1
            rows.append(pose_target(p, dp, ddp, r, np.full(3, 0.5 * k), np.full(3, -1.5 * k)))
        elif k == 6:
            r = np.eye(3)
            rows.append(pose_target(p.astype(np.float32), dp, ddp, r))
        else:
            rows.append(pose_target(p, dp, ddp, r))
    return np.array(rows)


@pytest.mark.parametrize("start", [0, 3])
def test_every_form_a_path_returns_is_laid_out_as_pose_target(start: int) -> None:
    got = tabulate(mixed, 9 - start, TS, R0, start=start)
    assert got.shape == (9 - start, 24)
    np.testing.assert_array_equal(got, expected(start, 9 - start))


def test_the_time_of_each_row_is_start_plus_k_times_ts() -> None:
    seen: list[float] = []

    def path(t: float) -> tuple[np.ndarray, ...]:
        seen.append(t)
        return (np.zeros(3), np.zeros(3), np.zeros(3))

    tabulate(path, 4, 0.1, np.eye(3), start=7)
    assert seen == [(7 + k) * 0.1 for k in range(4)]


def test_no_steps_no_call() -> None:
    def path(t: float) -> Any:
        raise AssertionError("called")

    assert tabulate(path, 0, TS, np.eye(3)).shape == (0, 24)


Z = np.zeros(3)


@pytest.mark.parametrize(
    ("value", "error", "message"),
    [
        ((np.zeros(2), Z, Z), MeasurementError,
         "path(t)[0] must have shape (3,), got shape (2,)"),
        ((Z, "x", Z), TypeError, "path(t)[1] must be real numbers, got str 'x'"),
        ((Z, Z, Z, np.zeros(9), Z, Z), MeasurementError,
         "path(t)[3] must have shape (3, 3), got shape (9,)"),
        ((Z, Z, Z, None, np.zeros((3, 1)), None), MeasurementError,
         "path(t)[4] must have shape (3,), got shape (3, 1)"),
        ((Z, Z, Z, Z), ValueError,
         "path(t) must return 3 or 6 arrays (p, dp, ddp[, R, w, dw]), got 4"),
    ],
)  # fmt: skip
def test_a_bad_value_is_refused_by_name(value: Any, error: type, message: str) -> None:
    with pytest.raises(error) as e:
        tabulate(lambda t: value, 3, TS, np.eye(3))
    assert str(e.value) == message


def test_an_error_of_the_path_itself_comes_through() -> None:
    def path(t: float) -> Any:
        raise KeyError("the user's")

    with pytest.raises(KeyError, match="the user's"):
        tabulate(path, 2, TS, np.eye(3))


def test_a_table_too_large_for_memory_is_a_memory_error() -> None:
    def path(t: float) -> Any:
        raise AssertionError("called")

    with pytest.raises(MemoryError, match="a path table of 100000000000000 rows"):
        tabulate(path, 10**14, TS, np.eye(3))
