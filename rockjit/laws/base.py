"""What a restitution law is: the small object every law of :mod:`rockjit.laws` is an instance of.

A law gives the coefficient of restitution ``e`` of an impact on ``theta = 0``, where the block
changes corner and ``theta'(+) = e theta'(-)``. Most laws give one coefficient per block, from
its slenderness alone (Housner's, Mao et al.'s) or as a number (the constant law). A law may also
depend on the impact itself, on its approach speed ``|theta'(-)|``: it then names a compiled
function that the integrator calls at every impact (:mod:`rockjit.laws.impact`).
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["RestitutionLaw", "register", "registered", "unregister"]

_REGISTRY = {}
_OWN = set()


@dataclass(frozen=True)
class RestitutionLaw:
    """A restitution law: its name, how figures show it, and its coefficient.

    Subclasses set the class attributes and :meth:`coefficient`; a law that depends on the
    impact also sets ``impact`` (see :mod:`rockjit.laws.impact`).

    Attributes
    ----------
    name : str
        The name a :class:`rockjit.Block`, the command line and the explorer select it by.
    label : str
        How figures and tables write it (matplotlib mathtext allowed).
    colour : str
        Its colour where figures compare laws in colour.
    line : dict
        Its line style and marker where laws share an axis in black.
    needs_e : bool
        Whether the block gives the coefficient itself (``Block(e=...)``).
    impact : numba function or None
        ``impact(speed, e, shape) -> (e_impact, slope)``: the coefficient at an impact of
        approach speed ``speed`` and the derivative ``d(e(v) v)/dv`` there, from the block's
        coefficient ``e`` and the law's ``shape``; ``None`` for a coefficient fixed per block.

    Examples
    --------
    >>> from rockjit import Block, laws
    >>> law = laws.get("mao")
    >>> law.label, round(law.coefficient(Block(hb=1).thc), 3)
    ('Mao et al.', 0.582)
    """

    name = ""
    order = 100  # where the law comes in tables (the study's two first)
    label = ""
    colour = "k"
    line = dict(color="k", ls="-.", marker="v")
    needs_e = False
    impact = None

    def coefficient(self, thc, e=None):
        """The block's coefficient of restitution for the diagonal angle ``thc`` (``e``: the
        block's own, for a law that ``needs_e``); of a slow impact, for a law that depends on
        the impact."""
        raise NotImplementedError

    def check(self, hb):
        """Refuse (``ValueError``) a slenderness the law has no meaning for."""

    @property
    def shape(self):
        """The parameter the compiled ``impact`` function takes beside ``e`` (0: none)."""
        return 0.0

    def at_impact(self, speed, e):
        """The coefficient at an impact of approach speed ``speed >= 0``: ``e`` for a law
        fixed per block, else the law's ``impact`` (the same compiled function the
        integrator calls)."""
        if self.impact is None:
            return e
        return self.impact(float(speed), float(e), self.shape)[0]

    def describe(self):
        """One line on the law, for reprs and reports."""
        return self.label


def register(law):
    """Make ``law`` selectable by its name: ``Block(hb, law=law.name)``, the command line's
    ``--law`` and every table of laws.

    Parameters
    ----------
    law : RestitutionLaw
        An instance, named (its class's ``name``) and not taken by another law.

    Returns
    -------
    RestitutionLaw
        ``law``.

    A law whose ``impact`` is a compiled function must be defined in a module of
    :mod:`rockjit.laws`: the integrator's kernels are compiled with the impact functions of
    the package's laws (:mod:`rockjit.laws.impact`), and a function they do not know is refused.

    Examples
    --------
    >>> from dataclasses import dataclass
    >>> from rockjit import Block, laws
    >>> @dataclass(frozen=True)
    ... class Measured(laws.RestitutionLaw):
    ...     name = "measured-0.9"
    ...     label = "Housner x 0.9"
    ...     def coefficient(self, thc, e=None):
    ...         return 0.9 * float(laws.housner.e_housner(thc))
    >>> _ = laws.register(Measured())
    >>> round(Block(hb=1, law="measured-0.9").restitution, 4)
    0.225
    >>> laws.unregister("measured-0.9")
    """
    if not isinstance(law, RestitutionLaw) or not law.name:
        raise ValueError(f"law must be a named RestitutionLaw instance (got {law!r})")
    if law.name in _REGISTRY and _REGISTRY[law.name] != law:
        raise ValueError(f"a restitution law named {law.name!r} is registered already")
    if law.impact is not None:
        from .impact import kind_of
        kind_of(law)  # refuses an impact function the kernels were not compiled with
    _REGISTRY[law.name] = law
    return law


def unregister(name):
    """Take the law named ``name`` out of the registry (a law a user registered; the package's
    own laws stay).

    Parameters
    ----------
    name : str
        The name of a law :func:`register` added.

    Examples
    --------
    >>> from rockjit import laws
    >>> laws.unregister("housner")
    Traceback (most recent call last):
    ...
    ValueError: the package's own law 'housner' stays registered
    """
    if name in _OWN:
        raise ValueError(f"the package's own law {name!r} stays registered")
    if name not in _REGISTRY:
        raise ValueError(f"no restitution law named {name!r} is registered")
    del _REGISTRY[name]


def keep_own():
    """Mark the laws registered so far as the package's own (:func:`unregister` keeps them)."""
    _OWN.update(_REGISTRY)


def registered():
    """The registered laws, in table order (``order``, then name).

    Examples
    --------
    >>> from rockjit import laws
    >>> [law.name for law in laws.registered()][:2]
    ['housner', 'mao']
    """
    return sorted(_REGISTRY.values(), key=lambda law: (law.order, law.name))
