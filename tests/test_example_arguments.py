"""examples/13's arguments are refused before any row runs (issue 33): a broken
--arm is a usage error, not a traceback; a --json that cannot be written is
known at once, not after every row; a --T whose records would not fit is
refused instead of a MemoryError."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "13_panda_table.py"


def _usage_error(*args: str) -> str:
    proc = subprocess.run(
        [sys.executable, str(EXAMPLE), *args],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
        env={**os.environ, "ADAPTIMP_QUICK": "1"},
    )
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert "Traceback" not in proc.stderr, proc.stderr
    assert proc.stdout == "", "nothing ran"
    return proc.stderr.strip().splitlines()[-1]


def test_a_broken_arm_is_a_usage_error(tmp_path: Path) -> None:
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot name='x'><link name='a'>")
    assert _usage_error("--arm", str(broken)) == (
        f"13_panda_table.py: error: cannot read {broken} as a URDF: it is not XML: it ends "
        "before its root element is closed; correct it against the URDF format "
        "(http://wiki.ros.org/urdf/XML)"
    )


@pytest.mark.parametrize("where", ["a directory", "a file in no writable place"])
def test_a_json_that_cannot_be_written_is_refused_before_the_rows(
    where: str, tmp_path: Path
) -> None:
    target = tmp_path if where == "a directory" else Path("/proc/adaptimp.json")
    assert _usage_error("--json", str(target)) == (
        f"13_panda_table.py: error: --json: cannot write {target} (a directory, or not writable)"
    )


def test_a_duration_whose_records_would_not_fit_is_refused() -> None:
    assert _usage_error("--T", "2e5") == (
        "13_panda_table.py: error: --T must be at most 3600 s (every step is kept), got 200000"
    )


_WITHOUT_PINOCCHIO = """
import importlib.metadata as md, runpy, sys
real = md.distribution
def distribution(name):
    if name == "example-robot-data":
        raise md.PackageNotFoundError(name)
    return real(name)
md.distribution = distribution
sys.modules["pinocchio"] = None  # `import pinocchio` fails, as without the extra
sys.argv = [sys.argv[1], *sys.argv[2:]]
runpy.run_path(sys.argv[0], run_name="__main__")
"""


def _without_pinocchio(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", _WITHOUT_PINOCCHIO, str(EXAMPLE.with_name("15_your_arm.py")), *args],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        env={**os.environ, "ADAPTIMP_QUICK": "1"},
    )


def test_your_arm_with_a_urdf_needs_only_mujoco() -> None:
    """examples/15 given a URDF looked the default UR5 up at import and died
    without the extra pinocchio, which the README does not name for it."""
    hobby = Path(__file__).resolve().parent / "data" / "hobby_arm.urdf"
    proc = _without_pinocchio(str(hobby))
    assert proc.returncode == 0, proc.stderr
    assert "hobby_arm.urdf: 5 joints" in proc.stdout
    assert "| sf |" in proc.stdout
    # The default arm and --payload's computed torque need the extra: said so.
    proc = _without_pinocchio()
    assert proc.returncode == 2
    assert "no file given, and the default UR5 needs the extra pinocchio" in proc.stderr
    proc = _without_pinocchio(str(hobby), "--payload", "0.1")
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert "pinocchio" in proc.stderr.strip().splitlines()[-1]


EXAMPLES = sorted(EXAMPLE.parent.glob("[0-9][0-9]_*.py"))


@pytest.mark.parametrize("path", EXAMPLES, ids=[p.stem for p in EXAMPLES])
def test_every_example_s_help_is_whole(path: Path) -> None:
    """--help prints the docstring's whole first paragraph (it stopped
    mid-sentence: issue 45, finding 4) and runs nothing."""
    proc = subprocess.run(
        [sys.executable, str(path), "--help"], capture_output=True, text=True, timeout=120,
        check=False,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    first = " ".join(path.read_text().split('"""')[1].split("\n\n")[0].split())
    assert first in " ".join(proc.stdout.split())
    assert first.endswith((".", "?", ")")), first


def test_the_figure_is_of_the_arm_run_and_goes_to_the_output_folder(tmp_path: Path) -> None:
    """examples/13 --arm FILE --figure plots that arm, into --out; docs/ is never
    written (issue 45, finding 4)."""
    docs = EXAMPLE.parent.parent / "docs" / "figures" / "contact_force.png"
    before = docs.stat().st_mtime_ns
    hobby = Path(__file__).resolve().parent / "data" / "hobby_arm.urdf"
    proc = subprocess.run(
        [sys.executable, str(EXAMPLE), "--arm", str(hobby), "--rows", "sf", "--figure",
         "--out", str(tmp_path / "figs")],
        capture_output=True, text=True, timeout=600, check=False,
        env={**os.environ, "ADAPTIMP_QUICK": "1", "MPLBACKEND": "Agg"},
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    figure = tmp_path / "figs" / "contact_force.png"
    assert f"wrote {figure}" in proc.stdout
    assert figure.read_bytes().startswith(b"\x89PNG")
    assert docs.stat().st_mtime_ns == before


def test_a_wrong_tip_is_one_line_not_a_traceback() -> None:
    """examples/15 given a tip its arm does not have: one line naming the links,
    closest first (issue 45, finding 6)."""
    hobby = Path(__file__).resolve().parent / "data" / "hobby_arm.urdf"
    proc = subprocess.run(
        [sys.executable, str(EXAMPLE.with_name("15_your_arm.py")), str(hobby), "--tip", "tcp"],
        capture_output=True, text=True, timeout=300, check=False,
        env={**os.environ, "ADAPTIMP_QUICK": "1"},
    )  # fmt: skip
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert "Traceback" not in proc.stderr
    assert lines[-1].startswith(
        "15_your_arm.py: error: URDF 'hobby_arm.urdf': tip= 'tcp' is neither a link nor a "
        "frame of it"
    )
    assert lines[-1].endswith("closest first: ['tool', 'wrist', 'upper_arm', 'jaw', 'base', "
                              "'hand', 'world', 'forearm', 'shoulder', 'finger_link']")  # fmt: skip


def test_drift_is_read_as_printed() -> None:
    """Both windows printed 0.000106 and the column read "no" (issue 45,
    finding 11): the verdict compares the numbers the table shows."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("your_arm", EXAMPLE.with_name("15_your_arm.py"))
    assert spec is not None
    assert spec.loader is not None
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    assert f"{0.00010601:.3g}" == f"{0.00010649:.3g}" == "0.000106"
    assert example.drift_ok(0.00010601, 0.00010649) == "yes"
    assert example.drift_ok(0.000106, 0.000107) == "no"
    assert example.drift_ok(0.000107, 0.000106) == "yes"
