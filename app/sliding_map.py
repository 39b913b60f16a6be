"""The Stability map's sliding verdict over every branch (docs/physics.md §14): computed coarse to fine, as a job.

A map of the sliding verdict costs the model's per-point price (:func:`model.sliding_analysis`: ~10 ms at η = ∞,
0.01-0.5 s at finite η), 20-400 times the Rayleigh branch's. So it is computed in passes over nested subgrids of
the map's grid: every :data:`STRIDES`-th point first (a 5 × 5 preview of a 40 × 40 map), then the points that halve
the spacing, down to every point. No point is computed twice. Until the last pass, a cell not yet computed shows
the value of the computed point at the lower-left corner of its block (nearest below, :func:`preview_index`), and
the hover says so. Each chunk of :data:`CHUNK_POINTS` points is a pure cached call (the map's
:class:`~app.stability_map.compute.ChunkCache`, shared by the sessions), so a map seen before comes back at once.

The app computes no physics: every number comes from :func:`model.sliding_analysis`.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from bokeh.palettes import Reds256

from asymslide import model

from . import jobs
from .common import FAMILY_NAMES
from .plotting import fmt

#: the strides of the passes, coarsest first (each halves the last; the final pass computes every point)
STRIDES = (8, 4, 2, 1)

#: points per chunk: how often a cancelled job can stop (~0.1 s at η = ∞, up to ~4 s at η ~ 1 and a low floor)
CHUNK_POINTS = 8

#: the growth floors offered (Im z). "auto": the model's default (1e-6) where η = ∞ over the whole map, FINITE_ETA_FLOOR
#: where the map has finite η: there the window at a low floor is often too wide to search (verdict undetermined)
#: and slow (0.1-2.5 s a point at 1e-6: docs/physics.md §14.6), while 1e-3 certifies most points at ~0.1 s
AUTO = "auto"
FLOORS = (AUTO, "1e-6", "1e-4", "1e-3", "1e-2")
FINITE_ETA_FLOOR = 1e-3


def floor_value(choice: str, finite_eta: bool) -> float:
    """The growth floor of a map: the choice, or for "auto" the model's default at η = ∞ and
    :data:`FINITE_ETA_FLOOR` where the map has finite η."""
    if choice == AUTO:
        return FINITE_ETA_FLOOR if finite_eta else float(model.DEFAULT_FLOOR)
    return float(choice)

#: the verdicts the map can be coloured by (the URL words after the arrow)
#: the verdict classes (model.Verdict), as the sliding map compares its int8 fields with them
STABLE, UNSTABLE, UNDETERMINED = model.Verdict
SLIDING, RAYLEIGH = "sliding (every branch)", "Rayleigh branch"
VERDICT_WORDS = {SLIDING: "sliding", RAYLEIGH: "rayleigh"}

#: the sliding verdict classes' colours: stable, unstable (drawn under the growth: shown where the maximum is not
#: certified), undetermined; model.VERDICTS
VERDICT_COLOURS = ("#4393c3", "#d6604d", "#636363")
#: the growth of an unstable point, over the verdict colours: ColorBrewer Reds from a visible pink (never white: a
#: slow growth must not read as neutral) to dark red, on a log scale from the floor (growth spans 1e-6 to ~1)
GROWTH_ALL_CMAP = list(reversed(Reds256))[64:]
GROWTH_ALL_LABEL = "max Im[c/c_s], every branch"

#: the legend of a map coloured by the sliding verdict
SLIDING_LEGEND = ("Red: sliding unstable (some branch has a root with Im z ≥ the floor; shade: its max growth, flat "
                  "red where that maximum is not certified), blue: sliding stable (no root of any branch at or above "
                  "the floor), dark grey: undetermined (see the readout); black line: the Rayleigh branch's neutral "
                  "curve (the paper's); purple line: the threshold of sliding over every branch (its neutral modes, "
                  "exact in γ; on the planes with γ); switch \"Colour by\" to the Rayleigh branch for the paper's maps")

#: the per-point fields of a sliding map: name -> (dtype, fill where not computed)
FIELDS = {"growth": (float, np.nan), "kH_at_max": (float, np.nan), "re_z": (float, np.nan),
          "family": (np.int8, -1), "verdict": (np.int8, -1), "reason": (np.int8, -1), "lower_bound": (bool, False)}


def passes(n: int, strides: tuple[int, ...] = STRIDES) -> list[np.ndarray]:
    """The flat indices (row-major, n × n) computed by each pass of `strides` (the last 1), coarsest first: the
    points on the stride's subgrid that no coarser pass computed. Together they are every point once."""
    done = np.zeros((n, n), bool)
    out = []
    for s in strides:
        grid = np.zeros((n, n), bool)
        grid[::s, ::s] = True
        new = grid & ~done
        out.append(np.flatnonzero(new))
        done |= new
    return out


def chunks(n: int, strides: tuple[int, ...] = STRIDES, size: int = CHUNK_POINTS) -> list[tuple[int, np.ndarray]]:
    """(pass, flat indices) of every chunk (up to `size` points) of an n × n map, in the order they are computed."""
    return [(k, idx[a:a + size]) for k, idx in enumerate(passes(n, strides)) for a in range(0, idx.size, size)]


def preview_index(n: int, stride: int) -> np.ndarray:
    """The index along an axis of the point whose value a cell shows once the pass of `stride` is done."""
    return (np.arange(n) // stride) * stride


def compute_chunk(x: np.ndarray, y: np.ndarray, names: tuple[str, str], fixed: tuple[tuple[str, float], ...],
                  floor: float, idx: np.ndarray) -> dict[str, np.ndarray]:
    """The sliding verdict at the points `idx` (flat, row-major: y rows, x columns) of the map x × y, the plane's
    parameters `names`, the others `fixed` (a pure function: the chunks are cached by their inputs)."""
    p: dict[str, object] = dict(fixed)
    iy, ix = np.divmod(idx, x.size)
    p[names[0]], p[names[1]] = x[ix], y[iy]
    r = model.sliding_analysis(**p, floor=floor)
    return {"growth": np.asarray(r.growth, float), "kH_at_max": np.asarray(r.kH_at_max, float),
            "re_z": np.asarray(r.z_at_max, complex).real, "family": np.asarray(r.family, np.int8),
            "verdict": np.asarray(r.verdict, np.int8), "reason": np.asarray(r.verdict_reason, np.int8),
            "lower_bound": np.asarray(r.lower_bound, bool)}


@dataclass(frozen=True, eq=False)
class SlidingMap:
    """The sliding verdict over a map (possibly a preview): per-point fields (n × n; :data:`FIELDS`, filled where
    not computed), the finest pass done (`stride`), and the kH range and floor of the search."""

    key: tuple
    x: np.ndarray
    y: np.ndarray
    fields: dict[str, np.ndarray]
    stride: int  # every stride-th point is computed (1: all)
    computed: int  # points computed (by this job or from the cache)
    seconds: float
    floor: float
    kH_range: tuple[float, float]

    @property
    def complete(self) -> bool:
        return self.stride == 1

    def shown(self) -> dict[str, np.ndarray]:
        """The fields as drawn: a computed cell its own value, every other cell the value of its preview point (the
        lower-left point of its block of `stride`; not computed yet in a pass published chunk by chunk)."""
        n = self.x.size
        iy, ix = preview_index(self.y.size, self.stride), preview_index(n, self.stride)
        exact = self.exact()
        return {k: np.where(exact, v, v[np.ix_(iy, ix)]) for k, v in self.fields.items()}

    def exact(self) -> np.ndarray:
        """Where a cell shows its own value (n × n bool)."""
        return self.fields["verdict"] >= 0


def compute_sliding_map(key: tuple, x: np.ndarray, y: np.ndarray, names: tuple[str, str],
                        cache_get: Callable[[tuple], dict | None], cache_put: Callable[[tuple, dict], None],
                        job: jobs.Job, *, strides: tuple[int, ...] = STRIDES, chunk_points: int = CHUNK_POINTS,
                        publish: Callable[[SlidingMap], None] | None = None,
                        every_chunk: bool = False) -> SlidingMap:
    """The sliding map of `key` = (plane, n, fixed, floor), pass by pass of `strides` (each pass's end published as
    a :class:`SlidingMap` preview: to `publish`, by default as the job's partial result), chunk by chunk of
    `chunk_points` from the cache when there; the work of a job. `every_chunk`: also publish after every chunk within
    a pass (a small map that should show something after its first chunk: the Stability map's preview while a
    slider is held), its cells not computed yet shown by the last complete pass (none yet in the first pass)."""
    plane, n, fixed, floor = key
    t0 = time.perf_counter()
    fields = {k: np.full((n, n), fill, dtype) for k, (dtype, fill) in FIELDS.items()}
    plan = chunks(n, strides, chunk_points)
    computed = 0
    kH = model.SLIDING_KH
    show = job.publish if publish is None else publish

    def result(stride: int) -> SlidingMap:
        return SlidingMap(key, x, y, {k: v.copy() for k, v in fields.items()}, stride, computed,
                          time.perf_counter() - t0, floor, (float(kH[0]), float(kH[-1])))

    for i, (k, idx) in enumerate(plan):
        job.check()
        ckey = ("sliding", plane, n, fixed, floor, tuple(strides), int(idx[0]), idx.size)
        part = cache_get(ckey)
        if part is None:
            part = compute_chunk(x, y, names, fixed, floor, idx)
            cache_put(ckey, part)
        for name, values in part.items():
            fields[name].flat[idx] = values
        computed += idx.size
        last_of_pass = i + 1 == len(plan) or plan[i + 1][0] != k
        if last_of_pass and strides[k] > 1:
            show(result(strides[k]))
        elif every_chunk and not last_of_pass:
            show(result(strides[max(k - 1, 0)]))
        job.advance("points", idx.size)
    return result(1)


def hover_text(verdict: np.ndarray, reason: np.ndarray, family: np.ndarray, floor: float) -> np.ndarray:
    """A cell's verdict in words (for the hover): 'unstable: intersonic guided mode', 'stable above the floor'...."""
    out = np.full(verdict.shape, "not computed", dtype=object)
    out[verdict == STABLE] = f"stable: no root of any branch with Im z ≥ {floor:g}"
    out[verdict == UNDETERMINED] = "undetermined"
    for code, name in FAMILY_NAMES.items():
        out[(verdict == UNSTABLE) & (family == code)] = f"unstable: {name}"
    out[(verdict == UNSTABLE) & (family < 0)] = "unstable (maximum not certified)"
    undetermined = verdict == UNDETERMINED
    out[undetermined & (reason == model.SlidingReason.WIDE)] = "undetermined: the window at the floor is too wide"
    out[undetermined & (reason == model.SlidingReason.FAILED)] = "undetermined: the contour count failed"
    return out


def family_counts(verdict: np.ndarray, family: np.ndarray) -> str:
    """The unstable points by the family of their fastest mode: "intersonic guided mode 15, ..." ("" if none)."""
    unstable = np.asarray(verdict) == UNSTABLE
    fam = np.asarray(family)
    return ", ".join(f"{name} {int((unstable & (fam == code)).sum())}" for code, name in FAMILY_NAMES.items()
                     if (unstable & (fam == code)).any())


def cell_text(*, verdict: int, reason: int, family: int, growth: float, kH: float, re_z: float, lower_bound: bool,
              floor: float) -> str:
    """One point's sliding verdict in words, with the fastest mode's growth, kH and z where it is certified (the
    readouts of the Stability map's star cell and of a clicked Atlas cell)."""
    text = hover_text(np.array([int(verdict)]), np.array([int(reason)]), np.array([int(family)]), floor)[0]
    if int(verdict) == UNSTABLE and np.isfinite(growth):
        text += (f", max Im[c/c_s] {'≥' if lower_bound else '='} {fmt(float(growth))} at kH = {fmt(float(kH))}, "
                 f"z = {fmt(float(re_z), 6)} + {fmt(float(growth))}i")
    return text
