"""The Stability map's boundary of sliding over every branch, exactly: the certified thresholds γ_c at every column.

On a plane whose y axis is γ (η-γ, f-γ, β-γ), the boundary between stable and unstable sliding (every branch, the
map's growth floor) is drawn through the model's certified crossings in γ of the max growth over every branch
(:func:`model.critical_gammas` with ``branches="all"``; docs/physics.md §14.10), at each x value of the map's grid,
every crossing in both directions, as the Rayleigh branch's neutral curve is
(app.stability_map.compute.compute_crossings). A column costs ~0.5 s at η = ∞ and a few seconds at finite η: the
curve is computed after the sliding map, as a job, :data:`COLUMNS_PER_CHUNK` columns at a time, each chunk a pure
cached call (the map's chunk cache; computed in the worker process of :mod:`app.jobs` when served: the search is
mostly Python and would hold the server's interpreter), and drawn as it grows (the job publishes the columns done so
far).

The app computes no physics: every number comes from :func:`model.critical_gammas`.
"""

from __future__ import annotations

import time
from collections.abc import Callable

import numpy as np

from asymslide import model

from . import jobs, sliding_work

#: columns of the map per call of the model (how often a cancelled job can stop: ~1 s at η = ∞)
COLUMNS_PER_CHUNK = 2
#: the crossings a column of a map may have (model.critical_gammas' max_crossings; the Rayleigh branch's too)
MAX_CROSSINGS = 4
#: the per-crossing fields kept (each n_columns × MAX_CROSSINGS)
FIELDS = ("value", "location", "direction", "reason", "kH", "z")


def empty(x: np.ndarray) -> dict[str, np.ndarray]:
    """The boundary's fields before any column is computed (NaN values, reason -1: nothing, as padding)."""
    n = x.size
    return {"x": x, "value": np.full((n, MAX_CROSSINGS), np.nan), "location": np.full((n, MAX_CROSSINGS), np.nan),
            "direction": np.zeros((n, MAX_CROSSINGS), np.int8), "reason": np.full((n, MAX_CROSSINGS), -1, np.int8),
            "kH": np.full((n, MAX_CROSSINGS), np.nan), "z": np.full((n, MAX_CROSSINGS), np.nan),
            "count": np.zeros(n, int), "done": np.zeros(n, bool), "seconds": 0.0, "cached": 0}


def compute_boundary(key: tuple, x: np.ndarray, x_name: str, gamma_range: tuple[float, float],
                     cache_get: Callable[[tuple], dict | None], cache_put: Callable[[tuple, dict], None],
                     job: jobs.Job, *, in_process: bool = False) -> dict[str, np.ndarray]:
    """The sliding boundary of the map `key` = (plane, n, fixed, floor) at its x values `x`, chunk by chunk (each
    from the cache when there), publishing the columns done so far after each chunk: the work of a job. Returns the
    fields of :func:`empty`, every column done."""
    plane, n, fixed, floor = key
    t0 = time.perf_counter()
    out = empty(x)
    for a in range(0, x.size, COLUMNS_PER_CHUNK):
        job.check()
        cols = tuple(float(v) for v in x[a:a + COLUMNS_PER_CHUNK])
        ckey = ("sliding boundary", plane, n, fixed, floor, gamma_range, cols, MAX_CROSSINGS)
        part = cache_get(ckey)
        if part is not None:
            out["cached"] += len(cols)
        else:
            part = job.call(sliding_work.sliding_gamma_crossings, x_name, cols, fixed, floor, gamma_range,
                            MAX_CROSSINGS, in_process=in_process, pool=jobs.BACKGROUND)
            cache_put(ckey, part)
        b = a + len(cols)
        for name in (*FIELDS, "count"):
            out[name][a:b] = part[name]
        out["done"][a:b] = True
        out["seconds"] = time.perf_counter() - t0
        job.advance("columns", len(cols))
        if b < x.size:
            job.publish({k: (v.copy() if isinstance(v, np.ndarray) else v) for k, v in out.items()})
    return out


def crossing_counts(c: dict) -> tuple[int, int]:
    """(certified thresholds, sign changes that are not thresholds) among the crossings `c` of a map's columns (the
    Rayleigh branch's, app.stability_map.compute.compute_crossings, or this boundary's)."""
    certified = int((np.isin(c["reason"], model.CERTIFIED_CROSSINGS) & np.isfinite(c["value"])).sum())
    refused = int(((c["reason"] >= 0) & ~np.isin(c["reason"], model.CERTIFIED_CROSSINGS)).sum())
    return certified, refused


def summary(b: dict, drawn_as: str = "") -> str:
    """The boundary in words for the readout (`drawn_as`: how the map draws it, e.g. "purple line"): certified
    thresholds, sign changes that are not thresholds, columns done."""
    done = int(b["done"].sum())
    certified, refused = crossing_counts(b)
    how = f", {drawn_as}" if drawn_as else ""
    text = (f"**Sliding boundary** (every branch{how}) exact in γ: {certified} certified threshold(s) at {done} of "
            f"{b['x'].size} x values (model.critical_gammas, branches=\"all\")")
    if refused:
        text += f"; {refused} sign change(s) that are not thresholds"
    text += (" — the neutral threshold (max Im z = 0): between it and the red cells the growth is below the floor "
             "(drawn blue)")
    return text
