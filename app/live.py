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
of the live path (tests/app/test_app_spectrum.py) fail if that changes, and :func:`push` then returns False and the
scene falls back to the full redraw (correct, only slower).

Served, Bokeh sends every change of a model to the browser by itself; in a Jupyter notebook nothing does (Panel
sends the changes it makes itself through its comm): :func:`flush` sends what was written there
(``pn.io.push_notebook``; nothing to do outside a notebook).
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping, Sequence

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


#: which layer a pushed layer goes to: its legend label (every layer of that label), or (label, n): the n-th layer (from
#: 0, in the overlay's order) of that label, for layers that share one (e.g. markers without a legend entry, label "")
LayerKey = str | tuple[str, int]


def _key(layers: Mapping[LayerKey, Layer], label: object, n: int) -> LayerKey | None:
    """The key of `layers` that addresses the `n`-th rendered layer labelled `label`, or None."""
    if label in layers:
        return label  # type: ignore[return-value]
    return (label, n) if (label, n) in layers else None  # type: ignore[return-value]


def push(pane: pn.pane.HoloViews, layers: Mapping[LayerKey, Layer], *, empty_others: bool = False,
         title: str | None = None) -> bool:
    """Write `layers` (by legend label, or (label, n): :data:`LayerKey`) into every rendered copy of the overlay in
    `pane`, then run the overlay's hooks on what is drawn (e.g. :func:`app.plotting.fit_y_hook`,
    :func:`app.spectrum.band_legend_hook`: HoloViews runs them after each of its own updates; they read the Bokeh
    models, so they fit the data written here).
    `empty_others`: the other layers with a data source are emptied (they belong to inputs no longer shown).
    `title`: the plot's new title (a title that names the followed value). False if nothing is rendered or a layer
    was not found: the caller then redraws through HoloViews."""
    plots = rendered_plots(pane)
    if not plots:
        return False
    for plot in plots:
        found = set()
        seen: dict[object, int] = {}
        for subplot in plot.subplots.values():
            label = getattr(subplot.current_frame, "label", None)
            n = seen[label] = seen.get(label, -1) + 1
            key = _key(layers, label, n)
            if key is not None:
                if not _write(subplot, layers[key]):
                    return False
                found.add(key)
            elif empty_others and subplot.handles.get("source") is not None:
                source = subplot.handles["source"]
                source.data = {name: np.array([]) for name in source.data}
        if found != set(layers):
            return False
        if title is not None and plot.state.title is not None:
            plot.state.title.text = title
        for hook in plot.hooks:
            hook(plot, None)
    flush(pane)
    return True


def flush(pane: pn.viewable.Viewable) -> None:
    """Send the Bokeh models of `pane` written outside Panel (:func:`push`, a Bokeh pane's figure updated in place)
    to the notebook outputs that show it: a notebook has no server session to send them (Panel's
    ``push_notebook``); served or headless there is nothing to send."""
    pn.io.push_notebook(pane)


#: the follows of a held slider, over every session of a server process, run at most this often (each costs ~25 ms
#: of the process' one GIL): one session's drag of 20 moves a second is followed at every move; ten sessions dragging
#: at once share the rate, so the process keeps time for the releases, which are never delayed (docs/design-notes.md,
#: "Ten sessions dragging at once")
FOLLOWS_PER_SECOND = 24.0


class FollowBudget:
    """When the next follow may run: slots of 1 / `per_second` seconds, handed out in the order asked for."""

    def __init__(self, per_second: float) -> None:
        self.interval = 1.0 / per_second
        self._next = 0.0
        self._lock = threading.Lock()

    def reserve(self) -> float:
        """Take the next slot; seconds until it starts (0: now)."""
        with self._lock:
            now = time.monotonic()
            start = max(now, self._next)
            self._next = start + self.interval
            return start - now


#: the budget of this server process' follows
BUDGET = FollowBudget(FOLLOWS_PER_SECOND)


def schedule_follow(callback: Callable[[], None]) -> None:
    """Run `callback` (a session's follow of its held slider) on the session's event loop, in the next slot of
    :data:`BUDGET`: on the next turn, or after a timeout while other follows of this process use the slots before
    it. Not served: at once. A caller that coalesces moves makes the callback a no-op once a release has drawn."""
    doc = pn.state.curdoc
    if doc is None or doc.session_context is None:
        callback()
        return
    wait = BUDGET.reserve()
    wrapped = pn.state._handle_exception_wrapper(callback, doc)  # as pn.state.execute: curdoc set, errors shown
    if wait <= 0:
        doc.add_next_tick_callback(wrapped)
    else:
        doc.add_timeout_callback(wrapped, wait * 1000.0)


def _served() -> bool:
    """Whether this runs in a server session (its events are then handled on the session's event loop)."""
    doc = pn.state.curdoc
    return doc is not None and doc.session_context is not None


class Follow:
    """A scene's plots that follow its held sliders (a slider is held while its ``value`` differs from its
    ``value_throttled``, its value at the last release): each new value is written into the plots on the page by
    `follow` (:func:`push`; it returns False where it cannot: the plots are then redrawn by `redraw`, through
    HoloViews). Served, a held slider's moves are read on the next turn of the event loop (:meth:`defer`), at the
    values then current: moves that arrive meanwhile are each a cheap parameter change, and only the latest is read,
    drawn and read out (no backlog of stale frames); the release is followed at once (a slider's events hold the
    document's lock, which writing into Bokeh models needs). A change that comes from elsewhere (a preset, the URL, a
    typed value) is redrawn by `redraw`.

    `follow` returns True where the page shows the current values (also when nothing changed); `redraw` redraws what
    the page does not show yet (nothing when it shows the current values: a release at the last written position
    costs no HoloViews update)."""

    def __init__(self, follow: Callable[[], bool], redraw: Callable[[], None]) -> None:
        self._follow, self._redraw = follow, redraw
        self.sliders: list[pn.widgets.FloatSlider] = []
        self._following = False  # the plots follow a held slider (also after a release whose follow is pending)
        self._pending: Callable[[], None] | None = None  # a deferred reading of the scene's parameters

    def track(self, widgets: Mapping[str, pn.widgets.Widget]) -> None:
        """Follow the sliders among `widgets` (a scene's widgets, bound to its parameters)."""
        for widget in widgets.values():
            if isinstance(widget, pn.widgets.FloatSlider):
                self.sliders.append(widget)
                widget.param.watch(self._released, "value_throttled")

    def held(self) -> bool:
        """Whether one of the tracked sliders is held."""
        return any(slider.value != slider.value_throttled for slider in self.sliders)

    def defer(self, update: Callable[[], None]) -> bool:
        """While a tracked slider is held in a served session: `update` (the scene's reading of its parameters, which
        calls :meth:`changed`) runs on the next turn of the event loop, once for every move until then; True if
        deferred (else the caller updates now)."""
        if not (self.held() and _served()):
            return False
        self._following = True
        if self._pending is None:
            self._pending = update
            schedule_follow(self._run_pending)
        return True

    def _run_pending(self) -> None:
        update, self._pending = self._pending, None
        if update is not None:
            update()

    def changed(self) -> None:
        """The followed inputs changed: written while a slider is held or at its release, else redrawn."""
        held = self.held()
        following, self._following = held or self._following, held
        if not (following and self._follow()):
            self._redraw()

    def _released(self, _event) -> None:
        """A slider released (or set): the page shows the released values, written (a deferred reading runs now) or
        redrawn."""
        if self._pending is not None:
            self._run_pending()
        else:
            self.changed()
