"""Thresholds of sliding over every branch: where the sliding verdict changes in gamma or eta (docs/physics.md §14.10).

The Rayleigh thresholds of :mod:`model.thresholds` are the sign changes of that branch's max growth. Over every
branch, the max growth G(t) (t = ln gamma or ln eta) is :func:`sliding_analysis`'s: the largest Im z of the
fastest root over the kH range, known where it is at least the floor and otherwise only as "below the floor". A
threshold is where G crosses zero: a neutral mode (real z, Im z stationary in ln kH, or at an end of the range) of
whichever root crosses. The solver

1. scans the sliding verdict at SCAN_POINTS log-spaced values of the range (+1 unstable, -1 stable, undetermined);
2. for each pair of neighbouring values with opposite verdicts, solves the neutral mode of the unstable side's
   fastest root (``_kernels.neutral.neutral_mode`` from that root, evaluated on the upper lip of the cut,
   where a root beyond the shear speed meets the real axis at eta = inf; free in kH, or at the end of the kH range
   where its maximum goes), bisecting the bracket on the verdict until it converges where the verdict can change:
   in the bracket or beyond its stable end by up to EXTEND x floor / |dG/dt| (the verdict at the floor changes
   where G = floor, not where G = 0);
3. certifies it twice, at t -/+ d (d such that the growth there is about CERT_GROWTH x the floor, within
   [CERT_MIN_REL, CERT_MAX_REL]) with a local floor a tenth of the growth expected there: on the unstable side the
   fastest root over the range is the neutral mode's continuation (same kH to CERT_S in ln kH, Re z to CERT_X
   relative) with the growth its slope predicts (within CERT_SLOPE); on the stable side sliding is stable (no root
   of any branch above the local floor). The sliding verdict at the floor changes where G = floor, about
   floor / |dG/dt| from the neutral mode.

Crossings are returned as :class:`crossings.Crossings` with the codes of :data:`CROSSING_STATUS`
(0 certified, 1 certified at an end of the kH range; 3 a jump: the verdict changes with no neutral mode; 5
undefined: an undetermined verdict in the bracket; 6 not certified).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _kernels as K
from ._crossing import Crossing, empty_crossings
from ._kernels.neutral import UPPER_LIP
from ._roots.search import M_BELOW, M_OK, Search
from ._roots.track import Analysis
from .crossings import (
    SCAN_POINTS,
    T_FOUND,
    T_JUMP,
    T_NOT_CERTIFIED,
    T_STABLE,
    T_UNDEFINED,
    T_UNSTABLE,
    X_CERTIFIED,
    X_EDGE,
    X_JUMP,
    X_NOT_CERTIFIED,
    X_UNDEFINED,
    Crossings,
)
from .stability import growth_chunk

BISECTIONS = 12  # bisections of a bracket on the verdict
CERT_GROWTH = 10.0  # the unstable side of the certificate: where the growth is about this x the floor ...
CERT_MAX_REL = 1e-3  # ... at most this far from the threshold (in t)
CERT_MIN_REL = 1e-9  # ... and at least this far
CERT_SLOPE = 3.0  # the growth there within this factor of |slope| x distance
CERT_S = 1e-4  # the fastest root there within this of the neutral mode in ln kH ...
CERT_X = 1e-6  # ... and in Re z, relative to max(|x|, 1e-3)
EDGE_S = 1e-12  # a maximum within this of an end of the kH range (in ln kH) is at that end
SLOPE_H = 1e-6  # the central difference (in t) of the slope dG/dt on the root at the maximum
JUMP_GROWTH = 100.0  # a bracket bisected to the end whose unstable side still grows this x the floor: a jump
EXTEND = 20.0  # the neutral mode may lie beyond the bracket's stable end by this x floor / |dG/dt| ...
EXTEND_MAX = 0.5  # ... at most this (in t)
APPROACH = 0.7  # a step towards the zero of the maximum growth covers this fraction of its linear estimate ...
APPROACH_STEPS = 8  # ... at most this many times


@dataclass
class _Side:
    """The sliding verdict at t = ln gamma or ln eta, and the fastest root over the range where unstable."""

    t: float
    sign: float  # +1 unstable, -1 stable, NaN undetermined
    g: float = math.nan  # the max growth (Im z) where unstable
    s: float = math.nan  # its ln kH
    z: complex = complex(math.nan, math.nan)
    slope: float = math.nan  # dG/dt there: Im dz/dt of that root at fixed kH (envelope theorem)


class _Point:
    """One parameter set: the sliding verdict as a function of t (each evaluation counted)."""

    def __init__(self, which: int, s_grid: np.ndarray, p: tuple[float, ...], floor: float):
        self.which = which
        self.s_grid = np.asarray(s_grid, dtype=float)
        self.p = p
        self.floor = floor
        self.evaluations = 0

    def params(self, t: float) -> tuple[float, ...]:
        q = list(self.p)
        q[self.which] = math.exp(t)
        return tuple(q)

    def ev(self, t: float, floor: float | None = None) -> _Side:
        """The sliding verdict and its maximum at t (as model.sliding_analysis; with another floor if given)."""
        self.evaluations += 1
        fl = self.floor if floor is None else floor
        par = self.params(t)
        ray = growth_chunk(self.s_grid, np.array(par, dtype=float)[:, None])[:, 0]
        an = Analysis(Search(*par, fl), self.s_grid)
        an.sample_from(ray)
        status = [top.status for top in an.tops.values()]
        if M_OK in status:
            peak = an.peak(rate=False)
            return _Side(t, 1.0, peak.value, peak.s, peak.z, self.slope(t, peak.s, peak.z))
        if all(st == M_BELOW for st in status):
            return _Side(t, -1.0)
        return _Side(t, math.nan)

    def slope(self, t: float, s: float, z: complex) -> float:
        """Im dz/dt of the root z at ln kH = s, by a central difference of SLOPE_H on roots polished by Newton."""
        zs = []
        for dt in (SLOPE_H, -SLOPE_H):
            got = Search(*self.params(t + dt), self.floor).polish(z, math.exp(s))
            if got is None or abs(got[0] - z) > 1e-3 * abs(z):
                return math.nan
            zs.append(got[0])
        return ((zs[0] - zs[1]) / (2.0 * SLOPE_H)).imag

    def at_edge(self, s: float) -> bool:
        return abs(s - self.s_grid[0]) <= EDGE_S or abs(s - self.s_grid[-1]) <= EDGE_S


def _allowed(pt: _Point, u: _Side, t_stable: float, t_unstable: float) -> tuple[float, float]:
    """Where the neutral mode may lie: between the bracket's ends, and beyond its stable end by up to EXTEND x floor /
    |slope| (the verdict at the floor changes where G = floor, that far from where G = 0)."""
    reach = min(EXTEND_MAX, EXTEND * pt.floor / abs(u.slope)) if math.isfinite(u.slope) and u.slope else 0.0
    if t_stable < t_unstable:
        return t_stable - reach, t_unstable
    return t_unstable, t_stable + reach


def _neutral(pt: _Point, u: _Side, t_stable: float, t_unstable: float) -> tuple[float, float, float, float] | None:
    """The neutral mode (x, s, t, slope) from an unstable point's fastest root u, if it converges where the verdict
    can change (:func:`_allowed`). Free in s, or at the end of the kH range Newton runs to."""
    a, b = _allowed(pt, u, t_stable, t_unstable)
    t0 = 0.5 * (a + b)
    if math.isfinite(u.slope) and u.slope != 0.0:
        t0 = min(max(u.t - u.g / u.slope, a), b)
    tries = [(u.s, pt.at_edge(u.s))]
    tiny = 4 * np.finfo(float).eps
    for s0, edge in tries:
        try:
            x, s, t, ok, _, _, slope, _ = K.neutral_mode(u.z.real, s0, t0, pt.which, edge, *pt.p, UPPER_LIP)
        except ZeroDivisionError:
            continue
        if not ok:
            continue
        if not edge and not (pt.s_grid[0] <= s <= pt.s_grid[-1]) and len(tries) == 1:
            tries.append((pt.s_grid[-1] if s > pt.s_grid[-1] else pt.s_grid[0], True))  # the maximum at that end
            continue
        in_range = edge or pt.s_grid[0] <= s <= pt.s_grid[-1]
        if in_range and a - tiny * max(1.0, abs(t)) <= t <= b + tiny * max(1.0, abs(t)):
            return x, s, t, slope
    return None


def _certify(pt: _Point, x: float, s: float, t: float, slope: float) -> Crossing | None:
    """The crossing at the neutral mode (x, s, t) if both sides confirm it (module docstring, step 3): at t -/+ d the
    sliding analysis with a floor well below |slope| d finds no root on the stable side, and on the unstable side
    the neutral mode's continuation as the fastest root, with the growth its slope predicts."""
    if not (math.isfinite(slope) and slope != 0.0):
        return None
    d = min(CERT_MAX_REL, max(CERT_GROWTH * pt.floor / abs(slope), CERT_MIN_REL * max(1.0, abs(t))))
    local = min(pt.floor, abs(slope) * d / CERT_GROWTH)  # the growth expected at t + d is CERT_GROWTH x this
    direction = 1 if slope > 0 else -1
    up = pt.ev(t + direction * d, local)
    if up.sign != 1.0 or abs(up.z.real - x) > CERT_X * max(abs(x), 1e-3):
        return None
    if not pt.at_edge(s) and abs(up.s - s) > CERT_S:
        return None
    if not abs(slope) * d / CERT_SLOPE <= up.g <= CERT_SLOPE * abs(slope) * d:
        return None
    if pt.ev(t - direction * d, local).sign != -1.0:
        return None
    return Crossing(X_EDGE if pt.at_edge(s) else X_CERTIFIED, t - d, t + d, t, s, x, direction)


def _approach(pt: _Point, u: _Side, t_stable: float, t_unstable: float) -> tuple[float, float, float, float] | None:
    """From the unstable side u toward where its maximum growth vanishes: steps of APPROACH x the linear estimate
    of the distance (g/slope), each searched with a floor a hundredth of the growth expected there (the growth
    shrinks; at eta = inf the window hardly depends on the floor), the neutral mode tried from each point."""
    a, b = _allowed(pt, u, t_stable, t_unstable)
    for _ in range(APPROACH_STEPS):
        res = _neutral(pt, u, t_stable, t_unstable)
        if res is not None:
            return res
        if not (math.isfinite(u.slope) and u.slope != 0.0 and u.g > 0.0):
            return None
        t = min(max(u.t - APPROACH * u.g / u.slope, a), b)
        nxt = pt.ev(t, max(1e-3 * pt.floor, 1e-2 * (1.0 - APPROACH) * u.g))
        if nxt.sign != 1.0:
            return None
        u = nxt
    return None


def _solve_bracket(pt: _Point, a: _Side, b: _Side) -> Crossing:
    """The verdict change between a and b (opposite signs): the neutral mode, certified, with bisection."""
    approached: set[complex] = set()  # the roots approached so far (each root once: an approach costs searches)
    for _ in range(BISECTIONS):
        u, v = (a, b) if a.sign > 0 else (b, a)
        new_root = not any(abs(u.z - z) <= 1e-3 * abs(z) for z in approached)
        res = _approach(pt, u, v.t, u.t) if new_root else _neutral(pt, u, v.t, u.t)
        approached.add(u.z)
        if res is not None:
            found = _certify(pt, *res)
            if found is not None:
                return found
        m = pt.ev(0.5 * (a.t + b.t))
        if not math.isfinite(m.sign):
            return Crossing(X_UNDEFINED, a.t, b.t, m.t)
        if m.sign == a.sign:
            a = m
        else:
            b = m
    u = a if a.sign > 0 else b
    reason = X_JUMP if u.g > JUMP_GROWTH * pt.floor else X_NOT_CERTIFIED
    return Crossing(reason, a.t, b.t, 0.5 * (a.t + b.t))


def _crossings(pt: _Point, ts: np.ndarray) -> tuple[list[Crossing], list[_Side]]:
    """Every change of the sliding verdict over the scan values ts (opposite verdicts, or only NaN between)."""
    scan = [pt.ev(float(t)) for t in ts]
    out: list[Crossing] = []
    prev: _Side | None = None
    gap = False
    for e in scan:
        if not math.isfinite(e.sign):
            gap = prev is not None or gap
            continue
        if prev is not None and prev.sign != e.sign:
            out.append(Crossing(X_UNDEFINED, prev.t, e.t) if gap else _solve_bracket(pt, prev, e))
        prev, gap = e, False
    return out, scan


def _status(found: list[Crossing], scan: list[_Side]) -> int:
    if any(c.certified for c in found):
        return T_FOUND
    if found:
        return {X_JUMP: T_JUMP, X_UNDEFINED: T_UNDEFINED}.get(found[0].reason, T_NOT_CERTIFIED)
    signs = [e.sign for e in scan if math.isfinite(e.sign)]
    if not signs:
        return T_UNDEFINED
    return T_STABLE if all(v < 0 for v in signs) else (T_UNSTABLE if all(v > 0 for v in signs) else T_UNDEFINED)


def all_crossings_chunk(which: int, name: str, s_grid: np.ndarray, p: np.ndarray, bounds: tuple[float, float],
                        floor: float, max_crossings: int) -> Crossings:
    """Every change of the sliding verdict in gamma or eta (row `which` of p, ignored) for each parameter set of a
    chunk, p (6, n) in growth_chunk's layout; the range `bounds` (validated by the caller)."""
    n = p.shape[1]
    res = empty_crossings(n, int(max_crossings), name)
    ts = np.linspace(math.log(bounds[0]), math.log(bounds[1]), SCAN_POINTS)
    for i in range(n):
        col = tuple(float(v) for v in p[:, i])
        if any(math.isnan(v) for k, v in enumerate(col) if k != which):
            continue
        pt = _Point(which, s_grid, col, floor)
        found, scan = _crossings(pt, ts)
        for k, c in enumerate(found[: res.value.shape[1]]):
            res.location[i, k] = math.exp(c.t if math.isfinite(c.t) else 0.5 * (c.lo + c.hi))
            res.lo[i, k], res.hi[i, k] = math.exp(min(c.lo, c.hi)), math.exp(max(c.lo, c.hi))
            res.reason[i, k] = c.reason
            if c.certified:
                res.value[i, k] = math.exp(c.t)
                res.kH[i, k], res.z[i, k], res.direction[i, k] = math.exp(c.s), c.x, c.direction
        g = np.array([e.g for e in scan if e.sign == 1.0])
        res.count[i] = len(found)
        res.complete[i] = all(c.certified for c in found)
        res.defined[i] = all(math.isfinite(e.sign) for e in scan)
        res.status[i] = _status(found, scan)
        res.growth_min[i], res.growth_max[i] = (g.min(), g.max()) if g.size else (np.nan, np.nan)
        res.n_undetermined[i] = sum(not math.isfinite(e.sign) for e in scan)
        res.evaluations[i] = pt.evaluations
    return res
