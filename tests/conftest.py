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


# The files that take minutes, longest first: make test hands out whole files to the cores
# (pytest-xdist, a file to a process, so a file's module fixtures are made once), so these
# start first and the short ones fill in around them; the releases' commands go a lab at a
# time (each lab's release is minutes of its own: its tests' parameter).
LONG_FILES = ["tests/grading/test_release_commands.py", "tests/tools/test_new_kind.py",
              "tests/grading/test_hostile.py", "tests/grading/test_release.py",
              "tests/tools/test_new_lab.py", "tests/labs/test_lab04.py",
              "tests/grading/test_batch_slurm.py", "tests/labs/test_properties.py"]
SPLIT_BY_PARAMETER = {"tests/grading/test_release_commands.py"}


def group_of(nodeid: str) -> str:
    """Which process a test goes to: its file, and for the files split by parameter, its
    parameter too (`...py::test_x[03]` -> `...py[03]`)."""
    path = nodeid.split("::", 1)[0]
    if path in SPLIT_BY_PARAMETER and nodeid.endswith("]"):
        path += nodeid[nodeid.rindex("["):]
    return path


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(session, config, items):
    def rank(item):
        path = item.path.as_posix()
        return next((i for i, name in enumerate(LONG_FILES) if path.endswith("/" + name)),
                    len(LONG_FILES))
    items.sort(key=rank)  # stable: each file keeps its own order


@pytest.hookimpl(tryfirst=True, optionalhook=True)  # a hook of pytest-xdist, where installed
def pytest_xdist_make_scheduler(config, log):
    """pytest-xdist's scheduler by scope, its scopes group_of's. (Its own loadgroup reads a
    group from a suffix it writes into the test's id, which pytest 9 no longer lets it write:
    every test would be a group of its own, and each process would make every module fixture.)"""
    from xdist.scheduler import LoadScopeScheduling

    class ByGroup(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return group_of(nodeid)

    return ByGroup(config, log)
