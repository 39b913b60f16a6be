"""Stability thresholds: every crossing of the max growth in gamma or eta, solved as a neutral mode and certified.

docs/physics.md §9. The max growth G(t) (t = ln gamma or ln eta, the other parameters fixed) is the continuous
maximum of Im z over the kH range on the Rayleigh branch (:func:`growth_analysis`). A threshold is a value of
t where G changes sign. There the maximising mode is neutral: z = x is real and Im z is stationary in s = ln kH
(or, if the maximum sits at an end of the kH range, Im z = 0 there). The solver

1. scans G at SCAN_POINTS log-spaced values of the range and inserts values where a cubic Hermite model of G (its
   values and exact slopes dG/dt, which the growth kernel gives by the envelope theorem) dips to the other sign
   between two scan values of one sign (two close crossings);
2. for every pair of neighbouring scan values with opposite signs, solves the neutral mode by Newton's method on
   the three real equations Re F = Im F = 0, Im(F_s/F_z) = 0 in (Re z, ln kH, t) from the end of the bracket
   nearer to zero (``_kernels.neutral.neutral_mode``), narrowing the bracket by Illinois steps on G until the
   neutral mode converges inside it;
3. certifies each crossing twice: G evaluated at value (1 - 1e-9) and value (1 + 1e-9) has opposite signs and a
   size consistent with the neutral mode's slope dG/dt (so it is no jump), and the maximising root there is the
   neutral mode (same kH and Re z to 1e-6: the continuation of the branch from kH = 1e4 reaches it);
4. classifies what cannot be certified: a jump of G across zero where the masked part of the kH range changes or
   where the branch is followed on both sides (the bracket narrowed until G changes across it JUMP_FACTOR times
   more than its slopes allow, or to NARROW, with no neutral mode), a neutral mode among the poles (pole-dense), an
   undefined G inside the bracket, or a failed certificate.

Crossings are returned in increasing t with their kH, Re z, direction (+1 destabilising: G goes from < 0 to > 0
as the parameter grows; -1 stabilising) and reason codes (:data:`CROSSING_STATUS`). The first certified crossing is
:func:`critical_gamma` / :func:`critical_eta`.
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from . import _kernels as K
from ._crossing import Crossing, empty_crossings
from ._sliding_thresholds import all_crossings_chunk
from ._validate import check, check_floor, check_kh_grid, check_range, check_rtol
from .crossings import (
    MAX_CROSSINGS,
    PER_POINT,
    POINT_REASON,
    SCAN_POINTS,
    T_FOUND,
    T_JUMP,
    T_NOT_CERTIFIED,
    T_POLE_DENSE,
    T_STABLE,
    T_UNDEFINED,
    T_UNSTABLE,
    THRESHOLD_STATUS,
    X_CERTIFIED,
    X_EDGE,
    X_JUMP,
    X_JUMP_MASKED,
    X_NOT_CERTIFIED,
    X_POLE_DENSE,
    X_UNDEFINED,
    Crossings,
)
from .sliding import DEFAULT_FLOOR, SLIDING_KH
from .stability import growth_rows

#: default kH grid for thresholds: 20 points per decade over [1e-4, 1e4] (only its ends matter: the growth is the
#: continuous maximum over the range)
DEFAULT_KH = np.logspace(-4, 4, 161)
CHUNK = 256  # parameter sets per chunk of the threaded public functions
#: the parameters with a threshold solver: their row in growth_chunk's params layout and default search range
THRESHOLD_ROWS = {"gamma": K.P_GAMMA, "eta": K.P_ETA}
THRESHOLD_RANGES = {"gamma": (1e-2, 1e3), "eta": (1.0, 1e8)}
MAX_INSERT = 8  # scan values the Hermite test may insert per parameter set
MAX_DEPTH = 3  # ... at most this many times between two original scan values (halving the spacing each time)
HERMITE_PROBES = 9  # points at which the Hermite model of G is tested between two scan values
CERT_REL = 1e-9  # the certificate evaluates G at value (1 -/+ CERT_REL)
CERT_SLOPE = 3.0  # |G| there must be at most CERT_SLOPE |dG/dt| CERT_REL + CERT_ERR x its error (a smooth crossing)
CERT_ERR = 4.0
CERT_S = 1e-4  # the maximum at value (1 -/+ CERT_REL) lies within this of the neutral mode in ln kH ...
CERT_X = 1e-6  # ... and its Re z within this relative to max(|x|, 1e-3)
MIN_SLOPE_ERR = 10.0  # |dG/dt| CERT_REL must exceed this x the growth's error (else the sign test resolves nothing)
NARROW = 1e-9  # a bracket narrower than this (in t, relative to max(1, |t|)) without a neutral mode is a jump ...
JUMP_FACTOR = 1e5  # ... as is one across which G changes this many times more than its end slopes allow
MIN_JUMP_SLOPE = 1e-3  # (the slopes' floor in that test: a flat G does not make every small step a jump)
BRACKET_STEPS = 100  # narrowing steps per bracket (at least every second one halves it: NARROW comes first)
NEUTRAL_TRIES = 3  # the neutral mode is tried at the first NEUTRAL_TRIES steps of a bracket, then every 4th step
EDGE_S = 1e-12  # a maximum within this of an end of the kH range (in ln kH) is at that end












class _Eval(NamedTuple):
    """One growth evaluation at t = ln x: the continuous max growth and what the solver needs of it."""

    t: float
    g: float  # max growth (NaN: no certified root)
    s: float  # ln kH at the maximum
    x: float  # Re z at the maximum
    masked: int  # masked kH grid points
    slope: float  # dG/dt
    err: float  # error estimate of g
    pole_dense: bool  # the branch enters the pole-dense part of the range
    lost_end: bool  # the maximum is at an end of the followed part inside the range (not a smooth maximum)
    certified: bool  # the verdict there is certified (stable or unstable, model.VERDICT_STATUS)


@dataclass
class _Point:
    """The solver's state for one parameter set: its growth function and evaluation count."""

    which: int
    s_grid: np.ndarray
    p: tuple[float, ...]  # gamma, f, beta, eta, Delta, xi (the row of `which` replaced)
    rtol: float
    evaluations: int = 0

    def ev(self, t: float) -> _Eval:
        q = list(self.p)
        q[self.which] = math.exp(t)
        return self.from_row(t, K.growth_point(self.s_grid, *q, self.rtol))

    def from_row(self, t: float, row) -> _Eval:
        """The _Eval of one growth evaluation `row` (growth_one's NOUT values: :class:`stability.GrowthRows`)
        at t (counted)."""
        self.evaluations += 1
        r = growth_rows(row)
        lost_end = r.max_at_lost_end > 0.0
        slope = math.nan if lost_end else (r.dgrowth_dln_gamma if self.which == K.P_GAMMA else r.dgrowth_dln_eta)
        return _Eval(t, r.growth, r.ln_kH_at_max, r.re_z_at_max, int(r.n_masked), slope, r.error, r.pole_dense > 0.0,
                     lost_end, r.verdict_reason in (K.V_STABLE, K.V_UNSTABLE))

    def at_edge(self, s: float) -> bool:
        return abs(s - self.s_grid[0]) <= EDGE_S or abs(s - self.s_grid[-1]) <= EDGE_S




def _sign(g: float) -> int:
    """The side of a max growth: -1 stable (g < 0), +1 unstable (g >= 0), as the scan counts it."""
    return -1 if g < 0 else 1


def _hermite_dips(a: _Eval, b: _Eval) -> float:
    """Where the cubic Hermite model of G between a and b (same sign) reaches the other sign (NaN if nowhere): the
    model's most opposite value among HERMITE_PROBES equally spaced interior points."""
    if not (math.isfinite(a.slope) and math.isfinite(b.slope)):
        return math.nan
    h = b.t - a.t
    if min(abs(a.g), abs(b.g)) > 4 / 27 * h * (abs(a.slope) + abs(b.slope)):
        return math.nan  # the model is a mean of G_a and G_b plus at most 4/27 h (|G'_a| + |G'_b|): no dip
    side = _sign(a.g)
    best, where = -math.inf, math.nan
    for i in range(1, HERMITE_PROBES + 1):
        u = i / (HERMITE_PROBES + 1)
        u2, u3 = u * u, u * u * u
        model = ((2 * u3 - 3 * u2 + 1) * a.g + (u3 - 2 * u2 + u) * h * a.slope + (3 * u2 - 2 * u3) * b.g
                 + (u3 - u2) * h * b.slope)
        if _sign(model) != side and -side * model > best:
            best, where = -side * model, a.t + h * u
    return where


def _scan_rows(which: int, s: np.ndarray, p: np.ndarray, ts: np.ndarray) -> np.ndarray:
    """growth_one at every scan value ts of every parameter set (columns of p): (n, len(ts), NOUT), in one compiled
    loop (the scan is most of a threshold's evaluations; each set's numbers are those of growth_point)."""
    n, m = p.shape[1], ts.size
    q = np.repeat(p, m, axis=1)
    q[which] = np.exp(np.tile(ts, n))
    out = np.empty((K.NOUT, n * m))
    K.growth_many(s, *(np.ascontiguousarray(q[i]) for i in range(6)), 0.0, out)
    return out.T.reshape(n, m, K.NOUT)


def _scan(pt: _Point, ts: np.ndarray, rows: np.ndarray) -> list[_Eval]:
    """G at the scan values ts (their growth evaluations rows, _scan_rows), plus values inserted where the Hermite
    model dips to the other sign."""
    base = [pt.from_row(float(t), row) for t, row in zip(ts, rows, strict=True)]
    budget = [MAX_INSERT]
    out = [base[0]]
    for a, b in zip(base[:-1], base[1:], strict=True):
        out.extend(_inserted(pt, a, b, MAX_DEPTH, budget))
        out.append(b)
    return out


def _inserted(pt: _Point, a: _Eval, b: _Eval, depth: int, budget: list[int]) -> list[_Eval]:
    """Values inserted between a and b (same sign) where the Hermite model of G dips to the other sign, in order."""
    if depth == 0 or budget[0] <= 0 or not (math.isfinite(a.g) and math.isfinite(b.g)) or _sign(a.g) != _sign(b.g):
        return []
    t = _hermite_dips(a, b)
    if not math.isfinite(t):
        return []
    budget[0] -= 1
    c = pt.ev(t)
    return [*_inserted(pt, a, c, depth - 1, budget), c, *_inserted(pt, c, b, depth - 1, budget)]


def _certify(pt: _Point, x: float, s: float, t: float, slope: float, err: float, edge: bool) -> Crossing | None:
    """The crossing at the neutral mode (x, s, t) if both certificates hold, else None (reason left to the caller).

    G at value (1 -/+ CERT_REL): opposite signs, each no larger than the neutral mode's slope allows (no jump),
    the masked part of the kH range unchanged, and the maximum at the neutral mode's kH and Re z."""
    if abs(slope) * CERT_REL <= MIN_SLOPE_ERR * max(err, 4 * np.finfo(float).eps):
        return None  # a tangential crossing: the sign test at +-1e-9 resolves nothing
    v = math.exp(t)
    lo, hi = pt.ev(math.log(v * (1 - CERT_REL))), pt.ev(math.log(v * (1 + CERT_REL)))
    for e in (lo, hi):
        if not math.isfinite(e.g) or e.g == 0.0:
            return None
        bound = CERT_SLOPE * abs(slope) * CERT_REL + CERT_ERR * e.err
        if abs(e.g) > bound or abs(e.s - s) > CERT_S or abs(e.x - x) > CERT_X * max(abs(x), 1e-3):
            return None
    if (lo.g > 0) == (hi.g > 0) or (hi.g > 0) != (slope > 0) or lo.masked != hi.masked:
        return None
    return Crossing(X_EDGE if edge else X_CERTIFIED, lo.t, hi.t, t, s, x, 1 if hi.g > 0 else -1)


def _try_neutral(pt: _Point, a: _Eval, b: _Eval) -> Crossing | None:
    """The neutral mode from the bracket [a, b] (opposite signs), certified; a pole-dense crossing; or None."""
    if a.lost_end and b.lost_end:
        return None  # no smooth maximum at either end to start from
    near = b if a.lost_end else (a if b.lost_end or abs(a.g) <= abs(b.g) else b)
    lo, hi = min(a.t, b.t), max(a.t, b.t)
    t0 = a.t - a.g * (b.t - a.t) / (b.g - a.g)  # secant, or Newton from the start's own slope
    if math.isfinite(near.slope) and near.slope != 0.0:
        t0 = min(max(near.t - near.g / near.slope, lo), hi)
    edge = pt.at_edge(near.s)
    try:
        x, s, t, ok, _, _, slope, _ = K.neutral_mode(near.x, near.s, t0, pt.which, edge, *pt.p)
    except ZeroDivisionError:  # an iterate hit a removable point of F's formulas exactly (z = 0, |z| = 1): no mode
        return None
    tiny = 4 * np.finfo(float).eps * max(1.0, abs(t))
    if not ok or not (lo - tiny <= t <= hi + tiny) or not (pt.s_grid[0] - EDGE_S <= s <= pt.s_grid[-1] + EDGE_S):
        return None
    eta = math.exp(t) if pt.which == K.P_ETA else pt.p[3]
    if not math.isinf(eta) and abs(x) > K.SUBSONIC:
        return Crossing(X_POLE_DENSE, lo, hi, t, s, x)
    return _certify(pt, x, s, t, slope, max(a.err, b.err), edge)


def _is_jump(a: _Eval, b: _Eval) -> bool:
    """The bracket [a, b] is narrow enough to call the sign change a jump: narrower than NARROW, or G changes across
    it JUMP_FACTOR times more than its slopes at the ends allow (a smooth crossing changes G by ~ slope x width)."""
    width = b.t - a.t
    if width <= NARROW * max(1.0, abs(a.t)):
        return True
    slopes = [abs(e.slope) for e in (a, b) if math.isfinite(e.slope)]
    return bool(slopes) and abs(b.g - a.g) > JUMP_FACTOR * max(max(slopes), MIN_JUMP_SLOPE) * width


def _solve_bracket(pt: _Point, a: _Eval, b: _Eval) -> Crossing:
    """The crossing in the bracket [a, b] of scan values with opposite signs (docstring of the module, steps 2-4).

    Between neutral-mode attempts the bracket is narrowed by false position on G until a step fails to halve it
    twice (a jump, not a smooth zero), then by bisection, until it is a jump (_is_jump) or a neutral mode is
    certified."""
    fp_failures = 0
    for step in range(BRACKET_STEPS):
        if step < NEUTRAL_TRIES or step % 4 == 0:
            c = _try_neutral(pt, a, b)
            if c is not None:
                return c
        if step >= NEUTRAL_TRIES and _is_jump(a, b):
            reason = X_JUMP_MASKED if a.masked != b.masked else X_JUMP
            return Crossing(reason, a.t, b.t, 0.5 * (a.t + b.t))
        width = b.t - a.t
        if fp_failures >= 2:
            t = 0.5 * (a.t + b.t)
        else:
            t = a.t - a.g * width / (b.g - a.g)
            t = min(max(t, a.t + 0.01 * width), b.t - 0.01 * width)  # strictly inside
        e = pt.ev(t)
        if not math.isfinite(e.g):
            return Crossing(X_UNDEFINED, a.t, b.t, t)
        if _sign(e.g) == _sign(a.g):
            a = e
        else:
            b = e
        if fp_failures < 2 and b.t - a.t > 0.5 * width:
            fp_failures += 1
    return Crossing(X_NOT_CERTIFIED, a.t, b.t, 0.5 * (a.t + b.t))


def _point_crossings(pt: _Point, ts: np.ndarray, rows: np.ndarray) -> tuple[list[Crossing], list[_Eval]]:
    """Every sign change of G over the scan values ts (scan values with opposite signs, or with only NaN between)."""
    scan = _scan(pt, ts, rows)
    out: list[Crossing] = []
    prev: _Eval | None = None  # the last finite scan value
    gap = False  # NaN scan values since prev
    for e in scan:
        if not math.isfinite(e.g):
            gap = prev is not None or gap
            continue
        if prev is not None and _sign(prev.g) != _sign(e.g):
            out.append(Crossing(X_UNDEFINED, prev.t, e.t, math.nan) if gap else _solve_bracket(pt, prev, e))
        prev, gap = e, False
    return out, scan








def _status(crossings: list[Crossing], scan: list[_Eval]) -> int:
    """The point's threshold code: found, or why not (the first crossing's reason; else the scan's signs)."""
    if any(c.certified for c in crossings):
        return T_FOUND
    if crossings:
        return POINT_REASON[crossings[0].reason]
    g = np.array([e.g for e in scan])
    fin = g[np.isfinite(g)]
    if not fin.size:
        return T_UNDEFINED
    return T_STABLE if np.all(fin < 0) else (T_UNSTABLE if np.all(fin >= 0) else T_UNDEFINED)


def _fill(res: Crossings, i: int, pt: _Point, crossings: list[Crossing], scan: list[_Eval]) -> None:
    """Write the crossings of parameter set i into res."""
    for k, c in enumerate(crossings[: res.value.shape[1]]):
        res.location[i, k] = math.exp(c.t) if math.isfinite(c.t) else math.exp(0.5 * (c.lo + c.hi))
        res.lo[i, k], res.hi[i, k] = math.exp(c.lo), math.exp(c.hi)
        res.reason[i, k] = c.reason
        if c.certified:
            res.value[i, k] = math.exp(c.t)
            res.kH[i, k], res.z[i, k], res.direction[i, k] = math.exp(c.s), c.x, c.direction
    g = np.array([e.g for e in scan])
    fin = g[np.isfinite(g)]
    res.count[i] = len(crossings)
    res.complete[i] = all(c.certified for c in crossings)
    res.defined[i] = fin.size == g.size
    res.status[i] = _status(crossings, scan)
    res.growth_min[i], res.growth_max[i] = (fin.min(), fin.max()) if fin.size else (np.nan, np.nan)
    res.n_undetermined[i] = sum(not e.certified for e in scan)
    res.evaluations[i] = pt.evaluations


def _params6(name: str, params: np.ndarray) -> np.ndarray:
    """params as (6, n) in growth_chunk's layout (a (5, n) input gets a NaN row for `name`)."""
    p = np.array(params, dtype=float)
    if p.ndim != 2 or p.shape[0] not in (5, 6):
        raise ValueError(f"params must have shape (6, n) or (5, n); got {p.shape}")
    if p.shape[0] == 5:
        p = np.insert(p, THRESHOLD_ROWS[name], np.nan, axis=0)
    return p


def crossings_chunk(name: str, s_grid: np.ndarray, params: np.ndarray, bounds: tuple[float, float] | None = None,
                    rtol: float | None = None, max_crossings: int = MAX_CROSSINGS, branches: str = "rayleigh",
                    floor: float | None = None) -> Crossings:
    """Every crossing of the max growth in gamma or eta for every parameter set of one chunk (Sect. IV; §9).

    branches : "rayleigh" (default: the Rayleigh branch's max growth, as the paper) or "all" (the max growth over
    every branch, model.sliding_analysis's, with its growth floor `floor`, default model.DEFAULT_FLOOR: every
    change of the sliding verdict solved as the neutral mode of the root that crosses, docs/physics.md §14.10).

    name : "gamma" or "eta"; s_grid : the ln kH grid (its ends are the kH range of the max growth);
    params : (6, n) in growth_chunk's layout (rows gamma, f, beta, eta, Delta, xi) with the row of `name` ignored,
    or (5, n) with that row left out; bounds : the search range (default ``THRESHOLD_RANGES[name]``);
    rtol : validated as everywhere (None or [1e-15, 1e-3]), but the growth is always evaluated and the neutral
    mode always solved at full accuracy: the certificate needs the threshold to ~1e-12, and a neutral mode
    converges quadratically, so a looser target would save nothing; max_crossings : the length of the last axis.
    A point's result does not depend on the rest of the chunk. The module docstring gives the method.
    """
    if name not in THRESHOLD_ROWS:
        raise ValueError(f"name must be one of {sorted(THRESHOLD_ROWS)}; got {name!r}")
    lo, hi = check_range(f"{name}_range", THRESHOLD_RANGES[name] if bounds is None else bounds, name)
    check_rtol(rtol)
    if not (isinstance(max_crossings, int | np.integer) and max_crossings >= 1):
        raise ValueError(f"max_crossings must be an integer >= 1; got {max_crossings!r}")
    p = _params6(name, params)
    s = np.ascontiguousarray(s_grid, dtype=float)
    if _branches(branches) == "all":
        fl = check_floor(DEFAULT_FLOOR if floor is None else floor)
        return all_crossings_chunk(THRESHOLD_ROWS[name], name, s, p, (lo, hi), fl, int(max_crossings))
    n = p.shape[1]
    res = empty_crossings(n, int(max_crossings), name)
    which = THRESHOLD_ROWS[name]
    valid = np.flatnonzero(~np.isnan(np.delete(p, which, axis=0)).any(axis=0))  # NaN parameters: undefined
    ts = np.linspace(math.log(lo), math.log(hi), SCAN_POINTS)
    rows = _scan_rows(which, s, p[:, valid], ts)
    for k, i in enumerate(valid):
        pt = _Point(which, s, tuple(float(v) for v in p[:, i]), 0.0)
        crossings, scan = _point_crossings(pt, ts, rows[k])
        _fill(res, i, pt, crossings, scan)
    return res


def _branches(branches) -> str:
    """The branches argument, validated: "rayleigh" or "all"."""
    if branches not in ("rayleigh", "all"):
        raise ValueError(f'branches must be "rayleigh" (the Rayleigh branch) or "all" (every branch); got {branches!r}')
    return branches


def critical_gamma_chunk(s_grid: np.ndarray, params: np.ndarray, *, gamma_range: tuple[float, float] = (1e-2, 1e3),
                         rtol: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(gamma_c, reason) for one chunk: the first certified crossing in gamma (:func:`crossings_chunk`).

    params : (5, n) rows f, beta, eta, Delta, xi, or (6, n) in growth_chunk's layout with the gamma row
    ignored. gamma_c is NaN where reason != 0 (reasons: :data:`THRESHOLD_STATUS`).
    """
    r = crossings_chunk("gamma", s_grid, params, gamma_range, rtol)
    return r.first, r.status


def critical_eta_chunk(s_grid: np.ndarray, params: np.ndarray, *, eta_range: tuple[float, float] = (1.0, 1e8),
                       rtol: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(eta_c, reason) for one chunk: the first certified crossing in eta (:func:`crossings_chunk`).

    params : (5, n) rows gamma, f, beta, Delta, xi, or (6, n) in growth_chunk's layout with the eta row
    ignored. eta_c is NaN where reason != 0 (reasons: :data:`THRESHOLD_STATUS`).
    """
    r = crossings_chunk("eta", s_grid, params, eta_range, rtol)
    return r.first, r.status


@dataclass(frozen=True)
class ThresholdChunk:
    """The first certified crossing of one chunk of parameter sets, with diagnostics (:func:`threshold_chunk`).

    value : the threshold (NaN unless reason == 0); reason : int8, a key of :data:`THRESHOLD_STATUS`;
    location : where the first sign change is (the threshold, or a jump's location; NaN without a sign change);
    lo, hi : its bracket; kH, z, direction : the neutral mode of the threshold (see :class:`Crossings`);
    n_crossings : sign changes found; complete : every one certified; growth_min, growth_max : extremes of the
    max growth at the scan values; n_undetermined : scan values with an undetermined verdict; evaluations : growth
    evaluations per parameter set.
    """

    value: np.ndarray
    reason: np.ndarray
    location: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    kH: np.ndarray
    z: np.ndarray
    direction: np.ndarray
    n_crossings: np.ndarray
    complete: np.ndarray
    growth_min: np.ndarray
    growth_max: np.ndarray
    n_undetermined: np.ndarray
    evaluations: np.ndarray


def threshold_chunk(name: str, s_grid: np.ndarray, params: np.ndarray, bounds: tuple[float, float] | None = None,
                    rtol: float | None = None, branches: str = "rayleigh", floor: float | None = None
                    ) -> ThresholdChunk:
    """The threshold of gamma or eta (the first certified crossing) for every parameter set of one chunk.

    Arguments as :func:`crossings_chunk`; the first certified crossing and, where there is none, the first sign
    change's location and bracket (so a jump's location is kept) and the reason (:data:`THRESHOLD_STATUS`).
    """
    r = crossings_chunk(name, s_grid, params, bounds, rtol, MAX_CROSSINGS, branches, floor)
    n = r.value.shape[0]
    ok = (r.reason == X_CERTIFIED) | (r.reason == X_EDGE)
    k = np.where(ok.any(axis=1), np.argmax(ok, axis=1), 0)
    rows = np.arange(n)
    has = r.count > 0
    pick = {name_: getattr(r, name_)[rows, k] for name_ in PER_POINT}
    loc = np.where(has, pick["location"], np.nan)
    return ThresholdChunk(r.first, r.status, loc, np.where(has, pick["lo"], np.nan), np.where(has, pick["hi"], np.nan),
                          pick["kH"], pick["z"], pick["direction"], r.count, r.complete, r.growth_min, r.growth_max,
                          r.n_undetermined, r.evaluations)


def _no_threshold_message(name: str, bounds: tuple[float, float], r: ThresholdChunk, i: int,
                          branches: str = "rayleigh") -> str:
    """The ValueError text for element i of r (reason != 0): the parameter, the range and why."""
    valid = f"[{bounds[0]:g}, {bounds[1]:g}]"
    code = int(r.reason[i])
    if branches == "all":
        why = {T_STABLE: "sliding is stable throughout (no root of any branch above the floor at any scan value)",
               T_UNSTABLE: "sliding is unstable throughout (a root above the floor at every scan value)",
               T_UNDEFINED: "the sliding verdict is undetermined where it would change",
               T_JUMP: f"the sliding verdict changes with no neutral mode at {name} = {r.location[i]:.10g}",
               T_NOT_CERTIFIED: f"the sliding verdict changes at {name} = {r.location[i]:.10g}, but no neutral mode "
               "there passed the certificates"}.get(code, THRESHOLD_STATUS.get(code, f"reason {code}"))
        return f"no sliding threshold (every branch) for {name} in {valid}: {why}"
    span = f"between {r.growth_min[i]:.3g} and {r.growth_max[i]:.3g}"
    nu = int(r.n_undetermined[i])
    if nu:
        span += (f" (but the verdict is undetermined at {nu} of the scan values: the Rayleigh branch is lost or "
                 "pole-dense there, docs/physics.md §9)")
    where = f" at {name} = {r.location[i]:.10g} (bracket {r.lo[i]:.6g} .. {r.hi[i]:.6g})"
    why = {
        T_STABLE: f"stable throughout: max growth stays {span} over the range (< 0 wherever defined)",
        T_UNSTABLE: f"unstable throughout: max growth stays {span} over the range (>= 0 wherever defined)",
        T_UNDEFINED: ("max growth undefined (no certified root of the Rayleigh branch on the kH range) at every scan "
                      "value" if not np.isfinite(r.growth_min[i]) else
                      f"max growth changes sign but is undefined (no certified root) in between{where}"),
        T_JUMP: f"the max growth jumps across zero{where}: {THRESHOLD_STATUS[T_JUMP]}",
        T_POLE_DENSE: f"the max growth changes sign{where}, {THRESHOLD_STATUS[T_POLE_DENSE]}",
        T_NOT_CERTIFIED: f"the max growth changes sign{where}, but no neutral mode there passed the certificates",
    }.get(code, THRESHOLD_STATUS.get(code, f"reason {code}"))
    return f"no stability threshold for {name} in {valid}: {why}"


def _broadcast(fixed: dict) -> tuple[dict[str, np.ndarray], tuple[int, ...]]:
    arrays = np.broadcast_arrays(*(check(k, v) for k, v in fixed.items()))
    return dict(zip(fixed, (a.ravel().astype(float) for a in arrays), strict=True)), arrays[0].shape


def _chunks(name: str, bounds, kH, fixed: dict, rtol, workers: int | None, fun, branches: str = "rayleigh"):
    """fun(name, s, params_chunk, bounds, rtol) over chunks of CHUNK parameter sets on `workers` threads (the default
    kH grid: DEFAULT_KH for the Rayleigh branch, model.SLIDING_KH for every branch)."""
    bounds = check_range(f"{name}_range", bounds, name)
    check_rtol(rtol)
    cols, shape = _broadcast(fixed)
    if kH is None and _branches(branches) == "all":
        kH = SLIDING_KH
    s = np.log(DEFAULT_KH if kH is None else check_kh_grid(kH))
    n = int(np.prod(shape))
    cols[name] = np.full(n, np.nan)
    params = np.stack([cols[k] for k in ("gamma", "f", "beta", "eta", "Delta", "xi")])
    chunks = [params[:, i : i + CHUNK] for i in range(0, n, CHUNK)]
    nworkers = workers or os.cpu_count() or 1
    if len(chunks) > 1 and nworkers > 1:
        with ThreadPoolExecutor(nworkers) as pool:
            parts = list(pool.map(lambda c: fun(name, s, c, bounds, rtol), chunks))
    else:
        parts = [fun(name, s, c, bounds, rtol) for c in chunks]
    return parts, cols, shape, bounds


def _thresholds(name: str, bounds, kH, fixed: dict, rtol: float | None, workers: int | None,
                branches: str = "rayleigh", floor: float | None = None):
    """The first certified threshold of `name` for every element of the broadcast fixed parameters."""
    def fun(name_, s, c, b, r):
        return threshold_chunk(name_, s, c, b, r, branches, floor)

    parts, cols, shape, bounds = _chunks(name, bounds, kH, fixed, rtol, workers, fun, branches)
    for c, part in enumerate(parts):
        bad = np.flatnonzero(part.reason != T_FOUND)
        if bad.size:
            msg = _no_threshold_message(name, bounds, part, int(bad[0]), branches)
            if shape:  # which element of the broadcast input
                i = c * CHUNK + int(bad[0])
                at = ", ".join(f"{k} = {cols[k][i]:.6g}" for k in fixed)
                msg += f" (element {tuple(int(j) for j in np.unravel_index(i, shape))}: {at})"
            raise ValueError(msg)
    out = np.concatenate([p.value for p in parts]) if parts else np.empty(0)
    return out.reshape(shape) if shape else float(out[0])


def _all_crossings(name: str, bounds, kH, fixed: dict, rtol, workers, max_crossings: int, branches: str = "rayleigh",
                   floor: float | None = None) -> Crossings:
    """crossings_chunk over the broadcast fixed parameters, reshaped to their shape (+ the crossing axis)."""
    def fun(name_, s, c, b, r):
        return crossings_chunk(name_, s, c, b, r, max_crossings, branches, floor)

    parts, _, shape, _ = _chunks(name, bounds, kH, fixed, rtol, workers, fun, branches)
    k = int(max_crossings)
    out = {}
    for f_ in Crossings.__dataclass_fields__:
        if f_ == "parameter":
            continue
        arr = np.concatenate([getattr(p, f_) for p in parts]) if parts else getattr(empty_crossings(0, k, name), f_)
        out[f_] = arr.reshape((*shape, k) if f_ in PER_POINT else shape)
    return Crossings(**out, parameter=name)


def critical_gammas(*, f, beta, eta=math.inf, Delta=1.0, xi=0.0, kH=None, gamma_range=(1e-2, 1e3),
                    rtol: float | None = None, workers: int | None = None,
                    max_crossings: int = MAX_CROSSINGS, branches: str = "rayleigh",
                    floor: float | None = None) -> Crossings:
    """Every crossing in gamma of the max growth on the Rayleigh branch, each solved as a neutral mode and certified.

    Sect. IV, Fig. 4c; docs/physics.md §9. Returns :class:`Crossings` with the shape of the broadcast parameters
    plus a last axis of max_crossings (NaN-padded, in increasing gamma): per crossing the threshold (NaN unless
    certified), kH and z of the neutral mode, the direction (+1 destabilising: unstable above, -1 stabilising) and
    a reason code (:data:`CROSSING_STATUS`); per parameter set the count, whether every crossing is certified, and
    the first certified one (`.first`, what :func:`critical_gamma` returns). kH: the grid whose ends are the kH
    range of the max growth (default DEFAULT_KH, [1e-4, 1e4]); the work is split into chunks run on `workers`
    threads. Never raises for a parameter set without crossings: count 0 and status say why.
    branches="all": the crossings of the max growth over every branch instead (the sliding verdict of
    :func:`sliding_analysis` with its `floor`; default kH :data:`SLIDING_KH`; docs/physics.md §14.10).
    """
    return _all_crossings("gamma", gamma_range, kH, dict(f=f, beta=beta, eta=eta, Delta=Delta, xi=xi), rtol,
                          workers, max_crossings, branches, floor)


def critical_etas(*, gamma, f, beta, Delta=1.0, xi=0.0, kH=None, eta_range=(1.0, 1e8), rtol: float | None = None,
                  workers: int | None = None, max_crossings: int = MAX_CROSSINGS, branches: str = "rayleigh",
                  floor: float | None = None) -> Crossings:
    """Every crossing in eta of the max growth on the Rayleigh branch (or over every branch, branches="all"), solved
    and certified: :func:`critical_gammas` with eta scanned over eta_range (log-spaced)."""
    return _all_crossings("eta", eta_range, kH, dict(gamma=gamma, f=f, beta=beta, Delta=Delta, xi=xi), rtol,
                          workers, max_crossings, branches, floor)


def critical_gamma(*, f, beta, eta=math.inf, Delta=1.0, xi=0.0, kH=None, gamma_range=(1e-2, 1e3),
                   rtol: float | None = None, workers: int | None = None, branches: str = "rayleigh",
                   floor: float | None = None):
    """gamma at which the max growth on the Rayleigh branch first changes sign in gamma_range: a certified neutral
    mode, to ~1e-12 relative.

    Sect. IV, Fig. 4c; docs/physics.md §9. Check value: 2.4149 for f = 0.9, beta = 0.3, eta = inf (paper:
    "between 2 and 3"). Parameters may be arrays (broadcast; one threshold per element). The threshold is the first
    certified crossing of :func:`critical_gammas` (in either direction: where growth is not monotone in gamma, the
    side below may be the unstable one); never a jump of the max growth or a pole-dense mode. ValueError naming
    gamma, the range and why (stable throughout, unstable throughout, undefined, a jump, pole-dense, not certified)
    if an element has no certified crossing in gamma_range. kH: the grid (default DEFAULT_KH); rtol: validated
    (see :func:`crossings_chunk`); the work is split into chunks run on `workers` threads. branches="all": the
    first certified change of the sliding verdict over every branch (with its `floor`; docs/physics.md §14.10).
    """
    return _thresholds("gamma", gamma_range, kH, dict(f=f, beta=beta, eta=eta, Delta=Delta, xi=xi), rtol, workers,
                       branches, floor)


def critical_eta(*, gamma, f, beta, Delta=1.0, xi=0.0, kH=None, eta_range=(1.0, 1e8), rtol: float | None = None,
                 workers: int | None = None, branches: str = "rayleigh", floor: float | None = None):
    """eta at which the max growth on the Rayleigh branch first changes sign in eta_range (certified), ~1e-12.

    Sect. IV; docs/physics.md §9. Check value: 3.2982 for gamma = 3, f = 0.9, beta = 0.3 (paper: "~3.3").
    As :func:`critical_gamma` with eta scanned over eta_range; ValueError without a certified crossing.
    """
    return _thresholds("eta", eta_range, kH, dict(gamma=gamma, f=f, beta=beta, Delta=Delta, xi=xi), rtol, workers,
                       branches, floor)


def critical_chi(beta, *, f):
    """Exact threshold chi_c = gamma_c f of the Rayleigh branch for eta = inf, Delta = 1 (Fig. 4c, open symbols)."""
    b, ff = np.broadcast_arrays(check("beta", beta), check("f", f))
    return critical_gamma(f=ff, beta=b) * ff
