"""`make bench`: run time against error for the model core (issue: model core, point 5).

Prints a table and writes benchmarks/results.md (with the thresholds, the stability atlases, the kernels' A/B and
benchmarks/design_measurements.md) and benchmarks/spectrum_pareto.png.
Timings are medians of repeated warm runs in one process (the model and the baseline it is compared with
measured interleaved); compare ratios, not absolute numbers.
"""

from __future__ import annotations

import cmath
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy import optimize

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide import model  # noqa: E402
from benchmarks.hostspeed import host_line, host_loop_seconds  # noqa: E402
from tests import oracle  # noqa: E402

OUT = Path(__file__).resolve().parent
PAPER = dict(gamma=3.0, f=0.9, beta=0.3)
RTOLS = (1e-10, 1e-6)  # accuracy settings shown besides the default (full certified accuracy)


def plain_dispersion(z: complex, q: float, gamma: float, f: float, beta: float, eta: float) -> complex:
    """Eq. Gs_general + Eq. implicit_spectrum written literally with cmath (the 'plain' baseline)."""
    a_s = cmath.sqrt(1 - z * z)
    a_d = cmath.sqrt(1 - beta * beta * z * z)
    t1s, t1d = cmath.tanh(q * a_s), cmath.tanh(q * a_d)
    if math.isinf(eta):
        t2s = t2d = 1.0
    else:
        t2s, t2d = cmath.tanh(eta * q * a_s), cmath.tanh(eta * q * a_d)
    gx = ((1 + a_s**2) ** 2 / (a_s * (t1s + t2s)) - 4 * a_d / (t1d + t2d)) / z**2
    gy = 2 * (1 + a_s**2) / z**2 * (t2d / (t1d + t2d) - t2s / (t1s + t2s))
    return gamma * (gx + 1j * f * gy) + 1j * z


def plain_dispersion_numpy(z: complex, q: float, gamma: float, f: float, beta: float, eta: float) -> complex:
    """The same literal formula with numpy scalar functions (np.sqrt, np.tanh), as most scripts write it."""
    a_s = np.sqrt(1 - z * z)
    a_d = np.sqrt(1 - beta * beta * z * z)
    t1s, t1d = np.tanh(q * a_s), np.tanh(q * a_d)
    if math.isinf(eta):
        t2s = t2d = 1.0
    else:
        t2s, t2d = np.tanh(eta * q * a_s), np.tanh(eta * q * a_d)
    gx = ((1 + a_s**2) ** 2 / (a_s * (t1s + t2s)) - 4 * a_d / (t1d + t2d)) / z**2
    gy = 2 * (1 + a_s**2) / z**2 * (t2d / (t1d + t2d) - t2s / (t1s + t2s))
    return gamma * (gx + 1j * f * gy) + 1j * z


def naive_newton_loop(q: np.ndarray, eta: float, fun=plain_dispersion) -> np.ndarray:
    """scipy.optimize.newton (secant) per kH, warm-started from the previous root, from kH = 1e4 down.

    Points where scipy reports no convergence are NaN.
    """
    order = np.argsort(-q)
    kw = dict(tol=1e-14, rtol=1e-14, maxiter=100)
    z = complex(model.rayleigh_speed(PAPER["beta"]))
    z = optimize.newton(fun, z, args=(1e4, *PAPER.values(), eta), **kw)
    out = np.full(q.size, complex(math.nan, math.nan))
    for i in order:
        try:
            z = optimize.newton(fun, z, args=(q[i], *PAPER.values(), eta), **kw)
        except RuntimeError:
            continue
        out[i] = z
    return out


def timeit(fn, repeat: int) -> float:
    fn()
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def paired_medians(fast, slow, rounds: int = 5, inner: int = 100) -> tuple[float, float]:
    """Median times of `fast` and `slow`, measured interleaved (per round: `inner` calls of fast, one of slow),
    so that a change of machine load during the run affects both alike (the ratio is what is reported)."""
    fast()
    slow()
    t_fast, t_slow = [], []
    for _ in range(rounds):
        for _ in range(inner):
            t0 = time.perf_counter()
            fast()
            t_fast.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        slow()
        t_slow.append(time.perf_counter() - t0)
    return statistics.median(t_fast), statistics.median(t_slow)


def max_rel_error(z: np.ndarray, q: np.ndarray, ref: dict[float, complex]) -> float:
    """Max relative error at the sampled points (inf if any sampled point is NaN)."""
    errs = [abs(z[i] - ref[q[i]]) / abs(ref[q[i]]) for i in range(q.size) if q[i] in ref]
    return math.inf if any(math.isnan(e) for e in errs) else max(errs)


def spectrum_rows(q: np.ndarray) -> list[tuple[str, str, float, float, int]]:
    """(eta, method, time [s] or speed ratio, max relative error, points) of the spectrum solvers at the paper's
    parameters, for eta = inf and 7."""
    rows = []
    for eta in (math.inf, 7.0):
        label = "inf" if math.isinf(eta) else f"{eta:g}"
        sample = q[::32]
        refs = oracle.rayleigh_branch(list(sample), *PAPER.values(), eta)
        ref = {float(s): complex(r) for s, r in zip(sample, refs, strict=True)}
        def run_model(eta: float = eta, rtol: float | None = None) -> np.ndarray:
            return model.spectrum(q, **PAPER, eta=eta, rtol=rtol)

        def run_naive(eta: float = eta) -> np.ndarray:
            return naive_newton_loop(q, eta)

        def run_naive_np(eta: float = eta) -> np.ndarray:
            return naive_newton_loop(q, eta, plain_dispersion_numpy)

        t_model, t_naive = paired_medians(run_model, run_naive)
        z_model = run_model()
        z_naive = run_naive()
        e_model = max_rel_error(z_model, q, ref)
        e_naive = max_rel_error(z_naive, q, ref)
        rows.append((label, "model.spectrum", t_model, e_model, q.size))
        failed = int(np.isnan(z_naive).sum())
        name = "scipy newton loop (plain F)" + (f", {failed} points failed" if failed else "")
        rows.append((label, name, t_naive, e_naive, q.size))
        rows.append((label, "speed ratio (vs cmath F)", t_naive / t_model, math.nan, q.size))
        for rtol in RTOLS:  # looser accuracy settings of the same solver (Pareto points)
            t_r = timeit(lambda rtol=rtol: run_model(rtol=rtol), 500)
            e_r = max_rel_error(run_model(rtol=rtol), q, ref)
            rows.append((label, f"model.spectrum rtol={rtol:g}", t_r, e_r, q.size))
        if math.isinf(eta):
            t_model2, t_np = paired_medians(run_model, run_naive_np)
            e_np = max_rel_error(run_naive_np(), q, ref)
            rows.append((label, "scipy newton loop (plain F, numpy scalars)", t_np, e_np, q.size))
            rows.append((label, "speed ratio (vs numpy-scalar F)", t_np / t_model2, math.nan, q.size))
    return rows


def spectrum_markdown(rows: list[tuple[str, str, float, float, int]]) -> str:
    """The spectrum benchmark's table."""
    lines = [
        "# Spectrum benchmark (make bench)",
        "",
        "512 log-spaced kH in [1e-4, 1e4], paper parameters f = 0.9, beta = 0.3, gamma = 3.",
        "Max relative error against the mpmath oracle at 16 of the 512 points. `rtol` rows: the same solver at",
        "looser accuracy settings (default: full certified accuracy).",
        "",
        "| eta | method | time [ms] / ratio | max rel. error | points |",
        "|---|---|---|---|---|",
    ]
    for label, name, t, e, n in rows:
        tt = f"{t:.1f}x" if name.startswith("speed ratio") else f"{t * 1e3:.3f}"
        ee = "" if math.isnan(e) else f"{e:.1e}"
        lines.append(f"| {label} | {name} | {tt} | {ee} | {n} |")
    return "\n".join(lines) + "\n"


def other_sections() -> str:
    """The other benchmarks' sections: maps, Pareto, modes, thresholds, coverage, atlases, the house work
    before/after."""
    from benchmarks import bench_maps

    text = "\n## Stability maps and thresholds (model.stability)\n\n" + bench_maps.table(bench_maps.run())
    from benchmarks import bench_modes, bench_pareto

    text += "\n## Run time against error (spectrum solvers; threshold vs kH grid)\n\n" + bench_pareto.markdown()

    text += ("\n## All unstable roots in |Re z| <= 5, im_min <= Im z <= 2 (model.unstable_modes vs cxroots)\n\n"
             + bench_modes.markdown(bench_modes.run()))
    from benchmarks import bench_eigen

    eigen_rows = bench_eigen.run()
    text += ("\n## Every mode at once: the collocation eigen-solver against the contour solver (model.eigenmodes; "
             "`benchmarks/bench_eigen.py`)\n\n" + bench_eigen.table(eigen_rows) + "\n" + bench_eigen.target(eigen_rows)
             + "\n")
    from benchmarks import bench_growth_limits

    text += ("\n## The temporal growth rate as kH -> inf (model.growth_rate_limit; "
             "`benchmarks/bench_growth_limits.py`)\n\n" + bench_growth_limits.markdown(bench_growth_limits.run())
             + "\n" + bench_growth_limits.finite_eta())
    text += ("\n## Counts beside dense real-axis poles (model.unstable_count; "
             "`python benchmarks/bench_modes.py --dense`)\n\n" + bench_modes.dense_markdown(bench_modes.dense_poles()))
    from benchmarks import bench_sliding

    text += ("\n## Sliding over the whole spectrum (model.sliding_analysis; `benchmarks/bench_sliding.py`)\n\n"
             + bench_sliding.markdown(sliding := bench_sliding.run())
             + bench_sliding.denser_grid(sliding, dense := bench_sliding.dense_results(sliding))
             + bench_sliding.track_fraction(sliding, dense) + bench_sliding.oracle_errors() + bench_sliding.rate_cost()
             + bench_sliding.atlas_cost() + bench_sliding.map_cost() + bench_sliding.threads_vs_processes()
             + bench_sliding.adaptive_atlas())
    from benchmarks import bench_coverage, bench_sweep, bench_thresholds, threshold_accuracy

    text += ("\n## Thresholds as certified neutral modes, before and after (model.crossings_chunk; "
             "`benchmarks/bench_thresholds.py`)\n\n" + bench_thresholds.table(bench_thresholds.run(256, 3, 32, 2)))
    text += ("\n## Certified thresholds against the oracle's neutral modes (`benchmarks/threshold_accuracy.py`)\n\n"
             + threshold_accuracy.markdown())
    text += ("\n## Coverage of the stability boundary per eta (certified crossings and verdicts; "
             "`benchmarks/bench_coverage.py`)\n\n" + bench_coverage.table(bench_coverage.run()))
    import tempfile

    from benchmarks import bench_adaptive

    with tempfile.TemporaryDirectory() as tmp:  # the dense 65^4 store, kept for the adaptive atlas's agreement
        dense = {"dir": Path(tmp)}
        text += ("\n## Stability atlases (asymslide sweep; `benchmarks/bench_sweep.py`)\n\n"
                 + bench_sweep.markdown(dense=dense))
        text += ("\n## Adaptive atlases against dense ones (asymslide sweep --adaptive; `benchmarks/bench_adaptive.py`)"
                 "\n\n" + bench_adaptive.run(dense_store=dense["store"], dense_seconds=dense["seconds"],
                                            dense_host=dense["host"]))

    from benchmarks import bench_revision_ab, bit_identity

    rev = bench_revision_ab.BEFORE_SPLIT
    n_arrays, n_values, differ = bit_identity.run(rev)
    text += (f"\n## Kernels split by algorithm, before and after (revision {rev} against this tree, interleaved, each "
             "in a process of its own; `benchmarks/bench_revision_ab.py`, `benchmarks/bit_identity.py`)\n\n"
             + bench_revision_ab.markdown(rev, bench_revision_ab.measure(rev))
             + f"\n{n_arrays} arrays ({n_values:,} values) of spectrum, growth, thresholds and unstable_modes on "
             f"fixed grids: {n_arrays - len(differ)} bit-identical to {rev}, {len(differ)} differ"
             + "".join(f"\n- differs: {k}" for k in differ)
             + "\n\nThe atlas engine and the command line, before and after "
             "(`python benchmarks/bench_revision_ab.py --sweep`): "
             + bench_revision_ab.sweep_ab(rev, rounds=5))
    return text


def plot_pareto(rows: list[tuple[str, str, float, float, int]]) -> None:
    """spectrum_pareto.png: run time against error of the spectrum solvers (skipped without matplotlib)."""
    try:
        import matplotlib
    except ImportError:
        print("matplotlib not installed: no plot")
        return
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    for eta_label in dict.fromkeys(r[0] for r in rows):  # the model's settings joined by a line
        pts = [(t * 1e3, max(e, 1e-17)) for label, name, t, e, _ in rows
               if label == eta_label and name.startswith("model.spectrum")]
        pts.sort(key=lambda p: p[1])  # in the order of the accuracy settings
        ax.loglog(*zip(*pts, strict=True), "-", color="0.7", zorder=0)
    for label, name, t, e, _ in rows:
        if not name.startswith("speed ratio"):
            shown = 1.0 if not math.isfinite(e) else max(e, 1e-17)  # failed runs plotted at 1
            ax.loglog(t * 1e3, shown, "o" if "model" in name else "s", label=f"{name}, eta={label}")
    ax.set_xlabel("run time for 512 kH [ms]")
    ax.set_ylabel("max relative error vs mpmath oracle")
    ax.set_title("Rayleigh branch: run time vs error")
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(OUT / "spectrum_pareto.png", dpi=120)


def main() -> None:
    host_before = host_loop_seconds()
    rows = spectrum_rows(np.logspace(-4, 4, 512))
    text = spectrum_markdown(rows) + other_sections()
    text += "\n" + (OUT / "design_measurements.md").read_text(encoding="utf-8")
    text += "\n" + host_line(host_before, host_loop_seconds()) + "\n"
    print(text)
    (OUT / "results.md").write_text(text)
    plot_pareto(rows)


if __name__ == "__main__":
    main()
