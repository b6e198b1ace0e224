"""Reproduce the paper's three simulation cases (SPEC §11) and print the SPEC §12
metrics as a table (what ``adaptimp reproduce`` does, without the figures).

    python examples/01_paper.py

Mirrored in Rust by ``examples/01_paper.rs``. ``ADAPTIMP_QUICK=1`` runs 2.5 s
instead of the paper's 20 s.
"""

from __future__ import annotations

import argparse
import os
import textwrap

import adaptimp
from adaptimp._params import CASE_NAMES


def main() -> None:
    T = 2.5 if os.environ.get("ADAPTIMP_QUICK") else 20.0
    print(f"paper scenario: T = {T:g} s, Ts = 50 µs, one RK4 substep")
    results = {CASE_NAMES[c]: adaptimp.simulate(c, T=T) for c in adaptimp.CASES}
    print(adaptimp.metrics_table(results))


if __name__ == "__main__":
    # --help: what the example does and how to run it (it takes no arguments).
    doc = (__doc__ or "").split("\n\n")
    argparse.ArgumentParser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(p for p in doc[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    ).parse_args()
    main()
