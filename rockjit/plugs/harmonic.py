"""The harmonic forcing ``f = alpha omega^2 sin(omega t + phi)``: the periodic kernels' plug.

The study's excitation, in its two forms: the functions of time and phase that the compiled
kernels of periodic runs (``rockjit._engine.integrate``, the lanes, the GPU driver) and the
scipy reference path (``rockjit.reference``) call, instead of a sine of the forcing of their
own. They give ``r``, the forcing over its amplitude: the kernels scale it by the parameter
``aw2 = alpha omega^2``, and the block's rule of rest (it lifts where ``|f| > cot(thc)``,
docs/theory/impacts.md) applies to ``f = aw2 r`` whatever the excitation. Its Python side is
:class:`rockjit.Harmonic`.

- The closed form ``r = sin(omega t + phi)`` (``forcing_closed``), its phase at a time
  (``phase_at``) and at the start of grid step ``j`` of a period of ``N`` steps
  (``grid_phase``, and the advance over a fraction of a grid step, ``grid_advance``),
  the phase advanced by an angle (``advance``, the stages of a step, and its time
  derivative ``advance_slope``) or taken back by one (``phase_before``), the rotation
  that advance is (``advance_rotation``, within a step); the derivatives the event
  interpolant needs, ``f' = alpha omega^3 cos`` from the phase (``slope``) and
  ``f'' = -omega^2 f`` (``curvature``).
- When a block at rest is lifted: the first instant ``|f|`` exceeds ``cot(thc)``
  (``uplift_time``, in closed form).
- The autonomous form: the oscillator ``(r, s)`` whose limit cycle is the closed form
  (``oscillator``, ``oscillator_jac``), which the embedding integrates with the block
  (docs/theory/model.md), and the largest ``|r|`` it reaches from a radius (``peak_after``).

The pairs come back as ``(sin, cos)``, except ``advance_rotation``'s ``(cos, sin)`` (the
order of the step table's rows).

The small functions of the phase are inlined in numba's IR where they are called (no compiled
function of their own: a cold start compiles less). Every function takes numbers, not the
kernels' parameter rows: which slot holds ``omega`` is the
kernels' business (``rockjit._engine.layout``). An excitation that ends is a transient plug
instead (:mod:`rockjit.plugs.base`), run by the transient kernel.
"""

from __future__ import annotations

import math

from .._jit import fma, jit
from ..model import NEAR_RANGE, near_poly, sincos, sincos_poly

__all__ = ["advance", "advance_rotation", "advance_slope", "curvature", "forcing_closed",
           "grid_advance", "grid_phase", "oscillator", "oscillator_jac", "phase_at",
           "peak_after", "phase_before", "slope", "uplift_time"]


# ---- the closed form --------------------------------------------------------------------------

@jit
def forcing_closed(t, omega, phi):
    """``r = sin(omega t + phi)``, the closed form of the forcing oscillator on its circle."""
    return math.sin(omega * t + phi)


@jit(ir_inline=True)
def phase_at(t, omega, phi):
    """``(sin, cos)`` of the phase ``omega t + phi`` (libm's)."""
    psi = omega * t + phi
    return math.sin(psi), math.cos(psi)


@jit(ir_inline=True)
def grid_phase(phi, j, n_per):
    """``(sin, cos)`` of the phase ``phi + 2 pi j / N`` at the start of grid step ``j`` of a
    period cut into ``N = n_per`` steps (libm's)."""
    ph0 = phi + 2.0 * math.pi * j / n_per
    return math.sin(ph0), math.cos(ph0)


@jit(ir_inline=True)
def grid_advance(c, n_per):
    """``(sin, cos)`` of the advance ``2 pi c / N`` of the phase over the fraction ``c`` of a
    grid step."""
    return sincos(2.0 * math.pi * c / n_per)


@jit(ir_inline=True)
def advance(s0, c0, cd, sd):
    """``sin(p + d)`` from ``s0, c0 = sin p, cos p`` and ``cd, sd = cos d, sin d``."""
    return fma(s0, cd, c0 * sd)


@jit(ir_inline=True)
def advance_slope(s0, c0, cd, sd):
    """``cos(p + d)`` from the same four numbers as :func:`advance` (the phase's derivative)."""
    return fma(c0, cd, -(s0 * sd))


@jit(ir_inline=True)
def phase_before(se, ce, u):
    """``(sin, cos)`` of the phase the angle ``u`` (``|u| <= SINCOS_RANGE``) before a phase of
    sine ``se`` and cosine ``ce``: a rotation back by the polynomial's sine and cosine of
    ``u``, instead of a sine of ``omega t + phi`` (no library call, and no rounding of a
    large ``t``)."""
    su, cu = sincos_poly(u)
    return fma(se, cu, -(ce * su)), fma(ce, cu, se * su)


@jit(ir_inline=True)
def advance_rotation(omega, h, c):
    """``(cos, sin)`` of the phase's advance ``omega c h`` to the node ``c`` of a step of length
    ``h``: while ``omega h`` is within ``NEAR_RANGE`` (0.3: from ``N = 21`` steps a period on)
    by the short polynomial of a small angle, else by the sine's."""
    u = omega * c * h
    if abs(omega * h) <= NEAR_RANGE:
        sn, cs = near_poly(u)
        return cs, sn * u
    sn, cs = sincos(u)
    return cs, sn


@jit(ir_inline=True)
def slope(aw3, c):
    """The forcing's time derivative ``alpha omega^3 cos(phase)``, from ``aw3 = alpha
    omega^3`` and the phase's cosine ``c``."""
    return aw3 * c


@jit(ir_inline=True)
def curvature(omega, f):
    """The forcing's second time derivative, ``f'' = -omega^2 f``."""
    return -(omega * omega) * f


# ---- the block at rest ------------------------------------------------------------------------

@jit
def uplift_time(t, aw2, cot, omega, phi):
    """First time ``>= t`` at which the closed-form forcing lifts a block at rest.

    The block at rest leaves it when ``|aw2 sin(omega t + phi)| > cot``
    (docs/theory/impacts.md). Returns ``t`` itself if that already holds, and ``inf`` if
    ``aw2 <= cot`` (it never leaves).
    """
    if aw2 <= cot:
        return math.inf
    a = math.asin(cot / aw2)
    psi = omega * t + phi
    u = psi - math.pi * math.floor(psi / math.pi)  # phase modulo pi: |sin| has period pi
    if a < u < math.pi - a:
        return t
    if u <= a:
        return t + (a - u) / omega
    return t + (math.pi - u + a) / omega


# ---- the autonomous form ----------------------------------------------------------------------

@jit
def oscillator(r, s, omega):
    """Right-hand side ``(r', s')`` of the autonomous forcing oscillator
    (docs/theory/model.md)."""
    q = r * r + s * s
    return r + omega * s - r * q, s - omega * r - s * q


@jit
def oscillator_jac(r, s, omega):
    """Jacobian ``[[dr'/dr, dr'/ds], [ds'/dr, ds'/ds]]`` of :func:`oscillator`."""
    q = r * r + s * s
    return (1.0 - q - 2.0 * r * r, omega - 2.0 * r * s,
            -omega - 2.0 * r * s, 1.0 - q - 2.0 * s * s)


@jit(ir_inline=True)
def peak_after(rad):
    """The largest ``|r|`` the oscillator reaches from radius ``rad``: it relaxes monotonically
    to its unit circle, so ``max(1, rad)`` (a block at rest whose ``aw2`` times this stays at
    or below ``cot(thc)`` stays at rest for good)."""
    return max(1.0, rad)
