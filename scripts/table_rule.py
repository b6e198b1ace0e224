"""The contact table's SF row with SPEC §18's rule in place of the table's
joint gains, learning constants and centres (docs/contact.md, "What was tried
on the heavy arms"): ``adaptimp.tuning.suggest`` along the joint orbit of the
circle on the table, the unified formulation at n = 0.3.

    python scripts/table_rule.py [--arm URDF ...] [--K1 20] [--gamma-scale 1] [--T 10]

Prints, per arm, the tracking (mm), along the table (mm), the force error,
the chatter (N), the time off the table (s), the peak normal force (N) and the
peak commanded torque over τmax. An arm given as "panda" is the Panda.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from adaptimp import cartesian as ac
from adaptimp import contact as act
from adaptimp import mujoco as amj
from adaptimp import tuning


def rule_keywords(sc: Any) -> dict[str, Any]:
    """tuning.suggest's keywords along the joint orbit of one circle (its start
    after the approach and the ramp), from the table's home."""
    outer = sc.outer()
    start = sc.t_approach + sc.t_ramp
    period = 1.0 / sc.freq
    steps = round((start + period) / sc.Ts)
    rot = sc.chain.fk(sc.q0)[:3, :3]
    table = np.array(
        [ac._sample(lambda t: sc.path(t, depth=0.0), k * sc.Ts, rot) for k in range(steps)]
    )
    q, dq = outer._core.orbit(sc.q0, table, steps)
    ddq = np.gradient(dq, sc.Ts, axis=0)
    k0 = round(start / sc.Ts)

    def path(t: float) -> tuple[Any, Any, Any]:
        k = min(k0 + round(t / sc.Ts), steps - 1)
        return q[k], dq[k], ddq[k]

    kw = tuning.suggest(
        amj.Plant(sc.model), sc.q0, sc.tau_max, Ts=sc.Ts, path=path, period=period, case="sf"
    )
    kw.pop("n")
    return dict(kw)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arm", nargs="+", default=["panda"], help="URDF paths, or panda")
    parser.add_argument("--K1", type=float, default=None, help="replace the rule's K1 (1/s)")
    parser.add_argument("--gamma-scale", type=float, default=1.0, help="times the rule's Γ")
    parser.add_argument("--T", type=float, default=10.0, help="duration (s)")
    args = parser.parse_args()
    for arm in args.arm:
        sc = act.arm_table(None if arm == "panda" else arm)
        kw = rule_keywords(sc)
        if args.K1 is not None:
            kw["K1"] = [args.K1] * sc.n
        gains = {k: kw.pop(k) for k in ("Kp", "Kzeta", "K1")}
        basis = (kw.pop("centers"), kw.pop("widths"))
        gamma = [g * args.gamma_scale for g in kw.pop("gamma")]
        for k in ("Ts", "tau_max"):
            kw.pop(k)
        ctrl = ac.panda_controller(
            "sf", sc, basis=basis, gains=gains, gamma=gamma, force_feedforward=False,
            formulation="unified", admittance_share=0.3, **kw,
        )  # fmt: skip
        res = amj.simulate(ctrl, amj.Plant(sc.model), T=args.T, q0=sc.q0)
        m = act.contact_metrics(res, ctrl, sc, settle=min(2.0, args.T / 2))
        print(
            f"{arm}: track {m['track_mm']:.3f} mm, along {m['track_along_mm']:.3f} mm, "
            f"force {m['force_rms_err_N']:.3f} N, chatter {m['force_chatter_N']:.3f} N, "
            f"off the table {m['contact_lost_s']:.3f} s, peak F_n {m['peak_force_N']:.1f} N, "
            f"peak τ/τmax {m['peak_tau_ratio']:.2f}"
        )


if __name__ == "__main__":
    main()
