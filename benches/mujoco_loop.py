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
- for a path given as a Python callable: (d) the path's own calls at t_k
  (``path(k·Ts)`` K times in a Python loop, nothing else), divided by K, and
  ((a) − (d)) / ((b) + (c)): the loop's cost without the user's function;
- the same controller behind a Python object (its ``step`` written in Python):
  the core's loop calls it back once a period (before, a loop written in
  Python stepped such controllers).

Cartesian rows: ``adaptimp.CartesianController`` (the core's outer loop of SPEC
§16, position-only, in front of state feedback with the same rule's gains and
centres along the joint orbit of its path): the UR5's tool on a 5 cm circle at
0.5 Hz about its start (free space), and the Panda of the scenario
"panda-table" (``adaptimp.panda_table``: the tool pressing on the table along
its circle, contact on). Twice: with the controller's path, a Python callable,
whose tabulation (one ``path(t)`` call per period) is in (a); and with the
path given to ``simulate`` as arrays (``reference=(xc, dxc, ddxc)``,
tabulated before the clock starts). (c) is ``CartesianImpedance.replay``
(outer loop and joint step in a Rust loop) over (a)'s rows.

The Panda table: ``examples/13_panda_table.py``'s controllers (T = ``--table-T``)
each run natively and behind a Python object (called back), side by side;
computed torque steps in the core (SPEC §20) in both. A third column,
"before", is the computed-torque rows' joint law written with Pinocchio in
Python (``PinocchioPDPlus`` below, the law of SPEC (20.4) at n = 0 that
``adaptimp.baselines`` stepped before §20), called back. Beside them, MuJoCo
alone on the same motion (``mujoco.rollout`` of the native run's torques):
the floor of any loop.

Then a sweep on MuJoCo: ``adaptimp.sweep(..., plant="mujoco")`` of 16 runs (the
paper's arm with its ceiling, state feedback in the robot scenario, T =
``--sweep-T``, a 4 × 4 grid of Kp and K1) on every core (``executor=None``)
against one thread (``threads=1``), and against the machine's ceiling: two
independent processes running 8 runs each; target ≥ 1.7× on 2 cores.

Builds side by side (``--only builds --before DIR``): the same rows timed in
this build and in another one whose Python package is in DIR (put first on
``PYTHONPATH``), alternating, each repeat in a fresh process of each: per
period, every controller natively and written in Python (behind a Python
object), on the paper's arm at its 50 µs (one MuJoCo step a period: the
loop's own cost shows most), the UR5 and the Panda (joint space and behind
the Cartesian impedance), and computed torque and a PD written in Python on
the paper's arm. To build the package of a commit into DIR:

    git worktree add --detach ../before COMMIT && cd ../before
    python -m venv venv && venv/bin/pip install maturin numpy mujoco pin example-robot-data
    venv/bin/maturin develop --release   # DIR = ../before/python

Each measurement is repeated ``--repeats`` times, interleaved; medians.

    target/py-venv/bin/python benches/mujoco_loop.py [--T 10] [--repeats 5] [--sweep-T 2]
        [--table-T 20] [--only loop,cartesian,table,sweep,builds] [--before DIR]
"""

from __future__ import annotations

import argparse
import gc
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
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
    """The same controller behind a Python object: its ``step`` in Python."""

    def __init__(self, inner: adaptimp.Controller) -> None:
        self.inner = inner
        self.Ts = inner.Ts
        self.params = inner.params

    def step(self, m: Any, **sp: Any) -> Any:
        return self.inner.step(m, **sp)

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
        q_end = states[0, -1, 1 : 1 + m.nq][plant.qpos_adr]
        assert np.allclose(q_end, log.q[-1], atol=1e-3), (q_end, log.q[-1])
        return seconds / steps

    def hold() -> float:
        plant.reset(q0)
        d.ctrl[plant._act] = plant.bias() / plant._gear  # hold the posture against gravity
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
        assert res.params["loop"] == "callback"
        return (time.perf_counter() - start) / steps

    return (
        {
            "native": native,
            "engine": engine,
            "hold": hold,
            "step": step,
            "python": python_loop,
        },
        plant.n,
        substeps,
    )


class InPython:
    """A controller behind a Python object: its ``step`` in Python."""

    def __init__(self, inner: Any) -> None:
        self.inner = inner

    def step(self, *args: Any, **kwargs: Any) -> Any:
        return self.inner.step(*args, **kwargs)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)


def cartesian(name: str) -> tuple[Any, Any, np.ndarray]:
    """The arm's plant, Cartesian controller and start."""
    from adaptimp.scenarios import panda_table as apt

    if name == "Panda":
        sc = apt.panda_table()
        return amj.Plant(sc.model), apt.panda_controller("sf", sc), sc.q0
    from adaptimp._models import panda_urdf_path

    urdf = panda_urdf_path().parents[2] / "ur_description" / "urdf" / "ur5_robot.urdf"
    model, q0 = arm(name)
    plant = amj.Plant(model)
    chain = adaptimp.Chain.from_urdf(urdf)
    p0 = chain.pose(q0)[0]
    r, w = 0.05, np.pi  # m, rad/s: 0.5 Hz

    def path(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        c, s = np.cos(w * t), np.sin(w * t)
        return (
            p0 + r * np.array([c - 1.0, s, 0.0]),
            r * w * np.array([-s, c, 0.0]),
            -r * w * w * np.array([c, s, 0.0]),
        )

    outer = adaptimp.cartesian.CartesianImpedance(chain, Ts=1e-3, q0=q0, Kd_rot=0.0)
    centres, widths = outer.orbit_centres(path, 2.0, nodes=64)
    kw = tuning.suggest(plant, q0, plant.tau_max, Ts=1e-3)
    kw.pop("n")
    ctrl = adaptimp.CartesianController(
        chain, "sf", q0=q0, path=path, Kd_rot=0.0, centers=centres, widths=widths, **kw
    )
    return plant, ctrl, q0


def tabulated(ctrl: Any, steps: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The controller's path at t_k = k·Ts as arrays (K, 3) (before any clock starts)."""
    rows = [ctrl.path(k * ctrl.Ts) for k in range(steps)]
    p, dp, ddp = (np.array([r[i] for r in rows]) for i in range(3))
    return p, dp, ddp


def cartesian_timers(
    name: str, T: float, table: bool = False
) -> tuple[dict[str, Callable[[], float]], int, int]:
    plant, ctrl, q0 = cartesian(name)
    steps = round(T / ctrl.Ts)
    substeps = max(1, round(ctrl.Ts / plant.timestep))
    reference = tabulated(ctrl, steps) if table else None
    if table:
        ctrl.path = None  # simulate's reference instead, tabulated before the clock starts
    log = amj.simulate(ctrl, plant, T=T, q0=q0, reference=reference)
    assert log.params["loop"] == "native"
    assert log.task is not None
    ctrl.reset()
    targets = ctrl.commanded_poses(steps, reference)
    controls = np.repeat(log.tau_sat / plant._gear, substeps, axis=0)
    m, d = plant.model, plant.data
    plant.reset(q0)
    spec = int(mujoco.mjtState.mjSTATE_FULLPHYSICS)
    initial = np.zeros(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, initial, spec)

    def native() -> float:
        ctrl.reset()
        start = time.perf_counter()
        amj.simulate(ctrl, plant, T=T, q0=q0, reference=reference)
        return (time.perf_counter() - start) / steps

    def engine() -> float:
        start = time.perf_counter()
        states, _ = rollout.rollout(m, d, initial, controls)
        seconds = time.perf_counter() - start
        q_end = states[0, -1, 1 : 1 + m.nq][plant.qpos_adr]
        assert np.allclose(q_end, log.q[-1], atol=1e-3), (q_end, log.q[-1])
        return seconds / steps

    def hold() -> float:
        plant.reset(q0)
        d.ctrl[plant._act] = plant.bias() / plant._gear
        start = time.perf_counter()
        mujoco.mj_step(m, d, nstep=substeps * steps)
        seconds = time.perf_counter() - start
        assert abs(d.time - steps * ctrl.Ts) < 1e-6, "MuJoCo reset its state"
        return seconds / steps

    def step() -> float:
        ctrl.reset()
        core = ctrl.outer.core
        assert log.task is not None
        start = time.perf_counter()
        tau = core.replay(ctrl.inner, log.q, log.dq, log.task["wrench"], targets)
        seconds = time.perf_counter() - start
        assert np.array_equal(tau, log.tau_sat)
        return seconds / steps

    def path_alone() -> float:
        # The path's own cost: its calls at t_k, as (a) makes them, with nothing else.
        if table:
            return 0.0
        path, ts = ctrl.path, ctrl.Ts
        start = time.perf_counter()
        for k in range(steps):
            path(k * ts)
        return (time.perf_counter() - start) / steps

    def python_loop() -> float:
        ctrl.reset()
        start = time.perf_counter()
        res = amj.simulate(InPython(ctrl), plant, T=T, q0=q0, reference=reference)
        assert res.params["loop"] == "callback"
        return (time.perf_counter() - start) / steps

    return (
        {
            "native": native,
            "engine": engine,
            "hold": hold,
            "step": step,
            "path": path_alone,
            "python": python_loop,
        },
        plant.n,
        substeps,
    )


LABELS = {
    "joint": "SF, joint space (own sinusoid)",
    "cartesian": "SF behind the Cartesian impedance, path in Python",
    "table": "SF behind the Cartesian impedance, path as arrays",
}


def loop_table(rows: list[tuple[str, str]], T: float, repeats: int) -> None:
    print(
        "\n| arm | controller | n | substeps | (a) simulate, native | (b) MuJoCo, same motion | "
        "(b') MuJoCo at rest | (c) Rust step | (a)/((b)+(c)) | (d) the path's calls | "
        "((a)−(d))/((b)+(c)) | in Python, called back | Python/(a) |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name, kind in rows:
        if kind == "joint":
            fns, n, substeps = timers(name, T)
        else:
            fns, n, substeps = cartesian_timers(name, T, table=kind == "table")
        times: dict[str, list[float]] = {k: [] for k in fns}
        gc.disable()
        try:
            for _ in range(repeats):
                for k, f in fns.items():
                    times[k].append(f())
        finally:
            gc.enable()
        med = {k: statistics.median(v) * 1e6 for k, v in times.items()}
        med.setdefault("path", 0.0)
        ratio = med["native"] / (med["engine"] + med["step"])
        own = (med["native"] - med["path"]) / (med["engine"] + med["step"])
        label = LABELS[kind]
        print(
            f"| {name} | {label} | {n} | {substeps} | {med['native']:.1f} | {med['engine']:.1f} | "
            f"{med['hold']:.1f} | {med['step']:.2f} | {ratio:.2f} | {med['path']:.1f} | "
            f"{own:.2f} | {med['python']:.1f} | {med['python'] / med['native']:.1f}× |"
        )


class PinocchioPDPlus:
    """The computed-torque rows' joint law as it stepped before SPEC §20, in
    Python with Pinocchio's CRBA and RNEA: τ = M q̈_c + C q̇ + G + τ_task +
    Π M (K_P (q_c − q) + K_D (q̇_c − q̇)), Π = I − Jᵀ (J Jᵀ + Λ²)⁻¹ J (the
    "before" column of the Panda table; the library's law is the core's)."""

    def __init__(self, model: Any, tau_max: np.ndarray, mass_scale: float) -> None:
        import pinocchio as pin

        from adaptimp.baselines import scale_masses

        self.pin = pin
        self.model = scale_masses(model, mass_scale)
        self.data = self.model.createData()
        self.tau_max, self.Ts, self.impedance = tau_max, 1e-3, "external"
        self.n = self.model.nv

    def step(self, m: Any, **kw: Any) -> np.ndarray:
        q, dq = m.q, m.dq
        pin, m_, d_ = self.pin, self.model, self.data
        xc, dxc, ddxc = kw["xc"], kw["dxc"], kw["ddxc"]
        j = np.asarray(kw["jacobian"]).reshape(6, self.n)
        null = np.eye(self.n) - j.T @ np.linalg.solve(j @ j.T + 1e-4 * np.eye(6), j)
        m = pin.crba(m_, d_, q)
        m = np.triu(m) + np.triu(m, 1).T
        pd = 400.0 * (xc - q) + 40.0 * (dxc - dq)
        h = pin.rnea(m_, d_, q, dq, np.zeros(self.n))
        tau = m @ ddxc + h + kw["task_torque"] + null @ (m @ pd)
        return np.clip(tau, -self.tau_max, self.tau_max)


def panda_table_times(T: float, repeats: int) -> None:
    """examples/13's table, the issue's five controllers (its rows pd, sf, of, ct,
    ct+30 on the default table): each natively and behind a Python object."""
    import importlib.util

    from adaptimp.scenarios import contact as act
    from adaptimp.scenarios import panda_table as apt

    path = Path(__file__).resolve().parent.parent / "examples" / "13_panda_table.py"
    spec = importlib.util.spec_from_file_location("panda_table_example", path)
    assert spec is not None
    assert spec.loader is not None
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    sc = act.arm_table()
    rule = act.rule_keywords(sc)
    plant = amj.Plant(sc.model)
    rows = {name: example.ROWS[name][0] for name in ("pd", "sf", "of", "ct", "ct+30")}
    times: dict[str, dict[str, list[float]]] = {
        k: {"native": [], "python": [], "before": [], "engine": []} for k in rows
    }
    loops: dict[str, str] = {}
    m, d = plant.model, plant.data
    substeps = max(1, round(sc.Ts / plant.timestep))
    full = int(mujoco.mjtState.mjSTATE_FULLPHYSICS)
    for _ in range(repeats):
        for kind in rows:
            for how in ("native", "python", "before"):
                if how == "before" and not kind.startswith("ct"):
                    # The rows the core stepped already: as called back.
                    times[kind]["before"].append(times[kind]["python"][-1])
                    continue
                ctrl = example.controller(kind, sc, rule)
                if how == "before" and kind.startswith("ct"):
                    law = PinocchioPDPlus(sc.pin_model, sc.tau_max, 1.3 if kind == "ct+30" else 1.0)
                    ctrl = adaptimp.CartesianController(
                        sc.chain, law, q0=sc.q0, path=sc.path, Kd_rot=0.0,
                        force_feedforward=False, formulation="impedance",
                    )  # fmt: skip
                start = time.perf_counter()
                res = amj.simulate(
                    ctrl if how == "native" else InPython(ctrl), plant, T=T, q0=sc.q0
                )
                apt.cartesian_metrics(res, ctrl, sc, settle=min(2.0, T / 2))
                times[kind][how].append(time.perf_counter() - start)
                if how == "native":
                    loops[kind] = res.params["loop"]
            # MuJoCo alone on the same motion: the run's torques through mujoco.rollout.
            plant.reset(sc.q0)
            initial = np.zeros(mujoco.mj_stateSize(m, full))
            mujoco.mj_getState(m, d, initial, full)
            controls = np.repeat(res.tau_sat / plant._gear, substeps, axis=0)
            start = time.perf_counter()
            rollout.rollout(m, d, initial, controls)
            times[kind]["engine"].append(time.perf_counter() - start)
    print(
        f"\nthe Panda table (examples/13_panda_table.py's controllers, T = {T:g} s; "
        f"medians of {repeats}, s per controller: simulate and cartesian_metrics)"
    )
    print(
        "\n| controller | loop | native (s) | called back (s) | before (s) | native/Python | "
        "native/before | MuJoCo alone (s) |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    total = {"native": 0.0, "python": 0.0, "before": 0.0, "engine": 0.0}
    for kind, label in rows.items():
        med = {how: statistics.median(v) for how, v in times[kind].items()}
        for how in total:
            total[how] += med[how]
        print(
            f"| {label} | {loops[kind]} | {med['native']:.2f} | {med['python']:.2f} | "
            f"{med['before']:.2f} | {med['native'] / med['python']:.2f} | "
            f"{med['native'] / med['before']:.2f} | {med['engine']:.2f} |"
        )
    print(
        f"| all | | {total['native']:.2f} | {total['python']:.2f} | {total['before']:.2f} | "
        f"{total['native'] / total['python']:.2f} | {total['native'] / total['before']:.2f} | "
        f"{total['engine']:.2f} |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--T", type=float, default=10.0, help="run length (s)")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--sweep-T", type=float, default=2.0, help="sweep run length (s)")
    parser.add_argument("--table-T", type=float, default=20.0, help="Panda table run length (s)")
    parser.add_argument(
        "--only", default="loop,cartesian,table,sweep", help="which tables, comma-separated"
    )
    parser.add_argument("--before", default=None, help="the other build's Python package dir")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        print(json.dumps(build_rows(args.T)))
        return
    only = set(args.only.split(","))
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores "
        f"(load average {load}), "
        f"{platform.python_implementation()} {platform.python_version()}, "
        f"MuJoCo {mujoco.__version__}; T = {args.T:g} s at Ts = 1 ms; "
        f"medians of {args.repeats}, µs per control period"
    )
    rows = [(name, "joint") for name in ("UR5", "Panda") if "loop" in only]
    rows += [(name, kind) for kind in ("cartesian", "table") for name in ("UR5", "Panda")]
    rows = [(name, kind) for name, kind in rows if kind == "joint" or "cartesian" in only]
    if rows:
        loop_table(rows, args.T, args.repeats)
    if "table" in only:
        panda_table_times(args.table_T, max(1, args.repeats // 2))
    if "sweep" in only:
        sweep_table(args.sweep_T, args.repeats)
    if "builds" in only:
        if args.before is None:
            parser.error("--only builds needs --before DIR")
        builds_table(args.before, args.T, args.repeats)


class PythonPD:
    """Joint PD with gravity compensation written in Python, on a reference."""

    Ts = 1e-3

    def __init__(self) -> None:
        self.arm = adaptimp.TwoLinkArm()
        self.Kp, self.Kd = np.array([60.0, 40.0]), np.array([8.0, 5.0])

    def step(self, m: Any, **sp: Any) -> np.ndarray:
        q, dq = m.q, m.dq
        q = np.asarray(q)
        return np.asarray(self.arm.G(q) + self.Kp * (sp["xc"] - q) + self.Kd * (sp["dxc"] - dq))


def build_rows(T: float) -> dict[str, float]:
    """One measurement of each row of :func:`builds_table` in this process's
    build: µs per control period of ``simulate`` (construction not counted)."""
    from adaptimp.baselines import ComputedTorque

    out: dict[str, float] = {}

    def timed(key: str, ctrl: Any, plant: Any, **kw: Any) -> None:
        start = time.perf_counter()
        res = amj.simulate(ctrl, plant, T=T, **kw)
        out[key] = (time.perf_counter() - start) / res.rows * 1e6

    gc.disable()
    try:
        paper = amj.Plant("two_link", contact=False)
        for how in ("native", "python"):
            ctrl = adaptimp.Controller("sf", "paper")
            timed(f"paper SF/{how}", ctrl if how == "native" else PythonSide(ctrl), paper)
        for name in ("UR5", "Panda"):
            model, q0 = arm(name)
            plant = amj.Plant(model)
            for how in ("native", "python"):
                ctrl = controller(plant, q0)
                side = ctrl if how == "native" else PythonSide(ctrl)
                timed(f"{name} SF joint/{how}", side, plant, q0=q0)
            plant, cart, q0 = cartesian(name)
            for how in ("native", "python"):
                cart.reset()
                side = cart if how == "native" else InPython(cart)
                timed(f"{name} SF Cartesian/{how}", side, plant, q0=q0)
        two = amj.Plant("two_link")
        ct = ComputedTorque(mass_scale=1.3)
        timed("two_link CT joint/native", ct, two)
        timed("two_link PD written in Python/python", PythonPD(), two, reference=amj.paper_circle())
    finally:
        gc.enable()
    for how in ("native", "python"):
        out[f"interrupt/{how}"] = interrupt_latency(how)
    return out


def interrupt_latency(how: str, after: float = 0.5) -> float:
    """Seconds from SIGINT to KeyboardInterrupt out of ``simulate`` with 10 000
    MuJoCo steps a period (the Panda on its table, SF natively or behind a
    Python object; the signal sent by a timer thread ``after`` s after the
    run's first progress report, inside the loop)."""
    import signal
    import threading

    model, q0 = arm("Panda")
    plant = amj.Plant(model)
    ctrl = controller(plant, q0)
    sent = [math.nan]

    def fire() -> None:
        sent[0] = time.perf_counter()
        os.kill(os.getpid(), signal.SIGINT)

    timer = threading.Timer(after, fire)

    def started(done: int, total: int) -> None:
        if not timer.is_alive() and math.isnan(sent[0]):
            timer.start()

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        side = ctrl if how == "native" else PythonSide(ctrl)
        amj.simulate(side, plant, T=60.0, q0=q0, substeps=10_000, progress=started)
    except KeyboardInterrupt:
        return time.perf_counter() - sent[0]
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    return math.nan


BUILD_ROWS = (
    ("paper SF", "the paper's arm, SF, Ts = 50 µs, 1 MuJoCo step"),
    ("UR5 SF joint", "UR5, SF, joint space, 1 MuJoCo step"),
    ("Panda SF joint", "Panda on its table, SF, joint space, 2 MuJoCo steps"),
    ("UR5 SF Cartesian", "UR5, SF behind the Cartesian impedance, path in Python"),
    ("Panda SF Cartesian", "Panda pressing on its table, SF behind the Cartesian impedance"),
    (
        "two_link CT joint",
        "the paper's arm at 1 kHz, computed torque (+30 % mass); before: the Python loop",
    ),
    ("two_link PD written in Python", "the paper's arm at 1 kHz, a PD written in Python"),
)


def builds_table(before: str, T: float, repeats: int) -> None:
    """:func:`build_rows` in this build and in the one at ``before``,
    alternating, each repeat in a fresh process of each; medians."""
    here = Path(__file__).resolve()
    runs: dict[str, dict[str, list[float]]] = {"before": {}, "after": {}}
    loads: list[float] = []
    for _ in range(repeats):
        for which in ("before", "after"):
            env = dict(os.environ)
            if which == "before":
                env["PYTHONPATH"] = os.pathsep.join(p for p in (before, env.get("PYTHONPATH")) if p)
            cmd = [sys.executable, str(here), "--child", "--T", str(T)]
            done = subprocess.run(cmd, env=env, check=True, capture_output=True, text=True)
            for key, us in json.loads(done.stdout.splitlines()[-1]).items():
                runs[which].setdefault(key, []).append(us)
            loads.append(os.getloadavg()[0])
    med = {w: {k: statistics.median(v) for k, v in r.items()} for w, r in runs.items()}
    print(
        f"\nthis build against {before}, T = {T:g} s per run, medians of {repeats} (alternating "
        f"processes; load average {min(loads):.1f}–{max(loads):.1f}), µs per control period:"
    )
    print(
        "\n| row | native before | native now | now/before | in Python before "
        "| in Python now | now/before |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|")

    def cell(which: str, key: str) -> str:
        v = med[which].get(key)
        return "—" if v is None else f"{v:.1f}"

    def ratio(key: str) -> str:
        a, b = med["after"].get(key), med["before"].get(key)
        return "—" if a is None or b is None else f"{a / b:.2f}"

    for key, label in BUILD_ROWS:
        nat, py = f"{key}/native", f"{key}/python"
        print(
            f"| {label} | {cell('before', nat)} | {cell('after', nat)} | {ratio(nat)} | "
            f"{cell('before', py)} | {cell('after', py)} | {ratio(py)} |"
        )
    print(
        "\nCtrl-C: s from SIGINT to KeyboardInterrupt, the Panda with 10 000 MuJoCo steps "
        "a period (about 0.3 s each):\n\n| controller | before | now |\n|---|---:|---:|"
    )
    for how, label in (("native", "SF, native"), ("python", "SF behind a Python object")):
        key = f"interrupt/{how}"
        print(f"| {label} | {med['before'][key]:.3f} | {med['after'][key]:.3f} |")


def _half(vary: dict[str, list[float]], T: float, part: int) -> None:
    """One process's share of the sweep: every other Kp, one thread."""
    share = {"Kp": vary["Kp"][part::2], "K1": vary["K1"]}
    adaptimp.sweep("sf", vary=share, plant="mujoco", T=T, threads=1)


def _cpu(who: int) -> float:
    """CPU seconds (user + system) used so far by this process or its children."""
    import resource

    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


def sweep_table(T: float, repeats: int) -> None:
    """Wall time and CPU time of the sweep: the CPU seconds tell whether the
    threads do more work than one thread (contention) independently of how
    much of the machine the other users leave (the wall time)."""
    import multiprocessing
    import resource

    vary = {"Kp": [7.0, 8.0, 9.0, 10.0], "K1": [4.0, 5.0, 6.0, 7.0]}
    labels = ("every core", "one thread", "two processes")
    times: dict[str, list[float]] = {k: [] for k in labels}
    cpu: dict[str, list[float]] = {k: [] for k in labels}
    loads: list[float] = []
    ctx = multiprocessing.get_context("fork")
    for _ in range(repeats):
        for label, threads in (("every core", None), ("one thread", 1)):
            c0, start = _cpu(resource.RUSAGE_SELF), time.perf_counter()
            df = adaptimp.sweep("sf", vary=vary, plant="mujoco", T=T, threads=threads)
            times[label].append(time.perf_counter() - start)
            cpu[label].append(_cpu(resource.RUSAGE_SELF) - c0)
            assert df["error"].isna().all(), df["error"].dropna().head()
        # The ceiling on this machine: two independent processes, half each.
        procs = [ctx.Process(target=_half, args=(vary, T, part)) for part in (0, 1)]
        c0, start = _cpu(resource.RUSAGE_CHILDREN), time.perf_counter()
        for p in procs:
            p.start()
        for p in procs:
            p.join()
        times["two processes"].append(time.perf_counter() - start)
        cpu["two processes"].append(_cpu(resource.RUSAGE_CHILDREN) - c0)
        loads.append(os.getloadavg()[0])
    med = {k: statistics.median(v) for k, v in times.items()}
    mcpu = {k: statistics.median(v) for k, v in cpu.items()}
    print(
        f"\nsweep(plant='mujoco'), 16 runs of T = {T:g} s on {os.cpu_count()} cores, "
        f"medians of {repeats} (load average over the repeats {min(loads):.1f}–{max(loads):.1f}):"
    )
    print("\n| how | wall (s) | speed-up | CPU (s) | CPU / wall (cores busy) |")
    print("|---|---:|---:|---:|---:|")
    for k in labels:
        print(
            f"| {k} | {med[k]:.2f} | {med['one thread'] / med[k]:.2f}× | {mcpu[k]:.2f} | "
            f"{mcpu[k] / med[k]:.2f} |"
        )


if __name__ == "__main__":
    main()
