"""The Stability map's readout and legend in words: the map (Rayleigh branch), a held slider's preview, the sliding
verdict (every branch), its exact boundary and the cell under the star; each a function of the scene's state (a
:class:`~asymslide.app.stability_map.scene.StabilityMapScene`)."""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import map_refine as mr
from .. import sliding_boundary as sb
from .. import sliding_map as sm
from ..common import COLOUR_LEGEND, MARGINAL
from ..params import SpectrumParams
from ..plotting import fmt
from .compute import MapResult
from .grids import KH, PLANES, grid_words, key_for
from .preview import PREVIEW_CONTOUR, PREVIEW_POINTS, preview_label


def map_readout(scene: Any) -> str:
    """The readout: the plane and grid, the map's numbers, the preview, the sliding verdict, the star's cell."""
    plane, n, fixed, levels = scene.map_key
    ax, ay = PLANES[plane]
    others = ", ".join(f"{SpectrumParams.symbol(k)} = {'∞' if np.isinf(v) else fmt(v)}" for k, v in fixed)
    lines = [f"**Plane** {plane}: x = {ax.label}, y = {ay.label}; {others}",
             f"**Grid** {grid_words(n, levels)}, max over {KH.size} kH from {KH[0]:g} to {KH[-1]:g}"]
    res = scene.result
    if scene.status.startswith("error"):
        lines.append(f"**Failed** {scene.status[len('error: '):]}")
    if res is None or res.key != scene.map_key:
        lines.append("**Computing** the map…" if scene.status == "computing" else "**Not computed yet**")
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
        lines.append(neutral_line(res))
        if res.refined is not None:
            lines.append(refined_line(res.refined))
        cached = res.chunks_total - res.chunks_computed
        lines.append(f"**Time** {res.seconds:.2f} s ({res.chunks_total} chunks"
                     + (f", {cached} from the cache)" if cached else ")"))
    lines += preview_lines(scene)
    lines += sliding_lines(scene)
    lines += star_cell_lines(scene)
    _, _, notes = scene.marker_position(plane)
    if notes:
        lines.append("**Marker** " + "; ".join(notes))
    return "\n\n".join(lines)


def legend_text(scene: Any) -> str:
    """The map's colour legend, for the verdict it is coloured by (and the preview's line while one is drawn)."""
    text = sm.SLIDING_LEGEND if scene.colours_sliding() else COLOUR_LEGEND
    if scene._shown_preview() is not None:
        text += (f". Drawn now: a preview of the held values; its dashed grey line is the Rayleigh branch's zero "
                 f"contour on the preview's grid ({PREVIEW_CONTOUR}), in place of the black and purple lines")
    return f"Click the map to move the sliders there. {text}; star: current parameters."


def preview_lines(scene: Any) -> list[str]:
    """The readout's lines on a held slider and the preview drawn (:func:`~.held.shown_preview`)."""
    pv = scene._shown_preview()
    lines = []
    held = scene.params.dragging and key_for(scene.plane, scene.resolution, scene.params.model_args()) != scene.map_key
    if held and pv is None:
        lines.append("**Slider held** the map is of the values above; a preview of the held values is drawn once "
                     "computed, the full map is computed at the release")
    if pv is not None:
        others = ", ".join(f"{SpectrumParams.symbol(k)} = {'∞' if np.isinf(v) else fmt(v)}" for k, v in pv.key[2])
        if held:
            lines.append(f"**Slider held** {preview_label(pv.points)}. The map drawn is a preview of {others}"
                         + ("" if pv.key == scene.preview_key else
                            " (the preview of the values now held is being computed)"))
        else:
            lines.append(f"**Released** the full map of {others} is being computed; until it is shown, the map "
                         f"drawn is their preview ({pv.points} × {pv.points} points)")
        lines.append(f"**Neutral curve (preview)** dashed grey: the zero contour of the Rayleigh branch's growth "
                     f"on the preview's {PREVIEW_POINTS} × {PREVIEW_POINTS} grid ({PREVIEW_CONTOUR}); the other "
                     "numbers are of the full map of the values on the first line")
    if scene.preview_status.startswith("error") and scene._previewing():
        lines.append(f"**Preview failed** {scene.preview_status[len('error: '):]}")
    return lines


def neutral_line(res: MapResult) -> str:
    """How the black curve was drawn: certified thresholds at every column, or the grid's contour."""
    c = res.crossings
    if c is None:
        return ("**Neutral curve** the contour of the grid's values (the model certifies thresholds in γ and η, "
                "not along Δ or ξ)")
    certified, refused = sb.crossing_counts(c)
    return (f"**Neutral curve** exact in γ: {certified} certified threshold(s) γ_c (a neutral mode each, "
            f"model.critical_gammas) at {c['x'].size} x values"
            + (f"; {refused} sign change(s) that are not thresholds (×, reason on hover)" if refused else ""))


def refined_line(r: mr.RefinedMap) -> str:
    """How the map was refined: the points of each level, the finest grid, what an unrefined cell shows."""
    per_level = ", ".join(f"{r.evaluated(level)} at level {level}" for level in range(1, r.levels + 1))
    return (f"**Refined** where the Rayleigh verdict changes between neighbouring cells (stable against unstable): "
            f"{per_level} (finest {r.size} × {r.size} cells). Each cell shows the value computed at its centre or, "
            "not refined, at the centre of the coarser cell that holds it (hover: computed at); no value is "
            "interpolated")


def sliding_lines(scene: Any) -> list[str]:
    """The readout's lines on the sliding verdict (every branch) of the current map."""
    if not scene.colours_sliding():
        return ["**Sliding (every branch)** not computed: colour by the sliding verdict to compute it (the "
                "numbers above are the Rayleigh branch's alone)"]
    sl = scene.sliding
    lines = []
    if scene.sliding_status.startswith("error"):
        lines.append(f"**Sliding failed** {scene.sliding_status[len('error: '):]}")
    if sl is None or sl.key != scene.sliding_key:
        lines.append("**Sliding (every branch)** computing…" if scene._current() else
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
    res = scene.result
    if res is not None and res.key == scene.map_key:
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
    lines += boundary_lines(scene)
    return lines


def boundary_lines(scene: Any) -> list[str]:
    """The readout's lines on the exact boundary of sliding over every branch (purple)."""
    if not scene.boundary_applies():
        return ["**Sliding boundary** not drawn on this plane: the model certifies thresholds of sliding in γ "
                "(model.critical_gammas, branches=\"all\"), and this plane has no γ axis"]
    if scene.boundary_status.startswith("error"):
        return [f"**Sliding boundary failed** {scene.boundary_status[len('error: '):]}"]
    b = scene.boundary
    if b is None or b["key"] != scene.sliding_key:
        if not scene._sliding_current():
            return ["**Sliding boundary** (purple) computed after the sliding map"]
        return [f"**Sliding boundary** (purple) {scene.boundary_status} (a few seconds a column at finite η)"]
    text = sb.summary(b, "purple line")
    if not b["done"].all():
        text += f"; {scene.boundary_status}"
    else:
        text += f"; {b['seconds']:.1f} s" + (f" ({b['cached']} of {b['x'].size} columns from the cache)"
                                              if b["cached"] else "")
    return [text]


def star_cell(scene: Any) -> tuple[int, int] | None:
    """(row, column) of the map's cell under the star (None: the star lies off the plane's range)."""
    x, y, notes = scene.marker_position()
    if notes:
        return None
    ax, ay = PLANES[scene.plane]
    n = scene.map_key[1]
    ix = int(np.clip(np.searchsorted(ax.edges(n), x) - 1, 0, n - 1))
    iy = int(np.clip(np.searchsorted(ay.edges(n), y) - 1, 0, n - 1))
    return iy, ix


def star_cell_lines(scene: Any) -> list[str]:
    """The readout of the map's cell under the star: both verdicts there, the fastest mode's family, kH and z."""
    cell = star_cell(scene)
    res = scene.result
    if cell is None or res is None or res.key != scene.map_key:
        return []
    iy, ix = cell
    ax, ay = PLANES[scene.plane]
    at_x, at_y, g, kh = res.x[ix], res.y[iy], float(res.growth[iy, ix]), float(res.kH_at_max[iy, ix])
    if res.refined is not None:  # the finest cell under the star, and the point its value was computed at
        r = res.refined
        x, y, _ = scene.marker_position()
        fy = int(np.clip(np.searchsorted(r.y_edges, y) - 1, 0, r.size - 1))
        fx = int(np.clip(np.searchsorted(r.x_edges, x) - 1, 0, r.size - 1))
        at_x, at_y = r.owner_x[fy, fx], r.owner_y[fy, fx]
        g, kh = float(r.growth[fy, fx]), float(r.kH_at_max[fy, fx])
    where = f"{ax.label} = {fmt(at_x)}, {ay.label} = {fmt(at_y)}"
    ray = ("not computable" if not np.isfinite(g) else
           f"unstable, max Im[c/c_s] = {fmt(g)} at kH = {fmt(kh)}" if g > MARGINAL
           else f"stable, max Im[c/c_s] = {fmt(g)}")
    lines = [f"**The star's cell** ({where}): Rayleigh branch {ray}"]
    sl = scene.sliding
    shown = scene.colours_sliding() and sl is not None and sl.key == scene.sliding_key
    if shown and sl.fields["verdict"][iy, ix] >= 0:
        f = {k: v[iy, ix] for k, v in sl.fields.items()}
        text = sm.cell_text(verdict=f["verdict"], reason=f["reason"], family=f["family"], growth=f["growth"],
                            kH=f["kH_at_max"], re_z=f["re_z"], lower_bound=bool(f["lower_bound"]), floor=sl.floor)
        at = (f" ({ax.label} = {fmt(res.x[ix])}, {ay.label} = {fmt(res.y[iy])})" if res.refined is not None
              else "")
        lines.append(f"**The star's cell, sliding (every branch)**{at} {text}")
    return lines
