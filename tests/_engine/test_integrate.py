"""The compiled integrator (rockjit._engine.integrate) against things that do not come from it.

- the Dormand–Prince tableau against the Runge–Kutta order conditions, generated here from the
  rooted trees (Butcher), for the 5th-order weights, the embedded 4th-order weights and the
  continuous extension;
- the empirical order of the fixed-step integrator against a tight scipy DOP853 solution on an
  impact-free segment;
- the tangent (variational + saltation) Jacobian against central finite differences of the
  flow across impacts;
- exact physics: energy conservation of undamped, unforced, elastic rocking;
- rest and uplift: the scipy path and the closed-form uplift instant (conftest), and an
  independent solve_ivp from that instant;
- the 4-D oscillator embedding against the closed-form forcing and against the oscillator's
  exact solution off the unit circle.
"""

import math
from fractions import Fraction

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic, Integration, Scipy
from rockjit._engine import integrate as ig
from rockjit._engine.kernel import pack
from rockjit.model import accel

DOP = Scipy("DOP853", rtol=1e-12, atol=1e-12)


# ---- the tableau ------------------------------------------------------------------------------

def _canon(tree):
    return tuple(sorted(_canon(c) for c in tree))


def _grow(tree):
    """All trees with one more node, attached anywhere in ``tree``."""
    yield _canon(tree + ((),))
    for i, child in enumerate(tree):
        for g in _grow(child):
            yield _canon(tree[:i] + (g,) + tree[i + 1:])


def _trees(max_order):
    """Rooted trees up to ``max_order``; a tree is the sorted tuple of its subtrees."""
    out = {1: {()}}
    for n in range(2, max_order + 1):
        out[n] = {g for t in out[n - 1] for g in _grow(t)}
    return out


def _order(tree):
    return 1 + sum(_order(c) for c in tree)


def _gamma(tree):
    g = _order(tree)
    for c in tree:
        g *= _gamma(c)
    return g


def _phi(tree, A):
    """Elementary weight vector: Phi_i(t) = prod over subtrees u of sum_j a_ij Phi_j(u)."""
    v = np.ones(A.shape[0])
    for c in tree:
        v = v * (A @ _phi(c, A))
    return v


TREES = _trees(6)


def _tableau():
    """The 7-stage (FSAL) tableau: A padded square with the last row B, C with 1 appended."""
    A = np.zeros((7, 7))
    A[:6, :ig.A.shape[1]] = ig.A
    A[6, :6] = ig.B
    C = np.append(ig.C, 1.0)
    b = np.append(ig.B, 0.0)
    return A, C, b


def test_tree_count():
    # 1, 1, 2, 4, 9, 20 rooted trees of orders 1..6: the generator is complete
    assert [len(TREES[n]) for n in range(1, 7)] == [1, 1, 2, 4, 9, 20]


def test_tableau_shapes_and_simplifying_identities():
    A, C, b = _tableau()
    assert ig.C.shape == (6,) and ig.B.shape == (6,) and ig.E.shape == (7,)
    assert ig.P.shape == (7, 4)
    np.testing.assert_allclose(A.sum(axis=1), C, rtol=0, atol=1e-15)  # row sums are C
    assert ig.B.sum() == pytest.approx(1.0, abs=1e-15)
    assert ig.E.sum() == pytest.approx(0.0, abs=1e-15)
    assert np.all(np.triu(A) == 0.0)  # explicit
    assert ig.C[0] == 0.0


@pytest.mark.parametrize("order", [1, 2, 3, 4, 5])
def test_fifth_order_weights_satisfy_order_conditions(order):
    A, _, b = _tableau()
    for tree in TREES[order]:
        assert b @ _phi(tree, A) == pytest.approx(1.0 / _gamma(tree), rel=1e-14, abs=1e-15), tree


def test_fifth_order_weights_are_not_sixth_order():
    A, _, b = _tableau()
    misses = [abs(b @ _phi(t, A) - 1.0 / _gamma(t)) for t in TREES[6]]
    assert max(misses) > 1e-5  # the test above could fail: not everything satisfies it


def test_quadrature_conditions_spelled_out():
    # sum b_i c_i^(k-1) = 1/k, k = 1..5, and the two classic order-3/4 tree conditions
    A, C, b = _tableau()
    for k in range(1, 6):
        assert b @ C ** (k - 1) == pytest.approx(1.0 / k, rel=1e-14)
    assert b @ (A @ C) == pytest.approx(1 / 6, rel=1e-14)
    assert b @ (A @ C**2) == pytest.approx(1 / 12, rel=1e-14)
    assert b @ (C * (A @ C)) == pytest.approx(1 / 8, rel=1e-14)
    assert b @ (A @ (A @ C)) == pytest.approx(1 / 24, rel=1e-14)


def test_embedded_weights_are_fourth_order():
    """scipy's convention: the error estimate is h K^T E with E = b_hat - b (7 entries)."""
    A, _, b = _tableau()
    b_hat = b + ig.E
    # Dormand & Prince (1980), Table 2, the 4th-order row, in exact fractions
    dp4 = [Fraction(5179, 57600), 0, Fraction(7571, 16695), Fraction(393, 640),
           Fraction(-92097, 339200), Fraction(187, 2100), Fraction(1, 40)]
    np.testing.assert_allclose(b_hat, [float(x) for x in dp4], rtol=1e-14, atol=1e-16)
    for order in range(1, 5):
        for tree in TREES[order]:
            assert b_hat @ _phi(tree, A) == pytest.approx(1.0 / _gamma(tree), rel=1e-13), tree
    misses = [abs(b_hat @ _phi(t, A) - 1.0 / _gamma(t)) for t in TREES[5]]
    assert max(misses) > 1e-5  # genuinely 4th order, so E is a genuine error estimate


def test_dense_output_reproduces_the_step_and_is_fourth_order():
    A, _, b = _tableau()
    # at x = 1 the continuous extension is the step itself
    np.testing.assert_allclose(ig.P.sum(axis=1), b, rtol=0, atol=1e-14)
    # b_i(x) = sum_k P[i, k] x^(k+1) (scipy's RK45 dense output) satisfies the continuous order
    # conditions sum_i b_i(x) Phi_i(t) = x^|t| / gamma(t) up to order 4
    for x in (0.1, 0.37, 0.5, 0.81):
        bx = ig.P @ x ** np.arange(1, 5)
        for order in range(1, 5):
            for tree in TREES[order]:
                assert bx @ _phi(tree, A) == pytest.approx(x**order / _gamma(tree),
                                                           rel=1e-12, abs=1e-15), (x, tree)


# ---- empirical order on an impact-free segment --------------------------------------------------

def test_empirical_order_is_five():
    # slender block (hb=2) thrown up on its corner: no impact within the one period
    run = (Block(hb=2.0, law="housner"), Harmonic(alpha=0.02, omega=5.0, phase=0.3), (0.2, 0.5))
    ref = rockjit.simulate(*run, integration=Integration(periods=1),
                           method=Scipy("DOP853", rtol=1e-13, atol=1e-14))
    assert ref.n_impacts == 0 and ref.status == "done"
    ns = np.array([12, 16, 24, 32, 48, 64])
    errs = []
    for n in ns:
        r = rockjit.simulate(*run, integration=Integration(periods=1, n_steps=int(n)))
        assert r.n_impacts == 0 and r.status == "done"
        errs.append(np.abs(r.state[:2] - ref.state[:2]).max())
    errs = np.array(errs)
    assert errs[-1] > 1e-13  # well above the reference's own error (~1e-15 here)
    slope = -np.polyfit(np.log(ns), np.log(errs), 1)[0]
    assert 4.7 <= slope <= 5.6, (slope, errs)
    # the embedded estimate is an error indicator of the same size as the step's local error
    assert r.max_error_estimate > 0.0


# ---- one step, against a readable reference step ------------------------------------------

def _reference_dp5_step(spec, t, y, h, side, hb, aw2, omega, phi, xi):
    """One Dormand–Prince step written plainly (tableau from rockjit, field from conftest's equations)."""
    k = []
    for i in range(7):
        if i == 0:
            yi = np.array(y, dtype=float)
        else:
            a = ig.A[i] if i < 6 else ig.B
            yi = np.array(y, dtype=float) + h * sum(a[j] * k[j] for j in range(i))
        ti = t + (ig.C[i] if i < 6 else 1.0) * h
        k.append(np.array([yi[1], spec.theta_ddot(ti, yi[0], yi[1], side, hb, aw2, omega, phi,
                                                  xi)]))
        if i == 6:
            return yi


@pytest.mark.parametrize("theta0, dtheta0, n", [
    (0.3, -0.4, 64),    # every stage within the polynomials' ranges (the fast path)
    (0.05, 2.5, 16),    # stages more than NEAR_RANGE from the start: redone afresh
    (1.55, 5.0, 8),     # stages beyond |theta| = 1.75: the step is redone with libm's sines
    (-1.6, -6.0, 8),
])
def test_one_step_matches_a_plain_reference_step(spec, theta0, dtheta0, n):
    hb, alpha, omega, xi = 1.0, 0.6, 1.3, 0.01
    blk = Block(hb=hb, xi=xi)
    phi = 0.4
    p = pack(blk, Harmonic(alpha=alpha, omega=omega), phi, Integration(), n)
    par = np.zeros(ig.N_PARW)
    par[:ig.N_PAR] = p
    par[ig.P_STHC], par[ig.P_CTHC] = math.sin(blk.thc), math.cos(blk.thc)
    side = 1 if theta0 > 0 else -1
    h = p[ig.P_H]
    y = np.array([theta0, dtheta0])
    K = np.zeros((ig.N_STAGES + 1, 2))
    tab = np.zeros((ig.N_TAB, ig.N_STAGES + 1))
    fr, jac = np.zeros(ig.N_STAGES + 1), np.zeros(ig.N_STAGES + 1)
    ytmp, ynew = np.zeros(2), np.zeros(2)
    ig.step_table(omega, h, tab)
    trig = np.zeros(4)
    ig.rhs(None, math.sin(phi), y, side, par, K, jac, trig)
    ig.rk_step(None, None, False, math.sin(phi), math.cos(phi), y, K, side, par, ytmp, ynew,
               tab, fr, jac, trig)
    want = _reference_dp5_step(spec, 0.0, y, h, side, hb, alpha * omega**2, omega, phi, xi)
    # the cases test what they say: the fast path, a stage far from the start, beyond 1.75
    assert (abs(ynew[0] - theta0) > 0.3) == (n <= 16)
    assert (max(abs(theta0), abs(ynew[0])) > 1.75) == (abs(theta0) > 1.5)
    np.testing.assert_allclose(ynew, want, rtol=1e-13, atol=1e-14)


# ---- the flow's Jacobian across impacts: tangent dynamics and saltation ---------------------

# (hb, law, omega, alpha, theta0, dtheta0, phase): one period with 1-3 impacts, no rest
SALTATION_CASES = [
    (1.0, "housner", 6.0, 0.02, 0.1, -0.6, 2.0),
    (1.0, "housner", 4.0, 0.05, -0.1, 0.5, 0.4),
    (1.0, "mao", 6.0, 0.02, 0.1, -0.6, 2.0),
    (1.0, "mao", 4.0, 0.05, 0.1, -0.5, 0.4),
    (1.0, "mao", 4.0, 0.05, -0.1, 0.5, 0.4),
    (2.0, "housner", 4.0, 0.05, 0.1, -0.5, 0.4),
    (2.0, "housner", 4.0, 0.05, -0.1, 0.5, 0.4),
    (2.0, "mao", 4.0, 0.05, 0.1, -0.5, 0.4),
    (2.0, "mao", 4.0, 0.05, -0.1, 0.5, 0.4),
]


@pytest.mark.parametrize("hb, law, omega, alpha, th0, dth0, phase", SALTATION_CASES)
def test_tangent_matches_finite_differences_across_impacts(hb, law, omega, alpha, th0, dth0,
                                                           phase):
    block, forcing = Block(hb=hb, law=law), Harmonic(alpha=alpha, omega=omega, phase=phase)
    one = Integration(periods=1)

    def flow(x):
        return rockjit.simulate(block, forcing, (x[0], x[1]), integration=one)

    r = rockjit.simulate(block, forcing, (th0, dth0), lyapunov=True,
                         integration=one.replace(qr_every=0, window=0))
    assert r.status == "done" and r.n_rest == 0 and 1 <= r.n_impacts <= 3
    V = r.extra["tangent"]
    eps = 1e-6
    x = np.array([th0, dth0])
    J = np.empty((2, 2))
    for j in range(2):
        d = np.zeros(2)
        d[j] = eps
        rp, rm = flow(x + d), flow(x - d)
        # the perturbation must not change the hybrid itinerary
        assert rp.n_impacts == rm.n_impacts == r.n_impacts
        J[:, j] = (rp.state[:2] - rm.state[:2]) / (2 * eps)
    assert np.abs(J - V).max() <= 1e-6 * np.abs(V).max(), (J, V)
    # and the product of the impacts' determinants e^2 shows up (det S = e^2, docs/theory/exponents.md)
    e = r.block.restitution
    assert abs(np.linalg.det(V)) == pytest.approx(
        e ** (2 * r.n_impacts) * math.exp(-0.75 * r.block.xi * r.t), rel=1e-8)


# ---- exact physics: free elastic rocking conserves energy -----------------------------------

@pytest.mark.parametrize("hb", [1.0, 2.0])
def test_free_elastic_rocking_conserves_energy(hb):
    thc = math.atan(hb)
    th0, dth0 = 0.15, 0.0
    # alpha = 0: omega only sets the grid, h = 2 pi / (5 * DEFAULT_N)
    r = rockjit.simulate(Block(hb, e=1.0, xi=0.0), Harmonic(alpha=0.0, omega=5.0), (th0, dth0),
                         integration=Integration(periods=1900, max_impacts=5000),
                         record_stride=5)
    assert r.status == "done" and r.n_impacts >= 1000

    def energy(th, dth):
        return 0.5 * dth**2 + 0.75 * np.sin(thc + np.abs(th))

    e0 = energy(th0, dth0)
    assert np.abs(energy(r.strobe[:, 0], r.strobe[:, 1]) / e0 - 1).max() < 1e-10
    traj = r.trajectory
    assert len(traj) == 1900 * rockjit.DEFAULT_N // 5 + 1
    assert np.abs(energy(traj[:, 1], traj[:, 2]) / e0 - 1).max() < 1e-10
    speeds = np.abs(r.impacts[:, 1])
    v0 = math.sqrt(2 * (e0 - 0.75 * math.sin(thc)))  # the impact speed, from the energy
    assert np.abs(speeds / v0 - 1).max() < 1e-10
    assert np.array_equal(r.impacts[:, 1], r.impacts[:, 2])  # e = 1: the jump is the identity
    # impacts alternate direction
    assert np.all(np.sign(r.impacts[1:, 1]) == -np.sign(r.impacts[:-1, 1]))


# ---- Zeno, rest and uplift (docs/theory/impacts.md) ---------------------------------------------------------

def test_zeno_cascade_comes_to_rest():
    # hb = 2: cot(thc) = 0.5 > alpha omega^2 = 0.3: once at rest the block stays there
    run = (Block(hb=2.0, law="housner"), Harmonic(alpha=0.3 / 9.0, omega=3.0), (0.05, 0.0))
    r = rockjit.simulate(*run, integration=Integration(periods=50))
    s = rockjit.simulate(*run, integration=Integration(periods=50), method=DOP)
    assert r.status == s.status == "rest"
    assert r.n_impacts == s.n_impacts < 1000
    # bounded work: 50 periods on the grid would cost 50 * 160 * 6 = 48000 evaluations
    assert r.n_rhs < 20_000
    assert r.t == pytest.approx(s.t, abs=1e-8)
    assert r.t < 50 * r.period
    np.testing.assert_array_equal(r.state[:2], [0.0, 0.0])
    np.testing.assert_allclose(r.impacts[:, 0], s.impacts[:, 0], rtol=0, atol=1e-8)
    # the cascade: each flight shorter than the last, speeds falling by e
    assert np.all(np.diff(r.impacts[-10:, 0]) > 0)
    np.testing.assert_allclose(r.impacts[:, 2], r.block.restitution * r.impacts[:, 1],
                               rtol=1e-15)


@pytest.mark.parametrize("phase", [0.0, math.pi, 4.0, 1.5])
def test_uplift_from_rest_at_the_analytic_instant(spec, phase):
    hb, omega, aw2 = 2.0, 3.0, 0.6  # above the uplift threshold cot(thc) = 0.5
    alpha = aw2 / omega**2
    r = rockjit.simulate(Block(hb=hb, law="housner"),
                         Harmonic(alpha=alpha, omega=omega, phase=phase), (0.0, 0.0),
                         integration=Integration(periods=1), record_stride=1)
    t_u, side = spec.first_uplift(0.0, aw2, 1.0 / hb, omega, phase)
    assert r.n_impacts >= 1
    traj = r.trajectory
    before = traj[:, 0] <= t_u
    np.testing.assert_array_equal(traj[before, 1:3], 0.0)  # at rest up to t_u
    t_imp = r.impacts[0, 0]
    flight = (traj[:, 0] > t_u) & (traj[:, 0] < t_imp)
    assert flight.sum() > 10
    assert np.all(np.sign(traj[flight, 1]) == side)  # on the side of the sign of f
    # an independent integration from (t_u, 0, 0) on that side: same flight, same landing
    ref = spec.run(hb, alpha, omega, spec.e_housner(hb), theta0=0.0, dtheta0=0.0,
                   phi=phase, t0=t_u, side=side, t_end=t_imp + 0.5, xi=r.block.xi,
                   max_impacts=1, dense=True)
    assert ref["impacts"][0, 0] == pytest.approx(t_imp, abs=1e-9)
    _, _, sol = ref["segments"][0]
    np.testing.assert_allclose(traj[flight, 1], sol(traj[flight, 0])[0], rtol=0, atol=1e-10)


def test_release_after_zeno_rest(spec):
    # hb = 1 at alpha omega^2 = 1.014 > cot(thc) = 1: the block comes to rest (Zeno) and is
    # lifted again, over and over. Each departure is at the analytic uplift instant after the rest.
    hb, alpha, omega, phase = 1.0, 0.6, 1.3, 2.5
    r = rockjit.simulate(Block(hb, "housner"), Harmonic(alpha=alpha, omega=omega, phase=phase),
                         (-0.2254, -0.1597), integration=Integration(periods=6))
    e = spec.e_housner(hb)
    rests = np.nonzero(np.abs(r.impacts[:, 2]) < 1e-6)[0]
    assert len(rests) >= 3
    aw2 = alpha * omega**2
    for i in rests[:4]:
        t_u, side = spec.first_uplift(r.impacts[i, 0], aw2, 1.0 / hb, omega, phase)
        ref = spec.run(hb, alpha, omega, e, theta0=0.0, dtheta0=0.0, phi=phase, t0=t_u,
                       side=side, t_end=r.impacts[i + 1, 0] + 0.5, xi=r.block.xi,
                       max_impacts=1)
        assert ref["impacts"][0, 0] == pytest.approx(r.impacts[i + 1, 0], abs=1e-9)
        assert ref["impacts"][0, 1] == pytest.approx(r.impacts[i + 1, 1], rel=1e-8)


# ---- the oscillator embedding (docs/theory/model.md) ---------------------------------------------------

EMBED_CASES = [
    (1.0, 0.6, 1.3, "housner", 0.0),
    (1.0, 0.6, 1.3, "housner", 1.0),
    (1.0, 0.6, 1.3, "housner", 2.5),        # with rests and uplifts
    (1.0, 0.6, 1.3, "housner", -2.0),       # overturns
    (2.0, 0.2, 1.6, "mao", math.atan2(-0.7778, 0.6284)),
    (1.0, 0.8, 1.3, "housner", -0.9),
]


@pytest.mark.parametrize("hb, alpha, omega, law, phase", EMBED_CASES)
def test_embedded_forcing_matches_closed_form(hb, alpha, omega, law, phase):
    block, state = Block(hb=hb, law=law), (-0.2254, -0.1597)
    closed = Harmonic(alpha=alpha, omega=omega, r0=math.sin(phase), s0=math.cos(phase))
    integration = Integration(periods=20, n_steps=512)
    a = rockjit.simulate(block, closed, state, integration=integration)
    b = rockjit.simulate(block, closed.replace(embedded=True), state, integration=integration)
    assert a.status == b.status
    assert a.n_impacts == b.n_impacts and a.n_rest == b.n_rest
    np.testing.assert_allclose(a.impacts[:, 0], b.impacts[:, 0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.state, b.state, rtol=0, atol=1e-9)
    np.testing.assert_allclose(a.strobe, b.strobe, rtol=0, atol=1e-9)
    assert a.t == pytest.approx(b.t, abs=1e-9)


def test_embedding_off_the_circle_follows_the_oscillator_exactly():
    # r = rho sin(omega t + phi), s = rho cos(omega t + phi), rho' = rho (1 - rho^2):
    # rho(t) = (1 + (1/rho0^2 - 1) exp(-2 t))^(-1/2)
    omega, r0, s0 = 1.6, 0.3, -0.2
    r = rockjit.simulate(Block(2.0, "housner"),
                         Harmonic(alpha=0.2, omega=omega, r0=r0, s0=s0, embedded=True), (0.1, 0.0),
                         integration=Integration(periods=5))
    rho0 = math.hypot(r0, s0)
    phi = math.atan2(r0, s0)
    t = np.arange(len(r.strobe)) * r.period
    rho = 1.0 / np.sqrt(1.0 + (1.0 / rho0**2 - 1.0) * np.exp(-2.0 * t))
    np.testing.assert_allclose(r.strobe[:, 2], rho * np.sin(omega * t + phi), atol=1e-9)
    np.testing.assert_allclose(r.strobe[:, 3], rho * np.cos(omega * t + phi), atol=1e-9)
    with pytest.raises(ValueError, match="r0"):  # the closed form lives on the circle
        Harmonic(alpha=0.2, omega=omega, r0=r0, s0=s0, embedded=False)


# ---- bookkeeping --------------------------------------------------------------------------------

def test_impact_bound_is_its_own_status():
    run = (Block(1.0, "housner"), Harmonic(alpha=0.6, omega=1.3))
    r = rockjit.simulate(*run, integration=Integration(periods=20, max_impacts=7))
    full = rockjit.simulate(*run, integration=Integration(periods=20))
    assert full.n_impacts > 7
    assert r.status == "max_impacts" and r.n_impacts == 7 and len(r.impacts) == 7
    np.testing.assert_array_equal(r.impacts, full.impacts[:7])
    assert r.t == full.impacts[6, 0]


def test_overturn_threshold_is_a_parameter(spec):
    # a tilted slender block falls over the threshold theta_over = 0.3
    run = (Block(hb=2.0, law="housner"), Harmonic(alpha=0.0, omega=1.6))
    integration = Integration(periods=2, theta_over=0.3)
    # theta0 = 0.5 is already past the threshold: refused, as on the command line
    with pytest.raises(ValueError, match=r"theta0\) must satisfy \|state\[0\] \(theta0\)\| < "
                                         r"theta_over = 0\.3"):
        rockjit.simulate(*run, (0.5, 0.2), integration=integration)
    r = rockjit.simulate(*run, (0.25, 0.2), integration=integration)
    ref = spec.run(2.0, 0.0, 1.6, spec.e_housner(2.0), theta0=0.25, dtheta0=0.2, phi=0.0,
                   t_end=2 * r.period, xi=r.block.xi, theta_over=0.3)
    assert r.status == ref["status"] == "overturned"
    assert r.t == pytest.approx(ref["t"], abs=1e-10)
    assert r.state[0] == pytest.approx(0.3, abs=1e-12)


def test_coarse_grid_does_not_miss_short_flights():
    # after each impact the flights get shorter until many fit in one grid step: with N = 16
    # every one of them must still be found (two crossings in one step), as the scipy path does
    run = (Block(hb=1.0, e=0.6, xi=0.0), Harmonic(alpha=0.0, omega=1.3), (0.05, 0.0))
    r = rockjit.simulate(*run, integration=Integration(periods=3, n_steps=16))
    s = rockjit.simulate(*run, integration=Integration(periods=3), method=DOP)
    h = r.period / 16
    assert np.sum(np.diff(r.impacts[:, 0]) < h) >= 5  # there are flights shorter than a step
    assert r.status == s.status == "rest"
    assert r.n_impacts == s.n_impacts
    # N = 16 is coarse (h = 0.3): the impact times carry its O(h^5) error, ~2e-6 here
    np.testing.assert_allclose(r.impacts[:, 0], s.impacts[:, 0], rtol=0, atol=1e-5)
    assert np.all(np.diff(np.sign(r.impacts[:, 1])) != 0)  # the corners alternate


@pytest.mark.parametrize("th0, dth0", [(0.001, -0.05), (0.0005, -0.03), (0.002, -0.06)])
def test_dip_through_zero_within_one_step_is_found(spec, th0, dth0):
    # theta > 0 at both ends of a coarse step (h = 0.3) but it dips through 0 in between: the
    # forcing (f = 2 > cot(thc) = 1) turns the block back. Two impacts hide inside that step.
    alpha, omega, phase = 2.0 / 1.3**2, 1.3, 0.5 * math.pi
    r = rockjit.simulate(Block(hb=1.0, law="housner"),
                         Harmonic(alpha=alpha, omega=omega, phase=phase), (th0, dth0),
                         integration=Integration(periods=1, n_steps=16))
    ref = spec.run(1.0, alpha, omega, spec.e_housner(1.0), theta0=th0, dtheta0=dth0, phi=phase,
                   xi=r.block.xi, t_end=r.period, max_step=1e-3)
    h = r.period / 16
    assert ref["impacts"][1, 0] < h  # the first two impacts lie in the first step
    assert r.status == ref["status"]
    assert r.n_impacts == len(ref["impacts"])
    # coarse grid: the 3rd impact carries the O(h^5) error of N = 16
    np.testing.assert_allclose(r.impacts[:, 0], ref["impacts"][:, 0], rtol=0, atol=1e-5)
    np.testing.assert_allclose(r.impacts[:2, 0], ref["impacts"][:2, 0], rtol=0, atol=1e-9)


def test_default_impact_bound_scales_with_the_periods(spec):
    """A fixed bound of 100,000 impacts (~2 a period) stopped 200,000-period runs half way.
    60,000 periods of the study's symmetric orbit run to the end, with its two impacts a period
    throughout: the latest impacts half a period apart, alternating in sign, at Housner's
    restitution (conftest's formula), and the last sample on the orbit found independently,
    the fixed point of tests/physics.py's stroboscopic map (measured 1.5e-10 off at N = 64;
    the impacts' spacing 1.1e-10 off T/2)."""
    import physics as ph
    r = rockjit.simulate(Block(1.0, "housner"), Harmonic(alpha=0.6, omega=1.3),
                         integration=Integration(periods=60_000, n_steps=64))
    T = 2 * math.pi / 1.3
    assert r.status == "done" and r.n_impacts == 2 * 60_000
    assert abs(r.t - 60_000 * T) <= 1e-9 * r.t
    last = r.impacts[-6:]
    np.testing.assert_allclose(np.diff(last[:, 0]), T / 2, rtol=0, atol=1e-9)
    np.testing.assert_allclose(last[:, 2], spec.e_housner(1.0) * last[:, 1], rtol=1e-14)
    assert np.all(last[1:, 1] * last[:-1, 1] < 0)
    x = r.strobe[-1, :2].copy()
    params = dict(hb=1.0, alpha=0.6, omega=1.3, law="housner", xi=Block(1.0).xi,
                  phi=math.atan2(r.strobe[0, 2], r.strobe[0, 3]))
    for _ in range(4):  # Newton on the independent map P, from the run's last sample
        M, y = ph.monodromy_fd(x, 1, **params)
        x = x - np.linalg.solve(M - np.eye(2), y - x)
    assert np.abs(ph.strobe_map(x, 1, **params)[0] - x).max() <= 1e-12
    assert np.abs(r.strobe[-1, :2] - x).max() <= 1e-9


def test_impact_record_keeps_the_latest_impacts_in_order(monkeypatch):
    from rockjit._engine import kernel as kernel
    run = (Block(1.0, "housner"), Harmonic(alpha=0.6, omega=1.3))
    full = rockjit.simulate(*run, integration=Integration(periods=40))
    assert full.n_impacts > 57
    monkeypatch.setattr(kernel, "IMPACT_RECORD", 57)  # a ring of 57 rows
    r = rockjit.simulate(*run, integration=Integration(periods=40))
    assert r.n_impacts == full.n_impacts and r.impacts.shape == (57, 3)
    np.testing.assert_array_equal(r.impacts, full.impacts[-57:])


# ---- the study's rule: a run goes on past overturning -------------------------------------------

@pytest.mark.parametrize("alpha", [0.59, 0.72])
def test_continuing_past_overturn_matches_the_scipy_path(alpha):
    # Mao, hb = 1, omega = 1.3: the block falls within two periods, turns over a few times and
    # settles on a bounded orbit (non-chaotic at these amplitudes): both paths, tight, agree
    run = (Block(hb=1.0, law="mao"), Harmonic(alpha=alpha, omega=1.3))
    on = Integration(periods=50, stop_at_overturn=False)
    r = rockjit.simulate(*run, integration=on.replace(n_steps=1024))
    s = rockjit.simulate(*run, integration=on, method=Scipy("DOP853", rtol=1e-13, atol=1e-13))
    assert r.status == s.status == "done"
    assert np.abs(r.strobe[:, 0]).max() > 0.5 * np.pi  # it did go past the threshold
    assert r.t_overturn == pytest.approx(s.t_overturn, abs=1e-10)
    np.testing.assert_allclose(r.strobe[:, :2], s.strobe[:, :2], rtol=0, atol=1e-8)
    stopped = rockjit.simulate(*run, integration=on.replace(n_steps=1024,
                                                            stop_at_overturn=True))
    assert stopped.status == "overturned" and stopped.t == pytest.approx(r.t_overturn, abs=1e-12)
    assert np.isnan(stopped.t_overturn)
    assert rockjit.classify_result(r) == ("overturn", 0)  # the study's rule: it fell once


@pytest.mark.parametrize("want_max", [True, False])
def test_turning_point_is_the_derivatives_root(want_max):
    """The extension's turning point (an apex, or the bottom of a grazing dip) is the root of its
    derivative, a cubic, that the step's ends bracket: checked against numpy's polynomial roots
    on random bracketing cubics, and against plain bisection when the ends do not bracket."""
    rng = np.random.default_rng(17)
    checked = 0
    for _ in range(2000):
        q = rng.normal(size=4) * 10.0 ** rng.uniform(-3, 3, size=4)
        sgn = rng.choice([-1.0, 1.0])
        coeffs = sgn * np.array([q[0], 2 * q[1], 3 * q[2], 4 * q[3]])  # d(x), ascending powers
        d0, d1 = coeffs[0], coeffs.sum()
        x = ig.turning_point(q[0], q[1], q[2], q[3], sgn, want_max)
        assert 0.0 <= x <= 1.0
        if ((d0 >= 0) == want_max) and ((d1 >= 0) != want_max):
            roots = np.roots(coeffs[::-1])
            real = roots[(abs(roots.imag) < 1e-9) & (roots.real >= 0) & (roots.real <= 1)].real
            scale = np.abs(coeffs).sum()
            # a root where the derivative crosses the wanted way, to round-off
            slope = np.polyval(np.polyder(coeffs[::-1]), x)
            assert abs(np.polyval(coeffs[::-1], x)) <= 1e-12 * scale or \
                np.min(abs(real - x)) <= 1e-9, (q, sgn, x, real)
            assert (slope <= 0) == want_max or abs(slope) <= 1e-9 * scale
            checked += 1
        else:
            lo, hi = 0.0, 1.0
            for _ in range(ig.BISECT_ITERS):
                mid = 0.5 * (lo + hi)
                if (np.polyval(coeffs[::-1], mid) >= 0) == want_max:
                    lo = mid
                else:
                    hi = mid
            assert abs(x - 0.5 * (lo + hi)) <= 1e-12
    assert checked > 200  # about a fifth of random cubics are bracketed


# ---- the event interpolant ------------------------------------------------------------------

def _exact(spec, t0, y0, t1, side, hb, aw2, omega, phi, xi, event=False):
    """A tight DOP853 solution of the equation of motion (docs/theory/model.md) on one corner from ``(t0, y0)`` to ``t1``: the state
    there, or with ``event`` the first ``theta = 0`` (its time and state)."""
    from scipy.integrate import solve_ivp

    def f(t, y):
        return [y[1], spec.theta_ddot(t, y[0], y[1], side, hb, aw2, omega, phi, xi)]

    ev = None
    if event:
        def ev(t, y):
            return y[0]
        ev.terminal = True
    sol = solve_ivp(f, (t0, t1), y0, method="DOP853", rtol=2.5e-14, atol=1e-16, events=ev)
    if event:
        return sol.t_events[0][0], sol.y_events[0][0]
    return sol.y[:, -1]


class _Step:
    """One compiled Dormand–Prince step of length ``T / n`` from ``(t0, y0)`` on corner ``side``
    (closed-form forcing), with what the event interpolant reads: the stages, the sines and
    cosines of theta at the ends, the forcing and its derivative at the ends."""

    def __init__(self, hb, alpha, omega, phi, t0, y0, n, side):
        block = Block(hb=hb)
        self.block = block
        self.par = np.zeros(ig.N_PARW)
        self.par[:ig.N_PAR] = pack(block, Harmonic(alpha=alpha, omega=omega), phi,
                                   Integration(), n)
        self.par[ig.P_STHC] = math.sin(block.thc)
        self.par[ig.P_CTHC] = math.cos(block.thc)
        self.h = h = self.par[ig.P_H]
        self.side, self.t0, self.phi = side, t0, phi
        self.aw2, self.omega = alpha * omega**2, omega
        sp, cp = math.sin(omega * t0 + phi), math.cos(omega * t0 + phi)
        self.sp, self.cp = sp, cp
        self.y = np.array(y0, dtype=float)
        self.K = np.zeros((ig.N_STAGES + 1, 2))
        self.jac = np.zeros(ig.N_STAGES + 1)
        self.trig = np.zeros(4)
        self.fr = np.zeros(ig.N_STAGES + 1)
        self.tab = np.zeros((ig.N_TAB, ig.N_STAGES + 1))
        self.ynew = np.zeros(2)
        ig.rhs(None, sp, self.y, side, self.par, self.K, self.jac, self.trig)
        ig.step_table(omega, h, self.tab)
        ig.rk_step(None, None, False, sp, cp, self.y, self.K, side, self.par, np.zeros(2),
                   self.ynew, self.tab, self.fr, self.jac, self.trig)
        aw3 = self.aw2 * omega
        self.fd = (self.fr[0], aw3 * cp, self.fr[ig.N_STAGES],
                   aw3 * math.cos(omega * (t0 + h) + phi))

    def with_end(self, y1):
        """The same step with its end state replaced (``K[-1]`` and the end's sines too)."""
        other = _Step.__new__(_Step)
        other.__dict__.update(self.__dict__)
        other.ynew = np.array(y1, dtype=float)
        other.K = self.K.copy()
        other.trig = self.trig.copy()
        other.K[ig.N_STAGES, 0] = y1[1]
        other.K[ig.N_STAGES, 1] = accel(y1[0], y1[1], self.fr[ig.N_STAGES], self.side,
                                        self.block.thc, self.block.xi)
        other.trig[2], other.trig[3] = math.sin(y1[0]), math.cos(y1[0])
        return other

    def at(self, x):
        """theta, theta' and the error estimate of the step's interpolant at ``x``."""
        return ig.interp_at(self.y, self.ynew, self.h, self.K, self.side, self.par, self.trig,
                            *self.fd, x)

    def locate(self, interp=True):
        """The impact in the step: ``(ok, tau, theta'(tau))`` on the interpolant, or by genuine
        steps (``ok`` None)."""
        if interp:
            ok, x, _, v = ig.locate_interp(ig.EV_IMPACT, self.y, self.ynew, self.h, 0.0, self.h,
                                           self.K, self.side, self.par, self.trig, *self.fd)
            return ok, x * self.h, v
        yev = np.zeros(2)
        tau = ig.locate_step(None, None, ig.EV_IMPACT, self.y, self.h, 0.0, self.h,
                             self.K.copy(), self.side, self.par, np.zeros(2), yev,
                             np.zeros(ig.N_IOUT, dtype=np.int64), self.tab.copy(),
                             self.fr.copy(), self.jac.copy(), self.trig.copy(), self.sp,
                             self.cp, -1.0)
        return None, tau, yev[1]


#: A slender block thrown up on its corner: no impact within one period (as in the test of the
#: empirical order above).
SMOOTH = dict(hb=2.0, alpha=0.02, omega=5.0, phi=0.3, y0=(0.2, 0.5), side=1)


def _smooth_errors(spec, n, exact_end, x):
    kw = SMOOTH
    st = _Step(kw["hb"], kw["alpha"], kw["omega"], kw["phi"], 0.0, kw["y0"], n, kw["side"])
    ex = lambda t: _exact(spec, 0.0, kw["y0"], t, kw["side"], kw["hb"], st.aw2, kw["omega"],
                          kw["phi"], st.block.xi)
    if exact_end:
        st = st.with_end(ex(st.h))
    th, v, est = st.at(x)
    ref = ex(x * st.h)
    return abs(th - ref[0]), abs(v - ref[1]), est


def _slope(ns, errs):
    return -np.polyfit(np.log(ns), np.log(errs), 1)[0]


@pytest.mark.parametrize("x", [0.3, 0.62])
def test_interpolant_is_of_degree_seven_through_exact_ends(spec, x):
    # with the exact state at the step's end, what is left is the interpolation error of the
    # two Hermite polynomials of degree 7: of order h^8
    ns = np.array([8, 12, 16, 24])
    e = np.array([_smooth_errors(spec, n, True, x)[:2] for n in ns])
    assert e[-1].max() > 1e-14  # above the reference's own error
    assert _slope(ns, e[:, 0]) >= 7.4, e[:, 0]
    assert _slope(ns, e[:, 1]) >= 7.4, e[:, 1]


def test_interpolant_carries_the_steps_own_error(spec):
    # with the step's own end state: the end's local error, of order h^6, weighted by the
    # basis function of the end value, so of order h^6 within the step as well
    ns = np.array([16, 24, 32, 48])
    e = np.array([_smooth_errors(spec, n, False, 0.5)[:2] for n in ns])
    assert 5.4 <= _slope(ns, e[:, 0]) <= 6.6, e[:, 0]
    assert 5.4 <= _slope(ns, e[:, 1]) <= 6.6, e[:, 1]


@pytest.mark.parametrize("n", [32, 64, 128])
def test_interpolant_error_estimate_tracks_its_error(spec, n):
    # the estimate (the end value's defect weighted, plus the septic less the quintic) is of the
    # size of the interpolant's true error in theta: neither far below (it would trust a bad
    # interpolant) nor far above (it would send every event to genuine steps)
    ratios = []
    for x in (0.25, 0.5, 0.75):
        th_err, _, est = _smooth_errors(spec, n, False, x)
        ratios.append(est / th_err)
    assert 0.5 <= min(ratios) and max(ratios) <= 4.0, ratios


#: States a little before an impact on the event test's asymmetric orbit's block.
EVENT_BLOCK = dict(hb=1.0, alpha=0.8, omega=1.3, phi=0.4)


@pytest.mark.parametrize("n, tol", [(64, 1e-10), (160, 1e-12)])
@pytest.mark.parametrize("frac, dth0, t0", [(0.6, -0.45, 0.3), (0.25, -0.12, 2.1),
                                            (0.9, 0.7, 4.0)])
def test_event_on_the_interpolant_against_dop853(spec, n, tol, frac, dth0, t0):
    # from an exact state, one step with an impact (about ``frac`` of the way): the time and
    # speed of the impact on the interpolant against a tight DOP853 event from the same state
    # (the local error only: the step's own, ~1e-11 at N = 64 and ~1e-13 at N = 160), and the
    # time's error within the interpolant's own estimate (theta's, over the crossing speed)
    kw = EVENT_BLOCK
    block = Block(hb=kw["hb"])
    T = Harmonic(alpha=kw["alpha"], omega=kw["omega"]).period
    th0 = -dth0 * frac * T / n
    side = 1 if th0 > 0 else -1
    aw2 = kw["alpha"] * kw["omega"] ** 2
    t_ev, y_ev = _exact(spec, t0, (th0, dth0), t0 + T / n, side, kw["hb"], aw2, kw["omega"],
                        kw["phi"], block.xi, event=True)
    st = _Step(kw["hb"], kw["alpha"], kw["omega"], kw["phi"], t0, (th0, dth0), n, side)
    assert side * st.ynew[0] < 0.0  # the impact lies in the step
    ok, tau, v = st.locate()
    assert ok == 1
    assert abs(t0 + tau - t_ev) <= tol
    assert abs(v - y_ev[1]) <= tol
    assert abs(t0 + tau - t_ev) <= 2.0 * st.at(tau / st.h)[2] / abs(v) + 1e-15
    # the genuine steps (a step of the event's own length) agree to the same level
    _, tau_g, v_g = st.locate(interp=False)
    assert abs(tau_g - tau) <= tol and abs(v_g - v) <= tol


def test_coarse_steps_take_genuine_steps_where_the_estimate_says_so():
    # the interpolant is trusted from N = 64 on on the event test's orbits; at N = 16 the
    # estimate sends most events to genuine steps, which keep the event times of the coarse
    # grid as they were (tests above: the dips through 0 at N = 16 to 1e-9)
    run = (Block(1.0, "housner"), Harmonic(alpha=0.8, omega=1.3))  # the study's state

    def resteps(**integration):
        return rockjit.simulate(*run, integration=Integration(periods=20, **integration))

    assert resteps(n_steps=64).extra["locate_resteps"] == 0
    assert resteps().extra["locate_resteps"] == 0
    coarse = resteps(n_steps=16)
    assert coarse.extra["locate_resteps"] > coarse.n_impacts // 2
