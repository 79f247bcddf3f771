# Shared fixtures of the Python tests (run by ctest: PYTHONPATH=build/python, FESD_SOURCE_DIR and
# FESD_CLI set by tests/CMakeLists.txt; by hand: PYTHONPATH=build/python python3 -m pytest
# tests/python from the repository root).
import os
import pathlib

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("FESD_SOURCE_DIR",
                                         pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture
def examples():
    return SOURCE_DIR / "examples"


@pytest.fixture
def cli():
    path = os.environ.get("FESD_CLI", str(SOURCE_DIR / "build" / "fesd"))
    if not os.path.exists(path):
        pytest.skip("the fesd program is not built")
    return path
