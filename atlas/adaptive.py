"""Adaptive atlases: the dense atlas grid, with the model called only where the verdict can change (issue 27).

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
further and evaluates that ring all around every flagged cell. On 33^4 points at eta = 10 following with margin 0
reproduced the dense verdict field at every point, where margin 0 alone missed 26 points and margin 1 needed 1.6
times the points (``benchmarks/bench_adaptive.py``). Neither finds a single point of another class inside a cell
whose corners agree (on 65^4 at eta = inf: 14 isolated undetermined points of 17.9 M); the guard below does.
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
every branch (``sliding``: the plan computes :func:`asymslide.atlas.sweep.sliding_arrays` at every evaluated point, so
each has both verdicts' variables) the pair of both classes (:func:`refinement_classes`): a cell is refined where
either verdict changes, so both can be filled (``verdict_filled``, ``verdict_filled_all``). The guard reads the
Rayleigh branch's growth (the sliding growth is NaN where stable). Journal entries name their rows (attribute
``rows``), so both kinds of store resume.

The store's attribute ``adaptive`` (JSON) records the levels, the coarse grid, margin, guard, the verdict refined
and the evaluated fraction overall and per level. The plan (:class:`AdaptiveSpec` in it) is part of the store's
identity, as the dense sweep's: another margin, guard, level count or verdict refuses to resume.

Layering: this module takes a validated :class:`asymslide.atlas.sweep.Plan` (the CLI parses, the engine takes a plan);
:func:`refine_targets` and :func:`fill_classes` are pure NumPy functions of the state arrays.
"""

from __future__ import annotations

import json
import math
import os
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:
    from .sweep import Plan

#: the coarse grid has about this many points along the longest axis when the levels are not given
COARSE_POINTS = 9
#: at most this many points per task of a level (a task never spans two Zarr chunks)
TASK_POINTS = 8192
#: at most this many points per task where the sweep also computes the sliding verdict (~10 ms a point at eta = inf,
#: ~0.1 s at finite eta: 128 points keep both threads busy on a coarse level and lose little to a kill)
SLIDING_TASK_POINTS = 128
#: the growth variables' chunks hold at most this many points in an adaptive store: a level rewrites every chunk it
#: touches, and larger chunks mean fewer writes (zarr writes cost ~1-5 ms per chunk and variable on this machine)
CHUNK_POINTS = 131072
#: ``computed`` where a point was not evaluated
NOT_COMPUTED = -1
#: the verdicts an adaptive sweep can refine: the Rayleigh branch's (the growth variables), or the sliding verdict
#: over every branch (docs/physics.md §14; the ``*_all`` variables, every evaluated point getting both verdicts and
#: a cell refined where either changes class, so that both filled verdicts hold)
RAYLEIGH, SLIDING = "rayleigh", "sliding"
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
    #: "rayleigh" (fixed by asymslide.atlas.sweep.make_plan)
    verdict: str | None = None

    def identity(self) -> dict[str, Any]:
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


# ------------------------------------------------------------------------------------------------
# the refinement: pure functions of the state arrays (full grid, C order)
# ------------------------------------------------------------------------------------------------


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


# ------------------------------------------------------------------------------------------------
# the engine: levels as Dask batches, grouped by Zarr chunk, written as they finish
# ------------------------------------------------------------------------------------------------

#: the variables the refinement reads (the rest of the growth variables is only written)
_STATE = ("growth", "verdict", "computed")


@dataclass(frozen=True)
class PointTask:
    """The points of one Zarr chunk that one level evaluates (at most :func:`task_points`): their flat indices in
    the grid and their parameter rows (gamma, f, beta, eta, Delta, xi), so a worker needs nothing else."""

    kind: str
    index: int
    level: int
    chunk: int
    flat: np.ndarray
    params: np.ndarray
    kH: tuple[float, ...]
    rtol: float | None
    #: the sliding verdict's spec (asymslide.atlas.sweep.SlidingSpec) where the sweep refines it; None: Rayleigh only
    sliding: Any = None

    @property
    def points(self) -> int:
        return int(self.flat.size)

    @property
    def holds_gil(self) -> bool:
        """Whether its model calls hold the GIL: the sliding verdict's (asymslide.atlas.sweep.Task.holds_gil)."""
        return self.sliding is not None


def run_points(task: PointTask) -> dict[str, np.ndarray]:
    """Evaluate one task's points (on a worker): :func:`asymslide.atlas.sweep.growth_arrays` and, where the sweep
    refines the sliding verdict, :func:`asymslide.atlas.sweep.sliding_arrays`, as the dense sweep."""
    from .sweep import growth_arrays, sliding_arrays

    out = growth_arrays(np.log(np.asarray(task.kH)), task.params, task.rtol)
    if task.sliding is not None:
        out.update(sliding_arrays(task.sliding, task.params))
    return out


class _Grid:
    """The grid's geometry: axis values, fixed values, Zarr chunks (for grouping points and writing chunks)."""

    def __init__(self, plan: Plan) -> None:
        from .sweep import PARAMETERS

        self.plan = plan
        self.shape = plan.shape
        self.chunks = tuple(plan.chunks[n] for n in plan.names)
        self.blocks = tuple(-(-n // c) for n, c in zip(self.shape, self.chunks, strict=True))
        self.values = [np.asarray(plan.axes[n]) for n in plan.names]
        self.parameters = PARAMETERS

    def params(self, flat: np.ndarray) -> np.ndarray:
        """(6, n) parameter rows of the grid points `flat` (the same floats as the dense sweep's meshgrid)."""
        index = np.unravel_index(flat, self.shape)
        columns = {n: v[i] for n, v, i in zip(self.plan.names, self.values, index, strict=True)}
        rows = [columns[p] if p in columns else np.full(flat.size, self.plan.fixed[p]) for p in self.parameters]
        return np.ascontiguousarray(np.stack(rows), dtype=float)

    def chunk_of(self, flat: np.ndarray) -> np.ndarray:
        index = np.unravel_index(flat, self.shape)
        return np.ravel_multi_index(tuple(i // c for i, c in zip(index, self.chunks, strict=True)), self.blocks)

    def region(self, chunk: int) -> tuple[slice, ...]:
        start = np.unravel_index(chunk, self.blocks)
        return tuple(slice(s * c, min((s + 1) * c, n)) for s, c, n in zip(start, self.chunks, self.shape, strict=True))

    def tasks(self, level: int, flat: np.ndarray) -> list[PointTask]:
        """The level's points `flat` as tasks: grouped by Zarr chunk, at most :func:`task_points` each, the largest
        first (a batch ends when its last task does)."""
        if flat.size == 0:
            return []
        chunk = self.chunk_of(flat)
        order = np.argsort(chunk, kind="stable")
        flat, chunk = flat[order], chunk[order]
        params = self.params(flat)
        starts = np.r_[0, np.flatnonzero(np.diff(chunk)) + 1]
        stops = np.r_[starts[1:], flat.size]
        size = task_points(self.plan)
        parts = [(int(chunk[a]), i, min(i + size, z)) for a, z in zip(starts, stops, strict=True)
                 for i in range(a, z, size)]
        parts.sort(key=lambda p: p[1] - p[2])
        return [PointTask(f"level{level}", k, level, cid, flat[a:z], params[:, a:z], self.plan.kH, self.plan.rtol,
                          self.plan.sliding) for k, (cid, a, z) in enumerate(parts)]


#: the Zarr group (inside the store) of the journal: the points evaluated since the grid variables were last written
JOURNAL = "adaptive_journal"
#: the growth variables in a journal entry's rows, after the flat index and the level (an entry records its rows in
#: its attribute ``rows``; entries written before it existed hold these)
_ROWS = ("growth", "kH_at_max", "kH_min", "kH_max", "n_masked", "verdict", "verdict_reason")


def task_points(plan: Plan) -> int:
    """The most points a task of the plan holds (a journal entry's chunk): :data:`TASK_POINTS`, or
    :data:`SLIDING_TASK_POINTS` where the sliding verdict is computed too."""
    return SLIDING_TASK_POINTS if plan.sliding is not None else TASK_POINTS


def journal_rows(plan: Plan) -> tuple[str, ...]:
    """The variables a journal entry of the plan holds: the growth variables, and the sliding ones where the sweep
    refines the sliding verdict."""
    from .sweep import SLIDING_VARS

    return _ROWS + (tuple(SLIDING_VARS) if plan.sliding is not None else ())


def state_names(plan: Plan) -> tuple[str, ...]:
    """The grid variables an adaptive sweep keeps in memory and writes at its end (``computed`` last)."""
    return (*journal_rows(plan), "computed")


class _Store:
    """An adaptive store: the grid variables, and a journal of the points evaluated since they were written.

    Writing the grid variables as points finish would rewrite a Zarr chunk at every level that touches it (the
    coarse levels touch every chunk): ~35 s of writing for a 65^4 atlas whose model calls take ~100 s. So each
    finished task goes to the journal instead (the group :data:`JOURNAL`: per level and run one array, whose chunk k
    holds task k's flat indices, level and values, NaN-padded: one atomic file per task), and the grid variables
    are written once, at the end, before the journal is removed. Reading a store replays its journal, so a killed
    sweep loses only the tasks in flight (a chunk not written reads as NaN: its points are computed again).
    """

    def __init__(self, path: Path, rows: tuple[str, ...] = _ROWS, size: int = TASK_POINTS) -> None:
        import zarr

        self.path = path
        self.rows, self.size = rows, size
        self.group = zarr.open_group(str(path), mode="r+")
        self._entry = None

    def load(self, names: tuple[str, ...]) -> dict[str, np.ndarray]:
        """The grid variables `names` as stored, with the journal's points applied."""
        memory = {name: self.group[name][...] for name in names}
        flat = {name: memory[name].reshape(-1) for name in names}
        for index, level, rows in read_journal(self.group):
            for name, values in rows.items():
                if name in flat:
                    flat[name][index] = values
            flat["computed"][index] = level
        return memory

    def begin(self, level: int, tasks: list[PointTask]) -> None:
        """The journal array of one level's tasks in this run (task k writes chunk k)."""
        from zarr.codecs import ZstdCodec

        self._entry = None
        if tasks:
            journal = self.group.require_group(JOURNAL)
            name = f"L{level}-{os.getpid()}-{time.time_ns()}"
            self._entry = journal.create_array(name, shape=(2 + len(self.rows), len(tasks) * self.size),
                                               chunks=(2 + len(self.rows), self.size), dtype="f8", fill_value=np.nan,
                                               compressors=[ZstdCodec(level=1)], attributes={"rows": list(self.rows)})

    def append(self, task: PointTask, result: dict[str, np.ndarray]) -> None:
        """One finished task into its chunk of the level's journal array."""
        rows = np.full((2 + len(self.rows), self.size), np.nan)
        n = task.flat.size
        rows[0, :n] = task.flat
        rows[1, :n] = task.level
        for i, name in enumerate(self.rows):
            rows[2 + i, :n] = result[name]
        self._entry[:, task.index * self.size:(task.index + 1) * self.size] = rows

    def finish(self, memory: dict[str, np.ndarray], names: tuple[str, ...], filled: dict[str, np.ndarray],
               summary: str) -> None:
        """The grid variables (``computed`` last), the filled verdicts (variable -> values) and the summary, then
        the journal removed."""
        for name in names:
            self.group[name][...] = memory[name]
        for name, values in filled.items():
            self.group[name][...] = values
        self.group.attrs["adaptive"] = summary
        if JOURNAL in self.group:
            del self.group[JOURNAL]


def read_journal(group) -> list[tuple[np.ndarray, int, dict[str, np.ndarray]]]:
    """(flat indices, level, variable -> values) of the points in a store's journal (none if it has none): every
    column of its arrays whose index is not NaN (the chunks of tasks that did not finish are)."""
    if JOURNAL not in group:
        return []
    out = []
    for _, entry in sorted(group[JOURNAL].arrays()):
        names = tuple(entry.attrs.get("rows", _ROWS))
        rows = entry[...]
        if rows.shape[0] != 2 + len(names):
            continue
        rows = rows[:, ~np.isnan(rows[0])]
        for level in np.unique(rows[1]):
            at = rows[1] == level
            values = rows[2:, at]
            out.append((rows[0, at].astype(np.intp), int(level), dict(zip(names, values, strict=True))))
    return out


def stored_computed(path: str | os.PathLike) -> np.ndarray:
    """The ``computed`` variable of an adaptive store with its journal applied (how far a sweep got)."""
    import zarr

    group = zarr.open_group(str(path), mode="r")
    computed = group["computed"][...]
    flat = computed.reshape(-1)
    for index, level, _ in read_journal(group):
        flat[index] = level
    return computed


def filled_names(plan: Plan) -> dict[str, str]:
    """The filled verdicts an adaptive sweep writes at its end: variable -> the verdict it fills."""
    return {"verdict_filled": "verdict", **({"verdict_filled_all": "verdict_all"} if plan.sliding is not None else {})}


def _ignore(kind: str, points: int) -> None:
    """A progress callback that does nothing."""


def _open(plan: Plan, names: tuple[str, ...], store: str | os.PathLike | None, command: str | None):
    """(dataset in memory or None, store path or None, journal writer or None, the variables `names` as arrays):
    without a store a dataset in memory (whose arrays these are, with ``verdict_filled``); with one, the store opened
    or created (:func:`asymslide.atlas.sweep.open_store`) and its values with the journal applied, or the fill values of
    a new store."""
    from . import sweep as S

    if store is None:
        ds = S.memory_dataset(plan, command)
        return ds, None, None, {name: ds[name].values for name in (*names, *filled_names(plan))}
    fresh = not Path(store).exists()
    path = S.open_store(plan, Path(store), command)
    writer = _Store(path, journal_rows(plan), task_points(plan))
    if not fresh:
        return None, path, writer, writer.load(names)
    kinds = {**S.GROWTH_VARS, **S.SLIDING_VARS, "computed": (np.int8, NOT_COMPUTED)}
    memory = {name: np.full(plan.shape, kinds[name][1], dtype=kinds[name][0]) for name in names}
    return None, path, writer, memory  # nothing to read: the fill values


class _Rounds:
    """The rounds of an adaptive sweep's levels: each one Dask batch of the points of a target mask not evaluated
    yet, kept in `memory` (the grid variables, updated as tasks finish) and in the store's journal."""

    def __init__(self, grid: _Grid, memory: dict[str, np.ndarray], writer: _Store | None, client, workers: int | None,
                 progress: Callable[[str, int], None], start: Callable[[str, int], None]) -> None:
        self.grid, self.memory, self.writer = grid, memory, writer
        self.client, self.workers, self.progress, self.start = client, workers, progress, start
        self.flat = {name: a.reshape(-1) for name, a in memory.items()}

    def levels(self, spec: AdaptiveSpec) -> None:
        """Levels 0 .. L: each its first round (:func:`refine_targets`), then its follow rounds until none is left
        (on :func:`refinement_classes`: the Rayleigh branch's verdict, or both verdicts)."""
        m = self.memory

        def classes() -> np.ndarray:
            return refinement_classes(m["verdict"], m["verdict_all"] if spec.verdict == SLIDING else None)

        for level in range(spec.levels + 1):
            target = refine_targets(level, spec, m["verdict"], m["growth"], m["computed"], classes())
            while target.any():
                self.execute(level, target)
                target = (follow_targets(level, spec, classes(), m["computed"]) if spec.follow
                          else np.zeros_like(target))

    def execute(self, level: int, target: np.ndarray) -> None:
        """One round of a level: the points of `target` not evaluated yet, as one Dask batch."""
        from . import sweep as S

        computed = self.memory["computed"]
        kind, done = f"level{level}", computed == level
        if np.any(target & (computed > level)):  # cannot happen with the same plan (which is checked)
            raise RuntimeError(f"the store holds points of a later level than {level} where level {level} evaluates")
        self.start(kind, int(target.sum()))
        if done.any():
            self.progress(kind, int((target & done).sum()))
        todo = self.grid.tasks(level, np.flatnonzero(target & ~done))
        if self.writer is not None:
            self.writer.begin(level, todo)
        S._execute(todo, self.keep, self.client, self.workers, run=run_points)

    def keep(self, task: PointTask, result: dict[str, np.ndarray]) -> None:
        """A finished task: into the journal and the grid variables."""
        if self.writer is not None:
            self.writer.append(task, result)
        for name, values in result.items():
            self.flat[name][task.flat] = values
        self.flat["computed"][task.flat] = task.level
        self.progress(task.kind, task.points)


def run(plan: Plan, *, store: str | os.PathLike | None = None, client=None, workers: int | None = None,
        progress: Callable[[str, int], None] | None = None, start: Callable[[str, int], None] | None = None,
        command: str | None = None):
    """The adaptive sweep of a validated plan (``plan.adaptive`` set): levels 0 .. L of the refinement, each one
    Dask batch of tasks grouped by Zarr chunk, then the filled verdict, the fractions and (dense, as
    :func:`asymslide.atlas.sweep.run_dense`) γ_c and the count if the plan asks for them. store/client/workers/command
    as :func:`asymslide.atlas.sweep.sweep`; progress(kind, points) as points finish and start(kind, points) as a level's
    batch starts (kind ``level L``; called again, with the points it adds, as each of the level's follow rounds
    starts). Returns the dataset (in memory without a store, else opened from it)."""
    import xarray as xr

    from . import sweep as S

    spec = plan.adaptive
    if spec is None or spec.levels is None:
        raise ValueError("run() needs a plan made with adaptive=... (asymslide.atlas.sweep.make_plan)")
    grid = _Grid(plan)
    names = state_names(plan)
    ds, path, writer, memory = _open(plan, names, store, command)
    progress = progress or _ignore
    _Rounds(grid, memory, writer, client, workers, progress, start or _ignore).levels(spec)
    filled = {name: fill_classes(memory[source], memory["computed"], spec.levels)
              for name, source in filled_names(plan).items()}
    text = json.dumps(summary(plan.shape, spec, level_counts(memory["computed"], spec.levels)))
    kinds = tuple(k for k in ("gamma_c", "gamma_c_all", "count") if k in S.tasks(plan))
    if writer is None:
        for name, values in filled.items():
            memory[name][...] = values
        ds.attrs["adaptive"] = text
        S.run_kinds(plan, kinds, ds=ds, client=client, workers=workers, progress=progress)
        return ds
    writer.finish(memory, names, filled, text)
    S.run_kinds(plan, kinds, path=path, client=client, workers=workers, progress=progress)
    return xr.open_zarr(path, consolidated=False)
