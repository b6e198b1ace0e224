"""Sweeps that never lie and never sink (issue 20, items 7-9): the cache key
covers every input that changes a result, one bad value is one error row, a
bad cache entry is recomputed with a warning, writers never collide, and an
unwritable cache is refused before any run starts."""

from __future__ import annotations

import json
import shutil
import threading
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import adaptimp

FIXED = {"T": 0.3, "substeps": 1}


# -- item 7: the key covers every input ---------------------------------------


def test_the_cache_never_returns_another_arms_result(tmp_path: Path) -> None:
    vary = {"Kp": [9.0, 10.0]}
    light = adaptimp.sweep(
        "pd", vary=vary, scenario="robot", arm=adaptimp.TwoLinkArm(), cache=tmp_path, **FIXED
    )
    heavy_arm = adaptimp.TwoLinkArm(m2=3.0)
    heavy = adaptimp.sweep(
        "pd", vary=vary, scenario="robot", arm=heavy_arm, cache=tmp_path, **FIXED
    )
    alone = adaptimp.sweep("pd", vary=vary, scenario="robot", arm=heavy_arm, **FIXED)
    assert not np.array_equal(light["rms_z1"], heavy["rms_z1"])
    pd.testing.assert_frame_equal(heavy, alone)
    assert len(list(tmp_path.glob("*.json"))) == 4


def test_the_cache_key_covers_the_mujoco_model_file(tmp_path: Path) -> None:
    source = Path(adaptimp.__file__).parent / "models" / "two_link.xml"
    model = tmp_path / "arm.xml"
    shutil.copy(source, model)
    cache = tmp_path / "cache"
    kw = {"plant": "mujoco", "model": str(model), "T": 0.1, "contact": False}
    first = adaptimp.sweep("pd", vary={"Kp": [10.0]}, cache=cache, scenario="robot", **kw)
    # The same path, another arm: a mass of link 2 changed in the file.
    text = model.read_text()
    heavier = text.replace('mass="0.85"', 'mass="2.5"', 1)
    assert heavier != text, "the model file declares a mass to change"
    model.write_text(heavier)
    second = adaptimp.sweep("pd", vary={"Kp": [10.0]}, cache=cache, scenario="robot", **kw)
    assert first["error"].isna().all()
    assert second["error"].isna().all()
    assert first["rms_z1"][0] != second["rms_z1"][0]


def test_a_value_without_a_stable_key_is_an_error_row_when_caching(tmp_path: Path) -> None:
    kw = {"plant": "mujoco", "T": 0.05, "contact": False}
    df = adaptimp.sweep("pd", vary={"settle": [0.01, object()]}, cache=tmp_path, **kw)
    assert df["error"].isna().tolist() == [True, False]
    assert df["error"][1].startswith("cannot be cached: a value of type object has no stable key")


def test_the_arm_is_checked_before_any_run() -> None:
    with pytest.raises(TypeError, match="a sweep's arm must be a TwoLinkArm or None"):
        adaptimp.sweep("pd", vary={"Kp": [9.0]}, arm=adaptimp.PlanarArm(2), **FIXED)
    with pytest.raises(TypeError, match="the MuJoCo plant's arm is its model="):
        adaptimp.sweep("pd", vary={"Kp": [9.0]}, arm=adaptimp.TwoLinkArm(), plant="mujoco")


# -- item 8: one bad value is one error row ------------------------------------


def test_an_arm_parameter_that_makes_no_arm_is_an_error_row(tmp_path: Path) -> None:
    df = adaptimp.sweep("pd", vary={"m2": [1.0, -1.0]}, scenario="robot", **FIXED)
    assert df["error"].isna().tolist() == [True, False]
    assert "m2" in df["error"][1]
    assert np.isfinite(df["rms_z1"][0])


def test_a_negative_normal_draw_is_an_error_row_cached_and_rerun_alike(tmp_path: Path) -> None:
    vary = {"m2": adaptimp.Normal(0.3, 0.5)}
    first = adaptimp.sweep("pd", vary=vary, samples=6, seed=1, cache=tmp_path, **FIXED)
    assert (first["m2"] < 0).any()
    assert (first["m2"] > 0).any()
    assert first["error"].isna().tolist() == (first["m2"] > 0).tolist()
    again = adaptimp.sweep("pd", vary=vary, samples=6, seed=1, cache=tmp_path, **FIXED)
    pd.testing.assert_frame_equal(first, again)


def test_numpy_values_are_keyed_and_cached(tmp_path: Path) -> None:
    vary = {"Kp": [np.float32(9.5), np.int64(10)], "delay": [np.int64(0)]}
    a = adaptimp.sweep("pd", vary=vary, scenario="robot", cache=tmp_path, **FIXED)
    b = adaptimp.sweep("pd", vary=vary, scenario="robot", cache=tmp_path, **FIXED)
    assert a["error"].isna().all()
    pd.testing.assert_frame_equal(a, b)
    mj = {"plant": "mujoco", "T": np.float64(0.05), "contact": False}
    c = adaptimp.sweep("pd", vary={"Kp": [np.int64(10)]}, cache=tmp_path, **mj)
    assert c["error"].isna().all()


def test_a_broken_model_on_the_mujoco_plant_is_an_error_row(tmp_path: Path) -> None:
    urdf = tmp_path / "broken.urdf"
    urdf.write_text("<robot name='x'><link name='a'>")
    df = adaptimp.sweep("pd", vary={"Kp": [10.0]}, plant="mujoco", model=str(urdf), T=0.05)
    assert df["error"].notna().all()


# -- item 9: a bad entry is recomputed, writers never collide ------------------


@pytest.mark.parametrize(
    "damage",
    [
        lambda p: p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2]),  # truncated
        lambda p: p.write_bytes(b""),  # empty
        lambda p: p.write_bytes(b"\xff\xfe\x00garbage"),  # not UTF-8
        lambda p: p.write_text("[1, 2]"),  # not an object
        lambda p: p.write_text(
            json.dumps({**json.loads(p.read_text()), "result": {"rms_z1": 1.0}})
        ),  # missing metrics
        lambda p: p.write_text(
            json.dumps(
                {
                    **json.loads(p.read_text()),
                    "result": {**json.loads(p.read_text())["result"], "rows": "many"},
                }
            )
        ),  # a metric that is not a number
    ],
)
def test_a_damaged_cache_entry_is_recomputed_with_a_warning(tmp_path: Path, damage) -> None:  # type: ignore[no-untyped-def]
    vary = {"Kp": [9.0, 10.0]}
    fresh = adaptimp.sweep("pd", vary=vary, scenario="robot", cache=tmp_path, **FIXED)
    path = sorted(tmp_path.glob("*.json"))[0]
    damage(path)
    with pytest.warns(RuntimeWarning, match="is unreadable .*recomputing that run"):
        again = adaptimp.sweep("pd", vary=vary, scenario="robot", cache=tmp_path, **FIXED)
    pd.testing.assert_frame_equal(fresh, again)
    # Rewritten whole: the next rerun reads it without a warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        third = adaptimp.sweep("pd", vary=vary, scenario="robot", cache=tmp_path, **FIXED)
    pd.testing.assert_frame_equal(fresh, third)


def test_concurrent_sweeps_share_a_cache_without_collisions(tmp_path: Path) -> None:
    vary = {"Kp": [8.0, 9.0, 10.0, 11.0]}
    kw = {"vary": vary, "scenario": "robot", "cache": tmp_path, "threads": 1, "batch_size": 1}
    start = threading.Barrier(6)

    def one(_: int) -> pd.DataFrame:
        start.wait()
        return adaptimp.sweep("pd", **kw, **FIXED)  # type: ignore[arg-type]

    with ThreadPoolExecutor(6) as ex:
        frames = list(ex.map(one, range(6)))
    for f in frames[1:]:
        pd.testing.assert_frame_equal(frames[0], f)
    assert sorted(p.suffix for p in tmp_path.iterdir()) == [".json"] * 4


def test_an_unwritable_cache_is_refused_before_any_run(tmp_path: Path) -> None:
    seen: list[int] = []
    not_a_dir = tmp_path / "file"
    not_a_dir.write_text("x")
    for cache in (not_a_dir, not_a_dir / "sub"):
        with pytest.raises(OSError, match=r"the cache directory cannot be written.*no run was"):
            adaptimp.sweep(
                "pd",
                vary={"Kp": [9.0, 10.0]},
                cache=cache,
                progress=lambda d, t: seen.append(d),
                **FIXED,
            )
    assert seen == []


def test_a_result_that_cannot_be_cached_stays_in_the_table(tmp_path: Path) -> None:
    cache = tmp_path / "cache"

    def vanish(done: int, total: int) -> None:
        # After the first run is recorded, the directory becomes a file.
        if cache.is_dir():
            shutil.rmtree(cache)
            cache.write_text("x")

    vary = {"Kp": [8.0, 9.0, 10.0]}
    with ThreadPoolExecutor(1) as ex, pytest.warns(RuntimeWarning, match="could not be cached"):
        df = adaptimp.sweep(
            "pd",
            vary=vary,
            scenario="robot",
            cache=cache,
            executor=ex,
            batch_size=1,
            progress=vanish,
            **FIXED,
        )
    fresh = adaptimp.sweep("pd", vary=vary, scenario="robot", **FIXED)
    pd.testing.assert_frame_equal(df, fresh)
