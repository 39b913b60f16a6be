"""Plots that follow the hand: a slider dragged in a real browser (issue 33; targets: >= 15 redraws during a 30-move
drag over 1.5 s, the final plot <= 200 ms after the release, ten sessions dragging at once: p95 <= 400 ms).

    python benchmarks/drag.py [--drags 6] [--sessions 10]

Serves the app (``asymslide serve``, the flags of ``make serve``) on a free port, opens the Spectrum tab in headless
Chromium (/usr/bin/chromium through Playwright, the tests' launch arguments) and drags the γ slider's handle with the
mouse: 30 moves over 1.5 s, then the release, as a hand does. Inside the page, with ``performance.now()``, a listener
on the Im[c/c_s] data of the plotted "Rayleigh branch" curve records every new data set and the frame that painted it.

The other scenes whose sliders follow the hand (Thin-on-thick's kW, Rupture fronts' c/c_R; :data:`SCENES`) are
timed the same way in one session each, a redraw there being any change of the numbers a plot on the page draws.

- *redraws during the drag*: new data sets painted between the press and the release;
- *after release*: from the release until the frame showing the data of the final γ is painted (the last new data
  set; 0 when the last frame of the drag already showed it).

Then `sessions` sessions drag at once (Bokeh-protocol clients, as benchmarks/load_test.py's: ten Chromium pages on
two cores would measure Chromium, not the server; all opened and drawn first, i.e. quiet for SETTLE_MS; starts
staggered by 150 ms, three drags each) and the time from
each release to the last new curve is pooled over them (p95; no paint in these clients). Prints a Markdown table
(benchmarks/results.md keeps the figures of record); exit status 0 whether or not the targets are met (timings do
not gate anything; PASS/MISS is printed).
"""

from __future__ import annotations

import argparse
import asyncio
import math
import os
import sys
import time
from collections.abc import Sequence
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.hostspeed import host_line, host_loop_seconds  # noqa: E402
from benchmarks.latency import _READY_JS  # noqa: E402 - the same page-ready check as the release latency
from benchmarks.load_test import model_args  # noqa: E402 - a session's widget values as model keywords
from tests.conftest import CHROMIUM, CHROMIUM_ARGS  # noqa: E402
from tests.support.served_app import ServedApp  # noqa: E402

MOVES, DRAG_MS = 30, 1500
TARGET_REDRAWS, TARGET_LAG_MS, TARGET_P95_MS = 15, 200.0, 400.0
FINAL_TIMEOUT_S = 60.0  # a crowd drag's final curve must arrive within this (else: an error, not a figure)
QUIET_MS = 1500  # no new data for this long after the release: the last one was the final plot
SETTLE_MS = 2000  # no message to a crowd's opened session for this long: its page is drawn (the drags start then)

#: record every new Im data set of the Rayleigh-branch curve and when it was painted (window.__drag)
_WATCH_JS = """() => {
  const doc = Bokeh.documents[0];
  const rec = {frames: [], press: null, release: null};
  window.__drag = rec;
  const source = () => {
    for (const m of doc.all_models)
      if (m.name === 'Rayleigh branch' && m.data_source !== undefined) {
        const col = Object.keys(m.data_source.data).find(c => c.startsWith('Im'));
        if (col !== undefined) return [m.data_source, col];
      }
    return null;
  };
  let last = null;
  const check = () => {
    const found = source();
    if (found === null) return;
    const y = found[0].data[found[1]];
    const key = y.length + ':' + y[0] + ':' + y[Math.floor(y.length / 2)] + ':' + y[y.length - 1];
    if (key === last) return;
    last = key;
    const t = performance.now();
    requestAnimationFrame(() => setTimeout(() => rec.frames.push({data: t, paint: performance.now()}), 0));
  };
  check();
  rec.frames.length = 0;
  const [src] = source();
  src.change.connect(check);
  const poll = () => { check(); setTimeout(poll, 10); };
  poll();
  return true;
}"""


#: the other scenes whose sliders follow the hand (tab in the URL, slider label), timed in one session each
SCENES = {"Thin-on-thick": ("thin", "kW"), "Rupture fronts": ("rupture", "c/c_R")}

#: every change of what the shown tab's plots draw (any numeric column of a glyph of a plot on the page) and when it
#: was painted (window.__drag); for the scenes without the Spectrum's "Rayleigh branch" curve
_WATCH_ANY_JS = """() => {
  const doc = Bokeh.documents[0];
  const rec = {frames: [], press: null, release: null};
  window.__drag = rec;
  const key = () => {
    const parts = [];
    for (const m of doc.all_models) {
      if (m.renderers === undefined) continue;
      const view = Bokeh.index.find_one(m);
      if (!view || !view.el || !view.el.isConnected) continue;
      for (const r of m.renderers) {
        if (!r.data_source || !r.data_source.data) continue;
        const d = r.data_source.data;
        for (const c of Object.keys(d).sort()) {
          const y = d[c];
          if (!y || y.length === undefined || y.length === 0 || typeof y[0] !== 'number') continue;
          parts.push(c + y.length + ':' + y[0] + ':' + y[Math.floor(y.length / 2)] + ':' + y[y.length - 1]);
        }
      }
    }
    return parts.join('|');
  };
  let last = key();
  const poll = () => {
    const k = key();
    if (k !== last) {
      last = k;
      const t = performance.now();
      requestAnimationFrame(() => setTimeout(() => rec.frames.push({data: t, paint: performance.now()}), 0));
    }
    setTimeout(poll, 20);
  };
  poll();
  return true;
}"""

#: a scene's page is ready: a plot on the page draws data and the document is idle
_ANY_READY_JS = """() => {
  if (window.Bokeh === undefined || Bokeh.documents.length === 0 || !Bokeh.documents[0].is_idle) return false;
  for (const m of Bokeh.documents[0].all_models) {
    if (m.renderers === undefined) continue;
    const view = Bokeh.index.find_one(m);
    if (view && view.el && view.el.isConnected && m.renderers.some(r => r.data_source && r.data_source.data &&
        Object.values(r.data_source.data).some(y => y && y.length > 1))) return true;
  }
  return false;
}"""


def _drag(page, label: str = "γ") -> None:
    """Press the handle of the slider labelled `label`, move it 30 times over 1.5 s, release it."""
    slider = page.locator(".bk-input-group", has_text=f"{label}:").first
    handle = slider.locator(".noUi-handle").first
    track = slider.locator(".noUi-base").first
    box, hb = track.bounding_box(), handle.bounding_box()
    x0, y = hb["x"] + hb["width"] / 2, hb["y"] + hb["height"] / 2
    x1 = box["x"] + 0.8 * box["width"] if x0 < box["x"] + 0.5 * box["width"] else box["x"] + 0.2 * box["width"]
    page.mouse.move(x0, y)
    page.mouse.down()
    page.evaluate("() => { window.__drag.press = performance.now(); }")
    for i in range(1, MOVES + 1):
        page.mouse.move(x0 + (x1 - x0) * i / MOVES, y)
        page.wait_for_timeout(DRAG_MS / MOVES)
    page.mouse.up()
    page.evaluate("() => { window.__drag.release = performance.now(); }")


def _collect(page) -> dict:
    """Wait until the plot is quiet after the release; the drag's redraws and lag after release."""
    page.wait_for_function(f"""() => {{ const r = window.__drag, f = r.frames;
        const lastT = f.length ? f[f.length - 1].paint : r.release;
        return performance.now() - Math.max(lastT, r.release) > {QUIET_MS}; }}""", timeout=120_000)
    r = page.evaluate("() => window.__drag")
    during = [f for f in r["frames"] if r["press"] <= f["paint"] <= r["release"]]
    after = [f for f in r["frames"] if f["paint"] > r["release"]]
    lag = (after[-1]["paint"] - r["release"]) if after else 0.0
    page.evaluate("() => { window.__drag.frames.length = 0; }")
    return {"redraws": len(during), "lag": lag, "after": len(after)}


def _open(browser, url: str, ready: str = _READY_JS, watch: str = _WATCH_JS):
    page = browser.new_context(viewport={"width": 1280, "height": 900}).new_page()
    page.goto(url, wait_until="load", timeout=600_000)
    page.wait_for_function(ready, timeout=600_000)
    if watch is not _WATCH_JS:  # the page's first drawing is over: nothing changes for a while
        page.wait_for_timeout(SETTLE_MS)
    page.evaluate(watch)
    return page


def _scene_drags(browser, url: str, drags: int, errors: list[str]) -> dict[str, list[dict]]:
    """One session per scene of :data:`SCENES`: its slider dragged `drags` times after a warm-up drag."""
    out: dict[str, list[dict]] = {}
    for scene, (tab, label) in SCENES.items():
        page = _open(browser, f"{url}?tab={tab}", _ANY_READY_JS, _WATCH_ANY_JS)
        page.on("pageerror", lambda exc, scene=scene: errors.append(f"{scene}: pageerror: {exc}"))
        _drag(page, label)
        _collect(page)
        out[scene] = []
        for _ in range(drags):
            _drag(page, label)
            out[scene].append(_collect(page))
        page.context.close()
    return out


def _stats(xs: Sequence[float]) -> dict[str, float]:
    if not xs:
        return {"median": math.nan, "p95": math.nan, "max": math.nan, "n": 0}
    a = np.asarray(xs, dtype=float)
    return {"median": float(np.median(a)), "p95": float(np.percentile(a, 95)), "max": float(a.max()), "n": a.size}


def measure(drags: int = 6, sessions: int = 10, log=print, procs: int = 1, with_scenes: bool = True) -> dict:
    """Serve; one page drags `drags` times; one page of each other scene too (`with_scenes`); then `sessions`
    pages drag at once (three times each)."""
    from playwright.sync_api import sync_playwright

    if not CHROMIUM.exists():
        raise SystemExit(f"{CHROMIUM} not found (apt-get install -y chromium)")
    load_before, host_before = os.getloadavg(), host_loop_seconds()
    single: list[dict] = []
    scenes: dict[str, list[dict]] = {}
    crowd: list[dict] = []
    errors: list[str] = []
    with ServedApp(num_procs=procs) as server:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=str(CHROMIUM), args=CHROMIUM_ARGS, headless=True)
            try:
                page = _open(browser, server.url)
                page.on("pageerror", lambda exc: errors.append(f"pageerror: {exc}"))
                _drag(page)  # warm-up: first updates load more JavaScript paths
                _collect(page)
                for _ in range(drags):
                    _drag(page)
                    single.append(_collect(page))
                log(f"one session: {len(single)} drags timed")
                page.context.close()
                scenes = _scene_drags(browser, server.url, drags, errors) if with_scenes else {}
                log(f"other scenes: {', '.join(f'{k} {len(v)}' for k, v in scenes.items())} drags timed")
            finally:
                browser.close()
        if sessions:
            crowd = _crowd(server, sessions, errors)
            bad = sum(not r["final"] for r in crowd)
            if bad:
                errors.append(f"{bad} of {len(crowd)} drags did not end on the model's curve at the released γ "
                              f"(within {FINAL_TIMEOUT_S:.0f} s)")
            log(f"{sessions} sessions: {len(crowd)} drags timed")
        errors += server.error_lines
    return {"single": single, "scenes": scenes, "crowd": crowd, "sessions": sessions, "procs": procs,
            "errors": errors,
            "load": (load_before, os.getloadavg()), "host": (host_before, host_loop_seconds())}


async def _send_drag(session, sid: str, lo: float, hi: float) -> None:
    """30 ``value`` patches over 1.5 s (what BokehJS sends while a handle moves); the last with ``value_throttled``
    (the release)."""
    for i in range(1, MOVES + 1):
        value = round(lo + (hi - lo) * i / MOVES, 4)
        events = [{"kind": "ModelChanged", "model": {"id": sid}, "attr": "value", "new": value}]
        if i == MOVES:
            events.append({"kind": "ModelChanged", "model": {"id": sid}, "attr": "value_throttled", "new": value})
        await session._send_events(events)
        if i < MOVES:
            await asyncio.sleep(DRAG_MS / MOVES / 1000)


async def _protocol_drag(session, lo: float, hi: float) -> dict:
    """One drag of the γ slider by a Bokeh-protocol client (benchmarks.load_test.AppSession, :func:`_send_drag`);
    new Im curves are read meanwhile, each compared with model.spectrum at the released γ (rtol 1e-12). After the
    release it waits until that curve has arrived (at most FINAL_TIMEOUT_S) and the server has then been quiet for
    QUIET_MS. Returns the curves received during the drag, the time from the release to the last new curve, and
    whether the last curve is the released γ's."""
    from asymslide import model

    params = {**session.params, "γ": hi}
    expected = model.spectrum(session.kH, **model_args(params)).imag
    frames: list[tuple[float, bool]] = []  # (arrival, equal to the released γ's curve)
    curves: list[np.ndarray] = []  # the Im data received, in order (to tell which γ a wrong one is of)

    async def read(until: float) -> None:
        while time.monotonic() < until:
            try:
                msg = await session._recv(until)
            except Exception:  # noqa: BLE001 - the read window ended
                return
            kH, im = session._new_curve(msg) if msg.msgtype == "PATCH-DOC" else (None, None)
            if im is not None:
                same = (kH is None or np.array_equal(kH, session.kH)) and im.shape == expected.shape
                frames.append((time.monotonic(), bool(same and np.allclose(im, expected, rtol=1e-12, atol=0,
                                                                          equal_nan=True))))
                curves.append(im)

    reader = asyncio.create_task(read(time.monotonic() + FINAL_TIMEOUT_S + 5))
    press = time.monotonic()
    await _send_drag(session, session.sliders["γ"], lo, hi)
    release = time.monotonic()
    while time.monotonic() - release < FINAL_TIMEOUT_S:
        arrived = any(ok for _, ok in frames)
        if arrived and time.monotonic() - max(t for t, _ in frames) > QUIET_MS / 1000:
            break
        await asyncio.sleep(0.05)
    reader.cancel()
    session.params["γ"] = hi
    during = [t for t, _ in frames if t <= release]
    after = [t for t, _ in frames if t > release]
    return {"redraws": len(during), "lag": (after[-1] - release) * 1000 if after else math.nan, "after": len(after),
            "press": press, "final": bool(frames) and frames[-1][1], "matched": sum(ok for _, ok in frames),
            "received": len(frames), "curves": curves, "lo": lo, "hi": hi}


async def _settle(session, quiet: float, timeout: float) -> None:
    """Read what the server sends `session` until it has sent nothing for `quiet` s (the rest of the page's first
    drawing: the other plots, the sliding markers computed in the worker process), at most `timeout` s."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        try:
            await session._recv(min(deadline, time.monotonic() + quiet))
        except Exception:  # noqa: BLE001 - nothing arrived within `quiet`: the page is drawn
            return


def _crowd(server: ServedApp, sessions: int, errors: list[str], rounds: int = 3) -> list[dict]:
    """`sessions` Bokeh-protocol clients (benchmarks.load_test's: ten Chromium pages on two cores would measure
    Chromium, not the server) each dragging γ `rounds` times, starts staggered by 150 ms."""
    from benchmarks.load_test import AppSession

    out: list[dict] = []

    async def user(i: int, session) -> None:
        await asyncio.sleep(0.15 * i)
        for r in range(rounds):
            lo, hi = (2.0, 8.0) if r % 2 == 0 else (8.0, 2.0)
            try:
                out.append(await _protocol_drag(session, lo + 0.01 * i, hi + 0.01 * i))
            except Exception as exc:  # noqa: BLE001 - a failed drag is reported
                errors.append(f"session {i} drag {r}: {type(exc).__name__}: {exc}")

    async def run() -> None:
        opened = []
        for _ in range(sessions):
            s = AppSession(server.url, server.ws_url)
            await s.open(600)
            opened.append(s)
        for s in opened:  # ten sessions dragging, not ten opening: every page has drawn what it draws at its open
            await _settle(s, SETTLE_MS / 1000, 600)
        try:
            await asyncio.gather(*(user(i, s) for i, s in enumerate(opened)))
        finally:
            for s in opened:
                await s.close()

    asyncio.run(run())
    return out


def _scene_row(name: str, rows: list[dict]) -> str:
    """A table row for another scene's drags in one session (any drawn data change counts as a redraw)."""
    tab, label = SCENES[name]
    lag = _stats([r["lag"] for r in rows])
    return (f"| {name}, its {label} slider, one session | {len(rows)} | "
            f"{np.median([r['redraws'] for r in rows]) if rows else math.nan:.0f}, "
            f"{min((r['redraws'] for r in rows), default=0)} | {lag['median']:.0f} | {lag['p95']:.0f} | "
            f"{lag['max']:.0f} |")


def report(res: dict) -> str:
    single, crowd = res["single"], res["crowd"]
    procs = f"{res.get('procs', 1)} server process" + ("es" if res.get("procs", 1) > 1 else "")
    redraws = _stats([r["redraws"] for r in single])
    lag = _stats([r["lag"] for r in single])
    crowd_lag = _stats([r["lag"] for r in crowd if math.isfinite(r["lag"])])
    ok = [redraws["median"] >= TARGET_REDRAWS, lag["median"] <= TARGET_LAG_MS,
          crowd_lag["p95"] <= TARGET_P95_MS if crowd else False, not res["errors"]]
    (l0, _, _), (l1, _, _) = res["load"]
    lines = [
        "### Live while dragging (`python benchmarks/drag.py`)",
        "",
        f"Spectrum tab, the γ slider's handle dragged with the mouse in headless Chromium: {MOVES} moves over "
        f"{DRAG_MS / 1000:.1f} s, then the release. A *redraw* is a new Im[c/c_s] data set of the Rayleigh-branch "
        "curve painted during the drag; *after release*: from the release until the final plot is painted.",
        "",
        "| case | drags | redraws during the drag (median, min) | after release median (ms) | p95 (ms) | max (ms) |",
        "|---|---|---|---|---|---|",
        f"| one session | {len(single)} | {redraws['median']:.0f}, {min((r['redraws'] for r in single), default=0)} "
        f"| {lag['median']:.0f} | {lag['p95']:.0f} | {lag['max']:.0f} |",
        f"| {res['sessions']} sessions at once (protocol clients, {procs}) | {len(crowd)} | "
        f"{np.median([r['redraws'] for r in crowd]) if crowd else math.nan:.0f}, "
        f"{min((r['redraws'] for r in crowd), default=0)} | {crowd_lag['median']:.0f} | {crowd_lag['p95']:.0f} | "
        f"{crowd_lag['max']:.0f} |",
        *(_scene_row(name, rows) for name, rows in res.get("scenes", {}).items()),
        "",
        f"Targets (Spectrum): >= {TARGET_REDRAWS} redraws during the drag: {'PASS' if ok[0] else 'MISS'}; final "
        f"plot <= {TARGET_LAG_MS:.0f} ms after release: {'PASS' if ok[1] else 'MISS'}; {res['sessions']} sessions "
        f"p95 <= {TARGET_P95_MS:.0f} ms: {'PASS' if ok[2] else 'MISS'}; no server or page error: "
        f"{'PASS' if ok[3] else 'MISS'}.",
        "",
        f"Machine: {os.cpu_count()} CPU(s), load average {l0:.2f} before and {l1:.2f} after; the server and every "
        "Chromium share these CPUs. " + host_line(*res["host"]),
    ]
    if res["errors"]:
        lines += ["", f"Errors ({len(res['errors'])}, first 10):", "", "```", *res["errors"][:10], "```"]
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--drags", type=int, default=6, help="drags timed in one session (default 6)")
    ap.add_argument("--sessions", type=int, default=10, help="sessions dragging at once (default 10; 0: none)")
    ap.add_argument("--procs", type=int, default=1, help="server processes (panel serve --num-procs; default 1)")
    ap.add_argument("--no-scenes", action="store_true", help="time only the Spectrum (not Thin-on-thick, Rupture)")
    args = ap.parse_args(argv)
    text = report(measure(args.drags, args.sessions, procs=args.procs, with_scenes=not args.no_scenes))
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
