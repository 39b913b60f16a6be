"""The temporal growth rate at the ends of the kH axis: sigma = kH Im z as kH -> infinity (docs/physics.md §14.14).

A mode grows like exp(sigma t), sigma = k Im c = kH Im z in units of c_s/H. As kH -> infinity the roots that keep a
finite sigma sit just above the real axis, z = x + i s/kH with s -> sigma, at |x| > 1 where the square roots
alpha_j(x) of Eq. Gs_general are imaginary, so that the upper block's tanh(kH alpha_j) does not tend to 1: with
alpha_j(x) = -i sgn(x) |alpha_j| and kH alpha_j(x + i s/kH) = kH alpha_j(x) + s |x| beta_j^2 / |alpha_j| + O(1/kH),

    T1_j -> tanh(s |x| beta_j^2 / |alpha_j| + i phi_j),   phi_j = -sgn(x) kH |alpha_j(x)|  (mod pi),

(beta_j = 1 for the shear wave, beta for the dilatational one); the lower block, of height eta H, likewise gives

    T2_j -> tanh(eta s |x| beta_j^2 / |alpha_j| + i psi_j),   psi_j = eta phi_j  (mod pi)

(T2_j = 1 at eta = inf: a half-space); the friction law's memory term vanishes (S -> 1 for xi > 0, S = Delta for
xi = 0) and every other z is x. The phases wind round as kH grows, so the roots' s at large kH runs over the values
of the *reduced equation* R(x, s; phases) = 0 (two real unknowns, one complex equation: Eq. implicit_spectrum with
those T1, T2 and S) over the torus of phases that kH reaches: the limit superior of sigma as kH -> infinity is the
largest s of its roots there. At eta = inf the torus is (phi_s, phi_d) (supersonic, |x| > 1/beta), or phi_s alone
(intersonic, 1 < |x| < 1/beta: T1_d, T2_d -> 1). At finite eta the lower block's phases join it: free (psi_j
independent of phi_j) where eta is not a ratio of small integers, tied where eta = p/q with q <= Q_MAX (phi_j = t_j,
psi_j = eta t_j, t_j in [0, q pi): kH alpha_j reaches only that q-fold winding). Subsonic roots (|x| < 1) have
T1_j, T2_j -> 1: F tends to the identical half-spaces' F_inf, which has no growing root (§14.5), so none keeps a
finite sigma. :func:`growth_rate_limit` solves the reduced equation on a grid of phases and x, follows the best root
to the phases where its s is largest, and reports that limit and where it is approached; the contour solver's
certified roots at kH = 1e3 ... 1e5 approach it at eta = inf, and roots of the full F at finite eta are polished
from it (tests/model/test_growth_limits.py).
"""

from __future__ import annotations

import cmath
import itertools
import math
from dataclasses import dataclass
from fractions import Fraction

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
PHASES = 24  # the Newton starts' grid of one free phase over [0, pi) (eta = inf, intersonic) ...
PHASES_2D = 12  # ... of each of two (finite eta) ...
PHASES_MANY = 3  # ... of each of four (finite eta, supersonic, free phases) ...
PHASE_CAP = 48  # ... and at most this many over a tied phase's period q pi
Q_MAX = 8  # eta = p/q with q at most this ties the lower block's phases to the upper block's
X_SEEDS = 8  # ... and its starts in |x| per sign
BISECTIONS = 60
STARTS_X = (0.15, 0.5, 0.85)  # interior starts of the constrained maximization: fractions of the family range (log)
STARTS_PHASE = (0.25 * math.pi, 0.75 * math.pi)
RESID_TOL = 1e-10  # |R| / (the size of its terms) at an accepted root
WINDOW_K = 1e8  # the window of the roots with kH Im z >= c is computed at this kH (it depends on kH Im z only)
SIGMA_WINDOWS = (1e-2, 1e-6)  # the windows searched: for sigma >= 1e-2 first (finite eta: |x| < ~4/sigma), then wider
EDGE = 1e-9  # |x| kept this far (relative) from the branch points (the expansion fails there)

L_OK, L_NONE, L_WINDOW = 0, 1, 2
#: status of a limit (GrowthRateLimit.status)
LIMIT_STATUS = {
    L_OK: "the supremum of sigma as kH -> infinity: the largest s of the reduced equation's roots over the phases",
    L_NONE: "no root of the reduced equation with s > 1e-6: sigma -> 0 as kH -> infinity (to that level)",
    L_WINDOW: "refused: no finite window holds the reduced equation's roots with s >= 1e-6 (the bound of "
    "model.root_window diverges)",
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
    phases : (phi_s, phi_d, psi_s, psi_d) mod pi where it is largest: the upper block's, then the lower block's
        (0 where a phase does not enter: psi at eta = inf, the dilatational ones of an intersonic root; NaN: none)
    tied : q where eta = p/q with q <= Q_MAX (the lower block's phases tied to the upper block's: psi_j = eta t_j,
        phi_j = t_j mod pi), else 0 (free)
    status : int8, a key of :data:`LIMIT_STATUS`
    """

    sigma: np.ndarray
    x: np.ndarray
    family: np.ndarray
    phases: np.ndarray
    tied: np.ndarray
    status: np.ndarray


class _Scalars:
    """The functions :func:`_reduced` needs, on Python scalars (cmath/math: ~10x faster than NumPy on one value)."""

    sign = staticmethod(lambda v: math.copysign(1.0, v))
    abs = staticmethod(abs)
    sqrt = staticmethod(math.sqrt)
    tanh = staticmethod(cmath.tanh)
    ones_like = staticmethod(lambda v: 1.0 + 0j)


@dataclass(frozen=True)
class _Torus:
    """The free phases t of one family and how they give the four phases (phi_s, phi_d, psi_s, psi_d) of
    :func:`_reduced` (module docstring): at eta = inf the upper block's only; at finite eta the lower block's too,
    free (eta not a ratio of small integers) or tied, psi_j = eta t_j with t_j in [0, q pi) (eta = p/q)."""

    supersonic: bool
    eta: float
    q: int  # eta = p/q with q <= Q_MAX: the phases are tied; 0: free (or eta = inf)

    @property
    def waves(self) -> int:
        return 2 if self.supersonic else 1

    @property
    def n(self) -> int:
        """The number of free phases."""
        return self.waves * (2 if math.isfinite(self.eta) and self.q == 0 else 1)

    @property
    def period(self) -> float:
        return math.pi * (self.q if self.q else 1)

    def phases(self, t: tuple) -> tuple:
        """(phi_s, phi_d, psi_s, psi_d) from the free phases t (zeros where a phase does not enter)."""
        zero = 0.0 * t[0]
        phi_s = t[0]
        phi_d = t[1] if self.supersonic else zero
        if math.isinf(self.eta):
            return phi_s, phi_d, zero, zero
        if self.q:
            return phi_s, phi_d, self.eta * phi_s, self.eta * phi_d
        w = self.waves
        return phi_s, phi_d, t[w], t[w + 1] if self.supersonic else zero


def _commensurate(eta: float) -> int:
    """q where eta = p/q to a relative 1e-12 with q <= Q_MAX (the lower block's phases are then tied to the upper
    block's), else 0."""
    if math.isinf(eta):
        return 0
    fr = Fraction(eta).limit_denominator(Q_MAX)
    return fr.denominator if abs(float(fr) - eta) <= 1e-12 * eta else 0


def _reduced(x, s, ph: tuple, par: tuple, torus: _Torus, xp=np):
    """R(x, s; phases) and the size of its terms (module docstring), elementwise (xp = np on arrays, _Scalars on
    floats); ph = (phi_s, phi_d, psi_s, psi_d) (:meth:`_Torus.phases`)."""
    gamma, f, beta, fric = par
    eta = torus.eta
    sg = xp.sign(x)
    ax = xp.abs(x)
    ms = xp.sqrt(ax * ax - 1.0)
    a_s = -1j * sg * ms
    t_s = xp.tanh(s * ax / ms + 1j * ph[0])
    u_s = xp.ones_like(a_s) if math.isinf(eta) else xp.tanh(eta * s * ax / ms + 1j * ph[2])
    if torus.supersonic:
        md = xp.sqrt(beta * beta * ax * ax - 1.0)
        a_d = -1j * sg * md
        t_d = xp.tanh(s * beta * beta * ax / md + 1j * ph[1])
        u_d = xp.ones_like(a_s) if math.isinf(eta) else xp.tanh(eta * s * beta * beta * ax / md + 1j * ph[3])
    else:
        a_d = xp.sqrt(1.0 - beta * beta * ax * ax) + 0j
        t_d = xp.ones_like(a_s)
        u_d = xp.ones_like(a_s)
    w = (1.0 + a_s * a_s) ** 2 / (a_s * (t_s + u_s))
    v = 4.0 * a_d / (t_d + u_d)
    gx = (w - v) / (x * x)
    gy = 2.0 * (1.0 + a_s * a_s) / (x * x) * (u_d / (t_d + u_d) - u_s / (t_s + u_s))
    r = gamma * (gx + 1j * f * gy) + 1j * x * fric
    scale = gamma * (xp.abs(w) + xp.abs(v)) / (x * x) + gamma * abs(f) * xp.abs(gy) + xp.abs(x * fric)
    return r, scale


def _newton(x: np.ndarray, s: np.ndarray, t: tuple, par: tuple, torus: _Torus, lo: float, hi: float
            ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Newton on the two real unknowns (x, s) at fixed phases t from every start at once (Jacobian by central
    differences), each step halved until |R| decreases with |x| inside (lo, hi); (x, s, converged)."""
    sg = np.sign(x)
    ph = torus.phases(t)
    with np.errstate(all="ignore"):
        r, scale = _reduced(x, s, ph, par, torus)
        for _ in range(NEWTON_STEPS):
            hx = 1e-7 * np.abs(x)
            hs = 1e-7 * np.maximum(np.abs(s), 1e-3)
            rx = (_reduced(x + hx, s, ph, par, torus)[0] - _reduced(x - hx, s, ph, par, torus)[0]) / (2.0 * hx)
            rs = (_reduced(x, s + hs, ph, par, torus)[0] - _reduced(x, s - hs, ph, par, torus)[0]) / (2.0 * hs)
            det = rx.real * rs.imag - rs.real * rx.imag
            dx = np.nan_to_num(-(rs.imag * r.real - rs.real * r.imag) / det)
            ds = np.nan_to_num(-(-rx.imag * r.real + rx.real * r.imag) / det)
            step = np.ones_like(x)
            done = np.zeros(x.shape, dtype=bool)
            nx, ns, nr, nsc = x.copy(), s.copy(), r.copy(), scale.copy()
            for _ in range(HALVINGS):
                cx, cs = x + step * dx, s + step * ds
                inside = (np.abs(cx) > lo * (1.0 + EDGE)) & (np.abs(cx) < hi) & (np.sign(cx) == sg)
                cr, csc = _reduced(np.where(inside, cx, x), np.where(inside, cs, s), ph, par, torus)
                better = inside & np.isfinite(cr) & (np.abs(cr) < np.abs(r)) & ~done
                nx, ns = np.where(better, cx, nx), np.where(better, cs, ns)
                nr, nsc = np.where(better, cr, nr), np.where(better, csc, nsc)
                done |= better
                step = np.where(done, step, 0.5 * step)
                if done.all():
                    break
            x, s, r, scale = nx, ns, nr, nsc
    ok = np.isfinite(r) & (np.abs(r) <= RESID_TOL * scale) & (np.abs(x) > lo * (1.0 + EDGE)) & (np.abs(x) < hi)
    return x, s, ok


def _residual(v: np.ndarray, par: tuple, torus: _Torus) -> tuple[float, float]:
    """(Re R, Im R) / scale at v = (x, s, *t): the constraint of the maximization."""
    ph = torus.phases(tuple(float(a) for a in v[2:]))
    try:
        r, sc = _reduced(float(v[0]), float(v[1]), ph, par, torus, _Scalars)
    except (ValueError, ZeroDivisionError, OverflowError):  # outside the family's range (sqrt of a negative)
        return math.inf, math.inf
    return r.real / sc, r.imag / sc


def _corner_best(par: tuple, torus: _Torus, lo: float, hi: float, s_top: float) -> tuple[float, np.ndarray]:
    """Supersonic roots at the corners of the phase torus, every t_j in {0, period/2} (every tanh real): R is then
    purely imaginary, so its roots form curves s(x) (Im R = 0), found on an X_GRID x S_GRID grid (the largest sign
    change in s at each x, bisected); the largest s of those curves and where: (s, (x, s, *t)); s = -inf if none."""
    ax = np.geomspace(lo * (1.0 + 1e-6), hi, X_GRID)
    ss = np.geomspace(S_MIN, s_top, S_GRID)
    best: tuple[float, np.ndarray] = (-math.inf, np.array([]))
    for sg in (1.0, -1.0):
        xg, sgrid = np.meshgrid(sg * ax, ss, indexing="ij")
        for corner in itertools.product((0.0, 0.5 * torus.period), repeat=torus.n):
            ph = torus.phases(tuple(np.full(xg.shape, c) for c in corner))
            with np.errstate(all="ignore"):
                g = _reduced(xg, sgrid, ph, par, torus)[0].imag
            change = np.isfinite(g[:, 1:]) & np.isfinite(g[:, :-1]) & (np.sign(g[:, 1:]) != np.sign(g[:, :-1]))
            rows = np.flatnonzero(change.any(axis=1))
            if rows.size == 0:
                continue
            last = change.shape[1] - 1 - np.argmax(change[rows, ::-1], axis=1)  # the largest bracket in s
            a, b = ss[last], ss[last + 1]
            x = sg * ax[rows]
            ph = torus.phases(tuple(np.full(x.shape, c) for c in corner))
            ga = g[rows, last]
            for _ in range(BISECTIONS):
                m = 0.5 * (a + b)
                with np.errstate(all="ignore"):
                    gm = _reduced(x, m, ph, par, torus)[0].imag
                left = np.sign(gm) == np.sign(ga)
                a, ga = np.where(left, m, a), np.where(left, gm, ga)
                b = np.where(left, b, m)
            s_root = 0.5 * (a + b)
            r, sc = _reduced(x, s_root, ph, par, torus)
            real = np.abs(r) <= 1e-6 * sc  # a sign change of Im R that is a root (not a pole of R)
            if real.any():
                k = int(np.argmax(np.where(real, s_root, -np.inf)))
                if s_root[k] > best[0]:
                    best = (float(s_root[k]), np.array([x[k], s_root[k], *corner]))
    return best


def _maximize(start: np.ndarray, par: tuple, torus: _Torus, lo: float, hi: float
              ) -> tuple[float, np.ndarray] | None:
    """The largest s on the reduced equation's roots near `start` = (x, s, *t): SLSQP with R = 0 as the
    constraint; (s, the point) or None if it did not end on a root."""
    sg = 1.0 if start[0] > 0 else -1.0
    xb = (lo * (1.0 + EDGE), hi) if sg > 0 else (-hi, -lo * (1.0 + EDGE))
    bounds = [xb, (0.0, None)] + [(None, None)] * (len(start) - 2)
    with np.errstate(all="ignore"):
        res = optimize.minimize(lambda v: -v[1], start, method="SLSQP", bounds=bounds,
                                constraints=[dict(type="eq", fun=lambda v: _residual(v, par, torus))],
                                options=dict(ftol=1e-15, maxiter=300))
    v = res.x
    r = _residual(v, par, torus)
    if not (math.hypot(*r) <= RESID_TOL and v[1] > 0.0 and lo < abs(v[0]) < hi):
        return None
    return float(v[1]), v


def _phase_grid(torus: _Torus) -> list[np.ndarray]:
    """The grid of free phases the Newton starts sit on, each over its period: PHASES values of one free phase,
    PHASES_2D of each of two, PHASES_MANY of each of four; a tied phase's period q pi holds q times as many, at most
    PHASE_CAP."""
    per = PHASES if torus.n == 1 else (PHASES_2D if torus.n == 2 else PHASES_MANY)
    count = min(per * (torus.q or 1), PHASE_CAP)
    return [np.arange(count) * (torus.period / count)] * torus.n


def _newton_best(par: tuple, torus: _Torus, lo: float, hi: float) -> tuple[float, np.ndarray] | None:
    """Newton in (x, s) from a grid of phases and starts; the root of largest s, or None."""
    xs = np.geomspace(lo * (1.0 + 1e-3), hi, X_SEEDS)
    grids = np.meshgrid(*_phase_grid(torus), np.concatenate((xs, -xs)), np.array((0.02, 0.2)), indexing="ij")
    flat = [g.ravel() for g in grids]
    t, g_x, g_s = tuple(flat[:-2]), flat[-2], flat[-1]
    x, s, ok = _newton(g_x, g_s, t, par, torus, lo, hi)
    good = ok & (s > 0.0)
    if not good.any():
        return None
    k = int(np.argmax(np.where(good, s, -np.inf)))
    return float(s[k]), np.array([x[k], s[k], *(a[k] for a in t)])


def _family_best(par: tuple, torus: _Torus, lo: float, hi: float, s_top: float) -> tuple[float, float, tuple]:
    """(s, x, free phases t mod their period) of the largest s on one family's roots."""
    cands: list[tuple[float, np.ndarray]] = []
    if torus.supersonic:
        got = _corner_best(par, torus, lo, hi, s_top)
        if got[0] > 0.0:
            cands.append(got)
        for sg in (1.0, -1.0):  # interior starts too: a maximum off the corners
            for fx in STARTS_X:
                start = [sg * lo * (hi / lo) ** fx, 0.1] + [STARTS_PHASE[0] * torus.period / math.pi] * torus.n
                got = _maximize(np.array(start), par, torus, lo, hi)
                if got is not None:
                    cands.append(got)
    if not torus.supersonic or math.isfinite(torus.eta):  # Newton on a grid of phases and starts
        got = _newton_best(par, torus, lo, hi)
        if got is not None:
            cands.append(got)
    if not cands:
        return -math.inf, math.nan, ()
    s, v = max(cands, key=lambda c: c[0])
    polished = _maximize(v, par, torus, lo, hi)
    if polished is not None and polished[0] >= s:
        s, v = polished
    return s, float(v[0]), tuple(float(a) % torus.period for a in v[2:])


def _limit_one(gamma: float, f: float, beta: float, eta: float, delta: float, xi: float
               ) -> tuple[float, float, int, tuple, int, int]:
    """(sigma, x, family, free phases, q, status) of one parameter set: the families searched in the window of the
    roots with s >= SIGMA_WINDOWS[0], then (if none is that high) in the wider one."""
    par = (gamma, f, beta, delta if xi == 0.0 else 1.0)
    p = Params(gamma, f, beta, eta, delta, xi)
    q = _commensurate(eta)
    out: tuple[float, float, int, tuple] = (-math.inf, math.nan, -1, ())
    for level in SIGMA_WINDOWS:
        x_max = exclusion_radius(level / WINDOW_K, WINDOW_K, p)
        if not math.isfinite(x_max):
            return math.nan, math.nan, -1, (), q, L_WINDOW
        if x_max > 1.0 / beta:
            s, x, t = _family_best(par, _Torus(True, eta, q), 1.0 / beta, x_max, S_TOP)
            if s > out[0]:
                out = (s, x, 3, t)
        s, x, t = _family_best(par, _Torus(False, eta, q), 1.0, min(1.0 / beta, x_max) * (1.0 - EDGE), S_TOP)
        if s > out[0]:
            out = (s, x, 2, t)
        if out[0] >= level:
            break
    if not out[0] > 0.0:
        return 0.0, math.nan, -1, (), q, L_NONE
    return (*out, q, L_OK)


def growth_rate_limit(*, gamma, f, beta, eta=math.inf, Delta=1.0, xi=0.0) -> GrowthRateLimit:
    """The supremum of the temporal growth rate sigma = kH Im z (c_s/H) approached as kH -> infinity.

    Eq. implicit_spectrum (with Eq. Gs_general and Eq. delta f RSF) in the limit kH -> infinity at fixed kH Im z: the
    reduced equation of the module docstring over the torus of the blocks' phases (the upper block's at eta = inf;
    the lower block's too at finite eta, free or tied to the upper block's where eta = p/q, q <= Q_MAX;
    docs/physics.md §14.14). Per family: the curves of roots on the torus' corners (every tanh real) on a grid of x
    and s, Newton in (x, s) from a grid of phases and X_SEEDS x 2 starts in |x| (the intersonic family, and every
    family at finite eta), SLSQP from interior starts; the best root is then followed on the root surface (SLSQP) to
    where its s is largest. |x| runs up to the window of :func:`root_window` for kH Im z >= 1e-2 (then >= 1e-6 if
    nothing grows that fast), which does not depend on kH. The search is not a certificate: a part of the root surface
    that no start reaches is not seen (the tests compare the limit with roots of the full F at large kH). Parameters
    broadcast.
    """
    arrays = np.broadcast_arrays(*(check(n, v) for n, v in (("gamma", gamma), ("f", f), ("beta", beta), ("eta", eta),
                                                             ("Delta", Delta), ("xi", xi))))
    shape = arrays[0].shape
    sigma = np.empty(shape)
    x = np.empty(shape)
    fam = np.empty(shape, dtype=np.int8)
    phases = np.empty((*shape, 4))
    status = np.empty(shape, dtype=np.int8)
    tied = np.zeros(shape, dtype=np.int64)
    for idx in np.ndindex(shape):
        s, xx, fa, t, q, st = _limit_one(*(float(a[idx]) for a in arrays))
        sigma[idx], x[idx], fam[idx], status[idx], tied[idx] = s, xx, fa, st, q
        phases[idx] = math.nan
        if t:
            torus = _Torus(fa == 3, float(arrays[3][idx]), q)
            phases[idx] = [float(v) % math.pi for v in torus.phases(tuple(t))]
    return GrowthRateLimit(sigma, x, fam, phases, tied, status)
