"""Run time and agreement of model.growth_rate_limit (the temporal growth rate kH Im z as kH -> inf).

    python benchmarks/bench_growth_limits.py

Per seeded set at eta = inf: the limit, its family, the time of one call, and the certified sigma of the contour
solver (model.fastest_mode) at kH = 1e3 and 3e3, which approach the limit from below; then the median time over the
sets. Then the same seeded sets at finite eta (1.5 ... 100, drawn): the limit, whether the lower block's phases are
tied (eta = p/q) or free, and the time.
Timings are on this machine, while other jobs may run: compare ratios, not absolute numbers.
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide import model  # noqa: E402

SEED = 7
SETS = 10
KH_CHECK = (1e3, 3e3)


def run(n: int = SETS, seed: int = SEED) -> list[dict]:
    """Rows {params, sigma, family, seconds, sigma_at: {kH: certified sigma}}."""
    rng = np.random.default_rng(seed)
    model.growth_rate_limit(gamma=3.0, f=0.9, beta=0.3)  # warm-up
    rows = []
    for _ in range(n):
        p = dict(gamma=float(10 ** rng.uniform(-1, 2)), f=float(rng.uniform(0.2, 1.5)),
                 beta=float(rng.uniform(0.1, 0.65)), Delta=float(rng.uniform(0.3, 1.0)),
                 xi=float(rng.choice([0.0, 1.0])))
        t = time.perf_counter()
        lim = model.growth_rate_limit(**p)
        seconds = time.perf_counter() - t
        at = {}
        for kH in KH_CHECK:
            fm = model.fastest_mode(kH, **p, count=False)
            at[kH] = kH * float(fm.growth) if int(fm.status) == 0 else (0.0 if int(fm.status) == 1 else math.nan)
        rows.append(dict(params=p, sigma=float(lim.sigma), family=int(lim.family), seconds=seconds, sigma_at=at))
    return rows


def markdown(rows: list[dict]) -> str:
    lines = ["| gamma | f | beta | Delta | xi | sigma_inf | family | s per call | "
             + " | ".join(f"certified sigma at kH = {k:g}" for k in KH_CHECK) + " |",
             "|---:|---:|---:|---:|---:|---:|---:|---:|" + "---:|" * len(KH_CHECK)]
    for r in rows:
        p = r["params"]
        lines.append(f"| {p['gamma']:.3g} | {p['f']:.3g} | {p['beta']:.3g} | {p['Delta']:.3g} | {p['xi']:g} | "
                     f"{r['sigma']:.6g} | {r['family']} | {r['seconds']:.2f} | "
                     + " | ".join(f"{r['sigma_at'][k]:.6g}" for k in KH_CHECK) + " |")
    above = sum(1 for r in rows for k in KH_CHECK if r["sigma_at"][k] > r["sigma"] * (1 + 1e-6))
    lines.append("")
    lines.append(f"Median time per call {statistics.median(r['seconds'] for r in rows):.2f} s over {len(rows)} sets; "
                 f"certified sigma above the limit (relative 1e-6) at {above} of {len(rows) * len(KH_CHECK)} checks.")
    return "\n".join(lines) + "\n"


def finite_eta(n: int = SETS, seed: int = SEED) -> str:
    """The limit at finite eta on seeded sets (eta drawn log-uniform in [1.5, 100], and eta = 2, tied): a table
    and the median time per call."""
    rng = np.random.default_rng(seed + 1)
    lines = ["| gamma | f | beta | Delta | xi | eta | phases | sigma_inf | family | s per call |",
             "|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|"]
    times = []
    for i in range(n):
        p = dict(gamma=float(10 ** rng.uniform(-1, 2)), f=float(rng.uniform(0.2, 1.5)),
                 beta=float(rng.uniform(0.1, 0.65)), Delta=float(rng.uniform(0.3, 1.0)),
                 xi=float(rng.choice([0.0, 1.0])), eta=2.0 if i % 3 == 0 else float(10 ** rng.uniform(0.18, 2)))
        t = time.perf_counter()
        lim = model.growth_rate_limit(**p)
        times.append(time.perf_counter() - t)
        tied = f"tied, q = {int(lim.tied)}" if int(lim.tied) else "free"
        lines.append(f"| {p['gamma']:.3g} | {p['f']:.3g} | {p['beta']:.3g} | {p['Delta']:.3g} | {p['xi']:g} | "
                     f"{p['eta']:.4g} | {tied} | {float(lim.sigma):.6g} | {int(lim.family)} | {times[-1]:.2f} |")
    lines.append("")
    lines.append(f"Median time per call at finite eta {statistics.median(times):.2f} s over {n} sets.")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    print(markdown(run()))
    print(finite_eta())
