"""The explorer's run panel: one cell's run (θ(t), the impacts, the running Lyapunov
exponent, the phase portrait) and what it and the basin say of that cell.

:class:`RunPanel` is one part of :class:`.app.ExplorerApp` (which holds the parameters, the
status lines and the worker it uses)."""

from __future__ import annotations

import html

import numpy as np
from bokeh.layouts import column, row
from bokeh.models import ColumnDataSource, Div, Range1d, Span

from . import requests as R
from .drawing import behaviour_colours, dim, fit, fmt, plot, swatch

__all__ = ["RunPanel"]


class RunPanel:
    """The run's widgets and drawing (a part of :class:`.app.ExplorerApp`)."""

    def _build_run(self):
        t = plot("θ(t)", 620, 190, tools="xbox_zoom,reset,save",
                 y_label="θ", name="run_theta", x_range=Range1d(0, 1), y_range=Range1d(-1, 1))
        self.traj_src = ColumnDataSource(data=dict(t=[], th=[], dth=[]))
        t.line("t", "th", source=self.traj_src, line_width=1, color="black")
        imp = plot("the impacts: |θ′| just before each", 620, 140, tools="xbox_zoom,reset,save",
                   y_label="|θ′⁻|", name="run_impacts", x_range=t.x_range,
                   y_range=Range1d(0, 1))
        self.imp_src = ColumnDataSource(data=dict(t=[], v=[]))
        imp.scatter("t", "v", source=self.imp_src, size=3, color="#d62728", line_color=None)
        lam = plot("λ₁(t), running estimate", 620, 170, tools="xbox_zoom,reset,save",
                   x_label="t (units of 1/Ω₀)", y_label="λ₁", x_range=t.x_range,
                   y_range=Range1d(-1, 1), name="run_lambda")
        self.lam_src = ColumnDataSource(data=dict(t=[], lam=[]))
        lam.line("t", "lam", source=self.lam_src, color="#d62728", line_width=1.5)
        lam.add_layout(Span(location=0, dimension="width", line_color="#888", line_width=1))
        ph = plot("phase portrait (○: t = kT)", 380, 380, tools="box_zoom,wheel_zoom,reset,save",
                  x_label="θ", y_label="θ′", name="run_phase", x_range=Range1d(-1, 1),
                  y_range=Range1d(-1, 1))
        self.phase_src = ColumnDataSource(data=dict(th=[], dth=[]))
        ph.line("th", "dth", source=self.phase_src, color="black", line_width=0.8)
        self.strobe_src = ColumnDataSource(data=dict(th=[], dth=[]))
        ph.scatter("th", "dth", source=self.strobe_src, size=7, fill_alpha=0, line_color="#d62728",
                   line_width=1.5)
        self.run_figs = (t, imp, lam, ph)
        for f in self.run_figs:  # shown with the first run
            f.visible = False
        self.run_info = Div(text='<div style="color:#666">Click a cell of the basin: its run '
                                 'appears here.</div>', width=320, css_classes=["rj-run-info"])
        buttons, self.run_code = self._export_row("run", width=1000)
        self.run_panel = column(
            row(column(t, imp, lam), ph, column(self.status["run"], self.run_info, buttons)),
            self.run_code, css_classes=["rj-view", "rj-view-run"])

    def _cell_html(self):
        """What the basin shown says of the selected state's cell."""
        view, st = self.basin_view, self.state
        if view is None or st is None or view.params != self.params:
            return ""
        res = view.result
        cell = R.nearest_cell(res, *st)
        if cell is None:
            return ""
        i, j = cell
        name = str(res.names[res.label[i, j]])
        out = f"basin {view.grid}² cell: <b>{name}</b>"
        if res.attractor is not None:
            aid = int(res.attractor[i, j])
            if aid >= 0:
                a = res.attractors[aid]
                out += (f", attractor <b class='rj-attractor'>{aid}</b> ({a.behaviour}"
                        f"{', period ' + str(a.period) if a.period else ''})")
            else:
                out += ", no attractor (" + ("overturn" if aid == -1 else "unresolved") + ")"
        return f"<div style='font-size:12px'>{out}</div>"

    def _show_cell_of_basin(self):
        if self.run_view is not None and self.state is not None:
            self.run_info.text = self._run_info_html(self.run_view)

    def _run_info_html(self, v):
        res = v.result
        colours = behaviour_colours()
        beh = v.behaviour + (f", period {v.period}" if v.period > 1 else "")
        lines = [
            f"<div>θ₀ = {fmt(v.state[0], 6)}, θ₀′ = {fmt(v.state[1], 6)}</div>",
            f"<div style='font-size:15px'>{swatch(colours.get(v.behaviour, '#999'))}"
            f"<b class='rj-run-behaviour' data-behaviour='{v.behaviour}'>{beh}</b></div>",
            f"<div>status: {res.status} ({html.escape(res.message)})</div>",
            f"<div>impacts: {res.n_impacts}, t end = {fmt(res.t, 6)}</div>",
            f"<div>λ_max over the window = {fmt(res.lambda_max, 4)}</div>",
            self._cell_html()]
        for note in res.caveats():
            lines.append(f"<div style='color:#8a5a00'>{html.escape(note)}</div>")
        return "<div style='font-size:12px'>" + "".join(lines) + "</div>"

    def _show_run(self, v):
        self.run_view = v
        res = v.result
        tr = res.trajectory
        self.traj_src.data = dict(t=tr[:, 0], th=tr[:, 1], dth=tr[:, 2])
        imp = res.impacts
        self.imp_src.data = dict(t=imp[:, 0], v=np.abs(imp[:, 1]))
        lam = res.lyapunov_running
        if lam is not None and lam.shape[0] > 1:
            k = np.arange(1, lam.shape[0])
            ok = np.isfinite(lam[1:, 0])
            self.lam_src.data = dict(t=(k * res.period)[ok], lam=lam[1:, 0][ok])
        else:
            self.lam_src.data = dict(t=[], lam=[])
        t0 = res.window[0] if res.window else 0.8 * res.periods * res.period
        w = tr[tr[:, 0] >= t0 - 1e-9]
        if w.shape[0] < 2:
            w, k0 = tr, 0
        else:
            k0 = int(round(t0 / res.period))
        self.phase_src.data = dict(th=w[:, 1], dth=w[:, 2])
        s = res.strobe[k0:]
        self.strobe_src.data = dict(th=s[:, 0], dth=s[:, 1])
        dim(self.run_figs, False)
        for f in self.run_figs:
            f.visible = True
        t_fig, imp_fig, lam_fig, ph_fig = self.run_figs
        t_fig.x_range.start, t_fig.x_range.end = 0.0, max(float(tr[-1, 0]), 1e-9)
        fit(t_fig.y_range, tr[:, 1], 0.05)
        imp_fig.y_range.start, imp_fig.y_range.end = 0.0, \
            1.05 * float(np.abs(imp[:, 1]).max()) if imp.shape[0] else 1.0
        lam_fig.y_range.start, lam_fig.y_range.end = -1.0, 1.0  # when no finite value
        fit(lam_fig.y_range, self.lam_src.data["lam"], 0.08)
        if len(self.lam_src.data["lam"]):
            lam_fig.y_range.start = min(lam_fig.y_range.start, 0.0)
            lam_fig.y_range.end = max(lam_fig.y_range.end, 0.0)
        fit(ph_fig.x_range, w[:, 1], 0.05)
        fit(ph_fig.y_range, w[:, 2], 0.05)
        self.run_info.text = self._run_info_html(v)
        self.run_code.text = v.call
        if self.basin_view is not None and v.cell is None:
            cell = R.nearest_cell(self.basin_view.result, *v.state)
            if cell is not None:
                self._mark_cell(self.basin_view.result, cell)
