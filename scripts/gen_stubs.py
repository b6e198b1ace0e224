"""Regenerate the parameter TypedDicts of ``python/adaptimp/_adaptimp.pyi``
from the compiled core's parameter schema (``src/schema.rs``).

    python scripts/gen_stubs.py          # rewrite the stub
    python scripts/gen_stubs.py --check  # exit 1 if the stub is stale

``tests/test_schema.py`` runs the check, so a parameter added to the schema
without regenerating the stub fails the tests.
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

from adaptimp import _adaptimp

STUB = Path(__file__).resolve().parent.parent / "python" / "adaptimp" / "_adaptimp.pyi"
BEGIN = "# BEGIN GENERATED from src/schema.rs by scripts/gen_stubs.py: do not edit\n"
END = "# END GENERATED\n"

TYPES = {
    "real": "float",
    "int": "int",
    "joint": "float | _Joint",
    "network": "float | Sequence[float]",
    "optional": "float | None",
    "derived": "float | None",
    "bound": 'float | Sequence[float] | Literal["auto"] | None',
    "limit": "float | _Joint | None",
    "axes": "float | Sequence[float]",
    "derived_axes": "float | Sequence[float] | None",
    "flag": "bool",
    "matrix": "Sequence[float] | Sequence[Sequence[float]] | None",
}

CLASSES = (
    ("ControllerParams", ("controller",), "Controller parameters (SPEC §4–§11, §13)."),
    ("SimParams", ("sim", "env"), "Run and environment parameters (SPEC §3, §11)."),
    ("ArmParams", ("arm",), "Arm parameters (SPEC §1)."),
    ("CartesianParams", ("cartesian",), "Cartesian impedance parameters (SPEC §16)."),
)


def generated() -> str:
    """The generated block, markers included."""
    table = _adaptimp.schema_table()
    out = [BEGIN]
    for cls, groups, doc in CLASSES:
        out.append("\n@type_check_only\n")
        out.append(f"class {cls}(TypedDict, total=False):\n")
        out.append(f'    """{doc}"""\n\n')
        for p in table:
            if p["group"] not in groups:
                continue
            if p["kind"] == "choice":
                typ = "Literal[" + ", ".join(f'"{c}"' for c in p["choices"]) + "]"
            else:
                typ = TYPES[p["kind"]]
            unit = f" ({p['unit']})" if p["unit"] else ""
            doc = textwrap.wrap(f"{p['doc']}{unit}.", width=88)
            out.append(f"    {p['name']}: {typ}\n")
            out.append('    """' + "\n    ".join(doc) + '"""\n')
    out.append("\n" + END)
    return "".join(out)


def updated(text: str) -> str:
    """``text`` (the stub) with its generated block replaced."""
    start, end = text.index(BEGIN), text.index(END) + len(END)
    return text[:start] + generated() + text[end:]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--check", action="store_true", help="only check, do not write")
    args = parser.parse_args()
    text = STUB.read_text(encoding="utf-8")
    new = updated(text)
    if args.check:
        if new != text:
            print(f"{STUB} is stale: run python scripts/gen_stubs.py", file=sys.stderr)
            return 1
        return 0
    STUB.write_text(new, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
