"""The tree's imports flow one way (issue: one core, thin fronts): no circle in
the Python package, the core or the C ABI, read by scripts/import_graph.py."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _graph_module():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location(
        "import_graph", ROOT / "scripts" / "import_graph.py"
    )
    assert spec is not None
    assert spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["import_graph"] = mod
    spec.loader.exec_module(mod)
    return mod


def test_no_import_circle_anywhere() -> None:
    g = _graph_module()
    edges = g.graph()
    assert g.circles(edges) == []


def test_the_graph_sees_the_imports_it_must() -> None:
    # The reader finds real edges of each kind, so an empty list of circles
    # is not an empty graph: a relative Python import inside a function, a
    # Rust `use crate::…`, a child's `super::sibling::…`, the C ABI's crate.
    edges = _graph_module().graph()
    assert "adaptimp._description" in edges["adaptimp._mjcf"]
    assert "src/control/state.rs" in edges["src/control/controller.rs"]
    assert "bindings/python/src/dynamic.rs" in edges["bindings/python/src/cartesian_loop.rs"]
    assert (
        "ffi/src/handles.rs" in edges["ffi/src/joint.rs"]
        or "ffi/src/lib.rs" in edges["ffi/src/joint.rs"]
    )


def test_a_circle_is_found_when_there_is_one() -> None:
    g = _graph_module()
    assert g.circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def _package(root: Path, files: dict[str, str]) -> Path:
    pkg = root / "pkg"
    pkg.mkdir()
    for name, text in files.items():
        (pkg / name).write_text(text, encoding="utf-8")
    return pkg


def test_a_circle_through_the_parent_package_is_found(tmp_path: Path) -> None:
    # A child that takes a name from the package that imports it, inside a
    # function: the package's __init__ and the child form a circle.
    pkg = _package(
        tmp_path,
        {
            "__init__.py": "from ._a import A\n__version__ = '1'\n",
            "_a.py": "class A:\n    def v(self):\n        from . import __version__\n",
            "_b.py": "from . import _a\n",  # a child module: an edge to it, not to the package
        },
    )
    g = _graph_module()
    edges = g.python_edges(pkg)
    assert edges["pkg._a"] == {"pkg"}
    assert edges["pkg._b"] == {"pkg._a"}
    assert g.circles(edges) == [["pkg", "pkg._a"]]


def test_a_circle_through_import_module_is_found(tmp_path: Path) -> None:
    pkg = _package(
        tmp_path,
        {
            "__init__.py": "",
            "_r.py": "import importlib\n\ndef load():\n"
            "    return importlib.import_module(f'{__package__}.m')\n",
            "m.py": "from ._r import load\n",
            "_s.py": "from importlib import import_module\nimport_module('.m', 'pkg')\n",
        },
    )
    g = _graph_module()
    edges = g.python_edges(pkg)
    assert edges["pkg._r"] == {"pkg.m"}
    assert edges["pkg._s"] == {"pkg.m"}
    assert g.circles(edges) == [["pkg._r", "pkg.m"]]


def test_a_dynamic_import_not_read_is_an_error(tmp_path: Path) -> None:
    pkg = _package(
        tmp_path,
        {"__init__.py": "", "_d.py": "import importlib\nimportlib.import_module(NAME)\n"},
    )
    g = _graph_module()
    with pytest.raises(g.Unread, match=r"_d\.py:2: a dynamic import of a name not read"):
        g.python_edges(pkg)


def test_the_package_takes_no_name_from_its_parent() -> None:
    # The package's modules import each other and the extension, never the
    # package itself (whose __init__ imports them): no edge into "adaptimp".
    edges = _graph_module().graph()
    into = sorted(m for m, to in edges.items() if "adaptimp" in to)
    assert into == []
    assert "adaptimp.mujoco" not in edges["adaptimp._result"]
