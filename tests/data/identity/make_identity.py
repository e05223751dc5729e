"""Record the exact results of a fixed set of computations (the arrays of commit f12ce1e).

The public API is about to be redesigned (signatures change, modules move); the redesign must
leave every result bit-identical. This script computes a fixed set of cases with today's API
and writes, next to itself:

``identity.json``
    For every case: ``call`` (the function, by its dotted name at f12ce1e, and every keyword
    argument it was called with, as JSON; ``{"case": NAME}`` stands for the result of an
    earlier case, a sweep passed to ``continue_branches``), ``settings`` (the settings the
    result reports it was computed with, for context: defaults resolved), ``arrays`` (every
    ndarray the result holds, nested objects included, by path: ``dtype``, ``shape`` and the
    SHA-256 of ``np.ascontiguousarray(a).tobytes()``) and ``scalars`` (every other value the
    result holds, by path: floats as ``float.hex()`` strings, complex numbers as two of them,
    ints, bools, strings, None; lists of numbers as nested lists of them).
``labels.npz``
    The small integer arrays in full (labels, periods, attractor ids, motions, outcomes, impact
    counts), keyed ``"<case>::<path>"``, so a failing comparison can say where it differs.

Paths: ``.field`` for a dataclass field, ``[i]`` for a list item, ``["key"]`` for a dict key.
Left out: ``Continuation.wall_s`` (a timing) and the ``settings``/``block`` fields of the
results (context, recorded under ``settings``, not compared as results). Nothing else.

Run from the repository root (``python tests/data/identity/make_identity.py [--out DIR]
[--only CASE ...]``); wall times go to stdout only, so that two runs write identical files.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
sys.path.insert(0, str(ROOT))  # this tree's rockjit, not an installed one

import rockjit  # noqa: E402
from rockjit import analysis, erosion, fate, orbits  # noqa: E402

assert Path(rockjit.__file__).resolve().parent == ROOT / "rockjit", rockjit.__file__
COMMIT = "f12ce1e"

FUNCS = {
    "rockjit.simulate": rockjit.simulate,
    "rockjit.analysis.sweep": analysis.sweep,
    "rockjit.analysis.basin": analysis.basin,
    "rockjit.analysis.plane": analysis.plane,
    "rockjit.erosion.erosion": erosion.erosion,
    "rockjit.fate.fate": fate.fate,
    "rockjit.orbits.continue_branches": orbits.continue_branches,
    "rockjit.orbits.continuation": orbits.continuation,
    "rockjit.orbits.periodic_orbit": orbits.periodic_orbit,
}

#: The cases, in order: (name, function, keyword arguments). Every argument is a keyword, so a
#: call can be re-made from its JSON whatever the positions become.
B, SW, PL, ER, FA, CB, CO, PO, SIM = (
    "rockjit.analysis.basin", "rockjit.analysis.sweep", "rockjit.analysis.plane",
    "rockjit.erosion.erosion", "rockjit.fate.fate", "rockjit.orbits.continue_branches",
    "rockjit.orbits.continuation", "rockjit.orbits.periodic_orbit", "rockjit.simulate")
RUN = dict(hb=1, alpha=0.6, omega=1.3, lyapunov=True, record_stride=16)
CASES = [
    # the study's four basins, and two variants
    ("basin_hb1_housner", B, dict(hb=1, alpha=0.66, omega=1.3, law="housner", grid=100,
                                  r0=0, s0=1)),
    ("basin_hb1_mao", B, dict(hb=1, alpha=0.66, omega=1.3, law="mao", grid=100, r0=0, s0=1)),
    ("basin_hb2_housner", B, dict(hb=2, alpha=0.2, omega=1.6, law="housner", grid=100,
                                  r0=0, s0=1)),
    ("basin_hb2_mao", B, dict(hb=2, alpha=0.2, omega=1.6, law="mao", grid=100, r0=0, s0=1)),
    ("basin_hb1_housner_lyapunov", B, dict(hb=1, alpha=0.66, omega=1.3, law="housner",
                                           grid=100, r0=0, s0=1, lyapunov=True)),
    ("basin_hb2_mao_full_length", B, dict(hb=2, alpha=0.2, omega=1.6, law="mao", grid=100,
                                          r0=0, s0=1, early_stop=False, periods=200)),
    ("basin_hb1_housner_uncertainty", B, dict(hb=1, alpha=0.66, omega=1.3, law="housner",
                                              grid=40, r0=0, s0=1, uncertainty=1e-6)),
    ("basin_constant_e_phase", B, dict(hb=1, alpha=0.66, omega=1.3, e=0.9, grid=40,
                                       phase=0.5)),
    # the study's four sweeps, and two variants
    ("sweep_hb1_housner", SW, dict(hb=1, omega=1.3, law="housner", alpha_range=[0.5, 1.0],
                                   alpha_step=0.001)),
    ("sweep_hb1_mao", SW, dict(hb=1, omega=1.3, law="mao", alpha_range=[0.3, 0.8],
                               alpha_step=0.001)),
    ("sweep_hb2_housner", SW, dict(hb=2, omega=1.6, law="housner", alpha_range=[0.1, 0.5],
                                   alpha_step=0.001)),
    ("sweep_hb2_mao", SW, dict(hb=2, omega=1.6, law="mao", alpha_range=[0.1, 0.5],
                               alpha_step=0.001)),
    ("sweep_hb1_housner_past_overturn", SW, dict(hb=1, omega=1.3, law="housner",
                                                 alpha_range=[0.5, 1.0], alpha_step=0.01,
                                                 stop_at_overturn=False)),
    ("sweep_hb1_housner_uncertainty", SW, dict(hb=1, omega=1.3, law="housner",
                                               alpha_range=[0.5, 1.0], alpha_step=0.01,
                                               uncertainty=1e-6)),
    ("sweep_alphas_no_lyapunov", SW, dict(hb=1, omega=1.3, law="mao",
                                          alphas=[0.3, 0.45, 0.6, 0.75], n_steps=128,
                                          periods=300, window=200, lyapunov=False)),
    # rocking charts
    ("plane_hb1", PL, dict(hb=1, alpha_range=[0.3, 1.0], omega_range=[1.0, 2.0],
                           grid=[15, 12])),
    ("plane_hb2_mao_two_states", PL, dict(hb=2, law="mao", alpha_range=[0.1, 0.5],
                                          omega_range=[1.2, 2.0], grid=[8, 6],
                                          z0=[[-0.2254, -0.1597, -0.7778, 0.6284],
                                              [0.1, 0.0, 0.0, 1.0]])),
    # erosion profiles
    ("erosion_hb1_mao", ER, dict(hb=1, omega=1.3, law="mao", alpha_range=[0.3, 1.0],
                                 alpha_step=0.05, grid=40)),
    ("erosion_hb2_housner", ER, dict(hb=2, omega=1.6, law="housner", alpha_range=[0.1, 0.5],
                                     alpha_step=0.05, grid=40)),
    # fates (the README's example, closed-form and embedded forcing)
    ("fate_hb1_0969", FA, dict(hb=1, alpha=0.969, omega=1.3, law="housner", ensemble=64)),
    ("fate_hb1_0969_embedded", FA, dict(hb=1, alpha=0.969, omega=1.3, law="housner",
                                        ensemble=64, forcing="embedded")),
    # periodic orbits
    ("orbit_hb1_08", PO, dict(block_or_params=dict(hb=1, alpha=0.8, omega=1.3),
                              x0=[-0.3, -0.3], p=1)),
    ("continuation_hb1_08", CO, dict(block_or_params=dict(hb=1, alpha=0.8, omega=1.3),
                                     seeds=[[0.8, [-0.3, -0.3], 1]], bounds=[0.75, 0.85])),
    ("continuation_hb1_omega", CO, dict(block_or_params=dict(hb=1, alpha=0.8, omega=1.3),
                                        seeds=[[1.3, [-0.3, -0.3], 1]], parameter="omega",
                                        bounds=[1.25, 1.35])),
    ("branches_hb1_housner", CB, dict(hb=1, law="housner", omega=1.3, alpha_range=[0.5, 1.0],
                                      sweep={"case": "sweep_hb1_housner"})),
    ("branches_hb2_mao", CB, dict(hb=2, law="mao", omega=1.6, alpha_range=[0.1, 0.5],
                                  sweep={"case": "sweep_hb2_mao"})),
    # single runs
    ("run_reference", SIM, dict(RUN)),
    ("run_reference_embedded", SIM, dict(RUN, forcing="embedded")),
    ("run_reference_scipy", SIM, dict(hb=1, alpha=0.6, omega=1.3, method="scipy", periods=20,
                                      record_stride=16)),
    ("run_rest", SIM, dict(hb=1, alpha=0.15, omega=1.0, theta0=0.05, dtheta0=0,
                           lyapunov=True, record_stride=16)),
    ("run_scipy_dop853", SIM, dict(hb=1, alpha=0.6, omega=1.3, method="scipy:DOP853",
                                   rtol=1e-10, atol=1e-10, periods=5)),
    ("run_past_overturn", SIM, dict(hb=2, alpha=0.448, omega=1.3, periods=50, lyapunov=True,
                                    stop_at_overturn=False, record_stride=64)),
    ("run_rest_gallery", SIM, dict(hb=1, alpha=0.15, omega=1.0, theta0=0.05, dtheta0=0,
                                   r0=-0.7778, s0=0.6284, lyapunov=True, record_stride=16)),
]

#: Fields that are not results: timings (not reproducible) and the inputs echoed back.
SKIP = {"wall_s"}
CONTEXT = {"settings", "block"}

#: Integer arrays kept in full in labels.npz when their path ends with one of these names.
SMALL_INT = {"label", "period", "attractor", "motion", "outcome", "impacts", "stable",
             "symmetric_points", "uncertain"}


def sha(a):
    return hashlib.sha256(np.ascontiguousarray(a).tobytes()).hexdigest()


def scalar(v):
    """A JSON value that compares exactly."""
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
        return [scalar(x) for x in v]
    raise TypeError(f"not a scalar: {type(v).__name__}")


def _numeric_list(v):
    if isinstance(v, (list, tuple)):
        return all(_numeric_list(x) for x in v)
    return v is None or isinstance(v, (bool, int, float, complex, str, np.generic))


def walk(obj, path, arrays, scalars, small):
    """Every array and value ``obj`` holds, by path."""
    if isinstance(obj, np.ndarray):
        arrays[path] = dict(dtype=obj.dtype.str, shape=list(obj.shape), sha256=sha(obj))
        leaf = path.rsplit(".", 1)[-1]
        if obj.dtype.kind in "iub" and leaf in SMALL_INT:
            small[path] = obj
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        for f in dataclasses.fields(obj):
            if f.name in SKIP or (f.name in CONTEXT and path == ""):
                continue
            walk(getattr(obj, f.name), f"{path}.{f.name}", arrays, scalars, small)
    elif isinstance(obj, dict):
        for k, v in obj.items():
            walk(v, f"{path}[{json.dumps(str(k))}]", arrays, scalars, small)
    elif isinstance(obj, (list, tuple)) and not _numeric_list(obj):
        for i, v in enumerate(obj):
            walk(v, f"{path}[{i}]", arrays, scalars, small)
    else:
        scalars[path] = scalar(obj)


def context(res):
    """The settings and block a result reports (JSON-ready), for the reader."""
    out = {}
    for name in ("settings", "block"):
        v = getattr(res, name, None)
        if v is None:
            continue
        if dataclasses.is_dataclass(v):
            v = {f.name: getattr(v, f.name) for f in dataclasses.fields(v)}
        ctx = {}
        for k, x in v.items():
            a, s = {}, {}
            walk(x, "", a, s, {})
            ctx[str(k)] = a[""] if "" in a else s[""] if "" in s else dict(s, **a)
        out[name] = ctx
    return out


def resolve(kw, results):
    """The call's keyword arguments with ``{"case": NAME}`` replaced by that case's result."""
    return {k: results[v["case"]] if isinstance(v, dict) and set(v) == {"case"} else v
            for k, v in kw.items()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=str(HERE), help="directory for identity.json, labels.npz")
    ap.add_argument("--only", nargs="*", help="case names (and the cases they use)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    wanted = set(args.only or [c[0] for c in CASES])
    for name, _, kw in CASES:  # the cases a wanted one uses
        if name in wanted:
            wanted |= {v["case"] for v in kw.values() if isinstance(v, dict) and "case" in v}
    doc = dict(commit=COMMIT, numpy=np.__version__, python=sys.version.split()[0],
               note="arrays: sha256 of np.ascontiguousarray(a).tobytes(); floats as "
                    "float.hex(); see make_identity.py", cases={})
    results, small, walls = {}, {}, {}
    t_all = time.perf_counter()
    for name, fn, kw in CASES:
        if name not in wanted:
            continue
        call_kw = json.loads(json.dumps(kw))  # called exactly as recorded
        t0 = time.perf_counter()
        res = FUNCS[fn](**resolve(call_kw, results))
        walls[name] = time.perf_counter() - t0
        results[name] = res
        arrays, scalars, sm = {}, {}, {}
        walk(res, "", arrays, scalars, sm)
        doc["cases"][name] = dict(call=dict(function=fn, kwargs=call_kw),
                                  type=type(res).__name__, settings=context(res),
                                  arrays=arrays, scalars=scalars)
        small.update({f"{name}::{p}": a for p, a in sm.items()})
        print(f"{name:34s} {walls[name]:7.3f} s  {len(arrays):4d} arrays  "
              f"{len(scalars):4d} scalars", flush=True)
    print(f"{'total':34s} {time.perf_counter() - t_all:7.2f} s", flush=True)
    with open(out / "identity.json", "w") as f:
        json.dump(doc, f, indent=1, sort_keys=False, allow_nan=False)
        f.write("\n")
    # fixed member order and no timestamps: two runs write identical bytes
    _savez(out / "labels.npz", small)


def _savez(path, arrays):
    import io
    import zipfile
    with zipfile.ZipFile(path, "w", compression=zipfile.ZIP_DEFLATED) as zf:
        for key in sorted(arrays):
            buf = io.BytesIO()
            np.lib.format.write_array(buf, np.ascontiguousarray(arrays[key]),
                                      allow_pickle=False)
            info = zipfile.ZipInfo(key + ".npy", date_time=(1980, 1, 1, 0, 0, 0))
            info.compress_type = zipfile.ZIP_DEFLATED
            zf.writestr(info, buf.getvalue())


if __name__ == "__main__":
    main()
