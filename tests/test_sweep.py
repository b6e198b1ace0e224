"""Sweeps: grids and random samples, every core, any executor (a real Dask
LocalCluster), failing runs, the cache and resumption."""

from __future__ import annotations

import json
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import adaptimp

FIXED = {"T": 0.4, "substeps": 2}


def _serial(df: pd.DataFrame, scenario: str = "robot") -> list[float]:
    """rms_z1 of every row, each run alone through adaptimp.simulate."""
    out = []
    for _, row in df.iterrows():
        kw = {k: row[k] for k in ("Kp", "m2") if k in row}
        out.append(adaptimp.simulate(row["case"], scenario, **FIXED, **kw).metrics["rms_z1"])
    return out


def test_grid_runs_the_product_on_every_core_equal_to_serial_runs() -> None:
    df = adaptimp.sweep(
        "sf", vary={"case": ["pd", "sf", "of"], "m2": [0.85, 1.5]}, scenario="robot", **FIXED
    )
    assert len(df) == 6
    assert list(df["case"]) == ["pd", "pd", "sf", "sf", "of", "of"]
    assert list(df["m2"]) == [0.85, 1.5] * 3
    assert df["error"].isna().all()
    # Bit for bit the runs made one by one.
    assert list(df["rms_z1"]) == _serial(df)
    for col in ("rms_z1_after2", "sat_duty", "peak_abs_tau_1", "peak_abs_tau_2", "rows"):
        assert col in df.columns


def test_random_samples_are_reproducible_from_the_seed() -> None:
    vary = {"Kp": adaptimp.Uniform(8.0, 10.0), "m2": adaptimp.Choice([0.85, 1.2])}
    a = adaptimp.sweep("pd", vary=vary, samples=5, seed=7, scenario="robot", **FIXED)
    b = adaptimp.sweep("pd", vary=vary, samples=5, seed=7, scenario="robot", **FIXED)
    c = adaptimp.sweep("pd", vary=vary, samples=5, seed=8, scenario="robot", **FIXED)
    pd.testing.assert_frame_equal(a, b)
    assert not a["Kp"].equals(c["Kp"])
    assert a["Kp"].between(8.0, 10.0).all()
    assert set(a["m2"]) <= {0.85, 1.2}


def test_a_failing_run_never_sinks_the_sweep() -> None:
    df = adaptimp.sweep("sf", vary={"Kp": [10.0, 200.0, "x"]}, scenario="robot", **FIXED)
    assert df["error"].isna().tolist() == [True, False, False]
    assert "raise Kzeta above 100.5 for Kp = 200 and inertia = 1 (joint 0)" in df["error"][1]
    assert df["error"][2].startswith("TypeError: Kp must be")
    assert np.isnan(df["rms_z1"][1])


def test_any_executor_gives_the_serial_results() -> None:
    vary = {"case": ["pd", "sf"], "Kp": [9.0, 10.0, 11.0]}
    local = adaptimp.sweep("sf", vary=vary, scenario="robot", **FIXED)
    with ThreadPoolExecutor(2) as ex:
        pooled = adaptimp.sweep(
            "sf", vary=vary, scenario="robot", executor=ex, batch_size=2, **FIXED
        )
    pd.testing.assert_frame_equal(local, pooled)


def test_a_dask_local_cluster_gives_the_serial_results() -> None:
    import distributed

    vary = {"case": ["pd", "sf", "of"], "m2": [0.85, 1.2, 1.5]}
    local = adaptimp.sweep("sf", vary=vary, scenario="robot", **FIXED)
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        remote = adaptimp.sweep(
            "sf", vary=vary, scenario="robot", executor=client.get_executor(), batch_size=2, **FIXED
        )
    pd.testing.assert_frame_equal(local, remote)


def test_cache_resumes_an_interrupted_sweep(tmp_path: Path) -> None:
    vary = {"Kp": [7.0, 8.0, 9.0, 10.0]}
    first = adaptimp.sweep("pd", vary={"Kp": [7.0, 8.0]}, scenario="robot", cache=tmp_path, **FIXED)
    assert first["error"].isna().all()
    assert len(list(tmp_path.glob("*.json"))) == 2
    # Poison one cached result: a resumed sweep must read it, not rerun it.
    path = sorted(tmp_path.glob("*.json"))[0]
    data = json.loads(path.read_text())
    data["result"]["rms_z1"] = 123.0
    path.write_text(json.dumps(data))
    seen: list[tuple[int, int]] = []
    full = adaptimp.sweep(
        "pd",
        vary=vary,
        scenario="robot",
        cache=tmp_path,
        progress=lambda d, t: seen.append((d, t)),
        **FIXED,
    )
    assert len(list(tmp_path.glob("*.json"))) == 4
    assert 123.0 in set(full["rms_z1"])
    assert seen[-1] == (4, 4)
    fresh = adaptimp.sweep("pd", vary=vary, scenario="robot", **FIXED)
    changed = full["rms_z1"] != fresh["rms_z1"]
    assert changed.sum() == 1
    assert first["rms_z1"].tolist()[1] == fresh["rms_z1"].tolist()[1]


def test_sweep_arguments_are_checked() -> None:
    with pytest.raises(TypeError, match="cannot vary 'Kq'"):
        adaptimp.sweep("pd", vary={"Kq": [1.0]})
    with pytest.raises(TypeError, match="must be a sequence of values for a grid"):
        adaptimp.sweep("pd", vary={"Kp": adaptimp.Uniform(1.0, 2.0)})
    with pytest.raises(ValueError, match="samples must be an integer ≥ 1"):
        adaptimp.sweep("pd", vary={"Kp": adaptimp.Uniform(1.0, 2.0)}, samples=0)


def test_sweep_on_the_mujoco_plant() -> None:

    df = adaptimp.sweep(
        "pd", vary={"Kp": [8.0, 10.0]}, plant="mujoco", T=0.3, contact=False, scenario="robot"
    )
    assert df["error"].isna().all()
    from adaptimp import mujoco as amj

    alone = amj.simulate("pd", "two_link", T=0.3, contact=False, scenario="robot", Kp=10.0)
    assert df["rms_z1"][1] == alone.metrics["rms_z1"]
    assert df["rms_z1"][0] != df["rms_z1"][1]


def test_disturbances_reach_simulate_and_sweeps() -> None:
    """The disturbances of SPEC §17 act on the plant and the sensors, seeded."""
    base = adaptimp.simulate("pd", "robot", **FIXED)
    heavy = adaptimp.simulate("pd", "robot", payload=1.0, **FIXED)
    assert heavy.metrics["rms_z1"] > base.metrics["rms_z1"]
    a = adaptimp.simulate("sf", "robot", noise_q=1e-3, seed=1, **FIXED)
    b = adaptimp.simulate("sf", "robot", noise_q=1e-3, seed=1, **FIXED)
    c = adaptimp.simulate("sf", "robot", noise_q=1e-3, seed=2, **FIXED)
    assert np.array_equal(a.tau, b.tau)
    assert not np.array_equal(a.tau, c.tau)
    weak = adaptimp.simulate("sf", "robot", actuator_fraction=0.5, **FIXED)
    assert np.all(np.abs(weak.tau_sat) <= 0.5 * np.array(weak.params["tau_max"]) + 1e-12)
    df = adaptimp.sweep(
        "sf",
        vary={"noise_q": [0.0, 1e-3], "delay": [0, 5]},
        scenario="robot",
        seed=3,
        **FIXED,
    )
    assert df["error"].isna().all()
    # Every-core results equal the single runs, noise included.
    for _, row in df.iterrows():
        alone = adaptimp.simulate(
            "sf", "robot", noise_q=row["noise_q"], delay=int(row["delay"]), **FIXED
        )
        assert row["rms_z1"] == alone.metrics["rms_z1"]
    with pytest.raises(ValueError, match="0 ≤ delay ≤ 64"):
        adaptimp.simulate("sf", delay=65)


def test_mujoco_sweeps_run_in_the_core_on_every_core_and_on_dask() -> None:
    """plant="mujoco": every core from the core's loop (each run with its own
    MuJoCo data), on a Dask cluster in batches; the results of each run alone."""
    import distributed

    from adaptimp import mujoco as amj

    vary = {"case": ["pd", "sf", "of"], "Kp": [8.0, 10.0]}
    fixed = {"T": 0.5, "scenario": "robot", "plant": "mujoco", "noise_q": 1e-4}
    local = adaptimp.sweep("sf", vary=vary, **fixed)
    serial = adaptimp.sweep("sf", vary=vary, threads=1, **fixed)
    assert local["error"].isna().all()
    pd.testing.assert_frame_equal(local, serial)
    for _, row in local.iterrows():
        alone = amj.simulate(row["case"], "two_link", T=0.5, Kp=row["Kp"], noise_q=1e-4).metrics
        assert row["rms_z1"] == alone["rms_z1"]
        assert row["imp_err_rms_after2"] == alone["imp_err_rms_after2"] or np.isnan(
            alone["imp_err_rms_after2"]
        )
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        remote = adaptimp.sweep(
            "sf", vary=vary, executor=client.get_executor(), batch_size=2, **fixed
        )
    pd.testing.assert_frame_equal(local, remote)


def test_a_failing_mujoco_run_never_sinks_the_sweep() -> None:
    df = adaptimp.sweep(
        "pd", vary={"Kp": [10.0, -1.0], "jitter": [0.0, 0.1]}, plant="mujoco", T=0.2
    )
    assert df["error"].isna().tolist() == [True, False, False, False]
    assert "jitter" in df["error"][1]
    assert "Kp" in df["error"][2]


def test_a_batch_starts_no_more_threads_than_jobs_and_refuses_fewer_than_one() -> None:
    """More threads than jobs would start only to idle (10⁶ of them used to
    take minutes to start): a batch runs on at most one thread per job, with
    the results of one thread; fewer than one thread is refused by name."""
    from adaptimp import _adaptimp

    jobs = [("sf", adaptimp.Controller("sf").params, None)]
    one = _adaptimp.simulate_many(jobs, 1, None)
    many = _adaptimp.simulate_many(jobs, 10**6, None)
    assert isinstance(one[0], dict)
    assert one == many
    for bad in (0, -1):
        with pytest.raises(
            adaptimp.ConfigError,
            match=rf"^threads must be ≥ 1 \(None: every core\), got {bad}$",
        ):
            _adaptimp.simulate_many(jobs, bad, None)
