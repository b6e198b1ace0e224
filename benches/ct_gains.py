"""Computed torque's gains against SF with a payload (SPEC §20, "Gains"; issue
29's payload targets), on files as they ship.

Per file: SF by the default route with a payload of ``--payload`` (a fraction
of the arm's moving mass) at the last link, on the plant only; then computed
torque read from the same file (``ComputedTorque(PATH, ...)``: the core's arm
with the file's drive terms) with the exact model (``payload=kg``) and the
nominal one (``payload=0``), through the same loop on the SF run's
reference, for each choice of gains. RMS ‖z1‖ over t ≥ 2 s (rad), as
``examples/15_your_arm.py`` measures. The targets: SF ≤ 0.2 × CT nominal
and CT exact ≤ SF, with the same gains for both (one controller, two
models).

    python benches/ct_gains.py [FILE ...] [--T 8] [--payload 0.1] [--gains 400/40 rule ...]

Without files: example-robot-data's UR5, Panda and xArm7 URDFs, and the
MJCF arms of robosuite and dm_control where they are installed (their
paths in ``ARMS``; set ``ADAPTIMP_ROBOTS`` to the directory that holds the
unpacked ``robosuite`` and ``dm_control`` packages).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

import adaptimp.mujoco as amj
from adaptimp import _models
from adaptimp.baselines import ComputedTorque

ROBOTS = Path(os.environ.get("ADAPTIMP_ROBOTS", "/work/robots"))
ERD = _models.panda_urdf_path().parents[2]
ARMS = {
    "UR5": ERD / "ur_description/urdf/ur5_robot.urdf",
    "Panda": ERD / "panda_description/urdf/panda.urdf",
    "xArm7": ERD / "xarm_description/urdf/xarm7.urdf",
    "servo arm": Path(__file__).resolve().parents[1] / "tests/data/hobby_arm.urdf",
    **{
        f"robosuite {name}": ROBOTS / f"robosuite/robosuite/models/assets/robots/{d}/robot.xml"
        for name, d in (
            ("Panda", "panda"),
            ("iiwa", "iiwa"),
            ("Sawyer", "sawyer"),
            ("Kinova Gen3", "kinova3"),
            ("xArm7", "xarm7"),
            ("Jaco", "jaco"),
        )
    },
    "dm_control Kinova": ROBOTS / "dm_control/dm_control/third_party/kinova/jaco_arm.xml",
}


def gains(name: str, sf: Any) -> dict[str, Any]:
    """Kp and Kd of a named choice; ``sf`` is the SF run (its rule's gains)."""
    if name == "default":  # SPEC (20.8): K1², 2 K1
        return {}
    if name == "rule":
        # The rule's poles (SPEC §18): K1 and the velocity loop's m/Ts.
        ts = float(sf.params["Ts"])
        k1, a = min(50.0, 0.05 / ts), 0.25 / ts
        return {"Kp": k1 * a, "Kd": k1 + a}
    kp, kd = (float(x) for x in name.split("/"))
    return {"Kp": kp, "Kd": kd}


def rms(res: Any) -> float:
    return float(res.metrics["rms_z1_after2"])


def measure(path: Path, T: float, fraction: float, choices: list[str]) -> dict[str, Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plant = amj.Plant(path)
        kg = fraction * amj.moving_mass(plant.model)
        sf = amj.simulate("sf", plant, T=T, payload=kg)
        out: dict[str, Any] = {"n": plant.n, "payload": kg, "SF": rms(sf), "CT": {}}
        for choice in choices:
            row = {}
            for model, model_kg in (("exact", kg), ("nominal", 0.0)):
                ct = ComputedTorque(
                    path,
                    Ts=sf.params["Ts"],
                    tau_max=sf.params["tau_max"],
                    payload=model_kg,
                    **gains(choice, sf),
                )
                res = amj.simulate(ct, plant, T=T, reference=sf, q0=sf.q[0], payload=kg)
                row[model] = rms(res)
                row[f"{model}_gains"] = [ct.Kp.tolist(), ct.Kd.tolist()]
            out["CT"][choice] = row
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("files", nargs="*", type=Path)
    parser.add_argument("--T", type=float, default=8.0)
    parser.add_argument("--payload", type=float, default=0.1)
    parser.add_argument("--gains", nargs="+", default=["400/40", "default", "rule"])
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    files = {p.name: p for p in args.files} or {k: p for k, p in ARMS.items() if p.is_file()}
    table: dict[str, Any] = {}
    head = "| file (joints) | payload (kg) | SF | " + " | ".join(
        f"{g}: CT exact | CT nominal | SF/CT nom. | exact/SF" for g in args.gains
    )
    print(head + " |")
    print("|---|---:|---:|" + "---:|---:|---:|---:|" * len(args.gains))
    for name, path in files.items():
        try:
            got = measure(path, args.T, args.payload, args.gains)
        except Exception as e:  # a file this build cannot run: say so, go on
            print(f"| {name} | {type(e).__name__}: {e} |", file=sys.stderr)
            continue
        table[name] = got
        sf = got["SF"]
        cells = [f"{name} ({got['n']})", f"{got['payload']:.3g}", f"{sf:.3g}"]
        for g in args.gains:
            r = got["CT"][g]
            ok = (
                "" if math.isfinite(r["nominal"]) and sf <= 0.2 * r["nominal"] else "✗",
                "" if r["exact"] <= sf else "✗",
            )
            cells += [
                f"{r['exact']:.3g}",
                f"{r['nominal']:.3g}",
                f"{sf / r['nominal']:.3f}{ok[0]}",
                f"{r['exact'] / sf:.2f}{ok[1]}",
            ]
        print("| " + " | ".join(cells) + " |", flush=True)
    if args.json:
        args.json.write_text(json.dumps(table, indent=1, default=np.asarray) + "\n")


if __name__ == "__main__":
    main()
