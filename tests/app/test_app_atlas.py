"""The Atlas tab: slices read from the stored cube (no model call), the γ_c slice, clicks that set the shared
parameters, the 3-D neutral surface, the one atlas directory, and the default atlas computed on first use."""

from __future__ import annotations

import math
import threading
from pathlib import Path
from unittest import mock

import numpy as np
import pytest
import xarray as xr

from asymslide import model
from asymslide.app.atlas import directory as D
from asymslide.app.atlas.heatmap import COLOURS, HeatMap
from asymslide.app.atlas.readout import REFUSED_CROSSING
from asymslide.app.atlas.scene import AtlasScene
from asymslide.app.params import SpectrumParams
from asymslide.atlas import store
from asymslide.atlas import sweep as S
from tests.conftest import save_screenshot
from tests.support.headless import build_app

KH = np.logspace(-3, 3, 33)
AXES = {"gamma": np.geomspace(0.3, 30, 8), "beta": np.linspace(0.1, 0.6, 5), "f": np.linspace(0.3, 1.5, 4)}


@pytest.fixture(scope="module")
def atlas_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("atlases")
    S.sweep(AXES, kH=KH, store=directory / "small.zarr")
    S.sweep({"eta": np.geomspace(2.0, 1e3, 5), "gamma": np.geomspace(0.5, 20, 6)}, kH=KH,
            store=directory / "eta-gamma.zarr")
    return directory


#: a finite-η atlas with every kind of boundary: undetermined (pole-dense) cells at small γ, certified thresholds and a
#: refused sign change (a jump at Δ = 0.2)
BOUNDARY_AXES = {"gamma": np.geomspace(0.1, 10, 9), "Delta": np.linspace(0.2, 1, 5)}
BOUNDARY_FIXED = {"eta": 10.0, "xi": 1.0}


@pytest.fixture(scope="module")
def boundary_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("boundary")
    S.sweep(BOUNDARY_AXES, fixed=BOUNDARY_FIXED, kH=KH, store=directory / "boundary.zarr")
    return directory


@pytest.fixture
def atlas_dir(atlas_store: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(atlas_store))
    store.read_atlas.cache_clear()  # the atlases read from the store: its misses
    return atlas_store


def _heat(scene: AtlasScene) -> HeatMap:
    """The drawn heat map of the scene (its figure in the pane, its sources updated)."""
    scene._show_heat_map()
    heat = scene.heat_map()
    assert scene.image_pane.object is heat.figure
    return heat


@pytest.mark.slow
def test_only_atlases_of_the_directory_are_listed_and_opened(atlas_dir: Path) -> None:
    assert D.list_atlases() == ["eta-gamma", "small"]
    assert D.resolve("small") == atlas_dir / "small.zarr"
    for bad in ("../small", "/etc/passwd", "small/../small", "", ".hidden", "missing", "small.zarr", "a" * 300):
        assert D.resolve(bad) is None, bad
    scene = AtlasScene(requested="../../etc")
    scene.refresh()
    scene.refresh()
    assert scene.data is None and "is not in" in scene.message


def test_slice_is_the_stored_cube_and_a_slice_change_calls_no_model_function(atlas_dir: Path,
                                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    scene = AtlasScene(requested="small")
    scene.refresh()
    stored = xr.open_zarr(atlas_dir / "small.zarr", consolidated=False)
    assert (scene.x_axis, scene.y_axis) == ("gamma", "beta") and store.read_atlas.cache_info().misses == 1

    def forbidden(*_a, **_k):
        raise AssertionError("a slice change called the model")

    for name in ("growth_chunk", "growth_analysis", "critical_gamma_chunk", "threshold_chunk", "spectrum",
                 "rayleigh_branch", "unstable_count"):
        monkeypatch.setattr(model, name, forbidden)
    heat = _heat(scene)
    for i in range(len(AXES["f"])):
        scene._set_index("f", i)
        want = stored.growth.isel(f=i).transpose("beta", "gamma").values  # rows: beta, columns: gamma
        np.testing.assert_array_equal(heat.cells.data["image"][0], want)  # Bokeh's image: row 0 at the bottom
        assert heat.cells.data["x"][0] == pytest.approx(np.log10(0.3) - 1 / 7)
        assert heat.cells.data["dw"][0] == pytest.approx(2 + 2 / 7)
        drawn = _drawn_thresholds(heat)
        stored_c = stored.gamma_c_crossing.isel(f=i).transpose("beta", "crossing").values
        want = {(round(float(np.log10(g)), 12), float(b)) for b, row in zip(AXES["beta"], stored_c, strict=True)
                for g in row[np.isfinite(row)]}
        assert want and {(round(x, 12), y) for x, y in drawn} == want  # every certified γ_c(β), nothing else
    scene.x_axis, scene.y_axis = "f", "gamma"
    heat = _heat(scene)
    want = stored.growth.isel(beta=scene.indices["beta"]).values  # rows: gamma, columns: f
    np.testing.assert_array_equal(heat.cells.data["image"][0], want)
    stored_c = stored.gamma_c_crossing.isel(beta=scene.indices["beta"]).values
    assert len(_drawn_thresholds(heat)) == int(np.isfinite(stored_c).sum())  # γ on y: the γ_c(f) lines
    assert store.read_atlas.cache_info().misses == 1  # read once; the slices come from memory
    assert [w.label for w in scene.sliders.objects] == ["β"]


def _drawn_thresholds(heat: HeatMap) -> list[tuple[float, float]]:
    """Every vertex of the drawn threshold lines (both directions), in plotted coordinates."""
    return [(float(x), float(y)) for source in heat.thresholds.values()
            for xs, ys in zip(source.data["xs"], source.data["ys"], strict=True) for x, y in zip(xs, ys, strict=True)]


def test_neutral_curve_separates_the_signs(atlas_dir: Path) -> None:
    scene = AtlasScene(requested="small")
    scene.refresh()
    heat = _heat(scene)
    x, y, g = scene.slice2d()
    assert (g > 0).any() and (g < 0).any()
    lines = list(zip(heat.contour.data["xs"], heat.contour.data["ys"], strict=True))
    assert lines, "no neutral curve drawn although the slice has both signs"
    for xs, ys in lines:
        assert x.min() <= xs.min() and xs.max() <= x.max() and y.min() <= ys.min() and ys.max() <= y.max()
        # on the line, the growth interpolated bilinearly in the grid cell is 0 (it separates the signs)
        from scipy.interpolate import RegularGridInterpolator

        values = RegularGridInterpolator((y, x), g)(np.column_stack([ys, xs]))
        assert np.max(np.abs(values)) < 0.05 * np.nanmax(np.abs(g))


def _rgb(color: str) -> tuple[int, int, int]:
    return tuple(int(color[i : i + 2], 16) for i in (1, 3, 5))


def test_colours_are_the_legend_and_the_stability_map(atlas_dir: Path) -> None:
    """Red: unstable (growth > 0), blue: stable, as the legend says and as the Stability map draws (RdBu_r)."""
    from holoviews.plotting.util import process_cmap

    scene = AtlasScene(requested="small")
    scene.refresh()
    mapper = _heat(scene).mapper
    assert mapper.low < 0 < mapper.high
    low, high = _rgb(mapper.palette[0]), _rgb(mapper.palette[-1])
    assert high[0] > high[2] and low[2] > low[0]  # the largest growth red, the most negative blue
    stability_map = process_cmap("RdBu_r", len(mapper.palette))  # app/stability_map/'s colour map
    assert _rgb(stability_map[-1])[0] > _rgb(stability_map[-1])[2] and _rgb(stability_map[0])[2] > \
        _rgb(stability_map[0])[0]
    assert COLOURS.startswith("Red: unstable (max growth > 0), blue: stable")


def _lab(color: str) -> np.ndarray:
    """CIE L*a*b* (D65) of an sRGB colour '#rrggbb'."""
    c = np.array(_rgb(color)) / 255
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    xyz = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]) @ lin
    t = xyz / np.array([0.95047, 1.0, 1.08883])
    f = np.where(t > (6 / 29) ** 3, np.cbrt(t), t / (3 * (6 / 29) ** 2) + 4 / 29)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def test_not_computable_never_looks_like_nearly_neutral_growth() -> None:
    """The grey of 'not computable' must not look like the palette's centre (growth ~ 0) nor like any other growth
    colour, in both heat maps (CIE76 colour difference; ~2 is just noticeable)."""
    from holoviews.plotting.util import process_cmap

    from asymslide.app import common

    palettes = {"atlas": list(common.GROWTH_PALETTE), "stability map": process_cmap(common.GROWTH_CMAP, 64)}
    nan = _lab(common.NAN_COLOR)
    for name, palette in palettes.items():
        centre = palette[len(palette) // 2]
        assert np.linalg.norm(nan - _lab(centre)) > 40, name
        assert min(np.linalg.norm(nan - _lab(c)) for c in palette) > 20, name
    assert "dark grey: not computable" in common.COLOUR_LEGEND and "white: nearly neutral" in common.COLOUR_LEGEND


def test_click_sets_all_six_shared_parameters(atlas_dir: Path) -> None:
    params = SpectrumParams(gamma=1.0, f=0.2, beta=0.5, eta_infinite=False, log10_eta=2.0, Delta=0.5, xi=3.0)
    scene = AtlasScene(requested="small", params=params)
    scene.refresh()
    scene._set_index("f", 1)
    scene._on_tap(x=math.log10(AXES["gamma"][5]) + 0.01, y=AXES["beta"][3] - 0.01)
    assert params.gamma == AXES["gamma"][5] and params.beta == AXES["beta"][3] and params.f == AXES["f"][1]
    assert params.eta_infinite and params.Delta == 1.0 and params.xi == 0.0  # the atlas's fixed values
    assert "Parameters set from the atlas cell" in scene.message
    other = AtlasScene(requested="eta-gamma", params=params)
    other.refresh()
    other._on_tap(x=math.log10(1e3), y=math.log10(0.5))
    assert not params.eta_infinite and params.log10_eta == pytest.approx(3.0) and params.gamma == pytest.approx(0.5)


def test_surface_figure_is_the_neutral_surface_over_the_atlas_ranges(atlas_dir: Path) -> None:
    scene = AtlasScene(requested="small")
    scene.refresh()
    fig = scene.surface_figure()
    mesh = fig["data"][0]
    assert mesh["type"] == "mesh3d" and len(mesh["x"]) > 0 and len(mesh["i"]) == len(mesh["x"]) // 3
    stored = xr.open_zarr(atlas_dir / "small.zarr", consolidated=False).growth
    assert (stored > 0).any() and (stored < 0).any()
    # Plotly takes a log axis's range in log10 units, and its data in the parameter's values
    ranges = [np.log10(AXES["gamma"]), AXES["beta"], AXES["f"]]
    for axis, name, shown, coords in zip("xyz", ("gamma", "beta", "f"), ranges, (mesh["x"], mesh["y"], mesh["z"]),
                                         strict=True):
        lo, hi = fig["layout"]["scene"][f"{axis}axis"]["range"]
        assert (lo, hi) == pytest.approx((shown.min(), shown.max()), rel=1e-12)  # the atlas's grid, not -1..1
        values = AXES[name]
        assert values.min() * (1 - 1e-12) <= np.min(coords) and np.max(coords) <= values.max() * (1 + 1e-12)
    assert fig["layout"]["scene"]["xaxis"]["title"]["text"] == "γ"
    n_nan = int(np.isnan(stored.values).sum())
    assert len(fig["data"]) == (2 if n_nan else 1)
    if n_nan:
        assert len(fig["data"][1]["x"]) == n_nan
    scene.surface_shown = True
    assert scene.surface_pane.object is not None
    scene.surface_axes = ["gamma", "beta"]
    assert scene.surface_figure() is None and scene.surface_pane.object is None


def test_the_3d_view_is_whole_zooms_on_the_wheel_reads_depth_and_log_axes_in_values(atlas_dir: Path) -> None:
    """The figure is as tall as its pane and seen from further out than Plotly's default camera (which cut the box's
    near corner off at the bottom), the wheel zooms, the surface is coloured by its third axis with a colour bar (it
    was one flat colour), and a log axis is a Plotly log axis over the parameter's values."""
    scene = AtlasScene(requested="small")
    scene.refresh()
    fig = scene.surface_figure()
    layout, mesh = fig["layout"], fig["data"][0]
    # no height of its own (Plotly gets the pane's, nothing cut off), and the pane's height follows its width: Plotly
    # scales the scene with the height, so a desktop's 600 px on a phone's 360 px wide pane cut the box at both sides
    assert layout["autosize"] is True and "height" not in layout
    pane = scene.surface_pane
    assert pane.sizing_mode == "scale_width"

    def height(width: float) -> float:  # Bokeh's scale_width: the aspect ratio within the least and most height
        return min(pane.max_height, max(pane.min_height, width / pane.aspect_ratio))

    assert height(360) <= 420 and height(870) >= 560
    eye = layout["scene"]["camera"]["eye"]
    assert math.hypot(eye["x"], eye["y"], eye["z"]) > math.hypot(1.25, 1.25, 1.25)  # Plotly's default eye
    assert scene.surface_pane.config["scrollZoom"] is True
    # coloured by depth: f (the z axis, linear) at every vertex, over the atlas's range of f, with its colour bar
    assert "color" not in mesh and mesh["colorbar"]["title"]["text"] == "f"
    assert np.array_equal(mesh["intensity"], mesh["z"]) and np.ptp(mesh["intensity"]) > 0
    assert (mesh["cmin"], mesh["cmax"]) == (0.3, 1.5)
    # γ on a log axis: the vertices in γ's values (0.3 ... 30; log10 would be -0.52 ... 1.48)
    assert layout["scene"]["xaxis"]["type"] == "log" and layout["scene"]["yaxis"]["type"] == "linear"
    assert 0.3 * (1 - 1e-12) <= np.min(mesh["x"]) and np.max(mesh["x"]) <= 30 * (1 + 1e-12)
    assert np.max(mesh["x"]) > 1.5
    # γ as the depth: a log colour scale whose ticks are labelled with γ's values at the decades
    scene.surface_axes = ["beta", "f", "gamma"]
    mesh = scene.surface_figure()["data"][0]
    assert mesh["colorbar"]["title"]["text"] == "γ" and mesh["colorbar"]["ticktext"] == ["1", "10"]
    assert mesh["colorbar"]["tickvals"] == [0.0, 1.0] and np.allclose(mesh["intensity"], np.log10(mesh["z"]))
    assert (mesh["cmin"], mesh["cmax"]) == pytest.approx((math.log10(0.3), math.log10(30)), rel=1e-12)


def test_the_default_atlas_is_named_by_what_it_is_and_its_hash_url_still_opens_it(
        atlas_store: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The select and the heat map's title call the default atlas "default (γ-η-f-β, 4-D)", not default-<hash>; the
    store and the URL keep the file name, so a link with atlas=default-<hash> opens it."""
    import shutil

    from asymslide.app.urlstate import query_string

    name = D.default_name()
    assert name.startswith("default-")
    shutil.copytree(atlas_store / "small.zarr", tmp_path / f"{name}.zarr")  # a complete store under the default's name
    shutil.copytree(atlas_store / "eta-gamma.zarr", tmp_path / "eta-gamma.zarr")
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path))
    store.read_atlas.cache_clear()
    app = build_app({"tab": ["atlas"], "atlas": [name]})  # an old link
    scene = app.atlas
    assert not app.messages.visible and scene.atlas == name and scene.data is not None
    assert scene.atlas_select.options == {"default (γ-η-f-β, 4-D)": name, "eta-gamma": "eta-gamma"}
    assert scene.atlas_select.value == name
    assert _heat(scene).figure.title.text.startswith("default (γ-η-f-β, 4-D): max growth rate over γ-β")
    assert scene.readout().startswith(f"**Atlas** default (γ-η-f-β, 4-D) (file {name}.zarr)")
    assert f"atlas={name}" in query_string(app.param_objects(), "atlas", scene.url_state())
    scene.atlas_select.value = "eta-gamma"  # another atlas keeps its file name
    assert scene.atlas == "eta-gamma" and _heat(scene).figure.title.text.startswith("eta-gamma: max growth rate")


def _log_tick_labels(code: str, ticks: list[float]) -> list[str]:
    """The labels a Bokeh CustomJSTickFormatter's `code` gives the ticks (run by Node, as the browser would)."""
    import json
    import shutil
    import subprocess

    node = shutil.which("node")
    if node is None:
        pytest.skip("no node to run the tick formatter's JavaScript")
    script = f"const f = (tick) => {{ {code} }}; console.log(JSON.stringify({json.dumps(ticks)}.map(f)));"
    return json.loads(subprocess.run([node, "-e", script], capture_output=True, text=True, check=True).stdout)


def test_heat_map_tick_labels_stay_apart_on_a_phone(atlas_dir: Path) -> None:
    """At 390 px (about 200 px of plot) the x ticks collided: fewer ticks are asked for, labels that would overlap
    are not drawn, and a log axis's labels are short."""
    from bokeh.models import NoOverlap

    scene = AtlasScene(requested="small")
    scene.refresh()
    fig = _heat(scene).figure
    assert fig.xaxis[0].ticker.desired_num_ticks <= 4  # Bokeh's default is 6
    assert all(isinstance(axis.major_label_policy, NoOverlap) for axis in (*fig.xaxis, *fig.yaxis))
    labels = _log_tick_labels(fig.xaxis[0].formatter.code, [-1, -0.5, 0, 0.5, 1, 4])  # γ is on a log axis
    assert labels == ["10⁻¹", "0.32", "10⁰", "3.2", "10¹", "10⁴"]


@pytest.mark.slow
def test_default_atlas_is_computed_on_first_use(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(D, "DEFAULT_AXES", {"gamma": np.geomspace(0.5, 10, 4), "eta": np.geomspace(2, 100, 3),
                                            "f": np.array([0.5, 0.9]), "beta": np.array([0.2, 0.3])})
    monkeypatch.setattr(D, "DEFAULT_KH", KH)
    monkeypatch.setattr(D, "_default_job", None)
    monkeypatch.setattr(S, "sweep", mock.Mock(wraps=S.sweep))  # a spy
    scene = AtlasScene()
    scene.refresh()
    assert scene.data is None and not D.default_ready()
    scene.start_default()
    assert scene.progress.visible and "Computing the default atlas" in scene.status.object
    scene.wait(60)  # without a server: wait for the computation, then show it
    assert S.sweep.call_count == 1 and D.default_ready() and not scene.progress.visible
    assert scene.atlas == D.default_name() and scene.data is not None and len(scene.data.names) == 4
    assert (tmp_path / "cache" / f"{D.default_name()}.zarr").is_dir()
    again = AtlasScene()  # the next session opens it at once
    again.start_default()
    assert again.data is not None and S.sweep.call_count == 1


def test_a_folder_the_server_cannot_write_is_explained_and_its_atlases_still_open(
        atlas_store: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """A mounted atlas folder the server's user cannot write (simulated: tests run as root, who may write anything)
    -> the tab says why the default atlas is not computed and how to fix it; the folder's atlases open."""
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(atlas_store))
    monkeypatch.setattr(D, "_default_job", None)

    def read_only(path, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(store, "open", read_only, raising=False)  # the lock file beside the default atlas
    scene = AtlasScene()
    scene.refresh()
    scene.start_default()
    scene.wait(60)
    assert "is not writable by this server" in scene.status.object and "--atlas-dir" in scene.status.object
    assert "Permission denied" in scene.status.object and "Traceback" not in scene.status.object
    scene.atlas = "small"  # what the folder has still opens
    assert scene.data is not None and scene.data.name == "small"
    monkeypatch.setattr(D, "_default_job", None)


@pytest.mark.slow
def test_an_atlas_that_appears_after_the_tab_was_built_is_shown_with_its_selects(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The tab is built while the default atlas does not exist yet (as on first use: the selects are on the page,
    empty, and the progress is shown); when the computation ends, the tab opens it: the selects show the atlas and
    two different axes, the sliders the other axes, and the heat map a 2-D slice -- without a reload."""
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path))
    axes = {"gamma": np.geomspace(0.5, 10, 4), "eta": np.geomspace(2, 100, 3), "f": np.array([0.5, 0.9])}
    monkeypatch.setattr(D, "DEFAULT_AXES", axes)
    monkeypatch.setattr(D, "DEFAULT_KH", KH)
    monkeypatch.setattr(D, "_default_job", None)
    held, release = threading.Event(), threading.Event()
    real = S.sweep

    def held_sweep(*args, progress, **kwargs):
        progress("growth", 5)  # 5 grid points of the first phase done, then hold
        held.set()
        assert release.wait(60)
        return real(*args, **kwargs)

    monkeypatch.setattr(S, "sweep", held_sweep)
    scene = AtlasScene()
    scene.__panel__()
    assert held.wait(60)
    scene.computation.update()  # headless: show the job's state now (served: the session's next tick does)
    assert scene.data is None and scene.x_select.value is None and scene.progress.visible
    label, bar = scene.phases["growth"]
    assert "Growth rates" in label.object and "5 of 24" in label.object and bar.value == 20
    release.set()
    scene.wait(60)
    assert scene.data is not None and not scene.progress.visible
    assert scene.atlas_select.value == D.default_name()
    assert list(scene.atlas_select.options.values()) == [D.default_name()]
    assert (scene.x_select.value, scene.y_select.value) == ("gamma", "eta")
    assert [w.label for w in scene.sliders.objects] == ["f"]
    heat = scene.heat_map()
    assert scene.image_pane.object is heat.figure and heat.cells.data["image"][0].shape == (3, 4)


def test_a_failed_default_atlas_is_shown_and_started_again_when_the_tab_is_shown_again(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """An error of the default atlas's computation is shown in the tab (its type and message, not a traceback); the
    session keeps working, and showing the tab again starts the computation again."""
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path))
    monkeypatch.setattr(D, "DEFAULT_AXES", {"gamma": np.geomspace(0.5, 10, 3), "f": np.array([0.5, 0.9])})
    monkeypatch.setattr(D, "DEFAULT_KH", KH)
    monkeypatch.setattr(D, "_default_job", None)
    real = S.sweep

    def failing(*_args, **_kwargs):
        raise RuntimeError("disk on fire (test)")

    monkeypatch.setattr(S, "sweep", failing)
    scene = AtlasScene()
    scene.start_default()
    scene.wait(60)
    assert scene.status.object == "**Default atlas failed**: RuntimeError: disk on fire (test)"
    assert not scene.progress.visible and scene.data is None
    monkeypatch.setattr(S, "sweep", real)
    scene.start_default()
    scene.wait(60)
    assert scene.data is not None and scene.atlas == D.default_name() and scene.status.object == ""


def test_x_and_y_axes_cannot_be_the_same(atlas_dir: Path) -> None:
    scene = AtlasScene(requested="small")
    scene.refresh()
    assert (scene.x_axis, scene.y_axis) == ("gamma", "beta")
    assert "gamma" not in scene.y_select.options.values() and set(scene.y_select.options.values()) == {"beta", "f"}
    scene.y_select.value = "f"  # the user picks another y
    assert (scene.x_axis, scene.y_axis) == ("gamma", "f") and scene.heat_map().y_axis == "f"
    scene.x_select.value = "f"  # x = the current y: the two swap
    assert (scene.x_axis, scene.y_axis) == ("f", "gamma") and scene.y_select.value == "gamma"
    assert "f" not in scene.y_select.options.values()
    assert [w.label for w in scene.sliders.objects] == ["β"]
    x, y, g = scene.slice2d()
    assert g.shape == (y.size, x.size) == (len(AXES["gamma"]), len(AXES["f"]))
    scene.param.update(x_axis="beta", y_axis="beta")  # forced from code: nothing is drawn for it
    assert scene.heat_map() is None


@pytest.mark.slow
def test_url_names_an_atlas_of_the_directory_only(atlas_store: Path, tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    import shutil


    shutil.copytree(atlas_store / "eta-gamma.zarr", tmp_path / "eta-gamma.zarr")
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path))

    # a page opening on the Atlas tab without a valid atlas computes the default one: keep it tiny here
    monkeypatch.setattr(D, "DEFAULT_AXES", {"gamma": np.geomspace(0.5, 10, 3), "f": np.array([0.5, 0.9])})
    monkeypatch.setattr(D, "DEFAULT_KH", KH)
    monkeypatch.setattr(D, "_default_job", None)
    from asymslide.app.urlstate import TABS, query_string

    app = build_app({"tab": ["atlas"], "atlas": ["eta-gamma"]})
    assert app.tabs.active == TABS.index("atlas") and not app.messages.visible
    assert app.atlas.atlas == "eta-gamma" and app.atlas.data is not None  # built: the tab is the active one
    assert "atlas=eta-gamma" in query_string(app.param_objects(), "atlas", app.atlas.url_state())
    for bad in ("../eta-gamma", "/etc/passwd", "nope"):
        other = build_app({"tab": ["atlas"], "atlas": [bad]})
        other.atlas.wait(60)  # the default atlas it computes instead
        assert other.messages.visible and "is not one of the atlases" in other.messages.object
        assert other.atlas.atlas != bad


# ------------------------------------------------------------------------------------------------
# browser
# ------------------------------------------------------------------------------------------------


#: the heat map's image data (JS): the sum of its finite values and its shape, or null before it is drawn
_IMAGE_JS = """() => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.type !== 'GlyphRenderer' || m.glyph === undefined || m.glyph.type !== 'Image') continue;
    const img = m.data_source.data['image'];
    if (img === undefined || img.length === 0) continue;
    const a = img[0];
    const values = Array.from(a.length !== undefined ? a : a.array ?? []);
    const finite = values.filter(v => Number.isFinite(v));
    if (finite.length === 0) continue;
    return {sum: finite.reduce((s, v) => s + v, 0), n: values.length};
  }
  return null;
}"""

#: move the atlas's slider of the axis off the image (an index slider: start 0, step 1)
_MOVE_JS = """(index) => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.type === 'Slider' && m.start === 0 && m.step === 1 && m.title === 'f') {
      m.value = index; m.value_throttled = index; return true;
    }
  }
  return false;
}"""


@pytest.mark.ui
@pytest.mark.slow
def test_atlas_tab_in_the_browser(atlas_dir: Path, served_app: str, browser_page) -> None:
    from tests.conftest import open_app

    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1500})
    open_app(page, served_app + "?tab=atlas&atlas=small")
    page.wait_for_function(f"() => ({_IMAGE_JS})() !== null", timeout=60_000)
    first = page.evaluate(_IMAGE_JS)
    stored = xr.open_zarr(atlas_dir / "small.zarr", consolidated=False).growth
    want = stored.isel(f=2).values  # the slider starts mid-way (index 2 of 4)
    assert first["n"] == want.size and first["sum"] == pytest.approx(float(np.nansum(want)), rel=1e-12)
    assert page.evaluate(_MOVE_JS, 0)
    page.wait_for_function(f"() => ({_IMAGE_JS})().sum !== {first['sum']!r}", timeout=30_000)
    moved = page.evaluate(_IMAGE_JS)
    assert moved["sum"] == pytest.approx(float(np.nansum(stored.isel(f=0).values)), rel=1e-12)
    save_screenshot(page, "screenshot_atlas.png", paint_ms=300)
    page.locator(".bk-tab", has_text="3-D neutral surface").first.click()
    page.locator(".js-plotly-plot").first.wait_for(state="visible", timeout=60_000)  # rendered offline
    save_screenshot(page, "screenshot_atlas_3d.png", paint_ms=800)  # the 3-D plot's first paint
    # browser_page fails the test on any console error (e.g. plotly.js not served by this server)


def test_a_shared_url_restores_the_atlas_view(atlas_dir: Path) -> None:
    """The atlas, its heat-map axes, the other axes' values and the 3-D axes go into the URL, and the URL brings
    them back; values that do not fit are reported and left as they were."""
    import urllib.parse

    from asymslide.app.urlstate import query_string

    app = build_app({"tab": ["atlas"], "atlas": ["small"]})
    scene = app.atlas
    scene.x_select.value = "beta"  # the current y: the two swap
    scene._set_index("f", 1)
    scene.surface_axes = ["f", "beta", "gamma"]
    query = query_string(app.param_objects(), "atlas", scene.url_state())
    args = urllib.parse.parse_qs(query[1:])
    assert args["atlas"] == ["small"] and args["ax"] == ["beta"] and args["ay"] == ["gamma"]
    assert float(args["at_f"][0]) == pytest.approx(AXES["f"][1]) and args["surface"] == ["f,beta,gamma"]
    again = build_app(args)
    restored = again.atlas
    assert not again.messages.visible
    assert (restored.atlas, restored.x_axis, restored.y_axis) == ("small", "beta", "gamma")
    assert restored.indices["f"] == 1 and restored.surface_axes == ["f", "beta", "gamma"]
    assert query_string(again.param_objects(), "atlas", restored.url_state()) == query
    odd = build_app({"tab": ["atlas"], "atlas": ["eta-gamma"], "ax": ["beta"], "at_f": ["0.5"],
                     "at_gamma": ["x"], "ay": ["../x"]})
    assert "at_gamma = 'x' is not a finite number" in odd.messages.object and "ay = '../x'" in odd.messages.object
    assert (odd.atlas.x_axis, odd.atlas.y_axis) == ("eta", "gamma")  # the atlas's own axes
    assert "x axis beta is not an axis of atlas eta-gamma" in odd.atlas.message


@pytest.mark.slow
def test_undetermined_cells_are_hatched_with_their_reason_and_every_crossing_is_drawn(
        boundary_store: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The heat map hatches the undetermined cells (a pole-dense one tells so on hover), draws every certified
    crossing by direction and marks the refused sign changes; the readouts count them."""
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(boundary_store))
    stored = xr.open_zarr(boundary_store / "boundary.zarr", consolidated=False)
    scene = AtlasScene(requested="boundary")
    scene.refresh()
    assert (scene.x_axis, scene.y_axis) == ("gamma", "Delta")
    heat = _heat(scene)
    verdict = stored.verdict.transpose("Delta", "gamma").values  # rows: Delta (y), columns: gamma (x)
    reason = stored.verdict_reason.transpose("Delta", "gamma").values
    undetermined = verdict == 2
    assert undetermined.any() and (verdict != 2).any()
    drawn = set(zip(np.round(heat.undetermined.data["x"], 12), np.round(heat.undetermined.data["y"], 12), strict=True))
    gx, dy = np.meshgrid(np.log10(BOUNDARY_AXES["gamma"]), BOUNDARY_AXES["Delta"])
    assert drawn == set(zip(np.round(gx[undetermined], 12), np.round(dy[undetermined], 12), strict=True))
    pole_dense = {model.VERDICT_STATUS[int(c)].split(": ")[1] for c in reason[undetermined]}
    assert pole_dense == {"pole-dense"} and set(heat.undetermined.data["why"]) == {"pole-dense"}
    # every certified crossing, with its direction; the refused ones as markers
    crossing = stored.gamma_c_crossing.values  # (Delta, crossing)
    direction = stored.gamma_c_direction.values
    for sign in (1, -1):
        want = {(round(float(np.log10(g)), 12), float(d)) for d, row, dirs in
                zip(BOUNDARY_AXES["Delta"], crossing, direction, strict=True) for g, s in zip(row, dirs, strict=True)
                if np.isfinite(g) and s == sign}
        source = heat.thresholds[sign].data
        got = {(round(float(x), 12), float(y)) for xs, ys in zip(source["xs"], source["ys"], strict=True)
               for x, y in zip(xs, ys, strict=True)}
        assert got == want
    assert heat.thresholds[1].data["xs"], "no destabilising threshold drawn"
    reasons = stored.gamma_c_crossing_reason.values
    refused = (reasons >= 0) & ~np.isin(reasons, (0, 1))
    assert refused.any()
    np.testing.assert_allclose(10 ** np.asarray(heat.refused.data["x"]), stored.gamma_c_location.values[refused])
    assert set(heat.refused.data["why"]) == {REFUSED_CROSSING[int(r)] for r in reasons[refused]}
    # legend: what the slice has, nothing else (no older-atlas γ_c entry, no stabilising one here)
    shown = {item.label["value"] for item in heat.figure.legend[0].items if item.visible}
    assert "undetermined (hatched)" in shown and "γ_c: unstable above (certified)" in shown
    assert "sign change, not a threshold" in shown
    assert not any("older atlas" in label for label in shown)
    assert "γ_c: stable above (certified)" not in shown
    # readouts
    assert f"undetermined (hatched) {int(undetermined.sum())}" in scene.slice_readout()
    text = scene.readout()
    assert f"certified (stable or unstable) at {int((verdict != 2).sum())} of {verdict.size} points" in text
    assert f"pole-dense {int(undetermined.sum())}" in text
    assert "refused (×, not thresholds): a jump: the branch changes route (branch exchange) 1" in text
    # the CSV has the verdict and its reason per point
    lines = scene.csv().getvalue().splitlines()
    header = next(line for line in lines if not line.startswith("#"))
    assert "verdict" in header.split(",") and "verdict_reason" in header.split(",")


def test_refused_crossing_labels_are_model_codes() -> None:
    assert set(REFUSED_CROSSING) <= set(model.CROSSING_STATUS) - {0, 1}


# ------------------------------------------------------------------------------------------------
# views revisited: what is drawn always matches the controls
# ------------------------------------------------------------------------------------------------

#: a four-axis atlas (η = ∞): six heat-map planes and four 3-D axis sets
FOUR_AXES = {"gamma": np.geomspace(0.5, 20, 5), "beta": np.linspace(0.1, 0.6, 4), "f": np.linspace(0.4, 1.4, 3),
             "Delta": np.array([0.5, 1.0])}
SYMBOL = {"gamma": "γ", "beta": "β", "f": "f", "Delta": "Δ"}

#: the shown heat map (JS): its title, and the shape and finite sum of its image (null before one is shown)
_SHOWN_HEAT_JS = """() => {
  for (const m of Bokeh.documents[0].all_models) {
    if (!(m.title && m.title.text && m.title.text.includes('max growth rate over'))) continue;
    const view = Bokeh.index.find_one(m);
    if (!view || !view.el.isConnected) continue;
    for (const r of m.renderers) {
      if (!r.glyph || r.glyph.type !== 'Image') continue;
      const img = r.data_source.data['image'][0];
      const values = Array.from(img.length !== undefined ? img : img.array ?? []);
      const finite = values.filter(v => Number.isFinite(v));
      const shape = img.shape ?? r.data_source.data['image'][0].shape ?? null;
      return {title: m.title.text, n: values.length, sum: finite.reduce((s, v) => s + v, 0), shape: shape};
    }
  }
  return null;
}"""

#: set the 3-D axes (the MultiChoice of the Atlas tab) as a user's three picks would
_SURFACE_JS = """(labels) => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.type === 'MultiChoice' && m.title === '3-D axes (three)') { m.value = labels; return true; }
  }
  return false;
}"""


@pytest.fixture(scope="module")
def four_axis_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("four")
    S.sweep(FOUR_AXES, fixed={"xi": 1.0}, kH=KH, store=directory / "four.zarr")
    return directory


def _choose_axis(page, which: int, name: str) -> None:
    """Pick the axis `name` in the x (which = 1) or y (which = 2) select of the Atlas tab, by its symbol."""
    select = page.locator("select").nth(which)
    labels = select.evaluate("e => [...e.options].map(o => o.value)")
    select.select_option(value=next(v for v in labels if v.split(" ")[0] == SYMBOL[name]))
    if which == 1:  # the server's answer: the y select no longer offers the new x
        page.locator("select").nth(2).element_handle().wait_for_element_state("stable")
        page.wait_for_function("([el, s]) => ![...el.options].some(o => o.value.split(' ')[0] === s)",
                               arg=[page.locator("select").nth(2).element_handle(), SYMBOL[name]], timeout=30_000)


@pytest.mark.ui
@pytest.mark.slow
def test_every_plane_and_3d_axis_set_revisited_shows_what_the_controls_say(
        four_axis_store: Path, served_app: str, browser_page, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every ordered pair of axes is shown twice (all pairs, then all again in the reverse order), and every 3-D axis
    set twice in both orders. After each change the heat map on the page has the title of the chosen pair and the
    stored slice's values in its shape; the 3-D view's axes are the chosen ones. A revisited plane once kept the
    previous figure (Panel raised a TypeError on a Bokeh figure shown again); the server log must stay clean."""
    import itertools

    from tests.conftest import open_app

    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(four_axis_store))
    stored = xr.open_zarr(four_axis_store / "four.zarr", consolidated=False).growth
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1500})
    open_app(page, served_app + "?tab=atlas&atlas=four")
    page.wait_for_function(f"() => ({_SHOWN_HEAT_JS})() !== null", timeout=60_000)
    pairs = list(itertools.permutations(FOUR_AXES, 2))
    for x, y in pairs + pairs[::-1]:
        if page.locator("select").nth(2).input_value().split(" ")[0] == SYMBOL[x]:
            _choose_axis(page, 1, x)  # x = the current y: the two swap
        _choose_axis(page, 1, x)
        _choose_axis(page, 2, y)
        title = f"four: max growth rate over {SYMBOL[x]}-{SYMBOL[y]}"
        page.wait_for_function(f"() => {{ const s = ({_SHOWN_HEAT_JS})(); return s !== null && s.title.startsWith("
                               f"{title!r}); }}", timeout=30_000)
        shown = page.evaluate(_SHOWN_HEAT_JS)
        others = {n: len(v) // 2 for n, v in FOUR_AXES.items() if n not in (x, y)}  # the sliders start mid-way
        want = stored.isel(others).transpose(y, x).values
        assert shown["n"] == want.size, (x, y)
        assert shown["sum"] == pytest.approx(float(np.nansum(want)), rel=1e-12), (x, y)
    page.locator(".bk-tab", has_text="3-D neutral surface").first.click()
    sets = list(itertools.combinations(FOUR_AXES, 3))
    for axes in sets + [s[::-1] for s in sets[::-1]]:
        labels = [next(o for o in ("γ (log)", "β", "f", "Δ") if o.split(" ")[0] == SYMBOL[n]) for n in axes]
        page.wait_for_function(_SURFACE_JS, arg=labels, timeout=30_000)  # the tab's widgets exist once it is shown
        plot = page.locator(".js-plotly-plot").first
        want_titles = [SYMBOL[n] for n in axes]  # log axes in physical values
        page.wait_for_function(
            "([el, want]) => el.layout && el.layout.scene && ['xaxis', 'yaxis', 'zaxis'].every((a, i) => "
            "el.layout.scene[a].title.text === want[i])", arg=[plot.element_handle(), want_titles], timeout=30_000)


def test_the_slice_follows_a_dragged_slider_before_its_release(atlas_dir: Path) -> None:
    """The other axes' sliders move the slice while their handle moves (`value`), not only at the release: the slice
    is read from the stored cube."""
    scene = build_app({"tab": ["atlas"], "atlas": ["small"]}).atlas
    (slider,) = [s for s in scene.sliders.objects if s.label == "f"]
    for index in (0, 3, 1):
        slider.value = index  # the handle moves; value_throttled (the release) is unchanged
        assert scene.indices["f"] == index
        want = xr.open_zarr(atlas_dir / "small.zarr", consolidated=False).growth.isel(f=index)
        shown = scene.slice2d()[2]  # growth[y, x]
        np.testing.assert_array_equal(shown, want.transpose(scene.y_axis, scene.x_axis).values)


def test_a_url_value_beyond_an_atlas_axis_is_said_where_it_is_snapped(atlas_dir: Path) -> None:
    """A URL value beyond an atlas axis is snapped to the end of the grid and said so, as the other clamps are
    (at_f=99 was once snapped without a word)."""
    scene = build_app({"tab": ["atlas"], "atlas": ["small"], "at_f": ["99"]}).atlas
    assert scene.indices["f"] == len(AXES["f"]) - 1
    assert f"at_f = 99 is outside the atlas's f range 0.3 … 1.5: set to {AXES['f'][-1]:.4g}" in scene.message
    inside = build_app({"tab": ["atlas"], "atlas": ["small"], "at_f": ["0.7"]}).atlas
    assert inside.indices["f"] == 1 and "outside" not in inside.message  # snapped to the nearest grid value only
