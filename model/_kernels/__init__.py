"""Compiled scalar kernels, one module per algorithm; the public, validated, broadcasting API is in the rest of model.

Everything here works on plain Python/NumPy scalars and arrays inside numba-compiled functions (docs/physics.md
§2-§9 give the equations and the numerics). A module uses only those above it:

=================  ===================================================================================================
``_common``        :func:`jitted`, the one decorator (compile options and the cache, below)
``records``        the records passed through the kernels: Params, Root, Box, Nodes, Path
``elementary``     complex elementary functions (overflow-safe |w|, 1/w, sqrt, exp, log, tanh/sech) and the series
                   and divided differences of g(u) = tanh(sqrt u)/sqrt u and psi(t) = expm1(t)/t
``response``       the response functions G_x, G_y in cancellation-free form and the dispersion function F, with
                   their derivatives (§2); F in the charts across the cuts beside the branch points (§14.7)
``newton``         Newton's method: the one loop and stopping rule for every root of the model (§8)
``rayleigh``       the Rayleigh speed z_R(beta), Newton on the Rayleigh cubic (§5)
``continuation``   predictor-corrector continuation of a root in ln kH (and the homotopy to its start at kH = 1e4)
``path``           the Rayleigh-branch path: nodes, their Hermite interpolant, roots at requested kH (§3, §8)
``growth``         the continuous max growth over a kH range, its band and its verdict (§9)
``neutral``        neutral modes: the thresholds of the max growth as certified roots (§9)
``contour``        the argument principle: adaptive sampling of F along lines, the winding number of a rectangle,
                   Newton in a cell (§10)
``window``         where the roots can be: the large-|z| bound of F and the window it gives (§14)
``cuts``           a root followed in kH in a chart across the cuts beside a branch point (§14.7)
=================  ===================================================================================================

Compile options and numba's cache
---------------------------------
Every compiled function of the model is decorated with :func:`jitted` (``@jitted``, or ``@jitted(inline="always")``
for the small helpers numba should inline into its callers), which holds the one set of options
(:data:`_common.OPTIONS`: ``cache=True, nogil=True``; no fastmath, so results are bit-reproducible).

numba's on-disk cache stamps a compiled function with the modification time and size of the function's own source
file only, while the machine code of a kernel contains every kernel it calls, inlined or linked, from whichever
module. With numba's own cache, after a change of (say) ``elementary.py`` a kernel of ``growth.py`` would still be
loaded with the old code of the elementary functions. :func:`jitted` therefore gives every function a cache
(:class:`_common.KernelCache`) whose stamp also holds :data:`_common.SOURCES`, the sha256 of all modules of this
package, computed at import: a change of any kernel module makes every cached kernel stale, and numba compiles it
again (and overwrites the stale entry) at its next call. tests/model/test_kernel_cache.py shows it on a copy: a
caller is recompiled after a change of its callee's module, where numba's own cache serves the stale code.

This module re-exports what the rest of model uses (and the pole-dense test of tests/model/test_boundary.py).
"""

from ._common import jitted
from .continuation import MAP_NODE_TOL, PRED_TOL
from .growth import (
    NOUT,
    SUBSONIC,
    V_MARGINAL,
    V_MASKED,
    V_NOBRANCH,
    V_POLE_DENSE,
    V_STABLE,
    V_UNSTABLE,
    growth_many,
    growth_point,
    is_pole_dense,
)
from .neutral import P_ETA, P_GAMMA, neutral_mode
from .newton import FULL_TOL, KH
from .path import INPUT, LOST, NOCONV, OK, START, branch_many, branch_one, build_path, solve_at
from .rayleigh import rayleigh_many, rayleigh_z
from .records import Box, Params
from .response import dispersion_dq, dispersion_eval, dispersion_many, response_many

__all__ = [
    "FULL_TOL", "INPUT", "KH", "LOST", "MAP_NODE_TOL", "NOCONV", "NOUT", "OK", "PRED_TOL", "P_ETA", "P_GAMMA", "START",
    "SUBSONIC", "V_MARGINAL", "V_MASKED", "V_NOBRANCH", "V_POLE_DENSE", "V_STABLE", "V_UNSTABLE", "Box", "Params",
    "is_pole_dense", "branch_many", "branch_one", "build_path", "dispersion_dq", "dispersion_eval", "dispersion_many",
    "growth_many", "growth_point", "jitted", "neutral_mode", "rayleigh_many", "rayleigh_z", "response_many",
    "solve_at",
]
