"""Keyword parameters: their names, units and meaning, the scenario defaults, validation.

Every SPEC quantity has one readable keyword name, used alike by
:func:`adaptimp.simulate`, :class:`adaptimp.Controller`, :class:`adaptimp.TwoLinkArm`
and the ``adaptimp`` command line. The compiled core's parameter schema
(``src/schema.rs``) declares each one once: :data:`PARAMS` (group, kind, unit,
meaning, validity condition) and :data:`SCENARIOS` (the defaults of each
scenario) are read from it. :func:`resolve` turns the keywords a user gave into
the complete, validated, JSON-serialisable dict the compiled core takes
(``weight_bound="auto"`` is resolved by the core, from the commanded trajectory).

Shape and type errors are found here (``TypeError`` for a wrong type, ``ValueError``
for a wrong shape or a non-finite number, each naming the parameter); the
stability conditions of SPEC §10 are checked by the Rust core, whose
``ValueError`` names the condition and the offending value.
"""

from __future__ import annotations

import difflib
import math
import numbers
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from . import _adaptimp

N_JOINTS: int = _adaptimp.N_JOINTS
"""Joints of the paper's arm (the compiled core is built for n = 2, l = 256 nodes)."""

N_NODES: int = _adaptimp.N_NODES
"""RBF nodes of the paper's vertex grid, 2^(4n) (SPEC §6)."""

CASES = ("pd", "sf", "of")
"""The paper's three controllers: PD (Case 1), state feedback (14), output feedback (35)."""

CASE_NAMES = {"pd": "PD", "sf": "state feedback", "of": "output feedback"}
"""Readable names of the cases, for tables and figure titles."""

GROUPS = ("sim", "controller", "env", "arm")
"""Parameter groups: the run, the controller, the environment (wall), the arm."""


@dataclass(frozen=True)
class Param:
    """One keyword parameter, as the core's schema (``src/schema.rs``) declares it.

    ``kind`` is one of ``"real"`` (a finite number), ``"int"``, ``"joint"`` (a
    number broadcast to every joint, or one value per joint), ``"network"``
    (a number, or one value per network D̂, Ĉ, Ĝ), ``"choice"`` (one of
    ``choices``), ``"optional"`` (a number or ``None``), ``"derived"`` (a
    number, or ``None`` for the value derived from other parameters),
    ``"bound"`` (``None``, ``"auto"`` or one number per network), ``"limit"``
    (``None`` for no limit, or a number > 0 per joint).
    ``condition`` is the validity condition the core checks (SPEC §10 style).
    """

    name: str
    group: str
    kind: str
    unit: str
    doc: str
    choices: tuple[str, ...] = ()
    condition: str = ""

    def describe(self) -> str:
        """One line: name, unit and meaning."""
        unit = f" ({self.unit})" if self.unit else ""
        choices = " | ".join(repr(c) for c in self.choices)
        extra = f": {choices}" if choices else ""
        return f"{self.name}{unit}{extra} — {self.doc}"


PARAMS: tuple[Param, ...] = tuple(
    Param(
        name=p["name"],
        group=p["group"],
        kind=p["kind"],
        unit=p["unit"],
        doc=p["doc"],
        choices=tuple(p["choices"]),
        condition=p["condition"],
    )
    for p in _adaptimp.schema_table()
)
"""Every keyword parameter, in the order of the documentation (from the core's schema)."""

BY_NAME: dict[str, Param] = {p.name: p for p in PARAMS}

SCENARIOS: dict[str, dict[str, Any]] = {
    name: _adaptimp.defaults(name) for name in ("paper", "robot")
}
"""Default values of every parameter, per scenario (from the core's schema)."""


def names(*groups: str) -> list[str]:
    """Parameter names of the given groups (all groups if none), in documentation order."""
    wanted = groups or GROUPS
    return [p.name for p in PARAMS if p.group in wanted]


def describe(*groups: str, scenario: str = "paper") -> str:
    """A reference list of the parameters of ``groups`` with units, validity
    conditions and the defaults of ``scenario``."""
    defaults = SCENARIOS[check_scenario(scenario)]
    lines = []
    for p in PARAMS:
        if p.group in (groups or GROUPS):
            cond = f"; valid: {p.condition}" if p.condition else ""
            lines.append(f"    {p.describe()}{cond}; {scenario}: {defaults[p.name]!r}")
    return "\n".join(lines)


# ---------------------------------------------------------------------------
# Validation of single values.
# ---------------------------------------------------------------------------


def _unit(p: Param) -> str:
    return f" ({p.unit})" if p.unit else ""


def _type_name(value: object) -> str:
    return type(value).__name__


def _real(p: Param, value: object) -> float:
    if isinstance(value, np.ndarray) and value.ndim == 0 and value.dtype.kind in "iuf":
        value = value.item()
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        if isinstance(value, (np.ndarray, list, tuple)):
            raise ValueError(
                f"{p.name} must be a single number{_unit(p)}, got shape {np.shape(value)}"
            )
        raise TypeError(f"{p.name} must be a real number{_unit(p)}, got {_type_name(value)}")
    x = float(value)
    if not math.isfinite(x):
        raise ValueError(f"{p.name} must be finite, got {x}")
    return x


def _vector(p: Param, value: object, size: int, per: str) -> list[float]:
    if isinstance(value, (str, bytes, bool)):
        raise TypeError(
            f"{p.name} must be a number or a sequence of {size} numbers ({per}){_unit(p)}, "
            f"got {_type_name(value)}"
        )
    try:
        arr = np.asarray(value)
    except ValueError as e:  # ragged nested sequences
        raise ValueError(
            f"{p.name} must be a number or have shape ({size},) ({per}), got {value!r}"
        ) from e
    if arr.dtype.kind not in "iuf":
        raise TypeError(
            f"{p.name} must be a number or a sequence of {size} numbers ({per}){_unit(p)}, "
            f"got {_type_name(value)}" + (f" of dtype {arr.dtype}" if arr.ndim else "")
        )
    if arr.shape not in ((), (size,)):
        raise ValueError(
            f"{p.name} must be a number or have shape ({size},) ({per}), got shape {arr.shape}"
        )
    out = np.broadcast_to(arr.astype(np.float64), (size,))
    bad = np.flatnonzero(~np.isfinite(out))
    if bad.size:
        raise ValueError(f"{p.name}[{bad[0]}] must be finite, got {out[bad[0]]}")
    return [float(x) for x in out]


def _integer(p: Param, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{p.name} must be an integer, got {_type_name(value)}")
    return int(value)


def _choice(p: Param, value: object) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{p.name} must be a string, one of {p.choices}, got {_type_name(value)}")
    if value not in p.choices:
        raise ValueError(f"{p.name} must be one of {p.choices}, got {value!r}")
    return value


def validate(name: str, value: object) -> Any:
    """``value`` of parameter ``name`` in its normal form (float, int, str, list of
    floats or None); raises ``TypeError``/``ValueError`` naming the parameter."""
    p = BY_NAME[name]
    if p.kind == "real":
        return _real(p, value)
    if p.kind == "int":
        return _integer(p, value)
    if p.kind == "joint":
        return _vector(p, value, N_JOINTS, "one value per joint")
    if p.kind == "network":
        return _vector(p, value, 3, "one value per network D, C, G")
    if p.kind == "choice":
        return _choice(p, value)
    if p.kind in ("optional", "derived"):
        return None if value is None else _real(p, value)
    if p.kind == "limit":
        return None if value is None else _vector(p, value, N_JOINTS, "one value per joint")
    if p.kind == "bound":
        if value is None or (isinstance(value, str) and value == "auto"):
            return value
        if isinstance(value, str):
            raise ValueError(f"{p.name} must be None, 'auto' or numbers, got {value!r}")
        return _vector(p, value, 3, "one value per network D, C, G")
    raise AssertionError(f"unknown parameter kind {p.kind!r}")  # pragma: no cover


# ---------------------------------------------------------------------------
# Whole parameter sets.
# ---------------------------------------------------------------------------


def check_case(case: object) -> str:
    """``case`` if it is one of :data:`CASES`, else ``ValueError``/``TypeError``."""
    if not isinstance(case, str):
        raise TypeError(f"case must be a string, one of {CASES}, got {_type_name(case)}")
    if case not in CASES:
        raise ValueError(f"case must be one of {CASES}, got {case!r}")
    return case


def check_scenario(scenario: object) -> str:
    """``scenario`` if it is a key of :data:`SCENARIOS`, else ``ValueError``/``TypeError``."""
    if not isinstance(scenario, str):
        raise TypeError(
            f"scenario must be a string, one of {tuple(SCENARIOS)}, got {_type_name(scenario)}"
        )
    if scenario not in SCENARIOS:
        raise ValueError(f"scenario must be one of {tuple(SCENARIOS)}, got {scenario!r}")
    return scenario


def _reject_unknown(given: Mapping[str, object], groups: tuple[str, ...], caller: str) -> None:
    valid = names(*groups)
    for key in given:
        if key in valid:
            continue
        if key in BY_NAME:
            where = {
                "sim": "a simulation parameter (adaptimp.simulate)",
                "env": "an environment parameter (adaptimp.simulate)",
                "arm": "an arm parameter (adaptimp.TwoLinkArm, adaptimp.simulate)",
                "controller": "a controller parameter (adaptimp.Controller, adaptimp.simulate)",
            }[BY_NAME[key].group]
            raise TypeError(
                f"{caller} got an unexpected keyword argument {key!r}: it is {where}. "
                f"Valid names: {', '.join(valid)}"
            )
        same = [v for v in valid if v.lower() == key.lower()]
        close = same or difflib.get_close_matches(key, valid, n=1, cutoff=0.5)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        raise TypeError(
            f"{caller} got an unknown keyword argument {key!r}{hint}. "
            f"Valid names: {', '.join(valid)}"
        )


def resolve(
    given: Mapping[str, object],
    *,
    scenario: str = "paper",
    groups: tuple[str, ...] = GROUPS,
    caller: str = "simulate()",
) -> dict[str, Any]:
    """The complete parameter dict of ``groups``: the scenario's defaults updated
    with ``given``, validated and normalised (per-joint values as lists of floats;
    derived arm values and ``weight_bound="auto"`` are left to the core, which
    reports what it derived). JSON-serialisable.

    Raises ``TypeError`` for a name outside ``groups`` (naming it and listing the
    valid names) or a value of the wrong type, ``ValueError`` for a wrong shape,
    a non-finite number or an unknown choice.
    """
    check_scenario(scenario)
    _reject_unknown(given, groups, caller)
    defaults = SCENARIOS[scenario]
    out: dict[str, Any] = {}
    for name in names(*groups):
        out[name] = validate(name, given.get(name, defaults[name]))
    return out
