"""Saves that never destroy data: a save is written beside its path and renamed
over it whole, so a failed save leaves the file that was there and saves from
several threads leave one of them complete; a folder is refused as a path; a
file that declares an older format is checked as that format's content allows,
and a later format's record in it gives it away; a MuJoCo result does not load
another kind's file."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest

import adaptimp
from adaptimp import mujoco as amj


@pytest.fixture(scope="module")
def runs() -> tuple[adaptimp.SimResult, adaptimp.SimResult]:
    return adaptimp.simulate("pd", T=0.3), adaptimp.simulate("sf", T=0.3)


def _same(a: adaptimp.SimResult, b: adaptimp.SimResult) -> bool:
    return a.case == b.case and all(
        np.array_equal(getattr(a, k), getattr(b, k)) for k in ("q", "tau", "z1")
    )


def test_concurrent_saves_to_one_path_leave_one_complete_save(
    tmp_path: Path, runs: tuple[adaptimp.SimResult, adaptimp.SimResult]
) -> None:
    """Four threads save two results to one path ten times each while another
    loads it: every load succeeds (it was unreadable 6–8 times a run, every
    save returning without error), and the file left is one of the two."""
    path = tmp_path / "run.npz"
    runs[0].save(path, recompute=False)
    done = threading.Event()
    failures: list[str] = []

    def save(r: adaptimp.SimResult) -> None:
        for _ in range(10):
            r.save(path, recompute=False)

    def load_once() -> None:
        try:
            adaptimp.SimResult.load(path)
        except Exception as e:  # the failure is the result
            failures.append(repr(e))

    def load() -> None:
        while not done.is_set():
            load_once()

    reader = threading.Thread(target=load)
    reader.start()
    savers = [threading.Thread(target=save, args=(r,)) for r in (*runs, *runs)]
    for t in savers:
        t.start()
    for t in savers:
        t.join()
    done.set()
    reader.join()
    assert failures == []
    left = adaptimp.SimResult.load(path)
    assert _same(left, runs[0]) or _same(left, runs[1])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]


def test_a_save_that_fails_partway_leaves_the_file_that_was_there(
    tmp_path: Path, runs: tuple[adaptimp.SimResult, adaptimp.SimResult]
) -> None:
    """A save over a good one that fails partway (here a file-size limit, as a
    full disk) raises, and the good save is still there, whole (it was
    destroyed: the file was truncated in place); nothing else is left."""
    path = tmp_path / "run.npz"
    runs[0].save(path, recompute=False)
    before = path.read_bytes()
    code = f"""
import resource, signal, sys
import adaptimp
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
res = adaptimp.simulate("sf", T=0.3)
resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
try:
    res.save({str(path)!r}, recompute=False)
except OSError as e:
    print("refused", e.errno)
"""
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.stdout.strip() == "refused 27", out.stderr  # EFBIG
    assert path.read_bytes() == before
    assert _same(adaptimp.SimResult.load(path), runs[0])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.npz"]


def test_a_folder_is_refused_as_a_path(
    tmp_path: Path, runs: tuple[adaptimp.SimResult, adaptimp.SimResult]
) -> None:
    """``save("dir/")`` wrote ``dir.npz`` beside the folder."""
    (tmp_path / "dir").mkdir()
    for given in (f"{tmp_path / 'dir'}/", str(tmp_path / "dir"), f"{tmp_path / 'new'}/"):
        with pytest.raises(IsADirectoryError, match="is a folder: give the file to write"):
            runs[0].save(given)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dir"]
    assert list((tmp_path / "dir").iterdir()) == []


def test_every_takes_any_integer(
    tmp_path: Path, runs: tuple[adaptimp.SimResult, adaptimp.SimResult]
) -> None:
    """``every=np.int64(2)`` was refused as not an integer."""
    path = runs[0].save(tmp_path / "half.npz", every=np.int64(2))
    assert adaptimp.SimResult.load(path).record_every == 2
    with pytest.raises(ValueError, match="every must be an integer ≥ 1, got True"):
        runs[0].save(tmp_path / "x.npz", every=True)


def _forge(path: Path, out: Path, version: int, swap: bool = True) -> Path:
    """``path`` declared ``version``, its format-4 record dropped (the
    digests of its arrays, inputs and metrics, and the class that saved
    it), q and tau swapped."""
    z = dict(np.load(path))
    fmt = json.loads(str(z["format"]))
    fmt["version"] = version
    for key in ("arrays", "inputs", "metrics", "result"):
        fmt.pop(key)
    if version < 3:
        fmt.pop("simulated")
        fmt.pop("n")
    if swap:
        z["q"], z["tau"] = z["tau"], z["q"]
        d = fmt["differences"]
        d["q"], d["tau"] = d["tau"], d["q"]
    z["format"] = np.array(json.dumps(fmt))
    np.savez(out, **z)
    return out


@pytest.mark.parametrize("version", [2, 3])
def test_a_declared_older_format_does_not_skip_the_checks(
    tmp_path: Path, runs: tuple[adaptimp.SimResult, adaptimp.SimResult], version: int
) -> None:
    """A format-4 file declared format 3 (or 2), its record dropped and q and
    tau swapped, loaded silently with q = the saved tau. Its content is a
    format-3 file's, which saved the metrics of the rows it holds: they no
    longer agree. Keeping any of the record gives the edit away too."""
    saved = runs[1].save(tmp_path / "run.npz", recompute=False)
    forged = _forge(saved, tmp_path / "forged.npz", version)
    with pytest.raises(adaptimp.SaveError, match="its metrics are not those of its rows"):
        adaptimp.SimResult.load(forged)
    # Unswapped, the same content is a genuine format-2/3 file's: it loads.
    honest = _forge(saved, tmp_path / "honest.npz", version, swap=False)
    assert _same(adaptimp.SimResult.load(honest), runs[1])
    # The record of format 4 kept beside a declared older version.
    z = dict(np.load(saved))
    fmt = json.loads(str(z["format"]))
    fmt["version"] = version
    z["format"] = np.array(json.dumps(fmt))
    np.savez(tmp_path / "kept.npz", **z)
    with pytest.raises(adaptimp.SaveError, match=f"declares format {version} but holds '"):
        adaptimp.SimResult.load(tmp_path / "kept.npz")


def test_a_declared_older_format_with_another_row_count_is_refused(
    tmp_path: Path, runs: tuple[adaptimp.SimResult, adaptimp.SimResult]
) -> None:
    """A format-3 file whose T does not give the rows it holds (edited)."""
    saved = runs[1].save(tmp_path / "run.npz", recompute=False)
    forged = _forge(saved, tmp_path / "forged.npz", 3, swap=False)
    z = dict(np.load(forged))
    params = json.loads(str(z["params"]))
    params["T"] = 0.2
    z["params"] = np.array(json.dumps(params))
    np.savez(forged, **z)
    with pytest.raises(adaptimp.SaveError, match="give 4000 rows, and it records 6000"):
        adaptimp.SimResult.load(forged)


def test_a_mujoco_result_does_not_load_another_kinds_file(
    tmp_path: Path, runs: tuple[adaptimp.SimResult, adaptimp.SimResult]
) -> None:
    """``MujocoResult.load`` of a plain SimResult's file loaded, then its
    ``repr`` raised KeyError 'controller'."""
    plain = runs[0].save(tmp_path / "plain.npz", compress=False)
    with pytest.raises(adaptimp.SaveError, match=r"holds a SimResult .* not a MujocoResult"):
        amj.MujocoResult.load(plain)
    # A file that does not name its class (format 1, plain arrays): by its parameters.
    z = dict(np.load(plain))
    del z["format"]
    np.savez(tmp_path / "v1.npz", **z)
    with pytest.raises(adaptimp.SaveError, match="its parameters have no 'controller'"):
        amj.MujocoResult.load(tmp_path / "v1.npz")
    assert adaptimp.SimResult.load(tmp_path / "v1.npz").case == "pd"
    assert os.path.exists(plain)
