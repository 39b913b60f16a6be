"""Smoke tests of the served app: over plain HTTP, and in a real headless Chromium (``ui``)."""

from __future__ import annotations

import html
import urllib.request

import pytest

from asymslide.app.main import TITLE
from tests.conftest import save_screenshot

#: titles of the page's Bokeh figures (JS function)
FIGURE_TITLES = ("() => Array.from(Bokeh.documents[0].all_models)"
                 ".filter(m => m.title && m.title.text && m.x_range).map(m => m.title.text)")


def test_server_answers_with_the_page(served_app: str) -> None:
    with urllib.request.urlopen(served_app, timeout=30) as response:
        assert response.status == 200
        page = response.read().decode("utf-8")
    assert TITLE in html.unescape(page)


def test_static_assets_are_served(served_app: str) -> None:
    with urllib.request.urlopen(served_app + "assets/logo.svg", timeout=30) as response:
        assert response.status == 200
        assert b"<svg" in response.read()


@pytest.mark.ui
@pytest.mark.slow
def test_page_renders_in_chromium(served_app: str, browser_page) -> None:
    page = browser_page
    page.goto(served_app, wait_until="load")
    page.get_by_text(TITLE).first.wait_for(state="visible", timeout=30_000)
    page.wait_for_function("() => window.Bokeh !== undefined && Bokeh.documents.length > 0", timeout=30_000)
    assert page.evaluate("() => Bokeh.documents[0] !== undefined")
    page.wait_for_function("() => Bokeh.documents[0].is_idle", timeout=30_000)
    page.get_by_text("lets you explore").first.wait_for(state="visible", timeout=30_000)
    assert page.title() == TITLE
    page.wait_for_load_state("networkidle")
    # the README's screenshot: tall enough for the three Spectrum plots, taken once they are drawn
    # (they are rendered after the page has loaded, one per server event-loop turn)
    page.set_viewport_size({"width": 1280, "height": 1560})
    page.wait_for_function(f"() => ({FIGURE_TITLES})().length >= 3", timeout=60_000)
    save_screenshot(page, "screenshot.png", full_page=False)
    assert page.console_errors == []
