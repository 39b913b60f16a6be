"""The fastest root of every branch over a kH range: branch and bound over the grid, the roots followed between
its points and across the cuts (docs/physics.md §14.7-14.8).

:class:`Analysis` holds one parameter set over a grid of ln kH: the grid searched (:class:`.search.Search`, each
point only above the level where it could raise a maximum found so far), the best point refined on the root that
carries it to where its objective is stationary, and the roots above a fraction of the maximum followed into the
neighbouring intervals (at eta = inf also across the cuts beside the branch points, :mod:`.cuts`); a peak found
higher is certified by a search there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..stability import growth_rows
from .contour import Problem, roots_from_sums, spacing
from .cuts import CHARTS, CutCharts
from .search import M_BELOW, M_FAILED, M_OK, M_WIDE, Search, Top

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
CUT_CHARTS = True  # eta = inf: also follow the roots across the cuts beside the branch points (.cuts)
CHART_MAX_ROOTS = 2  # ... where a chart's box holds at most this many (their number grows like kH: cost)
CERT_ROUNDS = 6  # rounds of refining the maximum and following the roots between the grid points


@dataclass
class Peak:
    """The best certified point of one objective (Im z or kH Im z) over the range."""

    value: float = -math.inf
    s: float = math.nan
    z: complex = complex(math.nan, math.nan)
    at_end: bool = False


class Analysis:
    """The fastest root over a kH range for one parameter set (:func:`sliding_analysis`), branch and bound: a kH
    is searched only above the level at which it could raise a maximum found so far (the contour then stays away
    from the real axis and its poles); the floor is searched only while no root above it has been found."""

    def __init__(self, search: Search, s_grid: np.ndarray, rate: bool = False):
        self.search = search
        self.s_grid = [float(v) for v in s_grid]
        self.lo, self.hi = self.s_grid[0], self.s_grid[-1]
        self.rate = rate
        self.tops: dict[float, Top] = {}
        self.charts: CutCharts | None = None  # eta = inf: the charts across the cuts (.cuts)
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
           level: float | None = None) -> Top:
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

    def sample_from(self, rayleigh: np.ndarray) -> None:
        """:meth:`sample`, started from the Rayleigh branch's own maximum (a certified root; rayleigh: its column of
        model.growth_chunk on the same grid) where it lies in the range above the floor: the maximum over every
        branch is never below it, and the other kH are then searched only above it."""
        r = growth_rows(rayleigh)
        growth, s_max, re_max = float(r.growth), float(r.ln_kH_at_max), float(r.re_z_at_max)
        start = None
        if math.isfinite(growth) and growth >= self.search.floor and self.lo <= s_max <= self.hi:
            start = (s_max, complex(re_max, growth))
        self.sample(start)

    def seed(self, guides: list[tuple[float, complex]]) -> None:
        """Search at each guide (ln kH, z) inside the range, above half its Im z (and the floor), warm-started from
        z: a certified root found there joins the points the maximum is taken over. Nothing else is kept (a search
        that finds nothing that high says nothing about the floor, so it does not enter the verdict)."""
        for s, z in guides:
            if not (self.lo <= s <= self.hi and math.isfinite(z.imag)) or s in self.tops:
                continue
            t = self.at(s, z, z.imag, level=max(self.search.floor, 0.5 * z.imag))
            if t.status != M_OK:
                del self.tops[s]

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

    def every_root(self, s: float) -> Top | None:
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
            t = Top(M_BELOW, searched_to=max(self.known[s][0], fl))
        else:
            z, dz = max(roots, key=lambda r: r[0].imag)
            t = Top(M_OK, z=z, dzds=dz)
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
    def objective(rate: bool, s: float, t: Top) -> float:
        if t.status != M_OK:
            return -math.inf
        return math.exp(s) * t.z.imag if rate else t.z.imag

    def best(self, rate: bool) -> tuple[float, Top]:
        return max(self.tops.items(), key=lambda kv: self.objective(rate, kv[0], kv[1]))

    def peak(self, rate: bool) -> Peak:
        """The maximum of Im z (rate False) or of kH Im z (rate True) over the range: the best certified point,
        refined on the root that carries it (followed to where its objective is stationary, then certified
        there; if another root is higher there, that one is refined in turn)."""
        for _ in range(FOLLOW_ROUNDS):
            s, t = self.best(rate)
            if t.status != M_OK or not self.refine(rate, s, t):
                break
        s, t = self.best(rate)
        if t.status != M_OK:
            return Peak()
        at_end = abs(s - self.lo) <= END_TOL or abs(s - self.hi) <= END_TOL
        return Peak(self.objective(rate, s, t), s, t.z, at_end)

    def refine(self, rate: bool, s: float, t: Top) -> bool:
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
            got = roots_from_sums(n, s1, s2, known, lambda z: self.search.polish(z, q),
                                   lambda z: x0 <= z.real <= x1 and y0 <= z.imag <= y1)
            if got is not None:
                return got
        prob = Problem(q, *self.search.p, x, level, top, spacing(q),
                        self.search.singularities(q, x, level))
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

    @staticmethod
    def slope(rate: bool, z: complex, dz: complex) -> float:
        """The sign-carrying slope of the objective along a root: d(Im z)/d ln kH, or (rate) e^-s d(kH Im z)/d ln kH
        = Im z + Im dz/d ln kH."""
        return dz.imag + (z.imag if rate else 0.0)

    def follow_to_peak(self, z: complex, dz: complex, s: float, end: float, rate: bool = False
                       ) -> tuple[float, complex] | None:
        """Follow the root z (slope dz) from ln kH = s towards `end` while its objective (Im z, or kH Im z with rate)
        rises; where it stops rising inside, the stationary point by Newton (as :meth:`refine`). (s, z) of that peak,
        or None if the objective falls from the start, rises all the way to `end` (the root is there: the search at
        `end` covers it), or the root is lost (it leaves the physical sheet through a cut)."""
        sign = 1.0 if end > s else -1.0
        if not math.isfinite(dz.real) or sign * self.slope(rate, z, dz) <= 0.0:
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
            if sign * self.slope(rate, *got) <= 0.0:  # passed the peak: Newton on the stationary point from here
                return self.stationary(got[0], got[1], s_new, rate)
            z, dz, s = got[0], got[1], s_new
            if s == end:
                return None
            cap = min(FOLLOW_STEP, 2.0 * cap)
        return None

    def stationary(self, z: complex, dz: complex, s: float, rate: bool = False) -> tuple[float, complex] | None:
        """Newton on the objective's slope = 0 along the root z from ln kH = s (its derivative by a difference over
        STATIONARY_H)."""
        for _ in range(12):
            other = self.search.polish(z + dz * STATIONARY_H, math.exp(s + STATIONARY_H))
            if other is None:
                return None
            g0 = self.slope(rate, z, dz)
            dg = (self.slope(rate, *other) - g0) / STATIONARY_H
            if not dg < 0.0:
                return None
            step = max(-FOLLOW_STEP, min(FOLLOW_STEP, -g0 / dg))
            s_new = min(max(s + step, self.lo), self.hi)
            pred = z + dz * (s_new - s)
            got = self.search.polish(pred, math.exp(s_new))
            if got is None or abs(got[0] - pred) > 0.1 * abs(pred - z) + 1e-12 * abs(z):
                return None
            z, dz, s_prev, s = got[0], got[1], s, s_new
            if abs(s - s_prev) <= STATIONARY_TOL:
                break
        return s, z

    def follow_and_search(self, z: complex, dz: complex, s: float, end: float, best: float,
                          rate: bool = False) -> bool:
        """Follow the root z from ln kH = s towards `end` to the peak of its objective; search there (certified) if
        the peak is above `best` (an Im z, or with rate a kH Im z)."""
        peak = self.follow_to_peak(z, dz, s, end, rate)
        if peak is None or peak[0] in self.tops:
            return False
        scale = math.exp(peak[0]) if rate else 1.0
        if not peak[1].imag * scale > best * (1.0 + CERT_MARGIN):
            return False
        t = self.at(peak[0], peak[1], peak[1].imag, level=best / scale)
        return t.status == M_OK and t.z.imag * scale > best

    def track(self, best: float, level: float | None = None, rate: bool = False) -> bool:
        """Between the grid points: every root above the level at a grid point (default: the fraction of `best`, and
        the floor; with rate, `best` is a kH Im z and the level at each point best x fraction / kH) is followed into
        both neighbouring intervals to where its objective peaks, and at eta = inf (Im z) the roots across the cuts
        (:meth:`across_cuts`); a peak above `best` is searched there (certified). True if a root higher than `best`
        was found. A grid point whose window is refused is not followed from (docs/physics.md §14.7)."""
        grid = self.s_grid
        higher = False
        for i, s in enumerate(grid):
            lev = level
            if lev is None:
                lev = max(self.search.floor, self.fraction() * best * (math.exp(-s) if rate else 1.0))
            for z, dz in self.roots_above(s, lev) or []:
                for j in (i - 1, i + 1):
                    if 0 <= j < len(grid):
                        higher = self.follow_and_search(z, dz, s, grid[j], best, rate) or higher
        if math.isinf(self.search.p.eta) and CUT_CHARTS and not rate:
            higher = self.across_cuts(best) or higher
        return higher

    def across_cuts(self, best: float) -> bool:
        """At eta = inf: every root in the charts beside the branch points (.cuts) at every grid point,
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

    # -- the maxima and their certificate ------------------------------------------------------------------------------
    def uncertified(self, value: float, rate: bool) -> bool:
        """Whether a refused search (window too wide, or failed) leaves room for a root above `value` (Im z, or kH Im
        z for the rate): a search refused below some level certifies nothing under it."""
        for s, t in self.tops.items():
            if t.status in (M_WIDE, M_FAILED):
                level = t.searched_to * (math.exp(s) if rate else 1.0)
                if not level <= value:
                    return True
        return False

    def certified_peak(self, rate: bool = False) -> tuple[Peak, bool]:
        """The maximum of Im z (or with rate of kH Im z), refined, then the roots followed between the grid points
        (:meth:`track`): a root found higher starts another round. Certified unless a search was refused above it."""
        pk = self.peak(rate)
        for _ in range(CERT_ROUNDS):
            if not math.isfinite(pk.value) or not self.track(pk.value, rate=rate):
                break
            pk = self.peak(rate)
        return pk, not self.uncertified(pk.value, rate)


def family(z: complex, beta: float, rayleigh_z: complex) -> int:
    """The family code (FAMILIES) of a root z; rayleigh_z: the Rayleigh branch's root at the same kH (NaN if
    not followed there)."""
    if not math.isfinite(z.real):
        return -1
    if math.isfinite(rayleigh_z.real) and abs(z - rayleigh_z) <= 1e-8 * abs(z):
        return 0
    x = abs(z.real)
    return 1 if x < 1.0 else (2 if x < 1.0 / beta else 3)


def rayleigh_roots(q: np.ndarray, par: tuple) -> np.ndarray:
    """The Rayleigh branch's roots at kH = q (NaN where it is not followed)."""
    from ..spectrum import rayleigh_branch

    g, f, b, e, d, x = par
    return np.asarray(rayleigh_branch(q, gamma=g, f=f, beta=b, eta=e, Delta=d, xi=x).z, dtype=complex)
