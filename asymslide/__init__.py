"""asymslide: frictional sliding without geometrical reflection symmetry (Aldam et al., PRX 6, 041023, 2016).

One import name, with a subpackage per layer (ARCHITECTURE.md), from the bottom up:

- :mod:`asymslide.model` -- the physics: the spectrum, the response functions, the verdicts (NumPy in, NumPy out);
- :mod:`asymslide.atlas` -- stability atlases: the sweep engine (Dask) and the Zarr store (``pip install
  asymslide[atlas]``);
- :mod:`asymslide.app` -- the Panel web app (``pip install asymslide[app]``);
- this package's own modules -- the command line (``asymslide serve | sweep | info | export | warmup``) and the
  server launcher.

Importing :mod:`asymslide` imports none of them: ``from asymslide import model`` loads the physics alone. In the
source tree the subpackages are the top-level folders model/, atlas/ and app/ (pyproject.toml maps them).
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("asymslide")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"
