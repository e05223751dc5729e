"""Checks of a drawn figure against what a journal's reader needs: its width and type size,
legends that name only what is drawn and tell their entries apart, labels that do not overprint
and legends that do not cover the data.

Each check takes a :class:`matplotlib.figure.Figure`, draws it on an Agg canvas and returns a
list of problems in words (empty when there is none); :func:`problems` runs them all. They
measure what the renderer draws: text extents, the colours of images and meshes as drawn, the
dash pattern a legend handle shows at its length. Colour differences are distances in
CAM02-UCS (``colorspacious``), where about 1 is a just-noticeable difference.
"""

from __future__ import annotations

import itertools

import numpy as np

__all__ = ["LEGEND_DELTA", "TEXT_POINTS", "WIDTHS", "canvas_problems", "colour_distance",
           "legend_colour_problems", "legend_handle_problems", "legend_over_data", "problems",
           "text_outside", "text_overlaps", "texts_outside", "type_problems"]

#: The smallest and largest type a figure may set, in points (a journal's 7-9 pt at print
#: size).
TEXT_POINTS = (7.0, 9.0)
#: The widths a figure may have, in inches: a journal's column and its page.
WIDTHS = (3.5, 7.2)
#: Smallest CAM02-UCS distance between two legend entries that differ in colour only, and
#: between an entry without an edge and the legend's background.
LEGEND_DELTA = 12.0


def _renderer(fig, again=False):
    """The Agg renderer ``fig`` was drawn with (drawn once; ``again`` draws it anew)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    got = getattr(fig, "_legibility_renderer", None)
    if got is not None and not again:
        return got
    canvas = fig.canvas if isinstance(fig.canvas, FigureCanvasAgg) else FigureCanvasAgg(fig)
    canvas.draw()
    fig._legibility_renderer = canvas.get_renderer()
    return fig._legibility_renderer


def colour_distance(a, b):
    """CAM02-UCS distance between two matplotlib colours (alpha ignored)."""
    from colorspacious import cspace_convert
    from matplotlib.colors import to_rgb
    ucs = cspace_convert(np.array([to_rgb(a), to_rgb(b)]), "sRGB1", "CAM02-UCS")
    return float(np.linalg.norm(ucs[0] - ucs[1]))


def canvas_problems(fig, tol=0.02):
    """The figure is a journal's column or page wide (:data:`rockjit.plotting.style.WIDTHS`)."""
    w = fig.get_figwidth()
    if min(abs(w - x) for x in WIDTHS) > tol:
        return [f"canvas {w:.2f} x {fig.get_figheight():.2f} in: not {' or '.join(map(str, WIDTHS))}"
                f" in wide"]
    return []


def _texts(fig, renderer):
    """The visible, non-empty texts drawn, tick labels only where their tick is drawn."""
    from matplotlib.axis import Axis
    from matplotlib.text import Text
    stale = set()
    for axis in fig.findobj(Axis):
        shown = axis.get_visible() and (axis.axes is None or axis.axes.axison)
        drawn = set(axis._update_ticks()) if shown else set()
        for tick in axis.majorTicks + axis.minorTicks:
            if tick not in drawn or not tick.get_visible():
                stale.update((id(tick.label1), id(tick.label2)))
            else:
                for lab in (tick.label1, tick.label2):
                    if not lab.get_visible():
                        stale.add(id(lab))
    out = []
    for t in fig.findobj(Text):
        if id(t) in stale or not t.get_visible() or not t.get_text().strip():
            continue
        if not _shown(t):
            continue
        out.append(t)
    return out


def _shown(artist):
    """The artist and the axes it is drawn in are visible."""
    ax = getattr(artist, "axes", None)
    return artist.get_visible() and (ax is None or ax.get_visible())


def type_problems(fig, lo=TEXT_POINTS[0], hi=TEXT_POINTS[1], tol=0.05):
    """Every text is set between ``lo`` and ``hi`` points."""
    r = _renderer(fig)
    bad = []
    for t in _texts(fig, r):
        size = t.get_fontsize()
        if size < lo - tol or size > hi + tol:
            bad.append(f"text {t.get_text()[:40]!r} at {size:.1f} pt (not {lo:g}-{hi:g})")
    return bad


def text_overlaps(fig, min_px=4.0):
    """Pairs of texts whose drawn extents overlap by more than ``min_px`` pixels both ways."""
    r = _renderer(fig)
    texts = _texts(fig, r)
    boxes = [t.get_window_extent(r) for t in texts]
    bad = []
    for (i, a), (j, b) in itertools.combinations(enumerate(boxes), 2):
        w = min(a.x1, b.x1) - max(a.x0, b.x0)
        h = min(a.y1, b.y1) - max(a.y0, b.y0)
        if w > min_px and h > min_px:
            bad.append(f"{texts[i].get_text()[:30]!r} overprints {texts[j].get_text()[:30]!r}")
    return bad


# ---------------------------------------------------------------------------------------------
# legends
# ---------------------------------------------------------------------------------------------

def _legends(fig):
    out = list(fig.legends)
    for ax in fig.get_axes():
        if ax.get_legend() is not None:
            out.append(ax.get_legend())
    for sub in getattr(fig, "subfigs", []):
        out += _legends(sub)
    return [lg for lg in out if lg.get_visible()]


def _hex(c):
    from matplotlib.colors import to_hex
    return to_hex(c, keep_alpha=False)


def _visible_rgba(c):
    from matplotlib.colors import to_rgba
    try:
        rgba = to_rgba(c)
    except (ValueError, TypeError):
        return None
    return None if rgba[3] == 0 else rgba


def _has_line(line):
    return line.get_linestyle() not in ("None", "none", "", " ") and line.get_linewidth() > 0


def _has_marker(line):
    return line.get_marker() not in (None, "None", "none", "", " ") and line.get_markersize() > 0


def _in_view(ax, x, y):
    """Which points ``(x, y)`` in data coordinates lie inside the axes' view."""
    x0, x1 = sorted(ax.get_xlim())
    y0, y1 = sorted(ax.get_ylim())
    x, y = np.asarray(x, float), np.asarray(y, float)
    return (x >= x0) & (x <= x1) & (y >= y0) & (y <= y1)


def _drawn(fig):
    """What the axes of ``fig`` draw within their view: ``lines`` (colour) of visible lines,
    ``marks`` (marker path key, colour) of markers and scatter points, ``fills`` (colour) of
    patches, collections' faces and the colours of images and meshes as drawn."""
    from matplotlib.collections import Collection, PathCollection, QuadMesh
    from matplotlib.image import AxesImage
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    lines, marks, fills = set(), set(), set()
    dashes, hatches = set(), set()
    for ax in fig.get_axes():
        if not ax.get_visible():
            continue
        spines = set(ax.spines.values())
        for a in ax.get_children():
            # the axes' frame (its background and spines) is drawn whatever the data
            if not a.get_visible() or a is ax.patch or a is ax.get_legend() or a in spines:
                continue
            if isinstance(a, Line2D):
                x, y = a.get_data()
                if len(x) == 0:
                    continue
                if a.get_transform() == ax.transData:
                    inside = _in_view(ax, np.asarray(x, float), np.asarray(y, float))
                    if not inside.any():
                        continue
                if _has_line(a):
                    lines.add(_hex(a.get_color()))
                    dashes.add(_dash(a))
                if _has_marker(a):
                    for c in (a.get_markerfacecolor(), a.get_markeredgecolor()):
                        if _visible_rgba(c) is not None:
                            marks.add((_marker_key(a.get_marker()), _hex(c)))
            elif isinstance(a, AxesImage):
                arr = a.get_array()
                if arr is None:
                    continue
                rgba = a.to_rgba(np.ma.masked_invalid(np.asarray(arr, float)), bytes=True)
                px = np.unique(rgba.reshape(-1, 4)[:, :3], axis=0)
                fills.update(_hex(p / 255.0) for p in px)
            elif isinstance(a, QuadMesh):
                arr = a.get_array()
                if arr is not None and a.get_cmap() is not None and np.size(arr):
                    rgba = a.to_rgba(np.ma.masked_invalid(np.asarray(arr, float)).ravel(),
                                     bytes=True)
                    rgba = rgba[rgba[:, 3] > 0]
                    fills.update(_hex(p[:3] / 255.0) for p in np.unique(rgba, axis=0))
                else:
                    fills.update(_hex(c) for c in a.get_facecolors())
            elif isinstance(a, PathCollection):
                off = np.asarray(a.get_offsets(), float).reshape(-1, 2)
                if a.get_offset_transform() == ax.transData and off.size:
                    if not _in_view(ax, off[:, 0], off[:, 1]).any():
                        continue
                key = _path_key(a.get_paths()[0]) if a.get_paths() else None
                for c in list(a.get_facecolors()) + list(a.get_edgecolors()):
                    if c[3] > 0:
                        marks.add((key, _hex(c)))
            elif isinstance(a, Collection):
                # a filled contour keeps one hatch per level in ``hatches``
                hatches.update(h for h in [a.get_hatch(), *getattr(a, "hatches", [])] if h)
                for c in a.get_facecolors():
                    if c[3] > 0:
                        fills.add(_hex(c))
                for c in a.get_edgecolors():
                    if c[3] > 0 and np.max(a.get_linewidths(), initial=0) > 0:
                        lines.add(_hex(c))
            elif isinstance(a, Patch):
                if a.get_hatch():
                    hatches.add(a.get_hatch())
                if a.get_fill() and _visible_rgba(a.get_facecolor()) is not None:
                    fills.add(_hex(a.get_facecolor()))
                if a.get_linewidth() > 0 and _visible_rgba(a.get_edgecolor()) is not None:
                    lines.add(_hex(a.get_edgecolor()))
    return dict(lines=lines, marks=marks, fills=fills, dashes=dashes, hatches=hatches)


def _dash(line):
    """A line's dash pattern as drawn (``None``: solid)."""
    off, seq = line._dash_pattern
    return tuple(np.round(np.asarray(seq, float) / max(line.get_linewidth(), 1e-9), 2)) \
        if seq else None


def _neutral(c):
    """A grey or black: a legend's key to a line style or marker shape, in any colour."""
    from matplotlib.colors import to_rgb
    r, g, b = to_rgb(c)
    return max(r, g, b) - min(r, g, b) < 0.02


def _path_key(path):
    return tuple(np.round(np.asarray(path.vertices, float), 3).ravel())


def _marker_key(marker):
    from matplotlib.markers import MarkerStyle
    ms = MarkerStyle(marker)
    return _path_key(ms.get_path().transformed(ms.get_transform()))


def _ucs(colours):
    from colorspacious import cspace_convert
    from matplotlib.colors import to_rgb
    return cspace_convert(np.array([to_rgb(c) for c in colours]).reshape(-1, 3), "sRGB1",
                          "CAM02-UCS")


def _near(colour, pool, tol=3.0):
    """``colour`` is within ``tol`` of a colour of ``pool`` (a set of hex strings)."""
    if colour in pool:
        return True
    if not pool:
        return False
    d = np.linalg.norm(_ucs(list(pool)) - _ucs([colour])[0], axis=1)
    return bool(d.min() <= tol)


def _entries(legend):
    """``[(label, handle)]`` of a legend (its drawn handles and their texts)."""
    return [(t.get_text(), h) for t, h in zip(legend.get_texts(), legend.legend_handles)]


def _entry_colour(h):
    """The colour a reader sees of a legend handle."""
    from matplotlib.collections import Collection
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    if isinstance(h, Line2D):
        if _has_line(h):
            return _hex(h.get_color())
        face = _visible_rgba(h.get_markerfacecolor())
        return _hex(face if face is not None else h.get_markeredgecolor())
    if isinstance(h, Patch):
        return _hex(h.get_facecolor()) if h.get_fill() else _hex(h.get_edgecolor())
    if isinstance(h, Collection) and len(h.get_facecolors()):
        return _hex(h.get_facecolors()[0])
    return None


def _entry_form(h):
    """What besides colour tells an entry apart: its line's dash pattern as drawn, its marker,
    whether it is a filled area."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    if isinstance(h, Line2D):
        dash = None
        if _has_line(h):
            off, seq = h._dash_pattern
            dash = tuple(np.round(seq, 1)) if seq else None
        return ("line" if _has_line(h) else "", dash,
                _marker_key(h.get_marker()) if _has_marker(h) else None)
    if isinstance(h, Patch):
        return ("fill", h.get_hatch())
    return (type(h).__name__,)


def legend_handle_problems(fig):
    """Every legend entry shows something (a line, a marker, or an area that stands out from
    the legend's background or has an edge), names something drawn in the figure's view (a
    line, marker or area of its colour), and a dashed entry shows its dashes at the handle's
    length."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch
    _renderer(fig)
    drawn = _drawn(fig)
    bad = []
    for lg in _legends(fig):
        bg = lg.get_frame().get_facecolor() if lg.get_frame_on() else "white"
        handle_pt = lg.handlelength * lg._fontsize
        for label, h in _entries(lg):
            if isinstance(h, Line2D):
                if not (_has_line(h) or _has_marker(h)):
                    bad.append(f"legend entry {label!r} draws nothing")
                    continue
                ok = False
                if _has_line(h):
                    ok = _near(_hex(h.get_color()), drawn["lines"]) or (
                        _neutral(h.get_color()) and _dash(h) in drawn["dashes"])
                    off, seq = h._dash_pattern
                    if seq and sum(seq) > handle_pt / 2:
                        bad.append(f"legend entry {label!r}: its dash pattern ({sum(seq):.0f} "
                                   f"pt) does not show in a {handle_pt:.0f} pt handle")
                if _has_marker(h) and not ok:
                    key = _marker_key(h.get_marker())
                    cols = [c for c in (h.get_markerfacecolor(), h.get_markeredgecolor())
                            if _visible_rgba(c) is not None]
                    same = {col for k, col in drawn["marks"] if k == key}
                    ok = any(_near(_hex(c), same) for c in cols) or (
                        bool(same) and all(_neutral(c) for c in cols))
                if not ok:
                    bad.append(f"legend entry {label!r} names nothing drawn")
            elif isinstance(h, Patch):
                face = _hex(h.get_facecolor()) if h.get_fill() else None
                edge = h.get_linewidth() > 0 and _visible_rgba(h.get_edgecolor()) is not None \
                    and colour_distance(h.get_edgecolor(), bg) > LEGEND_DELTA
                hatch = h.get_hatch()
                if face is None or (not edge and colour_distance(face, bg) < LEGEND_DELTA):
                    bad.append(f"legend entry {label!r} is not seen on the legend's background")
                elif hatch and hatch not in drawn["hatches"]:
                    bad.append(f"legend entry {label!r}: its hatching is drawn nowhere")
                elif not hatch and not _near(face, drawn["fills"]):
                    bad.append(f"legend entry {label!r} names nothing drawn")
                elif hatch and not _near(face, drawn["fills"] | {_hex(bg)}):
                    bad.append(f"legend entry {label!r} names nothing drawn")
    return bad


def legend_colour_problems(fig, delta=LEGEND_DELTA):
    """No two entries of one legend that differ only in colour are closer than ``delta``."""
    _renderer(fig)
    bad = []
    for lg in _legends(fig):
        entries = [(lab, _entry_colour(h), _entry_form(h)) for lab, h in _entries(lg)]
        for (la, ca, fa), (lb, cb, fb) in itertools.combinations(entries, 2):
            if ca is None or cb is None or fa != fb:
                continue
            d = colour_distance(ca, cb)
            if d < delta:
                bad.append(f"legend entries {la!r} and {lb!r} differ by colour only, "
                           f"{d:.1f} apart")
    return bad


def legend_over_data(fig):
    """No legend drawn inside an axes covers its images or meshes, or crosses its lines or
    points (reference lines drawn in axes coordinates aside)."""
    from matplotlib.collections import PathCollection, QuadMesh
    from matplotlib.image import AxesImage
    from matplotlib.lines import Line2D
    r = _renderer(fig)
    bad = []
    for ax in fig.get_axes():
        lg = ax.get_legend()
        if lg is None or not lg.get_visible():
            continue
        box = lg.get_window_extent(r)
        axbox = ax.get_window_extent(r)
        if not box.overlaps(axbox):
            continue
        box = box.shrunk(0.98, 0.98)
        for a in ax.get_children():
            if not a.get_visible():
                continue
            hit = False
            if isinstance(a, (AxesImage, QuadMesh)):
                ext = a.get_window_extent(r).intersection(a.get_window_extent(r), axbox)
                hit = ext is not None and box.overlaps(ext)
            elif isinstance(a, Line2D) and len(a.get_xdata()) and \
                    a.get_transform() == ax.transData:
                path = a.get_transform().transform_path(a.get_path())
                hit = path.intersects_bbox(box, filled=False) if _has_line(a) else \
                    bool(box.count_contains(path.vertices))
            elif isinstance(a, PathCollection) and a.get_offset_transform() == ax.transData:
                off = a.get_offset_transform().transform(np.asarray(a.get_offsets(), float))
                hit = bool(box.count_contains(off))
            if hit:
                bad.append(f"the legend of {ax.get_title(loc='left') or ax.get_title()!r} "
                           f"covers data ({type(a).__name__})")
                break
    return bad


def texts_outside(fig, tol=1.0):
    """The visible, non-empty text artists of ``fig`` whose drawn extent leaves the figure's
    canvas (by more than ``tol`` pixels): ``[(text, extent)]``; empty when all fit. Tick labels
    count only where a tick is drawn (within the axis' view). The figure is drawn anew."""
    renderer = _renderer(fig, again=True)
    W, H = fig.bbox.width, fig.bbox.height
    bad = []
    for t in _texts(fig, renderer):
        bb = t.get_window_extent(renderer)
        if bb.x0 < -tol or bb.y0 < -tol or bb.x1 > W + tol or bb.y1 > H + tol:
            bad.append((t.get_text(), tuple(round(v, 1) for v in bb.extents)))
    return bad


def text_outside(fig):
    """Every text lies on the canvas (:func:`texts_outside`)."""
    return [f"text {t[:40]!r} leaves the canvas" for t, _ in texts_outside(fig)]


def problems(fig):
    """Every check's problems together."""
    _renderer(fig, again=True)
    return (canvas_problems(fig) + type_problems(fig) + text_outside(fig) + text_overlaps(fig)
            + legend_handle_problems(fig) + legend_colour_problems(fig) + legend_over_data(fig))
