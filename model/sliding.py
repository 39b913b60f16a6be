"""Stability of steady sliding over the whole spectrum: the fastest root of every branch (docs/physics.md §14).

Every verdict of :mod:`model.stability` concerns one root of Eq. implicit_spectrum, the Rayleigh branch. The
equation has other roots (guided modes of the finite blocks, faster than the shear or the dilatational wave), and
they often grow where the Rayleigh branch does not, or faster. This module answers *is steady sliding stable?*
over all of them:

- :func:`root_window`: where the roots can be. For Im z >= floor, no root lies outside
  [-re_max, re_max] x [floor, im_max] (a theorem, §14: a lower bound of Re[F/(iz)] at large |z|).
- :func:`fastest_mode`: at each kH the root of largest Im z over every branch (a root found by the argument
  principle and Newton, certified by a count: no other root above it in the window), its family, and the
  number of roots above the floor.
- :func:`sliding_analysis`: over a kH range, the maximum of that growth (and of the temporal rate kH Im z),
  the verdict of sliding (stable: no root with Im z >= floor anywhere in the range; unstable; undetermined,
  with a reason), side by side with the Rayleigh branch's (:func:`growth_analysis`).
- :func:`sliding_chunk`: one chunk of parameter sets for sweeps (rows :data:`SLIDING_ROWS`).

The floor is stated: roots with 0 < Im z < floor are not searched (at finite eta they are dense: §14).
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass
from enum import IntEnum

import numpy as np

from ._kernels.contour import H0, LIN_TOL, PHASE_MAX, TRAP_TOL, count_rectangle
from ._kernels.newton import FULL_TOL, KH, _newton
from ._kernels.records import NO_BOX, Params
from ._kernels.window import exclusion_radius, top_of_roots
from ._sliding_cuts import CHARTS, CutCharts
from ._validate import check
from .modes import AXIS_HMIN, MAX_LADDER_POLES, MAX_SHIFTS, REL_HMIN, SHIFT, SHIFT_GROWTH, _Problem, _roots_from_sums
from .stability import GrowthResult, Verdict, growth_rows

__all__ = [
    "DEFAULT_FLOOR",
    "FAMILIES",
    "MODE_STATUS",
    "SLIDING_KH",
    "SLIDING_ROWS",
    "SLIDING_STATUS",
    "FastestMode",
    "SlidingResult",
    "fastest_mode",
    "root_window",
    "sliding_analysis",
    "sliding_chunk",
    "sliding_verdict",
    "family_codes",
]

#: the default growth floor: roots with Im z below it are not searched (their e-folding time is > 1e6 H/(c_s kH))
DEFAULT_FLOOR = 1e-6
#: the default kH grid of :func:`sliding_analysis` (its ends are the range)
SLIDING_KH = np.logspace(-2, 2, 17)
SAMPLE_LIMIT = 2e5  # a window whose bottom edge needs more samples than this (estimated) is refused ("too wide")
POLE_SAMPLES = 25.0  # samples per real-axis pole per level of its graded seeds (the estimate of _Search.affordable)
DESCENT = 2.0  # ratio of the levels of the cold search (a band [y/2, y] at a time) ...
HINT_FACTOR = 0.5  # ... below one band [HINT_FACTOR x the expected growth, top]
TOP_REL = 1e-6  # a located root at Im z = c is certified the fastest by a count above c (1 - TOP_REL)
WARM_ITERS = 40  # Newton evaluations allowed for a warm start
LADDER_DAMPED = 1.0  # pole families seen from a line at height y only while (1 + eta) kH beta_j y < this

#: the families of a root (FastestMode.family; -1: no root)
FAMILIES = {
    0: "Rayleigh branch",
    1: "sub-shear (|Re z| < 1, not the Rayleigh branch)",
    2: "intersonic guided mode (1 <= |Re z| < 1/beta)",
    3: "supersonic guided mode (|Re z| >= 1/beta)",
}
M_OK, M_BELOW, M_WIDE, M_FAILED = 0, 1, 2, 3
#: status of the fastest mode at one kH (FastestMode.status)
MODE_STATUS = {
    M_OK: "certified: the root of largest Im z in the window (a count finds no other root above it)",
    M_BELOW: "below the floor: no root with Im z >= floor (the window's count is 0)",
    M_WIDE: "refused: the window at the floor is too wide to search (finite eta, small floor: roots just above the "
    "layers' poles reach far out; more than 2e5 samples on its edge) and no root was found above the level searched",
    M_FAILED: "refused: the contour count failed (a root on an edge that could not be moved, or too many samples)",
}


@dataclass
class _Top:
    """The outcome of the search at one kH."""

    status: int
    z: complex = complex(math.nan, math.nan)
    dzds: complex = complex(math.nan, math.nan)  # dz/d ln kH at z
    searched_to: float = math.nan  # the lowest level certified empty above (status M_WIDE)
    count: int = -1  # roots with Im z >= floor (-1: not counted)
    evaluations: int = 0


class _Search:
    """One parameter set: the windows, counts and the fastest root at any kH."""

    def __init__(self, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float, floor: float,
                 sample_limit: float = SAMPLE_LIMIT):
        self.p = Params(gamma, f, beta, eta, delta, xi)
        self.floor = floor
        self.sample_limit = sample_limit
        self.evaluations = 0
        self._rho: dict[tuple[float, float], float] = {}  # the windows computed (a few bisections each)
        self._top: dict[float, float] = {}

    # -- windows ---------------------------------------------------------------------------------
    def rho(self, y: float, q: float) -> float:
        key = (y, q)
        hit = self._rho.get(key)
        if hit is None:
            hit = self._rho[key] = exclusion_radius(y, q, self.p)
        return hit

    def top(self, q: float) -> float:
        hit = self._top.get(q)
        if hit is None:
            hit = self._top[q] = top_of_roots(self.floor, q, self.p)
        return hit

    # -- counts ----------------------------------------------------------------------------------
    def count(self, q: float, x: float, y0: float, y1: float) -> int | None:
        """Roots in [-x, x] x [y0, y1] (edges moved outward past a root on them, as model.modes does); None if the
        count failed."""
        got = self.count_sums(q, x, y0, y1)
        return None if got is None else got[0]

    def count_sums(self, q: float, x: float, y0: float, y1: float
                   ) -> tuple[int, complex, complex, tuple[float, float, float, float]] | None:
        """(count, estimates of the sum of the roots and of their squares, the rectangle counted: [-x, x] x [y0, y1]
        with its edges moved outward past a root on them) or None if the count failed."""
        size = max(2.0 * x, y1 - y0)
        poles, half = _singularities(q, self.p.beta, self.p.eta, x, y0)
        x0, x1 = -x, x
        shifts = [0, 0, 0, 0]
        while True:
            hb = min(REL_HMIN * size, AXIS_HMIN * y0)
            ht = min(REL_HMIN * size, AXIS_HMIN * y1)
            st, n, edge, _, nev, s1, s2 = count_rectangle(x0, x1, y0, y1, _spacing(q), poles, half, q, *self.p, hb,
                                                          hb, ht, PHASE_MAX, TRAP_TOL, LIN_TOL)
            self.evaluations += nev
            if st == 0:
                return n, s1, s2, (x0, x1, y0, y1)
            if st != 1:
                return None
            shifts[edge] += 1
            if shifts[edge] > MAX_SHIFTS:
                return None
            grow = SHIFT * SHIFT_GROWTH ** (shifts[edge] - 1)
            if edge == 0:
                y0 -= grow * min(REL_HMIN * size, AXIS_HMIN * y0)
            elif edge == 1:
                x1 += grow * REL_HMIN * size
            elif edge == 2:
                y1 += grow * min(REL_HMIN * size, AXIS_HMIN * y1)
            else:
                x0 -= grow * REL_HMIN * size

    def top_root_in(self, q: float, x: float, y0: float, y1: float) -> tuple[complex | None, int]:
        """(the root of largest Im z in [-x, x] x [y0, y1], the number of roots there): best first, the cell with
        the highest top is split until its root is located by Newton; cells below the best root found are never
        split. (None, 0) if the window holds none; RuntimeError if the contour fails."""
        prob = _Problem(q, *self.p, x, y0, y1, _spacing(q), _singularities(q, self.p.beta, self.p.eta, x, y0))
        cell, n = prob.outer()
        best = _best_first(prob, cell, n) if n else None
        self.evaluations += prob.evaluations
        return best, n

    # -- the fastest root at one kH --------------------------------------------------------------------
    def polish(self, z0: complex, q: float) -> tuple[complex, complex] | None:
        """Newton on F(z; q) from z0 (the model's one loop); (z, dz/d ln kH) or None."""
        r = _newton(z0, KH, 0.0, q, self.p, WARM_ITERS, FULL_TOL, 0.0, 0.9, 1.0, NO_BOX)
        self.evaluations += r.evals
        if not r.ok or not math.isfinite(r.z.imag):
            return None
        return r.z, q * r.dzds  # dz/dkH -> dz/d ln kH

    def certify(self, z: complex, q: float, top: float, level: float) -> complex | None:
        """z (a root, Im z >= level) if no other root lies above Im z (1 - TOP_REL); else the fastest root above
        that level. None if the window there is too wide or the count fails."""
        lo = max(level, z.imag * (1.0 - TOP_REL))
        x = self.rho(lo, q)
        if not self.affordable(q, x, lo):
            return None
        n = self.count(q, x, lo, top)
        if n is None:
            return None
        if n == 1 and -x <= z.real <= x:
            return z
        return self.top_root_in(q, x, lo, top)[0]

    def fastest(self, q: float, warm: complex | None = None, hint: float | None = None,
                with_count: bool = False, level: float | None = None) -> _Top:
        """The root of largest Im z at kH = q over every branch, certified, if it lies at or above `level` (default:
        the floor); else status M_BELOW with searched_to = level (no root there). warm: a start for Newton (e.g. the
        fastest root at a neighbouring kH); hint: a level near the expected growth (the search starts with the band
        above HINT_FACTOR x hint). with_count: also count the roots above the floor."""
        ev0 = self.evaluations
        top = self.top(q)
        lev = self.floor if level is None else max(level, self.floor)
        res = self._fastest(q, top, warm, hint, lev)
        if with_count and res.status == M_OK and res.count < 0:
            x = self.rho(self.floor, q)
            if self.affordable(q, x, self.floor):
                n = self.count(q, x, self.floor, top)
                res.count = -1 if n is None else n
        elif with_count and res.status == M_BELOW and lev == self.floor:
            res.count = 0
        res.evaluations = self.evaluations - ev0
        return res

    def _fastest(self, q: float, top: float, warm: complex | None, hint: float | None, level: float) -> _Top:
        if not top > level:
            return _Top(M_BELOW, searched_to=level, count=0 if level == self.floor else -1)
        try:
            if warm is not None:
                got = self.polish(warm, q)
                if got is not None and level <= got[0].imag <= top:
                    z = self.certify(got[0], q, top, level)
                    if z is not None:
                        return self._located(z, q)
            return self._descend(q, top, hint, level)
        except RuntimeError:
            return _Top(M_FAILED, searched_to=top)

    def _descend(self, q: float, top: float, hint: float | None, level: float) -> _Top:
        """Search band by band from the top down to `level`, until a band holds a root: first
        [HINT_FACTOR x hint, top] (hint: the growth expected, e.g. at a neighbouring kH), then the rest at once
        where the window at `level` is cheap to count (eta = inf, or the layers' poles damped at that height) or
        `level` is above the floor (a maximum found elsewhere: the search shows that nothing lies above it), else
        bands [y/DESCENT, y] (the floor at finite eta: a root found high up spares the widest windows). A band's top
        root is found by best-first subdivision of the band."""
        hi = top
        # one band where the window at `level` is cheap, or where a root above that level is already known (the
        # level is then a maximum found: the search only has to show that nothing lies above it, in one count)
        cheap = (math.isinf(self.p.eta) or (1.0 + self.p.eta) * q * self.p.beta * level >= LADDER_DAMPED
                 or level > self.floor)
        expect_root = hint is not None and hint > level
        if expect_root:
            lo = HINT_FACTOR * hint
        else:
            lo = level if cheap else hi / DESCENT
        lowest = self.lowest_level(q)  # the lowest level whose window is within the search limit
        while hi > level:
            lo = max(lo, level, lowest)
            if lo >= hi:
                return _Top(M_WIDE, searched_to=hi)
            x = self.rho(lo, q)
            if expect_root:  # the band of the hint: sampled once, for the count and the search at once
                z, n = self.top_root_in(q, x, lo, hi)
                expect_root = False
            else:  # bands expected empty: counted by the compiled kernel first (no samples kept)
                n = self.count(q, x, lo, hi)
                if n is None:
                    return _Top(M_FAILED, searched_to=hi)
                z = self.top_root_in(q, x, lo, hi)[0] if n else None
            if z is not None:
                res = self._located(z, q)
                if lo == self.floor:
                    res.count = n
                return res
            hi = lo
            lo = level if cheap else hi / DESCENT
        return _Top(M_BELOW, searched_to=level, count=0 if level == self.floor else -1)

    def affordable(self, q: float, x: float, y: float) -> bool:
        """Whether the window [-x, x] at height y is within the search limit: the samples its bottom edge needs,
        estimated as its length over the initial spacing plus, for each real-axis pole it sees (finite eta: the
        families whose poles the edge does not damp, (1 + eta) kH beta_j y < LADDER_DAMPED, spaced
        d = pi / ((1 + eta) kH beta_j) in Re z far out), POLE_SAMPLES x (1 + log3(d / y)) samples (measured: the
        graded seeds and the refinement between them), are at most SAMPLE_LIMIT."""
        if not math.isfinite(x):
            return False
        n = 2.0 * x / _spacing(q)
        if math.isfinite(self.p.eta):
            for bj in (1.0, self.p.beta):
                if (1.0 + self.p.eta) * q * bj * y < LADDER_DAMPED:
                    d = math.pi / ((1.0 + self.p.eta) * q * bj)
                    n += 2.0 * x / d * POLE_SAMPLES * (1.0 + max(0.0, math.log(d / y) / math.log(3.0)))
        return n <= self.sample_limit

    def lowest_level(self, q: float) -> float:
        """The lowest level y >= floor whose window is within the search limit (to a relative 1e-3, on the safe
        side): the window shrinks as y grows."""
        if self.affordable(q, self.rho(self.floor, q), self.floor):
            return self.floor
        lo, hi = self.floor, max(2.0 * self.floor, 1.0)
        while not self.affordable(q, self.rho(hi, q), hi):
            lo, hi = hi, 2.0 * hi
            if hi > 1e6:
                return math.inf
        while hi - lo > 1e-3 * hi:
            mid = 0.5 * (lo + hi)
            if self.affordable(q, self.rho(mid, q), mid):
                hi = mid
            else:
                lo = mid
        return hi

    def _located(self, z: complex, q: float) -> _Top:
        got = self.polish(z, q)
        dzds = got[1] if got is not None and abs(got[0] - z) <= 1e-10 * abs(z) else complex(math.nan, math.nan)
        return _Top(M_OK, z=z, dzds=dzds)


def _spacing(q: float) -> float:
    """The initial spacing of the samples along a line: model.modes' H0 at kH >= 1, H0/kH below. F's structure away
    from the real-axis singularities (which get graded seeds) scales like 1/kH in z at small kH (the oscillation
    exp(2i kH z), the spacing of the roots, |z| ~ 1/kH of the long-wave roots), and the acceptance tests of a
    segment are scale-free (relative changes of F along it)."""
    return H0 / min(q, 1.0)


def _singularities(q: float, beta: float, eta: float, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
    """The real-axis singularities around which lines at height >= y get graded seeds (as model.modes does), and
    the half-distances to their neighbours (capped at H0): z = +-1, +-1/beta, and the finite-eta pole families
    (docs/physics.md §2) only where a line at height y sees them, (1 + eta) kH beta_j y < LADDER_DAMPED (beta_j = 1
    for the shear family, beta for the dilatational one): above that, F along the line changes on the scale of the
    pole spacing by less than exp(-2 LADDER_DAMPED) of its size, and the adaptive sampling alone resolves it."""
    xmax = x + 1.0
    pts = [1.0, 1.0 / beta]
    if math.isinf(eta) or (1.0 + eta) * q * beta * y >= LADDER_DAMPED:  # the branch points alone (no NumPy: fast)
        h = _spacing(q)
        xs = [v for v in sorted(set(pts)) if v <= xmax]
        p = [-v for v in reversed(xs)] + xs
        gaps = [b - a for a, b in zip(p[:-1], p[1:], strict=True)]
        half = [min(h, 0.5 * max(lo, hi)) for lo, hi in zip([0.0, *gaps], [*gaps, 0.0], strict=True)]
        return np.array(p), np.array(half)
    if math.isfinite(eta):
        a = math.pi / ((1.0 + eta) * q)
        for bj in (1.0, beta):
            if (1.0 + eta) * q * bj * y >= LADDER_DAMPED:
                continue
            nmax = math.sqrt(max((xmax * bj) ** 2 - 1.0, 0.0)) / a
            if nmax > MAX_LADDER_POLES:
                continue
            n = np.arange(1, int(nmax) + 1, dtype=float)
            pts.extend((np.sqrt(1.0 + (n * a) ** 2) / bj).tolist())
    xs = np.unique(np.array(pts))
    xs = xs[xs <= xmax]
    p = np.concatenate((-xs[::-1], xs))
    gaps = np.diff(p)
    half = 0.5 * np.maximum(np.concatenate(([0.0], gaps)), np.concatenate((gaps, [0.0])))
    return p, np.minimum(half, _spacing(q))


def _best_first(prob: _Problem, cell: tuple, n: int) -> complex:
    """The root of largest Im z among the n counted in `cell` of `prob`: cells in the order of their tops, split
    until a cell holds one root, which Newton locates; stops when the highest cell left lies below the best root."""
    heap = [(-cell[3], 0, cell, n, None)]
    order = 1
    best: complex | None = None
    while heap:
        neg_top, _, c, n, moment = heapq.heappop(heap)
        if best is not None and -neg_top <= best.imag:
            break
        if n == 1:
            z = prob.newton_in(c, 1, prob.winding(c)[1] if moment is None else moment)
            if z is not None:
                best = z if best is None or z.imag > best.imag else best
                continue
        for cc, nn, mm in prob.halves(c, n):
            if nn > 0:
                heapq.heappush(heap, (-cc[3], order, cc, nn, mm))
                order += 1
    if best is None:
        raise RuntimeError("sliding: a counted root could not be located")
    return best


# ------------------------------------------------------------------------------------------------
# public API
# ------------------------------------------------------------------------------------------------


def _floor(floor) -> float:
    if isinstance(floor, (str, bytes, complex)) or np.ndim(floor) != 0:
        raise ValueError(f"floor must be a positive real number; got {floor!r}")
    try:
        v = float(floor)
    except (TypeError, ValueError):
        raise ValueError(f"floor must be a positive real number; got {floor!r}") from None
    if not (math.isfinite(v) and v > 0.0):
        raise ValueError(f"floor must be a positive real number; got {floor!r}")
    return v


def _physical(gamma, f, beta, eta, Delta, xi) -> list[np.ndarray]:
    return [check(n, v) for n, v in (("gamma", gamma), ("f", f), ("beta", beta), ("eta", eta),
                                     ("Delta", Delta), ("xi", xi))]


def root_window(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, floor=DEFAULT_FLOOR
                ) -> tuple[np.ndarray, np.ndarray]:
    """The window outside which F(z; kH) (Eq. implicit_spectrum) has no root with Im z >= floor.

    Returns (re_max, im_max), broadcast over the arguments: every root with Im z >= floor has |Re z| < re_max and
    Im z < im_max (docs/physics.md §14: a lower bound of Re[F/(iz)] over |z| >= r, Im z >= floor, positive beyond
    re_max). re_max is inf where no finite bound exists at this floor (it grows like 1/floor at finite eta).
    """
    fl = _floor(floor)
    q = check("kH", kH)
    arrays = np.broadcast_arrays(q, *_physical(gamma, f, beta, eta, Delta, xi))
    re = np.empty(arrays[0].shape)
    im = np.empty(arrays[0].shape)
    for idx in np.ndindex(re.shape):
        qq, *par = (float(a[idx]) for a in arrays)
        p = Params(*par)
        re[idx] = exclusion_radius(fl, qq, p)
        im[idx] = top_of_roots(fl, qq, p)
    return re, im


# ------------------------------------------------------------------------------------------------
# over a kH range
# ------------------------------------------------------------------------------------------------



class SlidingReason(IntEnum):
    """Why the sliding verdict is what it is (SlidingResult.verdict_reason; atlases' ``verdict_reason_all``): the
    keys of :data:`SLIDING_STATUS`."""

    STABLE = 0
    UNSTABLE = 1
    WIDE = 2
    FAILED = 3
    UNSTABLE_UNCERTIFIED_MAX = 4


S_STABLE, S_UNSTABLE, S_WIDE, S_FAILED, S_UNSTABLE_UNCERTIFIED_MAX = SlidingReason
#: reason codes of the sliding verdict (SlidingResult.verdict_reason; atlases' ``verdict_reason_all``)
SLIDING_STATUS = {
    S_STABLE: "stable: at every kH of the range, no root of any branch has Im z >= floor (the window's count is 0)",
    S_UNSTABLE: "unstable: a certified root has Im z >= floor; the maximum is certified at every kH searched",
    S_WIDE: "undetermined: no root above the floor was found, but at some kH the window at the floor is wider "
    "than the search limit (finite eta: roots just above the layers' poles reach far out as the floor shrinks)",
    S_FAILED: "undetermined: no root above the floor was found, and the contour count failed at some kH",
    S_UNSTABLE_UNCERTIFIED_MAX: "unstable: a certified root has Im z >= floor, but at some kH the search was "
    "refused above that root's growth (the window too wide, or the count failed), so the maximum is not certified "
    "(growth NaN)",
}
FOLLOW_STEP = 0.05  # largest step in ln kH when the root carrying a maximum is followed to its stationary point
FOLLOW_ITERS = 60  # steps allowed for that
STATIONARY_H = 1e-5  # the difference step (in ln kH) of d(objective)/d ln kH along the root
FOLLOW_ROUNDS = 4  # Newton rounds on the stationary point, then certified there; a higher root found starts again
STATIONARY_TOL = 1e-10  # |step in ln kH| at which the stationary point has converged
END_TOL = 1e-12  # a maximum within this of an end of the range (in ln kH) lies at that end
TRACK_FRACTION = 0.25  # roots above this x the maximum (and the floor) at a grid point are followed to their peaks
# (at eta = inf; M/8 found no more on the samples of docs/physics.md §14.8 once the roots across the cuts are
# followed)
TRACK_FRACTION_FINITE = 0.5  # ... at finite eta (windows ~ 1/level, many roots: M/4 costs 1.6-1.9x, §14.8)
FLOOR_WATCH = 0.1  # eta = inf: the roots in [floor x FLOOR_WATCH, floor) at a grid point are followed between them
CERT_MARGIN = 1e-9  # a peak counts as higher than the maximum M above M (1 + CERT_MARGIN)
CUT_CHARTS = True  # eta = inf: also follow the roots across the cuts beside the branch points (model._sliding_cuts)
CHART_MAX_ROOTS = 2  # ... where a chart's box holds at most this many (their number grows like kH: cost)
CERT_ROUNDS = 6  # rounds of refining the maximum and following the roots between the grid points


@dataclass
class _Peak:
    """The best certified point of one objective (Im z or kH Im z) over the range."""

    value: float = -math.inf
    s: float = math.nan
    z: complex = complex(math.nan, math.nan)
    at_end: bool = False


class _Analysis:
    """The fastest root over a kH range for one parameter set (:func:`sliding_analysis`), branch and bound: a kH
    is searched only above the level at which it could raise a maximum found so far (the contour then stays away
    from the real axis and its poles); the floor is searched only while no root above it has been found."""

    def __init__(self, search: _Search, s_grid: np.ndarray, rate: bool = False):
        self.search = search
        self.s_grid = [float(v) for v in s_grid]
        self.lo, self.hi = self.s_grid[0], self.s_grid[-1]
        self.rate = rate
        self.tops: dict[float, _Top] = {}
        self.charts: CutCharts | None = None  # eta = inf: the charts across the cuts (model._sliding_cuts)
        self.chart_roots: dict[tuple[float, int], list[tuple[complex, complex]] | None] = {}
        # every root above a level at a grid point (s -> (level, [(z, dz/d ln kH)])): the sample's and the track's
        self.known: dict[float, tuple[float, list[tuple[complex, complex]]]] = {}
        self.best_im = -math.inf  # the largest Im z and kH Im z of the roots found
        self.best_rate = -math.inf

    def level(self, s: float) -> float:
        """The level above which a root at ln kH = s would raise a maximum (the floor until one is found)."""
        lev = self.best_im
        if self.rate:
            lev = min(lev, self.best_rate * math.exp(-s))
        return max(lev, self.search.floor)

    def at(self, s: float, warm: complex | None = None, hint: float | None = None,
           level: float | None = None) -> _Top:
        """The certified fastest root at ln kH = s if it lies above `level` (default: self.level(s))."""
        hit = self.tops.get(s)
        if hit is None or (hit.status == M_BELOW and level is not None and level < hit.searched_to):
            lev = self.level(s) if level is None else level
            hit = self.search.fastest(math.exp(s), warm, hint, level=lev)
            self.tops[s] = hit
            if hit.status == M_OK:
                self.best_im = max(self.best_im, hit.z.imag)
                self.best_rate = max(self.best_rate, math.exp(s) * hit.z.imag)
        return hit

    def sample(self, start: tuple[float, complex] | None = None) -> None:
        """Every point of the grid, from the start (a certified root, e.g. the Rayleigh branch's maximum) outward,
        each search warm-started from the last root found."""
        prev: tuple[float, complex] | None = None
        if start is not None:
            t = self.at(start[0], start[1], start[1].imag, level=self.search.floor)
            if t.status == M_OK:
                prev = (start[0], t.z)
        for s in self.s_grid:
            t = self.every_root(s) if prev is not None or math.isinf(self.search.p.eta) else None
            if t is None and prev is None:
                t = self.at(s)
            elif t is None:  # the growth of the guided modes falls like 1/kH: the expected level scales so
                t = self.at(s, prev[1], prev[1].imag * min(1.0, math.exp(prev[0] - s)))
            if t.status == M_OK:
                prev = (s, t.z)

    def every_root(self, s: float) -> _Top | None:
        """The grid point ln kH = s searched once for the sample and the track (:meth:`track`): every root above
        the track's fraction of the level (a maximum M found so far; at eta = inf before any root is found, above
        floor x FLOOR_WATCH), located (:meth:`roots_above`); the fastest of them is certified by that count. The
        track then needs no other contour here (its level, the fraction of the final maximum, is not lower). None
        where that window is refused (the caller searches above the level alone)."""
        if s in self.tops:
            return self.tops[s]
        fl = self.search.floor
        if math.isinf(self.search.p.eta) and self.level(s) <= fl:  # nothing found yet: down to the watched band
            level = fl * FLOOR_WATCH  # (:meth:`rises_above_floor` follows its roots if sliding is stable)
        else:
            level = max(fl, self.fraction() * self.level(s))
        found = self.roots_above(s, level)
        if found is None:
            return None
        roots = [r for r in found if r[0].imag >= fl]
        if not roots:
            t = _Top(M_BELOW, searched_to=max(self.known[s][0], fl))
        else:
            z, dz = max(roots, key=lambda r: r[0].imag)
            t = _Top(M_OK, z=z, dzds=dz)
            self.best_im = max(self.best_im, z.imag)
            self.best_rate = max(self.best_rate, math.exp(s) * z.imag)
        if self.known[s][0] <= fl:
            t.count = len(roots)
        self.tops[s] = t
        return t

    def rises_above_floor(self) -> bool:
        """eta = inf, where no root reaches the floor at any grid point: :meth:`track` with M = floor from the roots
        in [floor x FLOOR_WATCH, floor) at the grid points (known from the sample); True if one rises above the floor
        between the grid points (found and certified there)."""
        return self.track(self.search.floor, self.search.floor * FLOOR_WATCH)

    def fraction(self) -> float:
        """Roots above this fraction of the maximum at a grid point are followed between the grid points."""
        return TRACK_FRACTION if math.isinf(self.search.p.eta) else TRACK_FRACTION_FINITE

    @staticmethod
    def objective(rate: bool, s: float, t: _Top) -> float:
        if t.status != M_OK:
            return -math.inf
        return math.exp(s) * t.z.imag if rate else t.z.imag

    def best(self, rate: bool) -> tuple[float, _Top]:
        return max(self.tops.items(), key=lambda kv: self.objective(rate, kv[0], kv[1]))

    def peak(self, rate: bool) -> _Peak:
        """The maximum of Im z (rate False) or of kH Im z (rate True) over the range: the best certified point,
        refined on the root that carries it (followed to where its objective is stationary, then certified
        there; if another root is higher there, that one is refined in turn)."""
        for _ in range(FOLLOW_ROUNDS):
            s, t = self.best(rate)
            if t.status != M_OK or not self.refine(rate, s, t):
                break
        s, t = self.best(rate)
        if t.status != M_OK:
            return _Peak()
        at_end = abs(s - self.lo) <= END_TOL or abs(s - self.hi) <= END_TOL
        return _Peak(self.objective(rate, s, t), s, t.z, at_end)

    def refine(self, rate: bool, s: float, t: _Top) -> bool:
        """Follow the root of the best point to the stationary point of the objective, clipped to the range, and
        certify there. Newton on g(s) = Im dz/ds (plus Im z for the rate) with g' by a difference over
        STATIONARY_H on the same root; steps of at most FOLLOW_STEP in ln kH, each accepted only where Newton
        from the linear predictor lands within a tenth of the step of it (the same root), else halved. True if
        a new point was certified."""
        z, dz, s0 = t.z, t.dzds, s
        cap = FOLLOW_STEP
        for _ in range(FOLLOW_ITERS):
            if not math.isfinite(dz.real) or cap < STATIONARY_TOL:
                break
            g0 = dz.imag + (z.imag if rate else 0.0)
            other = self.search.polish(z + dz * STATIONARY_H, math.exp(s + STATIONARY_H))
            if other is None:
                break
            dg = (other[1].imag + (other[0].imag if rate else 0.0) - g0) / STATIONARY_H
            step = -g0 / dg if dg < 0.0 else math.copysign(cap, g0)
            s_new = min(max(s + max(-cap, min(cap, step)), self.lo), self.hi)
            if abs(s_new - s) <= STATIONARY_TOL:
                break
            pred = z + dz * (s_new - s)
            got = self.search.polish(pred, math.exp(s_new))
            if got is None or abs(got[0] - pred) > 0.1 * abs(pred - z) + 1e-12 * abs(z):
                cap *= 0.5  # not the same root: a shorter step
                continue
            z, dz, s = got[0], got[1], s_new
            cap = min(FOLLOW_STEP, 2.0 * cap)
        if s == s0 or s in self.tops:
            return False
        self.at(s, z, z.imag)
        return True


    # -- between the points searched ------------------------------------------------------------------------
    def roots_above(self, s: float, level: float) -> list[tuple[complex, complex]] | None:
        """Every root with Im z >= level at ln kH = s, with its dz/d ln kH (None if the window there is refused, or
        a counted root could not be located and polished)."""
        hit = self.known.get(s)
        if hit is not None and hit[0] <= level:
            return [r for r in hit[1] if r[0].imag >= level]
        got = self._roots_above(s, level)
        if got is not None:
            self.known[s] = (level, got)
        return got

    def _roots_above(self, s: float, level: float) -> list[tuple[complex, complex]] | None:
        q = math.exp(s)
        top = self.search.top(q)
        if not top > level:
            return []
        x = self.search.rho(level, q)
        if not self.search.affordable(q, x, level):
            return None
        if not self.expect_roots(s, level):
            # the compiled count first (it keeps no samples: most points hold no root), with the sums of the roots
            # and of their squares: up to two roots not known are located from them, certified by the count
            counted = self.search.count_sums(q, x, level, top)
            if counted is None:
                return None
            n, s1, s2, (x0, x1, y0, y1) = counted
            if n == 0:
                return []
            here = self.tops.get(s)
            known = [here.z] if here is not None and here.status == M_OK and here.z.imag >= level else []
            got = _roots_from_sums(n, s1, s2, known, lambda z: self.search.polish(z, q),
                                   lambda z: x0 <= z.real <= x1 and y0 <= z.imag <= y1)
            if got is not None:
                return got
        prob = _Problem(q, *self.search.p, x, level, top, _spacing(q),
                        _singularities(q, self.search.p.beta, self.search.p.eta, x, level))
        try:
            cell, n = prob.outer()
            roots = prob.locate(cell, n) if n else []
        except RuntimeError:
            return None
        finally:
            self.search.evaluations += prob.evaluations
        out = []
        for z in roots:
            got = self.search.polish(complex(z), q)
            if got is None or not abs(got[0] - z) <= 1e-10 * abs(z):
                return None  # not every root counted is known: the list would certify nothing
            out.append(got)
        return out

    def expect_roots(self, s: float, level: float) -> bool:
        """Whether ln kH = s is expected to hold more than two roots above `level` (the neighbouring grid point
        searched does): the contour is then sampled once, keeping its samples to locate the roots, rather than
        counted first (roots move little between neighbours)."""
        i = self.s_grid.index(s) if s in self.s_grid else -1
        for j in (i - 1, i + 1):
            hit = self.known.get(self.s_grid[j]) if 0 <= j < len(self.s_grid) and i >= 0 else None
            if hit is not None and sum(r[0].imag >= level for r in hit[1]) > 2:
                return True
        return False

    def follow_to_peak(self, z: complex, dz: complex, s: float, end: float) -> tuple[float, complex] | None:
        """Follow the root z (slope dz) from ln kH = s towards `end` while its Im z rises; where it stops rising
        inside, the stationary point by Newton (as :meth:`refine`). (s, z) of that peak, or None if Im z falls from
        the start, rises all the way to `end` (the root is there: the search at `end` covers it), or the root is
        lost (it leaves the physical sheet through a cut)."""
        sign = 1.0 if end > s else -1.0
        if not math.isfinite(dz.real) or sign * dz.imag <= 0.0:
            return None
        cap = FOLLOW_STEP
        for _ in range(FOLLOW_ITERS):
            if cap < STATIONARY_TOL:
                return None
            s_new = s + sign * min(cap, abs(end - s))
            pred = z + dz * (s_new - s)
            got = self.search.polish(pred, math.exp(s_new))
            if got is None or abs(got[0] - pred) > 0.1 * abs(pred - z) + 1e-12 * abs(z):
                cap *= 0.5
                continue
            if sign * got[1].imag <= 0.0:  # passed the peak: Newton on the stationary point from here
                return self.stationary(got[0], got[1], s_new)
            z, dz, s = got[0], got[1], s_new
            if s == end:
                return None
            cap = min(FOLLOW_STEP, 2.0 * cap)
        return None

    def stationary(self, z: complex, dz: complex, s: float) -> tuple[float, complex] | None:
        """Newton on Im dz/d ln kH = 0 along the root z from ln kH = s (g' by a difference over STATIONARY_H)."""
        for _ in range(12):
            other = self.search.polish(z + dz * STATIONARY_H, math.exp(s + STATIONARY_H))
            if other is None:
                return None
            dg = (other[1].imag - dz.imag) / STATIONARY_H
            if not dg < 0.0:
                return None
            step = max(-FOLLOW_STEP, min(FOLLOW_STEP, -dz.imag / dg))
            s_new = min(max(s + step, self.lo), self.hi)
            pred = z + dz * (s_new - s)
            got = self.search.polish(pred, math.exp(s_new))
            if got is None or abs(got[0] - pred) > 0.1 * abs(pred - z) + 1e-12 * abs(z):
                return None
            z, dz, s_prev, s = got[0], got[1], s, s_new
            if abs(s - s_prev) <= STATIONARY_TOL:
                break
        return s, z

    def follow_and_search(self, z: complex, dz: complex, s: float, end: float, best: float) -> bool:
        """Follow the root z from ln kH = s towards `end` to its peak; search there if the peak is above `best`."""
        peak = self.follow_to_peak(z, dz, s, end)
        if peak is None or not peak[1].imag > best * (1.0 + CERT_MARGIN) or peak[0] in self.tops:
            return False
        t = self.at(peak[0], peak[1], peak[1].imag, level=best)
        return t.status == M_OK and t.z.imag > best

    def track(self, best: float, level: float | None = None) -> bool:
        """Between the grid points: every root with Im z >= level (default max(floor, fraction x best)) at a grid
        point is followed into both neighbouring intervals to where its Im z peaks, and at eta = inf the roots across
        the cuts (:meth:`across_cuts`); a peak above `best` is searched there (certified). True if a root higher than
        `best` was found. A grid point whose window is refused is not followed from (docs/physics.md §14.7)."""
        if level is None:
            level = max(self.search.floor, self.fraction() * best)
        grid = self.s_grid
        higher = False
        for i, s in enumerate(grid):
            for z, dz in self.roots_above(s, level) or []:
                for j in (i - 1, i + 1):
                    if 0 <= j < len(grid):
                        higher = self.follow_and_search(z, dz, s, grid[j], best) or higher
        if math.isinf(self.search.p.eta) and CUT_CHARTS:
            higher = self.across_cuts(best) or higher
        return higher

    def across_cuts(self, best: float) -> bool:
        """At eta = inf: every root in the charts beside the branch points (model._sliding_cuts) at every grid point,
        followed into both neighbouring intervals (a root that arrived from the left is not followed back); where
        one grows on the physical sheet above `best`, that kH is searched (certified). True if a root higher than
        `best` was found."""
        if self.charts is None:
            self.charts = CutCharts(self.search.p)
        ev0 = self.charts.evaluations
        crowded: set[int] = set()  # charts whose box held more than CHART_MAX_ROOTS roots at a smaller kH
        arrivals: dict[int, list[complex]] = {}  # chart -> where the roots followed from the last grid point arrived
        higher = False
        for i, s in enumerate(self.s_grid):
            for chart in CHARTS:
                came = arrivals.pop(chart, [])
                for v, dv in self.chart_roots_at(s, chart, crowded, came) or []:
                    back = not any(abs(v - a) <= 1e-8 * abs(v) for a in came)
                    for j in (i - 1, i + 1) if back else (i + 1,):
                        higher = self.follow_chart_root(v, dv, i, j, chart, best, arrivals) or higher
        self.search.evaluations += self.charts.evaluations - ev0
        return higher

    def chart_roots_at(self, s: float, chart: int, crowded: set[int], came: list[complex]
                       ) -> list[tuple[complex, complex]] | None:
        """The roots in a chart's box at grid point s (None: the count failed, or the box is crowded: more than
        CHART_MAX_ROOTS roots, which grow in number like kH, so the chart is not counted at larger kH). came: the
        roots followed there from the last grid point."""
        key = (s, chart)
        if chart in crowded:
            self.chart_roots[key] = None
        elif key not in self.chart_roots:
            n, roots = self.charts.roots(math.exp(s), chart, came, CHART_MAX_ROOTS)
            if n > CHART_MAX_ROOTS:
                crowded.add(chart)
            self.chart_roots[key] = roots
        return self.chart_roots[key]

    def follow_chart_root(self, v: complex, dv: complex, i: int, j: int, chart: int, best: float,
                          arrivals: dict[int, list[complex]]) -> bool:
        """Follow a chart root from grid point i to grid point j; search its highest growing point if above best."""
        if not 0 <= j < len(self.s_grid):
            return False
        top, arrived = self.charts.highest(v, dv, self.s_grid[i], self.s_grid[j], chart, best)
        if j > i and arrived is not None:
            arrivals.setdefault(chart, []).append(arrived)
        if top is None or not top[1].imag > best * (1.0 + CERT_MARGIN) or top[0] in self.tops:
            return False
        t = self.at(top[0], top[1], top[1].imag, level=best)
        return t.status == M_OK and t.z.imag > best


def _family(z: complex, beta: float, rayleigh_z: complex) -> int:
    """The family code (FAMILIES) of a root z; rayleigh_z: the Rayleigh branch's root at the same kH (NaN if
    not followed there)."""
    if not math.isfinite(z.real):
        return -1
    if math.isfinite(rayleigh_z.real) and abs(z - rayleigh_z) <= 1e-8 * abs(z):
        return 0
    x = abs(z.real)
    return 1 if x < 1.0 else (2 if x < 1.0 / beta else 3)


# ------------------------------------------------------------------------------------------------
# public API: one kH, a kH range, a chunk
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class FastestMode:
    """The fastest root of every branch at each kH (:func:`fastest_mode`), broadcast over the arguments.

    growth : Im z of the fastest root (NaN unless status is 0)
    z : that root (complex; NaN unless status is 0)
    family : int8, its family (a key of :data:`FAMILIES`; -1: none)
    count : number of roots with Im z >= floor in the window (-1: not counted, or refused: the window too wide)
    status : int8, a key of :data:`MODE_STATUS`
    re_max, im_max : the window at the floor (:func:`root_window`)
    floor : the growth floor
    """

    growth: np.ndarray
    z: np.ndarray
    family: np.ndarray
    count: np.ndarray
    status: np.ndarray
    re_max: np.ndarray
    im_max: np.ndarray
    floor: float


def _rayleigh_roots(q: np.ndarray, par: tuple) -> np.ndarray:
    """The Rayleigh branch's roots at kH = q (NaN where it is not followed)."""
    from .spectrum import rayleigh_branch

    g, f, b, e, d, x = par
    return np.asarray(rayleigh_branch(q, gamma=g, f=f, beta=b, eta=e, Delta=d, xi=x).z, dtype=complex)


def fastest_mode(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, floor=DEFAULT_FLOOR,
                 count: bool = True) -> FastestMode:
    """At each kH, the root of Eq. implicit_spectrum with the largest Im z over every branch (docs/physics.md §14).

    The roots with Im z >= floor lie in the window of :func:`root_window`. The root is located by the argument
    principle (model.modes' contour sampling: cells with the highest top first, Newton in a cell) and certified
    by a count: no other root of F lies above Im z (1 - 1e-6) in the window. Its family (:data:`FAMILIES`)
    compares it with the Rayleigh branch at the same kH (:func:`rayleigh_branch`) and else says how fast
    it travels. With count=True, also the number of roots with Im z >= floor (refused, -1, where the window at the
    floor is too wide to search: finite eta with a small floor). Arguments broadcast.
    """
    fl = _floor(floor)
    q = check("kH", kH)
    arrays = np.broadcast_arrays(q, *_physical(gamma, f, beta, eta, Delta, xi))
    shape = arrays[0].shape
    out = {k: np.empty(shape, dtype=t) for k, t in (("growth", float), ("z", complex), ("family", np.int8),
                                                    ("count", np.int64), ("status", np.int8), ("re", float),
                                                    ("im", float))}
    warm: dict[tuple, complex] = {}
    for idx in np.ndindex(shape):
        qq, *par = (float(a[idx]) for a in arrays)
        search = _Search(*par, fl)
        key = tuple(par)
        top = search.fastest(qq, warm.get(key), with_count=count)
        if top.status == M_OK:
            warm[key] = top.z
        rz = _rayleigh_roots(np.array([qq]), par)[0] if top.status == M_OK else complex(math.nan, math.nan)
        out["growth"][idx] = top.z.imag
        out["z"][idx] = top.z
        out["family"][idx] = _family(top.z, par[2], rz)
        out["count"][idx] = top.count
        out["status"][idx] = top.status
        out["re"][idx] = search.rho(fl, qq)
        out["im"][idx] = search.top(qq)
    return FastestMode(out["growth"], out["z"], out["family"], out["count"], out["status"], out["re"], out["im"], fl)


#: rows of :func:`sliding_chunk`'s result
SLIDING_ROWS = ("growth_all", "ln_kH_at_max_all", "re_z_at_max_all", "family_all", "rate_all",
                "ln_kH_at_max_rate_all", "re_z_at_max_rate_all", "im_z_at_max_rate_all", "family_rate_all",
                "verdict_reason_all", "max_at_end_all", "rate_at_end_all")


def _verdict_reason(tops: list[_Top]) -> int:
    """The sliding verdict's reason code from the searches at every kH (before the maximum is checked)."""
    status = [t.status for t in tops]
    if M_OK in status:
        return S_UNSTABLE
    if all(s == M_BELOW for s in status):
        return S_STABLE
    return S_WIDE if M_WIDE in status else S_FAILED


def _uncertified(tops: dict[float, _Top], value: float, rate: bool) -> bool:
    """Whether a refused search (window too wide, or failed) leaves room for a root above `value` (Im z, or kH Im
    z for the rate): a search refused below some level certifies nothing under it."""
    for s, t in tops.items():
        if t.status in (M_WIDE, M_FAILED):
            level = t.searched_to * (math.exp(s) if rate else 1.0)
            if not level <= value:
                return True
    return False


def _analyse_one(s_grid: np.ndarray, par: tuple, floor: float, rayleigh: np.ndarray, rate: bool) -> list[float]:
    """One column of :data:`SLIDING_ROWS` for one parameter set; rayleigh: its column of model.growth_chunk on the
    same grid (the Rayleigh branch's own maximum, a certified root, is searched first: the sliding maximum is never
    below it, and the other kH are searched only above it)."""
    an = _Analysis(_Search(*par, floor), s_grid, rate)
    r = growth_rows(rayleigh)
    growth, s_max, re_max = float(r.growth), float(r.ln_kH_at_max), float(r.re_z_at_max)
    start = None
    if math.isfinite(growth) and growth >= floor and an.lo <= s_max <= an.hi:
        start = (s_max, complex(re_max, growth))
    an.sample(start)
    reason = _verdict_reason(list(an.tops.values()))
    if reason == S_STABLE and math.isinf(par[3]) and an.rises_above_floor():
        reason = _verdict_reason(list(an.tops.values()))
    nan = math.nan
    if reason != S_UNSTABLE:
        return [nan] * 9 + [float(reason), nan, nan]
    im, certified = _certified_peak(an)
    row_im = [im.value, im.s, im.z.real, nan]
    if not certified:
        row_im, reason = [nan] * 4, S_UNSTABLE_UNCERTIFIED_MAX
    rt = an.peak(rate=True) if rate else _Peak()
    row_rt = [nan] * 5
    if rate and not _uncertified(an.tops, rt.value, rate=True):
        row_rt = [rt.value, rt.s, rt.z.real, rt.z.imag, nan]
    ks = [v for v in (row_im[1], row_rt[1]) if math.isfinite(v)]
    rz = dict(zip(ks, _rayleigh_roots(np.exp(ks), par), strict=True)) if ks else {}
    if math.isfinite(row_im[1]):
        row_im[3] = float(_family(im.z, par[2], rz[row_im[1]]))
    if math.isfinite(row_rt[1]):
        row_rt[4] = float(_family(rt.z, par[2], rz[row_rt[1]]))
    return row_im + row_rt + [float(reason), float(im.at_end), float(rt.at_end) if rate else nan]


def _certified_peak(an: _Analysis) -> tuple[_Peak, bool]:
    """The maximum of Im z, refined, then the roots followed between the grid points (_Analysis.track): a root found
    higher starts another round. Certified unless a search was refused above it."""
    im = an.peak(rate=False)
    for _ in range(CERT_ROUNDS):
        if not an.track(im.value):
            break
        im = an.peak(rate=False)
    return im, not _uncertified(an.tops, im.value, rate=False)


def sliding_chunk(s_grid: np.ndarray, params: np.ndarray, floor: float = DEFAULT_FLOOR,
                  rayleigh: np.ndarray | None = None, rate: bool = False) -> np.ndarray:
    """Pure function of one chunk: params (6, n) rows gamma, f, beta, eta, Delta, xi -> (12, n) results.

    Rows (:data:`SLIDING_ROWS`): the maximum over ln kH in [s_grid[0], s_grid[-1]] of the fastest root's Im z,
    its ln kH, Re z and family; the maximum of the temporal rate kH Im z, its ln kH, root and family; the verdict
    reason (:data:`SLIDING_STATUS`); 1.0 where a maximum lies at an end of the range (it may go on beyond). The
    maxima are NaN unless the verdict reason is 1 (unstable, maximum certified). rayleigh: the result of
    :func:`growth_chunk` for the same grid and parameters, if already computed (else it is). No shared
    state: a distributed backend can run chunks anywhere.
    """
    from .stability import growth_chunk

    fl = _floor(floor)
    s = np.asarray(s_grid, dtype=float)
    ray = growth_chunk(s, params) if rayleigh is None else rayleigh
    out = np.empty((len(SLIDING_ROWS), params.shape[1]))
    for j in range(params.shape[1]):
        out[:, j] = _analyse_one(s, tuple(float(v) for v in params[:, j]), fl, ray[:, j], rate)
    return out


def sliding_verdict(reason: np.ndarray) -> np.ndarray:
    """The sliding verdict class (int8: 0 stable, 1 unstable, 2 undetermined; :data:`VERDICTS`) of reason codes
    (:data:`SLIDING_STATUS`, e.g. :func:`sliding_chunk`'s ``verdict_reason_all`` row)."""
    reason = np.asarray(reason)
    unstable = np.isin(reason, (S_UNSTABLE, S_UNSTABLE_UNCERTIFIED_MAX))
    return np.where(reason == S_STABLE, Verdict.STABLE,
                    np.where(unstable, Verdict.UNSTABLE, Verdict.UNDETERMINED)).astype(np.int8)


def family_codes(row: np.ndarray) -> np.ndarray:
    """A family row of :func:`sliding_chunk` (NaN: none) as int8 codes of :data:`FAMILIES` (-1: none)."""
    row = np.asarray(row)
    return np.where(np.isnan(row), -1, row).astype(np.int8)


@dataclass(frozen=True)
class SlidingResult:
    """The stability of steady sliding over every branch and a kH range (:func:`sliding_analysis`).

    Attributes
    ----------
    growth : the maximum over the kH range of the fastest root's Im z (as the paper's c(k) plots; NaN unless the
        verdict is unstable with a certified maximum), kH_at_max, z_at_max and family (:data:`FAMILIES`) there
    rate : the maximum of the temporal growth rate kH Im z (in units of c_s/H), kH_at_max_rate, z_at_max_rate
    max_at_end, rate_at_end : the maximum lies at an end of the range (it may continue beyond)
    lower_bound : True at finite eta: the result holds at the kH grid searched and along the roots followed from
        it (above M/2), but a root can rise higher between two grid points unseen (narrow humps, 0.005 to 0.1
        decades wide in kH, of roots that come up through the real axis beside the layers' poles: docs/physics.md
        §14.7), so growth is a lower bound of the maximum over the continuous range and a stable verdict holds at
        the kH searched; a denser kH grid narrows the gap. False at eta = inf, where the roots beside the branch
        points are followed across the cuts too (§14.7 states what remains unexcluded)
    verdict : int8, 0 stable, 1 unstable, 2 undetermined (:data:`VERDICTS`); verdict_reason :
        :data:`SLIDING_STATUS`
    floor : the growth floor; kH_range : the range searched
    rayleigh : the Rayleigh branch alone on the same grid (:func:`growth_analysis`), side by side
    """

    growth: np.ndarray
    kH_at_max: np.ndarray
    z_at_max: np.ndarray
    family: np.ndarray
    rate: np.ndarray
    kH_at_max_rate: np.ndarray
    z_at_max_rate: np.ndarray
    family_rate: np.ndarray
    max_at_end: np.ndarray
    rate_at_end: np.ndarray
    lower_bound: np.ndarray
    verdict: np.ndarray
    verdict_reason: np.ndarray
    floor: float
    kH_range: tuple[float, float]
    rayleigh: GrowthResult


def sliding_analysis(*, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, kH=None, floor=DEFAULT_FLOOR,
                     rate: bool = False) -> SlidingResult:
    """Is steady sliding stable? The fastest root of every branch over a kH range (docs/physics.md §14).

    kH : 1-D increasing grid (default :data:`SLIDING_KH`, 17 points over [1e-2, 1e2]) whose ends are the range.
    The Rayleigh branch's maximum (:func:`growth_analysis`, returned as ``.rayleigh``) is searched first;
    then every grid point, once a growth M is known only above a fraction of it (every root there located in one
    contour, which serves the maximum and the tracking below; branch and bound: a root lower cannot raise the
    maximum, and the contour stays away from the real axis), at the floor until a root above it is found. The
    best point is refined on the root that carries it (followed in kH to where its Im z is stationary,
    Newton, and certified there); then every root above max(floor, M/4) (M/2 at finite eta) at a grid point is
    followed to its peak in the neighbouring intervals, and at eta = inf every root beside a branch point is
    followed across the cuts (``_sliding_cuts``); a peak above the maximum M is certified and taken. What
    is not excluded between the grid points, and how often it matters, is in docs/physics.md §14.7: at finite eta
    the maximum is a lower bound of the continuous one (``lower_bound``; a denser kH narrows the gap). Verdict:
    stable if no root has Im z >= floor at any kH searched, unstable if one does (:data:`SLIDING_STATUS`).
    rate=True also gives the maximum of the temporal rate kH Im z (a point is then searched above the lower of the
    two levels: costlier at finite eta and large kH, where the rate often keeps growing to the end of the range);
    else those fields are NaN. Parameters broadcast.
    """
    from .stability import _grid, growth_chunk, growth_result

    fl = _floor(floor)
    grid = SLIDING_KH if kH is None else _grid(kH)
    arrays = np.broadcast_arrays(*_physical(gamma, f, beta, eta, Delta, xi))
    shape = arrays[0].shape
    params = np.stack([a.reshape(-1) for a in arrays])
    s_grid = np.log(grid)
    ray = growth_chunk(s_grid, params)
    rows = sliding_chunk(s_grid, params, fl, ray, rate)
    r = dict(zip(SLIDING_ROWS, (row.reshape(shape) for row in rows), strict=True))
    reason = r["verdict_reason_all"]
    verdict = sliding_verdict(reason)
    fam = family_codes

    z_rate = r["re_z_at_max_rate_all"] + 1j * r["im_z_at_max_rate_all"]
    return SlidingResult(r["growth_all"], np.exp(r["ln_kH_at_max_all"]),
                         r["re_z_at_max_all"] + 1j * r["growth_all"], fam(r["family_all"]), r["rate_all"],
                         np.exp(r["ln_kH_at_max_rate_all"]), z_rate, fam(r["family_rate_all"]),
                         r["max_at_end_all"] == 1.0, r["rate_at_end_all"] == 1.0, np.isfinite(arrays[3]), verdict,
                         reason.astype(np.int8), fl,
                         (float(grid[0]), float(grid[-1])), growth_result(ray, shape))
