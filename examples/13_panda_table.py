"""The Panda on a table (scenario "panda-table", docs/panda.md): one command, one table.

The Franka Emika Panda (example-robot-data's URDF, effort limits 87/12 N m) in
MuJoCo draws a 5 cm circle at 0.25 Hz on a table with its tool while pressing
δ_c = 15 mm into it through the target impedance (SPEC §16: M_d = 2 kg,
K_d = 500 N/m, B_d critically damped, position-only). Every controller has the
same outer loop, the core's (``adaptimp.CartesianController`` over the Panda's
``adaptimp.Chain``, scenario in ``adaptimp.panda_table``); the joint controller
differs:

- PD, adaptive state feedback (SF), adaptive output feedback (OF):
  ``adaptimp.Controller(case, "robot", n=7, impedance="external")`` at 1 kHz,
  the same gains Kp_i = 0.25/(Ts (D⁻¹)_ii) (D = D(q0) from Pinocchio),
  Kζ_i = (1 + Kp_i²)/2 + 10, K1 = 20; SF and OF learn with Γ = 1 on 64 RBF
  centres along the joint orbit of the circle (SPEC §15).
- CT, CT+30%: computed torque with Pinocchio's RNEA/CRBA, the exact model and
  every link's mass and inertia +30 %, K_P = 400 s⁻², K_D = 40 s⁻¹.

Metrics over t ≥ 2 s (p the TCP, p_d the compliant reference, F_n = −F_e,z):

- track: RMS ‖p_d − p‖ (mm), the Cartesian tracking error.
- force: RMS (F_n − K_d δ_c) (N), the normal force against the target's
  steady value against a rigid table (SPEC (16.1)), 7.5 N.
- imp: RMS ‖M_d (p̈ − p̈_c) + B_d (ṗ − ṗ_c) + K_d (p − p_c) + F_e‖ (N), the
  residual of the target impedance at the arm's motion.
- sat: fraction of all steps with some sat(τ_i) ≠ τ_i.
- peak: max_i max_{t ≥ 0.1 s} |τ_i| / τmax_i of the commanded τ (≤ 2: no windup).

Needs the extras ``mujoco`` and ``pinocchio`` (from a checkout:
``pip install ".[mujoco,pinocchio]"``). Run ``python examples/13_panda_table.py``
(T = 20 s; ``--long 120`` adds a long SF run reporting the weight norms);
``ADAPTIMP_QUICK=1``: T = 1 s, no figure.
Writes ``docs/figures/panda_table.png``.
"""

from __future__ import annotations

import argparse
import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from adaptimp import cartesian as ac
from adaptimp import mujoco as amj

QUICK = os.environ.get("ADAPTIMP_QUICK") == "1"
KINDS = {
    "pd": "PD",
    "sf": "SF as printed (+τe, Γ = 1)",
    "of": "OF as printed (+τe, Γ = 1)",
    "sf-noff": "SF, no τe feedforward, Γ = 1",
    "sf-learn": "SF, no τe feedforward, gravity learning",
    "of-learn": "OF, no τe feedforward, gravity learning",
    "ct": "CT exact",
    "ct+30": "CT +30% mass",
}
# "Gravity learning": the Ĝ network learns fast and forgets slowly (ΓG = 5000,
# σG = 1e-5; the normalised step keeps it stable), with a bound of 100 N m on
# ‖ŴG‖ (the "auto" bound, 21.9, is binding: gravity along the orbit needs 27.8).
LEARN = {
    "gamma": [1.0, 1.0, 5000.0],
    "sigma": [0.01, 0.01, 1e-5],
    "weight_bound": [4.19, 13.2, 100.0],
}
FIGURE = Path(__file__).resolve().parent.parent / "docs" / "figures" / "panda_table.png"


def run(kind: str, sc: ac.PandaTable, basis: Any, T: float) -> tuple[Any, Any, dict[str, float]]:
    """One controller on the panda-table scenario: (result, controller, metrics)."""
    base, _, variant = kind.partition("-")
    extra: dict[str, Any] = LEARN if variant == "learn" else {}
    ctrl = ac.panda_controller(base, sc, basis=basis, force_feedforward=variant == "", **extra)
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=T, q0=sc.q0)
    return res, ctrl, ac.cartesian_metrics(res, ctrl, sc, settle=min(2.0, T / 2))


def figure(res: Any, ctrl: Any, sc: ac.PandaTable, path: Path) -> None:
    """Path on the table, normal force against the target, torques against limits."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    log = ctrl.arrays()
    fig = plt.figure(figsize=(12, 7.5), layout="constrained")
    grid = fig.add_gridspec(2, 2)
    ax = fig.add_subplot(grid[:, 0])
    a = res.t >= 2.0
    ax.plot(log["pc"][a, 0], log["pc"][a, 1], "k--", lw=1, label="p_c, commanded")
    ax.plot(res.x_ee[:, 0], res.x_ee[:, 1], color="tab:blue", lw=0.8, label="p, TCP (all t)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("SF: the path on the table")
    ax.legend(loc="upper right", fontsize=8)
    ax = fig.add_subplot(grid[0, 1])
    fn = -res.wrench_ee[:, 2]
    ax.plot(res.t, fn, color="tab:blue", lw=0.4, label="F_n, measured")
    kernel = np.ones(50) / 50
    ax.plot(res.t, np.convolve(fn, kernel, "same"), color="tab:green", lw=1.2, label="50 ms mean")
    ax.axhline(sc.target_force(), color="k", ls="--", lw=1, label="K_d δ_c (target)")
    ax.set_ylabel("normal force (N)")
    ax.set_xlabel("t (s)")
    ax.legend(loc="upper right", fontsize=8, ncol=3)
    ax = fig.add_subplot(grid[1, 1])
    ratio = res.tau / np.asarray(res.params["tau_max"])
    for i in range(sc.n):
        ax.plot(res.t, ratio[:, i], lw=0.6, label=f"τ{i + 1}")
    ax.axhline(1, color="tab:red", ls="--", lw=1)
    ax.axhline(-1, color="tab:red", ls="--", lw=1, label="±τmax")
    ax.set_ylabel("τ_i / τmax_i (commanded)")
    ax.set_xlabel("t (s)")
    ax.legend(loc="upper right", fontsize=7, ncol=4)
    fig.suptitle("Panda on a table, adaptive state feedback (examples/13_panda_table.py)")
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def long_run(sc: ac.PandaTable, basis: Any, T: float) -> None:
    """SF (without the τe feedforward) for T seconds on the plant directly; prints
    ‖Ŵ‖_F every 10 s."""
    ctrl = ac.panda_controller("sf", sc, basis=basis, force_feedforward=False, **LEARN)
    plant = amj.Plant(sc.model)
    plant.reset(sc.q0)
    substeps = max(1, round(sc.Ts / plant.timestep))
    plant.timestep = sc.Ts / substeps
    print(f"\nlong run, SF without τe feedforward, gravity learning, T = {T:g} s: weight norms")
    print("| t (s) | ‖W_D‖ | ‖W_C‖ | ‖W_G‖ | max |τ_i|/τmax_i applied |")
    print("|---:|---:|---:|---:|---:|")
    peak = 0.0
    for k in range(round(T / sc.Ts)):
        wrench = plant.wrench()
        tau = ctrl.step(plant.q, plant.dq, wrench)
        peak = max(peak, float(np.max(np.abs(plant.apply(tau)) / plant.tau_max)))
        plant.step(substeps)
        plant.forward()
        if (k + 1) % round(10.0 / sc.Ts) == 0:
            sd = ctrl.inner.state_dict()
            norms = [float(np.linalg.norm(sd[w])) for w in ("W_D", "W_C", "W_G")]
            print(
                f"| {(k + 1) * sc.Ts:.0f} | "
                + " | ".join(f"{v:.3g}" for v in norms)
                + f" | {peak:.3f} |"
            )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--T", type=float, default=1.0 if QUICK else 20.0, help="duration (s)")
    parser.add_argument("--long", type=float, default=0.0, help="also a long SF run (s)")
    args = parser.parse_args()
    sc = ac.panda_table()
    basis = ac.orbit_basis(sc)
    print(
        f"panda-table: {sc.radius * 100:g} cm circle at {sc.freq:g} Hz, δ_c = "
        f"{sc.depth * 1e3:g} mm (target {sc.target_force():g} N), T = {args.T:g} s, "
        f"{basis[0].shape[0]} centres, η_q = {basis[1][0]:.3g} rad, η_v = {basis[1][7]:.3g} rad/s"
    )
    print("\n| controller | track (mm) | force (N) | imp (N) | sat | peak τ/τmax | time (s) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    keep: dict[str, Any] = {}
    for kind, label in KINDS.items():
        t0 = time.perf_counter()
        res, ctrl, m = run(kind, sc, basis, args.T)
        keep[kind] = (res, ctrl)
        print(
            f"| {label} | {m['rms_track'] * 1e3:.3f} | {m['rms_force']:.2f} | {m['rms_imp']:.2f} "
            f"| {m['sat_duty']:.3f} | {m['peak_tau_ratio']:.3f} | {time.perf_counter() - t0:.1f} |"
        )
        assert m["applied_ratio"] <= 1.0 + 1e-12, "applied torque beyond its limit"
    if not QUICK:
        figure(*keep["sf-learn"], sc, FIGURE)
        print(f"\nwrote {FIGURE}")
    if args.long > 0:
        long_run(sc, basis, args.long)


if __name__ == "__main__":
    main()
