"""The gain and basis rule of SPEC §18 on arms nobody tuned for: the same code
on a 3-joint planar arm under gravity, the UR5 and the Panda (MuJoCo, from the
URDFs of example-robot-data): stable, within the torque limits, and the
adaptive controllers no worse than PD with the same gains."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

import adaptimp
from adaptimp import tuning

W = 1.0  # rad/s
A = 0.15  # rad


def _path(q0: np.ndarray) -> Any:
    """A sinusoid of amplitude A (rad) about q0 on every joint: (q, q̇, q̈) at t (s)."""
    ones = np.ones_like(q0)
    return lambda t: (
        q0 + A * np.sin(W * t),
        A * W * np.cos(W * t) * ones,
        -A * W * W * np.sin(W * t) * ones,
    )


def test_suggest_follows_the_rule() -> None:
    arm = adaptimp.PlanarArm(3, masses=[2.0, 1.5, 1.0], lengths=[0.4, 0.35, 0.25])
    q0 = np.array([0.3, 0.3, 0.3])
    kw = tuning.suggest(arm, q0, [60.0, 30.0, 15.0], Ts=1e-3, path=_path(q0), period=2 * np.pi)
    dinv = np.diag(np.linalg.inv(arm.D(q0)))
    np.testing.assert_allclose(kw["Kp"], 0.25 / (1e-3 * dinv), rtol=1e-12)
    kp = np.array(kw["Kp"])
    assert np.all(2 * np.array(kw["Kzeta"]) - 1 - kp**2 > 0)  # SPEC §10
    assert kw["centers"].shape[1] == 12
    assert 16 <= kw["centers"].shape[0] <= 256
    assert np.all(np.isinf(kw["widths"][6:]))


def test_a_3_joint_planar_arm_under_gravity() -> None:
    arm = adaptimp.PlanarArm(3, masses=[2.0, 1.5, 1.0], lengths=[0.4, 0.35, 0.25])
    q0 = np.full(3, 0.3)
    kw = tuning.suggest(arm, q0, [60.0, 30.0, 15.0], Ts=1e-3, path=_path(q0), period=2 * np.pi)
    kw.pop("n")
    common = {"n": 3, "arm": arm, "T": 8.0, "wall": None, "q0": q0.tolist()}
    traj = {"xc_offset": 0.3, "xc_sin": A, "xc_cos": 0.0, "xc_omega": W}
    rms = {}
    for case in ("pd", "sf", "of"):
        r = adaptimp.simulate(case, "robot", **common, **traj, **kw)
        assert np.all(np.abs(r.tau_sat) <= np.array(kw["tau_max"]) + 1e-12)
        rms[case] = r.metrics["rms_z1_after2"]
    assert rms["sf"] < rms["pd"]
    assert rms["of"] < rms["pd"]


@pytest.mark.parametrize("robot", ["ur5", "panda"])
def test_real_arms_in_mujoco(robot: str) -> None:
    from adaptimp import mujoco as amj

    if robot == "ur5":
        from adaptimp._models import panda_urdf_path

        root = panda_urdf_path().parents[2]
        model = amj.from_urdf(root / "ur_description" / "urdf" / "ur5_robot.urdf")
        q0 = np.array([0.0, -1.2, 1.2, -1.5, -1.5, 0.0])
    else:
        model = amj.panda()
        q0 = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    plant = amj.Plant(model, contact=False)
    kw = tuning.suggest(plant, q0, plant.tau_max, Ts=1e-3, path=_path(q0), period=2 * np.pi)
    n = kw.pop("n")
    rms = {}
    for case in ("pd", "sf"):
        ctrl = adaptimp.Controller(case, "robot", n=n, impedance="external", **kw)
        r = amj.simulate(ctrl, amj.Plant(model, contact=False), T=5.0, q0=q0, reference=_path(q0))
        assert np.all(np.isfinite(r.q))
        assert np.all(np.abs(r.tau_sat) <= plant.tau_max + 1e-9)
        assert r.metrics["sat_duty"] < 0.01
        rms[case] = r.metrics["rms_z1_after2"]
    assert rms["sf"] <= rms["pd"]
    assert rms["pd"] < 0.05


def test_inertia_from_every_kind_of_model(tmp_path: Path) -> None:
    arm = adaptimp.PlanarArm(2)
    q = [0.1, 0.2]
    np.testing.assert_array_equal(tuning.inertia(arm, q), arm.D(q))
    np.testing.assert_array_equal(tuning.inertia(arm.D(q), q), arm.D(q))
    with pytest.raises(TypeError, match="must have D"):
        tuning.inertia("not a model", q)
