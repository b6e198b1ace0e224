"""Commanded trajectories xc(t) with their derivatives (SPEC §4), for the loops
of :mod:`adaptimp.mujoco` and :mod:`adaptimp.baselines` (NumPy only)."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]

Reference = Callable[[float], tuple[ArrayLike, ArrayLike, ArrayLike]]
"""A commanded trajectory: ``reference(t) -> (xc, dxc, ddxc)`` at time t (s)."""


def sinusoid(offset: ArrayLike, sin: ArrayLike, cos: ArrayLike, omega: ArrayLike) -> Reference:
    """xc_i(t) = o_i + a_i sin(ω_i t) + b_i cos(ω_i t) with its derivatives (SPEC §4).

    ``offset`` o and the amplitudes a, b in rad (or m), ``omega`` ω in rad/s;
    each a number or one value per coordinate.
    """
    o, a, b, w = np.broadcast_arrays(
        *(np.asarray(v, dtype=np.float64) for v in (offset, sin, cos, omega))
    )

    def reference(t: float) -> tuple[FloatArray, FloatArray, FloatArray]:
        s, c = np.sin(w * t), np.cos(w * t)
        return o + a * s + b * c, w * (a * c - b * s), -(w**2) * (a * s + b * c)

    return reference


def paper_circle() -> Reference:
    """The paper's commanded trajectory (64): xc = [0.2 − 0.2 cos πt, 0.2 + 0.2 sin πt] rad."""
    return sinusoid([0.2, 0.2], [0.0, 0.2], [-0.2, 0.0], math.pi)
