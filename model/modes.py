"""Every unstable mode in a window: all roots of F(z; kH) = 0 with Im z > 0 (docs/physics.md §2-3, §10).

The dispersion function F(z; kH) of Eq. implicit_spectrum (with Eq. delta f RSF and the response functions
of Eq. Gs_general / S-G_gen) is analytic in the open upper half-plane Im z > 0: its poles (finite eta) and
branch cuts (eta = inf) lie on the real axis (docs/physics.md §2). The number of roots inside a rectangle
R = [-re_max, re_max] x [im_min, im_max] with im_min > 0 is therefore given by the argument principle with no
pole correction,

    N = (1 / 2 pi i) closed-integral_{dR} F'(z)/F(z) dz = (1 / 2 pi) [change of arg F along dR].

Method
------
*Counting.* Each edge (a horizontal or vertical line segment) is sampled adaptively by a compiled routine.
For every pair of neighbouring samples a, b (step h = z_b - z_a) it accepts the segment only if

- the principal log-increment L = Log(F_b / F_a) has |Im L| <= pi/3 and |Re L| <= ln 4,
- the trapezoidal estimate T = h/2 (F'_a/F_a + F'_b/F_b) of the integral of F'/F agrees with L to 0.3,
- the linear predictions F_a + h F'_a and F_b - h F'_b agree with F_b and F_a to 0.7 of their size
  (this catches a pair of roots straddling the edge, whose phase changes cancel),

and otherwise bisects it. The increment of log F along an accepted segment is then L (the true increment
differs from L by a multiple of 2 pi i, and the checks keep it far below pi), so the winding number is an
integer by construction; it is still checked to be within WINDING_TOL = 1e-6 of one. Lines start from nodes
spaced <= 0.1; vertical lines add nodes graded geometrically (ratio 3) from their distance to the real axis, horizontal
lines at height y add nodes p +- y 3^k around each real-axis singularity p (z = +-1, +-1/beta, and for
finite eta the poles z^2 = 1 + (pi n / ((1+eta) kH))^2, z^2 = beta^-2 [1 + (pi n / ((1+eta) kH))^2]) that is
at least 2y from one of its neighbours, so that a root sitting next to a pole is resolved at every scale.
(Every pole in range is graded, however many there are; a line needing more than 2^23 samples is refused:
docs/physics.md §10, beside dense poles.)

*Locating.* The rectangle is split recursively (a vertical line at mid-width, or for a tall cell a horizontal
line at mid-height, geometric mean height near the axis); the samples of the parent's edges are reused, only
the new splitting line is sampled (its end values give the corners on the edges it meets). A cell holding
exactly one root is solved by Newton's method with the analytic derivative (as model.dispersion_derivative;
the model's one Newton loop, model._kernels.newton.newton_root), started from the contour-integral estimate
(1 / 2 pi i) closed-integral z F'/F dz of the cell (else its centre); the root must converge inside its cell
with |F| / scale < RESID_MAX = 1e-12 (scale = model.dispersion_scale).
Cells where Newton fails are split further. The number of located roots always equals the certified count,
or a RuntimeError is raised.

Window semantics
----------------
The window is closed: roots with im_min <= Im z <= im_max and |Re z| <= re_max are counted, including roots
lying exactly on the boundary (for example Im z = im_min). A root closer to an edge than
h_min = min(1e-11 x window size, 1e-7 x distance of the edge from the real axis) cannot be placed on either
side in double precision; the edge is then moved outward by 16 h_min (64 h_min, ... if a root is found again)
and the root is counted and reported with its true coordinates, which may lie outside the window by at most
about h_min. Splitting lines inside the window are moved instead. im_min = 0 is accepted and means "just
above the real axis": the bottom edge is placed at Im z = 1e-10 (the poles and branch cuts of F on the real
axis forbid a contour there), so neutral roots on the real axis are not counted.

For large finite eta the real-axis poles are dense and many roots sit just above them, so the count depends
on im_min (f = 0.9, beta = 0.3, gamma = 3, kH = 0.77, |Re z| <= 5: eta = 100 gives 1, 36, 85, 93 roots for
im_min = 1e-2, 1e-3, 1e-4, 1e-5): a stability verdict must state its window.
"""

from __future__ import annotations

import math

import numpy as np

from ._roots.contour import Problem
from ._validate import check

__all__ = ["unstable_count", "unstable_modes"]


# ------------------------------------------------------------------------------------------------
# public API
# ------------------------------------------------------------------------------------------------


def _problem(kH, gamma, f, beta, eta, Delta, xi, re_max, im_min, im_max) -> Problem:
    """Validate the arguments (ValueError naming the parameter and its range) and set up the problem."""
    physical = (("kH", kH), ("gamma", gamma), ("f", f), ("beta", beta), ("eta", eta), ("Delta", Delta), ("xi", xi))
    for name, v in physical:
        if np.ndim(v) != 0:
            raise ValueError(f"{name} must be a scalar here; got an array of shape {np.shape(v)}")
    vals = [float(check(name, v)) for name, v in physical]
    win = []
    for name, v in (("re_max", re_max), ("im_min", im_min), ("im_max", im_max)):
        if isinstance(v, (str, bytes, complex, np.complexfloating)) or np.ndim(v) != 0:
            raise ValueError(f"{name} must be a finite real number; got {v!r}")
        try:
            x = float(v)
        except (TypeError, ValueError):
            raise ValueError(f"{name} must be a finite real number; got {v!r}") from None
        if not math.isfinite(x):
            raise ValueError(f"{name} must be a finite real number; got {v!r}")
        win.append(x)
    re_m, im_lo, im_hi = win
    if re_m <= 0:
        raise ValueError(f"re_max must be > 0; got {re_m!r}")
    if im_lo < 0:
        raise ValueError(f"im_min must be >= 0; got {im_lo!r}")
    if im_hi <= im_lo:
        raise ValueError(f"im_max must be > im_min = {im_lo!r}; got {im_hi!r}")
    return Problem(*vals, re_m, im_lo, im_hi)


def unstable_count(
    kH,
    *,
    gamma,
    f,
    beta,
    eta=math.inf,
    Delta=1.0,
    xi=0.0,
    re_max: float = 5.0,
    im_min: float = 1e-4,
    im_max: float = 2.0,
) -> int:
    """Number of roots of F(z; kH) = 0 (Eq. implicit_spectrum with Eq. delta f RSF) in the closed window.

    Certified by the argument principle, N = (1/2 pi i) closed-integral F'/F dz along the boundary of
    [-re_max, re_max] x [im_min, im_max]; F has no poles in Im z > 0 (docs/physics.md §2), so no pole
    correction is needed. The phase of F is tracked continuously with adaptive refinement (see the module
    docstring for the acceptance criteria and the window semantics: roots on the boundary count).

    Parameters
    ----------
    kH : float > 0 (a scalar; ValueError otherwise)
    gamma, f, beta, eta, Delta, xi : physical parameters as in :func:`dispersion`
    re_max : > 0, half-width of the window in Re z
    im_min, im_max : 0 <= im_min < im_max, the window in Im z (im_min = 0 means Im z >= 1e-10)

    Returns
    -------
    int, the number of unstable modes (with multiplicity) in the window.
    """
    prob = _problem(kH, gamma, f, beta, eta, Delta, xi, re_max, im_min, im_max)
    return prob.outer()[1]


def unstable_modes(
    kH,
    *,
    gamma,
    f,
    beta,
    eta=math.inf,
    Delta=1.0,
    xi=0.0,
    re_max: float = 5.0,
    im_min: float = 1e-4,
    im_max: float = 2.0,
) -> np.ndarray:
    """Every root z = c/c_s of F(z; kH) = 0 (any branch) in the closed window, sorted by decreasing Im z.

    F is Eq. implicit_spectrum with Eq. delta f RSF and the response functions of Eq. Gs_general. The window
    is |Re z| <= re_max, im_min <= Im z <= im_max; roots on its boundary count (module docstring). The
    number of roots returned always equals :func:`unstable_count` for the same arguments: the rectangle is
    subdivided until each cell holds one root, which Newton's method (analytic F') polishes to
    |F| / scale < 1e-12 inside its cell (relative accuracy ~1e-15, at worst 1e-10). A RuntimeError naming
    the counts is raised if that cannot be achieved; a partial list is never returned.

    Parameters
    ----------
    kH : float > 0 (a scalar; ValueError otherwise)
    gamma, f, beta, eta, Delta, xi : physical parameters as in :func:`dispersion`
    re_max : > 0, half-width of the window in Re z
    im_min, im_max : 0 <= im_min < im_max, the window in Im z (im_min = 0 means Im z >= 1e-10)

    Returns
    -------
    1-D complex ndarray (repeated entries for a multiple root).
    """
    prob = _problem(kH, gamma, f, beta, eta, Delta, xi, re_max, im_min, im_max)
    return _modes(prob)[0]


def _modes(prob: Problem) -> tuple[np.ndarray, int]:
    """(roots sorted by decreasing Im z, number of evaluations of F) for a validated problem."""
    cell, n = prob.outer()
    roots = prob.locate(cell, n) if n else np.empty(0, dtype=np.complex128)
    if roots.size != n:
        raise RuntimeError(f"unstable_modes: located {roots.size} roots but the argument principle counts {n}")
    order = np.lexsort((roots.real, -roots.imag))
    return roots[order], prob.evaluations
