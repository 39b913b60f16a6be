"""Newton's method: the one loop and stopping rule for every root of the model (docs/physics.md §8).

:func:`newton_root` finds a root of the function :func:`eval_mode` selects (F along ln kH, F/gamma along
tau = 1/gamma, F at a fixed kH, or the Rayleigh cubic), certifies its convergence (quadratic model or a convergence
constant measured elsewhere), estimates the error of the root and the branch slope there,
and gives up on a start outside the basin.
"""

from __future__ import annotations

import cmath
import math

from ._common import jitted
from .elementary import ABS_FLOOR, EPS, cabs, cinv
from .records import Box, Params, Root
from .response import weighted_dispersion

# What eval_mode (and so newton_root) evaluates; s and q as named here.
LN_KH = 0  # F along s = ln kH, evaluated at kH = q = e^s (newton_root sets q once per root): the Rayleigh-branch path
TAU = 1  # F/gamma along s = tau = 1/gamma at kH = q: the homotopy to the branch's starting root
KH = 2  # F at kH = q (s unused): one root of model.modes
CUBIC = 3  # the Rayleigh cubic in x = z^2 (docs/physics.md §5), b = beta^2 (s, q and the other parameters unused)

NOISE_ULPS = 8.0  # rounding level of a Newton step: NOISE_ULPS eps scale/|F'| (scale bounds F's rounding error)
STEP_FLOOR = 1e-14  # a step below STEP_FLOOR |z| has converged: the error it leaves (~C a^2) is far below rounding
QUAD_TRUST = 1e-4  # C estimated from two steps (a/prev^2) is trusted for steps below QUAD_TRUST |z| ...
QUAD_SHRINK = 0.1  # ... that shrank at least 10x (quadratic convergence seen, not a chance small step)
C_FIRST_TRUST = 1e-6  # a C measured elsewhere (path nodes) is trusted for a first step below this x local_scale
SHRINK_PATH = 0.5  # a branch root fails if a step is not below half the previous one (start outside the basin)
FULL_TOL = 0.25e-16  # relative error target of a converged root at full accuracy (rtol = None)
LOCAL_SCALE_MIN = 1e-12  # floor of local_scale (a root this close to a singularity is not followed anyway)


@jitted
def eval_mode(z: complex, mode: int, s: float, q: float, p: Params) -> tuple[complex, complex, float, complex]:
    """F, dF/dz, rounding scale and dF/ds of the function selected by mode (LN_KH, TAU, KH or CUBIC).

    TAU evaluates F/gamma = G_x + i f G_y + tau i z S, which is linear in tau and finite at tau = 0 (gamma = inf),
    where its root is the Rayleigh root of the large-kH response. CUBIC is x^3 - 8 x^2 + 8 (3 - 2b) x - 16 (1 - b)
    at x = z (its scale: the sum of the magnitudes of its terms; dF/ds = 0).
    """
    if mode == LN_KH:
        fv, dfv, sc, fq = weighted_dispersion(z, q, p.gamma, 1.0, p)
        return fv, dfv, sc, q * fq
    if mode == TAU:
        fv, dfv, sc, _ = weighted_dispersion(z, q, 1.0, s, p)
        sf = 1.0 + (p.delta - 1.0) / (1.0 - 1j * p.xi * z * q)
        return fv, dfv, sc, 1j * z * sf
    if mode == KH:
        return weighted_dispersion(z, q, p.gamma, 1.0, p)
    b = p.beta * p.beta
    c1 = 8.0 * (3.0 - 2.0 * b)
    c0 = 16.0 * (1.0 - b)
    ax = cabs(z)
    return ((z - 8.0) * z + c1) * z - c0, (3.0 * z - 16.0) * z + c1, ((ax + 8.0) * ax + c1) * ax + c0, 0j


@jitted
def local_scale(z: complex) -> float:
    """Radius on which the root can move smoothly: min(|z|, distance to the real-axis singularities |Re z| >= 1).

    Poles (finite eta) and branch cuts (eta = inf) of F lie on the real axis with |z| >= 1 only
    (docs/physics.md §2), so predictor errors are measured against this distance.
    """
    x = abs(z.real)
    d = abs(z.imag) if x >= 1.0 else cabs(complex(1.0 - x, z.imag))
    return max(min(cabs(z), d), LOCAL_SCALE_MIN)


@jitted
def newton_root(z0: complex, mode: int, s: float, q: float, p: Params, maxit: int, tol: float, c_first: float,
            shrink: float, mult: float, box: Box) -> Root:
    """Newton's method from z0 on the function selected by mode (see eval_mode): the one Newton loop of the model.

    Each step is dz = mult F/F' (mult = n for a root of multiplicity n, else 1). After a step of size a to z:

    - converged if the step is at rounding level, a <= floor, or the quadratic model puts the error left,
      rest = C a^2, below tol |z|. Normally floor = max(STEP_FLOOR |z|, noise), noise = mult NOISE_ULPS eps
      scale/|F'|, and the convergence constant C = a/prev^2 is estimated from the last two steps once they
      are in the quadratic regime (a < QUAD_TRUST |z|, a < QUAD_SHRINK prev; else no quadratic test).
      With c_first > 0 the first step is instead certified by that constant measured elsewhere (at the path
      nodes): C = c_first, floor = STEP_FLOOR |z| (a step at noise level certifies nothing: it takes a second
      step to show contraction), and only for a <= C_FIRST_TRUST local_scale(z) (close to a singularity
      the constant may not hold);
    - failed if F or F' is not finite or F' = 0, if z leaves the box, if a step is not below shrink times
      the previous one, or after maxit evaluations.

    A small theta = |step 2| / |step 1| certifies that z0 was well inside the quadratic basin of the root
    found: with two roots a distance d apart, theta ~ |z0 - z|/d, so theta <= THETA_MAX = 0.1 rules out
    starting nearer the other root (the callers on the branch check it). The error estimate is
    noise + rest (rest = a^2/|z| where no C is trusted); the residual estimate is that times |F'|/scale.
    dz/ds = -F_s/F_z: the slopes at the last two iterates extrapolated linearly (the slope is analytic in
    z) to the final z, so its error is O(|last two steps|^2) instead of O(|last step|).
    """
    z = z0
    prev = math.inf
    first = 0.0
    theta = 0.0
    nanz = complex(math.nan, math.nan)
    z_prev = nanz  # previous iterate and the slope there
    d_prev = nanz
    evals = 0
    if mode == LN_KH:
        q = math.exp(s)  # kH, once for all iterations at this s
    for it in range(maxit):
        fv, dfv, sc, fs = eval_mode(z, mode, s, q, p)
        evals += 1
        if not (cmath.isfinite(fv) and cmath.isfinite(dfv)) or dfv == 0:
            break
        inv_df = cinv(dfv)
        step = fv * inv_df
        if mult != 1.0:
            step = mult * step
        a = cabs(step)
        if it == 0:
            first = a
        elif it == 1 and first > 0.0:
            theta = a / first
        adf = cabs(dfv)
        noise = mult * NOISE_ULPS * EPS * sc / adf
        slope = -fs * inv_df
        z_eval = z
        z = z - step
        if z.real < box.re_lo or z.real > box.re_hi or z.imag < box.im_lo or z.imag > box.im_hi:
            break
        az = max(cabs(z), ABS_FLOOR)
        if it == 0 and c_first > 0.0:  # first step certified by a convergence constant measured elsewhere
            c = c_first
            trusted = a <= C_FIRST_TRUST * local_scale(z)
            floor = STEP_FLOOR * az
        else:
            c = a / (prev * prev) if (it >= 1 and a < QUAD_TRUST * az and a < QUAD_SHRINK * prev) else 0.0
            trusted = True
            floor = max(STEP_FLOOR * az, noise)
        rest = c * a * a if c > 0.0 else a * a / az
        if trusted and (a <= floor or (c > 0.0 and rest <= tol * az)):
            if it >= 1 and z_eval != z_prev:
                slope = slope + (slope - d_prev) / (z_eval - z_prev) * (z - z_eval)
            err = noise + rest
            return Root(z, True, evals, first, theta, err * adf / sc, err, slope)
        if it >= 1 and a > shrink * prev:
            break
        prev = a
        z_prev = z_eval
        d_prev = slope
    return Root(z, False, evals, first, theta, math.inf, math.inf, nanz)
