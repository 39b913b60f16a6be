"""The current 2-D slice of an atlas (two axes of the heat map, the other axes at grid indices), read from the stored
cube only -- no model function is called on a slice change: its values, the undetermined cells' reasons, the slice of
the boundary in γ, the sliding verdict's variables, the grid cell under a click, and its readout and CSV.

The scene (AtlasScene) holds the state and draws; a :class:`Slice` is that state's one slice, so what is read is
tested without widgets or a figure."""

from __future__ import annotations

import io
import math
from dataclasses import dataclass, field

import numpy as np

from asymslide import model

from .. import sliding_map as slm
from ..common import MARGINAL
from ..exports import csv_table
from ..plotting import fmt
from .directory import Atlas
from .readout import NAN_ROWS, REFUSED_CROSSING, UNDETERMINED, short_reason


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


@dataclass(frozen=True)
class Slice:
    """The slice of atlas `data` over `x_axis` and `y_axis` (None: a 1-axis atlas), every other axis at its grid
    index in `indices` (0 where missing)."""

    data: Atlas
    x_axis: str
    y_axis: str | None
    indices: dict[str, int]

    def values(self, variable: str | None = None):
        """(x, y, growth[y, x]) of the slice, in display coordinates; read from the cube only. `variable`: another of
        the store's variables over the same axes instead of the growth (read from the store; None if the store has
        none)."""
        d = self.data
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
        """The short reason (model.VERDICT_STATUS) of every undetermined point of the slice, "" elsewhere
        (same shape as the slice's growth); None for an atlas without verdicts."""
        verdict, reason = self.values("verdict"), self.values("verdict_reason")
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
        if "gamma" not in (self.x_axis, self.y_axis) or self.y_axis is None:
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

    def sliding(self) -> dict[str, np.ndarray] | None:
        """The slice's sliding variables (None: the atlas has none)."""
        if not self.data.has_sliding:
            return None
        out = {}
        for name in self.data.sliding:
            got = self.values(name)
            if got is None:
                return None
            out[name] = got[2]
        return out

    def cell_parameters(self, x: float, y: float) -> dict[str, float]:
        """All six model parameters at the grid cell nearest the display coordinates (x, y)."""
        d = self.data
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

    def cell_verdicts(self, x: float, y: float | None) -> str:
        """Both verdicts at the clicked cell, with the fastest mode's family, kH and z (an atlas with sliding)."""
        d = self.data
        if d.verdict is None:
            return ""
        xs = d.display(self.x_axis)
        ix = int(np.argmin(np.abs(xs - x)))
        iy = int(np.argmin(np.abs(d.display(self.y_axis) - y))) if self.y_axis and y is not None else 0
        v = self.values("verdict")
        if v is None:
            return ""
        words = {0: "stable", 1: "unstable", 2: "undetermined"}

        def not_computed(name: str) -> str:  # an adaptive atlas: the class filled from the point's cell
            filled = self.values(name) if d.adaptive else None
            k = int(filled[2][iy, ix]) if filled is not None else -1
            return f"not computed ({words[k]} from its cell)" if k in words else "not computed"

        rayleigh = int(v[2][iy, ix])
        out = f" Rayleigh branch: {words[rayleigh] if rayleigh in words else not_computed('verdict_filled')}."
        f = self.sliding()
        if f is not None:
            c = {k: val[iy, ix] for k, val in f.items()}
            text = (slm.cell_text(verdict=c["verdict_all"], reason=c["verdict_reason_all"], family=c["family_all"],
                                  growth=c["growth_all"], kH=c["kH_at_max_all"], re_z=c["re_z_at_max_all"],
                                  lower_bound=bool(c.get("lower_bound_all", False)), floor=d.sliding_floor)
                    if int(c["verdict_all"]) >= 0 else not_computed("verdict_filled_all"))
            out += f" Sliding (every branch): {text}."
        return out

    def readout(self, colours_sliding: bool) -> str:
        """The slice in words: how much of it is unstable or masked (`colours_sliding`: the heat map shows the
        sliding verdict, so nothing is hatched or dark grey)."""
        _, _, g = self.values()
        finite = np.isfinite(g)
        n_nan = int((~finite).sum())
        largest = fmt(float(np.max(g[finite])) if finite.any() else math.nan)
        if self.data.adaptive:
            filled = self.values("verdict_filled")
            return (self._adaptive_slice_readout(g, largest)
                    + ("" if filled is None else self._sliding_slice_readout(filled[2])))
        verdict = self.values("verdict")
        if verdict is None:
            unstable = int((g[finite] > MARGINAL).sum())
            return (f"**This slice** (Rayleigh branch) {unstable} of {int(finite.sum())} points unstable (growth > "
                    f"{MARGINAL:g}); "
                    f"largest growth {largest}; not computable (dark grey) {n_nan}")
        v = verdict[2]
        text = (f"**This slice** ({v.size} points, Rayleigh branch) unstable {int((v == 1).sum())}, stable "
                f"{int((v == 0).sum())}, "
                f"undetermined{'' if colours_sliding else ' (hatched)'} {int((v == UNDETERMINED).sum())}; "
                f"largest growth {largest}; not computable{'' if colours_sliding else ' (dark grey)'} {n_nan}")
        return text + self._sliding_slice_readout(v)

    def _sliding_slice_readout(self, rayleigh: np.ndarray) -> str:
        """The slice's sliding verdict over every branch (an atlas swept with --sliding), or that it has none."""
        if not self.data.has_sliding:
            return "\n\nThe atlas holds the Rayleigh branch only (sweep with `--sliding` for every branch)"
        f = self.sliding()
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
        computed, filled = self.values("computed"), self.values("verdict_filled")
        if computed is None or filled is None:
            return "**This slice**: the adaptive atlas's computed mask cannot be read"
        c, v = computed[2] >= 0, filled[2]
        return (f"**This slice** ({v.size} points, Rayleigh branch) unstable {int((v == 1).sum())}, stable "
                f"{int((v == 0).sum())}, "
                f"undetermined {int((v == UNDETERMINED).sum())}; computed {int(c.sum())} "
                f"({100 * c.sum() / max(v.size, 1):.0f} %), the others filled from their cell (pale, dotted); "
                f"largest computed growth {largest}; not computable (dark grey) {int((c & ~np.isfinite(g)).sum())}")

    def description(self) -> str:
        """The slice in words: the atlas, the two axes, the other axes' values and the fixed ones."""
        d = self.data
        at = [f"{n} = {float(d.axes[n][self.indices.get(n, 0)])!r}" for n in d.names
              if n not in (self.x_axis, self.y_axis)]
        fixed = [f"{k} = {float(v)!r}" for k, v in d.fixed.items()]
        return (f"atlas {d.name}, x = {self.x_axis}, y = {self.y_axis}" + (f"; at {', '.join(at)}" if at else "")
                + (f"; fixed {', '.join(fixed)}" if fixed else "") + f"; kH grid {d.attrs.get('kH_grid')}")

    def csv(self) -> io.StringIO:
        """The slice as CSV: both axes (physical values), the max growth, the kH of the maximum and the masked kH
        grid points, as stored (NaN growth: not computable, see the readout)."""
        d = self.data
        _, _, g = self.values()
        xs, ys = d.axes[self.x_axis], (d.axes[self.y_axis] if self.y_axis else np.array([math.nan]))
        columns = {self.x_axis: np.tile(xs, ys.size), str(self.y_axis): np.repeat(ys, xs.size), "max_growth": g.ravel()}
        for name, column in (("kH_at_max", "kH_at_max"), ("n_masked", "n_masked_kH"), ("verdict", "verdict"),
                             ("verdict_reason", "verdict_reason"), ("computed", "computed_level"),
                             ("verdict_filled", "verdict_filled"),
                             *((n, n) for n in (d.sliding if d.has_sliding else ()))):
            extra = self.values(variable=name)
            if extra is not None:
                columns[column] = extra[2].ravel()
        codes = "; ".join(f"{k} " + (model.VERDICT_STATUS[k].split(":")[0] if model.VERDICT_STATUS[k].startswith(
            ("stable", "unstable")) else f"undetermined, {short_reason(k, model.VERDICT_STATUS)}")
                          for k in model.VERDICT_STATUS)
        adaptive = (" Adaptive atlas: computed_level is the refinement level at which a point was computed (-1: not "
                    "computed, its max_growth NaN and verdict -1); verdict_filled is the verdict class at every point "
                    "(where not computed: from the computed cell around it)." if d.adaptive else "")
        return csv_table(f"asymslide atlas slice: {self.description()}. {NAN_ROWS}. verdict: 0 stable, 1 "
                         f"unstable, 2 undetermined; verdict_reason: {codes} (docs/physics.md §9).{adaptive}", columns)
