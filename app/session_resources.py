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
"""

from __future__ import annotations

import panel as pn
from panel.io.resources import get_dist_path, patch_model_css


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
