"""Pulses, transient runs and overturning spectra on the scipy reference path.

Checked: the pulses are the functions docs/theory/ground-motions.md defines (the Ricker
wavelet's peak, zero crossings, side lobes and start); their uplift windows are where
``|f| > cot(thc)``, in closed form; a block whose peak ground acceleration is at or below
``g tan alpha_s`` never moves (exactly at rest, no impact) and one above it lifts off at the
closed-form instant; free rocking after a pulse conserves ``E = 1/2 theta'^2 +
3/4 sin(thc + |theta|)`` across impacts with ``e = 1``, ``xi = 0``; stopping a run once its
outcome is decided changes neither the outcome nor ``max |theta|``; the two overturning modes;
the located boundary of overturning without impact converges to the slender linearised block's
closed forms (rockjit.ground.closed_forms) at second order in ``alpha_s``; the bisection's
bracket; the batch kernel's interface (a kernel registered under "rockjit" takes the batches);
and the refusals: periods, exponents.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rockjit
from rockjit import Block, Integration, Pulse, Scipy, Transient
from rockjit.ground import batch as B
from rockjit.ground.batch import transient_scipy
from rockjit.ground.closed_forms import cosine_no_impact, sine_no_impact, sine_phi
from rockjit.ground.response import OVERTURN_IMPACT, OVERTURN_NO_IMPACT, SAFE

TIGHT = Scipy("DOP853", rtol=1e-11, atol=1e-13)
P = math.sqrt(0.75)


# ---- the pulses -------------------------------------------------------------------------------

def test_pulse_shapes():
    p = Pulse("sine", ratio=2.0, amplitude=3.0, hb=4.0)
    w = 2.0 * P
    assert p.omega_p == pytest.approx(w) and p.accel == 0.75 and p.end == pytest.approx(
        2 * math.pi / w)
    t = np.linspace(0, p.end, 101)
    np.testing.assert_allclose(p.f(t), 0.75 * np.sin(w * t), atol=1e-15)
    assert p.f(p.end + 1e-9) == 0.0 and p.f(-1e-9) == 0.0
    c = p.replace(kind="cosine")
    np.testing.assert_allclose(c.f(t), 0.75 * np.cos(w * t), atol=1e-15)
    assert c.f(0.0) == 0.75 and c.f(p.end + 1e-9) == 0.0
    for q in (p, c):
        f = q.scalar()
        for x in np.linspace(-0.5, q.end + 0.5, 73):
            assert f(float(x)) == pytest.approx(float(q.f(x)), abs=1e-15)


def test_ricker_follows_the_documented_convention():
    r = Pulse("ricker", ratio=1.5, amplitude=2.0, hb=2.0)
    a, w, t0 = 1.0, 1.5 * P, 3 * math.pi / (1.5 * P)
    assert r.delay == pytest.approx(t0) and r.end == pytest.approx(2 * t0)
    assert r.f(t0) == pytest.approx(a, rel=1e-15)                      # the peak is a_p
    for u in (-1 / math.sqrt(2), 1 / math.sqrt(2)):                    # zero crossings
        assert abs(r.f(t0 + 2 * u / w)) < 1e-15
    for u in (-math.sqrt(1.5), math.sqrt(1.5)):                        # side lobes
        assert r.f(t0 + 2 * u / w) == pytest.approx(-2 * math.exp(-1.5) * a, rel=1e-12)
    assert abs(r.f(0.0)) < 1e-8 * a and abs(r.f(r.end)) < 1e-8 * a     # starts from ~0
    t = np.linspace(0, r.end, 200_001)
    assert abs(np.trapezoid(r.f(t), t)) < 1e-7                           # no net velocity
    # Fourier amplitude ~ w^2 exp(-w^2 / w_p^2): largest at w_p
    freqs = np.linspace(0.2, 4, 400) * w
    amp = [abs(np.trapezoid(r.f(t) * np.exp(-1j * om * t), t)) for om in freqs]
    assert freqs[int(np.argmax(amp))] == pytest.approx(w, rel=0.01)


@pytest.mark.parametrize("kind", ["sine", "cosine", "ricker"])
@pytest.mark.parametrize("amplitude", [1.05, 1.8, 4.0])
def test_windows_are_where_f_exceeds_the_threshold(kind, amplitude):
    p = Pulse(kind, ratio=1.7, amplitude=amplitude, hb=2.0)
    thr = 0.5
    w = p.windows(thr)
    t = np.linspace(-0.1, p.end + 0.1, 400_001)
    inside = np.zeros(t.size, dtype=bool)
    for t0, t1, sg in w:
        inside |= (t > t0) & (t < t1)
        for edge in (t0, t1):
            assert abs(abs(p.f(edge)) - thr) < 1e-12 or edge in (0.0, p.end)
        mid = 0.5 * (t0 + t1)
        assert sg * p.f(mid) > thr
    f = np.abs(p.f(t))
    assert np.all(f[~inside] <= thr + 1e-9) and np.all(f[inside] > thr - 1e-9)
    assert Pulse(kind, ratio=1.7, amplitude=0.99, hb=2.0).windows(thr).shape == (0, 3)


def test_pulse_validation():
    with pytest.raises(ValueError, match="kind"):
        Pulse("square", ratio=1, amplitude=2)
    with pytest.raises(ValueError, match="ratio must be in"):
        Pulse("sine", ratio=0.0, amplitude=2)
    with pytest.raises(ValueError, match="amplitude must be in"):
        Pulse("sine", ratio=1.0, amplitude=-1)
    with pytest.raises(ValueError, match="amplitude must be finite"):
        Pulse("sine", ratio=1.0, amplitude=float("nan"))
    with pytest.raises(ValueError, match="hb"):
        Pulse("sine", ratio=1.0, amplitude=2.0, hb=3.0).bind(Block(hb=2))
    with pytest.raises(ValueError, match="needs hb"):
        Pulse("sine", ratio=1.0, amplitude=2.0).f(0.1)


# ---- runs -----------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", ["sine", "cosine", "ricker"])
@pytest.mark.parametrize("amplitude", [0.3, 0.999999, 1.0])
def test_below_the_uplift_threshold_the_block_never_moves(kind, amplitude):
    r = rockjit.simulate(Block(hb=3), Pulse(kind, ratio=2.0, amplitude=amplitude),
                         method=TIGHT)
    assert r.status == "rest" and r.n_impacts == 0 and r.max_theta == 0.0
    assert math.isnan(r.t_uplift) and r.outcome == SAFE and r.mode is None
    assert np.all(r.trajectory[:, 1:] == 0.0) and np.all(r.state == 0.0)


def test_uplift_at_the_closed_form_instant():
    for kind, amp in (("sine", 1.6), ("cosine", 1.6), ("sine", 7.0)):
        p = Pulse(kind, ratio=1.3, amplitude=amp)
        r = rockjit.simulate(Block(hb=2.5), p, method=TIGHT, integration=Transient(
            duration=p.bind(Block(hb=2.5)).end))
        w = 1.3 * P
        expect = math.asin(1 / amp) / w if kind == "sine" else 0.0
        assert r.t_uplift == pytest.approx(expect, abs=1e-12)
        # onto the corner the forcing pushes it to
        assert np.all(r.trajectory[r.trajectory[:, 0] > r.t_uplift][:5, 1] > 0)


def test_free_rocking_after_the_pulse_conserves_energy():
    """e = 1, xi = 0: after the pulse, E is constant along the flight and across impacts."""
    block = Block(hb=3, e=1.0, xi=0.0)
    pulse = Pulse("sine", ratio=3.0, amplitude=1.2)
    r = rockjit.simulate(block, pulse, method=Scipy("DOP853", rtol=1e-12, atol=1e-14),
                         integration=Transient(free_time=60.0))
    end = pulse.bind(block).end
    assert r.status == "time_limit" and r.outcome == SAFE
    after = r.trajectory[r.trajectory[:, 0] > end]
    assert np.count_nonzero(r.impacts[:, 0] > end) >= 5
    E = 0.5 * after[:, 2] ** 2 + 0.75 * np.sin(block.thc + np.abs(after[:, 1]))
    assert np.ptp(E) < 1e-9 * E.mean()
    np.testing.assert_allclose(r.impacts[:, 2], r.impacts[:, 1])  # e = 1


def test_impacts_and_damping_only_lose_energy_after_the_pulse():
    block = Block(hb=2, law="mao", xi=0.01)
    pulse = Pulse("cosine", ratio=1.5, amplitude=1.3)
    r = rockjit.simulate(block, pulse, method=TIGHT, integration=Transient(free_time=40.0))
    assert r.status == "rest" and np.count_nonzero(r.impacts[:, 0] > 4.9) > 10
    after = r.trajectory[r.trajectory[:, 0] > pulse.bind(block).end]
    E = 0.5 * after[:, 2] ** 2 + 0.75 * np.sin(block.thc + np.abs(after[:, 1]))
    assert np.all(np.diff(E) <= 1e-9) and E[-1] < E[0]


@pytest.mark.parametrize("kind", ["sine", "cosine", "ricker"])
@pytest.mark.parametrize("law", ["housner", "mao"])
def test_stopping_when_decided_changes_no_outcome(kind, law):
    block = Block(hb=4, law=law)
    for ratio, amp in ((1.0, 1.3), (2.0, 2.0), (2.0, 2.45), (3.0, 2.0), (5.0, 6.0),
                       (5.0, 9.0), (1.5, 1.02)):
        p = Pulse(kind, ratio=ratio, amplitude=amp)
        full = rockjit.simulate(block, p, method=TIGHT, integration=Transient(free_time=80.0))
        cut = rockjit.simulate(block, p, method=TIGHT,
                               integration=Transient(free_time=80.0, stop_when_decided=True))
        assert cut.outcome == full.outcome, (ratio, amp)
        assert cut.max_rotation == pytest.approx(full.max_rotation, rel=1e-12, abs=1e-15)
        assert cut.t <= full.t
        if cut.status == "decided":
            assert full.status in ("rest", "time_limit")


def test_the_two_modes():
    block = Block(hb=4, law="housner")
    one = rockjit.simulate(block, Pulse("sine", ratio=2.0, amplitude=2.0), method=TIGHT)
    two = rockjit.simulate(block, Pulse("sine", ratio=2.0, amplitude=3.0), method=TIGHT)
    assert one.outcome == OVERTURN_IMPACT and one.mode == "with impact" and one.n_impacts > 0
    assert two.outcome == OVERTURN_NO_IMPACT and two.mode == "without impact"
    assert two.n_impacts == 0 and two.t_overturn == two.t
    assert two.max_theta == pytest.approx(math.pi / 2)
    assert one.summary()["mode"] == "with impact"


def test_the_linearised_solution_is_the_slender_limit():
    """theta / alpha_s of a slender block during a one-sine pulse approaches the closed form
    phi(tau) of the linearised equation, the error shrinking as alpha_s^2."""
    a, beta = 2.0, 1.5
    errs = []
    for hb in (20, 40):
        block = Block(hb=hb, xi=0.0)
        p = Pulse("sine", ratio=beta, amplitude=a)
        r = rockjit.simulate(block, p, method=TIGHT,
                             integration=Transient(duration=p.bind(block).end))
        tr = r.trajectory[r.trajectory[:, 1] > 0]
        phi = sine_phi(a, beta, tr[:, 0] * P)
        errs.append(np.max(np.abs(tr[:, 1] / math.atan(1 / hb) - phi)) / np.max(phi))
    assert errs[1] < 5e-4 and 3.0 < errs[0] / errs[1] < 5.0, errs


# ---- the spectra and the closed forms --------------------------------------------------------

CLOSED = [("sine", 1.0, sine_no_impact), ("sine", 2.0, sine_no_impact),
          ("sine", 5.0, sine_no_impact), ("sine", 8.0, sine_no_impact),
          ("cosine", 1.0, cosine_no_impact), ("cosine", 2.0, cosine_no_impact),
          ("cosine", 3.0, cosine_no_impact)]


@pytest.mark.parametrize("kind, ratio, closed", CLOSED, ids=[f"{c[0]}-{c[1]:g}" for c in CLOSED])
def test_boundary_without_impact_approaches_the_closed_form(kind, ratio, closed):
    """The located boundary of overturning without impact of blocks of h/b = 20 and 40
    against the slender linearised block's closed form (rockjit.ground.closed_forms; Zhang &
    Makris 2001): within 0.1 % at h/b = 40, the error falling 3 to 5 times as alpha_s halves
    (second order: the linearisation drops terms of relative size alpha_s^2)."""
    ref = closed(ratio)
    errs = []
    for hb in (20, 40):
        sp = rockjit.spectrum(Block(hb=hb, xi=0.0), Pulse(kind), [ratio],
                              [0.95 * ref, 1.05 * ref], tol=1e-8)
        assert sp.outcome[0, 1] == OVERTURN_NO_IMPACT
        errs.append(abs(sp.min_no_impact[0] - ref) / ref)
    assert errs[1] < 1e-3, errs
    assert 3.0 < errs[0] / errs[1] < 5.0, errs


def test_closed_forms_large_ratio_asymptote():
    # a short one-sine pulse overturns through the ground displacement it leaves:
    # a -> beta^2 / (2 pi) (1 + O(1/beta))
    q = [sine_no_impact(b) / (b * b / (2 * math.pi)) for b in (20.0, 80.0, 320.0)]
    assert q[0] > q[1] > q[2] > 1.0 and q[2] < 1.05
    assert cosine_no_impact(1e-3) == pytest.approx(1.0, rel=1e-6)  # quasi-static: uplift


def test_spectrum_grid_and_bisection():
    block = Block(hb=4, law="mao")
    ratios, amps = [1.0, 3.0, 6.0], [0.8, 1.5, 3.0, 6.0, 12.0]
    sp = rockjit.spectrum(block, Pulse("sine"), ratios, amps, tol=1e-6)
    assert sp.outcome.shape == (3, 5) and sp.max_rotation.shape == (3, 5)
    assert np.all(sp.outcome[:, 0] == SAFE) and np.all(sp.max_rotation[:, 0] == 0)
    rows = sp.min_overturn_list()
    assert [r["ratio"] for r in rows] == ratios
    tight = Transient(stop_when_decided=True)
    for i, row in enumerate(rows):
        k = row["amplitude"]
        assert k is not None and row["mode"] in ("with impact", "without impact")
        j = int(np.argmax(np.isin(sp.outcome[i], (1, 2))))
        assert (amps[j - 1] if j else 1.0) <= k <= amps[j]
        hit = rockjit.simulate(block, Pulse("sine", ratio=ratios[i], amplitude=k),
                               method=transient_scipy(), integration=tight)
        miss = rockjit.simulate(block, Pulse("sine", ratio=ratios[i],
                                             amplitude=k * (1 - 2e-6)),
                                method=transient_scipy(),
                                integration=tight)
        assert hit.overturned and not miss.overturned
        assert {1: "with impact", 2: "without impact"}[hit.outcome] == row["mode"]
    s = sp.summary()
    assert s["min_overturn"] == rows and s["law"] == "mao"
    assert sum(s["fractions"].values()) == pytest.approx(100.0)
    grid_only = rockjit.spectrum(block, Pulse("sine"), ratios, amps, locate=False)
    assert np.array_equal(grid_only.outcome, sp.outcome)
    assert np.all(np.isnan(grid_only.min_overturn))


def test_compare_two_laws():
    from rockjit.ground.spectrum import compare
    ratios, amps = [2.0, 6.0], [2.0, 4.0, 8.0, 11.0]
    h = rockjit.spectrum(Block(hb=4, law="housner"), Pulse("sine"), ratios, amps, tol=1e-4)
    m = rockjit.spectrum(Block(hb=4, law="mao"), Pulse("sine"), ratios, amps, tol=1e-4)
    same = compare(h, h)
    assert same["cells_differ"] == 0 and all(
        r["housner_over_housner"] == 1.0 for r in same["min_overturn_ratio"])
    c = compare(h, m)
    assert c["cells_differ"] == int(np.count_nonzero(h.outcome != m.outcome))
    assert len(c["differ_at"]) == c["cells_differ"]


def test_a_registered_compiled_kernel_takes_the_batches(monkeypatch):
    """The kernel registered under "rockjit" runs the spectra's batches: a stand-in that counts
    its cells and delegates to the scipy kernel gives the scipy kernel's spectrum."""
    seen = []

    def stand_in(blocks, sources, block_of, source_of, gain, settings, method):
        seen.append(len(gain))
        return B.scipy_kernel(blocks, sources, block_of, source_of, gain, settings,
                              transient_scipy())

    args = (Block(hb=3), Pulse("cosine"), [1.0, 2.0], [1.5, 4.0])
    monkeypatch.setitem(B.KERNELS, "rockjit", stand_in)
    got = rockjit.spectrum(*args, method="rockjit", tol=1e-3)
    ref = rockjit.spectrum(*args, tol=1e-3, method=transient_scipy())
    assert seen and sum(seen) == got.n_runs
    assert np.array_equal(got.outcome, ref.outcome)
    np.testing.assert_array_equal(got.min_overturn, ref.min_overturn)


def test_batch_outputs_on_a_dask_cluster_are_the_same():
    distributed = pytest.importorskip("dask.distributed")
    from rockjit import Execution
    args = (Block(hb=3), Pulse("sine"), [1.0, 2.0, 4.0], [1.5, 3.0, 6.0])
    ref = rockjit.spectrum(*args, tol=1e-3)
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=2,
                            dashboard_address=None) as client:
        got = rockjit.spectrum(*args, tol=1e-3, execution=Execution(client=client, chunk=2))
    assert np.array_equal(got.outcome, ref.outcome)
    np.testing.assert_array_equal(got.min_overturn, ref.min_overturn)
    np.testing.assert_array_equal(got.max_rotation, ref.max_rotation)


# ---- refusals ---------------------------------------------------------------------------------

def test_refusals():
    block, p = Block(hb=2), Pulse("sine", ratio=1.0, amplitude=2.0)
    assert rockjit.simulate(block, p).method == "rockjit"  # the default: the compiled path
    with pytest.raises(ValueError, match="no period"):
        rockjit.simulate(block, p, integration=Integration(periods=5), method="scipy")
    with pytest.raises(ValueError, match="lyapunov"):
        rockjit.simulate(block, p, lyapunov=True, method="scipy")
    with pytest.raises(ValueError, match="record_stride"):
        rockjit.simulate(block, p, record_stride=2, method="scipy")
    with pytest.raises(ValueError, match="theta_over"):
        rockjit.simulate(block, p, (2.0, 0.0), method="scipy")
    with pytest.raises(ValueError, match="needs the pulse's amplitude"):
        rockjit.simulate(block, Pulse("sine", ratio=1.0), method="scipy")
    with pytest.raises(ValueError, match="sweeps the pulse's ratio"):
        rockjit.spectrum(block, p, [1.0], [2.0])
    with pytest.raises(ValueError, match="ratios must be increasing"):
        rockjit.spectrum(block, Pulse("sine"), [2.0, 1.0], [2.0])
    with pytest.raises(ValueError, match="amplitudes must be in"):
        rockjit.spectrum(block, Pulse("sine"), [2.0], [-1.0, 2.0])
    with pytest.raises(ValueError, match="tol must be in"):
        rockjit.spectrum(block, Pulse("sine"), [2.0], [2.0], tol=0.5)
    with pytest.raises(ValueError, match="free_time must be in"):
        Transient(free_time=-1.0)
    with pytest.raises(ValueError, match="rest_speed must be > 0"):
        Transient(rest_speed=0)


def test_a_given_state_and_the_time_limit():
    block = Block(hb=2, e=1.0, xi=0.0)
    # free rocking from a tilt under a pulse of no amplitude
    r = rockjit.simulate(block, Pulse("sine", ratio=1.0, amplitude=0.0), (0.2, 0.0),
                         method=TIGHT, integration=Transient(duration=30.0))
    assert r.status == "time_limit" and r.t == 30.0 and r.n_impacts > 3
    assert r.max_theta == pytest.approx(0.2, rel=1e-9)


def test_transient_figure():
    from rockjit.ground.figures import fig_transient
    r = rockjit.simulate(Block(hb=4), Pulse("ricker", ratio=2.0, amplitude=2.0),
                         method=TIGHT, integration=Transient(free_time=20.0))
    fig = fig_transient(r)
    assert len(fig.axes) == 2 and "with impact" in fig.axes[0].get_title()
    line = fig.axes[0].get_lines()[0]
    np.testing.assert_allclose(line.get_ydata(), r.trajectory[:, 1] / r.alpha_s)


@pytest.mark.parametrize("module", ["plugs.pulse", "plugs.record", "ground.records",
                                    "ground.settings", "ground.spectrum", "ground.fitting"])
def test_the_examples_in_the_docstrings_run(module):
    import doctest
    import importlib
    mod = importlib.import_module(f"rockjit.{module}")
    result = doctest.testmod(mod, optionflags=doctest.NORMALIZE_WHITESPACE)
    assert result.attempted > 0 and result.failed == 0
