"""Excitations as plugs: transient excitations that the compiled kernel of pulses and records runs
through functions of their own, one module each.

Every module of this package defines and registers one plug (:mod:`rockjit.plugs.base` says what
a plug gives): :class:`rockjit.HarmonicSum`, a sum of harmonics over a given duration. When the package is
imported, the kernel's two entry points are rendered over the registered plugs:
``plug_value`` and ``plug_window`` dispatch on the plug's kind (``FIRST_KIND``, the next,
...) to its compiled functions. A new excitation of this kind is one more module here
(docs/guide/extending.md), and nothing else changes.
"""

from __future__ import annotations

import importlib
import pkgutil

from .._jit import jit
from .base import TransientPlug, register, registered

__all__ = ["FIRST_KIND", "HarmonicSum", "TransientPlug", "plug_value", "plug_window", "register",
           "registered"]

#: The kind of the first plug: the kernel's own kinds (the three pulses, a record) come before.
FIRST_KIND = 4

for _m in sorted(m.name for m in pkgutil.iter_modules(__path__)):
    if _m != "base":
        importlib.import_module(f"{__name__}.{_m}")


def _render():
    """Compile the dispatch of ``plug_value`` and ``plug_window`` over the registered
    plugs, giving each its kind."""
    value = ['def plug_value(kind, t, rec, off, n):',
             '    """The registered plug of kind ``kind``: its ``value(t, rec, off, n)``."""']
    window = ['def plug_window(kind, tq, end, rec, off, n, thr):',
              '    """The registered plug of kind ``kind``: its ``window(tq, end, rec, off, n,',
              '    thr)``; ``(0, 0, 0)`` for an unknown kind."""']
    for i, cls in enumerate(registered()):
        cls.kind = FIRST_KIND + i
        globals()[f"_value_{i}"] = cls.value
        globals()[f"_window_{i}"] = cls.window
        value += [f"    if kind == {cls.kind}:", f"        return _value_{i}(t, rec, off, n)"]
        window += [f"    if kind == {cls.kind}:",
                   f"        return _window_{i}(tq, end, rec, off, n, thr)"]
    value.append("    return 0.0")
    window.append("    return 0.0, 0.0, 0.0")
    src = "\n".join(value) + "\n\n\n" + "\n".join(window) + "\n"
    exec(compile(src, __file__, "exec"), globals())  # noqa: S102 - our own template
    return (jit(globals()["plug_value"], nrt=False), jit(globals()["plug_window"], nrt=False))


plug_value, plug_window = _render()

from .harmonic_sum import HarmonicSum  # noqa: E402
