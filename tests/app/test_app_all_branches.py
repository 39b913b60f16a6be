"""The "All branches" scene: the plotted roots, the Rayleigh marker and the count curve are the model's, the
param graph recomputes only what changed, bad window input gives a message, the CSVs hold the plotted data (all
headless), plus one real-browser test of the served tab."""

from __future__ import annotations

import csv
import math

import holoviews as hv
import numpy as np
import panel as pn
import pytest
from bokeh.document import Document
from bokeh.models import ColumnDataSource
from pyviz_comms import Comm

from asymslide import model
from asymslide.app import all_branches as ab
from asymslide.app.all_branches import KH_COUNT, KH_FINE, AllBranchesScene
from asymslide.app.declarations import from_log10
from asymslide.app.params import SpectrumParams
from tests.conftest import open_app, set_slider
from tests.support.spies import Calls, spying

PAPER = dict(gamma=3.0, f=0.9, beta=0.3)  # the defaults of SpectrumParams (eta = inf, Delta = 1)
WINDOW = dict(re_max=5.0, im_min=1e-4, im_max=2.0)  # the scene's default window (the model's defaults)


pytestmark = pytest.mark.usefixtures("fresh_caches")

#: the scene's cache misses and model calls in the current test (tests/support/spies.py)
calls = Calls()


_spies = spying((ab, calls))


def _scene(kH: float = 0.45, **p) -> AllBranchesScene:
    scene = AllBranchesScene(params=SpectrumParams(**p), log10_kH=math.log10(kH))
    assert scene.kH_key == kH  # the rounding of 10**log10(kH) gives kH back
    return scene


def _model_kwargs(scene: AllBranchesScene) -> dict:
    gamma, f, beta, eta, Delta, xi = scene.params.model_args()
    return dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)


def _render_all(scene: AllBranchesScene) -> None:
    """Evaluate every view the tab shows (both DynamicMaps and the readout)."""
    scene.zplane_dmap[()]
    scene.count_dmap[()]
    scene.readout()


def _element(overlay: hv.Overlay, cls: type, label: str):
    (el,) = [el for el in overlay if isinstance(el, cls) and el.label == label]
    return el


def _csv_rows(text: str) -> list[dict]:
    return list(csv.DictReader(line for line in text.splitlines() if not line.startswith("#")))


# --------------------------------------------------------------------------------------------
# the plotted data is the model's
# --------------------------------------------------------------------------------------------

CASES = [
    pytest.param(0.45, dict(), id="paper-defaults"),
    pytest.param(0.77, dict(eta_infinite=False, log10_eta=1.0), id="eta10"),
    pytest.param(2.0, dict(gamma=1.5, f=0.6, beta=0.5, eta_infinite=False, log10_eta=2.0, Delta=0.4, xi=2.0),
                 id="Delta-xi"),
]


@pytest.mark.parametrize(("kH", "p"), CASES)
def test_plotted_roots_and_rayleigh_marker_equal_the_model(kH: float, p: dict) -> None:
    scene = _scene(kH, **p)
    kw = _model_kwargs(scene)
    z = model.unstable_modes(kH, **kw, **WINDOW)
    assert z.size > 0
    overlay = scene.zplane_dmap[()]
    roots = _element(overlay, hv.Scatter, "unstable roots")
    np.testing.assert_array_equal(roots.dimension_values("re"), z.real)
    np.testing.assert_array_equal(roots.dimension_values("im"), z.imag)
    # hover: residual |F|/scale as the model defines it, and an error estimate small against |z|
    resid = np.abs(model.dispersion(z, kH, **kw)) / model.dispersion_scale(z, kH, **kw)
    np.testing.assert_allclose(roots.dimension_values("residual"), resid, rtol=1e-12)
    assert np.all(roots.dimension_values("residual") < 1e-12)
    err = roots.dimension_values("error")
    assert np.all(err > 0) and np.all(err < 1e-10 * np.abs(z))
    rayleigh = _element(overlay, hv.Scatter, "Rayleigh-branch root")
    z_r = complex(model.spectrum(kH, **kw))
    np.testing.assert_array_equal(rayleigh.dimension_values("re"), [z_r.real])
    np.testing.assert_array_equal(rayleigh.dimension_values("im"), [z_r.imag])
    assert rayleigh.dimension_values("rb_error")[0] == float(model.rayleigh_branch(kH, **kw).error)
    bounds = _element(overlay, hv.Bounds, "window")
    assert (bounds.range(0), bounds.range(1)) == ((-5.0, 5.0), (1e-4, 2.0))
    assert set(_element(overlay, hv.VLines, "Re z = ±1/β (c_d)").data["x"]) == {-1 / kw["beta"], 1 / kw["beta"]}


def test_stable_rayleigh_root_is_shown_below_the_window_and_said_so() -> None:
    scene = _scene(5.0)  # paper defaults: the Rayleigh branch is stable at kH = 5 and nothing else is unstable
    z_r = complex(model.spectrum(5.0, **PAPER))
    assert z_r.imag < 0 and model.unstable_count(5.0, **PAPER) == 0
    overlay = scene.zplane_dmap[()]
    assert len(_element(overlay, hv.Scatter, "unstable roots")) == 0
    np.testing.assert_array_equal(_element(overlay, hv.Scatter, "Rayleigh-branch root").dimension_values("im"),
                                  [z_r.imag])
    fig = hv.render(scene.zplane_dmap, backend="bokeh")
    assert fig.y_range.start < z_r.imag < 0 < fig.y_range.end  # in view although outside the window
    text = scene.readout()
    assert "**Unstable roots** 0" in text and "stable (Im z ≤ 0)" in text


def test_count_curve_equals_unstable_count_on_the_grid() -> None:
    scene = _scene(0.45)
    overlay = scene.count_dmap[()]
    expected = np.array([model.unstable_count(float(k), **PAPER, **WINDOW) for k in KH_COUNT], float)
    total = _element(overlay, hv.Curve, "all roots in window")
    np.testing.assert_array_equal(total.dimension_values("kH"), KH_COUNT)
    np.testing.assert_array_equal(total.dimension_values("count"), expected)
    assert expected.max() > 1  # the curve is not trivial at these parameters
    # other branches = all minus the Rayleigh root where it lies in the window (Rayleigh root from the model)
    z_r = model.spectrum(KH_COUNT, **PAPER)
    in_window = (np.abs(z_r.real) <= 5.0) & (z_r.imag >= 1e-4) & (z_r.imag <= 2.0)
    other = _element(overlay, hv.Curve, "other branches (all − Rayleigh)")
    np.testing.assert_array_equal(other.dimension_values("count"), expected - in_window)
    assert np.all(other.dimension_values("count") >= 0)
    # shaded bands: exactly the fine-grid points where the model's Rayleigh branch has Im z > 0
    unstable = model.spectrum(KH_FINE, **PAPER).imag > 0
    bands = _element(overlay, hv.VSpans, "Rayleigh branch unstable").array()
    covered = np.zeros(KH_FINE.shape, bool)
    for a, b in bands:
        covered |= (KH_FINE >= a) & (KH_FINE <= b)
    np.testing.assert_array_equal(covered, unstable)
    assert len(bands) >= 1
    # the marker at the current kH is the certified count there
    marker = _element(overlay, hv.Scatter, "current kH")
    assert marker.dimension_values("kH")[0] == 0.45
    assert marker.dimension_values("count")[0] == model.unstable_count(0.45, **PAPER, **WINDOW) == 2


# --------------------------------------------------------------------------------------------
# reference cases of docs/physics.md §3: unstable roots off the Rayleigh branch
# --------------------------------------------------------------------------------------------


def test_eta3_backward_root_is_unstable_where_the_rayleigh_branch_is_stable() -> None:
    scene = _scene(0.45, eta_infinite=False, log10_eta=math.log10(3.0))
    roots = _element(scene.zplane_dmap[()], hv.Scatter, "unstable roots")
    z = roots.dimension_values("re") + 1j * roots.dimension_values("im")
    np.testing.assert_allclose(z, [-1.86154054015624 + 0.04806456251133j], rtol=1e-10)
    z_r = complex(model.spectrum(0.45, **PAPER, eta=3.0))
    assert z_r.imag < 0
    text = scene.readout()
    assert "**Unstable roots** 1" in text and "stable (Im z ≤ 0)" in text and "(Rayleigh)" not in text
    # count curve: this branch adds instability (about 0.29 < kH < 0.76) where no Rayleigh band is shaded
    overlay = scene.count_dmap[()]
    kh = KH_COUNT
    other = _element(overlay, hv.Curve, "other branches (all − Rayleigh)").dimension_values("count")
    inside = (kh > 0.3) & (kh < 0.75)
    assert np.all(other[inside] >= 1)
    assert len(_element(overlay, hv.VSpans, "Rayleigh branch unstable")) == 0


def test_eta10_fastest_root_is_not_the_rayleigh_root() -> None:
    scene = _scene(0.77, eta_infinite=False, log10_eta=1.0)
    roots = _element(scene.zplane_dmap[()], hv.Scatter, "unstable roots")
    z = roots.dimension_values("re") + 1j * roots.dimension_values("im")
    assert z.size == 10
    np.testing.assert_allclose(z[0], 2.3954 + 0.03804j, atol=1e-4)  # the fastest-growing root (sorted by Im z)
    z_r = complex(model.spectrum(0.77, **PAPER, eta=10.0))
    np.testing.assert_allclose(z_r, 0.8847 + 0.01045j, atol=1e-4)
    i_r = int(np.argmin(np.abs(z - z_r)))
    assert abs(z[i_r] - z_r) < 1e-10 and i_r > 0
    text = scene.readout()
    assert f"| {i_r + 1} (Rayleigh) |" in text and f"root #{i_r + 1} above" in text


# --------------------------------------------------------------------------------------------
# the param graph and the cache
# --------------------------------------------------------------------------------------------


def test_building_the_tab_computes_nothing() -> None:
    AllBranchesScene().__panel__()
    assert sum(calls.values()) == 0


def test_each_change_recomputes_only_what_depends_on_it() -> None:
    scene = _scene(0.45)
    _render_all(scene)
    base = dict(compute_roots=1, unstable_modes=1, compute_rayleigh_point=1, compute_count_curve=1,
                unstable_count=len(KH_COUNT), compute_rayleigh_curve=1)
    assert {k: calls[k] for k in base} == base
    # kH: the roots and the Rayleigh root at kH only, not the count curve
    scene.log10_kH = math.log10(0.77)
    _render_all(scene)
    assert (calls["compute_roots"], calls["compute_rayleigh_point"]) == (2, 2)
    assert (calls["compute_count_curve"], calls["unstable_count"], calls["compute_rayleigh_curve"]) == (
        1, len(KH_COUNT), 1)
    # gamma: everything, exactly once
    scene.params.gamma = 4.0
    _render_all(scene)
    assert (calls["compute_roots"], calls["compute_count_curve"], calls["compute_rayleigh_curve"],
            calls["compute_rayleigh_point"], calls["unstable_count"]) == (3, 2, 2, 3, 2 * len(KH_COUNT))
    # xi while Delta == 1 does not enter F: nothing
    before = dict(calls)
    fired: list = []
    scene.param.watch(fired.append, ["args_key", "kH_key", "window_key"])
    scene.params.xi = 3.0
    _render_all(scene)
    assert dict(calls) == before and fired == []
    # the window: roots and count, not the Rayleigh branch
    scene.im_max = 1.0
    _render_all(scene)
    assert (calls["compute_roots"], calls["compute_count_curve"]) == (4, 3)
    assert (calls["compute_rayleigh_curve"], calls["compute_rayleigh_point"]) == (2, 3)
    # back to a previous state: all cached
    scene.im_max = 2.0
    scene.params.gamma = 3.0
    scene.log10_kH = math.log10(0.45)
    before = dict(calls)
    _render_all(scene)
    assert dict(calls) == before


def test_cache_is_bounded() -> None:
    for i in range(40):  # more than the count curve's bound (32): the oldest entries are evicted
        ab.compute_rayleigh_curve(3.0 + i, 0.9, 0.3, math.inf, 1.0, 0.0)
    ab.compute_rayleigh_curve(3.0, 0.9, 0.3, math.inf, 1.0, 0.0)
    assert calls["compute_rayleigh_curve"] == 40
    for i in range(70):
        ab.compute_rayleigh_curve(100.0 + i, 0.9, 0.3, math.inf, 1.0, 0.0)
    ab.compute_rayleigh_curve(3.0, 0.9, 0.3, math.inf, 1.0, 0.0)  # evicted (max_items=64): computed again
    assert calls["compute_rayleigh_curve"] == 111


def test_inactive_scene_defers_shared_parameter_changes_until_shown() -> None:
    """Panel's dynamic Tabs keep a shown tab's plots alive; with `active` wired to the tab, a change made on
    another tab recomputes nothing here until the tab is shown again, and then exactly once."""
    params = SpectrumParams()
    scene = AllBranchesScene(params=params, log10_kH=math.log10(0.45))
    tabs = pn.Tabs(("Other", pn.pane.Markdown("other tab")), ("All branches", scene.__panel__()), dynamic=True)
    tabs.param.watch(lambda e: setattr(scene, "active", e.new == 1), "active")
    scene.active = False
    tabs.get_root(Document(), comm=Comm())
    tabs.active = 1  # shown: computes
    assert (calls["compute_roots"], calls["compute_count_curve"]) == (1, 1)
    tabs.active = 0  # hidden again; the shared parameters change on another tab
    params.gamma = 4.0
    params.f = 0.8
    assert (calls["compute_roots"], calls["compute_count_curve"]) == (1, 1)
    assert scene.args_key[:2] == (3.0, 0.9)
    tabs.active = 1  # shown: both changes applied at once
    assert (calls["compute_roots"], calls["compute_count_curve"]) == (2, 2)
    assert scene.args_key[:2] == (4.0, 0.8)
    roots = _element(scene.zplane_dmap[()], hv.Scatter, "unstable roots")
    np.testing.assert_array_equal(roots.dimension_values("re"),
                                  model.unstable_modes(0.45, gamma=4.0, f=0.8, beta=0.3).real)


def _sources(root) -> list[ColumnDataSource]:
    return list(root.select({"type": ColumnDataSource}))


def test_dynamic_maps_update_in_place_in_a_bokeh_document() -> None:
    scene = _scene(0.45)
    zpane = pn.pane.HoloViews(scene.zplane_dmap)
    cpane = pn.pane.HoloViews(scene.count_dmap)
    zroot = zpane.get_root(Document(), comm=Comm())
    croot = cpane.get_root(Document(), comm=Comm())
    (roots_cds,) = [s for s in _sources(zroot) if "residual" in s.data]
    np.testing.assert_array_equal(roots_cds.data["re"], model.unstable_modes(0.45, **PAPER).real)
    curves = [s for s in _sources(croot) if len(s.data.get("count", ())) > 1]
    assert len(curves) == 3  # all roots, other branches, every root above the floor (as steps)
    before = [np.array(s.data["count"]) for s in curves]
    n = calls["unstable_count"]
    scene.log10_kH = math.log10(0.77)
    (roots_after,) = [s for s in _sources(zroot) if "residual" in s.data]
    assert roots_after is roots_cds  # the same model, new data
    np.testing.assert_array_equal(roots_cds.data["im"], model.unstable_modes(0.77, **PAPER).imag)
    assert [s for s in _sources(croot) if len(s.data.get("count", ())) > 1] == curves
    for cds, old in zip(curves, before, strict=True):
        np.testing.assert_array_equal(cds.data["count"], old)
    (marker,) = [s for s in _sources(croot) if len(s.data.get("count", ())) == 1]
    assert marker.data["kH"][0] == 0.77 and marker.data["count"][0] == model.unstable_count(0.77, **PAPER)
    assert calls["unstable_count"] == n


# --------------------------------------------------------------------------------------------
# window input
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "value", "says"),
    [
        ("im_max", -1.0, "must be below max Im z"),
        ("im_max", 1e-4, "must be below max Im z"),
        ("im_min", None, "min Im z: enter a finite number"),
        ("im_min", 1e-7, "min Im z must be ≥"),
        ("re_max", 0.0, "max |Re z| must be in"),
        ("re_max", 1e3, "max |Re z| must be in"),
        ("im_max", 50.0, "max Im z must be ≤"),
        ("re_max", float("inf"), "enter a finite number"),
    ],
)
def test_bad_window_input_gives_a_message_and_keeps_working(name: str, value, says: str) -> None:
    scene = _scene(0.45)
    widgets = scene.make_widgets()
    _render_all(scene)
    before = dict(calls)
    widgets[name].value = value
    assert says in scene.window_message and "still showing the window |Re z| ≤ 5" in scene.window_message
    assert scene.window_alert.visible and says in scene.window_alert.object
    assert scene.window_key == (5.0, 1e-4, 2.0)
    _render_all(scene)  # the plots still work, with the last valid window, and nothing was recomputed
    assert dict(calls) == before
    scene.log10_kH = math.log10(0.77)  # the rest of the scene keeps working
    roots = _element(scene.zplane_dmap[()], hv.Scatter, "unstable roots")
    np.testing.assert_array_equal(roots.dimension_values("re"), model.unstable_modes(0.77, **PAPER).real)
    # a valid value clears the message and applies the window
    widgets[name].value = {"im_max": 0.05, "im_min": 1e-3, "re_max": 2.0}[name]
    assert scene.window_message == "" and not scene.window_alert.visible
    window = dict(WINDOW, **{name: widgets[name].value})
    assert scene.window_key == (window["re_max"], window["im_min"], window["im_max"])
    roots = _element(scene.zplane_dmap[()], hv.Scatter, "unstable roots")
    np.testing.assert_array_equal(roots.dimension_values("re"), model.unstable_modes(0.77, **PAPER, **window).real)


def test_model_failure_gives_a_message_and_keeps_working(monkeypatch: pytest.MonkeyPatch) -> None:
    def fail(*_args, **_kwargs):
        raise RuntimeError("unstable_modes: test failure")

    scene = _scene(0.45)
    monkeypatch.setattr(model, "unstable_modes", fail)
    real_count = model.unstable_count

    def fail_above_one(kH, **kw):
        if kH > 1.0:
            raise RuntimeError("unstable_count: test failure")
        return real_count(kH, **kw)

    monkeypatch.setattr(model, "unstable_count", fail_above_one)
    text = scene.readout()
    assert "**Model error** no roots shown: unstable_modes: test failure" in text
    assert len(_element(scene.zplane_dmap[()], hv.Scatter, "unstable roots")) == 0
    overlay = scene.count_dmap[()]
    count = _element(overlay, hv.Curve, "all roots in window").dimension_values("count")
    assert np.all(np.isnan(count[KH_COUNT > 1.0])) and np.all(np.isfinite(count[KH_COUNT <= 1.0]))
    n_failed = int(np.count_nonzero(KH_COUNT > 1.0))
    assert f"({n_failed} grid point(s) failed: gaps)" in str(overlay.opts.get("plot").kwargs.get("title"))
    assert "# model error: unstable_modes: test failure" in scene.roots_csv().getvalue()
    assert f"# {n_failed} grid point(s) failed: unstable_count: test failure" in scene.count_csv().getvalue()
    monkeypatch.undo()
    scene.log10_kH = math.log10(0.77)  # recovers at the next change
    assert "**Unstable roots** 1" in scene.readout()


# --------------------------------------------------------------------------------------------
# CSV export and the bokeh figures
# --------------------------------------------------------------------------------------------


def test_roots_csv_equals_the_plotted_data() -> None:
    scene = _scene(0.77, eta_infinite=False, log10_eta=1.0)
    kw = _model_kwargs(scene)
    text = scene.roots_download.callback().getvalue()
    assert scene.roots_download.filename.endswith(".csv")
    rows = _csv_rows(text)
    z = model.unstable_modes(0.77, **kw)
    roots = [r for r in rows if r["kind"] == "unstable_root"]
    assert len(roots) == z.size == 10
    np.testing.assert_array_equal([float(r["re_z"]) for r in roots], z.real)
    np.testing.assert_array_equal([float(r["im_z"]) for r in roots], z.imag)
    assert all(float(r["kH"]) == 0.77 for r in rows)
    resid = np.abs(model.dispersion(z, 0.77, **kw)) / model.dispersion_scale(z, 0.77, **kw)
    np.testing.assert_allclose([float(r["residual"]) for r in roots], resid, rtol=1e-12)
    (rb,) = [r for r in rows if r["kind"] == "rayleigh_branch"]
    res = model.rayleigh_branch(0.77, **kw)
    assert complex(float(rb["re_z"]), float(rb["im_z"])) == complex(res.z)
    assert float(rb["error_estimate"]) == float(res.error)
    flagged = [i for i, r in enumerate(roots) if r["on_rayleigh_branch"] == "1"]
    assert flagged == [int(np.argmin(np.abs(z - complex(res.z))))]
    assert f"eta={kw['eta']!r}" in text and "im_min=0.0001" in text


def test_count_csv_equals_the_plotted_data() -> None:
    scene = _scene(0.45)
    text = scene.count_download.callback().getvalue()
    rows = _csv_rows(text)
    assert [float(r["kH"]) for r in rows] == KH_COUNT.tolist()
    expected = [model.unstable_count(float(k), **PAPER, **WINDOW) for k in KH_COUNT]
    assert [int(r["count"]) for r in rows] == expected
    z_r = model.spectrum(KH_COUNT, **PAPER)
    np.testing.assert_allclose([float(r["rayleigh_re_z"]) for r in rows], z_r.real, rtol=1e-12)
    np.testing.assert_allclose([float(r["rayleigh_im_z"]) for r in rows], z_r.imag, rtol=1e-10, atol=1e-15)
    in_window = (np.abs(z_r.real) <= 5.0) & (z_r.imag >= 1e-4) & (z_r.imag <= 2.0)
    assert [int(r["rayleigh_in_window"]) for r in rows] == in_window.astype(int).tolist()
    assert [int(r["other_branches"]) for r in rows] == (np.array(expected) - in_window).tolist()
    assert "# current kH=0.45 count=2" in text


def test_bokeh_figures_axes_hover_and_png_save_tool() -> None:
    scene = _scene(0.45)
    zfig = hv.render(scene.zplane_dmap, backend="bokeh")
    cfig = hv.render(scene.count_dmap, backend="bokeh")
    assert zfig.xaxis[0].axis_label == "Re[c/c_s]" and zfig.yaxis[0].axis_label == "Im[c/c_s]"
    assert type(cfig.x_scale).__name__ == "LogScale" and cfig.xaxis[0].axis_label == "kH"
    for fig in (zfig, cfig):
        assert any(type(t).__name__ == "SaveTool" for t in fig.tools)  # PNG export from the toolbar
    hover = [t for t in zfig.tools if type(t).__name__ == "HoverTool"]
    assert any(any("@error" in str(v) for _, v in h.tooltips) for h in hover)


def test_app_has_the_all_branches_tab() -> None:
    from asymslide.app.main import create_app

    template = create_app()
    (tabs,) = [obj for obj in template.main.objects if isinstance(obj, pn.Tabs)]
    assert "All branches" in tabs._names


# --------------------------------------------------------------------------------------------
# browser
# --------------------------------------------------------------------------------------------

_SOURCE_JS = """(key) => {
  for (const m of Bokeh.documents[0].all_models) {
    if (m.data != null && m.data[key] !== undefined && m.data.re !== undefined && m.data.re.length > 0) {
      return {re: Array.from(m.data.re), im: Array.from(m.data.im)};
    }
  }
  return null;
}"""


@pytest.mark.ui
@pytest.mark.slow
def test_all_branches_tab_shows_the_model_roots(served_app: str, browser_page) -> None:
    page = browser_page
    open_app(page, served_app, "All branches")
    page.wait_for_function(f"() => ({_SOURCE_JS})('residual') !== null", timeout=60_000)
    z = model.unstable_modes(0.45, **PAPER)
    got = page.evaluate(_SOURCE_JS, "residual")
    np.testing.assert_allclose(np.array(got["re"]) + 1j * np.array(got["im"]), z, rtol=1e-14)
    rb = page.evaluate(_SOURCE_JS, "rb_error")
    assert complex(rb["re"][0], rb["im"][0]) == pytest.approx(complex(model.spectrum(0.45, **PAPER)), rel=1e-14)
    # the kH slider (on release) moves the roots
    log_kh = math.log10(0.77)
    assert set_slider(page, "kH", log_kh)
    kh = from_log10(log_kh)
    expected = model.unstable_modes(kh, **PAPER)
    page.wait_for_function(f"() => {{ const d = ({_SOURCE_JS})('residual'); return d !== null && "
                           f"d.re.length === {expected.size} && d.re[0] !== {got['re'][0]!r}; }}", timeout=30_000)
    got = page.evaluate(_SOURCE_JS, "residual")
    np.testing.assert_allclose(np.array(got["re"]) + 1j * np.array(got["im"]), expected, rtol=1e-14)
    assert page.console_errors == []


def test_the_fastest_root_outside_the_window_is_drawn_and_reported() -> None:
    """At eta = 3, kH = 0.45 the fastest root of every branch, z = 17.98 + 0.098i (model.fastest_mode in the complete
    window), lies outside the default window |Re z| <= 5: the z-plane plot draws it (a star, inside the view) and the
    readout says it lies outside; at eta = inf it is root #1 of the window's list. The count plot counts every root
    above the floor in the complete window (refused at finite eta)."""
    scene = _scene(0.45)
    text = scene.readout()
    assert "**Fastest root, every branch**" in text and "supersonic guided mode: root #1 above" in text
    fc = scene.floor_count()
    m = model.fastest_mode(ab.KH_COUNT, **PAPER, count=True)
    np.testing.assert_array_equal(fc["count"], m.count.astype(float))
    scene.params.param.update(eta_infinite=False, log10_eta=math.log10(3.0))
    fm = model.fastest_mode(0.45, **{**PAPER, "eta": 3.0}, count=False)
    z = complex(fm.z)
    assert z.real > 5 and int(fm.status) == 0
    text = scene.readout()
    assert "the fastest mode lies outside the window" in text and f"{z.real:.8g}" in text
    overlay = scene.zplane_dmap[()]
    (star,) = [e for e in overlay if e.label == "fastest root, every branch"]
    assert star.dimension_values(0).tolist() == [z.real] and star.dimension_values(1).tolist() == [z.imag]
    xlim = overlay.opts.get().kwargs["xlim"]
    assert xlim[0] < z.real < xlim[1]
    assert "fastest_root_every_branch" in scene.roots_csv().getvalue()
    assert scene.floor_count()["refused"] == ab.KH_COUNT.size  # the window at the floor is too wide at finite eta
