"""The explorer's page: Bokeh widgets and plots over the compute side (:mod:`.requests`,
:mod:`.worker`).

One :class:`ExplorerApp` per browser tab, built once the tab's websocket is open and the page
has loaded (:func:`document`; until then a request of the page holds a placeholder and computes
nothing), stopped when the websocket closes (:mod:`.pages`). A change of a control is checked
by the library first (a refused value is shown under its control with the library's message,
and nothing else changes); an accepted change marks the views it affects as updating and submits their
computations to the tab's worker thread; results come back through the document's next-tick
callbacks and are shown only while their request is still the newest (:meth:`Computer.
is_current`). Behaviour colours come from :data:`rockjit.plotting.style.BEHAVIOUR_COLOURS`,
read when a view is drawn.
"""

from __future__ import annotations

import base64
import html
import io
import math
import threading
from functools import partial

import numpy as np
from bokeh.events import DocumentReady, RangesUpdate, Tap
from bokeh.layouts import column, row
from bokeh.models import (Button, ColumnDataSource, CustomJS, Div, NumericInput, PreText,
                          RadioButtonGroup, Range1d, Select, Slider, Span, Toggle)
from bokeh.plotting import figure

from ..plotting import style
from ..result import BEHAVIOURS
from . import requests as R
from .worker import Computer

__all__ = ["ExplorerApp", "document"]

#: Colours of the agreement map (as in rockjit.plotting.figures.fig_basin_compare).
AGREE_COLOURS = {"same": style.AGREE_COLOUR, "different": style.DISAGREE_COLOUR}
#: Opacity of a view whose parameters changed and whose new result is not there yet.
STALE_ALPHA = 0.35
BASIN_SIZE = 400
#: How often a page looks whether its websocket is still open, in milliseconds.
WATCH_MS = 400
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


def _law_name(law):
    """A restitution law's name as the figures write it (:data:`rockjit.plotting.style.LAW_NAMES`),
    in plain text."""
    return plain_text(style.LAW_NAMES.get(law, law))


def _finite(*values):
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


def _image_data(result, img):
    th, dth = np.asarray(result.theta0), np.asarray(result.dtheta0)
    dx = (th[-1] - th[0]) / max(th.size - 1, 1)
    dy = (dth[-1] - dth[0]) / max(dth.size - 1, 1)
    return dict(image=[img], x=[th[0] - dx / 2], y=[dth[0] - dy / 2], dw=[th[-1] - th[0] + dx],
                dh=[dth[-1] - dth[0] + dy])


def _fmt(v, digits=4):
    if v is None:
        return "–"
    v = float(v)
    if math.isnan(v):
        return "nan"
    if math.isinf(v):
        return "−∞" if v < 0 else "∞"
    return f"{v:.{digits}g}"


def _swatch(colour):
    return (f'<span style="display:inline-block;width:11px;height:11px;background:{colour};'
            f'border:1px solid #999;margin-right:5px;vertical-align:middle"></span>')


def _progress_html(stage, fraction):
    pct = int(round(100 * fraction))
    return (f'<div class="rj-progress" data-stage="{html.escape(stage)}">'
            f'<progress value="{pct}" max="100" style="width:150px;vertical-align:middle">'
            f'</progress> <span style="color:#555">{html.escape(stage)} {pct} %</span></div>')


def _error_html(message):
    return (f'<div class="rj-refused" style="color:#b00020;font-size:12px;max-width:220px;'
            f'white-space:normal">refused: {html.escape(message)}</div>')


def _fit(rng, values, pad):
    """Set a Range1d around finite ``values`` (unchanged when there are none)."""
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    if v.size:
        lo, hi = float(v.min()), float(v.max())
        d = max(hi - lo, 1e-3) * pad
        rng.start, rng.end = lo - d, hi + d


def _dim(figs, stale):
    """Show plots as updating (faded) or current."""
    for f in figs:
        f.styles = {"opacity": str(STALE_ALPHA) if stale else "1"}


def _fig(title, width, height, tools="save", x_label=None, y_label=None, toolbar="above",
         **kw):
    p = figure(title=title, width=width, height=height, tools=tools, toolbar_location=toolbar,
               **kw)
    if x_label:
        p.xaxis.axis_label = x_label
    if y_label:
        p.yaxis.axis_label = y_label
    if p.title is not None:
        p.title.text_font_size = "11pt"
    return p


class ExplorerApp:
    """The page of one browser tab (see the module's docstring)."""

    def __init__(self, doc, params=None, pages=None, root=None):
        self.doc = doc
        self.pages = pages
        self._placeholder = root
        self.params = (params or R.Params()).check()
        self.default_alpha_range = self.params.alpha_range
        self.basin_view = None      # the BasinView shown
        self.sweep_view = None
        self.run_view = None
        self.compare_view = None
        self.state = None           # the selected (theta0, theta0')
        self.colour_by = "behaviour"
        self._quiet = False         # widget updates made by the app, not by the user
        self.computer = None        # the worker: started by start()
        self.closed = False
        self._watch = None
        self._drawing = False       # a PNG is being drawn
        self._build()

    def start(self):
        """Start computing: the worker thread, the basin and the bifurcation diagram; and watch
        the page's websocket (when it closes, :meth:`close`)."""
        if self.computer is not None or self.closed:
            return
        self.computer = Computer(self._from_worker, progress_every=0.25)
        if self.pages is not None:
            self.pages.started(self.computer)
        self.doc.on_session_destroyed(lambda ctx: self.close())
        if self._session() is not None:
            self._watch = self.doc.add_periodic_callback(self._watch_connection, WATCH_MS)
        self.submit_basin()
        self.submit_sweep()

    def _session(self):
        ctx = self.doc.session_context
        return None if ctx is None else getattr(ctx, "session", None)

    def _watch_connection(self):
        session = self._session()
        if session is None or session.connection_count == 0:
            self.close()

    def stop_work(self):
        """Stop computing, from any thread: the worker ends at its current piece of work's end
        (a grid's chunk), and the page gives its place back."""
        self.closed = True
        if self.computer is not None:
            self.computer.close(timeout=0)
        if self.pages is not None:
            self.pages.release(self)

    def close(self):
        """Stop computing and watching (the tab was closed or reloaded, or its session ended);
        on the document's loop."""
        self.stop_work()
        if self._watch is not None:
            try:
                self.doc.remove_periodic_callback(self._watch)
            except ValueError:  # already gone with its session
                pass
            self._watch = None

    # ---------------------------------------------------------------------------------------
    # the worker's events, on the document's loop
    # ---------------------------------------------------------------------------------------
    def _from_worker(self, event):
        self.doc.add_next_tick_callback(partial(self._on_event, event))

    def _on_event(self, event):
        if self.closed or not self.computer.is_current(event.channel, event.request):
            return  # superseded meanwhile: never shown
        status = self.status[event.channel]
        if event.kind == "progress":
            status.text = _progress_html(event.stage, event.fraction)
        elif event.kind == "error":
            status.text = _error_html(event.message)
        elif event.kind == "done":
            status.text = ""
        elif event.kind == "result":
            getattr(self, f"_show_{event.channel}")(event.value)
            if not event.final:
                status.text = _progress_html(f"{event.stage} shown; refining", 1.0)

    # ---------------------------------------------------------------------------------------
    # the page
    # ---------------------------------------------------------------------------------------
    def _build(self):
        p = self.params
        # fixed sizes: a progress update rerenders the line without laying the page out again
        self.status = {c: Div(text="", width=280, height=40, css_classes=[f"rj-status-{c}"])
                       for c in ("basin", "run", "sweep", "compare")}
        self.errors = {}
        controls = [Div(text="<b>Block</b>")]
        self.w = {}

        def number(name, title, value, mode="float", placeholder=""):
            w = NumericInput(title=title, value=value, mode=mode, width=210,
                             placeholder=placeholder, css_classes=[f"rj-{name}"])
            w.on_change("value", lambda attr, old, new, name=name: self._control(name, new))
            self.w[name] = w
            return self._with_error(name, w)

        controls.append(number("hb", "h/b (slenderness)", p.hb))
        law = Select(title="restitution law", value=p.law, width=210, css_classes=["rj-law"],
                     options=[(k, plain_text(v)) for k, v in style.LAW_NAMES.items()])
        law.on_change("value", lambda attr, old, new: self._control("law", new))
        self.w["law"] = law
        controls.append(self._with_error("law", law))
        controls.append(number("e", "e (constant law)", p.e))
        self.w["e"].visible = p.law == "constant"
        controls.append(number("xi", "ξ (viscous damping)", p.xi))
        controls.append(Div(text="<b>Forcing</b>"))
        slider = Slider(title="α (amplitude A/R)", start=0.0, end=1.5, step=0.001, value=p.alpha,
                        width=210, css_classes=["rj-alpha-slider"])
        slider.on_change("value_throttled",
                         lambda attr, old, new: self._control("alpha", new, source="slider"))
        self.w["alpha_slider"] = slider
        controls.append(slider)
        controls.append(number("alpha", "α", p.alpha))
        controls.append(number("omega", "ω (frequency Ω/Ω₀)", p.omega))
        controls.append(number("phase", "forcing phase φ [rad]", p.phase))
        controls.append(Div(text="<b>Integration</b>"))
        controls.append(number("n_steps", "N (steps per period)", p.n_steps, mode="int",
                               placeholder="default"))
        controls.append(number("periods", f"periods (at most {R.MAX_PERIODS:,})", p.periods,
                               mode="int"))
        self.limits = Div(text=self._limits_html(), width=215, css_classes=["rj-limits"])
        controls.append(self.limits)
        controls.append(Div(text='<div style="color:#666;font-size:11px;max-width:215px">'
                                 'A value the library refuses is shown here with its message '
                                 'and the views keep the last accepted parameters.</div>'))
        self.controls = column(*controls, width=230, css_classes=["rj-controls"])

        self.download = ColumnDataSource(data=dict(name=[], b64=[], mime=[]))
        self.download.js_on_change("data", CustomJS(args=dict(src=self.download), code="""
            const d = src.data;
            if (!d.name || d.name.length == 0) return;
            const bin = atob(d.b64[0]);
            const bytes = new Uint8Array(bin.length);
            for (let i = 0; i < bin.length; i++) bytes[i] = bin.charCodeAt(i);
            const a = document.createElement('a');
            a.href = URL.createObjectURL(new Blob([bytes], {type: d.mime[0]}));
            a.download = d.name[0];
            document.body.appendChild(a);
            a.click();
            setTimeout(() => { URL.revokeObjectURL(a.href); a.remove(); }, 2000);
        """))

        self._build_basin()
        self._build_run()
        self._build_sweep()
        self._build_compare()
        header = Div(text=(
            '<div style="font-size:20px;font-weight:600">rockjit explore</div>'
            '<div style="color:#555;font-size:12px;max-width:1100px">The forced rocking '
            'block, live: change a parameter and the basin is recomputed (50², then 100², '
            'then 200²). Click a cell of the basin for its run; box-zoom the bifurcation '
            'diagram to recompute it on that range, click it to set α. Every view gives its '
            'figure as a PNG and the Python call that reproduces it.</div>'), width=1200)
        if self._placeholder is not None:
            self.doc.remove_root(self._placeholder)
        self.doc.add_root(column(
            header,
            row(self.controls, column(row(self.basin_panel, self.sweep_panel), self.run_panel,
                                      self.compare_panel)),
        ))
        self.doc.add_root(self.download)  # not drawn: in the document so that it syncs
        # the page's own timing log, window.rockjitLog: [what, value, time in ms], stamped
        # when the user changes alpha and after the frame that shows a new basin or diagram
        # (benchmarks/bench_explore.py reads it; nothing polls the page's DOM)
        stamp = ("(window.rockjitLog = window.rockjitLog || []);"
                 "const v = {value}; requestAnimationFrame(() => "
                 "window.rockjitLog.push(['{what}', v, performance.now()]));")
        now = ("(window.rockjitLog = window.rockjitLog || []).push(['{what}', {value}, "
               "performance.now()]);")
        self.w["alpha"].js_on_change("value", CustomJS(code=now.format(
            what="alpha", value="cb_obj.value")))
        self.basin_state.js_on_change("text", CustomJS(code=stamp.format(
            what="basin", value="cb_obj.text")))
        self.sweep_state.js_on_change("text", CustomJS(code=stamp.format(
            what="sweep", value="cb_obj.text")))
        self.doc.title = "rockjit explore"

    def _limits_html(self):
        p = self.params
        n = p.grid_n_steps()
        return (f'<div class="rj-limits-text" style="color:#666;font-size:11px;max-width:215px">'
                f'Limits of the explorer: '
                f'{html.escape(R.limits_text())}. Now {p.periods:,} × {n} = '
                f'<span class="rj-cell-steps">{p.periods * n:,}</span>.</div>')

    def _with_error(self, name, widget):
        err = Div(text="", visible=False, css_classes=[f"rj-error-{name}"], width=215)
        self.errors[name] = err
        return column(widget, err, css_classes=[f"rj-control-{name}"])

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

    # basin ---------------------------------------------------------------------------------
    def _build_basin(self):
        p = _fig("basin", BASIN_SIZE + 40, BASIN_SIZE + 40, tools="tap,box_zoom,wheel_zoom,reset,save",
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
        self.basin_src.data = _image_data(res, img)
        _dim([self.basin_fig], False)
        self.basin_info.text = self._basin_info_html(view)

    def _basin_info_html(self, view):
        res, m = view.result, view.measures
        colours = behaviour_colours()
        fr = res.fractions()
        rows = "".join(f"<tr><td>{_swatch(colours[n])}{n}</td><td style='text-align:right'>"
                       f"{fr[n]:.1f} %</td></tr>" for n in BEHAVIOURS if fr[n] > 0)
        out = f"<b>behaviours</b><table style='font-size:12px'>{rows}</table>"
        if res.attractor is not None:
            acol = attractor_colours(res.attractors)
            names = style.attractor_names(res.attractors)
            lim = m.get("integrity", {}).get("LIM", {})
            num = "text-align:right;white-space:nowrap;padding-left:6px"
            arows = "".join(
                f"<tr><td>{_swatch(acol[a.id])}{html.escape(plain_text(names[i]))}</td>"
                f"<td style='{num}'>{a.fraction:.1f} %</td>"
                f"<td style='{num}' class='rj-lim'>{_fmt(lim.get(a.id), 3)}</td></tr>"
                for i, a in enumerate(res.attractors))
            out += ("<b>attractors</b><table class='rj-attractors' style='font-size:12px;"
                    "border-collapse:collapse;width:100%'>"
                    f"<tr><th></th><th style='{num}'>basin</th>"
                    f"<th style='{num}' title='local integrity measure'>LIM</th></tr>"
                    f"{arows}</table>")
            integ = m.get("integrity", {})
            out += ("<b>measures</b><table style='font-size:12px'>"
                    f"<tr><td>basin entropy S<sub>b</sub></td><td>{_fmt(m['basin_entropy'], 3)}"
                    "</td></tr>"
                    f"<tr><td>boundary entropy S<sub>bb</sub></td>"
                    f"<td>{_fmt(m['boundary_basin_entropy'], 3)}</td></tr>"
                    f"<tr><td>integrity GIM</td><td>{_fmt(integ.get('GIM'), 3)}</td></tr>"
                    f"<tr><td>integrity IF</td><td>{_fmt(integ.get('IF'), 3)}</td></tr>"
                    "</table>")
        return f"<div style='font-size:12px'>{out}</div>"

    def _show_basin(self, view):
        self.basin_view = view
        self._draw_basin(view)
        self.basin_code.text = view.call
        p = view.params
        self.basin_fig.title.text = (f"basin {view.grid}², {_law_name(p.law)}, h/b = "
                                     f"{_fmt(p.hb)}, α = {_fmt(p.alpha)}, ω = {_fmt(p.omega)}")
        self.basin_state.text = (
            f'<span class="rj-basin-shown" data-grid="{view.grid}" '
            f'data-alpha="{p.alpha!r}" data-law="{p.law}" data-final="{int(view.final)}" '
            f'style="font-size:11px;color:#555">{view.grid}² cells shown</span>')
        self._show_cell_of_basin()

    # run -----------------------------------------------------------------------------------
    def _build_run(self):
        t = _fig("θ(t)", 620, 190, tools="xbox_zoom,reset,save",
                 y_label="θ", name="run_theta", x_range=Range1d(0, 1), y_range=Range1d(-1, 1))
        self.traj_src = ColumnDataSource(data=dict(t=[], th=[], dth=[]))
        t.line("t", "th", source=self.traj_src, line_width=1, color="black")
        imp = _fig("the impacts: |θ′| just before each", 620, 140, tools="xbox_zoom,reset,save",
                   y_label="|θ′⁻|", name="run_impacts", x_range=t.x_range,
                   y_range=Range1d(0, 1))
        self.imp_src = ColumnDataSource(data=dict(t=[], v=[]))
        imp.scatter("t", "v", source=self.imp_src, size=3, color="#d62728", line_color=None)
        lam = _fig("λ₁(t), running estimate", 620, 170, tools="xbox_zoom,reset,save",
                   x_label="t (units of 1/Ω₀)", y_label="λ₁", x_range=t.x_range,
                   y_range=Range1d(-1, 1), name="run_lambda")
        self.lam_src = ColumnDataSource(data=dict(t=[], lam=[]))
        lam.line("t", "lam", source=self.lam_src, color="#d62728", line_width=1.5)
        lam.add_layout(Span(location=0, dimension="width", line_color="#888", line_width=1))
        ph = _fig("phase portrait (○: t = kT)", 380, 380, tools="box_zoom,wheel_zoom,reset,save",
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

    def _basin_tap(self, event):
        view = self.basin_view
        if view is None:
            return
        if not _finite(event.x, event.y):
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
            f"<div>θ₀ = {_fmt(v.state[0], 6)}, θ₀′ = {_fmt(v.state[1], 6)}</div>",
            f"<div style='font-size:15px'>{_swatch(colours.get(v.behaviour, '#999'))}"
            f"<b class='rj-run-behaviour' data-behaviour='{v.behaviour}'>{beh}</b></div>",
            f"<div>status: {res.status} ({html.escape(res.message)})</div>",
            f"<div>impacts: {res.n_impacts}, t end = {_fmt(res.t, 6)}</div>",
            f"<div>λ_max over the window = {_fmt(res.lambda_max, 4)}</div>",
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
        _dim(self.run_figs, False)
        for f in self.run_figs:
            f.visible = True
        t_fig, imp_fig, lam_fig, ph_fig = self.run_figs
        t_fig.x_range.start, t_fig.x_range.end = 0.0, max(float(tr[-1, 0]), 1e-9)
        _fit(t_fig.y_range, tr[:, 1], 0.05)
        imp_fig.y_range.start, imp_fig.y_range.end = 0.0, \
            1.05 * float(np.abs(imp[:, 1]).max()) if imp.shape[0] else 1.0
        lam_fig.y_range.start, lam_fig.y_range.end = -1.0, 1.0  # when no finite value
        _fit(lam_fig.y_range, self.lam_src.data["lam"], 0.08)
        if len(self.lam_src.data["lam"]):
            lam_fig.y_range.start = min(lam_fig.y_range.start, 0.0)
            lam_fig.y_range.end = max(lam_fig.y_range.end, 0.0)
        _fit(ph_fig.x_range, w[:, 1], 0.05)
        _fit(ph_fig.y_range, w[:, 2], 0.05)
        self.run_info.text = self._run_info_html(v)
        self.run_code.text = v.call
        if self.basin_view is not None and v.cell is None:
            cell = R.nearest_cell(self.basin_view.result, *v.state)
            if cell is not None:
                self._mark_cell(self.basin_view.result, cell)

    # bifurcation ---------------------------------------------------------------------------
    def _build_sweep(self):
        a0, a1 = self.params.alpha_range
        xr = Range1d(a0, a1)
        b = _fig("θ′(kT) from the study's z0", 560, 330,
                 tools="xbox_zoom,tap,reset,save", y_label="θ′(kT)", x_range=xr,
                 y_range=Range1d(-1, 1), name="bif")
        self.bif_src = ColumnDataSource(data=dict(a=[], y=[], c=[]))
        b.scatter("a", "y", source=self.bif_src, size=2, color="c", line_color=None)
        strip = _fig(None, 560, 40, tools="", x_range=xr, y_range=Range1d(0, 1),
                     name="bif_strip")
        strip.yaxis.visible = False
        strip.xaxis.visible = False
        strip.toolbar_location = None
        strip.min_border_top = 0
        self.strip_src = ColumnDataSource(data=dict(image=[], x=[], y=[], dw=[], dh=[]))
        strip.image_rgba(image="image", x="x", y="y", dw="dw", dh="dh", source=self.strip_src)
        lam = _fig(None, 560, 190, tools="", x_label="α", y_label="λ max", x_range=xr,
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

    def _ignored(self, channel, what):
        """Say in the view's status line that an event was ignored (the app goes on)."""
        self.status[channel].text = (f'<div class="rj-ignored" style="color:#8a5a00;'
                                     f'font-size:12px">ignored: {html.escape(what)}</div>')

    def _bif_range(self, event):
        if event.x0 is None and event.x1 is None:
            return
        if not _finite(event.x0, event.x1):
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
            self.status["sweep"].text = _error_html(str(exc))
            return
        self.submit_sweep()

    def _bif_tap(self, event):
        if not _finite(event.x):
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
        _fit(self.bif_figs[0].y_range, self.bif_src.data["y"], 0.05)
        _fit(self.bif_figs[2].y_range, np.append(lam[ok], 0.0), 0.08)
        self.blam_src.data = dict(a=alpha[ok], lam=lam[ok],
                                  c=[colours[names[k]] for k in label[ok]])
        present = [n for n in BEHAVIOURS if np.any(label == names.index(n))]
        fr = sw.fractions()
        self.bif_legend.text = ("<div style='font-size:12px'>" + " &nbsp; ".join(
            f"<span style='white-space:nowrap'>{_swatch(colours[n])}{n} {fr[n]:.0f} %</span>"
            for n in present)
            + " &nbsp; <span style='color:#666'>(strip: the behaviour of every α)</span></div>")
        p = v.params
        self.bif_figs[0].title.text = (f"{_law_name(p.law)}, h/b = {_fmt(p.hb)}, ω = "
                                       f"{_fmt(p.omega)}: θ′(kT) from the study's z0")
        _dim(self.bif_figs, False)
        a0, a1 = p.alpha_range
        self.sweep_state.text = (f'<span class="rj-sweep-shown" data-a0="{a0!r}" '
                                 f'data-a1="{a1!r}" data-n="{alpha.size}" '
                                 f'style="font-size:11px;color:#555">{alpha.size} amplitudes '
                                 f'over [{_fmt(a0, 6)}, {_fmt(a1, 6)}]</span>')
        self.sweep_code.text = v.call
        rng = self.bif_figs[0].x_range
        if (rng.start, rng.end) != (a0, a1):
            rng.start, rng.end = a0, a1

    # both laws -----------------------------------------------------------------------------
    def _build_compare(self):
        self.compare_toggle = Toggle(label="show both laws side by side", active=False,
                                     width=260, css_classes=["rj-compare-toggle"])
        self.compare_toggle.on_change("active", lambda attr, old, new: self._compare(new))
        size = 330
        xr, yr = Range1d(-1, 1), Range1d(-1, 1)
        self.cmp_src, self.cmp_figs = {}, {}
        for key, title in (("housner", "Housner"), ("mao", "Mao"), ("agree", "agreement")):
            f = _fig(title, size, size + 30, tools="box_zoom,reset,save", x_label="θ₀",
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
            self.cmp_src[key].data = _image_data(res, rgba_image(res.label, lut))
            self.cmp_figs[key].title.text = f"{_law_name(key)} (e = {res.block.restitution:.3f})"
        agree = rgba_image(v.agree.astype(int), [AGREE_COLOURS["different"], AGREE_COLOURS["same"]])
        self.cmp_src["agree"].data = _image_data(v.housner, agree)
        self.cmp_figs["agree"].title.text = f"agreement: {v.percent:.1f} % of cells"
        _dim(self.cmp_figs.values(), False)
        fh, fm = v.housner.fractions(), v.mao.fractions()
        rows = "".join(f"<tr><td>{_swatch(colours[n])}{n}</td><td>{fh[n]:.1f} %</td>"
                       f"<td>{fm[n]:.1f} %</td></tr>" for n in BEHAVIOURS if fh[n] or fm[n])
        self.cmp_info.text = (
            f"<div style='font-size:12px'><b>{v.grid}² cells</b><table style='font-size:12px'>"
            f"<tr><th></th><th>Housner</th><th>Mao</th></tr>{rows}</table>"
            f"<div>{_swatch(AGREE_COLOURS['same'])}same behaviour "
            f"<b class='rj-agreement'>{v.percent:.1f} %</b></div>"
            f"<div>{_swatch(AGREE_COLOURS['different'])}different {100 - v.percent:.1f} %"
            "</div></div>")
        self.compare_code.text = v.call

    # ---------------------------------------------------------------------------------------
    # controls and submissions
    # ---------------------------------------------------------------------------------------
    def _set_widgets(self, **values):
        self._quiet = True
        try:
            for name, v in values.items():
                if name == "alpha":
                    s = self.w["alpha_slider"]
                    if v > s.end:
                        s.end = float(v)
                    s.value = v
                    self.w["alpha"].value = v
                else:
                    self.w[name].value = v
        finally:
            self._quiet = False

    def _control(self, name, value, source=None):
        """A control changed: the library checks the new parameters; refused, the message
        stays under the control and nothing else changes."""
        if self._quiet:
            return
        err = self.errors["alpha" if name == "alpha" else name]
        try:
            new = self.params.with_(**{name: value}).check()
        except Exception as exc:  # refused: the message under the control, the app goes on
            msg = str(exc) if isinstance(exc, ValueError) else f"{type(exc).__name__}: {exc}"
            err.text = _error_html(msg)
            err.visible = True
            return
        err.text, err.visible = "", False
        if name == "law":
            self.w["e"].visible = value == "constant"
            if value != "constant":
                self.errors["e"].visible = False
        if name == "alpha":  # the slider and the box show the same value
            self._set_widgets(alpha=new.alpha)
        self.apply(new)

    def apply(self, new):
        """Take new (checked) parameters: resubmit what depends on what changed."""
        old, self.params = self.params, new
        if new == old:
            return
        self.submit_basin()
        if self.state is not None:
            self.submit_run()
        sweep_fields = ("hb", "law", "e", "omega", "xi", "n_steps", "periods", "alpha_range")
        if any(getattr(old, f) != getattr(new, f) for f in sweep_fields):
            self.submit_sweep()
        for s in self.alpha_spans:
            s.location = new.alpha
        self.limits.text = self._limits_html()
        if self.compare_toggle.active:
            self.submit_compare()

    def submit_basin(self):
        if self.computer is None or self.closed:
            return
        _dim([self.basin_fig], True)
        self.computer.submit("basin", R.basin_stages(self.params))

    def submit_run(self):
        if self.computer is None or self.closed:
            return
        _dim(self.run_figs, True)
        self.computer.submit("run", R.run_stages(self.params, self.state))

    def submit_sweep(self):
        if self.computer is None or self.closed:
            return
        _dim(self.bif_figs, True)
        self.computer.submit("sweep", R.sweep_stages(self.params))

    def submit_compare(self):
        if self.computer is None or self.closed:
            return
        _dim(self.cmp_figs.values(), True)
        self.computer.submit("compare", R.compare_stages(self.params))

    # ---------------------------------------------------------------------------------------
    # exports
    # ---------------------------------------------------------------------------------------
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
        self.status[view].text = _progress_html("drawing the PNG", 0.0)

        def done(update):
            def later():
                self._drawing = False
                update()
            self.doc.add_next_tick_callback(later)

        def draw():
            try:
                data, name = _png(view, shown, colour_by)
            except Exception as exc:  # said in the page; the app goes on
                msg = f"{type(exc).__name__}: {exc}"
                done(lambda: setattr(self.status[view], "text", _error_html(msg)))
                return

            def send():
                self.download.data = dict(name=[name], b64=[data], mime=["image/png"])
                self.status[view].text = ""
            done(send)
        threading.Thread(target=draw, daemon=True, name="rockjit-explore-png").start()


def _png(view, shown, colour_by):
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


def document(doc, pages=None):
    """The Bokeh application's function, one call per session: a placeholder until the page's
    websocket is open and the page has loaded (Bokeh's ``DocumentReady``, which only the
    browser's websocket can carry), then the explorer, computing, if fewer than
    ``pages.limit`` pages compute already (:class:`.pages.Pages`)."""
    doc.title = "rockjit explore"
    wait = Div(text='<div class="rj-connecting" style="color:#555">rockjit explore: '
                    'connecting…</div>', width=600)
    doc.add_root(wait)
    if pages is not None:
        pages.opened()
        doc.on_session_destroyed(lambda ctx: pages.closed())
    built = []

    def ready(event):
        if built:
            return
        if pages is not None and not pages.room():
            wait.text = (f'<div class="rj-full" style="color:#b00020">rockjit explore computes '
                         f'for at most {pages.limit} pages at once: close one of them and '
                         f'reload this page.</div>')
            return
        app = ExplorerApp(doc, pages=pages, root=wait)
        built.append(app)
        if pages is not None:
            pages.claim(app)
        app.start()
    doc.on_event(DocumentReady, ready)
