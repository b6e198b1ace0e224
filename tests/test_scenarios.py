"""The scenarios are users of the public API, kept apart from it (adaptimp.scenarios)."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest


def test_the_api_imports_no_scenario() -> None:
    """Importing the public API (the package and every module a user imports)
    loads nothing of adaptimp.scenarios."""
    code = (
        "import sys, adaptimp, adaptimp.cartesian, adaptimp.chain, adaptimp.mujoco, "
        "adaptimp.tuning, adaptimp.baselines; "
        "print(sorted(m for m in sys.modules if m.startswith('adaptimp.scenarios')))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == "[]"


@pytest.mark.parametrize("name", ["contact", "panda_table"])
def test_the_old_scenario_modules_warn_and_forward(name: str) -> None:
    """adaptimp.contact and adaptimp.panda_table stay importable for one release,
    with a DeprecationWarning, and give the scenario's own objects."""
    sys.modules.pop(f"adaptimp.{name}", None)
    new = importlib.import_module(f"adaptimp.scenarios.{name}")
    with pytest.warns(DeprecationWarning, match="is deprecated") as caught:
        __import__(f"adaptimp.{name}")  # as an import statement does: the warning names it
    old = sys.modules[f"adaptimp.{name}"]
    assert str(caught[0].message) == (
        f"adaptimp.{name} is deprecated: import adaptimp.scenarios.{name} instead "
        "(the same names; this alias goes away in 0.3)"
    )
    assert caught[0].filename == __file__
    assert old.__all__ == new.__all__
    for attr in new.__all__:
        assert getattr(old, attr) is getattr(new, attr)
