"""The fastest root of every branch at one kH, certified by counts (docs/physics.md §14).

:class:`Search` holds one parameter set: the window where the roots above a level can be (``_kernels.window``),
counts of rectangles (the compiled ``_kernels.contour.count_rectangle``, edges moved past a root by
:func:`.contour.move_edge`), and the fastest root at a kH, found band by band from the top down
(:func:`.contour.best_first` in a band), certified by a count above it and refused where the window is too wide.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .._kernels.contour import LIN_TOL, PHASE_MAX, TRAP_TOL, count_rectangle
from .._kernels.newton import FULL_TOL, KH, newton_root
from .._kernels.records import NO_BOX, Params
from .._kernels.window import exclusion_radius, top_of_roots
from .contour import LADDER_DAMPED, Problem, best_first, h_min, move_edge, real_axis_singularities, spacing

SAMPLE_LIMIT = 2e5  # a window whose bottom edge needs more samples than this (estimated) is refused ("too wide")
POLE_SAMPLES = 25.0  # samples per real-axis pole per level of its graded seeds (the estimate of Search.affordable)
DESCENT = 2.0  # ratio of the levels of the cold search (a band [y/2, y] at a time) ...
HINT_FACTOR = 0.5  # ... below one band [HINT_FACTOR x the expected growth, top]
TOP_REL = 1e-6  # a located root at Im z = c is certified the fastest by a count above c (1 - TOP_REL)
WARM_ITERS = 40  # Newton evaluations allowed for a warm start

#: status of the fastest mode at one kH (the keys of model.sliding.MODE_STATUS)
M_OK, M_BELOW, M_WIDE, M_FAILED = 0, 1, 2, 3


@dataclass
class Top:
    """The outcome of the search at one kH."""

    status: int
    z: complex = complex(math.nan, math.nan)
    dzds: complex = complex(math.nan, math.nan)  # dz/d ln kH at z
    searched_to: float = math.nan  # the lowest level certified empty above (status M_WIDE)
    count: int = -1  # roots with Im z >= floor (-1: not counted)
    evaluations: int = 0


class Search:
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

    def singularities(self, q: float, x: float, y: float) -> tuple:
        """The real-axis singularities that lines at height >= y of the window [-x, x] see (graded seeds)."""
        return real_axis_singularities(q, self.p.beta, self.p.eta, x + 1.0, spacing(q), y)

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
        poles, half = self.singularities(q, x, y0)
        x0, x1 = -x, x
        shifts = [0, 0, 0, 0]
        while True:
            hb = h_min(size, y0)
            ht = h_min(size, y1)
            st, n, edge, _, nev, s1, s2 = count_rectangle(x0, x1, y0, y1, spacing(q), poles, half, q, *self.p, hb,
                                                          hb, ht, PHASE_MAX, TRAP_TOL, LIN_TOL)
            self.evaluations += nev
            if st == 0:
                return n, s1, s2, (x0, x1, y0, y1)
            if st != 1:
                return None
            moved = move_edge((x0, x1, y0, y1), edge, shifts, size)
            if moved is None:
                return None
            x0, x1, y0, y1 = moved

    def top_root_in(self, q: float, x: float, y0: float, y1: float) -> tuple[complex | None, int]:
        """(the root of largest Im z in [-x, x] x [y0, y1], the number of roots there): best first, the cell with
        the highest top is split until its root is located by Newton; cells below the best root found are never
        split. (None, 0) if the window holds none; RuntimeError if the contour fails."""
        prob = Problem(q, *self.p, x, y0, y1, spacing(q), self.singularities(q, x, y0))
        cell, n = prob.outer()
        best = best_first(prob, cell, n) if n else None
        self.evaluations += prob.evaluations
        return best, n

    # -- the fastest root at one kH --------------------------------------------------------------------
    def polish(self, z0: complex, q: float) -> tuple[complex, complex] | None:
        """Newton on F(z; q) from z0 (the model's one loop); (z, dz/d ln kH) or None."""
        r = newton_root(z0, KH, 0.0, q, self.p, WARM_ITERS, FULL_TOL, 0.0, 0.9, 1.0, NO_BOX)
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
                with_count: bool = False, level: float | None = None) -> Top:
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

    def _fastest(self, q: float, top: float, warm: complex | None, hint: float | None, level: float) -> Top:
        if not top > level:
            return Top(M_BELOW, searched_to=level, count=0 if level == self.floor else -1)
        try:
            if warm is not None:
                got = self.polish(warm, q)
                if got is not None and level <= got[0].imag <= top:
                    z = self.certify(got[0], q, top, level)
                    if z is not None:
                        return self._located(z, q)
            return self._descend(q, top, hint, level)
        except RuntimeError:
            return Top(M_FAILED, searched_to=top)

    def _descend(self, q: float, top: float, hint: float | None, level: float) -> Top:
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
                return Top(M_WIDE, searched_to=hi)
            x = self.rho(lo, q)
            if expect_root:  # the band of the hint: sampled once, for the count and the search at once
                z, n = self.top_root_in(q, x, lo, hi)
                expect_root = False
            else:  # bands expected empty: counted by the compiled kernel first (no samples kept)
                n = self.count(q, x, lo, hi)
                if n is None:
                    return Top(M_FAILED, searched_to=hi)
                z = self.top_root_in(q, x, lo, hi)[0] if n else None
            if z is not None:
                res = self._located(z, q)
                if lo == self.floor:
                    res.count = n
                return res
            hi = lo
            lo = level if cheap else hi / DESCENT
        return Top(M_BELOW, searched_to=level, count=0 if level == self.floor else -1)

    def affordable(self, q: float, x: float, y: float) -> bool:
        """Whether the window [-x, x] at height y is within the search limit: the samples its bottom edge needs,
        estimated as its length over the initial spacing plus, for each real-axis pole it sees (finite eta: the
        families whose poles the edge does not damp, (1 + eta) kH beta_j y < LADDER_DAMPED, spaced
        d = pi / ((1 + eta) kH beta_j) in Re z far out), POLE_SAMPLES x (1 + log3(d / y)) samples (measured: the
        graded seeds and the refinement between them), are at most SAMPLE_LIMIT."""
        if not math.isfinite(x):
            return False
        n = 2.0 * x / spacing(q)
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

    def _located(self, z: complex, q: float) -> Top:
        got = self.polish(z, q)
        dzds = got[1] if got is not None and abs(got[0] - z) <= 1e-10 * abs(z) else complex(math.nan, math.nan)
        return Top(M_OK, z=z, dzds=dzds)
