"""Arms with their grippers, as robosuite composes them (docs/your_arm.md).

robosuite ships each arm (``models/assets/robots/<arm>/robot.xml``, torque
motors, the end effector the body ``right_hand``) apart from its grippers
(``models/assets/grippers/<gripper>.xml``, position servos, coupled fingers)
and attaches one to the other when it builds a scene. This does the same in
memory (``MjSpec.attach``), hands the spec to ``adaptimp.mujoco.simulate`` as
it is, and prints one row per pair as docs/your_arm.md tabulates them: SF/PD,
OF/PD, SF's drift, the peak commanded τ/τmax and the steps at a torque limit
(T = 8 s, free space, metrics over t ≥ 2 s). With ``--payload 0.1``, SF with
10 % of the moving mass at the hand, unknown to the controller.

    python scripts/arms_with_grippers.py ROBOSUITE_ASSETS [ARM:GRIPPER ...] [--T 8]

ROBOSUITE_ASSETS is robosuite's ``models/assets`` directory (``pip install
robosuite``; nothing is downloaded here).
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path

import mujoco
import numpy as np

from adaptimp import mujoco as amj

PAIRS = (
    "panda:panda_gripper",
    "panda:robotiq_gripper_140",
    "sawyer:rethink_gripper",
    "iiwa:robotiq_gripper_140",
    "jaco:jaco_three_finger_gripper",
    "kinova3:robotiq_gripper_140",
    "ur5e:robotiq_gripper_140",
    "xarm7:robotiq_gripper_140",
)


def composed(assets: Path, arm: str, gripper: str) -> mujoco.MjSpec:
    """robosuite's arm with its gripper attached at ``right_hand``."""
    spec = mujoco.MjSpec.from_file(str(assets / "robots" / arm / "robot.xml"))
    hand = mujoco.MjSpec.from_file(str(assets / "grippers" / f"{gripper}.xml"))
    spec.body("right_hand").add_frame().attach_body(hand.worldbody.first_body(), "gripper0_", "")
    return spec


def row(spec: mujoco.MjSpec, label: str, T: float) -> str:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        plant = amj.Plant(spec)
        runs = {case: amj.simulate(case, plant, T=T) for case in ("pd", "sf", "of")}
    t = runs["pd"].t
    rms = {c: r.metrics["rms_z1_after2"] for c, r in runs.items()}
    z = np.sum(runs["sf"].z1 ** 2, axis=1)
    early = np.sqrt(np.mean(z[(t >= 2.0) & (t < 4.0)]))
    late = np.sqrt(np.mean(z[t >= t[-1] - 2.0 + 1e-9]))
    peak = max(float(np.max(np.abs(r.tau[t >= 0.1]) / plant.tau_max)) for r in runs.values())
    limit = max(r.metrics["sat_duty"] for r in runs.values())
    said = sum(len(r.params["warnings"]) for r in runs.values())
    locked = len(plant.notes.get("locked", {}))
    del caught
    return (
        f"| {label} ({plant.n}; {locked} locked) | {rms['pd']:.3g} | {rms['sf'] / rms['pd']:.3f} "
        f"| {rms['of'] / rms['pd']:.3f} | {early:.3g} → {late:.3g} | {peak:.2f} "
        f"| {100 * limit:.1f} % | {said} |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("assets", type=Path, help="robosuite's models/assets directory")
    parser.add_argument("pairs", nargs="*", default=list(PAIRS), help="ARM:GRIPPER")
    parser.add_argument("--T", type=float, default=8.0, help="duration (s)")
    args = parser.parse_args()
    if not (args.assets / "robots").is_dir():
        parser.error(f"{str(args.assets)!r} has no robots/: give robosuite's models/assets")
    print(
        "| arm + gripper (joints; locked) | PD (rad) | SF/PD | OF/PD | SF [2,4) → last 2 s "
        "| peak τ/τmax | at a limit | run warnings |"
    )
    print("|---|---:|---:|---:|---|---:|---:|---:|")
    for pair in args.pairs:
        arm, _, gripper = pair.partition(":")
        try:
            spec = composed(args.assets, arm, gripper)
            print(row(spec, f"{arm} + {gripper}", args.T), flush=True)
        except ValueError as e:
            print(f"| {arm} + {gripper} | {e} |||||||", flush=True)


if __name__ == "__main__":
    main()
