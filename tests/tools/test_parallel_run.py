"""make test's run on every core (tests/conftest.py): pytest-xdist hands each test file to one
process, so a file's module fixtures (a release, a scratch copy of the repository, a set of
mutants: minutes each) are made once, and the releases' command tests go a lab at a time.
Runs pytest on a folder of small made-up test files with this conftest: a few seconds."""
import subprocess
import sys

import pytest

from labkit.harness import ROOT
from tests.conftest import group_of

pytest.importorskip("xdist")

TEST_FILE = '''import os, pathlib, pytest
@pytest.fixture(scope="module")
def made():
    with open(pathlib.Path(__file__).parent / "made.log", "a") as log:
        log.write(f"{pathlib.Path(__file__).stem} {os.getpid()}\\n")
@pytest.mark.parametrize("i", range(6))
def test_a(made, i):
    pass
def test_b(made):
    pass
'''


def test_each_file_goes_to_one_process_and_makes_its_fixtures_once(tmp_path):
    for name in "abcd":
        (tmp_path / f"test_{name}.py").write_text(TEST_FILE)
    p = subprocess.run([sys.executable, "-m", "pytest", "-q", "-n", "2", "-p", "tests.conftest",
                        "-p", "no:cacheprovider", "--rootdir", str(tmp_path), str(tmp_path)],
                       cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stdout[-2000:] + p.stderr[-2000:]
    made = (tmp_path / "made.log").read_text().split("\n")[:-1]
    files = sorted(line.split()[0] for line in made)
    assert files == ["test_a", "test_b", "test_c", "test_d"], made
    assert len({line.split()[1] for line in made}) == 2, f"one process did every file: {made}"


def test_the_releases_commands_go_a_lab_at_a_time():
    release = "tests/grading/test_release_commands.py"
    assert group_of(f"{release}::test_render_and_test_pass[03]") == f"{release}[03]"
    assert group_of(f"{release}::test_no_stale_allowlist_entry") == release
    assert group_of("tests/labs/test_lab01.py::test_x[a]") == "tests/labs/test_lab01.py"
