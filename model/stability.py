"""Stability analysis on the Rayleigh branch: growth maps, unstable bands, thresholds (Sect. IV, Fig. 4c)."""

from __future__ import annotations

import math
import os
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
    q = check("kH", kH)
    if q.ndim != 1 or q.size < 2 or np.any(np.diff(q) <= 0):
        raise ValueError("kH must be a 1-D increasing grid with at least 2 points")
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


class _Undefined(Exception):
    """Max growth is NaN (Rayleigh branch masked on the whole kH grid) at a trial parameter value."""

    def __init__(self, x: float) -> None:
        super().__init__(x)
        self.x = x


def _threshold(fun, lo: float, hi: float, name: str, valid: str) -> float:
    """Zero crossing of fun (max growth) on [lo, hi] in log space, to ~1e-12 relative.

    A coarse log-spaced scan (17 values) brackets the first crossing from the stable (negative) side
    among finite values (NaN = branch masked on the whole kH grid), then Brent's method refines it.
    ValueError naming the parameter when no crossing exists in the range, or when the max growth is
    undefined (NaN) at a value Brent's method tries inside the bracket: no silent jump elsewhere.
    """
    ts = np.linspace(math.log(lo), math.log(hi), 17)
    vals = np.array([fun(math.exp(t)) for t in ts])

    def g(t: float) -> float:
        v = fun(math.exp(t))
        if not math.isfinite(v):
            raise _Undefined(math.exp(t))
        return v

    for i in range(ts.size - 1):
        a, b = vals[i], vals[i + 1]
        if np.isfinite(a) and np.isfinite(b) and (a < 0) != (b < 0):
            try:
                x = optimize.brentq(g, ts[i], ts[i + 1], xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200)
            except _Undefined as e:
                raise ValueError(
                    f"no stability threshold for {name} located in {valid}: max growth changes sign between "
                    f"{name} = {math.exp(ts[i]):.6g} and {math.exp(ts[i + 1]):.6g} but is undefined (Rayleigh "
                    f"branch masked on the whole kH grid) at {name} = {e.x:.6g} in between") from None
            return math.exp(x)
    finite = vals[np.isfinite(vals)]
    span = f"between {finite.min():.3g} and {finite.max():.3g}" if finite.size else "undefined (branch masked)"
    raise ValueError(f"no stability threshold for {name} in {valid}: max growth stays {span} over the range")


def _scalar_growth(kH: np.ndarray, **p) -> float:
    return float(growth_analysis(kH, **p).growth)


def _param_threshold(kH: np.ndarray, base: dict, name: str, bounds: tuple[float, float]) -> float:
    """Threshold of the parameter `name` (the others fixed at `base`)."""
    valid = f"[{bounds[0]:g}, {bounds[1]:g}]"
    return _threshold(lambda v: _scalar_growth(kH, **base, **{name: v}), *bounds, name, valid)


def _thresholds(name: str, bounds: tuple[float, float], kH, fixed: dict):
    """Threshold of `name` for every element of the broadcast fixed parameters (validated by name)."""
    q = DEFAULT_KH if kH is None else kH
    bounds = check_range(f"{name}_range", bounds, name)
    names = list(fixed)
    arrays = np.broadcast_arrays(*(check(k, v) for k, v in fixed.items()))
    out = np.empty(arrays[0].shape)
    for idx in np.ndindex(out.shape):
        base = dict(zip(names, (float(a[idx]) for a in arrays), strict=True))
        out[idx] = _param_threshold(q, base, name, bounds)
    return out if out.ndim else float(out)


def critical_gamma(*, f, beta, eta=math.inf, Delta=1.0, xi=0.0, kH=None, gamma_range=(1e-2, 1e3)):
    """gamma at which the max growth on the Rayleigh branch crosses zero (stable below), to ~1e-12 relative.

    Check value: 2.4149 for f = 0.9, beta = 0.3, eta = inf (paper: "between 2 and 3"). Parameters may be
    arrays (broadcast; one threshold per element). ValueError if there is no crossing in gamma_range.
    """
    return _thresholds("gamma", gamma_range, kH, dict(f=f, beta=beta, eta=eta, Delta=Delta, xi=xi))


def critical_eta(*, gamma, f, beta, Delta=1.0, xi=0.0, kH=None, eta_range=(1.0, 1e8)):
    """eta at which the max growth on the Rayleigh branch crosses zero (stable below), to ~1e-12 relative.

    Check value: 3.2982 for gamma = 3, f = 0.9, beta = 0.3 (paper: "~3.3"). ValueError without a crossing.
    """
    return _thresholds("eta", eta_range, kH, dict(gamma=gamma, f=f, beta=beta, Delta=Delta, xi=xi))


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

    The count only covers its window (PHYSICS section 3: for large eta many roots sit just above the
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
