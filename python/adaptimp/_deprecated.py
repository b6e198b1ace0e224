"""Every deprecated name and call of the package, in one place, with the
release in which it goes (this is 0.1.0).

Each warns with a ``DeprecationWarning`` that names its replacement, at the
user's line, and otherwise works as before. :data:`DEPRECATED` is the list
(tests check that every warning the package gives is in it); the functions
below are the warnings themselves, called where the old name is read.

Imports nothing of the package (the standard library only): every module
may import it.
"""

from __future__ import annotations

import sys
import warnings
from typing import Any, NamedTuple


class Deprecated(NamedTuple):
    """One deprecated name or call: what it is, what replaces it, the release
    that removes it, and where the warning is given."""

    old: str
    new: str
    removed_in: str
    where: str


DEPRECATED: tuple[Deprecated, ...] = (
    Deprecated("adaptimp.contact", "adaptimp.scenarios.contact", "0.3", "adaptimp/contact.py"),
    Deprecated(
        "adaptimp.panda_table", "adaptimp.scenarios.panda_table", "0.3", "adaptimp/panda_table.py"
    ),
    Deprecated(
        ".ts of Controller, ComputedTorque, CartesianController, CartesianImpedance",
        ".Ts",
        "0.3",
        "period_alias",
    ),
    Deprecated(
        ".ts of a controller written in Python (adaptimp.mujoco.simulate)",
        ".Ts",
        "0.3",
        "period_of",
    ),
    Deprecated(
        "step(q, tau_e, dq) of a controller written in Python",
        "step(m, **setpoint), m an adaptimp.Measurement",
        "0.3",
        "old_step_shape",
    ),
    Deprecated(
        "step(q, dq, wrench) of a task-space controller written in Python",
        "step(m, **setpoint), m an adaptimp.Measurement",
        "0.3",
        "old_step_shape",
    ),
    Deprecated(
        "CartesianController.step(q, dq, wrench)",
        "CartesianController.step(adaptimp.Measurement(q, dq, wrench=wrench))",
        "0.3",
        "old_cartesian_step",
    ),
    Deprecated(
        "Controller.step(q, tau_e, dq), ComputedTorque.step(q, tau_e, dq)",
        "step(adaptimp.Measurement(q, dq, tau_e=tau_e))",
        "0.3",
        "the bindings (their step's argument conversion warns, beside the core's call)",
    ),
)
"""The deprecated names and calls, each with the release that removes it."""


def outside() -> int:
    """The ``stacklevel`` of the first caller outside the adaptimp package,
    for a warning raised by the function that calls this one: the user's
    line that asked for the deprecated call."""
    frame = sys._getframe(1)
    level = 1
    while frame.f_back is not None and frame.f_globals.get("__name__", "").startswith("adaptimp"):
        frame = frame.f_back
        level += 1
    return level


def moved_module(old: str, new: str) -> None:
    """Warn that the alias module ``old`` was imported: ``new`` replaces it
    (removed in 0.3). Called from the alias module's body."""
    warnings.warn(
        f"{old} is deprecated: import {new} instead (the same names; this alias goes away in 0.3)",
        DeprecationWarning,
        stacklevel=3,
    )


def period_alias(owner: object) -> float:
    """The deprecated ``.ts`` of adaptimp's objects: warns, then returns ``.Ts`` (s).

    ``Ts`` is the one name of the sampling period (the schema's, ``simulate(Ts=…)``);
    ``.ts`` stays readable, for code written before, with a ``DeprecationWarning``
    (removed in 0.3).
    """
    warnings.warn(
        f"{type(owner).__name__}.ts is deprecated: the period is .Ts (s)",
        DeprecationWarning,
        stacklevel=3,
    )
    return float(owner.Ts)  # type: ignore[attr-defined]


def period_of(ctrl: Any) -> float | None:
    """The period (s) of a controller written in Python that names it ``.ts``,
    with a DeprecationWarning (removed in 0.3); None if it has no ``.ts``."""
    if getattr(ctrl, "ts", None) is None:
        return None
    warnings.warn(
        f"the controller's period .ts is deprecated: name it .Ts ({type(ctrl).__name__})",
        DeprecationWarning,
        stacklevel=4,
    )
    return float(ctrl.ts)


def old_step_shape(ctrl: Any, shape: str) -> None:
    """Warn of a controller written in Python whose step has the old ``shape``
    (``"step(q, tau_e, dq)"`` or ``"step(q, dq, wrench)"``; removed in 0.3)."""
    warnings.warn(
        f"{type(ctrl).__name__}.{shape} is deprecated: write step(m, **setpoint), m an "
        "adaptimp.Measurement (m.q, m.dq, m.tau_e, m.wrench)",
        DeprecationWarning,
        stacklevel=outside(),
    )


def old_cartesian_step() -> None:
    """Warn of ``CartesianController.step(q, dq, wrench)`` (removed in 0.3)."""
    warnings.warn(
        "CartesianController.step(q, dq, wrench) is deprecated: pass one "
        "adaptimp.Measurement(q, dq, wrench=wrench)",
        DeprecationWarning,
        stacklevel=outside(),
    )
