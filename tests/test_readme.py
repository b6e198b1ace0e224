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
