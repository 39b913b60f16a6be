"""The Atlas tab's 3-D view: a Plotly figure of the neutral surface (max growth = 0) over three axes of an atlas, the
other axes at the sliders' values. The surface itself is pure geometry (asymslide.atlas.surface.neutral_surface);
here are its colours, axes, camera and layout, and the pane's size."""

from __future__ import annotations

import math

import numpy as np

from asymslide.atlas.surface import neutral_surface

from ..common import MARGINAL, NAN_COLOR
from ..plotting import fmt
from .directory import Atlas

#: the 3-D view's pane: its width over its height, and the least and most height (px). Plotly scales a 3-D scene with
#: the plot's height, so a tall plot on a narrow (phone's) page cut the box off at both sides: the height follows the
#: width instead, and the figure has none of its own (autosize: the pane gives Plotly its size, nothing cut off)
SURFACE_ASPECT = 1.45
SURFACE_MIN_HEIGHT = 420
SURFACE_MAX_HEIGHT = 600
#: the colours of the 3-D neutral surface by the value of its third axis (its depth)
SURFACE_COLORSCALE = "Viridis"
#: the camera of the 3-D view: further out than Plotly's default eye (1.25, 1.25, 1.25), whose view of the box's near
#: corner ran out of the bottom of the plot, and aimed a little below the box's centre, which lifts the box (its near
#: corner, nearest the camera, is drawn largest)
SURFACE_CAMERA = {"eye": {"x": 1.75, "y": 1.75, "z": 1.15}, "center": {"x": 0, "y": 0, "z": -0.12}}
#: Plotly's options of the 3-D view: the wheel zooms (said in the help text; no page-dependent default) and no logo
SURFACE_CONFIG = {"scrollZoom": True, "displaylogo": False}


def _surface_axis(title: str, plotted: np.ndarray, log: bool) -> dict:
    """A 3-D axis over an atlas axis's grid (`plotted`: its plotted coordinates, log10 of the values on a log axis):
    a log axis is a Plotly log axis that shows the parameter's values (whose range Plotly takes in log10 units)."""
    lo, hi = float(plotted.min()), float(plotted.max())
    axis = {"title": {"text": title}, "type": "log" if log else "linear", "range": [lo, hi]}
    if log and hi - lo >= 2:  # ticks at the decades: Plotly's 2 and 5 between them overlapped on a short axis
        axis["dtick"] = 1
    return axis


def _depth_colours(depth: np.ndarray, plotted: np.ndarray, title: str, log: bool) -> dict:
    """The mesh's colours by its vertices' third coordinate (`depth`, plotted coordinates: log10 on a log axis) over
    the axis's grid (`plotted`), with a colour bar titled by the axis that reads in the parameter's values."""
    lo, hi = float(plotted.min()), float(plotted.max())
    bar: dict = {"title": {"text": title}, "thickness": 14, "len": 0.7}
    if log:  # ticks at the decades inside the range, else at its ends and middle, labelled with the values
        ticks = np.arange(math.ceil(lo), math.floor(hi) + 1, dtype=float)
        ticks = ticks if ticks.size >= 2 else np.linspace(lo, hi, 3)
        bar |= {"tickmode": "array", "tickvals": ticks.tolist(), "ticktext": [fmt(10.0 ** t) for t in ticks]}
    return {"intensity": depth, "intensitymode": "vertex", "colorscale": SURFACE_COLORSCALE, "cmin": lo, "cmax": hi,
            "colorbar": bar}


def _surface_layout(title: str, scene: dict) -> dict:
    """The 3-D view's layout: the title and the legend above the scene (not over it), the scene in the rest of the
    pane's height (autosize)."""
    # a title of two lines anchored at its top still rose by one line out of the plot: the pad gives that line back
    return {"title": {"text": title, "font": {"size": 13}, "x": 0.01, "xanchor": "left", "yref": "container", "y": 1,
                      "yanchor": "top", "pad": {"t": 22}},
            "scene": {**scene, "camera": SURFACE_CAMERA}, "autosize": True,
            "margin": {"l": 0, "r": 0, "t": 96, "b": 0},
            "legend": {"orientation": "h", "x": 0, "xanchor": "left", "y": 1.0, "yanchor": "bottom"}}


def surface_figure(d: Atlas | None, axes: list[str], indices: dict[str, int]) -> dict | None:
    """A Plotly figure (dict) of the neutral surface growth = 0 of atlas `d` over the three chosen `axes` (the others
    at their grid `indices`, the sliders'): a triangle mesh (:func:`~asymslide.atlas.surface.neutral_surface`, none
    through cells with a masked corner) coloured by the third axis's value (a colour bar tells the depth a flat
    colour hid), the masked grid points as grey markers, and axes spanning the atlas's grid in the parameters'
    values (log axes as Plotly log axes). None without three axes."""
    axes = list(axes)
    if d is None or len(axes) != 3:
        return None
    names = d.names
    index = tuple(slice(None) if n in axes else indices.get(n, 0) for n in names)
    cube = np.asarray(getattr(d.growth[index], "values", d.growth[index]), dtype=float)
    kept = [n for n in names if n in axes]
    cube = np.transpose(cube, [kept.index(n) for n in axes])  # to the chosen order
    # interpolated along the plotted coordinates (log10 on a log axis), as the heat map's neutral curve, then
    # drawn at the parameters' values: a log axis puts them back where they were interpolated
    plotted = [d.display(n) for n in axes]
    vertices, triangles = neutral_surface(*plotted, cube, marginal=MARGINAL)
    logs = [bool(d.log[n]) for n in axes]
    values = np.column_stack([10.0 ** vertices[:, a] if logs[a] else vertices[:, a] for a in range(3)])
    not_computable = ~np.isfinite(cube)
    if d.adaptive and d.computed is not None:  # not computed is not "not computable"
        done = np.asarray(getattr(d.computed[index], "values", d.computed[index]))
        not_computable &= np.transpose(done, [kept.index(n) for n in axes]) >= 0
    masked = np.argwhere(not_computable)
    data = [{"type": "mesh3d", "x": values[:, 0], "y": values[:, 1], "z": values[:, 2],
             "i": triangles[:, 0], "j": triangles[:, 1], "k": triangles[:, 2], "opacity": 0.9,
             "flatshading": False, "name": "neutral surface (max growth = 0)", "showlegend": True,
             "hoverinfo": "skip", **_depth_colours(vertices[:, 2], plotted[2], d.label(axes[2]), logs[2])}]
    if masked.size:
        data.append({"type": "scatter3d", "mode": "markers", "name": "not computable (masked)",
                     "x": d.axes[axes[0]][masked[:, 0]], "y": d.axes[axes[1]][masked[:, 1]],
                     "z": d.axes[axes[2]][masked[:, 2]], "marker": {"size": 3, "color": NAN_COLOR},
                     "hoverinfo": "skip"})
    others = ", ".join(f"{d.label(n)} = {d.axes[n][indices.get(n, 0)]:.4g}" for n in names if n not in axes)
    # the conditions on a second line: one line of title did not fit a phone's width
    title = "Neutral surface (max growth = 0)" + (f"<br>at {others}" if others else "")
    if not len(triangles):
        title += "<br>no sign change of the growth in this cube: no surface"
    scene = {f"{a}axis": _surface_axis(d.label(n), c, log)
             for a, n, c, log in zip("xyz", axes, plotted, logs, strict=True)}
    return {"data": data, "layout": _surface_layout(title, scene)}


def surface_note(d: Atlas | None) -> str:
    """Why an atlas of fewer than three axes has no 3-D view (empty otherwise)."""
    if d is None or len(d.names) >= 3:
        return ""
    axes = ", ".join(d.label(n) for n in d.names)
    return (f"**No 3-D view of atlas {d.name}**: it has {len(d.names)} {'axes' if len(d.names) > 1 else 'axis'} "
            f"({axes}) and the neutral surface needs three. Make an atlas with three or more `--axis` "
            "(`asymslide sweep`), or open one in the Atlas menu.")
