"""Grids on every core: chunks that run at once give the same results, bit for bit, and keep
progress, resumption, cancellation and errors working; the device setting says no clearly.

Checked against: the kernel called once on the whole grid with one thread (no chunks, nothing
at once); a runner that counts, for a fact, how many of its calls run at once; the store's
manifest as written; numba's own answer on whether a CUDA device is usable here.
"""

import json
import threading
import time

import numba
import numpy as np
import pytest

import rockjit
from rockjit import Block, Classification, Execution, Harmonic, Integration
from rockjit._engine import kernel
from rockjit.grids import runner
from rockjit.settings import cuda_missing

OUTPUTS = ("res", "pts", "imp", "n_got", "n_imp_got")


def _plan(grid=9, periods=40, early_stop=True, lyapunov=False):
    return rockjit.basin.plan(Block(1.0), Harmonic(alpha=0.66, omega=1.3), grid,
                              integration=Integration(periods=periods, window=20),
                              classification=Classification(early_stop=early_stop),
                              lyapunov=lyapunov)


def _whole(p):
    """The kernel once on every cell, one thread: no chunk, nothing at once."""
    return kernel.run_chunk(p.tangent, p.y0s, p.pars, p.ipar, p.cpar, p.n_pts, p.n_imp_pts, 1)


def _chunked(p, **execution):
    return runner.run_grid(p.y0s, p.pars, p.ipar, p.cpar, tangent=p.tangent, n_pts=p.n_pts,
                           n_imp_pts=p.n_imp_pts, label="test", execution=Execution(**execution))


def _same(a, b):
    for k in OUTPUTS:
        assert a[k].shape == b[k].shape and np.array_equal(a[k], b[k], equal_nan=True), k


@pytest.mark.parametrize("early_stop", [True, False])
def test_any_chunking_gives_the_same_cells_bit_for_bit(early_stop):
    p = _plan(early_stop=early_stop)  # 81 cells
    ref = _whole(p)
    threads = numba.config.NUMBA_NUM_THREADS
    for chunk in (1, 7, 40, 81, None):
        for t in sorted({1, threads}):
            _same(_chunked(p, chunk=chunk, threads=t), ref)


def test_grids_with_exponents_too():
    p = _plan(grid=5, periods=30, lyapunov=True)
    _same(_chunked(p, chunk=3), _whole(p))


@pytest.mark.parametrize("safe, plans", [
    (True, {1: (1, 1), 3: (1, 3), 16: (1, 16)}),  # pieces of one thread, `threads` at once
    (False, {1: (1, 1), 3: (3, 1), 16: (16, 1)}),  # one call at a time on every thread
])
def test_local_plan_never_asks_for_more_threads_than_given(monkeypatch, safe, plans):
    monkeypatch.setattr(runner, "_thread_safe_layer", lambda: safe)
    for threads, plan in plans.items():
        assert runner.local_plan(threads) == plan


# the pieces by hand: each holds (cells not yet given out) // (2 * at_once) cells, at least 32
# and at most `largest`, and ends at its chunk's end if that comes first
@pytest.mark.parametrize("bounds, at_once, largest, expected", [
    # 200 // 4 = 50, 150 // 4 = 37, then 28, 20, 12 and 4 cells: 32, the last cut to 17
    ([(0, 200)], 2, 4096, [(0, 50, 0), (50, 87, 0), (87, 119, 0), (119, 151, 0),
                           (151, 183, 0), (183, 200, 0)]),
    # 130 // 2 = 65 and 90 // 2 = 45: 40 at most; 50 // 2 = 25: 32, cut to 20 at the chunk's
    # end; 30 // 2 = 15: 32, the whole second chunk
    ([(0, 100), (100, 130)], 1, 40, [(0, 40, 0), (40, 80, 0), (80, 100, 0), (100, 130, 1)]),
    # 10000 // 2 = 5000: 4096 at most; then 5904 // 2 = 2952, 1476, 738, 369, 184, 92, 46,
    # then 47 // 2 = 23: 32, then the last 15
    ([(0, 10000)], 1, 4096, [(0, 4096, 0), (4096, 7048, 0), (7048, 8524, 0), (8524, 9262, 0),
                             (9262, 9631, 0), (9631, 9815, 0), (9815, 9907, 0),
                             (9907, 9953, 0), (9953, 9985, 0), (9985, 10000, 0)]),
    # chunks shorter than the smallest piece are one piece each
    ([(0, 5), (5, 10)], 4, 4096, [(0, 5, 0), (5, 10, 1)]),
])
def test_pieces_cover_each_chunk_in_order_and_shrink_to_the_end(bounds, at_once, largest,
                                                                 expected):
    got = list(runner.pieces(bounds, at_once, smallest=32, largest=largest))
    assert got == expected
    for k, (a, b) in enumerate(bounds):
        mine = [(p, q) for p, q, kk in got if kk == k]
        assert mine[0][0] == a and mine[-1][1] == b
        assert all(q0 == p1 for (_, q0), (p1, _) in zip(mine, mine[1:]))


def _counting(calls, state, lock, delay=0.02, fail_at=None):
    def run(x):
        with lock:
            state["now"] += 1
            state["most"] = max(state["most"], state["now"])
            k = len(calls)
            calls.append((int(x[0]), int(x[-1]) + 1))
        try:
            if fail_at is not None and k == fail_at:
                raise ZeroDivisionError("chunk failed")
            time.sleep(delay)  # releases the GIL, as the compiled kernels do
            return {"y": np.sqrt(x) + 1.0}
        finally:
            with lock:
                state["now"] -= 1
    return run


@pytest.mark.parametrize("at_once", [1, 3, 5])
def test_chunks_run_at_once_and_land_in_place(at_once):
    n, chunk = 430, 40
    calls, state, lock = [], dict(now=0, most=0), threading.Lock()
    out = {"y": np.zeros(n), "pair": np.zeros((n, 2))}
    seen = []

    def run(x):
        got = _counting(calls, state, lock, delay=0.005)(x)
        return dict(got, pair=np.stack([x, -x], axis=1))

    x = np.arange(n, dtype=float)
    runner.run_chunks(run, (x,), n, chunk, out, at_once=at_once,
                      progress=lambda d, t: seen.append(d))
    assert np.array_equal(out["y"], np.sqrt(x) + 1.0)
    assert np.array_equal(out["pair"], np.stack([x, -x], axis=1))
    spans = sorted(calls)
    assert spans[0][0] == 0 and spans[-1][1] == n
    assert all(q0 == p1 for (_, q0), (p1, _) in zip(spans, spans[1:]))
    if at_once == 1:  # whole chunks, one at a time
        assert spans == [(a, min(n, a + chunk)) for a in range(0, n, chunk)]
    else:
        assert len(spans) > n // chunk  # the chunks were cut into pieces
    # at most at_once calls at a time, and (with their sleeps) more than one when allowed
    assert state["most"] >= 2 if at_once > 1 else state["most"] == 1
    assert state["most"] <= at_once
    # progress is told once at the start, then once per chunk, in whole chunks (in the order
    # the chunks finish: the short last chunk may land before a full one)
    assert seen[0] == 0 and seen[-1] == n and seen == sorted(seen) and len(seen) == 12
    assert sorted(np.diff(seen)) == [n - 10 * chunk] + [chunk] * 10


def test_a_grid_keeps_to_its_threads(monkeypatch):
    p = _plan(grid=10, periods=30)
    ref = _whole(p)
    real = kernel.run_chunk
    state, lock, per_call = dict(now=0, most=0), threading.Lock(), []

    def counted(*args):
        with lock:
            state["now"] += 1
            state["most"] = max(state["most"], state["now"])
            per_call.append(args[7])
        try:
            time.sleep(0.01)
            return real(*args)
        finally:
            with lock:
                state["now"] -= 1

    monkeypatch.setattr(kernel, "run_chunk", counted)
    real_layer = runner._thread_safe_layer
    threads = min(2, numba.config.NUMBA_NUM_THREADS)
    # a layer that cannot launch kernels from several threads: one call at a time on them all
    monkeypatch.setattr(runner, "_thread_safe_layer", lambda: False)
    _same(_chunked(p, threads=threads, chunk=50), ref)
    assert set(per_call) == {threads} and state["most"] == 1
    if not real_layer():
        pytest.skip("numba's threading layer here cannot launch kernels from two threads")
    # one that can: calls of one thread each, never more at once than the threads
    monkeypatch.setattr(runner, "_thread_safe_layer", lambda: True)
    per_call.clear()
    state["most"] = 0
    _same(_chunked(p, threads=threads, chunk=50), ref)
    assert set(per_call) == {1}
    assert state["most"] >= 2 if threads > 1 else state["most"] == 1
    assert state["most"] <= threads


def test_a_cancelled_run_starts_nothing_more_and_stores_what_ran(tmp_path):
    from rockjit.storage import chunkstore
    n, chunk, at_once = 40, 4, 3
    x = np.arange(n, dtype=float)
    key = chunkstore.fingerprint((x,), {})
    calls, state, lock = [], dict(now=0, most=0), threading.Lock()

    def cancel(done, total):
        if done >= 2 * chunk:
            raise KeyboardInterrupt

    store = chunkstore.ChunkStore(tmp_path / "s", key, n, chunk)
    with pytest.raises(KeyboardInterrupt):
        runner.run_chunks(_counting(calls, state, lock), (x,), n, chunk, {"y": np.zeros(n)},
                          store=store, at_once=at_once, progress=cancel)
    assert len(calls) <= 2 + at_once  # two placed, then at most the ones already running
    stored = sorted(tmp_path.joinpath("s").glob("cells-*.npz"))
    assert len(stored) == len(calls)  # every chunk that ran is kept
    assert not store.locked and state["now"] == 0
    # the rerun computes only the rest
    again = []
    out = {"y": np.zeros(n)}
    runner.run_chunks(_counting(again, state, lock), (x,), n, chunk, out,
                      store=chunkstore.ChunkStore(tmp_path / "s", key, n, chunk),
                      at_once=at_once)
    assert sorted(calls + again) == [(a, a + chunk) for a in range(0, n, chunk)]
    assert np.array_equal(out["y"], np.sqrt(x) + 1.0)


def test_a_failing_chunk_raises_after_the_others_finish():
    n, chunk = 40, 4
    calls, state, lock = [], dict(now=0, most=0), threading.Lock()
    with pytest.raises(ZeroDivisionError, match="chunk failed"):
        runner.run_chunks(_counting(calls, state, lock, fail_at=2), (np.arange(n, dtype=float),),
                          n, chunk, {"y": np.zeros(n)}, at_once=3)
    assert state["now"] == 0  # nothing runs on after the error is raised
    assert len(calls) < n // chunk


@pytest.mark.parametrize("ahead", [True, False])
def test_ahead_the_next_chunk_starts_before_the_last_is_placed(ahead):
    """``ahead`` (the GPU's chunks): whole chunks, one call at a time, and the next chunk's call
    running before the chunk just finished is placed and reported; without, the next call waits
    for the placing (the wait below then times out)."""
    n, chunk = 100, 30
    calls, state, lock = [], dict(now=0, most=0), threading.Lock()
    count = _counting(calls, state, lock, delay=0.0)
    started = [threading.Event() for _ in range(4)]

    def run(x):
        started[int(x[0]) // chunk].set()
        return count(x)

    running_next = []

    def progress(done, total):
        if 0 < done < n:  # chunk done // chunk - 1 placed: has the next one started?
            running_next.append(started[done // chunk].wait(timeout=2.0 if ahead else 0.2))

    x = np.arange(n, dtype=float)
    out = {"y": np.zeros(n)}
    runner.run_chunks(run, (x,), n, chunk, out, ahead=ahead, progress=progress)
    assert np.array_equal(out["y"], np.sqrt(x) + 1.0)
    assert calls == [(0, 30), (30, 60), (60, 90), (90, 100)] and state["most"] == 1
    assert running_next == [ahead] * 3


def test_ahead_a_failing_chunk_raises_and_the_chunks_before_it_are_stored(tmp_path):
    from rockjit.storage import chunkstore
    n, chunk = 40, 8
    calls, state, lock = [], dict(now=0, most=0), threading.Lock()
    store = chunkstore.ChunkStore(tmp_path / "s", "k", n, chunk)
    with pytest.raises(ZeroDivisionError, match="chunk failed"):
        runner.run_chunks(_counting(calls, state, lock, fail_at=3), (np.arange(n, dtype=float),),
                          n, chunk, {"y": np.zeros(n)}, store=store, ahead=True)
    assert state["now"] == 0 and len(calls) == 4
    assert [a for a in range(0, n, chunk) if store.has(a, a + chunk)] == [0, 8, 16]


def test_a_rerun_without_a_chunk_keeps_the_chunk_the_first_run_gave(tmp_path, monkeypatch):
    p = _plan(grid=6, periods=30)
    first = _chunked(p, chunk=5, threads=1, store=tmp_path / "s")
    manifest = (tmp_path / "s" / "manifest.json").read_text()
    assert '"chunk": 5' in manifest
    from rockjit.storage.chunkstore import ChunkStore
    key, n = json.loads(manifest)["key"], p.y0s.shape[0]
    assert ChunkStore.stored_chunk(tmp_path / "s", key, n) == 5
    for other in ((tmp_path / "s", key, n - 1), (tmp_path / "s", "other", n),
                  (tmp_path / "none", key, n)):
        assert ChunkStore.stored_chunk(*other) is None
    calls = []
    monkeypatch.setattr(kernel, "run_chunk", lambda *a: calls.append(a) or None)
    assert kernel.default_chunk(p.y0s.shape[0]) != 5
    again = _chunked(p, store=tmp_path / "s")  # no chunk given: loads them all
    assert calls == []
    _same(again, first)


def test_device_is_cpu_or_cuda():
    assert Execution().device == "cpu" and Execution(device="cpu").device == "cpu"
    for bad in ("gpu", "CUDA", "", None, 0):
        with pytest.raises(ValueError, match=r"device must be one of 'cpu', 'cuda'"):
            Execution(device=bad)


def test_cuda_without_a_gpu_is_one_clear_line(monkeypatch):
    try:
        from numba import cuda
        usable = bool(cuda.is_available())
    except Exception:
        usable = False
    assert (cuda_missing() is None) == usable
    with pytest.raises(ValueError) as exc:
        Execution(device="cuda")
    text = str(exc.value)
    assert "\n" not in text and "numba-cuda" in text and "GPU" in text and 'device="cpu"' in text
    # numba-cuda absent: the import fails, and the line says so
    import sys
    monkeypatch.setitem(sys.modules, "numba.cuda", None)
    assert cuda_missing() == "numba-cuda is not installed"
    with pytest.raises(ValueError, match="numba-cuda is not installed"):
        Execution(device="cuda")


def test_cuda_on_a_gpu_is_taken(monkeypatch):
    import rockjit.settings as st
    monkeypatch.setattr(st, "cuda_missing", lambda: None)
    assert Execution(device="cuda").device == "cuda"


def test_cli_device(tmp_path, capsys):
    from rockjit.cli.main import main
    args = ["basin", "--hb", "1", "--alpha", "0.66", "--omega", "1.3", "--grid", "3",
            "--periods", "10", "--quiet"]
    assert main(args + ["--out", str(tmp_path / "a"), "--device", "cuda"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("rockjit: error: --device cuda needs") and "\n" not in err
    assert "--device cpu" in err
    assert not (tmp_path / "a").exists()
    assert main(args + ["--out", str(tmp_path / "b"), "--device", "cpu"]) == 0
    assert main(args + ["--out", str(tmp_path / "c"), "--device", "tpu"]) == 2
    assert "invalid choice" in capsys.readouterr().err
