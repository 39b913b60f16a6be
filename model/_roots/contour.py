"""The argument principle on rectangles of the upper half-plane: sampled lines, counts, cells and Newton in a cell.

What :mod:`model.modes` documents (its docstring: the acceptance tests of a segment, the graded seeds beside the
real-axis singularities, the window semantics and the edges moved past a root; docs/physics.md §10), in one place
for every caller: :class:`Problem` samples, counts and locates every root of a window; :func:`best_first` only
the highest; :func:`real_axis_singularities` is the one rule for the graded seeds and :func:`move_edge` the one
for an edge moved outward past a root (the compiled count of ``_kernels.contour.count_rectangle`` uses both too).
"""

from __future__ import annotations

import cmath
import heapq
import math
from collections.abc import Callable

import numpy as np

from .._kernels.contour import (
    CAP,
    H0,
    LIN_TOL,
    PHASE_MAX,
    TRAP_TOL,
    WINDING_TOL,
    line_point,
    newton_cell,
    sample_line,
)

IM_FLOOR = 1e-10  # the bottom edge never goes below this (im_min = 0)
REL_HMIN = 1e-11  # smallest segment, relative to the window size ...
AXIS_HMIN = 1e-7  # ... and relative to the distance of the line from the real axis
SHIFT = 16.0  # an edge holding a root moves outward by SHIFT * h_min (then SHIFT_GROWTH x more per retry)
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

LADDER_DAMPED = 1.0  # pole families seen from a line at height y only while (1 + eta) kH beta_j y < this

_FLOAT = np.float64


def h_min(size: float, dist_axis: float) -> float:
    """The smallest segment of a line at distance `dist_axis` from the real axis in a window of this size."""
    return min(REL_HMIN * size, AXIS_HMIN * dist_axis)


def move_edge(rect: tuple[float, float, float, float], edge: int, shifts: list[int], size: float
              ) -> tuple[float, float, float, float] | None:
    """The rectangle (x0, x1, y0, y1) with its edge `edge` (0 bottom, 1 right, 2 top, 3 left), which holds a root,
    moved outward by SHIFT x SHIFT_GROWTH^k h_min at its k-th move (counted in `shifts`); None after MAX_SHIFTS."""
    shifts[edge] += 1
    if shifts[edge] > MAX_SHIFTS:
        return None
    x0, x1, y0, y1 = rect
    grow = SHIFT * SHIFT_GROWTH ** (shifts[edge] - 1)
    if edge == 0:
        y0 -= grow * h_min(size, y0)
    elif edge == 1:
        x1 += grow * h_min(size, size)
    elif edge == 2:
        y1 += grow * h_min(size, y1)
    else:
        x0 -= grow * h_min(size, size)
    return x0, x1, y0, y1


def real_axis_singularities(q: float, beta: float, eta: float, xmax: float, h: float, y: float = 0.0
                            ) -> tuple[np.ndarray, np.ndarray]:
    """The real-axis singularities of F with |x| <= xmax around which lines at height >= y get graded seeds, and
    the half-distances to their neighbours (capped at h).

    z = +-1, +-1/beta, and for finite eta the pole families z^2 = beta_j^-2 [1 + (pi n / ((1 + eta) kH))^2]
    (docs/physics.md §2; beta_j = 1 for the shear family, beta for the dilatational one), each only where a line at
    height y sees it, (1 + eta) kH beta_j y < LADDER_DAMPED: above that, F along the line changes on the scale of
    the pole spacing by less than exp(-2 LADDER_DAMPED) of its size, and the adaptive sampling alone resolves it
    (y = 0: every family). Every family is seeded whatever its number of poles in range (a
    pole without its seeds can hide a root beside it: docs/physics.md §10); a line then needing more than CAP samples
    is refused.
    """
    pts = [1.0, 1.0 / beta]
    if math.isinf(eta) or (1.0 + eta) * q * beta * y >= LADDER_DAMPED:  # the branch points alone (no NumPy: fast)
        xs = [v for v in sorted(set(pts)) if v <= xmax]
        p = [-v for v in reversed(xs)] + xs
        gaps = [b - a for a, b in zip(p[:-1], p[1:], strict=True)]
        half = [min(h, 0.5 * max(lo, hi)) for lo, hi in zip([0.0, *gaps], [*gaps, 0.0], strict=True)]
        return np.array(p), np.array(half)
    a = math.pi / ((1.0 + eta) * q)
    for bj in (1.0, beta):
        if (1.0 + eta) * q * bj * y >= LADDER_DAMPED:
            continue
        nmax = math.sqrt(max((xmax * bj) ** 2 - 1.0, 0.0)) / a
        if 2.0 * nmax > CAP:  # (both signs) every pole needs a seed: more than a line's cap of samples
            raise RuntimeError(f"unstable_modes: more than {CAP} samples needed on a line near the real axis: "
                               f"{2 * int(nmax):,} real-axis poles of the lower block in range, each graded "
                               "(raise im_min or narrow the window)")
        n = np.arange(1, int(nmax) + 1, dtype=_FLOAT)
        pts.extend((np.sqrt(1.0 + (n * a) ** 2) / bj).tolist())
    xs = np.unique(np.array(pts))
    xs = xs[xs <= xmax]
    p = np.concatenate((-xs[::-1], xs))
    gaps = np.diff(p)
    half = 0.5 * np.maximum(np.concatenate(([0.0], gaps)), np.concatenate((gaps, [0.0])))
    return p, np.minimum(half, h)


# ------------------------------------------------------------------------------------------------
# lines (sampled edges) and cells
# ------------------------------------------------------------------------------------------------


class RootOnLine(Exception):
    """A root lies on (or within h_min of) a line that was being sampled."""


class Line:
    """A sampled horizontal (z = t + i c) or vertical (z = c + i t) line with cumulative log-increments.

    C[i] = log F(t_i) - log F(t_0) (continuous branch), M[i] = integral of z dlog F from t_0 to t_i (midpoint
    rule in the log measure, for root estimates). `extra` holds the same values at cell corners that are not
    nodes (added by :meth:`Problem.corner`).
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


def roots_from_sums(n: int, s1: complex, s2: complex, known: list[complex],
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


class Problem:
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
        # the real-axis singularities whose neighbourhoods get graded seeds (a search passes those its lines see)
        if singularities is None:
            singularities = real_axis_singularities(q, beta, eta, re_max + 1.0, self.h0)
        self.poles, self.half = singularities

    # -- sampling ------------------------------------------------------------------------------
    def _h_min(self, dist_axis: float) -> float:
        return h_min(self.size, dist_axis)

    def sample(self, c: float, horizontal: bool, t0: float, t1: float) -> Line:
        """Sample a line; raise RootOnLine if a root lies on it."""
        if horizontal:
            geo0, lad_y, hmin = 0.0, c, self._h_min(c)
        else:
            geo0, lad_y, hmin = t0, 0.0, self._h_min(t0)
        t, F, L, status, tbad, nev = sample_line(
            t0, t1, c, horizontal, self.h0, geo0, lad_y, self.poles, self.half, *self.par, hmin, *self.tols
        )
        self.evaluations += nev
        if status == 1:
            raise RootOnLine(tbad)
        if status == 2:
            raise RuntimeError(
                f"unstable_modes: more than {CAP} samples needed on the line {'Im' if horizontal else 'Re'} z = {c}"
                " (dense real-axis poles closer than the line: raise im_min)"
            )
        if status == 3:
            raise RuntimeError(f"unstable_modes: F is not finite at z = {line_point(tbad, c, horizontal)}")
        return Line(c, horizontal, t, F, L)

    @staticmethod
    def corner(line: Line, t: float, fv: complex) -> None:
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
            raise RootOnLine(t)
        z0 = line_point(line.t[i - 1], line.c, line.horizontal)
        z1 = line_point(t, line.c, line.horizontal)
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
            except RootOnLine:
                k = len(lines)  # the edge that holds a root moves outward
                moved = move_edge((x0, x1, y0, y1), k, shifts, self.size)
                if moved is None:
                    break
                x0, x1, y0, y1 = moved
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
            except RootOnLine:
                continue
        raise RuntimeError(f"unstable_modes: could not split the cell [{x0}, {x1}] x [{y0}, {y1}] away from roots")

    def newton_in(self, cell: tuple, n: int, moment: complex) -> complex | None:
        """The root of multiplicity `n` in `cell` by Newton from the contour's estimate (its first moment over n,
        if inside the cell) and then from the centre; None if neither converges inside the cell."""
        x0, x1, y0, y1 = cell[:4]
        est = moment / (2j * math.pi) / n
        centre = complex(0.5 * (x0 + x1), 0.5 * (y0 + y1))
        for s in ([est, centre] if (x0 <= est.real <= x1 and y0 <= est.imag <= y1) else [centre]):
            z, ok, res, nev = newton_cell(s, x0, x1, y0, y1, float(n), *self.par)
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


def spacing(q: float) -> float:
    """The initial spacing of the samples along a line: H0 at kH >= 1, H0/kH below. F's structure away
    from the real-axis singularities (which get graded seeds) scales like 1/kH in z at small kH (the oscillation
    exp(2i kH z), the spacing of the roots, |z| ~ 1/kH of the long-wave roots), and the acceptance tests of a
    segment are scale-free (relative changes of F along it)."""
    return H0 / min(q, 1.0)


def best_first(prob: Problem, cell: tuple, n: int) -> complex:
    """The root of largest Im z among the n counted in `cell` of `prob`: cells in the order of their tops, split
    until a cell holds one root, which Newton locates; stops when the highest cell left lies below the best root."""
    heap = [(-cell[3], 0, cell, n, None)]
    order = 1
    best: complex | None = None
    while heap:
        neg_top, _, c, n, moment = heapq.heappop(heap)
        if best is not None and -neg_top <= best.imag:
            break
        if n == 1:
            z = prob.newton_in(c, 1, prob.winding(c)[1] if moment is None else moment)
            if z is not None:
                best = z if best is None or z.imag > best.imag else best
                continue
        for cc, nn, mm in prob.halves(c, n):
            if nn > 0:
                heapq.heappush(heap, (-cc[3], order, cc, nn, mm))
                order += 1
    if best is None:
        raise RuntimeError("sliding: a counted root could not be located")
    return best
