"""The ``adaptimp`` command.

``adaptimp reproduce [--out DIR] [--PARAM VALUE ...]``
    Run the paper's three cases (SPEC §11) and write, into DIR, the figures of
    each case (tracking, errors, torques: the kinds of the paper's Figs. 2–10),
    a comparison of the three, ``metrics.json`` and ``metrics.md``; print the table.

``adaptimp simulate [--case sf] [--PARAM VALUE ...] [--plot FILE [--kind KIND]] [--save FILE]``
    Run one case and print its SPEC §12 metrics.

``adaptimp params [--scenario paper|robot]``
    List every parameter with its unit, meaning, validity condition and the
    scenario's default.

Any parameter of :func:`adaptimp.simulate` is given as ``--name value`` (or
``--name=value``); per-joint and per-network values as comma-separated lists
(``--Kp 10.5,9``), ``none`` for no wall (``--wall none``) or no weight bound
(``--weight_bound none``; ``auto`` or ``1,2,3`` otherwise).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from . import __version__
from ._api import simulate
from ._params import BY_NAME, CASE_NAMES, CASES, SCENARIOS, describe
from ._plot import PLOT_KINDS, compare
from ._result import SimResult, metrics_json, metrics_table


class CliError(Exception):
    """A usage error: reported on stderr with exit status 2."""


def _parse_value(name: str, text: str) -> Any:
    p = BY_NAME[name]
    try:
        if p.kind in ("optional", "derived", "bound", "limit", "derived_axes") and (
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
        if p.kind in ("joint", "network", "limit", "axes", "derived_axes"):
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
    }.get(kind, "a value")


def parse_params(tokens: Sequence[str]) -> dict[str, Any]:
    """``--name value`` / ``--name=value`` pairs into simulate() keywords."""
    out: dict[str, Any] = {}
    i = 0
    while i < len(tokens):
        token = tokens[i]
        if not token.startswith("--") or len(token) == 2:
            raise CliError(f"unexpected argument {token!r}; parameters are given as --name value")
        name, eq, value = token[2:].partition("=")
        if name not in BY_NAME:
            raise CliError(
                f"unknown parameter --{name}; valid names: {', '.join(BY_NAME)} "
                "(see `adaptimp params`)"
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
    res, seconds = _run(args.case, args.scenario, params)
    if args.json:
        print(json.dumps(metrics_json(res.metrics), indent=2))
    else:
        print(f"{CASE_NAMES[res.case]} ({res.case}): {res.rows} steps in {seconds:.2f} s")
        print(metrics_table({CASE_NAMES[res.case]: res}))
    if args.plot:
        _save_figure(res, args.kind, Path(args.plot))
        print(f"wrote {args.plot}", file=sys.stderr)
    if args.save:
        path = res.save(args.save)
        print(f"wrote {path}", file=sys.stderr)
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


def build_parser() -> argparse.ArgumentParser:
    """The argument parser (parameters are parsed from the leftover arguments;
    ``--help`` lists them, from the schema)."""
    parser = argparse.ArgumentParser(
        prog="adaptimp",
        description="Adaptive neural impedance control with input saturation "
        "(He, Dong & Sun, IEEE TSMC 2016): simulations of the paper's 2-link arm.",
        epilog="Parameters: any keyword of adaptimp.simulate as --name value "
        "(lists comma-separated, e.g. --Kp 10.5,9; --wall none). "
        "List them with `adaptimp params`.",
        allow_abbrev=False,
    )
    parser.add_argument("--version", action="version", version=f"adaptimp {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

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
        help="run one case and print its metrics",
        description="Run one case and print its SPEC §12 metrics. Any parameter "
        "as --name value (e.g. --T 5 --Kp 10.5 --wall none).",
        epilog=_params_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        allow_abbrev=False,
    )
    sim.add_argument("--case", default="sf", choices=CASES, help="controller (default: sf)")
    sim.add_argument("--scenario", default="paper", choices=tuple(SCENARIOS))
    sim.add_argument("--plot", metavar="FILE", help="write a figure (PNG, PDF, SVG, …)")
    sim.add_argument(
        "--kind",
        default="tracking",
        choices=PLOT_KINDS,
        help="figure of --plot (default: tracking)",
    )
    sim.add_argument("--save", metavar="FILE", help="write the run to a .npz file")
    sim.add_argument("--json", action="store_true", help="print the metrics as JSON")
    sim.set_defaults(func=cmd_simulate)

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
    args, rest = parser.parse_known_args(argv)
    try:
        params = parse_params(rest)
        status: int = args.func(args, params)
    except CliError as e:
        parser.exit(2, f"adaptimp {args.command}: error: {e}\n")
    except OSError as e:  # a file that cannot be written (a folder, a full disk): one line
        parser.exit(1, f"adaptimp {args.command}: error: {e}\n")
    return status


if __name__ == "__main__":
    raise SystemExit(main())
