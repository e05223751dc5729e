"""The sum-of-harmonics excitation plug on the compiled transient kernel.

References: numpy's sines (the value), the plug's Python windows (a dense scan and Brent's
method, written apart from the compiled scan), scipy's DOP853 path at tight tolerances (whole
runs), and the one-sine pulse, whose windows are in closed form (a sum of one tone over one
period is that pulse).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rockjit
from rockjit import Block, HarmonicSum, Pulse, Scipy, Transient
from rockjit.ground import batch as B
from rockjit.ground.compiled import compiled_kernel
from rockjit.ground.plan import grid_settings
from rockjit.plugs import plug_value, plug_window, registered

REF = Scipy("DOP853", rtol=1e-12, atol=1e-14)


def _random_sums(n, seed):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        k = int(rng.integers(1, 5))
        yield HarmonicSum(amplitudes=tuple(rng.uniform(-1, 1, k)),
                          frequencies=tuple(rng.uniform(0.3, 6.0, k)),
                          phases=tuple(rng.uniform(-3, 3, k)), duration=float(rng.uniform(1, 30)))


def _compiled_windows(h, thr):
    c = h.coefficients()
    rows, t = [], 0.0
    while True:
        t0, t1, sg = plug_window(h.code, t, h.end, 1.0, c, 0, c.size, thr)
        if sg == 0.0:
            return np.array(rows).reshape(-1, 3)
        assert t1 > t
        rows.append((t0, t1, sg))
        t = t1


def test_every_plug_has_its_own_code():
    assert [cls.code for cls in registered()] == list(range(len(registered())))
    assert HarmonicSum in registered()


def test_the_compiled_value_is_the_sum_of_sines():
    for h in _random_sums(20, 1):
        c = h.coefficients()
        t = np.linspace(0.0, h.end, 37)
        got = np.array([plug_value(h.code, s, 1.0, c, 0, c.size) for s in t])
        ref = sum(a * np.sin(w * t + p) for a, w, p in zip(h.amplitudes, h.frequencies, h.phases))
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-14)


def test_the_compiled_windows_are_the_python_windows():
    """200 random sums and thresholds: the same windows, their ends within 1e-12 (measured
    1.1e-14)."""
    rng = np.random.default_rng(7)
    n_windows = 0
    for h in _random_sums(200, 2):
        thr = float(rng.uniform(0.05, 0.8)) * float(np.abs(h.amplitudes).sum())
        got, ref = _compiled_windows(h, thr), h.windows(thr)
        assert got.shape == ref.shape
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12)
        n_windows += len(ref)
        # |f| > thr inside each window and not just outside it
        for t0, t1, sg in ref:
            mid = 0.5 * (t0 + t1)
            assert sg * h.f(mid) > thr
    assert n_windows > 500


def test_a_tone_over_one_period_is_the_one_sine_pulse():
    """A sum of one tone over one period is the one-sine pulse: the same windows (the pulse's
    closed form) and the same run, on their different grids, to 1e-7."""
    block = Block(hb=4.0)
    pulse = Pulse("sine", ratio=2.0, amplitude=2.0).bind(block)
    tone = HarmonicSum(amplitudes=(pulse.accel,), frequencies=(pulse.omega_p,),
                       duration=2 * math.pi / pulse.omega_p)
    np.testing.assert_allclose(_compiled_windows(tone, block.cot), pulse.windows(block.cot),
                               rtol=0, atol=1e-13)
    settings = Transient(free_time=20.0)
    a = rockjit.simulate(block, pulse, integration=settings)
    b = rockjit.simulate(block, tone, integration=settings)
    assert a.outcome == b.outcome and a.n_impacts == b.n_impacts == 1
    np.testing.assert_allclose(b.impacts, a.impacts, rtol=0, atol=1e-7)
    assert b.t_overturn == pytest.approx(a.t_overturn, abs=1e-7)


@pytest.mark.parametrize("hb, amplitudes", [(2.0, (0.6, 0.3)), (4.0, (0.3, 0.2)),
                                            (2.0, (0.9, 0.4))])
def test_a_single_run_agrees_with_the_scipy_path(hb, amplitudes):
    """Safe rocking with 48 impacts and an overturning: measured 3.9e-9 and 3.3e-8 in the
    impacts, 2.3e-9 in max_rotation."""
    h = HarmonicSum(amplitudes=amplitudes, frequencies=(2.0, 5.0), duration=20.0)
    settings = Transient(free_time=20.0)
    got = rockjit.simulate(Block(hb=hb), h, integration=settings)
    ref = rockjit.simulate(Block(hb=hb), h, integration=settings, method=REF)
    assert got.method == "rockjit"
    assert got.outcome == ref.outcome and got.status == ref.status
    assert got.n_impacts == ref.n_impacts >= 2
    np.testing.assert_allclose(got.impacts, ref.impacts, rtol=0, atol=3e-7)
    assert got.t_uplift == pytest.approx(ref.t_uplift, abs=1e-12)
    assert got.max_rotation == pytest.approx(ref.max_rotation, abs=3e-8)


def test_a_batch_of_cells_agrees_with_the_scipy_kernel():
    """The grid kernel (gains on the sum, several blocks) against scipy's, cell by cell."""
    sums = [HarmonicSum(amplitudes=(0.3, 0.15), frequencies=(2.0, 5.0), duration=15.0),
            HarmonicSum(amplitudes=(0.2, 0.2, 0.1), frequencies=(1.0, 2.5, 7.0),
                        phases=(0.3, 0.0, 1.0), duration=25.0)]
    blocks = (Block(hb=2.0), Block(hb=3.0, law="mao"))
    cells = [(b, s, g) for b in blocks for s in sums for g in (0.8, 1.5, 2.5, 4.0)]
    bl = tuple(dict.fromkeys(c[0] for c in cells))
    batch = (bl, tuple(c[1] for c in cells), np.array([bl.index(c[0]) for c in cells]),
             np.arange(len(cells)), np.array([c[2] for c in cells], dtype=float))
    settings = grid_settings(None)
    got = compiled_kernel(*batch, settings, "rockjit")
    ref = B.scipy_kernel(*batch, settings, REF)
    assert len(set(ref["outcome"].tolist())) >= 2  # safe and overturned cells both
    np.testing.assert_array_equal(got["outcome"], ref["outcome"])
    np.testing.assert_array_equal(got["n_impacts"], ref["n_impacts"])
    np.testing.assert_allclose(got["max_rotation"], ref["max_rotation"], rtol=0, atol=1e-7)


@pytest.mark.parametrize("kw, match", [
    (dict(amplitudes=()), "amplitudes must be 1 to 64"),
    (dict(amplitudes=(1.0, 2.0), frequencies=(1.0,)), "frequencies must be as many"),
    (dict(frequencies=(0.0,)), r"frequencies\[0\]"),
    (dict(amplitudes=(float("nan"),)), "amplitudes"),
    (dict(duration=0.0), "duration"),
    (dict(phases=(1.0, 2.0)), "phases must be as many"),
    (dict(amplitudes=(6e7, 6e7), frequencies=(1.0, 2.0)), "sum of magnitudes"),
])
def test_bad_sums_are_refused_naming_the_parameter(kw, match):
    with pytest.raises(ValueError, match=match):
        HarmonicSum(**kw)
