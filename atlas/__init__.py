"""The atlas layer: stability atlases computed on a grid (Dask) and stored (Zarr), between :mod:`asymslide.model`
below and the app and the command line above. The pipeline runs one way:

- :mod:`~asymslide.atlas.plan` -- what a sweep computes (:func:`~asymslide.atlas.plan.make_plan`: axes, fixed
  values, kH grid, the optional parts, the chunks), validated;
- :mod:`~asymslide.atlas.tasks` -- pure functions of one chunk (model calls only);
- :mod:`~asymslide.atlas.executor` -- runs tasks on threads, processes or a Dask cluster;
- :mod:`~asymslide.atlas.writers` -- where results go (memory, a resumable Zarr store, the adaptive journal), with
  :mod:`~asymslide.atlas.schema` (the variables and attributes of a store);
- :mod:`~asymslide.atlas.dense` and :mod:`~asymslide.atlas.adaptive` (on :mod:`~asymslide.atlas.refinement`) -- the
  two planners of the tasks;
- :mod:`~asymslide.atlas.sweep` -- the entry points :func:`~asymslide.atlas.sweep.sweep` and
  :func:`~asymslide.atlas.sweep.run`;
- :mod:`~asymslide.atlas.summary` -- what a store holds, in lines (``asymslide info``) and counts;
- :mod:`~asymslide.atlas.store` -- the atlas directory the app reads.

Beside the pipeline, :mod:`~asymslide.atlas.surface` is the neutral surface of a 3-D grid (pure NumPy geometry),
which the Atlas tab's 3-D view draws.

It imports :mod:`asymslide.model` and the scientific stack only, never the app or the command line
(ARCHITECTURE.md).
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("asymslide")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"
