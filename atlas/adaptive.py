"""The adaptive sweep: the levels of the refinement (:mod:`asymslide.atlas.refinement`), each a batch of tasks of
the points it evaluates, grouped by Zarr chunk, run by the same executor as the dense sweep and kept in a journal
(:class:`asymslide.atlas.writers.JournalWriter`) until the grid variables are written at the end; then the
thresholds and the count, dense.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable

import numpy as np

from .dense import run_kinds
from .executor import execute
from .plan import PARAMETERS, Plan
from .refinement import (
    SLIDING,
    AdaptiveSpec,
    fill_classes,
    follow_targets,
    level_counts,
    refine_targets,
    refinement_classes,
    summary,
)
from .tasks import PointTask, run_points, task_points, tasks
from .writers import JournalWriter, MemoryJournal, filled_names, open_writer, state_names

#: an adaptive sweep's journal: in the store, or the dataset in memory
Journal = JournalWriter | MemoryJournal


#: the variables the refinement reads (the rest of the growth variables is only written)
_STATE = ("growth", "verdict", "computed")


class _Grid:
    """The grid's geometry: axis values, fixed values, Zarr chunks (for grouping points and writing chunks)."""

    def __init__(self, plan: Plan) -> None:
        self.plan = plan
        self.shape = plan.shape
        self.chunks = tuple(plan.chunks[n] for n in plan.names)
        self.blocks = tuple(-(-n // c) for n, c in zip(self.shape, self.chunks, strict=True))
        self.values = [np.asarray(plan.axes[n]) for n in plan.names]
        self.parameters = PARAMETERS

    def params(self, flat: np.ndarray) -> np.ndarray:
        """(6, n) parameter rows of the grid points `flat` (the same floats as the dense sweep's meshgrid)."""
        index = np.unravel_index(flat, self.shape)
        columns = {n: v[i] for n, v, i in zip(self.plan.names, self.values, index, strict=True)}
        rows = [columns[p] if p in columns else np.full(flat.size, self.plan.fixed[p]) for p in self.parameters]
        return np.ascontiguousarray(np.stack(rows), dtype=float)

    def chunk_of(self, flat: np.ndarray) -> np.ndarray:
        index = np.unravel_index(flat, self.shape)
        return np.ravel_multi_index(tuple(i // c for i, c in zip(index, self.chunks, strict=True)), self.blocks)

    def region(self, chunk: int) -> tuple[slice, ...]:
        start = np.unravel_index(chunk, self.blocks)
        return tuple(slice(s * c, min((s + 1) * c, n)) for s, c, n in zip(start, self.chunks, self.shape, strict=True))

    def tasks(self, level: int, flat: np.ndarray) -> list[PointTask]:
        """The level's points `flat` as tasks: grouped by Zarr chunk, at most :func:`task_points` each, the largest
        first (a batch ends when its last task does)."""
        if flat.size == 0:
            return []
        chunk = self.chunk_of(flat)
        order = np.argsort(chunk, kind="stable")
        flat, chunk = flat[order], chunk[order]
        params = self.params(flat)
        starts = np.r_[0, np.flatnonzero(np.diff(chunk)) + 1]
        stops = np.r_[starts[1:], flat.size]
        size = task_points(self.plan)
        parts = [(int(chunk[a]), i, min(i + size, z)) for a, z in zip(starts, stops, strict=True)
                 for i in range(a, z, size)]
        parts.sort(key=lambda p: p[1] - p[2])
        return [PointTask(f"level{level}", k, level, cid, flat[a:z], params[:, a:z], self.plan.kH, self.plan.rtol,
                          self.plan.sliding) for k, (cid, a, z) in enumerate(parts)]


def _ignore(kind: str, points: int) -> None:
    """A progress callback that does nothing."""


class _Rounds:
    """The rounds of an adaptive sweep's levels: each one Dask batch of the points of a target mask not evaluated
    yet, kept in `memory` (the grid variables, updated as tasks finish) and in the store's journal."""

    def __init__(self, grid: _Grid, memory: dict[str, np.ndarray], writer: Journal, client, workers: int | None,
                 progress: Callable[[str, int], None], start: Callable[[str, int], None]) -> None:
        self.grid, self.memory, self.writer = grid, memory, writer
        self.client, self.workers, self.progress, self.start = client, workers, progress, start
        self.flat = {name: a.reshape(-1) for name, a in memory.items()}

    def levels(self, spec: AdaptiveSpec) -> None:
        """Levels 0 .. L: each its first round (:func:`refine_targets`), then its follow rounds until none is left
        (on :func:`refinement_classes`: the Rayleigh branch's verdict, or both verdicts)."""
        m = self.memory

        def classes() -> np.ndarray:
            return refinement_classes(m["verdict"], m["verdict_all"] if spec.verdict == SLIDING else None)

        for level in range(spec.levels + 1):
            target = refine_targets(level, spec, m["verdict"], m["growth"], m["computed"], classes())
            while target.any():
                self.execute(level, target)
                target = (follow_targets(level, spec, classes(), m["computed"]) if spec.follow
                          else np.zeros_like(target))

    def execute(self, level: int, target: np.ndarray) -> None:
        """One round of a level: the points of `target` not evaluated yet, as one Dask batch."""
        computed = self.memory["computed"]
        kind, done = f"level{level}", computed == level
        if np.any(target & (computed > level)):  # cannot happen with the same plan (which is checked)
            raise RuntimeError(f"the store holds points of a later level than {level} where level {level} evaluates")
        self.start(kind, int(target.sum()))
        if done.any():
            self.progress(kind, int((target & done).sum()))
        todo = self.grid.tasks(level, np.flatnonzero(target & ~done))
        self.writer.begin(level, todo)
        execute(todo, self.keep, run_points, self.client, self.workers)

    def keep(self, task: PointTask, result: dict[str, np.ndarray]) -> None:
        """A finished task: into the journal and the grid variables."""
        self.writer.write(task, result)
        for name, values in result.items():
            self.flat[name][task.flat] = values
        self.flat["computed"][task.flat] = task.level
        self.progress(task.kind, task.points)


def run(plan: Plan, *, store: str | os.PathLike | None = None, client=None, workers: int | None = None,
        progress: Callable[[str, int], None] | None = None, start: Callable[[str, int], None] | None = None,
        command: str | None = None):
    """The adaptive sweep of a validated plan (``plan.adaptive`` set): levels 0 .. L of the refinement, each one
    Dask batch of tasks grouped by Zarr chunk, then the filled verdict, the fractions and (dense, as
    :func:`asymslide.atlas.dense.run_dense`) γ_c and the count if the plan asks for them. store/client/workers/command
    as :func:`asymslide.atlas.sweep.sweep`; progress(kind, points) as points finish and start(kind, points) as a
    level's batch starts (kind ``level L``; called again, with the points it adds, as each of the level's follow
    rounds starts). Returns the dataset (in memory without a store, else opened from it)."""
    spec = plan.adaptive
    if spec is None or spec.levels is None:
        raise ValueError("run() needs a plan made with adaptive=... (asymslide.atlas.plan.make_plan)")
    names = state_names(plan)
    writer = open_writer(plan, store, command)
    journal = writer.journal()
    memory = journal.load(names, plan.shape)
    progress = progress or _ignore
    _Rounds(_Grid(plan), memory, journal, client, workers, progress, start or _ignore).levels(spec)
    filled = {name: fill_classes(memory[source], memory["computed"], spec.levels)
              for name, source in filled_names(plan).items()}
    journal.finish(memory, names, filled, json.dumps(summary(plan.shape, spec, level_counts(memory["computed"],
                                                                                             spec.levels))))
    kinds = tuple(k for k in ("gamma_c", "gamma_c_all", "count") if k in tasks(plan))
    run_kinds(plan, kinds, writer, client=client, workers=workers, progress=progress)
    return writer.result()
