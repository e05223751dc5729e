"""The slender linearised block under a one-sine or one-cosine pulse, in closed form.

For a slender block (``alpha_s`` small) rocking on the corner of ``theta > 0``, equation
(eq-motion) of docs/theory/model.md linearises, with ``phi = theta / alpha_s``, the time
``tau = p t`` and ``tan alpha_s ~ alpha_s``, to

    phi'' - phi = a s(tau) - 1,

where ``a = a_p / (g tan alpha_s)`` is the amplitude ratio and ``s`` the pulse's shape
(``sin(beta tau)`` or ``cos(beta tau)`` on ``0 <= tau <= 2 pi / beta``, ``beta = omega_p / p``
the frequency ratio). This is the equation of Housner (1963) and Zhang & Makris (2001) in
dimensionless form; Dimitrakopoulos & DeJong (2012) showed that its solutions, drawn in these
two ratios, hold for every slender block. Once the pulse has ended, ``phi'' = phi - 1`` has a
saddle at ``phi = 1``, and the block escapes (overturns) exactly when ``phi - 1 + phi' > 0``:
the coefficient of ``e^tau`` in its free motion is positive. Solving the forced equation from
uplift in closed form gives the boundary of overturning *without impact* (mode 2):

- **one-cosine pulse**: the block lifts at ``tau = 0`` (for ``a > 1``),
  ``phi = 1 - c cos(beta tau) + (c - 1) cosh(tau)`` with ``c = a / (1 + beta^2)``, which stays
  positive for ``c > 1``; at the pulse's end ``phi - 1 + phi' = (c - 1) e^{tau_e} - c``, so
  the block overturns without impact exactly when

      a > (1 + beta^2) / (1 - exp(-2 pi / beta));

- **one-sine pulse**: the block lifts at ``tau_u = arcsin(1/a) / beta``, then
  ``phi = 1 - a sin(beta tau) / (1 + beta^2) + A cosh(tau - tau_u) + B sinh(tau - tau_u)`` with
  ``A = -beta^2 / (1 + beta^2)``, ``B = a beta cos(beta tau_u) / (1 + beta^2)``; at the pulse's
  end ``phi - 1 + phi' = (A + B) e^{tau_e - tau_u} - a beta / (1 + beta^2)``, so the boundary
  is the root ``a > 1`` of

      (sqrt(a^2 - 1) - beta) exp((2 pi - arcsin(1/a)) / beta) = a,

  provided ``phi`` stays positive until the pulse ends (checked, :func:`sine_phi`). For large
  ``beta`` the root approaches ``beta^2 / (2 pi)``: a short one-sine pulse overturns the block
  through the displacement ``2 pi a_p / omega_p^2`` it leaves on the ground.

These are the literature's mode-2 boundaries of the linearised block (Zhang & Makris 2001
found them by the same route; Dimitrakopoulos & DeJong 2012 give the similarity argument).
The nonlinear block of slenderness ``h/b`` approaches them as ``alpha_s -> 0``, with an error of
order ``alpha_s^2`` (tests/ground/test_ground.py measures it).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

__all__ = ["cosine_no_impact", "sine_no_impact", "sine_phi"]


def cosine_no_impact(ratio):
    """The one-cosine pulse's smallest amplitude ratio that overturns the slender linearised
    block without impact: ``(1 + beta^2) / (1 - exp(-2 pi / beta))``."""
    b = float(ratio)
    return (1.0 + b * b) / (-math.expm1(-2.0 * math.pi / b))


def _sine_escape_log(s, b):
    """The escape condition in logarithms, free of overflow at small ``beta`` (where
    ``exp(2 pi / beta)`` exceeds any float): with ``u = sqrt(a^2 - 1) = beta + e^s`` the
    condition ``(u - beta) exp((2 pi - arcsin(1/a)) / beta) = a`` reads
    ``s - log(a) + (2 pi - arctan(1/u)) / beta = 0``, increasing in ``s``."""
    u = b + math.exp(s)
    return s - math.log(math.hypot(1.0, u)) + (2.0 * math.pi - math.atan2(1.0, u)) / b


def _sine_root(b):
    """``(a, d)``: the root ``a`` of the one-sine escape condition and ``d = sqrt(a^2 - 1) -
    beta > 0``, found in ``s = log d`` (``d`` may be far below the smallest float: then ``a``
    rounds to ``hypot(1, beta)`` and ``d`` to 0)."""
    lo = -2.0 * math.pi / b - 1.0  # there the condition is < 0: each other term is <= 0
    hi = math.log(1.0 + b * b) + 2.0
    while _sine_escape_log(hi, b) < 0.0:
        hi *= 2.0
    s = brentq(_sine_escape_log, lo, hi, args=(b,), xtol=1e-15, rtol=4 * np.finfo(float).eps)
    d = math.exp(s)
    a = math.hypot(1.0, b + d)
    if b > 1.0:
        # here the condition is flat in s (a ~ beta^2 / (2 pi) grows as e^s): polished where
        # it is steep, in a itself, whose exponential cannot overflow for beta > 1
        lo, hi = a * (1.0 - 1e-9), a * (1.0 + 1e-9)
        if _sine_escape(lo, b) < 0.0 < _sine_escape(hi, b):
            a = brentq(_sine_escape, lo, hi, args=(b,), xtol=1e-14,
                       rtol=4 * np.finfo(float).eps)
            d = math.sqrt(a * a - 1.0) - b
    return a, d


def _sine_escape(a, b):
    """``(sqrt(a^2 - 1) - beta) exp((2 pi - arcsin(1/a)) / beta) - a``, scaled by ``1/a``
    (for ``beta > 1`` only: smaller ratios overflow the exponential)."""
    return (math.sqrt(a * a - 1.0) - b) / a * math.exp((2.0 * math.pi - math.asin(1.0 / a)) / b) \
        - 1.0


def _sine_phi(a, b, d, tau):
    """:func:`sine_phi` with the growing and the decaying parts apart, each exponential taken
    with its coefficient's logarithm so that neither overflows (``A cosh s + B sinh s =
    (A + B)/2 e^s + (A - B)/2 e^-s``), and ``A + B = beta d / (1 + beta^2)`` without the
    cancellation of ``A`` against ``B``."""
    q = 1.0 + b * b
    tu = math.asin(1.0 / a) / b
    grow = 0.5 * b * d / q
    decay = 0.5 * (-b * b - b * (b + d)) / q
    tau = np.asarray(tau, dtype=float)
    s = np.maximum(tau - tu, 0.0)
    with np.errstate(over="ignore", under="ignore"):
        g = np.exp(s + math.log(grow)) if grow > 0.0 else np.zeros_like(s)
        phi = 1.0 - a * np.sin(b * tau) / q + g - np.exp(math.log(-decay) - s)
    return np.where(tau >= tu, phi, 0.0)


def sine_phi(a, ratio, tau):
    """``phi = theta / alpha_s`` of the slender linearised block under the one-sine pulse of
    amplitude ratio ``a`` and frequency ratio ``ratio``, at ``tau = p t`` (while it rocks on
    its first corner, during the pulse)."""
    b = float(ratio)
    return _sine_phi(a, b, math.sqrt(a * a - 1.0) - b, tau)


def sine_no_impact(ratio):
    """The one-sine pulse's smallest amplitude ratio that overturns the slender linearised
    block without impact: the root ``a > 1`` of
    ``(sqrt(a^2 - 1) - beta) exp((2 pi - arcsin(1/a)) / beta) = a``. Raises ``ValueError``
    where the block would strike the ground before the pulse ends."""
    b = float(ratio)
    a, d = _sine_root(b)
    tau = np.linspace(math.asin(1.0 / a) / b, 2.0 * math.pi / b, 2001)[1:]
    if not np.min(_sine_phi(a, b, d, tau)) > 0.0:
        raise ValueError(f"at ratio {b:g} the linearised block strikes the ground during the "
                         f"pulse: the closed form does not apply")
    return a
