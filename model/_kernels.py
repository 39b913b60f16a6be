"""Compiled scalar kernels: response functions, dispersion relation and the Rayleigh-branch path.

Everything here works on plain Python/NumPy scalars inside ``numba.njit`` functions; the public,
validated, broadcasting API lives in the other modules of :mod:`model`.

Records
-------
Two NamedTuples travel through the kernels (numba passes them by value, like their fields):
:class:`Params`, the six physical parameters of F, and :class:`Path`, a followed Rayleigh branch (its
nodes and the interpolation table built on them). :class:`Nodes` are the buffers a continuation fills,
:class:`Root` is what the one Newton loop (:func:`_newton`) returns, :class:`Box` confines it.

Cancellation-free forms (docs/physics.md §2)
--------------------------------------------
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

Where eta q Re(alpha_j) > HALF_SPACE_ARG the lower block is a half-space to rounding (tanh = 1 in
double precision) and the finite-eta kernel hands over to the eta = inf one. Every kernel also gives
the analytic q-derivatives, for the branch slope dz/d(ln kH) = -kH F_kH / F_z.

Rayleigh-branch path (docs/physics.md §3, §8)
---------------------------------------------
Adaptive predictor-corrector continuation in s = ln kH from the root at kH = 1e4 (_continue): the
predictor is the cubic Hermite extrapolant of ln z through the last two nodes (values and analytic
slopes), every node a certified Newton root (contraction rate <= THETA_MAX, predictor error <=
PRED_REJECT of the distance to the singularities). Requested points are reached from the degree-7
Hermite interpolant of the four surrounding nodes (_interp_table, accurate to ~1e-12 on the fine
path) by Newton's method whose first step is certified with the convergence constants measured at
the nodes (solve_at); with a looser rtol the interpolant itself is returned where its truncation
estimate allows.
"""

from __future__ import annotations

import cmath
import math
from fractions import Fraction
from typing import NamedTuple

import numpy as np
from numba import njit

EPS = 2.220446049250313e-16


class Params(NamedTuple):
    """The physical parameters of F (docs/physics.md §1; delta is Delta). All floats: numba types the record as
    a homogeneous tuple of six float64, passed by value like six scalars."""

    gamma: float
    f: float
    beta: float
    eta: float
    delta: float
    xi: float


def _tanh_over_x_coefficients(n: int) -> np.ndarray:
    """Taylor coefficients a_k of tanh(x)/x = sum_k a_k x^(2k), from y' = 1 - y^2 in exact rationals."""
    t = [Fraction(1)]
    for k in range(1, n):
        acc = sum((t[i] * t[k - 1 - i] for i in range(k)), Fraction(0))
        t.append(-acc / (2 * k + 1))
    return np.array([float(c) for c in t])


# ----------------------------------------------------------------------------- series and magnitudes
_SERIES_U = 0.3  # |u| below which g(u) and its divided differences use the Taylor series
_SERIES_R = math.pi**2 / 4  # radius of convergence of that series in u
_GCOEF = _tanh_over_x_coefficients(24)  # at |u| = _SERIES_U the last term is < 1e-21 (_nterms' bound 4e-18)
SERIES_TRUNC = 1e-18  # truncation target of the tanh(x)/x series: well below rounding of values and derivatives
SHC_MAX = 0.5  # |d| below which sinh(d)/d uses its Taylor series (the difference form would cancel)
SHC_TERMS = 14  # terms of that series: the last, d^26/27!, is < 1e-36 at |d| = SHC_MAX
DIVDIFF_FAR = 0.5  # |u2 - u1| >= DIVDIFF_FAR max(|u1|, |u2|): the plain quotient (g2 - g1)/(u2 - u1) cancels little
PSI_MAX = 0.5  # |t| below which psi(t) = expm1(t)/t uses its Taylor series (to t^16: truncation < 1e-19)
_PSICOEF = np.array([1.0 / math.factorial(k + 1) for k in range(17)])  # psi(t) = sum_k t^k/(k+1)!
CABS_LO, CABS_HI = 1e-150, 1e150  # |Re|, |Im| between these: their squares neither overflow nor underflow
ABS_FLOOR = 1e-300  # floor of |z| where it divides (z = 0 is no root for kH > 0)
HALF_SPACE_ARG = 22.0  # eta kH Re(alpha) above which tanh(eta kH alpha) = 1 in double precision (e^-44 < 1e-19)


@njit(cache=True, inline="always")
def _nterms(a: float) -> int:
    """Terms of the tanh(x)/x series (in u = x^2) needed at |u| <= a < _SERIES_U: the smallest n (at most all)
    with n^2 r^(n-2) <= SERIES_TRUNC, r = a/(pi^2/4) (|a_k| ~ 0.81 (pi^2/4)^-k: truncation of the values and of
    the divided differences' derivatives below SERIES_TRUNC)."""
    r = a / _SERIES_R
    n = 3
    rn = r  # r^(n-2)
    while n < _GCOEF.shape[0] and n * n * rn > SERIES_TRUNC:
        n += 1
        rn *= r
    return n


@njit(cache=True, inline="always")
def _fix0(u: complex) -> complex:
    """Turn a negative zero imaginary part into +0 (principal sqrt of a negative real -> +i)."""
    return complex(u.real, u.imag + 0.0)


@njit(cache=True)
def _tanh_sech(w: complex) -> tuple[complex, complex]:
    """tanh(w) and sech(w) without overflow for any w (exponentials of non-positive real part)."""
    s = 1.0 if w.real >= 0.0 else -1.0
    e1 = cmath.exp(-s * w)
    e = e1 * e1
    inv_den = 1.0 / (1.0 + e)
    return s * (1.0 - e) * inv_den, 2.0 * e1 * inv_den


@njit(cache=True)
def _g(u: complex) -> tuple[complex, complex]:
    """g(u) = tanh(sqrt u)/sqrt u and g'(u)."""
    a = _cabs(u)
    if a < _SERIES_U:
        c = _GCOEF
        n = _nterms(a)
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
    """sinh(d)/d and its derivative for |d| < SHC_MAX by Taylor series."""
    d2 = d * d
    val = 0j
    der = 0j
    term = 1.0 + 0j  # d^(2k)/(2k+1)!
    for k in range(SHC_TERMS):
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
    X/d = sinh(d)/d sech w1 sech w2 for |d| < SHC_MAX (no cancellation) and (tanh w2 - tanh w1)/d otherwise.
    """
    a1 = _cabs(u1)
    a2 = _cabs(u2)
    big = max(a1, a2)
    if big < _SERIES_U:
        g1, d1 = _g(u1)
        g2, d2 = _g(u2)
        c = _GCOEF
        n = _nterms(big)
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
    if _cabs(du) >= DIVDIFF_FAR * big:
        g1, d1 = _g(u1)
        g2, d2 = _g(u2)
        dd = (g2 - g1) / du
        return g1, d1, g2, d2, dd, (dd - d1) / du, (d2 - dd) / du
    w1 = cmath.sqrt(u1)
    w2 = cmath.sqrt(u2)
    if _cabs(w2 + w1) < _cabs(w2 - w1):  # g is even: take the square root nearest w1
        w2 = -w2
    th1, s1 = _tanh_sech(w1)
    th2, s2 = _tanh_sech(w2)
    g1 = th1 / w1
    g2 = th2 / w2
    d1 = (w1 * s1 * s1 - th1) / (2.0 * w1 * u1)
    d2 = (w2 * s2 * s2 - th2) / (2.0 * w2 * u2)
    d = w2 - w1
    if _cabs(d) < SHC_MAX:
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
    """psi(t) = expm1(t)/t and psi'(t) for |t| < PSI_MAX (Taylor series to t^16: truncation < 1e-19)."""
    c = _PSICOEF
    n = c.shape[0]
    val = c[n - 1] + 0j
    der = (n - 1) * c[n - 1] + 0j
    for k in range(n - 2, 0, -1):
        val = val * t + c[k]
        der = der * t + k * c[k]
    return val * t + c[0], der


@njit(cache=True, inline="always")
def _squares_safe(w: complex) -> bool:
    """Re w^2 + Im w^2 neither overflows nor underflows (the fast forms below; else the library's functions)."""
    m = max(abs(w.real), abs(w.imag))
    return CABS_LO < m < CABS_HI


@njit(cache=True, inline="always")
def _cabs(w: complex) -> float:
    """|w| by sqrt(re^2 + im^2) (several times faster than hypot), hypot where squares could over/underflow."""
    if _squares_safe(w):
        return math.sqrt(w.real * w.real + w.imag * w.imag)
    return abs(w)


@njit(cache=True, inline="always")
def _cinv(w: complex) -> complex:
    """1/w with one real division (conj(w)/|w|^2), the library's division where |w|^2 could over/underflow."""
    if _squares_safe(w):
        d = 1.0 / (w.real * w.real + w.imag * w.imag)
        return complex(w.real * d, -w.imag * d)
    return 1.0 / w


@njit(cache=True, inline="always")
def _csqrt(u: complex) -> complex:
    """Principal sqrt(u) (+i sqrt|u| on the negative real axis with Im u = +0) with the modulus as
    sqrt(re^2 + im^2); the library's sqrt where the squares could over/underflow (and at u = 0)."""
    if not _squares_safe(u):
        return cmath.sqrt(u)
    a = _cabs(u)
    if u.real >= 0.0:
        t = math.sqrt(0.5 * (a + u.real))
        return complex(t, 0.5 * u.imag / t)
    t = math.sqrt(0.5 * (a - u.real))
    return complex(0.5 * abs(u.imag) / t, math.copysign(t, u.imag))


EXP_ZERO = -746.0  # exp(x) is exactly 0 in double precision below this


@njit(cache=True, inline="always")
def _cexp(w: complex) -> complex:
    """exp(w), exactly 0 without the trigonometric functions where exp(Re w) underflows to 0."""
    if w.real < EXP_ZERO:
        return 0j
    return cmath.exp(w)


@njit(cache=True, inline="always")
def _clog(w: complex) -> complex:
    """Principal ln w: ln|w| as ln(|w|^2)/2 (no hypot), the library's log where |w|^2 could over/underflow."""
    if _squares_safe(w):
        return complex(0.5 * math.log(w.real * w.real + w.imag * w.imag), math.atan2(w.imag, w.real))
    return cmath.log(w)


@njit(cache=True, inline="always")
def _root(x: float, order: float) -> float:
    """x ** (1/order) for the predictor orders 2 and 4 (square roots instead of pow)."""
    r = math.sqrt(x)
    return r if order == 2.0 else math.sqrt(r)


@njit(cache=True, inline="always")
def _abs1(w: complex) -> float:
    """|Re w| + |Im w|: a cheap magnitude (within sqrt 2 of |w|) for rounding scales."""
    return abs(w.real) + abs(w.imag)


@njit(cache=True)
def response_inf(
    z: complex, q: float, beta: float
) -> tuple[complex, complex, complex, complex, complex, complex, float]:
    """G_x, G_y, dG_x/dz, dG_y/dz, dG_x/dq, dG_y/dq and a rounding scale for eta = inf (Eqs. Gx_LSA, Gy_LSA)."""
    b2 = beta * beta
    z2 = z * z
    us = _fix0((1.0 - z) * (1.0 + z))
    ud = _fix0((1.0 - beta * z) * (1.0 + beta * z))
    a_s = _csqrt(us)
    a_d = _csqrt(ud)
    inv_as = _cinv(a_s)
    inv_ad = _cinv(a_d)
    das = -z * inv_as
    dad = -b2 * z * inv_ad
    es = _cexp(-2.0 * q * a_s)
    ed = _cexp(-2.0 * q * a_d)
    des = -2.0 * q * das * es
    ded = -2.0 * q * dad * ed
    hs = 0.5 * (1.0 + es)
    dhs = 0.5 * des
    # Rayleigh function over z^2
    inv_one = _cinv(1.0 + a_s * a_d)
    cnum = 1.0 + b2 - b2 * z2
    c4 = 4.0 * cnum * inv_one
    rt = z2 - 4.0 + c4
    dprod = das * a_d + a_s * dad
    drt = 2.0 * z + 4.0 * (-2.0 * b2 * z - cnum * dprod * inv_one) * inv_one
    # Hd = (h_s - h_d)/z^2
    inv_sum = _cinv(a_s + a_d)
    dssum = das + dad
    k = -2.0 * q * (1.0 - b2)
    t = k * z2 * inv_sum
    dt = k * (2.0 * z - z2 * dssum * inv_sum) * inv_sum
    # q-derivatives: d e_j/dq = -2 alpha_j e_j, dt/dq = t/q
    qes = -2.0 * a_s * es
    qed = -2.0 * a_d * ed
    qt = -2.0 * (1.0 - b2) * z2 * inv_sum
    if _abs1(t) < PSI_MAX:
        ps, dps = _psi(t)
        qv = es * ps
        dqv = des * ps + es * dps * dt
        qqv = qes * ps + es * dps * qt
    else:
        inv_t = _cinv(t)
        qv = (ed - es) * inv_t
        dqv = ((ded - des) - qv * dt) * inv_t
        qqv = ((qed - qes) - qv * qt) * inv_t
    c = q * (1.0 - b2)
    hd = c * qv * inv_sum
    dhd = c * (dqv - qv * dssum * inv_sum) * inv_sum
    qhd = (1.0 - b2) * (qv + q * qqv) * inv_sum
    hs_as = hs * inv_as
    gx_a = rt * hs_as
    gx_b = 4.0 * a_d * hd
    gx = gx_a + gx_b
    dgx = (drt * hs + rt * dhs) * inv_as - gx_a * das * inv_as + 4.0 * (dad * hd + a_d * dhd)
    gy = -2.0 * (2.0 - z2) * hd
    dgy = -2.0 * (-2.0 * z * hd + (2.0 - z2) * dhd)
    qgx = 0.5 * rt * qes * inv_as + 4.0 * a_d * qhd
    qgy = -2.0 * (2.0 - z2) * qhd
    scale = (_abs1(z2) + 4.0 + _abs1(c4)) * _abs1(hs_as) + _abs1(gx_b)
    return gx, gy, dgx, dgy, qgx, qgy, scale


@njit(cache=True)
def response_fin(
    z: complex, q: float, beta: float, eta: float
) -> tuple[complex, complex, complex, complex, complex, complex, float]:
    """G_x, G_y, dG_x/dz, dG_y/dz, dG_x/dq, dG_y/dq and a rounding scale for finite eta (Eq. Gs_general).

    Where eta kH Re(alpha_j) > HALF_SPACE_ARG for both j (and eta != 1, whose G_y = 0 is kept exact),
    tanh(eta kH alpha_j) = 1 - O(e^-44) is 1 in double precision: the lower block is a half-space to
    rounding and the cheaper eta = inf kernel gives the same F (difference below 1e-19 of its terms).
    """
    b2 = beta * beta
    z2 = z * z
    us = _fix0((1.0 - z) * (1.0 + z))
    ud = _fix0((1.0 - beta * z) * (1.0 + beta * z))
    if eta != 1.0:
        # Re sqrt(u) = sqrt((|u| + Re u)/2)
        re_min = min(_cabs(us) + us.real, _cabs(ud) + ud.real)
        if re_min > 0.0 and eta * q * math.sqrt(0.5 * re_min) > HALF_SPACE_ARG:
            return response_inf(z, q, beta)
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
    # q-derivatives: d/dq [q g(q^2 u)] = g + 2 q^2 u g',
    # d/dq [q^3 g[q^2 u_s, q^2 u_d]] = 3 q^2 g[.] + 2 q^4 (u_s dg[.]/du_1 + u_d dg[.]/du_2)
    qg1s = gs + 2.0 * a * us * gds
    qg1d = gd + 2.0 * a * ud * gdd
    qd1 = 3.0 * a * dd + 2.0 * a * a * (us * dd1 + ud * dd2)
    qg2s = eta * (hs + 2.0 * b * us * hds)
    qg2d = eta * (hd + 2.0 * b * ud * hdd)
    qd2 = eta * (3.0 * b * ee + 2.0 * b * b * (us * ee1 + ud * ee2))
    qps = qg1s + qg2s
    qpd = qg1d + qg2d
    c = 1.0 - b2
    pp = ps * pd
    dpp_pp = dps / ps + dpd / pd
    qpp_pp = qps / ps + qpd / pd
    gx_a = 4.0 * c * pdd / pp
    gx_b = z2 / (us * ps)
    gx = gx_a + gx_b
    dgx = 4.0 * c * (dpdd / pp - pdd * dpp_pp / pp) + (2.0 * z - z2 * (dus / us + dps / ps)) / (us * ps)
    qgx = 4.0 * c * ((qd1 + qd2) - pdd * qpp_pp) / pp - gx_b * qps / ps
    kk = (g1s * d2 - g2s * d1) / pp
    dkk = (dg1s * d2 + g1s * dd2z - dg2s * d1 - g2s * dd1z) / pp - kk * dpp_pp
    qkk = (qg1s * d2 + g1s * qd2 - qg2s * d1 - g2s * qd1) / pp - kk * qpp_pp
    gy = 2.0 * (2.0 - z2) * c * kk
    dgy = 2.0 * c * (-2.0 * z * kk + (2.0 - z2) * dkk)
    qgy = 2.0 * (2.0 - z2) * c * qkk
    scale = _cabs(gx_a) + _cabs(gx_b) + 2.0 * _cabs(2.0 - z2) * c * (_cabs(g1s * d2) + _cabs(g2s * d1)) / _cabs(pp)
    return gx, gy, dgx, dgy, qgx, qgy, scale


@njit(cache=True)
def response(
    z: complex, q: float, beta: float, eta: float
) -> tuple[complex, complex, complex, complex, complex, complex, float]:
    """Dispatch on eta (inf -> half-space lower block): G_x, G_y, their z- and q-derivatives, rounding scale."""
    if math.isinf(eta):
        return response_inf(z, q, beta)
    return response_fin(z, q, beta, eta)


@njit(cache=True)
def _weighted_dispersion(z: complex, q: float, wg: float, wz: float, p: Params) -> tuple[complex, complex, float,
                                                                                           complex]:
    """wg (G_x + i f G_y) + wz i z S with S = 1 + (Delta - 1)/(1 - i xi z kH): value, dF/dz, rounding scale, dF/dkH.

    The rounding scale is the sum of the magnitudes of the terms plus |z F'| (the change of F under a
    relative perturbation of z by one unit: no evaluation can resolve F below eps times this).
    """
    f = p.f
    delta = p.delta
    xi = p.xi
    gx, gy, dgx, dgy, qgx, qgy, sc = response(z, q, p.beta, p.eta)
    if delta == 1.0:
        sf = 1.0 + 0j
        dsf = 0j
        qsf = 0j
        sabs = 1.0
    else:
        inv_den = _cinv(1.0 - 1j * xi * z * q)
        sf = 1.0 + (delta - 1.0) * inv_den
        dsf = (delta - 1.0) * (1j * xi * q) * inv_den * inv_den
        qsf = (delta - 1.0) * (1j * xi * z) * inv_den * inv_den
        sabs = 1.0 + _abs1((delta - 1.0) * inv_den)
    fval = wg * (gx + 1j * f * gy) + wz * 1j * z * sf
    dfval = wg * (dgx + 1j * f * dgy) + wz * 1j * (sf + z * dsf)
    qfval = wg * (qgx + 1j * f * qgy) + wz * 1j * z * qsf
    scale = wg * (sc + _abs1(f * gy)) + wz * _abs1(z) * sabs + _abs1(z * dfval)
    return fval, dfval, scale, qfval


@njit(cache=True)
def dispersion_eval(
    z: complex, q: float, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float
) -> tuple[complex, complex, float]:
    """F(z; q) of Eq. implicit_spectrum with Eq. delta f RSF, dF/dz, and the rounding scale of F."""
    fv, dfv, sc, _ = _weighted_dispersion(z, q, gamma, 1.0, Params(gamma, f, beta, eta, delta, xi))
    return fv, dfv, sc


@njit(cache=True)
def dispersion_dq(
    z: complex, q: float, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float
) -> complex:
    """dF/dkH of Eq. implicit_spectrum at fixed z (gives the branch slope dz/dkH = -F_kH / F_z)."""
    return _weighted_dispersion(z, q, gamma, 1.0, Params(gamma, f, beta, eta, delta, xi))[3]


# ---------------------------------------------------------------------------------------------
# Newton's method: the one loop and stopping rule for every root of the model
# ---------------------------------------------------------------------------------------------

# What _eval (and so _newton) evaluates; s and q as named here.
LN_KH = 0  # F along s = ln kH, evaluated at kH = q = e^s (_newton sets q once per root): the Rayleigh-branch path
TAU = 1  # F/gamma along s = tau = 1/gamma at kH = q: the homotopy to the branch's starting root
KH = 2  # F at kH = q (s unused): one root of model.modes
CUBIC = 3  # the Rayleigh cubic in x = z^2 (docs/physics.md §5), b = beta^2 (s, q and the other parameters unused)

NOISE_ULPS = 8.0  # rounding level of a Newton step: NOISE_ULPS eps scale/|F'| (scale bounds F's rounding error)
STEP_FLOOR = 1e-14  # a step below STEP_FLOOR |z| has converged: the error it leaves (~C a^2) is far below rounding
QUAD_TRUST = 1e-4  # C estimated from two steps (a/prev^2) is trusted for steps below QUAD_TRUST |z| ...
QUAD_SHRINK = 0.1  # ... that shrank at least 10x (quadratic convergence seen, not a chance small step)
C_FIRST_TRUST = 1e-6  # a C measured elsewhere (path nodes) is trusted for a first step below this x _local_scale
SHRINK_PATH = 0.5  # a branch root fails if a step is not below half the previous one (start outside the basin)
FULL_TOL = 0.25e-16  # relative error target of a converged root at full accuracy (rtol = None)
LOCAL_SCALE_MIN = 1e-12  # floor of _local_scale (a root this close to a singularity is not followed anyway)


class Root(NamedTuple):
    """What _newton returns."""

    z: complex  # the last iterate
    ok: bool  # converged by the stopping rule of _newton
    evals: int  # evaluations of F made
    first: float  # |first step|
    theta: float  # first contraction rate |step 2| / |step 1| (0 if converged at the first evaluation)
    resid: float  # |F(z)| / scale predicted by the quadratic model (inf if not converged)
    err: float  # estimated absolute error of z (inf if not converged)
    dzds: complex  # branch slope dz/ds = -F_s/F_z at z (NaN if not converged)


class Box(NamedTuple):
    """A rectangle the iterates of _newton must stay in (a root confined to its cell in model.modes)."""

    re_lo: float
    re_hi: float
    im_lo: float
    im_hi: float


NO_BOX = Box(-math.inf, math.inf, -math.inf, math.inf)


@njit(cache=True)
def _eval(z: complex, mode: int, s: float, q: float, p: Params) -> tuple[complex, complex, float, complex]:
    """F, dF/dz, rounding scale and dF/ds of the function selected by mode (LN_KH, TAU, KH or CUBIC).

    TAU evaluates F/gamma = G_x + i f G_y + tau i z S, which is linear in tau and finite at tau = 0 (gamma = inf),
    where its root is the Rayleigh root of the large-kH response. CUBIC is x^3 - 8 x^2 + 8 (3 - 2b) x - 16 (1 - b)
    at x = z (its scale: the sum of the magnitudes of its terms; dF/ds = 0).
    """
    if mode == LN_KH:
        fv, dfv, sc, fq = _weighted_dispersion(z, q, p.gamma, 1.0, p)
        return fv, dfv, sc, q * fq
    if mode == TAU:
        fv, dfv, sc, _ = _weighted_dispersion(z, q, 1.0, s, p)
        sf = 1.0 + (p.delta - 1.0) / (1.0 - 1j * p.xi * z * q)
        return fv, dfv, sc, 1j * z * sf
    if mode == KH:
        return _weighted_dispersion(z, q, p.gamma, 1.0, p)
    b = p.beta * p.beta
    c1 = 8.0 * (3.0 - 2.0 * b)
    c0 = 16.0 * (1.0 - b)
    ax = _cabs(z)
    return ((z - 8.0) * z + c1) * z - c0, (3.0 * z - 16.0) * z + c1, ((ax + 8.0) * ax + c1) * ax + c0, 0j


@njit(cache=True)
def _local_scale(z: complex) -> float:
    """Radius on which the root can move smoothly: min(|z|, distance to the real-axis singularities |Re z| >= 1).

    Poles (finite eta) and branch cuts (eta = inf) of F lie on the real axis with |z| >= 1 only
    (docs/physics.md §2), so predictor errors are measured against this distance.
    """
    x = abs(z.real)
    d = abs(z.imag) if x >= 1.0 else _cabs(complex(1.0 - x, z.imag))
    return max(min(_cabs(z), d), LOCAL_SCALE_MIN)


@njit(cache=True, nogil=True)
def _newton(z0: complex, mode: int, s: float, q: float, p: Params, maxit: int, tol: float, c_first: float,
            shrink: float, mult: float, box: Box) -> Root:
    """Newton's method from z0 on the function selected by mode (see _eval): the one Newton loop of the model.

    Each step is dz = mult F/F' (mult = n for a root of multiplicity n, else 1). After a step of size a to z:

    - converged if the step is at rounding level, a <= floor, or the quadratic model puts the error left,
      rest = C a^2, below tol |z|. Normally floor = max(STEP_FLOOR |z|, noise), noise = mult NOISE_ULPS eps
      scale/|F'|, and the convergence constant C = a/prev^2 is estimated from the last two steps once they
      are in the quadratic regime (a < QUAD_TRUST |z|, a < QUAD_SHRINK prev; else no quadratic test).
      With c_first > 0 the first step is instead certified by that constant measured elsewhere (at the path
      nodes): C = c_first, floor = STEP_FLOOR |z| (a step at noise level certifies nothing: it takes a second
      step to show contraction), and only for a <= C_FIRST_TRUST _local_scale(z) (close to a singularity
      the constant may not hold);
    - failed if F or F' is not finite or F' = 0, if z leaves the box, if a step is not below shrink times
      the previous one, or after maxit evaluations.

    A small theta = |step 2| / |step 1| certifies that z0 was well inside the quadratic basin of the root
    found: with two roots a distance d apart, theta ~ |z0 - z|/d, so theta <= THETA_MAX = 0.1 rules out
    starting nearer the other root (the callers on the branch check it). The error estimate is
    noise + rest (rest = a^2/|z| where no C is trusted); the residual estimate is that times |F'|/scale.
    dz/ds = -F_s/F_z: the slopes at the last two iterates extrapolated linearly (the slope is analytic in
    z) to the final z, so its error is O(|last two steps|^2) instead of O(|last step|).
    """
    z = z0
    prev = math.inf
    first = 0.0
    theta = 0.0
    nanz = complex(math.nan, math.nan)
    z_prev = nanz  # previous iterate and the slope there
    d_prev = nanz
    evals = 0
    if mode == LN_KH:
        q = math.exp(s)  # kH, once for all iterations at this s
    for it in range(maxit):
        fv, dfv, sc, fs = _eval(z, mode, s, q, p)
        evals += 1
        if not (cmath.isfinite(fv) and cmath.isfinite(dfv)) or dfv == 0:
            break
        inv_df = _cinv(dfv)
        step = fv * inv_df
        if mult != 1.0:
            step = mult * step
        a = _cabs(step)
        if it == 0:
            first = a
        elif it == 1 and first > 0.0:
            theta = a / first
        adf = _cabs(dfv)
        noise = mult * NOISE_ULPS * EPS * sc / adf
        slope = -fs * inv_df
        z_eval = z
        z = z - step
        if z.real < box.re_lo or z.real > box.re_hi or z.imag < box.im_lo or z.imag > box.im_hi:
            break
        az = max(_cabs(z), ABS_FLOOR)
        if it == 0 and c_first > 0.0:  # first step certified by a convergence constant measured elsewhere
            c = c_first
            trusted = a <= C_FIRST_TRUST * _local_scale(z)
            floor = STEP_FLOOR * az
        else:
            c = a / (prev * prev) if (it >= 1 and a < QUAD_TRUST * az and a < QUAD_SHRINK * prev) else 0.0
            trusted = True
            floor = max(STEP_FLOOR * az, noise)
        rest = c * a * a if c > 0.0 else a * a / az
        if trusted and (a <= floor or (c > 0.0 and rest <= tol * az)):
            if it >= 1 and z_eval != z_prev:
                slope = slope + (slope - d_prev) / (z_eval - z_prev) * (z - z_eval)
            err = noise + rest
            return Root(z, True, evals, first, theta, err * adf / sc, err, slope)
        if it >= 1 and a > shrink * prev:
            break
        prev = a
        z_prev = z_eval
        d_prev = slope
    return Root(z, False, evals, first, theta, math.inf, math.inf, nanz)


RAYLEIGH_X0 = 0.85  # start on the Rayleigh cubic: increasing and concave on (0, 1), where its root x = z_R^2 lies
RAYLEIGH_ITERS = 40  # far more than needed: Newton converges monotonically after its first step from RAYLEIGH_X0


@njit(cache=True, nogil=True)
def rayleigh_x(beta: float) -> float:
    """x_R = z_R^2 (docs/physics.md §5): Newton on the Rayleigh cubic in x = z^2 from RAYLEIGH_X0 (NaN if it fails).

    For the spectrum's beta in (0, 1/sqrt(2)] (from x = 0.85 the iterates converge to the root in (0, 1); near
    beta = 1, i.e. Poisson ratios near -1, they do not: model.rayleigh._rayleigh_x covers those)."""
    r = _newton(RAYLEIGH_X0 + 0j, CUBIC, 0.0, 0.0, Params(1.0, 0.0, beta, math.inf, 1.0, 0.0), RAYLEIGH_ITERS,
                FULL_TOL, 0.0, SHRINK_PATH, 1.0, NO_BOX)
    return r.z.real if r.ok else math.nan


@njit(cache=True, nogil=True)
def rayleigh_z(beta: float) -> float:
    """z_R(beta) = sqrt(x_R) (docs/physics.md §5)."""
    return math.sqrt(rayleigh_x(beta))


@njit(cache=True)
def rayleigh_many(beta: np.ndarray, out: np.ndarray) -> None:
    """rayleigh_z over a 1-D array."""
    for i in range(beta.shape[0]):
        out[i] = rayleigh_z(beta[i])


# ---------------------------------------------------------------------------------------------
# Rayleigh-branch continuation (docs/physics.md §3, §8)
# ---------------------------------------------------------------------------------------------

OK = 0
LOST = 1  # the branch could not be followed down to this kH (collision / ill-conditioning)
NOCONV = 2  # Newton did not converge at this kH although the path reached it
START = 3  # the starting root at kH = 1e4 could not be found
INPUT = 4  # the parameters themselves were NaN

S_TOP = math.log(1e4)  # the branch is defined by its root at kH = 1e4 (docs/physics.md §3)
H_MAX = 0.4  # largest continuation step in ln(kH)
CUT_APPROACH = 0.9  # eta = inf: a step covers at most this fraction of the way to the branch cut (see _continue)
H_MIN = 1e-7  # a step this short that still fails: the branch is lost (collision with another branch)
H_START = 0.05  # first continuation step in ln(kH)
TAU_H_START = 0.25  # first step of the homotopy in tau = 1/gamma, as a fraction of [0, 1/gamma]
PRED_TOL = 1e-3  # target predictor error per step, relative to _local_scale (coarse paths)
PRED_TOL_FINE = 1e-4  # the same for paths whose interpolant should be accurate to ~1e-12 (spectrum)
PRED_OVERSHOOT = 10.0  # steps whose predictor error exceeds this multiple of the target are retried shorter
PRED_REJECT = 1e-2  # predictor error (relative to _local_scale) above which a step is rejected
THETA_MAX = 0.1  # largest first Newton contraction rate accepted (basin certificate, see _newton)
NODE_ITERS = 6  # Newton evaluations allowed for a node (from a predictor within PRED_REJECT: a few)
NODE_EVALS = 5  # a node that needed more evaluations is retried with a shorter step (predictor too far)
STEP_SAFETY = 0.9  # safety factor on the step the error model predicts for pred_tol (the model is asymptotic)
STEP_GROW = 2.0  # after an accepted node the step at most doubles ...
STEP_CUT = 0.5  # ... and at most halves
RETRY_CUT_MIN = 0.2  # a step certified but too far from its prediction is shortened by the error model,
RETRY_CUT_MAX = 0.5  # by a factor in [RETRY_CUT_MIN, RETRY_CUT_MAX]
RETRY_HALVE = 0.5  # a step whose Newton failed (or failed the certificate) is halved
MAX_NODES = 8192  # nodes per direction (typically ~100 for kH in [1e-4, 1e4]); a path filling it counts as lost
START_NODES = 4096  # nodes of the tau homotopy (typically 5, a few hundred at most seen)
# node buffers start this small and double when full (up to the limits above): allocating the limits at every call
# cost more than the continuation where freed memory goes back to the OS at once (Dask workers set glibc's
# MALLOC_TRIM_THRESHOLD_), and the typical path needs a hundred nodes
NODES_INITIAL = 128
START_ITERS = 20  # Newton from z_R at tau = 0, kH = 1e4, where z_R is the root to rounding: a wide margin
EXTRA_NODES = 2  # nodes built beyond the requested range: the end intervals keep two nodes on each side
SOLVE_ITERS = 10  # Newton at a requested point from the interpolant (~1e-12 accurate): usually one step
C_FIRST_SAFETY = 10.0  # C at a requested point: this x the largest C of the four surrounding nodes (margin for
# its variation between nodes, where it was measured with larger steps)
RTOL_MARGIN = 0.1  # with a requested rtol, points are accepted once their estimated error is below 0.1 rtol
MAP_NODE_TOL = 1e-10  # relative accuracy of the path nodes of a growth map (see _map_node_tol)
MAP_NODE_RTOL = 1e-3  # ... tightened to this x rtol where the interpolant may be reported (a looser rtol)
RTOL_COARSE_PATH = 1e-7  # from this rtol on the spectrum uses the coarse path (PRED_TOL, interpolant ~1e-8)


class Nodes(NamedTuple):
    """Buffers of path nodes filled by _continue (node 0 = the start)."""

    s: np.ndarray  # continuation parameter (ln kH, or tau = 1/gamma)
    z: np.ndarray  # roots (complex)
    dzds: np.ndarray  # branch slopes dz/ds (complex)
    conv: np.ndarray  # quadratic-convergence constants C = |step 2| / |step 1|^2 of the nodes' Newton (0: one step)
    err: np.ndarray  # estimated relative errors of the roots


@njit(cache=True)
def _nodes(n: int) -> Nodes:
    """Empty node buffers of length n."""
    return Nodes(np.empty(n), np.empty(n, dtype=np.complex128), np.empty(n, dtype=np.complex128), np.empty(n),
                 np.empty(n))


@njit(cache=True)
def _grown(out: Nodes, n: int, cap: int) -> Nodes:
    """Node buffers of length cap holding the first n nodes of out."""
    new = _nodes(cap)
    new.s[:n] = out.s[:n]
    new.z[:n] = out.z[:n]
    new.dzds[:n] = out.dzds[:n]
    new.conv[:n] = out.conv[:n]
    new.err[:n] = out.err[:n]
    return new


@njit(cache=True, inline="always")
def _path_tol(rtol: float) -> float:
    """Predictor target of the spectrum's path: fine (interpolant ~1e-12) unless rtol >= RTOL_COARSE_PATH."""
    return PRED_TOL if rtol >= RTOL_COARSE_PATH else PRED_TOL_FINE


@njit(cache=True, inline="always")
def _map_node_tol(rtol: float) -> float:
    """Node accuracy of a growth map's path: MAP_NODE_TOL (the grid only brackets; the reported values are
    re-solved from the nodes), tightened to MAP_NODE_RTOL rtol where a looser rtol lets the interpolant be
    reported."""
    return MAP_NODE_TOL if rtol <= 0.0 else max(FULL_TOL, min(MAP_NODE_TOL, MAP_NODE_RTOL * rtol))


@njit(cache=True, inline="always")
def _target(rtol: float) -> float:
    """Relative error target of one root: full accuracy for rtol <= 0, else RTOL_MARGIN * rtol."""
    return FULL_TOL if rtol <= 0.0 else max(FULL_TOL, RTOL_MARGIN * rtol)


@njit(cache=True, inline="always")
def _hermite2(s0: float, w0: complex, d0: complex, s1: float, w1: complex, d1: complex, s: float) -> complex:
    """Cubic Hermite interpolant/extrapolant through (s0, w0, w0') and (s1, w1, w1'), evaluated at s."""
    ih = 1.0 / (s1 - s0)
    f01 = (w1 - w0) * ih
    f001 = (f01 - d0) * ih
    f0011 = ((d1 - f01) * ih - f001) * ih
    x = s - s0
    return w0 + x * (d0 + x * (f001 + (s - s1) * f0011))


@njit(cache=True, inline="always")
def _hermite3(s0: float, w0: complex, d0: complex, s1: float, w1: complex, d1: complex, s2: float, w2: complex,
              d2: complex, s: float) -> complex:
    """Quintic Hermite interpolant/extrapolant through three nodes (values and slopes), evaluated at s."""
    i10 = 1.0 / (s1 - s0)
    i21 = 1.0 / (s2 - s1)
    i20 = 1.0 / (s2 - s0)
    f01 = (w1 - w0) * i10
    f12 = (w2 - w1) * i21
    f001 = (f01 - d0) * i10
    f011 = (d1 - f01) * i10
    f112 = (f12 - d1) * i21
    f122 = (d2 - f12) * i21
    f0011 = (f011 - f001) * i10
    f0112 = (f112 - f011) * i20
    f1122 = (f122 - f112) * i21
    f00112 = (f0112 - f0011) * i20
    f01122 = (f1122 - f0112) * i20
    f001122 = (f01122 - f00112) * i20
    x0 = s - s0
    x1 = s - s1
    x2 = s - s2
    return w0 + x0 * (d0 + x0 * (f001 + x1 * (f0011 + x1 * (f00112 + x2 * f001122))))


@njit(cache=True, inline="always")
def _unwrap(w: complex, ref: complex) -> complex:
    """ln z with the phase shifted by a multiple of 2 pi to lie within pi of ln z_ref."""
    k = math.floor((w.imag - ref.imag) / (2.0 * math.pi) + 0.5)
    return complex(w.real, w.imag - 2.0 * math.pi * k)


@njit(cache=True, nogil=True)
def _continue(z0: complex, dz0: complex, e0: float, s0: float, s_stop: float, extra: int, direction: float,
              mode: int, q: float, p: Params, pred_tol: float, node_tol: float, out: Nodes,
              max_nodes: int) -> tuple[int, bool, Nodes]:
    """Adaptive predictor-corrector continuation of one root in s from s0 towards s_stop (mode LN_KH or TAU).

    Nodes are written to out (node 0 = start, slope dz0, error e0); continues until `extra` nodes lie
    beyond s_stop (or, if extra == 0, stops exactly at s_stop). The sequence of nodes depends only on the
    start and the physical parameters, never on s_stop, except for where it is cut off. The predictor is
    the cubic Hermite extrapolant of ln z through the last two nodes (values and slopes) -- for eta = inf the
    quintic one through the last three (O(h^6): longer steps for the same predictor error; for finite eta it moved
    where the branch counts as lost, see docs/physics.md §8); every node is a
    converged Newton root (to node_tol relative) whose first contraction rate passed the basin certificate
    (THETA_MAX) with a predictor error below PRED_REJECT of _local_scale. The step size aims at a predictor
    error of pred_tol (relative to _local_scale); steps above PRED_OVERSHOOT pred_tol are retried shorter,
    which bounds the error of the path interpolant. For eta = inf a root moving towards the branch cut (the real
    axis at |Re z| >= 1, which it cannot cross on the physical sheet) takes steps of at most CUT_APPROACH of the
    linear distance to it, so that the approach that ends in a lost branch costs a node per decade instead of
    rejected steps (30 % of the sets of a 64^4 atlas: 7.9 -> 0.7 rejected steps per set); the acceptance tests
    are unchanged. out.conv receives the quadratic-convergence constant
    observed at each node. The buffers double when full, up to max_nodes (then the branch counts as lost).
    Returns (number of nodes, lost flag, the buffers holding them).
    """
    o_s, o_z, o_d, o_c, o_e = out  # unpacked once (see Path)
    o_s[0] = s0
    o_z[0] = z0
    o_d[0] = dz0
    o_c[0] = 0.0
    o_e[0] = e0
    cap = o_s.shape[0]
    use_log = z0 != 0
    # predictor data of the previous and the current node (ln z and d ln z/ds, or z and dz/ds)
    wq = 0j
    dq = 0j
    wp = 0j
    dp = 0j
    wc = _clog(z0) if use_log else z0
    dc = dz0 / z0 if use_log else dz0
    n = 1
    h = H_START if mode == LN_KH else TAU_H_START * abs(s_stop - s0)
    h_cap = H_MAX if mode == LN_KH else abs(s_stop - s0)
    beyond = 0
    cut = math.isinf(p.eta)
    while True:
        s_cur = o_s[n - 1]
        if extra == 0:
            if direction * (s_stop - s_cur) <= 0.0:
                return n, False, out
            h_try = min(h, direction * (s_stop - s_cur))
        else:
            if beyond >= extra:
                return n, False, out
            h_try = h
        if n >= cap:
            if cap >= max_nodes:
                return n, True, out
            out = _grown(out, n, min(2 * cap, max_nodes))
            o_s, o_z, o_d, o_c, o_e = out
            cap = o_s.shape[0]
        accepted = False
        while not accepted:
            if h_try < H_MIN:
                return n, True, out
            s_new = s_cur + direction * h_try
            if n == 1:
                wpred = wc + dc * (s_new - s_cur)
            elif n >= 3 and cut:
                wpred = _hermite3(o_s[n - 3], wq, dq, o_s[n - 2], wp, dp, s_cur, wc, dc, s_new)
            else:
                wpred = _hermite2(o_s[n - 2], wp, dp, s_cur, wc, dc, s_new)
            zp = cmath.exp(wpred) if use_log else wpred
            r = _newton(zp, mode, s_new, q, p, NODE_ITERS, node_tol, 0.0, SHRINK_PATH, 1.0, NO_BOX)
            err = _cabs(r.z - zp) / _local_scale(r.z)
            # predictor error O(h^2) from one node, O(h^4) from two, O(h^6) from three (eta = inf)
            order = 2.0 if n == 1 else (6.0 if (n >= 3 and cut) else 4.0)
            certified = r.ok and err <= PRED_REJECT and r.theta <= THETA_MAX and cmath.isfinite(r.dzds)
            if certified and r.evals <= NODE_EVALS and err <= PRED_OVERSHOOT * pred_tol:
                accepted = True
                z = r.z
                o_s[n] = s_new
                o_z[n] = z
                o_d[n] = r.dzds
                o_c[n] = r.theta / r.first if (r.first > 0.0 and r.theta > 0.0) else 0.0
                o_e[n] = r.err / max(_cabs(z), ABS_FLOOR)
                wq = wp
                dq = dp
                wp = wc
                dp = dc
                if use_log and z == 0:
                    return n + 1, True, out  # cannot happen on a followable branch (z = 0 is no root for kH > 0)
                wc = _unwrap(_clog(z), wc) if use_log else z
                dc = r.dzds * _cinv(z) if use_log else r.dzds
                n += 1
                if extra > 0 and direction * (s_new - s_stop) > 0.0:
                    beyond += 1
                fac = STEP_GROW if err == 0.0 else STEP_SAFETY * _root(pred_tol / err, order)
                fac = min(STEP_GROW, max(STEP_CUT, fac))
                h = min(h_cap, h_try * fac)
                if cut:
                    rate = direction * r.dzds.imag
                    if abs(z.real) >= 1.0 and z.imag * rate < 0.0:
                        h = min(h, CUT_APPROACH * (-z.imag / rate))
            elif certified:
                # certified but too far from the prediction for the target: shorten by the error model
                h_try *= min(RETRY_CUT_MAX, max(RETRY_CUT_MIN, STEP_SAFETY * _root(pred_tol / err, order)))
                h = h_try
            else:
                h_try *= RETRY_HALVE
                h = h_try


@njit(cache=True)
def rayleigh_start(z_r: float, p: Params) -> tuple[complex, complex, float, bool]:
    """The Rayleigh-branch root at kH = 1e4 and its slope dz/d(ln kH): homotopy in tau = 1/gamma from
    tau = 0 (gamma = inf, where the root is the Rayleigh root of the large-kH response, found by Newton
    from z_R) to 1/gamma. Returns (z, dz/ds, estimated relative error of z, found)."""
    q = math.exp(S_TOP)
    work = _nodes(min(NODES_INITIAL, START_NODES))
    nanz = complex(math.nan, math.nan)
    r = _newton(z_r + 0j, TAU, 0.0, q, p, START_ITERS, FULL_TOL, 0.0, SHRINK_PATH, 1.0, NO_BOX)
    if not r.ok:
        return r.z, nanz, math.nan, False
    # eta = inf: homotopy nodes to MAP_NODE_TOL and one full-accuracy Newton at its end; for finite eta this
    # changed the start of small-gamma sets, so there every node is at full accuracy
    cut = math.isinf(p.eta)
    n, lost, work = _continue(r.z, r.dzds, r.err / max(abs(r.z), ABS_FLOOR), 0.0, 1.0 / p.gamma, 0, 1.0, TAU, q, p,
                              PRED_TOL, MAP_NODE_TOL if cut else FULL_TOL, work, START_NODES)
    z = work.z[n - 1]
    if lost:
        return z, nanz, math.nan, False
    err = work.err[n - 1]
    if cut:
        r = _newton(z, TAU, 1.0 / p.gamma, q, p, START_ITERS, FULL_TOL, 0.0, SHRINK_PATH, 1.0, NO_BOX)
        if not r.ok:
            return r.z, nanz, math.nan, False
        z = r.z
        err = r.err / max(abs(z), ABS_FLOOR)
    fv, dfv, _, fs = _eval(z, LN_KH, S_TOP, q, p)
    if not (cmath.isfinite(fv) and cmath.isfinite(dfv)) or dfv == 0:
        return z, nanz, math.nan, False
    return z, -fs / dfv, err, True


# ----------------------------------------------------------------------------- the path and its interpolant
NTERM = 8  # Hermite data of up to four nodes (value and slope): degree-7 interpolant per interval


class Path(NamedTuple):
    """A followed Rayleigh branch (build_path): nodes ascending in s = ln kH and the interpolant through them.

    Functions that loop over points (branch_solve, growth_one, _refine_max, _crossing) unpack the record once,
    ``ns, nz, nc, ne, cx, cf, cm, nn, use_log = path``, and pass the fields to the per-point helpers (_interval,
    _interp, _im_at, _solve_at, inlined into the loop): every read of an array field of a record costs an atomic
    reference-count increment and decrement, which inside a loop is a third of the time of an interpolated point.
    """

    s: np.ndarray  # node positions ln kH, ascending
    z: np.ndarray  # roots at the nodes
    conv: np.ndarray  # quadratic-convergence constants of the nodes (Nodes.conv)
    err: np.ndarray  # estimated relative errors of the nodes
    cx: np.ndarray  # interpolation table (_interp_table): abscissae (n-1, NTERM) of each interval's Newton form,
    cf: np.ndarray  # its coefficients (n-1, NTERM), of ln z (use_log) or of z,
    cm: np.ndarray  # and its number of terms (n-1)
    n: int  # number of nodes (0: no path)
    use_log: bool  # the table interpolates ln z (False only if a node is exactly 0)


@njit(cache=True)
def _interp_table(ns: np.ndarray, nw: np.ndarray, nd: np.ndarray,
                  nn: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Newton-form coefficients of the Hermite interpolant on each path interval [ns[j], ns[j+1]].

    nw, nd: ln z and d ln z/ds at the nodes (or z and dz/ds). The interpolant of interval j matches
    values and slopes at nodes j, j+1, j-1, j+2 (those that exist): degree 7 inside the path, 5 at
    its ends. Returns (nodes x (nn-1, 8), coefficients c (nn-1, 8), number of terms m (nn-1)) with
    p(s) = c0 + (s - x0)(c1 + (s - x1)(c2 + ...)).
    """
    ni = max(nn - 1, 0)
    cx = np.zeros((ni, NTERM))
    cf = np.zeros((ni, NTERM), dtype=np.complex128)
    cm = np.zeros(ni, dtype=np.int64)
    idx = np.empty(4, dtype=np.int64)
    for j in range(ni):
        k = 0
        for node in (j, j + 1, j - 1, j + 2):
            if 0 <= node < nn:
                idx[k] = node
                k += 1
        m = 2 * k
        # the row's abscissae and coefficients indexed in place (row views cost a reference count each)
        for i in range(k):
            cx[j, 2 * i] = ns[idx[i]]
            cx[j, 2 * i + 1] = ns[idx[i]]
            cf[j, 2 * i] = nw[idx[i]]
            cf[j, 2 * i + 1] = nw[idx[i]]
        # divided differences in place (column 1: slopes at the doubled nodes)
        for i in range(m - 1, 0, -1):
            if i % 2 == 1:
                cf[j, i] = nd[idx[i // 2]]
            else:
                cf[j, i] = (cf[j, i] - cf[j, i - 1]) * (1.0 / (cx[j, i] - cx[j, i - 1]))
        for order in range(2, m):
            for i in range(m - 1, order - 1, -1):
                cf[j, i] = (cf[j, i] - cf[j, i - 1]) * (1.0 / (cx[j, i] - cx[j, i - order]))
        cm[j] = m
    return cx, cf, cm


@njit(cache=True, inline="always")
def _interp_value(s: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray) -> complex:
    """Value of the Hermite interpolant of interval j at s (Horner on the Newton form of Path.cx, cf, cm)."""
    m = cm[j]
    p = cf[j, m - 1]
    for k in range(m - 2, -1, -1):
        p = p * (s - cx[j, k]) + cf[j, k]
    return p


@njit(cache=True, inline="always")
def _interp(s: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray) -> tuple[complex, complex, complex,
                                                                                       float]:
    """(p, p', p'', truncation estimate) of the Hermite interpolant of interval j at s (Path.cx, cf, cm).

    The estimate is |last term| + |second-to-last term| of the Newton form: the difference between the
    interpolant and the one with the data of the outermost node removed (an upper estimate of the error).
    """
    m = cm[j]
    p = cf[j, m - 1]
    dp = 0j
    d2p = 0j
    for k in range(m - 2, -1, -1):
        t = s - cx[j, k]
        d2p = d2p * t + 2.0 * dp
        dp = dp * t + p
        p = p * t + cf[j, k]
    w = 1.0
    for k in range(m - 2):
        w *= abs(s - cx[j, k])
    est = (abs(cf[j, m - 2]) + abs(cf[j, m - 1] * (s - cx[j, m - 2]))) * w
    return p, dp, d2p, est


@njit(cache=True, nogil=True)
def _no_path() -> Path:
    """The empty Path (n = 0) that build_path returns with a failure code."""
    ns = np.empty(1)
    return Path(ns, np.empty(1, dtype=np.complex128), ns, ns, np.zeros((0, NTERM)),
                np.zeros((0, NTERM), dtype=np.complex128), np.zeros(0, dtype=np.int64), 0, True)


@njit(cache=True, nogil=True)
def build_path(s_lo: float, s_hi: float, z_r: float, p: Params, pred_tol: float, node_tol: float) -> tuple[Path, int]:
    """Rayleigh-branch path covering [s_lo, s_hi] (s = ln kH), ascending in s, with its interpolation table.

    Start at ln 1e4 (see rayleigh_start), continue down to EXTRA_NODES nodes below min(s_lo, ln 1e4) and up
    to EXTRA_NODES nodes above max(s_hi, ln 1e4) -- unless EXTRA_NODES nodes of the downward path lie above s_hi
    already (a growth map up to kH = 1e3): the interpolant of every interval up to s_hi is then the same without
    the upward nodes and without the downward ones above those EXTRA_NODES, which are dropped. The node sequence
    depends only on the physical parameters; s_lo/s_hi only decide where it is cut off. pred_tol and node_tol: see
    _continue. Returns (path, code)
    with code OK, START (no starting root; path.n = 0) or INPUT (NaN parameter; path.n = 0).
    """
    for v in p:
        if math.isnan(v):
            return _no_path(), INPUT
    z0, dz0, e0, ok = rayleigh_start(z_r, p)
    if not ok:
        return _no_path(), START
    nd, _, dn = _continue(z0, dz0, e0, S_TOP, min(s_lo, S_TOP), EXTRA_NODES, -1.0, LN_KH, 1.0, p, pred_tol,
                          node_tol, _nodes(NODES_INITIAL), MAX_NODES)
    top = 0  # downward nodes before this index are dropped (they lie above the EXTRA_NODES nodes above s_hi)
    if nd > EXTRA_NODES and s_hi < dn.s[EXTRA_NODES - 1]:
        # EXTRA_NODES nodes of the downward path lie above s_hi already: the interpolant up to s_hi needs no more
        nu, up = 1, dn
        while top + EXTRA_NODES < nd and dn.s[top + EXTRA_NODES] > s_hi:
            top += 1
    else:
        nu, _, up = _continue(z0, dz0, e0, S_TOP, max(s_hi, S_TOP), EXTRA_NODES, 1.0, LN_KH, 1.0, p, pred_tol,
                              node_tol, _nodes(NODES_INITIAL), MAX_NODES)
    nd -= top
    nn = nd + nu - 1
    ns = np.empty(nn)
    nz = np.empty(nn, dtype=np.complex128)
    ndz = np.empty(nn, dtype=np.complex128)
    nc = np.empty(nn)
    ne = np.empty(nn)
    for i in range(nd):
        k = nd - 1 - i + top
        ns[i] = dn.s[k]
        nz[i] = dn.z[k]
        ndz[i] = dn.dzds[k]
        nc[i] = dn.conv[k]
        ne[i] = dn.err[k]
    for i in range(1, nu):
        k = nd - 1 + i
        ns[k] = up.s[i]
        nz[k] = up.z[i]
        ndz[k] = up.dzds[i]
        nc[k] = up.conv[i]
        ne[k] = up.err[i]
    use_log = True
    for i in range(nn):
        use_log = use_log and nz[i] != 0
    if use_log:
        nw = np.empty(nn, dtype=np.complex128)
        for i in range(nn):
            nw[i] = _clog(nz[i])
            if i > 0:
                nw[i] = _unwrap(nw[i], nw[i - 1])
            ndz[i] = ndz[i] * _cinv(nz[i])
        cx, cf, cm = _interp_table(ns, nw, ndz, nn)
    else:
        cx, cf, cm = _interp_table(ns, nz, ndz, nn)
    return Path(ns, nz, nc, ne, cx, cf, cm, nn, use_log), OK


@njit(cache=True, inline="always")
def _interval(s: float, ns: np.ndarray, nn: int) -> int:
    """Index j of the path interval [ns[j], ns[j+1]] holding s (-1 outside the path or for nn < 2 nodes)."""
    if nn < 2 or not (ns[0] <= s <= ns[nn - 1]):
        return -1
    j = np.searchsorted(ns, s, side="right") - 1  # ns[j] <= s
    return min(j, nn - 2)


@njit(cache=True, inline="always")
def _around(v: np.ndarray, j: int, nn: int) -> float:
    """Largest of v over the (up to) four nodes j-1 .. j+2 whose data the interpolant of interval j uses."""
    return max(max(v[max(j - 1, 0)], v[j]), max(v[j + 1], v[min(j + 2, nn - 1)]))


@njit(cache=True, nogil=True)
def path_value(s: float, path: Path) -> tuple[complex, complex, complex, float]:
    """(z, dz/ds, d2z/ds2, estimated relative error) of the path interpolant at s (NaN outside the path)."""
    nanz = complex(math.nan, math.nan)
    ns, nz, _, _, cx, cf, cm, nn, use_log = path
    j = _interval(s, ns, nn)
    if j < 0:
        if nn == 1 and s == ns[0]:
            return nz[0], nanz, nanz, 0.0
        return nanz, nanz, nanz, math.nan
    p, dp, d2p, est = _interp(s, j, cx, cf, cm)
    if use_log:
        z = cmath.exp(p)
        return z, dp * z, (d2p + dp * dp) * z, est
    return p, dp, d2p, est / max(abs(p), ABS_FLOOR)


@njit(cache=True, nogil=True, inline="always")
def _solve_at(s: float, ns: np.ndarray, nz: np.ndarray, nc: np.ndarray, ne: np.ndarray, cx: np.ndarray,
              cf: np.ndarray, cm: np.ndarray, nn: int, use_log: bool, p: Params,
              rtol: float) -> tuple[complex, int, float, float, complex]:
    """The Rayleigh-branch root at s = ln kH from the path (its fields unpacked, see Path): (z, status, residual,
    error, dz/ds).

    Start from the Hermite interpolant of the path nodes. With rtol > 0 the interpolant itself is
    returned where its truncation estimate plus the nodes' error estimates is below RTOL_MARGIN rtol
    (residual NaN: F not evaluated; dz/ds from the interpolant). Otherwise Newton's method (_newton)
    with the first step certified by the quadratic-convergence constants measured at the surrounding
    path nodes (their steps passed the contraction certificate with larger predictor errors), times
    C_FIRST_SAFETY: where that bounds the error after one step below the target (_target), the point
    costs one evaluation of F. Further steps must show a strong first contraction (THETA_MAX) and end
    near the prediction (PRED_REJECT), else NOCONV. Outside the nodes' range the branch was lost (LOST).
    """
    nanz = complex(math.nan, math.nan)
    j = _interval(s, ns, nn)
    if j < 0:
        if nn == 1 and s == ns[0]:
            return nz[0], OK, 0.0, 0.0, nanz
        return nanz, LOST, math.nan, math.nan, nanz
    if rtol > 0.0:
        w, dw, _, est = _interp(s, j, cx, cf, cm)
        if use_log:
            zp = cmath.exp(w)
            dzp = dw * zp
        else:
            zp = w
            dzp = dw
            est /= max(abs(w), ABS_FLOOR)
        # add the nodes' own errors (the truncation estimate is 0 at a node)
        est += _around(ne, j, nn)
        if est <= RTOL_MARGIN * rtol:
            return zp, OK, math.nan, est * abs(zp), dzp
    else:
        w = _interp_value(s, j, cx, cf, cm)
        zp = cmath.exp(w) if use_log else w
    c_nodes = C_FIRST_SAFETY * _around(nc, j, nn)
    r = _newton(zp, LN_KH, s, 1.0, p, SOLVE_ITERS, _target(rtol), c_nodes, SHRINK_PATH, 1.0, NO_BOX)
    if r.ok and r.theta <= THETA_MAX and abs(r.z - zp) <= PRED_REJECT * _local_scale(r.z):
        return r.z, OK, r.resid, r.err, r.dzds
    return nanz, NOCONV, math.nan, math.nan, nanz


@njit(cache=True, nogil=True)
def solve_at(s: float, path: Path, p: Params, rtol: float) -> tuple[complex, int, float, float, complex]:
    """_solve_at for one point of a path (the loops over points inline _solve_at instead)."""
    ns, nz, nc, ne, cx, cf, cm, nn, use_log = path
    return _solve_at(s, ns, nz, nc, ne, cx, cf, cm, nn, use_log, p, rtol)


@njit(cache=True, nogil=True)
def branch_solve(s_req: np.ndarray, z_r: float, p: Params, rtol: float, z_out: np.ndarray, status: np.ndarray,
                 resid: np.ndarray, err: np.ndarray) -> None:
    """Rayleigh-branch roots at the requested s = ln kH values for one parameter set.

    Each requested point is reached from the interpolated path nodes by Newton's method
    (solve_at), so its digits do not depend on the other requests.
    """
    m = s_req.shape[0]
    if m == 0:
        return
    path, code = build_path(s_req.min(), s_req.max(), z_r, p, _path_tol(rtol), FULL_TOL)
    ns, nz, nc, ne, cx, cf, cm, nn, use_log = path  # unpacked once (see Path)
    for i in range(m):
        if code != OK:
            z_out[i] = complex(math.nan, math.nan)
            status[i] = code
            resid[i] = math.nan
            err[i] = math.nan
            continue
        z_out[i], status[i], resid[i], err[i], _ = _solve_at(s_req[i], ns, nz, nc, ne, cx, cf, cm, nn, use_log, p,
                                                             rtol)


# ----------------------------------------------------------------------------- growth maps: the continuous maximum
#: the compile options of every kernel below (one set for the new kernels; issue 25 extends it to all)
kernel = njit(cache=True, nogil=True)

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


@njit(cache=True, nogil=True, inline="always")
def _im_in(s: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray, use_log: bool) -> float:
    """Im z of the interpolant of path interval j at s (Im e^w = e^Re w sin Im w where it interpolates w = ln z)."""
    w = _interp_value(s, j, cx, cf, cm)
    return math.exp(w.real) * math.sin(w.imag) if use_log else w.imag


@njit(cache=True, nogil=True, inline="always")
def _im_at(s: float, ns: np.ndarray, nz: np.ndarray, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray, nn: int,
           use_log: bool) -> float:
    """Im z of the path interpolant at s (NaN outside the path); the path's fields unpacked (see Path)."""
    j = _interval(s, ns, nn)
    if j < 0:
        return nz[0].imag if (nn == 1 and s == ns[0]) else math.nan
    return _im_in(s, j, cx, cf, cm, use_log)


@kernel
def _sample_at(s: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray,
               use_log: bool) -> tuple[complex, complex, complex]:
    """(z, dz/ds, d2z/ds2) of the path interpolant of interval j at s."""
    w, dw, d2w, _ = _interp(s, j, cx, cf, cm)
    if use_log:
        z = cmath.exp(w)
        return z, dw * z, (d2w + dw * dw) * z
    return w, dw, d2w


@njit(cache=True, nogil=True, inline="always")
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


@kernel
def _pole_margin(z: complex, dz: complex, s: float, eta: float) -> tuple[float, float]:
    """(phi, dphi/ds): phi > 0 where the root z (slope dz at s = ln kH) is pole-dense (docs/physics.md §9).

    phi = min(|Re z| - SUBSONIC, 1 - eta kH Re(alpha_s) / POLE_ATTENUATION): finite eta, beyond the shear speed,
    and the lower block too thin to damp its thickness resonances (its real-axis poles). -1 for eta = inf.
    """
    if math.isinf(eta):
        return -1.0, 0.0
    a = abs(z.real) - SUBSONIC
    da = math.copysign(1.0, z.real) * dz.real
    alpha = _csqrt(_fix0((1.0 - z) * (1.0 + z)))
    q = math.exp(s)
    att = eta * q * alpha.real
    b = 1.0 - att / POLE_ATTENUATION
    if alpha == 0:
        return min(a, b), da
    datt = att + eta * q * (-z * _cinv(alpha) * dz).real
    return (a, da) if a <= b else (b, -datt / POLE_ATTENUATION)


@kernel
def _is_pole_dense(z: complex, s: float, eta: float) -> bool:
    """The root z at s = ln kH lies among the lower block's undamped real-axis poles (_pole_margin > 0)."""
    return _pole_margin(z, 0j, s, eta)[0] > 0.0


@kernel
def _sample_path(lo: float, hi: float, ns: np.ndarray, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray, nn: int,
                 use_log: bool, eta: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The path interpolant on [lo, hi] (inside the path) at NSUB + 1 points of every path interval (ends shared).

    Returns (s, z, d Im z/ds, interval index, regular) of the samples; regular: not pole-dense (_is_pole_dense).
    """
    j0 = _interval(lo, ns, nn)
    j1 = _interval(hi, ns, nn)
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
            reg[k] = not _is_pole_dense(z, s, eta)
            k += 1
    return xs, zs, gs, js, reg


# kinds of candidate maxima (_candidates)
C_IN = 0  # between samples k and k+1
C_LEFT = 1  # at the left end of a regular run starting at sample k (the range's start, or a pole-dense boundary)
C_RIGHT = 2  # at the right end of a regular run ending at sample k


@kernel
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


@kernel
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


@kernel
def _refine_peak(a: float, b: float, j: int, lo: float, hi: float, path: Path, p: Params,
                 rtol: float) -> tuple[float, float, complex, float]:
    """The local maximum of Im z in [a, b] (interval j; slope > 0 at a, <= 0 at b): (Im z, s, z, error of Im z).

    Located on the interpolant (Illinois on its slope, to S_TOL_FP), then the exact root there (solve_at) and one
    Newton correction of the location from the exact slope Im dz/ds and the interpolant's curvature (inside
    [lo, hi]); the larger of the two exact values is returned. NaN if the exact root is not certified.
    """
    ns, nz, nc, ne, cx, cf, cm, nn, use_log = path
    s0 = _slope_root(a, b, j, cx, cf, cm, use_log)
    z0, st, _, err0, dz0 = _solve_at(s0, ns, nz, nc, ne, cx, cf, cm, nn, use_log, p, rtol)
    if st != OK:
        return math.nan, math.nan, complex(math.nan, math.nan), math.nan
    d2 = _sample_at(s0, j, cx, cf, cm, use_log)[2].imag
    if d2 < 0.0 and cmath.isfinite(dz0):
        ds = -dz0.imag / d2
        if S_TOL_MAX < abs(ds) <= MAX_SHIFT and lo <= s0 + ds <= hi:
            z1, st1, _, err1, _ = _solve_at(s0 + ds, ns, nz, nc, ne, cx, cf, cm, nn, use_log, p, rtol)
            # the corrected location unless its value is lower beyond rounding (the maximum is flat)
            if st1 == OK and z1.imag >= z0.imag - FLAT_ULPS * EPS * abs(z0):
                if z1.imag >= z0.imag:
                    return z1.imag, s0 + ds, z1, err1
    return z0.imag, s0, z0, err0


@kernel
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


@kernel
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


@kernel
def _on_path(s: float, which: int, ns: np.ndarray, nz: np.ndarray, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray,
             nn: int, use_log: bool, eta: float) -> float:
    """Im z (which = Z_IM) or _pole_margin (Z_PD) of the path interpolant at s (NaN outside the path)."""
    if which == Z_IM:
        return _im_at(s, ns, nz, cx, cf, cm, nn, use_log)
    j = _interval(s, ns, nn)
    if j < 0:
        return math.nan
    z, dz, _ = _sample_at(s, j, cx, cf, cm, use_log)
    return _pole_margin(z, dz, s, eta)[0]


@kernel
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


@kernel
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


@kernel
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


@kernel
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


@kernel
def _growth_slopes(z: complex, s: float, p: Params) -> tuple[float, float]:
    """(d Im z/d ln gamma, d Im z/d ln eta) of the root z at s = ln kH: Im(-F_t/F_z), which is the slope of the max
    growth in that parameter (the maximum's location may move, its value changes only through F). dF/d ln gamma =
    gamma (G_x + i f G_y); dF/d ln eta by central difference (ETA_FD); 0 for eta = inf."""
    q = math.exp(s)
    _, dfv, _, _ = _weighted_dispersion(z, q, p.gamma, 1.0, p)
    fg = _weighted_dispersion(z, q, p.gamma, 0.0, p)[0]
    if not (cmath.isfinite(dfv) and cmath.isfinite(fg)) or dfv == 0:
        return math.nan, math.nan
    inv = _cinv(dfv)
    dg_gamma = (-fg * inv).imag
    if math.isinf(p.eta):
        return dg_gamma, 0.0
    up = Params(p.gamma, p.f, p.beta, p.eta * math.exp(ETA_FD), p.delta, p.xi)
    dn = Params(p.gamma, p.f, p.beta, p.eta * math.exp(-ETA_FD), p.delta, p.xi)
    fe = (_weighted_dispersion(z, q, p.gamma, 1.0, up)[0] - _weighted_dispersion(z, q, p.gamma, 1.0, dn)[0]) / (
        2.0 * ETA_FD)
    return dg_gamma, (-fe * inv).imag


@kernel
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


@kernel
def _lost_at_cut(z: complex, eta: float) -> bool:
    """eta = inf: the last root of a path lost downward lies on the cut's lower lip (|Re z| > 1, Im z < 0, |Im z| <=
    CUT_LOSS |z|): the branch leaves the physical sheet there (docs/physics.md §9), it does not become ambiguous."""
    return math.isinf(eta) and abs(z.real) > SUBSONIC and z.imag < 0.0 and -z.imag <= CUT_LOSS * abs(z)


@kernel
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
    path, code = build_path(s_grid[0], s_grid[m - 1], z_r, p, PRED_TOL, _map_node_tol(rtol))
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


# ----------------------------------------------------------------------------- entry points (flat arrays)
@kernel
def growth_many(s_grid: np.ndarray, gamma: np.ndarray, f: np.ndarray, beta: np.ndarray, eta: np.ndarray,
                delta: np.ndarray, xi: np.ndarray, rtol: float, out: np.ndarray) -> None:
    """growth_one over flattened parameter sets (one chunk of a stability map); out: (NOUT, n)."""
    for i in range(gamma.shape[0]):
        p = Params(gamma[i], f[i], beta[i], eta[i], delta[i], xi[i])
        r = growth_one(s_grid, rayleigh_z(beta[i]), p, rtol)
        for k in range(NOUT):
            out[k, i] = r[k]


@kernel
def growth_point(s_grid: np.ndarray, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float,
                 rtol: float) -> tuple[float, float, float, float, float, float, float, float, float, float, float,
                                       float]:
    """growth_one for one parameter set given as scalars (the threshold solver's evaluations)."""
    return growth_one(s_grid, rayleigh_z(beta), Params(gamma, f, beta, eta, delta, xi), rtol)


@njit(cache=True, nogil=True)
def branch_many(s_req: np.ndarray, gamma: np.ndarray, f: np.ndarray, beta: np.ndarray, eta: np.ndarray,
                delta: np.ndarray, xi: np.ndarray, rtol: float, z_out: np.ndarray, status: np.ndarray,
                resid: np.ndarray, err: np.ndarray) -> None:
    """branch_solve for many parameter sets (rows of the 2-D outputs)."""
    for i in range(gamma.shape[0]):
        p = Params(gamma[i], f[i], beta[i], eta[i], delta[i], xi[i])
        branch_solve(s_req, rayleigh_z(beta[i]), p, rtol, z_out[i], status[i], resid[i], err[i])


@njit(cache=True, nogil=True)
def branch_one(s_req: np.ndarray, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float,
               rtol: float, z_out: np.ndarray, status: np.ndarray, resid: np.ndarray, err: np.ndarray) -> None:
    """branch_solve for one parameter set given as scalars (1-D outputs)."""
    branch_solve(s_req, rayleigh_z(beta), Params(gamma, f, beta, eta, delta, xi), rtol, z_out, status, resid, err)


@njit(cache=True)
def response_many(z: np.ndarray, q: np.ndarray, beta: np.ndarray, eta: np.ndarray, gx: np.ndarray,
                  gy: np.ndarray, dgx: np.ndarray, dgy: np.ndarray) -> None:
    """Vector loop over flattened broadcast inputs."""
    for i in range(z.shape[0]):
        gx[i], gy[i], dgx[i], dgy[i], _, _, _ = response(z[i], q[i], beta[i], eta[i])


@njit(cache=True)
def dispersion_many(z: np.ndarray, q: np.ndarray, gamma: np.ndarray, f: np.ndarray, beta: np.ndarray,
                    eta: np.ndarray, delta: np.ndarray, xi: np.ndarray, fo: np.ndarray, dfo: np.ndarray,
                    sco: np.ndarray) -> None:
    """Vector loop over flattened broadcast inputs."""
    for i in range(z.shape[0]):
        fo[i], dfo[i], sco[i] = dispersion_eval(z[i], q[i], gamma[i], f[i], beta[i], eta[i], delta[i], xi[i])


# ----------------------------------------------------------------------------- neutral modes (thresholds, docs §9)
P_GAMMA = 0  # the threshold parameter of neutral_mode: t = ln gamma ...
P_ETA = 3  # ... or t = ln eta (rows of growth_chunk's parameter layout)
NEUTRAL_ITERS = 40  # Newton iterations of a neutral mode (quadratic from a good start: a bound, not a budget)
NEUTRAL_FD = 1e-5  # step (relative in Re z, absolute in s and t) of the central differences of the slope equation
NEUTRAL_STEP = 0.5  # largest Newton step in s = ln kH and in t (larger steps are scaled down: damping)
NEUTRAL_TOL = 1e-12  # converged when the last step is below this relative to max(|x|, 1e-3), max(1, |t|) ...
NEUTRAL_TOL_S = 1e-9  # ... and in s below this (t is stationary in s at the neutral mode: s matters to 2nd order)


@kernel
def _with_param(p: Params, which: int, t: float) -> Params:
    """p with gamma (which = P_GAMMA) or eta (P_ETA) set to e^t."""
    v = math.exp(t)
    if which == P_GAMMA:
        return Params(v, p.f, p.beta, p.eta, p.delta, p.xi)
    return Params(p.gamma, p.f, p.beta, v, p.delta, p.xi)


@kernel
def _neutral_terms(x: float, s: float, t: float, which: int,
                   p: Params) -> tuple[complex, complex, complex, complex, float]:
    """F, dF/dz, dF/ds, dF/dt at the real z = x, s = ln kH, t = ln gamma or ln eta, and the rounding scale of F.

    dF/d ln gamma = gamma (G_x + i f G_y) exactly; dF/d ln eta by a central difference of step ETA_FD (Newton's
    Jacobian only: the equations themselves are exact)."""
    pp = _with_param(p, which, t)
    q = math.exp(s)
    z = complex(x, 0.0)
    fv, dfv, sc, fq = _weighted_dispersion(z, q, pp.gamma, 1.0, pp)
    if which == P_GAMMA:
        ft = _weighted_dispersion(z, q, pp.gamma, 0.0, pp)[0]
    else:
        fp = _weighted_dispersion(z, q, pp.gamma, 1.0, _with_param(p, which, t + ETA_FD))[0]
        fm = _weighted_dispersion(z, q, pp.gamma, 1.0, _with_param(p, which, t - ETA_FD))[0]
        ft = (fp - fm) / (2.0 * ETA_FD)
    return fv, dfv, q * fq, ft, sc


@kernel
def _slope_eq(x: float, s: float, t: float, which: int, p: Params) -> float:
    """The third equation of a neutral mode: Im(dF/ds / dF/dz) = -Im dz/ds (zero where Im z is stationary in s)."""
    pp = _with_param(p, which, t)
    q = math.exp(s)
    _, dfv, _, fq = _weighted_dispersion(complex(x, 0.0), q, pp.gamma, 1.0, pp)
    if dfv == 0:
        return math.nan
    return (q * fq * _cinv(dfv)).imag


@kernel
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


@kernel
def _neutral_system(x: float, s: float, t: float, which: int, edge: bool, p: Params, a: np.ndarray,
                    r: np.ndarray) -> tuple[int, float]:
    """Newton's linear system of a neutral mode at (x, s, t): fills a and r (r = -residual); (size, |F|/scale).

    Unknowns (x, t) at fixed s for an edge mode (Im z = 0 at an end of the kH range: 2 equations Re F = Im F = 0),
    else (x, s, t) with the slope equation (_slope_eq) as the third, its derivatives by central differences.
    Size 0 if F or its derivatives are not finite."""
    fv, fz, fs, ft, sc = _neutral_terms(x, s, t, which, p)
    if not (cmath.isfinite(fv) and cmath.isfinite(fz) and cmath.isfinite(fs) and cmath.isfinite(ft)) or fz == 0:
        return 0, math.inf
    a[0, 0], a[1, 0], r[0], r[1] = fz.real, fz.imag, -fv.real, -fv.imag
    if not sc > 0.0:
        return 0, math.inf
    if edge:
        a[0, 1], a[1, 1] = ft.real, ft.imag
        return 2, abs(fv) / sc
    a[0, 1], a[1, 1], a[0, 2], a[1, 2] = fs.real, fs.imag, ft.real, ft.imag
    r[2] = -(fs * _cinv(fz)).imag
    hx = NEUTRAL_FD * max(abs(x), 1e-3)
    h = NEUTRAL_FD
    a[2, 0] = (_slope_eq(x + hx, s, t, which, p) - _slope_eq(x - hx, s, t, which, p)) / (2.0 * hx)
    a[2, 1] = (_slope_eq(x, s + h, t, which, p) - _slope_eq(x, s - h, t, which, p)) / (2.0 * h)
    a[2, 2] = (_slope_eq(x, s, t + h, which, p) - _slope_eq(x, s, t - h, which, p)) / (2.0 * h)
    return 3, abs(fv) / sc


@kernel
def neutral_mode(x0: float, s0: float, t0: float, which: int, edge: bool, gamma: float, f: float, beta: float,
                 eta: float, delta: float, xi: float) -> tuple[float, float, float, bool, int, float, float, float]:
    """A neutral mode by Newton's method from (x0, s0, t0): real z = x, s = ln kH, t = ln gamma (which = P_GAMMA)
    or ln eta (P_ETA) with F(x; e^s) = 0 and Im dz/ds = 0 (or, for edge = True, s fixed at an end of the range).

    Returns (x, s, t, converged, iterations, |F|/scale, Im dz/dt, Re dz/dt): dz/dt = -F_t/F_z at the mode, whose
    imaginary part is the slope of the max growth across the threshold (its sign: the crossing's direction).
    Converged when the last step is below NEUTRAL_TOL (relative) in x and t and NEUTRAL_TOL_S in s; steps in s
    and t are scaled down to NEUTRAL_STEP. The parameter being solved for is ignored in the arguments.
    """
    p = Params(gamma, f, beta, eta, delta, xi)
    a = np.empty((3, 3))
    r = np.empty(3)
    x, s, t = x0, s0, t0
    for it in range(NEUTRAL_ITERS):
        n, res = _neutral_system(x, s, t, which, edge, p, a, r)
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
            fv, fz, _, ft, sc = _neutral_terms(x, s, t, which, p)
            if fz == 0 or not sc > 0.0:
                break
            dzdt = -ft * _cinv(fz)
            return x, s, t, True, it + 1, abs(fv) / sc, dzdt.imag, dzdt.real
    return x, s, t, False, NEUTRAL_ITERS, math.nan, math.nan, math.nan
