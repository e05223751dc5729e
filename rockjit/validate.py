"""One validator per kind of parameter, shared by the API and the command line.

Each function takes the parameter's user-facing ``name`` and its value, and either returns the
value in canonical form or raises ``ValueError`` naming the parameter, the allowed range and the
value got: ``ValueError: periods must be in [1, 1e9] (got 0)``. No value a user can
type reaches numpy, numba or scipy unchecked.

:func:`memory` refuses a computation whose arrays would not fit, before anything is allocated:
``ValueError: periods = 1e12 would need 29.1 TiB; at most 18.3 GiB fits (memory available)``.
"""

from __future__ import annotations

import math
import numbers
import os
import time

import numpy as np

__all__ = ["available_memory", "boolean", "choice", "integer", "memory", "pair", "real",
           "real_array", "size_text"]


def _fmt(v):
    """A number as a user would type it back (integers without a trailing ``.0``)."""
    if isinstance(v, float) and v.is_integer() and abs(v) < 1e16:
        return str(int(v))
    return f"{v:g}" if isinstance(v, float) else str(v)


def _range_text(lo, hi, lo_open, hi_open):
    if hi is None:
        return f"{'>' if lo_open else '>='} {_fmt(lo)}"
    if lo is None:
        return f"{'<' if hi_open else '<='} {_fmt(hi)}"
    return f"in {'(' if lo_open else '['}{_fmt(lo)}, {_fmt(hi)}{')' if hi_open else ']'}"


def _refuse_non_number(name, value, kind):
    """Refuse what is not a number at all: text (the command line parses its own options
    into numbers first), booleans and complex numbers (whose imaginary part would be
    dropped)."""
    if isinstance(value, (bool, np.bool_, str, bytes, complex, np.complexfloating)):
        raise ValueError(f"{name} must be {kind} (got {value!r})")


def real(name, value, lo=None, hi=None, *, lo_open=False, hi_open=False):
    """A finite real number in the given range (``None``: unbounded on that side)."""
    if type(value) is float:  # the common case, checked first (a run's fixed cost)
        v = value
    else:
        _refuse_non_number(name, value, "a real number")
        try:
            v = float(value)
        except (TypeError, ValueError, OverflowError):
            raise ValueError(f"{name} must be a real number (got {value!r})") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite (got {v})")
    bad = (lo is not None and (v < lo or (lo_open and v == lo))) or \
          (hi is not None and (v > hi or (hi_open and v == hi)))
    if bad:
        raise ValueError(f"{name} must be {_range_text(lo, hi, lo_open, hi_open)} "
                         f"(got {_fmt(v)})")
    return v


def integer(name, value, lo=None, hi=None):
    """An integer in ``[lo, hi]``; integral floats (``3.0``) are accepted, ``True`` is not."""
    _refuse_non_number(name, value, "an integer")
    if isinstance(value, numbers.Integral):
        v = int(value)
    else:
        try:
            f = float(value)
        except (TypeError, ValueError, OverflowError):
            raise ValueError(f"{name} must be an integer (got {value!r})") from None
        if not math.isfinite(f) or not f.is_integer():
            raise ValueError(f"{name} must be an integer (got {value!r})")
        v = int(f)
    if (lo is not None and v < lo) or (hi is not None and v > hi):
        raise ValueError(f"{name} must be {_range_text(lo, hi, False, False)} (got {v})")
    return v


def real_array(name, value, what):
    """``value`` as an array of floats: numbers only (no text, booleans or complex numbers
    among them); ``what`` describes the expected shape in the message."""
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        a = None
    if a is None or a.dtype.kind not in "iuf":
        raise ValueError(f"{name} must be {what} (got {value!r})")
    return a.astype(float)


def boolean(name, value):
    """``True`` or ``False`` (numpy's booleans too); anything else, ``'no'`` or ``1`` included,
    is refused rather than read by its truth."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise ValueError(f"{name} must be True or False (got {value!r})")


def choice(name, value, options):
    """One of ``options`` (strings)."""
    if not isinstance(value, str) or value not in options:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, options))} "
                         f"(got {value!r})")
    return value


def pair(name, value, lo=None, hi=None, *, lo_open=False, increasing=True):
    """Two finite numbers ``(a, b)`` in ``[lo, hi]`` with ``a <= b`` (when ``increasing``)."""
    try:
        a, b = value
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be two numbers (got {value!r})") from None
    a = real(f"{name}[0]", a, lo, hi, lo_open=lo_open)
    b = real(f"{name}[1]", b, lo, hi, lo_open=lo_open)
    if increasing and b < a:
        raise ValueError(f"{name} must satisfy start <= end (got {_fmt(a)}, {_fmt(b)})")
    return a, b


# ---- memory -----------------------------------------------------------------------------------

_AVAILABLE = [-math.inf, None]  # (when read, bytes): read at most once a second


def available_memory():
    """Bytes this process may allocate: ``MemAvailable`` (Linux), else physical memory, else
    ``None`` (unknown: no check). Read at most once a second (reading ``/proc/meminfo`` took
    a third of a one-period run's fixed cost)."""
    now = time.monotonic()
    if now - _AVAILABLE[0] > 1.0:
        _AVAILABLE[:] = now, _read_available_memory()
    return _AVAILABLE[1]


def _read_available_memory():
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (AttributeError, ValueError, OSError):
        return None


def size_text(n):
    """``n`` bytes in binary units: ``'29.1 TiB'``."""
    n = float(n)
    for unit in ("B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"):
        if n < 1024 or unit == "EiB":
            return f"{n:.0f} {unit}" if unit == "B" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} EiB"  # pragma: no cover


#: Fraction of the available memory a computation may take.
MEMORY_SHARE = 0.8


def memory(what, nbytes, limit=None):
    """Refuse a computation needing ``nbytes`` (a float, so no overflow) if it cannot fit.

    ``what`` names the cause in the user's terms (``"periods = 1e+12"``). ``limit`` overrides the
    machine's available memory (tests).
    """
    avail = available_memory() if limit is None else limit
    if avail is None:
        return
    cap = MEMORY_SHARE * avail
    if not nbytes <= cap:  # also catches inf and nan
        raise ValueError(f"{what} would need {size_text(nbytes)}; at most {size_text(cap)} fits "
                         f"(memory available)")
