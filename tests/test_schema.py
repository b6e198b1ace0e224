"""One parameter schema, declared in the Rust core (src/schema.rs): the Python
keyword table, the defaults, help(), the command line and the stubs follow it."""

from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
from pathlib import Path

import numpy as np
import pytest

import adaptimp
from adaptimp import _adaptimp, cartesian
from adaptimp._params import ALL_GROUPS, BY_NAME, GROUPS, PARAMS, SCENARIOS, names

ROOT = Path(__file__).resolve().parent.parent


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    exe = Path(sysconfig.get_path("scripts")) / "adaptimp"
    env = {**os.environ, "MPLBACKEND": "Agg"}
    return subprocess.run(
        [str(exe), *args], capture_output=True, text=True, env=env, timeout=300, check=False
    )


def test_every_core_parameter_has_a_python_keyword_and_back() -> None:
    """A Rust option without a Python name fails here (the core's own test checks
    that every configuration field has a schema entry)."""
    core = _adaptimp.defaults("paper")
    assert names(*ALL_GROUPS) == list(core)
    assert {p.group for p in PARAMS} == set(ALL_GROUPS)
    assert [p["name"] for p in _adaptimp.schema_table()] == [p.name for p in PARAMS]
    for scenario in ("paper", "robot"):
        assert set(SCENARIOS[scenario]) == set(BY_NAME)


def test_the_table_carries_units_docs_conditions_and_choices() -> None:
    kzeta = BY_NAME["Kzeta"]
    assert (kzeta.group, kzeta.kind, kzeta.unit) == ("controller", "joint", "1/s")
    assert kzeta.condition == (
        "2Kζ − I − KpᵀKp > 0 (conditions 'paper'); 2Kζ − ρ − Kp/d > 0 ('scaled')"
    )
    assert BY_NAME["conditions"].choices == ("paper", "scaled")
    assert BY_NAME["learning_step"].choices == ("euler", "normalized")
    assert BY_NAME["weight_bound"].kind == "bound"
    assert all(p.doc for p in PARAMS)
    # Every choice a user can name is accepted by the core.
    arm = adaptimp.Chain(
        [
            {"kind": "revolute", "axis": [0, 0, 1]},
            {"kind": "revolute", "xyz": [0.3, 0, 0], "axis": [0, 0, 1]},
        ],
        tip={"xyz": [0.2, 0, 0]},
    )
    for p in PARAMS:
        for choice in p.choices:
            if p.group == "cartesian":
                cartesian.CartesianImpedance(arm, Ts=1e-3, q0=[0.3, 0.6], **{p.name: choice})
            else:
                adaptimp.Controller("sf", **{p.name: choice})


def test_help_lists_every_parameter_with_unit_and_condition() -> None:
    doc = adaptimp.simulate.__doc__ or ""
    cart = adaptimp.CartesianController.__doc__ or ""
    for p in PARAMS:
        assert f"{p.name}" in (doc if p.group in GROUPS else cart), p.name
    assert "Kzeta (1/s)" in doc
    assert "valid: 2Kζ − I − KpᵀKp > 0 (conditions 'paper')" in doc


def test_stubs_are_generated_from_the_schema() -> None:
    proc = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "gen_stubs.py"), "--check"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    stub = (ROOT / "python" / "adaptimp" / "_adaptimp.pyi").read_text(encoding="utf-8")
    for p in PARAMS:
        assert f"    {p.name}: " in stub, p.name


def test_cli_lists_the_robot_scenarios_defaults() -> None:
    proc = cli("params", "--scenario", "robot")
    assert proc.returncode == 0, proc.stderr
    assert "'robot' scenario" in proc.stdout
    assert "Ts (s) — sampling period of the controller; valid: Ts > 0; robot: 0.001" in proc.stdout
    assert "learning_step" in proc.stdout
    assert "robot: 'normalized'" in proc.stdout


@pytest.mark.parametrize(("text", "expect"), [("1,2,3", [1.0, 2.0, 3.0]), ("none", None)])
def test_cli_takes_weight_bounds_as_numbers_or_none(text: str, expect: object) -> None:
    proc = cli(
        "simulate", "--case", "sf", "--scenario", "robot", "--T", "0.05",
        "--weight_bound", text, "--json",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    ctrl = adaptimp.Controller("sf", scenario="robot", weight_bound=expect)
    assert ctrl.params["weight_bound"] == expect


def test_auto_means_one_thing_in_rust_and_python() -> None:
    """'auto' is resolved by the core from the trajectory that is tracked: at
    ω = 6 rad/s the D̂ and Ĉ bounds follow the trajectory, not the paper circle."""
    paper = np.array(adaptimp.Controller("sf", scenario="robot").params["weight_bound"])
    fast = np.array(
        adaptimp.Controller("sf", scenario="robot", xc_omega=6.0).params["weight_bound"]
    )
    ratio = np.pi / 6.0
    assert fast == pytest.approx(paper * [ratio**2, ratio, 1.0])
