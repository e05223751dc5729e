"""The visual language: one colour per behaviour that colour-blind readers tell apart, attractors
named by what they are, tints that stay within their behaviour's hue, styles that come and go.

The colour-vision check simulates deuteranopia, protanopia and tritanopia at full severity
(colorspacious, Machado et al. 2009) and measures every pair of behaviour colours in CAM02-UCS,
where a distance of about 10 is a clearly visible difference; the palette this one replaced put
asymmetric and chaotic 5.2 apart under deuteranopia.
"""

import numpy as np
import pytest

from rockjit.plotting import style
from rockjit.result import BEHAVIOURS

pytest.importorskip("colorspacious")

#: The smallest CAM02-UCS distance allowed between two behaviour colours, in every condition.
MIN_DISTANCE = 15.0


def test_every_behaviour_has_one_colour():
    assert list(style.BEHAVIOUR_COLOURS) == list(BEHAVIOURS)
    assert len(set(style.BEHAVIOUR_COLOURS.values())) == len(BEHAVIOURS)
    # the agreement map's two colours are no behaviour's
    assert {style.AGREE_COLOUR, style.DISAGREE_COLOUR}.isdisjoint(
        style.BEHAVIOUR_COLOURS.values())


def test_behaviour_colours_stay_apart_under_colour_blindness():
    d = style.cvd_distances()
    assert set(d) == {"normal", "deuteranomaly", "protanomaly", "tritanomaly"}
    for cond, (dist, a, b) in d.items():
        assert dist >= MIN_DISTANCE, f"{a} and {b} are {dist:.1f} apart under {cond}"
    # the check itself sees a palette that fails: red and green under deuteranopia
    bad = style.cvd_distances({"a": "#2ca02c", "b": "#d62728"})
    assert bad["deuteranomaly"][0] < 10 < bad["normal"][0]


def test_attractors_are_named_by_what_they_are():
    rocking = dict(behaviour="symmetric", period=1, multipliers=[[0.1, 0.3], [0.1, -0.3]])
    resting = dict(behaviour="symmetric", period=1, multipliers=[[0.0, 0.0], [0.0, 0.0]])
    names = style.attractor_names([rocking, resting, dict(behaviour="multiperiodic", period=3),
                                   dict(behaviour="chaotic", period=0), dict(behaviour="rest",
                                                                             period=0)])
    assert names == ["symmetric rocking $p = 1$", "symmetric through rest $p = 1$", "period-3",
                     "chaotic", "rest"]
    assert not any(ch.isdigit() and "p = " not in n and "period" not in n
                   for n in names for ch in n)  # no internal id anywhere
    twins = style.attractor_names([dict(behaviour="asymmetric", period=1)] * 2)
    assert twins == ["asymmetric $p = 1$, I", "asymmetric $p = 1$, II"]


def test_attractor_tints_keep_their_behaviours_hue():
    from matplotlib.colors import rgb_to_hsv, to_rgb
    atts = [dict(behaviour="symmetric", period=1, multipliers=[[0.1, 0.3]] * 2),
            dict(behaviour="symmetric", period=1, multipliers=[[0.0, 0.0]] * 2),
            dict(behaviour="symmetric", period=1, multipliers=[[0.2, 0.1]] * 2)]
    cols = style.attractor_colours(atts)
    assert cols[0] == style.BEHAVIOUR_COLOURS["symmetric"].lower()
    assert len(set(cols)) == 3
    hue = rgb_to_hsv(to_rgb(style.BEHAVIOUR_COLOURS["symmetric"]))[0]
    for c in cols:
        assert rgb_to_hsv(to_rgb(c))[0] == pytest.approx(hue, abs=0.02)
    # the orbit through rest is lighter than the rocking ones
    light = [np.mean(to_rgb(c)) for c in cols]
    assert light[1] > light[0] and light[1] > light[2]


def test_styles():
    with style.use("paper") as st:
        assert st.double == 7.2 and not style.current().suptitles
        import matplotlib
        assert matplotlib.rcParams["font.size"] == 8.0
    assert style.current().name == "default"
    with pytest.raises(ValueError, match="style"):
        with style.use("poster"):
            pass
