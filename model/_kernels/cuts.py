"""A root followed in kH in a chart across the cuts beside a branch point (eta = inf; docs/physics.md §14.7).

The compiled loop of :meth:`model._roots.cuts.CutCharts.highest`: predictor-corrector steps in ln kH in the chart's
variable v (:func:`model._kernels.response.chart_point`), each accepted where Newton from the linear predictor
lands within a tenth of the step of it (the same root), else halved; at every accepted step, the growth Im z where the
root lies on the physical sheet (Re w > 0, Im z > 0), else -inf.
"""

from __future__ import annotations

import math

import numpy as np

from ._common import jitted
from .newton import FULL_TOL, KH, newton_root
from .records import NO_BOX, Params
from .response import CHART_ORIGIN, chart_point

FOLLOW_ITERS = 200  # steps allowed (an interval of the default grid is 0.58 in ln kH)
WARM_ITERS = 40  # Newton evaluations per step
MIN_STEP = 1e-9  # a step in ln kH this small ends the follow (the root is lost)


@jitted
def growth_in_chart(v: complex, beta: float, chart: int) -> float:
    """Im z at the chart point v if it lies on the physical sheet with Im z > 0, else -inf."""
    w = v - CHART_ORIGIN
    if not w.real > 0.0:
        return -math.inf
    z = chart_point(v, beta, chart)[0]
    return z.imag if z.imag > 0.0 else -math.inf


@jitted
def follow_chart(v: complex, dv: complex, s: float, end: float, p: Params, chart: int, step_max: float,
                 w_max: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, int, int]:
    """Follow the root v (dv = dv/d ln kH) of F in chart `chart` (p.eta = -chart) from ln kH = s towards `end`, with
    steps of at most step_max, while |w| < w_max. Returns (s_k, v_k, growth_k) of the accepted points (the start
    first), the number of them, and the evaluations of F."""
    sk = np.empty(FOLLOW_ITERS + 1)
    vk = np.empty(FOLLOW_ITERS + 1, dtype=np.complex128)
    gk = np.empty(FOLLOW_ITERS + 1)
    sign = 1.0 if end > s else -1.0
    cap = step_max
    sk[0], vk[0], gk[0] = s, v, growth_in_chart(v, p.beta, chart)
    n = 1
    evals = 0
    for _ in range(FOLLOW_ITERS):
        if s == end or cap < MIN_STEP or not abs(v - CHART_ORIGIN) < w_max or not math.isfinite(dv.real):
            break
        s_new = s + sign * min(cap, abs(end - s))
        pred = v + dv * (s_new - s)
        r = newton_root(pred, KH, 0.0, math.exp(s_new), p, WARM_ITERS, FULL_TOL, 0.0, 0.9, 1.0, NO_BOX)
        evals += r.evals
        if not r.ok or not abs(r.z - pred) <= 0.1 * abs(pred - v) + 1e-12:
            cap *= 0.5
            continue
        v, dv, s = r.z, math.exp(s_new) * r.dzds, s_new
        sk[n], vk[n], gk[n] = s, v, growth_in_chart(v, p.beta, chart)
        n += 1
        cap = min(step_max, 2.0 * cap)
    return sk[:n], vk[:n], gk[:n], n, evals

