"""The C ABI (ffi/) from C and C++: the examples built with CMake and
-Wall -Wextra -Werror, their results against Rust and Python, and valgrind."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import adaptimp

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "target" / "ffi-examples"


def sh(*args: str | Path, timeout: float = 900) -> subprocess.CompletedProcess[str]:
    proc = subprocess.run(
        [str(a) for a in args], capture_output=True, text=True, timeout=timeout, check=False
    )
    assert proc.returncode == 0, f"{args}: {proc.stdout}\n{proc.stderr}"
    return proc


@pytest.fixture(scope="module")
def examples() -> Path:
    """The C and C++ examples, configured and built with CMake (incrementally)."""
    assert shutil.which("cmake"), "cmake is needed (scripts/test.sh installs it)"
    sh("cmake", "-S", ROOT / "ffi" / "examples", "-B", BUILD, "-DCMAKE_BUILD_TYPE=Release")
    sh("cmake", "--build", BUILD)
    return BUILD


def test_ctest_runs_the_examples(examples: Path) -> None:
    out = sh("ctest", "--test-dir", examples, "--output-on-failure").stdout
    assert "100% tests passed" in out


def test_c_torques_equal_python_and_rust_for_the_same_inputs(examples: Path) -> None:
    """paper --torques steps each preset and law through the C ABI with a fixed
    input sequence; Python (the Rust core) steps the same sequence."""
    lines = sh(examples / "paper", "--torques").stdout.split()
    rows = np.array(lines, dtype=object).reshape(-1, 5)
    assert len(rows) == 3 * 2 * 200
    for case in ("pd", "sf", "of"):
        for scenario in ("paper", "robot"):
            ctrl = adaptimp.Controller(case, scenario=scenario)
            sel = rows[(rows[:, 0] == case) & (rows[:, 1] == scenario)]
            c_tau = sel[:, 3:].astype(float)
            for k in range(200):
                s = float(k)
                q = [0.25 + 0.01 * math.sin(0.1 * s), -0.05 + 0.01 * math.cos(0.07 * s)]
                dq = [0.1 * math.cos(0.1 * s), -0.1 * math.sin(0.07 * s)]
                te = [max(0.0, 5.0 * math.sin(0.05 * s)), 0.0]
                tau = ctrl.step(q, te, dq)
                np.testing.assert_allclose(c_tau[k], tau, rtol=1e-12, atol=1e-12)


def test_the_c_paper_example_prints_the_rust_examples_metrics(examples: Path) -> None:
    """The paper's arm written in C, the controllers through the ABI: the SPEC
    §12 table equals `cargo run --example paper`'s to every printed digit."""

    def table(text: str) -> list[str]:
        return [ln for ln in text.splitlines() if ln.startswith("|") and "wall time" not in ln]

    c = table(sh(examples / "paper").stdout)
    # The test profile (optimised, like release) reuses the build of `cargo test`.
    rust = table(sh("cargo", "run", "--quiet", "--profile", "test", "--example", "paper").stdout)
    assert len(c) == 13
    assert c == rust


def test_valgrind_finds_no_error_no_leak_and_allocations_do_not_grow(examples: Path) -> None:
    assert shutil.which("valgrind"), "valgrind is needed (scripts/test.sh installs it)"
    counts = []
    for steps in ("10", "100000"):
        proc = subprocess.run(
            [
                "valgrind",
                "--leak-check=full",
                "--errors-for-leak-kinds=all",
                "--error-exitcode=3",
                str(examples / "paper"),
                "--steps",
                steps,
            ],
            capture_output=True,
            text=True,
            timeout=600,
            check=False,
        )
        assert proc.returncode == 0, proc.stderr
        assert "ERROR SUMMARY: 0 errors" in proc.stderr
        m = re.search(r"total heap usage: ([\d,]+) allocs, ([\d,]+) frees", proc.stderr)
        assert m, proc.stderr
        allocs, frees = (int(g.replace(",", "")) for g in m.groups())
        assert allocs == frees
        counts.append(allocs)
    assert counts[0] == counts[1], counts
