"""adaptimp's native Cartesian loop on MuJoCo against the loop a MuJoCo user writes,
per control period, side by side in one run.

The arms: the UR5 of example-robot-data as ``adaptimp.mujoco.from_urdf``
compiles it (MuJoCo's RK4 at 1 ms: one step a period), with a site at the
URDF's ``tool0``, and the Panda of ``adaptimp.mujoco.panda(table_height=None)``
(free space, RK4 at 0.5 ms: two steps a period, its site ``ee``), each from
its home posture; the task: the tool's position along a 5 cm circle at 0.5 Hz about its start,
the orientation held (6-D), the commanded pose a Python function of t
called once per period by both loops. The control period Ts = 1 ms in both,
the torque held for the period's MuJoCo steps.

- **adaptimp**: ``adaptimp.CartesianController.from_rule(chain, "sf", circle,
  q0, model=plant)`` (the core's 6-D Cartesian impedance of SPEC §16 in
  front of the adaptive state feedback, which learns as it runs; gains,
  centres and learning by the rule, SPEC (16.10)–(16.12) and §18, from the
  arm's model and the circle's joint path over one period; nothing set per
  arm), run by ``adaptimp.mujoco.simulate`` (the loop in the core: MuJoCo
  through its C library, the controller and the path's call each period,
  the log and the metrics).
- **the user's loop**, as in kevinzakka/mjctrl's ``opspace.py``: each period,
  in Python, ``mj_jacSite`` and ``mj_fullM``, the operational-space law
  τ = Jᵀ Λ (K_p e − K_d J q̇) + (I − Jᵀ J̄ᵀ)(k_n (q_0 − q) − d_n q̇) + the
  bias ``qfrc_bias`` with Λ = (J M⁻¹ Jᵀ)⁻¹, J̄ = M⁻¹ Jᵀ Λ and the
  orientation error from MuJoCo's quaternion functions (``mju_mat2Quat``,
  ``mju_negQuat``, ``mju_mulQuat``, ``mju_quat2Vel``), the torque clipped to
  ``ctrlrange`` and set in ``ctrl``, then ``mj_step`` for the period's steps.

Both runs track the circle (checked: the RMS position error after 1 s is
printed, and must be below 5 mm), runs of ``--T`` and 2 ``--T`` repeated
``--repeats`` times interleaved; per period, the difference of their
medians over the extra periods (what a run costs once is not a period's
cost; the whole run's time a period is printed too). Target (issue 32): adaptimp ≤
0.5× the user's loop.
``--count`` also counts instructions per period under callgrind (two runs of
each loop, of ``--T`` and 2 ``--T``: the difference over the extra periods).

``--tracking`` compares tracking instead of time (:func:`tracking`): each
loop's RMS position error over the last 2 s of a 12 s run, once learning has
run, on the nominal arm and with a payload of 10 % of the arm's moving mass
on its last link that neither the OSC's model (M, the bias, evaluated on the
nominal arm at the measured state) nor adaptimp's rule knows of. Target
(issue 42): adaptimp ≤ 1.5× the user's OSC with the exact model.

    python benches/mujoco_user_loop.py [--T 2] [--repeats 5] [--arms ur5 panda] [--count]
    python benches/mujoco_user_loop.py --tracking [--json] [--arms ur5 panda]
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np

import adaptimp
from adaptimp import _plant_models
from adaptimp import mujoco as amj

TS = 1e-3  # s: the control period of both loops
RADIUS, OMEGA = 0.05, np.pi  # m, rad/s: 0.5 Hz


SITES = {"panda": "ee", "ur5": "tool0"}


def arm(name: str) -> tuple[Any, np.ndarray, adaptimp.Chain]:
    """The arm's MuJoCo model (with its tool's site), home posture and chain."""
    if name == "panda":
        model = amj.panda(table_height=None)
        q0 = np.array(adaptimp._models.PANDA_HOME)
    else:
        # The UR5 of example-robot-data as adaptimp.mujoco.from_urdf compiles it
        # (RK4 at 1 ms, a motor per joint), with a site at the URDF's tool0.
        import pinocchio as pin

        from adaptimp import _models

        urdf = _models.panda_urdf_path().parents[2] / "ur_description/urdf/ur5_robot.urdf"
        arm_urdf = _plant_models.urdf_arm(urdf, None, ())
        pm = pin.buildModelFromXML(arm_urdf.urdf)
        tool = pm.frames[pm.getFrameId("tool0")].placement
        spec = _plant_models.arm_spec(arm_urdf, 1e-3, drive=False, stacklevel=2)
        quat = np.zeros(4)
        mujoco.mju_mat2Quat(quat, np.ascontiguousarray(tool.rotation).ravel())
        spec.body("wrist_3_link").add_site(name="tool0", pos=tool.translation, quat=quat)
        model = _plant_models.compile_arm(spec)
        q0 = np.array([0.0, -1.2, 1.2, -1.5, -1.5, 0.0])
    return model, q0, adaptimp.Chain.from_mujoco(model, SITES[name])


def circle(p0: np.ndarray) -> Callable[[float], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    def path(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        c, s = np.cos(OMEGA * t), np.sin(OMEGA * t)
        return (
            p0 + RADIUS * np.array([c - 1.0, s, 0.0]),
            RADIUS * OMEGA * np.array([-s, c, 0.0]),
            -RADIUS * OMEGA * OMEGA * np.array([c, s, 0.0]),
        )

    return path


def circle_table(p0: np.ndarray, R0: np.ndarray, steps: int) -> Any:
    """The circle of :func:`circle` at t_k = k·Ts, k < ``steps``, as the path
    a user of the native loop gives: its table (p, ṗ, p̈, R, ω, ω̇), computed
    at once, which the core reads row by row (no Python in the loop)."""
    from adaptimp._cartesian_task import TablePath

    t = np.arange(steps) * TS
    c, s, z = np.cos(OMEGA * t), np.sin(OMEGA * t), np.zeros(steps)
    p = p0 + RADIUS * np.stack([c - 1.0, s, z], axis=1)
    dp = RADIUS * OMEGA * np.stack([-s, c, z], axis=1)
    ddp = -RADIUS * OMEGA * OMEGA * np.stack([c, s, z], axis=1)
    rest = np.zeros((steps, 3))
    return TablePath((p, dp, ddp, np.broadcast_to(R0, (steps, 3, 3)), rest, rest), TS)


def adaptimp_loop(
    name: str,
    T: float,
    python_path: bool = False,
    payload: float = 0.0,
    window: tuple[float, float] = (1.0, math.inf),
) -> tuple[Callable[[], float], Callable[[], float]]:
    """(run: the seconds of one run, setup included; the last run's RMS
    position error over ``window`` (s), by default after 1 s).

    The commanded pose: the circle's table (:func:`circle_table`, built in
    each timed run), or with ``python_path`` the user's Python function
    :func:`circle` itself (called once per period, before the loop starts).
    ``payload`` (kg): a point mass on the last link of the arm the loop
    drives (:func:`adaptimp.mujoco.with_payload`), which the controller's
    model (the nominal arm the rule reads) lacks."""
    model, q0, chain = arm(name)
    plant = amj.Plant(model)
    driven = amj.Plant(amj.with_payload(model, payload)) if payload > 0 else plant
    p0, R0 = chain.pose(q0)
    path = circle(p0)
    # The rule's controller for the circle (one period, 2 s): nothing set per arm.
    ctrl = adaptimp.CartesianController.from_rule(
        chain, "sf", path, q0, model=plant, Ts=TS, span=2.0
    )
    steps = round(T / TS)
    last: list[Any] = [None]

    def run() -> float:
        ctrl.reset()
        start = time.perf_counter()
        if not python_path:
            ctrl.path = circle_table(p0, R0, steps)
        res = amj.simulate(ctrl, driven, T=T, q0=q0)
        seconds = time.perf_counter() - start
        assert res.params["loop"] == "native"
        last[0] = res
        return seconds

    def error() -> float:
        """The last run's RMS position error over ``window`` (m), every 10th
        period, computed when asked (outside the run, as it is outside its
        time: not in a count either)."""
        res = last[0]
        rows = np.flatnonzero((res.t >= window[0] - 1e-9) & (res.t < window[1] - 1e-9))[::10]
        p = np.array([chain.pose(q)[0] for q in res.q[rows]])
        want = np.array([path(t)[0] for t in res.t[rows]])
        return float(np.sqrt(np.mean(np.sum((p - want) ** 2, axis=1))))

    return run, error


def user_loop(
    name: str, T: float, payload: float = 0.0, window: tuple[float, float] = (1.0, math.inf)
) -> tuple[Callable[[], float], Callable[[], float]]:
    """The mjctrl-style operational-space loop in Python (module doc): (run:
    the seconds of one run's loop, after its reset; the RMS position error
    over ``window`` (s), by default after 1 s). ``payload`` (kg): a point mass
    on the last link of the simulated arm (:func:`adaptimp.mujoco.with_payload`);
    the law's model (J, M, the bias) stays the nominal arm's, evaluated at the
    measured q, q̇ on a data of its own."""
    model, q0, _ = arm(name)
    sim = amj.with_payload(model, payload) if payload > 0 else model
    data = mujoco.MjData(sim)
    # The law's own model: the nominal arm (the same data when nothing differs).
    known = mujoco.MjData(model) if payload > 0 else data
    substeps = round(TS / model.opt.timestep)
    site = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, SITES[name])
    n = model.nv
    kp = np.array([1500.0] * 3 + [200.0] * 3)  # 1/s² per unit of task inertia
    kd = 2.0 * np.sqrt(kp)
    kn, dn = 25.0, 10.0
    lo, hi = model.actuator_ctrlrange.T
    steps = round(T / TS)
    error = [np.nan]

    def reset() -> None:
        mujoco.mj_resetData(sim, data)
        data.qpos[:] = q0
        mujoco.mj_forward(sim, data)

    reset()
    p0 = data.site_xpos[site].copy()
    path = circle(p0)
    quat_d = np.zeros(4)
    mujoco.mju_mat2Quat(quat_d, data.site_xmat[site])

    jacp, jacr = np.zeros((3, n)), np.zeros((3, n))
    jac = np.zeros((6, n))
    mass = np.zeros((n, n))
    quat, conj, err_quat = np.zeros(4), np.zeros(4), np.zeros(4)
    twist = np.zeros(6)
    eye = np.eye(n)

    def full_mass() -> None:
        try:
            mujoco.mj_fullM(model, known, mass)
        except TypeError:  # MuJoCo 3: mj_fullM(m, dst, qM)
            mujoco.mj_fullM(model, mass, known.qM)

    lo_k, hi_k = (round(w / TS) if math.isfinite(w) else steps for w in window)

    def run() -> float:
        reset()
        errors = []
        start = time.perf_counter()
        for k in range(steps):
            p_c, dp_c, _ = path(k * TS)
            if known is not data:  # the nominal model at the measured state
                known.qpos[:], known.qvel[:] = data.qpos, data.qvel
                mujoco.mj_forward(model, known)
            mujoco.mj_jacSite(model, known, jacp, jacr, site)
            jac[:3], jac[3:] = jacp, jacr
            full_mass()
            m_inv = np.linalg.inv(mass)
            task_inv = jac @ m_inv @ jac.T
            task = np.linalg.inv(task_inv)
            twist[:3] = p_c - data.site_xpos[site]
            mujoco.mju_mat2Quat(quat, data.site_xmat[site])
            mujoco.mju_negQuat(conj, quat)
            mujoco.mju_mulQuat(err_quat, quat_d, conj)
            mujoco.mju_quat2Vel(twist[3:], err_quat, 1.0)
            dq = data.qvel
            velocity = jac @ dq - np.concatenate([dp_c, np.zeros(3)])
            tau = jac.T @ task @ (kp * twist - kd * velocity)
            jbar = m_inv @ jac.T @ task
            tau += (eye - jac.T @ jbar.T) @ (kn * (q0 - data.qpos) - dn * dq)
            tau += known.qfrc_bias
            data.ctrl[:] = np.clip(tau, lo, hi)
            mujoco.mj_step(sim, data, nstep=substeps)
            if lo_k <= k + 1 < hi_k and (k + 1) % 10 == 0:
                errors.append(np.sum((data.site_xpos[site] - path((k + 1) * TS)[0]) ** 2))
        seconds = time.perf_counter() - start
        error[0] = float(np.sqrt(np.mean(errors))) if errors else np.nan
        return seconds

    return run, lambda: error[0]


def measure(name: str, T: float, repeats: int) -> dict[str, Any]:
    """Per period, each loop's time by the slope: runs of ``T`` and ``2 T``,
    interleaved, the difference of their medians over the extra periods (as
    the instruction counts): what a run costs once whatever its length (the
    model's checks, the resets) is not a period's; what grows with the run
    (the path's table, the result's arrays) stays in the slope.
    ``*_run_ns``: a ``T`` run's whole time over its periods, setup included."""
    loops = {
        "core": (adaptimp_loop(name, T), adaptimp_loop(name, 2 * T)),
        "py_path": (
            adaptimp_loop(name, T, python_path=True),
            adaptimp_loop(name, 2 * T, python_path=True),
        ),
        "peer": (user_loop(name, T), user_loop(name, 2 * T)),
    }
    runs = [(key, i, pair[i][0]) for key, pair in loops.items() for i in (0, 1)]
    times: dict[tuple[str, int], list[float]] = {(key, i): [] for key, i, _ in runs}
    gc.collect()
    for k in range(repeats):
        for key, i, run in runs[:: 1 if k % 2 == 0 else -1]:
            times[key, i].append(run())
    periods = round(T / TS)
    got: dict[str, Any] = {}
    for key in loops:
        one, two = (statistics.median(times[key, i]) for i in (0, 1))
        got[f"{key}_ns"] = round((two - one) / periods * 1e9, 1)
        got[f"{key}_run_ns"] = round(one / periods * 1e9, 1)
        got[f"{key}_rms_mm"] = round(loops[key][1][1]() * 1e3, 3)
    got["ratio"] = round(got["core_ns"] / got["peer_ns"], 3)
    got["py_path_ratio"] = round(got["py_path_ns"] / got["peer_ns"], 3)
    got["run_ratio"] = round(got["core_run_ns"] / got["peer_run_ns"], 3)
    return {**got, "periods": periods, "substeps": round(TS / arm_timestep(name))}


def arm_timestep(name: str) -> float:
    return 0.5e-3 if name == "panda" else 1e-3


def count(name: str, side: str, T: float) -> float:
    """Instructions of one run of ``side``'s loop of ``T`` s on the arm ``name`` (callgrind)."""
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "cg"
        proc = subprocess.run(
            [
                "valgrind",
                "--tool=callgrind",
                f"--callgrind-out-file={out}",
                sys.executable,
                __file__,
                "--one",
                side,
                "--arms",
                name,
                "--T",
                str(T),
            ],
            capture_output=True,
            text=True,
            check=True,
            env={**os.environ, "OPENBLAS_NUM_THREADS": "1", "PYTHONHASHSEED": "0"},
        )
        for line in proc.stderr.splitlines():
            if "refs:" in line:
                return float(line.split()[-1].replace(",", ""))
    raise RuntimeError(f"callgrind gave no count for {side}")


def side_by_side(
    name: str, count_ir: bool = False, T: float = 2.0, repeats: int = 5
) -> dict[str, Any]:
    """The JSON entry of ``benches/peers.py`` (arm "mujoco", row "cartesian_loop_ARM")."""
    got = measure(name, T, repeats)
    if count_ir:
        t1, t2 = 1.2, 2.4
        k = round((t2 - t1) / TS)
        for side, key in (
            ("adaptimp", "core_ir"),
            ("adaptimp-python-path", "py_path_ir"),
            ("user", "peer_ir"),
        ):
            got[key] = round((count(name, side, t2) - count(name, side, t1)) / k)
        got["ir_ratio"] = round(got["core_ir"] / got["peer_ir"], 3)
        got["py_path_ir_ratio"] = round(got["py_path_ir"] / got["peer_ir"], 3)
    return got


PAYLOAD_SHARE = 0.10
"""The payload of :func:`tracking`: this share of the arm's moving mass (kg)."""


def tracking(name: str, T: float = 12.0, last: float = 2.0) -> dict[str, Any]:
    """Tracking, not time: each loop's RMS position error (mm) over the last
    ``last`` s of a ``T`` s run, on the nominal arm and with a payload of
    :data:`PAYLOAD_SHARE` of its moving mass on the last link that neither
    the OSC's model nor adaptimp's rule knows of (adaptimp learning from zero
    weights in each run)."""
    model, _, _ = arm(name)
    payload = round(PAYLOAD_SHARE * amj.moving_mass(model), 3)
    window = (T - last, T)
    got: dict[str, Any] = {"T": T, "last": last, "payload_kg": payload}
    for key, mass in (("", 0.0), ("_payload", payload)):
        core, core_err = adaptimp_loop(name, T, payload=mass, window=window)
        peer, peer_err = user_loop(name, T, payload=mass, window=window)
        core()
        peer()
        got[f"core{key}_mm"] = round(core_err() * 1e3, 4)
        got[f"peer{key}_mm"] = round(peer_err() * 1e3, 4)
        got[f"ratio{key}"] = round(got[f"core{key}_mm"] / got[f"peer{key}_mm"], 3)
    return got


ARM_NAMES = {"ur5": "UR5 (example-robot-data)", "panda": "Panda (example-robot-data)"}


def tracking_markdown(rows: dict[str, dict[str, Any]]) -> str:
    """The table of docs/robosuite.md from ``--tracking --json``'s output."""
    out = [
        "| arm | payload (kg) | nominal: adaptimp (mm) | the user's OSC (mm) | ÷ "
        "| with the payload: adaptimp (mm) | the user's OSC (mm) | ÷ |",
        "|---|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for name, g in rows.items():
        out.append(
            f"| {ARM_NAMES.get(name, name)} | {g['payload_kg']:.3f} | {g['core_mm']:.4f} | "
            f"{g['peer_mm']:.4f} | **{g['ratio']:.3f}** | {g['core_payload_mm']:.4f} | "
            f"{g['peer_payload_mm']:.4f} | **{g['ratio_payload']:.3f}** |"
        )
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--T", type=float, default=2.0, help="run length (s), ≥ 1.2")
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--arms", nargs="+", default=["ur5", "panda"], choices=list(SITES))
    ap.add_argument("--count", action="store_true", help="also count instructions (callgrind)")
    ap.add_argument(
        "--tracking",
        action="store_true",
        help="compare tracking instead of time: T = 12 s, the last 2 s, with and without "
        "a payload the OSC's model lacks",
    )
    ap.add_argument("--json", action="store_true", help="with --tracking: print JSON")
    ap.add_argument(
        "--markdown", metavar="FILE", help="print the table of a --tracking --json FILE and exit"
    )
    ap.add_argument(
        "--one", choices=["adaptimp", "adaptimp-python-path", "user"], help=argparse.SUPPRESS
    )
    args = ap.parse_args()
    if args.one:
        if args.one == "user":
            run, _ = user_loop(args.arms[0], args.T)
        else:
            run, _ = adaptimp_loop(args.arms[0], args.T, args.one == "adaptimp-python-path")
        run()
        return
    if args.markdown:
        import json

        with open(args.markdown, encoding="utf-8") as f:
            print(tracking_markdown(json.load(f)))
        return
    if args.tracking:
        rows = {name: tracking(name) for name in args.arms}
        if args.json:
            import json

            print(json.dumps(rows, indent=1))
            return
        for name, got in rows.items():
            print(
                f"\n{name}, tracking, T = {got['T']:g} s, RMS position error over the last "
                f"{got['last']:g} s (mm):\n"
                f"  nominal arm: adaptimp {got['core_mm']:.4f}, the user's OSC (exact model) "
                f"{got['peer_mm']:.4f}: {got['ratio']:.3f}× (target ≤ 1.5)\n"
                f"  payload {got['payload_kg']:g} kg the models lack: adaptimp "
                f"{got['core_payload_mm']:.4f}, the user's OSC {got['peer_payload_mm']:.4f}: "
                f"{got['ratio_payload']:.3f}×"
            )
        return
    for name in args.arms:
        got = side_by_side(name, args.count, args.T, args.repeats)
        print(
            f"\n{name}, per period (Ts = 1 ms, {got['substeps']} MuJoCo steps), runs of "
            f"{got['periods']} and {2 * got['periods']} periods, medians of {args.repeats}, "
            "the slope:\n"
            f"  adaptimp (native Cartesian SF loop, learning; the path's table): "
            f"{got['core_ns'] / 1e3:.2f} µs (RMS error after 1 s {got['core_rms_mm']:.2f} mm)\n"
            f"  adaptimp (the same, the user's Python path tabulated first): "
            f"{got['py_path_ns'] / 1e3:.2f} µs (RMS error after 1 s "
            f"{got['py_path_rms_mm']:.2f} mm)\n"
            f"  the user's loop (mjctrl-style OSC in Python):  {got['peer_ns'] / 1e3:.2f} µs "
            f"(RMS error after 1 s {got['peer_rms_mm']:.2f} mm)\n"
            f"  adaptimp ÷ user: {got['ratio']:.3f} (target ≤ 0.5); with the Python path "
            f"{got['py_path_ratio']:.3f}\n"
            f"  a {args.T:g} s run's whole time a period, setup included: "
            f"{got['core_run_ns'] / 1e3:.2f} µs against {got['peer_run_ns'] / 1e3:.2f} µs "
            f"({got['run_ratio']:.3f})"
        )
        if "core_ir" in got:
            print(
                f"  instructions per period: {got['core_ir']:,} against {got['peer_ir']:,} "
                f"({got['ir_ratio']:.2f}); with the Python path {got['py_path_ir']:,} "
                f"({got['py_path_ir_ratio']:.2f})"
            )
        for key in ("core_rms_mm", "py_path_rms_mm", "peer_rms_mm"):
            assert got[key] < 5.0, f"{key} = {got[key]} mm: a loop does not track the circle"


if __name__ == "__main__":
    main()
