"""Benchmark of model.sliding_analysis (issue 31): cost per parameter set, and how often sliding (every branch)
and the Rayleigh branch disagree; the fastest root against the oracle.

The samples are issue 31's: 120 random points each at eta = inf, 10 and 2 with gamma in [0.1, 30] (log), f in
[0.2, 1.2], beta in [0.08, 0.68], Delta in [0.2, 1], xi = 1, on the default kH grid (model.SLIDING_KH, 17 points
over [1e-2, 1e2]) and the default floor 1e-6. Each point is one call of model.sliding_analysis (warm: the kernels
are compiled before the first timed call), which also gives the Rayleigh branch alone on the same grid
(`.rayleigh`, model.growth_analysis). Each set is timed three times and the shortest run kept (the search is
deterministic; longer runs measure other load). Timings are on this machine while other jobs may run: compare
ratios.
Run ``python benchmarks/bench_sliding.py`` (about 5 minutes).
"""

from __future__ import annotations

import json
import math
import statistics
import sys
import time
from collections import Counter
from functools import partial
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide import model  # noqa: E402
from tests import oracle  # noqa: E402

ETAS = (math.inf, 10.0, 2.0)
N = 120
SEED = 31
VERDICT = {0: "stable", 1: "unstable", 2: "undetermined"}
REPEAT = 3  # each set is timed REPEAT times and the shortest kept


def sample(eta: float, n: int = N, seed: int = SEED) -> list[dict]:
    """Issue 31's random parameter sets at one eta."""
    rng = np.random.default_rng([seed, 0 if math.isinf(eta) else int(eta)])
    return [dict(gamma=float(10 ** rng.uniform(-1, math.log10(30))), f=float(rng.uniform(0.2, 1.2)),
                 beta=float(rng.uniform(0.08, 0.68)), Delta=float(rng.uniform(0.2, 1.0)), xi=1.0, eta=eta)
            for _ in range(n)]


def run(etas: tuple[float, ...] = ETAS, n: int = N) -> dict[float, list[dict]]:
    """Per eta, one record per point: the time, both verdicts, both growths and the family at the maximum."""
    model.sliding_analysis(gamma=3.0, f=0.9, beta=0.3)  # compile / load the kernels
    model.sliding_analysis(gamma=3.0, f=0.9, beta=0.3, eta=10.0)
    out: dict[float, list[dict]] = {}
    for eta in etas:
        rows = []
        for p in sample(eta, n):
            dt = math.inf
            for _ in range(REPEAT):  # the best of REPEAT runs (the search is deterministic: the rest is other load)
                t0 = time.perf_counter()
                r = model.sliding_analysis(**p)
                dt = min(dt, time.perf_counter() - t0)
            rows.append(dict(p=p, seconds=dt, rayleigh=int(r.rayleigh.verdict), sliding=int(r.verdict),
                             reason=int(r.verdict_reason), g_r=float(r.rayleigh.growth), g_s=float(r.growth),
                             family=int(r.family), kH=float(r.kH_at_max), at_end=bool(r.max_at_end)))
        out[eta] = rows
    return out


def _eta(eta: float) -> str:
    return "inf" if math.isinf(eta) else f"{eta:g}"


def markdown(results: dict[float, list[dict]]) -> str:
    """The cost table, the verdict table and the families at the maximum."""
    lines = ["Cost per parameter set of `model.sliding_analysis` (17 kH over [1e-2, 1e2], floor 1e-6; the shortest of "
             f"{REPEAT} runs; targets of issue 31: median <= 10 ms at eta = inf, <= 100 ms at eta = 10):", "",
             "| eta | points | median [ms] | 90th percentile [ms] | max [ms] |", "|---|---|---|---|---|"]
    for eta, rows in results.items():
        ms = sorted(1e3 * r["seconds"] for r in rows)
        lines.append(f"| {_eta(eta)} | {len(rows)} | {statistics.median(ms):.1f} | {ms[int(0.9 * (len(ms) - 1))]:.1f} "
                     f"| {ms[-1]:.1f} |")
    lines += ["", "Verdicts (Rayleigh branch alone -> sliding, every branch), and where sliding is unstable how the "
              "fastest root compares with the Rayleigh branch's maximum:", "",
              "| eta | Rayleigh stable -> sliding unstable | Rayleigh stable -> sliding stable | Rayleigh unstable "
              "-> sliding unstable | Rayleigh undetermined -> sliding (stable / unstable / undetermined) | sliding "
              "undetermined | fastest root faster than the Rayleigh branch (x1.01) | maximum at an end of the kH range "
              "| families at the maximum |",
              "|---|---|---|---|---|---|---|---|---|"]
    for eta, rows in results.items():
        pairs = Counter((r["rayleigh"], r["sliding"]) for r in rows)
        n_ray0 = sum(v for (a, _), v in pairs.items() if a == 0)
        n_ray1 = sum(v for (a, _), v in pairs.items() if a == 1)
        und = "/".join(str(pairs[(2, b)]) for b in (0, 1, 2))
        faster = sum(1 for r in rows if r["sliding"] == 1 and math.isfinite(r["g_s"])
                     and (r["rayleigh"] != 1 or r["g_s"] > 1.01 * r["g_r"]))
        fams = Counter(model.FAMILIES.get(r["family"], "maximum not certified").split(" (")[0] for r in rows
                       if r["sliding"] == 1)
        ends = sum(1 for r in rows if r["sliding"] == 1 and r["at_end"])
        fam_text = ", ".join(f"{k}: {v}" for k, v in sorted(fams.items()))
        n_und = sum(1 for r in rows if r["sliding"] == 2)
        lines.append(f"| {_eta(eta)} | {pairs[(0, 1)]} of {n_ray0} | {pairs[(0, 0)]} of {n_ray0} | {pairs[(1, 1)]} of "
                     f"{n_ray1} | {und} | {n_und} | {faster} | {ends} | {fam_text} |")
    reasons = Counter((_eta(eta), r["reason"]) for eta, rows in results.items() for r in rows
                      if r["sliding"] == 2 or r["reason"] == 4)
    if reasons:
        lines += ["", "Undetermined or uncertified maxima: " + ", ".join(
            f"eta = {e}: {n} x '{model.SLIDING_STATUS[c]}'" for (e, c), n in sorted(reasons.items()))]
    return "\n".join(lines) + "\n"


DENSE_LIMITS = {math.inf: N, 10.0: 40, 2.0: 30}  # sets compared with a dense kH grid, per eta


def dense_results(results: dict[float, list[dict]], n_dense: int = 129,
                  limits: dict | None = None) -> dict[float, list[tuple[float, int]]]:
    """(growth, verdict) on a grid of n_dense points over the same range, for the first sets of each eta."""
    limits = DENSE_LIMITS if limits is None else limits
    grid = np.logspace(-2, 2, n_dense)
    out = {}
    for eta, n in limits.items():
        out[eta] = []
        for r in results.get(eta, [])[:n]:
            d = model.sliding_analysis(**r["p"], kH=grid)
            out[eta].append((float(d.growth), int(d.verdict)))
    return out


def _differ(rows: list[dict], dense: list[tuple[float, int]]) -> tuple[int, list[float], int]:
    """(sets differing from the dense grid, dense / default maxima where both unstable, verdicts differing)."""
    diff, ratios, verdicts = 0, [], 0
    for r, (gd, vd) in zip(rows, dense, strict=False):
        ga = r["g_s"]
        same_v = vd == r["sliding"]
        same_g = (math.isnan(gd) and math.isnan(ga)) or abs(gd - ga) <= 1e-9 * max(abs(gd), 1e-300)
        if not (same_v and same_g):
            diff += 1
            verdicts += not same_v
            if same_v and math.isfinite(gd) and math.isfinite(ga) and ga > 0:
                ratios.append(gd / ga)
    return diff, ratios, verdicts


def denser_grid(results: dict[float, list[dict]], dense: dict[float, list[tuple[float, int]]],
                n_dense: int = 129) -> str:
    """How often the default 17-point grid's verdict or maximum differs from a grid of n_dense points over the same
    range (the roots the search misses between grid points, docs/physics.md §14.7)."""
    lines = [f"\nAgainst a {n_dense}-point kH grid over the same range (same floor): sets whose verdict or maximum (to "
             "1e-9 relative) differs from the default grid's, and by how much the dense grid's maximum is larger:", "",
             "| eta | sets | differ | dense / default maximum (where both unstable) | verdicts differ |",
             "|---|---|---|---|---|"]
    for eta, dn in dense.items():
        diff, ratios, verdicts = _differ(results.get(eta, [])[: len(dn)], dn)
        rtext = ", ".join(f"{x:.3g}" for x in sorted(ratios)) or "-"
        lines.append(f"| {_eta(eta)} | {len(dn)} | {diff} | {rtext} | {verdicts} |")
    return "\n".join(lines) + "\n"


def track_fraction(results: dict[float, list[dict]], dense: dict[float, list[tuple[float, int]]],
                   fractions: tuple[float, ...] = (0.25, 0.5)) -> str:
    """Run time against error of the level of the between-grid tracking at finite eta (model.sliding's
    TRACK_FRACTION_FINITE: roots above that fraction of the maximum at a grid point are followed): the median cost
    and the sets differing from the dense grid, on the sets compared with it."""
    from asymslide.model._roots import track as sliding  # the tracking constants live in the root engine

    lines = ["\nThe between-grid tracking at finite eta (roots above a fraction of the maximum M at a grid point are "
             f"followed; the default is M x {sliding.TRACK_FRACTION_FINITE:g}): cost against the sets differing from "
             "the dense grid:", "", "| eta | fraction of M | sets | median [ms] | differ | dense / default maximum |",
             "|---|---|---|---|---|---|"]
    default = sliding.TRACK_FRACTION_FINITE
    try:
        for eta, dn in dense.items():
            if math.isinf(eta):
                continue
            for frac in fractions:
                sliding.TRACK_FRACTION_FINITE = frac
                rows = run((eta,), len(dn))[eta]
                diff, ratios, _ = _differ(rows, dn)
                ms = statistics.median(1e3 * r["seconds"] for r in rows)
                rtext = ", ".join(f"{x:.3g}" for x in sorted(ratios)) or "-"
                lines.append(f"| {_eta(eta)} | {frac:g} | {len(rows)} | {ms:.1f} | {diff} | {rtext} |")
    finally:
        sliding.TRACK_FRACTION_FINITE = default
    return "\n".join(lines) + "\n"


def oracle_errors(n: int = 8) -> str:
    """The fastest root and the count above the floor against the oracle on a few of the test's random cases."""
    from tests.model.test_sliding import ORACLE_CASES

    worst, agree, roots = 0.0, 0, 0
    for kH, p, floor in ORACLE_CASES[:: max(1, len(ORACLE_CASES) // n)]:
        fm = model.fastest_mode(kH, **p, floor=floor)
        args = dict(gamma=p["gamma"], f=p["f"], beta=p["beta"], eta=p.get("eta", math.inf),
                    Delta=p.get("Delta", 1.0), xi=p.get("xi", 0.0))
        z_o, n_o = oracle.fastest_root(kH, **args, re_max=float(fm.re_max), im_min=floor, im_max=float(fm.im_max))
        agree += int(fm.count) == n_o
        if z_o is not None:
            roots += 1
            worst = max(worst, abs(complex(fm.z) - complex(z_o)) / abs(complex(z_o)))
    return (f"\nAgainst the oracle (tests/oracle.py §8, 20 digits, its own contour sampling) on "
            f"{len(ORACLE_CASES[:: max(1, len(ORACLE_CASES) // n)])} of tests/model/test_sliding.py's random cases: "
            "counts "
            f"above the floor equal in {agree}; the fastest root's largest relative error {worst:.1e} "
            f"({roots} cases with a root).\n")


def rate_cost(n: int = 12, etas: tuple[float, ...] = (10.0, 2.0, 1e3)) -> str:
    """The temporal rate's maximum at finite eta (docs/physics.md §14.15): on the first n of issue 31's sets at each
    eta, how many rates ``sliding_analysis(rate=True)`` certifies (among the unstable sets) and its time, beside the
    same call without the rate (one run each: the guide and the limit make repeats long)."""
    lines = ["", "The temporal rate's maximum at finite eta (`sliding_analysis(rate=True)`, the first "
             f"{n} of the sets above per eta; its time includes `rate_limit`):", "",
             "| eta | unstable | rate certified | median time, rate | max | median time, no rate |",
             "|---|---:|---:|---:|---:|---:|"]
    for eta in etas:
        unstable = certified = 0
        t_rate, t_plain = [], []
        for p in sample(eta, n):
            t0 = time.perf_counter()
            plain = model.sliding_analysis(**p)
            t_plain.append(time.perf_counter() - t0)
            t0 = time.perf_counter()
            r = model.sliding_analysis(**p, rate=True)
            t_rate.append(time.perf_counter() - t0)
            if int(r.verdict) == 1 or int(plain.verdict) == 1:
                unstable += 1
                certified += bool(np.isfinite(r.rate))
        lines.append(f"| {_eta(eta)} | {unstable} | {certified} | {statistics.median(t_rate):.2f} s | "
                     f"{max(t_rate):.2f} s | {statistics.median(t_plain):.2f} s |")
    return "\n".join(lines) + "\n"


def atlas_cost(n: int = 12) -> str:
    """An atlas with both verdicts against the Rayleigh branch alone: a dense n x n sweep over gamma in [0.3, 30] (log)
    and beta in [0.1, 0.65] at eta = inf (f = 0.9), in memory on this machine's threads, with and without
    ``sliding=True`` (asymslide sweep --sliding), the shortest of two runs each; and how often the verdicts differ."""
    from asymslide.atlas import sweep as S

    axes = {"gamma": np.geomspace(0.3, 30, n), "beta": np.linspace(0.1, 0.65, n)}
    S.sweep({"gamma": [3.0]}, gamma_c=False, sliding=True)  # warm: kernels and Dask
    times = {}
    ds = None
    for sliding in (False, True):
        best = math.inf
        for _ in range(2):
            t0 = time.perf_counter()
            ds = S.sweep(axes, fixed={"f": 0.9}, gamma_c=False, sliding=sliding)
            best = min(best, time.perf_counter() - t0)
        times[sliding] = best
    r, v = ds["verdict"].values, ds["verdict_all"].values
    return (f"\nAn atlas of both verdicts (`asymslide sweep --sliding`; dense {n} x {n} over gamma 0.3..30 (log) x "
            f"beta 0.1..0.65, f = 0.9, eta = inf, in memory, the shortest of 2 runs): Rayleigh branch alone "
            f"{times[False]:.2f} s ({1e3 * times[False] / n**2:.1f} ms a point), with the sliding verdict "
            f"{times[True]:.2f} s ({1e3 * times[True] / n**2:.1f} ms a point, {times[True] / times[False]:.1f}x); "
            f"Rayleigh-stable cells sliding-unstable: {int(((r == 0) & (v == 1)).sum())} of {int((r == 0).sum())}; "
            f"sliding undetermined: {int((v == 2).sum())}.\n")


def map_cost(plane: str = "β-γ", resolution: str = "medium") -> str:
    """The Stability map of both verdicts as the app computes it (issue 32 point 6): the Rayleigh branch's map
    (app.stability_map.compute.compute_map), then the sliding verdict in coarse-to-fine passes (app.sliding_map), on one
    job thread with empty caches; against the model's own cost, model.sliding_analysis over the same grid in one
    call. Reported: the time to the first coarse view (the Rayleigh map + the first pass) and to the whole map, and
    the app's overhead over the model."""
    from asymslide.app import jobs
    from asymslide.app import sliding_map as slm
    from asymslide.app.params import SpectrumParams
    from asymslide.app.stability_map import compute, grids
    from asymslide.app.stability_map.scene import StabilityMapScene

    scene = StabilityMapScene(plane=plane, resolution=resolution, params=SpectrumParams())
    key, skey = scene.map_key, scene.sliding_key
    n = key[1]
    x, y = grids.plane_axes(plane, n)
    names = (grids.PLANES[plane][0].name, grids.PLANES[plane][1].name)
    args = dict(zip(SpectrumParams.MODEL_ARGS, SpectrumParams().model_args(), strict=True))
    args[names[0]], args[names[1]] = x[None, :], y[:, None]
    model.sliding_analysis(**{**args, names[0]: x[None, :2], names[1]: y[:2, None]})  # warm
    t0 = time.perf_counter()
    model.sliding_analysis(**args, floor=skey[-1])
    t_model = time.perf_counter() - t0
    compute.CHUNKS.clear()
    t0 = time.perf_counter()
    jobs.Job(lambda job: compute.compute_map(key, job), name="map").start().wait(None)
    t_rayleigh = time.perf_counter() - t0
    first: list[float] = []
    job = jobs.Job(lambda job: slm.compute_sliding_map(skey, x, y, names, compute.CHUNKS.get, compute.CHUNKS.put, job),
                   name="sliding map")
    job.subscribe(lambda: first.append(time.perf_counter()) if job.state().partial is not None and not first else None)
    t0 = time.perf_counter()
    job.start().wait(None)
    t_sliding = time.perf_counter() - t0
    t_first = first[0] - t0
    budget = t_rayleigh + t_model
    return (f"\nThe Stability map of both verdicts as the app computes it ({plane}, {resolution} {n} x {n}, paper "
            f"defaults, floor {skey[-1]:g}, empty caches): the Rayleigh branch's map {t_rayleigh:.2f} s; the sliding "
            f"verdict's first coarse view (every {slm.STRIDES[0]}th point) {t_first:.2f} s after it, the whole map "
            f"{t_sliding:.2f} s after it ({1e3 * t_sliding / n**2:.1f} ms a point). The model alone over the same "
            f"grid in one call: {t_model:.2f} s ({1e3 * t_model / n**2:.1f} ms a point). Target (issue 32): the "
            f"whole map within the Rayleigh map + the model's cost = {budget:.2f} s; measured "
            f"{t_rayleigh + t_sliding:.2f} s ({(t_rayleigh + t_sliding) / budget:.2f} of it); the first coarse view "
            f"at {t_rayleigh + t_first:.2f} s.\n")


def adaptive_atlas(n: int = 33, sample: int = 400, seed: int = 32) -> str:
    """A 33^3 adaptive atlas on the sliding verdict at eta = inf (issue 32 point 6; ``asymslide sweep --adaptive
    --verdict sliding``): gamma in [0.1, 30] (log), f in [0.1, 1.5], beta in [0.05, 0.7], xi = 1, the default
    refinement and sliding spec, into a Zarr store (the sliding tasks in one process per core: they hold the GIL).
    Reported: the wall time, the evaluated
    fraction per level, and against the dense model call at `sample` random points (half among the filled, half
    among the computed ones): both filled verdicts' agreement, the values' bitwise equality, and the dense sweep's
    time estimated from those calls' cost per point."""
    import tempfile

    from asymslide.atlas import adaptive as A
    from asymslide.atlas import plan as atlas_plan
    from asymslide.atlas import refinement, schema
    from asymslide.atlas import sweep as S
    from asymslide.atlas import tasks as atlas_tasks

    axes = {"gamma": np.geomspace(0.1, 30, n), "f": np.linspace(0.1, 1.5, n), "beta": np.linspace(0.05, 0.7, n)}
    fixed = {"eta": math.inf, "xi": 1.0}
    S.sweep({"gamma": [3.0]}, fixed=fixed, gamma_c=False, sliding=True)  # warm: kernels and Dask
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        ds = S.sweep(axes, fixed=fixed, gamma_c=False, adaptive=refinement.AdaptiveSpec(verdict="sliding"),
                     store=Path(tmp) / "adaptive.zarr").load()
        t_adaptive = time.perf_counter() - t0
    summary = json.loads(ds.attrs["adaptive"])
    computed = ds["computed"].values
    rng = np.random.default_rng(seed)
    picks = np.concatenate([rng.choice(np.flatnonzero(mask.ravel()), sample // 2, replace=False)
                            for mask in (computed < 0, computed >= 0)])
    plan = atlas_plan.make_plan(axes, fixed=fixed, gamma_c=False,
                                adaptive=refinement.AdaptiveSpec(verdict="sliding"))
    params = A._Grid(plan).params(picks)
    t0 = time.perf_counter()
    dense = {**atlas_tasks.growth_arrays(np.log(np.asarray(plan.kH)), params, plan.rtol),
             **atlas_tasks.sliding_arrays(plan.sliding, params)}
    per_point = (time.perf_counter() - t0) / picks.size
    filled, done = picks[: sample // 2], picks[sample // 2:]
    differ = {name: int((ds[f"verdict_filled{suffix}"].values.ravel()[filled] != dense[name][: sample // 2]).sum())
              for name, suffix in (("verdict", ""), ("verdict_all", "_all"))}
    bitwise = all(np.array_equal(ds[name].values.ravel()[done], dense[name][sample // 2:], equal_nan=True)
                  for name in (*schema.GROWTH_VARS, *schema.SLIDING_VARS))
    classes = np.bincount(ds["verdict_filled_all"].values.ravel(), minlength=3)
    levels = ", ".join(f"level {lv['level']} {100 * lv['fraction_of_grid']:.1f} %" for lv in summary["per_level"])
    dense_estimate = per_point * computed.size
    return (f"\nAn adaptive atlas on the sliding verdict (`asymslide sweep --adaptive --verdict sliding`; {n}^3 over "
            f"gamma 0.1..30 (log) x f 0.1..1.5 x beta 0.05..0.7, eta = inf, xi = 1, {summary['levels']} levels from a "
            f"{summary['coarse_shape'][0]}^3 coarse grid, refined where either verdict changes, into Zarr, the "
            f"sliding tasks in two processes): **{t_adaptive:.0f} s**, evaluated "
            f"**{100 * summary['evaluated_fraction']:.1f} %** of the {computed.size} points ({levels}); filled "
            "sliding classes stable/unstable/undetermined "
            f"{[int(c) for c in classes]}. Against the dense model call at {sample} random points: the filled class "
            f"differs at {differ['verdict_all']} (sliding) and {differ['verdict']} (Rayleigh branch) of "
            f"{sample // 2} points not computed; the values at {sample // 2} computed points bitwise equal: "
            f"{'yes' if bitwise else 'NO'}. Those calls cost {1e3 * per_point:.1f} ms a point on one thread, so the "
            f"dense sweep of both verdicts would take about {dense_estimate:.0f} s on one thread "
            f"({dense_estimate / 2:.0f} s on two; the adaptive one: {t_adaptive / (dense_estimate / 2):.2f} of "
            "that).\n")


def threads_vs_processes(n: int = 60, seed: int = 33) -> str:
    """Why sliding sweeps run in processes: asymslide.atlas.tasks.sliding_arrays on two blocks of `n` random points at
    eta = inf, one after the other, in two threads, and in two spawned processes (warm: each process computes one
    point first)."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor

    from asymslide.atlas import plan as atlas_plan
    from asymslide.atlas import tasks as atlas_tasks


    rng = np.random.default_rng(seed)
    blocks = [np.ascontiguousarray(np.stack([np.exp(rng.uniform(math.log(0.1), math.log(30), n)),
                                             rng.uniform(0.1, 1.5, n), rng.uniform(0.05, 0.7, n), np.full(n, math.inf),
                                             np.full(n, 1.0), np.full(n, 1.0)])) for _ in range(2)]
    spec = atlas_plan.SlidingSpec()
    atlas_tasks.sliding_arrays(spec, blocks[0][:, :2])
    t0 = time.perf_counter()
    for b in blocks:
        atlas_tasks.sliding_arrays(spec, b)
    serial = time.perf_counter() - t0
    with ThreadPoolExecutor(2) as pool:
        t0 = time.perf_counter()
        list(pool.map(partial(atlas_tasks.sliding_arrays, spec), blocks))
        threads = time.perf_counter() - t0
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        list(pool.map(partial(atlas_tasks.sliding_arrays, spec), [b[:, :1] for b in blocks]))  # warm
        t0 = time.perf_counter()
        list(pool.map(partial(atlas_tasks.sliding_arrays, spec), blocks))
        processes = time.perf_counter() - t0
    return (f"\nThe sliding verdict holds the GIL (asymslide.atlas.tasks.sliding_arrays on 2 x {n} random points at "
            f"eta = inf): one after the other {serial:.2f} s; two threads {threads:.2f} s ({serial / threads:.2f}x); "
            f"in two processes {processes:.2f} s ({serial / processes:.2f}x). So sweeps run the sliding tasks in "
            "processes (asymslide.atlas.executor.execute).\n")


def main() -> None:
    results = run()
    dense = dense_results(results)
    text = (markdown(results) + denser_grid(results, dense) + track_fraction(results, dense) + oracle_errors()
            + rate_cost() + atlas_cost() + map_cost() + threads_vs_processes() + adaptive_atlas())
    print(text)


if __name__ == "__main__":
    main()
