"""A 7-joint arm's 6-D Cartesian loop (SPEC §16), the same in Rust
(``examples/14_cartesian_pose.rs``), Python and C: the Franka Emika Panda's
kinematics from its URDF (example-robot-data), the core's Cartesian controller
(6-D outer loop, hardened state feedback with RBF centres along the joint
orbit), and a simple plant: decoupled joint inertias I q̈ = sat(τ) − Jᵀ F_e, no
gravity, against a table (a penalty plane, k_e = 5000 N/m, b_e = 50 N s/m).

The tool goes 5 cm forward and 4 cm down in 1 s (a quintic) while turning 20°
about the vertical: 1 cm into the table. Then it holds. Prints the pose error
during the motion, the contact force against what the target impedance
prescribes, (16.1), and the torques. ``ADAPTIMP_QUICK=1``: 1.2 s.

    python examples/14_cartesian_pose.py
"""

from __future__ import annotations

import argparse
import math
import os
import textwrap

import numpy as np

import adaptimp
from adaptimp import Measurement, _models

TS = 1e-3
INERTIA = np.array([0.27, 0.97, 0.54, 0.40, 0.037, 0.034, 0.0065])  # kg m²
TAU_MAX = np.array(_models.PANDA_EFFORT)  # N m
HOME = np.array(_models.PANDA_HOME)  # rad
KE, BE, BELOW = 5000.0, 50.0, 0.03  # the table: N/m, N s/m, m below the home TCP
# ‖ŴD‖, ‖ŴC‖, ‖ŴG‖ ≤ ‖τmax‖/√L over 10 rad/s², 1 rad/s, 1 (L = 32), rounded.
WEIGHT_BOUND = [3.1, 31.0, 31.0]


def rot_z(angle: float) -> np.ndarray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def target(p0: np.ndarray, r0: np.ndarray, t: float) -> tuple[np.ndarray, ...]:
    """The commanded pose at t (s): 5 cm along x, 4 cm down, 20° about z in 1 s."""
    s = min(max(t, 0.0), 1.0)
    f = s**3 * (10 - 15 * s + 6 * s * s)
    df, ddf = 30 * s * s * (1 - s) ** 2, 60 * s * (1 - s) * (1 - 2 * s)
    d, yaw = np.array([0.05, 0.0, -0.04]), math.radians(20.0)
    w = np.array([0.0, 0.0, yaw])
    return p0 + f * d, df * d, ddf * d, rot_z(f * yaw) @ r0, df * w, ddf * w


def table(z_table: float, p: np.ndarray, dp: np.ndarray) -> np.ndarray:
    """The wrench the tool exerts on the table (pressing down: f_z < 0)."""
    depth = z_table - p[2]
    push = max(0.0, KE * depth - BE * dp[2]) if depth > 0 else 0.0
    return np.array([0.0, 0.0, -push, 0.0, 0.0, 0.0])


def main() -> None:
    chain = adaptimp.Chain.from_urdf(_models.panda_urdf_path(), tip=_models.PANDA_EE)
    p0, r0 = chain.pose(HOME)
    z_table = p0[2] - BELOW
    kp = 0.25 * INERTIA / TS
    common = {"q0": HOME, "path": lambda t: target(p0, r0, t)}
    outer = adaptimp.cartesian.CartesianImpedance(chain, Ts=TS, q0=HOME)
    centres, widths = outer.orbit_centres(common["path"], 1.5, nodes=32, tube=(0.05, 0.2))
    ctrl = adaptimp.CartesianController(
        chain,
        "sf",
        "robot",
        centers=centres,
        widths=widths,
        Ts=TS,
        tau_max=TAU_MAX.tolist(),
        Kp=kp.tolist(),
        Kzeta=((1 + kp**2) / 2 + 10).tolist(),
        K1=20.0,
        gamma=1.0,
        weight_bound=WEIGHT_BOUND,
        record=False,
        **common,
    )
    q, dq = HOME.copy(), np.zeros(7)
    t_final = 1.2 if os.environ.get("ADAPTIMP_QUICK") == "1" else 2.0
    worst_p = worst_r = peak = 0.0
    wrench = np.zeros(6)
    for k in range(round(t_final / TS)):
        t = k * TS
        jac = chain.jacobian(q)
        p, rot = chain.pose(q)
        wrench = table(z_table, p, jac[:3] @ dq)
        tau = ctrl.step(Measurement(q, dq, wrench=wrench))
        if 0.2 <= t < 0.6:
            pc, _, _, rc, _, _ = target(p0, r0, t)
            worst_p = max(worst_p, float(np.linalg.norm(p - pc)))
            worst_r = max(worst_r, angle(rc @ rot.T))
        peak = max(peak, float(np.max(np.abs(tau) / TAU_MAX)))
        h = TS / 10
        for _ in range(10):  # the plant: 10 semi-implicit Euler substeps, τ held
            jac = chain.jacobian(q)
            p, _ = chain.pose(q)
            f = table(z_table, p, jac[:3] @ dq)
            dq = dq + h * (tau - jac.T @ f) / INERTIA
            q = q + h * dq
    pc, _, _, rc, _, _ = target(p0, r0, t_final)
    pd, pm, rm = ctrl.outer.last("p_d"), ctrl.outer.last("p"), ctrl.outer.last("R")
    kd = ctrl.outer.params["Kd"][2]
    depth, ne = z_table - pc[2], pd[2] - pm[2]
    print(
        f"Panda (7 joints), 6-D Cartesian impedance, state feedback, Ts = 1 ms, t = {t_final:g} s"
    )
    print(
        f"  moving (0.2 s ≤ t < 0.6 s): |p − p_c| ≤ {worst_p * 1e3:.3f} mm, "
        f"|e_o| ≤ {worst_r * 1e3:.3f} mrad"
    )
    print(f"  normal force on the table       = {-wrench[2]:.3f} N")
    print(f"  target impedance K_d (p_c − p_d)_z = {-kd * (pc[2] - pd[2]):.3f} N")
    print(
        f"  (16.1): K_d k_e/(K_d + k_e)(δ_c + n·e) = {kd * KE / (kd + KE) * (depth + ne):.3f} N "
        f"(δ_c = {depth * 1e3:.1f} mm, n·e = {ne * 1e3:.4f} mm)"
    )
    print(
        f"  orientation error |Log(R_c Rᵀ)| = {angle(rc @ rm.T) * 1e3:.3f} mrad; "
        f"peak |τ_i|/τmax_i = {peak:.3f}"
    )


def angle(r: np.ndarray) -> float:
    """The rotation angle of r (rad)."""
    return math.atan2(
        np.linalg.norm([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]]), np.trace(r) - 1
    )


if __name__ == "__main__":
    # --help: what the example does and how to run it (it takes no arguments).
    doc = (__doc__ or "").split("\n\n")
    argparse.ArgumentParser(
        description=textwrap.fill(" ".join(doc[0].split()), 79),
        epilog="\n\n".join(p for p in doc[1:]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    ).parse_args()
    main()
