"""Lyapunov exponents through impacts (docs/theory/exponents.md) against what they must equal.

- the exact identity ``lambda1 + lambda2 = -3/4 xi + 2 nu ln(e)``, with the impact rate ``nu``
  counted here from the recorded impacts;
- a stable period-1 orbit: ``log|mu| / T`` of the multipliers ``mu`` of the stroboscopic map,
  whose Jacobian is taken here by central finite differences of one-period runs;
- a chaotic orbit: a two-trajectory (Benettin) estimate computed here with repeated one-period
  ``simulate`` calls, renormalised every period, on the same orbit segment;
- the running estimate settles; switching tangents on does not change the trajectory.
"""

import math

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic, Integration, Scipy
from stress import simulate_flat

Z0 = (-0.2254, -0.1597, -0.7778, 0.6284)  # docs/theory/study.md
PHI0 = math.atan2(Z0[2], Z0[3])


def _run(kw, **more):
    """``rockjit.simulate`` of a table's flat keywords (those of
    ``stress.simulate_flat`` (tests/stress.py), and ``z0``: the four of the initial state)."""
    kw = dict(kw, **more)
    if "z0" in kw:
        kw.update(zip(("theta0", "dtheta0", "r0", "s0"), kw.pop("z0")))
    return simulate_flat(**kw)

ORBITS = {
    "reference hb=1 housner a=0.6": dict(hb=1.0, alpha=0.6, omega=1.3, law="housner",
                                         periods=500),
    "asymmetric hb=1 housner a=0.8": dict(hb=1.0, alpha=0.8, omega=1.3, law="housner",
                                          periods=500),
    "hb=1 mao a=0.3": dict(hb=1.0, alpha=0.3, omega=1.3, law="mao", periods=500),
    "hb=2 housner a=0.2": dict(hb=2.0, alpha=0.2, omega=1.6, law="housner", periods=500),
    "hb=2 mao a=0.2": dict(hb=2.0, alpha=0.2, omega=1.6, law="mao", periods=500),
    "chaotic hb=1 housner a=0.955": dict(hb=1.0, alpha=0.955, omega=1.3, law="housner",
                                         periods=300),
}


@pytest.fixture(scope="module")
def runs():
    """The Lyapunov runs, computed once for the module."""
    return {name: _run(kw, z0=Z0, lyapunov=True) for name, kw in ORBITS.items()}


def _one_period(kw, x):
    """The stroboscopic map: one period from (theta, theta') at the strobe phase PHI0."""
    r = rockjit.simulate(Block(kw["hb"], kw["law"]),
                         Harmonic(alpha=kw["alpha"], omega=kw["omega"], phase=PHI0), (x[0], x[1]),
                         integration=Integration(periods=1))
    return r.state[:2]


def _strobe_jacobian(kw, x, eps=1e-6):
    J = np.empty((2, 2))
    for j in range(2):
        d = np.zeros(2)
        d[j] = eps
        J[:, j] = (_one_period(kw, x + d) - _one_period(kw, x - d)) / (2 * eps)
    return J


@pytest.mark.parametrize("name", list(ORBITS))
def test_sum_of_exponents_is_exact(runs, name):
    r = runs[name]
    assert r.status == "done" and r.n_rest_window == 0
    t0, t1 = r.window
    assert t0 == pytest.approx(round(0.8 * r.periods) * r.period, rel=1e-14)
    assert t1 == pytest.approx(r.periods * r.period, rel=1e-14)
    # impacts in the window, counted here
    n_win = int(np.sum((r.impacts[:, 0] >= t0) & (r.impacts[:, 0] <= t1)))
    assert n_win == r.n_impacts_window > 0
    nu = n_win / (t1 - t0)
    want = -0.75 * r.block.xi + 2.0 * nu * math.log(r.block.restitution)
    assert r.lyapunov.sum() == pytest.approx(want, abs=1e-6)


@pytest.mark.parametrize("name", list(ORBITS))
def test_running_exponents_satisfy_the_identity_at_every_period(runs, name):
    """The running estimates at every ``kT`` (``lyapunov_running``: the logs of the stretches
    summed from 0, over ``kT``) obey the identity too: ``(lambda1 + lambda2) kT = -3/4 xi kT +
    2 n(kT) ln(e)``, with ``n(kT)`` the impacts before ``kT`` counted here from the record
    (measured within 1.7e-8 in the logs at every period). Each exponent's own sum is banked
    separately, so a slip in either shows here even where the window's sum is right."""
    r = runs[name]
    assert len(r.impacts) == r.n_impacts  # every impact is in the record
    lam = r.lyapunov_running
    k = np.arange(1, len(lam))
    t = k * r.period
    n = np.searchsorted(r.impacts[:, 0], t, side="right")
    want = -0.75 * r.block.xi * t + 2.0 * n * math.log(r.block.restitution)
    got = (lam[1:, 0] + lam[1:, 1]) * t
    assert np.abs(got - want).max() <= 2e-7
    assert np.all(lam[1:, 0] >= lam[1:, 1])


def test_period_one_orbit_exponents_are_log_multipliers(runs):
    """Asymmetric orbit (docs/theory/study.md gallery): real, distinct multipliers."""
    name = "asymmetric hb=1 housner a=0.8"
    kw, r = ORBITS[name], runs[name]
    k = 400
    x = r.strobe[k, :2]
    np.testing.assert_allclose(r.strobe[k + 1, :2], x, rtol=0, atol=1e-10)  # period 1
    np.testing.assert_allclose(_one_period(kw, x), r.strobe[k + 1, :2], rtol=0, atol=1e-11)
    mu = np.linalg.eigvals(_strobe_jacobian(kw, x))
    assert np.all(np.isreal(mu)) and np.all(np.abs(mu) < 1)
    lam = np.sort(np.log(np.abs(mu)) / r.period)[::-1]
    np.testing.assert_allclose(r.lyapunov, lam, rtol=1e-4)


def test_reference_orbit_exponents_are_log_multipliers(runs):
    """Reference symmetric orbit: a complex pair, so lambda1 = lambda2 = log|mu| / T exactly.

    A finite window resolves the two only to O(1/window) (the QR estimate of a rotating pair
    oscillates about the common value), so their mean is checked tightly and each one loosely.
    """
    name = "reference hb=1 housner a=0.6"
    kw, r = ORBITS[name], runs[name]
    k = 400
    x = r.strobe[k, :2]
    np.testing.assert_allclose(r.strobe[k + 1, :2], x, rtol=0, atol=1e-10)  # period 1
    mu = np.linalg.eigvals(_strobe_jacobian(kw, x))
    assert np.all(np.abs(mu.imag) > 1e-3) and np.all(np.abs(mu) < 1)
    lam = math.log(abs(mu[0])) / r.period
    assert r.lyapunov.mean() == pytest.approx(lam, rel=1e-6)
    np.testing.assert_allclose(r.lyapunov, lam, rtol=1e-2)
    # the running estimate over the whole run is closer still
    np.testing.assert_allclose(r.lyapunov_running[-1], lam, rtol=1e-3)


def test_reference_run_is_stable_and_settles(runs):
    r = runs["reference hb=1 housner a=0.6"]
    assert r.lambda_max < 0
    run = r.lyapunov_running
    assert run.shape == (r.periods + 1, 2)
    assert np.all(run[0] == 0.0)
    tail = run[int(0.8 * len(run)):, 0]
    assert np.ptp(tail) < 2e-3 * abs(r.lambda_max)
    assert np.all(tail < 0)


def test_chaotic_run_matches_two_trajectory_estimate(runs):
    name = "chaotic hb=1 housner a=0.955"
    kw, r = ORBITS[name], runs[name]
    assert r.status == "done" and r.n_rest == 0
    assert r.lambda_max > 0.01
    T = r.period
    w0 = int(round(r.window[0] / T))
    d0 = 1e-8
    u = np.array([1.0, 1.0]) / math.sqrt(2.0)
    total, n = 0.0, 0
    # along the run's own strobe points; 20 periods before the window to align the direction
    for k in range(w0 - 20, r.periods):
        x = r.strobe[k, :2]
        y0 = _one_period(kw, x)
        dy = _one_period(kw, x + d0 * u) - y0
        d = np.linalg.norm(dy)
        u = dy / d
        if k >= w0:
            total += math.log(d / d0)
            n += 1
    lam = total / (n * T)
    assert n == r.periods - w0
    assert lam > 0
    assert r.lambda_max == pytest.approx(lam, rel=1e-3)


# ---- switches do not change the trajectory, bit for bit ----------------------------------------

BIT_CASES = {
    "reference": dict(hb=1.0, alpha=0.6, omega=1.3, law="housner", z0=Z0, periods=60),
    "chaotic": dict(hb=1.0, alpha=0.955, omega=1.3, law="housner", z0=Z0, periods=60),
    "rest and uplift": dict(hb=1.0, alpha=0.6, omega=1.3, law="housner", theta0=Z0[0],
                            dtheta0=Z0[1], r0=math.sin(2.5), s0=math.cos(2.5), periods=20),
}
FIELDS = ("t", "status", "n_impacts", "state", "strobe", "strobe_half", "impacts")


@pytest.mark.parametrize("forcing", ["closed", "embedded"])
@pytest.mark.parametrize("name", list(BIT_CASES))
def test_switches_do_not_change_the_trajectory(name, forcing):
    """Tangent vectors and trajectory recording on or off: the same run to the last bit."""
    kw = dict(BIT_CASES[name], forcing=forcing)
    plain = _run(kw)
    tangent = _run(kw, lyapunov=True)
    recorded = _run(kw, record_stride=3)
    both = _run(kw, lyapunov=True, record_stride=3)
    for other in (tangent, recorded, both):
        for field in FIELDS:
            assert np.array_equal(getattr(other, field), getattr(plain, field)), field
    assert np.array_equal(both.trajectory, recorded.trajectory)
    assert np.array_equal(both.lyapunov, tangent.lyapunov)
    assert np.array_equal(both.lyapunov_running, tangent.lyapunov_running)


# ---- orbits through rest: every perturbation dies, the exponents are -inf ----------------------

THROUGH_REST = dict(hb=1.0, alpha=0.6, omega=1.3, law="housner", theta0=0.0, dtheta0=0.0,
                    r0=0.0, s0=1.0)


def _scipy_period(x, phase):
    """One period of the scipy path (DOP853, tight) from (theta, theta') at ``phase``."""
    kw = {k: v for k, v in THROUGH_REST.items() if k not in ("theta0", "dtheta0", "r0", "s0")}
    r = _run(kw, theta0=x[0], dtheta0=x[1], phase=phase, periods=1,
             method=Scipy("DOP853", rtol=1e-12, atol=1e-12))
    return r.state[:2]


def test_orbit_through_rest_has_exponents_minus_infinity_at_every_cut_off():
    # Before the fix: lambda1 = +1.954 at rest_speed 1e-6, 0.79 at 1e-3, 0.82 at 1e-8 (the
    # saltation entries of the cascade's last impacts, ~1/theta', counted as growth).
    for rest_speed in (1e-3, 1e-4, 1e-6, 1e-8):
        r = _run(THROUGH_REST, lyapunov=True, rest_speed=rest_speed)
        assert r.status == "done" and r.n_rest_window > 0
        assert np.all(r.lyapunov == -math.inf), (rest_speed, r.lyapunov)


def test_orbit_through_rest_has_a_zero_monodromy_like_the_scipy_path():
    # The stroboscopic map's Jacobian on the settled orbit, by central differences of the
    # independent scipy path: zero, since both perturbed runs reach rest and leave it when the
    # forcing alone says.
    T = 2 * math.pi / THROUGH_REST["omega"]
    r = _run(THROUGH_REST, periods=40, qr_every=0, lyapunov=True)
    k = 30
    x = r.strobe[k, :2]
    phase = THROUGH_REST["omega"] * k * T  # phi = atan2(0, 1) = 0 at t = 0
    eps = 1e-5
    J = np.empty((2, 2))
    for j in range(2):
        d = np.zeros(2)
        d[j] = eps
        J[:, j] = (_scipy_period(x + d, phase) - _scipy_period(x - d, phase)) / (2 * eps)
    assert np.abs(J).max() < 1e-6
    # the compiled run's flow Jacobian over the run is that zero matrix too
    assert r.n_rest > 0 and np.array_equal(r.extra["tangent"], np.zeros((2, 2)))


def test_rest_only_in_the_transient_leaves_the_window_exponents_finite():
    # hb = 1 at alpha omega^2 = 1.49 > cot(thc) = 1: from theta0 = -0.07 the block rocks down
    # to rest within the first period (a Zeno cascade: every perturbation collapses), is lifted
    # again and settles on a symmetric orbit that never rests. The window's exponents are that
    # orbit's, finite, as from a start that never rests.
    block, forcing = Block(1.0, "housner"), Harmonic(alpha=0.22, omega=2.6, phase=2.9)
    r = rockjit.simulate(block, forcing, (-0.07, 0.0), lyapunov=True)
    ref = rockjit.simulate(block, forcing, (0.1, 0.0), lyapunov=True)
    assert ref.status == "done" and ref.n_rest == 0
    assert r.status == "done" and r.n_rest >= 1 and r.extra["collapses"] >= 1
    t_rest = r.impacts[np.abs(r.impacts[:, 2]) < Integration().rest_speed, 0]
    assert len(t_rest) == r.n_rest and t_rest.max() < r.period  # long before the window
    assert r.n_rest_window == 0
    assert np.all(np.isfinite(r.lyapunov)), r.lyapunov
    np.testing.assert_allclose(r.lyapunov, ref.lyapunov, rtol=1e-3)
    # the contrast: from rest under the reference forcing the orbit rests in the window too
    c = rockjit.simulate(Block(1.0, "housner"), Harmonic(alpha=0.6, omega=1.3, phase=PHI0),
                         (0.0, 0.0), lyapunov=True)
    assert c.extra["collapses"] >= 1 and c.n_rest_window > 0
    assert np.all(c.lyapunov == -math.inf)
