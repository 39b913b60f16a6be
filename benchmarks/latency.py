"""Slider-to-updated-plot latency of the Spectrum scene in a real browser (target: median <= 150 ms).

    python benchmarks/latency.py [--n 30]

Serves the app (``panel serve app/main.py``, the flags of ``make serve``) on a free port, opens it
in headless Chromium (/usr/bin/chromium through Playwright, the launch arguments of the tests) and,
for `n` γ values the server has not computed before, releases the γ slider (``value`` and
``value_throttled``, as a handle release does) and measures inside the page, with
``performance.now()``:

- *data*: until the Im[c/c_s] ColumnDataSource of the "Rayleigh branch" curve holds new values
  (a listener on the source's ``change`` signal, with a 10 ms polling fallback);
- *painted*: until the frame showing them has been painted (``requestAnimationFrame`` then
  ``setTimeout(0)`` after the data arrived).

Then it revisits γ values computed earlier in the run (served from the app's ``pn.cache``) and
reports that *cached* case separately: it is the cost of Panel, HoloViews, Bokeh and the browser
alone. Prints a table, writes ``benchmarks/latency_results.md``; the exit status is 0 whether or not
the target is met (timings do not gate anything; PASS/MISS is printed).
"""

from __future__ import annotations

import argparse
import math
import os
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.hostspeed import host_line, host_loop_seconds  # noqa: E402
from tests.conftest import CHROMIUM, CHROMIUM_ARGS  # noqa: E402
from tests.support.served_app import ServedApp  # noqa: E402

OUT = Path(__file__).resolve().parent / "latency_results.md"
TARGET_MS = 150.0
GAP_MS = 400  # quiet time between two releases (the rest of the previous update lands)

_READY_JS = """() => {
  if (window.Bokeh === undefined || Bokeh.documents.length === 0 || !Bokeh.documents[0].is_idle) return false;
  for (const m of Bokeh.documents[0].all_models)
    if (m.name === 'Rayleigh branch' && m.data_source !== undefined &&
        Object.keys(m.data_source.data).some(c => c.startsWith('Im'))) return true;
  return false;
}"""

_MEASURE_JS = """async ([title, value, timeoutMs]) => {
  const doc = Bokeh.documents[0];
  const imSource = () => {
    for (const m of doc.all_models) {
      if (m.name === 'Rayleigh branch' && m.data_source !== undefined) {
        const col = Object.keys(m.data_source.data).find(c => c.startsWith('Im'));
        if (col !== undefined) return [m.data_source, col];
      }
    }
    return null;
  };
  let slider = null;
  for (const m of doc.all_models)
    if (m.title === title && m.start !== undefined && m.end !== undefined) { slider = m; break; }
  const found = imSource();
  if (slider === null || found === null) return {error: 'slider or Im source not found'};
  const [src, col] = found;
  const before = Array.from(src.data[col]);
  const changed = () => {
    const now = imSource();
    if (now === null) return false;
    const y = now[0].data[now[1]];
    if (y.length !== before.length) return true;
    for (let i = 0; i < y.length; i++)
      if (!(y[i] === before[i] || (Number.isNaN(y[i]) && Number.isNaN(before[i])))) return true;
    return false;
  };
  return await new Promise((resolve) => {
    let tData = null, done = false, t0 = 0;
    const finish = (result) => {
      if (done) return;
      done = true;
      src.change.disconnect(check);
      resolve(result);
    };
    const check = () => {
      if (tData !== null || !changed()) return;
      tData = performance.now();
      requestAnimationFrame(() => setTimeout(() => finish({data: tData - t0, paint: performance.now() - t0}), 0));
    };
    const poll = () => {
      if (done || tData !== null) return;
      check();
      if (tData === null && performance.now() - t0 > timeoutMs) finish({error: 'timeout'});
      else if (tData === null) setTimeout(poll, 10);
    };
    src.change.connect(check);
    t0 = performance.now();
    slider.value = value;
    slider.value_throttled = value;
    setTimeout(poll, 10);
  });
}"""


def _stats(xs: Sequence[float]) -> dict[str, float]:
    if not xs:
        return {"median": math.nan, "p90": math.nan, "max": math.nan, "n": 0}
    a = np.asarray(xs, dtype=float)
    return {"median": float(np.median(a)), "p90": float(np.percentile(a, 90)), "max": float(a.max()), "n": a.size}


def gamma_values(n: int, seed: int = 7) -> list[float]:
    """`n` distinct γ values in the slider range (0.1-30), in random order, none equal to the default 3."""
    rng = np.random.default_rng(seed)
    values = np.round(np.geomspace(0.3, 25.0, n) * rng.uniform(0.97, 1.03, n), 4)
    values = [float(v) for v in values if v != 3.0]
    rng.shuffle(values)
    return values


def measure(n: int = 30, cached: int = 15, timeout_ms: float = 30_000, log=print) -> dict:
    """Serve, open the page, time `n` uncached and `cached` cached γ releases; return the figures (ms)."""
    from playwright.sync_api import sync_playwright

    if not CHROMIUM.exists():
        raise SystemExit(f"{CHROMIUM} not found (apt-get install -y chromium)")
    load_before, host_before = os.getloadavg(), host_loop_seconds()
    fresh = gamma_values(n)
    revisit = fresh[-2::-1][:cached]  # computed earlier in this run, most recent first; never the current value
    results: dict[str, list[dict]] = {"uncached": [], "cached": []}
    errors: list[str] = []
    with ServedApp() as server, sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True)
        try:
            page = browser.new_context(viewport={"width": 1280, "height": 800}).new_page()
            page.on("console", lambda m: errors.append(f"console.{m.type}: {m.text}") if m.type == "error" else None)
            page.on("pageerror", lambda exc: errors.append(f"pageerror: {exc}"))
            page.goto(server.url, wait_until="load", timeout=600_000)  # a clean checkout compiles numba first
            page.wait_for_function(_READY_JS, timeout=600_000)
            for value in (5.55, 7.77, 3.33):  # warm-up (first updates load more JavaScript paths), not counted
                page.evaluate(_MEASURE_JS, ["γ", value, 600_000])
                page.wait_for_timeout(GAP_MS)
            for case, values in (("uncached", fresh), ("cached", revisit)):
                for value in values:
                    r = page.evaluate(_MEASURE_JS, ["γ", value, timeout_ms])
                    if "error" in r:
                        errors.append(f"γ = {value}: {r['error']}")
                    else:
                        results[case].append(r)
                    page.wait_for_timeout(GAP_MS)
                log(f"{case}: {len(results[case])} releases timed")
        finally:
            browser.close()
        errors += server.error_lines
    return {
        "n": n,
        "uncached": {k: _stats([r[k] for r in results["uncached"]]) for k in ("data", "paint")},
        "cached": {k: _stats([r[k] for r in results["cached"]]) for k in ("data", "paint")},
        "errors": errors,
        "load": (load_before, os.getloadavg()),
        "host": (host_before, host_loop_seconds()),
    }


def report(res: dict) -> str:
    """The figures as Markdown (also printed)."""
    median = res["uncached"]["paint"]["median"]
    verdict = "PASS" if median <= TARGET_MS else "MISS"
    rows = []
    for case in ("uncached", "cached"):
        for key, what in (("data", "new data in the page"), ("paint", "painted")):
            s = res[case][key]
            rows.append(f"| {case} | {what} | {s['median']:.0f} | {s['p90']:.0f} | {s['max']:.0f} | {s['n']} |")
    (l0, _, _), (l1, _, _) = res["load"]
    lines = [
        "# Slider-to-plot latency in the browser (`python benchmarks/latency.py`)",
        "",
        "Spectrum scene, γ slider released (value + value_throttled) in headless Chromium; time measured in the",
        "page from the release until the Im[c/c_s] data of the plotted curve changed (*new data*) and until the",
        "next frame was painted (*painted*). *uncached*: γ values the server had not computed; *cached*: values",
        "revisited (served from the app's `pn.cache`), i.e. Panel + HoloViews + Bokeh + browser alone.",
        "",
        "| case | until | median (ms) | p90 (ms) | max (ms) | n |",
        "|---|---|---|---|---|---|",
        *rows,
        "",
        f"**Target: median slider-to-painted-plot (uncached) <= {TARGET_MS:.0f} ms: {verdict}** "
        f"({median:.0f} ms).",
        "",
        f"Machine: {os.cpu_count()} CPU(s), load average {l0:.2f} before and {l1:.2f} after; the server, Chromium "
        "and any other jobs share these CPUs, so the figures are indicative. " + host_line(*res["host"]),
    ]
    if res["errors"]:
        lines += ["", f"Errors ({len(res['errors'])}, first 10):", "", "```", *res["errors"][:10], "```"]
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=30, help="uncached γ releases to time (default 30)")
    ap.add_argument("--cached", type=int, default=15, help="cached γ releases to time (default 15)")
    ap.add_argument("--out", type=Path, default=OUT, help="Markdown report (default benchmarks/latency_results.md)")
    args = ap.parse_args(argv)
    res = measure(args.n, args.cached)
    text = report(res)
    print(text)
    args.out.write_text(text, encoding="utf-8")
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
