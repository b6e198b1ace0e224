"""Your arm in five lines: a URDF or MJCF in, a figure and the metrics out (docs/your_arm.md).

The five lines a user writes::

    from adaptimp import mujoco as amj

    runs = {case: amj.simulate(case, "my_arm.urdf", T=10.0) for case in ("pd", "sf", "of")}
    for case, res in runs.items():
        print(case, res.metrics["rms_z1_after2"])
    runs["sf"].plot("tracking").savefig("my_arm.png")

``simulate`` given only the file (a URDF, or an MJCF as it ships: position
servos become torque motors of their force range, a gripper's joints are
locked, the end effector may be a body) fixes the gripper and any branch,
chooses a home posture inside the joint limits where gravity is well within
the effort limits and the swing keeps the arm off itself, a default task
(every joint swings ±0.2 rad at 0.5 Hz about it, from rest), and the gains,
the RBF centres and the learning rates by the rule of SPEC §18; nothing is
tuned per arm. This script does that and prints, per controller, the targets
of docs/your_arm.md: RMS ‖z1‖ over t ≥ 2 s and its ratio to PD's, the drift
check (the last 2 s against [2, 4) s), the peak commanded torque after 0.1 s
over τmax and the share of steps at a torque limit; with ``--payload`` it adds
a point mass (a fraction of the arm's moving mass) to the plant only and runs
computed torque with the exact and the nominal model on the same task.

    python examples/15_your_arm.py [FILE] [--payload 0.1] [--figure out/my_arm.png]
    python examples/15_your_arm.py [FILE] --tip tool0 --fix wrist_3_joint --home 0,-1,1,0,0,0
    python examples/15_your_arm.py [FILE] --long 600     # weight norms over 600 s
    python examples/15_your_arm.py FILE... --T 8 --rows [--json out.json]   # the docs' tables

Default URDF: the UR5 of example-robot-data. ``ADAPTIMP_QUICK=1``: T = 2.5 s.
On a terminal each run longer than 2 s shows a progress bar (the extra
``progress``: tqdm). A wrong argument, path, tip or joint name is one line
on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import os
import sys
import textwrap
import time
from pathlib import Path
from typing import Any, NoReturn

import mujoco
import numpy as np

import adaptimp
from adaptimp import Measurement, _models
from adaptimp import mujoco as amj

QUICK = os.environ.get("ADAPTIMP_QUICK") == "1"
PROGRESS = sys.stderr.isatty()
"""A progress bar for runs longer than 2 s, on a terminal only."""


class Parser(argparse.ArgumentParser):
    """A usage error is one line (``prog: error: …``), exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


def ur5() -> Path:
    """The UR5 of example-robot-data (the extra ``pinocchio``): the default arm,
    looked up only when no file is given (a given file needs only ``mujoco``)."""
    return _models.panda_urdf_path().parents[2] / "ur_description" / "urdf" / "ur5_robot.urdf"


def targets(res: Any) -> dict[str, float]:
    """RMS ‖z1‖ (t ≥ 2 s), over [2, 4) s and over the last 2 s (rad); peak
    commanded |τ_i|/τmax_i after 0.1 s; the largest applied |τ_i|/τmax_i; the
    share of steps with a torque at its limit."""
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
        "at_limit": float(res.metrics["sat_duty"]),
    }


def drift_ok(early: float, late: float) -> str:
    """ "yes" if the last 2 s are no worse than [2, 4) s, read as printed (to 3
    digits: 0.000106 and 0.000106 read "no" when the unprinted digits differed)."""
    return "yes" if float(f"{late:.3g}") <= float(f"{early:.3g}") else "no"


def table(
    path: Path, T: float, payload: float | None, arm: dict[str, Any], home: Any = None
) -> dict[str, Any]:
    """PD, SF and OF by the default route (``arm``: the Plant's ``tip``/``fix``;
    ``home`` the task's posture); with a payload fraction, computed torque with
    the exact and the nominal model through simulate's controller protocol on
    the SF run's reference (docs/your_arm.md)."""
    nominal = amj.Plant(path, **arm)
    kg = 0.0 if payload is None else payload * amj.moving_mass(nominal.model)
    runs = {
        case: amj.simulate(case, nominal, T=T, payload=kg, home=home, progress=PROGRESS)
        for case in ("pd", "sf", "of")
    }
    if payload is not None:
        from adaptimp.baselines import ComputedTorque

        sf = runs["sf"]
        for name, model_kg in (("CT exact", kg), ("CT nominal", 0.0)):
            ct = ComputedTorque(
                path, Ts=sf.params["Ts"], tau_max=sf.params["tau_max"], payload=model_kg, **arm
            )
            runs[name] = amj.simulate(
                ct, nominal, T=T, reference=sf, q0=sf.q[0], payload=kg, progress=PROGRESS
            )
    rows = {name: targets(res) for name, res in runs.items()}
    task = runs["pd"].params["task"]
    print(
        f"{path.name}: {nominal.n} joints {nominal.joint_names}, "
        f"τmax = {nominal.tau_max.tolist()} N m"
    )
    print(f"home posture (rad): {np.round(task['home'], 3).tolist()}; payload {kg:.3f} kg")
    pd = rows["pd"]["rms"]
    print(
        "| controller | RMS ‖z1‖, t ≥ 2 s (rad) | / PD | [2, 4) s | last 2 s | drift ok "
        "| peak τ/τmax | steps at a limit |"
    )
    print("|---|---:|---:|---:|---:|:-:|---:|---:|")
    for name, m in rows.items():
        print(
            f"| {name} | {m['rms']:.3g} | {m['rms'] / pd:.3f} | {m['early']:.3g} | "
            f"{m['late']:.3g} | {drift_ok(m['early'], m['late'])} | {m['peak']:.3f} | "
            f"{100 * m['at_limit']:.1f} % |"
        )
        assert m["applied"] <= 1.0 + 1e-12, "the applied torque stays within the limits"
    for name, res in runs.items():
        for text in res.params.get("warnings", []):
            print(f"  {name}: {text}")
    return {"runs": runs, "rows": rows, "payload": kg, "home": task["home"]}


def long_run(path: Path, seconds: float, arm: dict[str, Any], case: str = "sf") -> None:
    """The default route's controller for ``seconds`` of the default task in
    your own loop (Controller.step and MuJoCo's mj_step), with the weight norms and the
    largest commanded |τ_i|/τmax_i every so often."""
    plant = amj.Plant(path, **arm)
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
    print(f"{case} on {path.name}, {seconds:g} s of the default task:")
    print(
        "| t (s) | RMS ‖z1‖ since the row above (rad) | ‖W_D‖ | ‖W_C‖ | ‖W_G‖ | bound ‖W_G‖ "
        "| max commanded \\|τ_i\\|/τmax_i, t ≥ 0.1 s |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|")
    start = time.perf_counter()
    for k in range(steps):
        xc, dxc, ddxc = ref(k * ctrl.Ts)
        tau = ctrl.step(
            Measurement(plant.q, plant.dq, tau_e=np.zeros(n)), xc=xc, dxc=dxc, ddxc=ddxc
        )
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


def summary(path: Path, out: dict[str, Any]) -> str:
    """One markdown row of docs/your_arm.md's tables: the file, its joints, SF/PD,
    OF/PD, SF's drift ([2, 4) s → last 2 s), the peak commanded τ/τmax and the
    most steps at a limit over PD, SF, OF; with a payload, computed torque's
    RMS ‖z1‖ (nominal, exact) and SF's ratios to them."""
    rows, n = out["rows"], len(out["home"])
    pd = rows["pd"]["rms"]
    cases = [rows[c] for c in ("pd", "sf", "of")]
    cells = [
        f"`{path.parent.name}/{path.name}` ({n})",
        f"{pd:.3g}",
        f"{rows['sf']['rms'] / pd:.3f}",
        f"{rows['of']['rms'] / pd:.3f}",
        f"{rows['sf']['early']:.3g} → {rows['sf']['late']:.3g}",
        f"{max(m['peak'] for m in cases):.2f}",
        f"{100 * max(m['at_limit'] for m in cases):.1f} %",
    ]
    if "CT nominal" in rows:
        sf, nom, exact = rows["sf"]["rms"], rows["CT nominal"]["rms"], rows["CT exact"]["rms"]
        cells += [f"{out['payload']:.3g}", f"{nom:.3g}", f"{exact:.3g}"]
        cells += [f"{sf / nom:.3f}", f"{exact / sf:.2f}"]
    return "| " + " | ".join(cells) + " |"


def main() -> None:
    doc = (__doc__ or "").split("\n\n")
    parser = Parser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(p for p in doc if p.startswith("    python")),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("paths", nargs="*", type=Path, help="URDF or MJCF files (default UR5)")
    parser.add_argument("--payload", type=float, default=None, help="fraction of the arm's mass")
    parser.add_argument(
        "--figure", type=Path, default=None, help="write SF's error figure of the arm run here"
    )
    parser.add_argument("--long", type=float, default=None, help="seconds of a long SF run")
    parser.add_argument("--tip", default=None, help="the end effector: a link, body or site")
    parser.add_argument("--fix", default="", help="joints to lock, comma-separated")
    parser.add_argument("--home", default=None, help="the task's posture (rad), comma-separated")
    parser.add_argument("--T", type=float, default=None, help="duration (s), default 10")
    parser.add_argument("--json", type=Path, default=None, help="write the table's numbers")
    parser.add_argument("--rows", action="store_true", help="one summary row per file at the end")
    args = parser.parse_args()
    if not args.paths:
        try:
            args.paths = [ur5()]
        except ImportError as e:
            parser.error(f"no file given, and the default UR5 needs the extra pinocchio: {e}")
    paths = args.paths
    missing = [str(p) for p in paths if not p.is_file()]
    if missing:
        parser.error(f"no file {missing[0]!r}")
    arm: dict[str, Any] = {}
    if args.tip is not None:
        arm["tip"] = args.tip
    if args.fix:
        arm["fix"] = tuple(j.strip() for j in args.fix.split(",") if j.strip())
    home = None
    if args.home is not None:
        try:
            home = [float(x) for x in args.home.split(",")]
        except ValueError:
            parser.error(f"--home must be numbers (rad) separated by commas, got {args.home!r}")
    for option in ("json", "figure"):
        given = getattr(args, option)
        if given is not None and not given.resolve().parent.is_dir():
            parser.error(f"--{option}: no directory {str(given.parent)!r}")
    try:
        run(args, paths, arm, home)
    except (ImportError, OSError, ValueError) as e:
        # The extra pinocchio for --payload's computed torque; a file, a tip, a
        # joint or a posture the arm does not have (the message names it).
        parser.error(str(e))


def run(args: argparse.Namespace, paths: list[Path], arm: dict[str, Any], home: Any) -> None:
    """The runs of the command line, printed (and written) as ``args`` say."""
    if args.long is not None:
        for path in paths:
            long_run(path, 1.0 if QUICK else args.long, arm)
        return
    T = 2.5 if QUICK else (args.T if args.T is not None else 10.0)
    records, lines = [], []
    for path in paths:
        out = table(path, T, args.payload, arm, home)
        lines.append(summary(path, out))
        records.append(
            {
                "file": str(path),
                "T": T,
                "payload_kg": out["payload"],
                "home": list(out["home"]),
                "rows": out["rows"],
                "warnings": {k: r.params.get("warnings", []) for k, r in out["runs"].items()},
                "plant": out["runs"]["pd"].params.get("plant", {}),
            }
        )
        if args.figure is not None:
            fig = out["runs"]["sf"].plot("errors")
            fig.savefig(args.figure, dpi=110)
            print(f"wrote {args.figure}")
    if args.rows:
        head = (
            "| file (joints) | PD (rad) | SF/PD | OF/PD | SF [2,4) → last 2 s | peak τ/τmax "
            "| at a limit |"
        )
        if args.payload is not None:
            head += " payload (kg) | CT nominal | CT exact | SF / CT nominal | CT exact / SF |"
        print(head)
        print("|" + "---|" * (head.count("|") - 1))
        print("\n".join(lines))
    if args.json is not None:
        import json

        args.json.write_text(json.dumps(records, indent=1, default=str))
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
