"""The command line's lines on stderr: progress and notes (silenced by ``--quiet``),
warnings, bad input (one line, exit status 2) and an error while running (one line, the
traceback in a report file, exit status 1)."""

from __future__ import annotations

import contextlib
import os
import sys

PROG = "rockjit"


def say(args, msg):  # progress and notes: silenced by --quiet
    if not args.quiet:
        print(f"{PROG}: {msg}", file=sys.stderr, flush=True)


def warn(msg):
    print(f"{PROG}: warning: {' '.join(str(msg).split())}", file=sys.stderr, flush=True)


def error(msg):
    msg = " ".join(str(msg).split())  # always one line
    print(f"{PROG}: error: {msg}", file=sys.stderr, flush=True)
    return 2


def internal_error(exc, prefix=""):
    """An error while running (a full disk, a file system refusing a write, a lost Dask
    scheduler, a bug): one line on stderr (after ``prefix``), the traceback in a report file
    (``rockjit-error-*.txt`` in the temporary directory), exit status 1. Never raises: if the
    report cannot be written either, the line says why."""
    import tempfile
    import traceback
    path = None
    try:
        fd, path = tempfile.mkstemp(prefix=f"{PROG}-error-", suffix=".txt")
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            traceback.print_exception(type(exc), exc, exc.__traceback__, file=f)
        report = f"the traceback is in {path}"
    except Exception as e:  # its disk may be full too
        if path is not None:
            with contextlib.suppress(OSError):
                os.unlink(path)
        report = f"no report could be written ({type(e).__name__}: {' '.join(str(e).split())})"
    if prefix:
        line = (f"{PROG}: error: {prefix}{type(exc).__name__}: {' '.join(str(exc).split())}; "
                f"--out is as it was; {report}")
    elif isinstance(exc, OSError) and exc.strerror:
        where = f": {exc.filename}" if exc.filename else ""
        line = f"{PROG}: error: {exc.strerror}{where}; --out is as it was; {report}"
    else:
        line = (f"{PROG}: internal error: {type(exc).__name__}: {' '.join(str(exc).split())}; "
                f"--out is as it was; {report} (please report it)")
    with contextlib.suppress(Exception):
        print(" ".join(line.split()), file=sys.stderr, flush=True)
    return 1


def from_dask(exc):
    """Whether ``exc`` is a connection's failure (``OSError``, ``TimeoutError``) raised inside
    dask.distributed."""
    if not isinstance(exc, (OSError, TimeoutError)):
        return False
    tb = exc.__traceback__
    while tb is not None:
        if f"{os.sep}distributed{os.sep}" in tb.tb_frame.f_code.co_filename:
            return True
        tb = tb.tb_next
    return False
