"""Every Panel/Bokeh workaround of the app, in one place (not physics, not layout), each written for and checked against
the library versions in :data:`CHECKED_WITH` (the pins of requirements.lock). tests/app/test_workarounds.py fails
when the installed Panel or Bokeh is another version: then re-check each workaround below (is it still needed, does
it still patch what it patches?) and update :data:`CHECKED_WITH` and the lock together.

1. Stylesheet URLs of a session whose page was not rendered with its document (:func:`use_server_stylesheets`,
   :func:`guard_detached_updates`; Panel internals: ``doc._template_variables``, ``patch_stylesheet``).
2. One Bokeh model-graph walk per parameter change instead of one per refreshed plot (:func:`frozen_document`;
   Bokeh internals: ``doc.models.invalidate`` / ``recompute``).
3. HoloViews' global stream registry used from several threads (:func:`guard_stream_registry`; HoloViews internal:
   ``holoviews.streams._StreamRegistry``).
4. A websocket closed twice over (:func:`guard_closed_connections`; Bokeh internals: ``WSHandler.on_close``,
   ``ServerConnection._session``).

(tests/support/spies.py relies on where ``pn.cache`` keeps the cached function; it checks that itself.)

## 1. Stylesheet URLs

Panel points its components' stylesheets at the server's own files (``static/extensions/panel/...``)
only when it renders the HTML page *with the session's document*: it then records the URL in
``doc._template_variables['dist_url']`` and rewrites the stylesheet URLs, which otherwise name its CDN
(cdn.holoviz.org). A session created when the websocket connects has no rendered page:

- ``panel serve --num-procs N``: the page request and the websocket reach different processes about
  half of the time; the second process builds the document from the session token;
- ``--reuse-sessions``: every page is rendered from one cached session, and each user's document is
  built when its websocket connects.

Those sessions then load ~8 stylesheets from the CDN: offline, the requests fail and the page loses
Panel's styles (loading spinner, alerts, Markdown, buttons, the Bootstrap theme);
tests/browser/test_app_multiprocess.py shows it. :func:`use_server_stylesheets` applies to such a session what
Panel applies to a rendered page.

A second way to the CDN: with ``pn.Tabs(dynamic=True)`` a tab that is switched away from keeps its panes'
models, now outside the document. A pane updated later (the Stability map finishing after the user opened
another tab) re-renders its properties for ``model.document`` = None, so Panel patches the stylesheet objects
-- shared with the live models of the session -- back to its CDN, and the browser requests them there.
:func:`guard_detached_updates` makes such a patch use the URL of the session whose callback is running.

## 2. frozen_document: see its docstring.

## 3. The stream registry

``holoviews.streams.Stream.registry`` is one ``WeakKeyDictionary`` for the whole process. A plot being built copies
it (``list(Stream.registry.items())``) while a stream made elsewhere registers itself in it. A served process runs
sessions on more than one thread (Panel's threaded serving; a preset click builds a tab while another session builds
its plots), and the copy then fails with ``RuntimeError: dictionary changed size during iteration``: a plot that never
appears. :func:`guard_stream_registry` serialises the registry's reads and writes with one lock.

## 4. A websocket closed twice over

Bokeh's keep-alive job pings every client; a ping to a page that has just gone raises ``WebSocketClosedError``, and
the job then drops the client (``client_lost``: the connection forgets its session). Tornado then reports the close
itself, and ``WSHandler.on_close`` asks the connection for its session again: ``AssertionError`` in
``bokeh/server/connection.py``, a Traceback in the server log for a page the user closed (seen in CI, with
``--num-procs 2``). :func:`guard_closed_connections` makes ``on_close`` skip a connection whose client was already
dropped: nothing is left to clean up.
"""

from __future__ import annotations

import contextlib
import functools
import threading
from collections.abc import Iterator

import panel as pn
import panel.io.resources
import panel.reactive
from panel.io.resources import CDN_DIST, get_dist_path, patch_model_css

#: the library versions the workarounds were written for and checked against (= requirements.lock)
CHECKED_WITH = {"panel": "1.9.4", "bokeh": "3.9.2", "holoviews": "1.23.2"}

#: serialises every read and write of HoloViews' stream registry (workaround 3)
_REGISTRY_LOCK = threading.RLock()
#: the registry methods HoloViews reads and writes it with
REGISTRY_METHODS = ("register", "unregister", "items", "values", "get", "__getitem__")


def guard_closed_connections() -> None:
    """Make Bokeh's ``WSHandler.on_close`` skip a connection the keep-alive job already dropped (workaround 4;
    idempotent)."""
    from bokeh.server.views.ws import WSHandler

    if getattr(WSHandler.on_close, "_asymslide_guard", False):
        return
    original = WSHandler.on_close

    @functools.wraps(original)
    def on_close(self) -> None:
        connection = self.connection
        if connection is not None and connection._session is None:  # client_lost ran: nothing left to clean up
            self.connection = None
        return original(self)

    on_close._asymslide_guard = True
    WSHandler.on_close = on_close


def guard_stream_registry() -> None:
    """Make HoloViews' process-wide stream registry safe to use from several threads (workaround 3; idempotent)."""
    from holoviews.streams import _StreamRegistry

    if getattr(_StreamRegistry, "_asymslide_locked", False):
        return
    for name in REGISTRY_METHODS:
        original = getattr(_StreamRegistry, name)

        def locked(self, *args, _original=original, **kwargs):
            with _REGISTRY_LOCK:
                return _original(self, *args, **kwargs)

        setattr(_StreamRegistry, name, functools.wraps(original)(locked))
    _StreamRegistry._asymslide_locked = True


def use_server_stylesheets() -> bool:
    """Point the current session's stylesheets where a page rendered by this server points them.

    Call after the app's roots are in the document. Components added later (lazy tabs, deferred
    plots) are patched by Panel itself from the recorded URL. Returns whether anything was changed:
    False outside a server session, or when the page was rendered with this document.
    """
    doc = pn.state.curdoc
    if doc is None or doc.session_context is None or "dist_url" in doc._template_variables:
        return False
    dist_url = get_dist_path()  # as Panel's server_html_page_for_session: local files unless CDN resources
    doc._template_variables["dist_url"] = dist_url
    for root in doc.roots:
        patch_model_css(root, dist_url=dist_url)
    return True


def _session_dist_url(patch):
    """patch_stylesheet that, asked for Panel's CDN while a session with local stylesheets is current, keeps them
    local (a model outside the document has no document of its own to tell Panel which URL the page uses)."""

    @functools.wraps(patch)
    def patch_stylesheet(stylesheet, dist_url):
        if dist_url == CDN_DIST:
            doc = pn.state.curdoc
            dist_url = (doc._template_variables.get("dist_url") if doc is not None else None) or dist_url
        return patch(stylesheet, dist_url)

    patch_stylesheet._asymslide_guard = True
    return patch_stylesheet


def guard_detached_updates() -> None:
    """Install the guard in the two places Panel calls patch_stylesheet from (idempotent)."""
    for module in (panel.io.resources, panel.reactive):
        if not getattr(module.patch_stylesheet, "_asymslide_guard", False):
            module.patch_stylesheet = _session_dist_url(module.patch_stylesheet)


def _skip_recompute() -> None:
    """Stands in for ``doc.models.recompute`` when the model graph is known not to have changed."""


@contextlib.contextmanager
def frozen_document() -> Iterator[None]:
    """Defer the Bokeh model-graph recompute to the end of a parameter change, and skip it when the
    graph did not change.

    HoloViews freezes the document around each plot it refreshes, and Bokeh walks every model of the
    page when the outermost freeze ends whether or not a model reference changed. Inside
    this context: nested freezes do not walk; at the end the walk happens once, and only if Bokeh
    reported a changed reference (``models.invalidate``) or a root was added or removed. A slider
    release that only sends new data (the usual case) walks nothing. Events are still sent as they
    happen (unlike ``pn.io.hold``), so the first plot is not delayed by the others. A no-op outside a
    Bokeh document (tests, scripts).
    """
    doc = pn.state.curdoc
    models = getattr(doc, "models", None)
    if models is None or "invalidate" in vars(models):  # no document, or inside another frozen_document
        yield
        return
    roots = list(doc.roots)
    changed = False

    def invalidate() -> None:  # Bokeh calls this when a property change adds or drops model references
        nonlocal changed
        changed = True

    models.invalidate = invalidate
    error: BaseException | None = None
    try:
        with models.freeze():
            try:
                yield
            except BaseException as exc:  # Bokeh's freeze() would stay frozen (no try/finally there)
                error = exc
            finally:
                del models.invalidate
                if not changed and list(doc.roots) == roots:
                    models.recompute = _skip_recompute  # the walk freeze() ends with
    finally:
        vars(models).pop("recompute", None)
    if error is not None:
        raise error
