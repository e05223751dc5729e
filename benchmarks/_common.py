"""Shared helpers of the benchmark scripts: timing, compile-time probes, tables, atomic writes.

House rules (benchmarks/README.md): every quoted time is a median of repeats taken side by side in
one run; compile time is measured apart from run time; every output file is written atomically
(temporary file in the same folder, then ``os.replace``), so an interrupted run leaves nothing
half-made.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import textwrap
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
QUICK_RESULTS = RESULTS / "quick"

#: The study's reference run (SPEC.md §7, figure 2).
REFERENCE_RUN = dict(hb=1.0, alpha=0.6, omega=1.3, law="housner")


# --------------------------------------------------------------------------- command line

def parser(description: str) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--quick", action="store_true",
                   help="fast smoke mode: fewer periods and repeats, no cold-compile "
                        "subprocesses; writes to benchmarks/results/quick/ unless --out is given")
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default benchmarks/results, or benchmarks/results/quick "
                        "with --quick)")
    return p


def out_dir(args) -> Path:
    out = args.out if args.out is not None else (QUICK_RESULTS if args.quick else RESULTS)
    out.mkdir(parents=True, exist_ok=True)
    if out.resolve() == QUICK_RESULTS.resolve():
        # smoke-mode outputs are never meant to be committed
        gi = out / ".gitignore"
        if not gi.exists():
            write_text(gi, "*\n")
    return out


# --------------------------------------------------------------------------- timing

def timed(fn, *args, **kwargs):
    """``(seconds, fn(*args, **kwargs))`` with ``time.perf_counter``."""
    t0 = time.perf_counter()
    out = fn(*args, **kwargs)
    return time.perf_counter() - t0, out


def median(xs) -> float:
    return float(statistics.median(xs))


def interleaved(cases: dict, repeats: int, *, counts: dict | None = None) -> dict:
    """Time every case round-robin, so that all are measured side by side in one run.

    ``cases`` maps a key to a zero-argument callable. There are ``repeats`` rounds; each calls
    every case once, in an order rotated (and reversed every other round) from round to round so
    that no case always runs first or always after the same one. ``counts`` lets an expensive
    case run in only ``counts[key]`` of the rounds, spread evenly over them.
    Returns ``{key: [seconds, ...]}``.
    """
    keys = list(cases)
    counts = counts or {}
    rounds = {k: {int(i * repeats / counts[k]) for i in range(counts[k])} if k in counts
              else set(range(repeats)) for k in keys}
    times = {k: [] for k in keys}
    for rep in range(repeats):
        i = rep % len(keys)
        order = keys[i:] + keys[:i]
        if rep % 2:
            order = order[::-1]
        for k in order:
            if rep in rounds[k]:
                dt, _ = timed(cases[k])
                times[k].append(dt)
    return times


_PROBE = textwrap.dedent("""
    import json, statistics, sys, time
    t0 = time.perf_counter()
    import rockjit
    t1 = time.perf_counter()
    kw = json.loads(sys.argv[1])
    rockjit.simulate(**kw)
    t2 = time.perf_counter()
    warm = []
    for _ in range(int(sys.argv[2])):
        a = time.perf_counter()
        rockjit.simulate(**kw)
        warm.append(time.perf_counter() - a)
    print(json.dumps(dict(import_s=t1 - t0, first_s=t2 - t1, warm_s=statistics.median(warm))))
""")


def _probe(kwargs: dict, cache_dir: str, warm_repeats: int) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    proc = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(kwargs), str(warm_repeats)],
                          env=env, capture_output=True, text=True, check=True,
                          cwd=cache_dir)  # not the repo root: '' on sys.path must not shadow
    d = json.loads(proc.stdout.strip().splitlines()[-1])
    d["compile_s"] = d["first_s"] - d["warm_s"]
    return d


def compile_times(kwargs: dict, *, warm_repeats: int = 5) -> dict:
    """Compile time of ``rockjit.simulate(**kwargs)``, measured in fresh processes.

    Two fresh Python processes share one new, empty ``NUMBA_CACHE_DIR``. In each, ``compile_s``
    is the first call's wall time minus the median of ``warm_repeats`` later calls (the run time
    itself). The first process compiles from nothing (``cold``); the second starts with the cache
    the first one wrote (``cached``), which is what a user sees in every session after the first.
    ``import_s`` (``import rockjit``) is reported apart.
    """
    with tempfile.TemporaryDirectory(prefix="rockjit-numba-cache-") as d:
        cold = _probe(kwargs, d, warm_repeats)
        cached = _probe(kwargs, d, warm_repeats)
    return dict(cold=cold, cached=cached)


# --------------------------------------------------------------------------- formatting

def fmt(x, digits: int = 3) -> str:
    """A number for a table: ``digits`` significant figures, ``—`` for missing values."""
    if x is None:
        return "—"
    if isinstance(x, str):
        return x
    if isinstance(x, (int,)) and not isinstance(x, bool):
        return f"{x:,}".replace(",", " ")
    if not math.isfinite(x):
        return "—" if math.isnan(x) else str(x)
    if x == 0:
        return "0"
    if 1e-3 <= abs(x) < 1e5:
        return f"{x:.{digits}g}"
    return f"{x:.{max(digits - 1, 0)}e}"


def md_table(headers, rows) -> str:
    lines = ["| " + " | ".join(headers) + " |", "|" + "|".join("---" for _ in headers) + "|"]
    lines += ["| " + " | ".join(fmt(v) for v in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def environment() -> dict:
    """What the numbers were measured on."""
    import numba
    import numpy
    import scipy

    import rockjit
    cpu = platform.processor() or ""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    repo = Path(rockjit.__file__).resolve().parent.parent  # the rockjit actually imported
    try:
        commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=repo,
                                capture_output=True, text=True).stdout.strip()
        dirty = bool(subprocess.run(["git", "status", "--porcelain", "rockjit"], cwd=repo,
                                    capture_output=True, text=True).stdout.strip())
    except OSError:
        commit, dirty = "", False
    return dict(cpu=cpu, cpus=os.cpu_count(), python=platform.python_version(),
                numpy=numpy.__version__, numba=numba.__version__, scipy=scipy.__version__,
                rockjit=rockjit.__version__, commit=commit + ("+dirty" if dirty else ""),
                date=time.strftime("%Y-%m-%d %H:%M:%S %z"))


def check_unchanged(env: dict):
    """Warn when rockjit's commit or working tree changed while a benchmark ran."""
    now = environment()["commit"]
    if now != env["commit"]:
        print(f"WARNING: rockjit changed during the run ({env['commit']} -> {now}); "
              "rerun on a quiet, unchanging tree", file=sys.stderr)


def env_line(env: dict) -> str:
    return (f"Measured on {env['cpu']} ({env['cpus']} logical CPUs), Python {env['python']}, "
            f"numpy {env['numpy']}, numba {env['numba']}, scipy {env['scipy']}, rockjit "
            f"{env['rockjit']} at commit {env['commit']}, {env['date']}.")


# --------------------------------------------------------------------------- atomic writes

def _atomic(path: Path, write, mode: str = "w"):
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}-", suffix=path.suffix)
    try:
        with os.fdopen(fd, mode) as f:
            write(f)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)  # mkstemp makes 0600; give the file the usual mode
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def update_readme(args, key: str, text: str):
    """Replace the block between ``<!-- key:begin -->`` and ``<!-- key:end -->`` in README.md.

    Only full runs written to the default folder update it, so the README always quotes the
    committed results and never a smoke run's.
    """
    if args.quick or (args.out is not None and Path(args.out).resolve() != RESULTS.resolve()):
        return
    readme = HERE / "README.md"
    if not readme.exists():
        return
    old = readme.read_text()
    begin, end = f"<!-- {key}:begin -->", f"<!-- {key}:end -->"
    i, j = old.find(begin), old.find(end)
    if i < 0 or j < i:
        print(f"note: no {begin} ... {end} block in {readme}; not updated", file=sys.stderr)
        return
    write_text(readme, old[:i + len(begin)] + "\n" + text.rstrip("\n") + "\n" + old[j:])


def write_text(path, text: str):
    _atomic(path, lambda f: f.write(text))


def write_json(path, obj):
    """JSON with non-finite floats written as ``null`` (strict JSON has no NaN)."""
    text = json.dumps(_finite(obj), indent=2, default=_jsonable, allow_nan=False) + "\n"
    write_text(path, text)


def _finite(x):
    import numpy as np
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, np.ndarray):
        return _finite(x.tolist())
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    return x


def write_csv(path, headers, rows):
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(headers)
    w.writerows([["" if v is None else v for v in row] for row in rows])
    write_text(path, buf.getvalue())


def save_figure(fig, path, **kwargs):
    """``fig.savefig`` through a temporary file in the same folder, then a rename."""
    path = Path(path)
    fmt_ = path.suffix.lstrip(".")
    _atomic(path, lambda f: fig.savefig(f, format=fmt_, **kwargs), mode="wb")


def _jsonable(x):
    import numpy as np
    if isinstance(x, np.generic):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    if isinstance(x, Path):
        return str(x)
    raise TypeError(f"not JSON serialisable: {type(x)}")


def pyplot():
    """matplotlib's pyplot on the Agg backend (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt
