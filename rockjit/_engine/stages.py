"""The Dormand–Prince stage chain, written once: a template rendered into each compiled step.

Every step of the package integrates a second-order equation ``x'' = a(t, x, x')`` (the block's
angle; a column of its tangent matrix) over one step of the tableau in
:mod:`rockjit._engine.tableau`. The chain of its stages is written here, once, as source text
that :func:`chain` renders for one step: where the coefficients come from (a step table of the
scalar kernel, a lane's row, literal floats), how a stage's derivative is evaluated, and in
which of two arithmetic forms:

- ``"fma"``: each sum is a chain of fused multiply-adds over the step's table, the newest stage
  last (the rest of it is ready early: the step's latency is this chain);
- ``"plain"``: ``x0 + h * (c_0 w_0 + c_1 w_1 + ...)`` with literal coefficients, summed left to
  right (the transient kernels' step).

And in which of two forms the positions are kept:

- ``"nystrom"``: as offsets ``d_i`` from the start, straight from the accelerations,
  ``d_i = h c_i v0 + h^2 sum_j (A A)_ij k_j`` (each waits for the acceleration two stages back,
  not for a velocity);
- ``"first"``: ``x_i = x0 + h sum_j A_ij v_j``, the first-order form.

The rendered lines name stage ``i``'s values ``x{i}, v{i}, k{i}`` (row 6 is the step's end);
the caller binds ``x0, v0, k0`` and writes what comes before and after (:func:`compile_step`
turns the whole into a compiled function). Only the coefficients not exactly zero enter a sum
(:data:`rockjit._engine.tableau.COLS`). The same source can be given to any decorator: a stage
is an expression over device functions the caller names, the step allocates nothing and calls
nothing but those and ``fma``.
"""

from __future__ import annotations

from .tableau import COEF, COLS, N_STAGES

__all__ = ["chain", "compile_step"]

ROWS = N_STAGES + 1  # stage rows 0..5 and the step's end


def _fma_sum(terms, base):
    """``fma(c_n, w_n, ... fma(c_0, w_0, base))``: the terms in order, the last outermost."""
    expr = base
    for c, w in terms:
        expr = f"fma({c}, {w}, {expr})"
    return expr


def _plain_sum(x0, h, terms):
    """``x0 + h * (c_0 * w_0 + c_1 * w_1 + ...)``, summed left to right."""
    return f"{x0} + {h} * ({' + '.join(f'{c} * {w}' for c, w in terms)})"


def chain(stage, coef=None, *, arith="fma", form="nystrom", h="hh", last=ROWS - 1):
    """The lines of the stage chain, rows ``1..last``.

    Parameters
    ----------
    stage : callable
        ``stage(i)`` -> the line(s) (a string, ``\\n``-separated) that set ``k{i}`` from
        ``x{i}, v{i}``; the row's node is not defined in the chain: a stage that needs it
        writes it in, as :func:`node` gives it (a literal, ``1.0`` at the step's end).
    coef : callable, optional
        With ``arith="fma"``: ``coef(kind, i, j)`` -> the expression of the step-scaled
        coefficient ``j`` of row ``i`` (``kind`` ``"A"``: ``h A``/``h B``; ``"AA"``:
        ``h^2 A A``/``h^2 B A``; ``"C"``: ``h c_i``, ``j`` unused).
    arith : {"fma", "plain"}
    form : {"nystrom", "first"}
        ``"nystrom"`` keeps ``x{i}`` as the offset from ``x0`` (``arith="fma"`` only).
    h : str
        With ``arith="plain"``, the name of the step's length.
    last : int
        The last row rendered (6: the step's end, with its derivative).
    """
    lines = []
    for i in range(1, last + 1):
        acols = COLS["A"][i]
        if arith == "fma":
            if form == "nystrom":
                x = _fma_sum([(coef("AA", i, j), f"k{j}") for j in COLS["AA"][i]],
                             f"{coef('C', i, 0)} * v0")
            else:
                x = _fma_sum([(coef("A", i, j), f"v{j}") for j in acols], "x0")
            v = _fma_sum([(coef("A", i, j), f"k{j}") for j in acols], "v0")
        else:
            a = COEF["A"][i]
            x = _plain_sum("x0", h, [(repr(float(a[j])), f"v{j}") for j in acols])
            v = _plain_sum("v0", h, [(repr(float(a[j])), f"k{j}") for j in acols])
        lines += [f"x{i} = {x}", f"v{i} = {v}"]
        lines += stage(i).split("\n")
    return lines


def node(i):
    """Row ``i``'s node ``c_i`` as a literal (1 at the step's end)."""
    return repr(float(COEF["C"][i]))


def compile_step(name, params, lines, env, deco, doc=""):
    """Compile ``def name(params): lines`` with ``deco``, its globals ``env``.

    ``env`` is the namespace of the module the step belongs to (its ``globals()``): the step's
    names resolve there, and numba's cache files it under that module's source file, told
    apart from the module's other functions by its name and from earlier renderings by its
    code."""
    body = "\n".join("    " + ln for ln in lines)
    assert '"""' not in doc and "\\" not in doc
    src = f'def {name}({params}):\n    """{doc}"""\n{body}\n'
    exec(compile(src, env["__file__"], "exec"), env)  # noqa: S102 - our own template
    fn = env[name]
    fn.__source__ = src
    return deco(fn)
