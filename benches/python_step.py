"""One ``Controller.step`` called from Python against the same step in Rust, side by side.

The Rust step is timed by ``Controller.replay`` over logged measurements: the
loop runs in Rust (GIL released) and calls exactly the step a Python call
reaches, so replay's time per row is the Rust step (plus a row copy of a few
ns). The Python call is ``Controller.step(m)``: alone, on measurements made
before, and with ``m = Measurement(q, dq, tau_e=tau_e)`` made each step from
NumPy arrays of shape (n,) or from lists, one call per row of the same log. All
run K = 20 000 rows of a recorded run of the robot scenario (state feedback,
Ts = 1 ms), interleaved round-robin (7 repeats, garbage collector off) so
that load falls on all alike: n = 2 (the paper's arm, the 256-node grid) and
n = 7 (a 7-link planar arm, gains and 64 centres along the orbit from
``adaptimp.tuning.suggest``, SPEC §18). Reports medians and the overhead of a
Python call over the Rust step (target: at most 0.5 µs), and then the speed-up
of two ``simulate`` runs in two threads over one after the other.

    target/py-venv/bin/python benches/python_step.py [--repeats 7] [--rows 20000] [--n 2 7]

Also run by ``benches/compare.py``, whose report includes this table.
"""

from __future__ import annotations

import argparse
import gc
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np

import adaptimp
from adaptimp import Measurement


def setup(rows: int, n: int) -> tuple[adaptimp.SimResult, dict[str, Any]]:
    """A logged run of ``rows`` steps (robot scenario, state feedback) and the
    controller's keywords: the paper's arm for n = 2; for other n a planar arm
    of 1 kg, 0.25 m links tracking a sinusoid of 0.15 rad about 0.3 rad, with
    the gains and centres of ``tuning.suggest``."""
    if n == 2:
        return adaptimp.simulate("sf", "robot", T=rows * 1e-3), {}
    from adaptimp import tuning

    arm = adaptimp.PlanarArm(n, masses=1.0, lengths=0.25)
    q0 = np.full(n, 0.3)
    ones = np.ones(n)

    def path(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return q0 + 0.15 * np.sin(t) * ones, 0.15 * np.cos(t) * ones, -0.15 * np.sin(t) * ones

    kw = tuning.suggest(arm, q0, np.full(n, 20.0), Ts=1e-3, path=path, period=2 * np.pi)
    kw.update(q0=q0.tolist(), xc_offset=0.3, xc_sin=0.15, xc_cos=0.0, xc_omega=1.0)
    log = adaptimp.simulate("sf", "robot", arm=arm, T=rows * 1e-3, wall=None, **kw)
    kw.pop("q0")
    return log, kw


def timers(rows: int, n: int = 2) -> dict[str, Callable[[], float]]:
    log, kw = setup(rows, n)
    q, tau_e, dq = log.q[:rows], log.tau_e[:rows], log.dq[:rows]
    arrays = list(zip(q, tau_e, dq))
    lists = [(a.tolist(), b.tolist(), c.tolist()) for a, b, c in arrays]
    ctrl = adaptimp.Controller("sf", "robot", **kw)

    def replay() -> float:
        ctrl.reset()
        start = time.perf_counter()
        ctrl.replay(q, tau_e, dq)
        return (time.perf_counter() - start) / rows

    made = [Measurement(a, c, tau_e=b) for a, b, c in arrays]

    def calls(data: list[tuple]) -> Callable[[], float]:
        """The measurement made each step from the sensors' arrays, then the step."""

        def run() -> float:
            ctrl.reset()
            step, measurement = ctrl.step, Measurement
            start = time.perf_counter()
            for a, b, c in data:
                step(measurement(a, c, tau_e=b))
            return (time.perf_counter() - start) / rows

        return run

    def steps() -> float:
        """The step alone, on measurements made before."""
        ctrl.reset()
        step = ctrl.step
        start = time.perf_counter()
        for m in made:
            step(m)
        return (time.perf_counter() - start) / rows

    return {
        "Rust step (Controller.replay, per row)": replay,
        "Python call, step(m) alone": steps,
        "Python call, Measurement of NumPy arrays + step": calls(arrays),
        "Python call, Measurement of lists + step": calls(lists),
    }


def measure(rows: int = 20_000, repeats: int = 7, n: int = 2) -> dict[str, float]:
    """Median seconds per step of each timer, interleaved round-robin."""
    ts = timers(rows, n)
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


def report(medians: dict[str, float], n: int = 2) -> str:
    rust = medians["Rust step (Controller.replay, per row)"]
    lines = [
        f"| n = {n}, state feedback, robot scenario | median (µs) | over the Rust step (µs) |",
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
    ap.add_argument("--n", type=int, nargs="+", default=[2, 7], help="joints (default: 2 7)")
    ap.add_argument("--no-threads", action="store_true", help="skip the two-thread run")
    args = ap.parse_args()
    for n in args.n:
        print(report(measure(args.rows, args.repeats, n), n), end="\n\n")
    if args.no_threads:
        return
    serial, parallel = threads()
    print(
        f"two simulate() runs (robot scenario, 10 s): one after the other {serial:.3f} s, "
        f"in two threads {parallel:.3f} s: {serial / parallel:.2f}x"
    )


if __name__ == "__main__":
    main()
