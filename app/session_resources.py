"""Stylesheet URLs of a session whose page was not rendered with its document (not physics, not layout).

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
tests/test_app_multiprocess.py shows it. :func:`use_server_stylesheets` applies to such a session what
Panel applies to a rendered page.

A second way to the CDN: with ``pn.Tabs(dynamic=True)`` a tab that is switched away from keeps its panes'
models, now outside the document. A pane updated later (the Stability map finishing after the user opened
another tab) re-renders its properties for ``model.document`` = None, so Panel patches the stylesheet objects
-- shared with the live models of the session -- back to its CDN, and the browser requests them there.
:func:`guard_detached_updates` makes such a patch use the URL of the session whose callback is running.
"""

from __future__ import annotations

import functools

import panel as pn
import panel.io.resources
import panel.reactive
from panel.io.resources import CDN_DIST, get_dist_path, patch_model_css


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
