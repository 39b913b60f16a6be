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
(Families with more than 20000 poles in range get no graded nodes and rely on the refinement alone.)

*Locating.* The rectangle is split recursively (a vertical line at mid-width, or for a tall cell a horizontal
line at mid-height, geometric mean height near the axis); the samples of the parent's edges are reused, only
the new splitting line is sampled (its end values give the corners on the edges it meets). A cell holding
exactly one root is solved by Newton's method with the analytic derivative (as model.dispersion_derivative;
the model's one Newton loop, model._kernels.newton._newton), started from the contour-integral estimate
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

import cmath
import math
from collections.abc import Callable

import numpy as np

from ._kernels.contour import (
    CAP,
    H0,
    LIN_TOL,
    PHASE_MAX,
    TRAP_TOL,
    WINDING_TOL,
    _newton_cell,
    _point,
    _sample_line,
)
from ._validate import check

__all__ = ["unstable_count", "unstable_modes"]

IM_FLOOR = 1e-10  # the bottom edge never goes below this (im_min = 0)
REL_HMIN = 1e-11  # smallest segment, relative to the window size ...
AXIS_HMIN = 1e-7  # ... and relative to the distance of the line from the real axis
SHIFT = 16.0  # an edge holding a root moves outward by SHIFT * h_min (then SHIFT_GROWTH x more per retry)
MAX_LADDER_POLES = 20000  # beyond this many isolated real-axis poles the graded seeding is skipped
RESID_MAX = 1e-12  # largest |F| / scale accepted at a cell's root (a converged root has it at rounding level)
CORNER_TOL = 1e-8  # a corner's two log-increments must sum to its segment's to this (else a root is near the corner)
MAX_SHIFTS = 6  # times an edge holding a root is moved outward (by SHIFT * SHIFT_GROWTH^k h_min) before giving up
SHIFT_GROWTH = 4.0  # growth of that move per retry
# splitting positions tried in turn (fractions of the cell): the middle; if a root lies on that line, irregular offsets
SPLIT_AT = (0.5, 0.5 + 0.0917, 0.5 - 0.1231, 0.5 + 0.2143, 0.5 - 0.2569, 0.3333, 0.6667)
GEOMETRIC_SPLIT = 4.0  # a cell with y1 > 4 y0 is split at the geometric mean height (structure geometric near the axis)
# a cell smaller than max(min(TINY_CELL_REL x window size, TINY_CELL_AXIS x its height), TINY_CELL_ULPS ulps of its
# coordinates) holding n > 1 roots is taken to hold one root of multiplicity n (distinct roots are not resolved there)
TINY_CELL_REL = 1e-9
TINY_CELL_AXIS = 1e-3
TINY_CELL_ULPS = 64

_FLOAT = np.float64


# ------------------------------------------------------------------------------------------------
# lines (sampled edges) and cells
# ------------------------------------------------------------------------------------------------


class _RootOnLine(Exception):
    """A root lies on (or within h_min of) a line that was being sampled."""


class _Line:
    """A sampled horizontal (z = t + i c) or vertical (z = c + i t) line with cumulative log-increments.

    C[i] = log F(t_i) - log F(t_0) (continuous branch), M[i] = integral of z dlog F from t_0 to t_i (midpoint
    rule in the log measure, for root estimates). `extra` holds the same values at cell corners that are not
    nodes (added by :meth:`_Problem.corner`).
    """

    __slots__ = ("c", "horizontal", "t", "F", "L", "C", "M", "node", "extra")

    def __init__(self, c: float, horizontal: bool, t: np.ndarray, F: np.ndarray, L: np.ndarray):
        self.c = c
        self.horizontal = horizontal
        self.t = t
        self.F = F
        self.L = L
        z = t + 1j * c if horizontal else c + 1j * t
        # Python lists and a node -> index dict: the cell bookkeeping reads single values (~200 per call of
        # unstable_modes), for which NumPy scalar indexing and searchsorted cost ~10x more
        self.C: list[complex] = np.concatenate(([0j], np.cumsum(L))).tolist()
        self.M: list[complex] = np.concatenate(([0j], np.cumsum(0.5 * (z[1:] + z[:-1]) * L))).tolist()
        self.node = dict(zip(t.tolist(), range(t.size), strict=True))
        self.extra: dict[float, tuple[complex, complex]] = {}

    def value(self, t: float) -> tuple[complex, complex]:
        hit = self.extra.get(t)
        if hit is not None:
            return hit
        i = self.node.get(t)
        if i is None:
            raise AssertionError("internal error: cell corner is not a node of its edge")
        return self.C[i], self.M[i]

    def piece(self, t0: float, t1: float) -> tuple[complex, complex]:
        """(increment of log F, integral of z dlog F) from t0 to t1 (nodes or corners)."""
        c0, m0 = self.value(t0)
        c1, m1 = self.value(t1)
        return c1 - c0, m1 - m0


def _roots_from_sums(n: int, s1: complex, s2: complex, known: list[complex],
                     polish: Callable[[complex], tuple[complex, complex] | None],
                     inside: Callable[[complex], bool]) -> list[tuple[complex, complex]] | None:
    """The n roots counted in a rectangle, without subdividing it: the known ones (roots there found otherwise) and
    at most two more, whose starts come from the estimates s1, s2 of the sum of the n roots and of their squares
    (model._kernels.contour.count_rectangle) less the known ones' (one more: s1'; two: the roots of
    x^2 - s1' x + (s1'^2 - s2')/2); each polished (polish(z) -> (root, slope) or None). The count certifies the
    result: it is returned only if it holds n distinct roots inside the rectangle (else None: subdivide)."""
    m = n - len(known)
    if not 0 <= m <= 2:
        return None
    a1 = s1 - sum(known, 0j)
    a2 = s2 - sum((v * v for v in known), 0j)
    if m == 0:
        starts: list[complex] = []
    elif m == 1:
        starts = [a1]
    else:
        d = cmath.sqrt(2.0 * a2 - a1 * a1)  # (r1 - r2)^2 = 2 (r1^2 + r2^2) - (r1 + r2)^2
        starts = [0.5 * (a1 + d), 0.5 * (a1 - d)]
    out: list[tuple[complex, complex]] = []
    for z0 in [*known, *starts]:
        got = polish(z0)
        if got is None or not inside(got[0]) or any(abs(got[0] - u[0]) <= 1e-8 * abs(got[0]) for u in out):
            return None
        out.append(got)
    return out


class _Problem:
    """One parameter set: line sampling with graded seeds, counting and locating (see module docstring)."""

    def __init__(self, q, gamma, f, beta, eta, delta, xi, re_max, im_min, im_max,
                 h0: float | None = None, singularities: tuple[np.ndarray, np.ndarray] | None = None):
        self.par = (q, gamma, f, beta, eta, delta, xi)
        self.re_max = re_max
        self.im_min = im_min
        self.im_max = im_max
        self.size = max(2.0 * re_max, im_max - im_min)
        self.evaluations = 0
        self.tols = (PHASE_MAX, TRAP_TOL, LIN_TOL)  # the acceptance tests of a sampled segment
        self.h0 = H0 if h0 is None else h0  # the initial spacing of the samples along a line (H0 read at set-up)
        # the real-axis singularities whose neighbourhoods get graded seeds (model.sliding passes its own)
        self.poles, self.half = self._real_axis_singularities() if singularities is None else singularities

    def _real_axis_singularities(self) -> tuple[np.ndarray, np.ndarray]:
        """Real-axis poles / branch points of F with |x| <= re_max + 1 (docs/physics.md §2) and the
        half-distance to their neighbours (capped at H0): where the initial nodes of low lines are graded.

        The spacing of a finite-eta pole family tends to a = pi / ((1+eta) kH) from below; a family with more
        than MAX_LADDER_POLES members in range is left to the adaptive refinement alone.
        """
        q, _, _, beta, eta, _, _ = self.par
        xmax = self.re_max + 1.0
        pts = [1.0, 1.0 / beta]
        if math.isfinite(eta):
            a = math.pi / ((1.0 + eta) * q)
            for scale in (1.0, 1.0 / beta):
                nmax = math.sqrt(max((xmax / scale) ** 2 - 1.0, 0.0)) / a
                if nmax > MAX_LADDER_POLES:
                    continue
                n = np.arange(1, int(nmax) + 1, dtype=_FLOAT)
                pts.extend((scale * np.sqrt(1.0 + (n * a) ** 2)).tolist())
        x = np.unique(np.array(pts, dtype=_FLOAT))
        x = x[x <= xmax]
        p = np.concatenate((-x[::-1], x))
        gaps = np.diff(p)
        half = 0.5 * np.maximum(np.concatenate(([0.0], gaps)), np.concatenate((gaps, [0.0])))
        return p, np.minimum(half, self.h0)

    # -- sampling ------------------------------------------------------------------------------
    def _h_min(self, dist_axis: float) -> float:
        return min(REL_HMIN * self.size, AXIS_HMIN * dist_axis)

    def sample(self, c: float, horizontal: bool, t0: float, t1: float) -> _Line:
        """Sample a line; raise _RootOnLine if a root lies on it."""
        if horizontal:
            geo0, lad_y, hmin = 0.0, c, self._h_min(c)
        else:
            geo0, lad_y, hmin = t0, 0.0, self._h_min(t0)
        t, F, L, status, tbad, nev = _sample_line(
            t0, t1, c, horizontal, self.h0, geo0, lad_y, self.poles, self.half, *self.par, hmin, *self.tols
        )
        self.evaluations += nev
        if status == 1:
            raise _RootOnLine(tbad)
        if status == 2:
            raise RuntimeError(
                f"unstable_modes: more than {CAP} samples needed on the line {'Im' if horizontal else 'Re'} z = {c}"
                " (dense real-axis poles closer than the line: raise im_min)"
            )
        if status == 3:
            raise RuntimeError(f"unstable_modes: F is not finite at z = {_point(tbad, c, horizontal)}")
        return _Line(c, horizontal, t, F, L)

    @staticmethod
    def corner(line: _Line, t: float, fv: complex) -> None:
        """Register the point t (where F = fv, known from the crossing line) as a corner on `line`.

        The segment holding t was accepted, so its two parts have principal log-increments summing to it.
        """
        if t in line.node:
            return
        i = int(np.searchsorted(line.t, t))
        if i == 0 or i == line.t.size:
            raise AssertionError("internal error: corner outside its line")
        l1 = cmath.log(fv / line.F[i - 1])
        l2 = cmath.log(line.F[i] / fv)
        if abs(l1 + l2 - line.L[i - 1]) > CORNER_TOL:
            raise _RootOnLine(t)
        z0 = _point(line.t[i - 1], line.c, line.horizontal)
        z1 = _point(t, line.c, line.horizontal)
        line.extra[t] = (line.C[i - 1] + l1, line.M[i - 1] + 0.5 * (z0 + z1) * l1)

    # -- counting ------------------------------------------------------------------------------
    @staticmethod
    def winding(cell: tuple) -> tuple[complex, complex]:
        """(change of log F, closed integral of z dlog F) counterclockwise around a cell."""
        x0, x1, y0, y1, bot, top, left, right = cell
        lb, mb = bot.piece(x0, x1)
        lr, mr = right.piece(y0, y1)
        lt, mt = top.piece(x0, x1)
        ll, ml = left.piece(y0, y1)
        return lb + lr - lt - ll, mb + mr - mt - ml

    @staticmethod
    def count_of(dlog: complex) -> int:
        """The winding number (must be within WINDING_TOL of an integer)."""
        w = dlog.imag / (2.0 * math.pi)
        n = round(w)
        if abs(w - n) > WINDING_TOL:
            raise RuntimeError(f"unstable_modes: winding number {w} is not an integer")
        return int(n)

    def outer(self) -> tuple[tuple, int]:
        """Sample the window's boundary (moving an edge outward if a root lies on it); return (cell, count)."""
        x0, x1 = -self.re_max, self.re_max
        y0, y1 = max(self.im_min, IM_FLOOR), self.im_max
        shifts = [0, 0, 0, 0]  # bottom, right, top, left
        while True:
            specs = ((y0, True, x0, x1), (x1, False, y0, y1), (y1, True, x0, x1), (x0, False, y0, y1))
            lines = []
            try:
                for c, hor, t0, t1 in specs:
                    lines.append(self.sample(c, hor, t0, t1))
            except _RootOnLine:
                k = len(lines)  # the edge that holds a root moves outward
                shifts[k] += 1
                if shifts[k] > MAX_SHIFTS:
                    break
                grow = SHIFT * SHIFT_GROWTH ** (shifts[k] - 1)
                if k == 0:
                    y0 -= grow * self._h_min(y0)
                elif k == 1:
                    x1 += grow * self._h_min(self.size)
                elif k == 2:
                    y1 += grow * self._h_min(y1)
                else:
                    x0 -= grow * self._h_min(self.size)
                continue
            bot, right, top, left = lines
            cell = (x0, x1, y0, y1, bot, top, left, right)
            return cell, self.count_of(self.winding(cell)[0])
        name = ("bottom", "right", "top", "left")[k]
        hint = " (or the real-axis poles below it are too dense to resolve: raise im_min)" if k == 0 else ""
        raise RuntimeError(f"unstable_modes: could not move the {name} edge of the window away from roots{hint}")

    # -- locating ------------------------------------------------------------------------------
    def split(self, cell: tuple, vertical: bool | None = None) -> tuple[tuple, tuple]:
        """Split a cell in two by a new sampled line (trying other positions if a root lies on it): vertical if
        the cell is wider than tall (or as `vertical` says)."""
        x0, x1, y0, y1, bot, top, left, right = cell
        if vertical is None:
            vertical = (x1 - x0) >= (y1 - y0)
        for fr in SPLIT_AT:
            try:
                if vertical:
                    xs = x0 + fr * (x1 - x0)
                    if not x0 < xs < x1:
                        break
                    mid = self.sample(xs, False, y0, y1)
                    self.corner(bot, xs, mid.F[0])
                    self.corner(top, xs, mid.F[-1])
                    return (x0, xs, y0, y1, bot, top, left, mid), (xs, x1, y0, y1, bot, top, mid, right)
                if y1 > GEOMETRIC_SPLIT * y0:  # near the axis the structure is geometric in Im z
                    ys = math.exp(math.log(y0) + fr * (math.log(y1) - math.log(y0)))
                else:
                    ys = y0 + fr * (y1 - y0)
                if not y0 < ys < y1:
                    break
                mid = self.sample(ys, True, x0, x1)
                self.corner(left, ys, mid.F[0])
                self.corner(right, ys, mid.F[-1])
                return (x0, x1, y0, ys, bot, mid, left, right), (x0, x1, ys, y1, mid, top, left, right)
            except _RootOnLine:
                continue
        raise RuntimeError(f"unstable_modes: could not split the cell [{x0}, {x1}] x [{y0}, {y1}] away from roots")

    def newton_in(self, cell: tuple, n: int, moment: complex) -> complex | None:
        """The root of multiplicity `n` in `cell` by Newton from the contour's estimate (its first moment over n,
        if inside the cell) and then from the centre; None if neither converges inside the cell."""
        x0, x1, y0, y1 = cell[:4]
        est = moment / (2j * math.pi) / n
        centre = complex(0.5 * (x0 + x1), 0.5 * (y0 + y1))
        for s in ([est, centre] if (x0 <= est.real <= x1 and y0 <= est.imag <= y1) else [centre]):
            z, ok, res, nev = _newton_cell(s, x0, x1, y0, y1, float(n), *self.par)
            self.evaluations += nev
            if ok and res < RESID_MAX and x0 <= z.real <= x1 and y0 <= z.imag <= y1:
                return z
        return None

    def locate(self, cell: tuple, n_total: int) -> np.ndarray:
        """Roots in `cell`, which holds n_total of them: subdivide to one root per cell, then Newton."""
        stack = [(cell, n_total, None)]
        roots: list[complex] = []
        eps = np.finfo(float).eps
        while stack:
            c, n, moment = stack.pop()
            if n == 0:
                continue
            if n < 0:
                raise RuntimeError("unstable_modes: negative root count in a cell (contour sampling failed)")
            x0, x1, y0, y1 = c[:4]
            # a cell this small holding n > 1 roots is taken to hold one root of multiplicity n
            tiny = max(min(TINY_CELL_REL * self.size, TINY_CELL_AXIS * y0),
                       TINY_CELL_ULPS * eps * max(abs(x0), abs(x1), y1))
            small = max(x1 - x0, y1 - y0) < tiny
            if n == 1 or small:
                found = self.newton_in(c, n, self.winding(c)[1] if moment is None else moment)
                if found is not None:
                    roots.extend([found] * n)
                    continue
                if small:
                    raise RuntimeError(
                        f"unstable_modes: {n} root(s) counted in a tiny cell near "
                        f"{complex(0.5 * (x0 + x1), 0.5 * (y0 + y1))} could not be located "
                        f"(located {len(roots)} of the {n_total} counted)"
                    )
            (a, na, ma), (b, nb, mb) = self.halves(c, n)
            stack.append((b, nb, mb))
            stack.append((a, na, ma))
        return np.array(roots, dtype=np.complex128)

    def halves(self, cell: tuple, n: int) -> tuple[tuple, tuple]:
        """The two halves of a cell holding n roots (:meth:`split`), each with its count and first moment; a
        RuntimeError if the counts do not add up to n."""
        a, b = self.split(cell)
        da, ma = self.winding(a)
        db, mb = self.winding(b)
        na, nb = self.count_of(da), self.count_of(db)
        if na + nb != n:
            raise RuntimeError(f"unstable_modes: split counts {na} + {nb} != {n} (contour sampling failed)")
        return (a, na, ma), (b, nb, mb)


# ------------------------------------------------------------------------------------------------
# public API
# ------------------------------------------------------------------------------------------------


def _problem(kH, gamma, f, beta, eta, Delta, xi, re_max, im_min, im_max) -> _Problem:
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
    return _Problem(*vals, re_m, im_lo, im_hi)


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


def _modes(prob: _Problem) -> tuple[np.ndarray, int]:
    """(roots sorted by decreasing Im z, number of evaluations of F) for a validated problem."""
    cell, n = prob.outer()
    roots = prob.locate(cell, n) if n else np.empty(0, dtype=np.complex128)
    if roots.size != n:
        raise RuntimeError(f"unstable_modes: located {roots.size} roots but the argument principle counts {n}")
    order = np.lexsort((roots.real, -roots.imag))
    return roots[order], prob.evaluations
