"""The paper's controllers at a robot's 1 kHz: printed laws against hardened options.

Runs state and output feedback at Ts = 1 ms (M = 10 RK4 substeps) twice: with
the laws as printed (``scenario="paper", Ts=1e-3, substeps=10``) and with the
hardened options of SPEC §13 (``scenario="robot"``), prints the SPEC §12
metrics and writes a figure, by default ``out/robot_1khz.png``: the
tracking error of joint 1 and the commanded torque of joint 1 for each
(docs/robot.md's is ``python examples/02_robot_1khz.py
docs/figures/robot_1khz.png``).

    python examples/02_robot_1khz.py [output.png]

Mirrored in Rust by ``examples/02_robot_1khz.rs``. ``ADAPTIMP_QUICK=1`` runs 3 s.
"""

from __future__ import annotations

import argparse
import os
import textwrap
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

import adaptimp
from adaptimp._params import CASE_NAMES

RUNS = {
    "printed": {"scenario": "paper", "Ts": 1e-3, "substeps": 10},
    "hardened": {"scenario": "robot"},
}
COLORS = {"printed": "#d62728", "hardened": "#1f77b4"}


def main(out: Path) -> None:
    T = 3.0 if os.environ.get("ADAPTIMP_QUICK") else 20.0
    # The printed laws are unstable at 1 ms, as their StabilityWarning says: that is the point.
    warnings.simplefilter("ignore", adaptimp.StabilityWarning)
    res = {
        (case, name): adaptimp.simulate(case, T=T, **kw)
        for case in ("sf", "of")
        for name, kw in RUNS.items()
    }
    print("| case | laws | RMS ‖z1‖, t ≥ 2 s (rad) | saturation duty | peak |τ| (N m) |")
    print("|---|---|---:|---:|---:|")
    for (case, name), r in res.items():
        m = r.metrics
        peak = ", ".join(f"{v:.1f}" for v in m["peak_abs_tau"])
        print(f"| {case} | {name} | {m['rms_z1_after2']:.5f} | {m['sat_duty']:.3f} | {peak} |")

    fig, axes = plt.subplots(2, 2, sharex=True, figsize=(10, 6.4), layout="constrained", dpi=100)
    fig.suptitle("At Ts = 1 ms: the printed laws against the hardened options (joint 1)")
    for col, case in enumerate(("sf", "of")):
        err, tau = axes[0, col], axes[1, col]
        for name in RUNS:
            r = res[(case, name)]
            rms = r.metrics["rms_z1_after2"]
            err.plot(
                r.t, r.z1[:, 0], color=COLORS[name], lw=0.8, label=f"{name} (RMS {rms:.4f} rad)"
            )
            tau.plot(r.t, r.tau[:, 0], color=COLORS[name], lw=0.8, label=name)
        tau_max = res[(case, "hardened")].params["tau_max"][0]
        for sign in (1, -1):
            tau.axhline(sign * tau_max, color="k", ls="--", lw=0.8)
        # Linear within ±2τmax (where the hardened torque lives), logarithmic beyond.
        tau.set_yscale("symlog", linthresh=2 * tau_max)
        ticks = [-1e4, -1e3, -1e2, -tau_max, 0.0, tau_max, 1e2, 1e3, 1e4]
        tau.set_yticks(ticks, [f"{t:g}" for t in ticks])
        err.set_title(CASE_NAMES[case])
        err.set_ylabel("tracking error z1 of joint 1 (rad)")
        err.set_ylim(-0.6, 0.6)
        tau.set_ylabel("commanded torque τ1 (N m, symlog)")
        tau.set_xlabel("time t (s)")
        tau.text(19.8, 1.25 * tau_max, "τmax", fontsize=8, ha="right", va="bottom")
        err.legend(loc="lower right", fontsize=8)
        for ax in (err, tau):
            ax.grid(True, alpha=0.3)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    print(f"figure written to {out}")


if __name__ == "__main__":
    doc = (__doc__ or "").split("\n\n")
    parser = argparse.ArgumentParser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(doc[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "output", nargs="?", type=Path, default=Path("out") / "robot_1khz.png",
        help="the figure (default: out/robot_1khz.png)",
    )  # fmt: skip
    main(parser.parse_args().output)
