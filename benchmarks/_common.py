"""The benchmark harness: options, side-by-side timing, compile probes and the one report writer.

Every script in this folder is a list of *experiments* (small functions that measure one thing
and return rows) and a ``main()`` that runs them and hands the rows to :meth:`Bench.report`. This
module is all they share:

- :class:`Bench` parses the common options (``--quick``, ``--out DIR``), records what the numbers
  were measured on, and writes the report: the Markdown table (``.md``, also pasted into its
  marked block of any page that carries one), the ``.csv``, the ``.json`` and the plots, every file
  through :mod:`rockjit.storage.atomic`'s writers (so the JSON is strict, with non-finite
  floats written as the strings ``"nan"``, ``"inf"``, ``"-inf"``, rockjit's one convention);
- :func:`side_by_side` times cases interleaved in rotating order (medians of repeats, every ratio
  taken within one process: the machine is shared and noisy);
- :func:`compile_times` measures compile time apart from run time, in fresh processes sharing one
  new ``NUMBA_CACHE_DIR`` (the call's settings objects travel to them as JSON: :func:`encode`);
- :func:`call_in` makes one call in whichever API a rockjit package has (for the scripts that
  compare versions);
- :func:`impact_time_error` compares the impact times of two runs.

House rules: every quoted time is a median of repeats taken side by side;
compile time is reported apart; a ``--quick`` run is a smoke test that never writes to
benchmarks/results/ and never touches the README.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import inspect
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
from dataclasses import dataclass, field
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
RESULTS = HERE / "results"
QUICK_RESULTS = RESULTS / "quick"
README = HERE / "README.md"



def reference_run():
    """The study's reference run (docs/theory/study.md, figure 2), ``(block, forcing)``: hb=1,
    Housner restitution, alpha=0.6, omega=1.3; it starts from the study's initial state (the
    default ``state=None`` of :func:`rockjit.simulate`)."""
    from rockjit import Block, Harmonic
    return Block(hb=1.0, law="housner"), Harmonic(alpha=0.6, omega=1.3)


# --------------------------------------------------------------------------- one benchmark run

def parser(description: str) -> argparse.ArgumentParser:
    """The options every script takes: ``--quick`` and ``--out DIR``."""
    p = argparse.ArgumentParser(description=description)
    p.add_argument("--quick", action="store_true",
                   help="smoke mode: tiny sizes, few repeats, no cold-compile processes; writes "
                        "to benchmarks/results/quick/ unless --out is given, never to "
                        "benchmarks/results/")
    p.add_argument("--out", type=Path, default=None,
                   help="output folder (default benchmarks/results, or benchmarks/results/quick "
                        "with --quick)")
    return p


def _same_path(a, b) -> bool:
    return Path(a).resolve() == Path(b).resolve()


class Bench:
    """One run of a benchmark script: its options, output folder, environment and report.

    Parameters
    ----------
    doc : str
        The script's module docstring; its first line is the ``--help`` description.
    argv : list of str, optional
        The command line (default ``sys.argv[1:]``).
    options : callable, optional
        ``options(parser)`` adds the script's own options.

    Attributes
    ----------
    args : argparse.Namespace
    parser : argparse.ArgumentParser
        For the script's own checks of its options (``bench.parser.error(...)``).
    quick : bool
        ``--quick`` was given.
    out_path : Path
        Where the outputs go: ``--out``, else benchmarks/results/ (benchmarks/results/quick/
        with ``--quick``). :attr:`out` makes it on first use.
    publishes : bool
        A full run into benchmarks/results/: its report also refreshes its README block.
    env : dict
        What the numbers are measured on (:func:`environment`), taken when the run starts.
    """

    def __init__(self, doc: str, argv=None, *, options=None):
        p = parser(doc.strip().splitlines()[0])
        if options is not None:
            options(p)
        self.parser = p
        self.args = p.parse_args(argv)
        self.quick = bool(self.args.quick)
        if self.quick and self.args.out is not None and _same_path(self.args.out, RESULTS):
            p.error("--quick never writes to benchmarks/results/ (it holds the committed "
                    "results); give another --out")
        a = self.args
        self.out_path = Path(a.out if a.out is not None else
                             QUICK_RESULTS if self.quick else RESULTS)
        self.publishes = not self.quick and _same_path(self.out_path, RESULTS)
        self.env = environment()
        print(env_line(self.env), flush=True)

    @property
    def out(self) -> Path:
        """The output folder, made on first use."""
        out = self.out_path
        if not out.is_dir():
            out.mkdir(parents=True, exist_ok=True)
        if _same_path(out, QUICK_RESULTS) and not (out / ".gitignore").exists():
            _io().write_text(out / ".gitignore", "*\n")  # smoke outputs are never committed
        return out

    def report(self, name: str, *, markdown: str, csv=None, data=None, figures=(),
               block: str | None = None, also=()):
        """Write the run's outputs and, for a full run into benchmarks/results/, its prose.

        Parameters
        ----------
        name : str
            Base name of the files: ``name.md``, ``name.csv``, ``name.json``.
        markdown : str
            The tables and prose, written to ``name.md`` and, when :attr:`publishes`, between
            the ``<!-- block:begin -->`` and ``<!-- block:end -->`` markers of the README.
        csv : (headers, rows), optional
        data : dict, optional
            Everything measured, raw times included, for ``name.json``.
        figures : iterable of (filename, figure, dpi)
            Saved into the output folder and closed.
        block : str, optional
            The README block's key (default ``name``).
        also : iterable of Path
            More files whose ``block`` is refreshed along with the README.
        """
        rio = _io()
        out = self.out
        rio.write_text(out / f"{name}.md", markdown)
        if csv is not None:
            headers, rows = csv
            rio.write_csv(out / f"{name}.csv", headers, rows)
        if data is not None:
            rio.write_json(out / f"{name}.json", data)
        for fname, fig, dpi in figures:
            rio.save_figure(fig, out / fname, dpi=dpi)
            pyplot().close(fig)
        if self.publishes:
            for path in (*also, README):
                update_block(path, block or name, markdown)
        check_unchanged(self.env)
        print(markdown)


def _io():
    import rockjit.storage.atomic
    return rockjit.storage.atomic


def update_block(path, key: str, text: str) -> bool:
    """Replace the block between ``<!-- key:begin -->`` and ``<!-- key:end -->`` in ``path``.

    Written atomically; a missing file, or one without the markers, is left alone.
    """
    path = Path(path)
    if not path.exists():
        return False
    old = path.read_text()
    begin, end = f"<!-- {key}:begin -->", f"<!-- {key}:end -->"
    i, j = old.find(begin), old.find(end)
    if i < 0 or j < i:
        print(f"note: no {begin} ... {end} block in {path}; not updated", file=sys.stderr)
        return False
    _io().write_text(path, old[:i + len(begin)] + "\n" + text.rstrip("\n") + "\n" + old[j:])
    return True


# --------------------------------------------------------------------------- timing

def timed(fn, *args, **kwargs):
    """``(seconds, fn(*args, **kwargs))`` with ``time.perf_counter``."""
    t0 = time.perf_counter()
    out = fn(*args, **kwargs)
    return time.perf_counter() - t0, out


def timed_cpu(fn, *args, **kwargs):
    """``(wall seconds, process CPU seconds of all threads, fn(*args, **kwargs))``."""
    c0 = time.process_time()
    t0 = time.perf_counter()
    out = fn(*args, **kwargs)
    wall = time.perf_counter() - t0
    return wall, time.process_time() - c0, out


def median(xs) -> float:
    return float(statistics.median(xs))


@dataclass
class Timings:
    """What :func:`side_by_side` measured, by case key.

    Attributes
    ----------
    wall, cpu : dict
        ``{key: [seconds, ...]}``: wall time and process CPU time (all threads) of every call.
    result : dict
        ``{key: value}``: what the case's last call returned.
    """

    wall: dict = field(default_factory=dict)
    cpu: dict = field(default_factory=dict)
    result: dict = field(default_factory=dict)

    def median(self, key) -> float:
        return median(self.wall[key])

    def medians(self) -> dict:
        return {k: median(v) for k, v in self.wall.items()}

    def cpu_median(self, key) -> float:
        return median(self.cpu[key])


def side_by_side(cases: dict, repeats: int, *, counts: dict | None = None,
                 warmups: dict | None = None) -> Timings:
    """Time every case round-robin, so that all are measured side by side in one process.

    ``cases`` maps a key to a zero-argument callable. There are ``repeats`` rounds; each calls
    every case once, in an order rotated (and reversed every other round) from round to round so
    that no case always runs first or always after the same one. ``counts`` lets an expensive
    case run in only ``counts[key]`` of the rounds, spread evenly over them. ``warmups[key]``
    untimed calls of a case come right before each of its timed calls: a call of microseconds
    is then timed as in a loop of such calls, not with the caches another case (a library of
    megabytes) just emptied.
    """
    keys = list(cases)
    counts = counts or {}
    warmups = warmups or {}
    rounds = {k: {int(i * repeats / counts[k]) for i in range(counts[k])} if k in counts
              else set(range(repeats)) for k in keys}
    t = Timings(wall={k: [] for k in keys}, cpu={k: [] for k in keys})
    for rep in range(repeats):
        i = rep % len(keys)
        order = keys[i:] + keys[:i]
        if rep % 2:
            order = order[::-1]
        for k in order:
            if rep in rounds[k]:
                for _ in range(warmups.get(k, 0)):
                    cases[k]()
                wall, cpu, t.result[k] = timed_cpu(cases[k])
                t.wall[k].append(wall)
                t.cpu[k].append(cpu)
    return t


# --------------------------------------------------------------------------- compile probes

#: The source of ``decode(x)``, the inverse of :func:`encode`, for the scripts of child
#: processes (which import rockjit before they call it).
DECODE = textwrap.dedent("""
    def decode(x):
        import rockjit
        if isinstance(x, dict) and "rockjit" in x:
            return getattr(rockjit, x["rockjit"])(**{k: decode(v) for k, v in x.items()
                                                      if k != "rockjit"})
        if isinstance(x, dict):
            return {k: decode(v) for k, v in x.items()}
        if isinstance(x, list):
            return [decode(v) for v in x]
        return x
""")

_PROBE = DECODE + textwrap.dedent("""
    import json, statistics, sys, time
    spec = json.loads(sys.argv[1])
    t0 = time.perf_counter()
    import rockjit
    t1 = time.perf_counter()
    fn = getattr(rockjit, spec["kind"])
    args, kwargs = decode(spec["args"]), decode(spec["kwargs"])
    fn(*args, **kwargs)
    t2 = time.perf_counter()
    warm = []
    for _ in range(spec["repeats"]):
        a = time.perf_counter()
        fn(*args, **kwargs)
        warm.append(time.perf_counter() - a)
    print(json.dumps(dict(import_s=t1 - t0, first_s=t2 - t1, warm_s=statistics.median(warm))))
""")


def encode(x):
    """``x`` as JSON: rockjit's settings objects (:class:`rockjit.Block`,
    :class:`rockjit.Harmonic`, :class:`rockjit.Integration`, ...) as ``{"rockjit": class name,
    field: value, ...}``, arrays and tuples as lists. What a compile probe is given (its child
    process makes the objects again with :data:`DECODE`), and how a script records the inputs
    of what it measured.
    """
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return {"rockjit": type(x).__name__,
                **{f.name: encode(getattr(x, f.name)) for f in dataclasses.fields(x)}}
    if isinstance(x, dict):
        return {k: encode(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [encode(v) for v in x]
    if hasattr(x, "tolist"):  # numpy arrays and scalars
        return x.tolist()
    return x


def child_env(**extra) -> dict:
    """The environment for a child Python process that imports the same rockjit as this one."""
    import rockjit
    src = str(Path(rockjit.__file__).resolve().parent.parent)
    path = os.environ.get("PYTHONPATH", "")
    env = dict(os.environ, PYTHONPATH=src + (os.pathsep + path if path else ""))
    env.update(extra)
    return env


def compile_times(kind: str, args=(), kwargs=None, *, processes=("cold", "cached"),
                  warm_repeats: int = 5) -> dict:
    """Compile time of one call, measured in fresh processes: the one compile probe.

    One fresh Python process per name in ``processes``, one after the other, all sharing one
    new, empty ``NUMBA_CACHE_DIR``: the first compiles from nothing (``cold``), the later ones
    start with what the earlier ones wrote (what a user sees in every process after the
    first). In
    each, ``compile_s`` is the first call's wall time minus the median of ``warm_repeats`` later
    calls (the run time itself); ``import_s`` (``import rockjit``) is reported apart.

    Parameters
    ----------
    kind : {"simulate", "basin", "sweep", "plane", "erosion", "fate"}
        The ``rockjit`` entry point called.
    args, kwargs : tuple, dict
        Its arguments: numbers, arrays and rockjit's settings objects (sent as JSON through
        :func:`encode`; a Dask client or a callable cannot travel).

    Returns
    -------
    dict
        ``{process name: dict(import_s, first_s, warm_s, compile_s)}``.
    """
    spec = json.dumps(dict(kind=kind, args=encode(list(args)), kwargs=encode(kwargs or {}),
                           repeats=warm_repeats))
    out = {}
    with tempfile.TemporaryDirectory(prefix="rockjit-numba-cache-") as d:
        env = child_env(NUMBA_CACHE_DIR=d)
        for name in processes:
            proc = subprocess.run([sys.executable, "-c", _PROBE, spec], env=env, cwd=d,
                                  capture_output=True, text=True, check=True)
            r = json.loads(proc.stdout.strip().splitlines()[-1])
            r["compile_s"] = r["first_s"] - r["warm_s"]
            out[name] = r
            print(f"compile {kind} {name}: {r['compile_s']:.1f} s (first call "
                  f"{r['first_s']:.1f} s, warm {r['warm_s']:.3g} s)", flush=True)
    return out


# --------------------------------------------------------------------------- either API

#: The flat keywords :func:`call_in` knows, by the settings object each belongs to.
_FLAT = dict(Block=("hb", "law", "e", "xi"), Harmonic=("alpha", "omega", "phase", "r0", "s0"),
             Integration=("n_steps", "periods", "window", "max_impacts"),
             Classification=("early_stop", "attractors", "tol", "pmax"),
             Execution=("threads", "chunk", "lanes"))


def api_of(rj) -> str:
    """Which API the rockjit package ``rj`` has: ``"objects"`` (the settings objects:
    ``rockjit.Harmonic`` and its kind) or ``"flat"`` (every parameter a keyword of
    ``simulate``, ``basin`` and ``sweep``, before them)."""
    return "objects" if hasattr(rj, "Harmonic") else "flat"


def _flat_grids(rj):
    """The module of the grid functions of a flat-API package: ``rockjit.grids.grids``, or
    ``rockjit.analysis`` in the older layout."""
    for sub in ("grids.grids", "analysis"):
        try:
            return importlib.import_module(f"{rj.__name__}.{sub}")
        except ImportError:
            continue
    raise ImportError(f"{rj.__name__} has neither grids.grids nor analysis")


def plan_in(rj, fn: str, kw: dict):
    """The validated plan of a ``basin`` or ``sweep`` case in the package ``rj``'s own API (its
    packed kernel inputs ``y0s, pars, ipar, cpar`` are laid out alike in every version)."""
    kw = dict(kw)
    if api_of(rj) == "flat":
        f = getattr(_flat_grids(rj), f"plan_{fn}")
        known = inspect.signature(f).parameters
        return f(**{k: v for k, v in kw.items() if k in known})
    entry, args, settings = _objects_call(rj, fn, kw)
    return entry.plan(*args, **settings)


def call_in(rj, fn: str, kw: dict):
    """A zero-argument callable running ``fn`` of the rockjit package ``rj`` in its own API.

    For the scripts that time two versions of rockjit side by side (bench_versions.py,
    bench_compile.py's speed part), whose cases must mean the same call in both: a case is
    written once, in flat keywords (``hb``, ``alpha``, ``omega``, ``law``, ``periods``,
    ``grid``, ``r0``, ``s0``, ``z0``, ``alpha_range``, ``alpha_step`` or ``alphas``,
    ``lyapunov``, ``early_stop``, ``attractors``, ``threads``, ...), which is also the older
    API's. A package with the settings objects (:func:`api_of`) gets them built from the
    keywords: the study's initial state unless ``z0`` says otherwise, ``(r0, s0) = (0, 1)``
    for a basin unless ``r0, s0`` do. A flat-API package gets the keywords its function
    knows (a keyword it predates, such as ``attractors``, is left out).

    Parameters
    ----------
    rj : module
        A rockjit package (it may be imported under another name).
    fn : {"simulate", "basin", "sweep", "spectrum", "fragility"}
    kw : dict
        The case's flat keywords (:func:`_ground_call`'s for the last two).
    """
    kw = dict(kw)
    if fn in ("spectrum", "fragility"):
        return _ground_call(rj, fn, kw)
    if api_of(rj) == "flat":
        f = rj.simulate if fn == "simulate" else getattr(_flat_grids(rj), fn)
        known = inspect.signature(f).parameters
        kw = {k: v for k, v in kw.items() if k in known}
        return lambda: f(**kw)
    entry, args, settings = _objects_call(rj, fn, kw)
    return lambda: entry(*args, **settings)


def _ground_call(rj, fn, kw):
    """A transient grid on the compiled path: the overturning spectrum of a pulse (``pulse``,
    ``grid`` x ``grid`` geometric ratios in [0.5, 8] and amplitudes in [1.02, 25], no
    bisection), or an incremental dynamic analysis of a block of R = 1 m under ``records``
    synthetic records (20 s at 100 Hz) at ``levels`` intensities in [1.25, 10], both laws."""
    import numpy as np
    block = rj.Block(hb=kw.pop("hb", 4.0), law=kw.pop("law", "housner"))
    if fn == "spectrum":
        pulse, n = rj.Pulse(kw.pop("pulse", "sine")), kw.pop("grid", 80)
        ratios, amplitudes = np.geomspace(0.5, 8.0, n), np.geomspace(1.02, 25.0, n)
        return lambda: rj.spectrum(block, pulse, ratios, amplitudes, locate=False)
    rng = np.random.default_rng(1)
    t = np.arange(0.0, 20.0, 0.01)
    recs = []
    for k in range(kw.pop("records", 6)):
        a = sum(np.sin(2 * np.pi * fi * t + rng.uniform(0, 6)) for fi in rng.uniform(0.5, 3, 3))
        recs.append(rj.Record(0.1 * a * np.sin(np.pi * t / 20.0) ** 2, 0.01, name=f"s{k}"))
    levels = np.linspace(1.25, 10.0, kw.pop("levels", 30))
    return lambda: rj.fragility(block, recs, [1.0], levels, laws=("housner", "mao"))


def _objects_call(rj, fn, kw):
    """``(entry point, args, keywords)`` of a case in the settings-objects API."""
    obj = {name: {k: kw.pop(k) for k in keys if k in kw} for name, keys in _FLAT.items()}
    state = None
    if "z0" in kw:
        z0 = [float(x) for x in kw.pop("z0")]
        state = tuple(z0[:2])
        obj["Harmonic"].update(r0=z0[2], s0=z0[3])
    block, forcing = rj.Block(**obj["Block"]), rj.Harmonic(**obj["Harmonic"])
    settings = dict(integration=rj.Integration(**obj["Integration"]))
    if fn != "simulate":
        settings.update(classification=rj.Classification(**obj["Classification"]),
                        execution=rj.Execution(**obj["Execution"]))
    if "lyapunov" in kw:
        settings["lyapunov"] = kw.pop("lyapunov")
    if fn == "simulate":
        args = (block, forcing, state)
    elif fn == "basin":
        args = (block, forcing, kw.pop("grid", 100))
    elif fn == "sweep":
        alphas = kw.pop("alphas", None)
        if alphas is None:
            alphas = rj.alpha_grid(kw.pop("alpha_range"), kw.pop("alpha_step"))
        args = (block, forcing, alphas, state)
    else:
        raise ValueError(f"call_in: no {fn!r} (simulate, basin or sweep)")
    if fn == "simulate":
        kw.update(obj["Classification"], **obj["Execution"])
    if kw:
        raise ValueError(f"call_in: keywords {sorted(kw)} have no place in a {fn} of "
                         f"rockjit's settings objects")
    return getattr(rj, fn), args, settings


# --------------------------------------------------------------------------- comparing runs

def impact_time_error(res, ref):
    """Largest impact-time difference of two runs.

    Returns a float; ``None`` when neither run has an impact; the string ``"counts differ (a vs
    b)"`` when their impact counts differ (then nothing can be compared).
    """
    if res.n_impacts != ref.n_impacts:
        return f"counts differ ({res.n_impacts} vs {ref.n_impacts})"
    if res.n_impacts == 0:
        return None
    import numpy as np
    return float(np.max(np.abs(res.impacts[:, 0] - ref.impacts[:, 0])))


# --------------------------------------------------------------------------- formatting

def fmt(x, digits: int = 3) -> str:
    """A number for a table: ``digits`` significant figures, ``—`` for missing values."""
    if x is None:
        return "—"
    if isinstance(x, str):
        return x
    if isinstance(x, int) and not isinstance(x, bool):
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


def quick_note(quick: bool, what: str = "") -> str:
    """The heading's mark of a smoke run."""
    return f" (QUICK MODE{': ' + what if what else ''})" if quick else ""


# --------------------------------------------------------------------------- the machine

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


def loadavg() -> tuple:
    """The 1-, 5- and 15-minute load averages (nan where the system has none)."""
    try:
        return tuple(os.getloadavg())
    except OSError:
        return (math.nan,) * 3


def load_text() -> str:
    """:func:`loadavg` as ``"1.08 / 1.10 / 0.97"``."""
    return " / ".join(f"{x:.2f}" for x in loadavg())


def pyplot():
    """matplotlib's pyplot on the Agg backend (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt
