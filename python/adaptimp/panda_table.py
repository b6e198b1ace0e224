"""Deprecated: the scenario moved to :mod:`adaptimp.scenarios.panda_table` (the public API
never imports a scenario). This alias imports it with a DeprecationWarning
and goes away in the next release."""

from __future__ import annotations

import warnings
from typing import Any

from .scenarios import panda_table as _moved

warnings.warn(
    "adaptimp.panda_table is deprecated: import adaptimp.scenarios.panda_table instead "
    "(the same names; this alias goes away in the next release)",
    DeprecationWarning,
    stacklevel=2,
)

__all__ = list(_moved.__all__)


def __getattr__(name: str) -> Any:
    return getattr(_moved, name)
