"""Deprecated: the scenario moved to :mod:`adaptimp.scenarios.contact` (the public API
never imports a scenario). This alias imports it with a DeprecationWarning
and goes away in the next release."""

from __future__ import annotations

import warnings
from typing import Any

from .scenarios import contact as _moved

warnings.warn(
    "adaptimp.contact is deprecated: import adaptimp.scenarios.contact instead "
    "(the same names; this alias goes away in the next release)",
    DeprecationWarning,
    stacklevel=2,
)

__all__ = list(_moved.__all__)


def __getattr__(name: str) -> Any:
    return getattr(_moved, name)
