"""Growth analysis: the continuous maximum of Im z over a kH range, its band and its verdict (docs/physics.md §9).

:func:`growth_one` samples the slope of the path interpolant (:mod:`model._kernels.path`) NSUB times per path
interval, refines every local maximum that may be the largest with exact roots (:func:`_best_peak`), including the
exact boundaries of the pole-dense part (finite eta), finds the band's ends (:func:`_band`) and gives the verdict
(V_*) and the slopes of the max growth in ln gamma and ln eta. :func:`growth_many` is the entry point of the
stability maps, :func:`growth_point` that of the threshold solver.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from ._common import jitted
from .continuation import PRED_TOL
from .elementary import EPS, cinv, csqrt, fix0
from .path import OK, build_path, interp_node, interp_value, map_node_tol, node_interval, solve_at, solve_at_unpacked
from .rayleigh import rayleigh_z
from .records import Params, Path
from .response import weighted_dispersion

NSUB = 4  # d Im z/ds of the path interpolant is sampled on NSUB sub-intervals of each path interval (local maxima)
MAX_MARGIN = 1e-6  # local maxima estimated within this x |z| of the best refined one are refined too
FALSE_POS_ITERS = 80  # Illinois steps on the interpolant's slope (superlinear: a bound, not a budget)
S_TOL_FP = 1e-12  # the interpolant's maximum is located to this in ln kH before the exact correction
S_TOL_MAX = 1e-9  # a Newton correction of the maximum's location below this is not taken (its effect is ~1e-18)
MAX_SHIFT = 0.1  # largest Newton correction of the maximum's location in ln kH (the local quadratic model's reach)
FLAT_ULPS = 4.0  # the corrected location is kept unless its Im z is lower by more than FLAT_ULPS eps |z|
S_TOL_CROSS = 1e-13  # relative location of a band end in ln kH
ILLINOIS = 0.5  # factor on the retained end's value in the Illinois variant of false position (superlinear)
ILLINOIS_ITERS = 100  # false-position iterations on the interpolant (superlinear: a bound, not a budget)
CROSS_ITERS = 8  # Newton in ln kH on exact roots from the false-position estimate (quadratic: a few steps)
CUT_LOSS = 1e-6  # eta = inf: a path lost with its last root this close (relative) below the cut left the sheet
SUBSONIC = 1.0  # finite eta: a root with |Re z| above this (the shear speed) lies among the lower block's poles ...
POLE_ATTENUATION = 1.0  # ... and is pole-dense where eta kH Re alpha_s (its decay across that block) is below this
ETA_FD = 1e-5  # step in ln eta of the central difference for dF/d ln eta (error ~1e-10 relative)

# verdict codes of growth_one (model.stability.VERDICT_STATUS): 0 stable, 1 unstable, the rest undetermined
V_STABLE = 0  # max growth < -its error on the whole kH range (where the branch exists), no pole-dense root
V_UNSTABLE = 1  # a certified root off the pole-dense region with Im z > its error
V_MASKED = 2  # the branch is lost on part of the range and the max growth on the rest is not > 0
V_NOBRANCH = 3  # no certified root anywhere on the range (no start, lost everywhere, or no convergence at the max)
V_POLE_DENSE = 4  # finite eta: the branch enters the lower block's poles (|Re z| > 1) and does not grow elsewhere
V_MARGINAL = 5  # |max growth| is not above its error estimate
NOUT = 12  # values growth_one returns per parameter set (rows of growth_many's output)


@jitted(inline="always")
def _im_in(s: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray, use_log: bool) -> float:
    """Im z of the interpolant of path interval j at s (Im e^w = e^Re w sin Im w where it interpolates w = ln z)."""
    w = interp_value(s, j, cx, cf, cm)
    return math.exp(w.real) * math.sin(w.imag) if use_log else w.imag


@jitted(inline="always")
def _im_at(s: float, ns: np.ndarray, nz: np.ndarray, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray, nn: int,
           use_log: bool) -> float:
    """Im z of the path interpolant at s (NaN outside the path); the path's fields unpacked (see Path)."""
    j = node_interval(s, ns, nn)
    if j < 0:
        return nz[0].imag if (nn == 1 and s == ns[0]) else math.nan
    return _im_in(s, j, cx, cf, cm, use_log)


@jitted
def _sample_at(s: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray,
               use_log: bool) -> tuple[complex, complex, complex]:
    """(z, dz/ds, d2z/ds2) of the path interpolant of interval j at s."""
    w, dw, d2w, _ = interp_node(s, j, cx, cf, cm)
    if use_log:
        z = cmath.exp(w)
        return z, dw * z, (d2w + dw * dw) * z
    return w, dw, d2w


@jitted(inline="always")
def _zslope_at(s: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray,
               use_log: bool) -> tuple[complex, complex]:
    """(z, dz/ds) of the path interpolant of interval j at s: Horner for the value and the first derivative only
    (the samples of _sample_path; at the interval's first node its stored value and slope)."""
    if s == cx[j, 0]:
        w, dw = cf[j, 0], cf[j, 1]
    else:
        m = cm[j]
        w = cf[j, m - 1]
        dw = 0j
        for k in range(m - 2, -1, -1):
            t = s - cx[j, k]
            dw = dw * t + w
            w = w * t + cf[j, k]
    if use_log:
        z = cmath.exp(w)
        return z, dw * z
    return w, dw


@jitted
def _pole_margin(z: complex, dz: complex, s: float, eta: float) -> tuple[float, float]:
    """(phi, dphi/ds): phi > 0 where the root z (slope dz at s = ln kH) is pole-dense (docs/physics.md §9).

    phi = min(|Re z| - SUBSONIC, 1 - eta kH Re(alpha_s) / POLE_ATTENUATION): finite eta, beyond the shear speed,
    and the lower block too thin to damp its thickness resonances (its real-axis poles). -1 for eta = inf.
    """
    if math.isinf(eta):
        return -1.0, 0.0
    a = abs(z.real) - SUBSONIC
    da = math.copysign(1.0, z.real) * dz.real
    alpha = csqrt(fix0((1.0 - z) * (1.0 + z)))
    q = math.exp(s)
    att = eta * q * alpha.real
    b = 1.0 - att / POLE_ATTENUATION
    if alpha == 0:
        return min(a, b), da
    datt = att + eta * q * (-z * cinv(alpha) * dz).real
    return (a, da) if a <= b else (b, -datt / POLE_ATTENUATION)


@jitted
def is_pole_dense(z: complex, s: float, eta: float) -> bool:
    """The root z at s = ln kH lies among the lower block's undamped real-axis poles (_pole_margin > 0)."""
    return _pole_margin(z, 0j, s, eta)[0] > 0.0


@jitted
def _sample_path(lo: float, hi: float, ns: np.ndarray, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray, nn: int,
                 use_log: bool, eta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The path interpolant on [lo, hi] (inside the path) at NSUB + 1 points of every path interval (ends shared).

    Returns (s, z, d Im z/ds, interval index, regular) of the samples; regular: not pole-dense (is_pole_dense).
    """
    j0 = node_interval(lo, ns, nn)
    j1 = node_interval(hi, ns, nn)
    if j1 > j0 and ns[j1] >= hi:
        j1 -= 1  # hi is a node: the interval ending there
    m = (j1 - j0 + 1) * NSUB + 1
    xs = np.empty(m)
    zs = np.empty(m, dtype=np.complex128)
    gs = np.empty(m)
    js = np.empty(m, dtype=np.int64)
    reg = np.empty(m, dtype=np.bool_)
    k = 0
    for j in range(j0, j1 + 1):
        a = max(ns[j], lo)
        b = min(ns[j + 1], hi)
        last = NSUB + 1 if j == j1 else NSUB
        for i in range(last):
            s = b if i == NSUB else a + (b - a) * (i / NSUB)
            z, dz = _zslope_at(s, j, cx, cf, cm, use_log)
            xs[k] = s
            zs[k] = z
            gs[k] = dz.imag
            js[k] = j
            reg[k] = not is_pole_dense(z, s, eta)
            k += 1
    return xs, zs, gs, js, reg


# kinds of candidate maxima (_candidates)
C_IN = 0  # between samples k and k+1
C_LEFT = 1  # at the left end of a regular run starting at sample k (the range's start, or a pole-dense boundary)
C_RIGHT = 2  # at the right end of a regular run ending at sample k


@jitted
def _candidates(xs: np.ndarray, zs: np.ndarray, gs: np.ndarray,
                reg: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Local maxima of Im z on the regular samples: (kind C_*, sample k, upper estimate) per candidate.

    Per run of regular samples: inside it, a bracket [k, k+1] with slope > 0 at k and <= 0 at k+1, estimated at
    most min(Im z_k + h g_k, Im z_k+1 - h g_k+1) (twice the triangle bound of a linear slope); at its ends, the
    range's end if Im z decreases into the run there, and always a boundary with the pole-dense part (which lies
    between the run's end sample and its neighbour: estimated Im z_k + 2 h |g_k|).
    """
    m = xs.shape[0]
    kind = np.empty(2 * m + 2, dtype=np.int64)
    ks = np.empty(2 * m + 2, dtype=np.int64)
    us = np.empty(2 * m + 2)
    c = 0
    k = 0
    while k < m:
        if not reg[k]:
            k += 1
            continue
        k0 = k
        while k + 1 < m and reg[k + 1]:
            k += 1
        k1 = k
        if k0 > 0 or gs[k0] <= 0.0:
            h = xs[k0] - xs[k0 - 1] if k0 > 0 else 0.0
            kind[c], ks[c], us[c] = C_LEFT, k0, zs[k0].imag + 2.0 * h * abs(gs[k0])
            c += 1
        for i in range(k0, k1):
            if gs[i] > 0.0 and gs[i + 1] <= 0.0:
                h = xs[i + 1] - xs[i]
                kind[c], ks[c], us[c] = C_IN, i, min(zs[i].imag + h * gs[i], zs[i + 1].imag - h * gs[i + 1])
                c += 1
        if k1 < m - 1 or gs[k1] > 0.0:
            h = xs[k1 + 1] - xs[k1] if k1 < m - 1 else 0.0
            kind[c], ks[c], us[c] = C_RIGHT, k1, zs[k1].imag + 2.0 * h * abs(gs[k1])
            c += 1
        k += 1
    return kind[:c], ks[:c], us[:c]


@jitted
def _slope_root(a: float, b: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray, use_log: bool) -> float:
    """Where d Im z/ds of the interpolant of interval j vanishes in [a, b] (positive at a, not at b): Illinois."""
    ga = _sample_at(a, j, cx, cf, cm, use_log)[1].imag
    gb = _sample_at(b, j, cx, cf, cm, use_log)[1].imag
    for _ in range(FALSE_POS_ITERS):
        if abs(b - a) <= S_TOL_FP or gb == ga:
            break
        c = b - gb * (b - a) / (gb - ga)
        gc = _sample_at(c, j, cx, cf, cm, use_log)[1].imag
        if gc == 0.0:
            return c
        if (gc > 0.0) == (gb > 0.0):
            ga *= ILLINOIS
        else:
            a, ga = b, gb
        b, gb = c, gc
    return b


@jitted
def _refine_peak(a: float, b: float, j: int, lo: float, hi: float, path: Path, p: Params,
                 rtol: float) -> tuple[float, float, complex, float]:
    """The local maximum of Im z in [a, b] (interval j; slope > 0 at a, <= 0 at b): (Im z, s, z, error of Im z).

    Located on the interpolant (Illinois on its slope, to S_TOL_FP), then the exact root there (solve_at) and one
    Newton correction of the location from the exact slope Im dz/ds and the interpolant's curvature (inside
    [lo, hi]); the larger of the two exact values is returned. NaN if the exact root is not certified.
    """
    ns, nz, nc, ne, cx, cf, cm, nn, use_log = path
    s0 = _slope_root(a, b, j, cx, cf, cm, use_log)
    z0, st, _, err0, dz0 = solve_at_unpacked(s0, ns, nz, nc, ne, cx, cf, cm, nn, use_log, p, rtol)
    if st != OK:
        return math.nan, math.nan, complex(math.nan, math.nan), math.nan
    d2 = _sample_at(s0, j, cx, cf, cm, use_log)[2].imag
    if d2 < 0.0 and cmath.isfinite(dz0):
        ds = -dz0.imag / d2
        if S_TOL_MAX < abs(ds) <= MAX_SHIFT and lo <= s0 + ds <= hi:
            z1, st1, _, err1, _ = solve_at_unpacked(s0 + ds, ns, nz, nc, ne, cx, cf, cm, nn, use_log, p, rtol)
            # the corrected location unless its value is lower beyond rounding (the maximum is flat)
            if st1 == OK and z1.imag >= z0.imag - FLAT_ULPS * EPS * abs(z0):
                if z1.imag >= z0.imag:
                    return z1.imag, s0 + ds, z1, err1
    return z0.imag, s0, z0, err0


@jitted
def _refine_candidate(kind: int, k: int, xs: np.ndarray, js: np.ndarray, path: Path, p: Params,
                      rtol: float) -> tuple[float, float, complex, float]:
    """The exact local maximum of a candidate of _candidates: (Im z, s, z, error); NaN if not certified.

    C_IN: _refine_peak. An end of a run: the exact root at the range's end, or at the exact boundary with the
    pole-dense part (_zero_on_path of _pole_margin between the run's end sample and its neighbour)."""
    m = xs.shape[0]
    nanr = (math.nan, math.nan, complex(math.nan, math.nan), math.nan)
    if kind == C_IN:
        return _refine_peak(xs[k], xs[k + 1], js[k], xs[0], xs[m - 1], path, p, rtol)
    s = xs[k]
    if kind == C_LEFT and k > 0:
        s = _zero_on_path(xs[k], xs[k - 1], Z_PD, path, p, rtol)
    elif kind == C_RIGHT and k < m - 1:
        s = _zero_on_path(xs[k], xs[k + 1], Z_PD, path, p, rtol)
    if math.isnan(s):
        return nanr
    z, st, _, err, _ = solve_at(s, path, p, rtol)
    if st != OK:
        return nanr
    return z.imag, s, z, err


@jitted
def _best_peak(xs: np.ndarray, zs: np.ndarray, gs: np.ndarray, js: np.ndarray, reg: np.ndarray, path: Path,
               p: Params, rtol: float) -> tuple[float, float, complex, float, int, int]:
    """The largest local maximum of Im z on the regular part of the samples' range: (Im z, s, z, error, kind, k).

    Candidates are refined in the order of their upper estimates until the next estimate lies below the best
    exact value (less MAX_MARGIN |z|): every local maximum that could be the largest is refined with exact roots.
    If one of them has no certified root, the growth is NaN (not a lower maximum's value); NaN also if no sample
    is regular.
    """
    kinds, ks, us = _candidates(xs, zs, gs, reg)
    nc = ks.shape[0]
    done = np.zeros(nc, dtype=np.bool_)
    best = (math.nan, math.nan, complex(math.nan, math.nan), math.nan)
    kbest = (-1, -1)
    for _ in range(nc):
        i = -1
        for c in range(nc):
            if not done[c] and (i < 0 or us[c] > us[i]):
                i = c
        if i < 0 or not (math.isnan(best[0]) or us[i] >= best[0] - MAX_MARGIN * abs(best[2])):
            break
        done[i] = True
        r = _refine_candidate(kinds[i], ks[i], xs, js, path, p, rtol)
        if math.isnan(r[0]):
            return math.nan, math.nan, complex(math.nan, math.nan), math.nan, -1, -1
        if math.isnan(best[0]) or r[0] > best[0]:
            best = r
            kbest = (kinds[i], ks[i])
    return best[0], best[1], best[2], best[3], kbest[0], kbest[1]


Z_IM = 0  # _zero_on_path: the zero of Im z (a band end) ...
Z_PD = 1  # ... or of _pole_margin (the boundary of the pole-dense part)


@jitted
def _on_path(s: float, which: int, ns: np.ndarray, nz: np.ndarray, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray,
             nn: int, use_log: bool, eta: float) -> float:
    """Im z (which = Z_IM) or _pole_margin (Z_PD) of the path interpolant at s (NaN outside the path)."""
    if which == Z_IM:
        return _im_at(s, ns, nz, cx, cf, cm, nn, use_log)
    j = node_interval(s, ns, nn)
    if j < 0:
        return math.nan
    z, dz, _ = _sample_at(s, j, cx, cf, cm, use_log)
    return _pole_margin(z, dz, s, eta)[0]


@jitted
def _zero_on_path(a: float, b: float, which: int, path: Path, p: Params, rtol: float) -> float:
    """s in [a, b] where Im z (which = Z_IM) or _pole_margin (Z_PD) vanishes (the interpolant's values at a and b
    have opposite signs), or NaN.

    Illinois false position on the interpolant, then Newton in s with the exact roots and slopes
    (solve_at) until the step is below S_TOL_CROSS (quadratic convergence: the last step's square
    is negligible). NaN if Newton leaves the bracket widened by its width or does not converge.
    """
    ns, nz, _, _, cx, cf, cm, nn, use_log = path  # unpacked once (see Path)
    fa = _on_path(a, which, ns, nz, cx, cf, cm, nn, use_log, p.eta)
    fb = _on_path(b, which, ns, nz, cx, cf, cm, nn, use_log, p.eta)
    if math.isnan(fa) or math.isnan(fb) or (fa > 0.0) == (fb > 0.0):
        return math.nan
    lo = min(a, b)
    hi = max(a, b)
    width = hi - lo
    for _ in range(ILLINOIS_ITERS):
        if abs(b - a) <= S_TOL_CROSS * max(1.0, abs(a)):
            break
        c = b - fb * (b - a) / (fb - fa)
        fc = _on_path(c, which, ns, nz, cx, cf, cm, nn, use_log, p.eta)
        if math.isnan(fc):
            return math.nan
        if fc == 0.0:
            b = c
            break
        if (fc > 0.0) == (fb > 0.0):
            fa *= ILLINOIS
        else:
            a, fa = b, fb
        b, fb = c, fc
    return _zero_newton(b, lo - width, hi + width, which, path, p, rtol)


@jitted
def _zero_newton(s: float, lo: float, hi: float, which: int, path: Path, p: Params, rtol: float) -> float:
    """Newton in s on exact roots from s for the zero of _zero_on_path (NaN if it leaves [lo, hi] or fails)."""
    for _ in range(CROSS_ITERS):
        z, st, _, err, dz = solve_at(s, path, p, rtol)
        if st != OK or not cmath.isfinite(dz):
            return math.nan
        if which == Z_IM:
            val, slope = z.imag, dz.imag
        else:
            val, slope = _pole_margin(z, dz, s, p.eta)
        if slope == 0.0:
            return math.nan
        ds = -val / slope
        s += ds
        if not (lo <= s <= hi):
            return math.nan
        if abs(ds) <= S_TOL_CROSS * max(1.0, abs(s)) or (rtol > 0.0 and err >= abs(val)):
            return s
    return math.nan


@jitted
def _band(s_max: float, g_max: float, kind: int, kbest: int, xs: np.ndarray, zs: np.ndarray, reg: np.ndarray,
          path: Path, p: Params, rtol: float) -> tuple[float, float]:
    """Ends (ln kH) of the unstable band around the maximum at s_max: the nearest zeros of Im z on either side
    (_zero_on_path between the samples, or between the last sample and s_max); NaN where Im z stays > 0 up to the
    end of the samples (the band runs past the kH grid or into the part where the branch is lost) or into the
    pole-dense part, or if g_max <= 0."""
    if not g_max > 0.0:
        return math.nan, math.nan
    m = xs.shape[0]
    # the last sample left of s_max and the first right of it
    k_l = kbest if kind == C_IN else (kbest - 1 if kind == C_LEFT else kbest)
    k_r = kbest + 1 if kind == C_IN else (kbest if kind == C_LEFT else kbest + 1)
    if kind == C_LEFT and xs[kbest] == s_max:
        k_r = kbest + 1
    if kind == C_RIGHT and xs[kbest] == s_max:
        k_l = kbest - 1
    i = k_l
    while i >= 0 and reg[i] and zs[i].imag > 0.0:
        i -= 1
    lo = math.nan
    if i >= 0 and reg[i]:
        lo = _zero_on_path(xs[i], s_max if i == k_l else xs[i + 1], Z_IM, path, p, rtol)
    i = k_r
    while i < m and reg[i] and zs[i].imag > 0.0:
        i += 1
    hi = math.nan
    if i < m and reg[i]:
        hi = _zero_on_path(xs[i], s_max if i == k_r else xs[i - 1], Z_IM, path, p, rtol)
    return lo, hi


@jitted
def _verdict(g: float, err: float, n_masked: int, pd: bool) -> int:
    """The verdict code (V_*) of a growth analysis (g: the max over the regular part): unstable if it exceeds its
    error; else undetermined where the branch enters the pole-dense part (V_POLE_DENSE), where it is not followed
    (V_NOBRANCH, V_MASKED) or where |growth| is within its error (V_MARGINAL); else stable."""
    if g > err:
        return V_UNSTABLE
    if pd:
        return V_POLE_DENSE
    if math.isnan(g):
        return V_NOBRANCH
    if n_masked > 0:
        return V_MASKED
    if abs(g) <= err:
        return V_MARGINAL
    return V_STABLE


@jitted
def _growth_slopes(z: complex, s: float, p: Params) -> tuple[float, float]:
    """(d Im z/d ln gamma, d Im z/d ln eta) of the root z at s = ln kH: Im(-F_t/F_z), which is the slope of the max
    growth in that parameter (the maximum's location may move, its value changes only through F). dF/d ln gamma =
    gamma (G_x + i f G_y); dF/d ln eta by central difference (ETA_FD); 0 for eta = inf."""
    q = math.exp(s)
    _, dfv, _, _ = weighted_dispersion(z, q, p.gamma, 1.0, p)
    fg = weighted_dispersion(z, q, p.gamma, 0.0, p)[0]
    if not (cmath.isfinite(dfv) and cmath.isfinite(fg)) or dfv == 0:
        return math.nan, math.nan
    inv = cinv(dfv)
    dg_gamma = (-fg * inv).imag
    if math.isinf(p.eta):
        return dg_gamma, 0.0
    up = Params(p.gamma, p.f, p.beta, p.eta * math.exp(ETA_FD), p.delta, p.xi)
    dn = Params(p.gamma, p.f, p.beta, p.eta * math.exp(-ETA_FD), p.delta, p.xi)
    fe = (weighted_dispersion(z, q, p.gamma, 1.0, up)[0] - weighted_dispersion(z, q, p.gamma, 1.0, dn)[0]) / (
        2.0 * ETA_FD)
    return dg_gamma, (-fe * inv).imag


@jitted
def _outside(s_grid: np.ndarray, ns: np.ndarray, nn: int) -> tuple[int, int]:
    """Grid points below and above the path's range [ns[0], ns[nn-1]] (masked: the branch was not followed there)."""
    below = 0
    above = 0
    for s in s_grid:
        if nn < 2 or s < ns[0]:
            below += 1
        elif s > ns[nn - 1]:
            above += 1
    return below, above


@jitted
def _lost_at_cut(z: complex, eta: float) -> bool:
    """eta = inf: the last root of a path lost downward lies on the cut's lower lip (|Re z| > 1, Im z < 0, |Im z| <=
    CUT_LOSS |z|): the branch leaves the physical sheet there (docs/physics.md §9), it does not become ambiguous."""
    return math.isinf(eta) and abs(z.real) > SUBSONIC and z.imag < 0.0 and -z.imag <= CUT_LOSS * abs(z)


@jitted
def growth_one(s_grid: np.ndarray, z_r: float, p: Params, rtol: float) -> tuple[float, float, float, float, float,
                                                                                float, float, float, float, float,
                                                                                float, float]:
    """Continuous max of Im z over the kH range of the grid on the Rayleigh branch, with the band and the verdict.

    Returns NOUT floats: (growth, s_at_max, s_band_lo, s_band_hi, n_masked, Re z at max, error of growth,
    verdict code V_*, d growth/d ln gamma, d growth/d ln eta, 1.0 if a sample of the range is pole-dense else 0.0,
    1.0 if the maximum is at an end of the followed part inside the range (where the branch is lost) or at a boundary
    of the pole-dense part, else 0.0: the maximum is then approached where the branch stops (being the Rayleigh
    mode), and its slopes are not those of the max growth).
    The maximum is taken over the range
    [s_grid[0], s_grid[-1]] where the branch is followed and is not pole-dense (for finite eta, |Re z| <= 1),
    between grid points too: the path interpolant's slope is sampled NSUB times per path interval and every local
    maximum that may be the largest is refined with exact roots (_best_peak), including the exact boundaries of the
    pole-dense part; so the growth is exact to rounding and depends on the grid's ends only (docs/physics.md §9).
    The grid's points decide only n_masked (points outside the followed part). The band: the zeros of Im z around
    the maximum (_band). The slopes are those of the max growth (envelope theorem; used to bracket thresholds).
    """
    m = s_grid.shape[0]
    nan = math.nan
    path, code = build_path(s_grid[0], s_grid[m - 1], z_r, p, PRED_TOL, map_node_tol(rtol))
    ns, nn = path.s, path.n
    below, above = (m, 0) if code != OK else _outside(s_grid, ns, nn)
    n_masked = below + above
    lo = max(s_grid[0], ns[0]) if nn >= 2 else 0.0
    hi = min(s_grid[m - 1], ns[nn - 1]) if nn >= 2 else -1.0
    if code != OK or nn < 2 or lo > hi:
        return nan, nan, nan, nan, float(n_masked), nan, nan, float(V_NOBRANCH), nan, nan, 0.0, 0.0
    xs, zs, gs, js, reg = _sample_path(lo, hi, ns, path.cx, path.cf, path.cm, nn, path.use_log, p.eta)
    g, s_max, z, err, kind, kbest = _best_peak(xs, zs, gs, js, reg, path, p, rtol)
    pd = 0.0 if np.all(reg) else 1.0
    # at a boundary with the pole-dense part the maximum is approached where the branch stops being the Rayleigh
    # mode; regular islands finer than the samples could lie beyond it: its error covers Im z's change to the
    # neighbouring sample
    m_s = xs.shape[0]
    pd_edge = (kind == C_LEFT and kbest > 0) or (kind == C_RIGHT and kbest < m_s - 1)
    if pd_edge and not math.isnan(g):
        err = max(err, abs(zs[kbest].imag - zs[kbest - 1 if kind == C_LEFT else kbest + 1].imag))
    # masked below the cut's end of the branch (eta = inf) leaves no undetermined part: the branch does not exist there
    unknown = above + (0 if (below > 0 and _lost_at_cut(path.z[0], p.eta)) else below)
    verdict = float(_verdict(g, err, unknown, pd > 0.0))
    if math.isnan(g):
        return nan, nan, nan, nan, float(n_masked), nan, nan, verdict, nan, nan, pd, 0.0
    b_lo, b_hi = _band(s_max, g, kind, kbest, xs, zs, reg, path, p, rtol)
    dg_gamma, dg_eta = _growth_slopes(z, s_max, p)
    lost_end = pd_edge or (s_max == lo and below > 0) or (s_max == hi and above > 0)
    return g, s_max, b_lo, b_hi, float(n_masked), z.real, err, verdict, dg_gamma, dg_eta, pd, 1.0 if lost_end else 0.0


@jitted
def growth_many(s_grid: np.ndarray, gamma: np.ndarray, f: np.ndarray, beta: np.ndarray, eta: np.ndarray,
                delta: np.ndarray, xi: np.ndarray, rtol: float, out: np.ndarray) -> None:
    """growth_one over flattened parameter sets (one chunk of a stability map); out: (NOUT, n)."""
    for i in range(gamma.shape[0]):
        p = Params(gamma[i], f[i], beta[i], eta[i], delta[i], xi[i])
        r = growth_one(s_grid, rayleigh_z(beta[i]), p, rtol)
        for k in range(NOUT):
            out[k, i] = r[k]


@jitted
def growth_point(s_grid: np.ndarray, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float,
                 rtol: float) -> tuple[float, float, float, float, float, float, float, float, float, float, float,
                                       float]:
    """growth_one for one parameter set given as scalars (the threshold solver's evaluations)."""
    return growth_one(s_grid, rayleigh_z(beta), Params(gamma, f, beta, eta, delta, xi), rtol)
