"""The SPEC §12 metrics of simulate() equal a recomputation from the recorded arrays."""

from __future__ import annotations

import math

import numpy as np
import pytest

import adaptimp
from adaptimp import SimResult


def commanded(res: SimResult) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """xc, ẋc, ẍc (rad, rad/s, rad/s²) of x_i = o_i + a_i sin ω_i t + b_i cos ω_i t."""
    p = res.params
    o, a, b, w = (np.asarray(p[k]) for k in ("xc_offset", "xc_sin", "xc_cos", "xc_omega"))
    wt = np.outer(res.t, w)
    s, c = np.sin(wt), np.cos(wt)
    return o + a * s + b * c, w * (a * c - b * s), -(w**2) * (a * s + b * c)


def recompute(res: SimResult) -> dict[str, object]:
    """SPEC §12 from the arrays, independently of the core's accumulator."""
    p = res.params
    after = res.t >= p["settle"] - 1e-9
    sq = np.sum(res.z1**2, axis=1)
    contact = np.any(res.tau_e != 0.0, axis=1)
    f = np.linalg.norm(res.tau_e, axis=1)
    # Impedance residual Dd(ẍc − ẍ) + Cd(ẋc − ẋ) + Gd(xc − x) − τe, with ẍ the
    # plant's acceleration at the row's state and applied torque.
    arm = adaptimp.TwoLinkArm(
        **{k: p[k] for k in ("m1", "m2", "l1", "l2", "lc1", "lc2", "I1", "I2", "g")}
    )
    xc, dxc, ddxc = commanded(res)
    rows = np.flatnonzero(after)
    ddx = np.array(
        [arm.forward_dynamics(res.q[k], res.dq[k], res.tau_sat[k], res.tau_e[k]) for k in rows]
    ).reshape(-1, 2)
    dd, cd, gd = (np.asarray(p[k]) for k in ("Dd", "Cd", "Gd"))
    resid = (
        dd * (ddxc[rows] - ddx)
        + cd * (dxc[rows] - res.dq[rows])
        + gd * (xc[rows] - res.q[rows])
        - res.tau_e[rows]
    )
    nan = float("nan")
    any_after = bool(after.any())
    return {
        "rows": res.rows,
        "rms_z1": math.sqrt(sq.mean()),
        "rms_z1_after2": math.sqrt(sq[after].mean()) if any_after else nan,
        "rms_z1_joint_after2": list(np.sqrt(np.mean(res.z1[after] ** 2, axis=0)))
        if any_after
        else [nan, nan],
        "max_abs_z1_joint_after2": list(np.max(np.abs(res.z1[after]), axis=0))
        if any_after
        else [nan, nan],
        "sat_duty": float(np.mean(np.any(res.tau_sat != res.tau, axis=1))),
        "steps_in_contact": int(contact.sum()),
        "peak_contact_after2": float(f[after].max()) if any_after else nan,
        "mean_contact": float(f[contact].mean()) if contact.any() else 0.0,
        "peak_abs_tau": list(np.max(np.abs(res.tau), axis=0)),
        "imp_err_rms_after2": math.sqrt(np.mean(np.sum(resid**2, axis=1))) if any_after else nan,
    }


@pytest.mark.parametrize("case", adaptimp.CASES)
def test_metrics_equal_a_recomputation_from_the_arrays(
    runs: dict[str, SimResult], case: str
) -> None:
    res = runs[case]
    expected = recompute(res)
    assert set(expected) == set(res.metrics)
    for key, value in expected.items():
        assert res.metrics[key] == pytest.approx(value, rel=1e-9, abs=1e-12), key


def test_metrics_follow_the_settle_parameter() -> None:
    res = adaptimp.simulate("sf", T=1.5, settle=0.5)
    expected = recompute(res)
    for key, value in expected.items():
        assert res.metrics[key] == pytest.approx(value, rel=1e-9, abs=1e-12), key


def test_recorded_commanded_trajectory_is_the_analytic_one(runs: dict[str, SimResult]) -> None:
    res = runs["pd"]
    xc, _, _ = commanded(res)
    np.testing.assert_allclose(res.xc, xc, rtol=0, atol=1e-12)
    # (64): xc = [0.2 − 0.2 cos(πt), 0.2 + 0.2 sin(πt)].
    np.testing.assert_allclose(
        res.xc,
        np.c_[0.2 - 0.2 * np.cos(np.pi * res.t), 0.2 + 0.2 * np.sin(np.pi * res.t)],
        atol=1e-12,
    )


def test_a_run_shorter_than_settle_has_nan_after_metrics() -> None:
    res = adaptimp.simulate("of", T=0.2)
    expected = recompute(res)
    for key, value in expected.items():
        got = res.metrics[key]
        if isinstance(value, list):
            np.testing.assert_allclose(got, value, rtol=1e-9, equal_nan=True)
        elif math.isnan(value):
            assert math.isnan(got), key
        else:
            assert got == pytest.approx(value, rel=1e-9), key
