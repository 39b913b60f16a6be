"""Scene "Atlas": a stored stability atlas (``asymslide sweep``), explored slice by slice.

An atlas is the Rayleigh branch's maximal growth rate on an N-D grid of (γ, f, β, η, Δ, ξ), with the exact threshold
γ_c over the other axes (atlas/schema.py; docs/physics.md §9). This scene shows any two axes as a heat map of the
growth with the neutral curve (growth = 0) and, where γ is one of the two, the slice of the γ_c surface; the other axes
are sliders that snap to the grid. A slice change only reads the stored cube (no model function is called). A 3-D
view shows the neutral surface (growth = 0) over three chosen axes, and a click on a cell sets the shared parameters
of the other scenes to that cell.

Atlases are read from one directory only: ``$ASYMSLIDE_ATLAS_DIR`` (``asymslide serve --atlas-dir``), default
``$XDG_CACHE_HOME/asymslide/atlases`` (~/.cache/asymslide/atlases). The URL may name an atlas of that directory
(``?tab=atlas&atlas=NAME`` for ``NAME.zarr``); no other path is ever read. The default atlas (4-D: γ, η, f, β) is not
shipped: it is computed on first use into that directory, in the background with a progress bar (~25 s on two
cores), and reused afterwards; another server process computing it is waited for (a file lock).
"""

from __future__ import annotations

import hashlib
import io
import json
import logging
import math
import os
import re
import threading
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import panel as pn
import param
from bokeh.models import CustomJSTickFormatter

from asymslide import model
from asymslide.atlas import store, summary
from asymslide.atlas.plan import make_plan
from asymslide.atlas.refinement import refinement_text
from asymslide.atlas.schema import model_fingerprint

from . import jobs
from . import sliding_map as slm
from .common import (
    COLOUR_LEGEND,
    GROWTH_LABEL,
    GROWTH_PALETTE,
    LOG_COORDINATE_TICKS,
    MARGINAL,
    NAN_COLOR,
    neutral_lines,
)
from .params import SpectrumParams, csv_table, fmt, heading, readable_ticks, scene_layout
from .workarounds import frozen_document

log = logging.getLogger(__name__)

#: the default atlas: 4-D over (γ, η, f, β) at Δ = 1, ξ = 0, with γ_c over (η, f, β)
DEFAULT_AXES = {
    "gamma": np.geomspace(0.1, 30.0, 16),
    "eta": np.geomspace(1.5, 1e4, 9),
    "f": np.linspace(0.3, 1.5, 5),
    "beta": np.linspace(0.1, 0.6, 5),
}
DEFAULT_KH = np.logspace(-3, 3, 49)
#: the default atlas is NAME.zarr with NAME = DEFAULT_PREFIX + a hash (see default_name)
DEFAULT_PREFIX = "default-"

#: where atlases are read from and how they may be named (the store's)
atlas_dir = store.atlas_dir
NAME = store.NAME


def default_name() -> str:
    """The default atlas's name: a hash of the model's fingerprint and the atlas's plan, so that another model
    version or another DEFAULT_AXES computes a new one instead of refusing to resume the old."""
    plan = make_plan(DEFAULT_AXES, kH=DEFAULT_KH).identity()
    key = model_fingerprint() + json.dumps(plan, sort_keys=True)
    return DEFAULT_PREFIX + hashlib.sha256(key.encode()).hexdigest()[:12]


def display_name(name: str) -> str:
    """How the select and the titles call an atlas: its file name, but the current default atlas by what it is
    ("default (γ-η-f-β, 4-D)") rather than by its hash. The URL and the store keep the file name
    (default-<hash>), so shared links stay valid."""
    if name != default_name():
        return name
    symbols = "-".join(model.PARAMETERS[n].symbol if n in model.PARAMETERS else n for n in DEFAULT_AXES)
    return f"default ({symbols}, {len(DEFAULT_AXES)}-D)"


def list_atlases(directory: Path | None = None) -> list[str]:
    """Names of the atlases in the directory (``NAME.zarr`` written by asymslide sweep), the current default first;
    defaults of other model versions are left out."""
    current = default_name()
    names = store.list_atlases(atlas_dir() if directory is None else directory,
                               skip=lambda name: name.startswith(DEFAULT_PREFIX) and name != current)
    return sorted(names, key=lambda n: (n != current, n))


def resolve(name: str) -> Path | None:
    """The store of the atlas `name` if it is listed in the atlas directory (never any other path)."""
    if not isinstance(name, str) or not NAME.match(name) or name not in list_atlases():
        return None
    return atlas_dir() / f"{name}.zarr"


# ------------------------------------------------------------------------------------------------
# the default atlas: computed once per machine, in the background
# ------------------------------------------------------------------------------------------------


#: the phases of an atlas computation, in the order the engine runs them (its task kinds), with their labels
PHASES = {"growth": "Growth rates (max Im[c/c_s] over kH at every grid point)",
          "gamma_c": "Thresholds γ_c (exact, over the other axes)"}


#: how often (s) the default atlas's job re-reads the store while another server process computes it
OTHER_PROCESS_POLL_S = 0.3

_default_lock = threading.Lock()
#: the default atlas's job in this process (app.jobs.Job), followed by every session that opens the tab meanwhile
_default_job: jobs.Job | None = None


def default_ready() -> bool:
    """Whether the default atlas is complete in the atlas directory."""
    return store.is_complete(atlas_dir() / f"{default_name()}.zarr")


def ensure_default() -> jobs.Job:
    """The job computing the default atlas in this process, started once (again if it failed, or if its atlas has gone
    since); its progress phases are the engine's task kinds (:data:`PHASES`)."""
    global _default_job
    with _default_lock:
        job = _default_job
        if job is None or (job.state().finished and not default_ready()):
            job = _default_job = jobs.Job(_compute_default, name="default atlas").start()
        return job


def _compute_default(job: jobs.Job) -> Path:
    """The work of the default atlas's job: compute it into the atlas directory, or, when another server process
    holds the directory's lock for it, follow that process's progress in the store; its path."""
    directory = atlas_dir()
    try:
        return store.compute_once(DEFAULT_AXES, DEFAULT_KH, directory / f"{default_name()}.zarr",
                                  set_totals=job.set_totals, advance=job.advance, set_done=job.set_done,
                                  poll_s=OTHER_PROCESS_POLL_S, command="the Atlas tab's default atlas (app/atlas.py)")
    except PermissionError as exc:  # a folder this server may read but not write (a mounted volume, say)
        raise jobs.Failed(read_only_message(directory, exc)) from None


def read_only_message(directory: Path, exc: OSError) -> str:
    """What the tab says when the atlas directory cannot be written: why, what still works, and how to fix it."""
    return (f"the atlas directory {directory} is not writable by this server (user id {os.getuid()}; "
            f"{exc.strerror or exc}), so the default atlas cannot be computed there. Atlases already in it still "
            "open (choose one above). To fix it, make the folder writable for this user (e.g. `chown` it), or serve "
            "with `--atlas-dir` (Docker: mount) a folder this user can write.")


# ------------------------------------------------------------------------------------------------
# an atlas in memory (asymslide.atlas.store)
# ------------------------------------------------------------------------------------------------

Atlas = store.Atlas
CROSSING_VARIABLES = store.CROSSING_VARIABLES
#: verdict class of an undetermined point
UNDETERMINED = model.Verdict.UNDETERMINED


#: the refused sign changes of the boundary in a few words (the full texts: model.CROSSING_STATUS)
REFUSED_CROSSING = {2: "a jump where the masked part of the kH range changes",
                    3: "a jump: the branch changes route (branch exchange)",
                    4: "a pole-dense neutral mode",
                    5: "the max growth is undefined in the bracket",
                    6: "not certified"}


def short_reason(code: int, texts: dict[int, str]) -> str:
    """The reason of a verdict or crossing code in a few words: its text up to the first colon or parenthesis after
    the class ("undetermined: pole-dense: ..." -> "pole-dense")."""
    text = texts.get(int(code), f"reason {int(code)}")
    head, _, rest = text.partition(": ")
    if head in ("stable", "unstable", "undetermined") and rest:
        text = rest
    return re.split(r": | \(", text, maxsplit=1)[0]


#: the atlases read from their stores, cached by name, path and the state of their done flags
_load = store.read_atlas


def load(name: str) -> Atlas:
    path = resolve(name)
    if path is None:
        raise ValueError(f"no atlas named {name!r} in {atlas_dir()}")
    return store.open_atlas(name, path)


# ------------------------------------------------------------------------------------------------
# the 3-D neutral surface: marching tetrahedra that skip masked cells
# ------------------------------------------------------------------------------------------------

#: what a NaN growth means (the atlas engine stores model.growth_analysis: NaN where the branch could not be
#: followed at any kH, or where the maximum could not be refined)
NOT_COMPUTABLE = ("the Rayleigh branch could not be followed at any kH, or its maximum could not be refined "
                  "(n_masked_kH in the CSV tells which)")

#: what the CSV exports say about NaN growth rows
NAN_ROWS = ("max_growth NaN: not computable (n_masked_kH = the number of kH grid points: the branch was not followed "
            "at any kH; fewer: its maximum could not be refined)")

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

#: a cube cell's corners (offsets along x, y, z) and its six tetrahedra around the diagonal from corner 0 to 6
_CORNERS = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)])
_TETRAHEDRA = np.array([(0, 5, 1, 6), (0, 1, 2, 6), (0, 2, 3, 6), (0, 3, 7, 6), (0, 7, 4, 6), (0, 4, 5, 6)])


def neutral_surface(x: np.ndarray, y: np.ndarray, z: np.ndarray, values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The surface values = 0 of values[i, j, k] on the grid (x[i], y[j], z[k]), as (vertices (n, 3), triangles
    (m, 3) of vertex indices): marching tetrahedra, i.e. linear interpolation along the edges of each grid cell's six
    tetrahedra, exact for a linear field. |value| <= MARGINAL counts as not unstable (as the heat maps' neutral
    curve). A cell with a masked (NaN) corner gets no surface: where the growth is not computable the boundary is
    not drawn, rather than guessed (Plotly's isosurface draws nothing at all once a value is NaN)."""
    v = np.where(np.abs(values) <= MARGINAL, -MARGINAL, np.asarray(values, dtype=float))
    nx, ny, nz = v.shape
    if min(nx, ny, nz) < 2:
        return np.empty((0, 3)), np.empty((0, 3), dtype=int)
    cells = np.stack(np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), np.arange(nz - 1), indexing="ij"), -1)
    cells = cells.reshape(-1, 3)
    corner_idx = cells[:, None, :] + _CORNERS[None, :, :]  # (cells, 8, 3)
    cell_finite = np.isfinite(v[corner_idx[..., 0], corner_idx[..., 1], corner_idx[..., 2]]).all(1)
    tet_idx = corner_idx[:, _TETRAHEDRA, :].reshape(-1, 4, 3)  # (cells * 6, 4, 3)
    val = v[tet_idx[..., 0], tet_idx[..., 1], tet_idx[..., 2]]  # (tets, 4)
    pos = np.stack([x[tet_idx[..., 0]], y[tet_idx[..., 1]], z[tet_idx[..., 2]]], -1)  # (tets, 4, 3)
    positive = val > 0
    n_pos = positive.sum(1)
    keep = np.repeat(cell_finite, len(_TETRAHEDRA)) & (n_pos > 0) & (n_pos < 4)
    val, pos, positive, n_pos = val[keep], pos[keep], positive[keep], n_pos[keep]

    def cross(a: np.ndarray, b: np.ndarray, rows: np.ndarray) -> np.ndarray:
        """Where the field is 0 on the edge between vertex a[r] and b[r] of each tetrahedron r of rows."""
        va, vb = val[rows, a], val[rows, b]
        t = (va / (va - vb))[:, None]
        return pos[rows, a] + t * (pos[rows, b] - pos[rows, a])

    tris: list[np.ndarray] = []
    order = np.argsort(~positive, axis=1, kind="stable")  # the positive vertices first
    # one vertex apart from the other three (1 or 3 positive): one triangle
    for n_odd, odd_first in ((1, True), (3, False)):
        rows = np.flatnonzero(n_pos == n_odd)
        if rows.size:
            o = order[rows]
            odd, rest = (o[:, 0], o[:, 1:]) if odd_first else (o[:, 3], o[:, :3])
            tris.append(np.stack([cross(odd, rest[:, i], rows) for i in range(3)], 1))
    # two positive, two negative: a quadrilateral, as two triangles
    rows = np.flatnonzero(n_pos == 2)
    if rows.size:
        o = order[rows]
        p0, p1, m0, m1 = o[:, 0], o[:, 1], o[:, 2], o[:, 3]
        a, b, c, e = cross(p0, m0, rows), cross(p0, m1, rows), cross(p1, m1, rows), cross(p1, m0, rows)
        tris += [np.stack([a, b, c], 1), np.stack([a, c, e], 1)]
    if not tris:
        return np.empty((0, 3)), np.empty((0, 3), dtype=int)
    corners = np.concatenate(tris)  # (m, 3 corners, 3 coordinates)
    return corners.reshape(-1, 3), np.arange(corners.shape[0] * 3).reshape(-1, 3)


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


# ------------------------------------------------------------------------------------------------
# the heat map: a Bokeh figure whose sources a slice change updates in place
# ------------------------------------------------------------------------------------------------

#: height of the heat map in px
HEIGHT = 480


#: ticks asked of the heat map's x axis (Bokeh's default, 6, collided on a 390 px wide page, where about 200 px of
#: plot are left between the y axis and the colour bar: issue 33)
X_TICKS = 4
#: the least gap (px) between two tick labels of the heat map; a label closer to its neighbour is not drawn
TICK_GAP = 8


#: the heat map's legend (HeatMap's colour mapper: growth > 0 red, as in the Stability map)
COLOURS = (f"{COLOUR_LEGEND}; hatched: undetermined verdict (the reason on hover; the colour is the growth where the "
           "branch is resolved). Where γ is an axis: every certified threshold γ_c, green where sliding becomes "
           "unstable as γ grows, orange where it becomes stable; ×: a sign change of the max growth that is not a "
           "threshold (a jump or a pole-dense mode, docs/physics.md §9). In an adaptive atlas (asymslide sweep "
           "--adaptive) the growth is computed only near the boundary: the pale dotted cells were not computed, and "
           "show the verdict class filled from the computed cell around them (pale red unstable, pale blue stable, "
           "pale grey undetermined); the neutral curve is drawn from computed cells only. Click a legend entry to "
           "hide it or to show the computed points.")
#: an adaptive atlas's not computed cells by filled verdict class: (word, pale colour of the class); -1: no class
FILLED_CLASSES = {0: ("stable", "#d6e6f4"), 1: ("unstable", "#f9d5c5"), 2: ("undetermined", "#e3e3e3"),
                  -1: ("unknown", "#ffffff")}
#: the dots over an adaptive atlas's not computed cells
FILLED_HATCH = "#8c8c8c"
#: colours of the certified crossings by direction (+1 destabilising, -1 stabilising as γ grows) and of the refused ones
CROSSING_COLORS = {1: "#1b7837", -1: "#e08214", 0: "#2ca25f"}
#: the threshold of sliding over every branch (an atlas swept with --sliding-thresholds), drawn when the heat map is
#: coloured by the sliding verdict
SLIDING_THRESHOLD_COLOR = "#762a83"
REFUSED_COLOR = "#404040"


def grid_hover(edges: np.ndarray, values: np.ndarray):
    """A hover formatter of a heat map axis: the atlas's value of the cell under the pointer (not the pointer's
    plotted coordinate, which is log10 of the value on a log axis), as the readouts print it. edges: the cells'
    edges in plotted coordinates (len(values) + 1)."""
    from bokeh.models import CustomJSHover

    return CustomJSHover(args={"edges": [float(e) for e in edges], "texts": [fmt(float(v)) for v in values]},
                         code="let i = 0; while (i < texts.length - 1 && value >= edges[i + 1]) { i++; } "
                              "return texts[i];")


#: a heat map's cells keep their colour when a click selects one (Bokeh dims the others to alpha 0.1 by default)
UNDIMMED = {"nonselection_fill_alpha": 1.0, "selection_fill_alpha": 1.0, "nonselection_line_alpha": 0.0,
            "selection_line_alpha": 0.0}


class HeatMap:
    """The heat map of one atlas and pair of axes: the slice's growth (an image glyph, or one rectangle per cell
    on irregular axes), the neutral curve and the γ_c slice, a colour bar over the whole atlas's range, hover and
    click (`on_tap(x, y)` in plotted coordinates).

    Why Bokeh directly and not a HoloViews DynamicMap as the other scenes: a slice change sends new data only, and
    updating three ColumnDataSources is an order of magnitude cheaper on the server than HoloViews' update of the
    same overlay (benchmarks/design_measurements.md); the slice-to-paint target is 100 ms in the browser."""

    def __init__(self, atlas: Atlas, x_axis: str, y_axis: str | None, on_tap) -> None:
        from bokeh.events import Tap
        from bokeh.models import ColorBar, ColumnDataSource, HoverTool, LinearColorMapper
        from bokeh.plotting import figure

        self.atlas, self.x_axis, self.y_axis = atlas, x_axis, y_axis
        x = atlas.display(x_axis)
        y = atlas.display(y_axis) if y_axis else np.array([0.0])
        self.regular = _uniform(x) and _uniform(y)
        xr = _edges(x)
        yr = _edges(y)
        fixed = ", ".join(f"{atlas.label(k)} = {'∞' if math.isinf(v) else fmt(v)}" for k, v in atlas.fixed.items())
        plane = f"{atlas.label(x_axis)}-{atlas.label(y_axis) if y_axis else ''}"
        title = (f"{display_name(atlas.name)}: max growth rate over {plane}"
                 + (f"; {fixed}" if fixed else ""))
        fig = figure(title=title, height=HEIGHT, sizing_mode="stretch_width", x_range=(xr[0], xr[-1]),
                     y_range=(yr[0], yr[-1]), tools="pan,wheel_zoom,box_zoom,reset,save,tap", toolbar_location="right",
                     x_axis_label=atlas.label(x_axis) + (" (log scale)" if atlas.log[x_axis] else ""),
                     y_axis_label=(atlas.label(y_axis) + (" (log scale)" if atlas.log[y_axis] else "")) if y_axis
                     else "")
        self._readable_ticks(fig, atlas, x_axis, y_axis)
        self.mapper = LinearColorMapper(palette=list(GROWTH_PALETTE), low=-atlas.clim, high=atlas.clim,  # high: red
                                        nan_color=NAN_COLOR)
        if self.regular:
            self.cells = ColumnDataSource({"image": [np.zeros((y.size, x.size))], "x": [xr[0]], "y": [yr[0]],
                                           "dw": [xr[-1] - xr[0]], "dh": [yr[-1] - yr[0]]})
            heat = fig.image(image="image", x="x", y="y", dw="dw", dh="dh", source=self.cells,
                             color_mapper=self.mapper)
            field = "@image"
        else:
            xc, yc = np.meshgrid((xr[:-1] + xr[1:]) / 2, (yr[:-1] + yr[1:]) / 2)
            w, h = np.meshgrid(np.diff(xr), np.diff(yr))
            self.cells = ColumnDataSource({"x": xc.ravel(), "y": yc.ravel(), "w": w.ravel(), "h": h.ravel(),
                                           "growth": np.zeros(xc.size)})
            heat = fig.rect(x="x", y="y", width="w", height="h", source=self.cells, line_alpha=0,
                            fill_color={"field": "growth", "transform": self.mapper}, **UNDIMMED)
            field = "@growth"
        axes_tips = [(atlas.label(x_axis), "$x{grid}")] + ([(atlas.label(y_axis), "$y{grid}")] if y_axis else [])
        fig.add_tools(HoverTool(renderers=[heat], tooltips=[*axes_tips, (GROWTH_LABEL, field)],
                                formatters={"$x": grid_hover(xr, atlas.axes[x_axis]),
                                            **({"$y": grid_hover(yr, atlas.axes[y_axis])} if y_axis else {})}))
        self._cell_geometry = self._geometry(xr, yr)
        self.filled, self.computed_points = self._adaptive_layers(fig) if atlas.adaptive else (None, None)
        self.undetermined = ColumnDataSource({"x": [], "y": [], "w": [], "h": [], "why": []})
        hatched = fig.rect(x="x", y="y", width="w", height="h", source=self.undetermined, fill_alpha=0, line_alpha=0,
                           hatch_pattern="/", hatch_color="#252525", hatch_alpha=0.7, hatch_scale=8,
                           legend_label="undetermined (hatched)")
        fig.add_tools(HoverTool(renderers=[hatched], tooltips=[("verdict", "undetermined: @why")]))
        self.contour = ColumnDataSource({"xs": [], "ys": []})
        fig.multi_line(xs="xs", ys="ys", source=self.contour, line_color="black", line_width=2,
                       legend_label="Rayleigh branch neutral curve (growth = 0)")
        self.sliding_thresholds, self.thresholds = self._threshold_layers(fig, atlas)
        self.refused = ColumnDataSource({"x": [], "y": [], "why": []})
        crosses = fig.scatter(x="x", y="y", source=self.refused, marker="x", size=9, line_width=2,
                              line_color=REFUSED_COLOR, legend_label="sign change, not a threshold")
        fig.add_tools(HoverTool(renderers=[crosses], tooltips=[("not a threshold", "@why")]))
        self._legend_style(fig)
        self.colorbar = ColorBar(color_mapper=self.mapper, title=GROWTH_LABEL, formatter=readable_ticks())
        fig.add_layout(self.colorbar, "right")
        self.heat_renderer, self.title_rayleigh = heat, title
        self.sliding_classes = self.sliding_growth = self.sliding_colorbar = None
        if atlas.has_sliding:
            self._sliding_layers(fig, atlas, axes_tips, {"$x": grid_hover(xr, atlas.axes[x_axis]),
                                                          **({"$y": grid_hover(yr, atlas.axes[y_axis])} if y_axis
                                                             else {})})
        fig.on_event(Tap, lambda event: on_tap(x=event.x, y=event.y))
        self.figure = fig

    @staticmethod
    def _readable_ticks(fig, atlas: Atlas, x_axis: str, y_axis: str | None) -> None:
        """Tick labels that stay apart at any width: fewer ticks on the x axis, where the labels sit side by side,
        labels in the app's style (log axes: 10ⁿ, app.common.LOG_COORDINATE_TICKS; linear ones: app.params.TICKS_JS),
        and labels that would still overlap (a phone's page) left out by the browser."""
        from bokeh.models import NoOverlap

        fig.xaxis.ticker.desired_num_ticks = X_TICKS
        for axis, name in ((fig.xaxis, x_axis), (fig.yaxis, y_axis)):
            axis.major_label_policy = NoOverlap(min_distance=TICK_GAP)
            axis.formatter = (CustomJSTickFormatter(code=LOG_COORDINATE_TICKS) if name is not None and atlas.log[name]
                              else readable_ticks())

    @staticmethod
    def _geometry(xr: np.ndarray, yr: np.ndarray) -> dict[str, np.ndarray]:
        """The cells' centres and sizes (flat, row-major) from their edges."""
        xc, yc = np.meshgrid((xr[:-1] + xr[1:]) / 2, (yr[:-1] + yr[1:]) / 2)
        w, h = np.meshgrid(np.diff(xr), np.diff(yr))
        return {"x": xc.ravel(), "y": yc.ravel(), "w": w.ravel(), "h": h.ravel()}

    @staticmethod
    def _legend_style(fig) -> None:
        fig.legend.location = "top_left"
        fig.legend.background_fill_alpha = 0.8
        fig.legend.click_policy = "hide"

    def _sliding_layers(self, fig, atlas: Atlas, axes_tips: list, formatters: dict) -> None:
        """The layers of the sliding verdict over every branch (an atlas swept with --sliding): the verdict classes
        (stable blue, undetermined dark grey, unstable red where its maximum is not certified) under the growth of
        every branch where unstable (log colour scale from the floor), with the verdict, family, kH and z on hover;
        empty (and the Rayleigh branch's image shown) while the map is coloured by the Rayleigh branch."""
        from bokeh.models import ColorBar, ColumnDataSource, HoverTool, LogColorMapper

        self.sliding_classes = ColumnDataSource({"x": [], "y": [], "w": [], "h": [], "color": [], "legend": []})
        fig.rect(x="x", y="y", width="w", height="h", source=self.sliding_classes, fill_color="color", line_alpha=0,
                 legend_field="legend", **UNDIMMED)
        floor = atlas.sliding_floor if math.isfinite(atlas.sliding_floor) else float(model.DEFAULT_FLOOR)
        top = atlas.sliding_top if math.isfinite(atlas.sliding_top) and atlas.sliding_top > floor else 10 * floor
        self.sliding_mapper = LogColorMapper(palette=slm.GROWTH_ALL_CMAP, low=floor, high=top,
                                             nan_color="rgba(0,0,0,0)")
        self.sliding_growth = ColumnDataSource({"x": [], "y": [], "w": [], "h": [], "growth_all": [], "sliding": [],
                                                "kH": [], "re_z": []})
        top_layer = fig.rect(x="x", y="y", width="w", height="h", source=self.sliding_growth, line_alpha=0,
                             fill_color={"field": "growth_all", "transform": self.sliding_mapper}, **UNDIMMED)
        fig.add_tools(HoverTool(renderers=[top_layer], formatters=formatters, tooltips=[
            *axes_tips, ("sliding", "@sliding"), (slm.GROWTH_ALL_LABEL, "@growth_all"), ("kH at max", "@kH"),
            ("Re z at max", "@re_z")]))
        self.sliding_colorbar = ColorBar(color_mapper=self.sliding_mapper, title=slm.GROWTH_ALL_LABEL, visible=False)
        fig.add_layout(self.sliding_colorbar, "right")
        # drawn right above the Rayleigh branch's image: the neutral curve, thresholds and marks stay on top
        new = fig.renderers[-2:]
        rest = [r for r in fig.renderers[:-2] if r is not self.heat_renderer]
        fig.renderers = [self.heat_renderer, *new, *rest]

    def update_sliding(self, fields: dict[str, np.ndarray] | None, floor: float, plane: str) -> None:
        """Colour the slice by the sliding verdict (`fields`: the slice's sliding variables, of the slice's shape)
        or, with None, by the Rayleigh branch's growth (the image)."""
        if self.sliding_classes is None:
            return
        sliding = fields is not None
        self.heat_renderer.visible = not sliding
        self.colorbar.visible = not sliding
        self.sliding_colorbar.visible = sliding
        self.figure.title.text = (f"{display_name(self.atlas.name)}: sliding verdict (every branch, Im z ≥ "
                                  f"{floor:g}) over {plane}" if sliding else self.title_rayleigh)
        if not sliding:
            self.sliding_classes.data = {k: [] for k in self.sliding_classes.data}
            self.sliding_growth.data = {k: [] for k in self.sliding_growth.data}
            return
        v = np.asarray(fields["verdict_all"]).ravel().astype(int)
        fam = np.asarray(fields["family_all"]).ravel().astype(int)
        reason = np.asarray(fields["verdict_reason_all"]).ravel().astype(int)
        g = np.asarray(fields["growth_all"], dtype=float).ravel()
        done = np.flatnonzero(v >= 0)
        words = {0: "sliding stable", 1: "sliding unstable", 2: "sliding undetermined"}
        colours = np.array(slm.VERDICT_COLOURS, dtype=object)
        self.sliding_classes.data = {**{k: val[done] for k, val in self._cell_geometry.items()},
                                     "color": colours[v[done]], "legend": np.array([words[int(c)] for c in v[done]],
                                                                                  dtype=object)}
        text = slm.hover_text(v, reason, fam, floor)
        self.sliding_growth.data = {**{k: val[done] for k, val in self._cell_geometry.items()},
                                    "growth_all": np.where(v == 1, g, np.nan)[done], "sliding": text[done],
                                    "kH": np.asarray(fields["kH_at_max_all"], dtype=float).ravel()[done],
                                    "re_z": np.asarray(fields["re_z_at_max_all"], dtype=float).ravel()[done]}

    @staticmethod
    def _threshold_layers(fig, atlas: Atlas):
        """The γ_c lines: the sliding threshold's (an atlas with it), then the Rayleigh branch's by direction.
        Returns their data sources (sliding, {direction: source})."""
        from bokeh.models import ColumnDataSource

        sliding = ColumnDataSource({"xs": [], "ys": []})
        if atlas.crossings_all:
            fig.multi_line(xs="xs", ys="ys", source=sliding, line_color=SLIDING_THRESHOLD_COLOR, line_width=3,
                           line_dash="dotdash", legend_label="sliding γ_c (every branch; certified)")
        thresholds = {}
        for direction, label in ((1, "γ_c: unstable above (certified)"), (-1, "γ_c: stable above (certified)"),
                                 (0, "γ_c (an older atlas: the first threshold, direction not stored)")):
            thresholds[direction] = ColumnDataSource({"xs": [], "ys": []})
            fig.multi_line(xs="xs", ys="ys", source=thresholds[direction], line_color=CROSSING_COLORS[direction],
                           line_width=3, line_dash="dashed", legend_label=label)
        return sliding, thresholds

    def _adaptive_layers(self, fig):
        """The layers of an adaptive atlas: the not computed cells in the pale colour of their filled verdict class,
        dotted, with hover "not computed: verdict ... from its cell (level L)", and the computed points as dots
        (hidden until their legend entry is clicked). Returns their two data sources."""
        from bokeh.models import ColumnDataSource, HoverTool

        # its own legend field: Bokeh merges the legend items of renderers whose label field has the same name (the
        # sliding classes' "legend"), drawing one layer's swatches with the other's labels
        filled = ColumnDataSource({"x": [], "y": [], "w": [], "h": [], "color": [], "filled_legend": [], "why": []})
        cells = fig.rect(x="x", y="y", width="w", height="h", source=filled, fill_color="color", fill_alpha=1,
                         line_alpha=0, hatch_pattern=".", hatch_color=FILLED_HATCH, hatch_alpha=0.6, hatch_scale=6,
                         legend_field="filled_legend")
        fig.add_tools(HoverTool(renderers=[cells], tooltips=[("not computed", "@why")]))
        points = ColumnDataSource({"x": [], "y": []})
        fig.scatter(x="x", y="y", source=points, marker="circle", size=3, color="#000000", alpha=0.6,
                    legend_label="computed points (click: show / hide)", visible=False)
        return filled, points

    def update_adaptive(self, computed: np.ndarray, cls: np.ndarray, level: np.ndarray | None,
                        which: str = "verdict") -> None:
        """The adaptive layers of the slice: `computed` (the level, -1 where not computed), the filled verdict class
        `cls` and the level of the cell it came from (`level`; None: not known), all of the slice's shape; `which`:
        the verdict's name in the hover ("verdict": the Rayleigh branch's, or "sliding verdict")."""
        if self.filled is None:
            return
        c, v = np.asarray(computed).ravel(), np.asarray(cls).ravel()
        lv = np.full(c.shape, -1) if level is None else np.asarray(level).ravel()
        hit = np.flatnonzero(c < 0)
        names = np.array([FILLED_CLASSES.get(int(k), FILLED_CLASSES[-1])[0] for k in range(-1, 3)], dtype=object)
        colors = np.array([FILLED_CLASSES.get(int(k), FILLED_CLASSES[-1])[1] for k in range(-1, 3)], dtype=object)
        k = (np.clip(v[hit], -1, 2) + 1).astype(int)  # slice2d gives floats
        prefix = "sliding " if which.startswith("sliding") else ""
        why = np.array([f"{which} {names[i]} from its cell (level {int(L)})" if L >= 0 else
                        f"{which} {names[i]} from its cell" for i, L in zip(k, lv[hit], strict=True)], dtype=object)
        self.filled.data = {**{key: val[hit] for key, val in self._cell_geometry.items()}, "color": colors[k],
                            "filled_legend": np.array([f"not computed: {prefix}{n} (from its cell)" for n in names],
                                               dtype=object)[k], "why": why}
        done = np.flatnonzero(c >= 0)
        self.computed_points.data = {"x": self._cell_geometry["x"][done], "y": self._cell_geometry["y"][done]}

    def update(self, x: np.ndarray, y: np.ndarray, g: np.ndarray, why: np.ndarray | None,
               boundary: Boundary | None) -> None:
        """Draw the slice g[y, x] (plotted coordinates), hatch the cells whose `why` (the short reason of an
        undetermined verdict, same shape as g; "" elsewhere) is set, and draw the γ boundary's slice (or none).
        Legend entries of what the slice does not have are hidden. In an adaptive atlas g is NaN where a point was
        not computed: the neutral curve is then drawn from the computed cells only (contourpy skips every cell with
        a NaN corner, so no line is guessed across a gap)."""
        if self.regular:
            self.cells.data.update(image=[g])
        else:
            self.cells.data.update(growth=g.ravel())
        lines = neutral_lines(x, y, g)
        self.contour.data = {"xs": [line[:, 0] for line in lines], "ys": [line[:, 1] for line in lines]}
        flat = np.asarray(why).ravel() if why is not None else np.empty(0, dtype=str)
        hit = np.flatnonzero(flat != "") if flat.size else np.empty(0, dtype=int)
        self.undetermined.data = {**{k: v[hit] for k, v in self._cell_geometry.items()}, "why": flat[hit]}
        b = boundary or Boundary()
        for direction, source in self.thresholds.items():
            source.data = {"xs": [p[0] for p in b.lines.get(direction, [])],
                           "ys": [p[1] for p in b.lines.get(direction, [])]}
        self.refused.data = {"x": b.refused[0], "y": b.refused[1], "why": b.refused[2]}
        self._legend_visibility()

    def update_sliding_thresholds(self, boundary: Boundary | None) -> None:
        """Draw the slice of the threshold of sliding in γ (every branch; both directions, certified crossings), or
        none."""
        lines = [] if boundary is None else [p for runs in boundary.lines.values() for p in runs]
        self.sliding_thresholds.data = {"xs": [p[0] for p in lines], "ys": [p[1] for p in lines]}
        self._legend_visibility()

    def _legend_visibility(self) -> None:
        """Legend entries of what the slice does not have are hidden."""
        for item in self.figure.legend[0].items:
            source = item.renderers[0].data_source
            item.visible = (bool(len(next(iter(source.data.values()), []))) or source is self.contour
                            or source is self.computed_points)


@dataclass
class Boundary:
    """The slice of an atlas's boundary in γ, in plotted coordinates: the certified thresholds as polylines by
    direction (+1 destabilising, -1 stabilising as γ grows; {direction: [(x, y), ...]}) and the refused sign changes
    as points (x, y, why)."""

    lines: dict[int, list[tuple[np.ndarray, np.ndarray]]] = field(default_factory=dict)
    refused: tuple[np.ndarray, np.ndarray, np.ndarray] = (np.empty(0), np.empty(0), np.empty(0, dtype=str))


def _runs(values: np.ndarray, along: np.ndarray, keep: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The polylines (values[i], along[i]) over the runs of consecutive indices where `keep` holds (a point alone is
    a run too: drawn as a dot-sized segment by its neighbours' absence, so it is still seen on hover)."""
    out = []
    idx = np.flatnonzero(keep)
    if not idx.size:
        return out
    for run in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1):
        out.append((values[run], along[run]))
    return out


def adaptive_readout(d: Atlas) -> str:
    """The readout line of an adaptive atlas: the evaluated fraction overall and per level, margin and guard (or
    that its sweep has not finished)."""
    a = d.adaptive
    if not a.get("evaluated"):
        return ("**Adaptive atlas, not finished**: its values are written when the sweep ends; run the same "
                "`asymslide sweep --adaptive` command again to resume it")
    levels = "; ".join(f"level {lv['level']} (stride {lv['stride']}) {100 * lv['fraction_of_grid']:.2f} %"
                       for lv in a.get("per_level", []))
    return (f"**Adaptive** (asymslide sweep --adaptive): computed {a['evaluated']} of {a['points']} points, "
            f"evaluated fraction **{100 * a['evaluated_fraction']:.1f} %** ({levels}; {refinement_text(a)}); the "
            "other points are not computed: their verdict class comes from their cell (pale, dotted), their growth is "
            "not stored"
            + ("" if a.get("guard") else "; a single point of another class inside a cell is not seen (`--guard` "
               "looks closer)"))


def verdict_coverage(verdict: np.ndarray, reason: np.ndarray) -> str:
    """The readout line of an atlas's verdicts (the counts of ``asymslide info``: summary.verdict_coverage): how many
    points are certified stable or unstable, and why the others are undetermined."""
    c = summary.verdict_coverage(verdict, reason)
    why = ", ".join(f"{short_reason(code, model.VERDICT_STATUS)} {k}" for code, k in c.undetermined.items())
    share = f"{100 * c.certified / max(c.computed, 1):.1f} %"
    return (f"**Verdict of the Rayleigh branch** certified (stable or unstable) at {c.certified} of "
            f"{c.computed} points ({share})" + (f"; undetermined (hatched): {why}" if why else ""))


def crossing_coverage(reason: np.ndarray, which: str = "Thresholds in γ") -> str:
    """The readout line of an atlas's boundary in γ: certified thresholds and refused sign changes by reason."""
    r = np.asarray(reason)
    points = r.reshape(-1, r.shape[-1])
    certified = int(np.isin(r, model.CERTIFIED_CROSSINGS).sum())
    complete = int(np.all((points < 0) | np.isin(points, model.CERTIFIED_CROSSINGS), axis=1).sum())
    refused = ", ".join(f"{REFUSED_CROSSING.get(int(code), f'reason {int(code)}')} {int((r == code).sum())}"
                        for code in np.unique(r[(r >= 0) & ~np.isin(r, model.CERTIFIED_CROSSINGS)]))
    return (f"**{which}** {certified} certified crossing(s); every sign change certified at {complete} of "
            f"{points.shape[0]} points of the other axes" + (f"; refused (×, not thresholds): {refused}" if refused
                                                             else ""))


def _uniform(t: np.ndarray) -> bool:
    return t.size < 3 or bool(np.allclose(np.diff(t), (t[-1] - t[0]) / (t.size - 1), rtol=1e-6))


def _edges(t: np.ndarray) -> np.ndarray:
    """Cell edges around the grid values (midpoints; half a step beyond the ends)."""
    if t.size == 1:
        return np.array([t[0] - 0.5, t[0] + 0.5])
    mid = (t[:-1] + t[1:]) / 2
    return np.concatenate([[t[0] - (mid[0] - t[0])], mid, [t[-1] + (t[-1] - mid[-1])]])


# ------------------------------------------------------------------------------------------------
# the scene
# ------------------------------------------------------------------------------------------------


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


class AtlasScene(pn.viewable.Viewer):
    """Heat map of a slice of an atlas, sliders over the other axes, the 3-D neutral surface, and the readout.

    The state (which atlas, the two axes of the heat map, the grid index of every other axis, the three axes of the
    3-D view) is set in one update when an atlas opens, and the selects show it: they are the scene's own widgets
    (not ``from_param``), so a select never picks a value by itself while its options change (it did, half-way
    through opening the default atlas, and drew a slice with x = y). The y select never offers the x axis; choosing
    the y axis as x swaps the two."""

    params = param.ClassSelector(class_=SpectrumParams, doc="the shared parameters a click sets")
    atlas = param.String(default=None, allow_None=True, label="Atlas")
    x_axis = param.String(default=None, allow_None=True, label="x axis")
    y_axis = param.String(default=None, allow_None=True, label="y axis")
    surface_axes = param.List(default=[], item_type=str, label="3-D axes (three)")
    #: grid index of every axis (those of the image are ignored); the sliders set it
    indices = param.Dict(default={}, precedence=-1)
    #: the loaded atlas (None until one is ready)
    data = param.ClassSelector(class_=Atlas, allow_None=True, precedence=-1)
    message = param.String(default="", precedence=-1)
    #: True while the 3-D view is shown (it is computed only then)
    surface_shown = param.Boolean(default=False, precedence=-1)
    #: what the heat map is coloured by, in an atlas swept with --sliding (app.sliding_map's SLIDING, RAYLEIGH)
    verdict = param.Selector(default=slm.SLIDING, objects=[slm.SLIDING, slm.RAYLEIGH], label="Colour by")

    def __init__(self, **kwargs):
        requested = kwargs.pop("requested", None)
        if "params" not in kwargs:
            kwargs["params"] = SpectrumParams()
        super().__init__(**kwargs)
        if isinstance(requested, dict):
            requested = AtlasRequest(**requested)
        self._requested = requested if isinstance(requested, AtlasRequest) else AtlasRequest(name=requested)
        self.phases = {kind: (pn.pane.Markdown("", sizing_mode="stretch_width", margin=(0, 10)),
                              pn.indicators.Progress(value=0, max=100, bar_color="primary",
                                                     sizing_mode="stretch_width", height=18))
                       for kind in PHASES}
        self.progress = pn.Column(*(w for pair in self.phases.values() for w in pair), visible=False,
                                  sizing_mode="stretch_width")
        self.status = pn.pane.Markdown("", sizing_mode="stretch_width")
        self.alert = pn.pane.Alert("", alert_type="warning", visible=False, sizing_mode="stretch_width")
        self.sliders = pn.Column(sizing_mode="stretch_width")
        self.atlas_select = pn.widgets.Select(label="Atlas", options=[], sizing_mode="stretch_width")
        self.x_select = pn.widgets.Select(label="x axis", options={}, sizing_mode="stretch_width")
        self.y_select = pn.widgets.Select(label="y axis", options={}, sizing_mode="stretch_width")
        # a MultiChoice: the order of the picks is the order of the 3-D view's axes (and of the URL's surface=). Its
        # Choices.js box logs "Deprecation warning: allowHTML will default to false" in the console: Bokeh creates it
        # without that option (bokeh-widgets.js, MultiChoiceView.render) and the model has no property to pass it
        # (tests/browser/test_phone_layout.py ALLOWED_CONSOLE).
        self.surface_select = pn.widgets.MultiChoice(label="3-D axes (three)", options={}, max_items=3,
                                                     sizing_mode="stretch_width", max_width=400)
        self._syncing = False
        self.atlas_select.param.watch(lambda e: self._from_widget("atlas", e.new), "value")
        self.x_select.param.watch(lambda e: self._from_widget("x", e.new), "value")
        self.y_select.param.watch(lambda e: self._from_widget("y", e.new), "value")
        self.surface_select.param.watch(lambda e: self._from_widget("surface", e.new), "value")
        #: the default atlas's computation this session shows (app.jobs; the job is shared by the sessions)
        self.computation = jobs.Follower(self._show_default)
        self._surface_key: tuple | None = None
        # the figure of the current atlas and axes (a new one per pair: Panel cannot show a Bokeh figure again once
        # it has left the page, its stylesheets raise a TypeError and the pane keeps the old figure)
        self._figure: HeatMap | None = None
        self.image_pane = pn.pane.Bokeh(None, sizing_mode="stretch_width", height=HEIGHT)
        self.param.watch(self._show_heat_map, ["data", "x_axis", "y_axis"])
        self.param.watch(self._slice_changed, ["indices", "verdict"])
        self.verdict_select = pn.widgets.RadioButtonGroup.from_param(self.param.verdict, color="light", visible=False)
        self.param.watch(lambda e: setattr(self.verdict_select, "visible", bool(e.new is not None
                                                                                and e.new.has_sliding)), "data")
        self.surface_pane = pn.pane.Plotly(None, sizing_mode="scale_width", aspect_ratio=SURFACE_ASPECT,
                                           min_height=SURFACE_MIN_HEIGHT, max_height=SURFACE_MAX_HEIGHT,
                                           config=dict(SURFACE_CONFIG))
        self.param.watch(self._atlas_changed, "atlas")
        self.param.watch(self._axes_changed, ["x_axis", "y_axis"])
        self.param.watch(self._sync_widgets, ["atlas", "data", "x_axis", "y_axis", "surface_axes"])
        self.param.watch(self._update_surface, ["data", "surface_axes", "indices", "surface_shown"])
        self.param.watch(lambda e: self._show(e.new), "message")

    def url_state(self) -> dict[str, object]:
        """What a URL needs to show this view again (app.urlstate.atlas_query): the atlas, the two axes, the other
        axes' grid values and the 3-D axes; before an atlas is open, what was requested."""
        d = self.data
        if d is None:
            r = self._requested
            return {"name": r.name, "x": r.x, "y": r.y, "at": dict(r.at), "surface": r.surface,
                    "verdict": r.verdict}
        at = {n: float(d.axes[n][self.indices.get(n, 0)]) for n in d.names if n not in (self.x_axis, self.y_axis)}
        return {"name": d.name, "x": self.x_axis, "y": self.y_axis, "at": at, "surface": tuple(self.surface_axes),
                "verdict": self.verdict if d.has_sliding else None}

    # -- which atlas --------------------------------------------------------------------------

    def refresh(self) -> None:
        """Re-list the atlas directory; open the requested atlas, else keep the current one, else the default.

        Not done when the scene is created (a page pays for this tab only when it is shown): :meth:`__panel__`
        does it, and tests call it."""
        names = list_atlases()
        self._names = names
        want = self._requested.name or self.atlas
        if want is not None and want not in names:
            self.message = (f"atlas '{want}' is not in {atlas_dir()} (available: {', '.join(names) or 'none'}): "
                            "showing the default atlas")
            want = None
            self._requested = AtlasRequest()
        if want is None and default_ready():
            want = default_name()
        self._sync_widgets()
        if want is not None and want in names:
            if self.atlas == want and self.data is None:
                self._atlas_changed()
            self.atlas = want

    def start_default(self) -> None:
        """Open the default atlas, or follow its computation (shared by the sessions of this process) with a labelled
        progress bar per phase, and open it when it is done (called when the tab is shown; without a server,
        :meth:`wait` waits for it)."""
        if self.data is not None or (self.atlas is not None and self.atlas != default_name()):
            return
        if default_ready():
            self.refresh()
            return
        self.progress.visible = True
        self.computation.follow(ensure_default())

    def wait(self, timeout: float | None = None) -> None:
        """Block until the default atlas being computed (if any) is done, and open it when not served (tests,
        scripts)."""
        self.computation.wait(timeout)

    def _show_default(self, _job: jobs.Job, state: jobs.JobState) -> None:
        """Show the default atlas's progress, one labelled bar per phase; open it when it is done (on the session's
        event loop; a failed computation is started again only when the tab is shown again)."""
        for kind, (label, bar) in self.phases.items():
            total, done = state.totals.get(kind, 0), min(state.done.get(kind, 0), state.totals.get(kind, 0))
            bar.value = int(100 * done / total) if total else 0
            label.object = f"{PHASES[kind]}: {done} of {total} grid points" if total else ""
            bar.visible = label.visible = bool(total)
        if state.status == jobs.FAILED:
            self.status.object = f"**Default atlas failed**: {state.error}"
        elif state.status == jobs.RUNNING:
            self.status.object = (f"**Computing the default atlas** (once; stored in {atlas_dir()}; about half a "
                                  "minute on two cores), in two phases:")
            return
        self.progress.visible = False
        if state.status == jobs.DONE:
            self.status.object = ""
            self.refresh()

    def _atlas_changed(self, *_events) -> None:
        """Open the atlas and set the whole state at once: its axes (the requested ones, else the current ones if it
        has them, else its first two), the other axes' grid indices and the 3-D axes."""
        if self.atlas is None:
            return
        try:
            data = load(self.atlas)
        except (OSError, ValueError, KeyError) as exc:
            self.message = f"atlas '{self.atlas}' could not be read: {exc}"
            return
        request, self._requested = self._requested, AtlasRequest()
        names = data.names
        notes: list[str] = []
        clamped: list[str] = []
        x, y = request.x or self.x_axis, request.y or self.y_axis
        for which, axis in (("x", request.x), ("y", request.y)):
            if axis is not None and axis not in names:
                notes.append(f"{which} axis {axis} is not an axis of atlas {data.name}")
        x, y = self._two_axes(names, x, y)
        indices = self._requested_indices(data, request.at, notes, clamped)
        surface = [n for n in request.surface if n in names]
        if len(set(surface)) != 3:
            if request.surface:
                notes.append(f"the 3-D view needs three axes of atlas {data.name}")
            surface = names[:3] if len(names) >= 3 else []
        verdict = request.verdict or self.verdict
        with param.parameterized.batch_call_watchers(self):
            self.param.update(data=data, x_axis=x, y_axis=y, surface_axes=surface, indices=indices, verdict=verdict)
        self._rebuild_sliders()
        said = (["; ".join(notes) + " (left as they were)"] if notes else []) + clamped
        if said:
            self.message = "From the URL: " + "; ".join(said) + "."

    @staticmethod
    def _requested_indices(data: Atlas, at: dict[str, float], notes: list[str], clamped: list[str]) -> dict[str, int]:
        """The grid index of every axis: the requested values (`at`, from the URL) snapped to the grid, the others
        mid-way. Axes the atlas lacks go into `notes`; values beyond an axis's ends into `clamped` (said, as the
        sliders' clamps are)."""
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

    @staticmethod
    def _two_axes(names: list[str], x: str | None, y: str | None) -> tuple[str, str | None]:
        """Two different axes of `names` for the heat map (x, y), keeping the given ones where they fit; y is None
        for a 1-axis atlas."""
        if len(names) == 1:
            return names[0], None
        x = x if x in names else names[0]
        y = y if y in names and y != x else next(n for n in names if n != x)
        return x, y

    def _from_widget(self, which: str, value) -> None:
        """A select changed by the user: set the state (the y select never offers x; x = y swaps the two)."""
        if self._syncing:
            return
        if which == "atlas":
            if value is not None and value != self.atlas:
                self.atlas = value
        elif which == "surface":
            self.surface_axes = list(value)
        elif self.data is not None and value is not None:
            x, y = (value, self.y_axis) if which == "x" else (self.x_axis, value)
            if x == y:  # x chosen as the y axis: swap
                y = self.x_axis
            x, y = self._two_axes(self.data.names, x, y)
            with frozen_document():
                self.param.update(x_axis=x, y_axis=y)

    def _sync_widgets(self, *_events) -> None:
        """Show the state in the selects (options and value in one update each; their watchers ignore it)."""
        d = self.data
        labels = {d.label(n) + (" (log)" if d.log[n] else ""): n for n in d.names} if d is not None else {}
        names = getattr(self, "_names", [])
        self._syncing = True
        try:
            # readable labels, file names as values (the URL's atlas=NAME)
            self.atlas_select.param.update(options={display_name(n): n for n in names},
                                           value=self.atlas if self.atlas in names else None)
            self.x_select.param.update(options=labels, value=self.x_axis if self.x_axis in labels.values() else None,
                                       disabled=len(labels) < 2)
            others = {k: v for k, v in labels.items() if v != self.x_axis}
            self.y_select.param.update(options=others, value=self.y_axis if self.y_axis in others.values() else None,
                                       disabled=len(others) < 2)
            surface = [n for n in self.surface_axes if n in labels.values()]
            self.surface_select.param.update(options=labels, value=surface)
        finally:
            self._syncing = False

    def _axes_changed(self, *_events: param.parameterized.Event) -> None:
        self._rebuild_sliders()

    def _rebuild_sliders(self) -> None:
        """A slider per axis off the image, snapping to the grid: an index slider whose label and ticks show the
        grid value (a plain IntSlider: Panel's DiscreteSlider syncs an inner slider and a label on the server,
        which cost more than the heat map's update)."""
        d = self.data
        widgets = []
        if d is not None:
            for name in d.names:
                if name in (self.x_axis, self.y_axis):
                    continue
                labels = json.dumps([f"{v:.4g}" for v in d.axes[name]])
                slider = pn.widgets.IntSlider(label=d.label(name), start=0, end=max(len(d.axes[name]) - 1, 1),
                                              value=self.indices.get(name, 0), disabled=len(d.axes[name]) < 2,
                                              format=CustomJSTickFormatter(code=f"return {labels}[tick] ?? ''"),
                                              sizing_mode="stretch_width")
                # on `value`: the slice follows the handle while it is dragged (it reads the stored cube, no model
                # call: a slice costs a few ms)
                slider.param.watch(lambda e, n=name: self._set_index(n, e.new), "value")
                widgets.append(slider)
        self.sliders.objects = widgets

    def _set_index(self, name: str, index: int) -> None:
        with frozen_document():
            self.indices = {**self.indices, name: int(index)}

    # -- the slice ----------------------------------------------------------------------------

    def slice2d(self, variable: str | None = None):
        """(x, y, growth[y, x]) of the current slice, in display coordinates; read from the cube only. `variable`:
        another of the store's variables over the same axes instead of the growth (read from the store; None if the
        store has none)."""
        d = self.data
        assert d is not None and self.x_axis is not None
        names = d.names
        index = tuple(slice(None) if n in (self.x_axis, self.y_axis) else self.indices.get(n, 0) for n in names)
        held = {None: d.growth, "verdict": d.verdict, "verdict_reason": d.verdict_reason, "computed": d.computed,
                "verdict_filled": d.verdict_filled, "filled_level": d.filled_level, **d.sliding}
        if held.get(variable) is not None:
            cube = held[variable][index]
        elif variable is None:
            return None
        elif variable == "filled_level" or (cube := d.read(variable, index)) is None:
            return None
        values = np.asarray(getattr(cube, "values", cube), dtype=float)
        kept = [n for n in names if n in (self.x_axis, self.y_axis)]
        if self.y_axis is None:
            return d.display(self.x_axis), np.array([0.0]), values[None, :]
        if kept != [self.y_axis, self.x_axis]:
            values = values.T
        return d.display(self.x_axis), d.display(self.y_axis), values

    def undetermined_reasons(self) -> np.ndarray | None:
        """The short reason (model.VERDICT_STATUS) of every undetermined point of the current slice, "" elsewhere
        (same shape as the slice's growth); None for an atlas without verdicts."""
        verdict, reason = self.slice2d("verdict"), self.slice2d("verdict_reason")
        if verdict is None or reason is None:
            return None
        codes = reason[2]
        out = np.full(codes.shape, "", dtype=object)
        for code in np.unique(codes[verdict[2] == UNDETERMINED]):
            out[(verdict[2] == UNDETERMINED) & (codes == code)] = short_reason(code, model.VERDICT_STATUS)
        return out

    def boundary(self, sliding: bool = False) -> Boundary | None:
        """The slice of the atlas's boundary in γ where γ is one of the image axes: every certified crossing as a
        polyline per crossing index and direction, and the refused sign changes (jumps, pole-dense modes) as points.
        An atlas without the crossing variables draws its γ_c (the first certified crossing) with direction 0.
        `sliding`: the threshold of sliding over every branch instead (None where the atlas has none)."""
        d = self.data
        if d is None or "gamma" not in (self.x_axis, self.y_axis) or self.y_axis is None:
            return None
        if sliding and not d.crossings_all:
            return None
        other = self.y_axis if self.x_axis == "gamma" else self.x_axis
        gnames = [n for n in d.names if n != "gamma"]
        index = tuple(slice(None) if n == other else self.indices.get(n, 0) for n in gnames)
        along = d.display(other)

        def shown(gamma: np.ndarray) -> np.ndarray:
            return np.log10(gamma) if d.log["gamma"] else gamma

        def xy(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return (a, b) if self.x_axis == "gamma" else (b, a)

        out = Boundary()
        if not sliding and not d.crossings:
            if d.gamma_c is None:
                return None
            gc = np.asarray(d.gamma_c[index], dtype=float)
            out.lines[0] = [xy(*run) for run in _runs(shown(gc), along, np.isfinite(gc))]
            return out
        c = {k: np.asarray(v[index]) for k, v in (d.crossings_all if sliding else d.crossings).items()}
        for k in range(c["gamma_c_crossing"].shape[-1]):
            value, direction = c["gamma_c_crossing"][:, k].astype(float), c["gamma_c_direction"][:, k]
            for sign in (1, -1):
                runs = _runs(shown(value), along, np.isfinite(value) & (direction == sign))
                out.lines.setdefault(sign, []).extend(xy(*run) for run in runs)
        reason, location = c["gamma_c_crossing_reason"], c["gamma_c_location"].astype(float)
        bad = np.isfinite(location) & (reason >= 0) & ~np.isin(reason, model.CERTIFIED_CROSSINGS)
        rows = np.nonzero(bad)
        px, py = xy(shown(location[bad]), along[rows[0]])
        why = np.array([REFUSED_CROSSING.get(int(r), f"reason {int(r)}") for r in reason[bad]], dtype=object)
        out.refused = (px, py, why)
        return out

    def heat_map(self) -> HeatMap | None:
        """The figure of the current atlas and pair of axes, built when the pair changes; None until an atlas and
        two different axes of it are chosen."""
        d = self.data
        if d is None or self.x_axis not in d.names or self.x_axis == self.y_axis or (
                self.y_axis is not None and self.y_axis not in d.names):
            return None
        heat = self._figure
        if heat is None or heat.atlas is not self.data or (heat.x_axis, heat.y_axis) != (self.x_axis, self.y_axis):
            self._figure = heat = HeatMap(self.data, self.x_axis, self.y_axis, self._on_tap)
        return heat

    def _show_heat_map(self, *_events) -> None:
        """Put the current figure in the pane and draw the current slice into it."""
        heat = self.heat_map()
        if heat is None:
            return
        self._draw(heat)
        if self.image_pane.object is not heat.figure:
            self.image_pane.object = heat.figure

    def colours_sliding(self) -> bool:
        """Whether the heat map shows the sliding verdict over every branch (the atlas has it, and it is chosen)."""
        return self.data is not None and self.data.has_sliding and self.verdict == slm.SLIDING

    def sliding_slice(self) -> dict[str, np.ndarray] | None:
        """The current slice's sliding variables (None: the atlas has none)."""
        if self.data is None or not self.data.has_sliding:
            return None
        out = {}
        for name in self.data.sliding:
            got = self.slice2d(name)
            if got is None:
                return None
            out[name] = got[2]
        return out

    def _draw(self, heat: HeatMap) -> None:
        x, y, g = self.slice2d()
        sliding = self.colours_sliding()
        heat.update(x, y, g, None if sliding else self.undetermined_reasons(), self.boundary())
        plane = f"{self.data.label(self.x_axis)}-{self.data.label(self.y_axis) if self.y_axis else ''}"
        heat.update_sliding(self.sliding_slice() if sliding else None, self.data.sliding_floor, plane)
        heat.update_sliding_thresholds(self.boundary(sliding=True) if sliding else None)
        if self.data.adaptive:
            self._draw_adaptive(heat)

    def _filled_names(self) -> tuple[str, str, str]:
        """The filled verdict shown (variable, its cells' levels, its name): the sliding one where the heat map
        colours it and the atlas refined it, else the Rayleigh branch's."""
        if self.colours_sliding() and "verdict_filled_all" in self.data.sliding:
            return "verdict_filled_all", "filled_level_all", "sliding verdict"
        return "verdict_filled", "filled_level", "verdict"

    def _draw_adaptive(self, heat: HeatMap) -> None:
        """An adaptive atlas's slice: which points were computed, and the filled class (and its cell's level) of
        the others, of the verdict the heat map colours."""
        name, level_name, which = self._filled_names()
        computed, filled = self.slice2d("computed"), self.slice2d(name)
        if computed is None or filled is None:
            return
        level = self.slice2d(level_name)
        heat.update_adaptive(computed[2], filled[2], None if level is None else level[2], which)

    def _slice_changed(self, *_events) -> None:
        heat = self.heat_map()
        if heat is not None and self.image_pane.object is heat.figure:
            with frozen_document():
                self._draw(heat)

    # -- a click sets the shared parameters ----------------------------------------------------

    def cell_parameters(self, x: float, y: float) -> dict[str, float]:
        """All six model parameters at the grid cell nearest the display coordinates (x, y)."""
        d = self.data
        assert d is not None
        values = dict(d.fixed)
        for name in d.names:
            if name == self.x_axis:
                i = int(np.argmin(np.abs(d.display(name) - x)))
            elif name == self.y_axis:
                i = int(np.argmin(np.abs(d.display(name) - y)))
            else:
                i = self.indices.get(name, 0)
            values[name] = float(d.axes[name][i])
        return values

    def _on_tap(self, x: float | None = None, y: float | None = None) -> None:
        if self.data is None or x is None or (y is None and self.y_axis is not None):
            return
        values = self.cell_parameters(x, 0.0 if y is None else y)
        updates: dict[str, float | bool] = {}
        notes = []
        for name, v in values.items():
            if name == "eta":
                if math.isinf(v):
                    updates["eta_infinite"] = True
                    continue
                decl, key, target = SpectrumParams.param.log10_eta, "log10_eta", math.log10(v)
                updates["eta_infinite"] = False
            else:
                decl, key, target = SpectrumParams.param[name], name, v
            lo, hi = decl.bounds
            clamped = min(max(target, lo), hi)
            if clamped != target:
                notes.append(f"{SpectrumParams.symbol(name)} = {v:.4g} is outside the sliders' range: set to the "
                             "nearest end")
            updates[key] = clamped
        with frozen_document():
            self.params.param.update(**updates)
        text = ", ".join(f"{SpectrumParams.symbol(k)} = {'∞' if math.isinf(v) else f'{v:.4g}'}"
                         for k, v in values.items())
        self.message = (f"Parameters set from the atlas cell: {text}." + self._cell_verdicts(x, y)
                        + (" " + "; ".join(notes) if notes else ""))

    def _cell_verdicts(self, x: float, y: float | None) -> str:
        """Both verdicts at the clicked cell, with the fastest mode's family, kH and z (an atlas with sliding)."""
        d = self.data
        if d is None or d.verdict is None:
            return ""
        xs = d.display(self.x_axis)
        ix = int(np.argmin(np.abs(xs - x)))
        iy = int(np.argmin(np.abs(d.display(self.y_axis) - y))) if self.y_axis and y is not None else 0
        v = self.slice2d("verdict")
        if v is None:
            return ""
        words = {0: "stable", 1: "unstable", 2: "undetermined"}

        def not_computed(name: str) -> str:  # an adaptive atlas: the class filled from the point's cell
            filled = self.slice2d(name) if d.adaptive else None
            k = int(filled[2][iy, ix]) if filled is not None else -1
            return f"not computed ({words[k]} from its cell)" if k in words else "not computed"

        rayleigh = int(v[2][iy, ix])
        out = f" Rayleigh branch: {words[rayleigh] if rayleigh in words else not_computed('verdict_filled')}."
        f = self.sliding_slice()
        if f is not None:
            c = {k: val[iy, ix] for k, val in f.items()}
            text = (slm.cell_text(verdict=c["verdict_all"], reason=c["verdict_reason_all"], family=c["family_all"],
                                  growth=c["growth_all"], kH=c["kH_at_max_all"], re_z=c["re_z_at_max_all"],
                                  lower_bound=bool(c.get("lower_bound_all", False)), floor=d.sliding_floor)
                    if int(c["verdict_all"]) >= 0 else not_computed("verdict_filled_all"))
            out += f" Sliding (every branch): {text}."
        return out

    def _show(self, text: str) -> None:
        self.alert.object = text
        self.alert.alert_type = "info" if text.startswith("Parameters set") else "warning"
        self.alert.visible = bool(text)

    # -- 3-D neutral surface ------------------------------------------------------------------

    def surface_figure(self) -> dict | None:
        """A Plotly figure (dict) of the neutral surface growth = 0 over the three chosen axes (the others at the
        sliders' values): a triangle mesh (:func:`neutral_surface`, none through cells with a masked corner) coloured
        by the third axis's value (a colour bar tells the depth a flat colour hid), the masked grid points as grey
        markers, and axes spanning the atlas's grid in the parameters' values (log axes as Plotly log axes). None
        without three axes."""
        d = self.data
        axes = list(self.surface_axes)
        if d is None or len(axes) != 3:
            return None
        names = d.names
        index = tuple(slice(None) if n in axes else self.indices.get(n, 0) for n in names)
        cube = np.asarray(getattr(d.growth[index], "values", d.growth[index]), dtype=float)
        kept = [n for n in names if n in axes]
        cube = np.transpose(cube, [kept.index(n) for n in axes])  # to the chosen order
        # interpolated along the plotted coordinates (log10 on a log axis), as the heat map's neutral curve, then
        # drawn at the parameters' values: a log axis puts them back where they were interpolated
        plotted = [d.display(n) for n in axes]
        vertices, triangles = neutral_surface(*plotted, cube)
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
        others = ", ".join(f"{d.label(n)} = {d.axes[n][self.indices.get(n, 0)]:.4g}" for n in names if n not in axes)
        # the conditions on a second line: one line of title did not fit a phone's width
        title = "Neutral surface (max growth = 0)" + (f"<br>at {others}" if others else "")
        if not len(triangles):
            title += "<br>no sign change of the growth in this cube: no surface"
        scene = {f"{a}axis": _surface_axis(d.label(n), c, log)
                 for a, n, c, log in zip("xyz", axes, plotted, logs, strict=True)}
        return {"data": data, "layout": _surface_layout(title, scene)}

    def surface_key(self) -> tuple | None:
        """What the 3-D view depends on: the atlas, the three axes and the indices of the other axes."""
        d = self.data
        if d is None or len(self.surface_axes) != 3:
            return None
        return (d.name, tuple(self.surface_axes),
                tuple((n, self.indices.get(n, 0)) for n in d.names if n not in self.surface_axes))

    def _update_surface(self, *_events) -> None:
        """Rebuild the 3-D view only when what it shows changed (a slider of one of its own axes does not), after
        the heat map's update has been sent (the figure is the larger message)."""
        drawable = self.data is None or len(self.data.names) >= 3  # else surface_note says why there is no view
        self.surface_pane.visible = self.surface_select.visible = drawable
        key = self.surface_key() if self.surface_shown else self._surface_key
        if key == self._surface_key:
            return
        self._surface_key = key
        doc = pn.state.curdoc
        if doc is not None and doc.session_context is not None:
            doc.add_next_tick_callback(self._send_surface)
        else:
            self._send_surface()

    @param.depends("data")
    def surface_note(self) -> str:
        """Why an atlas of fewer than three axes has no 3-D view (empty otherwise)."""
        d = self.data
        if d is None or len(d.names) >= 3:
            return ""
        axes = ", ".join(d.label(n) for n in d.names)
        return (f"**No 3-D view of atlas {d.name}**: it has {len(d.names)} {'axes' if len(d.names) > 1 else 'axis'} "
                f"({axes}) and the neutral surface needs three. Make an atlas with three or more `--axis` "
                "(`asymslide sweep`), or open one in the Atlas menu.")

    def _send_surface(self) -> None:
        fig = self.surface_figure()
        self.surface_pane.object = None  # replaced, not compared element by element with the previous figure
        self.surface_pane.object = fig

    # -- readout and export --------------------------------------------------------------------

    @param.depends("data", "x_axis", "y_axis", "indices")
    def slice_readout(self) -> str:
        """The current slice: how much of it is unstable or masked."""
        if self.data is None or self.x_axis is None:
            return ""
        _, _, g = self.slice2d()
        finite = np.isfinite(g)
        n_nan = int((~finite).sum())
        largest = fmt(float(np.max(g[finite])) if finite.any() else math.nan)
        if self.data.adaptive:
            filled = self.slice2d("verdict_filled")
            return (self._adaptive_slice_readout(g, largest)
                    + ("" if filled is None else self._sliding_slice_readout(filled[2])))
        verdict = self.slice2d("verdict")
        if verdict is None:
            unstable = int((g[finite] > MARGINAL).sum())
            return (f"**This slice** (Rayleigh branch) {unstable} of {int(finite.sum())} points unstable (growth > "
                    f"{MARGINAL:g}); "
                    f"largest growth {largest}; not computable (dark grey) {n_nan}")
        v = verdict[2]
        text = (f"**This slice** ({v.size} points, Rayleigh branch) unstable {int((v == 1).sum())}, stable "
                f"{int((v == 0).sum())}, "
                f"undetermined{'' if self.colours_sliding() else ' (hatched)'} {int((v == UNDETERMINED).sum())}; "
                f"largest growth {largest}; not computable{'' if self.colours_sliding() else ' (dark grey)'} {n_nan}")
        return text + self._sliding_slice_readout(v)

    def _sliding_slice_readout(self, rayleigh: np.ndarray) -> str:
        """The slice's sliding verdict over every branch (an atlas swept with --sliding), or that it has none."""
        if self.data is None or not self.data.has_sliding:
            return "\n\nThe atlas holds the Rayleigh branch only (sweep with `--sliding` for every branch)"
        f = self.sliding_slice()
        if f is None:
            return ""
        s = f.get("verdict_filled_all", f["verdict_all"])  # an adaptive atlas: filled where not computed
        families = slm.family_counts(f["verdict_all"], f["family_all"])
        filled = (f" ({int((f['verdict_all'] >= 0).sum())} computed, the others filled from their cell)"
                  if "verdict_filled_all" in f else "")
        return (f"\n\n**This slice, sliding (every branch)**{filled} unstable {int((s == 1).sum())}, stable "
                f"{int((s == 0).sum())}, undetermined {int((s == UNDETERMINED).sum())}, not computed "
                f"{int((s < 0).sum())}; Rayleigh-branch stable but sliding unstable "
                f"{int(((rayleigh == 0) & (s == 1)).sum())}" + (f" (fastest: {families})" if families else ""))

    def _adaptive_slice_readout(self, g: np.ndarray, largest: str) -> str:
        """The slice of an adaptive atlas: the verdict classes (filled where not computed), how many points were
        computed, and the not computable ones among those."""
        computed, filled = self.slice2d("computed"), self.slice2d("verdict_filled")
        if computed is None or filled is None:
            return "**This slice**: the adaptive atlas's computed mask cannot be read"
        c, v = computed[2] >= 0, filled[2]
        return (f"**This slice** ({v.size} points, Rayleigh branch) unstable {int((v == 1).sum())}, stable "
                f"{int((v == 0).sum())}, "
                f"undetermined {int((v == UNDETERMINED).sum())}; computed {int(c.sum())} "
                f"({100 * c.sum() / max(v.size, 1):.0f} %), the others filled from their cell (pale, dotted); "
                f"largest computed growth {largest}; not computable (dark grey) {int((c & ~np.isfinite(g)).sum())}")

    @param.depends("data")
    def readout(self) -> str:
        d = self.data
        if d is None:
            return "**No atlas loaded yet.**"
        a = d.attrs
        shown = display_name(d.name)
        sizes = ", ".join(f"{d.label(n)}: {v.size}" for n, v in d.axes.items())
        lines = [f"**Atlas** {shown}" + (f" (file {d.name}.zarr)" if shown != d.name else "") + f" ({sizes} points)",
                 "**Fixed** " + ", ".join(f"{d.label(k)} = {'∞' if math.isinf(v) else fmt(v)}"
                                           for k, v in d.fixed.items()),
                 f"**Computed** by asymslide {a.get('asymslide_version')} (git {a.get('git_revision')}) on "
                 f"{a.get('created')}; kH grid {a.get('kH_grid')}; rtol {a.get('rtol')}"]
        masked = int(np.sum(~np.isfinite(np.asarray(d.growth)))) if isinstance(d.growth, np.ndarray) else None
        if d.adaptive:
            lines.append(adaptive_readout(d))
            computed = np.asarray(d.computed) >= 0 if d.computed is not None else None
            masked = (int(np.sum(computed & ~np.isfinite(np.asarray(d.growth))))
                      if computed is not None and isinstance(d.growth, np.ndarray) else None)
        if masked is not None:
            lines.append(f"**Not computable** {masked} point(s) of the atlas (dark grey): {NOT_COMPUTABLE}"
                         if masked else "**Not computable** none")
        if isinstance(d.verdict, np.ndarray):
            lines.append(verdict_coverage(d.verdict, d.verdict_reason))
        if d.has_sliding:
            lo, hi = d.sliding_kH
            s = np.asarray(d.sliding.get("verdict_filled_all", d.sliding["verdict_all"]))
            how = (" (adaptive: refined on both verdicts, classes filled from their cells where not computed)"
                   if "verdict_filled_all" in d.sliding else "")
            lines.append(f"**Sliding (every branch)** Im z ≥ {d.sliding_floor:g}, kH {lo:g} to {hi:g}{how}: unstable "
                         f"{int((s == 1).sum())}, stable {int((s == 0).sum())}, undetermined {int((s == 2).sum())}, "
                         f"not computed {int((s < 0).sum())} of {s.size} points")
        else:
            lines.append("**Rayleigh branch only**: this atlas has no sliding verdict over every branch")
        if d.crossings:
            which = "Thresholds in γ (Rayleigh branch)" if d.crossings_all else "Thresholds in γ"
            lines.append(crossing_coverage(d.crossings["gamma_c_crossing_reason"], which))
        if d.crossings_all:
            lines.append(crossing_coverage(d.crossings_all["gamma_c_crossing_reason"],
                                           "Thresholds of sliding in γ (every branch; dash-dotted, purple)"))
        elif d.gamma_c_reason is not None:
            r = np.asarray(d.gamma_c_reason)
            lines.append(f"**γ_c** found at {int((r == 0).sum())} of {r.size} points of the other axes")
        return "\n\n".join(lines)

    @param.depends("data", "verdict")
    def help_text(self) -> str:
        """The heat map's legend, for what it is coloured by."""
        colours = (slm.SLIDING_LEGEND.replace('switch "Colour by"', 'switch "sliding / Rayleigh branch" (left)')
                   + "; where γ is an axis, the certified thresholds γ_c of the Rayleigh branch (green: unstable "
                   "above, orange: stable above)"
                   + (" and of sliding over every branch (purple, dash-dotted)" if self.data.crossings_all else "")
                   + "." if self.colours_sliding() else COLOURS)
        return (f"{colours} Sliders snap to the atlas grid; click a cell to set the other tabs' parameters (and read "
                f"its verdicts). Atlases are read from `{atlas_dir()}`; make your own with "
                "`asymslide sweep ... --out DIR/NAME.zarr` (`--sliding`: also the sliding verdict over every branch).")

    def slice_description(self) -> str:
        """The current slice in words: the atlas, the two axes, the other axes' values and the fixed ones."""
        d = self.data
        if d is None or self.x_axis is None:
            return "none loaded"
        at = [f"{n} = {float(d.axes[n][self.indices.get(n, 0)])!r}" for n in d.names
              if n not in (self.x_axis, self.y_axis)]
        fixed = [f"{k} = {float(v)!r}" for k, v in d.fixed.items()]
        return (f"atlas {d.name}, x = {self.x_axis}, y = {self.y_axis}" + (f"; at {', '.join(at)}" if at else "")
                + (f"; fixed {', '.join(fixed)}" if fixed else "") + f"; kH grid {d.attrs.get('kH_grid')}")

    def csv(self) -> io.StringIO:
        """The current slice as CSV: both axes (physical values), the max growth, the kH of the maximum and the
        masked kH grid points, as stored (NaN growth: not computable, see the readout)."""
        d = self.data
        if d is None or self.x_axis is None:
            return csv_table("asymslide atlas slice (none loaded)", {"x": [], "y": [], "max_growth": []})
        _, _, g = self.slice2d()
        xs, ys = d.axes[self.x_axis], (d.axes[self.y_axis] if self.y_axis else np.array([math.nan]))
        columns = {self.x_axis: np.tile(xs, ys.size), str(self.y_axis): np.repeat(ys, xs.size), "max_growth": g.ravel()}
        for name, column in (("kH_at_max", "kH_at_max"), ("n_masked", "n_masked_kH"), ("verdict", "verdict"),
                             ("verdict_reason", "verdict_reason"), ("computed", "computed_level"),
                             ("verdict_filled", "verdict_filled"),
                             *((n, n) for n in (d.sliding if d.has_sliding else ()))):
            extra = self.slice2d(variable=name)
            if extra is not None:
                columns[column] = extra[2].ravel()
        codes = "; ".join(f"{k} " + (model.VERDICT_STATUS[k].split(":")[0] if model.VERDICT_STATUS[k].startswith(
            ("stable", "unstable")) else f"undetermined, {short_reason(k, model.VERDICT_STATUS)}")
                          for k in model.VERDICT_STATUS)
        adaptive = (" Adaptive atlas: computed_level is the refinement level at which a point was computed (-1: not "
                    "computed, its max_growth NaN and verdict -1); verdict_filled is the verdict class at every point "
                    "(where not computed: from the computed cell around it)." if d.adaptive else "")
        return csv_table(f"asymslide atlas slice: {self.slice_description()}. {NAN_ROWS}. verdict: 0 stable, 1 "
                         f"unstable, 2 undetermined; verdict_reason: {codes} (docs/physics.md §9).{adaptive}", columns)

    # -- layout -------------------------------------------------------------------------------

    def __panel__(self) -> pn.viewable.Viewable:
        """The tab (built when first shown): opens the requested or default atlas, computing the default atlas
        in the background if it is not there yet."""
        self.refresh()
        self.start_default()
        # the readouts that change with a slider have a fixed size: a div that grows would make the browser lay
        # out the page again (and resize the 3-D plot), which cost more than the heat map's own update
        choose = pn.Column(
            self.atlas_select, self.x_select, self.y_select, self.verdict_select,
            heading("Other axes"), self.sliders,
            # a fixed height (a slice change does not move the panes below); longer readouts (both verdicts of an
            # adaptive atlas) scroll inside it instead of running over the next pane
            pn.pane.Markdown(self.slice_readout, sizing_mode="stretch_width", height=190,
                             styles={"overflow-y": "auto"}),
            pn.pane.Markdown(self.readout, sizing_mode="stretch_width"),
            width=340,
        )
        help_text = pn.pane.Markdown(self.help_text, sizing_mode="stretch_width")
        self._show_heat_map()
        heat = pn.Column(self.image_pane,
                         pn.widgets.FileDownload(callback=self.csv, filename="atlas_slice.csv",
                                                 label="Download slice (CSV)", color="primary", width=200),
                         sizing_mode="stretch_width")
        surface = pn.Column(
            pn.pane.Markdown(self.surface_note, sizing_mode="stretch_width"),
            self.surface_select,
            pn.pane.Markdown("The surface where the max growth is 0 over three axes of the atlas, the others at the "
                             "sliders' values (none is drawn through cells with a not computable corner); drag to "
                             "rotate, scroll to zoom.", sizing_mode="stretch_width"),
            self.surface_pane, sizing_mode="stretch_width")
        # the 3-D view in its own tab: rendered (and recomputed) only while shown, so a slice change repaints the
        # heat map alone
        views = pn.Tabs(("Heat map", heat), ("3-D neutral surface", surface), dynamic=True,
                        sizing_mode="stretch_width")
        views.param.watch(lambda e: setattr(self, "surface_shown", e.new == 1), "active")
        plots = pn.Column(self.alert, self.status, self.progress, help_text, views, sizing_mode="stretch_width")
        return scene_layout(choose, plots, "Atlas")
