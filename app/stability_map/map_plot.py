"""The Stability map's plot: one HoloViews overlay per plane and colouring (heat map, neutral curves, the star), each
layer a function of the scene's state (a :class:`~asymslide.app.stability_map.scene.StabilityMapScene`), and the
hooks that draw it seamless and title a preview."""

from __future__ import annotations

import math
from functools import partial
from typing import Any

import holoviews as hv
import numpy as np

from asymslide import model

from .. import map_refine as mr
from .. import sliding_map as sm
from ..common import GROWTH_CMAP, GROWTH_LABEL, NAN_COLOR, neutral_lines
from ..plotting import fmt, readable_ticks_hook
from ..workarounds import frozen_document
from .compute import crossing_lines
from .grids import PLANES, Axis, plane_axes
from .preview import PREVIEW_CONTOUR, preview_words

#: the colour of the boundary of sliding over every branch (app.sliding_boundary) on the map
SLIDING_BOUNDARY_COLOR = "#762a83"
#: the opacity of a preview (a full map is opaque, a map of the previous inputs 0.45)
PREVIEW_ALPHA = 0.8

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


def _round_sig(v: float, digits: int = 3) -> float:
    """`v` rounded to `digits` significant digits (a click on a log axis)."""
    return float(f"{v:.{digits - 1}e}") if v != 0 else 0.0


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
    :func:`~.preview.preview_words`). A HoloViews hook of the map's overlay, run at every update (its title option is
    fixed). A module function, not a method: HoloViews keeps options in a store for the life of the process until their
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


def build_view(scene: Any, plane: str, verdict: str) -> tuple[hv.Overlay, hv.streams.Tap]:
    """The map of `plane` coloured by `verdict`: heat map * Rayleigh neutral curve * marker, and the Tap stream of
    its heat map, whose click sets the sliders."""
    ax, ay = PLANES[plane]
    if verdict == sm.SLIDING:
        streams = [hv.streams.Params(scene, ["sliding", "sliding_key", "result", "map_key", "preview"])]
        under = hv.DynamicMap(partial(sliding_classes, scene, plane), streams=streams)
        heat_map = hv.DynamicMap(partial(sliding_heat, scene, plane), streams=streams)
        title = f"Sliding verdict (every branch) over the {plane} plane"
    else:
        heat_map = hv.DynamicMap(partial(heat, scene, plane),
                                 streams=[hv.streams.Params(scene, ["result", "map_key", "preview"])])
        title = f"Max growth rate of the Rayleigh branch over the {plane} plane"
    curves = hv.DynamicMap(partial(neutral, scene, plane, verdict),
                           streams=[hv.streams.Params(scene, ["result", "preview", "boundary"])])
    names = [p for a in (ax, ay) for p in (("log10_eta", "eta_infinite") if a.name == "eta" else (a.name,))]
    # the held inputs' key too: the marker's render is what starts their preview (only a shown map computes)
    star = hv.DynamicMap(partial(marker, scene, plane), streams=[hv.streams.Params(scene.params, names),
                                                                 hv.streams.Params(scene, ["preview_key"])])
    tap = hv.streams.Tap(source=heat_map, x=None, y=None)  # the source must give single elements
    tap.add_subscriber(partial(on_tap, scene, plane))
    layers = (under * heat_map) if verdict == sm.SLIDING else heat_map
    overlay = (layers * curves * star).opts(hv.opts.Overlay(
        title=title, responsive=True, height=460, logx=ax.log, logy=ay.log, show_legend=False,
        xlim=_padded(ax), ylim=_padded(ay), hooks=[preview_title_hook]))
    return overlay, tap


def dims(plane: str) -> tuple[hv.Dimension, hv.Dimension]:
    """The plane's x and y dimensions (model names, the paper's symbols as labels)."""
    ax, ay = PLANES[plane]
    return hv.Dimension(ax.name, label=ax.label), hv.Dimension(ay.name, label=ay.label)


def shown_map(scene: Any, plane: str) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, bool]:
    """x, y, growth of what the plane's plot shows (growth None: nothing computed for this plane yet) and
    whether it is the map of the current inputs; a refined map's on its finest grid (cell centres, each cell's
    value its owner's: app.map_refine)."""
    res, key = scene.result, scene.map_key
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


def heat_cells(scene: Any, plane: str) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray, np.ndarray,
                                           bool]:
    """The heat map's cells: x and y edges, growth (None: nothing computed for this plane), where each cell's
    value was computed (x, y: the cell's centre, or its owner's on a refined map) and whether the map is current."""
    ax, ay = PLANES[plane]
    res = scene.result
    x, y, growth, current = shown_map(scene, plane)
    if res is not None and res.plane == plane and res.refined is not None:
        r = res.refined
        return r.x_edges, r.y_edges, growth, r.owner_x, r.owner_y, current
    return (ax.edges(x.size), ay.edges(y.size), growth, np.broadcast_to(x[None, :], (y.size, x.size)),
            np.broadcast_to(y[:, None], (y.size, x.size)), current)


def heat(scene: Any, plane: str, **_stream_values) -> hv.QuadMesh:
    """The heat map: the finished map; while one is computed, the previous map of this plane (faded) or a
    blank; while a slider is held at inputs off the map's, their preview (:func:`~.held.shown_preview`; its hover
    says so). Rendering it is what starts the computation (only a shown map computes)."""
    ax, ay = PLANES[plane]
    xe, ye, growth, at_x, at_y, current = heat_cells(scene, plane)
    if plane == scene.plane and not current:
        scene.ensure_map()
    alpha = 1.0 if current else 0.45
    what = "the map" if current else "the map of the previous inputs"
    pv = scene._shown_preview(plane, sm.RAYLEIGH)
    if pv is not None:
        xe, ye, growth, alpha, what = ax.edges(pv.x.size), ay.edges(pv.y.size), pv.growth, PREVIEW_ALPHA, \
            preview_words(pv)
        at_x, at_y = np.broadcast_to(pv.x[None, :], growth.shape), np.broadcast_to(pv.y[:, None], growth.shape)
    if growth is None:  # blank (zeros, transparent: an all-NaN mesh has no colour range)
        growth, alpha = np.zeros((ye.size - 1, xe.size - 1)), 0.0
    finite = np.abs(growth[np.isfinite(growth)])
    top = float(finite.max()) if finite.size and finite.max() > 0 else 1e-3
    xd, yd = dims(plane)
    shown = np.full(growth.shape, what, dtype=object)
    return hv.QuadMesh((xe, ye, growth, shown, at_x, at_y), kdims=[xd, yd],
                       vdims=[hv.Dimension("growth", label=GROWTH_LABEL), "shown", "at_x", "at_y"]).opts(
        cmap=GROWTH_CMAP, clim=(-top, top), colorbar=True, clabel=GROWTH_LABEL, framewise=True, alpha=alpha,
        clipping_colors={"NaN": NAN_COLOR}, line_alpha=0, logx=ax.log, logy=ay.log, tools=["hover"],
        hooks=[seamless_cells_hook],
        hover_tooltips=[(ax.label, "$x"), (ay.label, "$y"), (GROWTH_LABEL, "@growth"),
                        ("computed at", f"{ax.label} = @at_x, {ay.label} = @at_y"), ("shown", "@shown")],
        responsive=True, height=460, xlim=(ax.lo, ax.hi), ylim=(ay.lo, ay.hi))


def shown_sliding(scene: Any, plane: str) -> tuple[sm.SlidingMap | None, bool]:
    """The sliding map the plane's plot shows (None: none for this plane yet) and whether it is of the current
    inputs (complete or a preview; while a slider is held at inputs off the map's, their preview's sliding
    verdict: :func:`~.held.shown_preview`). Rendering it is what starts the computation."""
    if plane == scene.plane and scene.colours_sliding():
        if not scene._current():
            scene.ensure_map()
        elif not scene._sliding_current():
            scene.ensure_sliding()
    pv = scene._shown_preview(plane, sm.SLIDING)
    if pv is not None:
        return pv.sliding, True
    sl = scene.sliding
    if sl is None or sl.key[0] != plane:
        return None, False
    return sl, sl.key == scene.sliding_key


def sliding_classes(scene: Any, plane: str, **_stream_values) -> hv.QuadMesh:
    """The sliding verdict's classes (stable, unstable, undetermined) under its growth; faded when stale."""
    ax, ay = PLANES[plane]
    sl, current = shown_sliding(scene, plane)
    n = scene.map_key[1] if sl is None else sl.x.size
    x, y = plane_axes(plane, n) if sl is None else (sl.x, sl.y)
    verdict = np.full((y.size, x.size), np.nan) if sl is None else sl.shown()["verdict"].astype(float)
    verdict[verdict < 0] = np.nan
    xd, yd = dims(plane)
    alpha = PREVIEW_ALPHA if scene._shown_preview(plane, sm.SLIDING) is not None else 1.0 if current else 0.45
    return hv.QuadMesh((ax.edges(x.size), ay.edges(y.size), verdict), kdims=[xd, yd], vdims=["verdict_class"]).opts(
        cmap=list(sm.VERDICT_COLOURS), clim=(-0.5, 2.5), colorbar=False, alpha=alpha,
        clipping_colors={"NaN": "rgba(0,0,0,0)"}, line_alpha=0, logx=ax.log, logy=ay.log, tools=[],
        responsive=True, height=460, xlim=(ax.lo, ax.hi), ylim=(ay.lo, ay.hi))


def sliding_heat(scene: Any, plane: str, **_stream_values) -> hv.QuadMesh:
    """The growth of every branch where sliding is unstable (NaN elsewhere: the classes show through), with the
    hover's fields: the verdict in words, the family, kH and z of the fastest mode, and whether the cell is a
    preview."""
    ax, ay = PLANES[plane]
    sl, current = shown_sliding(scene, plane)
    pv = scene._shown_preview(plane, sm.SLIDING)
    n = scene.map_key[1] if sl is None else sl.x.size
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
    floor = scene.sliding_key[-1] if sl is None else sl.floor
    finite = growth[np.isfinite(growth)]
    top = max(float(finite.max()) if finite.size else 0.0, 10 * floor)
    xd, yd = dims(plane)
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


def neutral(scene: Any, plane: str, verdict: str | None = None, **_stream_values) -> hv.Overlay:
    """The Rayleigh branch's neutral curve (:func:`rayleigh_neutral`) and, on the map coloured by the sliding
    verdict, the exact boundary of sliding over every branch (:func:`boundary_layers`)."""
    layers = rayleigh_neutral(scene, plane, verdict)
    if (verdict or scene.verdict) != sm.SLIDING:
        return hv.Overlay(layers)
    return hv.Overlay([*layers, *boundary_layers(scene, plane)])


def boundary_layers(scene: Any, plane: str) -> list[hv.Element]:
    """The boundary of sliding over every branch through its certified thresholds γ_c at every column computed
    so far (purple; app.sliding_boundary), joined as the Rayleigh branch's are (:func:`~.compute.crossing_lines`): drawn
    only over the sliding map it is of (empty layers otherwise: an overlay keeps its layers)."""
    kd = list(dims(plane))
    b = scene.boundary
    lines, points = [], {"x": [], "y": []}
    if (b is not None and b["key"] == scene.sliding_key and b["key"][0] == plane
            and scene._shown_preview(plane, sm.SLIDING) is None):
        lines, points = crossing_lines(b)
    return [hv.Path(lines, kdims=kd, label="sliding boundary (every branch): certified γ_c").opts(
                color=SLIDING_BOUNDARY_COLOR, line_width=3),
            hv.Points((points["x"], points["y"]), kdims=kd,
                      label="threshold of sliding γ_c (certified, every branch)").opts(
                color=SLIDING_BOUNDARY_COLOR, size=5)]


def rayleigh_neutral(scene: Any, plane: str, verdict: str | None = None) -> list[hv.Element]:
    """The Rayleigh branch's neutral curve: on a plane with γ, through its certified thresholds γ_c at every
    column (exact along γ: :func:`~.compute.compute_crossings`; sign changes that are not thresholds marked ×); on Δ-ξ,
    the contour of the grid's values. Over a preview (the map coloured by `verdict`, default the current one),
    the contour of the preview's coarse grid, dashed grey: :data:`~.preview.PREVIEW_CONTOUR`."""
    x, y, growth, _ = shown_map(scene, plane)
    ax, ay = PLANES[plane]
    res = scene.result
    kd = list(dims(plane))
    pv = scene._shown_preview(plane, verdict)
    if pv is not None:
        lines = neutral_lines(pv.x, pv.y, pv.growth, log_x=ax.log, log_y=ay.log)
        path = hv.Path(lines, kdims=kd, label=f"Rayleigh branch neutral curve: {PREVIEW_CONTOUR}").opts(
            color="#7f7f7f", line_width=2, line_dash="dashed")
        return [path, *crossing_points(kd, None)]
    crossings = res.crossings if res is not None and res.plane == plane else None
    if crossings is None:
        lines = [] if growth is None else neutral_lines(x, y, growth, log_x=ax.log, log_y=ay.log)
        label = ("Rayleigh branch neutral curve (max Im = 0" + (", grid contour)" if ay.name != "gamma" else ")"))
        return [hv.Path(lines, kdims=kd, label=label).opts(color="black", line_width=2),
                *crossing_points(kd, None)]
    lines, points = crossing_lines(crossings)
    path = hv.Path(lines, kdims=kd, label="Rayleigh branch neutral curve: certified γ_c").opts(
        color="black", line_width=2)
    return [path, *crossing_points(kd, points)]


def crossing_points(kd: list, points: dict | None) -> list[hv.Element]:
    """The certified thresholds (small black dots) and the refused sign changes (×, with the reason on hover);
    empty elements keep the overlay's layers the same on every plane."""
    p = points or {"x": [], "y": [], "refused_x": [], "refused_y": [], "refused_reason": []}
    why = [model.CROSSING_STATUS[int(r)].split(":")[0] for r in p["refused_reason"]]
    return [hv.Points((p["x"], p["y"]), kdims=kd, label="threshold γ_c (certified neutral mode)").opts(
                color="black", size=4),
            hv.Points((p["refused_x"], p["refused_y"], why), kdims=kd, vdims=["why"],
                      label="sign change, not a threshold").opts(
                marker="x", size=9, color="#e66101", line_width=2, tools=["hover"])]


def marker(scene: Any, plane: str, **_stream_values) -> hv.Points:
    """The star at the sliders' values. Its render, at every move of a held slider that changes the map's key,
    is what starts the held inputs' preview (:func:`~.map_jobs.start_preview`): only a shown map computes."""
    if plane == scene.plane:
        scene.ensure_preview()
    x, y, _ = scene.marker_position(plane)
    xd, yd = dims(plane)
    return hv.Points([(x, y)], kdims=[xd, yd], label="current parameters").opts(
        marker="star", size=18, color="#ffd92f", line_color="black", line_width=1.5)


def on_tap(scene: Any, plane: str, x: float | None = None, y: float | None = None) -> None:
    """A click on the map: set the plane's two parameters there (rounded, clamped to their bounds)."""
    if x is None or y is None or not (np.isfinite(x) and np.isfinite(y)):
        return
    updates: dict[str, float | bool] = {}
    for a, v in zip(PLANES[plane], (x, y), strict=True):
        if a.name == "eta":
            if v <= 0:
                continue
            lo, hi = scene.params.param.log10_eta.bounds
            updates.update(eta_infinite=False, log10_eta=min(max(round(math.log10(v), 2), lo), hi))
        else:
            lo, hi = scene.params.param[a.name].bounds
            r = _round_sig(v) if a.log else round(round(v / a.step) * a.step, 6)
            updates[a.name] = float(min(max(r, lo), hi))
    with frozen_document():
        scene.params.param.update(**updates)


def marker_position(scene: Any, plane: str | None = None) -> tuple[float, float, list[str]]:
    """(x, y) of the sliders' values on the plane, clipped to its range, and notes on the clipping."""
    plane = plane or scene.plane
    out, notes = [], []
    for a in PLANES[plane]:
        v = scene.params.eta if a.name == "eta" else float(getattr(scene.params, a.name))
        shown = min(max(v, a.lo), a.hi)
        if shown != v:
            notes.append(f"{a.label} = {fmt(v) if np.isfinite(v) else '∞'} drawn at {fmt(shown)}")
        out.append(shown)
    return out[0], out[1], notes
