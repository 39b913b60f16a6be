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
