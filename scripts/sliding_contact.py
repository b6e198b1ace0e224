"""MuJoCo's sliding contact, reduced to a point (docs/contact.md, SPEC §19, (19.5)).

A sphere of 1 cm on three slide joints (a point of mass m, no gravity: the arm's
controller carries the arm's weight) is pressed on a rigid box with a constant
force F and kept sliding along x at speed v (a constant push μF plus a
velocity servo). The table's normal force should stay at F. With MuJoCo's
default contact it does not: the convex contact trades the friction rows'
unmet reference against the normal row, and the point lifts off for single
steps. The rows:

- ``pyramidal`` / ``elliptic``: MuJoCo's default contact (pyramidal cone) and
  the elliptic cone, everything else default;
- ``elliptic, tau_t = …``: the elliptic cone with the tool–table pair's
  friction time constant (``solreffriction``) set to a value; ``(19.5)``: set
  by :func:`adaptimp.contact.sliding_timeconst`;
- ``frictionless …``: μ = 0 with each cone.

Columns over the last 2 s of 3 s at MuJoCo's 0.5 ms step: mean and standard
deviation of the normal force (N), its chatter (RMS of the step-to-step change,
N), the share of steps without force, and (19.4)'s B_crit, the friction
damping above which the point lifts off (1/s).

    python scripts/sliding_contact.py            # the Panda's tool: 2.35 kg, 7.5 N, 7.85 cm/s
    python scripts/sliding_contact.py --mass 10 --json out.json

Needs the extra ``mujoco``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

from adaptimp.scenarios import contact as act

MASS = 2.35
"""kg: the Panda tool's inverse-mass approximation in MuJoCo (``body_invweight0``
of the tool body, 0.426 1/kg)."""
FORCE = 7.5
"""N: the table scenario's prescribed force K_d δ_c."""
SPEED = 2 * math.pi * 0.25 * 0.05
"""m/s: the scenario's circle speed (5 cm at 0.25 Hz)."""


def model(*, mass: float, friction: float, cone: str, timeconst: float | None) -> mujoco.MjModel:
    """The point on the box; ``timeconst`` (s): the pair's friction time constant
    (None: no explicit pair, MuJoCo's default contact)."""
    pair = (
        ""
        if timeconst is None
        else f"""<contact><pair geom1="tool" geom2="table" condim="3"
        friction="{friction} {friction} 0.005 0.0001 0.0001"
        solreffriction="{timeconst} 1"/></contact>"""
    )
    xml = f"""<mujoco><option timestep="0.0005" gravity="0 0 0" cone="{cone}"/>
    <worldbody>
      <geom name="table" type="box" size="50 50 0.025" pos="0 0 -0.025"
        friction="{friction} 0.005 0.0001"/>
      <body pos="0 0 0.01">
        <joint type="slide" axis="1 0 0"/><joint type="slide" axis="0 1 0"/>
        <joint type="slide" axis="0 0 1"/>
        <geom name="tool" type="sphere" size="0.01" mass="{mass}"
          friction="{friction} 0.005 0.0001"/>
      </body>
    </worldbody>{pair}</mujoco>"""
    return mujoco.MjModel.from_xml_string(xml)


def slide(
    *,
    mass: float = MASS,
    force: float = FORCE,
    speed: float = SPEED,
    friction: float = 0.1,
    cone: str = "pyramidal",
    timeconst: float | None = None,
    T: float = 3.0,
) -> dict[str, float]:
    """Run the point for ``T`` s; the normal force's statistics over the last 2 s
    (see the module doc)."""
    m = model(mass=mass, friction=friction, cone=cone, timeconst=timeconst)
    d = mujoco.MjData(m)
    d.qvel[0] = speed
    out = np.zeros(6)
    steps = round(T / m.opt.timestep)
    fn = np.zeros(steps)
    for k in range(steps):
        # Constant push against kinetic friction, a velocity servo (80 N s/m,
        # 34 ms on 2.35 kg) for the rest, and the constant pressing force.
        d.qfrc_applied[:3] = [friction * force + 80.0 * (speed - d.qvel[0]), 0.0, -force]
        mujoco.mj_step(m, d)
        for i in range(d.ncon):
            mujoco.mj_contactForce(m, d, i, out)
            fn[k] += out[0]
    tail = fn[steps - round(2.0 / m.opt.timestep) :]
    return {
        "mean_N": float(tail.mean()),
        "std_N": float(tail.std()),
        "chatter_N": float(np.sqrt(np.mean(np.diff(tail) ** 2))),
        "no_force_share": float(np.mean(tail <= 0.0)),
        "speed_m_s": float(d.qvel[0]),
    }


def critical_damping(
    *, mass: float = MASS, force: float = FORCE, speed: float = SPEED, friction: float = 0.1
) -> float:
    """(19.4)'s B_crit = F (1 − d) A/(d μ v) (1/s) with d = MuJoCo's impedance at
    zero penetration (``solimp``'s d_min, 0.9) and A = 1/m."""
    dmin = 0.9
    return force * (1 - dmin) / (mass * dmin * friction * speed)


def rows(mass: float) -> dict[str, dict[str, float]]:
    """The table of the module doc for a point of ``mass`` kg."""
    rule = act.sliding_timeconst(
        model(mass=mass, friction=0.1, cone="elliptic", timeconst=0.02),
        force=FORCE,
        speed=SPEED,
        friction=0.1,
    )
    table: dict[str, dict[str, float]] = {
        "pyramidal (MuJoCo's default)": slide(mass=mass),
        "elliptic": slide(mass=mass, cone="elliptic"),
    }
    for tc in (0.02, 0.03, 0.04, 0.05, 0.1, 0.2, 0.3):
        table[f"elliptic, tau_t = {tc:g} s"] = slide(mass=mass, cone="elliptic", timeconst=tc)
    table[f"elliptic, tau_t = {rule:.3g} s (19.5)"] = slide(
        mass=mass, cone="elliptic", timeconst=rule
    )
    table["frictionless, pyramidal"] = slide(mass=mass, friction=0.0)
    table["frictionless, elliptic"] = slide(mass=mass, friction=0.0, cone="elliptic")
    return table


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--mass", type=float, default=MASS, help="the point's mass (kg)")
    parser.add_argument("--json", type=str, default=None, help="write the table as JSON here")
    args = parser.parse_args()
    bc = critical_damping(mass=args.mass)
    print(
        f"point of {args.mass:g} kg pressed with {FORCE:g} N, sliding at {SPEED * 100:.2f} cm/s, "
        f"friction 0.1: (19.4) B_crit = {bc:.1f} 1/s (tau_t = 2/(0.95 B) = "
        f"{2 / (0.95 * bc):.3f} s)\n"
    )
    print("| contact | mean (N) | std (N) | chatter (N) | steps without force |")
    print("|---|---:|---:|---:|---:|")
    table = rows(args.mass)
    for name, r in table.items():
        print(
            f"| {name} | {r['mean_N']:.3f} | {r['std_N']:.3f} | {r['chatter_N']:.3f} "
            f"| {r['no_force_share'] * 100:.1f} % |"
        )
    if args.json:
        out: dict[str, Any] = {"B_crit": bc, "rows": table}
        Path(args.json).write_text(json.dumps(out, indent=2) + "\n")
        print(f"\nwrote {args.json}")


if __name__ == "__main__":
    main()
