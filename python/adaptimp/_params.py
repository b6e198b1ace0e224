"""Keyword parameters: their names, units and meaning, the scenario defaults, validation.

Every SPEC quantity has one readable keyword name, used alike by
:func:`adaptimp.simulate`, :class:`adaptimp.Controller`, :class:`adaptimp.TwoLinkArm`
and the ``adaptimp`` command line. :data:`PARAMS` describes them (group, kind,
unit, meaning) and :data:`SCENARIOS` holds the defaults of each scenario, in one
place. :func:`resolve` turns the keywords a user gave into the complete,
validated, JSON-serialisable dict the compiled core takes.

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

N_JOINTS = 2
"""Joints of the paper's arm (the compiled core is built for n = 2, l = 256 nodes)."""

CASES = ("pd", "sf", "of")
"""The paper's three controllers: PD (Case 1), state feedback (14), output feedback (35)."""

CASE_NAMES = {"pd": "PD", "sf": "state feedback", "of": "output feedback"}
"""Readable names of the cases, for tables and figure titles."""

GROUPS = ("sim", "controller", "env", "arm")
"""Parameter groups: the run, the controller, the environment (wall), the arm."""


@dataclass(frozen=True)
class Param:
    """One keyword parameter.

    ``kind`` is one of ``"real"`` (a finite number), ``"int"``, ``"joint"`` (a
    number broadcast to every joint, or one value per joint), ``"network"``
    (a number, or one value per network D̂, Ĉ, Ĝ), ``"choice"`` (one of
    ``choices``), ``"optional"`` (a number or ``None``), ``"derived"`` (a
    number, or ``None`` for the value derived from other parameters).
    """

    name: str
    group: str
    kind: str
    unit: str
    doc: str
    choices: tuple[str, ...] = ()

    def describe(self) -> str:
        """One line: name, unit and meaning."""
        unit = f" ({self.unit})" if self.unit else ""
        choices = " | ".join(repr(c) for c in self.choices)
        extra = f": {choices}" if choices else ""
        return f"{self.name}{unit}{extra} — {self.doc}"


def _p(
    name: str, group: str, kind: str, unit: str, doc: str, choices: tuple[str, ...] = ()
) -> Param:
    return Param(name, group, kind, unit, doc, choices)


PARAMS: tuple[Param, ...] = (
    # The run, SPEC §11.
    _p("T", "sim", "real", "s", "duration; rows k = 0 … round(T/Ts) − 1 are recorded"),
    _p("substeps", "sim", "int", "", "RK4 substeps M of the plant per controller period"),
    _p("q0", "sim", "joint", "rad", "initial joint position q(0)"),
    _p("dq0", "sim", "joint", "rad/s", "initial joint velocity q̇(0)"),
    _p("settle", "sim", "real", "s", "start of the 'after2' window of the metrics (SPEC §12)"),
    # The controller, SPEC §4–§9, §11.
    _p("Ts", "controller", "real", "s", "sampling period of the controller"),
    _p("K1", "controller", "joint", "1/s", "K1 of α1 = ẋd + K1 z1, (7)"),
    _p("Kp", "controller", "joint", "N m s/rad", "feedback gain Kp, (14)"),
    _p("Kzeta", "controller", "joint", "1/s", "auxiliary-system gain Kζ, (11)"),
    _p("mu", "controller", "real", "N m", "radius μ of the auxiliary system's inner ball"),
    _p(
        "aux_law",
        "controller",
        "choice",
        "",
        "auxiliary law: inside ‖ζ‖ < μ ζ̇ = −Kζ ζ + Δτ, or the printed ζ̇ = 0 (SPEC §8);"
        " 'linear': ζ̇ = −Kζ ζ + Δτ everywhere, without the −β term (SPEC §13)",
        ("default", "printed", "linear"),
    ),
    _p(
        "robust",
        "controller",
        "choice",
        "",
        "robust term r(z2): kr sgn z2, kr tanh(z2/φ), Remark 1's gain, none (SPEC §7)",
        ("sign", "tanh", "remark1", "none"),
    ),
    _p("kr", "controller", "joint", "N m", "gain of the 'sign' and 'tanh' robust terms"),
    _p("phi", "controller", "real", "rad/s", "boundary layer φ of the 'tanh' robust term"),
    _p("kD", "controller", "real", "kg m²", "Remark 1 (30): kr_i = kD |α̇1_i| + kC |α1_i| + kG"),
    _p("kC", "controller", "real", "N m s/rad", "Remark 1 (30): gain on |α1_i|"),
    _p("kG", "controller", "real", "N m", "Remark 1 (30): constant part"),
    _p("gamma", "controller", "network", "", "learning gains Γ of D̂, Ĉ, Ĝ, (15)–(17)"),
    _p("sigma", "controller", "network", "", "leakages σ of D̂, Ĉ, Ĝ, (15)–(17)"),
    _p("eta2", "controller", "real", "", "RBF width η² (the paper's 'variance 25')"),
    _p("eps", "controller", "real", "s", "high-gain observer ε, (31)"),
    _p("lam1", "controller", "joint", "", "high-gain observer λ1, (31)"),
    _p(
        "observer_init",
        "controller",
        "choice",
        "",
        "observer start: π(0) = 0 (paper), or π1(0) = the first measurement",
        ("zero", "first"),
    ),
    _p(
        "observer_hold",
        "controller",
        "choice",
        "",
        "observer discretisation: zero-order hold (SPEC §11) or triangle hold",
        ("zoh", "triangle"),
    ),
    _p("tau_max", "controller", "joint", "N m", "actuator limits τmax (SPEC §2)"),
    _p("Dd", "controller", "joint", "kg m²", "target inertia Dd, (3)"),
    _p("Cd", "controller", "joint", "N m s/rad", "target damping Cd, (3)"),
    _p("Gd", "controller", "joint", "N m/rad", "target stiffness Gd, (3)"),
    _p(
        "xc_offset",
        "controller",
        "joint",
        "rad",
        "commanded trajectory xc_i = o_i + a_i sin(ω_i t) + b_i cos(ω_i t): offset o",
    ),
    _p("xc_sin", "controller", "joint", "rad", "commanded trajectory: sine amplitude a"),
    _p("xc_cos", "controller", "joint", "rad", "commanded trajectory: cosine amplitude b"),
    _p("xc_omega", "controller", "joint", "rad/s", "commanded trajectory: angular frequency ω"),
    # Hardened options (SPEC §13, beyond the paper; the "robot" scenario's defaults).
    _p(
        "learning_step",
        "controller",
        "choice",
        "",
        "learning step: explicit Euler of (15)–(17), or normalised so that one step's"
        " gain from z2 to the network output stays below κ·Kp",
        ("euler", "normalized"),
    ),
    _p("kappa", "controller", "real", "", "κ of the normalised step, 0 < κ ≤ 1"),
    _p(
        "saturation_learning",
        "controller",
        "choice",
        "",
        "learning while a joint saturates: as printed, or conditional integration"
        " (no step that pushes τ further beyond the limit)",
        ("ignore", "freeze"),
    ),
    _p(
        "weight_bound",
        "controller",
        "bound",
        "",
        "projection onto ‖Ŵ‖_F ≤ b for D̂, Ĉ, Ĝ: None (none), 'auto' (derived from"
        " tau_max and the commanded trajectory's peak speed and acceleration), or b",
    ),
    # The environment, SPEC §3.
    _p("wall", "env", "optional", "rad", "wall on joint 1 at this position; None: free space"),
    _p("ke", "env", "real", "N m/rad", "wall stiffness"),
    _p("be", "env", "real", "N m s/rad", "wall damping"),
    # The arm, SPEC §1 (the plant only: the controller is model-free).
    _p("m1", "arm", "real", "kg", "mass of link 1"),
    _p("m2", "arm", "real", "kg", "mass of link 2"),
    _p("l1", "arm", "real", "m", "length of link 1"),
    _p("l2", "arm", "real", "m", "length of link 2"),
    _p("lc1", "arm", "derived", "m", "joint 1 to the centre of mass of link 1 (None: l1/2)"),
    _p("lc2", "arm", "derived", "m", "joint 2 to the centre of mass of link 2 (None: l2/2)"),
    _p("I1", "arm", "derived", "kg m²", "inertia of link 1 about its centre (None: m1 l1²/4)"),
    _p("I2", "arm", "derived", "kg m²", "inertia of link 2 about its centre (None: m2 l2²/4)"),
    _p("g", "arm", "real", "m/s²", "gravitational acceleration (vertical plane)"),
)
"""Every keyword parameter, in the order of the documentation."""

BY_NAME: dict[str, Param] = {p.name: p for p in PARAMS}

_PAPER: dict[str, Any] = {
    # SPEC §11: T = 20 s, Ts = 50 µs, M = 1 (400 000 steps), q(0) = [0.25, −0.05].
    "T": 20.0,
    "substeps": 1,
    "q0": [0.25, -0.05],
    "dq0": [0.0, 0.0],
    "settle": 2.0,
    "Ts": 50e-6,
    # (67), SPEC §5, §8.
    "K1": 6.0,
    "Kp": 10.0,
    "Kzeta": 60.0,
    "mu": 0.01,
    "aux_law": "default",
    # SPEC §7: kr sgn(z2) with kr = 0.5 N m. The other robust terms' gains are
    # our choices. φ = 0.05 rad/s (as in the core's robot scenario) is of the
    # order of the adaptive loops' |z2| after settling (measured on joint 1:
    # median 0.015, RMS 0.09 rad/s), so tanh is smooth near the target and
    # gives kr further away. The Remark 1 gains make kr ≈ 0.55 N m on the
    # paper's circle (|α̇1| ≲ 2 rad/s², |α1| ≲ 0.6 rad/s), close to the sign term's.
    "robust": "sign",
    "kr": 0.5,
    "phi": 0.05,
    "kD": 0.01,
    "kC": 0.05,
    "kG": 0.5,
    # SPEC §6: Γ = 100, σ = 0.01, η² = 25 for all three networks.
    "gamma": 100.0,
    "sigma": 0.01,
    "eta2": 25.0,
    # SPEC §9: ε = 1e-4 s (not the paper's 1e-3), λ1 = 3, π(0) = 0, ZOH.
    "eps": 1e-4,
    "lam1": 3.0,
    "observer_init": "zero",
    "observer_hold": "zoh",
    # SPEC §2, (66).
    "tau_max": [17.0, 15.0],
    "Dd": 1.0,
    "Cd": 10.0,
    "Gd": 60.0,
    # (64): xc = [0.2 − 0.2 cos(πt), 0.2 + 0.2 sin(πt)].
    "xc_offset": [0.2, 0.2],
    "xc_sin": [0.0, 0.2],
    "xc_cos": [-0.2, 0.0],
    "xc_omega": math.pi,
    # SPEC §13 options, off in the paper scenario.
    "learning_step": "euler",
    "kappa": 0.5,
    "saturation_learning": "ignore",
    "weight_bound": None,
    # SPEC §3.
    "wall": 0.2,
    "ke": 1000.0,
    "be": 10.0,
    # SPEC §1 (Table I is missing; the same group's arm).
    "m1": 2.0,
    "m2": 0.85,
    "l1": 0.35,
    "l2": 0.31,
    "lc1": None,
    "lc2": None,
    "I1": None,
    "I2": None,
    "g": 9.81,
}

_ROBOT: dict[str, Any] = {
    # SPEC §13: the paper scenario at a robot's Ts = 1 ms with M = 10 substeps,
    # and the hardened options (Config::robot in the core; docs/robot.md).
    **_PAPER,
    "Ts": 1e-3,
    "substeps": 10,
    "learning_step": "normalized",
    "kappa": 0.5,
    "saturation_learning": "freeze",
    "weight_bound": "auto",
    "robust": "tanh",
    "phi": 0.05,
    "observer_hold": "triangle",
    "observer_init": "first",
}

SCENARIOS: dict[str, dict[str, Any]] = {"paper": _PAPER, "robot": _ROBOT}
"""Default values of every parameter, per scenario."""


def names(*groups: str) -> list[str]:
    """Parameter names of the given groups (all groups if none), in documentation order."""
    wanted = groups or GROUPS
    return [p.name for p in PARAMS if p.group in wanted]


def describe(*groups: str) -> str:
    """A reference list of the parameters of ``groups`` with units and paper defaults."""
    lines = []
    for p in PARAMS:
        if p.group in (groups or GROUPS):
            default = _PAPER[p.name]
            lines.append(f"    {p.describe()}; paper: {default!r}")
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
    with ``given``, validated and normalised (per-joint values as lists of floats,
    derived arm values computed). JSON-serialisable.

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
    if "arm" in groups:
        # Derived defaults follow the GIVEN masses and lengths (SPEC §1).
        for i in ("1", "2"):
            m, length = out["m" + i], out["l" + i]
            if out["lc" + i] is None:
                out["lc" + i] = length / 2.0
            if out["I" + i] is None:
                out["I" + i] = m * length * length / 4.0
    if "controller" in groups and out["weight_bound"] == "auto":
        out["weight_bound"] = auto_weight_bound(out)
    return out


N_NODES = 2 ** (4 * N_JOINTS)
"""RBF nodes of the paper's vertex grid, 2^(4n) (SPEC §6)."""


def peak_rates(p: Mapping[str, Any], samples: int = 4096) -> tuple[float, float]:
    """Peak ‖ẋc‖ (rad/s) and ‖ẍc‖ (rad/s²) of the commanded trajectory of ``p``,
    sampled over one period of its slowest non-zero frequency (exact for the
    paper's circle, whose speed and acceleration are constant)."""
    a, b, w = (np.asarray(p[k], dtype=float) for k in ("xc_sin", "xc_cos", "xc_omega"))
    moving = np.abs(w) > 0
    if not moving.any():
        return 0.0, 0.0
    t = np.linspace(0.0, 2 * math.pi / np.min(np.abs(w[moving])), samples)[:, None]
    c, s = np.cos(w * t), np.sin(w * t)
    speed = np.linalg.norm(w * (a * c - b * s), axis=1).max()
    accel = np.linalg.norm(w * w * (a * s + b * c), axis=1).max()
    return float(speed), float(accel)


def auto_weight_bound(p: Mapping[str, Any]) -> list[float]:
    """The weight bounds of ``weight_bound='auto'`` (``network::weight_bounds`` in
    the core): ‖τmax‖/(√l · r) with r = peak ‖ẍc‖ for D̂, peak ‖ẋc‖ for Ĉ, 1 for
    Ĝ (a trajectory that does not move uses r = 1 rad/s, 1 rad/s²). Since every
    S_i ≤ 1, no network can then produce more than the actuator's torque at the
    commanded regressor scale. For the paper: ≈ [0.718, 2.255, 1.417]."""
    speed, accel = peak_rates(p)
    scale = float(np.linalg.norm(p["tau_max"])) / math.sqrt(N_NODES)
    return [scale / (accel or 1.0), scale / (speed or 1.0), scale]
