"""The result of a simulation: recorded arrays, SPEC §12 metrics, plots, saving."""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ._errors import SaveError, needs_extra
from ._params import CASE_NAMES
from ._plot import FIGURES, PLOT_KINDS, into
from ._save import (
    _META,
    ARRAYS,
    EXTRA_ARRAYS,
    _array_record,
    _check_arrays,
    _check_inputs,
    _check_row_count,
    _check_shapes,
    _check_stored,
    _decode,
    _encode,
    _fmt_list,
    _input_digests,
    _rerun,
    _resimulated,
    _same_metric,
    _sha_json,
)
from ._save import METRIC_KEYS as METRIC_KEYS  # the keys of SimResult.metrics
from ._save_file import (
    FORMAT,
    _open,
    _Reader,
    _save_path,
    _saved_kind,
    _write_atomically,
)

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

FloatArray = NDArray[np.float64]


UNITS = {
    "t": "s",
    "q": "rad",
    "dq": "rad/s",
    "ddq": "rad/s^2",
    "xc": "rad",
    "dxc": "rad/s",
    "ddxc": "rad/s^2",
    "xd": "rad",
    "dq_hat": "rad/s",
    "tau": "N m",
    "tau_sat": "N m",
    "tau_e": "N m",
    "zeta": "N m",
    "z1": "rad",
}
"""Units of the per-joint arrays (``w_norms``: kg m², kg m²/s, N m per network)."""


RESULT_KINDS: dict[str, Callable[[], type[SimResult] | None]] = {}
"""The subclasses :meth:`SimResult.load` gives for a file saved by one, by
the class's name: a callable that returns the class, or None where its
extra does not import. Filled by the package above both (``adaptimp``'s
``__init__``: ``"MujocoResult"``), so this module imports none of them."""


@dataclass(frozen=True, repr=False, eq=False)
class SimResult:
    """One simulated run (SPEC §11): every recorded row k = 0 … K − 1 at t_k = k·Ts.

    Arrays are float64 with one row per recorded step; per-joint arrays have
    shape (K, n).

    Attributes
    ----------
    t : (K,)
        Time t_k (s).
    q, dq : (K, 2)
        Plant joint positions (rad) and velocities (rad/s).
    xc, xd : (K, 2)
        Commanded position and compliant reference (rad), SPEC §4.
    dq_hat : (K, 2)
        Velocity the controller used (rad/s): measured, or estimated for "of".
    tau, tau_sat : (K, 2)
        Commanded torque τ and applied torque sat(τ) (N m).
    tau_e : (K, 2)
        Force the arm exerts on the wall (N m).
    zeta : (K, 2)
        Auxiliary state ζ used at the step (N m), SPEC §8.
    z1 : (K, 2)
        Tracking error z1 = xd − q (rad).
    w_norms : (K, 3)
        Frobenius norms of the weights ŴD, ŴC, ŴG before the step's update.
    metrics : dict
        SPEC §12 figures: ``rms_z1``, ``rms_z1_after2``, ``rms_z1_joint_after2``,
        ``max_abs_z1_joint_after2``, ``sat_duty``, ``steps_in_contact``,
        ``peak_contact_after2``, ``mean_contact``, ``peak_abs_tau``,
        ``imp_err_rms_after2`` and ``rows`` (per-joint ones as lists). "after2"
        means t ≥ ``params["settle"]`` (2 s by default); those are NaN if the run
        is shorter than the default (a ``settle`` given beyond the run's last
        step is refused before the run, SPEC §12).
    params : dict
        Every parameter that ran (JSON-serialisable).
    case : str
        "pd", "sf" or "of".
    scenario : str
        The scenario whose defaults were used.
    """

    case: str
    scenario: str
    params: dict[str, Any]
    metrics: dict[str, Any]
    t: FloatArray
    q: FloatArray
    dq: FloatArray
    xc: FloatArray
    xd: FloatArray
    dq_hat: FloatArray
    tau: FloatArray
    tau_sat: FloatArray
    tau_e: FloatArray
    zeta: FloatArray
    z1: FloatArray
    w_norms: FloatArray
    ddq: FloatArray | None = None
    dxc: FloatArray | None = None
    ddxc: FloatArray | None = None
    refused: NDArray[np.bool_] | None = None
    record_every: int = 1
    centers: FloatArray | None = None
    widths: FloatArray | None = None

    @property
    def n(self) -> int:
        """Joints n."""
        return int(self.q.shape[1])

    @property
    def dtau(self) -> FloatArray:
        """Δτ = sat(τ) − τ (N m), (K, 2)."""
        return self.tau_sat - self.tau

    @property
    def rows(self) -> int:
        """Number of recorded rows K."""
        return int(self.t.shape[0])

    def plot(self, kind: str = "tracking", ax: Axes | Sequence[Axes] | None = None) -> Figure:
        """A figure of the run, per joint, returned as a matplotlib ``Figure``.

        Parameters
        ----------
        kind : {"tracking", "errors", "torques"}
            ``"tracking"``: q against xc and xd, with the wall (Figs. 2, 5, 8);
            ``"errors"``: z1 (Figs. 3, 6, 9); ``"torques"``: commanded and applied
            torque with the limits ±τmax (Figs. 4, 7, 10).
        ax : Axes or sequence of n Axes, optional
            Draw into these axes (one per joint, or one for every joint) instead
            of a new figure, so that several runs overlay; the returned figure is
            theirs. Lines are labelled with the case.
        """
        if kind not in PLOT_KINDS:
            raise ValueError(f"kind must be one of {PLOT_KINDS}, got {kind!r}")
        if ax is not None:
            return into(self, kind, ax)
        return FIGURES[kind](self)

    def to_pandas(self) -> pd.DataFrame:
        """The run as a tidy pandas ``DataFrame``: one row per recorded step, indexed
        by ``t [s]``, one column per joint quantity named with its unit
        (``"q1 [rad]"``, ``"tau_sat2 [N m]"``, ``"w_norm_G"``); ``attrs`` holds
        the case, scenario, metrics, parameters and the units by column; needs
        pandas (the extra ``pandas``)."""
        try:
            import pandas as pd
        except ImportError:
            raise needs_extra("SimResult.to_pandas()", "pandas>=1.5", "pandas") from None

        columns: dict[str, Any] = {}
        units: dict[str, str] = {}
        for name in (*ARRAYS[1:-1], *EXTRA_ARRAYS[:-1]):
            arr = getattr(self, name)
            if arr is None:
                continue
            for i in range(arr.shape[1]):
                col = f"{name}{i + 1} [{UNITS[name]}]"
                columns[col] = arr[:, i]
                units[col] = UNITS[name]
        for j, net in enumerate(("D", "C", "G")):
            columns[f"w_norm_{net}"] = self.w_norms[:, j]
        if self.refused is not None:
            columns["refused"] = self.refused
        df = pd.DataFrame(columns, index=pd.Index(self.t, name="t [s]"))
        df.attrs.update(
            case=self.case,
            scenario=self.scenario,
            metrics=dict(self.metrics),
            params=dict(self.params),
            units=units,
            record_every=self.record_every,
        )
        return df

    def to_xarray(self) -> xr.Dataset:
        """The run as an xarray ``Dataset`` with dimensions ``t`` (s) and ``joint``
        (1 … n), one variable per quantity with its ``units`` attribute; needs
        xarray (the extra ``xarray``)."""
        try:
            import xarray as xr
        except ImportError:
            raise needs_extra("SimResult.to_xarray()", "xarray>=2022.6", "xarray") from None
        joints = np.arange(1, self.n + 1)
        data: dict[str, Any] = {}
        for name in (*ARRAYS[1:-1], *EXTRA_ARRAYS[:-1]):
            arr = getattr(self, name)
            if arr is not None:
                data[name] = (("t", "joint"), arr, {"units": UNITS[name]})
        data["w_norms"] = (("t", "network"), self.w_norms, {})
        if self.refused is not None:
            data["refused"] = (("t",), self.refused, {})
        coords = {"t": ("t", self.t, {"units": "s"}), "joint": joints, "network": ["D", "C", "G"]}
        attrs = {
            "case": self.case,
            "scenario": self.scenario,
            "metrics": json.dumps(metrics_json(self.metrics)),
            "params": json.dumps(self.params),
        }
        return xr.Dataset(data, coords=coords, attrs=attrs)

    def save(
        self,
        path: str | os.PathLike[str],
        *,
        every: int = 1,
        compress: bool = True,
        recompute: bool = True,
    ) -> Path:
        """Write the arrays, metrics and parameters to an ``.npz`` file (metrics and
        parameters as JSON strings, so no pickle is needed to read it back); returns
        the path written (``.npz`` is appended if missing). :meth:`load` reads it back
        bit-identically.

        Parameters
        ----------
        every : int
            Keep every k-th row (k ≥ 1): rows 0, k, 2k, … exactly as recorded (the
            loaded result has ``record_every`` multiplied by k); the metrics stay
            those of the whole run.

        The file is written whole or not at all: into a new file beside ``path``,
        flushed to the disk, then renamed over ``path`` (an atomic rename), so a
        save that fails partway (a full disk, Ctrl-C) leaves what ``path`` held,
        and saves to one path from several threads or processes leave one of
        them complete. A ``path`` that is a folder (or ends with a separator) is
        refused (``IsADirectoryError``): name the file.
        compress : bool
            True (default): arrays that the core recomputes exactly are not
            stored: a run of :func:`adaptimp.simulate` is deterministic, so the
            save runs it again from the recorded case, scenario and parameters
            and drops every array that comes out bit-identical (with its SHA-256,
            which the load checks after running it again); arrays that are
            exactly t_k = k·Ts, ``xd − q``, ``sat(τ)`` or ``dq`` are recomputed
            on load (checked bit for bit); the others (a warm start, a fault, an
            edited result, another arm, a MuJoCo run) are stored as integer
            differences of their bit patterns (lossless), deflated. The paper
            scenario's 400 000 rows take under 1 MB (a save and a load then
            each cost one run of the simulation).
            False: plain float64 arrays (``np.savez``), readable by NumPy alone.
        recompute : bool
            True (default): leave to the core what it repeats bit for bit (with
            ``compress``). Such a file loads only where the simulation gives the
            same bits (the load checks, and names the version that saved it);
            False: store every array, for a file that any later version loads on
            any platform.
        """
        if isinstance(every, bool) or not isinstance(every, (int, np.integer)) or every < 1:
            raise ValueError(f"every must be an integer ≥ 1, got {every!r}")
        every = int(every)
        path = _save_path(path)
        arrays: dict[str, NDArray[Any]] = {name: getattr(self, name) for name in ARRAYS}
        for name in EXTRA_ARRAYS:
            if getattr(self, name) is not None:
                arrays[name] = getattr(self, name)
        arrays.update(self._own_arrays())
        if every > 1:
            arrays = {name: a[::every] for name, a in arrays.items()}
        record_every = self.record_every * every
        meta: dict[str, Any] = {
            "case": np.array(self.case),
            "scenario": np.array(self.scenario),
            "metrics": np.array(json.dumps(self.metrics)),
            "params": np.array(json.dumps(self.params)),
            "record_every": np.array(record_every),
        }
        # What every load checks, whatever the encoding: the digest of each
        # array as saved (so a swapped, scaled or flipped array is refused),
        # of each input and each metric.
        record = {
            "result": type(self).__name__,
            "arrays": {name: _array_record(a) for name, a in arrays.items()},
            "inputs": _input_digests(self.case, self.scenario, self.params, record_every),
            "metrics": {k: _sha_json(v) for k, v in self.metrics.items()},
        }
        if not compress:
            # Plain float64 arrays, readable by NumPy alone; the record beside them.
            meta["format"] = np.array(json.dumps({"version": FORMAT, "plain": True, **record}))
            _write_atomically(path, lambda f: np.savez(f, **{**arrays, **meta}))
            return path
        # Only a SimResult of simulate() can be a run of the native loop; a
        # subclass (a MuJoCo run) comes from another engine and keeps its arrays.
        rerun = (
            _rerun(self.case, self.scenario, self.params, self.n, record_every)
            if recompute and type(self) is SimResult
            else None
        )
        stored, manifest = _encode(arrays, self.params, record_every, rerun)
        meta["format"] = np.array(json.dumps({"version": FORMAT, **manifest, **record}))
        _write_atomically(path, lambda f: np.savez_compressed(f, **{**stored, **meta}))
        return path

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> SimResult:
        """Read a result written by :meth:`save` (by this or an earlier version).

        Everything is checked before it is used: a file that is not a save of
        adaptimp's, truncated or damaged, of an unknown format, or edited after
        it was saved is a :class:`adaptimp.SaveError` naming the file and what
        is wrong. A file of this version records the SHA-256 of every array
        (stored plain, as differences, derived or left to the simulation), of
        every input (case, scenario, parameters, rows kept) and of every metric:
        the inputs are checked before the simulation is run again, each array
        after it is decoded. In a file without that record (``compress=False``
        of an earlier version, format 1) the metrics are checked against its
        rows, where it holds every step: the core's accumulator recomputes them,
        and a metric that differs is replaced, with a warning naming it and both
        values (the impedance residual only where the parameters give the target
        impedance, ``Dd``, ``Cd``, ``Gd``; not a MuJoCo run's).

        ``SimResult.load`` of a MuJoCo run's file gives a
        :class:`adaptimp.mujoco.MujocoResult` where ``adaptimp.mujoco`` imports.
        """
        kind = _saved_kind(path)
        if kind in {c.__name__ for c in cls.__mro__[1:]}:  # a parent's save
            raise SaveError(
                f"{path}: holds a {kind} (saved by {kind}.save), not a {cls.__name__}: load it "
                "with adaptimp.SimResult.load"
            )
        if cls is SimResult and kind in RESULT_KINDS:
            # The class the file names, given by the package above (this module
            # is below adaptimp.mujoco and does not import it); None without
            # its extra: the common arrays.
            kind_cls = RESULT_KINDS[kind]()
            if kind_cls is not None:
                return kind_cls.load(path)
        with _open(path) as f:
            r = _Reader(path, f)
            params = r.json("params", dict)
            case, scenario = r.text("case"), r.text("scenario")
            metrics = r.json("metrics", dict)
            record_every = r.integer("record_every") if "record_every" in f else 1
            manifest = r.manifest() if "format" in f else None
            if manifest is None:  # format 1: plain float64 arrays
                arrays = {name: r.array(name) for name in f if name not in _META}
            else:
                # The inputs before anything runs: an edited file is not simulated.
                _check_inputs(path, case, scenario, params, record_every, manifest)
                if manifest.get("plain"):
                    arrays = {name: r.array(name) for name in f if name not in _META}
                else:
                    stored = {name: r.array(name) for name in f if name not in _META}
                    _check_stored(path, stored, manifest)
                    simulated = (
                        _resimulated(path, case, scenario, params, record_every, manifest)
                        if manifest.get("simulated")
                        else {}
                    )
                    arrays = _decode(path, stored, manifest, params, record_every, simulated)
                _check_arrays(path, arrays, manifest)
        _check_shapes(path, arrays, params, metrics)
        missing = [k for k in cls._own_params if k not in params]
        if missing:
            raise SaveError(
                f"{path}: its parameters have no {', '.join(map(repr, missing))}: not a "
                f"{cls.__name__}'s save (a SimResult's?): load it with adaptimp.SimResult.load"
            )
        if manifest is not None and manifest.get("inputs") is None:
            _check_row_count(path, arrays, params, record_every)
        names = [*ARRAYS, *EXTRA_ARRAYS]
        res = cls(
            case=case,
            scenario=scenario,
            metrics=metrics,
            params=params,
            record_every=record_every,
            **{name: arrays[name] for name in names if name in arrays},
            **cls._own_fields(arrays),
        )
        _check_metrics(path, res, manifest)
        return res

    _own_params: ClassVar[tuple[str, ...]] = ()
    """The parameters a subclass's results always have (its file is refused
    without them)."""

    def _own_arrays(self) -> dict[str, NDArray[Any]]:
        """A subclass's own recorded arrays (one row per recorded step), by the
        names :meth:`save` stores them under; :meth:`_own_fields` reads them back."""
        return {}

    @classmethod
    def _own_fields(cls, arrays: Mapping[str, NDArray[Any]]) -> dict[str, Any]:
        """The constructor's keywords of a subclass's own arrays (see :meth:`_own_arrays`)."""
        return {}

    def __repr__(self) -> str:
        m = self.metrics
        p = self.params
        t_end = self.rows * self.record_every * p["Ts"]
        rows = (
            f"{self.rows} steps"
            if self.record_every == 1
            else f"{self.rows} rows (every {self.record_every}th step)"
        )
        wall = (
            "free space"
            if p.get("wall") is None
            else f"wall at {p['wall']:g} rad"
            if isinstance(p["wall"], (int, float))
            else f"wall {p['wall']!r}"
        )
        lines = [
            f"SimResult({self.case!r}: {CASE_NAMES.get(self.case, self.case)}, "
            f"scenario {self.scenario!r}; "
            f"{rows}, n = {self.n}, Ts = {p['Ts']:g} s, T = {t_end:g} s; {wall})",
            f"  RMS ‖z1‖ = {m['rms_z1']:.4g} rad, over t ≥ {p.get('settle', 2.0):g} s: "
            f"{m['rms_z1_after2']:.4g} rad "
            f"(per joint {_fmt_list(m['rms_z1_joint_after2'], '.4g')})",
            f"  saturated {100 * m['sat_duty']:.1f}% of steps; "
            f"peak commanded |τ| = {_fmt_list(m['peak_abs_tau'], '.4g')} N m; "
            f"{m['steps_in_contact']} steps in contact",
            "  arrays: " + ", ".join(ARRAYS) + "; .metrics, .params, .plot(kind), .save(path), "
            ".to_pandas()",
        ]
        return "\n".join(lines)


def _metrics_of_rows(res: SimResult) -> dict[str, Any] | None:
    """The metrics the core's accumulator gives for the rows of ``res`` (bit for
    bit those of the run), or None where the rows cannot give them (every k-th
    row kept, rates missing, no rows). Without ``Dd``, ``Cd``, ``Gd`` in the
    parameters (a MuJoCo run) the impedance residual is left out."""
    from . import _adaptimp

    ddq, dxc, ddxc = res.ddq, res.dxc, res.ddxc
    p = res.params
    if res.record_every != 1 or res.rows == 0 or ddq is None or dxc is None or ddxc is None:
        return None
    if not isinstance(p.get("settle"), (int, float)):
        return None
    target = tuple(
        np.broadcast_to(np.asarray(p.get(k, default), dtype=np.float64), (res.n,)).tolist()
        for k, default in (("Dd", 1.0), ("Cd", 10.0), ("Gd", 60.0))
    )
    try:
        again = dict(
            _adaptimp.metrics(
                res.t, res.q, res.dq, ddq, res.xc, dxc, ddxc, res.z1,
                res.tau, res.tau_sat, res.tau_e, float(p["settle"]), target, None,
            )
        )  # fmt: skip
    except ValueError:
        return None
    if not {"Dd", "Cd", "Gd"} <= set(p):
        again.pop("imp_err_rms_after2", None)
    return {k: v for k, v in again.items() if k in res.metrics}


def _check_metrics(
    path: str | os.PathLike[str], res: SimResult, manifest: Mapping[str, Any] | None
) -> None:
    """The stored metrics of a loaded result against the save's record, or its
    rows (see :meth:`SimResult.load`)."""
    recorded = None if manifest is None else manifest.get("metrics")
    if recorded is not None:
        now = {k: _sha_json(v) for k, v in res.metrics.items()}
        changed = [f"{k!r} (now {res.metrics[k]!r})" for k in now if now[k] != recorded.get(k)]
        changed += [f"{k!r} (removed)" for k in recorded if k not in now]
        if changed:
            raise SaveError(
                f"{path}: the file was edited after it was saved: the "
                f"{'metric' if len(changed) == 1 else 'metrics'} {', '.join(changed)} "
                f"{'is' if len(changed) == 1 else 'are'} not what the save recorded (its "
                "SHA-256 differs)"
            )
        return
    again = _metrics_of_rows(res)
    if again is None:
        return
    differ = [k for k in again if not _same_metric(res.metrics[k], again[k])]
    if differ and manifest is not None:
        # Format 2 and 3 saved the metrics of the rows they hold, bit for bit.
        values = "; ".join(
            f"{k} = {res.metrics[k]!r} stored, {again[k]!r} from the rows" for k in differ
        )
        raise SaveError(
            f"{path}: the file was edited after it was saved: its metrics are not those of "
            f"its rows ({values}; format {manifest.get('version')} saved them together)"
        )
    if differ:
        import warnings

        values = "; ".join(
            f"{k} = {res.metrics[k]!r} stored, {again[k]!r} from the rows" for k in differ
        )
        warnings.warn(
            f"{path}: the stored metrics disagree with what its rows give ({values}); "
            "the file records no digest of them (saved with compress=False, or by an "
            "earlier version): the metrics are recomputed from the rows",
            stacklevel=3,
        )
        res.metrics.update({k: again[k] for k in differ})


# ---------------------------------------------------------------------------
# Tables of metrics.
# ---------------------------------------------------------------------------

_ROWS: tuple[tuple[str, str, str], ...] = (
    # (key, label, format); "{after}" is replaced by the settle time.
    ("rms_z1", "RMS ‖z1‖ (rad)", ".5f"),
    ("rms_z1_after2", "RMS ‖z1‖, t ≥ {after} s (rad)", ".5f"),
    ("rms_z1_joint_after2", "RMS z1 per joint, t ≥ {after} s (rad)", ".5f"),
    ("max_abs_z1_joint_after2", "max \\|z1\\| per joint, t ≥ {after} s (rad)", ".5f"),
    ("sat_duty", "saturation duty", ".4f"),
    ("steps_in_contact", "steps in contact", "d"),
    ("peak_contact_after2", "peak τe, t ≥ {after} s (N m)", ".3f"),
    ("mean_contact", "mean τe in contact (N m)", ".3f"),
    ("peak_abs_tau", "peak commanded \\|τ\\| (N m)", ".1f"),
    ("imp_err_rms_after2", "impedance error RMS, t ≥ {after} s (N m)", ".3f"),
    ("rows", "rows", "d"),
)


def _cell(value: Any, spec: str) -> str:
    if isinstance(value, (list, tuple, np.ndarray)):
        return ", ".join(_cell(v, spec) for v in value)
    if isinstance(value, float) and math.isnan(value):
        return "n/a"
    return format(value, spec)


def _label(label: str, results: Sequence[Any]) -> str:
    """``label`` for these runs: a Cartesian run's z1 is the tip's position
    error in task space (x, y, z in m), not a joint's (the table printed
    three "per joint" values in rad for a 5-joint arm)."""
    task = ["rms_pos" in r.metrics for r in results]
    if not any(task) or "z1" not in label:
        return label
    if all(task):
        return label.replace("per joint", "per axis x, y, z").replace("(rad)", "(m)")
    return label.replace("(rad)", "(rad; a Cartesian run's: m, per axis x, y, z)")


def metrics_table(results: Mapping[str, SimResult] | Iterable[SimResult]) -> str:
    """The SPEC §12 metrics of several runs as a Markdown table, one column per run.

    ``results`` is a mapping from column title to result, or results (titled by
    their case).
    """
    if isinstance(results, Mapping):
        cols = list(results.items())
    else:
        cols = [(CASE_NAMES.get(r.case, r.case), r) for r in results]
    after = ", ".join(sorted({f"{r.params['settle']:g}" for _, r in cols}))
    header = ["metric (SPEC §12)"] + [title for title, _ in cols]
    body = [
        [_label(label, [r for _, r in cols]).replace("{after}", after)]
        + [_cell(r.metrics[key], spec) for _, r in cols]
        for key, label, spec in _ROWS
    ]
    widths = [max(len(row[i]) for row in [header, *body]) for i in range(len(header))]

    def line(cells: list[str]) -> str:
        first = cells[0].ljust(widths[0])
        rest = [c.rjust(w) for c, w in zip(cells[1:], widths[1:])]
        return "| " + " | ".join([first, *rest]) + " |"

    rule = "|" + "|".join(["-" * (widths[0] + 2)] + ["-" * (w + 1) + ":" for w in widths[1:]])
    return "\n".join([line(header), rule + "|", *[line(row) for row in body]])


def metrics_json(metrics: Mapping[str, Any]) -> dict[str, Any]:
    """``metrics`` with NaN replaced by None (strict JSON)."""

    def clean(v: Any) -> Any:
        if isinstance(v, float) and math.isnan(v):
            return None
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    return {k: clean(v) for k, v in metrics.items()}
