"""The journeys and served-app tests in a real browser, and load. Each test here is marked ``browser``
(tests/support/layers.py)."""

from pathlib import Path

import pytest

from tests.support.layers import mark_layer


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    mark_layer(items, Path(__file__).parent)
