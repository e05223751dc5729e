"""rockjit against a second statement of its physics that shares no code with it.

Both of rockjit's integration paths (compiled, and scipy through :mod:`rockjit.reference`) are
fed by :mod:`rockjit.model`, so comparing them with each other cannot see a mistake in the
model. Here every quantity is checked against ``tests/physics.py``, which writes the physics
again from the papers (Housner 1963; Mao et al. 2024; Müller 1995) and never imports rockjit:

- the restitution laws against their formulas and the published values;
- the angular acceleration and its derivatives against the two corner equations written out;
- the saltation matrix against Müller's formula; the uplift instant against a brute-force scan;
- whole runs, compiled and scipy, against a slow event-driven ``solve_ivp`` integration with
  its own jump, rest and uplift (impact times and speeds, the stroboscopic samples);
- Floquet multipliers (:func:`rockjit.grids.identity.floquet`, :func:`rockjit.orbits.
  periodic_orbit`) of period-1, 2 and 3 orbits against the eigenvalues of a finite-difference
  Jacobian of ``P^p`` computed from that slow integrator.

Every tolerance is about ten times the agreement measured on this tree (stated beside it); for
the Floquet multipliers, ten times the error of the finite differences themselves.
"""

import functools
import math

import numpy as np
import pytest

import physics as ph  # tests/physics.py: the independent statement
import rockjit
from rockjit import Block, Harmonic, Integration, Scipy, model
from rockjit.grids.identity import floquet
from rockjit.orbits import periodic_orbit
from rockjit.plugs import harmonic

#: The study's initial state (theta, theta', r, s) of its single runs and sweeps.
Z0 = (-0.2254, -0.1597, -0.7778, 0.6284)
PHI0 = math.atan2(Z0[2], Z0[3])
#: The study's damping ``c_b / (M R^2 Omega0)`` from its block: M = 2e4 kg, c_b = 101 N s m,
#: R = 3.764 m, g = 9.81 m/s^2 (rockjit's default, checked here by passing it to the reference).
XI = 101.0 / (2e4 * 3.764**2 * math.sqrt(9.81 / 3.764))

RNG_SEED = 20250101


# ---------------------------------------------------------------------------------------------
# restitution
# ---------------------------------------------------------------------------------------------

@pytest.mark.parametrize("hb, e_h, e_m, delta", [(1.0, "0.250", "0.582", "79.85"),
                                                   (2.0, "0.700", "0.830", "17.03")])
def test_restitution_matches_the_published_values(hb, e_h, e_m, delta):
    """Housner's and Mao et al.'s coefficients and their difference, to the printed digits
    (within half a unit of the last printed place)."""
    thc = float(model.thc_from_hb(hb))
    assert thc == math.atan(hb)
    got = (float(model.e_housner(thc)), float(model.e_mao(thc)))
    got += (float(model.delta_e_percent(got[1], got[0])),)
    for value, printed in zip(got, (e_h, e_m, delta)):
        half_ulp = 0.5 * 10.0 ** -len(printed.split(".")[1])
        assert abs(value - float(printed)) <= half_ulp, (value, printed)
    # and the independent formulas give the same printed values
    ref = (ph.e_housner(thc), ph.e_mao(thc))
    ref += (ph.delta_e_percent(ref[1], ref[0]),)
    for value, printed in zip(ref, (e_h, e_m, delta)):
        assert abs(value - float(printed)) <= 0.5 * 10.0 ** -len(printed.split(".")[1])


def test_restitution_laws_match_the_papers_formulas():
    """Over slenderness 1/sqrt(2) to 20: measured agreement 0 (Housner, absolute), 2.2e-16
    (Mao, relative), 0 (the percentage, relative); a few units in the last place allowed."""
    worst = [0.0, 0.0, 0.0]
    for hb in np.linspace(1.0 / math.sqrt(2.0), 20.0, 97):
        thc = math.atan(hb)
        eh, em = float(model.e_housner(thc)), float(model.e_mao(thc))
        worst[0] = max(worst[0], abs(eh - ph.e_housner(thc)))
        worst[1] = max(worst[1], abs(em / ph.e_mao(thc) - 1.0))
        if hb > 0.72:  # e_H > 0
            d = float(model.delta_e_percent(em, eh))
            worst[2] = max(worst[2], abs(d / ph.delta_e_percent(em, eh) - 1.0))
    assert worst[0] <= 2e-15 and worst[1] <= 2e-15 and worst[2] <= 2e-15, worst
    # the Block picks the law it is given
    for hb in (1.0, 2.0):
        thc = math.atan(hb)
        assert Block(hb, "housner").restitution == pytest.approx(ph.e_housner(thc), rel=1e-14)
        assert Block(hb, "mao").restitution == pytest.approx(ph.e_mao(thc), rel=1e-14)


# ---------------------------------------------------------------------------------------------
# equations of motion, jump, saltation, uplift
# ---------------------------------------------------------------------------------------------

def _random_states(n, seed=RNG_SEED):
    """``n`` states on both corners: (theta, theta', f, side, thc, xi), theta of the side's
    sign (and some at theta = 0), slenderness 0.75 to 5, damping up to 0.5."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        side = 1 if i % 2 else -1
        theta = 0.0 if i % 7 == 0 else side * rng.uniform(0.0, 0.5 * math.pi)
        out.append((theta, rng.uniform(-3.0, 3.0), rng.uniform(-5.0, 5.0), side,
                    math.atan(rng.uniform(0.75, 5.0)), rng.uniform(0.0, 0.5)))
    return out


def test_accel_matches_the_corner_equations():
    """``model.accel`` (compiled) against the two corner equations written out, at 400 random
    states: measured 8.9e-16 of max(1, |theta''|). At rest (side 0) it is zero."""
    worst = 0.0
    for th, dth, f, side, thc, xi in _random_states(400):
        a = model.accel(th, dth, f, side, thc, xi)
        b = ph.theta_ddot(th, dth, f, side, thc, xi)
        worst = max(worst, abs(a - b) / max(1.0, abs(b)))
    assert worst <= 1e-14, worst
    assert model.accel(0.0, 0.0, 3.0, 0, 0.7, 0.1) == 0.0


def test_accel_jac_matches_partials_and_finite_differences():
    """``model.accel_jac`` (d/dtheta, d/dtheta', d/df) against the derivatives by hand
    (measured 7.8e-16 relative) and against central differences of the independent
    ``theta_ddot`` and of ``model.accel`` itself, step 1e-5 (measured 9.5e-11 and 8.6e-11)."""
    h = 1e-5
    worst = [0.0, 0.0, 0.0]
    for th, dth, f, side, thc, xi in _random_states(200, RNG_SEED + 1):
        jac = np.array(model.accel_jac(th, dth, f, side, thc, xi))
        exact = np.array(ph.theta_ddot_partials(th, dth, f, side, thc, xi))
        worst[0] = max(worst[0], np.abs(jac - exact).max() / max(1.0, np.abs(exact).max()))
        for k, fun in ((1, ph.theta_ddot), (2, model.accel)):
            fd = []
            for j in range(3):
                d = np.zeros(3)
                d[j] = h
                up = fun(th + d[0], dth + d[1], f + d[2], side, thc, xi)
                dn = fun(th - d[0], dth - d[1], f - d[2], side, thc, xi)
                fd.append((up - dn) / (2.0 * h))
            worst[k] = max(worst[k], np.abs(jac - np.array(fd)).max())
    assert worst[0] <= 1e-14 and worst[1] <= 1e-9 and worst[2] <= 1e-9, worst
    assert model.accel_jac(0.3, 0.1, 2.0, 0, 0.7, 0.1) == (0.0, 0.0, 0.0)


def test_saltation_matches_muellers_formula():
    """``model.saltation`` (the lower-left entry of S) and ``model.jump`` against Müller's
    S = [[e, 0], [(A+ - e A-) / theta'-, e]] built from the independent accelerations, at 400
    impacts on either corner: measured 1.2e-15 of max(1, |S10|); the closed form
    3/4 [(1 - e) f sin(thc) - sgn(theta'-)(1 + e) cos(thc)] / theta'- (damping cancels) too
    (1.4e-15)."""
    rng = np.random.default_rng(RNG_SEED + 2)
    worst = [0.0, 0.0]
    for _ in range(400):
        side = int(rng.choice([-1, 1]))
        dm = -side * rng.uniform(0.01, 3.0)  # arriving at theta = 0 from the side's sign
        f, thc = rng.uniform(-5.0, 5.0), math.atan(rng.uniform(0.75, 5.0))
        xi, e = rng.uniform(0.0, 0.5), rng.uniform(0.0, 1.0)
        S = ph.saltation_matrix(dm, f, side, thc, xi, e)
        s10 = model.saltation(dm, f, side, thc, xi, e)
        closed = 0.75 * ((1 - e) * f * math.sin(thc)
                         - math.copysign(1.0, dm) * (1 + e) * math.cos(thc)) / dm
        worst[0] = max(worst[0], abs(s10 - S[1, 0]) / max(1.0, abs(S[1, 0])))
        worst[1] = max(worst[1], abs(closed - S[1, 0]) / max(1.0, abs(S[1, 0])))
        assert model.jump(dm, e) == ph.jump(dm, e) == e * dm
    assert worst[0] <= 2e-14 and worst[1] <= 2e-14, worst


def test_saltation_of_a_law_that_depends_on_the_impact_matches_muellers_formula():
    """The saltation matrix of the speed-softened law, ``S = G + (F+ - G F-) n^T / (n^T F-)``
    with the jump's Jacobian ``G = diag(1, g'(theta'-))`` of ``g(v) = e(v) v`` taken by central
    differences of the reference's law (:func:`physics.at_impact`), against
    ``model.saltation_at`` with the coefficient and slope of ``rockjit.laws.impact``, at 300
    impacts: ``S[1, 0]`` to 1e-8 (the differences' own error) and the coefficient exactly."""
    from rockjit.laws.impact import restitution_at
    kind, shape = Block(1.0, "speed").impact_law
    rng = np.random.default_rng(RNG_SEED + 5)
    worst = 0.0
    for _ in range(300):
        side = int(rng.choice([-1, 1]))
        dm = -side * rng.uniform(0.01, 3.0)
        f, thc, xi = rng.uniform(-5.0, 5.0), math.atan(rng.uniform(0.75, 5.0)), rng.uniform(0, 0.5)
        e = ph.e_housner(thc)
        h = 1e-6 * abs(dm)
        g = lambda v: ph.at_impact("speed", e, v) * v  # noqa: E731
        slope = (g(dm + h) - g(dm - h)) / (2 * h)
        a_minus = ph.theta_ddot(0.0, dm, f, side, thc, xi)
        a_plus = ph.theta_ddot(0.0, g(dm), f, -side, thc, xi)
        s10_ref = (a_plus - slope * a_minus) / dm
        e_imp, e_slope = restitution_at(int(kind), abs(dm), e, shape)
        assert e_imp == pytest.approx(ph.at_impact("speed", e, dm), rel=1e-15)
        assert e_slope == pytest.approx(slope, rel=1e-8)
        s10 = model.saltation_at(dm, f, side, thc, xi, e_imp, e_slope)
        worst = max(worst, abs(s10 - s10_ref) / max(1.0, abs(s10_ref)))
    assert worst <= 1e-8, worst


def test_uplift_time_matches_a_brute_force_scan():
    """``harmonic.uplift_time`` against a scan of |f(t)| > cot (step T/400, then bisection to
    rounding), at 300 random starts: measured 5.2e-15 of T. Edge cases: lifted already (t
    itself), a forcing that reaches the threshold but never exceeds it, and one below it
    (inf)."""
    rng = np.random.default_rng(RNG_SEED + 3)
    worst = 0.0
    for _ in range(300):
        omega = rng.uniform(0.3, 3.0)
        cot = 1.0 / rng.uniform(0.75, 5.0)
        aw2 = cot * rng.uniform(1.001, 4.0)
        phi = rng.uniform(-math.pi, math.pi)
        t0 = rng.uniform(0.0, 50.0)
        got = harmonic.uplift_time(t0, aw2, cot, omega, phi)
        ref = ph.first_uplift(t0, aw2, omega, phi, cot)
        worst = max(worst, abs(got - ref) / (2 * math.pi / omega))
        assert got >= t0
    assert worst <= 5e-14, worst
    # already above the threshold: leaves at once
    t0 = 0.5 * math.pi / 1.3  # f at its crest
    assert harmonic.uplift_time(t0, 1.5, 1.0, 1.3, 0.0) == t0 == ph.first_uplift(t0, 1.5, 1.3,
                                                                                 0.0, 1.0)
    # |f| reaches cot at its crests but never exceeds it, or stays below: never lifted
    for aw2 in (1.0, 0.999):
        assert harmonic.uplift_time(0.3, aw2, 1.0, 1.0, 0.0) == math.inf
        assert ph.first_uplift(0.3, aw2, 1.0, 0.0, 1.0) == math.inf


# ---------------------------------------------------------------------------------------------
# whole runs against the slow reference integrator
# ---------------------------------------------------------------------------------------------

PERIODS = 15

#: The runs: (rockjit.simulate keywords, initial state z0).
RUNS = {
    # the study's reference symmetric run (period 1, two impacts a period)
    "symmetric": (dict(hb=1.0, alpha=0.6, omega=1.3, law="housner"), Z0),
    # its asymmetric run
    "asymmetric": (dict(hb=1.0, alpha=0.8, omega=1.3, law="housner"), Z0),
    # the study's Housner-vs-Mao comparison, Mao's law, from its third start (a transient that
    # expands errors about a thousandfold over the 15 periods)
    "mao": (dict(hb=2.0, alpha=0.2, omega=1.6, law="mao"), (0.3535, -0.3333, 0.0, 1.0)),
    # the damped block from a small tilt: nine impacts, a Zeno cut-off, at rest for good
    "rest": (dict(hb=1.0, alpha=0.15, omega=1.0, law="housner"), (0.05, 0.0, 0.0, 1.0)),
    # from rest, lifted every half period just past the threshold, back to rest each time
    # (seven impacts and a Zeno cut-off): 30 uplifts and 30 rests
    "uplift": (dict(hb=1.0, alpha=0.6, omega=1.3, law="housner"), (0.0, 0.0, 0.0, 1.0)),
    # a law that depends on the impact (Housner's coefficient softened at fast impacts):
    # the study's start into its period-1 orbit, two impacts a period
    "speed": (dict(hb=1.0, alpha=0.8, omega=1.3, law="speed"), Z0),
}

#: The paths compared: rockjit.simulate's steps per period and method.
METHODS = {
    "compiled": dict(n_steps=None, method="rockjit"),  # the default grid, N = 160
    "compiled-N640": dict(n_steps=640, method="rockjit"),
    "scipy-DOP853": dict(n_steps=None, method=Scipy("DOP853", rtol=1e-12, atol=1e-12)),
}


def _run(kw, z0, *, periods, n_steps=None, method="rockjit", **more):
    """``rockjit.simulate`` of a block ``kw`` (hb, alpha, omega, law) from ``z0``
    ``(theta, theta', r, s)``."""
    return rockjit.simulate(Block(kw["hb"], kw["law"]),
                            Harmonic(alpha=kw["alpha"], omega=kw["omega"], r0=z0[2], s0=z0[3]),
                            tuple(z0[:2]), integration=Integration(periods=periods,
                                                                   n_steps=n_steps, **more),
                            method=method)

#: Tolerance on impact times, impact speeds and strobe samples, about 10x the largest of the
#: three differences measured (in brackets) over the 15 periods.
RUN_TOL = {
    ("symmetric", "compiled"): 1e-10,        # 8.8e-12
    ("symmetric", "compiled-N640"): 1e-12,   # 5.7e-14
    ("symmetric", "scipy-DOP853"): 2e-11,    # 1.8e-12
    ("asymmetric", "compiled"): 1e-9,        # 6.5e-11
    ("asymmetric", "compiled-N640"): 2e-12,  # 1.7e-13
    ("asymmetric", "scipy-DOP853"): 3e-10,   # 2.9e-11
    ("mao", "compiled"): 2e-6,               # 1.7e-7 (the transient's expansion, see RUNS)
    ("mao", "compiled-N640"): 4e-9,          # 3.8e-10
    ("mao", "scipy-DOP853"): 8e-6,           # 8.0e-7
    ("rest", "compiled"): 4e-10,             # 3.7e-11
    ("rest", "compiled-N640"): 1e-12,        # 5.5e-14
    ("rest", "scipy-DOP853"): 1.5e-9,        # 1.05e-10
    ("uplift", "compiled"): 3e-10,           # 2.4e-11
    ("uplift", "compiled-N640"): 2e-12,      # 1.7e-13
    ("uplift", "scipy-DOP853"): 2e-9,        # 1.5e-10
    ("speed", "compiled"): 4e-10,            # 3.9e-11
    ("speed", "compiled-N640"): 1e-12,       # 7.1e-14
    ("speed", "scipy-DOP853"): 1e-10,        # 9.7e-12
}


@functools.lru_cache(maxsize=None)
def _reference(name):
    kw, z0 = RUNS[name]
    return ph.reference_run(kw["hb"], kw["alpha"], kw["omega"], law=kw["law"], xi=XI,
                            theta0=z0[0], dtheta0=z0[1], phi=math.atan2(z0[2], z0[3]),
                            periods=PERIODS)


@pytest.mark.parametrize("method", list(METHODS))
@pytest.mark.parametrize("name", list(RUNS))
def test_run_matches_the_independent_integrator(name, method):
    kw, z0 = RUNS[name]
    ref = _reference(name)
    r = _run(kw, z0, periods=PERIODS, **METHODS[method])
    tol = RUN_TOL[name, method]
    assert r.status == ref.status
    assert r.n_impacts == len(ref.impacts) == len(r.impacts)
    assert r.n_rest == len(ref.rests)
    d_imp = np.abs(r.impacts - ref.impacts).max(initial=0.0)
    assert len(r.strobe) == len(ref.strobe)
    d_strobe = np.abs(r.strobe[:, :2] - ref.strobe).max()
    assert max(d_imp, d_strobe) <= tol, (d_imp, d_strobe)
    # the forcing's phase at the samples: r = sin(omega kT + phi), s = cos(...)
    psi = kw["omega"] * r.period * np.arange(len(r.strobe)) + math.atan2(z0[2], z0[3])
    assert np.abs(r.strobe[:, 2] - np.sin(psi)).max() <= 1e-12
    assert np.abs(r.strobe[:, 3] - np.cos(psi)).max() <= 1e-12
    if ref.status == "rest":
        # at rest for good from the last impact on
        assert abs(r.t - ref.t) <= tol
        assert ref.t == ref.impacts[-1, 0] == ref.rests[-1]
    else:
        assert np.abs(r.state[:2] - ref.state).max() <= tol
    if name == "uplift":
        assert len(ref.uplifts) == 2 * PERIODS  # the run did exercise the uplift


# ---------------------------------------------------------------------------------------------
# Floquet multipliers against a finite-difference monodromy
# ---------------------------------------------------------------------------------------------

#: Orbits: (rockjit.simulate keywords, initial state whose settled strobe is on the cycle,
#: period p, the forcing phase). All hb = 1 Housner at omega = 1.3 from the study's z0, but the
#: Mao one (hb = 2, from the third start of the study's comparison, phase 0).
ATTRACTORS = {
    "p1-symmetric": (dict(hb=1.0, alpha=0.6, omega=1.3, law="housner"), Z0, 1),
    "p1-asymmetric": (dict(hb=1.0, alpha=0.8, omega=1.3, law="housner"), Z0, 1),
    "p1-mao": (dict(hb=2.0, alpha=0.2, omega=1.6, law="mao"), (0.3535, -0.3333, 0.0, 1.0), 1),
    # the stable period-2 orbit of the doubling cascade: |mu| = 0.2074, 7.3e-5
    "p2": (dict(hb=1.0, alpha=0.92, omega=1.3, law="housner"), Z0, 2),
    # a stable period-3 window of the sweep (alpha = 0.946; period 6 at 0.9465): mu = -0.482
    "p3": (dict(hb=1.0, alpha=0.946, omega=1.3, law="housner"), Z0, 3),
    # the speed-softened law's period-1 orbit: the saltation matrix carries d(e(v) v)/dv
    "p1-speed": (dict(hb=1.0, alpha=0.8, omega=1.3, law="speed"), Z0, 1),
}

#: Tolerances of the Floquet comparisons, by period. The finite-difference Jacobian's own error
#: dominates (truncation, and each reference run's ~1e-14 of round-off over the step
#: 2h = 6e-6 |x|) and grows with the length of the runs: against a converged tangent
#: integration (N = 4096) over 17 cycles at several phases it was at most 8.8e-10 in an entry
#: and 9.5e-10 in a multiplier for period 1, 2.1e-9 and 1.7e-9 for period 2, 9e-9 and 1.4e-8
#: for period 3, scattered from case to case as round-off is. Each tolerance is 10x those.
#: rockjit's multipliers in the cases below differed from the finite differences' by 3e-11 to
#: 4.3e-10 (period 1), 3e-10 and 2e-9 (period 2), 2.2e-9 and 8.6e-9 (period 3); the tangent
#: matrices' entries by 1.1e-10 to 6.5e-10, 1e-9 to 1.7e-9, 1.5e-9 to 4.7e-9. (A dropped period,
#: a sign in the saltation matrix, moves the multipliers by 1e-2 or more.)
MULT_TOL = {1: 1e-8, 2: 2e-8, 3: 1.5e-7}
MATRIX_TOL = {1: 1e-8, 2: 2e-8, 3: 1e-7}


def _params(kw, phi):
    return dict(hb=kw["hb"], alpha=kw["alpha"], omega=kw["omega"], law=kw["law"], xi=XI,
                phi=phi)


@functools.lru_cache(maxsize=None)
def _settled(name):
    """The attractor's cycle point at t = kT after 600 periods, and the reference's
    Jacobian of P^p there."""
    kw, z0, p = ATTRACTORS[name]
    r = _run(kw, z0, periods=600)
    s = r.strobe[:, :2]
    size = np.abs(s[-p:]).max()
    assert np.abs(s[-1] - s[-1 - p]).max() <= 1e-10 * size  # settled on period p ...
    if p > 1:
        assert np.abs(s[-1] - s[-2]).max() >= 1e-2 * size  # ... and not on period 1
    x = s[-1].copy()
    phi = math.atan2(z0[2], z0[3])
    M, y = ph.monodromy_fd(x, p, **_params(kw, phi))
    return x, phi, M, y


@pytest.mark.parametrize("name", list(ATTRACTORS))
def test_floquet_multipliers_match_the_finite_difference_monodromy(name):
    """``rockjit.attractors.floquet`` at the attractor's cycle point: its multipliers, matched
    pairwise as complex numbers with the eigenvalues of the reference's Jacobian of ``P^p``;
    and the tangent matrix it is computed from, entry by entry; its exponents
    ``ln|mu| / (pT)``."""
    kw, _, p = ATTRACTORS[name]
    x, phi, M, y = _settled(name)
    block = Block(kw["hb"], kw["law"])
    forcing = Harmonic(alpha=kw["alpha"], omega=kw["omega"])
    T = 2.0 * math.pi / kw["omega"]
    mu_fd = np.linalg.eigvals(M)
    mu, lam = floquet(block, forcing, phi, Integration(), 160, x, p)
    assert ph.match_pairs(mu, mu_fd) <= MULT_TOL[p], (mu, mu_fd)
    if name == "p2":  # the value an independent monodromy gave when floquet's loop was broken
        assert abs(np.abs(mu).max() - 0.2074) <= 0.5e-4
    np.testing.assert_allclose(np.sort(lam), np.sort(np.log(np.abs(mu_fd)) / (p * T)),
                               rtol=0, atol=MULT_TOL[p] / np.abs(mu_fd).min() / (p * T))
    r = rockjit.simulate(block, forcing.replace(phase=phi), (x[0], x[1]),
                         integration=Integration(periods=p, n_steps=160, qr_every=0),
                         lyapunov=True)
    assert np.abs(r.extra["tangent"] - M).max() <= MATRIX_TOL[p]
    # the reference agrees the point is on the cycle (measured 1.2e-12 to 7.6e-11: the
    # settled point of the N = 160 run)
    assert np.abs(y - x).max() <= 1e-9


#: Orbits found by rockjit.orbits.periodic_orbit: the attractors above, and an unstable one,
#: the asymmetric period-1 orbit at alpha = 0.92 past its period doubling (mu = -1.189),
#: seeded from the asymmetric attractor at alpha = 0.9.
ORBITS = list(ATTRACTORS) + ["p1-unstable"]


def _orbit_case(name):
    if name != "p1-unstable":
        kw, _, p = ATTRACTORS[name]
        x, phi, _, _ = _settled(name)
        return kw, x, p, phi
    kw = dict(hb=1.0, alpha=0.92, omega=1.3, law="housner")
    seed = _run({**kw, "alpha": 0.9}, Z0, periods=600).strobe[-1, :2]
    return kw, seed, 1, PHI0


@pytest.mark.parametrize("name", ORBITS)
def test_periodic_orbit_multipliers_match_the_finite_difference_monodromy(name):
    """``rockjit.orbits.periodic_orbit``: its point is a fixed point of the reference's
    ``P^p`` (measured residual 1.5e-14 to 8.5e-13) and its multipliers, matched pairwise, are
    the eigenvalues of the reference's Jacobian of ``P^p`` there; so is its monodromy matrix,
    entry by entry, when its section is the requested phase (no impact near it)."""
    kw, seed, p, phi = _orbit_case(name)
    orb = periodic_orbit(Block(kw["hb"], kw["law"]),
                         Harmonic(alpha=kw["alpha"], omega=kw["omega"], phase=phi), seed, p)
    assert orb.period == p
    params = _params(kw, phi)
    M, y = ph.monodromy_fd(orb.state, p, **params)
    assert np.abs(y - orb.state).max() <= 1e-11
    mu_fd = np.linalg.eigvals(M)
    assert ph.match_pairs(orb.multipliers, mu_fd) <= MULT_TOL[p], (orb.multipliers, mu_fd)
    assert orb.section_phase == phi  # no impact near the requested section in these cases
    assert np.abs(orb.monodromy - M).max() <= MATRIX_TOL[p]
    assert orb.stable == (np.abs(mu_fd).max() < 1.0)
    if name == "p1-unstable":
        assert not orb.stable and np.abs(mu_fd).max() > 1.1
