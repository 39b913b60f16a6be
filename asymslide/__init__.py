"""asymslide: the command line (``asymslide serve | sweep | info | export | warmup``) and the server launcher,
the top layer (ARCHITECTURE.md).

The physics lives in the :mod:`model` package, the atlas engine and store in :mod:`atlas_engine`, the web app in
:mod:`app`. The distribution installs these four import names; ``model`` and ``app`` keep their short names (see
the README's "Installation and packaging" section for why), so asymslide belongs in its own environment (the
Makefile's .venv, the Docker image): :func:`import_name_clashes` tells when another installed distribution
provides one of them too.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, packages_distributions, version

#: the top-level import names this distribution installs
IMPORT_NAMES = ("model", "atlas_engine", "app", "asymslide")

try:
    __version__ = version("asymslide")
except PackageNotFoundError:  # a source tree that was never installed
    __version__ = "0+unknown"


def import_name_clashes() -> dict[str, list[str]]:
    """Import name -> the other installed distributions that also provide it (empty: no clash)."""
    providers = packages_distributions()
    return {name: others for name in IMPORT_NAMES
            if (others := sorted({d for d in providers.get(name, []) if d.lower() != "asymslide"}))}
