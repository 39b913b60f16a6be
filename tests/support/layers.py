"""The layer markers: each test folder's conftest marks the tests under it with its layer's name (``-m model``,
``-m "engine and not slow"``), so that a marker never has to be written on a test by hand."""

from __future__ import annotations

from pathlib import Path

import pytest

#: the test folders, each named after the layer it tests, and what its marker selects
LAYERS = {
    "model": "tests of the physics (model/) against the oracle, properties and bad input",
    "engine": "tests of the atlas layer (atlas/): sweeps, adaptive refinement, stores",
    "app": "tests of the app's scenes and page, headless (a few in a real browser, marked ui)",
    "browser": "journeys and served-app tests in a real browser, and load",
    "infra": "packaging, the launcher, Docker's entrypoint, CI and the test suite's own guards",
}


def mark_layer(items: list[pytest.Item], folder: Path) -> None:
    """Mark every collected test under `folder` with the marker named after the folder (a key of :data:`LAYERS`)."""
    marker = getattr(pytest.mark, folder.name)
    for item in items:
        if item.path.is_relative_to(folder):
            item.add_marker(marker)
