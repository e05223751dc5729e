"""Runs stopped once decided against the same runs carried on to their time limit, both paths.

With ``stop_when_decided`` (every spectrum and fragility curve) a run under a pulse or a record
stops after the excitation once free rocking can change neither its outcome nor its
``max_rotation``. The reference knows nothing of that rule: the same run, on the same path,
carried on to its time limit. The cells scan blocks (both laws, restitution near 1, no
damping), pulses of every kind that leave the block rocking or overturn it, and the same pulses
sampled into records of either sign: a record and its negative are mirror images, so runs are
decided on both sides of ``theta = 0``.
"""

from __future__ import annotations

import numpy as np
import pytest

import rockjit
from rockjit import Block, Pulse, Record, Scipy, Transient
from rockjit.ground import batch as B
from rockjit.ground.compiled import compiled_kernel
from rockjit.ground.response import SAFE

SCIPY = Scipy("DOP853", rtol=1e-10, atol=1e-12)
PATHS = {"compiled": "rockjit", "scipy": SCIPY}


def _settings(free_time, decide):
    return Transient(free_time=free_time, stop_when_decided=decide, record=False)


def _sampled(pulse, block, sign, n):
    """``pulse`` on ``block`` sampled at ``n`` instants into a record, times ``sign``."""
    bound = pulse.bind(block)
    f = bound.scalar()
    t = np.linspace(0.0, bound.end, n)
    per_second = Record(np.zeros(2), 1.0, size=1.0).time_factor  # model units per second
    return Record(sign * np.array([f(x) for x in t]), (t[1] - t[0]) / per_second, size=1.0)


def _pair(block, exc, method, free_time):
    """``(full, cut)``: one run to its time limit and stopped once decided."""
    full = rockjit.simulate(block, exc, method=method, integration=_settings(free_time, False))
    cut = rockjit.simulate(block, exc, method=method, integration=_settings(free_time, True))
    return full, cut


def _same(full, cut, what, rel):
    assert cut.outcome == full.outcome, what
    assert cut.max_rotation == pytest.approx(full.max_rotation, rel=rel, abs=1e-15), what
    assert cut.t <= full.t, what
    if cut.status == "decided":
        assert full.status in ("rest", "time_limit") and cut.t >= cut.excitation.end, what


@pytest.mark.parametrize("path", PATHS)
def test_a_wider_swing_after_the_pulse_is_kept(path):
    """The block leaves the one-cosine pulse moving back towards theta = 0 below the tipping
    energy, and after the next impact swings wider than ever during the pulse."""
    block = Block(hb=4, law="constant", e=0.95)
    pulse = Pulse("cosine", ratio=5.0, amplitude=1.6)
    method = PATHS[path]
    full = rockjit.simulate(block, pulse, method=method, integration=Transient(free_time=10.0))
    end = pulse.bind(block).end
    during = np.max(np.abs(full.trajectory[full.trajectory[:, 0] <= end, 1]))
    assert full.max_theta > 1.01 * during  # the widest swing comes after the pulse
    cut = rockjit.simulate(block, pulse, method=method,
                           integration=Transient(free_time=10.0, stop_when_decided=True))
    assert cut.status == "decided" and full.status == "time_limit"
    _same(full, cut, path, rel=1e-12)
    # a grid's cell (the compiled kernel, as spectra and fragility curves run it) too
    if path == "compiled":
        got = compiled_kernel((block,), (Pulse("cosine", ratio=5.0, amplitude=1.0, hb=4.0),),
                              np.array([0]), np.array([0]), np.array([1.6]),
                              _settings(10.0, True), "rockjit")
        assert got["max_rotation"][0] == pytest.approx(full.max_rotation, rel=1e-12)


#: blocks that lose little energy at an impact (e near 1, none at all) and the study's laws
BLOCKS = [Block(hb=4, law="constant", e=0.95), Block(hb=3, law="constant", e=1.0, xi=0.0),
          Block(hb=6, law="constant", e=0.98), Block(hb=4, law="housner"),
          Block(hb=2, law="mao")]


def _forms(pulse, block, n):
    """The pulse, and it sampled into a record and into its negative."""
    return [("pulse", pulse), ("record", _sampled(pulse, block, 1.0, n)),
            ("negative record", _sampled(pulse, block, -1.0, n))]


def test_the_compiled_path_decides_as_the_full_run_ends():
    sides = []
    outcomes = set()
    for block in BLOCKS:
        for kind in ("sine", "cosine", "ricker"):
            for ratio in (2.0, 5.0):
                for amp in (1.6, 3.0):
                    pulse = Pulse(kind, ratio=ratio, amplitude=amp)
                    for form, exc in _forms(pulse, block, 601):
                        full, cut = _pair(block, exc, "rockjit", 30.0)
                        what = (block, kind, ratio, amp, form)
                        _same(full, cut, what, rel=1e-9)
                        outcomes.add(full.outcome)
                        if cut.status == "decided":
                            sides.append(np.sign(cut.state[0]))
    # the scan decides runs on both sides of theta = 0 and holds overturning runs
    assert sides.count(-1.0) >= 20 and sides.count(1.0) >= 20
    assert len(outcomes - {SAFE}) >= 1


def test_the_scipy_path_decides_as_the_full_run_ends():
    sides = []
    for block in BLOCKS[:3]:
        for kind, ratio, amp in (("cosine", 5.0, 1.6), ("sine", 2.0, 1.6)):
            pulse = Pulse(kind, ratio=ratio, amplitude=amp)
            for form, exc in _forms(pulse, block, 101):
                full, cut = _pair(block, exc, SCIPY, 20.0)
                _same(full, cut, (block, kind, form), rel=1e-9)
                if cut.status == "decided":
                    sides.append(np.sign(cut.state[0]))
    assert sides.count(-1.0) >= 3 and sides.count(1.0) >= 3


def test_a_grid_of_mirror_images_decides_as_its_full_runs_end():
    """The compiled and scipy kernels of the batches, on records of either sign."""
    block = Block(hb=4, law="constant", e=0.95)
    recs = tuple(_sampled(Pulse("cosine", ratio=5.0, amplitude=1.0), block, sign, 101)
                 for sign in (1.0, -1.0))
    gains = np.array([1.3, 1.6, 2.2] * 2)
    batch = ((block,), recs, np.zeros(6, dtype=int), np.repeat([0, 1], 3), gains)
    for kernel, method in ((compiled_kernel, "rockjit"), (B.scipy_kernel, SCIPY)):
        full = kernel(*batch, _settings(20.0, False), method)
        cut = kernel(*batch, _settings(20.0, True), method)
        np.testing.assert_array_equal(cut["outcome"], full["outcome"])
        np.testing.assert_allclose(cut["max_rotation"], full["max_rotation"], rtol=1e-9)
        assert np.all(cut["status"] == B.STATUS_CODES.index("decided"))
