"""Restitution laws: the coefficient of an impact, one law per module, and the one table of them.

Every module of this package defines and registers its laws (:func:`register`): Housner's and
Mao et al.'s (one coefficient per block, from its slenderness), the constant law (a number given
with the block) and a law that depends on the impact (:class:`SpeedDependent`). The table of
names, labels, colours and line styles that figures, the command line and the explorer use is
read from the registered laws (:func:`names`, and ``Table``, a live view of one attribute).
A new law is one module here (docs/guide/extending.md).
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Mapping

from . import base, impact
from .base import RestitutionLaw, register, registered, unregister

__all__ = ["Constant", "Housner", "Mao", "RestitutionLaw", "SpeedDependent", "Table", "get",
           "names", "register", "registered", "unregister"]

_OWN = ("base", "impact")
for _m in sorted(m.name for m in pkgutil.iter_modules(__path__)):
    if _m not in _OWN:
        importlib.import_module(f"{__name__}.{_m}")
impact.render(sorted({law.impact for law in registered() if law.impact is not None},
                     key=lambda fn: (fn.__module__, fn.__name__)))

from .constant import Constant  # noqa: E402
from .housner import Housner  # noqa: E402
from .mao import Mao  # noqa: E402
from .speed import SpeedDependent  # noqa: E402

base.keep_own()


def get(name):
    """The registered law named ``name``.

    Parameters
    ----------
    name : str
        A registered law's name (:func:`names`); another is refused with a ``ValueError``
        naming them.

    Returns
    -------
    RestitutionLaw

    Examples
    --------
    >>> from rockjit import laws
    >>> laws.get("speed").describe()
    'Housner, speed-softened (v_half = 1)'
    """
    for law in registered():
        if law.name == name:
            return law
    raise ValueError(f"law must be one of {', '.join(map(repr, names()))} (got {name!r})")


def names():
    """The registered laws' names, in table order.

    Examples
    --------
    >>> from rockjit import laws
    >>> laws.names()[:3]
    ('housner', 'mao', 'constant')
    """
    return tuple(law.name for law in registered())


class Table(Mapping):
    """A live ``{name: value}`` view of one attribute of the registered laws (a law registered
    later is in it too).

    Parameters
    ----------
    attr : {"label", "colour", "line"}
        The attribute.

    Examples
    --------
    >>> from rockjit import laws
    >>> laws.Table("label")["mao"]
    'Mao et al.'
    """

    def __init__(self, attr):
        self._attr = attr

    def _value(self, law):
        value = getattr(law, self._attr)
        return dict(value) if isinstance(value, dict) else value

    def __getitem__(self, name):
        for law in registered():
            if law.name == name:
                return self._value(law)
        raise KeyError(name)

    def __iter__(self):
        return iter(names())

    def __len__(self):
        return len(registered())

    def __repr__(self):
        return f"Table({self._attr!r}: {dict(self)!r})"
