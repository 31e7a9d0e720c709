"""Shared pytest setup: build binaries once. The repository root is on the import path
through pyproject.toml (pythonpath), so labkit and grading import as packages."""
import pytest

from labkit.harness import build


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
    from labkit.variants import build_pristine_skeleton
    return build_pristine_skeleton("01-serial", tmp_path_factory.mktemp("lab01-skeleton"))
