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

import model  # noqa: E402
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
        ("model.spectrum", lambda: model.spectrum(q, **PAPER), 200),
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


def threshold_rows() -> list[tuple[str, float, float]]:
    ref = 2.414880573904  # the oracle's critical gamma (tests/test_oracle.py, slow test), 12 digits
    rows = []
    for n in (11, 21, 41, 81, 161, 321):
        q = np.logspace(-3, 3, n)
        t0 = time.perf_counter()
        g = model.critical_gamma(f=0.9, beta=0.3, kH=q)
        rows.append((f"critical_gamma with {n} kH grid points", time.perf_counter() - t0, abs(g - ref) / ref))
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
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(markdown())
