"""The Stability map refined where its verdict changes: the cells the neutral curve crosses, at finer levels.

The map's base grid has n cells per axis, each drawn with the value at its centre (:meth:`Axis.values`). Level l
splits every cell of level l - 1 into 2 x 2, so the finest level L has N = n · 2^L cells per axis, and the cells of
every level nest (in the axis' own scale: log10 of a log axis). A cell of level l is **evaluated** (the model is
called at its centre) when it lies in a cell not yet evaluated at level l in which a finest cell is stable and an
edge neighbour unstable, or the reverse (the rule of the adaptive atlas engine, ``asymslide.atlas.adaptive``, on cell
centres: a cell is refined where the verdict changes across it; stable includes marginal, |growth| <= MARGINAL; a
cell that is not computable, NaN, flags nothing: it is not a side of the neutral curve, and refining the speckles of
NaN at small γ on η-γ would cost more than the whole map). The rule is applied in rounds until no such cell is left,
so the refinement follows the curve out of the cells first flagged (``follow`` in the engine); on the finest level
a stable and an unstable neighbour are both evaluated at level L.

Every finest cell shows the value at its **owner**: the centre of the finest evaluated cell that contains it (the
cell's own centre where it was evaluated at level L). No value is interpolated: a cell drawn in a colour has that
colour's value at the point its hover names. A centre that lies beyond the axis' range (the half cells at either end
of the base grid) is evaluated at the range's end, and the hover names that point.

Pure NumPy functions of the arrays; the model is called through the `evaluate` callable the caller gives.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .common import MARGINAL

#: the values one evaluation gives, per point
FIELDS = ("growth", "kH_at_max", "n_masked")

Evaluate = Callable[[np.ndarray, np.ndarray], dict[str, np.ndarray]]


@dataclass(frozen=True, eq=False)
class RefinedMap:
    """The map on its finest grid: each cell's value is its owner's (module docstring)."""

    levels: int
    x_edges: np.ndarray  # N + 1
    y_edges: np.ndarray  # N + 1
    level: np.ndarray  # (N, N): the level of each cell's owner
    owner_x: np.ndarray  # (N, N): where the value drawn in the cell was computed
    owner_y: np.ndarray
    growth: np.ndarray
    kH_at_max: np.ndarray
    n_masked: np.ndarray
    #: the points evaluated above level 0, in order: x, y, level and the FIELDS
    points: dict[str, np.ndarray]

    @property
    def size(self) -> int:
        """Cells per axis on the finest grid."""
        return self.level.shape[0]

    def evaluated(self, level: int) -> int:
        """Points evaluated at `level` (level 0: the base grid)."""
        if level == 0:
            return int(round(self.size / 2**self.levels)) ** 2
        return int((self.points["level"] == level).sum())


def transformed(v: np.ndarray, log: bool) -> np.ndarray:
    return np.log10(v) if log else np.asarray(v, float)


def untransformed(t: np.ndarray, log: bool) -> np.ndarray:
    return 10.0**t if log else t


def level_centres(base: np.ndarray, log: bool, level: int) -> np.ndarray:
    """The cell centres of `level` along an axis whose base cell centres are `base` (equally spaced in the axis'
    scale): n · 2^level values."""
    t = transformed(base, log)
    h = t[1] - t[0]
    m = 2**level
    k = np.arange(t.size * m)
    return untransformed(t[0] - h / 2 + (k + 0.5) * h / m, log)


def level_edges(base: np.ndarray, log: bool, level: int) -> np.ndarray:
    """The n · 2^level + 1 cell edges of `level` (level 0: the base cells' edges, midpoints in the axis' scale)."""
    t = transformed(base, log)
    h = t[1] - t[0]
    m = 2**level
    return untransformed(t[0] - h / 2 + np.arange(t.size * m + 1) * h / m, log)


def verdict_class(growth: np.ndarray) -> np.ndarray:
    """0 stable or marginal (growth <= MARGINAL), 1 unstable, 2 not computable (NaN)."""
    g = np.asarray(growth, float)
    return np.where(np.isnan(g), 2, np.where(g > MARGINAL, 1, 0)).astype(np.int8)


def _differs(cls: np.ndarray) -> np.ndarray:
    """Cells whose class differs from that of an edge neighbour, stable against unstable (a cell not computable does
    not flag its neighbours: its class is not a side of the neutral curve)."""
    d = np.zeros(cls.shape, bool)
    h = (cls[:, 1:] + cls[:, :-1]) == 1
    v = (cls[1:, :] + cls[:-1, :]) == 1
    d[:, 1:] |= h
    d[:, :-1] |= h
    d[1:, :] |= v
    d[:-1, :] |= v
    return d


def _blocks_any(mask: np.ndarray, b: int) -> np.ndarray:
    """Any over the b x b blocks of `mask`."""
    n = mask.shape[0] // b
    return mask.reshape(n, b, n, b).any(axis=(1, 3))


def targets(level: int, levels: int, owner_level: np.ndarray, cls: np.ndarray) -> np.ndarray:
    """The cells of `level` to evaluate next: (rows, cols) of level-`level` cells not yet evaluated at that level
    in which a finest cell's class differs from an edge neighbour's."""
    b = 2 ** (levels - level)
    flagged = _blocks_any(_differs(cls), b) & _blocks_any(owner_level < level, b)
    return np.nonzero(flagged)


def refine(x: np.ndarray, y: np.ndarray, log_x: bool, log_y: bool, base: dict[str, np.ndarray], levels: int,
           ranges: tuple[tuple[float, float], tuple[float, float]], evaluate: Evaluate,
           check: Callable[[], None] = lambda: None, advance: Callable[[int], None] = lambda _l: None) -> RefinedMap:
    """The map whose base grid (cell centres x, y) holds `base` (FIELDS, (ny, nx)) refined over `levels` levels,
    calling ``evaluate(xs, ys)`` at the centres of the cells to evaluate (clipped to `ranges`, the axes' (lo, hi));
    `check` is called between rounds (a job's cancellation), `advance(level)` after each level."""
    if x.size != y.size:
        raise ValueError(f"a refined map needs a square base grid, not {y.size} x {x.size}")
    b = 2**levels
    rep = np.ones((b, b))
    owner_level = np.zeros((y.size * b, x.size * b), np.int16)
    values = {k: np.kron(np.asarray(base[k], float), rep) for k in FIELDS}
    owner_x = np.kron(np.broadcast_to(x[None, :], (y.size, x.size)), rep)
    owner_y = np.kron(np.broadcast_to(y[:, None], (y.size, x.size)), rep)
    done: list[dict[str, np.ndarray]] = []
    for level in range(1, levels + 1):
        cx = np.clip(level_centres(x, log_x, level), *ranges[0])
        cy = np.clip(level_centres(y, log_y, level), *ranges[1])
        s = 2 ** (levels - level)
        while True:
            check()
            rows, cols = targets(level, levels, owner_level, verdict_class(values["growth"]))
            if rows.size == 0:
                break
            got = evaluate(cx[cols], cy[rows])
            done.append({"x": cx[cols], "y": cy[rows], "level": np.full(rows.size, level),
                         **{k: np.asarray(got[k], float) for k in FIELDS}})
            for i, j, m in zip(rows, cols, range(rows.size), strict=True):
                block = (slice(i * s, (i + 1) * s), slice(j * s, (j + 1) * s))
                owner_level[block] = level
                owner_x[block], owner_y[block] = cx[j], cy[i]
                for k in FIELDS:
                    values[k][block] = got[k][m]
        advance(level)
    points = ({k: np.concatenate([d[k] for d in done]) for k in done[0]} if done else
              {k: np.empty(0) for k in ("x", "y", "level", *FIELDS)})
    return RefinedMap(levels=levels, x_edges=level_edges(x, log_x, levels), y_edges=level_edges(y, log_y, levels),
                      level=owner_level, owner_x=owner_x, owner_y=owner_y, growth=values["growth"],
                      kH_at_max=values["kH_at_max"], n_masked=values["n_masked"], points=points)
