"""``rockjit explore``: its compute side without a browser (the refinement sequence, a superseded
request never publishing, the Python call text reproducing each view, the library's messages
for bad values), then the app in a real headless Chromium: it starts bound to 127.0.0.1, the
basin renders, moving alpha recomputes it, a click on a cell shows the run the library gives for
that cell, a box zoom recomputes the bifurcation diagram, and the console stays free of errors;
``--address ::1`` serves on IPv6's loopback. The server's defences (Host and Origin checks,
limits, cancellation, a closed tab) are ``test_explore_security.py``'s.

The browser part needs the ``explore`` extra (Bokeh), Playwright and a system Chromium
(``apt-get install chromium``; Playwright's own browsers are never downloaded); it is skipped,
saying which is missing, otherwise. ``ROCKJIT_EXPLORE_TIMINGS=path`` makes it write its timings
(JSON) there: ``benchmarks/bench_explore.py`` runs it that way.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import shutil
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import rockjit
from rockjit import Block, Harmonic
from rockjit.explorer import requests as R
from rockjit.explorer.worker import Cancelled, Computer

ROOT = Path(__file__).resolve().parents[2]


# ---------------------------------------------------------------------------------------------
# the compute side
# ---------------------------------------------------------------------------------------------

def _collector():
    events, lock = [], threading.Lock()

    def publish(ev):
        with lock:
            events.append(ev)
    return events, publish


def test_basin_refines_coarse_to_fine_and_the_last_stage_is_final():
    p = R.Params(periods=20).check()
    stages = R.basin_stages(p)
    assert [s.label for s in stages] == ["basin 50\u00b2", "basin 100\u00b2", "basin 200\u00b2"]
    assert R.REFINE == (50, 100, 200)
    events, publish = _collector()
    c = Computer(publish)
    try:
        n = c.submit("basin", R.basin_stages(p, levels=(8, 12, 16)))
        assert c.wait_idle(120)
    finally:
        c.close()
    results = [e for e in events if e.kind == "result"]
    assert [e.value.grid for e in results] == [8, 12, 16]
    assert [e.final for e in results] == [False, False, True]
    assert all(e.request == n for e in events)
    assert [e.value.result.label.shape for e in results] == [(8, 8), (12, 12), (16, 16)]
    assert events[-1].kind == "done"
    # progress went up within each stage, from 0 to 1
    for grid in (8, 12, 16):
        fr = [e.fraction for e in events if e.kind == "progress" and e.stage == f"basin {grid}\u00b2"]
        assert fr[0] == 0.0 and fr[-1] == 1.0 and fr == sorted(fr)


def _blocking_stage(started, release, label="blocking"):
    """A stage that reports progress until released, as a grid's chunks would."""
    def stage(progress):
        started.set()
        k = 0
        while not release.is_set():
            progress(k % 10, 10)  # raises Cancelled once superseded
            k += 1
            time.sleep(0.005)
        progress(10, 10)
        return label
    stage.label = label
    return stage


def test_a_superseded_request_never_publishes_a_result():
    events, publish = _collector()
    c = Computer(publish)
    try:
        started, release = threading.Event(), threading.Event()
        old = c.submit("basin", [_blocking_stage(started, release, "old")])
        assert started.wait(10)
        new = c.submit("basin", [lambda progress: "new"])
        release.set()
        assert c.wait_idle(10)
    finally:
        c.close()
    assert not any(e.request == old and e.kind in ("result", "done", "error") for e in events)
    assert [e.value for e in events if e.kind == "result"] == ["new"]
    assert not c.is_current("basin", old)


def test_a_finished_but_superseded_stage_is_dropped_under_the_lock():
    """A stage that returns after its request was superseded (no progress call in between)
    publishes nothing: the check and the publication happen under the submit's lock."""
    events, publish = _collector()
    c = Computer(publish)
    try:
        started, go = threading.Event(), threading.Event()

        def slow(progress):
            started.set()
            go.wait(10)
            return "stale"
        old = c.submit("run", [slow])
        assert started.wait(10)
        c.submit("run", [lambda progress: "fresh"])
        go.set()
        assert c.wait_idle(10)
    finally:
        c.close()
    assert [e.value for e in events if e.kind == "result"] == ["fresh"]
    assert not any(e.request == old and e.kind != "progress" for e in events)


def test_cancel_stops_a_grid_between_chunks():
    """The real library: a superseded basin stops at its next chunk (Execution(progress=...))."""
    p = R.Params(periods=200).check()
    stage = R.basin_stages(p, levels=(60,))[0]
    calls = []

    def progress(done, total):
        calls.append(done)
        if len(calls) == 3:
            raise Cancelled
    with pytest.raises(Cancelled):
        stage(progress)
    assert len(calls) == 3 and calls[-1] < 60 * 60


def test_a_more_urgent_channel_goes_first_and_the_interrupted_stage_runs_again():
    events, publish = _collector()
    c = Computer(publish)
    try:
        started, release = threading.Event(), threading.Event()
        runs = []

        def sweep(progress):
            runs.append("sweep")
            started.set()
            for k in range(400):
                progress(k, 400)
                time.sleep(0.005)
            return "sweep done"
        c.submit("sweep", [sweep])
        assert started.wait(10)
        c.submit("run", [lambda progress: "run done"])
        assert c.wait_idle(30)
    finally:
        c.close()
    results = [e.value for e in events if e.kind == "result"]
    assert results == ["run done", "sweep done"]
    assert runs == ["sweep", "sweep"]  # preempted once, run again from its start


def test_an_error_is_the_librarys_message_and_the_worker_goes_on():
    events, publish = _collector()
    c = Computer(publish)
    try:
        def refused(progress):
            rockjit.Block(hb=0.5, law="housner")
        c.submit("basin", [refused])
        assert c.wait_idle(10)
        c.submit("basin", [lambda progress: "after"])
        assert c.wait_idle(10)
    finally:
        c.close()
    err = [e for e in events if e.kind == "error"]
    with pytest.raises(ValueError) as lib:
        rockjit.Block(hb=0.5, law="housner")
    assert len(err) == 1 and err[0].message == str(lib.value)
    assert [e.value for e in events if e.kind == "result"] == ["after"]


@pytest.mark.parametrize("change, field", [
    (dict(hb=0.5), "hb"),                 # Housner needs hb >= 1/sqrt(2)
    (dict(hb=float("nan")), "hb"),
    (dict(omega=0.0), "omega"),
    (dict(periods=0), "periods"),
    (dict(n_steps=7), "n_steps"),
    (dict(law="newton"), "law"),
    (dict(law="constant", e=1.5), "e"),
    (dict(xi=-1.0), "xi"),
    (dict(alpha=-0.1), "alpha"),
    (dict(alpha_range=(0.9, 0.3)), "alpha_range"),
])
def test_a_bad_value_gives_the_librarys_own_message(change, field):
    with pytest.raises(ValueError) as ours:
        R.Params().with_(**change).check()
    assert field in str(ours.value)
    # the same message as the library's own call where the library has one
    p = R.Params().with_(**change)
    if field in ("hb", "law", "e", "xi"):
        with pytest.raises(ValueError) as lib:
            Block(hb=p.hb, law=p.law, e=p.e if p.law == "constant" else None, xi=p.xi)
        assert str(ours.value) == str(lib.value)
    elif field in ("omega", "alpha"):
        with pytest.raises(ValueError) as lib:
            rockjit.basin(Block(hb=1), Harmonic(alpha=p.alpha, omega=p.omega), grid=4)
        assert str(ours.value) == str(lib.value)
    elif field in ("periods", "n_steps"):
        with pytest.raises(ValueError) as lib:
            rockjit.Integration(n_steps=p.n_steps, periods=p.periods)
        assert str(ours.value) == str(lib.value)


def test_controls_noise_is_cleaned_and_numbers_print_exactly():
    assert R.clean_number(0.66 + 0.01) == 0.67
    assert R.clean_number("abc") == "abc" and R.clean_number(None) is None
    assert R.python_number(1.0) == "1" and R.python_number(0.66) == "0.66"
    x = np.linspace(-1, 1, 100)[37]
    assert float(R.python_number(x)) == x


def _run_call(text, name):
    ns = {}
    exec(text, ns)  # noqa: S102 - the text is the app's own output
    return ns[name]


def test_the_python_call_of_a_basin_gives_the_same_labels():
    p = R.Params(hb=1.0, law="mao", alpha=0.66, omega=1.3, periods=100).check()
    view = R.basin_stages(p, levels=(24,))[0]()
    assert "rockjit.basin(Block(hb=1, law='mao'), Harmonic(alpha=0.66, omega=1.3), grid=24" \
        in view.call
    b = _run_call(view.call, "b")
    assert np.array_equal(b.label, view.result.label)
    assert np.array_equal(b.attractor, view.result.attractor)


def test_the_python_call_of_a_constant_law_phase_and_settings():
    p = R.Params(law="constant", e=0.7, phase=0.3, n_steps=96, periods=60, xi=0.01).check()
    view = R.basin_stages(p, levels=(12,))[0]()
    assert "e=0.7" in view.call and "phase=0.3" in view.call and "n_steps=96" in view.call
    assert np.array_equal(_run_call(view.call, "b").label, view.result.label)


def test_the_python_call_of_a_sweep_gives_the_same_labels():
    p = R.Params(periods=60, alpha_range=(0.5, 0.9)).check()
    view = R.sweep_stages(p)[0]()
    sw = _run_call(view.call, "sw")
    assert sw.alpha.size == R.SWEEP_POINTS
    assert np.array_equal(sw.alpha, view.result.alpha)
    assert np.array_equal(sw.label, view.result.label)


def test_the_python_call_of_a_run_gives_the_same_behaviour():
    p = R.Params(periods=100).check()
    basin = R.basin_stages(p, levels=(20,))[0]().result
    state = (float(basin.theta0[13]), float(basin.dtheta0[5]))
    view = R.run_stages(p, state)[0]()
    ns = {}
    exec(view.call, ns)  # noqa: S102
    assert (ns["behaviour"], ns["period"]) == (view.behaviour, view.period)
    assert np.array_equal(ns["res"].trajectory, view.result.trajectory)
    # the run uses the basin's steps per period: the cell's own computation, carried on
    assert view.result.n_steps == basin.settings["n_steps"]


def test_the_python_call_of_both_laws_gives_the_same_agreement():
    p = R.Params(periods=60, alpha=0.5).check()
    view = R.compare_stages(p, grid=12)[0]()
    ns = {}
    exec(view.call, ns)  # noqa: S102
    assert np.array_equal(ns["same"], view.agree)
    assert ns["percent"] == pytest.approx(view.percent)


def test_nearest_cell():
    b = R.basin_stages(R.Params(periods=20).check(), levels=(11,))[0]().result
    assert R.nearest_cell(b, -1.0, -1.0) == (0, 0)
    assert R.nearest_cell(b, 0.02, 0.19) == (5, 6)
    assert R.nearest_cell(b, 1.2, 0.0) is None


def test_every_view_exports_its_figure_as_a_png():
    pytest.importorskip("bokeh", reason="the explore extra is not installed")
    import base64

    from rockjit.explorer.export import png_of
    p = R.Params(periods=40).check()
    basin = R.basin_stages(p, levels=(10,))[0]()
    views = dict(basin=basin, sweep=R.sweep_stages(p.with_(alpha_range=(0.6, 0.7)))[0](),
                 run=R.run_stages(p, (0.1, 0.2))[0](), compare=R.compare_stages(p, grid=10)[0]())
    for view, shown in views.items():
        for colour_by in ("behaviour", "attractor") if view == "basin" else ("behaviour",):
            data, name = png_of(view, shown, colour_by)
            assert base64.b64decode(data)[:8] == b"\x89PNG\r\n\x1a\n"
            assert name.endswith(".png") and "/" not in name


def test_rockjit_explore_is_the_explorers_function():
    import rockjit.explorer as pkg
    assert rockjit.explore is pkg.explore and callable(rockjit.explore)
    assert pkg.requests is R


def test_the_explorers_laws_are_the_models_table_not_a_copy():
    import rockjit.model
    assert R.LAWS is rockjit.model.LAWS


# ---------------------------------------------------------------------------------------------
# the app in a headless browser
# ---------------------------------------------------------------------------------------------

def _chromium():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


def _browser_missing():
    if importlib.util.find_spec("bokeh") is None:
        return "the explore extra is not installed (pip install 'rockjit[explore]')"
    if importlib.util.find_spec("playwright") is None:
        return "Playwright is not installed (pip install playwright)"
    if _chromium() is None:
        return "no system Chromium (apt-get install chromium)"
    return None


#: True once the page's timing log shows the 100² basin of alpha ``a`` after its last change
#: (the log is the app's window.rockjitLog; polling it every 100 ms costs the page nothing).
WAIT_100 = """([a, text]) => {
  const log = window.rockjitLog || [];
  const changes = log.filter(e => e[0] === 'alpha' && e[1] === a);
  if (!changes.length) return false;
  const t = changes[changes.length - 1][2];
  return log.some(e => e[0] === 'basin' && e[2] >= t && e[1].includes(`data-alpha="${text}"`)
                       && e[1].includes('data-grid="100"'));
}"""

#: The changes of alpha the browser test makes (the last one is 0.62), and the longer list it
#: makes when timing (benchmarks/bench_explore.py: medians of at least 10 changes).
ALPHAS = (0.68, 0.64, 0.62)
ALPHAS_TIMED = (0.64, 0.68, 0.72, 0.70, 0.66, 0.60, 0.64, 0.68, 0.74, 0.66, 0.62)

browser = pytest.mark.skipif(_browser_missing() is not None,
                             reason=str(_browser_missing()))

#: Where each plot's frame is, from Bokeh's own views: a point in data coordinates to a pixel of
#: the page (``y`` null: the frame's middle height).
PIXEL_JS = """([name, x, y]) => {
  function find(v) {
    if (v.model && v.model.name === name) return v;
    for (const c of (v.child_views || [])) { const r = find(c); if (r) return r; }
    return null;
  }
  let pv = null;
  for (const r of Bokeh.index) { pv = find(r); if (pv) break; }
  if (!pv) return null;
  const rect = pv.canvas_view.el.getBoundingClientRect();
  const f = pv.frame;
  const py = y === null ? f.bbox.top + f.bbox.height / 2 : f.y_scale.compute(y);
  return [rect.left + f.x_scale.compute(x), rect.top + py];
}"""


def _listening_addresses(port):
    """Local addresses of the sockets listening on ``port`` (from /proc/net/tcp{,6})."""
    out = []
    for name in ("/proc/net/tcp", "/proc/net/tcp6"):
        try:
            lines = Path(name).read_text().splitlines()[1:]
        except OSError:
            continue
        for line in lines:
            f = line.split()
            local, state = f[1], f[3]
            if state != "0A":  # LISTEN
                continue
            addr, p = local.split(":")
            if int(p, 16) != port:
                continue
            if len(addr) == 8:
                out.append(socket.inet_ntop(socket.AF_INET, bytes.fromhex(addr)[::-1]))
            else:
                b = bytes.fromhex(addr)
                out.append(socket.inet_ntop(socket.AF_INET6, b"".join(
                    b[i:i + 4][::-1] for i in range(0, 16, 4))))
    return out


def _non_loopback_address():
    """One of this machine's own IPv4 addresses other than loopback, if it has one (read from
    the kernel's table of local addresses: nothing is sent anywhere)."""
    try:
        lines = Path("/proc/net/fib_trie").read_text().splitlines()
    except OSError:
        return None
    for prev, line in zip(lines, lines[1:]):
        if "/32 host LOCAL" in line:
            addr = prev.split()[-1]
            if not addr.startswith("127."):
                return addr
    return None


@pytest.fixture(scope="module")
def server():
    """``rockjit explore --no-browser`` in a subprocess; its printed address."""
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.Popen([sys.executable, "-m", "rockjit", "explore", "--no-browser"],
                            cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    line = proc.stdout.readline()
    m = re.search(r"serving on (http://127\.0\.0\.1:(\d+)/)", line)
    if not m:
        proc.kill()
        pytest.fail(f"no address printed: {line!r} {proc.stderr.read()}")
    try:
        yield m.group(1), int(m.group(2)), proc
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()


@browser
def test_the_server_accepts_only_this_machine(server):
    url, port, proc = server
    assert _listening_addresses(port) == ["127.0.0.1"]
    with socket.create_connection(("127.0.0.1", port), timeout=5):
        pass
    other = _non_loopback_address()
    if other is not None:  # the machine's own address on its network: refused
        with pytest.raises(OSError):
            socket.create_connection((other, port), timeout=5).close()


def _assert_palette(png_bytes, names):
    """The picture holds each behaviour's colour of the project's palette."""
    import io

    from PIL import Image

    from rockjit.plotting.figures import BEHAVIOUR_COLOURS
    img = np.asarray(Image.open(io.BytesIO(png_bytes)).convert("RGB")).reshape(-1, 3)
    for name in names:
        h = BEHAVIOUR_COLOURS[name].lstrip("#")
        rgb = np.array([int(h[k:k + 2], 16) for k in (0, 2, 4)])
        share = np.mean(np.all(np.abs(img.astype(int) - rgb) <= 3, axis=1))
        assert share > 0.02, f"{name} ({BEHAVIOUR_COLOURS[name]}) covers {share:.1%}"


@browser
def test_the_app_in_a_browser(server, tmp_path):
    from playwright.sync_api import sync_playwright
    url, port, proc = server
    timings = {"alpha_to_100": [], "alpha_to_50": []}
    errors = []
    with sync_playwright() as pw:
        b = pw.chromium.launch(executable_path=_chromium(),
                               args=["--no-sandbox", "--disable-gpu"])
        page = b.new_page(viewport={"width": 1600, "height": 1400}, accept_downloads=True)
        page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
        page.on("pageerror", lambda e: errors.append(str(e)))
        t0 = time.perf_counter()
        page.goto(url)
        # the basin renders (100², then refined) and the bifurcation diagram
        page.wait_for_selector(".rj-basin-shown[data-grid='100']", timeout=120_000)
        page.wait_for_selector(".rj-sweep-shown", timeout=120_000)
        timings["first_view"] = time.perf_counter() - t0
        call = page.locator(".rj-call-basin pre").inner_text()
        assert "rockjit.basin(Block(hb=1, law='housner'), Harmonic(alpha=0.66, omega=1.3), " \
               "grid=100)" in call
        _assert_palette(page.locator(".rj-view-basin canvas").first.screenshot(),
                        ("symmetric", "overturn"))

        # moving alpha recomputes the basin: 50², then 100² for the new alpha
        alpha_in = page.locator(".rj-alpha input")
        alphas = ALPHAS_TIMED if os.environ.get("ROCKJIT_EXPLORE_TIMINGS") else ALPHAS
        for a in alphas:
            alpha_in.fill(str(a))
            alpha_in.press("Enter")
            page.wait_for_function(WAIT_100, arg=[a, repr(a)], polling=100, timeout=30_000)
            # from the page's own log: the change of alpha, the first frame showing its basins
            log = page.evaluate("() => window.rockjitLog")
            t_change = [e[2] for e in log if e[0] == "alpha" and e[1] == a][-1]

            def shown(grid):
                return min(e[2] for e in log if e[0] == "basin" and e[2] >= t_change
                           and f'data-alpha="{a!r}"' in e[1] and f'data-grid="{grid}"' in e[1])
            timings["alpha_to_50"].append((shown(50) - t_change) / 1e3)
            timings["alpha_to_100"].append((shown(100) - t_change) / 1e3)
            assert shown(50) < shown(100)  # coarse first, then refined
        page.wait_for_selector(".rj-basin-shown[data-final='1'][data-alpha='0.62']",
                               timeout=60_000)
        assert "Harmonic(alpha=0.62, omega=1.3)" in page.locator(".rj-call-basin pre").inner_text()

        # the view's PNG: the figure drawn by rockjit.plotting, downloaded
        with page.expect_download(timeout=30_000) as dl:
            page.locator(".rj-png-basin button").click()
        assert dl.value.suggested_filename.startswith("basin_housner_hb1_alpha0.62")
        assert Path(dl.value.path()).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

        # a click on a known cell shows the run the library gives for it
        theta0, dtheta0 = rockjit.Lattice(200).axes()  # the basin shown: 200², the final one
        i, j = 150, 40
        th, dth = float(theta0[i]), float(dtheta0[j])
        x, y = page.evaluate(PIXEL_JS, ["basin", th, dth])
        page.mouse.click(x, y)
        page.wait_for_selector(".rj-run-behaviour", timeout=30_000)
        call = page.locator(".rj-call-run pre").inner_text()
        assert f"({R.python_number(th)}, {R.python_number(dth)})" in call
        n = R.run_n_steps(R.Params(alpha=0.62))
        expected = rockjit.classify_result(rockjit.simulate(
            Block(hb=1, law="housner"), Harmonic(alpha=0.62, omega=1.3), (th, dth),
            integration=rockjit.Integration(n_steps=n), lyapunov=True))
        shown = page.locator(".rj-run-behaviour").get_attribute("data-behaviour")
        assert shown == expected[0]
        page.locator(".rj-view-run").screenshot(path=str(tmp_path / "run.png"))

        # a box zoom on the bifurcation diagram recomputes it on the zoomed range
        xa, ym = page.evaluate(PIXEL_JS, ["bif", 0.85, None])
        xb, _ = page.evaluate(PIXEL_JS, ["bif", 0.95, None])
        page.mouse.move(xa, ym)
        page.mouse.down()
        page.mouse.move((xa + xb) / 2, ym, steps=5)
        page.mouse.move(xb, ym, steps=5)
        t = time.perf_counter()
        page.mouse.up()
        shown = page.locator(".rj-sweep-shown")
        deadline = time.time() + 30
        while time.time() < deadline:
            a0 = float(shown.get_attribute("data-a0"))
            if abs(a0 - 0.85) < 0.01:
                break
            time.sleep(0.05)
        timings["zoom_to_sweep"] = time.perf_counter() - t
        a0, a1 = float(shown.get_attribute("data-a0")), float(shown.get_attribute("data-a1"))
        assert abs(a0 - 0.85) < 0.01 and abs(a1 - 0.95) < 0.01
        assert int(shown.get_attribute("data-n")) == R.SWEEP_POINTS
        assert "np.linspace(0.85" in page.locator(".rj-call-sweep pre").inner_text()

        # a refused value: the library's message under the control, the app goes on
        hb_in = page.locator(".rj-hb input")
        hb_in.fill("0.5")
        hb_in.press("Enter")
        page.wait_for_selector(".rj-error-hb .rj-refused", timeout=10_000)
        with pytest.raises(ValueError) as lib:
            Block(hb=0.5, law="housner")
        assert str(lib.value) in page.locator(".rj-error-hb .rj-refused").inner_text()
        hb_in.fill("1")
        hb_in.press("Enter")
        alpha_in.fill("0.6")
        alpha_in.press("Enter")
        page.wait_for_selector(".rj-basin-shown[data-alpha='0.6']", timeout=30_000)
        assert not page.locator(".rj-error-hb .rj-refused").count()
        b.close()
    path = os.environ.get("ROCKJIT_EXPLORE_TIMINGS")
    if path:
        Path(path).write_text(json.dumps(timings, indent=1))
    assert errors == [], errors


def _ipv6_loopback():
    try:
        with socket.socket(socket.AF_INET6, socket.SOCK_STREAM) as s:
            s.bind(("::1", 0))
        return True
    except OSError:
        return False


@pytest.mark.skipif(importlib.util.find_spec("bokeh") is None or not _ipv6_loopback(),
                    reason="needs the explore extra and an IPv6 loopback")
def test_the_command_serves_on_the_ipv6_loopback():
    """``rockjit explore --address ::1``: the address printed, the page served to a request
    naming it, and one naming another host refused."""
    import http.client
    env = dict(os.environ, PYTHONPATH=str(ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
    proc = subprocess.Popen([sys.executable, "-m", "rockjit", "explore", "--no-browser",
                             "--address", "::1"], cwd=ROOT, env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    try:
        line = proc.stdout.readline()
        m = re.search(r"serving on http://\[::1\]:(\d+)/", line)
        assert m, (line, proc.stderr.read() if proc.poll() is not None else "")
        port = int(m.group(1))
        assert _listening_addresses(port) == ["::1"]
        for host, status in ((f"[::1]:{port}", 200), (f"evil.example:{port}", 403)):
            c = http.client.HTTPConnection("::1", port, timeout=30)
            c.putrequest("GET", "/", skip_host=True)
            c.putheader("Host", host)
            c.endheaders()
            r = c.getresponse()
            r.read()
            c.close()
            assert r.status == status, host
    finally:
        proc.terminate()
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            proc.kill()
