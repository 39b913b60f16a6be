"""The records that travel through the kernels (numba passes a NamedTuple by value, like its fields).

:class:`Params`, the six physical parameters of F; :class:`Root`, what the one Newton loop
(:func:`model._kernels.newton.newton_root`) returns, and :class:`Box`, the rectangle that confines it;
:class:`Nodes`, the buffers a continuation fills (:mod:`model._kernels.continuation`); :class:`Path`, a followed
Rayleigh branch (its nodes and the interpolation table built on them, :mod:`model._kernels.path`).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np


class Params(NamedTuple):
    """The physical parameters of F (docs/physics.md §1; delta is Delta). All floats: numba types the record as
    a homogeneous tuple of six float64, passed by value like six scalars."""

    gamma: float
    f: float
    beta: float
    eta: float
    delta: float
    xi: float


class Root(NamedTuple):
    """What newton_root returns."""

    z: complex  # the last iterate
    ok: bool  # converged by the stopping rule of newton_root
    evals: int  # evaluations of F made
    first: float  # |first step|
    theta: float  # first contraction rate |step 2| / |step 1| (0 if converged at the first evaluation)
    resid: float  # |F(z)| / scale predicted by the quadratic model (inf if not converged)
    err: float  # estimated absolute error of z (inf if not converged)
    dzds: complex  # branch slope dz/ds = -F_s/F_z at z (NaN if not converged)


class Box(NamedTuple):
    """A rectangle the iterates of newton_root must stay in (a root confined to its cell in model.modes)."""

    re_lo: float
    re_hi: float
    im_lo: float
    im_hi: float


NO_BOX = Box(-math.inf, math.inf, -math.inf, math.inf)


class Nodes(NamedTuple):
    """Buffers of path nodes filled by continue_root (node 0 = the start)."""

    s: np.ndarray  # continuation parameter (ln kH, or tau = 1/gamma)
    z: np.ndarray  # roots (complex)
    dzds: np.ndarray  # branch slopes dz/ds (complex)
    conv: np.ndarray  # quadratic-convergence constants C = |step 2| / |step 1|^2 of the nodes' Newton (0: one step)
    err: np.ndarray  # estimated relative errors of the roots


class Path(NamedTuple):
    """A followed Rayleigh branch (build_path): nodes ascending in s = ln kH and the interpolant through them.

    Functions that loop over points (branch_solve, _refine_peak, _zero_on_path) unpack the record once,
    ``ns, nz, nc, ne, cx, cf, cm, nn, use_log = path``, and pass the fields to the per-point helpers (node_interval,
    interp_node, _im_at, solve_at_unpacked, inlined into the loop): every read of an array field of a record costs an
    atomic reference-count increment and decrement, which inside a loop is a third of the time of an interpolated point.
    """

    s: np.ndarray  # node positions ln kH, ascending
    z: np.ndarray  # roots at the nodes
    conv: np.ndarray  # quadratic-convergence constants of the nodes (Nodes.conv)
    err: np.ndarray  # estimated relative errors of the nodes
    cx: np.ndarray  # interpolation table (_interp_table): abscissae (n-1, NTERM) of each interval's Newton form,
    cf: np.ndarray  # its coefficients (n-1, NTERM), of ln z (use_log) or of z,
    cm: np.ndarray  # and its number of terms (n-1)
    n: int  # number of nodes (0: no path)
    use_log: bool  # the table interpolates ln z (False only if a node is exactly 0)
