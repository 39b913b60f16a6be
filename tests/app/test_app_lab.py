"""The Lab-units panel (app/lab.py): lab values -> sliders through model.dimensionless_parameters (one update, clamped,
bad input refused with the model's message), the readouts and the plot in lab units equal to the model's values, the
model calls it makes, the URL round trip of the lab keys; and a browser test in which the γ slider follows a lab
value."""

from __future__ import annotations

import html
import io
import math
import re
import urllib.parse

import holoviews as hv
import numpy as np
import panel as pn
import pytest

from asymslide import model
from asymslide.app import lab as lb
from asymslide.app import spectrum as sp
from asymslide.app.lab import E_FOLDING_AXIS, KH, LabScene, slider_values
from asymslide.app.params import CUSTOM, LabParams, SpectrumParams
from asymslide.app.stability_map import map_plot
from asymslide.app.urlstate import parse_query, query_string
from tests.conftest import open_app, save_screenshot
from tests.support.headless import build_app
from tests.support.spies import Calls, spying

pytestmark = pytest.mark.usefixtures("fresh_caches")

#: the scene's cache misses and model calls in the current test (tests/support/spies.py)
calls = Calls()
sp_calls = Calls()


_spies = spying((lb, calls), (sp, sp_calls))


PMMA = model.material("PMMA")


def _lab_si(p: LabParams) -> dict:
    """The keyword arguments of model.dimensionless_parameters for `p` (SI units)."""
    return dict(rho=p.rho, c_s=p.c_s, c_d=p.c_d, sigma0=p.sigma0_MPa * 1e6, f=p.f, H1=p.H1_mm * 1e-3,
                H2=math.inf if p.H2_infinite else p.H2_mm * 1e-3, v=p.v, a=p.a, b=p.b, D_c=p.D_c_um * 1e-6,
                plane=p.plane)


def _expected(p: LabParams) -> dict[str, float]:
    return {k: float(v) for k, v in model.dimensionless_parameters(**_lab_si(p)).items()}


def _linked() -> LabScene:
    scene = LabScene()
    scene.params.link = True
    return scene


# --------------------------------------------------------------------------------------------
# defaults and the link
# --------------------------------------------------------------------------------------------


def test_defaults_are_pmma_with_the_papers_gamma_f_eta_delta() -> None:
    p = LabParams()
    assert (p.material, p.rho, p.c_s, p.c_d, p.plane) == ("PMMA", PMMA.rho, PMMA.c_s, PMMA.c_d, "strain")
    d = _expected(p)
    assert d["gamma"] == pytest.approx(3.0, abs=5e-5)
    assert (d["f"], d["eta"], d["Delta"]) == (0.9, math.inf, 1.0)
    assert d["beta"] == pytest.approx(1345.0 / 2700.0, rel=1e-15)  # PMMA's, not the paper's 0.3
    assert not p.link  # the sliders start at the paper's Fig. 4 values


def test_link_sets_every_slider_in_one_update() -> None:
    scene = LabScene()
    batches: list[list[str]] = []
    scene.spectrum.param.watch(lambda *events: batches.append([e.name for e in events]),
                               [n for n in scene.spectrum.param if n != "name"])
    scene.params.link = True
    assert len(batches) == 1 and {"gamma", "beta"} <= set(batches[0])
    d = _expected(scene.params)
    assert scene.spectrum.model_args() == (d["gamma"], d["f"], d["beta"], d["eta"], d["Delta"], 0.0)
    assert scene.state().matches and "follow" in scene.title


def test_sliders_follow_every_lab_change_only_while_linked() -> None:
    scene = LabScene()
    scene.params.v = 2 * scene.params.v
    assert scene.spectrum.gamma == 3.0  # link off: nothing moves
    assert "link off" in scene.title and "differ from the lab values" in scene.status().object
    scene.params.link = True
    for name, value in (("v", 0.05), ("H2_infinite", False), ("H2_mm", 25.0), ("b", 0.004), ("plane", "stress"),
                        ("sigma0_MPa", 3.0), ("material", "Homalite-100"), ("f", 0.6), ("D_c_um", 5.0)):
        setattr(scene.params, name, value)
        d = _expected(scene.params)
        assert scene.spectrum.model_args() == pytest.approx(
            (d["gamma"], d["f"], d["beta"], d["eta"], d["Delta"], d["xi"] if d["Delta"] != 1 else 0.0), rel=1e-12), name
    assert scene.spectrum.eta == pytest.approx(2.5, rel=1e-12) and not scene.spectrum.eta_infinite
    scene.params.link = False
    before = scene.spectrum.model_args()
    scene.params.v = 0.02
    assert scene.spectrum.model_args() == before


def test_a_slider_moved_by_hand_is_reported_and_can_be_reapplied() -> None:
    scene = _linked()
    scene.spectrum.gamma = 4.0  # by hand
    st = scene.state()
    assert [m.split(" =")[0] for m in st.mismatches] == ["γ"]
    assert "no longer match" in scene.title
    text = scene.status().object
    assert "no longer match" in text and "γ = 4 on the slider" in text
    assert scene.apply()
    assert scene.state().matches and scene.spectrum.gamma == pytest.approx(_expected(scene.params)["gamma"])
    scene.spectrum.eta_infinite = False
    assert scene.state().mismatches == ["η = 1e+08 on the slider, ∞ from the lab values"]


def test_values_outside_a_sliders_range_are_clamped_with_a_message() -> None:
    scene = _linked()
    scene.params.v = 1e-5  # gamma = 3.5e-4 < 0.01, xi = 1.3e4 > 1e4
    d = _expected(scene.params)
    assert d["gamma"] < 0.01 and d["xi"] > 1e4
    assert scene.spectrum.gamma == 0.01 and scene.spectrum.xi == 1e4
    st = scene.state()
    assert st.matches and len(st.notes) == 2
    status = scene.status()
    assert status.alert_type == "warning"
    assert "γ = 0.0003527 is outside the slider's range 0.01 … 1000: set to 0.01" in status.object


def test_slider_values_are_the_declarations_clamps() -> None:
    updates, notes = slider_values({"gamma": 5.0, "f": 3.0, "beta": 0.70710678, "eta": 1e-3, "Delta": 0.5, "xi": 2.0})
    assert updates == {"gamma": 5.0, "f": 2.0, "beta": 0.7071, "eta_infinite": False, "log10_eta": -2.0,
                       "Delta": 0.5, "xi": 2.0}
    assert [n.split(" =")[0] for n in notes] == ["f", "β", "η"]
    updates, notes = slider_values({"gamma": 5.0, "f": 0.5, "beta": 0.3, "eta": math.inf, "Delta": 1.0, "xi": 0.0})
    assert updates["eta_infinite"] is True and "log10_eta" not in updates and notes == []


# --------------------------------------------------------------------------------------------
# bad input: a visible message, sliders unchanged, the session keeps working
# --------------------------------------------------------------------------------------------

BAD = [
    # fields typed in mm, MPa, µm: their units and labels, not the model's SI ones
    ({"H1_mm": -5.0}, ["H₁ must be in (0, ∞) mm", "got -5 mm"]),
    ({"H2_infinite": False, "H2_mm": -30.0}, ["H₂ must be in (0, ∞) mm", "H₂ = ∞", "got -30 mm"]),
    ({"sigma0_MPa": 0.0}, ["σ₀ must be in (0, ∞) MPa", "got 0 MPa"]),
    ({"D_c_um": -1.0}, ["D_c must be in [0, ∞) µm", "got -1 µm"]),
    ({"b": 0.01}, ["0 <= b < a", "a = 0.01, b = 0.01"]),
    ({"b": 0.05}, ["0 <= b < a"]),
    ({"c_d": 1.1 * 1345.0}, ["c_d must be >= sqrt(2) c_s", "Poisson ratio"]),  # nu < 0 (and < -1 for stress)
    ({"c_d": 1.1 * 1345.0, "plane": "stress"}, ["c_d", "Poisson ratio"]),
    ({"c_d": 1000.0}, ["c_d", "Poisson ratio"]),  # c_d < c_s: no isotropic solid
    ({"rho": -1180.0}, ["rho must be in (0, inf)"]),
    ({"a": 0.0}, ["a must be in (0, inf)"]),
    ({"v": 0.0}, ["v must be in (0, inf) m/s"]),
]


@pytest.mark.parametrize(("bad", "needles"), BAD)
def test_bad_input_gives_the_models_message_and_leaves_the_sliders(bad: dict, needles: list[str]) -> None:
    scene = _linked()
    before = scene.spectrum.model_args()
    scene.params.param.update(**bad)
    assert scene.spectrum.model_args() == before
    status = scene.status()
    assert isinstance(status, pn.pane.Alert) and status.alert_type == "danger"
    text = html.unescape(status.object)  # the model's message, escaped for Markdown
    assert "sliders are unchanged" in text
    for needle in needles:
        assert needle in text
    assert "not valid" in scene.title
    assert "not valid" in scene.readout() and scene.lab_plot() is not None
    assert not scene.apply() and scene.spectrum.model_args() == before
    # the session keeps working: a good value again, and the sliders follow
    good = {k: LabParams.param[k].default for k in bad}
    scene.params.param.update(**good)
    assert scene.state().matches and scene.status().alert_type == "success"


@pytest.mark.parametrize(("bad", "model_words", "shown"), [
    ({"H1_mm": -5.0}, "H1 must be in (0, inf) m; got -0.005", "H₁ must be in (0, ∞) mm; got -5 mm"),
    ({"sigma0_MPa": -2.0}, "sigma0 must be in (0, inf) Pa; got -2000000", "σ₀ must be in (0, ∞) MPa; got -2 MPa"),
])
def test_a_field_typed_in_other_units_is_refused_in_those_units(bad: dict, model_words: str, shown: str) -> None:
    """H₁ = −5 mm was refused with the model's words, which speak of metres (H1 = -0.005 m). The panel says it in
    the units and with the label of the field the user typed; the model's own message is unchanged."""
    scene = _linked()
    scene.params.param.update(**bad)
    with pytest.raises(ValueError, match=re.escape(model_words)):
        model.dimensionless_parameters(**_lab_si(scene.params))
    text = html.unescape(scene.status().object)
    assert shown in text
    assert model_words not in text and " m;" not in text and " Pa;" not in text


def test_unknown_material_in_the_url_is_a_message() -> None:
    app = build_app({"material": ["unobtainium"], "lab": ["1"], "H1": ["20"]})
    assert app.messages.visible
    assert "Material = 'unobtainium' is not one of PMMA" in app.messages.object
    assert app.lab_params.material == "PMMA" and app.lab_params.H1_mm == 20.0


def test_material_preset_fills_in_its_values_and_editing_makes_it_custom() -> None:
    scene = _linked()
    scene.params.material = "fused silica"
    silica = model.material("fused silica")
    assert (scene.params.rho, scene.params.c_s, scene.params.c_d) == (silica.rho, silica.c_s, silica.c_d)
    assert scene.spectrum.beta == pytest.approx(silica.c_s / silica.c_d, rel=1e-15)
    scene.params.c_s = 3700.0
    assert scene.params.material == CUSTOM and scene.params.c_d == silica.c_d
    scene.params.material = "PMMA"
    assert (scene.params.rho, scene.params.c_s, scene.params.c_d) == (PMMA.rho, PMMA.c_s, PMMA.c_d)


# --------------------------------------------------------------------------------------------
# which change calls which model function
# --------------------------------------------------------------------------------------------


def test_model_calls() -> None:
    spectrum = sp.SpectrumScene()
    scene = LabScene(spectrum=spectrum.params)
    assert calls["dimensionless_parameters"] == 1 and calls["compute_lab_spectrum"] == 0  # nothing is rendered
    scene.params.link = True
    spectrum.im_dmap[()]
    scene.readout()
    scene.lab_plot()
    # the matched sliders and the lab readout share one spectrum computation
    assert sp_calls["compute_spectrum"] == 1
    assert (calls["compute_lab_spectrum"], calls["fastest_growing_mode"]) == (1, 1)
    spectrum.params.gamma = 4.0  # a slider by hand: the lab values are not recomputed
    scene.readout()
    assert calls["dimensionless_parameters"] == 1 and calls["compute_lab_spectrum"] == 1
    scene.params.v = 0.1  # a lab value: one new mapping, one new lab spectrum
    scene.readout()
    scene.lab_plot()
    assert calls["dimensionless_parameters"] == 2 and calls["compute_lab_spectrum"] == 2
    scene.params.v = 0.08506  # back: both from the cache
    scene.readout()
    assert calls["dimensionless_parameters"] == 2 and calls["compute_lab_spectrum"] == 2


# --------------------------------------------------------------------------------------------
# readouts, plot and CSV equal the model's values
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("lab", [{}, {"H1_mm": 50.0, "H2_infinite": False, "H2_mm": 100.0, "b": 0.005,
                                      "D_c_um": 2.0, "v": 0.2}])
def test_readout_and_plot_equal_the_model(lab: dict) -> None:
    scene = LabScene(params=LabParams(**lab))
    p = _expected(scene.params)
    args = {k: p[k] for k in SpectrumParams.MODEL_ARGS}
    H1, c_s = scene.params.H1_mm * 1e-3, scene.params.c_s
    k, z = model.fastest_growing_mode(KH, **args)
    peak = model.spectrum_in_lab_units(kH=k, z=z, H1=H1, c_s=c_s)
    text = scene.readout()
    assert f"λ = {float(peak['wavelength']) * 1e3:.4g} mm" in text
    assert f"**Growth rate** {float(peak['growth_rate']):.4g} 1/s" in text
    assert f"**e-folding time** {float(peak['e_folding_time']) * 1e3:.4g} ms" in text
    assert f"**Phase speed** {float(peak['phase_speed']):.4g} m/s" in text
    g = model.growth_analysis(KH, **args)
    lo, hi = model.wavelength(kH=np.array([g.kH_max, g.kH_min]), H1=H1) * 1e3
    assert f"**Unstable band** {lo:.4g} mm < λ < {hi:.4g} mm" in text
    # the plot: growth rate [1/s] vs wavelength [mm] on the Spectrum scene's kH grid
    lab_units = model.spectrum_in_lab_units(kH=KH, z=model.spectrum(KH, **args), H1=H1, c_s=c_s)
    overlay = scene.plot_dmap[()]
    (curve,) = [e for e in overlay if isinstance(e, hv.Curve)]
    assert [d.name for d in curve.dimensions()] == ["λ [mm]", "growth rate k Im c [1/s]"]
    np.testing.assert_array_equal(curve.dimension_values(0), lab_units["wavelength"][::-1] * 1e3)
    np.testing.assert_array_equal(curve.dimension_values(1), lab_units["growth_rate"][::-1])
    (mark,) = [e for e in overlay if isinstance(e, hv.Scatter)]
    assert mark.dimension_values(0)[0] == float(peak["wavelength"]) * 1e3
    assert mark.dimension_values(1)[0] == float(peak["growth_rate"])
    (band,) = [e for e in overlay if isinstance(e, hv.VSpans)]
    np.testing.assert_array_equal(band.array()[0], [lo, hi])
    # the CSV holds what the plot shows
    lines = scene.csv().getvalue().splitlines()
    names = lines[1].split(",")
    data = np.genfromtxt(io.StringIO("\n".join(lines[2:])), delimiter=",")
    np.testing.assert_array_equal(data[:, names.index("wavelength_mm")], lab_units["wavelength"] * 1e3)
    np.testing.assert_array_equal(data[:, names.index("growth_rate_per_s")], lab_units["growth_rate"])
    # the e-folding time only where the mode grows (decaying modes are empty, not inf)
    growing = lab_units["growth_rate"] > 0
    e_folding = data[:, names.index("e_folding_time_ms")]
    np.testing.assert_array_equal(e_folding[growing], lab_units["e_folding_time"][growing] * 1e3)
    assert growing.any() and (~growing).any() and np.isnan(e_folding[~growing]).all()
    np.testing.assert_array_equal(data[:, names.index("phase_speed_m_per_s")], lab_units["phase_speed"])


@pytest.mark.parametrize("lab", [{}, {"H1_mm": 50.0, "H2_infinite": False, "H2_mm": 100.0, "b": 0.005,
                                      "D_c_um": 2.0, "v": 0.2}])
def test_the_fastest_mode_of_every_branch_in_lab_units(lab: dict) -> None:
    """The panel reads back the fastest growth of every branch over every kH (model.sliding_analysis(rate=True).sigma:
    the largest k Im c over every branch and 0 < kH < inf) in lab units, with its family, beside the Rayleigh
    branch's. At PMMA's defaults the fastest growth is a supersonic guided mode's, approached as kH -> inf (over
    [0.01, 100] an intersonic guided mode grows fastest, ~5 times faster than the Rayleigh branch)."""
    scene = LabScene(params=LabParams(**lab))
    p = _expected(scene.params)
    args = {k: p[k] for k in SpectrumParams.MODEL_ARGS}
    H1, c_s = scene.params.H1_mm * 1e-3, scene.params.c_s
    r = model.sliding_analysis(**args, rate=True)
    text = scene.readout()
    assert "**Fastest-growing mode of the Rayleigh branch**" in text or "**No growing mode**" in text
    if not np.isfinite(r.sigma):
        if r.verdict != 1:
            assert f"**Sliding {model.VERDICTS[int(r.verdict)]}**" in text
            return
        b = model.spectrum_in_lab_units(kH=r.kH_at_max, z=r.z_at_max, H1=H1, c_s=c_s)
        assert "the largest growth rate k Im c of every branch is not certified" in text
        assert f"grows at {float(b['growth_rate']):.4g} 1/s (λ = {float(b['wavelength']) * 1e3:.4g} mm" in text
        return
    sign = "≥ " if bool(r.lower_bound) else ""
    if np.isinf(r.kH_at_sigma):
        line = next(s for s in text.split("\n\n") if s.startswith("**Fastest growth of every branch: approached"))
        assert f"growth rate → {sign}{float(r.sigma) * c_s / H1:.4g} 1/s" in line
        assert f"phase speed → {float(r.z_at_sigma.real) * c_s:.4g} m/s, as λ → 0" in line
        if not lab:
            assert int(r.family_sigma) == 3 and "supersonic guided mode" in line and int(r.family_rate) == 2
        return
    peak = model.spectrum_in_lab_units(kH=r.kH_at_sigma, z=r.z_at_sigma, H1=H1, c_s=c_s)
    line = next(s for s in text.split("\n\n") if s.startswith("**Fastest-growing mode of every branch**"))
    assert f"({lb.FAMILY_NAMES[int(r.family_sigma)]}, at kH = {float(r.kH_at_sigma):.4g}; every branch and every kH" \
        in line
    assert f"λ = {float(peak['wavelength']) * 1e3:.4g} mm" in line
    assert f"growth rate {sign}{float(peak['growth_rate']):.4g} 1/s" in line
    assert f"e-folding time {float(peak['e_folding_time']) * 1e3:.4g} ms" in line
    assert f"phase speed {float(peak['phase_speed']):.4g} m/s" in line
    if not lab:
        assert int(r.family_sigma) == 2 and "intersonic guided mode" in line


def test_the_lab_readout_names_a_growth_approached_as_kh_goes_to_infinity() -> None:
    """gamma = 15 (eta = inf): the range's maximum of k Im c (kH ~ 56) lies below its limit as kH -> inf, so the
    panel says the fastest growth is approached as kH -> inf, with the limit's rate in 1/s, not the range's."""
    r = model.sliding_analysis(gamma=15.0, f=0.9, beta=0.3, rate=True)
    d = lb.compute_lab_sliding(15.0, 0.9, 0.3, math.inf, 1.0, 0.0, 0.01, 1000.0)
    (line,) = lb.sliding_lab_lines(d)
    assert line.startswith("**Fastest growth of every branch: approached as kH → ∞** (supersonic guided mode")
    assert f"growth rate → {float(r.rate_limit) * 1000.0 / 0.01:.4g} 1/s" in line
    assert float(r.rate) < float(r.rate_limit) and "at kH =" not in line


def test_the_sliders_point_in_lab_units() -> None:
    """Where the sliders differ from the lab values (a slider moved, a click on the stability map), the panel also
    reads the sliders' point in lab units: with the lab's H₁ and c_s, and the a, b, D_c, H₂ that
    model.rate_state_parameters gives for it."""
    app = build_app({})
    scene = app.lab
    scene.params.link = True
    assert scene.point_readout() == ""  # matched: the lab readout is the current point's
    map_plot.on_tap(app.map, "Δ-ξ", 0.5, 2.0)  # a click on the stability map moves Δ and ξ
    args = app.spectrum_params.model_args()
    assert args[4:] == (0.5, 2.0)
    gamma, f, beta, eta, Delta, xi = args
    k, z = model.fastest_growing_mode(KH, gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    peak = model.spectrum_in_lab_units(kH=k, z=z, H1=0.01, c_s=PMMA.c_s)
    r = model.rate_state_parameters(gamma=gamma, Delta=Delta, xi=xi, eta=eta, rho=PMMA.rho, c_s=PMMA.c_s,
                                    sigma0=4.5e6, H1=0.01, v=scene.params.v)
    text = scene.point_readout()
    assert f"fastest-growing λ = {float(peak['wavelength']) * 1e3:.4g} mm" in text
    assert f"e-folding time {float(peak['e_folding_time']) * 1e3:.4g} ms" in text
    assert f"a = {float(r['a']):.4g}, b = {float(r['b']):.4g}, D_c = {float(r['D_c']) * 1e6:.4g} µm, H₂ = ∞" in text
    assert calls["rate_state_parameters"] == 1


def test_derived_values_are_shown() -> None:
    scene = LabScene()
    d = _expected(scene.params)
    text = scene.derived_view()
    assert f"γ = {d['gamma']:.4g}" in text and f"β = {d['beta']:.4g}" in text and "η = ∞" in text
    assert "does not enter at Δ = 1" in text


def test_e_folding_time_axis_shares_the_growth_rate_range() -> None:
    """The right axis is the plot's own y range with tick labels 1000/rate (ms); it is added once."""
    from bokeh.document import Document
    from bokeh.models import CustomJSTickFormatter

    scene = LabScene()
    plot = hv.renderer("bokeh").get_plot(scene.plot_dmap, doc=Document())
    for v in (0.1, 0.2):
        scene.params.v = v
    fig = plot.state
    axes = [a for a in fig.right if getattr(a, "name", None) == E_FOLDING_AXIS]
    assert len(axes) == 1
    (axis,) = axes
    assert axis.y_range_name == "default" and "ms" in axis.axis_label
    assert isinstance(axis.formatter, CustomJSTickFormatter) and "1000 / tick" in axis.formatter.code
    assert type(fig.x_scale).__name__ == "LogScale" and fig.xaxis[0].axis_label == "λ [mm]"


def _model_rates(p: LabParams) -> tuple[np.ndarray, np.ndarray, float]:
    """λ [mm] and growth rate k Im c [1/s] of the lab setting `p` on :data:`KH`, and its peak growth rate, from
    the model directly."""
    d = _expected(p)
    args = {k: d[k] for k in SpectrumParams.MODEL_ARGS}
    H1, c_s = p.H1_mm * 1e-3, p.c_s
    lab_units = model.spectrum_in_lab_units(kH=KH, z=model.spectrum(KH, **args), H1=H1, c_s=c_s)
    k, z = model.fastest_growing_mode(KH, **args)
    peak = float(model.spectrum_in_lab_units(kH=k, z=z, H1=H1, c_s=c_s)["growth_rate"])
    return lab_units["wavelength"] * 1e3, lab_units["growth_rate"], peak


def test_the_lab_plots_y_range_follows_the_shown_curve() -> None:
    """A stable setting shown after an unstable one kept the unstable one's y range of about ±1000 1/s (a DynamicMap
    keeps a plot option that a later frame leaves out), and its curve, decaying at up to millions per second, was
    nearly all off the plot. The y range follows the shown curve, with zero; while a mode grows, the growing part
    fills it (the short wavelengths' decay is cut)."""
    scene = LabScene()  # PMMA's defaults: a Rayleigh-branch mode grows
    fig = hv.render(scene.plot_dmap, backend="bokeh")
    assert fig.left[0].axis_label == "growth rate k Im c [1/s]" and fig.xaxis[0].axis_label == "λ [mm]"

    def assert_shows_the_growing_part() -> None:
        _, _, peak = _model_rates(scene.params)
        assert peak > 0
        y0, y1 = fig.y_range.start, fig.y_range.end
        assert y0 < 0 < peak < y1 and y1 - y0 < 3 * peak

    assert_shows_the_growing_part()
    scene.params.f = 0.3  # stable: every mode decays
    lam, rate, peak = _model_rates(scene.params)
    assert peak < 0 and np.nanmax(rate) < 0
    y0, y1 = fig.y_range.start, fig.y_range.end
    assert y0 <= np.nanmin(rate) and y1 >= 0  # the whole curve and zero
    assert -np.nanmin(rate) >= 0.7 * (y1 - y0)  # the curve fills the plot (room above it for the legend)
    assert fig.x_range.start <= lam.min() * (1 + 1e-9) and fig.x_range.end >= lam.max() * (1 - 1e-9)
    scene.params.f = 0.9  # unstable again
    assert_shows_the_growing_part()


def test_panel_is_built_when_opened_and_shared_by_both_scenes() -> None:
    app = build_app({})
    assert app.spectrum.lab is app.map.lab is app.lab
    card = app.lab.panel()
    assert card.collapsed and card.objects == []  # built when first opened
    card.collapsed = False
    texts = " ".join(str(getattr(o, "object", "")) for o in card.select(pn.pane.Markdown))
    assert "Assumption: rate-and-state friction" in texts and "Dieterich–Ruina" in texts
    assert any(isinstance(o, pn.pane.HoloViews) for o in card.objects)
    map_card = app.lab.panel(with_plot=False)
    map_card.collapsed = False
    assert not any(isinstance(o, pn.pane.HoloViews) for o in map_card.objects)
    # the Stability-map scene shows the panel above its map
    map_panel = app.map.__panel__()
    assert any(isinstance(o, pn.Card) and o.title.startswith("Lab units") for o in map_panel.select(pn.Card))


# --------------------------------------------------------------------------------------------
# URL
# --------------------------------------------------------------------------------------------


def test_url_round_trip_of_the_lab_keys() -> None:
    query = ("material=Homalite-100&plane=stress&H1=25&H2=60&lab_sigma0=2.5&lab_f=0.55&a=0.012&b=0.003&Dc=3&v=0.04"
             "&lab_rho=1250&lab=1&tab=map")
    app = build_app(urllib.parse.parse_qs(query))
    p = app.lab_params
    assert not app.messages.visible
    assert (p.material, p.plane, p.H1_mm, p.H2_mm, p.H2_infinite, p.sigma0_MPa, p.f, p.a, p.b, p.D_c_um, p.v,
            p.link) == (CUSTOM, "stress", 25.0, 60.0, False, 2.5, 0.55, 0.012, 0.003, 3.0, 0.04, True)
    assert (p.rho, p.c_s, p.c_d) == (1250.0, 1200.0, 2498.0)  # Homalite's speeds, the density given
    written = query_string(app.param_objects(), "map")
    again = build_app(urllib.parse.parse_qs(written[1:]))
    for name in LabParams.param:
        if name != "name":
            assert getattr(again.lab_params, name) == getattr(p, name), name
    assert "lab=1" in written and "H2=60" in written and "material=custom" in written


def test_url_holds_only_changed_lab_values_and_inf_heights() -> None:
    app = build_app({})
    written = urllib.parse.parse_qs(query_string(app.param_objects(), "spectrum")[1:])
    assert not {"material", "H1", "H2", "v", "lab", "lab_rho"} & set(written)
    app.lab_params.H2_infinite = False
    app.lab_params.H2_mm = 40.0
    written = urllib.parse.parse_qs(query_string(app.param_objects(), "spectrum")[1:])
    assert written["H2"] == ["40"]
    app.lab_params.H2_infinite = True
    written = urllib.parse.parse_qs(query_string(app.param_objects(), "spectrum")[1:])
    assert written["H2"] == ["inf"]  # H2 = 40 is kept, but the half-space is what is shown
    updates, _, messages = parse_query({"H2": ["inf"], "lab": ["maybe"]})
    assert updates["lab"] == {"H2_infinite": True}
    assert messages == ["Sliders follow the lab values = 'maybe' is not 1 or 0: ignored."]


def test_a_shared_link_shows_its_sliders_even_where_they_differ_from_the_lab_values() -> None:
    """Loading a URL never moves the sliders: a link shared after a slider was moved by hand shows that slider and
    the panel says it differs (and the panel is open, since the link is on)."""
    app = build_app({"lab": ["1"], "gamma": ["4"], "beta": ["0.498148"]})
    assert app.spectrum_params.gamma == 4.0
    st = app.lab.state()
    assert [m.split(" =")[0] for m in st.mismatches] == ["γ"]
    assert not app.lab.panel().collapsed
    app.lab_params.v = 0.1  # a lab change applies again
    assert app.lab.state().matches


# --------------------------------------------------------------------------------------------
# browser
# --------------------------------------------------------------------------------------------

_SLIDER_VALUE_JS = """(title) => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.title === title && m.start !== undefined && m.end !== undefined) return m.value;
  }
  return null;
}"""

_SET_INPUT_JS = """([title, value]) => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.title === title && m.low !== undefined && m.start === undefined) { m.value = value; return true; }
  }
  return false;
}"""

_FIGURES_JS = ("() => Array.from(Bokeh.documents[0].all_models)"
               ".filter(m => m.title && m.title.text && m.x_range).map(m => m.title.text)")


@pytest.mark.ui
@pytest.mark.slow
def test_lab_panel_moves_the_gamma_slider(served_app: str, browser_page) -> None:
    page = browser_page
    page.set_viewport_size({"width": 1280, "height": 1900})  # the screenshot shows the panel down to its plot
    open_app(page, served_app)
    page.get_by_text("Lab units:").first.click()  # open the panel
    link = page.get_by_text("Sliders follow the lab values").first  # Bokeh's label, next to its checkbox
    link.wait_for(state="visible", timeout=30_000)
    link.evaluate("label => label.previousElementSibling.click()")  # tick the link
    page.wait_for_function(f"() => Math.abs(({_SLIDER_VALUE_JS})('γ') - 3) < 1e-3 "
                           f"&& Math.abs(({_SLIDER_VALUE_JS})('β') - 0.49815) < 1e-4", timeout=30_000)
    assert page.evaluate(_SET_INPUT_JS, ["v [m/s]", 0.17012])
    page.wait_for_function(f"() => Math.abs(({_SLIDER_VALUE_JS})('γ') - 6) < 1e-3", timeout=30_000)
    expected = float(model.dimensionless_parameters(**PMMA.elastic_constants(), sigma0=4.5e6, f=0.9, H1=0.01,
                                                    H2=math.inf, v=0.17012, a=0.01, b=0.0, D_c=1e-6)["gamma"])
    assert page.evaluate(_SLIDER_VALUE_JS, "γ") == pytest.approx(expected, rel=1e-12)
    page.get_by_text("The sliders follow the lab values").first.wait_for(state="visible", timeout=30_000)
    page.get_by_text("Fastest-growing mode").first.wait_for(state="visible", timeout=30_000)
    page.wait_for_function(f"() => ({_FIGURES_JS})().includes('Growth rate vs wavelength (lab values)')",
                           timeout=60_000)
    page.wait_for_function("() => window.location.search.includes('lab=1')", timeout=30_000)
    save_screenshot(page, "screenshot_lab.png")
    assert page.console_errors == []
