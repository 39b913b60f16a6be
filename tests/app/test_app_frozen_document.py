"""`app.params.frozen_document`: one Bokeh model-graph walk per parameter change, and none when the graph
did not change -- but every model that did join the page is attached to the document."""

from __future__ import annotations

import holoviews as hv
import numpy as np
import pytest
from bokeh.document import Document
from bokeh.document.models import DocumentModelManager
from bokeh.models import ColumnDataSource, GlyphRenderer, Span
from panel.io.state import set_curdoc

from asymslide.app.declarations import set_frozen
from asymslide.app.spectrum import SpectrumScene
from asymslide.app.workarounds import frozen_document

pytestmark = pytest.mark.usefixtures("fresh_caches")


@pytest.fixture
def recomputes(monkeypatch) -> list[int]:
    """Counts calls of Bokeh's model-graph walk (DocumentModelManager.recompute) that really run."""
    calls: list[int] = []
    original = DocumentModelManager.recompute

    def counted(self) -> None:
        calls.append(1)
        original(self)

    monkeypatch.setattr(DocumentModelManager, "recompute", counted)
    return calls


def _served_im_plot() -> tuple[Document, SpectrumScene, object]:
    doc = Document()
    scene = SpectrumScene()
    plot = hv.renderer("bokeh").get_plot(scene.im_dmap, doc=doc)
    doc.add_root(plot.state)
    return doc, scene, plot


def _sources(plot) -> list[ColumnDataSource]:
    return [r.data_source for r in plot.state.renderers if isinstance(r, GlyphRenderer)]


def test_a_data_update_walks_nothing_and_sends_the_new_data(recomputes: list[int]) -> None:
    doc, scene, plot = _served_im_plot()
    before = [dict(s.data) for s in _sources(plot)]
    recomputes.clear()
    with set_curdoc(doc):
        set_frozen(scene.params, "gamma", 5.5)
    assert recomputes == []  # HoloViews froze the document for its refresh; no walk was needed
    after = [dict(s.data) for s in _sources(plot)]
    changed = [k for a, b in zip(after, before, strict=True) for k in a if not np.array_equal(a[k], b[k])]
    assert "Im[c/c_s]" in changed


def test_without_frozen_document_bokeh_walks_the_graph(recomputes: list[int]) -> None:
    """The control for the test above: the same change outside the context costs a walk per plot refresh."""
    doc, scene, _plot = _served_im_plot()
    recomputes.clear()
    with set_curdoc(doc):
        scene.params.gamma = 5.5
    assert len(recomputes) >= 1


def test_new_renderers_join_the_document_once(recomputes: list[int]) -> None:
    """A family of curves (a preset) adds glyph renderers: they are attached after one walk."""
    doc, scene, plot = _served_im_plot()
    n_before = len(_sources(plot))
    recomputes.clear()
    with set_curdoc(doc), frozen_document():
        scene.param.update(compare_key="gamma", compare_values=[2.0, 4.0])
    renderers = [r for r in plot.state.renderers if isinstance(r, GlyphRenderer)]
    assert len(renderers) > n_before
    assert all(doc.get_model_by_id(r.id) is r and r.document is doc for r in renderers)
    assert all(doc.get_model_by_id(r.data_source.id) is r.data_source for r in renderers)
    assert len(recomputes) == 1


def test_a_new_root_and_a_new_layout_model_are_attached(recomputes: list[int]) -> None:
    doc = Document()
    span = Span(location=1.0)
    with set_curdoc(doc), frozen_document():
        doc.add_root(span)
    assert doc.get_model_by_id(span.id) is span
    _, _, plot = _served_im_plot()
    doc2 = plot.state.document
    extra = Span(location=2.0)
    with set_curdoc(doc2), frozen_document():
        plot.state.add_layout(extra)
    assert doc2.get_model_by_id(extra.id) is extra


def test_nested_contexts_walk_at_most_once_at_the_outer_end(recomputes: list[int]) -> None:
    doc, scene, plot = _served_im_plot()
    recomputes.clear()
    with set_curdoc(doc), frozen_document():
        with frozen_document():
            plot.state.add_layout(Span(location=3.0))
        assert recomputes == []
    assert len(recomputes) == 1
    assert "invalidate" not in vars(doc.models) and "recompute" not in vars(doc.models)


def test_outside_a_document_it_is_a_no_op() -> None:
    scene = SpectrumScene()
    with set_curdoc(None), frozen_document():
        scene.params.gamma = 4.0
    assert scene.params.gamma == 4.0


def test_the_document_is_restored_after_an_exception() -> None:
    doc, scene, _plot = _served_im_plot()
    with pytest.raises(RuntimeError), set_curdoc(doc), frozen_document():
        raise RuntimeError("boom")
    assert "invalidate" not in vars(doc.models) and "recompute" not in vars(doc.models)
    extra = Span(location=4.0)
    doc.add_root(extra)  # Bokeh's own bookkeeping works as before
    assert doc.get_model_by_id(extra.id) is extra
