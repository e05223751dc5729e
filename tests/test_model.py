"""rockjit.model against independent statements of the same physics.

- restitution laws: the values docs/theory/impacts.md quotes from the paper, and the papers' formulas typed in
  again in conftest;
- ``accel``: the two corner equations of docs/theory/model.md written out separately (conftest);
- ``accel_jac``: central finite differences of ``accel``;
- ``saltation``: the closed form of docs/theory/exponents.md written out here.

The harmonic forcing's functions are checked in tests/plugs/test_harmonic.py.
"""

import math

import numpy as np
import pytest

from rockjit import model
from rockjit.model import Block

RNG_SEED = 20240607


def _states(n=8, seed=RNG_SEED):
    """A few (theta, theta', f) points spread over the physically relevant range."""
    rng = np.random.default_rng(seed)
    th = rng.uniform(-1.2, 1.2, n)
    dth = rng.uniform(-2.0, 2.0, n)
    f = rng.uniform(-3.0, 3.0, n)
    return list(zip(th, dth, f))


# ---- restitution (docs/theory/impacts.md) -----------------------------------------------------------------

@pytest.mark.parametrize("hb, e_h, e_m, delta", [(1.0, 0.250, 0.582, 79.85),
                                                   (2.0, 0.700, 0.830, 17.03)])
def test_restitution_matches_values_quoted_in_spec(hb, e_h, e_m, delta):
    thc = model.thc_from_hb(hb)
    eh = float(model.e_housner(thc))
    em = float(model.e_mao(thc))
    # to the quoted digits: within half a unit of the last quoted place
    assert abs(eh - e_h) <= 0.5e-3
    assert abs(em - e_m) <= 0.5e-3
    assert abs(float(model.delta_e_percent(em, eh)) - delta) <= 0.5e-2
    # Block picks the law it is given
    assert Block(hb, "housner").restitution == eh
    assert Block(hb, "mao").restitution == em
    assert Block(hb, e=0.37).restitution == 0.37


def test_restitution_laws_match_spec_formulas(spec):
    for hb in np.linspace(1 / math.sqrt(2), 6.0, 25):
        thc = model.thc_from_hb(hb)
        assert float(model.e_housner(thc)) == pytest.approx(spec.e_housner(hb), rel=1e-13,
                                                             abs=1e-15)
        assert float(model.e_mao(thc)) == pytest.approx(spec.e_mao(hb), rel=1e-13)
    # vectorised, for the figures
    thc = model.thc_from_hb(np.array([1.0, 2.0]))
    np.testing.assert_allclose(model.e_mao(thc), [spec.e_mao(1.0), spec.e_mao(2.0)], rtol=1e-13)


def test_housner_law_vanishes_at_its_limit():
    # e_H = 1 - 1.5 cos^2(thc) = 0 exactly when tan(thc) = 1/sqrt(2) (docs/theory/impacts.md)
    assert abs(float(model.e_housner(model.thc_from_hb(1 / math.sqrt(2))))) < 1e-15
    assert float(model.e_housner(model.thc_from_hb(0.7))) < 0.0


# ---- the block's sine and cosine ----------------------------------------------------------------

def test_sincos_polynomial_matches_libm_on_its_range():
    """The polynomial the stages use agrees with libm to ~1 ulp on [-1.75, 1.75] (the fit's
    maximum error is 2.3e-16), odd and even as sin and cos are."""
    x = np.concatenate([np.linspace(-model.SINCOS_RANGE, model.SINCOS_RANGE, 20001),
                        [0.0, 1e-300, 1e-8, -1e-8, math.pi / 4, math.pi / 2]])
    for xi in x:
        s, c = model.sincos_poly(xi)
        assert abs(s - math.sin(xi)) <= 3.5e-16 and abs(c - math.cos(xi)) <= 3.5e-16, xi
        s2, c2 = model.sincos_poly(-xi)
        assert s2 == -s and c2 == c
        assert model.sincos(xi) == (s, c)  # on the range, sincos is the polynomial


def test_sincos_falls_back_to_libm_beyond_its_range():
    for xi in (1.7500001, -1.76, 2.5, -3.0, 10.0, 1e6):
        assert model.sincos(xi) == (math.sin(xi), math.cos(xi))
    s, c = model.sincos(math.nan)
    assert math.isnan(s) and math.isnan(c)


def test_near_polynomial_matches_libm_on_its_range():
    for d in np.concatenate([np.linspace(-model.NEAR_RANGE, model.NEAR_RANGE, 6001),
                             [0.0, 1e-300, 1e-9]]):
        sn, cn = model.near_poly(d)
        assert abs(d * sn - math.sin(d)) <= 2e-16 and abs(cn - math.cos(d)) <= 2e-16, d


def test_acceleration_near_a_base_angle_is_the_acceleration_there():
    """``rotate`` + ``accel_near`` (the integrator's stages) against ``accel`` at the same angle,
    and the rotated slope against ``accel_jac``."""
    rng = np.random.default_rng(3)
    for side in (1, -1):
        for hb in (1.0, 2.0):
            thc = math.atan(hb)
            for _ in range(200):
                th0, d = rng.uniform(-1.5, 1.5), rng.uniform(-0.3, 0.3)
                dth, f, xi = rng.uniform(-3, 3), rng.uniform(-2, 2), 0.05
                P, Q = model.corner(f, side, math.sin(thc), math.cos(thc))
                Pr, Qr = model.rotate(P, Q, math.sin(th0), math.cos(th0))
                want = model.accel(th0 + d, dth, f, side, thc, xi)
                assert model.accel_near(Pr, Qr, d, dth, xi) == pytest.approx(want, abs=2e-15)
                sn, cn = model.near_poly(d)
                assert model.slope_pq(Pr, Qr, d * sn, cn) == pytest.approx(
                    model.accel_jac(th0 + d, dth, f, side, thc, xi)[0], abs=2e-15)


# ---- the vector field (docs/theory/model.md) ------------------------------------------------------------

@pytest.mark.parametrize("side", [1, -1])
@pytest.mark.parametrize("hb", [1.0, 2.0, 0.8])
def test_accel_matches_spec_equations(spec, side, hb):
    thc = math.atan(hb)
    xi = 0.07
    omega, phi = 1.7, 0.3
    for k, (th, dth, f) in enumerate(_states()):
        # put the forcing value f at some time t through the documented sin(omega t + phi)
        t = 0.1 * k
        aw2 = f / math.sin(omega * t + phi)
        want = spec.theta_ddot(t, th, dth, side, hb, aw2, omega, phi, xi)
        got = model.accel(th, dth, aw2 * math.sin(omega * t + phi), side, thc, xi)
        assert got == pytest.approx(want, rel=1e-12, abs=1e-14)
    assert model.accel(0.3, 0.2, 1.0, 0, thc, xi) == 0.0  # at rest


@pytest.mark.parametrize("side", [1, -1])
@pytest.mark.parametrize("hb", [1.0, 2.0])
def test_accel_jac_matches_finite_differences(side, hb):
    thc = math.atan(hb)
    xi = 0.05
    eps = 1e-6
    for th, dth, f in _states():
        jac = np.array(model.accel_jac(th, dth, f, side, thc, xi))
        x = np.array([th, dth, f])
        fd = np.empty(3)
        for i in range(3):
            d = np.zeros(3)
            d[i] = eps
            fd[i] = (model.accel(*(x + d), side, thc, xi)
                     - model.accel(*(x - d), side, thc, xi)) / (2 * eps)
        np.testing.assert_allclose(jac, fd, rtol=1e-7, atol=1e-9)


# ---- the impact (docs/theory/impacts.md, §5) --------------------------------------------------------------

def test_jump_map():
    assert model.jump(-0.4, 0.25) == -0.1
    assert model.jump(0.8, 1.0) == 0.8


@pytest.mark.parametrize("xi", [0.0, 0.3])
@pytest.mark.parametrize("hb", [0.8, 1.0, 2.0, 4.0])
def test_saltation_matches_spec_closed_form(hb, xi):
    """S[1, 0] = 3/4 [(1-e) aw2 r sin(thc) - sgn(theta'-)(1+e) cos(thc)] / theta'- (docs/theory/exponents.md)."""
    thc = math.atan(hb)
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(20):
        dm = rng.choice([-1, 1]) * rng.uniform(1e-3, 2.0)
        f = rng.uniform(-3.0, 3.0)  # f = aw2 * r
        e = rng.uniform(0.0, 1.0)
        side_old = -int(np.sign(dm))  # theta'- < 0 on the corner theta > 0, and vice versa
        want = 0.75 * ((1 - e) * f * math.sin(thc)
                       - np.sign(dm) * (1 + e) * math.cos(thc)) / dm
        got = model.saltation(dm, f, side_old, thc, xi, e)
        assert got == pytest.approx(want, rel=1e-12, abs=1e-12 / abs(dm))
