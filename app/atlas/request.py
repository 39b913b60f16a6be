"""What a URL asks the Atlas tab to show (:class:`AtlasRequest`, parsed and validated by app.urlstate), and how a
request meets the atlas once it is open: the asked axes kept where the atlas has them, the other axes' values snapped
to its grid, and what does not fit said in one message rather than refused."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .directory import Atlas


@dataclass(frozen=True)
class AtlasRequest:
    """What a URL asks the Atlas tab to show (validated names and numbers, see app.urlstate): the atlas, the heat
    map's axes, the other axes' values (snapped to the grid) and the 3-D view's axes. Values that do not fit the
    atlas, once it is open, are left out with a message."""

    name: str | None = None
    x: str | None = None
    y: str | None = None
    at: dict[str, float] = field(default_factory=dict)
    surface: tuple[str, ...] = ()
    verdict: str | None = None  # what the heat map is coloured by (app.sliding_map.SLIDING or RAYLEIGH)


def two_axes(names: list[str], x: str | None, y: str | None) -> tuple[str, str | None]:
    """Two different axes of `names` for the heat map (x, y), keeping the given ones where they fit; y is None for a
    1-axis atlas."""
    if len(names) == 1:
        return names[0], None
    x = x if x in names else names[0]
    y = y if y in names and y != x else next(n for n in names if n != x)
    return x, y


def requested_indices(data: Atlas, at: dict[str, float], notes: list[str], clamped: list[str]) -> dict[str, int]:
    """The grid index of every axis: the requested values (`at`, from the URL) snapped to the grid, the others
    mid-way. Axes the atlas lacks go into `notes`; values beyond an axis's ends into `clamped` (said, as the sliders'
    clamps are)."""
    indices = {n: len(v) // 2 for n, v in data.axes.items()}
    for name, value in at.items():
        if name not in data.names:
            notes.append(f"{name} is not an axis of atlas {data.name}")
            continue
        indices[name] = int(np.argmin(np.abs(data.axes[name] - value)))
        lo, hi = float(np.min(data.axes[name])), float(np.max(data.axes[name]))
        if not lo <= value <= hi:
            clamped.append(f"at_{name} = {value:g} is outside the atlas's {data.label(name)} range {lo:.4g} … "
                           f"{hi:.4g}: set to {float(data.axes[name][indices[name]]):.4g}")
    return indices


def opened_state(data: Atlas, request: AtlasRequest, x_axis: str | None, y_axis: str | None,
                 verdict: str) -> tuple[dict[str, object], str]:
    """The Atlas scene's whole state once atlas `data` is open, set in one update: its axes (the requested ones, else
    the current `x_axis` and `y_axis` if it has them, else its first two), the other axes' grid indices, the 3-D
    axes and what the heat map is coloured by; and the message saying which of the request's values did not fit
    ("" when all did)."""
    names = data.names
    notes: list[str] = []
    clamped: list[str] = []
    x, y = request.x or x_axis, request.y or y_axis
    for which, axis in (("x", request.x), ("y", request.y)):
        if axis is not None and axis not in names:
            notes.append(f"{which} axis {axis} is not an axis of atlas {data.name}")
    x, y = two_axes(names, x, y)
    indices = requested_indices(data, request.at, notes, clamped)
    surface = [n for n in request.surface if n in names]
    if len(set(surface)) != 3:
        if request.surface:
            notes.append(f"the 3-D view needs three axes of atlas {data.name}")
        surface = names[:3] if len(names) >= 3 else []
    state = {"data": data, "x_axis": x, "y_axis": y, "surface_axes": surface, "indices": indices,
             "verdict": request.verdict or verdict}
    said = (["; ".join(notes) + " (left as they were)"] if notes else []) + clamped
    return state, ("From the URL: " + "; ".join(said) + "." if said else "")
