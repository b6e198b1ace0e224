"""MuJoCo at engine speed: the cost of one control period of ``adaptimp.mujoco.simulate``
against what MuJoCo and the controller cost alone, side by side in one run.

Per control period (Ts = 1 ms), for the UR5 (6 joints, from example-robot-data's
URDF, free space) and the Panda (7 joints, ``adaptimp.mujoco.panda()``, on its
table, tool 27 mm above it, contact on), state feedback with the SPEC §18 rule's
gains and centres along a sinusoid of 0.15 rad at 1 rad/s about the posture:

- (a) ``mujoco.simulate(ctrl, plant, T)``: the native loop (the core steps the
  controller, records, computes the metrics; MuJoCo through its C library);
- (b) MuJoCo alone on the same motion: ``mujoco.rollout.rollout`` (one Python
  call whose loop is MuJoCo's C: ``mj_step`` per substep with the given
  controls) of (a)'s applied torques, each held for its period's substeps,
  divided by K: the engine's cost of a period's substeps (contacts included),
  with nothing of adaptimp's;
- (b') MuJoCo alone at rest: ``mujoco.mj_step(m, d, nstep=substeps · K)`` with
  the torque held at gravity compensation of the posture (no motion, no
  contact), divided by K;
- (c) the controller alone: ``Controller.replay`` over (a)'s K recorded rows
  (the Rust step in a Rust loop), divided by K;
- the ratio (a) / ((b) + (c)) (target ≤ 1.5);
- for reference, the Python loop (``simulate`` with the same controller behind a
  Python object: the fallback, the loop every controller took before).

Then a sweep on MuJoCo: ``adaptimp.sweep(..., plant="mujoco")`` of 16 runs (the
paper's arm with its ceiling, state feedback in the robot scenario, T =
``--sweep-T``, a 4 × 4 grid of Kp and K1) on every core (``executor=None``)
against one thread (``threads=1``), and against the machine's ceiling: two
independent processes running 8 runs each; target ≥ 1.7× on 2 cores.

Each measurement is repeated ``--repeats`` times, interleaved; medians.

    target/py-venv/bin/python benches/mujoco_loop.py [--T 10] [--repeats 5] [--sweep-T 2]
"""

from __future__ import annotations

import argparse
import gc
import platform
import statistics
import time
from collections.abc import Callable
from typing import Any

import mujoco
import numpy as np
from mujoco import rollout

import adaptimp
from adaptimp import mujoco as amj
from adaptimp import tuning

W, A = 1.0, 0.15  # rad/s, rad: the task's sinusoid about the posture


def arm(name: str) -> tuple[Any, np.ndarray]:
    if name == "UR5":
        from adaptimp._models import panda_urdf_path

        root = panda_urdf_path().parents[2]
        model = amj.from_urdf(root / "ur_description" / "urdf" / "ur5_robot.urdf")
        return model, np.array([0.0, -1.2, 1.2, -1.5, -1.5, 0.0])
    return amj.panda(), np.array(adaptimp._models.PANDA_HOME)


def controller(plant: amj.Plant, q0: np.ndarray) -> adaptimp.Controller:
    def path(t: float) -> tuple[Any, Any, Any]:
        one = np.ones_like(q0)
        return q0 + A * np.sin(W * t), A * W * np.cos(W * t) * one, -A * W * W * np.sin(W * t) * one

    kw = tuning.suggest(plant, q0, plant.tau_max, Ts=1e-3, path=path, period=2 * np.pi)
    n = kw.pop("n")
    traj = {"xc_offset": q0.tolist(), "xc_sin": A, "xc_cos": 0.0, "xc_omega": W}
    return adaptimp.Controller("sf", "robot", n=n, impedance="joint", **kw, **traj)


class PythonSide:
    """The same controller behind a Python object: simulate's Python loop."""

    def __init__(self, inner: adaptimp.Controller) -> None:
        self.inner = inner
        self.Ts = inner.Ts
        self.params = inner.params

    def step(self, q: Any, tau_e: Any, dq: Any = None, **sp: Any) -> Any:
        return self.inner.step(q, tau_e, dq, **sp)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


def timers(name: str, T: float) -> tuple[dict[str, Callable[[], float]], int, int]:
    model, q0 = arm(name)
    plant = amj.Plant(model)
    ctrl = controller(plant, q0)
    steps = round(T / ctrl.Ts)
    substeps = max(1, round(ctrl.Ts / plant.timestep))
    log = amj.simulate(ctrl, plant, T=T, q0=q0)
    assert log.params["loop"] == "native"

    def native() -> float:
        ctrl.reset()
        start = time.perf_counter()
        amj.simulate(ctrl, plant, T=T, q0=q0)
        return (time.perf_counter() - start) / steps

    # MuJoCo alone on the same trajectory: (a)'s applied torques, each held for
    # its period's substeps, as MuJoCo's controls.
    controls = np.repeat(log.tau_sat / plant._gear, substeps, axis=0)
    m, d = plant.model, plant.data
    plant.reset(q0)
    spec = int(mujoco.mjtState.mjSTATE_FULLPHYSICS)
    initial = np.zeros(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, initial, spec)

    def engine() -> float:
        start = time.perf_counter()
        states, _ = rollout.rollout(m, d, initial, controls)
        seconds = time.perf_counter() - start
        # The same motion as (a), to MuJoCo's rounding (not a diverged run).
        q_end = states[0, -1, 1 : 1 + m.nq][plant._qadr]
        assert np.allclose(q_end, log.q[-1], atol=1e-3), (q_end, log.q[-1])
        return seconds / steps

    def hold() -> float:
        plant.reset(q0)
        plant.apply(plant.bias())  # hold the posture against gravity
        start = time.perf_counter()
        mujoco.mj_step(m, d, nstep=substeps * steps)
        seconds = time.perf_counter() - start
        assert abs(d.time - steps * ctrl.Ts) < 1e-6, "MuJoCo reset its state"
        return seconds / steps

    def step() -> float:
        ctrl.reset()
        start = time.perf_counter()
        ctrl.replay(log.q, log.tau_e, log.dq)
        return (time.perf_counter() - start) / steps

    def python_loop() -> float:
        ctrl.reset()
        start = time.perf_counter()
        res = amj.simulate(PythonSide(ctrl), plant, T=T, q0=q0)
        assert res.params["loop"] == "python"
        return (time.perf_counter() - start) / steps

    return (
        {"native": native, "engine": engine, "hold": hold, "step": step, "python": python_loop},
        plant.n,
        substeps,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--T", type=float, default=10.0, help="run length (s)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--sweep-T", type=float, default=2.0, help="sweep run length (s)")
    args = parser.parse_args()
    print(
        f"machine: {platform.processor() or platform.machine()}, "
        f"{platform.python_implementation()} {platform.python_version()}, "
        f"MuJoCo {mujoco.__version__}; T = {args.T:g} s at Ts = 1 ms; "
        f"medians of {args.repeats}, µs per control period"
    )
    print(
        "\n| arm | n | substeps | (a) simulate, native | (b) MuJoCo, same motion | "
        "(b') MuJoCo at rest | (c) Rust step | (a)/((b)+(c)) | Python loop | Python/(a) |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name in ("UR5", "Panda"):
        fns, n, substeps = timers(name, args.T)
        times: dict[str, list[float]] = {k: [] for k in fns}
        gc.disable()
        try:
            for _ in range(args.repeats):
                for k, f in fns.items():
                    times[k].append(f())
        finally:
            gc.enable()
        med = {k: statistics.median(v) * 1e6 for k, v in times.items()}
        ratio = med["native"] / (med["engine"] + med["step"])
        print(
            f"| {name} | {n} | {substeps} | {med['native']:.1f} | {med['engine']:.1f} | "
            f"{med['hold']:.1f} | {med['step']:.2f} | {ratio:.2f} | {med['python']:.1f} | "
            f"{med['python'] / med['native']:.1f}× |"
        )
    sweep_table(args.sweep_T, args.repeats)


def _half(vary: dict[str, list[float]], T: float, part: int) -> None:
    """One process's share of the sweep: every other Kp, one thread."""
    share = {"Kp": vary["Kp"][part::2], "K1": vary["K1"]}
    adaptimp.sweep("sf", vary=share, plant="mujoco", T=T, threads=1)


def sweep_table(T: float, repeats: int) -> None:
    import multiprocessing
    import os

    vary = {"Kp": [7.0, 8.0, 9.0, 10.0], "K1": [4.0, 5.0, 6.0, 7.0]}
    times: dict[str, list[float]] = {"every core": [], "one thread": [], "two processes": []}
    ctx = multiprocessing.get_context("fork")
    for _ in range(repeats):
        for label, threads in (("every core", None), ("one thread", 1)):
            start = time.perf_counter()
            df = adaptimp.sweep("sf", vary=vary, plant="mujoco", T=T, threads=threads)
            times[label].append(time.perf_counter() - start)
            assert df["error"].isna().all(), df["error"].dropna().head()
        # The ceiling on this machine: two independent processes, half each.
        procs = [ctx.Process(target=_half, args=(vary, T, part)) for part in (0, 1)]
        start = time.perf_counter()
        for p in procs:
            p.start()
        for p in procs:
            p.join()
        times["two processes"].append(time.perf_counter() - start)
    med = {k: statistics.median(v) for k, v in times.items()}
    print(
        f"\nsweep(plant='mujoco'), 16 runs of T = {T:g} s on {os.cpu_count()} cores "
        f"(medians of {repeats}): one thread {med['one thread']:.2f} s, every core "
        f"{med['every core']:.2f} s (speed-up {med['one thread'] / med['every core']:.2f}×); "
        f"two independent processes, 8 runs each: {med['two processes']:.2f} s "
        f"(speed-up {med['one thread'] / med['two processes']:.2f}×, this machine's ceiling)"
    )


if __name__ == "__main__":
    main()
