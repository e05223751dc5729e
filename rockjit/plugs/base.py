"""What an excitation plug is: a transient excitation the compiled transient kernel runs through
two compiled functions of its own.

A plug is an :class:`rockjit.Excitation` that ends (``transient = True``), written in one module
of :mod:`rockjit.plugs`: the pulses, recorded motions and sums of harmonics are plugs. The compiled
kernel of transient runs (:mod:`rockjit._engine.transient`) keeps a plug's numbers,
:meth:`TransientPlug.coefficients`, in one flat array and calls the plug's two compiled
functions, with ``a`` the cell's amplitude (:meth:`TransientPlug.amplitude_at`):

- ``value(t, a, c, off, n)``: the base acceleration (``g``) at model time ``0 <= t <= end``,
  from the ``n`` numbers ``c[off:off + n]``;
- ``window(tq, end, a, c, off, n, thr)``: the first interval ``(t0, t1, sign)`` of
  ``[0, end]`` with ``t1 > tq`` where ``|f| > thr`` (``sign`` of ``f`` there, 0 if none):
  where a block at rest may lift off.

The kernel steps a plug on the grid :meth:`TransientPlug.grid` gives (equal steps over
``[0, end]``, or equal steps between the kinks of a sampled motion) and adds its own steps at
every event. The scipy reference path uses the plug's Python side (:meth:`scalar`,
:meth:`windows`, ``breaks``, ``max_step``), which each plug writes independently of its compiled
functions.
"""

from __future__ import annotations

from ..excitation import Excitation

__all__ = ["TransientPlug", "register", "registered"]

#: The registered plugs' classes, in the order of their codes.
_PLUGS = []


class TransientPlug(Excitation):
    """The base of an excitation plug (see the module's description).

    Subclasses set the class attributes ``value`` and ``window`` (``staticmethod`` of compiled
    functions), the excitation's fields, and the methods below; the module registers the class
    with :func:`register`.

    Examples
    --------
    >>> import rockjit
    >>> from rockjit.plugs import TransientPlug
    >>> isinstance(rockjit.HarmonicSum(duration=5.0), TransientPlug)
    True
    """

    transient = True
    value = None
    window = None
    #: The kernel's code of the plug (set when :mod:`rockjit.plugs` is imported).
    code = -1

    # ---- what the compiled kernel needs ----------------------------------------------------
    def coefficients(self):
        """The numbers ``value`` and ``window`` read (a 1-d float array)."""
        raise NotImplementedError

    def grid(self, shrink):
        """The kernel's step grid over ``[0, end]``: ``(steps, 0.0)`` for ``steps`` equal
        steps, or ``(steps, kink_step)`` for ``steps`` equal steps between consecutive multiples
        of ``kink_step`` (the samples of a record, where its slope jumps). ``shrink`` <= 1: the
        steps of a heavily damped block are that much shorter."""
        raise NotImplementedError

    def amplitude_at(self, gains):
        """The amplitude ``a`` the compiled functions get for each of ``gains``: this
        excitation ``gain`` times stronger (an array)."""
        raise NotImplementedError

    # ---- what every transient excitation gives ---------------------------------------------
    def bind(self, block):
        """This excitation on ``block`` (a plug in units of ``g`` needs nothing of it)."""
        return self

    def plan_run(self, block, state, integration, lyapunov, record_stride, method):
        """The plan of a single run: :mod:`rockjit.ground` plans it (and replaces this method
        when it is imported, as ``rockjit.HarmonicSum`` and every entry point do)."""
        raise ValueError(f"a run under {type(self).__name__} is planned by rockjit.ground: "
                         f"import rockjit.ground first")


def register(plug):
    """Register the plug class ``cls``: a class decorator for the plugs of this package (the
    kernel is compiled with their functions when :mod:`rockjit.plugs` is imported, which
    gives each its ``code``).

    Parameters
    ----------
    plug : type
        A :class:`TransientPlug` subclass with compiled ``value`` and ``window``.

    Returns
    -------
    type
        ``plug``.

    Examples
    --------
    >>> from rockjit.plugs import HarmonicSum, registered
    >>> HarmonicSum in registered(), HarmonicSum.code >= 0
    (True, True)
    """
    if not (isinstance(plug, type) and issubclass(plug, TransientPlug)) or plug.value is None \
            or plug.window is None:
        raise ValueError(f"a plug must be a TransientPlug subclass with compiled value and "
                         f"window functions (got {plug!r})")
    if plug not in _PLUGS:
        _PLUGS.append(plug)
    return plug


def registered():
    """The registered plug classes, in the order their codes are given.

    Examples
    --------
    >>> from rockjit import plugs
    >>> [cls.__name__ for cls in plugs.registered()]
    ['HarmonicSum', 'Pulse', 'Record']
    """
    return list(_PLUGS)
