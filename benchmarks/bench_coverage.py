"""Coverage of the stability boundary (issue 24): how much of an atlas gets a certified answer, per eta.

The 16 x 8 x 8 x 8 grid of the issue: gamma in [0.1, 30] (16 values, log), f in [0.2, 1.2], beta in [0.08, 0.68],
Delta in [0.2, 1] (8 values each), xi = 1, kH in [1e-3, 1e3] (the atlases' default grid), at eta = inf, 100, 10, 2.
Per eta:

- crossings: the fraction of the 512 (f, beta, Delta) points whose crossings in gamma in [0.1, 30] are all certified
  (model.crossings_chunk: neutral modes; jumps, pole-dense modes and undefined stretches count against it), with
  the reasons of the others;
- verdicts: the fraction of the 8192 cells with a certified verdict (stable or unstable, model.growth_chunk), with
  the reasons of the undetermined ones.

    python benchmarks/bench_coverage.py [--n 8] [--gammas 16]
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide import model  # noqa: E402
from asymslide.atlas import plan  # noqa: E402

ETAS = (math.inf, 100.0, 10.0, 2.0)
GAMMA_RANGE = (0.1, 30.0)
TARGET = 0.95


def grid(n: int, eta: float) -> np.ndarray:
    """(5, n^3) rows f, beta, eta, Delta, xi of the (f, beta, Delta) grid."""
    f, b, d = np.meshgrid(np.linspace(0.2, 1.2, n), np.linspace(0.08, 0.68, n), np.linspace(0.2, 1.0, n),
                          indexing="ij")
    m = f.size
    return np.stack([f.ravel(), b.ravel(), np.full(m, eta), d.ravel(), np.ones(m)])


def one_eta(eta: float, n: int, n_gamma: int) -> dict:
    """Crossings over the (f, beta, Delta) points and verdicts over the (gamma, f, beta, Delta) cells at one eta."""
    s = np.log(plan.DEFAULT_KH)
    p = grid(n, eta)
    t0 = time.perf_counter()
    c = model.crossings_chunk("gamma", s, p, GAMMA_RANGE)
    t_cross = time.perf_counter() - t0
    gammas = np.geomspace(*GAMMA_RANGE, n_gamma)
    cells = np.vstack([np.tile(gammas, p.shape[1]), np.repeat(p, n_gamma, axis=1)])
    t0 = time.perf_counter()
    reason = model.growth_chunk(s, cells)[7].astype(int)
    t_growth = time.perf_counter() - t0
    verdict = model.verdict_class(reason)
    jumps = np.isin(c.reason, (2, 3)).any(axis=1)
    jump_deltas = dict(zip(*np.unique(np.round(p[3, jumps], 3), return_counts=True), strict=True))
    return dict(jump_deltas={float(k): int(v) for k, v in jump_deltas.items()},
                eta=eta, points=p.shape[1], cells=cells.shape[1], complete=float(c.complete.mean()),
                crossing_reasons=np.bincount(c.reason[c.reason >= 0], minlength=len(model.CROSSING_STATUS)),
                counts=np.bincount(c.count), certified=float(np.isin(verdict, (0, 1)).mean()),
                stable=float((verdict == 0).mean()), unstable=float((verdict == 1).mean()),
                verdict_reasons=np.bincount(reason, minlength=len(model.VERDICT_STATUS)),
                pole_dense_gammas=_pole_dense_gammas(reason.reshape(-1, n_gamma), gammas),
                t_cross=t_cross, t_growth=t_growth)


def _pole_dense_gammas(reason: np.ndarray, gammas: np.ndarray) -> str:
    """The gamma values at which some cell is pole-dense, with the fraction of cells there."""
    frac = (reason == 4).mean(axis=0)
    return ", ".join(f"{g:.3g}: {100 * x:.0f} %" for g, x in zip(gammas, frac, strict=True) if x > 0) or "none"


def run(n: int = 8, n_gamma: int = 16) -> list[dict]:
    return [one_eta(eta, n, n_gamma) for eta in ETAS]


def table(rows: list[dict]) -> str:
    lines = [f"{rows[0]['points']} (f, beta, Delta) points x {rows[0]['cells'] // rows[0]['points']} gamma values in "
             f"[{GAMMA_RANGE[0]:g}, {GAMMA_RANGE[1]:g}], xi = 1, kH in [1e-3, 1e3]. Target: {100 * TARGET:.0f} % for "
             "both fractions at every eta.", "",
             "| eta | points with every crossing certified | cells with a certified verdict (stable / unstable) "
             "| crossing reasons 0..6 | undetermined cells by reason 2..5 | time crossings / growth [s] |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        eta = "inf" if math.isinf(r["eta"]) else f"{r['eta']:g}"
        vr = r["verdict_reasons"]
        lines.append(f"| {eta} | {100 * r['complete']:.1f} % | {100 * r['certified']:.1f} % ({100 * r['stable']:.1f} "
                     f"/ {100 * r['unstable']:.1f}) | {'/'.join(map(str, r['crossing_reasons']))} | "
                     f"{'/'.join(map(str, vr[2:]))} | {r['t_cross']:.1f} / {r['t_growth']:.1f} |")
    lines += ["", "Crossing reasons (model.CROSSING_STATUS): " + "; ".join(
        f"{k} {v.split(':')[0]}" for k, v in model.CROSSING_STATUS.items()) + ". Verdict reasons "
        "(model.VERDICT_STATUS): 2 branch lost on part of the range, 3 no branch, 4 pole-dense, 5 marginal."]
    for r in rows:
        eta = "inf" if math.isinf(r["eta"]) else f"{r['eta']:g}"
        if r["jump_deltas"]:
            lines.append(f"- eta = {eta}: points with a jump, by Delta: {r['jump_deltas']}")
    for r in rows:
        if r["verdict_reasons"][4]:
            eta = "inf" if math.isinf(r["eta"]) else f"{r['eta']:g}"
            lines.append(f"- eta = {eta}: pole-dense cells at gamma = {r['pole_dense_gammas']}")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=8, help="points per axis of (f, beta, Delta) (default 8)")
    ap.add_argument("--gammas", type=int, default=16, help="gamma values of the verdict cells (default 16)")
    a = ap.parse_args()
    print(table(run(a.n, a.gammas)))
