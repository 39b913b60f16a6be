"""The Stability map while a slider is held: the key of the held inputs, the preview drawn in place of the map (of
them while the slider is held, of the released inputs until their full map is shown), and dropping it; functions of
the scene's state (a :class:`~asymslide.app.stability_map.scene.StabilityMapScene`)."""

from __future__ import annotations

from typing import Any

from .. import sliding_map as sm
from ..workarounds import frozen_document
from .grids import key_for
from .map_jobs import settle_progress
from .preview import MapPreview


def follow_held_inputs(scene: Any) -> None:
    """A held slider moved: the scene's ``preview_key`` is the key of the held inputs where they change the map (a
    parameter off the plane). A new key cancels the running preview (latest value wins; the next render of the
    map starts the new one: :func:`~.map_jobs.start_preview`); back at the map's own key the preview is dropped."""
    held = key_for(scene.plane, scene.resolution, scene.params.model_args())
    held = None if held == scene.map_key else held
    if held == scene.preview_key:
        return
    scene.preview_computation.cancel()
    if held is None:
        drop_preview(scene, key_too=True)
        return
    scene.preview_key = held
    scene._update_download()


def release_preview(scene: Any) -> None:
    """No slider held (the keys are those of the released inputs): stop the preview job; the preview of the
    released inputs stays drawn until their full map is shown (:func:`shown_preview`), a preview of other inputs
    is dropped."""
    if scene.preview_key is None and scene.preview is None and scene.preview_computation.job is None:
        return
    scene.preview_computation.cancel()
    pv = scene.preview
    if pv is not None and pv.job_key != scene._preview_job_key(scene.map_key):
        drop_preview(scene, key_too=True)
    else:
        scene.param.update(preview_key=None, preview_status="idle")
        settle_progress(scene)


def drop_preview(scene: Any, key_too: bool = False) -> None:
    """Stop and forget the preview (and, `key_too`, the held key): the map is drawn again."""
    scene.preview_computation.cancel()
    was = scene.preview is not None or scene.preview_key is not None
    updates: dict[str, Any] = {"preview": None, "preview_status": "idle"}
    if key_too:
        updates["preview_key"] = None
    with frozen_document():
        scene.param.update(**updates)
    if was:
        settle_progress(scene)
    scene._update_download()


def shown_preview(scene: Any, plane: str | None = None, verdict: str | None = None) -> MapPreview | None:
    """The preview the map of `plane` coloured by `verdict` (defaults: the current ones) draws in place of the map:
    while a slider is held at inputs off the map's, the latest preview (of them, or of the previous held value
    until theirs is computed); after the release, the preview of the released inputs until their full map (or
    its sliding map's first pass) is shown. None: the map is drawn."""
    pv = scene.preview
    plane, verdict = plane or scene.plane, verdict or scene.verdict
    if pv is None or pv.plane != plane or pv.verdict != verdict or (pv.sliding is None and verdict == sm.SLIDING):
        return None
    if scene.params.dragging:
        return pv if scene.preview_key is not None else None
    if pv.job_key != scene._preview_job_key(scene.map_key):
        return None
    if verdict == sm.SLIDING:
        sl = scene.sliding
        return None if sl is not None and sl.key == scene.sliding_key else pv
    return None if scene._current() else pv


def preview_drawn_over(scene: Any) -> None:
    """The full map (or the sliding map's first pass) of the released inputs is shown: their preview is
    dropped."""
    pv = scene.preview
    if pv is not None and not scene.params.dragging and shown_preview(scene, pv.plane, pv.verdict) is None:
        drop_preview(scene, key_too=True)
