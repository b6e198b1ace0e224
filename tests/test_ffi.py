"""The C ABI (ffi/) from C and C++: the examples built with CMake and
-Wall -Wextra -Werror, their results against Rust and Python, and valgrind."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import adaptimp
from adaptimp import Measurement, tuning

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
                tau = ctrl.step(Measurement(q, dq, tau_e=te))
                np.testing.assert_allclose(c_tau[k], tau, rtol=1e-12, atol=1e-12)


# The same parameters given to both fronts: (n, case, scenario, parameters);
# n > 3 without centres takes the rule's default basis (SPEC §18) in both.
SAME = [
    (1, "pd", "robot", {"Kp": [3.0]}),
    (2, "sf", "paper", {}),
    (3, "of", "robot", {"tau_max": [30.0, 20.0, 10.0], "delay": 1}),
    (4, "sf", "robot", {}),
    (5, "pd", "paper", {"xc_sin": [0.1, 0.2, 0.3, 0.2, 0.1], "xc_omega": [1.0] * 5}),
    (6, "of", "robot", {"Ts": 0.002, "gamma": [20.0, 10.0, 5.0]}),
    (7, "sf", "robot", {"tau_max": [80.0, 80.0, 60.0, 60.0, 30.0, 20.0, 10.0]}),
]


def _inputs(n: int, steps: int) -> np.ndarray:
    """q (rad), dq (rad/s), tau_e (N m) of each step: (steps, 3n)."""
    k = np.arange(steps)[:, None]
    i = np.arange(n)[None, :]
    q = 0.2 * np.sin(0.05 * k + i)
    dq = 0.01 * np.cos(0.05 * k + i)
    te = np.where(i == 0, 0.5 * np.sin(0.03 * k), 0.0)
    return np.hstack([q, dq, te])


def _c_controller(
    examples: Path, n: int, case: str, scenario: str, params: dict[str, Any], x: np.ndarray
) -> np.ndarray:
    args = [
        f"{k}={','.join(repr(float(v)) for v in np.atleast_1d(val))}" for k, val in params.items()
    ]
    proc = subprocess.run(
        [str(examples / "same_controller"), str(n), case, scenario, *args],
        input="\n".join(" ".join(repr(float(v)) for v in row) for row in x) + "\n",
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    return np.array([[float(v) for v in ln.split()] for ln in proc.stdout.splitlines()])


def _python_controller(ctrl: adaptimp.Controller, n: int, x: np.ndarray) -> np.ndarray:
    rows = []
    for row in x:
        tau_sat = ctrl.step(Measurement(row[:n], row[n : 2 * n], tau_e=row[2 * n :]))
        rows.append(np.concatenate([tau_sat, ctrl.tau]))
    return np.array(rows)


@pytest.mark.parametrize(("n", "case", "scenario", "params"), SAME)
def test_c_and_python_build_the_same_controller_from_the_same_parameters(
    examples: Path, n: int, case: str, scenario: str, params: dict[str, Any]
) -> None:
    """The same parameters through the C ABI (ffi/tests/same_controller.c) and
    through Python, the same inputs: the same sat(τ) and τ at every step, bit
    for bit, for every n, law and preset (n > 3 without centres included: C
    refused it, Python made the rule's basis; both now take the core's one
    builder's)."""
    x = _inputs(n, 40)
    c = _c_controller(examples, n, case, scenario, params, x)
    py = _python_controller(adaptimp.Controller(case, scenario=scenario, n=n, **params), n, x)
    assert c.shape == (40, 2 * n)
    np.testing.assert_array_equal(c, py)
    assert np.abs(c[:, n:]).max() > 0.0


def test_c_and_python_build_the_same_controller_on_user_centres(examples: Path) -> None:
    """User centres and widths (L, 4n), (4n,) given to both fronts: the same
    torques, bit for bit."""
    n, nodes = 6, 30
    rng = np.random.default_rng(7)
    centers = rng.uniform(-0.5, 0.5, size=(nodes, 4 * n))
    widths = np.linspace(0.5, 2.0, 4 * n)
    x = _inputs(n, 30)
    params = {"centers": centers.ravel(), "widths2": widths**2}
    c = _c_controller(examples, n, "sf", "robot", params, x)
    ctrl = adaptimp.Controller("sf", scenario="robot", n=n, centers=centers, widths=widths)
    np.testing.assert_array_equal(c, _python_controller(ctrl, n, x))


class _Arm:
    """A made-up arm of n joints: D(q) symmetric positive definite and G(q),
    smooth in q (kg m², N m)."""

    def __init__(self, n: int, heavy: float = 1.0) -> None:
        rng = np.random.default_rng(n)
        a = rng.uniform(-0.3, 0.3, size=(n, n))
        self.base = a @ a.T + np.diag(np.linspace(2.0, 0.2, n))
        self.n, self.heavy = n, heavy

    def D(self, q: np.ndarray) -> np.ndarray:
        c = np.cos(q)
        return self.base + 0.1 * np.outer(c, c) + np.diag(0.05 * np.sin(q) ** 2)

    def G(self, q: np.ndarray) -> np.ndarray:
        return self.heavy * 5.0 * np.sin(q + 0.3) * np.linspace(1.0, 0.2, self.n)


# The rule's inputs given to both fronts: (n, case, delay, path, keywords of
# tuning.suggest); every field of AdaptimpTuning is set by one of them, and
# the gravity ("heavy": the arm's G scaled, the tube then holding its sag)
# and `resolve` (on a path small enough for (16.10) to narrow the tube,
# "small": its amplitude scaled) each change the controller where given.
RULE = [
    (2, "sf", 0, False, {}),
    (3, "pd", 0, True, {"coupled": True}),
    (3, "sf", 0, True, {"heavy": 1000.0}),
    (4, "of", 1, True, {"resolve": True}),
    (4, "sf", 0, True, {"resolve": True, "small": 0.05}),
    (6, "sf", 2, True, {"damping": 0.5, "orbit": True, "critical": True, "weightless": True}),
    (7, "sf", 1, True, {"coupled": False, "damping": [0.1, 0.2, 0.3, 0.4, 0.3, 0.2, 0.1]}),
]


def _differ(a: dict[str, Any], b: dict[str, Any]) -> bool:
    """Whether two suggestions differ in any keyword."""
    return a.keys() != b.keys() or any(
        not np.array_equal(np.asarray(a[k]), np.asarray(b[k])) for k in a
    )


@pytest.mark.parametrize(("n", "case", "delay", "with_path", "kw"), RULE)
def test_c_and_python_build_the_same_controller_from_the_same_rule_inputs(
    examples: Path, n: int, case: str, delay: int, with_path: bool, kw: dict[str, Any]
) -> None:
    """The rule of SPEC §18 given the same inputs through C
    (adaptimp_params_suggest_tuning, every field of AdaptimpTuning) and
    through Python (tuning.suggest): the same controller, its torques bit for
    bit; with a path, the inertia along it, the gravity, the damping, the
    orbit and the flags as Python reads them from its model."""
    kw = dict(kw)
    heavy, small = kw.pop("heavy", 1.0), kw.pop("small", 1.0)
    arm = _Arm(n, heavy)
    period, k = 4.0, 40
    t = np.arange(k)[:, None] * period / k
    w = 2 * np.pi / period
    amp = small * np.linspace(0.4, 0.1, n)[None, :]
    q = 0.2 + amp * np.sin(w * t)
    rows = np.hstack([q, amp * w * np.cos(w * t), -amp * w * w * np.sin(w * t)])
    q0 = rows[0, :n]
    tau = np.linspace(60.0, 10.0, n)
    fields: dict[str, Any] = {"tau_max": tau, "Ts": 1e-3, "delay": delay}
    py_kw = dict(kw)
    if with_path:
        py_kw.update(path=rows, period=period)
        fields.update(path=rows.ravel(), period=period, gravity=arm.G(q0), inertia_samples=k)
        fields["inertia"] = np.concatenate([arm.D(r).ravel() for r in q])
    else:
        fields["inertia"] = arm.D(q0).ravel()
    if kw.get("orbit"):
        py_kw["orbit"] = q[::4]
        fields["orbit"] = q[::4].ravel()
    if "damping" in kw:
        fields["damping"] = np.broadcast_to(kw["damping"], (n,))
    for flag in ("resolve", "critical", "weightless"):
        fields[flag] = float(kw.get(flag, False))
    fields["coupling"] = {None: 0, False: 1, True: 2}[kw.get("coupled")]
    sug = tuning.suggest(arm, q0, tau, Ts=1e-3, case=case, delay=delay, **py_kw)
    # The row's gravity and resolve change the controller (so C must pass them).
    if heavy != 1.0:
        light = tuning.suggest(_Arm(n), q0, tau, Ts=1e-3, case=case, delay=delay, **py_kw)
        assert _differ(sug, light)
    if small != 1.0:
        coarse = {**py_kw, "resolve": False}
        assert _differ(sug, tuning.suggest(arm, q0, tau, Ts=1e-3, case=case, delay=delay, **coarse))
    x = _inputs(n, 40)
    c = _c_controller(examples, n, case, "rule", fields, x)
    ctrl = adaptimp.Controller(case, scenario="robot", **sug)
    assert ("centers" in sug) == with_path
    assert ("inertia_matrix" in sug) == kw.get("coupled", delay >= 1)
    np.testing.assert_array_equal(c, _python_controller(ctrl, n, x))
    assert np.abs(c[:, n:]).max() > 0.0


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


def test_the_c_cartesian_example_prints_the_rust_and_python_examples_figures(
    examples: Path,
) -> None:
    """examples/14_cartesian_pose in C (the Panda's joint data written in C, the
    plant in C, the controller through the ABI), Rust and Python: the same
    printed figures."""
    c = sh(examples / "cartesian_pose").stdout
    rust = sh("cargo", "run", "--quiet", "--release", "--example", "cartesian_pose").stdout
    py = sh(sys.executable, ROOT / "examples" / "14_cartesian_pose.py").stdout
    assert c.count("\n") == 6
    assert "normal force on the table       = 4.545 N" in c
    assert c == rust
    assert c == py


def test_the_c_examples_build_as_iso_c11_and_cxx17(examples: Path) -> None:
    """Each example compiles alone with -std=c11 (-std=c++17) -Wall -Wextra
    -Werror: no GNU extension (paper.c's clock_gettime needs its POSIX feature
    macro), whatever CMake would add."""
    for src, compiler, std in (
        ("paper.c", "cc", "-std=c11"),
        ("14_cartesian_pose.c", "cc", "-std=c11"),
        ("torque_callback.cpp", "c++", "-std=c++17"),
    ):
        sh(
            compiler,
            std,
            "-Wall",
            "-Wextra",
            "-Werror",
            "-pedantic",
            "-fsyntax-only",
            "-I",
            ROOT / "ffi" / "include",
            ROOT / "ffi" / "examples" / src,
        )


def valgrind(*args: str | Path, stdin: str | None = None) -> str:
    """Run under valgrind's memcheck: no error, no leak; its stderr."""
    proc = subprocess.run(
        [
            "valgrind",
            "--leak-check=full",
            "--errors-for-leak-kinds=all",
            "--error-exitcode=3",
            *[str(a) for a in args],
        ],
        input=stdin,
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "ERROR SUMMARY: 0 errors" in proc.stderr
    assert "All heap blocks were freed -- no leaks are possible" in proc.stderr
    return proc.stderr


def test_valgrind_finds_no_error_and_no_leak_in_the_cartesian_example(examples: Path) -> None:
    assert shutil.which("valgrind"), "valgrind is needed (scripts/test.sh installs it)"
    valgrind(examples / "cartesian_pose")
    valgrind(examples / "cartesian_pose", "--abi-checks")
    valgrind(examples / "paper", "--abi-checks")


def test_valgrind_finds_no_error_and_no_leak_building_seven_joints_without_centres(
    examples: Path,
) -> None:
    """The one builder's default basis for n > 3 through the C ABI, and user
    centres, under memcheck."""
    assert shutil.which("valgrind"), "valgrind is needed (scripts/test.sh installs it)"
    rows = "\n".join(" ".join(repr(float(v)) for v in row) for row in _inputs(7, 5)) + "\n"
    valgrind(examples / "same_controller", "7", "of", "robot", stdin=rows)
    centres = ",".join(["0.1"] * (2 * 4 * 7))
    valgrind(examples / "same_controller", "7", "sf", "robot", f"centers={centres}", stdin=rows)


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


def test_the_c_break_it_probe_finds_no_crash_hang_or_wrong_result_under_valgrind(
    examples: Path,
) -> None:
    """ffi/tests/breakit.c: NULLs, sizes, enum integers, NaN/inf/huge values,
    bit flips and truncations of snapshots, dead and foreign handles, caller
    buffers, bad chains and rotations through the C ABI; each case is a clear
    refusal or an accepted call whose invariants hold, and memcheck finds no
    error and no leak in any of its processes."""
    assert shutil.which("valgrind"), "valgrind is needed (scripts/test.sh installs it)"
    proc = subprocess.run(
        [
            "valgrind",
            "--leak-check=full",
            "--errors-for-leak-kinds=all",
            "--error-exitcode=3",
            str(examples / "breakit"),
        ],
        capture_output=True,
        text=True,
        timeout=900,
        check=False,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    summaries = re.findall(r"ERROR SUMMARY: (\d+) errors", proc.stderr)
    assert summaries, proc.stderr
    assert set(summaries) == {"0"}, proc.stderr
    m = re.search(r"^\| \*\*all\*\* \|(.*)\|$", proc.stdout, re.MULTILINE)
    assert m, proc.stdout
    cases, accepted, clear, crash, hang, wrong, false_refusal = (
        int(c.strip().strip("*")) for c in m.group(1).split("|")
    )
    assert cases == accepted + clear > 10_000, proc.stdout
    assert (crash, hang, wrong, false_refusal) == (0, 0, 0, 0), proc.stdout


def test_the_forged_handle_probe_covers_every_entry_point_that_takes_a_handle() -> None:
    """breakit.c's category "forged handles" calls each function of the header
    that takes a handle, with every bad handle in each handle argument; a new
    entry point must be added to its table (ENTRIES)."""
    header = (ROOT / "ffi" / "include" / "adaptimp.h").read_text()
    kinds = re.findall(r"typedef struct (Adaptimp\w+) \1;", header)
    assert len(kinds) >= 5, kinds
    takes = set()
    for name, args in re.findall(r"\b(adaptimp_\w+)\(([^;]*?)\);", header, re.S):
        if any(re.search(rf"struct {k} \*", args) and f"struct {k} **" not in args for k in kinds):
            takes.add(name)
    probe = (ROOT / "ffi" / "tests" / "breakit.c").read_text()
    table = probe[probe.index("static const Entry ENTRIES[]") :]
    table = table[: table.index("};")]
    listed = set(re.findall(r'\{"(adaptimp_\w+)"', table))
    assert takes - listed == set(), f"not probed with forged handles: {sorted(takes - listed)}"
    assert listed - takes == set(), sorted(listed - takes)


def test_the_c_urdf_reader_reads_the_arm_python_reads(examples: Path) -> None:
    """ffi/examples/16_read_urdf.c: adaptimp_chain_from_urdf reads a URDF file
    (or text) by the core's one reduction (SPEC §21): the arm's joints, limits,
    efforts, drive terms and tip equal Python's; each refusal is a status with
    a message naming the file and the element; memcheck finds no error and no
    leak, reading or refusing."""
    from adaptimp._description import read_arm

    assert shutil.which("valgrind"), "valgrind is needed (scripts/test.sh installs it)"
    hobby = ROOT / "tests" / "data" / "hobby_arm.urdf"
    out = sh(examples / "read_urdf", hobby).stdout
    arm = read_arm(hobby)
    assert f"n = {arm.n}\n" in out
    for i, (lo, hi, effort, damping) in enumerate(
        zip(arm.lower, arm.upper, arm.effort, arm.damping)
    ):
        line = re.search(
            rf"^joint {i}: revolute, limits \[(\S+), (\S+)\], effort (\S+), "
            rf"damping (\S+), friction",
            out,
            re.MULTILINE,
        )
        assert line, out
        got = [float(x) for x in line.groups()]
        np.testing.assert_array_equal(got, [lo, hi, effort, damping])
    chain = adaptimp.Chain.from_urdf(hobby)
    tip = re.search(r"^tip at q = 0: (\S+) (\S+) (\S+)$", out, re.MULTILINE)
    assert tip, out
    np.testing.assert_array_equal([float(x) for x in tip.groups()], chain.fk([0.0] * 5)[:3, 3])
    # Held by the rule in C as in Python: a tip beyond the gripper's joint.
    assert "n = 6\n" in sh(examples / "read_urdf", hobby, "--tip", "jaw").stdout
    errors = sh(examples / "read_urdf", "--errors").stdout
    assert "FAIL" not in errors, errors
    assert errors.count("ok ") == 6, errors
    valgrind(examples / "read_urdf")
    valgrind(examples / "read_urdf", "--errors")
    valgrind(examples / "read_urdf", hobby, "--fix", "wrist_roll")
