"""The Stability map's scene, :class:`StabilityMapScene`: its state (the parameters, the keys of what is shown, the
finished map, the sliding verdict, the preview of a held slider, the sliding boundary, Fig. 4c's sliding threshold),
the watchers that keep it current, its jobs (:mod:`app.jobs`), and the page. What it shows is built by the package's
other modules (:mod:`asymslide.app.stability_map`)."""

from __future__ import annotations

import io
import math
from functools import partial

import holoviews as hv
import panel as pn
import param

from .. import jobs
from .. import sliding_map as sm
from ..declarations import Choice
from ..exports import csv_download
from ..layout import controls_column, scene_layout
from ..params import SpectrumParams
from . import downloads, fig4c, held, map_jobs, map_plot, readout
from .compute import MapResult
from .grids import PLANE_WORDS, PLANES, RESOLUTIONS, key_for
from .preview import MapPreview


class StabilityMapScene(pn.viewable.Viewer):
    """Heat map of the maximal growth rate over a parameter plane, with Fig. 4c, for one :class:`SpectrumParams`."""

    params = param.ClassSelector(class_=SpectrumParams)
    plane = Choice("η-γ", objects=list(PLANES), label="Plane (x-y)", url="map", words=PLANE_WORDS)
    resolution = Choice("medium", objects=list(RESOLUTIONS), label="Resolution", url="map_res")
    verdict = Choice(sm.SLIDING, objects=[sm.SLIDING, sm.RAYLEIGH], label="Colour by", url="map_verdict",
                     words=sm.VERDICT_WORDS)
    floor = Choice(sm.AUTO, objects=list(sm.FLOORS), label="Growth floor (sliding)", url="map_floor")
    #: what the map depends on (see :func:`key_for`); changes only when the map must be recomputed
    map_key = param.Tuple(default=None, length=4, allow_None=True, precedence=-1)
    #: the last finished map (possibly for an older key)
    result = param.ClassSelector(class_=MapResult, allow_None=True, precedence=-1)
    #: what the sliding map depends on: the map's key and the floor
    sliding_key = param.Tuple(default=None, length=4, allow_None=True, precedence=-1)
    #: the last sliding map shown (a preview while its job runs; possibly for an older key)
    sliding = param.ClassSelector(class_=sm.SlidingMap, allow_None=True, precedence=-1)
    #: the sliding job: "idle", "computing", "done", "error: ..."
    sliding_status = param.String("idle", precedence=-1)
    #: "idle", "computing", "done", "error: ..."
    status = param.String("idle", precedence=-1)
    #: Fig. 4c's sliding threshold (every branch; compute_fig4c_sliding) for the f it was computed at; None: none yet
    fig4c_sliding = param.Dict(default=None, allow_None=True, precedence=-1)
    #: its job's progress in words ("" when shown complete)
    fig4c_sliding_status = param.String("", precedence=-1)
    #: while a slider is held: the map key of the held inputs where it differs from :attr:`map_key` (a preview of them
    #: is drawn in place of the map); None otherwise
    preview_key = param.Tuple(default=None, length=4, allow_None=True, precedence=-1)
    #: the last preview shown (possibly partial; see :meth:`StabilityMapScene._shown_preview` for when it is drawn)
    preview = param.ClassSelector(class_=MapPreview, allow_None=True, precedence=-1)
    #: the preview job: "idle", "computing", "done", "error: ..."
    preview_status = param.String("idle", precedence=-1)
    #: the boundary of sliding over every branch, exact in γ (app.sliding_boundary; its "key" is the sliding key it
    #: is of; possibly partial, "done" per column); None: none yet
    boundary = param.Dict(default=None, allow_None=True, precedence=-1)
    #: its job: "idle", "computing", "done", "error: ..."
    boundary_status = param.String("idle", precedence=-1)
    #: the Lab-units panel (an app.lab.LabScene, shared with the Spectrum scene) shown above the map; None: none
    lab = param.ClassSelector(class_=pn.viewable.Viewer, default=None, allow_None=True, precedence=-1)

    #: the URL holds the plane and resolution only where they differ from the defaults
    URL_CHANGED_ONLY = True


    def __init__(self, **kwargs):
        if "params" not in kwargs:
            kwargs["params"] = SpectrumParams()
        super().__init__(**kwargs)
        #: the background computation of the map (app.jobs): cancelled when the map's inputs change
        self.computation = jobs.Follower(partial(map_jobs.show_map_job, self))
        #: the background computation of the sliding verdict (coarse to fine): cancelled when its inputs change
        self.sliding_computation = jobs.Follower(partial(map_jobs.show_sliding_job, self))
        #: the background computation of Fig. 4c's sliding threshold: cancelled when f changes
        self.fig4c_computation = jobs.Follower(partial(map_jobs.show_fig4c_job, self))
        #: the background computation of the preview while a slider is held: cancelled at every move and the release
        self.preview_computation = jobs.Follower(partial(map_jobs.show_preview_job, self))
        #: the background computation of the exact sliding boundary (after the sliding map; planes with γ)
        self.boundary_computation = jobs.Follower(partial(map_jobs.show_boundary_job, self))
        self._fig4c_drawn = False  # whether Fig. 4c has been drawn (its sliding threshold is then kept current)
        self._last_preview_job: jobs.Job | None = None  # the next preview job starts computing once this one ended
        self._views: dict[tuple[str, str], hv.DynamicMap] = {}  # by (plane, verdict)
        self.tap_streams: dict[tuple[str, str], hv.streams.Tap] = {}  # by (plane, verdict)
        self.progress = pn.indicators.Progress(value=0, max=1, bar_color="primary", sizing_mode="stretch_width",
                                               height=18)
        self.progress_label = pn.pane.Markdown("", sizing_mode="stretch_width", margin=(0, 10))
        self.map_key = key_for(self.plane, self.resolution, self.params.model_args())
        self.sliding_key = self._sliding_key_for(self.map_key)
        self.params.param.watch(self._update_key, list(self.params.param))
        self.param.watch(self._update_key, ["plane", "resolution", "floor"])
        self.param.watch(self._key_changed, "map_key")
        self.param.watch(self._sliding_key_changed, "sliding_key")
        self.param.watch(self._verdict_changed, "verdict")
        self.fig4c_dmap = fig4c.fig4c_view(self)
        self.map_download = csv_download(self.map_csv, "stability_map.csv", "Download map (CSV)")
        self.map_download.disabled = True
        self.boundary_download = csv_download(self.boundary_csv, "stability_map_sliding_boundary.csv",
                                              "Download sliding boundary (CSV)")
        self.boundary_download.disabled = True
        self.boundary_download.width = 280
        self.fig4c_download = csv_download(self.fig4c_csv, "stability_fig4c.csv", "Download Fig. 4c (CSV)")

    # ----------------------------------------------------------------------------------------
    # keys and the background computation
    # ----------------------------------------------------------------------------------------


    def _update_key(self, *_events) -> None:
        """The map's and the sliding map's keys from the inputs. While a slider is held the keys wait for its
        release: the marker and the readout follow the hand, a preview of held inputs off the plane is computed
        (:func:`~.held.follow_held_inputs`), a whole map (seconds) is computed once, at the release."""
        if self.params.dragging:
            held.follow_held_inputs(self)
            return
        if self._fig4c_drawn:  # f may have moved under a held slider: Fig. 4c's sliding threshold follows now
            self.ensure_fig4c_sliding()
        key = key_for(self.plane, self.resolution, self.params.model_args())
        if key != self.map_key:
            self.map_key = key
        skey = self._sliding_key_for(key)
        if skey != self.sliding_key:
            self.sliding_key = skey
        held.release_preview(self)

    # ----------------------------------------------------------------------------------------
    # the preview while a slider is held
    # ----------------------------------------------------------------------------------------


    def _previewing(self) -> bool:
        """A slider is held at inputs off the map's: its preview (once computed) is drawn, the map's jobs' progress
        is not shown and the CSV is not offered."""
        return bool(self.params.dragging) and self.preview_key is not None

    def _preview_job_key(self, key: tuple) -> tuple:
        """What the preview of the held map key `key` depends on: the colouring and the growth floor too."""
        return (self.verdict, key, self._sliding_key_for(key)[-1])

    def ensure_preview(self) -> None:
        """While a slider is held at inputs off the map's, start their preview unless it is shown complete or being
        computed (called as the map is rendered: only a shown map computes). It starts computing once the previous
        preview job has stopped (:func:`after_previous`)."""
        map_jobs.start_preview(self)

    def wait_preview(self, timeout: float = 60.0) -> None:
        """Block until the preview being computed (if any) is finished, shown when not served (tests, scripts)."""
        self.preview_computation.wait(timeout)

    def _drop_preview(self, key_too: bool = False) -> None:
        """Stop and forget the preview (and, `key_too`, the held key): the map is drawn again."""
        held.drop_preview(self, key_too)

    def _shown_preview(self, plane: str | None = None, verdict: str | None = None) -> MapPreview | None:
        """The preview the map of `plane` coloured by `verdict` (defaults: the current ones) draws in place of the map:
        while a slider is held at inputs off the map's, the latest preview (of them, or of the previous held value
        until theirs is computed); after the release, the preview of the released inputs until their full map (or
        its sliding map's first pass) is shown. None: the map is drawn."""
        return held.shown_preview(self, plane, verdict)

    def _preview_drawn_over(self) -> None:
        """The full map (or the sliding map's first pass) of the released inputs is shown: their preview is
        dropped."""
        held.preview_drawn_over(self)

    def _key_changed(self, event: param.parameterized.Event) -> None:
        """Inputs changed: cancel a running computation (it stops after its chunk and is never shown); if one was
        running (the map is shown), start the new one at once (otherwise the next render starts it)."""
        job = self.computation.job
        running = job is not None and not job.state().finished
        self.computation.cancel()
        self._update_download()
        if running:
            self.ensure_map()

    def _current(self) -> bool:
        return self.result is not None and self.result.key == self.map_key

    def _sliding_key_for(self, key: tuple) -> tuple:
        """What the sliding map depends on: the map's key and the growth floor (for "auto", whether the map has
        finite η: its x axis, or the η fixed off the plane)."""
        plane, n, fixed, _ = key
        finite_eta = PLANES[plane][0].name == "eta" or any(k == "eta" and math.isfinite(v) for k, v in fixed)
        return (plane, n, fixed, sm.floor_value(self.floor, finite_eta))

    def colours_sliding(self) -> bool:
        """Whether the map is coloured by the sliding verdict (every branch), not the Rayleigh branch's growth."""
        return self.verdict == sm.SLIDING

    def _sliding_current(self) -> bool:
        """The sliding map of the current inputs is complete."""
        return self.sliding is not None and self.sliding.key == self.sliding_key and self.sliding.complete

    def _sliding_key_changed(self, _event: param.parameterized.Event) -> None:
        """The sliding map's inputs changed: cancel its job; restart at once if one was running."""
        job = self.sliding_computation.job
        running = job is not None and not job.state().finished
        self.sliding_computation.cancel()
        self.boundary_computation.cancel()
        self.param.update(sliding_status="idle", boundary_status="idle")
        self._update_download()
        if running:
            self.ensure_sliding()

    def _verdict_changed(self, _event: param.parameterized.Event) -> None:
        """Back to the Rayleigh branch: stop the sliding job (it is computed only while its map is shown)."""
        if not self.colours_sliding():
            self.sliding_computation.cancel()
            self.boundary_computation.cancel()
            self.param.update(sliding_status="idle", boundary_status="idle")
        if self.preview is not None or self.preview_computation.job is not None:
            self._drop_preview()  # a preview is of one colouring: a held slider's next render starts the other's
        if not self._previewing():
            map_jobs.name_progress(self)  # the label names the colouring shown, not the one left
        self._update_download()

    def ensure_sliding(self) -> None:
        """Start computing the sliding map of the current inputs unless it is shown complete or being computed."""
        map_jobs.start_sliding(self)

    def boundary_applies(self, plane: str | None = None) -> bool:
        """Whether the map coloured by the sliding verdict gets its exact boundary: on a plane whose y axis is γ."""
        return self.colours_sliding() and PLANES[plane or self.plane][1].name == "gamma"

    def _boundary_current(self) -> bool:
        b = self.boundary
        return b is not None and b["key"] == self.sliding_key and bool(b["done"].all())

    def ensure_boundary(self) -> None:
        """Start computing the exact boundary of sliding over every branch once the sliding map of the current
        inputs is complete (unless it is shown complete or being computed):
        :func:`app.sliding_boundary.compute_boundary` over the map's x values and γ range, in the background worker
        when served."""
        map_jobs.start_boundary(self)

    def wait_boundary(self, timeout: float = 300.0) -> None:
        """Block until the boundary being computed (if any) is finished, and show it when not served (tests)."""
        self.boundary_computation.wait(timeout)

    def _update_download(self) -> None:
        """Offer the CSVs that are what is shown (:func:`~.downloads.update_downloads`)."""
        downloads.update_downloads(self)

    def ensure_map(self) -> None:
        """Start computing the map of the current key unless it is shown or already being computed (called where the
        session may be modified: a render, a parameter change)."""
        map_jobs.start_map(self)

    def wait(self, timeout: float = 60.0) -> None:
        """Block until the map being computed (if any) is finished, and show it when not served (tests, scripts)."""
        self.computation.wait(timeout)

    # ----------------------------------------------------------------------------------------
    # the map plot (one DynamicMap per plane: the axes' scales differ)
    # ----------------------------------------------------------------------------------------


    def view(self, plane: str | None = None, verdict: str | None = None) -> hv.DynamicMap:
        """The map of `plane` coloured by `verdict` (defaults: the current ones): heat map * Rayleigh neutral curve *
        marker (:func:`~.map_plot.build_view`, built once); a click on the heat map (its Tap stream,
        :attr:`tap_streams`) sets the sliders."""
        plane, verdict = plane or self.plane, verdict or self.verdict
        if (plane, verdict) not in self._views:
            self._views[plane, verdict], self.tap_streams[plane, verdict] = map_plot.build_view(self, plane, verdict)
        return self._views[plane, verdict]

    def _neutral(self, plane: str, verdict: str | None = None, **_stream_values) -> hv.Overlay:
        """The map's neutral curves (:func:`~.map_plot.neutral`)."""
        return map_plot.neutral(self, plane, verdict)

    def marker_position(self, plane: str | None = None) -> tuple[float, float, list[str]]:
        """(x, y) of the sliders' values on the plane, clipped to its range, and notes on the clipping."""
        return map_plot.marker_position(self, plane)

    # ----------------------------------------------------------------------------------------
    # Fig. 4c
    # ----------------------------------------------------------------------------------------


    def ensure_fig4c_sliding(self) -> None:
        """Start computing Fig. 4c's sliding threshold at the current f unless it is shown or being computed
        (called as Fig. 4c is drawn: a render, a change of f)."""
        map_jobs.start_fig4c_sliding(self)

    def wait_fig4c(self, timeout: float = 120.0) -> None:
        """Block until Fig. 4c's sliding threshold (if computing) is finished, shown when not served (tests)."""
        self.fig4c_computation.wait(timeout)

    def fig4c_applies(self) -> bool:
        """Fig. 4c is for η = ∞ and Δ = 1: only then is the current χ = γ f comparable with χ_c."""
        return fig4c.fig4c_applies(self.params)

    @param.depends("params.gamma", "params.f", "params.beta", "params.eta_infinite", "params.Delta", "fig4c_sliding",
                   "fig4c_sliding_status")
    def fig4c_readout(self) -> str:
        """Fig. 4c's readout (:func:`~.fig4c.fig4c_readout`)."""
        return fig4c.fig4c_readout(self.params, self.fig4c_sliding, self.fig4c_sliding_status)

    # ----------------------------------------------------------------------------------------
    # readout and export
    # ----------------------------------------------------------------------------------------

    @param.depends("result", "map_key", "status", "sliding", "sliding_key", "sliding_status", "verdict",
                   "preview", "preview_key", "preview_status", "boundary", "boundary_status",
                   "params.gamma", "params.log10_eta", "params.eta_infinite",
                   "params.f", "params.beta", "params.Delta", "params.xi", "params.dragging")
    def readout(self) -> str:
        """The readout in words (:func:`~.readout.map_readout`)."""
        return readout.map_readout(self)

    def preview_lines(self) -> list[str]:
        """The readout's lines on a held slider and the preview drawn."""
        return readout.preview_lines(self)

    @param.depends("verdict", "preview", "preview_key", "sliding", "result")
    def legend(self) -> str:
        """The map's colour legend, for the verdict it is coloured by (and the preview's line while one is drawn)."""
        return readout.legend_text(self)

    def sliding_lines(self) -> list[str]:
        """The readout's lines on the sliding verdict (every branch) of the current map."""
        return readout.sliding_lines(self)

    def boundary_lines(self) -> list[str]:
        """The readout's lines on the exact boundary of sliding over every branch (purple)."""
        return readout.boundary_lines(self)

    def star_cell(self) -> tuple[int, int] | None:
        """(row, column) of the map's cell under the star (None: the star lies off the plane's range)."""
        return readout.star_cell(self)

    def star_cell_lines(self) -> list[str]:
        """The readout of the map's cell under the star: both verdicts there."""
        return readout.star_cell_lines(self)

    def _show_view(self, pane: pn.pane.HoloViews) -> None:
        """Show the view of the current plane and colouring, and start what it needs: a view shown again is not
        rendered again by HoloViews, so the render alone would leave a plane revisited "Not computed yet"."""
        pane.object = self.view()
        if not self._current():
            self.ensure_map()
        elif self.colours_sliding():
            self.ensure_sliding()
            self.ensure_boundary()

    def map_csv(self) -> io.StringIO:
        """What the map shows (:func:`~.downloads.map_csv`)."""
        return downloads.map_csv(self)

    def boundary_csv(self) -> io.StringIO:
        """The threshold of sliding over every branch drawn on the map (:func:`~.downloads.boundary_csv`)."""
        return downloads.boundary_csv(self)

    def fig4c_csv(self) -> io.StringIO:
        """What Fig. 4c shows at the current f (:func:`~.fig4c.fig4c_csv`)."""
        return fig4c.fig4c_csv(float(self.params.f), self.fig4c_sliding)

    # ----------------------------------------------------------------------------------------
    # layout
    # ----------------------------------------------------------------------------------------


    def __panel__(self) -> pn.viewable.Viewable:
        controls = controls_column(self.params.make_widgets(), self.readout)
        plane = pn.widgets.RadioButtonGroup.from_param(self.param.plane, color="primary", variant="outline")
        resolution = pn.widgets.RadioButtonGroup.from_param(self.param.resolution, color="light")
        verdict = pn.widgets.RadioButtonGroup.from_param(self.param.verdict, color="light")
        floor = pn.widgets.Select.from_param(self.param.floor, width=170,
                                             disabled=self.param.verdict.rx() != sm.SLIDING)
        map_pane = pn.pane.HoloViews(self.view(), sizing_mode="stretch_width")
        self.param.watch(lambda _e: self._show_view(map_pane), ["plane", "verdict"])
        plots = pn.Column(
            *([self.lab.panel(with_plot=False)] if self.lab is not None else []),
            pn.FlexBox(plane, resolution, flex_wrap="wrap", sizing_mode="stretch_width"),
            pn.FlexBox(pn.pane.Markdown("**Colour by**", margin=(12, 5, 0, 10)), verdict, floor, flex_wrap="wrap",
                       sizing_mode="stretch_width"),
            self.progress_label,
            self.progress,
            pn.pane.Markdown(self.legend, sizing_mode="stretch_width"),
            map_pane,
            pn.FlexBox(self.map_download, self.boundary_download, flex_wrap="wrap", sizing_mode="stretch_width"),
            pn.pane.HoloViews(self.fig4c_dmap, sizing_mode="stretch_width"),
            pn.pane.Markdown(self.fig4c_readout, sizing_mode="stretch_width"),
            self.fig4c_download,
            sizing_mode="stretch_width",
        )
        return scene_layout(controls, plots, "Stability map")
