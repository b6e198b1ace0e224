"""The ``adaptimp`` command.

``adaptimp reproduce [--out DIR] [--PARAM VALUE ...]``
    Run the paper's three cases (SPEC §11) and write, into DIR, the figures of
    each case (tracking, errors, torques: the kinds of the paper's Figs. 2–10),
    a comparison of the three, ``metrics.json`` and ``metrics.md``; print the table.

``adaptimp simulate [--case sf] [--PARAM VALUE ...] [--plot FILE [--kind KIND]] [--save FILE]``
    Run one case and print its SPEC §12 metrics: on the paper's arm, or with
    ``--model FILE`` on any arm (a URDF or MJCF file, on MuJoCo: the extra
    ``mujoco``) by the calls of the Python route,
    :func:`adaptimp.mujoco.simulate` for ``--task joint`` (the default task
    of SPEC §18) and :func:`adaptimp.mujoco.cartesian_task` then
    :func:`adaptimp.mujoco.simulate` for ``--task cartesian`` (SPEC §16);
    ``--tip``, ``--fix``, ``--home``, ``--payload`` (kg, the plant's only),
    ``--gravity model`` (SPEC (20.10)).

``adaptimp table [--model FILE] [--home q1,…,qn] [--rows pd,sf,of] [--T 20] [--json FILE]``
    The arm (default: the Panda) pressing on a table (SPEC §19,
    :func:`adaptimp.scenarios.contact.arm_table`): the rows of
    docs/contact.md's table, printed (the extras ``mujoco`` and ``pinocchio``).

``adaptimp params [--scenario paper|robot]``
    List every parameter with its unit, meaning, validity condition and the
    scenario's default.

Any parameter of :func:`adaptimp.simulate` is given as ``--name value`` (or
``--name=value``); per-joint and per-network values as comma-separated lists
(``--Kp 10.5,9``), ``none`` for no wall (``--wall none``) or no weight bound
(``--weight_bound none``; ``auto`` or ``1,2,3`` otherwise). A name that is
not one is refused with the names closest to it ("did you mean"). A usage
error is one line on stderr, exit status 2.
"""

from __future__ import annotations

import argparse
import difflib
import json
import math
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from ._adaptimp import __version__
from ._api import simulate
from ._errors import ConfigError
from ._params import BY_NAME, CASE_NAMES, CASES, SCENARIOS, describe
from ._plot import PLOT_KINDS, compare
from ._result import SimResult, metrics_json, metrics_table


class CliError(Exception):
    """A usage error: reported on stderr with exit status 2."""


def _parse_value(name: str, text: str) -> Any:
    p = BY_NAME[name]
    try:
        if p.kind in ("optional", "derived", "bound", "limit", "derived_axes", "matrix") and (
            text.lower() == "none"
        ):
            return None
        if p.kind == "bound":
            if text.lower() == "auto":
                return "auto"
            parts = [float(x) for x in text.split(",")]
            return parts[0] if len(parts) == 1 else parts
        if p.kind == "int":
            return int(text)
        if p.kind in ("real", "optional", "derived"):
            return float(text)
        if p.kind in ("joint", "network", "limit", "axes", "derived_axes", "matrix"):
            parts = [float(x) for x in text.split(",")]
            return parts[0] if len(parts) == 1 else parts
        if p.kind == "flag":
            if text.lower() in ("true", "false"):
                return text.lower() == "true"
            raise ValueError(text)
    except ValueError:
        raise CliError(f"--{name}: cannot read {text!r} as {_expected(p.kind)}") from None
    return text  # a choice


def _expected(kind: str) -> str:
    return {
        "int": "an integer",
        "real": "a number",
        "optional": "a number or 'none'",
        "derived": "a number or 'none'",
        "joint": "a number or comma-separated numbers, one per joint",
        "network": "a number or comma-separated numbers, one per network (D, C, G)",
        "bound": "'none', 'auto', or comma-separated numbers, one per network (D, C, G)",
        "limit": "'none', or a number or comma-separated numbers, one per joint",
        "axes": "a number or comma-separated numbers, one per axis (x, y, z)",
        "derived_axes": "'none', or a number or comma-separated numbers, one per axis (x, y, z)",
        "flag": "'true' or 'false'",
        "matrix": "'none', or n × n comma-separated numbers, row-major",
    }.get(kind, "a value")


def suggest(name: str, choices: Sequence[str]) -> str:
    """ " did you mean --x (or --y)?" for the ``choices`` closest to ``name``
    (the same name in another case, else by difflib's ratio), or "" if none
    is close."""
    lower = {c.lower(): c for c in choices}
    if name.lower() in lower:  # the name in another case: that one alone
        return f" did you mean --{lower[name.lower()]}?"
    close = difflib.get_close_matches(name, choices, n=3, cutoff=0.6)
    if not close:
        return ""
    return " did you mean " + " or ".join(f"--{c}" for c in close) + "?"


def parse_params(tokens: Sequence[str], options: Sequence[str] = ()) -> dict[str, Any]:
    """``--name value`` / ``--name=value`` pairs into simulate() keywords; an
    unknown name is refused with the closest names (of the schema and of the
    command's own ``options``)."""
    out: dict[str, Any] = {}
    i = 0
    while i < len(tokens):
        token = tokens[i]
        if not token.startswith("--") or len(token) == 2:
            raise CliError(f"unexpected argument {token!r}; parameters are given as --name value")
        name, eq, value = token[2:].partition("=")
        if name not in BY_NAME:
            hint = suggest(name, [*BY_NAME, *options])
            raise CliError(
                f"unknown parameter --{name}{';' + hint if hint else ''} (every name: "
                f"`adaptimp params`{', and --help' if options else ''})"
            )
        if not eq:
            if i + 1 >= len(tokens):
                raise CliError(f"--{name} needs a value")
            i += 1
            value = tokens[i]
        out[name] = _parse_value(name, value)
        i += 1
    return out


def _run(case: str, scenario: str, params: dict[str, Any]) -> tuple[SimResult, float]:
    start = time.perf_counter()
    try:
        res = simulate(case, scenario, **params)
    except (TypeError, ValueError) as e:
        raise CliError(str(e)) from None
    return res, time.perf_counter() - start


def _figure_format(path: str) -> None:
    """A figure's file name whose suffix matplotlib writes, checked before a run
    (``x.unknownext`` ended the run in a traceback)."""
    from matplotlib.figure import Figure

    supported = Figure().canvas.get_supported_filetypes()
    suffix = Path(path).suffix[1:].lower()
    if suffix not in supported:
        raise CliError(
            f"--plot {path}: {'no suffix' if not suffix else f'.{suffix} is not a figure format'}; "
            f"give one of {', '.join('.' + s for s in sorted(supported))}"
        )


def _save_figure(res: SimResult, kind: str, path: Path) -> None:
    import matplotlib.pyplot as plt

    fig = res.plot(kind)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def cmd_reproduce(args: argparse.Namespace, params: dict[str, Any]) -> int:
    """Run the three cases; write figures, metrics.json, metrics.md; print the table."""
    out = Path(args.out)
    if out.exists() and not out.is_dir():  # /dev/null ended in a traceback
        raise CliError(f"--out {out}: not a folder (the figures and metrics go into one)")
    out.mkdir(parents=True, exist_ok=True)
    note = f" with {params}" if params else ""
    print(f"adaptimp {__version__}: the paper's three cases, scenario {args.scenario!r}{note}")
    results: dict[str, SimResult] = {}
    for case in CASES:
        res, seconds = _run(case, args.scenario, params)
        results[case] = res
        print(f"  {case}: {res.rows} steps in {seconds:.2f} s")
        for kind in PLOT_KINDS:
            _save_figure(res, kind, out / f"{case}_{kind}.png")

    import matplotlib.pyplot as plt

    fig = compare(list(results.values()))
    fig.savefig(out / "comparison.png", dpi=120)
    plt.close(fig)

    table = metrics_table({CASE_NAMES[c]: r for c, r in results.items()})
    summary = {
        "adaptimp_version": __version__,
        "scenario": args.scenario,
        "overrides": params,
        "metrics": {c: metrics_json(r.metrics) for c, r in results.items()},
        "params": {c: r.params for c, r in results.items()},
    }
    (out / "metrics.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    (out / "metrics.md").write_text(table + "\n", encoding="utf-8")
    print()
    print(table)
    print(f"\nwrote {len(list(out.glob('*.png')))} figures, metrics.json and metrics.md to {out}/")
    return 0


def cmd_simulate(args: argparse.Namespace, params: dict[str, Any]) -> int:
    """Run one case; print its metrics; optionally plot and save."""
    if args.plot:
        _figure_format(args.plot)
    if args.model is None:
        mujoco_only = [
            f"--{k}" for k in ("tip", "fix", "task", "payload", "home", "gravity")
            if getattr(args, k) not in (None, "", "joint", False)
        ] + (["--[no-]coupled"] if args.coupled is not None else [])  # fmt: skip
        if mujoco_only:
            verb = "applies" if len(mujoco_only) == 1 else "apply"
            raise CliError(f"{', '.join(mujoco_only)} {verb} to an arm given with --model FILE")
        res, seconds = _run(args.case, args.scenario or "paper", params)
    else:
        res, seconds = _run_model(args, params)
    if args.json:
        print(json.dumps(metrics_json(res.metrics), indent=2))
    else:
        where = "" if args.model is None else f" on {Path(args.model).name}"
        print(f"{CASE_NAMES[res.case]} ({res.case}){where}: {res.rows} steps in {seconds:.2f} s")
        print(metrics_table({CASE_NAMES[res.case]: res}))
        if getattr(res, "pos_err", None) is not None:
            m = res.metrics
            rot = (
                f", orientation RMS {1e3 * m['rms_rot_after2']:.4g} mrad"
                if res.params.get("orients")
                else " (the position only: fewer than six joints)"
            )
            print(
                f"\nthe Cartesian task, t ≥ {res.params['settle']:g} s: position RMS "
                f"{1e3 * m['rms_pos_after2']:.4g} mm (max {1e3 * m['max_pos_after2']:.4g} mm){rot}"
            )
        for text in res.params.get("warnings", []):
            print(f"warning: {text}", file=sys.stderr)
    if args.plot:
        _save_figure(res, args.kind, Path(args.plot))
        print(f"wrote {args.plot}", file=sys.stderr)
    if args.save:
        path = res.save(args.save)
        print(f"wrote {path}", file=sys.stderr)
    return 0


def _angles(text: str) -> list[float]:
    """Joint angles (rad) separated by commas, each a number or an expression of
    numbers and ``pi`` (``-pi/4``, ``3*pi/4``)."""
    import ast
    import operator

    ops: dict[type, Any] = {
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
            raise CliError(
                f"--home: a joint angle (rad) must be a number or an expression of numbers "
                f"and pi, got {item.strip()!r}"
            ) from None

    return [angle(item) for item in text.split(",")]


def _fix(text: str) -> tuple[str, ...]:
    return tuple(j.strip() for j in text.split(",") if j.strip())


def _run_model(args: argparse.Namespace, params: dict[str, Any]) -> tuple[Any, float]:
    """One case on the arm of ``--model`` (MuJoCo), as the Python route runs it:
    ``amj.simulate(case, FILE, ...)``, or for ``--task cartesian``
    ``amj.cartesian_task(FILE, ...)`` then ``amj.simulate(case, plant, task=task)``."""
    try:
        from . import mujoco as amj
    except ImportError as e:
        raise CliError(str(e)) from None
    start = time.perf_counter()
    where: dict[str, Any] = {"tip": args.tip, "fix": _fix(args.fix)}
    scenario = args.scenario or "robot"
    extra: dict[str, Any] = {"gravity": args.gravity, "payload": args.payload or 0.0}
    if args.coupled is not None:
        extra["coupled"] = args.coupled
    try:
        if args.task == "cartesian":
            plant = amj.Plant(args.model, **where)
            q0 = None if args.home is None else _angles(args.home)
            try:
                task = amj.cartesian_task(plant, q0=q0)
            except ConfigError as e:  # its advice in the shell's words, too
                raise CliError(
                    f"{e} (from the shell: --home q1,…,qn gives q0, --tip the tip)"
                ) from None
            params.setdefault("T", 12.0)
            res = amj.simulate(args.case, plant, task=task, scenario=scenario, **extra, **params)
            res.params["orients"] = task.orients
        else:
            home = None if args.home is None else _angles(args.home)
            params.setdefault("T", 10.0)
            res = amj.simulate(
                args.case, args.model, scenario=scenario, home=home, **where, **extra, **params
            )
    except (TypeError, ValueError, OSError) as e:
        raise CliError(str(e)) from None
    return res, time.perf_counter() - start


def cmd_table(args: argparse.Namespace, params: dict[str, Any]) -> int:
    """The arm pressing on a table (SPEC §19): the rows of docs/contact.md, printed."""
    if params:
        raise CliError(f"`adaptimp table` takes no parameters, got {sorted(params)}")
    try:
        from ._errors import DivergedError
        from .scenarios import contact as act
    except ImportError as e:
        raise CliError(str(e)) from None
    names = [r.strip() for r in args.rows.split(",") if r.strip()]
    unknown = [r for r in names if r not in act.TABLE_ROWS]
    if unknown:
        hint = suggest(unknown[0], list(act.TABLE_ROWS)).replace("--", "")
        raise CliError(f"--rows: no row {unknown[0]!r};{hint} (the rows: {list(act.TABLE_ROWS)})")
    if not (math.isfinite(args.T) and args.T > 0):
        raise CliError(f"--T must be a finite number > 0 (s), got {args.T}")
    where: dict[str, Any] = {}
    if args.model is not None:
        where = {"tip": args.tip, "fix": _fix(args.fix)}
        if args.home is not None:
            where["home"] = _angles(args.home)
    elif args.home is not None or args.tip is not None or args.fix:
        raise CliError("--home, --tip and --fix apply to an arm given with --model FILE")
    try:
        sc = act.arm_table(args.model, spring=args.spring, friction=args.friction, **where)
    except (TypeError, ValueError, OSError) as e:
        raise CliError(str(e)) from None
    if sc.pin_model is None:  # computed torque's model is Pinocchio's, from a URDF
        ct = [n for n in names if act.TABLE_ROWS[n][1].startswith("ct")]
        if ct:
            raise CliError(f"--rows: {ct} need a URDF arm (computed torque's model)")
    if sc.t_approach + sc.t_press >= args.T:
        raise CliError(
            f"--T must be longer than the approach, which ends with the tool pressed in at "
            f"t = {sc.t_approach + sc.t_press:g} s; got {args.T:g}"
        )
    rule = act.rule_keywords(sc)
    arm = Path(args.model).name if args.model else "the Panda"
    print(
        f"{arm} on a table: {sc.radius * 100:g} cm circle at {sc.freq:g} Hz, δ_c = "
        f"{sc.depth * 1e3:g} mm, friction {args.friction:g}, "
        f"{'rigid' if args.spring is None else f'spring {args.spring:g} N/m'}, T = {args.T:g} s, "
        f"home {[round(float(x), 4) for x in sc.q0]} (rad)"
    )
    print(
        "\n| controller | track (mm) | along (mm) | force RMS err (N) | target (N) "
        "| chatter (N) | contact lost (s) | peak F_n (N) | peak τ/τmax | sat |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    table: dict[str, Any] = {}
    for name in names:
        try:
            _, _, m = act.run_row(name, sc, rule, args.T)
        except DivergedError as e:
            print(f"| {act.TABLE_ROWS[name][0]} | diverged: {str(e).splitlines()[0]} |")
            continue
        table[name] = m
        print(
            f"| {act.TABLE_ROWS[name][0]} | {m['track_mm']:.3f} | {m['track_along_mm']:.3f} "
            f"| {m['force_rms_err_N']:.3f} | {m['force_target_N']:.3f} "
            f"| {m['force_chatter_N']:.3f} | {m['contact_lost_s']:.3f} | {m['peak_force_N']:.1f} "
            f"| {m['peak_tau_ratio']:.3f} | {m['sat_duty']:.3f} |"
        )
    if args.json:
        home = [float(x) for x in sc.q0]
        Path(args.json).write_text(json.dumps({"home": home, "rows": table}, indent=2) + "\n")
        print(f"wrote {args.json}", file=sys.stderr)
    return 0


def cmd_params(args: argparse.Namespace, params: dict[str, Any]) -> int:
    """Print every parameter with its unit, meaning, condition and the scenario's default."""
    if params:
        raise CliError("`adaptimp params` takes no parameters")
    print(
        f"Parameters of adaptimp.simulate (units; validity; defaults of the "
        f"{args.scenario!r} scenario):"
    )
    print(describe(scenario=args.scenario))
    print("\nParameters of adaptimp.CartesianController, the 6-D Cartesian impedance (SPEC §16):")
    print(describe("cartesian", scenario=args.scenario))
    return 0


_GROUPS = {"sim": "the run", "controller": "the controller", "arm": "the arm", "env": "the wall"}


def _params_epilog() -> str:
    """Every parameter a run takes as --name value, by group, from the schema
    (units, meanings and defaults: `adaptimp params`)."""
    import textwrap

    from ._params import PARAMS

    lines = ["parameters (--name value; units, meanings, defaults: `adaptimp params`):"]
    for group, title in _GROUPS.items():
        names = " ".join(f"--{p.name}" for p in PARAMS if p.group == group)
        lines += textwrap.wrap(
            f"{title}: {names}", width=79, initial_indent="  ", subsequent_indent="    "
        )
    return "\n".join(lines)


class _Parser(argparse.ArgumentParser):
    """A usage error is one line (``adaptimp …: error: …``), exit status 2."""

    def error(self, message: str) -> Any:
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (parameters are parsed from the leftover arguments;
    ``--help`` lists them, from the schema)."""
    parser = _Parser(
        prog="adaptimp",
        description="Adaptive neural impedance control with input saturation "
        "(He, Dong & Sun, IEEE TSMC 2016): simulations of the paper's 2-link arm.",
        epilog="Parameters: any keyword of adaptimp.simulate as --name value "
        "(lists comma-separated, e.g. --Kp 10.5,9; --wall none). "
        "List them with `adaptimp params`.",
        allow_abbrev=False,
    )
    parser.add_argument("--version", action="version", version=f"adaptimp {__version__}")
    sub = parser.add_subparsers(
        dest="command", required=True, metavar="COMMAND", parser_class=_Parser
    )

    rep = sub.add_parser(
        "reproduce",
        help="run the paper's three cases; write figures and metrics",
        description="Run PD, state feedback and output feedback in the paper scenario; "
        "write per-case figures (tracking, errors, torques), a comparison figure, "
        "metrics.json and metrics.md into --out; print the metrics table.",
        epilog=_params_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        allow_abbrev=False,
    )
    rep.add_argument("--out", default="reproduce", help="output directory (default: reproduce)")
    rep.add_argument("--scenario", default="paper", choices=tuple(SCENARIOS))
    rep.set_defaults(func=cmd_reproduce)

    sim = sub.add_parser(
        "simulate",
        help="run one case, on the paper's arm or any arm (--model), and print its metrics",
        description="Run one case and print its SPEC §12 metrics: on the paper's arm, or "
        "with --model FILE on any arm (a URDF or MJCF file, on MuJoCo: the calls of the "
        "Python route, adaptimp.mujoco.simulate and cartesian_task). Any parameter as "
        "--name value (e.g. --T 5 --Kp 10.5 --wall none).",
        epilog="examples:\n"
        "  adaptimp simulate --case of --T 5 --Kp 10.5,9 --robust tanh --wall none\n"
        "  adaptimp simulate --model my_arm.urdf --plot my_arm.png            # 10 s, T\n"
        "  adaptimp simulate --model my_arm.xml --task cartesian --case pd     # 12 s\n"
        "  adaptimp simulate --model my_arm.urdf --payload 0.2 --gravity model\n\n"
        + _params_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        allow_abbrev=False,
    )
    sim.add_argument("--case", default="sf", choices=CASES, help="controller (default: sf)")
    sim.add_argument(
        "--scenario",
        default=None,
        choices=tuple(SCENARIOS),
        help="the defaults (default: paper for the paper's arm, robot with --model)",
    )
    sim.add_argument(
        "--model", metavar="FILE", help="an arm's URDF, xacro or MJCF file (MuJoCo's plant)"
    )
    sim.add_argument("--tip", help="with --model: the end effector (a link, body or site)")
    sim.add_argument("--fix", default="", help="with --model: joints to hold, J1,J2")
    sim.add_argument(
        "--task",
        default="joint",
        choices=("joint", "cartesian"),
        help="with --model: the default joint task (SPEC §18) or the Cartesian task "
        "(SPEC §16: a start drawn by the posture rule, a 3 cm circle)",
    )
    sim.add_argument(
        "--payload",
        type=float,
        default=None,
        help="with --model: a point mass (kg) at the end effector, the plant's only",
    )
    sim.add_argument(
        "--home",
        help="with --model: the joint task's posture, or the Cartesian task's start, q1,…,qn "
        "(rad; -pi/4 allowed)",
    )
    sim.add_argument(
        "--gravity",
        choices=("model",),
        default=None,
        help="with --model: feed the nominal model's gravity forward, SPEC (20.10) (for a "
        "robot that does not compensate it)",
    )
    sim.add_argument(
        "--coupled",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="with --model: the rule's inertia-shaped gains, SPEC (18.12) (the default "
        "with --delay 1 or 2); --no-coupled: the diagonal gains of (18.1)",
    )
    sim.add_argument("--plot", metavar="FILE", help="write a figure (PNG, PDF, SVG, …)")
    sim.add_argument(
        "--kind",
        default="tracking",
        choices=tuple(dict.fromkeys((*PLOT_KINDS, "contact"))),
        help="figure of --plot (default: tracking; contact: a --model run's force)",
    )
    sim.add_argument("--save", metavar="FILE", help="write the run to a .npz file")
    sim.add_argument("--json", action="store_true", help="print the metrics as JSON")
    sim.set_defaults(func=cmd_simulate)

    tab = sub.add_parser(
        "table",
        help="an arm pressing on a table: the rows of docs/contact.md",
        description="An arm (default: the Panda) draws a 5 cm circle on a table with its "
        "tool while pressing 15 mm into it (SPEC §19, adaptimp.scenarios.contact.arm_table): "
        "the rows of docs/contact.md's table. Needs the extras mujoco and pinocchio.",
        epilog="examples:\n"
        "  adaptimp table                                   # the Panda at Franka's ready\n"
        "  adaptimp table --model ur5.urdf --home 0,-pi/2,pi/2,-pi/2,-pi/2,0 --rows sf",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        allow_abbrev=False,
    )
    tab.add_argument("--model", metavar="FILE", help="an arm's URDF or MJCF (default: Panda)")
    tab.add_argument(
        "--home",
        help="the home posture, q1,…,qn (rad; -pi/4 allowed; default: the first the table can run)",
    )
    tab.add_argument("--tip", help="the tool's link (body)")
    tab.add_argument("--fix", default="", help="joints to hold, J1,J2")
    tab.add_argument("--rows", default="pd,sf,of", help="rows (default: pd,sf,of)")
    tab.add_argument("--T", type=float, default=20.0, help="duration (s, default 20)")
    tab.add_argument("--friction", type=float, default=0.1, help="sliding friction (0.1)")
    tab.add_argument("--spring", type=float, default=None, help="table spring k_e (N/m)")
    tab.add_argument("--json", metavar="FILE", help="write the rows' metrics as JSON")
    tab.set_defaults(func=cmd_table)

    par = sub.add_parser(
        "params",
        help="list the parameters, units and defaults",
        description="List every parameter with its unit, meaning, validity condition "
        "and the default of --scenario.",
        allow_abbrev=False,
    )
    par.add_argument("--scenario", default="paper", choices=tuple(SCENARIOS))
    par.set_defaults(func=cmd_params)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``adaptimp`` console script; returns the exit status."""
    parser = build_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    # A posture that starts with a negative angle (--home -0.47,…) is the
    # option's value, not an option.
    for i, a in enumerate(argv[:-1]):
        if a == "--home" and argv[i + 1].startswith("-"):
            argv[i : i + 2] = [f"--home={argv[i + 1]}"]
    args, rest = parser.parse_known_args(argv)
    sub = _subparser(parser, args.command)
    options = [o[2:] for a in sub._actions for o in a.option_strings if o.startswith("--")]
    try:
        params = parse_params(rest, options)
        status: int = args.func(args, params)
    except CliError as e:
        parser.exit(2, f"adaptimp {args.command}: error: {e}\n")
    except OSError as e:  # a file that cannot be written (a folder, a full disk): one line
        parser.exit(1, f"adaptimp {args.command}: error: {e}\n")
    return status


def _subparser(parser: argparse.ArgumentParser, command: str) -> argparse.ArgumentParser:
    """The parser of ``command``."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            found: argparse.ArgumentParser = action.choices[command]
            return found
    return parser


if __name__ == "__main__":
    raise SystemExit(main())
