"""Sweeps: many runs of :func:`adaptimp.simulate` over a grid or random samples of
parameters, on every core (Rust threads, the GIL released) or on any
``concurrent.futures.Executor`` (a process pool, a Dask cluster), with a
progress bar and a cache that lets an interrupted sweep resume."""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import Executor, Future, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Union

import numpy as np

from . import _adaptimp
from ._adaptimp import __version__
from ._errors import needs_extra
from ._params import BY_NAME, check_case, check_scenario, config_hint, resolve

if TYPE_CHECKING:
    import pandas as pd

    from ._api import TwoLinkArm


# ---------------------------------------------------------------------------
# Distributions for random samples.
# ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Uniform:
    """Uniform on [low, high] (the parameter's unit)."""

    low: float
    high: float

    def sample(self, rng: np.random.Generator) -> float:
        return float(rng.uniform(self.low, self.high))


@dataclass(frozen=True)
class LogUniform:
    """Log-uniform on [low, high], both > 0: for gains and scales spanning decades."""

    low: float
    high: float

    def sample(self, rng: np.random.Generator) -> float:
        return float(np.exp(rng.uniform(np.log(self.low), np.log(self.high))))


@dataclass(frozen=True)
class Normal:
    """Normal with mean ``mean`` and standard deviation ``std``."""

    mean: float
    std: float

    def sample(self, rng: np.random.Generator) -> float:
        return float(rng.normal(self.mean, self.std))


@dataclass(frozen=True)
class Choice:
    """One of ``values``, each equally likely."""

    values: Sequence[Any]

    def sample(self, rng: np.random.Generator) -> Any:
        return self.values[int(rng.integers(len(self.values)))]


Distribution = Union[Uniform, LogUniform, Normal, Choice]

METRIC_COLUMNS = (
    "rms_z1",
    "rms_z1_after2",
    "sat_duty",
    "steps_in_contact",
    "peak_contact_after2",
    "mean_contact",
    "imp_err_rms_after2",
    "rows",
)
JOINT_METRICS = ("rms_z1_joint_after2", "max_abs_z1_joint_after2", "peak_abs_tau")


# ---------------------------------------------------------------------------
# The runs.
# ---------------------------------------------------------------------------


def _runs(vary: Mapping[str, Any], samples: int | None, seed: int) -> list[dict[str, Any]]:
    """The varied values of every run: the grid's product, or ``samples`` draws."""
    for name in vary:
        if name != "case" and name not in BY_NAME:
            raise TypeError(f"sweep() cannot vary {name!r}: not a parameter of adaptimp.simulate")
    if samples is None:
        for name, values in vary.items():
            if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
                raise TypeError(
                    f"vary[{name!r}] must be a sequence of values for a grid "
                    "(give samples= for random draws from a distribution)"
                )
        names = list(vary)
        return [dict(zip(names, combo)) for combo in itertools.product(*vary.values())]
    if isinstance(samples, bool) or not isinstance(samples, int) or samples < 1:
        raise ValueError(f"samples must be an integer ≥ 1, got {samples!r}")
    rng = np.random.default_rng(seed)
    runs = []
    for _ in range(samples):
        run = {}
        for name, dist in vary.items():
            if hasattr(dist, "sample"):
                run[name] = dist.sample(rng)
            elif isinstance(dist, Sequence) and not isinstance(dist, (str, bytes)):
                run[name] = Choice(dist).sample(rng)
            else:
                raise TypeError(
                    f"vary[{name!r}] must be a distribution (adaptimp.Uniform, LogUniform, "
                    f"Normal, Choice) or a sequence of values, got {type(dist).__name__}"
                )
        runs.append(run)
    return runs


def _key(case: str, scenario: str, params: Mapping[str, Any]) -> str:
    text = json.dumps(
        {"case": case, "scenario": scenario, "params": params, "version": __version__},
        sort_keys=True,
    )
    return hashlib.sha256(text.encode()).hexdigest()[:24]


@dataclass
class _Run:
    """One run: what varied, the complete parameters (or the error that made them)."""

    varied: dict[str, Any]
    case: str
    params: dict[str, Any] | None
    error: str | None
    key: str


def _prepare(
    case: str,
    scenario: str,
    fixed: Mapping[str, Any],
    varied: Mapping[str, Any],
    model: str | None = None,
) -> _Run:
    run_case = str(varied.get("case", case))
    given = {**fixed, **{k: v for k, v in varied.items() if k != "case"}}
    if model is not None:
        # The MuJoCo plant takes the keywords as they are (adaptimp.mujoco.simulate).
        key = _key(run_case, scenario, {"mujoco": model, **given})
        return _Run(dict(varied), run_case, dict(given), None, key)
    try:
        check_case(run_case)
        p = resolve(given, scenario=scenario, caller="sweep()")
    except (TypeError, ValueError) as e:
        return _Run(dict(varied), run_case, None, f"{type(e).__name__}: {e}", "")
    return _Run(dict(varied), run_case, p, None, _key(run_case, scenario, p))


def _run_batch(
    jobs: list[tuple[str, dict[str, Any], TwoLinkArm | None]],
    threads: int | None = 1,
    progress: Callable[[int, int], object] | None = None,
) -> list[dict[str, Any] | str]:
    """Run ``jobs`` (case, params, arm) in this process on ``threads`` threads: the
    task an executor runs, and the batches of ``executor=None``."""
    core_jobs = [(c, p, None if a is None else a._core) for c, p, a in jobs]
    return list(_adaptimp.simulate_many(core_jobs, threads, progress))


def _run_mujoco_batch(
    jobs: list[tuple[str, str, str, dict[str, Any]]],
) -> list[dict[str, Any] | str]:
    """Run ``jobs`` (case, scenario, model, keywords) on the MuJoCo plant, one by one."""
    from . import mujoco as amj

    def one(case: str, scenario: str, model: str, kw: dict[str, Any]) -> dict[str, Any] | str:
        try:
            return dict(amj.simulate(case, model, scenario=scenario, **kw).metrics)
        except (TypeError, ValueError, ArithmeticError, RuntimeError) as e:
            return f"{type(e).__name__}: {e}"

    return [one(*job) for job in jobs]


def _batches(items: list[Any], size: int) -> Iterator[list[Any]]:
    for i in range(0, len(items), size):
        yield items[i : i + size]


class _Cache:
    """One JSON file per finished run in ``root``, named by its parameters' hash."""

    def __init__(self, root: str | os.PathLike[str] | None) -> None:
        self.root = None if root is None else Path(root)
        if self.root is not None:
            self.root.mkdir(parents=True, exist_ok=True)

    def get(self, key: str) -> dict[str, Any] | str | None:
        if self.root is None or not key:
            return None
        path = self.root / f"{key}.json"
        if not path.exists():
            return None
        data = json.loads(path.read_text(encoding="utf-8"))
        result: dict[str, Any] | str = data["result"]
        if isinstance(result, dict):
            result = {k: (math.nan if v is None else v) for k, v in result.items()}
            for k in JOINT_METRICS:
                if k in result:
                    result[k] = [math.nan if v is None else v for v in result[k]]
        return result

    def put(self, run: _Run, result: dict[str, Any] | str) -> None:
        if self.root is None:
            return
        from ._result import metrics_json

        clean = metrics_json(result) if isinstance(result, dict) else result
        body = {"case": run.case, "params": run.params, "result": clean, "version": __version__}
        tmp = self.root / f".{run.key}.tmp"
        tmp.write_text(json.dumps(body), encoding="utf-8")
        tmp.replace(self.root / f"{run.key}.json")


def _frame(runs: list[_Run], results: list[dict[str, Any] | str | None]) -> pd.DataFrame:
    import pandas as pd

    rows = []
    for run, result in zip(runs, results):
        row: dict[str, Any] = {"case": run.case}
        row.update((k, v) for k, v in run.varied.items() if k != "case")
        if isinstance(result, dict):
            for k in METRIC_COLUMNS:
                row[k] = result[k]
            for k in JOINT_METRICS:
                for i, v in enumerate(result[k]):
                    row[f"{k}_{i + 1}"] = v
            row["error"] = None
        else:
            row["error"] = run.error if run.error is not None else result
        rows.append(row)
    return pd.DataFrame(rows)


def sweep(
    case: str = "sf",
    vary: Mapping[str, Any] | None = None,
    samples: int | None = None,
    seed: int = 0,
    executor: Executor | None = None,
    *,
    scenario: str = "paper",
    arm: TwoLinkArm | None = None,
    cache: str | os.PathLike[str] | None = None,
    progress: bool | Callable[[int, int], object] = False,
    batch_size: int | None = None,
    threads: int | None = None,
    plant: str = "rigid",
    model: str = "two_link",
    **params: Any,
) -> pd.DataFrame:
    """Many runs of :func:`adaptimp.simulate`: one row per run, with its varied
    parameters and every SPEC §12 metric.

    Parameters
    ----------
    case : {"pd", "sf", "of"}
        The controller (vary ``"case"`` to compare them in one sweep).
    vary : dict
        Parameter name → values. Without ``samples``: a sequence per parameter,
        and the sweep runs their full grid (the product). With ``samples``: a
        distribution per parameter (:class:`Uniform`, :class:`LogUniform`,
        :class:`Normal`, :class:`Choice`, or a sequence to choose from), drawn
        ``samples`` times, reproducibly from ``seed``. Per-joint parameters take
        a number (every joint) or one value per joint.
    samples : int, optional
        Random runs instead of a grid.
    seed : int
        Seed of the random draws (NumPy's ``default_rng``).
    executor : concurrent.futures.Executor, optional
        Where to run: None runs on every core of this machine from Rust (each
        run single-threaded, the GIL released); an executor (a
        ``ProcessPoolExecutor``, a Dask ``Client.get_executor()``) gets the runs
        in batches of ``batch_size``. Results are identical, bit for bit, to
        running each run alone.
    scenario : {"paper", "robot"}
        The defaults every run starts from.
    arm : TwoLinkArm, optional
        The plant of every run (default: the arm of the run's parameters, so
        ``m1``, ``m2``, … can be varied).
    cache : path, optional
        A directory where each finished run is written (one JSON file named by
        a hash of its parameters and the adaptimp version). A sweep started
        again with the same cache runs only what is missing: an interrupted
        sweep resumes where it stopped.
    progress : bool or callable
        ``True``: a progress bar over the runs (tqdm if installed, else a line on
        stderr) for sweeps longer than 2 s; a callable gets ``(done, total)``.
    batch_size : int, optional
        Runs per task: default all runs at once (``executor=None``; 8 × the
        threads when caching) or 8 per task (an executor).
    threads : int, optional
        Threads of ``executor=None`` (default: every core).
    plant : {"rigid", "mujoco"}
        The plant: the RK4 rigid body of :func:`adaptimp.simulate`, or MuJoCo
        (``adaptimp.mujoco.simulate`` with ``model``; needs ``adaptimp[mujoco]``).
        MuJoCo runs step in Python: with ``executor=None`` they run one after the
        other in this process; give a process pool or a Dask executor to spread them.
    model : str
        The MuJoCo model of ``plant="mujoco"`` (``"two_link"``, ``"panda"``, a path).
    **params
        Fixed parameters of every run, as for :func:`adaptimp.simulate`.

    Returns
    -------
    pandas.DataFrame
        One row per run in the order of the grid or the draws: ``case``, the
        varied parameters, the metrics (per-joint ones as ``name_1``,
        ``name_2``), and ``error`` (None, or the message of a run that failed:
        one failing run never sinks the sweep).

    Examples
    --------
    >>> import adaptimp
    >>> df = adaptimp.sweep("pd", vary={"Kp": [8.0, 12.0]}, T=0.2, Kzeta=80.0)
    >>> df[["Kp", "rms_z1"]].shape
    (2, 2)
    """
    from ._api import ProgressReport

    try:  # before any run: the result is a DataFrame
        import pandas  # noqa: F401
    except ImportError:
        raise needs_extra("adaptimp.sweep()", "pandas>=1.5", "sweep") from None
    check_scenario(scenario)
    check_case(case)
    if plant not in ("rigid", "mujoco"):
        raise ValueError(f"plant must be 'rigid' or 'mujoco', got {plant!r}")
    mj_model = model if plant == "mujoco" else None
    runs = [_prepare(case, scenario, params, v, mj_model) for v in _runs(vary or {}, samples, seed)]
    store = _Cache(cache)
    results: list[dict[str, Any] | str | None] = [
        run.error if run.error is not None else store.get(run.key) for run in runs
    ]
    todo = [i for i, r in enumerate(results) if r is None]
    total = len(runs)
    bar: Any = None
    report: Callable[[int, int], object] | None = None
    if progress is True:
        bar = ProgressReport("sweep")
        report = bar
    elif callable(progress):
        report = progress
    finished = total - len(todo)

    def job(i: int) -> tuple[str, dict[str, Any], TwoLinkArm | None]:
        p = runs[i].params
        assert p is not None
        return (runs[i].case, p, arm)

    def record(batch: list[int], out: Sequence[dict[str, Any] | str]) -> None:
        nonlocal finished
        for i, result in zip(batch, out):
            p = runs[i].params
            if isinstance(result, str) and p is not None and mj_model is None:
                hint = config_hint(result, p)
                result = f"{result}; {hint}" if hint else result
            results[i] = result
            store.put(runs[i], result)
        finished += len(batch)
        if report is not None:
            report(finished, total)

    def mj_job(i: int) -> tuple[str, str, str, dict[str, Any]]:
        p = runs[i].params
        assert p is not None
        return (runs[i].case, scenario, model, p)

    def on_executor(
        run_batch: Callable[[list[Any]], Any], make: Callable[[int], Any], size: int
    ) -> None:
        """Every batch of ``todo`` to ``executor``, recorded as it finishes."""
        assert executor is not None
        pending: dict[Future[list[dict[str, Any] | str]], list[int]] = {
            executor.submit(run_batch, [make(i) for i in batch]): batch
            for batch in _batches(todo, size)
        }
        try:
            for future in as_completed(pending):
                record(pending[future], future.result())
        finally:
            for future in pending:
                future.cancel()

    try:
        if mj_model is not None and executor is None:
            for batch in _batches(todo, batch_size or 1):
                record(batch, _run_mujoco_batch([mj_job(i) for i in batch]))
        elif mj_model is not None:
            on_executor(_run_mujoco_batch, mj_job, batch_size or 1)
        elif executor is None:
            cores = threads or os.cpu_count() or 1
            size = batch_size or (8 * cores if cache is not None else max(len(todo), 1))
            for batch in _batches(todo, size):
                base = finished

                def inner(done: int, _total: int, base: int = base) -> None:
                    if report is not None:
                        report(base + done, total)

                record(batch, _run_batch([job(i) for i in batch], threads, inner))
        else:
            on_executor(_run_batch, job, batch_size or 8)
    finally:
        if bar is not None:
            bar.close(total)
    return _frame(runs, results)
