"""SimResult.save / load: lossless (bit for bit), smaller than np.savez_compressed,
decimation by rows, and files of the first format still load."""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

import adaptimp
from adaptimp import SimResult
from adaptimp._result import ARRAYS, EXTRA_ARRAYS

DATA = Path(__file__).resolve().parent / "data"
NAMES = (*ARRAYS, *EXTRA_ARRAYS)


def assert_same_bits(a: SimResult, b: SimResult, every: int = 1) -> None:
    for name in NAMES:
        x, y = getattr(a, name), getattr(b, name)
        assert x is not None, name
        assert y is not None, name
        x = np.ascontiguousarray(x[::every])
        assert (x.dtype, x.shape) == (y.dtype, y.shape), name
        assert np.array_equal(x.view(np.uint8), y.view(np.uint8)), name


@pytest.fixture(scope="module")
def runs() -> dict[str, SimResult]:
    return {
        "pd": adaptimp.simulate("pd", T=0.3),
        "sf": adaptimp.simulate("sf", T=0.3),
        "of": adaptimp.simulate("of", "robot", T=2.5, noise_q=1e-4, seed=3),
    }


@pytest.mark.parametrize("case", ["pd", "sf", "of"])
@pytest.mark.parametrize("compress", [True, False])
def test_round_trip_is_bit_identical(
    runs: dict[str, SimResult], case: str, compress: bool, tmp_path: Path
) -> None:
    res = runs[case]
    back = SimResult.load(res.save(tmp_path / "run", compress=compress))
    assert_same_bits(res, back)
    assert (back.case, back.scenario, back.record_every) == (res.case, res.scenario, 1)
    assert back.params == res.params
    assert json.dumps(back.metrics) == json.dumps(res.metrics)


def test_compressed_is_smaller_than_savez_compressed(
    runs: dict[str, SimResult], tmp_path: Path
) -> None:
    res = runs["sf"]
    path = res.save(tmp_path / "new")
    np.savez_compressed(tmp_path / "old.npz", **{n: getattr(res, n) for n in NAMES})
    assert path.stat().st_size < 0.6 * (tmp_path / "old.npz").stat().st_size
    plain = res.save(tmp_path / "plain", compress=False)
    with np.load(plain) as f:  # compress=False: plain float64 arrays for NumPy alone
        assert np.array_equal(f["q"], res.q)


def test_derived_arrays_are_stored_when_they_do_not_hold(
    runs: dict[str, SimResult], tmp_path: Path
) -> None:
    res = runs["sf"]
    z1 = res.z1.copy()
    z1[5, 1] = np.nextafter(z1[5, 1], 1.0)  # one ulp off xd − q
    t = res.t.copy()
    t[7] = -0.0
    odd = dataclasses.replace(res, z1=z1, t=t, tau_sat=-res.tau_sat, dq_hat=res.dq_hat * 2)
    back = SimResult.load(odd.save(tmp_path / "odd"))
    assert_same_bits(odd, back)


def test_every_keeps_every_kth_row(runs: dict[str, SimResult], tmp_path: Path) -> None:
    res = runs["of"]
    back = SimResult.load(res.save(tmp_path / "every", every=7))
    assert_same_bits(res, back, every=7)
    assert back.rows == len(range(0, res.rows, 7))
    assert back.record_every == 7
    assert json.dumps(back.metrics) == json.dumps(res.metrics)  # those of the whole run
    again = SimResult.load(back.save(tmp_path / "again", every=2))
    assert again.record_every == 14
    assert np.array_equal(again.t, res.t[::14])


@pytest.mark.parametrize("every", [0, -1, 1.5, True, "2"])
def test_every_must_be_a_positive_integer(
    runs: dict[str, SimResult], every: object, tmp_path: Path
) -> None:
    with pytest.raises(ValueError, match=f"every must be an integer ≥ 1, got {every!r}"):
        runs["pd"].save(tmp_path / "bad", every=every)  # type: ignore[arg-type]
    assert not (tmp_path / "bad.npz").exists()


def test_a_file_of_the_first_format_still_loads() -> None:
    """tests/data/simresult_v1.npz was written by SimResult.save before the
    compressed format (plain float64 arrays, np.savez_compressed)."""
    path = DATA / "simresult_v1.npz"
    res = SimResult.load(path)
    with np.load(path, allow_pickle=False) as f:
        assert "format" not in f
        for name in NAMES:
            assert np.array_equal(getattr(res, name).view(np.uint8), f[name].view(np.uint8))
    assert (res.case, res.scenario, res.rows, res.record_every) == ("sf", "paper", 200, 1)
    assert res.params["Ts"] == 50e-6


def test_an_unknown_format_is_refused(runs: dict[str, SimResult], tmp_path: Path) -> None:
    path = runs["pd"].save(tmp_path / "run")
    with np.load(path) as f:
        content = dict(f)
    content["format"] = np.array(json.dumps({"version": 99}))
    np.savez(tmp_path / "future.npz", **content)
    with pytest.raises(ValueError, match="saved in format 99, which this version of adaptimp"):
        SimResult.load(tmp_path / "future.npz")
