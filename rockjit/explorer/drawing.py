"""How the explorer's page draws: the project's colours, maps as RGBA images, the figures'
labels in plain text, numbers and small HTML pieces (status lines, swatches), and the Bokeh
figures' common shape. No state: the panels (:mod:`.basin_panel`, :mod:`.run_panel`,
:mod:`.sweep_panel`, :mod:`.compare_panel`) call these."""

from __future__ import annotations

import html
import math

import numpy as np
from bokeh.plotting import figure

from ..plotting import style

__all__ = ["STALE_ALPHA", "attractor_colours", "behaviour_colours", "dim", "error_html",
           "finite", "fit", "fmt", "image_data", "law_name", "plain_text", "plot",
           "progress_html", "rgba_image", "swatch"]

#: Opacity of a view whose parameters changed and whose new result is not there yet.
STALE_ALPHA = 0.35
#: Mathematical notation of the figures' labels (matplotlib's ``$...$``) in plain text.
_TEX = ((r"\theta", "θ"), (r"\alpha", "α"), (r"\omega", "ω"), (r"\lambda", "λ"),
        (r"\xi", "ξ"), (r"\Delta", "Δ"), (r"\mathrm", ""), ("$", ""), ("{", ""), ("}", ""))


def plain_text(label):
    """A figure's label as plain text for the page: ``'symmetric $p = 1$'`` is
    ``'symmetric p = 1'``."""
    text = str(label)
    for tex, out in _TEX:
        text = text.replace(tex, out)
    return text


def law_name(law):
    """A restitution law's name as the figures write it (:data:`rockjit.plotting.style.LAW_NAMES`),
    in plain text."""
    return plain_text(style.LAW_NAMES.get(law, law))


def finite(*values):
    """Whether every value is a finite number (a browser event may carry None, NaN or ±inf)."""
    try:
        return all(v is not None and math.isfinite(float(v)) for v in values)
    except (TypeError, ValueError):
        return False


def behaviour_colours():
    """The project's behaviour palette (:mod:`rockjit.plotting.style`)."""
    return dict(style.BEHAVIOUR_COLOURS)


def attractor_colours(attractors):
    """Colours of the attractors (by id), as the attractor figures draw them: tints of their
    behaviours' colours."""
    from matplotlib.colors import to_hex
    return [to_hex(c) for c in style.attractor_colours(attractors)] or ["#999999"]


def _rgba(hex_colour):
    h = hex_colour.lstrip("#")
    return int(h[0:2], 16), int(h[2:4], 16), int(h[4:6], 16), 255


def _lut(colours):
    """uint32 RGBA values (little-endian bytes R, G, B, A) of a list of hex colours."""
    a = np.array([_rgba(c) for c in colours], dtype=np.uint8)
    return a.view(np.uint32).ravel()


def rgba_image(codes, colours, offset=0):
    """An RGBA image (rows: theta0', columns: theta0) of a map ``codes[i, j]`` of ``theta0[i],
    theta0'[j]``, colour ``colours[code + offset]``."""
    lut = _lut(colours)
    return np.ascontiguousarray(lut[np.asarray(codes).T + offset])


def image_data(result, img):
    """The data of a Bokeh ``image_rgba`` that draws ``img`` over a basin's lattice, each cell
    centred on its point."""
    th, dth = np.asarray(result.theta0), np.asarray(result.dtheta0)
    dx = (th[-1] - th[0]) / max(th.size - 1, 1)
    dy = (dth[-1] - dth[0]) / max(dth.size - 1, 1)
    return dict(image=[img], x=[th[0] - dx / 2], y=[dth[0] - dy / 2], dw=[th[-1] - th[0] + dx],
                dh=[dth[-1] - dth[0] + dy])


def fmt(v, digits=4):
    """A number for the page: ``digits`` significant digits; ``–`` for None, ``nan``, ``±∞``."""
    if v is None:
        return "–"
    v = float(v)
    if math.isnan(v):
        return "nan"
    if math.isinf(v):
        return "−∞" if v < 0 else "∞"
    return f"{v:.{digits}g}"


def swatch(colour):
    """A small square of ``colour``, for a legend's line."""
    return (f'<span style="display:inline-block;width:11px;height:11px;background:{colour};'
            f'border:1px solid #999;margin-right:5px;vertical-align:middle"></span>')


def progress_html(stage, fraction):
    """A view's status line: its stage and a progress bar."""
    pct = int(round(100 * fraction))
    return (f'<div class="rj-progress" data-stage="{html.escape(stage)}">'
            f'<progress value="{pct}" max="100" style="width:150px;vertical-align:middle">'
            f'</progress> <span style="color:#555">{html.escape(stage)} {pct} %</span></div>')


def error_html(message):
    """A refusal's message, under a control or in a view's status line."""
    return (f'<div class="rj-refused" style="color:#b00020;font-size:12px;max-width:220px;'
            f'white-space:normal">refused: {html.escape(message)}</div>')


def fit(rng, values, pad):
    """Set a Range1d around finite ``values`` (unchanged when there are none)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size:
        lo, hi = float(v.min()), float(v.max())
        d = max(hi - lo, 1e-3) * pad
        rng.start, rng.end = lo - d, hi + d


def dim(figs, stale):
    """Show plots as updating (faded) or current."""
    for f in figs:
        f.styles = {"opacity": str(STALE_ALPHA) if stale else "1"}


def plot(title, width, height, tools="save", x_label=None, y_label=None, toolbar="above",
         **kw):
    """A Bokeh figure as the explorer draws them: its size, tools, axis labels and title."""
    p = figure(title=title, width=width, height=height, tools=tools, toolbar_location=toolbar,
               **kw)
    if x_label:
        p.xaxis.axis_label = x_label
    if y_label:
        p.yaxis.axis_label = y_label
    if p.title is not None:
        p.title.text_font_size = "11pt"
    return p
