"""Adaptive atlases (issue 27) against dense ones: wall time, evaluated fraction per level, verdict agreement.

- 65^4 over (gamma, f, beta, Delta) at eta = inf, xi = 1, the ranges of the dense 64^4 benchmark
  (benchmarks/bench_sweep.py), adaptive from a 9^4 coarse grid (3 levels, the default refinement: margin 0, the
  boundary followed): wall time against the target of
  2 min, the fraction of points evaluated (overall and per level), and, given the dense sweep of the same grid, the
  verdict field's agreement at every point and the bitwise equality of the values at the computed points (given
  that dense sweep, the same with the guard too);
- 33^4 at eta = 10 (same axes and xi), dense and adaptive (2 levels): the default refinement (margin 0, the
  boundary followed) with and without the guard, and for comparison without following, at margin 0 and 1.

Every time is printed with the host-speed gauge (benchmarks/hostspeed.py) measured just before and after it.

    python benchmarks/bench_adaptive.py [--quick] [--dense-store DIR [--dense-seconds S]] [--sample N]
                                        [--dense10-store DIR] [--only-eta10]

--dense-store: a dense 65^4 store of the same grid (bench_sweep.big_sweep(65, keep=...) writes one; `make bench`
passes the one of its own run). Without it no dense 65^4 is run (~13 min on two cores): the dense model call is made
at N random points of the grid instead (--sample, default 200000: N/2 among the points the adaptive sweep filled, N/2
among those it computed), the filled verdict class is compared with the dense one there and the computed values
bitwise, and the dense time is the latest 64^4 figure in benchmarks/results.md. --quick: 17^4 and 9^4 grids.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide.atlas import (  # noqa: E402
    plan,
    refinement,  # noqa: E402
    schema,
    tasks,
)
from asymslide.atlas import sweep as S  # noqa: E402
from benchmarks.hostspeed import host_loop_seconds  # noqa: E402

KH = plan.DEFAULT_KH
GROWTH_VARS = tuple(schema.GROWTH_VARS)


def axes(n: int) -> dict[str, np.ndarray]:
    """The 4-D grid of the atlas benchmarks: gamma in [0.1, 30] log, f in [0.1, 1.5], beta in [0.05, 0.7], Delta in
    [0.05, 1] (bench_sweep.big_sweep's ranges)."""
    return {"gamma": np.geomspace(0.1, 30, n), "f": np.linspace(0.1, 1.5, n), "beta": np.linspace(0.05, 0.7, n),
            "Delta": np.linspace(0.05, 1.0, n)}


def timed_sweep(store: Path, n: int, eta: float, adaptive: refinement.AdaptiveSpec | None) -> dict:
    """One sweep into `store` (growth only, xi = 1): wall time and the host gauge before and after."""
    h0 = host_loop_seconds()
    t0 = time.perf_counter()
    S.sweep(axes(n), fixed={"xi": 1.0, "eta": eta}, kH=KH, store=store, gamma_c=False, adaptive=adaptive)
    t = time.perf_counter() - t0
    return {"seconds": t, "host": (h0, host_loop_seconds()), "store": store}


def _read(store: Path, names: tuple[str, ...]) -> dict[str, np.ndarray]:
    import zarr

    group = zarr.open_group(str(store), mode="r")
    return {name: group[name][...] for name in names}


def compare(adaptive_store: Path, dense_store: Path) -> dict:
    """Agreement of an adaptive store with the dense store of the same grid."""
    a = _read(adaptive_store, (*GROWTH_VARS, "computed", "verdict_filled"))
    d = _read(dense_store, GROWTH_VARS)
    computed = a["computed"] >= 0
    bitwise = all(np.array_equal(a[n][computed], d[n][computed], equal_nan=a[n].dtype.kind == "f")
                  for n in GROWTH_VARS)
    wrong = a["verdict_filled"] != d["verdict"]
    return {"points": int(wrong.size), "mismatches": int(wrong.sum()),
            "mismatch_by_dense_class": [int(x) for x in np.bincount(d["verdict"][wrong], minlength=3)],
            "bitwise_at_computed": bitwise, "dense_classes": [int(x) for x in np.bincount(d["verdict"].ravel(),
                                                                                          minlength=3)]}


def compare_sample(adaptive_store: Path, n: int, eta: float, sample: int, seed: int = 0) -> dict:
    """Agreement of an adaptive store with the dense model call at `sample` random points (half among the filled,
    half among the computed ones; fewer if there are fewer): the dense values there are computed here, one point at
    a time as the dense sweep does (:func:`asymslide.atlas.tasks.growth_arrays`)."""
    a = _read(adaptive_store, (*GROWTH_VARS, "computed", "verdict_filled"))
    computed = a["computed"].reshape(-1) >= 0
    rng = np.random.default_rng(seed)
    picks = {}
    for name, where in (("filled", np.flatnonzero(~computed)), ("computed", np.flatnonzero(computed))):
        picks[name] = np.sort(rng.choice(where, size=min(sample // 2, where.size), replace=False))
    flat = np.concatenate(list(picks.values()))
    grid = axes(n)
    index = np.unravel_index(flat, tuple(v.size for v in grid.values()))
    columns = dict(zip(grid, (v[i] for v, i in zip(grid.values(), index, strict=True)), strict=True))
    rows = [columns[p] if p in columns else np.full(flat.size, {"xi": 1.0, "eta": eta}[p]) for p in plan.PARAMETERS]
    t0 = time.perf_counter()
    dense = tasks.growth_arrays(np.log(KH), np.ascontiguousarray(np.stack(rows), dtype=float), None)
    seconds = time.perf_counter() - t0
    nf = picks["filled"].size
    wrong = a["verdict_filled"].reshape(-1)[picks["filled"]] != dense["verdict"][:nf]
    at = picks["computed"]
    bitwise = all(np.array_equal(a[name].reshape(-1)[at], dense[name][nf:], equal_nan=a[name].dtype.kind == "f")
                  for name in GROWTH_VARS)
    return {"filled_points": int(nf), "mismatches": int(wrong.sum()),
            "mismatch_by_dense_class": [int(x) for x in np.bincount(dense["verdict"][:nf][wrong], minlength=3)],
            "computed_points": int(at.size), "bitwise_at_computed": bitwise, "seconds": seconds}


def latest_dense_figure() -> tuple[int, float] | None:
    """(n, seconds) of the latest dense n^4 sweep in benchmarks/results.md (bench_sweep's line), None if none."""
    import re

    path = ROOT / "benchmarks" / "results.md"
    found = re.search(r"^(\d+)\^4 sweep \(gamma, f, beta, Delta; eta = inf, xi = 1;.*?Zarr: (\d+) s",
                      path.read_text(encoding="utf-8") if path.exists() else "", re.M)
    return (int(found[1]), float(found[2])) if found else None


def fractions(store: Path) -> dict:
    import xarray as xr

    return json.loads(xr.open_zarr(store, consolidated=False).attrs["adaptive"])


def _host(h: tuple[float, float]) -> str:
    return f"host loop {h[0]:.2f} -> {h[1]:.2f} s"


def _levels(f: dict) -> str:
    return "; ".join(f"level {lv['level']} (stride {lv['stride']}): {lv['points']} = "
                     f"{100 * lv['fraction_of_grid']:.2f} %" for lv in f["per_level"])


def _agreement(c: dict) -> str:
    return (f"verdict field equal to the dense one at {c['points'] - c['mismatches']} of {c['points']} points "
            f"({c['mismatches']} differ; by dense class stable/unstable/undetermined {c['mismatch_by_dense_class']}); "
            f"values at the computed points bitwise equal: {'yes' if c['bitwise_at_computed'] else 'NO'}")


def run(quick: bool = False, dense_store: Path | None = None, dense_seconds: float | None = None,
        dense_host: tuple[float, float] | None = None, sample: int = 200_000, dense10: Path | None = None) -> str:
    """The benchmark as Markdown. dense_store/dense_seconds/dense_host: a dense sweep of the big grid measured in
    the same run (bench_sweep); else the adaptive atlas is checked against the dense model call at `sample` random
    points and timed against the latest dense 64^4 figure of benchmarks/results.md. dense10: a dense store of the
    eta = 10 grid from an earlier run (else one is computed: ~15-30 min)."""
    n_big, n_small = (17, 9) if quick else (65, 33)
    lines = []
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        spec = refinement.AdaptiveSpec(levels=refinement.default_levels([n_big]))
        ad = timed_sweep(tmp / "adaptive.zarr", n_big, math.inf, spec)
        f = fractions(ad["store"])
        lines += [f"**{n_big}^4 adaptive** (gamma, f, beta, Delta; eta = inf, xi = 1; {KH.size} kH; growth only; "
                  f"L = {spec.levels} levels of refinement from a {f['coarse_shape'][0]}^4 coarse grid, margin 0, "
                  "boundary followed, no guard) into Zarr: "
                  f"**{ad['seconds']:.0f} s** ({_host(ad['host'])}; target <= 120 s); evaluated "
                  f"**{100 * f['evaluated_fraction']:.1f} %** of the points ({_levels(f)}).", ""]
        if dense_store is not None:
            c = compare(ad["store"], dense_store)
            scale = 64**4 / n_big**4
            lines += [f"Dense {n_big}^4 of the same grid: {dense_seconds:.0f} s ({_host(dense_host)}), i.e. "
                      f"{dense_seconds * scale:.0f} s for 64^4 points; adaptive / dense: "
                      f"{ad['seconds'] / dense_seconds:.3f} ({dense_seconds / ad['seconds']:.1f}x faster). "
                      + _agreement(c) + ".", ""]
            guarded = timed_sweep(tmp / "guard.zarr", n_big, math.inf,
                                  refinement.AdaptiveSpec(levels=spec.levels, guard=1.0))
            fg = fractions(guarded["store"])
            lines += [f"With the guard (guard 1): {guarded['seconds']:.0f} s ({_host(guarded['host'])}); evaluated "
                      f"{100 * fg['evaluated_fraction']:.1f} % ({_levels(fg)}). "
                      + _agreement(compare(guarded["store"], dense_store)) + ".", ""]
        else:
            latest = latest_dense_figure()
            if latest is not None:
                n_d, t_d = latest
                t64 = t_d * 64**4 / n_d**4
                lines += [f"Dense: no dense {n_big}^4 in this run; the latest dense {n_d}^4 figure of "
                          f"benchmarks/results.md is {t_d:.0f} s, i.e. {t64:.0f} s for 64^4 points and "
                          f"{t64 * n_big**4 / 64**4:.0f} s for {n_big}^4 (adaptive / dense "
                          f"{ad['seconds'] / (t64 * n_big**4 / 64**4):.3f}; another run, another host load).", ""]
            c = compare_sample(ad["store"], n_big, math.inf, sample)
            lines += [f"Agreement with the dense model call at {c['filled_points'] + c['computed_points']} random "
                      f"points (dense values computed here in {c['seconds']:.0f} s): the filled verdict class equals "
                      f"the dense verdict at {c['filled_points'] - c['mismatches']} of {c['filled_points']} points the "
                      f"adaptive sweep did not compute ({c['mismatches']} differ; by dense class "
                      f"stable/unstable/undetermined {c['mismatch_by_dense_class']}); values at "
                      f"{c['computed_points']} computed points bitwise equal: "
                      f"{'yes' if c['bitwise_at_computed'] else 'NO'}.", ""]
        lines += eta10_table(tmp, n_small, dense10)
    return "\n".join(lines) + "\n"


#: the refinements compared at eta = 10: (row label, margin, guard, follow)
ETA10_SPECS = (("margin 0, followed (default)", 0, 0.0, True), ("margin 0, followed, guard 1", 0, 1.0, True),
               ("margin 0, not followed", 0, 0.0, False), ("margin 1, not followed", 1, 0.0, False))


def eta10_table(tmp: Path, n_small: int, dense10: Path | None = None) -> list[str]:
    """The n_small^4 grid at eta = 10: a dense sweep (or the dense store `dense10` of that grid) and the adaptive
    refinements of ETA10_SPECS against it, as Markdown lines."""
    if dense10 is None:
        d10 = timed_sweep(tmp / "dense10.zarr", n_small, 10.0, None)
        dense_text = f"dense {d10['seconds']:.0f} s ({_host(d10['host'])})"
    else:
        d10 = {"store": dense10}
        dense_text = f"dense store {dense10.name} of an earlier run"
    classes = [int(x) for x in np.bincount(_read(d10["store"], ("verdict",))["verdict"].ravel(), minlength=3)]
    lines = [f"**{n_small}^4 at eta = 10** (same axes, xi = 1): {dense_text}; classes "
             f"stable/unstable/undetermined {classes}.", "",
             "| adaptive | wall [s] | host loop [s] | evaluated | per level | verdict mismatches "
             "(by dense class) | bitwise at computed |", "|---|---|---|---|---|---|---|"]
    for k, (label, margin, guard, follow) in enumerate(ETA10_SPECS):
        s10 = refinement.AdaptiveSpec(levels=refinement.default_levels([n_small]), margin=margin, guard=guard,
                                      follow=follow)
        r = timed_sweep(tmp / f"adaptive10-{k}.zarr", n_small, 10.0, s10)
        f10, c10 = fractions(r["store"]), compare(r["store"], d10["store"])
        per = ", ".join(f"{100 * lv['fraction_of_grid']:.2f} %" for lv in f10["per_level"])
        lines.append(f"| {label} | {r['seconds']:.0f} | {r['host'][0]:.2f} -> "
                     f"{r['host'][1]:.2f} | {100 * f10['evaluated_fraction']:.1f} % | {per} | "
                     f"{c10['mismatches']} {c10['mismatch_by_dense_class']} | "
                     f"{'yes' if c10['bitwise_at_computed'] else 'NO'} |")
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="small grids (a smoke test)")
    parser.add_argument("--dense-store", type=Path,
                        help="a dense store of the big grid (else: a sample of dense model calls)")
    parser.add_argument("--dense-seconds", type=float, default=math.nan,
                        help="the wall time of the --dense-store sweep, if known (printed beside the adaptive one)")
    parser.add_argument("--sample", type=int, default=200_000, help="points of the sample (without --dense-store)")
    parser.add_argument("--dense10-store", type=Path,
                        help="a dense store of the eta = 10 grid from an earlier run (else one is computed)")
    parser.add_argument("--only-eta10", action="store_true", help="only the eta = 10 table")
    args = parser.parse_args()
    if args.only_eta10:
        with tempfile.TemporaryDirectory() as tmp:
            print("\n".join(eta10_table(Path(tmp), 9 if args.quick else 33, args.dense10_store)))
        return
    dense = (args.dense_seconds, (math.nan, math.nan)) if args.dense_store else (None, None)
    print(run(args.quick, args.dense_store, *dense, sample=args.sample, dense10=args.dense10_store))


if __name__ == "__main__":
    main()
