"""The project's one numba policy: every compiled function is decorated with :func:`jit`.

``FASTMATH`` is the single fastmath setting (STYLE.md 7). It keeps IEEE NaN/inf semantics (no
``nnan``/``ninf``) so event tests and non-finite guards behave, and it leaves out ``contract`` and
``reassoc``: with them LLVM fuses or reorders the same arithmetic differently in two compilations
(tangent vectors on or off, say), and the state's trajectory then differs in the last bit. The
switch-independence of trajectories is a promise (tests/test_lyapunov.py); measured on the
reference run, contraction bought no speed distinguishable from the noise of this machine.
"""

import hashlib
import os
from pathlib import Path

import numba
from llvmlite import ir
from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

FASTMATH = frozenset({"nsz"})


def jit(func=None, *, parallel=False, nrt=True, inline=False):
    """``numba.njit`` with the project policy: cached, the one fastmath set.

    ``nrt=False`` compiles without numba's reference-counting runtime: for the helpers of the
    hot loop, which read and write arrays they are given but never allocate. With the runtime,
    every call increments and decrements the count of each array argument with a locked
    (serialising) instruction, which cost a third of a step's time.

    ``inline=True`` inlines the function into its callers in numba's own IR (``inline=
    "always"``). For the pieces of the step: LLVM declines to inline a function that large at
    more than one call site, and an out-of-line call passes every array as seven scalars on the
    stack and hides the stage chain from the scheduler.
    """
    opts = dict(cache=True, fastmath=set(FASTMATH), parallel=parallel, error_model="numpy")
    if inline:
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


# ---- keeping numba's on-disk cache honest ------------------------------------------------------
# numba invalidates a cached function only when its own source file changes; the kernels inline
# code from other modules (model.py, _jit.py), and an edit there would leave stale machine code
# in use. The package's compiled sources are hashed at import, and numba's cache files of this
# package are dropped whenever the hash differs from the one stamped beside them.

_SOURCES = ("_jit.py", "model.py", "integrate.py", "analysis.py")


def _cache_dirs(pkg):
    """``(stamp folder, folders whose numba files it vouches for)`` pairs."""
    pairs = [(pkg / "__pycache__", [pkg / "__pycache__"])]
    root = os.environ.get("NUMBA_CACHE_DIR")
    if root:
        # numba makes its per-package folders there only when it first compiles, so the stamp
        # lives at the root and covers every folder of this package below it
        subs = [Path(d) for d, _, _ in os.walk(root) if "rockjit" in Path(d).name] \
            if Path(root).is_dir() else []
        pairs.append((Path(root), subs))
    return pairs


def check_cache(pkg=None):
    """Drop numba's cache files of the package when its compiled sources changed."""
    pkg = Path(__file__).resolve().parent if pkg is None else Path(pkg)
    h = hashlib.sha256()
    for name in _SOURCES:
        try:
            h.update((pkg / name).read_bytes())
        except OSError:
            return
    digest = h.hexdigest()
    for home, dirs in _cache_dirs(pkg):
        stamp = home / "rockjit-sources.sha256"
        try:
            if stamp.read_text() == digest:
                continue
        except OSError:
            pass
        try:
            for d in dirs:
                for f in d.glob("*.nb[ic]"):
                    f.unlink(missing_ok=True)
            home.mkdir(parents=True, exist_ok=True)
            tmp = home / f"rockjit-sources.sha256.{os.getpid()}"
            tmp.write_text(digest)
            os.replace(tmp, stamp)
        except OSError:
            pass  # a read-only install: numba then caches elsewhere or not at all


check_cache()
