"""Runs per second of a 256-run sweep of the robot scenario, four ways, in one run.

1. serial: ``adaptimp.sweep(..., threads=1)``, one run after the other;
2. ``executor=None``: every core from Rust (rayon, the GIL released);
3. a Dask ``LocalCluster`` with one single-threaded worker process per core,
   through ``client.get_executor()`` (batches of 8 runs);
4. the ceiling: one independent Python process per core, each running its share
   of the runs serially (``threads=1``), started together; wall time from the
   first start to the last exit, each process's interpreter start and import
   excluded (they wait on a barrier file before timing starts).

The sweep: state feedback in the robot scenario (T = 20 s at 1 kHz, 10 RK4
substeps), Kp × m2 × payload-free grid of 256 runs (16 Kp from 6 to 10.5, 16 m2
from 0.6 to 2.1 kg). Each configuration is timed ``--repeats`` times
(interleaved), medians reported, with the targets of issue 11: executor=None
≥ 90% of the ceiling, Dask ≥ 80%.

    target/py-venv/bin/python benches/sweep.py [--repeats 3] [--runs 256] [--T 20]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

import numpy as np

import adaptimp

CORES = os.cpu_count() or 1


def grid(runs: int) -> dict[str, list[float]]:
    side = round(runs**0.5)
    return {
        "Kp": [float(x) for x in np.linspace(6.0, 10.5, side)],
        "m2": [float(x) for x in np.linspace(0.6, 2.1, runs // side)],
    }


def timed_sweep(vary: dict[str, list[float]], T: float, **kw: object) -> float:
    start = time.perf_counter()
    df = adaptimp.sweep("sf", vary=vary, scenario="robot", T=T, **kw)
    seconds = time.perf_counter() - start
    assert df["error"].isna().all(), df["error"].dropna().head()
    return seconds


CHILD = textwrap.dedent(
    """
    import sys, time, os, json
    import adaptimp
    part, parts, T, barrier = int(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    vary = json.loads(sys.argv[5])
    import itertools
    runs = [dict(zip(vary, v)) for v in itertools.product(*vary.values())][part::parts]
    while not os.path.exists(barrier):
        time.sleep(0.001)
    for run in runs:
        adaptimp.simulate("sf", "robot", T=T, record_every=10**9, **run)
    """
)


def timed_processes(vary: dict[str, list[float]], T: float) -> float:
    import json

    with tempfile.TemporaryDirectory() as tmp:
        barrier = Path(tmp) / "go"
        procs = [
            subprocess.Popen(
                [
                    sys.executable,
                    "-c",
                    CHILD,
                    str(i),
                    str(CORES),
                    str(T),
                    str(barrier),
                    json.dumps(vary),
                ]
            )
            for i in range(CORES)
        ]
        time.sleep(3.0)  # interpreters started, adaptimp imported
        start = time.perf_counter()
        barrier.touch()
        for p in procs:
            if p.wait() != 0:
                raise RuntimeError("a ceiling process failed")
        return time.perf_counter() - start


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--runs", type=int, default=256)
    ap.add_argument("--T", type=float, default=20.0)
    args = ap.parse_args()
    vary = grid(args.runs)
    runs = len(vary["Kp"]) * len(vary["m2"])
    from distributed import Client, LocalCluster

    with (
        LocalCluster(
            n_workers=CORES, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        ex = client.get_executor()
        client.run(lambda: __import__("adaptimp"))  # imported in every worker before timing
        ways = {
            "serial (threads=1)": lambda: timed_sweep(vary, args.T, threads=1),
            "executor=None (every core)": lambda: timed_sweep(vary, args.T),
            f"Dask LocalCluster ({CORES} processes)": lambda: timed_sweep(
                vary, args.T, executor=ex, batch_size=8
            ),
            f"ceiling: {CORES} independent processes": lambda: timed_processes(vary, args.T),
        }
        samples: dict[str, list[float]] = {k: [] for k in ways}
        for _ in range(args.repeats):
            for key, way in ways.items():
                samples[key].append(way())
    med = {k: statistics.median(v) for k, v in samples.items()}
    ceiling = runs / med[f"ceiling: {CORES} independent processes"]
    print(
        f"{runs} runs of the robot scenario (T = {args.T:g} s), {CORES} cores, "
        f"medians of {args.repeats}"
    )
    print("| way | wall (s) | runs/s | of the ceiling |")
    print("|---|---:|---:|---:|")
    for key, seconds in med.items():
        rate = runs / seconds
        print(f"| {key} | {seconds:.2f} | {rate:.2f} | {100 * rate / ceiling:.0f}% |")


if __name__ == "__main__":
    main()
