"""Predictor-corrector continuation of one root: the nodes of a Rayleigh-branch path (docs/physics.md §3, §8).

Adaptive continuation in s = ln kH from the root at kH = 1e4 (:func:`continue_root`), which :func:`rayleigh_start`
finds by a homotopy in tau = 1/gamma (the same continuation in tau): the predictor is the cubic Hermite extrapolant
of ln z through the last two nodes (values and analytic slopes), for eta = inf the quintic one through the last
three; every node is a certified Newton root (contraction rate <= THETA_MAX, predictor error <= PRED_REJECT of the
distance to the singularities). :mod:`model._kernels.path` builds the path's interpolant on the nodes.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from ._common import jitted
from .elementary import ABS_FLOOR, cabs, cinv, clog, real_root
from .newton import FULL_TOL, LN_KH, SHRINK_PATH, TAU, eval_mode, local_scale, newton_root
from .records import NO_BOX, Nodes, Params

S_TOP = math.log(1e4)  # the branch is defined by its root at kH = 1e4 (docs/physics.md §3)
H_MAX = 0.4  # largest continuation step in ln(kH)
CUT_APPROACH = 0.9  # eta = inf: a step covers at most this fraction of the way to the branch cut (see continue_root)
H_MIN = 1e-7  # a step this short that still fails: the branch is lost (collision with another branch)
H_START = 0.05  # first continuation step in ln(kH)
TAU_H_START = 0.25  # first step of the homotopy in tau = 1/gamma, as a fraction of [0, 1/gamma]
PRED_TOL = 1e-3  # target predictor error per step, relative to local_scale (coarse paths)
PRED_TOL_FINE = 1e-4  # the same for paths whose interpolant should be accurate to ~1e-12 (spectrum)
PRED_OVERSHOOT = 10.0  # steps whose predictor error exceeds this multiple of the target are retried shorter
PRED_REJECT = 1e-2  # predictor error (relative to local_scale) above which a step is rejected
THETA_MAX = 0.1  # largest first Newton contraction rate accepted (basin certificate, see newton_root)
NODE_ITERS = 6  # Newton evaluations allowed for a node (from a predictor within PRED_REJECT: a few)
NODE_EVALS = 5  # a node that needed more evaluations is retried with a shorter step (predictor too far)
STEP_SAFETY = 0.9  # safety factor on the step the error model predicts for pred_tol (the model is asymptotic)
STEP_GROW = 2.0  # after an accepted node the step at most doubles ...
STEP_CUT = 0.5  # ... and at most halves
RETRY_CUT_MIN = 0.2  # a step certified but too far from its prediction is shortened by the error model,
RETRY_CUT_MAX = 0.5  # by a factor in [RETRY_CUT_MIN, RETRY_CUT_MAX]
RETRY_HALVE = 0.5  # a step whose Newton failed (or failed the certificate) is halved
MAX_NODES = 8192  # nodes per direction (typically ~100 for kH in [1e-4, 1e4]); a path filling it counts as lost
START_NODES = 4096  # nodes of the tau homotopy (typically 5, a few hundred at most seen)
# node buffers start this small and double when full (up to the limits above): allocating the limits at every call
# cost more than the continuation where freed memory goes back to the OS at once (Dask workers set glibc's
# MALLOC_TRIM_THRESHOLD_), and the typical path needs a hundred nodes
NODES_INITIAL = 128
START_ITERS = 20  # Newton from z_R at tau = 0, kH = 1e4, where z_R is the root to rounding: a wide margin
MAP_NODE_TOL = 1e-10  # relative accuracy of the path nodes of a growth map (see map_node_tol)


@jitted
def new_nodes(n: int) -> Nodes:
    """Empty node buffers of length n."""
    return Nodes(np.empty(n), np.empty(n, dtype=np.complex128), np.empty(n, dtype=np.complex128), np.empty(n),
                 np.empty(n))


@jitted
def _grown(out: Nodes, n: int, cap: int) -> Nodes:
    """Node buffers of length cap holding the first n nodes of out."""
    new = new_nodes(cap)
    new.s[:n] = out.s[:n]
    new.z[:n] = out.z[:n]
    new.dzds[:n] = out.dzds[:n]
    new.conv[:n] = out.conv[:n]
    new.err[:n] = out.err[:n]
    return new


@jitted(inline="always")
def _hermite2(s0: float, w0: complex, d0: complex, s1: float, w1: complex, d1: complex, s: float) -> complex:
    """Cubic Hermite interpolant/extrapolant through (s0, w0, w0') and (s1, w1, w1'), evaluated at s."""
    ih = 1.0 / (s1 - s0)
    f01 = (w1 - w0) * ih
    f001 = (f01 - d0) * ih
    f0011 = ((d1 - f01) * ih - f001) * ih
    x = s - s0
    return w0 + x * (d0 + x * (f001 + (s - s1) * f0011))


@jitted(inline="always")
def _hermite3(s0: float, w0: complex, d0: complex, s1: float, w1: complex, d1: complex, s2: float, w2: complex,
              d2: complex, s: float) -> complex:
    """Quintic Hermite interpolant/extrapolant through three nodes (values and slopes), evaluated at s."""
    i10 = 1.0 / (s1 - s0)
    i21 = 1.0 / (s2 - s1)
    i20 = 1.0 / (s2 - s0)
    f01 = (w1 - w0) * i10
    f12 = (w2 - w1) * i21
    f001 = (f01 - d0) * i10
    f011 = (d1 - f01) * i10
    f112 = (f12 - d1) * i21
    f122 = (d2 - f12) * i21
    f0011 = (f011 - f001) * i10
    f0112 = (f112 - f011) * i20
    f1122 = (f122 - f112) * i21
    f00112 = (f0112 - f0011) * i20
    f01122 = (f1122 - f0112) * i20
    f001122 = (f01122 - f00112) * i20
    x0 = s - s0
    x1 = s - s1
    x2 = s - s2
    return w0 + x0 * (d0 + x0 * (f001 + x1 * (f0011 + x1 * (f00112 + x2 * f001122))))


@jitted(inline="always")
def unwrap_phase(w: complex, ref: complex) -> complex:
    """ln z with the phase shifted by a multiple of 2 pi to lie within pi of ln z_ref."""
    k = math.floor((w.imag - ref.imag) / (2.0 * math.pi) + 0.5)
    return complex(w.real, w.imag - 2.0 * math.pi * k)


@jitted
def continue_root(z0: complex, dz0: complex, e0: float, s0: float, s_stop: float, extra: int, direction: float,
              mode: int, q: float, p: Params, pred_tol: float, node_tol: float, out: Nodes,
              max_nodes: int) -> tuple[int, bool, Nodes]:
    """Adaptive predictor-corrector continuation of one root in s from s0 towards s_stop (mode LN_KH or TAU).

    Nodes are written to out (node 0 = start, slope dz0, error e0); continues until `extra` nodes lie
    beyond s_stop (or, if extra == 0, stops exactly at s_stop). The sequence of nodes depends only on the
    start and the physical parameters, never on s_stop, except for where it is cut off. The predictor is
    the cubic Hermite extrapolant of ln z through the last two nodes (values and slopes) -- for eta = inf the
    quintic one through the last three (O(h^6): longer steps for the same predictor error; for finite eta it moved
    where the branch counts as lost, see docs/physics.md §8); every node is a
    converged Newton root (to node_tol relative) whose first contraction rate passed the basin certificate
    (THETA_MAX) with a predictor error below PRED_REJECT of local_scale. The step size aims at a predictor
    error of pred_tol (relative to local_scale); steps above PRED_OVERSHOOT pred_tol are retried shorter,
    which bounds the error of the path interpolant. For eta = inf a root moving towards the branch cut (the real
    axis at |Re z| >= 1, which it cannot cross on the physical sheet) takes steps of at most CUT_APPROACH of the
    linear distance to it, so that the approach that ends in a lost branch costs a node per decade instead of
    rejected steps (30 % of the sets of a 64^4 atlas: 7.9 -> 0.7 rejected steps per set); the acceptance tests
    are unchanged. out.conv receives the quadratic-convergence constant
    observed at each node. The buffers double when full, up to max_nodes (then the branch counts as lost).
    Returns (number of nodes, lost flag, the buffers holding them).
    """
    o_s, o_z, o_d, o_c, o_e = out  # unpacked once (see Path)
    o_s[0] = s0
    o_z[0] = z0
    o_d[0] = dz0
    o_c[0] = 0.0
    o_e[0] = e0
    cap = o_s.shape[0]
    use_log = z0 != 0
    # predictor data (ln z and d ln z/ds, or z and dz/ds) of the last three nodes, the current one last
    pred = (0j, 0j, 0j, 0j, clog(z0) if use_log else z0, dz0 / z0 if use_log else dz0)
    n = 1
    h = H_START if mode == LN_KH else TAU_H_START * abs(s_stop - s0)
    h_cap = H_MAX if mode == LN_KH else abs(s_stop - s0)
    beyond = 0
    cut = math.isinf(p.eta)
    while True:
        s_cur = o_s[n - 1]
        if extra == 0:
            if direction * (s_stop - s_cur) <= 0.0:
                return n, False, out
            h_try = min(h, direction * (s_stop - s_cur))
        else:
            if beyond >= extra:
                return n, False, out
            h_try = h
        if n >= cap:
            if cap >= max_nodes:
                return n, True, out
            out = _grown(out, n, min(2 * cap, max_nodes))
            o_s, o_z, o_d, o_c, o_e = out
            cap = o_s.shape[0]
        found, s_new, z, dzds, conv, rel_err, h_try, err, order = _corrected(
            s_cur, h_try, direction, o_s, n, pred, use_log, cut, mode, q, p, pred_tol, node_tol)
        if not found:
            return n, True, out
        o_s[n] = s_new
        o_z[n] = z
        o_d[n] = dzds
        o_c[n] = conv
        o_e[n] = rel_err
        if use_log and z == 0:
            return n + 1, True, out  # cannot happen on a followable branch (z = 0 is no root for kH > 0)
        pred = (pred[2], pred[3], pred[4], pred[5], unwrap_phase(clog(z), pred[4]) if use_log else z,
                dzds * cinv(z) if use_log else dzds)
        n += 1
        if extra > 0 and direction * (s_new - s_stop) > 0.0:
            beyond += 1
        h = _next_step(h_try, err, order, pred_tol, h_cap, cut, z, dzds, direction)


@jitted(inline="always")
def _predict(o_s: np.ndarray, n: int, cut: bool, pred: tuple[complex, complex, complex, complex, complex, complex],
             s_cur: float, s_new: float) -> complex:
    """The predictor of ln z (or z) at s_new from the n nodes so far (positions o_s, predictor data pred, see
    continue_root): linear from one node, the cubic Hermite extrapolant from two, for eta = inf (cut) the quintic one
    from three."""
    wq, dq, wp, dp, wc, dc = pred
    if n == 1:
        return wc + dc * (s_new - s_cur)
    if n >= 3 and cut:
        return _hermite3(o_s[n - 3], wq, dq, o_s[n - 2], wp, dp, s_cur, wc, dc, s_new)
    return _hermite2(o_s[n - 2], wp, dp, s_cur, wc, dc, s_new)


@jitted
def _corrected(s_cur: float, h_try: float, direction: float, o_s: np.ndarray, n: int,
               pred: tuple[complex, complex, complex, complex, complex, complex], use_log: bool, cut: bool, mode: int,
               q: float, p: Params, pred_tol: float,
               node_tol: float) -> tuple[bool, float, complex, complex, float, float, float, float, float]:
    """The node after s_cur (see continue_root): predictor, then Newton's method as corrector; a step whose root is not
    accepted is retried shorter (by the error model where the root was certified, else halved).

    Returns (found, s, z, dz/ds, convergence constant, relative error of z, the step taken, the predictor error
    relative to local_scale, that error's order in the step); found is False (the branch is lost) once the step
    falls below H_MIN.
    """
    nanz = complex(math.nan, math.nan)
    while True:
        if h_try < H_MIN:
            return False, math.nan, nanz, nanz, 0.0, 0.0, h_try, 0.0, 0.0
        s_new = s_cur + direction * h_try
        wpred = _predict(o_s, n, cut, pred, s_cur, s_new)
        zp = cmath.exp(wpred) if use_log else wpred
        r = newton_root(zp, mode, s_new, q, p, NODE_ITERS, node_tol, 0.0, SHRINK_PATH, 1.0, NO_BOX)
        err = cabs(r.z - zp) / local_scale(r.z)
        # predictor error O(h^2) from one node, O(h^4) from two, O(h^6) from three (eta = inf)
        order = 2.0 if n == 1 else (6.0 if (n >= 3 and cut) else 4.0)
        certified = r.ok and err <= PRED_REJECT and r.theta <= THETA_MAX and cmath.isfinite(r.dzds)
        if certified and r.evals <= NODE_EVALS and err <= PRED_OVERSHOOT * pred_tol:
            conv = r.theta / r.first if (r.first > 0.0 and r.theta > 0.0) else 0.0
            return True, s_new, r.z, r.dzds, conv, r.err / max(cabs(r.z), ABS_FLOOR), h_try, err, order
        if certified:
            # certified but too far from the prediction for the target: shorten by the error model
            h_try *= min(RETRY_CUT_MAX, max(RETRY_CUT_MIN, STEP_SAFETY * real_root(pred_tol / err, order)))
        else:
            h_try *= RETRY_HALVE


@jitted(inline="always")
def _next_step(h_try: float, err: float, order: float, pred_tol: float, h_cap: float, cut: bool, z: complex,
               dzds: complex, direction: float) -> float:
    """The step after a node accepted with step h_try and predictor error err of the given order: aimed at
    pred_tol by the error model (growing at most STEP_GROW, shrinking at most STEP_CUT times), at most h_cap, and
    for eta = inf (cut) at most CUT_APPROACH of the linear distance to the branch cut where the root moves towards
    it."""
    fac = STEP_GROW if err == 0.0 else STEP_SAFETY * real_root(pred_tol / err, order)
    fac = min(STEP_GROW, max(STEP_CUT, fac))
    h = min(h_cap, h_try * fac)
    if cut:
        rate = direction * dzds.imag
        if abs(z.real) >= 1.0 and z.imag * rate < 0.0:
            h = min(h, CUT_APPROACH * (-z.imag / rate))
    return h


@jitted
def rayleigh_start(z_r: float, p: Params) -> tuple[complex, complex, float, bool]:
    """The Rayleigh-branch root at kH = 1e4 and its slope dz/d(ln kH): homotopy in tau = 1/gamma from
    tau = 0 (gamma = inf, where the root is the Rayleigh root of the large-kH response, found by Newton
    from z_R) to 1/gamma. Returns (z, dz/ds, estimated relative error of z, found)."""
    q = math.exp(S_TOP)
    work = new_nodes(min(NODES_INITIAL, START_NODES))
    nanz = complex(math.nan, math.nan)
    r = newton_root(z_r + 0j, TAU, 0.0, q, p, START_ITERS, FULL_TOL, 0.0, SHRINK_PATH, 1.0, NO_BOX)
    if not r.ok:
        return r.z, nanz, math.nan, False
    # eta = inf: homotopy nodes to MAP_NODE_TOL and one full-accuracy Newton at its end; for finite eta this
    # changed the start of small-gamma sets, so there every node is at full accuracy
    cut = math.isinf(p.eta)
    n, lost, work = continue_root(r.z, r.dzds, r.err / max(abs(r.z), ABS_FLOOR), 0.0, 1.0 / p.gamma, 0, 1.0, TAU, q, p,
                              PRED_TOL, MAP_NODE_TOL if cut else FULL_TOL, work, START_NODES)
    z = work.z[n - 1]
    if lost:
        return z, nanz, math.nan, False
    err = work.err[n - 1]
    if cut:
        r = newton_root(z, TAU, 1.0 / p.gamma, q, p, START_ITERS, FULL_TOL, 0.0, SHRINK_PATH, 1.0, NO_BOX)
        if not r.ok:
            return r.z, nanz, math.nan, False
        z = r.z
        err = r.err / max(abs(z), ABS_FLOOR)
    fv, dfv, _, fs = eval_mode(z, LN_KH, S_TOP, q, p)
    if not (cmath.isfinite(fv) and cmath.isfinite(dfv)) or dfv == 0:
        return z, nanz, math.nan, False
    return z, -fs / dfv, err, True
