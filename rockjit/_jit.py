"""The project's one numba policy: every compiled function is decorated with :func:`jit`.

``FASTMATH`` is the single fastmath setting (STYLE.md 7). It allows contraction of multiply-add
pairs and ignores the sign of zero, but keeps IEEE NaN/inf semantics (no ``nnan``/``ninf``) so
event tests and non-finite guards behave, and does not allow reassociation, which would let two
compilations of the same arithmetic (tangent on/off, one or many threads) round differently.
"""

import numba

FASTMATH = frozenset({"contract", "nsz"})


def jit(func=None, *, parallel=False, inline="never"):
    """``numba.njit`` with the project policy: cached, the one fastmath set.

    ``inline="always"`` inlines at numba's IR level: used for the few helpers called once per
    step, whose many array arguments would otherwise cost more than their arithmetic.
    """
    deco = numba.njit(cache=True, fastmath=set(FASTMATH), parallel=parallel,
                      error_model="numpy", inline=inline)
    return deco if func is None else deco(func)
