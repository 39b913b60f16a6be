"""The Stability map's cached model calls and the computed map: the chunks of the Rayleigh branch's max growth (cached
for every session), a whole map computed chunk by chunk as a job, its refinement at the neutral curve and its
certified thresholds γ_c."""

from __future__ import annotations

import collections
import threading
import time
from dataclasses import dataclass
from functools import partial

import numpy as np
import panel as pn

from asymslide import model

from .. import jobs
from .. import map_refine as mr
from .. import sliding_boundary as sb
from .grids import KH, PLANES, chunk_rows, plane_axes


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
    """The map of `key` (:func:`~.grids.key_for`), chunk by chunk, each from the cache of chunks when it is there: the
    work of a map job, on its thread (it stops at :meth:`~app.jobs.Job.check` once the job is cancelled)."""
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
