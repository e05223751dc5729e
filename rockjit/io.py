"""Atomic writers: an interrupted run leaves nothing half-written (STYLE.md 11).

Every writer here writes a hidden temporary file next to its target
(``.<name>.<random>.tmp``, same directory so the rename stays on one file system), flushes and
``fsync``s it, then moves it over the target with :func:`os.replace`, which is atomic on POSIX
and Windows. If anything goes wrong before the rename, including ``KeyboardInterrupt``, the
temporary file is removed and the target is left as it was (absent, or its previous complete
version).

JSON conventions (:func:`write_json`, :func:`to_jsonable`):

- numpy scalars become Python numbers, numpy arrays nested lists, tuples lists, paths strings;
- non-finite floats, which strict JSON cannot hold, are written as the **strings**
  ``"nan"``, ``"inf"`` and ``"-inf"``, everywhere (also inside arrays). ``float(value)`` reads
  both forms back, so a reader can always do ``float(summary["lambda_max"])``. (``-inf`` is
  meaningful here: the Lyapunov exponent of a block at rest.)
"""

from __future__ import annotations

import contextlib
import csv
import dataclasses
import io as _io
import json
import math
import os
import tempfile
from pathlib import Path

import numpy as np

__all__ = ["atomic_open", "save_figure", "to_jsonable", "write_csv", "write_json",
           "write_npz", "write_text"]

TMP_SUFFIX = ".tmp"


@contextlib.contextmanager
def atomic_open(path, mode="w", **kwargs):
    """Open a temporary file beside ``path``; on a clean exit, rename it to ``path``.

    Parameters
    ----------
    path : str or Path
        The target. Its directory must exist.
    mode : {"w", "wb"}
        Text or binary.
    **kwargs
        Passed to :func:`open` (e.g. ``newline=""`` for CSV, ``encoding``).

    Yields
    ------
    file
        The open temporary file.
    """
    path = Path(path)
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' or 'wb' (got {mode!r})")
    if "b" not in mode:
        kwargs.setdefault("encoding", "utf-8")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=TMP_SUFFIX,
                               dir=path.parent if str(path.parent) else ".")
    try:
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def _float(x):
    x = float(x)
    if math.isfinite(x):
        return x
    return "nan" if math.isnan(x) else ("inf" if x > 0 else "-inf")


def to_jsonable(obj):
    """``obj`` with numpy types, tuples, paths and non-finite floats made JSON-safe.

    See the module docstring for the conventions.
    """
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return _float(obj)
    if isinstance(obj, (str, type(None))):
        return obj
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        return to_jsonable(dataclasses.asdict(obj))
    raise TypeError(f"cannot write {type(obj).__name__} to JSON")


def write_json(path, obj, *, indent=2):
    """Write ``obj`` as strict JSON (``allow_nan=False``), atomically."""
    text = json.dumps(to_jsonable(obj), indent=indent, allow_nan=False) + "\n"
    write_text(path, text)


def write_text(path, text):
    """Write a string, atomically."""
    with atomic_open(path, "w") as fh:
        fh.write(text)


def write_npz(path, **arrays):
    """Write arrays to an uncompressed ``.npz`` archive, atomically.

    Arrays are stored without pickling (string arrays as numpy unicode), so
    ``np.load(path)`` reads them with the default ``allow_pickle=False``.
    """
    buf = {k: np.asarray(v) for k, v in arrays.items()}
    for k, v in buf.items():
        if v.dtype == object:
            raise TypeError(f"array {k!r} has dtype object; store plain numbers or strings")
    with atomic_open(path, "wb") as fh:
        np.savez(fh, **buf)


def write_csv(path, header, rows):
    """Write a CSV table (``header``: column names; ``rows``: sequences), atomically.

    Floats are written with ``repr`` precision; non-finite ones as ``nan``, ``inf``, ``-inf``.
    """
    with atomic_open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(list(header))
        for row in rows:
            w.writerow([_cell(v) for v in row])


def _cell(v):
    if isinstance(v, (float, np.floating)):
        v = float(v)
        return repr(v) if math.isfinite(v) else _float(v)
    if isinstance(v, np.integer):
        return int(v)
    return v


def save_figure(fig, path, *, dpi=150):
    """Save a matplotlib figure, atomically; the format follows ``path``'s suffix."""
    path = Path(path)
    fmt = path.suffix.lstrip(".").lower() or "png"
    buf = _io.BytesIO()  # render fully first: a failing render never opens the target
    fig.savefig(buf, format=fmt, dpi=dpi)
    with atomic_open(path, "wb") as fh:
        fh.write(buf.getvalue())
