"""Faults injected into a closed loop (the core's ``src/sim/inject.rs``): what goes
wrong on a real robot, over a window of time, for :func:`adaptimp.simulate` and
:func:`adaptimp.mujoco.simulate` alike."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Union

import numpy as np

from ._inputs import number, positive

FAULT_KINDS = ("stale", "nan_burst", "force_bias", "actuator_drop", "skipped")
"""The kinds of :class:`Fault`."""

CoreFault = tuple[str, float, float, Union[list[float], None], Union[float, None]]


@dataclass(frozen=True)
class Fault:
    """A fault injected over ``start ≤ t < start + duration`` (s).

    ``kind``:

    - ``"stale"``: the sensors repeat their last sample (q, q̇, τe frozen);
    - ``"nan_burst"``: the position sensor reads NaN;
    - ``"force_bias"``: the force sensor reads τe + ``bias`` (N m, a number
      or one per joint);
    - ``"actuator_drop"``: each actuator delivers at most ``fraction`` of its
      limit τmax (the controller's; on MuJoCo the actuators');
    - ``"skipped"``: no control step runs; the last applied torque is held.

    During the window a step the controller refuses does not end the run: its
    fallback torque is applied and the row is marked in ``refused``.

    Examples
    --------
    >>> import adaptimp
    >>> res = adaptimp.simulate("sf", "robot", T=0.5, fault=adaptimp.Fault("nan_burst", 0.2, 0.05))
    >>> int(res.refused.sum())
    50
    """

    kind: str
    start: float
    duration: float
    bias: float | Sequence[float] | None = None
    fraction: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in FAULT_KINDS:
            raise ValueError(f"Fault kind must be one of {FAULT_KINDS}, got {self.kind!r}")
        if (self.bias is not None) != (self.kind == "force_bias"):
            raise TypeError("bias= goes with kind 'force_bias' (and only with it)")
        if (self.fraction is not None) != (self.kind == "actuator_drop"):
            raise TypeError("fraction= goes with kind 'actuator_drop' (and only with it)")
        # By name, before any run: "2" was taken as 2 s, a duration ≤ 0 refused
        # only when a run began.
        number("Fault start", self.start)
        positive("Fault duration", self.duration)

    def core(self, n: int) -> CoreFault:
        """The form the compiled core takes, for n joints."""
        bias = None
        if self.bias is not None:
            b = np.asarray(self.bias, dtype=np.float64)
            if b.shape not in ((), (n,)):
                raise ValueError(f"Fault bias must be a number or have shape ({n},), got {b.shape}")
            bias = np.broadcast_to(b, (n,)).tolist()
        fraction = None if self.fraction is None else float(self.fraction)
        return (self.kind, float(self.start), float(self.duration), bias, fraction)
