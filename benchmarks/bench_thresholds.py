"""Chunked stability thresholds against the per-point method (issue 13: the stability boundary of an atlas).

The chunk: gamma_c over an n x n x n grid of (f, beta, Delta) at eta = inf, xi = 1 (Sect. IV, Fig. 4c;
docs/physics.md §9), solved by model.stability.critical_gamma_chunk (one growth_chunk call per step for
every unresolved point). The per-point method is the one critical_gamma used before: a 17-value log
scan of the max growth (growth_analysis), then scipy.optimize.brentq in ln gamma, one growth_analysis
call per evaluation; it runs on a random subset, and the chunk solver on the same subset, in
alternating rounds (the machine may be shared: compare the ratios); its time for the whole grid is
estimated as that ratio times the chunk's time. The threaded run splits the grid into chunks of 256
on --workers threads (the kernels release the GIL), as a sweep engine or critical_gamma would. kH grids:
DEFAULT_KH (161 points over [1e-4, 1e4]) and logspace(-3, 3, 96).

    python benchmarks/bench_thresholds.py            # 8^3 grid; the 32^3 figures are extrapolated
    python benchmarks/bench_thresholds.py --n 32     # the full 32^3 = 32768 points (minutes)
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
from scipy import optimize

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from model import stability  # noqa: E402

GRIDS = {"DEFAULT_KH (161)": stability.DEFAULT_KH, "logspace(-3, 3, 96)": np.logspace(-3, 3, 96)}
FULL = 32**3  # points of the atlas chunk the extrapolation is for


def atlas_params(n: int) -> np.ndarray:
    """(5, n^3) rows f, beta, eta, Delta, xi: f in [0.1, 2], beta in [0.02, 0.7], Delta in [0.05, 1]; eta = inf,
    xi = 1."""
    f, beta, delta = np.meshgrid(np.linspace(0.1, 2.0, n), np.linspace(0.02, 0.7, n), np.linspace(0.05, 1.0, n),
                                 indexing="ij")
    m = f.size
    return np.stack([f.ravel(), beta.ravel(), np.full(m, math.inf), delta.ravel(), np.ones(m)])


def per_point(kH: np.ndarray, f: float, beta: float, eta: float, Delta: float, xi: float) -> tuple[float, int]:
    """(gamma_c or NaN, evaluations): the per-point method (17-value scan + brentq on growth_analysis)."""
    calls = 0

    def growth(t: float) -> float:
        nonlocal calls
        calls += 1
        return float(stability.growth_analysis(kH, gamma=math.exp(t), f=f, beta=beta, eta=eta, Delta=Delta,
                                               xi=xi).growth)

    ts = np.linspace(math.log(1e-2), math.log(1e3), 17)
    vals = [growth(t) for t in ts]
    for i in range(16):
        a, b = vals[i], vals[i + 1]
        if math.isfinite(a) and math.isfinite(b) and (a < 0) != (b < 0):
            try:
                t = optimize.brentq(growth, ts[i], ts[i + 1], xtol=1e-14, rtol=4 * np.finfo(float).eps, maxiter=200)
            except ValueError:  # NaN met inside the bracket
                return math.nan, calls
            return math.exp(t), calls
    return math.nan, calls


def threaded(s: np.ndarray, p: np.ndarray, workers: int, chunk: int = 256) -> stability.ThresholdChunk:
    """threshold_chunk over chunks of `chunk` points on `workers` threads (as a sweep engine would)."""
    parts = [p[:, i : i + chunk] for i in range(0, p.shape[1], chunk)]
    with ThreadPoolExecutor(workers) as pool:
        done = list(pool.map(lambda c: stability.threshold_chunk("gamma", s, c), parts))
    return stability.ThresholdChunk(*(np.concatenate([getattr(d, k) for d in done], axis=-1)
                                      for k in stability.ThresholdChunk.__dataclass_fields__))


def run(n: int, subset: int, rounds: int, workers: int) -> list[dict]:
    p = atlas_params(n)
    m = p.shape[1]
    sub = np.sort(np.random.default_rng(0).choice(m, size=min(subset, m), replace=False))
    rows = []
    for label, kH in GRIDS.items():
        s = np.log(kH)
        stability.threshold_chunk("gamma", s, p[:, :2])  # compile / warm up
        t0 = time.perf_counter()
        r = stability.threshold_chunk("gamma", s, p)
        t_chunk = time.perf_counter() - t0
        t0 = time.perf_counter()
        rt = threaded(s, p, workers)
        t_thr = time.perf_counter() - t0
        assert np.array_equal(rt.value, r.value, equal_nan=True)
        jump = r.reason == 5  # a sign change where the masked kH points change: located, not a threshold
        found = (r.reason == 0) | jump
        # old and new on the same subset, alternating
        t_old, t_new, diff = [], [], 0.0
        ev_old = []
        for _ in range(rounds):
            t0 = time.perf_counter()
            old = [per_point(kH, *p[:, i]) for i in sub]
            t_old.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            new = stability.threshold_chunk("gamma", s, p[:, sub])
            t_new.append(time.perf_counter() - t0)
            ev_old = [c for _, c in old]
            g_old = np.array([g for g, _ in old])
            # brentq (the per-point method) locates a jump like a root: compare where each found a sign change
            same = np.isfinite(g_old) == np.isin(new.reason, (0, 5))
            assert same.all(), "per-point and chunk disagree on which points have a sign change"
            ok = np.isfinite(g_old)
            diff = float(np.max(np.abs(new.location[ok] / g_old[ok] - 1), initial=0.0))
        ratio = statistics.median(o / w for o, w in zip(t_old, t_new, strict=True))
        per_pt_new = t_chunk / m
        rows.append(dict(
            grid=label, points=m, reasons=np.bincount(r.reason, minlength=6).tolist(), jumps=int(jump.sum()),
            evals_new=float(r.evaluations.mean()), evals_new_smooth=float(r.evaluations[found & ~jump].mean()),
            evals_new_jump=float(r.evaluations[jump].mean()) if jump.any() else math.nan,
            t_chunk=t_chunk, t_threaded=t_thr, workers=workers, ms_new=1e3 * per_pt_new,
            subset=sub.size, evals_old=float(np.mean(ev_old)), evals_new_subset=float(new.evaluations.mean()),
            ms_old=1e3 * statistics.median(t_old) / sub.size, ms_new_subset=1e3 * statistics.median(t_new) / sub.size,
            ratio=ratio, max_rel_diff=diff,
            full_1=per_pt_new * FULL, full_w=t_thr / m * FULL,
            full_old=ratio * per_pt_new * FULL,
        ))
    return rows


def table(rows: list[dict]) -> str:
    lines = [
        "| kH grid | points | reasons 0/1/2/3/4/5 | jumps | evals/pt (smooth, jump) | chunk s (ms/pt) "
        "| threads s | 32^3 est. 1 thread / threads / per-point [s] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['grid']} | {r['points']} | {'/'.join(map(str, r['reasons']))} | {r['jumps']} "
            f"| {r['evals_new']:.1f} ({r['evals_new_smooth']:.1f}, {r['evals_new_jump']:.1f}) "
            f"| {r['t_chunk']:.2f} ({r['ms_new']:.2f}) | {r['t_threaded']:.2f} ({r['workers']}) "
            f"| {r['full_1']:.0f} / {r['full_w']:.0f} / {r['full_old']:.0f} |")
    lines += ["", "| kH grid | subset | per-point evals/pt, ms/pt | chunk evals/pt, ms/pt | time ratio per-point/chunk "
              "| max rel. diff of the sign change's location |", "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(
            f"| {r['grid']} | {r['subset']} | {r['evals_old']:.1f}, {r['ms_old']:.2f} "
            f"| {r['evals_new_subset']:.1f}, {r['ms_new_subset']:.2f} | {r['ratio']:.2f} | {r['max_rel_diff']:.1e} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=8, help="grid points per axis (default 8; the atlas uses 32)")
    ap.add_argument("--subset", type=int, default=64, help="points for the per-point comparison")
    ap.add_argument("--rounds", type=int, default=3, help="alternating per-point / chunk rounds on the subset")
    ap.add_argument("--workers", type=int, default=2, help="threads for the chunked run")
    a = ap.parse_args()
    print(table(run(a.n, a.subset, a.rounds, a.workers)))
