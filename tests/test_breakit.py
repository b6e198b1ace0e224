"""The break-it probe (scripts/breakit.py), its quick form: about a thousand
deterministic cases over state restore (bit flips, edits), the fault
semantics, the n-joint API, sweeps and their cache, chains, the Cartesian
front, formulations, the dynamics and computed torque, saved results,
MuJoCo runs, robot descriptions, callbacks reading their controller and
wrong inputs named, each category in its own process. Not one crash, hang,
silent wrong result or false refusal."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

SCRIPT = Path(__file__).resolve().parent.parent / "scripts" / "breakit.py"


def test_the_quick_break_it_probe_finds_nothing() -> None:
    out = subprocess.run(
        [sys.executable, str(SCRIPT), "--quick", "--json"],
        capture_output=True,
        text=True,
        timeout=1800,
        check=False,
    )
    tallies = json.loads(out.stdout.strip().splitlines()[-1])
    assert [t["name"] for t in tallies] == [
        "state restore",
        "fault semantics",
        "n-joint API",
        "sweeps and cache",
        "chains",
        "Cartesian front",
        "formulations",
        "dynamics",
        "saves",
        "MuJoCo runs",
        "robot descriptions",
        "callbacks",
        "named inputs",
    ]
    for t in tallies:
        assert t["cases"] >= 10, t
        assert t["accepted"] + t["clear"] == t["cases"], t
        bad = {k: t[k] for k in ("crash", "hang", "wrong", "false_refusal")}
        assert bad == dict.fromkeys(bad, 0), t["notes"]
    assert sum(t["cases"] for t in tallies) >= 1000
    assert out.returncode == 0
