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


def test_a_file_of_the_second_format_still_loads() -> None:
    """tests/data/simresult_v2.npz was written by SimResult.save in format 2 (every
    array stored or derived from stored ones); simresult_v2_plain.npz is the same
    run with compress=False."""
    res = SimResult.load(DATA / "simresult_v2.npz")
    with np.load(DATA / "simresult_v2.npz", allow_pickle=False) as f:
        assert json.loads(str(f["format"]))["version"] == 2
    plain = SimResult.load(DATA / "simresult_v2_plain.npz")
    assert_same_bits(plain, res)
    assert (res.case, res.scenario, res.rows, res.record_every) == ("sf", "paper", 200, 1)
    assert res.params == plain.params


def manifest(path: Path) -> dict:
    with np.load(path, allow_pickle=False) as f:
        return dict(json.loads(str(f["format"])))


def test_the_paper_run_saves_under_10_mb_and_loads_bit_identically(tmp_path: Path) -> None:
    """The default paper run (400 000 rows) is repeated by the core at save: every
    array comes out bit-identical, so none is stored; the load runs it again."""
    res = adaptimp.simulate("sf")
    path = res.save(tmp_path / "paper")
    assert path.stat().st_size < 10_000_000
    m = manifest(path)
    assert m["version"] == 4
    assert sorted(m["simulated"]) == sorted(NAMES)
    back = SimResult.load(path)
    assert_same_bits(res, back)
    assert (back.case, back.scenario, back.record_every) == ("sf", "paper", 1)
    kept = res.save(tmp_path / "kept", every=10, recompute=False)  # every array stored
    assert manifest(kept)["simulated"] == {}
    assert_same_bits(res, SimResult.load(kept), every=10)
    assert back.params == res.params
    assert json.dumps(back.metrics) == json.dumps(res.metrics)


def test_arrays_the_core_does_not_repeat_are_stored(tmp_path: Path) -> None:
    """A warm start, a fault and an edited array are not what the recorded
    parameters give: those arrays are stored (and still load bit for bit)."""
    cold = adaptimp.simulate("sf", T=0.05)
    weights = {"D": np.full((2, 2, 256), 0.01), "C": np.zeros((2, 2, 256)), "G": np.zeros((2, 256))}
    warm = adaptimp.simulate("sf", T=0.05, weights=weights)
    faulty = adaptimp.simulate("sf", T=0.05, fault=adaptimp.Fault("nan_burst", 0.01, 0.01))
    tau = cold.tau.copy()
    tau[3, 0] = np.nextafter(tau[3, 0], np.inf)
    edited = dataclasses.replace(cold, tau=tau)
    for name, res in (("warm", warm), ("faulty", faulty), ("edited", edited)):
        path = res.save(tmp_path / name)
        assert_same_bits(res, SimResult.load(path))
        simulated = manifest(path)["simulated"]
        assert "tau" not in simulated, name
        if name == "edited":  # the rest still comes from the core
            assert "q" in simulated
        else:
            assert "q" not in simulated, name


def test_a_rerun_that_differs_from_the_save_is_refused(tmp_path: Path) -> None:
    """The load checks each recomputed array against the SHA-256 the save recorded
    (another version of the core or another platform could give other bits)."""
    path = adaptimp.simulate("pd", T=0.05).save(tmp_path / "run")
    with np.load(path) as f:
        content = dict(f)
    m = manifest(path)
    m["simulated"]["zeta"]["sha256"] = "0" * 64
    content["format"] = np.array(json.dumps(m))
    np.savez(tmp_path / "other.npz", **content)
    with pytest.raises(
        ValueError,
        match=r"zeta was left to the simulation to recompute, .* does not give the same bits",
    ):
        SimResult.load(tmp_path / "other.npz")


def test_an_unknown_format_is_refused(runs: dict[str, SimResult], tmp_path: Path) -> None:
    path = runs["pd"].save(tmp_path / "run")
    with np.load(path) as f:
        content = dict(f)
    content["format"] = np.array(json.dumps({"version": 99}))
    np.savez(tmp_path / "future.npz", **content)
    with pytest.raises(ValueError, match="saved in format 99, which this version of adaptimp"):
        SimResult.load(tmp_path / "future.npz")


def test_a_stored_copy_of_a_recomputed_array_is_refused(tmp_path: Path) -> None:
    """An array the manifest leaves to the core, stored in the file too (the file
    edited after the save), would replace the checked one unseen: refused."""
    path = adaptimp.simulate("pd", T=0.05).save(tmp_path / "run")
    assert "q" in manifest(path)["simulated"]
    with np.load(path) as f:
        content = dict(f)
    content["q"] = np.zeros((50, 2))
    np.savez(tmp_path / "edited.npz", **content)
    with pytest.raises(
        adaptimp.SaveError, match=r"edited\.npz: q is both stored and left to the core to recompute"
    ):
        SimResult.load(tmp_path / "edited.npz")
