"""Acceleration pulses: the one-sine, the one-cosine and the symmetric Ricker wavelet, as one
excitation plug (:mod:`rockjit.plugs.base`).

A pulse is given, as in the rocking literature (Zhang & Makris 2001; Dimitrakopoulos & DeJong
2012), by two dimensionless ratios: its frequency against the block's frequency parameter,
``ratio = omega_p / p``, and its peak acceleration against the uplift threshold,
``amplitude = a_p / (g cot theta_c)`` with ``cot theta_c = b/h``. In model units
(docs/theory/model.md), ``p = sqrt(3/4)``, so ``omega_p = ratio * sqrt(3/4)`` and the peak base
acceleration in ``g`` is ``a_p / g = amplitude / hb``: the pulse needs the block's slenderness to
become a base acceleration. :meth:`Pulse.bind` gives it the block's; the forms of
docs/theory/ground-motions.md then hold.

The compiled side, :func:`pulse_value` and :func:`pulse_window`, is what the compiled transient
kernel runs (the windows in closed form for the sine and cosine, by bisection to adjacent floats
on the Ricker wavelet's lobes); the Python side (:meth:`Pulse.scalar`, :meth:`Pulse.windows`,
the lobes by Brent's method) is what the scipy reference path runs, written apart from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .._jit import jit
from ..excitation import ACCEL_MAX
from ..model import HB_RANGE
from ..validate import choice, real
from .base import TransientPlug, register

__all__ = ["AMPLITUDE_MAX", "H_PULSE", "KINDS", "MIN_PULSE_STEPS", "P_MODEL", "Pulse",
           "RATIO_RANGE", "pulse_value", "pulse_window"]

#: The pulses' shapes, in the order of their codes among the plug's coefficients.
KINDS = ("sine", "cosine", "ricker")
SINE, COSINE, RICKER = range(3)
#: Housner's frequency parameter ``p = sqrt(3 g / 4 R)`` in model units (``1/sqrt(R/g)``).
P_MODEL = math.sqrt(0.75)
#: Allowed ranges of the ratios: wide, and keeping the model-unit frequency within the range
#: every solver handles (``omega_p`` in about ``[1e-3, 1e3]``).
RATIO_RANGE = (1e-3, 1e3)
AMPLITUDE_MAX = 1e6
#: The Ricker wavelet's delay in units of ``pi / omega_p``: ``t0 = 3 pi / omega_p`` puts its
#: value at ``t = 0`` below ``1e-8 a_p`` (docs/theory/ground-motions.md); the wavelet is cut at
#: ``2 t0``, where it is as small again.
RICKER_DELAY = 3.0
#: The compiled kernel's longest step during a pulse (model time).
H_PULSE = 0.01
#: The fewest steps the compiled kernel takes per pulse (a short pulse still has its shape
#: resolved).
MIN_PULSE_STEPS = 256


# ---- the compiled side --------------------------------------------------------------------------

@jit(nrt=False, inline=True)
def pulse_value(t, a, c, off, n):
    """The pulse of peak ``a`` (``g``) at model time ``t`` inside it, from its coefficients
    ``c[off:off + 3]``: the shape's code, ``omega_p`` and the Ricker wavelet's delay."""
    shape = int(c[off])
    w = c[off + 1]
    if shape == SINE:
        return a * math.sin(w * t)
    if shape == COSINE:
        return a * math.cos(w * t)
    u = 0.5 * w * (t - c[off + 2])
    u2 = u * u
    return a * (1.0 - 2.0 * u2) * math.exp(-u2)


@jit(nrt=False)
def _ricker_root(r, lo, hi, lobe):
    """The ``u`` in ``[lo, hi]`` where the Ricker shape ``g(u) = (1 - 2u^2) exp(-u^2)`` meets
    ``r`` (``lobe`` 1: the main lobe, ``g = r``; -1: a side lobe, ``-g = r``), by bisection to
    adjacent floats."""
    glo = lobe * (1.0 - 2.0 * lo * lo) * math.exp(-lo * lo) - r
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        g = lobe * (1.0 - 2.0 * mid * mid) * math.exp(-mid * mid) - r
        if g == 0.0:
            return mid
        if (g > 0.0) == (glo > 0.0):
            lo, glo = mid, g
        else:
            hi = mid
    return 0.5 * (lo + hi)


@jit(nrt=False, inline=True)
def _first_after(tq, a0, a1, sa, b0, b1, sb, c0, c1, sc):
    """The first of the windows ``(a0, a1, sa)``, ``(b0, b1, sb)``, ``(c0, c1, sc)`` (in order;
    a sign 0 for none) that ends after ``tq``; ``(0, 0, 0)`` if none does."""
    if sa != 0.0 and a1 > tq:
        return a0, a1, sa
    if sb != 0.0 and b1 > tq:
        return b0, b1, sb
    if sc != 0.0 and c1 > tq:
        return c0, c1, sc
    return 0.0, 0.0, 0.0


@jit(nrt=False)
def pulse_window(tq, end, a, c, off, n, thr):
    """The first interval ``(t0, t1, sign f)`` where the pulse of peak ``a`` has
    ``|f| > thr`` and ``t1 > tq`` (``sign`` 0 if none): of the sine's two and the cosine's three
    half-waves in closed form, of the Ricker wavelet's main lobe and side lobes by bisection."""
    if not a > thr:
        return 0.0, 0.0, 0.0
    r = thr / a
    shape = int(c[off])
    w = c[off + 1]
    if shape == SINE:
        s = math.asin(r)
        return _first_after(tq, s / w, (math.pi - s) / w, 1.0,
                            (math.pi + s) / w, (2.0 * math.pi - s) / w, -1.0, 0.0, 0.0, 0.0)
    if shape == COSINE:
        q = math.acos(r)
        return _first_after(tq, 0.0, q / w, 1.0, (math.pi - q) / w, (math.pi + q) / w, -1.0,
                            (2.0 * math.pi - q) / w, 2.0 * math.pi / w, 1.0)
    t0 = c[off + 2]
    um = _ricker_root(r, 0.0, math.sqrt(0.5), 1.0)
    if r < 2.0 * math.exp(-1.5):  # deeper than the side lobes
        ui = _ricker_root(r, math.sqrt(0.5), math.sqrt(1.5), -1.0)
        uo = _ricker_root(r, math.sqrt(1.5), 10.0, -1.0)
        return _first_after(tq, t0 + 2.0 * -uo / w, t0 + 2.0 * -ui / w, -1.0,
                            t0 + 2.0 * -um / w, t0 + 2.0 * um / w, 1.0,
                            t0 + 2.0 * ui / w, t0 + 2.0 * uo / w, -1.0)
    return _first_after(tq, t0 + 2.0 * -um / w, t0 + 2.0 * um / w, 1.0,
                        0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


# ---- the excitation -----------------------------------------------------------------------------


@register
@dataclass(frozen=True)
class Pulse(TransientPlug):
    """An acceleration pulse on the base, in the literature's ratios.

    Parameters
    ----------
    kind : {"sine", "cosine", "ricker"}
        ``a_p sin(omega_p t)`` or ``a_p cos(omega_p t)`` on ``0 <= t <= 2 pi / omega_p``, zero
        after; or the symmetric Ricker wavelet ``a_p (1 - 2u^2) exp(-u^2)``,
        ``u = omega_p (t - t0) / 2``, ``t0 = 3 pi / omega_p``, cut at ``2 t0``
        (docs/theory/ground-motions.md: ``omega_p`` is where its Fourier amplitude peaks).
    ratio : float, optional
        ``omega_p / p`` in ``[1e-3, 1e3]``. Left out where a spectrum sweeps it.
    amplitude : float, optional
        ``a_p / (g cot theta_c)`` in ``[0, 1e6]``: above 1 the pulse can lift the block. Left
        out where a spectrum sweeps it.
    hb : float, optional
        The slenderness ``h/b`` the amplitude refers to; :func:`rockjit.simulate` binds the
        block's (:meth:`bind`). Needed to evaluate :meth:`f`.

    Examples
    --------
    >>> from rockjit import Block, Pulse
    >>> pulse = Pulse("sine", ratio=2.0, amplitude=3.0).bind(Block(hb=4))
    >>> round(pulse.accel, 4), round(pulse.end, 4)
    (0.75, 3.6276)
    """

    kind: str = "sine"
    ratio: float | None = None
    amplitude: float | None = None
    hb: float | None = None

    def __post_init__(self):
        choice("kind", self.kind, KINDS)
        if self.ratio is not None:
            object.__setattr__(self, "ratio", real("ratio", self.ratio, *RATIO_RANGE))
        if self.amplitude is not None:
            object.__setattr__(self, "amplitude", real("amplitude", self.amplitude, 0.0,
                                                       AMPLITUDE_MAX))
        if self.hb is not None:
            object.__setattr__(self, "hb", real("hb", self.hb, *HB_RANGE))
        if self.amplitude is not None and self.hb is not None and \
                self.amplitude / self.hb > ACCEL_MAX:
            raise ValueError(f"the pulse's peak acceleration amplitude / hb must be <= "
                             f"{ACCEL_MAX:g} g (got {self.amplitude:g} / {self.hb:g})")

    value = staticmethod(pulse_value)
    window = staticmethod(pulse_window)

    # ---- the compiled kernel's side ------------------------------------------------------
    def coefficients(self):
        """The shape's code, ``omega_p`` and the Ricker wavelet's delay."""
        return np.array([KINDS.index(self.kind), self.omega_p, self.delay], dtype=float)

    def grid(self, shrink):
        """Equal steps of at most ``H_PULSE`` (times ``shrink``) over the pulse, at least
        ``MIN_PULSE_STEPS`` of them."""
        return max(MIN_PULSE_STEPS, math.ceil(self.end / (shrink * H_PULSE))), 0.0

    def amplitude_at(self, gains):
        """The peak acceleration in ``g`` of this pulse ``gains`` times stronger, as
        :meth:`scaled` then :attr:`accel` form it: ``amplitude * gain / hb``."""
        self._need("amplitude", "hb")
        return self.amplitude * np.asarray(gains, dtype=float) / self.hb

    # ---- what every transient excitation says --------------------------------------------
    def bind(self, block):
        """This pulse on ``block``: its slenderness set (refused if another was given)."""
        if self.hb is not None and self.hb != block.hb:
            raise ValueError(f"the pulse was given hb = {self.hb:g} but the block has "
                             f"hb = {block.hb:g}")
        return self if self.hb == block.hb else replace(self, hb=block.hb)

    def scaled(self, gain):
        """The same pulse with its amplitude multiplied by ``gain``."""
        return replace(self, amplitude=self.amplitude * gain)

    def require(self, *names, why):
        """Refuse a pulse that lacks one of ``names`` (``why``: the entry point) or gives one
        the entry point sweeps itself (``names`` prefixed with ``-``)."""
        for name in names:
            if name.startswith("-"):
                if getattr(self, name[1:]) is not None:
                    raise ValueError(f"{why} sweeps the pulse's {name[1:]} itself: leave it "
                                     f"out (got {name[1:]} = {getattr(self, name[1:])})")
            elif getattr(self, name) is None:
                raise ValueError(f"{why} needs the pulse's {name} (e.g. Pulse("
                                 f"{self.kind!r}, {name}=...))")
        return self

    def _need(self, *names):
        missing = [n for n in names if getattr(self, n) is None]
        if missing:
            raise ValueError(f"the pulse needs {' and '.join(missing)} to be evaluated "
                             f"(hb: Pulse(..., hb=...) or pulse.bind(block))")

    @property
    def omega_p(self) -> float:
        """The pulse's circular frequency in model units, ``ratio * sqrt(3/4)``."""
        self._need("ratio")
        return self.ratio * P_MODEL

    @property
    def accel(self) -> float:
        """The peak base acceleration ``a_p / g = amplitude / hb``."""
        self._need("amplitude", "hb")
        return self.amplitude / self.hb

    @property
    def peak(self) -> float:
        """The largest ``|f|`` (in ``g``): ``a_p / g``."""
        return self.accel

    @property
    def delay(self) -> float:
        """The Ricker wavelet's centre ``t0 = 3 pi / omega_p`` (0 for the other pulses)."""
        return RICKER_DELAY * math.pi / self.omega_p if self.kind == "ricker" else 0.0

    @property
    def end(self) -> float:
        """Model time after which the base is still: ``2 pi / omega_p`` (``2 t0`` for the
        Ricker wavelet)."""
        if self.kind == "ricker":
            return 2.0 * self.delay
        return 2.0 * math.pi / self.omega_p

    @property
    def breaks(self) -> np.ndarray:
        """Model times where ``f`` or its derivative jumps: the pulse's start and end."""
        return np.array([0.0, self.end])

    @property
    def max_step(self) -> float:
        """The longest solver step that cannot step over the pulse's shape: a sixteenth of
        ``2 pi / omega_p``."""
        return 2.0 * math.pi / self.omega_p / 16.0

    def f(self, t):
        """The base acceleration in ``g`` at model time(s) ``t`` (zero outside the pulse)."""
        a, w, end = self.accel, self.omega_p, self.end
        t = np.asarray(t, dtype=float)
        inside = (t >= 0.0) & (t <= end)
        if self.kind == "sine":
            v = a * np.sin(w * t)
        elif self.kind == "cosine":
            v = a * np.cos(w * t)
        else:
            u2 = (0.5 * w * (t - self.delay)) ** 2
            v = a * (1.0 - 2.0 * u2) * np.exp(-u2)
        out = np.where(inside, v, 0.0)
        return float(out) if out.ndim == 0 else out

    def scalar(self):
        """``f`` as a fast function of one float (the scipy path's right-hand side)."""
        a, w, end, t0 = self.accel, self.omega_p, self.end, self.delay
        sin, cos, exp = math.sin, math.cos, math.exp
        if self.kind == "sine":
            return lambda t: a * sin(w * t) if 0.0 <= t <= end else 0.0
        if self.kind == "cosine":
            return lambda t: a * cos(w * t) if 0.0 <= t <= end else 0.0

        def ricker(t):
            if not 0.0 <= t <= end:
                return 0.0
            u2 = (0.5 * w * (t - t0)) ** 2
            return a * (1.0 - 2.0 * u2) * exp(-u2)
        return ricker

    def windows(self, threshold):
        """The intervals where ``|f| > threshold``: rows ``(t_start, t_end, sign of f)`` in
        order, located in closed form (sine, cosine) or to rounding (the Ricker lobes)."""
        a, w = self.accel, self.omega_p
        if not a > threshold:
            return np.zeros((0, 3))
        r = threshold / a
        if self.kind == "sine":
            s = math.asin(r)
            rows = [(s, math.pi - s, 1.0), (math.pi + s, 2.0 * math.pi - s, -1.0)]
            return np.array([(t0 / w, t1 / w, sg) for t0, t1, sg in rows])
        if self.kind == "cosine":
            c = math.acos(r)
            rows = [(0.0, c, 1.0), (math.pi - c, math.pi + c, -1.0),
                    (2.0 * math.pi - c, 2.0 * math.pi, 1.0)]
            return np.array([(t0 / w, t1 / w, sg) for t0, t1, sg in rows])
        # Ricker: shape g(u) = (1 - 2u^2) exp(-u^2), t = t0 + 2u / omega_p
        from scipy.optimize import brentq
        g = lambda u: (1.0 - 2.0 * u * u) * math.exp(-u * u)  # noqa: E731
        tol = 4 * np.finfo(float).eps
        u_main = brentq(lambda u: g(u) - r, 0.0, math.sqrt(0.5), xtol=tol)
        rows = []
        side = 2.0 * math.exp(-1.5)  # the side lobes' depth
        u_in = u_out = None
        if r < side:
            u_in = brentq(lambda u: -g(u) - r, math.sqrt(0.5), math.sqrt(1.5), xtol=tol)
            u_out = brentq(lambda u: -g(u) - r, math.sqrt(1.5), 10.0, xtol=tol)
            rows.append((-u_out, -u_in, -1.0))
        rows.append((-u_main, u_main, 1.0))
        if u_in is not None:
            rows.append((u_in, u_out, -1.0))
        t0 = self.delay
        return np.array([(t0 + 2.0 * u0 / w, t0 + 2.0 * u1 / w, sg) for u0, u1, sg in rows])

    def describe(self) -> str:
        """One line: the pulse and its ratios."""
        return (f"one-{self.kind} pulse" if self.kind != "ricker" else "Ricker wavelet") + \
            f", omega_p/p = {self.ratio:g}, a_p/(g cot theta_c) = {self.amplitude:g}"
