"""Scene "Stability map" (paper Sect. IV, Figs. 4c and 5): where steady sliding is unstable in a parameter plane.

The map is the maximal growth rate max_kH Im[c/c_s] on the Rayleigh branch (:func:`model.growth_analysis`, the
function behind :func:`model.max_growth`) over a plane of two parameters (η-γ, Δ-ξ, f-γ or β-γ), the other four
taken from the sliders shared with the other scenes. It shows the neutral curve (zero contour of the growth) and a
marker at the sliders' values; clicking the map moves the two sliders there. The second plot is Fig. 4c: the exact
threshold χ_c(β) = γ_c f (:func:`model.critical_chi`) and the approximate criterion (:func:`model.criterion_chi`).

The app computes no physics: every number comes from a ``pn.cache``'d call into the public :mod:`model` API.

Computation on demand. The map is computed only when its plot is rendered (dynamic tabs render the visible
scene only, and building the page computes nothing), as a background job (:mod:`app.jobs`), in chunks of rows; each
chunk is a pure cached call (:func:`compute_chunk`), so a map seen before, or the unchanged part of one, comes back
from the cache. A labelled progress bar advances per chunk. When the map's inputs change, the running job is
cancelled (it stops after its current chunk and is never shown) and the new one starts.

What the map depends on: its plane, resolution, and the four parameters off the plane (ξ normalised to 0 at Δ = 1,
where it does not enter F). Moving a parameter of the plane moves only the marker.

While a slider is held (:attr:`SpectrumParams.dragging`) the map waits for the release. If the held value is off the
plane, a coarse preview of the held inputs is drawn in place of the map meanwhile (:func:`compute_preview`, its own
job: each move cancels the previous one, and a new one starts only once the previous one has stopped, so the latest
value wins and no work piles up): the Rayleigh branch's growth at :data:`PREVIEW_POINTS` per axis (the map's cached
chunks; its neutral curve the grid's contour, dashed grey, not certified), and coloured by the sliding verdict the
verdict at :data:`PREVIEW_SLIDING_POINTS` per axis, published chunk by chunk. Its title, hover, progress label and
readout say so; the CSV never holds it. It is dropped once the full map (or the sliding map's first pass) of the
released inputs is shown.
"""

from __future__ import annotations

import collections
import io
import math
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import partial
from typing import Any

import holoviews as hv
import numpy as np
import panel as pn
import param

from asymslide import model

from . import jobs
from . import map_refine as mr
from . import sliding_boundary as sb
from . import sliding_map as sm
from .common import COLOUR_LEGEND, GROWTH_CMAP, GROWTH_LABEL, MARGINAL, NAN_COLOR, neutral_lines
from .declarations import Choice
from .exports import csv_download, csv_table
from .layout import controls_column, scene_layout
from .params import SpectrumParams
from .plotting import fmt, readable_ticks_hook
from .workarounds import frozen_document

# --------------------------------------------------------------------------------------------
# grids
# --------------------------------------------------------------------------------------------

#: kH grid on which the maximum over kH is bracketed (then refined between grid points by the model)
KH = np.logspace(-3, 3, 96)

#: points per axis of the map. The η-γ plane is the slowest (finite η costs ~20x more per point): on 2 cores
#: ~0.6 / 0.9 / 2.0 s coarse / medium / fine (2-4x that when the cores are busy); the others take <= 0.2 s at η = ∞
RESOLUTIONS = {"coarse": 24, "medium": 24, "fine": 40}
#: the levels of refinement at the neutral curve per resolution (app.map_refine: each level halves the cells the
#: Rayleigh branch's verdict changes across; finest grid: 24, 96, 160 cells per axis)
LEVELS = {"coarse": 0, "medium": 2, "fine": 2}

#: a chunk has up to 256 parameter points per CPU (the model runs blocks of 256 on parallel threads), and a map
#: has at least MIN_CHUNKS chunks (progress steps, and how soon a stale computation stops)
CHUNK_POINTS = 256 * (os.cpu_count() or 1)
MIN_CHUNKS = 4

#: the order of SpectrumParams.model_args()
ARG_NAMES = SpectrumParams.MODEL_ARGS

#: points per axis of the preview of the Rayleigh branch's map while a slider is held (its chunks are the map's
#: cached chunks at this resolution): ~0.01 s at η = ∞, ~0.1 s on the η-γ plane (benchmarks: see the report)
PREVIEW_POINTS = 12
#: points per axis of the preview of the sliding verdict while a slider is held, computed coarse to fine (every other
#: point, then the rest) in chunks of PREVIEW_SLIDING_CHUNK points, each shown as it is done
PREVIEW_SLIDING_POINTS = 6
PREVIEW_SLIDING_STRIDES = (2, 1)
PREVIEW_SLIDING_CHUNK = 3
#: what the neutral curve of a preview is (the readout and the path's label)
PREVIEW_CONTOUR = "preview contour, not certified"
#: the colour of the boundary of sliding over every branch (app.sliding_boundary) on the map
SLIDING_BOUNDARY_COLOR = "#762a83"
#: the opacity of a preview (a full map is opaque, a map of the previous inputs 0.45)
PREVIEW_ALPHA = 0.8

#: β grids of Fig. 4c: the criterion (line) and, at every other of its points, the exact threshold (symbols)
BETA_CRITERION = np.linspace(0.025, 0.70, 28)
BETA_EXACT = BETA_CRITERION[1::2].copy()
#: Fig. 4c y range; a current χ off this range is drawn at its edge
CHI_RANGE = (0.0, 5.0)
#: β per cached chunk of Fig. 4c's sliding threshold (about 0.5 s a β at η = ∞)
FIG4C_SLIDING_CHUNK = 2
#: Fig. 4c's marker colour of the sliding threshold (every branch)
SLIDING_THRESHOLD_COLOR = "#d6604d"


@dataclass(frozen=True)
class Axis:
    """One axis of a plane: the model keyword, the paper's symbol, the plotted range, log or linear."""

    name: str
    lo: float
    hi: float
    log: bool
    step: float = 0.0  # a click on a linear axis is rounded to this (the slider's step)

    @classmethod
    def of(cls, name: str) -> Axis:
        """The axis of the model argument `name`, from its declaration (SpectrumParams, ``axis`` and ``step``)."""
        decl = SpectrumParams.declaration(name)
        lo, hi, log = decl.axis
        return cls(name, lo, hi, log, step=0.0 if log else decl.step)

    @property
    def label(self) -> str:
        return SpectrumParams.symbol(self.name)

    def values(self, n: int) -> np.ndarray:
        """The n grid values (cell centres), log- or linearly spaced from lo to hi."""
        if self.log:
            return np.logspace(math.log10(self.lo), math.log10(self.hi), n)
        return np.linspace(self.lo, self.hi, n)

    def edges(self, n: int) -> np.ndarray:
        """The n + 1 cell edges around :meth:`values` (midpoints in the axis' own scale)."""
        t = np.log10(self.values(n)) if self.log else self.values(n)
        h = t[1] - t[0]
        e = np.concatenate([[t[0] - h / 2], (t[:-1] + t[1:]) / 2, [t[-1] + h / 2]])
        return 10.0**e if self.log else e


#: the planes (x, y) by model argument; the name of a plane reads "x-y" in the paper's symbols
PLANE_ARGS = (("eta", "gamma"), ("Delta", "xi"), ("f", "gamma"), ("beta", "gamma"))
PLANES: dict[str, tuple[Axis, Axis]] = {
    f"{Axis.of(x).label}-{Axis.of(y).label}": (Axis.of(x), Axis.of(y)) for x, y in PLANE_ARGS}


#: the planes' URL words ("eta-gamma" for "η-γ")
PLANE_WORDS = {f"{Axis.of(x).label}-{Axis.of(y).label}": f"{x}-{y}" for x, y in PLANE_ARGS}


def plane_axes(plane: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(x, y) grid values of a plane at n points per axis."""
    ax, ay = PLANES[plane]
    return ax.values(n), ay.values(n)


def chunk_rows(n: int) -> list[tuple[int, int]]:
    """Row ranges [start, stop) of the chunks of an n x n map: <= CHUNK_POINTS points each, at least MIN_CHUNKS."""
    rows = max(1, min(CHUNK_POINTS // n, math.ceil(n / MIN_CHUNKS)))
    return [(a, min(a + rows, n)) for a in range(0, n, rows)]


# --------------------------------------------------------------------------------------------
# cached model calls
# --------------------------------------------------------------------------------------------


class ChunkCache:
    """The map chunks computed by every session (LRU, `max_items`), safe for the sessions' worker threads.

    Only a lookup or an insert holds the lock, never a computation: sessions computing different maps run in
    parallel (a chunk two sessions need at the same moment is computed twice, harmlessly). pn.cache could
    not be used here: it prunes its store outside its own lock.
    """

    def __init__(self, max_items: int) -> None:
        self.max_items = max_items
        self._items: collections.OrderedDict[tuple, dict] = collections.OrderedDict()
        self._lock = threading.Lock()

    def get(self, key: tuple) -> dict | None:
        with self._lock:
            value = self._items.get(key)
            if value is not None:
                self._items.move_to_end(key)
            return value

    def put(self, key: tuple, value: dict) -> None:
        with self._lock:
            self._items[key] = value
            self._items.move_to_end(key)
            while len(self._items) > self.max_items:
                self._items.popitem(last=False)

    def clear(self) -> None:
        with self._lock:
            self._items.clear()


#: the chunks of every map computed by this process
CHUNKS = ChunkCache(max_items=1024)


def compute_chunk(plane: str, n: int, start: int, stop: int, fixed: tuple[tuple[str, float], ...]) -> dict:
    """Rows start..stop-1 (y values) of the map of `plane` at n x n points; `fixed` = the other parameters.

    growth, kH_at_max (NaN growth: the branch could not be followed at any kH), n_masked (kH points masked).
    """
    ax, ay = PLANES[plane]
    x, y = plane_axes(plane, n)
    p = dict(fixed)
    p[ax.name] = x[None, :]
    p[ay.name] = y[start:stop, None]
    return _growth_fields(model.growth_analysis(KH, **p))


def _growth_fields(r: model.GrowthResult) -> dict:
    """The map's fields of a :func:`model.growth_analysis` result, as arrays."""
    return {"growth": np.asarray(r.growth, float), "kH_at_max": np.asarray(r.kH_at_max, float),
            "n_masked": np.asarray(r.n_masked, int)}


@pn.cache(max_items=1)
def compute_criterion() -> np.ndarray:
    """χ_c of the approximate criterion (Eq. criterion) on :data:`BETA_CRITERION` (independent of f)."""
    return np.asarray(model.criterion_chi(BETA_CRITERION), float)


@pn.cache(max_items=32)
def compute_fig4c(f: float) -> dict:
    """Fig. 4c at friction coefficient f: exact χ_c(β) (NaN where there is no threshold) and the criterion."""
    exact = np.full(BETA_EXACT.shape, np.nan)
    reason = ""
    try:
        exact = np.asarray(model.critical_chi(BETA_EXACT, f=f), float)
    except ValueError:  # no threshold at some beta: per point, NaN there
        for i, b in enumerate(BETA_EXACT):
            try:
                exact[i] = float(model.critical_chi(float(b), f=f))
            except ValueError as exc:
                reason = str(exc)
    return {"beta": BETA_EXACT, "exact": exact, "beta_criterion": BETA_CRITERION, "criterion": compute_criterion(),
            "reason": reason}


@pn.cache(max_items=64)
def compute_fig4c_sliding_chunk(f: float, betas: tuple[float, ...]) -> dict:
    """Fig. 4c's threshold of sliding over every branch at `betas` (η = ∞, Δ = 1; the model's kH range and growth
    floor: :func:`model.critical_gammas` with ``branches="all"``, docs/physics.md §14.10): χ_c = γ_c f at the first
    certified crossing in γ (NaN where there is none), its crossing reason (model.CROSSING_STATUS; 1: at an end of
    the kH range), kH and z, and the status (model.THRESHOLD_STATUS) of each β."""
    r = model.critical_gammas(f=f, beta=np.asarray(betas, dtype=float), branches="all")
    first = r.first  # the model's first certified crossing; its kH and z are the ones at the same crossing
    found = np.isfinite(first)
    rows = np.arange(len(betas))
    k = np.argmax(r.value == first[:, None], axis=1)
    pick = {name: np.where(found, np.asarray(getattr(r, name))[rows, k], np.nan) for name in ("kH", "z")}
    return {"chi": first * f, "kH": pick["kH"], "z": np.real(pick["z"]),
            "reason": np.where(found, r.reason[rows, k], -1), "status": np.asarray(r.status, int)}


def compute_fig4c_sliding(f: float, job: jobs.Job) -> dict:
    """Fig. 4c's sliding threshold at every β of :data:`BETA_EXACT` (a job: cached chunks of
    :data:`FIG4C_SLIDING_CHUNK` β, progress per β)."""
    parts = []
    for i in range(0, BETA_EXACT.size, FIG4C_SLIDING_CHUNK):
        job.check()
        betas = tuple(float(b) for b in BETA_EXACT[i:i + FIG4C_SLIDING_CHUNK])
        parts.append(compute_fig4c_sliding_chunk(f, betas))
        job.advance("β", len(betas))
    out = {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}
    return {"f": f, "beta": BETA_EXACT, **out}


def fig4c_sliding_text(d: dict) -> str:
    """The sliding threshold of Fig. 4c in words: where it is certified, where it lies on an end of the kH range
    (over a wider range it may lie elsewhere), and why it is missing at the other β."""
    chi, beta = d["chi"], d["beta"]
    found = np.isfinite(chi)
    text = (f"**Sliding threshold (every branch, f = {fmt(d['f'])})** certified at {int(found.sum())} of "
            f"{beta.size} β (triangles)")
    if found.any():
        text += f": χ_c from {fmt(float(np.nanmin(chi)))} to {fmt(float(np.nanmax(chi)))}"
        at_end = found & (d["reason"] == model.CrossingReason.EDGE)
        if at_end.any():
            text += (f"; at {int(at_end.sum())} β its neutral mode is at kH = {fmt(float(np.nanmax(d['kH'][at_end])))}"
                     f", the end of the kH range searched (z = {fmt(float(d['z'][at_end][0]), 6)}: a root just beyond "
                     "the shear wave speed; over a wider kH range the threshold may lie lower)")
        text += (". The map's sliding verdict, with its growth floor, turns unstable a little higher, where the "
                 "growth exceeds the floor (docs/physics.md §14.10)")
    missing = [f"β = {fmt(float(b))}: {model.THRESHOLD_STATUS.get(int(st), f'status {int(st)}')}"
               for b, st, ok in zip(beta, d["status"], found, strict=True) if not ok]
    if missing:
        text += ". No certified threshold at " + "; ".join(missing)
    return text + "."


# --------------------------------------------------------------------------------------------
# the computed map
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class MapResult:
    """A finished map: the key it was computed for, its grid and the model's values on it."""

    key: tuple
    x: np.ndarray
    y: np.ndarray
    growth: np.ndarray  # (ny, nx)
    kH_at_max: np.ndarray
    n_masked: np.ndarray
    seconds: float
    chunks_computed: int  # chunks that were not in the cache
    chunks_total: int
    #: the Rayleigh branch's certified thresholds γ_c at each x (:func:`compute_crossings`); None on a plane without γ
    crossings: dict | None = None
    #: the map refined at its neutral curve (app.map_refine); None at resolution coarse
    refined: mr.RefinedMap | None = None

    @property
    def plane(self) -> str:
        return self.key[0]


def cached_chunk(plane: str, n: int, start: int, stop: int, fixed: tuple[tuple[str, float], ...]) -> tuple[dict, bool]:
    """Rows start..stop-1 of the map of `plane` at n x n points from :data:`CHUNKS`, computed (:func:`compute_chunk`)
    and stored there when absent; and whether it was computed."""
    chunk_key = (plane, n, start, stop, fixed)
    part = CHUNKS.get(chunk_key)
    if part is not None:
        return part, False
    part = compute_chunk(plane, n, start, stop, fixed)
    CHUNKS.put(chunk_key, part)
    return part, True


def compute_map(key: tuple, job: jobs.Job) -> MapResult:
    """The map of `key` (:func:`key_for`), chunk by chunk, each from the cache of chunks when it is there: the work of
    a map job, on its thread (it stops at :meth:`~app.jobs.Job.check` once the job is cancelled)."""
    plane, n, fixed, levels = key
    chunks = chunk_rows(n)
    t0 = time.perf_counter()
    parts, computed = [], 0
    for a, b in chunks:
        job.check()
        part, new = cached_chunk(plane, n, a, b, fixed)
        computed += new
        parts.append(part)
        job.advance("chunks")
    base = {k: np.concatenate([p[k] for p in parts]) for k in mr.FIELDS}
    x, y = plane_axes(plane, n)
    refined = refine_map(plane, x, y, base, levels, fixed, job) if levels else None
    job.check()
    crossings = compute_crossings(plane, n, fixed, crossing_columns(n, levels))
    return MapResult(key=key, x=x, y=y, **base, seconds=time.perf_counter() - t0, chunks_computed=computed,
                     chunks_total=len(chunks), crossings=crossings, refined=refined)


def evaluate_points(plane: str, fixed: tuple[tuple[str, float], ...], xs: np.ndarray, ys: np.ndarray) -> dict:
    """The Rayleigh branch's max growth (:func:`model.growth_analysis`, as :func:`compute_chunk`) at the points
    (xs[i], ys[i]) of `plane`."""
    ax, ay = PLANES[plane]
    return _growth_fields(model.growth_analysis(KH, **dict(fixed), **{ax.name: xs, ay.name: ys}))


def refine_map(plane: str, x: np.ndarray, y: np.ndarray, base: dict, levels: int,
               fixed: tuple[tuple[str, float], ...], job: jobs.Job) -> mr.RefinedMap:
    """The map refined `levels` times in the cells its Rayleigh verdict changes across (:func:`app.map_refine.refine`;
    one job step per level)."""
    ax, ay = PLANES[plane]
    return mr.refine(x, y, ax.log, ay.log, base, levels, ((ax.lo, ax.hi), (ay.lo, ay.hi)),
                     partial(evaluate_points, plane, fixed), check=job.check,
                     advance=lambda _level: job.advance("chunks"))


def crossing_columns(n: int, levels: int) -> int:
    """The x values at which the neutral curve is certified: twice the base grid's on a refined map."""
    return n * 2 if levels else n


#: the crossings a map column may have: the same for the Rayleigh branch's neutral curve and the sliding boundary
#: (a certified one: model.CERTIFIED_CROSSINGS)
MAX_MAP_CROSSINGS = sb.MAX_CROSSINGS


@pn.cache(max_items=64)
def compute_crossings(plane: str, n: int, fixed: tuple[tuple[str, float], ...], columns: int | None = None,
                      ) -> dict | None:
    """The Rayleigh branch's neutral curve of a plane whose y axis is γ, exactly: at each of `columns` x values
    (default n: the map's),
    every crossing in γ of the max growth over the map's kH range, each a certified neutral mode
    (:func:`model.critical_gammas`, Sect. IV, Fig. 4c; docs/physics.md §9). None on a plane without γ (Δ-ξ).
    0.03-0.6 s for 24 columns: computed with the map, after its chunks."""
    ax, ay = PLANES[plane]
    if ay.name != "gamma":
        return None
    x = ax.values(columns or n)
    edges = ay.edges(n)
    args = {**dict(fixed), ax.name: x}
    c = model.critical_gammas(**args, kH=KH, gamma_range=(float(edges[0]), float(edges[-1])),
                              max_crossings=MAX_MAP_CROSSINGS)
    return {"x": x, "value": c.value, "location": c.location, "direction": c.direction, "reason": c.reason,
            "count": c.count}


def crossing_lines(c: dict) -> tuple[list[tuple[np.ndarray, np.ndarray]], dict[str, np.ndarray]]:
    """The neutral curve through the certified crossings of neighbouring columns (joined in order where both have
    the same directions, so a curve is never drawn across a column where a crossing appears or vanishes), the
    certified points, and the sign changes that are not thresholds (jumps, pole-dense, not certified)."""
    x, value, direction, reason = c["x"], c["value"], c["direction"], c["reason"]
    certified = np.isin(reason, model.CERTIFIED_CROSSINGS) & np.isfinite(value)
    lines = []
    for i in range(x.size - 1):
        a, b = certified[i], certified[i + 1]
        if not a.any() or a.sum() != b.sum() or not np.array_equal(direction[i][a], direction[i + 1][b]):
            continue
        for ya, yb in zip(value[i][a], value[i + 1][b], strict=True):
            lines.append((np.array([x[i], x[i + 1]]), np.array([ya, yb])))
    cols = np.broadcast_to(x[:, None], value.shape)
    refused = (reason >= 0) & ~np.isin(reason, model.CERTIFIED_CROSSINGS)
    return lines, {"x": cols[certified], "y": value[certified], "direction": direction[certified],
                   "refused_x": cols[refused], "refused_y": c["location"][refused], "refused_reason": reason[refused]}


# --------------------------------------------------------------------------------------------
# the preview while a slider is held
# --------------------------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class MapPreview:
    """A coarse map of the held inputs while a slider is held: the Rayleigh branch's growth at :data:`PREVIEW_POINTS`
    per axis and, for a map coloured by the sliding verdict, that verdict at :data:`PREVIEW_SLIDING_POINTS` per axis
    (a partial one while it is computed)."""

    #: (verdict, map key of the held inputs (:func:`key_for`), growth floor of the sliding verdict)
    job_key: tuple
    x: np.ndarray
    y: np.ndarray
    growth: np.ndarray  # (ny, nx), the Rayleigh branch's
    kH_at_max: np.ndarray
    n_masked: np.ndarray
    seconds: float
    sliding: sm.SlidingMap | None = None

    @property
    def verdict(self) -> str:
        return self.job_key[0]

    @property
    def key(self) -> tuple:
        """The map key of the inputs previewed (the full map's key once they are released)."""
        return self.job_key[1]

    @property
    def plane(self) -> str:
        return self.key[0]

    @property
    def points(self) -> int:
        """Points per axis of what is drawn: the sliding verdict's grid or the Rayleigh branch's."""
        return PREVIEW_SLIDING_POINTS if self.verdict == sm.SLIDING else PREVIEW_POINTS

    @property
    def complete(self) -> bool:
        return self.verdict != sm.SLIDING or (self.sliding is not None and self.sliding.complete)


#: the start of the progress label while a preview is shown
PREVIEW_HEADING = "Preview while the slider is held"


def preview_label(n: int) -> str:
    """What a preview is, in the progress label and the readout."""
    return f"{PREVIEW_HEADING}: {n} × {n} points; the full map is computed at the release"


def preview_words(pv: MapPreview) -> str:
    """What a preview is, in a hover."""
    return f"preview, {pv.points} × {pv.points} points (the full map is computed at the release)"


def seamless_cells_hook(plot: Any, element: Any) -> None:
    """HoloViews plot hook of an opaque heat map: each cell's edge is stroked in its own fill colour, so that the
    antialiased edges of neighbouring cells do not let the background show through as white seams (visible on the
    96 x 96 refined map). A faded or transparent mesh keeps no stroke (it would darken the cells' edges)."""
    readable_ticks_hook(plot, element)
    glyph = plot.handles.get("glyph")
    if glyph is None:
        return
    if glyph.fill_alpha == 1:
        glyph.update(line_color=glyph.fill_color, line_alpha=1, line_width=0.5)
    else:
        glyph.update(line_alpha=0)


def preview_title_hook(plot: Any, element: Any) -> None:
    """The map's title, which says when the map drawn is a preview (its heat map's hover column says so: see
    :func:`preview_words`). A HoloViews hook of the map's overlay, run at every update (its title option is fixed).
    A module function, not a method: HoloViews keeps options in a store for the life of the process until their
    object is collected, and a scene referred to from its own options would never be."""
    suffix = ""
    for el in element.values() if isinstance(element, hv.Overlay) else [element]:
        for dim in ("shown", "value_of"):
            if isinstance(el, hv.QuadMesh) and el.get_dimension(dim) is not None:
                values = el.dimension_values(dim)
                if values.size and str(values[0]).startswith("preview, "):
                    suffix = ": " + str(values[0]).split(" (")[0]
    fig_title = plot.state.title
    if fig_title is not None:
        fig_title.text = plot.title + suffix


def preview_totals(verdict: str) -> dict[str, int]:
    """The phases of a preview job: the Rayleigh branch's chunks, then the sliding verdict's points."""
    totals = {"chunks": len(chunk_rows(PREVIEW_POINTS))}
    if verdict == sm.SLIDING:
        totals["points"] = PREVIEW_SLIDING_POINTS**2
    return totals


def compute_preview(job_key: tuple, job: jobs.Job) -> MapPreview:
    """The preview of `job_key` (:attr:`MapPreview.job_key`): the Rayleigh branch's growth at :data:`PREVIEW_POINTS`
    per axis from the map's cached chunks (:func:`cached_chunk`; no certified crossings), then, coloured by the
    sliding verdict, that verdict at :data:`PREVIEW_SLIDING_POINTS` per axis
    (:func:`app.sliding_map.compute_sliding_map`, its chunks cached, each chunk published with the growth as the job's
    partial result); the work of a job."""
    verdict, key, floor = job_key
    plane, _, fixed, _ = key
    t0 = time.perf_counter()
    parts = []
    for a, b in chunk_rows(PREVIEW_POINTS):
        job.check()
        parts.append(cached_chunk(plane, PREVIEW_POINTS, a, b, fixed)[0])
        job.advance("chunks")
    x, y = plane_axes(plane, PREVIEW_POINTS)
    preview = MapPreview(job_key, x, y, growth=np.concatenate([p["growth"] for p in parts]),
                         kH_at_max=np.concatenate([p["kH_at_max"] for p in parts]),
                         n_masked=np.concatenate([p["n_masked"] for p in parts]), seconds=time.perf_counter() - t0)
    if verdict != sm.SLIDING:
        return preview
    n = PREVIEW_SLIDING_POINTS
    xs, ys = plane_axes(plane, n)
    names = (PLANES[plane][0].name, PLANES[plane][1].name)

    def publish(sliding: sm.SlidingMap) -> None:
        job.publish(replace(preview, sliding=sliding, seconds=time.perf_counter() - t0))

    sliding = sm.compute_sliding_map((plane, n, fixed, floor), xs, ys, names, CHUNKS.get, CHUNKS.put, job,
                                     strides=PREVIEW_SLIDING_STRIDES, chunk_points=PREVIEW_SLIDING_CHUNK,
                                     publish=publish, every_chunk=True)
    return replace(preview, sliding=sliding, seconds=time.perf_counter() - t0)


def after_previous(previous: list[jobs.Job], work: Callable[[jobs.Job], Any], job: jobs.Job) -> Any:
    """``work(job)`` once the job in `previous` (if any) has ended: a cancelled preview stops after its current chunk,
    and the next one starts computing only then, so that one preview of a session computes at a time however fast
    the hand moves (the list is emptied: an ended job is not kept alive by the next)."""
    if previous:
        before = previous.pop()
        before.wait(None)
        del before
    job.check()
    return work(job)


#: a margin around a map's range (a fraction of it, in log units on a log axis): the star clamped to an end (η = ∞
#: at the right edge) is drawn whole, not cut in half by the frame
MAP_MARGIN = 0.02


def _padded(a: Axis) -> tuple[float, float]:
    """The plotted range of axis `a` with :data:`MAP_MARGIN` either side."""
    if a.log:
        lo, hi = math.log10(a.lo), math.log10(a.hi)
        pad = MAP_MARGIN * (hi - lo)
        return 10.0 ** (lo - pad), 10.0 ** (hi + pad)
    pad = MAP_MARGIN * (a.hi - a.lo)
    return a.lo - pad, a.hi + pad


def key_for(plane: str, resolution: str, args: tuple[float, ...]) -> tuple:
    """What a map depends on: plane, points per axis, and the model arguments off the plane (normalised)."""
    names = {a.name for a in PLANES[plane]}
    fixed = tuple((k, float(v)) for k, v in zip(ARG_NAMES, args, strict=True) if k not in names)
    return (plane, RESOLUTIONS[resolution], fixed, LEVELS[resolution])


def grid_words(n: int, levels: int) -> str:
    """The map's grid in words: "24 × 24 points", refined: "…, refined to 96 × 96 at the neutral curve"."""
    m = n * 2**levels
    return f"{n} × {n} points" + (f", refined to {m} × {m} at the neutral curve" if levels else "")


def _round_sig(v: float, digits: int = 3) -> float:
    return float(f"{v:.{digits - 1}e}") if v != 0 else 0.0


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
        self.computation = jobs.Follower(self._show_job)
        #: the background computation of the sliding verdict (coarse to fine): cancelled when its inputs change
        self.sliding_computation = jobs.Follower(self._show_sliding_job)
        #: the background computation of Fig. 4c's sliding threshold: cancelled when f changes
        self.fig4c_computation = jobs.Follower(self._show_fig4c_job)
        #: the background computation of the preview while a slider is held: cancelled at every move and the release
        self.preview_computation = jobs.Follower(self._show_preview_job)
        #: the background computation of the exact sliding boundary (after the sliding map; planes with γ)
        self.boundary_computation = jobs.Follower(self._show_boundary_job)
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
        self.fig4c_dmap = (hv.DynamicMap(self._fig4c_curves, streams=[hv.streams.Params(self.params, ["f"])])
                           * hv.DynamicMap(self._fig4c_sliding_points,
                                           streams=[hv.streams.Params(self, ["fig4c_sliding"]),
                                                    hv.streams.Params(self.params, ["f"])])
                           * hv.DynamicMap(self._fig4c_marker, streams=[hv.streams.Params(
                               self.params, ["beta", "gamma", "f", "eta_infinite", "Delta"])])).opts(
            hv.opts.Overlay(title="Fig. 4c: instability threshold χ_c vs β (η = ∞, Δ = 1)", responsive=True,
                            height=340, legend_position="top_left", xlim=(0.0, 0.7071), ylim=CHI_RANGE))
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
        (:meth:`_follow_held_inputs`), a whole map (seconds) is computed once, at the release."""
        if self.params.dragging:
            self._follow_held_inputs()
            return
        if self._fig4c_drawn:  # f may have moved under a held slider: Fig. 4c's sliding threshold follows now
            self.ensure_fig4c_sliding()
        key = key_for(self.plane, self.resolution, self.params.model_args())
        if key != self.map_key:
            self.map_key = key
        skey = self._sliding_key_for(key)
        if skey != self.sliding_key:
            self.sliding_key = skey
        self._release_preview()

    # ----------------------------------------------------------------------------------------
    # the preview while a slider is held
    # ----------------------------------------------------------------------------------------

    def _follow_held_inputs(self) -> None:
        """A held slider moved: :attr:`preview_key` is the key of the held inputs where they change the map (a
        parameter off the plane). A new key cancels the running preview (latest value wins; the next render of the
        map starts the new one: :meth:`ensure_preview`); back at the map's own key the preview is dropped."""
        held = key_for(self.plane, self.resolution, self.params.model_args())
        held = None if held == self.map_key else held
        if held == self.preview_key:
            return
        self.preview_computation.cancel()
        if held is None:
            self._drop_preview(key_too=True)
            return
        self.preview_key = held
        self._update_download()

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
        if not self._previewing():
            return
        key = self._preview_job_key(self.preview_key)
        pv, job = self.preview, self.preview_computation.job
        if pv is not None and pv.job_key == key and pv.complete:
            return
        if job is not None and job.key == key and job.state().status != jobs.CANCELLED:
            return
        previous = [] if self._last_preview_job is None else [self._last_preview_job]
        self._last_preview_job = self.preview_computation.run(
            partial(after_previous, previous, partial(compute_preview, key)), name="stability map preview", key=key,
            totals=preview_totals(key[0]))
        self.preview_status = "computing"

    def wait_preview(self, timeout: float = 60.0) -> None:
        """Block until the preview being computed (if any) is finished, shown when not served (tests, scripts)."""
        self.preview_computation.wait(timeout)

    def _show_preview_job(self, job: jobs.Job, state: jobs.JobState) -> None:
        """Show a preview job's progress (in place of the map's while the slider is held) and its partial and final
        preview, or the failure (on the session's event loop)."""
        verdict = job.key[0]
        phase = "points" if verdict == sm.SLIDING else "chunks"
        total, done = state.totals.get(phase, 0), state.done.get(phase, 0)
        if self._previewing():
            if self.progress.max != total:
                self.progress.value = 0
                self.progress.max = total
            self.progress.value = done
            self.progress.visible = done < total
            n = PREVIEW_SLIDING_POINTS if verdict == sm.SLIDING else PREVIEW_POINTS
            self.progress_label.object = preview_label(n) + (
                f" (the sliding verdict at {done} of {total} points)" if phase == "points" and done < total else "")
        if state.status == jobs.RUNNING:
            self.preview_status = "computing"
            if state.partial is not None and state.partial is not self.preview:
                with frozen_document():
                    self.preview = state.partial
        elif state.status == jobs.FAILED:
            self.preview_status = f"error: {state.error}"
        elif state.status == jobs.DONE:
            with frozen_document():
                self.param.update(preview=state.result, preview_status="done")

    def _release_preview(self) -> None:
        """No slider held (the keys are those of the released inputs): stop the preview job; the preview of the
        released inputs stays drawn until their full map is shown (:meth:`_shown_preview`), a preview of other inputs
        is dropped."""
        if self.preview_key is None and self.preview is None and self.preview_computation.job is None:
            return
        self.preview_computation.cancel()
        pv = self.preview
        if pv is not None and pv.job_key != self._preview_job_key(self.map_key):
            self._drop_preview(key_too=True)
        else:
            self.param.update(preview_key=None, preview_status="idle")
            self._settle_progress()

    def _drop_preview(self, key_too: bool = False) -> None:
        """Stop and forget the preview (and, `key_too`, the held key): the map is drawn again."""
        self.preview_computation.cancel()
        was = self.preview is not None or self.preview_key is not None
        updates: dict[str, Any] = {"preview": None, "preview_status": "idle"}
        if key_too:
            updates["preview_key"] = None
        with frozen_document():
            self.param.update(**updates)
        if was:
            self._settle_progress()
        self._update_download()

    def _settle_progress(self) -> None:
        """The progress bar and label of the map once they no longer follow a preview: the map's name, or the
        progress of its job being computed (which the preview's label hid)."""
        if self._previewing() or not self.progress_label.object.startswith(PREVIEW_HEADING):
            return
        self._name_progress()

    def _name_progress(self) -> None:
        """The progress bar and label of the colouring shown: the map's name when it is complete, or the progress of
        its job being computed, or nothing."""
        plane, n, _, levels = self.map_key
        self.progress.visible = False
        if self.colours_sliding():
            done = self._sliding_current()
            self.progress_label.object = f"The sliding verdict over the {plane} map ({n} × {n} points)" if done else ""
        elif self._current():
            self.progress_label.object = f"The {plane} map ({grid_words(n, levels)})"
        else:
            self.progress_label.object = ""
        for follower, show in ((self.computation, self._show_job), (self.sliding_computation, self._show_sliding_job)):
            job = follower.job
            state = None if job is None else job.state()
            if state is not None and not state.finished:
                show(job, state)

    def _shown_preview(self, plane: str | None = None, verdict: str | None = None) -> MapPreview | None:
        """The preview the map of `plane` coloured by `verdict` (defaults: the current ones) draws in place of the map:
        while a slider is held at inputs off the map's, the latest preview (of them, or of the previous held value
        until theirs is computed); after the release, the preview of the released inputs until their full map (or
        its sliding map's first pass) is shown. None: the map is drawn."""
        pv = self.preview
        plane, verdict = plane or self.plane, verdict or self.verdict
        if pv is None or pv.plane != plane or pv.verdict != verdict or (pv.sliding is None and verdict == sm.SLIDING):
            return None
        if self.params.dragging:
            return pv if self.preview_key is not None else None
        if pv.job_key != self._preview_job_key(self.map_key):
            return None
        if verdict == sm.SLIDING:
            sl = self.sliding
            return None if sl is not None and sl.key == self.sliding_key else pv
        return None if self._current() else pv

    def _preview_drawn_over(self) -> None:
        """The full map (or the sliding map's first pass) of the released inputs is shown: their preview is
        dropped."""
        pv = self.preview
        if pv is not None and not self.params.dragging and self._shown_preview(pv.plane, pv.verdict) is None:
            self._drop_preview(key_too=True)

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
            self._name_progress()  # the label names the colouring shown, not the one left
        self._update_download()

    def ensure_sliding(self) -> None:
        """Start computing the sliding map of the current inputs unless it is shown complete or being computed."""
        key = self.sliding_key
        job = self.sliding_computation.job
        if self._sliding_current() or (job is not None and job.key == key
                                       and job.state().status in (jobs.RUNNING, jobs.DONE)):
            return
        plane, n = key[0], key[1]
        x, y = plane_axes(plane, n)
        names = (PLANES[plane][0].name, PLANES[plane][1].name)
        self.sliding_computation.run(partial(sm.compute_sliding_map, key, x, y, names, CHUNKS.get, CHUNKS.put),
                                     name="sliding map", key=key, totals={"points": n * n})
        self.sliding_status = "computing"

    def _show_sliding_job(self, job: jobs.Job, state: jobs.JobState) -> None:
        """Show the sliding job's progress, its latest preview and, at its end, the map or the failure."""
        plane, n = job.key[0], job.key[1]
        total, done = state.totals.get("points", 0), state.done.get("points", 0)
        if self.colours_sliding() and not self._previewing():
            if self.progress.max != total:
                self.progress.value = 0
                self.progress.max = total
            self.progress.value = done
            self.progress.visible = done < total  # a finished bar is not left on the page; the label says it
            preview = state.partial
            self.progress_label.object = (
                f"Computing the sliding verdict over the {plane} map ({n} × {n} points): {done} of {total} points"
                + (f"; shown: one point in {preview.stride} along each axis, each cell the value of its block's "
                   "lower-left point"
                   if preview is not None and state.status == jobs.RUNNING else "")
                if done < total else f"The sliding verdict over the {plane} map ({n} × {n} points)")
        if state.status == jobs.RUNNING:
            self.sliding_status = "computing"
            if state.partial is not None and state.partial is not self.sliding:
                with frozen_document():
                    self.sliding = state.partial
                self._preview_drawn_over()
        elif state.status == jobs.FAILED:
            self.sliding_status = f"error: {state.error}"
        elif state.status == jobs.DONE:
            with frozen_document():
                self.param.update(sliding=state.result, sliding_status="done")
            self._preview_drawn_over()
            self._update_download()
            self.ensure_boundary()

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
        key = self.sliding_key
        job = self.boundary_computation.job
        if (not self.boundary_applies() or not self._sliding_current() or self._boundary_current()
                or (job is not None and job.key == key and job.state().status in (jobs.RUNNING, jobs.DONE))):
            return
        plane, n = key[0], key[1]
        x, _ = plane_axes(plane, n)
        edges = PLANES[plane][1].edges(n)
        work = partial(sb.compute_boundary, key, x, PLANES[plane][0].name, (float(edges[0]), float(edges[-1])),
                       CHUNKS.get, CHUNKS.put, in_process=jobs.served_document() is not None)
        self.boundary_computation.run(work, name="sliding boundary", key=key, totals={"columns": n})
        self.boundary_status = "computing"

    def wait_boundary(self, timeout: float = 300.0) -> None:
        """Block until the boundary being computed (if any) is finished, and show it when not served (tests)."""
        self.boundary_computation.wait(timeout)

    def _show_boundary_job(self, job: jobs.Job, state: jobs.JobState) -> None:
        """Show the boundary's columns as they are computed and its end (or failure)."""
        shown = state.result if state.status == jobs.DONE else state.partial
        if shown is not None and shown is not self.boundary and state.status in (jobs.RUNNING, jobs.DONE):
            with frozen_document():
                self.boundary = {**shown, "key": job.key}
        if state.status == jobs.RUNNING:
            done, total = state.done.get("columns", 0), state.totals.get("columns", 0)
            self.boundary_status = f"computing: {done} of {total} columns"
        elif state.status == jobs.FAILED:
            self.boundary_status = f"error: {state.error}"
        elif state.status == jobs.DONE:
            self.boundary_status = "done"
        self._update_download()

    def _update_download(self) -> None:
        """The CSV is offered once the Rayleigh map is current (the sliding columns are added once that map is), never
        while a slider is held at inputs off the map's (a preview is drawn: the CSV would not be what is shown)."""
        self.map_download.disabled = not self._current() or self._previewing()
        self.boundary_download.disabled = not (self.boundary_applies() and self._boundary_current()
                                               and not self._previewing())
        if not self.boundary_download.disabled:
            ax, ay = PLANES[self.plane]
            self.boundary_download.filename = f"stability_map_{ax.name}_{ay.name}_sliding_boundary.csv"

    def ensure_map(self) -> None:
        """Start computing the map of the current key unless it is shown or already being computed (called where the
        session may be modified: a render, a parameter change)."""
        key = self.map_key
        job = self.computation.job
        if self._current() or (job is not None and job.key == key
                               and job.state().status in (jobs.RUNNING, jobs.DONE)):
            return
        self.computation.run(partial(compute_map, key), name="stability map", key=key,
                             totals={"chunks": len(chunk_rows(key[1])) + key[3]})

    def wait(self, timeout: float = 60.0) -> None:
        """Block until the map being computed (if any) is finished, and show it when not served (tests, scripts)."""
        self.computation.wait(timeout)

    def _show_job(self, job: jobs.Job, state: jobs.JobState) -> None:
        """Show a map job's progress and, at its end, the map or the failure (on the session's event loop)."""
        plane, n, _, levels = job.key
        total, done = state.totals.get("chunks", 0), state.done.get("chunks", 0)
        if not self._previewing():  # a held slider's preview shows its own progress
            if self.progress.max != total:
                self.progress.value = 0
                self.progress.max = total
            self.progress.value = done
            self.progress.visible = done < total  # a finished bar is not left on the page; the label says it
            unit = "steps (chunks, then levels of refinement)" if levels else "chunks"
            self.progress_label.object = (f"Computing the {plane} map ({grid_words(n, levels)}): {done} of {total} "
                                          f"{unit}" if done < total else f"The {plane} map ({grid_words(n, levels)})")
        if state.status == jobs.RUNNING:
            self.status = "computing"
        elif state.status == jobs.FAILED:
            self.status = f"error: {state.error}"
        elif state.status == jobs.DONE:
            with frozen_document():
                self.param.update(result=state.result, status="done")
            self._preview_drawn_over()
            ax, ay = PLANES[plane]
            self.map_download.filename = f"stability_map_{ax.name}_{ay.name}.csv"
            self._update_download()
            if self.colours_sliding() and self._current():
                self.ensure_sliding()

    # ----------------------------------------------------------------------------------------
    # the map plot (one DynamicMap per plane: the axes' scales differ)
    # ----------------------------------------------------------------------------------------

    def view(self, plane: str | None = None, verdict: str | None = None) -> hv.DynamicMap:
        """The map of `plane` coloured by `verdict` (defaults: the current ones): heat map * Rayleigh neutral curve *
        marker; a click on the heat map (its Tap stream, :attr:`tap_streams`) sets the sliders."""
        plane, verdict = plane or self.plane, verdict or self.verdict
        if (plane, verdict) not in self._views:
            ax, ay = PLANES[plane]
            if verdict == sm.SLIDING:
                streams = [hv.streams.Params(self, ["sliding", "sliding_key", "result", "map_key", "preview"])]
                under = hv.DynamicMap(partial(self._sliding_classes, plane), streams=streams)
                heat = hv.DynamicMap(partial(self._sliding_heat, plane), streams=streams)
                title = f"Sliding verdict (every branch) over the {plane} plane"
            else:
                heat = hv.DynamicMap(partial(self._heat, plane),
                                     streams=[hv.streams.Params(self, ["result", "map_key", "preview"])])
                title = f"Max growth rate of the Rayleigh branch over the {plane} plane"
            neutral = hv.DynamicMap(partial(self._neutral, plane, verdict),
                                    streams=[hv.streams.Params(self, ["result", "preview", "boundary"])])
            names = [p for a in (ax, ay) for p in (("log10_eta", "eta_infinite") if a.name == "eta" else (a.name,))]
            # the held inputs' key too: the marker's render is what starts their preview (only a shown map computes)
            marker = hv.DynamicMap(partial(self._marker, plane), streams=[hv.streams.Params(self.params, names),
                                                                          hv.streams.Params(self, ["preview_key"])])
            tap = hv.streams.Tap(source=heat, x=None, y=None)  # the source must give single elements
            tap.add_subscriber(partial(self._on_tap, plane))
            layers = (under * heat) if verdict == sm.SLIDING else heat
            overlay = (layers * neutral * marker).opts(hv.opts.Overlay(
                title=title, responsive=True, height=460, logx=ax.log, logy=ay.log, show_legend=False,
                xlim=_padded(ax), ylim=_padded(ay), hooks=[preview_title_hook]))
            self._views[plane, verdict], self.tap_streams[plane, verdict] = overlay, tap
        return self._views[plane, verdict]

    def _dims(self, plane: str) -> tuple[hv.Dimension, hv.Dimension]:
        ax, ay = PLANES[plane]
        return hv.Dimension(ax.name, label=ax.label), hv.Dimension(ay.name, label=ay.label)

    def _shown(self, plane: str) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, bool]:
        """x, y, growth of what the plane's plot shows (growth None: nothing computed for this plane yet) and
        whether it is the map of the current inputs; a refined map's on its finest grid (cell centres, each cell's
        value its owner's: app.map_refine)."""
        res, key = self.result, self.map_key
        current = res is not None and res.key == key
        if res is not None and res.plane == plane:
            if res.refined is not None:
                ax, ay = PLANES[plane]
                r = res.refined
                return (mr.level_centres(res.x, ax.log, r.levels), mr.level_centres(res.y, ay.log, r.levels),
                        r.growth, current)
            return res.x, res.y, res.growth, current
        x, y = plane_axes(plane, key[1])
        return x, y, None, False

    def _heat_cells(self, plane: str) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray, np.ndarray,
                                               bool]:
        """The heat map's cells: x and y edges, growth (None: nothing computed for this plane), where each cell's
        value was computed (x, y: the cell's centre, or its owner's on a refined map) and whether the map is current."""
        ax, ay = PLANES[plane]
        res = self.result
        x, y, growth, current = self._shown(plane)
        if res is not None and res.plane == plane and res.refined is not None:
            r = res.refined
            return r.x_edges, r.y_edges, growth, r.owner_x, r.owner_y, current
        return (ax.edges(x.size), ay.edges(y.size), growth, np.broadcast_to(x[None, :], (y.size, x.size)),
                np.broadcast_to(y[:, None], (y.size, x.size)), current)

    def _heat(self, plane: str, **_stream_values) -> hv.QuadMesh:
        """The heat map: the finished map; while one is computed, the previous map of this plane (faded) or a
        blank; while a slider is held at inputs off the map's, their preview (:meth:`_shown_preview`; its hover says
        so). Rendering it is what starts the computation (only a shown map computes)."""
        ax, ay = PLANES[plane]
        xe, ye, growth, at_x, at_y, current = self._heat_cells(plane)
        if plane == self.plane and not current:
            self.ensure_map()
        alpha = 1.0 if current else 0.45
        what = "the map" if current else "the map of the previous inputs"
        pv = self._shown_preview(plane, sm.RAYLEIGH)
        if pv is not None:
            xe, ye, growth, alpha, what = ax.edges(pv.x.size), ay.edges(pv.y.size), pv.growth, PREVIEW_ALPHA, \
                preview_words(pv)
            at_x, at_y = np.broadcast_to(pv.x[None, :], growth.shape), np.broadcast_to(pv.y[:, None], growth.shape)
        if growth is None:  # blank (zeros, transparent: an all-NaN mesh has no colour range)
            growth, alpha = np.zeros((ye.size - 1, xe.size - 1)), 0.0
        finite = np.abs(growth[np.isfinite(growth)])
        top = float(finite.max()) if finite.size and finite.max() > 0 else 1e-3
        xd, yd = self._dims(plane)
        shown = np.full(growth.shape, what, dtype=object)
        return hv.QuadMesh((xe, ye, growth, shown, at_x, at_y), kdims=[xd, yd],
                           vdims=[hv.Dimension("growth", label=GROWTH_LABEL), "shown", "at_x", "at_y"]).opts(
            cmap=GROWTH_CMAP, clim=(-top, top), colorbar=True, clabel=GROWTH_LABEL, framewise=True, alpha=alpha,
            clipping_colors={"NaN": NAN_COLOR}, line_alpha=0, logx=ax.log, logy=ay.log, tools=["hover"],
            hooks=[seamless_cells_hook],
            hover_tooltips=[(ax.label, "$x"), (ay.label, "$y"), (GROWTH_LABEL, "@growth"),
                            ("computed at", f"{ax.label} = @at_x, {ay.label} = @at_y"), ("shown", "@shown")],
            responsive=True, height=460, xlim=(ax.lo, ax.hi), ylim=(ay.lo, ay.hi))

    def _shown_sliding(self, plane: str) -> tuple[sm.SlidingMap | None, bool]:
        """The sliding map the plane's plot shows (None: none for this plane yet) and whether it is of the current
        inputs (complete or a preview; while a slider is held at inputs off the map's, their preview's sliding
        verdict: :meth:`_shown_preview`). Rendering it is what starts the computation."""
        if plane == self.plane and self.colours_sliding():
            if not self._current():
                self.ensure_map()
            elif not self._sliding_current():
                self.ensure_sliding()
        pv = self._shown_preview(plane, sm.SLIDING)
        if pv is not None:
            return pv.sliding, True
        sl = self.sliding
        if sl is None or sl.key[0] != plane:
            return None, False
        return sl, sl.key == self.sliding_key

    def _sliding_classes(self, plane: str, **_stream_values) -> hv.QuadMesh:
        """The sliding verdict's classes (stable, unstable, undetermined) under its growth; faded when stale."""
        ax, ay = PLANES[plane]
        sl, current = self._shown_sliding(plane)
        n = self.map_key[1] if sl is None else sl.x.size
        x, y = plane_axes(plane, n) if sl is None else (sl.x, sl.y)
        verdict = np.full((y.size, x.size), np.nan) if sl is None else sl.shown()["verdict"].astype(float)
        verdict[verdict < 0] = np.nan
        xd, yd = self._dims(plane)
        alpha = PREVIEW_ALPHA if self._shown_preview(plane, sm.SLIDING) is not None else 1.0 if current else 0.45
        return hv.QuadMesh((ax.edges(x.size), ay.edges(y.size), verdict), kdims=[xd, yd], vdims=["verdict_class"]).opts(
            cmap=list(sm.VERDICT_COLOURS), clim=(-0.5, 2.5), colorbar=False, alpha=alpha,
            clipping_colors={"NaN": "rgba(0,0,0,0)"}, line_alpha=0, logx=ax.log, logy=ay.log, tools=[],
            responsive=True, height=460, xlim=(ax.lo, ax.hi), ylim=(ay.lo, ay.hi))

    def _sliding_heat(self, plane: str, **_stream_values) -> hv.QuadMesh:
        """The growth of every branch where sliding is unstable (NaN elsewhere: the classes show through), with the
        hover's fields: the verdict in words, the family, kH and z of the fastest mode, and whether the cell is a
        preview."""
        ax, ay = PLANES[plane]
        sl, current = self._shown_sliding(plane)
        pv = self._shown_preview(plane, sm.SLIDING)
        n = self.map_key[1] if sl is None else sl.x.size
        x, y = plane_axes(plane, n) if sl is None else (sl.x, sl.y)
        shape = (y.size, x.size)
        if sl is None:
            growth, kh, rez = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
            words, shown = np.full(shape, "not computed yet", dtype=object), np.full(shape, "", dtype=object)
        else:
            d = sl.shown()
            growth = np.where(d["verdict"] == model.Verdict.UNSTABLE, d["growth"], np.nan)
            kh, rez = d["kH_at_max"], d["re_z"]
            words = sm.hover_text(d["verdict"], d["reason"], d["family"], sl.floor)
            shown = np.where(sl.exact(), "this point", np.where(d["verdict"] >= 0, "preview: its block's lower-left "
                                                                "point", "not computed yet")).astype(object)
            if pv is not None:
                shown = np.char.add(f"{preview_words(pv)}: ", shown.astype(str)).astype(object)
        floor = self.sliding_key[-1] if sl is None else sl.floor
        finite = growth[np.isfinite(growth)]
        top = max(float(finite.max()) if finite.size else 0.0, 10 * floor)
        xd, yd = self._dims(plane)
        return hv.QuadMesh((ax.edges(x.size), ay.edges(y.size), growth, words, kh, rez, shown), kdims=[xd, yd],
                           vdims=[hv.Dimension("growth_all", label=sm.GROWTH_ALL_LABEL), "sliding", "kH_at_max",
                                  "re_z", "value_of"]).opts(
            cmap=sm.GROWTH_ALL_CMAP, clim=(floor, top), logz=True, colorbar=True, clabel=sm.GROWTH_ALL_LABEL,
            framewise=True, alpha=PREVIEW_ALPHA if pv is not None else 1.0 if current else 0.45,
            clipping_colors={"NaN": "rgba(0,0,0,0)"}, line_alpha=0,
            logx=ax.log, logy=ay.log, tools=["hover"],
            hover_tooltips=[(ax.label, "$x"), (ay.label, "$y"), ("sliding", "@sliding"),
                            (sm.GROWTH_ALL_LABEL, "@growth_all"), ("kH at max", "@kH_at_max"),
                            ("Re z at max", "@re_z"), ("value of", "@value_of")],
            responsive=True, height=460, xlim=(ax.lo, ax.hi), ylim=(ay.lo, ay.hi))

    def _neutral(self, plane: str, verdict: str | None = None, **_stream_values) -> hv.Overlay:
        """The Rayleigh branch's neutral curve (:meth:`_rayleigh_neutral`) and, on the map coloured by the sliding
        verdict, the exact boundary of sliding over every branch (:meth:`_boundary_layers`)."""
        layers = self._rayleigh_neutral(plane, verdict)
        if (verdict or self.verdict) != sm.SLIDING:
            return hv.Overlay(layers)
        return hv.Overlay([*layers, *self._boundary_layers(plane)])

    def _boundary_layers(self, plane: str) -> list[hv.Element]:
        """The boundary of sliding over every branch through its certified thresholds γ_c at every column computed
        so far (purple; app.sliding_boundary), joined as the Rayleigh branch's are (:func:`crossing_lines`): drawn
        only over the sliding map it is of (empty layers otherwise: an overlay keeps its layers)."""
        dims = list(self._dims(plane))
        b = self.boundary
        lines, points = [], {"x": [], "y": []}
        if (b is not None and b["key"] == self.sliding_key and b["key"][0] == plane
                and self._shown_preview(plane, sm.SLIDING) is None):
            lines, points = crossing_lines(b)
        return [hv.Path(lines, kdims=dims, label="sliding boundary (every branch): certified γ_c").opts(
                    color=SLIDING_BOUNDARY_COLOR, line_width=3),
                hv.Points((points["x"], points["y"]), kdims=dims,
                          label="threshold of sliding γ_c (certified, every branch)").opts(
                    color=SLIDING_BOUNDARY_COLOR, size=5)]

    def _rayleigh_neutral(self, plane: str, verdict: str | None = None) -> list[hv.Element]:
        """The Rayleigh branch's neutral curve: on a plane with γ, through its certified thresholds γ_c at every
        column (exact along γ: :func:`compute_crossings`; sign changes that are not thresholds marked ×); on Δ-ξ,
        the contour of the grid's values. Over a preview (the map coloured by `verdict`, default the current one),
        the contour of the preview's coarse grid, dashed grey: :data:`PREVIEW_CONTOUR`."""
        x, y, growth, _ = self._shown(plane)
        ax, ay = PLANES[plane]
        res = self.result
        dims = list(self._dims(plane))
        pv = self._shown_preview(plane, verdict)
        if pv is not None:
            lines = neutral_lines(pv.x, pv.y, pv.growth, log_x=ax.log, log_y=ay.log)
            path = hv.Path(lines, kdims=dims, label=f"Rayleigh branch neutral curve: {PREVIEW_CONTOUR}").opts(
                color="#7f7f7f", line_width=2, line_dash="dashed")
            return [path, *self._crossing_points(dims, None)]
        crossings = res.crossings if res is not None and res.plane == plane else None
        if crossings is None:
            lines = [] if growth is None else neutral_lines(x, y, growth, log_x=ax.log, log_y=ay.log)
            label = ("Rayleigh branch neutral curve (max Im = 0" + (", grid contour)" if ay.name != "gamma" else ")"))
            return [hv.Path(lines, kdims=dims, label=label).opts(color="black", line_width=2),
                    *self._crossing_points(dims, None)]
        lines, points = crossing_lines(crossings)
        path = hv.Path(lines, kdims=dims, label="Rayleigh branch neutral curve: certified γ_c").opts(
            color="black", line_width=2)
        return [path, *self._crossing_points(dims, points)]

    @staticmethod
    def _crossing_points(dims: list, points: dict | None) -> list[hv.Element]:
        """The certified thresholds (small black dots) and the refused sign changes (×, with the reason on hover);
        empty elements keep the overlay's layers the same on every plane."""
        p = points or {"x": [], "y": [], "refused_x": [], "refused_y": [], "refused_reason": []}
        why = [model.CROSSING_STATUS[int(r)].split(":")[0] for r in p["refused_reason"]]
        return [hv.Points((p["x"], p["y"]), kdims=dims, label="threshold γ_c (certified neutral mode)").opts(
                    color="black", size=4),
                hv.Points((p["refused_x"], p["refused_y"], why), kdims=dims, vdims=["why"],
                          label="sign change, not a threshold").opts(
                    marker="x", size=9, color="#e66101", line_width=2, tools=["hover"])]

    def marker_position(self, plane: str | None = None) -> tuple[float, float, list[str]]:
        """(x, y) of the sliders' values on the plane, clipped to its range, and notes on the clipping."""
        plane = plane or self.plane
        out, notes = [], []
        for a in PLANES[plane]:
            v = self.params.eta if a.name == "eta" else float(getattr(self.params, a.name))
            shown = min(max(v, a.lo), a.hi)
            if shown != v:
                notes.append(f"{a.label} = {fmt(v) if np.isfinite(v) else '∞'} drawn at {fmt(shown)}")
            out.append(shown)
        return out[0], out[1], notes

    def _marker(self, plane: str, **_stream_values) -> hv.Points:
        """The star at the sliders' values. Its render, at every move of a held slider that changes the map's key,
        is what starts the held inputs' preview (:meth:`ensure_preview`): only a shown map computes."""
        if plane == self.plane:
            self.ensure_preview()
        x, y, _ = self.marker_position(plane)
        xd, yd = self._dims(plane)
        return hv.Points([(x, y)], kdims=[xd, yd], label="current parameters").opts(
            marker="star", size=18, color="#ffd92f", line_color="black", line_width=1.5)

    def _on_tap(self, plane: str, x: float | None = None, y: float | None = None) -> None:
        """A click on the map: set the plane's two parameters there (rounded, clamped to their bounds)."""
        if x is None or y is None or not (np.isfinite(x) and np.isfinite(y)):
            return
        updates: dict[str, float | bool] = {}
        for a, v in zip(PLANES[plane], (x, y), strict=True):
            if a.name == "eta":
                if v <= 0:
                    continue
                lo, hi = self.params.param.log10_eta.bounds
                updates.update(eta_infinite=False, log10_eta=min(max(round(math.log10(v), 2), lo), hi))
            else:
                lo, hi = self.params.param[a.name].bounds
                r = _round_sig(v) if a.log else round(round(v / a.step) * a.step, 6)
                updates[a.name] = float(min(max(r, lo), hi))
        with frozen_document():
            self.params.param.update(**updates)

    # ----------------------------------------------------------------------------------------
    # Fig. 4c
    # ----------------------------------------------------------------------------------------

    def _fig4c_curves(self, f: float, **_stream_values) -> hv.Overlay:
        self._fig4c_drawn = True
        self.ensure_fig4c_sliding()
        d = compute_fig4c(float(f))
        beta, chi = hv.Dimension("beta", label="β = c_s/c_d"), hv.Dimension("chi", label="χ_c = γ_c f")
        criterion = hv.Curve((d["beta_criterion"], d["criterion"]), beta, chi, label="criterion (Eq. criterion)").opts(
            color="#b2182b", line_width=2)
        exact = hv.Scatter((d["beta"], d["exact"]), beta, chi, label=f"exact threshold (f = {f:g})").opts(
            marker="circle", size=8, fill_color="white", line_color="#1f4e79", line_width=1.5)
        return criterion * exact

    def ensure_fig4c_sliding(self) -> None:
        """Start computing Fig. 4c's sliding threshold at the current f unless it is shown or being computed
        (called as Fig. 4c is drawn: a render, a change of f)."""
        if self.params.dragging:  # a held f slider: the job starts at the release (_update_key)
            return
        f = float(self.params.f)
        job = self.fig4c_computation.job
        shown = self.fig4c_sliding is not None and self.fig4c_sliding["f"] == f
        if shown or (job is not None and job.key == f and job.state().status in (jobs.RUNNING, jobs.DONE)):
            return
        self.fig4c_computation.run(partial(compute_fig4c_sliding, f), name="Fig. 4c sliding threshold", key=f,
                                   totals={"β": BETA_EXACT.size})

    def _show_fig4c_job(self, job: jobs.Job, state: jobs.JobState) -> None:
        """Fig. 4c's sliding-threshold job: its progress in the readout, then the points (or the failure)."""
        done, total = state.done.get("β", 0), state.totals.get("β", 0)
        if state.status == jobs.RUNNING:
            self.fig4c_sliding_status = (f"Computing the sliding threshold (every branch) at f = {fmt(job.key)}: "
                                         f"{done} of {total} β")
        elif state.status == jobs.FAILED:
            self.fig4c_sliding_status = f"The sliding threshold could not be computed: {state.error}"
        elif state.status == jobs.DONE:
            with frozen_document():
                self.param.update(fig4c_sliding=state.result, fig4c_sliding_status="")

    def wait_fig4c(self, timeout: float = 120.0) -> None:
        """Block until Fig. 4c's sliding threshold (if computing) is finished, shown when not served (tests)."""
        self.fig4c_computation.wait(timeout)

    def _fig4c_sliding_points(self, fig4c_sliding: dict | None = None, f: float | None = None,
                              **_stream_values) -> hv.Scatter:
        """The sliding threshold's certified points, at the f they were computed for (none for another f: redrawn
        when f changes, not only when the points do)."""
        beta, chi = hv.Dimension("beta", label="β = c_s/c_d"), hv.Dimension("chi", label="χ_c = γ_c f")
        d = fig4c_sliding
        current = d is not None and d["f"] == float(self.params.f if f is None else f)
        points = (d["beta"], d["chi"]) if current else ([], [])
        return hv.Scatter(points, beta, chi, label="sliding threshold (every branch)").opts(
            marker="triangle", size=9, color=SLIDING_THRESHOLD_COLOR, line_color="black")

    def _fig4c_marker(self, **_stream_values) -> hv.Overlay:
        p = self.params
        beta = hv.Dimension("beta", label="β = c_s/c_d")
        chi = hv.Dimension("chi", label="χ_c = γ_c f")
        point = [(p.beta, min(max(p.gamma * p.f, CHI_RANGE[0]), CHI_RANGE[1]))] if self.fig4c_applies() else []
        return (hv.VLine(p.beta).opts(color="#666666", line_dash="dotted", line_width=1.5)
                * hv.Points(point, kdims=[beta, chi], label="current χ = γ f").opts(
                    marker="star", size=16, color="#ffd92f", line_color="black"))

    def fig4c_applies(self) -> bool:
        """Fig. 4c is for η = ∞ and Δ = 1: only then is the current χ = γ f comparable with χ_c."""
        return bool(self.params.eta_infinite and self.params.Delta == 1)

    @param.depends("params.gamma", "params.f", "params.beta", "params.eta_infinite", "params.Delta", "fig4c_sliding",
                   "fig4c_sliding_status")
    def fig4c_readout(self) -> str:
        p = self.params
        if self.fig4c_applies():
            text = (f"**Current** χ = γ f = {fmt(p.gamma * p.f)} at β = {fmt(p.beta)} (star; dotted line: β). "
                    "The Rayleigh branch is unstable above its exact threshold (circles), sliding (every branch) "
                    "above the sliding threshold (triangles).")
            if not CHI_RANGE[0] <= p.gamma * p.f <= CHI_RANGE[1]:
                text += f" The star is drawn at the edge of the plotted range {CHI_RANGE}."
        else:
            text = (f"**Current** β = {fmt(p.beta)} (dotted line). Fig. 4c is for η = ∞ and Δ = 1; at the current "
                    "η and Δ the threshold differs, so χ = γ f is not drawn.")
        d = self.fig4c_sliding
        if self.fig4c_sliding_status:
            text += f"\n\n{self.fig4c_sliding_status}"
        elif d is not None and d["f"] == float(p.f):
            text += "\n\n" + fig4c_sliding_text(d)
        return text

    # ----------------------------------------------------------------------------------------
    # readout and export
    # ----------------------------------------------------------------------------------------

    @param.depends("result", "map_key", "status", "sliding", "sliding_key", "sliding_status", "verdict",
                   "preview", "preview_key", "preview_status", "boundary", "boundary_status",
                   "params.gamma", "params.log10_eta", "params.eta_infinite",
                   "params.f", "params.beta", "params.Delta", "params.xi", "params.dragging")
    def readout(self) -> str:
        plane, n, fixed, levels = self.map_key
        ax, ay = PLANES[plane]
        others = ", ".join(f"{SpectrumParams.symbol(k)} = {'∞' if np.isinf(v) else fmt(v)}" for k, v in fixed)
        lines = [f"**Plane** {plane}: x = {ax.label}, y = {ay.label}; {others}",
                 f"**Grid** {grid_words(n, levels)}, max over {KH.size} kH from {KH[0]:g} to {KH[-1]:g}"]
        res = self.result
        if self.status.startswith("error"):
            lines.append(f"**Failed** {self.status[len('error: '):]}")
        if res is None or res.key != self.map_key:
            lines.append("**Computing** the map…" if self.status == "computing" else "**Not computed yet**")
        else:
            g = res.growth
            finite = np.isfinite(g)
            n_nan = int((~finite).sum())
            unstable = int((g[finite] > MARGINAL).sum())
            marginal = int((np.abs(g[finite]) <= MARGINAL).sum())
            partial_mask = int((finite & (res.n_masked > 0)).sum())
            frac = unstable / finite.sum() if finite.any() else float("nan")
            largest = float(np.max(g[finite])) if finite.any() else float("nan")
            lines.append(f"**Unstable (Rayleigh branch)** {100 * frac:.1f} % of the {int(finite.sum())} computed "
                         f"points (max Im[c/c_s] > {MARGINAL:g}); largest growth {fmt(largest)}")
            if marginal:
                lines.append(f"**Marginal** {marginal} point(s) with |max Im| ≤ {MARGINAL:g}, drawn neutral")
            everywhere = int((~finite & (res.n_masked >= KH.size)).sum())
            if everywhere:
                lines.append(f"**Not computable** {everywhere} point(s) (dark grey): the Rayleigh branch could not be "
                             "followed at any kH")
            if n_nan - everywhere:
                lines.append(f"**Not computable** {n_nan - everywhere} point(s) (dark grey): the branch was followed "
                             "on (part of) the kH grid, but its maximum could not be refined (no value is shown "
                             "rather than an unrefined one)")
            if not n_nan:
                lines.append("**Not computable** none")
            if partial_mask:
                lines.append(f"**Partly masked** {partial_mask} point(s): branch not followable on part of the kH "
                             "grid; maximum over the rest")
            lines.append(self._neutral_line(res))
            if res.refined is not None:
                lines.append(self._refined_line(res.refined))
            cached = res.chunks_total - res.chunks_computed
            lines.append(f"**Time** {res.seconds:.2f} s ({res.chunks_total} chunks"
                         + (f", {cached} from the cache)" if cached else ")"))
        lines += self.preview_lines()
        lines += self.sliding_lines()
        lines += self.star_cell_lines()
        _, _, notes = self.marker_position(plane)
        if notes:
            lines.append("**Marker** " + "; ".join(notes))
        return "\n\n".join(lines)

    def preview_lines(self) -> list[str]:
        """The readout's lines on a held slider and the preview drawn (:meth:`_shown_preview`)."""
        pv = self._shown_preview()
        lines = []
        held = self.params.dragging and key_for(self.plane, self.resolution, self.params.model_args()) != self.map_key
        if held and pv is None:
            lines.append("**Slider held** the map is of the values above; a preview of the held values is drawn once "
                         "computed, the full map is computed at the release")
        if pv is not None:
            others = ", ".join(f"{SpectrumParams.symbol(k)} = {'∞' if np.isinf(v) else fmt(v)}" for k, v in pv.key[2])
            if held:
                lines.append(f"**Slider held** {preview_label(pv.points)}. The map drawn is a preview of {others}"
                             + ("" if pv.key == self.preview_key else
                                " (the preview of the values now held is being computed)"))
            else:
                lines.append(f"**Released** the full map of {others} is being computed; until it is shown, the map "
                             f"drawn is their preview ({pv.points} × {pv.points} points)")
            lines.append(f"**Neutral curve (preview)** dashed grey: the zero contour of the Rayleigh branch's growth "
                         f"on the preview's {PREVIEW_POINTS} × {PREVIEW_POINTS} grid ({PREVIEW_CONTOUR}); the other "
                         "numbers are of the full map of the values on the first line")
        if self.preview_status.startswith("error") and self._previewing():
            lines.append(f"**Preview failed** {self.preview_status[len('error: '):]}")
        return lines

    @staticmethod
    def _neutral_line(res: MapResult) -> str:
        """How the black curve was drawn: certified thresholds at every column, or the grid's contour."""
        c = res.crossings
        if c is None:
            return ("**Neutral curve** the contour of the grid's values (the model certifies thresholds in γ and η, "
                    "not along Δ or ξ)")
        certified, refused = sb.crossing_counts(c)
        return (f"**Neutral curve** exact in γ: {certified} certified threshold(s) γ_c (a neutral mode each, "
                f"model.critical_gammas) at {c['x'].size} x values"
                + (f"; {refused} sign change(s) that are not thresholds (×, reason on hover)" if refused else ""))

    @staticmethod
    def _refined_line(r: mr.RefinedMap) -> str:
        """How the map was refined: the points of each level, the finest grid, what an unrefined cell shows."""
        per_level = ", ".join(f"{r.evaluated(level)} at level {level}" for level in range(1, r.levels + 1))
        return (f"**Refined** where the Rayleigh verdict changes between neighbouring cells (stable against unstable): "
                f"{per_level} (finest {r.size} × {r.size} cells). Each cell shows the value computed at its centre or, "
                "not refined, at the centre of the coarser cell that holds it (hover: computed at); no value is "
                "interpolated")

    def _show_view(self, pane: pn.pane.HoloViews) -> None:
        """Show the view of the current plane and colouring, and start what it needs: a view shown again is not
        rendered again by HoloViews, so the render alone would leave a plane revisited "Not computed yet"."""
        pane.object = self.view()
        if not self._current():
            self.ensure_map()
        elif self.colours_sliding():
            self.ensure_sliding()
            self.ensure_boundary()

    @param.depends("verdict", "preview", "preview_key", "sliding", "result")
    def legend(self) -> str:
        """The map's colour legend, for the verdict it is coloured by (and the preview's line while one is drawn)."""
        text = sm.SLIDING_LEGEND if self.colours_sliding() else COLOUR_LEGEND
        if self._shown_preview() is not None:
            text += (f". Drawn now: a preview of the held values; its dashed grey line is the Rayleigh branch's zero "
                     f"contour on the preview's grid ({PREVIEW_CONTOUR}), in place of the black and purple lines")
        return f"Click the map to move the sliders there. {text}; star: current parameters."

    def sliding_lines(self) -> list[str]:
        """The readout's lines on the sliding verdict (every branch) of the current map."""
        if not self.colours_sliding():
            return ["**Sliding (every branch)** not computed: colour by the sliding verdict to compute it (the "
                    "numbers above are the Rayleigh branch's alone)"]
        sl = self.sliding
        lines = []
        if self.sliding_status.startswith("error"):
            lines.append(f"**Sliding failed** {self.sliding_status[len('error: '):]}")
        if sl is None or sl.key != self.sliding_key:
            lines.append("**Sliding (every branch)** computing…" if self._current() else
                         "**Sliding (every branch)** computed after the Rayleigh branch's map")
            return lines
        v = sl.fields["verdict"]
        done = v >= 0
        n_done = int(done.sum())
        lo, hi = sl.kH_range
        scope = f"Im z ≥ {sl.floor:g}, kH {lo:g} to {hi:g}"
        head = ("**Sliding (every branch)**" if sl.complete
                else f"**Sliding (every branch), preview** of {n_done} points:")
        unstable = int((v == 1).sum())
        lines.append(f"{head} unstable at {unstable} of {n_done} points ({100 * unstable / max(n_done, 1):.1f} %), "
                     f"stable at {int((v == 0).sum())}, undetermined at {int((v == 2).sum())} ({scope})")
        by_family = sm.family_counts(v, sl.fields["family"])
        if by_family:
            lines.append(f"**Fastest mode's family** (unstable points) {by_family}")
        res = self.result
        if res is not None and res.key == self.map_key:
            hidden = int((done & (v == 1) & ~(res.growth > MARGINAL)).sum())
            lines.append(f"**Rayleigh-branch stable, sliding unstable** {hidden} point(s): another branch grows there")
            below = int((done & (v == 0) & (res.growth > MARGINAL)).sum())
            if below:
                lines.append(f"**Below the floor** {below} point(s) drawn sliding stable where the Rayleigh "
                             f"branch grows slower than Im z = {sl.floor:g} (or only outside kH {lo:g} to {hi:g}): "
                             "lower the floor to resolve them")
        if (v == 2).any():
            lines.append("**Undetermined** (dark grey): no root above the floor was found, but the search was "
                         "refused at some kH (at finite η the window at a low floor is too wide: raise the floor)")
        if sl.fields["lower_bound"][done].any():
            lines.append("**Finite η**: the verdict holds at the kH searched (a narrow hump between them can be "
                         "missed; docs/physics.md §14.7)")
        lines.append(f"**Time (sliding)** {sl.seconds:.1f} s, {sl.computed} points")
        lines += self.boundary_lines()
        return lines

    def boundary_lines(self) -> list[str]:
        """The readout's lines on the exact boundary of sliding over every branch (purple)."""
        if not self.boundary_applies():
            return ["**Sliding boundary** not drawn on this plane: the model certifies thresholds of sliding in γ "
                    "(model.critical_gammas, branches=\"all\"), and this plane has no γ axis"]
        if self.boundary_status.startswith("error"):
            return [f"**Sliding boundary failed** {self.boundary_status[len('error: '):]}"]
        b = self.boundary
        if b is None or b["key"] != self.sliding_key:
            if not self._sliding_current():
                return ["**Sliding boundary** (purple) computed after the sliding map"]
            return [f"**Sliding boundary** (purple) {self.boundary_status} (a few seconds a column at finite η)"]
        text = sb.summary(b, "purple line")
        if not b["done"].all():
            text += f"; {self.boundary_status}"
        else:
            text += f"; {b['seconds']:.1f} s" + (f" ({b['cached']} of {b['x'].size} columns from the cache)"
                                                  if b["cached"] else "")
        return [text]

    def star_cell(self) -> tuple[int, int] | None:
        """(row, column) of the map's cell under the star (None: the star lies off the plane's range)."""
        x, y, notes = self.marker_position()
        if notes:
            return None
        ax, ay = PLANES[self.plane]
        n = self.map_key[1]
        ix = int(np.clip(np.searchsorted(ax.edges(n), x) - 1, 0, n - 1))
        iy = int(np.clip(np.searchsorted(ay.edges(n), y) - 1, 0, n - 1))
        return iy, ix

    def star_cell_lines(self) -> list[str]:
        """The readout of the map's cell under the star: both verdicts there, the fastest mode's family, kH and z."""
        cell = self.star_cell()
        res = self.result
        if cell is None or res is None or res.key != self.map_key:
            return []
        iy, ix = cell
        ax, ay = PLANES[self.plane]
        at_x, at_y, g, kh = res.x[ix], res.y[iy], float(res.growth[iy, ix]), float(res.kH_at_max[iy, ix])
        if res.refined is not None:  # the finest cell under the star, and the point its value was computed at
            r = res.refined
            x, y, _ = self.marker_position()
            fy = int(np.clip(np.searchsorted(r.y_edges, y) - 1, 0, r.size - 1))
            fx = int(np.clip(np.searchsorted(r.x_edges, x) - 1, 0, r.size - 1))
            at_x, at_y = r.owner_x[fy, fx], r.owner_y[fy, fx]
            g, kh = float(r.growth[fy, fx]), float(r.kH_at_max[fy, fx])
        where = f"{ax.label} = {fmt(at_x)}, {ay.label} = {fmt(at_y)}"
        ray = ("not computable" if not np.isfinite(g) else
               f"unstable, max Im[c/c_s] = {fmt(g)} at kH = {fmt(kh)}" if g > MARGINAL
               else f"stable, max Im[c/c_s] = {fmt(g)}")
        lines = [f"**The star's cell** ({where}): Rayleigh branch {ray}"]
        sl = self.sliding
        shown = self.colours_sliding() and sl is not None and sl.key == self.sliding_key
        if shown and sl.fields["verdict"][iy, ix] >= 0:
            f = {k: v[iy, ix] for k, v in sl.fields.items()}
            text = sm.cell_text(verdict=f["verdict"], reason=f["reason"], family=f["family"], growth=f["growth"],
                                kH=f["kH_at_max"], re_z=f["re_z"], lower_bound=bool(f["lower_bound"]), floor=sl.floor)
            at = (f" ({ax.label} = {fmt(res.x[ix])}, {ay.label} = {fmt(res.y[iy])})" if res.refined is not None
                  else "")
            lines.append(f"**The star's cell, sliding (every branch)**{at} {text}")
        return lines

    def map_csv(self) -> io.StringIO:
        """What the map shows: both plane parameters, max growth, kH at the maximum, masked kH points per point."""
        res = self.result
        plane, n, fixed, levels = self.map_key
        ax, ay = PLANES[plane]
        header = (f"asymslide stability map, plane {ax.name}-{ay.name}; max over kH = logspace(-3, 3, {KH.size}); "
                  + ", ".join(f"{k} = {v!r}" for k, v in fixed)
                  + f". max_growth NaN: not computable (n_masked_kH = {KH.size}: the branch was not followed at any "
                    "kH; fewer: its maximum could not be refined)")
        if res is None or res.key != self.map_key:
            return csv_table(header + " (not computed yet)",
                             {ax.name: [], ay.name: [], "max_growth": [], "kH_at_max": [], "n_masked_kH": []})
        nx, ny = res.x.size, res.y.size
        columns = {ax.name: np.tile(res.x, ny), ay.name: np.repeat(res.y, nx), "max_growth": res.growth.ravel(),
                   "kH_at_max": res.kH_at_max.ravel(), "n_masked_kH": res.n_masked.ravel()}
        refined = res.refined.points if res.refined is not None else None
        if refined is not None:
            header += (f". level 0: the {nx} × {ny} grid; level 1..{levels}: the points added where the Rayleigh "
                       "verdict changes between neighbouring cells (each level halves the cells)")
            columns = {ax.name: np.concatenate([columns[ax.name], refined["x"]]),
                       ay.name: np.concatenate([columns[ay.name], refined["y"]]),
                       "max_growth": np.concatenate([columns["max_growth"], refined["growth"]]),
                       "kH_at_max": np.concatenate([columns["kH_at_max"], refined["kH_at_max"]]),
                       "n_masked_kH": np.concatenate([columns["n_masked_kH"], refined["n_masked"]]).astype(int),
                       "level": np.concatenate([np.zeros(nx * ny, int), refined["level"].astype(int)])}
        sl = self.sliding
        if self.colours_sliding() and not self._sliding_current():
            header += ". Sliding over every branch: not in this file (its map is being computed: download it again "
            header += "when it is complete)"
        if self.colours_sliding() and self._sliding_current() and sl is not None:
            lo, hi = sl.kH_range
            header += (f". Sliding over every branch (model.sliding_analysis, kH {lo!r} to {hi!r}, floor "
                       f"{sl.floor!r}): verdict_all 0 stable, 1 unstable, 2 undetermined; verdict_reason_all "
                       "model.SLIDING_STATUS; "
                       "family_all model.FAMILIES (-1: none); max_growth_all NaN unless unstable and certified")
            f = sl.fields
            extra = 0 if refined is None else refined["x"].size
            if extra:
                header += " (on the level-0 grid only: NaN or -1 on the refined points)"

            def pad(a: np.ndarray, fill: float) -> np.ndarray:
                a = a.ravel()
                return np.concatenate([a, np.full(extra, fill, dtype=float if np.isnan(fill) else a.dtype)])

            columns.update({"max_growth_all": pad(f["growth"], np.nan), "kH_at_max_all": pad(f["kH_at_max"], np.nan),
                            "re_z_at_max_all": pad(f["re_z"], np.nan), "family_all": pad(f["family"], -1),
                            "verdict_all": pad(f["verdict"], -1), "verdict_reason_all": pad(f["reason"], -1)})
        return csv_table(header, columns)

    def boundary_csv(self) -> io.StringIO:
        """The threshold of sliding over every branch drawn on the map (purple): per column of the grid, every
        crossing in γ (model.critical_gammas with branches="all"), certified or not, with its reason."""
        plane, n, fixed, floor = self.sliding_key
        ax, _ = PLANES[plane]
        header = (f"asymslide stability map, plane {ax.name}-gamma: crossings in gamma of the max growth over every "
                  f"branch (model.critical_gammas, branches='all', floor {floor!r}, kH model.SLIDING_KH) at each "
                  f"x of the {n} x {n} grid; " + ", ".join(f"{k} = {v!r}" for k, v in fixed)
                  + ". gamma_c NaN unless certified (reason 0: a neutral mode; 1: at an end of the kH range); "
                    "location: where the sign change is; direction +1: unstable above, -1: stable above; reason: "
                    "model.CROSSING_STATUS; kH, re_z: the neutral mode")
        names = (ax.name, "crossing", "gamma_c", "location", "direction", "reason", "kH", "re_z")
        b = self.boundary
        if not (self.boundary_applies() and self._boundary_current()):
            return csv_table(header + " (not computed yet)", dict.fromkeys(names, []))
        rows = np.argwhere(b["reason"] >= 0)  # (column, crossing) of every crossing found
        i, k = rows[:, 0], rows[:, 1]
        return csv_table(header, dict(zip(names, (b["x"][i], k, b["value"][i, k], b["location"][i, k],
                                                  b["direction"][i, k], b["reason"][i, k], b["kH"][i, k],
                                                  b["z"][i, k]), strict=True)))

    def fig4c_csv(self) -> io.StringIO:
        """What Fig. 4c shows: β, the criterion's χ_c, and the exact threshold χ_c at the current f (computed at
        every other β: NaN at the others, and where there is no threshold)."""
        f = float(self.params.f)
        d = compute_fig4c(f)
        exact = np.full(d["beta_criterion"].shape, np.nan)
        exact[1::2] = d["exact"]
        columns = {"beta": d["beta_criterion"], "chi_c_criterion": d["criterion"], "chi_c_exact": exact}
        sl = self.fig4c_sliding
        note = "chi_c_sliding (every branch) not computed yet"
        if sl is not None and sl["f"] == f:
            chi = np.full(exact.shape, np.nan)
            chi[1::2] = sl["chi"]
            columns["chi_c_sliding"] = chi
            note = ("chi_c_sliding: the sliding threshold over every branch (model.critical_gammas branches='all', "
                    "first certified crossing; NaN: none certified)")
        return csv_table(f"asymslide Fig. 4c (eta = inf, Delta = 1); f = {f!r}; chi_c_exact at every other beta; "
                         f"{note}", columns)

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
