"""Isotropic elastic constants: the wave-speed ratio beta = c_s/c_d from Poisson's ratio and back, for plane
strain and plane stress, and the shear modulus mu = rho c_s^2 (docs/physics.md §1 and §6).

Plane strain (a thick body): beta^2 = (1 - 2 nu) / (2 (1 - nu)).
Plane stress (a thin plate, Sect. III of the paper): the 2-D Poisson ratio is nu / (1 + nu), so
beta^2 = (1 - nu) / 2.
"""

from __future__ import annotations

import numpy as np

from ._validate import check, check_plane


def wave_speed_ratio(nu, *, plane: str = "strain"):
    """beta = c_s/c_d of an isotropic solid with Poisson ratio nu in (-1, 0.5).

    plane = "strain": beta^2 = (1 - 2 nu) / (2 (1 - nu)); plane = "stress": beta^2 = (1 - nu) / 2.
    The spectrum functions need beta <= 1/sqrt(2), i.e. nu >= 0 in plane strain (nu >= 0 also in plane stress).
    """
    n = check("nu", nu, domain="nu_any")
    if check_plane(plane) == "strain":
        return np.sqrt((1.0 - 2.0 * n) / (2.0 * (1.0 - n)))
    return np.sqrt((1.0 - n) / 2.0)


def poisson_ratio(beta, *, plane: str = "strain"):
    """Poisson ratio nu from beta = c_s/c_d (the inverse of :func:`wave_speed_ratio`).

    plane = "strain": nu = (1 - 2 beta^2) / (2 (1 - beta^2)), beta in (0, sqrt(3)/2);
    plane = "stress": nu = 1 - 2 beta^2, beta in (1/2, 1). Both ranges are nu in (-1, 0.5).
    """
    b = check("beta", beta, domain="beta_any")
    b2 = b * b
    if check_plane(plane) == "strain":
        lo, hi, text = 0.0, 0.75, "(0, sqrt(3)/2)"
        nu = (1.0 - 2.0 * b2) / (2.0 * (1.0 - b2))
    else:
        lo, hi, text = 0.25, 1.0, "(1/2, 1)"
        nu = 1.0 - 2.0 * b2
    bad = (b2 <= lo) | (b2 >= hi)
    if np.any(bad):
        first = float(np.ravel(b[bad])[0])
        raise ValueError(f"beta must be in {text} for plane {plane} (nu in (-1, 0.5)); got {first!r}")
    return nu


def shear_modulus(rho, c_s):
    """mu = rho c_s^2 [Pa] from the density rho [kg/m^3] and the shear wave speed c_s [m/s]."""
    r = check("rho", rho)
    cs = check("c_s", c_s)
    return r * cs * cs
