"""The plan of an atlas: what a sweep computes, independent of where it runs.

:func:`make_plan` validates the axes, the fixed values, the kH grid and the optional parts (the all-branch count,
the sliding verdict, the adaptive refinement) into a frozen :class:`Plan`, and cuts the grid into chunks
(deterministically, from the shape alone, so that a resumed sweep cuts it the same way on any machine). Everything
that determines the numbers in a store is in :meth:`Plan.identity`: a store resumes only the plan it was written
with. :func:`parse_axis` and :func:`parse_fixed` read the command line's ``name=lo:hi:n`` and ``name=value``
(only ``float()`` is applied: nothing is evaluated). Bad input raises :class:`SweepError` (a ValueError) naming the
problem.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from asymslide import model

from . import refinement
from .refinement import AdaptiveSpec

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


class SweepError(ValueError):
    """A sweep that cannot run as asked (bad axes or values, a store that cannot be resumed); the message says why."""


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
        """What identifies these settings in a store's plan (a resumed sweep must ask for the same)."""
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
        """The axes' names, in order (the dataset's dimensions)."""
        return tuple(self.axes)

    @property
    def shape(self) -> tuple[int, ...]:
        """The number of values on each axis."""
        return tuple(len(v) for v in self.axes.values())

    @property
    def size(self) -> int:
        """The number of grid points."""
        return math.prod(self.shape)

    @property
    def gamma_c_names(self) -> tuple[str, ...]:
        """The axes of gamma_c: every axis but gamma."""
        return tuple(n for n in self.axes if n != "gamma")

    def identity(self) -> dict[str, Any]:
        """The plan as JSON-able data: equal identities give equal numbers (with the same model)."""
        return {
            "axes": {k: list(v) for k, v in self.axes.items()},
            "fixed": {k: json_float(v) for k, v in self.fixed.items()},
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
        """The index blocks (start, stop per axis) of the γ_c chunks (over every axis but γ)."""
        return _blocks([(len(self.axes[n]), self.chunks[f"gamma_c:{n}"]) for n in self.gamma_c_names])

    def count_blocks(self) -> list[tuple[tuple[int, int], ...]]:
        """The index blocks (start, stop per axis) of the all-branch count's chunks."""
        return _blocks([(len(self.axes[n]), self.chunks[f"count:{n}"]) for n in self.names])

    def sliding_blocks(self) -> list[tuple[tuple[int, int], ...]]:
        """The index blocks (start, stop per axis) of the sliding verdict's chunks."""
        return _blocks([(len(self.axes[n]), self.chunks[f"sliding:{n}"]) for n in self.names])


def json_float(x: float) -> float | str:
    """A float for JSON: "inf" for ∞ (JSON has no infinity), else the value."""
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
        lo, hi = parse_number(name, parts[0]), parse_number(name, parts[1])
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
    return name, np.array([parse_number(name, v) for v in values.split(",") if v.strip()])


def parse_fixed(spec: str) -> tuple[str, float]:
    """``name=value`` (``eta=inf`` for a half-space below)."""
    if "=" not in spec:
        raise SweepError(f"fixed {spec!r}: expected name=value")
    name, _, value = (s.strip() for s in spec.partition("="))
    return name, parse_number(name, value)


def parse_number(name: str, text: str) -> float:
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
    points per growth chunk (default :data:`CHUNK_POINTS`, adaptive :data:`asymslide.atlas.refinement.CHUNK_POINTS`);
    adaptive: None or False (the dense sweep), True or an :class:`~asymslide.atlas.refinement.AdaptiveSpec` (levels,
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
        chunk_points = CHUNK_POINTS if spec is None else refinement.CHUNK_POINTS
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
        spec = refinement.resolve_spec(adaptive, shape)
        refinement.check_shape(tuple(axes), shape, spec.levels)  # type: ignore[arg-type]
    except (TypeError, ValueError) as exc:
        raise SweepError(str(exc)) from None
    return spec


def _adaptive_verdict(spec: AdaptiveSpec, sliding: SlidingSpec | None) -> tuple[AdaptiveSpec, SlidingSpec | None]:
    """The adaptive spec with its verdict fixed, and the sliding spec it needs: refining the sliding verdict computes
    it (the model's default spec unless one is given); refining the Rayleigh branch's alone with the sliding verdict
    asked for is refused (the sliding verdict would be filled from cells whose corners agree only on the Rayleigh
    branch's)."""
    verdict = spec.verdict or (refinement.SLIDING if sliding is not None else refinement.RAYLEIGH)
    if verdict == refinement.RAYLEIGH and sliding is not None:
        raise SweepError("an adaptive sweep refining the Rayleigh branch's verdict cannot give the sliding verdict "
                         "(it would be filled from cells refined on the Rayleigh branch alone): refine on the sliding "
                         "verdict (--verdict sliding) or drop --sliding")
    if verdict == refinement.SLIDING and sliding is None:
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


def sliding_thresholds(plan: Plan) -> bool:
    """Whether the plan computes the threshold of sliding in gamma (``gamma_c_all``): gamma_c with the sliding
    verdict and its ``thresholds``."""
    return plan.gamma_c and plan.sliding is not None and plan.sliding.thresholds


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
