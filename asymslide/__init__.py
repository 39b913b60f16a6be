"""asymslide: the command line (``asymslide serve | sweep | info``) and the server launcher.

The physics lives in the :mod:`model` package, the web app in :mod:`app` (see the README's
"Packaging" section for why these keep their short import names).
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("asymslide")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"
