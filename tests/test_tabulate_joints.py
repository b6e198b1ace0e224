"""A joint reference written in Python tabulated by the bindings
(``_adaptimp.tabulate_joints``, the one tabulation ``adaptimp.mujoco``'s
runs use): the reference's own values at t_k = (start + k)·Ts, bit for bit,
and a wrong value named."""

from __future__ import annotations

import numpy as np
import pytest

from adaptimp import MeasurementError, _adaptimp, _loops
from adaptimp._cartesian_impedance import _array


def _reference(t: float) -> tuple[np.ndarray, np.ndarray, list[float]]:
    w = np.array([1.0, 2.0, 3.0])
    return (
        0.3 * np.sin(w * t),
        0.3 * w * np.cos(w * t),
        [float(v) for v in -0.3 * w * w * np.sin(w * t)],  # a list: read through check
    )


def test_the_tables_are_the_python_loops() -> None:
    got = _adaptimp.tabulate_joints(_reference, 250, 1e-3, 3, 7, "reference(t)", _array)
    rows = [_reference((7 + k) * 1e-3) for k in range(250)]
    want = [np.array([np.asarray(r[i], dtype=np.float64) for r in rows]) for i in range(3)]
    for g, w, run in zip(got, want, _loops.tabulate(_reference, 250, 1e-3, 3, 7)):
        assert g.shape == (250, 3)
        assert np.array_equal(g, w)
        assert np.array_equal(run, w)  # what a run of adaptimp.mujoco tabulates


def test_a_wrong_value_is_named() -> None:
    def short(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return np.zeros(3), np.zeros(2), np.zeros(3)

    with pytest.raises(
        MeasurementError, match=r"^reference\(t\)\[1\] must have shape \(3,\), got shape \(2,\)$"
    ):
        _adaptimp.tabulate_joints(short, 2, 1e-3, 3, 0, "reference(t)", _array)
    with pytest.raises(ValueError, match=r"^reference\(t\) must return 3 arrays"):
        _adaptimp.tabulate_joints(lambda t: (np.zeros(3),), 2, 1e-3, 3, 0, "reference(t)", _array)
