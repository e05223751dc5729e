"""rockjit.plugs.harmonic, the harmonic forcing, against independent statements of it.

- ``oscillator_jac``: central finite differences of ``oscillator``; ``oscillator`` on its circle
  against the closed form's derivatives;
- the phase's rotations (``advance``, ``advance_slope``, ``phase_before``, ``advance_rotation``,
  ``grid_advance``, ``grid_phase``, ``phase_at``) against libm's sine and cosine of the rotated
  angle (a wrong sign, swapped pair or branch errs by ~1e-1; these agree to a few ulps);
- ``peak_after``: the oscillator integrated by scipy from inside and outside its circle;
- ``slope``, ``curvature``: central differences of ``alpha omega^2 sin(omega t + phi)``;
- ``uplift_time``: a brute-force scan of the forcing, and the closed form in conftest.
"""

import math

import numpy as np
import pytest

from rockjit.plugs import harmonic

RNG_SEED = 20240607

# ---- the oscillator and the closed form (docs/theory/model.md) ----------------------------------

def test_oscillator_jac_matches_finite_differences():
    eps = 1e-6
    rng = np.random.default_rng(RNG_SEED)
    for r, s, omega in zip(rng.uniform(-1.5, 1.5, 8), rng.uniform(-1.5, 1.5, 8),
                           rng.uniform(0.5, 3.0, 8)):
        jac = np.array(harmonic.oscillator_jac(r, s, omega)).reshape(2, 2)
        fd = np.empty((2, 2))
        fd[:, 0] = (np.array(harmonic.oscillator(r + eps, s, omega))
                    - np.array(harmonic.oscillator(r - eps, s, omega))) / (2 * eps)
        fd[:, 1] = (np.array(harmonic.oscillator(r, s + eps, omega))
                    - np.array(harmonic.oscillator(r, s - eps, omega))) / (2 * eps)
        np.testing.assert_allclose(jac, fd, rtol=1e-7, atol=1e-9)


def test_oscillator_on_the_circle_is_the_closed_form():
    # r = sin(omega t + phi), s = cos(omega t + phi) solves r' = omega s, s' = -omega r there
    omega, phi = 1.3, 0.7
    for t in np.linspace(0.0, 5.0, 11):
        r, s = math.sin(omega * t + phi), math.cos(omega * t + phi)
        dr, ds = harmonic.oscillator(r, s, omega)
        assert dr == pytest.approx(omega * s, abs=1e-14)
        assert ds == pytest.approx(-omega * r, abs=1e-14)
        assert harmonic.forcing_closed(t, omega, phi) == pytest.approx(r, abs=1e-15)


# ---- the phase's rotations, which the kernels use instead of a sine per stage ------------------

def _angles(n=200, seed=RNG_SEED):
    """Phases anywhere on the circle and small rotations (a grid step's, up to 2 pi / 8)."""
    rng = np.random.default_rng(seed)
    return rng.uniform(-math.pi, math.pi, n), rng.uniform(-2 * math.pi / 8, 2 * math.pi / 8, n)


def test_advancing_and_taking_back_the_phase_agree_with_libm():
    for p, d in zip(*_angles()):
        s0, c0, sd, cd = math.sin(p), math.cos(p), math.sin(d), math.cos(d)
        assert harmonic.advance(s0, c0, cd, sd) == pytest.approx(math.sin(p + d), abs=1e-15)
        assert harmonic.advance_slope(s0, c0, cd, sd) == pytest.approx(math.cos(p + d),
                                                                       abs=1e-15)
        sb, cb = harmonic.phase_before(s0, c0, d)
        assert sb == pytest.approx(math.sin(p - d), abs=1e-15)
        assert cb == pytest.approx(math.cos(p - d), abs=1e-15)


@pytest.mark.parametrize("n_per", [8, 16, 21, 64, 1000])
def test_the_advance_to_a_node_is_the_rotation_by_its_angle(n_per):
    """Both branches: the short polynomial while omega h <= 0.3 (from N = 21 steps a period on),
    the sine's for N < 21."""
    omega = 1.3  # (omega h = 2 pi / N whatever omega)
    h = 2 * math.pi / omega / n_per
    for c in (0.0, 0.2, 0.3, 0.8, 8 / 9, 1.0):
        cs, sn = harmonic.advance_rotation(omega, h, c)
        assert cs == pytest.approx(math.cos(omega * c * h), abs=1e-15)
        assert sn == pytest.approx(math.sin(omega * c * h), abs=1e-15)
        sd, cd = harmonic.grid_advance(c, n_per)
        assert (sd, cd) == pytest.approx((math.sin(omega * c * h), math.cos(omega * c * h)),
                                         abs=1e-15)


def test_the_phase_at_a_time_and_at_a_grid_step():
    omega, phi, n_per = 1.3, -0.7778, 64
    for j in (0, 1, 17, 63):
        t = j * (2 * math.pi / omega) / n_per
        s, c = harmonic.grid_phase(phi, j, n_per)
        assert (s, c) == pytest.approx((math.sin(omega * t + phi), math.cos(omega * t + phi)),
                                       abs=1e-15)
        assert harmonic.phase_at(t, omega, phi) == (math.sin(omega * t + phi),
                                                    math.cos(omega * t + phi))


def test_slope_and_curvature_are_the_forcings_derivatives():
    alpha, omega, phi, eps = 0.66, 1.3, 0.4, 1e-4
    aw2 = alpha * omega ** 2
    f = lambda t: aw2 * math.sin(omega * t + phi)  # noqa: E731
    for t in np.linspace(0.0, 5.0, 9):
        d1 = (f(t + eps) - f(t - eps)) / (2 * eps)
        d2 = (f(t + eps) - 2 * f(t) + f(t - eps)) / eps ** 2
        assert harmonic.slope(aw2 * omega, math.cos(omega * t + phi)) == pytest.approx(
            d1, abs=1e-7)
        assert harmonic.curvature(omega, f(t)) == pytest.approx(d2, abs=1e-6)


def test_the_oscillators_peak_from_a_radius():
    """From inside its circle ``|r|`` grows to 1, from outside it shrinks from the radius: the
    largest ``|r|`` over many turns, integrated by scipy, is ``peak_after``'s when the start
    is on the ``r`` axis, and never more from any start on that circle."""
    from scipy.integrate import solve_ivp
    omega = 1.3
    for rad in (0.2, 0.9, 1.0, 1.7, 3.0):
        peaks = []
        for phase in np.linspace(0.0, 2 * math.pi, 7)[:-1]:
            sol = solve_ivp(lambda t, z: harmonic.oscillator(z[0], z[1], omega), (0.0, 60.0),
                            [rad * math.cos(phase), rad * math.sin(phase)], method="DOP853",
                            rtol=1e-11, atol=1e-13, max_step=0.05)
            peaks.append(np.abs(sol.y[0]).max())
        # (below the circle the crests are sampled every 0.05: within 1e-3 of the top)
        assert peaks[0] == pytest.approx(harmonic.peak_after(rad), abs=1e-9 if rad >= 1 else 1e-3)
        assert max(peaks) <= harmonic.peak_after(rad) + 1e-9


# ---- when a block at rest is lifted (docs/theory/impacts.md) ------------------------------------

@pytest.mark.parametrize("t0, aw2, cot, omega, phi", [
    (0.0, 0.6, 0.5, 3.0, 0.0),
    (0.0, 0.6, 0.5, 3.0, math.pi),
    (0.0, 0.6, 0.5, 3.0, 4.0),
    (1.234, 1.2, 1.0, 1.3, 0.2),
    (7.5, 0.9, 0.5, 2.0, -2.0),
    (0.0, 0.6, 0.5, 3.0, 1.5),   # already lifting at t0
])
def test_uplift_time(spec, t0, aw2, cot, omega, phi):
    got = harmonic.uplift_time(t0, aw2, cot, omega, phi)
    want, _ = spec.first_uplift(t0, aw2, cot, omega, phi)
    assert got == pytest.approx(want, rel=0, abs=1e-12)
    # brute force: scan one forcing period on a fine grid
    ts = t0 + np.linspace(0.0, 2 * math.pi / omega, 400_001)
    lifted = np.abs(aw2 * np.sin(omega * ts + phi)) > cot
    t_scan = ts[np.argmax(lifted)]
    assert abs(got - t_scan) <= (ts[1] - ts[0])
    # a block that can never be lifted
    assert harmonic.uplift_time(t0, cot, cot, omega, phi) == math.inf
