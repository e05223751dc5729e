"""What moves the base: the excitations a block can be driven by.

An excitation is a small frozen object, validated once in its constructor. Today's is the
harmonic forcing of the study (:class:`Harmonic`): the base acceleration ``f(t) = alpha omega^2
sin(omega t + phi)`` in units of ``g`` (docs/theory/model.md), written either in closed form or
through the autonomous oscillator that the study's own code integrated. Every entry point takes
an excitation beside the block. The transient excitations, acceleration pulses and recorded
ground motions, are further subclasses of :class:`Excitation` in :mod:`rockjit.ground`
(:class:`rockjit.Pulse`, :class:`rockjit.Record`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .validate import boolean, real

__all__ = ["ACCEL_MAX", "ALPHA_MAX", "OMEGA_RANGE", "Excitation", "Harmonic", "STUDY_PHASE"]

#: Allowed ranges of the forcing: wide (the study's values are alpha <= 1, omega ~ 1) and
#: keeping every product the integrator forms finite.
ALPHA_MAX = 1e9
OMEGA_RANGE = (1e-4, 1e4)
#: Largest forcing acceleration ``alpha omega^2`` (in units of g): slow forcing may take a
#: large amplitude alpha, what the block feels is the acceleration.
ACCEL_MAX = 1e8

#: The study's forcing point ``(r0, s0)`` of its single runs and sweeps (with its initial angle
#: and velocity, :data:`rockjit.Z0_STUDY`).
STUDY_PHASE = (-0.7778, 0.6284)

#: How far from the unit circle a closed-form ``(r0, s0)`` may lie.
CIRCLE_TOL = 1e-3


class Excitation:
    """The base of every excitation: a frozen, validated description of the base's motion.

    Every excitation evaluates ``f(t)``, the base acceleration in ``g`` at model time ``t``,
    and says when it ends (``end``; ``inf`` for the harmonic forcing). A transient one
    (``transient = True``: :class:`rockjit.Pulse`, :class:`rockjit.Record`) also gives, once
    bound to a block (``bind``), ``scalar()`` (``f`` as a function of one float), ``peak``
    (``max |f|``), ``breaks`` (the instants where ``f`` or its derivative jumps),
    ``windows(threshold)`` (the intervals where ``|f| > threshold``, which is where a block at
    rest lifts off) and ``scaled(gain)`` (the same motion, ``gain`` times stronger).
    """

    #: Whether the excitation ends (pulses, records) rather than repeats.
    transient = False

    def plan_run(self, block, state, integration, lyapunov, record_stride, method):
        """The plan of a single run under this excitation, for an excitation whose runs take
        a path of their own (:func:`rockjit.simulate` asks it): a pulse or a record plans its
        transient run (``rockjit.ground.plan``); the harmonic forcing plans in
        ``rockjit.single`` itself. The plan's ``run()`` executes it."""
        raise NotImplementedError(f"{type(self).__name__} plans no run of its own")

    def replace(self, **changes):
        """A copy with some fields changed (validated again)."""
        return replace(self, **changes)


@dataclass(frozen=True)
class Harmonic(Excitation):
    """The harmonic base acceleration ``f(t) = alpha omega^2 sin(omega t + phi)`` (in ``g``).

    Parameters
    ----------
    alpha : float, optional
        Amplitude ``A/R`` in ``[0, 1e9]`` with ``alpha omega^2 <= 1e8``. Left out where a grid
        sweeps it (:func:`rockjit.sweep`, :func:`rockjit.erosion`, :func:`rockjit.plane`).
    omega : float, optional
        Frequency ``Omega/Omega0`` in ``[1e-4, 1e4]``. Left out where a grid sweeps it
        (:func:`rockjit.plane`).
    phase : float, optional
        The phase ``phi``; or give the oscillator's starting point ``(r0, s0)``, with
        ``phi = atan2(r0, s0)``. Neither: the study's forcing point for runs from the study's
        initial state, ``(r0, s0) = (0, 1)`` otherwise.
    r0, s0 : float, optional
        The forcing oscillator's starting point (both or neither), on the unit circle for the
        closed form (to 1e-3).
    embedded : bool
        Integrate the study's 4-D oscillator embedding with the block instead of using the
        closed form (the only meaningful choice for an ``(r0, s0)`` off the circle).

    Examples
    --------
    >>> from rockjit import Harmonic
    >>> f = Harmonic(alpha=0.6, omega=1.3)
    >>> round(f.period, 4), f.start()[1:]
    (4.8332, (0.0, 1.0))
    """

    alpha: float | None = None
    omega: float | None = None
    phase: float | None = None
    r0: float | None = None
    s0: float | None = None
    embedded: bool = False

    def __post_init__(self):
        values = {}
        if self.alpha is not None:
            values["alpha"] = real("alpha", self.alpha, 0.0, ALPHA_MAX)
        if self.omega is not None:
            values["omega"] = real("omega", self.omega, *OMEGA_RANGE)
        if self.alpha is not None and self.omega is not None:
            check_acceleration(values["alpha"], values["omega"])
        embedded = boolean("embedded", self.embedded)
        if self.phase is not None:
            if self.r0 is not None or self.s0 is not None:
                raise ValueError("give either phase or (r0, s0), not both")
            values["phase"] = real("phase", self.phase)
        elif (self.r0 is None) != (self.s0 is None):
            raise ValueError("r0 and s0 go together: give both or neither")
        elif self.r0 is not None:
            r0 = real("r0", self.r0, -1e3, 1e3)
            s0 = real("s0", self.s0, -1e3, 1e3)
            check_point(r0, s0, embedded)
            values.update(r0=r0, s0=s0)
        values["embedded"] = embedded
        for name, value in values.items():
            object.__setattr__(self, name, value)

    @property
    def phase_given(self) -> bool:
        """Whether a phase or ``(r0, s0)`` was given."""
        return self.phase is not None or self.r0 is not None

    def start(self, default=(0.0, 1.0)):
        """``(phi, r0, s0)``: the phase and the oscillator's starting point, from the phase or
        ``(r0, s0)`` given, else from the point ``default``."""
        if self.phase is not None:
            return self.phase, math.sin(self.phase), math.cos(self.phase)
        r0, s0 = (self.r0, self.s0) if self.r0 is not None else default
        return math.atan2(r0, s0), r0, s0

    def require(self, *names, why):
        """Refuse an excitation that lacks one of ``names`` (``why``: the entry point) or that
        gives one the entry point sweeps itself (``names`` prefixed with ``-``)."""
        for name in names:
            if name.startswith("-"):
                if getattr(self, name[1:]) is not None:
                    raise ValueError(f"{why} sweeps {name[1:]} itself: leave it out of the "
                                     f"excitation (got {name[1:]} = {getattr(self, name[1:])})")
            elif getattr(self, name) is None:
                raise ValueError(f"{why} needs the excitation's {name} "
                                 f"(e.g. Harmonic({name}=...))")
        return self

    @property
    def period(self) -> float:
        """The forcing period ``2 pi / omega``."""
        return 2.0 * math.pi / self.omega

    @property
    def aw2(self) -> float:
        """The acceleration amplitude ``alpha omega^2`` (in ``g``)."""
        return self.alpha * self.omega**2

    #: The harmonic forcing never ends.
    end = math.inf

    def f(self, t):
        """The base acceleration ``alpha omega^2 sin(omega t + phi)`` in ``g`` at model time(s)
        ``t``, at the phase given (0 when none was)."""
        import numpy as np
        phi = self.start()[0]
        out = self.aw2 * np.sin(self.omega * np.asarray(t, dtype=float) + phi)
        return float(out) if out.ndim == 0 else out


def check_acceleration(alpha, omega):
    """Refuse ``alpha omega^2 > ACCEL_MAX``."""
    if alpha * omega**2 > ACCEL_MAX:
        raise ValueError(f"the forcing acceleration alpha * omega**2 must be <= "
                         f"{ACCEL_MAX:g} (got alpha = {alpha:g}, omega = {omega:g}: "
                         f"{alpha * omega**2:.3g})")


def check_point(r0, s0, embedded):
    """Refuse an oscillator point at the origin, or off the circle for the closed form."""
    rad = math.hypot(r0, s0)
    if rad == 0.0:
        raise ValueError("(r0, s0) must not be (0, 0): the forcing oscillator has no phase there")
    if not embedded and abs(rad - 1.0) > CIRCLE_TOL:
        raise ValueError(f"(r0, s0) must lie on the unit circle for the closed-form forcing "
                         f"(|(r0, s0)| = {rad:.6g}); use Harmonic(..., embedded=True) for a "
                         f"start off the circle")
