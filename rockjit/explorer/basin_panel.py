"""The explorer's basin panel: the basin image (coloured by behaviour or by attractor), its
behaviours, attractors and measures, and a click on a cell, which selects that cell's run.

:class:`BasinPanel` is one part of :class:`.app.ExplorerApp` (which holds the parameters, the
status lines and the worker it uses)."""

from __future__ import annotations

import html

import numpy as np
from bokeh.events import Tap
from bokeh.layouts import column, row
from bokeh.models import ColumnDataSource, Div, RadioButtonGroup, Range1d

from ..plotting import style
from ..result import BEHAVIOURS
from . import requests as R
from .drawing import (attractor_colours, behaviour_colours, dim, finite, fmt, image_data,
                      law_name, plain_text, plot, rgba_image, swatch)

__all__ = ["BASIN_SIZE", "BasinPanel"]

BASIN_SIZE = 400


class BasinPanel:
    """The basin's widgets, drawing and clicks (a part of :class:`.app.ExplorerApp`)."""

    def _build_basin(self):
        p = plot("basin", BASIN_SIZE + 40, BASIN_SIZE + 40, tools="tap,box_zoom,wheel_zoom,reset,save",
                 x_label="θ₀", y_label="θ₀′", x_range=Range1d(-1, 1), y_range=Range1d(-1, 1),
                 name="basin", toolbar="below")
        p.toolbar.active_drag = None
        self.basin_src = ColumnDataSource(data=dict(image=[], x=[], y=[], dw=[], dh=[]))
        self.basin_img = p.image_rgba(image="image", x="x", y="y", dw="dw", dh="dh",
                                      source=self.basin_src)
        self.cycle_src = ColumnDataSource(data=dict(x=[], y=[], c=[]))
        p.scatter("x", "y", source=self.cycle_src, marker="star", size=14, fill_color="c",
                  line_color="black")
        self.cell_src = ColumnDataSource(data=dict(x=[], y=[], w=[], h=[]))
        p.rect("x", "y", "w", "h", source=self.cell_src, fill_alpha=0, line_color="black",
               line_width=2)
        p.scatter("x", "y", source=self.cell_src, marker="circle", size=16, fill_alpha=0,
                  line_color="white", line_width=3)
        p.scatter("x", "y", source=self.cell_src, marker="circle", size=16, fill_alpha=0,
                  line_color="black", line_width=1.5)
        p.on_event(Tap, self._basin_tap)
        self.basin_fig = p
        mode = RadioButtonGroup(labels=["behaviour", "attractor"], active=0, width=200,
                                css_classes=["rj-colour-by"])
        mode.on_change("active", lambda attr, old, new: self._colour_by(new))
        self.basin_info = Div(text="", width=290, css_classes=["rj-basin-info"])
        self.basin_state = Div(text="", css_classes=["rj-basin-state"], width=250, height=20)
        buttons, self.basin_code = self._export_row("basin", width=680)
        side = column(Div(text="<b>colour by</b>"), mode, self.basin_state, self.status["basin"],
                      self.basin_info, buttons, width=290)
        self.basin_panel = column(row(p, side), self.basin_code,
                                  css_classes=["rj-view", "rj-view-basin"])

    def _colour_by(self, active):
        self.colour_by = ("behaviour", "attractor")[active]
        if self.basin_view is not None:
            self._draw_basin(self.basin_view)

    def _draw_basin(self, view):
        res = view.result
        if self.colour_by == "attractor" and res.attractor is not None:
            colours = behaviour_colours()
            lut = [colours["unresolved"], colours["overturn"]] + \
                attractor_colours(res.attractors)
            img = rgba_image(res.attractor, lut, offset=2)
            pts = [(a.points[:, 0], a.points[:, 1], lut[2 + a.id]) for a in res.attractors
                   if a.period]
            self.cycle_src.data = dict(
                x=np.concatenate([q[0] for q in pts]) if pts else [],
                y=np.concatenate([q[1] for q in pts]) if pts else [],
                c=sum(([q[2]] * len(q[0]) for q in pts), []))
        else:
            colours = behaviour_colours()
            img = rgba_image(res.label, [colours[n] for n in BEHAVIOURS])
            self.cycle_src.data = dict(x=[], y=[], c=[])
        self.basin_src.data = image_data(res, img)
        dim([self.basin_fig], False)
        self.basin_info.text = self._basin_info_html(view)

    def _basin_info_html(self, view):
        res, m = view.result, view.measures
        colours = behaviour_colours()
        fr = res.fractions()
        rows = "".join(f"<tr><td>{swatch(colours[n])}{n}</td><td style='text-align:right'>"
                       f"{fr[n]:.1f} %</td></tr>" for n in BEHAVIOURS if fr[n] > 0)
        out = f"<b>behaviours</b><table style='font-size:12px'>{rows}</table>"
        if res.attractor is not None:
            acol = attractor_colours(res.attractors)
            names = style.attractor_names(res.attractors)
            lim = m.get("integrity", {}).get("LIM", {})
            num = "text-align:right;white-space:nowrap;padding-left:6px"
            arows = "".join(
                f"<tr><td>{swatch(acol[a.id])}{html.escape(plain_text(names[i]))}</td>"
                f"<td style='{num}'>{a.fraction:.1f} %</td>"
                f"<td style='{num}' class='rj-lim'>{fmt(lim.get(a.id), 3)}</td></tr>"
                for i, a in enumerate(res.attractors))
            out += ("<b>attractors</b><table class='rj-attractors' style='font-size:12px;"
                    "border-collapse:collapse;width:100%'>"
                    f"<tr><th></th><th style='{num}'>basin</th>"
                    f"<th style='{num}' title='local integrity measure'>LIM</th></tr>"
                    f"{arows}</table>")
            integ = m.get("integrity", {})
            out += ("<b>measures</b><table style='font-size:12px'>"
                    f"<tr><td>basin entropy S<sub>b</sub></td><td>{fmt(m['basin_entropy'], 3)}"
                    "</td></tr>"
                    f"<tr><td>boundary entropy S<sub>bb</sub></td>"
                    f"<td>{fmt(m['boundary_basin_entropy'], 3)}</td></tr>"
                    f"<tr><td>integrity GIM</td><td>{fmt(integ.get('GIM'), 3)}</td></tr>"
                    f"<tr><td>integrity IF</td><td>{fmt(integ.get('IF'), 3)}</td></tr>"
                    "</table>")
        return f"<div style='font-size:12px'>{out}</div>"

    def _show_basin(self, view):
        self.basin_view = view
        self._draw_basin(view)
        self.basin_code.text = view.call
        p = view.params
        self.basin_fig.title.text = (f"basin {view.grid}², {law_name(p.law)}, h/b = "
                                     f"{fmt(p.hb)}, α = {fmt(p.alpha)}, ω = {fmt(p.omega)}")
        self.basin_state.text = (
            f'<span class="rj-basin-shown" data-grid="{view.grid}" '
            f'data-alpha="{p.alpha!r}" data-law="{p.law}" data-final="{int(view.final)}" '
            f'style="font-size:11px;color:#555">{view.grid}² cells shown</span>')
        self._show_cell_of_basin()

    def _basin_tap(self, event):
        view = self.basin_view
        if view is None:
            return
        if not finite(event.x, event.y):
            self._ignored("basin", "a click outside the plot's finite coordinates")
            return
        cell = R.nearest_cell(view.result, float(event.x), float(event.y))
        if cell is None:
            return
        i, j = cell
        self.state = (float(view.result.theta0[i]), float(view.result.dtheta0[j]))
        self._mark_cell(view.result, cell)
        self.submit_run()

    def _mark_cell(self, res, cell):
        i, j = cell
        th, dth = np.asarray(res.theta0), np.asarray(res.dtheta0)
        w = (th[-1] - th[0]) / max(th.size - 1, 1)
        h = (dth[-1] - dth[0]) / max(dth.size - 1, 1)
        self.cell_src.data = dict(x=[th[i]], y=[dth[j]], w=[w], h=[h])
