"""Roots that cross the cuts beside the branch points between grid points (eta = inf; docs/physics.md §14.7).

At eta = inf, F has branch points at z = +-1 (alpha_s) and +-1/beta (alpha_d), with cuts along the real axis beyond
them. A root of the physical sheet can leave through a cut, and a root of the other sheet can come out of one: for a
short kH span it then grows, possibly faster than anything at the grid points, and no count on the physical sheet
at a grid point sees it. Near a branch point the local uniformizing variable w (alpha_d near +-1/beta, alpha_s near
+-1) makes F analytic on both sides of the cut (``_kernels.response.chart_point``), so the roots there are
continuous in kH across it. At each grid point, every root in a box of half-width CHART_BOX x (the distance to the
chart's other singularities) around w = 0 is counted, located and followed in kH to the neighbouring grid points;
where it lies on the physical sheet (Re w > 0) with Im z > 0, its growth is watched, and its highest point is handed
to the certified search of :mod:`.track`.
"""

from __future__ import annotations

import math

import numpy as np

from .._kernels.contour import LIN_TOL, PHASE_MAX, TRAP_TOL, count_rectangle
from .._kernels.cuts import WARM_ITERS, follow_chart, growth_in_chart
from .._kernels.newton import FULL_TOL, KH, newton_root
from .._kernels.records import NO_BOX, Params
from .._kernels.response import CHART_ORIGIN, chart_point
from .contour import AXIS_HMIN, REL_HMIN, Problem, roots_from_sums

CHARTS = (1, 2, 3, 4)  # beside +1/beta, -1/beta, +1, -1 (chart_point)
CHART_BOX = 0.6  # the box's half-width over the distance (in w) to the chart's other singularities (and to |w| = 1)
CHART_H0 = 0.25  # initial sample spacing on the box's edges
FOLLOW_STEP = 0.05  # largest step in ln kH when a chart root is followed
_EMPTY = np.empty(0)


class CutCharts:
    """The four charts of one parameter set (eta = inf)."""

    def __init__(self, p: Params):
        self.p = p
        self.evaluations = 0
        # per chart: the parameters that select it (eta = -chart) and the box's half-width
        self._par = {c: Params(p.gamma, p.f, p.beta, -float(c), p.delta, p.xi) for c in CHARTS}
        self._half = {c: self._half_width(c) for c in CHARTS}

    def _params(self, chart: int) -> Params:
        return self._par[chart]

    def half_width(self, chart: int) -> float:
        return self._half[chart]

    def _half_width(self, chart: int) -> float:
        """The box's half-width in w: the chart is valid for |w| below the distance to the other branch points
        (sqrt(1 - beta^2) in alpha_d, sqrt(1/beta^2 - 1) in alpha_s) and to |w| = 1 (the chart's own square root);
        the box's corners stay within CHART_BOX x sqrt(2) of that."""
        b = self.p.beta
        lim = math.sqrt(1.0 - b * b) if chart <= 2 else math.sqrt(1.0 / (b * b) - 1.0)
        return CHART_BOX * min(1.0, lim)

    def roots(self, q: float, chart: int, known: list[complex] = (), most: int = 2**31
              ) -> tuple[int, list[tuple[complex, complex]] | None]:
        """(the number of roots of F in the chart's box at kH = q, -1 if the count failed; every one of them as
        (v, dv/d ln kH), None if the count failed, a location failed or there are more than `most`).

        known: roots at this kH found otherwise (followed from a neighbouring kH). The box is counted with the sums
        of its roots and of their squares (``_kernels.contour.count_rectangle``); the roots not known (at
        most two) are estimated from them and polished by Newton; if that does not give as many distinct roots in
        the box as it holds, the box is subdivided (Problem.locate)."""
        r = self.half_width(chart)
        pc = self._params(chart)
        x0, x1 = -r, r  # symmetric in Re v, as model.modes' windows are (w = v - CHART_ORIGIN: off-centre by 0.012)
        y0, y1 = CHART_ORIGIN.imag - r, CHART_ORIGIN.imag + r
        h = min(REL_HMIN * 2.0 * r, AXIS_HMIN * y0)
        st, n, _, _, nev, s1, s2 = count_rectangle(x0, x1, y0, y1, CHART_H0, _EMPTY, _EMPTY, q, *pc, h, h, h,
                                                   PHASE_MAX, TRAP_TOL, LIN_TOL)
        self.evaluations += nev
        if st != 0:
            return -1, None
        if n == 0 or n > most:
            return n, [] if n == 0 else None
        inside = [v for v in known if x0 < v.real < x1 and y0 < v.imag < y1]
        distinct = [v for k, v in enumerate(inside) if all(abs(v - u) > 1e-8 * abs(v) for u in inside[:k])]
        got = roots_from_sums(n, s1, s2, distinct, lambda v: self.polish(v, q, chart),
                               lambda v: x0 < v.real < x1 and y0 < v.imag < y1)
        if got is not None:
            return n, got
        prob = Problem(q, *pc, r, y0, y1, CHART_H0, (_EMPTY, _EMPTY))
        try:
            cell, n = prob.outer()
            found = prob.locate(cell, n) if n else []
        except RuntimeError:
            return n, None
        finally:
            self.evaluations += prob.evaluations
        out = []
        for v in found:
            got1 = self.polish(complex(v), q, chart)
            if got1 is None:
                return n, None
            out.append(got1)
        return n, out

    def polish(self, v0: complex, q: float, chart: int) -> tuple[complex, complex] | None:
        """Newton in the chart from v0 at kH = q: (v, dv/d ln kH) or None."""
        r = newton_root(v0, KH, 0.0, q, self._params(chart), WARM_ITERS, FULL_TOL, 0.0, 0.9, 1.0, NO_BOX)
        self.evaluations += r.evals
        if not r.ok or not math.isfinite(r.z.real):
            return None
        return r.z, q * r.dzds

    def highest(self, v: complex, dv: complex, s: float, end: float, chart: int, best: float
                ) -> tuple[tuple[float, complex] | None, complex | None]:
        """Follow the chart root v (slope dv) from ln kH = s to `end` (``_kernels.cuts.follow_chart``).
        Returns (the (ln kH, z) of its highest point on the physical sheet with Im z > 0, or None if it never grows
        there; v at `end`, or None if the root left the chart's domain or was lost). Where the highest sample is
        above best/2, the peak between samples is estimated by a parabola through the three around it and
        polished there."""
        w_max = 0.95 * self.half_width(chart) / CHART_BOX
        sk, vk, gk, n, ev = follow_chart(v, dv, s, end, self._params(chart), chart, FOLLOW_STEP, w_max)
        self.evaluations += ev
        arrived = complex(vk[n - 1]) if sk[n - 1] == end else None
        k = int(np.argmax(gk))
        if not math.isfinite(gk[k]):
            return None, arrived
        s_k, v_k, im_k = float(sk[k]), complex(vk[k]), float(gk[k])
        if im_k > 0.5 * best and 0 < k < n - 1 and math.isfinite(gk[k - 1]) and math.isfinite(gk[k + 1]):
            (s0, y0), (s2, y2) = (float(sk[k - 1]), float(gk[k - 1])), (float(sk[k + 1]), float(gk[k + 1]))
            den = (s0 - s_k) * (s0 - s2) * (s_k - s2)
            a = (s2 * (im_k - y0) + s_k * (y0 - y2) + s0 * (y2 - im_k)) / den
            b = (s2 * s2 * (y0 - im_k) + s_k * s_k * (y2 - y0) + s0 * s0 * (im_k - y2)) / den
            if a < 0.0:
                s_star = min(max(-b / (2.0 * a), min(s0, s2)), max(s0, s2))
                got = self.polish(v_k, math.exp(s_star), chart)
                if got is not None and growth_in_chart(got[0], self.p.beta, chart) > im_k:
                    return (s_star, chart_point(got[0], self.p.beta, chart)[0]), arrived
        return (s_k, chart_point(v_k, self.p.beta, chart)[0]), arrived
