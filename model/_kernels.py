"""Compiled scalar kernels: response functions, dispersion relation and the Rayleigh-branch path.

Everything here works on plain Python/NumPy scalars inside ``numba.njit`` functions; the public,
validated, broadcasting API lives in the other modules of :mod:`model`.

Cancellation-free forms (PHYSICS.md section 2)
-------------------------------------------
Finite eta. With u_j = alpha_j^2 (u_s = 1 - z^2, u_d = 1 - beta^2 z^2) and g(u) = tanh(sqrt u)/sqrt u
(even in sqrt u, so no branch cut), write g1(u) = q g(q^2 u), g2(u) = eta q g(eta^2 q^2 u) and
P = g1 + g2, so that T1_j + T2_j = alpha_j P(u_j). Eq. S-G_gen becomes

    G_x = 4 (1 - beta^2) P[u_s, u_d] / (P_s P_d) + z^2 / (u_s P_s)
    G_y = 2 (2 - z^2) (1 - beta^2) (g1_s g2[u_s, u_d] - g2_s g1[u_s, u_d]) / (P_s P_d)

where h[u_s, u_d] is the divided difference (h(u_d) - h(u_s))/(u_d - u_s); u_d - u_s = (1-beta^2) z^2
cancelled the z^-2 prefactor analytically. Divided differences are computed without cancellation
(Taylor series for small arguments, tanh-difference identity for close large ones). G_y is exactly
0 for eta = 1.

Infinite eta (T2 = +1). With h_j = 1/(1 + tanh(q alpha_j)) = (1 + e^{-2 q alpha_j})/2 and the
Rayleigh function over z^2, Rt = z^2 - 4 + 4 (1 + beta^2 - beta^2 z^2)/(1 + alpha_s alpha_d):

    G_x = Rt h_s / alpha_s + 4 alpha_d Hd,      G_y = -2 (2 - z^2) Hd,
    Hd  = (h_s - h_d)/z^2 = q (1-beta^2) e^{-2 q alpha_s} psi(t) / (alpha_s + alpha_d),
    t   = -2 q (1-beta^2) z^2/(alpha_s + alpha_d),  psi(t) = expm1(t)/t.
"""

from __future__ import annotations

import cmath
import math
from fractions import Fraction

import numpy as np
from numba import njit

EPS = 2.220446049250313e-16


def _tanh_over_x_coefficients(n: int) -> np.ndarray:
    """Taylor coefficients a_k of tanh(x)/x = sum_k a_k x^(2k), from y' = 1 - y^2 in exact rationals."""
    t = [Fraction(1)]
    for k in range(1, n):
        acc = sum((t[i] * t[k - 1 - i] for i in range(k)), Fraction(0))
        t.append(-acc / (2 * k + 1))
    return np.array([float(c) for c in t])


_GCOEF = _tanh_over_x_coefficients(24)
_SERIES_U = 0.3  # |u| below which g(u) and its divided differences use the Taylor series


@njit(cache=True, inline="always")
def _fix0(u: complex) -> complex:
    """Turn a negative zero imaginary part into +0 (principal sqrt of a negative real -> +i)."""
    return complex(u.real, u.imag + 0.0)


@njit(cache=True)
def _tanh_sech(w: complex) -> tuple[complex, complex]:
    """tanh(w) and sech(w) without overflow for any w (exponentials of non-positive real part)."""
    s = 1.0 if w.real >= 0.0 else -1.0
    e = cmath.exp(-2.0 * s * w)
    den = 1.0 + e
    return s * (1.0 - e) / den, 2.0 * cmath.exp(-s * w) / den


@njit(cache=True)
def _g(u: complex) -> tuple[complex, complex]:
    """g(u) = tanh(sqrt u)/sqrt u and g'(u)."""
    if abs(u) < _SERIES_U:
        c = _GCOEF
        n = c.shape[0]
        val = c[n - 1] + 0j
        der = (n - 1) * c[n - 1] + 0j
        for k in range(n - 2, 0, -1):
            val = val * u + c[k]
            der = der * u + k * c[k]
        val = val * u + c[0]
        return val, der
    w = cmath.sqrt(u)
    th, sech = _tanh_sech(w)
    return th / w, (w * sech * sech - th) / (2.0 * w * u)


@njit(cache=True)
def _shc(d: complex) -> tuple[complex, complex]:
    """sinh(d)/d and its derivative for |d| < 0.5 by Taylor series."""
    d2 = d * d
    val = 0j
    der = 0j
    term = 1.0 + 0j  # d^(2k)/(2k+1)!
    for k in range(14):
        val += term
        if k > 0:
            der += 2 * k * term / d if d != 0 else 0j
        term = term * d2 / ((2 * k + 2) * (2 * k + 3))
    return val, der


@njit(cache=True)
def _divdiff(u1: complex, u2: complex) -> tuple[complex, complex, complex, complex, complex, complex, complex]:
    """g(u1), g'(u1), g(u2), g'(u2), g[u1,u2], d g[u1,u2]/du1, d g[u1,u2]/du2 without cancellation.

    Small arguments: Taylor series. Otherwise with w = sqrt(u) (the root of u2 nearest w1: g is even),
    D = g[u1, u2] = (w1 X/d - tanh w1) / (w1 w2 (w1 + w2)), d = w2 - w1, X = tanh w2 - tanh w1, where
    X/d = sinh(d)/d sech w1 sech w2 for |d| < 0.5 (no cancellation) and (tanh w2 - tanh w1)/d otherwise.
    """
    a1 = abs(u1)
    a2 = abs(u2)
    big = max(a1, a2)
    if big < _SERIES_U:
        g1, d1 = _g(u1)
        g2, d2 = _g(u2)
        c = _GCOEF
        n = c.shape[0]
        # h_m = sum_{k<m} u1^k u2^(m-1-k);  h_{m+1} = u2 h_m + u1^m
        h = 1.0 + 0j
        h1 = 0j  # dh/du1
        h2 = 0j  # dh/du2
        p = 1.0 + 0j  # u1^(m-1)
        dd = c[1] * h
        dd1 = 0j
        dd2 = 0j
        for m in range(1, n - 1):
            nh1 = u2 * h1 + m * p
            nh2 = h + u2 * h2
            p_next = p * u1
            h = u2 * h + p_next
            h1 = nh1
            h2 = nh2
            p = p_next
            dd += c[m + 1] * h
            dd1 += c[m + 1] * h1
            dd2 += c[m + 1] * h2
        return g1, d1, g2, d2, dd, dd1, dd2
    du = u2 - u1
    if abs(du) >= 0.5 * big:
        g1, d1 = _g(u1)
        g2, d2 = _g(u2)
        dd = (g2 - g1) / du
        return g1, d1, g2, d2, dd, (dd - d1) / du, (d2 - dd) / du
    w1 = cmath.sqrt(u1)
    w2 = cmath.sqrt(u2)
    if abs(w2 + w1) < abs(w2 - w1):  # g is even: take the square root nearest w1
        w2 = -w2
    th1, s1 = _tanh_sech(w1)
    th2, s2 = _tanh_sech(w2)
    g1 = th1 / w1
    g2 = th2 / w2
    d1 = (w1 * s1 * s1 - th1) / (2.0 * w1 * u1)
    d2 = (w2 * s2 * s2 - th2) / (2.0 * w2 * u2)
    d = w2 - w1
    if abs(d) < 0.5:
        sh, dsh = _shc(d)
        xd = sh * s1 * s2
        dxd2 = dsh * s1 * s2 - xd * th2
        dxd1 = -dsh * s1 * s2 - xd * th1
    else:
        xd = (th2 - th1) / d
        dxd2 = (s2 * s2 - xd) / d
        dxd1 = (xd - s1 * s1) / d
    num = w1 * xd - th1
    inv_den = 1.0 / (w1 * w2 * (w1 + w2))
    dd = num * inv_den
    dd_dw2 = (w1 * dxd2 - dd * w1 * (w1 + 2.0 * w2)) * inv_den
    dd_dw1 = (xd + w1 * dxd1 - s1 * s1 - dd * w2 * (2.0 * w1 + w2)) * inv_den
    return g1, d1, g2, d2, dd, dd_dw1 / (2.0 * w1), dd_dw2 / (2.0 * w2)


@njit(cache=True)
def _psi(t: complex) -> tuple[complex, complex]:
    """psi(t) = expm1(t)/t and psi'(t) for |t| < 0.5 (Taylor series)."""
    val = 0j
    der = 0j
    term = 1.0 + 0j  # t^k/(k+1)!
    for k in range(20):
        val += term
        if k > 0:
            der += k * term / t if t != 0 else 0j
        term = term * t / (k + 2)
    if t == 0:
        der = 0.5 + 0j
    return val, der


@njit(cache=True, inline="always")
def _abs1(w: complex) -> float:
    """|Re w| + |Im w|: a cheap magnitude (within sqrt 2 of |w|) for rounding scales."""
    return abs(w.real) + abs(w.imag)


@njit(cache=True)
def response_inf(z: complex, q: float, beta: float) -> tuple[complex, complex, complex, complex, float]:
    """G_x, G_y, dG_x/dz, dG_y/dz and a rounding scale for eta = inf (Eqs. Gx_LSA, Gy_LSA)."""
    b2 = beta * beta
    z2 = z * z
    us = _fix0((1.0 - z) * (1.0 + z))
    ud = _fix0((1.0 - beta * z) * (1.0 + beta * z))
    a_s = cmath.sqrt(us)
    a_d = cmath.sqrt(ud)
    inv_as = 1.0 / a_s
    inv_ad = 1.0 / a_d
    das = -z * inv_as
    dad = -b2 * z * inv_ad
    es = cmath.exp(-2.0 * q * a_s)
    ed = cmath.exp(-2.0 * q * a_d)
    des = -2.0 * q * das * es
    ded = -2.0 * q * dad * ed
    hs = 0.5 * (1.0 + es)
    dhs = 0.5 * des
    # Rayleigh function over z^2
    inv_one = 1.0 / (1.0 + a_s * a_d)
    cnum = 1.0 + b2 - b2 * z2
    c4 = 4.0 * cnum * inv_one
    rt = z2 - 4.0 + c4
    dprod = das * a_d + a_s * dad
    drt = 2.0 * z + 4.0 * (-2.0 * b2 * z - cnum * dprod * inv_one) * inv_one
    # Hd = (h_s - h_d)/z^2
    inv_sum = 1.0 / (a_s + a_d)
    dssum = das + dad
    k = -2.0 * q * (1.0 - b2)
    t = k * z2 * inv_sum
    dt = k * (2.0 * z - z2 * dssum * inv_sum) * inv_sum
    if _abs1(t) < 0.5:
        ps, dps = _psi(t)
        qv = es * ps
        dqv = des * ps + es * dps * dt
    else:
        inv_t = 1.0 / t
        qv = (ed - es) * inv_t
        dqv = ((ded - des) - qv * dt) * inv_t
    c = q * (1.0 - b2)
    hd = c * qv * inv_sum
    dhd = c * (dqv - qv * dssum * inv_sum) * inv_sum
    hs_as = hs * inv_as
    gx_a = rt * hs_as
    gx_b = 4.0 * a_d * hd
    gx = gx_a + gx_b
    dgx = (drt * hs + rt * dhs) * inv_as - gx_a * das * inv_as + 4.0 * (dad * hd + a_d * dhd)
    gy = -2.0 * (2.0 - z2) * hd
    dgy = -2.0 * (-2.0 * z * hd + (2.0 - z2) * dhd)
    scale = (_abs1(z2) + 4.0 + _abs1(c4)) * _abs1(hs_as) + _abs1(gx_b)
    return gx, gy, dgx, dgy, scale


@njit(cache=True)
def response_fin(
    z: complex, q: float, beta: float, eta: float
) -> tuple[complex, complex, complex, complex, float]:
    """G_x, G_y, dG_x/dz, dG_y/dz and a rounding scale for finite eta (Eq. Gs_general)."""
    b2 = beta * beta
    z2 = z * z
    us = _fix0((1.0 - z) * (1.0 + z))
    ud = _fix0((1.0 - beta * z) * (1.0 + beta * z))
    dus = -2.0 * z
    dud = -2.0 * b2 * z
    a = q * q
    eq = eta * q
    b = eq * eq
    # upper block, height H: g1 = q g(q^2 u)
    gs, gds, gd, gdd, dd, dd1, dd2 = _divdiff(a * us, a * ud)
    q3 = q * a
    q5 = q3 * a
    g1s = q * gs
    g1d = q * gd
    dg1s = q3 * gds * dus
    dg1d = q3 * gdd * dud
    d1 = q3 * dd
    dd1z = q5 * (dd1 * dus + dd2 * dud)
    # lower block, height eta H: g2 = eta q g(eta^2 q^2 u)
    hs, hds, hd, hdd, ee, ee1, ee2 = _divdiff(b * us, b * ud)
    e3 = eq * b
    e5 = e3 * b
    g2s = eq * hs
    g2d = eq * hd
    dg2s = e3 * hds * dus
    dg2d = e3 * hdd * dud
    d2 = e3 * ee
    dd2z = e5 * (ee1 * dus + ee2 * dud)
    ps = g1s + g2s
    pd = g1d + g2d
    dps = dg1s + dg2s
    dpd = dg1d + dg2d
    pdd = d1 + d2
    dpdd = dd1z + dd2z
    c = 1.0 - b2
    pp = ps * pd
    dpp_pp = dps / ps + dpd / pd
    gx_a = 4.0 * c * pdd / pp
    gx_b = z2 / (us * ps)
    gx = gx_a + gx_b
    dgx = 4.0 * c * (dpdd / pp - pdd * dpp_pp / pp) + (2.0 * z - z2 * (dus / us + dps / ps)) / (us * ps)
    kk = (g1s * d2 - g2s * d1) / pp
    dkk = (dg1s * d2 + g1s * dd2z - dg2s * d1 - g2s * dd1z) / pp - kk * dpp_pp
    gy = 2.0 * (2.0 - z2) * c * kk
    dgy = 2.0 * c * (-2.0 * z * kk + (2.0 - z2) * dkk)
    scale = abs(gx_a) + abs(gx_b) + 2.0 * abs(2.0 - z2) * c * (abs(g1s * d2) + abs(g2s * d1)) / abs(pp)
    return gx, gy, dgx, dgy, scale


@njit(cache=True)
def response(z: complex, q: float, beta: float, eta: float) -> tuple[complex, complex, complex, complex, float]:
    """Dispatch on eta (inf -> half-space lower block)."""
    if math.isinf(eta):
        return response_inf(z, q, beta)
    return response_fin(z, q, beta, eta)


@njit(cache=True)
def _weighted_dispersion(z, q, wg, wz, f, beta, eta, delta, xi):
    """wg (G_x + i f G_y) + wz i z S with S = 1 + (Delta - 1)/(1 - i xi z kH), its z-derivative and rounding scale.

    The rounding scale is the sum of the magnitudes of the terms plus |z F'| (the change of F under a
    relative perturbation of z by one unit: no evaluation can resolve F below eps times this).
    """
    gx, gy, dgx, dgy, sc = response(z, q, beta, eta)
    if delta == 1.0:
        sf = 1.0 + 0j
        dsf = 0j
        sabs = 1.0
    else:
        inv_den = 1.0 / (1.0 - 1j * xi * z * q)
        sf = 1.0 + (delta - 1.0) * inv_den
        dsf = (delta - 1.0) * (1j * xi * q) * inv_den * inv_den
        sabs = 1.0 + _abs1((delta - 1.0) * inv_den)
    fval = wg * (gx + 1j * f * gy) + wz * 1j * z * sf
    dfval = wg * (dgx + 1j * f * dgy) + wz * 1j * (sf + z * dsf)
    scale = wg * (sc + _abs1(f * gy)) + wz * _abs1(z) * sabs + _abs1(z * dfval)
    return fval, dfval, scale


@njit(cache=True)
def dispersion_eval(
    z: complex, q: float, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float
) -> tuple[complex, complex, float]:
    """F(z; q) of Eq. implicit_spectrum with Eq. delta f RSF, dF/dz, and the rounding scale of F."""
    return _weighted_dispersion(z, q, gamma, 1.0, f, beta, eta, delta, xi)


# ---------------------------------------------------------------------------------------------
# Rayleigh-branch continuation (PHYSICS.md section 3)
# ---------------------------------------------------------------------------------------------

OK = 0
LOST = 1  # the branch could not be followed down to this kH (collision / ill-conditioning)
NOCONV = 2  # Newton did not converge at this kH although the path reached it
START = 3  # the starting root at kH = 1e4 could not be found
INPUT = 4  # the parameters themselves were NaN

S_TOP = math.log(1e4)
H_MAX = 0.4  # largest continuation step in ln(kH)
H_MIN = 1e-7
PRED_TOL = 1e-3  # target predictor error per step, relative to _local_scale
PRED_REJECT = 1e-2  # predictor error (relative to _local_scale) above which a step is rejected
THETA_MAX = 0.1  # largest first Newton contraction rate accepted (basin certificate, see _newton)
MAX_NODES = 8192


@njit(cache=True)
def _eval_mode(z, s, mode, q, gamma, f, beta, eta, delta, xi):
    """F along a continuation path: mode 0 varies ln kH = s; mode 1 varies tau = 1/gamma = s at fixed kH = q.

    Mode 1 evaluates F/gamma = G_x + i f G_y + tau i z S, which is linear in tau and finite at
    tau = 0 (gamma = inf), where its root is the Rayleigh root of the large-kH response.
    """
    if mode == 0:
        return dispersion_eval(z, math.exp(s), gamma, f, beta, eta, delta, xi)
    return _weighted_dispersion(z, q, 1.0, s, f, beta, eta, delta, xi)


@njit(cache=True)
def _newton(z0, s, mode, q, gamma, f, beta, eta, delta, xi, maxit):
    """Newton's method with contraction safeguards.

    Returns (z, converged, iterations, |first step|, |F|/scale, estimated error of z, theta) where
    theta = |second step| / |first step| is the first contraction rate (0 if converged at once).
    A small theta certifies that z0 was well inside the quadratic basin of the root found: with two
    roots a distance d apart, theta ~ |z0 - z|/d, so theta <= 0.1 rules out starting nearer the
    other root. Converged means the last step was below max(1e-14 |z|, rounding-level noise), or
    quadratic convergence predicts the remaining error below 2.5e-17 |z|.
    """
    z = z0
    prev = math.inf
    first = 0.0
    theta = 0.0
    for it in range(maxit):
        fv, dfv, sc = _eval_mode(z, s, mode, q, gamma, f, beta, eta, delta, xi)
        if not (cmath.isfinite(fv) and cmath.isfinite(dfv)) or dfv == 0:
            return z, False, it, first, math.inf, math.inf, math.inf
        step = fv / dfv
        a = abs(step)
        if it == 0:
            first = a
        elif it == 1 and first > 0.0:
            theta = a / first
        noise = 8.0 * EPS * sc / abs(dfv)
        z = z - step
        az = max(abs(z), 1e-300)
        if a <= max(1e-14 * az, noise):
            return z, True, it + 1, first, abs(fv) / sc, noise + a * a / az, theta
        if it >= 1 and a < 1e-4 * az and a < 0.1 * prev:
            # quadratic convergence: error after this step ~ C a^2 with C ~ a/prev^2
            rest = a * a * a / (prev * prev)
            if rest <= 0.25e-16 * az:
                return z, True, it + 1, first, (rest / az) * abs(dfv) * az / sc, noise + rest, theta
        if it >= 1 and a > 0.5 * prev:
            return z, False, it + 1, first, abs(fv) / sc, math.inf, theta
        prev = a
    return z, False, maxit, first, math.inf, math.inf, theta


@njit(cache=True)
def _log_nodes(zs):
    """ln z of path nodes with the phase unwrapped along the path (None-safe: z = 0 -> -inf)."""
    m = zs.shape[0]
    lz = np.empty(m, dtype=np.complex128)
    for i in range(m):
        lz[i] = cmath.log(zs[i])
        if i > 0:
            d = lz[i].imag - lz[i - 1].imag
            k = math.floor(d / (2.0 * math.pi) + 0.5)
            lz[i] = complex(lz[i].real, lz[i].imag - 2.0 * math.pi * k)
    return lz


@njit(cache=True)
def _lagrange(ss, zs, s):
    """Lagrange interpolation/extrapolation in s of ln z through the given nodes (exact for power laws)."""
    m = ss.shape[0]
    for i in range(m):
        if zs[i] == 0:
            return zs[m - 1]
    return _lagrange_log(ss, _log_nodes(zs), s)


@njit(cache=True)
def _lagrange_log(ss, lz, s):
    """exp of the Lagrange interpolant in s of the (unwrapped) logarithms lz."""
    m = ss.shape[0]
    acc = 0j
    for i in range(m):
        li = 1.0
        for j in range(m):
            if j != i:
                li *= (s - ss[j]) / (ss[i] - ss[j])
        acc += li * lz[i]
    return cmath.exp(acc)


@njit(cache=True)
def _local_scale(z):
    """Radius on which the root can move smoothly: min(|z|, distance to the real-axis singularities |Re z| >= 1).

    Poles (finite eta) and branch cuts (eta = inf) of F lie on the real axis with |z| >= 1 only
    (PHYSICS.md section 2), so predictor errors are measured against this distance.
    """
    x = abs(z.real)
    d = abs(z.imag) if x >= 1.0 else math.hypot(1.0 - x, z.imag)
    return max(min(abs(z), d), 1e-12)


@njit(cache=True, inline="always")
def _predict_log(ss, lz, n, s):
    """exp of the Lagrange extrapolant in s of ln z through the last min(n, 3) nodes (ring buffer lz)."""
    k = min(n, 3)
    acc = 0j
    for a in range(n - k, n):
        la = 1.0
        for b in range(n - k, n):
            if b != a:
                la *= (s - ss[b]) / (ss[a] - ss[b])
        acc += la * lz[a % 3]
    return cmath.exp(acc)


@njit(cache=True, nogil=True)
def _continue(z0, s0, s_stop, extra, direction, mode, q, gamma, f, beta, eta, delta, xi, out_s, out_z, out_c, targets):
    """Adaptive predictor-corrector continuation of one root in s from s0 towards s_stop.

    Nodes are written to out_s/out_z (node 0 = start); continues until `extra` nodes lie beyond
    s_stop (or, if extra == 0, stops exactly at s_stop). With an empty `targets` the sequence of
    nodes depends only on the start and the physical parameters, never on s_stop, except for where
    it is cut off. `targets` (in the direction of travel) are s values the path must land on
    exactly (steps are shortened to hit them), for grid-following continuation.
    out_c receives the quadratic-convergence constant C = |step 2|/|step 1|^2 observed at each node
    (0 where Newton converged at once). Returns (number of nodes, lost flag).
    """
    out_s[0] = s0
    out_z[0] = z0
    out_c[0] = 0.0
    lz = np.empty(3, dtype=np.complex128)  # unwrapped ln z of the last three nodes (ring buffer)
    lz_ok = z0 != 0
    if lz_ok:
        lz[0] = cmath.log(z0)
    n = 1
    h = 0.05 if mode == 0 else 0.25 * abs(s_stop - s0)
    h_cap = H_MAX if mode == 0 else abs(s_stop - s0)
    beyond = 0
    kt = 0
    nt = targets.shape[0]
    while kt < nt and direction * (targets[kt] - s0) <= 0.0:
        kt += 1
    while True:
        s_cur = out_s[n - 1]
        if extra == 0:
            if direction * (s_stop - s_cur) <= 0.0:
                return n, False
            h_try = min(h, direction * (s_stop - s_cur))
        else:
            if beyond >= extra:
                return n, False
            h_try = h
        if n >= out_s.shape[0]:
            return n, True
        accepted = False
        while not accepted:
            if h_try < H_MIN:
                return n, True
            landing = kt < nt and h_try >= direction * (targets[kt] - s_cur)
            if landing:
                h_try = direction * (targets[kt] - s_cur)
                s_new = targets[kt]
            else:
                s_new = s_cur + direction * h_try
            zp = _predict_log(out_s, lz, n, s_new) if lz_ok else _lagrange(out_s[max(0, n - 3) : n],
                                                                             out_z[max(0, n - 3) : n], s_new)
            z, ok, its, first, _, _, theta = _newton(zp, s_new, mode, q, gamma, f, beta, eta, delta, xi, 6)
            err = abs(z - zp) / _local_scale(z)
            if ok and its <= 5 and err <= PRED_REJECT and theta <= THETA_MAX:
                accepted = True
                out_s[n] = s_new
                out_z[n] = z
                out_c[n] = theta / first if (first > 0.0 and theta > 0.0) else 0.0
                if z == 0:
                    lz_ok = False
                else:
                    lnew = cmath.log(z)
                    kk = math.floor((lnew.imag - lz[(n - 1) % 3].imag) / (2.0 * math.pi) + 0.5)
                    lz[n % 3] = complex(lnew.real, lnew.imag - 2.0 * math.pi * kk)
                n += 1
                if landing:
                    kt += 1
                if extra > 0 and direction * (s_new - s_stop) > 0.0:
                    beyond += 1
                # step-size control (third-order predictor error once 3 nodes exist)
                fac = 2.0 if err == 0.0 else 0.9 * (PRED_TOL / err) ** (1.0 / 3.0)
                fac = min(2.0, max(0.5, fac))
                if not (landing and fac >= 1.0):  # a step shortened to land on a target keeps h
                    h = min(h_cap, h_try * fac)
            else:
                h_try *= 0.5
                h = h_try


@njit(cache=True)
def rayleigh_start(z_r, gamma, f, beta, eta, delta, xi):
    """The Rayleigh-branch root at kH = 1e4: homotopy in tau = 1/gamma from tau = 0 (gamma = inf, where
    the root is the Rayleigh root of the large-kH response, found by Newton from z_R) to 1/gamma."""
    q = math.exp(S_TOP)
    work_s = np.empty(4096)
    work_z = np.empty(4096, dtype=np.complex128)
    work_c = np.empty(4096)
    z, ok, _, _, _, _, _ = _newton(z_r + 0j, 0.0, 1, q, gamma, f, beta, eta, delta, xi, 20)
    if not ok:
        return z, False
    n, lost = _continue(z, 0.0, 1.0 / gamma, 0, 1.0, 1, q, gamma, f, beta, eta, delta, xi, work_s, work_z,
                        work_c, np.empty(0))
    if lost:
        return work_z[n - 1], False
    return work_z[n - 1], True


@njit(cache=True, nogil=True)
def build_path(s_lo, s_hi, z_r, gamma, f, beta, eta, delta, xi, grid):
    """Rayleigh-branch path nodes covering [s_lo, s_hi] (s = ln kH), ascending in s.

    Start at ln 1e4 (see rayleigh_start), continue down to two nodes below min(s_lo, ln 1e4) and up to
    two nodes above max(s_hi, ln 1e4). The node sequence depends only on the physical parameters;
    s_lo/s_hi only decide where it is cut off. Returns (ns, nz, lnz, nc, nn, has_zero, code) with code
    OK, START (no starting root) or INPUT (NaN parameter); lnz = unwrapped ln z of the nodes.
    `grid` (ascending, may be empty) are s values the path must land on exactly (see _continue).
    """
    ns = np.empty(1)
    nz = np.empty(1, dtype=np.complex128)
    for v in (gamma, f, beta, eta, delta, xi):
        if math.isnan(v):
            return ns, nz, nz, ns, 0, False, INPUT
    z0, ok = rayleigh_start(z_r, gamma, f, beta, eta, delta, xi)
    if not ok:
        return ns, nz, nz, ns, 0, False, START
    dn_s = np.empty(MAX_NODES)
    dn_z = np.empty(MAX_NODES, dtype=np.complex128)
    up_s = np.empty(MAX_NODES)
    up_z = np.empty(MAX_NODES, dtype=np.complex128)
    dn_c = np.empty(MAX_NODES)
    up_c = np.empty(MAX_NODES)
    down = grid[::-1].copy()
    nd, _ = _continue(z0, S_TOP, min(s_lo, S_TOP), 2, -1.0, 0, 1.0, gamma, f, beta, eta, delta, xi,
                      dn_s, dn_z, dn_c, down)
    nu, _ = _continue(z0, S_TOP, max(s_hi, S_TOP), 2, 1.0, 0, 1.0, gamma, f, beta, eta, delta, xi,
                      up_s, up_z, up_c, grid)
    nn = nd + nu - 1
    ns = np.empty(nn)
    nz = np.empty(nn, dtype=np.complex128)
    nc = np.empty(nn)
    for i in range(nd):
        ns[i] = dn_s[nd - 1 - i]
        nz[i] = dn_z[nd - 1 - i]
        nc[i] = dn_c[nd - 1 - i]
    for i in range(1, nu):
        ns[nd - 1 + i] = up_s[i]
        nz[nd - 1 + i] = up_z[i]
        nc[nd - 1 + i] = up_c[i]
    has_zero = False
    for i in range(nn):
        has_zero = has_zero or nz[i] == 0
    return ns, nz, _log_nodes(nz), nc, nn, has_zero, OK


@njit(cache=True, nogil=True)
def solve_at(s, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi):
    """The Rayleigh-branch root at s = ln kH from the path nodes: (z, status, residual, error).

    Newton from the cubic interpolant (in ln z) of the four surrounding nodes; accepted only with a
    strong first contraction and a small distance from the prediction (else NOCONV); outside the
    nodes' range the branch was lost (LOST).
    """
    nanz = complex(math.nan, math.nan)
    if nn == 0 or s < ns[0] or s > ns[nn - 1]:
        return nanz, LOST, math.nan, math.nan
    j = np.searchsorted(ns, s, side="right") - 1  # ns[j] <= s
    lo = max(0, j - 1)
    hi = min(nn, j + 3)
    zp = _lagrange(ns[lo:hi], nz[lo:hi], s) if has_zero else _lagrange_log(ns[lo:hi], lnz[lo:hi], s)
    # One Newton step from the interpolant. The quadratic-convergence constant C was measured at the
    # surrounding path nodes (whose steps passed the contraction certificate with larger predictor
    # errors); if 10 C |step|^2 is below rounding, the stepped point is accepted without a second
    # evaluation (error estimate noise + 10 C |step|^2). Otherwise Newton continues as usual.
    c_loc = 0.0
    for i in range(lo, hi):
        c_loc = max(c_loc, nc[i])
    fv, dfv, sc = dispersion_eval(zp, math.exp(s), gamma, f, beta, eta, delta, xi)
    if cmath.isfinite(fv) and cmath.isfinite(dfv) and dfv != 0 and c_loc > 0.0:
        step = fv / dfv
        a = abs(step)
        z1 = zp - step
        az = abs(z1)
        rest = 10.0 * c_loc * a * a
        noise = 8.0 * EPS * sc / abs(dfv)
        if (a <= 1e-14 * az or rest <= 0.25e-16 * az) and a <= 1e-6 * _local_scale(z1):
            return z1, OK, abs(fv) / sc * (rest + noise) / max(a, 1e-300), noise + rest
        # continue Newton from the stepped point; the first contraction rate is |step 2| / |step 1|
        z, ok, _, second, rr, ee, _ = _newton(z1, s, 0, 1.0, gamma, f, beta, eta, delta, xi, 9)
        theta = second / a if a > 0.0 else 0.0
    else:
        z, ok, _, _, rr, ee, theta = _newton(zp, s, 0, 1.0, gamma, f, beta, eta, delta, xi, 10)
    if ok and abs(z - zp) <= PRED_REJECT * _local_scale(z) and theta <= THETA_MAX:
        return z, OK, rr, ee
    return nanz, NOCONV, math.nan, math.nan


@njit(cache=True, nogil=True)
def branch_solve(s_req, z_r, gamma, f, beta, eta, delta, xi, z_out, status, resid, err):
    """Rayleigh-branch roots at the requested s = ln kH values for one parameter set.

    Each requested point is reached from the interpolated path nodes by Newton's method
    (solve_at), so its digits do not depend on the other requests.
    """
    m = s_req.shape[0]
    if m == 0:
        return
    ns, nz, lnz, nc, nn, has_zero, code = build_path(s_req.min(), s_req.max(), z_r, gamma, f, beta, eta, delta, xi,
                                                 np.empty(0))
    for i in range(m):
        if code != OK:
            z_out[i] = complex(math.nan, math.nan)
            status[i] = code
            resid[i] = math.nan
            err[i] = math.nan
            continue
        z_out[i], status[i], resid[i], err[i] = solve_at(s_req[i], ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta,
                                                         delta, xi)


GOLDEN = 0.3819660112501051


@njit(cache=True, nogil=True)
def _im_at(s, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi):
    z, st, _, _ = solve_at(s, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
    return z.imag if st == OK else math.nan


@njit(cache=True, nogil=True)
def _crossing(a, fa, b, fb, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi):
    """s in [a, b] where Im z(s) = 0: Illinois false position to 1e-13 (end values re-evaluated exactly)."""
    fa = _im_at(a, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
    fb = _im_at(b, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
    if math.isnan(fa) or math.isnan(fb) or (fa > 0.0) == (fb > 0.0):
        return math.nan
    for _ in range(200):
        if abs(b - a) <= 1e-13 * max(1.0, abs(a)):
            break
        c = b - fb * (b - a) / (fb - fa)
        fc = _im_at(c, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
        if math.isnan(fc):
            return math.nan
        if fc == 0.0:
            return c
        if (fc > 0.0) == (fb > 0.0):
            fa *= 0.5
        else:
            a, fa = b, fb
        b, fb = c, fc
    return 0.5 * (a + b) if abs(fb) > abs(fa) else b


@njit(cache=True, nogil=True)
def growth_one(s_grid, z_r, gamma, f, beta, eta, delta, xi):
    """Max of Im z over kH on the Rayleigh branch, refined between grid points, and the unstable band.

    Returns (growth, s_at_max, s_band_lo, s_band_hi, n_masked). The maximum over the grid is refined
    by golden-section search on the two neighbouring grid intervals (location to 1e-9 in ln kH, so the
    value is exact to rounding); the band is the interval around the maximum where Im z > 0, with both
    ends refined by false position (NaN where Im z stays positive up to the end of the grid or where
    the growth is not positive).
    """
    m = s_grid.shape[0]
    ns, nz, lnz, nc, nn, has_zero, code = build_path(s_grid[0], s_grid[m - 1], z_r, gamma, f, beta, eta, delta, xi,
                                                 np.empty(0))
    if code != OK:
        return math.nan, math.nan, math.nan, math.nan, m
    # Im z on the grid from the path interpolant (relative error ~1e-8): it only brackets the maximum
    # and the band ends, which are then computed from converged roots (solve_at)
    im = np.empty(m)
    n_masked = 0
    best = -1
    for i in range(m):
        si = s_grid[i]
        if nn == 0 or si < ns[0] or si > ns[nn - 1]:
            im[i] = math.nan
        else:
            j = np.searchsorted(ns, si, side="right") - 1
            lo_ = max(0, j - 1)
            hi_ = min(nn, j + 3)
            zp = _lagrange(ns[lo_:hi_], nz[lo_:hi_], si) if has_zero else _lagrange_log(ns[lo_:hi_], lnz[lo_:hi_], si)
            im[i] = zp.imag
        if math.isnan(im[i]):
            n_masked += 1
        elif best < 0 or im[i] > im[best]:
            best = i
    if best < 0:
        return math.nan, math.nan, math.nan, math.nan, n_masked
    # golden-section refinement on [s_{best-1}, s_{best+1}] (valid neighbours only)
    a = s_grid[best - 1] if best > 0 and not math.isnan(im[best - 1]) else s_grid[best]
    b = s_grid[best + 1] if best < m - 1 and not math.isnan(im[best + 1]) else s_grid[best]
    s_max = s_grid[best]
    g_max = _im_at(s_max, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
    if math.isnan(g_max):
        return math.nan, math.nan, math.nan, math.nan, n_masked
    if b > a:
        x1 = a + GOLDEN * (b - a)
        x2 = b - GOLDEN * (b - a)
        f1 = _im_at(x1, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
        f2 = _im_at(x2, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
        for _ in range(60):
            if b - a <= 1e-9 or math.isnan(f1) or math.isnan(f2):
                break
            if f1 >= f2:
                b, x2, f2 = x2, x1, f1
                x1 = a + GOLDEN * (b - a)
                f1 = _im_at(x1, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
            else:
                a, x1, f1 = x1, x2, f2
                x2 = b - GOLDEN * (b - a)
                f2 = _im_at(x2, ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
        for sx, fx in ((x1, f1), (x2, f2)):
            if not math.isnan(fx) and fx > g_max:
                g_max = fx
                s_max = sx
    lo = math.nan
    hi = math.nan
    if g_max > 0.0:
        i = best
        while i > 0 and not math.isnan(im[i - 1]) and im[i - 1] > 0.0:
            i -= 1
        if i > 0 and not math.isnan(im[i - 1]):
            lo = _crossing(s_grid[i - 1], im[i - 1], s_grid[i], im[i],
                           ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
        i = best
        while i < m - 1 and not math.isnan(im[i + 1]) and im[i + 1] > 0.0:
            i += 1
        if i < m - 1 and not math.isnan(im[i + 1]):
            hi = _crossing(s_grid[i + 1], im[i + 1], s_grid[i], im[i],
                           ns, nz, lnz, nc, nn, has_zero, gamma, f, beta, eta, delta, xi)
    return g_max, s_max, lo, hi, n_masked


@njit(cache=True, nogil=True)
def growth_many(s_grid, gamma, f, beta, eta, delta, xi, g_out, s_out, lo_out, hi_out, nm_out):
    """growth_one over flattened parameter sets (one chunk of a stability map)."""
    for p in range(gamma.shape[0]):
        g_out[p], s_out[p], lo_out[p], hi_out[p], nm_out[p] = growth_one(
            s_grid, rayleigh_z(beta[p]), gamma[p], f[p], beta[p], eta[p], delta[p], xi[p]
        )


@njit(cache=True)
def rayleigh_z(beta):
    """z_R(beta): Newton on the Rayleigh cubic in x = z^2 from x = 0.9 (monotone convergence)."""
    b = beta * beta
    x = 0.85
    for _ in range(40):
        fx = ((x - 8.0) * x + 8.0 * (3.0 - 2.0 * b)) * x - 16.0 * (1.0 - b)
        dfx = (3.0 * x - 16.0) * x + 8.0 * (3.0 - 2.0 * b)
        dx = fx / dfx
        x -= dx
        if abs(dx) <= 1e-17:
            break
    return math.sqrt(x)


@njit(cache=True, nogil=True)
def branch_many(s_req, gamma, f, beta, eta, delta, xi, z_out, status, resid, err):
    """branch_solve for many parameter sets (rows of the 2-D outputs)."""
    for p in range(gamma.shape[0]):
        zr = rayleigh_z(beta[p])
        branch_solve(s_req, zr, gamma[p], f[p], beta[p], eta[p], delta[p], xi[p], z_out[p], status[p], resid[p], err[p])


@njit(cache=True)
def response_many(z, q, beta, eta, gx, gy, dgx, dgy):
    """Vector loop over flattened broadcast inputs."""
    for i in range(z.shape[0]):
        gx[i], gy[i], dgx[i], dgy[i], _ = response(z[i], q[i], beta[i], eta[i])


@njit(cache=True)
def dispersion_many(z, q, gamma, f, beta, eta, delta, xi, fo, dfo, sco):
    """Vector loop over flattened broadcast inputs."""
    for i in range(z.shape[0]):
        fo[i], dfo[i], sco[i] = dispersion_eval(z[i], q[i], gamma[i], f[i], beta[i], eta[i], delta[i], xi[i])
