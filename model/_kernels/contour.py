"""Contour sampling for the argument principle: adaptive sampling of F along a line, and Newton in a cell.

The compiled core of :mod:`model.modes` (docs/physics.md §10; the module docstring of model.modes states the
acceptance tests of a sampled segment and the window semantics) and of the whole-spectrum search of
:mod:`model.sliding`: :func:`sample_line` samples F(z; kH) along a horizontal or vertical line until every
segment between neighbouring samples passes the acceptance tests, :func:`count_rectangle` sums the log-increments
of F around a rectangle (the winding number, without keeping the samples), and :func:`newton_cell` polishes the
root of a cell with the model's one Newton loop.
"""

from __future__ import annotations

import cmath
import math

import numpy as np

from ._common import jitted
from .newton import FULL_TOL, KH, newton_root
from .records import Box, Params
from .response import dispersion_eval

PHASE_MAX = math.pi / 3  # largest accepted |arg(F_b / F_a)| between neighbouring samples
LOGMOD_MAX = math.log(4.0)  # largest accepted |ln|F_b / F_a||
TRAP_TOL = 0.3  # largest accepted |Log(F_b/F_a) - trapezoid of F'/F|
LIN_TOL = 0.7  # largest accepted relative error of the linear (F') prediction across a segment
H0 = 0.1  # initial sample spacing along lines
LADDER = 3.0  # ratio of the graded initial nodes around real-axis poles
GRADE = 3.0  # ratio of the initial nodes of a vertical line graded towards the real axis
TINY = 1e-13  # |F| / scale below which a sample is taken to be a root on the line
CAP = 1 << 23  # most samples on one line (its seeds included: a line needing more is refused, status 2)
NEWTON_ITERS = 60  # Newton evaluations allowed in a cell (generous: a start at the cell's centre may converge slowly)
SHRINK_CELL = 0.9  # Newton in a cell fails once a step is not below 0.9 x the previous one (slow but converging
# steps are allowed: the start is an estimate, and the confinement to the cell guards against wandering)
WINDING_TOL = 1e-6  # largest distance of a winding number from an integer (it is one up to rounding by construction)
IM_POSITIVE = 5e-324  # smallest positive double: "Im z < IM_POSITIVE" is "Im z <= 0" (a root must stay above the axis)


@jitted
def _seg_ok(za, fa, dfa, zb, fb, dfb, tol_phase, tol_trap, tol_lin):
    """Accept the segment [za, zb] (criteria in the module docstring) and return Log(F_b / F_a)."""
    lg = cmath.log(fb / fa)
    if abs(lg.imag) > tol_phase or abs(lg.real) > LOGMOD_MAX:
        return False, lg
    h = zb - za
    trap = 0.5 * h * (dfa / fa + dfb / fb)
    if abs(trap - lg) > tol_trap:
        return False, lg
    big = max(abs(fa), abs(fb))
    if abs(fa + h * dfa - fb) > tol_lin * big or abs(fb - h * dfb - fa) > tol_lin * big:
        return False, lg
    return True, lg


@jitted
def line_point(t: float, c: float, horizontal: bool) -> complex:
    return complex(t, c) if horizontal else complex(c, t)


@jitted
def _seeds(t0, t1, h0, geo0, lad_y, poles, half):
    """Initial nodes on [t0, t1]: spacing <= h0; plus geo0 3^k (k >= 0) if geo0 > 0 (grading towards the
    real axis along a vertical line); plus p +- lad_y 3^k around each pole p with ladder half-width
    half > 2 lad_y if lad_y > 0 (a horizontal line at height lad_y). Sorted, unique, both ends included."""
    n = max(2, int(math.ceil((t1 - t0) / h0)))
    extra = 0
    kmax = 0
    if geo0 > 0.0 and geo0 < h0:
        kmax = int(math.ceil(math.log(h0 / geo0) / math.log(GRADE)))
        extra += kmax + 1
    lmax = 0
    if lad_y > 0.0 and lad_y < h0:
        lmax = int(math.ceil(math.log(h0 / lad_y) / math.log(LADDER)))
        for j in range(poles.shape[0]):
            if half[j] > lad_y and poles[j] > t0 - half[j] and poles[j] < t1 + half[j]:
                extra += 2 * lmax + 3
    buf = np.empty(n + 1 + extra)
    m = 0
    for k in range(n + 1):
        buf[m] = t0 + (t1 - t0) * k / n
        m += 1
    buf[n] = t1
    if geo0 > 0.0 and geo0 < h0:
        for k in range(kmax + 1):
            buf[m] = geo0 * GRADE**k
            m += 1
    if lad_y > 0.0 and lad_y < h0:
        for j in range(poles.shape[0]):
            p = poles[j]
            if half[j] > lad_y and p > t0 - half[j] and p < t1 + half[j]:
                buf[m] = p
                m += 1
                for k in range(lmax + 1):
                    o = lad_y * LADDER**k
                    if o < half[j]:
                        buf[m] = p + o
                        buf[m + 1] = p - o
                        m += 2
    u = np.unique(buf[:m])
    lo = np.searchsorted(u, t0)
    hi = np.searchsorted(u, t1, side="right")
    return u[lo:hi]


@jitted(inline="always")
def _sample_at(t: float, c: float, horizontal: bool, q: float, gamma: float, f: float, beta: float, eta: float,
               delta: float, xi: float) -> tuple[complex, complex, int]:
    """F and F' at the point t of a line (see sample_line) and a status: 0, 1 (a root: |F| <= TINY x scale) or 3 (F
    or F' not finite)."""
    fv, dfv, sc = dispersion_eval(line_point(t, c, horizontal), q, gamma, f, beta, eta, delta, xi)
    if not (cmath.isfinite(fv) and cmath.isfinite(dfv)):
        return fv, dfv, 3
    if abs(fv) <= TINY * sc:
        return fv, dfv, 1
    return fv, dfv, 0


@jitted
def _doubled(a: np.ndarray, n: int, size: int) -> np.ndarray:
    """A buffer of `size` elements of a's dtype holding a[:n] (a full buffer of sample_line grown)."""
    new = np.empty(size, dtype=a.dtype)
    new[:n] = a[:n]
    return new


@jitted
def sample_line(t0, t1, c, horizontal, h0, geo0, lad_y, poles, half, q, gamma, f, beta, eta, delta, xi, h_min,
                 tol_phase, tol_trap, tol_lin):
    """Adaptively sample F along the line z = t + i c (horizontal) or z = c + i t (vertical), t0 <= t <= t1.

    The initial nodes are :func:`_seeds`. Returns (t, F, L, status, t_bad, evaluations): nodes t (sorted),
    F at the nodes, L[j] = Log(F[j+1]/F[j]) of the accepted segments; status 0 = ok, 1 = a root on (or
    within h_min of) the line near t_bad, 2 = too many samples, 3 = F not finite at t_bad.
    """
    ts = _seeds(t0, t1, h0, geo0, lad_y, poles, half)
    n0 = ts.shape[0]
    if n0 > CAP:  # the graded seeds alone exceed the cap: refused before any evaluation
        return ts[:0], np.empty(0, dtype=np.complex128), np.empty(0, dtype=np.complex128), 2, t0, 0
    st_t = np.empty(n0 + 4096)
    st_f = np.empty(n0 + 4096, dtype=np.complex128)
    st_d = np.empty(n0 + 4096, dtype=np.complex128)
    out_t = np.empty(2 * n0 + 64)  # (grown by doubling as needed)
    out_f = np.empty(2 * n0 + 64, dtype=np.complex128)
    out_l = np.empty(2 * n0 + 64, dtype=np.complex128)
    nev = 0
    # evaluate the initial points and push them (right to left) on the stack
    sp = 0
    for k in range(n0 - 1, -1, -1):
        fv, dfv, status = _sample_at(ts[k], c, horizontal, q, gamma, f, beta, eta, delta, xi)
        nev += 1
        if status != 0:
            return out_t[:0], out_f[:0], out_l[:0], status, ts[k], nev
        st_t[sp] = ts[k]
        st_f[sp] = fv
        st_d[sp] = dfv
        sp += 1
    # the current node is the leftmost one (ts[0])
    sp -= 1
    ta = st_t[sp]
    fa = st_f[sp]
    da = st_d[sp]
    za = line_point(ta, c, horizontal)
    n = 1
    out_t[0] = ta
    out_f[0] = fa
    while sp > 0:
        tb = st_t[sp - 1]
        fb = st_f[sp - 1]
        db = st_d[sp - 1]
        zb = line_point(tb, c, horizontal)
        ok, lg = _seg_ok(za, fa, da, zb, fb, db, tol_phase, tol_trap, tol_lin)
        if ok:
            if n >= out_t.shape[0]:
                if n >= CAP:
                    return out_t[:n], out_f[:n], out_l[: n - 1], 2, ta, nev
                out_t = _doubled(out_t, n, 2 * n)
                out_f = _doubled(out_f, n, 2 * n)
                out_l = _doubled(out_l, n - 1, 2 * n)
            out_t[n] = tb
            out_f[n] = fb
            out_l[n - 1] = lg
            n += 1
            sp -= 1
            ta, fa, da, za = tb, fb, db, zb
            continue
        if tb - ta <= h_min:
            return out_t[:n], out_f[:n], out_l[: n - 1], 1, 0.5 * (ta + tb), nev
        tm = 0.5 * (ta + tb)
        fm, dfm, status = _sample_at(tm, c, horizontal, q, gamma, f, beta, eta, delta, xi)
        nev += 1
        if status != 0:
            return out_t[:n], out_f[:n], out_l[: n - 1], status, tm, nev
        if sp >= st_t.shape[0]:
            st_t = _doubled(st_t, sp, 2 * sp)
            st_f = _doubled(st_f, sp, 2 * sp)
            st_d = _doubled(st_d, sp, 2 * sp)
        st_t[sp] = tm
        st_f[sp] = fm
        st_d[sp] = dfm
        sp += 1
    return out_t[:n], out_f[:n], out_l[: n - 1], 0, ta, nev


@jitted
def newton_cell(z0: complex, x0: float, x1: float, y0: float, y1: float, mult: float, q: float, gamma: float,
                f: float, beta: float, eta: float, delta: float, xi: float) -> tuple[complex, bool, float, int]:
    """The root of F(z; kH = q) in the cell [x0, x1] x [y0, y1] by the model's one Newton loop (newton_root, thin
    wrapper): the step multiplied by `mult` for a multiple root; the iterates confined to the cell enlarged by
    its own size on every side and to Im z > 0; steps allowed to shrink slowly (SHRINK_CELL: the start is a
    contour-integral estimate or the cell's centre, not a certified predictor).

    Returns (z, converged, |F|/scale at z (one more evaluation), evaluations).
    """
    w = max(x1 - x0, y1 - y0)
    box = Box(x0 - w, x1 + w, max(y0 - w, IM_POSITIVE), y1 + w)
    p = Params(gamma, f, beta, eta, delta, xi)
    r = newton_root(z0, KH, 0.0, q, p, NEWTON_ITERS, FULL_TOL, 0.0, SHRINK_CELL, mult, box)
    if not r.ok:
        return r.z, False, math.inf, r.evals
    fv, _, sc = dispersion_eval(r.z, q, gamma, f, beta, eta, delta, xi)
    return r.z, True, abs(fv) / sc, r.evals + 1


@jitted
def count_rectangle(x0: float, x1: float, y0: float, y1: float, h0: float, poles: np.ndarray, half: np.ndarray,
                    q: float, gamma: float, f: float, beta: float, eta: float, delta: float, xi: float,
                    h_bottom: float, h_side: float, h_top: float, tol_phase: float, tol_trap: float,
                    tol_lin: float) -> tuple[int, int, int, float, int, complex, complex]:
    """The number of roots of F(z; kH = q) in [x0, x1] x [y0, y1] (0 < y0 < y1) by the argument principle.

    The four edges are sampled by :func:`sample_line` (bottom, right, top, left; the smallest segments h_bottom,
    h_side, h_top) and the log-increments of their accepted segments summed counterclockwise; the samples are not
    kept (:class:`model._roots.contour.Problem` keeps them where roots are to be located). Returns (status, count, edge,
    t_bad, evaluations, s1, s2): status 0 = counted, 1 = a root on (or within the smallest segment of) edge `edge`
    near its coordinate t_bad, 2 = too many samples on a line, 3 = F not finite, 4 = the winding number is not
    within WINDING_TOL of an integer; s1, s2: estimates of the sum of the roots and of their squares, (1/2 pi i)
    times the closed integrals of z^k dlog F by the midpoint rule on the accepted segments (starts for Newton: the
    segments are coarse; a count certifies what Newton finds from them).
    """
    nev = 0
    total = 0j
    m1 = 0j
    m2 = 0j
    for edge in range(4):
        horizontal = edge % 2 == 0
        c = y0 if edge == 0 else (x1 if edge == 1 else (y1 if edge == 2 else x0))
        t0 = x0 if horizontal else y0
        t1 = x1 if horizontal else y1
        geo0 = 0.0 if horizontal else y0
        lad_y = c if horizontal else 0.0
        h_min = h_bottom if edge == 0 else (h_top if edge == 2 else h_side)
        ts, _, lg, st, tb, ne = sample_line(t0, t1, c, horizontal, h0, geo0, lad_y, poles, half, q, gamma, f, beta,
                                             eta, delta, xi, h_min, tol_phase, tol_trap, tol_lin)
        nev += ne
        if st != 0:
            return st, 0, edge, tb, nev, 0j, 0j
        sg = 1.0 if edge < 2 else -1.0
        for k in range(lg.shape[0]):
            tm = 0.5 * (ts[k] + ts[k + 1])
            zm = line_point(tm, c, horizontal)
            total += sg * lg[k]
            m1 += sg * zm * lg[k]
            m2 += sg * zm * zm * lg[k]
    w = total.imag / (2.0 * math.pi)
    n = round(w)
    if abs(w - n) > WINDING_TOL:
        return 4, 0, -1, w, nev, 0j, 0j
    return 0, int(n), -1, 0.0, nev, m1 / (2j * math.pi), m2 / (2j * math.pi)
