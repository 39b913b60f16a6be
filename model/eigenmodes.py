"""Every mode at once: the linear problem of Sect. S-II and S-III as one eigenvalue problem (docs/physics.md §15).

A second solver of the linear stability problem, independent of the closed-form response functions: the Navier
equations (Eq. S-LE) are discretised across the thickness of both blocks by Chebyshev collocation, the boundary
conditions of the paper (Eq. S-SBC at the far boundaries; at the interface continuous tractions and u_y, and the
linearised rate-and-state friction law, Eq. S-fric_law with Eq. S-delta f RSF_SM, the state variable an unknown of its
own) are rows of the same linear system, and the frequency omega = kH z at fixed kH is the eigenvalue of a
polynomial eigenvalue problem, linearised and solved with :func:`scipy.linalg.eigvals`. It returns every mode of
the discretisation; two resolutions tell the converged eigenvalues from the unresolved ones.

This module uses numpy, scipy.linalg and :mod:`model._validate` only: nothing of the closed-form response
functions G_x, G_y (Eq. S-G_gen), of the dispersion function F (Eq. implicit_spectrum) or of the compiled kernels.
That independence is its purpose: it cross-validates the contour-integral root finder
(:func:`model.unstable_modes`) on the elastodynamic equations themselves.

Units and fields
----------------
Lengths in H (the upper block's height), speeds in c_s, stresses in mu, rho = 1; so lambda + 2 mu = 1/beta^2,
lambda = 1/beta^2 - 2. Perturbations go as exp(i (q x - omega t)) with q = kH and omega = q z (z = c/c_s; Im z > 0:
the mode grows). The upper block (1) is 0 < y < 1, the lower block (2) -eta < y < 0.

Discretisation
--------------
*Bulk.* In each block, u_x and u_y on the N + 1 Chebyshev-Gauss-Lobatto points y_k (k = 0..N), d/dy by the
Chebyshev differentiation matrix D. Eq. S-LE with d/dx -> i q, d/dt -> -i omega reads, at every interior point,

    D^2 u_x - q^2 u_x / beta^2 + i q (1/beta^2 - 1) D u_y + omega^2 u_x = 0
    D^2 u_y / beta^2 - q^2 u_y + i q (1/beta^2 - 1) D u_x + omega^2 u_y = 0

with sigma_xy = D u_x + i q u_y, sigma_yy = i q (1/beta^2 - 2) u_x + D u_y / beta^2.

*Boundary rows* (the equations at the 8 end points are replaced):

- far boundaries y = 1 and y = -eta (Eq. S-SBC): d_t u_x = -i omega u_x = 0, i.e. u_x = 0 (omega != 0), and
  sigma_yy = 0;
- interface y = 0: u_y^(1) = u_y^(2) (no opening), sigma_xy^(1) = sigma_xy^(2), sigma_yy^(1) = sigma_yy^(2);
- the slip eps = u_x^(1) - u_x^(2) (Eq. epsilon) and the linearised friction law (Eq. S-fric_law:
  delta sigma_xy + f delta sigma_yy = sigma_0 delta f, delta f = d_v f [delta v + (1 - Delta) theta]) divided by mu:
  gamma (sigma_xy + f sigma_yy) + i omega eps - (1 - Delta) theta = 0, with the slip rate delta v = -i omega eps;
- the state variable theta = (v^2/D) delta phi (a velocity) is one more unknown; the linearised evolution law of
  Sect. S-III, -i c k delta phi = g'(1) (v/D delta phi + delta v / v), reads theta (1 - i xi omega) = i omega eps.
  Eliminated, it gives delta f = d_v f delta v S with S = 1 + (Delta - 1)/(1 - i xi z q), Eq. S-delta f RSF_SM.
  Where theta does not act (Delta = 1) or follows the slip rate at once (xi = 0: theta = i omega eps), it is
  eliminated and not an unknown.

*Eigenvalue problem.* The seven rows that do not contain omega (far boundaries, continuity) are solved for seven of
the eight end values, in terms of the interior values and eps: the end values are eliminated ("boundary
bordering"). What remains is (K + omega C + omega^2 M) x = 0 for x = (interior values, eps[, theta]) with M = I
on the interior values, C nonzero only in the friction and state rows. With w = omega x_interior it is the standard
eigenvalue problem T v = omega v of v = (x, w): omega x_int = w, omega w = -K_int x, and the friction and state
rows solved for omega eps and omega theta (their omega-coefficient matrix [[i, 0], [-i, -i xi]] is invertible for
xi > 0). T has no infinite eigenvalues (eliminating the boundary rows removes them), and
:func:`scipy.linalg.eigvals` (LAPACK geev, balanced) costs 2-3x less than the QZ algorithm on the singular pencil
A x = omega B x with the boundary rows kept. Every eigenvalue of T is finite: z = omega / q.

*eta = inf.* The lower half-space is mapped to the Chebyshev interval by the rational map
y = -L (1 - x)/(1 + x) (L = HALF_SPACE_SCALE / kH), on the complex path y~ = (1 + i s) y (a complex coordinate
stretch, as in arXiv 2306.10064): the fields exp(q alpha y~) of a mode on the physical sheet decay along the path
where Re[alpha (1 + i s)] > 0, and u = 0 at the path's end (y = -inf). In the upper half-plane that holds for every
physical mode (Re alpha > 0) in Re z > 0 if s > 0, in Re z < 0 if s < 0 (Re alpha_s >= Im z and Im alpha has the
sign of -Re z, docs/physics.md §14.2), and for no mode of another sheet. So two solves, s = +HALF_SPACE_STRETCH for
Re z >= 0 and s = -HALF_SPACE_STRETCH for Re z < 0. The branch cuts of F become lines of eigenvalues along the
rotated cuts, z^2 = 1 + t^2/(1 + i s)^2 and beta^2 z^2 = 1 + ..., which lie in the lower half-plane of the half
solved; they and the leaky modes of other sheets are the eigenvalues below the real axis and are not roots of F.
A window at eta = inf must therefore lie above the real axis (im_min > 0).

Convergence rule
----------------
Each solve is done at two resolutions, (N1, N2) points in the upper and lower block and about FINE_RATIO times as
many. An eigenvalue of the finer one in the window is *converged* if the coarser has one within tol |z| and the two
are each other's nearest; it is returned with the finer value and its error estimate |z_fine - z_coarse|. The others
in the window are dropped and counted (:attr:`Eigenmodes.dropped`). Unless the caller fixes n, the coarser
resolution comes from the window (:func:`eigenmode_resolution`: the exponents q L alpha/2 of the fields exp(q alpha
y) of a mode anywhere in the window, L the block's height) and is raised by 1.5x (the finer solve reused) while
eigenvalues are dropped, up to MAX_POINTS points in all. What can be trusted: the converged eigenvalues in the
window. Eigenvalues far outside the window (|z| >> re_max) are resolved only as far as N allows: the modes whose
fields oscillate faster than about N/(2 L) across a block are not resolved at all.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from ._validate import check

__all__ = ["Eigenmodes", "ModeShape", "eigenmodes", "mode_shape", "eigenmode_resolution"]

DEFAULT_TOL = 1e-8  # agreement of the two resolutions demanded of a converged eigenvalue (relative)
TOL_RANGE = (1e-13, 1e-2)  # accepted tol
FINE_RATIO = 1.3  # points of the finer resolution / the coarser (+ FINE_EXTRA)
FINE_EXTRA = 2
RAISE_RATIO = 1.5  # while eigenvalues in the window are dropped, the resolution is raised by this factor ...
MAX_POINTS = 320  # ... as long as the finer one has at most this many points in both blocks together
MIN_POINTS = 8  # fewest Chebyshev points per block (N)
MAX_N = 2000  # largest N per block a caller may ask for
# the resolution rule (:func:`eigenmode_resolution`): N = min(|a| + OSC |a|^(1/3), sqrt(EVAN |a|^2 / Re a)) + EXTRA
# for the exponent a = q L alpha / 2 of a field exp(q alpha y) across a block of height L (docs/physics.md §15.4:
# what the benchmark measured at this rule and at 0.6 and 0.8 times it)
OSC = 8.0
EVAN = 46.0
EXTRA = 3.0
HALF_SPACE_POINTS = 64  # eta = inf: Chebyshev points on the mapped, stretched lower half-space (coarser solve)
HALF_SPACE_SCALE = 4.0  # its map scale L = HALF_SPACE_SCALE / kH (a field exp(-kH |y|) has half its points above L)
HALF_SPACE_STRETCH = 0.75  # s of the complex path y~ = (1 + i s) y
EDGE = 1e-12  # relative slack of the window when an eigenvalue lies on its edge (rounding of z = omega / q)


# ------------------------------------------------------------------------------------------------
# results
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Eigenmodes:
    """The converged eigenvalues of one kH (:func:`eigenmodes`).

    Attributes
    ----------
    z : complex ndarray, every converged eigenvalue z = c/c_s in the window, by decreasing Im z (then Re z)
    error : float ndarray, |z_fine - z_coarse| of each (an estimate of the error of the coarser value; the finer,
        returned, is more accurate)
    dropped : number of eigenvalues of the finer solve in the window that the coarser does not confirm
    n : (N1, N2), Chebyshev points (N + 1 nodes) per block of the finer solve
    n_coarse : (N1, N2) of the coarser solve
    window : (re_max, im_min, im_max)
    tol : the relative agreement demanded
    z_all : complex ndarray, every eigenvalue of the finer discretisation (unfiltered: unresolved ones included;
        at eta = inf, Re z >= 0 from the solve with s > 0 and Re z < 0 from the one with s < 0)
    """

    z: np.ndarray
    error: np.ndarray
    dropped: int
    n: tuple[int, int]
    n_coarse: tuple[int, int]
    window: tuple[float, float, float]
    tol: float
    z_all: np.ndarray

    @property
    def complete(self) -> bool:
        """True if every eigenvalue of the finer solve in the window is converged (none dropped)."""
        return self.dropped == 0


@dataclass(frozen=True)
class ModeShape:
    """The fields of one mode (:func:`mode_shape`), exp(i (kH x - kH z t)) times the arrays below.

    The displacements are scaled to max(|u_x|, |u_y|) = 1 over both blocks; stresses in units of mu (H = 1).

    Attributes
    ----------
    z : complex, the eigenvalue of the discretisation this is the eigenvector of (nearest the z asked for)
    mismatch : |z - z asked| / |z asked|
    n : (N1, N2), Chebyshev points per block
    y_upper : float ndarray, nodes of the upper block, increasing, 0 ... 1 (units of H)
    y_lower : float ndarray, nodes of the lower block, increasing, -eta ... 0 (eta = inf: the finite nodes of the
        mapped half-space, the deepest first)
    stretch : 0 for finite eta; at eta = inf the s of the complex path: the lower block's fields are given at
        y~ = (1 + i s) y_lower (their analytic continuation; the upper block and the interface are physical)
    u_x_upper, u_y_upper, sigma_xy_upper, sigma_yy_upper : complex ndarrays at y_upper
    u_x_lower, u_y_lower, sigma_xy_lower, sigma_yy_lower : complex ndarrays at y_lower
    slip : eps_x = u_x^(1)(0+) - u_x^(2)(0-) (Eq. epsilon), real and positive (this fixes the phase)
    shear_stress, normal_stress : delta sigma_xy, delta sigma_yy at the interface (units of mu)
    state : theta = (v^2/D) delta phi, the state variable's change (units of c_s, as the slip rate -i kH z eps)
    """

    z: complex
    mismatch: float
    n: tuple[int, int]
    y_upper: np.ndarray
    y_lower: np.ndarray
    stretch: float
    u_x_upper: np.ndarray
    u_y_upper: np.ndarray
    sigma_xy_upper: np.ndarray
    sigma_yy_upper: np.ndarray
    u_x_lower: np.ndarray
    u_y_lower: np.ndarray
    sigma_xy_lower: np.ndarray
    sigma_yy_lower: np.ndarray
    slip: complex
    shear_stress: complex
    normal_stress: complex
    state: complex


@dataclass(frozen=True)
class _Params:
    """One validated parameter set (q = kH)."""

    q: float
    gamma: float
    f: float
    beta: float
    eta: float
    Delta: float
    xi: float

    @property
    def has_state(self) -> bool:
        """Whether theta is an unknown (it acts, Delta < 1, and relaxes over a memory length, xi > 0)."""
        return self.Delta != 1.0 and self.xi != 0.0


# ------------------------------------------------------------------------------------------------
# the discretisation
# ------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class _Block:
    """One block on Chebyshev nodes: node k = 0 .. N, d/dy on them, and where its unknowns start."""

    N: int
    y: np.ndarray  # nodes (real parameter of the path)
    D: np.ndarray  # d/dy~ on the path (d/dy for a finite block)
    ix: int  # index of u_x at node 0 in the unknown vector (u_y follows N + 1 later)
    far: int  # node at the far boundary
    interface: int  # node at y = 0

    @property
    def iy(self) -> int:
        return self.ix + self.N + 1


def _chebyshev(N: int) -> tuple[np.ndarray, np.ndarray]:
    """Chebyshev-Gauss-Lobatto points x_k = cos(pi k / N) and the differentiation matrix (Trefethen, Spectral
    Methods in MATLAB, cheb.m; the diagonal as minus the row sums)."""
    x = np.cos(np.pi * np.arange(N + 1) / N)
    c = np.ones(N + 1)
    c[0] = c[-1] = 2.0
    c *= (-1.0) ** np.arange(N + 1)
    dx = x[:, None] - x[None, :]
    D = np.outer(c, 1.0 / c) / (dx + np.eye(N + 1))
    D -= np.diag(D.sum(axis=1))
    return x, D


def _blocks(p: _Params, n1: int, n2: int, stretch: float) -> tuple[_Block, _Block]:
    """The upper block on [0, 1] (node 0 at y = 1) and the lower one on [-eta, 0] (node 0 at y = 0), or at
    eta = inf the rational map y = -L (1 - x)/(1 + x) on the path y~ = (1 + i stretch) y (node N2 at -inf)."""
    x1, d1 = _chebyshev(n1)
    upper = _Block(n1, 0.5 * (1.0 + x1), 2.0 * d1, 0, 0, n1)
    x2, d2 = _chebyshev(n2)
    if math.isinf(p.eta):
        scale = HALF_SPACE_SCALE / p.q
        with np.errstate(divide="ignore"):
            y2 = -scale * (1.0 - x2) / (1.0 + x2)
        dydx = 2.0 * scale * (1.0 + 1j * stretch) / (1.0 + x2[:-1]) ** 2  # dy~/dx (infinite at the last node)
        D2 = np.zeros((n2 + 1, n2 + 1), dtype=complex)
        D2[:-1] = d2[:-1] / dydx[:, None]  # the row at -inf is never used: u = 0 replaces its equations
    else:
        y2 = -0.5 * p.eta * (1.0 - x2)
        D2 = (2.0 / p.eta) * d2
    lower = _Block(n2, y2, D2, 2 * (n1 + 1), n2, 0)
    return upper, lower


def _navier(block: _Block, p: _Params, K: np.ndarray) -> None:
    """Write the Navier equations (Eq. S-LE) of one block, omega^2 u moved aside, into its rows of K."""
    D = block.D
    D2 = D @ D
    eye = np.eye(block.N + 1)
    lam2 = 1.0 / p.beta**2  # lambda + 2 mu
    mix = 1j * p.q * (lam2 - 1.0)  # i q (lambda + mu)
    sx = slice(block.ix, block.ix + block.N + 1)
    sy = slice(block.iy, block.iy + block.N + 1)
    K[sx, sx] = D2 - (lam2 * p.q * p.q) * eye
    K[sx, sy] = mix * D
    K[sy, sy] = lam2 * D2 - (p.q * p.q) * eye
    K[sy, sx] = mix * D


def _row(block: _Block, size: int, kind: str, k: int, p: _Params) -> np.ndarray:
    """The row that evaluates u_x, u_y, sigma_xy or sigma_yy of `block` at node k (Eq. S-LE, mu = 1)."""
    r = np.zeros(size, dtype=complex)
    cols_x = slice(block.ix, block.ix + block.N + 1)
    cols_y = slice(block.iy, block.iy + block.N + 1)
    if kind == "ux":
        r[block.ix + k] = 1.0
    elif kind == "uy":
        r[block.iy + k] = 1.0
    elif kind == "sxy":
        r[cols_x] = block.D[k]
        r[block.iy + k] += 1j * p.q
    else:  # "syy"
        r[cols_y] = block.D[k] / p.beta**2
        r[block.ix + k] += 1j * p.q * (1.0 / p.beta**2 - 2.0)
    return r


def _end_nodes(upper: _Block, lower: _Block) -> np.ndarray:
    """Indices of the 8 end values (u_x, u_y at y = 1, at the interface on both sides, at the lower far end)."""
    return np.array(
        [
            upper.ix + upper.far,
            upper.iy + upper.far,
            upper.ix + upper.interface,
            upper.iy + upper.interface,
            lower.ix + lower.interface,
            lower.iy + lower.interface,
            lower.ix + lower.far,
            lower.iy + lower.far,
        ]
    )


def _boundary_rows(upper: _Block, lower: _Block, p: _Params, size: int) -> np.ndarray:
    """The 7 rows without omega (Eq. S-SBC at both far ends, or u = 0 at the end of a half-space; continuity of
    u_y, sigma_xy, sigma_yy at y = 0) and, last, the slip eps = u_x^(1) - u_x^(2) at y = 0 (Eq. epsilon)."""

    def row(b: _Block, kind: str, k: int) -> np.ndarray:
        return _row(b, size, kind, k, p)

    i1, i2 = upper.interface, lower.interface
    far_kind = "uy" if math.isinf(p.eta) else "syy"
    return np.array(
        [
            row(upper, "ux", upper.far),
            row(upper, "syy", upper.far),
            row(lower, "ux", lower.far),
            row(lower, far_kind, lower.far),
            row(upper, "uy", i1) - row(lower, "uy", i2),
            row(upper, "sxy", i1) - row(lower, "sxy", i2),
            row(upper, "syy", i1) - row(lower, "syy", i2),
            row(upper, "ux", i1) - row(lower, "ux", i2),
        ]
    )


def _prolongation(rows: np.ndarray, ends: np.ndarray, interior: np.ndarray) -> np.ndarray:
    """E with (all nodal values) = E (interior values, eps): the end values solved from the boundary rows."""
    m = interior.size
    rhs = np.zeros((ends.size, m + 1), dtype=complex)
    rhs[:, :m] = -rows[:, interior]
    rhs[-1, m] = 1.0  # the last row defines eps
    E = np.zeros((rows.shape[1], m + 1), dtype=complex)
    E[interior, np.arange(m)] = 1.0
    E[ends] = np.linalg.solve(rows[:, ends], rhs)
    return E


@dataclass(frozen=True)
class _System:
    """The linearised eigenvalue problem T v = omega v of one discretisation, and how to read its vectors."""

    T: np.ndarray
    E: np.ndarray  # nodal values from (interior values, eps)
    m: int  # number of interior values
    upper: _Block
    lower: _Block


def _system(p: _Params, n1: int, n2: int, stretch: float = 0.0) -> _System:
    """Assemble the bulk (Eq. S-LE), eliminate the end values (Eq. S-SBC, continuity), add friction (Eq. S-fric_law
    with Eq. S-delta f RSF_SM and the state equation) and linearise in omega (module docstring)."""
    upper, lower = _blocks(p, n1, n2, stretch)
    size = 2 * (n1 + 1) + 2 * (n2 + 1)
    K = np.zeros((size, size), dtype=complex)
    _navier(upper, p, K)
    _navier(lower, p, K)
    ends = _end_nodes(upper, lower)
    interior = np.setdiff1d(np.arange(size), ends)
    E = _prolongation(_boundary_rows(upper, lower, p, size), ends, interior)
    KE = K[interior] @ E  # the interior equations in terms of (interior values, eps)
    i1 = upper.interface
    friction = p.gamma * (_row(upper, size, "sxy", i1, p) + p.f * _row(upper, size, "syy", i1, p)) @ E
    return _System(_companion(KE, friction, p), E, interior.size, upper, lower)


def _companion(KE: np.ndarray, friction: np.ndarray, p: _Params) -> np.ndarray:
    """T of T v = omega v, v = (x_int, eps[, theta], w = omega x_int).

    Rows: omega x_int = w; omega w = -KE (x_int, eps); the friction row gamma (sigma_xy + f sigma_yy) + i omega eps
    - (1 - Delta) theta = 0 solved for omega eps; the state row theta - i xi omega theta - i omega eps = 0 for
    omega theta. Without theta (Delta = 1, or xi = 0 where theta = i omega eps) the friction row is
    gamma (sigma_xy + f sigma_yy) + i Delta' omega eps = 0 with Delta' = 1 or Delta.
    """
    m = KE.shape[0]
    extra = 2 if p.has_state else 1
    dim = 2 * m + extra
    w0 = m + extra
    T = np.zeros((dim, dim), dtype=complex)
    T[:m, w0:] = np.eye(m)
    T[w0:, : m + 1] = -KE
    if p.has_state:
        T[m, : m + 1] = 1j * friction  # omega eps = i [gamma (...) - (1 - Delta) theta]
        T[m, m + 1] = -1j * (1.0 - p.Delta)
        T[m + 1] = -T[m] / p.xi  # omega theta = (-i theta - omega eps) / xi
        T[m + 1, m + 1] -= 1j / p.xi
    else:
        T[m, : m + 1] = 1j * friction / (p.Delta if p.xi == 0.0 else 1.0)
    return T


# ------------------------------------------------------------------------------------------------
# resolution and convergence
# ------------------------------------------------------------------------------------------------


def _window_samples(window: tuple[float, float, float]) -> np.ndarray:
    """Points of the window (a 5 x 3 grid, corners included) at which the resolution rule is evaluated."""
    re_max, im_min, im_max = window
    re = np.linspace(-re_max, re_max, 5)
    im = np.linspace(im_min, im_max, 3)
    return (re[:, None] + 1j * im[None, :]).ravel()


def _points_for(a: np.ndarray) -> int:
    """Chebyshev points that resolve exp(a x) on [-1, 1] for each exponent a (the resolution rule).

    The Chebyshev coefficients of exp(a x) are 2 I_n(a) (I_n(a) = i^-n J_n(i a)): they fall off
    super-exponentially once n > |a| + O(|a|^(1/3)) (the turning point of the Bessel function), and before that
    like |exp(-n^2 / (2 a))| = exp(-n^2 Re(a) / (2 |a|^2)), which for a nearly real a (a decaying, evanescent field)
    is small sooner. The smaller of the two estimates, OSC and EVAN fitted to the eigenvalues' errors.
    """
    r = np.abs(a)
    with np.errstate(divide="ignore"):
        gaussian = np.sqrt(EVAN * r * r / np.maximum(a.real, 0.0))
    need = np.minimum(r + OSC * np.cbrt(r), gaussian) + EXTRA
    return max(MIN_POINTS, int(math.ceil(float(np.max(need)))))


def eigenmode_resolution(
    kH: float, *, beta: float, eta: float, re_max: float = 5.0, im_min: float = 1e-4, im_max: float = 2.0
) -> tuple[int, int]:
    """The coarser resolution (N1, N2) of :func:`eigenmodes` for a window: Chebyshev points per block.

    A mode z has the fields exp(kH alpha y), alpha = alpha_s = sqrt(1 - z^2) or alpha_d = sqrt(1 - beta^2 z^2)
    (Eq. S-full_sol); across a block of height L that is exp(a x) on the Chebyshev interval with a = kH L alpha / 2.
    N = min(|a| + 8 |a|^(1/3), sqrt(46 |a|^2 / Re a)) + 3, rounded up and at least 8, the largest over the two
    alphas at 15 points of the window (a 5 x 3 grid, corners included; docs/physics.md §15.4). At eta = inf the
    lower block gets HALF_SPACE_POINTS (the rational map's field does not depend on kH).

    Parameters
    ----------
    kH : float > 0
    beta, eta : as in :func:`eigenmodes`
    re_max, im_min, im_max : the window

    Returns
    -------
    (N1, N2)
    """
    z = _window_samples((re_max, im_min, im_max))
    alphas = np.concatenate([np.sqrt(1.0 - z * z), np.sqrt(1.0 - (beta * z) ** 2)])
    n1 = _points_for(0.5 * kH * alphas)
    n2 = HALF_SPACE_POINTS if math.isinf(eta) else _points_for(0.5 * kH * eta * alphas)
    return n1, n2


def _finer(n: tuple[int, int], ratio: float) -> tuple[int, int]:
    return tuple(int(math.ceil(ratio * k)) + FINE_EXTRA for k in n)  # type: ignore[return-value]


def _in_window(z: np.ndarray, window: tuple[float, float, float]) -> np.ndarray:
    """Mask of z in the closed window (with a relative slack EDGE for the rounding of omega / q)."""
    re_max, im_min, im_max = window
    s = EDGE * np.maximum(1.0, np.abs(z))
    return (np.abs(z.real) <= re_max + s) & (z.imag >= im_min - s) & (z.imag <= im_max + s)


def _converged(
    fine: np.ndarray, coarse: np.ndarray, window: tuple[float, float, float], tol: float
) -> tuple[np.ndarray, np.ndarray, int]:
    """The eigenvalues of `fine` in the window confirmed by `coarse` (mutual nearest, within tol |z|), their
    errors |z_fine - z_coarse|, and the number of the others in the window."""
    cand = fine[_in_window(fine, window)]
    if cand.size == 0:
        return cand, np.empty(0), 0
    if coarse.size == 0:
        return np.empty(0, dtype=complex), np.empty(0), int(cand.size)
    j = np.argmin(np.abs(cand[:, None] - coarse[None, :]), axis=1)
    partner = coarse[j]
    back = fine[np.argmin(np.abs(partner[:, None] - fine[None, :]), axis=1)]
    err = np.abs(cand - partner)
    ok = (err <= tol * np.abs(cand)) & (back == cand)
    order = np.lexsort((cand[ok].real, -cand[ok].imag))
    return cand[ok][order], err[ok][order], int(np.count_nonzero(~ok))


def _eigenvalues(p: _Params, n: tuple[int, int]) -> np.ndarray:
    """Every eigenvalue z = omega / q of the discretisation with n = (N1, N2) points (eta = inf: the solve with
    s > 0 for Re z >= 0 and the one with s < 0 for Re z < 0)."""
    if not math.isinf(p.eta):
        return scipy.linalg.eigvals(_system(p, *n).T, overwrite_a=True, check_finite=False) / p.q
    halves = []
    for sign in (1.0, -1.0):
        z = (
            scipy.linalg.eigvals(_system(p, *n, sign * HALF_SPACE_STRETCH).T, overwrite_a=True, check_finite=False)
            / p.q
        )
        halves.append(z[(z.real >= 0.0) if sign > 0 else (z.real < 0.0)])
    return np.concatenate(halves)


# ------------------------------------------------------------------------------------------------
# validation
# ------------------------------------------------------------------------------------------------


def _params(kH, gamma, f, beta, eta, Delta, xi) -> _Params:
    """Validate the physical parameters (scalars; ValueError naming the parameter and its range)."""
    physical = (("kH", kH), ("gamma", gamma), ("f", f), ("beta", beta), ("eta", eta), ("Delta", Delta), ("xi", xi))
    for name, v in physical:
        if np.ndim(v) != 0:
            raise ValueError(f"{name} must be a scalar here; got an array of shape {np.shape(v)}")
    return _Params(*(float(check(name, v)) for name, v in physical))


def _real(name: str, v) -> float:
    if isinstance(v, (str, bytes, bool, complex, np.complexfloating)) or np.ndim(v) != 0:
        raise ValueError(f"{name} must be a finite real number; got {v!r}")
    try:
        x = float(v)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a finite real number; got {v!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"{name} must be a finite real number; got {v!r}")
    return x


def _window(re_max, im_min, im_max, eta: float) -> tuple[float, float, float]:
    """Validate the window (re_max > 0, im_min < im_max; im_min > 0 at eta = inf)."""
    re_m, im_lo, im_hi = _real("re_max", re_max), _real("im_min", im_min), _real("im_max", im_max)
    if re_m <= 0:
        raise ValueError(f"re_max must be > 0; got {re_m!r}")
    if im_hi <= im_lo:
        raise ValueError(f"im_max must be > im_min = {im_lo!r}; got {im_hi!r}")
    if math.isinf(eta) and im_lo <= 0:
        raise ValueError(
            f"im_min must be > 0 at eta = inf (the stretched half-space holds the physical modes "
            f"above the real axis only); got {im_lo!r}"
        )
    return re_m, im_lo, im_hi


def _tol(tol) -> float:
    lo, hi = TOL_RANGE
    x = _real("tol", tol)
    if not lo <= x <= hi:
        raise ValueError(f"tol must be in [{lo:g}, {hi:g}]; got {tol!r}")
    return x


def _resolution_arg(n) -> tuple[int, int] | None:
    """n: None (chosen by the window), an int N for both blocks, or (N1, N2); each in [MIN_POINTS, MAX_N]."""
    if n is None:
        return None
    pair = (n, n) if np.ndim(n) == 0 else n
    text = f"n must be None, an integer or a pair of integers in [{MIN_POINTS}, {MAX_N}]; got {n!r}"
    if isinstance(pair, (str, bytes)) or len(pair) != 2:
        raise ValueError(text)
    out = []
    for k in pair:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not MIN_POINTS <= int(k) <= MAX_N:
            raise ValueError(text)
        out.append(int(k))
    return out[0], out[1]


# ------------------------------------------------------------------------------------------------
# public API
# ------------------------------------------------------------------------------------------------


def eigenmodes(
    kH, *, gamma, f, beta, eta, Delta=1.0, xi=0.0, n=None, tol=DEFAULT_TOL, re_max=5.0, im_min=1e-4, im_max=2.0
) -> Eigenmodes:
    """Every eigenvalue z = c/c_s of the linear problem at one kH that two resolutions agree on, in a window.

    The Navier equations (Eq. S-LE) in both blocks on Chebyshev points, the far boundaries loaded as in Eq. S-SBC,
    the interface with continuous tractions and u_y and the linearised friction law (Eq. S-fric_law with
    Eq. S-delta f RSF_SM; the slip of Eq. epsilon; the state variable an unknown) make one polynomial eigenvalue
    problem in omega = kH z, linearised and solved at once (module docstring; docs/physics.md §15). Its roots are
    those of Eq. implicit_spectrum with the response functions of Eq. S-G_gen, which this function never
    evaluates.

    Parameters
    ----------
    kH : float > 0 (a scalar)
    gamma, f, beta, eta, Delta, xi : the physical parameters (docs/physics.md §1), scalars; eta = math.inf is the
        half-space below (a stretched, mapped domain; the window must then have im_min > 0)
    n : None (the resolution chosen by the window, :func:`eigenmode_resolution`, and raised while eigenvalues are
        dropped), an int N or a pair (N1, N2): the coarser resolution, Chebyshev points per block, used as given
    tol : relative agreement of the two resolutions for a converged eigenvalue, in [1e-13, 1e-2]
    re_max, im_min, im_max : the closed window |Re z| <= re_max, im_min <= Im z <= im_max where convergence is
        demanded and eigenvalues returned (im_min may be negative for finite eta: damped modes)

    Returns
    -------
    Eigenmodes
        ``z`` (sorted by decreasing Im z), their ``error``, ``dropped`` (unconverged in the window; 0: none missed
        within the resolution, :attr:`Eigenmodes.complete`), the resolutions ``n``, ``n_coarse``, ``z_all``.

    Raises
    ------
    ValueError
        For a parameter outside its domain (naming it and its range), an array, a bad window, tol or n.

    Notes
    -----
    The finer eigenvalue is returned: with spectral convergence its error is far below ``error``. Eigenvalues
    far outside the window are not checked; a mode whose fields oscillate faster than about N/(2 L) across a block
    of height L is not resolved (N grows like kH (1 + eta) |z|: docs/physics.md §15 gives the cost).

    References
    ----------
    Aldam et al., Phys. Rev. X 6, 041023 (2016), Sect. S-I to S-III; Trefethen, Spectral Methods in MATLAB
    (SIAM, 2000), ch. 6-7; Adamou and Craster, J. Acoust. Soc. Am. 116, 1524 (2004); Kiefer et al.,
    arXiv:2306.10064 (2023) for the half-space on a complex path.
    """
    p = _params(kH, gamma, f, beta, eta, Delta, xi)
    window = _window(re_max, im_min, im_max, p.eta)
    tol = _tol(tol)
    fixed = _resolution_arg(n)
    coarse_n = fixed or eigenmode_resolution(
        p.q, beta=p.beta, eta=p.eta, re_max=window[0], im_min=window[1], im_max=window[2]
    )
    fine_n = _finer(coarse_n, FINE_RATIO)
    coarse, fine = _eigenvalues(p, coarse_n), _eigenvalues(p, fine_n)
    z, err, dropped = _converged(fine, coarse, window, tol)
    while dropped and fixed is None and sum(_finer(fine_n, RAISE_RATIO)) <= MAX_POINTS:
        coarse_n, fine_n = fine_n, _finer(fine_n, RAISE_RATIO)
        coarse, fine = fine, _eigenvalues(p, fine_n)
        z, err, dropped = _converged(fine, coarse, window, tol)
    return Eigenmodes(z, err, dropped, fine_n, coarse_n, window, tol, fine)


def _inverse_iteration(T: np.ndarray, omega: complex, steps: int = 3) -> np.ndarray:
    """The eigenvector of T for its eigenvalue omega (inverse iteration from a fixed start, shift nudged off
    the eigenvalue so that the LU factors stay finite)."""
    shift = omega * (1.0 + 1e-13) + 1e-14
    lu = scipy.linalg.lu_factor(T - shift * np.eye(T.shape[0]), check_finite=False)
    v = np.cos(np.arange(T.shape[0]) + 0.5) + 0.3j  # deterministic, with no special structure
    for _ in range(steps):
        v = scipy.linalg.lu_solve(lu, v, check_finite=False)
        v /= np.linalg.norm(v)
    return v


def _fields(block: _Block, x: np.ndarray, p: _Params, size: int) -> tuple[np.ndarray, ...]:
    """u_x, u_y, sigma_xy, sigma_yy of one block from the nodal values x."""
    ux = x[block.ix : block.ix + block.N + 1]
    uy = x[block.iy : block.iy + block.N + 1]
    sxy = block.D @ ux + 1j * p.q * uy
    syy = block.D @ uy / p.beta**2 + 1j * p.q * (1.0 / p.beta**2 - 2.0) * ux
    return ux, uy, sxy, syy


def mode_shape(kH, z, *, gamma, f, beta, eta, Delta=1.0, xi=0.0, n=None) -> ModeShape:
    """The fields of one mode: the eigenvector of the discretisation's eigenvalue nearest z.

    The problem is that of :func:`eigenmodes` (Eq. S-LE in both blocks, Eq. S-SBC, continuity and Eq. S-fric_law at
    the interface), at the resolution :func:`eigenmode_resolution` gives for a window just holding z (or n). The
    eigenvector is found by inverse iteration; the end values come from the boundary rows, so the fields satisfy them to
    rounding, and the stresses are sigma_xy = d_y u_x + i kH u_y, sigma_yy = i kH (1/beta^2 - 2) u_x +
    d_y u_y / beta^2 (units of mu).

    Parameters
    ----------
    kH : float > 0
    z : complex, the eigenvalue wanted (e.g. from :func:`eigenmodes` or :func:`model.unstable_modes`)
    gamma, f, beta, eta, Delta, xi : as in :func:`eigenmodes`
    n : None, an int or a pair (N1, N2), Chebyshev points per block

    Returns
    -------
    ModeShape
        The fields against y in both blocks, the slip (real positive: the phase), the interface tractions and
        the state variable, normalised to max |u| = 1; ``z`` the eigenvalue used and ``mismatch`` its distance to
        the z asked (relative): a large one means the mode asked for is not an eigenvalue at this resolution.

    Raises
    ------
    ValueError
        For a parameter outside its domain, a non-finite z, or a bad n.

    Notes
    -----
    At eta = inf the lower block is the stretched half-space of :func:`eigenmodes` (s > 0 for Re z >= 0, s < 0
    for Re z < 0): its fields are those at the complex depth (1 + i s) y (``ModeShape.stretch``).

    References
    ----------
    Aldam et al., Phys. Rev. X 6, 041023 (2016), Eq. S-LE, Eq. S-SBC, Eq. S-full_sol, Eq. epsilon, Eq. S-fric_law,
    Eq. S-delta f RSF_SM.
    """
    p = _params(kH, gamma, f, beta, eta, Delta, xi)
    z0 = complex(check("z", z, complex_ok=True))
    if np.ndim(z) != 0:
        raise ValueError(f"z must be a scalar; got an array of shape {np.shape(z)}")
    fixed = _resolution_arg(n)
    r = abs(z0.real) * 1.05 + 0.1
    im = abs(z0.imag) * 1.05 + 0.1
    nn = fixed or _finer(eigenmode_resolution(p.q, beta=p.beta, eta=p.eta, re_max=r, im_min=-im, im_max=im), FINE_RATIO)
    stretch = math.copysign(HALF_SPACE_STRETCH, z0.real) if math.isinf(p.eta) else 0.0
    sys_ = _system(p, *nn, stretch)
    omegas = scipy.linalg.eigvals(sys_.T, check_finite=False)
    omega = omegas[np.argmin(np.abs(omegas - p.q * z0))]
    v = _inverse_iteration(sys_.T, omega)
    return _shape(p, sys_, v, omega, z0, nn, stretch)


def _shape(
    p: _Params, s: _System, v: np.ndarray, omega: complex, z0: complex, nn: tuple[int, int], stretch: float
) -> ModeShape:
    """The normalised fields of the eigenvector v of T (eigenvalue omega)."""
    m = s.m
    eps = v[m]
    theta = v[m + 1] if p.has_state else 1j * omega * eps / (1.0 - 1j * p.xi * omega)
    x = s.E @ v[: m + 1]
    size = x.size
    up = _fields(s.upper, x, p, size)
    lo = _fields(s.lower, x, p, size)
    keep = slice(None) if not math.isinf(p.eta) else slice(0, s.lower.N)  # the node at -inf (u = 0) left out
    umax = max(np.max(np.abs(np.concatenate([up[0], up[1]]))), np.max(np.abs(np.concatenate([lo[0], lo[1]]))))
    scale = (abs(eps) / eps if eps != 0 else 1.0) / umax
    i1 = s.upper.interface
    z = complex(omega / p.q)
    return ModeShape(
        z=z,
        mismatch=abs(z - z0) / abs(z0) if z0 != 0 else abs(z),
        n=nn,
        y_upper=s.upper.y[::-1].copy(),
        y_lower=s.lower.y[keep][::-1].copy(),
        stretch=stretch,
        u_x_upper=scale * up[0][::-1],
        u_y_upper=scale * up[1][::-1],
        sigma_xy_upper=scale * up[2][::-1],
        sigma_yy_upper=scale * up[3][::-1],
        u_x_lower=scale * lo[0][keep][::-1],
        u_y_lower=scale * lo[1][keep][::-1],
        sigma_xy_lower=scale * lo[2][keep][::-1],
        sigma_yy_lower=scale * lo[3][keep][::-1],
        slip=complex(scale * eps),
        shear_stress=complex(scale * up[2][i1]),
        normal_stress=complex(scale * up[3][i1]),
        state=complex(scale * theta),
    )
