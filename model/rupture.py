"""Steady mode-II cohesive-zone model of a rupture front: the slip-velocity estimate of the supplement
(Sect. S-V, "Slip velocity estimation"; docs/physics.md §13).

Setting and assumptions (the supplement is terse; each one is stated here and in docs/physics.md §13):

1. Thin-on-thin approximation. The front is a steady 2-D mode-II shear crack moving at constant speed c
   along the interface between two *identical* isotropic elastic blocks, both infinite in height (the
   supplement invokes the thin-on-thin cohesive model for both geometries; the geometric asymmetry
   enters only afterwards, through Eq. dsigma, docs/physics.md §6).
2. In-plane elasticity. ``plane="stress"`` (default, the thin PMMA plates of the experiment): 2-D
   Poisson ratio nu_2D = nu/(1+nu), E' = E = 2 mu (1+nu), beta^2 = (1-nu)/2. ``plane="strain"``:
   nu_2D = nu, E' = E/(1-nu^2) = 2 mu/(1-nu). In both cases E' = 2 mu/(1-nu_2D).
3. Coordinates move with the front: x is measured from the tip, the front moves towards +x, x < 0 is
   behind the tip (slipping), x > 0 ahead (stuck). Slip delta(x) >= 0 is the displacement jump in the
   sliding direction, delta = 0 ahead of the tip; the slip velocity is v = d delta/dt = -c d delta/dx >= 0.
4. Exponential cohesive law with an infinite tail: behind the tip the shear stress in excess of its
   residual value is tau(x) - tau_r = tau_p exp(x/X_c) for all x < 0 (supplement: tau_tilde(xi) = e^xi);
   there is no point where weakening is complete, the tail extends to x -> -inf.
5. Small-scale yielding: X_c is small against the crack length, so near the tip the field is tau_r plus the
   square-root K field plus the cohesive correction; the stress far ahead matches K_II/sqrt(2 pi x) and
   the nonsingular terms of the macroscopic crack (stress drop, T-terms) are left out.
6. Constant fracture energy Gamma (measured, ~1.1 J/m^2 for 0.9 c_R < c < c_R) and peak strength tau_p
   independent of c (the supplement's choice); the cohesive length then follows X_c(c) = X_c0/f_II(c).
7. 0 < c < c_R (sub-Rayleigh; c_R the Rayleigh speed for the chosen plane).

Formulas (derivation in docs/physics.md §13):

    f_II(c)  = (c^2/c_s^2) alpha_s / ((1 - nu_2D) D),   D = 4 alpha_d alpha_s - (1 + alpha_s^2)^2,
               alpha_{s,d} = sqrt(1 - c^2/c_{s,d}^2)      (Freund 1990, Eq. 5.3.11; f_II(0) = 1, f_II(c_R) = inf)
    M(c)     = mu / ((1 - nu_2D) f_II(c)) = E'/(2 f_II)     (modulus relating slip gradient to stress)
    K_II     = tau_p sqrt(X_c) sqrt(2/pi) Int_{-inf}^0 e^xi/sqrt(-xi) dxi = tau_p sqrt(2 X_c)
    Gamma    = K_II^2 f_II(c)/E' = K_II^2/(2 M)             (dynamic energy balance)
    X_c(c)   = X_c0/f_II(c),   tau_p = sqrt(Gamma E'/(2 X_c0))
    tau(x) - tau_r = tau_p e^{x/X_c}                          for x < 0
                   = tau_p erfcx(sqrt(x/X_c))                 for x > 0 (erfcx(s) = e^{s^2} erfc(s))
    v(x)     = (4/sqrt(pi)) (c tau_p/M(c)) F(sqrt(-x/X_c))    for x < 0, 0 for x >= 0,
               F(y) = e^{-y^2} Int_0^y e^{t^2} dt (Dawson's function)
    v_m(c)   = (4/sqrt(pi)) F(y_p) c tau_p/M(c),  at x_m = -y_p^2 X_c(c),  y_p: 2 y_p F(y_p) = 1
               (y_p = 0.92413887300..., F(y_p) = 1/(2 y_p) = 0.54104422463...)

The stress and slip velocity are the boundary values of one analytic function,
tau_p e^{zeta} erfc(sqrt(zeta)) = (tau - tau_r) - i (M/(2c)) v on the real axis (zeta = (x + i0)/X_c).

Accuracy: all results to ~1e-15 relative times the conditioning 1/(1 - c^2/c_R^2) of f_II near c_R (the
Rayleigh factor is written as (z_R^2 - z^2) times the deflated Rayleigh cubic, so it stays positive and
accurate for every c below the computed c_R); scipy's Dawson function and erfcx are accurate to a few ulp.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import MappingProxyType
from typing import ClassVar

import numpy as np
from scipy.optimize import brentq
from scipy.special import dawsn, erfcx

from ._validate import check, check_plane
from .elastic import wave_speed_ratio
from .thin_on_thick import normal_stress_change

_SQRT_PI = math.sqrt(math.pi)


def _rayleigh_x(b2) -> np.ndarray:
    """x_R = z_R^2, the root in (0, 1) of the Rayleigh cubic x^3 - 8x^2 + 8(3 - 2 b2)x - 16(1 - b2), for
    beta^2 = b2 in (0, 1): any Poisson ratio in (-1, 0.5) (model.rupture; the spectrum's beta <= 1/sqrt(2) uses
    the kernel's Newton, whose start x = 0.85 is not safe near b2 = 1). Closed form (trigonometric Cardano for
    three real roots, real cube roots for one), then two Newton corrections to the last bit; no domain check."""
    b = np.atleast_1d(np.asarray(b2, dtype=float))
    # depressed cubic for x = y + 8/3:  y^3 + p y + r = 0
    p = 8.0 * (3.0 - 2.0 * b) - 64.0 / 3.0
    r = -16.0 * (1.0 - b) + 8.0 * 8.0 * (3.0 - 2.0 * b) / 3.0 - 2.0 * 512.0 / 27.0
    disc = (r / 2.0) ** 2 + (p / 3.0) ** 3
    x = np.empty_like(b)
    three = disc < 0.0
    if np.any(three):
        pp, rr = p[three], r[three]
        m = 2.0 * np.sqrt(-pp / 3.0)
        theta = np.arccos(np.clip(3.0 * rr / (pp * m), -1.0, 1.0)) / 3.0
        roots = np.stack([m * np.cos(theta - 2.0 * np.pi * k / 3.0) for k in range(3)]) + 8.0 / 3.0
        x[three] = np.where((roots > 0.0) & (roots < 1.0), roots, np.inf).min(axis=0)
    one = ~three
    if np.any(one):
        rr, dd = r[one], np.sqrt(disc[one])
        x[one] = np.cbrt(-rr / 2.0 + dd) + np.cbrt(-rr / 2.0 - dd) + 8.0 / 3.0
    for _ in range(2):
        fx = ((x - 8.0) * x + 8.0 * (3.0 - 2.0 * b)) * x - 16.0 * (1.0 - b)
        x = x - fx / ((3.0 * x - 16.0) * x + 8.0 * (3.0 - 2.0 * b))
    return x.reshape(np.shape(b2))


def _peak_of_dawson() -> tuple[float, float]:
    """(y_p, F(y_p)): the maximum of Dawson's function, where F'(y) = 1 - 2 y F(y) = 0."""

    def g(y: float) -> float:
        return 1.0 - 2.0 * y * float(dawsn(y))

    y = brentq(g, 0.5, 1.5, xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=200)
    for _ in range(2):  # Newton polish: g'(y) = -2 F(y) - 2 y F'(y) = -2 F - 2 y g(y)
        fy = float(dawsn(y))
        gy = 1.0 - 2.0 * y * fy
        y -= gy / (-2.0 * fy - 2.0 * y * gy)
    return y, float(dawsn(y))


_Y_PEAK, _F_PEAK = _peak_of_dawson()

#: Position of the slip-velocity peak in units of the cohesive length: x_m / X_c(c) = -y_p^2 (~ -0.854).
PEAK_SLIP_POSITION = -_Y_PEAK * _Y_PEAK
#: Peak of the universal profile F(sqrt(-x/X_c)) (the maximum of Dawson's function, 1/(2 y_p) ~ 0.5410).
PEAK_SLIP_PROFILE = _F_PEAK


# ----------------------------------------------------------------------------------------- defaults
@dataclass(frozen=True)
class RuptureParameters:
    """Inputs of the cohesive-zone model, by default the paper's values (SI units).

    ``rho`` is an ASSUMPTION: the paper does not state PMMA's density; 1180 kg/m^3 is a typical value and
    only enters through mu = rho c_s^2 (tau_p scales as sqrt(rho), v as 1/sqrt(rho)). See ``SOURCES``.
    """

    Gamma: float = 1.1  # J/m^2
    X_c0: float = 2.5e-3  # m
    sigma0: float = 4.5e6  # Pa
    c_s: float = 1345.0  # m/s
    nu: float = 0.33
    rho: float = 1180.0  # kg/m^3 (assumed)
    plane: str = "stress"
    kW: tuple[float, ...] = (3.0, 4.0, 5.0)
    #: Where each default comes from (read-only).
    SOURCES: ClassVar[MappingProxyType] = MappingProxyType(
        {
            "Gamma": "supplement Sect. S-V C (experimental results): Gamma ~ 1.1 J/m^2, roughly constant in c",
            "X_c0": "supplement Sect. S-V C, slip velocity estimation: X_c^0 = X_c(c -> 0) ~ 2.5 mm",
            "sigma0": "main text Fig. 3c and supplement Sect. S-V A: nominal normal stress ~4.5 MPa",
            "c_s": "supplement Sect. S-V A: c_s = 1345 +- 10 m/s (ultrasonic time of flight)",
            "nu": "main text Fig. 3 and supplement Sect. S-IV: nu = 0.33 for PMMA",
            "rho": "ASSUMPTION (not stated in the paper): typical PMMA density 1180 kg/m^3",
            "plane": "supplement Sect. S-V: plane stress for the thin plates (c_R ~ 1237 m/s)",
            "kW": "main text Fig. 3c: kW = 3, 4, 5",
        }
    )

    @property
    def mu(self) -> float:
        """Shear modulus mu = rho c_s^2 [Pa] (depends on the assumed density)."""
        return self.rho * self.c_s * self.c_s

    def model_kwargs(self) -> dict:
        """Keyword arguments (Gamma, X_c0, mu, c_s, nu, plane) for the profile and peak functions."""
        return dict(Gamma=self.Gamma, X_c0=self.X_c0, mu=self.mu, c_s=self.c_s, nu=self.nu, plane=self.plane)


#: the paper's PMMA front (docs/physics.md §13.7): the defaults of :class:`RuptureParameters`
PAPER_DEFAULTS = RuptureParameters()


# ----------------------------------------------------------------------------------------- helpers
def _one_minus_nu2d(n: np.ndarray, plane: str) -> np.ndarray:
    """1 - nu_2D: 1 - nu (plane strain), 1/(1 + nu) (plane stress, nu_2D = nu/(1+nu))."""
    return 1.0 - n if plane == "strain" else 1.0 / (1.0 + n)


def _speed_terms(c, c_s, nu, plane: str):
    """Validated (c, c_s, nu) broadcast, z = c/c_s, b = beta^2 and x_R = (c_R/c_s)^2.

    ValueError naming c unless 0 < c < c_R (tested as z^2 < x_R, the quantity f_II divides by).
    """
    check_plane(plane)
    cc = check("c", c)
    cs = check("c_s", c_s)
    n = check("nu", nu, domain="nu_any")
    cc, cs, n = np.broadcast_arrays(cc, cs, n)
    b = wave_speed_ratio(n, plane=plane) ** 2
    x_r = _rayleigh_x(np.atleast_1d(b).astype(float)).reshape(np.shape(b))
    z = cc / cs
    bad = z * z >= x_r
    if np.any(bad):
        i = np.flatnonzero(np.ravel(bad))[0]
        c_bad = float(np.ravel(cc)[i])
        c_r = float(np.ravel(cs * np.sqrt(x_r))[i])
        raise ValueError(
            f"c must be in (0, c_R), c_R = c_s z_R(nu) the Rayleigh speed (plane {plane}); "
            f"got c = {c_bad!r} with c_R = {c_r!r}"
        )
    return cc, cs, n, z, b, x_r


def _f_ii(z: np.ndarray, b: np.ndarray, x_r: np.ndarray) -> np.ndarray:
    """f_II from z = c/c_s, b = beta^2, x_R = z_R^2, free of cancellation at both ends.

    With D = 4 a_d a_s - (1 + a_s^2)^2 and the Rayleigh cubic R(x) = x^3 - 8x^2 + 8(3-2b)x - 16(1-b),
    D (4 a_s a_d + (2 - z^2)^2) = -z^2 R(z^2) and R(x) = (x - x_R)(x^2 + (x_R - 8) x + 16(1-b)/x_R), so
    f_II = 2(1-b) a_s (4 a_s a_d + (2-z^2)^2) / ((x_R - z^2)(z^4 + (x_R-8) z^2 + 16(1-b)/x_R)),
    using 1/(1 - nu_2D) = 2(1 - b) in both planes. Exactly 1 at z = 0; positive for z^2 < x_R.
    """
    z2 = z * z
    a_s = np.sqrt((1.0 - z) * (1.0 + z))
    a_d = np.sqrt(1.0 - b * z2)
    num = 2.0 * (1.0 - b) * a_s * (4.0 * a_s * a_d + (2.0 - z2) ** 2)
    quad = z2 * z2 + (x_r - 8.0) * z2 + 16.0 * (1.0 - b) / x_r
    return num / ((x_r - z2) * quad)


def _cohesive_terms(c, Gamma, X_c0, mu, c_s, nu, plane: str):
    """(c, tau_p, X_c(c), M(c)) validated and broadcast."""
    cc, _, n, z, b, x_r = _speed_terms(c, c_s, nu, plane)
    g = check("Gamma", Gamma)
    xc0 = check("X_c0", X_c0)
    m = check("mu", mu)
    f = _f_ii(z, b, x_r)
    one_nu = _one_minus_nu2d(n, plane)
    tau_p = np.sqrt(g * m / (one_nu * xc0))
    modulus = m / (one_nu * f)
    return cc, tau_p, xc0 / f, modulus


# ---------------------------------------------------------------------------------------- public API
def rayleigh_wave_speed(*, c_s, nu, plane: str = "stress"):
    """Rayleigh wave speed c_R = c_s z_R(beta) [m/s] of the in-plane problem (docs/physics.md §13).

    beta = c_s/c_d from nu for the given plane (plane stress: beta^2 = (1-nu)/2); z_R^2 is the root in
    (0, 1) of the Rayleigh cubic. nu in (-1, 0.5) (unlike :func:`rayleigh_speed`, negative nu allowed).
    PMMA, nu = 0.33, plane stress: c_R = 0.91909 c_s = 1236.2 m/s (paper: ~1237 m/s). ~1e-15 relative.
    """
    check_plane(plane)
    cs = check("c_s", c_s)
    n = check("nu", nu, domain="nu_any")
    cs, n = np.broadcast_arrays(cs, n)
    b = wave_speed_ratio(n, plane=plane) ** 2
    x_r = _rayleigh_x(np.atleast_1d(b).astype(float)).reshape(np.shape(b))
    return cs * np.sqrt(x_r)


def plane_modulus(*, mu, nu, plane: str = "stress"):
    """E' = 2 mu/(1 - nu_2D) [Pa]: E = 2 mu (1+nu) in plane stress, E/(1-nu^2) = 2 mu/(1-nu) in plane strain.

    The modulus of the energy balance Gamma = K_II^2 f_II(c)/E' (docs/physics.md §13). mu > 0, nu in (-1, 0.5).
    """
    check_plane(plane)
    m = check("mu", mu)
    n = check("nu", nu, domain="nu_any")
    return 2.0 * m / _one_minus_nu2d(n, plane)


def mode_ii_universal_function(c, *, c_s, nu, plane: str = "stress"):
    """The universal mode-II function f_II(c) of dynamic LEFM (Freund 1990, Eq. 5.3.11; Broberg 1999).

        f_II(c) = (c^2/c_s^2) alpha_s / ((1 - nu_2D) D),  D = 4 alpha_d alpha_s - (1 + alpha_s^2)^2,
        alpha_s = sqrt(1 - c^2/c_s^2), alpha_d = sqrt(1 - c^2/c_d^2),

    so that G = K_II^2 f_II(c)/E'. f_II(0) = 1 (D ~ c^2/((1-nu_2D) c_s^2) for small c), f_II -> inf as
    c -> c_R. Evaluated in a cancellation-free form (see ``_f_ii``). Domain: 0 < c < c_R, c_s > 0,
    nu in (-1, 0.5); ValueError naming the parameter otherwise. Accuracy ~1e-15 / (1 - c^2/c_R^2) relative.
    """
    _, _, _, z, b, x_r = _speed_terms(c, c_s, nu, plane)
    return _f_ii(z, b, x_r)


def cohesive_zone_size(c, *, X_c0, c_s, nu, plane: str = "stress"):
    """Cohesive length X_c(c) = X_c0/f_II(c) [m] (supplement, slip velocity estimation; docs/physics.md §13).

    Decreases from X_c0 at c -> 0 to 0 at c -> c_R (Lorentz-like contraction). X_c0 > 0; 0 < c < c_R.
    """
    xc0 = check("X_c0", X_c0)
    return xc0 / mode_ii_universal_function(c, c_s=c_s, nu=nu, plane=plane)


def peak_cohesive_stress(*, Gamma, X_c0, mu, nu, plane: str = "stress"):
    """Peak cohesive strength tau_p = sqrt(Gamma E'/(2 X_c0)) [Pa], independent of c (docs/physics.md §13).

    From Gamma = K_II^2 f_II/E', K_II = tau_p sqrt(2 X_c) and X_c = X_c0/f_II. The paper's inputs (Gamma =
    1.1 J/m^2, X_c0 = 2.5 mm, c_s = 1345 m/s, nu = 0.33, assumed rho = 1180 kg/m^3, plane stress) give
    ~1.12 MPa (supplement: "tau_p ~ 1.1 MPa"). Gamma, X_c0, mu > 0; nu in (-1, 0.5).
    """
    g = check("Gamma", Gamma)
    xc0 = check("X_c0", X_c0)
    return np.sqrt(g * plane_modulus(mu=mu, nu=nu, plane=plane) / (2.0 * xc0))


def stress_intensity_factor(c, *, Gamma, X_c0, mu, c_s, nu, plane: str = "stress"):
    """Mode-II stress intensity factor K_II(c) = tau_p sqrt(2 X_c(c)) = sqrt(Gamma E'/f_II(c)) [Pa m^1/2].

    The supplement's K_II = tau_p sqrt(X_c) sqrt(2/pi) Int_{-inf}^0 tau_tilde(xi)/sqrt(-xi) dxi with
    tau_tilde = e^xi (the integral is sqrt(pi)). Vanishes as c -> c_R. Domain as :func:`slip_velocity_profile`.
    """
    _, tau_p, x_c, _ = _cohesive_terms(c, Gamma, X_c0, mu, c_s, nu, plane)
    return tau_p * np.sqrt(2.0 * x_c)


def universal_slip_profile(xi):
    """The dimensionless slip-velocity profile V(xi) = F(sqrt(-xi)) for xi = x/X_c < 0, 0 for xi >= 0.

    F is Dawson's function (scipy.special.dawsn). V ~ sqrt(-xi) at the tip, V ~ 1/(2 sqrt(-xi)) far
    behind (the K field), maximum PEAK_SLIP_PROFILE at xi = PEAK_SLIP_POSITION. xi finite real.
    """
    s = check("xi", xi, domain="x")
    return np.where(s < 0.0, dawsn(np.sqrt(np.maximum(-s, 0.0))), 0.0)


def shear_stress_profile(x, *, c, Gamma, X_c0, mu, c_s, nu, plane: str = "stress"):
    """Shear stress above its residual value, tau(x) - tau_r [Pa], on the interface (docs/physics.md §13).

        tau - tau_r = tau_p exp(x/X_c)              x <= 0 (the prescribed cohesive law)
                    = tau_p erfcx(sqrt(x/X_c))       x > 0  (the elastic response ahead of the tip)

    Continuous at the tip (= tau_p) and -> K_II/sqrt(2 pi x) far ahead. x in metres from the tip (front
    moving to +x). Broadcasts over all arguments. Domain as :func:`slip_velocity_profile`.
    """
    xx = check("x", x)
    _, tau_p, x_c, _ = _cohesive_terms(c, Gamma, X_c0, mu, c_s, nu, plane)
    s = xx / x_c
    behind = tau_p * np.exp(np.minimum(s, 0.0))
    ahead = tau_p * erfcx(np.sqrt(np.maximum(s, 0.0)))
    return np.where(s <= 0.0, behind, ahead)


def slip_velocity_profile(x, *, c, Gamma, X_c0, mu, c_s, nu, plane: str = "stress"):
    """Slip velocity v(x) [m/s] of the steady exponential cohesive zone (supplement S-V; docs/physics.md §13).

        v(x) = (4/sqrt(pi)) (c tau_p / M(c)) F(sqrt(-x/X_c(c)))   for x < 0,   v = 0 for x >= 0,

    M = mu/((1 - nu_2D) f_II(c)), tau_p = sqrt(Gamma E'/(2 X_c0)), X_c = X_c0/f_II, F Dawson's function.
    Positive behind the tip, ~ K-field decay (2 c K_II/M)/sqrt(2 pi |x|) for |x| >> X_c.

    x: position from the tip [m] (x < 0 behind; finite). c: rupture speed [m/s], 0 < c < c_R(c_s, nu, plane).
    Gamma [J/m^2], X_c0 [m], mu [Pa], c_s [m/s] > 0; nu in (-1, 0.5); plane "stress" or "strain".
    All broadcast. ValueError naming the parameter and range otherwise. Accuracy as the module docstring.
    """
    xx = check("x", x)
    cc, tau_p, x_c, modulus = _cohesive_terms(c, Gamma, X_c0, mu, c_s, nu, plane)
    scale = (4.0 / _SQRT_PI) * cc * tau_p / modulus
    s = xx / x_c
    return np.where(s < 0.0, scale * dawsn(np.sqrt(np.maximum(-s, 0.0))), 0.0)


def peak_slip_velocity(c, *, Gamma, X_c0, mu, c_s, nu, plane: str = "stress"):
    """Maximum slip velocity v_m(c) = (4/sqrt(pi)) F(y_p) c tau_p/M(c) [m/s] (docs/physics.md §13).

    y_p = 0.924138873... is the maximum of Dawson's function (2 y_p F(y_p) = 1), so
    v_m = (2/(sqrt(pi) y_p)) c tau_p (1 - nu_2D) f_II(c)/mu, reached at x_m = -y_p^2 X_c(c)
    (:func:`peak_slip_location`). Increases with c and diverges as c -> c_R. Domain as
    :func:`slip_velocity_profile`.
    """
    cc, tau_p, _, modulus = _cohesive_terms(c, Gamma, X_c0, mu, c_s, nu, plane)
    return (4.0 / _SQRT_PI) * PEAK_SLIP_PROFILE * cc * tau_p / modulus


def peak_slip_location(c, *, X_c0, c_s, nu, plane: str = "stress"):
    """Position x_m = -y_p^2 X_c(c) [m] (~ -0.854 X_c) of the slip-velocity peak behind the tip."""
    return PEAK_SLIP_POSITION * cohesive_zone_size(c, X_c0=X_c0, c_s=c_s, nu=nu, plane=plane)


def relative_normal_stress_change_at_peak_slip(c, *, kW, sigma0, Gamma, X_c0, mu, c_s, nu):
    """Delta sigma_yy(v_m)/sigma0: Eq. dsigma (docs/physics.md §6) at the peak slip velocity v_m(c).

        Delta sigma_yy/sigma0 = -(mu/c) G_y(c/c_s; kW, nu) v_m(c) / sigma0,

    with v_m from :func:`peak_slip_velocity` in plane stress (the thin block of Eq. dsigma is in plane
    stress, so the slip model is too; there is no ``plane`` argument on purpose). Positive (the normal
    compression is reduced) where the thick block is effectively stiffer (G_y < 0, kW = 3..5).
    kW > 0, sigma0 > 0, nu in [0, 0.5) (the thin-on-thick functions need nu >= 0), 0 < c < c_R; the
    other parameters as :func:`slip_velocity_profile`. All broadcast.
    """
    s0 = check("sigma0", sigma0)
    v_m = peak_slip_velocity(c, Gamma=Gamma, X_c0=X_c0, mu=mu, c_s=c_s, nu=nu, plane="stress")
    return normal_stress_change(v_m, c=c, c_s=c_s, kW=kW, nu=nu, mu=mu) / s0
