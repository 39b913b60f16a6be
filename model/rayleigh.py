"""Rayleigh wave speed (docs/physics.md §5)."""

from __future__ import annotations

import numpy as np

from ._validate import check


def _rayleigh_x(b: np.ndarray) -> np.ndarray:
    """Root in (0, 1) of x^3 - 8 x^2 + 8 (3 - 2b) x - 16 (1 - b) = 0, x = z_R^2, b = beta^2."""
    # depressed cubic for x = y + 8/3:  y^3 + p y + r = 0
    p = 8.0 * (3.0 - 2.0 * b) - 64.0 / 3.0
    r = -16.0 * (1.0 - b) + 8.0 * 8.0 * (3.0 - 2.0 * b) / 3.0 - 2.0 * 512.0 / 27.0
    disc = (r / 2.0) ** 2 + (p / 3.0) ** 3
    x = np.empty_like(b)
    three = disc < 0.0  # three real roots: trigonometric form, take the one in (0, 1)
    if np.any(three):
        pp, rr = p[three], r[three]
        m = 2.0 * np.sqrt(-pp / 3.0)
        theta = np.arccos(np.clip(3.0 * rr / (pp * m), -1.0, 1.0)) / 3.0
        roots = np.stack([m * np.cos(theta - 2.0 * np.pi * k / 3.0) for k in range(3)]) + 8.0 / 3.0
        pick = np.where((roots > 0.0) & (roots < 1.0), roots, np.inf)
        x[three] = pick.min(axis=0)
    one = ~three  # one real root: Cardano with real cube roots
    if np.any(one):
        pp, rr, dd = p[one], r[one], np.sqrt(disc[one])
        x[one] = np.cbrt(-rr / 2.0 + dd) + np.cbrt(-rr / 2.0 - dd) + 8.0 / 3.0
    for _ in range(2):  # Newton polish to the last bit
        fx = ((x - 8.0) * x + 8.0 * (3.0 - 2.0 * b)) * x - 16.0 * (1.0 - b)
        dfx = (3.0 * x - 16.0) * x + 8.0 * (3.0 - 2.0 * b)
        x = x - fx / dfx
    return x


def rayleigh_speed(beta):
    """Rayleigh wave speed z_R = c_R/c_s for beta = c_s/c_d (docs/physics.md §5).

    z_R^2 is the root in (0, 1) of the Rayleigh cubic x^3 - 8x^2 + 8(3 - 2 beta^2)x - 16(1 - beta^2) = 0,
    solved in closed form (trigonometric Cardano) and polished by two Newton steps; accurate to
    1e-15 relative for beta in (0, 1/sqrt(2)].

    Parameters
    ----------
    beta : array_like, in (0, 1/sqrt(2)]

    Returns
    -------
    ndarray (float) of the broadcast shape of beta.
    """
    b = check("beta", beta)
    bb = np.atleast_1d(b * b)
    z = np.sqrt(_rayleigh_x(bb.astype(float)))
    return z.reshape(np.shape(b))
