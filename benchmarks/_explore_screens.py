"""Screenshots of rockjit explore's views for the docs (docs/_static/explore/), taken in a
headless system Chromium as a user would see them: the whole page, the basin (by attractor),
a cell's run, the bifurcation diagram zoomed, both laws side by side."""

from __future__ import annotations

import shutil
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT))


def main(folder, width=1600, height=1500):
    from playwright.sync_api import sync_playwright

    from rockjit.explorer.server import start
    from test_explore import PIXEL_JS
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    h = start(browser=False, quiet=True)
    try:
        with sync_playwright() as pw:
            b = pw.chromium.launch(executable_path=shutil.which("chromium"),
                                   args=["--no-sandbox", "--disable-gpu"])
            page = b.new_page(viewport={"width": width, "height": height},
                              device_scale_factor=1)
            page.goto(h.url)
            page.wait_for_selector(".rj-basin-shown[data-final='1']", timeout=120_000)
            page.wait_for_selector(".rj-sweep-shown", timeout=120_000)
            # a run: a cell of the smaller symmetric attractor's basin
            x, y = page.evaluate(PIXEL_JS, ["basin", 0.3, -0.55])
            page.mouse.click(x, y)
            page.wait_for_selector(".rj-run-behaviour", timeout=60_000)
            time.sleep(1.0)
            page.screenshot(path=str(folder / "page.png"), full_page=True)
            page.locator(".rj-view-run").screenshot(path=str(folder / "run.png"))
            # the basin by attractor
            page.get_by_text("attractor", exact=True).click()
            time.sleep(1.0)
            page.locator(".rj-view-basin").screenshot(path=str(folder / "basin.png"))
            # the bifurcation diagram zoomed on the period doublings and the chaos
            xa, ym = page.evaluate(PIXEL_JS, ["bif", 0.88, None])
            xb, _ = page.evaluate(PIXEL_JS, ["bif", 0.98, None])
            page.mouse.move(xa, ym)
            page.mouse.down()
            page.mouse.move(xb, ym, steps=8)
            page.mouse.up()
            deadline = time.time() + 120
            while time.time() < deadline:
                a0 = page.locator(".rj-sweep-shown").get_attribute("data-a0")
                if a0 and abs(float(a0) - 0.88) < 0.01:
                    break
                time.sleep(0.1)
            time.sleep(1.0)
            page.locator(".rj-view-sweep").screenshot(path=str(folder / "bifurcation.png"))
            # both laws
            page.locator(".rj-compare-toggle button").click()
            page.wait_for_selector(".rj-agreement", timeout=120_000)
            time.sleep(1.0)
            page.locator(".rj-view-compare").screenshot(path=str(folder / "laws.png"))
            b.close()
    finally:
        h.stop()
    for name in ("page", "basin", "run", "bifurcation", "laws"):
        print(folder / f"{name}.png")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ROOT / "docs" / "_static" / "explore")
