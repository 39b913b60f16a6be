"""Interleaved A/B of this tree's model against a git revision's, each in a process of its own; bit-identity checked.

    python benchmarks/bench_revision_ab.py [--old-rev 8252cca] [--rounds 5] [--quick]

(`make bench` runs it against BEFORE_SPLIT, main before the kernels were split by algorithm, and
benchmarks/bit_identity.py against the same revision.)

The old revision's model/ is exported (``git archive``) into a temporary folder and imported there by a worker
process with its own numba cache folder (so it compiles once per run); this tree's model runs in a second worker
with the tree's cache (NUMBA_CACHE_DIR, default .numba_cache). A worker never sees the other's package: numba's cache
of one process must not meet two packages with the same kernels (see bench_thresholds.OLD_WORKER). Each case is
timed alternately old, new / new, old (`--rounds` rounds, each the median of as many calls as take ~0.5 s), so a
change of the machine's load affects both alike; the table gives the median times and the median of the per-round
ratios new/old, of wall time and of the worker thread's CPU time (less sensitive to other processes on a shared
host). Every worker also returns a sha256 of its results' bytes: "bit-identical" says whether the two revisions gave
the same bits.

Cases: growth_chunk (the compiled growth_many of the stability maps) on atlas grids of (gamma, f, beta) with eta =
inf, (gamma, eta, f) with finite eta and (gamma, Delta, xi) with rate-and-state friction, on the atlases' kH grid
(1e-3..1e3, 97 points), at full accuracy and rtol = 1e-6; the spectrum (rayleigh_branch) on 512 kH; the thresholds
(critical_gammas); the argument principle (unstable_modes).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

#: how a worker imports the model of the tree at argv[1]: by the name argv[2] (:func:`model_name`), checked to come
#: from that tree
IMPORT_MODEL = r'''
import importlib, sys
sys.path.insert(0, sys.argv[1])
model = importlib.import_module(sys.argv[2])
assert model.__file__.startswith(sys.argv[1]), model.__file__
'''

#: the worker: imports the model of argv[1] (IMPORT_MODEL), then times the case named on each line of stdin
#: (argv[3]: "quick")
WORKER = IMPORT_MODEL + r'''
import hashlib, json, math, statistics, time
import numpy as np
modes = importlib.import_module(sys.argv[2] + ".modes")

n = 6 if sys.argv[3] == "quick" else 12
S = np.log(np.logspace(-3, 3, 97))


def grid(**axes):
    """(6, n) parameter rows of the product of the axes (the rest: the paper's defaults)."""
    p = dict(gamma=3.0, f=0.9, beta=0.3, eta=math.inf, Delta=1.0, xi=0.0)
    mesh = np.meshgrid(*axes.values(), indexing="ij")
    p.update({k: m.ravel() for k, m in zip(axes, mesh)})
    size = mesh[0].size
    return np.stack([np.broadcast_to(np.asarray(p[k], dtype=float), (size,)) for k in
                     ("gamma", "f", "beta", "eta", "Delta", "xi")])


GAMMA = np.geomspace(0.05, 50.0, n)
ATLAS = {
    "eta=inf": grid(gamma=GAMMA, f=np.linspace(0.1, 2.0, n), beta=np.linspace(0.02, 0.7, n)),
    "finite eta": grid(gamma=GAMMA, eta=np.geomspace(1.0, 1e4, n), f=np.linspace(0.1, 2.0, n)),
    "Delta, xi": grid(gamma=GAMMA, Delta=np.linspace(0.05, 1.0, n), xi=np.geomspace(0.1, 100.0, n)),
}
KH = np.logspace(-4, 4, 512)
PAPER = dict(gamma=3.0, f=0.9, beta=0.3)
CASES = {}
for name, p in ATLAS.items():
    for rtol in (None, 1e-6):
        CASES[f"growth_many {p.shape[1]} sets ({name}), rtol={rtol}"] = (lambda p=p, rtol=rtol:
                                                                       model.growth_chunk(S, p, rtol))
for eta in (math.inf, 7.0):
    CASES[f"spectrum 512 kH, eta={eta:g}"] = lambda eta=eta: model.rayleigh_branch(KH, **PAPER, eta=eta)
CASES["critical_gammas 4 sets"] = lambda: model.critical_gammas(f=np.array([0.5, 0.9, 1.3, 0.9]),
                                                                 beta=np.array([0.3, 0.3, 0.2, 0.3]),
                                                                 eta=np.array([math.inf, math.inf, math.inf, 10.0]),
                                                                 workers=1)
CASES["unstable_modes 2 problems"] = lambda: [modes._modes(modes._problem(k, 3.0, 0.9, 0.3, e, 1.0, 0.0, 5.0, 1e-4,
                                                                          2.0)) for k, e in ((0.77, 10.0),
                                                                                             (0.45, math.inf))]


def digest(r) -> str:
    h = hashlib.sha256()

    def feed(x):
        if isinstance(x, (list, tuple)):
            for y in x:
                feed(y)
        elif hasattr(x, "__dataclass_fields__"):
            for f in x.__dataclass_fields__:
                feed(getattr(x, f))
        elif isinstance(x, str):
            h.update(x.encode())
        else:
            h.update(np.ascontiguousarray(x).tobytes())

    feed(r)
    return h.hexdigest()


print(json.dumps(list(CASES)), flush=True)
for line in sys.stdin:
    name, inner = json.loads(line)
    ts, cpu = [], []
    for _ in range(inner):
        t0, c0 = time.perf_counter(), time.thread_time()
        r = CASES[name]()
        ts.append(time.perf_counter() - t0)
        cpu.append(time.thread_time() - c0)
    print(json.dumps([statistics.median(ts), statistics.median(cpu), digest(r)]), flush=True)
'''


class Worker:
    """A process running WORKER on the model package of `root`."""

    def __init__(self, root: Path, name: str, cache: Path, quick: bool) -> None:
        env = dict(os.environ, PYTHONPATH="", NUMBA_CACHE_DIR=str(cache))
        self.proc = subprocess.Popen([sys.executable, "-c", WORKER, str(root), name, "quick" if quick else "full"],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, env=env, cwd=root)
        self.cases = json.loads(self.proc.stdout.readline())

    def run(self, name: str, inner: int) -> tuple[float, float, str]:
        """(median wall and CPU seconds of `inner` calls, sha256 of the last result) of case `name`."""
        self.proc.stdin.write(json.dumps([name, inner]) + "\n")
        self.proc.stdin.flush()
        t, cpu, h = json.loads(self.proc.stdout.readline())
        return t, cpu, h

    def close(self) -> None:
        self.proc.stdin.close()
        self.proc.wait(timeout=120)


#: the folders a revision of one import name maps into the asymslide package (pyproject.toml's package-dir)
SUBPACKAGES = ("model", "atlas", "app")


def model_name(rev: str | None = None) -> str:
    """The import name of the model at git revision `rev` (None: this tree): ``asymslide.model`` since the project
    has one import name, ``model`` before."""
    if rev is None:
        return "asymslide.model"
    toml = subprocess.run(["git", "-C", str(ROOT), "show", f"{rev}:pyproject.toml"], capture_output=True, text=True,
                          check=True, timeout=60).stdout
    return "asymslide.model" if '"asymslide.model" = "model"' in toml else "model"


def export_revision(rev: str, target: Path, packages: tuple[str, ...] = ("model",)) -> Path:
    """`git archive` the `packages` (folders; those the revision has) of revision `rev` into target. A revision of
    one import name also gets its asymslide/ folder, with links asymslide/model -> model/ (and so on) standing in for
    the installed mapping, so that ``sys.path.insert(0, target); import asymslide.model`` imports the exported code."""
    import io
    import tarfile

    mapped = model_name(rev) == "asymslide.model"
    tree = set(subprocess.run(["git", "-C", str(ROOT), "ls-tree", "--name-only", rev], capture_output=True, text=True,
                              check=True, timeout=60).stdout.split())
    wanted = tuple(p for p in dict.fromkeys((*packages, "asymslide") if mapped else packages) if p in tree)
    data = subprocess.run(["git", "-C", str(ROOT), "archive", rev, *wanted], capture_output=True, check=True,
                          timeout=120).stdout
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        tar.extractall(target, filter="data")
    if mapped:
        for folder in SUBPACKAGES:
            if (target / folder).is_dir():
                (target / "asymslide" / folder).symlink_to(target / folder, target_is_directory=True)
    return target


#: seconds of one measurement (the median of that many calls): short cases are repeated
MEASURE = 0.5


def ab(old: Worker, new: Worker, rounds: int) -> list[tuple]:
    """Per case: (name, old and new median wall seconds, median of the per-round wall ratios new/old, old and new
    median CPU seconds, median of the CPU ratios, bit-identical)."""
    rows = []
    for name in new.cases:
        old.run(name, 1)  # compile or load from the cache
        t_warm, _, h_new = new.run(name, 1)
        h_old = old.run(name, 1)[2]
        inner = max(1, min(2000, round(MEASURE / t_warm)))  # calls per measurement: ~MEASURE seconds
        m = {k: [] for k in ("wo", "wn", "wr", "co", "cn", "cr")}
        for r in range(rounds):
            if r % 2 == 0:
                a, b = old.run(name, inner), new.run(name, inner)
            else:
                b, a = new.run(name, inner), old.run(name, inner)
            for key, v in zip(m, (a[0], b[0], b[0] / a[0], a[1], b[1], b[1] / a[1]), strict=True):
                m[key].append(v)
        med = {k: statistics.median(v) for k, v in m.items()}
        rows.append((name, med["wo"], med["wn"], med["wr"], med["co"], med["cn"], med["cr"], h_old == h_new))
        print(f"{name}: wall old {med['wo']:.4f} s, new {med['wn']:.4f} s, new/old {med['wr']:.3f}; CPU old "
              f"{med['co']:.4f} s, new {med['cn']:.4f} s, new/old {med['cr']:.3f}; identical {h_old == h_new}",
              file=sys.stderr, flush=True)
    return rows


#: the revision of main before the kernels were split by algorithm (issue 25): `make bench` compares with it
BEFORE_SPLIT = "8252cca"


def measure(old_rev: str, rounds: int = 5, quick: bool = False) -> list[tuple]:
    """The rows of :func:`ab` for `old_rev`'s model against this tree's (each in a worker process of its own)."""
    cache = Path(os.environ.get("NUMBA_CACHE_DIR", ROOT / ".numba_cache"))
    with tempfile.TemporaryDirectory() as tmp:
        old_root = export_revision(old_rev, Path(tmp) / "old")
        old = Worker(old_root, model_name(old_rev), Path(tmp) / "numba_cache", quick)
        new = Worker(ROOT, model_name(), cache, quick)
        try:
            return ab(old, new, rounds)
        finally:
            old.close()
            new.close()


def markdown(old_rev: str, rows: list[tuple]) -> str:
    """The table of `rows`, the geometric means of the ratios and whether every case was bit-identical."""
    lines = [f"| case ({old_rev} = old, this tree = new) | old wall [s] | new wall [s] | new/old wall | "
             "old CPU [s] | new CPU [s] | new/old CPU | bit-identical |", "|---|---|---|---|---|---|---|---|"]
    for name, wo, wn, wr, co, cn, cr, same in rows:
        lines.append(f"| {name} | {wo:.4f} | {wn:.4f} | {wr:.3f} | {co:.4f} | {cn:.4f} | {cr:.3f} | "
                     f"{'yes' if same else 'NO'} |")
    lines.append("")
    for k, label in ((3, "wall"), (6, "CPU")):
        geo = math.exp(statistics.fmean(math.log(r[k]) for r in rows))
        lines.append(f"geometric mean of the {label} ratios new/old (medians of rounds): {geo:.3f}  ")
    lines.append(f"all bit-identical: {all(r[7] for r in rows)}")
    return "\n".join(lines) + "\n"


#: the atlas of the sweep A/B: eta = inf over (gamma, f, beta) with its threshold gamma_c, both cores (~10-20 s)
SWEEP_ARGS = ["sweep", "--axis", "gamma=0.5:20:24:log", "--axis", "f=0.3:1.5:10", "--axis", "beta=0.05:0.65:10",
              "--kH", "1e-3:1e3:97:log", "--workers", "2", "--quiet"]
#: the sweep as the command line runs it, with the model of argv[1] by the name argv[2] (checked) and argv[3:] as
#: its arguments
SWEEP_CHILD = IMPORT_MODEL + r"""
from asymslide.cli import main
sys.exit(main(sys.argv[3:]))
"""


def _timed_sweep(root: Path, name: str, cache: Path, store: Path) -> float:
    """Wall seconds of SWEEP_ARGS into a new `store` by the command line of the tree at `root`."""
    import shutil
    import time

    shutil.rmtree(store, ignore_errors=True)
    env = dict(os.environ, PYTHONPATH="", NUMBA_CACHE_DIR=str(cache))
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-c", SWEEP_CHILD, str(root), name, *SWEEP_ARGS, "--out", str(store)], cwd=root,
                   env=env, check=True, capture_output=True, timeout=1800)
    return time.perf_counter() - t0


def sweep_ab(old_rev: str, rounds: int = 3) -> str:
    """The atlas of SWEEP_ARGS by `old_rev`'s command line (its model and engine) and this tree's, alternately, each
    a process of its own (the compile or cache load included, as a user meets it); whether the stores hold the same
    bits. Markdown lines."""
    import numpy as np
    import zarr

    cache = Path(os.environ.get("NUMBA_CACHE_DIR", ROOT / ".numba_cache"))
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        old_root = export_revision(old_rev, tmp / "old", ("model", "atlas", "atlas_engine", "asymslide"))
        runs = {"old": (old_root, model_name(old_rev), tmp / "cache_old"), "new": (ROOT, model_name(), cache)}
        for name, run in runs.items():  # compile (old) or load the cache once before timing
            _timed_sweep(*run, tmp / f"{name}.zarr")
        times: dict[str, list[float]] = {"old": [], "new": []}
        for r in range(rounds):
            for name in ("old", "new") if r % 2 == 0 else ("new", "old"):
                times[name].append(_timed_sweep(*runs[name], tmp / f"{name}.zarr"))
        stores = {name: zarr.open_group(str(tmp / f"{name}.zarr"), mode="r") for name in runs}
        names = sorted(k for k, v in stores["old"].arrays() if v.ndim >= 1 and k in dict(stores["new"].arrays()))
        differ = [k for k in names if not np.array_equal(stores["old"][k][...], stores["new"][k][...],
                                                         equal_nan=stores["old"][k].dtype.kind == "f")]
    med = {k: statistics.median(v) for k, v in times.items()}
    ratio = statistics.median(n / o for n, o in zip(times["new"], times["old"], strict=True))
    return (f"`asymslide {' '.join(SWEEP_ARGS)}` (24·10·10 points, gamma_c over 10·10), {rounds} rounds alternately: "
            f"old ({old_rev}) {med['old']:.1f} s, new {med['new']:.1f} s, new/old {ratio:.3f} (median of rounds); "
            f"{len(names) - len(differ)} of {len(names)} shared arrays bit-identical"
            + (f" (differ: {', '.join(differ)})" if differ else "") + "\n")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--old-rev", default=BEFORE_SPLIT, help="git revision of this repository to compare with "
                    f"(default {BEFORE_SPLIT}, main before the kernels' split)")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--quick", action="store_true", help="smaller atlas grids (6^3 instead of 12^3)")
    ap.add_argument("--sweep", action="store_true", help="also time an atlas by both revisions' command lines")
    args = ap.parse_args()
    print(markdown(args.old_rev, measure(args.old_rev, args.rounds, args.quick)))
    if args.sweep:
        print(sweep_ab(args.old_rev))


if __name__ == "__main__":
    main()
