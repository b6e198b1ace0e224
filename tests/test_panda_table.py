"""The core's outer loop of SPEC §16 through adaptimp.cartesian, and the panda-table scenario."""

from __future__ import annotations

import numpy as np
import pytest

from adaptimp import cartesian as ac
from adaptimp import mujoco as amj
from adaptimp.scenarios import panda_table as apt


@pytest.fixture(scope="module")
def sc() -> apt.PandaTable:
    return apt.panda_table()


def test_free_space_clik_follows_the_command(sc: apt.PandaTable) -> None:
    """F_e = 0: p_d ≡ p_c (Euler), and the CLIK drives fk(q_d) to p_d."""
    outer = sc.outer()
    err, gap = [], []
    for k in range(3000):
        p, dp, ddp = sc.path(k * sc.Ts, depth=0.0)
        q, _, _ = outer.step(p, dp, ddp)
        if k * sc.Ts >= 1.5:
            pd = outer.last("p_d")
            err.append(np.linalg.norm(sc.fk(q) - pd))
            gap.append(np.linalg.norm(pd - p))
    assert max(gap) < 1e-5
    assert max(err) < 1e-4


def test_steady_contact_force_is_kd_times_depth(sc: apt.PandaTable) -> None:
    """A plane z ≤ w of stiffness k_e with a perfect inner loop (p = fk(q_d)):
    F = K_d k_e/(K_d + k_e) δ_c (16.1), → K_d δ_c as k_e ≫ K_d."""
    outer = sc.outer()
    ke, w = 5000.0, 0.46
    p0 = sc.fk(sc.q0)
    pc = np.array([p0[0], p0[1], w - 0.01])  # commanded 1 cm into the plane
    f = np.zeros(3)
    for k in range(4000):
        s = min(k * sc.Ts / 1.0, 1.0)
        q, _, _ = outer.step(p0 + s * (pc - p0), wrench=f)
        z = sc.fk(q)[2]
        f = np.array([0.0, 0.0, -ke * max(0.0, w - z), 0.0, 0.0, 0.0])  # the tool presses down
    fn = -f[2]
    expected = 500.0 * ke / (500.0 + ke) * 0.01
    assert fn == pytest.approx(expected, rel=2e-3)
    assert fn == pytest.approx(500.0 * 0.01, rel=0.1)


def test_outer_loop_validates(sc: apt.PandaTable) -> None:
    with pytest.raises(ValueError, match="Ts·clik_kd < 1"):
        ac.CartesianImpedance(sc.chain, Ts=0.02, q0=sc.q0)
    with pytest.raises(ValueError, match=r"Md > 0"):
        ac.CartesianImpedance(sc.chain, Ts=1e-3, q0=sc.q0, Md=0.0)


@pytest.mark.parametrize("kind", ["pd", "sf"])
def test_short_run_within_limits(sc: apt.PandaTable, kind: str) -> None:
    ctrl = apt.panda_controller(kind, sc)
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=0.6, q0=sc.q0)
    m = apt.cartesian_metrics(res, ctrl, sc, settle=0.3)
    assert all(np.isfinite(v) for v in m.values())
    assert m["applied_ratio"] <= 1.0 + 1e-12
    assert np.all(np.abs(res.tau_sat) <= np.asarray(res.params["tau_max"]) + 1e-12)


def test_computed_torque_tracks_the_circle(sc: apt.PandaTable) -> None:
    ctrl = apt.panda_controller("ct", sc)
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=3.0, q0=sc.q0)
    m = apt.cartesian_metrics(res, ctrl, sc)
    assert m["rms_track"] < 1e-3  # m
    assert m["rms_path_xy"] < 3e-3  # m: the circle on the table
    assert res.metrics["steps_in_contact"] > 500


def test_cartesian_impedance_needs_external_inner(sc: apt.PandaTable) -> None:
    from adaptimp.baselines import ComputedTorque

    with pytest.raises(ValueError, match="external"):
        ac.CartesianController(sc.chain, ComputedTorque(sc.pin_model, tau_max=sc.tau_max), q0=sc.q0)
    with pytest.raises(ValueError, match="external"):
        ac.CartesianController(sc.chain, "pd", q0=sc.q0, impedance="joint")


def test_gravity_learning_without_feedforward_beats_pd(sc: apt.PandaTable) -> None:
    """5 s of the scenario of examples/13 (t ≥ 2.5 s): state feedback without the τe
    feedforward and with gravity learning tracks the tool at under half of PD's
    error, with PD's joint gains, and winds nothing up."""
    basis = apt.orbit_basis(sc)
    learn = {"gamma": [1.0, 1.0, 5000.0], "sigma": [0.01, 0.01, 1e-5]}
    track = {}
    for kind in ("pd", "sf"):
        extra = learn if kind == "sf" else {}
        ctrl = apt.panda_controller(
            kind,
            sc,
            basis=basis,
            force_feedforward=False,
            weight_bound=[4.19, 13.2, 100.0],
            **extra,
        )
        res = amj.simulate(ctrl, amj.Plant(sc.model), T=5.0, q0=sc.q0)
        m = apt.cartesian_metrics(res, ctrl, sc, settle=2.5)
        assert m["applied_ratio"] <= 1.0 + 1e-12
        assert m["peak_tau_ratio"] <= 2.0
        track[kind] = m["rms_track"]
    assert track["sf"] < 0.5 * track["pd"]
