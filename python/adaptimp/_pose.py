"""Typed I/O: the pose target a Cartesian step takes and the named outputs it
gives (SPEC §16), in place of a flat array and string keys; and how a
controller written in Python is called (one step signature,
``step(m, **setpoint)`` with an :class:`adaptimp.Measurement`).

:class:`PoseTarget` is the core's ``PoseTarget`` (Rust) and ``AdaptimpPoseTarget``
(C) in Python: the commanded pose p_c, R_c and its rates. :class:`CartesianStep`
is what the last step computed, each quantity an attribute with its unit.
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._deprecated import old_step_shape
from ._errors import ConfigError
from ._inputs import reals

FloatArray = NDArray[np.float64]

#: The length of a flat pose target: p, ṗ, p̈ (3 each), R row-major (9), ω, ω̇ (3 each).
FLAT = 24


def _vec(name: str, v: ArrayLike | None, shape: tuple[int, ...]) -> FloatArray:
    """``v`` as a read-only float array of ``shape`` (zeros if None), named in every
    error (text, bools and complex numbers refused: "0.1" was taken as 0.1)."""
    if v is None:
        a = np.zeros(shape)
    else:
        try:
            a = reals(name, v, shape).copy()
        except ValueError as e:
            raise ConfigError(str(e)) from None
    a.setflags(write=False)
    return a


@dataclass(frozen=True)
class PoseTarget:
    """A commanded pose and its rates, in the world frame (SPEC §16).

    ``p`` position p_c (m), ``dp`` velocity ṗ_c (m/s), ``ddp`` acceleration
    p̈_c (m/s²), each (3,); ``R`` rotation R_c (3, 3), world ← tool
    (orthonormal: the core refuses one that is not, naming it); ``w``
    angular velocity ω_c (rad/s), ``dw`` angular acceleration ω̇_c (rad/s²),
    (3,) each. Rates default to 0 and ``R`` to the identity. Immutable: a
    target is a value, as the core's is.

    >>> import numpy as np
    >>> t = PoseTarget(p=[0.4, 0.0, 0.3], dp=[0.0, 0.1, 0.0])
    >>> t.flat.shape
    (24,)
    >>> PoseTarget.from_flat(t.flat) == t
    True
    """

    p: FloatArray
    dp: FloatArray = field(default_factory=lambda: _vec("dp", None, (3,)))
    ddp: FloatArray = field(default_factory=lambda: _vec("ddp", None, (3,)))
    R: FloatArray = field(default_factory=lambda: _vec("R", np.eye(3), (3, 3)))
    w: FloatArray = field(default_factory=lambda: _vec("w", None, (3,)))
    dw: FloatArray = field(default_factory=lambda: _vec("dw", None, (3,)))

    def __post_init__(self) -> None:
        for name, shape in (
            ("p", (3,)),
            ("dp", (3,)),
            ("ddp", (3,)),
            ("R", (3, 3)),
            ("w", (3,)),
            ("dw", (3,)),
        ):
            object.__setattr__(self, name, _vec(name, getattr(self, name), shape))

    @classmethod
    def at(cls, p: ArrayLike, R: ArrayLike | None = None) -> PoseTarget:
        """The pose (p (m), R) at rest (R default the identity)."""
        return cls(p=np.asarray(p), R=np.eye(3) if R is None else np.asarray(R))

    @classmethod
    def from_flat(cls, flat: ArrayLike) -> PoseTarget:
        """From the flat (24,) form: p, ṗ, p̈, R row-major, ω, ω̇."""
        a = _vec("target", flat, (FLAT,))
        return cls(
            p=a[0:3], dp=a[3:6], ddp=a[6:9], R=a[9:18].reshape(3, 3), w=a[18:21], dw=a[21:24]
        )

    @property
    def flat(self) -> FloatArray:
        """The flat (24,) form the core's array entry points take (``run(targets=…)``)."""
        return np.concatenate([self.p, self.dp, self.ddp, self.R.ravel(), self.w, self.dw])

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, PoseTarget):
            return NotImplemented
        return bool(np.array_equal(self.flat, other.flat))

    __hash__ = None  # type: ignore[assignment]

    # Copies and pickles are built by the constructor, so their arrays are
    # read-only too (deepcopy and pickle gave writable ones, the class
    # documented immutable); a copy of a value is the value.
    def __reduce__(self) -> tuple[Any, ...]:
        return (PoseTarget, (self.p, self.dp, self.ddp, self.R, self.w, self.dw))

    def __copy__(self) -> PoseTarget:
        return self

    def __deepcopy__(self, memo: dict[int, Any]) -> PoseTarget:
        return self


#: The quantities of a Cartesian step, in the core's order (its ``last`` names).
STEP_FIELDS = (
    "q_d",
    "dq_d",
    "ddq_d",
    "p_d",
    "dp_d",
    "ddp_d",
    "R_d",
    "w_d",
    "dw_d",
    "p_t",
    "R_t",
    "error",
    "p",
    "R",
    "tau_e",
    "tau",
    "tau_sat",
    "z1",
    "p_c",
    "dp_c",
    "ddp_c",
    "wrench",
)


@dataclass(frozen=True)
class CartesianStep:
    """What the last Cartesian step computed, by name (SPEC §16).

    The compliant reference: ``q_d``, ``dq_d``, ``ddq_d`` (n,) (rad, rad/s,
    rad/s²); ``p_d``, ``dp_d``, ``ddp_d`` (3,) (m, m/s, m/s²), ``R_d`` (3,
    3), ``w_d``, ``dw_d`` (3,) (rad/s, rad/s²). The filtered target ``p_t``
    (3,) (m), ``R_t`` (3, 3). ``error`` (6,): [e_p (m); e_o (rad)] after
    clipping. The measured tip ``p`` (3,) (m), ``R`` (3, 3). ``tau_e``,
    ``tau``, ``tau_sat`` (n,) (N m), ``z1`` (n,) (rad). The commanded
    ``p_c``, ``dp_c``, ``ddp_c`` (3,) (m, m/s, m/s²). ``wrench`` (6,) (N, N m),
    the F_e the step was given. NaN before a first step.
    """

    q_d: FloatArray
    dq_d: FloatArray
    ddq_d: FloatArray
    p_d: FloatArray
    dp_d: FloatArray
    ddp_d: FloatArray
    R_d: FloatArray
    w_d: FloatArray
    dw_d: FloatArray
    p_t: FloatArray
    R_t: FloatArray
    error: FloatArray
    p: FloatArray
    R: FloatArray
    tau_e: FloatArray
    tau: FloatArray
    tau_sat: FloatArray
    z1: FloatArray
    p_c: FloatArray
    dp_c: FloatArray
    ddp_c: FloatArray
    wrench: FloatArray

    @classmethod
    def of(cls, core: Any) -> CartesianStep:
        """The last step of ``core`` (an object with ``last(name)``, as the
        compiled Cartesian classes have)."""
        return cls(**{name: np.asarray(core.last(name), dtype=np.float64) for name in STEP_FIELDS})


def target_of(target: PoseTarget | ArrayLike) -> FloatArray:
    """A :class:`PoseTarget` or a flat (24,) array as the flat form."""
    if isinstance(target, PoseTarget):
        return target.flat
    return _vec("target", target, (FLAT,))


def task_space(ctrl: Any) -> bool:
    """A controller in task space (``task_space = True``; ``wants_wrench`` is
    its deprecated name): it reads the wrench, and its reference is p_c (3,)."""
    return bool(getattr(ctrl, "task_space", getattr(ctrl, "wants_wrench", False)))


def call_shape(ctrl: Any) -> str:
    """How a controller written in Python is called: ``"measurement"``, the
    protocol (``step(m, **setpoint)``), or a deprecated shape (a step that
    one positional argument does not bind but three do, with or without the
    setpoint's keywords, or whose parameters are named ``q`` then ``tau_e``
    or ``dq``), with a ``DeprecationWarning`` at the user's line:
    ``"joint"`` (``step(q, tau_e, dq, …)``) or, for a task-space controller,
    ``"wrench"`` (``step(q, dq, wrench, …)``)."""
    try:
        sig = inspect.signature(ctrl.step)
    except (TypeError, ValueError):  # no signature to read (a compiled step): the protocol
        return "measurement"
    sp = dict.fromkeys(("xc", "dxc", "ddxc"))

    def binds(*args: object) -> bool:
        """Whether ``args`` bind, with the setpoint's keywords or without."""
        for kw in (sp, {}):
            try:
                sig.bind(*args, **kw)
            except TypeError:
                continue
            return True
        return False

    # A step whose parameters are the old call's names (q, then tau_e or dq)
    # is the old shape, though defaults let one argument bind it (it was
    # given a Measurement as q, with no warning).
    positional = [
        p.name
        for p in sig.parameters.values()
        if p.kind in (inspect.Parameter.POSITIONAL_ONLY, inspect.Parameter.POSITIONAL_OR_KEYWORD)
    ]
    named_old = positional[:1] == ["q"] and positional[1:2] in (["tau_e"], ["dq"])
    old = (not binds(None) or named_old) and binds(None, None, None)
    if not old:
        return "measurement"
    old_step_shape(ctrl, "step(q, dq, wrench)" if task_space(ctrl) else "step(q, tau_e, dq)")
    return "wrench" if task_space(ctrl) else "joint"
