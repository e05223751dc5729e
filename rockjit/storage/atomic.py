"""Atomic writes: a file appears complete or not at all, with the permissions a plain ``open``
would give.

Every writer here writes a hidden temporary file next to its target
(``.<name>.<random>.tmp``, same directory so the rename stays on one file system), flushes and
``fsync``s it, then moves it over the target with :func:`os.replace`, which is atomic on POSIX
and Windows. If anything goes wrong before the rename, including ``KeyboardInterrupt``, the
temporary file is removed and the target is left as it was (absent, or its previous complete
version).

Permissions: files are created with mode ``0o666`` and directories with ``0o777``, and the
operating system applies the process's umask (and a directory's default ACL, where there is
one), so everything rockjit writes gets the permissions a plain ``open()`` or ``mkdir`` would
give: ``-rw-r--r--`` and ``drwxr-xr-x`` under umask ``022``. (:func:`tempfile.mkstemp` and
:func:`tempfile.mkdtemp` would leave ``-rw-------`` and ``drwx------``.)

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
import errno
import io as _io
import json
import math
import os
import secrets
from pathlib import Path

import numpy as np

__all__ = ["TMP_SUFFIX", "atomic_open", "create_temp", "markdown_table", "save_figure",
           "to_jsonable", "write_csv", "write_json", "write_npz", "write_text"]

TMP_SUFFIX = ".tmp"
_O_CLOEXEC = getattr(os, "O_CLOEXEC", 0)


def create_temp(directory, prefix, suffix=TMP_SUFFIX):
    """Create a new empty file ``<directory>/<prefix><random><suffix>`` for writing.

    The file is created with mode ``0o666`` less the umask, as :func:`open` would create it.

    Returns
    -------
    fd : int
        An open file descriptor, write-only.
    path : Path
        The file's path.
    """
    directory = Path(directory) if str(directory) else Path(".")
    for _ in range(100):
        path = directory / f"{prefix}{secrets.token_hex(4)}{suffix}"
        try:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _O_CLOEXEC, 0o666)
        except FileExistsError:
            continue
        return fd, path
    raise FileExistsError(errno.EEXIST, "no unused temporary file name", str(directory))


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
        The open temporary file (permissions: ``0o666`` less the umask).
    """
    path = Path(path)
    if mode not in ("w", "wb"):
        raise ValueError(f"mode must be 'w' or 'wb' (got {mode!r})")
    if "b" not in mode:
        kwargs.setdefault("encoding", "utf-8")
    fd, tmp = create_temp(path.parent, f".{path.name}.")
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


def markdown_table(header, rows, fmt=None):
    """A Markdown table; floats formatted with ``fmt[column]`` (default ``".4g"``)."""
    fmt = fmt or {}

    def cell(i, v):
        if isinstance(v, (float, np.floating)):
            return format(float(v), fmt.get(header[i], ".4g"))
        return str(v)

    lines = ["| " + " | ".join(header) + " |",
             "|" + "|".join("---" for _ in header) + "|"]
    lines += ["| " + " | ".join(cell(i, v) for i, v in enumerate(r)) + " |" for r in rows]
    return "\n".join(lines) + "\n"
