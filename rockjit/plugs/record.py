"""A recorded ground motion as an excitation plug (:mod:`rockjit.plugs.base`): accelerations in
``g`` at a fixed time step in seconds, linear between samples, the base still after the last.

A record becomes a forcing of the dimensionless model only on a block of a given size: model
time is ``t sqrt(g/R)`` (docs/theory/ground-motions.md, "Recorded motions, scaled to the
block"), so a :class:`Record` carries the block's half-diagonal ``R`` in metres (``size``), or its
frequency parameter ``p = sqrt(3 g / 4 R)`` in rad/s. :mod:`rockjit.ground.records` reads records
from files.

The compiled side, :func:`record_value` and :func:`record_window`, is what the compiled transient
kernel runs, on a grid whose step boundaries hold every sample (the kinks of the linear
interpolation); the Python side (:meth:`Record.scalar`, :meth:`Record.windows`) is what the
scipy reference path runs, written apart from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from .._jit import jit
from ..excitation import ACCEL_MAX
from ..validate import real
from .base import TransientPlug, register

__all__ = ["DT_RANGE", "G", "H_RECORD", "MAX_SAMPLES", "Record", "SIZE_RANGE", "record_value",
           "record_window"]

#: Gravity in m/s^2, as in the model's own scaling (docs/theory/model.md).
G = 9.81
#: Allowed half-diagonals (m): from a figurine to a tower.
SIZE_RANGE = (1e-3, 1e4)
#: Allowed time steps (s).
DT_RANGE = (1e-6, 10.0)
#: Relative spread of the time steps a time column may have and still count as even (a
#: column written with 4 to 6 digits varies by that much).
EVEN_TOL = 1e-4
#: Most samples a record may hold (a day at 1 kHz).
MAX_SAMPLES = 10**8#: The compiled kernel's longest step during a record (model time).
H_RECORD = 0.005


# ---- the compiled side --------------------------------------------------------------------------

@jit(nrt=False, inline=True)
def record_value(t, a, c, off, n):
    """The record at gain ``a`` at model time ``t`` inside it, from its coefficients
    ``c[off:off + n]``: the model time step, then the ``n - 1`` samples; linear between
    samples."""
    s = off + 1
    last = n - 2
    q = t / c[off]
    k = int(q)
    if k >= last:
        return a * c[s + last]
    w = q - k
    y0 = a * c[s + k]
    y1 = a * c[s + k + 1]
    return y0 + w * (y1 - y0)


@jit(nrt=False, inline=True)
def _excess(a, c, j, sg, thr):
    """``sg f - thr`` at sample ``j`` (index ``j`` of ``c``)."""
    return sg * (a * c[j]) - thr


@jit(nrt=False)
def record_window(tq, end, a, c, off, n, thr):
    """The first window ``(t_start, t_end, sign f)`` of the record at gain ``a`` with
    ``t_end > tq``: a run of samples with ``|f| > thr``, its ends on the linear pieces;
    ``sign`` 0 when there is none."""
    dt = c[off]
    s = off + 1
    ns = n - 1
    j = max(0, int(tq / dt) - 1)
    while j < ns:
        sg = 0.0
        if _excess(a, c, s + j, 1.0, thr) > 0.0:
            sg = 1.0
        elif _excess(a, c, s + j, -1.0, thr) > 0.0:
            sg = -1.0
        if sg == 0.0:
            j += 1
            continue
        i = j
        while i > 0 and _excess(a, c, s + i - 1, sg, thr) > 0.0:
            i -= 1
        if i == 0:
            start = 0.0
        else:
            s0, s1 = _excess(a, c, s + i - 1, sg, thr), _excess(a, c, s + i, sg, thr)
            start = (i - 1) * dt + (-s0) / (s1 - s0) * dt
        m = j
        while m + 1 < ns and _excess(a, c, s + m + 1, sg, thr) > 0.0:
            m += 1
        if m == ns - 1:
            stop = (ns - 1) * dt
        else:
            s0, s1 = _excess(a, c, s + m, sg, thr), _excess(a, c, s + m + 1, sg, thr)
            stop = m * dt + s0 / (s0 - s1) * dt
        if stop > tq:
            return start, stop, sg
        j = m + 1
    return 0.0, 0.0, 0.0


# ---- the excitation -----------------------------------------------------------------------------

def _refuse(source, problem):
    raise ValueError(f"record {source}: {problem}")


def _p_of(size):
    return math.sqrt(3.0 * G / (4.0 * size))


@register
@dataclass(frozen=True, eq=False)
class Record(TransientPlug):
    """A recorded ground motion: accelerations in ``g`` at a fixed step ``dt`` in seconds.

    Parameters
    ----------
    accel : array of float
        The horizontal ground acceleration in ``g`` at ``t_k = k dt`` (at least two samples,
        all finite). Positive throws the block onto the corner of ``theta > 0``
        (docs/theory/model.md, "The forcing").
    dt : float
        The time step in seconds, in ``[1e-6, 10]``.
    size : float, optional
        The block's half-diagonal ``R`` in metres, in ``[1e-3, 1e4]``; or give ``p``. Needed
        to play the record in model time (:func:`rockjit.simulate`; :func:`rockjit.fragility`
        binds each of its sizes).
    p : float, optional
        The block's frequency parameter ``sqrt(3 g / 4 R)`` in rad/s, instead of ``size``.
    scale : float
        A factor on every acceleration (``>= 0``), default 1: the scaled record of an
        incremental dynamic analysis.
    name : str
        What the record is called in messages and outputs.

    Examples
    --------
    >>> import numpy as np
    >>> from rockjit import Record
    >>> rec = Record(np.array([0.0, 0.1, -0.2, 0.05, 0.0]), 0.01, size=1.0)
    >>> round(rec.pga, 3), round(rec.end, 4), round(rec.f(0.5 * rec.dt_model), 3)
    (0.2, 0.1253, 0.05)
    """

    accel: np.ndarray
    dt: float
    size: float | None = None
    p: float | None = None
    scale: float = 1.0
    name: str = "record"

    def __post_init__(self):
        name = self.name if isinstance(self.name, str) and self.name else "record"
        object.__setattr__(self, "name", name)
        src = repr(name)
        a = self.accel
        if not isinstance(a, np.ndarray) or a.dtype != np.float64 or a.flags.writeable:
            try:
                a = np.asarray(a)
            except (TypeError, ValueError):
                _refuse(src, "the accelerations are not numbers")
            if a.dtype.kind not in "iuf":
                _refuse(src, f"the accelerations are not numbers (got {a.dtype})")
            a = np.array(a, dtype=float)  # a copy, made read-only below
        if a.ndim != 1:
            _refuse(src, f"the accelerations must be one column (got shape {a.shape})")
        if a.size == 0:
            _refuse(src, "it holds no samples")
        if a.size < 2:
            _refuse(src, "it holds one sample: at least two are needed")
        if a.size > MAX_SAMPLES:
            _refuse(src, f"it holds {a.size} samples, more than {MAX_SAMPLES}")
        bad = ~np.isfinite(a)
        if bad.any():
            k = int(np.argmax(bad))
            _refuse(src, f"sample {k} is not finite ({a[k]})")
        if a.flags.writeable:
            a.flags.writeable = False
        object.__setattr__(self, "accel", a)
        try:
            dt = real("dt", self.dt, *DT_RANGE)
        except ValueError as exc:
            _refuse(src, str(exc))
        object.__setattr__(self, "dt", dt)
        scale = real("scale", self.scale, 0.0, None)
        if scale * float(np.max(np.abs(a))) > ACCEL_MAX:
            raise ValueError(f"record {src}: scale * PGA must be <= {ACCEL_MAX:g} g "
                             f"(got scale = {scale:g})")
        object.__setattr__(self, "scale", scale)
        if self.size is not None and self.p is not None:
            raise ValueError("give the block's size R or its frequency parameter p, not both")
        if self.size is not None:
            size = real("size", self.size, *SIZE_RANGE)
            object.__setattr__(self, "size", size)
            object.__setattr__(self, "p", _p_of(size))
        elif self.p is not None:
            lo, hi = _p_of(SIZE_RANGE[1]), _p_of(SIZE_RANGE[0])
            p = real("p", self.p, lo, hi)
            object.__setattr__(self, "p", p)
            object.__setattr__(self, "size", 3.0 * G / (4.0 * p * p))

    def __reduce__(self):
        # rebuilt through the constructor, so that a copy (Dask, pickle) is validated and
        # read-only again
        return (Record, (self.accel, self.dt, self.size, None, self.scale, self.name))

    @classmethod
    def from_arrays(cls, t, accel, *, size=None, p=None, name="record", source=None):
        """A record from its sample times (s, increasing, evenly spaced; the first is taken as
        0) and accelerations (``g``). ``source`` names the data in messages (a file)."""
        src = source or repr(name)
        t = _numbers(src, t, "time")
        a = _numbers(src, accel, "acceleration")
        if t.shape != a.shape:
            _refuse(src, f"{t.size} times for {a.size} accelerations")
        dt = _even_step(src, t)
        return _named(src, name, lambda: cls(a, dt, size=size, p=p, name=name))

    value = staticmethod(record_value)
    window = staticmethod(record_window)

    # ---- the compiled kernel's side ------------------------------------------------------
    def coefficients(self):
        """The model time step, then the samples."""
        return np.concatenate(([self.dt_model], np.asarray(self.accel, dtype=float)))

    def grid(self, shrink):
        """The fewest equal steps of at most ``H_RECORD`` (times ``shrink``) per sample
        step, so that every sample is a step boundary."""
        return max(1, math.ceil(self.dt_model / (shrink * H_RECORD))), self.dt_model

    def amplitude_at(self, gains):
        """``scale`` times each of ``gains``: the factor on every sample."""
        return self.scale * np.asarray(gains, dtype=float)

    # ---- what every transient excitation says --------------------------------------------

    def bind(self, block=None, *, size=None):
        """This record played on a block of half-diagonal ``size`` (m); without ``size``, the
        record as it is, which must already have one (``block`` has no size: its shape only)."""
        if size is not None:
            return replace(self, size=size, p=None)
        if self.size is None:
            raise ValueError(f"record {self.name!r} needs the block's size to become a "
                             f"forcing: Record(..., size=R in metres) or record.bind(size=R)")
        return self

    def scaled(self, gain):
        """The same record with every acceleration multiplied by ``gain``."""
        return replace(self, scale=self.scale * gain, p=None)

    @property
    def n(self) -> int:
        """Number of samples."""
        return int(self.accel.size)

    @property
    def duration(self) -> float:
        """The record's length in seconds, ``(n - 1) dt``."""
        return (self.n - 1) * self.dt

    @cached_property
    def pga(self) -> float:
        """Peak ground acceleration in ``g``, scale included."""
        return self.scale * float(np.max(np.abs(self.accel)))

    @cached_property
    def pgv(self) -> float:
        """Peak ground velocity in m/s, scale included: the largest ``|v|`` of the exact
        integral of the piecewise-linear acceleration from rest."""
        a = self.accel
        v = np.concatenate(([0.0], np.cumsum(0.5 * (a[1:] + a[:-1])) * self.dt))
        return self.scale * G * float(np.max(np.abs(v)))

    @property
    def peak(self) -> float:
        """The largest ``|f|`` (in ``g``): the PGA."""
        return self.pga

    def _need_size(self):
        if self.size is None:
            self.bind()

    @property
    def time_factor(self) -> float:
        """Model time units per second, ``sqrt(g / R)``."""
        self._need_size()
        return math.sqrt(G / self.size)

    @property
    def dt_model(self) -> float:
        """The time step in model units, ``dt sqrt(g / R)``."""
        return self.dt * self.time_factor

    @property
    def end(self) -> float:
        """Model time of the last sample, after which the base is still."""
        return (self.n - 1) * self.dt_model

    @property
    def breaks(self) -> np.ndarray:
        """Model times of the samples: the acceleration's slope jumps at each."""
        return np.arange(self.n) * self.dt_model

    @property
    def max_step(self) -> float:
        """The longest solver step that steps over no sample: the sample step."""
        return self.dt_model

    def f(self, t):
        """The base acceleration in ``g`` at model time(s) ``t``: linear between samples, zero
        before the first and after the last."""
        t = np.asarray(t, dtype=float)
        out = self.scale * np.interp(t, self.breaks, self.accel, left=0.0, right=0.0)
        out = np.where((t < 0.0) | (t > self.end), 0.0, out)
        return float(out) if out.ndim == 0 else out

    def scalar(self):
        """``f`` as a fast function of one float (the scipy path's right-hand side)."""
        y = (self.scale * self.accel).tolist()
        h = self.dt_model
        last = self.n - 1
        end = self.end

        def f(t):
            if not 0.0 <= t <= end:
                return 0.0
            x = t / h
            k = int(x)
            if k >= last:
                return y[last]
            w = x - k
            return y[k] + w * (y[k + 1] - y[k])
        return f

    def windows(self, threshold):
        """The intervals where ``|f| > threshold``: rows ``(t_start, t_end, sign of f)`` in
        order, each end located exactly on its linear piece."""
        y = self.scale * self.accel
        tk = self.breaks
        rows = []
        for sign in (1.0, -1.0):
            s = sign * y - threshold
            inside = s > 0.0
            if not inside.any():
                continue
            d = np.diff(inside.astype(np.int8))
            up = np.flatnonzero(d == 1)      # s[k] <= 0 < s[k+1]
            down = np.flatnonzero(d == -1)   # s[k] > 0 >= s[k+1]
            starts = tk[up] + (-s[up]) / (s[up + 1] - s[up]) * self.dt_model
            ends = tk[down] + s[down] / (s[down] - s[down + 1]) * self.dt_model
            if inside[0]:
                starts = np.concatenate(([tk[0]], starts))
            if inside[-1]:
                ends = np.concatenate((ends, [tk[-1]]))
            rows.append(np.column_stack((starts, ends, np.full(starts.size, sign))))
        if not rows:
            return np.zeros((0, 3))
        w = np.vstack(rows)
        return w[np.argsort(w[:, 0], kind="stable")]

    def describe(self) -> str:
        """One line: the record, its length and its peak."""
        return (f"{self.name}: {self.n} samples at dt = {self.dt:g} s ({self.duration:g} s), "
                f"PGA {self.pga:.3g} g")

    def __repr__(self):
        size = "" if self.size is None else f", size={self.size:g}"
        scale = "" if self.scale == 1.0 else f", scale={self.scale:g}"
        return f"Record({self.name!r}, n={self.n}, dt={self.dt:g}{size}{scale})"


def _numbers(src, values, what):
    try:
        a = np.asarray(values)
    except (TypeError, ValueError):
        a = None
    if a is None or a.dtype.kind not in "iuf":
        _refuse(src, f"the {what} column is not numbers")
    a = a.astype(float).ravel()
    if a.size == 0:
        _refuse(src, "it holds no samples")
    bad = ~np.isfinite(a)
    if bad.any():
        k = int(np.argmax(bad))
        _refuse(src, f"{what} {k} is not finite ({a[k]})")
    return a


def _even_step(src, t):
    """The step of an increasing, evenly spaced time column."""
    if t.size < 2:
        _refuse(src, "it holds one sample: at least two are needed")
    d = np.diff(t)
    if not np.all(d > 0):
        k = int(np.argmax(~(d > 0)))
        _refuse(src, f"the time does not increase at sample {k + 1} "
                     f"({t[k]:g} s, then {t[k + 1]:g} s)")
    dt = (t[-1] - t[0]) / (t.size - 1)
    spread = np.max(np.abs(d - dt)) / dt
    if spread > EVEN_TOL:
        k = int(np.argmax(np.abs(d - dt)))
        _refuse(src, f"the time step is uneven (step {k + 1} is {d[k]:g} s, the mean "
                     f"{dt:g} s): resample it to an even step first")
    return float(dt)


def _named(src, name, make):
    """``make()``, its refusals naming ``src`` (the file) instead of the record's name."""
    try:
        return make()
    except ValueError as exc:
        msg = str(exc)
        prefix = f"record {name!r}: "
        if msg.startswith(prefix):
            msg = f"record {src}: " + msg[len(prefix):]
        raise ValueError(msg) from None
