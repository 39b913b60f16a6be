"""The browser half of the Docker smoke test (.ci/docker-smoke), run with the project's .venv (Playwright, xarray)
and Debian's Chromium, as a user would see the container:

``first-page URL STARTED SCREENSHOT``
    waits for the page of a container started at STARTED (epoch seconds) and for the Spectrum tab's three plots;
    prints ``page_s=`` (HTTP 200) and ``plots_s=`` (plots drawn), both counted from STARTED.
``atlas URL NAME STORE SCREENSHOT``
    opens ``?tab=atlas&atlas=NAME`` and checks that the heat map shows the data of STORE (the Zarr store the
    container wrote into the mounted folder, read here on the host).

Exits 1, with the reason, on a console error, a timeout or a mismatch.
"""

from __future__ import annotations

import argparse
import sys
import time
import urllib.request
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"
#: as tests/conftest.py: headless, as root, and no background connections (the machine has no network)
CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
                 "--disable-background-networking", "--disable-component-update", "--disable-sync"]
#: how long the page may take to answer at all (a broken image never does)
PAGE_TIMEOUT = 180.0
#: titles of the page's Bokeh figures (as tests/browser/test_ui_smoke.py)
FIGURE_TITLES = ("() => Array.from(Bokeh.documents[0].all_models)"
                 ".filter(m => m.title && m.title.text && m.x_range).map(m => m.title.text)")
#: the sum and size of the finite values of the Atlas tab's heat map, or null before it is drawn
IMAGE_JS = """() => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.type !== 'GlyphRenderer' || m.glyph === undefined || m.glyph.type !== 'Image') continue;
    const img = m.data_source.data['image'];
    if (img === undefined || img.length === 0) continue;
    const values = Array.from(img[0].length !== undefined ? img[0] : img[0].array ?? []);
    const finite = values.filter(v => Number.isFinite(v));
    if (finite.length === 0) continue;
    return {sum: finite.reduce((s, v) => s + v, 0), n: values.length};
  }
  return null;
}"""


def wait_for_page(url: str, deadline: float) -> None:
    last: Exception | None = None
    while time.time() < deadline:
        try:
            with urllib.request.urlopen(url, timeout=30) as response:
                if response.status == 200:
                    return
        except OSError as exc:
            last = exc
        time.sleep(0.1)
    raise SystemExit(f"docker_browser: {url} did not answer within {PAGE_TIMEOUT:g} s ({last!r})")


def open_page(browser, url: str):
    page = browser.new_page(viewport={"width": 1280, "height": 1500})
    errors: list[str] = []
    page.on("console", lambda m: errors.append(f"console.{m.type}: {m.text}") if m.type == "error" else None)
    page.on("pageerror", lambda exc: errors.append(f"pageerror: {exc}"))
    page.goto(url, wait_until="load")
    page.wait_for_function("() => window.Bokeh !== undefined && Bokeh.documents.length > 0", timeout=60_000)
    return page, errors


def first_page(browser, url: str, started: float, screenshot: Path) -> None:
    wait_for_page(url, started + PAGE_TIMEOUT)
    page_s = time.time() - started
    page, errors = open_page(browser, url)
    try:
        page.wait_for_function(f"() => ({FIGURE_TITLES})().length >= 3", timeout=120_000)
    except Exception:
        page.screenshot(path=str(screenshot))
        raise SystemExit(f"docker_browser: the Spectrum plots were not drawn within 120 s (screenshot: {screenshot}); "
                         f"console errors: {errors}") from None
    page.wait_for_function("() => Bokeh.documents[0].is_idle", timeout=60_000)
    plots_s = time.time() - started
    page.screenshot(path=str(screenshot))
    if errors:
        raise SystemExit("docker_browser: console errors on the first page:\n" + "\n".join(errors))
    print(f"page_s={page_s:.1f}")
    print(f"plots_s={plots_s:.1f}")


def atlas(browser, url: str, name: str, store: Path, screenshot: Path) -> None:
    import numpy as np
    import xarray as xr

    page, errors = open_page(browser, f"{url}?tab=atlas&atlas={name}")
    try:
        page.wait_for_function(f"() => ({IMAGE_JS})() !== null", timeout=120_000)
    except Exception:
        page.screenshot(path=str(screenshot))
        raise SystemExit(f"docker_browser: no heat map in the Atlas tab within 120 s (screenshot: {screenshot}); "
                         f"console errors: {errors}") from None
    shown = page.evaluate(IMAGE_JS)
    growth = xr.open_zarr(store, consolidated=False).growth
    # the heat map shows the first two axes; every other axis starts at its middle index (app/atlas/request.py)
    middle = {d: growth.sizes[d] // 2 for d in growth.dims[2:]}
    want = growth.isel(middle).values
    page.wait_for_function("() => Bokeh.documents[0].is_idle", timeout=60_000)
    page.screenshot(path=str(screenshot))
    if errors:
        raise SystemExit("docker_browser: console errors in the Atlas tab:\n" + "\n".join(errors))
    if shown["n"] != want.size or not np.isclose(shown["sum"], float(np.nansum(want)), rtol=1e-12, atol=0):
        raise SystemExit(f"docker_browser: the heat map ({shown}) is not the stored atlas (n={want.size}, "
                         f"sum={float(np.nansum(want))})")
    print(f"atlas_points={want.size}")


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="check", required=True)
    fp = sub.add_parser("first-page")
    fp.add_argument("url")
    fp.add_argument("started", type=float)
    fp.add_argument("screenshot", type=Path)
    at = sub.add_parser("atlas")
    at.add_argument("url")
    at.add_argument("name")
    at.add_argument("store", type=Path)
    at.add_argument("screenshot", type=Path)
    args = parser.parse_args(argv)
    from playwright.sync_api import sync_playwright

    with sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            if args.check == "first-page":
                first_page(browser, args.url, args.started, args.screenshot)
            else:
                atlas(browser, args.url, args.name, args.store, args.screenshot)
        finally:
            browser.close()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
