"""Where the roots of F can be: a lower bound of Re[F/(iz)] at large |z| and the window it gives (docs/physics.md §14).

For Im z >= 0 and |z| = r >= R0 = R0_FACTOR/beta (> 1/beta, so that the series of alpha_s/(-iz) and
alpha_d/(-i beta z) in 1/z^2 converge), Eq. implicit_spectrum with Eq. Gs_general and Eq. delta f RSF reads exactly

    F/(iz) = S + gamma [u A_s + v A_d] - (2 gamma f / z) w (B_d - B_s),
    u = (1 - 2/z^2)^2 / sqrt(1 - 1/z^2),  v = 4 beta sqrt(1 - 1/(beta z)^2) / z^2,  w = 1 - 2/z^2,
    A_j = 1/(T1_j + T2_j),  B_j = T2_j A_j,   T1_j = tanh(kH alpha_j), T2_j = tanh(eta kH alpha_j) (1 at eta = inf).

With Re alpha_s >= Im z and Re alpha_d >= beta Im z (proved in §14) every term is bounded by a function of r and of
y = Im z, monotone in both (:func:`lower_bound`); where the bound is positive, F has no zero. :func:`exclusion_radius`
gives rho(y): no root with Im z >= y has |z| >= rho(y); :func:`top_of_roots` the height above which there is none.
"""

from __future__ import annotations

import math

from ._common import jitted
from .records import Params

R0_FACTOR = 1.05  # the bound is used for |z| >= R0_FACTOR / beta (it needs |z| > 1/beta)
RHO_MAX = 1e12  # an exclusion radius beyond this is reported as inf (no finite window)
BISECTIONS = 60  # bisection steps of rho and of the top (the bracket ends are always valid: no accuracy is lost)
RHO_TOL = 1e-7  # relative width at which the bisection of rho stops (its upper end is returned: the safe side)
TOP_TOL = 1e-5  # ... and that of the top of the roots (a window a relative 1e-5 taller costs nothing)


@jitted(inline="always")
def _block_bounds(u1: float, eta: float) -> tuple[float, float, float]:
    """Bounds for one wave type j with Re(kH alpha_j) >= u1 > 0: (max |A_j|, min Re A_j, max |B_j - 1/2|).

    With a = exp(-2 kH alpha_j), b = exp(-2 eta kH alpha_j), |a| <= r1 = exp(-2 u1), |b| <= r2 = exp(-2 eta u1):
    A = (1 + a)(1 + b)/(2 (1 - ab)), B - 1/2 = (a - b)/(2 (1 - ab)), and Re A >= the larger of
    t1^2 t2^2/(t1 + t2) (Re tanh >= tanh u, |tanh| <= coth u) and (1 - r1)/2 - |1 - T2| max|A| / (1 + t1).
    """
    r1 = math.exp(-2.0 * u1)
    if math.isinf(eta):
        return 0.5 * (1.0 + r1), 0.5 * (1.0 - r1), 0.5 * r1
    u2 = eta * u1
    r2 = math.exp(-2.0 * u2)
    den = -2.0 * math.expm1(-2.0 * (u1 + u2))  # 2 (1 - r1 r2), without cancellation
    if den <= 0.0:
        return math.inf, 0.0, math.inf
    a_max = (1.0 + r1) * (1.0 + r2) / den
    t1 = math.tanh(u1)
    t2 = math.tanh(u2)
    re_a = t1 * t1 * t2 * t2 / (t1 + t2)
    if r2 < 1.0:
        re_a = max(re_a, 0.5 * (1.0 - r1) - 2.0 * r2 / (1.0 - r2) * a_max / (1.0 + t1))
    return a_max, re_a, (r1 + r2) / den


@jitted
def lower_bound(r: float, y: float, q: float, p: Params) -> float:
    """A lower bound of Re[F(z)/(iz)] over all z with |z| >= r and Im z >= y (r >= R0_FACTOR/beta, y >= 0).

    Non-decreasing in r and in y (docs/physics.md §14): Re S >= S_lo, Re(u A_s) >= Re A_s - |u - 1| |A_s| with
    |u - 1| <= (1 + 2e)^2 / sqrt(1 - e) - 1 (e = 1/r^2, a majorant series), |v| <= 4 beta sqrt(1 + 1/(beta r)^2)/r^2,
    |w| <= 1 + 2e, and the block bounds of :func:`_block_bounds` at u1 = kH y (shear) and kH beta y (dilatation).
    """
    e = 1.0 / (r * r)
    m = (1.0 + 2.0 * e) ** 2 / math.sqrt(1.0 - e) - 1.0
    a_s, re_s, b_s = _block_bounds(q * y, p.eta)
    a_d, _, b_d = _block_bounds(q * p.beta * y, p.eta)
    s_lo = 1.0
    if p.delta != 1.0:
        t = p.xi * q * y
        xr = p.xi * q * r
        s_lo = 1.0 - (1.0 - p.delta) * max((1.0 + t) / (1.0 + 2.0 * t + xr * xr), 1.0 / (1.0 + xr))
    v = 4.0 * p.beta * math.sqrt(1.0 + 1.0 / (p.beta * r) ** 2) * e
    bound = s_lo + p.gamma * re_s - p.gamma * (m * a_s + v * a_d)
    if p.eta != 1.0 and p.f != 0.0:  # G_y = 0 exactly for eta = 1 (B_d = B_s = 1/2)
        bound -= 2.0 * p.gamma * abs(p.f) / r * (1.0 + 2.0 * e) * (b_s + b_d)
    return bound


@jitted
def exclusion_radius(y: float, q: float, p: Params) -> float:
    """rho(y): no root of F with Im z >= y has |z| >= rho(y) (R0_FACTOR/beta at least; inf if beyond RHO_MAX).

    The smallest r (to the bisection's last step, taken on the safe side) with :func:`lower_bound`(r, y) > 0.
    """
    lo = R0_FACTOR / p.beta
    if lower_bound(lo, y, q, p) > 0.0:
        return lo
    hi = 2.0 * lo
    while lower_bound(hi, y, q, p) <= 0.0:
        lo = hi
        hi *= 2.0
        if hi > RHO_MAX:
            return math.inf
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if lower_bound(mid, y, q, p) > 0.0:
            hi = mid
        else:
            lo = mid
        if hi - lo <= RHO_TOL * hi:
            break
    return hi


@jitted
def top_of_roots(y_min: float, q: float, p: Params) -> float:
    """A height above which F has no root: the smallest y >= y_min (to the bisection's step, on the safe side) with
    exclusion_radius(y) <= y (a root with Im z >= y has |z| >= y). inf if exclusion_radius(y_min) is."""
    lo = y_min
    hi = exclusion_radius(y_min, q, p)
    if math.isinf(hi) or hi <= lo:
        return max(hi, lo)
    for _ in range(BISECTIONS):
        mid = 0.5 * (lo + hi)
        if exclusion_radius(mid, q, p) <= mid:
            hi = mid
        else:
            lo = mid
        if hi - lo <= TOP_TOL * hi:
            break
    return hi
