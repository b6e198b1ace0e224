"""The tree's imports flow one way (issue: one core, thin fronts): no circle in
the Python package, the core or the C ABI, read by scripts/import_graph.py."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

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
