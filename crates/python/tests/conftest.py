"""Shared paths of the Python tests: the repository's test data."""

from pathlib import Path

import pytest

DATA = Path(__file__).resolve().parents[3] / "tests" / "data"


@pytest.fixture
def data():
    return DATA
