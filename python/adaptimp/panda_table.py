"""Deprecated: the scenario moved to :mod:`adaptimp.scenarios.panda_table` (the public API
never imports a scenario). This alias imports it with a DeprecationWarning
and goes away in 0.3 (:mod:`adaptimp._deprecated`)."""

from __future__ import annotations

from typing import Any

from ._deprecated import moved_module
from .scenarios import panda_table as _moved

moved_module("adaptimp.panda_table", "adaptimp.scenarios.panda_table")

__all__ = list(_moved.__all__)


def __getattr__(name: str) -> Any:
    return getattr(_moved, name)
