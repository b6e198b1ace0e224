"""The deprecated names and calls are gathered in one module
(``adaptimp._deprecated``), each with the release that removes it, and each
still warns with a DeprecationWarning that names its replacement."""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

import adaptimp
from adaptimp import _deprecated

PKG = Path(adaptimp.__file__).parent


def _release(v: str) -> tuple[int, ...]:
    return tuple(int(x) for x in v.split(".")[:2])


def test_every_deprecation_warning_is_given_by_the_one_module() -> None:
    # The Python package's own warnings: DeprecationWarning is named in
    # _deprecated.py only (the bindings' step conversion is listed there too).
    named = sorted(
        str(f.relative_to(PKG))
        for f in PKG.rglob("*.py")
        if "DeprecationWarning," in f.read_text(encoding="utf-8")
    )
    assert named == ["_deprecated.py"]


def test_each_says_the_release_that_removes_it() -> None:
    assert len(_deprecated.DEPRECATED) == 8
    for d in _deprecated.DEPRECATED:
        assert _release(d.removed_in) > _release(adaptimp.__version__), d
        assert d.new
        assert d.old != d.new


@pytest.mark.parametrize("old", ["contact", "panda_table"])
def test_the_moved_modules_warn_naming_the_new(old: str) -> None:
    sys.modules.pop(f"adaptimp.{old}", None)
    with pytest.warns(
        DeprecationWarning,
        match=rf"^adaptimp\.{old} is deprecated: import adaptimp\.scenarios\.{old} instead",
    ):
        alias = importlib.import_module(f"adaptimp.{old}")
    new = importlib.import_module(f"adaptimp.scenarios.{old}")
    assert alias.__all__ == new.__all__
    assert all(getattr(alias, n) is getattr(new, n) for n in new.__all__)
