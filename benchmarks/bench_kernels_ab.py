"""Interleaved A/B of the compiled kernels: this tree's `model` against another checkout's or revision's.

    python benchmarks/bench_kernels_ab.py [--old /path/to/other/checkout | --old-rev REV]

(`make bench` runs it against the revision before the kernels' refactor, BEFORE_REFACTOR.)

The other checkout's `model` package is imported under the name `model_old` (its compiled functions are
cached next to this tree's, keyed by their source path). Every case is timed alternately old, new, old, new...
(`--rounds` rounds, each the median of `--inner` calls), so a change of machine load affects both alike; the
table reports the median times and the median of the per-round ratios new/old. Then the results are compared:
status codes and NaN patterns must be identical, values may differ at rounding level (max differences printed),
and the spectrum is checked against the mpmath oracle (tests/oracle.py) at 16 of its 512 points.
"""

from __future__ import annotations

import argparse
import importlib.util
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

import model as new  # noqa: E402
from model import modes as new_modes  # noqa: E402

PAPER = dict(gamma=3.0, f=0.9, beta=0.3)


def load_old(checkout: Path):
    """Import checkout/model as the package `model_old` (and its `modes` submodule)."""
    init = checkout / "model" / "__init__.py"
    spec = importlib.util.spec_from_file_location("model_old", init, submodule_search_locations=[str(init.parent)])
    mod = importlib.util.module_from_spec(spec)
    sys.modules["model_old"] = mod
    spec.loader.exec_module(mod)
    return mod, importlib.import_module("model_old.modes")


def cases(m, modes_mod):
    """name -> zero-argument callable returning the result to compare."""
    q = np.logspace(-4, 4, 512)
    qm = np.logspace(-3, 3, 96)
    gam = np.logspace(math.log10(0.5), math.log10(20.0), 64)
    eta = np.logspace(0.0, 4.0, 64)
    ff = np.linspace(0.1, 2.0, 64)
    out = {}
    for e in (math.inf, 7.0):
        for rtol in (None, 1e-6):
            out[f"spectrum 512 kH, eta={e:g}, rtol={rtol}"] = (
                lambda e=e, rtol=rtol: m.rayleigh_branch(q, **PAPER, eta=e, rtol=rtol))
    out["growth map eta-gamma 64x64x96"] = lambda: m.growth_analysis(qm, gamma=gam[:, None], f=0.9, beta=0.3,
                                                                     eta=eta[None, :], workers=1)
    out["growth map f-gamma 64x64x96 (eta=inf)"] = lambda: m.growth_analysis(qm, gamma=gam[:, None],
                                                                             f=ff[None, :], beta=0.3, workers=1)
    out["critical_gamma + critical_eta"] = lambda: (m.critical_gamma(f=0.9, beta=0.3),
                                                    m.critical_eta(gamma=3.0, f=0.9, beta=0.3))
    for e, k in ((10.0, 0.77), (math.inf, 0.45)):
        args = (k, PAPER["gamma"], PAPER["f"], PAPER["beta"], e, 1.0, 0.0, 5.0, 1e-4, 2.0)
        out[f"unstable_modes eta={e:g}, kH={k:g}"] = lambda args=args: modes_mod._modes(modes_mod._problem(*args))
    return out


def timed(fn, inner: int) -> float:
    ts = []
    for _ in range(inner):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def ab_table(old_cases, new_cases, rounds: int, inner_for) -> list[tuple[str, float, float, float]]:
    rows = []
    for name in new_cases:
        fo, fn = old_cases[name], new_cases[name]
        fo()
        fn()  # warm (compilation / cache load)
        inner = inner_for(name)
        to, tn, ratios = [], [], []
        for r in range(rounds):
            pair = (fo, fn) if r % 2 == 0 else (fn, fo)  # alternate which goes first
            t = [timed(f, inner) for f in pair]
            a, b = (t[0], t[1]) if r % 2 == 0 else (t[1], t[0])
            to.append(a)
            tn.append(b)
            ratios.append(b / a)
        rows.append((name, statistics.median(to), statistics.median(tn), statistics.median(ratios)))
    return rows


def _rel(a, b):
    a = np.asarray(a)
    b = np.asarray(b)
    both = np.isfinite(a) & np.isfinite(b)
    if not both.any():
        return 0.0
    return float(np.max(np.abs(a[both] - b[both]) / np.maximum(np.abs(b[both]), 1e-300)))


def _same_nan(a, b) -> bool:
    return bool(np.array_equal(np.isnan(np.asarray(a)), np.isnan(np.asarray(b))))


def compare(old_cases, new_cases) -> list[str]:
    lines = []
    for name in new_cases:
        ro, rn = old_cases[name](), new_cases[name]()
        if name.startswith("spectrum"):
            st = np.array_equal(ro.status, rn.status)
            lines.append(f"{name}: status identical {st}, max rel diff of z {_rel(rn.z, ro.z):.1e}, "
                         f"bit-identical {np.array_equal(rn.z, ro.z, equal_nan=True)}")
        elif name.startswith("growth"):
            diffs = [_rel(getattr(rn, k), getattr(ro, k)) for k in ("kH_at_max", "kH_min", "kH_max")]
            nan_ok = all(_same_nan(getattr(rn, k), getattr(ro, k)) for k in ("growth", "kH_at_max", "kH_min",
                                                                            "kH_max"))
            dg = float(np.nanmax(np.abs(rn.growth - ro.growth)))  # Im z in units of c_s: |z| ~ 1, so absolute
            lines.append(f"{name}: n_masked identical {np.array_equal(rn.n_masked, ro.n_masked)}, NaN pattern "
                         f"identical {nan_ok}, max |diff| of growth (Im z) {dg:.1e}, max rel diff kH_at_max "
                         f"{diffs[0]:.1e}, band ends {max(diffs[1:]):.1e}")
        elif name.startswith("critical"):
            lines.append(f"{name}: rel diff {_rel(rn[0], ro[0]):.1e}, {_rel(rn[1], ro[1]):.1e} "
                         f"(new {rn[0]:.15g}, {rn[1]:.15g})")
        else:
            (zo, no), (zn, nn) = ro, rn
            d = _rel(zn, zo) if zn.size == zo.size else math.inf
            lines.append(f"{name}: roots {zn.size} (old {zo.size}), max rel diff {d:.1e}, evaluations {nn} "
                         f"(old {no})")
    return lines


def oracle_errors(m_old, m_new) -> list[str]:
    from tests import oracle

    q = np.logspace(-4, 4, 512)
    sample = q[::32]
    lines = []
    for e in (math.inf, 7.0):
        refs = np.array([complex(r) for r in oracle.rayleigh_branch(list(sample), *PAPER.values(), e)])
        for rtol in (None, 1e-6):
            errs = []
            for m in (m_old, m_new):
                z = m.spectrum(q, **PAPER, eta=e, rtol=rtol)[::32]
                errs.append(float(np.max(np.abs(z - refs) / np.abs(refs))))
            lines.append(f"spectrum eta={e:g}, rtol={rtol}: max rel error vs oracle old {errs[0]:.1e}, "
                         f"new {errs[1]:.1e}")
    return lines


def _random_params(n: int, seed: int) -> dict:
    rng = np.random.default_rng(seed)
    return dict(gamma=10 ** rng.uniform(-2, 3, n), f=rng.uniform(-2, 2, n), beta=rng.uniform(0.05, 0.707, n),
                eta=np.where(rng.random(n) < 0.3, math.inf, 10 ** rng.uniform(-2, 6, n)),
                Delta=np.where(rng.random(n) < 0.5, 1.0, rng.uniform(0.05, 1.0, n)), xi=10 ** rng.uniform(-2, 3, n))


def random_growth(m_old, m_new, n: int = 2000, seed: int = 2) -> str:
    """NaN patterns, n_masked and values of growth_analysis on random parameter sets (both rtol settings)."""
    q = np.logspace(-4, 4, 161)
    p = _random_params(n, seed)
    out = []
    for rtol in (None, 1e-6):
        ro = m_old.growth_analysis(q, **p, rtol=rtol, workers=1)
        rn = m_new.growth_analysis(q, **p, rtol=rtol, workers=1)
        differ = rn.n_masked != ro.n_masked
        for k in ("growth", "kH_at_max", "kH_min", "kH_max"):
            differ |= np.isnan(getattr(rn, k)) != np.isnan(getattr(ro, k))
        same = ~differ
        dg = float(np.nanmax(np.abs(rn.growth - ro.growth)[same]))
        dg_all = float(np.nanmax(np.abs(rn.growth - ro.growth)))
        band = max(_rel(rn.kH_min[same], ro.kH_min[same]), _rel(rn.kH_max[same], ro.kH_max[same]))
        n_nan = int(np.isnan(ro.growth).sum())
        out.append(f"rtol={rtol}: {int(differ.sum())} sets differ in n_masked or a NaN ({n_nan} NaN growths); "
                   f"on the others max |diff| of growth {dg:.1e}, max rel diff of band ends {band:.1e} "
                   f"(all sets: max |diff| of growth {dg_all:.1e})")
    return f"random growth maps ({n} parameter sets x 161 kH): " + "; ".join(out)


def random_statuses(m_old, m_new, n: int = 200, seed: int = 1) -> str:
    """Statuses and values of rayleigh_branch on random parameter sets (both rtol settings)."""
    q = np.logspace(-4, 4, 200)
    p = _random_params(n, seed)
    out = []
    for rtol in (None, 1e-6):
        ro = m_old.rayleigh_branch(q, **{k: v[:, None] for k, v in p.items()}, rtol=rtol)
        rn = m_new.rayleigh_branch(q, **{k: v[:, None] for k, v in p.items()}, rtol=rtol)
        out.append(f"rtol={rtol}: statuses identical {np.array_equal(ro.status, rn.status)} "
                   f"({int(np.count_nonzero(ro.status))} masked of {ro.status.size}), max rel diff of z "
                   f"{_rel(rn.z, ro.z):.1e}, bit-identical {np.array_equal(rn.z, ro.z, equal_nan=True)}")
    return f"random parameter sets ({n} x 200 kH): " + "; ".join(out)


#: the commit before the kernels were regrouped into records with one Newton loop (issue 15, point 5)
BEFORE_REFACTOR = "2c58f4c"


def export_revision(rev: str, target: Path) -> Path:
    """`git archive` the model/ package of revision `rev` into target (a checkout holding only model/)."""
    import io
    import subprocess
    import tarfile

    data = subprocess.run(["git", "-C", str(ROOT), "archive", rev, "model"], capture_output=True, check=True,
                          timeout=120).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(target, filter="data")
    return target


def markdown(old: Path, rounds: int = 6, oracle: bool = True) -> str:
    """The A/B table and the comparisons as Markdown."""
    m_old, modes_old = load_old(old.resolve())
    co, cn = cases(m_old, modes_old), cases(new, new_modes)

    def inner_for(name: str) -> int:
        return 1 if name.startswith(("growth", "critical")) else (20 if name.startswith("spectrum") else 5)

    rows = ab_table(co, cn, rounds, inner_for)
    lines = ["| case | old [ms] | new [ms] | new/old (median of rounds) |", "|---|---|---|---|"]
    lines += [f"| {name} | {to * 1e3:.2f} | {tn * 1e3:.2f} | {r:.3f} |" for name, to, tn, r in rows]
    lines += ["", *(f"- {line}" for line in compare(co, cn)), f"- {random_statuses(m_old, new)}",
              f"- {random_growth(m_old, new)}"]
    if oracle:
        lines += [f"- {line}" for line in oracle_errors(m_old, new)]
    return "\n".join(lines) + "\n"


def main() -> None:
    import tempfile

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old", type=Path, help="checkout holding the old model/ package")
    ap.add_argument("--old-rev", default=BEFORE_REFACTOR, help=f"or a git revision of this repository (default "
                                                               f"{BEFORE_REFACTOR}, before the kernels' refactor)")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--no-oracle", action="store_true")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        old = args.old or export_revision(args.old_rev, Path(tmp))
        print(markdown(old, args.rounds, not args.no_oracle))


if __name__ == "__main__":
    main()
