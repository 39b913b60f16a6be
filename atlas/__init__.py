"""The atlas layer: stability atlases computed on a grid (Dask) and stored (Zarr), between :mod:`model` below and
the app and the command line above.

- :mod:`asymslide.atlas.sweep` -- the plan of a sweep, its chunked tasks, their execution and the store they are
  written to (resumable; a store remembers its plan and the model's fingerprint).

It imports :mod:`model` and the scientific stack only, never :mod:`app` or :mod:`asymslide` (ARCHITECTURE.md).
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("asymslide")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"
