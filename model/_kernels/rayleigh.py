"""The Rayleigh speed z_R(beta): Newton's method on the Rayleigh cubic in x = z^2 (docs/physics.md §5)."""

from __future__ import annotations

import math

import numpy as np

from ._common import jitted
from .newton import CUBIC, FULL_TOL, SHRINK_PATH, newton_root
from .records import NO_BOX, Params

RAYLEIGH_X0 = 0.85  # start on the Rayleigh cubic: increasing and concave on (0, 1), where its root x = z_R^2 lies
RAYLEIGH_ITERS = 40  # far more than needed: Newton converges monotonically after its first step from RAYLEIGH_X0


@jitted
def rayleigh_x(beta: float) -> float:
    """x_R = z_R^2 (docs/physics.md §5): Newton on the Rayleigh cubic in x = z^2 from RAYLEIGH_X0 (NaN if it fails).

    For the spectrum's beta in (0, 1/sqrt(2)] (from x = 0.85 the iterates converge to the root in (0, 1); near
    beta = 1, i.e. Poisson ratios near -1, they do not: model.rayleigh.rayleigh_x_of_b2 covers those)."""
    r = newton_root(RAYLEIGH_X0 + 0j, CUBIC, 0.0, 0.0, Params(1.0, 0.0, beta, math.inf, 1.0, 0.0), RAYLEIGH_ITERS,
                FULL_TOL, 0.0, SHRINK_PATH, 1.0, NO_BOX)
    return r.z.real if r.ok else math.nan


@jitted
def rayleigh_z(beta: float) -> float:
    """z_R(beta) = sqrt(x_R) (docs/physics.md §5)."""
    return math.sqrt(rayleigh_x(beta))


@jitted
def rayleigh_many(beta: np.ndarray, out: np.ndarray) -> None:
    """rayleigh_z over a 1-D array."""
    for i in range(beta.shape[0]):
        out[i] = rayleigh_z(beta[i])
