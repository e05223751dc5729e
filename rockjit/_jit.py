"""The project's one numba policy: every compiled function is decorated with :func:`jit`.

``FASTMATH`` is the single fastmath setting, for every kernel. It keeps IEEE NaN/inf semantics (no
``nnan``/``ninf``) so event tests and non-finite guards behave, and it leaves out ``contract`` and
``reassoc``: with them LLVM fuses or reorders the same arithmetic differently in two compilations
(tangent vectors on or off, say), and the state's trajectory then differs in the last bit. The
switch-independence of trajectories is a promise (tests/_engine/test_lyapunov.py); measured on the
reference run, contraction bought no speed distinguishable from the noise of this machine.
"""

import hashlib
import os
import re
from pathlib import Path

import numba
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

FASTMATH = frozenset({"nsz"})


def jit(func=None, *, parallel=False, nrt=True, inline=False, ir_inline=False):
    """``numba.njit`` with the project policy: cached, the one fastmath set.

    ``nrt=False`` compiles without numba's reference-counting runtime: for the helpers of the
    hot loop, which read and write arrays they are given but never allocate. With the runtime,
    every call increments and decrements the count of each array argument with a locked
    (serialising) instruction, which cost a third of a step's time.

    ``inline=True`` marks the function ``alwaysinline`` for LLVM (numba's ``forceinline``):
    it is typed and lowered once, as a function of its own, and LLVM inlines it into every
    caller when the caller's module is linked. For the pieces of the step: left to its own
    heuristics, LLVM declines to inline a function that large at more than one call site, and
    an out-of-line call passes every array as seven scalars on the stack and hides the stage
    chain from the scheduler (1.6x the time per step). Inlining in numba's own IR
    (``inline="always"``, used before) gave the same speed but re-typed and re-lowered the piece
    at every call site: the step's pieces made a cold compile 1.5x longer
    (benchmarks/bench_compile.py). The flag is set on every function, off where not asked for:
    numba would otherwise let a callee inherit it from its caller.

    ``ir_inline=True`` inlines the function in numba's own IR (``inline="always"``) instead:
    no compiled function of its own. For a layer with one or two callers above the whole loop
    (``integrate._run``): every compiled function is linked with all it calls and optimised and
    turned into machine code again, so each layer above the loop pays the loop's LLVM time once
    more (benchmarks/results/compile_code_levers.md). For a piece of a loop with one call site,
    and for a leaf of a few lines (the harmonic forcing's phase rotations): typing it at each call
    site costs less than compiling it as a function of its own.
    """
    opts = dict(cache=True, fastmath=set(FASTMATH), parallel=parallel, error_model="numpy",
                forceinline=bool(inline))
    if ir_inline:
        opts["inline"] = "always"
    if not nrt:
        opts["_nrt"] = False
    deco = numba.njit(**opts)
    return deco if func is None else deco(func)


@intrinsic
def fma(typingctx, a, b, c):
    """``a * b + c`` rounded once (LLVM's ``llvm.fma.f64``: one instruction on x86-64 with FMA).

    Written out where it matters instead of letting fastmath contract at will: each fused
    multiply-add is then the same in every compilation, which keeps results bit-identical across
    compile-time switches, and it halves the latency of the Runge–Kutta stage sums and
    polynomial evaluations that make up a step's critical path.
    """
    sig = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, signature, args):
        vals = [context.cast(builder, v, t, types.float64)
                for v, t in zip(args, signature.args)]
        d = ir.DoubleType()
        fn = cgutils.get_or_insert_function(builder.module, ir.FunctionType(d, [d, d, d]),
                                            "llvm.fma.f64")
        return builder.call(fn, vals)

    return sig, codegen


@intrinsic
def cycles(typingctx):
    """The CPU's cycle counter (LLVM's ``readcyclecounter``: ``rdtsc`` on x86-64), for the
    lanes' own accounting of where their time goes (read only when profiling: each read costs
    tens of cycles)."""
    sig = types.int64()

    def codegen(context, builder, signature, args):
        fn = builder.module.declare_intrinsic("llvm.readcyclecounter", fnty=ir.FunctionType(
            ir.IntType(64), []))
        return builder.call(fn, [])

    return sig, codegen


# ---- keeping numba's on-disk cache honest ------------------------------------------------------
# numba invalidates a cached function only when its own source file changes; the kernels inline
# code from other modules (model.py, _jit.py), and an edit there would leave stale machine code
# in use. The package's compiled sources are hashed at import, and numba's cache files of this
# package are dropped whenever the hash differs from the one stamped beside them.
#
# Which files are "numba's cache files of this package" follows numba's own cache locators
# (numba/core/caching.py, numba 0.59-0.68), tried in this order for a function defined in
# <pkg>/<module>.py:
#   _UserProvidedCacheLocator  $NUMBA_CACHE_DIR/<subpath>    when NUMBA_CACHE_DIR is set
#   _InTreeCacheLocator        <pkg>/__pycache__             when writable
#   _UserWideCacheLocator      <user cache dir>/<subpath>    otherwise (appdirs "numba")
# where <subpath> = _CacheLocator.get_suitable_cache_subpath(py_file) = "<basename of pkg>_"
# + sha1(<absolute path of pkg>).hexdigest(), and each function's files are named
# "<module>.<qualname without < >>-<first line>.py<major><minor><abiflags>" + ".nbi" (the index)
# or ".<n>.nbc" (the data). Only files of that form whose <module> is a module of the package
# are deleted, and only in those folders: nothing else under NUMBA_CACHE_DIR is touched.

_SOURCES = ("_jit.py", "model.py")
STAMP = "rockjit-sources.sha256"
_IMPORTS_JIT = re.compile(rb"^\s*from\s+(\.+|rockjit\.)_jit\s+import\b", re.M)


def _compiled_sources(pkg):
    """The package's modules whose code numba compiles, as paths relative to ``pkg``: those
    named in ``_SOURCES`` and every module, in any subpackage, that imports this one (the only
    way to reach the project's ``jit``)."""
    names = set(_SOURCES)
    for f in pkg.rglob("*.py"):
        try:
            text = f.read_bytes()
        except OSError:
            continue
        if _IMPORTS_JIT.search(text):
            names.add(f.relative_to(pkg).as_posix())
    return sorted(names)


def _compiled_folders(pkg):
    """The folders of the package that hold compiled modules: numba keeps a cache per folder."""
    return sorted({(pkg / name).parent for name in _compiled_sources(pkg)})


def _subpath(pkg_dir):
    """numba's folder name for the functions of files in ``pkg_dir`` (``_CacheLocator.
    get_suitable_cache_subpath``)."""
    path = os.path.abspath(pkg_dir)
    return "_".join([os.path.split(path)[-1], hashlib.sha1(path.encode()).hexdigest()])


def _user_wide_dir():
    """numba's user-wide cache folder (``_UserWideCacheLocator``)."""
    try:
        from numba.misc.appdirs import AppDirs
        return Path(AppDirs(appname="numba", appauthor=False).user_cache_dir)
    except Exception:  # pragma: no cover - numba's private layout changed
        return None


def _cache_dirs(pkg):
    """The folders where numba may keep this package's compiled functions, in numba's order
    of preference (see the comment above)."""
    variants = {os.path.abspath(pkg), os.path.realpath(pkg)}  # numba uses the path imported
    dirs = []
    root = os.environ.get("NUMBA_CACHE_DIR")
    if root:
        dirs += [Path(root) / _subpath(v) for v in sorted(variants)]
    dirs.append(Path(pkg) / "__pycache__")
    wide = _user_wide_dir()
    if wide is not None:
        dirs += [wide / _subpath(v) for v in sorted(variants)]
    return dirs


def _cache_file_pattern(modules):
    """Names numba gives the cache files of functions defined in ``modules`` (stems)."""
    alt = "|".join(re.escape(m) for m in sorted(modules))
    return re.compile(rf"(?:{alt})\.[^/\\]+-\d+\.py\d+[a-z]*(?:\.\d+\.nbc|\.nbi)")


def check_cache(pkg=None):
    """Drop numba's cache files of the package when its compiled sources changed.

    Parameters
    ----------
    pkg : str or Path, optional
        The package folder (default: this package's).

    Notes
    -----
    The sources hashed are the package's modules that numba compiles (``_compiled_sources``).
    Each cache folder of the package (``_cache_dirs``) holds a stamp, ``rockjit-sources.sha256``,
    with the hash its files were compiled from. Where the stamp differs or is missing, the
    folder's cache files of the package's modules are deleted and the stamp rewritten. The first
    folder numba would use is created if absent (numba would create it when compiling), so the
    stamp is in place before the first compilation; the others are checked only if they exist.
    """
    pkg = Path(__file__).parent if pkg is None else Path(pkg)
    h = hashlib.sha256()
    for name in _compiled_sources(pkg):
        try:
            h.update(name.encode() + b"\0" + (pkg / name).read_bytes())
        except OSError:
            continue  # a module listed in _SOURCES that no longer exists
    digest = h.hexdigest()
    for folder in _compiled_folders(pkg):
        _stamp_folder(folder, digest)


def _stamp_folder(folder, digest):
    """Make ``folder``'s cache folders carry ``digest``, deleting the cache files of its modules
    where they carry another."""
    pattern = _cache_file_pattern(f.stem for f in folder.glob("*.py"))
    settled = False  # a folder numba will use has been stamped
    for home in _cache_dirs(folder):
        if settled and not home.is_dir():
            continue
        try:
            if (home / STAMP).read_text() == digest:
                settled = True
                continue
        except OSError:
            pass
        try:
            home.mkdir(parents=True, exist_ok=True)
            for f in home.iterdir():
                if pattern.fullmatch(f.name):
                    f.unlink(missing_ok=True)
            tmp = home / f"{STAMP}.{os.getpid()}"
            tmp.write_text(digest)
            os.replace(tmp, home / STAMP)
            settled = True
        except OSError:
            pass  # read-only: numba then caches in the next folder, or not at all


def cached_kernels(pkg=None, modules=("integrate", "kernel")):
    """Whether numba's cache already holds compiled kernels of the package (any cache file of
    ``modules`` in ``_engine``: by default ``integrate.py``, where every harmonic kernel's loop
    lives; ``("transient",)`` for the pulses' and records' kernel): a cold first run compiles
    for a minute."""
    pkg = Path(__file__).parent if pkg is None else Path(pkg)
    pkg = pkg / "_engine"
    pattern = _cache_file_pattern(list(modules))
    root = os.environ.get("NUMBA_CACHE_DIR")
    for home in _cache_dirs(pkg):
        if root and Path(root) not in home.parents:
            continue  # with NUMBA_CACHE_DIR set, numba reads and writes only there
        try:
            if any(f.name.endswith(".nbc") and pattern.fullmatch(f.name)
                   for f in home.iterdir()):
                return True
        except OSError:
            continue
    return False


check_cache()
