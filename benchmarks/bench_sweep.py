"""Stability-atlas benchmarks (issue 13): throughput of the sweep engine against the direct model call, on the
local default (Dask's threaded scheduler), a distributed.LocalCluster and a real two-worker cluster started as
processes on 127.0.0.1 (``dask scheduler`` + ``dask worker``), scaling from one to two workers, the wall time of a
64^4 sweep and of a 32^3 gamma_c surface.

    python benchmarks/bench_sweep.py [--quick]

Throughput is parameter sets x kH grid points per second per core. Timings on a shared machine are noisy: the
configurations are measured in one run, the direct call before and after the others, and the ratios are what
counts. --quick runs smaller grids (a smoke test, not the figures quoted).
"""

from __future__ import annotations

import argparse
import os
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from asymslide import model  # noqa: E402
from asymslide.atlas import plan  # noqa: E402
from asymslide.atlas import sweep as S  # noqa: E402
from asymslide.atlas import tasks as atlas_tasks  # noqa: E402
from benchmarks.hostspeed import host_line, host_loop_seconds  # noqa: E402

KH = np.logspace(-3, 3, 97)
CORES = os.cpu_count() or 1


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@contextmanager
def real_cluster(workers: int) -> Iterator[str]:
    """``dask scheduler`` and `workers` x ``dask worker`` (one thread each) as separate processes on 127.0.0.1."""
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    dask = str(Path(sys.executable).parent / "dask")
    env = dict(os.environ, NUMBA_CACHE_DIR=os.environ.get("NUMBA_CACHE_DIR", str(ROOT / ".numba_cache")),
               PYTHONPATH=str(ROOT))
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env, cwd=ROOT)
    procs = [subprocess.Popen([dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
                              **quiet)]
    try:
        procs += [subprocess.Popen([dask, "worker", address, "--nworkers", "1", "--nthreads", "1",
                                    "--no-dashboard", "--memory-limit", "0"], **quiet) for _ in range(workers)]
        from distributed import Client

        with Client(address, timeout=60) as client:
            client.wait_for_workers(workers, timeout=120)
        yield address
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in reversed(procs):
            try:
                p.wait(30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait()


def _timed(fn: Callable[[], object]) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def _warm() -> None:
    """Run on a worker: import the model and load its compiled kernels (numba's cache) once."""
    atlas_tasks.run_task(atlas_tasks.tasks(plan.make_plan({"gamma": [1.0, 2.0]}, kH=KH, gamma_c=False))["growth"][0])


def _warm_cluster(client) -> None:
    """Load the kernels on every worker, then one small sweep through the scheduler (its first tasks are slower)."""
    client.run(_warm)
    S.sweep({"gamma": np.geomspace(0.5, 20, 16)}, kH=KH, gamma_c=False, client=client, chunk_points=1)


def throughput(n: int) -> list[tuple[str, float, int]]:
    """(configuration, wall seconds, cores) for an n^3 grid over (gamma, f, beta) at eta = inf, growth only (the
    default chunks of 8192 points: 32 for n = 64)."""
    from distributed import Client, LocalCluster

    axes = {"gamma": np.geomspace(0.1, 30, n), "f": np.linspace(0.1, 1.5, n), "beta": np.linspace(0.05, 0.7, n)}
    g, f, b = np.meshgrid(*axes.values(), indexing="ij")

    def direct(workers: int) -> Callable[[], object]:
        return lambda: model.growth_analysis(KH, gamma=g, f=f, beta=b, workers=workers)

    def swept(client=None, workers: int | None = None) -> Callable[[], object]:
        return lambda: S.sweep(axes, kH=KH, gamma_c=False, client=client, workers=workers)

    direct(1)()  # warm-up: numba's caches, page cache, the engine's imports (xarray, dask)
    S.sweep({"gamma": axes["gamma"][:4]}, kH=KH, gamma_c=False)
    rows = [("direct growth_analysis, 1 thread", _timed(direct(1)), 1),
            (f"direct growth_analysis, {CORES} threads", _timed(direct(CORES)), CORES),
            (f"sweep, local default (threads, {CORES})", _timed(swept(workers=CORES)), CORES)]
    with LocalCluster(n_workers=CORES, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        _warm_cluster(client)
        rows.append((f"sweep, distributed.LocalCluster ({CORES} processes)", _timed(swept(client)), CORES))
    for workers in (1, 2):
        with real_cluster(workers) as address, Client(address) as client:
            _warm_cluster(client)
            rows.append((f"sweep, dask scheduler + {workers} dask worker process(es)", _timed(swept(client)), workers))
    rows.append(("direct growth_analysis, 1 thread (again)", _timed(direct(1)), 1))
    rows.append((f"direct growth_analysis, {CORES} threads (again)", _timed(direct(CORES)), CORES))
    return rows


def big_sweep(n: int, gamma_c: bool, keep: Path | None = None) -> tuple[float, int, tuple[float, float]]:
    """Wall time of an n^4 sweep over (gamma, f, beta, Delta) at eta = inf, xi = 1 into a Zarr store, its size and
    the host gauge before and after; keep: a directory to leave the store in (as big.zarr), else it is removed."""
    axes = {"gamma": np.geomspace(0.1, 30, n), "f": np.linspace(0.1, 1.5, n), "beta": np.linspace(0.05, 0.7, n),
            "Delta": np.linspace(0.05, 1.0, n)}
    with tempfile.TemporaryDirectory() as tmp:
        where = keep or Path(tmp)
        h0 = host_loop_seconds()
        t = _timed(lambda: S.sweep(axes, fixed={"xi": 1.0}, kH=KH, store=where / "big.zarr", gamma_c=gamma_c))
        h1 = host_loop_seconds()
        size = sum(p.stat().st_size for p in (where / "big.zarr").rglob("*") if p.is_file())
    return t, size, (h0, h1)


def gamma_c_surface(n: int) -> tuple[float, np.ndarray]:
    """Wall time of gamma_c over an n^3 grid (f, beta, Delta) at eta = inf, xi = 1 (no growth variables)."""
    axes = {"f": np.linspace(0.1, 1.5, n), "beta": np.linspace(0.05, 0.7, n), "Delta": np.linspace(0.05, 1.0, n)}
    out: dict = {}
    t = _timed(lambda: out.setdefault("ds", S.sweep(axes, fixed={"xi": 1.0}, kH=KH, growth=False)))
    return t, out["ds"].gamma_c_reason.values


def markdown(quick: bool = False, dense: dict | None = None) -> str:
    """The benchmark as Markdown. dense: a dict to receive the big dense sweep (its store kept in dense["dir"], and
    "store", "seconds", "host"), for the adaptive benchmark of the same grid (benchmarks/bench_adaptive.py): the
    big grid is then 65^4 (2^6 + 1 points per axis, as an adaptive grid needs), else 64^4."""
    host0 = host_loop_seconds()
    n_tp, n_big, n_gc = (12, 8, 6) if quick else (64, 64, 32)
    if dense is not None:
        n_big = 17 if quick else 65
    rows = throughput(n_tp)
    points = n_tp**3 * KH.size
    ref1 = (rows[0][1] + rows[-2][1]) / 2
    refn = (rows[1][1] + rows[-1][1]) / 2
    lines = [f"{n_tp}^3 parameter sets (gamma, f, beta; eta = inf) x {KH.size} kH, growth only; {CORES} cores. "
             "Throughput = parameter sets x kH per second per core used; overhead = wall time over the direct call "
             "with as many cores (its two runs averaged).", "",
             "| configuration | wall [s] | cores | throughput [sets x kH / s / core] | overhead vs direct |",
             "|---|---|---|---|---|"]
    one_worker = two_workers = None
    for name, t, cores in rows:
        ref = ref1 if cores == 1 else refn
        over = "" if name.startswith("direct") else f"{100 * (t / ref - 1):+.1f} %"
        lines.append(f"| {name} | {t:.2f} | {cores} | {points / t / cores:.3g} | {over} |")
        if "1 dask worker" in name:
            one_worker = t
        if "2 dask worker" in name:
            two_workers = t
    if one_worker and two_workers:
        lines += ["", f"Scaling, dask scheduler with 1 -> 2 worker processes: {one_worker / two_workers:.2f}x "
                      "(target >= 1.8x)."]
    t_big, size, host = big_sweep(n_big, gamma_c=False, keep=None if dense is None else dense["dir"])
    per64 = "" if n_big == 64 else f", i.e. {t_big * 64**4 / n_big**4:.0f} s for 64^4 points"
    lines += ["", f"{n_big}^4 sweep (gamma, f, beta, Delta; eta = inf, xi = 1; {KH.size} kH; growth only) into Zarr: "
                  f"{t_big:.0f} s = {t_big / 60:.1f} min{per64} ({n_big**4 / t_big:.3g} sets/s, store "
                  f"{size / 1e6:.0f} MB; host loop {host[0]:.2f} -> {host[1]:.2f} s; target <= 8 min for 64^4)."]
    if dense is not None:
        dense.update(store=dense["dir"] / "big.zarr", seconds=t_big, host=host)
    t_gc, reasons = gamma_c_surface(n_gc)
    counts = {int(c): int((reasons == c).sum()) for c in np.unique(reasons)}
    lines += ["", f"gamma_c surface over {n_gc}^3 points (f, beta, Delta; eta = inf, xi = 1): {t_gc:.0f} s "
                  f"(target <= 120 s); reason codes {counts} (0 found, 5 jump, 6 pole-dense: model.THRESHOLD_STATUS)."]
    lines += ["", host_line(host0, host_loop_seconds())]
    return "\n".join(lines) + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--quick", action="store_true", help="small grids (a smoke test)")
    args = parser.parse_args()
    print(markdown(args.quick))


if __name__ == "__main__":
    main()
