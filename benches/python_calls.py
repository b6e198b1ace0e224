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
  with ``rnea`` and NumPy;
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
from adaptimp.baselines import ComputedTorque

RUST = {
    "fk": "fk",
    "jacobian": "pose_jacobian",
    "jdot_qdot": "jdot_qdot",
    "inverse_dynamics": "rnea",
    "ct_step": "ct_step",
}


def python_timers(name: str, states: list[tuple[Any, Any, Any]], calls: int) -> dict[str, Any]:
    """Per entry point: (the adaptimp call, Pinocchio's) as functions timing
    ``calls`` calls over the states, seconds per call."""
    import pinocchio as pin

    urdf, frame = peers.ARMS[name]
    path = peers.robots() / urdf
    model = peers.pinocchio_arm(name)
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

    def pin_ct(q: Any, dq: Any, ddq: Any) -> Any:
        # (20.3), external mode, as a user writes it with Pinocchio.
        a = ddq + kd * (dq - dq) + kp * (q - q)
        return np.clip(pin.rnea(model, data, q, dq, a) + zero, -tau_max, tau_max)

    def loop(f: Callable[[Any, Any, Any], Any]) -> Callable[[], float]:
        def run() -> float:
            gc.disable()
            start = time.perf_counter()
            for q, dq, ddq in rows:
                f(q, dq, ddq)
            seconds = time.perf_counter() - start
            gc.enable()
            return seconds / calls

        return run

    fk, jac, jdq = chain.fk, chain.jacobian, chain.jdot_qdot
    inv, step = ct.inverse_dynamics, ct.step
    return {
        "fk": (
            loop(lambda q, dq, ddq: fk(q)),
            loop(
                lambda q, dq, ddq: (
                    pin.forwardKinematics(model, data, q),
                    pin.updateFramePlacement(model, data, fid),
                )
            ),
        ),
        "jacobian": (
            loop(lambda q, dq, ddq: jac(q)),
            loop(lambda q, dq, ddq: pin.computeFrameJacobian(model, data, q, fid, lwa)),
        ),
        "jdot_qdot": (
            loop(lambda q, dq, ddq: jdq(q, dq)),
            loop(
                lambda q, dq, ddq: (
                    pin.forwardKinematics(model, data, q, dq, zero),
                    pin.getFrameClassicalAcceleration(model, data, fid, lwa),
                )
            ),
        ),
        "inverse_dynamics": (
            loop(lambda q, dq, ddq: inv(q, dq, ddq)),
            loop(lambda q, dq, ddq: pin.rnea(model, data, q, dq, ddq)),
        ),
        "ct_step": (
            loop(lambda q, dq, ddq: step(q, zero, dq, xc=q, dxc=dq, ddxc=ddq)),
            loop(pin_ct),
        ),
    }


def cartesian_timers(name: str, calls: int) -> dict[str, Callable[[], float]]:
    """``CartesianController.step`` (SF, a 5 cm circle, rows of a native MuJoCo
    run) against the core's replay of the same rows, the path's own calls and
    the law of SPEC (20.7) written with Pinocchio."""
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
    targets = ctrl._targets(calls, None)
    rows = list(zip(log.q, log.dq, log.task["wrench"]))

    pm = peers.pinocchio_arm(name)
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
            step(q, dq, f)
        seconds = time.perf_counter() - start
        gc.enable()
        return seconds / calls

    def rust() -> float:
        ctrl.reset()
        start = time.perf_counter()
        ctrl.outer.core.replay(ctrl.inner, log.q, log.dq, log.task["wrench"], targets)
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

    return {"python": python_calls, "rust": rust, "path": path_calls, "pinocchio": pinocchio}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--calls", type=int, default=20000)
    ap.add_argument("--arms", nargs="+", default=["ur5", "panda"], choices=list(peers.ARMS))
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    core = peers.build_core()
    out: dict[str, Any] = {"machine": peers.machine()}
    with tempfile.TemporaryDirectory() as tmp:
        arms = peers.write_arms(args.arms, Path(tmp))
        for name, (_, core_file, states_file, _) in arms.items():
            text = states_file.read_text().split("\n")
            n = int(text[0].split()[1])
            states = []
            for line in text[1:]:
                if line.strip():
                    x = np.array([float(v) for v in line.split()])
                    states.append((x[:n], x[n : 2 * n], x[2 * n :]))
            timers = python_timers(name, states, args.calls)
            cart = cartesian_timers(name, min(args.calls, 5000))
            got: dict[str, dict[str, list[float]]] = {
                k: {"python": [], "rust": [], "pinocchio": []} for k in [*timers, "cartesian"]
            }
            got["cartesian"]["path"] = []
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
    print("(cartesian: over = Python call − core's step − the path's own calls)")


if __name__ == "__main__":
    main()
