"""One source of truth: the parameter declarations (app/params.py) decide the widgets, the URL keys and ranges,
the stability-map axes and the symbols shown everywhere."""

from __future__ import annotations

import pytest

from asymslide.app.all_branches import AllBranchesScene
from asymslide.app.declarations import Choice, Physical, Switch, declared_parameters, physical_parameters
from asymslide.app.params import LabParams, RuptureParams, SpectrumParams, ThinOnThickParams
from asymslide.app.spectrum import FAMILY
from asymslide.app.stability_map.grids import PLANES
from asymslide.app.stability_map.scene import StabilityMapScene
from asymslide.app.urlstate import QUERY, TARGETS, parse_query

CLASSES = (("spectrum", SpectrumParams), ("thin", ThinOnThickParams), ("lab", LabParams), ("rupture", RuptureParams))
#: scenes whose own settings are in the URL too (the map's plane and resolution, the All-branches kH and window)
SCENES = (("map", StabilityMapScene), ("branches", AllBranchesScene))


def test_every_url_key_is_a_declared_parameter_with_its_range_and_symbol() -> None:
    assert tuple(TARGETS.items()) == CLASSES + SCENES
    declared = [(target, name, p) for target, cls in CLASSES + SCENES for name, p in declared_parameters(cls).items()
                if p.url]
    assert [q.key for q in QUERY] == [p.url for _, _, p in declared]
    assert len({q.key for q in QUERY}) == len(QUERY)
    for q, (target, name, p) in zip(QUERY, declared, strict=True):
        assert (q.target, q.attribute, q.symbol) == (target, name, p.label)
        if isinstance(p, Physical):
            bounds = p.physical_bounds() if p.bounds is not None else (float("-inf"), float("inf"))
            assert (q.kind, q.log10, q.infinite, (q.lo, q.hi)) == ("number", p.log10, p.infinite, bounds)
        elif isinstance(p, Choice):
            words = tuple((p.words or {}).get(o, o) for o in p.objects)
            assert (q.kind, q.choices, q.words) == ("choice", tuple(p.objects), words)
        else:
            assert isinstance(p, Switch) and q.kind == "switch"


@pytest.mark.parametrize(("target", "cls"), CLASSES)
def test_url_values_outside_the_declared_bounds_are_clamped_to_them(target: str, cls) -> None:
    for p in physical_parameters(cls).values():
        if not p.url:
            continue
        lo, hi = p.physical_bounds()
        updates, _, messages = parse_query({p.url: [repr(hi * 10 if hi > 0 else 1.0)]})
        value = updates[target][[q.attribute for q in QUERY if q.key == p.url][0]]
        assert value == pytest.approx(p.bounds[1]) and messages


def test_widgets_are_built_from_the_declarations() -> None:
    for _, cls in CLASSES:
        obj = cls()
        widgets = obj.make_widgets()
        for name, p in physical_parameters(cls).items():
            w = widgets[name]
            assert w.label == p.label
            if p.widget == "slider":
                assert (w.start, w.end) == (p.softbounds or p.bounds) and w.step == p.step


def test_map_axes_and_families_come_from_the_declarations() -> None:
    for ax, ay in PLANES.values():
        for a in (ax, ay):
            decl = SpectrumParams.declaration(a.name)
            assert (a.lo, a.hi, a.log) == decl.axis and a.label == decl.label
    assert list(PLANES) == ["η-γ", "Δ-ξ", "f-γ", "β-γ"]
    assert {k: v[1] for k, v in FAMILY.items()} == {n: SpectrumParams.symbol(n) for n in SpectrumParams.MODEL_ARGS}


def test_declarations_are_complete() -> None:
    for _, cls in CLASSES:
        for name, p in physical_parameters(cls).items():
            assert isinstance(p, Physical) and p.label and p.doc and p.step, name
            assert p.bounds[0] < p.default < p.bounds[1] or p.default in p.bounds, name
            assert p.infinite is None or isinstance(cls.param[p.infinite].default, bool), name
        for name, p in declared_parameters(cls).items():
            assert p.label and p.doc, name
    # the load test moves the sliders by these titles
    from benchmarks.load_test import PARAM_TITLES

    assert PARAM_TITLES == {n: p.label for n, p in physical_parameters(SpectrumParams).items()}


def test_symbols_and_meanings_come_from_the_model() -> None:
    """The model declares the six parameters (model.PARAMETERS); the app shows its symbols and meanings."""
    from asymslide import model

    for name in SpectrumParams.MODEL_ARGS:
        decl, p = SpectrumParams.declaration(name), model.PARAMETERS[name]
        assert decl.label == p.symbol and decl.doc.startswith(p.description)


def test_sliders_show_as_many_decimals_as_their_step() -> None:
    """Sliders show as many decimals as their step (the c/c_R slider once read "1" at 0.996)."""
    from asymslide.app.widgets import decimals

    assert [decimals(s) for s in (1.0, 0.5, 0.1, 0.01, 0.005, 0.001)] == [0, 1, 1, 2, 3, 3]
    w = RuptureParams().make_widgets()
    assert w["c_over_cR"].format == "0.000" and (w["c_over_cR"].start, w["c_over_cR"].end) == (0.01, 0.999)
    assert SpectrumParams().make_widgets()["beta"].format == "0.000"


def test_the_eta_slider_shows_no_stale_number_while_eta_is_infinite() -> None:
    """With η = ∞ ticked the slider once still read 1.00e+8 (its last finite value), and a formatter reading ∞ kept
    reading ∞ after the box was unticked (BokehJS does not redraw the title for a new format). While η = ∞ the slider
    is disabled and shows no number (the ticked box below says ∞); unticked, it shows its value again."""
    p = SpectrumParams()
    w = p.make_widgets()
    assert w["log10_eta"].disabled and not w["log10_eta"].show_value
    w["eta_infinite"].checked = False
    assert not p.eta_infinite and not w["log10_eta"].disabled and w["log10_eta"].show_value
    assert "Math.pow(10, tick)" in w["log10_eta"].format.code  # the finite value
    p.eta_infinite = True
    assert w["eta_infinite"].value == ["η = ∞"] and not w["log10_eta"].show_value and w["log10_eta"].disabled


def test_references_to_the_physics_notes_open_their_section() -> None:
    """Each reference to the physics notes in a scene is a card that opens on that section ("docs/physics.md §12.3"
    was text, not something to follow)."""
    from asymslide.app import all_branches, lab, rupture
    from asymslide.app.docs import reference_card, section

    for text, number in ((lab.ASSUMPTION, "12.3"), (rupture.ASSUMPTIONS, "13.1"), (all_branches.HELP, "3")):
        assert f"docs/physics.md §{number}" in text
        title, body = section(number)
        card = reference_card(number)
        assert card.title == f"docs/physics.md §{number}: {title}" and card.collapsed and not card.objects
        card.collapsed = False
        assert card.objects[0].object == body and len(body) > 200
    assert "Dieterich" in section("12.3")[1] or "rate-and-state" in section("12.3")[1].lower()


@pytest.mark.ui
def test_log_slider_values_read_in_one_style(browser_page) -> None:
    """The η slider read "1.00e+4", "100" and "1.00" (toPrecision(3)); now plain numbers from 0.01 to 10⁴ and powers
    of ten beyond, in one style (the formatter run in Chromium as BokehJS runs it)."""
    from asymslide.app.widgets import LOG10_TICKS

    shown = browser_page.evaluate("([code, ticks]) => ticks.map(t => new Function('tick', code)(t))",
                                  [LOG10_TICKS, [8, 5.4, 4, 2, 0, -1, -1.3, -2, -2.5, 0.6]])
    assert shown == ["10⁸", "2.51×10⁵", "10⁴", "100", "1", "0.1", "0.0501", "0.01", "3.16×10⁻³", "3.98"]


def test_xi_at_delta_one_is_normalised_in_one_place() -> None:
    """ξ does not enter F at Δ = 1: every scene's model arguments (the sliders' and the lab setting's) carry ξ = 0
    there, through the one function app.params.model_args."""
    import re
    from pathlib import Path

    from asymslide import app
    from asymslide.app.params import SpectrumParams, model_args

    assert SpectrumParams(Delta=1.0, xi=5.0).model_args() == SpectrumParams(Delta=1.0, xi=0.0).model_args()
    assert SpectrumParams(Delta=0.5, xi=5.0).model_args()[-1] == 5.0
    assert model_args(3, 0.9, 0.3, float("inf"), 1, 2.0) == (3.0, 0.9, 0.3, float("inf"), 1.0, 0.0)
    rule = re.compile(r"0\.0 if .*Delta\W* == 1")
    written = [f"{p.name}:{i}" for p in Path(app.__file__).parent.glob("*.py")
               for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if rule.search(line)]
    assert written == [f"params.py:{model_args.__code__.co_firstlineno + 3}"], written
