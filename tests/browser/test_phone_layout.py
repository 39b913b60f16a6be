"""The page on a phone and in the browser's console ("Exploration that follows the hand", presentation items).

- At 390 x 844 (a phone), every tab: no plot title and no legend runs past its plot's canvas (Bokeh cuts them off
  there: titles are drawn on one line, legends where HoloViews put them), no figure past the screen, and the page
  does not scroll sideways (app.layout.FitPlots wraps the titles and moves the legends below their plots).
- Tick labels: one style on every axis (app.plotting.TICKS_JS, app.common.LOG_COORDINATE_TICKS): zero is "0", never
  Bokeh's "0.000e+0".
- The console: opening every tab logs no warning or error but those of :data:`ALLOWED_CONSOLE` (the libraries').
"""

from __future__ import annotations

import re
from pathlib import Path

import holoviews as hv
import pytest
from bokeh.models import CustomJSTickFormatter, LogTickFormatter

from asymslide.app.common import LOG_COORDINATE_TICKS
from asymslide.app.plotting import TICKS_JS
from asymslide.app.tabs import TABS_REGISTRY
from tests.conftest import open_app, unexpected

#: the tabs' titles, in the order shown
TAB_TITLES = [tab.title for tab in TABS_REGISTRY]

#: a phone's screen (CSS px)
PHONE = {"width": 390, "height": 844}
WAIT = 90_000

#: per tab, the beginnings of the titles of the plots it shows once drawn (line breaks read as spaces)
TAB_PLOTS = {
    "Spectrum": ["Growth rate", "Phase velocity", "Slip–normal-stress coupling"],
    "Stability map": ["Fig. 4c"],
    "Thin-on-thick": ["(a) Effective shear modulus", "(b) G_y", "(c) Normal-stress change"],
    "Rupture fronts": ["(a) Slip velocity", "(b) Peak slip velocity", "(c)", "(d)"],
    "All branches": ["z-plane", "Unstable roots vs kH"],
    "Atlas": ["small"],
}

#: console messages of the page that come from the libraries and cannot be silenced from the app (pattern: why)
ALLOWED_CONSOLE = {
    # Bokeh's MultiChoice (the Atlas tab's "3-D axes (three)") creates its Choices.js box without `allowHTML`
    # (bokeh-widgets.js, MultiChoiceView.render), and the model has no property to pass it. The widget stays: the
    # order of the picks is the order of the 3-D view's axes (and of the URL's surface=), which check buttons or a
    # multi-select would not keep.
    r"Deprecation warning: allowHTML will default to false in a future release": "Bokeh's MultiChoice",
    # Plotly (the Atlas tab's 3-D view) reads pixels back from a 2-D canvas it creates without the attribute;
    # plotly.js has no option for it
    r"Canvas2D: Multiple readback operations using getImageData are faster with the willReadFrequently":
        "plotly.js's own canvas",
    # Chromium's software GL (no GPU here) reporting a stall when Plotly's WebGL scene is read back
    r"GL Driver Message \(OpenGL, Performance, .*\): GPU stall due to ReadPixels": "Chromium's software WebGL",
}

pytestmark = pytest.mark.ui

# --------------------------------------------------------------------------------------------
# what the page shows (JavaScript over Bokeh's views)
# --------------------------------------------------------------------------------------------

#: normalised titles of the shown figures that hold data (a glyph with points)
_DRAWN_JS = """() => {
  const out = [];
  for (const v of Bokeh.index.all_views()) {
    const m = v.model;
    if (m.type !== 'Figure' || !v.el.isConnected || v.el.getBoundingClientRect().width === 0) continue;
    const drawn = m.renderers.some(r => r.type === 'GlyphRenderer' && r.data_source && r.data_source.data &&
      Object.values(r.data_source.data).some(c => c !== undefined && c.length > 0));
    if (drawn) out.push((m.title && m.title.text ? m.title.text : '').replace(/\\n/g, ' '));
  }
  return out;
}"""

#: every title or legend of a shown figure that runs past its canvas (Bokeh cuts it off there), and every figure
#: that runs past the screen (`vw` px wide). A title is measured in the box Bokeh drew it in (TitleView._rect,
#: Bokeh 3.9), a legend in its view's bbox; both in canvas px.
_CLIPPED_JS = """(vw) => {
  const problems = [];
  const sides = ['above', 'below', 'left', 'right', 'center'];
  const r1 = x => Math.round(x);
  for (const v of Bokeh.index.all_views()) {
    const m = v.model;
    if (m.type !== 'Figure' || !v.el.isConnected || !v.canvas_view) continue;
    const el = v.el.getBoundingClientRect();
    if (el.width === 0) continue;  // not shown
    const name = JSON.stringify((m.title && m.title.text ? m.title.text : m.id).replace(/\\n/g, ' ').slice(0, 50));
    const W = v.canvas_view.bbox.width, H = v.canvas_view.bbox.height;
    if (el.left < -1 || el.right > vw + 1) problems.push(`${name}: the figure spans ${r1(el.left)}…${r1(el.right)} px`);
    const tv = m.title && m.title.text ? Bokeh.index.find_one(m.title) : null;
    if (tv && tv._rect) {
      const r = tv._rect, left = r.sx - r.anchor.x * r.width, top = r.sy - r.anchor.y * r.height;
      if (left < -1 || left + r.width > W + 1 || top < -1)
        problems.push(`${name}: its title spans x ${r1(left)}…${r1(left + r.width)}, y from ${r1(top)} ` +
                      `(canvas ${r1(W)} x ${r1(H)})`);
    }
    for (const legend of sides.flatMap(p => m[p]).filter(x => x.type === 'Legend')) {
      const lv = Bokeh.index.find_one(legend);
      if (!lv || !legend.visible || legend.items.length === 0) continue;
      const b = lv.bbox;
      if (b.width === 0) continue;
      if (b.left < -1 || b.right > W + 1 || b.top < -1 || b.bottom > H + 1)
        problems.push(`${name}: its legend spans x ${r1(b.left)}…${r1(b.right)}, y ${r1(b.top)}…${r1(b.bottom)} ` +
                      `(canvas ${r1(W)} x ${r1(H)})`);
    }
  }
  return problems;
}"""

#: how wide the page scrolls, and the elements (in the document and in every shadow root) that run past the screen
#: without an ancestor that clips them inside it (a scroller such as the equations')
_OVERFLOW_JS = """(vw) => {
  const up = e => e.parentElement ?? (e.getRootNode() instanceof ShadowRoot ? e.getRootNode().host : null);
  const clipped = e => {
    for (let p = up(e); p; p = up(p)) {
      if (getComputedStyle(p).overflowX !== 'visible' && p.getBoundingClientRect().right <= vw + 1) return true;
    }
    return false;
  };
  const out = [];
  const walk = root => {
    for (const e of root.querySelectorAll('*')) {
      const r = e.getBoundingClientRect();
      if (r.width > 0 && r.height > 0 && r.right > vw + 1 && !clipped(e))
        out.push(`<${e.tagName.toLowerCase()} class="${e.className}"> right at ${Math.round(r.right)} px`);
      if (e.shadowRoot) walk(e.shadowRoot);
    }
  };
  walk(document);
  return {width: document.scrollingElement.scrollWidth, elements: out.slice(0, 10)};
}"""


def show_tab(page, title: str) -> None:
    """Click the tab `title` and wait until each of its plots (:data:`TAB_PLOTS`) shows data."""
    page.locator(".bk-tab", has_text=title).first.click()
    want = repr(TAB_PLOTS[title])
    page.wait_for_function(f"""() => {{
      const drawn = ({_DRAWN_JS})();
      return Bokeh.documents[0].is_idle && {want}.every(t => drawn.some(d => d.startsWith(t)));
    }}""", timeout=WAIT)


def clipped_plots(page, width: int, settle_ms: int = 20_000) -> list[str]:
    """The titles and legends clipped by their canvas, once none is (up to `settle_ms`: the page fits its plots
    after Bokeh has laid them out), else those still clipped then."""
    try:
        page.wait_for_function(f"(vw) => ({_CLIPPED_JS})(vw).length === 0", arg=width, timeout=settle_ms)
    except Exception:  # noqa: BLE001 -- Playwright's TimeoutError: report what is clipped
        pass
    return page.evaluate(_CLIPPED_JS, width)


# --------------------------------------------------------------------------------------------
# a phone's screen
# --------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_every_tab_fits_a_phone_screen(atlas_with_small: Path, served_app: str, browser_context) -> None:
    """At 390 x 844 every tab's plot titles and legends stay inside their plots (titles longer than the plot
    wrap, legends that do not fit move below the plot), no figure runs off the screen, and nothing on the page
    (nor inside Panel's shadow roots) makes it scroll sideways. Before: "Slip–normal-stress coupling at c = c_R (…"
    ran 712 px wide on a 340 px canvas, the growth-rate legend 617 px, All branches' legend squeezed the z-plane."""
    width = PHONE["width"]
    page = browser_context(viewport=PHONE, device_scale_factor=1)
    open_app(page, served_app + "?atlas=small")
    assert list(TAB_PLOTS) == list(TAB_TITLES)  # every tab is checked
    problems: dict[str, list[str]] = {}
    for tab in TAB_TITLES:
        show_tab(page, tab)
        found = clipped_plots(page, width)
        overflow = page.evaluate(_OVERFLOW_JS, width)
        if overflow["width"] > width + 1 or overflow["elements"]:
            found.append(f"the page scrolls {overflow['width']} px wide: {overflow['elements']}")
        if found:
            problems[tab] = found
    assert problems == {}


@pytest.mark.slow
def test_the_plots_keep_their_titles_and_legends_on_a_wide_page(served_app: str,
                                                                 browser_context) -> None:
    """At 1400 px nothing is changed: no title wrapped, the legends where HoloViews put them (inside the plot;
    All branches' z-plane: right of it), none clipped."""
    page = browser_context(viewport={"width": 1400, "height": 900})
    open_app(page, served_app)
    for tab in ("Spectrum", "All branches"):
        show_tab(page, tab)
        page.wait_for_timeout(1000)  # a few rounds of app.layout.FitPlots
        assert clipped_plots(page, 1400, settle_ms=5000) == []
        shown = page.evaluate("""() => [...Bokeh.index.all_views()].filter(v => v.model.type === 'Figure' &&
          v.el.isConnected && v.el.getBoundingClientRect().width > 0).map(v => ({title: v.model.title.text,
          legends: ['below', 'right', 'center'].map(p => v.model[p].filter(m => m.type === 'Legend').length)}))""")
        assert shown and all("\n" not in s["title"] for s in shown), shown
        for s in shown:
            assert s["legends"][0] == 0, s  # none moved below
            if s["title"].startswith("z-plane"):
                assert s["legends"][1] == 1, s


# --------------------------------------------------------------------------------------------
# tick labels
# --------------------------------------------------------------------------------------------

#: tick arrays as Bokeh's tickers give them and the labels wanted
TICK_CASES = [
    ([0.0, 0.0005, 0.001], ["0", "0.0005", "0.001"]),  # Bokeh's default: "0.000e+0", "5.000e-4", "1.000e-3"
    ([0.0, 2e-5, 4e-5, 6e-5], ["0", "2×10⁻⁵", "4×10⁻⁵", "6×10⁻⁵"]),
    ([0.0, 50000.0, 100000.0, 150000.0], ["0", "0.5×10⁵", "1×10⁵", "1.5×10⁵"]),
    ([-0.4, -0.30000000000000004, -0.2, -0.1, 0.0], ["−0.4", "−0.3", "−0.2", "−0.1", "0"]),
    ([0.88, 0.9, 0.92, 0.94], ["0.88", "0.9", "0.92", "0.94"]),
    ([-0.1, 1.3877787807814457e-17, 0.1], ["−0.1", "0", "0.1"]),  # round-off at zero
    ([0.0, 0.25, 0.5, 0.75], ["0", "0.25", "0.5", "0.75"]),
    ([0.0, 2000.0, 4000.0, 6000.0], ["0", "2000", "4000", "6000"]),
]
#: the Atlas heat map's log10 axes: ticks (log10 of the value) and labels
LOG_COORDINATE_CASES = [([-1.0, -0.5, 0.0, 0.5, 1.0, 4.5], ["10⁻¹", "0.32", "10⁰", "3.2", "10¹", "3.2×10⁴"])]

_FORMAT_JS = """([code, ticks]) => {
  const f = new Function('tick', 'index', 'ticks', code);
  return ticks.map((t, i) => f(t, i, ticks));
}"""


def test_tick_labels_have_one_readable_style_and_zero_reads_0(browser_context) -> None:
    """The formatter of the app's linear axes and colour bars (run as BokehJS runs a CustomJSTickFormatter's code:
    per tick, with every tick of the axis): zero is "0" (Bokeh's BasicTickFormatter wrote "0.000e+0" where the
    ticks reach below 10⁻³ or 10⁴), plain numbers with the digits the step needs, one power of ten per axis for tiny
    or huge values; the Atlas's log10 axes write powers of ten as 10ⁿ."""
    page = browser_context()
    page.goto("about:blank")
    for ticks, labels in TICK_CASES:
        assert page.evaluate(_FORMAT_JS, [TICKS_JS, ticks]) == labels, ticks
    for ticks, labels in LOG_COORDINATE_CASES:
        assert page.evaluate(_FORMAT_JS, [LOG_COORDINATE_TICKS, ticks]) == labels, ticks


@pytest.mark.parametrize("logy", [False, True])
def test_every_plot_uses_the_readable_tick_labels(logy: bool) -> None:
    """Every element's plot runs app.plotting.readable_ticks_hook (a default option): a linear axis gets the app's
    formatter, even in an Overlay that sets its own hooks; a log axis keeps Bokeh's 10ⁿ labels. (No browser.)"""
    import asymslide.app.plotting  # noqa: F401 -- sets the defaults

    overlay = (hv.Curve([(1, 0.0), (2, 1e-4)]) * hv.Scatter([(1, 2e-4)])).opts(
        hv.opts.Overlay(logy=logy, hooks=[lambda plot, element: None]))
    fig = hv.render(overlay)
    assert isinstance(fig.xaxis[0].formatter, CustomJSTickFormatter) and fig.xaxis[0].formatter.code == TICKS_JS
    if logy:
        assert isinstance(fig.yaxis[0].formatter, LogTickFormatter)
    else:
        assert isinstance(fig.yaxis[0].formatter, CustomJSTickFormatter) and fig.yaxis[0].formatter.code == TICKS_JS


# --------------------------------------------------------------------------------------------
# the console
# --------------------------------------------------------------------------------------------


@pytest.mark.slow
def test_opening_every_tab_logs_no_console_warning(atlas_with_small: Path, served_app: str,
                                                   browser_context) -> None:
    """Every tab, and the Atlas tab's 3-D view, opened one after the other: the console holds no warning or error
    but the libraries' own (:data:`ALLOWED_CONSOLE`, each with the reason it cannot be silenced from the app)."""
    page = browser_context(viewport={"width": 1280, "height": 1000})
    messages: list[str] = []
    page.on("console", lambda msg: messages.append(f"console.{msg.type}: {msg.text}")
            if msg.type in ("warning", "error") else None)
    open_app(page, served_app + "?atlas=small")
    for tab in TAB_TITLES:
        show_tab(page, tab)
    page.locator(".bk-tab", has_text="3-D neutral surface").first.click()
    page.wait_for_function("""() => { const find = root => { for (const e of root.querySelectorAll('*')) {
        if (e.classList && e.classList.contains('js-plotly-plot') && e.data && e.data.length) return true;
        if (e.shadowRoot && find(e.shadowRoot)) return true; } return false; }; return find(document); }""",
                           timeout=WAIT)
    page.wait_for_timeout(2000)  # the 3-D scene's first frames
    assert unexpected(messages, [re.compile(p) for p in ALLOWED_CONSOLE]) == []
