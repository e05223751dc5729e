"""``rockjit explore``'s defences: the Host header of every request and the Origin of the
websocket are checked (DNS rebinding, cross-site requests), a request of the page computes
nothing until its websocket is open, the explorer's limits refuse work too long for an
interactive tool, a grid stops within a chunk whose work is bounded, closing the tab stops the
work, and browser events with NaN or infinite coordinates are ignored.

Every server here is bound to a loopback address (127.0.0.1, or ::1 where the machine has
one); no request leaves the machine. The browser parts need Playwright and a system Chromium
and are skipped otherwise (as in ``test_explore.py``).
"""

from __future__ import annotations

import asyncio
import http.client
import importlib.util
import math
import re
import socket
import threading
import time

import numpy as np
import pytest

import rockjit
from rockjit.explorer import requests as R
from rockjit.explorer.worker import Cancelled

pytestmark = pytest.mark.skipif(importlib.util.find_spec("bokeh") is None,
                                reason="the explore extra is not installed")


def _workers():
    """The explorer's worker threads alive in this process (by the thread's name)."""
    return [t for t in threading.enumerate() if t.name == "rockjit-explore" and t.is_alive()]


def _request(port, host, path="/", address="127.0.0.1", headers=()):
    """``(status, body)`` of a GET sent to ``address:port`` with the ``Host`` header ``host``
    (``None``: no Host header) and other ``headers``."""
    c = http.client.HTTPConnection(address, port, timeout=30)
    try:
        c.putrequest("GET", path, skip_host=True, skip_accept_encoding=True)
        if host is not None:
            c.putheader("Host", host)
        for k, v in headers:
            c.putheader(k, v)
        c.endheaders()
        r = c.getresponse()
        return r.status, r.read()
    finally:
        c.close()


def _websocket(address, port, origin, token):
    """The HTTP status of the websocket's opening request with this ``Origin`` (``None``: none):
    101 when it opened (and Bokeh acknowledged it), else the refusal's status."""
    from tornado.httpclient import HTTPClientError, HTTPRequest
    from tornado.websocket import WebSocketClosedError, websocket_connect

    host = f"[{address}]" if ":" in address else address

    async def go():
        req = HTTPRequest(f"ws://{host}:{port}/ws",
                          headers={"Origin": origin} if origin is not None else {},
                          request_timeout=30)
        try:
            conn = await websocket_connect(req, subprotocols=["bokeh", token])
        except HTTPClientError as exc:
            return exc.code
        except WebSocketClosedError:
            return None
        try:
            msg = await asyncio.wait_for(conn.read_message(), 30)
            return 101 if msg is not None else None
        finally:
            conn.close()
    return asyncio.run(go())


def _token(body):
    return re.search(rb'"token":"([^"]+)"', body).group(1).decode()


@pytest.fixture(scope="module")
def server():
    """An explorer on 127.0.0.1, in this process: its handle."""
    from rockjit.explorer.server import start
    h = start(browser=False, quiet=True)
    try:
        yield h
    finally:
        h.stop()


# ---------------------------------------------------------------------------------------------
# the Host and Origin checks
# ---------------------------------------------------------------------------------------------

def test_a_request_naming_another_host_is_refused(server):
    port = server.port
    before = server.stats()["sessions"]
    refused = ["evil.example", f"evil.example:{port}", f"127.0.0.1.evil.example:{port}",
               f"localhost.evil.example:{port}", f"127.0.0.2:{port}", f"[::1]:{port}",
               "127.0.0.1:x", "127.0.0.1:80:80", "", None]
    for host in refused:
        for path in ("/", "/ws", "/static/js/bokeh.min.js", "/autoload.js"):
            status, body = _request(port, host, path)
            assert status == 403, (host, path, status)
            assert body.startswith(b"rockjit explore: refused:")
    # no session was opened by any of them
    assert server.stats()["sessions"] == before
    for host in (f"127.0.0.1:{port}", f"localhost:{port}", f"LOCALHOST:{port}", "127.0.0.1",
                 "localhost:8000"):  # a forwarded port names this server too
        status, body = _request(port, host)
        assert status == 200 and b"<title>rockjit explore</title>" in body, host


def test_a_page_request_computes_nothing_until_a_websocket_is_open(server):
    assert _workers() == []
    s0 = server.stats()["sessions"]
    for _ in range(5):  # as five <img> tags of another site's page would
        status, _body = _request(server.port, f"127.0.0.1:{server.port}")
        assert status == 200
    time.sleep(0.5)  # what a page would have started, it would have started by now
    assert _workers() == []
    stats = server.stats()
    assert stats["sessions"] == s0 + 5
    assert stats["pages"] == 0 and stats["workers"] == 0
    assert _workers() == []


def test_origins_other_than_the_page_are_refused(server):
    port = server.port
    host = f"127.0.0.1:{port}"
    for origin in ("http://evil.example", f"http://evil.example:{port}", "null",
                   f"http://127.0.0.1:{port + 1}", f"file://127.0.0.1:{port}",
                   f"http://localhost:{port}"):  # the page is 127.0.0.1's: not the same origin
        status, _ = _request(port, host, headers=[("Origin", origin)])
        assert status == 403, origin
    status, body = _request(port, host, headers=[("Origin", f"http://{host}")])
    assert status == 200
    token = _token(body)
    assert _websocket("127.0.0.1", port, "http://evil.example", token) == 403
    assert _websocket("127.0.0.1", port, None, token) == 403
    assert _websocket("127.0.0.1", port, f"http://{host}", token) == 101
    # a websocket alone (no page loaded in a browser) still computes nothing
    assert server.stats()["workers"] == 0 and _workers() == []


def _has_ipv6_loopback():
    if not socket.has_ipv6:
        return False
    try:
        with socket.socket(socket.AF_INET6, socket.SOCK_STREAM) as s:
            s.bind(("::1", 0))
        return True
    except OSError:
        return False


@pytest.mark.skipif(not _has_ipv6_loopback(), reason="this machine has no IPv6 loopback")
def test_the_ipv6_loopback_works():
    from rockjit.explorer.server import start
    h = start(address="::1", browser=False, quiet=True)
    try:
        assert h.url == f"http://[::1]:{h.port}/"
        status, body = _request(h.port, f"[::1]:{h.port}", address="::1")
        assert status == 200
        assert _websocket("::1", h.port, f"http://[::1]:{h.port}", _token(body)) == 101
        assert _request(h.port, f"evil.example:{h.port}", address="::1")[0] == 403
    finally:
        h.stop()


def test_which_hosts_each_address_accepts():
    """The policy against a table written out by hand."""
    from rockjit.explorer.guard import HostPolicy
    cases = {
        "127.0.0.1": (["127.0.0.1:1", "localhost", "LocalHost:9"],
                      ["[::1]:1", "127.0.0.2", "evil.example", "192.168.1.5:1"]),
        "::1": (["[::1]:1", "localhost:1", "[0:0:0:0:0:0:0:1]:1"],
                ["127.0.0.1", "::1", "evil.example"]),
        "0.0.0.0": (["192.168.1.5:1", "10.0.0.1", "localhost:1", "127.0.0.1:1",
                     f"{socket.gethostname()}:1"],
                    ["evil.example:1", "192.168.1.5.evil.example", "1.2.3"]),
        "::": (["[fe80::1]:1", "192.168.1.5:1", "localhost"], ["evil.example"]),
    }
    for address, (yes, no) in cases.items():
        policy = HostPolicy(address)
        for host in yes:
            assert policy.allows_host(host), (address, host)
        for host in no:
            assert not policy.allows_host(host), (address, host)
    extra = HostPolicy("127.0.0.1", allow_hosts=["Box.Lab"])
    assert extra.allows_host("box.lab:8000") and not extra.allows_host("lab:8000")
    for bad in ("", "a b", "*.lab", "x" * 300):
        with pytest.raises(ValueError, match="allow_hosts"):
            HostPolicy("127.0.0.1", allow_hosts=[bad])


def test_every_address_lets_bokehs_own_origin_check_pass_its_pages():
    """Bokeh checks the websocket's origin again with its own patterns: they must let in the
    pages the policy lets in (else ``--address 0.0.0.0`` or ``::1`` could not be used)."""
    from bokeh.server.util import check_allowlist

    from rockjit.explorer.guard import HostPolicy
    for address, hosts in (("127.0.0.1", ["127.0.0.1:5006", "localhost:5006"]),
                           ("::1", ["[::1]:5006", "localhost:5006"]),
                           ("0.0.0.0", ["192.168.1.5:5006", "localhost:5006"]),
                           ("::", ["[fe80::1]:5006", "10.1.2.3:5006"])):
        policy = HostPolicy(address)
        for host in hosts:
            assert policy.allows_origin(f"http://{host}", host)
            assert check_allowlist(host, policy.websocket_origins()), (address, host)
        assert not policy.allows_origin("http://evil.example:5006", hosts[0])


def test_an_address_other_than_loopback_warns_that_it_exposes_the_app():
    from rockjit.explorer.server import exposure_warning
    for address in ("0.0.0.0", "::", "192.168.1.5", "fe80::1"):
        text = exposure_warning(address, 5006)
        assert text is not None and "\n" not in text
        assert address in text and "network" in text and "5006" in text
    for address in ("127.0.0.1", "::1", "localhost", "127.0.0.2"):
        assert exposure_warning(address, 5006) is None


# ---------------------------------------------------------------------------------------------
# limits and cancellation
# ---------------------------------------------------------------------------------------------

def _grid_n(p):
    """Steps per period the library's basin uses for these parameters (its own plan)."""
    plan = rockjit.basin.plan(p.block(), p.forcing(), 4, integration=p.integration())
    return plan.settings["n_steps"]


@pytest.mark.parametrize("change", [
    dict(periods=4000), dict(periods=4001), dict(periods=10**5), dict(periods=5 * 10**6),
    dict(n_steps=512), dict(n_steps=512, periods=500), dict(n_steps=1024, periods=250),
    dict(omega=0.01), dict(omega=0.01, periods=40), dict(omega=0.01, periods=41),
    dict(xi=100.0), dict(xi=100.0, periods=700),
])
def test_the_explorers_limits(change):
    """Accepted exactly when periods <= 4000 and periods x N <= 256000, N as the library's own
    basin resolves it."""
    p = R.Params().with_(**change)
    n = _grid_n(p)
    ok = p.periods <= 4000 and p.periods * n <= 256_000
    if ok:
        p.check()
    else:
        with pytest.raises(ValueError, match="periods") as exc:
            p.check()
        assert "explorer" in str(exc.value)
        if p.periods <= 4000:
            assert f"{p.periods} × {n}" in str(exc.value)


def test_an_empty_box_is_refused_with_the_controls_name():
    for name in ("hb", "alpha", "omega", "xi", "phase", "periods"):
        for empty in (None, "", "  "):
            with pytest.raises(ValueError, match=f"^{name} must be a number"):
                R.Params().with_(**{name: empty}).check()
    assert R.Params().with_(n_steps=None).check().n_steps is None  # empty N: the default


@pytest.mark.parametrize("periods, n_steps, view", [
    (4000, None, "basin"), (250, 1024, "basin"), (4000, None, "sweep"),
])
def test_the_heaviest_grids_stop_within_a_chunk_of_bounded_work(periods, n_steps, view):
    """The real library's progress calls: a grid at the explorer's heaviest settings reports
    (and can be stopped) after chunks no larger in work than the default settings' chunk
    (256 cells of 500 × 64 steps for a basin, 32 for a bifurcation diagram)."""
    p = R.Params(periods=periods, n_steps=n_steps).check()
    stage = R.sweep_stages(p)[0] if view == "sweep" else R.basin_stages(p, levels=(40,))[0]
    base = 32 if view == "sweep" else 256
    done = []

    def progress(d, total):
        done.append(d)
        if len(done) == 3:
            raise Cancelled
    with pytest.raises(Cancelled):
        stage(progress)
    chunk = done[2] - done[1]
    work = periods * max(_grid_n(p), 64)
    assert 2 <= chunk and chunk * work <= base * 500 * 64, (chunk, work)


def test_the_heaviest_cell_run_is_stopped_with_its_request():
    """A cell's run at the explorer's largest work per cell, superseded as it starts: nothing of
    it is shown and the worker is free again (the bound is a guard against a hang only)."""
    from rockjit.explorer.worker import Computer
    events, lock = [], threading.Lock()

    def publish(ev):
        with lock:
            events.append(ev)
    p = R.Params(periods=4000).check()
    assert p.periods * p.grid_n_steps() == R.MAX_CELL_STEPS
    basin = R.basin_stages(p.with_(periods=20), levels=(20,))[0]().result
    lab = np.asarray(basin.label)
    i, j = np.argwhere(lab == list(basin.names).index("symmetric"))[0]
    state = (float(basin.theta0[i]), float(basin.dtheta0[j]))
    c = Computer(publish)
    try:
        started = threading.Event()
        run = R.run_stages(p, state)[0]

        def stage(progress):
            started.set()
            return run(progress)
        stage.label = "run"
        old = c.submit("run", [stage])
        assert started.wait(30)
        c.cancel("run")
        assert c.wait_idle(60)
    finally:
        c.close()
    assert not any(e.request == old and e.kind in ("result", "done") for e in events)
    assert not c.alive


# ---------------------------------------------------------------------------------------------
# the page's events
# ---------------------------------------------------------------------------------------------

@pytest.fixture()
def app():
    """The page on a document of its own, not started (nothing computes)."""
    from bokeh.document import Document

    from rockjit.explorer.app import ExplorerApp
    a = ExplorerApp(Document())
    yield a
    a.close()


def test_events_with_nan_or_infinite_coordinates_are_ignored(app):
    from bokeh.events import RangesUpdate, Tap
    bif = app.bif_figs[0]
    before = app.params
    end = app.w["alpha_slider"].end
    for bad in (math.nan, math.inf, -math.inf):
        app._bif_range(RangesUpdate(bif, x0=0.5, x1=bad, y0=0.0, y1=1.0))
        app._bif_range(RangesUpdate(bif, x0=bad, x1=0.9, y0=0.0, y1=1.0))
        app._bif_tap(Tap(bif, x=bad, y=0.0))
        app._basin_tap(Tap(app.basin_fig, x=bad, y=0.1))
        app._basin_tap(Tap(app.basin_fig, x=0.1, y=bad))
        assert app.params == before
        assert app.w["alpha_slider"].end == end and math.isfinite(app.w["alpha_slider"].end)
        assert "ignored" in app.status["sweep"].text
    # a finite zoom and click still act
    app._bif_range(RangesUpdate(bif, x0=0.5, x1=0.9, y0=0.0, y1=1.0))
    assert app.params.alpha_range == (0.5, 0.9)
    app._bif_tap(Tap(bif, x=0.7, y=0.0))
    assert app.params.alpha == 0.7 and app.w["alpha"].value == 0.7


def test_an_empty_phase_box_is_refused_and_the_app_goes_on(app):
    app._control("phase", None)
    assert app.errors["phase"].visible and "phase must be a number" in app.errors["phase"].text
    assert app.params.phase == 0.0
    app._control("phase", 0.5)
    assert not app.errors["phase"].visible and app.params.phase == 0.5


def test_attractor_names_are_plain_text_with_a_lim_column(app):
    from rockjit.plotting.style import attractor_names
    p = R.Params(periods=100).check()
    view = R.basin_stages(p, levels=(30,))[0]()
    text = app._basin_info_html(view)
    names = attractor_names(view.result.attractors)
    assert any("$" in n for n in names)  # the figures' names carry math
    assert "$" not in text
    for n in names:
        assert n.replace("$", "") in text
    lim = view.measures["integrity"]["LIM"]
    cells = re.findall(r"class='rj-lim'>([^<]*)<", text)
    assert len(cells) == len(view.result.attractors)
    for a, cell in zip(view.result.attractors, cells):
        v = lim.get(a.id)
        assert cell == ("–" if v is None else f"{float(v):.3g}")


# ---------------------------------------------------------------------------------------------
# in a browser: the page computes once open, stops when closed; what it shows
# ---------------------------------------------------------------------------------------------

def _browser_missing():
    import shutil
    if importlib.util.find_spec("playwright") is None:
        return "Playwright is not installed (pip install playwright)"
    if not (shutil.which("chromium") or shutil.which("chromium-browser")):
        return "no system Chromium (apt-get install chromium)"
    return None


@pytest.mark.skipif(_browser_missing() is not None, reason=str(_browser_missing()))
def test_a_closed_tab_stops_its_work(server):
    import shutil

    from playwright.sync_api import sync_playwright
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=chromium, args=["--no-sandbox", "--disable-gpu"])
        try:
            page = b.new_page(viewport={"width": 1600, "height": 1400})
            page.goto(server.url)
            page.wait_for_selector(".rj-basin-shown", timeout=120_000)
            assert server.stats()["pages"] == 1 and len(_workers()) == 1
            # the limits beside the integration's controls, as the explorer enforces them
            limits = page.locator(".rj-limits-text").inner_text()
            assert f"{R.MAX_PERIODS:,}" in limits and f"{R.MAX_CELL_STEPS:,}" in limits
            # the attractors' table: plain names, its LIM column inside the panel
            page.locator(".rj-colour-by button").nth(1).click()
            page.wait_for_selector(".rj-attractors", timeout=60_000)
            table = page.locator(".rj-attractors")
            assert "$" not in table.inner_text() and "LIM" in table.inner_text()
            panel = page.locator(".rj-basin-info").evaluate(
                "el => el.getBoundingClientRect().right")
            right = [page.locator(".rj-attractors th").last.evaluate(
                "el => el.getBoundingClientRect().right")]
            right += page.locator(".rj-lim").evaluate_all(
                "els => els.map(el => el.getBoundingClientRect().right)")
            assert len(right) > 1 and max(right) <= panel + 0.5, (right, panel)
            # a long computation, then the tab is closed: the work stops
            box = page.locator(".rj-periods input")
            box.fill(str(R.MAX_PERIODS))
            box.press("Enter")
            deadline = time.time() + 30
            while time.time() < deadline and not server.stats()["busy"]:
                time.sleep(0.05)
            assert server.stats()["busy"] == 1
            page.close()
            deadline = time.time() + 20  # a guard against a hang, not a timing
            while time.time() < deadline and _workers():
                time.sleep(0.1)
            assert _workers() == []
            stats = server.stats()
            assert stats["pages"] == 0 and stats["workers"] == 0
        finally:
            b.close()


def test_a_page_draws_one_png_at_a_time(app):
    app.basin_view = R.basin_stages(R.Params(periods=20).check(), levels=(10,))[0]()
    before = {t for t in threading.enumerate() if t.name == "rockjit-explore-png"}
    for _ in range(5):
        app.export_png("basin")
    drawing = {t for t in threading.enumerate() if t.name == "rockjit-explore-png"} - before
    assert len(drawing) <= 1
    assert "another PNG is being drawn" in app.status["basin"].text
    for t in drawing:
        t.join(60)


def _frame_server(address, html_text):
    """A plain HTTP server on ``address`` (loopback) serving ``html_text`` at ``/``; ``None``
    where that address cannot be bound."""
    import functools
    import http.server
    body = html_text.encode()

    class Page(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            self.send_response(200)
            self.send_header("Content-Type", "text/html")
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass
    try:
        srv = http.server.ThreadingHTTPServer((address, 0), functools.partial(Page))
    except OSError:
        return None
    threading.Thread(target=srv.serve_forever, daemon=True).start()
    return srv


@pytest.mark.skipif(_browser_missing() is not None, reason=str(_browser_missing()))
def test_another_sites_page_cannot_frame_the_explorer(server):
    """A page of another origin (here 127.0.0.2, which the explorer does not accept) showing the
    explorer in a frame gets no page: the browser refuses to render it (the response's
    frame-ancestors). A page served by this machine's own name (``localhost``), as a notebook's
    inline view is, gets the explorer."""
    import shutil

    from playwright.sync_api import sync_playwright
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    frame = (f'<html><body><iframe src="{server.url}" width="1200" height="900"></iframe>'
             f'</body></html>')
    other, own = _frame_server("127.0.0.2", frame), _frame_server("127.0.0.1", frame)
    if other is None:
        own.shutdown()
        pytest.skip("127.0.0.2 cannot be bound here")
    try:
        with sync_playwright() as pw:
            b = pw.chromium.launch(executable_path=chromium,
                                   args=["--no-sandbox", "--disable-gpu"])
            try:
                page = b.new_page()
                s0 = server.stats()["sessions"]
                page.goto(f"http://127.0.0.2:{other.server_address[1]}/")
                page.wait_for_load_state("load")
                deadline = time.time() + 30  # the frame's request reaches the server...
                while time.time() < deadline and server.stats()["sessions"] == s0:
                    time.sleep(0.05)
                assert server.stats()["sessions"] > s0
                child = page.frames[1]
                child.wait_for_load_state("load")
                assert child.url != server.url  # ...and its answer is not rendered
                assert not child.locator(".rj-connecting, .rj-view").count()
                assert server.stats()["pages"] == 0
                page.goto(f"http://localhost:{own.server_address[1]}/")
                page.frames[1].wait_for_selector(".rj-basin-shown", timeout=120_000)
                assert server.stats()["pages"] == 1
                page.close()
            finally:
                b.close()
    finally:
        other.shutdown()
        own.shutdown()
    deadline = time.time() + 20
    while time.time() < deadline and server.stats()["pages"]:
        time.sleep(0.1)


def test_pages_beyond_the_limit_are_told_to_close_one():
    """The document function of each session: a placeholder until the page is ready in the
    browser; then the explorer, while fewer than the limit compute; else a message."""
    from bokeh.document import Document
    from bokeh.events import DocumentReady

    from rockjit.explorer.app import document
    from rockjit.explorer.pages import Pages
    pages = Pages(limit=1)
    docs = [Document(), Document()]
    for d in docs:
        document(d, pages=pages)
    assert pages.stats() == dict(sessions=2, pages=0, workers=0, busy=0)
    assert _workers() == []
    try:
        for d in docs:
            d.callbacks.trigger_event(DocumentReady())
        first = docs[0].select_one({"css_classes": ["rj-controls"]})
        assert first is not None  # the first page was built
        full = [r for r in docs[1].roots]
        assert len(full) == 1 and "at most 1 pages" in full[0].text
        stats = pages.stats()
        assert stats["pages"] == 1 and stats["workers"] == 1 and len(_workers()) == 1
    finally:
        pages.close_all()
    deadline = time.time() + 30
    while time.time() < deadline and _workers():
        time.sleep(0.05)
    assert _workers() == [] and pages.stats()["pages"] == 0 and pages.room()
