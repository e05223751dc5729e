"""The numba policy: explicit FMA and the source stamp that keeps the on-disk cache honest."""

import numpy as np
import pytest
from numba.core.caching import _CacheLocator

from rockjit import _jit
from rockjit._jit import fma, jit


@jit
def _fma_kernel(a, b, c):
    return fma(a, b, c)


def test_fma_rounds_once():
    # 0.1 * 10 - 1 is 0 in two roundings but 2^-54 * 3 (the error of 0.1) in one
    exact = float(np.longdouble(0.1) * 10 - 1) if np.finfo(np.longdouble).eps < 1e-18 else None
    got = _fma_kernel(0.1, 10.0, -1.0)
    assert got != 0.1 * 10.0 - 1.0
    assert got == pytest.approx(5.551115123125783e-17, rel=1e-15)
    if exact is not None:
        assert got == exact


def _fake_package(tmp_path):
    pkg = tmp_path / "rockjit"
    cache = pkg / "__pycache__"
    cache.mkdir(parents=True)
    for name in _jit._SOURCES:
        (pkg / name).write_text(f"# {name}\n")
    (pkg / "integrate.py").write_text("from ._jit import jit\n")  # compiles: imports the policy
    for name in ("integrate._run-1.py311.nbi", "integrate._run-1.py311.1.nbc"):
        (cache / name).write_text("stale")
    (cache / "simulate.cpython-311.pyc").write_text("keep")
    return pkg, cache


def test_cache_dropped_when_a_compiled_source_changes(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    pkg, cache = _fake_package(tmp_path)
    _jit.check_cache(pkg)  # no stamp yet: the cache cannot be trusted
    assert not list(cache.glob("*.nb[ic]"))
    assert (cache / "simulate.cpython-311.pyc").exists()
    stamp = (cache / "rockjit-sources.sha256").read_text()
    # unchanged sources: the cache is kept
    (cache / "integrate._run-1.py311.nbi").write_text("fresh")
    _jit.check_cache(pkg)
    assert (cache / "integrate._run-1.py311.nbi").exists()
    # an edit of a module the kernels inline (model.py) invalidates it
    (pkg / "model.py").write_text("# model.py, edited\n")
    _jit.check_cache(pkg)
    assert not list(cache.glob("*.nb[ic]"))
    assert (cache / "rockjit-sources.sha256").read_text() != stamp


def test_cache_dir_elsewhere_survives_a_cold_start(tmp_path, monkeypatch):
    # NUMBA_CACHE_DIR: numba creates the package's folders there only when it compiles, after
    # the import-time check; the next process must keep what the first one compiled
    root = tmp_path / "numba-cache"
    monkeypatch.setenv("NUMBA_CACHE_DIR", str(root))
    pkg, _ = _fake_package(tmp_path)
    _jit.check_cache(pkg)  # cold: nothing there yet
    # the folder numba itself picks for functions of pkg/*.py (its own locator code)
    compiled = root / _CacheLocator.get_suitable_cache_subpath(str(pkg / "integrate.py"))
    compiled.mkdir(parents=True, exist_ok=True)
    (compiled / "integrate._run-1.py311.nbi").write_text("fresh")
    _jit.check_cache(pkg)  # a second process, sources unchanged
    assert (compiled / "integrate._run-1.py311.nbi").exists()
    (pkg / "integrate.py").write_text("from ._jit import jit  # integrate.py, edited\n")
    _jit.check_cache(pkg)
    assert not list(compiled.glob("*.nb[ic]"))


def test_a_subpackage_that_compiles_has_its_cache_checked(tmp_path, monkeypatch):
    monkeypatch.delenv("NUMBA_CACHE_DIR", raising=False)
    monkeypatch.setattr(_jit, "_user_wide_dir", lambda: tmp_path / "user-wide")
    pkg, _ = _fake_package(tmp_path)
    engine = pkg / "_engine"
    (engine / "__pycache__").mkdir(parents=True)
    (engine / "kernel.py").write_text("from .._jit import jit\n")
    (engine / "notes.py").write_text("# compiles nothing\n")
    _jit.check_cache(pkg)
    cache = engine / "__pycache__"
    assert (cache / _jit.STAMP).exists()
    (cache / "kernel._grid-1.py311.nbi").write_text("fresh")
    (cache / "notes.f-1.py311.nbi").write_text("fresh")
    _jit.check_cache(pkg)
    assert (cache / "kernel._grid-1.py311.nbi").exists()
    (pkg / "model.py").write_text("# model.py, edited\n")  # the engine inlines the model
    _jit.check_cache(pkg)
    assert not (cache / "kernel._grid-1.py311.nbi").exists()
