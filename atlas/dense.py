"""The dense sweep: every chunk of every kind of task of a plan, into a writer (:mod:`asymslide.atlas.writers`)."""

from __future__ import annotations

import os
from collections.abc import Sequence

import numpy as np

from .executor import Progress, execute
from .plan import Plan
from .tasks import Task, run_task, tasks
from .writers import Writer, open_writer


def run_dense(plan: Plan, *, store: str | os.PathLike | None = None, client=None, workers: int | None = None,
              progress: Progress | None = None, command: str | None = None):
    """The dense sweep of a validated plan (:func:`asymslide.atlas.sweep.sweep` without the parsing): every chunk of
    every kind. Returns the dataset (in memory without a store, else opened lazily from it)."""
    writer = open_writer(plan, store, command)
    run_kinds(plan, tuple(tasks(plan)), writer, client=client, workers=workers, progress=progress)
    return writer.result()


def run_kinds(plan: Plan, kinds: Sequence[str], writer: Writer, *, client=None, workers: int | None = None,
              progress: Progress | None = None) -> None:
    """Run the chunks of the task kinds `kinds` that `writer` does not hold yet, each written as it finishes;
    progress(kind, points) for the chunks held already, then as chunks finish."""
    groups = tasks(plan, kinds)
    todo = [t for group in groups.values() for t in group if not writer.done(t)]
    if progress is not None:
        for kind, group in groups.items():
            finished = sum(t.points for t in group if writer.done(t))
            if finished:
                progress(kind, finished)

    def write(task: Task, result: dict[str, np.ndarray]) -> None:
        writer.write(task, result)
        if progress is not None:
            progress(task.kind, task.points)

    execute(todo, write, run_task, client, workers)
