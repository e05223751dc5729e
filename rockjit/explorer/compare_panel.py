"""The explorer's two-laws panel: the basins of Housner's and Mao's laws side by side, the map
of the cells where they agree, and their behaviours' shares; computed only while shown.

:class:`ComparePanel` is one part of :class:`.app.ExplorerApp` (which holds the parameters, the
status lines and the worker it uses)."""

from __future__ import annotations

from bokeh.layouts import column, row
from bokeh.models import ColumnDataSource, Div, Range1d, Toggle

from ..plotting import style
from ..result import BEHAVIOURS
from .drawing import behaviour_colours, dim, image_data, law_name, plot, rgba_image, swatch

__all__ = ["AGREE_COLOURS", "ComparePanel"]

#: Colours of the agreement map (as in rockjit.plotting.figures.fig_basin_compare).
AGREE_COLOURS = {"same": style.AGREE_COLOUR, "different": style.DISAGREE_COLOUR}


class ComparePanel:
    """The two laws' widgets and drawing (a part of :class:`.app.ExplorerApp`)."""

    def _build_compare(self):
        self.compare_toggle = Toggle(label="show both laws side by side", active=False,
                                     width=260, css_classes=["rj-compare-toggle"])
        self.compare_toggle.on_change("active", lambda attr, old, new: self._compare(new))
        size = 330
        xr, yr = Range1d(-1, 1), Range1d(-1, 1)
        self.cmp_src, self.cmp_figs = {}, {}
        for key, title in (("housner", "Housner"), ("mao", "Mao"), ("agree", "agreement")):
            f = plot(title, size, size + 30, tools="box_zoom,reset,save", x_label="θ₀",
                     y_label="θ₀′" if key == "housner" else None, x_range=xr, y_range=yr,
                     name=f"cmp_{key}")
            src = ColumnDataSource(data=dict(image=[], x=[], y=[], dw=[], dh=[]))
            f.image_rgba(image="image", x="x", y="y", dw="dw", dh="dh", source=src)
            self.cmp_src[key], self.cmp_figs[key] = src, f
        self.cmp_info = Div(text="", width=300, css_classes=["rj-compare-info"])
        buttons, self.compare_code = self._export_row("compare", width=1000)
        self.compare_body = column(
            row(*self.cmp_figs.values(), column(self.status["compare"], self.cmp_info, buttons)),
            self.compare_code, visible=False)
        self.compare_panel = column(self.compare_toggle, self.compare_body,
                                    css_classes=["rj-view", "rj-view-compare"])

    def _compare(self, on):
        self.compare_body.visible = bool(on)
        if on:
            self.submit_compare()
        else:
            if self.computer is not None:
                self.computer.cancel("compare")
            self.status["compare"].text = ""

    def _show_compare(self, v):
        self.compare_view = v
        colours = behaviour_colours()
        lut = [colours[n] for n in BEHAVIOURS]
        for key, res in (("housner", v.housner), ("mao", v.mao)):
            self.cmp_src[key].data = image_data(res, rgba_image(res.label, lut))
            self.cmp_figs[key].title.text = f"{law_name(key)} (e = {res.block.restitution:.3f})"
        agree = rgba_image(v.agree.astype(int), [AGREE_COLOURS["different"], AGREE_COLOURS["same"]])
        self.cmp_src["agree"].data = image_data(v.housner, agree)
        self.cmp_figs["agree"].title.text = f"agreement: {v.percent:.1f} % of cells"
        dim(self.cmp_figs.values(), False)
        fh, fm = v.housner.fractions(), v.mao.fractions()
        rows = "".join(f"<tr><td>{swatch(colours[n])}{n}</td><td>{fh[n]:.1f} %</td>"
                       f"<td>{fm[n]:.1f} %</td></tr>" for n in BEHAVIOURS if fh[n] or fm[n])
        self.cmp_info.text = (
            f"<div style='font-size:12px'><b>{v.grid}² cells</b><table style='font-size:12px'>"
            f"<tr><th></th><th>Housner</th><th>Mao</th></tr>{rows}</table>"
            f"<div>{swatch(AGREE_COLOURS['same'])}same behaviour "
            f"<b class='rj-agreement'>{v.percent:.1f} %</b></div>"
            f"<div>{swatch(AGREE_COLOURS['different'])}different {100 - v.percent:.1f} %"
            "</div></div>")
        self.compare_code.text = v.call
