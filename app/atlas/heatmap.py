"""The Atlas tab's heat map: a Bokeh figure of one atlas and pair of axes whose data sources a slice change updates
in place -- the growth, the neutral curve, hatched undetermined cells, the thresholds γ_c and the refused sign
changes, the sliding verdict over every branch, and an adaptive atlas's filled cells -- with its colours, legend,
hover and ticks."""

from __future__ import annotations

import math

import numpy as np
from bokeh.models import CustomJSTickFormatter

from asymslide import model

from .. import sliding_map as slm
from ..common import COLOUR_LEGEND, GROWTH_LABEL, GROWTH_PALETTE, LOG_COORDINATE_TICKS, NAN_COLOR, neutral_lines
from ..plotting import fmt, readable_ticks
from .directory import Atlas, atlas_dir, display_name
from .slicing import Boundary, Slice

#: height of the heat map in px
HEIGHT = 480


#: ticks asked of the heat map's x axis (Bokeh's default, 6, collided on a 390 px wide page, where about 200 px of
#: plot are left between the y axis and the colour bar)
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

    def draw(self, s: Slice, sliding: bool) -> None:
        """Draw the slice `s` (of this figure's atlas and axes), coloured by the sliding verdict over every branch
        (`sliding`) or by the Rayleigh branch's growth."""
        d = s.data
        x, y, g = s.values()
        self.update(x, y, g, None if sliding else s.undetermined_reasons(), s.boundary())
        plane = f"{d.label(s.x_axis)}-{d.label(s.y_axis) if s.y_axis else ''}"
        self.update_sliding(s.sliding() if sliding else None, d.sliding_floor, plane)
        self.update_sliding_thresholds(s.boundary(sliding=True) if sliding else None)
        if d.adaptive:
            self._draw_adaptive(s, sliding)

    def _draw_adaptive(self, s: Slice, sliding: bool) -> None:
        """An adaptive atlas's slice: which points were computed, and the filled class (and its cell's level) of
        the others, of the verdict the heat map colours: the sliding one where it colours it and the atlas refined
        it, else the Rayleigh branch's."""
        if sliding and "verdict_filled_all" in s.data.sliding:
            name, level_name, which = "verdict_filled_all", "filled_level_all", "sliding verdict"
        else:
            name, level_name, which = "verdict_filled", "filled_level", "verdict"
        computed, filled = s.values("computed"), s.values(name)
        if computed is None or filled is None:
            return
        level = s.values(level_name)
        self.update_adaptive(computed[2], filled[2], None if level is None else level[2], which)

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


def help_text(d: Atlas | None, sliding: bool) -> str:
    """The heat map's legend for what it is coloured by (`sliding`: the sliding verdict of atlas `d`), and where
    atlases come from."""
    colours = (slm.SLIDING_LEGEND.replace('switch "Colour by"', 'switch "sliding / Rayleigh branch" (left)')
               + "; where γ is an axis, the certified thresholds γ_c of the Rayleigh branch (green: unstable "
               "above, orange: stable above)"
               + (" and of sliding over every branch (purple, dash-dotted)" if d.crossings_all else "")
               + "." if sliding else COLOURS)
    return (f"{colours} Sliders snap to the atlas grid; click a cell to set the other tabs' parameters (and read "
            f"its verdicts). Atlases are read from `{atlas_dir()}`; make your own with "
            "`asymslide sweep ... --out DIR/NAME.zarr` (`--sliding`: also the sliding verdict over every branch).")


def _uniform(t: np.ndarray) -> bool:
    """Whether the grid values are evenly spaced (then the slice is one image glyph, else a rectangle per cell)."""
    return t.size < 3 or bool(np.allclose(np.diff(t), (t[-1] - t[0]) / (t.size - 1), rtol=1e-6))


def _edges(t: np.ndarray) -> np.ndarray:
    """Cell edges around the grid values (midpoints; half a step beyond the ends)."""
    if t.size == 1:
        return np.array([t[0] - 0.5, t[0] + 0.5])
    mid = (t[:-1] + t[1:]) / 2
    return np.concatenate([[t[0] - (mid[0] - t[0])], mid, [t[-1] + (t[-1] - mid[-1])]])

