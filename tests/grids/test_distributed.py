"""Grids on a Dask cluster and resumable runs.

Checked against the in-process computation of the same grid: identical arrays whether the
chunks ran here or on two worker processes, after a worker was killed mid-run, after an
interrupted run was resumed from its store, and when several computations share one client (in
a row or at once). A scheduler without workers ends a computation, with a clear error, after
its timeout.
"""

import os
import threading
import time

import dask.distributed as distributed
import numpy as np
import pytest

import rockjit
from rockjit import Block, Execution, Harmonic, Integration
from rockjit.grids import runner as grid_runner
from rockjit.storage import chunkstore as chunks
from rockjit._engine import kernel
from rockjit.cli.main import main


PLANE = dict(hb=1, alpha_range=(0.4, 1.0), omega_range=(0.9, 1.8), grid=(8, 6), periods=120)


class an:
    """The grids of these tests, from their parameters in a few words: ``execution``'s fields
    (``chunk``, ``client``, ``store``) as keywords."""

    @staticmethod
    def _execution(kw):
        return Execution(**{k: kw.pop(k) for k in ("chunk", "client", "store") if k in kw})

    @staticmethod
    def plane(hb, alpha_range, omega_range, grid, periods, **kw):
        return rockjit.plane(Block(hb=hb), alpha_range, omega_range, grid=grid,
                             integration=Integration(periods=periods),
                             execution=an._execution(kw))

    @staticmethod
    def basin(hb, alpha, omega, grid, periods, **kw):
        return rockjit.basin(Block(hb=hb), Harmonic(alpha=alpha, omega=omega), grid,
                             integration=Integration(periods=periods),
                             execution=an._execution(kw))

    @staticmethod
    def sweep(hb, omega, alphas, periods, **kw):
        return rockjit.sweep(Block(hb=hb), Harmonic(omega=omega), alphas,
                             integration=Integration(periods=periods),
                             execution=an._execution(kw))


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


@pytest.fixture(scope="module")
def local_plane():
    return an.plane(**PLANE, chunk=6)


def same(a, b):
    for name in ("label", "period", "lambda_max", "t_end"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


def test_distributed_equals_in_process(client, local_plane):
    same(an.plane(**PLANE, chunk=6, client=client), local_plane)
    b_local = an.basin(1, 0.66, 1.3, grid=10, periods=100, chunk=13)
    b_dist = an.basin(1, 0.66, 1.3, grid=10, periods=100, chunk=13, client=client)
    np.testing.assert_array_equal(b_dist.label, b_local.label)
    sw_local = an.sweep(1, 1.3, np.linspace(0.55, 0.98, 12), periods=100, chunk=5)
    sw_dist = an.sweep(1, 1.3, np.linspace(0.55, 0.98, 12), periods=100, chunk=5,
                       client=client)
    np.testing.assert_array_equal(sw_dist.label, sw_local.label)
    np.testing.assert_array_equal(sw_dist.strobe, sw_local.strobe)


def test_losing_a_worker_mid_run_still_completes(client, local_plane, tmp_path):
    store = tmp_path / "store"
    out = {}

    def run():
        out["plane"] = an.plane(**PLANE, chunk=2, client=client, store=store)

    th = threading.Thread(target=run)
    th.start()
    deadline = time.time() + 120
    while not list(store.glob("cells-*.npz")) and time.time() < deadline:
        time.sleep(0.05)
    assert list(store.glob("cells-*.npz")), "no chunk finished"
    victim = list(client.scheduler_info()["workers"])[0]
    try:
        client.run(os._exit, 1, workers=[victim])
    except Exception:
        pass  # the worker died before answering, as intended
    th.join(timeout=300)
    assert not th.is_alive()
    same(out["plane"], local_plane)
    client.wait_for_workers(2, timeout=60)  # the nanny restarts the worker for later tests


def test_interrupted_run_resumes(tmp_path, local_plane, monkeypatch):
    store = tmp_path / "store"
    real = kernel.run_chunk
    calls = []

    def interrupt_after_three(*args):
        if len(calls) == 3:
            raise KeyboardInterrupt
        calls.append(args[1].shape[0])
        return real(*args)

    monkeypatch.setattr(kernel, "run_chunk", interrupt_after_three)
    with pytest.raises(KeyboardInterrupt):
        an.plane(**PLANE, chunk=6, store=store)
    done = sorted(store.glob("cells-*.npz"))
    assert len(done) == 3
    assert not list(store.glob(".*.tmp"))  # nothing half-written (rockjit.storage.atomic names)
    assert not (store / "lock.json").exists()  # the interrupted run released the store
    counted = []

    def count(*args):
        counted.append(args[1].shape[0])
        return real(*args)

    monkeypatch.setattr(kernel, "run_chunk", count)
    resumed = an.plane(**PLANE, chunk=6, store=store)
    assert sum(counted) == 48 - 3 * 6  # only the missing cells were computed
    same(resumed, local_plane)


def test_store_refuses_another_computation(tmp_path):
    store = tmp_path / "store"
    an.basin(1, 0.66, 1.3, grid=4, periods=30, store=store)
    with pytest.raises(ValueError, match="different computation"):
        an.basin(1, 0.70, 1.3, grid=4, periods=30, store=store)


def test_fingerprint_sees_every_input():
    a = np.arange(6.0).reshape(3, 2)
    base = chunks.fingerprint((a,), dict(x=1))
    b = a.copy()
    b[2, 1] += 1e-12
    assert chunks.fingerprint((b,), dict(x=1)) != base
    assert chunks.fingerprint((a,), dict(x=2)) != base
    assert chunks.fingerprint((a.astype(np.float32),), dict(x=1)) != base
    assert chunks.fingerprint((a.copy(),), dict(x=1)) == base


def test_plane_command_resumes_and_cleans_up(tmp_path, monkeypatch, capsys):
    out = tmp_path / "plane"
    args = ["plane", "--hb", "1", "--alpha-range", "0.4", "1.0", "--omega-range", "0.9",
            "1.8", "--grid", "8", "6", "--periods", "120", "--out", str(out), "--quiet"]
    real = kernel.run_chunk
    n = []

    def interrupt_once(*a):
        if len(n) == 1:
            raise KeyboardInterrupt
        n.append(1)
        return real(*a)

    monkeypatch.setattr(kernel, "run_chunk", interrupt_once)
    monkeypatch.setattr(grid_runner, "run_grid", _small_chunks(grid_runner.run_grid))
    assert main(args) == 130
    assert not out.exists()  # --out is written only once everything is computed
    assert list((tmp_path / "plane.chunks" / "plane").glob("cells-*.npz"))
    monkeypatch.setattr(kernel, "run_chunk", real)
    assert main(args) == 0
    assert not (tmp_path / "plane.chunks").exists()
    z = np.load(out / "plane.npz")
    local = an.plane(**PLANE)
    np.testing.assert_array_equal(z["label"], local.label[0])
    assert main(args[:-3] + ["--scheduler", "tcp://127.0.0.1:9", "--scheduler-timeout", "2",
                             "--out", str(tmp_path / "x"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "rockjit: error: --scheduler tcp://127.0.0.1:9: cannot reach the Dask scheduler" in err


def _small_chunks(run_grid):
    def wrapped(*a, **kw):
        kw["execution"] = kw["execution"].replace(chunk=8)
        return run_grid(*a, **kw)
    return wrapped


# ---------------------------------------------------------------------------------------------
# computations sharing a scheduler; a scheduler without workers
# ---------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def thread_client():
    """One in-process worker with two threads: quick to start, and enough to run two
    computations at once."""
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                       dashboard_address=":0")
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


ALPHAS = (0.62, 0.66, 0.70, 0.74)


def _basin_at(alpha, **kw):
    return an.basin(1, alpha, 1.3, grid=6, periods=30, chunk=6, **kw)


def _same_basin(a, b, what):
    for name in ("label", "period", "t_end"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name),
                                      err_msg=f"{what}: {name}")


#: How long a call may run before it counts as waiting forever (the fault these tests guard
#: against): a bound far above any normal run, so that it never decides a correct run's fate.
HANG = 300


def _returns(fn, *args):
    """``fn(*args)`` in a thread, returned or raised; a call that never returns (a wait for
    workers without end) fails the test instead of hanging the suite."""
    box = {}

    def run():
        try:
            box["value"] = fn(*args)
        except BaseException as exc:  # noqa: BLE001 - handed to the caller
            box["error"] = exc

    th = threading.Thread(target=run, daemon=True)
    th.start()
    th.join(HANG)
    if th.is_alive():
        pytest.fail(f"{getattr(fn, '__name__', fn)} never returned: it waits forever")
    if "error" in box:
        raise box["error"]
    return box["value"]


def test_computations_in_a_row_on_one_client_get_their_own_results(thread_client):
    # task keys used to repeat from one computation to the next: of eight basins in a row,
    # five came back with an earlier basin's chunks
    local = {a: _basin_at(a) for a in ALPHAS}
    for i in range(8):
        a = ALPHAS[i % len(ALPHAS)]
        _same_basin(_basin_at(a, client=thread_client), local[a], f"run {i}, alpha {a}")


def test_computations_at_once_on_one_client_get_their_own_results(thread_client):
    local = {a: _basin_at(a) for a in (0.66, 0.70)}
    for _ in range(3):
        got = {}
        start = threading.Barrier(2)

        def run(a):
            start.wait()
            got[a] = _basin_at(a, client=thread_client)

        threads = [threading.Thread(target=run, args=(a,)) for a in local]
        for th in threads:
            th.start()
        for th in threads:
            th.join(300)
        for a in local:
            _same_basin(got[a], local[a], f"alpha {a}")


def test_a_result_of_another_task_is_refused(thread_client, monkeypatch):
    def wrong(runner, tag, *args):
        return "another computation:0:1", runner(*args)

    monkeypatch.setattr(grid_runner, "_tagged", wrong)
    with pytest.raises(RuntimeError, match="not its chunk's"):
        _basin_at(0.66, client=thread_client)


@pytest.fixture
def no_workers():
    """A scheduler without any worker."""
    cluster = distributed.LocalCluster(n_workers=0, processes=False, protocol="tcp",
                                       dashboard_address=":0")
    try:
        yield cluster
    finally:
        cluster.close()


def test_a_scheduler_without_workers_is_an_error_after_the_timeout(no_workers, capsys):
    msgs = []
    with distributed.Client(no_workers) as c:
        with pytest.raises(grid_runner.NoWorkers, match="had no worker in 1 s"):
            _returns(lambda: grid_runner.run_chunks(
                kernel.run_chunk, (), 4, 2, {}, client=c, message=msgs.append,
                worker_timeout=1))
        assert len(msgs) == 1 and msgs[0].startswith("waiting for a worker on the Dask "
                                                     "scheduler at ")

        def basin_in_half_a_second():
            with grid_runner.worker_timeout(0.5):  # the default a block sets (the CLI's)
                return _basin_at(0.66, client=c)

        with pytest.raises(grid_runner.NoWorkers, match="in 0.5 s"):
            _returns(basin_in_half_a_second)


def test_the_command_line_gives_up_on_a_scheduler_without_workers(no_workers, tmp_path,
                                                                   capsys):
    out = tmp_path / "b"
    argv = ["basin", "--hb", "1", "--alpha", "0.66", "--omega", "1.3", "--grid", "4",
            "--periods", "20", "--scheduler", no_workers.scheduler_address,
            "--scheduler-timeout", "1", "--out", str(out)]
    assert _returns(main, argv) == 2
    err = capsys.readouterr().err.splitlines()
    assert any(line.startswith("rockjit: waiting for a worker") for line in err), err
    assert err[-1].startswith(f"rockjit: error: --scheduler {no_workers.scheduler_address}: ")
    assert "had no worker in 1 s" in err[-1] and "--scheduler-timeout" in err[-1]
    assert not out.exists()


def _slow_chunk(x):
    time.sleep(0.3)
    return {"y": x * 2.0}


def test_losing_every_worker_mid_run_is_an_error_after_the_timeout():
    cluster = distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                       dashboard_address=":0")
    try:
        with distributed.Client(cluster) as c:
            x = np.arange(40.0)
            out = {"y": np.zeros(40)}
            msgs = []
            started = threading.Event()

            def run():
                return grid_runner.run_chunks(_slow_chunk, (x,), 40, 2, out, client=c,
                                              message=msgs.append, worker_timeout=1,
                                              progress=lambda done, total: done and
                                              started.set())

            def lose_the_workers():
                started.wait()  # one chunk is back: the run is under way
                cluster.scale(0)

            threading.Thread(target=lose_the_workers, daemon=True).start()
            with pytest.raises(grid_runner.NoWorkers, match="lost its workers"):
                _returns(run)
            assert out["y"].any()  # the chunks before the loss were placed
            assert any(m.startswith("waiting for a worker") for m in msgs)
    finally:
        cluster.close()
