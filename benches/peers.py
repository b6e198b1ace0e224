"""The core's kinematics and dynamics side by side with Pinocchio's, compiled against compiled.

For the Panda, the UR5 and the xArm7 of example-robot-data (the URDFs the core
reads), per call, each row on the same 64 states (q, q̇, q̈ seeded, within the
joint limits):

- ``pose_jacobian``: the tool frame's pose and its 6 × n world-aligned Jacobian
  (Pinocchio: ``computeFrameJacobian(…, LOCAL_WORLD_ALIGNED)``, which also
  places the frame);
- ``jdot_qdot``: the frame's classical acceleration at q̈ = 0, J̇ q̇
  (``forwardKinematics(q, v, 0)`` + ``getFrameClassicalAcceleration``);
- ``rnea``: τ = M q̈ + C q̇ + G;
- ``crba``: the mass matrix (Pinocchio fills its upper triangle; the core the
  whole matrix);
- ``impedance``: the libfranka-style Cartesian impedance law of SPEC (20.7),
  τ = Jᵀ(−K e − D J q̇) + (I − Jᵀ (J Jᵀ + Λ²)⁻¹ J)(k_n (q_n − q) − d_n q̇) with
  the core's pose error e = [p − p_d; Log(R R_dᵀ)], pose and Jacobian included
  (Pinocchio with Eigen's 6 × 6 Cholesky).

The peer is ``benches/peers/peers.cpp``, built with g++ -O3 against the
``libpinocchio_default`` of the ``pin`` wheel (its headers and Boost from the
wheels, Eigen from ``libeigen3-dev``); the model is Pinocchio's parse of the
URDF, written by ``Model.saveToText``. The core's side is
``benches/peers.rs`` (``cargo bench --bench peers --no-run``), on the core's
description of the same model. Neither build asks for a CPU beyond x86-64.

First the two sides must agree on every value of every row to 1e-12 (of the
row's largest magnitude, at least 1) on every state, or the script stops.
Then ``--rounds`` rounds, each running the peer's and the core's program in
turn (the order alternating), each timing every row for ``--ms`` ms; the
medians of the rounds per side, and the ratio core ÷ Pinocchio. Then the
instructions per call, counted by ``valgrind --tool=callgrind`` inside each
row's ``measured_*`` function (2 000 calls), exact whatever the load. Then
the MuJoCo loop: ``benches/mujoco_user_loop.py`` (``--no-mujoco`` skips it).

    python benches/peers.py [--json FILE] [--rounds 7] [--ms 30] [--arms panda ur5 xarm7]
        [--no-count] [--no-mujoco] [--check]

``--check`` builds both sides and checks the agreement only (no timing).
``--json`` writes ``{arm: {row: {"core_ns", "peer_ns", "ratio", "core_ir",
"peer_ir", "ir_ratio"}}}`` (plus ``"machine"``), the MuJoCo loop as the arm
``"mujoco"``, rows ``"cartesian_loop_ur5"`` and ``"cartesian_loop_panda"``
(``benches/mujoco_user_loop.py``: adaptimp's native Cartesian SF loop against
the operational-space loop a MuJoCo user writes in Python, per period).
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import os
import platform
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
ROWS = ("pose_jacobian", "jdot_qdot", "rnea", "crba", "impedance")
# URDF under example-robot-data's robots/, and the tool frame.
ARMS = {
    "panda": ("panda_description/urdf/panda.urdf", "panda_hand_tcp"),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "tool0"),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", "link_eef"),
}
STATES = 64
CALLS = 2000
TOLERANCE = 1e-12


def robots() -> Path:
    dist = importlib.metadata.distribution("example-robot-data")
    return Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))


def pin_prefix() -> Path:
    return Path(str(importlib.metadata.distribution("pin").locate_file("cmeel.prefix")))


def target_dir() -> Path:
    return Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))


def machine() -> dict[str, Any]:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass

    def version(cmd: list[str]) -> str:
        try:
            out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
            return out.splitlines()[0]
        except (OSError, subprocess.CalledProcessError):
            return "?"

    import pinocchio

    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "system": f"{platform.system()} {platform.release()}",
        "load": [round(x, 2) for x in os.getloadavg()],
        "rustc": version(["rustc", "--version"]),
        "cxx": version(["g++", "--version"]),
        "pinocchio": pinocchio.__version__,
        "python": platform.python_version(),
    }


# --- the arms ----------------------------------------------------------------


def pinocchio_arm(urdf: Path) -> Any:
    """Pinocchio's model of the arm's URDF (its gripper fixed by the core's
    reduction, as everywhere in adaptimp)."""
    from adaptimp.baselines import pinocchio_model

    return pinocchio_model(urdf)


def arm_files(names: list[str], urdfs: list[str]) -> dict[str, tuple[Path, str]]:
    """The arms to run: the named ones (:data:`ARMS`) and each ``--urdf
    FILE[:FRAME]`` (a path, or one inside example-robot-data's ``robots/``;
    named by the file's stem; its tool frame FRAME, default
    the link that ends the arm as adaptimp reads the file, ``Chain.from_urdf``'s
    tip)."""
    out: dict[str, tuple[Path, str]] = {
        name: (robots() / ARMS[name][0], ARMS[name][1]) for name in names
    }
    for spec in urdfs:
        file, _, frame = spec.rpartition(":") if ":" in spec else (spec, "", "")
        if not Path(file).suffix:  # the colon was the path's own (no frame given)
            file, frame = spec, ""
        path = Path(file)
        if not path.is_file() and (robots() / file).is_file():
            path = robots() / file  # a path inside example-robot-data's robots/
        if not path.is_file():
            raise SystemExit(f"--urdf {spec}: no such file {file!r}")
        if not frame:
            from adaptimp._description import read_arm

            frame = read_arm(path, None, ()).tip
        elif not pinocchio_arm(path).existFrame(frame):  # an IndexError after the build
            raise SystemExit(
                f"--urdf {spec}: the file has no link or frame {frame!r}; give one of its "
                "links (FILE:LINK), or no frame for the link that ends the arm"
            )
        if path.stem in out:
            raise SystemExit(
                f"--urdf {spec}: an arm named {path.stem!r} already runs "
                f"({out[path.stem][0]}); leave it out of --arms, or copy the file "
                "under another name"
            )
        out[path.stem] = (path, frame)
    return out


def core_lines(model: Any, frame: str) -> list[str]:
    """The core's description of ``model`` (``baselines.core_description``)
    and the tool frame as the chain's tip, as ``benches/peers.rs`` reads it."""
    from adaptimp.baselines import core_description

    joints, inertials, gravity = core_description(model)
    import pinocchio as pin

    body = model.existFrame(frame, pin.FrameType.BODY)
    fid = model.getFrameId(frame, pin.FrameType.BODY) if body else model.getFrameId(frame)
    if model.frames[fid].parentJoint != model.njoints - 1:
        raise SystemExit(f"the frame {frame!r} is not on the last joint")

    def numbers(*xs: Any) -> str:
        return " ".join(repr(float(x)) for x in np.concatenate([np.ravel(x) for x in xs]))

    lines = [
        f"joint {j['kind']} " + numbers(j["translation"], j["rotation"], j["axis"]) for j in joints
    ]
    lines += ["inertial " + numbers([i["mass"]], i["translation"], i["inertia"]) for i in inertials]
    tip = model.frames[fid].placement
    lines.append("tip " + numbers(tip.translation, tip.rotation))
    lines.append("gravity " + numbers(gravity))
    return lines


def states(model: Any, rng: np.random.Generator) -> list[str]:
    """``STATES`` rows of (q, q̇, q̈), the angles within the joints' limits
    (±π where a joint has none: a continuous joint, whose configuration in
    Pinocchio is (cos θ, sin θ), which the peer makes of θ)."""
    n = model.nv
    lo, hi = np.full(n, -np.pi), np.full(n, np.pi)
    for j in range(1, model.njoints):
        if model.nqs[j] == 1:
            iq, iv = model.idx_qs[j], model.idx_vs[j]
            lo[iv] = max(model.lowerPositionLimit[iq], -np.pi)
            hi[iv] = min(model.upperPositionLimit[iq], np.pi)
    rows = [f"{STATES} {n}"]
    for _ in range(STATES):
        x = np.concatenate([rng.uniform(lo, hi), rng.uniform(-2, 2, n), rng.uniform(-10, 10, n)])
        rows.append(" ".join(repr(float(v)) for v in x))
    return rows


def write_arms(
    arms: dict[str, tuple[Path, str]], where: Path
) -> dict[str, tuple[Path, Path, Path, str]]:
    """Per arm: Pinocchio's model file, the core's, the states and the frame."""
    out = {}
    rng = np.random.default_rng(20240601)
    for name, (urdf, tip) in arms.items():
        model = pinocchio_arm(urdf)
        frame = tip
        pin_file, core_file, states_file = (
            where / f"{name}.pinocchio.txt",
            where / f"{name}.core.txt",
            where / f"{name}.states.txt",
        )
        model.saveToText(str(pin_file))
        core_file.write_text("\n".join(core_lines(model, frame)) + "\n")
        states_file.write_text("\n".join(states(model, rng)) + "\n")
        out[name] = (pin_file, core_file, states_file, frame)
    return out


# --- building ----------------------------------------------------------------


def eigen_include() -> Path:
    for p in (Path("/usr/include/eigen3"), Path("/usr/local/include/eigen3")):
        if (p / "Eigen" / "Core").exists():
            return p
    if shutil.which("apt-get") and os.geteuid() == 0:
        print("Eigen's headers are missing: apt-get install -y libeigen3-dev", flush=True)
        subprocess.run(["apt-get", "install", "-y", "-q", "libeigen3-dev"], check=True)
        return Path("/usr/include/eigen3")
    raise SystemExit("the peer needs Eigen's headers: apt-get install libeigen3-dev")


def build_peer() -> Path:
    src = ROOT / "benches" / "peers" / "peers.cpp"
    out = target_dir() / "peers" / "peers"
    prefix = pin_prefix()
    if out.exists() and out.stat().st_mtime > src.stat().st_mtime:
        return out
    out.parent.mkdir(parents=True, exist_ok=True)
    cmd = [
        os.environ.get("CXX", "g++"),
        "-O3",
        "-DNDEBUG",
        "-std=c++17",
        # pinocchio_default's interface (its CMake package): the algorithms
        # are the library's explicit instantiations.
        "-DPINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION",
        "-DBOOST_MPL_LIMIT_LIST_SIZE=30",
        "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
        "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS",
        "-DBOOST_FUSION_INVOKE_MAX_ARITY=12",
        f"-I{prefix / 'include'}",
        f"-I{eigen_include()}",
        str(src),
        "-o",
        str(out),
        f"-L{prefix / 'lib'}",
        f"-Wl,-rpath,{prefix / 'lib'}",
        "-lpinocchio_default",
        "-lboost_serialization",
    ]
    print("building the peer (about a minute of g++):", " ".join(cmd[:3]), "…", flush=True)
    subprocess.run(cmd, check=True)
    return out


def build_core() -> Path:
    print("building the core's side: cargo bench --bench peers --no-run", flush=True)
    res = subprocess.run(
        ["cargo", "bench", "--bench", "peers", "--no-run", "--message-format=json"],
        cwd=ROOT,
        check=True,
        capture_output=True,
        text=True,
    )
    for line in res.stdout.splitlines():
        msg = json.loads(line)
        artifact = msg.get("reason") == "compiler-artifact" and msg["target"]["name"] == "peers"
        if artifact and msg.get("executable"):
            return Path(msg["executable"])
    raise SystemExit("cargo built no 'peers' bench executable")


# --- running -----------------------------------------------------------------


def run(cmd: list[str]) -> str:
    return subprocess.run(cmd, check=True, capture_output=True, text=True).stdout


def values(text: str) -> list[tuple[str, np.ndarray]]:
    out = []
    for line in text.splitlines():
        words = line.split()
        out.append((words[0], np.array([float(w) for w in words[1:]])))
    return out


def check(name: str, peer: str, core: str) -> dict[str, float]:
    """The largest difference per row over the states, relative to the row's
    scale (its largest magnitude, at least 1); stops beyond TOLERANCE."""
    a, b = values(peer), values(core)
    if [k for k, _ in a] != [k for k, _ in b]:
        raise SystemExit(f"{name}: the two sides print different rows")
    worst: dict[str, float] = {}
    for (what, x), (_, y) in zip(a, b):
        if x.shape != y.shape:
            raise SystemExit(f"{name} {what}: {x.shape} values against {y.shape}")
        err = float(np.max(np.abs(x - y)) / max(1.0, float(np.max(np.abs(x)))))
        worst[what] = max(worst.get(what, 0.0), err)
    bad = {k: v for k, v in worst.items() if not v <= TOLERANCE}
    if bad:
        raise SystemExit(f"{name}: the core and Pinocchio disagree beyond {TOLERANCE:g}: {bad}")
    return worst


def timings(text: str) -> dict[str, float]:
    return {k: float(v) for k, v in (line.split() for line in text.splitlines())}


def table_rows(times: dict[str, float]) -> dict[str, float]:
    """The rows of the table (the core's side also times the calls behind the
    Python entry points, for benches/python_calls.py)."""
    return {k: v for k, v in times.items() if k in ROWS}


def instructions(cmd: list[str], calls: int, rows: tuple[str, ...] = ROWS) -> dict[str, float]:
    """Instructions per call of each of ``rows`` under callgrind, inside ``measured_ROW``."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cg.out"
        subprocess.run(
            [
                "valgrind",
                "--tool=callgrind",
                f"--callgrind-out-file={out}",
                "--toggle-collect=*measured_*",
                *cmd,
                "count",
                str(calls),
            ],
            check=True,
            capture_output=True,
        )
        text = run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", str(out)])
    got: dict[str, float] = {}
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+)\s.*measured_(\w+)", line)
        if m and m.group(2) in rows:
            # The function's inclusive count is its largest line (others are calls from it).
            ir = int(m.group(1).replace(",", "")) / calls
            got[m.group(2)] = max(got.get(m.group(2), 0.0), ir)
    return got


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", type=Path, help="write the results here")
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--ms", type=float, default=30.0, help="time per row per round (ms)")
    ap.add_argument("--arms", nargs="*", default=list(ARMS), choices=list(ARMS))
    ap.add_argument(
        "--urdf",
        action="append",
        default=[],
        metavar="FILE[:FRAME]",
        help="also this arm (its tool frame FRAME, default the link that ends the arm); repeatable",
    )
    ap.add_argument("--no-count", action="store_true", help="skip the callgrind counts")
    ap.add_argument("--no-mujoco", action="store_true", help="skip the MuJoCo loop")
    ap.add_argument("--check", action="store_true", help="agreement only, no timing")
    args = ap.parse_args()

    chosen = arm_files(args.arms, args.urdf)  # refused by name before anything is built
    peer, core = build_peer(), build_core()
    with tempfile.TemporaryDirectory() as tmp:
        arms = write_arms(chosen, Path(tmp))
        cmds = {
            name: (
                [str(peer), str(pf), frame, str(sf)],
                [str(core), str(cf), str(sf)],
            )
            for name, (pf, cf, sf, frame) in arms.items()
        }
        print("\nagreement (largest difference over 64 states, relative to the row's scale):")
        for name, (p, c) in cmds.items():
            worst = check(name, run([*p, "check"]), run([*c, "check"]))
            print(f"  {name}: " + ", ".join(f"{k} {v:.1e}" for k, v in worst.items()))
        if args.check:
            return
        ns: dict[str, dict[str, dict[str, list[float]]]] = {
            a: {"core": {r: [] for r in ROWS}, "peer": {r: [] for r in ROWS}} for a in cmds
        }
        print(f"\ntiming: {args.rounds} rounds of {args.ms:g} ms per row and side", flush=True)
        for k in range(args.rounds):
            for name, (p, c) in cmds.items():
                order = [("peer", p), ("core", c)] if k % 2 == 0 else [("core", c), ("peer", p)]
                for side, cmd in order:
                    for row, t in table_rows(timings(run([*cmd, "time", str(args.ms)]))).items():
                        ns[name][side][row].append(t)
        ir: dict[str, dict[str, dict[str, float]]] = {}
        if not args.no_count and shutil.which("valgrind"):
            print("counting instructions under callgrind", flush=True)
            for name, (p, c) in cmds.items():
                ir[name] = {"peer": instructions(p, CALLS), "core": instructions(c, CALLS)}

    result: dict[str, Any] = {"machine": machine()}
    for name in cmds:
        result[name] = {}
        for row in ROWS:
            core_ns = statistics.median(ns[name]["core"][row])
            peer_ns = statistics.median(ns[name]["peer"][row])
            entry: dict[str, Any] = {
                "core_ns": round(core_ns, 1),
                "peer_ns": round(peer_ns, 1),
                "ratio": round(core_ns / peer_ns, 3),
            }
            if name in ir:
                ci, pi = ir[name]["core"][row], ir[name]["peer"][row]
                entry.update(core_ir=round(ci), peer_ir=round(pi), ir_ratio=round(ci / pi, 3))
            result[name][row] = entry
    if not args.no_mujoco:
        sys.path.insert(0, str(ROOT / "benches"))
        from mujoco_user_loop import side_by_side

        result["mujoco"] = {
            f"cartesian_loop_{arm}": side_by_side(arm, count_ir=not args.no_count)
            for arm in ("ur5", "panda")
        }
    print_table(result)
    if args.json:
        args.json.write_text(json.dumps(result, indent=1) + "\n")
        print(f"\nwrote {args.json}")


def print_table(result: dict[str, Any]) -> None:
    m = result["machine"]
    print(
        f"\nmachine: {m['cpu']}, {m['cores']} cores, {m['system']}, load {m['load']}; "
        f"{m['rustc']}; {m['cxx']}; Pinocchio {m['pinocchio']}"
    )
    print(
        "\n| arm | row | core (ns) | Pinocchio (ns) | core ÷ Pinocchio | core Ir "
        "| Pinocchio Ir | Ir ratio |"
    )
    print("|---|---|---:|---:|---:|---:|---:|---:|")
    for arm, rows in result.items():
        if arm == "machine":
            continue
        for row, e in rows.items():
            ir = (
                f"{e['core_ir']:,} | {e['peer_ir']:,} | {e['ir_ratio']:.2f}"
                if "core_ir" in e
                else "– | – | –"
            )
            print(
                f"| {arm} | {row} | {e['core_ns']:,.0f} | {e['peer_ns']:,.0f} | "
                f"**{e['ratio']:.2f}** | {ir} |"
            )


if __name__ == "__main__":
    main()
