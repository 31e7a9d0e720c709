"""Shared pytest setup: build binaries once. The repository root is on the import path
through pyproject.toml (pythonpath), so labkit and grading import as packages."""
import pytest

from labkit.harness import ROOT, build


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
# (pytest-xdist's loadgroup, a group a file), so these start first and the short ones fill in
# around them; the releases' commands are a group a lab (each lab's release is minutes of its
# own).
LONG_FILES = ["tests/grading/test_release_commands.py", "tests/tools/test_new_kind.py",
              "tests/grading/test_hostile.py", "tests/grading/test_release.py",
              "tests/tools/test_new_lab.py", "tests/labs/test_lab04.py",
              "tests/grading/test_batch_slurm.py", "tests/labs/test_properties.py"]
SPLIT_BY = {"tests/grading/test_release_commands.py": ("finished", "gpu_release")}


@pytest.hookimpl(tryfirst=True)  # before xdist reads the groups
def pytest_collection_modifyitems(session, config, items):
    def rank(item):
        path = item.path.as_posix()
        return next((i for i, name in enumerate(LONG_FILES) if path.endswith("/" + name)),
                    len(LONG_FILES))
    items.sort(key=rank)  # stable: each file keeps its own order
    for item in items:
        group = item.path.relative_to(ROOT).as_posix()
        params = getattr(item, "callspec", None)
        for fixture in SPLIT_BY.get(group, ()):
            if params and fixture in params.params:
                group += f"[{params.params[fixture]}]"
        item.add_marker(pytest.mark.xdist_group(group))
