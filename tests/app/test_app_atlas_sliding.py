"""The Atlas tab on an atlas swept with --sliding: the heat map coloured by the sliding verdict over every branch by
default (the stored verdict_all, growth_all, family_all), a switch to the Rayleigh branch's growth, both verdicts in
the readouts and at a clicked cell, the colouring in the URL, the CSV; an atlas of the Rayleigh branch only says so;
and a browser journey on a slice where only another branch is unstable."""

from __future__ import annotations

import math
import re
import shutil
import urllib.parse
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from asymslide.app import sliding_map as slm
from asymslide.app.atlas.heatmap import FILLED_CLASSES
from asymslide.app.atlas.request import AtlasRequest
from asymslide.app.atlas.scene import AtlasScene
from asymslide.app.common import FAMILY_NAMES
from asymslide.app.urlstate import parse_query, query_string
from asymslide.atlas import plan, store
from asymslide.atlas import sweep as S
from tests.conftest import open_app, save_screenshot
from tests.support.headless import build_app

KH = np.logspace(-3, 3, 33)
#: every class of the sliding verdict: stable at gamma = 1, Rayleigh-stable / sliding-unstable rows, both unstable
AXES = {"gamma": np.geomspace(1.0, 10.0, 8), "beta": np.linspace(0.3, 0.6, 6)}
#: a slice where the Rayleigh branch is stable everywhere and sliding unstable everywhere (guided modes)
HIDDEN = {"gamma": np.geomspace(1.4, 2.2, 5), "beta": np.linspace(0.35, 0.6, 6)}
FIXED = {"f": 0.9}
#: an adaptive atlas of the sliding verdict (asymslide sweep --adaptive --verdict sliding): both boundaries cross it
ADAPTIVE = {"beta": np.linspace(0.2, 0.7, 17), "gamma": np.geomspace(0.3, 30, 17)}
#: an atlas with the threshold of sliding in gamma (asymslide sweep --sliding-thresholds): below the Rayleigh one
THRESHOLDS = {"gamma": np.geomspace(0.5, 4.0, 8), "f": np.array([0.5, 0.7, 0.9, 1.2])}


@pytest.fixture(scope="module")
def sliding_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("sliding_atlases")
    S.sweep(AXES, fixed=FIXED, kH=KH, gamma_c=False, sliding=True, store=directory / "both.zarr")
    S.sweep(HIDDEN, fixed=FIXED, kH=KH, gamma_c=False, sliding=True, store=directory / "hidden.zarr")
    S.sweep(AXES, fixed=FIXED, kH=KH, gamma_c=False, store=directory / "rayleigh.zarr")
    S.sweep(ADAPTIVE, fixed={"eta": math.inf}, kH=KH, gamma_c=False, sliding=True, adaptive={"levels": 2},
            store=directory / "adaptive.zarr")
    S.sweep(THRESHOLDS, fixed={"beta": 0.3}, kH=KH, sliding=plan.SlidingSpec(thresholds=True),
            store=directory / "thresholds.zarr")
    return directory


@pytest.fixture
def atlas_dir(sliding_store: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    directory = tmp_path / "atlases"
    shutil.copytree(sliding_store, directory)
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(directory))
    store.read_atlas.cache_clear()
    return directory


def _stored(directory: Path, name: str) -> xr.Dataset:
    return xr.open_zarr(directory / f"{name}.zarr", consolidated=False).load()


def _scene(name: str, x: str = "beta", **kwargs) -> AtlasScene:
    scene = AtlasScene(requested=AtlasRequest(name=name, x=x, y="gamma", **kwargs))
    scene.refresh()
    scene._show_heat_map()
    assert scene.image_pane.object is scene.heat_map().figure
    return scene


@pytest.mark.slow
def test_the_heat_map_is_coloured_by_the_stored_sliding_verdict(atlas_dir: Path) -> None:
    scene = _scene("both")
    ds = _stored(atlas_dir, "both")
    v = ds["verdict_all"].values  # (gamma, beta): rows gamma, columns beta as the slice
    assert scene.colours_sliding() and scene.verdict_select.visible
    heat = scene.heat_map()
    assert not heat.heat_renderer.visible and heat.sliding_colorbar.visible and not heat.colorbar.visible
    assert "sliding verdict (every branch, Im z ≥ 1e-06)" in heat.figure.title.text
    colours = np.array(heat.sliding_classes.data["color"], dtype=object)
    assert list(colours) == [slm.VERDICT_COLOURS[k] for k in v.ravel()]
    growth = np.asarray(heat.sliding_growth.data["growth_all"], dtype=float)
    np.testing.assert_array_equal(growth, np.where(v == 1, ds["growth_all"].values, np.nan).ravel())
    words = list(heat.sliding_growth.data["sliding"])
    fam = ds["family_all"].values.ravel()
    for word, verdict, family in zip(words, v.ravel(), fam, strict=True):
        if verdict == 1:
            assert word == f"unstable: {FAMILY_NAMES[int(family)]}"
        else:
            assert word.startswith("stable: no root of any branch")
    assert {0, 1} <= set(v.ravel().tolist())  # the slice has both classes

    text = scene.slice_readout()
    r = ds["verdict"].values
    hidden = int(((r == 0) & (v == 1)).sum())
    assert hidden > 0
    assert (f"**This slice, sliding (every branch)** unstable {int((v == 1).sum())}, stable {int((v == 0).sum())}, "
            f"undetermined 0, not computed 0; Rayleigh-branch stable but sliding unstable {hidden}") in text
    assert "**Sliding (every branch)** Im z ≥ 1e-06, kH 0.01 to 100: unstable" in scene.readout()


def test_colouring_by_the_rayleigh_branch_shows_its_growth_and_goes_into_the_url(atlas_dir: Path) -> None:
    scene = _scene("both")
    scene.verdict = slm.RAYLEIGH
    heat = scene.heat_map()
    assert heat.heat_renderer.visible and heat.colorbar.visible and not heat.sliding_colorbar.visible
    assert heat.sliding_classes.data["color"] == [] and "max growth rate" in heat.figure.title.text
    state = scene.url_state()
    assert state["verdict"] == slm.RAYLEIGH
    app = build_app({"tab": ["atlas"], "atlas": ["both"], "atlas_verdict": ["rayleigh"]})
    app.atlas.refresh()
    assert app.atlas.verdict == slm.RAYLEIGH and not app.atlas.colours_sliding()
    query = query_string(app.param_objects(), "atlas", app.atlas.url_state())
    assert "atlas_verdict=rayleigh" in query
    updates, _, messages = parse_query(urllib.parse.parse_qs(query[1:]))
    assert updates["atlas"]["verdict"] == slm.RAYLEIGH and messages == []
    _, _, messages = parse_query({"atlas_verdict": ["<b>every</b>"]})  # nothing typed is evaluated or rendered
    assert messages == ["atlas_verdict = '&lt;b&gt;every&lt;/b&gt;' is not one of sliding, rayleigh: ignored."]


def test_a_click_reads_both_verdicts_of_the_cell(atlas_dir: Path) -> None:
    scene = _scene("hidden")
    ds = _stored(atlas_dir, "hidden")
    d = scene.data
    x, y = d.display("beta")[2], d.display("gamma")[1]
    scene._on_tap(x=x, y=y)
    fam = FAMILY_NAMES[int(ds["family_all"].values[1, 2])]
    g, k, rez = (float(ds[n].values[1, 2]) for n in ("growth_all", "kH_at_max_all", "re_z_at_max_all"))
    assert "Rayleigh branch: stable." in scene.message
    assert f"Sliding (every branch): unstable: {fam}, max Im[c/c_s] = {g:.4g} at kH = {k:.4g}" in scene.message
    assert f"z = {rez:.6g} + {g:.4g}i" in scene.message


def test_an_atlas_of_the_rayleigh_branch_only_says_so(atlas_dir: Path) -> None:
    scene = _scene("rayleigh")
    assert not scene.colours_sliding() and not scene.verdict_select.visible
    assert "**Rayleigh branch only**" in scene.readout()
    assert "The atlas holds the Rayleigh branch only" in scene.slice_readout()
    assert scene.heat_map().heat_renderer.visible


def test_the_csv_holds_the_sliding_variables(atlas_dir: Path) -> None:
    scene = _scene("both")
    ds = _stored(atlas_dir, "both")
    lines = scene.csv().getvalue().splitlines()
    names = lines[1].split(",")
    data = np.genfromtxt(lines[2:], delimiter=",")
    for name in ("verdict_all", "family_all", "growth_all"):
        assert name in names
    np.testing.assert_array_equal(data[:, names.index("verdict_all")], ds["verdict_all"].values.ravel())
    np.testing.assert_array_equal(data[:, names.index("growth_all")], ds["growth_all"].values.ravel())


@pytest.mark.ui
@pytest.mark.slow
def test_the_atlas_cell_says_where_only_another_branch_is_unstable(atlas_dir: Path, served_app: str,
                                                                    browser_page) -> None:
    """A user opens an atlas swept with --sliding whose slice is Rayleigh-branch stable and sliding unstable: the
    heat map is coloured by the sliding verdict, the readout counts the hidden points, a click on a cell reads both
    verdicts with the family; the Rayleigh colouring and back."""
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1400})
    open_app(page, served_app + "?tab=atlas&atlas=hidden&ax=beta&ay=gamma")
    readout = page.locator("p", has_text="This slice, sliding (every branch)").first
    readout.wait_for(timeout=90_000)
    assert "Rayleigh-branch stable but sliding unstable 30" in readout.text_content()
    page.wait_for_function("() => Bokeh.documents[0].is_idle", timeout=30_000)
    canvas = page.locator(".bk-Figure").first
    box = canvas.bounding_box()
    page.mouse.click(box["x"] + 0.45 * box["width"], box["y"] + 0.5 * box["height"])
    message = page.get_by_text("Parameters set from the atlas cell").first
    message.wait_for(timeout=60_000)
    text = message.text_content()
    assert "Rayleigh branch: stable." in text, text
    dimmed = page.evaluate("() => Array.from(Bokeh.documents[0].all_models).filter(m => m.type === 'GlyphRenderer' "
                           "&& m.data_source && m.data_source.data.growth_all !== undefined).map(r => "
                           "r.nonselection_glyph.fill_alpha.value)")
    assert dimmed == [1.0], dimmed  # a click selects a cell: the others keep their colour
    assert re.search(r"Sliding \(every branch\): unstable: (intersonic|supersonic) guided mode, max Im", text), text
    save_screenshot(page, "atlas_sliding.png", full_page=False)
    page.get_by_role("button", name=slm.RAYLEIGH).click()
    page.wait_for_function("() => Array.from(Bokeh.documents[0].all_models).some(m => m.type === 'Title' && "
                           "m.text.includes('max growth rate'))", timeout=60_000)
    assert "atlas_verdict=rayleigh" in page.evaluate("() => window.location.search")
    page.get_by_role("button", name=slm.SLIDING).click()
    page.wait_for_function("() => Array.from(Bokeh.documents[0].all_models).some(m => m.type === 'Title' && "
                           "m.text.includes('sliding verdict'))", timeout=60_000)
    assert page.console_errors == []


@pytest.mark.slow
def test_an_adaptive_sliding_atlas_shows_the_filled_verdict_it_colours(atlas_dir: Path) -> None:
    """Not computed cells of an adaptive atlas swept on the sliding verdict: pale in the class of their cell of the
    sliding verdict (hover "sliding verdict ... from its cell"), of the Rayleigh branch's once it is chosen; the
    readouts count the filled classes; a click on a not computed cell reads both filled classes."""
    scene = _scene("adaptive")
    ds = _stored(atlas_dir, "adaptive")
    computed = ds["computed"].values  # (beta, gamma): the slice is (gamma, beta)
    hit = (computed < 0).T.ravel()
    assert 0 < hit.sum() < hit.size
    heat = scene.heat_map()
    pale = {k: colour for k, (_, colour) in FILLED_CLASSES.items()}

    def filled(name: str) -> list[str]:
        return [pale[int(k)] for k in ds[name].values.T.ravel()[hit]]

    assert filled("verdict_filled_all") != filled("verdict_filled")  # cells filled differently by the two verdicts
    # one legend item per layer (Bokeh merged the filled cells' and the sliding classes' items when both had the label
    # field "legend": the browser drew the classes' swatches beside the filled cells' labels)
    assert all(len(item.renderers) == 1 for item in heat.figure.legend[0].items)
    assert set(heat.filled.data["filled_legend"]) <= {f"not computed: sliding {w} (from its cell)"
                                                      for w in ("stable", "unstable", "undetermined")}
    assert scene.colours_sliding() and list(heat.filled.data["color"]) == filled("verdict_filled_all")
    assert all(w.startswith("sliding verdict ") and "from its cell (level " in w for w in heat.filled.data["why"])
    s = ds["verdict_filled_all"].values
    assert (f"**This slice, sliding (every branch)** ({int((~hit).sum())} computed, the others filled from their "
            f"cell) unstable {int((s == 1).sum())}, stable {int((s == 0).sum())}") in scene.slice_readout()
    assert "refined on both verdicts" in scene.readout()
    i, j = np.argwhere(computed < 0)[0]  # (beta, gamma) of a not computed point
    scene._on_tap(x=scene.data.display("beta")[i], y=scene.data.display("gamma")[j])
    words = {0: "stable", 1: "unstable", 2: "undetermined"}
    assert f"Rayleigh branch: not computed ({words[int(ds['verdict_filled'].values[i, j])]} from its cell)" in (
        scene.message)
    assert f"Sliding (every branch): not computed ({words[int(s[i, j])]} from its cell)" in scene.message
    scene.verdict = slm.RAYLEIGH
    assert list(heat.filled.data["color"]) == filled("verdict_filled")
    assert all(w.startswith("verdict ") for w in heat.filled.data["why"])


def test_the_threshold_of_sliding_is_drawn_with_the_sliding_verdict(atlas_dir: Path) -> None:
    """An atlas swept with --sliding-thresholds: coloured by the sliding verdict, its γ_c over every branch is drawn
    (dash-dotted, purple) through the stored crossings, beside the Rayleigh branch's; the readout counts both;
    colouring by the Rayleigh branch hides it."""
    scene = _scene("thresholds", x="f")
    ds = _stored(atlas_dir, "thresholds")
    heat = scene.heat_map()
    crossing, reason = ds["gamma_c_all_crossing"].values, ds["gamma_c_all_crossing_reason"].values
    assert np.isin(reason[:, 0], (0, 1)).all()  # one certified crossing at every f
    drawn = heat.sliding_thresholds.data
    assert len(drawn["xs"]) == 1  # one run along f
    np.testing.assert_allclose(drawn["xs"][0], THRESHOLDS["f"])
    np.testing.assert_allclose(drawn["ys"][0], np.log10(crossing[:, 0]))  # gamma is a log axis: log10 plotted
    legend = [str(item.label) for item in heat.figure.legend[0].items if item.visible]
    assert any("sliding γ_c (every branch; certified)" in label for label in legend)
    text = scene.readout()
    assert "**Thresholds of sliding in γ (every branch; dash-dotted, purple)** 4 certified crossing(s)" in text
    assert "**Thresholds in γ (Rayleigh branch)**" in text
    assert "and of sliding over every branch (purple, dash-dotted)." in scene.help_text()
    scene.verdict = slm.RAYLEIGH
    assert heat.sliding_thresholds.data["xs"] == []
