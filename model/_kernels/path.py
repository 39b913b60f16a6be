"""The Rayleigh-branch path: its interpolant and the roots at requested kH (docs/physics.md §3, §8).

:func:`build_path` follows the branch from kH = 1e4 down and up (:mod:`model._kernels.continuation`) and builds on
the nodes the degree-7 Hermite interpolant of the four surrounding nodes (:func:`_interp_table`, accurate to ~1e-12
on the fine path). Requested points are reached from it by Newton's method whose first step is certified with the
convergence constants measured at the nodes (:func:`solve_at`); with a looser rtol the interpolant itself is
returned where its truncation estimate allows. :func:`branch_many` and :func:`branch_one` are the entry points of
model.spectrum.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from ._common import jitted
from .continuation import (
    MAP_NODE_TOL,
    MAX_NODES,
    NODES_INITIAL,
    PRED_REJECT,
    PRED_TOL,
    PRED_TOL_FINE,
    S_TOP,
    THETA_MAX,
    continue_root,
    new_nodes,
    rayleigh_start,
    unwrap_phase,
)
from .elementary import ABS_FLOOR, cinv, clog
from .newton import FULL_TOL, LN_KH, SHRINK_PATH, local_scale, newton_root
from .rayleigh import rayleigh_z
from .records import NO_BOX, Nodes, Params, Path

# status codes of a point of the branch (model.spectrum.STATUS)
OK = 0
LOST = 1  # the branch could not be followed down to this kH (collision / ill-conditioning)
NOCONV = 2  # Newton did not converge at this kH although the path reached it
START = 3  # the starting root at kH = 1e4 could not be found
INPUT = 4  # the parameters themselves were NaN

EXTRA_NODES = 2  # nodes built beyond the requested range: the end intervals keep two nodes on each side
SOLVE_ITERS = 10  # Newton at a requested point from the interpolant (~1e-12 accurate): usually one step
C_FIRST_SAFETY = 10.0  # C at a requested point: this x the largest C of the four surrounding nodes (margin for
# its variation between nodes, where it was measured with larger steps)
RTOL_MARGIN = 0.1  # with a requested rtol, points are accepted once their estimated error is below 0.1 rtol
MAP_NODE_RTOL = 1e-3  # MAP_NODE_TOL tightened to this x rtol where the interpolant may be reported (a looser rtol)
RTOL_COARSE_PATH = 1e-7  # from this rtol on the spectrum uses the coarse path (PRED_TOL, interpolant ~1e-8)


@jitted(inline="always")
def _path_tol(rtol: float) -> float:
    """Predictor target of the spectrum's path: fine (interpolant ~1e-12) unless rtol >= RTOL_COARSE_PATH."""
    return PRED_TOL if rtol >= RTOL_COARSE_PATH else PRED_TOL_FINE


@jitted(inline="always")
def map_node_tol(rtol: float) -> float:
    """Node accuracy of a growth map's path: MAP_NODE_TOL (the grid only brackets; the reported values are
    re-solved from the nodes), tightened to MAP_NODE_RTOL rtol where a looser rtol lets the interpolant be
    reported."""
    return MAP_NODE_TOL if rtol <= 0.0 else max(FULL_TOL, min(MAP_NODE_TOL, MAP_NODE_RTOL * rtol))


@jitted(inline="always")
def _target(rtol: float) -> float:
    """Relative error target of one root: full accuracy for rtol <= 0, else RTOL_MARGIN * rtol."""
    return FULL_TOL if rtol <= 0.0 else max(FULL_TOL, RTOL_MARGIN * rtol)


NTERM = 8  # Hermite data of up to four nodes (value and slope): degree-7 interpolant per interval


@jitted
def _interp_table(ns: np.ndarray, nw: np.ndarray, nd: np.ndarray,
                  nn: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Newton-form coefficients of the Hermite interpolant on each path interval [ns[j], ns[j+1]].

    nw, nd: ln z and d ln z/ds at the nodes (or z and dz/ds). The interpolant of interval j matches
    values and slopes at nodes j, j+1, j-1, j+2 (those that exist): degree 7 inside the path, 5 at
    its ends. Returns (nodes x (nn-1, 8), coefficients c (nn-1, 8), number of terms m (nn-1)) with
    p(s) = c0 + (s - x0)(c1 + (s - x1)(c2 + ...)).
    """
    ni = max(nn - 1, 0)
    cx = np.zeros((ni, NTERM))
    cf = np.zeros((ni, NTERM), dtype=np.complex128)
    cm = np.zeros(ni, dtype=np.int64)
    idx = np.empty(4, dtype=np.int64)
    for j in range(ni):
        k = 0
        for node in (j, j + 1, j - 1, j + 2):
            if 0 <= node < nn:
                idx[k] = node
                k += 1
        m = 2 * k
        # the row's abscissae and coefficients indexed in place (row views cost a reference count each)
        for i in range(k):
            cx[j, 2 * i] = ns[idx[i]]
            cx[j, 2 * i + 1] = ns[idx[i]]
            cf[j, 2 * i] = nw[idx[i]]
            cf[j, 2 * i + 1] = nw[idx[i]]
        # divided differences in place (column 1: slopes at the doubled nodes)
        for i in range(m - 1, 0, -1):
            if i % 2 == 1:
                cf[j, i] = nd[idx[i // 2]]
            else:
                cf[j, i] = (cf[j, i] - cf[j, i - 1]) * (1.0 / (cx[j, i] - cx[j, i - 1]))
        for order in range(2, m):
            for i in range(m - 1, order - 1, -1):
                cf[j, i] = (cf[j, i] - cf[j, i - 1]) * (1.0 / (cx[j, i] - cx[j, i - order]))
        cm[j] = m
    return cx, cf, cm


@jitted(inline="always")
def interp_value(s: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray) -> complex:
    """Value of the Hermite interpolant of interval j at s (Horner on the Newton form of Path.cx, cf, cm)."""
    m = cm[j]
    p = cf[j, m - 1]
    for k in range(m - 2, -1, -1):
        p = p * (s - cx[j, k]) + cf[j, k]
    return p


@jitted(inline="always")
def interp_node(s: float, j: int, cx: np.ndarray, cf: np.ndarray, cm: np.ndarray) -> tuple[complex, complex, complex,
                                                                                       float]:
    """(p, p', p'', truncation estimate) of the Hermite interpolant of interval j at s (Path.cx, cf, cm).

    The estimate is |last term| + |second-to-last term| of the Newton form: the difference between the
    interpolant and the one with the data of the outermost node removed (an upper estimate of the error).
    """
    m = cm[j]
    p = cf[j, m - 1]
    dp = 0j
    d2p = 0j
    for k in range(m - 2, -1, -1):
        t = s - cx[j, k]
        d2p = d2p * t + 2.0 * dp
        dp = dp * t + p
        p = p * t + cf[j, k]
    w = 1.0
    for k in range(m - 2):
        w *= abs(s - cx[j, k])
    est = (abs(cf[j, m - 2]) + abs(cf[j, m - 1] * (s - cx[j, m - 2]))) * w
    return p, dp, d2p, est


@jitted
def _no_path() -> Path:
    """The empty Path (n = 0) that build_path returns with a failure code."""
    ns = np.empty(1)
    return Path(ns, np.empty(1, dtype=np.complex128), ns, ns, np.zeros((0, NTERM)),
                np.zeros((0, NTERM), dtype=np.complex128), np.zeros(0, dtype=np.int64), 0, True)


@jitted
def build_path(s_lo: float, s_hi: float, z_r: float, p: Params, pred_tol: float, node_tol: float) -> tuple[Path, int]:
    """Rayleigh-branch path covering [s_lo, s_hi] (s = ln kH), ascending in s, with its interpolation table.

    Start at ln 1e4 (see rayleigh_start), continue down to EXTRA_NODES nodes below min(s_lo, ln 1e4) and up
    to EXTRA_NODES nodes above max(s_hi, ln 1e4) -- unless EXTRA_NODES nodes of the downward path lie above s_hi
    already (a growth map up to kH = 1e3): the interpolant of every interval up to s_hi is then the same without
    the upward nodes and without the downward ones above those EXTRA_NODES, which are dropped. The node sequence
    depends only on the physical parameters; s_lo/s_hi only decide where it is cut off. pred_tol and node_tol: see
    continue_root. Returns (path, code)
    with code OK, START (no starting root; path.n = 0) or INPUT (NaN parameter; path.n = 0).
    """
    for v in p:
        if math.isnan(v):
            return _no_path(), INPUT
    z0, dz0, e0, ok = rayleigh_start(z_r, p)
    if not ok:
        return _no_path(), START
    nd, _, dn = continue_root(z0, dz0, e0, S_TOP, min(s_lo, S_TOP), EXTRA_NODES, -1.0, LN_KH, 1.0, p, pred_tol,
                          node_tol, new_nodes(NODES_INITIAL), MAX_NODES)
    top = 0  # downward nodes before this index are dropped (they lie above the EXTRA_NODES nodes above s_hi)
    if nd > EXTRA_NODES and s_hi < dn.s[EXTRA_NODES - 1]:
        # EXTRA_NODES nodes of the downward path lie above s_hi already: the interpolant up to s_hi needs no more
        nu, up = 1, dn
        while top + EXTRA_NODES < nd and dn.s[top + EXTRA_NODES] > s_hi:
            top += 1
    else:
        nu, _, up = continue_root(z0, dz0, e0, S_TOP, max(s_hi, S_TOP), EXTRA_NODES, 1.0, LN_KH, 1.0, p, pred_tol,
                              node_tol, new_nodes(NODES_INITIAL), MAX_NODES)
    nd -= top
    return _path_on(_ascending(dn, nd, top, up, nu), nd + nu - 1), OK


@jitted
def _ascending(dn: Nodes, nd: int, top: int, up: Nodes, nu: int) -> Nodes:
    """The nodes of a path ascending in s: the downward nodes dn[top:top + nd] in reverse order, then up[1:nu] (node 0
    of both is the start)."""
    nn = nd + nu - 1
    ns = np.empty(nn)
    nz = np.empty(nn, dtype=np.complex128)
    ndz = np.empty(nn, dtype=np.complex128)
    nc = np.empty(nn)
    ne = np.empty(nn)
    for i in range(nd):
        k = nd - 1 - i + top
        ns[i] = dn.s[k]
        nz[i] = dn.z[k]
        ndz[i] = dn.dzds[k]
        nc[i] = dn.conv[k]
        ne[i] = dn.err[k]
    for i in range(1, nu):
        k = nd - 1 + i
        ns[k] = up.s[i]
        nz[k] = up.z[i]
        ndz[k] = up.dzds[i]
        nc[k] = up.conv[i]
        ne[k] = up.err[i]
    return Nodes(ns, nz, ndz, nc, ne)


@jitted
def _path_on(nodes: Nodes, nn: int) -> Path:
    """The path on nn ascending nodes: the interpolation table of ln z (of z if a node is exactly 0) built on them
    (their slopes are overwritten with those of ln z)."""
    ns, nz, ndz, nc, ne = nodes
    use_log = True
    for i in range(nn):
        use_log = use_log and nz[i] != 0
    if use_log:
        nw = np.empty(nn, dtype=np.complex128)
        for i in range(nn):
            nw[i] = clog(nz[i])
            if i > 0:
                nw[i] = unwrap_phase(nw[i], nw[i - 1])
            ndz[i] = ndz[i] * cinv(nz[i])
        cx, cf, cm = _interp_table(ns, nw, ndz, nn)
    else:
        cx, cf, cm = _interp_table(ns, nz, ndz, nn)
    return Path(ns, nz, nc, ne, cx, cf, cm, nn, use_log)


@jitted(inline="always")
def node_interval(s: float, ns: np.ndarray, nn: int) -> int:
    """Index j of the path interval [ns[j], ns[j+1]] holding s (-1 outside the path or for nn < 2 nodes)."""
    if nn < 2 or not (ns[0] <= s <= ns[nn - 1]):
        return -1
    j = np.searchsorted(ns, s, side="right") - 1  # ns[j] <= s
    return min(j, nn - 2)


@jitted(inline="always")
def _around(v: np.ndarray, j: int, nn: int) -> float:
    """Largest of v over the (up to) four nodes j-1 .. j+2 whose data the interpolant of interval j uses."""
    return max(max(v[max(j - 1, 0)], v[j]), max(v[j + 1], v[min(j + 2, nn - 1)]))


@jitted
def path_value(s: float, path: Path) -> tuple[complex, complex, complex, float]:
    """(z, dz/ds, d2z/ds2, estimated relative error) of the path interpolant at s (NaN outside the path)."""
    nanz = complex(math.nan, math.nan)
    ns, nz, _, _, cx, cf, cm, nn, use_log = path
    j = node_interval(s, ns, nn)
    if j < 0:
        if nn == 1 and s == ns[0]:
            return nz[0], nanz, nanz, 0.0
        return nanz, nanz, nanz, math.nan
    p, dp, d2p, est = interp_node(s, j, cx, cf, cm)
    if use_log:
        z = cmath.exp(p)
        return z, dp * z, (d2p + dp * dp) * z, est
    return p, dp, d2p, est / max(abs(p), ABS_FLOOR)


@jitted(inline="always")
def solve_at_unpacked(s: float, ns: np.ndarray, nz: np.ndarray, nc: np.ndarray, ne: np.ndarray, cx: np.ndarray,
              cf: np.ndarray, cm: np.ndarray, nn: int, use_log: bool, p: Params,
              rtol: float) -> tuple[complex, int, float, float, complex]:
    """The Rayleigh-branch root at s = ln kH from the path (its fields unpacked, see Path): (z, status, residual,
    error, dz/ds).

    Start from the Hermite interpolant of the path nodes. With rtol > 0 the interpolant itself is
    returned where its truncation estimate plus the nodes' error estimates is below RTOL_MARGIN rtol
    (residual NaN: F not evaluated; dz/ds from the interpolant). Otherwise Newton's method (newton_root)
    with the first step certified by the quadratic-convergence constants measured at the surrounding
    path nodes (their steps passed the contraction certificate with larger predictor errors), times
    C_FIRST_SAFETY: where that bounds the error after one step below the target (_target), the point
    costs one evaluation of F. Further steps must show a strong first contraction (THETA_MAX) and end
    near the prediction (PRED_REJECT), else NOCONV. Outside the nodes' range the branch was lost (LOST).
    """
    nanz = complex(math.nan, math.nan)
    j = node_interval(s, ns, nn)
    if j < 0:
        if nn == 1 and s == ns[0]:
            return nz[0], OK, 0.0, 0.0, nanz
        return nanz, LOST, math.nan, math.nan, nanz
    if rtol > 0.0:
        w, dw, _, est = interp_node(s, j, cx, cf, cm)
        if use_log:
            zp = cmath.exp(w)
            dzp = dw * zp
        else:
            zp = w
            dzp = dw
            est /= max(abs(w), ABS_FLOOR)
        # add the nodes' own errors (the truncation estimate is 0 at a node)
        est += _around(ne, j, nn)
        if est <= RTOL_MARGIN * rtol:
            return zp, OK, math.nan, est * abs(zp), dzp
    else:
        w = interp_value(s, j, cx, cf, cm)
        zp = cmath.exp(w) if use_log else w
    c_nodes = C_FIRST_SAFETY * _around(nc, j, nn)
    r = newton_root(zp, LN_KH, s, 1.0, p, SOLVE_ITERS, _target(rtol), c_nodes, SHRINK_PATH, 1.0, NO_BOX)
    if r.ok and r.theta <= THETA_MAX and abs(r.z - zp) <= PRED_REJECT * local_scale(r.z):
        return r.z, OK, r.resid, r.err, r.dzds
    return nanz, NOCONV, math.nan, math.nan, nanz


@jitted
def solve_at(s: float, path: Path, p: Params, rtol: float) -> tuple[complex, int, float, float, complex]:
    """solve_at_unpacked for one point of a path (the loops over points inline solve_at_unpacked instead)."""
    ns, nz, nc, ne, cx, cf, cm, nn, use_log = path
    return solve_at_unpacked(s, ns, nz, nc, ne, cx, cf, cm, nn, use_log, p, rtol)


@jitted
def branch_solve(s_req: np.ndarray, z_r: float, p: Params, rtol: float, z_out: np.ndarray, status: np.ndarray,
                 resid: np.ndarray, err: np.ndarray) -> None:
    """Rayleigh-branch roots at the requested s = ln kH values for one parameter set.

    Each requested point is reached from the interpolated path nodes by Newton's method
    (solve_at), so its digits do not depend on the other requests.
    """
    m = s_req.shape[0]
    if m == 0:
        return
    path, code = build_path(s_req.min(), s_req.max(), z_r, p, _path_tol(rtol), FULL_TOL)
    ns, nz, nc, ne, cx, cf, cm, nn, use_log = path  # unpacked once (see Path)
    for i in range(m):
        if code != OK:
            z_out[i] = complex(math.nan, math.nan)
            status[i] = code
            resid[i] = math.nan
            err[i] = math.nan
            continue
        z_out[i], status[i], resid[i], err[i], _ = solve_at_unpacked(s_req[i], ns, nz, nc, ne, cx, cf, cm, nn,
                                                                      use_log, p, rtol)


@jitted
def branch_many(s_req: np.ndarray, gamma: np.ndarray, f: np.ndarray, beta: np.ndarray, eta: np.ndarray,
                delta: np.ndarray, xi: np.ndarray, rtol: float, z_out: np.ndarray, status: np.ndarray,
                resid: np.ndarray, err: np.ndarray) -> None:
    """branch_solve for many parameter sets (rows of the 2-D outputs)."""
    for i in range(gamma.shape[0]):
        p = Params(gamma[i], f[i], beta[i], eta[i], delta[i], xi[i])
        branch_solve(s_req, rayleigh_z(beta[i]), p, rtol, z_out[i], status[i], resid[i], err[i])


@jitted
def branch_one(s_req: np.ndarray, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float,
               rtol: float, z_out: np.ndarray, status: np.ndarray, resid: np.ndarray, err: np.ndarray) -> None:
    """branch_solve for one parameter set given as scalars (1-D outputs)."""
    branch_solve(s_req, rayleigh_z(beta), Params(gamma, f, beta, eta, delta, xi), rtol, z_out, status, resid, err)
