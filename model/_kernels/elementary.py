"""Complex elementary functions of the kernels and the series behind the response functions (docs/physics.md §2).

Overflow-safe complex arithmetic several times faster than the library's (|w| and 1/w without hypot, the principal
sqrt, exp and log; each falls back on the library's function where squares could over- or underflow), tanh and sech
without overflow, and the functions the cancellation-free response functions are built from: g(u) =
tanh(sqrt u)/sqrt u (even in sqrt u, so without branch cut), its divided differences g[u1, u2] with their
derivatives (Taylor series for small arguments, the tanh-difference identity for close large ones), and psi(t) =
expm1(t)/t.
"""

from __future__ import annotations

import cmath
import math
from fractions import Fraction

import numpy as np

from ._common import jitted

EPS = 2.220446049250313e-16


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


@jitted(inline="always")
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


@jitted(inline="always")
def fix0(u: complex) -> complex:
    """Turn a negative zero imaginary part into +0 (principal sqrt of a negative real -> +i)."""
    return complex(u.real, u.imag + 0.0)


@jitted
def _tanh_sech(w: complex) -> tuple[complex, complex]:
    """tanh(w) and sech(w) without overflow for any w (exponentials of non-positive real part)."""
    s = 1.0 if w.real >= 0.0 else -1.0
    e1 = cmath.exp(-s * w)
    e = e1 * e1
    inv_den = 1.0 / (1.0 + e)
    return s * (1.0 - e) * inv_den, 2.0 * e1 * inv_den


@jitted
def _g(u: complex) -> tuple[complex, complex]:
    """g(u) = tanh(sqrt u)/sqrt u and g'(u)."""
    a = cabs(u)
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


@jitted
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


@jitted
def divdiff(u1: complex, u2: complex) -> tuple[complex, complex, complex, complex, complex, complex, complex]:
    """g(u1), g'(u1), g(u2), g'(u2), g[u1,u2], d g[u1,u2]/du1, d g[u1,u2]/du2 without cancellation.

    Small arguments: Taylor series. Otherwise with w = sqrt(u) (the root of u2 nearest w1: g is even),
    D = g[u1, u2] = (w1 X/d - tanh w1) / (w1 w2 (w1 + w2)), d = w2 - w1, X = tanh w2 - tanh w1, where
    X/d = sinh(d)/d sech w1 sech w2 for |d| < SHC_MAX (no cancellation) and (tanh w2 - tanh w1)/d otherwise.
    """
    a1 = cabs(u1)
    a2 = cabs(u2)
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
    if cabs(du) >= DIVDIFF_FAR * big:
        g1, d1 = _g(u1)
        g2, d2 = _g(u2)
        dd = (g2 - g1) / du
        return g1, d1, g2, d2, dd, (dd - d1) / du, (d2 - dd) / du
    w1 = cmath.sqrt(u1)
    w2 = cmath.sqrt(u2)
    if cabs(w2 + w1) < cabs(w2 - w1):  # g is even: take the square root nearest w1
        w2 = -w2
    th1, s1 = _tanh_sech(w1)
    th2, s2 = _tanh_sech(w2)
    g1 = th1 / w1
    g2 = th2 / w2
    d1 = (w1 * s1 * s1 - th1) / (2.0 * w1 * u1)
    d2 = (w2 * s2 * s2 - th2) / (2.0 * w2 * u2)
    d = w2 - w1
    if cabs(d) < SHC_MAX:
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


@jitted
def psi_pair(t: complex) -> tuple[complex, complex]:
    """psi(t) = expm1(t)/t and psi'(t) for |t| < PSI_MAX (Taylor series to t^16: truncation < 1e-19)."""
    c = _PSICOEF
    n = c.shape[0]
    val = c[n - 1] + 0j
    der = (n - 1) * c[n - 1] + 0j
    for k in range(n - 2, 0, -1):
        val = val * t + c[k]
        der = der * t + k * c[k]
    return val * t + c[0], der


@jitted(inline="always")
def _squares_safe(w: complex) -> bool:
    """Re w^2 + Im w^2 neither overflows nor underflows (the fast forms below; else the library's functions)."""
    m = max(abs(w.real), abs(w.imag))
    return CABS_LO < m < CABS_HI


@jitted(inline="always")
def cabs(w: complex) -> float:
    """|w| by sqrt(re^2 + im^2) (several times faster than hypot), hypot where squares could over/underflow."""
    if _squares_safe(w):
        return math.sqrt(w.real * w.real + w.imag * w.imag)
    return abs(w)


@jitted(inline="always")
def cinv(w: complex) -> complex:
    """1/w with one real division (conj(w)/|w|^2), the library's division where |w|^2 could over/underflow."""
    if _squares_safe(w):
        d = 1.0 / (w.real * w.real + w.imag * w.imag)
        return complex(w.real * d, -w.imag * d)
    return 1.0 / w


@jitted(inline="always")
def csqrt(u: complex) -> complex:
    """Principal sqrt(u) (+i sqrt|u| on the negative real axis with Im u = +0) with the modulus as
    sqrt(re^2 + im^2); the library's sqrt where the squares could over/underflow (and at u = 0)."""
    if not _squares_safe(u):
        return cmath.sqrt(u)
    a = cabs(u)
    if u.real >= 0.0:
        t = math.sqrt(0.5 * (a + u.real))
        return complex(t, 0.5 * u.imag / t)
    t = math.sqrt(0.5 * (a - u.real))
    return complex(0.5 * abs(u.imag) / t, math.copysign(t, u.imag))


EXP_ZERO = -746.0  # exp(x) is exactly 0 in double precision below this


@jitted(inline="always")
def cexp(w: complex) -> complex:
    """exp(w), exactly 0 without the trigonometric functions where exp(Re w) underflows to 0."""
    if w.real < EXP_ZERO:
        return 0j
    return cmath.exp(w)


@jitted(inline="always")
def clog(w: complex) -> complex:
    """Principal ln w: ln|w| as ln(|w|^2)/2 (no hypot), the library's log where |w|^2 could over/underflow."""
    if _squares_safe(w):
        return complex(0.5 * math.log(w.real * w.real + w.imag * w.imag), math.atan2(w.imag, w.real))
    return cmath.log(w)


@jitted(inline="always")
def real_root(x: float, order: float) -> float:
    """x ** (1/order) for the predictor orders 2 and 4 (square roots instead of pow)."""
    r = math.sqrt(x)
    return r if order == 2.0 else math.sqrt(r)


@jitted(inline="always")
def abs1(w: complex) -> float:
    """|Re w| + |Im w|: a cheap magnitude (within sqrt 2 of |w|) for rounding scales."""
    return abs(w.real) + abs(w.imag)
