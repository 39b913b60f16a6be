"""Benchmark of model.modes (issue 3): all unstable modes in the default window, against cxroots.

For each parameter set (f = 0.9, beta = 0.3, gamma = 3, Delta = 1) the rows compare

- ``modes.unstable_modes`` / ``modes.unstable_count`` (median of warm repeats),
- ``cxroots`` (Rectangle(...).roots(F, F'), default settings, one run) on the same window, and on a window
  with a larger im_min where cxroots fails or miscounts on the default one,
- ``mpmath findroot`` polishing of every root on the independent oracle's F (tests/oracle.py, 30 digits):
  the accuracy reference of max_rel_error (cxroots roots are matched to the nearest reference root).

``points`` is the number of evaluations of F (cxroots: of F and F' each). Timings are on this machine,
while other jobs may be running: compare ratios, not absolute numbers. Run ``python benchmarks/bench_modes.py``.
"""

from __future__ import annotations

import contextlib
import io
import math
import statistics
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from mpmath import mp

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide import model  # noqa: E402
from asymslide.model import modes  # noqa: E402
from tests import oracle  # noqa: E402

PAPER = dict(gamma=3.0, f=0.9, beta=0.3)
WINDOW = dict(re_max=5.0, im_min=1e-4, im_max=2.0)
# (eta, kH, a larger im_min for cxroots where it fails on the default window, extra cxroots options)
CASES = [
    (10.0, 0.77, 1e-2, dict(int_method="romb")),
    (3.0, 0.45, 1e-3, {}),
    (math.inf, 0.45, 1e-3, {}),
]
REPEATS = 20


def _reference(roots: np.ndarray, kH: float, eta: float) -> np.ndarray:
    """mpmath findroot (30 digits, oracle F) from each root: the accuracy reference."""
    p = oracle.Params.make(PAPER["gamma"], PAPER["f"], PAPER["beta"], eta)
    out = []
    with mp.workdps(30):
        q = mp.mpf(kH)
        for z in roots:
            out.append(complex(mp.findroot(lambda w: oracle.dispersion_core(w, q, p), mp.mpc(z))))
    return np.array(out, dtype=np.complex128)


def _rel_error(roots: np.ndarray, ref: np.ndarray) -> tuple[float, int]:
    """Largest relative distance of each reference root to the nearest of `roots`; and how many are missing."""
    if ref.size == 0:
        return 0.0, 0
    if roots.size == 0:
        return math.nan, ref.size
    d = np.min(np.abs(ref[:, None] - roots[None, :]), axis=1) / np.abs(ref)
    found = d < 1e-6
    return (float(np.max(d[found])) if found.any() else math.nan), int(np.count_nonzero(~found))


def _time_modes(kH: float, eta: float, window: dict) -> tuple[float, np.ndarray, int, float]:
    args = (kH, PAPER["gamma"], PAPER["f"], PAPER["beta"], eta, 1.0, 0.0, window["re_max"], window["im_min"],
            window["im_max"])
    modes._modes(modes._problem(*args))  # warm-up (compilation is cached on disk)
    times = []
    for _ in range(REPEATS):
        t = time.perf_counter()
        roots, points = modes._modes(modes._problem(*args))
        times.append(time.perf_counter() - t)
    count_times = []
    for _ in range(REPEATS):
        t = time.perf_counter()
        modes._problem(*args).outer()
        count_times.append(time.perf_counter() - t)
    return statistics.median(times) * 1e3, roots, points, statistics.median(count_times) * 1e3


def _cxroots(kH: float, eta: float, window: dict, options: dict) -> tuple[float, np.ndarray | None, int, str]:
    import cxroots

    p = dict(eta=eta, **PAPER)
    calls = [0]

    def f(z):
        calls[0] += np.size(z)
        return model.dispersion(z, kH, **p)

    def df(z):
        return model.dispersion_derivative(z, kH, **p)

    rect = cxroots.Rectangle([-window["re_max"], window["re_max"]], [window["im_min"], window["im_max"]])
    t = time.perf_counter()
    try:
        sink = io.StringIO()
        with warnings.catch_warnings(), contextlib.redirect_stdout(sink), contextlib.redirect_stderr(sink):
            warnings.simplefilter("ignore")
            res = rect.roots(f, df, **options)
        roots = np.array(res.roots, dtype=np.complex128)
        note = ""
    except Exception as exc:  # cxroots raises RuntimeError / RootError when its integration fails
        roots = None
        note = f"failed: {type(exc).__name__}"
    return (time.perf_counter() - t) * 1e3, roots, calls[0], note


def run() -> list[dict]:
    """Rows {case, window, method, time_ms_per_kH, max_rel_error, n_roots, points, note}."""
    rows: list[dict] = []
    for eta, kH, im_fallback, cx_options in CASES:
        case = f"eta={eta:g}, kH={kH:g}"
        windows = [WINDOW, dict(WINDOW, im_min=im_fallback)]
        for k, window in enumerate(windows):
            wtxt = f"im_min={window['im_min']:g}"
            t_modes, roots, points, t_count = _time_modes(kH, eta, window)
            t = time.perf_counter()
            ref = _reference(roots, kH, eta)
            t_ref = (time.perf_counter() - t) * 1e3
            err, _ = _rel_error(roots, ref)
            rows.append(dict(case=case, window=wtxt, method="modes.unstable_modes", time_ms_per_kH=t_modes,
                             max_rel_error=err, n_roots=roots.size, points=points, note=""))
            if k == 0:
                rows.append(dict(case=case, window=wtxt, method="modes.unstable_count", time_ms_per_kH=t_count,
                                 max_rel_error=math.nan, n_roots=roots.size, points=math.nan, note="count only"))
                rows.append(dict(case=case, window=wtxt, method="mpmath findroot polish (reference)",
                                 time_ms_per_kH=t_ref, max_rel_error=0.0, n_roots=ref.size, points=math.nan,
                                 note="30 digits, oracle F, started from our roots"))
            t_cx, cx_roots, cx_points, note = _cxroots(kH, eta, window, cx_options)
            if cx_roots is None:
                cx_err, n_cx = math.nan, 0
            else:
                cx_err, missing = _rel_error(cx_roots, ref)
                n_cx = cx_roots.size
                if missing:
                    note = f"missed {missing} of {ref.size} roots"
            opt = ", ".join(f"{a}={b}" for a, b in cx_options.items())
            rows.append(dict(case=case, window=wtxt, method=f"cxroots ({opt or 'defaults'})", time_ms_per_kH=t_cx,
                             max_rel_error=cx_err, n_roots=n_cx, points=cx_points,
                             note=note or f"{t_cx / t_modes:.0f}x slower than modes"))
            if k == 0 and not note:
                break  # cxroots works on the default window: no fallback needed
    return rows


def markdown(rows: list[dict]) -> str:
    def fmt(x, spec):
        return "" if isinstance(x, float) and math.isnan(x) else format(x, spec)

    lines = [
        "| case | window | method | time [ms] per kH | max rel. error | roots | points | note |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['case']} | {r['window']} | {r['method']} | {fmt(r['time_ms_per_kH'], '.3g')} | "
            f"{fmt(r['max_rel_error'], '.1e')} | {r['n_roots']} | {fmt(r['points'], 'd')} | {r['note']} |"
        )
    return "\n".join(lines)




#: the issue-52 windows: finite eta, thousands of the lower block's real-axis poles in the window
DENSE = [
    (dict(gamma=3.2801, f=0.6919, beta=0.35, eta=3.0, Delta=0.3654, xi=2.7141), 10.0, 1e-4, 3.0,
     (100.0, 400.0, 1569.79, 1569.80, 2191.7)),
    (dict(gamma=5.6087, f=1.2033, beta=0.3576, eta=3.0, Delta=0.8781, xi=1.3451), 1.0, 1e-4, 2.936254836205487,
     (1000.0, 10000.0, 30000.0, 64056.57098757342)),
    (dict(gamma=3.0, f=0.9, beta=0.3, eta=1e4, Delta=1.0, xi=0.0), 1.0, 1e-4, 2.0, (5.0, 20.0, 50.0)),
    (dict(gamma=3.0, f=0.9, beta=0.3, eta=1e4, Delta=1.0, xi=0.0), 1.0, 1e-5, 2.0, (5.0, 20.0, 50.0, 200.0)),
]


def poles_in_window(kH: float, beta: float, eta: float, re_max: float) -> int:
    """The real-axis poles of both families (docs/physics.md §2) with |x| <= re_max + 1 (both signs)."""
    a = math.pi / ((1.0 + eta) * kH)
    x = re_max + 1.0
    return 2 * sum(int(math.sqrt(max((x * bj) ** 2 - 1.0, 0.0)) / a) for bj in (1.0, beta))


def dense_poles() -> list[dict]:
    """Rows {case, re_max, poles, count, time_s, evaluations, note}: model.unstable_count (one run each) in windows
    holding more and more real-axis poles; a refused count names its reason."""
    rows = []
    for p, kH, im_min, im_max, radii in DENSE:
        case = f"kH={kH:g}, eta={p['eta']:g}, beta={p['beta']:g}, im_min={im_min:g}"
        for re_max in radii:
            args = (kH, p["gamma"], p["f"], p["beta"], p["eta"], p["Delta"], p["xi"], re_max, im_min, im_max)
            prob = modes._problem(*args)
            t = time.perf_counter()
            try:
                n, note = prob.outer()[1], ""
            except RuntimeError as exc:
                n, note = -1, f"refused: {exc}"
            rows.append(dict(case=case, re_max=re_max, poles=poles_in_window(kH, p["beta"], p["eta"], re_max),
                             count=n, time_s=time.perf_counter() - t, evaluations=prob.evaluations, note=note))
    return rows


def dense_markdown(rows: list[dict]) -> str:
    lines = ["| case | re_max | poles in window | count | time (s) | evaluations of F | note |",
             "|---|---:|---:|---:|---:|---:|---|"]
    for r in rows:
        count = "refused" if r["count"] < 0 else str(r["count"])
        lines.append(f"| {r['case']} | {r['re_max']:g} | {r['poles']:,} | {count} | {r['time_s']:.2f} | "
                     f"{r['evaluations']:,} | {r['note']} |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    if "--dense" not in sys.argv:
        print("Unstable modes in |Re z| <= 5, im_min <= Im z <= 2 (f = 0.9, beta = 0.3, gamma = 3, Delta = 1)\n")
        print(markdown(run()))
    print("Counts beside dense real-axis poles: time against the number of poles in the window\n")
    print(dense_markdown(dense_poles()))
