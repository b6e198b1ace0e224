"""Your own control loop: a 3-joint planar arm under gravity, stepped at 1 kHz by
the adaptive state-feedback controller, tracking setpoints that come from outside
(a planner, a teleoperation device, a file) rather than the controller's own
trajectory. Prints the RMS tracking error of PD and of the adaptive controller
over the last 2 s.

    python examples/03_your_loop.py

Mirrored in Rust by ``examples/03_your_loop.rs``. ``ADAPTIMP_QUICK=1`` shortens it.
"""

from __future__ import annotations

import argparse
import os
import textwrap

import numpy as np

import adaptimp
from adaptimp import Measurement

N = 3
TS = 1e-3  # s


def setpoint(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The planner's path at t (s): position (rad), velocity (rad/s), acceleration (rad/s²)."""
    x = np.full(N, 0.2 + 0.1 * np.sin(t))
    return x, np.full(N, 0.1 * np.cos(t)), np.full(N, -0.1 * np.sin(t))


def run(case: str, seconds: float) -> float:
    """RMS ‖z1‖ (rad) over the last 2 s of a run."""
    arm = adaptimp.PlanarArm(N, masses=1.0, lengths=0.25)  # 1 kg, 0.25 m rods; g = 9.81
    # The robot scenario's hardened options; gains for these light links.
    ctrl = adaptimp.Controller(
        case, "robot", n=N, Kp=2.0, Kzeta=10.0, K1=10.0, tau_max=40.0,
        xc_offset=0.2, xc_sin=0.1, xc_cos=0.0, xc_omega=1.0,  # sets the "auto" weight bounds
    )  # fmt: skip
    q, dq = np.zeros(N), np.zeros(N)
    steps = round(seconds / TS)
    last = round(2.0 / TS)
    z1 = []
    for k in range(steps):
        xc, dxc, ddxc = setpoint(k * TS)
        tau = ctrl.step(Measurement(q, dq, tau_e=np.zeros(N)), xc=xc, dxc=dxc, ddxc=ddxc)
        dq = dq + TS * arm.forward_dynamics(q, dq, tau, np.zeros(N))  # semi-implicit Euler
        q = q + TS * dq
        if k + last >= steps:
            z1.append(ctrl.z1)
    return float(np.sqrt(np.mean(np.sum(np.square(z1), axis=1))))


def main() -> None:
    seconds = 2.5 if os.environ.get("ADAPTIMP_QUICK") else 10.0
    print(f"3-joint planar arm under gravity, 1 kHz, setpoints from outside, {seconds} s")
    pd, sf = run("pd", seconds), run("sf", seconds)
    print(f"RMS ‖z1‖ over the last 2 s: PD {pd:.4f} rad, adaptive state feedback {sf:.4f} rad")


if __name__ == "__main__":
    # --help: what the example does and how to run it (it takes no arguments).
    doc = (__doc__ or "").split("\n\n")
    argparse.ArgumentParser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(p for p in doc[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    ).parse_args()
    main()
