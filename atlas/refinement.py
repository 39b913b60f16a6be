"""The refinement of adaptive atlases: which points of the dense grid each level evaluates, and the verdict
filled in between (pure NumPy; :mod:`asymslide.atlas.adaptive` runs it).

The grid is the dense sweep's grid, with axes of m·2^L + 1 points (a single value is m = 0), so that the grids of
stride 2^(L-l), l = 0 .. L, nest. **Level 0** is the coarse grid (stride 2^L), evaluated in full. At **level l**
(stride s = 2^(L-l)) the cells of level l-1 (hyper-cubes of side 2s whose 2^d corners are evaluated) are
*flagged* where their corners differ in verdict class (0 stable / 1 unstable / 2 undetermined: undetermined is a
class of its own); level l evaluates every point of stride s in the flagged cells and, as a **margin**, every point of
stride s within `margin` cells of level l (side s; Chebyshev distance) of them: margin 1 adds the ring of level-l
cells around the flagged cells (margin 2 the ring of level-(l-1) cells). Then, with **follow** (the default), the
level follows the boundary out of the flagged cells: every level-l cell (side s) whose evaluated corners already
differ in class has its other corners evaluated, in rounds, until no such cell is left (:func:`follow_targets`).
A boundary that leaves a flagged cell through a face whose coarse corners agree (it crosses an edge of the coarse
grid twice) is so followed as far as it goes, at the level's resolution, where a margin only looks one ring of cells
further and evaluates that ring all around every flagged cell (docs/design-notes.md, "Following the boundary").
Neither finds a single point of another class inside a cell whose corners agree; the guard below does.
The rounds reach the smallest set closed under that rule whatever order points come in (adding points only adds
cells with differing corners), so a resumed sweep ends where an uninterrupted one does. A cell whose corners agree
is not refined, and its points that are never evaluated take its corners' class. With the optional **guard** a
cell whose corners agree on stable or unstable is flagged too where

    min over its corners |growth|  <=  guard · max over its corners  Σ_i |δ²_i growth| / 8

δ²_i being the second difference of the growth along axis i at the cell's stride (from evaluated certified points;
at the ends of an axis the neighbour's): |δ²_i|/8 estimates how far the growth can leave the multilinear
interpolant of the corners inside the cell, so the guard refines the nearly neutral cells where a sign change
between the corners is not excluded (islands of the other sign smaller than a cell). Its cost is a higher evaluated
fraction (``benchmarks/bench_adaptive.py``).

Which points a level evaluates depends only on the stored values (``growth``, ``verdict``, ``computed``) of the
levels before it and, for the follow rounds, of its own points (whose closure does not depend on their order), so
a killed sweep, run again with the same command, computes only what is missing and ends identical to an
uninterrupted run. The values at evaluated points are computed by :func:`model.growth_chunk` exactly as the dense
sweep computes them (bitwise equal). Variables besides the dense sweep's growth variables
(which stay NaN / fill where not evaluated):

- ``computed``: the level at which the point was evaluated, -1 where it was not;
- ``verdict_filled``: the verdict class at every point: the model's verdict where evaluated, else the common class
  of the corners of the finest evaluated cell (all corners evaluated and of one class) that contains the point.

**The verdict refined** (:attr:`AdaptiveSpec.verdict`): the Rayleigh branch's, or with the sliding verdict over
every branch (``sliding``: the plan computes :func:`asymslide.atlas.tasks.sliding_arrays` at every evaluated point, so
each has both verdicts' variables) the pair of both classes (:func:`refinement_classes`): a cell is refined where
either verdict changes, so both can be filled (``verdict_filled``, ``verdict_filled_all``). The guard reads the
Rayleigh branch's growth (the sliding growth is NaN where stable). Journal entries name their rows (attribute
``rows``), so both kinds of store resume.

The store's attribute ``adaptive`` (JSON) records the levels, the coarse grid, margin, guard, the verdict refined
and the evaluated fraction overall and per level. The plan (:class:`AdaptiveSpec` in it) is part of the store's
identity, as the dense sweep's: another margin, guard, level count or verdict refuses to resume.

Layering: this module imports nothing of the project; :class:`AdaptiveSpec` is part of a plan
(:mod:`asymslide.atlas.plan`), and :func:`refine_targets` and :func:`fill_classes` are pure NumPy functions of the
state arrays.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

#: the coarse grid has about this many points along the longest axis when the levels are not given
COARSE_POINTS = 9
#: the growth variables' chunks hold at most this many points in an adaptive store: a level rewrites every chunk it
#: touches, and larger chunks mean fewer writes (zarr writes cost ~1-5 ms per chunk and variable on this machine)
CHUNK_POINTS = 131072
#: ``computed`` where a point was not evaluated
NOT_COMPUTED = -1
#: the verdicts an adaptive sweep can refine: the Rayleigh branch's (the growth variables), or the sliding verdict
#: over every branch (docs/physics.md §14; the ``*_all`` variables, every evaluated point getting both verdicts and
#: a cell refined where either changes class, so that both filled verdicts hold)
RAYLEIGH, SLIDING = "rayleigh", "sliding"
#: the verdicts an adaptive sweep can refine
VERDICTS = (RAYLEIGH, SLIDING)


@dataclass(frozen=True)
class AdaptiveSpec:
    """An adaptive sweep's refinement: `levels` L (the coarse grid has stride 2^L; None: a coarse grid of about
    :data:`COARSE_POINTS` points along the longest axis), `margin` (the ring of cells of the new level evaluated
    around every flagged cell, in cells), `guard` (0: off; else the factor of the curvature test for nearly
    neutral cells, 1 the estimate itself) and `follow` (each level follows the boundary out of the flagged cells:
    :func:`follow_targets`)."""

    levels: int | None = None
    margin: int = 0
    guard: float = 0.0
    follow: bool = True
    #: the verdict refined: "rayleigh" (the Rayleigh branch's), "sliding" (the sliding verdict over every branch and
    #: the Rayleigh branch's: :data:`VERDICTS`); None: "sliding" if the plan computes the sliding verdict, else
    #: "rayleigh" (fixed by asymslide.atlas.plan.make_plan)
    verdict: str | None = None

    def identity(self) -> dict[str, Any]:
        """What identifies these settings in a store's plan (a resumed sweep must ask for the same)."""
        out = {"levels": self.levels, "margin": self.margin, "guard": self.guard, "follow": self.follow}
        # only where the sliding verdict is refined: the plans of Rayleigh-branch atlases keep their identity
        return {**out, "verdict": self.verdict} if self.verdict == SLIDING else out


def adaptive_size(n: int, levels: int) -> int:
    """The smallest axis length >= n of the form m·2^levels + 1 (1 stays 1)."""
    step = 2**levels
    return 1 if n <= 1 else math.ceil((n - 1) / step) * step + 1


def default_levels(shape: tuple[int, ...] | list[int]) -> int:
    """L such that the coarse grid has about COARSE_POINTS points along the longest axis (0 for tiny grids)."""
    longest = max(shape, default=1)
    if longest <= COARSE_POINTS:
        return 0
    return max(0, round(math.log2((longest - 1) / (COARSE_POINTS - 1))))


def resolve_spec(spec: AdaptiveSpec | bool | Mapping[str, Any], shape: tuple[int, ...]) -> AdaptiveSpec:
    """A validated spec with its levels fixed for the grid `shape`; ValueError naming the problem."""
    if spec is True:
        spec = AdaptiveSpec()
    elif isinstance(spec, Mapping):
        spec = AdaptiveSpec(**spec)
    if not isinstance(spec, AdaptiveSpec):
        raise ValueError(f"adaptive must be True, an AdaptiveSpec or a mapping of its fields; got {spec!r}")
    levels = default_levels(shape) if spec.levels is None else spec.levels
    if not isinstance(levels, int | np.integer) or not 0 <= levels <= 20:
        raise ValueError(f"adaptive levels must be an integer in [0, 20]; got {levels!r}")
    if not isinstance(spec.margin, int | np.integer) or not 0 <= spec.margin <= 8:
        raise ValueError(f"adaptive margin must be an integer in [0, 8]; got {spec.margin!r}")
    guard = float(spec.guard)
    if not (math.isfinite(guard) and guard >= 0):
        raise ValueError(f"adaptive guard must be a finite factor >= 0 (0: off); got {spec.guard!r}")
    if not isinstance(spec.follow, bool | np.bool_):
        raise ValueError(f"adaptive follow must be True or False; got {spec.follow!r}")
    if spec.verdict is not None and spec.verdict not in VERDICTS:
        raise ValueError(f"adaptive verdict must be one of {', '.join(VERDICTS)} (or None: the plan's); got "
                         f"{spec.verdict!r}")
    return AdaptiveSpec(int(levels), int(spec.margin), guard, bool(spec.follow), spec.verdict)


def check_shape(names: tuple[str, ...], shape: tuple[int, ...], levels: int) -> None:
    """ValueError unless every axis has m·2^levels + 1 points, saying which size to use instead."""
    for name, n in zip(names, shape, strict=True):
        if n > 1 and (n - 1) % 2**levels:
            raise ValueError(f"axis {name} has {n} points: an adaptive grid of {levels} levels needs m·2^{levels} + 1 "
                             f"points per axis (nested grids of stride 2^{levels} .. 1); use "
                             f"{adaptive_size(n, levels)} (asymslide.atlas.adaptive.adaptive_size) or other levels")


def _squeeze(shape: tuple[int, ...]) -> tuple[int, ...]:
    """The axes of more than one point (the refinement works on those; a single value has no cells)."""
    return tuple(i for i, n in enumerate(shape) if n > 1)


def _squeezed(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """The arrays (full grid, one shape) without their axes of a single point."""
    shape = arrays[0].shape
    keep = _squeeze(shape)
    drop = tuple(i for i in range(len(shape)) if i not in keep)
    return tuple(np.squeeze(a, axis=drop) for a in arrays)


def _corner_span(known: np.ndarray, classes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(min, max) of the classes over the evaluated corners of every cell of a lattice (`known`: evaluated there);
    127 and -1 for a cell with no evaluated corner."""
    vmin = _corner_reduce(np.where(known, classes, 127).astype(np.int8), np.minimum)
    vmax = _corner_reduce(np.where(known, classes, -1).astype(np.int8), np.maximum)
    return vmin, vmax


def _lattice(a: np.ndarray, stride: int) -> np.ndarray:
    """The view of `a` (squeezed) on the points of stride `stride`."""
    return a[(slice(None, None, stride),) * a.ndim]


def _corner_reduce(a: np.ndarray, fn: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> np.ndarray:
    """fn over the 2^d corners of every cell of the lattice array `a` (cells: shape - 1 per axis)."""
    out = a
    for axis in range(a.ndim):
        lo = [slice(None)] * a.ndim
        hi = [slice(None)] * a.ndim
        lo[axis], hi[axis] = slice(None, -1), slice(1, None)
        out = fn(out[tuple(lo)], out[tuple(hi)])
    return out


def _expand(cells: np.ndarray, factor: int) -> np.ndarray:
    """Max over the cells whose closure holds each point: a cell array of shape c -> points of shape c·factor + 1 on
    the lattice `factor` times finer (a point on a face between cells takes the larger value)."""
    out = cells
    for axis in range(cells.ndim):
        rep = np.repeat(out, factor, axis=axis)
        last = np.take(out, [-1], axis=axis)
        full = np.concatenate([rep, last], axis=axis)
        faces = [slice(None)] * cells.ndim
        faces[axis] = slice(factor, -1, factor)
        before = np.take(out, np.arange(out.shape[axis] - 1), axis=axis)
        full[tuple(faces)] = np.maximum(full[tuple(faces)], before)
        out = full
    return out


def _dilate(mask: np.ndarray, margin: int) -> np.ndarray:
    """Points within `margin` points (Chebyshev distance, on one lattice) of a True point."""
    if margin <= 0 or not mask.any():
        return mask
    from scipy import ndimage

    return ndimage.maximum_filter(mask, size=2 * margin + 1, mode="constant", cval=False)


def _curvature(growth: np.ndarray, certified: np.ndarray) -> np.ndarray:
    """Σ_i |δ²_i growth| / 8 at every point of a lattice (δ² from three certified points, else 0; the ends of an
    axis take their neighbour's): the deviation of the growth from linear interpolation inside a cell."""
    g = np.where(certified, growth, np.nan)
    total = np.zeros(g.shape)
    for axis in range(g.ndim):
        n = g.shape[axis]
        if n < 3:
            continue
        a, b, c = (np.take(g, np.arange(k, n - 2 + k), axis=axis) for k in range(3))
        d2 = np.abs(a - 2 * b + c) / 8
        d2 = np.nan_to_num(d2, nan=0.0)
        pad = [(0, 0)] * g.ndim
        pad[axis] = (1, 1)
        total += np.pad(d2, pad, mode="edge")
    return total


def refine_targets(level: int, spec: AdaptiveSpec, verdict: np.ndarray, growth: np.ndarray,
                   computed: np.ndarray, classes: np.ndarray | None = None) -> np.ndarray:
    """Boolean mask (full grid) of the points level `level` evaluates, from the points evaluated at levels below it
    (only those: the result does not depend on how far `level` itself got), excluding those already evaluated
    there. `verdict`: the class (0, 1, 2) where evaluated; `growth`: the growth; `computed`: the level, or -1;
    `classes`: the classes whose change flags a cell (default `verdict`; :func:`refinement_classes`), the guard
    reading `verdict` and `growth`."""
    shape = verdict.shape
    v, g, c, k = _squeezed(verdict, growth, computed, verdict if classes is None else classes)
    L = spec.levels
    if level == 0:
        out = np.zeros(v.shape, bool)
        out[(slice(None, None, 2**L),) * out.ndim] = True
        return out.reshape(shape)
    if v.ndim == 0:
        return np.zeros(shape, bool)
    parent = 2 ** (L - level + 1)
    known = (c >= 0) & (c < level)
    kv, kk = _lattice(k, parent), _lattice(known, parent)
    all_known = _corner_reduce(kk, np.logical_and)
    vmin, vmax = _corner_span(kk, kv)
    flagged = all_known & (vmin != vmax)
    if spec.guard > 0:
        kg = _lattice(g, parent)
        certified = kk & (_lattice(v, parent) <= 1) & np.isfinite(kg)
        curvature = _corner_reduce(_curvature(kg, certified), np.maximum)
        nearest = _corner_reduce(np.where(certified, np.abs(kg), np.inf), np.minimum)
        flagged |= all_known & (vmin == vmax) & (vmin <= 1) & (nearest <= spec.guard * curvature)
    # the points of the flagged cells on the new level's grid, and those within `margin` of its cells of them
    child = _dilate(_expand(flagged.astype(np.int8), 2).astype(bool), spec.margin)
    out = np.zeros(v.shape, bool)
    stride = parent // 2
    out[(slice(None, None, stride),) * out.ndim] = child
    out &= ~known
    return out.reshape(shape)


def follow_targets(level: int, spec: AdaptiveSpec, verdict: np.ndarray, computed: np.ndarray) -> np.ndarray:
    """Boolean mask (full grid) of the points a follow round of level `level` evaluates: the corners not evaluated
    yet of every cell of the level (side 2^(L - level) grid steps) among whose evaluated corners (of this level and
    those below) two classes of `verdict` (or of :func:`refinement_classes`) are found. Empty when the level's
    points are closed under that rule; a point added can only add such cells, so rounds until it is empty reach the
    same closure whatever order points came in."""
    shape = verdict.shape
    v, c = _squeezed(verdict, computed)
    if level == 0 or v.ndim == 0:  # level 0 evaluates its whole lattice
        return np.zeros(shape, bool)
    stride = 2 ** (spec.levels - level)
    kk = _lattice((c >= 0) & (c <= level), stride)
    kv = _lattice(v, stride)
    vmin, vmax = _corner_span(kk, kv)
    split = vmin < vmax  # two evaluated corners of different classes (none evaluated: 127 > -1)
    out = np.zeros(v.shape, bool)
    if split.any():
        out[(slice(None, None, stride),) * out.ndim] = _expand(split.astype(np.int8), 1).astype(bool) & ~kk
    return out.reshape(shape)


def refinement_classes(verdict: np.ndarray, verdict_all: np.ndarray | None = None) -> np.ndarray:
    """The classes whose change between a cell's corners flags it: the Rayleigh branch's verdict class, or, with
    the sliding verdict `verdict_all` (a sweep refining it), the pair of both classes as one number (3·verdict +
    verdict_all; -1 where either is not computed), so that a cell is refined where either verdict changes and
    both verdicts can be filled from cells whose corners agree."""
    if verdict_all is None:
        return verdict
    pair = 3 * verdict.astype(np.int16) + verdict_all
    return np.where((verdict >= 0) & (verdict_all >= 0), pair, -1).astype(np.int8)


def fill_classes(verdict: np.ndarray, computed: np.ndarray, levels: int) -> np.ndarray:
    """The verdict class at every point: the model's where evaluated, else the class of the finest cell (of any
    level's stride) whose corners are all evaluated and of one class and whose closure holds the point (cells of
    one stride that share the point share the corners of their common face, so they agree); -1 where no such cell
    holds it (not in a finished adaptive sweep)."""
    return _fill(verdict, computed, levels)[0]


def fill_levels(verdict: np.ndarray, computed: np.ndarray, levels: int) -> np.ndarray:
    """The level of the cell a point's class was filled from by :func:`fill_classes` (a cell of level k has side
    2^(levels - k) grid steps); -1 where the point was evaluated or has no class."""
    return _fill(verdict, computed, levels)[1]


def _fill(verdict: np.ndarray, computed: np.ndarray, levels: int) -> tuple[np.ndarray, np.ndarray]:
    """(:func:`fill_classes`, :func:`fill_levels`)."""
    shape = verdict.shape
    v, c = _squeezed(verdict, computed)
    done = c >= 0
    out = np.where(done, v, -1).astype(np.int8)
    source = np.full(out.shape, -1, dtype=np.int8)
    if v.ndim == 0:
        return out.reshape(shape), source.reshape(shape)
    for level in range(levels - 1, -1, -1):
        stride = 2 ** (levels - level)
        kk, kv = _lattice(done, stride), _lattice(v, stride)
        all_known = _corner_reduce(kk, np.logical_and)
        vmin, vmax = _corner_span(kk, kv)
        cls = np.where(all_known & (vmin == vmax), vmin, -1).astype(np.int8)
        spread = _expand(cls, stride)
        now = (out == -1) & (spread != -1)
        out = np.where(now, spread, out)
        source[now] = level
    return out.reshape(shape), source.reshape(shape)


def refinement_text(a: Mapping[str, Any]) -> str:
    """The refinement recorded in an adaptive store's ``adaptive`` attribute, in words (``asymslide info`` and the
    Atlas tab): margin, guard and following (stores written before following existed record none: not followed)."""
    guard = f"guard {a['guard']:g}" if a.get("guard") else "guard off"
    follow = "boundary followed" if a.get("follow") else "boundary not followed"
    which = ("refined where the sliding verdict (every branch) or the Rayleigh branch's changes"
             if a.get("verdict") == SLIDING else "refined on the Rayleigh branch's verdict")
    return f"margin {a.get('margin')}, {guard}, {follow}; {which}"


def level_counts(computed: np.ndarray, levels: int) -> list[int]:
    """Points evaluated at each level 0 .. levels."""
    counts = np.bincount(computed[computed >= 0].astype(np.intp).ravel(), minlength=levels + 1)
    return [int(x) for x in counts[: levels + 1]]


def lattice_size(shape: tuple[int, ...], levels: int, level: int) -> int:
    """Points of the grid of level `level` (stride 2^(levels - level))."""
    stride = 2 ** (levels - level)
    return math.prod((n - 1) // stride + 1 for n in shape)


def summary(shape: tuple[int, ...], spec: AdaptiveSpec, counts: list[int] | None = None) -> dict[str, Any]:
    """What the store's ``adaptive`` attribute records: the spec, the coarse grid and the evaluated fractions
    (`counts`: points evaluated per level, :func:`level_counts`; None: none yet)."""
    L = spec.levels or 0
    counts = counts or [0] * (L + 1)
    size = math.prod(shape)
    per_level = [{"level": lv, "stride": 2 ** (L - lv), "points": n, "fraction_of_grid": n / size,
                  "fraction_of_level_grid": n / lattice_size(shape, L, lv)} for lv, n in enumerate(counts)]
    return {"levels": L, "coarse_stride": 2**L, "coarse_shape": [(n - 1) // 2**L + 1 for n in shape],
            "margin": spec.margin, "guard": spec.guard, "follow": spec.follow, "verdict": spec.verdict or RAYLEIGH,
            "points": size, "evaluated": sum(counts),
            "evaluated_fraction": sum(counts) / size, "per_level": per_level}
