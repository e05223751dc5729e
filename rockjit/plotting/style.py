"""One visual language for every figure rockjit draws: colours, names, symbols, sizes.

Colour carries one meaning everywhere: the *behaviour* of a run or a cell
(docs/theory/behaviours.md). The eight behaviour colours are Paul Tol's (the "bright" and
"muted" qualitative schemes, https://personal.sron.nl/~pault/) with two greys for the outcomes
without motion, chosen so that every pair stays apart for readers with a colour-vision
deficiency: simulated with ``colorspacious`` (Machado et al. 2009, severity 100) and measured in
CAM02-UCS, the closest pair is 25.8 apart with normal vision, 17.3 under deuteranopia, 17.2
under protanopia and 17.7 under tritanopia (:func:`cvd_distances` recomputes it;
``tests/plotting/test_style.py`` keeps it above 15). The palette they replace put green (asymmetric) and
red (chaotic) 5.2 apart under deuteranopia, and green and orange (multiperiodic) 1.6 apart under
protanopia.

- An *attractor* is drawn in a tint of its behaviour's colour (:func:`attractor_colours`) and
  named by what it is (:func:`attractor_names`): "symmetric rocking p=1", "symmetric through
  rest p=1", "period-3", never by an internal id.
- The two restitution laws are told apart by line style and marker (:data:`LAW_LINES`), in
  black, so that no hue means two things; where both laws' runs are shown, each run keeps its
  behaviour's colour.
- Cells where the laws disagree are black, cells where they agree white
  (:data:`DISAGREE_COLOUR`, :data:`AGREE_COLOUR`); no behaviour is either.
- Symbols are mathtext (:data:`SYMBOLS`); panels are lettered a), b), c) as in the study
  (:func:`letter`).

Two styles (:func:`use`), both sized for a journal's column (3.5 in) or page (7.2 in) with
7-9 pt type (:data:`WIDTHS`, :data:`TEXT_POINTS`): ``"default"`` (figure titles, 200 dpi) and
``"paper"`` (no figure titles, the journal's caption replaces them; 300 dpi).
A figure function reads the style in force when it is called (:func:`current`); save it
inside the same :func:`use` block.
"""

from __future__ import annotations

import contextlib
import contextvars
import itertools
from dataclasses import dataclass, field

import numpy as np

from .. import laws
from .legibility import TEXT_POINTS, WIDTHS

__all__ = ["AGREE_COLOUR", "BEHAVIOUR_COLOURS", "DISAGREE_COLOUR", "FORMATS", "LAW_COLOURS",
           "LAW_LINES", "LAW_NAMES", "STYLES", "SYMBOLS", "Style", "TEXT_POINTS", "WIDTHS",
           "attractor_colours", "attractor_names", "behaviour_cmap", "current", "cvd_distances", "figure", "law_name", "letter", "shade",
           "styled", "suptitle", "tint", "use", "variant"]

#: One colour per behaviour (rockjit.result.BEHAVIOURS), in every figure and command.
BEHAVIOUR_COLOURS = {
    "overturn": "#555555",       # dark grey: the block fell
    "rest": "#DDDDDD",           # pale grey: the block stopped
    "symmetric": "#332288",      # Tol muted indigo
    "asymmetric": "#66CCEE",     # Tol bright cyan
    "multiperiodic": "#228833",  # Tol bright green
    "chaotic": "#EE6677",        # Tol bright red
    "aperiodic": "#AA4499",      # Tol muted purple
    "unresolved": "#CCBB44",     # Tol bright yellow
}
#: The two laws' point-wise comparison of two maps.
AGREE_COLOUR = "#FFFFFF"
DISAGREE_COLOUR = "#000000"

#: The laws' names, their lines where two laws share an axis (black: colour is behaviour), and
#: their colours where a figure shows no behaviour and compares the laws in colour (the
#: ground-motion spectra and fragility curves; Okabe and Ito's palette, apart under every
#: colour-vision deficiency): live views of the one table, the laws' own (rockjit.laws).
LAW_NAMES = laws.Table("label")
LAW_LINES = laws.Table("line")
LAW_COLOURS = laws.Table("colour")

#: Mathtext of the quantities on the axes.
SYMBOLS = {"theta": r"$\theta$", "dtheta": r"$\theta'$", "theta0": r"$\theta_0$",
           "dtheta0": r"$\theta'_0$", "alpha": r"$\alpha$", "omega": r"$\omega$",
           "t": r"$t$", "lambda_max": r"$\lambda_\mathrm{max}$", "lambda1": r"$\lambda_1$",
           "thc": r"$\theta_c$", "hb": r"$h/b$", "e_H": r"$e_H$", "e_M": r"$e_M$",
           "delta_e": r"$\Delta e$", "strobe": r"$\theta'(kT)$", "strobe_theta": r"$\theta(kT)$",
           "S_b": r"$S_b$", "S_bb": r"$S_{bb}$",
           # with their units: the model's time is dimensionless (unit sqrt(R/g)), and so is
           # the angular velocity theta' = d theta / dt
           "t_unit": r"$t$ (dimensionless, unit $\sqrt{R/g}$)", "theta_unit": r"$\theta$ [rad]",
           "dtheta_unit": r"$\theta'$ (dimensionless)"}

#: Figure formats every command can write.
FORMATS = ("png", "pdf", "svg")


# ---------------------------------------------------------------------------------------------
# styles
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Style:
    """Sizes and decorations of the figures.

    Attributes
    ----------
    name : str
    suptitles : bool
        Figure titles above the panels (a journal sets its own caption instead).
    single, double : float
        Widths, in inches, of a figure one and two columns wide.
    scale : float
        Heights relative to the default style's (the paper's panels are proportioned alike).
    rc : dict
        Matplotlib settings in force while a figure is drawn and saved.
    """

    name: str
    suptitles: bool
    single: float
    double: float
    scale: float
    rc: dict = field(default_factory=dict)

    def size(self, width, aspect):
        """``(w, h)``: ``width`` ``"single"``, ``"double"`` or a fraction of the double width,
        ``h = aspect * w``. A fraction is rounded to the column or the page, whichever is
        nearer (a journal has no other width)."""
        w = {"single": self.single, "double": self.double}.get(width)
        if w is None:
            want = self.double * float(width)
            w = self.single if abs(want - self.single) <= abs(want - self.double) else \
                self.double
        return (w, aspect * w)


_COMMON_RC = {"axes.titlesize": "medium", "legend.frameon": False, "axes.spines.top": True,
              "font.size": 8.0, "legend.fontsize": 7.0, "legend.title_fontsize": 7.0,
              "legend.handlelength": 3.0,
              "axes.labelsize": 8.0, "xtick.labelsize": 7.0, "ytick.labelsize": 7.0,
              "figure.titlesize": 9.0, "axes.linewidth": 0.6, "lines.linewidth": 1.0,
              "xtick.major.width": 0.6, "ytick.major.width": 0.6,
              "pdf.fonttype": 42, "svg.fonttype": "none"}
STYLES = {
    "default": Style("default", True, 3.5, 7.2, 1.0, {**_COMMON_RC, "savefig.dpi": 200}),
    "paper": Style("paper", False, 3.5, 7.2, 1.0, {**_COMMON_RC, "savefig.dpi": 300}),
}
_CURRENT = contextvars.ContextVar("rockjit_style", default=STYLES["default"])


def current() -> Style:
    """The style in force (:func:`use`), ``"default"`` outside any."""
    return _CURRENT.get()


@contextlib.contextmanager
def use(name="default"):
    """Draw (and save) figures in style ``name`` within the block.

    Examples
    --------
    >>> from rockjit.plotting import style
    >>> with style.use("paper") as s:
    ...     s.double, style.current().suptitles
    (7.2, False)
    >>> style.current().name
    'default'
    """
    if isinstance(name, Style):
        st = name
    elif name in STYLES:
        st = STYLES[name]
    else:
        raise ValueError(f"style must be one of {', '.join(STYLES)} (got {name!r})")
    import logging

    import matplotlib
    # embedding TrueType fonts in a PDF (pdf.fonttype 42, what journals ask for) subsets them
    # with fontTools, which logs a warning about DejaVu's build date on every figure
    logging.getLogger("fontTools").setLevel(logging.ERROR)
    token = _CURRENT.set(st)
    try:
        with matplotlib.rc_context(st.rc):
            yield st
    finally:
        _CURRENT.reset(token)


def styled(fn):
    """Decorate a figure function so that it draws in the style in force (:func:`current`)
    whether or not it is called within :func:`use`: its type sizes, line widths and legends
    are the style's, not matplotlib's defaults, and so are the tick labels matplotlib makes
    when the figure is drawn."""
    import functools

    @functools.wraps(fn)
    def drawn_in_style(*args, **kwargs):
        import matplotlib
        st = current()
        with matplotlib.rc_context(st.rc):
            fig = fn(*args, **kwargs)
            for ax in fig.get_axes():
                for axis in ("x", "y"):
                    size = st.rc.get(f"{axis}tick.labelsize")
                    if size is not None:
                        ax.tick_params(axis=axis, which="both", labelsize=size)
        return fig
    return drawn_in_style


def figure(width, aspect, pad=(0.04, 0.04)):
    """A figure without pyplot, a journal's column (``"single"``) or page (``"double"``) wide in
    the style in force (:meth:`Style.size`), laid out by constrained layout with ``pad =
    (w_pad, h_pad)`` inches around each axes (``None``: matplotlib's defaults)."""
    from matplotlib.figure import Figure
    from matplotlib.layout_engine import ConstrainedLayoutEngine
    size = current().size(width, aspect)
    if pad is None:
        return Figure(figsize=size, layout="constrained")
    return Figure(figsize=size, layout=ConstrainedLayoutEngine(w_pad=pad[0], h_pad=pad[1]))


def suptitle(fig, text, **kw):
    """The figure's title, in the styles that draw one."""
    if text and current().suptitles:
        fig.suptitle(text, **kw)


def letter(ax, i, text=None):
    """Panel letter ``a)``, ``b)``, ... (``i`` from 0) at the axes' top left, with an optional
    title beside it."""
    lab = f"{'abcdefghijklmnopqrstuvwxyz'[i]})"
    ax.set_title(lab if not text else f"{lab} {text}", loc="left", fontweight="normal")


def law_name(block):
    """The law of a block in words (a constant law with its value)."""
    if block.law == "constant":
        return f"constant $e = {block.restitution:g}$"
    return LAW_NAMES.get(block.law, block.law)


# ---------------------------------------------------------------------------------------------
# colours
# ---------------------------------------------------------------------------------------------

def _rgb(colour):
    from matplotlib.colors import to_rgb
    return np.asarray(to_rgb(colour))


def tint(colour, amount):
    """``colour`` mixed with white (``amount`` 0: the colour, 1: white) as a hex string."""
    from matplotlib.colors import to_hex
    return to_hex(_rgb(colour) + (1.0 - _rgb(colour)) * float(amount))


def shade(colour, amount):
    """``colour`` mixed with black (``amount`` 0: the colour, 1: black) as a hex string."""
    from matplotlib.colors import to_hex
    return to_hex(_rgb(colour) * (1.0 - float(amount)))


#: The variants of an attractor's colour, by kind: orbits that rock in the behaviour's colour
#: and darker shades, orbits through rest (and small attractors) in lighter tints.
_DARK = (("tint", 0.0), ("shade", 0.45), ("shade", 0.7), ("tint", 0.25), ("shade", 0.25))
_LIGHT = (("tint", 0.5), ("tint", 0.7), ("tint", 0.35), ("tint", 0.6))


def variant(colour, k, light=False):
    """The ``k``-th variant of ``colour``: ``k = 0`` the colour itself, then darker shades
    (``light``: lighter tints, from the first)."""
    kinds = _LIGHT if light else _DARK
    kind, amount = kinds[k % len(kinds)]
    return tint(colour, amount) if kind == "tint" else shade(colour, amount)


def behaviour_cmap():
    """``(cmap, norm)`` of the behaviour codes (an image of labels)."""
    from matplotlib.colors import BoundaryNorm, ListedColormap

    from ..result import BEHAVIOURS
    cmap = ListedColormap([BEHAVIOUR_COLOURS[n] for n in BEHAVIOURS])
    return cmap, BoundaryNorm(np.arange(len(BEHAVIOURS) + 1) - 0.5, cmap.N)


def _get(a, name):
    return a.get(name) if isinstance(a, dict) else getattr(a, name, None)


def _through_rest(a):
    """An orbit whose monodromy is zero (it comes to rest once a cycle); None when unknown."""
    mu = _get(a, "multipliers")
    if mu is None:
        return None
    mu = np.asarray(mu, dtype=float if isinstance(a, dict) else complex)
    return bool(np.all(mu == 0))


def attractor_colours(attractors):
    """One colour per attractor (in order): the first attractor of a behaviour that rocks gets
    its behaviour's colour, the next ones darker shades; an orbit through rest (Floquet
    multipliers zero) gets a light tint. ``attractors`` are
    :class:`rockjit.grids.identity.Attractor` or erosion branches (dicts)."""
    seen = {}
    out = []
    for a in attractors:
        b = _get(a, "behaviour")
        light = bool(_through_rest(a))
        k = seen.get((b, light), 0)
        seen[(b, light)] = k + 1
        out.append(variant(BEHAVIOUR_COLOURS.get(b, "#999999"), k, light))
    return out


def _base_name(a):
    b, p = _get(a, "behaviour"), int(_get(a, "period") or 0)
    rest = _through_rest(a)
    how = "" if rest is None else (" through rest" if rest else " rocking")
    if b in ("symmetric", "asymmetric"):
        return f"{b}{how} $p = {p}$"
    if b == "multiperiodic":
        return f"period-{p}" + (" through rest" if rest else "")
    return b


def attractor_names(attractors):
    """What each attractor is, in words: its behaviour, whether it rocks or passes through rest
    once a cycle (Floquet multipliers zero), and its period; attractors that would share a
    name are told apart by I, II, III (largest basin first, as they are ordered).

    Examples
    --------
    >>> from rockjit.plotting.style import attractor_names
    >>> attractor_names([dict(behaviour="symmetric", period=1, multipliers=[[0.1, 0.2]] * 2),
    ...                  dict(behaviour="symmetric", period=1, multipliers=[[0, 0]] * 2),
    ...                  dict(behaviour="multiperiodic", period=3, multipliers=None),
    ...                  dict(behaviour="asymmetric", period=1, multipliers=None),
    ...                  dict(behaviour="asymmetric", period=1, multipliers=None)])
    ['symmetric rocking $p = 1$', 'symmetric through rest $p = 1$', 'period-3', 'asymmetric $p = 1$, I', 'asymmetric $p = 1$, II']
    """
    base = [_base_name(a) for a in attractors]
    count = {n: base.count(n) for n in base}
    seen = {}
    out = []
    roman = ("I", "II", "III", "IV", "V", "VI", "VII", "VIII", "IX", "X")
    for n in base:
        if count[n] > 1:
            k = seen.get(n, 0)
            seen[n] = k + 1
            n = f"{n}, {roman[k] if k < len(roman) else k + 1}"
        out.append(n)
    return out


# ---------------------------------------------------------------------------------------------
# checks
# ---------------------------------------------------------------------------------------------

def cvd_distances(colours=None):
    """The closest pair of ``colours`` (default the behaviour colours) in CAM02-UCS, with
    normal vision and under each simulated deficiency (colorspacious, severity 100):
    ``{condition: (distance, name_a, name_b)}``. Needs ``colorspacious``."""
    from colorspacious import cspace_convert
    colours = dict(BEHAVIOUR_COLOURS) if colours is None else dict(colours)
    names = list(colours)
    rgb = np.array([_rgb(c) for c in colours.values()])
    out = {}
    for cond in ("normal", "deuteranomaly", "protanomaly", "tritanomaly"):
        if cond == "normal":
            seen = rgb
        else:
            seen = np.clip(cspace_convert(rgb, {"name": "sRGB1+CVD", "cvd_type": cond,
                                                "severity": 100}, "sRGB1"), 0, 1)
        ucs = cspace_convert(seen, "sRGB1", "CAM02-UCS")
        d, i, j = min((float(np.linalg.norm(ucs[i] - ucs[j])), i, j)
                      for i, j in itertools.combinations(range(len(names)), 2))
        out[cond] = (d, names[i], names[j])
    return out
