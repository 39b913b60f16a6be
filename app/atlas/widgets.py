"""The Atlas tab's own widgets: the selects of the atlas, of the heat map's axes and of the 3-D view's axes (they show
the scene's state and pass on a user's choice only), the sliders of the other axes (snapping to the grid), and the
default atlas's progress (one labelled bar per phase)."""

from __future__ import annotations

import json
from collections.abc import Callable

import panel as pn
from bokeh.models import CustomJSTickFormatter

from .. import jobs
from .directory import PHASES, Atlas, atlas_dir, display_name


class Selects:
    """The atlas, x-axis, y-axis and 3-D-axes selects. They are the scene's own widgets (not ``from_param``), so a
    select never picks a value by itself while its options change (it did, half-way through opening the default
    atlas, and drew a slice with x = y). `on_choice(which, value)` gets a user's choice ("atlas", "x", "y" or
    "surface"), never a change made by :meth:`show`."""

    def __init__(self, on_choice: Callable[[str, object], None]) -> None:
        self.atlas = pn.widgets.Select(label="Atlas", options=[], sizing_mode="stretch_width")
        self.x = pn.widgets.Select(label="x axis", options={}, sizing_mode="stretch_width")
        self.y = pn.widgets.Select(label="y axis", options={}, sizing_mode="stretch_width")
        # a MultiChoice: the order of the picks is the order of the 3-D view's axes (and of the URL's surface=). Its
        # Choices.js box logs "Deprecation warning: allowHTML will default to false" in the console: Bokeh creates it
        # without that option (bokeh-widgets.js, MultiChoiceView.render) and the model has no property to pass it
        # (tests/browser/test_phone_layout.py ALLOWED_CONSOLE).
        self.surface = pn.widgets.MultiChoice(label="3-D axes (three)", options={}, max_items=3,
                                              sizing_mode="stretch_width", max_width=400)
        self._syncing = False
        for which, widget in (("atlas", self.atlas), ("x", self.x), ("y", self.y), ("surface", self.surface)):
            widget.param.watch(lambda e, which=which: None if self._syncing else on_choice(which, e.new), "value")

    def show(self, names: list[str], d: Atlas | None, atlas: str | None, x_axis: str | None, y_axis: str | None,
             surface_axes: list[str]) -> None:
        """Show the state in the selects (options and value in one update each; their watchers ignore it): the atlas
        directory's `names`, the open atlas `d` and the chosen atlas and axes. The y select never offers x."""
        labels = {d.label(n) + (" (log)" if d.log[n] else ""): n for n in d.names} if d is not None else {}
        self._syncing = True
        try:
            # readable labels, file names as values (the URL's atlas=NAME)
            self.atlas.param.update(options={display_name(n): n for n in names},
                                    value=atlas if atlas in names else None)
            self.x.param.update(options=labels, value=x_axis if x_axis in labels.values() else None,
                                disabled=len(labels) < 2)
            others = {k: v for k, v in labels.items() if v != x_axis}
            self.y.param.update(options=others, value=y_axis if y_axis in others.values() else None,
                                disabled=len(others) < 2)
            surface = [n for n in surface_axes if n in labels.values()]
            self.surface.param.update(options=labels, value=surface)
        finally:
            self._syncing = False


def index_sliders(d: Atlas | None, x_axis: str | None, y_axis: str | None, indices: dict[str, int],
                  on_index: Callable[[str, int], None]) -> list[pn.widgets.IntSlider]:
    """A slider per axis of `d` off the image, snapping to the grid: an index slider whose label and ticks show the
    grid value (a plain IntSlider: Panel's DiscreteSlider syncs an inner slider and a label on the server, which cost
    more than the heat map's update). `on_index(name, index)` gets every move."""
    widgets = []
    if d is not None:
        for name in d.names:
            if name in (x_axis, y_axis):
                continue
            labels = json.dumps([f"{v:.4g}" for v in d.axes[name]])
            slider = pn.widgets.IntSlider(label=d.label(name), start=0, end=max(len(d.axes[name]) - 1, 1),
                                          value=indices.get(name, 0), disabled=len(d.axes[name]) < 2,
                                          format=CustomJSTickFormatter(code=f"return {labels}[tick] ?? ''"),
                                          sizing_mode="stretch_width")
            # on `value`: the slice follows the handle while it is dragged (it reads the stored cube, no model
            # call: a slice costs a few ms)
            slider.param.watch(lambda e, n=name: on_index(n, e.new), "value")
            widgets.append(slider)
    return widgets


class DefaultProgress:
    """The default atlas's computation as a session shows it: a status line and, while it runs, one labelled bar per
    phase (the engine's task kinds, :data:`~asymslide.app.atlas.directory.PHASES`)."""

    def __init__(self) -> None:
        self.phases = {kind: (pn.pane.Markdown("", sizing_mode="stretch_width", margin=(0, 10)),
                              pn.indicators.Progress(value=0, max=100, bar_color="primary",
                                                     sizing_mode="stretch_width", height=18))
                       for kind in PHASES}
        self.bars = pn.Column(*(w for pair in self.phases.values() for w in pair), visible=False,
                              sizing_mode="stretch_width")
        self.status = pn.pane.Markdown("", sizing_mode="stretch_width")

    def show(self, state: jobs.JobState) -> None:
        """Show the job's state: the bars of its phases while it runs, else why it failed (its error, not a
        traceback), or nothing once it is done."""
        for kind, (label, bar) in self.phases.items():
            total, done = state.totals.get(kind, 0), min(state.done.get(kind, 0), state.totals.get(kind, 0))
            bar.value = int(100 * done / total) if total else 0
            label.object = f"{PHASES[kind]}: {done} of {total} grid points" if total else ""
            bar.visible = label.visible = bool(total)
        if state.status == jobs.FAILED:
            self.status.object = f"**Default atlas failed**: {state.error}"
        elif state.status == jobs.RUNNING:
            self.status.object = (f"**Computing the default atlas** (once; stored in {atlas_dir()}; about half a "
                                  "minute on two cores), in two phases:")
            return
        self.bars.visible = False
        if state.status == jobs.DONE:
            self.status.object = ""
