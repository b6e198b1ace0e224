"""Every code block of README.md and docs/*.md runs as written.

A page's Python blocks run in order in one namespace, as a reader follows the
page, from a directory where the checkout's ``tests/`` and ``examples/`` are
(a block that names ``tests/data/hobby_arm.urdf`` finds it) and where the
files a block writes go. A block that is not Python is checked where the
table below says, or is not run for the reason it gives; a block the table
does not account for fails the test, so a new block is runnable or says why
not.
"""

from __future__ import annotations

import os
import pathlib
import re
import shlex
import subprocess
import sys
from typing import Any

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
PAGES = ["README.md", *sorted(f"docs/{p.name}" for p in (ROOT / "docs").glob("*.md"))]
BLOCK = re.compile(r"^```(\w*)\n(.*?)^```", re.S | re.M)

# (page, index of the block in the page): how a block that is not run here as
# Python is checked, or why it is not run.
ELSEWHERE: dict[tuple[str, int], str] = {
    ("README.md", 0): "installs from the checkout (a build) and runs the whole suite: "
    "scripts/test.sh is that suite; scripts/test_wheel.sh runs `adaptimp reproduce` from "
    "an installed wheel",
    ("README.md", 1): "builds and installs the wheel: scripts/wheel.sh and "
    "scripts/test_wheel.sh do, in scripts/test.sh",
    ("README.md", 6): "shell: run here (RUN_SHELL)",
    ("README.md", 7): "Rust: tests/snippets/readme_quickstart.rs, a doctest of src/lib.rs; "
    "tests/readme.rs keeps the README's copy identical",
    ("README.md", 8): "CMake: run here in a project of one C file "
    "(test_the_cmake_lines_link_a_project), path/to/adaptimp being this checkout",
    ("README.md", 9): "runs this whole suite (it is scripts/test.sh)",
    ("docs/cartesian.md", 4): "Rust: the shape of the calls; the whole program is "
    "examples/14_cartesian_pose.rs, which tests/test_ffi.py runs against C and Python",
    ("docs/franka.md", 0): "installs the extra and starts a server that runs until Ctrl-C: "
    "scripts/test.sh installs both, tests/test_franka_sim.py starts the same server "
    "(franka.Simulator)",
    ("docs/franka.md", 1): "drives a robot (or a server) at 127.0.0.1 for 20 s: "
    "tests/test_franka_sim.py makes the same calls against franky-sim on a loopback address",
    ("docs/franka.md", 2): "a 10 s run on a server of its own: tests/test_franka_sim.py's "
    "loaded runs are these calls",
    ("docs/franka.md", 3): "needs libfranka's C++ library (its CMake package), which CI does "
    "not install",
    ("docs/index.md", 0): "installs the wheel or builds the checkout: scripts/test_wheel.sh",
    ("docs/layout.md", 0): "the import graph's command: tests/test_layout.py runs its "
    "graph() and asserts no circle",
    ("docs/mujoco.md", 0): "installs the extras: scripts/test.sh installs the test extra",
    ("docs/mujoco.md", 2): "the callback protocol's three call shapes, not a program: the "
    "next block runs one (MyPD); tests/test_python_real_work.py and test_mujoco_cartesian.py "
    "run Python controllers of the other two",
    ("docs/paper.md", 0): "shell: run here (RUN_SHELL)",
    ("docs/panda.md", 0): "installs the extras and runs the Panda's table (9 min): "
    "tests/test_examples.py runs examples/13 with ADAPTIMP_QUICK=1",
    ("docs/robot.md", 1): "Rust: tests/snippets/robot_hardened.rs, a doctest of src/lib.rs; "
    "test_every_block_is_accounted_for keeps the page's copy identical",
    ("docs/robosuite.md", 0): "installs the extra robosuite: scripts/test.sh installs it in "
    "target/robosuite-venv",
    ("docs/robosuite.md", 1): "needs robosuite, which runs on MuJoCo 3.3 (an environment of its "
    "own): tests/test_robosuite.py runs this block there (test_the_two_lines_of_the_page_run)",
    ("docs/robosuite.md", 2): "the head-to-head bench, an hour of robosuite episodes on two "
    "cores: tests/test_robosuite.py runs one of its rows (the square with a payload) and checks "
    "the page's tables against its --markdown of the committed results",
    ("docs/robosuite.md", 3): "the lift's phases on six arms (a few minutes of robosuite "
    "episodes): tests/test_robosuite.py checks the page's table against its --markdown of the "
    "committed results",
    ("docs/robosuite.md", 4): "the tracking bench (12 s runs): tests/test_robosuite.py checks "
    "the page's table against its --markdown of the committed results",
    ("docs/rust.md", 0): "an error message the page shows, not code",
    ("docs/rust.md", 1): "Rust: tests/snippets/dynamic_urdf.rs, a doctest of "
    "src/dynamic/mod.rs; test_every_block_is_accounted_for keeps the page's copy identical",
    ("docs/sweeps.md", 2): "needs Ray, which no extra of adaptimp installs",
    ("docs/your_arm.md", 4): "the delay tables on robot files of packages CI does not "
    "install (robosuite, gymnasium, dm_control, metaworld, franky-sim, pybullet): "
    "tests/test_delay.py makes the same simulate calls on the Panda",
    ("docs/your_arm.md", 5): "on a file of the reader's (FILE): tests/test_coupling.py makes "
    "the same calls on the Panda",
    ("docs/your_arm.md", 6): "the comparison tables (the joint task's diagonal gains, the "
    "Cartesian task's shaped ones) on the same files as block 4, which CI does not install: "
    "tests/test_coupling.py runs the Panda's joint rows both ways",
}

# Shell blocks run here as written (each line, from the checkout's root).
RUN_SHELL = {("README.md", 6), ("docs/paper.md", 0)}

# Rust blocks kept identical to a compiled snippet (a doctest of src/lib.rs).
RUST_SNIPPETS = {
    ("README.md", 7): "tests/snippets/readme_quickstart.rs",
    ("docs/robot.md", 1): "tests/snippets/robot_hardened.rs",
    ("docs/rust.md", 1): "tests/snippets/dynamic_urdf.rs",
}


# Numbers a page states of what its own blocks compute: after block i of the
# page, (an expression in the page's namespace, the text the page must contain
# with the value formatted into it). The numbers cannot go stale: a change
# that moves one fails here, with the value to write.
CHECKS: dict[tuple[str, int], list[tuple[str, str]]] = {
    ("README.md", 2): [
        ('res.metrics["rms_z1_after2"]', "# {:.2g} rad (SPEC §12)"),
        ('ctrl.weights["G"].shape', "# {}"),
    ],
    ("README.md", 3): [
        ('runs["sf"].metrics["rms_z1_after2"] / runs["pd"].metrics["rms_z1_after2"]',
         "on this arm SF tracks at {:.2g}× PD's error"),
    ],
    ("README.md", 4): [("len(df)", "one row per run: {} runs")],
    ("README.md", 5): [
        ('cart["sf"].metrics["rms_pos_after2"]', "# {:.3g} m, RMS ‖p_c − p‖ over t ≥ 2 s"),
        ('cart["pd"].metrics["rms_pos_after2"]', "(PD: {:.3g} m)"),
    ],
    ("docs/cartesian.md", 3): [
        ("1e3 * res.pos_err[-1]", "the tip ends {:.2g} mm from the target"),
    ],
    ("docs/contact.md", 0): [
        ("act.contact_metrics(res, ctrl, sc)",
         "track_mm {0[track_mm]:.3f}, force_rms_err_N {0[force_rms_err_N]:.3f}, "
         "force_chatter_N {0[force_chatter_N]:.3f}"),
    ],
    ("docs/index.md", 1): [('res.metrics["rms_z1_after2"]', "# {:.2g} rad (SPEC §12)")],
}  # fmt: skip


def _blocks(page: str) -> list[tuple[str, str]]:
    return BLOCK.findall((ROOT / page).read_text(encoding="utf-8"))


def test_every_check_is_of_a_python_block() -> None:
    for page, i in CHECKS:
        assert _blocks(page)[i][0] == "python", (page, i)


def test_every_block_is_accounted_for() -> None:
    missing = []
    for page in PAGES:
        for i, (lang, code) in enumerate(_blocks(page)):
            if lang == "python" and (page, i) not in ELSEWHERE:
                continue
            if (page, i) not in ELSEWHERE:
                missing.append(f"{page} block {i} ({lang or 'no language'})")
            snippet = RUST_SNIPPETS.get((page, i))
            if snippet is not None:
                assert code == (ROOT / snippet).read_text(encoding="utf-8"), (page, i)
    assert not missing, f"blocks neither run nor accounted for: {missing}"
    for key in ELSEWHERE:
        page, i = key
        assert i < len(_blocks(page)), f"{key}: no such block (the page changed)"


PRIVATE = re.compile(r"adaptimp\._\w+|from adaptimp import (?:[\w, ]*, )?_\w+")


def test_no_block_of_the_docs_uses_a_private_name() -> None:
    """What a reader copies uses the public API only (issue 45, finding 9:
    docs/cartesian.md called adaptimp._models.panda_urdf_path())."""
    found = [
        f"{page} block {i}: {m.group(0)}"
        for page in PAGES
        for i, (_, code) in enumerate(_blocks(page))
        for m in PRIVATE.finditer(code)
    ]
    assert not found, found


def test_the_cmake_lines_link_a_project(tmp_path: pathlib.Path) -> None:
    """The README's two CMake lines in a project of one C file: it configures,
    builds (the library with cargo, into this checkout's target/) and runs."""
    import shutil

    assert shutil.which("cmake"), "cmake is needed (scripts/test.sh installs it)"
    lang, lines = _blocks("README.md")[8]
    assert lang == "cmake"
    (tmp_path / "main.c").write_text(
        '#include "adaptimp.h"\n#include <stdio.h>\n'
        'int main(void) { printf("%s\\n", adaptimp_version()); return 0; }\n'
    )
    (tmp_path / "CMakeLists.txt").write_text(
        "cmake_minimum_required(VERSION 3.16)\nproject(mine LANGUAGES C)\n"
        "add_executable(my_controller main.c)\n" + lines.replace("path/to/adaptimp", str(ROOT))
    )
    build = tmp_path / "build"
    for cmd in (
        ["cmake", "-S", str(tmp_path), "-B", str(build), "-DCMAKE_BUILD_TYPE=Release"],
        ["cmake", "--build", str(build)],
        [str(build / "my_controller")],
    ):
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=1800, check=False)
        assert proc.returncode == 0, f"{cmd}: {proc.stdout}\n{proc.stderr}"
    assert proc.stdout.strip() == "0.1.0"


def _workdir(tmp_path: pathlib.Path) -> pathlib.Path:
    """A directory with the checkout's tests/ and examples/ (read-only by
    convention), where the blocks write."""
    for name in ("tests", "examples"):
        (tmp_path / name).symlink_to(ROOT / name)
    return tmp_path


PYTHON_PAGES = [page for page in PAGES if any(lang == "python" for lang, _ in _blocks(page))]


@pytest.mark.parametrize("page", PYTHON_PAGES)
def test_the_python_blocks_of_a_page_run_in_order(
    page: str, tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch, close_figures: None
) -> None:
    import warnings

    monkeypatch.chdir(_workdir(tmp_path))
    namespace: dict[str, Any] = {"__name__": "__docs__"}
    text = (ROOT / page).read_text(encoding="utf-8")
    # A reader sees the warnings a block gives (the hobby arm's estimated
    # effort limit): kept; none may say that the page uses what is deprecated.
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        for i, (lang, code) in enumerate(_blocks(page)):
            if lang != "python" or (page, i) in ELSEWHERE:
                continue
            exec(compile(code, f"{page} block {i}", "exec"), namespace)
            for expression, template in CHECKS.get((page, i), []):
                stated = template.format(eval(expression, namespace))
                assert stated in text, f"{page} must say {stated!r} ({expression})"
    old = [
        str(w.message) for w in seen if issubclass(w.category, (DeprecationWarning, FutureWarning))
    ]
    assert not old, old


@pytest.mark.parametrize("key", sorted(RUN_SHELL))
def test_the_shell_blocks_run(key: tuple[str, int], tmp_path: pathlib.Path) -> None:
    page, i = key
    env = {**os.environ, "PATH": f"{pathlib.Path(sys.executable).parent}:{os.environ['PATH']}"}
    for line in _blocks(page)[i][1].splitlines():
        command = line.split("#")[0].strip()
        if not command:
            continue
        cwd = ROOT if command.startswith("cargo") else tmp_path
        proc = subprocess.run(
            shlex.split(command), cwd=cwd, env=env, capture_output=True, text=True,
            timeout=1800, check=False,
        )  # fmt: skip
        assert proc.returncode == 0, f"{page} block {i}: {command}\n{proc.stdout}\n{proc.stderr}"


@pytest.mark.filterwarnings("ignore:the URDF gives no effort limit:UserWarning")
def test_the_readme_numbers_hold(
    tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch, close_figures: None
) -> None:
    """What the README's quick start says of its results: the save's size, the
    arm's errors (SF at a fraction of PD's), the shell line's metrics equal to
    the Python line's."""
    import adaptimp
    from adaptimp import cli

    monkeypatch.chdir(_workdir(tmp_path))
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    namespace: dict[str, Any] = {}
    blocks = [code for lang, code in _blocks("README.md") if lang == "python"]
    exec(compile(blocks[0], "README.md", "exec"), namespace)
    kb = int(re.search(r"bit for bit in (\d+) KB", text).group(1))  # type: ignore[union-attr]
    size = (tmp_path / "sf.npz").stat().st_size
    assert (kb - 1) * 1000 < size <= kb * 1000, size
    exec(compile(blocks[1], "README.md", "exec"), namespace)
    rms = {case: res.metrics["rms_z1_after2"] for case, res in namespace["runs"].items()}
    assert rms["sf"] < 0.1 * rms["pd"], rms
    assert rms["of"] < 0.1 * rms["pd"], rms
    # "The same from the shell": the metrics of the Python line, to the bit.
    shell = re.search(r"The same from the shell: `adaptimp (simulate [^`]*)`", text)
    assert shell is not None
    argv = shlex.split(shell.group(1).replace("--plot of.png", "--json"))
    python = adaptimp.simulate("of", T=5.0, Kp=[10.5, 9.0], robust="tanh", wall=None)
    out = tmp_path / "metrics.json"
    with out.open("w") as f:
        monkeypatch.setattr(sys, "stdout", f)
        assert cli.main(argv) == 0
    monkeypatch.undo()
    import json

    assert json.loads(out.read_text()) == json.loads(
        json.dumps(adaptimp._result.metrics_json(python.metrics))
    )
