"""Garbage-collector settings of the server process (not physics, not layout): see :func:`configure_gc`.

Measured with benchmarks/load_test.py (20 sessions) and, for the figures below, with 40 sessions opened
and 400 updates in one process.
"""

from __future__ import annotations

import gc

import panel as pn

#: first-generation threshold of the garbage collector in the server (Python's default: 700)
GC_THRESHOLD0 = 10_000

_configured = False
_live_sessions = 0


def configure_gc() -> None:
    """Garbage-collector settings for the server process, applied once, when the first session starts.

    - The objects alive after start-up (modules, HoloViews/Bokeh/Panel internals) move to the permanent
      generation: they are never garbage, and a full collection would walk every one of them, a pause every
      open session feels. Later sessions' objects stay collectable, so closed sessions are still reclaimed.
    - Young collections every GC_THRESHOLD0 allocations instead of Python's 700: a session allocates ~10^5
      container objects, so the default collected (and promoted) many times per session opened. The price:
      closed sessions' memory is reclaimed later (full collections are rarer), hence :func:`track_session`.
      Measurements: benchmarks/design_measurements.md.
    """
    global _configured
    if not _configured:
        gc.collect()
        gc.freeze()
        gc.set_threshold(GC_THRESHOLD0, *gc.get_threshold()[1:])
        _configured = True


def track_session() -> None:
    """Count the current session as live; when the last live session is destroyed, run a full
    collection (nobody is waiting then), so an idle server holds no closed session's memory."""
    global _live_sessions
    if pn.state.curdoc is None or pn.state.curdoc.session_context is None:
        return
    if never_destroyed(pn.state.curdoc.session_context.request.path, bool(pn.config.reuse_sessions)):
        return
    _live_sessions += 1
    pn.state.on_session_destroyed(_session_destroyed)


def never_destroyed(request_path: str, reuse_sessions: bool) -> bool:
    """Whether a session is one ``panel serve --reuse-sessions`` keeps for rendering pages.

    With that flag a session created by a page request (not by a websocket, whose path ends in
    ``/ws``) is cached and blocked from expiring, so counting it would keep :func:`track_session`'s
    count above zero for ever and the idle-server collection would never run.
    """
    return reuse_sessions and not request_path.rstrip("/").endswith("/ws")


def _session_destroyed(_session_context) -> None:
    global _live_sessions
    _live_sessions -= 1
    if _live_sessions == 0:
        gc.collect()
