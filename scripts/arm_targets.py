"""The Cartesian task's and the table's targets on arms that are not in this
repository (docs/cartesian.md, docs/contact.md): one command for every table
those pages give, nothing set per arm.

1. **The default Cartesian task** (``amj.cartesian_task(PATH)``, then
   ``amj.simulate("pd"|"sf", PATH, T=12, task=task)``; SPEC (16.8)–(16.13)):
   σmin(J) at the start ≥ 0.05; SF's position and orientation RMS over t ≥ 2 s
   ≤ 0.2× PD's; SF's position RMS over the last 2 s ≤ 0.5× its RMS over
   [2, 4) s; the peak commanded |τ_i|/τmax_i ≤ 1.
2. **The table at the maker's ready posture** (``python
   examples/13_panda_table.py --arm PATH --home … --T 10 --rows pd,sf,of``):
   some SF row with force RMS error ≤ 10 % of the target, chatter ≤ 5 %,
   never off the table, tracking ≤ 1 mm, peak commanded torque ≤ 2 τmax, no
   saturation. A ready posture the table cannot run is refused by name before
   the run (the refusal is the row).
3. **Drawn placements** (``… --placements 8 --T 10 --rows sf``): homes drawn
   within the joint limits that the rule accepts, each run to the same
   targets.
4. **Postures refused by name** (singular, out of reach, the arm below the
   table, the rule's gains ringing on the path): the message the user gets
   before anything runs.

The arms: example-robot-data's URDFs (installed with the extra ``pinocchio``),
robosuite's MJCF arms (``robot.xml``, no gripper), dm_control's Kinova Jaco
and rtb-data's Puma 560 and KUKA KR16, found as installed packages or under
``--robots DIR`` (a directory holding those packages' files, e.g. unpacked
wheels: DIR/robosuite/robosuite/…). An arm whose files are not found is left
out and said so; nothing is downloaded.

    python scripts/arm_targets.py [--robots DIR] [--only cartesian,ready,placements,refusals]
                                  [--arms SUBSTRING,...] [--json out.json] [--check]

Prints one Markdown table per part (the tables of docs/cartesian.md and
docs/contact.md). About 25 min on one core for every part and arm; the
Cartesian table alone about 1 min. ``--check``: the Cartesian rows printed
must be docs/cartesian.md's, cell for cell (exit status 1 and the rows that
differ otherwise); ``tests/test_doc_numbers.py`` checks the rows of
example-robot-data's arms so in every test run.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import math
import subprocess
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE13 = ROOT / "examples" / "13_panda_table.py"
PI = math.pi


@dataclass(frozen=True)
class Arm:
    """An arm file: where it is found, its maker's ready posture (rad) and
    where that posture comes from."""

    label: str
    package: str  # "erd", "robosuite", "dm_control", "rtbdata"
    path: str  # below the package's robot directory
    home: tuple[float, ...] | None = None
    home_source: str = ""
    placements: bool = False
    gripper: str | None = None  # robosuite's gripper attached at right_hand (Cartesian only)


UR_HOME = (0.0, -PI / 2, PI / 2, -PI / 2, -PI / 2, 0.0)
KINOVA_HOME = (4.80 - 2 * PI, 2.92, 1.00, 4.19 - 2 * PI, 1.44, 1.31)
RS = "robosuite's init_qpos"
ARMS = (
    Arm("Panda (ERD)", "erd", "panda_description/urdf/panda.urdf",
        (0.0, -PI / 4, 0.0, -3 * PI / 4, 0.0, PI / 2, PI / 4), "Franka's ready", True),
    Arm("UR3 (ERD)", "erd", "ur_description/urdf/ur3_robot.urdf", UR_HOME, "UR's home", True),
    Arm("UR5 (ERD)", "erd", "ur_description/urdf/ur5_robot.urdf", UR_HOME, "UR's home", True),
    Arm("UR10 (ERD)", "erd", "ur_description/urdf/ur10_robot.urdf", UR_HOME, "UR's home", True),
    Arm("xArm7 (ERD)", "erd", "xarm_description/urdf/xarm7.urdf",
        (0.0, 0.0, 0.0, 0.39 * PI, 0.0, 0.39 * PI, 0.0), "robosuite's init_qpos", True),
    Arm("Kinova (ERD)", "erd", "kinova_description/robots/kinova.urdf", KINOVA_HOME,
        "Kinova's home", True),
    Arm("Unitree Z1 (ERD)", "erd", "z1_description/urdf/z1.urdf",
        (0.0, 1.5, -1.0, -0.54, 0.0, 0.0), "Unitree's", True),
    Arm("SO-100 (ERD, 5 joints)", "erd", "so_arm_description/urdf/so100.urdf", placements=True),
    Arm("iiwa (robosuite)", "robosuite", "iiwa/robot.xml",
        (0.0, 0.65, 0.0, -1.89, 0.0, 0.6, 0.0), RS),
    Arm("Jaco (robosuite)", "robosuite", "jaco/robot.xml",
        (3.192, 3.680, 0.0, 1.170, 0.050, 3.760, 3.142), RS),
    Arm("Kinova Gen3 (robosuite)", "robosuite", "kinova3/robot.xml",
        (0.0, 0.65, 0.0, 1.89, 0.0, 0.6, -PI / 2), RS),
    Arm("Panda (robosuite)", "robosuite", "panda/robot.xml",
        (0.0, PI / 16, 0.0, -PI / 2 - PI / 3, 0.0, PI - 0.2, PI / 4), RS),
    Arm("Sawyer (robosuite)", "robosuite", "sawyer/robot.xml",
        (0.0, -1.18, 0.0, 2.18, 0.0, 0.57, -1.57), RS),
    Arm("UR5e (robosuite)", "robosuite", "ur5e/robot.xml",
        (-0.470, -1.735, 2.480, -2.275, -1.590, -1.991), RS),
    Arm("xArm7 (robosuite)", "robosuite", "xarm7/robot.xml",
        (0.0, 0.0, 0.0, 0.39 * PI, 0.0, 0.39 * PI, 0.0), RS),
    Arm("Spot arm (robosuite)", "robosuite", "spot_arm/robot.xml"),
    Arm("Jaco + three-finger gripper (robosuite)", "robosuite", "jaco/robot.xml",
        gripper="jaco_three_finger_gripper"),
    Arm("Panda + Panda gripper (robosuite)", "robosuite", "panda/robot.xml",
        gripper="panda_gripper"),
    Arm("Sawyer + Rethink gripper (robosuite)", "robosuite", "sawyer/robot.xml",
        gripper="rethink_gripper"),
    Arm("UR5e + Robotiq 140 (robosuite)", "robosuite", "ur5e/robot.xml",
        gripper="robotiq_gripper_140"),
    Arm("Kinova Jaco (dm_control)", "dm_control", "kinova/jaco_arm.xml", KINOVA_HOME,
        "Kinova's home"),
    Arm("Puma 560 (rtb-data)", "rtbdata", "unimation_puma560_description/urdf/puma560_robot.urdf"),
    Arm("KUKA KR16 (rtb-data)", "rtbdata", "kuka_description/kuka_kr16/urdf/kr16_2.urdf"),
)  # fmt: skip
"""The makers' ready postures: Franka's documented ready pose, the UR
family's and Kinova's home positions, robosuite's ``init_qpos`` (its arm
classes), Unitree's Z1 ready pose (folded, the tool forward)."""

REFUSALS = (
    ("UR5 (ERD)", (0.0, -PI / 2, 0.0, -PI / 2, 0.0, 0.0), "upright"),
    ("Panda (ERD)", (0.0, 0.0, 0.0, -0.07, 0.0, 0.0, 0.0), "upright"),
    ("Kinova (ERD)", (0.0, PI, PI, 0.0, PI, 0.0), "stretched up"),
    (
        "xArm7 (ERD)",
        (3.953, 0.742, 3.550, 0.659, 3.739, -0.706, -5.175),
        "joints 1 and 3 in line on the circle",
    ),
)
"""Postures a table cannot run at, and what they are."""

# Below the package directory, where each package keeps its robots.
WITHIN = {
    "robosuite": "models/assets/robots",
    "dm_control": "third_party",
    "rtbdata": "xacro",
}


def package_dir(name: str, robots: Path | None) -> Path | None:
    """An installed package's directory, or ``robots/name/name`` (an unpacked
    wheel) or ``robots/name``; the package is located, not imported."""
    if robots is not None:
        for cand in (robots / name / name, robots / name, *robots.glob(f"*/{name}")):
            if (cand / "__init__.py").is_file():
                return cand
    spec = importlib.util.find_spec(name)
    if spec is not None and spec.origin is not None:
        return Path(spec.origin).parent
    return None


def locate(arm: Arm, robots: Path | None) -> Path | None:
    """The arm's file, or None if its package is not found."""
    if arm.package == "erd":
        from adaptimp import _models

        base = _models.panda_urdf_path().parents[2]
    else:
        pkg = package_dir(arm.package, robots)
        if pkg is None:
            return None
        base = pkg / WITHIN[arm.package]
    path = base / arm.path
    return path if path.is_file() else None


def model_of(arm: Arm, path: Path) -> Any:
    """The file's path, or robosuite's arm with its gripper attached in memory
    at ``right_hand`` (as robosuite composes them, scripts/arms_with_grippers.py)."""
    if arm.gripper is None:
        return str(path)
    import mujoco

    from adaptimp import mujoco as amj

    spec = mujoco.MjSpec.from_file(str(path))
    grippers = path.parents[2] / "grippers"
    hand = mujoco.MjSpec.from_file(str(grippers / f"{arm.gripper}.xml"))
    spec.body("right_hand").add_frame().attach_body(hand.worldbody.first_body(), "gripper0_", "")
    return amj.Plant(spec)


def cartesian(model: Any, T: float) -> dict[str, Any]:
    """PD and SF on the arm's default Cartesian task: the row and its verdicts."""
    from adaptimp import mujoco as amj

    task = amj.cartesian_task(model)
    runs = {case: amj.simulate(case, model, T=T, task=task) for case in ("pd", "sf")}
    pd, sf = (runs[c].metrics for c in ("pd", "sf"))
    peak = max(
        float(np.max(np.abs(r.tau) / np.asarray(r.params["tau_max"]))) for r in runs.values()
    )
    row: dict[str, Any] = {
        "n": task.chain.n,
        "orients": task.orients,
        "q0": task.q0.tolist(),
        "sigma_min": float(task.assessment["sigma_min"]),
        "pd_pos_mm": pd["rms_pos_after2"] * 1e3,
        "sf_pos_mm": sf["rms_pos_after2"] * 1e3,
        "pd_rot_mrad": pd["rms_rot_after2"] * 1e3,
        "sf_rot_mrad": sf["rms_rot_after2"] * 1e3,
        "pos_ratio": sf["rms_pos_after2"] / pd["rms_pos_after2"],
        "rot_ratio": sf["rms_rot_after2"] / pd["rms_rot_after2"] if task.orients else None,
        "learning": sf["rms_pos_last2"] / sf["rms_pos_first2"],
        "peak_tau_ratio": peak,
    }
    row["pass"] = {
        "sigma_min": row["sigma_min"] >= 0.05,
        "pos": row["pos_ratio"] <= 0.2,
        "rot": (not task.orients) or row["rot_ratio"] <= 0.2,
        "learning": row["learning"] <= 0.5,
        "peak": peak <= 1.0,
    }
    return row


def cartesian_row(label: str, r: dict[str, Any]) -> str:
    """The Markdown row of docs/cartesian.md's table for the arm ``label``."""
    failed = [k for k, ok in r["pass"].items() if not ok]
    verdict = "met" if not failed else "NOT met: " + ", ".join(failed)
    return (
        f"| {label} | {r['n']} | {r['sigma_min']:.3f} | {r['pd_pos_mm']:.4f} "
        f"| {r['sf_pos_mm']:.4f} | {r['pos_ratio']:.3f} | {r['pd_rot_mrad']:.3f} "
        f"| {r['sf_rot_mrad']:.4f} | {fmt(r['rot_ratio'])} | {r['learning']:.3f} "
        f"| {r['peak_tau_ratio']:.3f} | {verdict} |"
    )


CARTESIAN_PAGE = ROOT / "docs" / "cartesian.md"


def documented_rows(page: Path = CARTESIAN_PAGE) -> dict[str, str]:
    """The rows of docs/cartesian.md's table of the default Cartesian task, by arm."""
    out = {}
    for line in page.read_text(encoding="utf-8").splitlines():
        label = line.split("|")[1].strip() if line.startswith("| ") else ""
        if any(a.label == label for a in ARMS):
            out[label] = line
    return out


def table_ok(r: dict[str, Any]) -> dict[str, bool]:
    """The table's targets for one row of examples/13's JSON."""
    target = r["force_target_N"]
    return {
        "force": r["force_rms_err_N"] <= 0.1 * target,
        "chatter": r["force_chatter_N"] <= 0.05 * target,
        "contact": r["contact_lost_s"] == 0.0,
        "track": r["track_mm"] <= 1.0,
        "peak": r["peak_tau_ratio"] <= 2.0,
        "saturation": r["sat_duty"] == 0.0,
    }


def example13(args: list[str]) -> tuple[dict[str, Any] | None, str]:
    """examples/13's JSON rows for these arguments, or None and its refusal."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "rows.json"
        proc = subprocess.run(
            [sys.executable, str(EXAMPLE13), *args, "--json", str(out)],
            capture_output=True,
            text=True,
            check=False,
        )
        if proc.returncode != 0 or not out.is_file():
            lines = [ln for ln in proc.stderr.splitlines() if "error" in ln.lower()]
            return None, (lines[-1] if lines else proc.stderr.strip()[-400:])
        return dict(json.loads(out.read_text())), ""


def home_text(q: tuple[float, ...]) -> str:
    return ",".join(repr(round(v, 6)) for v in q)


def fmt(v: float | None, digits: int = 3) -> str:
    return "—" if v is None else f"{v:.{digits}f}"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=Path, default=None, help="unpacked robot packages")
    parser.add_argument("--only", type=str, default="cartesian,ready,placements,refusals")
    parser.add_argument("--arms", type=str, default=None, help="labels containing one of these")
    parser.add_argument("--json", type=Path, default=None, help="write every figure here")
    parser.add_argument("--T", type=float, default=12.0, help="the Cartesian task's duration")
    parser.add_argument("--T-table", type=float, default=10.0, help="the table's duration")
    parser.add_argument("--placements", type=int, default=8)
    parser.add_argument(
        "--check", action="store_true", help="the Cartesian rows must be docs/cartesian.md's"
    )
    args = parser.parse_args()
    parts = set(args.only.split(","))
    known = {"cartesian", "ready", "placements", "refusals"}
    if not parts <= known:  # ran nothing and exited 0
        parser.error(
            f"--only: unknown part(s) {', '.join(sorted(parts - known))}; "
            f"choose from {', '.join(sorted(known))}"
        )
    picked = [
        a
        for a in ARMS
        if args.arms is None or any(s.lower() in a.label.lower() for s in args.arms.split(","))
    ]
    if not picked:
        parser.error(f"--arms {args.arms}: no arm's label contains it")
    found: dict[str, Path] = {}
    for arm in picked:
        path = locate(arm, args.robots)
        if path is None:
            print(f"(left out: {arm.label}, {arm.package} not found)", file=sys.stderr)
        else:
            found[arm.label] = path
    out: dict[str, Any] = {"cartesian": {}, "ready": {}, "placements": {}, "refusals": {}}
    warnings.simplefilter("ignore")

    documented, differ = documented_rows(), []
    if "cartesian" in parts:
        print(f"\n### The default Cartesian task, T = {args.T:g} s, metrics over t ≥ 2 s\n")
        print("| arm | n | σmin | PD pos (mm) | SF pos (mm) | SF/PD pos | PD rot (mrad) "
              "| SF rot (mrad) | SF/PD rot | last 2 s / [2, 4) | peak τ/τmax "
              "| targets |")  # fmt: skip
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
        for arm in picked:
            if arm.label not in found:
                continue
            t0 = time.perf_counter()
            try:
                r = cartesian(model_of(arm, found[arm.label]), args.T)
            except Exception as e:  # a row per arm, whatever happens
                row = f"| {arm.label} | refused or failed: {type(e).__name__}: {e} |"
                print(row)
                out["cartesian"][arm.label] = {"error": f"{type(e).__name__}: {e}"}
                if args.check and documented.get(arm.label) != row:
                    differ.append(f"documented: {documented.get(arm.label)}\nmeasured:   {row}")
                continue
            r["time_s"] = time.perf_counter() - t0
            out["cartesian"][arm.label] = r
            row = cartesian_row(arm.label, r)
            print(row, flush=True)
            if args.check and documented.get(arm.label) != row:
                differ.append(f"documented: {documented.get(arm.label)}\nmeasured:   {row}")

    if "ready" in parts:
        print(f"\n### The table at the maker's ready posture, T = {args.T_table:g} s\n")
        print("| arm | home | controller | track (mm) | force RMS err (N) | chatter (N) "
              "| contact lost (s) | peak τ/τmax | sat | targets |")  # fmt: skip
        print("|---|---|---|---:|---:|---:|---:|---:|---:|---|")
        for arm in picked:
            if arm.label not in found or arm.home is None:
                continue
            rows, refusal = example13(
                ["--arm", str(found[arm.label]), "--home", home_text(arm.home),
                 "--T", str(args.T_table), "--rows", "pd,sf,of"]
            )  # fmt: skip
            out["ready"][arm.label] = {"home": arm.home, "source": arm.home_source,
                                       "rows": rows, "refused": refusal}  # fmt: skip
            if rows is None:
                print(f"| {arm.label} | {arm.home_source} | refused | {refusal} |||||||")
                continue
            for name, r in rows.items():
                ok = table_ok(r)
                failed = [k for k, v in ok.items() if not v]
                verdict = "met" if not failed else "not: " + ", ".join(failed)
                print(
                    f"| {arm.label} | {arm.home_source} | {name} | {r['track_mm']:.3f} "
                    f"| {r['force_rms_err_N']:.3f} | {r['force_chatter_N']:.3f} "
                    f"| {r['contact_lost_s']:.3f} | {r['peak_tau_ratio']:.3f} "
                    f"| {r['sat_duty']:.3f} | {verdict} |",
                    flush=True,
                )

    if "placements" in parts:
        print(f"\n### {args.placements} drawn placements per arm, SF, T = {args.T_table:g} s "
              "(the worst of them per column)\n")  # fmt: skip
        print("| arm | placements | all targets met | track (mm) | force RMS err (N) "
              "| chatter (N) | contact lost (s) | peak τ/τmax | sat |")  # fmt: skip
        print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
        for arm in picked:
            if arm.label not in found or not arm.placements:
                continue
            rows, refusal = example13(
                ["--arm", str(found[arm.label]), "--placements", str(args.placements),
                 "--T", str(args.T_table), "--rows", "sf"]
            )  # fmt: skip
            out["placements"][arm.label] = {"rows": rows, "refused": refusal}
            if rows is None:
                print(f"| {arm.label} | refused: {refusal} ||||||||", flush=True)
                continue
            rs = list(rows.values())
            met = sum(all(table_ok(r).values()) for r in rs)
            worst = {k: max(r[k] for r in rs) for k in
                     ("track_mm", "force_rms_err_N", "force_chatter_N", "contact_lost_s",
                      "peak_tau_ratio", "sat_duty")}  # fmt: skip
            print(
                f"| {arm.label} | {len(rs)} | {met} | {worst['track_mm']:.3f} "
                f"| {worst['force_rms_err_N']:.3f} | {worst['force_chatter_N']:.3f} "
                f"| {worst['contact_lost_s']:.3f} | {worst['peak_tau_ratio']:.3f} "
                f"| {worst['sat_duty']:.3f} |",
                flush=True,
            )

    if "refusals" in parts:
        print("\n### Postures refused by name before the run\n")
        print("| arm | posture | refusal |")
        print("|---|---|---|")
        for label, home, what in REFUSALS:
            if label not in found:
                continue
            rows, refusal = example13(
                ["--arm", str(found[label]), "--home", home_text(home), "--T", "2"]
            )
            out["refusals"][label] = {"home": home, "refused": refusal, "ran": rows is not None}
            print(f"| {label} | {what} ({home_text(home)}) | {refusal or 'NOT refused'} |")

    if args.json is not None:
        args.json.write_text(json.dumps(out, indent=1) + "\n")
        print(f"\nwrote {args.json}")
    if differ:
        print("\nrows that differ from docs/cartesian.md:\n" + "\n".join(differ), file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
