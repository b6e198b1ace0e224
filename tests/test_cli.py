"""The ``adaptimp`` console script, end to end, in subprocesses."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import sysconfig
from pathlib import Path

import numpy as np
import pytest

import adaptimp
from adaptimp import SimResult
from adaptimp._result import METRIC_KEYS


def adaptimp_exe() -> str:
    """The installed console script."""
    name = "adaptimp.exe" if os.name == "nt" else "adaptimp"
    path = Path(sysconfig.get_path("scripts")) / name
    assert path.exists(), f"console script not installed at {path}"
    return str(path)


def run(*args: str, check: bool = True) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "MPLBACKEND": "Agg"}
    proc = subprocess.run(
        [adaptimp_exe(), *args], capture_output=True, text=True, env=env, timeout=300
    )
    if check:
        assert proc.returncode == 0, proc.stderr
    return proc


def test_reproduce_writes_figures_metrics_and_prints_the_table(tmp_path: Path) -> None:
    out = tmp_path / "rep"
    proc = run("reproduce", "--out", str(out), "--T", "2.5")
    pngs = sorted(p.name for p in out.glob("*.png"))
    assert pngs == sorted(
        [f"{c}_{k}.png" for c in ("pd", "sf", "of") for k in ("tracking", "errors", "torques")]
        + ["comparison.png"]
    )
    for png in out.glob("*.png"):
        assert png.read_bytes().startswith(b"\x89PNG")
        assert png.stat().st_size > 20_000
    summary = json.loads((out / "metrics.json").read_text())
    assert summary["overrides"] == {"T": 2.5}
    assert summary["adaptimp_version"] == adaptimp.__version__
    assert set(summary["metrics"]) == {"pd", "sf", "of"}
    for case, metrics in summary["metrics"].items():
        assert set(metrics) == {*METRIC_KEYS, "rows"}
        assert metrics["rows"] == 50_000
        assert summary["params"][case]["T"] == 2.5
    # PD tracks far worse than the adaptive controllers (SPEC §12).
    m = summary["metrics"]
    assert m["pd"]["rms_z1_after2"] > 5 * m["sf"]["rms_z1_after2"]
    table = (out / "metrics.md").read_text()
    assert table.startswith("| metric (SPEC §12)")
    assert table.strip() in proc.stdout
    assert f"{m['sf']['rms_z1_after2']:.5f}" in table


def test_simulate_takes_parameters_plots_and_saves(tmp_path: Path) -> None:
    png, npz = tmp_path / "errors.png", tmp_path / "run.npz"
    proc = run(
        "simulate", "--case", "pd", "--T", "0.5", "--Kp", "10.5,9", "--wall", "none",
        "--settle=0.25", "--plot", str(png), "--kind", "errors", "--save", str(npz), "--json",
    )  # fmt: skip
    metrics = json.loads(proc.stdout)
    assert metrics["rows"] == 10_000
    assert metrics["steps_in_contact"] == 0
    assert png.read_bytes().startswith(b"\x89PNG")
    res = SimResult.load(npz)
    assert res.case == "pd"
    assert res.params["Kp"] == [10.5, 9.0]
    assert res.params["wall"] is None
    assert res.params["settle"] == 0.25
    assert res.metrics["rms_z1_after2"] == pytest.approx(metrics["rms_z1_after2"])
    assert np.all(res.tau_e == 0.0)


def test_simulate_prints_a_table_by_default() -> None:
    proc = run("simulate", "--case", "of", "--T", "0.1")
    assert "output feedback (of): 2000 steps" in proc.stdout
    assert "| RMS ‖z1‖ (rad)" in proc.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--Kq", "1"], "unknown parameter --Kq (every name: `adaptimp params`, and --help)"),
        (["--Kpp", "1"], "unknown parameter --Kpp; did you mean --Kp? (every name:"),
        (["--kzeta", "1"], "unknown parameter --kzeta; did you mean --Kzeta?"),
        (["--modle", "x.urdf"], "unknown parameter --modle; did you mean --model?"),
        (["--model", "nowhere.urdf"], "no file 'nowhere.urdf'"),
        (["--tip", "tool0"], "--tip applies to an arm given with --model FILE"),
        (["--coupled"], "--[no-]coupled applies to an arm given with --model FILE"),
        (["--no-coupled"], "--[no-]coupled applies to an arm given with --model FILE"),
        (["--Kp", "abc"], "--Kp: cannot read 'abc' as a number or comma-separated numbers"),
        (["--Kp"], "--Kp needs a value"),
        (["--Kp", "0.25", "--T", "0.01"], "condition 2Kp − I > 0 is violated"),
        (["--T", "0.01", "--Kp", "1,2,3"], "Kp must be a number or have shape (2,)"),
        (["extra"], "unexpected argument 'extra'"),
    ],
)
def test_simulate_reports_bad_arguments_with_status_2(args: list[str], message: str) -> None:
    proc = run("simulate", *args, check=False)
    assert proc.returncode == 2
    assert message in proc.stderr
    assert "Traceback" not in proc.stderr


def test_params_lists_every_parameter_and_module_entry_point_works() -> None:
    proc = run("params")
    for name in ("Kzeta (1/s)", "tau_max (N m)", "wall (rad)", "robust:", "xc_omega (rad/s)"):
        assert name in proc.stdout
    version = subprocess.run(
        [sys.executable, "-m", "adaptimp", "--version"], capture_output=True, text=True, check=True
    )
    assert version.stdout.startswith("adaptimp ")


HOBBY = str(Path(__file__).resolve().parent / "data" / "hobby_arm.urdf")
FOLD = str(Path(__file__).resolve().parent / "data" / "fold_arm.xml")


def test_simulate_runs_any_arm_on_the_python_route(tmp_path: Path) -> None:
    """``--model FILE`` (a URDF, an MJCF) runs amj.simulate on it: the default
    joint task, or the Cartesian task; the figure names the joints (issue 45,
    finding 8)."""
    png = tmp_path / "arm.png"
    proc = run("simulate", "--model", HOBBY, "--T", "2.5", "--plot", str(png), "--json")
    metrics = json.loads(proc.stdout)
    from adaptimp import mujoco as amj

    with pytest.warns(UserWarning, match="effort limit"):
        want = amj.simulate("sf", HOBBY, T=2.5)
    assert metrics["rms_z1_after2"] == want.metrics["rms_z1_after2"]
    assert png.read_bytes().startswith(b"\x89PNG")
    proc = run("simulate", "--model", FOLD, "--task", "cartesian", "--case", "pd", "--T", "2.5",
               check=False)  # fmt: skip
    assert proc.returncode == 2
    assert proc.stderr.startswith("adaptimp simulate: error: no start posture found")
    assert proc.stderr.endswith(" (from the shell: --home q1,…,qn gives q0, --tip the tip)\n")
    assert len(proc.stderr.strip().splitlines()) == 1
    # The refusal's advice runs from the shell: --home is the Cartesian task's start.
    with pytest.warns(UserWarning, match="effort limit"):
        plant = amj.Plant(HOBBY)
    task = amj.cartesian_task(plant)
    home = ",".join(repr(float(x)) for x in task.q0)
    proc = run("simulate", "--model", HOBBY, "--task", "cartesian", "--home", home, "--T", "2.5",
               "--json")  # fmt: skip
    given = amj.simulate("sf", plant, T=2.5, task=amj.cartesian_task(plant, q0=task.q0))
    assert json.loads(proc.stdout)["rms_pos_after2"] == given.metrics["rms_pos_after2"]
    proc = run("simulate", "--model", HOBBY, "--task", "cartesian", "--T", "2.5")
    assert "on hobby_arm.urdf: 2500 steps" in proc.stdout
    assert "the Cartesian task, t ≥ 2 s: position RMS " in proc.stdout
    assert "(the position only: fewer than six joints)" in proc.stdout
    # z1 of a Cartesian run is the tip's position error: three axes in m, not joints in rad.
    assert "| RMS z1 per axis x, y, z, t ≥ 2 s (m) " in proc.stdout
    assert "| RMS ‖z1‖ (m) " in proc.stdout
    assert "(rad)" not in proc.stdout
    proc = run("simulate", "--model", HOBBY, "--tip", "tcp", check=False)
    assert proc.returncode == 2
    assert proc.stderr == (
        "adaptimp simulate: error: URDF 'hobby_arm.urdf': tip= 'tcp' is neither a link nor a "
        "frame of it: name the link (a MuJoCo body) or the frame (a site) that ends the arm; "
        "its 10 links and 0 frames, closest first: ['tool', 'wrist', 'upper_arm', 'jaw', "
        "'base', 'hand', 'world', 'forearm', 'shoulder', 'finger_link']\n"
    )


def test_table_runs_an_arm_at_a_home_given(tmp_path: Path) -> None:
    """``adaptimp table --model FILE --home …`` (pi in the angles, a negative
    first one) runs the table's rows on the arm, as arm_table and run_row do."""
    out = tmp_path / "t.json"
    ur5 = Path(adaptimp._models.panda_urdf_path()).parents[2] / "ur_description/urdf/ur5_robot.urdf"
    proc = run("table", "--model", str(ur5), "--home", "-pi/2+pi/2,-pi/2,pi/2,-pi/2,-pi/2,0",
               "--rows", "sf", "--T", "2.5", "--json", str(out))  # fmt: skip
    assert "| SF, unified n = 0.3 |" in proc.stdout
    table = json.loads(out.read_text())
    assert table["home"] == pytest.approx([0.0, -np.pi / 2, np.pi / 2, -np.pi / 2, -np.pi / 2, 0])
    assert set(table["rows"]) == {"sf"}
    proc = run("table", "--rows", "sff", check=False)
    assert proc.returncode == 2
    assert proc.stderr.startswith(
        "adaptimp table: error: --rows: no row 'sff'; did you mean sf or sf-ff?"
    )


def test_simulate_takes_the_rules_inertia_shaped_gains() -> None:
    """The rule's inertia-shaped gains (SPEC (18.12)) are simulate's default
    with a delay, ``--no-coupled`` is ``coupled=False``: two periods late, PD
    with the coupled gains holds the servo arm far closer than the diagonal
    rule's PD (docs/your_arm.md: 0.018 against 0.123 rad, T = 8 s)."""
    rms = {}
    for flag in ((), ("--coupled",), ("--no-coupled",)):
        proc = run("simulate", "--model", HOBBY, "--case", "pd", "--T", "4", "--delay", "2",
                   *flag, "--json")  # fmt: skip
        rms[flag] = json.loads(proc.stdout)["rms_z1_after2"]
    assert rms[()] == rms[("--coupled",)]
    assert rms[()] < 0.5 * rms[("--no-coupled",)]
