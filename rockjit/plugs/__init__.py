"""Excitations as plugs: each excitation one module, which the compiled kernels run through
functions of its own.

The harmonic forcing of the study, ``rockjit.plugs.harmonic``, is the plug of the periodic
kernels (single runs, sweeps, basins, the lanes and the GPU's cells): its closed form, the
rotations of its phase over a step, its derivatives, the instant it lifts a block at rest and
its oscillator. Every other module but ``base`` (which says what a plug gives,
:mod:`rockjit.plugs.base`) defines and registers one transient plug: :class:`rockjit.HarmonicSum`, a sum of
harmonics over a given duration; :class:`rockjit.Pulse`, the one-sine, one-cosine and Ricker
pulses; :class:`rockjit.Record`, a recorded ground motion. When the package is imported, the
transient kernel's two entry points are rendered over the registered plugs: ``plug_value`` and
``plug_window`` dispatch on the plug's code (0, 1, ..., in the order of registration) to its
compiled functions. A new excitation that ends is one more module here
(docs/guide/extending.md), and nothing else changes.
"""

from __future__ import annotations

import importlib
import pkgutil

from .._jit import jit
from .base import TransientPlug, register, registered

__all__ = ["HarmonicSum", "Pulse", "Record", "TransientPlug", "plug_value", "plug_window",
           "register", "registered"]

for _m in sorted(m.name for m in pkgutil.iter_modules(__path__)):
    if _m not in ("base", "harmonic"):
        importlib.import_module(f"{__name__}.{_m}")


def _render():
    """Compile the dispatch of ``plug_value`` and ``plug_window`` over the registered
    plugs, giving each its code."""
    value = ['def plug_value(code, t, a, c, off, n):',
             '    """The registered plug of code ``code``: its ``value(t, a, c, off, n)``."""']
    window = ['def plug_window(code, tq, end, a, c, off, n, thr):',
              '    """The registered plug of code ``code``: its ``window(tq, end, a, c, off, n,',
              '    thr)``; ``(0, 0, 0)`` for an unknown code."""']
    for i, cls in enumerate(registered()):
        cls.code = i
        globals()[f"_value_{i}"] = cls.value
        globals()[f"_window_{i}"] = cls.window
        value += [f"    if code == {i}:", f"        return _value_{i}(t, a, c, off, n)"]
        window += [f"    if code == {i}:",
                   f"        return _window_{i}(tq, end, a, c, off, n, thr)"]
    value.append("    return 0.0")
    window.append("    return 0.0, 0.0, 0.0")
    src = "\n".join(value) + "\n\n\n" + "\n".join(window) + "\n"
    exec(compile(src, __file__, "exec"), globals())  # noqa: S102 - our own template
    # the value is called at every stage of every step: inlined, as the kernel's own code
    return (jit(globals()["plug_value"], nrt=False, inline=True),
            jit(globals()["plug_window"], nrt=False))


plug_value, plug_window = _render()

from .harmonic_sum import HarmonicSum  # noqa: E402
from .pulse import Pulse  # noqa: E402
from .record import Record  # noqa: E402
