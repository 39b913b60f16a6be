"""A user holds the f slider of the Stability map (off its plane) in a real browser: while the handle is held the map
shows a coarse preview of the held f, said to be one, and after the release the full map of the final f, no longer
called a preview; the server logs no error (conftest ``server_log``) and the page no console error
(``browser_context``). Once coloured by the Rayleigh branch (the preview: its growth at 12 x 12 points, equal to
model.growth_analysis), once by the sliding verdict (the preview: 6 x 6 points)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from asymslide import model
from asymslide.app.params import SpectrumParams
from asymslide.app.stability_map import grids, map_plot, preview
from asymslide.app.stability_map.grids import KH, PLANES
from tests.conftest import download, open_app, save_screenshot

pytestmark = [pytest.mark.ui, pytest.mark.usefixtures("fresh_caches")]

#: a long computation on a loaded 2-core host (ms)
WAIT = 180_000

#: the renderers of the map plot on the page (the plot whose title names a plane): `(m, r) => result or undefined`
#: is called on each; the first result is returned (null: none)
_ON_MAP_JS = """(pick) => {
  for (const m of Bokeh.documents[0].all_models) {
    if (!(m.title && m.title.text && m.title.text.includes(' plane'))) continue;
    const view = Bokeh.index.find_one(m);
    if (!view || !view.el || !view.el.isConnected) continue;
    for (const r of m.renderers) {
      const out = pick(m, r);
      if (out !== undefined) return out;
    }
  }
  return null;
}"""

#: the heat map drawn: its title and its cells' data
_HEAT_JS = """() => (""" + _ON_MAP_JS + """)((m, r) => {
      const d = r.data_source ? r.data_source.data : undefined;
      if (!d || d.left === undefined || d.bottom === undefined) return undefined;
      const key = d.growth !== undefined ? 'growth' : (d.growth_all !== undefined ? 'growth_all' : null);
      if (key === null) return undefined;
      const f = a => Array.from(a);
      const label = d.shown !== undefined ? d.shown : d.value_of;
      return {title: m.title.text, cells: d.left.length, left: f(d.left), bottom: f(d.bottom),
              growth: f(d[key]).map(v => Number.isFinite(v) ? v : null), shown: label ? f(label) : []};
})"""

#: the text of the readout line that names the preview's values
_PREVIEW_LINE = re.compile(r"The map drawn is a preview of f = ([0-9.]+),")


def _slider(page):
    """The f slider of the shared parameters (not the Lab panel's "f (friction coefficient)")."""
    return page.locator(".bk-input-group").filter(has_text=re.compile(r"^\s*f:")).first


def _press_and_move(page, fraction: float, moves: int = 12) -> None:
    """Press the f handle and move it, `moves` steps over ~1 s, to `fraction` of its track; the button stays down."""
    slider = _slider(page)
    handle, track = slider.locator(".noUi-handle").first, slider.locator(".noUi-base").first
    hb, tb = handle.bounding_box(), track.bounding_box()
    x0, y = hb["x"] + hb["width"] / 2, hb["y"] + hb["height"] / 2
    x1 = tb["x"] + fraction * tb["width"]
    page.mouse.move(x0, y)
    page.mouse.down()
    for i in range(1, moves + 1):
        page.mouse.move(x0 + (x1 - x0) * i / moves, y)
        page.wait_for_timeout(80)


def _held_f(page) -> float:
    return float(_slider(page).locator(".bk-slider-value").inner_text())


def _heat_grid(d: dict, plane: str, n: int) -> np.ndarray:
    """The heat map's growth as an n x n array (rows: y), NaN where not finite, from its cells' lower-left edges."""
    ax, ay = PLANES[plane]
    xe, ye = ax.edges(n), ay.edges(n)
    out = np.full((n, n), np.inf)
    for left, bottom, g in zip(d["left"], d["bottom"], d["growth"], strict=True):
        j = int(np.argmin(np.abs(np.log(xe[:-1] / left)))) if ax.log else int(np.argmin(np.abs(xe[:-1] - left)))
        i = int(np.argmin(np.abs(np.log(ye[:-1] / bottom)))) if ay.log else int(np.argmin(np.abs(ye[:-1] - bottom)))
        out[i, j] = np.nan if g is None else g
    return out


def _growth(plane: str, n: int, f: float) -> np.ndarray:
    """model.growth_analysis over the plane at n x n points, the other parameters the defaults but f."""
    ax, ay = PLANES[plane]
    x, y = grids.plane_axes(plane, n)
    args = dict(zip(SpectrumParams.MODEL_ARGS, SpectrumParams(f=f).model_args(), strict=True))
    args[ax.name], args[ay.name] = x[None, :], y[:, None]
    return np.asarray(model.growth_analysis(KH, **args).growth, float)


def _wait_for_preview_of_the_held_value(page) -> float:
    """While the handle is held: wait until the map drawn is the preview of the value the slider shows; that f."""
    line = page.locator("p", has_text="The map drawn is a preview of f = ")
    for _ in range(600):
        f = _held_f(page)
        texts = line.all_text_contents()
        shown = [float(m.group(1)) for t in texts if (m := _PREVIEW_LINE.search(t))]
        if shown and math.isclose(shown[0], f, rel_tol=1e-9):
            return f
        page.wait_for_timeout(200)
    raise AssertionError(f"no preview of the held f = {_held_f(page)} within 120 s: {line.all_text_contents()}")


def _wait_for_drawn_preview(page, plane: str, expected: np.ndarray) -> dict:
    """The heat map once it draws `expected` (the preview of the held value, p x p): the readout can name the new
    preview a render before the heat map's data arrive (under load, an earlier preview of the same size is still
    drawn); the caller's assertion then compares what is drawn (the last one read, if never)."""
    p = expected.shape[0]
    d = None
    for _ in range(600):
        d = page.evaluate(_HEAT_JS)
        if d is not None and d["cells"] == p * p and np.allclose(_heat_grid(d, plane, p), expected, rtol=1e-12, atol=0,
                                                                   equal_nan=True):
            break
        page.wait_for_timeout(200)
    assert d is not None
    return d


@pytest.mark.slow
def test_a_held_f_slider_previews_the_rayleigh_map_and_the_release_draws_the_full_one(served_app: str,
                                                                                       browser_page) -> None:
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=map&map_res=coarse&map_verdict=rayleigh")
    n, plane = grids.RESOLUTIONS["coarse"], "η-γ"
    page.get_by_text(f"The {plane} map ({n} × {n} points)", exact=True).first.wait_for(timeout=WAIT)
    page.wait_for_function(f"() => {{ const d = ({_HEAT_JS})(); return d !== null && d.cells === {n * n}; }}",
                           timeout=WAIT)

    _press_and_move(page, 0.3)  # f from 0.9 towards 0.6, held
    try:
        p = preview.PREVIEW_POINTS
        page.get_by_text(f"Preview while the slider is held: {p} × {p} points; the full map is computed at the "
                         "release").first.wait_for(timeout=WAIT)
        f = _wait_for_preview_of_the_held_value(page)
        d = _wait_for_drawn_preview(page, plane, _growth(plane, p, f))
        assert d["title"].endswith(f"over the {plane} plane: preview, {p} × {p} points"), d["title"]
        assert set(d["shown"]) == {f"preview, {p} × {p} points (the full map is computed at the release)"}
        np.testing.assert_allclose(_heat_grid(d, plane, p), _growth(plane, p, f), rtol=1e-12, atol=0)
        save_screenshot(page, "map_preview_rayleigh.png", full_page=False)
    finally:
        page.mouse.up()

    page.get_by_text(f"The {plane} map ({n} × {n} points)", exact=True).first.wait_for(timeout=WAIT)
    page.wait_for_function(f"() => {{ const d = ({_HEAT_JS})(); return d !== null && d.cells === {n * n} "
                           "&& !d.title.includes('preview'); }", timeout=WAIT)
    d = page.evaluate(_HEAT_JS)
    assert set(d["shown"]) == {"the map"}
    np.testing.assert_allclose(_heat_grid(d, plane, n), _growth(plane, n, _held_f(page)), rtol=1e-12, atol=0)
    assert page.get_by_text("Preview while the slider is held").count() == 0
    assert page.locator("p", has_text="The map drawn is a preview").count() == 0


@pytest.mark.slow
def test_a_held_f_slider_previews_the_sliding_verdict_and_the_release_draws_the_full_map(served_app: str,
                                                                                        browser_page) -> None:
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=map&map=beta-gamma&map_res=coarse")
    n, plane = grids.RESOLUTIONS["coarse"], "β-γ"
    page.get_by_text(f"The sliding verdict over the {plane} map ({n} × {n} points)", exact=True).first.wait_for(
        timeout=WAIT)

    _press_and_move(page, 0.3)
    try:
        p = preview.PREVIEW_SLIDING_POINTS
        _wait_for_preview_of_the_held_value(page)
        page.wait_for_function(f"() => {{ const d = ({_HEAT_JS})(); return d !== null && d.cells === {p * p} && "
                               "d.shown.every(s => s.startsWith('preview, ')); }", timeout=WAIT)
        d = page.evaluate(_HEAT_JS)
        assert d["title"].endswith(f"over the {plane} plane: preview, {p} × {p} points"), d["title"]
        page.get_by_text(f"Preview while the slider is held: {p} × {p} points").first.wait_for(timeout=WAIT)
        save_screenshot(page, "map_preview_sliding.png", full_page=False)
    finally:
        page.mouse.up()

    page.get_by_text(f"The sliding verdict over the {plane} map ({n} × {n} points)", exact=True).first.wait_for(
        timeout=WAIT)
    page.wait_for_function(f"() => {{ const d = ({_HEAT_JS})(); return d !== null && d.cells === {n * n} && "
                           "d.shown.every(s => s === 'this point') && !d.title.includes('preview'); }",
                           timeout=WAIT)
    assert page.get_by_text("Preview while the slider is held").count() == 0
    assert page.locator("p", has_text="The map drawn is a preview").count() == 0


#: the purple line of the sliding boundary on the page: its segments' y values (one list per segment)
_BOUNDARY_JS = """() => (""" + _ON_MAP_JS + """)((m, r) => {
  const g = r.glyph, c = g ? g.line_color : undefined;
  const colour = c && c.value !== undefined ? c.value : c;  // a value spec: {value: '#762a83'}
  if (colour !== 'COLOUR' || !r.data_source || r.data_source.data.ys === undefined) return undefined;
  return Array.from(r.data_source.data.ys).map(a => Array.from(a));
})""".replace("COLOUR", map_plot.SLIDING_BOUNDARY_COLOR)


@pytest.mark.slow
def test_the_sliding_boundary_is_drawn_and_stays_when_the_colouring_is_switched_and_back(served_app: str,
                                                                                        browser_page) -> None:
    """β-γ at η = ∞ (24 × 24): after the sliding map, the purple threshold of sliding over every branch is drawn
    through the model's certified thresholds (model.critical_gammas branches="all", computed here); colouring by the
    Rayleigh branch removes it, and coming back draws it again at once (from the cache), never a stale view."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=map&map=beta-gamma&map_res=coarse")
    n = grids.RESOLUTIONS["coarse"]
    done = f"at {n} of {n} x values"
    page.get_by_text(re.compile(re.escape(done))).first.wait_for(timeout=WAIT)
    x, _ = grids.plane_axes("β-γ", n)
    edges = PLANES["β-γ"][1].edges(n)
    p = SpectrumParams()
    want = model.critical_gammas(f=p.f, beta=x, gamma_range=(float(edges[0]), float(edges[-1])), branches="all",
                                 max_crossings=4)
    ok = np.isin(want.reason, (0, 1)) & np.isfinite(want.value)
    page.wait_for_function(f"() => {{ const s = ({_BOUNDARY_JS})(); return s !== null && s.length > 0; }}",
                           timeout=WAIT)
    segments = page.evaluate(_BOUNDARY_JS)
    drawn = np.round(np.concatenate([np.asarray(s, float) for s in segments]), 9)
    assert set(drawn) <= set(np.round(want.value[ok], 9)) and len(set(drawn)) >= n // 2
    save_screenshot(page, "map_sliding_boundary.png", full_page=False)
    text = download(page, "Download sliding boundary (CSV)", timeout=WAIT)
    lines = text.splitlines()
    assert lines[0].startswith("# asymslide stability map, plane beta-gamma: crossings in gamma")
    assert lines[1] == "beta,crossing,gamma_c,location,direction,reason,kH,re_z"
    table = np.array([ln.split(",") for ln in lines[2:]], float)
    np.testing.assert_allclose(table[:, 2], want.value[want.reason >= 0], rtol=1e-9, equal_nan=True)

    page.get_by_role("button", name="Rayleigh branch").click()
    page.wait_for_function(f"() => ({_BOUNDARY_JS})() === null", timeout=WAIT)
    page.get_by_role("button", name="sliding (every branch)").click()
    page.wait_for_function(f"() => {{ const s = ({_BOUNDARY_JS})(); return s !== null && s.length === "
                           f"{len(segments)}; }}", timeout=WAIT)
    page.get_by_text(re.compile(re.escape(done))).first.wait_for(timeout=WAIT)
