"""The Panda (or any arm) pressing on a table (scenario "panda-table", docs/panda.md,
docs/contact.md): one command, one table.

The Franka Emika Panda (example-robot-data's URDF, effort limits 87/12 N m) in
MuJoCo draws a 5 cm circle at 0.25 Hz on a table with its tool while pressing
δ_c = 15 mm into it through the target impedance (SPEC §16: M_d = 2 kg,
K_d = 500 N/m, B_d critically damped, position-only): K_d δ_c = 7.5 N. Every
controller has the same outer loop, the core's (``adaptimp.CartesianController``
over the arm's ``adaptimp.Chain``); the rows differ in the joint controller and
in the formulation of the impedance (SPEC §19, schema keyword ``formulation``):

- ``admittance``: the measured wrench drives the compliant reference that the
  joint law tracks (SPEC §16); "with +τe": the paper's law with its +τe
  feedforward (and Γ = 1: no learning rates of the rule).
- ``unified``: the convex combination of the admittance's torque (share n =
  ``admittance_share``) and the torque-level one; the networks learn from the
  paper's z2 on the compliant reference.
- ``impedance``: the torque-level impedance τ = Jᵀ(K e + B ė) at the measured
  pose, the model terms along the commanded motion; the wrench never reaches
  the torque.

Joint controllers: PD, adaptive state feedback (SF) and output feedback (OF),
``adaptimp.Controller(case, "robot", n, impedance="external")`` at 1 kHz with
the core's rule (SPEC §18, ``adaptimp.contact.rule_keywords``): gains from
D(q0), RBF centres and learning rates along the scenario's whole joint path,
K1 = 10 s⁻¹ (SPEC (19.6)); nothing per arm. Computed torque with the exact
model (CT) and with +30 % mass (CT +30 %), the core's RNEA on the URDF.

The path (SPEC (19.6)): the home posture held 0.5 s (the networks learn the
arm's gravity in free space), the approach to the table's surface arriving at
rest at t = 1.3 s, the depth pressed in over 0.5 s while the circle's speed
ramps up over 1 s. For a URDF arm the table lies at least twice the arm's sag
before learning below the tool at home.

Metrics over t ≥ 2 s (p the tool, p_d the compliant reference, F_n = −F_e,z),
the keys of ``--json``: ``track_mm`` RMS ‖p_d − p‖; ``track_along_mm`` its part
along the table, RMS ‖(p_d − p)_xy‖; ``force_target_N`` K_d δ_c
(a spring table: SPEC (16.1)); ``force_rms_err_N`` RMS (F_n − target);
``force_chatter_N`` RMS of F_n's sample-to-sample change; ``contact_lost_s``
time with F_n ≤ 0 after the first contact once the approach has ended (the
commanded point δ_c into the table, t = 1.8 s);
``peak_force_N`` max F_n over the run (the approach's impact included);
``peak_tau_ratio`` max |τ_i|/τmax_i commanded after 0.1 s; ``sat_duty`` the
share of steps that saturate.

    python examples/13_panda_table.py                      # the Panda, T = 20 s, the table
    python examples/13_panda_table.py --friction 0         # a frictionless table
    python examples/13_panda_table.py --spring 5000        # a table on a 5 kN/m spring
    python examples/13_panda_table.py --arm path/to/ur5_robot.urdf --json ur5.json
    python examples/13_panda_table.py --figure --out out   # out/contact_force.png, of the arm run
    python examples/13_panda_table.py --long 120           # and a long SF run, weight norms
    python examples/13_panda_table.py --jobs 1             # the rows one after another

The rows run at once on threads, one per core (``--jobs``): each is its own
plant and controller in the core's loop, which releases the GIL; the table
is the same to the bit whatever ``--jobs``. The time column is each row's
own (they overlap); the last line gives the table's wall time. On a terminal
a progress bar counts the rows' steps (the extra ``progress``: tqdm). A
wrong argument or an arm the table cannot run is one line on stderr, exit
status 2.

Needs the extras ``mujoco`` and ``pinocchio`` (from a checkout:
``pip install ".[mujoco,pinocchio]"``). ``ADAPTIMP_QUICK=1``: T = 2.5 s.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import textwrap
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

import adaptimp
from adaptimp import mujoco as amj
from adaptimp.scenarios import contact as act
from adaptimp.scenarios import panda_table as apt

QUICK = os.environ.get("ADAPTIMP_QUICK") == "1"
"""``ADAPTIMP_QUICK=1``: T = 2.5 s (the tool is pressed in at 1.8 s)."""
ROWS = act.TABLE_ROWS
"""The table's rows (adaptimp.scenarios.contact.TABLE_ROWS): name: (label, joint
controller, formulation, +τe feedforward, learning)."""
GRAVITY_LEARNING = {
    "gamma": [1.0, 1.0, 5000.0],
    "sigma": [0.01, 0.01, 1e-5],
    "weight_bound": [4.19, 13.2, 100.0],
}
"""docs/panda.md's gravity learning, found by hand on that scenario (before the rule's)."""
# The scenario of docs/panda.md as first measured (--first): name: (label, joint
# controller, +τe feedforward, learning keywords).
FIRST: dict[str, tuple[str, str, bool, dict[str, Any]]] = {
    "pd": ("PD", "pd", True, {}),
    "sf-printed": ("SF as printed (+τe, Γ = 1)", "sf", True, {}),
    "of-printed": ("OF as printed (+τe, Γ = 1)", "of", True, {}),
    "sf-no-ff": ("SF, no τe feedforward, Γ = 1", "sf", False, {}),
    "sf-gravity": ("SF, no τe feedforward, gravity learning", "sf", False, GRAVITY_LEARNING),
    "of-gravity": ("OF, no τe feedforward, gravity learning", "of", False, GRAVITY_LEARNING),
    "ct": ("CT exact", "ct", True, {}),
    "ct+30": ("CT +30 % mass", "ct+30", True, {}),
}
KEYS = (
    "track_mm",
    "track_along_mm",
    "force_rms_err_N",
    "force_target_N",
    "force_chatter_N",
    "contact_lost_s",
    "peak_force_N",
    "peak_tau_ratio",
    "sat_duty",
)
FIGURE = "contact_force.png"
"""The figure ``--figure`` writes into ``--out``."""


class Parser(argparse.ArgumentParser):
    """A usage error is one line (``prog: error: …``), exit status 2."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message}\n")


class Progress:
    """One progress bar on a terminal for rows that run at once (tqdm, the extra
    ``progress``; without it a line per finished row): :meth:`of` is a row's
    ``progress(done, total)`` for :func:`adaptimp.mujoco.simulate`."""

    def __init__(self, rows: int, steps: int, desc: str) -> None:
        self.bar: Any = None
        self.shown = sys.stderr.isatty()
        self.done: dict[str, int] = {}
        self.lock = threading.Lock()
        if self.shown:
            try:
                from tqdm import tqdm
            except ImportError:
                return
            self.bar = tqdm(total=rows * steps, desc=desc, unit="step", unit_scale=True)

    def of(self, row: str) -> Any:
        if not self.shown:
            return None

        def report(done: int, total: int) -> None:
            with self.lock:
                if self.bar is not None:
                    self.bar.update(done - self.done.get(row, 0))
                elif done == total:
                    print(f"  {row}: done", file=sys.stderr, flush=True)
                self.done[row] = done

        return report

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def run(
    name: str, sc: apt.PandaTable, rule: dict[str, Any], T: float, progress: Any = None
) -> tuple[Any, Any, dict[str, float]]:
    """One row on the scenario: (result, controller, metrics)."""
    return act.run_row(name, sc, rule, T, progress=progress)


def figure(
    path: Path, T: float, build: Callable[[float], apt.PandaTable], arm: str, frictions: list[float]
) -> None:
    """Normal force against time, the admittance with the +τe feedforward and the
    new formulations, on the table of the arm that was run (``build(friction)``:
    its scenario, home, tip and spring), at each of ``frictions``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(
        len(frictions), 1, figsize=(11, 3.5 * len(frictions) + 0.5), sharex=True,
        layout="constrained", squeeze=False,
    )  # fmt: skip
    for ax, friction in zip(axes[:, 0], frictions, strict=True):
        sc = build(friction)
        rule = act.rule_keywords(sc)
        rows = [
            ("sf-printed", "tab:red", 0.5),
            ("ct-admittance", "tab:orange", 0.5),
            ("sf", "tab:blue", 0.9),
            ("ct", "tab:green", 0.9),
        ]
        for name, color, lw in rows:
            if sc.pin_model is None and ROWS[name][1].startswith("ct"):
                continue  # computed torque's model is Pinocchio's, read from a URDF
            res, _, m = run(name, sc, rule, T)
            ax.plot(
                res.t,
                -res.wrench_ee[:, 2],
                color=color,
                lw=lw,
                label=f"{ROWS[name][0]}: chatter {m['force_chatter_N']:.2f} N",
            )
        ax.axhline(sc.target_force(), color="k", ls="--", lw=1, label="K_d δ_c")
        ax.set_ylim(-2, 4 * sc.target_force())
        ax.set_ylabel("normal force F_n (N)")
        ax.set_title(f"{arm} on a rigid table, sliding friction {friction:g}")
        ax.legend(loc="upper right", fontsize=7)
    axes[-1, 0].set_xlabel("t (s)")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def long_run(sc: apt.PandaTable, rule: dict[str, Any], T: float) -> None:
    """SF (unified, n = SHARE) for T seconds, in parts of 10 s in the core's loop
    (the plant and the controller go on from one part to the next: the rows of
    one run); prints ‖Ŵ‖_F and the mean normal force every 10 s."""
    ctrl = act.row_controller("sf", sc, rule)
    plant = amj.Plant(sc.model)
    print(f"\nlong run, {ROWS['sf'][0]}, T = {T:g} s: weight norms, mean normal force")
    print("| t (s) | ‖W_D‖ | ‖W_C‖ | ‖W_G‖ | mean F_n over the last 10 s (N) |")
    print("|---:|---:|---:|---:|---:|")
    part = 10.0
    for i in range(round(T / part)):
        first = i == 0
        res = amj.simulate(
            ctrl, plant, T=part, q0=sc.q0 if first else None, reset=first, record_every=1
        )
        sd = ctrl.inner.state_dict()
        norms = [float(np.linalg.norm(sd[w])) for w in ("W_D", "W_C", "W_G")]
        mean = -float(np.mean(res.task["wrench"][:, 2]))
        print(
            f"| {(i + 1) * part:.0f} | "
            + " | ".join(f"{v:.3g}" for v in norms)
            + f" | {mean:.3f} |"
        )


MAX_T = 3600.0
"""The longest --T: each row keeps every step (a 20 s row is about 4 MB)."""


def _writable(path: Path) -> bool:
    """Whether ``path`` can be written (it is not a directory, and a file can
    be made beside it), tried with a temporary file that is removed."""
    import tempfile

    if path.is_dir():
        return False
    try:
        with tempfile.NamedTemporaryFile(dir=path.resolve().parent):
            pass
    except OSError:
        return False
    return not path.exists() or os.access(path, os.W_OK)


def first(T: float, jobs: int, path: str | None) -> None:
    """docs/panda.md's table: the Panda of ``panda_table()`` (its SRDF home,
    MuJoCo's default contact, straight from home into the table, the
    admittance), every joint controller with the core's gain rule
    (``panda_table.rule_gains``) and Γ = 1 or the page's gravity learning."""
    sc = apt.panda_table()
    print(
        f"docs/panda.md: the Panda, {sc.radius * 100:g} cm circle at {sc.freq:g} Hz, δ_c = "
        f"{sc.depth * 1e3:g} mm, T = {T:g} s, the core's gain rule"
    )
    print("\n| controller | track (mm) | force (N) | imp (N) | sat | peak τ/τmax |")
    print("|---|---:|---:|---:|---:|---:|")

    def one(name: str) -> dict[str, float]:
        _, kind, ff, learning = FIRST[name]
        kw = {"gamma": 1.0, **learning} if kind in ("pd", "sf", "of") else {}
        ctrl = apt.panda_controller(kind, sc, force_feedforward=ff, **kw)
        res = amj.simulate(ctrl, amj.Plant(sc.model), T=T, q0=sc.q0)
        return apt.cartesian_metrics(res, ctrl, sc, settle=min(2.0, T / 2))

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        results = list(pool.map(one, FIRST))
    table = {}
    for name, m in zip(FIRST, results):
        table[name] = m
        print(
            f"| {FIRST[name][0]} | {m['rms_track'] * 1e3:.3f} | {m['rms_force']:.2f} "
            f"| {m['rms_imp']:.2f} | {m['sat_duty']:.3f} | {m['peak_tau_ratio']:.3f} |"
        )
    if path:
        Path(path).write_text(json.dumps(table, indent=2) + "\n")
        print(f"\nwrote {path}")


def posture(text: str) -> list[float]:
    """``--home``: joint angles (rad) separated by commas; each a number or an
    arithmetic expression of numbers and ``pi`` (``-pi/4``, ``3*pi/4``)."""
    import ast
    import operator

    ops = {
        ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
        ast.Div: operator.truediv, ast.USub: operator.neg, ast.UAdd: operator.pos,
    }  # fmt: skip

    def value(node: ast.AST) -> float:
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)):
            return float(node.value)
        if isinstance(node, ast.Name) and node.id == "pi":
            return math.pi
        if isinstance(node, ast.BinOp) and type(node.op) in ops:
            return float(ops[type(node.op)](value(node.left), value(node.right)))
        if isinstance(node, ast.UnaryOp) and type(node.op) in ops:
            return float(ops[type(node.op)](value(node.operand)))
        raise ValueError(ast.dump(node))

    def angle(item: str) -> float:
        try:
            return value(ast.parse(item.strip(), mode="eval").body)
        except (ValueError, SyntaxError):
            raise argparse.ArgumentTypeError(
                f"a joint angle (rad) must be a number or an expression of numbers and pi, "
                f"got {item.strip()!r}"
            ) from None

    return [angle(item) for item in text.split(",")]


def main() -> None:
    doc = (__doc__ or "").split("\n\n")
    parser = Parser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(p for p in doc if p.startswith("    python")),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--arm", type=str, default=None, help="URDF or MJCF file of the arm (default: Panda)"
    )
    parser.add_argument(
        "--home",
        type=posture,
        default=None,
        help="the home posture, q1,...,qn (rad; e.g. 0,-pi/4,0,-3*pi/4,0,pi/2,pi/4); "
        "default: the first the table can run of the rule's home and postures drawn",
    )
    parser.add_argument("--tip", type=str, default=None, help="the tool's link (body)")
    parser.add_argument(
        "--fix",
        type=str,
        default="",
        help="joints to hold at their reference, J1,J2 (a URDF's or an MJCF's)",
    )
    parser.add_argument(
        "--placements",
        type=int,
        default=0,
        help="run the rows at this many home postures drawn within the joint limits "
        "(each one the table can run) instead of one home",
    )
    parser.add_argument(
        "--first",
        action="store_true",
        help="docs/panda.md's table: the scenario as first measured, the core's gain rule",
    )
    parser.add_argument("--T", type=float, default=2.5 if QUICK else 20.0, help="duration (s)")
    parser.add_argument("--json", type=str, default=None, help="write the table as JSON here")
    parser.add_argument("--friction", type=float, default=0.1, help="sliding friction")
    parser.add_argument("--spring", type=float, default=None, help="table spring k_e (N/m)")
    parser.add_argument("--rows", type=str, default=None, help="rows to run (default: all)")
    parser.add_argument(
        "--figure",
        action="store_true",
        help=f"also write {FIGURE} into --out: the normal force of the arm run, without "
        "friction and at --friction",
    )
    parser.add_argument(
        "--out", type=Path, default=Path("out"), help="where --figure writes (default: out)"
    )
    parser.add_argument("--long", type=float, default=0.0, help="also a long SF run (s)")
    parser.add_argument(
        "--jobs",
        type=int,
        default=os.cpu_count() or 1,
        help="rows run at once, on threads (the core's loop releases the GIL); default: every core",
    )
    # A posture that starts with a negative angle (--home -0.47,…) is the
    # option's value, not an option.
    argv = sys.argv[1:]
    for i, a in enumerate(argv[:-1]):
        if a == "--home" and argv[i + 1].startswith("-"):
            argv[i : i + 2] = [f"--home={argv[i + 1]}"]
            break
    args = parser.parse_args(argv)
    if args.jobs < 1:
        parser.error(f"--jobs must be ≥ 1, got {args.jobs}")
    if not (math.isfinite(args.T) and args.T > 0):
        parser.error(f"--T must be a finite number > 0 (s), got {args.T}")
    if not (math.isfinite(args.long) and args.long >= 0 and args.long % 10 == 0):
        parser.error(
            f"--long must be 0 or a multiple of 10 s (it runs in parts of 10 s), got {args.long}"
        )
    if args.first:
        first(args.T, args.jobs, args.json)
        return
    if args.placements < 0 or (args.placements and args.home is not None):
        parser.error("--placements must be ≥ 0, and draws the homes: give it without --home")
    names = list(ROWS) if args.rows is None else args.rows.split(",")
    unknown = [n for n in names if n not in ROWS]
    if unknown:
        parser.error(f"--rows: unknown {unknown}; the rows are {list(ROWS)}")
    if args.json and not Path(args.json).resolve().parent.is_dir():
        parser.error(f"--json: no directory {Path(args.json).resolve().parent}")
    if args.json and not _writable(Path(args.json)):
        # Known before the rows run, not after.
        parser.error(f"--json: cannot write {args.json} (a directory, or not writable)")
    # Every row keeps every step's record (about 190 bytes): 2e5 s were 36 GiB.
    if args.T > MAX_T:
        parser.error(f"--T must be at most {MAX_T:g} s (every step is kept), got {args.T:g}")

    fix = tuple(j for j in args.fix.split(",") if j)
    where = {"tip": args.tip, "fix": fix} if args.arm is not None else {}
    try:
        if args.placements:
            drawn = act.placements(
                args.arm, args.placements, spring=args.spring, friction=args.friction, **where
            )
            scenarios = [(f"placement {k}", sc) for k, sc in enumerate(drawn)]
        else:
            home = {} if args.home is None else {"home": args.home}
            sc = act.arm_table(
                args.arm, spring=args.spring, friction=args.friction, **where, **home
            )
            scenarios = [("", sc)]
    except (adaptimp.ConfigError, ValueError, OSError) as e:
        parser.error(str(e))
    if scenarios[0][1].pin_model is None:
        # Computed torque's model is Pinocchio's, read from a URDF.
        given = [n for n in names if ROWS[n][1].startswith("ct")]
        if args.rows is not None and given:
            parser.error(f"--rows: {given} need a URDF arm (computed torque's model)")
        names = [n for n in names if not ROWS[n][1].startswith("ct")]
    table: dict[str, dict[str, Any]] = {}
    for label, sc in scenarios:
        if sc.t_approach + sc.t_press >= args.T:
            parser.error(
                f"--T must be longer than the approach, which ends with the tool pressed in "
                f"at t = {sc.t_approach + sc.t_press:g} s; got {args.T:g}"
            )
        table.update(run_table(args, label, sc, names))
    if args.json:
        Path(args.json).write_text(json.dumps(table, indent=2) + "\n")
        print(f"\nwrote {args.json}")
    if args.figure:
        home = {"home": scenarios[0][1].q0} if args.arm is not None else {}

        def build(friction: float) -> apt.PandaTable:
            return act.arm_table(args.arm, spring=args.spring, friction=friction, **where, **home)

        path = args.out / FIGURE
        frictions = sorted({0.0, args.friction})
        figure(path, args.T, build, Path(args.arm).name if args.arm else "Panda", frictions)
        print(f"\nwrote {path}")
    if args.long > 0:
        sc = scenarios[0][1]
        long_run(sc, act.rule_keywords(sc), args.long)


def run_table(
    args: argparse.Namespace, label: str, sc: apt.PandaTable, names: list[str]
) -> dict[str, dict[str, Any]]:
    """The rows ``names`` on one scenario, printed as a Markdown table; their
    metrics by row name (prefixed with ``label``)."""
    rule = act.rule_keywords(sc)
    print(
        f"\n{label + ': ' if label else ''}{args.arm or 'Panda'}: {sc.radius * 100:g} cm "
        f"circle at {sc.freq:g} Hz about ({sc.centre[0]:.3f}, {sc.centre[1]:.3f}) m, table top "
        f"{sc.surface_z - 0.01:.4f} m, δ_c = {sc.depth * 1e3:g} mm, friction {args.friction:g}, "
        f"{'rigid' if args.spring is None else f'spring {args.spring:g} N/m'}, T = {args.T:g} s, "
        f"home {np.round(sc.q0, 3).tolist()}, {rule['basis'][0].shape[0]} centres"
    )
    print(
        "\n| controller | track (mm) | along (mm) | force RMS err (N) | target (N) | mean (N) "
        "| (16.1) (N) | chatter (N) | contact lost (s) | peak F_n (N) | peak τ/τmax | sat "
        "| time (s) |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    table: dict[str, dict[str, Any]] = {}

    def timed(name: str, progress: Any) -> tuple[dict[str, float] | None, float, str]:
        """One row: its metrics (None if it diverged), its own time (s), the error."""
        t0 = time.perf_counter()
        try:
            _, _, m = run(name, sc, rule, args.T, progress)
        except adaptimp.DivergedError as e:
            return None, time.perf_counter() - t0, str(e).splitlines()[0]
        return m, time.perf_counter() - t0, ""

    # The rows are independent runs: on every core at once (each its own
    # plant and controller; the model is shared read-only), printed in order.
    start = time.perf_counter()
    bar = Progress(len(names), round(args.T / sc.Ts), f"{len(names)} rows")
    try:
        with ThreadPoolExecutor(max_workers=args.jobs) as pool:
            results = list(pool.map(lambda name: timed(name, bar.of(name)), names))
    finally:
        bar.close()
    wall = time.perf_counter() - start
    for name, (m, took, error) in zip(names, results):
        if m is None:
            print(f"| {ROWS[name][0]} | diverged: {error} |")
            continue
        table[f"{label}: {name}" if label else name] = {
            **{k: m[k] for k in KEYS},
            **({"home": [float(x) for x in sc.q0]} if label else {}),
        }
        print(
            f"| {ROWS[name][0]} | {m['track_mm']:.3f} | {m['track_along_mm']:.3f} "
            f"| {m['force_rms_err_N']:.3f} "
            f"| {m['force_target_N']:.3f} | {m['force_mean_N']:.3f} | {m['force_16_1_N']:.3f} "
            f"| {m['force_chatter_N']:.3f} | {m['contact_lost_s']:.3f} | {m['peak_force_N']:.1f} "
            f"| {m['peak_tau_ratio']:.3f} | {m['sat_duty']:.3f} "
            f"| {took:.1f} |"
        )
        assert m["applied_ratio"] <= 1.0 + 1e-12, "applied torque beyond its limit"
    print(f"\n{len(names)} rows in {wall:.1f} s on {min(args.jobs, len(names))} thread(s)")
    return table


if __name__ == "__main__":
    main()
