"""The Python tests run from the source tree (ctest's working directory) against the module of the
build tree (PYTHONPATH=build/python, set by tests/python/CMakeLists.txt)."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent.parent
ROBODOC = str(ROOT / "examples" / "robodoc" / "robodoc.json")


@pytest.fixture
def robodoc(safecass_system):
    return safecass_system(ROBODOC)
