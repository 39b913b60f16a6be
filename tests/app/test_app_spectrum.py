"""The "Spectrum" scene: the param graph, caching, the plotted data and the widgets (headless),
plus one real-browser test that a slider updates the plot in place."""

from __future__ import annotations

import math

import holoviews as hv
import numpy as np
import panel as pn
import param
import pytest

from asymslide import model
from asymslide.app import spectrum as sp
from asymslide.app.params import SpectrumParams
from asymslide.app.spectrum import KH, SpectrumScene
from tests.conftest import open_app, set_slider
from tests.support.spies import Calls, spying

pytestmark = pytest.mark.usefixtures("fresh_caches")

#: the scene's cache misses and model calls in the current test (tests/support/spies.py)
calls = Calls()


_spies = spying((sp, calls))


def _render_all(scene: SpectrumScene) -> None:
    """Evaluate every view the page shows (both DynamicMaps and the readout)."""
    scene.im_dmap[()]
    scene.re_dmap[()]
    scene.readout()


def _curve(overlay: hv.Overlay, label: str, ylabel: str) -> hv.Curve:
    (curve,) = [el for el in overlay if isinstance(el, hv.Curve) and el.label == label]
    assert curve.vdims[0].name == ylabel
    return curve


# --------------------------------------------------------------------------------------------
# the param graph and the cache
# --------------------------------------------------------------------------------------------


def test_changing_gamma_recomputes_exactly_once() -> None:
    scene = SpectrumScene()
    _render_all(scene)
    assert calls["compute_spectrum"] == 1
    assert calls["rayleigh_branch"] == 1
    scene.params.gamma = 5.0
    _render_all(scene)
    assert calls["compute_spectrum"] == 2
    assert calls["rayleigh_branch"] == 2
    assert calls["growth_analysis"] == 2


def test_xi_is_ignored_when_delta_is_one() -> None:
    scene = SpectrumScene()
    _render_all(scene)
    inputs = scene.inputs
    fired = []
    scene.param.watch(fired.append, "inputs")
    scene.params.xi = 3.0
    _render_all(scene)
    assert scene.inputs == inputs and fired == []
    assert calls["compute_spectrum"] == 1
    scene.params.Delta = 0.5  # now xi matters
    _render_all(scene)
    assert calls["compute_spectrum"] == 2
    assert scene.inputs[-2:] == (0.5, 3.0)
    scene.params.xi = 4.0
    _render_all(scene)
    assert calls["compute_spectrum"] == 3


def test_eta_infinite_and_finite_eta_are_distinct_keys() -> None:
    p = SpectrumParams(eta_infinite=True, log10_eta=8)
    assert p.eta == math.inf
    args_inf = p.model_args()
    p.eta_infinite = False
    assert p.eta == 1e8
    args_fin = p.model_args()
    assert args_inf != args_fin
    sp.compute_spectrum(*args_inf)
    sp.compute_spectrum(*args_fin)
    assert calls["compute_spectrum"] == 2
    sp.compute_spectrum(*args_inf)
    assert calls["compute_spectrum"] == 2


def test_linear_expansion_only_when_delta_is_one() -> None:
    d1 = sp.compute_spectrum(3.0, 0.9, 0.3, math.inf, 1.0, 0.0)
    np.testing.assert_array_equal(d1["linear"], model.linear_expansion(KH, gamma=3.0, f=0.9, beta=0.3))
    d2 = sp.compute_spectrum(3.0, 0.9, 0.3, math.inf, 0.5, 1.0)
    assert np.all(np.isnan(d2["linear"]))
    assert calls["linear_expansion"] == 1


# --------------------------------------------------------------------------------------------
# the plotted data is the model's
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "p",
    [
        dict(gamma=3.0, f=0.9, beta=0.3, eta_infinite=True, Delta=1.0, xi=0.0),
        dict(gamma=1.5, f=0.6, beta=0.5, eta_infinite=False, log10_eta=2.0, Delta=0.4, xi=2.0),
    ],
)
def test_plotted_curves_equal_model_spectrum(p: dict) -> None:
    scene = SpectrumScene(params=SpectrumParams(**p))
    eta = math.inf if p["eta_infinite"] else 10.0 ** p["log10_eta"]
    z = model.spectrum(KH, gamma=p["gamma"], f=p["f"], beta=p["beta"], eta=eta, Delta=p["Delta"], xi=p["xi"])
    im = _curve(scene.im_dmap[()], "Rayleigh branch", "Im[c/c_s]")
    re = _curve(scene.re_dmap[()], "Rayleigh branch", "Re[c/c_s]")
    np.testing.assert_array_equal(im.dimension_values("kH"), KH)
    np.testing.assert_array_equal(im.dimension_values("Im[c/c_s]"), z.imag)
    np.testing.assert_array_equal(re.dimension_values("Re[c/c_s]"), z.real)
    assert im.kdims[0].name == "kH"


def test_bokeh_plot_has_log_x_axis_and_labels() -> None:
    scene = SpectrumScene()
    fig = hv.render(scene.im_dmap, backend="bokeh")
    assert type(fig.x_scale).__name__ == "LogScale"
    assert fig.xaxis[0].axis_label == "kH"
    assert fig.yaxis[0].axis_label == "Im[c/c_s]"


def test_unstable_band_and_readout() -> None:
    scene = SpectrumScene()
    g = model.growth_analysis(KH, gamma=3.0, f=0.9, beta=0.3)
    (spans,) = [el for el in scene.im_dmap[()] if isinstance(el, hv.VSpans)]
    np.testing.assert_allclose(spans.array()[0], [g.kH_min, g.kH_max])
    text = scene.readout()
    assert f"{float(g.growth):.4g}" in text and "Masked** none" in text
    scene.params.gamma = 0.1  # stable at these parameters
    if not float(model.growth_analysis(KH, gamma=0.1, f=0.9, beta=0.3).growth) > 0:
        (spans,) = [el for el in scene.im_dmap[()] if isinstance(el, hv.VSpans)]
        assert len(spans) == 0


# --------------------------------------------------------------------------------------------
# the widgets
# --------------------------------------------------------------------------------------------


def _release(slider, value: float) -> None:
    """What the browser does when a slider handle is released (value_throttled is read-only in Python)."""
    with param.edit_constant(slider):
        slider.value = value
        slider.value_throttled = value


def test_a_held_slider_stays_held_while_a_second_set_of_sliders_bound_to_the_same_parameters_follows_it() -> None:
    """The Spectrum and Stability map tabs show two slider sets of one SpectrumParams. Moving a handle of one set
    writes each value into the other set's slider (value and value_throttled at once: set, not dragged); that echo
    is not a release: `dragging` stays True at every move until the held slider is released (before, it flipped
    at every move and the map started a full computation per move)."""
    p = SpectrumParams()
    held, mirror = p.make_widgets(), p.make_widgets()
    seen: list[bool] = []
    p.param.watch(lambda e: seen.append(e.new), "dragging")
    for g in (6.0, 6.5, 7.0):
        held["gamma"].value = g
        assert p.gamma == g and p.dragging
        assert mirror["gamma"].value == g and mirror["gamma"].value_throttled == g
    _release(held["gamma"], 7.0)
    assert not p.dragging
    assert seen == [True, False]


def test_widget_labels_are_the_papers_symbols() -> None:
    w = SpectrumParams().make_widgets()
    labels = [w[n].label for n in ("gamma", "f", "beta", "log10_eta", "Delta", "xi")]
    assert labels == ["γ", "f", "β", "η", "Δ", "ξ"]
    assert w["eta_infinite"].label == "η = ∞"


def test_a_held_slider_moves_its_parameter_and_says_it_is_held_and_xi_is_disabled_when_delta_is_one() -> None:
    """The plots follow a dragged handle, so the parameter follows `value`; `dragging` is True until the release
    (`value_throttled`), and a value set by the program (URL, preset) is never taken for a held slider."""
    p = SpectrumParams()
    w = p.make_widgets()
    assert w["xi"].disabled and w["log10_eta"].disabled
    w["gamma"].value = 7.0  # the handle moves, not released
    assert p.gamma == 7.0 and p.dragging
    w["gamma"].value = 6.5
    assert p.gamma == 6.5 and p.dragging
    _release(w["gamma"], 7.0)
    assert p.gamma == 7.0 and not p.dragging
    p.gamma = 4.0  # set by the program: shown, not held
    assert w["gamma"].value == 4.0 and w["gamma"].value_throttled == 4.0 and not p.dragging
    _release(w["f"], 0.8999999999999999)  # what a slider sends for 0.9 (its steps are added in binary)
    assert p.f == 0.9 and repr(p.model_args()[1]) == "0.9"  # the CSV headers read f = 0.9
    _release(w["Delta"], 0.5)
    assert p.Delta == 0.5 and not w["xi"].disabled
    w["eta_infinite"].checked = False
    assert not p.eta_infinite and not w["log10_eta"].disabled
    p.beta = 0.4  # programmatic changes show in the widget
    assert w["beta"].value == 0.4


def test_app_builds_with_spectrum_tab() -> None:
    from asymslide.app.main import create_app

    template = create_app()
    tabs = [obj for obj in template.main.objects if isinstance(obj, pn.Tabs)]
    assert tabs and tabs[0]._names[0] == "Spectrum"


# --------------------------------------------------------------------------------------------
# browser
# --------------------------------------------------------------------------------------------

_IM_SOURCE_JS = """() => {
  const doc = Bokeh.documents[0];
  for (const m of doc.all_models) {
    if (m.type === 'ColumnDataSource' || (m.constructor && m.constructor.__name__ === 'ColumnDataSource')) {
      const cols = Object.keys(m.data ?? {});
      if (cols.some(c => c.startsWith('Im')) && m.data.kH !== undefined) {
        const y = m.data[cols.find(c => c.startsWith('Im'))];
        const arr = Array.from(y);
        if (arr.some(v => Number.isFinite(v) && v !== 0)) return arr.map(v => Number.isFinite(v) ? v : null);
      }
    }
  }
  return null;
}"""

@pytest.mark.ui
@pytest.mark.slow
def test_gamma_slider_updates_the_im_curve(served_app: str, browser_page) -> None:
    page = browser_page
    open_app(page, served_app)
    page.wait_for_function(_IM_SOURCE_JS, timeout=30_000)
    before = page.evaluate(_IM_SOURCE_JS)
    expected = model.spectrum(KH, gamma=3.0, f=0.9, beta=0.3).imag
    np.testing.assert_allclose(np.array(before, dtype=float), expected, rtol=1e-12, atol=0)
    assert set_slider(page, "γ", 6.0)
    changed = f"() => {{ const y = ({_IM_SOURCE_JS})(); return y !== null && y[200] !== {before[200]!r}; }}"
    page.wait_for_function(changed, timeout=30_000)
    after = np.array(page.evaluate(_IM_SOURCE_JS), dtype=float)
    np.testing.assert_allclose(after, model.spectrum(KH, gamma=6.0, f=0.9, beta=0.3).imag, rtol=1e-12, atol=0)
    assert page.console_errors == []


def test_zero_line_is_drawn_once_and_survives_updates() -> None:
    """The y = 0 line of the growth-rate plot is a Bokeh Span added by a hook, once, also after updates."""
    from bokeh.document import Document

    from asymslide.app.plotting import ZERO_LINE

    scene = SpectrumScene()
    plot = hv.renderer("bokeh").get_plot(scene.im_dmap, doc=Document())
    for gamma in (2.0, 5.0):
        scene.params.gamma = gamma
    spans = [r for r in plot.state.center if getattr(r, "name", None) == ZERO_LINE]
    assert len(spans) == 1 and spans[0].location == 0


def test_gy_curve_element_is_reused_while_beta_and_eta_are_unchanged() -> None:
    """γ and f move only the criterion line: the G_y curve element is the same object (HoloViews then does
    not re-send its data); a change of β gives a new curve."""
    scene = SpectrumScene()

    def curve():
        (c,) = [e for e in scene.gy_dmap[()] if isinstance(e, hv.Curve)]
        return c

    first = curve()
    scene.params.gamma = 5.0
    scene.params.f = 0.5
    assert curve() is first
    scene.params.beta = 0.5
    assert curve() is not first


def test_plots_are_rendered_at_once_outside_a_server_session() -> None:
    """Outside a served session (scripts, notebooks, these tests) the three plots are in the panel at once;
    served, they are rendered after the page has loaded (the load test and the browser tests see them)."""
    scene = SpectrumScene()
    panes = [p for p in scene.__panel__().select(pn.pane.HoloViews)]
    assert [p.object for p in panes] == [scene.im_dmap, scene.re_dmap, scene.gy_dmap]


def test_the_legend_lists_the_unstable_band_only_when_there_is_one() -> None:
    """The legend lists "unstable band" only where there is one (it once did at stable parameters too)."""
    from bokeh.document import Document

    scene = SpectrumScene()
    plot = hv.renderer("bokeh").get_plot(scene.im_dmap, doc=Document())

    def band_item_visible() -> bool:
        (item,) = [i for legend in plot.state.legend for i in legend.items if i.label.value == "unstable band"]
        return item.visible

    assert np.isfinite(scene.data()["kH_min"]) and band_item_visible()  # the paper's defaults: unstable
    scene.params.gamma = 1.0  # below the threshold 2.41: stable, no band
    assert not np.isfinite(scene.data()["kH_min"]) and not band_item_visible()
    scene.params.gamma = 5.0
    assert band_item_visible()


def test_a_maximum_at_the_end_of_the_kh_range_is_not_called_a_maximum() -> None:
    """The largest growth at the edge of the kH grid is not called a maximum (it once read "Max growth ... at kH =
    0.001", the grid's edge)."""
    scene = SpectrumScene(params=SpectrumParams(gamma=1.0, eta_infinite=False, log10_eta=1.0))
    d = scene.data()
    assert d["kH_at_max"] == pytest.approx(sp.KH[0])  # stable (η = 10): Im z largest at the smallest kH computed
    text = scene.readout()
    assert "**Largest growth on the range, Rayleigh branch**" in text and "not a maximum" in text
    assert "**Max growth" not in text
    assert "**Max growth, Rayleigh branch**" in SpectrumScene().readout()


# --------------------------------------------------------------------------------------------
# sliding over every branch beside the Rayleigh branch
# --------------------------------------------------------------------------------------------


def test_the_fastest_root_of_every_branch_is_drawn_and_read_out_as_the_model_gives_it() -> None:
    scene = SpectrumScene(params=SpectrumParams(gamma=2.0))
    scene.wait_sliding()
    d = scene.sliding
    r = model.sliding_analysis(gamma=2.0, f=0.9, beta=0.3)
    assert d["max"] == float(r.growth) and d["kH_at_max"] == float(r.kH_at_max)
    assert int(r.rayleigh.verdict) == 0 and int(r.verdict) == 1  # the Rayleigh branch stable, sliding not
    m = model.fastest_mode(sp.KH_ALL, gamma=2.0, f=0.9, beta=0.3, count=False)
    ok = m.status == 0
    np.testing.assert_array_equal(d["growth"][ok], m.growth[ok])
    np.testing.assert_array_equal(d["family"][ok], m.family[ok])
    assert np.isnan(d["growth"][~ok]).all()
    text = scene.readout()
    assert "**Rayleigh branch stable**" in text and "**Sliding unstable**" in text
    assert "intersonic guided mode" in text and f"{float(r.growth):.4g}" in text
    overlay = scene.im_dmap[()]
    (star,) = [e for e in overlay if e.label == "max growth, every branch (sliding)"]
    assert star.dimension_values(1).tolist() == [float(r.growth)]
    (points,) = [e for e in overlay if e.label == "fastest root: intersonic guided mode"]
    assert len(points) == int(((d["family"] == 2) & ok).sum()) > 0
    assert "Sliding unstable" in scene.csv_growth().getvalue().splitlines()[0]


@pytest.mark.usefixtures("worker_pool")
def test_sliding_computed_in_the_worker_process_is_the_same_as_here() -> None:
    """Served sessions compute sliding over every branch in the worker process (app.jobs.Job.call): the same
    numbers, bit for bit, as computed in the job's own thread."""
    from asymslide.app import jobs

    args = SpectrumParams(gamma=2.0).model_args()
    results = []
    for in_process in (True, False):
        job = jobs.Job(lambda job, p=in_process: sp.compute_sliding(args, job, in_process=p), name="sliding").start()
        state = job.wait(300)
        assert state.status == jobs.DONE, state.error
        results.append(state.result)
    there, here = results
    assert set(there) == set(here)
    for name, value in here.items():
        if isinstance(value, np.ndarray):
            np.testing.assert_array_equal(there[name], value)
        else:
            assert there[name] == value or (value != value and there[name] != there[name]), name


def test_new_inputs_cancel_the_sliding_job_and_a_set_seen_before_shows_at_once() -> None:
    scene = SpectrumScene()
    first = scene.sliding_job.job
    scene.params.gamma = 5.0
    assert first is not None and first.cancelled and scene.sliding is None  # never shown for gamma = 5
    scene.wait_sliding()
    assert scene.sliding["max"] == float(model.sliding_analysis(gamma=5.0, f=0.9, beta=0.3).growth)
    scene.params.gamma = 3.0
    scene.wait_sliding()
    scene.params.gamma = 5.0  # computed before: shown at once, no job
    assert scene.sliding is not None and scene.sliding["max"] > 0 and "computing" not in scene.readout()


def test_a_stable_set_says_sliding_is_stable_over_every_branch() -> None:
    scene = SpectrumScene(params=SpectrumParams(gamma=1.0))
    scene.wait_sliding()
    text = scene.readout()
    assert "**Sliding stable** (every branch, Im z ≥ 1e-06, kH 0.01 to 100)" in text
    assert "**Rayleigh branch stable**" in text


# --------------------------------------------------------------------------------------------
# a held slider: the plots follow the hand
# --------------------------------------------------------------------------------------------


def _rendered_scene() -> tuple[SpectrumScene, list]:
    """A scene whose three plots are rendered into a Bokeh document, and their HoloViews plots."""
    from bokeh.document import Document

    scene = SpectrumScene()
    doc = Document()
    panes = [scene.plot_pane(i) for i in range(3)]
    for pane in panes:
        pane.get_root(doc)
    return scene, [next(iter(pane._plots.values()))[0] for pane in panes]


def _source(plot, label: str) -> dict[str, np.ndarray]:
    """The data of the layer `label` of a rendered overlay, as the page has it."""
    (sub,) = [s for s in plot.subplots.values() if getattr(s.current_frame, "label", None) == label]
    return {k: np.asarray(v) for k, v in sub.handles["source"].data.items()}


def test_a_held_slider_moves_the_curves_on_the_page_without_a_holoviews_redraw() -> None:
    """While γ is held the growth-rate, phase-velocity and G_y plots on the page show the model at every position of
    the handle (written into their sources, app.live), the markers of every branch are emptied (they belong to the
    previous γ), the readout follows, and sliding over every branch is not computed; the release lets HoloViews
    redraw once and starts that job."""
    scene, (im, re, gy) = _rendered_scene()
    before = scene.inputs
    jobs_before = calls["compute_sliding"]
    for gamma in (4.0, 5.5, 7.25):
        scene.params.param.update(dragging=True, gamma=gamma)
        z = model.spectrum(KH, gamma=gamma, f=0.9, beta=0.3)
        np.testing.assert_allclose(_source(im, "Rayleigh branch")["Im[c/c_s]"], z.imag, rtol=1e-12, atol=0)
        np.testing.assert_allclose(_source(re, "Rayleigh branch")["Re[c/c_s]"], z.real, rtol=1e-12, atol=0)
        assert _source(im, "fastest root, every branch")["kH"].size == 0
        lo, hi = im.state.y_range.start, im.state.y_range.end
        assert lo <= np.nanmin(z.imag) and np.nanmax(z.imag) <= hi  # the y range follows the curve
        assert scene.inputs == before  # HoloViews has not redrawn
        text = scene.readout()
        growth = model.growth_analysis(KH, gamma=gamma, f=0.9, beta=0.3)
        assert f"kH = {sp.fmt(float(growth.kH_at_max))}" in text and "computed when the slider is released" in text
    assert calls["compute_sliding"] == jobs_before
    scene.params.dragging = False  # the release
    assert scene.inputs == scene.params.model_args() and scene.shown == scene.inputs
    scene.wait_sliding()
    assert scene.sliding is not None and "computed when the slider is released" not in scene.readout()
    level = float(model.criterion_gy_level(gamma=7.25, f=0.9, beta=0.3))
    (line,) = [s for s in gy.subplots.values() if getattr(s.current_frame, "label", "").startswith("criterion")]
    assert line.handles["glyph"].location == pytest.approx(level, rel=1e-12)


def _band_item_visible(plot) -> bool:
    (item,) = [i for legend in plot.state.legend for i in legend.items if i.label.value == "unstable band"]
    return bool(item.visible)


@pytest.mark.parametrize("gamma", [1.0, 7.25, None])
def test_a_release_where_the_plots_already_show_the_held_values_needs_no_redraw(gamma: float | None) -> None:
    """At the release of a held slider whose last position the page already shows (written by app.live with the
    plots' hooks run), HoloViews does not redraw the curves (~0.3 s of server time a release): the page keeps the
    model's curves of the released values, the legend lists the unstable band only when there is one (γ = 1 is
    below the threshold 2.41: no band), and the markers of every branch, emptied while held, come back with the
    sliding job's result, without the curves going back to the previous values. None: released where the drag
    began (the sliding result shown before the drag is the one shown after it)."""
    scene, (im, re, gy) = _rendered_scene()
    scene.wait_sliding()
    gamma = scene.params.gamma if gamma is None else gamma
    drawn, markers_drawn = scene.drawn, scene.sliding_drawn
    for g in (4.0, gamma):
        scene.params.param.update(dragging=True, gamma=g)
        band = model.growth_analysis(KH, gamma=g, f=0.9, beta=0.3)
        assert _band_item_visible(im) == bool(np.isfinite(band.kH_min))  # the legend follows while held
    scene.params.dragging = False  # the release, at the last held position
    assert scene.drawn == drawn and scene.inputs == scene.shown == scene.params.model_args()
    scene.wait_sliding()
    assert "computed when the slider is released" not in scene.readout()
    z = model.spectrum(KH, gamma=gamma, f=0.9, beta=0.3)
    np.testing.assert_allclose(_source(im, "Rayleigh branch")["Im[c/c_s]"], z.imag, rtol=1e-12, atol=0)
    np.testing.assert_allclose(_source(re, "Rayleigh branch")["Re[c/c_s]"], z.real, rtol=1e-12, atol=0)
    band = model.growth_analysis(KH, gamma=gamma, f=0.9, beta=0.3)
    assert _band_item_visible(im) == bool(np.isfinite(band.kH_min))
    markers = _source(im, "fastest root, every branch")
    assert markers["kH"].size == sp.KH_ALL.size
    assert scene.sliding_drawn == markers_drawn  # written into the page, not redrawn by HoloViews
    for k in model.FAMILIES:  # each family's markers as the model's fastest roots give them
        sel = scene.sliding["family"] == k
        np.testing.assert_array_equal(_source(im, f"fastest root: {sp.FAMILY_NAMES[k]}")["kH"], sp.KH_ALL[sel])
    np.testing.assert_array_equal(markers["Im[c/c_s]"], scene.sliding["growth"])
    lo, hi = im.state.y_range.start, im.state.y_range.end
    shown = np.concatenate([z.imag[np.isfinite(z.imag)], scene.sliding["growth"][np.isfinite(scene.sliding["growth"])]])
    assert lo <= shown.min() and shown.max() <= hi
    level = float(model.criterion_gy_level(gamma=gamma, f=0.9, beta=0.3))
    (line,) = [s for s in gy.subplots.values() if getattr(s.current_frame, "label", "").startswith("criterion")]
    assert line.handles["glyph"].location == pytest.approx(level, rel=1e-12)


def test_a_release_elsewhere_than_the_last_held_position_is_redrawn() -> None:
    """A release at values the page does not show yet (moved by a program while held, or the plots not rendered)
    is drawn by HoloViews as before."""
    scene, (im, _re, _gy) = _rendered_scene()
    drawn = scene.drawn
    scene.params.param.update(dragging=True, gamma=4.0)
    scene.params.param.update(dragging=False, gamma=6.0)  # released elsewhere in one change
    z = model.spectrum(KH, gamma=6.0, f=0.9, beta=0.3)
    np.testing.assert_allclose(_source(im, "Rayleigh branch")["Im[c/c_s]"], z.imag, rtol=1e-12, atol=0)
    scene.params.gamma = 1.0  # then a change without a held slider: HoloViews redraws
    assert scene.drawn > drawn
    assert not _band_item_visible(im)


def test_a_held_slider_with_a_family_of_curves_redraws_through_holoviews() -> None:
    """A preset's family of curves (other γ, Δ or kW) cannot be written by app.live (it would stay at the previous
    inputs): the plots are then redrawn by HoloViews at every position."""
    scene, _ = _rendered_scene()
    scene.param.update(compare_key="Delta", compare_values=[0.5, 0.8])
    scene.params.param.update(dragging=True, gamma=5.0)
    assert scene.inputs == scene.params.model_args()


@pytest.mark.ui
@pytest.mark.slow
def test_a_dragged_gamma_handle_moves_the_plot_with_the_hand(served_app: str, browser_page) -> None:
    """A real mouse drag of the γ handle (30 moves over 1.5 s): the growth-rate curve changes several times before
    the release, and after it shows the model at the slider's final value; the server log stays clean."""
    page = browser_page
    open_app(page, served_app)
    page.wait_for_function(_IM_SOURCE_JS, timeout=30_000)
    page.evaluate("""(js) => { window.__frames = 0; let last = null;
      const poll = () => { const y = eval(js)(); const k = y === null ? null : y[100] + ':' + y[300];
        if (k !== last) { window.__frames += 1; last = k; } setTimeout(poll, 10); }; poll(); }""", _IM_SOURCE_JS)
    slider = page.locator(".bk-input-group", has_text="γ:").first
    handle, track = slider.locator(".noUi-handle").first, slider.locator(".noUi-base").first
    hb, tb = handle.bounding_box(), track.bounding_box()
    x0, y = hb["x"] + hb["width"] / 2, hb["y"] + hb["height"] / 2
    page.mouse.move(x0, y)
    page.mouse.down()
    start = page.evaluate("() => window.__frames")
    for i in range(1, 31):
        page.mouse.move(x0 + (tb["x"] + 0.6 * tb["width"] - x0) * i / 30, y)
        page.wait_for_timeout(50)
    during = page.evaluate("() => window.__frames") - start
    page.mouse.up()
    assert during >= 3, f"{during} new curves during the drag"
    gamma = float(page.locator(".bk-input-group", has_text="γ:").first.locator(".bk-slider-value").inner_text())
    want = model.spectrum(KH, gamma=gamma, f=0.9, beta=0.3).imag
    page.wait_for_function(f"() => {{ const y = ({_IM_SOURCE_JS})(); return y !== null && "
                           f"Math.abs(y[200] - {float(want[200])!r}) < 1e-9 * Math.max(1, Math.abs(y[200])); }}",
                           timeout=30_000)
    np.testing.assert_allclose(np.array(page.evaluate(_IM_SOURCE_JS), dtype=float), want, rtol=1e-9, atol=1e-12)


def test_no_linear_expansion_line_or_legend_entry_where_it_is_not_defined() -> None:
    """At Δ ≠ 1 the linear expansion (defined at Δ = 1 only) was drawn as a dashed line at Im = 0 with its legend
    entry, which reads as neutral growth. Now neither plot draws it or lists it; at Δ = 1 both do."""
    for delta, shown in ((0.5, False), (1.0, True)):
        scene = SpectrumScene(params=SpectrumParams(Delta=delta, xi=1.0))
        for dmap in (scene.im_dmap, scene.re_dmap):
            fig = hv.render(dmap, backend="bokeh")
            (item,) = [i for i in fig.legend[0].items if i.label.value == "linear expansion"]
            data = item.renderers[0].data_source.data
            assert item.visible is shown and (len(data["kH"]) > 0) is shown, (delta, dmap)
    assert np.isnan(sp.compute_spectrum(3.0, 0.9, 0.3, math.inf, 0.5, 1.0)["linear"].imag).all()


def test_a_held_handle_does_not_raise_the_busy_flag_of_every_session_but_its_release_does() -> None:
    """Panel's busy flag is one per process and every session's spinner follows it: the ~20 moves a second of a
    held handle must not set it (each set sent an update to every open session); the release still does."""
    w = SpectrumParams().make_widgets()["gamma"]
    seen: list[bool] = []
    watcher = pn.state.param.watch(lambda e: seen.append(e.new), "busy")
    try:
        w._process_events({"value": 5.0})  # what BokehJS sends while the handle moves
        assert seen == [] and w.value == 5.0
        w._process_events({"value_throttled": 5.0})  # the release
        assert seen == [True, False]
    finally:
        pn.state.param.unwatch(watcher)
