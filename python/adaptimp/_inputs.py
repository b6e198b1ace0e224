"""Arguments checked by the name the user wrote: reals (an array of a given
shape), a positive number. The fronts' conversions in one place, so that text
("0.1" became 0.1), bools (True became 1), complex numbers (their imaginary
part dropped) and objects are refused by name, never by NumPy's own words."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ._errors import ConfigError

FloatArray = NDArray[np.float64]


def reals(
    name: str, value: Any, shape: tuple[int, ...] | None = None, *, finite: bool = True
) -> FloatArray:
    """``value`` as a float64 array (of ``shape`` if given), or an error naming
    ``name``: a ``TypeError`` for anything but real numbers (text, bools,
    complex numbers, objects), a ``ValueError`` for another shape or (with
    ``finite``) a value that is NaN or infinite."""
    if isinstance(value, (str, bytes, bool, np.bool_)) or value is None:
        raise TypeError(f"{name} must be real numbers, got {type(value).__name__} {value!r:.40}")
    try:
        given = np.asarray(value)
    except (TypeError, ValueError) as e:
        raise TypeError(f"{name} must be real numbers ({e})") from None
    if given.dtype.kind not in "fiu":
        raise TypeError(f"{name} must hold real numbers, got an array of dtype {given.dtype}")
    v = given.astype(np.float64)
    if shape is not None and v.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {v.shape}")
    if finite and not np.all(np.isfinite(v)):
        bad = int(np.flatnonzero(~np.isfinite(v))[0])
        raise ValueError(f"{name}[{bad}] = {v.flat[bad]} is not finite")
    return v


def number(name: str, value: Any) -> float:
    """``value`` as a finite real number, or an error naming ``name`` (a
    ``TypeError`` for text, a bool, a sequence, a complex number)."""
    real = isinstance(value, (int, float, np.integer, np.floating))
    if isinstance(value, (bool, np.bool_)) or not real:
        raise TypeError(f"{name} must be a number, got {type(value).__name__} {value!r:.40}")
    v = float(value)
    if not math.isfinite(v):
        raise ConfigError(f"{name} must be finite, got {value!r}")
    return v


def positive(name: str, value: Any, unit: str = "s") -> float:
    """:func:`number`, and > 0."""
    v = number(name, value)
    if not v > 0:
        raise ConfigError(f"{name} must be a finite number > 0 ({unit}), got {value!r}")
    return v
