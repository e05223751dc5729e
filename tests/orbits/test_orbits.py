"""Periodic orbits (rockjit.orbits): shooting, continuation and bifurcations against independent
references: plain and scipy runs, finite differences, Lyapunov exponents, brute-force sweeps."""

import math

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic, Integration, orbits
from rockjit.orbits import ContinuationSettings, OrbitRefused, Shooting

HB, OMEGA = 1.0, 1.3
T = 2 * math.pi / OMEGA
BLOCK = Block(hb=HB, law="housner")
SWEEP_FORCING = Harmonic(omega=OMEGA)


def forcing(alpha, phase=0.0):
    return Harmonic(alpha=alpha, omega=OMEGA, phase=phase)


def settle(alpha, x0=(0.1, 0.0), periods=400):
    """A plain long run at phase 0: the attractor's stroboscopic point (an independent seed)."""
    r = rockjit.simulate(BLOCK, forcing(alpha), x0, integration=Integration(periods=periods))
    assert r.status == "done"
    return r.strobe[-1, :2]


def plain(x, alpha, p, phase=0.0, n_steps=4096, record_stride=None):
    return rockjit.simulate(BLOCK, forcing(alpha, phase), (x[0], x[1]),
                            integration=Integration(periods=p, n_steps=n_steps),
                            record_stride=record_stride)


@pytest.fixture(scope="module")
def asym08():
    """The study's asymmetric orbit (alpha = 0.8), stable, real multipliers."""
    return orbits.periodic_orbit(BLOCK, forcing(0.8), settle(0.8) + 0.01, 1)


@pytest.fixture(scope="module")
def sym085():
    """The symmetric orbit continued past its pitchfork: unstable (seeded from alpha = 0.75)."""
    seed = orbits.periodic_orbit(BLOCK, forcing(0.75), settle(0.75), 1)
    assert seed.symmetric and seed.stable
    return orbits.periodic_orbit(BLOCK, forcing(0.85), seed.state, 1)


@pytest.fixture(scope="module")
def study():
    """The hb=1 Housner branches over [0.5, 1.0] from a sweep's attractors."""
    sw = rockjit.sweep(BLOCK, SWEEP_FORCING, rockjit.alpha_grid((0.5, 1.0), 0.002))
    return sw, orbits.continue_branches(BLOCK, SWEEP_FORCING, (0.5, 1.0), sweep=sw)


def of_type(cont, kind, period=None, lo=-math.inf, hi=math.inf):
    return [b for b in cont.bifurcations if b.type == kind and lo <= b.alpha <= hi
            and (period is None or b.period == period)]


# --------------------------------------------------------------------------- shooting

@pytest.mark.parametrize("alpha,p,x0", [(0.8, 1, (0.1, 0.0)), (0.92, 2, (0.1, 0.0)),
                                         (0.6, 1, (0.3, 0.0))])
def test_fixed_point_confirmed_by_a_converged_plain_run(alpha, p, x0):
    o = orbits.periodic_orbit(BLOCK, forcing(alpha), settle(alpha, x0) + 0.005, p)
    assert o.residual <= 1e-11
    # an independent run (no tangent vectors, 16x finer grid) over p periods
    r = plain(o.state, alpha, p)
    assert np.abs(r.strobe[p, :2] - o.state).max() <= 1e-10
    # the cycle's points are the stroboscopic samples of that run
    assert np.abs(r.strobe[:p, :2] - o.cycle).max() <= 1e-10
    assert np.abs(r.strobe_half[:p, :2] - o.cycle_half).max() <= 1e-10
    assert o.impacts == r.n_impacts


def test_unstable_orbit_converges_and_is_unstable(sym085):
    o = sym085
    assert o.symmetric and not o.stable
    mu = o.multipliers[0]
    assert abs(mu.imag) == 0 and 1.2 < mu.real < 1.7
    r = plain(o.state, 0.85, 1)
    assert np.abs(r.strobe[1, :2] - o.state).max() <= 1e-10
    assert np.abs(r.strobe_half[0, :2] + o.state).max() <= 1e-10   # x(T/2) = -x(0)
    # independent: a small perturbation grows by mu per period (the other multiplier, 3e-3,
    # has wiped out its other component after a few periods)
    far = plain(o.state + 1e-10 * np.array([1.0, 0.3]), 0.85, 30, n_steps=256)
    d = np.abs(far.strobe[:, :2] - o.state).max(axis=1)
    rate = (d[30] / d[10]) ** (1 / 20)
    assert abs(rate - abs(mu)) <= 1e-4 * abs(mu)


def test_multipliers_against_scipy_finite_differences(asym08, sym085):
    for o in (asym08, sym085):
        h = 1e-5
        M = np.empty((2, 2))
        for i in range(2):
            cols = []
            for sgn in (1, -1):
                x = o.state.copy()
                x[i] += sgn * h
                r = rockjit.simulate(o.block, o.forcing, x, integration=Integration(periods=1),
                                     method=rockjit.Scipy("DOP853", rtol=1e-12, atol=1e-12))
                assert r.n_impacts == o.impacts
                cols.append(r.strobe[1, :2])
            M[:, i] = (cols[0] - cols[1]) / (2 * h)
        mu = np.sort_complex(np.linalg.eigvals(M))
        # (measured: 4e-10; central differences of the scipy path at rtol 1e-12)
        assert np.allclose(mu, np.sort_complex(o.multipliers), rtol=0, atol=1e-8 * max(
            1.0, abs(o.multipliers[0])))


def test_det_monodromy_identity(asym08, sym085):
    # docs/theory/exponents.md: lambda1 + lambda2 = -3/4 xi + 2 nu ln e, i.e. over one cycle
    # det M = e^(2 n) exp(-3/4 xi p T), n impacts per cycle
    for o in (asym08, sym085):
        b = o.block
        expect = b.restitution ** (2 * o.impacts) * math.exp(-0.75 * b.xi * o.period * T)
        assert abs(np.prod(o.multipliers).real - expect) <= 1e-10 * expect


def test_lyapunov_exponents_equal_log_multipliers(asym08):
    o = asym08
    assert o.forcing == Harmonic(alpha=0.8, omega=OMEGA, phase=o.phase)
    r = rockjit.simulate(o.block, o.forcing, o.state,
                         integration=Integration(periods=300, n_steps=o.n_steps, window=100),
                         lyapunov=True)
    assert r.status == "done"
    lam = np.log(np.abs(o.multipliers)) / T
    assert np.allclose(r.lyapunov, lam, rtol=0, atol=1e-10)
    assert np.allclose(o.lyapunov, lam)


def test_phase_is_the_section_and_states_match_a_trajectory(asym08):
    # the same orbit sampled at another forcing phase, on the grid of a plain run: phase
    # 2 pi j / N is the instant t = j T / N
    o = asym08
    j, n = 37, 4096
    o2 = orbits.periodic_orbit(BLOCK, forcing(0.8, 2 * math.pi * j * 16 / n), o.state, 1)
    assert np.allclose(np.sort(np.abs(o2.multipliers)), np.sort(np.abs(o.multipliers)),
                       rtol=1e-8)
    r = plain(o.state, 0.8, 1, record_stride=16, n_steps=n)
    assert np.abs(r.trajectory[j, 1:3] - o2.state).max() <= 1e-10


# --------------------------------------------------------------------------- refusals

def test_refusals():
    with pytest.raises(OrbitRefused) as e:
        orbits.periodic_orbit(BLOCK, forcing(0.8), (1.4, 2.0))
    assert e.value.reason == "overturn"
    assert plain((1.4, 2.0), 0.8, 1, n_steps=256).status == "overturned"
    with pytest.raises(OrbitRefused) as e:
        orbits.periodic_orbit(BLOCK, forcing(0.4), (0.05, 0.0))
    assert e.value.reason == "rest"
    assert plain((0.05, 0.0), 0.4, 1, n_steps=256).status == "rest"
    with pytest.raises(OrbitRefused) as e:
        orbits.periodic_orbit(BLOCK, forcing(0.65), (0.01, 0.0))
    assert e.value.reason == "passes_through_rest"
    assert plain((0.01, 0.0), 0.65, 1, n_steps=256).n_rest > 0


def test_bad_input():
    with pytest.raises(ValueError, match="p must be"):
        orbits.periodic_orbit(BLOCK, forcing(0.8), (0.1, 0.1), 0)
    with pytest.raises(ValueError, match="x0"):
        orbits.periodic_orbit(BLOCK, forcing(0.8), (0.1, 0.1, 0.2))
    with pytest.raises(ValueError, match="x0 must be finite"):
        orbits.periodic_orbit(BLOCK, forcing(0.8), (0.1, math.nan))
    with pytest.raises(ValueError, match="n_steps must be even"):
        orbits.periodic_orbit(BLOCK, forcing(0.8), (0.1, 0.1), n_steps=255)
    with pytest.raises(ValueError, match="block must be a rockjit.Block"):
        orbits.periodic_orbit(0.8, forcing(0.8), (0.1, 0.1))
    with pytest.raises(ValueError, match="parameter must be"):
        orbits.continuation(BLOCK, forcing(0.8), [], parameter="xi", bounds=(0.5, 1.0))
    with pytest.raises(ValueError, match="alpha_range"):
        orbits.continue_branches(BLOCK, SWEEP_FORCING, (1.0, 0.5), seeds=[])
    with pytest.raises(ValueError, match=r"seeds\[0\]"):
        orbits.continuation(BLOCK, forcing(0.8), [(0.8, (0.1,), 1)], bounds=(0.5, 1.0))
    # the excitation: alpha and omega for one orbit, no alpha where it is continued
    with pytest.raises(ValueError, match="needs the excitation's alpha"):
        orbits.periodic_orbit(BLOCK, SWEEP_FORCING, (0.1, 0.1))
    with pytest.raises(ValueError, match="sweeps alpha itself"):
        orbits.continue_branches(BLOCK, forcing(0.8), (0.5, 1.0), seeds=[])
    with pytest.raises(ValueError, match="closed-form"):
        orbits.periodic_orbit(BLOCK, Harmonic(alpha=0.8, omega=OMEGA, embedded=True),
                              (0.1, 0.1))
    # the settings objects, validated where they are made
    with pytest.raises(ValueError, match="graze_tol must be in"):
        Shooting(graze_tol=1.5)
    with pytest.raises(ValueError, match="tol must be > 0"):
        Shooting(tol=0)
    with pytest.raises(ValueError, match="need ds_min <= ds0 <= ds_max"):
        ContinuationSettings(ds_max=1e-3)
    with pytest.raises(ValueError, match="max_period must be"):
        ContinuationSettings(max_period=0)
    with pytest.raises(ValueError, match="settings must be"):
        orbits.continuation(BLOCK, forcing(0.8), [], bounds=(0.5, 1.0), settings=dict(ds0=1))


# --------------------------------------------------------------------------- continuation

def test_period_doubling_where_the_sweeps_period_two_window_opens(study):
    sw, cont = study
    pd = of_type(cont, "period_doubling", 1, 0.85, 0.95)
    assert len(pd) == 1
    a = pd[0].alpha
    assert 0.90 < a < 0.92  # the gallery's period-2 orbit (alpha = 0.92) lies just beyond
    # a brute-force sweep from the study's z0 on either side of it
    near = rockjit.sweep(BLOCK, SWEEP_FORCING, [a - 0.004, a - 0.002, a + 0.002, a + 0.004])
    assert list(near.period) == [1, 1, 2, 2]
    # the doubled branch was switched onto and is stable beyond the point
    br = cont.branches[pd[0].new_branch]
    assert br.period == 2 and br.parent == pd[0].branch
    k = int(np.argmin(np.abs(br.value - (a + 0.004))))
    assert br.stable[k]


def test_bifurcations_bracketed_by_their_neighbours(study):
    _, cont = study
    crit = {"fold": 1.0, "symmetry_breaking": 1.0, "period_doubling": -1.0}
    seen = 0
    for b in cont.bifurcations:
        if b.type not in crit or not b.located:
            continue
        seen += 1
        c = crit[b.type]
        # the test function det(M - c I) = prod(mu - c) changes sign between the neighbours
        f = [np.prod(np.asarray(mu) - c).real for mu in b.neighbour_multipliers]
        assert f[0] * f[1] < 0, b
        # and a multiplier sits on c at the located point
        assert np.min(np.abs(np.asarray(b.multipliers) - c)) <= 1e-6, b
        lo, hi = sorted(b.neighbours)
        if b.type == "fold":
            # a turning point: the branch's neighbours both lie on one side
            assert not lo < b.alpha < hi or min(hi - b.alpha, b.alpha - lo) < 1e-6
        else:
            assert lo <= b.alpha <= hi
    assert seen >= 8


def test_located_to_1e8_by_independent_shooting(study):
    """Re-solve the orbit 2e-8 to either side of the located alpha: the critical multiplier is
    on either side of -1 (period doubling) or +1 (symmetry breaking)."""
    _, cont = study
    for b in of_type(cont, "period_doubling", 1) + of_type(cont, "period_doubling", 2) + \
            of_type(cont, "symmetry_breaking", 1):
        c = -1.0 if b.type == "period_doubling" else 1.0
        side = []
        for da in (-2e-8, 2e-8):
            o = orbits.periodic_orbit(BLOCK, forcing(b.alpha + da, cont.phase), b.state,
                                      b.period, shooting=Shooting(graze_tol=0))
            assert o.symmetric == (b.type == "symmetry_breaking")
            mu = o.multipliers[np.argmin(np.abs(o.multipliers - c))]
            side.append(np.sign(abs(mu.real) - 1.0))
        assert side[0] * side[1] < 0, b


def test_symmetry_breaking_near_078(study):
    sw, cont = study
    sb = of_type(cont, "symmetry_breaking", 1, 0.7, 0.85)
    assert len(sb) == 1
    a = sb[0].alpha
    assert abs(a - 0.78) < 0.005
    assert sb[0].new_branch is not None and not cont.branches[sb[0].new_branch].symmetric
    # independent: plain runs from the symmetric orbit, slightly perturbed, settle on a
    # symmetric orbit below the point and on an asymmetric one above it
    for da, want in ((-0.005, "symmetric"), (0.005, "asymmetric")):
        o = orbits.periodic_orbit(BLOCK, forcing(a + da, cont.phase), sb[0].state, 1)
        assert o.symmetric and o.stable == (da < 0)
        r = rockjit.simulate(BLOCK, forcing(a + da, cont.phase),
                             (o.state[0] + 1e-6, o.state[1]),
                             integration=Integration(periods=1500))
        assert rockjit.classify_result(r) == (want, 1)
    # the sweep labels the two sides the same way
    def label(x):
        return str(sw.names[sw.label[int(np.argmin(np.abs(sw.alpha - x)))]])
    assert label(0.76) == "symmetric" and label(0.8) == "asymmetric"


def test_every_periodic_sweep_cell_lies_on_a_stable_branch(study):
    sw, cont = study
    bif_a = np.array([b.alpha for b in cont.bifurcations])
    checked = 0
    for i in range(0, sw.alpha.size, 5):
        a, p = float(sw.alpha[i]), int(sw.period[i])
        if not 1 <= p <= 8 or np.min(np.abs(bif_a - a)) < 3e-3:
            continue
        pts = sw.strobe[i][np.all(np.isfinite(sw.strobe[i]), axis=1)][-p:]
        scale = np.abs(pts).max()
        hit = False
        for br in cont.branches:
            if br.period != p:
                continue
            dist = np.where(br.stable, np.abs(br.value - a), np.inf)  # a fold has two arms
            k = int(np.argmin(dist))
            if dist[k] > 0.02:
                continue
            o = orbits.periodic_orbit(BLOCK, forcing(a, cont.phase), br.cycle[k], p)
            for cyc in (o.cycle, -o.cycle_half):
                d = min(np.abs(pts - np.roll(cyc, s, axis=0)).max() for s in range(p))
                hit |= d <= 1e-5 * scale  # the sweep's grid is N = 64
        assert hit, (a, p)
        checked += 1
    assert checked >= 20


def test_unstable_branch_points_are_orbits(study):
    _, cont = study
    br = next(b for b in cont.branches if b.symmetric)
    bad = np.nonzero(~br.stable & (np.abs(br.multipliers[:, 0]) < 10))[0]
    assert bad.size >= 5
    for k in bad[:: max(1, bad.size // 4)]:
        x = br.cycle[k, 0]
        r = plain(x, br.value[k], 1, phase=cont.phase)
        assert np.abs(r.strobe[1, :2] - x).max() <= 1e-9 * max(1, abs(br.multipliers[k, 0]))


def test_grazing_end_of_the_unstable_symmetric_arm(study):
    _, cont = study
    g = of_type(cont, "grazing", 1, 0.6, 0.76)
    assert len(g) == 1
    a = g[0].alpha
    # the orbit turns back short of theta = 0 without impact, ever closer as alpha -> a: the
    # depth of that turn, read off dense plain runs (the vertex of a parabola through the
    # three grid points around it), extrapolates to 0 at a
    depth = []
    (a1, a2) = (a - 3e-7, a - 1e-7)
    for al in (a1, a2):
        o = orbits.periodic_orbit(BLOCK, forcing(al, cont.phase), g[0].state, 1,
                                  shooting=Shooting(graze_tol=0))
        assert o.impacts == 2 and not o.stable
        r = plain(o.state, al, 1, phase=cont.phase, record_stride=1, n_steps=16384)
        th = r.trajectory[:, 1]
        same = (th[:-2] * th[1:-1] > 0) & (th[1:-1] * th[2:] > 0)
        turn = same & (np.abs(th[1:-1]) <= np.abs(th[:-2])) & \
            (np.abs(th[1:-1]) <= np.abs(th[2:]))
        k = np.nonzero(turn)[0] + 1
        k = k[np.argmin(np.abs(th[k]))]
        m = np.abs(th[k - 1:k + 2])
        depth.append(m[1] - (m[2] - m[0]) ** 2 / (8 * (m[2] - 2 * m[1] + m[0])))
    a0 = a1 - depth[0] * (a2 - a1) / (depth[1] - depth[0])
    assert abs(a0 - a) < 1e-8
    with pytest.raises(OrbitRefused) as e:
        orbits.periodic_orbit(BLOCK, forcing(a - 5e-7, cont.phase), g[0].state, 1)
    assert e.value.reason == "grazing"


def test_cascade_ratios_approach_feigenbaums(study):
    _, cont = study
    pd = sorted(b.alpha for b in cont.bifurcations if b.type == "period_doubling"
                and b.period in (1, 2, 4, 8) and 0.9 < b.alpha < 0.94)
    assert len(pd) == 4
    r1 = (pd[1] - pd[0]) / (pd[2] - pd[1])
    r2 = (pd[2] - pd[1]) / (pd[3] - pd[2])
    assert abs(r2 - 4.669) < abs(r1 - 4.669) < 1.0


def test_continuation_in_omega_uses_the_same_code(asym08):
    c = orbits.continuation(BLOCK, Harmonic(alpha=0.8), [(OMEGA, asym08.state, 1)],
                            parameter="omega", bounds=(1.25, 1.35),
                            settings=ContinuationSettings(switch=False))
    br = c.branches[0]
    k = int(np.argmin(np.abs(br.value - OMEGA)))
    assert abs(br.value[k] - OMEGA) < 1e-12
    assert np.allclose(br.alpha, 0.8) and np.allclose(br.omega, br.value)
    # the asymmetric branch ends where it meets the symmetric one (the pitchfork in omega)
    assert "branch_point" in br.ends
    for k in (0, len(br) // 2, len(br) - 1):
        w = br.value[k]
        x = br.cycle[k, 0]
        r = rockjit.simulate(BLOCK, Harmonic(alpha=0.8, omega=w, phase=0.0), x,
                             integration=Integration(periods=1, n_steps=4096))
        assert np.abs(r.strobe[1, :2] - x).max() <= 1e-9


def test_summary_and_arrays_round_trip(study, tmp_path):
    """The files hold the continuation exactly: every bifurcation and branch read back equals
    the one in memory, field by field and entry by entry. And what they hold is right, checked
    independently: at each located symmetry breaking and period doubling of periods 1 and 2,
    the state read back is a fixed point of tests/physics.py's ``P^p`` (a slow solve_ivp
    integration sharing no code with rockjit; measured 1.4e-13 to 1.7e-12) whose
    finite-difference monodromy has the critical multiplier, +1 or -1 (measured within 2.6e-9),
    and the multipliers read back are its eigenvalues (measured within 1.7e-9)."""
    import json

    import physics as ph  # tests/physics.py
    from rockjit.storage import atomic as io
    _, cont = study
    summary, arrays = cont.to_summary()
    io.write_json(tmp_path / "summary.json", summary)
    io.write_npz(tmp_path / "branches.npz", **arrays)
    back = json.loads((tmp_path / "summary.json").read_text())
    z = np.load(tmp_path / "branches.npz")
    assert back["phase"] == cont.phase and back["parameter"] == "alpha"
    assert back["hb"] == HB and back["omega"] == OMEGA and back["law"] == BLOCK.law
    assert len(back["bifurcations"]) == len(cont.bifurcations) == len(z["bif_type"])
    for k, (d, bf) in enumerate(zip(back["bifurcations"], cont.bifurcations)):
        assert d["type"] == bf.type == z["bif_type"][k] and d["type"] in orbits.BIFURCATION_TYPES
        assert d["alpha"] == bf.alpha == z["bif_alpha"][k]
        assert d["period"] == bf.period == z["bif_period"][k]
        assert d["branch"] == bf.branch == z["bif_branch"][k]
        assert d["state"] == list(bf.state) == list(z["bif_state"][k])
        mu = np.asarray(bf.multipliers, dtype=complex)
        assert d["multipliers"] == [[m.real, m.imag] for m in mu]
        np.testing.assert_array_equal(z["bif_multipliers"][k], np.stack([mu.real, mu.imag], -1))
    assert len(back["branches"]) == len(cont.branches)
    for i, br in enumerate(cont.branches):
        assert back["branches"][i]["period"] == br.period
        assert back["branches"][i]["n_points"] == len(br)
        for name in ("value", "alpha", "omega", "cycle", "cycle_half", "stable", "impacts",
                     "t_next_impact", "t_next_impact_half"):
            np.testing.assert_array_equal(z[f"branch{i}_{name}"], getattr(br, name))
        np.testing.assert_array_equal(z[f"branch{i}_multipliers"],
                                      np.stack([br.multipliers.real, br.multipliers.imag], -1))
    checked = 0
    for d in back["bifurcations"]:
        critical = {"symmetry_breaking": 1.0, "period_doubling": -1.0}.get(d["type"])
        if critical is None or d["period"] > 2 or not d["located"]:
            continue
        M, y = ph.monodromy_fd(d["state"], d["period"], hb=HB, alpha=d["alpha"], omega=OMEGA,
                               law=BLOCK.law, xi=BLOCK.xi, phi=back["phase"])
        mu_fd = np.linalg.eigvals(M)
        assert np.abs(y - d["state"]).max() <= 1e-10
        assert np.abs(mu_fd - critical).min() <= 3e-8, (d["type"], mu_fd)
        assert ph.match_pairs([complex(*m) for m in d["multipliers"]], mu_fd) <= 2e-8
        checked += 1
    assert checked == 3  # the pitchfork, and the doublings of periods 1 and 2


def test_fig_branches(study):
    from rockjit.plotting import figures as plotting
    sw, cont = study
    fig = plotting.fig_branches(cont, sw)
    ax = fig.axes[0]
    styles = {ln.get_linestyle() for ln in ax.get_lines() if len(ln.get_xdata()) > 1}
    assert "-" in styles and "--" in styles
    # the list of bifurcations is the caption's, not a text table in the axes
    assert len(fig.axes) == 1 and not ax.texts
    text = plotting.branch_caption(cont)
    assert "period doubling" in text and "symmetry-breaking pitchfork" in text
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "stable orbits: solid" in legend and "unstable orbits: dashed" in legend
    fig2 = plotting.fig_branches(cont, sw, limits=(0.9, 0.96), component=0)
    lo, hi = fig2.axes[0].get_xlim()
    assert (lo, hi) == (0.9, 0.96)


def test_branches_and_bifurcations_stay_inside_the_range():
    # the asymmetric branch switched onto at Mao hb=1's symmetry breaking (alpha = 0.7876) was
    # followed to alpha = 1.93 and a grazing reported there, outside the requested (0.3, 0.8)
    mao = Block(hb=1.0, law="mao")
    sw = rockjit.sweep(mao, Harmonic(omega=1.3), rockjit.alpha_grid((0.3, 0.8), 0.004),
                       integration=Integration(periods=300))
    c = orbits.continue_branches(mao, Harmonic(omega=1.3), (0.3, 0.8), sweep=sw)
    assert c.bifurcations and all(0.3 <= b.alpha <= 0.8 for b in c.bifurcations)
    for br in c.branches:
        assert br.value.min() >= 0.3 - 1e-9 and br.value.max() <= 0.8 + 1e-9


def test_a_periodic_orbit_seeds_a_continuation_at_its_own_section(asym08):
    c = orbits.continuation(asym08.block, asym08.forcing, [asym08], bounds=(0.79, 0.81),
                            settings=ContinuationSettings(switch=False))
    assert c.forcing == Harmonic(omega=OMEGA, phase=asym08.phase)
    br = c.branches[0]
    k = int(np.argmin(np.abs(br.value - 0.8)))
    assert abs(br.value[k] - 0.8) < 1e-12
    assert np.abs(br.cycle[k] - asym08.cycle).max() <= 1e-10
    with pytest.raises(ValueError, match="phase"):
        orbits.continuation(BLOCK, forcing(0.8, 0.3), [asym08], bounds=(0.79, 0.81))
    with pytest.raises(ValueError, match="omega"):
        orbits.continuation(BLOCK, Harmonic(omega=1.2), [asym08], bounds=(0.79, 0.81))


def test_a_sweep_fixes_the_section(study):
    sw, cont = study
    z = sw.settings["z0"]
    assert cont.phase == math.atan2(z[2], z[3]) and cont.forcing.phase == cont.phase
    with pytest.raises(ValueError, match="the sweep's forcing phase"):
        orbits.continue_branches(BLOCK, Harmonic(omega=OMEGA, phase=0.3), (0.5, 1.0), sweep=sw)
    with pytest.raises(ValueError, match="sweep must be of the same block"):
        orbits.continue_branches(Block(hb=2), SWEEP_FORCING, (0.5, 1.0), sweep=sw)


def test_orbits_of_sweep_plans_then_runs_the_sweep_and_its_branches():
    """The command line's entry point: its plan refuses bad input before any run, and its run
    is the sweep followed by continue_branches on it."""
    with pytest.raises(ValueError, match="alpha_step"):
        orbits.orbits_of_sweep.plan(BLOCK, SWEEP_FORCING, (0.75, 0.85), alpha_step=0)
    with pytest.raises(ValueError, match="n_steps must be even"):
        orbits.orbits_of_sweep.plan(BLOCK, SWEEP_FORCING, (0.75, 0.85), n_steps=383)
    with pytest.raises(ValueError, match="execution must be"):
        orbits.orbits_of_sweep.plan(BLOCK, SWEEP_FORCING, (0.75, 0.85), execution="threads")
    settings = ContinuationSettings(max_period=2)
    plan = orbits.orbits_of_sweep.plan(BLOCK, SWEEP_FORCING, (0.75, 0.85), alpha_step=0.01,
                                       settings=settings)
    assert plan.sweep_plan.axes["alpha"].size == 11 and plan.settings is settings
    cont, sw = orbits.orbits_of_sweep(BLOCK, SWEEP_FORCING, (0.75, 0.85), alpha_step=0.01,
                                      settings=settings,
                                      execution=rockjit.Execution(progress=False))
    ref_sw = rockjit.sweep(BLOCK, SWEEP_FORCING, rockjit.alpha_grid((0.75, 0.85), 0.01))
    assert np.array_equal(sw.label, ref_sw.label)
    assert np.array_equal(sw.strobe, ref_sw.strobe, equal_nan=True)
    ref = orbits.continue_branches(BLOCK, SWEEP_FORCING, (0.75, 0.85), sweep=ref_sw,
                                   settings=settings)
    assert len(cont.branches) == len(ref.branches) >= 2
    for a, b in zip(cont.branches, ref.branches):
        assert np.array_equal(a.value, b.value) and np.array_equal(a.cycle, b.cycle)
    assert [b.type for b in cont.bifurcations] == [b.type for b in ref.bifurcations]
    assert cont.forcing.omega == OMEGA and cont.forcing.alpha is None


# --------------------------------------------------------------------------- steps and reports

#: short steps, so that a branch has many of them between its bifurcations
FINE = ContinuationSettings(ds0=0.002, ds_max=0.005, max_period=2)


@pytest.fixture(scope="module")
def fine(asym08):
    """The study's asymmetric orbit followed at phase 0 over (0.77, 0.92) with short steps:
    its symmetry-breaking pitchfork (0.7798) and period doubling (0.9115), and the branches
    followed from there."""
    return orbits.continuation(BLOCK, SWEEP_FORCING, [asym08], bounds=(0.77, 0.92),
                               settings=FINE)


#: long steps
COARSE = ContinuationSettings(ds0=0.02, ds_max=0.05, switch=False)


@pytest.fixture(scope="module")
def coarse():
    """Long steps from a sweep's attractors over (0.55, 0.6), seeds on either side of the
    symmetric branch's fold (0.5573): the seed nearest to it lies close to the branch already
    followed from the other but far from the chord between that branch's points."""
    sw = rockjit.sweep(BLOCK, SWEEP_FORCING, rockjit.alpha_grid((0.55, 0.6), 0.002))
    return orbits.continue_branches(BLOCK, SWEEP_FORCING, (0.55, 0.6), sweep=sw,
                                    settings=COARSE)


def continued(request, which):
    """A continuation fixture by name, and the largest step it was asked for."""
    cont = request.getfixturevalue(which)
    if which == "study":
        return cont[1], ContinuationSettings().ds_max
    return cont, {"fine": FINE, "coarse": COARSE}[which].ds_max


def impact_phases(cont, br, k):
    """Impact instants of point ``k`` of a branch over its period, as fractions of ``T`` after
    the section (a plain run from the point's state)."""
    w = float(br.omega[k])
    r = rockjit.simulate(cont.block, Harmonic(alpha=float(br.alpha[k]), omega=w,
                                              phase=cont.phase), br.cycle[k, 0],
                         integration=Integration(periods=br.period, n_steps=4096))
    assert r.status == "done" and r.n_impacts == br.impacts[k]
    return (r.impacts[:, 0] % (2 * math.pi / w)) * w / (2 * math.pi)


def test_no_step_is_longer_than_ds_max(fine):
    """The step is measured in (theta, theta', alpha) at the section (the norm of
    ContinuationSettings), from each branch's returned points. Each corrected point lies on the
    hyperplane ``ds`` from the last one along the secant, so the chord between neighbours is
    ``ds`` over the cosine of a small angle: at most ``ds_max`` to within 1e-3."""
    ds_max = FINE.ds_max
    longest = 0.0
    for br in fine.branches:
        for k in range(len(br.value)):
            # no impact within 0.15 T of the section: the continuation keeps working at the
            # output section (it moves its section only when an impact comes near), so the
            # branch's points are in the coordinates the steps were taken in
            ph = impact_phases(fine, br, k)
            assert np.min(np.minimum(ph, 1.0 - ph)) >= 0.15, (br.period, k)
        y = np.column_stack([br.cycle[:, 0], br.value])
        chord = np.linalg.norm(np.diff(y, axis=0), axis=1)
        assert chord.max() <= ds_max * (1 + 1e-3), (br.period, br.symmetric, chord.max())
        longest = max(longest, float(chord.max()))
    # the steps do grow to the bound (so that the bound is what is tested)
    assert longest >= 0.95 * ds_max


@pytest.mark.parametrize("which", ["study", "coarse"])
def test_no_step_moves_the_parameter_by_more_than_ds_max(which, request):
    # whatever section a step was taken at, alpha is one of the step's coordinates
    cont, ds_max = continued(request, which)
    for br in cont.branches:
        assert np.abs(np.diff(br.value)).max() <= ds_max * (1 + 1e-3), br.origin


def same_bifurcation(a, b):
    """One bifurcation reported twice: the same type and period, alpha within 1e-6 and the
    same orbit to 1e-4 of its size, under any cyclic shift or as its mirror image (the mirror
    of ``x(t)`` is ``-x(t + T/2)``, whose cycle is ``-cycle_half``)."""
    if a.type != b.type or a.period != b.period or abs(a.value - b.value) > 1e-6:
        return False
    scale = float(np.abs(a.cycle).max())
    for other in (b.cycle, -b.cycle_half):
        d = min(float(np.abs(a.cycle - np.roll(other, s, axis=0)).max())
                for s in range(a.period))
        if d <= 1e-4 * scale:
            return True
    return False


@pytest.mark.parametrize("which", ["study", "fine", "coarse"])
def test_no_bifurcation_is_reported_twice(which, request):
    cont, _ = continued(request, which)
    # real bifurcations passed
    assert any(b.located and b.type in ("fold", "period_doubling", "symmetry_breaking")
               for b in cont.bifurcations)
    bifs = cont.bifurcations
    for i in range(len(bifs)):
        for j in range(i + 1, len(bifs)):
            assert not same_bifurcation(bifs[i], bifs[j]), (bifs[i].type, bifs[i].value)
