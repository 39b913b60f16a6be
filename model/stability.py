"""Stability analysis on the Rayleigh branch: growth maps, unstable bands, thresholds (Sect. IV, Fig. 4c)."""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from . import _kernels as K
from ._validate import check, check_range, check_rtol
from .elastodynamics import response_functions
from .rayleigh import rayleigh_speed

#: default kH grid for thresholds: 20 points per decade over [1e-4, 1e4]
DEFAULT_KH = np.logspace(-4, 4, 161)
CHUNK = 256  # parameter sets per chunk of a stability map


@dataclass(frozen=True)
class GrowthResult:
    """Max growth rate over kH on the Rayleigh branch, per parameter set.

    growth : max_kH Im z (c/c_s units), refined between grid points (NaN if the branch is masked
        at every grid point)
    kH_at_max : where the maximum is reached
    kH_min, kH_max : the unstable band around the maximum (Im z > 0), NaN if growth <= 0 or if the
        band reaches beyond the grid
    n_masked : how many grid points were masked (branch not followable there)
    """

    growth: np.ndarray
    kH_at_max: np.ndarray
    kH_min: np.ndarray
    kH_max: np.ndarray
    n_masked: np.ndarray


def growth_chunk(s_grid: np.ndarray, params: np.ndarray, rtol: float | None = None) -> np.ndarray:
    """Pure function of one chunk: params (6, n) rows gamma, f, beta, eta, Delta, xi -> (5, n) results.

    Rows of the result: growth, ln kH at max, ln kH_min, ln kH_max, n_masked. No shared state, so a
    distributed backend can run chunks anywhere. rtol as in :func:`growth_analysis`.
    """
    tol = check_rtol(rtol)
    n = params.shape[1]
    out = np.empty((5, n))
    cols = [np.ascontiguousarray(params[i]) for i in range(6)]
    K.growth_many(np.ascontiguousarray(s_grid), *cols, tol, out[0], out[1], out[2], out[3], out[4])
    return out


def _grid(kH) -> np.ndarray:
    """The kH grid, validated: a 1-D increasing array of at least 2 positive values."""
    q = check("kH", kH)
    if q.ndim != 1 or q.size < 2 or np.any(np.diff(q) <= 0):
        raise ValueError("kH must be a 1-D increasing grid with at least 2 points")
    return q


def growth_analysis(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, workers: int | None = None,
                    rtol: float | None = None) -> GrowthResult:
    """Max over kH of Im z on the Rayleigh branch (the stability map) and the unstable band.

    kH : 1-D increasing grid (> 0) on which the maximum is bracketed (Im z on the grid comes from the
    Hermite interpolant of the branch's path nodes); the maximum is then refined between grid points
    (golden-section search on the interpolant, then a Newton correction of the location with the exact
    root and slope: location to 1e-9 in ln kH) and the band ends by Newton's method in ln kH on exact
    roots. Parameters broadcast against each other: e.g.
    ``growth_analysis(k, gamma=g[:, None], eta=e[None, :], f=0.9, beta=0.3)`` is a 2-D map.
    Work is split into chunks of parameter sets (:func:`growth_chunk`) run on `workers` threads
    (default: the number of CPUs; the compiled kernels release the GIL).
    rtol : None (default: the growth is a certified root, accurate to ~1e-15) or the requested relative
    accuracy of the roots in [1e-15, 1e-3] (growth accurate to rtol |z| absolute): the refinement then
    uses the path interpolant wherever its estimated error is below 0.1 rtol.
    """
    tol = check_rtol(rtol)
    q = _grid(kH)
    arrays = [check("gamma", gamma), check("f", f), check("beta", beta), check("eta", eta), check("Delta", Delta),
              check("xi", xi)]
    shape = np.broadcast_shapes(*(a.shape for a in arrays))
    params = np.stack([np.broadcast_to(a, shape).ravel() for a in arrays]).astype(float)
    s = np.log(q)
    n = params.shape[1]
    chunks = [params[:, i : i + CHUNK] for i in range(0, n, CHUNK)]
    nworkers = workers or os.cpu_count() or 1
    if len(chunks) > 1 and nworkers > 1:
        with ThreadPoolExecutor(nworkers) as pool:
            parts = list(pool.map(lambda c: growth_chunk(s, c, tol or None), chunks))
    else:
        parts = [growth_chunk(s, c, tol or None) for c in chunks]
    out = np.concatenate(parts, axis=1) if parts else np.empty((5, 0))
    res = [r.reshape(shape) for r in out]
    return GrowthResult(res[0], np.exp(res[1]), np.exp(res[2]), np.exp(res[3]), res[4].astype(int))


def max_growth(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, rtol: float | None = None):
    """(growth, kH_at_max): max over kH of Im[c/c_s] on the Rayleigh branch, refined between grid points.

    See :func:`growth_analysis` (which also gives the unstable band, and explains `rtol`); parameters
    broadcast, so this is the stability map. Sliding is unstable on this branch where growth > 0.
    """
    r = growth_analysis(kH, gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi, rtol=rtol)
    return r.growth, r.kH_at_max


def unstable_band(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, rtol: float | None = None):
    """(kH_min, kH_max) of the unstable band around the fastest-growing mode (NaN where stable; rtol as in
    :func:`growth_analysis`)."""
    r = growth_analysis(kH, gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi, rtol=rtol)
    return r.kH_min, r.kH_max


#: the parameters with a threshold solver: their row in growth_chunk's params layout and default search range
THRESHOLD_ROWS = {"gamma": 0, "eta": 3}
THRESHOLD_RANGES = {"gamma": (1e-2, 1e3), "eta": (1.0, 1e8)}
SCAN_POINTS = 17  # log-spaced scan values of the search range that bracket the first crossing
XTOL = 1e-14  # bracket width in ln x at convergence (plus 4 eps |ln x|), as brentq's xtol
BRENT_ITER = 100  # Brent steps before forced bisection (which bounds the iteration count; see threshold_chunk)

#: reason codes of :func:`threshold_chunk` (int8), like :data:`model.spectrum.STATUS`
THRESHOLD_STATUS = {
    0: "found: the max growth changes sign at the threshold",
    1: "stable throughout: max growth < 0 at every scan value of the range where it is defined",
    2: "unstable throughout: max growth >= 0 at every scan value of the range where it is defined",
    3: "undefined: max growth NaN (Rayleigh branch masked on the whole kH grid) at the scan values needed to "
    "bracket a crossing, or inside the bracket",
    4: "did not converge (not reachable: Brent's method falls back to bisection)",
    5: "jump, not a threshold: the max growth jumps across zero where the Rayleigh branch can be followed over "
    "fewer kH grid points on one side (a limit of the branch's continuation, not a marginal mode)",
}
_FOUND, _STABLE, _UNSTABLE, _UNDEFINED, _NOCONV, _JUMP = 0, 1, 2, 3, 4, 5


@dataclass(frozen=True)
class ThresholdChunk:
    """Thresholds of one chunk of parameter sets with diagnostics (:func:`threshold_chunk`).

    value : the threshold (NaN unless reason == 0)
    reason : int8, a key of :data:`THRESHOLD_STATUS`
    location : where the max growth changes sign (reason 0: the threshold; reason 5: the jump; else NaN)
    lo, hi : the adjacent scan values bracketing the crossing (NaN without a bracket)
    undefined_at : where the max growth is NaN inside the bracket (NaN unless that is the reason)
    growth_min, growth_max : extremes of the finite max growth at the scan values evaluated (NaN if none;
        without a bracket every scan value was evaluated)
    n_undefined : how many of the scan values evaluated have an undefined (NaN) max growth
    n_masked : (2, n) masked kH grid points at the lower and upper end of the final bracket (-1 without a
        located sign change). Where they differ, the max growth jumps across zero because the Rayleigh branch
        can be followed over less of the kH grid on one side: a limit of the branch's continuation rather than
        a marginal mode, so the point gets reason 5 and no value (its location is kept in ``location``).
    evaluations : growth evaluations (growth_one calls) per parameter set
    """

    value: np.ndarray
    reason: np.ndarray
    location: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    undefined_at: np.ndarray
    growth_min: np.ndarray
    growth_max: np.ndarray
    n_undefined: np.ndarray
    n_masked: np.ndarray
    evaluations: np.ndarray


def threshold_chunk(name: str, s_grid: np.ndarray, params: np.ndarray, bounds: tuple[float, float] | None = None,
                    rtol: float | None = None) -> ThresholdChunk:
    """Threshold of gamma or eta for every parameter set of one chunk: the zero of the max growth (Sect. IV, Fig. 4c).

    The stability threshold of docs/physics.md §9: the value x of the parameter `name` ("gamma" or "eta")
    where max_kH Im z on the Rayleigh branch (:func:`growth_chunk` on the ln kH grid `s_grid`) crosses zero,
    the others fixed. params : (6, n) in growth_chunk's layout (rows gamma, f, beta, eta, Delta, xi) with
    the row of `name` ignored, or (5, n) with that row left out. bounds : the search range (lo, hi) of x,
    default :data:`THRESHOLD_RANGES`[name], searched in t = ln x. Domain: any parameters growth_chunk
    takes (NaN parameters give reason 3).

    Definition (the same for every point, so a point's result does not depend on the rest of the chunk,
    bitwise): the first pair of adjacent values among SCAN_POINTS = 17 log-spaced scan values of the range
    whose max growths are finite and of opposite sign (growth < 0 counts as stable, >= 0 as unstable; in
    either direction), refined by Brent's method in t. Accuracy: the final bracket is narrower than 1e-14
    + 4 eps |t| in t (or than `rtol`); the computed max growth is accurate to ~1e-15 absolute, which moves
    its zero by ~1e-15 / |d growth / d ln x| (~1e-13 at the paper's check values): ~1e-12 relative.

    The whole chunk is solved at once: each step evaluates the growth of every unresolved point in one
    growth_chunk call. The scan stops at a point's first bracket (the earlier scan values are needed to
    rule out an earlier crossing), and Brent's method starts from the scan values at the bracket ends, so
    a point costs (bracket index + 2) + (Brent steps) evaluations, 17 without a bracket. The steps are
    scipy.optimize.brentq's (xtol = 1e-14, rtol = 4 eps), elementwise, so the threshold is the one the
    scalar brentq gives. They are bounded: after BRENT_ITER steps only bisection steps are taken, which
    halve the bracket each step, so reason 4 cannot occur. A max growth that jumps across zero is located
    like a crossing, at about bisection speed (see ThresholdChunk.n_masked).

    Reasons (:data:`THRESHOLD_STATUS`): 0 found; 1 stable / 2 unstable at every scan value where the max
    growth is defined; 3 undefined: no scan value defined, or growths of both signs only across undefined
    scan values, or an undefined growth met inside the bracket (no silent jump to another crossing); 5 a
    jump: the sign change located is where the masked part of the kH grid changes (the max over the rest
    jumps across zero), not a zero of a continuous max growth.
    rtol : None (default) or the relative accuracy of the threshold in [1e-15, 1e-3] (the final bracket
    width in t); the growth itself is always evaluated at full accuracy, since a looser growth is not
    cheaper to evaluate here and its error, divided by the slope, would move the threshold.
    """
    if name not in THRESHOLD_ROWS:
        raise ValueError(f"name must be one of {sorted(THRESHOLD_ROWS)}; got {name!r}")
    row = THRESHOLD_ROWS[name]
    lo, hi = check_range(f"{name}_range", THRESHOLD_RANGES[name] if bounds is None else bounds, name)
    xtol = check_rtol(rtol) or XTOL
    p = np.array(params, dtype=float)
    if p.ndim != 2 or p.shape[0] not in (5, 6):
        raise ValueError(f"params must have shape (6, n) or (5, n); got {p.shape}")
    if p.shape[0] == 5:
        p = np.insert(p, row, np.nan, axis=0)
    s = np.ascontiguousarray(s_grid, dtype=float)
    n = p.shape[1]
    evaluations = np.zeros(n, dtype=np.int64)

    def growth(idx: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(max growth, masked grid points) at x = exp(t) for the points idx: one growth_chunk call."""
        q = p[:, idx]
        q[row] = np.exp(t)
        evaluations[idx] += 1
        out = growth_chunk(s, q)
        return out[0], out[4].astype(np.int64)

    res = ThresholdChunk(value=np.full(n, np.nan), reason=np.full(n, _NOCONV, dtype=np.int8),
                         location=np.full(n, np.nan), lo=np.full(n, np.nan), hi=np.full(n, np.nan),
                         undefined_at=np.full(n, np.nan),
                         growth_min=np.full(n, np.inf), growth_max=np.full(n, -np.inf),
                         n_undefined=np.zeros(n, dtype=np.int64),
                         n_masked=np.full((2, n), -1, dtype=np.int64), evaluations=evaluations)
    gmin, gmax = res.growth_min, res.growth_max

    # scan value j only for the points without a bracket among scan values 0 .. j-1
    ts = np.linspace(math.log(lo), math.log(hi), SCAN_POINTS)
    scanning = np.arange(n)
    prev = np.full(n, np.nan)
    prev_m = np.full(n, -1, dtype=np.int64)
    k = np.full(n, -1)  # bracket [ts[k], ts[k + 1]]
    f_lo, f_hi = np.full(n, np.nan), np.full(n, np.nan)
    m_lo, m_hi = np.full(n, -1, dtype=np.int64), np.full(n, -1, dtype=np.int64)
    for j in range(SCAN_POINTS):
        if not scanning.size:
            break
        v, m = growth(scanning, np.full(scanning.size, ts[j]))
        fin = np.isfinite(v)
        res.n_undefined[scanning[~fin]] += 1
        gmin[scanning[fin]] = np.minimum(gmin[scanning[fin]], v[fin])
        gmax[scanning[fin]] = np.maximum(gmax[scanning[fin]], v[fin])
        a = prev[scanning]
        cross = fin & np.isfinite(a) & ((a < 0) != (v < 0))
        hit = scanning[cross]
        k[hit], f_lo[hit], f_hi[hit], m_lo[hit], m_hi[hit] = j - 1, a[cross], v[cross], prev_m[hit], m[cross]
        prev[scanning], prev_m[scanning] = v, m
        scanning = scanning[~cross]
    # no bracket: classify by the signs of the finite scan values (all were evaluated)
    lo_s, hi_s = gmin[scanning], gmax[scanning]
    res.reason[scanning] = np.where(np.isfinite(lo_s) & (hi_s < 0), _STABLE,
                                    np.where(np.isfinite(lo_s) & (lo_s >= 0), _UNSTABLE, _UNDEFINED))
    gmin[gmin == np.inf] = np.nan
    gmax[gmax == -np.inf] = np.nan

    br = np.flatnonzero(k >= 0)
    res.lo[br] = np.exp(ts[k[br]])
    res.hi[br] = np.exp(ts[k[br] + 1])
    _brent(growth, br, ts[k[br]], ts[k[br] + 1], f_lo[br], f_hi[br], m_lo[br], m_hi[br], xtol, ts[1] - ts[0], res)
    return res


_Growth = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]  # (points, ln x) -> (growth, n_masked)


def _brent(growth: _Growth, idx: np.ndarray, xa: np.ndarray, xb: np.ndarray, fa: np.ndarray, fb: np.ndarray,
           ma: np.ndarray, mb: np.ndarray, xtol: float, width: float, res: ThresholdChunk) -> None:
    """Brent's method (scipy.optimize.brentq's steps, elementwise) on the brackets [xa, xb] in t = ln x.

    fa, fb: the growths at the bracket ends (opposite signs), ma, mb: their masked grid points. Writes
    value = exp(root), reason, undefined_at and n_masked of res at idx. Each iteration evaluates the growth
    of every unresolved point at once; the arithmetic of each element is that of brentq's scalar loop
    (scipy's C implementation), so the result does not depend on the other elements. After BRENT_ITER
    iterations only bisection steps are taken: the bracket (at most `width` wide) then halves each step
    until narrower than xtol, which bounds the loop by maxiter below.
    """
    rtol_t = 4 * np.finfo(float).eps
    maxiter = BRENT_ITER + math.ceil(math.log2(width / xtol)) + 2

    def found(sel: np.ndarray, x: np.ndarray, m_lo: np.ndarray, m_hi: np.ndarray) -> None:
        at = idx[sel]
        jump = m_lo[sel] != m_hi[sel]  # the masked kH points change across the bracket: no threshold here
        res.location[at] = np.exp(x[sel])
        res.value[at] = np.where(jump, np.nan, res.location[at])
        res.reason[at] = np.where(jump, _JUMP, _FOUND)
        res.n_masked[0, at] = m_lo[sel]
        res.n_masked[1, at] = m_hi[sel]

    # brentq returns an end where the growth is exactly zero without iterating
    zero_a = fa == 0
    zero_b = (fb == 0) & ~zero_a
    found(zero_a, xa, ma, ma)
    found(zero_b, xb, mb, mb)
    live = ~(zero_a | zero_b)
    idx, xpre, xcur, fpre, fcur, mpre, mcur = (a[live] for a in (idx, xa, xb, fa, fb, ma, mb))
    xblk, fblk, spre, scur = (np.zeros_like(xcur) for _ in range(4))
    mblk = np.zeros_like(mcur)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        for it in range(maxiter):
            if not idx.size:
                return
            # the contrapoint (xblk) is the last point where the growth had the other sign
            new = (fpre != 0) & (fcur != 0) & (np.signbit(fpre) != np.signbit(fcur))
            xblk, fblk, mblk = np.where(new, xpre, xblk), np.where(new, fpre, fblk), np.where(new, mpre, mblk)
            spre = np.where(new, xcur - xpre, spre)
            scur = np.where(new, spre, scur)
            # xcur is the end with the smaller growth
            sw = np.abs(fblk) < np.abs(fcur)
            xpre, xcur, xblk = np.where(sw, xcur, xpre), np.where(sw, xblk, xcur), np.where(sw, xcur, xblk)
            fpre, fcur, fblk = np.where(sw, fcur, fpre), np.where(sw, fblk, fcur), np.where(sw, fcur, fblk)
            mpre, mcur, mblk = np.where(sw, mcur, mpre), np.where(sw, mblk, mcur), np.where(sw, mcur, mblk)
            delta = (xtol + rtol_t * np.abs(xcur)) / 2
            sbis = (xblk - xcur) / 2
            done = (fcur == 0) | (np.abs(sbis) < delta)
            below = xcur <= xblk
            found(done, xcur, np.where(below, mcur, mblk), np.where(below, mblk, mcur))
            keep = ~done
            idx, xpre, xcur, xblk, fpre, fcur, fblk, mpre, mcur, mblk, spre, scur, delta, sbis = (
                a[keep] for a in (idx, xpre, xcur, xblk, fpre, fcur, fblk, mpre, mcur, mblk, spre, scur, delta, sbis))
            if not idx.size:
                return
            # interpolation: secant if the previous point is the contrapoint, else inverse quadratic
            dpre = (fpre - fcur) / (xpre - xcur)
            dblk = (fblk - fcur) / (xblk - xcur)
            stry = np.where(xpre == xblk, -fcur * (xcur - xpre) / (fcur - fpre),
                            -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre)))
            # accepted only if short enough (else bisection), as in brentq
            good = ((np.abs(spre) > delta) & (np.abs(fcur) < np.abs(fpre)) & (it < BRENT_ITER)
                    & (2 * np.abs(stry) < np.minimum(np.abs(spre), 3 * np.abs(sbis) - delta)))
            spre = np.where(good, scur, sbis)
            scur = np.where(good, stry, sbis)
            xpre, fpre, mpre = xcur, fcur, mcur
            xcur = xcur + np.where(np.abs(scur) > delta, scur, np.where(sbis > 0, delta, -delta))
            fcur, mcur = growth(idx, xcur)
            bad = ~np.isfinite(fcur)
            res.undefined_at[idx[bad]] = np.exp(xcur[bad])
            res.reason[idx[bad]] = _UNDEFINED
            keep = ~bad
            idx, xpre, xcur, xblk, fpre, fcur, fblk, mpre, mcur, mblk, spre, scur = (
                a[keep] for a in (idx, xpre, xcur, xblk, fpre, fcur, fblk, mpre, mcur, mblk, spre, scur))


def critical_gamma_chunk(s_grid: np.ndarray, params: np.ndarray, *, gamma_range: tuple[float, float] = (1e-2, 1e3),
                         rtol: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(gamma_c, reason) for one chunk: :func:`threshold_chunk` for gamma (Sect. IV, Fig. 4c).

    params : (5, n) rows f, beta, eta, Delta, xi, or (6, n) in growth_chunk's layout with the gamma row
    ignored. gamma_c is NaN where reason != 0 (reasons: :data:`THRESHOLD_STATUS`).
    """
    r = threshold_chunk("gamma", s_grid, params, gamma_range, rtol)
    return r.value, r.reason


def critical_eta_chunk(s_grid: np.ndarray, params: np.ndarray, *, eta_range: tuple[float, float] = (1.0, 1e8),
                       rtol: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(eta_c, reason) for one chunk: :func:`threshold_chunk` for eta (Sect. IV).

    params : (5, n) rows gamma, f, beta, Delta, xi, or (6, n) in growth_chunk's layout with the eta row
    ignored. eta_c is NaN where reason != 0 (reasons: :data:`THRESHOLD_STATUS`).
    """
    r = threshold_chunk("eta", s_grid, params, eta_range, rtol)
    return r.value, r.reason


def _no_threshold_message(name: str, bounds: tuple[float, float], r: ThresholdChunk, i: int) -> str:
    """The ValueError text for element i of r (reason != 0): the parameter, the range and why."""
    valid = f"[{bounds[0]:g}, {bounds[1]:g}]"
    code = int(r.reason[i])
    masked = "Rayleigh branch masked on the whole kH grid"
    if code == _UNDEFINED and np.isfinite(r.undefined_at[i]):
        return (f"no stability threshold for {name} located in {valid}: max growth changes sign between {name} = "
                f"{r.lo[i]:.6g} and {r.hi[i]:.6g} but is undefined ({masked}) at {name} = {r.undefined_at[i]:.6g} in "
                "between")
    span = f"between {r.growth_min[i]:.3g} and {r.growth_max[i]:.3g}"
    nu = int(r.n_undefined[i])
    where = f"; undefined at {nu} of {SCAN_POINTS} scan values" if nu else ""
    if code == _JUMP:
        m = r.n_masked[:, i]
        return (f"no stability threshold for {name} in {valid}: the max growth jumps across zero at {name} = "
                f"{r.location[i]:.10g}, where the Rayleigh branch is masked on {int(m[0])} kH grid points below and "
                f"{int(m[1])} above (a limit of the branch's continuation, not a marginal mode)")
    why = {
        _STABLE: f"stable throughout: max growth stays {span} over the range (< 0 wherever defined{where})",
        _UNSTABLE: f"unstable throughout: max growth stays {span} over the range (>= 0 wherever defined{where})",
        _UNDEFINED: (f"max growth undefined ({masked}) at every scan value" if not np.isfinite(r.growth_min[i]) else
                     f"max growth changes sign ({span}) only across scan values where it is undefined ({masked})"),
    }.get(code, THRESHOLD_STATUS.get(code, f"reason {code}"))
    return f"no stability threshold for {name} in {valid}: {why}"


def _thresholds(name: str, bounds, kH, fixed: dict, rtol: float | None, workers: int | None):
    """Threshold of `name` for every element of the broadcast fixed parameters (validated by name)."""
    bounds = check_range(f"{name}_range", bounds, name)
    check_rtol(rtol)
    arrays = np.broadcast_arrays(*(check(k, v) for k, v in fixed.items()))
    s = np.log(DEFAULT_KH if kH is None else _grid(kH))
    shape = arrays[0].shape
    cols = dict(zip(fixed, (a.ravel().astype(float) for a in arrays), strict=True))
    n = arrays[0].size
    cols[name] = np.full(n, np.nan)
    params = np.stack([cols[k] for k in ("gamma", "f", "beta", "eta", "Delta", "xi")])
    chunks = [params[:, i : i + CHUNK] for i in range(0, n, CHUNK)]
    nworkers = workers or os.cpu_count() or 1
    if len(chunks) > 1 and nworkers > 1:
        with ThreadPoolExecutor(nworkers) as pool:
            parts = list(pool.map(lambda c: threshold_chunk(name, s, c, bounds, rtol), chunks))
    else:
        parts = [threshold_chunk(name, s, c, bounds, rtol) for c in chunks]
    for c, part in enumerate(parts):
        bad = np.flatnonzero(part.reason != _FOUND)
        if bad.size:
            msg = _no_threshold_message(name, bounds, part, int(bad[0]))
            if shape:  # which element of the broadcast input
                i = c * CHUNK + int(bad[0])
                at = ", ".join(f"{k} = {cols[k][i]:.6g}" for k in fixed)
                msg += f" (element {tuple(int(j) for j in np.unravel_index(i, shape))}: {at})"
            raise ValueError(msg)
    out = np.concatenate([p.value for p in parts]) if parts else np.empty(0)
    return out.reshape(shape) if shape else float(out[0])


def critical_gamma(*, f, beta, eta=math.inf, Delta=1.0, xi=0.0, kH=None, gamma_range=(1e-2, 1e3),
                   rtol: float | None = None, workers: int | None = None):
    """gamma at which the max growth on the Rayleigh branch crosses zero (stable below), to ~1e-12 relative.

    Sect. IV, Fig. 4c; docs/physics.md §9. Check value: 2.4149 for f = 0.9, beta = 0.3, eta = inf (paper:
    "between 2 and 3"). Parameters may be arrays (broadcast; one threshold per element). The threshold is
    that of :func:`threshold_chunk`: the first sign change in a 17-value log scan of gamma_range (either
    direction: where growth is not monotone in gamma, e.g. finite eta with Delta < 1, the side below may be
    the unstable one), refined by Brent's method; rtol as there. ValueError naming gamma, the range and why
    (stable throughout, unstable throughout, undefined) if an element has no crossing in gamma_range.
    kH: the grid (default DEFAULT_KH); the work is split into chunks run on `workers` threads as in
    :func:`growth_analysis`.
    """
    return _thresholds("gamma", gamma_range, kH, dict(f=f, beta=beta, eta=eta, Delta=Delta, xi=xi), rtol, workers)


def critical_eta(*, gamma, f, beta, Delta=1.0, xi=0.0, kH=None, eta_range=(1.0, 1e8), rtol: float | None = None,
                 workers: int | None = None):
    """eta at which the max growth on the Rayleigh branch crosses zero (stable below), to ~1e-12 relative.

    Sect. IV; docs/physics.md §9. Check value: 3.2982 for gamma = 3, f = 0.9, beta = 0.3 (paper: "~3.3").
    As :func:`critical_gamma` with eta scanned over eta_range; ValueError without a crossing.
    """
    return _thresholds("eta", eta_range, kH, dict(gamma=gamma, f=f, beta=beta, Delta=Delta, xi=xi), rtol, workers)


def min_gy_at_rayleigh_speed(beta, *, eta=math.inf):
    """(q_min, min_q G_y(z_R, q)) (Eq. criterion): G_y at the Rayleigh speed is negative with one minimum."""
    b = check("beta", beta)
    e = check("eta", eta)
    bb, ee = np.broadcast_arrays(b, e)
    qmin = np.empty(bb.shape)
    gmin = np.empty(bb.shape)
    for idx in np.ndindex(bb.shape):
        zr = complex(rayleigh_speed(float(bb[idx])))

        def gy(t: float, zr: complex = zr, beta_: float = float(bb[idx]), eta_: float = float(ee[idx])) -> float:
            return float(response_functions(zr, math.exp(t), beta=beta_, eta=eta_)[1].real)

        ts = np.linspace(math.log(1e-3), math.log(1e3), 121)
        vals = [gy(t) for t in ts]
        k = int(np.argmin(vals))
        r = optimize.minimize_scalar(gy, bracket=(ts[max(k - 1, 0)], ts[k], ts[min(k + 1, len(ts) - 1)]),
                                     method="brent", tol=1e-12)
        qmin[idx] = math.exp(r.x)
        gmin[idx] = r.fun
    return (qmin, gmin) if qmin.ndim else (float(qmin), float(gmin))


def criterion_chi(beta):
    """chi_c from the approximate criterion gamma f G_y(z_R, kH) = -z_R (Eq. criterion): z_R / |min G_y|.

    Check value: 1.99750 for beta = 0.3 (min G_y = -0.475111 at kH = 0.86438). The solid line of Fig. 4c.
    """
    _, gmin = min_gy_at_rayleigh_speed(beta)
    return rayleigh_speed(beta) / np.abs(gmin)


def critical_chi(beta, *, f):
    """Exact threshold chi_c = gamma_c f of the Rayleigh branch for eta = inf, Delta = 1 (Fig. 4c, open symbols)."""
    b, ff = np.broadcast_arrays(check("beta", beta), check("f", f))
    return critical_gamma(f=ff, beta=b) * ff


@dataclass(frozen=True)
class StabilityVerdict:
    """Global verdict on linear stability of steady sliding in a stated window.

    stable : True when the Rayleigh branch has max growth <= 0 on the kH grid (NaN: not stable) and no root of the
        dispersion relation (any branch) lies in the window im_min <= Im z <= im_max, |Re z| <= re_max
        at any kH of the grid.
    rayleigh_growth : max Im z of the Rayleigh branch over the grid (refined)
    counts : number of roots in the window per kH (argument principle, certified)
    kH : the grid; window : (re_max, im_min, im_max)
    """

    stable: bool
    rayleigh_growth: float
    counts: np.ndarray
    kH: np.ndarray
    window: tuple[float, float, float]

    def __bool__(self) -> bool:
        return self.stable


VERDICT_KH = np.logspace(-2, 2, 41)


def stability_verdict(*, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, kH=None, re_max=5.0, im_min=1e-4,
                      im_max=2.0) -> StabilityVerdict:
    """Combine the Rayleigh branch (:func:`growth_analysis`) with :func:`model.unstable_count` over kH.

    The count only covers its window (docs/physics.md §3: for large eta many roots sit just above the
    real axis and the count depends on im_min), so the verdict states it.
    """
    from .modes import unstable_count

    q = VERDICT_KH if kH is None else check("kH", kH)
    p = dict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi)
    growth = float(growth_analysis(q, **p).growth)
    counts = np.array([unstable_count(float(k), **p, re_max=re_max, im_min=im_min, im_max=im_max) for k in q])
    # a NaN growth (branch masked on the whole grid) certifies nothing: not stable
    ok = growth <= 0.0 and not np.any(counts > 0)
    return StabilityVerdict(bool(ok), growth, counts, np.asarray(q), (re_max, im_min, im_max))


def stable(*, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, kH=None, re_max=5.0, im_min=1e-4, im_max=2.0):
    """True if steady sliding is linearly stable: see :func:`stability_verdict` (which gives the details)."""
    return stability_verdict(gamma=gamma, f=f, beta=beta, eta=eta, Delta=Delta, xi=xi, kH=kH, re_max=re_max,
                             im_min=im_min, im_max=im_max).stable


def criterion_gy_level(*, gamma, f, beta):
    """The level -z_R/(gamma f) of the approximate criterion gamma f G_y(z_R, kH) = -z_R (Eq. criterion).

    Steady sliding is approximately unstable at the kH where G_y(z_R, kH) (:func:`model.response_functions` at
    the Rayleigh speed) lies below this level (docs/physics.md §4). Broadcasts; -inf where gamma f = 0 (the
    criterion is never met without friction).
    """
    g, ff, b = check("gamma", gamma), check("f", f), check("beta", beta)
    chi = g * ff
    with np.errstate(divide="ignore"):
        return np.where(chi == 0.0, -np.inf, -rayleigh_speed(b) / np.where(chi == 0.0, 1.0, chi))
