"""What a new user does, in a real browser, each journey from a fresh page.

Every test here runs against the app served in this process (conftest ``served_app``) or by ``asymslide serve``, and
fails on any error the server logs and on any browser console or page error (conftest ``server_log``,
``browser_context``), unless it names the error as expected. Waits are on conditions with generous timeouts: the
host is shared and can be several times slower than a quiet one.
"""

from __future__ import annotations

import logging
import math
import re
import threading
import time
import urllib.parse
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from asymslide.app.atlas import directory as atlas_directory
from asymslide.app.presets import load_presets
from asymslide.atlas import sweep as engine
from tests.conftest import (
    ServerLog,
    clear_patched_curdocs,
    download,
    open_app,
    save_screenshot,
    set_slider,
    unexpected,
    watch_errors,
)
from tests.support.atlases import KH, SMALL

#: the default atlas of the first-use journey, small so that it computes in seconds (the code path is the real one)
TINY_DEFAULT = {"gamma": np.geomspace(0.3, 30, 6), "eta": np.geomspace(2, 1e3, 3), "f": np.array([0.6, 1.2]),
                "beta": np.array([0.2, 0.4])}

#: a long computation on a loaded 2-core host (ms)
LONG = 300_000
WAIT = 90_000

# --------------------------------------------------------------------------------------------
# what the page shows (JavaScript over Bokeh's document)
# --------------------------------------------------------------------------------------------

#: the figures of the page (those of the shown tab: hidden tabs' models leave the document): title, ranges, and
#: per visible line or marker glyph its finite y extent and number of points
_FIGURES_JS = """() => {
  const out = [];
  for (const m of Bokeh.documents[0].all_models) {
    if (!(m.x_range && m.y_range && m.renderers)) continue;
    const glyphs = [];
    for (const r of m.renderers) {
      if (r.type !== 'GlyphRenderer' || !r.visible || !r.glyph) continue;
      const field = r.glyph.y && r.glyph.y.field;
      const data = r.data_source && r.data_source.data;
      if (!field || !data || data[field] === undefined) continue;
      const ys = Array.from(data[field]).filter(v => Number.isFinite(v));
      glyphs.push({type: r.glyph.type, n: ys.length, lo: ys.length ? Math.min(...ys) : null,
                   hi: ys.length ? Math.max(...ys) : null});
    }
    out.push({title: m.title && m.title.text ? m.title.text : '', x: [m.x_range.start, m.x_range.end],
              y: [m.y_range.start, m.y_range.end], glyphs: glyphs});
  }
  return out;
}"""

#: values and options of the page's selects by title
_SELECTS_JS = """() => Object.fromEntries(Array.from(Bokeh.documents[0].all_models)
  .filter(m => m.type.endsWith('Select') && m.options !== undefined).map(m => [m.title, {value: m.value,
    options: m.options.map(o =>
    Array.isArray(o) ? o[0] : o)}]))"""

#: set a select (by title) as a user's choice does
_CHOOSE_JS = """([title, value]) => {
  for (const m of Bokeh.documents[0].all_models)
    if (m.type.endsWith('Select') && m.title === title) { m.value = value; return true; }
  return false;
}"""

#: the atlas heat map's image: its shape, or null before it is drawn
_IMAGE_JS = """() => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.type !== 'GlyphRenderer' || !m.glyph || m.glyph.type !== 'Image') continue;
    const img = m.data_source.data['image'];
    if (img === undefined || img.length === 0) continue;
    const a = img[0];
    const shape = a.shape !== undefined ? Array.from(a.shape) : null;
    const values = Array.from(a.length !== undefined ? a : (a.array ?? []));
    if (!values.some(v => Number.isFinite(v))) continue;
    return {shape: shape, n: values.length};
  }
  return null;
}"""

#: index sliders of the atlas (start 0, step 1): title -> value
_INDEX_SLIDERS_JS = """() => Object.fromEntries(Array.from(Bokeh.documents[0].all_models)
  .filter(m => m.type === 'Slider' && m.start === 0 && m.step === 1).map(m => [m.title, m.value]))"""

#: the 3-D view's plotly figure: the mesh's vertex count and the scene's axis ranges (plotly renders in a shadow root)
_PLOTLY_JS = """() => {
  const find = (root) => {
    for (const e of root.querySelectorAll('*')) {
      if (e.classList && e.classList.contains('js-plotly-plot')) return e;
      if (e.shadowRoot) { const r = find(e.shadowRoot); if (r) return r; }
    }
    return null;
  };
  const p = find(document);
  if (!p || !p.data || !p.data.length || !p._fullLayout || !p._fullLayout.scene) return null;
  const s = p._fullLayout.scene;
  return {type: p.data[0].type, vertices: p.data[0].x ? p.data[0].x.length : 0,
          ranges: [s.xaxis.range, s.yaxis.range, s.zaxis.range]};
}"""


def idle(page) -> None:
    page.wait_for_function("() => Bokeh.documents[0].is_idle", timeout=WAIT)


def figures(page) -> list[dict]:
    return page.evaluate(_FIGURES_JS)


def show_tab(page, title: str) -> None:
    page.locator(".bk-tab", has_text=title).first.click()
    idle(page)


def wait_for_figures(page, titles: list[str], timeout: int = WAIT) -> None:
    """Until figures whose titles start with each of `titles` show data (a glyph with points)."""
    want = repr(titles)
    page.wait_for_function(f"""() => {{
      const figs = ({_FIGURES_JS})();
      return Bokeh.documents[0].is_idle && {want}.every(t => figs.some(f => f.title.startsWith(t) &&
        f.glyphs.some(g => g.n > 0)));
    }}""", timeout=timeout)


def curves_outside_their_range(page) -> list[str]:
    """Every line or marker glyph of every figure shown whose finite y values leave the figure's y range."""
    out = []
    for fig in figures(page):
        lo, hi = fig["y"]
        span = abs(hi - lo) or 1.0
        for g in fig["glyphs"]:
            if g["n"] and g["type"] in ("Line", "Scatter", "Circle", "Step", "MultiLine") and (
                    g["lo"] < lo - 1e-9 * span or g["hi"] > hi + 1e-9 * span):
                out.append(f"{fig['title']!r}: a {g['type']} spans {g['lo']:.4g} … {g['hi']:.4g}, the y range "
                           f"{lo:.4g} … {hi:.4g}")
    return out


def click_preset(page, label: str) -> None:
    """Click a preset button as a user does: the pointer stays there, so its description shows; it must not cover
    the next button (it did, to the right of the button: the next click landed on the description)."""
    page.get_by_role("button", name=label, exact=True).first.click(timeout=WAIT)


# --------------------------------------------------------------------------------------------
# atlases
# --------------------------------------------------------------------------------------------


@pytest.fixture
def fresh_atlas_dir(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """An empty atlas directory whose default atlas is the tiny one (computed on first use, as the real one)."""
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path / "atlases"))
    monkeypatch.setattr(atlas_directory, "DEFAULT_AXES", TINY_DEFAULT)
    monkeypatch.setattr(atlas_directory, "DEFAULT_KH", KH)
    monkeypatch.setattr(atlas_directory, "_default_job", None)
    return tmp_path / "atlases"


@pytest.fixture
def held_default_sweep(monkeypatch: pytest.MonkeyPatch) -> threading.Event:
    """The default atlas's sweep waits (its plan and totals already published) until the test sets the event: the
    tiny atlas would otherwise finish before the browser has loaded the page, and the progress would be unseen."""
    release = threading.Event()
    real = engine.sweep

    def held(*args, **kwargs):
        if not release.wait(timeout=LONG / 1000):
            raise TimeoutError("the test never released the default atlas's sweep")
        return real(*args, **kwargs)

    monkeypatch.setattr(engine, "sweep", held)
    return release


pytestmark = pytest.mark.ui


@pytest.mark.slow
def test_first_use_of_the_atlas_tab_shows_the_default_atlas_without_a_reload(
        fresh_atlas_dir: Path, held_default_sweep: threading.Event, served_app: str, browser_page) -> None:
    """A fresh atlas directory; the default atlas computes with a labelled progress bar per phase, then the heat map,
    the selects and the sliders appear on the same page; x = y cannot be chosen."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=atlas")
    page.get_by_text("Growth rates (max Im[c/c_s] over kH at every grid point): 0 of").first.wait_for(timeout=WAIT)
    page.get_by_text("Thresholds γ_c (exact, over the other axes): 0 of").first.wait_for(timeout=WAIT)
    page.get_by_text("Computing the default atlas").first.wait_for(timeout=WAIT)
    held_default_sweep.set()
    page.evaluate("() => { window.asymslideJourney = 'same page'; }")
    page.wait_for_function(f"() => ({_IMAGE_JS})() !== null", timeout=LONG)
    idle(page)
    assert page.evaluate("() => window.asymslideJourney") == "same page"  # no reload
    selects = page.evaluate(_SELECTS_JS)
    name = atlas_directory.default_name()
    assert selects["Atlas"]["value"] == name and selects["Atlas"]["options"] == [name]
    x, y = selects["x axis"]["value"], selects["y axis"]["value"]
    assert (x, y) == ("gamma", "eta")
    assert x not in selects["y axis"]["options"]  # the y select never offers the x axis
    assert set(page.evaluate(_INDEX_SLIDERS_JS)) == {"f", "β"}
    assert page.evaluate(_IMAGE_JS)["n"] == len(TINY_DEFAULT["gamma"]) * len(TINY_DEFAULT["eta"])
    # x set to the current y: the two swap (no slice with x = y, no error)
    assert page.evaluate(_CHOOSE_JS, ["x axis", "eta"])
    page.wait_for_function(f"() => ({_SELECTS_JS})()['y axis'].value === 'gamma'", timeout=WAIT)
    idle(page)
    selects = page.evaluate(_SELECTS_JS)
    assert selects["x axis"]["value"] == "eta" and "eta" not in selects["y axis"]["options"]
    assert not page.get_by_text("Computing the default atlas").count()


@pytest.mark.slow
def test_the_3d_view_shows_a_surface_over_the_atlas_ranges(atlas_with_small: Path, served_app: str,
                                                            browser_page) -> None:
    """The neutral surface has vertices, and the axes span the atlas's grid (they read -1 … 1, empty)."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=atlas&atlas=small")
    page.wait_for_function(f"() => ({_IMAGE_JS})() !== null", timeout=WAIT)
    show_tab(page, "3-D neutral surface")
    page.wait_for_function(f"() => {{ const p = ({_PLOTLY_JS})(); return p !== null && p.vertices > 0; }}",
                           timeout=WAIT)
    fig = page.evaluate(_PLOTLY_JS)
    assert fig["type"] == "mesh3d" and fig["vertices"] % 3 == 0
    want = [np.log10(SMALL["gamma"]), SMALL["beta"], SMALL["f"]]
    for got, values in zip(fig["ranges"], want, strict=True):
        assert got == pytest.approx([values.min(), values.max()], rel=1e-9)


@pytest.mark.slow
def test_every_download_button_gives_a_file_with_a_header(atlas_with_small: Path, served_app: str,
                                                          browser_page) -> None:
    """Every download button in every tab gives a non-empty file, a '#' header line, a CSV header, data."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1600})
    open_app(page, served_app + "?atlas=small")
    wait_for_figures(page, ["Growth rate", "Phase velocity", "Slip–normal-stress"])
    tabs = {
        "Spectrum": ["Growth rate (CSV)", "Phase velocity (CSV)", "G_y criterion (CSV)"],
        "Stability map": ["Download map (CSV)", "Download Fig. 4c (CSV)"],
        "Thin-on-thick": ["CSV (a)", "CSV (b)", "CSV (c)"],
        "Rupture fronts": ["CSV (a)", "CSV (b)-(d)"],
        "All branches": ["Download roots (CSV)", "Download count vs kH (CSV)"],
        "Atlas": ["Download slice (CSV)"],
    }
    files: dict[str, str] = {}
    for tab, labels in tabs.items():
        show_tab(page, tab)
        if tab == "Spectrum":  # the lab panel's own plot and download
            page.get_by_text("Lab units:").first.click()  # the folded panel's title
            labels = [*labels, "Download CSV (lab units)"]
        if tab == "Atlas":
            page.wait_for_function(f"() => ({_IMAGE_JS})() !== null", timeout=WAIT)
        for label in labels:
            files[f"{tab}: {label}"] = download(page, label, timeout=LONG)
    for what, text in files.items():
        lines = text.splitlines()
        assert lines and lines[0].startswith("#") and "asymslide" in lines[0], what  # what the file holds
        table = [ln for ln in lines if ln and not ln.startswith("#")]
        header, rows = table[0], table[1:]
        assert "," in header and not header[0].isdigit(), what  # column names
        assert rows and all(row.count(",") == header.count(",") for row in rows), what  # data rows


@pytest.mark.parametrize("preset", load_presets(), ids=lambda p: p.id)
@pytest.mark.slow
def test_every_preset_on_a_fresh_page_shows_its_tab_with_data(served_app: str, browser_page, preset) -> None:
    """Each preset shows its tab with data (Fig. 3 once left Thin-on-thick empty, Fig. 4c the Stability map, and the
    next preset raised 'reference isn't known' in the browser); every curve of the preset's family lies inside its
    plot's y range."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1600})
    open_app(page, served_app)
    wait_for_figures(page, ["Growth rate"])
    click_preset(page, preset.label)
    tab_title = {"spectrum": "Spectrum", "map": "Stability map", "thin": "Thin-on-thick",
                 "rupture": "Rupture fronts"}[preset.tab]
    page.wait_for_function(f"() => Array.from(document.querySelectorAll('*')).some(e => e.shadowRoot && "
                           f"Array.from(e.shadowRoot.querySelectorAll('.bk-tab.bk-active')).some(t => "
                           f"t.textContent === {tab_title!r}))", timeout=WAIT)
    expected = {"spectrum": ["Growth rate", "Phase velocity"],
                "map": ["Max growth rate of the Rayleigh branch over", "Fig. 4c"],
                "thin": ["(a) Effective shear modulus", "(b) G_y", "(c) Normal-stress change"],
                "rupture": ["(a) Slip velocity", "(b) Peak slip velocity", "(c) Δσ_yy/σ₀"]}[preset.tab]
    wait_for_figures(page, expected, timeout=LONG)
    if preset.tab == "map":  # the map itself: computed (its readout counts the unstable points), not a blank
        unstable = re.compile(r"Unstable \(Rayleigh branch\) \d+(\.\d)? % of the \d+ computed points")
        page.get_by_text(unstable).first.wait_for(timeout=LONG)
    if preset.compare_values:
        idle(page)
        assert curves_outside_their_range(page) == []
    presets = load_presets()
    i = [p.id for p in presets].index(preset.id)
    right = presets[i + 1].label if i + 1 < len(presets) else "Clear curves"
    click_preset(page, right)  # the button to the right, the pointer still on this one (its description shows)
    idle(page)
    click_preset(page, next(p for p in presets if p.tab != preset.tab).label)  # a preset of another tab
    page.wait_for_timeout(500)
    idle(page)
    # browser_context fails the test on any console or page error (such as an unknown reference)


@pytest.mark.slow
def test_opening_the_lab_panel_leaves_the_spectrum_axes_unchanged(served_app: str, browser_page) -> None:
    """The lab plot keeps its own x range (it shared the Growth-rate plot's: kH 5.6 … 1412) and the three Spectrum
    plots span the same kH range; ticking 'Sliders follow the lab values' logs no error (KeyError 'link'); a
    checkbox's label toggles it."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 2200})
    open_app(page, served_app)
    titles = ["Growth rate", "Phase velocity", "Slip–normal-stress"]
    wait_for_figures(page, titles)

    def spectrum_ranges() -> dict[str, list[float]]:
        return {f["title"]: f["x"] for f in figures(page)
                if any(f["title"].startswith(t) for t in titles) and "wavelength" not in f["title"]}

    before = spectrum_ranges()
    assert len(before) == 3
    for x in before.values():
        assert x == pytest.approx([1e-3, 1e3], rel=1e-9)
    page.get_by_text("Lab units:").first.click()  # the folded panel's title
    page.get_by_text("H₂ = ∞ (half-space)").first.click()  # the label, not the box
    page.wait_for_function("() => window.location.search.includes('H2=30')", timeout=WAIT)
    page.get_by_text("Sliders follow the lab values").first.click()
    page.wait_for_function("() => window.location.search.includes('lab=1')", timeout=WAIT)
    wait_for_figures(page, ["Growth rate vs wavelength"])
    idle(page)
    assert spectrum_ranges() == before
    (lab,) = [f for f in figures(page) if f["title"].startswith("Growth rate vs wavelength")]
    # λ in mm (its grid: 0.06 mm to 63 m; the whole of it where no mode grows), not the kH range
    assert lab["x"][0] >= 0.05 and lab["x"][1] < 1e5 and lab["x"] != pytest.approx([1e-3, 1e3])


def test_the_lab_panel_reads_the_fastest_growth_over_every_kh(served_app: str, browser_page) -> None:
    """At the paper's defaults with PMMA's lab values, the folded lab panel, once opened, names the fastest growth of
    every branch over every kH: approached as kH -> inf (a supersonic guided mode) for the lab values, attained at
    kH = 0.4932 (intersonic) for the sliders' point (beta = 0.3), each with its rate in 1/s; no error on the page or
    in the server's log (the fixtures fail on one)."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 2200})
    open_app(page, served_app)
    page.get_by_text("Lab units:").first.click()  # the folded panel's title
    limit = page.locator("p", has_text="Fastest growth of every branch: approached as kH → ∞").first
    limit.wait_for(timeout=LONG)  # (the panes' text is in shadow roots: CSS locators reach it, body's text does not)
    line = limit.inner_text()
    assert "supersonic guided mode" in line and re.search(r"growth rate → [0-9.]+ 1/s", line) and "as λ → 0" in line
    point = page.locator("p", has_text="The sliders' point in lab units").first.inner_text()
    assert re.search(r"Fastest-growing mode of every branch \(intersonic guided mode, at kH = 0\.4932; every branch "
                     r"and every kH", point), point


@pytest.mark.slow
def test_a_shared_url_restores_the_map_plane_atlas_slices_and_window(atlas_with_small: Path, served_app: str,
                                                                      browser_context) -> None:
    """The map plane and resolution, the atlas with its axes and slices, and the All-branches kH and window go into
    the address bar; a fresh page opened on it shows the same."""
    page = browser_context(viewport={"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=map&atlas=small")
    page.get_by_role("button", name="f-γ", exact=True).first.click()
    page.get_by_role("button", name="coarse", exact=True).first.click()
    page.wait_for_function("() => window.location.search.includes('map=f-gamma') && "
                           "window.location.search.includes('map_res=coarse')", timeout=WAIT)
    wait_for_figures(page, ["Sliding verdict (every branch) over the f-γ plane"], timeout=LONG)
    shared = page.evaluate("() => window.location.search")
    again = browser_context(viewport={"width": 1280, "height": 1400})
    open_app(again, served_app + shared)
    wait_for_figures(again, ["Sliding verdict (every branch) over the f-γ plane"], timeout=LONG)
    assert again.evaluate("() => window.location.search") == shared

    show_tab(page, "Atlas")
    page.wait_for_function(f"() => ({_IMAGE_JS})() !== null", timeout=WAIT)
    assert page.evaluate(_CHOOSE_JS, ["y axis", "f"])
    page.wait_for_function("() => window.location.search.includes('ay=f')", timeout=WAIT)
    idle(page)
    assert page.evaluate("""() => { for (const m of Bokeh.documents[0].all_models)
      if (m.type === 'Slider' && m.title === 'β' && m.step === 1) { m.value = 1; m.value_throttled = 1; return true; }
      return false; }""")
    page.wait_for_function("() => window.location.search.includes('at_beta=0.225')", timeout=WAIT)
    shared = page.evaluate("() => window.location.search")
    args = urllib.parse.parse_qs(shared[1:])
    assert args["atlas"] == ["small"] and args["ax"] == ["gamma"] and args["ay"] == ["f"]
    third = browser_context(viewport={"width": 1280, "height": 1400})
    open_app(third, served_app + shared)
    third.wait_for_function(f"() => ({_IMAGE_JS})() !== null", timeout=WAIT)
    idle(third)
    selects = third.evaluate(_SELECTS_JS)
    assert (selects["Atlas"]["value"], selects["x axis"]["value"], selects["y axis"]["value"]) == \
        ("small", "gamma", "f")
    assert third.evaluate(_INDEX_SLIDERS_JS) == {"β": 1}
    assert third.evaluate(_IMAGE_JS)["n"] == len(SMALL["gamma"]) * len(SMALL["f"])

    fourth = browser_context(viewport={"width": 1280, "height": 1400})
    open_app(fourth, served_app + "?tab=branches&kH=0.77&im_min=0.001&eta=10")
    fourth.wait_for_function("() => Array.from(Bokeh.documents[0].all_models).some(m => m.title && m.title.text "
                             "&& m.title.text.startsWith('z-plane at kH = 0.77'))", timeout=LONG)
    assert "im_min=0.001" in fourth.evaluate("() => window.location.search")


@pytest.mark.slow
def test_bad_url_values_leave_the_address_bar(served_app: str, browser_page) -> None:
    """After the banner reports them, the address bar shows the values used, not the bad ones."""
    page = browser_page
    open_app(page, served_app + "?gamma=junk&beta=0.9&c_cR=1.5&H1=-5&kW=5")
    page.get_by_text("Some values in the URL were not used as given").first.wait_for(timeout=WAIT)
    page.get_by_text("the lab values are not valid").first.wait_for(timeout=WAIT)
    page.wait_for_function("() => !window.location.search.includes('junk')", timeout=WAIT)
    args = urllib.parse.parse_qs(page.evaluate("() => window.location.search")[1:])
    assert args["beta"] == ["0.7071"] and args["c_cR"] == ["0.999"] and args["gamma"] == ["3"]
    assert "kW" not in args  # thin-on-thick defaults are not written


@pytest.mark.slow
def test_phone_layout_reflows_at_390_px(served_app: str, browser_context) -> None:
    """A viewport meta tag; at 390 x 844 (a phone) nothing runs off the screen: the tabs and the presets wrap, the
    controls sit above the plots, and the plots take the page's width."""
    page = browser_context(viewport={"width": 390, "height": 844}, is_mobile=True, has_touch=True,
                           device_scale_factor=2)
    open_app(page, served_app)
    wait_for_figures(page, ["Growth rate"])
    assert page.evaluate("() => document.querySelector('meta[name=viewport]').content") == \
        "width=device-width, initial-scale=1"
    assert page.evaluate("() => document.documentElement.scrollWidth") <= 390
    for tab in page.locator(".bk-tab").all():
        box = tab.bounding_box()
        assert box is not None and box["x"] >= 0 and box["x"] + box["width"] <= 390, tab.text_content()
    for preset in load_presets():
        box = page.get_by_role("button", name=preset.label, exact=True).first.bounding_box()
        assert box["x"] >= 0 and box["x"] + box["width"] <= 390, preset.label
    slider = page.locator(".bk-slider-title", has_text="γ").first.bounding_box()
    plot = page.locator(".bk-Figure").first.bounding_box()
    assert slider["y"] + slider["height"] <= plot["y"]  # the controls above the plots
    assert plot["x"] >= 0 and plot["x"] + plot["width"] <= 390 and plot["width"] >= 0.8 * 390  # the full width
    equation = page.locator(".katex-display, .katex").first.evaluate(  # it once ran 458 px wide
        "el => { let p = el; while (p && getComputedStyle(p).overflowX !== 'auto') p = p.parentElement ?? "
        "p.getRootNode().host; const r = (p ?? el).getBoundingClientRect(); return [r.left, r.right]; }")
    assert equation[0] >= 0 and equation[1] <= 390, equation
    page.locator(".bk-tab", has_text="Spectrum").first.scroll_into_view_if_needed()
    save_screenshot(page, "screenshot_phone.png", full_page=False)


@pytest.mark.expected_errors(browser=["a deliberate page error", "Unhandled ERROR reply .*ZeroDivisionError"])
@pytest.mark.slow
def test_the_checks_catch_server_and_browser_errors(free_port: int, browser_context) -> None:
    """The checks above are live: an exception in a served callback reaches the server log collector, and an
    uncaught error in the page reaches the browser's."""
    import panel as pn

    def broken_app():
        pn.state.onload(lambda: 1 / 0)
        return pn.pane.Markdown("a page whose load callback fails")

    with ServerLog() as log:
        server = pn.serve(broken_app, port=free_port, address="127.0.0.1", websocket_origin=[f"127.0.0.1:{free_port}"],
                          threaded=True, show=False, start=True, verbose=False)
        try:
            page = browser_context()
            errors = watch_errors(page)
            page.goto(f"http://127.0.0.1:{free_port}/", wait_until="load")
            page.wait_for_function("() => window.Bokeh !== undefined && Bokeh.documents.length > 0", timeout=WAIT)
            deadline = time.monotonic() + 60
            while not any("ZeroDivisionError" in e for e in log.errors) and time.monotonic() < deadline:
                time.sleep(0.2)
            page.evaluate("() => setTimeout(() => { throw new Error('a deliberate page error'); }, 0)")
            page.wait_for_timeout(500)
        finally:
            server.stop()
            server.join(timeout=10)
            clear_patched_curdocs()  # the failing load callback left its document patched in as Bokeh's curdoc()
    assert any("ZeroDivisionError" in e for e in log.errors), log.errors
    assert any("a deliberate page error" in e for e in errors)  # named expected above: the fixture lets it pass
    assert any("ZeroDivisionError" in e for e in errors)  # BokehJS reports the server's error reply too
    assert unexpected(errors, [re.compile("a deliberate page error"), re.compile("ZeroDivisionError")]) == []
    assert not any(isinstance(h, ServerLog) for h in logging.getLogger().handlers)  # detached after the test


@pytest.mark.slow
def test_a_click_on_an_atlas_cell_then_the_spectrum_tab_shows_its_parameters(atlas_with_small: Path, served_app: str,
                                                                             browser_page) -> None:
    """A journey across tabs: a click on the heat map sets the shared parameters; the Spectrum tab shows them."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=atlas&atlas=small")
    page.wait_for_function(f"() => ({_IMAGE_JS})() !== null", timeout=WAIT)
    idle(page)
    canvas = page.locator(".bk-Figure").first
    box = canvas.bounding_box()
    page.mouse.click(box["x"] + 0.5 * box["width"], box["y"] + 0.5 * box["height"])
    page.get_by_text("Parameters set from the atlas cell").first.wait_for(timeout=WAIT)
    show_tab(page, "Spectrum")
    wait_for_figures(page, ["Growth rate", "Phase velocity"])
    gamma = page.evaluate("() => Array.from(Bokeh.documents[0].all_models).find(m => m.type === 'Slider' && "
                          "m.title === 'γ').value")
    assert any(math.isclose(gamma, g, rel_tol=1e-9) for g in SMALL["gamma"])
    assert set_slider(page, "γ", 3.0)
    idle(page)
    stored = xr.open_zarr(atlas_with_small / "small.zarr", consolidated=False)
    assert stored.growth.size == math.prod(len(v) for v in SMALL.values())


@pytest.mark.slow
def test_the_spectrum_names_both_verdicts_where_only_another_branch_is_unstable(served_app: str,
                                                                                 browser_page) -> None:
    """At gamma = 2 (f = 0.9, beta = 0.3, eta = inf) the Rayleigh branch is stable and sliding is not (a backward
    intersonic root at kH ~ 20). The readout says both, with the family, and the growth-rate plot marks the sliding
    maximum (a star at Im z ~ 3.6e-5) beside the Rayleigh branch; back at gamma = 3 (both unstable) the star moves to
    the supersonic mode, 9.3 times the Rayleigh branch's maximum."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1600})
    open_app(page, served_app + "?gamma=2")
    wait_for_figures(page, ["Growth rate"])
    sliding = page.locator("p", has_text="Sliding unstable").first
    sliding.wait_for(timeout=WAIT)
    text = sliding.text_content()
    assert "intersonic guided mode" in text and "kH = 19.81" in text, text
    page.get_by_text("Rayleigh branch stable").first.wait_for(timeout=WAIT)

    def star() -> list[dict]:
        (fig,) = [f for f in figures(page) if f["title"] == "Growth rate"]
        return [g for g in fig["glyphs"] if g["type"] == "Scatter" and g["n"] == 1]

    page.wait_for_function("() => Bokeh.documents[0].is_idle", timeout=WAIT)
    stars = star()
    assert any(abs(g["hi"] - 3.626e-5) < 1e-7 for g in stars), stars
    save_screenshot(page, "spectrum_sliding_gamma2.png", full_page=False)
    page.goto(served_app + "?gamma=3", wait_until="load")
    page.wait_for_function("() => window.Bokeh !== undefined && Bokeh.documents.length > 0", timeout=30_000)
    page.locator("p", has_text="supersonic guided mode (9.28").first.wait_for(timeout=WAIT)
    wait_for_figures(page, ["Growth rate"])
    assert any(abs(g["hi"] - 0.09904) < 1e-4 for g in star())
    # the All-branches tab at gamma = 2, kH = 19.81: the fastest root (Im z = 3.6e-5) lies below the default window
    # (Im z >= 1e-4): drawn as a star and reported, with its family
    page.goto(served_app + "?gamma=2&tab=branches&kH=19.81", wait_until="load")
    fastest = page.locator("p", has_text="Fastest root, every branch").first
    fastest.wait_for(timeout=WAIT)
    text = fastest.text_content()
    assert "intersonic guided mode" in text and "lies outside the window" in text, text
    wait_for_figures(page, ["z-plane at kH"])
    (zplane,) = [f for f in figures(page) if f["title"].startswith("z-plane at kH")]
    assert any(g["type"] == "Scatter" and g["n"] == 1 and abs(g["hi"] - 3.6e-5) < 1e-6 for g in zplane["glyphs"])
    save_screenshot(page, "all_branches_fastest_outside_window.png", full_page=False)


@pytest.mark.ui
@pytest.mark.expected_errors(browser=["[Ww]eb[Ss]ocket", "ERR_CONNECTION_REFUSED", "[Ll]ost.*connection"])
@pytest.mark.slow
def test_a_lost_server_is_said_on_the_page(free_port: int, browser_context) -> None:
    """When the server stops, the page says so (a notification that stays) instead of leaving plots that silently
    no longer follow the controls."""
    import panel as pn

    from asymslide.app.main import create_app

    server = pn.serve(create_app, port=free_port, address="127.0.0.1", websocket_origin=[f"127.0.0.1:{free_port}"],
                      threaded=True, show=False, start=True, verbose=False)
    try:
        page = browser_context()
        open_app(page, f"http://127.0.0.1:{free_port}/")
        assert page.get_by_text("Connection to the asymslide server lost").count() == 0
    finally:
        server.stop()
        server.join(timeout=10)
        clear_patched_curdocs()
    note = page.get_by_text("Connection to the asymslide server lost").first
    note.wait_for(state="visible", timeout=WAIT)
    page.wait_for_timeout(4000)  # it stays (a toast of the default duration would be gone after 3 s)
    assert note.is_visible()
    save_screenshot(page, "screenshot_connection_lost.png", full_page=False)


@pytest.mark.ui
@pytest.mark.slow
def test_the_eta_slider_reads_its_value_once_eta_is_finite(served_app: str, browser_page) -> None:
    """After "η = ∞" was unticked the slider once still read "η: ∞" (its value was then 10⁸), also when the lab link
    set η = 4. Ticked it shows no number; unticked it reads its value, and follows a move."""
    page = browser_page
    open_app(page, served_app)
    title = page.locator(".bk-input-group", has_text="η:").first
    assert "∞" not in title.inner_text() and "10" not in title.inner_text()
    page.get_by_text("η = ∞").first.click()
    page.wait_for_function("(el) => el.innerText.includes('10⁸')", arg=title.element_handle(), timeout=WAIT)
    assert set_slider(page, "η", math.log10(4.0))
    page.wait_for_function("(el) => el.innerText.includes('4')", arg=title.element_handle(), timeout=WAIT)
    assert "∞" not in title.inner_text()
