"""Contact that holds (SPEC §19): the formulations on MuJoCo's table, the scenario on
any arm, the spring table, the JSON table of examples/13, and the MuJoCo behaviour
the docs rely on (a sliding contact's normal force alternates)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import mujoco
import numpy as np
import pytest

import adaptimp
from adaptimp import cartesian as ac
from adaptimp import contact as act
from adaptimp import mujoco as amj

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "13_panda_table.py"


def _ur5() -> Path:
    from adaptimp._models import panda_urdf_path

    root = panda_urdf_path().parent.parent.parent
    return root / "ur_description" / "urdf" / "ur5_robot.urdf"


def test_the_torque_level_formulation_holds_a_rigid_frictionless_table() -> None:
    """Computed torque with the exact model as the torque-level impedance's
    feedforward (SPEC (19.2) with a model): the force is K_d δ_c, steady, and the
    tool never leaves the table."""
    sc = act.arm_table(friction=0.0)
    ctrl = ac.panda_controller("ct", sc, formulation="impedance")
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=3.0, q0=sc.q0)
    m = act.contact_metrics(res, ctrl, sc)
    assert m["force_target_N"] == pytest.approx(7.5)
    assert m["force_rms_err_N"] < 0.01 * 7.5  # measured 0.005 N over t ≥ 2 s
    assert m["force_chatter_N"] < 1e-3
    assert m["contact_lost_s"] == 0.0
    assert m["track_mm"] < 0.1


def test_the_unified_formulation_holds_the_table_with_the_paper_s_feedforward() -> None:
    """SF with the paper's +τe in the admittance share n = 0.3: no chatter, no loss
    of contact on the frictionless table (the admittance alone chatters, SPEC §19)."""
    sc = act.arm_table(friction=0.0)
    basis = ac.orbit_basis(sc)
    learn = {"gamma": [1.0, 1.0, 5000.0], "sigma": [0.01, 0.01, 1e-5]}
    ctrl = ac.panda_controller(
        "sf",
        sc,
        basis=basis,
        formulation="unified",
        admittance_share=0.3,
        weight_bound=[4.19, 13.2, 100.0],
        **learn,
    )
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=3.0, q0=sc.q0)
    m = act.contact_metrics(res, ctrl, sc)
    assert m["force_chatter_N"] < 0.05 * 7.5
    assert m["contact_lost_s"] == 0.0
    assert m["peak_tau_ratio"] <= 2.0
    assert m["sat_duty"] == 0.0


def test_a_spring_table_gives_the_force_16_1_prescribes() -> None:
    """A table on a 5 kN/m spring: at rest, pressing δ_c = 15 mm, the normal force
    is K_d k_e/(K_d + k_e)(δ_c + n·e) (SPEC (16.1)), e the inner loop's error."""
    k_e = 5000.0
    sc = act.arm_table(friction=0.0, spring=k_e, freq=1e-9)
    assert amj.Plant(sc.model).n == 7  # the spring's slide joint is the table's
    ctrl = ac.panda_controller("ct", sc, formulation="impedance")
    res = amj.simulate(ctrl, amj.Plant(sc.model), T=4.0, q0=sc.q0)
    fn = -res.wrench_ee[-500:, 2].mean()
    log = ctrl.arrays()
    e = float(np.mean(res.x_ee[-500:, 2] - log["pd"][-500:, 2]))
    kd = 500.0
    prescribed = kd * k_e / (kd + k_e) * (sc.depth + e)
    assert fn == pytest.approx(prescribed, rel=0.02)
    assert fn == pytest.approx(kd * k_e / (kd + k_e) * sc.depth, rel=0.02)


def test_the_scenario_on_the_ur5_is_placed_from_its_reach() -> None:
    sc = act.arm_table(_ur5())
    plant = amj.Plant(sc.model)
    assert plant.n == 6
    centre, top, reach = act.placement(sc.chain, sc.q0, (np.full(6, -np.pi), np.full(6, np.pi)))
    np.testing.assert_allclose(sc.centre, centre)
    p_home = sc.chain.fk(sc.q0)[:3, 3]
    # OUTWARD beyond the home tip, within REACH_SHARE of the reach.
    radial = np.linalg.norm(p_home[:2])
    assert np.linalg.norm(centre) == pytest.approx(
        min(radial + act.OUTWARD, act.REACH_SHARE * reach)
    )
    assert sc.surface_z == pytest.approx(p_home[2] - act.CLEARANCE)
    assert top == pytest.approx(sc.surface_z - 0.01)
    # The path starts at the home tip and ends δ_c below the surface.
    assert np.allclose(sc.path(0.0)[0], sc.p0)
    assert sc.path(sc.t_approach)[0][2] == pytest.approx(sc.surface_z - sc.depth)


def test_example_13_writes_the_table_as_json(tmp_path: Path) -> None:
    out = tmp_path / "table.json"
    env = dict(os.environ, MPLBACKEND="Agg")
    args = [sys.executable, str(EXAMPLE), "--T", "0.4", "--rows", "pd,ct", "--json", str(out)]
    run = subprocess.run(args, capture_output=True, text=True, env=env, timeout=600, check=False)
    assert run.returncode == 0, run.stderr
    table = json.loads(out.read_text())
    assert sorted(table) == ["ct", "pd"]
    for row in table.values():
        assert sorted(row) == sorted(
            [
                "track_mm",
                "force_rms_err_N",
                "force_target_N",
                "force_chatter_N",
                "contact_lost_s",
                "peak_tau_ratio",
                "sat_duty",
            ]
        )
        assert all(np.isfinite(v) for v in row.values())


def _sliding_point(mu: float, push: float) -> tuple[float, float]:
    """A 4 kg point (three slides) sliding at 8 cm/s and more on a MuJoCo box,
    pushed down with 7.5 N and along x with ``push`` N: (mean, std) of its
    normal contact force over the last 2 s."""
    xml = f"""<mujoco><option timestep="0.0005"/><worldbody>
      <geom type="box" size="5 5 0.025" pos="0 0 -0.025" friction="{mu} 0.005 0.0001"/>
      <body pos="0 0 0.01"><joint type="slide" axis="1 0 0"/><joint type="slide" axis="0 1 0"/>
        <joint type="slide" axis="0 0 1"/>
        <geom type="sphere" size="0.01" mass="4" friction="{mu} 0.005 0.0001"/></body>
    </worldbody></mujoco>"""
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    d.qvel[0] = 0.08
    d.qfrc_applied[:3] = [push, 0.0, -7.5]
    f = []
    out = np.zeros(6)
    for _ in range(6000):
        mujoco.mj_step(m, d)
        total = 0.0
        for i in range(d.ncon):
            mujoco.mj_contactForce(m, d, i, out)
            total += out[0]
        f.append(total)
    tail = np.array(f[2000:])
    return float(tail.mean()), float(tail.std())


def test_mujoco_alternates_a_sliding_contact_s_normal_force() -> None:
    """The plant's bound on the friction table (docs/contact.md): under constant
    forces a point sliding under friction 0.1 (pushed with 6 N against μ N =
    4.7 N) keeps its mean normal force (7.5 + 4 g N) but it alternates from step
    to step (measured std 38.6 N); sliding without friction it varies 18×
    less (2.1 N)."""
    mean, std = _sliding_point(0.1, 6.0)
    assert mean == pytest.approx(7.5 + 4 * 9.81, rel=1e-3)
    assert std > 0.5 * mean
    mean0, std0 = _sliding_point(0.0, 0.0)
    assert mean0 == pytest.approx(7.5 + 4 * 9.81, rel=1e-4)
    assert std > 10.0 * std0


@pytest.mark.parametrize(
    ("name", "value", "what"),
    [
        ("friction", float("nan"), "≥ 0"),
        ("friction", -0.1, "≥ 0"),
        ("radius", -0.05, r"> 0 \(m\)"),
        ("freq", float("inf"), r"> 0 \(Hz\)"),
        ("depth", float("nan"), r"≥ 0 \(m\)"),
        ("tool_radius", -0.01, r"> 0 \(m\)"),
        ("Ts", 0.0, r"> 0 \(s\)"),
        ("t_approach", -1.0, r"≥ 0 \(s\)"),
        ("spring", 0.0, r"> 0 \(N/m\), or None for a rigid table"),
        ("spring", "stiff", r"> 0 \(N/m\), or None for a rigid table"),
    ],
)
def test_a_scenario_quantity_out_of_range_is_refused_by_name(
    name: str, value: object, what: str
) -> None:
    """arm_table refuses, before building anything, a quantity that is not a
    finite number in its range, naming it and the value (both the Panda's
    default table and a URDF's)."""
    for urdf in (None, _ur5()):
        message = rf"^{name} must be a finite number {what}, got "
        with pytest.raises(adaptimp.ConfigError, match=message):
            act.arm_table(urdf, **{name: value})
