"""The temporal growth rate at the ends of the kH axis: sigma = kH Im z as kH -> infinity (docs/physics.md §14.14).

A mode grows like exp(sigma t), sigma = k Im c = kH Im z in units of c_s/H. As kH -> infinity the roots that keep a
finite sigma sit just above the real axis, z = x + i s/kH with s -> sigma, at |x| > 1 where the square roots
alpha_j(x) of Eq. Gs_general are imaginary, so that the upper block's tanh(kH alpha_j) does not tend to 1: with
alpha_j(x) = -i sgn(x) |alpha_j| and kH alpha_j(x + i s/kH) = kH alpha_j(x) + s |x| beta_j^2 / |alpha_j| + O(1/kH),

    T1_j -> tanh(s |x| beta_j^2 / |alpha_j| + i phi_j),   phi_j = -sgn(x) kH |alpha_j(x)|  (mod pi),

(beta_j = 1 for the shear wave, beta for the dilatational one), while the half-space below gives T2_j = 1 (eta = inf),
the friction law's memory term vanishes (S -> 1 for xi > 0, S = Delta for xi = 0) and every other z is x. The phases
phi_j wind round as kH grows, incommensurately, so the roots' s at large kH runs over the values of the *reduced
equation* R(x, s; phi_s, phi_d) = 0 (two real unknowns, one complex equation, Eq. implicit_spectrum with those T1,
T2 and S) over the torus of phases: the supremum of sigma as kH -> infinity is the largest s of its roots over all
phases (supersonic, |x| > 1/beta: both phases; intersonic, 1 < |x| < 1/beta: T1_d -> 1, one phase). Subsonic roots
(|x| < 1) have T1_j -> 1: F tends to the identical half-spaces' F_inf, which has no growing root (§14.5), so none
keeps a finite sigma. :func:`growth_rate_limit` solves the reduced equation on a grid of phases and x, follows the
best root to the phases where its s is largest, and reports that limit and where it is approached; the contour
solver's certified roots at kH = 1e3 ... 1e5 approach it (tests/model/test_growth_limits.py).
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from ._kernels.records import Params
from ._kernels.window import exclusion_radius
from ._validate import check

__all__ = ["LIMIT_STATUS", "GrowthRateLimit", "growth_rate_limit"]

X_GRID = 256  # the corner scan: values of |x| per family range ...
S_GRID = 160  # ... and of s (geometric from S_MIN to the largest s a root can have)
S_MIN = 1e-7
S_TOP = 1e3  # the corner scan's largest s (kH Im z in c_s/H; the maximization itself is unbounded)
NEWTON_STEPS = 40
HALVINGS = 12  # step halvings allowed per Newton step
PHASES = 24  # the intersonic family's grid of phi_s over [0, pi) ...
X_SEEDS = 8  # ... and its starts in |x| per sign
BISECTIONS = 60
STARTS_X = (0.15, 0.5, 0.85)  # interior starts of the constrained maximization: fractions of the family range (log)
STARTS_PHASE = (0.25 * math.pi, 0.75 * math.pi)
RESID_TOL = 1e-10  # |R| / (the size of its terms) at an accepted root
WINDOW_K = 1e8  # the window of the roots with kH Im z >= c is computed at this kH (it depends on kH Im z only)
SIGMA_WINDOW = 1e-6
EDGE = 1e-9  # |x| kept this far (relative) from the branch points (the expansion fails there)

L_OK, L_NONE, L_FINITE_ETA = 0, 1, 2
#: status of a limit (GrowthRateLimit.status)
LIMIT_STATUS = {
    L_OK: "the supremum of sigma as kH -> infinity: the largest s of the reduced equation's roots over the phases",
    L_NONE: "no root of the reduced equation with s > 0: sigma -> 0 as kH -> infinity",
    L_FINITE_ETA: "not computed: the kH -> infinity limit at finite eta (the lower block's phases too) is not yet in "
    "the model",
}


@dataclass(frozen=True)
class GrowthRateLimit:
    """The limit of the temporal growth rate as kH -> infinity (:func:`growth_rate_limit`), broadcast.

    Attributes
    ----------
    sigma : the supremum of kH Im z (c_s/H) approached as kH -> infinity (0.0 where none grows; NaN unless status
        is 0 or 1)
    x : Re z of the root that approaches it (NaN unless status 0)
    family : 2 intersonic (1 < |x| < 1/beta), 3 supersonic (|x| > 1/beta), -1 none (as model.FAMILIES)
    phases : (phi_s, phi_d) where it is largest (phi_d NaN for an intersonic root)
    status : int8, a key of :data:`LIMIT_STATUS`
    """

    sigma: np.ndarray
    x: np.ndarray
    family: np.ndarray
    phases: np.ndarray
    status: np.ndarray


class _Scalars:
    """The functions :func:`_reduced` needs, on Python scalars (cmath/math: ~10x faster than NumPy on one value)."""

    sign = staticmethod(lambda v: math.copysign(1.0, v))
    abs = staticmethod(abs)
    sqrt = staticmethod(math.sqrt)
    tanh = staticmethod(cmath.tanh)
    ones_like = staticmethod(lambda v: 1.0 + 0j)


def _reduced(x, s, ph_s, ph_d, par: tuple, supersonic: bool, xp=np):
    """R(x, s; phases) and the size of its terms (module docstring), elementwise (xp = np on arrays, _Scalars on
    floats)."""
    gamma, f, beta, fric = par
    sg = xp.sign(x)
    ax = xp.abs(x)
    ms = xp.sqrt(ax * ax - 1.0)
    a_s = -1j * sg * ms
    t_s = xp.tanh(s * ax / ms + 1j * ph_s)
    if supersonic:
        md = xp.sqrt(beta * beta * ax * ax - 1.0)
        a_d = -1j * sg * md
        t_d = xp.tanh(s * beta * beta * ax / md + 1j * ph_d)
    else:
        a_d = xp.sqrt(1.0 - beta * beta * ax * ax) + 0j
        t_d = xp.ones_like(a_s)
    w = (1.0 + a_s * a_s) ** 2 / (a_s * (t_s + 1.0))
    v = 4.0 * a_d / (t_d + 1.0)
    gx = (w - v) / (x * x)
    gy = 2.0 * (1.0 + a_s * a_s) / (x * x) * (1.0 / (t_d + 1.0) - 1.0 / (t_s + 1.0))
    r = gamma * (gx + 1j * f * gy) + 1j * x * fric
    scale = gamma * (xp.abs(w) + xp.abs(v)) / (x * x) + gamma * abs(f) * xp.abs(gy) + xp.abs(x * fric)
    return r, scale


def _newton(x: np.ndarray, s: np.ndarray, ph_s: np.ndarray, ph_d: np.ndarray, par: tuple, supersonic: bool,
            lo: float, hi: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Newton on the two real unknowns (x, s) at fixed phases from every start at once (Jacobian by central
    differences), each step halved until |R| decreases with |x| inside (lo, hi); (x, s, converged)."""
    sg = np.sign(x)
    with np.errstate(all="ignore"):
        r, scale = _reduced(x, s, ph_s, ph_d, par, supersonic)
        for _ in range(NEWTON_STEPS):
            hx = 1e-7 * np.abs(x)
            hs = 1e-7 * np.maximum(np.abs(s), 1e-3)
            rx = (_reduced(x + hx, s, ph_s, ph_d, par, supersonic)[0]
                  - _reduced(x - hx, s, ph_s, ph_d, par, supersonic)[0]) / (2.0 * hx)
            rs = (_reduced(x, s + hs, ph_s, ph_d, par, supersonic)[0]
                  - _reduced(x, s - hs, ph_s, ph_d, par, supersonic)[0]) / (2.0 * hs)
            det = rx.real * rs.imag - rs.real * rx.imag
            dx = np.nan_to_num(-(rs.imag * r.real - rs.real * r.imag) / det)
            ds = np.nan_to_num(-(-rx.imag * r.real + rx.real * r.imag) / det)
            t = np.ones_like(x)
            done = np.zeros(x.shape, dtype=bool)
            nx, ns, nr, nsc = x.copy(), s.copy(), r.copy(), scale.copy()
            for _ in range(HALVINGS):
                cx, cs = x + t * dx, s + t * ds
                inside = (np.abs(cx) > lo * (1.0 + EDGE)) & (np.abs(cx) < hi) & (np.sign(cx) == sg)
                cr, csc = _reduced(np.where(inside, cx, x), np.where(inside, cs, s), ph_s, ph_d, par, supersonic)
                better = inside & np.isfinite(cr) & (np.abs(cr) < np.abs(r)) & ~done
                nx, ns = np.where(better, cx, nx), np.where(better, cs, ns)
                nr, nsc = np.where(better, cr, nr), np.where(better, csc, nsc)
                done |= better
                t = np.where(done, t, 0.5 * t)
                if done.all():
                    break
            x, s, r, scale = nx, ns, nr, nsc
    ok = np.isfinite(r) & (np.abs(r) <= RESID_TOL * scale) & (np.abs(x) > lo * (1.0 + EDGE)) & (np.abs(x) < hi)
    return x, s, ok


def _residual(v: np.ndarray, par: tuple, supersonic: bool) -> tuple[float, float]:
    """(Re R, Im R) / scale at v = (x, s, phi_s[, phi_d]): the constraint of the maximization."""
    pd = float(v[3]) if supersonic else 0.0
    try:
        r, sc = _reduced(float(v[0]), float(v[1]), float(v[2]), pd, par, supersonic, _Scalars)
    except (ValueError, ZeroDivisionError, OverflowError):  # outside the family's range (sqrt of a negative)
        return math.inf, math.inf
    return r.real / sc, r.imag / sc


def _corner_best(par: tuple, lo: float, hi: float, s_top: float) -> tuple[float, float, float, float]:
    """Supersonic roots at the four corners of the phase torus, phi_j in {0, pi/2} (T1_j real): R is then purely
    imaginary, so its roots form curves s(x) (Im R = 0), found on an X_GRID x S_GRID grid (the largest sign change in
    s at each x, bisected); the largest s of those curves and where. (s, x, phi_s, phi_d); s = -inf if none."""
    ax = np.geomspace(lo * (1.0 + 1e-6), hi, X_GRID)
    ss = np.geomspace(S_MIN, s_top, S_GRID)
    best = (-math.inf, math.nan, math.nan, math.nan)
    for sg in (1.0, -1.0):
        xg, sgrid = np.meshgrid(sg * ax, ss, indexing="ij")
        for p_s in (0.0, 0.5 * math.pi):
            for p_d in (0.0, 0.5 * math.pi):
                ps = np.full(xg.shape, p_s)
                pd = np.full(xg.shape, p_d)
                with np.errstate(all="ignore"):
                    g = _reduced(xg, sgrid, ps, pd, par, True)[0].imag
                change = np.isfinite(g[:, 1:]) & np.isfinite(g[:, :-1]) & (np.sign(g[:, 1:]) != np.sign(g[:, :-1]))
                rows = np.flatnonzero(change.any(axis=1))
                if rows.size == 0:
                    continue
                last = change.shape[1] - 1 - np.argmax(change[rows, ::-1], axis=1)  # the largest bracket in s
                a, b = ss[last], ss[last + 1]
                x = sg * ax[rows]
                ga = g[rows, last]
                for _ in range(BISECTIONS):
                    m = 0.5 * (a + b)
                    with np.errstate(all="ignore"):
                        gm = _reduced(x, m, np.full(x.shape, p_s), np.full(x.shape, p_d), par, True)[0].imag
                    left = np.sign(gm) == np.sign(ga)
                    a, ga = np.where(left, m, a), np.where(left, gm, ga)
                    b = np.where(left, b, m)
                s_root = 0.5 * (a + b)
                r, sc = _reduced(x, s_root, np.full(x.shape, p_s), np.full(x.shape, p_d), par, True)
                real = np.abs(r) <= 1e-6 * sc  # a sign change of Im R that is a root (not a pole of R)
                if real.any():
                    k = int(np.argmax(np.where(real, s_root, -np.inf)))
                    if s_root[k] > best[0]:
                        best = (float(s_root[k]), float(x[k]), p_s, p_d)
    return best


def _maximize(start: np.ndarray, par: tuple, supersonic: bool, lo: float, hi: float
              ) -> tuple[float, np.ndarray] | None:
    """The largest s on the reduced equation's roots near `start` = (x, s, phi_s[, phi_d]): SLSQP with R = 0 as
    the constraint; (s, the point) or None if it did not end on a root."""
    sg = 1.0 if start[0] > 0 else -1.0
    xb = (lo * (1.0 + EDGE), hi) if sg > 0 else (-hi, -lo * (1.0 + EDGE))
    bounds = [xb, (0.0, None)] + [(None, None)] * (len(start) - 2)
    with np.errstate(all="ignore"):
        res = optimize.minimize(lambda v: -v[1], start, method="SLSQP", bounds=bounds,
                                constraints=[dict(type="eq", fun=lambda v: _residual(v, par, supersonic))],
                                options=dict(ftol=1e-15, maxiter=300))
    v = res.x
    r = _residual(v, par, supersonic)
    if not (math.hypot(*r) <= RESID_TOL and v[1] > 0.0 and lo < abs(v[0]) < hi):
        return None
    return float(v[1]), v


def _family_best(par: tuple, supersonic: bool, lo: float, hi: float, s_top: float
                 ) -> tuple[float, float, float, float]:
    """(s, x, phi_s, phi_d) of the largest s on one family's roots (phi_d NaN for the intersonic family)."""
    cands: list[tuple[float, np.ndarray]] = []
    if supersonic:
        s0, x0, p1, p2 = _corner_best(par, lo, hi, s_top)
        if s0 > 0.0:
            cands.append((s0, np.array([x0, s0, p1, p2])))
    if supersonic:  # interior starts too: a maximum off the corners
        for sg in (1.0, -1.0):
            for fx in STARTS_X:
                got = _maximize(np.array([sg * lo * (hi / lo) ** fx, 0.1, STARTS_PHASE[0], STARTS_PHASE[0]]), par,
                                True, lo, hi)
                if got is not None:
                    cands.append(got)
    else:  # one phase: Newton in (x, s) on a grid of phases and starts, then the best followed
        ph = np.arange(PHASES) * (math.pi / PHASES)
        xs = np.geomspace(lo * (1.0 + 1e-3), hi, X_SEEDS)
        g_p, g_x, g_s = (g.ravel() for g in np.meshgrid(ph, np.concatenate((xs, -xs)), np.array((0.02, 0.2)),
                                                         indexing="ij"))
        x, s, ok = _newton(g_x, g_s, g_p, np.zeros_like(g_p), par, False, lo, hi)
        good = ok & (s > 0.0)
        if good.any():
            k = int(np.argmax(np.where(good, s, -np.inf)))
            cands.append((float(s[k]), np.array([x[k], s[k], g_p[k]])))
    if not cands:
        return -math.inf, math.nan, math.nan, math.nan
    s, v = max(cands, key=lambda c: c[0])
    polished = _maximize(v, par, supersonic, lo, hi)
    if polished is not None and polished[0] >= s:
        s, v = polished
    return s, float(v[0]), float(v[2]) % math.pi, float(v[3]) % math.pi if supersonic else math.nan


def _limit_one(gamma: float, f: float, beta: float, eta: float, delta: float, xi: float
               ) -> tuple[float, float, int, float, float, int]:
    if math.isfinite(eta):
        return math.nan, math.nan, -1, math.nan, math.nan, L_FINITE_ETA
    par = (gamma, f, beta, delta if xi == 0.0 else 1.0)
    p = Params(gamma, f, beta, eta, delta, xi)
    x_max = exclusion_radius(SIGMA_WINDOW / WINDOW_K, WINDOW_K, p)
    s_top = S_TOP
    out = (-math.inf, math.nan, -1, math.nan, math.nan)
    if x_max > 1.0 / beta:
        s, x, p1, p2 = _family_best(par, True, 1.0 / beta, x_max, s_top)
        if s > out[0]:
            out = (s, x, 3, p1, p2)
    s, x, p1, p2 = _family_best(par, False, 1.0, min(1.0 / beta, x_max) * (1.0 - EDGE), s_top)
    if s > out[0]:
        out = (s, x, 2, p1, p2)
    if not out[0] > 0.0:
        return 0.0, math.nan, -1, math.nan, math.nan, L_NONE
    return (*out, L_OK)


def growth_rate_limit(*, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0) -> GrowthRateLimit:
    """The supremum of the temporal growth rate sigma = kH Im z (c_s/H) approached as kH -> infinity.

    Eq. implicit_spectrum (with Eq. Gs_general and Eq. delta f RSF) in the limit kH -> infinity at fixed kH Im z: the
    reduced equation of the module docstring over the torus of the upper block's phases, at eta = inf (docs/physics.md
    §14.14). Found on a grid of PHASES^2 phases and X_SEEDS x 2 starts in |x| per family and sign (|x| up to the
    window of :func:`root_window` for kH Im z >= 1e-6, which does not depend on kH), each by Newton in (x, s); the
    best root is then followed in the phases (Nelder-Mead) to where its s is largest. The grid search is not a
    certificate: a root family that no start reaches is not seen (the tests compare the limit with the contour
    solver's certified roots at large kH). Finite eta: status 2, NaN. Parameters broadcast.
    """
    arrays = np.broadcast_arrays(*(check(n, v) for n, v in (("gamma", gamma), ("f", f), ("beta", beta), ("eta", eta),
                                                             ("Delta", Delta), ("xi", xi))))
    shape = arrays[0].shape
    sigma = np.empty(shape)
    x = np.empty(shape)
    fam = np.empty(shape, dtype=np.int8)
    phases = np.empty((*shape, 2))
    status = np.empty(shape, dtype=np.int8)
    for idx in np.ndindex(shape):
        s, xx, fa, p1, p2, st = _limit_one(*(float(a[idx]) for a in arrays))
        sigma[idx], x[idx], fam[idx], phases[idx], status[idx] = s, xx, fa, (p1, p2), st
    return GrowthRateLimit(sigma, x, fam, phases, status)
