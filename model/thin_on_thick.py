"""Thin-on-thick: effective moduli of the thick block and the effective bimaterial response (Sect. III, S-IV)."""

from __future__ import annotations

import numpy as np
from scipy.special import k0

from ._validate import check

_H = 0.125  # trapezoid step in the natural variable (see _bessel_k0_integrals)


def _trapezoid_nodes(n: int) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n) * _H
    w = np.full(n, _H)
    w[0] = 0.5 * _H
    return t, w


_T, _W = _trapezoid_nodes(400)


def _bessel_k0_integrals(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Head Int_0^x K0 and tail Int_x^inf K0, each to full relative precision (x > 0).

    Uses K0(t) = Int_0^inf exp(-t cosh u) du, so that
        tail(x) = Int_0^inf exp(-x cosh u)/cosh u du,  head(x) = Int_0^inf -expm1(-x cosh u)/cosh u du,
    both integrands analytic and even in u, so the trapezoid rule converges exponentially
    (error ~ exp(-pi^2 / h_eff)). For large x the tail integrand has width ~ 1/sqrt(x): the variable
    u = v / sqrt(max(x, 1)) keeps the step adequate. head + tail = pi/2; the smaller one is computed
    directly and the other one from it, so neither suffers cancellation.
    """
    x = np.asarray(x, dtype=float)
    scale = 1.0 / np.sqrt(np.maximum(x.ravel(), 1.0))  # flat, as the quadrature's results
    u = _T[None, :] * scale.reshape(-1, 1)
    xx = x.reshape(-1, 1)
    with np.errstate(under="ignore", over="ignore"):  # the far nodes underflow to 0 by design
        ch = np.cosh(u)
        tail_int = np.exp(-xx * (ch - 1.0)) / ch  # times exp(-x)
        tail = np.exp(-x.ravel()) * (tail_int @ _W) * scale
        head_int = -np.expm1(-xx * ch) / ch
    head = (head_int @ _W) * scale
    small = x.ravel() < 1.0
    tail = np.where(small, 0.5 * np.pi - head, tail)
    head = np.where(small, head, 0.5 * np.pi - tail)
    return head.reshape(x.shape), tail.reshape(x.shape)


def bessel_integral_B(kW):
    """B(q) = (1/pi) Int_0^q K0(q'/2) dq' = (2/pi) Int_0^{q/2} K0(t) dt (Eq. B(q)C(q)), q = kW > 0.

    Full relative precision for both B and 1 - B (see :func:`one_minus_bessel_integral_B`).
    """
    q = check("kW", kW)
    head, _ = _bessel_k0_integrals(0.5 * q)
    return 2.0 / np.pi * head


def one_minus_bessel_integral_B(kW):
    """1 - B(q) = (2/pi) Int_{q/2}^inf K0(t) dt, computed directly (no 1 - (almost 1) cancellation)."""
    q = check("kW", kW)
    _, tail = _bessel_k0_integrals(0.5 * q)
    return 2.0 / np.pi * tail


def bessel_term_C(kW):
    """C(q) = (q/pi) K0(|q|/2) (Eq. B(q)C(q)); negligible against B except at small q."""
    q = check("kW", kW)
    return q / np.pi * k0(0.5 * np.abs(q))


def _moduli_parts(q: np.ndarray, nu: np.ndarray):
    """delta with mu/mu_eff = 1 + delta, the denominator itself and the nu_eff numerator."""
    head, tail = _bessel_k0_integrals(0.5 * q)
    b = 2.0 / np.pi * head
    one_b = 2.0 / np.pi * tail
    with np.errstate(under="ignore"):
        e = np.exp(-0.5 * q)
    one_e = -np.expm1(-0.5 * q)
    # denominator 2(1-nu)B - (1-2nu)(1-e^{-q/2}) = 1 + delta, delta = (1-2nu)e^{-q/2} - 2(1-nu)(1-B)
    delta = (1.0 - 2.0 * nu) * e - 2.0 * (1.0 - nu) * one_b
    den_direct = 2.0 * (1.0 - nu) * b - (1.0 - 2.0 * nu) * one_e
    den = np.where(b < 0.5, den_direct, 1.0 + delta)
    delta = np.where(b < 0.5, den_direct - 1.0, delta)
    num = np.where(b < 0.5, (1.0 - nu) * b - (1.0 - 2.0 * nu) * one_e, nu - (1.0 - nu) * one_b + (1.0 - 2.0 * nu) * e)
    return delta, den, num


def effective_moduli(kW, nu):
    """(mu_eff/mu, nu_eff) of the thick block seen through a strip of width W (Eq. effective_constants).

    mu_eff/mu = 1/[2(1-nu)B - (1-2nu)(1-e^{-q/2})],
    nu_eff = [(1-nu)B - (1-2nu)(1-e^{-q/2})] / [2(1-nu)B - (1-2nu)(1-e^{-q/2})],   q = kW.

    For large q the denominator is written 1 + delta with delta = (1-2nu)e^{-q/2} - 2(1-nu)(1-B)
    and 1 - B from the Bessel tail, so mu_eff/mu - 1 (see :func:`effective_modulus_excess`) keeps
    full relative precision even where it is 1e-13. Accuracy ~1e-15 relative; kW > 0, nu in [0, 0.5).
    """
    q = check("kW", kW)
    n = check("nu", nu)
    q, n = np.broadcast_arrays(q, n)
    _, den, num = _moduli_parts(q, n)
    return 1.0 / den, num / den


def effective_modulus_excess(kW, nu):
    """mu_eff/mu - 1 = -delta/(1 + delta) at full relative precision (Eq. effective_constants)."""
    q = check("kW", kW)
    n = check("nu", nu)
    q, n = np.broadcast_arrays(q, n)
    delta, den, _ = _moduli_parts(q, n)
    return -delta / den


def _half_space_m(z: np.ndarray, b2: np.ndarray):
    """Entries of mu k D M for a half-space (Eq. S-m2s) divided by z^2, cancellation-free.

    Returns (a_s, a_d, p, Dt, kappa) with D/z^2 = Dt = z^2 - 4 + 4(1+b2-b2 z^2)/(1+a_s a_d),
    (1 + a_s^2 - 2 a_s a_d)/z^2 = p = 1 - 2 a_s (1-b2)/(a_s + a_d), and the determinant identity
    a_s a_d - p^2 = kappa Dt with kappa = -(1 + b2 - b2 z^2)/(1 + a_s a_d) (so det M = kappa/(mu k)^2 Dt:
    the half-space compliance has a simple pole at its Rayleigh speed).
    """
    us = (1.0 - z) * (1.0 + z)
    ud = 1.0 - b2 * z * z
    us = us.real + 1j * (us.imag + 0.0)
    ud = ud.real + 1j * (ud.imag + 0.0)
    a_s = np.sqrt(us)
    a_d = np.sqrt(ud)
    cnum = 1.0 + b2 - b2 * z * z
    one = 1.0 + a_s * a_d
    dt = z * z - 4.0 + 4.0 * cnum / one
    p = 1.0 - 2.0 * a_s * (1.0 - b2) / (a_s + a_d)
    return a_s, a_d, p, dt, -cnum / one


def thin_on_thick_response(z, kW, *, nu):
    """(G_x, G_y) of the effective bimaterial pair of the thin-on-thick setup (Eq. G, S-m2s, docs/physics.md §6).

    Upper: the thin block under plane stress (shear modulus mu, 2D Poisson ratio nu/(1+nu));
    lower: a half-space with mu_eff(kW), nu_eff(kW) (Eq. effective_constants) and the same density,
    so its shear speed is c_s sqrt(mu_eff/mu). z = c/c_s of the thin block. With M of Eq. S-m2s for
    each half-space (lower: diagonal negated), G = (M_upper - M_lower)^-1, G_x = G_xx/(mu k),
    G_y = G_yx/(i mu k). Written with the determinant identity of ``_half_space_m``:

        G_x = (a_d1 Dt2 + r a_d2 Dt1) / N,   G_y = (p1 Dt2 - r p2 Dt1) / N,
        N = kappa1 Dt2 + r (a_s1 a_d2 + a_s2 a_d1 + 2 p1 p2) + r^2 kappa2 Dt1,   r = mu/mu_eff,

    so neither the 0/0 of both M's at z -> 0 (the quasi-static limit, Eq. S-M_QS_inf_H, comes out
    exact) nor the poles of the M's at each block's Rayleigh speed appear. Principal square roots;
    real z are on the upper lip.
    """
    zz = check("z", z, complex_ok=True)
    q = check("kW", kW)
    n = check("nu", nu)
    zz, q, n = np.broadcast_arrays(zz, q, n)
    _, den, num = _moduli_parts(q, n)
    nu1 = n / (1.0 + n)
    b1 = (1.0 - 2.0 * nu1) / (2.0 - 2.0 * nu1)
    nu2 = num / den
    b2 = (1.0 - 2.0 * nu2) / (2.0 - 2.0 * nu2)
    r = den  # mu/mu_eff
    z2 = zz * np.sqrt(den)  # c / c_s of the lower block
    as1, ad1, p1, dt1, k1 = _half_space_m(zz, b1)
    as2, ad2, p2, dt2, k2 = _half_space_m(z2, b2)
    big_n = k1 * dt2 + r * (as1 * ad2 + as2 * ad1 + 2.0 * p1 * p2) + r * r * k2 * dt1
    return (ad1 * dt2 + r * ad2 * dt1) / big_n, (p1 * dt2 - r * p2 * dt1) / big_n


def limiting_speed(kW, nu):
    """The largest c/c_s (c_s of the thin block) below the shear wave speed of both effective blocks:
    min(1, sqrt(mu_eff/mu)) (same density, so the lower block's shear speed is c_s sqrt(mu_eff/mu); Eq.
    effective_constants). G_y of :func:`thin_on_thick_response` diverges there (docs/physics.md §6)."""
    q = check("kW", kW)
    n = check("nu", nu)
    den = _moduli_parts(*np.broadcast_arrays(q, n))[1]
    return np.minimum(1.0, np.sqrt(1.0 / den))


def normal_stress_change(v, *, c, c_s, kW, nu, mu):
    """Normal-stress change Delta sigma_yy = -(mu/c) G_y(c/c_s; kW, nu) v (Eq. dsigma), SI units.

    v: slip velocity [m/s]; c: rupture speed [m/s], 0 < c < shear speed of both effective blocks;
    c_s: shear speed of the thin block [m/s]; mu: its shear modulus [Pa]. Returns Pa (real).
    """
    vv = check("v", v)
    cc, cs, m = check("c", c), check("c_s", c_s), check("mu", mu)
    q, n = check("kW", kW), check("nu", nu)
    ratio = cc / cs
    if np.any(ratio >= limiting_speed(q, n)):
        raise ValueError("c must be below the shear wave speed of both blocks: c/c_s < min(1, sqrt(mu_eff/mu))")
    _, gy = thin_on_thick_response(ratio.astype(complex), q, nu=n)
    return -(m / cc) * gy.real * vv
