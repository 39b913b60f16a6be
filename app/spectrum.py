"""Scene "Spectrum" (paper Sect. IV, Fig. 4a-b): the Rayleigh branch c/c_s(kH) and its stability, beside the fastest
root of every branch (sliding, docs/physics.md §14: computed in the background, :mod:`app.jobs`).

The app computes no physics: :func:`compute_spectrum` only calls the public API of :mod:`model`
(cached with ``pn.cache``), and the plots are HoloViews DynamicMaps over parameter-dependent
methods, so they update in place.
"""

from __future__ import annotations

import functools
import io
import math
from functools import partial

import holoviews as hv
import numpy as np
import panel as pn
import param

from asymslide import model

from . import jobs, live, sliding_work
from .common import FAMILY_NAMES
from .exports import csv_download, csv_table
from .layout import EQUATION_STYLES, controls_column, placeholder, scene_layout
from .params import SpectrumParams
from .plotting import PALETTE, fit_y_hook, fmt, zero_line_hook

#: kH grid of the plots
KH = np.logspace(-3, 3, 400)

#: heights (px) of the growth-rate, phase-velocity and G_y plots
PLOT_HEIGHTS = (360, 300, 260)

#: the dispersion relation whose Rayleigh-branch root z(kH) is plotted (rendered by KaTeX)
EQUATION = (r"$F(z;\,kH) = \gamma\,\big(G_x + i f\,G_y\big) + i z\left[1 + \frac{\Delta - 1}{1 - i\,\xi\,z\,kH}\right]"
            r" = 0, \qquad z = c/c_s$")

IM_LABEL = "Im[c/c_s]"
RE_LABEL = "Re[c/c_s]"
GY_LABEL = "G_y(c_R, kH)"

#: options shared by the three plots (besides title, height, legend position and y label): the same kH range, the
#: computed one (HoloViews padded the growth-rate plot's alone to 2.5e-4 ... 4e3)
OVERLAY = dict(logx=True, responsive=True, framewise=True, xlabel="kH", xlim=(float(KH[0]), float(KH[-1])))


@functools.cache
def styled(kind: type[hv.Element], vdim: str, label: str = "", **style: object) -> hv.Element:
    """An empty `kind` element (Curve, VSpans or HLine; `vdim` names a curve's y) with its style applied once.

    The plot callbacks ``clone`` it with data; a clone keeps the style (HoloViews looks options up by
    the element's id), which is several times cheaper than setting the same options on a new curve in
    every update (benchmarks/design_measurements.md).
    """
    if kind is hv.HLine:
        return hv.HLine(0.0, label=label).opts(**style)
    if kind is hv.VSpans:  # its x named kH: a default name ("x0") linked it to other plots' spans (the lab panel's)
        return hv.VSpans([], kdims=["kH", "kH_end"], label=label, datatype=["dictionary"]).opts(**style)
    return kind(([], []), "kH", vdim, label=label, datatype=["dictionary"]).opts(**style)


#: the legend labels of the unstable band and of the criterion's level in the G_y plot
BAND_LABEL = "unstable band"
CRITERION_LABEL = "criterion −c_R/(c_s γ f)"


#: legend entries listed only while their element holds data (the band; the families of the fastest root)
OPTIONAL_LEGEND = {BAND_LABEL, *(f"fastest root: {v.split(' (')[0]}" for v in model.FAMILIES.values()),
                   "max growth, every branch (sliding)", "fastest root, every branch", "linear expansion"}


def linear_layer(d: dict, part: str) -> tuple[np.ndarray, np.ndarray]:
    """(kH, real or imaginary part) of the linear expansion of a :func:`compute_spectrum` result; empty where it is
    not defined (Δ ≠ 1): no line, and no legend entry (:func:`band_legend_hook`)."""
    linear = d["linear"]
    if not np.isfinite(linear).any():
        return np.array([]), np.array([])
    return d["kH"], getattr(linear, part)


def band_legend_hook(plot, _element) -> None:
    """HoloViews plot hook: the legend lists the unstable band (and each family of the fastest root) only while
    there is one."""
    for legend in plot.state.legend:
        for item in legend.items:
            if getattr(item.label, "value", None) in OPTIONAL_LEGEND:
                item.visible = any(len(next(iter(r.data_source.data.values()), [])) for r in item.renderers)


#: kH of the fastest root of every branch (the markers of the growth-rate plot): over the sliding verdict's range
KH_ALL = np.logspace(math.log10(model.SLIDING_KH[0]), math.log10(model.SLIDING_KH[-1]), 33)
#: colour of each family of roots (model.FAMILIES) in the growth-rate plot
FAMILY_COLOURS = {0: "#1f4e79", 1: "#7b3294", 2: "#e08214", 3: "#1b7837"}


def _family_points(code: int) -> hv.Scatter:
    return hv.Scatter(([], []), "kH", IM_LABEL, label=f"fastest root: {FAMILY_NAMES[code]}").opts(
        color=FAMILY_COLOURS[code], size=6, marker="circle", alpha=0.85)


#: room above the data of the growth-rate plot for its legend (fraction of the data's span): the legend has up to
#: three rows there, and the fastest roots are often the highest points of the plot
LEGEND_ROOM = 0.6


def legend_room_hook(plot, _element) -> None:
    """HoloViews plot hook (after :func:`fit_y_hook`): the y range reaches :data:`LEGEND_ROOM` higher, so that the
    legend (top left) covers no data."""
    y = plot.state.y_range
    if y.start is not None and y.end is not None and y.end > y.start:
        y.update(end=y.end + LEGEND_ROOM * (y.end - y.start))


#: the styled templates of the plotted elements
STYLE = {
    "band": styled(hv.VSpans, IM_LABEL, BAND_LABEL, color="#f4a582", alpha=0.35),
    "im branch": styled(hv.Curve, IM_LABEL, "Rayleigh branch", color="#1f4e79", line_width=2),
    "im linear": styled(hv.Curve, IM_LABEL, "linear expansion", color="#b2182b", line_dash="dashed", line_width=1.5),
    "re branch": styled(hv.Curve, RE_LABEL, "Rayleigh branch", color="#1f4e79", line_width=2),
    "re linear": styled(hv.Curve, RE_LABEL, "linear expansion", color="#b2182b", line_dash="dashed", line_width=1.5),
    "gy": styled(hv.Curve, GY_LABEL, "G_y(c_R, kH)", color="#1f4e79", line_width=2),
    "criterion": styled(hv.HLine, GY_LABEL, CRITERION_LABEL, color="#b2182b", line_dash="dashed",
                        line_width=1.5),
    "all line": styled(hv.Curve, IM_LABEL, "fastest root, every branch", color="#777777", line_width=1,
                       line_dash="dotted"),
    **{f"all {k}": _family_points(k) for k in model.FAMILIES},
    "all max": hv.Scatter(([], []), "kH", IM_LABEL, label="max growth, every branch (sliding)").opts(
        color="#b2182b", size=16, marker="star", line_color="black"),
}


def styled_overlay(**options: object) -> hv.Overlay:
    """An empty Overlay with the plot `options` applied once; the plot callbacks ``clone`` it with their
    layers, which keeps the options (looked up by the overlay's id) without applying them, and
    registering a new option tree, on every update (benchmarks/design_measurements.md)."""
    return hv.Overlay([]).opts(hv.opts.Overlay(**options))


#: the growth-rate plot's options (set on its DynamicMap: it overlays two, see SpectrumScene)
IM_OVERLAY = dict(title="Growth rate", height=PLOT_HEIGHTS[0], legend_position="top_left", legend_cols=3,
                  legend_opts={"background_fill_alpha": 0.6}, ylabel=IM_LABEL,
                  hooks=[zero_line_hook, band_legend_hook, fit_y_hook, legend_room_hook], **OVERLAY)

#: the styled overlays of the three plots (growth rate, phase velocity, G_y criterion)
OVERLAYS = {
    "im": styled_overlay(**IM_OVERLAY),
    "re": styled_overlay(title="Phase velocity", height=PLOT_HEIGHTS[1], legend_position="top_right",
                         ylabel=RE_LABEL, hooks=[band_legend_hook, fit_y_hook], **OVERLAY),
    "gy": styled_overlay(height=PLOT_HEIGHTS[2], legend_position="bottom_right",
                         title="Slip–normal-stress coupling at c = c_R (unstable approx. where G_y is below the "
                               "dashed line)", ylabel=GY_LABEL, hooks=[zero_line_hook, fit_y_hook], **OVERLAY),
}


#: model-argument index and symbol of each parameter a family of curves can vary (preset 'compare')
FAMILY = {name: (i, SpectrumParams.symbol(name)) for i, name in enumerate(SpectrumParams.MODEL_ARGS)}


@pn.cache(max_items=64)
def compute_spectrum(gamma: float, f: float, beta: float, eta: float, Delta: float, xi: float) -> dict:
    """Rayleigh branch, linear expansion (Delta == 1 only) and growth analysis on :data:`KH`."""
    p = dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    branch = model.rayleigh_branch(KH, **p)
    out = {"kH": KH, "z": branch.z, "status": branch.status, "error": branch.error}
    if Delta == 1:
        out["linear"] = model.linear_expansion(KH, gamma=gamma, f=f, beta=beta, eta=eta)
    else:
        out["linear"] = np.full(KH.shape, complex(np.nan, np.nan))  # none (nan + 0j would read Im = 0)
    g = model.growth_analysis(KH, **p)
    out.update(growth=float(g.growth), kH_at_max=float(g.kH_at_max), kH_min=float(g.kH_min),
               kH_max=float(g.kH_max))
    return out


@pn.cache(max_items=16)
def compute_gy_rayleigh(beta: float, eta: float) -> dict:
    """G_y(z_R, kH) on :data:`KH` (Eq. Gs_general at the Rayleigh speed), for the criterion of Eq. criterion."""
    z_r = float(model.rayleigh_speed(beta))
    _, gy = model.response_functions(np.full(KH.shape, z_r), KH, beta=beta, eta=eta)
    return {"kH": KH, "gy": np.real(gy), "z_R": z_r}


def family_args(base: tuple, key: str, value: float) -> tuple:
    """Model arguments of one family curve: `base` with parameter `key` set to `value`."""
    args = list(base)
    args[FAMILY[key][0]] = float(value)
    if args[4] == 1:
        args[5] = 0.0  # xi does not enter F at Delta = 1 (same normalisation as SpectrumParams.model_args)
    return tuple(args)


def family_label(key: str, value: float) -> str:
    return f"{FAMILY[key][1]} = {'∞' if math.isinf(value) else f'{value:g}'}"


#: the sliding results computed (args -> result), most recent last: a parameter set seen before is shown at once
SLIDING_CACHE: dict[tuple, dict] = {}
SLIDING_CACHE_SIZE = 64


#: kH of the fastest roots computed per call (app.sliding_work.fastest_roots): progress steps, and how soon a
#: cancelled job stops
KH_PER_CALL = 4


def compute_sliding(args: tuple, job: jobs.Job, *, in_process: bool = False) -> dict:
    """Sliding over every branch at the model arguments `args` (SpectrumParams.MODEL_ARGS), on a job's thread: the
    maximum over kH (model.sliding_analysis, with the Rayleigh branch's beside it), then the fastest root at each kH
    of :data:`KH_ALL` (model.fastest_mode), :data:`KH_PER_CALL` at a time (the job stops between two calls once
    cancelled). `in_process`: each piece runs in the worker process of app.jobs (served sessions), not here."""
    p = dict(zip(SpectrumParams.MODEL_ARGS, args, strict=True))
    out: dict = {"kH": KH_ALL, **job.call(sliding_work.sliding_maximum, p, in_process=in_process)}
    job.advance("maximum")
    parts = []
    for start in range(0, KH_ALL.size, KH_PER_CALL):
        kH = tuple(float(k) for k in KH_ALL[start:start + KH_PER_CALL])
        parts.append(job.call(sliding_work.fastest_roots, p, kH, in_process=in_process))
        job.advance("kH", len(kH))
    out.update({name: np.concatenate([part[name] for part in parts]) for name in ("growth", "z", "family", "status")})
    SLIDING_CACHE[args] = out
    while len(SLIDING_CACHE) > SLIDING_CACHE_SIZE:
        SLIDING_CACHE.pop(next(iter(SLIDING_CACHE)))
    return out


#: the sliding job's progress while a slider is held (the job starts at the release: too slow to follow the hand)
HELD = "held"


def sliding_lines(d: dict | None, progress: str = "") -> list[str]:
    """The readout lines of sliding over every branch (d: compute_sliding's result; None: being computed, or waiting
    for a held slider's release when progress is :data:`HELD`)."""
    if progress == HELD:
        return ["**Sliding, every branch**: computed when the slider is released"]
    if d is None:
        return [f"**Sliding, every branch**: computing{' (' + progress + ')' if progress else ''}…"]
    lo, hi = d["range"]
    scope = f"every branch, Im z ≥ {d['floor']:g}, kH {lo:g} to {hi:g}"
    if d["verdict"] == model.Verdict.STABLE:
        return [f"**Sliding stable** ({scope}): no root of any branch grows"]
    if d["verdict"] == model.Verdict.UNDETERMINED:
        return [f"**Sliding undetermined** ({scope}): {model.SLIDING_STATUS[d['reason']]}"]
    if not math.isfinite(d["max"]):
        return [f"**Sliding unstable** ({scope}): {model.SLIDING_STATUS[d['reason']]}"]
    z = d["z_at_max"]
    sign = "≥" if d["lower_bound"] else "="
    lines = [f"**Sliding unstable** ({scope}): max Im[c/c_s] {sign} {fmt(d['max'])} at kH = {fmt(d['kH_at_max'])}, "
             f"z = {fmt(z.real, 6)} {'+' if z.imag >= 0 else '−'} {fmt(abs(z.imag))}i, "
             f"{FAMILY_NAMES.get(d['family_at_max'], 'family unknown')}"]
    ray = d["rayleigh_max"]
    if d["family_at_max"] != 0 and math.isfinite(ray) and ray > 0:
        lines[0] += f" ({fmt(d['max'] / ray, 3)}× the Rayleigh branch's max)"
    if d["at_end"]:
        lines.append("the maximum lies at an end of the kH range (it may continue beyond)")
    if d["lower_bound"]:
        lines.append("at finite η a root can rise higher between the kH searched: the maximum is a lower bound")
    refused = int((d["status"] == 2).sum())
    if refused:
        lines.append(f"markers: the window was too wide to search at {refused} of {d['kH'].size} kH (no marker)")
    return lines


class SpectrumScene(pn.viewable.Viewer):
    """Widgets, plots and readout of the spectrum for one :class:`SpectrumParams`."""

    params = param.ClassSelector(class_=SpectrumParams)
    #: normalised model arguments; the plots depend only on this, so a change that does not change
    #: the model call (xi while Delta == 1) re-renders nothing
    inputs = param.Tuple(default=None, length=6, allow_None=True)
    #: the inputs the plots show: `inputs`, or while a slider is held the values its curves follow (app.live)
    shown = param.Tuple(default=None, length=6, allow_None=True)
    #: counts HoloViews' redraws of the Rayleigh-branch plots (they depend on it, not on `inputs`): at the release of
    #: a held slider whose values the plots already show (written by app.live), `inputs` changes without a redraw
    drawn = param.Integer(default=0)
    #: counts HoloViews' redraws of the markers of every branch: where the plots are on the page, a new `sliding` is
    #: written into them (app.live) instead
    sliding_drawn = param.Integer(default=0)
    #: a family of curves drawn behind the current one (set by the paper-figure presets)
    compare_key = param.Selector(default="", objects=["", *FAMILY])
    compare_values = param.List(default=[], item_type=float)
    #: the Lab-units panel (an app.lab.LabScene, shared with the Stability-map scene) shown above the plots; None: none
    lab = param.ClassSelector(class_=pn.viewable.Viewer, default=None, allow_None=True)
    #: sliding over every branch at `inputs` (compute_sliding's result; None while it is computed)
    sliding = param.Dict(default=None, allow_None=True)
    sliding_progress = param.String(default="")

    def __init__(self, **kwargs):
        if "params" not in kwargs:
            kwargs["params"] = SpectrumParams()
        super().__init__(**kwargs)
        self.inputs = self.shown = self.params.model_args()
        #: the plot panes (growth rate, phase velocity, G_y) once built
        self.panes: list[pn.pane.HoloViews] = []
        self._following = False  # the plots follow a held slider (app.live) until HoloViews redraws them
        self._follow_scheduled = False  # a follow of the latest values is scheduled on the session's event loop
        self._written: tuple | None = None  # the inputs app.live last wrote into the plots (None: HoloViews drew)
        self._gy_curve: tuple[tuple[float, float], hv.Curve] | None = None
        self.params.param.watch(self._update_inputs, list(self.params.param))
        #: the background computation of sliding over every branch (app.jobs): cancelled when the inputs change
        self.sliding_job = jobs.Follower(self._show_sliding)
        self.param.watch(self._draw_sliding, ["sliding"])
        self.ensure_sliding()
        # the fastest roots of every branch in a DynamicMap of their own: their arrival (a background job) re-sends
        # their few points, not the Rayleigh branch's curves; the overlay's options are set on the product (the
        # product of two overlays keeps neither's)
        self.im_dmap = (hv.DynamicMap(self.im_plot) * hv.DynamicMap(self.sliding_plot)).opts(
            hv.opts.Overlay(**IM_OVERLAY))
        self.re_dmap = hv.DynamicMap(self.re_plot)
        self.gy_dmap = hv.DynamicMap(self.gy_plot)

    def _update_inputs(self, *_events) -> None:
        """New model arguments: the plots on the page follow at once (:meth:`_follow`, a few ms); unless a slider is
        still held, HoloViews then redraws them once (:meth:`_redraw`, after the followed frame has been sent), with
        sliding over every branch. A plot that cannot follow is redrawn at once."""
        held = self.params.dragging
        if held and self.panes and jobs.served_document() is not None:
            # served: follow on the next turn of the event loop, at the values then current; the handle's moves
            # that arrive meanwhile (a busy server) are each a cheap parameter change, and only the latest is drawn
            # (no backlog of stale frames)
            self._following = True  # also when the release comes before the scheduled follow has run
            if not self._follow_scheduled:
                self._follow_scheduled = True
                live.schedule_follow(self._scheduled_follow)
            return
        self._follow_latest()

    def _scheduled_follow(self) -> None:
        """The follow scheduled while a slider was held (:func:`app.live.schedule_follow`); nothing if the release
        has drawn since."""
        if self._follow_scheduled:
            self._follow_latest()

    def _follow_latest(self) -> None:
        """Draw the current arguments: written into the plots while a slider is held or at its release (a slider's
        own events run with the session's document locked, which writing into Bokeh models needs; a preset's or a
        link's change may not: HoloViews redraws those), then, unless still held, redrawn by HoloViews once."""
        self._follow_scheduled = False
        args = self.params.model_args()
        held = self.params.dragging
        if (held or self._following) and args != self.shown and self._follow(args):
            self._following, self._written = held, args
            self.param.update(shown=args, sliding_progress=HELD if held else self.sliding_progress)
            if not held:
                pn.state.execute(self._redraw, schedule=True)
            return
        self._following = held
        self._redraw()

    def _redraw(self) -> None:
        """The plots drawn by HoloViews at the current arguments, and with them sliding over every branch (in one
        update: the growth-rate plot is redrawn once; if not computed before, it is computed in the background and
        drawn when done). While a slider is held the job waits for the release (it takes ~0.1-1 s).

        At the release of a held slider the plots on the page already show the released values when app.live wrote
        them last (with the plots' hooks run: ranges and legends as a redraw would make them): then HoloViews does
        not redraw them (~0.3 s of server time a release; the curves are not sent again), and only the markers of
        every branch, emptied while the slider was held, are drawn again."""
        args = self.params.model_args()
        held = self.params.dragging
        if held and args == self.shown:  # a drag began meanwhile: the plots follow it (_follow)
            return
        if args != self.inputs:
            self.sliding_job.cancel()
            hit = SLIDING_CACHE.get(tuple(args))
            written = not held and args == self._written and not self.compare_values
            previous = self.sliding
            self.param.update(inputs=args, shown=args, sliding=hit,
                              sliding_progress=HELD if hit is None and held else "",
                              **({} if written else {"drawn": self.drawn + 1}))
            if written and hit is not None and hit is previous:  # the emptied markers: drawn again
                self.param.trigger("sliding")
            if not held:
                self._written = None
            if hit is None and not held:
                self.ensure_sliding()
        elif not held and self.sliding is None and self.sliding_progress == HELD:  # released: its job starts now
            self.ensure_sliding()
        elif not held and self._written == args:  # released where the drag began: its markers, emptied, come back
            self._written = None
            self.sliding_progress = ""
            self.param.trigger("sliding")

    def _follow(self, args: tuple) -> bool:
        """A held slider: write the curves of `args` into the plots on the page (:mod:`app.live`, a few ms) instead
        of letting HoloViews redraw them (80-170 ms each); the markers of every branch are emptied (they are of the
        previous inputs) until the release redraws everything. False where that cannot be done (plots not rendered,
        a preset's family of curves shown, which would stay at the previous inputs): HoloViews redraws then."""
        if self.compare_values or len(self.panes) < 3:
            return False
        d = compute_spectrum(*args)
        gamma, f, beta, eta = args[:4]
        gy = compute_gy_rayleigh(beta, eta)
        kH, z = d["kH"], d["z"]
        band = ([d["kH_min"]], [d["kH_max"]]) if np.isfinite(d["kH_min"]) and np.isfinite(d["kH_max"]) else ([], [])
        level = float(model.criterion_gy_level(gamma=gamma, f=f, beta=beta))
        return (live.push(self.panes[0], {"Rayleigh branch": (kH, z.imag),
                                          "linear expansion": linear_layer(d, "imag"), BAND_LABEL: band},
                                 empty_others=True)
                and live.push(self.panes[1], {"Rayleigh branch": (kH, z.real),
                                              "linear expansion": linear_layer(d, "real")})
                and live.push(self.panes[2], {"G_y(c_R, kH)": (gy["kH"], gy["gy"]), CRITERION_LABEL: level}))

    def data(self) -> dict:
        return compute_spectrum(*self.inputs)

    def ensure_sliding(self) -> None:
        """Show sliding over every branch at the current inputs: at once if computed before, else computed in the
        background (the job of the previous inputs is cancelled)."""
        args = tuple(self.inputs)
        hit = SLIDING_CACHE.get(args)
        if hit is not None:
            self.sliding_job.cancel()
            self.param.update(sliding=hit, sliding_progress="")
            return
        job = self.sliding_job.job
        if job is not None and job.key == args and not job.state().finished:
            return
        if self.sliding is not None or self.sliding_progress:
            self.param.update(sliding=None, sliding_progress="")
        self.sliding_job.run(partial(compute_sliding, args, in_process=jobs.served_document() is not None),
                             name="sliding", key=args,
                             totals={"maximum": 1, "kH": len(KH_ALL)})

    def _show_sliding(self, job: jobs.Job, state: jobs.JobState) -> None:
        """The sliding job's progress, and at its end its result (on the session's event loop)."""
        if job.key != tuple(self.inputs):
            return
        if state.status == jobs.DONE:
            self.param.update(sliding=state.result, sliding_progress="")
        elif state.status == jobs.FAILED:
            self.sliding_progress = f"failed: {state.error}"
        else:
            done = state.done.get("kH", 0)
            self.sliding_progress = ("the maximum over kH" if not state.done.get("maximum")
                                     else f"the fastest root at {done} of {len(KH_ALL)} kH")

    def wait_sliding(self, timeout: float = 120.0) -> None:
        """Block until sliding at the current inputs is computed and shown (tests, scripts)."""
        self.sliding_job.wait(timeout)

    def sliding_points(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """(kH, Im[c/c_s]) of each marker layer, by its style key: the fastest root of every branch at each kH of
        :data:`KH_ALL` (by family, and a dotted line through them) and the sliding maximum; empty while computed."""
        keys = ["all line", *(f"all {k}" for k in model.FAMILIES), "all max"]
        d = self.sliding
        if d is None:
            return {key: (np.array([]), np.array([])) for key in keys}
        points = {"all line": (d["kH"], d["growth"])}
        for k in model.FAMILIES:
            sel = d["family"] == k
            points[f"all {k}"] = (d["kH"][sel], d["growth"][sel])
        points["all max"] = ((np.array([d["kH_at_max"]]), np.array([d["max"]])) if math.isfinite(d["max"])
                             else (np.array([]), np.array([])))
        return points

    def sliding_layers(self) -> list[hv.Element]:
        """The markers of :meth:`sliding_points` as the growth-rate plot's layers (coloured by family)."""
        return [STYLE[key].clone(xy) for key, xy in self.sliding_points().items()]

    def _draw_sliding(self, *_events) -> None:
        """A new `sliding` (or the same, its markers emptied by a held slider): written into the growth-rate plot on
        the page (app.live, a few ms: a HoloViews update of the whole overlay took ~0.1 s a release, twice: the
        markers emptied, then the job's result); HoloViews redraws them where the plot is not on a page."""
        doc = jobs.served_document()
        if doc is None:
            self._write_sliding()
        else:  # a preset's or the URL's change runs without the document's lock, which writing into it needs: a
            # next-tick callback has it (Bokeh), and reads the latest `sliding` then
            doc.add_next_tick_callback(self._write_sliding)

    def _write_sliding(self) -> None:
        """The markers of `sliding` written into the growth-rate plot; HoloViews redraws them where it is not on a
        page."""
        layers = {STYLE[key].label: xy for key, xy in self.sliding_points().items()}
        if not (self.panes and live.push(self.panes[0], layers)):
            self.sliding_drawn += 1

    def family(self, part: str, ylabel: str) -> list[hv.Curve]:
        """The preset's family of curves (real or imaginary part), each a cached model call."""
        curves = []
        for i, value in enumerate(self.compare_values):
            d = compute_spectrum(*family_args(self.inputs, self.compare_key, value))
            template = styled(hv.Curve, ylabel, color=PALETTE[i % len(PALETTE)], line_width=1.2, alpha=0.9)
            curves.append(template.clone((d["kH"], getattr(d["z"], part)),
                                         label=family_label(self.compare_key, value)))
        return curves

    @param.depends("sliding_drawn")
    def sliding_plot(self) -> hv.Overlay:
        """The fastest root of every branch and the sliding maximum (empty while they are computed)."""
        return hv.Overlay(self.sliding_layers())

    @param.depends("drawn", "compare_key", "compare_values")
    def im_plot(self) -> hv.Overlay:
        d = self.data()
        kH, z = d["kH"], d["z"]
        band = [(d["kH_min"], d["kH_max"])] if np.isfinite(d["kH_min"]) and np.isfinite(d["kH_max"]) else []
        layers = [STYLE["band"].clone(band), *self.family("imag", IM_LABEL), STYLE["im branch"].clone((kH, z.imag)),
                  STYLE["im linear"].clone(linear_layer(d, "imag"))]
        return OVERLAYS["im"].clone(layers)

    @param.depends("drawn", "compare_key", "compare_values")
    def re_plot(self) -> hv.Overlay:
        d = self.data()
        kH = d["kH"]
        return OVERLAYS["re"].clone([*self.family("real", RE_LABEL), STYLE["re branch"].clone((kH, d["z"].real)),
                                     STYLE["re linear"].clone(linear_layer(d, "real"))])

    @param.depends("drawn")
    def gy_plot(self) -> hv.Overlay:
        gamma, f, beta, eta = self.inputs[:4]
        layers = [self.gy_curve(beta, eta)]
        level = float(model.criterion_gy_level(gamma=gamma, f=f, beta=beta))
        if np.isfinite(level):
            layers.append(STYLE["criterion"].clone(level))
        return OVERLAYS["gy"].clone(layers)

    def gy_curve(self, beta: float, eta: float) -> hv.Curve:
        """The G_y(c_R, kH) curve, one element per (β, η): when only γ or f change, HoloViews sees the
        same element and does not re-send its data."""
        if self._gy_curve is None or self._gy_curve[0] != (beta, eta):
            d = compute_gy_rayleigh(beta, eta)
            self._gy_curve = ((beta, eta), STYLE["gy"].clone((d["kH"], d["gy"])))
        return self._gy_curve[1]

    def _csv_header(self, what: str) -> str:
        return f"asymslide spectrum, {what}; " + ", ".join(
            f"{n} = {v!r}" for n, v in zip(SpectrumParams.MODEL_ARGS, self.inputs, strict=True))

    def _family_columns(self, part: str, name: str) -> dict[str, np.ndarray]:
        """The preset's family of curves as CSV columns (`name`(key=value))."""
        return {f"{name}({self.compare_key}={value!r})":
                getattr(compute_spectrum(*family_args(self.inputs, self.compare_key, value))["z"], part)
                for value in self.compare_values}

    def csv_growth(self) -> io.StringIO:
        """What the growth-rate plot shows: kH, Im z on the Rayleigh branch with its error and status, the linear
        expansion, the preset's family of curves; the unstable band in the header."""
        d = self.data()
        band = (f"unstable band {d['kH_min']!r} < kH < {d['kH_max']!r}" if np.isfinite(d["kH_min"])
                and np.isfinite(d["kH_max"]) else "no unstable band on the kH range")
        sliding = " ".join(line.replace("**", "") for line in sliding_lines(self.sliding, self.sliding_progress))
        return csv_table(self._csv_header(f"growth rate (Rayleigh branch); {band}; {sliding}"),
                         {"kH": d["kH"], "Im_z": d["z"].imag, "error": d["error"], "status": d["status"],
                          "linear_Im_z": d["linear"].imag, **self._family_columns("imag", "Im_z")})

    def csv_phase(self) -> io.StringIO:
        """What the phase-velocity plot shows: kH, Re z with its error and status, the linear expansion, the family."""
        d = self.data()
        return csv_table(self._csv_header("phase velocity (Rayleigh branch)"),
                         {"kH": d["kH"], "Re_z": d["z"].real, "error": d["error"], "status": d["status"],
                          "linear_Re_z": d["linear"].real, **self._family_columns("real", "Re_z")})

    def csv_gy(self) -> io.StringIO:
        """What the G_y plot shows: kH, G_y(c_R, kH), and the criterion level -c_R/(c_s γ f) in the header."""
        gamma, f, beta, eta = self.inputs[:4]
        gy = compute_gy_rayleigh(beta, eta)
        level = float(model.criterion_gy_level(gamma=gamma, f=f, beta=beta))
        return csv_table(self._csv_header(f"G_y at the Rayleigh speed z_R = {gy['z_R']!r}; criterion level "
                                          f"-c_R/(c_s gamma f) = {level!r}"), {"kH": gy["kH"], "G_y_at_z_R": gy["gy"]})

    @param.depends("shown", "sliding", "sliding_progress")
    def readout(self) -> str:
        d = compute_spectrum(*self.shown)  # the plotted inputs, also while a slider is held
        z, status, error = d["z"], d["status"], d["error"]
        shown = np.isfinite(z)
        rel = float(np.max(error[shown] / np.abs(z[shown]))) if shown.any() else np.nan
        at_edge = np.isfinite(d["kH_at_max"]) and (np.isclose(d["kH_at_max"], KH[0], rtol=1e-9)
                                                    or np.isclose(d["kH_at_max"], KH[-1], rtol=1e-9))
        if at_edge:  # the largest value on the range is at its end: no maximum inside it
            side = "smaller" if np.isclose(d["kH_at_max"], KH[0], rtol=1e-9) else "larger"
            lines = [f"**Largest growth on the range, Rayleigh branch** Im[c/c_s] = {fmt(d['growth'])} at its end, "
                     f"kH = {fmt(d['kH_at_max'])}: not a maximum (Im[c/c_s] still grows towards {side} kH)"]
        else:
            lines = [f"**Max growth, Rayleigh branch** Im[c/c_s] = {fmt(d['growth'])} at kH = {fmt(d['kH_at_max'])}"]
        if np.isfinite(d["kH_min"]) and np.isfinite(d["kH_max"]):
            lines.append(f"**Unstable band, Rayleigh branch** {fmt(d['kH_min'])} < kH < {fmt(d['kH_max'])}")
        elif np.isfinite(d["growth"]) and d["growth"] > 0:
            lines.append("**Unstable band, Rayleigh branch** extends beyond the plotted kH range")
        else:
            lines.append("**Rayleigh branch stable** (no unstable band in the plotted range)")
        lines.extend(sliding_lines(self.sliding, self.sliding_progress))
        lines.append(f"**Accuracy** max error/|z| = {rel:.1e} over {int(shown.sum())} points")
        masked = {model.STATUS[int(c)]: int(n) for c, n in zip(*np.unique(status[~shown], return_counts=True),
                                                               strict=True)}
        if masked:
            lines.extend(f"**Masked** {n} point(s): {reason}" for reason, n in masked.items())
        else:
            lines.append("**Masked** none")
        return "\n\n".join(lines)

    def plot_pane(self, index: int) -> pn.pane.HoloViews:
        """Live plot `index`: 0 growth rate, 1 phase velocity, 2 G_y criterion (top to bottom)."""
        pane = pn.pane.HoloViews((self.im_dmap, self.re_dmap, self.gy_dmap)[index], sizing_mode="stretch_width")
        if len(self.panes) == index:  # the scene's panes, in order (a held slider writes into them: _follow)
            self.panes.append(pane)
        return pane

    def downloads(self) -> list[pn.widgets.FileDownload]:
        """One CSV button per plot, below it: what that plot shows."""
        return [csv_download(self.csv_growth, "spectrum_growth_rate.csv", "Growth rate (CSV)"),
                csv_download(self.csv_phase, "spectrum_phase_velocity.csv", "Phase velocity (CSV)"),
                csv_download(self.csv_gy, "spectrum_gy.csv", "G_y criterion (CSV)")]

    def _load_plots(self, slots: list[pn.Column], index: int = 0) -> None:
        """Render the plot of slot `index`, then schedule the next one on the server's event loop."""
        slots[index].objects = [self.plot_pane(index)]
        if index + 1 < len(slots):
            pn.state.execute(partial(self._load_plots, slots, index + 1), schedule=True)

    def __panel__(self) -> pn.viewable.Viewable:
        """The tab: widgets and readout (left); equation, plots and download (right).

        Served, the plots are rendered after the page has loaded, one per event-loop turn, instead of all
        three while the session is created (a large part of its cost): other sessions' updates are served
        in between. Outside a server session they are rendered at once.
        """
        controls = controls_column(self.params.make_widgets(), self.readout)
        names = ("growth-rate", "phase-velocity", "G_y")
        slots = [pn.Column(placeholder(f"Drawing the {name} plot…"), sizing_mode="stretch_width", min_height=h)
                 for name, h in zip(names, PLOT_HEIGHTS, strict=True)]
        doc = pn.state.curdoc
        if doc is not None and doc.session_context is not None:
            pn.state.onload(partial(self._load_plots, slots))
        else:
            for index, slot in enumerate(slots):
                slot.objects = [self.plot_pane(index)]
        plots = pn.Column(
            *([self.lab.panel(with_plot=True)] if self.lab is not None else []),
            pn.pane.LaTeX(EQUATION, renderer="katex", styles=EQUATION_STYLES, sizing_mode="stretch_width"),
            *(w for pair in zip(slots, self.downloads(), strict=True) for w in pair),
            sizing_mode="stretch_width",
        )
        return scene_layout(controls, plots, "Spectrum")
