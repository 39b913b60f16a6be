"""Neutral modes: the thresholds of the max growth as certified roots of three real equations (docs/physics.md §9).

:func:`neutral_mode` solves F(x; e^s) = 0 for a real z = x together with Im dz/ds = 0 (the max growth is stationary
in s = ln kH there) for x, s and t = ln gamma or ln eta, by Newton's method (:func:`_neutral_system`, a 3x3 real
system solved by :func:`_solve3`); at an end of the kH range (edge = True) s is fixed. model.thresholds calls it.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from ._common import jitted
from .elementary import cinv
from .growth import ETA_FD
from .records import Params
from .response import weighted_dispersion

P_GAMMA = 0  # the threshold parameter of neutral_mode: t = ln gamma ...
P_ETA = 3  # ... or t = ln eta (rows of growth_chunk's parameter layout)
NEUTRAL_ITERS = 40  # Newton iterations of a neutral mode (quadratic from a good start: a bound, not a budget)
NEUTRAL_FD = 1e-5  # step (relative in Re z, absolute in s and t) of the central differences of the slope equation
NEUTRAL_STEP = 0.5  # largest Newton step in s = ln kH and in t (larger steps are scaled down: damping)
NEUTRAL_TOL = 1e-12  # converged when the last step is below this relative to max(|x|, 1e-3), max(1, |t|) ...
NEUTRAL_TOL_S = 1e-9  # ... and in s below this (t is stationary in s at the neutral mode: s matters to 2nd order)
UPPER_LIP = 5e-300  # Im z of the evaluation of a real z on the upper lip of the cuts (eta = inf, |Re z| > 1)


@jitted
def _with_param(p: Params, which: int, t: float) -> Params:
    """p with gamma (which = P_GAMMA) or eta (P_ETA) set to e^t."""
    v = math.exp(t)
    if which == P_GAMMA:
        return Params(v, p.f, p.beta, p.eta, p.delta, p.xi)
    return Params(p.gamma, p.f, p.beta, v, p.delta, p.xi)


@jitted
def _neutral_terms(x: float, s: float, t: float, which: int, p: Params,
                   lip: float) -> tuple[complex, complex, complex, complex, float]:
    """F, dF/dz, dF/ds, dF/dt at the real z = x (evaluated at x + i lip: lip = 5e-300 gives the upper lip of the
    cuts at |x| > 1 for eta = inf, the limit from Im z > 0; 0.0 the value the Rayleigh thresholds use), s = ln kH,
    t = ln gamma or ln eta, and the rounding scale of F.

    dF/d ln gamma = gamma (G_x + i f G_y) exactly; dF/d ln eta by a central difference of step ETA_FD (Newton's
    Jacobian only: the equations themselves are exact)."""
    pp = _with_param(p, which, t)
    q = math.exp(s)
    z = complex(x, lip)
    fv, dfv, sc, fq = weighted_dispersion(z, q, pp.gamma, 1.0, pp)
    if which == P_GAMMA:
        ft = weighted_dispersion(z, q, pp.gamma, 0.0, pp)[0]
    else:
        fp = weighted_dispersion(z, q, pp.gamma, 1.0, _with_param(p, which, t + ETA_FD))[0]
        fm = weighted_dispersion(z, q, pp.gamma, 1.0, _with_param(p, which, t - ETA_FD))[0]
        ft = (fp - fm) / (2.0 * ETA_FD)
    return fv, dfv, q * fq, ft, sc


@jitted
def _slope_eq(x: float, s: float, t: float, which: int, p: Params, lip: float) -> float:
    """The third equation of a neutral mode: Im(dF/ds / dF/dz) = -Im dz/ds (zero where Im z is stationary in s)."""
    pp = _with_param(p, which, t)
    q = math.exp(s)
    _, dfv, _, fq = weighted_dispersion(complex(x, lip), q, pp.gamma, 1.0, pp)
    if dfv == 0:
        return math.nan
    return (q * fq * cinv(dfv)).imag


@jitted
def _solve3(a: np.ndarray, r: np.ndarray, n: int) -> bool:
    """Solve a[:n, :n] d = r in place (r becomes d) by Gaussian elimination with partial pivoting; False if singular."""
    for c in range(n):
        piv = c
        for i in range(c + 1, n):
            if abs(a[i, c]) > abs(a[piv, c]):
                piv = i
        if a[piv, c] == 0.0 or not math.isfinite(a[piv, c]):
            return False
        if piv != c:
            for k in range(n):
                a[c, k], a[piv, k] = a[piv, k], a[c, k]
            r[c], r[piv] = r[piv], r[c]
        for i in range(c + 1, n):
            f = a[i, c] / a[c, c]
            for k in range(c, n):
                a[i, k] -= f * a[c, k]
            r[i] -= f * r[c]
    for c in range(n - 1, -1, -1):
        acc = r[c]
        for k in range(c + 1, n):
            acc -= a[c, k] * r[k]
        r[c] = acc / a[c, c]
    return True


@jitted
def _neutral_system(x: float, s: float, t: float, which: int, edge: bool, p: Params, a: np.ndarray,
                    r: np.ndarray, lip: float) -> tuple[int, float]:
    """Newton's linear system of a neutral mode at (x, s, t): fills a and r (r = -residual); (size, |F|/scale).

    Unknowns (x, t) at fixed s for an edge mode (Im z = 0 at an end of the kH range: 2 equations Re F = Im F = 0),
    else (x, s, t) with the slope equation (_slope_eq) as the third, its derivatives by central differences.
    Size 0 if F or its derivatives are not finite."""
    fv, fz, fs, ft, sc = _neutral_terms(x, s, t, which, p, lip)
    if not (cmath.isfinite(fv) and cmath.isfinite(fz) and cmath.isfinite(fs) and cmath.isfinite(ft)) or fz == 0:
        return 0, math.inf
    a[0, 0], a[1, 0], r[0], r[1] = fz.real, fz.imag, -fv.real, -fv.imag
    if not sc > 0.0:
        return 0, math.inf
    if edge:
        a[0, 1], a[1, 1] = ft.real, ft.imag
        return 2, abs(fv) / sc
    a[0, 1], a[1, 1], a[0, 2], a[1, 2] = fs.real, fs.imag, ft.real, ft.imag
    r[2] = -(fs * cinv(fz)).imag
    hx = NEUTRAL_FD * max(abs(x), 1e-3)
    h = NEUTRAL_FD
    a[2, 0] = (_slope_eq(x + hx, s, t, which, p, lip) - _slope_eq(x - hx, s, t, which, p, lip)) / (2.0 * hx)
    a[2, 1] = (_slope_eq(x, s + h, t, which, p, lip) - _slope_eq(x, s - h, t, which, p, lip)) / (2.0 * h)
    a[2, 2] = (_slope_eq(x, s, t + h, which, p, lip) - _slope_eq(x, s, t - h, which, p, lip)) / (2.0 * h)
    return 3, abs(fv) / sc


@jitted
def neutral_mode(x0: float, s0: float, t0: float, which: int, edge: bool, gamma: float, f: float, beta: float,
                 eta: float, delta: float, xi: float,
                 lip: float = 0.0) -> tuple[float, float, float, bool, int, float, float, float]:
    """A neutral mode by Newton's method from (x0, s0, t0): real z = x, s = ln kH, t = ln gamma (which = P_GAMMA)
    or ln eta (P_ETA) with F(x; e^s) = 0 and Im dz/ds = 0 (or, for edge = True, s fixed at an end of the range).

    Returns (x, s, t, converged, iterations, |F|/scale, Im dz/dt, Re dz/dt): dz/dt = -F_t/F_z at the mode, whose
    imaginary part is the slope of the max growth across the threshold (its sign: the crossing's direction).
    Converged when the last step is below NEUTRAL_TOL (relative) in x and t and NEUTRAL_TOL_S in s; steps in s
    and t are scaled down to NEUTRAL_STEP. The parameter being solved for is ignored in the arguments. F is
    evaluated at x + i lip (see _neutral_terms: 0.0 for the Rayleigh branch, UPPER_LIP for any root at eta = inf,
    whose neutral mode beyond the shear speed lies on the upper lip of the cut).
    """
    p = Params(gamma, f, beta, eta, delta, xi)
    a = np.empty((3, 3))
    r = np.empty(3)
    x, s, t = x0, s0, t0
    for it in range(NEUTRAL_ITERS):
        n, res = _neutral_system(x, s, t, which, edge, p, a, r, lip)
        if n == 0 or not _solve3(a, r, n):
            break
        dx = r[0]
        ds = 0.0 if edge else r[1]
        dt = r[n - 1]
        damp = min(1.0, NEUTRAL_STEP / max(abs(ds), abs(dt), 1e-300))
        x += damp * dx
        s += damp * ds
        t += damp * dt
        if not (math.isfinite(x) and math.isfinite(s) and math.isfinite(t)):
            break
        if (damp == 1.0 and abs(dx) <= NEUTRAL_TOL * max(abs(x), 1e-3) and abs(dt) <= NEUTRAL_TOL * max(1.0, abs(t))
                and abs(ds) <= NEUTRAL_TOL_S):
            fv, fz, _, ft, sc = _neutral_terms(x, s, t, which, p, lip)
            if fz == 0 or not sc > 0.0:
                break
            dzdt = -ft * cinv(fz)
            return x, s, t, True, it + 1, abs(fv) / sc, dzdt.imag, dzdt.real
    return x, s, t, False, NEUTRAL_ITERS, math.nan, math.nan, math.nan
