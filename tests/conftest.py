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
    """The student's own lab-01 build (whatever state it is in)."""
    return build("lab01")[0]


@pytest.fixture(scope="session")
def lab01_pristine_skeleton(tmp_path_factory):
    """Lab 01's skeleton exactly as generated from the solution, untouched by students."""
    from grading.variants import build_pristine_skeleton
    return build_pristine_skeleton("01-serial", tmp_path_factory.mktemp("lab01-skeleton"))
