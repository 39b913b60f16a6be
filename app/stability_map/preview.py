"""The Stability map's preview while a slider is held: a coarse map of the held inputs (the Rayleigh branch's growth
from the map's cached chunks and, coloured by the sliding verdict, that verdict published chunk by chunk), its words,
and the job that computes it once the previous preview job has stopped."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .. import jobs
from .. import sliding_map as sm
from .compute import CHUNKS, cached_chunk
from .grids import PLANES, chunk_rows, plane_axes

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



@dataclass(frozen=True, eq=False)
class MapPreview:
    """A coarse map of the held inputs while a slider is held: the Rayleigh branch's growth at :data:`PREVIEW_POINTS`
    per axis and, for a map coloured by the sliding verdict, that verdict at :data:`PREVIEW_SLIDING_POINTS` per axis
    (a partial one while it is computed)."""

    #: (verdict, map key of the held inputs (:func:`~.grids.key_for`), growth floor of the sliding verdict)
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


def preview_totals(verdict: str) -> dict[str, int]:
    """The phases of a preview job: the Rayleigh branch's chunks, then the sliding verdict's points."""
    totals = {"chunks": len(chunk_rows(PREVIEW_POINTS))}
    if verdict == sm.SLIDING:
        totals["points"] = PREVIEW_SLIDING_POINTS**2
    return totals


def compute_preview(job_key: tuple, job: jobs.Job) -> MapPreview:
    """The preview of `job_key` (:attr:`MapPreview.job_key`): the Rayleigh branch's growth at :data:`PREVIEW_POINTS` per
    axis from the map's cached chunks (:func:`~.compute.cached_chunk`; no certified crossings), then, coloured by the
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
