"""Run time against error: Rayleigh branch solvers and threshold-vs-grid-resolution (issue: stability analysis).

Reference: the mpmath oracle (tests/oracle.py) at 16 kH values of the 512-point grid, and the
oracle's critical gamma 2.41488057... for f = 0.9, beta = 0.3, eta = inf.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import mpmath
import numpy as np
from scipy import optimize

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from asymslide import model  # noqa: E402
from benchmarks.run import PAPER, naive_newton_loop, plain_dispersion  # noqa: E402
from tests import oracle  # noqa: E402


def vectorized_newton(q: np.ndarray) -> np.ndarray:
    """scipy.optimize.newton on all kH at once from z_R (no continuation: it may land on other roots)."""
    z0 = np.full(q.size, complex(model.rayleigh_speed(PAPER["beta"])))
    return optimize.newton(plain_dispersion_vec, z0, args=(q,), tol=1e-14, maxiter=100, full_output=False)


def plain_dispersion_vec(z, q):
    with np.errstate(all="ignore"):
        return np.array([plain_dispersion(zi, qi, *PAPER.values(), math.inf) for zi, qi in zip(z, q, strict=True)])


def mpmath_loop(q: np.ndarray, dps: int = 15) -> np.ndarray:
    """mpmath.findroot per kH, warm-started, from kH = 1e4 down (plain formula at `dps` digits; NaN on failure)."""
    out = np.empty(q.size, complex)
    with mpmath.workdps(dps):
        def fun(z, qq):
            a_s = mpmath.sqrt(1 - z * z)
            a_d = mpmath.sqrt(1 - 0.09 * z * z)
            ts, td = mpmath.tanh(qq * a_s) + 1, mpmath.tanh(qq * a_d) + 1
            gx = ((1 + a_s**2) ** 2 / (a_s * ts) - 4 * a_d / td) / z**2
            gy = 2 * (1 + a_s**2) / z**2 * (1 / td - 1 / ts)
            return 3 * (gx + 0.9j * gy) + 1j * z

        z = mpmath.mpc(complex(model.spectrum(np.array([1e4]), **PAPER)[0]))  # same start as the others
        for i in np.argsort(-q):
            try:
                z = mpmath.findroot(lambda w, qq=q[i]: fun(w, qq), z, tol=1e-26)
                out[i] = complex(z)
            except ValueError:
                out[i] = complex(math.nan, math.nan)
    return out


def spectrum_rows(ref: dict[float, complex], q: np.ndarray) -> list[tuple[str, float, float]]:
    def err(z: np.ndarray) -> float:
        e = [abs(z[i] - ref[q[i]]) / abs(ref[q[i]]) for i in range(q.size) if q[i] in ref]
        return math.inf if any(math.isnan(x) for x in e) else max(e)

    rows = []
    for name, fn, rep in [
        ("model.spectrum (default: full certified accuracy)", lambda: model.spectrum(q, **PAPER), 200),
        ("model.spectrum rtol=1e-10", lambda: model.spectrum(q, **PAPER, rtol=1e-10), 200),
        ("model.spectrum rtol=1e-6", lambda: model.spectrum(q, **PAPER, rtol=1e-6), 200),
        ("scipy newton loop, warm-started (cmath F)", lambda: naive_newton_loop(q, math.inf), 3),
        ("scipy newton, vectorised over kH from z_R (no continuation)", lambda: vectorized_newton(q), 1),
        ("mpmath findroot loop, 15 digits", lambda: mpmath_loop(q), 1),
    ]:
        fn()
        t0 = time.perf_counter()
        for _ in range(rep):
            z = fn()
        rows.append((name, (time.perf_counter() - t0) / rep, err(z)))
    return rows


GAMMA_C = 2.414880573904  # the oracle's critical gamma for f = 0.9, beta = 0.3, eta = inf (12 digits)


def threshold_rows() -> list[tuple[str, float, float]]:
    """critical_gamma (threshold refined by Brent's method) against the kH grid it brackets the maximum on."""
    rows = []
    model.critical_gamma(f=0.9, beta=0.3, kH=np.logspace(-3, 3, 11))  # warm up (compiled code loaded)
    for n in (11, 21, 41, 81, 161, 321):
        q = np.logspace(-3, 3, n)
        t0 = time.perf_counter()
        g = model.critical_gamma(f=0.9, beta=0.3, kH=q)
        rows.append((f"critical_gamma with {n} kH grid points", time.perf_counter() - t0, abs(g - GAMMA_C) / GAMMA_C))
    return rows


def map_threshold(n: int, rtol: float | None = None) -> float:
    """gamma_c read off a stability map: max growth on n log-spaced gamma in [0.5, 20] (256 kH in [1e-3, 1e3]),
    the sign change located by linear interpolation of the growth in ln gamma."""
    gam = np.logspace(math.log10(0.5), math.log10(20.0), n)
    growth, _ = model.max_growth(np.logspace(-3, 3, 256), gamma=gam, f=0.9, beta=0.3, rtol=rtol)
    i = int(np.flatnonzero((growth[:-1] < 0) & (growth[1:] >= 0))[0])
    x0, x1 = math.log(gam[i]), math.log(gam[i + 1])
    return math.exp(x0 - growth[i] * (x1 - x0) / (growth[i + 1] - growth[i]))


def map_rows() -> list[tuple[str, float, float]]:
    """Threshold from a map against the map's resolution (and accuracy setting)."""
    rows = []
    for n, rtol in [(9, None), (17, None), (33, None), (65, None), (129, None), (257, None), (65, 1e-6),
                    (257, 1e-6)]:
        t0 = time.perf_counter()
        g = map_threshold(n, rtol)
        label = f"gamma map, {n} points" + ("" if rtol is None else f", rtol={rtol:g}")
        rows.append((label, time.perf_counter() - t0, abs(g - GAMMA_C) / GAMMA_C))
    return rows


def markdown() -> str:
    q = np.logspace(-4, 4, 512)
    sample = q[::32]
    ref = {float(s): complex(r) for s, r in zip(sample, oracle.rayleigh_branch(list(sample), *PAPER.values(),
                                                                                math.inf), strict=True)}
    lines = ["| method (512 kH, eta = inf) | time [ms] | max rel. error |", "|---|---|---|"]
    lines += [f"| {n} | {t * 1e3:.3g} | {e:.1e} |" for n, t, e in spectrum_rows(ref, q)]
    lines += ["", "| threshold vs grid resolution | time [ms] | rel. error vs oracle (12 digits) |", "|---|---|---|"]
    lines += [f"| {n} | {t * 1e3:.3g} | {e:.1e} |" for n, t, e in threshold_rows()]
    lines += ["", "| threshold read off a stability map (linear interpolation between map points) | time [ms] "
              "| rel. error vs oracle |", "|---|---|---|"]
    lines += [f"| {n} | {t * 1e3:.3g} | {e:.1e} |" for n, t, e in map_rows()]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(markdown())
