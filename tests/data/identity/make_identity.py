"""Record the exact results of a fixed set of computations, for tests/test_identity.py.

Each case is a call kept in ``identity.json`` by the name and keywords it was first recorded
with; ``tests/test_identity.py``'s ``translate`` turns it into today's call. This script
recomputes every case (or those named with ``--only`` and the cases they use) and writes, next
to itself:

``identity.json``
    For every case: ``call`` (kept as it is), ``type``, ``settings`` (kept as it is: context for
    the reader), ``arrays`` (every ndarray the result holds, nested objects included, by path:
    ``dtype``, ``shape`` and the SHA-256 of ``np.ascontiguousarray(a).tobytes()``) and
    ``scalars`` (every other value the result holds, by path: floats as ``float.hex()``
    strings, complex numbers as two of them, ints, bools, strings, None; lists of numbers as
    nested lists of them).
``labels.npz``
    The small integer arrays in full (labels, periods, attractor ids, motions, outcomes, impact
    counts), keyed ``"<case>::<path>"``, so a failing comparison can say where it differs.

Paths: ``.field`` for a dataclass field, ``[i]`` for a list item, ``["key"]`` for a dict key.
Left out: timings (``wall_s``) and the inputs a result echoes back (``settings``, ``block``,
``forcing``, ``integration``).

Re-record only when a change is meant to move results, and say in the commit why the new
results are right (the accuracy tests against scipy still pass, by how much they moved).
Run from the repository root: ``python tests/data/identity/make_identity.py [--only CASE ...]``;
wall times go to stdout only, so that two runs write identical files.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[2]
sys.path.insert(0, str(ROOT))  # this tree's rockjit, not an installed one

import rockjit  # noqa: E402

assert Path(rockjit.__file__).resolve().parent == ROOT / "rockjit", rockjit.__file__

#: Fields that are not results: timings (not reproducible) and the inputs echoed back.
SKIP = {"wall_s"}
CONTEXT = {"settings", "block", "forcing", "integration"}

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


def _two_state_plane():
    """The plane of two states, one plane per state, joined (as the test compares it)."""
    import test_identity as ti
    return {f: np.concatenate([getattr(p, f) for p in ti.two_state_planes()])
            for f in ("label", "period", "lambda_window", "t_end")}


def main(argv=None):
    sys.path.insert(0, str(HERE.parent.parent))  # tests/, for test_identity
    import test_identity as ti

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="*", help="case names (and the cases they use)")
    args = ap.parse_args(argv)
    old = json.loads((HERE / "identity.json").read_text())
    wanted = set(args.only or old["cases"])
    with np.load(HERE / "labels.npz") as z:
        small = {k: z[k] for k in z.files if k.split("::")[0] not in wanted}
    doc = dict(commit=_commit(), numpy=np.__version__, python=sys.version.split()[0],
               note=old["note"], cases=old["cases"])
    t_all = time.perf_counter()
    for name in old["cases"]:
        if name not in wanted:
            continue
        case = doc["cases"][name]
        t0 = time.perf_counter()
        res = _two_state_plane() if name == ti.TWO_STATES else ti._result(name)
        arrays, scalars, sm = {}, {}, {}
        walk(res, "", arrays, scalars, sm)
        case["arrays"], case["scalars"] = arrays, scalars
        small.update({f"{name}::{p}": a for p, a in sm.items()})
        print(f"{name:34s} {time.perf_counter() - t0:7.3f} s  {len(arrays):4d} arrays  "
              f"{len(scalars):4d} scalars", flush=True)
    print(f"{'total':34s} {time.perf_counter() - t_all:7.2f} s", flush=True)
    with open(HERE / "identity.json", "w") as f:
        json.dump(doc, f, indent=1, sort_keys=False, allow_nan=False)
        f.write("\n")
    # fixed member order and no timestamps: two runs write identical bytes
    _savez(HERE / "labels.npz", small)


def _commit():
    import subprocess
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True,
                              text=True, cwd=HERE, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


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
