"""Saves that check every byte (issue 33 E): every array of a saved result is
checked by its SHA-256 (stored plain, as differences, derived or recomputed),
a MuJoCo run's too; an edited file is refused before its simulation is run
again; a truncated, non-JSON or foreign file is a SaveError naming the file and
what is wrong; SimResult.load of a MuJoCo run's file gives a MujocoResult."""

from __future__ import annotations

import dataclasses
import json
import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import adaptimp
from adaptimp import SaveError, SimResult, _result


def _content(path: Path) -> dict[str, np.ndarray]:
    with np.load(path, allow_pickle=False) as f:
        return dict(f)


def _rewrite(path: Path, out: Path, edit: Callable[[dict[str, np.ndarray]], None]) -> Path:
    content = _content(path)
    edit(content)
    np.savez(out, **content)
    return out


@pytest.fixture(scope="module")
def faulty() -> SimResult:
    """A fault run: its arrays are not what its parameters give, so they are
    stored (as differences of their bit patterns)."""
    return adaptimp.simulate("sf", T=0.05, fault=adaptimp.Fault("nan_burst", 0.01, 0.01))


def _arrays_of(path: Path) -> dict[str, np.ndarray]:
    """The decoded arrays of a saved file (loaded, so checked)."""
    res = SimResult.load(path)
    return {name: getattr(res, name) for name in _result.ARRAYS}


def _swap(content: dict[str, np.ndarray], a: str, b: str) -> None:
    content[a], content[b] = content[b], content[a]
    m = json.loads(str(content["format"]))
    d = m["differences"]
    d[a], d[b] = d[b], d[a]
    content["format"] = np.array(json.dumps(m))


@pytest.mark.parametrize("other", ["tau", "xd", "tau_e", "zeta"])
def test_swapping_two_stored_arrays_of_a_fault_run_is_refused(
    faulty: SimResult, other: str, tmp_path: Path
) -> None:
    path = faulty.save(tmp_path / "run")
    assert {"q", other} <= set(json.loads(str(_content(path)["format"]))["differences"])
    bad = _rewrite(path, tmp_path / "bad.npz", lambda c: _swap(c, "q", other))
    with pytest.raises(SaveError) as e:
        SimResult.load(bad)
    message = str(e.value)
    prefix = (
        f"{bad}: the file was edited or damaged after it was saved: its arrays are not what "
        "the save recorded (their SHA-256 differs; changed: "
    )
    assert message.startswith(prefix), message
    # The two swapped, and what is derived from them (z1 = xd − q, sat(τ)).
    changed = set(re.findall(r"'(\w+)'", message[len(prefix) :]))
    assert {"q", other} <= changed <= {"q", other, "z1", "tau_sat"}, message


def test_one_flipped_bit_of_a_stored_array_is_refused(faulty: SimResult, tmp_path: Path) -> None:
    path = faulty.save(tmp_path / "run")

    def flip(c: dict[str, np.ndarray]) -> None:
        planes = c["q"].copy()
        planes[0, 0, 7] ^= 1  # the low byte of one row's first column
        c["q"] = planes

    bad = _rewrite(path, tmp_path / "bad.npz", flip)
    # q, and z1 = xd − q derived from it.
    with pytest.raises(SaveError, match=r"changed: 'q', 'z1'\)$"):
        SimResult.load(bad)


@pytest.mark.parametrize("compress", [True, False])
def test_every_array_is_checked_whatever_its_encoding(
    faulty: SimResult, compress: bool, tmp_path: Path
) -> None:
    path = faulty.save(tmp_path / "run", compress=compress)
    m = json.loads(str(_content(path)["format"]))
    assert m["version"] == 4
    assert set(m["arrays"]) == {*_result.ARRAYS, *_result.EXTRA_ARRAYS}
    if compress:
        assert m["derived"], "some arrays are derived (t, z1, …), checked all the same"
    # The whole result loads back bit for bit.
    back = SimResult.load(path)
    for name in _result.ARRAYS:
        assert np.array_equal(getattr(back, name), getattr(faulty, name), equal_nan=True)
    if not compress:
        bad = _rewrite(path, tmp_path / "plain.npz", lambda c: c.update(q=c["q"] * 1.5))
        with pytest.raises(SaveError, match=r"changed: 'q'\)$"):
            SimResult.load(bad)


def test_an_edited_file_is_refused_before_its_simulation_runs(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = adaptimp.simulate("pd", T=0.05).save(tmp_path / "run")
    assert json.loads(str(_content(path)["format"]))["simulated"]

    def no_rerun(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("the edited file's simulation was run")

    monkeypatch.setattr(_result, "_rerun", no_rerun)

    def edit(c: dict[str, np.ndarray], drop: str) -> None:
        params = json.loads(str(c["params"]))
        params["T"] = 1e5
        c["params"] = np.array(json.dumps(params))
        m = json.loads(str(c["format"]))
        del m[drop]
        c["format"] = np.array(json.dumps(m))

    for drop, message in (
        ("inputs", "its format 4 record has no 'inputs': the file was edited after it was saved"),
        ("arrays", "its format 4 record has no 'arrays': the file was edited after it was saved"),
    ):
        bad = _rewrite(path, tmp_path / f"no-{drop}.npz", lambda c, d=drop: edit(c, d))
        with pytest.raises(SaveError) as e:
            SimResult.load(bad)
        assert str(e.value) == f"{bad}: {message}"
    # T edited, the record intact: refused by the inputs' digest, not run.
    bad = _rewrite(path, tmp_path / "T.npz", lambda c: edit(c, "version") or None)
    content = _content(path)
    params = json.loads(str(content["params"]))
    params["T"] = 1e5
    content["params"] = np.array(json.dumps(params))
    np.savez(tmp_path / "T.npz", **content)
    with pytest.raises(SaveError, match=r"the parameter 'T' \(now 100000\.0\) is not what"):
        SimResult.load(tmp_path / "T.npz")
    del bad


def test_an_earlier_format_3_file_without_inputs_loads_and_an_edited_t_is_not_run(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = adaptimp.simulate("pd", T=0.05).save(tmp_path / "run")

    def as_v3(c: dict[str, np.ndarray]) -> None:
        m = json.loads(str(c["format"]))
        for key in ("inputs", "arrays", "metrics", "result"):
            m.pop(key)
        m["version"] = 3
        c["format"] = np.array(json.dumps(m))

    old = _rewrite(path, tmp_path / "v3.npz", as_v3)
    assert SimResult.load(old).rows == 1000  # an earlier file still loads

    def longer(c: dict[str, np.ndarray]) -> None:
        as_v3(c)
        params = json.loads(str(c["params"]))
        params["T"] = 1e5
        c["params"] = np.array(json.dumps(params))

    bad = _rewrite(path, tmp_path / "T.npz", longer)
    monkeypatch.setattr(_result, "_rerun", lambda *a, **k: pytest.fail("it ran"))
    with pytest.raises(SaveError) as e:
        SimResult.load(bad)
    assert str(e.value) == (
        f"{bad}: the file's parameters (T = 100000.0, Ts = 5e-05, one row in 1) do not give "
        "the 1000 rows it records: it was edited after it was saved (its simulation is not run "
        "again)"
    )


def _damaged(path: Path, tmp_path: Path) -> list[tuple[str, Path, str]]:
    """Damaged copies of a saved file: (what, path, the message's tail)."""
    data = path.read_bytes()
    out = []
    for frac in (0.0, 0.1, 0.5, 0.9, 0.99):
        p = tmp_path / f"cut{frac}.npz"
        p.write_bytes(data[: int(len(data) * frac)])
        out.append((f"truncated to {frac:.0%}", p, ""))
    middle = bytearray(data)
    for i in range(len(data) // 3, len(data) // 3 + 64):
        middle[i] ^= 0x5A  # inside a member: its CRC or its deflate stream fails
    p = tmp_path / "middle.npz"
    p.write_bytes(bytes(middle))
    out.append(("bytes changed in the middle", p, ""))
    p = tmp_path / "text.npz"
    p.write_text("not an archive")
    out.append(("text", p, ""))
    p = tmp_path / "single.npy"
    np.save(p, np.zeros(3))
    out.append((".npy", p, "a single NumPy array (.npy), not a result saved by SimResult.save"))
    content = _content(path)
    for entry, value in (
        ("params", "{not json"),
        ("metrics", "[1, 2]"),
        ("format", "{"),
        ("format", '{"version": true}'),
        ("format", '{"version": 4, "derived": "t"}'),
        ("case", 3.0),
    ):
        p = tmp_path / f"{entry}-{len(out)}.npz"
        np.savez(p, **{**content, entry: np.array(value)})
        out.append((f"{entry} = {value!r}", p, entry if entry != "format" else "format"))
    plain = "differences" not in json.loads(str(content["format"]))
    # (A plain file without its format record is one of format 1, which loads.)
    for entry in [e for e in ("params", "q", "t", "format") if e in content]:
        if plain and entry == "format":
            continue
        p = tmp_path / f"without-{entry}.npz"
        np.savez(p, **{k: v for k, v in content.items() if k != entry})
        out.append((f"without {entry}", p, ""))
    return out


@pytest.mark.parametrize("compress", [True, False])
def test_a_damaged_or_foreign_file_is_a_save_error_naming_it(
    faulty: SimResult, compress: bool, tmp_path: Path
) -> None:
    path = faulty.save(tmp_path / "run", compress=compress)
    for what, bad, tail in _damaged(path, tmp_path):
        with pytest.raises(SaveError) as e:
            SimResult.load(bad)
        message = str(e.value)
        assert message.startswith(f"{bad}: "), (what, message)
        assert tail in message, (what, message)
        assert not re.search(r"KeyError|BadZipFile|JSONDecodeError|EOFError", message) or (
            "not a readable .npz archive" in message or "cannot be read" in message
        ), (what, message)


def test_a_missing_file_is_still_an_os_error(tmp_path: Path) -> None:
    with pytest.raises(FileNotFoundError):
        SimResult.load(tmp_path / "nowhere.npz")


def test_a_saved_result_is_still_a_value_error_for_old_callers(
    faulty: SimResult, tmp_path: Path
) -> None:
    bad = tmp_path / "bad.npz"
    bad.write_bytes(b"PK\x03\x04 truncated")
    with pytest.raises(ValueError, match=r"bad\.npz: not a result saved by SimResult\.save"):
        SimResult.load(bad)


def test_an_edited_derived_rule_input_is_refused(faulty: SimResult, tmp_path: Path) -> None:
    """z1 is stored as xd − q; editing xd (stored) changes z1 too: both named."""
    odd = dataclasses.replace(faulty, xd=faulty.xd + 0.0)
    path = odd.save(tmp_path / "run")
    m = json.loads(str(_content(path)["format"]))
    assert "z1" in m["derived"]

    def edit(c: dict[str, np.ndarray]) -> None:
        c["xd"], c["tau"] = c["tau"], c["xd"]
        d = m["differences"]
        d["xd"], d["tau"] = d["tau"], d["xd"]
        c["format"] = np.array(json.dumps(m))

    bad = _rewrite(path, tmp_path / "bad.npz", edit)
    with pytest.raises(SaveError, match=r"changed: 'tau', 'tau_sat', 'xd', 'z1'\)$"):
        SimResult.load(bad)


@pytest.fixture(scope="module")
def mujoco_run() -> Any:
    from adaptimp import mujoco as amj

    return amj.simulate("pd", "two_link", T=0.05)


@pytest.mark.parametrize(
    ("what", "edit", "changed"),
    [
        ("q ↔ dq", lambda c: _swap(c, "q", "dq"), {"q", "dq"}),
        ("xc ↔ xd", lambda c: _swap(c, "xc", "xd"), {"xc", "xd"}),
        ("x_ee ↔ wrench_ee[:, :3]", None, {"x_ee"}),
    ],
)
def test_a_mujoco_runs_arrays_are_checked(
    mujoco_run: Any, what: str, edit: Any, changed: set[str], tmp_path: Path
) -> None:
    from adaptimp import mujoco as amj

    path = mujoco_run.save(tmp_path / "run")
    m = json.loads(str(_content(path)["format"]))
    assert m["result"] == "MujocoResult"
    assert {"q", "dq", "xc", "xd", "x_ee"} <= set(m["differences"])
    if edit is None:  # a stored array replaced by another of its shape

        def edit(c: dict[str, np.ndarray]) -> None:
            c["x_ee"] = c["wrench_ee"][:3].copy()

    bad = _rewrite(path, tmp_path / "bad.npz", edit)
    for load in (amj.MujocoResult.load, SimResult.load):
        with pytest.raises(SaveError) as e:
            load(bad)
        found = set(re.findall(r"'(\w+)'", str(e.value).split("changed: ")[1]))
        assert changed <= found <= changed | {"z1", "tau_sat", "dq_hat"}, (what, str(e.value))


@pytest.mark.parametrize("compress", [True, False])
def test_a_mujoco_run_scaled_by_half_again_is_refused(
    mujoco_run: Any, compress: bool, tmp_path: Path
) -> None:
    from adaptimp import mujoco as amj

    scaled = dataclasses.replace(mujoco_run)
    path = scaled.save(tmp_path / "run", compress=compress)
    if compress:
        # A whole result made again with q × 1.5 and written over the record:
        # its planes differ, so does its digest.
        other = dataclasses.replace(mujoco_run, q=mujoco_run.q * 1.5)
        again = _content(other.save(tmp_path / "other", compress=True))
        bad = _rewrite(path, tmp_path / "bad.npz", lambda c: c.update(q=again["q"]))
    else:
        bad = _rewrite(path, tmp_path / "bad.npz", lambda c: c.update(q=c["q"] * 1.5))
    with pytest.raises(SaveError, match=r"changed: 'q'"):
        amj.MujocoResult.load(bad)


def test_simresult_load_of_a_mujoco_file_gives_a_mujoco_result_whose_repr_works(
    mujoco_run: Any, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from adaptimp import mujoco as amj

    path = mujoco_run.save(tmp_path / "run")
    back = SimResult.load(path)
    assert type(back) is amj.MujocoResult
    assert repr(back) == repr(mujoco_run)
    np.testing.assert_array_equal(back.x_ee, mujoco_run.x_ee)
    # Where adaptimp.mujoco does not import (no extra): a SimResult of its
    # common arrays, whose repr does not need the wall a native run has.
    # (A module that is None in sys.modules raises ImportError on import.)
    monkeypatch.setitem(sys.modules, "adaptimp.mujoco", None)
    plain = SimResult.load(path)
    assert type(plain) is SimResult
    text = repr(plain)
    assert text.startswith("SimResult('pd': PD, scenario 'robot'; 50 steps, n = 2, Ts = 0.001 s")
    assert "free space" in text
