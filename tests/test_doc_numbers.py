"""The numbers the README and the docs quote from a table that a command prints:
each test runs the command's own functions at the documented size and compares
the page's cells to the digit, and the ranges the text quotes are those of the
table, so that none can go stale. (The numbers a page's own code blocks
compute are checked where those blocks run, ``tests/test_readme.py``.)

- docs/contact.md's table of the formulations (the Panda at Franka's ready
  posture on the table, friction 0.1, T = 20 s; ``python
  examples/13_panda_table.py``, 13 s on 2 cores), and the README's row of it;
- docs/cartesian.md's table of the default Cartesian task (``python
  scripts/arm_targets.py --robots DIR --only cartesian --check`` for every
  arm; here the eight of example-robot-data, which the tests install, about
  12 s), and the ranges the README, the page and SPEC §16 quote from it.
"""

from __future__ import annotations

import re
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "scripts"))

import arm_targets  # noqa: E402  (scripts/, not a package)


def _flat(text: str) -> str:
    """``text`` with every run of white space one space (a line-wrapped sentence)."""
    return " ".join(text.split())


def _rows_after(page: str, heading: str) -> dict[str, list[str]]:
    """The first Markdown table after ``heading`` in ``page``: its cells by the
    first cell (bold marks removed)."""
    text = (ROOT / page).read_text(encoding="utf-8")
    lines = text[text.index(heading) :].splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("|"))
    out = {}
    for line in lines[start + 2 :]:
        if not line.startswith("|"):
            break
        cells = [c.strip().strip("*") for c in line.strip("|").split("|")]
        out[cells[0]] = cells[1:]
    return out


@pytest.fixture(scope="module")
def table() -> dict[str, dict[str, float]]:
    """examples/13's default table: every row of the Panda's, T = 20 s."""
    from adaptimp.scenarios import contact as act

    sc = act.arm_table()
    rule = act.rule_keywords(sc)

    def row(name: str) -> dict[str, float]:
        return act.run_row(name, sc, rule, 20.0)[2]

    import warnings

    from adaptimp import PlantWarning

    # The rows the table shows failing say so (PlantWarning); the filter is
    # set here, around both threads.
    with warnings.catch_warnings(), ThreadPoolExecutor(max_workers=2) as pool:
        warnings.simplefilter("ignore", PlantWarning)
        return dict(zip(act.TABLE_ROWS, pool.map(row, act.TABLE_ROWS)))


def test_contact_md_s_table_is_what_the_example_prints(table: dict[str, Any]) -> None:
    from adaptimp.scenarios import contact as act

    documented = _rows_after(
        "docs/contact.md", "## Measured: the formulations compared (Panda, 1 kHz, T = 20 s"
    )
    keys = (
        ("track_mm", ".3f"), ("track_along_mm", ".3f"), ("force_rms_err_N", ".3f"),
        ("force_chatter_N", ".3f"), ("contact_lost_s", ".3f"), ("peak_force_N", ".1f"),
        ("peak_tau_ratio", ".3f"), ("sat_duty", ".3f"),
    )  # fmt: skip
    assert len(documented) == len(act.TABLE_ROWS)
    for name, m in table.items():
        label = act.TABLE_ROWS[name][0]
        measured = [format(m[k], spec) for k, spec in keys]
        assert documented[label] == measured, label


def test_the_readme_quotes_the_table_s_row(table: dict[str, Any]) -> None:
    m = table["sf"]
    stated = (
        f"the Panda at Franka's presses with {m['track_mm']:.3f} mm tracking, "
        f"{m['force_rms_err_N']:.3f} N force error and no chatter"
    )
    assert m["force_chatter_N"] < 5e-4
    assert stated in _flat((ROOT / "README.md").read_text(encoding="utf-8"))


def test_cartesian_md_s_rows_of_example_robot_data() -> None:
    """Each row of an arm of example-robot-data is what scripts/arm_targets.py
    prints for it now, cell for cell."""
    import warnings

    documented = arm_targets.documented_rows()
    erd = [a for a in arm_targets.ARMS if a.package == "erd"]
    assert len(erd) == 8
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for arm in erd:
            path = arm_targets.locate(arm, None)
            assert path is not None, arm.label
            row = arm_targets.cartesian_row(arm.label, arm_targets.cartesian(str(path), 12.0))
            assert documented[arm.label] == row, arm.label


def test_the_ranges_quoted_are_those_of_the_cartesian_table() -> None:
    """The README, docs/cartesian.md and SPEC §16 quote the table's ranges: SF/PD
    in position and orientation, σmin, the last 2 s over [2, 4) s, the peak
    torque, and the number of arms."""
    table = _rows_after("docs/cartesian.md", "### Measured: the default task on")
    assert len(table) == len(arm_targets.ARMS)
    # A file the reader refuses (SPEC (21.5)) has its message for a row.
    rows = {k: r for k, r in table.items() if not r[0].startswith("refused")}
    assert len(table) - len(rows) == 1
    col = {name: i for i, name in enumerate(
        ["n", "sigma", "pd", "sf", "pos", "pdrot", "sfrot", "rot", "learn", "peak", "targets"]
    )}  # fmt: skip

    def values(name: str) -> list[float]:
        return [float(r[col[name]]) for r in rows.values() if r[col[name]] != "—"]

    ratios = values("pos") + values("rot")
    low, high = min(ratios), max(ratios)
    n = len(rows)
    assert all(r[col["targets"]] == "met" for r in rows.values())
    readme = _flat((ROOT / "README.md").read_text(encoding="utf-8"))
    assert f"at {low:.3f}–{high:.2f}× PD's on all {n} arms measured" in readme
    page = _flat((ROOT / "docs" / "cartesian.md").read_text(encoding="utf-8"))
    learn = values("learn")
    assert (
        f"Every target is met on the {n} arms with a dynamics: σ_min ≥ "
        f"{min(values('sigma')):.3f} at the start "
        "(the rule's bound: 0.05), "
        f"SF's position and orientation RMS {low:.3f}–{high:.2f}× PD's, its last 2 s "
        f"{min(learn):.2f}–{max(learn):.2f} of its [2, 4) s, the commanded torque at most "
        f"{max(values('peak')):.2f} τmax"
    ) in page
    spec = _flat((ROOT / "docs" / "SPEC.md").read_text(encoding="utf-8"))
    assert (
        f"SF's position and orientation RMS are {low:.3f}–{high:.2f}× PD's and its error "
        f"over the last 2 s {min(learn):.2f}–{max(learn):.2f} of that over [2, 4) s; σ_min ≥ "
        f"{min(values('sigma')):.3f} at every start; the peak commanded torque ≤ "
        f"{max(values('peak')):.2f} τmax; every target on all {n}"
    ) in spec
    assert re.search(rf"### Measured: the default task on {len(table)} files", page)
