"""The tests of the app's scenes and page, headless (a few in a real browser, marked ui). Each test here is marked
``app`` (tests/support/layers.py)."""

from pathlib import Path

import pytest

from tests.support.layers import mark_layer


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    mark_layer(items, Path(__file__).parent)
