"""The Atlas tab opens an adaptive atlas, in a real browser from a fresh page.

The heat map shows the computed values (NaN in the image where a point was not computed), the not computed cells in
the pale colour of their filled verdict class with a hover that says so, a legend entry per class shown, the neutral
curve only through computed cells, and the evaluated fraction in the readout. The test fails on any server log error
or browser console error (conftest ``served_app``, ``browser_context``).
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from asymslide.app.atlas.heatmap import FILLED_CLASSES
from asymslide.app.atlas.readout import adaptive_readout
from asymslide.app.atlas.scene import AtlasScene
from asymslide.app.plotting import fmt
from asymslide.atlas import refinement
from asymslide.atlas import sweep as S
from tests.browser.test_journeys import _IMAGE_JS, WAIT, idle
from tests.conftest import open_app, save_screenshot

KH = np.logspace(-3, 3, 33)
#: γ × f × β with 17 = 4·2^2 + 1 and 5 = 2^2 + 1 points (two levels of refinement from a 5 × 5 × 2 coarse grid)
AXES = {"gamma": np.geomspace(0.1, 30, 17), "f": np.linspace(0.2, 1.5, 17), "beta": np.linspace(0.1, 0.6, 5)}

#: per glyph renderer of the page: glyph type, the columns of its source, the number of rows, whether it is shown,
#: the hover tooltips attached to it, and the first `why` texts and the distinct `legend` labels of its source
_LAYERS_JS = """() => {
  const out = [];
  const doc = Bokeh.documents[0];
  const models = Array.from(doc.all_models);
  const hovers = models.filter(m => m.type === 'HoverTool');
  for (const r of models) {
    if (r.type !== 'GlyphRenderer' || !r.glyph) continue;
    const data = r.data_source.data;
    const cols = Object.keys(data);
    const n = cols.length ? Array.from(data[cols[0]]).length : 0;
    const tips = hovers.filter(h => (h.renderers === 'auto' ? [] : h.renderers).includes(r))
      .map(h => h.tooltips.map(t => t.join(': ')).join(' | '));
    out.push({type: r.glyph.type, cols: cols, n: n, visible: r.visible, tips: tips,
              why: data.why ? Array.from(data.why).slice(0, 3) : [],
              legend: data.legend ? Array.from(new Set(Array.from(data.legend))) : [],
              filled_legend: data.filled_legend ? Array.from(new Set(Array.from(data.filled_legend))) : []});
  }
  return out;
}"""

#: the heat map image's values (row-major, y then x; null where NaN)
_IMAGE_VALUES_JS = """() => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.type !== 'GlyphRenderer' || !m.glyph || m.glyph.type !== 'Image') continue;
    const a = m.data_source.data['image'][0];
    return Array.from(a.length !== undefined ? a : (a.array ?? [])).map(v => Number.isFinite(v) ? v : null);
  }
  return null;
}"""


@pytest.fixture(scope="module")
def adaptive_atlas(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("adaptive-atlases") / "adaptive.zarr"
    S.sweep(AXES, fixed={"xi": 1.0}, kH=KH, store=path, adaptive=refinement.AdaptiveSpec(levels=2))
    return path


@pytest.fixture
def atlas_dir_with_adaptive(adaptive_atlas: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A fresh atlas directory holding the adaptive atlas."""
    shutil.copytree(adaptive_atlas, tmp_path / "adaptive.zarr")
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path))
    return tmp_path


@pytest.mark.ui
@pytest.mark.slow
def test_an_adaptive_atlas_shows_computed_values_and_filled_classes_apart(
        atlas_dir_with_adaptive: Path, served_app: str, browser_page) -> None:
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=atlas&atlas=adaptive&ax=gamma&ay=f&at_beta=0.35")
    page.wait_for_function(f"() => ({_IMAGE_JS})() !== null", timeout=WAIT)
    idle(page)
    ds = xr.open_zarr(atlas_dir_with_adaptive / "adaptive.zarr", consolidated=False)
    at = {"beta": 2}
    computed = ds.computed.isel(at).transpose("f", "gamma").values  # the image's rows are y = f
    filled = ds.verdict_filled.isel(at).transpose("f", "gamma").values
    growth = ds.growth.isel(at).transpose("f", "gamma").values
    not_computed = computed < 0
    assert not_computed.any() and (~not_computed).any() and set(np.unique(filled)) >= {0, 1}

    # the image: the computed values where computed (float32 in the browser), nothing where not
    image = page.evaluate(_IMAGE_VALUES_JS)
    values = np.array([np.nan if v is None else v for v in image]).reshape(growth.shape)
    assert np.array_equal(np.isnan(values), np.isnan(growth))
    assert np.isnan(values[not_computed]).all()
    np.testing.assert_allclose(values[~not_computed], growth[~not_computed], rtol=1e-6, atol=1e-12)

    # the filled layer: one pale dotted cell per not computed point, coloured and labelled by its class, with a hover
    layers = page.evaluate(_LAYERS_JS)
    fills = [g for g in layers if g["type"] == "Rect" and "filled_legend" in g["cols"]]
    assert len(fills) == 1, layers
    fill = fills[0]
    assert fill["n"] == int(not_computed.sum())
    want = {f"not computed: {FILLED_CLASSES[int(k)][0]} (from its cell)" for k in np.unique(filled[not_computed])}
    assert set(fill["filled_legend"]) == want
    assert any("not computed: @why" in t for t in fill["tips"]), fill
    assert all(w.startswith("verdict ") and "from its cell (level " in w for w in fill["why"]), fill
    # the computed points: a layer hidden until its legend entry is clicked
    dots = [g for g in layers if g["type"] == "Scatter" and g["n"] == int((~not_computed).sum())]
    assert dots and not dots[0]["visible"]
    page.get_by_text("evaluated fraction").first.wait_for(timeout=WAIT)
    summary = json.loads(ds.attrs["adaptive"])
    assert page.get_by_text(f"{100 * summary['evaluated_fraction']:.1f} %").count() >= 1
    save_screenshot(page, "atlas_adaptive.png")

    # a hover on a not computed cell says so: move the pointer over the figure until the tooltip shows it
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    fig = page.locator(".bk-Figure").first.bounding_box()
    tip = page.get_by_text(re.compile(r"verdict (stable|unstable|undetermined) from its cell \(level \d\)"))
    seen = False
    for fx, fy in ((fx, fy) for fx in np.linspace(0.1, 0.85, 7) for fy in np.linspace(0.15, 0.85, 5)):
        page.mouse.move(fig["x"] + fx * fig["width"], fig["y"] + fy * fig["height"])
        try:
            tip.first.wait_for(state="visible", timeout=1500)
        except PlaywrightTimeout:
            continue
        seen = True
        break
    assert seen, "no tooltip 'verdict ... from its cell (level L)' over the heat map"
    # the same hover names the cell's γ and f as the atlas's grid has them (on the log axis not log10 γ)
    labels = [t.strip().rstrip(":") for t in page.locator(".bk-Tooltip .bk-tooltip-row-label").all_text_contents()]
    values = [t.strip() for t in page.locator(".bk-Tooltip .bk-tooltip-row-value").all_text_contents()]
    rows = dict(zip(labels, values, strict=True))
    assert rows.get("γ") in {fmt(float(v)) for v in AXES["gamma"]}, rows
    assert rows.get("f") in {fmt(float(v)) for v in AXES["f"]}, rows


def test_not_computed_points_are_neither_not_computable_nor_exported_as_values(atlas_dir_with_adaptive: Path) -> None:
    """Headless: the readouts count not computable points among the computed ones only (a not computed point is NaN
    in `growth` too), the 3-D view marks none of the not computed points as masked, and the slice CSV says which
    rows were computed and gives every row its filled class."""
    scene = AtlasScene(requested={"name": "adaptive", "x": "gamma", "y": "f", "at": {"beta": 0.35}})
    scene.refresh()
    d = scene.data
    assert d is not None and d.adaptive and d.filled_level is not None
    readout = adaptive_readout(d)  # the refinement in the words `asymslide info` prints
    assert "margin 0, guard off, boundary followed" in readout and "--guard` looks closer" in readout
    computed = np.asarray(d.computed) >= 0
    masked = int((computed & ~np.isfinite(np.asarray(d.growth))).sum())
    readout = scene.readout()
    assert "evaluated fraction" in readout
    assert ("**Not computable** none" in readout) == (masked == 0)
    assert "computed " in scene.slice_readout() and "filled from their cell" in scene.slice_readout()
    scene.surface_axes = ["gamma", "f", "beta"]
    names = [trace.get("name") for trace in scene.surface_figure()["data"]]
    assert ("not computable (masked)" in names) == (masked > 0)
    text = scene.csv().getvalue()
    header = next(line for line in text.splitlines() if not line.startswith("#"))
    assert "computed_level" in header and "verdict_filled" in header and "Adaptive atlas" in text


@pytest.fixture
def atlas_dir_with_two_axes(atlas_dir_with_adaptive: Path) -> Path:
    """The adaptive atlas's directory with a dense atlas of two axes beside it."""
    S.sweep({"gamma": np.geomspace(0.3, 30, 5), "f": np.linspace(0.3, 1.5, 3)}, fixed={"xi": 1.0, "beta": 0.3},
            kH=KH, store=atlas_dir_with_adaptive / "two.zarr", gamma_c=False)
    return atlas_dir_with_adaptive


def test_an_atlas_of_two_axes_has_no_blank_3d_view(atlas_dir_with_two_axes: Path) -> None:
    """Headless: with two axes the 3-D tab says why there is no surface and hides the empty plot and menu; with three
    it shows them and says nothing."""
    scene = AtlasScene(requested={"name": "two", "x": "gamma", "y": "f"})
    scene.refresh()
    assert scene.data is not None and scene.data.names == ["gamma", "f"]
    assert "No 3-D view of atlas two" in scene.surface_note() and "2 axes (γ, f)" in scene.surface_note()
    assert not scene.surface_pane.visible and not scene.surface_select.visible
    scene.atlas = "adaptive"
    assert scene.data is not None and len(scene.data.names) == 3
    assert scene.surface_note() == "" and scene.surface_pane.visible and scene.surface_select.visible


@pytest.mark.ui
@pytest.mark.slow
def test_the_3d_tab_of_an_atlas_of_two_axes_says_why_it_is_empty(
        atlas_dir_with_two_axes: Path, served_app: str, browser_page) -> None:
    page = browser_page
    open_app(page, served_app + "?tab=atlas&atlas=two&ax=gamma&ay=f")
    page.wait_for_function(f"() => ({_IMAGE_JS})() !== null", timeout=WAIT)
    page.locator(".bk-tab", has_text="3-D neutral surface").first.click()
    page.get_by_text("No 3-D view of atlas two").wait_for(timeout=WAIT)
    save_screenshot(page, "atlas_two_axes_3d.png")
