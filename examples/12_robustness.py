"""A robustness study in one command: where do PD, state feedback and output
feedback break?

The robot scenario (Ts = 1 ms, the hardened options) against a payload on the
last link (0 … 2 kg, the plant's only: the controllers are model-free), sensor
noise on q and q̇ (σ_q = 0 … 2 mrad, σ_q̇ = 50 σ_q /s, seeded), and a
measurement delay (0 … 8 steps). Two sweeps on every core, drawn as heatmaps of
the RMS tracking error (t ≥ 2 s) and the saturation duty, written to
``robustness_noise.png`` and ``robustness_delay.png`` in the directory given
(default ``out/``; docs/sweeps.md's are ``python examples/12_robustness.py
docs/figures``), and the tables printed.

    python examples/12_robustness.py [output_dir]

Needs the extra ``sweep`` (pandas; from a checkout: ``pip install ".[sweep]"``).

``ADAPTIMP_QUICK=1`` runs a small, short grid.
"""

from __future__ import annotations

import argparse
import os
import sys
import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

import adaptimp
from adaptimp._params import CASE_NAMES

QUICK = bool(os.environ.get("ADAPTIMP_QUICK"))
PAYLOADS = [0.0, 1.0] if QUICK else [0.0, 0.5, 1.0, 1.5, 2.0]
NOISES = [0.0, 2e-3] if QUICK else [0.0, 0.5e-3, 1e-3, 1.5e-3, 2e-3]
DELAYS = [0, 8] if QUICK else [0, 2, 4, 6, 8]
T = 3.0 if QUICK else 20.0


def heatmaps(df: pd.DataFrame, x: str, xlabel: str, out: Path) -> None:
    fig, axes = plt.subplots(
        2, 3, figsize=(11, 6.5), layout="constrained", sharex=True, sharey=True, dpi=120
    )
    for col, case in enumerate(("pd", "sf", "of")):
        sub = df[df["case"] == case]
        for row, (metric, label, cmap) in enumerate(
            (
                ("rms_z1_after2", "RMS ‖z1‖, t ≥ 2 s (rad)", "viridis"),
                ("sat_duty", "saturation duty", "magma"),
            )
        ):
            table = sub.pivot(index="payload", columns=x, values=metric)
            ax = axes[row, col]
            data = np.log10(table.to_numpy()) if row == 0 else table.to_numpy()
            im = ax.imshow(data, origin="lower", aspect="auto", cmap=cmap,
                           vmin=np.log10(df[metric].min()) if row == 0 else 0.0,
                           vmax=np.log10(df[metric].max()) if row == 0 else 1.0)  # fmt: skip
            ax.set_xticks(range(len(table.columns)), [f"{v:g}" for v in table.columns])
            ax.set_yticks(range(len(table.index)), [f"{v:g}" for v in table.index])
            for (i, j), v in np.ndenumerate(table.to_numpy()):
                ax.text(j, i, f"{v:.3f}" if row == 0 else f"{v:.2f}", ha="center", va="center",
                        fontsize=7, color="w")  # fmt: skip
            if row == 0:
                ax.set_title(CASE_NAMES[case])
            if col == 0:
                ax.set_ylabel("payload (kg)")
            if row == 1:
                ax.set_xlabel(xlabel)
            if col == 2:
                cb = fig.colorbar(im, ax=axes[row, :], shrink=0.9)
                cb.set_label(("log10 " if row == 0 else "") + label)
    fig.suptitle(f"robot scenario, T = {T:g} s: {xlabel} × payload", fontsize=12)
    fig.savefig(out)
    plt.close(fig)


def main(out_dir: Path) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    cases = ["pd", "sf", "of"]
    # σ_q̇ = 50 σ_q: the two noises move together, one sweep over the payload per level.
    runs = [
        adaptimp.sweep(
            case,
            vary={"payload": PAYLOADS},
            scenario="robot",
            T=T,
            noise_q=nq,
            noise_dq=50 * nq,
        ).assign(noise_q=nq)
        for case in cases
        for nq in NOISES
    ]
    noise = pd.concat(runs, ignore_index=True)
    delay = adaptimp.sweep(
        "sf",
        vary={"case": cases, "payload": PAYLOADS, "delay": DELAYS},
        scenario="robot",
        T=T,
        progress=True,
    )
    for df in (noise, delay):
        bad = df["error"].dropna()
        if len(bad):
            print("failed runs:", bad.to_dict(), file=sys.stderr)
    heatmaps(noise.assign(noise_q=1e3 * noise["noise_q"]), "noise_q", "σ_q (mrad), σ_q̇ = 50 σ_q /s",
             out_dir / "robustness_noise.png")  # fmt: skip
    heatmaps(delay, "delay", "measurement delay (steps of 1 ms)", out_dir / "robustness_delay.png")
    for name, df, x in (("noise", noise, "noise_q"), ("delay", delay, "delay")):
        print(f"\nRMS ‖z1‖ (t ≥ 2 s, rad) against payload (rows) and {x} (columns)")
        for case in cases:
            table = df[df["case"] == case].pivot(index="payload", columns=x, values="rms_z1_after2")
            print(f"\n{CASE_NAMES[case]} ({name}):")
            print(table.to_string(float_format=lambda v: f"{v:.4f}"))
    print(f"\nwrote {out_dir}/robustness_noise.png and robustness_delay.png")


if __name__ == "__main__":
    doc = (__doc__ or "").split("\n\n")
    parser = argparse.ArgumentParser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(doc[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "output", nargs="?", type=Path, default=Path("out"),
        help="the directory of the figures (default: out)",
    )  # fmt: skip
    main(parser.parse_args().output)
