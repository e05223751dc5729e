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
sys.path.insert(0, str(HERE.parent.parent))  # tests/: the cases' translation and the walk

import test_identity as ti  # noqa: E402

def _two_state_plane():
    """The plane of two states, one plane per state, joined (as the test compares it)."""
    return {f: np.concatenate([getattr(p, f) for p in ti.two_state_planes()])
            for f in ("label", "period", "lambda_window", "t_end")}


def main(argv=None):

    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="*", help="case names (and the cases they use)")
    args = ap.parse_args(argv)
    old = json.loads((HERE / "identity.json").read_text())
    wanted = set(args.only or old["cases"])
    with np.load(HERE / "labels.npz") as z:
        small = {k: z[k] for k in z.files if k.split("::")[0] not in wanted}
    with np.load(HERE / "blas_values.npz") as z:
        blas = {k: z[k] for k in z.files if k.split("::")[0] not in wanted}
    core = ti.blas_core()
    if old.get("blas_core") not in (None, core) and not wanted >= ti.BLAS_CASES:
        sys.exit(f"the record's BLAS cases were made under {old['blas_core']} kernels and "
                 f"this machine's are {core}: re-record all of them or none")
    doc = dict(commit=_commit(), numpy=np.__version__, python=sys.version.split()[0],
               blas_core=core, note=old["note"], cases=old["cases"])
    t_all = time.perf_counter()
    for name in old["cases"]:
        if name not in wanted:
            continue
        case = doc["cases"][name]
        t0 = time.perf_counter()
        res = _two_state_plane() if name == ti.TWO_STATES else ti._result(name)
        arrays, scalars, sm, whole = {}, {}, {}, {}
        ti.walk(res, "", arrays, scalars, sm, whole)
        case["arrays"], case["scalars"] = arrays, scalars
        small.update({f"{name}::{p}": a for p, a in sm.items()})
        if name in ti.BLAS_CASES:
            blas.update({f"{name}::{p}": a for p, a in whole.items()})
        print(f"{name:34s} {time.perf_counter() - t0:7.3f} s  {len(arrays):4d} arrays  "
              f"{len(scalars):4d} scalars", flush=True)
    print(f"{'total':34s} {time.perf_counter() - t_all:7.2f} s", flush=True)
    with open(HERE / "identity.json", "w") as f:
        json.dump(doc, f, indent=1, sort_keys=False, allow_nan=False)
        f.write("\n")
    # fixed member order and no timestamps: two runs write identical bytes
    _savez(HERE / "labels.npz", small)
    _savez(HERE / "blas_values.npz", blas)


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
