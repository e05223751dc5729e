"""What the explorer's views give back: each view's figure as a PNG, drawn by
:mod:`rockjit.plotting.figures` off the page's loop and sent to the browser as a download, and
the Python call that reproduces the view, shown with a button that copies it.

:class:`Exports` is one part of :class:`.app.ExplorerApp`; :func:`png_of` draws a view's PNG
without a page."""

from __future__ import annotations

import base64
import io
import threading

from bokeh.layouts import row
from bokeh.models import Button, CustomJS, PreText

from .drawing import error_html, progress_html

__all__ = ["Exports", "png_of"]


class Exports:
    """The views' PNG and call buttons (a part of :class:`.app.ExplorerApp`)."""

    def _export_row(self, view, width=440):
        png = Button(label="PNG", width=60, css_classes=[f"rj-png-{view}"])
        png.on_click(lambda: self.export_png(view))
        code = PreText(text="", width=width, css_classes=[f"rj-call-{view}"],
                       stylesheets=["pre { white-space: pre-wrap; word-break: break-word; "
                                    "font-size: 11px; background: #f4f4f4; padding: 4px; "
                                    "margin: 2px 0; }"])
        copy = Button(label="copy call", width=80, css_classes=[f"rj-copy-{view}"])
        copy.js_on_click(CustomJS(args=dict(pre=code, btn=copy), code="""
            navigator.clipboard.writeText(pre.text).then(
                () => { btn.label = 'copied'; setTimeout(() => { btn.label = 'copy call'; }, 1500); },
                () => { btn.label = 'select the text'; });
        """))
        return row(png, copy), code

    def export_png(self, view):
        """The view's figure drawn by rockjit.plotting, sent to the browser as a PNG file."""
        shown = {"basin": self.basin_view, "run": self.run_view, "sweep": self.sweep_view,
                 "compare": self.compare_view}[view]
        if shown is None or self.closed:
            return
        if self._drawing:  # one PNG at a time per page
            self._ignored(view, "another PNG is being drawn")
            return
        self._drawing = True
        colour_by = self.colour_by
        self.status[view].text = progress_html("drawing the PNG", 0.0)

        def done(update):
            def later():
                self._drawing = False
                update()
            self.doc.add_next_tick_callback(later)

        def draw():
            try:
                data, name = png_of(view, shown, colour_by)
            except Exception as exc:  # said in the page; the app goes on
                msg = f"{type(exc).__name__}: {exc}"
                done(lambda: setattr(self.status[view], "text", error_html(msg)))
                return

            def send():
                self.download.data = dict(name=[name], b64=[data], mime=["image/png"])
                self.status[view].text = ""
            done(send)
        threading.Thread(target=draw, daemon=True, name="rockjit-explore-png").start()


def png_of(view, shown, colour_by):
    """``(base64 PNG, file name)`` of a view, drawn by :mod:`rockjit.plotting.figures`."""
    from ..plotting import figures as F
    p = shown.params
    if view == "basin":
        fig = F.fig_attractors(shown.result) if colour_by == "attractor" else \
            F.fig_basin(shown.result)
        name = f"basin_{p.law}_hb{p.hb:g}_alpha{p.alpha:g}_omega{p.omega:g}.png"
    elif view == "run":
        fig = F.fig_trajectory(shown.result, (shown.behaviour, shown.period))
        name = f"run_{p.law}_theta{shown.state[0]:.4g}_dtheta{shown.state[1]:.4g}.png"
    elif view == "sweep":
        fig = F.fig_bifurcation(shown.result)
        a0, a1 = p.alpha_range
        name = f"bifurcation_{p.law}_hb{p.hb:g}_omega{p.omega:g}_alpha{a0:g}-{a1:g}.png"
    else:
        fig = F.fig_basin_compare(shown.housner, shown.mao)
        name = f"laws_hb{p.hb:g}_alpha{p.alpha:g}_omega{p.omega:g}.png"
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=120)
    return base64.b64encode(buf.getvalue()).decode("ascii"), name
