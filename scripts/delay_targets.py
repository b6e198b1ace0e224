"""The loop's delay on any arm (SPEC (17.1), (18.11); docs/your_arm.md, "The
robot's loop"): the default joint task and the default Cartesian task with the
torque acting d periods after its sample, the controllers made by the rule for
that delay, nothing set per arm.

    python scripts/delay_targets.py FILE [FILE ...] [--delays 0,1,2] [--T 8]
                                    [--cartesian] [--[no-]coupled] [--tip NAME]
                                    [--json out.json]

For each file and delay d: ``amj.simulate(case, FILE, T=T, delay=d)`` for PD,
SF and OF (RMS ‖z1‖ over t ≥ 2 s, the plant's true q), SF's drift (RMS over the
last 2 s against [2, 4) s), the peak commanded |τ_i|/τmax_i after 0.1 s and
the share of rows at a limit; with ``--cartesian`` also ``amj.cartesian_task``
and SF/PD in position and orientation over t ≥ 2 s (T = 12 s, ``--cartesian-T``). Prints one
Markdown table per part; the targets of the issue are SF/PD and OF/PD ≤ 0.2,
no drift, peak ≤ 2 τmax. Every controller (PD too) is made by the rule with
its default: the inertia-shaped gains of SPEC (18.12) for d ≥ 1, the
diagonal gains of (18.1) for d = 0;
``--coupled`` / ``--no-coupled``: the one or the other everywhere
(``coupled=True`` / ``False``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np


def joint_row(
    path: str, d: int, T: float, tip: str | None, coupled: bool | None = None
) -> dict[str, Any]:
    """PD, SF, OF of the default joint task at delay ``d``."""
    from adaptimp import mujoco as amj

    runs = {
        c: amj.simulate(c, path, T=T, delay=d, tip=tip, coupled=coupled) for c in ("pd", "sf", "of")
    }
    rms = {c: float(r.metrics["rms_z1_after2"]) for c, r in runs.items()}
    sf = runs["sf"]
    t = sf.t

    def window(a: float, b: float) -> float:
        s = (t >= a) & (t < b)
        return float(np.sqrt(np.mean(np.sum(sf.z1[s] ** 2, axis=1))))

    tau_max = np.asarray(sf.params["tau_max"])
    peak = max(float(np.max(np.abs(r.tau[r.t >= 0.1]) / tau_max)) for r in runs.values())
    at_limit = max(float(r.metrics["sat_duty"]) for r in runs.values())
    warned = sum(len(r.params.get("warnings", [])) for r in runs.values())
    return {
        "pd": rms["pd"],
        "sf/pd": rms["sf"] / rms["pd"],
        "of/pd": rms["of"] / rms["pd"],
        "sf": rms["sf"],
        "drift": window(T - 2.0, T) / window(2.0, 4.0),
        "peak": peak,
        "at_limit": at_limit,
        "warnings": warned,
    }


def cartesian_row(
    path: str, d: int, tip: str | None, coupled: bool | None = None, T: float = 12.0
) -> dict[str, Any]:
    """PD and SF of the default Cartesian task at delay ``d`` (T s, 12 by default)."""
    from adaptimp import mujoco as amj

    plant = amj.Plant(path, tip=tip, contact=False)
    task = amj.cartesian_task(plant)
    runs = {
        c: amj.simulate(c, plant, T=T, task=task, delay=d, coupled=coupled) for c in ("pd", "sf")
    }
    pos = {c: float(r.metrics["rms_pos_after2"]) for c, r in runs.items()}
    rot = {c: float(r.metrics["rms_rot_after2"]) for c, r in runs.items()}
    tau_max = np.asarray(runs["sf"].params["tau_max"])
    return {
        "pd_pos": pos["pd"],
        "sf/pd pos": pos["sf"] / pos["pd"],
        "sf/pd rot": rot["sf"] / rot["pd"] if rot["pd"] > 0 else math.nan,
        "sf_pos": pos["sf"],
        "peak": float(np.max(np.abs(runs["sf"].tau[runs["sf"].t >= 0.1]) / tau_max)),
        "orients": bool(task.orients),
    }


def main() -> None:
    parser = argparse.ArgumentParser(
        description="The default joint and Cartesian tasks with the loop's delay d "
        "(SPEC (18.11)): PD, SF and OF made by the rule for d, on each file."
    )
    parser.add_argument("paths", nargs="+", help="URDF or MJCF files")
    parser.add_argument("--delays", default="0,1,2", help="delays in periods, comma-separated")
    parser.add_argument("--T", type=float, default=8.0, help="joint runs' duration (s)")
    parser.add_argument("--cartesian", action="store_true", help="also the Cartesian task")
    parser.add_argument(
        "--cartesian-T", type=float, default=12.0, help="Cartesian runs' duration (s)"
    )
    parser.add_argument(
        "--coupled",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the inertia-shaped gains of SPEC (18.12) (the rule's default: joint task, d ≥ 1); "
        "--no-coupled: the diagonal gains of (18.1) at every d; --coupled: at every d",
    )
    parser.add_argument("--tip", default=None, help="the end effector, for every file")
    parser.add_argument("--json", type=Path, default=None, help="write the numbers")
    args = parser.parse_args()
    try:
        delays = [int(x) for x in args.delays.split(",")]
    except ValueError:
        parser.error(f"--delays must be integers, comma-separated: {args.delays!r}")
    out: dict[str, Any] = {}
    print("| file | d | PD (rad) | SF/PD | OF/PD | SF (rad) | drift | peak τ/τmax | at a limit |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for path in args.paths:
        name = Path(path).name
        for d in delays:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    r = joint_row(path, d, args.T, args.tip, args.coupled)
                except Exception as e:  # a file the library refuses: the refusal is the row
                    print(f"| {name} | {d} | {type(e).__name__}: {str(e)[:120]} |||||||")
                    continue
            out.setdefault(path, {})[f"joint {d}"] = r
            print(
                f"| {name} | {d} | {r['pd']:.3g} | {r['sf/pd']:.3f} | {r['of/pd']:.3f} | "
                f"{r['sf']:.3g} | {r['drift']:.2f} | {r['peak']:.2f} | "
                f"{100 * r['at_limit']:.1f} % |",
                flush=True,
            )
    if args.cartesian:
        print()
        print("| file | d | PD position (mm) | SF/PD position | SF/PD orientation | peak τ/τmax |")
        print("|---|---:|---:|---:|---:|---:|")
        for path in args.paths:
            name = Path(path).name
            for d in delays:
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    try:
                        c = cartesian_row(path, d, args.tip, args.coupled, args.cartesian_T)
                    except Exception as e:
                        print(f"| {name} | {d} | {type(e).__name__}: {str(e)[:120]} ||||")
                        continue
                out.setdefault(path, {})[f"cartesian {d}"] = c
                rot = f"{c['sf/pd rot']:.3f}" if c["orients"] else "— (position only)"
                print(
                    f"| {name} | {d} | {1e3 * c['pd_pos']:.3g} | {c['sf/pd pos']:.3f} | {rot} | "
                    f"{c['peak']:.2f} |",
                    flush=True,
                )
    if args.json is not None:
        args.json.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")


if __name__ == "__main__":
    sys.exit(main())
