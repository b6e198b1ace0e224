"""One ``Controller.step`` called from Python against the same step in Rust, side by side.

The Rust step is timed by ``Controller.replay`` over logged measurements: the
loop runs in Rust (GIL released) and calls exactly the step a Python call
reaches, so replay's time per row is the Rust step (plus a row copy of a few
ns). The Python call is ``Controller.step(q, tau_e, dq)`` with NumPy arrays of
shape (2,), one call per row of the same log, and the same with lists. Both
run K = 20 000 rows of a recorded run of the robot scenario (state feedback,
n = 2, Ts = 1 ms), interleaved round-robin (7 repeats, garbage collector off)
so that load falls on all alike. Reports medians and the overhead of a Python
call over the Rust step (the target of issue 9: at most 0.5 µs), and then
the speed-up of two ``simulate`` runs in two threads over one after the other.

    target/py-venv/bin/python benches/python_step.py [--repeats 7] [--rows 20000]

Also run by ``benches/compare.py``, whose report includes this table.
"""

from __future__ import annotations

import argparse
import gc
import statistics
import time
from collections.abc import Callable

import adaptimp


def timers(rows: int) -> dict[str, Callable[[], float]]:
    log = adaptimp.simulate("sf", "robot", T=rows * 1e-3)
    q, tau_e, dq = log.q[:rows], log.tau_e[:rows], log.dq[:rows]
    arrays = list(zip(q, tau_e, dq))
    lists = [(a.tolist(), b.tolist(), c.tolist()) for a, b, c in arrays]
    ctrl = adaptimp.Controller("sf", "robot")

    def replay() -> float:
        ctrl.reset()
        start = time.perf_counter()
        ctrl.replay(q, tau_e, dq)
        return (time.perf_counter() - start) / rows

    def calls(data: list[tuple]) -> Callable[[], float]:
        def run() -> float:
            ctrl.reset()
            step = ctrl.step
            start = time.perf_counter()
            for a, b, c in data:
                step(a, b, c)
            return (time.perf_counter() - start) / rows

        return run

    return {
        "Rust step (Controller.replay, per row)": replay,
        "Python call, NumPy arrays": calls(arrays),
        "Python call, lists": calls(lists),
    }


def measure(rows: int = 20_000, repeats: int = 7) -> dict[str, float]:
    """Median seconds per step of each timer, interleaved round-robin."""
    ts = timers(rows)
    for run in ts.values():  # warm-up
        run()
    samples: dict[str, list[float]] = {k: [] for k in ts}
    gc.disable()
    try:
        for _ in range(repeats):
            for key, run in ts.items():
                samples[key].append(run())
    finally:
        gc.enable()
    return {k: statistics.median(v) for k, v in samples.items()}


def report(medians: dict[str, float]) -> str:
    rust = medians["Rust step (Controller.replay, per row)"]
    lines = [
        "| n = 2, state feedback, robot scenario | median (µs) | over the Rust step (µs) |",
        "|---|---:|---:|",
    ]
    for key, s in medians.items():
        over = "" if s is rust else f"{(s - rust) * 1e6:+.3f}"
        lines.append(f"| {key} | {s * 1e6:.3f} | {over} |")
    return "\n".join(lines)


def threads(repeats: int = 3, T: float = 10.0) -> tuple[float, float]:
    """Median wall time (s) of two robot-scenario runs one after the other, and in
    two threads (distinct controllers, the GIL released by ``simulate``)."""
    import threading

    def run() -> None:
        adaptimp.simulate("sf", "robot", T=T, record_every=1000)

    serial, parallel = [], []
    for _ in range(repeats):
        start = time.perf_counter()
        run()
        run()
        serial.append(time.perf_counter() - start)
        ts = [threading.Thread(target=run) for _ in range(2)]
        start = time.perf_counter()
        for t in ts:
            t.start()
        for t in ts:
            t.join()
        parallel.append(time.perf_counter() - start)
    return statistics.median(serial), statistics.median(parallel)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rows", type=int, default=20_000)
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    print(report(measure(args.rows, args.repeats)))
    serial, parallel = threads()
    print(
        f"\ntwo simulate() runs (robot scenario, 10 s): one after the other {serial:.3f} s, "
        f"in two threads {parallel:.3f} s: {serial / parallel:.2f}x"
    )


if __name__ == "__main__":
    main()
