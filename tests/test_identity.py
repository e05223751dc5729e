"""Bit-identity with recorded results: the study's basins, sweeps, planes, erosion profiles,
fates, orbit branches and single runs, recomputed through today's API, against the SHA-256 of
every array and the exact value of every scalar recorded in ``tests/data/identity/``.

The record keeps each call by the name and keywords it was first recorded with (in
``identity.json``); :func:`translate` turns each into today's call, and
``tests/data/identity/make_identity.py`` re-records the results when a change is meant to move
them. A change that moves any
result by one bit fails here, naming the case and the first array that differs (with the cells
where the behaviour labels differ, from ``labels.npz``).

Cases whose arithmetic passes through the BLAS (:data:`BLAS_CASES`: scipy's integrators sum
their stages with ``np.dot`` and factor with LAPACK; shooting and continuation solve their
Newton steps with LAPACK) are bit-identical only under the OpenBLAS kernels they were recorded
with, which OpenBLAS picks by processor (``blas_core``). Under other kernels those cases are
held to their recorded values (``blas_values.npz``) to the tolerances of :func:`_close`, and
everything else stays bit for bit.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
from pathlib import Path

import numpy as np
import pytest

import rockjit
from rockjit import Block, Classification, Harmonic, Integration, Lattice

DATA = Path(__file__).parent / "data" / "identity"
RECORD = json.loads((DATA / "identity.json").read_text())
CASES = RECORD["cases"]

#: Fields that are not results: timings, and the inputs echoed back (compared as inputs).
SKIP = {"wall_s"}
CONTEXT = {"settings", "block", "forcing", "integration"}


def _sha(a):
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


def _scalar(v):
    if v is None or isinstance(v, (bool, np.bool_)):
        return None if v is None else bool(v)
    if isinstance(v, (int, np.integer)):
        return int(v)
    if isinstance(v, (float, np.floating)):
        return float(v).hex()
    if isinstance(v, (complex, np.complexfloating)):
        return [float(v.real).hex(), float(v.imag).hex()]
    if isinstance(v, str):
        return v
    if isinstance(v, (list, tuple)):
        return [_scalar(x) for x in v]
    raise TypeError(f"not a scalar: {type(v).__name__}")


def _numeric_list(v):
    if isinstance(v, (list, tuple)):
        return all(_numeric_list(x) for x in v)
    return v is None or isinstance(v, (bool, int, float, complex, str, np.generic))


#: Integer arrays :func:`walk` also keeps whole (in ``small``) when their path ends with one of
#: these names: ``labels.npz`` holds them, so that a failing comparison says where.
SMALL_INT = {"label", "period", "attractor", "motion", "outcome", "impacts", "stable",
             "symmetric_points", "uncertain"}


def walk(obj, path, arrays, scalars, small=None, whole=None):
    """Every array (by SHA-256) and value ``obj`` holds, by path (and the small integer
    arrays whole, into ``small`` if given; every array whole, into ``whole`` if given)."""
    if isinstance(obj, np.ndarray):
        arrays[path] = dict(dtype=obj.dtype.str, shape=list(obj.shape), sha256=_sha(obj))
        if small is not None and obj.dtype.kind in "iub" \
                and path.rsplit(".", 1)[-1] in SMALL_INT:
            small[path] = obj
        if whole is not None:
            whole[path] = obj
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        for f in dataclasses.fields(obj):
            if f.name in SKIP or (f.name in CONTEXT and path == ""):
                continue
            walk(getattr(obj, f.name), f"{path}.{f.name}", arrays, scalars, small, whole)
    elif isinstance(obj, dict):
        for k, v in obj.items():
            walk(v, f"{path}[{json.dumps(str(k))}]", arrays, scalars, small, whole)
    elif isinstance(obj, (list, tuple)) and not _numeric_list(obj):
        for i, v in enumerate(obj):
            walk(v, f"{path}[{i}]", arrays, scalars, small, whole)
    else:
        scalars[path] = _scalar(obj)


# ---------------------------------------------------------------------------------------------
# the recorded calls in today's API
# ---------------------------------------------------------------------------------------------

def _block(kw):
    return Block(hb=kw.pop("hb"), law=kw.pop("law", None), e=kw.pop("e", None))


def _integration(kw):
    names = ("n_steps", "periods", "window", "max_impacts", "stop_at_overturn")
    return Integration(**{n: kw.pop(n) for n in names if n in kw})


def _classification(kw):
    names = ("early_stop", "uncertainty")
    return Classification(**{n: kw.pop(n) for n in names if n in kw})


def _alphas(kw):
    if "alphas" in kw:
        return kw.pop("alphas")
    return rockjit.alpha_grid(kw.pop("alpha_range"), kw.pop("alpha_step"))


def _phase(kw):
    out = {}
    if "phase" in kw:
        out["phase"] = kw.pop("phase")
    if "r0" in kw:
        out["r0"], out["s0"] = kw.pop("r0"), kw.pop("s0")
    return out


def translate(fn, kw, results):
    """``(callable, args, kwargs)`` of today's API for a recorded call."""
    kw = dict(kw)
    if fn == "rockjit.analysis.basin":
        block = _block(kw)
        forcing = Harmonic(alpha=kw.pop("alpha"), omega=kw.pop("omega"), **_phase(kw))
        args = (block, forcing, kw.pop("grid"))
        out = dict(integration=_integration(kw), classification=_classification(kw))
        if "lyapunov" in kw:
            out["lyapunov"] = kw.pop("lyapunov")
        call = rockjit.basin
    elif fn == "rockjit.analysis.sweep":
        block = _block(kw)
        args = (block, Harmonic(omega=kw.pop("omega")), _alphas(kw))
        out = dict(integration=_integration(kw), classification=_classification(kw))
        if "lyapunov" in kw:
            out["lyapunov"] = kw.pop("lyapunov")
        call = rockjit.sweep
    elif fn == "rockjit.analysis.plane":
        block = _block(kw)
        args = (block, kw.pop("alpha_range"), kw.pop("omega_range"))
        out = dict(grid=kw.pop("grid"))
        call = rockjit.plane
    elif fn == "rockjit.erosion.erosion":
        block = _block(kw)
        args = (block, Harmonic(omega=kw.pop("omega")), _alphas(kw), kw.pop("grid"))
        out = {}
        call = rockjit.erosion
    elif fn == "rockjit.fate.fate":
        block = _block(kw)
        forcing = Harmonic(alpha=kw.pop("alpha"), omega=kw.pop("omega"),
                           embedded=kw.pop("forcing", "closed") == "embedded")
        args = (block, forcing)
        out = dict(ensemble=kw.pop("ensemble"))
        call = rockjit.fate
    elif fn == "rockjit.simulate":
        block = _block(kw)
        forcing = Harmonic(alpha=kw.pop("alpha"), omega=kw.pop("omega"),
                           embedded=kw.pop("forcing", "closed") == "embedded", **_phase(kw))
        state = (kw.pop("theta0"), kw.pop("dtheta0")) if "theta0" in kw else None
        if state is not None and not forcing.phase_given:
            forcing = forcing.replace(r0=0.0, s0=1.0)
        method = kw.pop("method", "rockjit")
        if "rtol" in kw:
            method = rockjit.Scipy(method.split(":")[1], rtol=kw.pop("rtol"),
                                   atol=kw.pop("atol"))
        args = (block, forcing, state)
        out = dict(integration=_integration(kw), method=method)
        for name in ("lyapunov", "record_stride"):
            if name in kw:
                out[name] = kw.pop(name)
        call = rockjit.simulate
    else:
        return translate_orbits(fn, kw, results)
    assert not kw, f"untranslated keywords of {fn}: {sorted(kw)}"
    return call, args, out


def translate_orbits(fn, kw, results):
    from rockjit import orbits
    if fn == "rockjit.orbits.periodic_orbit":
        p = kw.pop("block_or_params")
        return orbits.periodic_orbit, (Block(hb=p["hb"]), Harmonic(alpha=p["alpha"],
                                                                   omega=p["omega"]),
                                       kw.pop("x0")), dict(p=kw.pop("p"))
    if fn == "rockjit.orbits.continuation":
        p = kw.pop("block_or_params")
        return orbits.continuation, (Block(hb=p["hb"]), Harmonic(alpha=p["alpha"],
                                                                 omega=p["omega"]),
                                     kw.pop("seeds")), dict(kw)
    if fn == "rockjit.orbits.continue_branches":
        sweep = results[kw.pop("sweep")["case"]]
        return orbits.continue_branches, (Block(hb=kw.pop("hb"), law=kw.pop("law")),
                                          Harmonic(omega=kw.pop("omega")),
                                          kw.pop("alpha_range")), dict(sweep=sweep)
    raise AssertionError(f"no translation for {fn}")


# ---------------------------------------------------------------------------------------------
# the comparison
# ---------------------------------------------------------------------------------------------

_RESULTS = {}


def _result(name):
    if name not in _RESULTS:
        case = CASES[name]
        kw = case["call"]["kwargs"]
        for v in kw.values():  # the cases this one uses first
            if isinstance(v, dict) and set(v) == {"case"}:
                _result(v["case"])
        call, args, kwargs = translate(case["call"]["function"], kw, _RESULTS)
        _RESULTS[name] = call(*args, **kwargs)
    return _RESULTS[name]


def _labels():
    with np.load(DATA / "labels.npz") as z:
        return {k: z[k] for k in z.files}


def _where_labels_differ(name, res):
    small = _labels()
    notes = []
    for key, want in small.items():
        case, _, path = key.partition("::")
        if case != name or not path.endswith(".label"):
            continue
        got = np.asarray(res.label)
        if got.shape == want.shape and not np.array_equal(got, want):
            cells = np.argwhere(got != want)
            notes.append(f"{path}: {len(cells)} cells differ, first {cells[:5].tolist()}")
    return "; ".join(notes)


def _is_result(path):
    """Not an echoed input: no ``.block.``, ``.forcing.``, ... along the path (a nested
    result's own inputs, such as a fate's nominal run's block, are inputs too)."""
    return not any(f".{c}." in path + "." for c in CONTEXT)


def blas_core():
    """The name of the kernels numpy's OpenBLAS chose for this processor (``"Haswell"``,
    ``"SkylakeX"``, ...), or None where it cannot be asked."""
    import ctypes
    import glob
    import os
    libs = glob.glob(os.path.join(os.path.dirname(np.__file__) + ".libs", "*openblas*"))
    for lib in libs:
        try:
            cdll = ctypes.CDLL(lib)
        except OSError:
            continue
        for sym in ("scipy_openblas_get_corename64_", "scipy_openblas_get_corename",
                    "openblas_get_corename64_", "openblas_get_corename"):
            f = getattr(cdll, sym, None)
            if f is not None:
                f.restype = ctypes.c_char_p
                return f().decode()
    return None


#: Cases whose arithmetic passes through the BLAS (see the module's docstring).
BLAS_CASES = {n for n, c in CASES.items()
              if ".orbits." in c["call"]["function"]
              or str(c["call"]["kwargs"].get("method", "")).startswith("scipy")}

#: The kernels the record was made with: under them, the BLAS cases are compared bit for bit.
SAME_KERNELS = blas_core() == RECORD.get("blas_core")

#: Values that measure round-off itself (a converged Newton residual) and counters of work
#: done (a step more or less to converge), which other kernels move by design.
ROUND_OFF = (".residual", ".n_simulate", ".n_newton", ".iterations")


def _blas_values():
    with np.load(DATA / "blas_values.npz") as z:
        return {k: z[k] for k in z.files}


def _close(name, path, got, want):
    """``got`` is ``want`` to the precision other BLAS kernels leave: the same shape, dtype,
    integers and strings; floats within 1e-6 of the array's own size (a Newton solve converged
    to ~1e-12 and its multipliers, several of them near zero)."""
    if path.endswith(ROUND_OFF):
        return
    if isinstance(want, np.ndarray):
        assert got.shape == want.shape and got.dtype == want.dtype, f"{name}{path}: shape"
        if want.dtype.kind in "fc":
            assert np.array_equal(np.isnan(got), np.isnan(want)), f"{name}{path}: NaNs moved"
            fin = np.isfinite(want)
            scale = max(float(np.max(np.abs(want[fin]), initial=0.0)), 1e-300)
            err = float(np.max(np.abs(got[fin] - want[fin]), initial=0.0))
            assert err <= 1e-6 * scale, f"{name}{path}: moved by {err:.3g} (size {scale:.3g})"
        else:
            assert np.array_equal(got, want), f"{name}{path} differs"
    elif isinstance(want, str) and isinstance(got, str) and want.startswith(("0x", "-0x")):
        g, w = float.fromhex(got), float.fromhex(want)
        assert abs(g - w) <= 1e-6 * max(abs(w), 1e-12), f"{name}{path}: {g!r} != {w!r}"
    elif isinstance(want, list) and isinstance(got, list) and len(got) == len(want):
        for i, (g, w) in enumerate(zip(got, want)):
            _close(name, f"{path}[{i}]", g, w)
    else:
        assert got == want, f"{name}{path}: {got} != {want}"


def _compare(name, res, *, arrays_only=False, skip=()):
    want = CASES[name]
    arrays, scalars, whole = {}, {}, {}
    walk(res, "", arrays, scalars, whole=whole)
    arrays = {k: v for k, v in arrays.items() if not k.startswith(skip) and _is_result(k)}
    want_arrays = {k: v for k, v in want["arrays"].items()
                   if not k.startswith(skip) and _is_result(k)}
    assert sorted(arrays) == sorted(want_arrays), (
        f"{name}: arrays held differ: missing {sorted(set(want_arrays) - set(arrays))[:5]}, "
        f"new {sorted(set(arrays) - set(want_arrays))[:5]}")
    by_value = name in BLAS_CASES and not SAME_KERNELS
    values = _blas_values() if by_value else {}
    for path, w in want_arrays.items():
        got = arrays[path]
        if by_value and got != w:
            _close(name, path, whole[path], values[f"{name}::{path}"])
            continue
        assert got == w, (f"{name}{path} differs ({got['dtype']} {got['shape']} vs "
                          f"{w['dtype']} {w['shape']}); {_where_labels_differ(name, res)}")
    if arrays_only:
        return
    want_scalars = {k: v for k, v in want["scalars"].items()
                    if not k.startswith(skip) and _is_result(k)}
    for path, w in want_scalars.items():
        assert path in scalars, f"{name}{path} is gone"
        if by_value and scalars[path] != w:
            _close(name, path, scalars[path], w)
            continue
        assert scalars[path] == w, f"{name}{path}: {scalars[path]} != {w}"


GRID_CASES = [n for n, c in CASES.items()
              if c["call"]["function"].split(".")[-1] in ("basin", "sweep", "erosion", "fate")]
RUN_CASES = [n for n, c in CASES.items() if c["call"]["function"] == "rockjit.simulate"]
ORBIT_CASES = [n for n, c in CASES.items() if ".orbits." in c["call"]["function"]]


@pytest.mark.slow
@pytest.mark.parametrize("name", GRID_CASES)
def test_grids_are_bit_identical(name):
    _compare(name, _result(name))


@pytest.mark.parametrize("name", RUN_CASES)
def test_single_runs_are_bit_identical(name):
    _compare(name, _result(name))


def test_plane_is_bit_identical():
    _compare("plane_hb1", _result("plane_hb1"))


#: Recorded as one plane of two initial states at two forcing phases; today a plane's states
#: share one phase, so each state is its own plane (the cells are the same runs).
TWO_STATES = "plane_hb2_mao_two_states"


def two_state_planes():
    block = Block(hb=2, law="mao")
    return [rockjit.plane(block, (0.1, 0.5), (1.2, 2.0), grid=(8, 6), state=(th, dth),
                          forcing=Harmonic(r0=r, s0=s))
            for (th, dth, r, s) in ((-0.2254, -0.1597, -0.7778, 0.6284), (0.1, 0.0, 0.0, 1.0))]


def test_plane_of_two_states_is_bit_identical_state_by_state():
    want = CASES[TWO_STATES]
    got = two_state_planes()
    for field in ("label", "period", "lambda_window", "t_end"):
        joined = np.concatenate([getattr(p, field) for p in got])
        assert _sha(joined) == want["arrays"][f"[{json.dumps(field)}]"]["sha256"], field


@pytest.mark.slow
@pytest.mark.parametrize("name", ORBIT_CASES)
def test_orbits_are_bit_identical(name):
    _compare(name, _result(name))


def test_the_comparison_catches_a_one_bit_change():
    res = _result("run_reference")
    moved = dataclasses.replace(res, strobe=res.strobe.copy())
    moved.strobe[3, 0] = np.nextafter(moved.strobe[3, 0], math.inf)
    with pytest.raises(AssertionError, match="strobe"):
        _compare("run_reference", moved)


def test_other_blas_kernels_are_held_to_the_recorded_values():
    """The tolerance path itself can fail: a BLAS case's strobe point moved by 1e-5 of its
    size is refused, one moved by a last bit is accepted."""
    name = "run_scipy_dop853"
    values = _blas_values()
    path = ".strobe_half" if f"{name}::.strobe_half" in values else next(
        k.split("::")[1] for k in values if k.startswith(name + "::"))
    want = values[f"{name}::{path}"]
    assert want.dtype.kind == "f" and want.size
    _close(name, path, np.nextafter(want, np.inf), want)
    moved = want.copy()
    flat = moved.reshape(-1)
    flat[np.argmax(np.abs(flat))] *= 1 + 1e-5
    with pytest.raises(AssertionError, match="moved by"):
        _close(name, path, moved, want)


def test_the_lattice_default_is_the_studys():
    assert Lattice().grid == 100 and Lattice().theta_range == (-1.0, 1.0)
