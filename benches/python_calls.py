"""The per-sample Python entry points against the core's calls behind them, and against
Pinocchio's Python calls for the same quantity.

For the UR5 and the Panda of example-robot-data, on the same 64 states (q, q̇,
q̈ seeded, within the joint limits), per call:

- ``Chain.fk(q)`` (4 × 4): the core's ``Chain::pose``; Pinocchio's
  ``forwardKinematics`` + ``updateFramePlacement``;
- ``Chain.jacobian(q)`` (6 × n): ``Chain::pose_jacobian``;
  ``computeFrameJacobian(…, LOCAL_WORLD_ALIGNED)``;
- ``Chain.jdot_qdot(q, dq)``: ``Chain::bias``; ``forwardKinematics(q, v, 0)`` +
  ``getFrameClassicalAcceleration``;
- ``ComputedTorque.inverse_dynamics``: ``Dynamics::inverse_dynamics``; ``rnea``;
- ``ComputedTorque.step`` (external mode): ``ComputedTorque::step``; (20.3)
  with ``rnea`` and NumPy; ``ct_step`` is ``step(m, xc, dxc, ddxc)`` on
  measurements made before, ``ct_step_measured`` makes ``m =
  adaptimp.Measurement(q, dq)`` in the loop too;
- ``CartesianController.step`` (SF, its path in Python): the core's Cartesian
  step (``CartesianImpedance.replay``, per row) plus the path's own calls;
  (20.7) with ``computeFrameJacobian`` and NumPy.

The Rust calls are timed by ``benches/peers.rs`` (built by ``cargo bench
--bench peers --no-run``; the rows ``fk``, ``pose_jacobian``, ``jdot_qdot``,
``rnea``, ``ct_step``) on the core's description of the same arm, in the
same rounds; the Cartesian step by the core's ``replay`` of the rows the
Python calls take (the outer loop and the joint step in a Rust loop). Each
round runs every measurement once, in turn; medians of ``--repeats`` rounds.
Targets (issue 32): a Python call at most 0.5 µs above the core's call, and
faster than Pinocchio's Python call for the same quantity (for the
Cartesian step, the law of SPEC (20.7) a user writes with Pinocchio: less
than the adaptive Cartesian step computes).

    python benches/python_calls.py [--repeats 7] [--calls 20000] [--arms ur5 panda] [--json FILE]
"""

from __future__ import annotations

import argparse
import gc
import json
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import peers

import adaptimp
from adaptimp import Measurement
from adaptimp.baselines import ComputedTorque

RUST = {
    "fk": "fk",
    "jacobian": "pose_jacobian",
    "jdot_qdot": "jdot_qdot",
    "inverse_dynamics": "rnea",
    "ct_step": "ct_step",
    "ct_step_measured": "ct_step",
}


def python_timers(name: str, states: list[tuple[Any, Any, Any]], calls: int) -> dict[str, Any]:
    """Per entry point: (the adaptimp call, Pinocchio's) as functions timing
    ``calls`` calls over the states, seconds per call."""
    import pinocchio as pin

    urdf, frame = peers.ARMS[name]
    path = peers.robots() / urdf
    model = peers.pinocchio_arm(path)
    data = model.createData()
    fid = model.getFrameId(frame)
    chain = adaptimp.Chain.from_urdf(path, tip=frame)
    n = chain.n
    ct = ComputedTorque(
        model, Ts=1e-3, Kp=1e3, Kd=40.0, tau_max=np.full(n, 1e3), impedance="external"
    )
    kp, kd, tau_max = ct.Kp, ct.Kd, ct.tau_max
    zero = np.zeros(n)
    k = len(states)
    rows = [states[i % k] for i in range(calls)]
    lwa = pin.LOCAL_WORLD_ALIGNED

    fk, jac, jdq = chain.fk, chain.jacobian, chain.jdot_qdot
    inv, step = ct.inverse_dynamics, ct.step
    fwd, place, frame_jac = (
        pin.forwardKinematics,
        pin.updateFramePlacement,
        pin.computeFrameJacobian,
    )
    accel, rnea, clip = pin.getFrameClassicalAcceleration, pin.rnea, np.clip

    # Each loop calls the entry point directly, as a user's loop does (no
    # wrapper in between): the loops differ only in the call.
    def fk_ours() -> None:
        for q, _, _ in rows:
            fk(q)

    def fk_pin() -> None:
        for q, _, _ in rows:
            fwd(model, data, q)
            place(model, data, fid)

    def jac_ours() -> None:
        for q, _, _ in rows:
            jac(q)

    def jac_pin() -> None:
        for q, _, _ in rows:
            frame_jac(model, data, q, fid, lwa)

    def jdq_ours() -> None:
        for q, dq, _ in rows:
            jdq(q, dq)

    def jdq_pin() -> None:
        for q, dq, _ in rows:
            fwd(model, data, q, dq, zero)
            accel(model, data, fid, lwa)

    def inv_ours() -> None:
        for q, dq, ddq in rows:
            inv(q, dq, ddq)

    def inv_pin() -> None:
        for q, dq, ddq in rows:
            rnea(model, data, q, dq, ddq)

    made = [(Measurement(q, dq), q, dq, ddq) for q, dq, ddq in rows]

    def step_ours() -> None:
        # The step alone, on measurements made before (the entry point's cost).
        for m, q, dq, ddq in made:
            step(m, q, dq, ddq)

    def step_measured() -> None:
        # The measurement made from the sensors' arrays each call, then the step.
        for q, dq, ddq in rows:
            step(Measurement(q, dq), q, dq, ddq)

    def step_pin() -> None:
        # (20.3), external mode, as a user writes it with Pinocchio and NumPy.
        for q, dq, ddq in rows:
            a = ddq + kd * (dq - dq) + kp * (q - q)
            clip(rnea(model, data, q, dq, a) + zero, -tau_max, tau_max)

    def timed(f: Callable[[], None]) -> Callable[[], float]:
        def run() -> float:
            gc.disable()
            start = time.perf_counter()
            f()
            seconds = time.perf_counter() - start
            gc.enable()
            return seconds / calls

        return run

    return {
        "fk": (timed(fk_ours), timed(fk_pin)),
        "jacobian": (timed(jac_ours), timed(jac_pin)),
        "jdot_qdot": (timed(jdq_ours), timed(jdq_pin)),
        "inverse_dynamics": (timed(inv_ours), timed(inv_pin)),
        "ct_step": (timed(step_ours), timed(step_pin)),
        "ct_step_measured": (timed(step_measured), timed(step_pin)),
    }


def cartesian_timers(
    name: str, calls: int
) -> tuple[dict[str, Callable[[], float]], dict[str, Any]]:
    """``CartesianController.step`` (SF, a 5 cm circle, rows of a native MuJoCo
    run) against the core's replay of the same rows, the path's own calls and
    the law of SPEC (20.7) written with Pinocchio; and the controller, its
    rows (q, q̇, F_e) and commanded poses (steps, 24)."""
    import pinocchio as pin

    from adaptimp import mujoco as amj
    from adaptimp import tuning

    urdf, frame = peers.ARMS[name]
    path = peers.robots() / urdf
    model = amj.from_urdf(path)
    plant = amj.Plant(model)
    chain = adaptimp.Chain.from_urdf(path, tip=frame)
    q0 = np.array(adaptimp._models.PANDA_HOME if name == "panda" else [0, -1.2, 1.2, -1.5, -1.5, 0])
    p0, r0 = chain.pose(q0)
    r, w = 0.05, np.pi

    def circle(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        c, s = np.cos(w * t), np.sin(w * t)
        return (
            p0 + r * np.array([c - 1.0, s, 0.0]),
            r * w * np.array([-s, c, 0.0]),
            -r * w * w * np.array([c, s, 0.0]),
        )

    outer = adaptimp.cartesian.CartesianImpedance(chain, Ts=1e-3, q0=q0, Kd_rot=0.0)
    centres, widths = outer.orbit_centres(circle, 2.0, nodes=64)
    kw = tuning.suggest(plant, q0, plant.tau_max, Ts=1e-3)
    kw.pop("n")
    ctrl = adaptimp.CartesianController(
        chain, "sf", q0=q0, path=circle, Kd_rot=0.0, centers=centres, widths=widths, **kw
    )
    log = amj.simulate(ctrl, plant, T=calls * 1e-3, q0=q0)
    assert log.task is not None
    ctrl.reset()
    targets = ctrl.commanded_poses(calls, None)
    wrenches = log.task["wrench"]
    rows = list(zip(log.q, log.dq, wrenches))

    pm = peers.pinocchio_arm(path)
    pd = pm.createData()
    fid = pm.getFrameId(frame)
    stiff = np.array([500.0] * 3 + [20.0] * 3)
    damp, lam = 2 * np.sqrt(stiff), 1e-4 * np.eye(6)

    def law(q: Any, dq: Any) -> Any:
        # SPEC (20.7) with Pinocchio and NumPy, as a user writes it.
        j = pin.computeFrameJacobian(pm, pd, q, fid, pin.LOCAL_WORLD_ALIGNED)
        x = pd.oMf[fid]
        e = np.concatenate([x.translation - p0, pin.log3(x.rotation @ r0.T)])
        t0 = 25.0 * (q0 - q) - 10.0 * dq
        f = -stiff * e - damp * (j @ dq)
        return j.T @ (f - np.linalg.solve(j @ j.T + lam, j @ t0)) + t0

    def python_calls() -> float:
        ctrl.reset()
        step = ctrl.step
        gc.disable()
        start = time.perf_counter()
        for q, dq, f in rows:
            step(Measurement(q, dq, wrench=f))
        seconds = time.perf_counter() - start
        gc.enable()
        return seconds / calls

    made = [Measurement(q, dq, wrench=f) for q, dq, f in rows]

    def python_before() -> float:
        # The same calls on measurements made before the loop.
        ctrl.reset()
        step = ctrl.step
        gc.disable()
        start = time.perf_counter()
        for m in made:
            step(m)
        seconds = time.perf_counter() - start
        gc.enable()
        return seconds / calls

    def rust() -> float:
        ctrl.reset()
        start = time.perf_counter()
        ctrl.outer.core.replay(ctrl.inner, log.q, log.dq, wrenches, targets)
        return (time.perf_counter() - start) / calls

    def path_calls() -> float:
        start = time.perf_counter()
        for k in range(calls):
            circle(k * 1e-3)
        return (time.perf_counter() - start) / calls

    def pinocchio() -> float:
        gc.disable()
        start = time.perf_counter()
        for q, dq, _ in rows:
            law(q, dq)
        seconds = time.perf_counter() - start
        gc.enable()
        return seconds / calls

    timers = {
        "python": python_calls,
        "python_before": python_before,
        "rust": rust,
        "path": path_calls,
        "pinocchio": pinocchio,
    }
    return timers, {"ctrl": ctrl, "rows": rows, "targets": targets}


def one(name: str, entry: str, calls: int) -> None:
    """``calls`` calls of ``entry`` (or none: ``"none"``, the setup alone), for
    callgrind: the setup of every entry runs, so two counts differ by the calls."""
    with tempfile.TemporaryDirectory() as tmp:
        arms = peers.write_arms(peers.arm_files([name], []), Path(tmp))
        states = read_states(arms[name][2])
    timers = python_timers(name, states, calls)
    cart, _ = cartesian_timers(name, calls)
    if entry == "none":
        return
    if entry.startswith("cartesian"):
        cart[entry.split(":")[1]]()
    else:
        side = 1 if entry.endswith(":pinocchio") else 0
        timers[entry.split(":")[0]][side]()


def read_states(path: Path) -> list[tuple[Any, Any, Any]]:
    text = path.read_text().split("\n")
    n = int(text[0].split()[1])
    out = []
    for line in text[1:]:
        if line.strip():
            x = np.array([float(v) for v in line.split()])
            out.append((x[:n], x[n : 2 * n], x[2 * n :]))
    return out


def count(name: str, entry: str, calls: int) -> float:
    """Instructions of a run of :func:`one` under callgrind."""
    import os
    import subprocess

    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cg"
        proc = subprocess.run(
            ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable,
             __file__, "--one", entry, "--arms", name, "--calls", str(calls)],
            capture_output=True, text=True, check=True,
            env={**os.environ, "OPENBLAS_NUM_THREADS": "1", "PYTHONHASHSEED": "0"},
        )  # fmt: skip
    for line in proc.stderr.splitlines():
        if "refs:" in line:
            return float(line.split()[-1].replace(",", ""))
    raise RuntimeError(f"callgrind gave no count for {entry}")


def counts(name: str, core: Path, calls: int = 2000) -> dict[str, dict[str, float]]:
    """Instructions per call: each entry point from Python, Pinocchio's Python
    call, and the core's call (the peers binary's ``measured_*`` rows; the
    Cartesian step's by the core's replay, the path's calls apart)."""
    with tempfile.TemporaryDirectory() as tmp:
        arms = peers.write_arms(peers.arm_files([name], []), Path(tmp))
        _, core_file, states_file, _ = arms[name]
        rust = peers.instructions(
            [str(core), str(core_file), str(states_file)], calls, tuple(RUST.values())
        )
    base = count(name, "none", calls)
    out: dict[str, dict[str, float]] = {}
    for key in RUST:
        out[key] = {
            "python": (count(name, key, calls) - base) / calls,
            "pinocchio": (count(name, f"{key}:pinocchio", calls) - base) / calls,
            "rust": rust[RUST[key]],
        }
    out["cartesian"] = {
        side: (count(name, f"cartesian:{side}", calls) - base) / calls
        for side in ("python", "python_before", "rust", "path", "pinocchio")
    }
    _split_cartesian(out)
    return out


def _split_cartesian(rows: dict[str, Any]) -> None:
    """The Cartesian step's row as two: ``cartesian`` (the measurement made
    in the loop) and ``cartesian_before`` (made before), the core's step, the
    path and Pinocchio's law the same."""
    e = rows["cartesian"]
    rows["cartesian_before"] = {**e, "python": e.pop("python_before")}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--calls", type=int, default=20000)
    ap.add_argument("--arms", nargs="+", default=["ur5", "panda"], choices=list(peers.ARMS))
    ap.add_argument("--json", type=Path)
    ap.add_argument("--count", action="store_true", help="also count instructions (callgrind)")
    ap.add_argument("--one", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        one(args.arms[0], args.one, args.calls)
        return
    core = peers.build_core()
    out: dict[str, Any] = {"machine": peers.machine()}
    with tempfile.TemporaryDirectory() as tmp:
        arms = peers.write_arms(peers.arm_files(args.arms, []), Path(tmp))
        for name, (_, core_file, states_file, _) in arms.items():
            states = read_states(states_file)
            timers = python_timers(name, states, args.calls)
            cart, _ = cartesian_timers(name, min(args.calls, 5000))
            got: dict[str, dict[str, list[float]]] = {
                k: {"python": [], "rust": [], "pinocchio": []} for k in [*timers, "cartesian"]
            }
            got["cartesian"]["path"] = []
            got["cartesian"]["python_before"] = []
            cmd = [str(core), str(core_file), str(states_file), "time", "20"]
            for _ in range(args.repeats):
                rust = peers.timings(peers.run(cmd))
                for key, (ours, theirs) in timers.items():
                    got[key]["python"].append(ours() * 1e9)
                    got[key]["pinocchio"].append(theirs() * 1e9)
                    got[key]["rust"].append(rust[RUST[key]])
                for key, f in cart.items():
                    got["cartesian"][key].append(f() * 1e9)
            out[name] = {
                k: {side: statistics.median(v) for side, v in d.items()} for k, d in got.items()
            }
            _split_cartesian(out[name])
    if args.count:
        for name in args.arms:
            for key, ir in counts(name, core).items():
                out[name].setdefault(key, {})
                out[name][key].update({f"{side}_ir": round(v) for side, v in ir.items()})
    print_table(out)
    if args.json:
        args.json.write_text(json.dumps(out, indent=1) + "\n")


def print_table(out: dict[str, Any]) -> None:
    m = out["machine"]
    print(f"\nmachine: {m['cpu']}, {m['cores']} cores, {m['system']}, load {m['load']}")
    print(
        "\n| arm | entry point | Python call | core's call | over it | Pinocchio (Python) "
        "| adaptimp ÷ Pinocchio |"
    )
    print("|---|---|---:|---:|---:|---:|---:|")
    for arm, rows in out.items():
        if arm == "machine":
            continue
        for key, e in rows.items():
            over = e["python"] - e["rust"] - e.get("path", 0.0)
            print(
                f"| {arm} | {key} | {e['python'] / 1e3:.3f} µs | {e['rust'] / 1e3:.3f} µs | "
                f"**{over / 1e3:+.3f} µs** | {e['pinocchio'] / 1e3:.3f} µs | "
                f"{e['python'] / e['pinocchio']:.2f} |"
            )
    print(
        "(cartesian: over = Python call − core's step − the path's own calls; the\n"
        " measurement made in the loop; cartesian_before: made before it)"
    )
    if any(
        "python_ir" in e
        for rows in out.values()
        if isinstance(rows, dict)
        for e in rows.values()
        if isinstance(e, dict)
    ):
        print(
            "\n| arm | entry point | Python call (Ir) | core's call (Ir) | over it "
            "| Pinocchio (Ir) |"
        )
        print("|---|---|---:|---:|---:|---:|")
        for arm, rows in out.items():
            if arm == "machine":
                continue
            for key, e in rows.items():
                if "python_ir" not in e:
                    continue
                over = e["python_ir"] - e["rust_ir"] - e.get("path_ir", 0)
                print(
                    f"| {arm} | {key} | {e['python_ir']:,} | {e['rust_ir']:,} | {over:+,} | "
                    f"{e['pinocchio_ir']:,} |"
                )


if __name__ == "__main__":
    main()
