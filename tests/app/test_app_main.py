"""The page as a whole: URL query state, bad URL input, presets, CSV export, the G_y criterion plot."""

from __future__ import annotations

import io
import logging
import math
import urllib.parse
import urllib.request

import holoviews as hv
import numpy as np
import pytest

from asymslide import model
from asymslide.app import spectrum as sp
from asymslide.app import thin_on_thick as tt
from asymslide.app.plotting import ZERO_LINE
from asymslide.app.presets import load_presets
from asymslide.app.urlstate import BY_KEY, QUERY, TABS, parse_query, query_string
from tests.conftest import open_app, set_slider
from tests.support.headless import build_app

#: bad queries (malformed, out of range, hostile) and what must come out of each (unknown/invalid values keep defaults)
BAD_QUERIES = {
    "gamma=nan": {"gamma": 3.0},
    "eta=-5&beta=junk": {"eta": math.inf, "beta": 0.3},
    "beta=0.9&kW=1e999": {"beta": 0.7071},
    "xi=<script>alert(1)</script>": {"xi": 0.0},
    "gamma=1e308&f=-1": {"gamma": 1e3, "f": 0.0},
}


def _args(query: str) -> dict[str, list[str]]:
    return urllib.parse.parse_qs(query, keep_blank_values=True)


# --------------------------------------------------------------------------------------------
# URL query
# --------------------------------------------------------------------------------------------


@pytest.mark.parametrize("query", list(BAD_QUERIES))
def test_bad_queries_give_messages_and_safe_values(query: str) -> None:
    app = build_app(_args(query))
    p = app.spectrum_params
    assert app.messages.visible
    n_keys = len(_args(query))
    assert app.messages.object.count("\n- ") == n_keys  # one message per bad value
    for name, expected in BAD_QUERIES[query].items():
        assert (p.eta if name == "eta" else getattr(p, name)) == expected
    assert app.thin_params.kW == pytest.approx(5.0)  # kW=1e999 ignored: the default stays
    assert "<script>" not in app.messages.object  # quoted back escaped, never as markup
    # the session keeps working: the spectrum scene computes with the (clamped) values
    d = app.spectrum.data()
    assert np.isfinite(d["z"]).any()


def test_values_are_parsed_with_float_only() -> None:
    """Nothing is evaluated: Python/JSON-looking values are rejected like any other non-number."""
    for raw in ("__import__('os').getcwd()", "[1, 2]", "{'a': 1}", "1+1", "0x10", "1_000"[:0] + "1e3e3"):
        updates, _, messages = parse_query({"gamma": [raw]})
        assert updates["spectrum"] == {} and len(messages) == 1 and "not a finite number" in messages[0]


def test_good_query_sets_every_parameter_and_tab() -> None:
    query = ("gamma=4.5&f=0.6&beta=0.25&eta=20&Delta=0.5&xi=2&kW=0.7&nu=0.25&lab_cs=1000&lab_rho=2000&lab_sigma0=3"
             "&map=f-gamma&map_res=fine&kH=0.8&re_max=3&im_min=0.001&im_max=1.5&tab=branches")
    app = build_app(_args(query))
    p, t, lab = app.spectrum_params, app.thin_params, app.lab_params
    assert not app.messages.visible
    assert p.model_args() == pytest.approx((4.5, 0.6, 0.25, 20.0, 0.5, 2.0), rel=1e-14)
    assert (t.kW, t.nu, lab.c_s, lab.rho, lab.sigma0_MPa) == pytest.approx((0.7, 0.25, 1000.0, 2000.0, 3.0), rel=1e-14)
    assert (app.map.plane, app.map.resolution) == ("f-γ", "fine")
    b = app.branches
    assert (10**b.log10_kH, b.re_max, b.im_min, b.im_max) == pytest.approx((0.8, 3.0, 1e-3, 1.5), rel=1e-12)
    assert app.tabs.active == TABS.index("branches")


def test_old_links_with_the_material_of_thin_on_thick_or_rupture_fronts_still_work() -> None:
    """The page has one set of material constants (the Lab-units panel's); the keys of the former copies in the
    Thin-on-thick and Rupture-fronts scenes set it."""
    app = build_app(_args("c_s=1000&rho=2000&sigma0=3&rup_material=Homalite-100"))
    lab = app.lab_params
    assert not app.messages.visible
    assert (lab.material, lab.c_s, lab.rho, lab.sigma0_MPa) == ("custom", 1000.0, 2000.0, 3.0)
    assert app.thin.stress_key[2:] == (1000.0, 2000.0, 3e6) and app.rupture.front_key[3:5] == (2000.0, 1000.0)
    homalite = build_app(_args("rup_material=Homalite-100"))
    assert homalite.lab_params.material == "Homalite-100" and homalite.rupture_params.nu == 0.35


def test_url_shows_only_what_was_used_and_reports_what_the_model_refuses() -> None:
    """c/c_R = 1.5 is clamped with a message (it was a red error box), a negative height is in the banner (the lab
    panel, folded, was the only place that said so), thin-on-thick defaults are not written."""
    app = build_app(_args("c_cR=1.5&H1=-5&tab=rupture"))
    text = app.messages.object
    assert "c/c_R = 1.5 is outside 0.01 … 0.999: set to 0.999" in text
    assert "the lab values are not valid" in text and "H₁ must be in (0, ∞) mm; got -5 mm" in text  # as typed
    assert app.rupture_params.c_over_cR == 0.999 and not app.rupture.errors()
    q = _args(query_string(app.param_objects(), "rupture")[1:])
    assert q["c_cR"] == ["0.999"] and q["H1"] == ["-5"]
    default = _args(query_string(build_app({}).param_objects(), "spectrum")[1:])
    assert not {"kW", "nu", "map", "map_res", "kH", "re_max", "im_min", "im_max"} & set(default)


def test_query_string_round_trip() -> None:
    app = build_app(_args("gamma=2.5&eta=300&Delta=0.4&xi=7&kW=12&tab=map"))
    query = query_string(app.param_objects(), TABS[app.tabs.active])
    again = build_app(_args(query[1:]))
    assert not again.messages.visible
    assert again.spectrum_params.model_args() == pytest.approx(app.spectrum_params.model_args(), rel=1e-5)
    assert again.thin_params.kW == pytest.approx(12.0, rel=1e-5)
    assert again.tabs.active == TABS.index("map")
    # every key of the spectrum parameters is written; the others only when changed
    assert {q.key for q in QUERY if q.target == "spectrum"} - {"xi"} <= set(_args(query[1:]))
    assert {"kW"} == {q.key for q in QUERY if q.target == "thin"} & set(_args(query[1:]))


def test_eta_infinite_is_written_as_inf_and_xi_omitted_at_delta_one() -> None:
    app = build_app({})
    q = _args(query_string(app.param_objects(), "spectrum")[1:])
    assert q["eta"] == ["inf"] and "xi" not in q


# --------------------------------------------------------------------------------------------
# presets
# --------------------------------------------------------------------------------------------


def test_every_figure_has_a_preset() -> None:
    labels = [p.label for p in load_presets()]
    assert labels == ["Fig. 3", "Fig. 4a-b", "Fig. 4c", "Fig. 5a", "Fig. 5b", "Fig. 5c", "Fronts (S-V)"]


@pytest.mark.parametrize("preset", load_presets(), ids=lambda p: p.id)
def test_preset_sets_values_family_and_tab(preset) -> None:
    app = build_app({"gamma": ["7"], "f": ["0.2"]})  # non-default start: the preset must reset it
    app.apply_preset(preset)
    assert app.tabs.active == TABS.index(preset.tab)
    objects = app.param_objects()
    for key, raw in preset.values.items():
        q = BY_KEY[key]
        if key == "eta":
            assert app.spectrum_params.eta == (math.inf if raw == "inf" else pytest.approx(float(raw)))
        elif q.kind == "choice":  # the URL word of the choice set
            value = getattr(objects[q.target], q.attribute)
            assert (q.words or q.choices)[q.choices.index(value)] == raw
        else:
            value = getattr(objects[q.target], q.attribute)
            assert (10.0**value if q.log10 else value) == pytest.approx(float(raw), rel=1e-12)
    if "gamma" not in preset.values:
        assert app.spectrum_params.gamma == 3.0  # reset to the paper's default
    if preset.compare_key == "kW":
        assert app.thin.compare_kW == list(preset.compare_values)
    elif preset.tab == "rupture":
        assert app.lab_params.material == "PMMA"  # the paper's values are the PMMA preset's (shared material)
    else:
        assert app.spectrum.compare_values == list(preset.compare_values)
    assert preset.label in app.preset_info.object
    if preset.tab == "map":  # Fig. 4c keeps the paper's look: the map coloured by the Rayleigh branch
        assert app.map.verdict == "Rayleigh branch"


def test_a_map_preset_resets_the_maps_colouring() -> None:
    app = build_app({"map_verdict": ["sliding"], "map_floor": ["1e-2"]})
    assert (app.map.verdict, app.map.floor) == ("sliding (every branch)", "1e-2")
    (fig4c,) = [p for p in load_presets() if p.id == "fig4c"]
    app.apply_preset(fig4c)
    assert (app.map.verdict, app.map.floor) == ("Rayleigh branch", "auto")
    assert "map_verdict=rayleigh" in query_string(app.param_objects(), "map")


def test_fig5a_family_curves_equal_the_model() -> None:
    app = build_app({})
    (fig5a,) = [p for p in load_presets() if p.id == "fig5a"]
    app.apply_preset(fig5a)
    overlay = app.spectrum.im_dmap[()]
    for eta in fig5a.compare_values:
        label = f"η = {'∞' if math.isinf(eta) else f'{eta:g}'}"
        (curve,) = [e for e in overlay if isinstance(e, hv.Curve) and e.label == label]
        expected = model.spectrum(sp.KH, gamma=3.0, f=0.9, beta=0.3, eta=eta)
        np.testing.assert_array_equal(curve.dimension_values(1), expected.imag)
    eta_one = model.spectrum(sp.KH, gamma=3.0, f=0.9, beta=0.3, eta=1.0)
    assert np.nanmax(eta_one.imag) < 0  # eta = 1 is the symmetric, stable curve of Fig. 5a
    app.clear_families()
    assert [e.label for e in app.spectrum.im_dmap[()] if isinstance(e, hv.Curve)] == [
        "Rayleigh branch", "linear expansion", "fastest root, every branch"]


# --------------------------------------------------------------------------------------------
# G_y criterion plot and CSV export
# --------------------------------------------------------------------------------------------


def test_gy_plot_is_gy_at_the_rayleigh_speed_with_the_criterion_line() -> None:
    scene = sp.SpectrumScene()
    overlay = scene.gy_dmap[()]
    (curve,) = [e for e in overlay if isinstance(e, hv.Curve)]
    z_r = float(model.rayleigh_speed(0.3))
    expected = model.response_functions(np.full(sp.KH.shape, z_r), sp.KH, beta=0.3)[1].real
    np.testing.assert_array_equal(curve.dimension_values(1), expected)
    (line,) = [e for e in overlay if isinstance(e, hv.HLine)]
    assert float(line.data) == pytest.approx(-z_r / (3.0 * 0.9), rel=1e-15)
    spans = [r for r in hv.render(overlay).center if getattr(r, "name", None) == ZERO_LINE]
    assert len(spans) == 1 and spans[0].location == 0 and spans[0].dimension == "width"  # the zero line
    # the criterion: gamma f min G_y < -z_R  <=>  unstable (paper: gamma = 3 unstable, gamma = 2 stable)
    assert 3.0 * 0.9 * expected.min() < -z_r < 2.0 * 0.9 * expected.min()


def _read_csv(buffer: io.StringIO) -> tuple[list[str], np.ndarray]:
    lines = buffer.getvalue().splitlines()
    assert lines[0].startswith("# asymslide")
    return lines[1].split(","), np.loadtxt(lines[2:], delimiter=",", ndmin=2)


def test_spectrum_csv_equals_the_plotted_data() -> None:
    """One CSV per plot (not one button for three plots), each with what the plot shows, the preset's family of
    curves included."""
    scene = sp.SpectrumScene()
    scene.param.update(compare_key="gamma", compare_values=[2.0, 10.0])
    d = scene.data()
    for csv, part, name in ((scene.csv_growth, "imag", "Im_z"), (scene.csv_phase, "real", "Re_z")):
        names, data = _read_csv(csv())
        assert names[:2] == ["kH", name] and names[-2:] == [f"{name}(gamma=2.0)", f"{name}(gamma=10.0)"]
        np.testing.assert_array_equal(data[:, 0], d["kH"])
        np.testing.assert_array_equal(data[:, 1], getattr(d["z"], part))
        np.testing.assert_array_equal(data[:, names.index("status")], d["status"])
        np.testing.assert_array_equal(data[:, -1], getattr(model.spectrum(d["kH"], gamma=10.0, f=0.9, beta=0.3), part))
    names, data = _read_csv(scene.csv_gy())
    assert names == ["kH", "G_y_at_z_R"]
    z_r = float(model.rayleigh_speed(0.3))
    np.testing.assert_array_equal(data[:, 1], np.real(model.response_functions(np.full(d["kH"].shape, z_r), d["kH"],
                                                                                beta=0.3, eta=math.inf)[1]))
    assert "criterion level" in scene.csv_gy().getvalue().splitlines()[0]


def test_thin_on_thick_csv_equals_the_plotted_data() -> None:
    scene = tt.ThinOnThickScene()
    scene.compare_kW = [0.5, 20.0]
    names, data = _read_csv(scene.csv_gy())
    assert len(names) == 6
    for j, kw in enumerate((scene.params.kW, 0.5, 20.0)):
        d = tt.compute_gy_curve(kw, 0.33)
        np.testing.assert_array_equal(data[:, 2 * j], d["z"])
        np.testing.assert_array_equal(data[:, 2 * j + 1], d["gy"])
    names, data = _read_csv(scene.csv_moduli())
    np.testing.assert_array_equal(data[:, 1], model.effective_moduli(tt.KW, 0.33)[0])
    names, data = _read_csv(scene.csv_stress())
    assert names == ["v_m_per_s", "dsigma_yy_over_sigma0"] and data.shape == (tt.V.size, 2)


# --------------------------------------------------------------------------------------------
# served: bad URLs never produce a server error; in the browser the message shows and the app works
# --------------------------------------------------------------------------------------------


class _Errors(logging.Handler):
    def __init__(self) -> None:
        super().__init__(level=logging.ERROR)
        self.records: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(self.format(record))


@pytest.mark.slow
def test_bad_urls_leave_no_error_in_the_server_log(served_app: str) -> None:
    handler = _Errors()
    logging.getLogger().addHandler(handler)
    try:
        for query in BAD_QUERIES:
            url = served_app + "?" + urllib.parse.quote(query, safe="=&")
            with urllib.request.urlopen(url, timeout=60) as response:
                assert response.status == 200
    finally:
        logging.getLogger().removeHandler(handler)
    assert handler.records == []




@pytest.mark.ui
@pytest.mark.slow
def test_bad_url_shows_message_and_the_app_keeps_working(served_app: str, browser_page) -> None:
    page = browser_page
    open_app(page, served_app + "?gamma=nan&xi=%3Cscript%3Ealert(1)%3C/script%3E&f=-1")
    page.get_by_text("not used as given").first.wait_for(state="visible", timeout=30_000)
    page.get_by_text("is not a finite number").first.wait_for(state="visible", timeout=30_000)
    page.get_by_text("f = -1 is outside").first.wait_for(state="visible", timeout=30_000)
    assert set_slider(page, "γ", 4.0)
    page.wait_for_function("() => window.location.search.includes('gamma=4')", timeout=30_000)
    query = urllib.parse.parse_qs(page.evaluate("() => window.location.search")[1:])
    assert query["gamma"] == ["4"] and query["f"] == ["0"] and query["tab"] == ["spectrum"]


@pytest.mark.ui
@pytest.mark.slow
def test_preset_button_draws_the_family(served_app: str, browser_page) -> None:
    page = browser_page
    open_app(page, served_app)
    page.locator("button", has_text="Fig. 5a").first.click(timeout=60_000)
    page.get_by_text("several η").first.wait_for(state="visible", timeout=30_000)
    page.wait_for_function("() => window.location.search.includes('eta=inf')", timeout=30_000)
    # one glyph renderer per family curve, with the legend label of its eta
    labels = ("() => Array.from(Bokeh.documents[0].all_models)"
              ".filter(m => m.label && m.label.value).map(m => m.label.value)")
    page.wait_for_function(f"() => ({labels})().includes('η = 3.3')", timeout=30_000)
    assert {"η = 1", "η = 10", "η = ∞"} <= set(page.evaluate(labels))


#: (tag, font size) of every visible h3 heading of the page, shadow roots included (JS function)
_HEADINGS_JS = """() => { const out = [];
  const walk = (root) => { for (const el of root.querySelectorAll('*')) {
    if (el.shadowRoot) walk(el.shadowRoot);
    if (el.tagName === 'H3' && el.getBoundingClientRect().width > 0)
      out.push([el.textContent.trim(), getComputedStyle(el).fontSize]); } };
  walk(document); return out; }"""

#: whether every stylesheet linked in the page's shadow roots has loaded (they load after the tab is drawn)
_STYLES_LOADED_JS = """() => { let ok = true;
  const walk = (root) => { for (const el of root.querySelectorAll('*')) {
    if (el.shadowRoot) walk(el.shadowRoot);
    if (el.tagName === 'LINK' && el.rel === 'stylesheet' && !el.sheet) ok = false; } };
  walk(document); return ok; }"""


def test_a_pane_outside_the_document_keeps_the_sessions_stylesheets() -> None:
    """app.workarounds.guard_detached_updates: a stylesheet patched for Panel's CDN while a session with local
    stylesheets is current stays local (a pane of a tab switched away from, updated later); without a session,
    Panel's own behaviour."""
    import panel.reactive
    from bokeh.document import Document
    from bokeh.models import ImportedStyleSheet
    from panel.io.resources import CDN_DIST
    from panel.io.state import set_curdoc

    import asymslide.app.main  # noqa: F401  (installs the guard)

    local = "static/extensions/panel/css/markdown.css"
    doc = Document()
    doc._template_variables["dist_url"] = "static/extensions/panel/"
    sheet = ImportedStyleSheet(url=local)
    with set_curdoc(doc):
        panel.reactive.patch_stylesheet(sheet, CDN_DIST)
    assert sheet.url.startswith(local)  # Panel appends ?v=VERSION
    panel.reactive.patch_stylesheet(sheet, CDN_DIST)
    assert sheet.url.startswith(CDN_DIST + "css/markdown.css")


@pytest.mark.ui
@pytest.mark.slow
def test_tabs_opened_later_keep_the_pages_styles(served_app: str, browser_page) -> None:
    """Tabs rendered after the page has loaded get Bootstrap's full stylesheet (h3 at 28 px): the headings of the
    controls (app.layout.heading) keep one size whichever tab they are in. And no stylesheet is requested from
    Panel's CDN (offline here) when the Stability map finishes after its tab was left."""
    page = browser_page
    requested = []
    page.on("request", lambda r: requested.append(r.url))
    open_app(page, served_app)
    sizes = {}
    for tab in ("Spectrum", "Stability map", "Thin-on-thick", "Rupture fronts", "All branches"):
        page.locator(".bk-tab", has_text=tab).first.click()
        page.wait_for_timeout(500)  # the previous tab hidden
        # the visible headings once the tab is drawn, the document idle and every stylesheet loaded
        headings = page.wait_for_function(
            f"""() => {{ const h = ({_HEADINGS_JS})().filter(h => h[0] === 'Parameters');
                return h.length > 0 && Bokeh.documents[0].is_idle && ({_STYLES_LOADED_JS})() ? h : null; }}""",
            timeout=60_000).json_value()
        sizes[tab] = {size for _, size in headings}
    assert len(set().union(*sizes.values())) == 1, sizes
    assert float(next(iter(sizes["Rupture fronts"])).removesuffix("px")) < 20, sizes
    assert not [url for url in requested if "cdn.holoviz.org" in url]
    assert page.console_errors == []


def test_a_tab_opened_on_a_served_page_shows_a_labelled_placeholder_first(monkeypatch: pytest.MonkeyPatch) -> None:
    """On a served page a tab opened for the first time shows a spinner and "Opening the … tab…" at once (it was
    blank for 2.5-6 s while its scene was built and rendered); the scene replaces it on the next turn of the event
    loop."""
    from asymslide.app import main

    app = build_app({})
    scheduled = []

    class Served:  # what jobs.served_document returns in a session: the callbacks are run by its event loop
        def add_next_tick_callback(self, callback):
            scheduled.append(callback)

    monkeypatch.setattr(main.jobs, "served_document", lambda: Served())
    index = main.TABS.index("branches")
    app.tabs.active = index
    (shown,) = app._tab_content["branches"].objects
    assert "Opening the All branches tab" in shown.objects[1].object and len(scheduled) == 1
    scheduled[0]()
    (shown,) = app._tab_content["branches"].objects
    assert shown.name != main.PLACEHOLDER and "Opening" not in str(getattr(shown, "object", ""))
