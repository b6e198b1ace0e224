"""The result of a simulation: recorded arrays, SPEC §12 metrics, plots, saving."""

from __future__ import annotations

import contextlib
import json
import math
import os
from collections.abc import Callable, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ._adaptimp import __version__
from ._errors import SaveError, needs_extra
from ._params import CASE_NAMES
from ._plot import FIGURES, PLOT_KINDS, into

if TYPE_CHECKING:
    import pandas as pd
    import xarray as xr
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

FloatArray = NDArray[np.float64]

ARRAYS = ("t", "q", "dq", "xc", "xd", "dq_hat", "tau", "tau_sat", "tau_e", "zeta", "z1", "w_norms")
"""Names of the recorded arrays every result has, in the order of :class:`SimResult`."""

EXTRA_ARRAYS = ("ddq", "dxc", "ddxc", "refused")
"""Recorded arrays of results made by this version (None in older saved files)."""

_META = frozenset({"case", "scenario", "metrics", "params", "record_every", "format"})
"""The entries of a saved file that are not arrays of rows."""

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

METRIC_KEYS = (
    "rms_z1",
    "rms_z1_after2",
    "rms_z1_joint_after2",
    "max_abs_z1_joint_after2",
    "sat_duty",
    "steps_in_contact",
    "peak_contact_after2",
    "mean_contact",
    "peak_abs_tau",
    "imp_err_rms_after2",
)
"""Keys of :attr:`SimResult.metrics` (SPEC §12), besides ``rows``."""

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


# ---------------------------------------------------------------------------
# The compressed format (version 2) of SimResult.save: lossless.
# ---------------------------------------------------------------------------

_U64 = np.dtype("<u8")

FORMAT = 4
"""The format :meth:`SimResult.save` writes: 3 with the record of every array's,
input's and metric's SHA-256 (``arrays``, ``inputs``, ``metrics``), required;
``plain`` for ``compress=False``."""

_VERSIONS = (2, 3, 4)
"""The versions of the ``format`` entry :meth:`SimResult.load` reads (1 has none)."""

_INTRODUCED = {
    3: ("simulated", "n"),
    4: ("result", "arrays", "inputs", "metrics", "plain"),
}
"""What a format's record first held, by the version that introduced it: a file
that declares an earlier version and holds any of it is a later format's file
edited to skip its checks (a genuine format 2 or 3 file never held it; a plain
file before format 4 had no record at all)."""


def _save_path(path: str | os.PathLike[str]) -> Path:
    """Where :meth:`SimResult.save` writes: ``path`` with ``.npz`` appended if it
    has another suffix; a folder (or a path that ends with a separator, as
    ``"runs/"``) is refused, naming it (it wrote ``runs.npz`` beside the folder)."""
    if not isinstance(path, (str, os.PathLike)) or isinstance(path, bytes):
        raise TypeError(f"path must be a file path (str or os.PathLike), got {path!r}")
    text = os.fspath(path)
    given = Path(text)
    if text.endswith((os.sep, "/")) or given.is_dir():
        raise IsADirectoryError(
            f"path {text!r} is a folder: give the file to write, e.g. {str(given / 'run.npz')!r}"
        )
    return given if given.suffix == ".npz" else given.with_name(given.name + ".npz")


def _write_atomically(path: Path, write: Callable[[Any], None]) -> None:
    """``write(file)`` into a new file beside ``path`` (its own name, so that
    saves from several threads or processes never share one), flushed and
    synced to the disk, then renamed over ``path``: ``path`` holds the old file
    or the new one whole, never a part; on any error the new file is removed."""
    import itertools
    import threading

    folder = path.parent
    for attempt in itertools.count():
        temp = folder / (f".{path.name}.{os.getpid()}.{threading.get_ident()}.{attempt}.part")
        try:
            # O_EXCL: never another's file; the mode as any new file's (umask).
            fd = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        break
    try:
        with os.fdopen(fd, "wb") as f:
            write(f)
            f.flush()
            os.fsync(f.fileno())
        os.replace(temp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(temp)
        raise
    # The rename itself on the disk (where the platform can sync a folder).
    with contextlib.suppress(OSError):
        dfd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(dfd)
        finally:
            os.close(dfd)


def _saved_kind(path: str | os.PathLike[str]) -> str | None:
    """The class that saved ``path`` (its format record's ``result``), if it says."""
    try:
        with _open(path) as f:
            record = json.loads(str(f["format"])) if "format" in f else {}
    except Exception:  # any damage is reported by the load itself
        return None
    kind = record.get("result") if isinstance(record, dict) else None
    return kind if isinstance(kind, str) else None


@contextlib.contextmanager
def _open(path: str | os.PathLike[str]) -> Iterator[Any]:
    """The archive of a saved result (closed after), or a SaveError naming the
    file and why it is none (a missing file or a directory stays an OSError)."""
    import zipfile
    import zlib

    if not isinstance(path, (str, os.PathLike)):  # an int was opened as a file descriptor
        raise TypeError(f"path must be a file path (str or os.PathLike), got {path!r:.40}")
    with open(path, "rb") as fh:
        try:
            f = np.load(fh, allow_pickle=False)
        except (zipfile.BadZipFile, EOFError, zlib.error, OSError, ValueError) as e:
            raise SaveError(
                f"{path}: not a result saved by SimResult.save (not a readable .npz archive: "
                f"{type(e).__name__}: {e}); the file may be truncated"
            ) from None
        if not isinstance(f, np.lib.npyio.NpzFile):
            raise SaveError(
                f"{path}: a single NumPy array (.npy), not a result saved by SimResult.save (.npz)"
            )
        with f:
            yield f


class _Reader:
    """The entries of a saved archive, each read with a SaveError naming the file
    and the entry when it is missing, damaged or not what it must be."""

    def __init__(self, path: str | os.PathLike[str], f: Any) -> None:
        self.path, self.f = path, f

    def fail(self, what: str) -> SaveError:
        return SaveError(f"{self.path}: {what}")

    def raw(self, name: str) -> NDArray[Any]:
        import zipfile
        import zlib

        if name not in self.f:
            raise self.fail(
                f"the entry {name!r} is missing: not a result saved by SimResult.save, or truncated"
            )
        try:
            return np.asarray(self.f[name])
        except (zipfile.BadZipFile, EOFError, zlib.error, OSError, ValueError) as e:
            raise self.fail(
                f"the entry {name!r} cannot be read ({type(e).__name__}: {e}): the file is "
                "damaged or truncated"
            ) from None

    def text(self, name: str) -> str:
        a = self.raw(name)
        if a.shape != () or a.dtype.kind != "U":
            raise self.fail(f"the entry {name!r} is not a string (a {a.dtype} array {a.shape})")
        return str(a)

    def json(self, name: str, kind: type) -> Any:
        try:
            value = json.loads(self.text(name))
        except json.JSONDecodeError as e:
            raise self.fail(f"the entry {name!r} is not JSON ({e})") from None
        if not isinstance(value, kind):
            raise self.fail(
                f"the entry {name!r} is not a JSON {'object' if kind is dict else kind.__name__}"
            )
        return value

    def integer(self, name: str) -> int:
        a = self.raw(name)
        if a.shape != () or a.dtype.kind not in "iu" or int(a) < 1:
            raise self.fail(f"the entry {name!r} is not an integer ≥ 1")
        return int(a)

    def array(self, name: str) -> NDArray[Any]:
        a = self.raw(name)
        if a.dtype.kind not in "fbu" or a.ndim == 0:
            raise self.fail(f"the array {name!r} is a {a.dtype} array {a.shape}, not recorded rows")
        return a

    def manifest(self) -> dict[str, Any]:
        """The format record, its structure checked."""
        m: dict[str, Any] = self.json("format", dict)
        version = m.get("version")
        if isinstance(version, bool) or version not in _VERSIONS:
            raise self.fail(
                f"saved in format {version!r}, which this version of adaptimp cannot read "
                "(it reads 1, 2, 3 and 4)"
            )

        def expect(key: str, kind: type, required: bool) -> None:
            if key not in m:
                if required:
                    raise self.fail(
                        f"its format {version} record has no {key!r}: the file was edited "
                        "after it was saved"
                    )
                return
            if not isinstance(m[key], kind):
                raise self.fail(f"its format record's {key!r} is damaged (not a {kind.__name__})")

        for later, keys in _INTRODUCED.items():
            held = [k for k in keys if k in m] if version < later else []
            if held:
                raise self.fail(
                    f"it declares format {version} but holds {', '.join(map(repr, held))} of "
                    f"format {later}'s record: a later file edited after it was saved (its "
                    "checks would be skipped)"
                )
        plain = m.get("plain") is True
        for key, kind in (("derived", list), ("differences", dict)):
            expect(key, kind, not plain)
        expect("simulated", dict, not plain and version >= 3)
        expect("n", int, not plain and version >= 3)
        for key in ("inputs", "metrics", "arrays"):
            expect(key, dict, version >= 4)
        for key in ("derived",):
            if any(not isinstance(x, str) for x in m.get(key, [])):
                raise self.fail(f"its format record's {key!r} is damaged")
        for key in ("differences", "simulated", "arrays"):
            if any(not isinstance(x, dict) for x in m.get(key, {}).values()):
                raise self.fail(f"its format record's {key!r} is damaged")
        for key in ("simulated", "arrays"):
            for spec in m.get(key, {}).values():
                if not (
                    isinstance(spec.get("shape"), list) and isinstance(spec.get("sha256"), str)
                ):
                    raise self.fail(f"its format record's {key!r} is damaged")
        return m


def _array_record(a: NDArray[Any]) -> dict[str, Any]:
    """What a save records of an array: its shape, dtype and the SHA-256 of all three."""
    return {"shape": list(a.shape), "dtype": a.dtype.str, "sha256": _array_digest(a)}


def _array_digest(a: NDArray[Any]) -> str:
    """SHA-256 of an array's dtype, shape and bytes (C order)."""
    import hashlib

    h = hashlib.sha256(f"{a.dtype.str}{list(a.shape)}".encode())
    h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def _check_stored(
    path: str | os.PathLike[str], stored: Mapping[str, NDArray[Any]], manifest: Mapping[str, Any]
) -> None:
    """The stored entries of a compressed file are those its record names, with
    the shapes it gives (before anything is decoded or run)."""
    differences: Mapping[str, Any] = manifest["differences"]
    for name, spec in differences.items():
        if name not in stored:
            raise SaveError(f"{path}: the array {name!r} its record names is missing")
        shape, order = spec.get("shape"), spec.get("order")
        ok = (
            isinstance(shape, list)
            and all(isinstance(d, int) and d >= 0 for d in shape)
            and isinstance(order, int)
            and 0 <= order <= 3
            and stored[name].dtype == np.uint8
            and stored[name].shape == (math.prod(shape[1:]), 8, shape[0] if shape else 0)
        )
        if not ok:
            raise SaveError(
                f"{path}: the array {name!r} is not what its record says ({stored[name].dtype} "
                f"{stored[name].shape}, recorded {spec!r}): the file was edited or damaged"
            )
    derivable = set(_derivations(0, {"Ts": 1.0}, 1))
    for name in manifest["derived"]:
        if name not in derivable:
            raise SaveError(f"{path}: its record derives {name!r}, which no rule gives")
    for name in stored:
        if name in manifest.get("simulated", {}) or name in manifest["derived"]:
            # The record leaves it to the core; a stored copy would replace the
            # checked one unseen.
            raise SaveError(
                f"{path}: {name} is both stored and left to the core to recompute: the file "
                "was edited after it was saved"
            )


def _check_arrays(
    path: str | os.PathLike[str], arrays: Mapping[str, NDArray[Any]], manifest: Mapping[str, Any]
) -> None:
    """Every array against the SHA-256 its save recorded (format 4; earlier files
    do not record them): none missing, none added, none changed."""
    recorded: Mapping[str, Any] | None = manifest.get("arrays")
    if recorded is None:
        return
    missing = sorted(set(recorded) - set(arrays))
    added = sorted(set(arrays) - set(recorded))
    changed = sorted(
        name
        for name in set(recorded) & set(arrays)
        if recorded[name].get("sha256") != _array_digest(arrays[name])
    )
    if missing or added or changed:
        what = [f"{k} {', '.join(map(repr, v))}" for k, v in
                (("changed:", changed), ("missing:", missing), ("added:", added)) if v]  # fmt: skip
        raise SaveError(
            f"{path}: the file was edited or damaged after it was saved: its arrays are "
            f"not what the save recorded (their SHA-256 differs; {'; '.join(what)})"
        )


def _check_shapes(
    path: str | os.PathLike[str],
    arrays: Mapping[str, NDArray[Any]],
    params: Mapping[str, Any],
    metrics: Mapping[str, Any],
) -> None:
    """What any result needs, in a file of any version: every array of
    :data:`ARRAYS` (float64, one row per step, per-joint ones (K, n) alike), the
    metrics and the period."""
    missing = [name for name in ARRAYS if name not in arrays]
    if missing:
        raise SaveError(
            f"{path}: the arrays {', '.join(map(repr, missing))} are missing: not a result "
            "saved by SimResult.save, or truncated"
        )
    rows = arrays["t"].shape[0]
    q = arrays["q"]
    if arrays["t"].ndim != 1 or q.ndim != 2 or q.shape[0] != rows or not 1 <= q.shape[1] <= 7:
        raise SaveError(f"{path}: t {arrays['t'].shape} and q {q.shape} are not rows of one run")
    for name, a in arrays.items():
        if a.shape[:1] != (rows,):
            raise SaveError(f"{path}: the array {name!r} has {a.shape[0]} rows, t has {rows}")
    for name in ("dq", "tau", "tau_sat", "tau_e", "zeta", "dq_hat"):
        if arrays[name].shape != q.shape:
            raise SaveError(f"{path}: {name} has shape {arrays[name].shape}, q {q.shape}")
    absent = [k for k in METRIC_KEYS if k not in metrics]
    if absent:
        raise SaveError(f"{path}: the metrics {', '.join(map(repr, absent))} are missing")
    if not isinstance(params.get("Ts"), (int, float)) or isinstance(params.get("Ts"), bool):
        raise SaveError(f"{path}: the parameters have no period Ts")


def _derivations(
    rows: int, params: Mapping[str, Any], record_every: int
) -> dict[str, Callable[[Mapping[str, NDArray[Any]]], NDArray[Any]]]:
    """Arrays that may be exact functions of others and of the parameters, each by
    IEEE operations that give the same bits on every platform (a product, a
    difference, a clip, a copy). Whether one holds is checked bit for bit."""
    ts = float(params["Ts"])
    tau_max = np.asarray(params.get("tau_max", np.inf), dtype=np.float64)
    return {
        "t": lambda a: (np.arange(rows, dtype=np.int64) * record_every).astype(np.float64) * ts,
        "z1": lambda a: a["xd"] - a["q"],
        "tau_sat": lambda a: np.clip(a["tau"], -tau_max, tau_max),
        "dq_hat": lambda a: a["dq"].copy(),
    }


def _same_bits(a: NDArray[Any], b: NDArray[Any]) -> bool:
    if a.shape != b.shape or a.dtype != b.dtype:
        return False
    if a.dtype == np.float64:
        return bool(np.array_equal(a.view(_U64), b.view(_U64)))
    return bool(np.array_equal(a, b))


def _ordered_bits(a: NDArray[np.float64]) -> NDArray[np.uint64]:
    """float64 bit patterns mapped to unsigned integers in the order of the values
    (sign-magnitude to offset binary), so that close values are close integers."""
    b = np.ascontiguousarray(a, dtype=np.float64).view(_U64).copy()
    negative = (b >> np.uint64(63)).astype(bool)
    b[negative] = ~b[negative]
    b[~negative] |= np.uint64(1 << 63)
    return b


def _from_ordered_bits(b: NDArray[np.uint64]) -> NDArray[np.float64]:
    b = b.copy()
    positive = (b >> np.uint64(63)).astype(bool)
    b[positive] &= np.uint64((1 << 63) - 1)
    b[~positive] = ~b[~positive]
    return b.view(np.float64)


def _differences(a: NDArray[np.float64], order: int) -> NDArray[np.uint8]:
    """``order``-th differences (modulo 2⁶⁴) of the ordered bit patterns along the
    rows, zigzag-coded and split into byte planes: smooth signals leave their high
    bytes zero, which deflate then packs."""
    d = _ordered_bits(a)
    for _ in range(order):
        d = np.diff(d, axis=0, prepend=np.zeros((1, *d.shape[1:]), dtype=_U64))
    s = d.view(np.int64)
    z = ((s << np.int64(1)) ^ (s >> np.int64(63))).view(_U64)
    columns = z.reshape(z.shape[0], -1).T  # (columns, rows)
    return np.ascontiguousarray(
        np.ascontiguousarray(columns)
        .view(np.uint8)
        .reshape(columns.shape[0], -1, 8)
        .transpose(0, 2, 1)
    )


def _undifferences(planes: NDArray[np.uint8], order: int, shape: Sequence[int]) -> FloatArray:
    columns = np.ascontiguousarray(planes.transpose(0, 2, 1)).view(_U64)[..., 0]
    z = np.ascontiguousarray(columns.T).reshape(shape)
    d = (z >> np.uint64(1)) ^ (np.uint64(0) - (z & np.uint64(1)))
    for _ in range(order):
        d = np.cumsum(d, axis=0, dtype=_U64)
    return _from_ordered_bits(d)


def _best_order(a: NDArray[np.float64]) -> int:
    """The difference order (0–3) that deflates a sample of the rows best."""
    import zlib

    sample = a[:20_000]
    sizes = [len(zlib.compress(_differences(sample, k).tobytes(), 1)) for k in range(4)]
    return int(np.argmin(sizes))


def _rerun(
    case: str,
    scenario: str,
    params: Mapping[str, Any],
    n: int,
    record_every: int,
    why: list[str] | None = None,
) -> dict[str, NDArray[Any]] | None:
    """The arrays of :func:`adaptimp.simulate` run again from the recorded case,
    scenario and parameters alone (the default arm for n, the vertex grid or the
    rule's centres, zero initial weights, no fault), keeping every
    ``record_every``-th step; None where those do not describe a run the core
    can repeat (another arm, user centres, an unknown parameter), the reason
    appended to ``why``."""
    import warnings

    from . import _adaptimp
    from ._arms import PlanarArm, TwoLinkArm
    from ._params import BY_NAME, N_JOINTS, _core_controller, names

    try:
        p = {k: v for k, v in params.items() if k in BY_NAME}
        if n == N_JOINTS and "arm" not in params:
            arm: TwoLinkArm | PlanarArm = TwoLinkArm(**{k: p[k] for k in names("arm")})
        else:
            arm = PlanarArm(n)
            if params.get("arm") != arm.params:
                if why is not None:
                    why.append("its arm is not the default arm of its n")
                return None
        if "nodes" in params:  # user centres (not recorded)
            if why is not None:
                why.append("it used centres of the user's (not recorded)")
            return None
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            core = _core_controller(case, p, n, None, None)
            out = _adaptimp.simulate(core, arm._core, p, record_every, None, None, None)
    except (TypeError, ValueError, KeyError, ArithmeticError) as e:
        if why is not None:
            why.append(f"{type(e).__name__}: {e}")
        return None  # not a run the core can repeat from what was recorded
    out.pop("metrics")
    return {k: v for k, v in out.items() if isinstance(v, np.ndarray)}


def _digest(a: NDArray[Any]) -> str:
    import hashlib

    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


def _resimulated(
    path: str | os.PathLike[str],
    case: str,
    scenario: str,
    params: Mapping[str, Any],
    record_every: int,
    manifest: Mapping[str, Any],
) -> dict[str, NDArray[Any]]:
    """The arrays a format-3 file left to the core, run again and checked against
    the SHA-256 the save recorded."""
    simulated: Mapping[str, Any] = manifest["simulated"]
    why: list[str] = []
    rerun = _rerun(case, scenario, params, int(manifest["n"]), record_every, why)
    saved_by = manifest.get("adaptimp")
    version = (
        f"saved by adaptimp {saved_by}, which this is"
        if saved_by == __version__
        else f"saved by adaptimp {saved_by}, this is {__version__}"
    )
    out: dict[str, NDArray[Any]] = {}
    for name, spec in simulated.items():
        if rerun is None:
            raise SaveError(
                f"{path}: {name} was left to the simulation to recompute, but the file's "
                f"case {case!r}, scenario {scenario!r} and parameters do not describe a run "
                f"the core can repeat ({'; '.join(why)}); {version}"
            )
        a = rerun.get(name)
        if a is None or list(a.shape) != spec["shape"]:
            got = "no such array" if a is None else f"shape {list(a.shape)}"
            raise SaveError(
                f"{path}: {name} was left to the simulation to recompute with shape "
                f"{spec['shape']}, but running the file's case {case!r}, scenario "
                f"{scenario!r} and parameters again gives {got}; {version}"
            )
        if _digest(a) != spec["sha256"]:
            cause = (
                "the file's case, scenario or parameters were edited after it was saved, "
                "or this platform's floating point differs from the one that saved it"
                if saved_by == __version__
                else "the file's case, scenario or parameters were edited after it was "
                "saved, or another version of the core or another platform's floating point "
                "gives other bits: load it with the version that saved it, and save it "
                "there with recompute=False for a file that any version reads"
            )
            raise SaveError(
                f"{path}: {name} was left to the simulation to recompute, but running the "
                f"file's case {case!r}, scenario {scenario!r} and parameters again does not "
                f"give the same bits (SHA-256 {_digest(a)[:12]}…, the save recorded "
                f"{spec['sha256'][:12]}…; {version}): {cause}"
            )
        out[name] = a
    return out


def _same_metric(a: Any, b: Any) -> bool:
    """Equal, NaN equal to NaN, element by element for lists."""
    if isinstance(a, list) or isinstance(b, list):
        return (
            isinstance(a, list)
            and isinstance(b, list)
            and len(a) == len(b)
            and all(_same_metric(x, y) for x, y in zip(a, b))
        )
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return bool(a == b)


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


def _sha_json(value: Any) -> str:
    """SHA-256 of ``value``'s JSON (keys sorted)."""
    import hashlib

    return hashlib.sha256(json.dumps(value, sort_keys=True).encode()).hexdigest()


def _input_digests(
    case: str, scenario: str, params: Mapping[str, Any], record_every: int
) -> dict[str, Any]:
    """SHA-256 of what a saved file's arrays and metrics are a function of: the
    case, the scenario, the rows kept and each parameter (its JSON, keys sorted)."""
    sha = _sha_json
    return {
        "case": sha(case),
        "scenario": sha(scenario),
        "record_every": sha(record_every),
        "params": {name: sha(value) for name, value in params.items()},
    }


def _check_rows(
    path: str | os.PathLike[str],
    params: Mapping[str, Any],
    record_every: int,
    manifest: Mapping[str, Any],
) -> None:
    """The rows a file's parameters give (round(T/Ts) steps, every
    ``record_every``-th kept) are the rows it records: checked before its
    simulation is run again, in a file without the digest of its inputs (an
    edited T ran for as long as it said)."""
    simulated: Mapping[str, Any] = manifest.get("simulated") or {}
    shapes = [spec["shape"] for spec in simulated.values()]
    if not shapes:
        return
    T, Ts = params.get("T"), params.get("Ts")
    rows = shapes[0][0] if shapes[0] else -1
    try:
        steps = round(float(T) / float(Ts))  # type: ignore[arg-type]
        expected = -(-steps // int(record_every))
    except (TypeError, ValueError, ZeroDivisionError, OverflowError):
        expected = None
    if expected != rows or any(not s or s[0] != rows for s in shapes):
        raise SaveError(
            f"{path}: the file's parameters (T = {T!r}, Ts = {Ts!r}, one row in "
            f"{record_every}) do not give the {rows} rows it records: it was edited "
            "after it was saved (its simulation is not run again)"
        )


def _check_row_count(
    path: str | os.PathLike[str],
    arrays: Mapping[str, NDArray[Any]],
    params: Mapping[str, Any],
    record_every: int,
) -> None:
    """A file without the digests of its inputs (format 2 or 3) records the rows
    its parameters give: round(T/Ts) steps, every ``record_every``-th kept."""
    T, Ts = params.get("T"), params.get("Ts")
    rows = int(arrays["t"].shape[0])
    try:
        steps = round(float(T) / float(Ts))  # type: ignore[arg-type]
        expected = -(-steps // int(record_every))
    except (TypeError, ValueError, ZeroDivisionError, OverflowError):
        return  # a file without T: nothing to compare
    if expected != rows:
        raise SaveError(
            f"{path}: the file's parameters (T = {T!r}, Ts = {Ts!r}, one row in "
            f"{record_every}) give {expected} rows, and it records {rows}: it was edited "
            "after it was saved"
        )


def _check_inputs(
    path: str | os.PathLike[str],
    case: str,
    scenario: str,
    params: Mapping[str, Any],
    record_every: int,
    manifest: Mapping[str, Any],
) -> None:
    """Refuse a file whose case, scenario or parameters are not those its save
    recorded (the file edited after it was saved), naming each that differs."""
    recorded = manifest.get("inputs")
    if recorded is None:  # saved (in format 2 or 3) before the inputs were recorded
        _check_rows(path, params, record_every, manifest)
        return
    if not isinstance(recorded.get("params"), dict):
        raise SaveError(f"{path}: its format record's 'inputs' is damaged")
    now = _input_digests(case, scenario, params, record_every)
    given = {"case": case, "scenario": scenario, "record_every": record_every}
    changed = [f"the {k} ({v!r})" for k, v in given.items() if now[k] != recorded.get(k)]
    saved, found = recorded.get("params", {}), now["params"]
    changed += [
        f"the parameter {k!r} (now {params[k]!r})"
        for k in found
        if k in saved and found[k] != saved[k]
    ]
    changed += [f"the parameter {k!r} (added)" for k in found if k not in saved]
    changed += [f"the parameter {k!r} (removed)" for k in saved if k not in found]
    if changed:
        raise SaveError(
            f"{path}: the file was edited after it was saved: {', '.join(changed)} "
            f"{'is' if len(changed) == 1 else 'are'} not what the save recorded (its SHA-256 "
            "differs), so its arrays and metrics are not those of a run with it"
        )


def _encode(
    arrays: Mapping[str, NDArray[Any]],
    params: Mapping[str, Any],
    record_every: int,
    rerun: Mapping[str, NDArray[Any]] | None = None,
) -> tuple[dict[str, NDArray[Any]], dict[str, Any]]:
    stored: dict[str, NDArray[Any]] = {}
    manifest: dict[str, Any] = {
        "derived": [],
        "differences": {},
        "simulated": {},
        "n": int(arrays["q"].shape[1]),
        "adaptimp": __version__,
    }
    derive = _derivations(arrays["t"].shape[0], params, record_every)
    for name, a in arrays.items():
        again = None if rerun is None else rerun.get(name)
        if again is not None and _same_bits(again, a):
            manifest["simulated"][name] = {"shape": list(a.shape), "sha256": _digest(a)}
            continue
        rule = derive.get(name)
        if rule is not None and a.dtype == np.float64:
            try:
                exact = _same_bits(rule(arrays), a)
            except (KeyError, ValueError):  # missing inputs or shapes that do not fit
                exact = False
            if exact:
                manifest["derived"].append(name)
                continue
        if a.dtype == np.float64 and a.ndim >= 1 and a.shape[0] > 0:
            order = _best_order(a)
            stored[name] = _differences(a, order)
            manifest["differences"][name] = {"order": order, "shape": list(a.shape)}
        else:
            stored[name] = a
    return stored, manifest


def _decode(
    path: str | os.PathLike[str],
    stored: Mapping[str, NDArray[Any]],
    manifest: Mapping[str, Any],
    params: Mapping[str, Any],
    record_every: int,
    simulated: Mapping[str, NDArray[Any]],
) -> dict[str, NDArray[Any]]:
    arrays: dict[str, NDArray[Any]] = dict(simulated)
    for name, a in stored.items():
        if name in manifest["differences"]:
            spec = manifest["differences"][name]
            arrays[name] = _undifferences(a, spec["order"], spec["shape"])
        else:
            arrays[name] = a
    # Each rule reads only arrays that are stored or simulated (q, xd, tau, dq),
    # never derived.
    if "q" not in arrays:
        raise SaveError(f"{path}: the array 'q' is missing (neither stored nor recomputed)")
    derive = _derivations(arrays["q"].shape[0], params, record_every)
    name = ""
    try:
        for name in manifest["derived"]:
            arrays[name] = derive[name](arrays)
    except (KeyError, ValueError) as e:
        raise SaveError(
            f"{path}: {name} cannot be derived from the arrays stored ({type(e).__name__}: "
            f"{e}): the file was edited or damaged"
        ) from None
    return arrays


def _fmt_list(values: Iterable[float], spec: str) -> str:
    return "[" + ", ".join(format(v, spec) for v in values) + "]"


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
