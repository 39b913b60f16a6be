"""Plots that follow a held slider: new data written straight into the Bokeh models HoloViews rendered.

A HoloViews update of one of the Spectrum's overlays costs 80-170 ms on the server (ranges, options and legends of
every layer are computed again; benchmarks/results.md "Live while dragging"), so a plot redrawn that way follows a
dragged slider at a few frames per second. While a slider is held, a scene instead writes the few arrays that
change into the data sources of the glyphs already on the page (a few ms; only the columns that changed are sent:
the kH column of a curve, or G_y(c_R) while γ or f moves, is not sent again) and runs the plot's own hooks again (the
y range fitted to what is drawn, the legend listing only the layers that show something): the page then shows what
a HoloViews redraw of the same inputs would show. At the release the scene needs no redraw when the last values
written are the released ones (app.spectrum.SpectrumScene._redraw).

This reads ``pn.pane.HoloViews._plots`` (the rendered plot of each root), which is not public Panel API: the tests
of the live path (tests/test_app_spectrum.py) fail if that changes, and :func:`push` then returns False and the
scene falls back to the full redraw (correct, only slower).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import panel as pn

#: what a layer is given: its columns in the order of its data source (a curve: x, y; spans: start, end), or a
#: number (a horizontal line's level; NaN hides it)
Layer = Sequence[np.ndarray] | float


def rendered_plots(pane: pn.pane.HoloViews) -> list:
    """The HoloViews plots `pane` has rendered (one per page it is on; none before it is shown)."""
    return [plot for plot, _ in getattr(pane, "_plots", {}).values()]


def _write(subplot, layer: Layer) -> bool:
    """Write `layer` into one rendered layer; False if the layer is not of a kind this knows."""
    if isinstance(layer, float):
        glyph = subplot.handles.get("glyph")
        if glyph is None or not hasattr(glyph, "location"):
            return False
        finite = bool(np.isfinite(layer))
        glyph.update(location=layer if finite else 0.0, visible=finite)
        return True
    source = subplot.handles.get("source")
    if source is None or len(source.data) != len(layer):
        return False
    new = {name: np.asarray(column) for name, column in zip(source.data, layer, strict=True)}
    if any(len(source.data[name]) != len(column) for name, column in new.items()):
        source.data = new  # a new length: every column at once (the page never sees columns of unequal lengths)
        return True
    changed = {name: column for name, column in new.items() if not _same(source.data[name], column)}
    if changed:  # only the columns that changed are sent (the kH column of a curve stays on the page)
        source.data.update(changed)
    return True


def _same(shown, column: np.ndarray) -> bool:
    """Whether a column on the page already holds `column` (NaN equal to NaN)."""
    shown = np.asarray(shown)
    if shown.shape != column.shape:
        return False
    try:
        return bool(np.array_equal(shown, column, equal_nan=True))
    except TypeError:  # not numbers (labels): compared as they are
        return bool(np.array_equal(shown, column))


def push(pane: pn.pane.HoloViews, layers: Mapping[str, Layer], *, empty_others: bool = False) -> bool:
    """Write `layers` (by legend label) into every rendered copy of the overlay in `pane`, then run the overlay's
    hooks on what is drawn (e.g. :func:`app.params.fit_y_hook`, :func:`app.spectrum.band_legend_hook`: HoloViews runs
    them after each of its own updates; they read the Bokeh models, so they fit the data written here).
    `empty_others`: the other layers with a data source are emptied (they belong to inputs no longer shown). False
    if nothing is rendered or a layer was not found: the caller then redraws through HoloViews."""
    plots = rendered_plots(pane)
    if not plots:
        return False
    for plot in plots:
        found = set()
        for subplot in plot.subplots.values():
            label = getattr(subplot.current_frame, "label", None)
            if label in layers:
                if not _write(subplot, layers[label]):
                    return False
                found.add(label)
            elif empty_others and subplot.handles.get("source") is not None:
                source = subplot.handles["source"]
                source.data = {name: np.array([]) for name in source.data}
        if found != set(layers):
            return False
        for hook in plot.hooks:
            hook(plot, None)
    return True
