"""The packaging, the launcher, Docker's entrypoint, CI and the test suite's own guards. Each test here is marked
``infra`` (tests/support/layers.py)."""

from pathlib import Path

import pytest

from tests.support.layers import mark_layer


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    mark_layer(items, Path(__file__).parent)
