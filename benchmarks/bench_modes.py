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


if __name__ == "__main__":
    print("Unstable modes in |Re z| <= 5, im_min <= Im z <= 2 (f = 0.9, beta = 0.3, gamma = 3, Delta = 1)\n")
    print(markdown(run()))
