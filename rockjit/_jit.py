"""The project's one numba policy: every compiled function is decorated with :func:`jit`.

``FASTMATH`` is the single fastmath setting (STYLE.md 7). It keeps IEEE NaN/inf semantics (no
``nnan``/``ninf``) so event tests and non-finite guards behave, and it leaves out ``contract`` and
``reassoc``: with them LLVM fuses or reorders the same arithmetic differently in two compilations
(tangent vectors on or off, say), and the state's trajectory then differs in the last bit. The
switch-independence of trajectories is a promise (tests/test_lyapunov.py); measured on the
reference run, contraction bought no speed distinguishable from the noise of this machine.
"""

import numba

FASTMATH = frozenset({"nsz"})


def jit(func=None, *, parallel=False, inline="never"):
    """``numba.njit`` with the project policy: cached, the one fastmath set.

    ``inline="always"`` inlines at numba's IR level: used for the few helpers called once per
    step, whose many array arguments would otherwise cost more than their arithmetic.
    """
    deco = numba.njit(cache=True, fastmath=set(FASTMATH), parallel=parallel,
                      error_model="numpy", inline=inline)
    return deco if func is None else deco(func)
