"""Stability atlases: N-D sweeps of the growth analysis, distributed with Dask, stored in Zarr (the entry points).

The paper leaves the multi-dimensional stability phase diagram in (γ, f, β, η, Δ, ξ) to future work; an atlas is
that diagram on a grid. :func:`sweep` plans (:mod:`asymslide.atlas.plan`) and runs it; :func:`run` runs a plan made
already (the command line parses and plans, then calls it). The pipeline runs one way:

    plan (plan.py) -> tasks (tasks.py) -> executor (executor.py) -> writer (writers.py) -> summary (summary.py)

with the dense sweep (dense.py) and the adaptive one (adaptive.py, on refinement.py) as the two planners of the
tasks; the variables and attributes of a store are in schema.py.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from .adaptive import run as run_adaptive
from .dense import run_dense
from .executor import Progress, sweep_processes
from .plan import CountSpec, Plan, SlidingSpec, make_plan
from .refinement import AdaptiveSpec


def sweep(axes: Mapping[str, Sequence[float] | np.ndarray], *, fixed: Mapping[str, float] | None = None,
          kH: Sequence[float] | np.ndarray | None = None, rtol: float | None = None,
          store: str | os.PathLike | None = None, client=None, growth: bool = True, gamma_c: bool = True,
          gamma_range: tuple[float, float] | None = None, count: CountSpec | None = None,
          chunk_points: int | None = None, workers: int | None = None, progress: Progress | None = None,
          command: str | None = None, adaptive: AdaptiveSpec | bool | Mapping[str, Any] | None = None,
          start: Progress | None = None, sliding: SlidingSpec | bool | None = None):
    """Sweep the Rayleigh branch's growth analysis over the grid `axes` (x the fixed values); an xarray.Dataset.

    axes: parameter name (gamma, f, beta, eta, Delta, xi) -> increasing values; fixed: other parameters (default:
    :data:`~plan.DEFAULT_FIXED`, η = ∞ allowed); kH: the grid the growth is bracketed on (default
    :data:`~plan.DEFAULT_KH`); rtol: the model's accuracy setting (None: full certified accuracy); store: a Zarr
    directory, written chunk by chunk and resumed if it exists with the same plan and model (else SweepError,
    nothing written); client: a ``distributed.Client`` (None: Dask's threaded scheduler here, `workers` threads);
    growth: the growth variables; gamma_c: the threshold γ_c over the other axes (searched in `gamma_range`); count:
    the optional all-branch count; progress: called with (kind, points) as chunks finish; command: recorded in the
    attributes; adaptive: None (every point) or True / an :class:`~refinement.AdaptiveSpec` (the growth computed
    only where the verdict can change: :mod:`asymslide.atlas.adaptive`; every axis must have m·2^levels + 1 points);
    start: called with (kind, points) when an adaptive level's batch of that many points starts (kind ``level L``,
    as in `progress`; again as each of its follow rounds starts, with the points the round adds); sliding: None (the
    Rayleigh branch only) or True / a :class:`~plan.SlidingSpec` (also the sliding verdict over every branch, the
    ``*_all`` variables; an adaptive sweep refines it too).

    Returns the dataset: in memory without a store, else opened lazily from the store. Variables and attributes:
    see the module docstring. Bad input raises SweepError (a ValueError) naming the problem.
    """
    plan = make_plan(axes, fixed=fixed, kH=kH, rtol=rtol, growth=growth, gamma_c=gamma_c, gamma_range=gamma_range,
                     count=count, chunk_points=chunk_points, adaptive=adaptive, sliding=sliding)
    return run(plan, store=store, client=client, workers=workers, progress=progress, start=start, command=command)


def run(plan: Plan, *, store: str | os.PathLike | None = None, client=None, workers: int | None = None,
        progress: Progress | None = None, start: Progress | None = None, command: str | None = None):
    """Compute a validated plan (:func:`~plan.make_plan`): the dense sweep, or the adaptive one if the plan has
    ``adaptive``; the other arguments and the result as :func:`sweep`. The command line parses and plans, then
    calls this."""
    with sweep_processes():  # processes started for the sliding verdict serve every round of the sweep
        if plan.adaptive is not None:
            return run_adaptive(plan, store=store, client=client, workers=workers, progress=progress, start=start,
                                command=command)
        return run_dense(plan, store=store, client=client, workers=workers, progress=progress, command=command)


def export_netcdf(store: str | os.PathLike, out: str | os.PathLike) -> Path:
    """Write the atlas as one NetCDF file (the done flags left out; attributes kept)."""
    import xarray as xr

    ds = xr.open_zarr(Path(store), consolidated=False)
    ds = ds.drop_vars([n for n in ds.data_vars if n.startswith("done_")])
    out = Path(out)
    ds.load().to_netcdf(out, engine="scipy", format="NETCDF3_64BIT")
    return out
