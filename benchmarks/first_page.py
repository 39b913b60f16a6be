"""First use: the first page after the server starts, and the All-branches tab's first opening (issue 23 item 13).

    python benchmarks/first_page.py [--no-cold]

Starts ``asymslide serve`` (as ``make serve``: the launcher compiles the model's kernels into numba's cache, or
loads them from it, then every server process loads them before it serves a page) with a fresh atlas directory, and
opens the page in headless Chromium as soon as the server answers. Times, from the launcher's start:

- *kernels ready*: the launcher's "kernels ready" line (the warm-up, before the server starts);
- *server up*: the server answers HTTP;
- *first page*: the page, requested as soon as the server answers in a browser that was open already, has loaded
  and drawn its three Spectrum plots (what a user waits for);
- *All branches*: then, from the click on its tab until its plots are drawn (the first opening in that process).

Twice: with the cache (``NUMBA_CACHE_DIR`` = the project's ``.numba_cache``, filled by ``asymslide warmup`` first)
and cold (an empty cache directory: what a fresh clone or container without a prebuilt cache waits). Targets: first
page <= 10 s with the cache, All branches <= 3 s. Prints a table, puts it into benchmarks/results.md (its own
section); exits 0 whether or not the targets are met.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.atlas_latency import put_section  # noqa: E402
from benchmarks.hostspeed import host_line, host_loop_seconds  # noqa: E402
from benchmarks.load_test import ServedApp  # noqa: E402
from tests.conftest import CHROMIUM, CHROMIUM_ARGS  # noqa: E402

FIRST_PAGE_TARGET = 10.0
BRANCHES_TARGET = 3.0
RESULTS = Path(__file__).resolve().parent / "results.md"
HEADING = "## First use: first page after start, All branches first open (`benchmarks/first_page.py`)"

#: the page is usable: Bokeh idle and the three Spectrum plots drawn (their figures have titles)
_PAGE_READY_JS = """() => window.Bokeh !== undefined && Bokeh.documents.length > 0 && Bokeh.documents[0].is_idle &&
  Array.from(Bokeh.documents[0].all_models).filter(m => m.title && m.title.text && m.x_range).length >= 3"""
#: the All-branches tab is drawn: its z-plane figure's title counts the roots, and Bokeh is idle
_BRANCHES_READY_JS = """() => Bokeh.documents[0].is_idle && Array.from(Bokeh.documents[0].all_models).some(
  m => m.title && m.title.text && m.title.text.includes('unstable root(s) in the window'))"""


def _line_time(server: ServedApp, needle: str, t0: float) -> float:
    """Seconds from t0 to the first server log line containing `needle` (NaN if none)."""
    for t, line in zip(server.log_times, server.log, strict=False):
        if needle in line:
            return t - t0
    return float("nan")


def measure(cache_dir: str) -> dict[str, float]:
    """One start of the server with NUMBA_CACHE_DIR = cache_dir: the times of the module docstring."""
    from playwright.sync_api import sync_playwright

    saved = {k: os.environ.get(k) for k in ("NUMBA_CACHE_DIR", "ASYMSLIDE_ATLAS_DIR")}
    with tempfile.TemporaryDirectory(prefix="asymslide-atlases-") as atlases:
        os.environ["NUMBA_CACHE_DIR"], os.environ["ASYMSLIDE_ATLAS_DIR"] = cache_dir, atlases
        try:
            with sync_playwright() as pw:  # the user's browser is open before the server starts
                browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True)
                page = browser.new_context(viewport={"width": 1280, "height": 1500}).new_page()
                t0 = time.monotonic()
                server = ServedApp()
                server.start_timeout = 900.0
                try:
                    server.__enter__()
                    up = time.monotonic() - t0
                    page.goto(server.url, wait_until="load", timeout=600_000)
                    page.wait_for_function(_PAGE_READY_JS, timeout=600_000, polling=50)
                    first = time.monotonic() - t0
                    t1 = time.monotonic()
                    page.locator(".bk-tab", has_text="All branches").first.click()
                    page.wait_for_function(_BRANCHES_READY_JS, timeout=600_000, polling=50)
                    branches = time.monotonic() - t1
                finally:  # the server first: a page closed under it made Tornado log the closed websocket
                    server.stop()
                    browser.close()
                ready = _line_time(server, "kernels ready", t0)
                errors = list(server.error_lines)
        finally:
            for k, v in saved.items():
                if v is None:
                    os.environ.pop(k, None)
                else:
                    os.environ[k] = v
    for line in errors:
        print("server error:", line)
    return {"kernels": ready, "up": up, "first": first, "branches": branches, "errors": len(errors)}


def report(results: dict[str, dict[str, float]], host: tuple) -> str:
    lines = ["`asymslide serve` started, the page opened in headless Chromium as soon as the server answers "
             "(seconds from the launcher's start; All branches: from the click on its tab):", "",
             "| numba cache | kernels ready | server up | first page | All branches first open | server errors |",
             "|---|---|---|---|---|---|"]
    for name, r in results.items():
        lines.append(f"| {name} | {r['kernels']:.1f} | {r['up']:.1f} | {r['first']:.1f} | {r['branches']:.2f} | "
                     f"{r['errors']} |")
    warm = results.get("with cache")
    if warm is not None:
        ok_page = "PASS" if warm["first"] <= FIRST_PAGE_TARGET else "MISS"
        ok_branches = "PASS" if warm["branches"] <= BRANCHES_TARGET else "MISS"
        lines += ["", f"**Target: first page after start <= {FIRST_PAGE_TARGET:.0f} s with the cache: {ok_page}** "
                      f"({warm['first']:.1f} s); **All branches first open <= {BRANCHES_TARGET:.0f} s: "
                      f"{ok_branches}** ({warm['branches']:.2f} s)."]
    if "cold" in results:
        lines.append(f"Cold (no numba cache: a fresh clone, or an image built without `asymslide warmup`): first "
                     f"page after {results['cold']['first']:.0f} s, of which {results['cold']['kernels']:.0f} s "
                     "compiling the kernels.")
    lines += ["", host_line(*host)]
    return "\n".join(lines) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--no-cold", action="store_true", help="skip the run without a numba cache (~1-2 min)")
    args = ap.parse_args()
    if not CHROMIUM.exists():
        print(f"first_page: skipped, {CHROMIUM} not found")
        return 0
    cache = str(ROOT / ".numba_cache")
    subprocess.run([sys.executable, "-m", "asymslide", "warmup"], check=True,
                   env={**os.environ, "NUMBA_CACHE_DIR": cache})  # "with the cache": it exists
    host_before = host_loop_seconds()
    results = {"with cache": measure(cache)}
    if not args.no_cold:
        with tempfile.TemporaryDirectory(prefix="asymslide-numba-cold-") as cold:
            results["cold"] = measure(cold)
    text = report(results, (host_before, host_loop_seconds()))
    print(text)
    put_section(RESULTS, HEADING, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
