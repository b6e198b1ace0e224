"""Your arm in five lines: a URDF in, a figure and the metrics out (docs/your_arm.md).

The five lines a user writes::

    from adaptimp import mujoco as amj

    runs = {case: amj.simulate(case, "my_arm.urdf", T=10.0) for case in ("pd", "sf", "of")}
    for case, res in runs.items():
        print(case, res.metrics["rms_z1_after2"])
    runs["sf"].plot("tracking").savefig("my_arm.png")

``simulate`` given only the URDF fixes the gripper and any branch, chooses a
home posture inside the joint limits where gravity is well within the effort
limits, a default task (every joint swings ±0.2 rad at 0.5 Hz about it, from
rest), and the gains, the RBF centres and the learning rates by the rule of
SPEC §18; nothing is tuned per arm. This script does that and prints, per
controller, the targets of docs/your_arm.md: RMS ‖z1‖ over t ≥ 2 s and its
ratio to PD's, the drift check (the last 2 s against [2, 4) s) and the peak
commanded torque after 0.1 s over τmax; with ``--payload`` it adds a point
mass (a fraction of the arm's moving mass) to the plant only and runs computed
torque with the exact and the nominal model on the same task.

    python examples/15_your_arm.py [URDF] [--payload 0.1] [--figure out.png]
    python examples/15_your_arm.py [URDF] --long 600     # weight norms over 600 s

Default URDF: the UR5 of example-robot-data. ``ADAPTIMP_QUICK=1``: T = 2.5 s.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

import adaptimp
from adaptimp import _models
from adaptimp import mujoco as amj

QUICK = os.environ.get("ADAPTIMP_QUICK") == "1"
UR5 = _models.panda_urdf_path().parents[2] / "ur_description" / "urdf" / "ur5_robot.urdf"


def targets(res: Any) -> dict[str, float]:
    """RMS ‖z1‖ (t ≥ 2 s), over [2, 4) s and over the last 2 s (rad); peak
    commanded |τ_i|/τmax_i after 0.1 s; the largest applied |τ_i|/τmax_i."""
    t, z = res.t, np.sum(res.z1**2, axis=1)
    end = t[-1] + (t[1] - t[0])

    def rms(a: float, b: float) -> float:
        return float(np.sqrt(np.mean(z[(t >= a - 1e-9) & (t < b - 1e-9)])))

    tau_max = np.asarray(res.params["tau_max"])
    return {
        "rms": res.metrics["rms_z1_after2"],
        "early": rms(2.0, 4.0),
        "late": rms(end - 2.0, end),
        "peak": float(np.max(np.abs(res.tau[t >= 0.1]) / tau_max)),
        "applied": float(np.max(np.abs(res.tau_sat) / tau_max)),
    }


def table(urdf: Path, T: float, payload: float | None) -> dict[str, Any]:
    """PD, SF and OF by the default route; with a payload fraction, computed
    torque with the exact and the nominal model through simulate's controller
    protocol on the SF run's reference (docs/your_arm.md)."""
    kg = 0.0
    if payload is not None:
        kg = payload * amj.moving_mass(amj.Plant(urdf).model)
    runs = {case: amj.simulate(case, urdf, T=T, payload=kg) for case in ("pd", "sf", "of")}
    if payload is not None:
        from adaptimp.baselines import ComputedTorque

        sf = runs["sf"]
        for name, model_kg in (("CT exact", kg), ("CT nominal", 0.0)):
            ct = ComputedTorque(
                urdf, Ts=sf.params["Ts"], tau_max=sf.params["tau_max"], payload=model_kg
            )
            runs[name] = amj.simulate(ct, urdf, T=T, reference=sf, q0=sf.q[0], payload=kg)
    rows = {name: targets(res) for name, res in runs.items()}
    task = runs["pd"].params["task"]
    print(f"{urdf.name}: {runs['pd'].q.shape[1]} joints, τmax = {runs['pd'].params['tau_max']} N m")
    print(f"home posture (rad): {np.round(task['home'], 3).tolist()}; payload {kg:.3f} kg")
    pd = rows["pd"]["rms"]
    print(
        "| controller | RMS ‖z1‖, t ≥ 2 s (rad) | / PD | [2, 4) s | last 2 s | drift ok "
        "| peak τ/τmax |"
    )
    print("|---|---:|---:|---:|---:|:-:|---:|")
    for name, m in rows.items():
        ok = "yes" if m["late"] <= m["early"] * (1 + 1e-9) else "no"  # (rounding: 1e-9)
        print(
            f"| {name} | {m['rms']:.3g} | {m['rms'] / pd:.3f} | {m['early']:.3g} | "
            f"{m['late']:.3g} | {ok} | {m['peak']:.3f} |"
        )
        assert m["applied"] <= 1.0 + 1e-12, "the applied torque stays within the limits"
    return runs


def long_run(urdf: Path, seconds: float, case: str = "sf") -> None:
    """The default route's controller for ``seconds`` of the default task in
    your own loop (Controller.step and MuJoCo's mj_step), with the weight norms and the
    largest commanded |τ_i|/τmax_i every so often."""
    plant = amj.Plant(urdf)
    task = amj.default_task(plant)
    kw = amj.rule_keywords(plant, task, case=case)
    n = kw.pop("n")
    ctrl = adaptimp.Controller(case, "robot", n=n, **kw)
    substeps = max(1, round(ctrl.Ts / plant.timestep))
    plant.timestep = ctrl.Ts / substeps
    plant.reset(task.q0)
    ref = task.reference
    steps = round(seconds / ctrl.Ts)
    marks = {round(s / ctrl.Ts) for s in (10, 30, 60, 120, 180, 300, 450, 600, seconds)}
    peak, z2sum, rows = 0.0, 0.0, 0
    print(f"{case} on {urdf.name}, {seconds:g} s of the default task:")
    print(
        "| t (s) | RMS ‖z1‖ since the row above (rad) | ‖W_D‖ | ‖W_C‖ | ‖W_G‖ | bound ‖W_G‖ "
        "| max commanded \\|τ_i\\|/τmax_i, t ≥ 0.1 s |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|")
    start = time.perf_counter()
    for k in range(steps):
        xc, dxc, ddxc = ref(k * ctrl.Ts)
        tau = ctrl.step(plant.q, np.zeros(n), plant.dq, xc=xc, dxc=dxc, ddxc=ddxc)
        if k * ctrl.Ts >= 0.1:
            peak = max(peak, float(np.max(np.abs(ctrl.tau) / plant.tau_max)))
        z2sum += float(np.sum(ctrl.z1**2))
        rows += 1
        # The motors' limits, then MuJoCo's steps of the period (the torque held).
        plant.data.ctrl[plant._act] = np.clip(tau, -plant.tau_max, plant.tau_max) / plant._gear
        mujoco.mj_step(plant.model, plant.data, nstep=substeps)
        if k + 1 in marks:
            w = ctrl.weights
            norms = [float(np.linalg.norm(w[net])) for net in ("D", "C", "G")]
            print(
                f"| {(k + 1) * ctrl.Ts:g} | {np.sqrt(z2sum / rows):.3g} | {norms[0]:.4g} | "
                f"{norms[1]:.4g} | {norms[2]:.4g} | {ctrl.weight_bound[2]:.4g} | {peak:.3f} |"
            )
            z2sum, rows = 0.0, 0
    print(f"({time.perf_counter() - start:.0f} s of wall time)")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("urdf", nargs="?", type=Path, default=UR5)
    parser.add_argument("--payload", type=float, default=None, help="fraction of the arm's mass")
    parser.add_argument("--figure", type=Path, default=None, help="write SF's tracking figure")
    parser.add_argument("--long", type=float, default=None, help="seconds of a long SF run")
    args = parser.parse_args()
    if args.long is not None:
        long_run(args.urdf, 1.0 if QUICK else args.long)
        return
    runs = table(args.urdf, 2.5 if QUICK else 10.0, args.payload)
    if args.figure is not None:
        fig = runs["sf"].plot("errors")
        fig.savefig(args.figure, dpi=110)
        print(f"wrote {args.figure}")


if __name__ == "__main__":
    main()
