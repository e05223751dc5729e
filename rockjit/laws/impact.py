"""The compiled restitution of an impact: the one function the integrator calls at every impact.

:func:`restitution_at` dispatches on a law's ``kind`` (a small integer the kernels carry among
their parameters) to the compiled ``impact`` function of the laws of :mod:`rockjit.laws` that
depend on the impact, and returns the block's own coefficient otherwise. Its source is rendered
once, when the package's law modules have been imported, from the impact functions they
define: a new law of that kind is one more module in :mod:`rockjit.laws`, and nothing here
changes.
"""

from __future__ import annotations

from .._jit import jit

__all__ = ["kind_of", "render", "restitution_at"]

#: The compiled impact functions of the package's laws, by kind (1, 2, ...; 0: none).
_FUNCTIONS = []
restitution_at = None


def render(functions):
    """Compile :func:`restitution_at` over ``functions`` (kinds 1, 2, ... in that order)."""
    global restitution_at
    _FUNCTIONS[:] = list(functions)
    lines = ['def restitution_at(kind, speed, e, shape):',
             '    """``(e(v), d(e(v) v)/dv)`` at an impact of approach speed ``speed``: the law of',
             '    kind ``kind`` with the block\'s coefficient ``e`` and the law\'s ``shape``; for',
             '    kind 0, a coefficient fixed per block, ``(e, e)``."""']
    for k, fn in enumerate(_FUNCTIONS, start=1):
        globals()[f"_impact_{k}"] = fn
        lines += [f"    if kind == {k}:", f"        return _impact_{k}(speed, e, shape)"]
    lines.append("    return e, e")
    exec(compile("\n".join(lines) + "\n", __file__, "exec"), globals())  # noqa: S102
    restitution_at = jit(globals()["restitution_at"], nrt=False)
    return restitution_at


def kind_of(law):
    """The kind code of ``law`` (0: a coefficient fixed per block); ``ValueError`` for an impact
    function that is not one of the package's laws'."""
    if law.impact is None:
        return 0
    for k, fn in enumerate(_FUNCTIONS, start=1):
        if fn is law.impact:
            return k
    if restitution_at is None:  # the package's own laws, before the dispatch is rendered
        return -1
    raise ValueError(f"the restitution law {law.name!r} has an impact function the integrator "
                     "was not compiled with: define such a law in a module of rockjit.laws")
