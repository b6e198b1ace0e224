"""Sweeps: many runs of :func:`adaptimp.simulate` over a grid or random samples of
parameters, on every core (Rust threads, the GIL released) or on any
``concurrent.futures.Executor`` (a process pool, a Dask cluster), with a
progress bar and a cache that lets an interrupted sweep resume."""

from __future__ import annotations

import contextlib
import hashlib
import itertools
import json
import math
import os
import tempfile
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from concurrent.futures import Executor, Future, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Union

import numpy as np

from . import _adaptimp
from ._adaptimp import __version__
from ._errors import needs_extra
from ._params import BY_NAME, check_case, check_scenario, config_hint, loop_delay, resolve

if TYPE_CHECKING:
    import pandas as pd

    from ._arms import TwoLinkArm


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


def _plain(value: Any) -> Any:
    """A JSON-able form of a NumPy value (``json.dumps``'s ``default``); any
    other object cannot be keyed or stored: ``TypeError``."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"a value of type {type(value).__name__} has no stable key")


def _json(value: Any) -> str:
    return json.dumps(value, sort_keys=True, default=_plain)


def _key(case: str, scenario: str, params: Mapping[str, Any], **more: Any) -> str:
    """The hash of every input that changes a run's result: the case, the
    scenario, the complete parameters, what else is given (``more``: the arm,
    the MuJoCo model) and the adaptimp version. ``TypeError`` for a value
    that has no stable key."""
    text = _json(
        {"case": case, "scenario": scenario, "params": params, "version": __version__, **more}
    )
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def _model_key(model: str) -> dict[str, Any]:
    """The MuJoCo model as a key: its name, and the content of its file if it
    is one (an edited file is another model)."""
    path = Path(model)
    if path.is_file():
        return {"model": model, "model_sha256": hashlib.sha256(path.read_bytes()).hexdigest()}
    return {"model": model}


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
    arm: TwoLinkArm | None = None,
    keyed: bool = True,
) -> _Run:
    """One run's complete parameters and, if ``keyed`` (a cache), its key; a
    run whose parameters are refused, or that cannot be keyed, is an error row."""
    run_case = str(varied.get("case", case))
    given = {**fixed, **{k: v for k, v in varied.items() if k != "case"}}
    if model is not None:
        # The MuJoCo plant takes the keywords as they are (adaptimp.mujoco.simulate).
        try:
            key = (
                _key(run_case, scenario, given, plant="mujoco", **_model_key(model))
                if keyed
                else ""
            )
        except (TypeError, ValueError, OSError) as e:
            return _Run(dict(varied), run_case, None, f"cannot be cached: {e}", "")
        return _Run(dict(varied), run_case, dict(given), None, key)
    try:
        check_case(run_case)
        given = dict(given)
        # SPEC (18.11): the loop's delay, the plant's and the controller's, as simulate().
        given["delay"] = loop_delay(given)
        p = resolve(given, scenario=scenario, caller="sweep()")
        more = {"arm": None if arm is None else arm.params}
        key = _key(run_case, scenario, p, **more) if keyed else ""
    except (TypeError, ValueError) as e:
        return _Run(dict(varied), run_case, None, f"{type(e).__name__}: {e}", "")
    return _Run(dict(varied), run_case, p, None, key)


def _run_batch(
    jobs: list[tuple[str, dict[str, Any], TwoLinkArm | None]],
    threads: int | None = 1,
    progress: Callable[[int, int], object] | None = None,
) -> list[dict[str, Any] | str]:
    """Run ``jobs`` (case, params, arm) in this process on ``threads`` threads: the
    task an executor runs, and the batches of ``executor=None``."""
    core_jobs = [(c, p, None if a is None else a.core) for c, p, a in jobs]
    return list(_adaptimp.simulate_many(core_jobs, threads, progress))


def _run_mujoco_batch(
    jobs: list[tuple[str, str, str, dict[str, Any]]],
    threads: int | None = 1,
    progress: Callable[[int, int], object] | None = None,
) -> list[dict[str, Any] | str]:
    """Run ``jobs`` (case, scenario, model, keywords) on the MuJoCo plant in this
    process on ``threads`` threads (the core's loop, the GIL released): the task
    an executor runs, and the batches of ``executor=None``."""
    from ._run import run_many

    return run_many(jobs, threads, progress)


def _batches(items: list[Any], size: int) -> Iterator[list[Any]]:
    for i in range(0, len(items), size):
        yield items[i : i + size]


class _Cache:
    """One JSON file per finished run in ``root``, named by its key (the hash of
    everything that changes its result).

    The directory is checked writable before any run starts. Each file is
    written under a name of its own and renamed into place (atomic: a reader
    never sees half a file, concurrent writers never share a temporary). An
    entry that cannot be read back whole (truncated, empty, not UTF-8, not
    JSON, a missing metric, another key) is recomputed, with a warning. A
    result that cannot be written is kept in the sweep's table, with a warning.
    """

    def __init__(self, root: str | os.PathLike[str] | None) -> None:
        self.root = None if root is None else Path(root)
        if self.root is None:
            return
        try:
            self.root.mkdir(parents=True, exist_ok=True)
            fd, probe = tempfile.mkstemp(dir=self.root, prefix=".probe.", suffix=".tmp")
            os.close(fd)
            os.unlink(probe)
        except OSError as e:
            raise OSError(
                e.errno,
                f"sweep(cache={str(root)!r}): the cache directory cannot be written "
                f"({e.strerror or e}); no run was started",
            ) from e

    def get(self, key: str) -> dict[str, Any] | str | None:
        if self.root is None or not key:
            return None
        path = self.root / f"{key}.json"
        if not path.exists():
            return None
        try:
            data = json.loads(path.read_bytes().decode("utf-8"))
            return self._result(data, key)
        except (OSError, ValueError, TypeError, KeyError) as e:
            warnings.warn(
                f"sweep(): the cache entry {path} is unreadable ({type(e).__name__}: {e}); "
                "recomputing that run",
                RuntimeWarning,
                stacklevel=4,
            )
            return None

    @staticmethod
    def _result(data: Any, key: str) -> dict[str, Any] | str:
        """The result of a cache entry, checked whole: ``ValueError`` if not."""
        if not isinstance(data, dict):
            raise ValueError("not a JSON object")
        if data.get("key", key) != key:
            raise ValueError(f"it holds the run {data.get('key')!r}")
        result = data["result"]
        if isinstance(result, str):
            return result
        if not isinstance(result, dict):
            raise ValueError("its result is neither metrics nor an error")
        out: dict[str, Any] = {}
        for k in METRIC_COLUMNS:
            v = result[k]
            if v is not None and (isinstance(v, bool) or not isinstance(v, (int, float))):
                raise ValueError(f"metric {k!r} is not a number")
            out[k] = math.nan if v is None else v
        for k in JOINT_METRICS:
            v = result[k]
            if not isinstance(v, list) or not all(
                x is None or (isinstance(x, (int, float)) and not isinstance(x, bool)) for x in v
            ):
                raise ValueError(f"metric {k!r} is not a list of numbers")
            out[k] = [math.nan if x is None else x for x in v]
        return out

    def put(self, run: _Run, result: dict[str, Any] | str) -> None:
        if self.root is None or not run.key or _transient(result):
            return
        from ._result import metrics_json

        clean = metrics_json(result) if isinstance(result, dict) else result
        body = {
            "key": run.key,
            "case": run.case,
            "params": run.params,
            "result": clean,
            "version": __version__,
        }
        tmp = None
        try:
            text = _json(body)
            fd, tmp = tempfile.mkstemp(dir=self.root, prefix=f".{run.key}.", suffix=".tmp")
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                f.write(text)
            os.replace(tmp, self.root / f"{run.key}.json")
            tmp = None
        except (OSError, TypeError, ValueError) as e:
            warnings.warn(
                f"sweep(): the result of run {run.key} could not be cached "
                f"({type(e).__name__}: {e}); it is in the returned table",
                RuntimeWarning,
                stacklevel=4,
            )
        finally:
            if tmp is not None:
                with contextlib.suppress(OSError):
                    os.unlink(tmp)


def _transient(result: dict[str, Any] | str) -> bool:
    """A failure that says nothing about the run's parameters (an interrupted
    run, memory): not cached, so a rerun tries again."""
    return isinstance(result, str) and (
        result == "stopped" or result.startswith(("cannot allocate", "MemoryError"))
    )


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
        a hash of everything that changes its result: the case, the scenario,
        the complete parameters, the arm, the MuJoCo model and its file, the
        adaptimp version). A sweep started again with the same cache runs only
        what is missing: an interrupted sweep resumes where it stopped. The
        directory must be writable (checked before any run starts); an entry
        that cannot be read back whole is recomputed, with a warning; a run
        with a value that has no stable key (e.g. a function) is an error row.
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
        MuJoCo runs go through the core's loop like rigid ones: on every core
        with ``executor=None`` (each run with its own MuJoCo data), in batches
        on an executor.
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
    from ._arms import TwoLinkArm

    try:  # before any run: the result is a DataFrame
        import pandas  # noqa: F401
    except ImportError:
        raise needs_extra("adaptimp.sweep()", "pandas>=1.5", "sweep") from None
    check_scenario(scenario)
    check_case(case)
    if plant not in ("rigid", "mujoco"):
        raise ValueError(f"plant must be 'rigid' or 'mujoco', got {plant!r}")
    if arm is not None and not isinstance(arm, TwoLinkArm):
        raise TypeError(f"a sweep's arm must be a TwoLinkArm or None, got {type(arm).__name__}")
    if arm is not None and plant == "mujoco":
        raise TypeError("arm= is the rigid plant's arm: the MuJoCo plant's arm is its model=")
    mj_model = model if plant == "mujoco" else None
    grid = _runs(vary or {}, samples, seed)
    store = _Cache(cache)
    runs = [_prepare(case, scenario, params, v, mj_model, arm, cache is not None) for v in grid]
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
        if executor is None:
            cores = threads or os.cpu_count() or 1
            size = batch_size or (8 * cores if cache is not None else max(len(todo), 1))
            for batch in _batches(todo, size):
                base = finished

                def inner(done: int, _total: int, base: int = base) -> None:
                    if report is not None:
                        report(base + done, total)

                if mj_model is not None:
                    record(batch, _run_mujoco_batch([mj_job(i) for i in batch], threads, inner))
                else:
                    record(batch, _run_batch([job(i) for i in batch], threads, inner))
        elif mj_model is not None:
            on_executor(_run_mujoco_batch, mj_job, batch_size or 8)
        else:
            on_executor(_run_batch, job, batch_size or 8)
    finally:
        if bar is not None:
            bar.close(total)
    return _frame(runs, results)
