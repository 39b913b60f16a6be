"""Stability analysis on the Rayleigh branch: growth maps, verdicts, unstable bands, thresholds (Sect. IV, Fig. 4c).

The threshold solver lives in :mod:`model.thresholds` (re-exported here).
"""

from __future__ import annotations

import math
import os
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from enum import IntEnum
from typing import Any, NamedTuple

import numpy as np
from scipy import optimize

from . import _kernels as K
from ._validate import check, check_kh_grid, check_rtol
from .elastodynamics import response_functions
from .rayleigh import rayleigh_speed

CHUNK = 256  # parameter sets per chunk of a stability map


@dataclass(frozen=True)
class GrowthResult:
    """Max growth rate over kH on the Rayleigh branch, per parameter set (docs/physics.md §9).

    Attributes
    ----------
    growth : the continuous max of Im z (c/c_s units) over the kH range [kH[0], kH[-1]] where the branch is followed,
        between grid points too, at an exact root (NaN if the branch is masked on the whole range)
    kH_at_max : where the maximum is reached
    kH_min, kH_max : the unstable band around the maximum (Im z > 0), NaN if growth <= 0 or if the
        band reaches beyond the grid
    n_masked : how many grid points were masked (branch not followed there)
    verdict : int8, 0 stable, 1 unstable, 2 undetermined (:data:`VERDICTS`)
    verdict_reason : int8, why (a key of :data:`VERDICT_STATUS`)
    error : estimated absolute error of the growth
    re_z_at_max : Re z at the maximum (the mode's phase velocity; its Im part is the growth)
    """

    growth: np.ndarray
    kH_at_max: np.ndarray
    kH_min: np.ndarray
    kH_max: np.ndarray
    n_masked: np.ndarray
    verdict: np.ndarray | None = None
    verdict_reason: np.ndarray | None = None
    error: np.ndarray | None = None
    re_z_at_max: np.ndarray | None = None


#: reason codes of a growth analysis's verdict (GrowthResult.verdict_reason; atlases' ``verdict_reason``)
VERDICT_STATUS = {
    K.V_STABLE: "stable: the max growth is below zero by more than its error on the whole kH range where the "
    "branch exists (for eta = inf it may leave the physical sheet through the cut, Im z -> 0-, at |Re z| > 1), and "
    "no root of the branch there is pole-dense",
    K.V_UNSTABLE: "unstable: the max growth (a certified root, not pole-dense) is above its error",
    K.V_MASKED: "undetermined: the Rayleigh branch is lost on part of the kH range and does not grow on the rest",
    K.V_NOBRANCH: "undetermined: no certified root of the Rayleigh branch on the kH range (no start, lost "
    "everywhere, or no convergence at a maximum)",
    K.V_POLE_DENSE: "undetermined: pole-dense: for finite eta the branch enters the lower block's undamped real-axis "
    "poles (|Re z| > 1 and eta kH Re alpha_s < 1), where which root a continuation follows depends on its resolution "
    "and many other roots lie just above the poles (docs/physics.md §9), and it does not grow elsewhere",
    K.V_MARGINAL: "undetermined: |max growth| is not above its error estimate",
}


class Verdict(IntEnum):
    """The verdict classes of the Rayleigh branch and of sliding over every branch (GrowthResult.verdict,
    SlidingResult.verdict; atlases' ``verdict`` and ``verdict_all``, int8)."""

    STABLE = 0
    UNSTABLE = 1
    UNDETERMINED = 2


#: the verdict classes' names, by code
VERDICTS = {v: v.name.lower() for v in Verdict}


def verdict_class(reason: np.ndarray) -> np.ndarray:
    """The :class:`Verdict` (int8: 0 stable, 1 unstable, 2 undetermined) of verdict reason codes (NaN or < 0: 2)."""
    r = np.asarray(reason, dtype=float)
    return np.where(r == K.V_STABLE, Verdict.STABLE,
                    np.where(r == K.V_UNSTABLE, Verdict.UNSTABLE, Verdict.UNDETERMINED)).astype(np.int8)


#: rows of :func:`growth_chunk`'s result
class GrowthRows(NamedTuple):
    """The rows of :func:`growth_chunk` by name (arrays over a chunk's parameter sets; of one column: one set's
    values): what :func:`growth_rows` gives, so that no caller indexes the rows by number."""

    growth: Any
    ln_kH_at_max: Any
    ln_kH_min: Any
    ln_kH_max: Any
    n_masked: Any
    re_z_at_max: Any
    error: Any
    verdict_reason: Any
    dgrowth_dln_gamma: Any
    dgrowth_dln_eta: Any
    pole_dense: Any
    max_at_lost_end: Any


#: the names of :func:`growth_chunk`'s rows, in order
GROWTH_ROWS = GrowthRows._fields


def growth_rows(rows) -> GrowthRows:
    """The rows of :func:`growth_chunk` (or one column of them, or the growth kernel's values at one point) by
    name."""
    return GrowthRows(*rows)


def growth_chunk(s_grid: np.ndarray, params: np.ndarray, rtol: float | None = None) -> np.ndarray:
    """Pure function of one chunk: params (6, n) rows gamma, f, beta, eta, Delta, xi -> (12, n) results.

    Rows of the result (:data:`GROWTH_ROWS`): growth, ln kH at max, ln kH_min, ln kH_max, n_masked, Re z at the
    max, the growth's error estimate, the verdict reason code (:data:`VERDICT_STATUS`), the slopes of the max
    growth in ln gamma and ln eta (0 for eta = inf), 1 where the branch enters the pole-dense part of the range
    (else 0), and 1 where the maximum is at an end of the followed part inside the range or at a boundary of the
    pole-dense part (the branch is lost, or not the Rayleigh mode, beyond it: the maximum is approached there, and
    its error covers Im z's change to the next sample) (else 0). No shared state, so a distributed backend can run
    chunks anywhere. rtol as in :func:`growth_analysis`.
    """
    tol = check_rtol(rtol)
    n = params.shape[1]
    out = np.empty((K.NOUT, n))
    cols = [np.ascontiguousarray(params[i], dtype=float) for i in range(6)]
    K.growth_many(np.ascontiguousarray(s_grid, dtype=float), *cols, tol, out)
    return out


def growth_analysis(kH, *, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0, workers: int | None = None,
                    rtol: float | None = None) -> GrowthResult:
    """Continuous max over kH of Im z on the Rayleigh branch (the stability map), its verdict and the unstable band.

    kH : 1-D increasing grid (> 0) whose ends give the kH range of the maximum (its points only decide
    `n_masked`). The maximum is the continuous one over the range where the branch is followed (docs/physics.md
    §9): the slope of the path interpolant is sampled NSUB = 4 times per path interval, every local maximum
    that may be the largest is located on the interpolant and refined with exact roots (a Newton correction of
    the location from the exact slope: the value is exact to rounding), the largest wins. The band ends are
    found by Newton's method in ln kH on exact roots. The verdict (stable / unstable / undetermined, with a
    reason: :data:`VERDICT_STATUS`) says whether the growth's sign is certified. Parameters broadcast against
    each other: e.g.
    ``growth_analysis(k, gamma=g[:, None], eta=e[None, :], f=0.9, beta=0.3)`` is a 2-D map.
    Work is split into chunks of parameter sets (:func:`growth_chunk`) run on `workers` threads
    (default: the number of CPUs; the compiled kernels release the GIL).
    rtol : None (default: the growth is a certified root, accurate to ~1e-15) or the requested relative
    accuracy of the roots in [1e-15, 1e-3] (growth accurate to rtol |z| absolute): the refinement then
    uses the path interpolant wherever its estimated error is below 0.1 rtol.
    """
    tol = check_rtol(rtol)
    q = check_kh_grid(kH)
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
    out = np.concatenate(parts, axis=1) if parts else np.empty((K.NOUT, 0))
    return growth_result(out, shape)


def growth_result(rows: np.ndarray, shape: tuple[int, ...] | None = None) -> GrowthResult:
    """The :class:`GrowthResult` of :func:`growth_chunk`'s rows, for parameter sets of this shape (None: one axis, as
    the rows): kH from ln kH, the verdict class from its reason code. The one place the rows become a result (the
    model's functions and the atlas engine both use it)."""
    r = growth_rows(row if shape is None else row.reshape(shape) for row in rows)
    reason = r.verdict_reason.astype(np.int8)  # the kernel always gives a code
    return GrowthResult(r.growth, np.exp(r.ln_kH_at_max), np.exp(r.ln_kH_min), np.exp(r.ln_kH_max),
                        r.n_masked.astype(int), verdict_class(reason), reason, r.error, r.re_z_at_max)


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


@dataclass(frozen=True)
class StabilityVerdict:
    """Global verdict on linear stability of steady sliding in a stated window.

    Attributes
    ----------
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
    """Combine the Rayleigh branch (:func:`growth_analysis`) with :func:`unstable_count` over kH.

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

    Steady sliding is approximately unstable at the kH where G_y(z_R, kH) (:func:`response_functions` at
    the Rayleigh speed) lies below this level (docs/physics.md §4). Broadcasts; -inf where gamma f = 0 (the
    criterion is never met without friction).
    """
    g, ff, b = check("gamma", gamma), check("f", f), check("beta", beta)
    chi = g * ff
    with np.errstate(divide="ignore"):
        return np.where(chi == 0.0, -np.inf, -rayleigh_speed(b) / np.where(chi == 0.0, 1.0, chi))
