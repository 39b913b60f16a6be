"""Response functions G_x, G_y and the dispersion function F with their derivatives (docs/physics.md §2).

Cancellation-free forms (docs/physics.md §2)
--------------------------------------------
Finite eta. With u_j = alpha_j^2 (u_s = 1 - z^2, u_d = 1 - beta^2 z^2) and g(u) = tanh(sqrt u)/sqrt u
(even in sqrt u, so no branch cut), write g1(u) = q g(q^2 u), g2(u) = eta q g(eta^2 q^2 u) and
P = g1 + g2, so that T1_j + T2_j = alpha_j P(u_j). Eq. S-G_gen becomes

    G_x = 4 (1 - beta^2) P[u_s, u_d] / (P_s P_d) + z^2 / (u_s P_s)
    G_y = 2 (2 - z^2) (1 - beta^2) (g1_s g2[u_s, u_d] - g2_s g1[u_s, u_d]) / (P_s P_d)

where h[u_s, u_d] is the divided difference (h(u_d) - h(u_s))/(u_d - u_s); u_d - u_s = (1-beta^2) z^2
cancelled the z^-2 prefactor analytically. Divided differences are computed without cancellation
(:mod:`model._kernels.elementary`). G_y is exactly 0 for eta = 1.

Infinite eta (T2 = +1). With h_j = 1/(1 + tanh(q alpha_j)) = (1 + e^{-2 q alpha_j})/2 and the
Rayleigh function over z^2, Rt = z^2 - 4 + 4 (1 + beta^2 - beta^2 z^2)/(1 + alpha_s alpha_d):

    G_x = Rt h_s / alpha_s + 4 alpha_d Hd,      G_y = -2 (2 - z^2) Hd,
    Hd  = (h_s - h_d)/z^2 = q (1-beta^2) e^{-2 q alpha_s} psi(t) / (alpha_s + alpha_d),
    t   = -2 q (1-beta^2) z^2/(alpha_s + alpha_d),  psi(t) = expm1(t)/t.

Where eta q Re(alpha_j) > HALF_SPACE_ARG the lower block is a half-space to rounding (tanh = 1 in
double precision) and the finite-eta kernel hands over to the eta = inf one. Every kernel also gives
the analytic q-derivatives, for the branch slope dz/d(ln kH) = -kH F_kH / F_z.
"""

from __future__ import annotations

import math

import numpy as np

from ._common import jitted
from .elementary import PSI_MAX, abs1, cabs, cexp, cinv, csqrt, divdiff, fix0, psi_pair
from .records import Params

HALF_SPACE_ARG = 22.0  # eta kH Re(alpha) above which tanh(eta kH alpha) = 1 in double precision (e^-44 < 1e-19)


@jitted
def response_inf(
    z: complex, q: float, beta: float
) -> tuple[complex, complex, complex, complex, complex, complex, float]:
    """G_x, G_y, dG_x/dz, dG_y/dz, dG_x/dq, dG_y/dq and a rounding scale for eta = inf (Eqs. Gx_LSA, Gy_LSA)."""
    us = fix0((1.0 - z) * (1.0 + z))
    ud = fix0((1.0 - beta * z) * (1.0 + beta * z))
    return response_inf_alpha(z, csqrt(us), csqrt(ud), q, beta)


@jitted
def response_inf_alpha(
    z: complex, a_s: complex, a_d: complex, q: float, beta: float
) -> tuple[complex, complex, complex, complex, complex, complex, float]:
    """As :func:`response_inf`, with alpha_s and alpha_d given (the physical sheet: their principal values; a chart
    across a cut near a branch point: their continuations, :func:`chart_point`). The z-derivatives take
    d alpha_j/dz = -beta_j^2 z / alpha_j, true on every sheet."""
    b2 = beta * beta
    z2 = z * z
    inv_as = cinv(a_s)
    inv_ad = cinv(a_d)
    das = -z * inv_as
    dad = -b2 * z * inv_ad
    es = cexp(-2.0 * q * a_s)
    ed = cexp(-2.0 * q * a_d)
    des = -2.0 * q * das * es
    ded = -2.0 * q * dad * ed
    hs = 0.5 * (1.0 + es)
    dhs = 0.5 * des
    # Rayleigh function over z^2
    inv_one = cinv(1.0 + a_s * a_d)
    cnum = 1.0 + b2 - b2 * z2
    c4 = 4.0 * cnum * inv_one
    rt = z2 - 4.0 + c4
    dprod = das * a_d + a_s * dad
    drt = 2.0 * z + 4.0 * (-2.0 * b2 * z - cnum * dprod * inv_one) * inv_one
    # Hd = (h_s - h_d)/z^2
    inv_sum = cinv(a_s + a_d)
    dssum = das + dad
    k = -2.0 * q * (1.0 - b2)
    t = k * z2 * inv_sum
    dt = k * (2.0 * z - z2 * dssum * inv_sum) * inv_sum
    # q-derivatives: d e_j/dq = -2 alpha_j e_j, dt/dq = t/q
    qes = -2.0 * a_s * es
    qed = -2.0 * a_d * ed
    qt = -2.0 * (1.0 - b2) * z2 * inv_sum
    if abs1(t) < PSI_MAX:
        ps, dps = psi_pair(t)
        qv = es * ps
        dqv = des * ps + es * dps * dt
        qqv = qes * ps + es * dps * qt
    else:
        inv_t = cinv(t)
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
    scale = (abs1(z2) + 4.0 + abs1(c4)) * abs1(hs_as) + abs1(gx_b)
    return gx, gy, dgx, dgy, qgx, qgy, scale


@jitted
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
    us = fix0((1.0 - z) * (1.0 + z))
    ud = fix0((1.0 - beta * z) * (1.0 + beta * z))
    if eta != 1.0:
        # Re sqrt(u) = sqrt((|u| + Re u)/2)
        re_min = min(cabs(us) + us.real, cabs(ud) + ud.real)
        if re_min > 0.0 and eta * q * math.sqrt(0.5 * re_min) > HALF_SPACE_ARG:
            return response_inf(z, q, beta)
    dus = -2.0 * z
    dud = -2.0 * b2 * z
    a = q * q
    eq = eta * q
    b = eq * eq
    # upper block, height H: g1 = q g(q^2 u)
    gs, gds, gd, gdd, dd, dd1, dd2 = divdiff(a * us, a * ud)
    q3 = q * a
    q5 = q3 * a
    g1s = q * gs
    g1d = q * gd
    dg1s = q3 * gds * dus
    dg1d = q3 * gdd * dud
    d1 = q3 * dd
    dd1z = q5 * (dd1 * dus + dd2 * dud)
    # lower block, height eta H: g2 = eta q g(eta^2 q^2 u)
    hs, hds, hd, hdd, ee, ee1, ee2 = divdiff(b * us, b * ud)
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
    scale = cabs(gx_a) + cabs(gx_b) + 2.0 * cabs(2.0 - z2) * c * (cabs(g1s * d2) + cabs(g2s * d1)) / cabs(pp)
    return gx, gy, dgx, dgy, qgx, qgy, scale


@jitted
def response(
    z: complex, q: float, beta: float, eta: float
) -> tuple[complex, complex, complex, complex, complex, complex, float]:
    """Dispatch on eta (inf -> half-space lower block): G_x, G_y, their z- and q-derivatives, rounding scale."""
    if math.isinf(eta):
        return response_inf(z, q, beta)
    return response_fin(z, q, beta, eta)


# a chart's variable is v = w + CHART_ORIGIN: its boxes |w| < 1 lie above the real v axis, and the lines that split
# a box centred on Re v = 0, Im v = 1 (at dyadic fractions of it) never pass through w = 0, where 1/alpha is infinite
CHART_ORIGIN = complex(0.0123456789, 1.0 + 0.0098765432)


@jitted
def chart_point(v: complex, beta: float, chart: int) -> tuple[complex, complex, complex, complex]:
    """(z, alpha_s, alpha_d, dz/dv) at the point v of a chart across the cuts beside a branch point b (eta = inf;
    docs/physics.md §14.7). w = v - CHART_ORIGIN is the local uniformizing variable: chart 1, 2: b = +-1/beta,
    w = alpha_d, z = b sqrt(1 - w^2) and alpha_s = -i sgn(b) sqrt(z^2 - 1) (its continuation from Im z > 0 across
    |Re z| > 1); chart 3, 4: b = +-1, w = alpha_s, z = b sqrt(1 - w^2), alpha_d principal. F is analytic in w
    near w = 0 (both sides of the cut); the physical sheet with Im z > 0 is Re w > 0, Im z > 0."""
    w = v - CHART_ORIGIN
    sgn = 1.0 if chart == 1 or chart == 3 else -1.0
    r = csqrt(fix0((1.0 - w) * (1.0 + w)))
    if chart <= 2:
        z = sgn * r / beta
        a_d = w
        a_s = -1j * sgn * csqrt(fix0((z - 1.0) * (z + 1.0)))
        dzdv = -w / (beta * beta * z)
    else:
        z = sgn * r
        a_s = w
        a_d = csqrt(fix0((1.0 - beta * z) * (1.0 + beta * z)))
        dzdv = -w / z
    return z, a_s, a_d, dzdv


@jitted
def weighted_dispersion(z: complex, q: float, wg: float, wz: float, p: Params) -> tuple[complex, complex, float,
                                                                                           complex]:
    """wg (G_x + i f G_y) + wz i z S with S = 1 + (Delta - 1)/(1 - i xi z kH): value, dF/dz, rounding scale, dF/dkH.

    The rounding scale is the sum of the magnitudes of the terms plus |z F'| (the change of F under a
    relative perturbation of z by one unit: no evaluation can resolve F below eps times this).

    Internal: p.eta = -c (c = 1..4) evaluates F in the chart c of :func:`chart_point` (z is then the chart's v, and
    dF/dz is dF/dv); the physical parameters never take that value (eta > 0 is validated).
    """
    f = p.f
    delta = p.delta
    xi = p.xi
    dzdv = 1.0 + 0j
    if p.eta < 0.0:
        z, a_s, a_d, dzdv = chart_point(z, p.beta, int(-p.eta))
        gx, gy, dgx, dgy, qgx, qgy, sc = response_inf_alpha(z, a_s, a_d, q, p.beta)
    else:
        gx, gy, dgx, dgy, qgx, qgy, sc = response(z, q, p.beta, p.eta)
    if delta == 1.0:
        sf = 1.0 + 0j
        dsf = 0j
        qsf = 0j
        sabs = 1.0
    else:
        inv_den = cinv(1.0 - 1j * xi * z * q)
        sf = 1.0 + (delta - 1.0) * inv_den
        dsf = (delta - 1.0) * (1j * xi * q) * inv_den * inv_den
        qsf = (delta - 1.0) * (1j * xi * z) * inv_den * inv_den
        sabs = 1.0 + abs1((delta - 1.0) * inv_den)
    fval = wg * (gx + 1j * f * gy) + wz * 1j * z * sf
    dfval = wg * (dgx + 1j * f * dgy) + wz * 1j * (sf + z * dsf)
    qfval = wg * (qgx + 1j * f * qgy) + wz * 1j * z * qsf
    scale = wg * (sc + abs1(f * gy)) + wz * abs1(z) * sabs + abs1(z * dfval)
    if p.eta < 0.0:
        dfval = dfval * dzdv
    return fval, dfval, scale, qfval


@jitted
def dispersion_eval(
    z: complex, q: float, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float
) -> tuple[complex, complex, float]:
    """F(z; q) of Eq. implicit_spectrum with Eq. delta f RSF, dF/dz, and the rounding scale of F."""
    fv, dfv, sc, _ = weighted_dispersion(z, q, gamma, 1.0, Params(gamma, f, beta, eta, delta, xi))
    return fv, dfv, sc


@jitted
def dispersion_dq(
    z: complex, q: float, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float
) -> complex:
    """dF/dkH of Eq. implicit_spectrum at fixed z (gives the branch slope dz/dkH = -F_kH / F_z)."""
    return weighted_dispersion(z, q, gamma, 1.0, Params(gamma, f, beta, eta, delta, xi))[3]


@jitted
def response_many(z: np.ndarray, q: np.ndarray, beta: np.ndarray, eta: np.ndarray, gx: np.ndarray,
                  gy: np.ndarray, dgx: np.ndarray, dgy: np.ndarray) -> None:
    """Vector loop over flattened broadcast inputs."""
    for i in range(z.shape[0]):
        gx[i], gy[i], dgx[i], dgy[i], _, _, _ = response(z[i], q[i], beta[i], eta[i])


@jitted
def dispersion_many(z: np.ndarray, q: np.ndarray, gamma: np.ndarray, f: np.ndarray, beta: np.ndarray,
                    eta: np.ndarray, delta: np.ndarray, xi: np.ndarray, fo: np.ndarray, dfo: np.ndarray,
                    sco: np.ndarray) -> None:
    """Vector loop over flattened broadcast inputs."""
    for i in range(z.shape[0]):
        fo[i], dfo[i], sco[i] = dispersion_eval(z[i], q[i], gamma[i], f[i], beta[i], eta[i], delta[i], xi[i])
