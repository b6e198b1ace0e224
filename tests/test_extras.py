"""Optional dependencies: what needs one names the pip commands that install it
(as they install: quoted, from a checkout and from a wheel), and a sweep checks
for pandas before it runs anything."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

import adaptimp

ROOT = Path(__file__).resolve().parent.parent
HINT = (
    r'pip install "{pkg}"; or adaptimp with the extra: pip install "\.\[{extra}\]" from a '
    r'checkout, pip install "adaptimp-<version>-<tags>\.whl\[{extra}\]" from a wheel'
)


def test_sweep_without_pandas_fails_before_any_run(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setitem(sys.modules, "pandas", None)
    calls: list[tuple[int, int]] = []
    with pytest.raises(ImportError) as err:
        adaptimp.sweep(
            "pd",
            vary={"Kp": [8.0, 12.0]},
            T=0.2,
            Kzeta=80.0,
            cache=tmp_path / "runs",
            progress=lambda done, total: calls.append((done, total)),
        )
    assert str(err.value).startswith(
        "adaptimp.sweep() needs pandas>=1.5, an optional dependency (adaptimp's extra 'sweep')"
    )
    assert err.match(HINT.format(pkg="pandas>=1.5", extra="sweep"))
    assert calls == []
    assert not (tmp_path / "runs").exists()


def test_to_pandas_and_to_xarray_name_their_extras(monkeypatch: pytest.MonkeyPatch) -> None:
    res = adaptimp.simulate("pd", T=0.01)
    monkeypatch.setitem(sys.modules, "pandas", None)
    monkeypatch.setitem(sys.modules, "xarray", None)
    with pytest.raises(ImportError, match=HINT.format(pkg="pandas>=1.5", extra="pandas")):
        res.to_pandas()
    with pytest.raises(ImportError, match=HINT.format(pkg="xarray>=2022.6", extra="xarray")):
        res.to_xarray()


def test_every_extra_a_message_names_is_declared() -> None:
    text = (ROOT / "pyproject.toml").read_text(encoding="utf-8")
    section = text.split("[project.optional-dependencies]", 1)[1].split("\n[", 1)[0]
    declared = set(re.findall(r"^(\w+) = \[", section, re.M))
    named = set()
    for path in (ROOT / "python" / "adaptimp").glob("*.py"):
        source = path.read_text(encoding="utf-8")
        named |= set(re.findall(r'needs_extra\((?:"[^"]*",\s*){2}"(\w+)"\)', source))
    assert named == {"mujoco", "pinocchio", "pandas", "xarray", "sweep", "franka", "robosuite"}
    assert named <= declared


def test_the_robosuite_controller_names_its_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    import importlib

    # robosuite and every submodule already imported (tests/test_robosuite.py
    # in the same process): each None, so that each import of it fails.
    for name in [n for n in sys.modules if n == "robosuite" or n.startswith("robosuite.")]:
        monkeypatch.setitem(sys.modules, name, None)
    monkeypatch.setitem(sys.modules, "robosuite", None)
    monkeypatch.delitem(sys.modules, "adaptimp.robosuite", raising=False)
    with pytest.raises(ImportError) as err:
        importlib.import_module("adaptimp.robosuite")
    assert str(err.value).startswith(
        "adaptimp.robosuite needs robosuite>=1.5, an optional dependency (adaptimp's extra "
        "'robosuite')"
    )
    assert err.match(HINT.format(pkg="robosuite>=1.5", extra="robosuite"))
