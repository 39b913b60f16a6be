"""Independent high-precision reference implementation ("test oracle") built on mpmath.

Everything here is written directly from ``docs/physics.md`` and the supplement of
Aldam et al., PRX 6, 041023 (2016) (``paper/aldam2016_geometric_asymmetry.tex``); equation labels in
the docstrings are the LaTeX labels of that file. It deliberately shares no code with ``model/``.

Conventions
-----------
* Public functions accept Python ``int``/``float``/``complex``, strings or mpmath numbers and return
  mpmath numbers rounded to ``DPS = 30`` significant digits. Internally they raise the working
  precision (``mp.workdps`` / ``mp.extradps``) as needed; the global ``mp.dps`` is never changed.
* ``eta`` may be ``math.inf`` or ``mp.inf``: the lower block is then a half-space, i.e. ``T2 = +1``
  (docs/physics.md §2; the supplement's "T2 -> -1" is a misprint).
* ``*_core`` helpers evaluate at the *ambient* precision plus the number of digits that the formula
  is known to lose by cancellation, so they can be used inside ``mp.diff`` / ``mp.findroot``.
"""

from __future__ import annotations

import bisect
import dataclasses
import functools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field

import mpmath
from mpmath import mp

DPS = 30  # digits of every public result
CONT_DPS = 20  # working digits while continuing the Rayleigh branch in q
Q_TOP = 10**4  # the Rayleigh branch is defined by its root nearest z_R at q = Q_TOP (docs/physics.md §3)
H_MAX = mpmath.mpf("0.02")  # grid spacing / largest continuation step in ln q
H_MIN = mpmath.mpf("1e-9")  # smallest continuation step in ln q before the branch counts as lost
MAX_ATTEMPTS = 400  # continuation steps (accepted + rejected) allowed per grid interval
RHO = mpmath.mpf("0.05")  # acceptance ratio: corrector displacement / predicted increment

Num = int | float | complex | str | mpmath.mpf | mpmath.mpc


class BranchLost(RuntimeError):
    """The Rayleigh branch could not be followed unambiguously (step underflow, solver failure,
    or a different root is closer to z_R at the starting point)."""


class PrecisionError(ArithmeticError):
    """An adaptive-precision evaluation did not stabilise."""


def _num(x: Num) -> mpmath.mpf | mpmath.mpc:
    """Convert to an mpmath number (floats exactly, strings to DPS + 20 digits)."""
    with mp.workdps(DPS + 20):
        return mp.mpmathify(x)


def _sq(x: Num) -> mpmath.mpf:
    """x^2 at DPS + 20 digits (never at the caller's ambient mp.dps)."""
    with mp.workdps(DPS + 20):
        return _num(x) ** 2


def _is_inf(x: mpmath.mpf) -> bool:
    return bool(mp.isinf(x)) and x > 0


def _round(x: mpmath.mpf | mpmath.mpc) -> mpmath.mpf | mpmath.mpc:
    """Round to DPS digits."""
    with mp.workdps(DPS):
        return +x


def _lost_digits(z: mpmath.mpc | mpmath.mpf, q: mpmath.mpf | None = None) -> int:
    """Digits lost by cancellation in the response functions near z = 0 (and small q).

    The bracket of G_x vanishes like z^2 (Eq. S-G_gen; for finite eta and small q like
    z^2 max(z^2, q^2) relative to its terms), the bracket of G_y like q z^2 at small q; the thin-on-thick
    M matrices are 0/0 ~ z^2/z^2 (Eq. S-m2s).
    """
    az = float(abs(z))
    if az == 0.0:
        raise ValueError("z = 0 is a removable singularity; evaluate at small nonzero z")
    lz = max(0.0, -math.log10(az)) if math.isfinite(math.log10(az)) else 400.0
    lq = 0.0
    if q is not None:
        fq = float(q)
        lq = max(0.0, -math.log10(fq)) if fq > 0 else 0.0
    return int(math.ceil(2 * lz + 2 * lq)) + 5


def _adaptive(
    fun: Callable[[], tuple[mpmath.mpc, ...]], base_extra: int, target: int = DPS + 2
) -> tuple[mpmath.mpc, ...]:
    """Evaluate ``fun`` at increasing precision until two successive results agree to ``target``
    significant digits, each component relative to itself (or to 1e-12 of the largest component, for
    components that are that much smaller); return the more precise one."""
    prev = None
    for k in range(8):
        with mp.workdps(DPS + base_extra + 15 * k):
            cur = fun()
        if prev is not None:
            with mp.workdps(DPS + base_extra + 15 * k):
                scale = max(abs(c) for c in cur)
                tol = mp.mpf(10) ** (-target)
                if all(
                    abs(a - b) <= tol * max(abs(a), mp.mpf("1e-12") * scale)
                    for a, b in zip(cur, prev, strict=True)
                ):
                    return cur
        prev = cur
    raise PrecisionError("adaptive precision did not converge")


# =============================================================================================
# 1. Rayleigh speed (docs/physics.md §5)
# =============================================================================================


def rayleigh_speed(beta: Num) -> mpmath.mpf:
    """z_R = c_R/c_s: x = z_R^2 is the root in (0, 1) of x^3 - 8x^2 + 8(3-2b)x - 16(1-b) = 0, b = beta^2.

    This is the Rayleigh equation (1 + alpha_s^2)^2 = 4 alpha_s alpha_d (denominator D of Eq. S-m2s)
    after squaring and dividing by x. Valid for 0 <= beta < 1/sqrt(2) (0 <= nu < 1/2).
    """
    with mp.workdps(DPS + 20):
        b = _sq(beta)

        def cubic(x: mpmath.mpf) -> mpmath.mpf:
            return ((x - 8) * x + 8 * (3 - 2 * b)) * x - 16 * (1 - b)

        # cubic(0) = -16(1-b) < 0 < 1 = cubic(1), and cubic' = 3x^2 - 16x + 24 - 16b >= 8 - 16b > 0 on (0, 1)
        # for b < 1/2: exactly one root in (0, 1).
        if not (cubic(0) < 0 < cubic(1)):
            raise ValueError("beta out of range: need 0 <= beta^2 < 1/2")
        if b >= mp.mpf(1) / 2:
            raise ValueError("beta out of range: need 0 <= beta^2 < 1/2")
        x = mp.findroot(cubic, (mp.mpf(0), mp.mpf(1)), solver="anderson")
        x = mp.findroot(cubic, x)  # Newton/secant polish
        if not 0 < x < 1:
            raise ValueError(f"root {x} not in (0, 1)")
        return _round(mp.sqrt(x))


# =============================================================================================
# 2. Response functions of two blocks (Eq. Gs_general = Eq. S-G_gen)
# =============================================================================================


def _alphas(z: mpmath.mpc, b: mpmath.mpf) -> tuple[mpmath.mpc, mpmath.mpc]:
    """alpha_s = sqrt(1 - z^2), alpha_d = sqrt(1 - beta^2 z^2), principal branch (Re >= 0)."""
    z2 = z * z
    return mp.sqrt(1 - z2), mp.sqrt(1 - b * z2)


def _block_factors(a: mpmath.mpc, q: mpmath.mpf, eta: mpmath.mpf) -> tuple[mpmath.mpc, mpmath.mpc]:
    """X = 1/(T1 + T2) and A = T2/(T1 + T2) - 1/2 for one wave type, with T1 = tanh(q a),
    T2 = tanh(eta q a) (T2 = +1 for eta = inf).

    Exact rewriting in u = exp(-2 q a), v = exp(-2 eta q a) (|u|, |v| <= 1 since Re a >= 0), which avoids
    tanh(large) and the cancellations 1 - tanh, T1 + T2 at small q, and T2 - T1 near eta = 1:
        T1 + T2 = 2 (1 - u v) / ((1 + u)(1 + v)),   T2/(T1 + T2) = 1/2 + (u - v) / (2 (1 - u v)),
        u - v = -u expm1(-2 (eta - 1) q a),          1 - u v = -expm1(-2 (1 + eta) q a).
    For eta = inf (v = 0): X = (1 + u)/2, A = u/2 (the "safe form" of docs/physics.md §2).
    """
    u = mp.exp(-2 * q * a)
    if _is_inf(eta):
        return (1 + u) / 2, u / 2
    v = mp.exp(-2 * eta * q * a)
    one_minus_uv = -mp.expm1(-2 * (1 + eta) * q * a)
    u_minus_v = -u * mp.expm1(-2 * (eta - 1) * q * a)
    return (1 + u) * (1 + v) / (2 * one_minus_uv), u_minus_v / (2 * one_minus_uv)


def response_functions_core(
    z: mpmath.mpc, q: mpmath.mpf, b: mpmath.mpf, eta: mpmath.mpf
) -> tuple[mpmath.mpc, mpmath.mpc]:
    """(G_x, G_y) of Eq. S-G_gen at the ambient precision plus the digits lost near z = 0.

        G_x = z^-2 [ (1 + alpha_s^2)^2 / (alpha_s (T1_s + T2_s)) - 4 alpha_d / (T1_d + T2_d) ]
        G_y = 2 (1 + alpha_s^2) z^-2 [ T2_d/(T1_d + T2_d) - T2_s/(T1_s + T2_s) ]

    ``b`` is beta^2. Uses 1 + alpha_s^2 = 2 - z^2 exactly.
    """
    with mp.extradps(_lost_digits(z, q)):
        z = mp.mpmathify(z)
        a_s, a_d = _alphas(z, b)
        x_s, h_s = _block_factors(a_s, q, eta)
        x_d, h_d = _block_factors(a_d, q, eta)
        z2 = z * z
        one_plus_as2 = 2 - z2
        g_x = (one_plus_as2**2 * x_s / a_s - 4 * a_d * x_d) / z2
        g_y = 2 * one_plus_as2 * (h_d - h_s) / z2
        return g_x, g_y


def response_functions(z: Num, q: Num, beta: Num, eta: Num = math.inf) -> tuple[mpmath.mpc, mpmath.mpc]:
    """(G_x, G_y) of two blocks of the same material, upper height H, lower height eta H, at z = c/c_s,
    q = kH (Eq. Gs_general = Eq. S-G_gen; eta = inf gives Eqs. Gx_LSA, Gy_LSA / S-Gx, S-Gy with T2 = +1).

    Accurate to ~30 significant digits, including near z = 0 (removable singularity; precision is raised
    adaptively and verified by re-evaluation at higher precision).
    """
    zz, qq, bb, ee = _num(z), _num(q), _sq(beta), _num(eta)
    res = _adaptive(lambda: response_functions_core(zz, qq, bb, ee), _lost_digits(zz, qq))
    return _round(mp.mpc(res[0])), _round(mp.mpc(res[1]))


def response_functions_tanh(z: Num, q: Num, beta: Num, eta: Num = math.inf) -> tuple[mpmath.mpc, mpmath.mpc]:
    """Eq. S-G_gen evaluated literally with tanh (T2 = +1 for eta = inf), at generous fixed precision.

    Only a cross-check of :func:`response_functions` for moderate q, eta q (tanh saturates to 1 at large
    arguments, so exponentially small G_y is lost here but not there).
    """
    zz, qq, bb, ee = _num(z), _num(q), _sq(beta), _num(eta)
    with mp.workdps(DPS + 2 * _lost_digits(zz, qq) + 20):
        a_s, a_d = _alphas(mp.mpmathify(zz), bb)
        t1s, t1d = mp.tanh(qq * a_s), mp.tanh(qq * a_d)
        if _is_inf(ee):
            t2s = t2d = mp.mpf(1)
        else:
            t2s, t2d = mp.tanh(ee * qq * a_s), mp.tanh(ee * qq * a_d)
        g_x = ((1 + a_s**2) ** 2 / (a_s * (t1s + t2s)) - 4 * a_d / (t1d + t2d)) / zz**2
        g_y = 2 * (1 + a_s**2) / zz**2 * (t2d / (t1d + t2d) - t2s / (t1s + t2s))
        return _round(mp.mpc(g_x)), _round(mp.mpc(g_y))


# =============================================================================================
# 3. Dispersion relation (Eq. implicit_spectrum with Eq. delta f RSF), dimensionless
# =============================================================================================


@dataclass(frozen=True)
class Params:
    """Parameters of the dispersion relation (docs/physics.md §1); b = beta^2."""

    gamma: mpmath.mpf
    f: mpmath.mpf
    b: mpmath.mpf
    eta: mpmath.mpf
    Delta: mpmath.mpf
    xi: mpmath.mpf

    @classmethod
    def make(cls, gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0) -> Params:
        with mp.workdps(DPS + 10):
            return cls(_num(gamma), _num(f), _num(beta) ** 2, _num(eta), _num(Delta), _num(xi))


def dispersion_core(z: mpmath.mpc, q: mpmath.mpf, p: Params) -> mpmath.mpc:
    """F(z; q) = gamma (G_x + i f G_y) + i z [1 + (Delta - 1)/(1 - i xi z q)] at the ambient precision
    (Eq. implicit_spectrum divided by sigma0 c_s d_v f, with Eq. delta f RSF)."""
    g_x, g_y = response_functions_core(z, q, p.b, p.eta)
    with mp.extradps(_lost_digits(z, q)):
        fric = 1 + (p.Delta - 1) / (1 - mp.j * p.xi * z * q)
        return p.gamma * (g_x + mp.j * p.f * g_y) + mp.j * z * fric


def dispersion(
    z: Num, q: Num, gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0
) -> mpmath.mpc:
    """F(z; q) of docs/physics.md §3 (Eq. implicit_spectrum + Eq. delta f RSF + Eq. Gs_general)."""
    p = Params.make(gamma, f, beta, eta, Delta, xi)
    zz, qq = _num(z), _num(q)
    g_x, g_y = response_functions(zz, qq, beta, eta)
    with mp.workdps(DPS + _lost_digits(zz, qq) + 10):
        fric = 1 + (p.Delta - 1) / (1 - mp.j * p.xi * zz * qq)
        return _round(p.gamma * (g_x + mp.j * p.f * g_y) + mp.j * zz * fric)


def dispersion_dz(
    z: Num, q: Num, gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0
) -> mpmath.mpc:
    """dF/dz of :func:`dispersion` (F is analytic in z off the real axis; mp.diff at high precision)."""
    p = Params.make(gamma, f, beta, eta, Delta, xi)
    zz, qq = _num(z), _num(q)
    with mp.workdps(DPS + _lost_digits(zz, qq) + 20):
        return _round(mp.diff(lambda w: dispersion_core(w, qq, p), mp.mpmathify(zz)))


# =============================================================================================
# 4. The Rayleigh branch (docs/physics.md §3): continuation in ln q from q = 1e4
# =============================================================================================


@dataclass
class _Node:
    s: mpmath.mpf  # continuation parameter (ln q, or ln gamma for the start homotopy)
    z: mpmath.mpc
    t: mpmath.mpc  # dz/ds at (s, z), from F_z dz + F_s ds = 0
    c: mpmath.mpc  # estimate of d^2z/ds^2 (0 at the start)


FunS = Callable[[mpmath.mpc, mpmath.mpf], mpmath.mpc]


def _F(p: Params, z: mpmath.mpc, s: mpmath.mpf) -> mpmath.mpc:
    """F(z; q = e^s)."""
    return dispersion_core(z, mp.exp(s), p)


def _tangent(fs: FunS, z: mpmath.mpc, s: mpmath.mpf) -> mpmath.mpc:
    """dz/ds = -F_s/F_z by central differences (used only as a predictor and a consistency check).

    Tiny steps at 12 extra digits, so that the derivative stays accurate even when a pole or another root
    is as close as ~1e-9 |z| (finite eta: real-axis poles next to the branch for small gamma)."""
    with mp.extradps(12):
        hz = mp.mpf("1e-12") * max(abs(z), mp.mpf("1e-3"))
        hs = mp.mpf("1e-12")
        f_z = (fs(z + hz, s) - fs(z - hz, s)) / (2 * hz)
        f_s = (fs(z, s + hs) - fs(z, s - hs)) / (2 * hs)
    if f_z == 0:
        raise BranchLost(f"F_z = 0 at s = {mp.nstr(s, 10)}, z = {mp.nstr(z, 10)} (double root)")
    return -f_s / f_z


def _secant(fun: Callable[[mpmath.mpc], mpmath.mpc], z0: mpmath.mpc, maxit: int = 40) -> mpmath.mpc:
    """Plain secant iteration from z0, z0 + small; raises ValueError if it does not converge."""
    d = mp.mpf("1e-8") * max(abs(z0), mp.mpf("1e-3"))
    za, zb = z0, z0 + d * (1 + 1j)
    fa, fb = fun(za), fun(zb)
    tol = mp.mpf(10) ** (-(mp.dps - 3)) * max(abs(z0), mp.mpf("1e-3"))
    for _ in range(maxit):
        if fb == fa:
            if fb == 0:
                return zb
            raise ValueError("secant: flat function")
        step = -fb * (zb - za) / (fb - fa)
        za, fa = zb, fb
        zb = zb + step
        fb = fun(zb)
        if abs(step) <= tol:
            return zb
        if abs(zb - z0) > 10 * max(abs(z0), 1):
            raise ValueError("secant: diverged")
    raise ValueError("secant: no convergence")


@dataclass
class _Counters:
    steps: int = 0
    rejected: int = 0
    h_smallest: float = math.inf
    where_smallest: tuple[float, complex] | None = None


def _step(fs: FunS, node: _Node, target: mpmath.mpf, cnt: _Counters) -> list[_Node]:
    """Continue the root of fs(., s) from ``node`` to s = target (one grid interval) at the ambient
    precision; return the accepted nodes (the last one is at ``target``).

    Predictor: z + h t + h^2 c / 2 (tangent t = dz/ds, c from the previous tangents). Corrector: secant.
    A step is accepted only if (i) the corrector moved the root by at most RHO |h t| (+ tiny absolute
    slack) from the prediction and (ii) the increment agrees with the trapezoidal rule h (t0 + t1)/2 to
    RHO |dz|; on a smooth branch both ratios shrink like h^2, while a jump to another root does not, so
    the step is halved until it passes or falls below H_MIN (-> BranchLost).
    """
    out = []
    cur = node
    h = target - cur.s
    attempts = 0
    while cur.s != target:
        attempts += 1
        if attempts > MAX_ATTEMPTS:
            raise BranchLost(
                f"more than {MAX_ATTEMPTS} continuation steps for one grid interval at "
                f"s = {mp.nstr(cur.s, 12)} (z = {mp.nstr(cur.z, 12)}): the branch cannot be followed reliably"
            )
        if abs(h) < H_MIN:
            raise BranchLost(
                f"step underflow at s = {mp.nstr(cur.s, 12)} (z = {mp.nstr(cur.z, 12)}): "
                "the branch cannot be followed unambiguously"
            )
        s1 = target if abs(target - cur.s) <= abs(h) else cur.s + h
        hh = s1 - cur.s
        z_pred = cur.z + hh * cur.t + hh * hh * cur.c / 2
        cnt.steps += 1
        try:
            z1 = _secant(lambda w, s1=s1: fs(w, s1), z_pred)
            t1 = _tangent(fs, z1, s1)
        except (ValueError, ZeroDivisionError, BranchLost):
            cnt.rejected += 1
            h = hh / 2
            continue
        dz = z1 - cur.z
        atol = mp.mpf("1e-12") * max(abs(cur.z), mp.mpf("1e-3"))
        ok_pred = abs(z1 - z_pred) <= RHO * abs(hh * cur.t) + atol
        ok_trap = abs(dz - hh * (cur.t + t1) / 2) <= RHO * abs(dz) + atol
        if not (ok_pred and ok_trap):
            cnt.rejected += 1
            h = hh / 2
            continue
        if abs(hh) < cnt.h_smallest:
            cnt.h_smallest = float(abs(hh))
            cnt.where_smallest = (float(cur.s), complex(cur.z))
        cur = _Node(s1, z1, t1, (t1 - cur.t) / hh)
        out.append(cur)
        h = hh * 2  # grow again (clipped at the target)
    return out


def _winding_number(fun: Callable[[mpmath.mpc], mpmath.mpc], center: mpmath.mpc, radius: mpmath.mpf) -> int:
    """Number of zeros minus poles of ``fun`` inside the circle |z - center| = radius (argument principle,
    phase increments refined until each is below pi/4)."""
    n = 64

    def point(theta: mpmath.mpf) -> mpmath.mpc:
        return center + radius * mp.expj(theta)

    def arc(t0: mpmath.mpf, f0: mpmath.mpc, t1: mpmath.mpf, f1: mpmath.mpc, depth: int) -> mpmath.mpf:
        dphi = mp.arg(f1 / f0)
        if abs(dphi) < mp.pi / 4 or depth > 30:
            return dphi
        tm = (t0 + t1) / 2
        fm = fun(point(tm))
        return arc(t0, f0, tm, fm, depth + 1) + arc(tm, fm, t1, f1, depth + 1)

    thetas = [2 * mp.pi * k / n for k in range(n + 1)]
    values = [fun(point(t)) for t in thetas[:-1]]
    values.append(values[0])
    total = mp.fsum(arc(thetas[k], values[k], thetas[k + 1], values[k + 1], 0) for k in range(n))
    return int(mp.nint(total / (2 * mp.pi)))


GAMMA_BIG = 10**4  # start of the gamma homotopy at q = 1e4 (root within ~1e-4 of z_R there)


@dataclass
class _BranchPath:
    """Continuation of the Rayleigh branch on the fixed grid s_k = ln(1e4) -/+ k H_MAX (CONT_DPS digits).

    ``down`` holds accepted nodes with decreasing s = ln q, ``up`` with increasing s (both start at
    ln 1e4). Intermediate (halved-step) nodes are stored too. ``lost_down``/``lost_up`` record a failure.
    """

    p: Params
    down: list[_Node] = field(default_factory=list)
    up: list[_Node] = field(default_factory=list)
    lost_down: BranchLost | None = None
    lost_up: BranchLost | None = None
    cnt: _Counters = field(default_factory=_Counters)
    start_note: str = ""

    def _fs(self, z: mpmath.mpc, s: mpmath.mpf) -> mpmath.mpc:
        return _F(self.p, z, s)

    def _gamma_homotopy(self, z_r: mpmath.mpf) -> mpmath.mpc | None:
        """Root at q = 1e4 continued in ln gamma from gamma = 1e4 (root next to z_R) to the wanted gamma."""
        g_big = mp.mpf(GAMMA_BIG)
        if self.p.gamma >= g_big:
            return None
        q = mp.mpf(Q_TOP)

        def fs(z: mpmath.mpc, s: mpmath.mpf) -> mpmath.mpc:
            return dispersion_core(z, q, dataclasses.replace(self.p, gamma=mp.exp(s)))

        s0, s_end = mp.log(g_big), mp.log(self.p.gamma)
        z0 = _secant(lambda w: fs(w, s0), mp.mpc(z_r))
        node = _Node(s0, z0, _tangent(fs, z0, s0), mp.mpc(0))
        cnt = _Counters()
        n = int(mp.ceil((s0 - s_end) / mp.mpf("0.1")))
        for k in range(1, n + 1):
            target = s_end if k == n else s0 - k * mp.mpf("0.1")
            node = _step(fs, node, target, cnt)[-1]
        return node.z

    def start(self) -> None:
        """Root at q = 1e4 nearest z_R: mp.findroot started at z_R, compared with the gamma homotopy
        (which reaches the root just past the branch point z = 1 that findroot misses for small gamma);
        the nearer one is taken and, when the circle around z_R through it stays clear of the real axis
        beyond z = 1 (cut for eta = inf, poles for finite eta), no root strictly closer is verified by the
        argument principle."""
        with mp.workdps(CONT_DPS):
            s0 = mp.log(Q_TOP)
            z_r = rayleigh_speed(mp.sqrt(self.p.b))

            def fun(w: mpmath.mpc) -> mpmath.mpc:
                return _F(self.p, w, s0)

            cands = []
            notes = []
            try:
                cands.append(
                    mp.findroot(fun, (mp.mpc(z_r), z_r * (1 + mp.mpf("1e-4") * 1j)), solver="secant")
                )
            except (ValueError, ZeroDivisionError) as exc:
                notes.append(f"findroot from z_R did not converge ({exc})")
            try:
                zh = self._gamma_homotopy(z_r)
                if zh is not None:
                    cands.append(zh)
            except (ValueError, ZeroDivisionError, BranchLost) as exc:
                notes.append(f"gamma homotopy failed ({exc})")
            if not cands:
                raise BranchLost("no root found near z_R at q = 1e4: " + "; ".join(notes))
            z0 = min(cands, key=lambda w: abs(w - z_r))
            if len(cands) == 2 and abs(cands[0] - cands[1]) > mp.mpf("1e-10"):
                notes.append(
                    f"findroot from z_R gave {mp.nstr(cands[0], 10)}, gamma homotopy {mp.nstr(cands[1], 10)};"
                    " took the nearer"
                )
            r = abs(z0 - z_r)
            if r > mp.mpf("1e-12") and r < (1 - z_r) * mp.mpf("0.98"):
                if _winding_number(fun, mp.mpc(z_r), r * mp.mpf("0.98")) != 0:
                    raise BranchLost("a root closer to z_R than the one found exists at q = 1e4")
            elif r >= (1 - z_r) * mp.mpf("0.98"):
                notes.append("nearest-root property not verified (circle would cross the real axis beyond 1)")
            self.start_note = "; ".join(notes)
            node = _Node(s0, z0, _tangent(self._fs, z0, s0), mp.mpc(0))
        self.down.append(node)
        self.up.append(node)

    def extend(self, s_req: mpmath.mpf) -> None:
        """Extend the main path on the fixed grid until it passes s_req (or record the loss)."""
        downward = s_req < self.down[0].s
        nodes = self.down if downward else self.up
        sign = -1 if downward else 1
        with mp.workdps(CONT_DPS):
            while (nodes[-1].s > s_req) if downward else (nodes[-1].s < s_req):
                if (self.lost_down if downward else self.lost_up) is not None:
                    return
                k = int(mp.nint(abs(nodes[-1].s - nodes[0].s) / H_MAX))
                target = nodes[0].s + sign * (k + 1) * H_MAX
                try:
                    nodes.extend(_step(self._fs, nodes[-1], target, self.cnt))
                except BranchLost as exc:
                    lost = BranchLost(
                        f"Rayleigh branch lost between q = {mp.nstr(mp.exp(nodes[-1].s), 10)} and "
                        f"q = {mp.nstr(mp.exp(target), 10)}: {exc}"
                    )
                    if downward:
                        self.lost_down = lost
                    else:
                        self.lost_up = lost
                    return

    def root(self, s_req: mpmath.mpf) -> mpmath.mpc:
        """Root at s_req (CONT_DPS digits), reached from the nearest path node on the q_top side."""
        self.extend(s_req)
        downward = s_req < self.down[0].s
        nodes = self.down if downward else self.up
        prev = nodes[0]  # last node not beyond s_req (on the q_top side of it)
        for nd in nodes:
            if (nd.s < s_req) if downward else (nd.s > s_req):
                break
            prev = nd
        if prev.s == s_req:
            return prev.z
        with mp.workdps(CONT_DPS):
            try:
                return _step(self._fs, prev, s_req, _Counters())[-1].z
            except BranchLost as exc:
                lost = self.lost_down if downward else self.lost_up
                if lost is not None:
                    raise lost from None
                raise BranchLost(f"at q = {mp.nstr(mp.exp(s_req), 10)}: {exc}") from None


@functools.lru_cache(maxsize=128)
def _path(p: Params) -> _BranchPath:
    path = _BranchPath(p)
    path.start()
    return path


def rayleigh_branch(
    qs: Iterable[Num] | Num,
    gamma: Num,
    f: Num,
    beta: Num,
    eta: Num,
    Delta: Num = 1,
    xi: Num = 0,
    strict: bool = True,
) -> list[mpmath.mpc | None]:
    """Roots z(q) on the Rayleigh branch (docs/physics.md §3), one per requested q (any order).

    Definition: at q = 1e4 the root nearest z_R (the nearer of mp.findroot started at z_R and of a
    continuation in ln gamma from gamma = 1e4, where the root is next to z_R; for gamma <~ 1 findroot from
    z_R lands on a far root on the imaginary axis. The nearest-root property is verified by the argument
    principle when the circle around z_R stays clear of the real-axis cut/poles; otherwise
    rayleigh_branch_stats()["start_note"] says it is unverified), continued in ln q on the
    fixed grid ln(1e4) -/+ k * 0.02 (downward for q < 1e4, upward for q > 1e4) with a second-order
    tangent predictor, secant corrector and step halving whenever the corrected root is not consistent
    with the predictor and with the trapezoidal rule of the tangents (a branch jump). Each requested q is
    reached from the grid node just on the q = 1e4 side of it, so results do not depend on which q's
    are requested. Roots are finally polished at DPS = 30 with mp.findroot (~25+ correct digits).

    Raises BranchLost where the branch cannot be followed (or returns None there if strict=False).
    Continuation results are cached per parameter set.
    """
    q_list = [qs] if isinstance(qs, int | float | str | mpmath.mpf) else list(qs)
    p = Params.make(gamma, f, beta, eta, Delta, xi)
    try:
        path = _path(p)
    except BranchLost:
        if strict:
            raise
        return [None] * len(q_list)
    out: list[mpmath.mpc | None] = []
    for q in q_list:
        qq = _num(q)
        try:
            with mp.workdps(CONT_DPS):
                z20 = path.root(mp.log(qq))
            out.append(_polish(p, qq, z20))
        except BranchLost:
            if strict:
                raise
            out.append(None)
    return out


def _polish(p: Params, q: mpmath.mpf, z20: mpmath.mpc) -> mpmath.mpc:
    """Refine a continuation root at DPS + 10 digits with mp.findroot (secant)."""
    with mp.workdps(DPS + 10):
        z0 = mp.mpc(z20)
        d = mp.mpf("1e-12") * max(abs(z0), mp.mpf("1e-3"))
        try:
            z = mp.findroot(lambda w: dispersion_core(w, q, p), (z0, z0 + d), solver="secant")
        except (ValueError, ZeroDivisionError) as exc:
            raise BranchLost(f"polishing failed at q = {mp.nstr(q, 10)}: {exc}") from exc
        if abs(z - z0) > mp.mpf("1e-12") * max(abs(z0), mp.mpf("1e-3")):
            raise BranchLost(f"polishing moved the root at q = {mp.nstr(q, 10)}: {z0} -> {z}")
        return _round(z)


def rayleigh_branch_stats(gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0) -> dict:
    """Diagnostics of the cached continuation: number of nodes, steps, rejected steps, losses."""
    path = _path(Params.make(gamma, f, beta, eta, Delta, xi))
    return {
        "nodes_down": len(path.down),
        "nodes_up": len(path.up),
        "q_min_reached": float(mp.exp(path.down[-1].s)),
        "steps": path.cnt.steps,
        "rejected": path.cnt.rejected,
        "smallest_step": path.cnt.h_smallest,
        "smallest_step_at_q_z": None
        if path.cnt.where_smallest is None
        else (math.exp(path.cnt.where_smallest[0]), path.cnt.where_smallest[1]),
        "start_note": path.start_note,
        "lost_down": None if path.lost_down is None else str(path.lost_down),
        "lost_up": None if path.lost_up is None else str(path.lost_up),
    }


def branch_tangent(
    q: Num, gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0
) -> tuple[mpmath.mpc, mpmath.mpc]:
    """(z, dz/dq) on the Rayleigh branch; dz/dq = -F_q/F_z by implicit differentiation (mp.diff)."""
    p = Params.make(gamma, f, beta, eta, Delta, xi)
    qq = _num(q)
    z = rayleigh_branch([qq], gamma, f, beta, eta, Delta, xi)[0]
    with mp.workdps(DPS + _lost_digits(z, qq) + 20):
        f_z = mp.diff(lambda w: dispersion_core(w, qq, p), mp.mpc(z))
        f_q = mp.diff(lambda x: dispersion_core(mp.mpc(z), x, p), qq)
        return z, _round(-f_q / f_z)


def rayleigh_branch_max_growth(
    q_guess: Num, gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0
) -> tuple[mpmath.mpf, mpmath.mpf]:
    """(q*, max Im z) of the Rayleigh branch near q_guess: mp.findroot on Im(dz/dq) = 0."""

    def dim(x: mpmath.mpf) -> mpmath.mpf:
        return mp.im(branch_tangent(x, gamma, f, beta, eta, Delta, xi)[1])

    with mp.workdps(DPS):
        q_star = mp.findroot(dim, (_num(q_guess), _num(q_guess) * mp.mpf("1.01")), solver="secant")
        z = rayleigh_branch([q_star], gamma, f, beta, eta, Delta, xi)[0]
        return _round(q_star), _round(mp.im(z))


# =============================================================================================
# 4b. Neutral modes: the thresholds of the max growth (docs/physics.md §9)
# =============================================================================================

NEUTRAL_DPS = DPS + 20  # working digits of the neutral-mode Newton iteration
NEUTRAL_H = mpmath.mpf("1e-22")  # central-difference step (relative) of F's derivatives at NEUTRAL_DPS digits
NEUTRAL_HJ = mpmath.mpf("1e-14")  # central-difference step of the Newton Jacobian
NEUTRAL_S_TOL = mpmath.mpf("1e-20")  # the Newton step in ln q at convergence (see neutral_mode)


def _neutral_params(p: Params, which: str, t: mpmath.mpf) -> Params:
    """p with gamma or eta set to e^t."""
    return dataclasses.replace(p, **{which: mp.exp(t)})


def _neutral_residual(p: Params, which: str, v: list, edge_s: mpmath.mpf | None, lip: mpmath.mpf = 0) -> list:
    """The three real equations of a neutral mode at v = (x, s, t) (or two at fixed s = edge_s for v = (x, t)):
    Re F = Im F = 0 at the real z = x, q = e^s, and Im(dF/ds / dF/dz) = 0 (Im z stationary in s = ln q).
    F = dispersion_core at x + i lip (lip > 0 tiny: the upper lip of the cuts |x| > 1 at eta = inf, the limit from
    Im z > 0; mpmath's square root of a negative real is +i sqrt, the lower lip for x > 1); its derivatives by
    central differences of relative step NEUTRAL_H."""
    if edge_s is None:
        x, s, t = v
    else:
        (x, t), s = v, edge_s
    pp = _neutral_params(p, which, t)
    q = mp.exp(s)
    z = mp.mpc(x, lip)
    fv = dispersion_core(z, q, pp)
    if edge_s is not None:
        return [mp.re(fv), mp.im(fv)]
    hz = NEUTRAL_H * max(abs(x), mp.mpf("1e-3"))
    fz = (dispersion_core(z + hz, q, pp) - dispersion_core(z - hz, q, pp)) / (2 * hz)
    fs = (dispersion_core(z, mp.exp(s + NEUTRAL_H), pp) - dispersion_core(z, mp.exp(s - NEUTRAL_H), pp)) / (
        2 * NEUTRAL_H)
    return [mp.re(fv), mp.im(fv), mp.im(fs / fz)]


def neutral_mode(
    which: str,
    x0: Num,
    q0: Num,
    value0: Num,
    gamma: Num,
    f: Num,
    beta: Num,
    eta: Num,
    Delta: Num = 1,
    xi: Num = 0,
    edge: bool = False,
    maxit: int = 30,
    upper_lip: bool = False,
) -> tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf]:
    """(x, q, value): a neutral mode of F(z; q) = 0 for the threshold parameter `which` ("gamma" or "eta"): real
    z = x, Im z stationary in ln q (dIm z/d ln q = 0, i.e. Im(F_q/F_z) = 0), at the parameter value `value`
    (docs/physics.md §9). With edge=True the kH is held at q0 (a maximum at an end of a kH range: two equations).

    Newton's method on the real equations in (x, ln q, ln value) at NEUTRAL_DPS digits, from (x0, q0, value0), with a
    central-difference Jacobian (step NEUTRAL_HJ); the parameter named by `which` is ignored in the arguments.
    upper_lip: F at x + i 10^-(NEUTRAL_DPS + 10), the upper lip of the cuts at eta = inf (any root's neutral mode
    beyond the shear speed; the Rayleigh branch's lie below it, where both agree).
    Converged when the step is below 10^-(DPS + 5) relative in x and the parameter (and NEUTRAL_S_TOL in ln q, to
    which the parameter is stationary); ValueError otherwise. Rounded to DPS digits.
    """
    if which not in ("gamma", "eta"):
        raise ValueError(f"which must be 'gamma' or 'eta'; got {which!r}")
    p = Params.make(gamma, f, beta, eta, Delta, xi)
    with mp.workdps(NEUTRAL_DPS):
        lip = mp.mpf(10) ** (-(NEUTRAL_DPS + 10)) if upper_lip else mp.mpf(0)
        edge_s = mp.log(_num(q0)) if edge else None
        v = [mp.mpf(_num(x0)), mp.log(_num(q0)), mp.log(_num(value0))]
        if edge:
            v = [v[0], v[2]]
        n = len(v)
        tol = mp.mpf(10) ** (-(DPS + 5))
        for _ in range(maxit):
            r = _neutral_residual(p, which, v, edge_s, lip)
            jac = mp.matrix(n, n)
            for k in range(n):
                h = NEUTRAL_HJ * max(abs(v[k]), 1)
                up, dn = list(v), list(v)
                up[k] += h
                dn[k] -= h
                ru, rd = _neutral_residual(p, which, up, edge_s, lip), _neutral_residual(p, which, dn, edge_s, lip)
                for i in range(n):
                    jac[i, k] = (ru[i] - rd[i]) / (2 * h)
            step = mp.lu_solve(jac, mp.matrix([-ri for ri in r]))
            v = [v[k] + step[k] for k in range(n)]
            # x and the parameter to DPS + 5 digits; ln q only to NEUTRAL_S_TOL: the slope equation is noisy at
            # ~NEUTRAL_H^-1 10^-NEUTRAL_DPS, and the parameter is stationary in ln q there (its error is 2nd order)
            tols = [tol, NEUTRAL_S_TOL, tol] if not edge else [tol, tol]
            if all(abs(step[k]) <= tols[k] * max(abs(v[k]), 1) for k in range(n)):
                x, s, t = (v[0], edge_s, v[1]) if edge else (v[0], v[1], v[2])
                return _round(x), _round(mp.exp(s)), _round(mp.exp(t))
    raise ValueError(f"neutral mode: Newton did not converge from x = {x0}, q = {q0}, {which} = {value0}")


def neutral_curvature(which: str, x: Num, q: Num, value: Num, gamma: Num, f: Num, beta: Num, eta: Num,
                      Delta: Num = 1, xi: Num = 0) -> tuple[mpmath.mpf, mpmath.mpf]:
    """(d^2 Im z/d(ln q)^2, d Im z/d ln value) of the root z = x at the neutral mode: the first < 0 says the mode is a
    maximum of Im z in kH (not a minimum); the second is the slope of the max growth across the threshold (its sign
    is the crossing's direction). By central differences of the root (secant solves) at NEUTRAL_DPS digits."""
    p = Params.make(gamma, f, beta, eta, Delta, xi)
    with mp.workdps(NEUTRAL_DPS):
        xx, s0, t0 = mp.mpf(_num(x)), mp.log(_num(q)), mp.log(_num(value))
        h = mp.mpf("1e-6")

        def root(s: mpmath.mpf, t: mpmath.mpf) -> mpmath.mpc:
            pp = _neutral_params(p, which, t)
            return _secant(lambda w: dispersion_core(w, mp.exp(s), pp), mp.mpc(xx, 0))

        zc = root(s0, t0)
        d2 = (mp.im(root(s0 + h, t0)) - 2 * mp.im(zc) + mp.im(root(s0 - h, t0))) / h**2
        dt = (mp.im(root(s0, t0 + h)) - mp.im(root(s0, t0 - h))) / (2 * h)
        return _round(d2), _round(dt)


# =============================================================================================
# 5. Linear expansion near z_R (Eq. S-dz) and the criterion (Eq. criterion)
# =============================================================================================


def linear_expansion(q: Num, gamma: Num, f: Num, beta: Num, eta: Num = math.inf) -> mpmath.mpc:
    """z_R + delta z with Eq. S-dz:
    delta z = -[z_R - i gamma (G_x + i f G_y)] / [1 - i gamma (G_x' + i f G_y')], G' = dG/dz at z_R."""
    qq, gg, ff = _num(q), _num(gamma), _num(f)
    b = _sq(beta)
    ee = _num(eta)
    z_r = rayleigh_speed(beta)
    with mp.workdps(DPS + 20):
        g_x, g_y = response_functions_core(mp.mpc(z_r), qq, b, ee)
        dg_x = mp.diff(lambda w: response_functions_core(w, qq, b, ee)[0], mp.mpc(z_r))
        dg_y = mp.diff(lambda w: response_functions_core(w, qq, b, ee)[1], mp.mpc(z_r))
        dz = -(z_r - 1j * gg * (g_x + 1j * ff * g_y)) / (1 - 1j * gg * (dg_x + 1j * ff * dg_y))
        return _round(z_r + dz)


def criterion_min_gy(beta: Num, eta: Num = math.inf, q_guess: Num = 0.9) -> tuple[mpmath.mpf, mpmath.mpf]:
    """(q_min, min_q G_y(z_R, q)) (Eq. criterion; docs/physics.md §4), by mp.findroot on dG_y/dq = 0."""
    z_r = rayleigh_speed(beta)
    b, ee = _sq(beta), _num(eta)
    with mp.workdps(DPS + 20):

        def gy(x: mpmath.mpf) -> mpmath.mpf:
            return mp.re(response_functions_core(mp.mpc(z_r), x, b, ee)[1])

        q_min = mp.findroot(lambda x: mp.diff(gy, x), _num(q_guess))
        return _round(q_min), _round(gy(q_min))


# =============================================================================================
# 6. Thin-on-thick: B, C, effective moduli (Eq. B(q)C(q), Eq. effective_constants = Eq. S-5)
# =============================================================================================


def _k0(t: mpmath.mpf) -> mpmath.mpf:
    """Modified Bessel function K0 (mpmath)."""
    return mp.besselk(0, t)


def _cosh_grid(x: mpmath.mpf) -> list[mpmath.mpf]:
    """Break points 0, w, 2w, 4w, ... up to u_max for integrands e^{-x cosh u}: w = min(1, x^{-1/2}) is the
    width of the peak at u = 0, and beyond u_max, e^{-x (cosh u - 1)} < 10^-(dps + 20)."""
    u_max = mp.acosh(1 + (mp.dps + 20) * mp.log(10) / x)
    w = min(mp.mpf(1), 1 / mp.sqrt(x))
    pts = [mp.mpf(0)]
    while pts[-1] + w < u_max:
        pts.append(pts[-1] + w)
        w *= 2
    pts.append(u_max)
    return pts


def _one_minus_b(qq: mpmath.mpf) -> mpmath.mpf:
    """1 - B(q) = (2/pi) Int_x^inf K0(t) dt, x = q/2, at the ambient precision, full relative precision.

    With K0(t) = Int_0^inf e^{-t cosh u} du:  Int_x^inf K0 = Int_0^inf e^{-x cosh u} / cosh u du
    = e^{-x} Int_0^inf e^{-2 x sinh^2(u/2)} / cosh u du (the e^{-x} is factored out so that mp.quad's
    absolute error control works for any x).
    """
    x = qq / 2
    if x <= 1:
        return 1 - _b(qq)
    integral = mp.quad(lambda u: mp.exp(-2 * x * mp.sinh(u / 2) ** 2) / mp.cosh(u), _cosh_grid(x))
    return 2 / mp.pi * mp.exp(-x) * integral


def _b(qq: mpmath.mpf) -> mpmath.mpf:
    """B(q) at the ambient precision, x = q/2:
    Int_0^x K0 = Int_0^inf (1 - e^{-x cosh u}) / cosh u du (full relative precision also for small x);
    beyond u_max the integrand is sech u, whose tail integral is 2 atan(e^{-u_max})."""
    x = qq / 2
    if x == 0:
        return mp.mpf(0)
    if x > 1:
        return 1 - _one_minus_b(qq)
    pts = _cosh_grid(x)
    integral = mp.quad(lambda u: -mp.expm1(-x * mp.cosh(u)) / mp.cosh(u), pts)
    return 2 / mp.pi * (integral + 2 * mp.atan(mp.exp(-pts[-1])))


def B(q: Num) -> mpmath.mpf:
    """B(q) = (1/pi) Int_0^q K0(q'/2) dq' = (2/pi) Int_0^{q/2} K0(t) dt (Eq. B(q)C(q)); q >= 0."""
    qq = _num(q)
    if qq < 0:
        raise ValueError("B(q) is defined for q >= 0")
    with mp.workdps(DPS + 15):
        return _round(_b(qq))


def one_minus_B(q: Num) -> mpmath.mpf:
    """1 - B(q) = (2/pi) Int_{q/2}^inf K0(t) dt, with full relative precision for large q."""
    with mp.workdps(DPS + 15):
        return _round(_one_minus_b(_num(q)))


def C(q: Num) -> mpmath.mpf:
    """C(q) = (q/pi) K0(|q|/2) (Eq. B(q)C(q))."""
    qq = _num(q)
    with mp.workdps(DPS + 10):
        return _round(qq / mp.pi * _k0(abs(qq) / 2))


def effective_moduli(q: Num, nu: Num) -> tuple[mpmath.mpf, mpmath.mpf]:
    """(mu_eff/mu, nu_eff) of Eq. effective_constants (= Eq. S-5), q = kW:
    mu_eff/mu = 1/[2(1-nu)B - (1-2nu)(1-e^{-q/2})],
    nu_eff = [(1-nu)B - (1-2nu)(1-e^{-q/2})] / [2(1-nu)B - (1-2nu)(1-e^{-q/2})]."""
    qq, nn = _num(q), _num(nu)
    with mp.workdps(DPS + 15):
        bq = 1 - _one_minus_b(qq)
        e = -mp.expm1(-abs(qq) / 2)
        den = 2 * (1 - nn) * bq - (1 - 2 * nn) * e
        return _round(1 / den), _round(((1 - nn) * bq - (1 - 2 * nn) * e) / den)


def mu_eff_minus_one(q: Num, nu: Num) -> mpmath.mpf:
    """mu_eff/mu - 1 without cancellation: with N = 1 - den = 2(1-nu)(1-B) - (1-2nu) e^{-q/2}
    (exact, since 1 + (1-2nu) = 2(1-nu)), mu_eff/mu - 1 = N/(1 - N)."""
    qq, nn = _num(q), _num(nu)
    with mp.workdps(DPS + 30):
        n = 2 * (1 - nn) * _one_minus_b(qq) - (1 - 2 * nn) * mp.exp(-abs(qq) / 2)
        return _round(n / (1 - n))


def mu_eff_minimum(nu: Num) -> tuple[mpmath.mpf, mpmath.mpf]:
    """(q_min, 1 - min_q mu_eff/mu) (docs/physics.md §6; the supplement's numbers are partly misprinted).

    d/dq (mu_eff/mu) = N'/(1-N)^2 with N' = -(2(1-nu)/pi) K0(q/2) + ((1-2nu)/2) e^{-q/2} (from
    dB/dq = K0(q/2)/pi); mp.findroot on N' = 0 written as ln(e^x K0(x)) = ln(pi(1-2nu)/(4(1-nu))), x = q/2
    (e^x K0(x) decreases monotonically, so the root, a minimum, is unique)."""
    nn = _num(nu)
    with mp.workdps(DPS + 20):
        rhs = mp.pi * (1 - 2 * nn) / (4 * (1 - nn))
        x0 = mp.pi / (2 * rhs**2)  # from e^x K0(x) ~ sqrt(pi/(2x))
        x = mp.findroot(lambda x: mp.log(mp.exp(x) * _k0(x)) - mp.log(rhs), x0)
        q_min = 2 * x
        return _round(q_min), _round(-mu_eff_minus_one(q_min, nn))


# =============================================================================================
# 7. Thin-on-thick effective bimaterial response (Eq. S-m2s, Eq. S-defG, Eq. S-sig_G, Eq. dsigma)
# =============================================================================================


def _beta2(nu: mpmath.mpf) -> mpmath.mpf:
    """beta^2 = (c_s/c_d)^2 = (1 - 2nu)/(2 - 2nu)."""
    return (1 - 2 * nu) / (2 - 2 * nu)


def _half_space_m(z: mpmath.mpc, b: mpmath.mpf, mu: mpmath.mpf, lower: bool) -> list[list[mpmath.mpc]]:
    """M of a half-space (units k = 1), z = c / c_s of that block, b = its beta^2 (Eq. S-m2s):

        M_upper = 1/(mu D) [[ a_s(1-a_s^2),  i(1+a_s^2-2 a_s a_d)], [-i(1+a_s^2-2 a_s a_d),  a_d(1-a_s^2)]]
        M_lower = the same with both diagonal entries negated,  D = (1+a_s^2)^2 - 4 a_s a_d.
    Uses 1 - a_s^2 = z^2 and 1 + a_s^2 = 2 - z^2 exactly.
    """
    z2 = z * z
    a_s, a_d = _alphas(z, b)
    den = mu * ((2 - z2) ** 2 - 4 * a_s * a_d)
    off = 2 - z2 - 2 * a_s * a_d
    sgn = -1 if lower else 1
    return [[sgn * a_s * z2 / den, mp.j * off / den], [-mp.j * off / den, sgn * a_d * z2 / den]]


def _g_from_m(mu_: list[list[mpmath.mpc]], ml: list[list[mpmath.mpc]]) -> tuple[mpmath.mpc, mpmath.mpc]:
    """G = (M_upper - M_lower)^-1 (Eq. S-defG); G_x = G_xx, G_y = G_yx / i (Eq. S-sig_G, mu_1 = k = 1)."""
    a = [[mu_[i][j] - ml[i][j] for j in range(2)] for i in range(2)]
    det = a[0][0] * a[1][1] - a[0][1] * a[1][0]
    return a[1][1] / det, (-a[1][0] / det) / mp.j


def _thin_on_thick_setup(kW: Num, nu: Num) -> tuple[mpmath.mpf, mpmath.mpf, mpmath.mpf, mpmath.mpf]:
    """(nu, nu_1, mu_eff/mu, nu_eff): upper = plane stress nu_1 = nu/(1+nu); lower = (mu_eff, nu_eff)."""
    nn = _num(nu)
    m, nu2 = effective_moduli(kW, nn)
    with mp.workdps(DPS + 10):
        nu1 = nn / (1 + nn)
    return nn, nu1, m, nu2


def thin_on_thick_response(z: Num, kW: Num, nu: Num) -> tuple[mpmath.mpc, mpmath.mpc]:
    """(G_x, G_y) of the effective bimaterial pair of Sect. III / S-IV (Fig. 3b), z = c/c_s of the thin block.

    Upper: thin block in plane stress (mu, Poisson ratio nu/(1+nu)), half-space. Lower: half-space with
    mu_eff(kW), nu_eff(kW) (Eq. effective_constants), same density, so its shear speed is
    c_s sqrt(mu_eff/mu) and its z_2 = z / sqrt(mu_eff/mu). M's of Eq. S-m2s, G = (M_upper - M_lower)^-1,
    G_x = G_xx/(mu_1 k), G_y = G_yx/(i mu_1 k), in units mu_1 = k = 1. Precision is raised near z = 0.
    """
    _, nu1, m, nu2 = _thin_on_thick_setup(kW, nu)
    zz = _num(z)

    def fun() -> tuple[mpmath.mpc, mpmath.mpc]:
        w = mp.mpmathify(zz)
        mu_ = _half_space_m(w, _beta2(nu1), mp.mpf(1), lower=False)
        ml = _half_space_m(w / mp.sqrt(m), _beta2(nu2), m, lower=True)
        return _g_from_m(mu_, ml)

    res = _adaptive(fun, _lost_digits(zz))
    return _round(mp.mpc(res[0])), _round(mp.mpc(res[1]))


def thin_on_thick_quasistatic_gy(kW: Num, nu: Num) -> mpmath.mpf:
    """z -> 0 limit of G_y from the quasi-static M of Eq. S-M_QS_inf_H (= Eq. M_2D_QS) with each block's
    (mu, nu): lower block M = (1/mu2)[[1-nu2, -i(1-2nu2)/2], [i(1-2nu2)/2, 1-nu2]]; the upper block has
    the diagonal sign flipped (H -> -H), with nu1 = nu/(1+nu), mu1 = 1."""
    _, nu1, m, nu2 = _thin_on_thick_setup(kW, nu)
    with mp.workdps(DPS + 10):
        mu_ = [[-(1 - nu1), -mp.j * (1 - 2 * nu1) / 2], [mp.j * (1 - 2 * nu1) / 2, -(1 - nu1)]]
        ml = [
            [(1 - nu2) / m, -mp.j * (1 - 2 * nu2) / (2 * m)],
            [mp.j * (1 - 2 * nu2) / (2 * m), (1 - nu2) / m],
        ]
        gy = _g_from_m(mu_, ml)[1]
        return _round(mp.re(gy)) if mp.im(gy) == 0 else _round(gy)


def normal_stress_change(v: Num, c: Num, c_s: Num, kW: Num, nu: Num, mu: Num) -> mpmath.mpc:
    """Delta sigma_yy = -(mu/c) G_y(c/c_s; mu_eff(kW), nu_eff(kW)) v (Eq. dsigma)."""
    cc = _num(c)
    with mp.workdps(DPS + 10):
        z = cc / _num(c_s)
    g_y = thin_on_thick_response(z, kW, nu)[1]
    with mp.workdps(DPS + 10):
        return _round(-(_num(mu) / cc) * g_y * _num(v))


# =============================================================================================
# 8. All branches: counting and locating roots in a rectangle (docs/physics.md §10)
# =============================================================================================
#
# F(z; q) is analytic in the open upper half-plane (its poles and cuts lie on the real axis, the friction pole at
# -i/(xi q) below it; docs/physics.md §2), so the number of roots in a closed rectangle inside Im z > 0 is the winding
# number of F along its boundary, with no pole correction. The sampling below is written independently of the model's
# (model/modes.py): different acceptance tests, spacing and grading (see _Contour).

ROOT_DPS = 20  # default working digits of the contour sampling and of the root search
ARG_STEP = math.pi / 8  # largest |change of arg F| over an accepted segment
LOG_MOD_STEP = 0.5  # largest |change of ln|F|| over an accepted segment
CURVATURE_TOL = 0.25  # largest |L1 - L2| (second difference of log F at the two ends and the midpoint)
EDGE_SPACING = 0.05  # largest initial spacing along any edge
GRADING = 2  # ratio of the geometric grading towards the real axis (vertical edges) and around singularities
H_MIN_REL = 1e-12  # smallest segment (relative to the window) before a root counts as lying on the edge
MAX_EVALS = 200_000  # new evaluations of F allowed for one count
INTEGER_TOL = 1e-6  # largest distance of the winding number from an integer
MAX_SINGULAR = 4000  # most real-axis poles in range around which horizontal edges are graded (more: refused)
POLISH_DPS = 25  # digits of the returned roots
CELL_MIN_REL = 1e-10  # smallest cell (relative to the window) still split while locating roots


class RootOnContour(RuntimeError):
    """A root lies on (or within ~1e-12 relative of) a sampled line: its winding number is undefined."""


def _real_singularities(p: Params, q: mpmath.mpf, lo: mpmath.mpf, hi: mpmath.mpf) -> list[mpmath.mpf]:
    """Real-axis singularities of F in [lo, hi] (docs/physics.md §2): the branch points +-1, +-1/beta and, for finite
    eta, the poles z^2 = 1 + t_n^2 and z^2 = (1 + t_n^2)/beta^2 with t_n = pi n/((1 + eta) q), n >= 1. More than
    MAX_SINGULAR poles in range: RuntimeError (a pole whose horizontal edges are not graded around it can hide a
    root beside it: the oracle refuses rather than count without them)."""
    reach = max(abs(lo), abs(hi))
    beta = mp.sqrt(p.b)
    pts = [mp.mpf(1)] + ([1 / beta] if beta > 0 else [])
    if not _is_inf(p.eta):
        fam: list[mpmath.mpf] = []
        dt = mp.pi / ((1 + p.eta) * q)
        for scale in [mp.mpf(1)] + ([1 / beta] if beta > 0 else []):
            n = 1
            while len(fam) <= MAX_SINGULAR:
                z = scale * mp.sqrt(1 + (n * dt) ** 2)
                if z > reach:
                    break
                fam.append(z)
                n += 1
        if len(fam) > MAX_SINGULAR:
            raise RuntimeError(f"more than {MAX_SINGULAR} real-axis poles in [{mp.nstr(lo, 8)}, {mp.nstr(hi, 8)}]: "
                               "too many for the oracle's graded nodes")
        pts += fam
    both = {s * x for x in pts for s in (1, -1)}
    return sorted(x for x in both if lo <= x <= hi)


class _Contour:
    """Samples of F(z; q) on the sides of axis-parallel rectangles inside the window [x0, x1] x [y0, y1] (Im z > 0),
    at the ambient precision (the caller's mp.workdps), with every value and segment increment memoised so that
    the sub-rectangles of roots_in_rectangle reuse their parent's samples.

    Nodes. A horizontal line at height y starts from the lattice x0 + k (x1 - x0)/n (spacing <= min(EDGE_SPACING,
    pi/(8q)): along lines near the real axis F oscillates like exp(2 i q z)), plus, around every real-axis singularity
    s (_real_singularities), the nodes s and s +- y GRADING^k up to half the distance to the neighbouring singularity:
    a root just above a pole (at distance ~y on the other side of the line) changes log F only within ~y of s, where
    no test on coarser samples would see it. A vertical line uses the nodes y0 GRADING^k (geometric towards the real
    axis, where F varies on the scale of Im z), then the same uniform spacing up to y1. A sub-rectangle's side uses
    the nodes of the line strictly inside it plus its own ends.

    Acceptance of a segment [a, b] (between neighbouring nodes, then bisected as needed). F is evaluated at the
    midpoint m and L1 = Log(F_m/F_a), L2 = Log(F_b/F_m) (principal logarithms). The segment is accepted when
      (i)  |Im(L1 + L2)| <= ARG_STEP (pi/8) and |Re(L1 + L2)| <= LOG_MOD_STEP (0.5): arg F and ln|F| change little;
      (ii) |L1 - L2| <= CURVATURE_TOL (0.25): log F is nearly linear, i.e. its second difference
           ~ (h/2)^2 |(log F)''| is small. A root (or pole) at distance d from the segment has (log F)'' ~ 1/d^2, so
           (ii) forces h <~ d near it and keeps the increments of log F free of aliasing; it also catches two roots
           on either side of the line, whose arg changes cancel but whose ln|F| is not linear.
    On acceptance the increment of log F is L1 + L2, which equals the principal Log(F_b/F_a) because
    |L1 + L2| < pi (so the two half-increments and the whole increment agree by construction); the winding number,
    the sum of these increments over the closed boundary / 2 pi, is then an integer up to rounding (checked to
    INTEGER_TOL). A rejected segment is bisected; one shorter than H_MIN_REL x the window's size that still fails
    means a root on (or within ~1e-12 of) the line: RootOnContour. A sample with F = 0 exactly, too.
    """

    def __init__(self, q: Num, p: Params, window: tuple[mpmath.mpf, ...]) -> None:
        self.q, self.p = mp.mpf(_num(q)), p
        x0, x1, y0, y1 = window
        self.size = max(x1 - x0, y1 - y0)
        self.h_min = H_MIN_REL * self.size
        cap = min(mp.mpf(EDGE_SPACING), mp.pi / (8 * self.q))
        n = int(mp.ceil((x1 - x0) / cap))
        self.xs = [x0 + (x1 - x0) * k / n for k in range(n)] + [x1]
        ys = [y0]
        while ys[-1] < y1:
            ys.append(ys[-1] + min(ys[-1] * (GRADING - 1), cap))
        ys[-1] = y1
        if len(ys) > 2 and ys[-1] - ys[-2] < cap / 4:  # no sliver at the top
            del ys[-2]
        self.ys = ys
        self.cap = cap
        self.singular = _real_singularities(p, self.q, x0 - 1, x1 + 1)
        self.values: dict[mpmath.mpc, mpmath.mpc] = {}
        self.segments: dict[tuple[mpmath.mpc, mpmath.mpc], tuple[mpmath.mpc, mpmath.mpc]] = {}
        self.lines: dict[tuple, tuple[mpmath.mpc, mpmath.mpc]] = {}
        self.h_nodes: dict[mpmath.mpf, list[mpmath.mpf]] = {}
        self.evals = 0  # new evaluations since the last reset
        self.total_evals = 0

    def F(self, z: mpmath.mpc) -> mpmath.mpc:
        v = self.values.get(z)
        if v is None:
            self.evals += 1
            self.total_evals += 1
            if self.evals > MAX_EVALS:
                raise RuntimeError(f"more than {MAX_EVALS} evaluations of F for one count (window too large, or "
                                   "im_min too small for the real-axis singularities)")
            v = dispersion_core(z, self.q, self.p)
            if v == 0:
                raise RootOnContour(f"F = 0 at the sample z = {mp.nstr(z, 15)}")
            self.values[z] = v
        return v

    def _horizontal_nodes(self, y: mpmath.mpf) -> list[mpmath.mpf]:
        """The lattice plus the nodes graded around the real-axis singularities at scale y (sorted)."""
        nodes = self.h_nodes.get(y)
        if nodes is None:
            extra = []
            sing = self.singular
            for k, s in enumerate(sing):
                gap = min([self.cap] + [abs(s - sing[j]) / 2 for j in (k - 1, k + 1) if 0 <= j < len(sing)])
                extra.append(s)
                d = y
                while d <= gap:
                    extra += [s - d, s + d]
                    d *= GRADING
            nodes = sorted(set(self.xs) | {x for x in extra if self.xs[0] < x < self.xs[-1]})
            self.h_nodes[y] = nodes
        return nodes

    def _segment(self, za: mpmath.mpc, zb: mpmath.mpc) -> tuple[mpmath.mpc, mpmath.mpc]:
        """(increment of log F, sum of z dlog F) from za to zb, adaptively (see the class docstring)."""
        key = (za, zb)
        hit = self.segments.get(key)
        if hit is not None:
            return hit
        total_l, total_m = mp.mpc(0), mp.mpc(0)
        stack = [(za, self.F(za), zb, self.F(zb))]
        while stack:
            a, fa, b, fb = stack.pop()
            m = (a + b) / 2
            fm = self.F(m)
            l1, l2 = mp.log(fm / fa), mp.log(fb / fm)
            s = l1 + l2
            if abs(mp.im(s)) <= ARG_STEP and abs(mp.re(s)) <= LOG_MOD_STEP and abs(l1 - l2) <= CURVATURE_TOL:
                total_l += s
                total_m += (a + m) / 2 * l1 + (m + b) / 2 * l2
                continue
            if abs(b - a) < self.h_min:
                raise RootOnContour(f"a root lies on (or next to) the line near {mp.nstr(a, 15)}: a segment is still "
                                    f"unresolved at length {mp.nstr(abs(b - a), 3)} < {mp.nstr(self.h_min, 3)}")
            stack.append((m, fm, b, fb))
            stack.append((a, fa, m, fm))
        self.segments[key] = (total_l, total_m)
        return total_l, total_m

    def line(self, horizontal: bool, c: mpmath.mpf, t0: mpmath.mpf, t1: mpmath.mpf) -> tuple[mpmath.mpc, mpmath.mpc]:
        """(increment of log F, sum of z dlog F) along the line Im z = c (horizontal) or Re z = c from
        coordinate t0 to t1 > t0."""
        key = (horizontal, c, t0, t1)
        hit = self.lines.get(key)
        if hit is not None:
            return hit
        nodes = self._horizontal_nodes(c) if horizontal else self.ys
        i, j = bisect.bisect_right(nodes, t0), bisect.bisect_left(nodes, t1)
        ts = [t0, *nodes[i:j], t1]
        pts = [mp.mpc(t, c) if horizontal else mp.mpc(c, t) for t in ts]
        total_l, total_m = mp.mpc(0), mp.mpc(0)
        for za, zb in zip(pts[:-1], pts[1:], strict=True):
            dl, dm = self._segment(za, zb)
            total_l += dl
            total_m += dm
        self.lines[key] = (total_l, total_m)
        return total_l, total_m

    def count(self, cell: tuple[mpmath.mpf, ...]) -> tuple[int, mpmath.mpc]:
        """(number of roots in the closed cell, estimate of their sum (1/2 pi i) contour integral of z dlog F)."""
        x0, x1, y0, y1 = cell
        self.evals = 0
        lb, mb = self.line(True, y0, x0, x1)
        lr, mr = self.line(False, x1, y0, y1)
        lt, mt = self.line(True, y1, x0, x1)
        ll, ml = self.line(False, x0, y0, y1)
        total = lb + lr - lt - ll
        w = mp.im(total) / (2 * mp.pi)
        n = int(mp.nint(w))
        if abs(w - n) > INTEGER_TOL or abs(mp.re(total)) > INTEGER_TOL or n < 0:
            raise RuntimeError(f"winding number {mp.nstr(w, 12)} (ln|F| mismatch {mp.nstr(mp.re(total), 3)}) is not "
                               f"a non-negative integer on [{mp.nstr(x0, 10)}, {mp.nstr(x1, 10)}] x "
                               f"[{mp.nstr(y0, 10)}, {mp.nstr(y1, 10)}]")
        return n, (mb + mr - mt - ml) / (2 * mp.pi * mp.j)


def _window(x0: Num, x1: Num, y0: Num, y1: Num) -> tuple[mpmath.mpf, ...]:
    """The rectangle as mpf's at the ambient precision; ValueError unless x0 < x1 and 0 < y0 < y1."""
    w = tuple(mp.mpf(_num(v)) for v in (x0, x1, y0, y1))
    if not (w[0] < w[1] and 0 < w[2] < w[3]) or not all(mp.isfinite(v) for v in w):
        raise ValueError(f"need x0 < x1 and 0 < y0 < y1 (finite); got {w}")
    return w


def count_roots(q: Num, gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0, *, x0: Num, x1: Num,
                y0: Num, y1: Num, dps: int = ROOT_DPS) -> int:
    """Number of roots of F(z; q) (docs/physics.md §3), with multiplicity, in the closed rectangle
    [x0, x1] x [y0, y1] (x0 < x1, 0 < y0 < y1), by the argument principle at `dps` digits (no pole correction: F is
    analytic in Im z > 0). Sampling and acceptance tests: see _Contour.

    Raises RuntimeError (never guesses) if a root lies on the boundary (RootOnContour), if one count needs more than
    MAX_EVALS evaluations of F, or if the winding number is not within INTEGER_TOL of an integer."""
    with mp.workdps(dps):
        window = _window(x0, x1, y0, y1)
        contour = _Contour(q, Params.make(gamma, f, beta, eta, Delta, xi), window)
        return contour.count(window)[0]


def _dispersion_scale(z: mpmath.mpc, q: mpmath.mpf, p: Params) -> mpmath.mpf:
    """The size of F's terms at z, gamma (|G_x| + |f G_y|) + |z S|: |F|/scale is a root's relative residual."""
    g_x, g_y = response_functions_core(z, q, p.b, p.eta)
    fric = 1 + (p.Delta - 1) / (1 - mp.j * p.xi * z * q)
    return p.gamma * (abs(g_x) + abs(p.f * g_y)) + abs(z * fric)


def _inside(z: mpmath.mpc, cell: tuple[mpmath.mpf, ...], margin: mpmath.mpf) -> bool:
    x0, x1, y0, y1 = cell
    return bool(x0 - margin <= mp.re(z) <= x1 + margin and y0 - margin <= mp.im(z) <= y1 + margin)


def _newton_in_cell(contour: _Contour, cell: tuple[mpmath.mpf, ...], guess: mpmath.mpc) -> mpmath.mpc | None:
    """The root in a one-root cell by the secant method from the contour estimate `guess` (if inside the cell) or
    from the cell's centre; accepted only if it converges inside the cell enlarged by 1e-9 of its size with
    |F| <= 10^(6 - dps) x scale. None if neither start gives such a root."""
    x0, x1, y0, y1 = cell
    size = max(x1 - x0, y1 - y0)
    margin = mp.mpf("1e-9") * size
    centre = mp.mpc((x0 + x1) / 2, (y0 + y1) / 2)
    starts = ([guess] if _inside(guess, cell, 0) else []) + [centre]
    tol = mp.mpf(10) ** (6 - mp.dps)
    for z0 in starts:
        d = mp.mpf("1e-4") * size
        try:
            z = mp.findroot(lambda w: dispersion_core(w, contour.q, contour.p), (z0, z0 + d * (1 + 1j)),
                            solver="secant", maxsteps=60)
        except (ValueError, ZeroDivisionError):
            continue
        z = mp.mpc(z)
        if mp.im(z) > 0 and _inside(z, cell, margin):
            if abs(dispersion_core(z, contour.q, contour.p)) <= tol * _dispersion_scale(z, contour.q, contour.p):
                return z
    return None


def _polish_root(contour: _Contour, z: mpmath.mpc, cell: tuple[mpmath.mpf, ...]) -> mpmath.mpc:
    """z refined by the secant method at POLISH_DPS + 10 digits and rounded to POLISH_DPS; RuntimeError if it moves
    by more than 1e-10 |z| or leaves the (enlarged) cell."""
    with mp.workdps(POLISH_DPS + 10):
        d = mp.mpf("1e-12") * max(abs(z), mp.mpf("1e-3"))
        try:
            zp = mp.mpc(mp.findroot(lambda w: dispersion_core(w, contour.q, contour.p), (z, z + d), solver="secant"))
        except (ValueError, ZeroDivisionError) as exc:
            raise RuntimeError(f"polishing the root {mp.nstr(z, 15)} failed: {exc}") from exc
        margin = mp.mpf("1e-9") * max(cell[1] - cell[0], cell[3] - cell[2])
        if abs(zp - z) > mp.mpf("1e-10") * max(abs(z), mp.mpf("1e-3")) or not _inside(zp, cell, margin):
            raise RuntimeError(f"polishing moved the root {mp.nstr(z, 15)} to {mp.nstr(zp, 15)}")
    with mp.workdps(POLISH_DPS):
        return +zp


def _split(contour: _Contour, cell: tuple[mpmath.mpf, ...], n: int) -> list[tuple[tuple[mpmath.mpf, ...], int]]:
    """The cell's two halves with their counts. The longer side is halved: at the lattice node (vertical edges'
    node, for a horizontal line) nearest the middle, the middle being the geometric mean sqrt(y0 y1) for cells reaching
    down towards the real axis (y1 > 4 y0), else at the exact middle; another position is tried when a root lies on
    the line. RuntimeError if the halves' counts do not add up to n."""
    x0, x1, y0, y1 = cell
    vertical_cut = x1 - x0 >= y1 - y0
    lo, hi = (x0, x1) if vertical_cut else (y0, y1)
    nodes = contour.xs if vertical_cut else contour.ys
    inner = nodes[bisect.bisect_right(nodes, lo):bisect.bisect_left(nodes, hi)]
    if vertical_cut or y1 <= 4 * y0:
        mid = (lo + hi) / 2
        cands = sorted(inner, key=lambda t: abs(t - mid))[:4]
    else:
        mid = mp.sqrt(y0 * y1)
        cands = sorted(inner, key=lambda t: abs(mp.log(t / mid)))[:4]
    cands += [lo + (hi - lo) * frac for frac in (mp.mpf(1) / 2, mp.mpf(3) / 8, mp.mpf(5) / 8, mp.mpf(7) / 16)]
    for t in cands:
        halves = [(x0, t, y0, y1), (t, x1, y0, y1)] if vertical_cut else [(x0, x1, y0, t), (x0, x1, t, y1)]
        try:
            counts = [contour.count(h)[0] for h in halves]
        except RootOnContour:
            continue
        if sum(counts) != n:
            raise RuntimeError(f"the halves of a cell hold {counts} roots, the cell {n}")
        return list(zip(halves, counts, strict=True))
    raise RuntimeError(f"every splitting line of the cell {cell} passes through a root")


def _isolate(contour: _Contour, window: tuple[mpmath.mpf, ...], n_total: int,
             est: mpmath.mpc) -> list[tuple[mpmath.mpc, tuple[mpmath.mpf, ...]]]:
    """(root at the ambient precision, its cell) for every root of the window, which holds n_total (see
    roots_in_rectangle)."""
    smallest = CELL_MIN_REL * contour.size
    found: list[tuple[mpmath.mpc, tuple[mpmath.mpf, ...]]] = []
    stack = [(window, n_total, est)]
    while stack:
        cell, n, est = stack.pop()
        if n == 1:
            z = _newton_in_cell(contour, cell, est)
            if z is not None:
                found.append((z, cell))
                continue
        if max(cell[1] - cell[0], cell[3] - cell[2]) < smallest:
            raise RuntimeError(f"{n} root(s) in a cell of size {mp.nstr(cell[1] - cell[0], 3)} near "
                               f"{mp.nstr(mp.mpc(cell[0], cell[2]), 15)} cannot be separated or located "
                               "(a multiple root?)")
        stack += [(half, m, contour.count(half)[1]) for half, m in _split(contour, cell, n) if m]
    return found


def roots_in_rectangle(q: Num, gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0, *, x0: Num,
                       x1: Num, y0: Num, y1: Num, dps: int = ROOT_DPS) -> list[mpmath.mpc]:
    """Every root of F(z; q) in the closed rectangle [x0, x1] x [y0, y1] (0 < y0 < y1), sorted by decreasing Im z,
    POLISH_DPS digits each.

    The rectangle is counted (count_roots) and bisected recursively (_split; the halves reuse the parent's samples)
    until each cell holds one root; that root is found by the secant method from the contour estimate
    (1/2 pi i) contour integral of z dlog F (or the cell's centre), accepted only inside the cell (enlarged by 1e-9 of
    its size) with a tiny relative residual, else the cell is split further; finally it is polished to POLISH_DPS
    digits. The number returned always equals the count of the whole rectangle; RuntimeError otherwise (including
    a root on the boundary, a multiple root or an unresolvable cluster)."""
    with mp.workdps(dps):
        window = _window(x0, x1, y0, y1)
        contour = _Contour(q, Params.make(gamma, f, beta, eta, Delta, xi), window)
        n_total, est = contour.count(window)
        found = _isolate(contour, window, n_total, est) if n_total else []
        roots = [_polish_root(contour, z, cell) for z, cell in found]
    roots.sort(key=lambda z: (-mp.im(z), mp.re(z)))
    for k, a in enumerate(roots):
        if any(abs(a - b) <= mp.mpf("1e-12") * max(abs(a), mp.mpf("1e-3")) for b in roots[k + 1:]):
            raise RuntimeError(f"the root {mp.nstr(a, 15)} was found in two cells")
    if len(roots) != n_total:
        raise RuntimeError(f"located {len(roots)} roots, counted {n_total}")
    return roots


def fastest_root(q: Num, gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0, *, re_max: Num,
                 im_min: Num, im_max: Num, dps: int = ROOT_DPS) -> tuple[mpmath.mpc | None, int]:
    """(the root of largest Im z, the number of roots) in [-re_max, re_max] x [im_min, im_max]; (None, 0) if none.
    From roots_in_rectangle."""
    with mp.workdps(dps):
        rm = mp.mpf(_num(re_max))
    roots = roots_in_rectangle(q, gamma, f, beta, eta, Delta, xi, x0=-rm, x1=rm, y0=im_min, y1=im_max, dps=dps)
    return (roots[0] if roots else None), len(roots)


def _geometric(a: mpmath.mpf, b: mpmath.mpf, m: int) -> list[mpmath.mpf]:
    """m points from a to b > a > 0 in geometric progression (both ends included)."""
    if m == 1:
        return [a]
    return [a * (b / a) ** (mp.mpf(k) / (m - 1)) for k in range(m)]


def exterior_points(re_max: Num, im_min: Num, im_max: Num, n: int = 400, factor: Num = 8) -> list[mpmath.mpc]:
    """About n points on rays outside the window [-re_max, re_max] x [im_min, im_max] (ambient precision), each ray
    sampled geometrically from the window outwards by `factor`:
    * horizontal rays (half the points, a third of those at Im z = im_min exactly, the tightest height) at heights
      im_min, ..., im_max (geometric), from |Re z| = re_max to factor re_max, on both sides;
    * vertical rays (a quarter) at Re z = -re_max, -re_max/2, 0, re_max/2, re_max from im_max to factor im_max;
    * radial rays (a quarter) at angles in (0, pi), from where they leave the window (beyond its corners for angles
      near the diagonals) out to factor times that radius."""
    rm, lo, hi, fac = (mp.mpf(_num(v)) for v in (re_max, im_min, im_max, factor))
    pts: list[mpmath.mpc] = []
    n_h = n // 2
    m_bottom = max(2, n_h // 6)  # per side at Im z = im_min
    heights = _geometric(lo, hi, 6)[1:]
    m_h = max(2, (n_h - 2 * m_bottom) // (2 * len(heights)))
    for y, m in [(lo, m_bottom)] + [(y, m_h) for y in heights]:
        for x in _geometric(rm, fac * rm, m):
            pts += [mp.mpc(x, y), mp.mpc(-x, y)]
    xs_v = [-rm, -rm / 2, mp.mpf(0), rm / 2, rm]
    m_v = max(2, (n // 4) // len(xs_v))
    for x in xs_v:
        pts += [mp.mpc(x, y) for y in _geometric(hi, fac * hi, m_v)]
    n_ang = 10
    m_r = max(2, (n - len(pts)) // n_ang)
    for k in range(n_ang):
        theta = mp.pi * (k + mp.mpf(1) / 2) / n_ang
        c, s = mp.cos(theta), mp.sin(theta)
        r0 = min(rm / abs(c), hi / s)
        pts += [r * mp.expj(theta) for r in _geometric(r0, fac * r0, m_r)]
    return pts


def exterior_min_margin(q: Num, gamma: Num, f: Num, beta: Num, eta: Num, Delta: Num = 1, xi: Num = 0, *,
                        re_max: Num, im_min: Num, im_max: Num, n: int = 400, factor: Num = 8,
                        dps: int = ROOT_DPS) -> float:
    """min over exterior_points(re_max, im_min, im_max, n, factor) of Re(F(z)/(i z)), at `dps` digits.

    A positive value is consistent with the theorem that Re(F/(i z)) > 0 (hence F != 0) outside the window."""
    with mp.workdps(dps):
        p = Params.make(gamma, f, beta, eta, Delta, xi)
        qq = mp.mpf(_num(q))
        return float(min(mp.re(dispersion_core(z, qq, p) / (mp.j * z))
                         for z in exterior_points(re_max, im_min, im_max, n, factor)))


__all__: Sequence[str] = [
    "B",
    "neutral_curvature",
    "neutral_mode",
    "BranchLost",
    "C",
    "DPS",
    "RootOnContour",
    "count_roots",
    "exterior_min_margin",
    "exterior_points",
    "fastest_root",
    "roots_in_rectangle",
    "PrecisionError",
    "branch_tangent",
    "criterion_min_gy",
    "dispersion",
    "dispersion_dz",
    "effective_moduli",
    "linear_expansion",
    "mu_eff_minimum",
    "mu_eff_minus_one",
    "normal_stress_change",
    "one_minus_B",
    "rayleigh_branch",
    "rayleigh_branch_max_growth",
    "rayleigh_branch_stats",
    "rayleigh_speed",
    "response_functions",
    "response_functions_tanh",
    "thin_on_thick_quasistatic_gy",
    "thin_on_thick_response",
]
