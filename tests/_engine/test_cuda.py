"""The GPU driver (rockjit._engine.gpu), without a GPU: its kernels compile to PTX for sm_90, and
under numba's CUDA simulator it gives the CPU kernels' results; device="cuda" where it cannot
run is one line."""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

cuda = pytest.importorskip("numba.cuda", reason="numba-cuda is not installed")

from rockjit import Block, Classification, Execution, Harmonic, Integration  # noqa: E402
from rockjit._engine import kernel  # noqa: E402
from rockjit._engine.cell import R_LABEL, R_PERIOD, R_STATUS  # noqa: E402


@pytest.fixture
def sm90(monkeypatch):
    """numba-cuda asks the current device for its compute capability when it types a device
    function; with no device here, it is told sm_90's."""
    import numba.cuda.dispatcher as d
    monkeypatch.setattr(d, "get_current_device",
                        lambda: type("Device", (), {"compute_capability": (9, 0)})())


def _nvvm():
    from numba.cuda.cudadrv import nvvm
    try:
        return nvvm.is_available()
    except Exception:  # noqa: BLE001 - a broken NVVM is no NVVM
        return False


@pytest.mark.skipif(not _nvvm(), reason="numba-cuda finds no NVVM (pip install \"rockjit[cuda]\" "
                    "brings the CUDA 12 one)")
@pytest.mark.parametrize("name", ["tables", "cells", "cells+tangent", "transient"])
def test_kernels_compile_to_ptx_for_sm90(sm90, name):
    from rockjit._engine import gpu, gpu_transient
    driver = gpu_transient if name == "transient" else gpu
    kern = driver.kernels()[name]
    ptx, _ = cuda.compile_ptx(kern, driver.signatures()[name], cc=(9, 0))
    assert ".target sm_90" in ptx
    assert ptx.count(".entry ") == 1
    entry = {"tables": "_tables", "cells": "_cells_plain", "cells+tangent": "_cells_tangent",
             "transient": "_cells"}
    assert entry[name] in ptx.split(".entry ")[1].split("(")[0]
    if name != "transient":
        # the stage chain's and the polynomials' explicit fused multiply-adds, as on the CPU
        assert "fma.rn.f64" in ptx


#: The cases run under the simulator: a grid plan's constructor and its arguments (small: the
#: simulator runs each thread's Python, the compiled pieces on the CPU).
CASES = {
    "basin housner early": ("basin", dict(law="housner", early=True)),
    "basin mao full": ("basin", dict(law="mao", early=False)),
    "sweep exponents": ("sweep", dict(law="housner", early=False)),
    "plane exponents": ("plane", dict(law="mao", early=True)),
}

_PLANS = textwrap.dedent('''
    import numpy as np
    import rockjit
    from rockjit import Block, Classification, Harmonic, Integration

    def plan(kind, law, early):
        block = Block(hb=1, law=law)
        integ = Integration(periods=24, window=12)
        cl = Classification(early_stop=early)
        if kind == "basin":
            return rockjit.basin.plan(block, Harmonic(alpha=0.66, omega=1.3), grid=4,
                                      integration=integ, classification=cl)
        if kind == "sweep":
            return rockjit.sweep.plan(block, Harmonic(omega=1.3), np.linspace(0.3, 0.9, 6),
                                      integration=integ, classification=cl, lyapunov=True,
                                      n_impact_points=8)
        return rockjit.plane.plan(block, (0.3, 0.9), (1.0, 2.0), grid=(3, 3), integration=integ,
                                  classification=cl, lyapunov=True)

    def transient_spectrum():
        return (Block(hb=3, law="mao"), rockjit.Pulse("ricker"), np.geomspace(0.7, 5.0, 4),
                np.geomspace(1.1, 8.0, 4))

    def transient_ida():
        t = np.arange(0.0, 3.0, 0.01)
        rec = rockjit.Record(0.3 * np.sin(2 * np.pi * 1.2 * t) * np.sin(np.pi * t / 3.0), 0.01)
        return Block(hb=3), [rec], [0.5], [0.5, 1.05, 1.2, 1.5]
''')

_SIMULATED = _PLANS + textwrap.dedent('''
    import json, sys
    from rockjit import Execution
    from rockjit._engine import gpu
    assert gpu.SIMULATOR
    cases, path = json.loads(sys.argv[1]), sys.argv[2]
    got = {}
    for name, (kind, kw) in cases.items():
        p = plan(kind, **kw)
        # two launches of 5 and 11 cells: the scratch is reused
        out = gpu.run_chunk(p.tangent, p.y0s, p.pars, p.ipar, p.cpar, p.n_pts, p.n_imp_pts,
                            batch=min(5, len(p.y0s)))
        for k, v in out.items():
            got[f"{name}/{k}"] = v
    # the public path: a basin with Execution(device="cuda")
    b = rockjit.basin(Block(hb=1), Harmonic(alpha=0.66, omega=1.3), grid=4,
                      integration=Integration(periods=24, window=12),
                      classification=Classification(attractors=False),
                      execution=Execution(device="cuda"))
    got["api/label"] = b.label
    # the transient kernel: a spectrum of the Ricker wavelet and an IDA over a short record
    sp = rockjit.spectrum(*transient_spectrum(), locate=False,
                          execution=Execution(device="cuda"))
    fr = rockjit.fragility(*transient_ida(), execution=Execution(device="cuda"))
    for k, r in (("spectrum", sp), ("ida", fr)):
        got[f"{k}/outcome"], got[f"{k}/max_rotation"] = r.outcome, r.max_rotation
    np.savez(path, **got)
''')


def _cpu(kind, law, early):
    namespace = {}
    exec(_PLANS, namespace)  # noqa: S102 - the same plans as the simulated run's
    p = namespace["plan"](kind, law, early)
    return kernel.run_chunk(p.tangent, p.y0s, p.pars, p.ipar, p.cpar, p.n_pts, p.n_imp_pts,
                            threads=1)


@pytest.mark.slow  # its compilations are its own (see below): about a minute
def test_simulated_gpu_gives_the_cpu_kernels_results(tmp_path):
    """The driver's logic (tables per forcing, per-thread scratch, launches of part of the
    cells, classification and samples) run by numba's CUDA simulator against the CPU
    kernels (the lanes for the basins, the single-lane loop for the grids with exponents)."""
    path = tmp_path / "gpu.npz"
    # the simulator calls the CPU-compiled pieces from Python, specialised for its arrays: they
    # are compiled without LLVM's optimisations (which keep IEEE arithmetic: the same numbers,
    # sooner) into a cache of their own, which the CPU kernels never read
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1", NUMBA_OPT="0",
               NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    proc = subprocess.run([sys.executable, "-c", _SIMULATED, json.dumps(CASES), str(path)],
                          env=env, capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    got = np.load(path)
    labels = set()
    for name, (kind, kw) in CASES.items():
        cpu = _cpu(kind, **kw)
        res, gres = cpu["res"], got[f"{name}/res"]
        for col in (R_STATUS, R_LABEL, R_PERIOD):
            np.testing.assert_array_equal(gres[:, col], res[:, col], err_msg=name)
        labels |= set(res[:, R_LABEL].astype(int))
        np.testing.assert_array_equal(got[f"{name}/n_got"], cpu["n_got"], err_msg=name)
        np.testing.assert_array_equal(got[f"{name}/n_imp_got"], cpu["n_imp_got"], err_msg=name)
        # the strobe samples of the classified stretch (NaN where a cell has none): within
        # 1e-9 is what a GPU must give; the simulator runs the pieces compiled for the CPU, so
        # there every output is the CPU kernels' bit for bit
        np.testing.assert_allclose(got[f"{name}/pts"], cpu["pts"], rtol=0, atol=1e-9,
                                   err_msg=name)
        for k in ("res", "pts", "imp"):
            np.testing.assert_array_equal(got[f"{name}/{k}"], cpu[k], err_msg=f"{name} {k}")
    assert len(labels) >= 3  # the cases reach several behaviours, not one
    cpu_basin = _cpu("basin", "housner", True)
    np.testing.assert_array_equal(got["api/label"].ravel(), cpu_basin["res"][:, R_LABEL])
    namespace = {}
    exec(_PLANS, namespace)  # noqa: S102 - the same cases as the simulated run's
    import rockjit
    sp = rockjit.spectrum(*namespace["transient_spectrum"](), locate=False)
    fr = rockjit.fragility(*namespace["transient_ida"]())
    for k, r in (("spectrum", sp), ("ida", fr)):
        assert len(set(r.outcome.ravel())) >= 2, k  # safe and overturned cells both
        np.testing.assert_array_equal(got[f"{k}/outcome"], r.outcome, err_msg=k)
        np.testing.assert_array_equal(got[f"{k}/max_rotation"], r.max_rotation, err_msg=k)


def test_cuda_without_a_gpu_is_refused(monkeypatch):
    """Here (no GPU): one line naming what is missing; the grid is not run."""
    from rockjit.settings import cuda_missing
    if cuda_missing() is None:
        pytest.skip("this machine has a GPU")
    with pytest.raises(ValueError) as exc:
        Execution(device="cuda")
    text = str(exc.value)
    assert "\n" not in text and "GPU" in text and 'device="cpu"' in text


def test_cuda_with_a_gpu_is_taken_and_the_scipy_path_refuses_it(monkeypatch):
    """Where a GPU is usable, Execution(device="cuda") is accepted; a batch on the scipy
    reference path, which runs on the CPU only, refuses it in one line."""
    import rockjit.settings as st
    from rockjit import Scipy
    monkeypatch.setattr(st, "cuda_missing", lambda: None)
    ex = Execution(device="cuda", progress=False)
    assert ex.device == "cuda"
    from rockjit.ground.batch import run_batch
    with pytest.raises(ValueError) as exc:
        run_batch([None], None, Scipy("DOP853"), ex)
    text = str(exc.value)
    assert "\n" not in text and "scipy" in text and 'device="cpu"' in text


def test_cli_refuses_cuda_for_the_scipy_path_in_one_line(tmp_path, capsys, monkeypatch):
    import rockjit.settings as st
    from rockjit.cli.main import main
    monkeypatch.setattr(st, "cuda_missing", lambda: None)
    code = main(["spectrum", "--hb", "1", "--ratio-range", "1", "2", "--amplitude-range", "1",
                 "2", "--grid", "2", "2", "--out", str(tmp_path / "s"), "--device", "cuda",
                 "--method", "scipy", "--quiet"])
    err = capsys.readouterr().err.strip()
    assert code == 2 and "\n" not in err and "--device cuda runs the compiled path" in err
    assert "--device cpu" in err and not (tmp_path / "s").exists()


def test_cli_spectrum_on_cuda_runs_its_cells_on_the_gpu_driver(tmp_path, monkeypatch):
    """``rockjit spectrum --device cuda`` hands every cell to the transient GPU driver
    (here replaced by the CPU kernel on one thread, which records the cells it gets): the
    outputs are the CPU run's."""
    import rockjit.settings as st
    from rockjit._engine import gpu_transient
    from rockjit._engine import transient as T
    from rockjit.cli.main import main
    monkeypatch.setattr(st, "cuda_missing", lambda: None)
    seen = []

    def on_the_cpu(xpar, rec, bpar, block_of, spar, t_lim, max_impacts, decide, out_f, out_i):
        seen.append(xpar.shape[0])
        T.run_cells(xpar, rec, bpar, block_of, spar, t_lim, max_impacts, decide, 1, out_f,
                    out_i)
    monkeypatch.setattr(gpu_transient, "run_cells", on_the_cpu)
    args = ["spectrum", "--hb", "3", "--ratio-range", "1", "4", "--amplitude-range", "1.2",
            "6", "--grid", "3", "3", "--quiet", "--tol", "1e-3"]
    assert main(args + ["--out", str(tmp_path / "g"), "--device", "cuda"]) == 0
    assert sum(seen) >= 9
    assert main(args + ["--out", str(tmp_path / "c")]) == 0
    for name in sorted(p.name for p in (tmp_path / "c").iterdir() if p.suffix == ".npz"):
        a, b = np.load(tmp_path / "g" / name), np.load(tmp_path / "c" / name)
        for k in a.files:
            np.testing.assert_array_equal(a[k], b[k], err_msg=f"{name} {k}")


def test_chunks_on_the_gpu_fill_it():
    """A chunk is the whole grid up to 2**20 cells, about a twentieth beyond; a launch holds
    what half the free memory holds in scratch."""
    from rockjit._engine import gpu
    assert gpu.default_chunk(10_000) == 2**20 and gpu.default_chunk(10**6) == 2**20
    assert gpu.default_chunk(10**8) == 5_000_000
    per = 8 * (4 * 501 + 4 * 501 + 3 + 3 + 501)  # 500 periods, no exponents: 20,072 bytes
    assert gpu.cell_bytes(500, 0, False) == per
    assert gpu.batch_cells(10**6, 500, 0, False, 2 * per * 1000) == 1000
    assert gpu.batch_cells(10, 500, 0, False, 10**12) == 10
    assert gpu.batch_cells(10**6, 500, 0, False, 10) == gpu.BLOCK


def test_cells_share_tables_exactly_when_their_forcing_is_the_same():
    """The tables are made once per forcing: two cells get the same tables if and only if
    their rows agree in alpha omega^2, omega, the phase and the step (checked pair by pair)."""
    from rockjit._engine import gpu
    from rockjit._engine.layout import N_PAR, P_AW2, P_H, P_OMEGA, P_PHI, P_THC
    rng = np.random.default_rng(3)
    pars = np.zeros((40, N_PAR))
    pars[:, P_THC] = rng.uniform(0.1, 0.3, 40)  # not a forcing column: may differ freely
    for col in (P_AW2, P_OMEGA, P_PHI, P_H):
        pars[:, col] = rng.choice([0.5, 1.5], 40)
    rows, index = gpu._forcings(pars)
    cols = [P_AW2, P_OMEGA, P_PHI, P_H]
    for i in range(40):
        np.testing.assert_array_equal(rows[index[i], cols], pars[i, cols])
        for j in range(40):
            assert (index[i] == index[j]) == bool((pars[i, cols] == pars[j, cols]).all())
    same = np.tile(pars[:1], (5, 1))
    same[:, P_THC] = np.arange(5)
    rows, index = gpu._forcings(same)
    assert rows.shape[0] == 1 and not index.any()


def test_the_runner_sends_cuda_grids_to_the_gpu_driver_with_stores_of_their_own(
        tmp_path, monkeypatch):
    """device="cuda" runs every chunk through rockjit._engine.gpu.run_chunk (here a stand-in
    that runs the CPU kernel and counts its cells), one chunk for a small grid; a chunk store
    begun on the CPU is refused for the GPU's computation (their last bits differ), and the
    GPU's own store is resumed."""
    import rockjit
    import rockjit.settings as st
    from rockjit._engine import gpu
    monkeypatch.setattr(st, "cuda_missing", lambda: None)
    calls = []

    def stand_in(tangent, y0s, *args, **kw):
        calls.append(len(y0s))
        return kernel.run_chunk(tangent, y0s, *args[:5], threads=1)

    monkeypatch.setattr(gpu, "run_chunk", stand_in)
    kw = dict(grid=6, integration=Integration(periods=20, window=10))
    forcing = Harmonic(alpha=0.66, omega=1.3)
    store = tmp_path / "store"
    cpu = rockjit.basin(Block(hb=1), forcing, **kw, execution=Execution(store=store))
    assert calls == []
    with pytest.raises(ValueError, match="holds the chunks of a different computation"):
        rockjit.basin(Block(hb=1), forcing, **kw, execution=Execution(device="cuda",
                                                                     store=store))
    assert calls == []
    store = tmp_path / "gpu store"
    on_gpu = rockjit.basin(Block(hb=1), forcing, **kw,
                           execution=Execution(device="cuda", store=store))
    assert calls == [36]  # all the cells, in one chunk
    np.testing.assert_array_equal(on_gpu.label, cpu.label)
    again = rockjit.basin(Block(hb=1), forcing, **kw,
                          execution=Execution(device="cuda", store=store))
    assert calls == [36]  # resumed from the GPU's own chunks
    np.testing.assert_array_equal(again.label, cpu.label)


def test_the_gpu_guide_quotes_the_default_chunk():
    # docs/guide/gpu.md: "a chunk defaults to the whole grid up to N cells"
    import re
    from pathlib import Path

    from rockjit._engine import gpu
    page = (Path(__file__).resolve().parents[2] / "docs" / "guide" / "gpu.md").read_text()
    quoted = re.search(r"the whole grid up to ([\d,]+) cells", " ".join(page.split()))
    assert quoted and int(quoted.group(1).replace(",", "")) == gpu.GPU_CHUNK
