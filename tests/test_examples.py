"""Every Python example runs (shortened by ADAPTIMP_QUICK=1) and its Rust mirror
prints the same figures: the numbered examples of ``examples/``."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
PYTHON = sorted(EXAMPLES.glob("[0-9][0-9]_*.py"))


def test_examples_are_numbered_and_mirrored_where_both_apply() -> None:
    names = {p.stem for p in EXAMPLES.iterdir() if p.suffix in (".py", ".rs")}
    assert all(n[:2].isdigit() and n[2] == "_" for n in names), sorted(names)
    for stem in (
        "01_paper",
        "02_robot_1khz",
        "03_your_loop",
        "04_custom_basis",
        "14_cartesian_pose",
    ):
        assert (EXAMPLES / f"{stem}.py").exists()
        assert (EXAMPLES / f"{stem}.rs").exists()


@pytest.mark.parametrize("path", PYTHON, ids=[p.stem for p in PYTHON])
def test_python_example_runs(path: Path, tmp_path: Path) -> None:
    env = dict(os.environ, ADAPTIMP_QUICK="1", MPLBACKEND="Agg")
    args = [sys.executable, str(path)]
    if path.stem == "02_robot_1khz":
        args.append(str(tmp_path / "figure.png"))
    if path.stem == "12_robustness":
        args.append(str(tmp_path))
    out = subprocess.run(args, capture_output=True, text=True, env=env, timeout=600, check=False)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip()
