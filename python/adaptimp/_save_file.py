"""A saved result's file (:meth:`adaptimp.SimResult.save`): where it is written
(:func:`_save_path`), written whole or not at all (:func:`_write_atomically`),
opened and read entry by entry with every damage named (:class:`_Reader`), and
the format's versions (:data:`FORMAT`).

Below :mod:`adaptimp._save`, which encodes and checks what it holds."""

from __future__ import annotations

import contextlib
import json
import os
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ._errors import SaveError

if TYPE_CHECKING:
    pass


# ---------------------------------------------------------------------------
# The compressed format (version 2) of SimResult.save: lossless.
# ---------------------------------------------------------------------------

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
