"""Your own RBF centres instead of the paper's vertex grid.

The vertex grid has 2^(4n) nodes (256 for the paper's arm) and exists for
n ≤ 3. Any n takes user centres: an (L, 4n) array of points in the networks'
input space Z = [x, v, α1, α̇1] with a width per input dimension. Here L = 32
centres are placed along the commanded circle (x = xc(t_i), v = α1 = ẋc(t_i),
α̇1 = ẍc(t_i)), as in deterministic learning (Wang & Hill, IEEE TNN 17(1),
2006), and state feedback in the robot scenario is compared with the grid.

    python examples/04_custom_basis.py

Mirrored in Rust by ``examples/04_custom_basis.rs``. ``ADAPTIMP_QUICK=1`` shortens it.
"""

from __future__ import annotations

import argparse
import os
import textwrap

import numpy as np

import adaptimp


def orbit_centres(nodes: int) -> np.ndarray:
    """``nodes`` centres along the robot scenario's commanded trajectory, shape (L, 8)."""
    d = adaptimp.defaults("robot")
    o, a, b, w = (np.array(d[k]) for k in ("xc_offset", "xc_sin", "xc_cos", "xc_omega"))
    t = np.arange(nodes)[:, None] * (2 * np.pi / nodes) / w[None, :]
    x = o + a * np.sin(w * t) + b * np.cos(w * t)
    v = w * (a * np.cos(w * t) - b * np.sin(w * t))
    acc = -w * w * (x - o)
    return np.hstack([x, v, v, acc])


def main() -> None:
    T = 4.0 if os.environ.get("ADAPTIMP_QUICK") else 20.0
    grid = adaptimp.simulate("sf", "robot", T=T)
    user = adaptimp.simulate("sf", "robot", T=T, centers=orbit_centres(32), widths=1.0)
    print(f"state feedback, robot scenario, T = {T:g} s")
    for name, r, nodes in (("vertex grid", grid, 256), ("32 centres on the orbit", user, 32)):
        m = r.metrics
        print(
            f"  {name:<24} L = {nodes:>3}: RMS ‖z1‖ (t ≥ 2 s) = {m['rms_z1_after2']:.5f} rad, "
            f"saturation duty {m['sat_duty']:.4f}"
        )


if __name__ == "__main__":
    # --help: what the example does and how to run it (it takes no arguments).
    doc = (__doc__ or "").split("\n\n")
    argparse.ArgumentParser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(p for p in doc[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    ).parse_args()
    main()
