"""The rocking block: the one place where its physics is written.

Everything that knows the equations of motion lives here: the angular acceleration on either
corner and its Jacobian, the impact (jump) map and the saltation matrix, with the restitution laws
of :mod:`rockjit.laws`. The excitations are plugs (:mod:`rockjit.plugs`): the harmonic forcing
and its oscillator in :mod:`rockjit.plugs.harmonic`. The compiled integrator
(:mod:`rockjit._engine.integrate`) and the scipy reference path call these same functions;
nothing else writes an equation of motion.

Conventions (docs/theory/model.md, impacts.md). State ``(theta, dtheta)``; ``side = +1`` rocks on the corner reached
for ``theta > 0`` and ``side = -1`` on the other one; ``side = 0`` is the block at rest. The
forcing acceleration is ``f = aw2 * r`` with ``aw2 = alpha * omega**2`` and ``r`` either
``sin(omega t + phi)`` (closed form) or the first component of the oscillator embedding.

Notes
-----
Equations of motion: Housner (1963), in the dimensionless form of docs/theory/model.md.
Restitution: Housner (1963) angular-momentum law; Mao et al. (2024) kinetic-energy law.
Saltation matrix: Müller (1995), specialised to the impact surface ``theta = 0`` (docs/theory/exponents.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np

from . import laws
from ._jit import fma, jit
from .laws.housner import e_housner
from .laws.mao import e_mao
from .validate import choice, real

__all__ = [
    "LAWS",
    "XI_STUDY",
    "Block",
    "accel",
    "accel_jac",
    "accel_near",
    "accel_pq",
    "corner",
    "delta_e_percent",
    "e_housner",
    "e_mao",
    "energy",
    "free_rocking_decided",
    "initial_side",
    "jump",
    "near_poly",
    "rotate",
    "saltation",
    "saltation_at",
    "sincos",
    "sincos_poly",
    "slope_pq",
    "thc_from_hb",
]

#: The names of the package's restitution laws (:mod:`rockjit.laws`, where they are defined).
LAWS = laws.names()


# --------------------------------------------------------------------------------------------
# The diagonal's angle (the restitution laws are in rockjit.laws)
# --------------------------------------------------------------------------------------------

def thc_from_hb(hb):
    """Angle of the block's diagonal from the ground, ``thc = arctan(h/b)``.

    Parameters
    ----------
    hb : float or array_like
        Slenderness ``h/b``.

    Returns
    -------
    float or ndarray
        ``thc`` in radians.

    Examples
    --------
    >>> from rockjit import thc_from_hb
    >>> round(float(thc_from_hb(1.0)), 6), round(float(thc_from_hb(2.0)), 4)
    (0.785398, 1.1071)
    """
    return np.arctan(hb)


def delta_e_percent(e1, e2):
    """Symmetric percentage difference ``|e1 - e2| / (0.5 (e1 + e2)) * 100``.

    Parameters
    ----------
    e1, e2 : float or array_like
        Two coefficients of restitution.

    Returns
    -------
    ndarray
        The difference in percent of their mean.

    Examples
    --------
    >>> import rockjit
    >>> thc = rockjit.thc_from_hb(1.0)
    >>> round(float(rockjit.delta_e_percent(rockjit.e_mao(thc), rockjit.e_housner(thc))), 2)
    79.85
    """
    e1 = np.asarray(e1, dtype=float)
    e2 = np.asarray(e2, dtype=float)
    return np.abs(e1 - e2) / (0.5 * (e1 + e2)) * 100.0


# --------------------------------------------------------------------------------------------
# The block
# --------------------------------------------------------------------------------------------

#: Allowed range of the slenderness: wide (the study's values are 1 and 2) and keeping every
#: product the integrator forms finite.
HB_RANGE = (1e-2, 1e2)
XI_MAX = 1e4
#: The study's damping ``c_b / (M R^2 Omega0)``: M = 2e4 kg, c_b = 101 N s m, R = 3.764 m,
#: g = 9.81 m/s^2 (docs/theory/model.md).
XI_STUDY = 101.0 / (2e4 * 3.764**2 * math.sqrt(9.81 / 3.764))


@dataclass(frozen=True)
class Block:
    """A rigid block rocking on a rigid base: its slenderness, restitution law and damping.

    Parameters
    ----------
    hb : float
        Slenderness ``h/b`` in ``[0.01, 100]`` (``>= 1/sqrt(2)`` for the Housner law).
    law : str, optional
        Restitution law, by its name in :mod:`rockjit.laws` (``"housner"``, ``"mao"``,
        ``"constant"``, ``"speed"``, or one registered with :func:`rockjit.laws.register`);
        default ``"housner"``, or ``"constant"`` when ``e`` is given.
    e : float, optional
        Coefficient of restitution in ``[0, 1]``, only with the constant law.
    xi : float
        Viscous damping in ``[0, 1e4]``; default the study's,
        :data:`rockjit.model.XI_STUDY`.

    Examples
    --------
    >>> from rockjit import Block
    >>> b = Block(hb=1, law="mao")
    >>> round(b.restitution, 3), round(b.thc, 4)
    (0.582, 0.7854)
    """

    hb: float
    law: str | None = None
    e: float | None = None
    xi: float = XI_STUDY

    def __post_init__(self):
        hb = real("hb", self.hb, *HB_RANGE)
        law = self.law
        if law is None:
            law = "housner" if self.e is None else "constant"
        if not isinstance(law, str):
            raise ValueError(f"law must be a restitution law's name, one of "
                             f"{', '.join(map(repr, laws.names()))} (got {law!r})")
        rule = laws.get(law)
        if rule.needs_e:
            if self.e is None:
                raise ValueError(f"e is required for law={law!r} (a number in [0, 1])")
            e = real("e", self.e, 0.0, 1.0)
        elif self.e is not None:
            raise ValueError(f"e is only given with law='constant' (law={law!r}, e={self.e})")
        rule.check(hb)
        object.__setattr__(self, "hb", hb)
        object.__setattr__(self, "law", law)
        object.__setattr__(self, "xi", real("xi", self.xi, 0.0, XI_MAX))
        object.__setattr__(self, "e", e if rule.needs_e else None)

    # thc and the restitution are computed once per block (numpy on scalars: a microsecond
    # each, a run's fixed cost); cached_property writes the instance's __dict__ directly, which
    # a frozen dataclass allows
    @cached_property
    def thc(self) -> float:
        """``arctan(hb)``."""
        return float(thc_from_hb(self.hb))

    @property
    def rule(self):
        """The restitution law itself (:mod:`rockjit.laws`), the object named by ``law``."""
        return laws.get(self.law)

    @cached_property
    def restitution(self) -> float:
        """The coefficient of restitution of this block under its law (of a slow impact, for a
        law that depends on the impact's speed)."""
        return self.rule.coefficient(self.thc, self.e)

    @property
    def impact_law(self):
        """``(kind, shape)``: how the integrator evaluates the law at an impact
        (``rockjit.laws.impact.restitution_at``)."""
        rule = self.rule
        return float(laws.impact.kind_of(rule)), float(rule.shape)

    @property
    def cot(self) -> float:
        """Uplift threshold ``cot(thc) = b/h`` on ``|f|``."""
        return 1.0 / self.hb

    def replace(self, **changes) -> "Block":
        """A copy with some fields changed (validated again); a new ``law`` drops ``e`` and a
        new ``e`` selects the constant law, unless both are given."""
        fields = dict(hb=self.hb, law=self.law, e=self.e, xi=self.xi)
        fields.update(changes)
        if "law" in changes and "e" not in changes:
            fields["e"] = None
        if "e" in changes and "law" not in changes:
            fields["law"] = None
        return Block(**fields)


# --------------------------------------------------------------------------------------------
# Compiled physics, shared by the compiled integrator and the scipy reference path
# --------------------------------------------------------------------------------------------

# sin x = x S(x^2), cos x = C(x^2) on |x| <= 1.75: least-squares fits of degree 8 in x^2 at
# Chebyshev nodes (made with mpmath at 50 digits; maximum error 2.3e-16 on the range, against
# mpmath). The block's angle theta lies in [-pi/2, pi/2] until it overturns; a step may overshoot
# that a little, and beyond 1.75 the libm functions take over.
_S = (
    1.0, -0.1666666666666666, 0.008333333333332672, -0.000198412698410478,
    2.7557319186664126e-06, -2.505210486029754e-08, 1.6058848125936605e-10,
    -7.640822990840576e-13, 2.70032005075978e-15,
)
_C = (
    1.0, -0.49999999999999856, 0.04166666666665413, -0.0013888888888468477,
    2.480158723091546e-05, -2.755731254792034e-07, 2.0876386266285834e-09,
    -1.1458730661760175e-11, 4.5687420770339104e-14,
)
SINCOS_RANGE = 1.75


@jit
def sincos_poly(x):
    """``(sin x, cos x)`` by the polynomial alone: valid on ``|x| <= SINCOS_RANGE`` only.

    Branch-free, for the integrator's stages, which check the range once per step and redo a
    step that left it with :func:`sincos` (a branch to libm inside the stage chain makes the
    compiler pass every sine through memory).
    """
    # Estrin's scheme: half the dependency depth of Horner's (the step is latency-bound)
    u = x * x
    u2 = u * u
    u4 = u2 * u2
    s = fma(fma(fma(_S[7], u, _S[6]), u2, fma(_S[5], u, _S[4])), u4,
            fma(fma(_S[3], u, _S[2]), u2, fma(_S[1], u, _S[0])))
    s = fma(_S[8] * u4, u4, s) * x
    c = fma(fma(fma(_C[7], u, _C[6]), u2, fma(_C[5], u, _C[4])), u4,
            fma(fma(_C[3], u, _C[2]), u2, fma(_C[1], u, _C[0])))
    c = fma(_C[8] * u4, u4, c)
    return s, c


# Near a known angle: sin d = d SN(d^2), cos d = CN(d^2) on |d| <= 0.3, least-squares fits at
# Chebyshev nodes as above (degrees 4 and 5 in d^2; maximum error 1.1e-16 against mpmath).
_SN = (
    0.9999999999999997, -0.1666666666665064, 0.008333333319085734, -0.00019841225508368003,
    2.7501005605705403e-06,
)
_CN = (
    1.0, -0.49999999999999956, 0.04166666666661057, -0.0013888888862292794,
    2.4801530301046397e-05, -2.7501004793934925e-07,
)
NEAR_RANGE = 0.3


@jit
def near_poly(d):
    """``(S, C)`` with ``sin d = d S`` and ``cos d = C``, for ``|d| <= NEAR_RANGE`` only."""
    u = d * d
    u2 = u * u
    u4 = u2 * u2
    sn = fma(fma(_SN[3], u, _SN[2]), u2, fma(_SN[1], u, _SN[0]))
    sn = fma(_SN[4], u4, sn)
    cn = fma(fma(_CN[3], u, _CN[2]), u2, fma(_CN[1], u, _CN[0]))
    cn = fma(fma(_CN[5], u, _CN[4]), u4, cn)
    return sn, cn


@jit
def sincos(x):
    """``(sin x, cos x)``: a polynomial on ``|x| <= 1.75``, libm beyond.

    Each step of the integrator needs six of these, one after another on its critical path; the
    polynomial has a third of the latency of libm's ``sin`` and ``cos`` and agrees with them to
    a unit or two in the last place.
    """
    if abs(x) > SINCOS_RANGE:
        return math.sin(x), math.cos(x)
    return sincos_poly(x)


@jit
def corner(f, side, sthc, cthc):
    """``(P, Q)`` with ``theta'' = P cos(theta) + Q sin(theta) - 3/4 xi theta'`` on corner ``side``.

    docs/theory/model.md on either corner is ``theta'' = 3/4 (f sin(thc + s theta) - s cos(thc + s theta)
    - xi theta')`` with ``s = side`` (+1 or -1) and ``f`` the forcing acceleration
    ``alpha omega^2 r``. Expanding the sum angles, ``P = 3/4 (f sin(thc) - s cos(thc))`` and
    ``Q = 3/4 (f s cos(thc) + sin(thc))``: they depend on time only through ``f``, so the
    integrator computes them off its critical path and needs the sine and cosine of ``theta``
    alone. ``sthc, cthc`` are ``sin(thc), cos(thc)``.
    """
    a1 = 0.75 * sthc
    a2 = 0.75 * (side * cthc)
    return fma(f, a1, -a2), fma(f, a2, a1)


@jit
def accel_pq(P, Q, s, c, dtheta, xi):
    """``theta''`` from :func:`corner`'s ``P, Q`` and ``s, c = sin(theta), cos(theta)``."""
    return fma(-damping_rate(xi), dtheta, fma(P, c, Q * s))


@jit
def rotate(P, Q, s0, c0):
    """:func:`corner`'s ``(P, Q)`` for angles measured from ``theta0``: with ``s0, c0`` the sine
    and cosine of ``theta0``, ``P cos(theta0 + d) + Q sin(theta0 + d) = P' cos d + Q' sin d``."""
    return fma(P, c0, Q * s0), fma(Q, c0, -(P * s0))


@jit
def accel_near(P, Q, d, dtheta, xi):
    """``theta''`` at ``theta0 + d`` from :func:`rotate`'s ``(P', Q')``, ``|d| <= NEAR_RANGE``.

    :func:`accel_pq` with :func:`near_poly`'s sine and cosine of ``d``; ``Q' d`` is formed
    while the polynomials are evaluated, a multiplication off the integrator's critical path.
    """
    sn, cn = near_poly(d)
    return fma(-damping_rate(xi), dtheta, fma(P, cn, (Q * d) * sn))


@jit
def slope_pq(P, Q, s, c):
    """``d theta'' / d theta`` from :func:`corner`'s ``P, Q`` and ``sin, cos`` of theta."""
    return fma(Q, c, -(P * s))


@jit(nrt=False, inline=True)
def damping_rate(xi):
    """``k`` of the damping term ``-k theta'`` in ``theta''``: ``k = 3/4 xi``."""
    return 0.75 * xi


@jit(nrt=False, inline=True)
def jerk_snap(f, df, ddf, side, sthc, cthc, xi, s, c, v, a):
    """The third and fourth derivatives of theta in time (jerk and snap) on corner ``side``.

    From the forcing acceleration ``f`` and its first two time derivatives ``df, ddf``, the
    sine and cosine ``s, c`` of theta, ``v = theta'`` and ``a = theta''``. With
    ``theta'' = P cos(theta) + Q sin(theta) - k theta'`` (:func:`corner`,
    :func:`damping_rate`), ``P`` and ``Q`` affine in ``f`` (``dP/df = a1 = 3/4 sin(thc)``,
    ``dQ/df = a2 = 3/4 side cos(thc)``)::

        jerk = (a1 c + a2 s) f' + (Q c - P s) v - k a
        snap = 2 (a2 c - a1 s) f' v + (a1 c + a2 s) f'' - (a + k v) v^2 + (Q c - P s) a - k jerk

    (``P c + Q s = a + k v``; ``Q c - P s`` is :func:`slope_pq`). ``sthc, cthc`` are
    ``sin(thc), cos(thc)``.
    """
    a1 = 0.75 * sthc
    a2 = 0.75 * (side * cthc)
    k = damping_rate(xi)
    P, Q = corner(f, side, sthc, cthc)
    dadf = fma(a1, c, a2 * s)
    dadf_th = fma(a2, c, -(a1 * s))
    sl = slope_pq(P, Q, s, c)
    j = fma(dadf, df, fma(sl, v, -(k * a)))
    sn = fma(2.0 * dadf_th * df, v,
             fma(dadf, ddf, fma(sl, a, fma(-fma(k, v, a) * v, v, -(k * j)))))
    return j, sn


@jit
def accel(theta, dtheta, f, side, thc, xi):
    """Angular acceleration ``theta''`` while rocking on corner ``side`` (+1 or -1).

    ``f`` is the forcing acceleration ``alpha omega^2 r``; the formula is docs/theory/model.md, arranged
    by :func:`corner`. On ``side = 0`` (rest) the acceleration is zero.
    """
    if side == 0:
        return 0.0
    P, Q = corner(f, side, math.sin(thc), math.cos(thc))
    s, c = sincos(theta)
    return accel_pq(P, Q, s, c, dtheta, xi)


@jit
def accel_jac(theta, dtheta, f, side, thc, xi):
    """Partial derivatives of :func:`accel` with respect to ``theta``, ``theta'`` and ``f``."""
    if side == 0:
        return 0.0, 0.0, 0.0
    sthc = math.sin(thc)
    cthc = math.cos(thc)
    P, Q = corner(f, side, sthc, cthc)
    s, c = sincos(theta)
    # d/df of P cos + Q sin is 3/4 (sin(thc) cos(theta) + side cos(thc) sin(theta))
    return slope_pq(P, Q, s, c), -damping_rate(xi), 0.75 * fma(sthc, c, side * cthc * s)


@jit
def initial_side(theta0, dtheta0):
    """The corner a run starts on: the sign of ``theta0``, else of ``theta0'``, else 0 (at
    rest) (docs/theory/impacts.md)."""
    if theta0 > 0.0 or (theta0 == 0.0 and dtheta0 > 0.0):
        return 1
    if theta0 < 0.0 or (theta0 == 0.0 and dtheta0 < 0.0):
        return -1
    return 0


@jit
def jump(dtheta_minus, e):
    """Impact map on ``theta = 0``: ``theta'(+) = e theta'(-)``; the side changes sign."""
    return e * dtheta_minus


@jit
def energy(theta, dtheta, thc):
    """The mechanical energy ``1/2 theta'^2 + 3/4 sin(thc + |theta|)`` with the base still.

    Kinetic energy and the potential of the centre of mass, which rises with ``|theta|`` to
    ``3/4`` at the tipping angle ``|theta| = pi/2 - thc`` (docs/theory/model.md). Free rocking
    never gains it: damping takes ``3/4 xi theta'^2`` per unit time, and an impact keeps the
    fraction ``e^2 <= 1`` of the kinetic part (:func:`jump`, the potential is ``3/4 sin(thc)``
    on either side of it).
    """
    return 0.5 * dtheta * dtheta + 0.75 * math.sin(thc + abs(theta))


@jit
def free_rocking_decided(theta, dtheta, max_theta, thc, th_top):
    """Whether free rocking from ``(theta, theta')`` can neither reach ``th_top`` nor swing wider
    than ``max_theta``, the largest ``|theta|`` so far.

    ``th_top`` is at most the tipping angle ``pi/2 - thc``, below which the potential
    ``3/4 sin(thc + |theta|)`` rises with ``|theta|``. The :func:`energy` ``E`` never grows in
    free rocking, so every later swing, on either side, stays below the angle where the
    potential equals ``E``. From inside ``th_top``, that angle lies below ``th_top`` when ``E``
    is below the potential there, and at most at ``max_theta`` when ``E`` is at most the
    potential there: at a turning point (``theta' = 0``) counted in ``max_theta`` the second
    always holds. The comparison is of energies, so that a turning point decides exactly.
    """
    if not abs(theta) < th_top:
        return False
    en = energy(theta, dtheta, thc)
    widest = min(max_theta, th_top)
    lim = 0.75 * math.sin(thc + widest)
    if widest == th_top:  # the two bounds are one: the strict one decides
        return en < lim
    return en <= lim and en < 0.75 * math.sin(thc + th_top)


@jit
def saltation(dtheta_minus, f, side_old, thc, xi, e):
    """:func:`saltation_at` for a coefficient ``e`` fixed per block (``e' = e``)."""
    return saltation_at(dtheta_minus, f, side_old, thc, xi, e, e)


@jit
def saltation_at(dtheta_minus, f, side_old, thc, xi, e, e_slope):
    """Lower-left entry of the saltation matrix of an impact on ``theta = 0``.

    ``S = [[e, 0], [s10, e']]`` with ``s10 = (F+ - e' F-) / theta'-``, ``F-`` the acceleration
    on the old corner before the jump and ``F+`` on the new corner after it, ``e`` the
    impact's coefficient and ``e' = d(e(v) v)/dv`` its slope in the approach speed ``v``
    (``e' = e`` for a coefficient fixed per block) (docs/theory/exponents.md; Müller 1995).
    Both accelerations come from :func:`accel`, so damping cancels exactly as it does
    analytically.
    """
    f_minus = accel(0.0, dtheta_minus, f, side_old, thc, xi)
    f_plus = accel(0.0, jump(dtheta_minus, e), f, -side_old, thc, xi)
    return (f_plus - e_slope * f_minus) / dtheta_minus
