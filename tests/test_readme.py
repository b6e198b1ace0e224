"""The README's Python example runs as written."""

from __future__ import annotations

import pathlib
import re

import pytest

README = pathlib.Path(__file__).resolve().parent.parent / "README.md"


def test_readme_python_example_runs(
    tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch, close_figures: None
) -> None:
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
    assert blocks, "the README has a Python example"
    monkeypatch.chdir(tmp_path)  # it writes tracking.png and sf.npz
    namespace: dict[str, object] = {}
    exec(compile(blocks[0], str(README), "exec"), namespace)
    assert (tmp_path / "tracking.png").stat().st_size > 0
    assert (tmp_path / "sf.npz").stat().st_size > 0


def test_readme_your_arm_example_runs(
    tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch, close_figures: None
) -> None:
    """The five lines of "Your arm", on the UR5 of example-robot-data for
    ``my_arm.urdf``: they run as written, and state feedback tracks the default
    task at under a fifth of PD's error (issue 22's target)."""
    from adaptimp import _models

    ur5 = _models.panda_urdf_path().parents[2] / "ur_description" / "urdf" / "ur5_robot.urdf"
    blocks = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
    (block,) = [b for b in blocks if "my_arm.urdf" in b]
    monkeypatch.chdir(tmp_path)  # it writes my_arm.png
    namespace: dict[str, object] = {}
    exec(compile(block.replace("my_arm.urdf", str(ur5)), str(README), "exec"), namespace)
    runs = namespace["runs"]
    assert isinstance(runs, dict)
    rms = {case: res.metrics["rms_z1_after2"] for case, res in runs.items()}
    assert rms["sf"] < 0.2 * rms["pd"], rms
    assert rms["of"] < 0.2 * rms["pd"], rms
    assert (tmp_path / "my_arm.png").stat().st_size > 0
