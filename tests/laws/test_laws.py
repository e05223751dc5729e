"""The restitution laws as objects: the one table of them, a law a user writes, and refusals.

References: the papers' closed forms (Housner's ``1 - 1.5 cos^2``), exact identities (a law a
user registers runs bit for bit as the constant law with the same coefficient), and the law's
own formula written out here.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic, Integration, laws
from rockjit.laws import RestitutionLaw, SpeedDependent, register
from rockjit.plotting import style


def test_one_table_of_laws_for_figures_the_command_line_and_blocks():
    assert laws.names()[:3] == ("housner", "mao", "constant")  # the study's laws first
    assert "speed" in laws.names()
    assert set(style.LAW_NAMES) == set(style.LAW_LINES) == set(style.LAW_COLOURS) \
        == set(laws.names())
    for name in laws.names():
        law = laws.get(name)
        assert style.LAW_NAMES[name] == law.label and style.LAW_COLOURS[name] == law.colour
        assert law.label and law.colour.startswith("#") and {"ls", "marker"} <= set(law.line)
    # every law is told apart from every other, by colour and by line or marker
    colours = [laws.get(n).colour for n in laws.names()]
    lines = [(str(laws.get(n).line["ls"]), laws.get(n).line["marker"]) for n in laws.names()]
    assert len(set(colours)) == len(colours) and len(set(lines)) == len(lines)


def test_the_speed_law_against_its_formula():
    thc = math.atan(1.5)
    e_h = 1.0 - 1.5 * math.cos(thc) ** 2
    b = Block(1.5, "speed")
    assert b.restitution == pytest.approx(e_h, rel=1e-15)
    law = SpeedDependent(v_half=0.4)
    for v in (0.0, 0.1, 0.4, 2.0):
        assert law.at_impact(v, e_h) == pytest.approx(e_h / (1.0 + v / 0.4), rel=1e-15)
    with pytest.raises(ValueError, match="v_half"):
        SpeedDependent(v_half=0.0)
    with pytest.raises(ValueError, match="1/sqrt"):
        Block(0.6, "speed")


def test_bad_law_names_and_registrations_are_refused():
    with pytest.raises(ValueError, match="law must be one of .*'speed'"):
        Block(1.0, "nope")
    with pytest.raises(ValueError, match="restitution law's name"):
        Block(1.0, SpeedDependent())
    with pytest.raises(ValueError, match="registered already"):
        register(SpeedDependent(v_half=0.3))
    with pytest.raises(ValueError, match="named RestitutionLaw"):
        register("housner")

    @dataclass(frozen=True)
    class Foreign(RestitutionLaw):
        name = "foreign-impact"
        impact = staticmethod(lambda speed, e, shape: (e, e))

        def coefficient(self, thc, e=None):
            return 0.5

    with pytest.raises(ValueError, match="define such a law in a module of rockjit.laws"):
        register(Foreign())
    assert "foreign-impact" not in laws.names()


@dataclass(frozen=True)
class ScaledHousner(RestitutionLaw):
    """Housner's coefficient times a measured factor: a law a user writes in a few lines."""

    factor: float = 0.9
    name = "scaled-housner-test"
    label = "Housner, scaled"
    colour = "#E69F00"
    line = dict(color="k", ls=(0, (1, 1)), marker="P")

    def coefficient(self, thc, e=None):
        return self.factor * (1.0 - 1.5 * math.cos(thc) ** 2)


@pytest.fixture
def scaled():
    """The user's law registered for one test, and taken out of the registry after it."""
    yield register(ScaledHousner(factor=0.9))
    laws.unregister(ScaledHousner.name)
    assert ScaledHousner.name not in laws.names()


def test_a_law_a_user_registers_runs_as_the_constant_law_with_its_coefficient(scaled):
    assert style.LAW_NAMES["scaled-housner-test"] == "Housner, scaled"  # the live table
    b = Block(1.0, "scaled-housner-test")
    e = 0.9 * (1.0 - 1.5 * math.cos(math.atan(1.0)) ** 2)
    assert b.restitution == pytest.approx(e, rel=1e-15)
    f = Harmonic(alpha=0.6, omega=1.3)
    it = Integration(periods=30)
    got = rockjit.simulate(b, f, integration=it, lyapunov=True)
    ref = rockjit.simulate(Block(1.0, e=b.restitution), f, integration=it, lyapunov=True)
    assert got.n_impacts == ref.n_impacts > 10
    np.testing.assert_array_equal(got.strobe, ref.strobe)
    np.testing.assert_array_equal(got.impacts, ref.impacts)
    np.testing.assert_array_equal(got.lyapunov, ref.lyapunov)
