"""Stability atlases: N-D sweeps of the Rayleigh branch's growth analysis, distributed with Dask, stored in Zarr.

The paper leaves the multi-dimensional stability phase diagram in (γ, f, β, η, Δ, ξ) to future work; an atlas is
that diagram on a grid. The engine only distributes: every number is computed by the model (docs/physics.md §9),

- ``growth``, ``kH_at_max``, ``kH_min``, ``kH_max``, ``n_masked``, ``verdict``, ``verdict_reason``:
  :func:`model.growth_chunk` at every grid point, bitwise what :func:`model.growth_analysis` gives at the same point
  (the continuous max growth over the kH range; the verdict 0 stable / 1 unstable / 2 undetermined and its reason
  code, :data:`model.VERDICT_STATUS`);
- ``gamma_c``, ``gamma_c_reason``: the threshold γ_c, the first certified crossing in γ (as
  :func:`model.critical_gamma`), over the grid of the other axes, so the 6-D boundary is stored as a 5-D function
  (NaN plus a reason code, :data:`model.THRESHOLD_STATUS`, where there is none in the γ range);
- the whole boundary in γ (:func:`model.crossings_chunk`, as :func:`model.critical_gammas`), over the same grid
  with a last dimension ``crossing`` of length :data:`CROSSINGS` (NaN-padded, in increasing γ): ``gamma_c_crossing``
  (the threshold where certified), ``gamma_c_location`` (where the sign change is, certified or not),
  ``gamma_c_kH`` and ``gamma_c_z`` (the neutral mode), ``gamma_c_direction`` (+1 destabilising, -1 stabilising as γ
  grows), ``gamma_c_crossing_reason`` (:data:`model.CROSSING_STATUS`); per point ``gamma_c_n_crossings`` (may
  exceed CROSSINGS) and ``gamma_c_complete`` (1 where every crossing is certified);
- optionally ``unstable_count``: :func:`model.unstable_count` (all branches) in a stated window at each kH of a
  stated grid;
- optionally the sliding verdict over every branch (:func:`model.sliding_chunk`, as :func:`model.sliding_analysis`,
  on its own kH grid ``kH_sliding`` with a stated growth floor; docs/physics.md §14): ``growth_all``,
  ``kH_at_max_all``, ``re_z_at_max_all`` (z at the maximum is re_z_at_max_all + i growth_all), ``family_all``
  (:data:`model.FAMILIES`), ``verdict_all`` and ``verdict_reason_all`` (:data:`model.SLIDING_STATUS`),
  ``max_at_end_all`` and ``lower_bound_all`` (1 at finite η: the maximum is a lower bound of the continuous one).
  A store without them covers the Rayleigh branch only (``asymslide info`` says so).

The grid is cut into chunks (a hyper-rectangle of grid points each, aligned with the Zarr chunks). A chunk is a
pure task: it needs only this package on the machine that runs it, and returns its arrays to the process that
writes them. A store is created by xarray (the template dataset: coordinates, attributes, encodings) and read back
with ``xarray.open_zarr``; each finished chunk is written at once (an xarray region write, by one thread while the
workers go on computing) and then marked done (``done_*`` flags, one Zarr chunk per flag, written after the data);
Ctrl-C, a killed process or a lost worker loses at most the chunks in flight, and running the same sweep again
computes only the chunks not marked done. A store remembers its plan (axes, fixed values, kH grid, rtol, chunks,
variables) and the model's fingerprint; a sweep with another plan or another model refuses to resume it, saying
why, and leaves it untouched.

Execution: without a client, Dask's threaded scheduler on this machine (the compiled kernels release the GIL;
``benchmarks/bench_sweep.py`` compares it with a ``distributed.LocalCluster``); with ``client=`` a
``distributed.Client`` of any cluster runs the same tasks (``asymslide sweep --scheduler tcp://HOST:PORT``).
"""

from __future__ import annotations

import contextlib
import datetime
import functools
import hashlib
import json
import math
import os
import queue
import shutil
import subprocess
import threading
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from asymslide import model

from . import __version__  # the distribution's version, recorded in every store
from . import adaptive as _adaptive
from .adaptive import AdaptiveSpec
from .adaptive import summary as adaptive_summary

#: the sweepable parameters, in the model's order
PARAMETERS = tuple(model.PARAMETERS)
#: values of the parameters that are neither an axis nor given as fixed: the paper's (model.Parameter.default)
DEFAULT_FIXED = {name: p.default for name, p in model.PARAMETERS.items()}
#: default kH grid: 16 points per decade over [1e-3, 1e3]
DEFAULT_KH = np.logspace(-3, 3, 97)
#: grid points per growth chunk (~0.6 s at eta = inf, ~7 s at finite eta on one core): smaller chunks cost ~10 ms
#: each on a distributed cluster (benchmarks/bench_sweep.py), larger ones lose more work when a sweep is killed
CHUNK_POINTS = 8192
#: grid points per gamma_c chunk (each point costs ~10-20 growth evaluations)
GAMMA_C_CHUNK_POINTS = 256
#: grid points per unstable_count chunk (each point costs one count per kH of the count grid, ~1-5 ms each)
COUNT_CHUNK_POINTS = 16
#: the window of the optional all-branch count: model.unstable_count's defaults
DEFAULT_WINDOW = (5.0, 1e-4, 2.0)
#: grid points per sliding chunk (model.sliding_chunk: ~10 ms a point at eta = inf, ~0.1 s at finite eta)
SLIDING_CHUNK_POINTS = 64
#: the task kinds whose model calls hold the GIL (run in processes: :func:`_execute`)
GIL_KINDS = ("sliding", "gamma_c_all")
#: the sliding variables (every branch; model.sliding_chunk): dtype, fill, long name
SLIDING_VARS = {
    "growth_all": (np.float64, np.nan, "max over kH of Im(c/c_s) over every branch (sliding; NaN unless unstable with "
                   "a certified maximum; at finite eta a lower bound: lower_bound_all)"),
    "kH_at_max_all": (np.float64, np.nan, "kH where the growth over every branch is largest"),
    "re_z_at_max_all": (np.float64, np.nan, "Re z of the fastest root at the maximum (z = re_z_at_max_all + i "
                        "growth_all)"),
    "family_all": (np.int8, -1, "family of the fastest root at the maximum (model.FAMILIES; -1: none)"),
    "verdict_all": (np.int8, -1, "sliding (every branch above the floor): 0 stable, 1 unstable, 2 undetermined (-1: "
                    "not computed); why: verdict_reason_all"),
    "verdict_reason_all": (np.int8, -1, "the sliding verdict's reason code (model.SLIDING_STATUS; -1: not computed)"),
    "max_at_end_all": (np.int8, -1, "1 where the maximum lies at an end of the kH range (it may continue beyond)"),
    "lower_bound_all": (np.int8, -1, "1 at finite eta: growth_all is the maximum at the kH searched and along the "
                        "roots followed, a lower bound of the continuous one (docs/physics.md §14.7)"),
}
#: seconds a scheduler address may take to answer (the command then fails within ~10 s of its start)
CONNECT_TIMEOUT = 8
#: the growth variables, their Zarr fill values (where not computed) and attributes
GROWTH_VARS = {
    "growth": (np.float64, np.nan, "max over kH of Im(c/c_s) on the Rayleigh branch (refined between grid points)",
               "1"),
    "kH_at_max": (np.float64, np.nan, "kH where the growth is largest", "1"),
    "kH_min": (np.float64, np.nan, "lower end of the unstable band around the maximum (NaN: none or beyond the grid)",
               "1"),
    "kH_max": (np.float64, np.nan, "upper end of the unstable band around the maximum (NaN: none or beyond the grid)",
               "1"),
    "n_masked": (np.int16, -1, "kH grid points where the Rayleigh branch could not be followed (masked; -1: not "
                 "computed)", "1"),
    "verdict": (np.int8, -1, "0 stable, 1 unstable, 2 undetermined (-1: not computed); why: verdict_reason", "1"),
    "verdict_reason": (np.int8, -1, "the verdict's reason code (model.VERDICT_STATUS; -1: not computed)", "1"),
}
#: crossings in gamma stored per point (the ``crossing`` dimension; model.critical_gammas' max_crossings)
CROSSINGS = model.thresholds.MAX_CROSSINGS
#: the variables of the whole boundary in gamma (with the ``crossing`` dimension): dtype, fill, long name
CROSSING_VARS = {
    "gamma_c_crossing": (np.float64, np.nan, "gamma at each certified crossing of the max growth (a neutral mode; NaN: "
                         "not certified or no such crossing)"),
    "gamma_c_location": (np.float64, np.nan, "gamma where each sign change of the max growth is (certified or not)"),
    "gamma_c_kH": (np.float64, np.nan, "kH of the neutral mode at each certified crossing"),
    "gamma_c_z": (np.float64, np.nan, "z = c/c_s (real) of the neutral mode at each certified crossing"),
    "gamma_c_direction": (np.int8, 0, "+1 destabilising (unstable above), -1 stabilising, 0 not certified or none"),
    "gamma_c_crossing_reason": (np.int8, -1, "reason code of each crossing (model.CROSSING_STATUS; -1: none)"),
}
#: the sliding threshold's variables (every branch; asymslide sweep --sliding-thresholds): the Rayleigh branch's
#: names with ``gamma_c_all`` for ``gamma_c`` (model.crossings_chunk with branches="all", docs/physics.md §14.10)
def _all(name: str) -> str:
    return name.replace("gamma_c", "gamma_c_all", 1)


#: per-point summaries of the boundary in gamma: dtype, fill, long name
CROSSING_SUMMARY_VARS = {
    "gamma_c_n_crossings": (np.int16, -1, "sign changes of the max growth found in the gamma range (-1: not computed; "
                            "may exceed the crossing dimension)"),
    "gamma_c_complete": (np.int8, -1, "1 where every crossing found is certified, 0 where not (-1: not computed)"),
}
#: the sliding threshold's crossing variables (with the ``crossing`` dimension)
CROSSING_ALL_VARS = {_all(name): v for name, v in CROSSING_VARS.items()}


class SweepError(ValueError):
    """A sweep that cannot run as asked (bad axes or values, a store that cannot be resumed); the message says why."""


# ------------------------------------------------------------------------------------------------
# the plan: what a sweep computes, independent of where
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class CountSpec:
    """The optional all-branch count: :func:`model.unstable_count` in `window` (re_max, im_min, im_max) at every kH
    of `kH`."""

    kH: tuple[float, ...]
    window: tuple[float, float, float] = DEFAULT_WINDOW


@dataclass(frozen=True)
class SlidingSpec:
    """The optional sliding verdict over every branch: :func:`model.sliding_chunk` on the kH grid `kH` (its ends are
    the range; default :data:`model.SLIDING_KH`) with the growth floor `floor` (default :data:`model.DEFAULT_FLOOR`)."""

    kH: tuple[float, ...] = tuple(float(x) for x in model.SLIDING_KH)
    floor: float = model.DEFAULT_FLOOR
    #: also the threshold of sliding in gamma over the axes other than gamma (``gamma_c_all`` and its crossings, with
    #: the plan's gamma_c; ~0.5 s a point at eta = inf, ~10 s at finite eta)
    thresholds: bool = False

    def identity(self) -> dict[str, Any]:
        out = {"kH": list(self.kH), "floor": self.floor}
        return {**out, "thresholds": True} if self.thresholds else out  # older plans keep their identity


@dataclass(frozen=True)
class Plan:
    """A validated sweep: the axes (name -> increasing values), the fixed parameters, the kH grid and the rest.

    Everything that determines the numbers in the store (and so whether a store can be resumed) is in
    :meth:`identity`.
    """

    axes: dict[str, tuple[float, ...]]
    fixed: dict[str, float]
    kH: tuple[float, ...]
    rtol: float | None
    growth: bool
    gamma_c: bool
    gamma_range: tuple[float, float]
    count: CountSpec | None
    chunks: dict[str, int] = field(default_factory=dict)
    #: the refinement of an adaptive sweep (asymslide.atlas.adaptive); None: the dense sweep
    adaptive: AdaptiveSpec | None = None
    #: the sliding verdict over every branch; None: the Rayleigh branch only
    sliding: SlidingSpec | None = None

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.axes)

    @property
    def shape(self) -> tuple[int, ...]:
        return tuple(len(v) for v in self.axes.values())

    @property
    def size(self) -> int:
        return math.prod(self.shape)

    @property
    def gamma_c_names(self) -> tuple[str, ...]:
        """The axes of gamma_c: every axis but gamma."""
        return tuple(n for n in self.axes if n != "gamma")

    def identity(self) -> dict[str, Any]:
        """The plan as JSON-able data: equal identities give equal numbers (with the same model)."""
        return {
            "axes": {k: list(v) for k, v in self.axes.items()},
            "fixed": {k: _json_float(v) for k, v in self.fixed.items()},
            "kH": list(self.kH),
            "rtol": self.rtol,
            "growth": self.growth,
            "gamma_c": self.gamma_c,
            "gamma_range": list(self.gamma_range),
            "count": None if self.count is None else {"kH": list(self.count.kH), "window": list(self.count.window)},
            "chunks": dict(self.chunks),
            # only in adaptive plans: a dense plan's identity (and so every dense store) is what it always was
            **({"adaptive": self.adaptive.identity()} if self.adaptive is not None else {}),
            # only where asked for: a plan without it has the identity it always had
            **({"sliding": self.sliding.identity()} if self.sliding is not None else {}),
        }

    # -- chunks -------------------------------------------------------------------------------

    def growth_blocks(self) -> list[tuple[tuple[int, int], ...]]:
        """Index ranges [start, stop) per axis of every growth chunk, in C order."""
        return _blocks([(len(self.axes[n]), self.chunks[n]) for n in self.names])

    def gamma_c_blocks(self) -> list[tuple[tuple[int, int], ...]]:
        return _blocks([(len(self.axes[n]), self.chunks[f"gamma_c:{n}"]) for n in self.gamma_c_names])

    def count_blocks(self) -> list[tuple[tuple[int, int], ...]]:
        return _blocks([(len(self.axes[n]), self.chunks[f"count:{n}"]) for n in self.names])

    def sliding_blocks(self) -> list[tuple[tuple[int, int], ...]]:
        return _blocks([(len(self.axes[n]), self.chunks[f"sliding:{n}"]) for n in self.names])


def _json_float(x: float) -> float | str:
    return "inf" if x == math.inf else float(x)


def _blocks(sizes: Sequence[tuple[int, int]]) -> list[tuple[tuple[int, int], ...]]:
    ranges = [[(a, min(a + c, n)) for a in range(0, n, c)] for n, c in sizes]
    out: list[tuple[tuple[int, int], ...]] = [()]
    for r in ranges:
        out = [(*b, x) for b in out for x in r]
    return out


#: a grid is cut into at least this many chunks where it has the points (a small sweep still keeps every core busy)
MIN_CHUNKS = 16


def chunk_sizes(shape: Sequence[int], points: int) -> list[int]:
    """Chunk length per axis with at most `points` points per chunk, and at most 1/MIN_CHUNKS of the grid: the
    longest chunk axis is halved until the chunk is small enough (deterministic, from the shape alone, so a resumed
    sweep cuts the grid the same way on any machine)."""
    c = list(shape)
    points = min(points, max(1, math.prod(shape) // MIN_CHUNKS))
    while math.prod(c) > points and max(c) > 1:
        i = int(np.argmax(c))
        c[i] = math.ceil(c[i] / 2)
    return c


def parse_axis(spec: str) -> tuple[str, np.ndarray]:
    """``name=lo:hi:n[:log|:lin]`` or ``name=v1,v2,...`` -> (name, values). η axes are log-spaced unless ``:lin``."""
    if "=" not in spec:
        raise SweepError(f"axis {spec!r}: expected name=lo:hi:n[:log] or name=v1,v2,...")
    name, _, values = (s.strip() for s in spec.partition("="))
    if ":" in values:
        parts = values.split(":")
        if len(parts) not in (3, 4) or (len(parts) == 4 and parts[3] not in ("log", "lin")):
            raise SweepError(f"axis {name}: expected lo:hi:n[:log|:lin]; got {values!r}")
        lo, hi = _number(name, parts[0]), _number(name, parts[1])
        try:
            n = int(parts[2])
        except ValueError:
            raise SweepError(f"axis {name}: the number of points must be an integer; got {parts[2]!r}") from None
        if n < 1:
            raise SweepError(f"axis {name}: empty range (n = {n}); give at least one point")
        if not lo < hi and not (n == 1 and lo == hi):
            raise SweepError(f"axis {name}: the range {lo:g}:{hi:g} is {'empty' if lo == hi else 'reversed'} "
                             "(lo must be below hi)")
        log = parts[3] == "log" if len(parts) == 4 else name == "eta"
        if log and lo <= 0:
            raise SweepError(f"axis {name}: a log-spaced axis needs lo > 0; got {lo:g}")
        pts = np.geomspace(lo, hi, n) if log else np.linspace(lo, hi, n)
        return name, pts
    return name, np.array([_number(name, v) for v in values.split(",") if v.strip()])


def parse_fixed(spec: str) -> tuple[str, float]:
    """``name=value`` (``eta=inf`` for a half-space below)."""
    if "=" not in spec:
        raise SweepError(f"fixed {spec!r}: expected name=value")
    name, _, value = (s.strip() for s in spec.partition("="))
    return name, _number(name, value)


def _number(name: str, text: str) -> float:
    """A float from text; only float() is applied (nothing is evaluated)."""
    try:
        return float(text)
    except ValueError:
        raise SweepError(f"{name}: {text!r} is not a number") from None


def make_plan(axes: Mapping[str, Sequence[float] | np.ndarray], *, fixed: Mapping[str, float] | None = None,
              kH: Sequence[float] | np.ndarray | None = None, rtol: float | None = None, growth: bool = True,
              gamma_c: bool = True, gamma_range: tuple[float, float] | None = None, count: CountSpec | None = None,
              chunk_points: int | None = None, adaptive: AdaptiveSpec | bool | Mapping[str, Any] | None = None,
              sliding: SlidingSpec | bool | None = None) -> Plan:
    """Validate a sweep and fix its chunks; SweepError (a ValueError) naming the problem otherwise.

    axes: parameter name -> strictly increasing finite values in the model's domain (η = ∞ only as a fixed
    value); fixed: values of other parameters (the rest take :data:`DEFAULT_FIXED`); kH: the grid on which the
    growth is bracketed (increasing, > 0; default :data:`DEFAULT_KH`); gamma_range: where γ_c is searched
    (default: the γ axis' range if γ is an axis of more than one value, else (1e-2, 1e3)); chunk_points: grid
    points per growth chunk (default :data:`CHUNK_POINTS`, adaptive :data:`asymslide.atlas.adaptive.CHUNK_POINTS`);
    adaptive: None or False (the dense sweep), True or an :class:`~asymslide.atlas.adaptive.AdaptiveSpec` (levels,
    margin, guard, follow, verdict; every axis must have m·2^levels + 1 points); sliding: None or False (the
    Rayleigh branch only), True or a :class:`SlidingSpec` (also the sliding verdict over every branch). An adaptive
    sweep with the sliding verdict refines it (and the Rayleigh branch's verdict): its spec's verdict is "sliding"
    (None: taken from `sliding`; "sliding" without `sliding`: the model's default spec).
    """
    if not axes:
        raise SweepError("no axis given: a sweep needs at least one axis (e.g. gamma=0.1:30:64:log)")
    sliding = _checked_sliding(sliding)
    if not (growth or gamma_c or count is not None or sliding is not None):
        raise SweepError("nothing to compute: ask for the growth, gamma_c, the all-branch count or the sliding verdict")
    fixed = dict(fixed or {})
    clean_axes = {name: _checked_axis(name, values, fixed) for name, values in axes.items()}
    full_fixed = _checked_fixed(fixed, clean_axes)
    grid = _checked_kh(kH, rtol)
    if gamma_range is None:
        gamma_range = ((clean_axes["gamma"][0], clean_axes["gamma"][-1]) if len(clean_axes.get("gamma", ())) > 1
                       else (1e-2, 1e3))  # a gamma axis of one value has no range to search
    lo, hi = (float(x) for x in gamma_range)
    if not (0 < lo < hi < math.inf):
        raise SweepError(f"gamma_range must be 0 < lo < hi < inf; got {gamma_range}")
    count = None if count is None else _checked_count(count)
    spec = None if adaptive is None or adaptive is False else _checked_adaptive(adaptive, clean_axes, growth)
    if spec is not None:
        spec, sliding = _adaptive_verdict(spec, sliding)
    if chunk_points is None:
        chunk_points = CHUNK_POINTS if spec is None else _adaptive.CHUNK_POINTS
    if chunk_points < 1:
        raise SweepError(f"chunk_points must be >= 1; got {chunk_points}")
    return Plan(clean_axes, full_fixed, tuple(float(x) for x in grid), rtol, growth, gamma_c, (lo, hi), count,
                _plan_chunks(clean_axes, chunk_points), spec, sliding)


def _checked_axis(name: str, values: Sequence[float] | np.ndarray, fixed: Mapping[str, float]) -> tuple[float, ...]:
    """An axis's values as floats, or SweepError: a known parameter, not also fixed, non-empty, finite, strictly
    increasing and in the model's domain."""
    if name not in PARAMETERS:
        raise SweepError(f"unknown axis {name!r}; the axes can be {', '.join(PARAMETERS)}")
    if name in fixed:
        raise SweepError(f"{name} is given both as an axis and as a fixed value")
    v = np.asarray(values, dtype=float).ravel()
    if v.size == 0:
        raise SweepError(f"axis {name}: empty (no values)")
    if not np.all(np.isfinite(v)):
        raise SweepError(f"axis {name}: values must be finite (η = ∞ is allowed as a fixed value only)")
    if np.any(np.diff(v) <= 0):
        raise SweepError(f"axis {name}: values must be strictly increasing")
    try:
        model.check_parameter(name, v)
    except ValueError as exc:
        raise SweepError(f"axis {name}: {exc}") from None
    return tuple(float(x) for x in v)


def _checked_fixed(fixed: Mapping[str, float], axes: Mapping[str, tuple[float, ...]]) -> dict[str, float]:
    """Every parameter that is not an axis with its value: `fixed`'s (checked) or :data:`DEFAULT_FIXED`'s."""
    for name, value in fixed.items():
        if name not in PARAMETERS:
            raise SweepError(f"unknown fixed parameter {name!r}; the parameters are {', '.join(PARAMETERS)}")
        try:
            model.check_parameter(name, float(value))
        except (TypeError, ValueError) as exc:
            raise SweepError(f"fixed {name}: {exc}") from None
    return {k: float(fixed.get(k, DEFAULT_FIXED[k])) for k in PARAMETERS if k not in axes}


def _checked_kh(kH: Sequence[float] | np.ndarray | None, rtol: float | None) -> np.ndarray:
    """The growth's kH grid (default :data:`DEFAULT_KH`), increasing and positive; rtol checked by the model."""
    grid = DEFAULT_KH if kH is None else np.asarray(kH, dtype=float).ravel()
    if grid.size < 2 or not np.all(np.isfinite(grid)) or np.any(grid <= 0) or np.any(np.diff(grid) <= 0):
        raise SweepError("kH must be an increasing grid of at least 2 positive values")
    if rtol is not None:
        try:
            model.growth_chunk(np.log(grid[:2]), np.zeros((6, 0)), rtol)  # validates rtol (ValueError naming it)
        except ValueError as exc:
            raise SweepError(str(exc)) from None
    return grid


def _checked_count(count: CountSpec) -> CountSpec:
    """The all-branch count's kH grid (positive, finite) and window (re_max > 0, 0 <= im_min < im_max) as floats."""
    ck = np.asarray(count.kH, dtype=float)
    if ck.size < 1 or np.any(~np.isfinite(ck)) or np.any(ck <= 0):
        raise SweepError("the count's kH grid must hold positive finite values")
    re_max, im_min, im_max = (float(x) for x in count.window)
    if not (re_max > 0 and 0 <= im_min < im_max):
        raise SweepError(f"count window must be re_max > 0, 0 <= im_min < im_max; got {count.window}")
    return CountSpec(tuple(float(x) for x in ck), (re_max, im_min, im_max))


def _checked_sliding(sliding: SlidingSpec | bool | None) -> SlidingSpec | None:
    """The sliding spec (True: the model's defaults) with its kH grid (increasing, positive, at least 2) and floor
    checked."""
    if sliding is None or sliding is False:
        return None
    spec = SlidingSpec() if sliding is True else sliding
    grid = np.asarray(spec.kH, dtype=float).ravel()
    if grid.size < 2 or not np.all(np.isfinite(grid)) or np.any(grid <= 0) or np.any(np.diff(grid) <= 0):
        raise SweepError("the sliding kH grid must be an increasing grid of at least 2 positive values")
    floor = float(spec.floor)
    if not (math.isfinite(floor) and floor > 0):
        raise SweepError(f"the sliding floor must be a positive finite growth; got {spec.floor!r}")
    return SlidingSpec(tuple(float(x) for x in grid), floor, bool(spec.thresholds))


def _checked_adaptive(adaptive: AdaptiveSpec | bool | Mapping[str, Any], axes: Mapping[str, tuple[float, ...]],
                      growth: bool) -> AdaptiveSpec:
    """The resolved refinement spec; every axis must have m·2^levels + 1 points."""
    if not growth:
        raise SweepError("an adaptive sweep refines the growth's verdict: it needs the growth variables")
    shape = tuple(len(v) for v in axes.values())
    try:
        spec = _adaptive.resolve_spec(adaptive, shape)
        _adaptive.check_shape(tuple(axes), shape, spec.levels)  # type: ignore[arg-type]
    except (TypeError, ValueError) as exc:
        raise SweepError(str(exc)) from None
    return spec


def _adaptive_verdict(spec: AdaptiveSpec, sliding: SlidingSpec | None) -> tuple[AdaptiveSpec, SlidingSpec | None]:
    """The adaptive spec with its verdict fixed, and the sliding spec it needs: refining the sliding verdict computes
    it (the model's default spec unless one is given); refining the Rayleigh branch's alone with the sliding verdict
    asked for is refused (the sliding verdict would be filled from cells whose corners agree only on the Rayleigh
    branch's)."""
    verdict = spec.verdict or (_adaptive.SLIDING if sliding is not None else _adaptive.RAYLEIGH)
    if verdict == _adaptive.RAYLEIGH and sliding is not None:
        raise SweepError("an adaptive sweep refining the Rayleigh branch's verdict cannot give the sliding verdict "
                         "(it would be filled from cells refined on the Rayleigh branch alone): refine on the sliding "
                         "verdict (--verdict sliding) or drop --sliding")
    if verdict == _adaptive.SLIDING and sliding is None:
        sliding = SlidingSpec()
    return replace(spec, verdict=verdict), sliding


def _plan_chunks(axes: Mapping[str, tuple[float, ...]], chunk_points: int) -> dict[str, int]:
    """Chunk lengths per axis of the growth (key: the axis), of gamma_c ("gamma_c:<axis>", over the axes other than
    gamma) and of the count ("count:<axis>"), from the growth's points per chunk."""
    shape = [len(v) for v in axes.values()]
    chunks = dict(zip(axes, chunk_sizes(shape, chunk_points), strict=True))
    gc_names = [n for n in axes if n != "gamma"]
    gc = chunk_sizes([len(axes[n]) for n in gc_names], max(1, chunk_points * GAMMA_C_CHUNK_POINTS // CHUNK_POINTS))
    chunks.update({f"gamma_c:{n}": c for n, c in zip(gc_names, gc, strict=True)})
    cc = chunk_sizes(shape, max(1, chunk_points * COUNT_CHUNK_POINTS // CHUNK_POINTS))
    chunks.update({f"count:{n}": c for n, c in zip(axes, cc, strict=True)})
    sc = chunk_sizes(shape, max(1, chunk_points * SLIDING_CHUNK_POINTS // CHUNK_POINTS))
    chunks.update({f"sliding:{n}": c for n, c in zip(axes, sc, strict=True)})
    return chunks


# ------------------------------------------------------------------------------------------------
# tasks: pure functions of one chunk, run wherever the scheduler puts them
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Task:
    """One chunk of one variable group: `kind` ("growth", "gamma_c" or "count"), its index among the group's
    chunks, its index ranges and the axis values of the chunk (so a worker needs nothing else)."""

    kind: str
    index: int
    block: tuple[tuple[int, int], ...]
    names: tuple[str, ...]
    values: tuple[tuple[float, ...], ...]
    fixed: tuple[tuple[str, float], ...]
    kH: tuple[float, ...]
    rtol: float | None
    gamma_range: tuple[float, float]
    count: CountSpec | None
    sliding: SlidingSpec | None = None

    @property
    def points(self) -> int:
        return math.prod(len(v) for v in self.values)

    @property
    def holds_gil(self) -> bool:
        """Whether the task's model calls hold the GIL (the sliding verdict and its thresholds: Python around the
        compiled kernels), so that threads do not run it in parallel: :func:`_execute` gives it processes."""
        return self.kind in GIL_KINDS


def _params(task: Task) -> tuple[tuple[int, ...], np.ndarray]:
    """The chunk's grid points as growth_chunk's (6, n) parameter rows (gamma, f, beta, eta, Delta, xi)."""
    shape = tuple(len(v) for v in task.values)
    mesh = np.meshgrid(*(np.asarray(v) for v in task.values), indexing="ij")
    columns = dict(zip(task.names, (m.ravel() for m in mesh), strict=True))
    n = math.prod(shape)
    fixed = dict(task.fixed)
    # a parameter neither in the chunk nor fixed is the one a threshold task solves for (its row is ignored)
    rows = [columns[p] if p in columns else np.full(n, fixed.get(p, math.nan)) for p in PARAMETERS]
    return shape, np.ascontiguousarray(np.stack(rows))


def growth_arrays(s: np.ndarray, params: np.ndarray, rtol: float | None) -> dict[str, np.ndarray]:
    """The growth variables (1-D, one value per column of `params`) of :func:`model.growth_chunk` on the ln kH grid
    `s`: the same operations as model.growth_analysis, so the values are bitwise equal (each point is computed on
    its own: the dense and the adaptive sweep give the same bits at a point whatever else a chunk holds)."""
    out = model.growth_chunk(s, params, rtol)
    reason = out[7].astype(np.int8)  # as model.growth_analysis (the kernel always gives a code)
    return {"growth": out[0], "kH_at_max": np.exp(out[1]), "kH_min": np.exp(out[2]), "kH_max": np.exp(out[3]),
            "n_masked": out[4].astype(np.int16), "verdict": model.verdict_class(reason), "verdict_reason": reason}


def sliding_arrays(spec: SlidingSpec, params: np.ndarray) -> dict[str, np.ndarray]:
    """The sliding variables (1-D, one per column of `params`) of :func:`model.sliding_chunk`: the numbers
    :func:`model.sliding_analysis` gives at the same point."""
    rows = dict(zip(model.SLIDING_ROWS, model.sliding_chunk(np.log(np.asarray(spec.kH)), params, spec.floor),
                    strict=True))
    reason = rows["verdict_reason_all"].astype(np.int8)
    return {"growth_all": rows["growth_all"], "kH_at_max_all": np.exp(rows["ln_kH_at_max_all"]),
            "re_z_at_max_all": rows["re_z_at_max_all"], "family_all": model.family_codes(rows["family_all"]),
            "verdict_all": model.sliding_verdict(reason), "verdict_reason_all": reason,
            "max_at_end_all": (rows["max_at_end_all"] == 1.0).astype(np.int8),
            "lower_bound_all": np.isfinite(params[PARAMETERS.index("eta")]).astype(np.int8)}


def run_task(task: Task) -> dict[str, np.ndarray]:
    """Compute one chunk (the only code that runs on a worker): model calls, nothing else."""
    shape, params = _params(task)
    s = np.log(np.asarray(task.kH))
    if task.kind == "growth":
        return {name: arr.reshape(shape) for name, arr in growth_arrays(s, params, task.rtol).items()}
    if task.kind == "gamma_c":
        return _crossing_arrays(model.crossings_chunk("gamma", s, params, task.gamma_range, task.rtol, CROSSINGS),
                                shape)
    if task.kind == "gamma_c_all":
        assert task.sliding is not None
        c = model.crossings_chunk("gamma", np.log(np.asarray(task.sliding.kH)), params, task.gamma_range, None,
                                  CROSSINGS, "all", task.sliding.floor)
        return {_all(name): arr for name, arr in _crossing_arrays(c, shape).items()}
    if task.kind == "count":
        assert task.count is not None
        re_max, im_min, im_max = task.count.window
        counts = np.empty((params.shape[1], len(task.count.kH)), np.int16)
        for i in range(params.shape[1]):
            p = dict(zip(PARAMETERS, (float(x) for x in params[:, i]), strict=True))
            for j, k in enumerate(task.count.kH):
                try:
                    counts[i, j] = model.unstable_count(k, **p, re_max=re_max, im_min=im_min, im_max=im_max)
                except (RuntimeError, ValueError):
                    counts[i, j] = -1  # the count failed (flag in the variable's attributes)
        return {"unstable_count": counts.reshape((*shape, len(task.count.kH)))}
    if task.kind == "sliding":
        assert task.sliding is not None
        return {name: arr.reshape(shape) for name, arr in sliding_arrays(task.sliding, params).items()}
    raise ValueError(f"unknown task kind {task.kind!r}")


def _crossing_arrays(c: model.Crossings, shape: tuple[int, ...]) -> dict[str, np.ndarray]:
    """The threshold variables of one chunk from model.crossings_chunk: the first certified crossing, its status,
    every crossing (last dimension ``crossing``) and their summaries."""
    k = (*shape, CROSSINGS)
    return {"gamma_c": c.first.reshape(shape), "gamma_c_reason": c.status.astype(np.int8).reshape(shape),
            "gamma_c_crossing": c.value.reshape(k), "gamma_c_location": c.location.reshape(k),
            "gamma_c_kH": c.kH.reshape(k), "gamma_c_z": c.z.reshape(k),
            "gamma_c_direction": c.direction.astype(np.int8).reshape(k),
            "gamma_c_crossing_reason": c.reason.astype(np.int8).reshape(k),
            "gamma_c_n_crossings": c.count.astype(np.int16).reshape(shape),
            "gamma_c_complete": c.complete.astype(np.int8).reshape(shape)}


def sliding_thresholds(plan: Plan) -> bool:
    """Whether the plan computes the threshold of sliding in gamma (``gamma_c_all``): gamma_c with the sliding
    verdict and its ``thresholds``."""
    return plan.gamma_c and plan.sliding is not None and plan.sliding.thresholds


def tasks(plan: Plan, kinds: Sequence[str] | None = None) -> dict[str, list[Task]]:
    """Every task of the plan, per kind."""
    common = dict(fixed=tuple(plan.fixed.items()), kH=plan.kH, rtol=plan.rtol, gamma_range=plan.gamma_range,
                  count=plan.count, sliding=plan.sliding)
    groups: dict[str, tuple[tuple[str, ...], list]] = {}
    if plan.growth:
        groups["growth"] = (plan.names, plan.growth_blocks())
    if plan.gamma_c:
        groups["gamma_c"] = (plan.gamma_c_names, plan.gamma_c_blocks())
    if sliding_thresholds(plan):
        groups["gamma_c_all"] = (plan.gamma_c_names, plan.gamma_c_blocks())
    if plan.count is not None:
        groups["count"] = (plan.names, plan.count_blocks())
    if plan.sliding is not None:
        groups["sliding"] = (plan.names, plan.sliding_blocks())
    out: dict[str, list[Task]] = {}
    for kind, (names, blocks) in groups.items():
        if kinds is not None and kind not in kinds:
            continue
        out[kind] = [Task(kind, i, b, names, tuple(plan.axes[n][a:z] for n, (a, z) in zip(names, b, strict=True)),
                          **common) for i, b in enumerate(blocks)]
    return out


# ------------------------------------------------------------------------------------------------
# the store
# ------------------------------------------------------------------------------------------------


@functools.cache
def model_fingerprint() -> str:
    """sha256 of the model's source and data files, its kernel package's included: any change of the model is another
    model version."""
    h = hashlib.sha256()
    root = Path(model.__file__).parent
    for path in sorted([*root.rglob("*.py"), *root.rglob("*.json")]):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()


@functools.cache
def git_revision() -> str:
    """The git commit of the source tree this package runs from ("+dirty" with uncommitted model changes), or
    "unknown" for an installed package."""
    root = Path(__file__).resolve().parent.parent
    try:
        rev = subprocess.run(["git", "-C", str(root), "rev-parse", "--short=12", "HEAD"], capture_output=True,
                             text=True, timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--", "model"],
                               capture_output=True, text=True, timeout=10, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return rev + ("+dirty" if dirty else "")


def _attrs(plan: Plan, command: str | None) -> dict[str, Any]:
    return {
        "title": "asymslide stability atlas: Rayleigh-branch growth and the threshold gamma_c",
        "source": "Aldam et al., Frictional sliding without geometrical reflection symmetry, PRX 6, 041023 (2016); "
                  "docs/physics.md §9",
        "asymslide_version": __version__,
        "model_fingerprint": model_fingerprint(),
        "git_revision": git_revision(),
        "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "plan": json.dumps(plan.identity()),
        "fixed": json.dumps({k: _json_float(v) for k, v in plan.fixed.items()}),
        "kH_grid": f"{len(plan.kH)} points from {plan.kH[0]:g} to {plan.kH[-1]:g} (variable kH)",
        "rtol": "None (full certified accuracy)" if plan.rtol is None else float(plan.rtol),
        "command": command or "",
        **({"adaptive": json.dumps(adaptive_summary(plan.shape, plan.adaptive))} if plan.adaptive else {}),
    }


def _long_name(name: str) -> str:
    p = model.PARAMETERS[name]
    return f"{p.symbol}: {p.description}"


def axis_scale(values: Any) -> str:
    """"log" if the axis's values are log-spaced (more than two, positive, a constant ratio), else "linear": the
    ``scale`` attribute of a store's axis, and how the Atlas tab reads a store written without it."""
    v = np.asarray(values, dtype=float)
    log = v.size > 2 and v[0] > 0 and bool(np.allclose(np.diff(np.log(v)), np.log(v[1] / v[0])))
    return "log" if log else "linear"


def template(plan: Plan, command: str | None = None):
    """The empty dataset of a plan (lazy arrays of fill values, chunked as the store), with every attribute."""
    import dask.array as da
    import xarray as xr

    coords: dict[str, Any] = {}
    for name, values in plan.axes.items():
        p = model.PARAMETERS[name]
        scale = axis_scale(values)
        coords[name] = (name, np.asarray(values), {"long_name": _long_name(name), "units": "1", "symbol": p.symbol,
                                                   "scale": scale})
    coords["kH"] = ("kH", np.asarray(plan.kH), {"long_name": "the kH grid the growth is bracketed on (then refined "
                                                "between its points)", "units": "1"})
    data: dict[str, Any] = {}
    flags: dict[str, int] = {}
    if plan.growth:
        data.update(_growth_vars(plan))
        if plan.adaptive is None:
            flags["growth"] = len(plan.growth_blocks())
    if plan.gamma_c:
        coords["crossing"] = ("crossing", np.arange(CROSSINGS), {"long_name": "index of a sign change of the max "
                                                                 "growth in gamma, in increasing gamma"})
        data.update(_gamma_c_vars(plan))
        flags["gamma_c"] = len(plan.gamma_c_blocks())
    if sliding_thresholds(plan):
        data.update(_gamma_c_all_vars(plan))
        flags["gamma_c_all"] = len(plan.gamma_c_blocks())
    if plan.count is not None:
        coords["kH_count"] = ("kH_count", np.asarray(plan.count.kH), {"long_name": "kH of the all-branch count",
                                                                      "units": "1"})
        data.update(_count_vars(plan))
        flags["count"] = len(plan.count_blocks())
    if plan.sliding is not None:
        coords["kH_sliding"] = ("kH_sliding", np.asarray(plan.sliding.kH),
                                {"long_name": "the kH grid of the sliding verdict (its ends are the range)",
                                 "units": "1"})
        data.update(_sliding_vars(plan))
        if plan.adaptive is None:  # an adaptive sweep's ``computed`` is its done flag, per point
            flags["sliding"] = len(plan.sliding_blocks())
    for kind, n in flags.items():
        data[f"done_{kind}"] = (f"{kind}_chunk", da.zeros(n, dtype=np.int8, chunks=1),
                                {"long_name": f"1 where the {kind} chunk is written (resumable sweeps)"})
    return xr.Dataset(data, coords=coords, attrs=_attrs(plan, command))


def _flag_attrs(meanings: Mapping[int, str]) -> dict[str, Any]:
    """CF flag_values / flag_meanings (the codes' texts, as JSON) of a variable of codes."""
    codes = sorted(meanings)
    return {"flag_values": codes, "flag_meanings": json.dumps({str(k): meanings[k] for k in codes})}


def _growth_vars(plan: Plan) -> dict[str, Any]:
    """The template's growth variables over the grid, with the adaptive sweep's own if the plan is adaptive (its
    ``computed`` is the done flag, per point)."""
    import dask.array as da

    dims = plan.names
    chunks = tuple(plan.chunks[n] for n in dims)
    meanings = {"verdict": model.VERDICTS, "verdict_reason": model.VERDICT_STATUS}
    data: dict[str, Any] = {}
    for name, (dtype, fill, long_name, units) in GROWTH_VARS.items():
        attrs = {"long_name": long_name, "units": units, **(_flag_attrs(meanings[name]) if name in meanings else {})}
        data[name] = (dims, da.full(plan.shape, fill, dtype=dtype, chunks=chunks), attrs)
    if plan.adaptive is not None:
        for name, (dtype, fill, long_name, attrs) in _adaptive_vars(plan.adaptive, plan.sliding is not None).items():
            data[name] = (dims, da.full(plan.shape, fill, dtype=dtype, chunks=chunks),
                          {"long_name": long_name, "units": "1", **attrs})
    return data


def _gamma_c_vars(plan: Plan) -> dict[str, Any]:
    """The template's threshold variables: gamma_c and its reason over the axes other than gamma, the crossings
    (with the dimension ``crossing``) and their summaries."""
    import dask.array as da

    gdims = plan.gamma_c_names
    gshape = tuple(len(plan.axes[n]) for n in gdims)
    gchunks = tuple(plan.chunks[f"gamma_c:{n}"] for n in gdims) or None
    data: dict[str, Any] = {
        "gamma_c": (gdims, da.full(gshape, np.nan, chunks=gchunks),
                    {"long_name": "the threshold gamma_c: the first certified crossing of the max growth on the "
                                  f"Rayleigh branch (searched in gamma {plan.gamma_range[0]:g} to "
                                  f"{plan.gamma_range[1]:g})", "units": "1"}),
        "gamma_c_reason": (gdims, da.full(gshape, INT_FILL["gamma_c_reason"], dtype=np.int8, chunks=gchunks),
                           {"long_name": "why gamma_c is NaN (0: found)", **_flag_attrs(model.THRESHOLD_STATUS)}),
    }
    xchunks = (*(gchunks or gshape), CROSSINGS)
    for name, (dtype, fill, long_name) in CROSSING_VARS.items():
        attrs = {"long_name": long_name, "units": "1"}
        if name == "gamma_c_crossing_reason":
            attrs.update(_flag_attrs(model.CROSSING_STATUS))
        data[name] = ((*gdims, "crossing"), da.full((*gshape, CROSSINGS), fill, dtype=dtype, chunks=xchunks), attrs)
    for name, (dtype, fill, long_name) in CROSSING_SUMMARY_VARS.items():
        data[name] = (gdims, da.full(gshape, fill, dtype=dtype, chunks=gchunks), {"long_name": long_name, "units": "1"})
    return data


def _gamma_c_all_vars(plan: Plan) -> dict[str, Any]:
    """The template's sliding threshold variables (every branch): the Rayleigh branch's, renamed, with their long
    names saying so and the floor and kH range of the search."""
    spec = plan.sliding
    assert spec is not None
    data = {}
    for name, (dims, arr, attrs) in _gamma_c_vars(plan).items():
        long_name = attrs["long_name"].replace("on the Rayleigh branch", "over every branch")
        data[_all(name)] = (dims, arr, {**attrs, "long_name": f"sliding (every branch, growth floor {spec.floor:g}, kH "
                                                              f"{spec.kH[0]:g} to {spec.kH[-1]:g}): {long_name}",
                                        "floor": spec.floor})
    return data


def _count_vars(plan: Plan) -> dict[str, Any]:
    """The template's all-branch count over the grid and ``kH_count``."""
    import dask.array as da

    cchunks = (*(plan.chunks[f"count:{n}"] for n in plan.names), len(plan.count.kH))
    re_max, im_min, im_max = plan.count.window
    return {"unstable_count": ((*plan.names, "kH_count"),
                               da.full((*plan.shape, len(plan.count.kH)), INT_FILL["unstable_count"], dtype=np.int16,
                                       chunks=cchunks),
                               {"long_name": "roots of F (any branch) with |Re z| <= re_max and im_min <= Im z <= "
                                             "im_max (argument principle; -1: the count failed)",
                                "re_max": re_max, "im_min": im_min, "im_max": im_max, "units": "1"})}


def _sliding_vars(plan: Plan) -> dict[str, Any]:
    """The template's sliding variables over the grid (every branch; the floor in each one's attributes)."""
    import dask.array as da

    # an adaptive sweep writes them with the growth variables, chunked as those
    chunks = tuple(plan.chunks[n if plan.adaptive is not None else f"sliding:{n}"] for n in plan.names)
    meanings = {"verdict_all": model.VERDICTS, "verdict_reason_all": model.SLIDING_STATUS,
                "family_all": {-1: "none", **model.FAMILIES}}
    data: dict[str, Any] = {}
    for name, (dtype, fill, long_name) in SLIDING_VARS.items():
        attrs = {"long_name": long_name, "units": "1", "floor": plan.sliding.floor,  # type: ignore[union-attr]
                 **(_flag_attrs(meanings[name]) if name in meanings else {})}
        data[name] = (plan.names, da.full(plan.shape, fill, dtype=dtype, chunks=chunks), attrs)
    return data


#: Zarr fill values (what a chunk not written yet reads as) of the integer variables; floats: NaN
INT_FILL = {"n_masked": -1, "gamma_c_reason": -1, "unstable_count": -2, "verdict": -1, "verdict_reason": -1,
            "gamma_c_direction": 0, "gamma_c_crossing_reason": -1, "gamma_c_n_crossings": -1, "gamma_c_complete": -1,
            "computed": -1, "verdict_filled": -1, "verdict_filled_all": -1, "gamma_c_all_reason": -1,
            "gamma_c_all_direction": 0, "gamma_c_all_crossing_reason": -1, "gamma_c_all_n_crossings": -1,
            "gamma_c_all_complete": -1,
            **{name: v[1] for name, v in SLIDING_VARS.items() if np.dtype(v[0]).kind == "i"}}


def _adaptive_vars(spec: AdaptiveSpec, sliding: bool = False) -> dict[str, tuple[Any, int, str, dict[str, Any]]]:
    """The adaptive sweep's variables: dtype, fill, long name, further attributes (`sliding`: also the filled
    sliding verdict)."""
    levels = spec.levels or 0
    meanings = {"-1": "not computed (growth NaN there; its class is in verdict_filled)",
                **{str(k): f"computed at level {k} (stride {2 ** (levels - k)})" for k in range(levels + 1)}}
    classes = {"flag_values": sorted(model.VERDICTS),
               "flag_meanings": json.dumps({str(k): v for k, v in model.VERDICTS.items()})}
    filled_all = {"verdict_filled_all": (
        np.int8, -1, "sliding verdict class (every branch above the floor) at every point: the model's where computed, "
        "else the common class of the corners of the finest computed cell holding the point (-1: not yet filled)",
        classes)} if sliding else {}
    return {
        "computed": (np.int8, -1, "the refinement level at which the point was computed (-1: not computed)",
                     {"flag_values": list(range(-1, levels + 1)), "flag_meanings": json.dumps(meanings)}),
        "verdict_filled": (np.int8, -1, "verdict class at every point: the model's verdict where computed, else the "
                           "common class of the corners of the finest computed cell holding the point (-1: not yet "
                           "filled)", classes),
        **filled_all,
    }


def _encoding(ds, fast: bool = False) -> dict[str, dict]:
    """Fill values; `fast`: Zstandard at level 1 instead of Zarr's default level (the same size on atlas data, ~3x
    faster to write: an adaptive sweep rewrites a chunk at every level that touches it)."""
    extra: dict[str, Any] = {}
    if fast:
        from zarr.codecs import ZstdCodec

        extra = {"compressors": [ZstdCodec(level=1)]}
    return {name: {"fill_value": np.nan if var.dtype.kind == "f" else INT_FILL.get(name, 0), **extra}
            for name, var in ds.data_vars.items()}


def _refuse(store: Path, why: str) -> SweepError:
    return SweepError(f"refusing to resume {store}: {why}. Nothing was written; use another --out or remove it.")


def check_resumable(store: Path, plan: Plan) -> None:
    """SweepError saying why the existing store cannot continue this plan (another plan or another model)."""
    import xarray as xr

    try:
        ds = xr.open_zarr(store, consolidated=False)
    except Exception as exc:  # noqa: BLE001 (any failure to read it means: not ours)
        raise _refuse(store, f"it is not a readable atlas ({type(exc).__name__}: {exc})") from None
    attrs = ds.attrs
    if "plan" not in attrs or "model_fingerprint" not in attrs:
        raise _refuse(store, "it was not written by asymslide sweep")
    theirs, ours = json.loads(attrs["plan"]), plan.identity()
    if theirs != ours:
        raise _refuse(store, "it was written with " + _plan_difference(theirs, ours))
    if attrs["model_fingerprint"] != model_fingerprint():
        raise _refuse(store, f"it was written by another model version (asymslide {attrs.get('asymslide_version')}, "
                             f"git {attrs.get('git_revision')}, model {attrs['model_fingerprint'][:12]}; this is "
                             f"asymslide {__version__}, git {git_revision()}, model {model_fingerprint()[:12]})")


def _plan_difference(theirs: dict, ours: dict) -> str:
    def axes_text(p: dict) -> str:
        return ", ".join(f"{k}({len(v)}: {v[0]:g}..{v[-1]:g})" for k, v in p["axes"].items())

    if theirs.get("axes") != ours["axes"]:
        return f"other axes: {axes_text(theirs)}; this sweep asks for {axes_text(ours)}"
    for key in ("adaptive", "fixed", "kH", "rtol", "gamma_c", "gamma_range", "count", "chunks"):
        if theirs.get(key) != ours.get(key):  # "adaptive" is in adaptive plans only
            return f"another {key}: {theirs.get(key)!r:.200}; this sweep asks for {ours.get(key)!r:.200}"
    return "another plan"


def done_chunks(store: Path) -> dict[str, np.ndarray]:
    """kind -> boolean array: which chunks of the store are written."""
    import xarray as xr

    ds = xr.open_zarr(store, consolidated=False)
    return {name[len("done_"):]: ds[name].values.astype(bool) for name in ds.data_vars if name.startswith("done_")}


def store_stamp(store: str | os.PathLike) -> str:
    """A short text that changes whenever a sweep writes to the store (its done flags; an adaptive sweep's summary,
    written when its grid variables are): readers cache an atlas by it."""
    import xarray as xr

    ds = xr.open_zarr(Path(store), consolidated=False)
    flags = {name: int(ds[name].values.sum()) for name in ds.data_vars if name.startswith("done_")}
    adaptive = json.loads(ds.attrs.get("adaptive", "{}"))
    return json.dumps({**flags, "adaptive_evaluated": adaptive.get("evaluated")})


def _write(store: Path, task: Task, result: dict[str, np.ndarray], region_dims: dict[str, tuple[str, ...]]) -> None:
    """Region write of one chunk, then its done flag (atomic files: a kill leaves the chunk unmarked)."""
    import xarray as xr

    dims = region_dims[task.kind]
    region = {n: slice(a, z) for n, (a, z) in zip(task.names, task.block, strict=True)}
    data = {}
    for name, arr in result.items():
        var_dims = (*dims, "kH_count") if name == "unstable_count" else (
            (*dims, "crossing") if name in CROSSING_VARS or name in CROSSING_ALL_VARS else dims)
        data[name] = (var_dims, arr)
    if task.kind == "count":
        region = {**region, "kH_count": slice(0, len(task.count.kH))}  # type: ignore[union-attr]
    if task.kind in ("gamma_c", "gamma_c_all"):
        region = {**region, "crossing": slice(0, CROSSINGS)}
    xr.Dataset(data).to_zarr(store, region=region, consolidated=False)
    flag = np.ones(1, np.int8)
    xr.Dataset({f"done_{task.kind}": (f"{task.kind}_chunk", flag)}).to_zarr(
        store, region={f"{task.kind}_chunk": slice(task.index, task.index + 1)}, consolidated=False)


# ------------------------------------------------------------------------------------------------
# running
# ------------------------------------------------------------------------------------------------

Progress = Callable[[str, int], None]


class _ResultQueue:
    """Hands finished chunks to one thread that calls `on_result` on them in order of completion, so that a worker
    thread starts its next chunk at once instead of waiting while the last one is written (Dask's threaded
    scheduler runs its callbacks before it gives a worker new work). An error of `on_result` stops the sweep.

    At most `backlog` finished chunks wait: beyond that :meth:`put` blocks, and with it the scheduler's next task,
    so that the workers never run far ahead of a slow writer (many small chunks, a slow disk). The backlog is what a
    Ctrl-C still writes before the sweep stops, and what memory holds."""

    def __init__(self, on_result: Callable[[Any, dict[str, np.ndarray]], None], backlog: int) -> None:
        self._on_result = on_result
        self._queue: queue.Queue = queue.Queue(maxsize=backlog)
        self._error: BaseException | None = None
        self._thread = threading.Thread(target=self._run, name="asymslide-writer", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while (item := self._queue.get()) is not None:
            if self._error is None:
                try:
                    self._on_result(*item)
                except BaseException as exc:  # noqa: BLE001 (handed to the sweep's thread by put/close)
                    self._error = exc

    def put(self, task: Any, result: dict[str, np.ndarray]) -> None:
        if self._error is not None:
            raise self._error
        self._queue.put((task, result))

    def close(self) -> None:
        """Write what is queued (a Ctrl-C keeps every finished chunk), then re-raise a writing error."""
        self._queue.put(None)
        self._thread.join()
        if self._error is not None:
            raise self._error


#: chunks handed to Dask's threaded scheduler at once: it keeps their results until the batch is done (memory),
#: and a batch ends with one worker waiting for the other's last chunk (~half a chunk's time lost per batch)
THREADED_BATCH = 256


def _spawnable() -> bool:
    """Whether spawned processes can start here: they import the main module by its path, which a script read from
    stdin has not (``python -c``, ``-m`` and notebooks have or need none)."""
    import sys

    main = getattr(sys.modules.get("__main__"), "__file__", None)
    return main is None or os.path.exists(main)


#: the process pools of the sweep running (workers -> pool): started when its first tasks that hold the GIL come,
#: shut down when the sweep ends (:func:`_sweep_processes`)
_POOLS: dict[int, Any] = {}
#: open :func:`_sweep_processes` blocks (a sweep in a sweep keeps the outer one's pools)
_SCOPES: list[None] = []


@contextlib.contextmanager
def _sweep_processes() -> Iterator[None]:
    """Keep the process pools started inside (by :func:`_process_pool`) until the block ends, then shut them down
    (a pool kept for the life of the process hung pytest's exit)."""
    outer = set(_POOLS)
    _SCOPES.append(None)
    try:
        yield
    finally:
        _SCOPES.pop()
        for key in [k for k in _POOLS if k not in outer]:
            _POOLS.pop(key).shutdown(wait=True, cancel_futures=True)


def _process_pool(workers: int):
    """The process pool for tasks that hold the GIL (:attr:`Task.holds_gil`): `workers` spawned processes, each
    importing the model once (the compiled kernels come from their on-disk cache), kept while the sweep runs."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    if workers not in _POOLS:
        _POOLS[workers] = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"))
    return _POOLS[workers]


def _execute_in_processes(todo: Sequence[Any], on_result: Callable[[Any, dict[str, np.ndarray]], None],
                          workers: int, run: Callable[[Any], dict[str, np.ndarray]]) -> None:
    """Run `todo` in :func:`_process_pool`, calling `on_result` in this thread as each task finishes; the tasks
    not started are cancelled if this is interrupted (a task running finishes in its process)."""
    with contextlib.ExitStack() as stack:
        if not _SCOPES:  # outside a sweep (a direct call): a pool for this call only
            stack.enter_context(_sweep_processes())
        pool = _process_pool(workers)
        _collect(pool, todo, on_result, run)


def _collect(pool, todo: Sequence[Any], on_result: Callable[[Any, dict[str, np.ndarray]], None],
             run: Callable[[Any], dict[str, np.ndarray]]) -> None:
    """Submit `todo` to `pool` and hand each result to `on_result` as it comes; cancel what has not started if
    interrupted."""
    from concurrent.futures import as_completed

    futures = {pool.submit(run, t): t for t in todo}
    try:
        for future in as_completed(futures):
            on_result(futures[future], future.result())
    finally:
        for future in futures:
            future.cancel()


def _execute(todo: Sequence[Any], on_result: Callable[[Any, dict[str, np.ndarray]], None], client=None,
             workers: int | None = None, run: Callable[[Any], dict[str, np.ndarray]] | None = None) -> None:
    """Run `todo` (tasks with a `kind` and an `index`, unique together), calling `on_result` in one thread as each
    task finishes (in any order); `run`: the function of a task (default :func:`run_task`). Without a client: Dask's
    threaded scheduler, and for the tasks that hold the GIL (the sliding verdict: two threads 0.93x one thread's
    speed, two processes 1.76x; ``bench_sliding.threads_vs_processes``) `workers` processes."""
    if not todo:
        return
    run = run or run_task
    if client is not None:
        from distributed import as_completed

        futures = client.map(run, todo, pure=False)
        by_key = {f.key: t for f, t in zip(futures, todo, strict=True)}
        try:
            for future, result in as_completed(futures, with_results=True):
                on_result(by_key[future.key], result)
                future.release()
        finally:
            client.cancel(futures)
        return
    n_workers = workers or os.cpu_count() or 1
    gil = [t for t in todo if getattr(t, "holds_gil", False)]
    if n_workers > 1 and len(gil) > 1 and _spawnable():  # threads would run them one at a time
        todo = [t for t in todo if not getattr(t, "holds_gil", False)]
        _execute_threaded(todo, on_result, n_workers, run)
        _execute_in_processes(gil, on_result, n_workers, run)
        return
    _execute_threaded(todo, on_result, n_workers, run)


def _execute_threaded(todo: Sequence[Any], on_result: Callable[[Any, dict[str, np.ndarray]], None], n_workers: int,
                      run: Callable[[Any], dict[str, np.ndarray]]) -> None:
    """Run `todo` on Dask's threaded scheduler (`n_workers` threads; the compiled kernels release the GIL), in
    batches of :data:`THREADED_BATCH`, handing each result to `on_result` in a writer thread."""
    if not todo:
        return
    import dask.threaded
    from dask.callbacks import Callback

    results: dict[str, Any] = {}
    writer = _ResultQueue(on_result, backlog=2 * n_workers)

    class _Handover(Callback):
        def _posttask(self, key, result, dsk, state, worker_id):  # noqa: ARG002 (dask's signature)
            writer.put(results[key], result)

    try:
        for start in range(0, len(todo), THREADED_BATCH):
            part = todo[start:start + THREADED_BATCH]
            graph = {}
            for t in part:
                key = f"{t.kind}-{t.index}"
                results[key] = t
                graph[key] = (run, t)
            with _Handover():
                dask.threaded.get(graph, list(graph), num_workers=n_workers)
            for key in graph:
                results.pop(key, None)
    finally:
        writer.close()


def sweep(axes: Mapping[str, Sequence[float] | np.ndarray], *, fixed: Mapping[str, float] | None = None,
          kH: Sequence[float] | np.ndarray | None = None, rtol: float | None = None,
          store: str | os.PathLike | None = None, client=None, growth: bool = True, gamma_c: bool = True,
          gamma_range: tuple[float, float] | None = None, count: CountSpec | None = None,
          chunk_points: int | None = None, workers: int | None = None, progress: Progress | None = None,
          command: str | None = None, adaptive: AdaptiveSpec | bool | Mapping[str, Any] | None = None,
          start: Progress | None = None, sliding: SlidingSpec | bool | None = None):
    """Sweep the Rayleigh branch's growth analysis over the grid `axes` (x the fixed values); an xarray.Dataset.

    axes: parameter name (gamma, f, beta, eta, Delta, xi) -> increasing values; fixed: other parameters (default:
    :data:`DEFAULT_FIXED`, η = ∞ allowed); kH: the grid the growth is bracketed on (default :data:`DEFAULT_KH`);
    rtol: the model's accuracy setting (None: full certified accuracy); store: a Zarr directory, written chunk by
    chunk and resumed if it exists with the same plan and model (else SweepError, nothing written); client: a
    ``distributed.Client`` (None: Dask's threaded scheduler here, `workers` threads); growth: the growth variables;
    gamma_c: the threshold γ_c over the other axes (searched in `gamma_range`); count: the optional all-branch
    count; progress: called with (kind, points) as chunks finish; command: recorded in the attributes; adaptive:
    None (every point) or True / an :class:`~asymslide.atlas.adaptive.AdaptiveSpec` (the growth computed only where the
    verdict can change: :mod:`asymslide.atlas.adaptive`; every axis must have m·2^levels + 1 points); start: called with
    (kind, points) when an adaptive level's batch of that many points starts (kind ``level L``, as in `progress`; again
    as each of its follow rounds starts, with the points the round adds); sliding: None (the Rayleigh branch only) or
    True / a :class:`SlidingSpec` (also the sliding verdict over every branch, the ``*_all`` variables; an adaptive
    sweep refines it too).

    Returns the dataset: in memory without a store, else opened lazily from the store. Variables and attributes:
    see the module docstring. Bad input raises SweepError (a ValueError) naming the problem.
    """
    plan = make_plan(axes, fixed=fixed, kH=kH, rtol=rtol, growth=growth, gamma_c=gamma_c, gamma_range=gamma_range,
                     count=count, chunk_points=chunk_points, adaptive=adaptive, sliding=sliding)
    return run(plan, store=store, client=client, workers=workers, progress=progress, start=start, command=command)


def run(plan: Plan, *, store: str | os.PathLike | None = None, client=None, workers: int | None = None,
        progress: Progress | None = None, start: Progress | None = None, command: str | None = None):
    """Compute a validated plan (:func:`make_plan`): the dense sweep, or the adaptive one if the plan has
    ``adaptive``; the other arguments and the result as :func:`sweep`. The command line parses and plans, then
    calls this."""
    with _sweep_processes():  # processes started for the sliding verdict serve every round of the sweep
        if plan.adaptive is not None:
            return _adaptive.run(plan, store=store, client=client, workers=workers, progress=progress, start=start,
                                 command=command)
        return run_dense(plan, store=store, client=client, workers=workers, progress=progress, command=command)


def run_dense(plan: Plan, *, store: str | os.PathLike | None = None, client=None, workers: int | None = None,
              progress: Progress | None = None, command: str | None = None):
    """The dense sweep of a validated plan (:func:`sweep` without the parsing): every chunk of every kind."""
    import xarray as xr

    if store is None:
        ds = memory_dataset(plan, command)
        run_kinds(plan, tuple(tasks(plan)), ds=ds, client=client, workers=workers, progress=progress)
        return ds
    path = open_store(plan, Path(store), command)
    run_kinds(plan, tuple(tasks(plan)), path=path, client=client, workers=workers, progress=progress)
    return xr.open_zarr(path, consolidated=False)


def memory_dataset(plan: Plan, command: str | None = None):
    """The plan's template in memory, with writable arrays (a sweep without a store fills it)."""
    ds = template(plan, command).compute()
    for name in ds.data_vars:  # writable copies (dask's fill arrays are broadcast views)
        ds[name] = ds[name].copy(data=np.array(ds[name].values))
    return ds


def open_store(plan: Plan, path: Path, command: str | None = None) -> Path:
    """The store of `plan` at `path`: checked if it exists (SweepError if it cannot be resumed), else created."""
    if path.exists():
        check_resumable(path, plan)
        return path
    # created beside it and renamed into place: a store interrupted while being created would be unreadable, and
    # refused, instead of resumed
    ds0 = template(plan, command)
    tmp = path.with_name(f".{path.name}.creating-{os.getpid()}")
    try:
        ds0.to_zarr(tmp, compute=False, mode="w-", encoding=_encoding(ds0, fast=plan.adaptive is not None),
                    consolidated=False)
        os.rename(tmp, path)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return path


def run_kinds(plan: Plan, kinds: Sequence[str], *, ds=None, path: Path | None = None, client=None,
              workers: int | None = None, progress: Progress | None = None) -> None:
    """Run the chunks of the task kinds `kinds` not yet done: into the in-memory dataset `ds` or the store `path`
    (region writes, then the done flags)."""
    groups = tasks(plan, kinds)
    region_dims = {"growth": plan.names, "gamma_c": plan.gamma_c_names, "count": plan.names, "sliding": plan.names,
                   "gamma_c_all": plan.gamma_c_names}
    if path is None:
        todo = [t for group in groups.values() for t in group]

        def keep(task: Task, result: dict[str, np.ndarray]) -> None:
            index = tuple(slice(a, z) for a, z in task.block)
            for name, arr in result.items():
                ds[name].values[index] = arr
            ds[f"done_{task.kind}"].values[task.index] = 1
            if progress is not None:
                progress(task.kind, task.points)

        _execute(todo, keep, client, workers)
        return
    done = done_chunks(path)
    todo = [t for kind, group in groups.items() for t in group if not done[kind][t.index]]
    if progress is not None:
        for kind, group in groups.items():
            finished = sum(t.points for t in group if done[kind][t.index])
            if finished:
                progress(kind, finished)

    def write(task: Task, result: dict[str, np.ndarray]) -> None:
        _write(path, task, result, region_dims)
        if progress is not None:
            progress(task.kind, task.points)

    _execute(todo, write, client, workers)


def plan_points(plan: Plan) -> dict[str, int]:
    """Grid points per kind of task (for progress bars)."""
    out = {"growth": plan.size} if plan.growth else {}
    if plan.gamma_c:
        out["gamma_c"] = math.prod(len(plan.axes[n]) for n in plan.gamma_c_names)
    if sliding_thresholds(plan):
        out["gamma_c_all"] = out["gamma_c"]
    if plan.count is not None:
        out["count"] = plan.size
    if plan.sliding is not None and plan.adaptive is None:  # an adaptive sweep's levels compute both verdicts
        out["sliding"] = plan.size
    return out


def iter_summary(store: str | os.PathLike) -> Iterator[str]:
    """Lines describing an atlas: plan, provenance, completion and a summary of its values."""
    import xarray as xr

    path = Path(store)
    ds = xr.open_zarr(path, consolidated=False)
    plan = json.loads(ds.attrs.get("plan", "{}"))
    yield f"atlas {path}"
    yield (f"  written by asymslide {ds.attrs.get('asymslide_version')} (git {ds.attrs.get('git_revision')}, model "
           f"{str(ds.attrs.get('model_fingerprint', ''))[:12]}) on {ds.attrs.get('created')}")
    for name, values in plan.get("axes", {}).items():
        v = np.asarray(values)
        yield f"  axis {name} ({model.PARAMETERS[name].symbol}): {v.size} values from {v[0]:g} to {v[-1]:g}"
    yield "  fixed: " + ", ".join(f"{k} = {v}" for k, v in plan.get("fixed", {}).items())
    yield f"  kH grid: {ds.attrs.get('kH_grid')}; rtol: {ds.attrs.get('rtol')}"
    done = done_chunks(path)
    if done:
        yield "  chunks written: " + ", ".join(f"{kind} {int(done[kind].sum())} of {done[kind].size}"
                                              for kind in ("growth", "gamma_c", "count", "sliding", "gamma_c_all")
                                              if kind in done)
    if "adaptive" in ds.attrs and "computed" in ds:
        yield from _adaptive_store_lines(ds)
    g = ds["growth"].values if "growth" in ds else np.empty(0)
    finite = np.isfinite(g)
    if finite.any():
        yield (f"  growth (Rayleigh branch): {int(finite.sum())} of {g.size} points computed; unstable (growth > 0) at "
               f"{100 * float((g[finite] > 0).mean()):.1f} %; range {np.nanmin(g):.4g} .. {np.nanmax(g):.4g}")
    yield from _both_verdicts(ds)
    for name, which in (("gamma_c", "gamma_c"), ("gamma_c_all", "gamma_c_all (sliding, every branch)")):
        if name in ds:
            yield from _gamma_c_lines(ds[name].values, ds[f"{name}_reason"].values, which)
    if "gamma_c_complete" in ds:
        yield from _crossing_lines(ds)
    if "unstable_count" in ds:
        uc = ds["unstable_count"]
        yield (f"  unstable_count: window |Re z| <= {uc.attrs['re_max']:g}, {uc.attrs['im_min']:g} <= Im z <= "
               f"{uc.attrs['im_max']:g} on {ds.sizes['kH_count']} kH; max {int(uc.max())}, failed counts "
               f"{int((uc == -1).sum())}")


def _adaptive_store_lines(ds) -> Iterator[str]:
    """An adaptive atlas: its refinement, the points evaluated per level and the filled verdicts' classes."""
    yield from adaptive_lines(ds.attrs["adaptive"], ds["computed"].values)
    filled = ds["verdict_filled"].values
    if not (filled >= 0).all():
        yield "  verdict_filled: not yet (the sweep has not finished: run the same command to resume it)"
        return
    for name, which in (("verdict_filled", "every point"), ("verdict_filled_all", "sliding, every point")):
        if name in ds:
            v = ds[name].values
            yield (f"  {name} ({which}): " + ", ".join(f"{model.VERDICTS[k]} {100 * (v == k).mean():.1f} %"
                                                       for k in sorted(model.VERDICTS)))


def _gamma_c_lines(gc: np.ndarray, reason: np.ndarray, which: str = "gamma_c") -> Iterator[str]:
    """Where the threshold was found, its range, and the count of each reason it was not."""
    ok = reason == model.ThresholdReason.FOUND
    yield (f"  {which}: found at {int(ok.sum())} of {gc.size} points"
           + (f", range {np.nanmin(gc):.6g} .. {np.nanmax(gc):.6g}" if ok.any() else ""))
    for code, text in model.THRESHOLD_STATUS.items():
        n = int((reason == code).sum())
        if code and n:
            yield f"    reason {code} at {n} points: {text}"


def adaptive_lines(attribute: str, computed: np.ndarray) -> Iterator[str]:
    """The refinement of an adaptive atlas (its ``adaptive`` attribute) and the points evaluated per level (from
    ``computed``, so a sweep not finished yet is described as far as it got)."""
    from .adaptive import lattice_size, level_counts, refinement_text

    a = json.loads(attribute)
    levels = int(a["levels"])
    counts = level_counts(computed, levels)
    size = computed.size
    yield (f"  adaptive: levels 0..{levels}, coarse grid {' x '.join(str(n) for n in a['coarse_shape'])} (stride "
           f"{a['coarse_stride']}), {refinement_text(a)}")
    for level, n in enumerate(counts):
        lattice = lattice_size(computed.shape, levels, level)
        yield (f"    level {level} (stride {2 ** (levels - level)}): {n} points evaluated = {100 * n / size:.2f} % of "
               f"the grid ({100 * n / lattice:.1f} % of the level's {lattice} points)")
    total = sum(counts)
    yield f"  evaluated fraction: {100 * total / size:.2f} % ({total} of {size} points)"


def _verdict_lines(verdict: np.ndarray, reason: np.ndarray, which: str = "Rayleigh branch",
                   status: Mapping[int, str] | None = None) -> Iterator[str]:
    """Coverage of a verdict (`which`: "Rayleigh branch" or "sliding (every branch)"): the fraction of computed cells
    with a certified verdict, and why the rest are not (codes of `status`, default model.VERDICT_STATUS)."""
    status = model.VERDICT_STATUS if status is None else status
    done = verdict >= 0
    n = int(done.sum())
    if not n:
        yield f"  {which} verdict: no cell computed yet"
        return
    cert = np.isin(verdict, (model.Verdict.STABLE, model.Verdict.UNSTABLE)) & done
    yield (f"  {which} verdict coverage: {100 * cert.sum() / n:.1f} % of {n} computed cells certified (stable "
           f"{100 * (verdict == model.Verdict.STABLE).sum() / n:.1f} %, unstable "
           f"{100 * (verdict == model.Verdict.UNSTABLE).sum() / n:.1f} %), undetermined "
           f"{100 * (verdict == model.Verdict.UNDETERMINED).sum() / n:.1f} %")
    for code, text in status.items():
        k = int(((reason == code) & (verdict == model.Verdict.UNDETERMINED)).sum())
        if k:
            yield f"    undetermined, reason {code} at {k} cells: {text.removeprefix('undetermined: ')}"


def _both_verdicts(ds) -> Iterator[str]:
    """The Rayleigh branch's verdict and the sliding one (or that the atlas covers the Rayleigh branch only)."""
    if "verdict" in ds:
        yield from _verdict_lines(ds["verdict"].values, ds["verdict_reason"].values, "Rayleigh branch",
                                  model.VERDICT_STATUS)
    if "verdict_all" in ds:
        yield from _sliding_lines(ds)
    elif "verdict" in ds:
        yield ("  sliding (every branch): not computed: this atlas covers the Rayleigh branch only (other branches can "
               "be unstable where it is stable; asymslide sweep --sliding)")


def _sliding_lines(ds) -> Iterator[str]:
    """The sliding verdict (every branch): coverage, the growth, the families at the maximum, and where it differs
    from the Rayleigh branch's."""
    v = ds["verdict_all"].values
    floor = ds["verdict_all"].attrs.get("floor", ds["growth_all"].attrs.get("floor"))
    yield (f"  sliding (every branch, growth floor {floor:g}) on {ds.sizes.get('kH_sliding', 0)} kH from "
           f"{float(ds['kH_sliding'][0]):g} to {float(ds['kH_sliding'][-1]):g}:")
    yield from _verdict_lines(v, ds["verdict_reason_all"].values, "  sliding", model.SLIDING_STATUS)
    g = ds["growth_all"].values
    if np.isfinite(g).any():
        fam = ds["family_all"].values
        yield (f"    growth_all: range {np.nanmin(g):.4g} .. {np.nanmax(g):.4g}; fastest family at the maximum: "
               + ", ".join(f"{name.split(' (')[0]} {int((fam == k).sum())}" for k, name in model.FAMILIES.items()
                           if (fam == k).any()))
    bound = int((ds["lower_bound_all"].values == 1).sum())
    if bound:
        yield (f"    at {bound} cells (finite eta) growth_all is a lower bound of the continuous maximum "
               "(docs/physics.md §14.7)")
    if "verdict" in ds:
        r = ds["verdict"].values
        both = (r >= 0) & (v >= 0)
        if both.any():
            yield (f"    Rayleigh branch stable but sliding unstable at {int(((r == 0) & (v == 1) & both).sum())} of "
                   f"{int(((r == 0) & both).sum())} Rayleigh-stable cells")


def _crossing_lines(ds) -> Iterator[str]:
    """Coverage of the boundary in gamma: points whose every crossing is certified, and the crossings' reasons."""
    complete, count = ds["gamma_c_complete"].values, ds["gamma_c_n_crossings"].values
    done = complete >= 0
    n = int(done.sum())
    if not n:
        return
    reasons = ds["gamma_c_crossing_reason"].values
    hist = np.bincount(count[done].astype(int))
    over = int((count > CROSSINGS).sum())
    yield (f"  crossing coverage: every crossing in gamma certified at {100 * (complete == 1).sum() / n:.1f} % of {n} "
           f"computed points; crossings per point: "
           + ", ".join(f"{k}: {int(c)}" for k, c in enumerate(hist) if c)
           + (f" ({over} points have more than the {CROSSINGS} stored)" if over else ""))
    for code, text in model.CROSSING_STATUS.items():
        k = int((reasons == code).sum())
        if k:
            yield f"    crossings with reason {code}: {k} ({text})"


def export_netcdf(store: str | os.PathLike, out: str | os.PathLike) -> Path:
    """Write the atlas as one NetCDF file (the done flags left out; attributes kept)."""
    import xarray as xr

    ds = xr.open_zarr(Path(store), consolidated=False)
    ds = ds.drop_vars([n for n in ds.data_vars if n.startswith("done_")])
    out = Path(out)
    ds.load().to_netcdf(out, engine="scipy", format="NETCDF3_64BIT")
    return out
