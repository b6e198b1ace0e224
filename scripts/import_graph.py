"""The project's import graph, and its circles.

Reads the imports of the Python package (``python/adaptimp``: module-level and
function-level ``import``/``from … import``, relative or absolute) and of the
Rust crates (``src/``, ``bindings/python/src/``, ``ffi/src/``: ``use crate::…``, ``use super::…``,
``use self::…``, paths written inline such as ``super::dynamic::MAX_JOINTS``),
as text, with the standard library alone, and prints every circle: a set of
files each of which reaches the others through imports.

    python scripts/import_graph.py            # the circles; exit status 1 if any
    python scripts/import_graph.py --edges    # every edge, then the circles

A Rust ``mod child;`` declares a child, it is not an import; a child's
``super::name`` is an edge to the parent's file unless ``name`` is a sibling
module (then the edge is to the sibling).
"""

from __future__ import annotations

import argparse
import ast
import re
import sys
from collections.abc import Iterable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


# --------------------------------------------------------------------------- Python


def python_edges(pkg: Path) -> dict[str, set[str]]:
    """module → the package's modules it imports (dotted names under ``adaptimp``).

    Every import counts, at module or function level: ``import a.b``; ``from
    a import b`` (an edge to the module ``a.b`` if ``b`` is one, else to ``a``
    itself, whose ``__init__`` defines or re-exports ``b``: a child taking a
    name from its parent package is an edge to that package);
    ``importlib.import_module(name[, package])`` and ``__import__(name)``
    with a literal name, or an f-string of ``__package__``/``__name__`` and
    literals. A dynamic import whose name cannot be read is an error
    (:class:`Unread`), not an edge left out."""
    top = pkg.name
    files = {_py_name(pkg, f): f for f in pkg.rglob("*.py")}
    # A compiled module (the extension, ``_adaptimp``, known by its stub) is
    # a leaf: it imports nothing of the package.
    leaves = {_py_name(pkg, f) for f in pkg.rglob("*.pyi")} - set(files)
    edges: dict[str, set[str]] = {m: set() for m in [*files, *leaves]}
    known = set(edges)
    for mod, f in files.items():
        tree = ast.parse(f.read_text(encoding="utf-8"), str(f))
        is_pkg = f.name == "__init__.py"
        base = mod if is_pkg else mod.rpartition(".")[0]
        for node in ast.walk(tree):
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                stem = _absolute(base, node.module or "", node.level)
                for a in node.names:
                    child = f"{stem}.{a.name}"
                    targets.append(child if child in known else stem)
            elif isinstance(node, ast.Call) and _is_dynamic_import(node.func):
                name = _literal(node.args[0], mod, base) if node.args else None
                if name is None:
                    raise Unread(f"{f}:{node.lineno}: a dynamic import of a name not read")
                level = len(name) - len(name.lstrip("."))
                if level:  # import_module(".x", package)
                    pkg_arg = node.args[1] if len(node.args) > 1 else None
                    anchor = _literal(pkg_arg, mod, base) if pkg_arg is not None else None
                    if anchor is None:
                        raise Unread(f"{f}:{node.lineno}: a relative import_module without package")
                    name = _absolute(anchor, name[level:], level)
                targets = [name]
            for t in targets:
                if t.split(".")[0] != top:
                    continue
                hit = _longest_module(t, known)
                if hit is not None and hit != mod:
                    edges[mod].add(hit)
    return edges


class Unread(Exception):
    """A dynamic import whose module name the graph cannot read."""


def _absolute(base: str, name: str, level: int) -> str:
    """``name`` imported ``level`` packages up from the package ``base``."""
    if not level:
        return name
    parts = base.split(".")
    anchor = ".".join(parts[: len(parts) - level + 1])
    return f"{anchor}.{name}" if name else anchor


def _is_dynamic_import(func: ast.expr) -> bool:
    """``importlib.import_module``, ``import_module`` or ``__import__``."""
    if isinstance(func, ast.Attribute):
        return func.attr == "import_module"
    return isinstance(func, ast.Name) and func.id in ("import_module", "__import__")


def _literal(node: ast.expr, mod: str, base: str) -> str | None:
    """The text of a literal or of an f-string of ``__package__``/``__name__``."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.Name) and node.id in ("__package__", "__name__"):
        return base if node.id == "__package__" else mod
    if isinstance(node, ast.JoinedStr):
        out = []
        for v in node.values:
            part = _literal(v.value if isinstance(v, ast.FormattedValue) else v, mod, base)
            if part is None:
                return None
            out.append(part)
        return "".join(out)
    return None


def _py_name(pkg: Path, f: Path) -> str:
    rel = f.relative_to(pkg.parent).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def _longest_module(name: str, modules: Iterable[str]) -> str | None:
    known = set(modules)
    parts = name.split(".")
    for k in range(len(parts), 0, -1):
        cand = ".".join(parts[:k])
        if cand in known:
            return cand
    return None


# --------------------------------------------------------------------------- Rust

_USE = re.compile(r"\buse\s+((?:crate|super|self)(?:::[\w{}*, \n:]+)?)\s*;", re.S)
_INLINE = re.compile(r"\b((?:crate|super)(?:::\w+)+)")
_MOD = re.compile(r"^\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;", re.M)


def rust_edges(src: Path, crate: str) -> dict[str, set[str]]:
    """file (relative to the repository) → the crate's files it imports."""
    files = {_rs_module(src, f): f for f in src.rglob("*.rs")}
    children: dict[tuple[str, ...], set[str]] = {}
    for m, f in files.items():
        children[m] = set(_MOD.findall(f.read_text(encoding="utf-8")))
    edges: dict[str, set[str]] = {_label(crate, src, files[m]): set() for m in files}
    for m, f in files.items():
        text = _strip_comments(f.read_text(encoding="utf-8"))
        paths = [p for u in _USE.findall(text) for p in _flatten(u)]
        paths += _INLINE.findall(text)
        for p in paths:
            target = _resolve(m, p.split("::"), files, children)
            if target is not None and target != m:
                edges[_label(crate, src, f)].add(_label(crate, src, files[target]))
    return edges


def _rs_module(src: Path, f: Path) -> tuple[str, ...]:
    parts = list(f.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib"):
        parts.pop()
    return tuple(parts)


def _label(crate: str, src: Path, f: Path) -> str:
    return str(f.relative_to(ROOT)) if f.is_relative_to(ROOT) else f"{crate}:{f}"


_TESTS = re.compile(r"#\[cfg\((?:all\()?test\b[^\]]*\]\s*mod\s+\w+\s*\{")


def _strip_comments(text: str) -> str:
    """The code without comments and without its unit-test modules (a test
    may use what the module's users use; that is not the module's import)."""
    text = re.sub(r"//[^\n]*", "", text)
    while (m := _TESTS.search(text)) is not None:
        depth, i = 1, m.end()
        while i < len(text) and depth:
            depth += text[i] == "{"
            depth -= text[i] == "}"
            i += 1
        text = text[: m.start()] + text[i:]
    return text


def _flatten(use: str) -> list[str]:
    """``a::{b, c::{d, e}}`` → [a::b, a::c::d, a::c::e]."""
    use = re.sub(r"\s+", "", use)
    if "{" not in use:
        return [use]
    i = use.index("{")
    head, body = use[:i], use[i + 1 : -1]
    out, depth, cur = [], 0, ""
    for ch in body + ",":
        if ch == "," and depth == 0:
            if cur:
                out += _flatten(head + cur)
            cur = ""
            continue
        depth += ch == "{"
        depth -= ch == "}"
        cur += ch
    return out


def _resolve(
    here: tuple[str, ...],
    path: list[str],
    files: dict[tuple[str, ...], Path],
    children: dict[tuple[str, ...], set[str]],
) -> tuple[str, ...] | None:
    """The file of the deepest module that ``path`` (as written in ``here``) names."""
    head, rest = path[0], path[1:]
    if head == "crate":
        at: tuple[str, ...] = ()
    elif head == "self":
        at = here
    else:  # super, possibly repeated
        at = here
        while path and path[0] == "super":
            at = at[:-1]
            path = path[1:]
        rest = path
    for name in rest:
        if name in ("*", "self"):
            break
        if name in children.get(at, set()) and (*at, name) in files:
            at = (*at, name)
        else:
            break
    return at if at in files else None


# --------------------------------------------------------------------------- circles


def circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one node (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]
    sys.setrecursionlimit(10_000)

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return out


def graph() -> dict[str, set[str]]:
    """Every edge of the project: the Python package, the core, the Python
    bindings, the C ABI."""
    edges = python_edges(ROOT / "python" / "adaptimp")
    edges.update(rust_edges(ROOT / "src", "adaptimp"))
    edges.update(rust_edges(ROOT / "bindings" / "python" / "src", "adaptimp-python"))
    edges.update(rust_edges(ROOT / "ffi" / "src", "adaptimp-ffi"))
    return edges


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--edges", action="store_true", help="print every edge first")
    args = ap.parse_args()
    edges = graph()
    if args.edges:
        for a in sorted(edges):
            for b in sorted(edges[a]):
                print(f"{a} -> {b}")
    found = circles(edges)
    for c in found:
        print("circle: " + ", ".join(c))
    n = sum(len(v) for v in edges.values())
    print(f"{len(edges)} modules, {n} imports, {len(found)} circles")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
