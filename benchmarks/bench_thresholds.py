"""Thresholds before and after issue 24 (certified neutral modes), interleaved in one run, and the 32^3 gamma_c surface.

Before: revision BEFORE_BOUNDARY's threshold_chunk (a 17-value scan of the grid-refined max growth, then Brent's
method in ln gamma; a jump of the max growth flagged by the masked kH points). After: this tree's crossings_chunk
(the continuous max growth, every crossing solved as a neutral mode and certified twice). Both on the same points of
the atlas grid (f in [0.1, 2], beta in [0.02, 0.7], Delta in [0.05, 1]; eta = inf, xi = 1; Sect. IV, Fig. 4c;
docs/physics.md §9), DEFAULT_KH, gamma in [1e-2, 1e3]. Each point is solved alone, old and new alternately (the
machine may be shared: compare the ratio), so the per-point times have a median; the old revision runs in a
process of its own (OldRevision). Then the whole 32^3 surface with
this tree on --workers threads (chunks of 256 points, as critical_gamma and the sweep engine do).

    python benchmarks/bench_thresholds.py                 # 256 points A/B, then the 32^3 surface
    python benchmarks/bench_thresholds.py --subset 64 --n 8
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide.model import thresholds  # noqa: E402
from benchmarks.bench_revision_ab import IMPORT_MODEL  # noqa: E402

#: the commit this work started from (issue 24): thresholds by Brent's method on the grid-refined max growth
BEFORE_BOUNDARY = "b57a94c"
S = np.log(thresholds.DEFAULT_KH)


def atlas_params(n: int) -> np.ndarray:
    """(5, n^3) rows f, beta, eta, Delta, xi: f in [0.1, 2], beta in [0.02, 0.7], Delta in [0.05, 1]; eta = inf,
    xi = 1."""
    f, beta, delta = np.meshgrid(np.linspace(0.1, 2.0, n), np.linspace(0.02, 0.7, n), np.linspace(0.05, 1.0, n),
                                 indexing="ij")
    m = f.size
    return np.stack([f.ravel(), beta.ravel(), np.full(m, math.inf), delta.ravel(), np.ones(m)])


#: the process that times the old revision: its own `model` package (numba's cache of one process must never see
#: two packages with the same kernels: a cache entry written with the other's record types cannot be read back)
OLD_WORKER = IMPORT_MODEL + """
import json, time
import numpy as np
s = np.log(np.logspace(-4, 4, 161))
for line in sys.stdin:
    p = np.array(json.loads(line), dtype=float)[:, None]
    t0 = time.perf_counter()
    r = model.threshold_chunk("gamma", s, p)
    t = time.perf_counter() - t0
    print(json.dumps([t, float(r.value[0]), int(r.reason[0]), int(r.evaluations[0])]), flush=True)
"""


class OldRevision:
    """The thresholds of git revision `rev`, timed in a process of their own (see OLD_WORKER)."""

    def __init__(self, rev: str, target: Path) -> None:
        from benchmarks.bench_revision_ab import export_revision, model_name

        export_revision(rev, target)
        env = dict(os.environ, PYTHONPATH="")
        self.proc = subprocess.Popen([sys.executable, "-c", OLD_WORKER, str(target), model_name(rev)],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env, cwd=target)

    def threshold(self, p: np.ndarray) -> tuple[float, float, int, int]:
        """(seconds, threshold, reason, evaluations) of one parameter set (column of (5, n) rows)."""
        self.proc.stdin.write(json.dumps([float(x) for x in p]) + "\n")  # inf as Infinity
        self.proc.stdin.flush()
        t, value, reason, evals = json.loads(self.proc.stdout.readline())
        return t, value, reason, evals

    def close(self) -> None:
        self.proc.stdin.close()
        self.proc.wait(timeout=60)


def per_point_ab(old: OldRevision, p: np.ndarray, rounds: int) -> dict:
    """Each point alone, old then new, `rounds` times: per-point times (ms, medians over rounds) and the results."""
    n = p.shape[1]
    t_old = np.zeros((rounds, n))
    t_new = np.zeros((rounds, n))
    old.threshold(p[:, 0])  # compile / load both
    thresholds.crossings_chunk("gamma", S, p[:, :1])
    r_old = r_new = None
    for k in range(rounds):
        r_old, r_new = [], []
        for i in range(n):
            t_old[k, i], *res = old.threshold(p[:, i])
            r_old.append(res)
            t0 = time.perf_counter()
            r_new.append(thresholds.crossings_chunk("gamma", S, p[:, i : i + 1]))
            t_new[k, i] = time.perf_counter() - t0
    ms_old, ms_new = 1e3 * np.median(t_old, axis=0), 1e3 * np.median(t_new, axis=0)
    return dict(ms_old=ms_old, ms_new=ms_new, ratio=float(np.median(ms_new / ms_old)), r_old=r_old, r_new=r_new)


def agreement(r_old: list, r_new: list) -> dict:
    """How the old and the new thresholds compare: both found, found by one only, relative differences."""
    v_old = np.array([r[0] for r in r_old])
    reason_old = np.array([r[1] for r in r_old])
    v_new = np.array([r.first[0] for r in r_new])
    both = np.isfinite(v_old) & np.isfinite(v_new)
    diff = np.abs(v_new[both] / v_old[both] - 1)
    return dict(both=int(both.sum()), old_only=int((np.isfinite(v_old) & ~np.isfinite(v_new)).sum()),
                new_only=int((~np.isfinite(v_old) & np.isfinite(v_new)).sum()),
                old_jumps=int((reason_old == 5).sum()), max_diff=float(diff.max(initial=0.0)),
                median_diff=float(np.median(diff)) if diff.size else math.nan,
                new_complete=int(sum(bool(r.complete[0]) for r in r_new)),
                evals_old=float(np.mean([r[2] for r in r_old])),
                evals_new=float(np.mean([r.evaluations[0] for r in r_new])))


def surface(n: int, workers: int) -> tuple[float, thresholds.Crossings]:
    """Wall time of every crossing of the n^3 atlas grid on `workers` threads (chunks of 256 points)."""
    p = atlas_params(n)
    parts = [p[:, i : i + thresholds.CHUNK] for i in range(0, p.shape[1], thresholds.CHUNK)]
    t0 = time.perf_counter()
    with ThreadPoolExecutor(workers) as pool:
        done = list(pool.map(lambda c: thresholds.crossings_chunk("gamma", S, c), parts))
    t = time.perf_counter() - t0
    fields = {k: np.concatenate([getattr(d, k) for d in done]) for k in thresholds.Crossings.__dataclass_fields__
              if k != "parameter"}
    return t, thresholds.Crossings(**fields)


def run(subset: int = 256, rounds: int = 3, n: int = 32, workers: int = 2, seed: int = 0) -> dict:
    full = atlas_params(32)
    pick = np.sort(np.random.default_rng(seed).choice(full.shape[1], size=subset, replace=False))
    with tempfile.TemporaryDirectory() as tmp:
        old = OldRevision(BEFORE_BOUNDARY, Path(tmp))
        try:
            ab = per_point_ab(old, full[:, pick], rounds)
        finally:
            old.close()
    agree = agreement(ab["r_old"], ab["r_new"])
    t_surface, c = surface(n, workers)
    return dict(ab=ab, agree=agree, n=n, workers=workers, t_surface=t_surface, surface=c, subset=subset,
                rounds=rounds)


def table(res: dict) -> str:
    ab, ag, c = res["ab"], res["agree"], res["surface"]
    lines = [f"{res['subset']} random points of the 32^3 atlas grid (f, beta, Delta; eta = inf, xi = 1), DEFAULT_KH, "
             f"gamma in [1e-2, 1e3]; each point alone, before (revision {BEFORE_BOUNDARY}: scan + Brent on the "
             "grid-refined max growth) and after (certified neutral modes) alternately, medians of "
             f"{res['rounds']} rounds.", "",
             "| | before | after |", "|---|---|---|",
             f"| per-point time, median [ms] | {np.median(ab['ms_old']):.2f} | {np.median(ab['ms_new']):.2f} |",
             f"| per-point time, mean [ms] | {np.mean(ab['ms_old']):.2f} | {np.mean(ab['ms_new']):.2f} |",
             f"| per-point time, 90th percentile [ms] | {np.percentile(ab['ms_old'], 90):.2f} "
             f"| {np.percentile(ab['ms_new'], 90):.2f} |",
             f"| growth evaluations per point, mean | {ag['evals_old']:.1f} | {ag['evals_new']:.1f} |",
             "", f"Median of the per-point ratios after/before: {ab['ratio']:.2f} (target <= 1). Thresholds found by "
                 f"both: {ag['both']}, max relative difference {ag['max_diff']:.1e} (median {ag['median_diff']:.1e}); "
                 f"found before only {ag['old_only']}, after only {ag['new_only']}; jumps flagged before: "
                 f"{ag['old_jumps']}; every crossing certified after: {ag['new_complete']} of {res['subset']}.",
             "", f"Every crossing of the {res['n']}^3 surface on {res['workers']} threads: {res['t_surface']:.1f} s "
                 f"(target <= 120 s); every crossing certified at {100 * c.complete.mean():.1f} % of the points, a "
                 f"certified threshold at {100 * (c.status == 0).mean():.1f} %; crossings per point "
                 f"{dict(enumerate(np.bincount(c.count).tolist()))}; reasons of the crossings "
                 f"{dict(enumerate(np.bincount(c.reason[c.reason >= 0], minlength=7).tolist()))} "
                 "(model.CROSSING_STATUS)."]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--subset", type=int, default=256, help="points of the A/B (default 256)")
    ap.add_argument("--rounds", type=int, default=3, help="alternating rounds of the A/B")
    ap.add_argument("--n", type=int, default=32, help="grid points per axis of the surface (default 32)")
    ap.add_argument("--workers", type=int, default=2, help="threads for the surface")
    a = ap.parse_args()
    print(table(run(a.subset, a.rounds, a.n, a.workers)))
