"""Scene "Atlas": a stored stability atlas (``asymslide sweep``), explored slice by slice.

An atlas is the Rayleigh branch's maximal growth rate on an N-D grid of (γ, f, β, η, Δ, ξ), with the exact threshold
γ_c over the other axes (atlas/schema.py; docs/physics.md §9). This scene shows any two axes as a heat map of the
growth with the neutral curve (growth = 0) and, where γ is one of the two, the slice of the γ_c surface; the other axes
are sliders that snap to the grid. A slice change only reads the stored cube (no model function is called). A 3-D
view shows the neutral surface (growth = 0) over three chosen axes, and a click on a cell sets the shared parameters
of the other scenes to that cell.

The scene holds the state and wires it to the page; what it shows is built by its package's other modules
(asymslide.app.atlas: directory, request, slicing, heatmap, surface_view, readout, widgets).
"""

from __future__ import annotations

import io
import math

import panel as pn
import param

from .. import jobs, live
from .. import sliding_map as slm
from ..exports import csv_table
from ..layout import heading, scene_layout
from ..params import SpectrumParams
from ..workarounds import frozen_document
from . import surface_view
from .directory import Atlas, atlas_dir, default_name, default_ready, ensure_default, list_atlases, load
from .heatmap import HEIGHT, HeatMap, help_text
from .readout import atlas_readout
from .request import AtlasRequest, opened_state, two_axes
from .slicing import Slice
from .surface_view import SURFACE_ASPECT, SURFACE_CONFIG, SURFACE_MAX_HEIGHT, SURFACE_MIN_HEIGHT
from .widgets import DefaultProgress, Selects, index_sliders


class AtlasScene(pn.viewable.Viewer):
    """Heat map of a slice of an atlas, sliders over the other axes, the 3-D neutral surface, and the readout.

    The state (which atlas, the two axes of the heat map, the grid index of every other axis, the three axes of the
    3-D view) is set in one update when an atlas opens, and the selects show it (:class:`~.widgets.Selects`: the
    scene's own widgets, which never pick a value by themselves while their options change). The y select never
    offers the x axis; choosing the y axis as x swaps the two."""

    params = param.ClassSelector(class_=SpectrumParams, doc="the shared parameters a click sets")
    atlas = param.String(default=None, allow_None=True, label="Atlas")
    x_axis = param.String(default=None, allow_None=True, label="x axis")
    y_axis = param.String(default=None, allow_None=True, label="y axis")
    surface_axes = param.List(default=[], item_type=str, label="3-D axes (three)")
    #: grid index of every axis (those of the image are ignored); the sliders set it
    indices = param.Dict(default={}, precedence=-1)
    #: the loaded atlas (None until one is ready)
    data = param.ClassSelector(class_=Atlas, allow_None=True, precedence=-1)
    message = param.String(default="", precedence=-1)
    #: True while the 3-D view is shown (it is computed only then)
    surface_shown = param.Boolean(default=False, precedence=-1)
    #: what the heat map is coloured by, in an atlas swept with --sliding (app.sliding_map's SLIDING, RAYLEIGH)
    verdict = param.Selector(default=slm.SLIDING, objects=[slm.SLIDING, slm.RAYLEIGH], label="Colour by")

    def __init__(self, **kwargs):
        requested = kwargs.pop("requested", None)
        if "params" not in kwargs:
            kwargs["params"] = SpectrumParams()
        super().__init__(**kwargs)
        if isinstance(requested, dict):
            requested = AtlasRequest(**requested)
        self._requested = requested if isinstance(requested, AtlasRequest) else AtlasRequest(name=requested)
        # the widgets the layout shows, by name (built in app/atlas/widgets.py)
        self.default_progress = DefaultProgress()
        self.phases, self.progress = self.default_progress.phases, self.default_progress.bars
        self.status = self.default_progress.status
        self.alert = pn.pane.Alert("", alert_type="warning", visible=False, sizing_mode="stretch_width")
        self.sliders = pn.Column(sizing_mode="stretch_width")
        self.selects = Selects(self._from_widget)
        self.atlas_select, self.x_select, self.y_select = self.selects.atlas, self.selects.x, self.selects.y
        self.surface_select = self.selects.surface
        #: the default atlas's computation this session shows (app.jobs; the job is shared by the sessions)
        self.computation = jobs.Follower(self._show_default)
        self._surface_key: tuple | None = None
        # the figure of the current atlas and axes (a new one per pair: Panel cannot show a Bokeh figure again once
        # it has left the page, its stylesheets raise a TypeError and the pane keeps the old figure)
        self._figure: HeatMap | None = None
        self.image_pane = pn.pane.Bokeh(None, sizing_mode="stretch_width", height=HEIGHT)
        self.param.watch(self._show_heat_map, ["data", "x_axis", "y_axis"])
        self.param.watch(self._slice_changed, ["indices", "verdict"])
        self.verdict_select = pn.widgets.RadioButtonGroup.from_param(self.param.verdict, color="light", visible=False)
        self.param.watch(lambda e: setattr(self.verdict_select, "visible", bool(e.new is not None
                                                                                and e.new.has_sliding)), "data")
        self.surface_pane = pn.pane.Plotly(None, sizing_mode="scale_width", aspect_ratio=SURFACE_ASPECT,
                                           min_height=SURFACE_MIN_HEIGHT, max_height=SURFACE_MAX_HEIGHT,
                                           config=dict(SURFACE_CONFIG))
        self.param.watch(self._atlas_changed, "atlas")
        self.param.watch(self._axes_changed, ["x_axis", "y_axis"])
        self.param.watch(self._sync_widgets, ["atlas", "data", "x_axis", "y_axis", "surface_axes"])
        self.param.watch(self._update_surface, ["data", "surface_axes", "indices", "surface_shown"])
        self.param.watch(lambda e: self._show(e.new), "message")

    def url_state(self) -> dict[str, object]:
        """What a URL needs to show this view again (app.urlstate.atlas_query): the atlas, the two axes, the other
        axes' grid values and the 3-D axes; before an atlas is open, what was requested."""
        d = self.data
        if d is None:
            r = self._requested
            return {"name": r.name, "x": r.x, "y": r.y, "at": dict(r.at), "surface": r.surface,
                    "verdict": r.verdict}
        at = {n: float(d.axes[n][self.indices.get(n, 0)]) for n in d.names if n not in (self.x_axis, self.y_axis)}
        return {"name": d.name, "x": self.x_axis, "y": self.y_axis, "at": at, "surface": tuple(self.surface_axes),
                "verdict": self.verdict if d.has_sliding else None}

    # -- which atlas --------------------------------------------------------------------------

    def refresh(self) -> None:
        """Re-list the atlas directory; open the requested atlas, else keep the current one, else the default.

        Not done when the scene is created (a page pays for this tab only when it is shown): :meth:`__panel__`
        does it, and tests call it."""
        names = list_atlases()
        self._names = names
        want = self._requested.name or self.atlas
        if want is not None and want not in names:
            self.message = (f"atlas '{want}' is not in {atlas_dir()} (available: {', '.join(names) or 'none'}): "
                            "showing the default atlas")
            want = None
            self._requested = AtlasRequest()
        if want is None and default_ready():
            want = default_name()
        self._sync_widgets()
        if want is not None and want in names:
            if self.atlas == want and self.data is None:
                self._atlas_changed()
            self.atlas = want

    def start_default(self) -> None:
        """Open the default atlas, or follow its computation (shared by the sessions of this process) with a labelled
        progress bar per phase, and open it when it is done (called when the tab is shown; without a server,
        :meth:`wait` waits for it)."""
        if self.data is not None or (self.atlas is not None and self.atlas != default_name()):
            return
        if default_ready():
            self.refresh()
            return
        self.progress.visible = True
        self.computation.follow(ensure_default())

    def wait(self, timeout: float | None = None) -> None:
        """Block until the default atlas being computed (if any) is done, and open it when not served (tests,
        scripts)."""
        self.computation.wait(timeout)

    def _show_default(self, _job: jobs.Job, state: jobs.JobState) -> None:
        """Show the default atlas's progress, one labelled bar per phase; open it when it is done (on the session's
        event loop; a failed computation is started again only when the tab is shown again)."""
        self.default_progress.show(state)
        if state.status == jobs.DONE:
            self.refresh()

    def _atlas_changed(self, *_events) -> None:
        """Open the atlas and set the whole state at once: its axes (the requested ones, else the current ones if it
        has them, else its first two), the other axes' grid indices and the 3-D axes."""
        if self.atlas is None:
            return
        try:
            data = load(self.atlas)
        except (OSError, ValueError, KeyError) as exc:
            self.message = f"atlas '{self.atlas}' could not be read: {exc}"
            return
        request, self._requested = self._requested, AtlasRequest()
        state, message = opened_state(data, request, self.x_axis, self.y_axis, self.verdict)
        with param.parameterized.batch_call_watchers(self):
            self.param.update(**state)
        self._rebuild_sliders()
        if message:
            self.message = message

    def _from_widget(self, which: str, value) -> None:
        """A select changed by the user: set the state (the y select never offers x; x = y swaps the two)."""
        if which == "atlas":
            if value is not None and value != self.atlas:
                self.atlas = value
        elif which == "surface":
            self.surface_axes = list(value)
        elif self.data is not None and value is not None:
            x, y = (value, self.y_axis) if which == "x" else (self.x_axis, value)
            if x == y:  # x chosen as the y axis: swap
                y = self.x_axis
            x, y = two_axes(self.data.names, x, y)
            with frozen_document():
                self.param.update(x_axis=x, y_axis=y)

    def _sync_widgets(self, *_events) -> None:
        """Show the state in the selects (their watchers ignore it)."""
        self.selects.show(getattr(self, "_names", []), self.data, self.atlas, self.x_axis, self.y_axis,
                          self.surface_axes)

    def _axes_changed(self, *_events: param.parameterized.Event) -> None:
        self._rebuild_sliders()

    def _rebuild_sliders(self) -> None:
        """A slider per axis off the image, snapping to the grid (:func:`widgets.index_sliders`)."""
        self.sliders.objects = index_sliders(self.data, self.x_axis, self.y_axis, self.indices, self._set_index)

    def _set_index(self, name: str, index: int) -> None:
        with frozen_document():
            self.indices = {**self.indices, name: int(index)}

    # -- the slice ----------------------------------------------------------------------------

    def current_slice(self) -> Slice | None:
        """The slice shown (None until an atlas and its axes are set): what the heat map, the readout, a click and
        the CSV read."""
        if self.data is None or self.x_axis is None:
            return None
        return Slice(self.data, self.x_axis, self.y_axis, self.indices)

    def slice2d(self, variable: str | None = None):
        """(x, y, growth[y, x]) of the current slice, in display coordinates, or of another of the store's variables
        (:meth:`Slice.values`)."""
        s = self.current_slice()
        assert s is not None
        return s.values(variable)

    def heat_map(self) -> HeatMap | None:
        """The figure of the current atlas and pair of axes, built when the pair changes; None until an atlas and
        two different axes of it are chosen."""
        d = self.data
        if d is None or self.x_axis not in d.names or self.x_axis == self.y_axis or (
                self.y_axis is not None and self.y_axis not in d.names):
            return None
        heat = self._figure
        if heat is None or heat.atlas is not self.data or (heat.x_axis, heat.y_axis) != (self.x_axis, self.y_axis):
            self._figure = heat = HeatMap(self.data, self.x_axis, self.y_axis, self._on_tap)
        return heat

    def _show_heat_map(self, *_events) -> None:
        """Put the current figure in the pane and draw the current slice into it."""
        heat = self.heat_map()
        if heat is None:
            return
        self._draw(heat)
        if self.image_pane.object is not heat.figure:
            self.image_pane.object = heat.figure
        else:
            live.flush(self.image_pane)  # in a notebook: the figure drawn in place (served, Bokeh sends it)

    def colours_sliding(self) -> bool:
        """Whether the heat map shows the sliding verdict over every branch (the atlas has it, and it is chosen)."""
        return self.data is not None and self.data.has_sliding and self.verdict == slm.SLIDING

    def _draw(self, heat: HeatMap) -> None:
        """Draw the current slice into the heat map (:meth:`HeatMap.draw`)."""
        heat.draw(self.current_slice(), self.colours_sliding())

    def _slice_changed(self, *_events) -> None:
        heat = self.heat_map()
        if heat is not None and self.image_pane.object is heat.figure:
            with frozen_document():
                self._draw(heat)
            live.flush(self.image_pane)  # in a notebook: the figure drawn in place (served, Bokeh sends it)

    # -- a click sets the shared parameters ----------------------------------------------------

    def _on_tap(self, x: float | None = None, y: float | None = None) -> None:
        if self.data is None or x is None or (y is None and self.y_axis is not None):
            return
        cell = self.current_slice()
        values = cell.cell_parameters(x, 0.0 if y is None else y)
        updates: dict[str, float | bool] = {}
        notes = []
        for name, v in values.items():
            if name == "eta":
                if math.isinf(v):
                    updates["eta_infinite"] = True
                    continue
                decl, key, target = SpectrumParams.param.log10_eta, "log10_eta", math.log10(v)
                updates["eta_infinite"] = False
            else:
                decl, key, target = SpectrumParams.param[name], name, v
            lo, hi = decl.bounds
            clamped = min(max(target, lo), hi)
            if clamped != target:
                notes.append(f"{SpectrumParams.symbol(name)} = {v:.4g} is outside the sliders' range: set to the "
                             "nearest end")
            updates[key] = clamped
        with frozen_document():
            self.params.param.update(**updates)
        text = ", ".join(f"{SpectrumParams.symbol(k)} = {'∞' if math.isinf(v) else f'{v:.4g}'}"
                         for k, v in values.items())
        self.message = (f"Parameters set from the atlas cell: {text}." + cell.cell_verdicts(x, y)
                        + (" " + "; ".join(notes) if notes else ""))

    def _show(self, text: str) -> None:
        self.alert.object = text
        self.alert.alert_type = "info" if text.startswith("Parameters set") else "warning"
        self.alert.visible = bool(text)

    # -- 3-D neutral surface ------------------------------------------------------------------

    def surface_figure(self) -> dict | None:
        """The 3-D view's Plotly figure (dict) over the three chosen axes, the others at the sliders' values
        (:func:`surface_view.surface_figure`); None without three axes."""
        return surface_view.surface_figure(self.data, self.surface_axes, self.indices)

    def surface_key(self) -> tuple | None:
        """What the 3-D view depends on: the atlas, the three axes and the indices of the other axes."""
        d = self.data
        if d is None or len(self.surface_axes) != 3:
            return None
        return (d.name, tuple(self.surface_axes),
                tuple((n, self.indices.get(n, 0)) for n in d.names if n not in self.surface_axes))

    def _update_surface(self, *_events) -> None:
        """Rebuild the 3-D view only when what it shows changed (a slider of one of its own axes does not), after
        the heat map's update has been sent (the figure is the larger message)."""
        drawable = self.data is None or len(self.data.names) >= 3  # else surface_note says why there is no view
        self.surface_pane.visible = self.surface_select.visible = drawable
        key = self.surface_key() if self.surface_shown else self._surface_key
        if key == self._surface_key:
            return
        self._surface_key = key
        doc = pn.state.curdoc
        if doc is not None and doc.session_context is not None:
            doc.add_next_tick_callback(self._send_surface)
        else:
            self._send_surface()

    @param.depends("data")
    def surface_note(self) -> str:
        """Why an atlas of fewer than three axes has no 3-D view (empty otherwise)."""
        return surface_view.surface_note(self.data)

    def _send_surface(self) -> None:
        fig = self.surface_figure()
        self.surface_pane.object = None  # replaced, not compared element by element with the previous figure
        self.surface_pane.object = fig

    # -- readout and export --------------------------------------------------------------------

    @param.depends("data", "x_axis", "y_axis", "indices")
    def slice_readout(self) -> str:
        """The current slice: how much of it is unstable or masked."""
        s = self.current_slice()
        return "" if s is None else s.readout(self.colours_sliding())

    @param.depends("data")
    def readout(self) -> str:
        """The whole atlas: its grid, provenance and coverage (:func:`readout.atlas_readout`)."""
        return atlas_readout(self.data)

    @param.depends("data", "verdict")
    def help_text(self) -> str:
        """The heat map's legend, for what it is coloured by."""
        return help_text(self.data, self.colours_sliding())

    def slice_description(self) -> str:
        """The current slice in words: the atlas, the two axes, the other axes' values and the fixed ones."""
        s = self.current_slice()
        return "none loaded" if s is None else s.description()

    def csv(self) -> io.StringIO:
        """The current slice as CSV (:meth:`Slice.csv`)."""
        s = self.current_slice()
        if s is None:
            return csv_table("asymslide atlas slice (none loaded)", {"x": [], "y": [], "max_growth": []})
        return s.csv()

    # -- layout -------------------------------------------------------------------------------

    def __panel__(self) -> pn.viewable.Viewable:
        """The tab (built when first shown): opens the requested or default atlas, computing the default atlas
        in the background if it is not there yet."""
        self.refresh()
        self.start_default()
        # the readouts that change with a slider have a fixed size: a div that grows would make the browser lay
        # out the page again (and resize the 3-D plot), which cost more than the heat map's own update
        choose = pn.Column(
            self.atlas_select, self.x_select, self.y_select, self.verdict_select,
            heading("Other axes"), self.sliders,
            # a fixed height (a slice change does not move the panes below); longer readouts (both verdicts of an
            # adaptive atlas) scroll inside it instead of running over the next pane
            pn.pane.Markdown(self.slice_readout, sizing_mode="stretch_width", height=190,
                             styles={"overflow-y": "auto"}),
            pn.pane.Markdown(self.readout, sizing_mode="stretch_width"),
            width=340,
        )
        help_text = pn.pane.Markdown(self.help_text, sizing_mode="stretch_width")
        self._show_heat_map()
        heat = pn.Column(self.image_pane,
                         pn.widgets.FileDownload(callback=self.csv, filename="atlas_slice.csv",
                                                 label="Download slice (CSV)", color="primary", width=200),
                         sizing_mode="stretch_width")
        surface = pn.Column(
            pn.pane.Markdown(self.surface_note, sizing_mode="stretch_width"),
            self.surface_select,
            pn.pane.Markdown("The surface where the max growth is 0 over three axes of the atlas, the others at the "
                             "sliders' values (none is drawn through cells with a not computable corner); drag to "
                             "rotate, scroll to zoom.", sizing_mode="stretch_width"),
            self.surface_pane, sizing_mode="stretch_width")
        # the 3-D view in its own tab: rendered (and recomputed) only while shown, so a slice change repaints the
        # heat map alone
        views = pn.Tabs(("Heat map", heat), ("3-D neutral surface", surface), dynamic=True,
                        sizing_mode="stretch_width")
        views.param.watch(lambda e: setattr(self, "surface_shown", e.new == 1), "active")
        plots = pn.Column(self.alert, self.status, self.progress, help_text, views, sizing_mode="stretch_width")
        return scene_layout(choose, plots, "Atlas")
