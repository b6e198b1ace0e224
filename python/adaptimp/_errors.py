"""The exceptions and warnings of adaptimp, catchable by kind.

The compiled core raises these classes directly (``adaptimp._adaptimp`` imports
them from here), so the same error is the same class whether it came from
Python's checks or from Rust's.
"""

from __future__ import annotations


class AdaptimpError(Exception):
    """Base class of every adaptimp error."""


class ConfigError(AdaptimpError, ValueError):
    """A parameter set that cannot make a controller or a run: a violated
    condition of SPEC §10 (the message says what to change), a wrong shape or
    an impossible value. A ``ValueError``."""


class XacroError(ConfigError):
    """A robot description with xacro markup (macros, ``${…}``, ``$(find …)``)
    given where a URDF is read: expand it first (the message says how; the
    extra ``xacro`` expands a ``.xacro`` path itself). A ``ConfigError``."""


class MeasurementError(AdaptimpError, ValueError):
    """A step's input that is not a measurement: non-finite, of the wrong shape,
    beyond a plausibility limit, or missing (``dq`` for "pd"/"sf"). Named as you
    named it (``q``, ``dq``, ``tau_e``, ``xc``). What the control law uses is
    unchanged; the refusal is recorded (the fault, the fallback as the torque
    applied: the fault semantics of docs/reliability.md). A ``ValueError``."""


class DivergedError(AdaptimpError, ValueError, ArithmeticError):
    """The controller's state, a signal or the plant left the finite range
    (|x| > 1e100): call ``reset()`` or restore a saved state. An
    ``ArithmeticError``, and a ``ValueError`` (what every run-time error of
    adaptimp is, so ``except ValueError`` keeps catching it)."""


class FaultError(AdaptimpError, RuntimeError):
    """A step refused because a fault is latched (``fault_policy="latch"``):
    call ``clear_fault()`` once the cause is gone. A ``RuntimeError``."""


class SaveError(AdaptimpError, ValueError):
    """A file that cannot be read back as what was saved: not a save of
    adaptimp's, truncated or damaged, of a format this version does not read,
    or edited after it was saved (a recorded SHA-256 differs). The message
    names the file and what is wrong. A ``ValueError``."""


class StabilityWarning(UserWarning):
    """The chosen parameters are valid but known to be unstable in discrete
    time, e.g. explicit-Euler learning whose per-step gain exceeds Kp (the Jury
    condition of docs/robot.md)."""


class PlantWarning(UserWarning):
    """What :class:`adaptimp.mujoco.Plant` made of a model as shipped (joints
    locked, servos driven as torque motors, τmax estimated) and what a run of
    :func:`adaptimp.mujoco.simulate` found (the arm touching itself, the
    torque beyond 2 τmax or at its limit): the run is valid, read the message."""


__all__ = [
    "AdaptimpError",
    "ConfigError",
    "DivergedError",
    "FaultError",
    "MeasurementError",
    "PlantWarning",
    "SaveError",
    "StabilityWarning",
    "XacroError",
]


def needs_extra(what: str, package: str, extra: str) -> ImportError:
    """The ImportError of an optional dependency: what needs it, and the pip
    commands that install it, as they install (quoted, for zsh too)."""
    return ImportError(
        f"{what} needs {package}, an optional dependency (adaptimp's extra {extra!r}): "
        f'pip install "{package}"; or adaptimp with the extra: pip install ".[{extra}]" '
        f'from a checkout, pip install "adaptimp-<version>-<tags>.whl[{extra}]" from a wheel'
    )


def no_file(what: str, path: object) -> FileNotFoundError:
    """The error of a path that is no file, the same wherever a file is read:
    ``FileNotFoundError`` whose text says what was expected there and names
    the path."""
    return FileNotFoundError(f"{what}; no file {str(path)!r}")
