"""The Atlas tab (issue 13): slices read from the stored cube (no model call), the γ_c slice, clicks that set the
shared parameters, the 3-D neutral surface, the one atlas directory, and the default atlas computed on first use."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import model
from app import atlas as A
from app.params import SpectrumParams
from asymslide import sweep as S

KH = np.logspace(-3, 3, 33)
AXES = {"gamma": np.geomspace(0.3, 30, 8), "beta": np.linspace(0.1, 0.6, 5), "f": np.linspace(0.3, 1.5, 4)}


@pytest.fixture(scope="module")
def atlas_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("atlases")
    S.sweep(AXES, kH=KH, store=directory / "small.zarr")
    S.sweep({"eta": np.geomspace(2.0, 1e3, 5), "gamma": np.geomspace(0.5, 20, 6)}, kH=KH,
            store=directory / "eta-gamma.zarr")
    return directory


@pytest.fixture
def atlas_dir(atlas_store: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(atlas_store))
    A.CALLS.clear()
    return atlas_store


def _heat(scene: A.AtlasScene):
    overlay = scene.image_dmap[()]
    return overlay.get(0), overlay.get(1), overlay.get(2)


def test_only_atlases_of_the_directory_are_listed_and_opened(atlas_dir: Path) -> None:
    assert A.list_atlases() == ["eta-gamma", "small"]
    assert A.resolve("small") == atlas_dir / "small.zarr"
    for bad in ("../small", "/etc/passwd", "small/../small", "", ".hidden", "missing", "small.zarr", "a" * 300):
        assert A.resolve(bad) is None, bad
    scene = A.AtlasScene(requested="../../etc")
    scene.refresh()
    scene.refresh()
    assert scene.data is None and "is not in" in scene.message


def test_slice_is_the_stored_cube_and_a_slice_change_calls_no_model_function(atlas_dir: Path,
                                                                            monkeypatch: pytest.MonkeyPatch) -> None:
    scene = A.AtlasScene(requested="small")
    scene.refresh()
    stored = xr.open_zarr(atlas_dir / "small.zarr", consolidated=False)
    assert (scene.x_axis, scene.y_axis) == ("gamma", "beta") and A.CALLS["load"] == 1

    def forbidden(*_a, **_k):
        raise AssertionError("a slice change called the model")

    for name in ("growth_chunk", "growth_analysis", "critical_gamma_chunk", "threshold_chunk", "spectrum",
                 "rayleigh_branch", "unstable_count"):
        monkeypatch.setattr(model, name, forbidden)
    for i in range(len(AXES["f"])):
        scene._set_index("f", i)
        heat, neutral, gc = _heat(scene)
        want = stored.growth.isel(f=i).transpose("beta", "gamma").values  # rows: beta, columns: gamma
        np.testing.assert_array_equal(np.flipud(heat.data), want)  # hv.Image rows run top-down
        np.testing.assert_allclose(heat.bounds.lbrt()[::2], [np.log10(0.3) - 1 / 7, np.log10(30) + 1 / 7])
        line = scene.gamma_c_line()
        np.testing.assert_allclose(10 ** line[0], stored.gamma_c.isel(f=i).values, rtol=1e-15)  # γ_c(β)
        np.testing.assert_array_equal(line[1], AXES["beta"])
    scene.x_axis, scene.y_axis = "f", "gamma"
    heat, _, _ = _heat(scene)
    want = stored.growth.isel(beta=scene.indices["beta"]).values  # rows: gamma, columns: f
    np.testing.assert_array_equal(np.flipud(heat.data), want)
    assert A.CALLS["load"] == 1  # read once; the slices come from memory
    assert [w.label for w in scene.sliders.objects] == ["β"]


def test_neutral_curve_separates_the_signs(atlas_dir: Path) -> None:
    scene = A.AtlasScene(requested="small")
    scene.refresh()
    heat, neutral, _ = _heat(scene)
    x, y, g = scene.slice2d()
    assert (g > 0).any() and (g < 0).any()
    lines = neutral.split()
    assert lines, "no neutral curve drawn although the slice has both signs"
    for part in lines:
        xs, ys = part.dimension_values(0), part.dimension_values(1)
        assert x.min() <= xs.min() and xs.max() <= x.max() and y.min() <= ys.min() and ys.max() <= y.max()


def test_click_sets_all_six_shared_parameters(atlas_dir: Path) -> None:
    params = SpectrumParams(gamma=1.0, f=0.2, beta=0.5, eta_infinite=False, log10_eta=2.0, Delta=0.5, xi=3.0)
    scene = A.AtlasScene(requested="small", params=params)
    scene.refresh()
    scene._set_index("f", 1)
    scene._on_tap(x=math.log10(AXES["gamma"][5]) + 0.01, y=AXES["beta"][3] - 0.01)
    assert params.gamma == AXES["gamma"][5] and params.beta == AXES["beta"][3] and params.f == AXES["f"][1]
    assert params.eta_infinite and params.Delta == 1.0 and params.xi == 0.0  # the atlas's fixed values
    assert "Parameters set from the atlas cell" in scene.message
    other = A.AtlasScene(requested="eta-gamma", params=params)
    other.refresh()
    other._on_tap(x=math.log10(1e3), y=math.log10(0.5))
    assert not params.eta_infinite and params.log10_eta == pytest.approx(3.0) and params.gamma == pytest.approx(0.5)


def test_surface_figure_is_the_neutral_isosurface(atlas_dir: Path) -> None:
    scene = A.AtlasScene(requested="small")
    scene.refresh()
    fig = scene.surface_figure()
    iso = fig["data"][0]
    assert iso["type"] == "isosurface" and iso["isomin"] == iso["isomax"] == 0.0
    assert len(iso["x"]) == len(iso["value"]) == math.prod(len(v) for v in AXES.values())
    stored = xr.open_zarr(atlas_dir / "small.zarr", consolidated=False).growth.values
    np.testing.assert_array_equal(np.array(iso["value"], dtype=float), stored.ravel())
    assert fig["layout"]["scene"]["xaxis"]["title"]["text"] == "γ (log10)"
    scene.surface_axes = ["gamma", "beta"]
    assert scene.surface_figure() is None and scene.surface_pane.object is None


def test_default_atlas_is_computed_on_first_use(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(A, "DEFAULT_AXES", {"gamma": np.geomspace(0.5, 10, 4), "eta": np.geomspace(2, 100, 3),
                                            "f": np.array([0.5, 0.9]), "beta": np.array([0.2, 0.3])})
    monkeypatch.setattr(A, "DEFAULT_KH", KH)
    monkeypatch.setattr(A, "_default_job", None)
    A.CALLS.clear()
    scene = A.AtlasScene()
    scene.refresh()
    assert scene.data is None and not A.default_ready()
    scene.start_default()  # without a server it waits for the computation
    assert A.CALLS["default_sweep"] == 1 and A.default_ready()
    assert scene.atlas == A.default_name() and scene.data is not None and len(scene.data.names) == 4
    assert (tmp_path / "cache" / f"{A.default_name()}.zarr").is_dir()
    again = A.AtlasScene()  # the next session opens it at once
    again.start_default()
    assert again.data is not None and A.CALLS["default_sweep"] == 1


def test_url_names_an_atlas_of_the_directory_only(atlas_store: Path, tmp_path: Path,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    import shutil

    from app.main import create_app

    shutil.copytree(atlas_store / "eta-gamma.zarr", tmp_path / "eta-gamma.zarr")
    monkeypatch.setenv("ASYMSLIDE_ATLAS_DIR", str(tmp_path))

    # a page opening on the Atlas tab without a valid atlas computes the default one: keep it tiny here
    monkeypatch.setattr(A, "DEFAULT_AXES", {"gamma": np.geomspace(0.5, 10, 3), "f": np.array([0.5, 0.9])})
    monkeypatch.setattr(A, "DEFAULT_KH", KH)
    monkeypatch.setattr(A, "_default_job", None)
    from app.urlstate import TABS, query_string

    app = create_app({"tab": ["atlas"], "atlas": ["eta-gamma"]}).app
    assert app.tabs.active == TABS.index("atlas") and not app.messages.visible
    assert app.atlas.atlas == "eta-gamma" and app.atlas.data is not None  # built: the tab is the active one
    assert "atlas=eta-gamma" in query_string(app.param_objects(), "atlas", app.atlas.atlas)
    for bad in ("../eta-gamma", "/etc/passwd", "nope"):
        other = create_app({"tab": ["atlas"], "atlas": [bad]}).app
        assert other.messages.visible and "is not one of the atlases" in other.messages.object
        assert other.atlas.atlas != bad
