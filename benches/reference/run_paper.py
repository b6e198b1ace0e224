"""Run the paper scenario (SPEC §11) with the reference implementations.

* the three cases (pd, sf, of) with ``spec_numba`` at T = 20 s, Ts = 50 µs,
  one RK4 substep, printing the SPEC §12 metrics as a table;
* PD with ``spec_numpy`` for a shorter run (``--t-numpy``, default 2 s) and the
  largest |q_numpy - q_numba| over that run (PD is not chaotic, so the two must
  agree to ~1e-12 rad);
* per-step timings: median and worst ``Controller.step`` call (µs) for both
  implementations, and whole-run time per step of ``simulate`` (numba: the
  20 s runs; NumPy: the PD run above and ``--t-numpy-timing`` s of sf, of).

Usage (from anywhere)::

    python benches/reference/run_paper.py [--t-numpy 2.0] [--t-numpy-timing 0.5]
                                           [--timing-steps 2000]
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

# Run as a script: its own folder is on sys.path, so the siblings import.
import spec_numba
import spec_numpy

CASES = ("pd", "sf", "of")


def _fmt(value) -> str:
    if isinstance(value, (int, np.integer)):
        return f"{int(value)}"
    arr = np.atleast_1d(np.asarray(value, dtype=float))
    return ", ".join(f"{v:.6g}" for v in arr)


def metrics_table(results: dict) -> str:
    """Markdown table: one row per SPEC §12 metric, one column per case."""
    keys = list(next(iter(results.values()))["metrics"])
    lines = [
        "| metric | " + " | ".join(results) + " |",
        "|---" * (len(results) + 1) + "|",
    ]
    for key in keys:
        cells = [_fmt(r["metrics"][key]) for r in results.values()]
        lines.append(f"| {key} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def step_timing(module, case: str, steps: int) -> tuple[float, float]:
    """Median and worst wall time (µs) of ``Controller.step`` in a closed loop."""
    p = module.make_params(case)
    pc = spec_numpy.arm_coefficients(p)
    ctrl = module.Controller(case)
    q, dq = p["q0"].copy(), p["dq0"].copy()
    ctrl.step(q, np.zeros(2), dq)  # warm-up (JIT load for numba)
    ctrl.reset()
    times = np.empty(steps)
    for k in range(steps):
        tau_e = spec_numpy.wall_force(q, dq, p["wall"], p["ke"], p["be"])
        t0 = time.perf_counter()
        tau_sat = ctrl.step(q, tau_e, dq)
        times[k] = time.perf_counter() - t0
        q, dq = spec_numpy.rk4_step(q, dq, tau_sat, p["Ts"], p, pc)
    return 1e6 * float(np.median(times)), 1e6 * float(times.max())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--t-numpy", type=float, default=2.0, help="NumPy PD run length (s)")
    parser.add_argument(
        "--t-numpy-timing",
        type=float,
        default=0.5,
        help="NumPy sf/of run length for the whole-run timing (s)",
    )
    parser.add_argument("--timing-steps", type=int, default=2000, help="steps per step-timing run")
    args = parser.parse_args()

    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cpus, "
        f"Python {platform.python_version()}, NumPy {np.__version__}"
    )

    # JIT compile (or load from cache) outside the timed runs
    spec_numba.simulate("of", T=1e-3)

    results, wall = {}, {}
    for case in CASES:
        t0 = time.perf_counter()
        results[case] = spec_numba.simulate(case)
        wall[case] = time.perf_counter() - t0
    K = len(results["pd"]["t"])
    print(f"\nPaper scenario, numba: T = 20 s, Ts = 50 µs, substeps = 1, K = {K} rows\n")
    print(metrics_table(results))

    t0 = time.perf_counter()
    ref = spec_numpy.simulate("pd", T=args.t_numpy)
    wall_numpy = time.perf_counter() - t0
    fast = spec_numba.simulate("pd", T=args.t_numpy)
    print(f"\nPD, NumPy vs numba over T = {args.t_numpy} s ({len(ref['t'])} rows):")
    for key in ("q", "dq", "tau", "z1"):
        print(f"  max |{key}_numpy - {key}_numba| = {np.max(np.abs(ref[key] - fast[key])):.3e}")

    # whole-run NumPy timings of the adaptive cases over a short run
    wall_np = {"pd": (wall_numpy, len(ref["t"]))}
    for case in ("sf", "of"):
        t0 = time.perf_counter()
        r = spec_numpy.simulate(case, T=args.t_numpy_timing)
        wall_np[case] = (time.perf_counter() - t0, len(r["t"]))

    # the metrics are post-processing (NumPy, shared); time them separately
    t0 = time.perf_counter()
    spec_numba.compute_metrics(results["sf"], spec_numba.make_params("sf"))
    metrics_us = 1e6 * (time.perf_counter() - t0) / K

    print("\nTime per step (µs); 'simulate' = whole run / rows, metrics included")
    print(f"(the §12 metrics alone cost {metrics_us:.2f} µs per row of a 20 s run)\n")
    print("| implementation | case | simulate | Controller.step median | worst |")
    print("|---|---|---|---|---|")
    for case in CASES:
        med, worst = step_timing(spec_numba, case, args.timing_steps)
        whole = 1e6 * wall[case] / K
        print(f"| numba | {case} | {whole:.2f} | {med:.2f} | {worst:.1f} |")
    for case in CASES:
        med, worst = step_timing(spec_numpy, case, args.timing_steps)
        seconds, rows = wall_np[case]
        whole = 1e6 * seconds / rows
        print(f"| numpy | {case} | {whole:.1f} | {med:.1f} | {worst:.1f} |")


if __name__ == "__main__":
    main()
