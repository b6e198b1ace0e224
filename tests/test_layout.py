"""The tree's imports flow one way (issue: one core, thin fronts): no circle in
the Python package, the core or the C ABI, read by scripts/import_graph.py."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _graph_module():  # type: ignore[no-untyped-def]
    spec = importlib.util.spec_from_file_location(
        "import_graph", ROOT / "scripts" / "import_graph.py"
    )
    assert spec is not None
    assert spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["import_graph"] = mod
    spec.loader.exec_module(mod)
    return mod


def test_no_import_circle_anywhere() -> None:
    g = _graph_module()
    edges = g.graph()
    assert g.circles(edges) == []


def test_the_graph_sees_the_imports_it_must() -> None:
    # The reader finds real edges of each kind, so an empty list of circles
    # is not an empty graph: a relative Python import inside a function, a
    # Rust `use crate::…`, a child's `super::sibling::…`, the C ABI's crate.
    edges = _graph_module().graph()
    assert "adaptimp._description" in edges["adaptimp._mjcf"]
    assert "src/control/state.rs" in edges["src/control/controller.rs"]
    assert "bindings/python/src/dynamic.rs" in edges["bindings/python/src/cartesian_loop.rs"]
    assert (
        "ffi/src/handles.rs" in edges["ffi/src/joint.rs"]
        or "ffi/src/lib.rs" in edges["ffi/src/joint.rs"]
    )


def test_a_circle_is_found_when_there_is_one() -> None:
    g = _graph_module()
    assert g.circles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def _package(root: Path, files: dict[str, str]) -> Path:
    pkg = root / "pkg"
    pkg.mkdir()
    for name, text in files.items():
        (pkg / name).write_text(text, encoding="utf-8")
    return pkg


def test_a_circle_through_the_parent_package_is_found(tmp_path: Path) -> None:
    # A child that takes a name from the package that imports it, inside a
    # function: the package's __init__ and the child form a circle.
    pkg = _package(
        tmp_path,
        {
            "__init__.py": "from ._a import A\n__version__ = '1'\n",
            "_a.py": "class A:\n    def v(self):\n        from . import __version__\n",
            "_b.py": "from . import _a\n",  # a child module: an edge to it, not to the package
        },
    )
    g = _graph_module()
    edges = g.python_edges(pkg)
    assert edges["pkg._a"] == {"pkg"}
    assert edges["pkg._b"] == {"pkg._a"}
    assert g.circles(edges) == [["pkg", "pkg._a"]]


def test_a_circle_through_import_module_is_found(tmp_path: Path) -> None:
    pkg = _package(
        tmp_path,
        {
            "__init__.py": "",
            "_r.py": "import importlib\n\ndef load():\n"
            "    return importlib.import_module(f'{__package__}.m')\n",
            "m.py": "from ._r import load\n",
            "_s.py": "from importlib import import_module\nimport_module('.m', 'pkg')\n",
        },
    )
    g = _graph_module()
    edges = g.python_edges(pkg)
    assert edges["pkg._r"] == {"pkg.m"}
    assert edges["pkg._s"] == {"pkg.m"}
    assert g.circles(edges) == [["pkg._r", "pkg.m"]]


def test_a_dynamic_import_not_read_is_an_error(tmp_path: Path) -> None:
    pkg = _package(
        tmp_path,
        {"__init__.py": "", "_d.py": "import importlib\nimportlib.import_module(NAME)\n"},
    )
    g = _graph_module()
    with pytest.raises(g.Unread, match=r"_d\.py:2: a dynamic import of a name not read"):
        g.python_edges(pkg)


def test_the_package_takes_no_name_from_its_parent() -> None:
    # The package's modules import each other and the extension, never the
    # package itself (whose __init__ imports them): no edge into "adaptimp".
    edges = _graph_module().graph()
    into = sorted(m for m, to in edges.items() if "adaptimp" in to)
    assert into == []
    assert "adaptimp.mujoco" not in edges["adaptimp._result"]


# The names each module split by responsibility had (its top-level definitions
# and the package names it imported), before the split: a user's
# ``from adaptimp.mujoco import X`` keeps working.
BEFORE_THE_SPLIT = {
    "adaptimp.mujoco": "ARRAYS CartesianTask ConfigError ControllerLike DISTURBANCES "
    "EFFORT_ACCEL Fault FloatArray HOME_CLEARANCE HOME_LOAD HOME_SAMPLES MAX_JOINTS "
    "MAX_SUBSTEPS MUJOCO_FIGURES MUJOCO_PLOT_KINDS ModelSource MujocoResult PLOT_KINDS "
    "Plant PlantWarning RUN_CONTACT_EVERY RUN_PEAK RUN_SATURATED RUN_SETTLE RUN_TRACKING "
    "Reference SWING_SAMPLES SimResult TASK_AMPLITUDE Task add_table add_tool call_shape "
    "cartesian_task chain_of collision default_task estimate_effort from_urdf "
    "holding_controls home_posture loop_delay measure mocap_welds moving_mass needs_extra "
    "no_file panda paper_circle reals rule_keywords scene_contact_findings self_collision "
    "simulate sinusoid task_of task_space torque_findings two_link with_payload",
    "adaptimp.cartesian": "BY_NAME CartesianController CartesianImpedance CartesianStep "
    "Chain ConfigError FloatArray Measurement MeasurementError PoseTarget call_shape "
    "check_scenario describe inner_params period_alias pose_target reals resolve tabulate",
    "adaptimp.franka": "AdaptimpError BLEND BLEND_SPEED COLLISION CartesianTask Chain "
    "ConfigError DELAY FloatArray LIBFRANKA_ERRORS Measurement PERIOD READY RobotError "
    "SERVER SETTLE SETTLED SETTLE_WAIT Setup Simulator TAU_MAX TORQUE_RATE chain_of "
    "move_to needs_extra plant run setup",
    "adaptimp.scenarios.contact": "ADMITTANCE_SHARE_OF_PERIOD AXIS_SHARE CLEARANCE "
    "CONTACT_IMPEDANCE CONTACT_K1 Chain ConfigError DEFAULT_MD FloatArray HOME_CANDIDATES "
    "LEARN_KEYS MAX_PATH_STEPS MIN_REACH_SHARE NORMAL_SAMPLES OUTWARD PandaTable "
    "REACH_SHARE REFUSAL_ROWS RINGING ROBUST_SLOPE SAG_MARGIN SHARE SLIP_SHARE TABLE_MASS "
    "TABLE_OFFSET_MARGIN TABLE_ROWS TABLE_TIMECONST THROUGH_TABLE T_APPROACH T_HOLD "
    "T_PRESS arm_model arm_table contact_impedance contact_metrics normal_inertia "
    "placement placements refusal_of row_controller rule_keywords run_row sag "
    "sliding_timeconst table_metrics velocity_loop_radius",
}


@pytest.mark.parametrize("module", sorted(BEFORE_THE_SPLIT))
def test_a_split_module_keeps_every_name_it_had(module: str) -> None:
    pytest.importorskip("mujoco")
    if module == "adaptimp.franka":
        pytest.importorskip("pylibfranka")
    mod = importlib.import_module(module)
    assert [n for n in BEFORE_THE_SPLIT[module].split() if not hasattr(mod, n)] == []
