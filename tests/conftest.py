"""Shared pytest setup: import grading/ from the repository, build binaries once."""
import pathlib
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from grading.harness import build  # noqa: E402


@pytest.fixture(scope="session")
def lab01_ref():
    return build("lab01-ref")[0]


@pytest.fixture(scope="session")
def lab01():
    return build("lab01")[0]
