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

This module holds the page's frame: its controls, its life (start, the websocket watch,
close), the worker's events and the submissions. Each view is a panel of its own, which
:class:`ExplorerApp` mixes in: :mod:`.basin_panel`, :mod:`.run_panel`, :mod:`.sweep_panel`
(the bifurcation diagram), :mod:`.compare_panel` (both laws); :mod:`.export` gives each view's
PNG and Python call; :mod:`.drawing` the colours, images and HTML pieces they share.
"""

from __future__ import annotations

import html
from functools import partial

from bokeh.events import DocumentReady
from bokeh.layouts import column, row
from bokeh.models import ColumnDataSource, CustomJS, Div, NumericInput, Select, Slider

from ..plotting import style
from . import requests as R
from .basin_panel import BasinPanel
from .compare_panel import ComparePanel
from .drawing import dim, error_html, plain_text, progress_html
from .export import Exports
from .run_panel import RunPanel
from .sweep_panel import SweepPanel
from .worker import Computer

__all__ = ["ExplorerApp", "document"]

#: How often a page looks whether its websocket is still open, in milliseconds.
WATCH_MS = 400


class ExplorerApp(BasinPanel, RunPanel, SweepPanel, ComparePanel, Exports):
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
            status.text = progress_html(event.stage, event.fraction)
        elif event.kind == "error":
            status.text = error_html(event.message)
        elif event.kind == "done":
            status.text = ""
        elif event.kind == "result":
            getattr(self, f"_show_{event.channel}")(event.value)
            if not event.final:
                status.text = progress_html(f"{event.stage} shown; refining", 1.0)

    # ---------------------------------------------------------------------------------------
    # the page
    # ---------------------------------------------------------------------------------------
    def _build(self):
        """Build the page: its controls, the views' panels, the layout and the timing log."""
        # fixed sizes: a progress update rerenders the line without laying the page out again
        self.status = {c: Div(text="", width=280, height=40, css_classes=[f"rj-status-{c}"])
                       for c in ("basin", "run", "sweep", "compare")}
        self.errors = {}
        self.w = {}
        self.controls = self._build_controls()
        self.download = self._download_source()
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
        self._log_timings()
        self.doc.title = "rockjit explore"

    def _build_controls(self):
        """The column of controls (block, forcing, integration), each with its error line."""
        p = self.params
        number = self._number
        controls = [Div(text="<b>Block</b>"),
                    number("hb", "h/b (slenderness)", p.hb),
                    self._law_control(p.law),
                    number("e", "e (constant law)", p.e)]
        self.w["e"].visible = p.law == "constant"
        controls += [number("xi", "ξ (viscous damping)", p.xi),
                     Div(text="<b>Forcing</b>"),
                     self._alpha_slider(p.alpha),
                     number("alpha", "α", p.alpha),
                     number("omega", "ω (frequency Ω/Ω₀)", p.omega),
                     number("phase", "forcing phase φ [rad]", p.phase),
                     Div(text="<b>Integration</b>"),
                     number("n_steps", "N (steps per period)", p.n_steps, mode="int",
                            placeholder="default"),
                     number("periods", f"periods (at most {R.MAX_PERIODS:,})", p.periods,
                            mode="int")]
        self.limits = Div(text=self._limits_html(), width=215, css_classes=["rj-limits"])
        controls.append(self.limits)
        controls.append(Div(text='<div style="color:#666;font-size:11px;max-width:215px">'
                                 'A value the library refuses is shown here with its message '
                                 'and the views keep the last accepted parameters.</div>'))
        return column(*controls, width=230, css_classes=["rj-controls"])

    def _number(self, name, title, value, mode="float", placeholder=""):
        """The number box of parameter ``name`` (``self.w[name]``) with its error line."""
        w = NumericInput(title=title, value=value, mode=mode, width=210,
                         placeholder=placeholder, css_classes=[f"rj-{name}"])
        w.on_change("value", lambda attr, old, new, name=name: self._control(name, new))
        self.w[name] = w
        return self._with_error(name, w)

    def _law_control(self, value):
        """The restitution law's menu (``self.w["law"]``) with its error line."""
        law = Select(title="restitution law", value=value, width=210, css_classes=["rj-law"],
                     options=[(k, plain_text(v)) for k, v in style.LAW_NAMES.items()])
        law.on_change("value", lambda attr, old, new: self._control("law", new))
        self.w["law"] = law
        return self._with_error("law", law)

    def _alpha_slider(self, value):
        """The amplitude's slider (``self.w["alpha_slider"]``), taken when it is let go."""
        slider = Slider(title="α (amplitude A/R)", start=0.0, end=1.5, step=0.001, value=value,
                        width=210, css_classes=["rj-alpha-slider"])
        slider.on_change("value_throttled",
                         lambda attr, old, new: self._control("alpha", new, source="slider"))
        self.w["alpha_slider"] = slider
        return slider

    @staticmethod
    def _download_source():
        """A data source whose new data the browser saves as a file (the views' exports)."""
        download = ColumnDataSource(data=dict(name=[], b64=[], mime=[]))
        download.js_on_change("data", CustomJS(args=dict(src=download), code="""
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
        return download

    def _log_timings(self):
        """The page's own timing log, window.rockjitLog: [what, value, time in ms], stamped
        when the user changes alpha and after the frame that shows a new basin or diagram
        (benchmarks/bench_explore.py reads it; nothing polls the page's DOM)."""
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

    def _ignored(self, channel, what):
        """Say in the view's status line that an event was ignored (the app goes on)."""
        self.status[channel].text = (f'<div class="rj-ignored" style="color:#8a5a00;'
                                     f'font-size:12px">ignored: {html.escape(what)}</div>')

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
            err.text = error_html(msg)
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
        dim([self.basin_fig], True)
        self.computer.submit("basin", R.basin_stages(self.params))

    def submit_run(self):
        if self.computer is None or self.closed:
            return
        dim(self.run_figs, True)
        self.computer.submit("run", R.run_stages(self.params, self.state))

    def submit_sweep(self):
        if self.computer is None or self.closed:
            return
        dim(self.bif_figs, True)
        self.computer.submit("sweep", R.sweep_stages(self.params))

    def submit_compare(self):
        if self.computer is None or self.closed:
            return
        dim(self.cmp_figs.values(), True)
        self.computer.submit("compare", R.compare_stages(self.params))


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
