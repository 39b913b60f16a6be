"""Load test of the served app (issue 5): concurrent sessions moving the Spectrum sliders.

    python benchmarks/load_test.py --sessions 20 --duration 60 [--num-procs 2]

1. Starts the app with ``asymslide serve`` as a subprocess on a free port, as ``make serve`` and the Docker
   image run it (:func:`serve_args`: ``--num-procs`` server processes, default 2 as in the image; the
   launcher adds ``--reuse-sessions``), with the session clean-up flags of :func:`cleanup_flags` and a
   session-info REST endpoint passed through to ``panel serve``.
2. Opens warm-up sessions until every server process has served one (imports, numba kernels, first
   page), measures the server CPU of a session open and of a slider release one at a time, waits
   for the server to discard those sessions and records the server's memory: the *start* figure.
3. Runs ``--rounds`` rounds (default 3). In each, ``--sessions`` users arrive ``--arrival-gap`` s
   apart and open a session; then, for ``duration / rounds`` seconds, each releases a random γ, f
   or β slider value every ``--think`` (1-3) s; a session lives 0.5-1.5 times the window and is then
   closed and replaced by a new one (while a quarter of the window remains). At the end of the
   round every session is closed; the script waits until the server reports the sessions destroyed
   and records the memory (RSS of the one process; with several, the Pss summed over them).
4. Verifies every plotted curve received against :func:`model.spectrum` at that session's
   parameters (catches cross-talk between sessions as well as wrong data).
5. Prints a table, writes ``benchmarks/load_results.md`` and exits non-zero when the verdict fails.

Client. Sessions are driven by a small Bokeh-protocol websocket client written here (all sessions
on one asyncio loop, ~1 s of client CPU per minute), not by browsers: 20 Chromium pages on a
2-core machine would measure Chromium, not the server. The client does what BokehJS does: it
requests the page for its session token, then sends over the websocket ACK, PULL-DOC-REQ,
``document_ready`` and PATCH-DOC with the slider's ``value`` and ``value_throttled`` (exactly what
a handle release sends), and times each release until the
server's PATCH-DOC carrying new data for the Im[c/c_s] ``ColumnDataSource`` of the "Rayleigh
branch" curve arrives. ``bokeh.client.pull_session`` was not used: it runs one blocking IOLoop per
connection whose waits have no timeout, and rebuilds the whole document as Python models.

Verdict (exit status 1 when any fails):

- errors == 0: any client exception, server ERROR reply, update not received within
  ``--timeout`` s, curve not equal to the model's, or an ERROR / Traceback line on the server's
  stderr;
- p95 of the update latency <= ``--p95-limit`` (1 s);
- memory bounded: after every round's clean-up the server holds no live session besides the page
  cache of ``--reuse-sessions`` (one per process; closed sessions are destroyed), and its memory
  grows by at most ``--mem-tolerance`` MB (20) over the last round, between clean-ups. The first
  round is excluded (caches and allocator pools fill once); a leak of the sessions' documents would
  add about 6 MB per session opened, every round.
"""

from __future__ import annotations

import argparse
import asyncio
import math
import os
import random
import re
import sys
import threading
import time
import urllib.request
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from bokeh.client.websocket import WebSocketClientConnectionWrapper
from bokeh.core.serialization import Deserializer
from bokeh.protocol import Protocol
from bokeh.protocol.message import Message
from bokeh.protocol.messages.patch_doc import patch_doc
from bokeh.protocol.receiver import Receiver
from bokeh.util.token import get_session_id
from tornado.httpclient import HTTPRequest
from tornado.websocket import websocket_connect

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # `model` for the verification, also when run as a script
from asymslide.app.declarations import physical_parameters  # noqa: E402
from asymslide.app.params import SpectrumParams  # noqa: E402
from benchmarks.hostspeed import host_line, host_loop_seconds  # noqa: E402
from tests.support.served_app import ServedApp, cpu_seconds  # noqa: E402

OUT = Path(__file__).resolve().parent / "load_results.md"


#: the sliders a session moves, with the range its values are drawn from
MOVES: dict[str, tuple[float, float]] = {"γ": (0.5, 20.0), "f": (0.2, 1.5), "β": (0.1, 0.65)}

#: slider titles of the six parameters and the checkbox label, in model order (the app's declarations)
PARAM_TITLES = {name: p.label for name, p in physical_parameters(SpectrumParams).items()}
ETA_INFINITE_LABEL = SpectrumParams.param.eta_infinite.label

#: a closed session is replaced only if at least this fraction of the window remains
MIN_SESSION = 0.25

#: server CPU seconds that show a process served a warm-up session (one costs 0.4-1.5 s, idle ~0)
WARM_CPU = 0.2

#: the session token in a served page (what BokehJS opens its websocket with)
TOKEN = re.compile(r'"token":\s*"([^"]+)"')


_PROTOCOL = Protocol()


# --------------------------------------------------------------------------------------------
# the server
# --------------------------------------------------------------------------------------------


# --------------------------------------------------------------------------------------------
# the client
# --------------------------------------------------------------------------------------------


class SessionError(RuntimeError):
    """A session failed: server ERROR reply, closed socket, timeout or unexpected document."""


def _objects(rep: Any, out: dict[str, dict]) -> dict[str, dict]:
    """Every serialized Bokeh model (``{"type": "object", "id": ...}``) nested in `rep`, by id."""
    if isinstance(rep, dict):
        if rep.get("type") == "object" and "id" in rep:
            out[rep["id"]] = rep
        for v in rep.values():
            _objects(v, out)
    elif isinstance(rep, list):
        for v in rep:
            _objects(v, out)
    return out


def _map_entries(rep: Any) -> dict[str, Any]:
    """A serialized ``dict`` (``{"type": "map", "entries": [[k, v], ...]}`` or a plain object)."""
    if isinstance(rep, dict) and rep.get("type") == "map":
        return {k: v for k, v in rep.get("entries", [])}
    return dict(rep) if isinstance(rep, dict) else {}


def _column(data_rep: Any, prefix: str, buffers: list) -> np.ndarray | None:
    """The column of a serialized ColumnDataSource ``data`` whose name starts with `prefix`."""
    for name, col in _map_entries(data_rep).items():
        if name.startswith(prefix):
            return np.asarray(Deserializer().decode(col, buffers), dtype=float)
    return None


@dataclass
class Update:
    """One slider release: the session's parameters after it, the curve received, the latency."""

    params: dict[str, float]
    kH: np.ndarray
    im: np.ndarray
    latency: float
    at: float = math.nan  # when the release was sent, seconds after the start of its round's window


def _page_token(url: str, timeout: float) -> str:
    """The session token of the page at `url`."""
    with urllib.request.urlopen(url, timeout=timeout) as response:
        found = TOKEN.search(response.read().decode("utf-8", "replace"))
    if found is None:
        raise SessionError(f"no session token in the page {url}")
    return found.group(1)


class AppSession:
    """One server session seen through the Bokeh websocket protocol (what one browser tab does)."""

    def __init__(self, url: str, ws_url: str) -> None:
        self.url, self.ws_url = url, ws_url
        self.session_id = ""
        self.ws = None
        self.sliders: dict[str, str] = {}  # title -> model id
        self.params: dict[str, float] = {}
        self.cds_id = ""
        self.renderer_id = ""  # the "Rayleigh branch" curve's GlyphRenderer (its data source may be replaced)
        self.kH = np.empty(0)
        self.im = np.empty(0)

    async def open(self, timeout: float) -> None:
        """Request the page, connect with its session token, pull the document, find the sliders and the
        plotted source, announce document_ready (what BokehJS does, without rendering)."""
        token = await asyncio.wait_for(asyncio.to_thread(_page_token, self.url, timeout), timeout)
        self.session_id = get_session_id(token)
        request = HTTPRequest(self.ws_url, connect_timeout=timeout, request_timeout=timeout)
        self.ws = await asyncio.wait_for(websocket_connect(request, subprotocols=["bokeh", token]), timeout)
        self._conn = WebSocketClientConnectionWrapper(self.ws)
        self._rx = Receiver(_PROTOCOL)
        deadline = time.monotonic() + timeout
        ack = await self._recv(deadline)
        if ack.msgtype != "ACK":
            raise SessionError(f"expected ACK, got {ack.msgtype}")
        await _PROTOCOL.create("PULL-DOC-REQ").send(self._conn)
        reply = await self._recv(deadline)
        while reply.msgtype != "PULL-DOC-REPLY":
            reply = await self._recv(deadline)
        self._parse_document(reply)
        await self._send_events([{"kind": "MessageSent", "msg_type": "bokeh_event",
                                  "msg_data": {"type": "event", "name": "document_ready", "values": {}}}])
        # the app renders its plots after the page has loaded (document_ready): wait for the Im curve
        while not self.cds_id:
            msg = await self._recv(deadline)
            if msg.msgtype == "PATCH-DOC":
                self._find_im_curve(_objects(msg.content, {}), msg.buffers)

    def _find_im_curve(self, objs: dict[str, dict], buffers: list) -> None:
        """The Im column of the "Rayleigh branch" curve among serialized models (sets cds_id, im, kH)."""
        for o in objs.values():  # document order: the Spectrum tab first
            attrs = o.get("attributes", {})
            if o.get("name") == "GlyphRenderer" and attrs.get("name") == "Rayleigh branch":
                src = objs.get(attrs["data_source"]["id"], {})
                im = _column(src.get("attributes", {}).get("data"), "Im", buffers)
                if im is not None:
                    self.cds_id, self.renderer_id = src["id"], o.get("id", "")
                    self.im = im
                    self.kH = _column(src["attributes"]["data"], "kH", buffers)
                    return

    def _parse_document(self, reply: Message[Any]) -> None:
        objs = _objects(reply.content["doc"], {})
        for o in objs.values():
            attrs = o.get("attributes", {})
            if o["name"].endswith("Slider") and attrs.get("title") in PARAM_TITLES.values():
                self.sliders.setdefault(attrs["title"], o["id"])
                self.params.setdefault(attrs["title"], float(attrs["value"]))
            if o["name"].endswith("CheckboxGroup") and attrs.get("labels") == [ETA_INFINITE_LABEL]:
                self.params.setdefault(ETA_INFINITE_LABEL, float(bool(attrs.get("active"))))  # [0] ticked, [] not
        self._find_im_curve(objs, reply.buffers)
        missing = [t for t in (*PARAM_TITLES.values(), ETA_INFINITE_LABEL) if t not in self.params]
        if missing:
            raise SessionError(f"document lacks the Spectrum widgets {missing}")

    async def _send_events(self, events: list[dict]) -> None:
        await patch_doc(patch_doc.create_header(), {}, {"events": events}).send(self._conn)

    async def _recv(self, deadline: float) -> Message[Any]:
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise SessionError("timed out waiting for the server")
            try:
                fragment = await asyncio.wait_for(self.ws.read_message(), remaining)
            except TimeoutError:
                raise SessionError("timed out waiting for the server") from None
            if fragment is None:
                raise SessionError("the server closed the websocket")
            msg = await self._rx.consume(fragment)
            if msg is None:
                continue
            if msg.msgtype == "ERROR":
                raise SessionError(f"server ERROR reply: {msg.content.get('text', msg.content)}")
            return msg

    def _new_curve(self, msg: Message[Any]) -> tuple[np.ndarray | None, np.ndarray | None]:
        """(kH, Im) from a PATCH-DOC if it sets the data of the plotted source (or replaces the source)."""
        for ev in msg.content.get("events", []):
            target = ev.get("model", {}).get("id")
            if target == self.cds_id and ev.get("kind") in ("ColumnDataChanged", "ModelChanged"):
                data = ev.get("data") if ev.get("kind") == "ColumnDataChanged" else ev.get("new")
                if ev.get("kind") == "ModelChanged" and ev.get("attr") != "data":
                    continue
                return _column(data, "kH", msg.buffers), _column(data, "Im", msg.buffers)
            # a new source of the curve's own renderer (not of another layer with an Im column: the markers of every
            # branch have one too; following theirs read the wrong curve)
            if (ev.get("kind") == "ModelChanged" and ev.get("attr") == "data_source" and target == self.renderer_id
                    and isinstance(ev.get("new"), dict)):
                src = _objects(ev["new"], {}).get(ev["new"].get("id", ""), {})
                im = _column(src.get("attributes", {}).get("data"), "Im", msg.buffers)
                if im is not None:
                    self.cds_id = src["id"]
                    return _column(src["attributes"]["data"], "kH", msg.buffers), im
        return None, None

    async def release(self, title: str, value: float, timeout: float) -> Update:
        """Release the slider `title` at `value`; wait for the new Im curve; return it and the latency."""
        sid = self.sliders[title]
        t0 = time.perf_counter()
        await self._send_events([{"kind": "ModelChanged", "model": {"id": sid}, "attr": "value", "new": value},
                                 {"kind": "ModelChanged", "model": {"id": sid}, "attr": "value_throttled",
                                  "new": value}])
        deadline = time.monotonic() + timeout
        while True:
            msg = await self._recv(deadline)
            if msg.msgtype != "PATCH-DOC":
                continue
            # the first new curve after the release is its answer (the previous release's was awaited; a
            # curve that is not the answer fails the verification against the model)
            kH, im = self._new_curve(msg)
            if im is not None:
                break
        latency = time.perf_counter() - t0
        self.params[title] = value
        self.im = im
        if kH is not None:
            self.kH = kH
        return Update(dict(self.params), self.kH, im, latency)

    async def close(self) -> None:
        if self.ws is not None:
            self.ws.close()
            self.ws = None


def model_args(params: dict[str, float]) -> dict[str, float]:
    """The model keywords of a session's widget values (as app.params.SpectrumParams.model_args)."""
    eta = math.inf if params[ETA_INFINITE_LABEL] else 10.0 ** params["η"]
    delta = params["Δ"]
    return dict(gamma=params["γ"], f=params["f"], beta=params["β"], eta=eta, Delta=delta,
                xi=0.0 if delta == 1 else params["ξ"])


# --------------------------------------------------------------------------------------------
# the load
# --------------------------------------------------------------------------------------------


@dataclass
class Stats:
    """What the run observed."""

    opened: int = 0
    closed: int = 0
    open_times: list[float] = field(default_factory=list)
    updates: list[Update] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    open_phase: list[float] = field(default_factory=list)
    session_ids: list[str] = field(default_factory=list)

    def error(self, where: str, exc: BaseException) -> None:
        self.errors.append(f"{where}: {type(exc).__name__}: {exc}")


async def _open(server: ServedApp, stats: Stats, timeout: float, who: str) -> AppSession | None:
    """A new session (its opening time recorded), or None after recording the error."""
    session = AppSession(server.url, server.ws_url)
    t0 = time.perf_counter()
    try:
        await session.open(timeout)
    except Exception as exc:  # noqa: BLE001 - every failure is counted and reported
        stats.error(f"{who} opening", exc)
        await session.close()
        return None
    stats.open_times.append(time.perf_counter() - t0)
    stats.opened += 1
    stats.session_ids.append(session.session_id)
    return session


async def _close(session: AppSession | None, stats: Stats) -> None:
    if session is not None:
        await session.close()
        stats.closed += 1


async def _work(who: str, session: AppSession | None, server: ServedApp, stats: Stats, rng: random.Random,
                window: tuple[float, float], think: tuple[float, float], life: tuple[float, float],
                timeout: float) -> None:
    """One user during the timed window: release a random slider value every `think` seconds; when the
    session's life (a fraction `life` of the window) is over, close it and open a replacement."""
    start, end = window
    seconds = end - start
    session_end = start + rng.uniform(*life) * seconds
    while True:
        now = time.monotonic()
        if session is None or now >= session_end:
            await _close(session, stats)
            session = None
            if end - now < max(MIN_SESSION * seconds, 2 * think[1]):
                break  # too late in the window for a new user
            session = await _open(server, stats, timeout, who)
            session_end = time.monotonic() + rng.uniform(*life) * seconds
            if session is None:
                await asyncio.sleep(rng.uniform(*think))
            continue
        pause = rng.uniform(*think)
        if now + pause >= end:
            break
        await asyncio.sleep(pause)
        if time.monotonic() >= session_end:
            continue
        title = rng.choice(list(MOVES))
        value = round(rng.uniform(*MOVES[title]), 4)
        if value == session.params[title]:
            continue
        try:
            sent = time.monotonic() - start
            update = await session.release(title, value, timeout)
            update.at = sent
            stats.updates.append(update)
        except Exception as exc:  # noqa: BLE001 - every failure is counted and reported
            stats.error(f"{who} release {title} = {value}", exc)
            session_end = time.monotonic()  # replace the failed session
    await _close(session, stats)


async def _round(server: ServedApp, stats: Stats, n: int, seconds: float, seed: int, think: tuple[float, float],
                 life: tuple[float, float], timeout: float, arrival_gap: float) -> None:
    """Open `n` sessions (users arriving `arrival_gap` s apart), then the timed window of `seconds`."""
    rngs = [random.Random(seed * 1000 + i) for i in range(n)]

    async def arrive(i: int) -> AppSession | None:
        await asyncio.sleep(i * arrival_gap)
        return await _open(server, stats, timeout, f"user {i}")

    t0 = time.monotonic()
    sessions = await asyncio.gather(*(arrive(i) for i in range(n)))
    stats.open_phase.append(time.monotonic() - t0)
    start = time.monotonic()
    await asyncio.gather(*(_work(f"user {i}", sessions[i], server, stats, rngs[i], (start, start + seconds), think,
                                 life, timeout) for i in range(n)))


async def _warm_up(server: ServedApp, timeout: float = 600.0) -> None:
    """Sessions that load the page and release each moved slider once, until every server process has
    served one: a process's first session pays for the imports and, on a clean checkout, numba's
    compilation. The kernel picks the process that accepts a connection; a process counts as warm once
    its CPU time has grown by a session's worth (:data:`WARM_CPU`)."""
    cold = set(server.workers())
    for _ in range(10 * len(cold)):
        before = {pid: cpu_seconds(pid) for pid in cold}
        session = AppSession(server.url, server.ws_url)
        try:
            await session.open(timeout)
            for title, (lo, hi) in MOVES.items():
                await session.release(title, round(0.5 * (lo + hi), 4), timeout)
        finally:
            await session.close()
        cold -= {pid for pid in before if cpu_seconds(pid) - before[pid] >= WARM_CPU}
        if not cold:
            return
    raise RuntimeError(f"server processes {sorted(cold)} served none of the warm-up sessions")


class RssSampler(threading.Thread):
    """Samples the server's memory every `period` seconds while running."""

    def __init__(self, server: ServedApp, period: float = 0.5) -> None:
        super().__init__(daemon=True)
        self.server, self.period = server, period
        self.samples: list[float] = []
        self._stop_event = threading.Event()

    def run(self) -> None:
        while not self._stop_event.is_set():
            try:
                self.samples.append(self.server.memory_mb())
            except (OSError, RuntimeError):
                return
            self._stop_event.wait(self.period)

    def stop(self) -> None:
        self._stop_event.set()
        self.join(timeout=5)


def _wait_for_cleanup(server: ServedApp, limit: float, opened: Sequence[str]) -> tuple[int | None, float]:
    """Wait (at most `limit` s) until the server has destroyed the sessions; (live sessions, seconds waited).

    Each REST request is answered by one process, so the answers are merged until they cover every
    session id in `opened` (every process hosting one of them has answered). ``--reuse-sessions`` keeps
    the session of each process's first page request for rendering pages, never destroyed: up to
    ``num_procs`` live sessions are that cache (:attr:`LoadResult.sessions_cleaned`)."""
    t0 = time.monotonic()
    polls = 1 if server.num_procs == 1 else 6 * server.num_procs
    wanted = set(opened)
    while True:
        states = server.session_states(polls)
        live = None if states is None else sum(states.values())
        if live is not None and live <= server.num_procs and wanted <= states.keys():
            break
        if time.monotonic() - t0 >= limit:
            break
        time.sleep(0.25)
    if live is None:  # no REST endpoint: wait out the whole clean-up interval
        time.sleep(max(0.0, limit - (time.monotonic() - t0)))
    time.sleep(1.0)  # let the interpreter finish releasing the discarded documents
    return live, time.monotonic() - t0


@dataclass
class LoadResult:
    """Figures and verdict of one run (see the module docstring for the criteria)."""

    config: dict[str, Any]
    server_flags: list[str]
    opened: int
    closed: int
    updates: int
    window_seconds: float
    errors: list[str]
    server_errors: list[str]
    latency: dict[str, float]
    session_open: dict[str, float]
    open_phase: list[float]
    server_cpu: float
    client_cpu: float
    rss_start: float
    rss_peak: float
    rss_after_round: list[float]
    live_after_round: list[int | None]
    cleanup_seconds: list[float]
    load_before: tuple[float, float, float]
    load_after: tuple[float, float, float]
    verified: int
    host_loop: tuple[float, float] = (math.nan, math.nan)  # hostspeed loop seconds, before and after
    cpu_per_open: float = math.nan
    cpu_per_update: float = math.nan

    @property
    def n_errors(self) -> int:
        return len(self.errors) + len(self.server_errors)

    @property
    def sessions_cleaned(self) -> bool:
        """After every round's clean-up the server held no session but ``--reuse-sessions``' page cache
        (at most one per process)."""
        return all(live is not None and live <= self.config["num_procs"] for live in self.live_after_round)

    @property
    def rss_growth(self) -> float:
        """RSS growth over the last round, between clean-ups (the first round's growth also holds the
        caches and allocator pools filling up once, so it is not a leak signal)."""
        before = self.rss_after_round[-2] if len(self.rss_after_round) > 1 else self.rss_start
        return self.rss_after_round[-1] - before

    @property
    def memory_bounded(self) -> bool:
        return self.sessions_cleaned and self.rss_growth <= self.config["mem_tolerance"]

    @property
    def p95_ok(self) -> bool:
        return self.updates > 0 and self.latency["p95"] <= self.config["p95_limit"]

    @property
    def ok(self) -> bool:
        return self.n_errors == 0 and self.p95_ok and self.memory_bounded


def _summary(values: Sequence[float]) -> dict[str, float]:
    if not values:
        return {"median": math.nan, "p95": math.nan, "max": math.nan, "n": 0}
    a = np.asarray(values)
    return {"median": float(np.median(a)), "p95": float(np.percentile(a, 95)), "max": float(a.max()), "n": a.size}


def _verify(updates: list[Update], limit: int, errors: list[str]) -> int:
    """Compare the received curves with model.spectrum at the sessions' parameters (all, up to `limit`)."""
    from asymslide import model

    chosen = updates if len(updates) <= limit else random.Random(0).sample(updates, limit)
    for u in chosen:
        p = model_args(u.params)
        expected = model.spectrum(u.kH, **p).imag
        if u.im.shape != expected.shape:
            errors.append(f"plotted Im[c/c_s] has shape {u.im.shape}, model.spectrum {expected.shape}, at {p}")
            continue
        bad = ~np.isclose(u.im, expected, rtol=1e-12, atol=0, equal_nan=True)
        if bad.any():
            i = int(np.flatnonzero(bad)[0])
            errors.append(f"plotted Im[c/c_s] differs from model.spectrum at {p} at {int(bad.sum())} of {bad.size} "
                          f"points, first at kH = {u.kH[i]:.6g}: {u.im[i]!r} != {expected[i]!r}")
    return len(chosen)


async def _calibrate(server: ServedApp, n_open: int = 3, n_release: int = 6,
                     timeout: float = 60.0) -> tuple[float, float]:
    """Server CPU seconds per session open and per slider release, measured one at a time (no queueing)."""
    sessions = []
    try:
        cpu0 = server.cpu_seconds()
        for _ in range(n_open):
            session = AppSession(server.url, server.ws_url)
            sessions.append(session)
            await session.open(timeout)
        await asyncio.sleep(1.0)  # the pages' deferred plots are still being rendered: count them with the opens
        cpu1 = server.cpu_seconds()
        titles = list(MOVES)
        for i in range(n_release):
            lo, hi = MOVES[titles[i % len(titles)]]
            await sessions[0].release(titles[i % len(titles)], round(lo + (hi - lo) * (i + 1) / (n_release + 1), 4),
                                      timeout)
        await asyncio.sleep(0.5)  # the last update's remaining work (other plots, readout) after the Im data
        cpu2 = server.cpu_seconds()
    finally:
        for session in sessions:
            await session.close()
    return (cpu1 - cpu0) / n_open, (cpu2 - cpu1) / n_release


def cleanup_flags(check_ms: int, lifetime_ms: int) -> list[str]:
    """The Bokeh server flags that discard closed sessions (Bokeh's defaults: 17000 ms and 15000 ms)."""
    return [f"--check-unused-sessions={check_ms}", f"--unused-session-lifetime={lifetime_ms}"]


def run_load(sessions: int = 20, duration: float = 60.0, rounds: int = 3, think: tuple[float, float] = (1.0, 3.0),
             life: tuple[float, float] = (0.5, 1.5), arrival_gap: float = 0.25, timeout: float = 30.0,
             check_ms: int = 1000, lifetime_ms: int = 1000, mem_tolerance: float = 20.0, p95_limit: float = 1.0,
             seed: int = 1, verify_limit: int = 5000, num_procs: int = 2, log=print) -> LoadResult:
    """Serve the app with `num_procs` processes, run the load, return the figures (module docstring)."""
    config = dict(sessions=sessions, duration=duration, rounds=rounds, think=think, life=life,
                  arrival_gap=arrival_gap, timeout=timeout, mem_tolerance=mem_tolerance, p95_limit=p95_limit,
                  num_procs=num_procs)
    flags = [*cleanup_flags(check_ms, lifetime_ms), "--rest-session-info", "--session-history=100000"]
    cleanup_limit = 2 * (check_ms + lifetime_ms) / 1000 + 10
    load_before = os.getloadavg()
    host_loop = host_loop_seconds()
    with ServedApp(flags, num_procs=num_procs) as server:
        log(f"server pid {server.pid} on port {server.port}: {' '.join(server.args[2:])}")
        log(f"warm-up sessions until each of the {num_procs} server process(es) has served one ...")
        asyncio.run(_warm_up(server))
        cpu_per_open, cpu_per_update = asyncio.run(_calibrate(server))
        _wait_for_cleanup(server, cleanup_limit, [])
        rss_start = server.memory_mb()
        stats = Stats()
        sampler = RssSampler(server)
        sampler.start()
        rss_after, live_after, waited = [], [], []
        server_cpu = client_cpu = 0.0
        for r in range(rounds):
            log(f"round {r + 1}/{rounds}: {sessions} sessions, then {duration / rounds:.0f} s of slider releases ...")
            cpu0, own0, first = server.cpu_seconds(), time.process_time(), len(stats.session_ids)
            asyncio.run(_round(server, stats, sessions, duration / rounds, seed + r, think, life, timeout,
                               arrival_gap))
            server_cpu += server.cpu_seconds() - cpu0
            client_cpu += time.process_time() - own0
            live, secs = _wait_for_cleanup(server, cleanup_limit, stats.session_ids[first:])
            rss_after.append(server.memory_mb())
            live_after.append(live)
            waited.append(secs)
            log(f"  {len(stats.updates)} updates so far, {len(stats.errors)} errors; after clean-up: "
                f"live sessions {live}, memory {rss_after[-1]:.0f} MB")
        sampler.stop()
        server_errors = list(server.error_lines)
    verified = _verify(stats.updates, verify_limit, stats.errors)
    return LoadResult(
        config=config, server_flags=flags, opened=stats.opened, closed=stats.closed, updates=len(stats.updates),
        window_seconds=duration + sum(stats.open_phase), errors=stats.errors, server_errors=server_errors,
        latency=_summary([u.latency for u in stats.updates]), session_open=_summary(stats.open_times),
        open_phase=stats.open_phase, server_cpu=server_cpu, client_cpu=client_cpu, rss_start=rss_start,
        rss_peak=max([rss_start, *sampler.samples]), rss_after_round=rss_after, live_after_round=live_after,
        cleanup_seconds=waited, load_before=load_before, load_after=os.getloadavg(), verified=verified,
        host_loop=(host_loop, host_loop_seconds()), cpu_per_open=cpu_per_open, cpu_per_update=cpu_per_update,
    )


# --------------------------------------------------------------------------------------------
# report
# --------------------------------------------------------------------------------------------


def _ms(x: float) -> str:
    return "—" if not math.isfinite(x) else f"{1000 * x:.0f} ms"


def _verdict(ok: bool) -> str:
    return "PASS" if ok else "FAIL"


def report(r: LoadResult) -> str:
    """The results as Markdown (also printed)."""
    c, lat, op = r.config, r.latency, r.session_open
    n = c["num_procs"]
    mem = "RSS" if n == 1 else f"memory (Pss of its {n + 1} processes)"
    rows = [
        ("sessions opened / closed", f"{r.opened} / {r.closed}", ""),
        ("slider releases answered (updates)", f"{r.updates} ({r.updates / r.window_seconds:.1f}/s)",
         f"{r.verified} verified against model.spectrum"),
        ("errors (client + server log)", f"{len(r.errors)} + {len(r.server_errors)}", _verdict(r.n_errors == 0)),
        ("update latency median / p95 / max", f"{_ms(lat['median'])} / {_ms(lat['p95'])} / {_ms(lat['max'])}",
         f"{_verdict(r.p95_ok)} (p95 <= {_ms(c['p95_limit'])})"),
        ("session open median / p95 / max", f"{_ms(op['median'])} / {_ms(op['p95'])} / {_ms(op['max'])}",
         f"all {c['sessions']} open after {' / '.join(f'{x:.0f}' for x in r.open_phase)} s"),
        ("CPU used: server / load client", f"{r.server_cpu:.0f} s / {r.client_cpu:.0f} s",
         f"server busy {100 * r.server_cpu / (r.window_seconds * n):.0f} % of {n} core(s) over the wall time"),
        ("server CPU per session open / per update, one at a time",
         f"{_ms(r.cpu_per_open)} / {_ms(r.cpu_per_update)}", ""),
        (f"server {mem} start / peak", f"{r.rss_start:.0f} / {r.rss_peak:.0f} MB", ""),
        (f"server {mem} after each round's clean-up", " / ".join(f"{x:.0f}" for x in r.rss_after_round) + " MB",
         f"last round {r.rss_growth:+.0f} MB (limit {c['mem_tolerance']:.0f})"),
        ("live sessions after each clean-up", " / ".join(str(x) for x in r.live_after_round),
         f"<= {n} (the page cache of --reuse-sessions, one per process); clean-up took "
         f"{' / '.join(f'{s:.0f}' for s in r.cleanup_seconds)} s"),
        ("memory bounded", "", _verdict(r.memory_bounded)),
    ]
    per_round = c["duration"] / c["rounds"]
    lines = [
        "# Load test (`python benchmarks/load_test.py`)",
        "",
        f"{c['rounds']} round(s); in each, {c['sessions']} users arrive {c['arrival_gap']} s apart and open a session, "
        f"then for {per_round:.0f} s each releases a random γ, f or β slider value every {c['think'][0]:g}-"
        f"{c['think'][1]:g} s; a session lives {c['life'][0]:g}-{c['life'][1]:g} × {per_round:.0f} s and is then "
        "replaced by a new one; at the end of the round all are closed and the server's clean-up awaited. "
        "Latency = release sent until the server's new Im[c/c_s] data for the plot is received (Bokeh-protocol "
        "client, no browser rendering).",
        "",
        f"Server: `asymslide serve --num-procs {n}` as `make serve` and the Docker image run it (`panel serve "
        f"app/main.py --reuse-sessions`), with `{' '.join(r.server_flags)}` passed to panel serve. "
        f"Machine: {os.cpu_count()} CPU(s), load average {r.load_before[0]:.2f} before and {r.load_after[0]:.2f} "
        "after (other jobs share the CPUs, so timings are indicative). " + host_line(*r.host_loop),
        "",
        "| figure | value | check |",
        "|---|---|---|",
        *(f"| {a} | {b} | {v} |" for a, b, v in rows),
        "",
        f"One round's {c['sessions']} arrivals need about {c['sessions'] * r.cpu_per_open:.1f} s of server CPU "
        f"(per-open cost above) and arrive within {c['sessions'] * c['arrival_gap']:.1f} s; each of the {n} server "
        "process(es) runs one event loop, so slider releases sent meanwhile wait behind the page builds.",
        "",
        f"**Verdict: {_verdict(r.ok)}**",
    ]
    if r.errors or r.server_errors:
        lines += ["", "Errors (first 20):", "", "```", *(r.errors + r.server_errors)[:20], "```"]
    return "\n".join(lines) + "\n"


def main(argv: Sequence[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sessions", type=int, default=20, help="concurrent sessions (default 20)")
    ap.add_argument("--duration", type=float, default=60.0, help="seconds of slider releases in total (default 60)")
    ap.add_argument("--rounds", type=int, default=3, help="rounds the duration is split into (default 3)")
    ap.add_argument("--think", type=float, nargs=2, default=(1.0, 3.0), metavar=("MIN", "MAX"),
                    help="seconds between a session's slider releases (uniform, default 1 3)")
    ap.add_argument("--arrival-gap", type=float, default=0.25, help="seconds between users arriving (default 0.25)")
    ap.add_argument("--timeout", type=float, default=30.0, help="seconds before an update counts as lost")
    ap.add_argument("--check-unused-ms", type=int, default=1000, help="--check-unused-sessions of the server")
    ap.add_argument("--unused-lifetime-ms", type=int, default=1000, help="--unused-session-lifetime of the server")
    ap.add_argument("--mem-tolerance", type=float, default=20.0,
                    help="MB of RSS growth allowed over the last round, between clean-ups (default 20)")
    ap.add_argument("--p95-limit", type=float, default=1.0, help="seconds (default 1)")
    ap.add_argument("--num-procs", type=int, default=2,
                    help="server processes (default 2, the Docker image's NUM_PROCS; make serve uses 1)")
    ap.add_argument("--out", type=Path, default=OUT, help="Markdown report (default benchmarks/load_results.md)")
    args = ap.parse_args(argv)
    result = run_load(args.sessions, args.duration, args.rounds, tuple(args.think), arrival_gap=args.arrival_gap,
                      timeout=args.timeout, check_ms=args.check_unused_ms, lifetime_ms=args.unused_lifetime_ms,
                      mem_tolerance=args.mem_tolerance, p95_limit=args.p95_limit, num_procs=args.num_procs)
    text = report(result)
    print(text)
    args.out.write_text(text, encoding="utf-8")
    print(f"wrote {args.out}")
    return 0 if result.ok else 1


if __name__ == "__main__":
    sys.exit(main())
