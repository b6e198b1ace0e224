"""Deprecated: the scenario moved to :mod:`adaptimp.scenarios.contact` (the public API
never imports a scenario). This alias imports it with a DeprecationWarning
and goes away in 0.3 (:mod:`adaptimp._deprecated`)."""

from __future__ import annotations

from typing import Any

from ._deprecated import moved_module
from .scenarios import contact as _moved

moved_module("adaptimp.contact", "adaptimp.scenarios.contact")

__all__ = list(_moved.__all__)


def __getattr__(name: str) -> Any:
    return getattr(_moved, name)
