"""The Stability map's CSV downloads: the map (with the sliding verdict's columns once computed) and the exact
boundary of sliding over every branch, and when each is offered; functions of the scene's state (a
:class:`~asymslide.app.stability_map.scene.StabilityMapScene`). Fig. 4c's CSV: :mod:`.fig4c`."""

from __future__ import annotations

import io
from typing import Any

import numpy as np

from ..exports import csv_table
from .grids import KH, PLANES


def update_downloads(scene: Any) -> None:
    """The CSV is offered once the Rayleigh map is current (the sliding columns are added once that map is), never
    while a slider is held at inputs off the map's (a preview is drawn: the CSV would not be what is shown)."""
    scene.map_download.disabled = not scene._current() or scene._previewing()
    scene.boundary_download.disabled = not (scene.boundary_applies() and scene._boundary_current()
                                            and not scene._previewing())
    if not scene.boundary_download.disabled:
        ax, ay = PLANES[scene.plane]
        scene.boundary_download.filename = f"stability_map_{ax.name}_{ay.name}_sliding_boundary.csv"


def map_csv(scene: Any) -> io.StringIO:
    """What the map shows: both plane parameters, max growth, kH at the maximum, masked kH points per point."""
    res = scene.result
    plane, n, fixed, levels = scene.map_key
    ax, ay = PLANES[plane]
    header = (f"asymslide stability map, plane {ax.name}-{ay.name}; max over kH = logspace(-3, 3, {KH.size}); "
              + ", ".join(f"{k} = {v!r}" for k, v in fixed)
              + f". max_growth NaN: not computable (n_masked_kH = {KH.size}: the branch was not followed at any "
                "kH; fewer: its maximum could not be refined)")
    if res is None or res.key != scene.map_key:
        return csv_table(header + " (not computed yet)",
                         {ax.name: [], ay.name: [], "max_growth": [], "kH_at_max": [], "n_masked_kH": []})
    nx, ny = res.x.size, res.y.size
    columns = {ax.name: np.tile(res.x, ny), ay.name: np.repeat(res.y, nx), "max_growth": res.growth.ravel(),
               "kH_at_max": res.kH_at_max.ravel(), "n_masked_kH": res.n_masked.ravel()}
    refined = res.refined.points if res.refined is not None else None
    if refined is not None:
        header += (f". level 0: the {nx} × {ny} grid; level 1..{levels}: the points added where the Rayleigh "
                   "verdict changes between neighbouring cells (each level halves the cells)")
        columns = {ax.name: np.concatenate([columns[ax.name], refined["x"]]),
                   ay.name: np.concatenate([columns[ay.name], refined["y"]]),
                   "max_growth": np.concatenate([columns["max_growth"], refined["growth"]]),
                   "kH_at_max": np.concatenate([columns["kH_at_max"], refined["kH_at_max"]]),
                   "n_masked_kH": np.concatenate([columns["n_masked_kH"], refined["n_masked"]]).astype(int),
                   "level": np.concatenate([np.zeros(nx * ny, int), refined["level"].astype(int)])}
    sl = scene.sliding
    if scene.colours_sliding() and not scene._sliding_current():
        header += ". Sliding over every branch: not in this file (its map is being computed: download it again "
        header += "when it is complete)"
    if scene.colours_sliding() and scene._sliding_current() and sl is not None:
        lo, hi = sl.kH_range
        header += (f". Sliding over every branch (model.sliding_analysis, kH {lo!r} to {hi!r}, floor "
                   f"{sl.floor!r}): verdict_all 0 stable, 1 unstable, 2 undetermined; verdict_reason_all "
                   "model.SLIDING_STATUS; "
                   "family_all model.FAMILIES (-1: none); max_growth_all NaN unless unstable and certified")
        f = sl.fields
        extra = 0 if refined is None else refined["x"].size
        if extra:
            header += " (on the level-0 grid only: NaN or -1 on the refined points)"

        def pad(a: np.ndarray, fill: float) -> np.ndarray:
            a = a.ravel()
            return np.concatenate([a, np.full(extra, fill, dtype=float if np.isnan(fill) else a.dtype)])

        columns.update({"max_growth_all": pad(f["growth"], np.nan), "kH_at_max_all": pad(f["kH_at_max"], np.nan),
                        "re_z_at_max_all": pad(f["re_z"], np.nan), "family_all": pad(f["family"], -1),
                        "verdict_all": pad(f["verdict"], -1), "verdict_reason_all": pad(f["reason"], -1)})
    return csv_table(header, columns)


def boundary_csv(scene: Any) -> io.StringIO:
    """The threshold of sliding over every branch drawn on the map (purple): per column of the grid, every
    crossing in γ (model.critical_gammas with branches="all"), certified or not, with its reason."""
    plane, n, fixed, floor = scene.sliding_key
    ax, _ = PLANES[plane]
    header = (f"asymslide stability map, plane {ax.name}-gamma: crossings in gamma of the max growth over every "
              f"branch (model.critical_gammas, branches='all', floor {floor!r}, kH model.SLIDING_KH) at each "
              f"x of the {n} x {n} grid; " + ", ".join(f"{k} = {v!r}" for k, v in fixed)
              + ". gamma_c NaN unless certified (reason 0: a neutral mode; 1: at an end of the kH range); "
                "location: where the sign change is; direction +1: unstable above, -1: stable above; reason: "
                "model.CROSSING_STATUS; kH, re_z: the neutral mode")
    names = (ax.name, "crossing", "gamma_c", "location", "direction", "reason", "kH", "re_z")
    b = scene.boundary
    if not (scene.boundary_applies() and scene._boundary_current()):
        return csv_table(header + " (not computed yet)", dict.fromkeys(names, []))
    rows = np.argwhere(b["reason"] >= 0)  # (column, crossing) of every crossing found
    i, k = rows[:, 0], rows[:, 1]
    return csv_table(header, dict(zip(names, (b["x"][i], k, b["value"][i, k], b["location"][i, k],
                                              b["direction"][i, k], b["reason"][i, k], b["kH"][i, k],
                                              b["z"][i, k]), strict=True)))
