"""The tests of the atlas layer (atlas/): sweeps, adaptive refinement, stores. Each test here is marked
``engine`` (tests/support/layers.py)."""

from pathlib import Path

import pytest

from tests.support.layers import mark_layer


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    mark_layer(items, Path(__file__).parent)
