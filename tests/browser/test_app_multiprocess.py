"""The app served as the Docker image serves it: ``--num-procs 2 --reuse-sessions`` (tests.support.served_app).

With these flags a session's document is built when its websocket connects, not with the page, so
Panel does not point its stylesheets at this server (app/workarounds.py); and the session
that renders pages is never destroyed (app/server_gc.py must not wait for it).
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from asymslide.app.server_gc import never_destroyed
from tests.conftest import open_app, set_slider
from tests.support.served_app import ServedApp

pytestmark = pytest.mark.slow

#: URLs of the page's Bokeh stylesheets (Panel's components load theirs as ImportedStyleSheet)
STYLESHEET_URLS = ("() => Array.from(Bokeh.documents[0].all_models)"
                   ".filter(m => typeof m.url === 'string' && m.url.includes('.css')).map(m => m.url)")


@pytest.fixture(scope="module")
def served_two_procs() -> Iterator[ServedApp]:
    with ServedApp(num_procs=2) as server:
        yield server
        assert server.error_lines == [], "\n".join(server.error_lines)


@pytest.mark.ui
@pytest.mark.parametrize("visit", range(3))  # sessions land in either process; the page cache serves all
def test_pages_use_this_servers_stylesheets_and_work(served_two_procs: ServedApp, browser_page, visit: int) -> None:
    page = browser_page
    open_app(page, served_two_procs.url + f"?gamma={5 + visit}&f=0.7")
    urls = page.evaluate(STYLESHEET_URLS)
    assert urls, "no stylesheet found"
    assert not [u for u in urls if u.startswith("http")], urls  # relative: served by this server, not a CDN
    values = page.evaluate("() => Object.fromEntries(Array.from(Bokeh.documents[0].all_models)"
                           ".filter(m => m.type === 'Slider' || m.constructor.name === 'Slider')"
                           ".map(m => [m.title, m.value]))")
    assert values["γ"] == 5 + visit and values["f"] == 0.7  # the URL query reached the session's process
    assert set_slider(page, "β", 0.25)
    page.wait_for_function("() => window.location.search.includes('beta=0.25')", timeout=30_000)
    # browser_page fails the test on any console error (e.g. a stylesheet that did not load)


#: where the page's roots were drawn (JS): the document's root names, the class of what the header's busy-indicator
#: slot holds, and the top of the introduction's heading and the bottom of the header (px)
_LAYOUT_JS = """() => {
  const busy = document.querySelector('#header .pn-busy-container [data-root-id] > div');
  return {roots: Bokeh.documents[0].roots().map(r => r.name), busy: busy ? busy.className : null,
          header_bottom: document.getElementById('header').getBoundingClientRect().bottom};
}"""


@pytest.mark.ui
@pytest.mark.parametrize("visit", range(3))
def test_every_session_fills_the_cached_pages_slots_in_order(served_two_procs: ServedApp, browser_page,
                                                              visit: int) -> None:
    """From the second page of a server process on, the introduction was once drawn inside the blue header and
    everything below moved up one slot. With --reuse-sessions every page is the first session's HTML, and a session's
    document fills its root slots in order; Panel kept `notifications=True` (set while the first session was built)
    for that session only, so later documents had one root fewer -- and no lost-connection banner."""
    page = browser_page
    open_app(page, served_two_procs.url + f"?gamma={4 + visit}")
    layout = page.evaluate(_LAYOUT_JS)
    assert "notifications" in layout["roots"], layout["roots"]  # the lost-connection banner's area
    assert layout["busy"] is not None and "loader" in layout["busy"], layout  # Panel's spinner, not a main item
    heading = page.get_by_role("heading", name="Frictional sliding without reflection symmetry", exact=True).first
    box = heading.bounding_box()
    assert box is not None and box["y"] >= layout["header_bottom"], (box, layout)  # in the page, below the header
    tab = page.locator(".bk-tab", has_text="Spectrum").first.bounding_box()
    assert tab is not None and tab["y"] > box["y"]  # the tabs below the introduction


@pytest.mark.parametrize(("path", "reuse", "expected"), [
    ("/main", True, True),  # the page request's session: kept for rendering pages
    ("/main/ws", True, False),  # a user's session, built when its websocket connected
    ("/ws/", True, False),
    ("/main", False, False),  # without --reuse-sessions every session is a user's
    ("/main/ws", False, False),
])
def test_only_the_page_cache_session_is_never_destroyed(path: str, reuse: bool, expected: bool) -> None:
    assert never_destroyed(path, reuse) is expected
