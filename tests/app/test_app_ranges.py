"""Plot axes follow the data when the parameters change (HoloViews ``framewise``, set in app/params.py).

Each scene's DynamicMaps are rendered into a Bokeh document as the served app renders them; after a
parameter change that moves the curves far from where they started, every line and marker drawn
must lie inside its figure's y range (a range kept from the first frame cut the curves off).
"""

from __future__ import annotations

import numpy as np
import panel as pn
import pytest
from bokeh.document import Document
from bokeh.models import GlyphRenderer, Range1d

from asymslide.app.all_branches import AllBranchesScene
from asymslide.app.declarations import set_frozen
from asymslide.app.params import SpectrumParams
from asymslide.app.spectrum import SpectrumScene
from asymslide.app.thin_on_thick import ThinOnThickScene


@pytest.fixture
def doc():
    document = Document()
    previous = pn.state.curdoc
    pn.state.curdoc = document
    try:
        yield document
    finally:
        pn.state.curdoc = previous


def render(doc: Document, dmaps) -> list:
    for dmap in dmaps:
        doc.add_root(pn.pane.HoloViews(dmap).get_root(doc))
    return [m for m in doc.models if type(m).__name__ == "figure"]


def y_outside(fig) -> list[str]:
    """Glyphs of `fig` with finite y values outside its y range (empty when everything is in view)."""
    assert isinstance(fig.y_range, Range1d)
    lo, hi = sorted((fig.y_range.start, fig.y_range.end))
    out = []
    for r in fig.renderers:
        if not isinstance(r, GlyphRenderer) or not isinstance(getattr(r.glyph, "y", None), str):
            continue
        y = np.asarray(r.data_source.data.get(r.glyph.y, []), dtype=float)
        y = y[np.isfinite(y)]
        if y.size and (y.min() < lo - 1e-12 * abs(lo) or y.max() > hi + 1e-12 * abs(hi)):
            out.append(f"{fig.title.text[:30]!r} {r.name!r}: y in [{y.min():.4g}, {y.max():.4g}], "
                       f"axis [{lo:.4g}, {hi:.4g}]")
    return out


def check_all(figs) -> None:
    drawn = [fig for fig in figs if any(isinstance(r, GlyphRenderer) for r in fig.renderers)]
    assert drawn
    assert [msg for fig in drawn for msg in y_outside(fig)] == []


@pytest.mark.slow
def test_spectrum_axes_follow_the_branch(doc) -> None:
    scene = SpectrumScene()
    scene.wait_sliding()  # the fastest root of every branch drawn too (a background job)
    figs = render(doc, (scene.im_dmap, scene.re_dmap, scene.gy_dmap))
    check_all(figs)
    im_fig = next(f for f in figs if f.title.text == "Growth rate")
    end0 = im_fig.y_range.end
    set_frozen(scene.params, "gamma", 30.0)
    scene.wait_sliding()
    assert scene.sliding["max"] > 3 * end0  # the growth rate left the first frame's range
    check_all(figs)
    set_frozen(scene.params, "beta", 0.6)
    scene.wait_sliding()
    check_all(figs)


def test_thin_on_thick_axes_follow_the_curves(doc) -> None:
    scene = ThinOnThickScene()
    figs = render(doc, (scene.moduli_dmap, scene.nu_eff_dmap, scene.gy_dmap, scene.stress_dmap))
    check_all(figs)
    before = [(f.y_range.start, f.y_range.end) for f in figs]
    set_frozen(scene.params, "nu", 0.1)
    set_frozen(scene.params, "sigma0_MPa", 40.0)
    assert [(f.y_range.start, f.y_range.end) for f in figs] != before
    check_all(figs)


@pytest.mark.slow
def test_all_branches_axes_follow_the_roots(doc) -> None:
    params = SpectrumParams()
    scene = AllBranchesScene(params=params)
    figs = render(doc, (scene.zplane_dmap, scene.count_dmap))
    check_all(figs)
    set_frozen(params, "eta_infinite", False)
    set_frozen(params, "log10_eta", 1.0)
    set_frozen(params, "gamma", 15.0)
    check_all(figs)
