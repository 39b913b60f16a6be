"""The Stability map's background jobs: each started where the session may be modified (unless its result is shown
or being computed), its progress shown in the bar and its label, and its partial and final result (or failure)
handed to the scene's state (a :class:`~asymslide.app.stability_map.scene.StabilityMapScene`), on the session's
event loop. While a slider is held at inputs off the map's, the bar follows the preview's job."""

from __future__ import annotations

from functools import partial
from typing import Any

from .. import jobs
from .. import sliding_boundary as sb
from .. import sliding_map as sm
from ..plotting import fmt
from ..workarounds import frozen_document
from . import compute, fig4c, preview
from .compute import CHUNKS
from .fig4c import BETA_EXACT
from .grids import PLANES, chunk_rows, grid_words, plane_axes
from .preview import (
    PREVIEW_HEADING,
    PREVIEW_POINTS,
    PREVIEW_SLIDING_POINTS,
    after_previous,
    preview_label,
    preview_totals,
)


def name_progress(scene: Any) -> None:
    """The progress bar and label of the colouring shown: the map's name when it is complete, or the progress of
    its job being computed, or nothing."""
    plane, n, _, levels = scene.map_key
    scene.progress.visible = False
    if scene.colours_sliding():
        done = scene._sliding_current()
        scene.progress_label.object = f"The sliding verdict over the {plane} map ({n} × {n} points)" if done else ""
    elif scene._current():
        scene.progress_label.object = f"The {plane} map ({grid_words(n, levels)})"
    else:
        scene.progress_label.object = ""
    for follower, show in ((scene.computation, show_map_job), (scene.sliding_computation, show_sliding_job)):
        job = follower.job
        state = None if job is None else job.state()
        if state is not None and not state.finished:
            show(scene, job, state)


def settle_progress(scene: Any) -> None:
    """The progress bar and label of the map once they no longer follow a preview: the map's name, or the
    progress of its job being computed (which the preview's label hid)."""
    if scene._previewing() or not scene.progress_label.object.startswith(PREVIEW_HEADING):
        return
    name_progress(scene)


def show_map_job(scene: Any, job: jobs.Job, state: jobs.JobState) -> None:
    """Show a map job's progress and, at its end, the map or the failure (on the session's event loop)."""
    plane, n, _, levels = job.key
    total, done = state.totals.get("chunks", 0), state.done.get("chunks", 0)
    if not scene._previewing():  # a held slider's preview shows its own progress
        if scene.progress.max != total:
            scene.progress.value = 0
            scene.progress.max = total
        scene.progress.value = done
        scene.progress.visible = done < total  # a finished bar is not left on the page; the label says it
        unit = "steps (chunks, then levels of refinement)" if levels else "chunks"
        scene.progress_label.object = (f"Computing the {plane} map ({grid_words(n, levels)}): {done} of {total} "
                                       f"{unit}" if done < total else f"The {plane} map ({grid_words(n, levels)})")
    if state.status == jobs.RUNNING:
        scene.status = "computing"
    elif state.status == jobs.FAILED:
        scene.status = f"error: {state.error}"
    elif state.status == jobs.DONE:
        with frozen_document():
            scene.param.update(result=state.result, status="done")
        scene._preview_drawn_over()
        ax, ay = PLANES[plane]
        scene.map_download.filename = f"stability_map_{ax.name}_{ay.name}.csv"
        scene._update_download()
        if scene.colours_sliding() and scene._current():
            scene.ensure_sliding()


def show_sliding_job(scene: Any, job: jobs.Job, state: jobs.JobState) -> None:
    """Show the sliding job's progress, its latest preview and, at its end, the map or the failure."""
    plane, n = job.key[0], job.key[1]
    total, done = state.totals.get("points", 0), state.done.get("points", 0)
    if scene.colours_sliding() and not scene._previewing():
        if scene.progress.max != total:
            scene.progress.value = 0
            scene.progress.max = total
        scene.progress.value = done
        scene.progress.visible = done < total  # a finished bar is not left on the page; the label says it
        preview = state.partial
        scene.progress_label.object = (
            f"Computing the sliding verdict over the {plane} map ({n} × {n} points): {done} of {total} points"
            + (f"; shown: one point in {preview.stride} along each axis, each cell the value of its block's "
               "lower-left point"
               if preview is not None and state.status == jobs.RUNNING else "")
            if done < total else f"The sliding verdict over the {plane} map ({n} × {n} points)")
    if state.status == jobs.RUNNING:
        scene.sliding_status = "computing"
        if state.partial is not None and state.partial is not scene.sliding:
            with frozen_document():
                scene.sliding = state.partial
            scene._preview_drawn_over()
    elif state.status == jobs.FAILED:
        scene.sliding_status = f"error: {state.error}"
    elif state.status == jobs.DONE:
        with frozen_document():
            scene.param.update(sliding=state.result, sliding_status="done")
        scene._preview_drawn_over()
        scene._update_download()
        scene.ensure_boundary()


def show_preview_job(scene: Any, job: jobs.Job, state: jobs.JobState) -> None:
    """Show a preview job's progress (in place of the map's while the slider is held) and its partial and final
    preview, or the failure (on the session's event loop)."""
    verdict = job.key[0]
    phase = "points" if verdict == sm.SLIDING else "chunks"
    total, done = state.totals.get(phase, 0), state.done.get(phase, 0)
    if scene._previewing():
        if scene.progress.max != total:
            scene.progress.value = 0
            scene.progress.max = total
        scene.progress.value = done
        scene.progress.visible = done < total
        n = PREVIEW_SLIDING_POINTS if verdict == sm.SLIDING else PREVIEW_POINTS
        scene.progress_label.object = preview_label(n) + (
            f" (the sliding verdict at {done} of {total} points)" if phase == "points" and done < total else "")
    if state.status == jobs.RUNNING:
        scene.preview_status = "computing"
        if state.partial is not None and state.partial is not scene.preview:
            with frozen_document():
                scene.preview = state.partial
    elif state.status == jobs.FAILED:
        scene.preview_status = f"error: {state.error}"
    elif state.status == jobs.DONE:
        with frozen_document():
            scene.param.update(preview=state.result, preview_status="done")


def show_boundary_job(scene: Any, job: jobs.Job, state: jobs.JobState) -> None:
    """Show the boundary's columns as they are computed and its end (or failure)."""
    shown = state.result if state.status == jobs.DONE else state.partial
    if shown is not None and shown is not scene.boundary and state.status in (jobs.RUNNING, jobs.DONE):
        with frozen_document():
            scene.boundary = {**shown, "key": job.key}
    if state.status == jobs.RUNNING:
        done, total = state.done.get("columns", 0), state.totals.get("columns", 0)
        scene.boundary_status = f"computing: {done} of {total} columns"
    elif state.status == jobs.FAILED:
        scene.boundary_status = f"error: {state.error}"
    elif state.status == jobs.DONE:
        scene.boundary_status = "done"
    scene._update_download()


def show_fig4c_job(scene: Any, job: jobs.Job, state: jobs.JobState) -> None:
    """Fig. 4c's sliding-threshold job: its progress in the readout, then the points (or the failure)."""
    done, total = state.done.get("β", 0), state.totals.get("β", 0)
    if state.status == jobs.RUNNING:
        scene.fig4c_sliding_status = (f"Computing the sliding threshold (every branch) at f = {fmt(job.key)}: "
                                      f"{done} of {total} β")
    elif state.status == jobs.FAILED:
        scene.fig4c_sliding_status = f"The sliding threshold could not be computed: {state.error}"
    elif state.status == jobs.DONE:
        with frozen_document():
            scene.param.update(fig4c_sliding=state.result, fig4c_sliding_status="")


def start_map(scene: Any) -> None:
    """Start computing the map of the current key unless it is shown or already being computed (called where the
    session may be modified: a render, a parameter change). A job's work is taken from its module at each start
    (``compute.compute_map``), not bound here at import."""
    key = scene.map_key
    job = scene.computation.job
    if scene._current() or (job is not None and job.key == key
                            and job.state().status in (jobs.RUNNING, jobs.DONE)):
        return
    scene.computation.run(partial(compute.compute_map, key), name="stability map", key=key,
                          totals={"chunks": len(chunk_rows(key[1])) + key[3]})


def start_sliding(scene: Any) -> None:
    """Start computing the sliding map of the current inputs unless it is shown complete or being computed."""
    key = scene.sliding_key
    job = scene.sliding_computation.job
    if scene._sliding_current() or (job is not None and job.key == key
                                    and job.state().status in (jobs.RUNNING, jobs.DONE)):
        return
    plane, n = key[0], key[1]
    x, y = plane_axes(plane, n)
    names = (PLANES[plane][0].name, PLANES[plane][1].name)
    scene.sliding_computation.run(partial(sm.compute_sliding_map, key, x, y, names, CHUNKS.get, CHUNKS.put),
                                  name="sliding map", key=key, totals={"points": n * n})
    scene.sliding_status = "computing"


def start_boundary(scene: Any) -> None:
    """Start computing the exact boundary of sliding over every branch once the sliding map of the current
    inputs is complete (unless it is shown complete or being computed):
    :func:`app.sliding_boundary.compute_boundary` over the map's x values and γ range, in the background worker
    when served."""
    key = scene.sliding_key
    job = scene.boundary_computation.job
    if (not scene.boundary_applies() or not scene._sliding_current() or scene._boundary_current()
            or (job is not None and job.key == key and job.state().status in (jobs.RUNNING, jobs.DONE))):
        return
    plane, n = key[0], key[1]
    x, _ = plane_axes(plane, n)
    edges = PLANES[plane][1].edges(n)
    work = partial(sb.compute_boundary, key, x, PLANES[plane][0].name, (float(edges[0]), float(edges[-1])),
                   CHUNKS.get, CHUNKS.put, in_process=jobs.served_document() is not None)
    scene.boundary_computation.run(work, name="sliding boundary", key=key, totals={"columns": n})
    scene.boundary_status = "computing"


def start_fig4c_sliding(scene: Any) -> None:
    """Start computing Fig. 4c's sliding threshold at the current f unless it is shown or being computed
    (called as Fig. 4c is drawn: a render, a change of f)."""
    if scene.params.dragging:  # a held f slider: the job starts at the release (_update_key)
        return
    f = float(scene.params.f)
    job = scene.fig4c_computation.job
    shown = scene.fig4c_sliding is not None and scene.fig4c_sliding["f"] == f
    if shown or (job is not None and job.key == f and job.state().status in (jobs.RUNNING, jobs.DONE)):
        return
    scene.fig4c_computation.run(partial(fig4c.compute_fig4c_sliding, f), name="Fig. 4c sliding threshold", key=f,
                                totals={"β": BETA_EXACT.size})


def start_preview(scene: Any) -> None:
    """While a slider is held at inputs off the map's, start their preview unless it is shown complete or being
    computed (called as the map is rendered: only a shown map computes). It starts computing once the previous
    preview job has stopped (:func:`~.preview.after_previous`)."""
    if not scene._previewing():
        return
    key = scene._preview_job_key(scene.preview_key)
    pv, job = scene.preview, scene.preview_computation.job
    if pv is not None and pv.job_key == key and pv.complete:
        return
    if job is not None and job.key == key and job.state().status != jobs.CANCELLED:
        return
    previous = [] if scene._last_preview_job is None else [scene._last_preview_job]
    scene._last_preview_job = scene.preview_computation.run(
        partial(after_previous, previous, partial(preview.compute_preview, key)), name="stability map preview", key=key,
        totals=preview_totals(key[0]))
    scene.preview_status = "computing"
