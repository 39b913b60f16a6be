"""The "Rupture fronts" scene (app/rupture.py; supplement S-V C, docs/physics.md §13), headless: which change calls
which model function, the plotted data and the readout equal to the model's values, bad input (c >= c_R, a Poisson
ratio outside (-1, 0.5), ...) as a visible message with the session still working, the URL keys and the preset; and
a browser test that renders the tab."""

from __future__ import annotations

import html
import io
import math
import urllib.parse

import holoviews as hv
import numpy as np
import panel as pn
import pytest

from asymslide import model
from asymslide.app import rupture as rp
from asymslide.app.params import CUSTOM, LabParams, RuptureParams, follow_material
from asymslide.app.rupture import C_RATIO, PROFILE_GRID, RuptureScene
from asymslide.app.urlstate import TABS, query_string
from tests.conftest import open_app, save_screenshot
from tests.support.headless import build_app
from tests.support.spies import Calls, spying

pytestmark = pytest.mark.usefixtures("fresh_caches")

#: the scene's cache misses and model calls in the current test (tests/support/spies.py)
calls = Calls()


_spies = spying((rp, calls))


P = model.PAPER_DEFAULTS
#: the paper's inputs as the model's keyword arguments (plane stress)
KW = P.model_kwargs()


def _render_all(scene: RuptureScene) -> None:
    for dmap in (scene.profile_dmap, scene.vm_dmap, scene.stress_dmap, scene.stress_vm_dmap):
        dmap[()]
    scene.readout()
    scene.messages()


def _el(overlay: hv.Overlay, kind: type, label: str) -> hv.Element:
    (el,) = [e for e in overlay if isinstance(e, kind) and e.label == label]
    return el


def _c_R(nu: float = P.nu, c_s: float = P.c_s) -> float:
    return float(model.rayleigh_wave_speed(c_s=c_s, nu=nu, plane="stress"))


# --------------------------------------------------------------------------------------------
# the param graph: one cached function per dependency group
# --------------------------------------------------------------------------------------------


def _counts() -> dict[str, int]:
    return {k: calls[k] for k in ("compute_speeds", "compute_front", "compute_profile", "compute_vm_curve",
                                  "compute_stress_curve", "compute_stress_point")}


def test_first_render_computes_each_group_once_and_rerender_is_free() -> None:
    scene = RuptureScene()
    _render_all(scene)
    first = _counts()
    assert first == {"compute_speeds": 1, "compute_front": 1, "compute_profile": 1, "compute_vm_curve": 1,
                     "compute_stress_curve": 3, "compute_stress_point": 3}
    assert calls["slip_velocity_profile"] == 1 and calls["rayleigh_wave_speed"] == 1
    _render_all(scene)
    assert _counts() == first


@pytest.mark.parametrize(("change", "delta"), [
    ({"c_over_cR": 0.95}, {"compute_front": 1, "compute_profile": 1, "compute_stress_point": 3}),
    ({"sigma0_MPa": 3.0}, {"compute_stress_curve": 3, "compute_stress_point": 3}),
    ({"kW1": 2.0}, {"compute_stress_curve": 1, "compute_stress_point": 1}),
    ({"Gamma": 2.0}, {"compute_front": 1, "compute_profile": 1, "compute_vm_curve": 1, "compute_stress_curve": 3,
                      "compute_stress_point": 3}),
    ({"rho": 1200.0}, {"compute_speeds": 1, "compute_front": 1, "compute_profile": 1, "compute_vm_curve": 1,
                       "compute_stress_curve": 3, "compute_stress_point": 3}),
])
def test_a_change_recomputes_only_what_depends_on_it(change: dict, delta: dict) -> None:
    scene = RuptureScene()
    _render_all(scene)
    before = _counts()
    _set(scene, change)
    _render_all(scene)
    after = _counts()
    assert {k: after[k] - before[k] for k in after if after[k] != before[k]} == delta


def test_the_paper_inputs_are_the_defaults() -> None:
    """Γ, X_c0, ν and kW are the scene's; ρ, c_s and σ₀ the page's shared material constants (the Lab-units
    panel's), whose defaults are the paper's PMMA values too."""
    p, m = RuptureParams(), LabParams()
    assert (p.Gamma, p.X_c0_mm * 1e-3, m.sigma0_MPa * 1e6, m.rho, m.c_s, p.nu) == pytest.approx(
        (P.Gamma, P.X_c0, P.sigma0, P.rho, P.c_s, P.nu), rel=1e-15)
    assert (p.kW1, p.kW2, p.kW3) == P.kW and m.material == "PMMA"
    assert RuptureParams.material_nu("PMMA") == P.nu  # PMMA's preset gives the paper's nu = 0.33


def _set(scene: RuptureScene, change: dict) -> None:
    """Set `change` on the scene's own parameters or on the shared material constants, whichever has it."""
    own = {k: v for k, v in change.items() if k in scene.params.param}
    scene.params.param.update(**own)
    scene.material.param.update(**{k: v for k, v in change.items() if k not in own})


# --------------------------------------------------------------------------------------------
# the plotted data and the readout are the model's
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("c_ratio", [0.5, 0.9, 0.99])
def test_profile_plot_equals_the_model(c_ratio: float) -> None:
    scene = RuptureScene(params=RuptureParams(c_over_cR=c_ratio))
    c = c_ratio * _c_R()
    overlay = scene.profile_dmap[()]
    curve = _el(overlay, hv.Curve, "v(x)")
    x_mm = curve.dimension_values(0)
    np.testing.assert_array_equal(x_mm, PROFILE_GRID * P.X_c0 * 1e3)
    assert x_mm.min() < 0 < x_mm.max()  # behind the tip, and a little ahead where v = 0
    np.testing.assert_array_equal(curve.dimension_values(1), model.slip_velocity_profile(PROFILE_GRID * P.X_c0, c=c,
                                                                                          **KW))
    peak = _el(overlay, hv.Scatter, "peak v_m")
    assert peak.dimension_values(0)[0] == float(model.peak_slip_location(c, X_c0=P.X_c0, c_s=P.c_s, nu=P.nu)) * 1e3
    assert peak.dimension_values(1)[0] == float(model.peak_slip_velocity(c, **KW))
    zone = _el(overlay, hv.VSpans, "cohesive zone size X_c")
    x_c = float(model.cohesive_zone_size(c, X_c0=P.X_c0, c_s=P.c_s, nu=P.nu))
    np.testing.assert_array_equal(zone.array()[0], [-x_c * 1e3, 0.0])


def test_curves_equal_the_model() -> None:
    scene = RuptureScene()
    c = C_RATIO * _c_R()
    v_m = model.peak_slip_velocity(c, **KW)
    vm = _el(scene.vm_dmap[()], hv.Curve, "v_m")
    assert [d.name for d in vm.dimensions()] == ["c/c_R", "v_m [m/s]"]
    np.testing.assert_array_equal(vm.dimension_values(0), C_RATIO)
    np.testing.assert_array_equal(vm.dimension_values(1), v_m)
    current = _el(scene.vm_dmap[()], hv.Scatter, "current c")
    assert current.dimension_values(1)[0] == float(model.peak_slip_velocity(0.9 * _c_R(), **KW))
    for kw in P.kW:
        ds = model.relative_normal_stress_change_at_peak_slip(c, kW=kw, sigma0=P.sigma0, Gamma=P.Gamma, X_c0=P.X_c0,
                                                              mu=P.mu, c_s=P.c_s, nu=P.nu)
        label = f"kW = {kw:g}"
        curve = _el(scene.stress_dmap[()], hv.Curve, label)
        assert [d.name for d in curve.dimensions()] == ["c/c_R", "Δσ_yy/σ₀ at v_m"]
        np.testing.assert_array_equal(curve.dimension_values(1), ds)
        against_vm = _el(scene.stress_vm_dmap[()], hv.Curve, label)  # as Figs. 2c and 3c: against v_m
        np.testing.assert_array_equal(against_vm.dimension_values(0), v_m)
        np.testing.assert_array_equal(against_vm.dimension_values(1), ds)
    # kW = 3 > 4 > 5 (docs/physics.md §13.6)
    curves = [_el(scene.stress_dmap[()], hv.Curve, f"kW = {kw:g}").dimension_values(1) for kw in P.kW]
    assert np.all(curves[0] > curves[1]) and np.all(curves[1] > curves[2]) and np.all(curves[2] > 0)


def test_readout_shows_the_models_values() -> None:
    scene = RuptureScene(params=RuptureParams(c_over_cR=0.95))
    c = 0.95 * _c_R()
    text = scene.readout()
    tau_p = float(model.peak_cohesive_stress(Gamma=P.Gamma, X_c0=P.X_c0, mu=P.mu, nu=P.nu))
    assert f"**τ_p** = {tau_p / 1e6:.4g} MPa" in text
    assert f"**K_II** = {float(model.stress_intensity_factor(c, **KW)) / 1e3:.4g} kPa·m^½" in text
    x_c = float(model.cohesive_zone_size(c, X_c0=P.X_c0, c_s=P.c_s, nu=P.nu))
    assert f"**X_c** = X_c0/f_II = {x_c * 1e3:.4g} mm" in text
    assert f"**f_II(c)** = {float(model.mode_ii_universal_function(c, c_s=P.c_s, nu=P.nu)):.4g}" in text
    assert f"**v_m** = {float(model.peak_slip_velocity(c, **KW)):.4g} m/s" in text
    ds = model.relative_normal_stress_change_at_peak_slip(c, kW=5.0, sigma0=P.sigma0, Gamma=P.Gamma, X_c0=P.X_c0,
                                                          mu=P.mu, c_s=P.c_s, nu=P.nu)
    assert f"**Δσ_yy/σ₀ at v_m**, kW = 5: {float(ds):.4g}" in text
    assert "τ_p** = 1.118 MPa" in text  # the supplement's ~1.1 MPa (docs/physics.md §13.7)


def test_every_assumption_is_stated() -> None:
    panel = RuptureScene().__panel__()
    text = " ".join(str(getattr(o, "object", "")) for o in panel.select(pn.pane.Markdown))
    for needle in ("Thin-on-thin", "Plane stress", "tail to −∞", "Constant Γ", "X_c(c) = X_c0/f_II(c)",
                   "Sub-Rayleigh", "Density", "ASSUMPTION (not stated in the paper)"):
        assert needle in text, needle


def test_csv_equals_the_plots() -> None:
    scene = RuptureScene()
    lines = scene.csv_profile().getvalue().splitlines()
    data = np.loadtxt(io.StringIO("\n".join(lines[2:])), delimiter=",")
    curve = _el(scene.profile_dmap[()], hv.Curve, "v(x)")
    np.testing.assert_array_equal(data[:, 0], curve.dimension_values(0))
    np.testing.assert_array_equal(data[:, 1], curve.dimension_values(1))
    lines = scene.csv_curves().getvalue().splitlines()
    names = lines[1].split(",")
    data = np.loadtxt(io.StringIO("\n".join(lines[2:])), delimiter=",")
    assert names == ["c_over_c_R", "v_m_m_per_s", "dsigma_yy_over_sigma0(kW=3.0)", "dsigma_yy_over_sigma0(kW=4.0)",
                     "dsigma_yy_over_sigma0(kW=5.0)"]
    np.testing.assert_array_equal(data[:, 1], _el(scene.vm_dmap[()], hv.Curve, "v_m").dimension_values(1))
    np.testing.assert_array_equal(data[:, 4], _el(scene.stress_dmap[()], hv.Curve, "kW = 5").dimension_values(1))


def test_bokeh_axes() -> None:
    scene = RuptureScene()
    fig = hv.render(scene.profile_dmap, backend="bokeh")
    assert (fig.xaxis[0].axis_label, fig.yaxis[0].axis_label) == ("x [mm] (from the tip; x < 0 behind it)", "v [m/s]")
    fig = hv.render(scene.stress_vm_dmap, backend="bokeh")
    assert (fig.xaxis[0].axis_label, fig.yaxis[0].axis_label) == ("v_m [m/s]", "Δσ_yy/σ₀ at v_m")


# --------------------------------------------------------------------------------------------
# bad input: a visible message, the views it affects empty, the session keeps working
# --------------------------------------------------------------------------------------------


def _message(scene: RuptureScene) -> str:
    pane = scene.messages()
    assert isinstance(pane, pn.pane.Alert) and pane.alert_type == "danger"
    return html.unescape(pane.object)


@pytest.mark.parametrize(("change", "needles", "empty"), [
    ({"nu": 0.7}, ["nu must be in (-1, 0.5); got 0.7"], ["profile", "vm", "stress"]),
    ({"nu": -1.5}, ["nu must be in (-1, 0.5); got -1.5"], ["profile", "vm", "stress"]),
    ({"nu": -0.2}, ["Eq. dsigma (thin-on-thick): nu must be in [0, 0.5)"], ["stress"]),  # the slip model is fine
    ({"Gamma": -1.1}, ["Gamma must be in (0, inf)"], ["profile", "vm", "stress"]),
    ({"X_c0_mm": 0.0}, ["X_c0 must be in (0, inf)"], ["profile", "vm", "stress"]),
    ({"rho": -5.0}, ["rho must be in (0, inf)"], ["profile", "vm", "stress"]),
    ({"kW2": -4.0}, ["kW must be in (0, inf)"], []),
])
def test_bad_input_is_a_message_and_the_session_keeps_working(change: dict, needles: list[str],
                                                               empty: list[str]) -> None:
    scene = RuptureScene()
    _render_all(scene)
    _set(scene, change)
    _render_all(scene)  # no exception
    text = _message(scene)
    for needle in needles:
        assert needle in text
    curves = {"profile": [e for e in scene.profile_dmap[()] if isinstance(e, hv.Curve)],
              "vm": [e for e in scene.vm_dmap[()] if isinstance(e, hv.Curve)],
              "stress": [e for e in scene.stress_dmap[()] if isinstance(e, hv.Curve)]}
    for name, elements in curves.items():
        lengths = [len(e) for e in elements]
        assert (all(n == 0 for n in lengths) if name in empty else any(n > 0 for n in lengths)), name
    if "profile" in empty:
        assert "see the message above" in scene.readout()
    # back to good values: everything is drawn again and the message is gone
    _set(scene, {k: (RuptureParams.param[k] if k in RuptureParams.param else LabParams.param[k]).default
                 for k in change})
    assert scene.errors() == {}
    assert not isinstance(scene.messages(), pn.pane.Alert)
    assert len(_el(scene.profile_dmap[()], hv.Curve, "v(x)")) == PROFILE_GRID.size


def test_c_over_c_R_cannot_leave_the_models_range() -> None:
    """0 < c < c_R: the slider and the URL stop at 0.999 (a URL's 1.5 is clamped with a message, see test_app_main);
    the curves (b)-(d) reach that end, so the current-speed markers lie on them."""
    with pytest.raises(ValueError):
        RuptureParams(c_over_cR=1.0)
    scene = RuptureScene(params=RuptureParams(c_over_cR=0.999))
    _render_all(scene)
    assert scene.errors() == {} and C_RATIO[-1] >= 0.999
    (curve,) = [e for e in scene.vm_dmap[()] if isinstance(e, hv.Curve)]
    assert curve.dimension_values(0).max() >= scene.params.c_over_cR


def test_bad_input_in_the_app_keeps_the_session_working() -> None:
    app = build_app({"c_cR": ["1.5"], "rup_nu": ["0.9"], "rup_material": ["unobtainium"], "tab": ["rupture"]})
    assert app.tabs.active == TABS.index("rupture")
    assert "Material = 'unobtainium' is not one of PMMA" in app.messages.object  # the URL message
    assert "c/c_R = 1.5 is outside 0.01 … 0.999: set to 0.999" in app.messages.object
    assert "nu must be in (-1, 0.5); got 0.9" in app.messages.object  # the model's refusal, in the banner too
    text = _message(app.rupture)
    assert "nu must be in (-1, 0.5); got 0.9" in text
    app.rupture_params.nu = 0.33
    app.rupture_params.c_over_cR = 0.9
    assert app.rupture.errors() == {}
    assert "**v_m** = 1.129 m/s" in app.rupture.readout()


def test_material_preset_fills_rho_cs_nu() -> None:
    scene = RuptureScene()
    follow_material(scene.material)  # as the Lab-units panel does on the page
    scene.material.material = "Homalite-100"
    assert (scene.material.rho, scene.material.c_s, scene.params.nu) == (1230.0, 1200.0, 0.35)  # the source's nu
    scene.material.material = "fused silica"
    silica = model.material("fused silica")
    assert scene.params.nu == pytest.approx(silica.nu, rel=1e-15)  # none reported: from the speeds
    scene.material.rho = 2000.0
    assert scene.material.material == CUSTOM and scene.front_key[3] == 2000.0


def test_one_set_of_material_constants_for_the_whole_page() -> None:
    """c_s, ρ and σ₀ had three unsynced copies (lab panel, Thin-on-thick, Rupture fronts); now a change in any tab's
    widget changes them everywhere, and each tab says which values it uses."""
    app = build_app({})
    thin_widgets = {w.label: w for w in app.thin.__panel__().objects[0] if isinstance(w, pn.widgets.Widget)}
    rupture_widgets = {w.label: w for w in app.rupture.__panel__().objects[0] if isinstance(w, pn.widgets.Widget)}
    thin_widgets["c_s [m/s]"].value = 1000.0
    rupture_widgets["σ₀ [MPa]"].value = 3.0
    assert (app.lab_params.c_s, app.lab_params.sigma0_MPa) == (1000.0, 3.0)
    assert app.thin.stress_key[2] == 1000.0 and app.thin.stress_key[4] == 3e6
    assert app.rupture.front_key[4] == 1000.0 and app.rupture.stress_key[0] == 3e6
    assert rupture_widgets["c_s [m/s]"].value == 1000.0 and thin_widgets["σ₀ [MPa]"].value == 3.0
    assert app.lab.key[1] == 1000.0 and app.lab.key[3] == 3e6
    for readout in (app.thin.readout(), app.rupture.readout()):
        assert "**Lab values used** (shared): custom, ρ = 1180 kg/m³, c_s = 1000 m/s, σ₀ = 3 MPa" in readout


# --------------------------------------------------------------------------------------------
# URL and preset
# --------------------------------------------------------------------------------------------


def test_url_round_trip_of_the_rupture_keys() -> None:
    query = "c_cR=0.97&Gamma=2&Xc0=1.5&lab_sigma0=3&material=Homalite-100&kW1=2&kW3=8&tab=rupture"
    app = build_app(urllib.parse.parse_qs(query))
    p, m = app.rupture_params, app.lab_params
    assert not app.messages.visible
    assert (p.c_over_cR, p.Gamma, p.X_c0_mm, m.sigma0_MPa, m.material, m.rho, p.nu, p.kW1, p.kW2, p.kW3) == (
        0.97, 2.0, 1.5, 3.0, "Homalite-100", 1230.0, 0.35, 2.0, 4.0, 8.0)
    written = query_string(app.param_objects(), "rupture")
    assert "kW2" not in written  # unchanged values are not written
    again = build_app(urllib.parse.parse_qs(written[1:]))
    for name in RuptureParams.param:
        if name != "name":
            assert getattr(again.rupture_params, name) == getattr(p, name), name


def test_preset_restores_the_papers_inputs() -> None:
    app = build_app({"Gamma": ["3"], "rup_nu": ["0.2"], "c_cR": ["0.5"]})
    (preset,) = [p for p in app.presets if p.id == "rupture"]
    app.apply_preset(preset)
    p = app.rupture_params
    assert app.tabs.active == TABS.index("rupture")
    assert (p.Gamma, p.nu, p.c_over_cR, app.lab_params.material) == (1.1, 0.33, 0.9, "PMMA")
    assert not math.isnan(app.rupture.front()["v_m"])


# --------------------------------------------------------------------------------------------
# browser
# --------------------------------------------------------------------------------------------

_FIGURES_JS = ("() => Array.from(Bokeh.documents[0].all_models)"
               ".filter(m => m.title && m.title.text && m.x_range).map(m => m.title.text)")

_VM_SOURCE_JS = """() => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.data != null && m.data['v_m [m/s]'] !== undefined && m.data['c/c_R'] !== undefined) {
      const y = Array.from(m.data['v_m [m/s]']);
      if (y.length > 10) return y;
    }
  }
  return null;
}"""


@pytest.mark.ui
@pytest.mark.slow
def test_rupture_tab_renders(served_app: str, browser_page) -> None:
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1700})
    open_app(page, served_app, "Rupture fronts")
    page.wait_for_function(f"() => ({_FIGURES_JS})().filter(t => /^\\(([abcd])\\)/.test(t)).length >= 4",
                           timeout=60_000)
    page.get_by_text("Exponential cohesive law").first.wait_for(state="visible", timeout=30_000)
    page.wait_for_function(_VM_SOURCE_JS, timeout=30_000)
    v_m = np.array(page.evaluate(_VM_SOURCE_JS), dtype=float)
    np.testing.assert_allclose(v_m, model.peak_slip_velocity(C_RATIO * _c_R(), **KW), rtol=1e-12, atol=0)
    page.wait_for_function("() => window.location.search.includes('tab=rupture')", timeout=30_000)
    save_screenshot(page, "screenshot_rupture.png")
    assert page.console_errors == []


# --------------------------------------------------------------------------------------------
# (c) is readable at the paper's inputs
# --------------------------------------------------------------------------------------------


def test_plot_c_has_a_log_axis_that_shows_the_curves_at_the_papers_inputs() -> None:
    """Plot (c) has a log axis: on a linear one its curves (10⁻² ... 10⁰, steep near c_R) looked flat at 0."""
    from bokeh.models import Plot

    scene = RuptureScene()
    # as on the page: in the scene's layout, where Panel links the axes of plots that share a dimension
    (fig,) = [m for m in scene.__panel__().get_root().references()
              if isinstance(m, Plot) and m.title is not None and m.title.text.startswith("(c)")]
    assert type(fig.y_scale).__name__ == "LogScale" and type(fig.yaxis[0]).__name__ == "LogAxis"
    assert fig.xaxis[0].axis_label == "c/c_R"
    assert fig.yaxis[0].axis_label == "Δσ_yy/σ₀ at v_m (dimensionless, log scale)"
    lo, hi = fig.y_range.start, fig.y_range.end
    assert 0 < lo < hi  # a log axis' range (it was (d)'s linear one, from below 0, while the two were linked)

    def height(y: np.ndarray) -> np.ndarray:
        """Position on the (log) y axis: 0 at its bottom, 1 at its top."""
        return np.log10(y / lo) / math.log10(hi / lo)

    c = C_RATIO * _c_R()
    ds = {kw: model.relative_normal_stress_change_at_peak_slip(c, kW=kw, sigma0=P.sigma0, Gamma=P.Gamma, X_c0=P.X_c0,
                                                                mu=P.mu, c_s=P.c_s, nu=P.nu) for kw in P.kW}
    for kw, y in ds.items():
        assert 0 < height(y.min()) and height(y.max()) < 1, kw  # every curve is on the plot
    # the three curves are apart, not one line at the bottom: kW = 3 lies above kW = 5 by more than 3 % of the
    # axis' height at most c (a linear axis to the steep end near c_R put them 0.15 % apart, under a pixel)
    apart = height(ds[P.kW[0]]) - height(ds[P.kW[-1]])
    assert np.median(apart) > 0.03 and np.all(apart > 0)
    (d,) = [r for r in hv.render(scene.stress_vm_dmap, backend="bokeh").yaxis]
    assert type(d).__name__ == "LinearAxis"  # (d) against v_m stays linear, as Figs. 2c and 3c


def test_values_a_log_axis_cannot_show_are_gaps_and_named() -> None:
    """At ν = 0 and kW = 10 the model's Δσ_yy/σ₀ is <= 0 near c = 0: a gap in (c), a note, every value in (d)."""
    scene = RuptureScene(params=RuptureParams(nu=0.0, kW1=10.0))
    assert not isinstance(RuptureScene().log_note(), pn.pane.Alert)
    c = C_RATIO * _c_R(nu=0.0)
    ds = model.relative_normal_stress_change_at_peak_slip(c, kW=10.0, sigma0=P.sigma0, Gamma=P.Gamma, X_c0=P.X_c0,
                                                          mu=P.mu, c_s=P.c_s, nu=0.0)
    assert np.any(ds <= 0) and np.any(ds > 0)
    shown = _el(scene.stress_dmap[()], hv.Curve, "kW = 10").dimension_values(1)
    np.testing.assert_array_equal(shown[ds > 0], ds[ds > 0])
    assert np.all(np.isnan(shown[ds <= 0]))
    np.testing.assert_array_equal(_el(scene.stress_vm_dmap[()], hv.Curve, "kW = 10").dimension_values(1), ds)
    note = scene.log_note()
    assert isinstance(note, pn.pane.Alert) and "kW = 10" in note.object and "(d)" in note.object


def test_the_readout_never_names_a_material_beside_another_materials_nu() -> None:
    """As in Thin-on-thick: ν has its own field, so it can differ from the named material's after the choice."""
    scene = RuptureScene()
    follow_material(scene.material)  # as the Lab-units panel does on the page
    assert "PMMA, ρ = 1180 kg/m³, c_s = 1345 m/s, σ₀ = 4.5 MPa, ν = 0.33 (PMMA's)" in scene.readout()
    scene.params.nu = 0.2
    text = scene.readout()
    assert "**ν** = 0.2, set here: not PMMA's ν = 0.33" in text and "(PMMA's)" not in text
    scene.material.material = "fused silica"  # a choice brings its ν
    assert f"ν = {model.material('fused silica').nu:.4g} (fused silica's)" in scene.readout()
    scene.material.material = CUSTOM  # the name alone changed: the readout follows it
    assert "(shared): custom," in scene.readout() and "fused silica" not in scene.readout()


# --------------------------------------------------------------------------------------------
# a held c/c_R slider moves the plots on the page without a HoloViews redraw (app.live)
# --------------------------------------------------------------------------------------------


def _page(**params: float) -> tuple[RuptureScene, pn.widgets.FloatSlider]:
    """A scene rendered as on the page (its layout in a Bokeh document, the axes linked as Panel links them) and its
    c/c_R slider."""
    from bokeh.document import Document

    scene = RuptureScene(params=RuptureParams(**params))
    scene.__panel__().get_root(Document())
    (slider,) = scene.follow.sliders
    return scene, slider


def _drawn(scene: RuptureScene) -> dict[str, dict]:
    """What each plot on the page shows: title, axis ranges, legend, each visible layer's columns (by HoloViews'
    key)."""
    from asymslide.app import live

    out = {}
    for name, pane in scene.panes.items():
        (plot,) = live.rendered_plots(pane)
        fig = plot.state
        out[name] = {
            "title": fig.title.text, "x": (fig.x_range.start, fig.x_range.end),
            "y": (fig.y_range.start, fig.y_range.end),
            "legend": [(getattr(i.label, "value", i.label), i.visible) for legend in fig.legend for i in legend.items],
            **{str(key): {c: np.asarray(v) for c, v in sub.handles["source"].data.items()}
               for key, sub in plot.subplots.items() if "source" in sub.handles
               and sub.handles["glyph_renderer"].visible},  # a layer a redraw left out is hidden (HoloViews)
        }
    return out


def _redrawn(opened: dict, **params: float) -> RuptureScene:
    """A page opened at `opened`, then redrawn by HoloViews at `params` (a change that no slider holds)."""
    scene, _ = _page(**opened)
    scene.params.param.update(**params)
    return scene


def _assert_same(shown: dict[str, dict], expected: dict[str, dict]) -> None:
    assert shown.keys() == expected.keys() == {"profile", "vm", "stress", "stress_vm"}
    for name, plot in expected.items():
        assert shown[name].keys() == plot.keys(), name
        for key, value in plot.items():
            if isinstance(value, dict):
                assert shown[name][key].keys() == value.keys(), (name, key)
                for column, data in value.items():
                    np.testing.assert_array_equal(shown[name][key][column], data, err_msg=f"{name} {key} {column}")
            else:
                assert shown[name][key] == value, (name, key)


def _assert_drawn_as_a_redraw(scene: RuptureScene, *, opened: dict | None = None, fresh: bool = True,
                              **params: float) -> None:
    """The page of `scene`, opened at `opened` (default: the defaults), shows exactly what HoloViews draws at its
    current inputs (`opened` and `params`): the same page redrawn by HoloViews there, and (`fresh`) a page opened
    there (not where a redraw gave a plot other ranges than a first drawing: HoloViews keeps some of a plot's history,
    e.g. the range of a layer a redraw left without data)."""
    opened = opened or {}
    shown = _drawn(scene)
    _assert_same(shown, _drawn(_redrawn(opened, **params)))
    if fresh:
        _assert_same(shown, _drawn(_page(**opened, **params)[0]))


def _release(slider: pn.widgets.FloatSlider, value: float | None = None) -> None:
    """Let go of the handle (at `value`, else where it is): value and value_throttled in one change, as Bokeh sends
    a release."""
    import param

    value = slider.value if value is None else value
    with param.edit_constant(slider):
        slider.param.update(value=value, value_throttled=value)


@pytest.mark.slow
def test_a_held_c_slider_moves_the_plots_on_the_page_without_a_holoviews_redraw() -> None:
    """While c/c_R is held, (a)-(d) on the page show at every position of the handle exactly what a HoloViews redraw
    at that c draws (profile, peak, cohesive zone, markers on (c)'s log axis, the title of (a), every range and
    legend), written into the Bokeh sources (app.live) without a redraw; the readout follows. At the release at the
    last position nothing is redrawn."""
    scene, slider = _page()
    drawn = scene.drawn
    for c in (0.5, 0.75, 0.97):
        slider.value = c  # the handle moves; value_throttled stays: held
        assert scene.follow.held() and scene.drawn == drawn
        _assert_drawn_as_a_redraw(scene, c_over_cR=c)
        front = model.peak_slip_velocity(c * _c_R(), **KW)
        assert f"**v_m** = {rp.fmt(float(front))} m/s" in scene.readout()
    _release(slider)
    assert not scene.follow.held() and scene.drawn == drawn
    _assert_drawn_as_a_redraw(scene, c_over_cR=0.97)


@pytest.mark.slow
def test_a_release_elsewhere_is_written_and_a_change_from_elsewhere_is_redrawn() -> None:
    """A release at a value the page does not show yet is written like a held position (the page then shows what a
    redraw shows); a change that does not come from a held slider (a preset, the URL) is redrawn by HoloViews."""
    scene, slider = _page()
    drawn = scene.drawn
    slider.value = 0.5
    _release(slider, 0.8)
    assert scene.drawn == drawn
    _assert_drawn_as_a_redraw(scene, c_over_cR=0.8)
    scene.params.c_over_cR = 0.6
    assert scene.drawn == drawn + 1 and slider.value == 0.6 and not scene.follow.held()
    _assert_drawn_as_a_redraw(scene, c_over_cR=0.6)


@pytest.mark.slow
def test_a_held_slider_over_bad_input_falls_back_to_a_holoviews_redraw() -> None:
    """Where the layers change kind (bad input empties (a) to one curve without its peak or cohesive zone), app.live
    cannot write them: HoloViews redraws at every position, and the page is what a redraw draws; back on good input
    the plots follow the hand again."""
    scene, slider = _page()
    scene.params.nu = 0.7  # outside (-1, 0.5): every plot empty
    drawn = scene.drawn
    slider.value = 0.5
    assert scene.drawn == drawn + 1
    _assert_drawn_as_a_redraw(scene, fresh=False, c_over_cR=0.5, nu=0.7)
    _release(slider)
    scene.params.nu = P.nu  # good input again: drawn by HoloViews (another input than c)
    drawn = scene.drawn
    slider.value = 0.6
    assert scene.drawn == drawn
    _assert_drawn_as_a_redraw(scene, c_over_cR=0.6)


@pytest.mark.slow
def test_a_layer_app_live_cannot_write_falls_back_to_a_holoviews_redraw(monkeypatch: pytest.MonkeyPatch) -> None:
    """A layer of another kind than the one on the page (here a third column) is not written: HoloViews redraws."""
    scene, slider = _page()
    layers = RuptureScene.live_layers

    def other_kind(self: RuptureScene, front_key: tuple) -> dict:
        out = layers(self, front_key)
        x, y = out["vm"]["current c"]
        out["vm"]["current c"] = (x, y, y)
        return out

    monkeypatch.setattr(RuptureScene, "live_layers", other_kind)
    drawn = scene.drawn
    slider.value = 0.4
    assert scene.drawn == drawn + 1
    _assert_drawn_as_a_redraw(scene, c_over_cR=0.4)


@pytest.mark.slow
def test_held_markers_on_the_log_axis_of_c_are_gaps_where_the_model_gives_values_le_0() -> None:
    """At ν = 0 and kW = 10, Δσ_yy/σ₀ <= 0 near c_R: written while held, the marker of (c) is a gap (NaN), as a
    redraw draws it, and (d) shows the value."""
    params = {"nu": 0.0, "kW1": 10.0}
    scene, slider = _page(**params)
    ds = model.relative_normal_stress_change_at_peak_slip(0.99 * _c_R(nu=0.0), kW=10.0, sigma0=P.sigma0,
                                                          Gamma=P.Gamma, X_c0=P.X_c0, mu=P.mu, c_s=P.c_s, nu=0.0)
    assert ds <= 0
    drawn = scene.drawn
    for c in (0.3, 0.99):
        slider.value = c
        assert scene.drawn == drawn
        _assert_drawn_as_a_redraw(scene, opened=params, c_over_cR=c)
    stress = _drawn(scene)["stress"]
    (marker,) = [v for k, v in stress.items() if k == str(("Scatter", "Current_c"))]
    assert np.isnan(marker["Δσ_yy/σ₀ at v_m"][0])
    (marker_d,) = [v for k, v in _drawn(scene)["stress_vm"].items() if k == str(("Scatter", "Current_c"))]
    assert marker_d["Δσ_yy/σ₀ at v_m"][0] == pytest.approx(float(ds), rel=1e-12)
