"""rockjit explore: how long a change of alpha takes to reach the screen.

Runs the browser test's scenario (tests/explorer/test_explore.py::test_the_app_in_a_browser: the app in a
headless system Chromium, driven by Playwright) with its timing log on, and reports the medians
over its changes of alpha: until the 50² basin of the new alpha is on the page, and until the
refined 100² one is (target: 1.5 s warm). Beside them, in the same run, the same stages computed
without a browser or a server (the library alone, in a worker thread), so that the app's own
share can be told from the machine's load; the load average is reported too, since the machine
is shared.

    python benchmarks/bench_explore.py                 # the browser scenario (about a minute)
    python benchmarks/bench_explore.py --quick         # smoke mode: the library alone, no browser
    python benchmarks/bench_explore.py --screenshots docs/_static/explore
                                                       # and a PNG of each view for the docs

Writes explore.{md,csv,json} to benchmarks/results/ (benchmarks/results/quick/ with --quick, or
--out DIR).
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import _common as H  # noqa: E402

TARGET_S = 1.5
ALPHAS = (0.64, 0.68, 0.72, 0.70, 0.66, 0.60, 0.64, 0.68, 0.74, 0.66, 0.62)
QUICK_ALPHAS = (0.64, 0.68, 0.62)


def _options(p):
    p.add_argument("--screenshots", type=Path, default=None, metavar="DIR",
                   help="also write a PNG of each view (basin, run, bifurcation, both laws) "
                        "into DIR")


def library_alone(alphas, periods, levels):
    """Each alpha's basin stages through the explorer's worker, no server nor browser:
    seconds from the submission to the 50² and to the 100² result."""
    from rockjit.explorer import requests as R
    from rockjit.explorer.worker import Computer
    marks = {}

    def publish(ev):
        if ev.kind == "result":
            marks[ev.value.grid] = time.perf_counter()
    c = Computer(publish)
    out = {levels[0]: [], levels[1]: []}
    try:
        c.submit("basin", R.basin_stages(R.Params(periods=periods).check(), levels[:2]))
        c.wait_idle(300)  # the kernels loaded
        for a in alphas:
            marks.clear()
            t = time.perf_counter()
            c.submit("basin", R.basin_stages(R.Params(alpha=a, periods=periods).check(),
                                             levels[:2]))
            c.wait_idle(300)
            for g in levels[:2]:
                out[g].append(marks[g] - t)
    finally:
        c.close()
    return out


def browser_scenario():
    """The browser test with its timing log: its timings, or ``None`` and why not."""
    with tempfile.TemporaryDirectory() as tmp:
        log = Path(tmp) / "timings.json"
        env = dict(os.environ, ROCKJIT_EXPLORE_TIMINGS=str(log),
                   PYTHONPATH=str(H.ROOT) + os.pathsep + os.environ.get("PYTHONPATH", ""))
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-rs", "-p",
                               "no:cacheprovider",
                               "tests/explorer/test_explore.py::test_the_app_in_a_browser"],
                              cwd=H.ROOT, env=env, capture_output=True, text=True, timeout=900)
        wall = time.perf_counter() - t0
        if proc.returncode != 0:
            raise SystemExit(f"the browser test failed:\n{proc.stdout[-3000:]}")
        if not log.exists():  # skipped: its reason
            tail = (proc.stdout + proc.stderr).strip().splitlines()[-3:]
            return None, wall, " / ".join(tail)
        return json.loads(log.read_text()), wall, ""


def screenshots(folder):
    """A PNG of each view, as a user sees it, into ``folder`` (:mod:`_explore_screens`)."""
    import _explore_screens
    _explore_screens.main(Path(folder))


def _stats(xs):
    return (statistics.median(xs), min(xs), max(xs), len(xs)) if xs else \
        (float("nan"),) * 3 + (0,)


def main(argv=None):
    b = H.Bench(__doc__, argv, options=_options)
    load0 = os.getloadavg()
    rows, md = [], ["#### rockjit explore: from a change of α to the basin on the page", ""]
    data = dict(load_average_before=load0)
    timings, wall, why = (None, 0.0, "--quick runs the library alone") if b.quick else \
        browser_scenario()
    alone = library_alone(QUICK_ALPHAS if b.quick else ALPHAS, 100 if b.quick else 500,
                          (24, 48) if b.quick else (50, 100))
    data.update(library_alone={str(k): v for k, v in alone.items()})
    load1 = os.getloadavg()
    data["load_average_after"] = load1
    cols = ["measurement", "median_s", "min_s", "max_s", "n", "target_s"]
    if timings is not None:
        data.update(browser=timings, browser_test_wall_s=wall)
        for key, what, target in (
                ("alpha_to_50", "browser: α changed → 50² basin on the page", ""),
                ("alpha_to_100", "browser: α changed → refined 100² basin on the page",
                 TARGET_S)):
            m, lo, hi, n = _stats(timings[key])
            rows.append([what, m, lo, hi, n, target])
        rows.append(["browser: box zoom → bifurcation diagram recomputed (500 α)",
                     timings["zoom_to_sweep"], timings["zoom_to_sweep"],
                     timings["zoom_to_sweep"], 1, ""])
        rows.append(["browser: page opened → 100² basin and diagram (first page)",
                     timings["first_view"], timings["first_view"], timings["first_view"], 1,
                     ""])
    else:
        rows.append([f"browser: not run ({why})", float("nan"), float("nan"), float("nan"), 0,
                     TARGET_S])
    g0, g1 = sorted(alone)
    for g in (g0, g1):
        m, lo, hi, n = _stats(alone[g])
        rows.append([f"library alone: submitted → {g}² basin computed", m, lo, hi, n, ""])
    md += ["Medians over the changes of α of the browser test's scenario (hb = 1, Housner, "
           "ω = 1.3, 500 periods; α moved among 0.60–0.74 by typing it in the page), warm "
           "(the kernels loaded by the page's first basin). \"On the page\": the page shows the "
           "basin of the new α (the page's own timing log, window.rockjitLog: from the change event of the α box to the first animation frame after the basin's update, which arrives in the same message as its image). "
           f"Target for the refined 100² basin: {TARGET_S} s.", "",
           "| measurement | median s | min s | max s | n | target s |", "|---|---|---|---|---|---|"]
    for r in rows:
        md.append("| " + " | ".join(f"{v:.3g}" if isinstance(v, float) else str(v)
                                    for v in r) + " |")
    md += ["", f"Load average of the machine (2 cores, shared) before and after: "
               f"{load0[0]:.2f} and {load1[0]:.2f} (1 min). The library-alone rows are the "
               "computation's own share: the rest of a browser row is the server, the transfer "
               "and the page, and the browser's own CPU use on the same two cores.", ""]
    b.report("explore", markdown="\n".join(md), csv=(cols, rows), data=data)
    if b.args.screenshots is not None:
        screenshots(b.args.screenshots)


if __name__ == "__main__":
    main()
