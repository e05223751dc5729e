"""Grids on a Dask cluster and resumable runs (issue 6).

Checked against the in-process computation of the same grid: identical arrays whether the
chunks ran here or on two worker processes, after a worker was killed mid-run, and after an
interrupted run was resumed from its store.
"""

import os
import threading
import time

import dask.distributed as distributed
import numpy as np
import pytest

from rockjit.grids import runner as grid_runner
from rockjit.grids import grids as an
from rockjit.storage import chunkstore as chunks
from rockjit._engine import kernel
from rockjit.cli.main import main


PLANE = dict(hb=1, alpha_range=(0.4, 1.0), omega_range=(0.9, 1.8), grid=(8, 6), periods=120)


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
    assert not list(store.glob(".*.tmp"))  # nothing half-written (rockjit.storage.files names)
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
    assert main(args[:-3] + ["--scheduler", "tcp://127.0.0.1:9", "--out",
                             str(tmp_path / "x"), "--quiet"]) == 2
    assert "cannot reach the Dask scheduler" in capsys.readouterr().err


def _small_chunks(run_grid):
    def wrapped(*a, **kw):
        kw["chunk"] = 8
        return run_grid(*a, **kw)
    return wrapped
