"""The Franka route (``adaptimp.franka``) through pylibfranka: the callback's time
from the state in to the torque out, and how each case tracks.

Against franky-sim's FR3 (a server of libfranka's protocol, MuJoCo behind it)
started here in a process of its own on a loopback address, at the posture
libfranka's examples start from, or against a robot (``--ip``: it moves!).
Per run: the callback's time from ``readOnce``'s return to ``writeOnce``'s
(p50, p99, max, µs), the share of cycles longer than 1 ms (the client was
late), and the tracking after 2 s against PD's (joint task: RMS ‖z1‖;
Cartesian task: position and orientation). Printed with the machine: its
cores and load average before and after the runs (the server shares the
machine: its wall-clock loop and the client compete for the cores).

``--simulate`` adds the library's own loop for comparison:
``adaptimp.mujoco.simulate(case, URDF, T=8, delay=1)`` (the plant's delay one
period, the arm with gravity) and on ``franka.plant(URDF)`` (the arm as the
controller acts on it on a Franka: no gravity); and the controllers the robot
route builds on franky-sim's own MuJoCo FR3 (rotor inertia, damping, friction
loss; gravity compensated) in the library's loop with one period of delay.

    python benches/franka_loop.py [--T 10] [--cases pd sf of] [--tasks joint cartesian]
                                  [--load 0.1] [--stretch] [--simulate] [--ip ADDRESS] [--json]
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from adaptimp import PlantWarning, franka
from adaptimp import mujoco as amj


def fr3_urdf() -> str:
    """franky-sim's own FR3 URDF."""
    spec = importlib.util.find_spec("franky_sim")
    if spec is None or spec.origin is None:
        raise SystemExit("franky-sim is not installed: pip install franky-sim (or give --urdf)")
    return str(Path(spec.origin).parent / "assets" / "fr3.urdf")


def stretch(k: int, t: float, state: Any) -> None:
    """1 % of the cycles stretched to 2–3 ms: the client sleeps 2.5 or 3.5 ms (the
    newest state is then 2 or 3 ms after the last)."""
    if k % 100 == 99:
        time.sleep(0.0025 if (k // 100) % 2 else 0.0035)


def one(args: argparse.Namespace, case: str, task: str, load: float) -> dict[str, Any]:
    hook = stretch if args.stretch else None
    if args.ip:
        res = franka.run(case, args.urdf, args.ip, T=args.T, task=task, start=franka.READY,
                         on_cycle=hook, coupled=args.coupled)  # fmt: skip
    else:
        with franka.Simulator(q0=franka.READY, load=load) as sim:
            res = franka.run(
                case, args.urdf, sim.ip, T=args.T, task=task, on_cycle=hook, coupled=args.coupled
            )
    m, p = res.metrics, res.params
    gaps = np.round(np.diff(res.t) / franka.PERIOD).astype(int)
    return {
        "case": case,
        "task": task,
        "load": load,
        "rows": res.rows,
        "rms": m["rms_z1_after2"],
        "pos": m.get("rms_pos_after2"),
        "rot": m.get("rms_rot_after2"),
        "p50": p["callback"]["p50"],
        "p99": p["callback"]["p99"],
        "max": p["callback"]["max"],
        "late": float(np.mean(gaps > 1)) if gaps.size else 0.0,
        "longest": p["cycles"]["longest"],
        "peak": float(np.max(np.abs(res.tau_sat[res.t >= 0.5]) / franka.TAU_MAX)),
    }


def franky_plant() -> amj.Plant:
    """franky-sim's own MuJoCo FR3 (its scene, built in this process, never
    served: rotor inertia, damping and friction loss on every joint, the hand's
    fingers locked) as a plant of the library's loop, its gravity compensated
    exactly, as franky-sim's server does."""
    import xml.etree.ElementTree as ET

    import mujoco
    from franky_sim.mujoco_simulator import MujocoSimulator

    sim = MujocoSimulator()
    sim.init()
    sim.add_robot()
    spec = mujoco.MjSpec.from_string(ET.tostring(sim.scene, encoding="unicode"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlantWarning)  # the fingers locked, said so
        plant = amj.Plant(spec, contact=False, tip="robot0_fr3_link7")
    plant.model.opt.gravity[:] = 0.0
    return plant


def twin(urdf: str, T: float, coupled: bool | None = None) -> list[dict[str, Any]]:
    """franka.setup's controllers (from the URDF, as the robot route builds them)
    on franky-sim's MuJoCo FR3 in the library's loop, one period of delay, from
    the ready posture: the robot route without the network and the wall clock."""
    out = []
    for task in ("joint", "cartesian"):
        row: dict[str, Any] = {"loop": f"franky-sim's MJCF FR3, delay=1, {task}"}
        for case in ("pd", "sf") if task == "cartesian" else ("pd", "sf", "of"):
            s = franka.setup(case, urdf, franka.READY, task=task, coupled=coupled)
            q0 = np.array(franka.READY)
            if task == "joint":
                ref = s.reference(round(T / franka.PERIOD))
                res = amj.simulate(s.controller, franky_plant(), T=T, reference=ref, q0=q0, delay=1)
                row[case] = res.metrics["rms_z1_after2"]
            else:
                res = amj.simulate(s.controller, franky_plant(), T=T, q0=q0, delay=1)
                s.task.measure(res)
                row[case] = (res.metrics["rms_pos_after2"], res.metrics["rms_rot_after2"])
        out.append(row)
    return out


def simulated(urdf: str, T: float, coupled: bool | None = None) -> list[dict[str, Any]]:
    """The library's own loop on the same arm: delay 1, with and without gravity."""
    out = []
    for label, model in (("URDF, delay=1", urdf), ("franka.plant(URDF), delay=1", None)):
        row: dict[str, Any] = {"loop": label, "warnings": []}
        for case in ("pd", "sf", "of"):
            plant = franka.plant(urdf) if model is None else model
            with warnings.catch_warnings():  # kept in the result, printed below
                warnings.simplefilter("ignore", PlantWarning)
                res = amj.simulate(case, plant, T=T, delay=1, coupled=coupled)
            row[case] = res.metrics["rms_z1_after2"]
            row["warnings"] += [f"{case}: {w}" for w in res.params["warnings"]]
        out.append(row)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--T", type=float, default=10.0, help="each run's duration (s)")
    parser.add_argument("--cases", nargs="+", default=["pd", "sf", "of"])
    parser.add_argument("--tasks", nargs="+", default=["joint", "cartesian"])
    parser.add_argument(
        "--load", type=float, help="also runs with a load on the hand: this share of the arm's mass"
    )
    parser.add_argument("--stretch", action="store_true", help="1 %% of the cycles 2–3 ms")
    parser.add_argument(
        "--coupled",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="the rule's inertia-shaped gains, SPEC (18.12) (the default of both tasks, "
        "libfranka's loop having a delay); --no-coupled: the diagonal gains of (18.1)",
    )
    parser.add_argument("--simulate", action="store_true", help="also the library's own loop")
    parser.add_argument("--ip", help="a robot's address instead of a simulator (it moves!)")
    parser.add_argument("--urdf", help="the arm's URDF (default: franky-sim's FR3)")
    parser.add_argument("--json", action="store_true", help="print the rows as JSON")
    args = parser.parse_args()
    args.urdf = args.urdf or fr3_urdf()
    load_before = os.getloadavg()
    loads = [0.0]
    if args.load is not None:
        loads.append(args.load * amj.moving_mass(franka.plant(args.urdf).model))
    rows = [
        one(args, case, task, load)
        for load in loads
        for task in args.tasks
        for case in args.cases
        if not (task == "cartesian" and case == "of")
    ]
    load_after = os.getloadavg()
    sim = simulated(args.urdf, 8.0, args.coupled) if args.simulate else []
    twins = twin(args.urdf, args.T, args.coupled) if args.simulate and not args.ip else []
    machine = {
        "cpus": os.cpu_count(),
        "machine": platform.machine(),
        "python": platform.python_version(),
        "load_before": [round(x, 2) for x in load_before],
        "load_after": [round(x, 2) for x in load_after],
    }
    if args.json:
        print(
            json.dumps({"machine": machine, "runs": rows, "simulate": sim, "twin": twins}, indent=1)
        )
        return
    print(
        f"{machine['cpus']} cores ({machine['machine']}), Python {machine['python']}; load "
        f"average (1, 5, 15 min) {machine['load_before']} before, {machine['load_after']} after"
    )
    print(f"T = {args.T:g} s, {'1 % of cycles 2–3 ms' if args.stretch else 'no stretched cycle'}")
    print(
        "| case | task | load (kg) | /PD (joint: ‖z1‖; Cartesian: position, orientation) "
        "| callback p50 / p99 / max (µs) | cycles > 1 ms | peak |τ|/τmax after 0.5 s |"
    )
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        pd = next(
            x
            for x in rows
            if x["case"] == "pd" and x["task"] == r["task"] and x["load"] == r["load"]
        )
        if r["task"] == "joint":
            ratio = f"{r['rms'] / pd['rms']:.3f} ({r['rms'] * 1e3:.3f} mrad)"
        else:
            ratio = (
                f"{r['pos'] / pd['pos']:.3f}, {r['rot'] / pd['rot']:.3f} "
                f"({r['pos'] * 1e3:.4f} mm, {r['rot'] * 1e3:.3f} mrad)"
            )
        print(
            f"| {r['case']} | {r['task']} | {r['load']:.2f} | {ratio} | {r['p50'] * 1e6:.0f} / "
            f"{r['p99'] * 1e6:.0f} / {r['max'] * 1e6:.0f} | {100 * r['late']:.2f} % "
            f"(longest {r['longest'] * 1e3:.0f} ms) | {r['peak']:.2f} |"
        )
    if sim:
        print("\nThe library's own loop on the same URDF (amj.simulate, T = 8 s):")
        print("| loop | PD ‖z1‖ (mrad) | SF/PD | OF/PD |\n|---|---|---|---|")
        for s in sim:
            print(
                f"| {s['loop']} | {s['pd'] * 1e3:.3f} | {s['sf'] / s['pd']:.3f} | "
                f"{s['of'] / s['pd']:.3f} |"
            )
        for s in sim:
            for w in s["warnings"]:
                print(f"  {s['loop']}, {w}")
    if twins:
        print(
            "\nThe same controllers on franky-sim's own MuJoCo FR3 in the library's loop "
            f"(T = {args.T:g} s):"
        )
        print("| loop | SF/PD | OF/PD |\n|---|---|---|")
        for s in twins:
            if isinstance(s["pd"], tuple):
                ratio = ", ".join(f"{a / b:.3f}" for a, b in zip(s["sf"], s["pd"]))
                print(f"| {s['loop']} (position, orientation) | {ratio} | |")
            else:
                print(f"| {s['loop']} | {s['sf'] / s['pd']:.3f} | {s['of'] / s['pd']:.3f} |")


if __name__ == "__main__":
    main()
