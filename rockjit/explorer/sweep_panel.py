"""The explorer's bifurcation panel: θ′(kT) over the amplitude α with its behaviour strip and
largest Lyapunov exponent; a box zoom recomputes it over that range, a click sets α.

:class:`SweepPanel` is one part of :class:`.app.ExplorerApp` (which holds the parameters, the
status lines and the worker it uses)."""

from __future__ import annotations

import math

import numpy as np
from bokeh.events import RangesUpdate, Tap
from bokeh.layouts import column, row
from bokeh.models import ColumnDataSource, Div, Range1d, Span

from ..result import BEHAVIOURS
from .drawing import (behaviour_colours, dim, error_html, finite, fit, fmt, law_name, plot,
                      rgba_image, swatch)

__all__ = ["SweepPanel"]


class SweepPanel:
    """The bifurcation diagram's widgets, drawing, zooms and clicks (a part of
    :class:`.app.ExplorerApp`)."""

    def _build_sweep(self):
        a0, a1 = self.params.alpha_range
        xr = Range1d(a0, a1)
        b = plot("θ′(kT) from the study's z0", 560, 330,
                 tools="xbox_zoom,tap,reset,save", y_label="θ′(kT)", x_range=xr,
                 y_range=Range1d(-1, 1), name="bif")
        self.bif_src = ColumnDataSource(data=dict(a=[], y=[], c=[]))
        b.scatter("a", "y", source=self.bif_src, size=2, color="c", line_color=None)
        strip = plot(None, 560, 40, tools="", x_range=xr, y_range=Range1d(0, 1),
                     name="bif_strip")
        strip.yaxis.visible = False
        strip.xaxis.visible = False
        strip.toolbar_location = None
        strip.min_border_top = 0
        self.strip_src = ColumnDataSource(data=dict(image=[], x=[], y=[], dw=[], dh=[]))
        strip.image_rgba(image="image", x="x", y="y", dw="dw", dh="dh", source=self.strip_src)
        lam = plot(None, 560, 190, tools="", x_label="α", y_label="λ max", x_range=xr,
                   y_range=Range1d(-1, 0.5), name="bif_lambda")
        lam.toolbar_location = None
        self.blam_src = ColumnDataSource(data=dict(a=[], lam=[], c=[]))
        lam.scatter("a", "lam", source=self.blam_src, size=3, color="c", line_color=None)
        lam.add_layout(Span(location=0, dimension="width", line_color="#888", line_width=1))
        # drawn on the overlay layer: moving it repaints the overlay, not the 50k points
        self.alpha_spans = [Span(location=self.params.alpha, dimension="height",
                                 line_color="#444", line_dash="dashed", line_width=1,
                                 level="overlay")
                            for _ in range(2)]
        b.add_layout(self.alpha_spans[0])
        lam.add_layout(self.alpha_spans[1])
        b.on_event(RangesUpdate, self._bif_range)
        b.on_event(Tap, self._bif_tap)
        self.bif_figs = (b, strip, lam)
        self.bif_legend = Div(text="", width=560)
        self.sweep_state = Div(text="", css_classes=["rj-sweep-state"])
        buttons, self.sweep_code = self._export_row("sweep", width=560)
        self.sweep_panel = column(b, strip, lam, self.bif_legend,
                                  row(buttons, self.status["sweep"], self.sweep_state),
                                  self.sweep_code, css_classes=["rj-view", "rj-view-sweep"])

    def _bif_range(self, event):
        if event.x0 is None and event.x1 is None:
            return
        if not finite(event.x0, event.x1):
            self._ignored("sweep", "a zoom to a range that is not finite")
            return
        a0, a1 = self.params.alpha_range
        x0, x1 = max(0.0, float(event.x0)), float(event.x1)
        if not x1 > x0:
            self._ignored("sweep", "a zoom to an empty range of α")
            return
        if abs(x0 - a0) + abs(x1 - a1) <= 1e-9 * max(a1 - a0, 1e-12):
            return
        digits = max(0, int(-math.floor(math.log10(max(x1 - x0, 1e-12) / 1e4))))
        rng = (round(x0, digits), round(x1, digits))
        try:
            self.params = self.params.with_(alpha_range=rng).check()
        except ValueError as exc:
            self.status["sweep"].text = error_html(str(exc))
            return
        self.submit_sweep()

    def _bif_tap(self, event):
        if not finite(event.x):
            self._ignored("sweep", "a click outside the plot's finite coordinates")
            return
        a0, a1 = self.params.alpha_range
        digits = max(0, int(-math.floor(math.log10(max(a1 - a0, 1e-12) / 1e3))))
        alpha = round(max(0.0, float(event.x)), digits)
        self._control("alpha", alpha, source="bifurcation")  # checked, then shown

    def _show_sweep(self, v):
        self.sweep_view = v
        sw = v.result
        colours = behaviour_colours()
        alpha = np.asarray(sw.alpha)
        label = np.asarray(sw.label)
        names = [str(n) for n in sw.names]
        a_list, y_list, c_list = [], [], []
        for i in range(alpha.size):
            y = sw.strobe[i, :, 1]
            y = np.unique(np.round(y[np.isfinite(y)], 7))
            if y.size:
                a_list.append(np.full(y.size, alpha[i]))
                y_list.append(y)
                c_list += [colours[names[label[i]]]] * y.size
        self.bif_src.data = dict(a=np.concatenate(a_list) if a_list else [],
                                 y=np.concatenate(y_list) if y_list else [], c=c_list)
        d = (alpha[-1] - alpha[0]) / max(alpha.size - 1, 1) if alpha.size > 1 else 1e-3
        strip = rgba_image(label[:, None], [colours[n] for n in BEHAVIOURS])
        self.strip_src.data = dict(image=[strip], x=[alpha[0] - d / 2], y=[0],
                                   dw=[alpha[-1] - alpha[0] + d], dh=[1])
        lam = np.asarray(sw.lambda_max, float)
        ok = np.isfinite(lam)
        fit(self.bif_figs[0].y_range, self.bif_src.data["y"], 0.05)
        fit(self.bif_figs[2].y_range, np.append(lam[ok], 0.0), 0.08)
        self.blam_src.data = dict(a=alpha[ok], lam=lam[ok],
                                  c=[colours[names[k]] for k in label[ok]])
        present = [n for n in BEHAVIOURS if np.any(label == names.index(n))]
        fr = sw.fractions()
        self.bif_legend.text = ("<div style='font-size:12px'>" + " &nbsp; ".join(
            f"<span style='white-space:nowrap'>{swatch(colours[n])}{n} {fr[n]:.0f} %</span>"
            for n in present)
            + " &nbsp; <span style='color:#666'>(strip: the behaviour of every α)</span></div>")
        p = v.params
        self.bif_figs[0].title.text = (f"{law_name(p.law)}, h/b = {fmt(p.hb)}, ω = "
                                       f"{fmt(p.omega)}: θ′(kT) from the study's z0")
        dim(self.bif_figs, False)
        a0, a1 = p.alpha_range
        self.sweep_state.text = (f'<span class="rj-sweep-shown" data-a0="{a0!r}" '
                                 f'data-a1="{a1!r}" data-n="{alpha.size}" '
                                 f'style="font-size:11px;color:#555">{alpha.size} amplitudes '
                                 f'over [{fmt(a0, 6)}, {fmt(a1, 6)}]</span>')
        self.sweep_code.text = v.call
        rng = self.bif_figs[0].x_range
        if (rng.start, rng.end) != (a0, a1):
            rng.start, rng.end = a0, a1
