"""Bit-identity of this tree's model against a git revision's: spectrum, growth, thresholds and unstable modes.

    python benchmarks/bit_identity.py [--old-rev main]

The old revision's model/ is exported (``git archive``) into a temporary folder. Two worker processes, one per
package (each with its own numba cache folder, so neither ever meets the other's kernels), compute the same fixed
cases through the public API and write every array of every result to an .npz file; this process then compares the
two files array by array, byte for byte (NaN payloads, signed zeros and status codes included). The expected values
are therefore those of the old revision's code, never of the code under test.

Cases (fixed grids): model.rayleigh_branch on 512 kH in [1e-4, 1e4] for eta = inf, 7, 0.5 at full accuracy and
rtol = 1e-6 (every field of SpectrumResult); model.growth_analysis on eta-gamma and f-gamma maps and a
(Delta, xi) map; model.growth_chunk on the atlases' kH grid for three atlas planes at two accuracies;
model.critical_gammas, model.critical_etas and model.threshold_chunk (every field); model.unstable_modes for four
parameter sets; model.unstable_count, model.fastest_mode, model.sliding_analysis (eta = inf and 10, rate on and off),
model.sliding_chunk and model.critical_gammas(branches="all").
Exit status 1 if any array differs (or is missing on one side).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.bench_revision_ab import IMPORT_MODEL, export_revision, model_name  # noqa: E402

#: the worker: imports the model of argv[1] by the name argv[2] (IMPORT_MODEL) and writes the arrays of every case
#: to argv[3] (.npz)
WORKER = IMPORT_MODEL + r'''
import dataclasses, math
import numpy as np
PAPER = dict(gamma=3.0, f=0.9, beta=0.3)
INF = math.inf
KH = np.logspace(-4, 4, 512)
QM = np.logspace(-3, 3, 97)
S = np.log(QM)
GAMMA = np.geomspace(0.05, 50.0, 24)


def rows(**axes):
    """(6, n) parameter rows of the product of the axes (the rest: the paper's defaults)."""
    p = dict(gamma=3.0, f=0.9, beta=0.3, eta=INF, Delta=1.0, xi=0.0)
    mesh = np.meshgrid(*axes.values(), indexing="ij")
    p.update({k: m.ravel() for k, m in zip(axes, mesh)})
    return np.stack([np.broadcast_to(np.asarray(p[k], dtype=float), (mesh[0].size,)) for k in
                     ("gamma", "f", "beta", "eta", "Delta", "xi")])


CASES = {}
for eta in (INF, 7.0, 0.5):
    for rtol in (None, 1e-6):
        CASES[f"rayleigh_branch eta={eta:g} rtol={rtol}"] = (
            lambda eta=eta, rtol=rtol: model.rayleigh_branch(KH, **PAPER, eta=eta, rtol=rtol))
CASES["growth_analysis eta-gamma 24x24"] = lambda: model.growth_analysis(
    QM, gamma=GAMMA[:, None], f=0.9, beta=0.3, eta=np.geomspace(1.0, 1e4, 24)[None, :], workers=1)
CASES["growth_analysis f-gamma 24x24 eta=inf"] = lambda: model.growth_analysis(
    QM, gamma=GAMMA[:, None], f=np.linspace(0.1, 2.0, 24)[None, :], beta=0.3, workers=1)
CASES["growth_analysis Delta-xi 16x16 eta=10"] = lambda: model.growth_analysis(
    QM, gamma=3.0, f=0.9, beta=0.3, eta=10.0, Delta=np.linspace(0.05, 1.0, 16)[:, None],
    xi=np.geomspace(0.1, 100.0, 16)[None, :], workers=1)
ATLAS = {
    "gamma-f-beta eta=inf": rows(gamma=GAMMA[::3], f=np.linspace(0.1, 2.0, 8), beta=np.linspace(0.02, 0.7, 8)),
    "gamma-eta-f": rows(gamma=GAMMA[::3], eta=np.geomspace(1.0, 1e4, 8), f=np.linspace(0.1, 2.0, 8)),
    "gamma-Delta-xi": rows(gamma=GAMMA[::3], Delta=np.linspace(0.05, 1.0, 8), xi=np.geomspace(0.1, 100.0, 8)),
}
for name, p in ATLAS.items():
    for rtol in (None, 1e-6):
        CASES[f"growth_chunk {name} rtol={rtol}"] = lambda p=p, rtol=rtol: model.growth_chunk(S, p, rtol)
CASES["critical_gammas 6 sets"] = lambda: model.critical_gammas(
    f=np.array([0.5, 0.9, 1.3, 0.9, 0.9, 2.0]), beta=np.array([0.3, 0.3, 0.2, 0.3, 0.5, 0.1]),
    eta=np.array([INF, INF, INF, 10.0, 3.0, 100.0]), workers=1)
CASES["critical_etas 4 sets"] = lambda: model.critical_etas(
    gamma=np.array([1.0, 3.0, 10.0, 3.0]), f=np.array([0.9, 0.9, 0.5, 1.5]), beta=0.3, workers=1)
CASES["threshold_chunk gamma 8 sets"] = lambda: model.threshold_chunk(
    "gamma", S, rows(f=np.linspace(0.2, 1.6, 4), eta=np.array([INF, 10.0])))
for k, eta in ((0.77, 10.0), (0.45, INF), (1.0, INF), (0.2, 3.0)):
    CASES[f"unstable_modes kH={k} eta={eta:g}"] = (
        lambda k=k, eta=eta: model.unstable_modes(k, **PAPER, eta=eta))
for k, eta, im_min in ((1.0, 10.0, 1e-3), (0.45, INF, 1e-4), (3.0, 3.0, 1e-3)):
    CASES[f"unstable_count kH={k} eta={eta:g}"] = (
        lambda k=k, eta=eta, im_min=im_min: model.unstable_count(k, **PAPER, eta=eta, re_max=40.0, im_min=im_min))
CASES["fastest_mode 5 kH eta=inf"] = lambda: model.fastest_mode(np.geomspace(0.05, 20.0, 5), **PAPER)
CASES["fastest_mode 3 kH eta=10"] = lambda: model.fastest_mode(np.array([0.1, 1.0, 5.0]), **PAPER, eta=10.0)
for eta in (INF, 10.0):
    for rate in (False, True):
        CASES[f"sliding_analysis eta={eta:g} rate={rate}"] = (
            lambda eta=eta, rate=rate: model.sliding_analysis(
                gamma=np.array([1.0, 2.5125, 3.0]), f=0.9, beta=0.3, eta=eta, rate=rate))
CASES["sliding_chunk 6 sets"] = lambda: model.sliding_chunk(
    np.log(np.geomspace(1e-2, 1e2, 9)), rows(gamma=np.array([1.0, 3.0]), eta=np.array([INF, 3.0, 30.0])))
CASES["critical_gammas branches=all 2 sets"] = lambda: model.critical_gammas(
    f=np.array([0.9, 0.5]), beta=0.3, eta=INF, branches="all", workers=1)


def leaves(prefix, x, out):
    """Every array of a result, named prefix/field/..."""
    if dataclasses.is_dataclass(x):
        for f in dataclasses.fields(x):
            leaves(f"{prefix}/{f.name}", getattr(x, f.name), out)
    elif isinstance(x, tuple) and hasattr(x, "_fields"):
        for f in x._fields:
            leaves(f"{prefix}/{f}", getattr(x, f), out)
    elif isinstance(x, dict):
        for k, v in x.items():
            leaves(f"{prefix}/{k}", v, out)
    elif isinstance(x, (list, tuple)):
        for i, v in enumerate(x):
            leaves(f"{prefix}/{i}", v, out)
    else:
        a = np.asarray(x)
        out[prefix] = a.astype(str) if a.dtype == object else a


arrays = {}
for name, case in CASES.items():
    leaves(name, case(), arrays)
np.savez(sys.argv[3], **arrays)
print(len(arrays), flush=True)
'''


def compute(root: Path, name: str, cache: Path, out: Path) -> dict[str, np.ndarray]:
    """Run WORKER on the model package of `root`, imported as `name` (numba cache `cache`); its arrays by name."""
    env = dict(os.environ, PYTHONPATH="", NUMBA_CACHE_DIR=str(cache))
    subprocess.run([sys.executable, "-c", WORKER, str(root), name, str(out)], check=True, env=env, cwd=root,
                   timeout=3600)
    with np.load(out) as data:
        return {k: data[k] for k in data.files}


def compare(old: dict[str, np.ndarray], new: dict[str, np.ndarray]) -> tuple[int, int, list[str]]:
    """(number of arrays, number of values, names of the arrays that differ in dtype, shape or any byte)."""
    differ = sorted(set(old) ^ set(new))
    for k in sorted(set(old) & set(new)):
        a, b = old[k], new[k]
        if a.dtype != b.dtype or a.shape != b.shape or a.tobytes() != b.tobytes():
            differ.append(k)
    return len(new), sum(a.size for a in new.values()), differ


def run(old_rev: str) -> tuple[int, int, list[str]]:
    """Compute the cases with `old_rev`'s model and this tree's, and compare them."""
    cache = Path(os.environ.get("NUMBA_CACHE_DIR", ROOT / ".numba_cache"))
    with tempfile.TemporaryDirectory() as tmp:
        old_root = export_revision(old_rev, Path(tmp) / "old")
        old = compute(old_root, model_name(old_rev), Path(tmp) / "numba_cache", Path(tmp) / "old.npz")
        new = compute(ROOT, model_name(), cache, Path(tmp) / "new.npz")
    return compare(old, new)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old-rev", default="main", help="git revision of this repository to compare with")
    args = ap.parse_args()
    rev = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", args.old_rev], capture_output=True,
                         text=True, check=True).stdout.strip()
    n_arrays, n_values, differ = run(args.old_rev)
    print(f"{n_arrays} arrays ({n_values:,} values) of spectrum, growth, thresholds and unstable_modes: "
          f"{n_arrays - len(differ)} bit-identical to {args.old_rev} ({rev}), {len(differ)} differ")
    for k in differ:
        print(f"  differs: {k}")
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main()
