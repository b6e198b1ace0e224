"""Cartesian in five lines on any arm (SPEC §16 (16.8)–(16.12), docs/cartesian.md):
the default task, PD against state feedback, one table.

For each arm (a URDF or MJCF file; default: the Panda of example-robot-data):
``task = adaptimp.mujoco.cartesian_task(PATH)`` draws a start posture by the
core's posture rule and the default path (hold 1 s, then a 3 cm circle at 0.5
Hz in the horizontal plane, the orientation held); ``simulate("pd"|"sf", PATH,
T, task=task)`` builds each Cartesian controller by the core's rule and runs
it. Printed per arm, over t ≥ 2 s: σmin of the 6 × n Jacobian at the start,
the position RMS (mm) and orientation RMS (mrad) of PD and SF and their
ratios, SF's position RMS over the last 2 s against [2, 4) s (whether
learning goes on), the peak commanded |τ_i|/τmax_i of both, and whether the
issue's targets hold (σmin ≥ 0.05; SF ≤ 0.2× PD in position and orientation;
last 2 s ≤ 0.5× [2, 4) s; peak ≤ 1).

``--why``: on the first arm, from the task's start, the recipe docs/cartesian.md
gave before (the rule's gains without the path, so the schema's Γ = 100, σ =
0.01 and "auto" bound, and 64 centres of tube (0.05 rad, 0.2 rad/s)) against
the rule, one change at a time (SPEC §16, "Why the networks barely learned").

    python examples/17_cartesian_task.py                       # the Panda, T = 12 s
    python examples/17_cartesian_task.py ARM.urdf ARM.xml --json out.json
    python examples/17_cartesian_task.py --why

Needs the extras ``mujoco`` and ``pinocchio``. ``ADAPTIMP_QUICK=1``: T = 3 s.
On a terminal each run longer than 2 s shows a progress bar (the extra
``progress``: tqdm); a wrong argument or path is one line on stderr.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import textwrap
import time
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

import adaptimp
from adaptimp import _models, tuning
from adaptimp import mujoco as amj
from adaptimp.cartesian import CartesianImpedance

QUICK = os.environ.get("ADAPTIMP_QUICK") == "1"
PROGRESS = sys.stderr.isatty()
"""A progress bar for runs longer than 2 s, on a terminal only."""


class Parser(argparse.ArgumentParser):
    """A usage error is one line (``prog: error: …``), exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


def measure(path: str, T: float) -> dict[str, Any]:
    """PD and SF on the arm's default Cartesian task: the row of the table."""
    t0 = time.perf_counter()
    task = amj.cartesian_task(path)
    runs = {
        case: amj.simulate(case, path, T=T, task=task, progress=PROGRESS) for case in ("pd", "sf")
    }
    pd, sf = (runs[c].metrics for c in ("pd", "sf"))
    peak = max(
        float(np.max(np.abs(r.tau) / np.asarray(r.params["tau_max"]))) for r in runs.values()
    )
    row = {
        "n": task.chain.n,
        "orients": task.orients,
        "sigma_min": task.assessment["sigma_min"],
        "pd_pos_mm": pd["rms_pos_after2"] * 1e3,
        "sf_pos_mm": sf["rms_pos_after2"] * 1e3,
        "pd_rot_mrad": pd["rms_rot_after2"] * 1e3,
        "sf_rot_mrad": sf["rms_rot_after2"] * 1e3,
        "pos_ratio": sf["rms_pos_after2"] / pd["rms_pos_after2"],
        "rot_ratio": sf["rms_rot_after2"] / pd["rms_rot_after2"],
        "learning": sf["rms_pos_last2"] / sf["rms_pos_first2"],
        "peak_tau_ratio": peak,
        "q0": task.q0.tolist(),
        "time_s": time.perf_counter() - t0,
    }
    row["met"] = bool(
        row["sigma_min"] >= 0.05
        and row["pos_ratio"] <= 0.2
        and (row["rot_ratio"] <= 0.2 or not task.orients)
        and row["learning"] <= 0.5
        and peak <= 1.0
    )
    return row


def why(path: str, T: float) -> None:
    """The recipe of docs/cartesian.md before against the rule, one change at a time."""
    task = amj.cartesian_task(path)
    plant = amj.Plant(path)
    outer = CartesianImpedance(task.chain, Ts=1e-3, q0=task.q0)
    old_centres, old_widths = outer.orbit_centres(task.path, task.span)
    bare = {k: v for k, v in tuning.suggest(plant, task.q0, plant.tau_max).items() if k != "n"}
    old_basis = {"centers": old_centres, "widths": old_widths}
    old_learning = {"gamma": [100.0] * 3, "sigma": [0.01] * 3, "weight_bound": "auto"}
    inner = task.controller("sf", plant).params["inner"]
    variants: dict[str, dict[str, Any]] = {
        "the recipe": {**bare, **old_basis},
        "the recipe, the rule's centres": {**bare, **old_learning},
        "the recipe, the rule's Γ, σ and bounds": old_basis,
        "the rule, σ = 0.01": {"sigma": [0.01] * 3},
        "the rule, Γ = 100": {"gamma": [100.0] * 3},
        "the rule, D̂ and Ĉ off": {"gamma": [1e-12, 1e-12, inner["gamma"][2]]},
        "the rule, D̂ and Ĉ as fast as Ĝ": {"gamma": [25 * g for g in inner["gamma"][:2]]
                                            + [inner["gamma"][2]]},
        "the rule": {},
    }  # fmt: skip
    pd = amj.simulate("pd", path, T=T, task=task).metrics
    print(f"\n{path}: why the networks learned little (SF against PD, t ≥ 2 s, T = {T:g} s)")
    print("\n| SF | position / PD | orientation / PD | last 2 s / [2, 4) s |")
    print("|---|---:|---:|---:|")
    for label, change in variants.items():
        m = amj.simulate("sf", path, T=T, task=task, **change).metrics
        print(
            f"| {label} | {m['rms_pos_after2'] / pd['rms_pos_after2']:.3f} "
            f"| {m['rms_rot_after2'] / pd['rms_rot_after2']:.3f} "
            f"| {m['rms_pos_last2'] / m['rms_pos_first2']:.3f} |"
        )


def main() -> None:
    doc = (__doc__ or "").split("\n\n")
    parser = Parser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(p for p in doc if p.startswith("    python")),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("arms", nargs="*", help="URDF or MJCF files (default: the Panda)")
    parser.add_argument("--T", type=float, default=3.0 if QUICK else 12.0, help="duration (s)")
    parser.add_argument("--json", type=str, default=None, help="write the table as JSON here")
    parser.add_argument("--why", action="store_true", help="the recipe against the rule")
    args = parser.parse_args()
    if not (math.isfinite(args.T) and args.T > 2.0):
        parser.error(f"--T must be a finite number > 2 s (the metrics' window), got {args.T}")
    arms = args.arms or [str(_models.panda_urdf_path())]
    missing = [a for a in arms if not Path(a).is_file()]
    if missing:
        parser.error(f"no file {missing[0]!r}")
    if args.why:
        why(arms[0], args.T)
        return
    print(
        f"The default Cartesian task, T = {args.T:g} s, metrics over t ≥ 2 s "
        "(pos in mm, rot in mrad)\n"
    )
    print(
        "| arm | n | σmin | PD pos | SF pos | SF/PD pos | PD rot | SF rot | SF/PD rot "
        "| last 2 s / [2, 4) | peak τ/τmax | targets | time |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    table = {}
    for path in arms:
        try:
            r = measure(path, args.T)
        except (adaptimp.ConfigError, ValueError) as e:
            print(f"| {Path(path).name} | refused: {e} |")
            continue
        table[path] = r
        rot = "—" if not r["orients"] else f"{r['rot_ratio']:.3f}"
        print(
            f"| {Path(path).parent.name}/{Path(path).name} | {r['n']} | {r['sigma_min']:.3f} "
            f"| {r['pd_pos_mm']:.3f} | {r['sf_pos_mm']:.4f} | {r['pos_ratio']:.3f} "
            f"| {r['pd_rot_mrad']:.3f} | {r['sf_rot_mrad']:.4f} | {rot} "
            f"| {r['learning']:.3f} | {r['peak_tau_ratio']:.3f} "
            f"| {'met' if r['met'] else 'NOT met'} | {r['time_s']:.0f} s |"
        )
    if args.json:
        Path(args.json).write_text(json.dumps(table, indent=2) + "\n")
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
