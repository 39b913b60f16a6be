"""Stability-map benchmark: 128 x 128 parameter grid x 256 kH (issue: stability analysis).

Compares the time of model.growth_analysis over the map with one plain numpy evaluation of the
dispersion function (Eq. Gs_general + Eq. implicit_spectrum, literal formula) over the same
4.2 M (parameter, kH) points, in one run, and reports the located thresholds. Map times are medians
of 3 runs; the rtol rows are the map at looser accuracy settings.
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from asymslide import model  # noqa: E402


def plain_numpy_dispersion(z, q, gamma, f, beta, eta):
    """Literal Eq. Gs_general with numpy (finite eta), F of Eq. implicit_spectrum with Delta = 1."""
    a_s = np.sqrt(1 - z * z)
    a_d = np.sqrt(1 - beta * beta * z * z)
    t1s, t1d = np.tanh(q * a_s), np.tanh(q * a_d)
    t2s, t2d = np.tanh(eta * q * a_s), np.tanh(eta * q * a_d)
    gx = ((1 + a_s**2) ** 2 / (a_s * (t1s + t2s)) - 4 * a_d / (t1d + t2d)) / z**2
    gy = 2 * (1 + a_s**2) / z**2 * (t2d / (t1d + t2d) - t2s / (t1s + t2s))
    return gamma * (gx + 1j * f * gy) + 1j * z


def median_time(fn, repeat: int = 3) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def run(n: int = 128, nk: int = 256) -> list[dict]:
    q = np.logspace(-3, 3, nk)
    gam = np.logspace(math.log10(0.5), math.log10(20.0), n)
    eta = np.logspace(0.0, 4.0, n)
    model.growth_analysis(q, gamma=gam[:2, None], f=0.9, beta=0.3, eta=eta[None, :2])  # compile / warm up
    rows = []
    t_map = median_time(lambda: model.growth_analysis(q, gamma=gam[:, None], f=0.9, beta=0.3, eta=eta[None, :]), 3)
    res = model.growth_analysis(q, gamma=gam[:, None], f=0.9, beta=0.3, eta=eta[None, :])
    zz = np.full((n, n, nk), 0.9 + 0.01j)
    with np.errstate(all="ignore"):
        t_np = median_time(lambda: plain_numpy_dispersion(zz, q, gam[:, None, None], 0.9, 0.3, eta[None, :, None]), 1)
    rows.append(dict(what=f"growth map eta-gamma {n}x{n}x{nk}", seconds=t_map, roots=n * n * nk,
                     masked_points=int(res.n_masked.sum())))
    rows.append(dict(what=f"one plain numpy evaluation of F over {n * n * nk} points", seconds=t_np, roots=n * n * nk))
    rows.append(dict(what="ratio map / numpy evaluation", seconds=t_map / t_np, roots=0))
    t_inf = median_time(lambda: model.growth_analysis(q, gamma=gam[:, None], f=np.linspace(0.1, 2.0, n)[None, :],
                                                      beta=0.3), 3)
    rows.append(dict(what=f"growth map f-gamma (eta = inf) {n}x{n}x{nk}", seconds=t_inf, roots=n * n * nk))
    for rtol in (1e-10, 1e-6):
        t_r = median_time(lambda rtol=rtol: model.growth_analysis(q, gamma=gam[:, None], f=0.9, beta=0.3,
                                                                  eta=eta[None, :], rtol=rtol), 3)
        res_r = model.growth_analysis(q, gamma=gam[:, None], f=0.9, beta=0.3, eta=eta[None, :], rtol=rtol)
        dev = float(np.nanmax(np.abs(res_r.growth - res.growth)))
        rows.append(dict(what=f"growth map eta-gamma rtol={rtol:g} (max growth deviation from default {dev:.1e})",
                         seconds=t_r, roots=n * n * nk))
    t0 = time.perf_counter()
    gc = model.critical_gamma(f=0.9, beta=0.3)
    ec = model.critical_eta(gamma=3.0, f=0.9, beta=0.3)
    rows.append(dict(what=f"critical gamma {gc:.10f} + critical eta {ec:.10f}", seconds=time.perf_counter() - t0,
                     roots=0))
    return rows


def table(rows: list[dict]) -> str:
    lines = ["| what | time [s] (or ratio) | roots |", "|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['what']} | {r['seconds']:.3f} | {r['roots']} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(table(run()))
