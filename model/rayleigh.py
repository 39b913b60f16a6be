"""Rayleigh wave speed (docs/physics.md §5)."""

from __future__ import annotations

import numpy as np

from . import _kernels as K
from ._validate import check


def rayleigh_speed(beta):
    """Rayleigh wave speed z_R = c_R/c_s for beta = c_s/c_d (docs/physics.md §5).

    z_R^2 is the root in (0, 1) of the Rayleigh cubic x^3 - 8x^2 + 8(3 - 2 beta^2)x - 16(1 - beta^2) = 0,
    found by the model's Newton loop (``_kernels.rayleigh.rayleigh_z``: from x = 0.85; the cubic is increasing
    and concave on (0, 1), so the iterates converge monotonically after the first step). The same value starts
    the Rayleigh branch. Accurate to 1e-15 relative for beta in (0, 1/sqrt(2)].

    Parameters
    ----------
    beta : array_like, in (0, 1/sqrt(2)]

    Returns
    -------
    ndarray (float) of the broadcast shape of beta.
    """
    b = check("beta", beta)
    bb = np.ascontiguousarray(np.atleast_1d(b), dtype=float).ravel()
    z = np.empty_like(bb)
    K.rayleigh_many(bb, z)
    return z.reshape(np.shape(b))


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
