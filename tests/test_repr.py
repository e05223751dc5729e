"""Every result type prints as a short summary: a bounded number of short lines, whatever the
grid, that state what was computed, its shape and its headline numbers (checked here against
the result's own arrays, counted independently)."""

import dataclasses

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic, Integration, Pulse, Record, Transient
from rockjit import reprs
from rockjit.reprs import MAX_LINES, MAX_WIDTH

SHORT = Integration(periods=100)


def _uncut(obj):
    """``obj``'s summary as it reads with no line limit and no line cut short (the summary
    cuts to MAX_LINES lines and each line to MAX_WIDTH characters: bounded by construction,
    so the bounds only mean something where nothing was cut)."""
    saved = reprs.MAX_LINES, reprs._one
    reprs.MAX_LINES, reprs._one = 10 ** 6, lambda line: line
    try:
        return reprs.text(obj)
    finally:
        reprs.MAX_LINES, reprs._one = saved


def _short(obj):
    """``repr(obj)``, checked short: within the bounds, and nothing cut to get there."""
    text = repr(obj)
    assert text == _uncut(obj), text  # no line left out, no line cut
    lines = text.splitlines()
    assert not any(ln.endswith("…") for ln in lines), text
    assert 1 <= len(lines) <= MAX_LINES, text
    assert max(len(ln) for ln in lines) <= MAX_WIDTH, text
    assert "array(" not in text and "[[" not in text, text  # no array values
    return text


def _shares_stated(text, label, names):
    # the largest behaviour's share, counted here from the label array
    codes, counts = np.unique(np.asarray(label), return_counts=True)
    top = codes[np.argmax(counts)]
    assert f"{names[top]} {100 * counts.max() / np.size(label):.1f} %" in text, text


def test_sweep():
    alphas = rockjit.alpha_grid((0.5, 1.0), 0.01)
    sw = rockjit.sweep(Block(hb=1), Harmonic(omega=1.3), alphas, integration=SHORT)
    text = _short(sw)
    assert f"{alphas.size} amplitudes" in text and f"({alphas.size},)" in text
    assert f"{sw.strobe.shape}".replace(" ", "") in text.replace(" ", "")
    _shares_stated(text, sw.label, rockjit.BEHAVIOURS)
    assert str(sw) == text  # print() shows the same


def test_basin_and_its_attractors():
    b = rockjit.basin(Block(hb=1, law="mao"), Harmonic(alpha=0.66, omega=1.3), grid=24,
                      integration=SHORT)
    text = _short(b)
    assert "24×24 initial states" in text and "(24, 24)" in text
    _shares_stated(text, b.label, rockjit.BEHAVIOURS)
    assert f"{len(b.attractors)}: " in text
    for a in b.attractors:
        one = _short(a)
        assert len(one.splitlines()) == 1 and f"{a.fraction:.1f} %" in one
    # a list of attractors prints a short line's worth each, not their cycle points
    assert len(repr(b.attractors)) <= (MAX_WIDTH + 2) * len(b.attractors)


def test_plane():
    pl = rockjit.plane(Block(hb=1), (0.5, 0.9), (1.2, 1.4), grid=(5, 3), integration=SHORT)
    text = _short(pl)
    assert "5×3 forcings, 1 initial state" in text and "(1, 5, 3)" in text
    _shares_stated(text, pl.label, rockjit.BEHAVIOURS)


def test_erosion_states_its_integrity_at_both_ends():
    prof = rockjit.erosion(Block(hb=1), Harmonic(omega=1.3), [0.6, 0.7], grid=10,
                           integration=SHORT)
    text = _short(prof)
    assert "2 amplitudes × 10×10 basins" in text
    assert f"{prof.GIM[0]:.3f} at alpha = 0.6 to {prof.GIM[-1]:.3f} at 0.7" in text
    assert f"{len(prof.branches)} attractors" in text


def test_fate_states_each_outcome_share():
    f = rockjit.fate(Block(hb=1), Harmonic(alpha=0.969, omega=1.3), ensemble=16,
                     integration=Integration(periods=200))
    text = _short(f)
    assert "16 runs" in text
    for key, v in f.ids.items():
        assert f"{key} {np.mean(f.outcome == v):.1%}" in text


def test_orbits_branches_and_bifurcations():
    from rockjit.orbits import ContinuationSettings, continuation, periodic_orbit
    o = periodic_orbit(Block(hb=1), Harmonic(alpha=0.8, omega=1.3), (-0.44, -0.36))
    text = _short(o)
    assert "period 1, asymmetric, stable" in text
    assert f"{abs(o.multipliers[0]):.4g}" in text
    c = continuation(Block(hb=1), Harmonic(omega=1.3), [(0.8, (-0.44, -0.36), 1)],
                     bounds=(0.77, 0.8), settings=ContinuationSettings(switch=False))
    text = _short(c)
    assert f"{len(c.branches)} branches along alpha" in text
    assert f"{len(c.bifurcations)} symmetry breaking" in text
    for br in c.branches:
        t = _short(br)
        assert f"{len(br.value)} orbits" in t
        assert f"{int(np.sum(br.stable))} of {len(br.value)} orbits" in t
    for bif in c.bifurcations:
        assert len(_short(bif).splitlines()) == 1 and "symmetry breaking" in repr(bif)


def test_chart():
    # the chart's own computation is tested elsewhere: here a small plane and no curves
    from rockjit.orbits.plane_chart import ChartResult
    pl = rockjit.plane(Block(hb=1), (0.7, 0.95), (1.25, 1.35), grid=(6, 5), integration=SHORT)
    res = ChartResult(block=pl.block, plane=pl, alpha_range=(0.7, 0.95),
                      omega_range=(1.25, 1.35), seed_omegas=(1.3,), curves=[], seeds=[],
                      refused=[], overturn_onset=np.full(5, np.nan), phase=0.0)
    text = _short(res)
    assert "6×5 forcings and 0 bifurcation curves" in text
    _shares_stated(text, pl.label, rockjit.BEHAVIOURS)


def test_spectrum():
    # a result as the spectrum builds it (its computation is tested elsewhere)
    from rockjit.ground import OUTCOMES
    from rockjit.ground.spectrum import SpectrumResult
    rng = np.random.default_rng(1)
    shape = (30, 40)
    outcome = rng.integers(0, 3, size=shape).astype(np.int8)
    sp = SpectrumResult(block=Block(hb=4), pulse=Pulse("sine"), ratio=np.linspace(0.5, 8, 30),
                        amplitude=np.linspace(1, 25, 40), outcome=outcome,
                        max_rotation=np.zeros(shape), t_overturn=np.zeros(shape),
                        n_impacts=np.zeros(shape, dtype=int), min_overturn=np.zeros(30),
                        min_mode=np.zeros(30, dtype=int), min_no_impact=np.zeros(30),
                        method="compiled", n_runs=1200)
    text = _short(sp)
    assert "30×40 pulses" in text and "(30, 40)" in text
    _shares_stated(text, outcome, OUTCOMES)


def test_fragility():
    t = np.arange(0.0, 2.0, 0.01)
    records = [Record(0.3 * np.sin(2 * np.pi * f * t) * np.sin(np.pi * t / 2), 0.01,
                      name=f"{f:g} Hz") for f in (1.0, 2.0)]
    fr = rockjit.fragility(Block(hb=3), records, sizes=[0.5], intensities=[0.9, 2.0, 4.0],
                           integration=Transient(free_time=20.0))
    text = _short(fr)
    assert "1 law × 1 size × 2 records × 3 intensities" in text
    assert f"{fr.outcome.shape}" in text
    # a fit the data do not determine is shown by its status and reason, not as median nan
    from rockjit.ground import fit_lognormal
    fits = {"ok": fit_lognormal([1, 2, 3, 4], [0, 3, 7, 9], [10, 10, 10, 10]),
            "survive": fit_lognormal([1, 2], [0, 0], [5, 5]),
            "one level": fit_lognormal([3.0], [1], [2])}
    assert [f.status for f in fits.values()] == ["ok", "all_survive", "unidentified"]
    for key, fit in fits.items():
        text = _short(dataclasses.replace(fr, fits={"housner": {0.5: {"overturn": fit}}}))
        row = next(ln for ln in text.splitlines() if ln.startswith("  housner "))
        assert "nan" not in text, text
        if key == "ok":
            assert f"median {fit.median:.3g}, beta {fit.beta:.3g} (size 0.5)" in row, row
        elif key == "survive":
            assert "all survive (bound 2, size 0.5)" in row, row
        else:
            assert "unidentified: one intensity level (size 0.5)" in row, row


def test_the_summary_does_not_grow_with_the_grid():
    # the same lines for 64 and 1600 initial states, neither cut to fit
    small, large = (rockjit.basin(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), grid=grid,
                                  integration=Integration(periods=50)) for grid in (8, 40))
    a, b = _short(small).splitlines(), _short(large).splitlines()
    assert len(a) == len(b), (a, b)
    assert [ln[:14] for ln in a[1:]] == [ln[:14] for ln in b[1:]], (a, b)  # the same rows
