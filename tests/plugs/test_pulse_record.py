"""The pulses' and records' plugs: their compiled value and windows against their Python side.

The compiled functions (:func:`rockjit.plugs.pulse.pulse_value`, ``pulse_window``,
:func:`rockjit.plugs.record.record_value`, ``record_window``), called through the kernel's
dispatch, are held to what the scipy reference path evaluates: ``f`` (numpy) and
``windows(threshold)`` (closed forms, Brent's method on the Ricker lobes, vectorised linear
pieces for a record), written apart from them.
"""

import numpy as np
import pytest

from rockjit import Block, Pulse, Record
from rockjit.plugs import plug_value, plug_window


def _compiled_windows(x, a, thr):
    """Every window of the plug ``x`` at amplitude ``a`` above ``thr``, one after the other as
    the kernel asks for them."""
    c = x.coefficients()
    rows, t = [], 0.0
    while True:
        t0, t1, sg = plug_window(x.code, t, x.end, a, c, 0, c.size, thr)
        if sg == 0.0:
            return np.array(rows).reshape(-1, 3)
        assert t1 > t
        rows.append((t0, t1, sg))
        t = t1


def _pulses():
    rng = np.random.default_rng(5)
    for kind in ("sine", "cosine", "ricker"):
        for _ in range(12):
            yield Pulse(kind, ratio=float(rng.uniform(0.2, 8.0)),
                        amplitude=float(rng.uniform(0.5, 6.0))).bind(Block(hb=3))


def _records():
    rng = np.random.default_rng(9)
    for k in range(8):
        n = int(rng.integers(2, 400))
        yield Record(rng.normal(0.0, 0.3, n), float(rng.uniform(0.002, 0.05)),
                     size=float(rng.uniform(0.2, 5.0)), scale=float(rng.uniform(0.5, 3.0)))


@pytest.mark.parametrize("source", ["pulse", "record"])
def test_the_compiled_value_is_the_python_value(source):
    for x in (_pulses() if source == "pulse" else _records()):
        a = x.amplitude_at(np.ones(1))[0]
        c = x.coefficients()
        t = np.linspace(0.0, x.end, 301)
        got = np.array([plug_value(x.code, s, a, c, 0, c.size) for s in t])
        np.testing.assert_allclose(got, x.f(t), rtol=0, atol=1e-13 * x.peak)


@pytest.mark.parametrize("source", ["pulse", "record"])
def test_the_compiled_windows_are_the_python_windows(source):
    """Every window, in order, at thresholds below and above the side lobes; the ends within
    1e-12 (the Ricker wavelet's by bisection here, by Brent's method there)."""
    n_windows = 0
    for x in (_pulses() if source == "pulse" else _records()):
        a = x.amplitude_at(np.ones(1))[0]
        for frac in (0.05, 0.2, 0.5, 0.9, 1.1):
            thr = frac * x.peak
            got, ref = _compiled_windows(x, a, thr), x.windows(thr)
            assert got.shape == ref.shape, (x, frac)
            np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12)
            n_windows += len(ref)
    assert n_windows > 50


def test_the_amplitude_of_a_scaled_source_is_what_the_reference_path_forms():
    p = Pulse("ricker", ratio=2.0, amplitude=3.0).bind(Block(hb=4))
    gains = np.array([0.5, 1.0, 3.0])
    assert list(p.amplitude_at(gains)) == [p.scaled(g).accel for g in gains]
    r = Record(np.array([0.0, 0.2, -0.1]), 0.01, size=1.0, scale=2.0)
    assert list(r.amplitude_at(gains)) == [r.scaled(g).scale for g in gains]
