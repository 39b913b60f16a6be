"""Atlas tab: slice change to painted heat map in a real browser (target: median <= 100 ms).

    python benchmarks/atlas_latency.py [--n 30]

Computes a 4-D atlas (γ 32 x β 32 x f 8 x Δ 8 at η = ∞, ξ = 1) into a temporary atlas directory, serves the
app on it (``asymslide serve``, as ``make serve``), opens ``?tab=atlas&atlas=bench`` in headless Chromium and
moves a slider of an axis off the image (``value`` and ``value_throttled``, as a handle release does), timing
inside the page with ``performance.now()`` until the heat map's image data changed (*data*) and until the next
frame was painted (*painted*). A slice change reads the stored cube only (no model call): this is Panel,
HoloViews, Bokeh and the browser. Prints a table and puts it into benchmarks/results.md (its own section, replaced
on every run; ``make bench`` runs this after benchmarks/run.py); exits 0 whether or not the target is met.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide.atlas import sweep as S  # noqa: E402
from benchmarks.hostspeed import host_line, host_loop_seconds  # noqa: E402
from benchmarks.latency import _stats  # noqa: E402
from tests.conftest import CHROMIUM, CHROMIUM_ARGS  # noqa: E402
from tests.support.served_app import ServedApp  # noqa: E402

TARGET_MS = 100.0
GAP_MS = 300
AXES = {"gamma": np.geomspace(0.1, 30, 32), "beta": np.linspace(0.05, 0.7, 32), "f": np.linspace(0.2, 1.6, 8),
        "Delta": np.linspace(0.1, 1.0, 8)}

_READY_JS = """() => {
  if (window.Bokeh === undefined || Bokeh.documents.length === 0 || !Bokeh.documents[0].is_idle) return false;
  for (const m of Bokeh.documents[0].all_models)
    if (m.type === 'GlyphRenderer' && m.glyph !== undefined && m.glyph.type === 'Image' &&
        m.data_source.data['image'] !== undefined && m.data_source.data['image'].length > 0) return true;
  return false;
}"""

_MEASURE_JS = """async ([which, index, timeoutMs]) => {
  const doc = Bokeh.documents[0];
  const source = () => {
    for (const m of doc.all_models)
      if (m.type === 'GlyphRenderer' && m.glyph !== undefined && m.glyph.type === 'Image') return m.data_source;
    return null;
  };
  const sliders = Array.from(doc.all_models).filter(m => m.type === 'Slider' && m.step === 1 && m.start === 0);
  const slider = sliders[which];
  const src = source();
  if (slider === undefined || src === null) return {error: 'slider or image not found'};
  const before = src.data['image'][0];
  return await new Promise((resolve) => {
    let t0 = 0, done = false;
    const finish = (r) => { if (!done) { done = true; resolve(r); } };
    const check = () => {
      const now = source();
      if (done || now === null || now.data['image'][0] === before) return false;
      const tData = performance.now();
      requestAnimationFrame(() => setTimeout(() => finish({data: tData - t0, paint: performance.now() - t0}), 0));
      return true;
    };
    const poll = () => {
      if (done || check()) return;
      if (performance.now() - t0 > timeoutMs) finish({error: 'timeout'}); else setTimeout(poll, 5);
    };
    t0 = performance.now();
    slider.value = index;
    slider.value_throttled = index;
    setTimeout(poll, 5);
  });
}"""


def measure(n: int) -> dict:
    from playwright.sync_api import sync_playwright

    if not CHROMIUM.exists():
        raise SystemExit(f"{CHROMIUM} not found (apt-get install -y chromium)")
    host0 = host_loop_seconds()
    results, errors = [], []
    with tempfile.TemporaryDirectory() as tmp:
        S.sweep(AXES, fixed={"xi": 1.0}, kH=np.logspace(-3, 3, 49), store=Path(tmp) / "bench.zarr")
        os.environ["ASYMSLIDE_ATLAS_DIR"] = tmp  # inherited by the server
        with ServedApp() as server, sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True)
            try:
                page = browser.new_context(viewport={"width": 1280, "height": 1000}).new_page()
                page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
                page.goto(server.url + "?tab=atlas&atlas=bench", wait_until="load", timeout=600_000)
                page.wait_for_function(_READY_JS, timeout=600_000)
                rng = np.random.default_rng(3)
                current = [4, 4]  # f and Delta start mid-way
                for i in range(n + 3):  # the first three are warm-up
                    which = i % 2
                    index = int(rng.choice([k for k in range(8) if k != current[which]]))
                    r = page.evaluate(_MEASURE_JS, [which, index, 30_000])
                    current[which] = index
                    if "error" in r:
                        errors.append(r["error"])
                    elif i >= 3:
                        results.append({**r, "axis": "f" if which == 0 else "Delta"})
                    page.wait_for_timeout(GAP_MS)
            finally:
                browser.close()
            errors += server.error_lines
    return {"data": _stats([r["data"] for r in results]), "paint": _stats([r["paint"] for r in results]),
            "paint_f": _stats([r["paint"] for r in results if r["axis"] == "f"]),
            "paint_Delta": _stats([r["paint"] for r in results if r["axis"] == "Delta"]),
            "errors": errors, "host": (host0, host_loop_seconds())}


def report(res: dict) -> str:
    p = res["paint"]
    verdict = "PASS" if p["median"] <= TARGET_MS else "MISS"
    lines = [f"Atlas tab, {'x'.join(str(len(v)) for v in AXES.values())} atlas (γ, β, f, Δ), a slider of f or Δ moved "
             "in headless Chromium (the heat map of γ-β is 32 x 32):", "",
             "| until | median (ms) | p90 (ms) | max (ms) | n |", "|---|---|---|---|---|"]
    for key, what in (("data", "new image data in the page"), ("paint", "painted"),
                      ("paint_f", "painted, f slider (the 3-D view is unchanged)"),
                      ("paint_Delta", "painted, Δ slider (the 3-D view is redrawn too)")):
        s = res[key]
        lines.append(f"| {what} | {s['median']:.0f} | {s['p90']:.0f} | {s['max']:.0f} | {s['n']} |")
    lines += ["", f"**Target: median slice change to painted heat map <= {TARGET_MS:.0f} ms: {verdict}** "
                  f"({p['median']:.0f} ms). " + host_line(*res["host"])]
    if res["errors"]:
        lines += ["", f"Errors ({len(res['errors'])}, first 5): " + "; ".join(res["errors"][:5])]
    return "\n".join(lines) + "\n"


RESULTS = Path(__file__).resolve().parent / "results.md"
HEADING = "## Atlas tab: slice change to painted heat map (`benchmarks/atlas_latency.py`)"


def put_section(path: Path, heading: str, body: str) -> None:
    """Replace the section `heading` of the Markdown file (up to the next '## ' heading), or append it."""
    text = path.read_text(encoding="utf-8") if path.exists() else ""
    start = text.find(heading)
    if start < 0:
        text = text.rstrip("\n") + "\n\n" + heading + "\n\n" + body
    else:
        end = text.find("\n## ", start + len(heading))
        text = text[:start] + heading + "\n\n" + body + (text[end:] if end >= 0 else "")
    path.write_text(text, encoding="utf-8")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=30, help="slice changes to time (default 30)")
    args = ap.parse_args()
    text = report(measure(args.n))
    print(text)
    put_section(RESULTS, HEADING, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
