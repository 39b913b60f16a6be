"""The "Thin-on-thick" scene (Fig. 3), headless: caching per dependency group, plotted data equal to the
model's values, the widgets, and the page with two tabs."""

from __future__ import annotations

import math

import holoviews as hv
import numpy as np
import panel as pn
import param
import pytest

from asymslide import model
from asymslide.app import thin_on_thick as tt
from asymslide.app.params import LabParams
from asymslide.app.thin_on_thick import KW, ThinOnThickParams, ThinOnThickScene
from tests.conftest import open_app, save_screenshot, set_slider
from tests.support.spies import Calls, spying

pytestmark = pytest.mark.usefixtures("fresh_caches")

#: the scene's cache misses and model calls in the current test (tests/support/spies.py)
calls = Calls()


_spies = spying((tt, calls))


def _render_all(scene: ThinOnThickScene) -> None:
    scene.moduli_dmap[()]
    scene.nu_eff_dmap[()]
    scene.gy_dmap[()]
    scene.stress_dmap[()]
    scene.readout()


def _el(overlay: hv.Overlay, kind: type, label: str) -> hv.Element:
    (el,) = [e for e in overlay if isinstance(e, kind) and e.label == label]
    return el


def _z_R(nu: float) -> float:
    return float(model.rayleigh_speed(math.sqrt((1 - nu) / 2)))


# --------------------------------------------------------------------------------------------
# the cache: one cached function per dependency group
# --------------------------------------------------------------------------------------------


def test_each_group_computed_once_and_rerender_is_free() -> None:
    scene = ThinOnThickScene()
    _render_all(scene)
    _render_all(scene)
    assert calls["compute_moduli_curve"] == 1
    assert calls["compute_point"] == 1
    assert calls["compute_gy_curve"] == 1
    assert calls["compute_stress_line"] == 1
    assert calls["thin_on_thick_response"] == 2  # G_y curve and G_y(c_R)


@pytest.mark.parametrize("name, value", [("rho", 1000.0), ("sigma0_MPa", 3.0), ("c_s", 1200.0)])
def test_material_inputs_recompute_only_the_stress_line(name: str, value: float) -> None:
    scene = ThinOnThickScene()
    _render_all(scene)
    before = dict(calls)
    setattr(scene.material, name, value)  # the page's shared material constants (the Lab-units panel's)
    _render_all(scene)
    assert calls["compute_stress_line"] == before["compute_stress_line"] + 1
    for key in ("compute_moduli_curve", "compute_point", "compute_gy_curve", "thin_on_thick_response",
                "effective_moduli"):
        assert calls[key] == before[key], key


def test_kW_does_not_recompute_the_moduli_curve() -> None:
    scene = ThinOnThickScene()
    _render_all(scene)
    scene.params.log10_kW = 1.0
    _render_all(scene)
    assert calls["compute_moduli_curve"] == 1
    assert calls["compute_point"] == 2
    assert calls["compute_gy_curve"] == 2
    assert calls["compute_stress_line"] == 2
    # the marker moved, the curve is the same object's data
    marker = _el(scene.moduli_dmap[()], hv.Scatter, "current kW")
    assert marker.dimension_values("kW")[0] == 10.0


def test_nu_recomputes_everything_once() -> None:
    scene = ThinOnThickScene()
    _render_all(scene)
    scene.params.nu = 0.25
    _render_all(scene)
    for key in ("compute_moduli_curve", "compute_point", "compute_gy_curve", "compute_stress_line"):
        assert calls[key] == 2, key


def test_kW_is_rounded_so_the_default_is_exactly_5() -> None:
    assert ThinOnThickParams().kW == 5.0
    scene = ThinOnThickScene()
    assert scene.point_key == (5.0, 0.33)
    assert scene.stress_key == (5.0, 0.33, 1345.0, 1180.0, 4.5e6)


# --------------------------------------------------------------------------------------------
# the plotted data is the model's
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("kW, nu", [(5.0, 0.33), (0.1, 0.2), (50.0, 0.45)])
def test_moduli_plots_equal_model(kW: float, nu: float) -> None:
    scene = ThinOnThickScene(params=ThinOnThickParams(log10_kW=math.log10(kW), nu=nu))
    mu_ratio, nu_eff = model.effective_moduli(KW, nu)
    curve = _el(scene.moduli_dmap[()], hv.Curve, "μ_eff/μ")
    np.testing.assert_array_equal(curve.dimension_values("kW"), KW)
    np.testing.assert_array_equal(curve.dimension_values("μ_eff/μ"), mu_ratio)
    assert KW[0] == 1e-2 and KW[-1] == 1e3
    inset = _el(scene.nu_eff_dmap[()], hv.Curve, "ν_eff")
    np.testing.assert_array_equal(inset.dimension_values("ν_eff"), nu_eff)
    mk = _el(scene.moduli_dmap[()], hv.Scatter, "current kW")
    m_pt, n_pt = model.effective_moduli(kW, nu)
    assert mk.dimension_values("kW")[0] == pytest.approx(kW, rel=1e-12)
    assert mk.dimension_values("μ_eff/μ")[0] == pytest.approx(float(m_pt), rel=1e-14)
    mk2 = _el(scene.nu_eff_dmap[()], hv.Scatter, "current kW")
    assert mk2.dimension_values("ν_eff")[0] == pytest.approx(float(n_pt), rel=1e-14)


@pytest.mark.parametrize("kW, nu", [(5.0, 0.33), (0.3, 0.33), (20.0, 0.1)])
def test_gy_plot_equals_model(kW: float, nu: float) -> None:
    scene = ThinOnThickScene(params=ThinOnThickParams(log10_kW=math.log10(kW), nu=nu))
    kW = scene.params.kW
    curve = _el(scene.gy_dmap[()], hv.Curve, "current kW")
    assert [d.name for d in curve.dimensions()] == ["c/c_s", "G_y"]
    z = curve.dimension_values("c/c_s")
    mu_ratio = float(model.effective_moduli(kW, nu)[0])
    assert z[0] == 1e-3
    assert z[-1] == pytest.approx(0.999 * min(1.0, math.sqrt(mu_ratio)), rel=1e-14)
    np.testing.assert_array_equal(curve.dimension_values("G_y"), model.thin_on_thick_response(z, kW, nu=nu)[1].real)


@pytest.mark.parametrize("c_s, rho, sigma0_MPa, kW", [(1345.0, 1180.0, 4.5, 5.0), (1000.0, 1180.0, 4.5, 5.0),
                                                      (1500.0, 900.0, 2.0, 3.0)])
def test_stress_plot_equals_model(c_s: float, rho: float, sigma0_MPa: float, kW: float) -> None:
    p = ThinOnThickParams(log10_kW=math.log10(kW))
    scene = ThinOnThickScene(params=p, material=LabParams(c_s=c_s, rho=rho, sigma0_MPa=sigma0_MPa))
    kW = p.kW
    curve = _el(scene.stress_dmap[()], hv.Curve, "Δσ_yy/σ₀")
    assert [d.name for d in curve.dimensions()] == ["v [m/s]", "Δσ_yy/σ₀"]
    v = curve.dimension_values("v [m/s]")
    assert v[0] == 0.0 and v[-1] == 2.0
    c = _z_R(0.33) * c_s
    with np.errstate(divide="ignore", invalid="ignore"):
        expected = model.normal_stress_change(v, c=c, c_s=c_s, kW=kW, nu=0.33, mu=rho * c_s**2) / (sigma0_MPa * 1e6)
    np.testing.assert_array_equal(curve.dimension_values("Δσ_yy/σ₀"), expected)


def test_readout_shows_model_values() -> None:
    scene = ThinOnThickScene(params=ThinOnThickParams(log10_kW=math.log10(50.0)), material=LabParams(c_s=1000.0))
    text = scene.readout()
    excess = float(model.effective_modulus_excess(50.0, 0.33))
    assert f"{excess:.6e}" in text  # exact even where it is tiny
    assert f"{float(model.effective_moduli(50.0, 0.33)[1]):.6g}" in text
    gy = float(model.thin_on_thick_response(_z_R(0.33), 50.0, nu=0.33)[1].real)
    assert f"{gy:.6g}" in text
    slope = float(model.normal_stress_change(1.0, c=_z_R(0.33) * 1000.0, c_s=1000.0, kW=50.0, nu=0.33,
                                             mu=1180.0 * 1000.0**2)) / 4.5e6
    assert f"{slope:.5g}" in text


def test_stress_line_is_finite_at_pmma_defaults() -> None:
    """At c = c_R of the thin block (a pole of its own compliance) the stress line is finite."""
    d = tt.compute_stress_line(5.0, 0.33, 1345.0, 1180.0, 4.5e6)
    assert np.isfinite(d["slope"])
    assert np.all(np.isfinite(d["ds"]))


def test_bokeh_axes() -> None:
    scene = ThinOnThickScene()
    fig = hv.render(scene.moduli_dmap, backend="bokeh")
    assert type(fig.x_scale).__name__ == "LogScale"
    assert fig.xaxis[0].axis_label == "kW"
    fig = hv.render(scene.gy_dmap, backend="bokeh")
    assert (fig.xaxis[0].axis_label, fig.yaxis[0].axis_label) == ("c/c_s", "G_y")
    fig = hv.render(scene.stress_dmap, backend="bokeh")
    assert (fig.xaxis[0].axis_label, fig.yaxis[0].axis_label) == ("v [m/s]", "Δσ_yy/σ₀")


# --------------------------------------------------------------------------------------------
# the widgets and the page
# --------------------------------------------------------------------------------------------


def _release(slider, value: float) -> None:
    with param.edit_constant(slider):
        slider.value = value
        slider.value_throttled = value


def test_widget_labels_and_throttling() -> None:
    p = ThinOnThickParams()
    w = p.make_widgets()
    assert w["log10_kW"].label == "kW" and w["nu"].label == "ν"
    assert set(w) == {"log10_kW", "nu"}  # c_s, ρ, σ₀: the shared material constants (test_app_rupture)
    assert (w["log10_kW"].start, w["log10_kW"].end) == (-2, 2)
    assert (w["nu"].start, w["nu"].end, w["nu"].value) == (0.0, 0.49, 0.33)
    w["log10_kW"].value = 0.5  # the handle moves (not released): the plots follow it
    assert p.kW == pytest.approx(10**0.5, rel=1e-12)
    _release(w["log10_kW"], 1.0)
    assert p.kW == 10.0
    p.nu = 0.2
    assert w["nu"].value == 0.2


def test_app_builds_with_five_tabs() -> None:
    from asymslide.app.main import create_app

    template = create_app()
    (tabs,) = [obj for obj in template.main.objects if isinstance(obj, pn.Tabs)]
    assert tabs._names == ["Spectrum", "Stability map", "Thin-on-thick", "Rupture fronts", "All branches", "Atlas"]


# --------------------------------------------------------------------------------------------
# browser
# --------------------------------------------------------------------------------------------

_GY_SOURCE_JS = """() => {
  const doc = Bokeh.documents[0];
  for (const m of doc.all_models) {
    if (m.type === 'ColumnDataSource' || (m.constructor && m.constructor.__name__ === 'ColumnDataSource')) {
      const cols = Object.keys(m.data ?? {});
      const y = cols.find(c => c.startsWith('G_y'));
      if (y !== undefined && cols.some(c => c.startsWith('c/c_s'))) {
        const arr = Array.from(m.data[y]);
        if (arr.length > 10) return arr.map(v => Number.isFinite(v) ? v : null);
      }
    }
  }
  return null;
}"""

@pytest.mark.ui
@pytest.mark.slow
def test_kW_slider_updates_the_gy_curve(served_app: str, browser_page) -> None:
    page = browser_page
    open_app(page, served_app, "Thin-on-thick")
    page.wait_for_function(_GY_SOURCE_JS, timeout=30_000)
    before = np.array(page.evaluate(_GY_SOURCE_JS), dtype=float)
    z = np.linspace(1e-3, 0.999 * min(1.0, math.sqrt(float(model.effective_moduli(5.0, 0.33)[0]))), tt.N_Z)
    np.testing.assert_allclose(before, model.thin_on_thick_response(z, 5.0, nu=0.33)[1].real, rtol=1e-12, atol=0)
    assert set_slider(page, "kW", 0.0)  # log10 kW = 0: kW = 1
    changed = f"() => {{ const y = ({_GY_SOURCE_JS})(); return y !== null && y[0] !== {float(before[0])!r}; }}"
    page.wait_for_function(changed, timeout=30_000)
    after = np.array(page.evaluate(_GY_SOURCE_JS), dtype=float)
    z = np.linspace(1e-3, 0.999 * min(1.0, math.sqrt(float(model.effective_moduli(1.0, 0.33)[0]))), tt.N_Z)
    np.testing.assert_allclose(after, model.thin_on_thick_response(z, 1.0, nu=0.33)[1].real, rtol=1e-12, atol=0)
    save_screenshot(page, "thin_on_thick.png")
    assert page.console_errors == []


def test_shared_lab_values_the_model_refuses_are_a_message() -> None:
    scene = ThinOnThickScene(material=LabParams(c_s=-5.0))
    _render_all(scene)
    pane = scene.messages()
    assert isinstance(pane, pn.pane.Alert) and "c_s" in pane.object
    assert len(_el(scene.stress_dmap[()], hv.Curve, "Δσ_yy/σ₀")) == 0 and "**Lab values used**" in scene.readout()
    scene.material.c_s = 1345.0
    assert not isinstance(scene.messages(), pn.pane.Alert)


# --------------------------------------------------------------------------------------------
# ν follows the chosen material; every line of (b) is named
# --------------------------------------------------------------------------------------------


def test_choosing_a_material_sets_its_nu_and_the_readout_never_mixes_them() -> None:
    """Choosing a material sets its ν (ν once stayed 0.44 after fused silica was chosen, while the readout named
    fused silica)."""
    from asymslide.app.params import follow_material

    scene = ThinOnThickScene(params=ThinOnThickParams(nu=0.44))
    follow_material(scene.material)  # as the Lab-units panel does on the page
    scene.material.material = "fused silica"
    silica = model.material("fused silica")  # no reported ν: the one of its bulk speeds
    assert scene.params.nu == pytest.approx(silica.nu, rel=1e-15) and scene.point_key[1] == scene.params.nu
    text = scene.readout()
    assert "fused silica" in text and f"ν = {silica.nu:.4g} (fused silica's)" in text and "0.44" not in text
    scene.material.material = "Homalite-100"  # a source that reports ν: that one
    assert scene.params.nu == 0.35 and "ν = 0.35 (Homalite-100's)" in scene.readout()
    scene.params.nu = 0.44  # ν set by hand afterwards: the readout says it is not the material's
    text = scene.readout()
    assert "Homalite-100" in text and "**ν** = 0.44" in text and "not Homalite-100's ν = 0.35" in text
    assert "(Homalite-100's)" not in text


def test_every_line_of_plot_b_has_a_legend_entry() -> None:
    """Every line of (b) has a legend entry (the dashed c_R line was a Bokeh Span, which no legend lists)."""
    from bokeh.models import GlyphRenderer, Span

    for compare in ([], [0.5, 2.0]):
        scene = ThinOnThickScene(compare_kW=compare)
        fig = hv.render(scene.gy_dmap, backend="bokeh")
        # a Bokeh Span (hv.HLine, hv.VLine; in fig.renderers or fig.center) is a line no legend can name
        assert not [a for a in [*fig.renderers, *fig.center] if isinstance(a, Span) and a.visible]
        shown = [r for r in fig.renderers if isinstance(r, GlyphRenderer) and r.visible]
        assert len(shown) == 3 + len(compare)  # G_y = 0, c_R, current kW and the family
        (legend,) = fig.legend
        assert legend.visible
        labelled = {id(r): item.label.value for item in legend.items for r in item.renderers}
        assert all(labelled.get(id(r)) for r in shown)
        assert set(labelled.values()) == {"G_y = 0", "c_R (thin block)", "current kW",
                                          *(f"kW = {k:g}" for k in compare)}
        c_r = [r for r in shown if labelled[id(r)] == "c_R (thin block)"][0]
        assert type(c_r.glyph).__name__ == "VSpan" and c_r.glyph.line_dash == "dashed"
        assert list(c_r.data_source.data[c_r.glyph.x]) == pytest.approx([_z_R(0.33)], rel=1e-12)


@pytest.mark.parametrize(("query", "own"), [
    ("tab=thin&material=fused+silica&nu=0.16974", True),  # a link the page wrote after fused silica was chosen
    ("tab=thin&material=fused+silica&nu=0.44", False),
])
def test_a_shared_link_keeps_the_readout_and_nu_consistent(query: str, own: bool) -> None:
    import urllib.parse

    from tests.support.headless import build_app

    app = build_app(urllib.parse.parse_qs(query))
    nu = float(urllib.parse.parse_qs(query)["nu"][0])
    assert (app.lab_params.material, app.thin_params.nu) == ("fused silica", nu)
    text = app.thin.readout()
    if own:
        assert "(fused silica's)" in text and "not fused silica's" not in text
    else:
        assert f"**ν** = {nu:g}, set here: not fused silica's ν = {model.material('fused silica').nu:.4g}" in text


# --------------------------------------------------------------------------------------------
# a held kW slider moves the plots on the page without a HoloViews redraw (app.live)
# --------------------------------------------------------------------------------------------


def _page(compare_kW: tuple[float, ...] = (), **params: float) -> tuple[ThinOnThickScene, dict]:
    """A scene rendered as on the page (its layout in a Bokeh document, the axes linked as Panel links them), with a
    family of kW (the Fig. 3 preset's) and σ₀ [MPa] (`sigma0_MPa`, the shared lab value) if given; its sliders by
    label."""
    from bokeh.document import Document

    lab = {k: params.pop(k) for k in ("sigma0_MPa",) if k in params}
    scene = ThinOnThickScene(params=ThinOnThickParams(**params), material=LabParams(**lab),
                             compare_kW=list(compare_kW))
    scene.__panel__().get_root(Document())
    return scene, {s.label: s for s in scene.follow.sliders}


def _drawn(scene: ThinOnThickScene) -> dict[str, dict]:
    """What each plot on the page shows: title, axis ranges, legend, each visible layer's columns (by HoloViews'
    key), the level of each horizontal line."""
    from asymslide.app import live

    out = {}
    for name, pane in scene.panes.items():
        (plot,) = live.rendered_plots(pane)
        fig = plot.state
        out[name] = {"title": fig.title.text, "x": (fig.x_range.start, fig.x_range.end),
                     "y": (fig.y_range.start, fig.y_range.end),
                     "legend": [(getattr(i.label, "value", i.label), i.visible) for lg in fig.legend for i in lg.items]}
        for key, sub in plot.subplots.items():
            if hasattr(sub.handles.get("glyph"), "location"):
                out[name][str(key)] = sub.handles["glyph"].location
            elif "source" in sub.handles and sub.handles["glyph_renderer"].visible:
                out[name][str(key)] = {c: np.asarray(v) for c, v in sub.handles["source"].data.items()}
    return out


def _redrawn(opened: dict, compare_kW: tuple[float, ...] = (), **params: float) -> ThinOnThickScene:
    """A page opened at `opened`, then redrawn by HoloViews at `params` (a change that no slider holds)."""
    scene, _ = _page(compare_kW, **opened)
    if "sigma0_MPa" in params:
        scene.material.sigma0_MPa = params.pop("sigma0_MPa")
    scene.params.param.update(**params)
    return scene


def _assert_drawn_as_a_redraw(scene: ThinOnThickScene, compare_kW: tuple[float, ...] = (), *,
                              opened: dict | None = None, **params: float) -> None:
    """The page of `scene`, opened at `opened` (default: the defaults), shows exactly what HoloViews draws at its
    current inputs (`opened` and `params`): the same page redrawn by HoloViews there, and a page opened there."""
    opened = opened or {}
    shown = _drawn(scene)
    for expected in (_drawn(_redrawn(opened, compare_kW, **params)), _drawn(_page(compare_kW, **opened, **params)[0])):
        assert shown.keys() == expected.keys() == {"moduli", "nu_eff", "gy", "stress"}
        for name, plot in expected.items():
            assert shown[name].keys() == plot.keys(), name
            for key, value in plot.items():
                if isinstance(value, dict):
                    assert shown[name][key].keys() == value.keys(), (name, key)
                    for column, data in value.items():
                        np.testing.assert_array_equal(shown[name][key][column], data,
                                                      err_msg=f"{name} {key} {column}")
                else:
                    assert shown[name][key] == value, (name, key)


def _let_go(slider: pn.widgets.FloatSlider, value: float | None = None) -> None:
    """Release the handle (at `value`, else where it is): value and value_throttled in one change, as Bokeh sends a
    release."""
    value = slider.value if value is None else value
    with param.edit_constant(slider):
        slider.param.update(value=value, value_throttled=value)


def _counts(scene: ThinOnThickScene) -> tuple[int, int]:
    return scene.drawn, scene.stress_drawn


@pytest.mark.parametrize("family", [(), (1.0, 10.0)])
@pytest.mark.slow
def test_a_held_kW_slider_moves_the_plots_on_the_page_without_a_holoviews_redraw(family: tuple) -> None:
    """While kW is held, (a), its inset, (b) and (c) on the page show at every position of the handle exactly what a
    HoloViews redraw at that kW draws (the markers, the G_y curve and the zero line under it, the Δσ_yy line, the
    title of (b), every range and legend; a preset's family of kW stays), written into the Bokeh sources (app.live)
    without a redraw; the readout follows. At the release at the last position nothing is redrawn."""
    scene, sliders = _page(family)
    counts = _counts(scene)
    for log10_kw in (0.5, -1.5, 1.9, -0.25):
        sliders["kW"].value = log10_kw  # the handle moves; value_throttled stays: held
        assert scene.follow.held() and _counts(scene) == counts
        _assert_drawn_as_a_redraw(scene, family, log10_kW=log10_kw)
        assert f"**kW** = {tt.fmt(scene.params.kW, 4)}" in scene.readout()
    _let_go(sliders["kW"])
    assert not scene.follow.held() and _counts(scene) == counts
    _assert_drawn_as_a_redraw(scene, family, log10_kW=-0.25)


@pytest.mark.slow
def test_a_release_elsewhere_is_written_and_a_change_from_elsewhere_is_redrawn() -> None:
    """A release at a value the page does not show yet is written like a held position; a change that does not come
    from a held slider (a preset, the URL) is redrawn by HoloViews."""
    scene, sliders = _page()
    counts = _counts(scene)
    sliders["kW"].value = 0.5
    _let_go(sliders["kW"], 1.0)
    assert _counts(scene) == counts
    _assert_drawn_as_a_redraw(scene, log10_kW=1.0)
    scene.params.log10_kW = 0.2
    assert _counts(scene) == (counts[0] + 1, counts[1] + 1) and sliders["kW"].value == 0.2
    _assert_drawn_as_a_redraw(scene, log10_kW=0.2)


@pytest.mark.slow
def test_a_held_nu_slider_is_redrawn_by_holoviews() -> None:
    """ν changes every curve (not only what kW moves): HoloViews redraws at each position of its handle."""
    scene, sliders = _page()
    drawn, stress_drawn = _counts(scene)
    sliders["ν"].value = 0.2
    assert _counts(scene) == (drawn + 1, stress_drawn + 1)
    _assert_drawn_as_a_redraw(scene, nu=0.2)
    _let_go(sliders["ν"])
    assert _counts(scene) == (drawn + 1, stress_drawn + 1)


def test_a_layer_of_a_new_length_is_written_whole(monkeypatch: pytest.MonkeyPatch) -> None:
    """A curve that comes with another number of points (here a coarser c/c_s grid of (b)) is written whole (every
    column at once) and the page is what a redraw draws."""
    scene, sliders = _page()
    monkeypatch.setattr(tt, "N_Z", 50)
    counts = _counts(scene)
    sliders["kW"].value = 0.5
    assert _counts(scene) == counts
    gy = _drawn(scene)["gy"][str(("Curve", "Current_kW"))]
    assert all(len(column) == 50 for column in gy.values())
    _assert_drawn_as_a_redraw(scene, log10_kW=0.5)


def test_a_layer_app_live_cannot_write_falls_back_to_a_holoviews_redraw(monkeypatch: pytest.MonkeyPatch) -> None:
    """A layer of another kind than the one on the page (here a third column) is not written: HoloViews redraws."""
    scene, sliders = _page()
    layers = ThinOnThickScene.live_layers

    def other_kind(point_key: tuple, stress_key: tuple) -> dict:
        out = layers(point_key, stress_key)
        v, ds = out["stress"][tt.DS_LABEL]
        out["stress"][tt.DS_LABEL] = (v, ds, ds)
        return out

    monkeypatch.setattr(ThinOnThickScene, "live_layers", staticmethod(other_kind))
    drawn, stress_drawn = _counts(scene)
    sliders["kW"].value = 0.5
    assert _counts(scene) == (drawn + 1, stress_drawn + 1)
    _assert_drawn_as_a_redraw(scene, log10_kW=0.5)


def test_a_held_kW_slider_over_lab_values_the_model_refuses_keeps_c_empty() -> None:
    """With a σ₀ the model refuses, (c) is empty: written while held as a redraw draws it (no line, the zero line's
    range), the other plots follow kW."""
    scene, sliders = _page(sigma0_MPa=-1.0)
    counts = _counts(scene)
    sliders["kW"].value = 1.2
    assert _counts(scene) == counts
    _assert_drawn_as_a_redraw(scene, opened={"sigma0_MPa": -1.0}, log10_kW=1.2)
    line = _drawn(scene)["stress"][str(("Curve", "Δσ_yy_over_σ_subscript_zero"))]
    assert all(len(column) == 0 for column in line.values())


@pytest.mark.slow
def test_served_the_moves_of_a_held_slider_are_read_once_a_turn_and_the_release_at_once(
        monkeypatch: pytest.MonkeyPatch) -> None:
    """Served, the moves of a held handle that arrive before the event loop's next turn are read (keys, readout,
    plots) once, at the latest value; a release before that turn reads and writes the released value at once."""
    from asymslide.app import live

    scene, sliders = _page()
    turns: list = []
    monkeypatch.setattr(live, "_served", lambda: True)
    monkeypatch.setattr(live, "schedule_follow", turns.append)  # the follow's turn (its slot of live.BUDGET)
    counts, key = _counts(scene), scene.point_key
    for log10_kw in (0.3, 0.6, 0.9):
        sliders["kW"].value = log10_kw
    assert len(turns) == 1 and scene.point_key == key  # not read yet
    turns.pop()()
    assert _counts(scene) == counts and scene.point_key == (scene.params.kW, scene.params.nu)
    _assert_drawn_as_a_redraw(scene, log10_kW=0.9)
    sliders["kW"].value = 1.4
    _let_go(sliders["kW"], 1.5)  # the release comes before the scheduled reading
    assert _counts(scene) == counts
    _assert_drawn_as_a_redraw(scene, log10_kW=1.5)
    turns.pop()()  # the scheduled reading: nothing left to do
    assert _counts(scene) == counts and not turns
    _assert_drawn_as_a_redraw(scene, log10_kW=1.5)
