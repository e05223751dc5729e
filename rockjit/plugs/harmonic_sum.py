"""A sum of harmonics: ``f(t) = sum_k a_k sin(omega_k t + phi_k)`` over a given duration.

A common test signal for rocking blocks (a few tones at once, e.g. a shake-table sweep's
components), written as one excitation plug (:mod:`rockjit.plugs.base`). The compiled side,
:func:`sum_value` and :func:`sum_window` (over :func:`harmonics_value` and
:func:`harmonics_window`, at unit gain), is what the compiled transient kernel runs; the Python
side (:meth:`HarmonicSum.f`, :meth:`HarmonicSum.windows`) is what the scipy reference path runs,
written apart from it: the windows by a dense scan of ``|f|`` and Brent's method, the compiled ones
by a scan whose steps the largest slope ``sum_k |a_k omega_k|`` bounds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._jit import jit
from ..excitation import ACCEL_MAX, OMEGA_RANGE
from ..validate import real, real_array
from .base import TransientPlug, register

__all__ = ["DURATION_MAX", "HarmonicSum", "MAX_TONES", "harmonics_value", "harmonics_window",
           "sum_value", "sum_window"]

#: At most this many tones.
MAX_TONES = 64
#: The longest duration (model time).
DURATION_MAX = 1e6
#: How far the compiled scan steps at least, as a fraction of the shortest tone's period: a
#: window narrower than that, where ``|f|`` barely passes the threshold, may go unseen.
SCAN_FLOOR = 1e-9
#: Bisection steps that locate a window's ends (to rounding on any duration).
ROOT_STEPS = 80
_EPS = float(np.finfo(float).eps)


@jit(nrt=False)
def harmonics_value(t, rec, off, n):
    """``sum_k a_k sin(omega_k t + phi_k)``, the tones ``(a_k, omega_k, phi_k)`` in
    ``rec[off:off + n]`` in threes."""
    f = 0.0
    for k in range(off, off + n, 3):
        f += rec[k] * math.sin(rec[k + 1] * t + rec[k + 2])
    return f


@jit(nrt=False)
def _slope_bound(rec, off, n):
    """``sum_k |a_k omega_k|``, a bound on ``|f'|``; and the shortest tone's period."""
    lip = 0.0
    w_max = 0.0
    for k in range(off, off + n, 3):
        lip += abs(rec[k] * rec[k + 1])
        w_max = max(w_max, abs(rec[k + 1]))
    return lip, 2.0 * math.pi / max(w_max, 1e-300)


@jit(nrt=False)
def _edge(lo, hi, sg, rec, off, n, thr):
    """Where ``sg f - thr`` changes sign between ``lo`` and ``hi`` (either order), by
    bisection to rounding: the end of the last bracket where it is not above 0 (so that
    a window's ends lie just outside it)."""
    g_lo = sg * harmonics_value(lo, rec, off, n) - thr
    for _ in range(ROOT_STEPS):
        mid = 0.5 * (lo + hi)
        if mid == lo or mid == hi:
            break
        g = sg * harmonics_value(mid, rec, off, n) - thr
        if (g > 0.0) == (g_lo > 0.0):
            lo, g_lo = mid, g
        else:
            hi = mid
    return hi if g_lo > 0.0 else lo


@jit(nrt=False)
def _window_at(t, end, rec, off, n, thr, lip, floor):
    """The window that ``t`` lies in or the next one after it: ``(t0, t1, sign)``."""
    f = harmonics_value(t, rec, off, n)
    if abs(f) > thr:  # inside a window: back to its start
        sg = 1.0 if f > 0.0 else -1.0
        s = t
        while s > 0.0:
            prev = s
            s = max(0.0, s - max((sg * harmonics_value(s, rec, off, n) - thr) / lip, floor))
            if not sg * harmonics_value(s, rec, off, n) > thr:
                s = _edge(prev, s, sg, rec, off, n, thr)
                break
        t0 = s
    else:
        while True:  # to the next window's start
            prev = t
            t = t + max((thr - abs(f)) / lip, floor)
            if t > end:
                return 0.0, 0.0, 0.0
            f = harmonics_value(t, rec, off, n)
            if abs(f) > thr:
                break
        sg = 1.0 if f > 0.0 else -1.0
        t0 = _edge(t, prev, sg, rec, off, n, thr)
    while True:  # to the window's end
        prev = t
        t = t + max((sg * f - thr) / lip, floor)
        if t >= end:
            return t0, end, sg
        f = harmonics_value(t, rec, off, n)
        if not sg * f > thr:
            return t0, _edge(prev, t, sg, rec, off, n, thr), sg


@jit(nrt=False)
def harmonics_window(tq, end, rec, off, n, thr):
    """The first interval ``(t0, t1, sign)`` of ``[0, end]`` with ``t1 > tq`` where
    ``|f| > thr`` (``sign`` 0 if none). From ``tq`` (or the start of the window it lies in)
    the scan steps by ``(thr - |f|) / L`` outside a window and ``(|f| - thr) / L`` inside,
    ``L`` the slope bound, so it never steps over a crossing (but by the floor
    ``SCAN_FLOOR`` of the shortest period); the crossings are then bisected."""
    lip, period = _slope_bound(rec, off, n)
    floor = SCAN_FLOOR * period
    t = max(tq, 0.0)
    while t <= end and lip > 0.0:
        t0, t1, sg = _window_at(t, end, rec, off, n, thr, lip, floor)
        if sg == 0.0 or t1 > tq:
            return t0, t1, sg
        t = t1 + floor  # a window that ends at tq, to rounding: the next one
    return 0.0, 0.0, 0.0


@jit(nrt=False)
def sum_value(t, a, rec, off, n):
    """The plug's value: ``a`` times ``harmonics_value`` (this module's sum of sines)."""
    return a * harmonics_value(t, rec, off, n)


@jit(nrt=False)
def sum_window(tq, end, a, rec, off, n, thr):
    """The plug's window: ``harmonics_window`` (this module's scan) of the tones at unit gain,
    above ``thr / a``; none for ``a <= 0``."""
    if not a > 0.0:
        return 0.0, 0.0, 0.0
    return harmonics_window(tq, end, rec, off, n, thr / a)


@register
@dataclass(frozen=True)
class HarmonicSum(TransientPlug):
    """A sum of harmonics ``f(t) = sum_k a_k sin(omega_k t + phi_k)`` on ``0 <= t <= duration``
    (the base still after it), in units of ``g``.

    Parameters
    ----------
    amplitudes : sequence of float
        ``a_k`` in ``g``, each in ``[-1e8, 1e8]``, at most 64 tones, ``sum |a_k| <= 1e8``.
    frequencies : sequence of float
        ``omega_k`` in the model's units (radians per unit of ``sqrt(R/g)``), each in
        ``[1e-4, 1e4]``.
    duration : float
        How long the base moves, in ``(0, 1e6]`` model time units.
    phases : sequence of float, optional
        ``phi_k`` in radians; default 0 (the base starts still and accelerates smoothly).
    gain : float, optional
        A factor on every tone, in ``[0, 1e8]``; default 1 (what a grid's gain multiplies).

    Examples
    --------
    >>> import rockjit
    >>> two = rockjit.HarmonicSum(amplitudes=(0.6, 0.3), frequencies=(2.0, 5.0), duration=20.0)
    >>> round(two.f(0.5), 6)
    0.684424
    >>> r = rockjit.simulate(rockjit.Block(hb=2), two)
    >>> rockjit.ground.OUTCOMES[r.outcome], r.n_impacts
    ('safe', 48)
    """

    amplitudes: tuple = (1.0,)
    frequencies: tuple = (1.0,)
    duration: float = 10.0
    phases: tuple | None = None
    gain: float = 1.0

    def __post_init__(self):
        a = real_array("amplitudes", self.amplitudes, "a sequence of amplitudes in g")
        w = real_array("frequencies", self.frequencies, "a sequence of frequencies")
        n = a.size
        if a.ndim != 1 or not 1 <= n <= MAX_TONES:
            raise ValueError(f"amplitudes must be 1 to {MAX_TONES} numbers (got {n})")
        if w.shape != a.shape:
            raise ValueError(f"frequencies must be as many as the amplitudes, {n} "
                             f"(got {w.size})")
        for k in range(n):
            real(f"amplitudes[{k}]", float(a[k]), -ACCEL_MAX, ACCEL_MAX)
            real(f"frequencies[{k}]", float(w[k]), *OMEGA_RANGE)
        if np.abs(a).sum() > ACCEL_MAX:
            raise ValueError(f"the amplitudes' sum of magnitudes must be <= {ACCEL_MAX:g} g "
                             f"(got {np.abs(a).sum():g})")
        phi = np.zeros(n) if self.phases is None else real_array(
            "phases", self.phases, "a sequence of phases in radians")
        if phi.shape != a.shape:
            raise ValueError(f"phases must be as many as the amplitudes, {n} (got {phi.size})")
        for k in range(n):
            real(f"phases[{k}]", float(phi[k]), -1e6, 1e6)
        set_ = object.__setattr__
        set_(self, "amplitudes", tuple(float(v) for v in a))
        set_(self, "frequencies", tuple(float(v) for v in w))
        set_(self, "phases", tuple(float(v) for v in phi))
        set_(self, "duration", real("duration", self.duration, 0.0, DURATION_MAX, lo_open=True))
        set_(self, "gain", real("gain", self.gain, 0.0, ACCEL_MAX))

    value = staticmethod(sum_value)
    window = staticmethod(sum_window)

    # ---- the compiled kernel's side ------------------------------------------------------
    def coefficients(self):
        """The tones ``(a_k, omega_k, phi_k)``, one after the other."""
        return np.array([v for k in range(len(self.amplitudes)) for v in
                         (self.amplitudes[k], self.frequencies[k], self.phases[k])], dtype=float)

    def grid(self, shrink):
        """Equal steps of a 32nd of the shortest tone's period, at most (and at least 8)."""
        h = 2.0 * math.pi / max(self.frequencies) / 32.0 * shrink
        return max(8, math.ceil(self.duration / h)), 0.0

    def amplitude_at(self, gains):
        """``gain`` times each of ``gains``: the factor on every tone."""
        return self.gain * np.asarray(gains, dtype=float)

    # ---- every transient excitation's side -----------------------------------------------
    @property
    def end(self) -> float:
        """Model time after which the base is still."""
        return self.duration

    @property
    def breaks(self) -> np.ndarray:
        """Where ``f`` or its slope may jump: the start and the end."""
        return np.array([0.0, self.duration])

    @property
    def max_step(self) -> float:
        """The scipy path's longest step: a sixteenth of the shortest tone's period."""
        return 2.0 * math.pi / max(self.frequencies) / 16.0

    @property
    def peak(self) -> float:
        """The largest ``|f|`` on a dense scan (64 points per shortest period)."""
        t = np.linspace(0.0, self.duration,
                        max(2, int(64 * self.duration / (2 * math.pi / max(self.frequencies)))))
        return float(np.abs(self.f(t)).max())

    def scaled(self, gain):
        """The same tones, ``gain`` times stronger."""
        return HarmonicSum(self.amplitudes, self.frequencies, self.duration, self.phases,
                         self.gain * gain)

    def f(self, t):
        """The base acceleration in ``g`` at model time(s) ``t`` (zero outside
        ``[0, duration]``)."""
        t = np.asarray(t, dtype=float)
        v = sum(a * np.sin(w * t + p)
                for a, w, p in zip(self.amplitudes, self.frequencies, self.phases))
        out = np.where((t >= 0.0) & (t <= self.duration), self.gain * v, 0.0)
        return float(out) if out.ndim == 0 else out

    def scalar(self):
        """``f`` as a function of one float (the scipy path's right-hand side)."""
        tones = list(zip(self.amplitudes, self.frequencies, self.phases))
        end, g, sin = self.duration, self.gain, math.sin

        def f(t):
            if not 0.0 <= t <= end:
                return 0.0
            return g * sum(a * sin(w * t + p) for a, w, p in tones)
        return f

    def windows(self, threshold):
        """Rows ``(t_start, t_end, sign of f)`` where ``|f| > threshold``, in order: sign
        changes of ``|f| - threshold`` on a scan of 256 points per shortest period, each
        refined by Brent's method (a window narrower than the scan's step may go unseen)."""
        from scipy.optimize import brentq
        f = self.scalar()
        n = max(2, int(256 * self.duration / (2 * math.pi / max(self.frequencies))) + 1)
        t = np.linspace(0.0, self.duration, n)
        v = self.f(t)
        rows = []
        for sg in (1.0, -1.0):
            above = sg * v > threshold
            g = lambda s: sg * f(s) - threshold  # noqa: E731
            k = 0
            while k < n:
                if not above[k]:
                    k += 1
                    continue
                j = k
                while j + 1 < n and above[j + 1]:
                    j += 1
                t0 = 0.0 if k == 0 else brentq(g, t[k - 1], t[k], xtol=1e-15, rtol=4 * _EPS)
                t1 = self.duration if j == n - 1 else brentq(g, t[j], t[j + 1], xtol=1e-15,
                                                             rtol=4 * _EPS)
                rows.append((t0, t1, sg))
                k = j + 1
        rows.sort()
        return np.array(rows, dtype=float).reshape(-1, 3)

    def describe(self) -> str:
        """One line: the tones."""
        tones = ", ".join(f"{a:g} sin({w:g} t + {p:g})" for a, w, p in
                          zip(self.amplitudes, self.frequencies, self.phases))
        g = "" if self.gain == 1.0 else f"{self.gain:g} x "
        return f"{g}sum of harmonics {tones} over {self.duration:g}"
