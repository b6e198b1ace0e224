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
from numpy.typing import ArrayLike, NDArray

from . import _adaptimp
from ._errors import ConfigError

N_JOINTS: int = 2
"""Joints of the paper's arm (the default ``n``)."""

MAX_JOINTS: int = _adaptimp.MAX_JOINTS
"""The most joints a controller may have (7)."""

N_NODES: int = _adaptimp.N_NODES
"""RBF nodes of the paper's vertex grid for n = 2, 2^(4n) = 256 (SPEC §6)."""

CASES = ("pd", "sf", "of")
"""The paper's three controllers: PD (Case 1), state feedback (14), output feedback (35)."""

CASE_NAMES = {"pd": "PD", "sf": "state feedback", "of": "output feedback"}
"""Readable names of the cases, for tables and figure titles."""

GROUPS = ("sim", "controller", "env", "arm")
"""Parameter groups of :func:`adaptimp.simulate`: the run, the controller, the
environment (wall), the arm."""

ALL_GROUPS = (*GROUPS, "cartesian")
"""Every parameter group: those of :data:`GROUPS` and the 6-D Cartesian impedance
of :class:`adaptimp.CartesianController` (SPEC §16)."""


@dataclass(frozen=True)
class Param:
    """One keyword parameter, as the core's schema (``src/schema.rs``) declares it.

    ``kind`` is one of ``"real"`` (a finite number), ``"int"``, ``"joint"`` (a
    number broadcast to every joint, or one value per joint), ``"network"``
    (a number, or one value per network D̂, Ĉ, Ĝ), ``"choice"`` (one of
    ``choices``), ``"optional"`` (a number or ``None``), ``"derived"`` (a
    number, or ``None`` for the value derived from other parameters),
    ``"bound"`` (``None``, ``"auto"`` or one number per network), ``"limit"``
    (``None`` for no limit, or a number > 0 per joint), ``"axes"`` (a number
    broadcast to the task axes x, y, z, or one value per axis),
    ``"derived_axes"`` (the same, or ``None`` for the value derived from other
    parameters), ``"flag"`` (``True`` or ``False``), ``"matrix"`` (``None``,
    or an (n, n) array, also given as n² values row-major).
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
"""Default values of every parameter, per scenario (from the core's schema), for
the paper's n = 2 joints; :func:`defaults` gives them for any n."""

_DEFAULTS: dict[tuple[str, int], dict[str, Any]] = {
    (name, 2): values for name, values in SCENARIOS.items()
}


def defaults(scenario: str = "paper", n: int = 2) -> dict[str, Any]:
    """Every parameter's default in ``scenario`` for ``n`` joints (a copy): per-joint
    values have n entries (the paper's first joint's value for every joint, when
    the paper gives two)."""
    check_scenario(scenario)
    n = check_n(n)
    key = (scenario, n)
    if key not in _DEFAULTS:
        _DEFAULTS[key] = _adaptimp.defaults(scenario, n)
    return dict(_DEFAULTS[key])


def check_n(n: object) -> int:
    """``n`` if it is a whole number of joints in 1 … :data:`MAX_JOINTS`, else an error."""
    if isinstance(n, bool) or not isinstance(n, numbers.Integral):
        raise TypeError(f"n must be an integer number of joints, got {_type_name(n)}")
    if not 1 <= int(n) <= MAX_JOINTS:
        raise ConfigError(f"n must be between 1 and {MAX_JOINTS} joints, got {n}")
    return int(n)


def names(*groups: str) -> list[str]:
    """Parameter names of the given groups (those of :func:`adaptimp.simulate`,
    :data:`GROUPS`, if none), in documentation order."""
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
            raise ConfigError(
                f"{p.name} must be a single number{_unit(p)}, got shape {np.shape(value)}"
            )
        raise TypeError(f"{p.name} must be a real number{_unit(p)}, got {_type_name(value)}")
    try:
        x = float(value)
    except OverflowError:
        raise ConfigError(f"{p.name} is too large for a float: {value}") from None
    if not math.isfinite(x):
        raise ConfigError(f"{p.name} must be finite, got {x}")
    return x


def _vector(p: Param, value: object, size: int, per: str, inf_ok: bool = False) -> list[float]:
    if isinstance(value, (str, bytes, bool)):
        raise TypeError(
            f"{p.name} must be a number or a sequence of {size} numbers ({per}){_unit(p)}, "
            f"got {_type_name(value)}"
        )
    try:
        arr = np.asarray(value)
    except OverflowError:
        raise ConfigError(f"{p.name} holds a number too large for a float") from None
    except ValueError as e:  # ragged nested sequences
        raise ConfigError(
            f"{p.name} must be a number or have shape ({size},) ({per}), got {value!r}"
        ) from e
    if arr.dtype == object:
        try:
            arr = np.asarray(value, dtype=np.float64)
        except OverflowError:
            raise ConfigError(f"{p.name} holds a number too large for a float") from None
        except (TypeError, ValueError):
            pass
    if arr.dtype.kind not in "iuf":
        raise TypeError(
            f"{p.name} must be a number or a sequence of {size} numbers ({per}){_unit(p)}, "
            f"got {_type_name(value)}" + (f" of dtype {arr.dtype}" if arr.ndim else "")
        )
    if arr.shape not in ((), (size,)):
        raise ConfigError(
            f"{p.name} must be a number or have shape ({size},) ({per}), got shape {arr.shape}"
        )
    try:
        out = np.broadcast_to(arr.astype(np.float64), (size,))
    except OverflowError:
        raise ConfigError(f"{p.name} holds a number too large for a float") from None
    # A limit may be +inf (none on that joint), as in C.
    bad = np.flatnonzero(np.isnan(out) if inf_ok else ~np.isfinite(out))
    if bad.size:
        need = "a number (inf: no limit)" if inf_ok else "finite"
        raise ConfigError(f"{p.name}[{bad[0]}] must be {need}, got {out[bad[0]]}")
    return [float(x) for x in out]


def _integer(p: Param, value: object) -> int:
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise TypeError(f"{p.name} must be an integer, got {_type_name(value)}")
    if not -(2**63) <= int(value) < 2**63:
        raise ConfigError(f"{p.name} is out of range: {value}")
    return int(value)


def _choice(p: Param, value: object) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{p.name} must be a string, one of {p.choices}, got {_type_name(value)}")
    if value not in p.choices:
        raise ConfigError(f"{p.name} must be one of {p.choices}, got {value!r}")
    return value


def _matrix(p: Param, value: object, n: int) -> list[float]:
    """An n × n matrix, given (n, n) or as n² values row-major: n² finite
    floats, row-major (symmetry is the core's check). Booleans, strings and
    complex numbers are refused, as for the other kinds."""
    what = (
        f"{p.name} must be an ({n}, {n}) array of real numbers{_unit(p)}, got {_type_name(value)}"
    )
    if isinstance(value, (str, bytes, bool)):
        raise TypeError(what)
    try:
        a = np.asarray(value)
        if a.dtype == object:
            a = np.asarray(value, dtype=np.float64)
    except OverflowError:
        raise ConfigError(f"{p.name} holds a number too large for a float") from None
    except (TypeError, ValueError):
        raise TypeError(what) from None
    if a.dtype.kind not in "iuf":
        raise TypeError(what + (f" of dtype {a.dtype}" if a.ndim else ""))
    a = a.astype(np.float64)
    if a.shape not in ((n, n), (n * n,)):
        raise ConfigError(f"{p.name} must have shape ({n}, {n}), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ConfigError(f"{p.name} must be finite, got {a.tolist()}")
    return [float(x) for x in a.reshape(-1)]


def flag(name: str, value: object) -> bool:
    """``value`` of the option ``name`` if it is ``True`` or ``False``; else
    ``TypeError`` naming it (a string such as "false" is not taken for True)."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise TypeError(f"{name} must be True or False, got {_type_name(value)}")


def validate(name: str, value: object, n: int = N_JOINTS) -> Any:
    """``value`` of parameter ``name`` in its normal form (float, int, str, list of
    floats or None) for ``n`` joints; raises ``TypeError``/``ValueError`` naming
    the parameter."""
    p = BY_NAME[name]
    if p.kind == "real":
        return _real(p, value)
    if p.kind == "int":
        return _integer(p, value)
    if p.kind == "joint":
        return _vector(p, value, n, "one value per joint")
    if p.kind == "network":
        return _vector(p, value, 3, "one value per network D, C, G")
    if p.kind == "choice":
        return _choice(p, value)
    if p.kind in ("optional", "derived"):
        return None if value is None else _real(p, value)
    if p.kind == "limit":
        if value is None:
            return None
        v = _vector(p, value, n, "one value per joint", inf_ok=True)
        # Infinity is "no limit": on every joint, that is None.
        return None if all(x == math.inf for x in v) else v
    if p.kind == "axes":
        return _vector(p, value, 3, "one value per axis x, y, z")
    if p.kind == "derived_axes":
        return None if value is None else _vector(p, value, 3, "one value per axis x, y, z")
    if p.kind == "matrix":
        return None if value is None else _matrix(p, value, n)
    if p.kind == "flag":
        return flag(p.name, value)
    if p.kind == "bound":
        if value is None or (isinstance(value, str) and value == "auto"):
            return value
        if isinstance(value, str):
            raise ConfigError(f"{p.name} must be None, 'auto' or numbers, got {value!r}")
        return _vector(p, value, 3, "one value per network D, C, G")
    raise AssertionError(f"unknown parameter kind {p.kind!r}")  # pragma: no cover


# ---------------------------------------------------------------------------
# Whole parameter sets.
# ---------------------------------------------------------------------------


def check_settle(settle: float, T: float, Ts: float) -> None:
    """Refuse a ``settle`` (s) the caller gave that starts the metrics' window
    t ≥ settle after the run's last recorded step, t = (round(T/Ts) − 1) Ts:
    the window's metrics would be NaN. (The default settle keeps its
    documented NaN for a shorter run; settle ≥ 0 is the core's check.)"""
    if not (math.isfinite(T) and math.isfinite(Ts) and T > 0 and Ts > 0):
        return  # the core names these
    steps = round(T / Ts)
    if steps < 1 or not math.isfinite(settle):
        return
    last = (steps - 1) * Ts
    if settle > last + 1e-9:
        raise ConfigError(
            f"settle = {settle:g} s starts the metrics' window t ≥ settle after the run's "
            f"last step (t = {last:g} s; T = {T:g} s at Ts = {Ts:g} s), so its metrics would "
            f"be NaN: give settle ≤ {last:g} s, or a longer T"
        )


def check_case(case: object) -> str:
    """``case`` if it is one of :data:`CASES`, else ``ValueError``/``TypeError``."""
    if not isinstance(case, str):
        raise TypeError(f"case must be a string, one of {CASES}, got {_type_name(case)}")
    if case not in CASES:
        raise ConfigError(f"case must be one of {CASES}, got {case!r}")
    return case


def check_scenario(scenario: object) -> str:
    """``scenario`` if it is a key of :data:`SCENARIOS`, else ``ValueError``/``TypeError``."""
    if not isinstance(scenario, str):
        raise TypeError(
            f"scenario must be a string, one of {tuple(SCENARIOS)}, got {_type_name(scenario)}"
        )
    if scenario not in SCENARIOS:
        raise ConfigError(f"scenario must be one of {tuple(SCENARIOS)}, got {scenario!r}")
    return scenario


def _reject_unknown(
    given: Mapping[str, object], groups: tuple[str, ...], caller: str, n: int = N_JOINTS
) -> None:
    valid = names(*groups)
    for key in given:
        if key in valid:
            if n != N_JOINTS and BY_NAME[key].group == "arm":
                raise TypeError(
                    f"{caller} got {key!r}, a parameter of the paper's 2-link arm, with "
                    f"n = {n}: pass arm=adaptimp.PlanarArm(...) for an arm of {n} joints"
                )
            continue
        if key in BY_NAME:
            where = {
                "sim": "a simulation parameter (adaptimp.simulate)",
                "env": "an environment parameter (adaptimp.simulate)",
                "arm": "an arm parameter (adaptimp.TwoLinkArm, adaptimp.simulate)",
                "controller": "a controller parameter (adaptimp.Controller, adaptimp.simulate)",
                "cartesian": "a Cartesian impedance parameter (adaptimp.CartesianController)",
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


def loop_delay(params: dict[str, Any]) -> Any:
    """``simulate``'s ``delay`` (SPEC (18.11), (17.1)): the loop's delay in
    periods, the plant's and the delay a case name's controller is made for
    alike; ``plant_delay`` alone delays the plant only (a controller not
    told). Pops ``delay`` from ``params`` (in place), sets ``plant_delay`` to
    it unless that is given, and returns the controller's delay: ``delay``,
    or 0 without it (the library's own loop, whatever the scenario's
    default for a controller alone). Validated where it is used."""
    d = params.pop("delay", None)
    if d is None:
        return 0
    if isinstance(d, bool) or not isinstance(d, (int, np.integer)):
        raise TypeError(f"delay must be an integer number of periods, got {_type_name(d)}")
    if not 0 <= int(d) <= 64:
        raise ConfigError(f"condition 0 ≤ delay ≤ 64 is violated: delay = {int(d)}")
    params.setdefault("plant_delay", int(d))
    return int(d)


def resolve(
    given: Mapping[str, object],
    *,
    scenario: str = "paper",
    groups: tuple[str, ...] = GROUPS,
    caller: str = "simulate()",
    n: int = N_JOINTS,
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
    n = check_n(n)
    _reject_unknown(given, groups, caller, n)
    table = defaults(scenario, n)
    out: dict[str, Any] = {}
    for name in names(*groups):
        if n != N_JOINTS and BY_NAME[name].group == "arm":
            continue
        out[name] = validate(name, given.get(name, table[name]), n)
    return out


# ---------------------------------------------------------------------------
# What to change when a condition of SPEC §10 fails.
# ---------------------------------------------------------------------------


def _fmt(x: float) -> str:
    return f"{x:.6g}"


def config_hint(message: str, params: Mapping[str, Any]) -> str:
    """A sentence saying what to change for the violated condition in ``message``
    (the core's text), from the parameters ``params``; empty if none applies."""
    kp = params.get("Kp")
    if "2Kζ − I − KpᵀKp" in message and kp is not None:
        kz = params["Kzeta"]
        for i, (k, z) in enumerate(zip(kp, kz)):
            need = (1.0 + k * k) / 2.0
            if 2.0 * z - 1.0 - k * k <= 0.0:
                top = math.sqrt(max(2.0 * z - 1.0, 0.0))
                return (
                    f"raise Kzeta above {_fmt(need)} for Kp = {_fmt(k)} (joint {i}), "
                    f"or lower Kp below {_fmt(top)} for Kzeta = {_fmt(z)}"
                )
    if "2Kζ − ρ − Kp/d" in message and kp is not None:
        kz, d, rho = params["Kzeta"], params["inertia"], params["rho"]
        for i, (k, z, di) in enumerate(zip(kp, kz, d)):
            if 2.0 * z - rho - k / di <= 0.0:
                return (
                    f"raise Kzeta above {_fmt((rho + k / di) / 2.0)} for Kp = {_fmt(k)} and "
                    f"inertia = {_fmt(di)} (joint {i}), or lower Kp below "
                    f"{_fmt(max(2.0 * z - rho, 0.0) * di)}"
                )
    if "2Kp − I" in message:
        return (
            "raise Kp above 0.5 on every joint, or use conditions='scaled' (SPEC §10: "
            "Kp > 0 with inertia scales)"
        )
    if "Ts Γ σ < 1" in message:
        ts = params["Ts"]
        return (
            f"lower Ts, gamma or sigma: gamma·sigma must stay below 1/Ts = {_fmt(1.0 / ts)} "
            f"at Ts = {_fmt(ts)} s"
        )
    if "Ts/ε ≤ 1e6" in message:
        return f"raise eps above Ts/1e6 = {_fmt(params['Ts'] / 1e6)} s, or lower Ts"
    if "λ1 ≤ 1e6" in message:
        return "lower lam1 to at most 1e6"
    return ""


def with_hint(error: ConfigError, params: Mapping[str, Any]) -> ConfigError:
    """``error`` with the :func:`config_hint` for ``params`` appended."""
    hint = config_hint(str(error), params)
    return ConfigError(f"{error}; {hint}") if hint else error


# ---------------------------------------------------------------------------
# The compiled controller from resolved keywords (Controller, simulate, a save's rerun).
# ---------------------------------------------------------------------------


def _basis(
    n: int, centers: ArrayLike | None, widths: ArrayLike | None, params: Mapping[str, Any]
) -> tuple[NDArray[np.float64] | None, NDArray[np.float64] | None]:
    """User centres as a (L, 4n) float64 array and the widths η (4n,), or
    (None, None) for the vertex grid."""
    if centers is None:
        if widths is not None:
            raise TypeError("widths needs centers (the vertex grid's width is eta2)")
        # n ≤ 3: the paper's vertex grid; beyond, the core places the rule's
        # centres along the controller's own trajectory (SPEC §18).
        return None, None
    c = np.asarray(centers)
    if c.dtype.kind not in "iuf":
        raise TypeError(f"centers must be an array of real numbers, got dtype {c.dtype}")
    c = np.ascontiguousarray(c, dtype=np.float64)
    if c.ndim != 2 or c.shape[1] != 4 * n or c.shape[0] == 0:
        raise ConfigError(
            f"centers must have shape (L, {4 * n}) (L ≥ 1 rows of x, v, α1, α̇1 for "
            f"{n} joints), got shape {c.shape}"
        )
    if not np.all(np.isfinite(c)):
        raise ConfigError("centers must be finite")
    w = np.sqrt(params["eta2"]) if widths is None else widths
    wa = np.asarray(w, dtype=np.float64)
    if wa.shape not in ((), (4 * n,)):
        raise ConfigError(
            f"widths must be a number or have shape ({4 * n},) (one per input dimension), "
            f"got shape {wa.shape}"
        )
    wa = np.broadcast_to(wa, (4 * n,))
    # +inf leaves an input out of the distance (SPEC §15.1); at least one finite.
    if np.any(np.isnan(wa)) or np.any(wa <= 0) or not np.any(np.isfinite(wa)):
        raise ConfigError("widths must be > 0, finite or +inf (that input left out), not all inf")
    return c, np.ascontiguousarray(wa)


def _core_controller(
    case: str,
    p: dict[str, Any],
    n: int,
    centers: NDArray[np.float64] | None,
    widths2: NDArray[np.float64] | None,
    cls: type[_adaptimp.Controller] = _adaptimp.Controller,
    gravity: tuple[list[dict[str, Any]], list[dict[str, Any]], list[float]] | None = None,
) -> _adaptimp.Controller:
    try:
        # The compiled constructor, also for the Python subclass Controller.
        return _adaptimp.Controller.__new__(cls, case, p, n, centers, widths2, gravity)
    except ConfigError as e:
        raise with_hint(e, p) from None
